//! The signals that end a server: Ctrl-C, SIGTERM, SIGHUP.

use tokio::runtime::Runtime;
use tokio::signal::unix::{Signal, SignalKind, signal};

/// The handlers of the signals that end a server, installed before it
/// takes connections: what waiting needs (a runtime, the handlers'
/// descriptors) is allocated then, so a server whose clients used up its
/// file descriptors can still be stopped. A signal that comes before
/// [`Signals::wait`] is kept for it.
pub(crate) struct Signals {
    runtime: Runtime,
    handlers: [Signal; 3],
}

impl Signals {
    pub(crate) fn install() -> Result<Signals, String> {
        let failed = |e: std::io::Error| format!("cannot install the signal handlers: {e}");
        let runtime = tokio::runtime::Builder::new_current_thread().enable_io().build().map_err(failed)?;
        let [interrupt, terminate, hangup] = {
            let _context = runtime.enter();
            [SignalKind::interrupt(), SignalKind::terminate(), SignalKind::hangup()].map(signal)
        };
        Ok(Signals { handlers: [interrupt.map_err(failed)?, terminate.map_err(failed)?, hangup.map_err(failed)?], runtime })
    }

    /// Blocks until the process gets Ctrl-C (SIGINT), SIGTERM or SIGHUP.
    pub(crate) fn wait(self) {
        let Signals { runtime, handlers: [mut interrupt, mut terminate, mut hangup] } = self;
        runtime.block_on(async {
            tokio::select! {
                _ = interrupt.recv() => {}
                _ = terminate.recv() => {}
                _ = hangup.recv() => {}
            }
        });
    }
}
