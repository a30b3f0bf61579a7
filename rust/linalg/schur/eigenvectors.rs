//! The eigenvectors of a real matrix from its Schur form A = Z T Z^T: those of T by back
//! substitution, then multiplied by Z (Golub & Van Loan, Matrix Computations, 4th ed., §7.6.4;
//! the method of LAPACK's xTREVC).
//!
//! For an eigenvalue λ of the diagonal block of T at k (1 x 1, or 2 x 2 in standard form
//! [[a, b], [c, a]], b c < 0, λ = a + iω with ω = sqrt(|b|) sqrt(|c|)), the eigenvector x of T
//! is zero below the block, the block's own null vector v of B - λI within it
//! (v = [1, iω/b] when |b| >= |c|, else [iω/c, 1], of components at most 1), and above it the
//! solution of the quasi-triangular system
//!
//! ```text
//!     (T_11 - λI) x_1 = -T_1k v,
//! ```
//!
//! solved block by block upwards: a 1 x 1 block divides, a 2 x 2 block solves its complex
//! 2 x 2 system by Gaussian elimination with complete pivoting. A pivot below
//! s_min = max(u |λ|, u ||T||_max, smallest normal) is replaced by s_min (LAPACK's
//! perturbation: a repeated or defective eigenvalue then gives nearly parallel vectors, which
//! the modal matrix's condition number reports, instead of a division by zero). Whenever a
//! component exceeds 2^500 the vector computed so far is scaled by 2^-500 (exact), so that a
//! chain of such pivots cannot overflow; each vector is normalised at the end. The
//! eigenvector of the conjugate eigenvalue is the conjugate vector.

use crate::error::Error;
use crate::linalg::product::multiply;
use crate::linalg::schur::RealSchur;
use crate::platform::interrupt;
use faer::{Accum, Mat, Par, c64};

/// A component beyond this makes the vector be scaled by [`RESCALE`].
const LARGE: f64 = 3.273390607896142e150; // 2^500
const RESCALE: f64 = 3.054936363499605e-151; // 2^-500

/// The eigenvalues of A = Z T Z^T in the order of T's diagonal (each conjugate pair adjacent,
/// Im > 0 first) and the unit eigenvectors of D A D^-1 as columns, in the same order, for D
/// the diagonal `scaling` (empty: the identity; a balancing's, to undo it).
///
/// Each eigenvector's back substitution (O(k^2) for the k-th, O(n^3) in all) starts with a
/// check of the computation's interrupt, so that Ctrl-C stops a large one between vectors.
pub fn schur_eigenvectors(
    schur: &RealSchur,
    scaling: &[f64],
) -> Result<(Vec<c64>, Mat<c64>), Error> {
    let t = schur.t.as_ref();
    let n = t.nrows();
    let largest = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .fold(0.0f64, |m, (i, j)| m.max(t[(i, j)].abs()));
    let mut values = Vec::with_capacity(n);
    // The eigenvectors of T, real and imaginary parts, column k for the k-th eigenvalue.
    let (mut x_re, mut x_im) = (Mat::<f64>::zeros(n, n), Mat::<f64>::zeros(n, n));
    let mut k = 0;
    while k < n {
        interrupt::check()?;
        let pair = k + 1 < n && t[(k + 1, k)] != 0.0;
        let mut x = vec![c64::new(0.0, 0.0); n];
        let lambda = if pair {
            let (a, b, c) = (t[(k, k)], t[(k, k + 1)], t[(k + 1, k)]);
            let omega = b.abs().sqrt() * c.abs().sqrt();
            // The null vector of [[-iω, b], [c, -iω]], its larger component 1.
            if b.abs() >= c.abs() {
                x[k] = c64::new(1.0, 0.0);
                x[k + 1] = c64::new(0.0, omega / b);
            } else {
                x[k] = c64::new(0.0, omega / c);
                x[k + 1] = c64::new(1.0, 0.0);
            }
            c64::new(a, omega)
        } else {
            x[k] = c64::new(1.0, 0.0);
            c64::new(t[(k, k)], 0.0)
        };
        let top = if pair { k + 2 } else { k + 1 };
        // The right-hand side -T_1k v above the block.
        for i in 0..k {
            x[i] = -(k..top).map(|j| x[j] * t[(i, j)]).sum::<c64>();
        }
        let small = (f64::EPSILON * lambda.norm())
            .max(f64::EPSILON * largest)
            .max(f64::MIN_POSITIVE);
        back_substitute(t, lambda, small, k, &mut x);
        let norm = x.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
        for (i, v) in x.iter().enumerate() {
            x_re[(i, values.len())] = v.re / norm;
            x_im[(i, values.len())] = v.im / norm;
        }
        values.push(lambda);
        if pair {
            for i in 0..n {
                x_re[(i, values.len())] = x_re[(i, values.len() - 1)];
                x_im[(i, values.len())] = -x_im[(i, values.len() - 1)];
            }
            values.push(lambda.conj());
        }
        k = top;
    }
    // The eigenvectors of A: Z X.
    let (mut v_re, mut v_im) = (Mat::<f64>::zeros(n, n), Mat::<f64>::zeros(n, n));
    let z = schur.z.as_ref();
    multiply(
        v_re.as_mut(),
        Accum::Replace,
        z,
        x_re.as_ref(),
        1.0,
        Par::Seq,
    )?;
    multiply(
        v_im.as_mut(),
        Accum::Replace,
        z,
        x_im.as_ref(),
        1.0,
        Par::Seq,
    )?;
    let row = |i: usize| scaling.get(i).copied().unwrap_or(1.0);
    let mut vectors = Mat::from_fn(n, n, |i, j| c64::new(v_re[(i, j)], v_im[(i, j)]) * row(i));
    for j in 0..n {
        let norm = vectors.col(j).norm_l2();
        if norm > 0.0 {
            for i in 0..n {
                vectors[(i, j)] /= norm;
            }
        }
    }
    Ok((values, vectors))
}

/// Solves (T[..k, ..k] - λI) x[..k] = x[..k] in place, block by block upwards, updating the
/// right-hand side above each solved block; pivots below `small` are replaced by it.
fn back_substitute(t: faer::MatRef<'_, f64>, lambda: c64, small: f64, k: usize, x: &mut [c64]) {
    let mut end = k; // rows ..end remain
    while end > 0 {
        let j = end - 1;
        let two = j > 0 && t[(j, j - 1)] != 0.0;
        let first = if two { j - 1 } else { j };
        if two {
            let m = [
                [
                    c64::new(t[(first, first)], 0.0) - lambda,
                    c64::new(t[(first, j)], 0.0),
                ],
                [
                    c64::new(t[(j, first)], 0.0),
                    c64::new(t[(j, j)], 0.0) - lambda,
                ],
            ];
            let (u, w) = solve_two(m, [x[first], x[j]], small);
            x[first] = u;
            x[j] = w;
        } else {
            let mut pivot = c64::new(t[(j, j)], 0.0) - lambda;
            if pivot.norm() < small {
                pivot = c64::new(small, 0.0);
            }
            x[j] /= pivot;
        }
        let largest = (first..=j).map(|i| x[i].norm()).fold(0.0f64, f64::max);
        if largest > LARGE {
            x.iter_mut().for_each(|v| *v *= RESCALE);
        }
        for i in 0..first {
            x[i] -= (first..=j).map(|l| x[l] * t[(i, l)]).sum::<c64>();
        }
        end = first;
    }
}

/// The solution of the complex 2 x 2 system m y = r by Gaussian elimination with complete
/// pivoting, a pivot below `small` replaced by it.
fn solve_two(m: [[c64; 2]; 2], r: [c64; 2], small: f64) -> (c64, c64) {
    // The largest entry as the first pivot (rows and columns swapped to bring it to (0, 0)).
    let (mut pi, mut pj) = (0, 0);
    for i in 0..2 {
        for j in 0..2 {
            if m[i][j].norm() > m[pi][pj].norm() {
                (pi, pj) = (i, j);
            }
        }
    }
    let (qi, qj) = (1 - pi, 1 - pj);
    let mut p = m[pi][pj];
    if p.norm() < small {
        p = c64::new(small, 0.0);
    }
    let factor = m[qi][pj] / p;
    let mut second = m[qi][qj] - factor * m[pi][qj];
    if second.norm() < small {
        second = c64::new(small, 0.0);
    }
    let y_q = (r[qi] - factor * r[pi]) / second;
    let y_p = (r[pi] - m[pi][qj] * y_q) / p;
    // y_p is the unknown of column pj, y_q of column qj.
    if pj == 0 { (y_p, y_q) } else { (y_q, y_p) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::schur::real_schur;
    use crate::test_matrices::seeded_square;

    fn residual(a: &Mat<f64>, values: &[c64], vectors: &Mat<c64>) -> f64 {
        let n = a.nrows();
        let mut worst = 0.0f64;
        for (k, &lambda) in values.iter().enumerate() {
            for i in 0..n {
                let av: c64 = (0..n).map(|j| vectors[(j, k)] * a[(i, j)]).sum();
                worst = worst.max((av - vectors[(i, k)] * lambda).norm());
            }
        }
        worst
    }

    #[test]
    fn eigenvectors_satisfy_a_v_equals_v_lambda() {
        for n in [1, 2, 3, 4, 7, 16, 40, 90] {
            let a = seeded_square(n, 7 + n as u64);
            let (values, vectors) =
                schur_eigenvectors(&real_schur(a.as_ref()).unwrap(), &[]).unwrap();
            let size = a.norm_l2();
            assert!(residual(&a, &values, &vectors) <= 100.0 * n as f64 * f64::EPSILON * size);
            for j in 0..n {
                assert!((vectors.col(j).norm_l2() - 1.0).abs() <= 1e-14);
            }
        }
    }

    #[test]
    fn a_defective_eigenvalue_gives_finite_parallel_vectors() {
        // A Jordan block of order 30: one eigenvector e_1; the perturbed pivots give vectors
        // that are finite and all close to it.
        let n = 30;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == j {
                -2.0
            } else if j == i + 1 {
                1.0
            } else {
                0.0
            }
        });
        let (values, vectors) = schur_eigenvectors(&real_schur(a.as_ref()).unwrap(), &[]).unwrap();
        assert!(
            values
                .iter()
                .all(|v| (v - c64::new(-2.0, 0.0)).norm() == 0.0)
        );
        for j in 0..n {
            assert!(
                vectors
                    .col(j)
                    .iter()
                    .all(|v| v.re.is_finite() && v.im.is_finite())
            );
            assert!(vectors[(0, j)].norm() > 1.0 - 1e-10);
        }
    }

    #[test]
    fn complex_pair_of_a_rotation() {
        // [[0, -2], [0.5, 0]]: λ = ±i, the eigenvector of i proportional to [2, -i]; the
        // conjugate pair in order, the second vector the first's conjugate.
        let a = Mat::from_fn(2, 2, |i, j| [[0.0, -2.0], [0.5, 0.0]][i][j]);
        let (values, vectors) = schur_eigenvectors(&real_schur(a.as_ref()).unwrap(), &[]).unwrap();
        assert!((values[0] - c64::new(0.0, 1.0)).norm() <= 1e-15);
        assert_eq!(values[1], values[0].conj());
        assert!(residual(&a, &values, &vectors) <= 1e-15);
        for i in 0..2 {
            assert_eq!(vectors[(i, 1)], vectors[(i, 0)].conj());
        }
    }
}
