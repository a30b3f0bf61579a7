//! Bindings of `aerocontrol.modal`: modes and the characteristic polynomial.

use super::compute::{Cost, compute};
use super::conversion::{Outputs, Real};
use super::errors::to_py_err;
use crate::control::modal::{Mode, modal_analysis as modal_analysis_core, mode_spectrum};
use crate::linalg::charpoly::charpoly as charpoly_core;
use faer::c64;
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The cost of an eigendecomposition with eigenvectors of order n.
pub fn eigen_cost(n: usize) -> Cost {
    Cost::of(30.0 * (n as f64).powi(3), 12.0, n)
}

/// The cost of the eigenvalues of order n by the real Schur form without Z.
fn eigenvalue_cost(n: usize) -> Cost {
    Cost::of(13.0 * (n as f64).powi(3), 3.0, n)
}

/// The modal analysis of A (and P^-1 B if B is given), as a dict of numpy arrays; without
/// `vectors`, only the modes (no modal matrix, its condition numbers or P^-1 B; B is still
/// checked).
#[pyfunction]
#[pyo3(signature = (a, b, vectors, /))]
fn modal_analysis<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: Option<&Bound<'py, PyAny>>,
    vectors: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let a = Real::convert(py, a, "A")?;
    let b = Real::convert_optional(py, b, "B")?;
    let a_matrix = a.matrix().map_err(|e| to_py_err(py, e))?;
    let b_matrix = b
        .as_ref()
        .map(|b| b.matrix())
        .transpose()
        .map_err(|e| to_py_err(py, e))?;
    let n = a_matrix.nrows();
    let mut outputs = Outputs::new(py);
    let result = PyDict::new(py);
    if !vectors {
        let spectrum = compute(py, eigenvalue_cost(n), || mode_spectrum(a_matrix, b_matrix))?;
        set_modes(
            &mut outputs,
            &result,
            &spectrum.eigenvalues,
            &spectrum.modes,
            &spectrum.characteristic_polynomial,
        )?;
        outputs.finish()?;
        return Ok(result);
    }
    let analysis = compute(py, eigen_cost(n), || {
        modal_analysis_core(a_matrix, b_matrix)
    })?;
    set_modes(
        &mut outputs,
        &result,
        &analysis.eigenvalues,
        &analysis.modes,
        &analysis.characteristic_polynomial,
    )?;
    result.set_item(
        "modal_matrix",
        outputs.complex_matrix("the modal matrix", analysis.modal_matrix.as_ref())?,
    )?;
    result.set_item("modal_matrix_condition", analysis.modal_matrix_condition)?;
    result.set_item(
        "balanced_modal_matrix_condition",
        analysis.balanced_modal_matrix_condition,
    )?;
    result.set_item(
        "modal_matrix_is_singular",
        analysis.modal_matrix_is_singular(),
    )?;
    let modal_input = analysis
        .modal_input
        .as_ref()
        .map(|m| outputs.complex_matrix("P^-1 B", m.as_ref()))
        .transpose()?;
    result.set_item("modal_input", modal_input)?;
    outputs.finish()?;
    Ok(result)
}

/// The eigenvalues, the modes' characteristics and the characteristic polynomial into
/// `result`.
fn set_modes<'py>(
    outputs: &mut Outputs<'py>,
    result: &Bound<'py, PyDict>,
    eigenvalues: &[c64],
    modes: &[Mode],
    polynomial: &[f64],
) -> PyResult<()> {
    result.set_item(
        "eigenvalues",
        outputs.complex("the eigenvalues", &[eigenvalues.len()], eigenvalues)?,
    )?;
    let mode_eigenvalues: Vec<c64> = modes.iter().map(|m| m.eigenvalue).collect();
    result.set_item(
        "mode_eigenvalue",
        outputs.complex("the eigenvalues", &[modes.len()], &mode_eigenvalues)?,
    )?;
    result.set_item(
        "oscillatory",
        modes.iter().map(|m| m.oscillatory).collect::<Vec<bool>>(),
    )?;
    result.set_item(
        "mode_indices",
        modes
            .iter()
            .map(|m| (m.indices[0], m.indices[1]))
            .collect::<Vec<_>>(),
    )?;
    // Infinite or NaN by definition for some modes (the period of a real mode): not checked.
    type Characteristic = (&'static str, fn(&Mode) -> f64);
    let characteristics: [Characteristic; 8] = [
        ("natural_frequency", |m| m.natural_frequency),
        ("damping_ratio", |m| m.damping_ratio),
        ("damped_frequency", |m| m.damped_frequency),
        ("period", |m| m.period),
        ("time_to_half", |m| m.time_to_half),
        ("time_to_double", |m| m.time_to_double),
        ("cycles_to_half", |m| m.cycles_to_half),
        ("time_constant", |m| m.time_constant),
    ];
    for (name, characteristic) in characteristics {
        let values: Vec<f64> = modes.iter().map(characteristic).collect();
        result.set_item(name, outputs.real_as_is(&[values.len()], &values)?)?;
    }
    result.set_item(
        "characteristic_polynomial",
        outputs.real(
            "the characteristic polynomial",
            &[polynomial.len()],
            polynomial,
        )?,
    )?;
    Ok(())
}

/// The coefficients [1, a_1, ..., a_n] of det(λI - A).
#[pyfunction]
#[pyo3(signature = (a, /))]
fn charpoly<'py>(py: Python<'py>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = Real::convert(py, a, "A")?;
    let a = a.matrix().map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    let coefficients = compute(py, Cost::of(4.0 * (n as f64).powi(3), 4.0, n), || {
        charpoly_core(a)
    })?;
    let mut outputs = Outputs::new(py);
    let out = outputs.real(
        "the characteristic polynomial",
        &[coefficients.len()],
        &coefficients,
    )?;
    outputs.finish()?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(modal_analysis, m)?)?;
    m.add_function(wrap_pyfunction!(charpoly, m)?)?;
    Ok(())
}
