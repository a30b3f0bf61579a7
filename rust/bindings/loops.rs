//! Bindings of `aerocontrol.loops`: the crossovers and peaks of a SISO loop.

use super::compute::{Cost, compute};
use super::conversion::Outputs;
use super::errors::to_py_err;
use super::statespace::ModelArgs;
use crate::control::margins::{Crossover, loop_margins as loop_margins_core};
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

type MarginsOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<c64>>,
    (f64, f64),
    (f64, f64),
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<c64>>,
    bool,
);

/// The crossovers of the continuous SISO loop L(s) = C (sI - A)^-1 B + D by eigenvalue
/// methods (`control/margins.rs`): (gain-crossover ω, L there, phase-crossover ω, L there,
/// (ω, max |1 - L|/(2|1 + L|)), (ω, max 1/|1 + L|), closed-loop poles, open-loop poles,
/// degenerate), every gain margin verified by a closed-loop pole.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, /))]
fn loop_margins<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
) -> PyResult<MarginsOutput<'py>> {
    let args = ModelArgs::convert(py, a, b, c, d)?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    let n = model.a.nrows();
    // A few eigenvalue problems of order 2n (Hamiltonians) and a QZ of order 2n + 1, each
    // about 25 (2n)^3 flops, and some hundred O(n^2) evaluations.
    let order = 2 * n + 1;
    let cost = Cost::of(10.0 * 25.0 * (order as f64).powi(3), 12.0, order);
    let margins = compute(py, cost, || {
        loop_margins_core(model.a, model.b, model.c, model.d)
    })?;
    let mut outputs = Outputs::new(py);
    let split = |x: &[Crossover]| -> (Vec<f64>, Vec<c64>) {
        (
            x.iter().map(|c| c.omega).collect(),
            x.iter().map(|c| c.value).collect(),
        )
    };
    let (gain_w, gain_v) = split(&margins.gain_crossovers);
    let (phase_w, phase_v) = split(&margins.phase_crossovers);
    let result = (
        outputs.real("gain crossovers", &[gain_w.len()], &gain_w)?,
        outputs.complex("L at the gain crossovers", &[gain_v.len()], &gain_v)?,
        outputs.real("phase crossovers", &[phase_w.len()], &phase_w)?,
        outputs.complex("L at the phase crossovers", &[phase_v.len()], &phase_v)?,
        (margins.disk.omega, margins.disk.value),
        (margins.sensitivity.omega, margins.sensitivity.value),
        outputs.complex(
            "closed-loop poles",
            &[margins.closed_loop_poles.len()],
            &margins.closed_loop_poles,
        )?,
        outputs.complex(
            "open-loop poles",
            &[margins.open_loop_poles.len()],
            &margins.open_loop_poles,
        )?,
        margins.degenerate,
    );
    outputs.finish()?;
    Ok(result)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(loop_margins, m)?)?;
    Ok(())
}
