//! The module's state, one plain struct per concern. None of them knows
//! `Module`: the behaviour lives in the `impl Module` files.

pub mod axis;
pub mod globals;
pub mod interrupts;
pub mod io;
pub mod link;
pub mod persistence;
pub mod registers;
