//! The Python bindings: the only PyO3 code in the crate.
//!
//! Each function reads numpy arrays as faer matrices, runs the pure Rust function and returns
//! C-ordered float64 arrays. Small problems run on a view of the caller's array with the GIL
//! held (so no Python code runs, let alone changes the array, meanwhile) and write straight into
//! the new result array; large ones, and every stack, copy their inputs and release the GIL, so
//! that other Python threads run while they compute.
//!
//! Every [`Error`] maps to one exception class of `aerocontrol.exceptions`. Memory is requested
//! fallibly: an impossible size (a broadcast array of 10^10 entries, say) raises MemoryError.
//! The core returns errors rather than panicking; as a last line of defence every call runs
//! under [`guarded`], which turns a panic that escaped anyway (an allocation inside faer that
//! failed) into a Python exception instead of unwinding into the interpreter.

use crate::batch::{
    CareBatchOutput, CareStacks, MatrixStack, PlaceBatchOutput, Placer, batch_count,
    care_batch as care_batch_core, expm_batch, place_batch as place_batch_core,
};
use crate::care::{CareOptions, solve_care as solve_care_core};
use crate::ctrb::{
    controllability as controllability_core, ctrb, observability as observability_core, obsv,
};
use crate::discretize::{Hold, discretize as discretize_core};
use crate::error::{Error, check_square};
use crate::expm::{expm_into, pade_choice, transition_matrices_into};
use crate::freq::{check_state_space, frequency_response_into};
use crate::lyapunov::solve_lyapunov as solve_lyapunov_core;
use crate::modes::{charpoly as charpoly_core, modal_analysis as modal_analysis_core};
use crate::norm::one_norm;
use crate::place::{
    ILL_CONDITIONED_CONTROLLABILITY, POLE_ERROR_WARNING, companion_form as companion_form_core,
    place as place_core, place_ackermann, place_bass_gura,
};
use crate::reorder::reorder_schur;
use crate::response::{
    Input, Model, simulate_into, simulate_models_into, steady_state as steady_state_core,
    uniform_grid_step,
};
use crate::riccati_ode::riccati_ode as riccati_ode_core;
use crate::schur::{quasi_triangular_eigenvalues, real_schur};
use faer::{Mat, MatMut, MatRef, c64};
use numpy::npyffi::{PY_ARRAY_API, npy_intp};
use numpy::{
    Element, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyComplex, PyDict, PyFloat, PyString, PyType};
use std::ffi::CString;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// The exception class of `aerocontrol.exceptions` that an error maps to.
fn exception_class_name(error: &Error) -> &'static str {
    match error {
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
        Error::InBatch { source, .. } => exception_class_name(source),
    }
}

static EXCEPTIONS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
static REAL_ARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
/// `aerocontrol.placement._poles`, for requested poles that are not a complex vector.
static POLES: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

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

/// 2^53 = 1/u: at ||tA|| beyond it the exponential's relative condition number (at least
/// ||tA||_2) times u exceeds 1, so the rounding of the input alone can change every digit.
const ILL_CONDITIONED_NORM: f64 = 9_007_199_254_740_992.0;

/// Warns when ||A||_1 max|t| makes e^{At} meaningless in double precision.
fn warn_if_ill_conditioned(py: Python<'_>, a_norm: f64, t_max: f64) -> PyResult<()> {
    let scaled = a_norm * t_max;
    if scaled >= ILL_CONDITIONED_NORM {
        let message = format!(
            "||tA||_1 = {scaled:.3e} exceeds 1/u = 2^53: the exponential's relative condition \
             number is at least ||tA||_2, so the rounding of the input alone can change every \
             digit of the result"
        );
        warn(py, "IllConditionedWarning", &message)?;
    }
    Ok(())
}

/// Warns if any entry of a result is not finite.
fn warn_on_overflow(py: Python<'_>, values: &[f64]) -> PyResult<()> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        warn(py, "NumericalOverflowWarning", OVERFLOW_MESSAGE)
    }
}

/// Runs `f`, turning a panic that escaped the core into a Python exception (MemoryError for a
/// failed allocation, RuntimeError otherwise) instead of unwinding into the interpreter.
fn guarded<T>(f: impl FnOnce() -> T) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        if message.to_lowercase().contains("alloc") {
            PyMemoryError::new_err(format!("not enough memory: {message}"))
        } else {
            PyRuntimeError::new_err(format!("internal error in aerocontrol: {message}"))
        }
    })
}

/// The number of entries of an array of this shape, or MemoryError if it cannot be addressed.
fn entries(shape: &[usize]) -> PyResult<usize> {
    shape
        .iter()
        .try_fold(1usize, |total, &d| total.checked_mul(d))
        .filter(|&total| total <= isize::MAX as usize / std::mem::size_of::<f64>())
        .ok_or_else(|| {
            PyMemoryError::new_err(format!(
                "an array of shape {shape:?} is too large to allocate"
            ))
        })
}

/// `values` copied into a new vector, or MemoryError.
fn copy_values(values: impl ExactSizeIterator<Item = f64>) -> PyResult<Vec<f64>> {
    let mut out = Vec::new();
    out.try_reserve_exact(values.len()).map_err(|_| {
        PyMemoryError::new_err(format!("not enough memory to copy {} values", values.len()))
    })?;
    out.extend(values);
    Ok(out)
}

/// Whether numpy may hand this array's memory to Rust as f64: aligned data and strides.
fn is_aligned(array: &Bound<'_, PyArrayDyn<f64>>) -> bool {
    let align = std::mem::align_of::<f64>();
    (array.data() as usize).is_multiple_of(align)
        && array
            .strides()
            .iter()
            .all(|s| s.unsigned_abs().is_multiple_of(align))
}

/// The argument as an aligned float64 numpy array: such an array passes through (a C-level
/// type check); anything else goes through `aerocontrol._validation.real_array`, which converts
/// array-likes (copying misaligned ones) and raises NotRealError naming the argument for complex
/// or non-numeric input.
fn float_array<'py>(
    py: Python<'py>,
    value: &Bound<'py, PyAny>,
    arg: &'static str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(array) = value.cast::<PyArrayDyn<f64>>()
        && is_aligned(array)
    {
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

/// A faer view of a 2-D aligned float64 array (any strides, including negative ones).
///
/// The view is valid while the GIL is held and the array alive: no Python code runs meanwhile,
/// and this module never takes a mutable borrow of an argument. (rust-numpy's dynamic borrow
/// tracking would cost a global lock and a table lookup per call for no protection beyond
/// that.) Work that releases the GIL copies the view first ([`run_on`]).
fn matrix_view<'a>(
    array: &'a Bound<'_, PyArrayDyn<f64>>,
    arg: &'static str,
) -> Result<MatRef<'a, f64>, Error> {
    // Shape and byte strides straight from the array object: an ndarray view of a dynamic-rank
    // array would cost more than a 4-state solve's arithmetic to build.
    const SIZE: isize = std::mem::size_of::<f64>() as isize;
    match (array.shape(), array.strides()) {
        (&[rows, cols], &[row_stride, col_stride]) => {
            // SAFETY: the array is aligned (`float_array`: data and strides multiples of 8
            // bytes), the GIL is held, and the view does not outlive `array` (see the function
            // documentation); pointer, shape and element strides describe its own memory.
            Ok(unsafe {
                MatRef::from_raw_parts(
                    array.data().cast_const(),
                    rows,
                    cols,
                    row_stride / SIZE,
                    col_stride / SIZE,
                )
            })
        }
        (shape, _) => Err(shape_error(arg, "a 2-D matrix", shape)),
    }
}

/// The input of a single-input function: a 2-D matrix as [`matrix_view`], or a 1-D vector
/// b as the n x 1 column.
fn input_column_view<'a>(
    array: &'a Bound<'_, PyArrayDyn<f64>>,
    arg: &'static str,
) -> Result<MatRef<'a, f64>, Error> {
    const SIZE: isize = std::mem::size_of::<f64>() as isize;
    match (array.shape(), array.strides()) {
        // SAFETY: as in `matrix_view`, for one column of `len` entries.
        (&[len], &[stride]) => Ok(unsafe {
            MatRef::from_raw_parts(array.data().cast_const(), len, 1, stride / SIZE, 0)
        }),
        _ => matrix_view(array, arg),
    }
}

/// A new zero-filled C-ordered array (float64 or complex128), or MemoryError.
fn new_array<'py, T: Element>(
    py: Python<'py>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    entries(shape)?;
    let mut dims: Vec<npy_intp> = shape.iter().map(|&d| d as npy_intp).collect();
    let descriptor = T::get_dtype(py).into_dtype_ptr();
    // SAFETY: numpy's PyArray_Zeros with a valid shape and a new reference to the element's
    // descriptor (which it steals); a null result is a raised Python exception.
    let pointer = unsafe {
        PY_ARRAY_API.PyArray_Zeros(py, dims.len() as i32, dims.as_mut_ptr(), descriptor, 0)
    };
    if pointer.is_null() {
        return Err(PyErr::fetch(py));
    }
    // SAFETY: a new, owned ndarray of element type T.
    Ok(unsafe {
        Bound::from_owned_ptr(py, pointer)
            .cast_into_unchecked::<PyUntypedArray>()
            .cast_into_unchecked::<PyArrayDyn<T>>()
    })
}

/// The data of an array created by [`new_array`] and not yet handed to Python.
///
/// # Safety
/// No other reference to the array's data may exist while the slice lives. (The same contract
/// as rust-numpy's `PyArray::as_slice_mut`: the array object is shared, its data is not.)
#[allow(clippy::mut_from_ref)]
unsafe fn new_array_data<'a, T: Element>(array: &'a Bound<'_, PyArrayDyn<T>>) -> &'a mut [T] {
    // SAFETY: a new array is C-contiguous and aligned, holding `len` float64 values; exclusive
    // access is the caller's promise.
    unsafe { std::slice::from_raw_parts_mut(array.data(), array.len()) }
}

/// A new C-ordered numpy array holding `m`.
fn matrix_to_numpy<'py>(py: Python<'py>, m: &Mat<f64>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let array = new_array(py, &[m.nrows(), m.ncols()])?;
    // SAFETY: the array was just created and is not yet visible to Python.
    let data = unsafe { new_array_data(&array) };
    MatMut::from_row_major_slice_mut(data, m.nrows(), m.ncols()).copy_from(m);
    Ok(array)
}

/// Work (in multiply-adds) below which releasing and re-acquiring the GIL costs more than it
/// lets other threads gain: about a 12 x 12 exponential.
const DETACH_MIN_WORK: usize = 2_000;

/// Runs `f(a)` guarded: on the view itself when the work is small (GIL held), else on a copy
/// with the GIL released.
fn run_on<T: Send>(
    py: Python<'_>,
    a: MatRef<'_, f64>,
    work: usize,
    f: impl FnOnce(MatRef<'_, f64>) -> T + Send,
) -> PyResult<T> {
    if work < DETACH_MIN_WORK {
        guarded(|| f(a))
    } else {
        entries(&[a.nrows(), a.ncols()])?;
        let copy = guarded(|| a.to_owned())?;
        py.detach(|| guarded(|| f(copy.as_ref())))
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
            let out = new_array(py, &[n, n])?;
            // SAFETY: `out` is new and not visible to Python until returned.
            let data = unsafe { new_array_data(&out) };
            run_on(py, view, n.saturating_pow(3), |a| {
                expm_into(a, MatMut::from_row_major_slice_mut(data, n, n))
            })?
            .map_err(|e| to_py_err(py, e))?;
            // SAFETY: as above; the mutable slice is no longer used.
            warn_on_overflow(py, unsafe { new_array_data(&out) })?;
            warn_if_ill_conditioned(py, one_norm(view), 1.0)?;
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
            // The stack is copied before the GIL is released, so that no Python thread can
            // write to what the computation reads.
            entries(&shape)?;
            let readonly = a.readonly();
            let data = match readonly.as_slice() {
                Ok(contiguous) => copy_values(contiguous.iter().copied())?,
                Err(_) => copy_values(readonly.as_array().iter().copied())?,
            };
            let out = new_array(py, &shape)?;
            // SAFETY: `out` is new and not visible to Python until returned.
            let out_data = unsafe { new_array_data(&out) };
            let stack = MatrixStack::new(&data, count, rows, cols).map_err(|e| to_py_err(py, e))?;
            py.detach(|| guarded(|| expm_batch(stack, out_data)))?
                .map_err(|e| to_py_err(py, e))?;
            let size = rows * rows;
            // SAFETY: as above.
            let values = unsafe { new_array_data(&out) };
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
            let mut column_sums = vec![0.0; rows];
            let largest_norm = data
                .chunks_exact(size.max(1))
                .map(|matrix| {
                    column_sums.fill(0.0);
                    for row in matrix.chunks_exact(rows.max(1)) {
                        for (sum, value) in column_sums.iter_mut().zip(row) {
                            *sum += value.abs();
                        }
                    }
                    column_sums.iter().copied().fold(0.0, f64::max)
                })
                .fold(0.0, f64::max);
            warn_if_ill_conditioned(py, largest_norm, 1.0)?;
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
    check_square(view, "A").map_err(|e| to_py_err(py, e))?;
    if t.ndim() != 1 {
        return Err(to_py_err(py, shape_error("t", "a 1-D array", t.shape())));
    }
    let times = copy_values(t.readonly().as_array().iter().copied())?;
    let n = view.nrows();
    let out = new_array(py, &[times.len(), n, n])?;
    // SAFETY: `out` is new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    let work = n.saturating_pow(3).saturating_mul(times.len());
    run_on(py, view, work, |a| {
        transition_matrices_into(a, &times, data)
    })?
    .map_err(|e| to_py_err(py, e))?;
    // SAFETY: as above; the mutable slice is no longer used.
    warn_on_overflow(py, unsafe { new_array_data(&out) })?;
    let t_max = times.iter().fold(0.0, |m: f64, t| m.max(t.abs()));
    warn_if_ill_conditioned(py, one_norm(view), t_max)?;
    Ok(out)
}

type Discretized<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Option<Bound<'py, PyArrayDyn<f64>>>,
);

/// The input hold named by the `method` argument: "zoh" (zero order) or "foh" (first order).
fn hold_from_method(py: Python<'_>, method: &str) -> PyResult<Hold> {
    match method {
        "zoh" => Ok(Hold::Zero),
        "foh" => Ok(Hold::First),
        other => Err(raise(
            py,
            "InvalidArgumentError",
            format!("method must be \"zoh\" or \"foh\", got {other:?}"),
        )),
    }
}

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
    let hold = hold_from_method(py, method)?;
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, "B")?);
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let b = matrix_view(&b, "B").map_err(|e| to_py_err(py, e))?;
    let size = a.nrows().saturating_add(b.ncols().saturating_mul(2));
    entries(&[size, size])?;
    let result = if size.saturating_pow(3) < DETACH_MIN_WORK {
        guarded(|| discretize_core(a, b, dt, hold))?
    } else {
        let (a, b) = guarded(|| (a.to_owned(), b.to_owned()))?;
        py.detach(|| guarded(|| discretize_core(a.as_ref(), b.as_ref(), dt, hold)))?
    }
    .map_err(|e| to_py_err(py, e))?;
    let gamma1 = result.gamma1.as_ref();
    let finite =
        |m: &Mat<f64>| (0..m.ncols()).all(|j| m.col_as_slice(j).iter().all(|v| v.is_finite()));
    if !finite(&result.phi) || !finite(&result.gamma0) || !gamma1.is_none_or(finite) {
        warn(py, "NumericalOverflowWarning", OVERFLOW_MESSAGE)?;
    }
    Ok((
        matrix_to_numpy(py, &result.phi)?,
        matrix_to_numpy(py, &result.gamma0)?,
        gamma1.map(|g| matrix_to_numpy(py, g)).transpose()?,
    ))
}

/// The Padé degree m and the number of squarings s that the exponential of A uses: a
/// diagnostic for tests and for users comparing algorithms.
#[pyfunction]
#[pyo3(signature = (a, /))]
fn expm_pade_choice(py: Python<'_>, a: &Bound<'_, PyAny>) -> PyResult<(usize, u32)> {
    let a = float_array(py, a, "A")?;
    let view = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    check_square(view, "A").map_err(|e| to_py_err(py, e))?;
    entries(&[view.nrows(), view.nrows()])?;
    guarded(|| pade_choice(view))?.map_err(|e| to_py_err(py, e))
}

/// The four matrices of a state-space model as aligned float64 arrays.
type ModelArrays<'py> = [Bound<'py, PyArrayDyn<f64>>; 4];

fn model_arrays<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
) -> PyResult<ModelArrays<'py>> {
    Ok([
        float_array(py, a, "A")?,
        float_array(py, b, "B")?,
        float_array(py, c, "C")?,
        float_array(py, d, "D")?,
    ])
}

fn model_views<'a>(arrays: &'a ModelArrays<'_>) -> Result<Model<'a>, Error> {
    let model = Model {
        a: matrix_view(&arrays[0], "A")?,
        b: matrix_view(&arrays[1], "B")?,
        c: matrix_view(&arrays[2], "C")?,
        d: matrix_view(&arrays[3], "D")?,
    };
    check_state_space(model.a, model.b, model.c, model.d)?;
    Ok(model)
}

/// Checks the shapes and values of A, B, C, D of a state-space model, naming the matrix at
/// fault.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, /))]
fn check_model(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    c: &Bound<'_, PyAny>,
    d: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let arrays = model_arrays(py, a, b, c, d)?;
    model_views(&arrays).map_err(|e| to_py_err(py, e))?;
    Ok(())
}

/// The step of a uniform time grid that starts at 0 (an error names `T` otherwise).
#[pyfunction]
#[pyo3(signature = (t, /))]
fn grid_step(py: Python<'_>, t: &Bound<'_, PyAny>) -> PyResult<f64> {
    let t = float_array(py, t, "T")?;
    if t.ndim() != 1 {
        return Err(to_py_err(
            py,
            shape_error("T", "a 1-D array of times", t.shape()),
        ));
    }
    let times = copy_values(t.readonly().as_array().iter().copied())?;
    uniform_grid_step(&times, "T").map_err(|e| to_py_err(py, e))
}

type SimulationOutput<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

/// States (r, steps, n) and outputs (r, steps, p) of r responses from the initial states
/// x0 (r, n): free (u and eta0 None), a constant input eta0 (m), or sampled inputs u
/// (r, steps, m) with a zero- or first-order hold.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, x0, u, eta0, dt, steps, method, /))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    x0: &Bound<'py, PyAny>,
    u: Option<&Bound<'py, PyAny>>,
    eta0: Option<&Bound<'py, PyAny>>,
    dt: f64,
    steps: usize,
    method: &str,
) -> PyResult<SimulationOutput<'py>> {
    let hold = hold_from_method(py, method)?;
    let arrays = model_arrays(py, a, b, c, d)?;
    let model = model_views(&arrays).map_err(|e| to_py_err(py, e))?;
    let (n, p) = (model.a.nrows(), model.c.nrows());
    let x0 = float_array(py, x0, "x0")?;
    if x0.ndim() != 2 || x0.shape()[1] != n {
        let error = Error::WrongDimensions {
            arg: "x0",
            expected: "one initial state per response, of the order of A",
            shape: x0.shape().to_vec(),
        };
        return Err(to_py_err(py, error));
    }
    let responses = x0.shape()[0];
    let x0 = copy_values(x0.readonly().as_array().iter().copied())?;
    let u = u.map(|u| float_array(py, u, "u")).transpose()?;
    let eta0 = eta0.map(|e| float_array(py, e, "eta0")).transpose()?;
    let u_values = u
        .map(|u| copy_values(u.readonly().as_array().iter().copied()))
        .transpose()?;
    let eta_values = eta0
        .map(|e| copy_values(e.readonly().as_array().iter().copied()))
        .transpose()?;
    let input = match (&u_values, &eta_values) {
        (Some(u), _) => Input::Sampled(u),
        (None, Some(eta)) => Input::Constant(eta),
        (None, None) => Input::Free,
    };
    let x = new_array::<f64>(py, &[responses, steps, n])?;
    let y = new_array::<f64>(py, &[responses, steps, p])?;
    // SAFETY: both arrays are new and not visible to Python until returned.
    let (x_data, y_data) = unsafe { (new_array_data(&x), new_array_data(&y)) };
    let work = responses
        .saturating_mul(steps)
        .saturating_mul(n * n + n * p);
    let x0 = &x0;
    let mut run =
        move |model: Model<'_>| simulate_into(model, x0, input, dt, steps, hold, x_data, y_data);
    if work < DETACH_MIN_WORK * 100 {
        guarded(move || run(model))?
    } else {
        let owned: Vec<Mat<f64>> = guarded(|| {
            [model.a, model.b, model.c, model.d]
                .map(|m| m.to_owned())
                .into()
        })?;
        py.detach(move || {
            guarded(move || {
                run(Model {
                    a: owned[0].as_ref(),
                    b: owned[1].as_ref(),
                    c: owned[2].as_ref(),
                    d: owned[3].as_ref(),
                })
            })
        })?
    }
    .map_err(|e| to_py_err(py, e))?;
    Ok((x, y))
}

/// A 3-D float64 array copied into a contiguous stack, with its shape.
fn stack_values(
    py: Python<'_>,
    value: &Bound<'_, PyAny>,
    arg: &'static str,
) -> PyResult<(Vec<f64>, [usize; 3])> {
    let array = float_array(py, value, arg)?;
    match *array.shape() {
        [count, rows, cols] => {
            let readonly = array.readonly();
            let values = copy_values(readonly.as_array().iter().copied())?;
            Ok((values, [count, rows, cols]))
        }
        _ => Err(to_py_err(
            py,
            shape_error(arg, "a 3-D stack of matrices", array.shape()),
        )),
    }
}

/// All values of an array argument, copied in C order.
fn all_values(py: Python<'_>, value: &Bound<'_, PyAny>, arg: &'static str) -> PyResult<Vec<f64>> {
    let array = float_array(py, value, arg)?;
    let readonly = array.readonly();
    copy_values(readonly.as_array().iter().copied())
}

/// One response of each model of a stack: A (q, n, n), B (q, n, m), C (q, p, n), D (q, p, m),
/// initial states x0 (q, n), and a free response, a constant input eta0 (q, m) or sampled
/// inputs u (q, steps, m). Returns states (q, steps, n) and outputs (q, steps, p).
#[pyfunction]
#[pyo3(signature = (a, b, c, d, x0, u, eta0, dt, steps, method, /))]
#[allow(clippy::too_many_arguments)]
fn simulate_models<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    x0: &Bound<'py, PyAny>,
    u: Option<&Bound<'py, PyAny>>,
    eta0: Option<&Bound<'py, PyAny>>,
    dt: f64,
    steps: usize,
    method: &str,
) -> PyResult<SimulationOutput<'py>> {
    let hold = hold_from_method(py, method)?;
    let (a, [q, n, na]) = stack_values(py, a, "A")?;
    let (b, [qb, nb, m]) = stack_values(py, b, "B")?;
    let (c, [qc, p, nc]) = stack_values(py, c, "C")?;
    let (d, [qd, pd, md]) = stack_values(py, d, "D")?;
    if let Some(&got) = [qb, qc, qd].iter().find(|&&count| count != q) {
        let error = Error::Mismatch {
            arg: "B, C and D",
            what: "as many models as",
            expected: q,
            other: "A",
            got,
        };
        return Err(to_py_err(py, error));
    }
    fn stack(values: &[f64], q: usize, rows: usize, cols: usize) -> Result<MatrixStack<'_>, Error> {
        MatrixStack::new(values, q, rows, cols)
    }
    let stacks = (|| {
        Ok::<_, Error>((
            stack(&a, q, n, na)?,
            stack(&b, q, nb, m)?,
            stack(&c, q, p, nc)?,
            stack(&d, q, pd, md)?,
        ))
    })();
    let (a_stack, b_stack, c_stack, d_stack) = stacks.map_err(|e| to_py_err(py, e))?;
    let models: Vec<Model<'_>> = (0..q)
        .map(|i| Model {
            a: a_stack.get(i),
            b: b_stack.get(i),
            c: c_stack.get(i),
            d: d_stack.get(i),
        })
        .collect();
    let x0 = all_values(py, x0, "x0")?;
    let u = u.map(|u| all_values(py, u, "u")).transpose()?;
    let eta = eta0.map(|e| all_values(py, e, "eta0")).transpose()?;
    let input = match (&u, &eta) {
        (Some(u), _) => Input::Sampled(u),
        (None, Some(eta)) => Input::Constant(eta),
        (None, None) => Input::Free,
    };
    let x = new_array::<f64>(py, &[q, steps, n])?;
    let y = new_array::<f64>(py, &[q, steps, p])?;
    // SAFETY: both arrays are new and not visible to Python until returned.
    let (x_data, y_data) = unsafe { (new_array_data(&x), new_array_data(&y)) };
    py.detach(|| {
        guarded(|| simulate_models_into(&models, &x0, input, dt, steps, hold, x_data, y_data))
    })?
    .map_err(|e| to_py_err(py, e))?;
    Ok((x, y))
}

/// -A^-1 B eta0, the steady state of a step (6.45).
#[pyfunction]
#[pyo3(signature = (a, b, eta0, /))]
fn steady_state<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    eta0: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let (a, b, eta0) = (
        float_array(py, a, "A")?,
        float_array(py, b, "B")?,
        float_array(py, eta0, "eta0")?,
    );
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let b = matrix_view(&b, "B").map_err(|e| to_py_err(py, e))?;
    let eta = copy_values(eta0.readonly().as_array().iter().copied())?;
    let x = guarded(|| steady_state_core(a, b, &eta))?.map_err(|e| to_py_err(py, e))?;
    let out = new_array::<f64>(py, &[x.len()])?;
    // SAFETY: new and not visible to Python until returned.
    unsafe { new_array_data(&out) }.copy_from_slice(&x);
    Ok(out)
}

/// G(jω_k) = C (jω_k I - A)^-1 B + D, as a complex (len(omega), p, m) array.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, omega, /))]
fn frequency_response<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
    let arrays = model_arrays(py, a, b, c, d)?;
    let model = model_views(&arrays).map_err(|e| to_py_err(py, e))?;
    let omega = float_array(py, omega, "omega")?;
    if omega.ndim() != 1 {
        return Err(to_py_err(
            py,
            shape_error("omega", "a 1-D array of frequencies", omega.shape()),
        ));
    }
    let omega = copy_values(omega.readonly().as_array().iter().copied())?;
    let (p, m) = (model.c.nrows(), model.b.ncols());
    let out = new_array::<c64>(py, &[omega.len(), p, m])?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    let Model { a, b, c, d } = model;
    let (a, b, c, d) = guarded(|| (a.to_owned(), b.to_owned(), c.to_owned(), d.to_owned()))?;
    py.detach(|| {
        guarded(|| {
            frequency_response_into(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &omega, data)
        })
    })?
    .map_err(|e| to_py_err(py, e))?;
    Ok(out)
}

fn complex_matrix<'py>(py: Python<'py>, m: &Mat<c64>) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
    let out = new_array::<c64>(py, &[m.nrows(), m.ncols()])?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    for (i, row) in data.chunks_exact_mut(m.ncols().max(1)).enumerate() {
        for (j, value) in row.iter_mut().enumerate() {
            *value = m[(i, j)];
        }
    }
    Ok(out)
}

fn real_vector<'py>(py: Python<'py>, values: &[f64]) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let out = new_array::<f64>(py, &[values.len()])?;
    // SAFETY: new and not visible to Python until returned.
    unsafe { new_array_data(&out) }.copy_from_slice(values);
    Ok(out)
}

/// The modal analysis of A (and P^-1 B if B is given), as a dict of numpy arrays.
#[pyfunction]
#[pyo3(signature = (a, b, /))]
fn modal_analysis<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let a = float_array(py, a, "A")?;
    let b = b.map(|b| float_array(py, b, "B")).transpose()?;
    let a_view = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let b_view = b
        .as_ref()
        .map(|b| matrix_view(b, "B"))
        .transpose()
        .map_err(|e| to_py_err(py, e))?;
    let analysis =
        guarded(|| modal_analysis_core(a_view, b_view))?.map_err(|e| to_py_err(py, e))?;
    let result = PyDict::new(py);
    let eigenvalues = new_array::<c64>(py, &[analysis.eigenvalues.len()])?;
    // SAFETY: new and not visible to Python until returned.
    unsafe { new_array_data(&eigenvalues) }.copy_from_slice(&analysis.eigenvalues);
    result.set_item("eigenvalues", eigenvalues)?;
    let modes = &analysis.modes;
    let column = |f: fn(&crate::modes::Mode) -> f64| -> Vec<f64> { modes.iter().map(f).collect() };
    let mode_eigenvalues = new_array::<c64>(py, &[modes.len()])?;
    // SAFETY: as above.
    let data = unsafe { new_array_data(&mode_eigenvalues) };
    for (value, mode) in data.iter_mut().zip(modes) {
        *value = mode.eigenvalue;
    }
    result.set_item("mode_eigenvalue", mode_eigenvalues)?;
    result.set_item(
        "oscillatory",
        modes.iter().map(|m| m.oscillatory).collect::<Vec<bool>>(),
    )?;
    result.set_item(
        "mode_indices",
        modes
            .iter()
            .map(|m| (m.indices[0], m.indices[1]))
            .collect::<Vec<_>>(),
    )?;
    for (name, f) in [
        (
            "natural_frequency",
            (|m| m.natural_frequency) as fn(&crate::modes::Mode) -> f64,
        ),
        ("damping_ratio", |m| m.damping_ratio),
        ("damped_frequency", |m| m.damped_frequency),
        ("period", |m| m.period),
        ("time_to_half", |m| m.time_to_half),
        ("time_to_double", |m| m.time_to_double),
        ("cycles_to_half", |m| m.cycles_to_half),
        ("time_constant", |m| m.time_constant),
    ] {
        result.set_item(name, real_vector(py, &column(f))?)?;
    }
    result.set_item("modal_matrix", complex_matrix(py, &analysis.modal_matrix)?)?;
    result.set_item("modal_matrix_condition", analysis.modal_matrix_condition)?;
    result.set_item(
        "modal_matrix_is_singular",
        analysis.modal_matrix_is_singular(),
    )?;
    let modal_input = analysis
        .modal_input
        .as_ref()
        .map(|m| complex_matrix(py, m))
        .transpose()?;
    result.set_item("modal_input", modal_input)?;
    result.set_item(
        "characteristic_polynomial",
        real_vector(py, &analysis.characteristic_polynomial)?,
    )?;
    Ok(result)
}

/// Two matrix views of one call, or the error naming the first bad one.
fn two_views<'a>(
    py: Python<'_>,
    first: (&'a Bound<'_, PyArrayDyn<f64>>, &'static str),
    second: (&'a Bound<'_, PyArrayDyn<f64>>, &'static str),
) -> PyResult<(MatRef<'a, f64>, MatRef<'a, f64>)> {
    let a = matrix_view(first.0, first.1).map_err(|e| to_py_err(py, e))?;
    let b = matrix_view(second.0, second.1).map_err(|e| to_py_err(py, e))?;
    Ok((a, b))
}

/// The controllability matrix [B AB ... A^{n-1}B] (6.74), or with `dual` the observability
/// matrix [C; CA; ...] (6.89) of (A, C).
#[pyfunction]
#[pyo3(signature = (a, b, dual, /))]
fn krylov_matrix<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    dual: bool,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let second_name = if dual { "C" } else { "B" };
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, second_name)?);
    let (a, b) = two_views(py, (&a, "A"), (&b, second_name))?;
    let matrix =
        guarded(|| if dual { obsv(a, b) } else { ctrb(a, b) })?.map_err(|e| to_py_err(py, e))?;
    matrix_to_numpy(py, &matrix)
}

fn complex_vector<'py>(py: Python<'py>, values: &[c64]) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
    let out = new_array::<c64>(py, &[values.len()])?;
    // SAFETY: new and not visible to Python until returned.
    unsafe { new_array_data(&out) }.copy_from_slice(values);
    Ok(out)
}

/// The controllability of (A, B) (or with `dual` the observability of (A, C)) as a dict.
#[pyfunction]
#[pyo3(signature = (a, b, tol, modal_test, with_transformation, dual, /))]
fn controllability<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    tol: Option<f64>,
    modal_test: bool,
    with_transformation: bool,
    dual: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let second_name = if dual { "C" } else { "B" };
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, second_name)?);
    let (a, b) = two_views(py, (&a, "A"), (&b, second_name))?;
    let analysis = guarded(|| {
        if dual {
            observability_core(a, b, tol, modal_test, with_transformation)
        } else {
            controllability_core(a, b, tol, modal_test, with_transformation)
        }
    })?
    .map_err(|e| to_py_err(py, e))?;
    let result = PyDict::new(py);
    let staircase = &analysis.staircase;
    result.set_item("a", matrix_to_numpy(py, &staircase.a)?)?;
    result.set_item("b", matrix_to_numpy(py, &staircase.b)?)?;
    result.set_item("z", matrix_to_numpy(py, &staircase.z)?)?;
    result.set_item("block_sizes", staircase.block_sizes.clone())?;
    result.set_item("controllable_order", staircase.controllable_order)?;
    result.set_item("smallest_pivot", staircase.smallest_pivot)?;
    result.set_item(
        "staircase_eigenvalues",
        complex_vector(py, &staircase.uncontrollable_eigenvalues)?,
    )?;
    result.set_item("eigenvalues", complex_vector(py, &analysis.eigenvalues)?)?;
    result.set_item("modal_measure", real_vector(py, &analysis.modal_measure)?)?;
    result.set_item(
        "uncontrollable_eigenvalues",
        complex_vector(py, &analysis.uncontrollable_eigenvalues)?,
    )?;
    result.set_item("tolerance", analysis.tolerance)?;
    Ok(result)
}

/// The coefficients [1, a_1, ..., a_n] of det(λI - A).
#[pyfunction]
#[pyo3(signature = (a, /))]
fn charpoly<'py>(py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = float_array(py, a, "A")?;
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let coefficients = guarded(|| charpoly_core(a))?.map_err(|e| to_py_err(py, e))?;
    real_vector(py, &coefficients)
}

/// The companion-form transformation (6.116)-(6.145) as a dict.
#[pyfunction]
#[pyo3(signature = (a, b, /))]
fn companion_form<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, "B")?);
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let b = input_column_view(&b, "B").map_err(|e| to_py_err(py, e))?;
    let form = guarded(|| companion_form_core(a, b))?.map_err(|e| to_py_err(py, e))?;
    let result = PyDict::new(py);
    result.set_item("V", matrix_to_numpy(py, &form.v)?)?;
    result.set_item("W", matrix_to_numpy(py, &form.w)?)?;
    result.set_item("T", matrix_to_numpy(py, &form.t)?)?;
    result.set_item("companion", matrix_to_numpy(py, &form.companion)?)?;
    result.set_item("coefficients", real_vector(py, &form.coefficients)?)?;
    Ok(result)
}

/// The placement algorithm named by `method`: "bass-gura", "ackermann" or "knv0".
fn placer_for(py: Python<'_>, method: &str) -> PyResult<Placer> {
    match method {
        "bass-gura" => Ok(place_bass_gura),
        "ackermann" => Ok(place_ackermann),
        "knv0" => Ok(place_core),
        other => Err(raise(
            py,
            "InvalidArgumentError",
            format!("unknown placement method {other:?}"),
        )),
    }
}

/// A state-feedback design η = -K x (6.91).
///
/// ``k`` is the gain vector of a single-input design (the chapter's k^T = K[0]).
// Built here rather than as a Python dataclass: filling a ten-field dataclass cost 0.4 µs, a
// sixth of a whole 4-state design called from Python, and this object costs a tenth of that.
#[pyclass(frozen, module = "aerocontrol", name = "Placement")]
struct PlacementResult {
    /// The gain matrix, m x n.
    #[pyo3(get, name = "K")]
    gain: Py<PyArrayDyn<f64>>,
    /// A - B K (6.93).
    #[pyo3(get)]
    closed_loop: Py<PyArrayDyn<f64>>,
    /// The requested poles, each conjugate pair adjacent with Im > 0 first.
    #[pyo3(get)]
    poles: Py<PyArrayDyn<c64>>,
    /// The eigenvalues of the computed A - B K, matched to ``poles``.
    #[pyo3(get)]
    achieved_poles: Py<PyArrayDyn<c64>>,
    /// max |achieved - requested| / |requested| (relative to ||A - BK||_F for a pole at 0).
    #[pyo3(get)]
    max_relative_error: f64,
    /// Sweeps of the robust method; 0 for the single-input formulas.
    #[pyo3(get)]
    iterations: usize,
    /// Whether the robust method met its tolerance (always True for the single-input
    /// formulas).
    #[pyo3(get)]
    converged: bool,
    /// The method's name.
    #[pyo3(get)]
    method: Py<PyString>,
    /// κ_1(V) for the single-input formulas, NaN for the robust method.
    #[pyo3(get)]
    controllability_condition: f64,
    /// κ_2(X) of the closed-loop eigenvectors for the robust method, NaN otherwise.
    #[pyo3(get)]
    eigenvector_condition: f64,
}

/// `aerocontrol.placement._describe`, the text of a design (`str`).
static DESCRIBE_PLACEMENT: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

#[pymethods]
impl PlacementResult {
    #[new]
    #[pyo3(signature = (K, closed_loop, poles, achieved_poles, max_relative_error, iterations,
        converged, method, controllability_condition, eigenvector_condition))]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        K: Py<PyArrayDyn<f64>>,
        closed_loop: Py<PyArrayDyn<f64>>,
        poles: Py<PyArrayDyn<c64>>,
        achieved_poles: Py<PyArrayDyn<c64>>,
        max_relative_error: f64,
        iterations: usize,
        converged: bool,
        method: Py<PyString>,
        controllability_condition: f64,
        eigenvector_condition: f64,
    ) -> PyResult<Self> {
        // The getters and `__str__` index these: shapes checked once, here.
        let (gain_shape, loop_shape) = (K.bind(py).shape(), closed_loop.bind(py).shape());
        let (requested, achieved) = (poles.bind(py).shape(), achieved_poles.bind(py).shape());
        let consistent = matches!(loop_shape, &[rows, cols] if rows == cols)
            && matches!(gain_shape, &[_, cols] if cols == loop_shape[0])
            && requested == [loop_shape[0]]
            && achieved == requested;
        if !consistent {
            return Err(raise(
                py,
                "ShapeError",
                format!(
                    "Placement needs K (m, n), closed_loop (n, n) and poles and \
                     achieved_poles (n,); got shapes {gain_shape:?}, {loop_shape:?}, \
                     {requested:?} and {achieved:?}"
                ),
            ));
        }
        Ok(Self {
            gain: K,
            closed_loop,
            poles,
            achieved_poles,
            max_relative_error,
            iterations,
            converged,
            method,
            controllability_condition,
            eigenvector_condition,
        })
    }

    /// The gain vector of a single-input design, shape (n,).
    #[getter]
    fn k<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let gain = self.gain.bind(py);
        let inputs = gain.shape()[0];
        if inputs != 1 {
            return Err(raise(
                py,
                "ShapeError",
                format!("k is defined for one input; this design has {inputs}"),
            ));
        }
        gain.get_item(0)
    }

    fn __str__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let py = slf.py();
        let describe = DESCRIBE_PLACEMENT.get_or_try_init(py, || {
            PyModule::import(py, "aerocontrol.placement")?
                .getattr("_describe")
                .map(Bound::unbind)
        })?;
        describe.bind(py).call1((slf,))?.extract()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let reprs = [
            self.gain.bind(py).repr()?,
            self.closed_loop.bind(py).repr()?,
            self.poles.bind(py).repr()?,
            self.achieved_poles.bind(py).repr()?,
            self.method.bind(py).repr()?,
            PyFloat::new(py, self.max_relative_error).repr()?,
            PyFloat::new(py, self.controllability_condition).repr()?,
            PyFloat::new(py, self.eigenvector_condition).repr()?,
        ];
        Ok(format!(
            "Placement(K={}, closed_loop={}, poles={}, achieved_poles={}, \
             max_relative_error={}, iterations={}, converged={}, method={}, \
             controllability_condition={}, eigenvector_condition={})",
            reprs[0],
            reprs[1],
            reprs[2],
            reprs[3],
            reprs[5],
            self.iterations,
            if self.converged { "True" } else { "False" },
            reprs[4],
            reprs[6],
            reprs[7],
        ))
    }

    /// Pickling: the constructor's arguments.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, PyType>,
        (
            Py<PyArrayDyn<f64>>,
            Py<PyArrayDyn<f64>>,
            Py<PyArrayDyn<c64>>,
            Py<PyArrayDyn<c64>>,
            f64,
            usize,
            bool,
            Py<PyString>,
            f64,
            f64,
        ),
    ) {
        let py = slf.py();
        let design = slf.get();
        (
            slf.get_type(),
            (
                design.gain.clone_ref(py),
                design.closed_loop.clone_ref(py),
                design.poles.clone_ref(py),
                design.achieved_poles.clone_ref(py),
                design.max_relative_error,
                design.iterations,
                design.converged,
                design.method.clone_ref(py),
                design.controllability_condition,
                design.eigenvector_condition,
            ),
        )
    }
}

/// Pole placement by `method` ("bass-gura", "ackermann" or "knv0"; the single-input ones
/// take b as a vector or an n x 1 matrix), as a `Placement`. Warns (IllConditionedWarning, at
/// the caller of the Python wrapper) when an achieved pole misses by more than
/// `POLE_ERROR_WARNING` relatively or κ(V) reaches `ILL_CONDITIONED_CONTROLLABILITY`.
#[pyfunction]
#[pyo3(signature = (a, b, poles, method, /))]
fn place<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    poles: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<Bound<'py, PlacementResult>> {
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, "B")?);
    let placer = placer_for(py, method)?;
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    // A single-input method takes b as a vector too.
    let b = if method == "knv0" {
        matrix_view(&b, "B")
    } else {
        input_column_view(&b, "B")
    }
    .map_err(|e| to_py_err(py, e))?;
    let requested = pole_values(py, poles)?;
    let design = guarded(|| placer(a, b, &requested))?.map_err(|e| to_py_err(py, e))?;
    let (name, measure) = match method {
        "bass-gura" => ("Bass-Gura", "controllability matrix"),
        "ackermann" => ("Ackermann", "controllability matrix"),
        _ => ("Kautsky-Nichols-Van Dooren", "closed-loop eigenvector"),
    };
    let (error, condition) = match method {
        "knv0" => (design.max_relative_error, design.eigenvector_condition),
        _ => (design.max_relative_error, design.controllability_condition),
    };
    if error > POLE_ERROR_WARNING
        || design.controllability_condition >= ILL_CONDITIONED_CONTROLLABILITY
    {
        let message = format!(
            "{name}: the achieved poles miss the requested ones by up to {error:.2e} relatively \
             ({measure} condition number {condition:.2e}); the gains may be inaccurate, and \
             poles that are repeated or close together are inherently sensitive (a k-fold pole \
             moves by about u^(1/k))"
        );
        warn(py, "IllConditionedWarning", &message)?;
    }
    Bound::new(
        py,
        PlacementResult {
            gain: matrix_to_numpy(py, &design.gain)?.unbind(),
            closed_loop: matrix_to_numpy(py, &design.closed_loop)?.unbind(),
            poles: complex_vector(py, &design.poles)?.unbind(),
            achieved_poles: complex_vector(py, &design.achieved_poles)?.unbind(),
            max_relative_error: design.max_relative_error,
            iterations: design.iterations,
            converged: design.converged,
            method: PyString::intern(py, name).unbind(),
            controllability_condition: design.controllability_condition,
            eigenvector_condition: design.eigenvector_condition,
        },
    )
}

/// The requested poles: a 1-D complex128 array as it is, anything else through
/// `aerocontrol.placement._poles` (its conversion and its errors).
fn pole_values(py: Python<'_>, poles: &Bound<'_, PyAny>) -> PyResult<Vec<c64>> {
    if let Ok(array) = poles.cast::<PyArrayDyn<c64>>()
        && array.ndim() == 1
    {
        return copy_complex(array);
    }
    let convert = POLES.get_or_try_init(py, || {
        PyModule::import(py, "aerocontrol.placement")?
            .getattr("_poles")
            .map(Bound::unbind)
    })?;
    copy_complex(
        convert
            .bind(py)
            .call1((poles,))?
            .cast::<PyArrayDyn<c64>>()?,
    )
}

/// Pole placement over a batch, in parallel with the GIL released: A (k or 1, n, n),
/// B (k or 1, n, m), poles (k or 1, n) complex, `method` as for `place`. Returns K (k, m, n),
/// the achieved poles (k, n), the largest relative pole errors (k,) and the condition numbers
/// (k,); an error names the lowest failing index.
#[pyfunction]
#[pyo3(signature = (a, b, poles, method, /))]
#[allow(clippy::type_complexity)]
fn place_batch<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    poles: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
)> {
    let placer = placer_for(py, method)?;
    let (a, [ka, n, na]) = stack_values(py, a, "A")?;
    let (b, [kb, nb, m]) = stack_values(py, b, "B")?;
    let requested = copy_complex(poles.cast::<PyArrayDyn<c64>>()?)?;
    let (a_stack, b_stack) = (|| {
        Ok::<_, Error>((
            MatrixStack::new(&a, ka, n, na)?,
            MatrixStack::new(&b, kb, nb, m)?,
        ))
    })()
    .map_err(|e| to_py_err(py, e))?;
    let rows = requested.len().checked_div(n).unwrap_or(0);
    let count =
        batch_count(&[("A", ka), ("B", kb), ("poles", rows)]).map_err(|e| to_py_err(py, e))?;
    entries(&[count, m.max(1), n])?;
    let gain = new_array::<f64>(py, &[count, m, n])?;
    let achieved = new_array::<c64>(py, &[count, n])?;
    let error = new_array::<f64>(py, &[count])?;
    let condition = new_array::<f64>(py, &[count])?;
    // SAFETY: the arrays are new and not visible to Python until returned.
    let out = unsafe {
        PlaceBatchOutput {
            gain: new_array_data(&gain),
            achieved: new_array_data(&achieved),
            max_relative_error: new_array_data(&error),
            condition: new_array_data(&condition),
        }
    };
    py.detach(|| guarded(|| place_batch_core(a_stack, b_stack, &requested, placer, out)))?
        .map_err(|e| to_py_err(py, e))?;
    Ok((gain, achieved, error, condition))
}

/// The real Schur form A = Z T Z^T, reordered when `select` (a callable on an eigenvalue,
/// called once per diagonal block) is given: (T, Z, eigenvalues, number selected).
#[pyfunction]
#[pyo3(signature = (a, select, /))]
#[allow(clippy::type_complexity)]
fn schur<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    select: Option<&Bound<'py, PyAny>>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    usize,
)> {
    let a = float_array(py, a, "A")?;
    let a = matrix_view(&a, "A").map_err(|e| to_py_err(py, e))?;
    let form = guarded(|| real_schur(a))?.map_err(|e| to_py_err(py, e))?;
    let Some(select) = select else {
        let values = quasi_triangular_eigenvalues(form.t.as_ref());
        let n = values.len();
        return Ok((
            matrix_to_numpy(py, &form.t)?,
            matrix_to_numpy(py, &form.z)?,
            complex_vector(py, &values)?,
            n,
        ));
    };
    // The first exception raised by `select` is kept and re-raised after the reordering.
    let mut failure: Option<PyErr> = None;
    let chooser = |lambda: c64| -> bool {
        if failure.is_some() {
            return false;
        }
        let value = PyComplex::from_doubles(py, lambda.re, lambda.im);
        match select.call1((value,)).and_then(|r| r.is_truthy()) {
            Ok(chosen) => chosen,
            Err(error) => {
                failure = Some(error);
                false
            }
        }
    };
    let ordered = guarded(|| reorder_schur(form, chooser))?;
    if let Some(error) = failure {
        return Err(error);
    }
    let ordered = ordered.map_err(|e| to_py_err(py, e))?;
    Ok((
        matrix_to_numpy(py, &ordered.t)?,
        matrix_to_numpy(py, &ordered.z)?,
        complex_vector(py, &ordered.eigenvalues)?,
        ordered.selected,
    ))
}

/// The solution X of A X + X A^T + Q = 0.
#[pyfunction]
#[pyo3(signature = (a, q, /))]
fn solve_lyapunov<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let (a, q) = (float_array(py, a, "A")?, float_array(py, q, "Q")?);
    let (a, q) = two_views(py, (&a, "A"), (&q, "Q"))?;
    let x = guarded(|| solve_lyapunov_core(a, q))?.map_err(|e| to_py_err(py, e))?;
    matrix_to_numpy(py, &x)
}

/// The stabilising solution of the CARE (6.228): (X, K, closed-loop eigenvalues, relative
/// residual, rcond(U11), Newton steps).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, s, e, refine, /))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn solve_care<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    s: Option<&Bound<'py, PyAny>>,
    e: Option<&Bound<'py, PyAny>>,
    refine: bool,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    f64,
    f64,
    usize,
)> {
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, "B")?);
    let (q, r) = (float_array(py, q, "Q")?, float_array(py, r, "R")?);
    let s = s.map(|s| float_array(py, s, "S")).transpose()?;
    let e = e.map(|e| float_array(py, e, "E")).transpose()?;
    let (a, b) = two_views(py, (&a, "A"), (&b, "B"))?;
    let (q, r) = two_views(py, (&q, "Q"), (&r, "R"))?;
    let options = CareOptions {
        s: optional_view(py, &s, "S")?,
        e: optional_view(py, &e, "E")?,
        refine,
    };
    let solution =
        guarded(|| solve_care_core(a, b, q, r, options))?.map_err(|e| to_py_err(py, e))?;
    Ok((
        matrix_to_numpy(py, &solution.x)?,
        matrix_to_numpy(py, &solution.gain)?,
        complex_vector(py, &solution.closed_loop_eigenvalues)?,
        solution.residual,
        solution.rcond,
        solution.refinement_steps,
    ))
}

/// The outputs of a batch of Riccati equations: X, K, closed-loop eigenvalues, residuals,
/// rcond(U11).
type CareBatchArrays<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
);

/// A batch of Riccati equations (6.199) solved in parallel with the GIL released: A, B, Q
/// and R are 3-D stacks of one matrix (shared by every problem) or k. Returns X (k, n, n),
/// K (k, m, n), the closed-loop eigenvalues (k, n), the relative residuals (k,) and
/// rcond(U11) (k,); an error names the lowest failing index.
#[pyfunction]
#[pyo3(signature = (a, b, q, r, refine, /))]
fn care_batch<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    refine: bool,
) -> PyResult<CareBatchArrays<'py>> {
    // Copied before the GIL is released, so that no Python thread can change what is read.
    let (a, [ka, n, na]) = stack_values(py, a, "A")?;
    let (b, [kb, nb, m]) = stack_values(py, b, "B")?;
    let (q, [kq, nq, mq]) = stack_values(py, q, "Q")?;
    let (r, [kr, nr, mr]) = stack_values(py, r, "R")?;
    let stacks = (|| {
        Ok::<_, Error>(CareStacks {
            a: MatrixStack::new(&a, ka, n, na)?,
            b: MatrixStack::new(&b, kb, nb, m)?,
            q: MatrixStack::new(&q, kq, nq, mq)?,
            r: MatrixStack::new(&r, kr, nr, mr)?,
        })
    })()
    .map_err(|e| to_py_err(py, e))?;
    let count = stacks.count().map_err(|e| to_py_err(py, e))?;
    entries(&[count, n.max(m), n])?;
    let x = new_array::<f64>(py, &[count, n, n])?;
    let gain = new_array::<f64>(py, &[count, m, n])?;
    let poles = new_array::<c64>(py, &[count, n])?;
    let residual = new_array::<f64>(py, &[count])?;
    let rcond = new_array::<f64>(py, &[count])?;
    // SAFETY: the arrays are new and not visible to Python until returned.
    let out = unsafe {
        CareBatchOutput {
            x: new_array_data(&x),
            gain: new_array_data(&gain),
            poles: new_array_data(&poles),
            residual: new_array_data(&residual),
            rcond: new_array_data(&rcond),
        }
    };
    py.detach(|| guarded(|| care_batch_core(stacks, refine, out)))?
        .map_err(|e| to_py_err(py, e))?;
    Ok((x, gain, poles, residual, rcond))
}

/// The Riccati differential equation (6.196) backward over the grid `t`: (S (k, n, n),
/// K (k, m, n), substeps).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, t, sf, /))]
#[allow(clippy::type_complexity)]
fn riccati_ode<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
    sf: Option<&Bound<'py, PyAny>>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    usize,
)> {
    let (a, b) = (float_array(py, a, "A")?, float_array(py, b, "B")?);
    let (q, r) = (float_array(py, q, "Q")?, float_array(py, r, "R")?);
    let sf = sf.map(|s| float_array(py, s, "Sf")).transpose()?;
    let times = all_values(py, t, "t")?;
    let (a, b) = two_views(py, (&a, "A"), (&b, "B"))?;
    let (q, r) = two_views(py, (&q, "Q"), (&r, "R"))?;
    let sf = optional_view(py, &sf, "Sf")?;
    let solution =
        guarded(|| riccati_ode_core(a, b, q, r, &times, sf))?.map_err(|e| to_py_err(py, e))?;
    Ok((
        matrices_to_numpy(py, &solution.s)?,
        matrices_to_numpy(py, &solution.gains)?,
        solution.substeps,
    ))
}

/// A new C-ordered (k, rows, cols) array holding equally shaped matrices.
fn matrices_to_numpy<'py>(
    py: Python<'py>,
    matrices: &[Mat<f64>],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let (rows, cols) = matrices.first().map_or((0, 0), |m| (m.nrows(), m.ncols()));
    let array = new_array(py, &[matrices.len(), rows, cols])?;
    // SAFETY: the array was just created and is not yet visible to Python.
    let data = unsafe { new_array_data(&array) };
    if rows * cols > 0 {
        for (chunk, m) in data.chunks_exact_mut(rows * cols).zip(matrices) {
            MatMut::from_row_major_slice_mut(chunk, rows, cols).copy_from(m);
        }
    }
    Ok(array)
}

/// A faer view of an optional matrix argument.
fn optional_view<'a>(
    py: Python<'_>,
    array: &'a Option<Bound<'_, PyArrayDyn<f64>>>,
    arg: &'static str,
) -> PyResult<Option<MatRef<'a, f64>>> {
    array
        .as_ref()
        .map(|array| matrix_view(array, arg).map_err(|e| to_py_err(py, e)))
        .transpose()
}

/// The values of a complex128 array, in C order.
fn copy_complex(array: &Bound<'_, PyArrayDyn<c64>>) -> PyResult<Vec<c64>> {
    // Read by byte offsets and unaligned loads (plain loads on x86-64): numpy allows strides
    // that are not multiples of the item size and misaligned data (a field of a structured
    // array, a buffer at an odd offset), which an element-strided view would misread. The
    // checked `readonly` borrow and ndarray view would also cost 0.1 µs, a twentieth of a
    // 4-state placement called from Python.
    let (shape, strides) = (array.shape(), array.strides());
    let count = entries(shape)?;
    entries(&[count, 2])?;
    let base = array.data().cast::<u8>().cast_const();
    let mut index = vec![0usize; shape.len()];
    let mut values = Vec::with_capacity(count);
    for _ in 0..count {
        let offset: isize = index
            .iter()
            .zip(strides)
            .map(|(&i, &s)| i as isize * s)
            .sum();
        // SAFETY: `index` stays within `shape`, so the offset addresses one of the array's own
        // elements; the read is unaligned-safe; the GIL is held throughout, so no Python code
        // writes the array meanwhile.
        values.push(unsafe { base.offset(offset).cast::<c64>().read_unaligned() });
        // The next index in C order.
        for axis in (0..shape.len()).rev() {
            index[axis] += 1;
            if index[axis] < shape[axis] {
                break;
            }
            index[axis] = 0;
        }
    }
    Ok(values)
}

/// The native core of aerocontrol; use the `aerocontrol` package, not this module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Every kernel whose size warrants threads gets its Par explicitly; faer's convenience
    // methods (small QR, LU and SVD in the placement code) follow the global setting, whose
    // default, rayon, costs more in dispatch than a 4 x 4 factorisation takes.
    faer::set_global_parallelism(faer::Par::Seq);
    m.add_function(wrap_pyfunction!(expm, m)?)?;
    m.add_function(wrap_pyfunction!(transition_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(discretize, m)?)?;
    m.add_function(wrap_pyfunction!(expm_pade_choice, m)?)?;
    m.add_function(wrap_pyfunction!(check_model, m)?)?;
    m.add_function(wrap_pyfunction!(grid_step, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_models, m)?)?;
    m.add_function(wrap_pyfunction!(steady_state, m)?)?;
    m.add_function(wrap_pyfunction!(frequency_response, m)?)?;
    m.add_function(wrap_pyfunction!(modal_analysis, m)?)?;
    m.add_function(wrap_pyfunction!(krylov_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(controllability, m)?)?;
    m.add_function(wrap_pyfunction!(charpoly, m)?)?;
    m.add_function(wrap_pyfunction!(companion_form, m)?)?;
    m.add_function(wrap_pyfunction!(place, m)?)?;
    m.add_class::<PlacementResult>()?;
    m.add_function(wrap_pyfunction!(schur, m)?)?;
    m.add_function(wrap_pyfunction!(solve_lyapunov, m)?)?;
    m.add_function(wrap_pyfunction!(solve_care, m)?)?;
    m.add_function(wrap_pyfunction!(care_batch, m)?)?;
    m.add_function(wrap_pyfunction!(place_batch, m)?)?;
    m.add_function(wrap_pyfunction!(riccati_ode, m)?)?;
    m.add("EXACT_NORM_MAX_ORDER", crate::expm::EXACT_NORM_MAX_ORDER)?;
    m.add("SMALL_MAX_ORDER", crate::expm::SMALL_MAX_ORDER)?;
    m.add("FMA_KERNELS", crate::dispatch::fma_available())?;
    m.add(
        "ILL_CONDITIONED_CONTROLLABILITY",
        crate::place::ILL_CONDITIONED_CONTROLLABILITY,
    )?;
    m.add("POLE_ERROR_WARNING", crate::place::POLE_ERROR_WARNING)?;
    Ok(())
}
