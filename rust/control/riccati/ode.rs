//! The Riccati differential equation of the finite-horizon regulator (chapter (6.196)-(6.200)):
//!
//! ```text
//! -dS/dt = S A + A^T S - S B R^-1 B^T S + Q,      S(t_f) = S_f,      K(t) = R^-1 B^T S(t),
//! ```
//!
//! integrated backward from t_f over the caller's time grid.
//!
//! # Method: the Hamiltonian transition matrix, re-normalised every step
//!
//! With G = B R^-1 B^T and H = [[A, -G], [-Q, -A^T]], write S = Y X^-1. Then S solves the
//! equation in reverse time τ = t_f - t exactly when d/dτ [X; Y] = -H [X; Y], a linear system
//! (Radon's lemma). Over a step of length h, therefore,
//!
//! ```text
//! [X; Y] = e^{-H h} [I; S(t + h)],      S(t) = Y X^-1,
//! ```
//!
//! with no truncation error: the only errors are those of the matrix exponential
//! ([`crate::linalg::expm`], accurate to a few units of u) and of one LU solve per step. Starting every
//! step again from [I; S] (the modified Davison–Maki method; Kenney & Leipnik 1985) keeps X
//! well conditioned, where the plain method, propagating [X; Y] over the whole horizon,
//! lets the growing modes of e^{-Ht} swamp the others. A step is further divided so that
//! h max|Re λ(H)| <= [`MAX_GROWTH_EXPONENT`]: across one substep the modes then grow
//! relative to each other by at most e^{2 MAX_GROWTH_EXPONENT}, which bounds the condition
//! number of X. A stiff integrator (the alternative the issue allowed) would control the error
//! only to a tolerance and cost many more steps on the long horizons where S(t) settles to the
//! algebraic solution; here the accuracy is that of double precision whatever the step.
//!
//! For a uniform grid (the usual case) one exponential serves every step. A grid counts as
//! uniform when every t_k is within [`GRID_ROUNDING`] max(|t_0|, |t_last|) of t_0 + k h̄,
//! h̄ = (t_last - t_0) / (len - 1): the spacing of `numpy.linspace` and `numpy.arange`, whose
//! intervals differ from one another in their last bits. Such a grid is integrated with the
//! step h̄, so S is computed at times within that rounding of the caller's, the uncertainty
//! with which the times themselves are stored; any other grid takes each interval as given.
//!
//! The work is bounded: once a substep leaves S unchanged to rounding ([`STATIONARY`]), S has
//! reached the fixed point of the step, the algebraic solution, and every earlier time has
//! the same S (a plant whose modes are fast against the horizon, A = [[1e8]] over one second,
//! needs a few dozen substeps instead of 1.4e8). A horizon that would take more than
//! [`MAX_SUBSTEPS`] substeps without settling is refused, naming t.

use crate::control::riccati::care::check_problem;
use crate::error::{Error, check_finite, check_rows, check_square};
use crate::linalg::expm::expm;
use crate::linalg::lu;
use crate::linalg::matrix::{FaerView, Symmetrize};
use crate::linalg::schur::eigenvalues;
use crate::platform::interrupt;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, MatRef, Par};

/// The largest h max|Re λ(H)| of one substep.
pub const MAX_GROWTH_EXPONENT: f64 = 1.0;

/// A substep that changes no entry of S by more than this times max|S| leaves it stationary.
pub const STATIONARY: f64 = 4.0 * f64::EPSILON;

/// The most substeps of one integration that has not become stationary.
pub const MAX_SUBSTEPS: usize = 1_000_000;

/// Substeps between two checks for an interrupt.
const INTERRUPT_INTERVAL: usize = 4096;

/// The distance, in units of max(|t_0|, |t_last|), within which every time of a grid must lie
/// of the evenly spaced times for the grid to count as uniform: a few roundings of the times.
pub const GRID_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// S(t) and K(t) at every time of the grid.
#[derive(Debug, Clone)]
pub struct RiccatiSolution {
    /// S(t_k), symmetric, one per time.
    pub s: Vec<Mat<f64>>,
    /// K(t_k) = R^-1 B^T S(t_k), m x n.
    pub gains: Vec<Mat<f64>>,
    /// Substeps taken over the whole horizon.
    pub substeps: usize,
}

/// Integrates the Riccati differential equation backward from the last time of `times`.
pub fn riccati_ode(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    times: &[f64],
    terminal: Option<MatRef<'_, f64>>,
) -> Result<RiccatiSolution, Error> {
    let (q, l) = check_problem(a, b, q, r)?;
    let n = a.nrows();
    check_times(times)?;
    let mut s = match terminal {
        Some(sf) => {
            check_square(sf, "Sf")?;
            check_rows(sf, "Sf", n, "A")?;
            check_finite(sf, "Sf")?;
            sf.to_owned()
        }
        None => Mat::zeros(n, n),
    };
    s.symmetrize();
    let l = l.as_faer();
    // G = B R^-1 B^T = B̂ B̂^T with B̂^T = L^-1 B^T.
    let mut b_hat_t = b.transpose().to_owned();
    solve_lower_triangular_in_place(l, b_hat_t.as_mut(), Par::Seq);
    let mut g = b_hat_t.transpose() * &b_hat_t;
    g.symmetrize();
    let mut minus_h = Mat::<f64>::zeros(2 * n, 2 * n);
    for j in 0..n {
        for i in 0..n {
            minus_h[(i, j)] = -a[(i, j)];
            minus_h[(i, n + j)] = g[(i, j)];
            minus_h[(n + i, j)] = q[(i, j)];
            minus_h[(n + i, n + j)] = a[(j, i)];
        }
    }
    let growth_rate = eigenvalues(minus_h.as_ref())?
        .iter()
        .fold(0.0f64, |acc, lambda| acc.max(lambda.re.abs()));

    let gain = |s: &Mat<f64>| -> Mat<f64> {
        // K = L^-T L^-1 B^T S.
        let mut k = b.transpose() * s;
        solve_lower_triangular_in_place(l, k.as_mut(), Par::Seq);
        solve_upper_triangular_in_place(l.transpose(), k.as_mut(), Par::Seq);
        k
    };
    let count = times.len();
    let mut solutions = vec![Mat::<f64>::zeros(0, 0); count];
    let mut gains = vec![Mat::<f64>::zeros(0, 0); count];
    gains[count - 1] = gain(&s);
    solutions[count - 1] = s.clone();
    // The transition matrix of the last substep length, reused while it repeats.
    let mut cached: Option<(f64, Mat<f64>)> = None;
    let uniform_step = uniform_step(times);
    let mut substeps = 0;
    let mut stationary = false;
    for k in (0..count - 1).rev() {
        interrupt::check()?;
        if !stationary {
            let interval = uniform_step.unwrap_or(times[k + 1] - times[k]);
            // (The float-to-integer conversion saturates: a horizon of 1e300 gives usize::MAX
            // pieces, of which only those before S settles are taken.)
            let pieces = ((interval * growth_rate / MAX_GROWTH_EXPONENT).ceil() as usize).max(1);
            let h = interval / pieces as f64;
            if cached.as_ref().is_none_or(|(length, _)| *length != h) {
                let scaled = Mat::from_fn(2 * n, 2 * n, |i, j| h * minus_h[(i, j)]);
                cached = Some((h, expm(scaled.as_ref())?));
            }
            let phi = &cached.as_ref().expect("just set").1;
            for piece in 0..pieces {
                let next = step(phi.as_ref(), &s)?;
                substeps += 1;
                stationary = is_stationary(&next, &s);
                s = next;
                if stationary {
                    break;
                }
                if substeps >= MAX_SUBSTEPS {
                    return Err(too_many_substeps(times, growth_rate));
                }
                if piece % INTERRUPT_INTERVAL == INTERRUPT_INTERVAL - 1 {
                    interrupt::check()?;
                }
            }
        }
        gains[k] = gain(&s);
        solutions[k] = s.clone();
    }
    Ok(RiccatiSolution {
        s: solutions,
        gains,
        substeps,
    })
}

/// Whether a substep from `previous` to `next` changed no entry by more than
/// [`STATIONARY`] max|S|.
fn is_stationary(next: &Mat<f64>, previous: &Mat<f64>) -> bool {
    let size = next.norm_max().max(previous.norm_max());
    (next - previous).norm_max() <= STATIONARY * size
}

/// The refusal of a horizon whose substeps exceed [`MAX_SUBSTEPS`] before S settles.
fn too_many_substeps(times: &[f64], growth_rate: f64) -> Error {
    let horizon = times[times.len() - 1] - times[0];
    Error::InvalidArgument {
        arg: "t",
        message: format!(
            "the horizon {horizon:.3e} s is too long for the Hamiltonian's fastest modes \
             (growth rate {growth_rate:.3e} 1/s): S(t) had not settled after {MAX_SUBSTEPS} \
             substeps; shorten t, or use lqr for the stationary solution"
        ),
    }
}

/// The step h̄ = (t_last - t_0) / (len - 1) of a grid of two times or more whose every time is
/// within [`GRID_ROUNDING`] max(|t_0|, |t_last|) of t_0 + k h̄; `None` for any other grid.
fn uniform_step(times: &[f64]) -> Option<f64> {
    let (first, last) = (*times.first()?, *times.last()?);
    let intervals = times.len().checked_sub(1).filter(|&count| count > 0)?;
    let step = (last - first) / intervals as f64;
    let tolerance = GRID_ROUNDING * first.abs().max(last.abs());
    times
        .iter()
        .enumerate()
        .all(|(k, &t)| (first + k as f64 * step - t).abs() <= tolerance)
        .then_some(step)
}

/// One step: [X; Y] = Φ [I; S], S <- Y X^-1 (by X^T S'^T = Y^T), symmetrised.
fn step(phi: MatRef<'_, f64>, s: &Mat<f64>) -> Result<Mat<f64>, Error> {
    let n = s.nrows();
    let x = phi.submatrix(0, 0, n, n) + phi.submatrix(0, n, n, n) * s;
    let y = phi.submatrix(n, 0, n, n) + phi.submatrix(n, n, n, n) * s;
    let mut factors = x.transpose().to_owned();
    let mut next = y.transpose().to_owned();
    lu::solve(factors.as_mut(), next.as_mut(), Par::Seq)?;
    if !next.is_all_finite() {
        return Err(Error::IllConditioned {
            message: "the Riccati differential equation's solution could not be continued: \
                      a step left S(t) infinite or X singular (a finite escape time, when Q \
                      or Sf is indefinite, or S beyond the range of doubles)"
                .into(),
        });
    }
    let mut next = next.transpose().to_owned();
    next.symmetrize();
    Ok(next)
}

/// Times must be finite and strictly increasing, at least one.
fn check_times(times: &[f64]) -> Result<(), Error> {
    if times.is_empty() {
        return Err(Error::InvalidArgument {
            arg: "t",
            message: "t must hold at least one time (the final time t_f)".into(),
        });
    }
    if let Some(index) = times.iter().position(|t| !t.is_finite()) {
        return Err(Error::NonFinite {
            arg: "t",
            index: vec![index],
            value: times[index],
        });
    }
    if let Some(index) = times.windows(2).position(|pair| pair[1] <= pair[0]) {
        return Err(Error::InvalidArgument {
            arg: "t",
            message: format!(
                "t must be strictly increasing, but t[{}] = {} follows t[{index}] = {}",
                index + 1,
                times[index + 1],
                times[index]
            ),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// t_k = t_0 + k (t_last - t_0) / (len - 1) rounded, as numpy.linspace makes it.
    fn linspace(first: f64, last: f64, len: usize) -> Vec<f64> {
        let step = (last - first) / (len - 1) as f64;
        let mut grid: Vec<f64> = (0..len).map(|k| first + k as f64 * step).collect();
        grid[len - 1] = last;
        grid
    }

    #[test]
    fn uniform_step_accepts_grids_uniform_to_rounding() {
        // The intervals of linspace(0, 20, 201) take 9 different values around 0.1.
        let grid = linspace(0.0, 20.0, 201);
        let intervals: std::collections::BTreeSet<u64> =
            grid.windows(2).map(|w| (w[1] - w[0]).to_bits()).collect();
        assert!(intervals.len() > 1);
        assert_eq!(uniform_step(&grid), Some(0.1));
        let shifted = linspace(-3.0, 1e3, 1001);
        assert_eq!(uniform_step(&shifted), Some(1003.0 / 1000.0));
        assert_eq!(uniform_step(&[2.0, 5.0]), Some(3.0));
    }

    #[test]
    fn uniform_step_refuses_other_grids() {
        assert_eq!(uniform_step(&[1.0]), None);
        assert_eq!(uniform_step(&[0.0, 0.1, 0.3]), None);
        let mut grid = linspace(0.0, 20.0, 201);
        // One time moved by 64 units of roundoff of the grid's largest time.
        grid[100] += 64.0 * f64::EPSILON * 20.0;
        assert_eq!(uniform_step(&grid), None);
        // Accumulated by a loop (numpy.arange computes start + k step instead): the times
        // drift from the even spacing by far more than their rounding, so each interval is
        // taken as given.
        let mut summed = vec![0.0];
        for _ in 0..1000 {
            summed.push(summed[summed.len() - 1] + 0.01);
        }
        assert_eq!(uniform_step(&summed), None);
        let logarithmic: Vec<f64> = (0..50).map(|k| 1.1f64.powi(k)).collect();
        assert_eq!(uniform_step(&logarithmic), None);
    }
}
