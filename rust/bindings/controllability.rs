//! Bindings of `aerocontrol.controllability`: controllability and observability matrices and
//! the staircase and modal verdicts.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real};
use super::errors::to_py_err;
use super::modal::eigen_cost;
use crate::control::controllability::{
    Controllability, controllability as controllability_core, ctrb, is_controllable, is_observable,
    observability as observability_core, obsv_transposed,
};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The converted (A, B), or (A, C) with `dual`.
fn pair(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    second: &Bound<'_, PyAny>,
    dual: bool,
) -> PyResult<(Real, Real)> {
    let second_name = if dual { "C" } else { "B" };
    Ok((
        Real::convert(py, a, "A")?,
        Real::convert(py, second, second_name)?,
    ))
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
    let (a, b) = pair(py, a, b, dual)?;
    let (a, b) = (|| Ok((a.matrix()?, b.matrix()?)))().map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    let width = if dual { b.nrows() } else { b.ncols() };
    let cost = Cost {
        flops: 2.0 * (n as f64).powi(3) * width as f64,
        bytes: 0.0,
        order: n.max(width),
    };
    let matrix = compute(py, cost, || {
        if dual {
            obsv_transposed(a, b)
        } else {
            ctrb(a, b)
        }
    })?;
    let matrix = if dual {
        matrix.transpose()
    } else {
        matrix.as_ref()
    };
    let mut outputs = Outputs::new(py);
    let name = if dual {
        "the observability matrix"
    } else {
        "the controllability matrix"
    };
    let out = outputs.matrix(name, matrix)?;
    outputs.finish()?;
    Ok(out)
}

/// The controllability of (A, B) (or with `dual` the observability of (A, C)) as a dict.
#[pyfunction]
#[pyo3(signature = (a, b, tol, modal_test, dual, /))]
fn controllability<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    tol: Option<f64>,
    modal_test: bool,
    dual: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let analysis = analyse(py, a, b, tol, modal_test, dual)?;
    let mut outputs = Outputs::new(py);
    let result = PyDict::new(py);
    let staircase = &analysis.staircase;
    result.set_item(
        "a",
        outputs.matrix("the staircase form", staircase.a.as_ref())?,
    )?;
    result.set_item(
        "b",
        outputs.matrix("the staircase form", staircase.b.as_ref())?,
    )?;
    result.set_item(
        "z",
        outputs.matrix("the transformation", staircase.z.as_ref())?,
    )?;
    result.set_item("block_sizes", staircase.block_sizes.clone())?;
    result.set_item("controllable_order", staircase.controllable_order)?;
    result.set_item("smallest_pivot", staircase.smallest_pivot)?;
    let complex = |outputs: &mut Outputs<'py>, values: &[faer::c64]| {
        outputs.complex("the eigenvalues", &[values.len()], values)
    };
    result.set_item(
        "staircase_eigenvalues",
        complex(&mut outputs, &staircase.uncontrollable_eigenvalues)?,
    )?;
    result.set_item("eigenvalues", complex(&mut outputs, &analysis.eigenvalues)?)?;
    let measure = &analysis.modal_measure;
    result.set_item(
        "modal_measure",
        outputs.real_as_is(&[measure.len()], measure)?,
    )?;
    result.set_item(
        "uncontrollable_eigenvalues",
        complex(&mut outputs, &analysis.uncontrollable_eigenvalues)?,
    )?;
    result.set_item("tolerance", analysis.tolerance)?;
    outputs.finish()?;
    Ok(result)
}

/// Whether (A, B) is controllable (with `dual`, (A, C) observable): the verdict of
/// [`controllability`] (no uncontrollable eigenvalue) without its form, transformation or
/// arrays, and without the modal test where the staircase already finds an uncontrollable
/// mode.
#[pyfunction]
#[pyo3(signature = (a, b, tol, modal_test, dual, /))]
fn controllability_verdict(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    tol: Option<f64>,
    modal_test: bool,
    dual: bool,
) -> PyResult<bool> {
    let (a, second) = pair(py, a, b, dual)?;
    let (a, second) = (|| Ok((a.matrix()?, second.matrix()?)))().map_err(|e| to_py_err(py, e))?;
    compute(
        py,
        verdict_cost(a.nrows(), second, modal_test, dual),
        || {
            if dual {
                is_observable(a, second, tol, modal_test)
            } else {
                is_controllable(a, second, tol, modal_test)
            }
        },
    )
}

/// The cost of the staircase of a pair of order n (`second` B, or C with `dual`), and of the
/// eigenvectors with the modal test.
fn verdict_cost(n: usize, second: faer::MatRef<'_, f64>, modal_test: bool, dual: bool) -> Cost {
    let width = if dual { second.nrows() } else { second.ncols() };
    let staircase = Cost::of(10.0 * (n as f64).powi(3), 6.0, n.max(width));
    if modal_test {
        staircase.then(eigen_cost(n))
    } else {
        staircase
    }
}

/// The core's analysis of the converted pair (the observability of (A, C) with `dual`), with
/// the staircase's transformation; the GIL released by the cost of the staircase, and of the
/// eigenvectors with the modal test.
fn analyse(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    second: &Bound<'_, PyAny>,
    tol: Option<f64>,
    modal_test: bool,
    dual: bool,
) -> PyResult<Controllability> {
    let (a, second) = pair(py, a, second, dual)?;
    let (a, second) = (|| Ok((a.matrix()?, second.matrix()?)))().map_err(|e| to_py_err(py, e))?;
    let cost = verdict_cost(a.nrows(), second, modal_test, dual);
    compute(py, cost, || {
        if dual {
            observability_core(a, second, tol, modal_test, true)
        } else {
            controllability_core(a, second, tol, modal_test, true)
        }
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(krylov_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(controllability, m)?)?;
    m.add_function(wrap_pyfunction!(controllability_verdict, m)?)?;
    Ok(())
}
