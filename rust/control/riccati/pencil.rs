//! The pieces of the extended-pencil Riccati solvers ([`super::dare`], and [`super::care`] with
//! an indefinite R): their argument checks, the compression of a pencil's input columns, and
//! the solution X from a deflating subspace.
//!
//! An extended pencil M - λ N of order 2n + m whose last m columns belong to the input u is
//! compressed to order 2n by the QR factorisation of M's last m columns, M_u = W [R_u; 0]:
//! applying W^T to the rows of both matrices and keeping rows m.. and columns ..2n leaves a
//! pencil with the same finite eigenvalues and the same deflating subspaces in (x, λ) (Van
//! Dooren 1981). It needs no inverse of R, so R may be indefinite or ill-conditioned.

use super::care::symmetric;
use crate::error::{Error, check_finite, check_rows, check_square};
use crate::linalg::householder::reflector;
use crate::linalg::lu::solve_with_inverse;
use crate::linalg::matrix::{FaerView, Symmetrize};
use crate::linalg::norm::one_norm;
use crate::linalg::product::product;
use crate::linalg::qz::GeneralizedSchur;
use faer::{Mat, MatRef};

/// The pencil (big_m, big_n) of order keep + m with its last m columns compressed away:
/// returns the keep x keep pencil.
pub(crate) fn compress(
    mut big_m: Mat<f64>,
    mut big_n: Mat<f64>,
    keep: usize,
) -> (Mat<f64>, Mat<f64>) {
    let size = big_m.nrows();
    let m = size - keep;
    let mut v = Vec::with_capacity(size);
    for c in 0..m {
        let col = keep + c;
        v.clear();
        v.extend((c..size).map(|i| big_m[(i, col)]));
        let (_, tau) = reflector(&mut v);
        v[0] = 1.0;
        if tau == 0.0 {
            continue;
        }
        for matrix in [&mut big_m, &mut big_n] {
            for j in 0..size {
                let w: f64 = v
                    .iter()
                    .enumerate()
                    .map(|(k, vk)| vk * matrix[(c + k, j)])
                    .sum();
                for (k, vk) in v.iter().enumerate() {
                    matrix[(c + k, j)] -= tau * w * vk;
                }
            }
        }
    }
    let take = |matrix: &Mat<f64>| Mat::from_fn(keep, keep, |i, j| matrix[(m + i, j)]);
    (take(&big_m), take(&big_n))
}

/// X = U21 (E U11)^-1 from the leading n columns [U11; U21] of Z, symmetrised, with the
/// reciprocal 1-norm condition number of E U11; `None` when E U11 is singular to working
/// precision (the subspace is not a graph).
pub(crate) fn graph_solution(
    form: &GeneralizedSchur,
    e: MatRef<'_, f64>,
    n: usize,
) -> Option<(Mat<f64>, f64)> {
    if n == 0 {
        // E U11 of order 0 is perfectly conditioned (1 / (0 * 0) would say inf).
        return Some((Mat::zeros(0, 0), 1.0));
    }
    let u11 = form.z.as_ref().submatrix(0, 0, n, n);
    let u21 = form.z.as_ref().submatrix(n, 0, n, n);
    // (E U11)^T X^T = U21^T.
    // An interruption refuses the subspace (the caller's next check stops).
    let eu11 = product(e, u11).ok()?;
    let norm = one_norm(eu11.as_ref());
    let mut factor = eu11.transpose().to_owned();
    let combined = solve_with_inverse(factor.as_mut(), u21.transpose()).ok()?;
    let (xt, inverse) = combined.as_ref().split_at_col(n);
    // The inverse of (E U11)^T: the 1-norm of its transpose is that of (E U11)^-1.
    let rcond = 1.0 / (norm * one_norm(inverse.transpose()));
    if !xt.is_all_finite() || rcond.is_nan() || rcond <= f64::EPSILON {
        return None;
    }
    let mut x = xt.transpose().to_owned();
    x.symmetrize();
    Some((x, rcond))
}

/// The checks shared by the pencil solvers and the difference equation: A square and finite,
/// B finite with n rows, Q and R finite and symmetric (to [`super::care::SYMMETRY_TOLERANCE`]),
/// the cross weight finite n x m (named by the caller: S or N) and E finite n x n when given.
/// Returns Q and R symmetrised.
pub(crate) fn checked_weights(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    cross: Option<(MatRef<'_, f64>, &'static str)>,
    e: Option<MatRef<'_, f64>>,
) -> Result<(Mat<f64>, Mat<f64>), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    let n = a.nrows();
    check_rows(b, "B", n, "A")?;
    check_finite(b, "B")?;
    let m = b.ncols();
    let q = symmetric(q, "Q", n, "A")?.to_faer();
    let r = symmetric(r, "R", m, "the columns of B")?.to_faer();
    if let Some((s, name)) = cross {
        check_rows(s, name, n, "A")?;
        check_finite(s, name)?;
        if s.ncols() != m {
            return Err(Error::Mismatch {
                arg: name,
                what: "columns",
                expected: m,
                other: "B",
                got: s.ncols(),
            });
        }
    }
    if let Some(e) = e {
        check_square(e, "E")?;
        check_rows(e, "E", n, "A")?;
        check_finite(e, "E")?;
    }
    Ok((q, r))
}
