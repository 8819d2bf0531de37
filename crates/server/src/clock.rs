//! The clock task: wakes exactly when the bus has something due on its own
//! ([`Bus::next_deadline`](tmclsim_firmware::Bus::next_deadline)), never on
//! a polling period.

use crate::SharedBus;
use std::sync::Arc;
use tokio::sync::{Notify, watch};
use tokio::time::Instant;

pub(crate) async fn run(bus: Arc<SharedBus>, mut stop: watch::Receiver<bool>) {
    // Woken whenever something changed the bus's plans.
    let changed = Arc::new(Notify::new());
    let notify = changed.clone();
    bus.set_waker(move || notify.notify_one());
    let mut behind = bus.fell_behind().0;
    loop {
        let due = bus.tick();
        let (now_behind, speed) = bus.fell_behind();
        if now_behind > behind {
            if behind == 0 {
                eprintln!(
                    "tmclsim: virtual time falls behind --speed {speed}: the modules cannot compute it as fast; it runs as fast as they can (docs/behaviour.md rule 119)"
                );
            }
            behind = now_behind;
            // The backlog was given up: requests, the control socket and a
            // stop signal have their turn before the modules go on.
            tokio::select! {
                _ = tokio::time::sleep(std::time::Duration::from_micros(500)) => {}
                _ = stop.changed() => return,
            }
            continue;
        }
        let at = due.and_then(|ns| bus.instant_of(ns));
        let sleep = async {
            match at {
                Some(at) => tokio::time::sleep_until(Instant::from_std(at)).await,
                None => std::future::pending::<()>().await,
            }
        };
        tokio::select! {
            _ = sleep => {
                if let Some(at) = at {
                    bus.record_wakeup(std::time::Instant::now().saturating_duration_since(at).as_nanos() as u64);
                }
            }
            _ = changed.notified() => {}
            _ = stop.changed() => return,
        }
    }
}
