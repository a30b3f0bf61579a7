//! Bindings of `aerocontrol.frequency`: the frequency response.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real, new_array, new_array_data};
use super::errors::to_py_err;
use super::statespace::ModelArgs;
use crate::control::frequency::{discrete_frequency_response_into, frequency_response_into};
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

/// G(jω_k) = C (jω_k I - A)^-1 B + D, as a complex (len(omega), p, m) array; for a discrete
/// model sampled every `dt`, G(e^{jω_k dt}) = C (e^{jω_k dt} I - A)^-1 B + D.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, omega, dt=None, /))]
fn frequency_response<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    omega: &Bound<'py, PyAny>,
    dt: Option<f64>,
) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
    let args = ModelArgs::convert(py, a, b, c, d)?;
    let omega = Real::convert(py, omega, "omega")?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let omega = omega
        .vector("a 1-D array of frequencies")
        .map_err(|e| to_py_err(py, e))?;
    let (n, m, p) = (model.a.nrows(), model.b.ncols(), model.c.nrows());
    let out = new_array::<c64>(py, &[omega.len(), p, m])?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    // A Hessenberg reduction, then per frequency a Hessenberg solve with m right-hand sides
    // (in complex arithmetic) and the product with C.
    let per_frequency = 8.0 * (n * n * m.max(1) + p * n * m) as f64 + 1.0;
    let threads = crate::platform::threads::num_threads() as f64;
    let cost = Cost {
        flops: 10.0 * (n as f64).powi(3) + omega.len() as f64 * per_frequency,
        bytes: (8.0 + 4.0 * threads) * (n * n.max(m)) as f64 * 8.0,
        order: n.max(m).max(p),
    };
    compute(py, cost, || match dt {
        None => frequency_response_into(model.a, model.b, model.c, model.d, omega, data),
        Some(dt) => {
            discrete_frequency_response_into(model.a, model.b, model.c, model.d, omega, dt, data)
        }
    })?;
    let mut outputs = Outputs::new(py);
    // SAFETY: as above; the computation is over.
    outputs.check_complex("G(jω)", unsafe { new_array_data(&out) });
    outputs.finish()?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(frequency_response, m)?)?;
    Ok(())
}
