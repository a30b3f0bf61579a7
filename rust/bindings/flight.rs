//! Bindings of the flight-vehicle layer, for `aerocontrol.aircraft` (models from derivatives)
//! and `aerocontrol.handling` (mode quantities and MIL-F-8785C Levels).

use super::compute::{Cost, compute};
use super::conversion::{Real, copy_values, new_array, new_array_data};
use super::errors::to_py_err;
use crate::error::Error;
use crate::flight::Axis;
use crate::flight::levels::{self, Limits};
use crate::flight::model::{self, ParameterRows};
use crate::flight::modes;
use faer::c64;
use numpy::{PyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

fn axis_of(py: Python<'_>, axis: &str) -> PyResult<Axis> {
    match axis {
        "longitudinal" => Ok(Axis::Longitudinal),
        "lateral" => Ok(Axis::Lateral),
        _ => Err(to_py_err(
            py,
            Error::InvalidArgument {
                arg: "axis",
                message: format!("must be 'longitudinal' or 'lateral', got {axis:?}"),
            },
        )),
    }
}

/// The models of k variants of an aircraft (see `crate::flight::model`): the nominal
/// parameter row, the (k, s) sampled values of the parameters `columns`; returns the
/// dimensional derivatives (k, d), A (k, 4, 4) and B (k, 4, inputs), and the index of the
/// first sample without a model (singular or overflowing; None if every one has one), for the
/// caller to name.
#[pyfunction]
#[pyo3(signature = (axis, nominal, sampled, columns, /))]
fn aircraft_models<'py>(
    py: Python<'py>,
    axis: &str,
    nominal: Vec<f64>,
    sampled: &Bound<'py, PyAny>,
    columns: Vec<usize>,
) -> PyResult<Bound<'py, PyTuple>> {
    let axis = axis_of(py, axis)?;
    let sampled = Real::convert(py, sampled, "sampled")?;
    let count = match *sampled.shape() {
        [count, width] if width == columns.len() => count,
        _ => {
            return Err(to_py_err(
                py,
                Error::WrongDimensions {
                    arg: "sampled",
                    expected: "a 2-D array of one column per sampled parameter",
                    shape: sampled.shape().to_vec(),
                },
            ));
        }
    };
    let rows = ParameterRows::new(axis, &nominal, sampled.values(), &columns, count)
        .map_err(|e| to_py_err(py, e))?;
    let d = axis.dimensional().len();
    let m = axis.inputs();
    let dimensional = new_array::<f64>(py, &[count, d])?;
    let a = new_array::<f64>(py, &[count, 4, 4])?;
    let b = new_array::<f64>(py, &[count, 4, m])?;
    // SAFETY: the arrays are new and not visible to Python until returned.
    let (dimensional_data, a_data, b_data) = unsafe {
        (
            new_array_data(&dimensional),
            new_array_data(&a),
            new_array_data(&b),
        )
    };
    let cost = Cost::of(120.0, 0.0, 4).times(count);
    let first_missing = compute(py, cost, || {
        model::model_stack(axis, &rows, dimensional_data, a_data, b_data)
    })?;
    PyTuple::new(
        py,
        [
            dimensional.into_any(),
            a.into_any(),
            b.into_any(),
            first_missing.into_pyobject(py)?.into_any(),
        ],
    )
}

/// The classical modes of k 4-state models of `axis` from their eigenvalues (k, 4), and for
/// the lateral axis optionally their state matrices A (k, 4, 4) (see `crate::flight::modes`):
/// the named modes (k, slots) and which models are unresolved (k,).
#[pyfunction]
#[pyo3(signature = (axis, eigenvalues, a, /))]
fn classify_mode_stack<'py>(
    py: Python<'py>,
    axis: &str,
    eigenvalues: &Bound<'py, PyAny>,
    a: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let axis = axis_of(py, axis)?;
    let (count, values) = complex_rows(py, eigenvalues, "eigenvalues", 4)?;
    let a = Real::convert_optional(py, a, "A")?;
    if let Some(a) = &a
        && a.shape() != [count, 4, 4]
    {
        return Err(to_py_err(
            py,
            Error::WrongDimensions {
                arg: "A",
                expected: "(k, 4, 4), one state matrix per row of eigenvalues",
                shape: a.shape().to_vec(),
            },
        ));
    }
    let named = new_array::<c64>(py, &[count, axis.mode_slots()])?;
    let unresolved = new_array::<bool>(py, &[count])?;
    // SAFETY: the arrays are new and not visible to Python until returned.
    let (named_data, unresolved_data) =
        unsafe { (new_array_data(&named), new_array_data(&unresolved)) };
    let matrices = a.as_ref().map(Real::values);
    // With A, each model with two complex pairs takes the 16 cofactors of A - λI for each of
    // its two pairs.
    let flops = if matrices.is_some() { 3400.0 } else { 200.0 };
    compute(py, Cost::of(flops, 0.0, 4).times(count), || {
        modes::classify_stack(axis, &values, matrices, named_data, unresolved_data)
    })?;
    PyTuple::new(py, [named.into_any(), unresolved.into_any()])
}

/// The cost, in floating-point operations, of one pair's quantities and Level (the exact
/// scaling by 2^-e and back, four products, a square root and the comparisons), and of one
/// root's: for `compute` to release the GIL for a large stack and make it interruptible.
const PAIR_FLOPS: f64 = 60.0;
const ROOT_FLOPS: f64 = 4.0;

/// The rows of a complex128 argument `arg` of k rows of `width` numbers: shape (k, width), or
/// (k,) for a width of 1; its row count and values in C order.
fn complex_rows(
    py: Python<'_>,
    value: &Bound<'_, PyAny>,
    arg: &'static str,
    width: usize,
) -> PyResult<(usize, Vec<c64>)> {
    let array = value.cast::<PyArrayDyn<c64>>().map_err(|_| {
        to_py_err(
            py,
            Error::InvalidArgument {
                arg,
                message: "must be a complex128 array".to_string(),
            },
        )
    })?;
    let count = match (array.shape(), width) {
        ([count], 1) => *count,
        ([count, w], _) if *w == width && width > 1 => *count,
        (shape, _) => {
            return Err(to_py_err(
                py,
                Error::WrongDimensions {
                    arg,
                    expected: match width {
                        1 => "(k,)",
                        2 => "(k, 2)",
                        _ => "(k, 4)",
                    },
                    shape: shape.to_vec(),
                },
            ));
        }
    };
    Ok((count, copy_values(py, array)?))
}

/// A quantity of k aircraft's mode from its roots: `kind` "pair", (k, 3) of (ω_n, ζ, ζω_n) from
/// (k, 2) roots; "time constant" (τ_R) or "time to double" (T2), (k,) from (k,) roots.
#[pyfunction]
#[pyo3(signature = (kind, roots, /))]
fn mode_quantities<'py>(
    py: Python<'py>,
    kind: &str,
    roots: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let single: fn(f64) -> f64 = match kind {
        "pair" => {
            let (count, values) = complex_rows(py, roots, "roots", 2)?;
            let array = new_array::<f64>(py, &[count, 3])?;
            // SAFETY: the array is new and not visible to Python until returned.
            let data = unsafe { new_array_data(&array) };
            compute(py, Cost::of(PAIR_FLOPS, 0.0, 1).times(count), || {
                for (out, pair) in data.chunks_exact_mut(3).zip(values.chunks_exact(2)) {
                    let q = levels::pair(pair[0], pair[1]);
                    out.copy_from_slice(&[q.omega_n, q.zeta, q.zeta_omega]);
                }
                Ok(())
            })?;
            return Ok(array);
        }
        "time constant" => levels::roll_time_constant,
        "time to double" => levels::time_to_double,
        _ => {
            return Err(to_py_err(
                py,
                Error::InvalidArgument {
                    arg: "kind",
                    message: format!(
                        "must be 'pair', 'time constant' or 'time to double', got {kind:?}"
                    ),
                },
            ));
        }
    };
    let (count, values) = complex_rows(py, roots, "roots", 1)?;
    let array = new_array::<f64>(py, &[count])?;
    // SAFETY: the array is new and not visible to Python until returned.
    let data = unsafe { new_array_data(&array) };
    compute(py, Cost::of(ROOT_FLOPS, 0.0, 1).times(count), || {
        for (out, root) in data.iter_mut().zip(&values) {
            *out = single(root.re);
        }
        Ok(())
    })?;
    Ok(array)
}

/// The Levels (int8, (k,)) of k aircraft's `mode` from its roots and its limits (laid out as
/// `Limits::from_values` reads them).
#[pyfunction]
#[pyo3(signature = (mode, roots, limits, /))]
fn mode_levels<'py>(
    py: Python<'py>,
    mode: &str,
    roots: &Bound<'py, PyAny>,
    limits: Vec<f64>,
) -> PyResult<Bound<'py, PyArrayDyn<i8>>> {
    let limits = Limits::from_values(mode, &limits).map_err(|e| to_py_err(py, e))?;
    let (count, values) = complex_rows(py, roots, "roots", limits.roots())?;
    let array = new_array::<i8>(py, &[count])?;
    // SAFETY: the array is new and not visible to Python until returned.
    let out = unsafe { new_array_data(&array) };
    let cost = Cost::of(PAIR_FLOPS, 0.0, 1).times(count);
    compute(py, cost, || levels::levels(&limits, &values, out))?;
    Ok(array)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(aircraft_models, m)?)?;
    m.add_function(wrap_pyfunction!(classify_mode_stack, m)?)?;
    m.add_function(wrap_pyfunction!(mode_quantities, m)?)?;
    m.add_function(wrap_pyfunction!(mode_levels, m)?)?;
    for axis in [Axis::Longitudinal, Axis::Lateral] {
        let name = match axis {
            Axis::Longitudinal => "LONGITUDINAL",
            Axis::Lateral => "LATERAL",
        };
        m.add(format!("{name}_PARAMETERS"), axis.parameters().to_vec())?;
        m.add(format!("{name}_DIMENSIONAL"), axis.dimensional().to_vec())?;
    }
    Ok(())
}
