//! The Riccati difference equation of the discrete finite-horizon regulator: for
//! x_{k+1} = A x_k + B u_k and the cost
//!
//! ```text
//! J = x_N^T S_f x_N + Σ_{k<N} (x_k^T Q x_k + 2 x_k^T N u_k + u_k^T R u_k),
//! ```
//!
//! the optimal control is u_k = -K_k x_k with, backward from S_N = S_f,
//!
//! ```text
//! W_k = R + B^T S_{k+1} B,     M_k = B^T S_{k+1} A + N^T,     K_k = W_k^-1 M_k,
//! S_k = A^T S_{k+1} A - M_k^T K_k + Q                                         (1)
//!     = (A - B K_k)^T S_{k+1} (A - B K_k) + K_k^T R K_k - N K_k - K_k^T N^T + Q,   (2)
//! ```
//!
//! and x_k^T S_k x_k the cost to go (the discrete counterpart of the chapter's (6.196)-(6.200);
//! Kwakernaak & Sivan 1972, Section 6.4). A long horizon converges to the stabilising solution
//! of the DARE ([`super::dare`]).
//!
//! # The form evaluated
//!
//! The form (2) (the "Joseph" form) is evaluated: where the weight [[Q, N], [N^T, R]] is
//! positive semidefinite each of its terms is, so S_k stays symmetric positive semidefinite
//! under rounding, which the difference in (1) does not ensure; on plants whose S grows over
//! the horizon it also kept four to six more digits than (1) or the subtraction-free
//! information form A^T S (I + G S)^-1 A + Q in trials against 60-digit recursions. Its weak
//! point is A - B K: where A and B K are far larger than their difference (a plant entry of
//! 1e149 beside weights of 1) the rounding δ = u (||A|| + ||B|| ||K||) of A - B K, carried
//! through S twice, can exceed S_k itself (every form in double loses those digits, (1) in
//! its subtraction). That amount, relative to ||S_k||, is returned as the error estimate for
//! the caller's warning.
//!
//! Where the states are measured in units far apart, the recursion runs on the states
//! balanced by an exact diagonal similarity of powers of two ([`super::scaling`]):
//! Ã = T^-1 A T, B̃ = T^-1 B, Q̃ = T Q T, Ñ = T N, S̃_f = T S_f T give S̃_k = T S_k T and
//! K̃_k = K_k T, taken back exactly. Its error estimate is then that of the balanced
//! recursion; in the caller's units ||A|| is set by the largest unit and the estimate would
//! flag states merely scaled apart (47 of 50 random models in states 10^±6 apart warned of
//! errors up to 2e2, where S_k was right to 4e-13).
//!
//! # Checks
//!
//! W_k must be nonsingular: its reciprocal 1-norm condition number is estimated from the
//! inverse formed with K_k, and a W_k with rcond <= u at any step is refused (the step and the
//! value are named). The worst rcond over the horizon is returned for the caller's warning. A
//! step that leaves S non-finite (the plant's growth over the horizon beyond the range of
//! doubles) is refused.

use super::pencil::checked_weights;
use super::scaling::{Equation, Scale, ScaledEquation};
use crate::error::Error;
use crate::linalg::lu::solve_with_inverse;
use crate::linalg::matrix::{FaerView, Symmetrize};
use crate::linalg::norm::{frobenius_norm, one_norm};
use crate::linalg::product::product;
use crate::platform::interrupt;
use faer::{Mat, MatRef};

/// S_k and K_k over the horizon.
#[derive(Debug, Clone)]
pub struct RiccatiDifferenceSolution {
    /// S_0 .. S_N (N + 1 matrices), symmetric; S_N = S_f.
    pub s: Vec<Mat<f64>>,
    /// K_0 .. K_{N-1}, each m x n.
    pub gains: Vec<Mat<f64>>,
    /// The smallest reciprocal 1-norm condition number of W_k = R + B^T S_{k+1} B over the
    /// horizon (1 for N = 0 or m = 0).
    pub rcond: f64,
    /// The largest estimated relative error of a step from the rounding of A - B K
    /// (module documentation), max over k of (n + m) δ (2 ||A - B K_k|| + δ) ||S_{k+1}|| /
    /// ||S_k|| with δ = u (||A|| + ||B|| ||K_k||), Frobenius norms.
    pub error_estimate: f64,
}

/// The optional arguments of [`riccati_difference`].
#[derive(Debug, Clone, Copy, Default)]
pub struct DifferenceOptions<'a> {
    /// The cross weight N (n x m).
    pub cross: Option<MatRef<'a, f64>>,
    /// The terminal weight S_f (n x n, symmetric); zero when absent.
    pub terminal: Option<MatRef<'a, f64>>,
}

/// Runs the recursion (2) of the module documentation backward over `steps` steps, on the
/// states balanced where they are scaled apart.
pub fn riccati_difference(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    steps: usize,
    options: DifferenceOptions<'_>,
) -> Result<RiccatiDifferenceSolution, Error> {
    let given = Equation {
        a,
        b,
        q,
        r,
        s: options.cross,
        e: None,
        terminal: options.terminal,
    };
    let Some(scaled) = ScaledEquation::of(given, Scale::WhereBalanced) else {
        return recursion(a, b, q, r, steps, options);
    };
    let equation = scaled.equation();
    let options = DifferenceOptions {
        cross: equation.s,
        terminal: equation.terminal,
    };
    let solution = recursion(
        equation.a, equation.b, equation.q, equation.r, steps, options,
    )?;
    Ok(RiccatiDifferenceSolution {
        s: solution
            .s
            .iter()
            .map(|s| scaled.unscaled_solution(s))
            .collect(),
        gains: solution
            .gains
            .iter()
            .map(|k| scaled.unscaled_gain(k))
            .collect(),
        ..solution
    })
}

/// [`riccati_difference`] of the equation as given.
fn recursion(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    steps: usize,
    options: DifferenceOptions<'_>,
) -> Result<RiccatiDifferenceSolution, Error> {
    let (q, r) = checked_weights(a, b, q, r, options.cross.map(|s| (s, "N")), None)?;
    let (n, m) = (a.nrows(), b.ncols());
    let mut s = match options.terminal {
        Some(sf) => crate::control::riccati::care::symmetric(sf, "Sf", n, "A")?
            .as_faer()
            .to_owned(),
        None => Mat::zeros(n, n),
    };
    let per_step = (n * n + m * n).saturating_mul(8);
    crate::platform::memory::reserve(per_step.saturating_mul(steps.saturating_add(1)))?;
    let mut solutions = Vec::with_capacity(steps + 1);
    let mut gains = Vec::with_capacity(steps);
    let mut rcond = 1.0f64;
    let mut error_estimate = 0.0f64;
    let (a_norm, b_norm) = (frobenius_norm(a), frobenius_norm(b));
    solutions.push(s.clone());
    for step in (0..steps).rev() {
        interrupt::check()?;
        let sb = product(s.as_ref(), b)?;
        let mut weight = &r + b.transpose() * &sb;
        weight.symmetrize();
        let mut mixed = product(sb.transpose(), a)?;
        if let Some(cross) = options.cross {
            mixed += cross.transpose();
        }
        let norm = one_norm(weight.as_ref());
        let combined = solve_with_inverse(weight.as_mut(), mixed.as_ref())?;
        let (gain, inverse) = combined.as_ref().split_at_col(n);
        if m > 0 {
            let step_rcond = 1.0 / (norm * one_norm(inverse));
            if !gain.is_all_finite() || step_rcond.is_nan() || step_rcond <= f64::EPSILON {
                return Err(Error::IllConditioned {
                    message: format!(
                        "R + B^T S B is singular to working precision at step {step} of the \
                         Riccati difference equation (rcond {step_rcond:.2e}), so the gain \
                         K_{step} is not determined; R must make R + B^T S B invertible"
                    ),
                });
            }
            rcond = rcond.min(step_rcond);
        }
        let gain = gain.to_owned();
        let (mut next, closed_loop_norm) = joseph_step(a, b, &q, &r, options.cross, &s, &gain)?;
        next.symmetrize();
        // The rounding of A - B K, u (||A|| + ||B|| ||K||), carried through S twice.
        let s_norm = frobenius_norm(s.as_ref());
        let rounding = f64::EPSILON * (a_norm + b_norm * frobenius_norm(gain.as_ref()));
        let bound = (n + m) as f64 * rounding * (2.0 * closed_loop_norm + rounding) * s_norm;
        let next_norm = frobenius_norm(next.as_ref());
        if bound > 0.0 {
            // Beyond the doubles (norms near 1e308) the estimate is the largest double.
            error_estimate = error_estimate.max((bound / next_norm).min(f64::MAX));
        }
        if !next.is_all_finite() {
            return Err(Error::IllConditioned {
                message: format!(
                    "the Riccati difference equation left the range of doubles at step {step}: \
                     S_{step} is not finite (the plant grows too fast over the horizon for its \
                     weights); shorten the horizon or scale the model"
                ),
            });
        }
        s = next;
        solutions.push(s.clone());
        gains.push(gain);
    }
    solutions.reverse();
    gains.reverse();
    Ok(RiccatiDifferenceSolution {
        s: solutions,
        gains,
        rcond,
        error_estimate,
    })
}

/// The step (2): (A - B K)^T S (A - B K) + K^T R K - N K - K^T N^T + Q, and ||A - B K||_F;
/// its products of order n stop when the computation is interrupted.
fn joseph_step(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: &Mat<f64>,
    r: &Mat<f64>,
    cross: Option<MatRef<'_, f64>>,
    s: &Mat<f64>,
    gain: &Mat<f64>,
) -> Result<(Mat<f64>, f64), Error> {
    let closed_loop = a - product(b, gain.as_ref())?;
    let sandwich = product(
        product(closed_loop.transpose(), s.as_ref())?.as_ref(),
        closed_loop.as_ref(),
    )?;
    let mut next = sandwich + gain.transpose() * r * gain + q;
    if let Some(cross) = cross {
        let coupling = cross * gain;
        next -= &coupling + coupling.transpose();
    }
    Ok((next, frobenius_norm(closed_loop.as_ref())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scalar equation (a, b, q, r) over `steps` steps from S_f = 0.
    fn scalar([a, b, q, r]: [f64; 4], steps: usize) -> Result<RiccatiDifferenceSolution, Error> {
        let [a, b, q, r] = [a, b, q, r].map(|x| Mat::from_fn(1, 1, |_, _| x));
        riccati_difference(
            a.as_ref(),
            b.as_ref(),
            q.as_ref(),
            r.as_ref(),
            steps,
            DifferenceOptions::default(),
        )
    }

    #[test]
    fn scalar_recursion_has_its_closed_form() {
        // a = 2, b = 1, q = 1, r = 1, s_f = 0: s_k = (5 s + 1) / (1 + s) and k_k = 2 s / (1 + s)
        // with s = s_{k+1}; backward from s_4 = 0: 1, 3, 4, 21/5.
        let solution = scalar([2.0, 1.0, 1.0, 1.0], 4).unwrap();
        let s: Vec<f64> = solution.s.iter().map(|s| s[(0, 0)]).collect();
        let expected = [21.0 / 5.0, 4.0, 3.0, 1.0, 0.0];
        for (got, want) in s.iter().zip(expected) {
            assert!((got - want).abs() <= 4.0 * f64::EPSILON * want, "{s:?}");
        }
        for (k, gain) in solution.gains.iter().enumerate() {
            let next = expected[k + 1];
            let want = 2.0 * next / (1.0 + next);
            assert!((gain[(0, 0)] - want).abs() <= 4.0 * f64::EPSILON * want.max(1.0));
        }
    }

    #[test]
    fn terms_far_larger_than_the_solution_are_flagged() {
        // a = 1.26e149, b = 3.46e149, q = r = 1: S_1 = 1, S_0 = a^2 / (1 + b^2) + 1 = 1.13,
        // but A - B K is 1e-150 beside terms of 1e149: no evaluation in double keeps a digit
        // of S_0, and the estimate says so.
        let solution = scalar([1.257302210933933e149, 3.45584192064786e149, 1.0, 1.0], 2).unwrap();
        assert!(solution.error_estimate > 1.0, "{}", solution.error_estimate);
        // The scaled problem (a, b of order 1, the same ratio) is exact and unflagged.
        let solution = scalar([1.257302210933933, 3.45584192064786, 1.0, 1.0], 2).unwrap();
        assert!(
            solution.error_estimate < 1e-14,
            "{}",
            solution.error_estimate
        );
    }

    #[test]
    fn singular_weight_is_refused_with_its_step() {
        // R = 0 and S_f = 0: W_{N-1} = 0.
        let error = scalar([1.0, 1.0, 1.0, 0.0], 3).unwrap_err();
        assert!(error.to_string().contains("step 2"), "{error}");
    }
}
