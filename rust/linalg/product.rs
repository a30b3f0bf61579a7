//! Matrix products that answer an interruption: C = C + α A B (or C = α A B) on real or
//! complex operands of any size, as faer's product, but for large operands split into column
//! panels of B and C, one faer product each, with [`interrupt::check`] between them.
//!
//! One faer product of order 3000 takes about a second on one core, during which Ctrl-C could
//! not be answered; a panel costs at most about [`PANEL_MULTIPLY_ADDS`] multiply-adds (tens of
//! milliseconds). Column j of C depends on A and column j of B only, and faer's kernel forms it
//! with the same operations (the same blocking of the inner dimension, the same order of
//! accumulation) whatever columns are formed with it, so the split product is bitwise the
//! product of one call: the tests below check it on square, tall, wide and thin operands,
//! widths that are not multiples of the panel's, sequentially and in parallel. Products below
//! [`SPLIT_MIN_MULTIPLY_ADDS`] are one faer call, unchanged.

use crate::error::Error;
use crate::platform::interrupt;
use faer::linalg::matmul::matmul;
use faer::prelude::ReborrowMut;
use faer::traits::ComplexField;
use faer::{Accum, Mat, MatMut, MatRef, Par, c64};

/// An entry of the matrices of the interruptible kernels (this module, [`crate::linalg::lu`]):
/// `f64` or `c64`, with the cost of its multiply-add in real ones (a complex multiply-add is
/// four real ones), by which the kernels size their blocks of work.
pub trait Entry: ComplexField + Copy + std::ops::Neg<Output = Self> + std::ops::MulAssign {
    /// Real multiply-adds in one multiply-add of this type.
    const REAL_MULTIPLY_ADDS: usize;
    const ZERO: Self;
    const ONE: Self;
}

impl Entry for f64 {
    const REAL_MULTIPLY_ADDS: usize = 1;
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
}

impl Entry for c64 {
    const REAL_MULTIPLY_ADDS: usize = 4;
    const ZERO: Self = c64::new(0.0, 0.0);
    const ONE: Self = c64::new(1.0, 0.0);
}

/// A panel of a split product costs about this many multiply-adds: 2^30, about 40 ms on one
/// core of a current x86-64 machine with FMA.
pub(crate) const PANEL_MULTIPLY_ADDS: usize = 1 << 30;

/// Products of fewer multiply-adds than this (two panels; the cube of order 1290) are one
/// faer call.
pub(crate) const SPLIT_MIN_MULTIPLY_ADDS: usize = 2 * PANEL_MULTIPLY_ADDS;

/// Panels are at least this many columns wide (a multiple of the widths of faer's
/// micro-kernels), however large the other dimensions.
const MIN_PANEL_COLUMNS: usize = 48;

/// The width of the column panels of a product of m x k and k x n operands of entries `T`:
/// `n` (one call) for a product of fewer than [`SPLIT_MIN_MULTIPLY_ADDS`] real multiply-adds,
/// else the multiple of 8 columns nearest below [`PANEL_MULTIPLY_ADDS`] / (m k) (in real
/// multiply-adds), at least [`MIN_PANEL_COLUMNS`].
pub(crate) fn panel_columns<T: Entry>(m: usize, k: usize, n: usize) -> usize {
    let per_column = m
        .saturating_mul(k)
        .saturating_mul(T::REAL_MULTIPLY_ADDS)
        .max(1);
    if per_column.saturating_mul(n) < SPLIT_MIN_MULTIPLY_ADDS {
        return n.max(1);
    }
    (PANEL_MULTIPLY_ADDS / per_column / 8 * 8).max(MIN_PANEL_COLUMNS)
}

/// C = C + α A B (`Accum::Add`) or C = α A B (`Accum::Replace`), as faer's `matmul` with the
/// same parallelism and bitwise the same result, stopping with [`Error::Interrupted`] between
/// column panels (see the module documentation) when the computation is interrupted. Panics,
/// as faer's does, if the shapes do not match.
pub fn multiply<T: Entry>(
    mut c: MatMut<'_, T>,
    accum: Accum,
    a: MatRef<'_, T>,
    b: MatRef<'_, T>,
    alpha: T,
    par: Par,
) -> Result<(), Error> {
    let n = b.ncols();
    let width = panel_columns::<T>(a.nrows(), a.ncols(), n);
    if width >= n {
        matmul(c, accum, a, b, alpha, par);
        return Ok(());
    }
    let mut first = 0;
    while first < n {
        interrupt::check()?;
        // The last panel takes the remainder if it would be narrower than half a panel.
        let columns = if n - first < width + width / 2 {
            n - first
        } else {
            width
        };
        matmul(
            c.rb_mut().subcols_mut(first, columns),
            accum,
            a,
            b.subcols(first, columns),
            alpha,
            par,
        );
        first += columns;
    }
    Ok(())
}

/// A B, as faer's `*` operator (with faer's global parallelism) and bitwise the same, through
/// [`multiply`].
pub fn product<T: Entry>(a: MatRef<'_, T>, b: MatRef<'_, T>) -> Result<Mat<T>, Error> {
    let mut c = Mat::<T>::zeros(a.nrows(), b.ncols());
    multiply(
        c.as_mut(),
        Accum::Replace,
        a,
        b,
        T::ONE,
        faer::get_global_parallelism(),
    )?;
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platform::interrupt::{Token, within};
    use crate::test_matrices::seeded;

    /// The product of one faer call, for comparison.
    fn one_call(a: MatRef<'_, f64>, b: MatRef<'_, f64>, c: &Mat<f64>, par: Par) -> Mat<f64> {
        let mut out = c.clone();
        matmul(out.as_mut(), Accum::Add, a, b, -0.75, par);
        out
    }

    #[test]
    fn split_products_are_bitwise_one_call() {
        // (m, k, n): square, tall, wide, a thin inner dimension, and n not a multiple of the
        // panel width; each large enough to be split.
        for (seed, &(m, k, n)) in [
            (1300, 1300, 1300),
            (2000, 700, 1700),
            (700, 2100, 1500),
            (3000, 64, 11_200),
            (1500, 1500, 1001),
        ]
        .iter()
        .enumerate()
        {
            assert!(
                panel_columns::<f64>(m, k, n) < n,
                "({m}, {k}, {n}) is not split"
            );
            let seed = 10 * seed as u64;
            let a = seeded(m, k, seed);
            let b = seeded(k, n, seed + 1);
            let c = seeded(m, n, seed + 2);
            for par in [Par::Seq, Par::rayon(2)] {
                let mut split = c.clone();
                multiply(
                    split.as_mut(),
                    Accum::Add,
                    a.as_ref(),
                    b.as_ref(),
                    -0.75,
                    par,
                )
                .unwrap();
                assert!(
                    split == one_call(a.as_ref(), b.as_ref(), &c, par),
                    "({m}, {k}, {n}), {par:?}"
                );
            }
            // Transposed operands (row-major views), as the Riccati residuals pass them.
            let mut split = Mat::<f64>::zeros(k, k);
            multiply(
                split.as_mut(),
                Accum::Replace,
                a.transpose(),
                a.as_ref(),
                1.0,
                Par::Seq,
            )
            .unwrap();
            assert!(split == a.transpose() * &a, "({m}, {k}): A^T A");
        }
        let (a, b) = (seeded(1400, 1400, 7), seeded(1400, 1400, 8));
        assert!(product(a.as_ref(), b.as_ref()).unwrap() == &a * &b);
        // Complex operands: a multiply-add counts four real ones, so this one is split.
        let complex = |m: &Mat<f64>, shift: usize| {
            Mat::from_fn(m.nrows(), m.ncols(), |i, j| {
                c64::new(m[(i, j)], m[((i + shift) % m.nrows(), j)])
            })
        };
        let (a, b) = (
            complex(&seeded(800, 800, 9), 1),
            complex(&seeded(800, 900, 10), 2),
        );
        assert!(panel_columns::<c64>(800, 800, 900) < 900);
        for par in [Par::Seq, Par::rayon(2)] {
            let mut split = Mat::<c64>::zeros(800, 900);
            let alpha = c64::new(0.5, -1.5);
            multiply(
                split.as_mut(),
                Accum::Replace,
                a.as_ref(),
                b.as_ref(),
                alpha,
                par,
            )
            .unwrap();
            let mut one = Mat::<c64>::zeros(800, 900);
            matmul(
                one.as_mut(),
                Accum::Replace,
                a.as_ref(),
                b.as_ref(),
                alpha,
                par,
            );
            assert!(split == one, "complex, {par:?}");
        }
    }

    #[test]
    fn small_products_are_one_call_and_panels_are_bounded() {
        assert_eq!(panel_columns::<f64>(1024, 1024, 1024), 1024);
        assert_eq!(panel_columns::<f64>(4, 4, 4), 4);
        assert_eq!(panel_columns::<f64>(0, 0, 0), 1);
        for (m, k, n) in [
            (1300, 1300, 1300),
            (3000, 3000, 3000),
            (100_000, 100_000, 3),
        ] {
            let width = panel_columns::<f64>(m, k, n);
            assert!(width >= MIN_PANEL_COLUMNS && width.is_multiple_of(8));
            assert!(m * k * width <= PANEL_MULTIPLY_ADDS || width == MIN_PANEL_COLUMNS);
        }
    }

    #[test]
    fn an_interrupted_product_stops() {
        let a = seeded(1300, 1300, 3);
        let mut c = Mat::<f64>::zeros(1300, 1300);
        let token = Token::default();
        token.cancel();
        let outcome = within(&token, || {
            multiply(
                c.as_mut(),
                Accum::Replace,
                a.as_ref(),
                a.as_ref(),
                1.0,
                Par::Seq,
            )
        });
        assert_eq!(outcome, Err(Error::Interrupted));
        // Small products are one call, and finish.
        let small = seeded(50, 50, 4);
        let outcome = within(&token, || product(small.as_ref(), small.as_ref()));
        assert!(outcome.unwrap() == &small * &small);
    }
}
