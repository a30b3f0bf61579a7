//! The Hessenberg-triangular reduction of a pencil (Moler & Stewart 1973; Golub & Van Loan,
//! *Matrix Computations*, 4th ed., Algorithm 7.7.1): orthogonal Q, Z with Q^T A Z upper
//! Hessenberg and Q^T B Z upper triangular.
//!
//! First B = Q R by Householder reflectors, applied to A from the left. Then, column by column
//! from the left and from the bottom up, a rotation of rows (i - 1, i) zeroes A[i, j], which
//! puts a fill-in at B[i, i - 1], and a rotation of columns (i - 1, i) zeroes that again. About
//! 8 n^3 flops for A and B and 3 n^3 each for Q and Z. Every transformation is orthogonal, so the
//! reduction is backward stable.

use crate::error::Error;
use crate::linalg::householder::reflector;
use crate::linalg::rotation::Rotation;
use crate::platform::interrupt;
use faer::Mat;

/// Reduces (a, b) in place and accumulates the transformations into q and z (from the left
/// and right: on return the original A is Q a Z^T when q and z entered as identities).
pub(crate) fn hessenberg_triangular(
    a: &mut Mat<f64>,
    b: &mut Mat<f64>,
    q: &mut Mat<f64>,
    z: &mut Mat<f64>,
) -> Result<(), Error> {
    let n = a.nrows();
    triangularize(b, a, q)?;
    for j in 0..n.saturating_sub(2) {
        interrupt::check()?;
        for i in (j + 2..n).rev() {
            let (g, r) = Rotation::zeroing(a[(i - 1, j)], a[(i, j)]);
            a[(i - 1, j)] = r;
            a[(i, j)] = 0.0;
            g.rows(a, i - 1, i, j + 1..n);
            g.rows(b, i - 1, i, i - 1..n);
            g.columns(q, i - 1, i, 0..n);
            let (g, r) = Rotation::zeroing_first(b[(i, i - 1)], b[(i, i)]);
            b[(i, i)] = r;
            b[(i, i - 1)] = 0.0;
            g.columns(b, i - 1, i, 0..i);
            g.columns(a, i - 1, i, 0..n);
            g.columns(z, i - 1, i, 0..n);
        }
    }
    Ok(())
}

/// B = Q R by Householder reflectors; `other` (A) is multiplied by Q^T and Q accumulated.
fn triangularize(b: &mut Mat<f64>, other: &mut Mat<f64>, q: &mut Mat<f64>) -> Result<(), Error> {
    let n = b.nrows();
    let mut v = Vec::new();
    let mut w = vec![0.0; n];
    for j in 0..n.saturating_sub(1) {
        interrupt::check()?;
        v.clear();
        v.extend((j..n).map(|i| b[(i, j)]));
        let (beta, tau) = reflector(&mut v);
        v[0] = 1.0;
        b[(j, j)] = beta;
        for i in j + 1..n {
            b[(i, j)] = 0.0;
        }
        if tau == 0.0 {
            continue;
        }
        let reflect_column = |m: &mut Mat<f64>, col: usize| {
            let s: f64 = v
                .iter()
                .enumerate()
                .map(|(k, vk)| vk * m[(j + k, col)])
                .sum();
            let s = tau * s;
            for (k, vk) in v.iter().enumerate() {
                m[(j + k, col)] -= s * vk;
            }
        };
        for col in j + 1..n {
            reflect_column(b, col);
        }
        for col in 0..n {
            reflect_column(other, col);
        }
        // Q <- Q (I - τ v v^T): w = Q v, then Q -= τ w v^T, column by column.
        w.iter_mut().for_each(|x| *x = 0.0);
        for (k, vk) in v.iter().enumerate() {
            for (r, wr) in w.iter_mut().enumerate() {
                *wr += vk * q[(r, j + k)];
            }
        }
        for (k, vk) in v.iter().enumerate() {
            for (r, wr) in w.iter().enumerate() {
                q[(r, j + k)] -= tau * wr * vk;
            }
        }
    }
    Ok(())
}
