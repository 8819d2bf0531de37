//! The web crate's integration tests, one test binary: one link, and
//! the shared helpers built once.

mod api;
mod common;
mod limits;
mod link;
