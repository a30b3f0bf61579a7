//! Square matrices whose order is fixed at compile time or known at run time, stored by
//! columns in one contiguous buffer: the working matrices of the QR iteration, the Hessenberg
//! reduction and the Riccati solver's Hamiltonian.
//!
//! With the order a constant ([`Fixed`], the orders of `fixed_orders!`: 2- to 4-state models,
//! their Hamiltonians and augmented models up to 8), index arithmetic folds, loops over whole
//! rows and columns unroll and the matrix lives on the stack; the arithmetic, and so every
//! result, is the same bit for bit as with the run-time order ([`Dynamic`]). [`with_order`]
//! picks the order type for n. Plane rotations and Householder reflections act on rows and
//! columns in place.

use faer::{Mat, MatRef};
use std::ops::{Index, IndexMut, Range};

/// The order of a [`Square`] matrix: fixed at compile time ([`Fixed`]) for the small orders
/// of flight models, or known at run time ([`Dynamic`]).
///
/// With the order a constant, the index arithmetic of the QR iteration folds, its loops over
/// whole rows and columns unroll, and the matrix lives on the stack; the arithmetic, and so
/// every result, is the same bit for bit as with the run-time order. [`with_order`] picks
/// the order type for n.
pub trait Order: Copy {
    /// Storage for the order^2 entries.
    type Data: AsRef<[f64]> + AsMut<[f64]> + Clone;
    /// Whether the order is a compile-time constant.
    const FIXED: bool;
    /// The order.
    fn get(self) -> usize;
    /// Zeroed storage.
    fn zeros(self) -> Self::Data;
}

/// An order known at run time; the entries on the heap.
#[derive(Debug, Clone, Copy)]
pub struct Dynamic(pub usize);

impl Order for Dynamic {
    type Data = Vec<f64>;
    const FIXED: bool = false;
    #[inline(always)]
    fn get(self) -> usize {
        self.0
    }
    fn zeros(self) -> Vec<f64> {
        vec![0.0; self.0 * self.0]
    }
}

/// An order fixed at compile time; the entries in an array.
#[derive(Debug, Clone, Copy)]
pub struct Fixed<const N: usize>;

/// The fixed orders: those of 2- to 4-state models, their Hamiltonians (twice the states)
/// and 5- to 8-state augmented models.
macro_rules! fixed_orders {
    ($($n:literal),*) => {
        $(
            impl Order for Fixed<$n> {
                type Data = [f64; $n * $n];
                const FIXED: bool = true;
                #[inline(always)]
                fn get(self) -> usize {
                    $n
                }
                #[inline(always)]
                fn zeros(self) -> Self::Data {
                    [0.0; $n * $n]
                }
            }
        )*
    };
}

fixed_orders!(2, 3, 4, 5, 6, 7, 8);

/// Evaluates `$body` with `$order` bound to the [`Order`] of an n x n matrix: [`Fixed`] for
/// the orders of `fixed_orders!`, [`Dynamic`] otherwise (the body is compiled for each).
macro_rules! with_order {
    ($n:expr, $order:ident => $body:expr) => {
        with_order!(@orders $n, $order, $body; 2 3 4 5 6 7 8)
    };
    (@orders $n:expr, $order:ident, $body:expr; $($fixed:literal)*) => {
        match $n {
            $($fixed => {
                let $order = $crate::linalg::square::Fixed::<$fixed>;
                $body
            })*
            n => {
                let $order = $crate::linalg::square::Dynamic(n);
                $body
            }
        }
    };
}
pub(crate) use with_order;

/// A square matrix stored by columns in one contiguous buffer: the QR iteration touches single
/// entries in tight loops, where a plain slice index is cheaper than a strided view.
#[derive(Clone)]
pub struct Square<O: Order = Dynamic> {
    pub(crate) order: O,
    pub(crate) data: O::Data,
}

impl Square {
    pub(crate) fn from_mat(a: MatRef<'_, f64>) -> Self {
        Self::from_mat_in(Dynamic(a.nrows()), a)
    }

    pub(crate) fn identity(n: usize) -> Self {
        Self::identity_in(Dynamic(n))
    }
}

impl<O: Order> Square<O> {
    /// The order.
    #[inline(always)]
    pub(crate) fn n(&self) -> usize {
        self.order.get()
    }

    /// A copy of the square matrix `a`, whose order is `order`.
    pub(crate) fn from_mat_in(order: O, a: MatRef<'_, f64>) -> Self {
        let n = order.get();
        debug_assert!(a.nrows() == n && a.ncols() == n);
        let mut data = order.zeros();
        for (j, column) in data.as_mut().chunks_exact_mut(n.max(1)).enumerate() {
            for (i, x) in column.iter_mut().enumerate() {
                *x = a[(i, j)];
            }
        }
        Self { order, data }
    }

    pub(crate) fn zeros_in(order: O) -> Self {
        Self {
            order,
            data: order.zeros(),
        }
    }

    pub(crate) fn identity_in(order: O) -> Self {
        let n = order.get();
        let mut data = order.zeros();
        for i in 0..n {
            data.as_mut()[i * (n + 1)] = 1.0;
        }
        Self { order, data }
    }

    pub(crate) fn to_mat(&self) -> Mat<f64> {
        self.to_mat_scaled(1.0)
    }

    /// A faer matrix of the entries times `scale`.
    pub(crate) fn to_mat_scaled(&self, scale: f64) -> Mat<f64> {
        let n = self.n();
        let mut out = Mat::zeros(n, n);
        for j in 0..n {
            let column = &self.data.as_ref()[j * n..(j + 1) * n];
            for (x, &value) in out.col_as_slice_mut(j).iter_mut().zip(column) {
                *x = value * scale;
            }
        }
        out
    }

    /// A faer view of the matrix.
    pub(crate) fn as_ref(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(self.data.as_ref(), self.n(), self.n())
    }

    /// Rows r and r + 1, columns `columns`: x <- cs x + sn y, y <- cs y - sn x.
    pub(crate) fn rotate_rows(&mut self, r: usize, columns: Range<usize>, cs: f64, sn: f64) {
        for j in columns {
            let (x, y) = (self[(r, j)], self[(r + 1, j)]);
            self[(r, j)] = cs * x + sn * y;
            self[(r + 1, j)] = cs * y - sn * x;
        }
    }

    /// Columns c and c + 1, rows `rows`: x <- cs x + sn y, y <- cs y - sn x.
    pub(crate) fn rotate_columns(&mut self, c: usize, rows: Range<usize>, cs: f64, sn: f64) {
        let n = self.n();
        let (left, right) = self.data.as_mut().split_at_mut((c + 1) * n);
        let (x_column, y_column) = (&mut left[c * n..], &mut right[..n]);
        for i in rows {
            let (x, y) = (x_column[i], y_column[i]);
            x_column[i] = cs * x + sn * y;
            y_column[i] = cs * y - sn * x;
        }
    }

    /// Applies I - τ w w^T (w = [1, v...], 2 or 3 long) from the left to rows k.. of the
    /// columns `columns`.
    pub(crate) fn reflect_rows(&mut self, k: usize, w: &[f64], tau: f64, columns: Range<usize>) {
        let n = self.n();
        for j in columns {
            let column = &mut self.data.as_mut()[j * n + k..j * n + k + w.len()];
            let sum: f64 = column.iter().zip(w).map(|(x, v)| x * v).sum();
            let scaled = tau * sum;
            for (x, v) in column.iter_mut().zip(w) {
                *x -= scaled * v;
            }
        }
    }

    /// Applies I - τ w w^T from the right to columns k.. of the rows `rows`: y = τ H w is
    /// accumulated column by column (contiguous in storage, so the loops vectorise), in
    /// chunks of rows, then column k + r loses w_r y. (The operations of the row-by-row
    /// order, in the same order for each entry, so the same rounding.)
    pub(crate) fn reflect_columns(&mut self, k: usize, w: &[f64], tau: f64, rows: Range<usize>) {
        const CHUNK: usize = 32;
        let n = self.n();
        let columns = &mut self.data.as_mut()[k * n..(k + w.len()) * n];
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
}

/// The reflectors of the bulge chase are 3 long (2 at the bottom of the window): with the
/// length fixed at compile time the updates unroll and the column update vectorises, which
/// roughly halves the cost of a QR sweep at the small orders of flight-control models.
impl<O: Order> Square<O> {
    /// [`Square::reflect_rows`] for a reflector of length `N` whose w_0 = 1 (as every
    /// reflector of the bulge chase): the products with w_0 are left out, as LAPACK's dlahqr
    /// leaves them (the same values, up to the sign of a zero).
    #[inline(always)]
    pub(crate) fn reflect_rows_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        columns: Range<usize>,
    ) {
        let n = self.n();
        for j in columns {
            let column: &mut [f64; N] = (&mut self.data.as_mut()[j * n + k..j * n + k + N])
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

    /// [`Square::reflect_columns`] for a reflector of length `N` whose w_0 = 1 (see
    /// [`Square::reflect_rows_fixed`]).
    // Row i of N column slices at once: an index, not an iterator, is the natural form.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    pub(crate) fn reflect_columns_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        rows: Range<usize>,
    ) {
        let n = self.n();
        let columns = &mut self.data.as_mut()[k * n..(k + N) * n];
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

impl<O: Order> Index<(usize, usize)> for Square<O> {
    type Output = f64;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        &self.data.as_ref()[i + j * self.order.get()]
    }
}

impl<O: Order> IndexMut<(usize, usize)> for Square<O> {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        &mut self.data.as_mut()[i + j * self.order.get()]
    }
}
