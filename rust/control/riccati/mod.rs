//! Riccati equations: the algebraic equations of the infinite-horizon regulators, continuous
//! ([`care`]) and discrete ([`dare`]), the differential equation of the continuous
//! finite-horizon one ([`ode`]) and the difference equation of the discrete one
//! ([`difference`]); the discrete equation's fast paths, by doubling ([`doubling`]) and the
//! Cayley transform ([`cayley`]).

pub mod care;
pub(crate) mod care_pencil;
pub(crate) mod cayley;
pub mod dare;
pub mod difference;
pub mod doubling;
pub mod ode;
pub(crate) mod pencil;
pub(crate) mod scaling;

use faer::{Mat, c64};

/// The stabilising solution of an algebraic Riccati equation, continuous ([`care::solve_care`])
/// or discrete ([`dare::solve_dare`]), with the checks it passed.
#[derive(Debug, Clone)]
pub struct AlgebraicSolution {
    /// The stabilising solution X = X^T.
    pub x: Mat<f64>,
    /// The regulator's gain, m x n: K = R^-1 (B^T X E + S^T) (continuous) or
    /// K = (R + B^T X B)^-1 (B^T X A + S^T) (discrete).
    pub gain: Mat<f64>,
    /// The eigenvalues of (A - B K, E), pairs adjacent with Im > 0 first.
    pub closed_loop_eigenvalues: Vec<c64>,
    /// The relative residual of the general equation (see each module's documentation).
    pub residual: f64,
    /// The reciprocal 1-norm condition number of U11 (continuous) or E U11 (discrete), the
    /// block of the invariant subspace's basis that X = U21 U11^-1 inverts.
    pub rcond: f64,
    /// Newton steps taken.
    pub refinement_steps: usize,
}
