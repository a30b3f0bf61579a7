//! Bindings of `aerocontrol.riccati`: the algebraic Riccati equations, the Riccati
//! differential and difference equations, and the Lyapunov equation.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real};
use super::errors::to_py_err;
use super::linalg::{expm_flops, schur_cost};
use crate::control::riccati::AlgebraicSolution;
use crate::control::riccati::care::{CareOptions, solve_care as solve_care_core};
use crate::control::riccati::dare::{DareOptions, solve_dare as solve_dare_core};
use crate::control::riccati::difference::{
    DifferenceOptions, riccati_difference as riccati_difference_core,
};
use crate::control::riccati::ode::riccati_ode as riccati_ode_core;
use crate::linalg::lyapunov::solve_lyapunov as solve_lyapunov_core;
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

/// The cross weight's name in errors: N as python-control's lqr and dlqr call it, else S as
/// MATLAB's care and dare do.
fn cross_name(named_n: bool) -> &'static str {
    if named_n { "N" } else { "S" }
}

/// The cost of one CARE of n states: the real Schur form of the Hamiltonian (order 2n), its
/// reordering, and a few Newton steps.
pub fn care_cost(n: usize) -> Cost {
    let order = 2 * n;
    Cost::of(40.0 * (order as f64).powi(3), 16.0, order)
}

/// An algebraic Riccati solution as Python receives it: (X, K, closed-loop eigenvalues,
/// relative residual, rcond, Newton steps).
type AlgebraicOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    f64,
    f64,
    usize,
);

/// The arrays and numbers of an [`AlgebraicOutput`].
fn algebraic_output<'py>(
    py: Python<'py>,
    solution: &AlgebraicSolution,
) -> PyResult<AlgebraicOutput<'py>> {
    let mut outputs = Outputs::new(py);
    let n = solution.closed_loop_eigenvalues.len();
    let result = (
        outputs.matrix("X", solution.x.as_ref())?,
        outputs.matrix("K", solution.gain.as_ref())?,
        outputs.complex(
            "the closed-loop eigenvalues",
            &[n],
            &solution.closed_loop_eigenvalues,
        )?,
        solution.residual,
        solution.rcond,
        solution.refinement_steps,
    );
    outputs.finish()?;
    Ok(result)
}

/// The stabilising solution of the CARE (6.228): (X, K, closed-loop eigenvalues, relative
/// residual, rcond(U11), Newton steps).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, s, e, refine, cross_named_n, /))]
#[allow(clippy::too_many_arguments)]
fn solve_care<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    s: Option<&Bound<'py, PyAny>>,
    e: Option<&Bound<'py, PyAny>>,
    refine: bool,
    cross_named_n: bool,
) -> PyResult<AlgebraicOutput<'py>> {
    let s_name = cross_name(cross_named_n);
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let (q, r) = (Real::convert(py, q, "Q")?, Real::convert(py, r, "R")?);
    let s = Real::convert_optional(py, s, s_name)?;
    let e = Real::convert_optional(py, e, "E")?;
    let (a, b, q, r, options) = (|| {
        let options = CareOptions {
            s: s.as_ref().map(|s| s.weight()).transpose()?,
            e: e.as_ref().map(|e| e.weight()).transpose()?,
            refine,
            s_name: Some(s_name),
        };
        Ok((a.matrix()?, b.matrix()?, q.weight()?, r.weight()?, options))
    })()
    .map_err(|e| to_py_err(py, e))?;
    let solution = compute(py, care_cost(a.nrows()), || {
        solve_care_core(a, b, q, r, options)
    })?;
    algebraic_output(py, &solution)
}

/// The cost of one DARE of n states and m inputs: the QZ form of the compressed pencil (order
/// 2n) and its reordering.
pub fn dare_cost(n: usize, m: usize) -> Cost {
    let order = 2 * n;
    Cost::of(
        80.0 * (order as f64).powi(3) + 4.0 * ((order + m) as f64).powi(3),
        12.0,
        order + m,
    )
}

/// The stabilising solution of the DARE: (X, K, closed-loop eigenvalues, relative residual,
/// rcond(E U11), Newton steps).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, s, e, cross_named_n, /))]
#[allow(clippy::too_many_arguments)]
fn solve_dare<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    s: Option<&Bound<'py, PyAny>>,
    e: Option<&Bound<'py, PyAny>>,
    cross_named_n: bool,
) -> PyResult<AlgebraicOutput<'py>> {
    let s_name = cross_name(cross_named_n);
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let (q, r) = (Real::convert(py, q, "Q")?, Real::convert(py, r, "R")?);
    let s = Real::convert_optional(py, s, s_name)?;
    let e = Real::convert_optional(py, e, "E")?;
    let (a, b, q, r, options) = (|| {
        let options = DareOptions {
            s: s.as_ref().map(|s| s.weight()).transpose()?,
            e: e.as_ref().map(|e| e.weight()).transpose()?,
            s_name: Some(s_name),
        };
        Ok((a.matrix()?, b.matrix()?, q.weight()?, r.weight()?, options))
    })()
    .map_err(|e| to_py_err(py, e))?;
    let solution = compute(py, dare_cost(a.nrows(), b.ncols()), || {
        solve_dare_core(a, b, q, r, options)
    })?;
    algebraic_output(py, &solution)
}

type RiccatiOdeOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    usize,
);

/// The Riccati differential equation (6.196) backward over the grid `t`: (S (k, n, n),
/// K (k, m, n), substeps).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, t, sf, /))]
#[allow(clippy::too_many_arguments)]
fn riccati_ode<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
    sf: Option<&Bound<'py, PyAny>>,
) -> PyResult<RiccatiOdeOutput<'py>> {
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let (q, r) = (Real::convert(py, q, "Q")?, Real::convert(py, r, "R")?);
    let t = Real::convert(py, t, "t")?;
    let sf = Real::convert_optional(py, sf, "Sf")?;
    let (a, b, q, r, sf, times) = (|| {
        let sf = sf.as_ref().map(|s| s.weight()).transpose()?;
        let times = t.vector("a 1-D array of times")?;
        Ok((
            a.matrix()?,
            b.matrix()?,
            q.weight()?,
            r.weight()?,
            sf,
            times,
        ))
    })()
    .map_err(|e| to_py_err(py, e))?;
    let (n, m) = (a.nrows(), b.ncols());
    // Per interval a few exponentials of the order-2n Hamiltonian.
    let cost = Cost::of(4.0 * expm_flops(2 * n), 30.0, 2 * n).times(times.len());
    let solution = compute(py, cost, || riccati_ode_core(a, b, q, r, times, sf))?;
    let mut outputs = Outputs::new(py);
    let result = (
        outputs.matrices("S", &solution.s, n, n)?,
        outputs.matrices("K", &solution.gains, m, n)?,
        solution.substeps,
    );
    outputs.finish()?;
    Ok(result)
}

/// S_0..S_N and K_0..K_{N-1} of the Riccati difference equation, the worst rcond of
/// R + B^T S B and the error estimate.
type RiccatiDifferenceOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    f64,
    f64,
);

/// The Riccati difference equation of the discrete finite-horizon regulator over `steps`
/// steps backward from Sf: (S (steps + 1, n, n), K (steps, m, n), worst rcond).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, steps, sf, s, /))]
#[allow(clippy::too_many_arguments)]
fn riccati_difference<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
    steps: usize,
    sf: Option<&Bound<'py, PyAny>>,
    s: Option<&Bound<'py, PyAny>>,
) -> PyResult<RiccatiDifferenceOutput<'py>> {
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let (q, r) = (Real::convert(py, q, "Q")?, Real::convert(py, r, "R")?);
    let sf = Real::convert_optional(py, sf, "Sf")?;
    let s = Real::convert_optional(py, s, "N")?;
    let (a, b, q, r, sf, s) = (|| {
        let sf = sf.as_ref().map(|m| m.weight()).transpose()?;
        let s = s.as_ref().map(|m| m.weight()).transpose()?;
        Ok((a.matrix()?, b.matrix()?, q.weight()?, r.weight()?, sf, s))
    })()
    .map_err(|e| to_py_err(py, e))?;
    let (n, m) = (a.nrows(), b.ncols());
    // Per step about six products of order n and a solve of order m.
    let cost = Cost::of(12.0 * (n.max(m) as f64).powi(3), 8.0, n).times(steps.max(1));
    let options = DifferenceOptions {
        cross: s,
        terminal: sf,
    };
    let solution = compute(py, cost, || {
        riccati_difference_core(a, b, q, r, steps, options)
    })?;
    let mut outputs = Outputs::new(py);
    let result = (
        outputs.matrices("S", &solution.s, n, n)?,
        outputs.matrices("K", &solution.gains, m, n)?,
        solution.rcond,
        solution.error_estimate,
    );
    outputs.finish()?;
    Ok(result)
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
    m.add_function(wrap_pyfunction!(solve_lyapunov, m)?)?;
    m.add_function(wrap_pyfunction!(solve_care, m)?)?;
    m.add_function(wrap_pyfunction!(solve_dare, m)?)?;
    m.add_function(wrap_pyfunction!(riccati_ode, m)?)?;
    m.add_function(wrap_pyfunction!(riccati_difference, m)?)?;
    Ok(())
}
