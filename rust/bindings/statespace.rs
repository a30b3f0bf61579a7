//! Bindings of `aerocontrol.statespace`: the four matrices of a model, converted and checked
//! together.

use super::conversion::Real;
use super::errors::to_py_err;
use crate::control::frequency::check_state_space;
use crate::control::responses::Model;
use crate::error::Error;
use pyo3::prelude::*;

/// The converted A, B, C and D of a model.
pub struct ModelArgs([Real; 4]);

impl ModelArgs {
    pub fn convert(
        py: Python<'_>,
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        c: &Bound<'_, PyAny>,
        d: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        Ok(Self([
            Real::convert(py, a, "A")?,
            Real::convert(py, b, "B")?,
            Real::convert(py, c, "C")?,
            Real::convert(py, d, "D")?,
        ]))
    }

    /// The model, its shapes and values checked (naming the matrix at fault).
    pub fn model(&self) -> Result<Model<'_>, Error> {
        let [a, b, c, d] = &self.0;
        let model = Model {
            a: a.matrix()?,
            b: b.matrix()?,
            c: c.matrix()?,
            d: d.matrix()?,
        };
        check_state_space(model.a, model.b, model.c, model.d)?;
        Ok(model)
    }
}

/// Checks the shapes and values of A, B, C, D of a state-space model, naming the matrix at
/// fault.
#[pyfunction]
#[pyo3(signature = (a, b, c, d, /))]
fn check_model(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    c: &Bound<'_, PyAny>,
    d: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let args = ModelArgs::convert(py, a, b, c, d)?;
    args.model().map_err(|e| to_py_err(py, e))?;
    Ok(())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check_model, m)?)?;
    Ok(())
}
