//! The signals that end a server: Ctrl-C, SIGTERM, SIGHUP; on Windows
//! Ctrl-C, Ctrl-Break and the console window closing.

use tokio::runtime::Runtime;
#[cfg(unix)]
use tokio::signal::unix::{Signal, SignalKind, signal};
#[cfg(windows)]
use tokio::signal::windows::{CtrlBreak, CtrlC, CtrlClose, ctrl_break, ctrl_c, ctrl_close};

/// The handlers of the signals that end a server, installed before it
/// takes connections: what waiting needs (a runtime, the handlers'
/// descriptors) is allocated then, so a server whose clients used up its
/// file descriptors can still be stopped. A signal that comes before
/// [`Signals::wait`] is kept for it.
pub(crate) struct Signals {
    runtime: Runtime,
    handlers: Handlers,
}

#[cfg(unix)]
type Handlers = [Signal; 3];

#[cfg(windows)]
type Handlers = (CtrlC, CtrlBreak, CtrlClose);

#[cfg(unix)]
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

#[cfg(windows)]
impl Signals {
    pub(crate) fn install() -> Result<Signals, String> {
        let failed = |e: std::io::Error| format!("cannot install the console control handlers: {e}");
        let runtime = tokio::runtime::Builder::new_current_thread().enable_io().build().map_err(failed)?;
        let handlers = {
            let _context = runtime.enter();
            (ctrl_c().map_err(failed)?, ctrl_break().map_err(failed)?, ctrl_close().map_err(failed)?)
        };
        Ok(Signals { runtime, handlers })
    }

    /// Blocks until the process gets Ctrl-C, Ctrl-Break (what
    /// `fleet-bench` sends its server), or its console window closes.
    pub(crate) fn wait(self) {
        let Signals { runtime, handlers: (mut interrupt, mut brk, mut close) } = self;
        runtime.block_on(async {
            tokio::select! {
                _ = interrupt.recv() => {}
                _ = brk.recv() => {}
                _ = close.recv() => {}
            }
        });
    }
}
