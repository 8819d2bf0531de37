//! What a host needs to talk to any TMCL module, virtual or real: a link
//! (TCP or a serial port), direct-mode lines with parameter names, replies
//! in words, and traces of sessions. Shared by `tmclsim send`/`console`/
//! `trace` and the browser IDE.

pub mod client;
pub mod line;
pub mod names;
pub mod reply;
pub mod trace;

pub use client::{Client, hex};
