//! The exceptions and warnings of `aerocontrol.exceptions`, raised from Rust.
//!
//! Every [`Error`] variant maps to one [`Class`] (an exhaustive match: a new variant does not
//! compile until it is mapped), and every class is looked up once, when the module is imported
//! ([`load`]): a class missing from `aerocontrol.exceptions` fails the import, not the first
//! error that needs it. The message is the error's `Display` text, so it reads the same from Rust
//! and from Python; the exception carries the error's data as attributes (`argument`,
//! `batch_index`, `eigenvalues`, `entry`, `value`).

use crate::error::Error;
use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyComplex, PyType};
use std::ffi::CString;

/// The exception and warning classes of `aerocontrol.exceptions` that Rust raises, named as in
/// Python.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(clippy::enum_variant_names)]
pub enum Class {
    ShapeError,
    NonFiniteError,
    InvalidArgumentError,
    UncontrollableError,
    ConvergenceError,
    SingularMatrixError,
    NotPositiveDefiniteError,
    NoStabilizingSolutionError,
    IllConditionedError,
    IllConditionedWarning,
    NumericalOverflowWarning,
}

impl Class {
    /// Every class, in the order of [`CLASSES`].
    pub const ALL: [Class; 11] = [
        Class::ShapeError,
        Class::NonFiniteError,
        Class::InvalidArgumentError,
        Class::UncontrollableError,
        Class::ConvergenceError,
        Class::SingularMatrixError,
        Class::NotPositiveDefiniteError,
        Class::NoStabilizingSolutionError,
        Class::IllConditionedError,
        Class::IllConditionedWarning,
        Class::NumericalOverflowWarning,
    ];

    /// The class's name in `aerocontrol.exceptions`.
    pub fn name(self) -> &'static str {
        match self {
            Class::ShapeError => "ShapeError",
            Class::NonFiniteError => "NonFiniteError",
            Class::InvalidArgumentError => "InvalidArgumentError",
            Class::UncontrollableError => "UncontrollableError",
            Class::ConvergenceError => "ConvergenceError",
            Class::SingularMatrixError => "SingularMatrixError",
            Class::NotPositiveDefiniteError => "NotPositiveDefiniteError",
            Class::NoStabilizingSolutionError => "NoStabilizingSolutionError",
            Class::IllConditionedError => "IllConditionedError",
            Class::IllConditionedWarning => "IllConditionedWarning",
            Class::NumericalOverflowWarning => "NumericalOverflowWarning",
        }
    }

    fn index(self) -> usize {
        Class::ALL
            .iter()
            .position(|&c| c == self)
            .expect("every class is in ALL")
    }
}

/// The class of a core error, or None for the built-in exceptions (MemoryError for a refused
/// allocation, KeyboardInterrupt for an interruption).
fn class_of(error: &Error) -> Option<Class> {
    Some(match error {
        Error::NotSquare { .. } | Error::WrongDimensions { .. } | Error::Mismatch { .. } => {
            Class::ShapeError
        }
        Error::NonFinite { .. } => Class::NonFiniteError,
        Error::InvalidValue { .. } | Error::InvalidArgument { .. } => Class::InvalidArgumentError,
        Error::Uncontrollable { .. } => Class::UncontrollableError,
        Error::NoConvergence { .. } => Class::ConvergenceError,
        Error::Singular { .. } => Class::SingularMatrixError,
        Error::NotPositiveDefinite { .. } => Class::NotPositiveDefiniteError,
        Error::NoStabilizingSolution { .. } => Class::NoStabilizingSolutionError,
        Error::IllConditioned { .. } => Class::IllConditionedError,
        Error::InBatch { source, .. } => return class_of(source),
        Error::OutOfMemory { .. } | Error::Interrupted => return None,
    })
}

/// The classes, looked up once.
static CLASSES: PyOnceLock<Vec<Py<PyType>>> = PyOnceLock::new();

/// Looks every [`Class`] up in `aerocontrol.exceptions`; an error if any is missing.
pub fn load(py: Python<'_>) -> PyResult<()> {
    CLASSES
        .get_or_try_init(py, || {
            let module = PyModule::import(py, "aerocontrol.exceptions")?;
            Class::ALL
                .iter()
                .map(|class| {
                    Ok(module
                        .getattr(class.name())?
                        .cast_into::<PyType>()?
                        .unbind())
                })
                .collect::<PyResult<Vec<_>>>()
        })
        .map(|_| ())
}

fn class<'py>(py: Python<'py>, class: Class) -> PyResult<Bound<'py, PyType>> {
    load(py)?;
    let classes = CLASSES.get(py).expect("loaded above");
    Ok(classes[class.index()].bind(py).clone())
}

/// The exception `class` with `message`.
pub fn raise(py: Python<'_>, exception: Class, message: String) -> PyErr {
    match class(py, exception) {
        Ok(class) => PyErr::from_type(class, message),
        Err(import_error) => import_error,
    }
}

/// Sets the error's data as attributes of its exception.
fn annotate(py: Python<'_>, exception: &PyErr, error: &Error) -> PyResult<()> {
    let value = exception.value(py);
    let mut error = error;
    if let Error::InBatch { index, .. } = error {
        value.setattr("batch_index", *index)?;
    }
    while let Error::InBatch { source, .. } = error {
        error = source;
    }
    match error {
        Error::NotSquare { arg, .. }
        | Error::WrongDimensions { arg, .. }
        | Error::Mismatch { arg, .. }
        | Error::InvalidArgument { arg, .. }
        | Error::NotPositiveDefinite { arg, .. } => value.setattr("argument", *arg)?,
        Error::NonFinite {
            arg,
            index,
            value: entry,
        } => {
            value.setattr("argument", *arg)?;
            value.setattr("entry", index.clone())?;
            value.setattr("value", *entry)?;
        }
        Error::InvalidValue {
            arg, value: given, ..
        } => {
            value.setattr("argument", *arg)?;
            value.setattr("value", *given)?;
        }
        Error::Singular { arg, .. } => value.setattr("argument", *arg)?,
        Error::Uncontrollable { eigenvalues, .. } => {
            let eigenvalues: Vec<Bound<'_, PyComplex>> = eigenvalues
                .iter()
                .map(|z| PyComplex::from_doubles(py, z.re, z.im))
                .collect();
            value.setattr("eigenvalues", eigenvalues)?;
        }
        _ => {}
    }
    Ok(())
}

/// The Python exception of a core error.
pub fn to_py_err(py: Python<'_>, error: Error) -> PyErr {
    let message = error.to_string();
    let Some(exception) = class_of(&error) else {
        return match error {
            Error::Interrupted => PyKeyboardInterrupt::new_err(message),
            Error::InBatch { ref source, .. } if matches!(**source, Error::Interrupted) => {
                PyKeyboardInterrupt::new_err(message)
            }
            _ => PyMemoryError::new_err(message),
        };
    };
    let raised = raise(py, exception, message);
    match annotate(py, &raised, &error) {
        Ok(()) => raised,
        Err(failure) => failure,
    }
}

/// Issues the warning `class`, pointing at the caller of the Python wrapper.
pub fn warn(py: Python<'_>, warning: Class, message: &str) -> PyResult<()> {
    let category = class(py, warning)?;
    let message = CString::new(message).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    PyErr::warn(py, category.as_any(), &message, 2)
}

/// The names of the exception and warning classes that the native module raises, for the test
/// that each exists in `aerocontrol.exceptions` with the right base class.
#[pyfunction]
pub fn exception_classes() -> Vec<&'static str> {
    Class::ALL.iter().map(|c| c.name()).collect()
}
