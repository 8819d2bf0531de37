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

/// Runs `f`, turning a panic inside it into `Err` with the panic's
/// message, so that no panic reaches Python (where it would be a
/// `PanicException`, which `except Exception` does not catch). Needs no
/// GIL; [`internal_error`] makes the exception.
pub fn catch<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(ToString::to_string)
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".to_string())
    })
}

/// `InternalError(message)`: the simulator failed inside.
pub fn internal_error(py: Python<'_>, message: String) -> PyErr {
    python_error(py, "InternalError", (format!("internal error in the simulator: {message}"),))
}

/// [`catch`] with the GIL held: a panic becomes `InternalError`.
pub fn guard<R>(py: Python<'_>, f: impl FnOnce() -> R) -> PyResult<R> {
    catch(f).map_err(|message| internal_error(py, message))
}
