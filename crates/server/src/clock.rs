//! The clock task: wakes when the module has something due on its own.

use crate::shared::SharedModule;
use std::sync::Arc;
use tokio::sync::watch;
use tokio::time::Instant;

pub(crate) async fn run(module: Arc<SharedModule>, mut stop: watch::Receiver<bool>) {
    loop {
        let due = module.schedule();
        let sleep = async {
            match due.and_then(|ns| module.instant_of(ns)) {
                Some(at) => tokio::time::sleep_until(Instant::from_std(at)).await,
                None => std::future::pending::<()>().await,
            }
        };
        tokio::select! {
            _ = sleep => {
                if let Some(at) = due.and_then(|ns| module.instant_of(ns)) {
                    module.record_wakeup(std::time::Instant::now().saturating_duration_since(at).as_nanos() as u64);
                }
                module.tick()
            }
            _ = module.changed() => {}
            _ = stop.changed() => return,
        }
    }
}
