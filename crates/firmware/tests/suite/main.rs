//! The firmware crate's integration tests, one test binary: one link, and
//! the shared helpers built once.

mod ascii;
mod bootloader;
mod can_bus;
mod common;
mod deadlines;
mod direct_mode;
mod driver;
mod eeprom;
mod features;
mod golden;
mod motion;
mod no_import_cycles;
mod no_io;
mod observers;
mod only_the_bus_moves_time;
mod program;
mod reference_search;
mod resync;
mod rust_source;
mod sibling_modules;
mod single_axis_family;
mod sixpoint;
mod sixpoint_family;
mod sixpoint_module;
mod tmc4361a;
mod tmcm_1310;
mod tmcm_351;
mod world_lines;
mod world_values;
