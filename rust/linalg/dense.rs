//! Small dense matrices for the temporaries of the control algorithms.
//!
//! A 4-state Riccati solve forms some forty temporaries of order n and m (products, residuals,
//! gains, factors). As faer matrices each costs an aligned allocation and faer's construction
//! machinery, and every entry access a bounds-checked strided index, which together cost more
//! than the arithmetic. [`Dense`] is a plain column-major `Vec<f64>` with its shape: one
//! unaligned small allocation (the fast path of the extension's allocator), contiguous columns
//! as slices, and [`Dense::as_ref`] and [`Dense::as_mut`] to lend it to faer as a view (no copy)
//! for the factorisations and the blocked products of large orders. (Entries are not stored
//! inline for small orders: moving such values between functions costs more than the
//! allocations it saves, on the Riccati benches.)

use faer::{Mat, MatMut, MatRef};
use std::ops::{Index, IndexMut};

/// A column-major matrix.
#[derive(Clone, Debug)]
pub(crate) struct Dense {
    rows: usize,
    cols: usize,
    data: Vec<f64>,
}

impl Dense {
    /// The rows x cols zero matrix.
    pub(crate) fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// The matrix with entries f(i, j), evaluated column by column.
    pub(crate) fn from_fn(
        rows: usize,
        cols: usize,
        mut f: impl FnMut(usize, usize) -> f64,
    ) -> Self {
        let mut out = Self::zeros(rows, cols);
        if rows > 0 {
            for (j, column) in out.data.chunks_exact_mut(rows).enumerate() {
                for (i, x) in column.iter_mut().enumerate() {
                    *x = f(i, j);
                }
            }
        }
        out
    }

    /// A copy of a faer matrix (any strides).
    pub(crate) fn from_ref(a: MatRef<'_, f64>) -> Self {
        let mut data = Vec::with_capacity(a.nrows() * a.ncols());
        for j in 0..a.ncols() {
            match a.col(j).try_as_col_major() {
                Some(column) => data.extend_from_slice(column.as_slice()),
                None => data.extend(a.col(j).iter().copied()),
            }
        }
        Self {
            rows: a.nrows(),
            cols: a.ncols(),
            data,
        }
    }

    pub(crate) fn nrows(&self) -> usize {
        self.rows
    }

    pub(crate) fn ncols(&self) -> usize {
        self.cols
    }

    /// Column j.
    #[inline]
    pub(crate) fn col(&self, j: usize) -> &[f64] {
        &self.data[j * self.rows..(j + 1) * self.rows]
    }

    /// Column j, mutably.
    #[inline]
    pub(crate) fn col_mut(&mut self, j: usize) -> &mut [f64] {
        &mut self.data[j * self.rows..(j + 1) * self.rows]
    }

    /// All entries, column by column.
    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// All entries, column by column, mutably.
    pub(crate) fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.data
    }

    /// A faer view of the matrix.
    pub(crate) fn as_ref(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.data, self.rows, self.cols)
    }

    /// A mutable faer view of the matrix.
    pub(crate) fn as_mut(&mut self) -> MatMut<'_, f64> {
        MatMut::from_column_major_slice_mut(&mut self.data, self.rows, self.cols)
    }

    /// A faer matrix holding the same values.
    pub(crate) fn to_mat(&self) -> Mat<f64> {
        let mut out = Mat::zeros(self.rows, self.cols);
        for j in 0..self.cols {
            out.col_as_slice_mut(j).copy_from_slice(self.col(j));
        }
        out
    }

    /// The transpose.
    pub(crate) fn transpose(&self) -> Self {
        let mut out = Self::zeros(self.cols, self.rows);
        if self.rows > 0 {
            for (j, column) in self.data.chunks_exact(self.rows).enumerate() {
                for (i, &x) in column.iter().enumerate() {
                    out.data[j + i * self.cols] = x;
                }
            }
        }
        out
    }

    /// X <- (X + X^T) / 2, for square X.
    pub(crate) fn symmetrize(&mut self) {
        debug_assert_eq!(self.rows, self.cols);
        let n = self.rows;
        for j in 0..n {
            for i in j + 1..n {
                let mean = 0.5 * (self[(i, j)] + self[(j, i)]);
                self[(i, j)] = mean;
                self[(j, i)] = mean;
            }
        }
    }

    /// sqrt(sum x_ij^2), by a plain sum of squares while it stays in the normal range, faer's
    /// scaled sum otherwise (as [`crate::linalg::norm::frobenius_norm`]).
    pub(crate) fn frobenius_norm(&self) -> f64 {
        crate::linalg::norm::frobenius_norm(self.as_ref())
    }
}

impl Index<(usize, usize)> for Dense {
    type Output = f64;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        debug_assert!(i < self.rows && j < self.cols);
        &self.data[i + j * self.rows]
    }
}

impl IndexMut<(usize, usize)> for Dense {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        debug_assert!(i < self.rows && j < self.cols);
        &mut self.data[i + j * self.rows]
    }
}

/// Products of at most this many multiply-adds are plain loops, larger ones faer's blocked
/// kernel (as [`crate::linalg::small_matrix::product`]).
const LOOP_PRODUCT_MAX_WORK: usize = 16 * 16 * 16;

/// lhs * rhs. Each entry of a small product is the sum over k, in order, of
/// lhs[i, k] rhs[k, j], as [`crate::linalg::small_matrix::product`] forms it.
pub(crate) fn product(lhs: &Dense, rhs: &Dense) -> Dense {
    let (rows, inner, cols) = (lhs.rows, lhs.cols, rhs.cols);
    debug_assert_eq!(inner, rhs.rows);
    let mut out = Dense::zeros(rows, cols);
    if rows * inner * cols > LOOP_PRODUCT_MAX_WORK {
        faer::linalg::matmul::matmul(
            out.as_mut(),
            faer::Accum::Replace,
            lhs.as_ref(),
            rhs.as_ref(),
            1.0,
            faer::Par::Seq,
        );
        return out;
    }
    match rows {
        1 => product_in::<1>(lhs, rhs, &mut out),
        2 => product_in::<2>(lhs, rhs, &mut out),
        3 => product_in::<3>(lhs, rhs, &mut out),
        4 => product_in::<4>(lhs, rhs, &mut out),
        5 => product_in::<5>(lhs, rhs, &mut out),
        6 => product_in::<6>(lhs, rhs, &mut out),
        7 => product_in::<7>(lhs, rhs, &mut out),
        8 => product_in::<8>(lhs, rhs, &mut out),
        _ => {
            for j in 0..cols {
                let (rhs_column, column) = (rhs.col(j), &mut out.data[j * rows..(j + 1) * rows]);
                for (k, &coefficient) in rhs_column.iter().enumerate() {
                    for (entry, x) in column.iter_mut().zip(lhs.col(k)) {
                        *entry += x * coefficient;
                    }
                }
            }
        }
    }
    out
}

/// The loops of [`product`] for columns of length R known at compile time: each column update
/// is a few vector operations instead of a loop (the same operations in the same order).
fn product_in<const R: usize>(lhs: &Dense, rhs: &Dense, out: &mut Dense) {
    for (j, column) in out.data.chunks_exact_mut(R).enumerate() {
        let column: &mut [f64; R] = column.try_into().expect("columns of R entries");
        for (k, &coefficient) in rhs.col(j).iter().enumerate() {
            let lhs_column: &[f64; R] = lhs.col(k).try_into().expect("columns of R entries");
            for r in 0..R {
                column[r] += lhs_column[r] * coefficient;
            }
        }
    }
}

/// lhs^T * rhs: each entry a dot product of two columns, summed in order (the same values as
/// [`product`] of the transpose).
pub(crate) fn transposed_product(lhs: &Dense, rhs: &Dense) -> Dense {
    let (rows, inner, cols) = (lhs.cols, lhs.rows, rhs.cols);
    debug_assert_eq!(inner, rhs.rows);
    if rows * inner * cols > LOOP_PRODUCT_MAX_WORK {
        let mut out = Dense::zeros(rows, cols);
        faer::linalg::matmul::matmul(
            out.as_mut(),
            faer::Accum::Replace,
            lhs.as_ref().transpose(),
            rhs.as_ref(),
            1.0,
            faer::Par::Seq,
        );
        return out;
    }
    match inner {
        1 => transposed_product_in::<1>(lhs, rhs),
        2 => transposed_product_in::<2>(lhs, rhs),
        3 => transposed_product_in::<3>(lhs, rhs),
        4 => transposed_product_in::<4>(lhs, rhs),
        5 => transposed_product_in::<5>(lhs, rhs),
        6 => transposed_product_in::<6>(lhs, rhs),
        7 => transposed_product_in::<7>(lhs, rhs),
        8 => transposed_product_in::<8>(lhs, rhs),
        _ => Dense::from_fn(rows, cols, |i, j| {
            let mut sum = 0.0;
            for (x, y) in lhs.col(i).iter().zip(rhs.col(j)) {
                sum += x * y;
            }
            sum
        }),
    }
}

/// [`transposed_product`] for an inner dimension K known at compile time: each dot product
/// unrolls (summed in the same order).
fn transposed_product_in<const K: usize>(lhs: &Dense, rhs: &Dense) -> Dense {
    let mut out = Dense::zeros(lhs.cols, rhs.cols);
    let rows = lhs.cols;
    for (j, column) in out.data.chunks_exact_mut(rows.max(1)).enumerate() {
        let y: &[f64; K] = rhs.col(j).try_into().expect("columns of K entries");
        for (i, entry) in column.iter_mut().enumerate() {
            let x: &[f64; K] = lhs.col(i).try_into().expect("columns of K entries");
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
pub(crate) fn cholesky(r: &Dense) -> Option<Dense> {
    let m = r.rows;
    debug_assert_eq!(m, r.cols);
    if m > SMALL_FACTOR_MAX_ORDER {
        let factor = r.as_ref().llt(faer::Side::Lower).ok()?;
        return Some(Dense::from_ref(factor.L()));
    }
    let mut l = Dense::zeros(m, m);
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
pub(crate) fn solve_lower_in_place(l: &Dense, b: &mut Dense) {
    let m = l.rows;
    debug_assert_eq!(m, b.rows);
    if m > SMALL_FACTOR_MAX_ORDER {
        let view = l.as_ref();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            view,
            b.as_mut(),
            faer::Par::Seq,
        );
        return;
    }
    match m {
        1 => solve_lower_in::<1>(l, b),
        2 => solve_lower_in::<2>(l, b),
        3 => solve_lower_in::<3>(l, b),
        4 => solve_lower_in::<4>(l, b),
        _ => {
            for j in 0..b.cols {
                let x = b.col_mut(j);
                for k in 0..m {
                    x[k] /= l[(k, k)];
                    let solved = x[k];
                    for i in k + 1..m {
                        x[i] -= l[(i, k)] * solved;
                    }
                }
            }
        }
    }
}

/// [`solve_lower_in_place`] for L of order M known at compile time (the same operations).
// Row and column indices of a triangle: indices read most clearly.
#[allow(clippy::needless_range_loop)]
fn solve_lower_in<const M: usize>(l: &Dense, b: &mut Dense) {
    for x in b.data.chunks_exact_mut(M) {
        let x: &mut [f64; M] = x.try_into().expect("columns of M entries");
        for k in 0..M {
            x[k] /= l.data[k + k * M];
            let solved = x[k];
            for i in k + 1..M {
                x[i] -= l.data[i + k * M] * solved;
            }
        }
    }
}

/// Solves L^T X = B in place for lower-triangular L, by back substitution.
pub(crate) fn solve_lower_transposed_in_place(l: &Dense, b: &mut Dense) {
    let m = l.rows;
    debug_assert_eq!(m, b.rows);
    if m > SMALL_FACTOR_MAX_ORDER {
        let view = l.as_ref().transpose();
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            view,
            b.as_mut(),
            faer::Par::Seq,
        );
        return;
    }
    match m {
        1 => solve_lower_transposed_in::<1>(l, b),
        2 => solve_lower_transposed_in::<2>(l, b),
        3 => solve_lower_transposed_in::<3>(l, b),
        4 => solve_lower_transposed_in::<4>(l, b),
        _ => {
            for j in 0..b.cols {
                let x = b.col_mut(j);
                for k in (0..m).rev() {
                    let mut value = x[k];
                    for i in k + 1..m {
                        value -= l[(i, k)] * x[i];
                    }
                    x[k] = value / l[(k, k)];
                }
            }
        }
    }
}

/// [`solve_lower_transposed_in_place`] for L of order M known at compile time (the same
/// operations).
#[allow(clippy::needless_range_loop)]
fn solve_lower_transposed_in<const M: usize>(l: &Dense, b: &mut Dense) {
    for x in b.data.chunks_exact_mut(M) {
        let x: &mut [f64; M] = x.try_into().expect("columns of M entries");
        for k in (0..M).rev() {
            let mut value = x[k];
            for i in k + 1..M {
                value -= l.data[i + k * M] * x[i];
            }
            x[k] = value / l.data[k + k * M];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_matrices::seeded;

    #[test]
    fn products_agree_with_faer() {
        for (rows, inner, cols) in [(4, 4, 4), (4, 2, 3), (1, 5, 1), (0, 3, 2), (20, 20, 20)] {
            let (a, b) = (seeded(rows, inner, 1), seeded(inner, cols, 2));
            let (da, db) = (Dense::from_ref(a.as_ref()), Dense::from_ref(b.as_ref()));
            let expected = &a * &b;
            let found = product(&da, &db).to_mat();
            assert!((&found - &expected).norm_max() <= 1e-14 * (inner as f64 + 1.0));
            let at = Dense::from_ref(a.transpose());
            let found = transposed_product(&at, &db).to_mat();
            assert!((&found - &expected).norm_max() <= 1e-14 * (inner as f64 + 1.0));
        }
    }

    #[test]
    fn small_products_round_like_the_faer_matrix_product_loop() {
        let (a, b) = (seeded(4, 4, 3), seeded(4, 2, 4));
        let expected = crate::linalg::small_matrix::product(a.as_ref(), b.as_ref());
        let found = product(&Dense::from_ref(a.as_ref()), &Dense::from_ref(b.as_ref()));
        assert_eq!(found.to_mat(), expected);
        let found = transposed_product(
            &Dense::from_ref(a.transpose()),
            &Dense::from_ref(b.as_ref()),
        );
        assert_eq!(found.to_mat(), expected);
    }

    #[test]
    fn cholesky_and_triangular_solves_agree_with_faer() {
        for m in [1, 2, 5, 16, 20] {
            let g = seeded(m, m, 6);
            let r = &g * g.transpose() + Mat::<f64>::identity(m, m);
            let l = cholesky(&Dense::from_ref(r.as_ref())).unwrap();
            let expected = r.as_ref().llt(faer::Side::Lower).unwrap();
            let difference = (&l.to_mat() - expected.L()).norm_max();
            assert!(difference <= 1e-13 * r.norm_max(), "m={m}: {difference:e}");
            let b = seeded(m, 3, 7);
            let mut x = Dense::from_ref(b.as_ref());
            solve_lower_in_place(&l, &mut x);
            assert!((&l.to_mat() * x.to_mat() - &b).norm_max() <= 1e-12, "m={m}");
            let mut x = Dense::from_ref(b.as_ref());
            solve_lower_transposed_in_place(&l, &mut x);
            assert!(
                (l.to_mat().transpose() * x.to_mat() - &b).norm_max() <= 1e-12,
                "m={m}"
            );
        }
        // Not positive definite: a zero, a negative and a NaN pivot.
        for r in [
            faer::mat![[1.0, 1.0], [1.0, 1.0]],
            faer::mat![[1.0, 2.0], [2.0, 1.0]],
            faer::mat![[f64::NAN, 0.0], [0.0, 1.0]],
        ] {
            assert!(cholesky(&Dense::from_ref(r.as_ref())).is_none());
        }
    }

    #[test]
    fn views_copies_and_symmetrisation() {
        let a = seeded(9, 9, 5);
        let mut d = Dense::from_ref(a.transpose());
        assert_eq!(d.to_mat(), a.transpose().to_owned());
        assert_eq!(d.as_ref(), a.transpose());
        d.as_mut()[(3, 4)] = 7.0;
        assert_eq!(d[(3, 4)], 7.0);
        d.symmetrize();
        assert_eq!(d[(3, 4)], d[(4, 3)]);
        assert_eq!(d.transpose().to_mat(), d.to_mat().transpose().to_owned());
    }
}
