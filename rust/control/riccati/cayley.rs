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

use super::care::{Standard, hamiltonian_solution};
use crate::linalg::lu::solve_with_inverse;
use crate::linalg::matrix::{FaerView, Symmetrize};
use crate::linalg::norm::one_norm;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::{Mat, MatRef, Par};
use nalgebra::DMatrix;

/// The smallest reciprocal 1-norm condition number of M + N for which the transform is used.
pub const MIN_RCOND: f64 = 1e-6;

/// X (symmetric) and rcond(U11) by the transform, or `None` where it does not apply (R not
/// positive definite, M + N ill-conditioned) or the Hamiltonian method refuses.
pub(crate) fn cayley_solution(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    s: Option<MatRef<'_, f64>>,
) -> Option<(Mat<f64>, f64)> {
    let n = a.nrows();
    let factor = r.llt(faer::Side::Lower).ok()?;
    let l = factor.L();
    // B̂^T = L^-1 B^T, Ŝ^T = L^-1 S^T.
    let mut b_hat_t = b.transpose().to_owned();
    solve_lower_triangular_in_place(l, b_hat_t.as_mut(), Par::Seq);
    let mut g = b_hat_t.transpose() * &b_hat_t;
    g.symmetrize();
    let (mut a_tilde, mut q_tilde) = (a.to_owned(), q.to_owned());
    if let Some(s) = s {
        let mut s_hat_t = s.transpose().to_owned();
        solve_lower_triangular_in_place(l, s_hat_t.as_mut(), Par::Seq);
        a_tilde -= b_hat_t.transpose() * &s_hat_t;
        q_tilde -= s_hat_t.transpose() * &s_hat_t;
        q_tilde.symmetrize();
    }
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
    let combined = solve_with_inverse(sum.as_mut(), difference.as_ref());
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
    let standard = Standard {
        a: DMatrix::from_fn(n, n, |i, j| h[(i, j)]),
        g: block(0, n, -1.0),
        q: block(n, 0, -1.0),
    };
    let solution = hamiltonian_solution(&standard).ok()?;
    Some((solution.y.as_faer().to_owned(), solution.rcond))
}
