//! The SLCAN adapter lives on a pty, which Windows has not (no_pty.rs):
//! there it is refused with the pty, before anything is opened.

use crate::SharedBus;
use crate::pty::Pty;
use std::sync::Arc;
use tokio::sync::watch;

pub(crate) async fn run(pty: Pty, _: Arc<SharedBus>, _: watch::Receiver<bool>) {
    pty.absurd()
}
