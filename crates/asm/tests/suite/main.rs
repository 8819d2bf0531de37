//! The asm crate's integration tests, one test binary: one link, and
//! the shared helpers built once.

mod common;
mod end_stop;
mod errors;
mod examples;
mod fuzz;
mod golden;
mod includes;
mod limits;
mod round_trip;
mod run_examples;
