//! The symmetric generalized Stein (discrete Lyapunov) equation
//!
//! ```text
//! A^T X A - E^T X E = C,      C = C^T,  X = X^T,
//! ```
//!
//! at small orders, in its vectorised form over the n (n + 1) / 2 unknowns x_kl, k <= l:
//! the coefficient of x_kl in equation (i, j), i <= j, is a_ki a_lj + a_li a_kj - (e_ki e_lj +
//! e_li e_kj) (halved when k = l). The system is solved by LU with partial pivoting; it is
//! nonsingular exactly when no two generalized eigenvalues of (A, E) have product 1 (for
//! E = I: λ_i λ_j != 1), which holds for a closed loop inside the unit circle. This is the
//! step of Newton's method for the discrete Riccati equation
//! ([`crate::control::riccati::dare`]); the cost, (n^2 / 2)^3 / 3 flops, limits it to
//! [`KRONECKER_MAX_ORDER`].
//!
//! Above it, for E = I and A with spectral radius below one, [`solve_stein_smith`] sums the
//! series X = Σ (A^T)^k C A^k (for X - A^T X A = C) by Smith's doubling (Smith 1968):
//! X_{k+1} = X_k + A_k^T X_k A_k, A_{k+1} = A_k^2, which after k steps has summed 2^k terms;
//! three products of order n per step, until A_k is negligible.

use crate::error::Error;
use crate::linalg::lu;
use faer::{Mat, MatRef, Par};

/// The largest order solved in vectorised form (136 unknowns).
pub const KRONECKER_MAX_ORDER: usize = 16;

/// Solves A^T X A - E^T X E = C for the symmetric X (only C's upper triangle is read).
/// Returns `None` when the order exceeds [`KRONECKER_MAX_ORDER`] or the system is singular to
/// working precision.
pub fn solve_stein_kronecker(
    a: MatRef<'_, f64>,
    e: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> Result<Option<Mat<f64>>, Error> {
    let n = a.nrows();
    if n > KRONECKER_MAX_ORDER {
        return Ok(None);
    }
    let unknowns = n * (n + 1) / 2;
    let index = |k: usize, l: usize| {
        let (k, l) = if k <= l { (k, l) } else { (l, k) };
        l * (l + 1) / 2 + k
    };
    let mut system = Mat::<f64>::zeros(unknowns, unknowns);
    let mut rhs = Mat::<f64>::zeros(unknowns, 1);
    for j in 0..n {
        for i in 0..=j {
            let row = index(i, j);
            rhs[(row, 0)] = c[(i, j)];
            for l in 0..n {
                for k in 0..=l {
                    let mut coefficient = a[(k, i)] * a[(l, j)] - e[(k, i)] * e[(l, j)];
                    if k != l {
                        coefficient += a[(l, i)] * a[(k, j)] - e[(l, i)] * e[(k, j)];
                    }
                    system[(row, index(k, l))] = coefficient;
                }
            }
        }
    }
    let scale = crate::linalg::norm::max_abs(system.as_ref());
    lu::solve(system.as_mut(), rhs.as_mut(), Par::Seq)?;
    if !rhs.is_all_finite() || scale.is_nan() || scale <= 0.0 {
        return Ok(None);
    }
    Ok(Some(Mat::from_fn(n, n, |i, j| rhs[(index(i, j), 0)])))
}

/// Doubling steps at most: 2^40 terms of the series, enough for a spectral radius up to
/// 1 - 3e-11.
const SMITH_MAX_STEPS: usize = 40;

/// Solves X - A^T X A = C (C symmetric) by Smith's doubling. Returns `None` when A^(2^k) does
/// not become negligible within [`SMITH_MAX_STEPS`] steps (spectral radius too close to one,
/// or above) or the sum overflows.
pub fn solve_stein_smith(
    a: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> Result<Option<Mat<f64>>, Error> {
    let mut x = c.to_owned();
    let mut power = a.to_owned();
    for _ in 0..SMITH_MAX_STEPS {
        crate::platform::interrupt::check()?;
        let update = power.transpose() * &x * &power;
        x += &update;
        let power_norm = crate::linalg::norm::frobenius_norm(power.as_ref());
        if !x.is_all_finite() || !power_norm.is_finite() {
            return Ok(None);
        }
        if power_norm * power_norm <= f64::EPSILON * 1e-3 {
            return Ok(Some(x));
        }
        power = &power * &power;
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_known_equation() {
        // X = [[2, 1], [1, 3]], A = [[0.5, 0.2], [-0.1, 0.3]], E = I: C = A^T X A - X.
        let x = Mat::from_fn(2, 2, |i, j| [[2.0, 1.0], [1.0, 3.0]][i][j]);
        let a = Mat::from_fn(2, 2, |i, j| [[0.5, 0.2], [-0.1, 0.3]][i][j]);
        let e = Mat::<f64>::identity(2, 2);
        let c = a.transpose() * &x * &a - &x;
        let solved = solve_stein_kronecker(a.as_ref(), e.as_ref(), c.as_ref())
            .unwrap()
            .unwrap();
        let error = &solved - &x;
        assert!(crate::linalg::norm::max_abs(error.as_ref()) < 1e-14);
        // The same by doubling: X - A^T X A = -C.
        let doubled = solve_stein_smith(a.as_ref(), (-&c).as_ref())
            .unwrap()
            .unwrap();
        let error = &doubled - &x;
        assert!(crate::linalg::norm::max_abs(error.as_ref()) < 1e-14);
        // Spectral radius one: no convergence, no answer.
        let rotation = Mat::from_fn(2, 2, |i, j| [[0.0, 1.0], [-1.0, 0.0]][i][j]);
        assert!(
            solve_stein_smith(rotation.as_ref(), c.as_ref())
                .unwrap()
                .is_none()
        );
    }
}
