//! The discrete Riccati equation through the Cayley transform of its symplectic pencil: the
//! fast path of [`super::dare`] for E = I and R positive definite.
//!
//! With R = L L^T, B̂ = B L^-T, Ŝ = S L^-T, the cross weight is absorbed (Ã = A - B̂ Ŝ^T,
//! Q̃ = Q - Ŝ Ŝ^T, G = B̂ B̂^T) and the stable deflating subspace of the symplectic pencil
//!
//! ```text
//! M - z N = [ Ã   0 ] - z [ I  G   ]
//!           [ -Q̃  I ]     [ 0  Ã^T ]
//! ```
//!
//! is the stable invariant subspace (Re s < 0) of the Hamiltonian matrix
//! H = (M + N)^-1 (M - N), whose eigenvalues are s = (z - 1) / (z + 1) (Mehrmann 1991, the
//! Cayley transform maps symplectic pencils to Hamiltonian matrices): |z| < 1 exactly when
//! Re s < 0, an infinite z (A singular) is s = 1. X = U21 U11^-1 then comes from the
//! continuous solver's Hamiltonian Schur method ([`super::care::hamiltonian_solution`]), with
//! its scaling, structured shifts and early stop: on a sampled plant, whose eigenvalues z
//! cluster near 1, it takes a third of the sweeps of the QZ iteration on the pencil.
//!
//! The transform is accurate when M + N is well conditioned; its condition number grows as
//! an eigenvalue of the pencil approaches z = -1. It is used only when the reciprocal
//! condition number of M + N is at least [`MIN_RCOND`], and [`super::dare`] keeps its result
//! only when, after its Newton refinement, the residual is within a few units of rounding
//! and the closed loop passes its checks; otherwise it solves by the pencil and QZ.

use super::care::{Standard, hamiltonian_solution, standardize};
use crate::linalg::dense::cholesky;
use crate::linalg::lu::solve_with_inverse;
use crate::linalg::matrix::{FaerView, Symmetrize, from_faer};
use crate::linalg::norm::one_norm;
use faer::{Mat, MatRef, c64};
use nalgebra::DMatrix;

/// The smallest reciprocal 1-norm condition number of M + N for which the transform is used.
pub const MIN_RCOND: f64 = 1e-6;

/// The transform's candidate solution of the DARE.
pub(crate) struct CayleySolution {
    /// X, symmetric.
    pub(crate) x: Mat<f64>,
    /// The reciprocal condition number of U11.
    pub(crate) rcond: f64,
    /// The closed-loop eigenvalues as the Hamiltonian's stable ones map back,
    /// z = (1 + s) / (1 - s): estimates (the shifts of the closed loop's own eigenvalue
    /// computation), not results.
    pub(crate) closed_loop_estimates: Vec<c64>,
}

/// The solution by the transform of the equation in standard form `plant` (E = I, R
/// positive definite: [`standard_form`]), or `None` where M + N is ill-conditioned or the
/// Hamiltonian method refuses.
pub(crate) fn cayley_solution(plant: &Standard) -> Option<CayleySolution> {
    let standard = cayley_transform(plant)?;
    let solution = hamiltonian_solution(&standard).ok()?;
    let closed_loop_estimates = solution
        .stable_eigenvalues
        .iter()
        .map(|&s| (1.0 + s) / (1.0 - s))
        .collect();
    Some(CayleySolution {
        x: solution.y.as_faer().to_owned(),
        rcond: solution.rcond,
        closed_loop_estimates,
    })
}

/// The standard form of the DARE with E = I (Ã = A - B̂ Ŝ^T, G = B̂ B̂^T, Q̃ = Q - Ŝ Ŝ^T with
/// R = L L^T, B̂ = B L^-T, Ŝ = S L^-T: the continuous equation's), from which both fast paths
/// start; `None` when R is not positive definite.
pub(crate) fn standard_form(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    s: Option<MatRef<'_, f64>>,
) -> Option<Standard> {
    let l = cholesky(&from_faer(r))?;
    Some(standardize(
        &from_faer(a),
        &from_faer(b),
        &from_faer(q),
        &l,
        s.map(from_faer).as_ref(),
    ))
}

/// The Hamiltonian H = (M + N)^-1 (M - N) as the blocks of a continuous equation, or `None`
/// where the transform does not apply.
fn cayley_transform(plant: &Standard) -> Option<Standard> {
    let n = plant.a.nrows();
    let (a_tilde, g, q_tilde) = (&plant.a, &plant.g, &plant.q);
    // M + N and M - N.
    let mut sum = Mat::<f64>::zeros(2 * n, 2 * n);
    let mut difference = Mat::<f64>::zeros(2 * n, 2 * n);
    for j in 0..n {
        for i in 0..n {
            let (aij, aji) = (a_tilde[(i, j)], a_tilde[(j, i)]);
            let identity = if i == j { 1.0 } else { 0.0 };
            sum[(i, j)] = aij + identity;
            sum[(i, n + j)] = g[(i, j)];
            sum[(n + i, j)] = -q_tilde[(i, j)];
            sum[(n + i, n + j)] = aji + identity;
            difference[(i, j)] = aij - identity;
            difference[(i, n + j)] = -g[(i, j)];
            difference[(n + i, j)] = -q_tilde[(i, j)];
            difference[(n + i, n + j)] = identity - aji;
        }
    }
    let norm = one_norm(sum.as_ref());
    // An interruption refuses the transform (the caller's next check stops).
    let combined = solve_with_inverse(sum.as_mut(), difference.as_ref()).ok()?;
    let (h, inverse) = combined.as_ref().split_at_col(2 * n);
    let rcond = 1.0 / (norm * one_norm(inverse));
    if rcond.is_nan() || rcond < MIN_RCOND || !h.is_all_finite() {
        return None;
    }
    // H = [[H11, H12], [H21, -H11^T]] (to rounding): the CARE's Ā = H11, G = -H12, Q̄ = -H21.
    let block = |row: usize, column: usize, sign: f64| {
        let mut m = DMatrix::from_fn(n, n, |i, j| sign * h[(row + i, column + j)]);
        m.symmetrize();
        m
    };
    Some(Standard {
        a: DMatrix::from_fn(n, n, |i, j| h[(i, j)]),
        g: block(0, n, -1.0),
        q: block(n, 0, -1.0),
    })
}
