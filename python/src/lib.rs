//! The native part of the `tmclsim` Python package (`tmclsim._tmclsim`):
//! PyO3 bindings over the tmclsim crates.
//!
//! - `module.rs`: `Module`, a virtual TMCL module in process (or, while it
//!   is served, a handle that reaches it through the server);
//! - `bus.rs`: `Bus`, several modules on one link;
//! - `server.rs`: `Server`, modules served on TCP and a pty;
//! - `asm.rs`: `Program`, `assemble`, `disassemble`;
//! - `types.rs`: `Reply`, `Instruction`, `Registers`;
//! - `world.rs`: the control protocol of docs/world.md on any module;
//! - `advance.rs`: moving virtual time on (checked durations, Ctrl-C);
//! - `errors.rs`: raising the package's Python exceptions, panics caught;
//! - `cli_main`: the `tmclsim` command itself, for the console script.
//!
//! The pure-Python part (`tmclsim/__init__.py`) subclasses `Module` and
//! `Server` to add the world convenience methods and PyTrinamic helpers.

// An extension module: its API is Python's, documented in _tmclsim.pyi.
#![allow(missing_docs)]

mod advance;
mod asm;
mod bus;
mod errors;
mod module;
mod server;
mod types;
mod world;

use pyo3::prelude::*;

/// cli_main(argv) -> int
/// --
///
/// Runs the `tmclsim` command with `argv` (the program name first) and
/// returns its exit status; the package's `tmclsim` console script and
/// `python -m tmclsim` call it. Usage errors, `--help` and `--version`
/// end the process, as the command does.
#[pyfunction]
fn cli_main(py: Python<'_>, argv: Vec<String>) -> u8 {
    py.detach(|| tmclsim_cli::run(argv))
}

#[pymodule]
fn _tmclsim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<module::Module>()?;
    m.add_class::<bus::Bus>()?;
    m.add_class::<server::Server>()?;
    m.add_class::<types::Reply>()?;
    m.add_class::<types::Instruction>()?;
    m.add_class::<types::Registers>()?;
    m.add_class::<asm::Program>()?;
    m.add_function(wrap_pyfunction!(asm::assemble, m)?)?;
    m.add_function(wrap_pyfunction!(asm::assemble_file, m)?)?;
    m.add_function(wrap_pyfunction!(asm::disassemble, m)?)?;
    m.add_function(wrap_pyfunction!(profiles, m)?)?;
    m.add_function(wrap_pyfunction!(cli_main, m)?)?;
    m.add_function(wrap_pyfunction!(module::_time_core, m)?)?;
    m.add_function(wrap_pyfunction!(status_text, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_inside_guard, m)?)?;
    Ok(())
}

/// profiles() -> list[str]
/// --
///
/// The names of the built-in module profiles (e.g. ``["tmcm-1141"]``).
#[pyfunction]
fn profiles() -> Vec<&'static str> {
    tmclsim_firmware::Profile::names()
}

/// status_text(status: int) -> str
/// --
///
/// A TMCL status code in words, as the firmware describes it (e.g.
/// ``status_text(4) == "invalid value"``).
#[pyfunction]
fn status_text(status: u8) -> String {
    tmclsim_protocol::Status::text(status).into_owned()
}

/// _panic_inside_guard() -> None
/// --
///
/// For the package's tests: panics inside the guard that every call into
/// the simulator runs in, which raises ``tmclsim.InternalError``.
#[pyfunction]
fn _panic_inside_guard(py: Python<'_>) -> PyResult<()> {
    errors::guard(py, || panic!("a panic on purpose"))
}
