//! Double-double arithmetic: a number as the unevaluated sum hi + lo of two doubles with
//! |lo| <= ulp(hi)/2, about 106 significant bits, and small matrices of such numbers.
//!
//! Built from the error-free transformations of T. J. Dekker, "A floating-point technique for
//! extending the available precision", Numer. Math. 18, 1971, pp. 224-242, and D. E. Knuth,
//! The Art of Computer Programming vol. 2, §4.2.2:
//!
//! * two_sum(a, b) = (s, e) with s = fl(a + b) and a + b = s + e exactly;
//! * two_product(a, b) = (p, e) with p = fl(a b) and a b = p + e exactly (by a fused multiply-add
//!   where the target has one, else by Dekker's splitting into 26-bit halves).
//!
//! The matrix product accumulates each entry as a double-double ("sloppy" addition, as in the QD
//! library of Hida, Li and Bailey, 2001): its error is a small multiple of 2^-104 times the sum of
//! the magnitudes of the terms, against 2^-53 for a double product. The exponential uses it where
//! squaring amplifies rounding errors (see `expm.rs`).

use crate::linalg::small_matrix::SmallMatrix;
use crate::platform::dispatch::fma_dispatch;

/// (s, e) with s = fl(a + b) and s + e = a + b exactly (Knuth's branch-free two-sum).
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    (s, (a - a_virtual) + (b - b_virtual))
}

/// (s, e) with s = fl(a + b) and s + e = a + b exactly, for |a| >= |b| (Dekker's fast two-sum).
#[inline(always)]
pub fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// Splits a into high and low halves of at most 26 significant bits each (Dekker), so that
/// products of halves are exact.
#[inline(always)]
fn split(a: f64) -> (f64, f64) {
    const SPLITTER: f64 = 134_217_729.0; // 2^27 + 1
    let t = SPLITTER * a;
    let high = t - (t - a);
    (high, a - high)
}

/// (p, e) with p = fl(a b) and p + e = a b exactly (barring overflow and underflow): by a fused
/// multiply-add when `FMA`, else by Dekker's splitting.
#[inline(always)]
pub fn two_product<const FMA: bool>(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    if FMA {
        (p, a.mul_add(b, -p))
    } else {
        two_product_split(split(a), split(b), p)
    }
}

/// The error of p = fl(a b) from the splits of a and b (Dekker).
#[inline(always)]
fn two_product_split(
    (a_high, a_low): (f64, f64),
    (b_high, b_low): (f64, f64),
    p: f64,
) -> (f64, f64) {
    let e = ((a_high * b_high - p) + a_high * b_low + a_low * b_high) + a_low * b_low;
    (p, e)
}

type Rows<const N: usize> = [[f64; N]; N];

/// The entries of a * b accumulated in double-double, not yet normalised.
#[inline(always)]
fn product_kernel<const N: usize, const FMA: bool>(
    a: &DoubleDoubleMatrix<N>,
    b: &DoubleDoubleMatrix<N>,
) -> (Rows<N>, Rows<N>) {
    let mut hi = [[0.0; N]; N];
    let mut lo = [[0.0; N]; N];
    // Dekker's splits of b's high parts, once per product (unused with FMA).
    let mut b_split = [[(0.0, 0.0); N]; N];
    if !FMA {
        for (split_row, row) in b_split.iter_mut().zip(&b.hi.rows) {
            for (x, &value) in split_row.iter_mut().zip(row) {
                *x = split(value);
            }
        }
    }
    for i in 0..N {
        let (acc_hi, acc_lo) = (&mut hi[i], &mut lo[i]);
        for (k, b_split_row) in b_split.iter().enumerate() {
            let (a_hi, a_lo) = (a.hi.rows[i][k], a.lo.rows[i][k]);
            let a_split = split(a_hi);
            let (b_hi, b_lo) = (&b.hi.rows[k], &b.lo.rows[k]);
            for j in 0..N {
                let p = a_hi * b_hi[j];
                let (p, mut e) = if FMA {
                    (p, a_hi.mul_add(b_hi[j], -p))
                } else {
                    two_product_split(a_split, b_split_row[j], p)
                };
                e += a_hi * b_lo[j] + a_lo * b_hi[j];
                let (s, t) = two_sum(acc_hi[j], p);
                acc_hi[j] = s;
                acc_lo[j] += t + e;
            }
        }
    }
    (hi, lo)
}

fma_dispatch!(fn accumulate_product<const N: usize>(a: &DoubleDoubleMatrix<N>, b: &DoubleDoubleMatrix<N>) -> (Rows<N>, Rows<N>) => product_kernel);

/// identity * I + sum_k coefficient_k * M_k accumulated in double-double, not yet normalised.
#[inline(always)]
fn combination_kernel<const N: usize, const FMA: bool>(
    identity: f64,
    terms: &[(f64, &DoubleDoubleMatrix<N>)],
) -> (Rows<N>, Rows<N>) {
    let mut hi = [[0.0; N]; N];
    let mut lo = [[0.0; N]; N];
    for (i, row) in hi.iter_mut().enumerate() {
        row[i] = identity;
    }
    for &(coefficient, m) in terms {
        for i in 0..N {
            for j in 0..N {
                let (p, e) = two_product::<FMA>(coefficient, m.hi.rows[i][j]);
                let (s, t) = two_sum(hi[i][j], p);
                hi[i][j] = s;
                lo[i][j] += t + e + coefficient * m.lo.rows[i][j];
            }
        }
    }
    (hi, lo)
}

fma_dispatch!(fn accumulate_combination<const N: usize>(identity: f64, terms: &[(f64, &DoubleDoubleMatrix<N>)]) -> (Rows<N>, Rows<N>) => combination_kernel);

/// An N x N matrix of double-double numbers: entry (i, j) is `hi[i][j] + lo[i][j]`.
#[derive(Clone, Copy, Debug)]
pub struct DoubleDoubleMatrix<const N: usize> {
    pub hi: SmallMatrix<N>,
    pub lo: SmallMatrix<N>,
}

impl<const N: usize> DoubleDoubleMatrix<N> {
    /// The exact double-double value of a double matrix.
    pub fn from_double(a: &SmallMatrix<N>) -> Self {
        Self {
            hi: *a,
            lo: SmallMatrix::zeros(),
        }
    }

    /// c A, exactly (each entry's product is error-free).
    pub fn scaled(a: &SmallMatrix<N>, c: f64) -> Self {
        let mut out = Self::from_double(&SmallMatrix::zeros());
        for i in 0..N {
            for j in 0..N {
                let (p, e) = two_product::<false>(c, a.rows[i][j]);
                out.hi.rows[i][j] = p;
                out.lo.rows[i][j] = e;
            }
        }
        out
    }

    /// The nearest double matrix (hi + lo rounded).
    pub fn round(&self) -> SmallMatrix<N> {
        let mut out = SmallMatrix::zeros();
        for i in 0..N {
            for j in 0..N {
                out.rows[i][j] = self.hi.rows[i][j] + self.lo.rows[i][j];
            }
        }
        out
    }

    /// Normalises accumulated (hi, lo) pairs so that |lo| <= ulp(hi)/2.
    fn normalize(hi: [[f64; N]; N], lo: [[f64; N]; N]) -> Self {
        let mut out = Self::from_double(&SmallMatrix::zeros());
        for i in 0..N {
            for j in 0..N {
                let (h, l) = quick_two_sum(hi[i][j], lo[i][j]);
                out.hi.rows[i][j] = h;
                out.lo.rows[i][j] = l;
            }
        }
        out
    }

    /// self * rhs, with each entry accumulated in double-double.
    pub fn product(&self, rhs: &Self) -> Self {
        let (hi, lo) = accumulate_product(self, rhs);
        Self::normalize(hi, lo)
    }

    /// identity * I + sum_k coefficient_k * M_k, each entry accumulated in double-double.
    pub fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self {
        let (hi, lo) = accumulate_combination(identity, terms);
        Self::normalize(hi, lo)
    }

    /// self - other.
    pub fn difference(&self, other: &Self) -> Self {
        let mut hi = [[0.0; N]; N];
        let mut lo = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                let (s, t) = two_sum(self.hi.rows[i][j], -other.hi.rows[i][j]);
                hi[i][j] = s;
                lo[i][j] = t + (self.lo.rows[i][j] - other.lo.rows[i][j]);
            }
        }
        Self::normalize(hi, lo)
    }

    /// self + delta for a double matrix delta.
    pub fn plus_double(&self, delta: &SmallMatrix<N>) -> Self {
        let mut hi = [[0.0; N]; N];
        let mut lo = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                let (s, t) = two_sum(self.hi.rows[i][j], delta.rows[i][j]);
                hi[i][j] = s;
                lo[i][j] = t + self.lo.rows[i][j];
            }
        }
        Self::normalize(hi, lo)
    }

    /// X with self X = rhs, to double-double accuracy when self is well conditioned: an LU
    /// solve in double, then two steps of iterative refinement with residuals rhs - self X
    /// computed in double-double. Each step gains a factor of about κ(self) u.
    pub fn solve(&self, rhs: &Self) -> Self {
        let lu = self.hi.lu();
        let mut x = Self::from_double(&lu.solve(rhs.round()));
        for _ in 0..2 {
            let residual = rhs.difference(&self.product(&x));
            x = x.plus_double(&lu.solve(residual.round()));
        }
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_free_transformations_are_exact() {
        // 1 + 2^-60 is not a double; two_sum keeps the tail.
        let (s, e) = two_sum(1.0, 2f64.powi(-60));
        assert_eq!((s, e), (1.0, 2f64.powi(-60)));
        // 1e16 + 1 is not a double either (the spacing there is 2).
        assert_eq!(quick_two_sum(1e16, 1.0), (1e16, 1.0));
        // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60: the last term is the product's rounding error.
        let x = 1.0 + 2f64.powi(-30);
        assert_eq!(
            two_product::<false>(x, x),
            (1.0 + 2f64.powi(-29), 2f64.powi(-60))
        );
        assert_eq!(
            two_product::<true>(x, x),
            (1.0 + 2f64.powi(-29), 2f64.powi(-60))
        );
        let (high, low) = split(0.1);
        assert_eq!(high + low, 0.1);
    }

    #[test]
    fn products_are_accurate_beyond_double() {
        // The product of (1 + ε) I with (1 - ε) I is (1 - ε^2) I, below double resolution.
        let epsilon = 2f64.powi(-40);
        let a = DoubleDoubleMatrix::<3>::scaled(&SmallMatrix::identity(), 1.0 + epsilon);
        let b = DoubleDoubleMatrix::<3>::scaled(&SmallMatrix::identity(), 1.0 - epsilon);
        let p = a.product(&b);
        for i in 0..3 {
            assert_eq!(p.hi.rows[i][i], 1.0);
            assert_eq!(p.lo.rows[i][i], -epsilon * epsilon);
        }
    }

    #[test]
    fn refined_solve_reaches_double_double_accuracy() {
        // A = [[3, 1], [1, 3]] has the exactly representable inverse [[3/8, -1/8], [-1/8, 3/8]].
        let a = DoubleDoubleMatrix::<2>::from_double(&SmallMatrix {
            rows: [[3.0, 1.0], [1.0, 3.0]],
        });
        let x = a.solve(&DoubleDoubleMatrix::from_double(&SmallMatrix::identity()));
        assert_eq!(x.hi.rows, [[0.375, -0.125], [-0.125, 0.375]]);
        assert_eq!(x.lo.rows, [[0.0, 0.0], [0.0, 0.0]]);
        // A 1/3 entry: 3 x = 1 has x = 1/3, whose double-double error is below 2^-105.
        let three = DoubleDoubleMatrix::<1>::from_double(&SmallMatrix { rows: [[3.0]] });
        let x = three.solve(&DoubleDoubleMatrix::from_double(&SmallMatrix {
            rows: [[1.0]],
        }));
        let (h, l) = (x.hi.rows[0][0], x.lo.rows[0][0]);
        // 3 (h + l) - 1 computed exactly: 3h = p + e exactly, then (p - 1) + e + 3l.
        let (p, e) = two_product::<false>(3.0, h);
        let residual = (p - 1.0) + e + 3.0 * l;
        assert!(residual.abs() < 2f64.powi(-104), "{residual}");
    }

    #[test]
    fn combination_and_difference_cancel_exactly() {
        let m = SmallMatrix::<2> {
            rows: [[0.1, 0.2], [0.3, 0.7]],
        };
        let d = DoubleDoubleMatrix::from_double(&m);
        let twice = DoubleDoubleMatrix::combination(0.0, &[(2.0, &d)]);
        let zero = twice.difference(&DoubleDoubleMatrix::combination(
            0.0,
            &[(1.0, &d), (1.0, &d)],
        ));
        assert!(zero.round().one_norm() == 0.0);
        let shifted = d.plus_double(&m);
        assert_eq!(shifted.round().rows, twice.round().rows);
    }
}
