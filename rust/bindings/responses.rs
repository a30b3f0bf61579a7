//! Bindings of `aerocontrol.responses`: time responses on a uniform grid, and the steady state
//! of a step.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real, new_array, new_array_data};
use super::errors::to_py_err;
use super::linalg::{discretize_cost, hold_from_method};
use super::statespace::ModelArgs;
use crate::control::responses::{
    Input, Model, OUTPUT_PRODUCT_MIN_ORDER, Sampling, dc_gain as dc_gain_core,
    simulate_models_sampled_into, simulate_sampled_into, steady_state as steady_state_core,
    uniform_grid_step,
};
use crate::error::Error;
use faer::MatRef;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

/// The step of a uniform time grid that starts at 0 (an error names `T` otherwise).
#[pyfunction]
#[pyo3(signature = (t, /))]
fn grid_step(py: Python<'_>, t: &Bound<'_, PyAny>) -> PyResult<f64> {
    let t = Real::convert(py, t, "T")?;
    let times = t
        .vector("a 1-D array of times")
        .map_err(|e| to_py_err(py, e))?;
    let cost = Cost {
        flops: times.len() as f64,
        ..Cost::default()
    };
    compute(py, cost, || uniform_grid_step(times, "T"))
}

type SimulationOutput<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

/// The sampling named by `method`: "zoh" or "foh" for a continuous model sampled every `dt`,
/// "discrete" for a discrete model (its own recurrence; `dt` is not used).
fn sampling_from_method(py: Python<'_>, method: &str, dt: f64) -> PyResult<Sampling> {
    if method == "discrete" {
        return Ok(Sampling::Discrete);
    }
    let hold = hold_from_method(py, method)?;
    Ok(Sampling::Continuous { dt, hold })
}

/// The input of a simulation: sampled inputs `u` if given, else a constant `eta0` if given, else
/// none.
///
/// Each is checked against the simulation's own shape: `u` of shape (responses, steps, m) and
/// `eta0` of shape `eta_shape` ((m,) for one model, (models, m) for a stack).
fn simulation_input<'a>(
    u: Option<&'a Real>,
    eta0: Option<&'a Real>,
    (responses, steps, m): (usize, usize, usize),
    eta_shape: &[usize],
) -> Result<Input<'a>, Error> {
    let shaped = |argument: &'a Real, shape: &[usize], expected: &'static str| {
        if argument.shape() == shape {
            Ok(argument.values())
        } else {
            Err(Error::WrongDimensions {
                arg: argument.name(),
                expected,
                shape: argument.shape().to_vec(),
            })
        }
    };
    Ok(match (u, eta0) {
        (Some(u), _) => Input::Sampled(shaped(
            u,
            &[responses, steps, m],
            "of shape (responses, times, inputs)",
        )?),
        (None, Some(eta)) => Input::Constant(shaped(
            eta,
            eta_shape,
            "one value per input (for a stack of models, one row per model)",
        )?),
        (None, None) => Input::Free,
    })
}

/// The work of `responses` responses of `steps` samples of a model (n, m, p), after its
/// discretisation.
fn simulation_cost(responses: usize, steps: usize, n: usize, m: usize, p: usize) -> Cost {
    let per_step = 2.0 * ((n + p) * (n + m)) as f64 + 1.0;
    let recurrence = responses as f64 * steps as f64 * per_step;
    let discretization = discretize_cost(n, m);
    // From order OUTPUT_PRODUCT_MIN_ORDER the outputs are one product over all samples.
    let outputs_order = if n >= OUTPUT_PRODUCT_MIN_ORDER {
        steps
    } else {
        0
    };
    Cost {
        flops: discretization.flops + recurrence,
        order: discretization.order.max(outputs_order),
        ..discretization
    }
}

/// States (r, steps, n) and outputs (r, steps, p) of r responses from the initial states
/// x0 (r, n): free (u and eta0 None), a constant input eta0 (m), or sampled inputs u
/// (r, steps, m) with a zero- or first-order hold ("zoh", "foh"), or of a discrete model
/// ("discrete", dt unused).
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
    let sampling = sampling_from_method(py, method, dt)?;
    let args = ModelArgs::convert(py, a, b, c, d)?;
    let x0 = Real::convert(py, x0, "x0")?;
    let u = Real::convert_optional(py, u, "u")?;
    let eta0 = Real::convert_optional(py, eta0, "eta0")?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let (n, m, p) = (model.a.nrows(), model.b.ncols(), model.c.nrows());
    let x0 = match *x0.shape() {
        [_, states] if states == n => x0.matrix().map_err(|e| to_py_err(py, e))?,
        _ => {
            let error = Error::WrongDimensions {
                arg: "x0",
                expected: "one initial state per response, of the order of A",
                shape: x0.shape().to_vec(),
            };
            return Err(to_py_err(py, error));
        }
    };
    let responses = x0.nrows();
    let input = simulation_input(u.as_ref(), eta0.as_ref(), (responses, steps, m), &[m])
        .map_err(|e| to_py_err(py, e))?;
    let x = new_array::<f64>(py, &[responses, steps, n])?;
    let y = new_array::<f64>(py, &[responses, steps, p])?;
    // SAFETY: both arrays are new and not visible to Python until returned.
    let (x_data, y_data) = unsafe { (new_array_data(&x), new_array_data(&y)) };
    let cost = simulation_cost(responses, steps, n, m, p);
    compute(py, cost, || {
        simulate_sampled_into(model, x0, input, sampling, steps, x_data, y_data)
    })?;
    finish_simulation(py, &x, &y)?;
    Ok((x, y))
}

/// Warns if the states or outputs of a simulation overflowed.
fn finish_simulation(
    py: Python<'_>,
    x: &Bound<'_, PyArrayDyn<f64>>,
    y: &Bound<'_, PyArrayDyn<f64>>,
) -> PyResult<()> {
    let mut outputs = Outputs::new(py);
    // SAFETY: the arrays are new, the computation that wrote them is over, and they are not
    // yet visible to Python.
    unsafe {
        outputs.check("the states x", new_array_data(x));
        outputs.check("the outputs y", new_array_data(y));
    }
    outputs.finish()
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
    let sampling = sampling_from_method(py, method, dt)?;
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert(py, b, "B")?;
    let c = Real::convert(py, c, "C")?;
    let d = Real::convert(py, d, "D")?;
    let x0 = Real::convert(py, x0, "x0")?;
    let u = Real::convert_optional(py, u, "u")?;
    let eta0 = Real::convert_optional(py, eta0, "eta0")?;
    let stacks = (|| {
        let stacks = (a.stack()?, b.stack()?, c.stack()?, d.stack()?);
        let q = stacks.0.len();
        for (arg, stack) in [("B", &stacks.1), ("C", &stacks.2), ("D", &stacks.3)] {
            if stack.len() != q {
                return Err(Error::Mismatch {
                    arg,
                    what: "as many models as",
                    expected: q,
                    other: "A",
                    got: stack.len(),
                });
            }
        }
        Ok(stacks)
    })()
    .map_err(|e| to_py_err(py, e))?;
    let q = stacks.0.len();
    let (n, m, p) = (a.shape()[1], b.shape()[2], c.shape()[1]);
    let models: Vec<Model<'_>> = (0..q)
        .map(|i| Model {
            a: stacks.0.get(i),
            b: stacks.1.get(i),
            c: stacks.2.get(i),
            d: stacks.3.get(i),
        })
        .collect();
    let input = simulation_input(u.as_ref(), eta0.as_ref(), (q, steps, m), &[q, m])
        .map_err(|e| to_py_err(py, e))?;
    let x0 = match *x0.shape() {
        [models, states] if (models, states) == (q, n) => {
            x0.matrix().map_err(|e| to_py_err(py, e))?
        }
        _ => {
            let error = Error::WrongDimensions {
                arg: "x0",
                expected: "one initial state per model, of the order of A",
                shape: x0.shape().to_vec(),
            };
            return Err(to_py_err(py, error));
        }
    };
    let x = new_array::<f64>(py, &[q, steps, n])?;
    let y = new_array::<f64>(py, &[q, steps, p])?;
    // SAFETY: both arrays are new and not visible to Python until returned.
    let (x_data, y_data) = unsafe { (new_array_data(&x), new_array_data(&y)) };
    let cost = simulation_cost(1, steps, n, m, p).times(q);
    compute(py, cost, || {
        simulate_models_sampled_into(&models, x0, input, sampling, steps, x_data, y_data)
    })?;
    finish_simulation(py, &x, &y)?;
    Ok((x, y))
}

/// -A^-1 B eta0, the steady state of a step (6.45): 1-D for one input vector eta0, n x k for
/// the k columns of a 2-D eta0. With `warn` false a result that overflows comes without the
/// NumericalOverflowWarning (for a caller that warns about what it makes of it).
#[pyfunction]
#[pyo3(signature = (a, b, eta0, warn, /))]
fn steady_state<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    eta0: &Bound<'py, PyAny>,
    warn: bool,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert(py, b, "B")?;
    let eta0 = Real::convert(py, eta0, "eta0")?;
    let (a, b) = (|| Ok((a.matrix()?, b.matrix()?)))().map_err(|e| to_py_err(py, e))?;
    // One input vector (1-D, one steady state), or one per column (2-D).
    let single = eta0.shape().len() == 1;
    let weights = if single {
        let values = eta0
            .vector("a 1-D array of one value per input")
            .map_err(|e| to_py_err(py, e))?;
        MatRef::from_column_major_slice(values, values.len(), 1)
    } else {
        eta0.matrix().map_err(|e| to_py_err(py, e))?
    };
    let n = a.nrows();
    let cost = Cost::of(2.0 * (n as f64).powi(3), 3.0, n);
    let x = compute(py, cost, || steady_state_core(a, b, weights))?;
    let mut outputs = Outputs::new(py);
    let out = if single {
        outputs.real("the steady state", &[n], x.col_as_slice(0))?
    } else {
        outputs.matrix("the steady state", x.as_ref())?
    };
    if warn {
        outputs.finish()?;
    }
    Ok(out)
}

/// D - C A^-1 B, the DC gain (p x m) of a continuous model, from one LU factorisation; the
/// error of a singular A names its eigenvalue at zero. A gain that overflows comes with a
/// NumericalOverflowWarning.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, /))]
fn dc_gain<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let args = ModelArgs::convert(py, a, b, c, d)?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let n = model.a.nrows();
    let cost = Cost::of(2.0 * (n as f64).powi(3), 3.0, n);
    let gain = compute(py, cost, || {
        dc_gain_core(model.a, model.b, model.c, model.d)
    })?;
    let mut outputs = Outputs::new(py);
    let out = outputs.matrix("the DC gain", gain.as_ref())?;
    outputs.finish()?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(dc_gain, m)?)?;
    m.add_function(wrap_pyfunction!(grid_step, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_models, m)?)?;
    m.add_function(wrap_pyfunction!(steady_state, m)?)?;
    Ok(())
}
