//! The package's exceptions are plain Python classes (tmclsim/errors.py);
//! these helpers build them from Rust.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use tmclsim_protocol::Status;

/// Calls `tmclsim.errors.<class_name>(*args)` and turns the instance into
/// an error to raise.
fn python_error<'py>(py: Python<'py>, class_name: &str, args: impl pyo3::call::PyCallArgs<'py>) -> PyErr {
    let made = py.import("tmclsim.errors").and_then(|m| m.getattr(class_name)).and_then(|class| class.call1(args));
    match made {
        Ok(exception) => PyErr::from_value(exception),
        Err(e) => e,
    }
}

/// `TmclError(status, message)`.
pub fn tmcl_error(py: Python<'_>, status: Status, message: String) -> PyErr {
    python_error(py, "TmclError", (status.code(), message))
}

/// `AssemblyError([Diagnostic(file, line, column, message), ...])`.
pub fn assembly_error(py: Python<'_>, diagnostics: &[tmclsim_asm::Diagnostic]) -> PyErr {
    let class = match py.import("tmclsim.errors").and_then(|m| m.getattr("Diagnostic")) {
        Ok(c) => c,
        Err(e) => return e,
    };
    let mut items = Vec::new();
    for d in diagnostics {
        match class.call1((d.file.as_str(), d.line, d.column, d.message.as_str())) {
            Ok(item) => items.push(item),
            Err(e) => return e,
        }
    }
    python_error(py, "AssemblyError", (items,))
}

pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

pub fn os_error(message: impl Into<String>) -> PyErr {
    PyOSError::new_err(message.into())
}
