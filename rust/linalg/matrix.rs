//! The one matrix type of the small-order kernels: nalgebra's column-major `Matrix`, with
//! its order fixed at compile time (`Const<N>`, stored in an array on the stack) or known at
//! run time (`Dyn`, stored in one vector), and faer for the blocked kernels of large orders.
//!
//! Flight models are small (4 states for each of the longitudinal and lateral motions, 8 to
//! 12 coupled or augmented, twice that for a Hamiltonian), and many algorithms run thousands
//! of them in a sweep. At these orders a general library call (dispatch, allocation,
//! blocking decisions) costs more than the arithmetic; with the order a constant, index
//! arithmetic folds, loops over whole rows and columns unroll and the matrix lives on the
//! stack. The kernels are written once, generic over the [`Order`]; [`with_order!`] is the
//! one dispatch from a run-time order to a constant one. The arithmetic, and so every result,
//! is the same bit for bit whichever order type runs it.
//!
//! A matrix is lent to faer without a copy ([`FaerView`]) for the factorisations and the
//! blocked products of large orders. Plane rotations and Householder reflections act on rows
//! and columns in place ([`Transformations`]).

use faer::{Mat, MatMut, MatRef};
use nalgebra::storage::{IsContiguous, RawStorageMut};
use nalgebra::{ArrayStorage, Const, DMatrix, Dim, Dyn, Matrix, SMatrix, VecStorage};
use std::ops::{IndexMut, Range};

/// The order of a [`Square`] matrix: `Const<N>` (entries in an array, on the stack) or `Dyn`
/// (entries in a vector, on the heap).
pub trait Order: Dim {
    /// Storage for the order^2 entries, column by column.
    type Buffer: RawStorageMut<f64, Self, Self> + IsContiguous + Clone + std::fmt::Debug;

    /// Whether the order is a compile-time constant.
    const FIXED: bool;

    /// The zero matrix of this order.
    fn zeros(self) -> Square<Self>;
}

/// A square matrix of order `O`, stored by columns in one contiguous buffer. `Square<Dyn>` is
/// nalgebra's `DMatrix<f64>`, `Square<Const<N>>` its `SMatrix<f64, N, N>`.
pub type Square<O = Dyn> = Matrix<f64, O, O, <O as Order>::Buffer>;

impl<const N: usize> Order for Const<N> {
    type Buffer = ArrayStorage<f64, N, N>;
    const FIXED: bool = true;

    #[inline(always)]
    fn zeros(self) -> Square<Self> {
        SMatrix::zeros()
    }
}

impl Order for Dyn {
    type Buffer = VecStorage<f64, Dyn, Dyn>;
    const FIXED: bool = false;

    fn zeros(self) -> Square<Self> {
        DMatrix::zeros(self.0, self.0)
    }
}

/// The fixed orders of [`with_order!`]: those of 2- to 4-state models, their Hamiltonians
/// (twice the states) and 5- to 8-state augmented models.
///
/// Evaluates `$body` with `$order` bound to the [`Order`] of an n x n matrix: `Const<n>` for
/// n in 2..=8, `Dyn(n)` otherwise (the body is compiled for each). The general form binds a
/// constant `$N` for each listed order and falls back to `$fallback` for the others:
/// `with_order!(n, [1, 2, 3], N => kernel::<N>(a), _ => general(a))`.
macro_rules! with_order {
    ($n:expr, $order:ident => $body:expr) => {
        $crate::linalg::matrix::with_order!(
            $n,
            [2, 3, 4, 5, 6, 7, 8],
            N => {
                let $order = ::nalgebra::Const::<N>;
                $body
            },
            n => {
                let $order = ::nalgebra::Dyn(n);
                $body
            }
        )
    };
    ($n:expr, [$($fixed:literal),* $(,)?], $N:ident => $body:expr, $other:pat => $fallback:expr) => {
        match $n {
            $($fixed => {
                const $N: usize = $fixed;
                $body
            })*
            $other => $fallback,
        }
    };
}
pub(crate) use with_order;

/// The identity of order `order`.
pub(crate) fn identity_in<O: Order>(order: O) -> Square<O> {
    let mut out = order.zeros();
    for i in 0..order.value() {
        out[(i, i)] = 1.0;
    }
    out
}

/// A copy of the square faer matrix `a` (any strides), whose order is `order`.
pub(crate) fn from_faer_in<O: Order>(order: O, a: MatRef<'_, f64>) -> Square<O> {
    let n = order.value();
    debug_assert!(a.nrows() == n && a.ncols() == n);
    let mut out = order.zeros();
    for (j, column) in out.as_mut_slice().chunks_exact_mut(n.max(1)).enumerate() {
        for (i, x) in column.iter_mut().enumerate() {
            *x = a[(i, j)];
        }
    }
    out
}

/// A copy of a faer matrix of any shape and strides.
pub(crate) fn from_faer(a: MatRef<'_, f64>) -> DMatrix<f64> {
    let mut data = Vec::with_capacity(a.nrows() * a.ncols());
    for j in 0..a.ncols() {
        match a.col(j).try_as_col_major() {
            Some(column) => data.extend_from_slice(column.as_slice()),
            None => data.extend(a.col(j).iter().copied()),
        }
    }
    DMatrix::from_vec(a.nrows(), a.ncols(), data)
}

/// Views of a contiguous nalgebra matrix as faer matrices, and copies into faer matrices.
pub(crate) trait FaerView {
    /// A faer view of the matrix (no copy).
    fn as_faer(&self) -> MatRef<'_, f64>;
    /// A mutable faer view of the matrix (no copy).
    fn as_faer_mut(&mut self) -> MatMut<'_, f64>;
    /// A faer matrix of the entries times `scale`.
    fn to_faer_scaled(&self, scale: f64) -> Mat<f64>;
    /// A faer matrix holding the same values.
    fn to_faer(&self) -> Mat<f64> {
        self.to_faer_scaled(1.0)
    }
    /// Column j as a slice.
    fn column_slice(&self, j: usize) -> &[f64];
    /// Column j as a mutable slice.
    fn column_slice_mut(&mut self, j: usize) -> &mut [f64];
}

impl<R: Dim, C: Dim, S: RawStorageMut<f64, R, C> + IsContiguous> FaerView for Matrix<f64, R, C, S> {
    fn as_faer(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(self.as_slice(), self.nrows(), self.ncols())
    }

    fn as_faer_mut(&mut self) -> MatMut<'_, f64> {
        let (rows, cols) = self.shape();
        MatMut::from_column_major_slice_mut(self.as_mut_slice(), rows, cols)
    }

    fn to_faer_scaled(&self, scale: f64) -> Mat<f64> {
        let (rows, cols) = self.shape();
        let mut out = Mat::zeros(rows, cols);
        for j in 0..cols {
            for (x, &value) in out.col_as_slice_mut(j).iter_mut().zip(self.column_slice(j)) {
                *x = value * scale;
            }
        }
        out
    }

    #[inline]
    fn column_slice(&self, j: usize) -> &[f64] {
        let rows = self.nrows();
        &self.as_slice()[j * rows..(j + 1) * rows]
    }

    #[inline]
    fn column_slice_mut(&mut self, j: usize) -> &mut [f64] {
        let rows = self.nrows();
        &mut self.as_mut_slice()[j * rows..(j + 1) * rows]
    }
}

/// X <- (X + X^T) / 2 for a square X, whether nalgebra's or faer's: the symmetric part of a
/// computed solution whose two triangles differ by rounding.
pub(crate) trait Symmetrize {
    /// Replaces each pair x_ij, x_ji by their mean.
    fn symmetrize(&mut self);
}

/// The means of the pairs x_ij, x_ji of the leading n x n block.
fn symmetrize_entries<M: IndexMut<(usize, usize), Output = f64>>(x: &mut M, n: usize) {
    for j in 0..n {
        for i in j + 1..n {
            let mean = 0.5 * (x[(i, j)] + x[(j, i)]);
            x[(i, j)] = mean;
            x[(j, i)] = mean;
        }
    }
}

impl<R: Dim, C: Dim, S: RawStorageMut<f64, R, C>> Symmetrize for Matrix<f64, R, C, S> {
    fn symmetrize(&mut self) {
        debug_assert_eq!(self.nrows(), self.ncols());
        symmetrize_entries(self, self.nrows());
    }
}

impl Symmetrize for Mat<f64> {
    fn symmetrize(&mut self) {
        debug_assert_eq!(self.nrows(), self.ncols());
        symmetrize_entries(self, self.nrows());
    }
}

/// Plane rotations and Householder reflections of rows and columns of a [`Square`] in place:
/// the updates of the QR iteration, the Hessenberg reduction and the reordering.
pub(crate) trait Transformations {
    /// Rows r and r + 1, columns `columns`: x <- cs x + sn y, y <- cs y - sn x.
    fn rotate_rows(&mut self, r: usize, columns: Range<usize>, cs: f64, sn: f64);
    /// Columns c and c + 1, rows `rows`: x <- cs x + sn y, y <- cs y - sn x.
    fn rotate_columns(&mut self, c: usize, rows: Range<usize>, cs: f64, sn: f64);
    /// Applies I - τ w w^T (w = [1, v...], 2 or 3 long) from the left to rows k.. of the
    /// columns `columns`.
    fn reflect_rows(&mut self, k: usize, w: &[f64], tau: f64, columns: Range<usize>);
    /// Applies I - τ w w^T from the right to columns k.. of the rows `rows`.
    fn reflect_columns(&mut self, k: usize, w: &[f64], tau: f64, rows: Range<usize>);
    /// [`Transformations::reflect_rows`] for a reflector of length `N` whose w_0 = 1.
    fn reflect_rows_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        columns: Range<usize>,
    );
    /// [`Transformations::reflect_columns`] for a reflector of length `N` whose w_0 = 1.
    fn reflect_columns_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        rows: Range<usize>,
    );
}

impl<O: Order> Transformations for Square<O> {
    fn rotate_rows(&mut self, r: usize, columns: Range<usize>, cs: f64, sn: f64) {
        for j in columns {
            let (x, y) = (self[(r, j)], self[(r + 1, j)]);
            self[(r, j)] = cs * x + sn * y;
            self[(r + 1, j)] = cs * y - sn * x;
        }
    }

    fn rotate_columns(&mut self, c: usize, rows: Range<usize>, cs: f64, sn: f64) {
        let n = self.nrows();
        let (left, right) = self.as_mut_slice().split_at_mut((c + 1) * n);
        let (x_column, y_column) = (&mut left[c * n..], &mut right[..n]);
        for i in rows {
            let (x, y) = (x_column[i], y_column[i]);
            x_column[i] = cs * x + sn * y;
            y_column[i] = cs * y - sn * x;
        }
    }

    fn reflect_rows(&mut self, k: usize, w: &[f64], tau: f64, columns: Range<usize>) {
        let n = self.nrows();
        for j in columns {
            let column = &mut self.as_mut_slice()[j * n + k..j * n + k + w.len()];
            let sum: f64 = column.iter().zip(w).map(|(x, v)| x * v).sum();
            let scaled = tau * sum;
            for (x, v) in column.iter_mut().zip(w) {
                *x -= scaled * v;
            }
        }
    }

    /// y = τ H w is accumulated column by column (contiguous in storage, so the loops
    /// vectorise), in chunks of rows, then column k + r loses w_r y. (The operations of the
    /// row-by-row order, in the same order for each entry, so the same rounding.)
    fn reflect_columns(&mut self, k: usize, w: &[f64], tau: f64, rows: Range<usize>) {
        const CHUNK: usize = 32;
        let n = self.nrows();
        let columns = &mut self.as_mut_slice()[k * n..(k + w.len()) * n];
        if O::FIXED && n <= CHUNK && rows == (0..n) {
            // Every row at a compile-time order: one chunk of constant length, whose loops
            // unroll (the same operations on each entry as below).
            let mut y = [0.0; CHUNK];
            let y = &mut y[..n];
            for (column, v) in columns.chunks_exact(n).zip(w) {
                for (sum, x) in y.iter_mut().zip(column) {
                    *sum += v * x;
                }
            }
            for sum in y.iter_mut() {
                *sum *= tau;
            }
            for (column, v) in columns.chunks_exact_mut(n).zip(w) {
                for (x, scaled) in column.iter_mut().zip(y.iter()) {
                    *x -= scaled * v;
                }
            }
            return;
        }
        let mut start = rows.start;
        while start < rows.end {
            let chunk = start..(start + CHUNK).min(rows.end);
            let mut y = [0.0; CHUNK];
            let y = &mut y[..chunk.len()];
            for (r, v) in w.iter().enumerate() {
                let column = &columns[r * n + chunk.start..r * n + chunk.end];
                for (sum, x) in y.iter_mut().zip(column) {
                    *sum += v * x;
                }
            }
            for sum in y.iter_mut() {
                *sum *= tau;
            }
            for (r, v) in w.iter().enumerate() {
                let column = &mut columns[r * n + chunk.start..r * n + chunk.end];
                for (x, scaled) in column.iter_mut().zip(y.iter()) {
                    *x -= scaled * v;
                }
            }
            start = chunk.end;
        }
    }

    /// The reflectors of the bulge chase are 3 long (2 at the bottom of the window): with the
    /// length fixed at compile time the updates unroll and the column update vectorises. The
    /// products with w_0 = 1 are left out, as LAPACK's dlahqr leaves them (the same values,
    /// up to the sign of a zero).
    #[inline(always)]
    fn reflect_rows_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        columns: Range<usize>,
    ) {
        let n = self.nrows();
        for j in columns {
            let column: &mut [f64; N] = (&mut self.as_mut_slice()[j * n + k..j * n + k + N])
                .try_into()
                .expect("N entries");
            debug_assert_eq!(w[0], 1.0);
            let mut sum = column[0];
            for r in 1..N {
                sum += column[r] * w[r];
            }
            let scaled = tau * sum;
            column[0] -= scaled;
            for r in 1..N {
                column[r] -= scaled * w[r];
            }
        }
    }

    // Row i of N column slices at once: an index, not an iterator, is the natural form.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn reflect_columns_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        rows: Range<usize>,
    ) {
        let n = self.nrows();
        let columns = &mut self.as_mut_slice()[k * n..(k + N) * n];
        debug_assert_eq!(w[0], 1.0);
        for i in rows {
            let mut sum = columns[i];
            for r in 1..N {
                sum += w[r] * columns[r * n + i];
            }
            let scaled = tau * sum;
            columns[i] -= scaled;
            for r in 1..N {
                columns[r * n + i] -= scaled * w[r];
            }
        }
    }
}
