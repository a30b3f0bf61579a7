//! Bindings of `aerocontrol.batch`: Riccati equations and pole placement over stacks of
//! problems, in parallel with the GIL released.

use super::compute::Cost;
use super::compute::compute;
use super::conversion::{Complex, Outputs, Real, new_array, new_array_data};
use super::errors::to_py_err;
use super::placement::{placement_cost, placer_for};
use super::riccati::{care_cost, dare_cost};
use crate::control::batch::{
    CareBatchOutput, CareStacks, PlaceBatchOutput, RiccatiKind, place_batch as place_batch_core,
    riccati_batch,
};
use crate::error::Error;
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

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
    riccati_batch_arrays(py, [a, b, q, r], RiccatiKind::Continuous { refine })
}

/// A batch of discrete Riccati equations solved in parallel with the GIL released, as
/// [`care_batch`]: X, K, the closed-loop eigenvalues (inside the unit circle), the relative
/// residuals, rcond(E U11).
#[pyfunction]
#[pyo3(signature = (a, b, q, r, /))]
fn dare_batch<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    q: &Bound<'py, PyAny>,
    r: &Bound<'py, PyAny>,
) -> PyResult<CareBatchArrays<'py>> {
    riccati_batch_arrays(py, [a, b, q, r], RiccatiKind::Discrete)
}

/// The batch of either kind: arguments converted, outputs allocated, the work done with the
/// GIL released, overflow reported.
fn riccati_batch_arrays<'py>(
    py: Python<'py>,
    [a, b, q, r]: [&Bound<'py, PyAny>; 4],
    kind: RiccatiKind,
) -> PyResult<CareBatchArrays<'py>> {
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let (q, r) = (Real::convert(py, q, "Q")?, Real::convert(py, r, "R")?);
    let (stacks, count) = (|| {
        let stacks = CareStacks {
            a: a.stack()?,
            b: b.stack()?,
            q: q.stack()?,
            r: r.stack()?,
        };
        let count = stacks.count()?;
        Ok((stacks, count))
    })()
    .map_err(|e| to_py_err(py, e))?;
    let (n, m) = (a.shape()[1], b.shape()[2]);
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
    let threads = crate::platform::threads::num_threads();
    let cost = match kind {
        RiccatiKind::Continuous { .. } => care_cost(n),
        RiccatiKind::Discrete => dare_cost(n, m),
    }
    .times(count);
    let cost = Cost {
        bytes: cost.bytes * threads as f64,
        ..cost
    };
    compute(py, cost, || riccati_batch(stacks, kind, out))?;
    let mut outputs = Outputs::new(py);
    // SAFETY: the computation is over and the arrays are not yet visible to Python.
    unsafe {
        outputs.check("X", new_array_data(&x));
        outputs.check("K", new_array_data(&gain));
    }
    outputs.finish()?;
    Ok((x, gain, poles, residual, rcond))
}

type PlaceBatchArrays<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
);

/// Pole placement over a batch, in parallel with the GIL released: A (k or 1, n, n),
/// B (k or 1, n, m), poles (k or 1, n) complex, `method` as for `place`. Returns K (k, m, n),
/// the achieved poles (k, n), the largest relative pole errors (k,) and the condition numbers
/// (k,); an error names the lowest failing index.
#[pyfunction]
#[pyo3(signature = (a, b, poles, method, /))]
fn place_batch<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    poles: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<PlaceBatchArrays<'py>> {
    let placer = placer_for(py, method)?;
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let poles = Complex::poles(py, poles)?;
    let (a_stack, b_stack) = (|| Ok((a.stack()?, b.stack()?)))().map_err(|e| to_py_err(py, e))?;
    let (n, m) = (a.shape()[1], b.shape()[2]);
    let rows = match poles.shape[..] {
        [rows, columns] if columns == n => rows,
        _ => {
            let error = Error::WrongDimensions {
                arg: "poles",
                expected: "a 2-D array of one row of n poles per problem (or one row for all), \
                           n the order of A",
                shape: poles.shape.clone(),
            };
            return Err(to_py_err(py, error));
        }
    };
    let count = crate::control::batch::batch_count(&[
        ("A", a_stack.len()),
        ("B", b_stack.len()),
        ("poles", rows),
    ])
    .map_err(|e| to_py_err(py, e))?;
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
    let cost = placement_cost(method, n, m).times(count);
    let requested = &poles.values;
    compute(py, cost, || {
        place_batch_core(a_stack, b_stack, requested, rows, placer, out)
    })?;
    let mut outputs = Outputs::new(py);
    // SAFETY: the computation is over and the arrays are not yet visible to Python.
    unsafe { outputs.check("K", new_array_data(&gain)) };
    outputs.finish()?;
    Ok((gain, achieved, error, condition))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(care_batch, m)?)?;
    m.add_function(wrap_pyfunction!(dare_batch, m)?)?;
    m.add_function(wrap_pyfunction!(place_batch, m)?)?;
    Ok(())
}
