//! Flight vehicles: the state-space models of an aircraft built from its nondimensional
//! stability derivatives, and the MIL-F-8785C Levels of its modes, for one aircraft or for a
//! stack of sampled variants (the stochastic robustness analysis and the envelope sweeps).
//!
//! * [`model`]: the longitudinal (6.49) and lateral-directional (6.150) models from the
//!   derivatives, through the dimensional derivatives (6.48), (6.148)-(6.149).
//! * [`modes`]: which eigenvalues are which classical mode, for a stack of models.
//! * [`levels`]: each mode's quantities (ω_n, ζ, ζω_n, τ_R, T2) and its Level against limits
//!   given as numbers (the specification's tables live with their citations in the Python
//!   package's `handling` module, the one place they are written).

use crate::error::Error;

pub mod levels;
pub mod model;
pub mod modes;

/// The two models of an aircraft.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// x = (u/u0, α, q, θ), input the elevator (6.49).
    Longitudinal,
    /// x = (β, p, φ, r), inputs (rudder, aileron) (6.150).
    Lateral,
}

/// Models handled per parallel task: a few microseconds of work, so that rayon's dispatch is
/// paid once per block, not once per model.
const BLOCK: usize = 1024;

/// Checks that each output (name, length, entries per model) holds `count` models.
fn check_lengths(count: usize, outputs: &[(&'static str, usize, usize)]) -> Result<(), Error> {
    for &(arg, got, per_model) in outputs {
        let expected = count.saturating_mul(per_model);
        if got != expected {
            return Err(Error::Mismatch {
                arg,
                what: "as many entries as",
                expected,
                other: "models x entries per model",
                got,
            });
        }
    }
    Ok(())
}
