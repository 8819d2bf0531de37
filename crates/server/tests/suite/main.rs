//! The server crate's integration tests, one test binary: one link, and
//! the shared helpers built once.

mod common;
mod control;
mod eeprom_file;
mod limits;
mod links;
mod sources;
