//! The module's parts, one per concern, each owning its state and the
//! logic of the commands that touch nothing else: the axes, the global
//! parameters, the parameter tables, the calculation registers, the I/O,
//! the interrupts and events, the host link, the EEPROM. None of them
//! knows `Module`, which lends them what else they need (the profile, the
//! world, a register) and coordinates what spans several parts in the
//! `impl Module` files.

pub mod axis;
pub mod calculator;
pub mod globals;
pub mod interrupts;
pub mod io;
pub mod link;
pub mod parameters;
pub mod persistence;
pub mod registers;
