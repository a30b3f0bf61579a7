//! Bindings of `aerocontrol.placement`: the companion form and pole placement.

use super::compute::{Cost, compute};
use super::conversion::{Complex, Outputs, Real, python_function};
use super::errors::{Class, raise, to_py_err, warn};
use crate::control::batch::Placer;
use crate::control::placement::{
    ILL_CONDITIONED_CONTROLLABILITY, POLE_ERROR_WARNING, companion_form as companion_form_core,
    place as place_core, place_ackermann, place_bass_gura,
};
use crate::error::Error;
use faer::c64;
use numpy::{PyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::PyTypeInfo;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyFloat, PyString, PyType};

/// The cost of placing the poles of an n-state model by `method`: the robust method's sweeps
/// each solve n small least-squares problems; the single-input formulas form and invert the
/// controllability matrix.
pub fn placement_cost(method: &str, n: usize, m: usize) -> Cost {
    let cube = (n as f64).powi(3);
    match method {
        "knv0" => Cost::of(
            40.0 * cube * (1.0 + m as f64 / n.max(1) as f64),
            12.0,
            n.max(m),
        ),
        _ => Cost::of(10.0 * cube, 8.0, n),
    }
}

/// The companion-form transformation (6.116)-(6.145) as a dict.
#[pyfunction]
#[pyo3(signature = (a, b, /))]
fn companion_form<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let (a, b) = (|| Ok((a.matrix()?, b.input_column()?)))().map_err(|e| to_py_err(py, e))?;
    let n = a.nrows();
    let form = compute(py, Cost::of(10.0 * (n as f64).powi(3), 8.0, n), || {
        companion_form_core(a, b)
    })?;
    let mut outputs = Outputs::new(py);
    let result = PyDict::new(py);
    result.set_item("V", outputs.matrix("V", form.v.as_ref())?)?;
    result.set_item("W", outputs.matrix("W", form.w.as_ref())?)?;
    result.set_item("T", outputs.matrix("T", form.t.as_ref())?)?;
    result.set_item(
        "companion",
        outputs.matrix("the companion matrix", form.companion.as_ref())?,
    )?;
    let coefficients = &form.coefficients;
    result.set_item(
        "coefficients",
        outputs.real("the coefficients", &[coefficients.len()], coefficients)?,
    )?;
    outputs.finish()?;
    Ok(result)
}

/// The placement algorithm named by `method`: "bass-gura", "ackermann" or "knv0".
pub fn placer_for(py: Python<'_>, method: &str) -> PyResult<Placer> {
    match method {
        "bass-gura" => Ok(place_bass_gura),
        "ackermann" => Ok(place_ackermann),
        "knv0" => Ok(place_core),
        other => Err(raise(
            py,
            Class::InvalidArgumentError,
            format!("unknown placement method {other:?}"),
        )),
    }
}

/// A state-feedback design η = -K x (6.91).
///
/// ``k`` is the gain vector of a single-input design (the chapter's k^T = `K[0]`).
// Built here rather than as a Python dataclass, whose construction costs a sixth of a whole
// 4-state design called from Python.
#[pyclass(frozen, module = "aerocontrol", name = "Placement")]
struct PlacementResult {
    /// The gain matrix, m x n.
    #[pyo3(get, name = "K")]
    gain: Py<PyArrayDyn<f64>>,
    /// A - B K (6.93).
    #[pyo3(get)]
    closed_loop: Py<PyArrayDyn<f64>>,
    /// The requested poles, each conjugate pair adjacent with Im > 0 first.
    #[pyo3(get)]
    poles: Py<PyArrayDyn<c64>>,
    /// The eigenvalues of the computed A - B K, matched to ``poles``.
    #[pyo3(get)]
    achieved_poles: Py<PyArrayDyn<c64>>,
    /// max abs(achieved - requested) / abs(requested) (relative to ||A - BK||_F for a pole
    /// at 0).
    #[pyo3(get)]
    max_relative_error: f64,
    /// Sweeps of the robust method; 0 for the single-input formulas.
    #[pyo3(get)]
    iterations: usize,
    /// Whether the robust method met its tolerance (always True for the single-input
    /// formulas).
    #[pyo3(get)]
    converged: bool,
    /// The method's name.
    #[pyo3(get)]
    method: Py<PyString>,
    /// κ_1(V) for the single-input formulas, NaN for the robust method.
    #[pyo3(get)]
    controllability_condition: f64,
    /// κ_2(X) of the closed-loop eigenvectors for the robust method, NaN otherwise.
    #[pyo3(get)]
    eigenvector_condition: f64,
}

/// `aerocontrol.placement._placement_arguments`: (A, B, poles) of a call that is not read as
/// given ([`read_as_given`]): a system, lists, a 1-D B, poles as a column.
static PLACEMENT_ARGUMENTS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

/// Whether `place*(A, B, poles)` is the common call, read as given: A and B 2-D float64 numpy
/// arrays (exactly ndarray, any memory layout: the conversion copies it) and the poles given,
/// other than a complex array of more or fewer than one dimension (which `_poles` reads as
/// python-control does). Deciding here rather than in Python saves the wrapper's test.
fn read_as_given(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    poles: &Bound<'_, PyAny>,
) -> bool {
    let ndarray = PyUntypedArray::type_object(py);
    let matrix = |x: &Bound<'_, PyAny>| {
        x.get_type().is(&ndarray)
            && x.cast::<PyArrayDyn<f64>>()
                .is_ok_and(|array| array.ndim() == 2)
    };
    matrix(a)
        && matrix(b)
        && !poles.is_none()
        && poles
            .cast::<PyArrayDyn<c64>>()
            .map_or(true, |array| array.ndim() == 1)
}

/// `aerocontrol.placement._describe`, the text of a design (`str`).
static DESCRIBE_PLACEMENT: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

#[pymethods]
impl PlacementResult {
    #[new]
    #[pyo3(signature = (K, closed_loop, poles, achieved_poles, max_relative_error, iterations,
        converged, method, controllability_condition, eigenvector_condition))]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        K: Py<PyArrayDyn<f64>>,
        closed_loop: Py<PyArrayDyn<f64>>,
        poles: Py<PyArrayDyn<c64>>,
        achieved_poles: Py<PyArrayDyn<c64>>,
        max_relative_error: f64,
        iterations: usize,
        converged: bool,
        method: Py<PyString>,
        controllability_condition: f64,
        eigenvector_condition: f64,
    ) -> PyResult<Self> {
        // The getters and `__str__` index these: shapes checked once, here.
        let (gain_shape, loop_shape) = (K.bind(py).shape(), closed_loop.bind(py).shape());
        let (requested, achieved) = (poles.bind(py).shape(), achieved_poles.bind(py).shape());
        let consistent = matches!(loop_shape, &[rows, cols] if rows == cols)
            && matches!(gain_shape, &[_, cols] if cols == loop_shape[0])
            && requested == [loop_shape[0]]
            && achieved == requested;
        if !consistent {
            return Err(raise(
                py,
                Class::ShapeError,
                format!(
                    "Placement needs K (m, n), closed_loop (n, n) and poles and \
                     achieved_poles (n,); got shapes {gain_shape:?}, {loop_shape:?}, \
                     {requested:?} and {achieved:?}"
                ),
            ));
        }
        Ok(Self {
            gain: K,
            closed_loop,
            poles,
            achieved_poles,
            max_relative_error,
            iterations,
            converged,
            method,
            controllability_condition,
            eigenvector_condition,
        })
    }

    /// The gain vector of a single-input design, shape (n,).
    #[getter]
    fn k<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let gain = self.gain.bind(py);
        let inputs = gain.shape()[0];
        if inputs != 1 {
            return Err(raise(
                py,
                Class::ShapeError,
                format!("k is defined for one input; this design has {inputs}"),
            ));
        }
        gain.get_item(0)
    }

    fn __str__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let py = slf.py();
        let describe = DESCRIBE_PLACEMENT.get_or_try_init(py, || {
            PyModule::import(py, "aerocontrol.placement")?
                .getattr("_describe")
                .map(Bound::unbind)
        })?;
        describe.bind(py).call1((slf,))?.extract()
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let reprs = [
            self.gain.bind(py).repr()?,
            self.closed_loop.bind(py).repr()?,
            self.poles.bind(py).repr()?,
            self.achieved_poles.bind(py).repr()?,
            self.method.bind(py).repr()?,
            PyFloat::new(py, self.max_relative_error).repr()?,
            PyFloat::new(py, self.controllability_condition).repr()?,
            PyFloat::new(py, self.eigenvector_condition).repr()?,
        ];
        Ok(format!(
            "Placement(K={}, closed_loop={}, poles={}, achieved_poles={}, \
             max_relative_error={}, iterations={}, converged={}, method={}, \
             controllability_condition={}, eigenvector_condition={})",
            reprs[0],
            reprs[1],
            reprs[2],
            reprs[3],
            reprs[5],
            self.iterations,
            if self.converged { "True" } else { "False" },
            reprs[4],
            reprs[6],
            reprs[7],
        ))
    }

    /// Pickling: the constructor's arguments.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, PyType>,
        (
            Py<PyArrayDyn<f64>>,
            Py<PyArrayDyn<f64>>,
            Py<PyArrayDyn<c64>>,
            Py<PyArrayDyn<c64>>,
            f64,
            usize,
            bool,
            Py<PyString>,
            f64,
            f64,
        ),
    ) {
        let py = slf.py();
        let design = slf.get();
        (
            slf.get_type(),
            (
                design.gain.clone_ref(py),
                design.closed_loop.clone_ref(py),
                design.poles.clone_ref(py),
                design.achieved_poles.clone_ref(py),
                design.max_relative_error,
                design.iterations,
                design.converged,
                design.method.clone_ref(py),
                design.controllability_condition,
                design.eigenvector_condition,
            ),
        )
    }
}

/// Pole placement by `method` ("bass-gura", "ackermann" or "knv0"; the single-input ones
/// take b as a vector or an n x 1 matrix), as a `Placement`. Warns (IllConditionedWarning, at
/// the caller of the Python wrapper) when an achieved pole misses by more than
/// `POLE_ERROR_WARNING` relatively or κ(V) reaches `ILL_CONDITIONED_CONTROLLABILITY`.
#[pyfunction]
#[pyo3(signature = (a, b, poles, method, /))]
fn place<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    poles: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<Bound<'py, PlacementResult>> {
    let placer = placer_for(py, method)?;
    let read;
    let (a, b, poles) = if read_as_given(py, a, b, poles) {
        (a, b, poles)
    } else {
        read = python_function(
            py,
            &PLACEMENT_ARGUMENTS,
            "aerocontrol.placement",
            "_placement_arguments",
        )?
        .call1((a, b, poles))?
        .extract::<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyAny>)>()?;
        (&read.0, &read.1, &read.2)
    };
    let (a, b) = (Real::convert(py, a, "A")?, Real::convert(py, b, "B")?);
    let poles = Complex::poles(py, poles)?;
    let (a, b) = (|| {
        let a = a.matrix()?;
        // A single-input method takes b as a vector too.
        let b = if method == "knv0" {
            b.matrix()?
        } else {
            b.input_column()?
        };
        Ok((a, b))
    })()
    .map_err(|e| to_py_err(py, e))?;
    if poles.shape.len() != 1 {
        let error = Error::WrongDimensions {
            arg: "poles",
            expected: "a 1-D array of poles",
            shape: poles.shape.clone(),
        };
        return Err(to_py_err(py, error));
    }
    let requested = &poles.values;
    let cost = placement_cost(method, a.nrows(), b.ncols());
    let design = compute(py, cost, || placer(a, b, requested))?;
    // The method's name, interned once per process (PyString::intern hashes it per call).
    let (name, measure) = match method {
        "bass-gura" => (intern!(py, "Bass-Gura"), "controllability matrix"),
        "ackermann" => (intern!(py, "Ackermann"), "controllability matrix"),
        _ => (
            intern!(py, "Kautsky-Nichols-Van Dooren"),
            "closed-loop eigenvector",
        ),
    };
    let (error, condition) = match method {
        "knv0" => (design.max_relative_error, design.eigenvector_condition),
        _ => (design.max_relative_error, design.controllability_condition),
    };
    let mut outputs = Outputs::new(py);
    let n = design.poles.len();
    let result = PlacementResult {
        gain: outputs.matrix("K", design.gain.as_ref())?.unbind(),
        closed_loop: outputs
            .matrix("the closed loop", design.closed_loop.as_ref())?
            .unbind(),
        poles: outputs.complex("the poles", &[n], &design.poles)?.unbind(),
        achieved_poles: outputs
            .complex("the achieved poles", &[n], &design.achieved_poles)?
            .unbind(),
        max_relative_error: design.max_relative_error,
        iterations: design.iterations,
        converged: design.converged,
        method: name.clone().unbind(),
        controllability_condition: design.controllability_condition,
        eigenvector_condition: design.eigenvector_condition,
    };
    outputs.finish()?;
    if error > POLE_ERROR_WARNING
        || design.controllability_condition >= ILL_CONDITIONED_CONTROLLABILITY
    {
        let message = format!(
            "{name}: the achieved poles miss the requested ones by up to {error:.2e} relatively \
             ({measure} condition number {condition:.2e}); the gains may be inaccurate, and \
             poles that are repeated or close together are inherently sensitive (a k-fold pole \
             moves by about u^(1/k))"
        );
        warn(py, Class::IllConditionedWarning, &message)?;
    }
    Bound::new(py, result)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(companion_form, m)?)?;
    m.add_function(wrap_pyfunction!(place, m)?)?;
    m.add_class::<PlacementResult>()?;
    Ok(())
}
