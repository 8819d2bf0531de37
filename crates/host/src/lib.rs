//! What a host needs to talk to any TMCL module, virtual or real: a link
//! (TCP or a serial port), direct-mode lines with parameter names, replies
//! in words, and traces of sessions. Shared by `tmclsim send`/`console`/
//! `trace` and the browser IDE.

pub mod client;
pub mod eeprom_file;
pub mod eeprom_files;
pub mod faults;
pub mod intel_hex;
pub mod shared;
pub mod trace;

// Without I/O, so that the playground has them too.
pub use tmclsim_ide::{download, line, names, observe, reply};

pub use client::{Client, LinkError, hex};
pub use faults::LinkFaults;
pub use shared::{SharedBus, Stats};
