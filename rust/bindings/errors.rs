//! The exceptions and warnings of `aerocontrol.exceptions`, raised from Rust.
//!
//! Every [`Error`] maps to one exception class; the message is the error's `Display` text, so it
//! reads the same from Rust and from Python. The classes are looked up once per process.

use crate::error::Error;
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;
use std::ffi::CString;

/// The exception class of `aerocontrol.exceptions` that an error maps to, or None for the
/// built-in exceptions (MemoryError, KeyboardInterrupt).
fn exception_class_name(error: &Error) -> Option<&'static str> {
    Some(match error {
        Error::NotSquare { .. } | Error::WrongDimensions { .. } | Error::Mismatch { .. } => {
            "ShapeError"
        }
        Error::NonFinite { .. } => "NonFiniteError",
        Error::InvalidValue { .. } | Error::InvalidArgument { .. } => "InvalidArgumentError",
        Error::Uncontrollable { .. } => "UncontrollableError",
        Error::NoConvergence { .. } => "ConvergenceError",
        Error::Singular { .. } => "SingularMatrixError",
        Error::NotPositiveDefinite { .. } => "NotPositiveDefiniteError",
        Error::NoStabilizingSolution { .. } => "NoStabilizingSolutionError",
        Error::IllConditioned { .. } => "IllConditionedError",
        Error::InBatch { source, .. } => return exception_class_name(source),
        Error::OutOfMemory { .. } | Error::Interrupted => return None,
    })
}

/// The innermost error of a batch's nesting.
fn root(error: &Error) -> &Error {
    match error {
        Error::InBatch { source, .. } => root(source),
        other => other,
    }
}

static EXCEPTIONS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

fn exception_class<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyType>> {
    let module = EXCEPTIONS_MODULE
        .get_or_try_init(py, || {
            PyModule::import(py, "aerocontrol.exceptions").map(Bound::unbind)
        })?
        .bind(py);
    Ok(module.getattr(name)?.cast_into::<PyType>()?)
}

/// The exception `class` of `aerocontrol.exceptions` with `message`.
pub fn raise(py: Python<'_>, class: &str, message: String) -> PyErr {
    match exception_class(py, class) {
        Ok(class) => PyErr::from_type(class, message),
        Err(import_error) => import_error,
    }
}

/// The Python exception of a core error.
pub fn to_py_err(py: Python<'_>, error: Error) -> PyErr {
    match exception_class_name(&error) {
        Some(class) => raise(py, class, error.to_string()),
        None => match root(&error) {
            Error::Interrupted => PyKeyboardInterrupt::new_err(error.to_string()),
            _ => PyMemoryError::new_err(error.to_string()),
        },
    }
}

/// Issues the warning `class` of `aerocontrol.exceptions`, pointing at the caller of the Python
/// wrapper.
pub fn warn(py: Python<'_>, class: &str, message: &str) -> PyResult<()> {
    let category = exception_class(py, class)?;
    let message = CString::new(message).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    PyErr::warn(py, category.as_any(), &message, 2)
}
