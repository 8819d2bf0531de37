//! The profile crate's integration tests, one test binary: one link, and
//! the shared helpers built once.

mod sibling_profiles;
mod single_axis_family;
