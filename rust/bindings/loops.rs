//! Bindings of `aerocontrol.loops`: the crossovers and peaks of a SISO loop.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real, new_array, new_array_data};
use super::errors::to_py_err;
use super::statespace::ModelArgs;
use crate::control::margins::{
    Crossover, CrossoverMargins, census_off_axis, crossover_margins as crossover_margins_core,
    loop_margins as loop_margins_core, within_range,
};
use crate::control::root_locus::{
    loop_root_locus as loop_root_locus_core, root_locus as root_locus_core,
};
use crate::error::Error;
use crate::linalg::balance::{
    balanced_loop as balanced_loop_core, balanced_states,
    states_scaled_apart as states_scaled_apart_core,
};
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;

/// The crossover margins as `loops.py`'s `_assemble` takes them: (the five parts of
/// [`CrossoverMargins::values`] in one array, (their counts g and c), (the critical gain
/// margin and its crossover, the critical phase margin and its crossover, the least delay
/// margin)).
type CrossoverOutput<'py> = (
    Bound<'py, PyArrayDyn<f64>>,
    (usize, usize),
    (f64, f64, f64, f64, f64),
);

type MarginsOutput<'py> = (
    CrossoverOutput<'py>,
    (f64, f64),
    (f64, f64),
    Bound<'py, PyArrayDyn<c64>>,
    Bound<'py, PyArrayDyn<c64>>,
    bool,
    f64,
    f64,
    Option<(usize, bool)>,
    Option<(usize, bool)>,
);

fn crossover_output<'py>(
    outputs: &mut Outputs<'py>,
    margins: &CrossoverMargins,
) -> PyResult<CrossoverOutput<'py>> {
    Ok((
        outputs.real_as_is(&[margins.values.len()], &margins.values)?,
        (margins.gain_margins, margins.phase_margins),
        (
            margins.gain_margin.0,
            margins.gain_margin.1,
            margins.phase_margin.0,
            margins.phase_margin.1,
            margins.delay_margin,
        ),
    ))
}

/// The margins of the crossovers (ω, (Re L(jω), Im L(jω))) of a SISO loop, each list by increasing ω
/// ([`crossover_margins`]): the crossover part of [`loop_margins`]'s result, for the margins
/// found on a frequency grid.
#[pyfunction]
#[pyo3(signature = (phase_omega, phase_values, gain_omega, gain_values, /))]
fn crossover_margins<'py>(
    py: Python<'py>,
    phase_omega: Vec<f64>,
    phase_values: Vec<(f64, f64)>,
    gain_omega: Vec<f64>,
    gain_values: Vec<(f64, f64)>,
) -> PyResult<CrossoverOutput<'py>> {
    let pair = |omega: Vec<f64>, values: Vec<(f64, f64)>, name: &'static str| {
        if omega.len() != values.len() {
            return Err(to_py_err(
                py,
                Error::InvalidArgument {
                    arg: name,
                    message: format!(
                        "{name} must have as many frequencies as values, got {} and {}",
                        omega.len(),
                        values.len()
                    ),
                },
            ));
        }
        // A crossover is at a frequency ω >= 0 with a finite L(jω): the margins divide by ω
        // and take the phase of L.
        let finite = |x: f64| x.is_finite();
        if let Some(k) = (0..omega.len()).find(|&k| {
            !(finite(omega[k]) && omega[k] >= 0.0 && finite(values[k].0) && finite(values[k].1))
        }) {
            return Err(to_py_err(
                py,
                Error::InvalidArgument {
                    arg: name,
                    message: format!(
                        "{name} must be at finite frequencies >= 0 with finite values, got \
                         ω = {} with L = {} + {}j at index {k}",
                        omega[k], values[k].0, values[k].1
                    ),
                },
            ));
        }
        Ok(omega
            .into_iter()
            .zip(values)
            .map(|(omega, (re, im))| Crossover {
                omega,
                value: c64::new(re, im),
            })
            .collect::<Vec<_>>())
    };
    let phase = pair(phase_omega, phase_values, "phase crossovers")?;
    let gain = pair(gain_omega, gain_values, "gain crossovers")?;
    let mut outputs = Outputs::new(py);
    let result = crossover_output(&mut outputs, &crossover_margins_core(&phase, &gain))?;
    outputs.finish()?;
    Ok(result)
}

/// The crossovers of the continuous SISO loop L(s) = C (sI - A)^-1 B + D by eigenvalue
/// methods (`control/margins.rs`): (gain-crossover ω, L there, phase-crossover ω, L there,
/// (ω, max |1 - L|/(2|1 + L|)), (ω, max 1/|1 + L|), closed-loop poles, open-loop poles,
/// degenerate, the Frobenius norms of the closed loop and of A each balanced alone), every
/// gain margin verified by a closed-loop pole, the closed-loop poles sorted as
/// `numpy.sort_complex`; None, before any work, for a loop with a term beyond
/// 2^RESCALE_EXPONENT ([`within_range`]), which the caller slows first.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, /))]
fn loop_margins<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: &Bound<'py, PyAny>,
) -> PyResult<Option<MarginsOutput<'py>>> {
    let args = ModelArgs::convert(py, a, b, c, d)?;
    let model = args.model().map_err(|e| to_py_err(py, e))?;
    if model.d.nrows() == 1
        && model.d.ncols() == 1
        && !within_range(model.a, model.b, model.c, model.d[(0, 0)])
    {
        return Ok(None);
    }
    let n = model.a.nrows();
    // A few eigenvalue problems of order 2n (Hamiltonians) and a QZ of order 2n + 1, each
    // about 25 (2n)^3 flops, and some hundred O(n^2) evaluations.
    let order = 2 * n + 1;
    let cost = Cost::of(10.0 * 25.0 * (order as f64).powi(3), 12.0, order);
    let margins = compute(py, cost, || {
        loop_margins_core(model.a, model.b, model.c, model.d)
    })?;
    let mut outputs = Outputs::new(py);
    for (name, found) in [
        ("gain crossovers", &margins.gain_crossovers),
        ("phase crossovers", &margins.phase_crossovers),
    ] {
        let omegas: Vec<f64> = found.iter().map(|x| x.omega).collect();
        let values: Vec<c64> = found.iter().map(|x| x.value).collect();
        outputs.check(name, &omegas);
        outputs.check_complex(name, &values);
    }
    let crossovers = crossover_margins_core(&margins.phase_crossovers, &margins.gain_crossovers);
    let result = (
        crossover_output(&mut outputs, &crossovers)?,
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
        margins.closed_loop_size,
        margins.open_loop_size,
        census_off_axis(&margins.closed_loop_poles, margins.closed_loop_size),
        census_off_axis(&margins.open_loop_poles, margins.open_loop_size),
    );
    outputs.finish()?;
    Ok(Some(result))
}

/// The closed-loop poles of the SISO loop (A, b, c) at each closed-loop gain g of `gains`: the
/// eigenvalues of A - g b c, a (k, n) complex array, each row sorted as `numpy.sort_complex`
/// sorts (`control/root_locus.rs`: one controller-Hessenberg form, then the QR iteration per
/// gain, in parallel).
#[pyfunction]
#[pyo3(signature = (a, b, c, gains, /))]
fn root_locus<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    gains: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<c64>>> {
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert(py, b, "B")?;
    let c = Real::convert(py, c, "C")?;
    let gains = Real::convert(py, gains, "gains")?;
    let (a, b, c) = (
        a.matrix().map_err(|e| to_py_err(py, e))?,
        b.matrix().map_err(|e| to_py_err(py, e))?,
        c.matrix().map_err(|e| to_py_err(py, e))?,
    );
    let gains = gains
        .vector("a 1-D array of gains")
        .map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    let out = new_array::<c64>(py, &[gains.len(), n])?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    // Per gain the double-shift QR iteration of a Hessenberg matrix (about 10 n^3 flops).
    let threads = crate::platform::threads::num_threads() as f64;
    let cost = Cost {
        flops: 10.0 * (n as f64).powi(3) * (gains.len() as f64 + 2.0),
        bytes: 3.0 * threads * (n * n) as f64 * 8.0,
        order: n,
    };
    compute(py, cost, || root_locus_core(a, b, c, gains, data))?;
    let mut outputs = Outputs::new(py);
    // SAFETY: as above; the computation is over.
    outputs.check_complex("the closed-loop poles", unsafe { new_array_data(&out) });
    outputs.finish()?;
    Ok(out)
}

/// The closed-loop poles of 1 + k L(s) = 0 for the open loop L = (A, B, C, D) (one input, one
/// output) at each loop gain k of `gains`, in one call (`control/root_locus.rs`,
/// loop_root_locus): the states balanced for the closed loops (`linalg/balance.rs`,
/// balanced_loop), g = k (1 + k D)^-1, then the poles as [`root_locus`] computes them, a (k, n)
/// complex array, each row sorted as `numpy.sort_complex`; None, before the poles, where a
/// term of a closed loop may exceed 2^RESCALE_EXPONENT (the caller scales those first).
#[pyfunction]
#[pyo3(signature = (a, b, c, d, gains, /))]
fn loop_root_locus<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    d: f64,
    gains: &Bound<'py, PyAny>,
) -> PyResult<Option<Bound<'py, PyArrayDyn<c64>>>> {
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert(py, b, "B")?;
    let c = Real::convert(py, c, "C")?;
    let gains = Real::convert(py, gains, "gains")?;
    let (a, b, c) = (
        a.matrix().map_err(|e| to_py_err(py, e))?,
        b.matrix().map_err(|e| to_py_err(py, e))?,
        c.matrix().map_err(|e| to_py_err(py, e))?,
    );
    let gains = gains
        .vector("a 1-D array of gains")
        .map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    let out = new_array::<c64>(py, &[gains.len(), n])?;
    // SAFETY: new and not visible to Python until returned.
    let data = unsafe { new_array_data(&out) };
    let threads = crate::platform::threads::num_threads() as f64;
    let cost = Cost {
        flops: 10.0 * (n as f64).powi(3) * (gains.len() as f64 + 2.0),
        bytes: 3.0 * threads * (n * n) as f64 * 8.0,
        order: n,
    };
    if !compute(py, cost, || loop_root_locus_core(a, b, c, d, gains, data))? {
        return Ok(None);
    }
    let mut outputs = Outputs::new(py);
    // SAFETY: as above; the computation is over.
    outputs.check_complex("the closed-loop poles", unsafe { new_array_data(&out) });
    outputs.finish()?;
    Ok(Some(out))
}

/// The loop (A, B, C) with its states balanced for the closed loops A - g B C
/// (`linalg/balance.rs`, balanced_loop): two balancings of [[A, B], [C, 0]] by diagonal
/// similarities of powers of two, the second with B and C brought to the size of A balanced
/// alone, then scaled back; (A, B, C) as given with no states or an entry not finite.
#[pyfunction]
#[pyo3(signature = (a, b, c, /))]
#[allow(clippy::type_complexity)]
fn balanced_loop<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
)> {
    balanced_system(py, (a, b, c), balanced_loop_core)
}

/// InvalidArgumentError unless A is n x n, B n x m and C p x n.
fn check_system_shapes(
    py: Python<'_>,
    a: faer::MatRef<'_, f64>,
    b: faer::MatRef<'_, f64>,
    c: faer::MatRef<'_, f64>,
) -> PyResult<()> {
    let n = a.nrows();
    if a.ncols() != n || b.nrows() != n || c.ncols() != n {
        return Err(to_py_err(
            py,
            Error::InvalidArgument {
                arg: "A",
                message: format!(
                    "A must be n x n, B n x m and C p x n, got A {} x {}, B {} x {} and C {} x {}",
                    a.nrows(),
                    a.ncols(),
                    b.nrows(),
                    b.ncols(),
                    c.nrows(),
                    c.ncols()
                ),
            },
        ));
    }
    Ok(())
}

/// The system (A, B, C) with its states balanced by a diagonal similarity of powers of two,
/// (T A T^-1, T B, C T^-1) (`linalg/balance.rs`, balanced_states): the same transfer matrix,
/// the rows and columns of [[A, B], [C, 0]] of one size; (A, B, C) as given where the scaling
/// would not be exact.
#[pyfunction]
#[pyo3(signature = (a, b, c, /))]
#[allow(clippy::type_complexity)]
fn balance_states<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
)> {
    balanced_system(py, (a, b, c), |a, b, c| {
        balanced_states(a, b, c).unwrap_or_else(|| (a.to_owned(), b.to_owned(), c.to_owned()))
    })
}

/// The system (A, B, C) converted and checked, through `balance`, as three arrays.
#[allow(clippy::type_complexity)]
fn balanced_system<'py>(
    py: Python<'py>,
    (a, b, c): (&Bound<'py, PyAny>, &Bound<'py, PyAny>, &Bound<'py, PyAny>),
    balance: impl FnOnce(
        faer::MatRef<'_, f64>,
        faer::MatRef<'_, f64>,
        faer::MatRef<'_, f64>,
    ) -> (faer::Mat<f64>, faer::Mat<f64>, faer::Mat<f64>),
) -> PyResult<(
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
)> {
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert(py, b, "B")?;
    let c = Real::convert(py, c, "C")?;
    let (a, b, c) = (
        a.matrix().map_err(|e| to_py_err(py, e))?,
        b.matrix().map_err(|e| to_py_err(py, e))?,
        c.matrix().map_err(|e| to_py_err(py, e))?,
    );
    check_system_shapes(py, a, b, c)?;
    let (am, bm, cm) = balance(a, b, c);
    let mut outputs = Outputs::new(py);
    let result = (
        outputs.matrix("A", am.as_ref())?,
        outputs.matrix("B", bm.as_ref())?,
        outputs.matrix("C", cm.as_ref())?,
    );
    outputs.finish()?;
    Ok(result)
}

/// Whether some state of the square matrix A is scaled apart from the others
/// (`linalg/balance.rs`, states_scaled_apart: its row's and its column's largest off-diagonal
/// magnitudes more than 2^10 apart): the cheap test before a balancing. False for a matrix that
/// is not square (its caller refuses it by name); a NaN entry is passed over.
#[pyfunction]
#[pyo3(signature = (a, /))]
fn states_scaled_apart(py: Python<'_>, a: &Bound<'_, PyAny>) -> PyResult<bool> {
    let a = Real::convert(py, a, "A")?;
    let a = a.matrix().map_err(|e| to_py_err(py, e))?;
    Ok(a.nrows() == a.ncols() && states_scaled_apart_core(a))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(states_scaled_apart, m)?)?;
    m.add_function(wrap_pyfunction!(balance_states, m)?)?;
    m.add_function(wrap_pyfunction!(balanced_loop, m)?)?;
    m.add_function(wrap_pyfunction!(loop_root_locus, m)?)?;
    m.add_function(wrap_pyfunction!(loop_margins, m)?)?;
    m.add_function(wrap_pyfunction!(crossover_margins, m)?)?;
    m.add_function(wrap_pyfunction!(root_locus, m)?)?;
    Ok(())
}
