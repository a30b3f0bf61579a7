//! Bindings of `aerocontrol.linalg`: the matrix exponential, transition matrices, exact
//! discretisation, and the real Schur form with reordering.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real, new_array, new_array_data};
use super::errors::{Class, raise, to_py_err, warn};
use crate::control::discretize::{
    Hold, StateSpaceMatrices, bilinear as bilinear_core, discretize as discretize_core,
    inverse_bilinear as inverse_bilinear_core, undiscretize_zoh as undiscretize_zoh_core,
};
use crate::error::{Error, check_square};
use crate::linalg::expm::{
    ILL_CONDITIONED_NORM, approximant_choice, expm_into, transition_matrices_into,
};
use crate::linalg::max_plus::{
    balancing_exponents as balancing_exponents_core, max_cycle_mean as max_cycle_mean_core,
    product as max_plus_product,
};
use crate::linalg::norm::one_norm;
use crate::linalg::qz::{
    GeneralizedEigenvalue, generalized_eigenvalues, qz as qz_core, reorder_qz,
};
use crate::linalg::schur::reorder::{OrderedSchur, reorder_schur};
use crate::linalg::schur::{
    eigenvalues as eigenvalues_core, quasi_triangular_eigenvalues, real_schur,
};
use faer::{MatMut, MatRef, c64};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyComplex;

/// Floating-point operations of one exponential of order n (a Padé evaluation of degree 13 and
/// a few squarings: about ten products).
pub fn expm_flops(n: usize) -> f64 {
    20.0 * (n as f64).powi(3)
}

/// Temporaries of one exponential: the powers, the Padé terms, the LU factors.
const EXPM_TEMPORARIES: f64 = 24.0;

/// Warns when ||A||_1 max|t| makes e^{At} meaningless in double precision.
fn warn_if_ill_conditioned(py: Python<'_>, a_norm: f64, t_max: f64) -> PyResult<()> {
    let scaled = a_norm * t_max;
    if scaled >= ILL_CONDITIONED_NORM {
        let message = format!(
            "||tA||_1 = {scaled:.3e} exceeds 1/u = 2^53: the exponential's relative condition \
             number is at least ||tA||_2, so the rounding of the input alone can change every \
             digit of the result"
        );
        warn(py, Class::IllConditionedWarning, &message)?;
    }
    Ok(())
}

/// max |v| over finite values, in four lanes (vector operations).
fn largest_magnitude(values: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 4];
    let chunks = values.chunks_exact(4);
    let tail = chunks.remainder();
    for chunk in chunks {
        for (lane, v) in lanes.iter_mut().zip(chunk) {
            let magnitude = v.abs();
            *lane = if magnitude > *lane { magnitude } else { *lane };
        }
    }
    tail.iter().chain(&lanes).fold(0.0, |m, v| m.max(v.abs()))
}

/// e^A for a 2-D A, or for every matrix of a 3-D stack (in parallel).
#[pyfunction]
#[pyo3(signature = (a, /))]
fn expm<'py>(py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = Real::convert(py, a, "A")?;
    match *a.shape() {
        [n, _] => {
            let matrix = a.matrix().map_err(|e| to_py_err(py, e))?;
            check_square(matrix, "A").map_err(|e| to_py_err(py, e))?;
            let out = new_array(py, &[n, n])?;
            // SAFETY: `out` is new and not visible to Python until returned.
            let data = unsafe { new_array_data(&out) };
            let cost = Cost::of(expm_flops(n), EXPM_TEMPORARIES, n);
            compute(py, cost, || {
                expm_into(matrix, MatMut::from_row_major_slice_mut(data, n, n))
            })?;
            let mut outputs = Outputs::new(py);
            // SAFETY: as above; the computation is over.
            outputs.check("e^A", unsafe { new_array_data(&out) });
            outputs.finish()?;
            warn_if_ill_conditioned(py, one_norm(matrix), 1.0)?;
            Ok(out)
        }
        [_, rows, cols] => {
            let stack = a.stack().map_err(|e| to_py_err(py, e))?;
            if rows != cols {
                return Err(to_py_err(
                    py,
                    Error::NotSquare {
                        arg: "A",
                        rows,
                        cols,
                    },
                ));
            }
            let out = new_array(py, a.shape())?;
            // SAFETY: `out` is new and not visible to Python until returned.
            let data = unsafe { new_array_data(&out) };
            let threads = crate::platform::threads::num_threads() as f64;
            let cost =
                Cost::of(expm_flops(rows), EXPM_TEMPORARIES * threads, rows).times(stack.len());
            compute(py, cost, || crate::control::batch::expm_batch(stack, data))?;
            // SAFETY: as above; the computation is over.
            let values = unsafe { new_array_data(&out) };
            let size = rows * rows;
            // One branch-free pass over each whole stack (vectorised) decides; the members are
            // looked at one by one only when it does not.
            if size > 0 && !values.iter().fold(true, |all, v| all & v.is_finite()) {
                let overflowed: Vec<usize> = values
                    .chunks_exact(size)
                    .enumerate()
                    .filter(|(_, m)| m.iter().any(|v| !v.is_finite()))
                    .map(|(k, _)| k)
                    .collect();
                let message = format!(
                    "the matrix exponential overflowed double precision: the result has \
                     infinite or NaN entries (matrices {overflowed:?} of the stack)"
                );
                warn(py, Class::NumericalOverflowWarning, &message)?;
            }
            // ||A||_1 <= n max|a_ij|: the norms are computed only where that bound reaches the
            // threshold of the warning.
            let largest_entry = largest_magnitude(a.values());
            if size > 0 && largest_entry * rows as f64 >= ILL_CONDITIONED_NORM {
                let largest_norm = a
                    .values()
                    .chunks_exact(size)
                    .map(|m| one_norm(MatRef::from_row_major_slice(m, rows, rows)))
                    .fold(0.0, f64::max);
                warn_if_ill_conditioned(py, largest_norm, 1.0)?;
            }
            Ok(out)
        }
        _ => Err(to_py_err(
            py,
            Error::WrongDimensions {
                arg: "A",
                expected: "a 2-D square matrix or a 3-D stack of square matrices",
                shape: a.shape().to_vec(),
            },
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
    let (a, t) = (Real::convert(py, a, "A")?, Real::convert(py, t, "t")?);
    let matrix = a.matrix().map_err(|e| to_py_err(py, e))?;
    check_square(matrix, "A").map_err(|e| to_py_err(py, e))?;
    let times = t.vector("a 1-D array").map_err(|e| to_py_err(py, e))?;
    let n = matrix.nrows();
    let out = new_array(py, &[times.len(), n, n])?;
    // SAFETY: `out` is new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    let cost = Cost::of(expm_flops(n), EXPM_TEMPORARIES, n).times(times.len());
    compute(py, cost, || transition_matrices_into(matrix, times, data))?;
    let mut outputs = Outputs::new(py);
    // SAFETY: as above; the computation is over.
    outputs.check("Φ(t)", unsafe { new_array_data(&out) });
    outputs.finish()?;
    let t_max = times.iter().fold(0.0, |m: f64, t| m.max(t.abs()));
    warn_if_ill_conditioned(py, one_norm(matrix), t_max)?;
    Ok(out)
}

type Discretized<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Option<Bound<'py, PyArrayDyn<f64>>>,
);

/// The input hold named by the `method` argument: "zoh" (zero order) or "foh" (first order).
pub fn hold_from_method(py: Python<'_>, method: &str) -> PyResult<Hold> {
    match method {
        "zoh" => Ok(Hold::Zero),
        "foh" => Ok(Hold::First),
        other => Err(raise(
            py,
            Class::InvalidArgumentError,
            format!("method must be \"zoh\" or \"foh\", got {other:?}"),
        )),
    }
}

/// The cost of discretising a model of n states and m inputs: one exponential of the augmented
/// matrix of order n + 2m.
pub fn discretize_cost(n: usize, m: usize) -> Cost {
    let order = n.saturating_add(m.saturating_mul(2));
    Cost::of(expm_flops(order), EXPM_TEMPORARIES, order)
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
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let a = a.matrix().map_err(|e| to_py_err(py, e))?;
    let b = b.matrix().map_err(|e| to_py_err(py, e))?;
    let cost = discretize_cost(a.nrows(), b.ncols());
    let result = compute(py, cost, || discretize_core(a, b, dt, hold))?;
    let mut outputs = Outputs::new(py);
    let phi = outputs.matrix("Phi", result.phi.as_ref())?;
    let gamma0 = outputs.matrix("Gamma0", result.gamma0.as_ref())?;
    let gamma1 = result
        .gamma1
        .as_ref()
        .map(|g| outputs.matrix("Gamma1", g.as_ref()))
        .transpose()?;
    outputs.finish()?;
    warn_if_ill_conditioned(py, one_norm(a), dt)?;
    Ok((phi, gamma0, gamma1))
}

type Matrices<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
);

/// The four matrices of a model as arrays, warning if any overflowed.
fn matrices_out<'py>(py: Python<'py>, model: &StateSpaceMatrices) -> PyResult<Matrices<'py>> {
    let mut outputs = Outputs::new(py);
    let result = (
        outputs.matrix("A", model.a.as_ref())?,
        outputs.matrix("B", model.b.as_ref())?,
        outputs.matrix("C", model.c.as_ref())?,
        outputs.matrix("D", model.d.as_ref())?,
    );
    outputs.finish()?;
    Ok(result)
}

/// The cost of a bilinear transformation of a model (n, m, p): an LU of order n and solves
/// with 2n + m right-hand sides.
fn bilinear_cost(n: usize, m: usize, p: usize) -> Cost {
    let flops = (n as f64).powi(2) * (4.0 * n as f64 + 2.0 * (m + p) as f64);
    Cost::of(flops, 6.0, n.max(m).max(p))
}

/// (Ad, Bd, Cd, Dd): the generalized bilinear transformation of (A, B, C, D) with step dt and
/// weight alpha (1/2: Tustin's).
#[pyfunction]
#[pyo3(signature = (a, b, c, d, dt, alpha, /))]
#[allow(clippy::too_many_arguments)]
fn bilinear<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    dt: f64,
    alpha: f64,
) -> PyResult<Matrices<'py>> {
    let args = super::statespace::ModelArgs::convert(py, a, b, c, d)?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let cost = bilinear_cost(model.a.nrows(), model.b.ncols(), model.c.nrows());
    let result = compute(py, cost, || {
        bilinear_core(model.a, model.b, model.c, model.d, dt, alpha)
    })?;
    matrices_out(py, &result)
}

/// (A, B, C, D): the continuous model whose generalized bilinear transformation with step dt
/// and weight alpha is the discrete model (a, b, c, d).
#[pyfunction]
#[pyo3(signature = (a, b, c, d, dt, alpha, /))]
#[allow(clippy::too_many_arguments)]
fn inverse_bilinear<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    dt: f64,
    alpha: f64,
) -> PyResult<Matrices<'py>> {
    let args = super::statespace::ModelArgs::convert(py, a, b, c, d)?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let cost = bilinear_cost(model.a.nrows(), model.b.ncols(), model.c.nrows());
    let result = compute(py, cost, || {
        inverse_bilinear_core(model.a, model.b, model.c, model.d, dt, alpha)
    })?;
    matrices_out(py, &result)
}

type PlantPair<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

/// (A, B): the continuous model whose zero-order-hold discretisation over dt is (phi, gamma),
/// by the principal logarithm of [[phi, gamma], [0, I]].
#[pyfunction]
#[pyo3(signature = (phi, gamma, dt, /))]
fn undiscretize_zoh<'py>(
    py: Python<'py>,
    phi: &Bound<'py, PyAny>,
    gamma: &Bound<'py, PyAny>,
    dt: f64,
) -> PyResult<PlantPair<'py>> {
    let (phi, gamma) = (Real::convert(py, phi, "A")?, Real::convert(py, gamma, "B")?);
    let phi = phi.matrix().map_err(|e| to_py_err(py, e))?;
    let gamma = gamma.matrix().map_err(|e| to_py_err(py, e))?;
    let order = phi.nrows() + gamma.ncols();
    // A Schur form, a few square roots and eight solves, and the exponential of the check.
    let cost = Cost::of(
        schur_cost(order).flops + 30.0 * (order as f64).powi(3) + expm_flops(order),
        EXPM_TEMPORARIES,
        order,
    );
    let (a, b) = compute(py, cost, || undiscretize_zoh_core(phi, gamma, dt))?;
    let mut outputs = Outputs::new(py);
    let result = (
        outputs.matrix("A", a.as_ref())?,
        outputs.matrix("B", b.as_ref())?,
    );
    outputs.finish()?;
    Ok(result)
}

/// The approximant's degree m (3, 5, 7, 9, 13: Padé; 15: the Taylor approximant 15+) and the
/// number of squarings s that the exponential of A uses: a diagnostic for tests and for users
/// comparing algorithms.
#[pyfunction]
#[pyo3(signature = (a, /))]
fn expm_approximant_choice(py: Python<'_>, a: &Bound<'_, PyAny>) -> PyResult<(usize, u32)> {
    let a = Real::convert(py, a, "A")?;
    let a = a.matrix().map_err(|e| to_py_err(py, e))?;
    check_square(a, "A").map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    compute(py, Cost::of(expm_flops(n) / 4.0, 8.0, n), || {
        approximant_choice(a)
    })
}

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

/// The eigenvalues of a real square matrix (the Schur form without Z), in the order of the
/// quasi-triangular form's diagonal; of a 3-D stack (k, n, n), a (k, n) array, in parallel.
#[pyfunction]
#[pyo3(signature = (a, /))]
fn eigenvalues<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
    let a = Real::convert(py, a, "A")?;
    match *a.shape() {
        [_, _] => {
            let a = a.matrix().map_err(|e| to_py_err(py, e))?;
            let values = compute(py, schur_cost(a.nrows()), || eigenvalues_core(a))?;
            let mut outputs = Outputs::new(py);
            let n = values.len();
            let result = outputs.complex("the eigenvalues", &[n], &values)?;
            outputs.finish()?;
            Ok(result)
        }
        [count, rows, cols] => {
            let stack = a.stack().map_err(|e| to_py_err(py, e))?;
            if rows != cols {
                return Err(to_py_err(
                    py,
                    Error::NotSquare {
                        arg: "A",
                        rows,
                        cols,
                    },
                ));
            }
            let out = new_array::<c64>(py, &[count, rows])?;
            // SAFETY: `out` is new and not visible to Python until returned.
            let data = unsafe { new_array_data(&out) };
            let threads = crate::platform::threads::num_threads() as f64;
            let single = schur_cost(rows);
            let cost = Cost {
                bytes: single.bytes * threads,
                ..single
            }
            .times(count);
            compute(py, cost, || {
                crate::control::batch::eigenvalues_batch(stack, data)
            })?;
            let mut outputs = Outputs::new(py);
            // SAFETY: as above; the computation is over.
            outputs.check_complex("the eigenvalues", unsafe { new_array_data(&out) });
            outputs.finish()?;
            Ok(out)
        }
        _ => Err(to_py_err(
            py,
            Error::WrongDimensions {
                arg: "A",
                expected: "a 2-D square matrix or a 3-D stack of square matrices",
                shape: a.shape().to_vec(),
            },
        )),
    }
}

/// The cost of the generalized Schur form of order n, with Q and Z.
pub fn qz_cost(n: usize) -> Cost {
    Cost::of(66.0 * (n as f64).powi(3), 8.0, n)
}

type QzOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    usize,
);

/// The generalized real Schur form (A, B) = Q (S, T) Z^T, reordered when `select` (a callable
/// on (alpha, beta), called once per diagonal block) is given: (S, T, alpha, beta, Q, Z,
/// number selected). As with `schur`, `select` runs with the GIL taken for each call and its
/// first exception is re-raised after the reordering.
#[pyfunction]
#[pyo3(signature = (a, b, select, /))]
fn qz<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    select: Option<&Bound<'py, PyAny>>,
) -> PyResult<QzOutput<'py>> {
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert(py, b, "B")?;
    let a = a.matrix().map_err(|e| to_py_err(py, e))?;
    let b = b.matrix().map_err(|e| to_py_err(py, e))?;
    let select: Option<Py<PyAny>> = select.map(|s| s.clone().unbind());
    let (form, selected, failure) = compute(py, qz_cost(a.nrows()), || {
        let form = qz_core(a, b)?;
        let Some(select) = select else {
            let n = form.s.nrows();
            return Ok((form, n, None));
        };
        let mut failure: Option<PyErr> = None;
        let chooser = |value: GeneralizedEigenvalue| -> bool {
            if failure.is_some() {
                return false;
            }
            Python::attach(|py| {
                let alpha = PyComplex::from_doubles(py, value.alpha.re, value.alpha.im);
                match select
                    .bind(py)
                    .call1((alpha, value.beta))
                    .and_then(|r| r.is_truthy())
                {
                    Ok(chosen) => chosen,
                    Err(error) => {
                        failure = Some(error);
                        false
                    }
                }
            })
        };
        let (form, selected) = reorder_qz(form, chooser)?;
        Ok((form, selected, failure))
    })?;
    if let Some(error) = failure {
        return Err(error);
    }
    let values = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref());
    let n = values.len();
    let alpha: Vec<c64> = values.iter().map(|v| v.alpha).collect();
    let beta: Vec<f64> = values.iter().map(|v| v.beta).collect();
    let mut outputs = Outputs::new(py);
    let result = (
        outputs.matrix("S", form.s.as_ref())?,
        outputs.matrix("T", form.t.as_ref())?,
        outputs.complex("alpha", &[n], &alpha)?,
        outputs.real("beta", &[n], &beta)?,
        outputs.matrix("Q", form.q.as_ref())?,
        outputs.matrix("Z", form.z.as_ref())?,
        selected,
    );
    outputs.finish()?;
    Ok(result)
}

/// The (max, +) product P ⊗ Q of two matrices of log2 sizes (`_scaling.max_plus`):
/// entry (i, j) is max_k P[i, k] + Q[k, j].
#[pyfunction]
#[pyo3(signature = (p, q, /))]
fn max_plus<'py>(
    py: Python<'py>,
    p: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let (p, q) = (Real::convert(py, p, "P")?, Real::convert(py, q, "Q")?);
    let (p, q) = (
        p.matrix().map_err(|e| to_py_err(py, e))?,
        q.matrix().map_err(|e| to_py_err(py, e))?,
    );
    // Rows x inner x columns of work in the memory of the result (not that of a square
    // matrix of the larger side), and no floating-point matrix products.
    let cost = Cost::without_products(
        (p.nrows() * p.ncols()) as f64 * q.ncols() as f64,
        (p.nrows() * q.ncols()) as f64 * 8.0,
    );
    let product = compute(py, cost, || max_plus_product(p, q))?;
    // -inf entries are sizes of zeros, not overflows: written unchecked.
    let out = new_array(py, &[product.nrows(), product.ncols()])?;
    // SAFETY: `out` is new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    MatMut::from_row_major_slice_mut(data, product.nrows(), product.ncols())
        .copy_from(product.as_ref());
    Ok(out)
}

/// The largest mean weight of a cycle of the graph of log2 sizes G
/// (`_scaling.max_cycle_mean`), by Karp's algorithm; -inf without a cycle.
#[pyfunction]
#[pyo3(signature = (g, /))]
fn max_cycle_mean(py: Python<'_>, g: &Bound<'_, PyAny>) -> PyResult<f64> {
    let g = Real::convert(py, g, "G")?;
    let g = g.matrix().map_err(|e| to_py_err(py, e))?;
    let n = g.nrows();
    let size = n as f64;
    let cost = Cost::without_products(size.powi(3), size * size * 8.0);
    compute(py, cost, || max_cycle_mean_core(g))
}

/// The max-balancing exponents of the graph of log2 sizes G and its largest scaled entry
/// (`_scaling.balancing_exponents`).
#[pyfunction]
#[pyo3(signature = (g, outside, /))]
fn balancing_exponents<'py>(
    py: Python<'py>,
    g: &Bound<'py, PyAny>,
    outside: bool,
) -> PyResult<(Bound<'py, PyArrayDyn<i64>>, f64)> {
    let g = Real::convert(py, g, "G")?;
    let g = g.matrix().map_err(|e| to_py_err(py, e))?;
    let n = g.nrows();
    let size = n as f64;
    let cost = Cost::without_products(size.powi(3), 3.0 * size * size * 8.0);
    let (exponents, largest) = compute(py, cost, || balancing_exponents_core(g, outside))?;
    let out = new_array::<i64>(py, &[exponents.len()])?;
    // SAFETY: `out` is new and not visible to Python until returned.
    unsafe { new_array_data(&out) }.copy_from_slice(&exponents);
    Ok((out, largest))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(balancing_exponents, m)?)?;
    m.add_function(wrap_pyfunction!(max_plus, m)?)?;
    m.add_function(wrap_pyfunction!(max_cycle_mean, m)?)?;
    m.add_function(wrap_pyfunction!(eigenvalues, m)?)?;
    m.add_function(wrap_pyfunction!(qz, m)?)?;
    m.add_function(wrap_pyfunction!(schur, m)?)?;
    m.add_function(wrap_pyfunction!(expm, m)?)?;
    m.add_function(wrap_pyfunction!(transition_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(discretize, m)?)?;
    m.add_function(wrap_pyfunction!(bilinear, m)?)?;
    m.add_function(wrap_pyfunction!(inverse_bilinear, m)?)?;
    m.add_function(wrap_pyfunction!(undiscretize_zoh, m)?)?;
    m.add_function(wrap_pyfunction!(expm_approximant_choice, m)?)?;
    Ok(())
}
