//! What a host needs to talk to any TMCL module, virtual or real: a link
//! (TCP or a serial port), direct-mode lines with parameter names, and
//! replies in words. Shared by `tmclsim send`/`console` and the browser
//! IDE.

pub mod client;
pub mod line;
pub mod names;
pub mod reply;

pub use client::{Client, hex};
