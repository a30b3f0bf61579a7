//! Products and factorisations of the temporaries of the control algorithms, on nalgebra's
//! `DMatrix` (a column-major vector with its shape; see [`crate::linalg::matrix`]).
//!
//! A 4-state Riccati solve forms some forty temporaries of order n and m (products, residuals,
//! gains, factors). As faer matrices each costs an aligned allocation and faer's construction
//! machinery, and every entry access a bounds-checked strided index, which together cost more
//! than the arithmetic. Small products and factorisations are plain loops here, compiled for
//! column lengths known at compile time where [`with_order!`] finds one; large ones lend the
//! matrices to faer as views (no copy) for its blocked kernels.

use faer::prelude::ReborrowMut;
use faer::{Mat, MatMut, MatRef};
use nalgebra::DMatrix;

use crate::error::Error;
use crate::linalg::matrix::{FaerView, from_faer, with_order};
use crate::linalg::product::multiply;

/// Products of at most this many multiply-adds are plain loops, larger ones faer's blocked
/// kernel (as [`view_product`]).
const LOOP_PRODUCT_MAX_WORK: usize = 16 * 16 * 16;

/// lhs * rhs for matrices of any (conforming) shapes and strides: a plain column-by-column
/// loop when the product is small (the Riccati and Lyapunov solvers form a dozen products of
/// order n and m at n = 4), faer's blocked kernel otherwise, in column panels with a check of
/// the interruption between them ([`crate::linalg::product::multiply`]: bitwise one call).
pub fn view_product(lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    let mut out = Mat::<f64>::zeros(lhs.nrows(), rhs.ncols());
    if lhs.nrows() * lhs.ncols() * rhs.ncols() > LOOP_PRODUCT_MAX_WORK {
        multiply(
            out.as_mut(),
            faer::Accum::Replace,
            lhs,
            rhs,
            1.0,
            faer::Par::Seq,
        )?;
    } else {
        view_product_into(out.as_mut(), lhs, rhs, faer::Par::Seq);
    }
    Ok(out)
}

/// out = lhs * rhs, as [`view_product`] forms it, with faer's kernel on `par` for large
/// products.
pub fn view_product_into(
    mut out: MatMut<'_, f64>,
    lhs: MatRef<'_, f64>,
    rhs: MatRef<'_, f64>,
    par: faer::Par,
) {
    let (rows, inner, cols) = (lhs.nrows(), lhs.ncols(), rhs.ncols());
    debug_assert_eq!(inner, rhs.nrows());
    debug_assert_eq!((rows, cols), (out.nrows(), out.ncols()));
    if rows * inner * cols > LOOP_PRODUCT_MAX_WORK {
        faer::linalg::matmul::matmul(out, faer::Accum::Replace, lhs, rhs, 1.0, par);
        return;
    }
    out.fill(0.0);
    for j in 0..cols {
        let mut column = out.rb_mut().col_mut(j);
        for k in 0..inner {
            let coefficient = rhs[(k, j)];
            // Contiguous columns (faer's own matrices) as slices: no per-entry index checks.
            match (
                lhs.col(k).try_as_col_major(),
                column.rb_mut().try_as_col_major_mut(),
            ) {
                (Some(lhs_column), Some(out_column)) => {
                    for (entry, x) in out_column
                        .as_slice_mut()
                        .iter_mut()
                        .zip(lhs_column.as_slice())
                    {
                        *entry += x * coefficient;
                    }
                }
                _ => {
                    for i in 0..rows {
                        column[i] += lhs[(i, k)] * coefficient;
                    }
                }
            }
        }
    }
}

/// lhs * rhs. Each entry of a small product is the sum over k, in order, of
/// lhs[i, k] rhs[k, j], as [`view_product`] forms it.
pub(crate) fn product(lhs: &DMatrix<f64>, rhs: &DMatrix<f64>) -> DMatrix<f64> {
    let (rows, inner, cols) = (lhs.nrows(), lhs.ncols(), rhs.ncols());
    debug_assert_eq!(inner, rhs.nrows());
    let mut out = DMatrix::zeros(rows, cols);
    if rows * inner * cols > LOOP_PRODUCT_MAX_WORK {
        faer::linalg::matmul::matmul(
            out.as_faer_mut(),
            faer::Accum::Replace,
            lhs.as_faer(),
            rhs.as_faer(),
            1.0,
            faer::Par::Seq,
        );
        return out;
    }
    with_order!(
        rows,
        [1, 2, 3, 4, 5, 6, 7, 8],
        R => product_in::<R>(lhs, rhs, &mut out),
        _ => {
            for j in 0..cols {
                let (rhs_column, column) = (rhs.column_slice(j), out.column_slice_mut(j));
                for (k, &coefficient) in rhs_column.iter().enumerate() {
                    for (entry, x) in column.iter_mut().zip(lhs.column_slice(k)) {
                        *entry += x * coefficient;
                    }
                }
            }
        }
    );
    out
}

/// The loops of [`product`] for columns of length R known at compile time: each column update
/// is a few vector operations instead of a loop (the same operations in the same order).
fn product_in<const R: usize>(lhs: &DMatrix<f64>, rhs: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    for (j, column) in out.as_mut_slice().chunks_exact_mut(R).enumerate() {
        let column: &mut [f64; R] = column.try_into().expect("columns of R entries");
        for (k, &coefficient) in rhs.column_slice(j).iter().enumerate() {
            let lhs_column: &[f64; R] = lhs
                .column_slice(k)
                .try_into()
                .expect("columns of R entries");
            for r in 0..R {
                column[r] += lhs_column[r] * coefficient;
            }
        }
    }
}

/// lhs^T * rhs: each entry a dot product of two columns, summed in order (the same values as
/// [`product`] of the transpose).
pub(crate) fn transposed_product(lhs: &DMatrix<f64>, rhs: &DMatrix<f64>) -> DMatrix<f64> {
    let (rows, inner, cols) = (lhs.ncols(), lhs.nrows(), rhs.ncols());
    debug_assert_eq!(inner, rhs.nrows());
    if rows * inner * cols > LOOP_PRODUCT_MAX_WORK {
        let mut out = DMatrix::zeros(rows, cols);
        faer::linalg::matmul::matmul(
            out.as_faer_mut(),
            faer::Accum::Replace,
            lhs.as_faer().transpose(),
            rhs.as_faer(),
            1.0,
            faer::Par::Seq,
        );
        return out;
    }
    with_order!(
        inner,
        [1, 2, 3, 4, 5, 6, 7, 8],
        K => transposed_product_in::<K>(lhs, rhs),
        _ => DMatrix::from_fn(rows, cols, |i, j| {
            let mut sum = 0.0;
            for (x, y) in lhs.column_slice(i).iter().zip(rhs.column_slice(j)) {
                sum += x * y;
            }
            sum
        })
    )
}

/// [`transposed_product`] for an inner dimension K known at compile time: each dot product
/// unrolls (summed in the same order).
fn transposed_product_in<const K: usize>(lhs: &DMatrix<f64>, rhs: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(lhs.ncols(), rhs.ncols());
    let rows = lhs.ncols();
    for (j, column) in out.as_mut_slice().chunks_exact_mut(rows.max(1)).enumerate() {
        let y: &[f64; K] = rhs
            .column_slice(j)
            .try_into()
            .expect("columns of K entries");
        for (i, entry) in column.iter_mut().enumerate() {
            let x: &[f64; K] = lhs
                .column_slice(i)
                .try_into()
                .expect("columns of K entries");
            let mut sum = 0.0;
            for k in 0..K {
                sum += x[k] * y[k];
            }
            *entry = sum;
        }
    }
    out
}

/// Up to this order the triangular solves and the Cholesky factorisation below are plain
/// loops; above it faer's blocked kernels (whose dispatch costs more than a 2 x 2 solve).
const SMALL_FACTOR_MAX_ORDER: usize = 16;

/// The lower-triangular Cholesky factor L of a symmetric positive definite R = L L^T (only
/// its lower triangle is read), or `None` when a pivot is not positive: R is not positive
/// definite to working precision.
pub(crate) fn cholesky(r: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let m = r.nrows();
    debug_assert_eq!(m, r.ncols());
    if m > SMALL_FACTOR_MAX_ORDER {
        let factor = r.as_faer().llt(faer::Side::Lower).ok()?;
        return Some(from_faer(factor.L()));
    }
    let mut l = DMatrix::zeros(m, m);
    for j in 0..m {
        let mut pivot = r[(j, j)];
        for k in 0..j {
            pivot -= l[(j, k)] * l[(j, k)];
        }
        // Not positive, or NaN.
        if pivot <= 0.0 || pivot.is_nan() {
            return None;
        }
        let pivot = pivot.sqrt();
        l[(j, j)] = pivot;
        for i in j + 1..m {
            let mut entry = r[(i, j)];
            for k in 0..j {
                entry -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = entry / pivot;
        }
    }
    Some(l)
}

/// Solves L X = B in place (X overwrites B) for lower-triangular L, by forward substitution.
pub(crate) fn solve_lower_in_place(l: &DMatrix<f64>, b: &mut DMatrix<f64>) {
    let m = l.nrows();
    debug_assert_eq!(m, b.nrows());
    if m > SMALL_FACTOR_MAX_ORDER {
        let view = l.as_faer();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            view,
            b.as_faer_mut(),
            faer::Par::Seq,
        );
        return;
    }
    with_order!(
        m,
        [1, 2, 3, 4],
        M => solve_lower_in::<M>(l, b),
        _ => {
            for j in 0..b.ncols() {
                let x = b.column_slice_mut(j);
                for k in 0..m {
                    x[k] /= l[(k, k)];
                    let solved = x[k];
                    for i in k + 1..m {
                        x[i] -= l[(i, k)] * solved;
                    }
                }
            }
        }
    )
}

/// [`solve_lower_in_place`] for L of order M known at compile time (the same operations).
// Row and column indices of a triangle: indices read most clearly.
#[allow(clippy::needless_range_loop)]
fn solve_lower_in<const M: usize>(l: &DMatrix<f64>, b: &mut DMatrix<f64>) {
    for x in b.as_mut_slice().chunks_exact_mut(M) {
        let x: &mut [f64; M] = x.try_into().expect("columns of M entries");
        for k in 0..M {
            x[k] /= l.as_slice()[k + k * M];
            let solved = x[k];
            for i in k + 1..M {
                x[i] -= l.as_slice()[i + k * M] * solved;
            }
        }
    }
}

/// Solves L^T X = B in place for lower-triangular L, by back substitution.
pub(crate) fn solve_lower_transposed_in_place(l: &DMatrix<f64>, b: &mut DMatrix<f64>) {
    let m = l.nrows();
    debug_assert_eq!(m, b.nrows());
    if m > SMALL_FACTOR_MAX_ORDER {
        let view = l.as_faer().transpose();
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            view,
            b.as_faer_mut(),
            faer::Par::Seq,
        );
        return;
    }
    with_order!(
        m,
        [1, 2, 3, 4],
        M => solve_lower_transposed_in::<M>(l, b),
        _ => {
            for j in 0..b.ncols() {
                let x = b.column_slice_mut(j);
                for k in (0..m).rev() {
                    let mut value = x[k];
                    for i in k + 1..m {
                        value -= l[(i, k)] * x[i];
                    }
                    x[k] = value / l[(k, k)];
                }
            }
        }
    )
}

/// [`solve_lower_transposed_in_place`] for L of order M known at compile time (the same
/// operations).
#[allow(clippy::needless_range_loop)]
fn solve_lower_transposed_in<const M: usize>(l: &DMatrix<f64>, b: &mut DMatrix<f64>) {
    for x in b.as_mut_slice().chunks_exact_mut(M) {
        let x: &mut [f64; M] = x.try_into().expect("columns of M entries");
        for k in (0..M).rev() {
            let mut value = x[k];
            for i in k + 1..M {
                value -= l.as_slice()[i + k * M] * x[i];
            }
            x[k] = value / l.as_slice()[k + k * M];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::matrix::Symmetrize;
    use crate::test_matrices::seeded;
    use faer::Mat;

    #[test]
    fn products_agree_with_faer() {
        for (rows, inner, cols) in [(4, 4, 4), (4, 2, 3), (1, 5, 1), (0, 3, 2), (20, 20, 20)] {
            let (a, b) = (seeded(rows, inner, 1), seeded(inner, cols, 2));
            let (da, db) = (from_faer(a.as_ref()), from_faer(b.as_ref()));
            let expected = &a * &b;
            let found = product(&da, &db).to_faer();
            assert!((&found - &expected).norm_max() <= 1e-14 * (inner as f64 + 1.0));
            let at = from_faer(a.transpose());
            let found = transposed_product(&at, &db).to_faer();
            assert!((&found - &expected).norm_max() <= 1e-14 * (inner as f64 + 1.0));
        }
    }

    #[test]
    fn small_products_round_like_the_faer_matrix_product_loop() {
        let (a, b) = (seeded(4, 4, 3), seeded(4, 2, 4));
        let expected = view_product(a.as_ref(), b.as_ref()).unwrap();
        let found = product(&from_faer(a.as_ref()), &from_faer(b.as_ref()));
        assert_eq!(found.to_faer(), expected);
        let found = transposed_product(&from_faer(a.transpose()), &from_faer(b.as_ref()));
        assert_eq!(found.to_faer(), expected);
    }

    #[test]
    fn cholesky_and_triangular_solves_agree_with_faer() {
        for m in [1, 2, 5, 16, 20] {
            let g = seeded(m, m, 6);
            let r = &g * g.transpose() + Mat::<f64>::identity(m, m);
            let l = cholesky(&from_faer(r.as_ref())).unwrap();
            let expected = r.as_ref().llt(faer::Side::Lower).unwrap();
            let difference = (&l.to_faer() - expected.L()).norm_max();
            assert!(difference <= 1e-13 * r.norm_max(), "m={m}: {difference:e}");
            let b = seeded(m, 3, 7);
            let mut x = from_faer(b.as_ref());
            solve_lower_in_place(&l, &mut x);
            assert!(
                (&l.to_faer() * x.to_faer() - &b).norm_max() <= 1e-12,
                "m={m}"
            );
            let mut x = from_faer(b.as_ref());
            solve_lower_transposed_in_place(&l, &mut x);
            assert!(
                (l.to_faer().transpose() * x.to_faer() - &b).norm_max() <= 1e-12,
                "m={m}"
            );
        }
        // Not positive definite: a zero, a negative and a NaN pivot.
        for r in [
            faer::mat![[1.0, 1.0], [1.0, 1.0]],
            faer::mat![[1.0, 2.0], [2.0, 1.0]],
            faer::mat![[f64::NAN, 0.0], [0.0, 1.0]],
        ] {
            assert!(cholesky(&from_faer(r.as_ref())).is_none());
        }
    }

    #[test]
    fn views_copies_and_symmetrisation() {
        let a = seeded(9, 9, 5);
        let mut d = from_faer(a.transpose());
        assert_eq!(d.to_faer(), a.transpose().to_owned());
        assert_eq!(d.as_faer(), a.transpose());
        d.as_faer_mut()[(3, 4)] = 7.0;
        assert_eq!(d[(3, 4)], 7.0);
        d.symmetrize();
        assert_eq!(d[(3, 4)], d[(4, 3)]);
        assert_eq!(d.transpose().to_faer(), d.to_faer().transpose().to_owned());
    }
}
