//! Bindings of `aerocontrol.transfer`: SISO channels' transfer functions from the state space,
//! and the evaluation of a factored transfer function.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, copy_values, new_array, new_array_data};
use super::errors::to_py_err;
use super::statespace::ModelArgs;
use crate::control::transfer::{
    Channel, factored_response as factored_response_core, factored_response_sorted,
    mantissa_and_exponent, transfer_channels as transfer_channels_core,
};
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

type ChannelOutput<'py> = Option<(
    Bound<'py, PyArrayDyn<c64>>,
    f64,
    Bound<'py, PyArrayDyn<f64>>,
)>;

/// The fast path's channels of one model (`control/transfer.rs`), kept in the core: a
/// channel's arrays are made when Python asks for them, and ``response`` evaluates every
/// channel's factored form from the zeros and poles the core sorted by modulus once.
#[pyclass(frozen, module = "aerocontrol._core", name = "FastChannels")]
struct FastChannels {
    channels: Vec<Option<Channel>>,
    poles_by_modulus: Vec<c64>,
}

#[pymethods]
impl FastChannels {
    fn __len__(&self) -> usize {
        self.channels.len()
    }

    /// The indices of the channels left to the reference path of `aerocontrol.transfer`.
    #[getter]
    fn deferred(&self) -> Vec<usize> {
        (0..self.channels.len())
            .filter(|&k| self.channels[k].is_none())
            .collect()
    }

    /// Channel k as (zeros, gain, numerator), None where it is left to the reference path.
    fn channel<'py>(&self, py: Python<'py>, k: usize) -> PyResult<ChannelOutput<'py>> {
        let Some(channel) = self.channels.get(k) else {
            return Err(to_py_err(
                py,
                crate::error::Error::InvalidArgument {
                    arg: "k",
                    message: format!("no channel {k} of {}", self.channels.len()),
                },
            ));
        };
        let Some(ch) = channel else {
            return Ok(None);
        };
        // Finite by the fast path's checks (it defers a channel whose zeros or numerator are
        // not): nothing to warn of.
        let mut outputs = Outputs::new(py);
        let zeros = outputs.complex("the zeros", &[ch.zeros.len()], &ch.zeros)?;
        let numerator = outputs.real_as_is(&[ch.numerator.len()], &ch.numerator)?;
        outputs.finish()?;
        Ok(Some((zeros, ch.gain, numerator)))
    }

    /// K Π(s - z_i) / Π(s - p_j) of every channel at each of `points`, as
    /// `factored_response` with each channel's gain as its mantissa and power of two (every
    /// channel must be the fast path's).
    #[pyo3(signature = (points, shape, /))]
    fn response<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyArrayDyn<c64>>,
        shape: Vec<i64>,
    ) -> PyResult<(Bound<'py, PyArrayDyn<c64>>, bool)> {
        let mut channels = Vec::with_capacity(self.channels.len());
        for channel in &self.channels {
            let Some(ch) = channel else {
                return Err(to_py_err(
                    py,
                    crate::error::Error::InvalidArgument {
                        arg: "channels",
                        message: "a channel is left to the reference path".to_string(),
                    },
                ));
            };
            channels.push(ch);
        }
        let points = copy_values(py, points)?;
        let roots = channels.iter().map(|ch| ch.zeros.len()).sum::<usize>()
            + self.poles_by_modulus.len() * channels.len();
        evaluate(py, channels.len(), &points, &shape, roots, |k, values| {
            let (mantissa, exponent) = mantissa_and_exponent(channels[k].gain);
            factored_response_sorted(
                mantissa,
                exponent,
                &channels[k].zeros_by_modulus,
                &self.poles_by_modulus,
                &points,
                values,
            );
        })
    }
}

/// A complex array of `shape` holding `count` channels' values at `points` (C order, channel
/// by channel), each filled by `fill(k, values)`, with whether every value is finite; an
/// InvalidArgumentError when `shape` does not hold them.
fn evaluate<'py>(
    py: Python<'py>,
    count: usize,
    points: &[c64],
    shape: &[i64],
    roots: usize,
    fill: impl Fn(usize, &mut [c64]) + Send + Sync,
) -> PyResult<(Bound<'py, PyArrayDyn<c64>>, bool)> {
    // A negative extent is no shape: None, as for a count of entries beyond usize.
    let extents: Option<Vec<usize>> = shape.iter().map(|&k| usize::try_from(k).ok()).collect();
    let entries = extents
        .as_ref()
        .and_then(|e| e.iter().try_fold(1usize, |p, &k| p.checked_mul(k)));
    if entries != count.checked_mul(points.len()) {
        return Err(to_py_err(
            py,
            crate::error::Error::InvalidArgument {
                arg: "shape",
                message: format!(
                    "shape {shape:?} does not hold {count} channels at {} points",
                    points.len()
                ),
            },
        ));
    }
    let out = new_array::<c64>(py, extents.as_deref().unwrap_or_default())?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    let cost = Cost {
        flops: 30.0 * roots as f64 * points.len() as f64,
        bytes: 0.0,
        order: 1,
    };
    compute(py, cost, || {
        for (k, values) in data.chunks_mut(points.len().max(1)).enumerate().take(count) {
            fill(k, values);
        }
        Ok(())
    })?;
    // SAFETY: as above; the computation is over.
    let finite = unsafe { new_array_data(&out) }
        .iter()
        .all(|z| z.re.is_finite() && z.im.is_finite());
    Ok((out, finite))
}

/// The channels (output i, input j) of the model (`control/transfer.rs`; None: every channel,
/// output by output): (poles, denominator, FastChannels), a channel of FastChannels None
/// where it is left to the reference path of `aerocontrol.transfer`. The denominator is empty
/// when it overflows.
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
    Bound<'py, FastChannels>,
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
    outputs.finish()?;
    let fast = Bound::new(
        py,
        FastChannels {
            channels: transfer.channels,
            poles_by_modulus: transfer.poles_by_modulus,
        },
    )?;
    Ok((poles, denominator, fast))
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
    shape: Vec<i64>,
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
    let roots = zeros.iter().map(Vec::len).sum::<usize>() + poles.len() * zeros.len();
    evaluate(py, mantissas.len(), &points, &shape, roots, |k, values| {
        factored_response_core(
            mantissas[k],
            exponents[k],
            &zeros[k],
            &poles,
            &points,
            values,
        );
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(transfer_channels, m)?)?;
    m.add_function(wrap_pyfunction!(factored_response, m)?)?;
    m.add_class::<FastChannels>()?;
    Ok(())
}
