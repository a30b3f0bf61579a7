//! Frequency response G(jω) = C (jωI - A)^-1 B + D at many frequencies (chapter §6.3).
//!
//! One Hessenberg reduction A = Q H Q^T (`hessenberg.rs`) turns every shifted solve into a
//! Hessenberg one:
//!
//! ```text
//! G(jω) = (C Q) (jωI - H)^-1 (Q^T B) + D,
//! ```
//!
//! and jωI - H is reduced to upper triangular form by eliminating its subdiagonal one entry at
//! a time, with partial pivoting between the two rows involved (the only rows with an entry in
//! that column). Each frequency then costs O(n^2 + n^2 m + p n m) instead of the O(n^3) of a
//! dense solve. The elimination is backward stable for each frequency, as Gaussian elimination
//! with partial pivoting is. Frequencies run in parallel.
//!
//! A frequency at an eigenvalue of A on the imaginary axis (a pole of G) gives infinite or NaN
//! entries, never an error: the caller decides how to report them.

use crate::error::{
    Error, check_finite, check_finite_values, check_output_len, check_rows, check_square,
};
use crate::hessenberg::{Hessenberg, hessenberg};
use faer::{Mat, MatRef, c64};
use rayon::prelude::*;

/// Checks A (n x n), B (n x m), C (p x n) and D (p x m) of a state-space model.
pub fn check_state_space(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
) -> Result<(), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    let n = a.nrows();
    check_rows(b, "B", n, "A")?;
    check_finite(b, "B")?;
    if c.ncols() != n {
        return Err(Error::Mismatch {
            arg: "C",
            what: "as many columns as",
            expected: n,
            other: "A",
            got: c.ncols(),
        });
    }
    check_finite(c, "C")?;
    check_rows(d, "D", c.nrows(), "C")?;
    if d.ncols() != b.ncols() {
        return Err(Error::Mismatch {
            arg: "D",
            what: "as many columns as",
            expected: b.ncols(),
            other: "B",
            got: d.ncols(),
        });
    }
    check_finite(d, "D")
}

/// The model in Hessenberg coordinates: H, Q^T B, C Q, D.
struct HessenbergModel {
    h: Mat<f64>,
    b: Mat<f64>,
    c: Mat<f64>,
    d: Mat<f64>,
}

/// Solves (jωI - H) X = B̃ into `x` (n x m row-major) with `work` (n x n row-major) as the
/// eliminated matrix.
fn solve_shifted(model: &HessenbergModel, omega: f64, work: &mut [c64], x: &mut [c64]) {
    let n = model.h.nrows();
    let m = model.b.ncols();
    for i in 0..n {
        for j in 0..n {
            work[i * n + j] = c64::new(-model.h[(i, j)], 0.0);
        }
        work[i * n + i].im += omega;
        for j in 0..m {
            x[i * m + j] = c64::new(model.b[(i, j)], 0.0);
        }
    }
    // Eliminate the subdiagonal, column by column, pivoting between rows k and k + 1.
    for k in 0..n.saturating_sub(1) {
        let (upper, lower) = work.split_at_mut((k + 1) * n);
        let (row_k, row_next) = (&mut upper[k * n..], &mut lower[..n]);
        if row_next[k].norm_sqr() > row_k[k].norm_sqr() {
            row_k[k..].swap_with_slice(&mut row_next[k..]);
            let (x_upper, x_lower) = x.split_at_mut((k + 1) * m);
            x_upper[k * m..].swap_with_slice(&mut x_lower[..m]);
        }
        if row_next[k] == c64::new(0.0, 0.0) {
            continue;
        }
        let factor = row_next[k] / row_k[k];
        row_next[k] = c64::new(0.0, 0.0);
        for j in k + 1..n {
            row_next[j] -= factor * row_k[j];
        }
        let (x_upper, x_lower) = x.split_at_mut((k + 1) * m);
        for j in 0..m {
            x_lower[j] -= factor * x_upper[k * m + j];
        }
    }
    // Back substitution with the upper triangular result.
    for k in (0..n).rev() {
        let (done_rows, below) = x.split_at_mut((k + 1) * m);
        let row = &mut done_rows[k * m..];
        for (i, solved) in below.chunks_exact(m).enumerate() {
            let coefficient = work[k * n + k + 1 + i];
            for (value, s) in row.iter_mut().zip(solved) {
                *value -= coefficient * s;
            }
        }
        let pivot = work[k * n + k];
        for value in row.iter_mut() {
            *value /= pivot;
        }
    }
}

/// Writes G(jω_k) = C (jω_k I - A)^-1 B + D for every ω_k into `out`, a row-major
/// len(omega) x p x m stack.
pub fn frequency_response_into(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    omega: &[f64],
    out: &mut [c64],
) -> Result<(), Error> {
    check_state_space(a, b, c, d)?;
    check_finite_values(omega, "omega")?;
    let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
    check_output_len(out.len(), omega.len() * p * m)?;
    if p * m == 0 {
        return Ok(());
    }
    let Hessenberg { h, q } = hessenberg(a);
    let model = HessenbergModel {
        h,
        b: q.transpose() * b,
        c: c * &q,
        d: d.to_owned(),
    };
    let evaluate = |(work, x): &mut (Vec<c64>, Vec<c64>), (&w, g): (&f64, &mut [c64])| {
        solve_shifted(&model, w, work, x);
        for i in 0..p {
            for j in 0..m {
                let mut value = c64::new(model.d[(i, j)], 0.0);
                for k in 0..n {
                    value += model.c[(i, k)] * x[k * m + j];
                }
                g[i * m + j] = value;
            }
        }
    };
    let workspace = || {
        (
            vec![c64::new(0.0, 0.0); n * n],
            vec![c64::new(0.0, 0.0); n * m],
        )
    };
    omega
        .par_iter()
        .zip(out.par_chunks_mut(p * m))
        .with_min_len(16)
        .for_each_init(workspace, evaluate);
    Ok(())
}

/// G(jω) for every ω, as a vector of p x m complex matrices.
pub fn frequency_response(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    omega: &[f64],
) -> Result<Vec<Mat<c64>>, Error> {
    let (p, m) = (c.nrows(), b.ncols());
    let mut out = vec![c64::new(0.0, 0.0); omega.len() * p * m];
    frequency_response_into(a, b, c, d, omega, &mut out)?;
    Ok((0..omega.len())
        .map(|k| Mat::from_fn(p, m, |i, j| out[k * p * m + i * m + j]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::Solve;
    use faer::mat;

    /// G(jω) by a dense complex solve, as the reference.
    fn dense(a: &Mat<f64>, b: &Mat<f64>, c: &Mat<f64>, d: &Mat<f64>, w: f64) -> Mat<c64> {
        let n = a.nrows();
        let shifted = Mat::from_fn(n, n, |i, j| {
            c64::new(-a[(i, j)], if i == j { w } else { 0.0 })
        });
        let rhs = Mat::from_fn(n, b.ncols(), |i, j| c64::new(b[(i, j)], 0.0));
        let x = shifted.partial_piv_lu().solve(&rhs);
        let cc = Mat::from_fn(c.nrows(), n, |i, j| c64::new(c[(i, j)], 0.0));
        let dd = Mat::from_fn(d.nrows(), d.ncols(), |i, j| c64::new(d[(i, j)], 0.0));
        cc * x + dd
    }

    #[test]
    fn matches_a_dense_solve() {
        for n in [1usize, 2, 4, 9, 30] {
            let mut state = n as u64;
            let a = Mat::from_fn(n, n, |_, _| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            });
            let b = Mat::from_fn(n, 2, |i, j| (i + 3 * j) as f64 / n as f64 - 0.5);
            let c = Mat::from_fn(3, n, |i, j| ((i + j) % 4) as f64 - 1.5);
            let d = Mat::from_fn(3, 2, |i, j| (i as f64) - (j as f64));
            let omega = [0.0, 0.01, 0.7, 3.0, 100.0, -2.0];
            let g =
                frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &omega).unwrap();
            for (k, &w) in omega.iter().enumerate() {
                let expected = dense(&a, &b, &c, &d, w);
                let err = (&g[k] - &expected).norm_l2() / expected.norm_l2().max(1e-300);
                assert!(err < 1e-12, "n={n} w={w}: {err}");
            }
        }
    }

    #[test]
    fn first_order_lag() {
        // G(s) = 1 / (s + 2): |G(2j)| = 1 / (2 sqrt 2), phase -45 degrees.
        let g = frequency_response(
            mat![[-2.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            &[2.0],
        )
        .unwrap();
        let value = g[0][(0, 0)];
        assert!((value.norm() - 1.0 / 8f64.sqrt()).abs() < 1e-16);
        assert!((value.arg().to_degrees() + 45.0).abs() < 1e-13);
    }

    #[test]
    fn dimension_errors_name_the_matrix() {
        let a = Mat::<f64>::identity(3, 3);
        let b = Mat::<f64>::zeros(3, 1);
        let c = Mat::<f64>::zeros(2, 4);
        let d = Mat::<f64>::zeros(2, 1);
        let err =
            frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[1.0]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "C must have as many columns as A (3), got 4"
        );
        let c = Mat::<f64>::zeros(2, 3);
        let d = Mat::<f64>::zeros(2, 2);
        let err =
            frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[1.0]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "D must have as many columns as B (1), got 2"
        );
        let d = Mat::<f64>::zeros(2, 1);
        let err = frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[f64::NAN])
            .unwrap_err();
        assert!(matches!(err, Error::NonFinite { arg: "omega", .. }));
    }
}
