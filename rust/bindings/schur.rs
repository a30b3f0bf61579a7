//! Bindings of `aerocontrol.schur`: the real Schur form with reordering, and the Lyapunov
//! equation.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real};
use super::errors::to_py_err;
use crate::linalg::lyapunov::solve_lyapunov as solve_lyapunov_core;
use crate::linalg::schur::reorder::{OrderedSchur, reorder_schur};
use crate::linalg::schur::{quasi_triangular_eigenvalues, real_schur};
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyComplex;

/// The cost of the real Schur form of order n, with Z.
pub fn schur_cost(n: usize) -> Cost {
    Cost::of(25.0 * (n as f64).powi(3), 6.0, n)
}

type SchurOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    usize,
);

/// The real Schur form A = Z T Z^T, reordered when `select` (a callable on an eigenvalue,
/// called once per diagonal block) is given: (T, Z, eigenvalues, number selected).
///
/// `select` runs with the GIL taken for each call, while the Schur form itself is computed
/// with the GIL released; the first exception it raises is re-raised after the reordering.
#[pyfunction]
#[pyo3(signature = (a, select, /))]
fn schur<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    select: Option<&Bound<'py, PyAny>>,
) -> PyResult<SchurOutput<'py>> {
    let a = Real::convert(py, a, "A")?;
    let a = a.matrix().map_err(|e| to_py_err(py, e))?;
    let select: Option<Py<PyAny>> = select.map(|s| s.clone().unbind());
    let (ordered, failure) = compute(py, schur_cost(a.nrows()), || {
        let form = real_schur(a)?;
        let Some(select) = select else {
            let eigenvalues = quasi_triangular_eigenvalues(form.t.as_ref());
            let selected = eigenvalues.len();
            let ordered = OrderedSchur {
                t: form.t,
                z: form.z,
                eigenvalues,
                selected,
            };
            return Ok((ordered, None));
        };
        let mut failure: Option<PyErr> = None;
        let chooser = |lambda: c64| -> bool {
            if failure.is_some() {
                return false;
            }
            Python::attach(|py| {
                let value = PyComplex::from_doubles(py, lambda.re, lambda.im);
                match select.bind(py).call1((value,)).and_then(|r| r.is_truthy()) {
                    Ok(chosen) => chosen,
                    Err(error) => {
                        failure = Some(error);
                        false
                    }
                }
            })
        };
        let ordered = reorder_schur(form, chooser)?;
        Ok((ordered, failure))
    })?;
    if let Some(error) = failure {
        return Err(error);
    }
    let mut outputs = Outputs::new(py);
    let n = ordered.eigenvalues.len();
    Ok((
        outputs.matrix("T", ordered.t.as_ref())?,
        outputs.matrix("Z", ordered.z.as_ref())?,
        outputs.complex("the eigenvalues", &[n], &ordered.eigenvalues)?,
        ordered.selected,
    ))
    .and_then(|result| outputs.finish().map(|()| result))
}

/// The solution X of A X + X A^T + Q = 0.
#[pyfunction]
#[pyo3(signature = (a, q, /))]
fn solve_lyapunov<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let (a, q) = (Real::convert(py, a, "A")?, Real::convert(py, q, "Q")?);
    let (a, q) = (|| Ok((a.matrix()?, q.matrix()?)))().map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    let cost = schur_cost(n).then(Cost::of(4.0 * (n as f64).powi(3), 4.0, n));
    let x = compute(py, cost, || solve_lyapunov_core(a, q))?;
    let mut outputs = Outputs::new(py);
    let out = outputs.matrix("X", x.as_ref())?;
    outputs.finish()?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(schur, m)?)?;
    m.add_function(wrap_pyfunction!(solve_lyapunov, m)?)?;
    Ok(())
}
