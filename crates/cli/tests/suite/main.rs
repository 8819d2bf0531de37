//! The cli crate's integration tests, one test binary: one link, and
//! the shared helpers built once.

mod common;
mod console;
mod eeprom_kill;
mod helpful_errors;
mod hostile;
mod hostile_cli;
mod hostile_eeprom;
mod hostile_links;
mod hostile_network;
mod hostile_world;
mod profile_table;
mod program_tools;
mod serial;
mod shell;
mod speed;
mod trace;
mod web;
