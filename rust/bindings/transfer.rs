//! Bindings of `aerocontrol.transfer`: SISO channels' transfer functions from the state space,
//! and the evaluation of a factored transfer function.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, copy_values, new_array, new_array_data};
use super::errors::to_py_err;
use super::statespace::ModelArgs;
use crate::control::transfer::{
    factored_response as factored_response_core, transfer_channels as transfer_channels_core,
};
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

type ChannelOutput<'py> = Option<(
    Bound<'py, PyArrayDyn<c64>>,
    f64,
    Bound<'py, PyArrayDyn<f64>>,
)>;

/// The channels (output i, input j) of the model (`control/transfer.rs`; None: every channel,
/// output by output): (poles, denominator,
/// [None or (zeros, gain, numerator) per channel]), None where the channel is left to the
/// reference path of `aerocontrol.transfer`. The denominator is empty when it overflows.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, dt, channels, /))]
#[allow(clippy::type_complexity)]
fn transfer_channels<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
    dt: f64,
    channels: Option<Vec<(usize, usize)>>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Vec<ChannelOutput<'py>>,
)> {
    let args = ModelArgs::convert(py, a, b, c, d)?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let n = model.a.nrows();
    let channels = channels.unwrap_or_else(|| {
        let (p, m) = (model.c.nrows(), model.b.ncols());
        (0..p * m).map(|k| (k / m, k % m)).collect()
    });
    // An eigenvalue problem of order n, and per channel a reduction and one of order n.
    let cost = Cost::of(25.0 * (n as f64).powi(3), 4.0, n).times(channels.len() + 1);
    let transfer = compute(py, cost, || {
        transfer_channels_core(model.a, model.b, model.c, model.d, dt, &channels)
    })?;
    let mut outputs = Outputs::new(py);
    let poles = outputs.complex("the poles", &[transfer.poles.len()], &transfer.poles)?;
    let denominator = outputs.real_as_is(&[transfer.denominator.len()], &transfer.denominator)?;
    let mut results = Vec::with_capacity(transfer.channels.len());
    for channel in transfer.channels {
        results.push(match channel {
            None => None,
            Some(ch) => Some((
                outputs.complex("the zeros", &[ch.zeros.len()], &ch.zeros)?,
                ch.gain,
                outputs.real_as_is(&[ch.numerator.len()], &ch.numerator)?,
            )),
        });
    }
    outputs.finish()?;
    Ok((poles, denominator, results))
}

/// K_k Π(s - z_ki) / Π(s - p_j) for each channel k (K_k = mantissas[k] 2^exponents[k], its
/// zeros zeros[k]) at each of `points` (complex128, any shape, taken in C order): a complex
/// array of `shape` (the channels' shape, such as (outputs, inputs), then the points'), channel
/// by channel, the products renormalised by powers of two after each factor; infinite or NaN
/// at a pole (not warned of: the caller does), with whether every value is finite.
#[pyfunction]
#[pyo3(signature = (mantissas, exponents, zeros, poles, points, shape, /))]
fn factored_response<'py>(
    py: Python<'py>,
    mantissas: Vec<f64>,
    exponents: Vec<i64>,
    zeros: Vec<Bound<'py, PyArrayDyn<c64>>>,
    poles: &Bound<'py, PyArrayDyn<c64>>,
    points: &Bound<'py, PyArrayDyn<c64>>,
    shape: Vec<usize>,
) -> PyResult<(Bound<'py, PyArrayDyn<c64>>, bool)> {
    if exponents.len() != mantissas.len() || zeros.len() != mantissas.len() {
        return Err(to_py_err(
            py,
            crate::error::Error::InvalidArgument {
                arg: "zeros",
                message: "one mantissa, exponent and array of zeros per channel".to_string(),
            },
        ));
    }
    let zeros = zeros
        .iter()
        .map(|z| copy_values(py, z))
        .collect::<PyResult<Vec<_>>>()?;
    let (poles, points) = (copy_values(py, poles)?, copy_values(py, points)?);
    let entries = shape.iter().try_fold(1usize, |p, &k| p.checked_mul(k));
    if entries != mantissas.len().checked_mul(points.len()) {
        return Err(to_py_err(
            py,
            crate::error::Error::InvalidArgument {
                arg: "shape",
                message: format!(
                    "shape {shape:?} does not hold {} channels at {} points",
                    mantissas.len(),
                    points.len()
                ),
            },
        ));
    }
    let out = new_array::<c64>(py, &shape)?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    let roots = zeros.iter().map(Vec::len).sum::<usize>() + poles.len() * zeros.len();
    let cost = Cost {
        flops: 30.0 * roots as f64 * points.len() as f64,
        bytes: 0.0,
        order: 1,
    };
    compute(py, cost, || {
        for (k, values) in data
            .chunks_mut(points.len().max(1))
            .enumerate()
            .take(mantissas.len())
        {
            factored_response_core(
                mantissas[k],
                exponents[k],
                &zeros[k],
                &poles,
                &points,
                values,
            );
        }
        Ok(())
    })?;
    // SAFETY: as above; the computation is over.
    let finite = unsafe { new_array_data(&out) }
        .iter()
        .all(|z| z.re.is_finite() && z.im.is_finite());
    Ok((out, finite))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(transfer_channels, m)?)?;
    m.add_function(wrap_pyfunction!(factored_response, m)?)?;
    Ok(())
}
