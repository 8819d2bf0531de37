//! Windows has no pseudo-terminals: a pty link and the SLCAN adapter on
//! a pty are refused there, before anything is opened. Host software that
//! opens only serial ports reaches a module on Windows through a real or
//! virtual COM port (the serial link; a com0com null-modem pair gives it a
//! port of its own), or over TCP.

use crate::{ServerConfig, SharedBus};
use std::convert::Infallible;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tokio::sync::watch;

/// What a pty link is refused with.
const UNSUPPORTED: &str = "a pty is a Unix device and Windows has none: serve the module on a COM port (a com0com \
                           virtual null-modem pair gives host software that opens only COM ports a port of its own) or on TCP";

/// A pty, which is never opened here.
pub(crate) struct Pty {
    pub link: PathBuf,
    pub device: PathBuf,
    pub claim: Option<LinkClaim>,
    never: Infallible,
}

/// A claim on a pty's path, which no pty here makes.
pub(crate) enum LinkClaim {}

impl Pty {
    /// Refuses: Windows has no ptys.
    pub fn open(_link: &Path) -> io::Result<Pty> {
        Err(io::Error::new(io::ErrorKind::Unsupported, UNSUPPORTED))
    }

    /// What a pty that cannot exist does: nothing.
    pub(crate) fn absurd(self) -> ! {
        match self.never {}
    }
}

pub(crate) async fn run(pty: Pty, _: Arc<SharedBus>, _: ServerConfig, _: watch::Receiver<bool>) {
    pty.absurd()
}
