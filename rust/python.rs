//! The Python bindings: the only PyO3 code in the crate.
//!
//! Each function reads numpy arrays as faer matrices, runs the pure Rust function and returns
//! C-ordered float64 arrays. Small problems run on a view of the caller's array with the GIL
//! held (so no Python code can run, let alone change the array, meanwhile) and write straight
//! into the new result array; large ones copy their inputs and release the GIL, so that other
//! Python threads run while they compute. Every [`Error`] maps to one exception class of
//! `aerocontrol.exceptions`; a Rust panic never reaches Python because no code path here panics
//! on input (the core validates and returns errors).
//!
//! The public Python API lives in `python/aerocontrol/`; these functions are its private
//! engine (`aerocontrol._core`).

use crate::batch::{MatrixStack, expm_batch};
use crate::discretize::{Hold, discretize as discretize_core};
use crate::error::{Error, check_square};
use crate::expm::{expm_into, pade_choice, transition_matrices_into};
use faer::{Mat, MatMut, MatRef};
use numpy::ndarray::IxDyn;
use numpy::{PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;
use std::ffi::CString;

/// The exception class of `aerocontrol.exceptions` that an error maps to.
fn exception_class_name(error: &Error) -> &'static str {
    match error {
        Error::NotSquare { .. } | Error::WrongDimensions { .. } | Error::Mismatch { .. } => {
            "ShapeError"
        }
        Error::NonFinite { .. } => "NonFiniteError",
        Error::InvalidValue { .. } => "InvalidArgumentError",
        Error::NoConvergence { .. } => "ConvergenceError",
        Error::InBatch { source, .. } => exception_class_name(source),
    }
}

static EXCEPTIONS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
static REAL_ARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

fn exceptions_module(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    EXCEPTIONS_MODULE
        .get_or_try_init(py, || {
            PyModule::import(py, "aerocontrol.exceptions").map(Bound::unbind)
        })
        .map(|module| module.bind(py))
}

fn exception_class<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyType>> {
    Ok(exceptions_module(py)?
        .getattr(name)?
        .cast_into::<PyType>()?)
}

fn raise(py: Python<'_>, class: &str, message: String) -> PyErr {
    match exception_class(py, class) {
        Ok(class) => PyErr::from_type(class, message),
        Err(import_error) => import_error,
    }
}

fn to_py_err(py: Python<'_>, error: Error) -> PyErr {
    raise(py, exception_class_name(&error), error.to_string())
}

/// Issues an `aerocontrol.exceptions` warning pointing at the caller of the Python wrapper.
fn warn(py: Python<'_>, class: &str, message: &str) -> PyResult<()> {
    let category = exception_class(py, class)?;
    let message = CString::new(message).map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    PyErr::warn(py, category.as_any(), &message, 2)
}

const OVERFLOW_MESSAGE: &str = "the matrix exponential overflowed double precision; \
     the result has infinite or NaN entries";

/// Warns if any entry of a result is not finite.
fn warn_on_overflow(py: Python<'_>, values: &[f64]) -> PyResult<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        warn(py, "NumericalOverflowWarning", OVERFLOW_MESSAGE)
    }
}

/// The argument as a float64 numpy array: a float64 array passes through (a C-level type
/// check); anything else goes through `aerocontrol._validation.real_array`, which converts
/// array-likes and raises NotRealError naming the argument for complex or non-numeric input.
fn float_array<'py>(
    py: Python<'py>,
    value: &Bound<'py, PyAny>,
    arg: &'static str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(array) = value.cast::<PyArrayDyn<f64>>() {
        return Ok(array.clone());
    }
    let convert = REAL_ARRAY.get_or_try_init(py, || {
        PyModule::import(py, "aerocontrol._validation")?
            .getattr("real_array")
            .map(Bound::unbind)
    })?;
    Ok(convert
        .bind(py)
        .call1((value, arg))?
        .cast_into::<PyArrayDyn<f64>>()?)
}

fn shape_error(arg: &'static str, expected: &'static str, shape: &[usize]) -> Error {
    Error::WrongDimensions {
        arg,
        expected,
        shape: shape.to_vec(),
    }
}

/// A faer view of a 2-D float64 array (any strides, including negative ones).
///
/// SAFETY (of using the view): valid while the GIL is held and the array alive; this module
/// never takes a mutable borrow of an argument, so nothing writes to it meanwhile. (rust-numpy's
/// dynamic borrow tracking would cost a global lock and a table lookup per call for no
/// protection beyond that.)
fn matrix_view<'a>(
    array: &'a Bound<'_, PyArrayDyn<f64>>,
    arg: &'static str,
) -> Result<MatRef<'a, f64>, Error> {
    // SAFETY: see the function documentation.
    let view = unsafe { array.as_array() };
    match (view.shape(), view.strides()) {
        (&[rows, cols], &[row_stride, col_stride]) => {
            // SAFETY: the pointer, shape and element strides describe the array's own memory,
            // which outlives the returned view (tied to `array`).
            Ok(
                unsafe {
                    MatRef::from_raw_parts(view.as_ptr(), rows, cols, row_stride, col_stride)
                },
            )
        }
        (shape, _) => Err(shape_error(arg, "a 2-D matrix", shape)),
    }
}

/// A new zero-filled C-ordered float64 array and its data, to be written before it is returned.
fn new_array<'py>(
    py: Python<'py>,
    shape: &[usize],
) -> (Bound<'py, PyArrayDyn<f64>>, &'py mut [f64]) {
    let array = PyArrayDyn::<f64>::zeros(py, IxDyn(shape), false);
    // SAFETY: the array was just created here and is C-contiguous; no other reference to its
    // data exists until it is returned to Python, after the slice is last used.
    let data = unsafe { std::slice::from_raw_parts_mut(array.data(), array.len()) };
    (array, data)
}

/// A new C-ordered numpy array holding `m`.
fn matrix_to_numpy<'py>(py: Python<'py>, m: &Mat<f64>) -> Bound<'py, PyArray2<f64>> {
    let array = PyArray2::<f64>::zeros(py, [m.nrows(), m.ncols()], false);
    // SAFETY: the array was just created here, is C-contiguous, and no other reference to it
    // exists yet.
    let data = unsafe { array.as_slice_mut() }.expect("a new array is contiguous");
    if m.ncols() > 0 {
        for (i, row) in data.chunks_exact_mut(m.ncols()).enumerate() {
            for (j, value) in row.iter_mut().enumerate() {
                *value = m[(i, j)];
            }
        }
    }
    array
}

/// Work (in multiply-adds) below which releasing and re-acquiring the GIL costs more than it
/// lets other threads gain: about a 12 x 12 exponential.
const DETACH_MIN_WORK: usize = 2_000;

/// Runs `f(a)`: on the view itself when the work is small (GIL held), else on a copy with the
/// GIL released.
fn run_on<T: Send>(
    py: Python<'_>,
    a: MatRef<'_, f64>,
    work: usize,
    f: impl FnOnce(MatRef<'_, f64>) -> T + Send,
) -> T {
    if work < DETACH_MIN_WORK {
        f(a)
    } else {
        let copy = a.to_owned();
        py.detach(|| f(copy.as_ref()))
    }
}

/// e^A for a 2-D A, or for every matrix of a 3-D stack (in parallel).
#[pyfunction]
#[pyo3(signature = (a, /))]
fn expm<'py>(py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = float_array(py, a, "A")?;
    let shape = a.shape().to_vec();
    match shape[..] {
        [n, _] => {
            let view = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
            check_square(view, "A").map_err(|e| to_py_err(py, e))?;
            let (out, data) = new_array(py, &[n, n]);
            run_on(py, view, n * n * n, |a| {
                expm_into(a, MatMut::from_row_major_slice_mut(data, n, n))
            })
            .map_err(|e| to_py_err(py, e))?;
            // SAFETY: the result was written above; nothing else refers to it yet.
            warn_on_overflow(py, unsafe { out.as_slice() }.expect("contiguous"))?;
            Ok(out)
        }
        [count, rows, cols] => {
            if rows != cols {
                let error = Error::NotSquare {
                    arg: "A",
                    rows,
                    cols,
                };
                return Err(to_py_err(py, error));
            }
            // The stack is read in place with the GIL released, as numpy's own functions read
            // their inputs: rust-numpy's read borrow excludes writers from Rust code, and a
            // Python thread that writes to an input while a call reads it gets what it asked
            // for. A non-contiguous stack is copied first.
            let readonly = a.readonly();
            let contiguous;
            let data = match readonly.as_slice() {
                Ok(slice) => slice,
                Err(_) => {
                    contiguous = readonly.as_array().iter().copied().collect::<Vec<f64>>();
                    &contiguous
                }
            };
            let (out, out_data) = new_array(py, &[count, rows, rows]);
            let stack = MatrixStack::new(data, count, rows, cols);
            py.detach(|| expm_batch(stack, out_data))
                .map_err(|e| to_py_err(py, e))?;
            let size = rows * rows;
            // SAFETY: as above.
            let values = unsafe { out.as_slice() }.expect("contiguous");
            let overflowed: Vec<usize> = (0..count)
                .filter(|k| {
                    values[k * size..(k + 1) * size]
                        .iter()
                        .any(|v| !v.is_finite())
                })
                .collect();
            if !overflowed.is_empty() {
                let message = format!("{OVERFLOW_MESSAGE} (matrices {overflowed:?} of the stack)");
                warn(py, "NumericalOverflowWarning", &message)?;
            }
            Ok(out)
        }
        _ => Err(to_py_err(
            py,
            shape_error(
                "A",
                "a 2-D square matrix or a 3-D stack of square matrices",
                &shape,
            ),
        )),
    }
}

/// Φ(t_k) = e^{A t_k} for a 1-D array of times, as a len(t) x n x n array.
#[pyfunction]
#[pyo3(signature = (a, t, /))]
fn transition_matrices<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = float_array(py, a, "A")?;
    let t = float_array(py, t, "t")?;
    let view = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let times: Vec<f64> = t.readonly().as_array().iter().copied().collect();
    if t.ndim() != 1 {
        return Err(to_py_err(py, shape_error("t", "a 1-D array", t.shape())));
    }
    check_square(view, "A").map_err(|e| to_py_err(py, e))?;
    let n = view.nrows();
    let (out, data) = new_array(py, &[times.len(), n, n]);
    run_on(py, view, n * n * n * times.len(), |a| {
        transition_matrices_into(a, &times, data)
    })
    .map_err(|e| to_py_err(py, e))?;
    // SAFETY: the result was written above; nothing else refers to it yet.
    warn_on_overflow(py, unsafe { out.as_slice() }.expect("contiguous"))?;
    Ok(out)
}

type Discretized<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Option<Bound<'py, PyArray2<f64>>>,
);

/// (Φ, Γ0, Γ1 or None) of x' = Ax + Bη over the step dt, for method "zoh" or "foh".
#[pyfunction]
#[pyo3(signature = (a, b, dt, method, /))]
fn discretize<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    dt: f64,
    method: &str,
) -> PyResult<Discretized<'py>> {
    let hold = match method {
        "zoh" => Hold::Zero,
        "foh" => Hold::First,
        other => {
            return Err(raise(
                py,
                "InvalidArgumentError",
                format!("method must be \"zoh\" or \"foh\", got {other:?}"),
            ));
        }
    };
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, "B")?);
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let b = matrix_view(&b, "B")
        .map_err(|e| to_py_err(py, e))?
        .to_owned();
    let size = a.nrows() + 2 * b.ncols();
    let result = run_on(py, a, size * size * size, |a| {
        discretize_core(a, b.as_ref(), dt, hold)
    })
    .map_err(|e| to_py_err(py, e))?;
    let gamma1 = result.gamma1.as_ref();
    let finite =
        |m: &Mat<f64>| (0..m.ncols()).all(|j| m.col_as_slice(j).iter().all(|v| v.is_finite()));
    if !finite(&result.phi) || !finite(&result.gamma0) || !gamma1.is_none_or(finite) {
        warn(py, "NumericalOverflowWarning", OVERFLOW_MESSAGE)?;
    }
    Ok((
        matrix_to_numpy(py, &result.phi),
        matrix_to_numpy(py, &result.gamma0),
        gamma1.map(|g| matrix_to_numpy(py, g)),
    ))
}

/// The Padé degree m and the number of squarings s that the exponential of A uses: a
/// diagnostic for tests and for users comparing algorithms.
#[pyfunction]
#[pyo3(signature = (a, /))]
fn expm_pade_choice(py: Python<'_>, a: &Bound<'_, PyAny>) -> PyResult<(usize, u32)> {
    let a = float_array(py, a, "A")?;
    let view = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    pade_choice(view).map_err(|e| to_py_err(py, e))
}

/// The native core of aerocontrol; use the `aerocontrol` package, not this module.
#[pymodule(gil_used = false)]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(expm, m)?)?;
    m.add_function(wrap_pyfunction!(transition_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(discretize, m)?)?;
    m.add_function(wrap_pyfunction!(expm_pade_choice, m)?)?;
    m.add("EXACT_NORM_MAX_ORDER", crate::expm::EXACT_NORM_MAX_ORDER)?;
    m.add("SMALL_MAX_ORDER", crate::expm::SMALL_MAX_ORDER)?;
    m.add("FMA_KERNELS", crate::dispatch::fma_available())?;
    Ok(())
}
