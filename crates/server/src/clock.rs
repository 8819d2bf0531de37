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
    loop {
        let due = bus.tick();
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
