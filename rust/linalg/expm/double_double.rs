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

use crate::linalg::small_matrix::{SmallLu, columns};
use crate::platform::dispatch::fma_dispatch;
use nalgebra::SMatrix;

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

/// The storage of an N x N matrix: N columns of N entries (`columns[j][i]` = a_ij).
type Columns<const N: usize> = [[f64; N]; N];

/// The entries of a * b accumulated in double-double, not yet normalised: column j of the
/// result gains b_kj times column k of a, k in order (each entry the sum over k, in order).
#[inline(always)]
fn product_kernel<const N: usize, const FMA: bool>(
    a: &DoubleDoubleMatrix<N>,
    b: &DoubleDoubleMatrix<N>,
) -> (Columns<N>, Columns<N>) {
    let mut hi = [[0.0; N]; N];
    let mut lo = [[0.0; N]; N];
    let (a_hi, a_lo) = (columns(&a.hi), columns(&a.lo));
    let (b_hi, b_lo) = (columns(&b.hi), columns(&b.lo));
    // Dekker's splits of the high parts, once per product (unused with FMA).
    let mut a_split = [[(0.0, 0.0); N]; N];
    let mut b_split = [[(0.0, 0.0); N]; N];
    if !FMA {
        for (splits, column) in a_split
            .iter_mut()
            .zip(a_hi)
            .chain(b_split.iter_mut().zip(b_hi))
        {
            for (x, &value) in splits.iter_mut().zip(column) {
                *x = split(value);
            }
        }
    }
    for j in 0..N {
        let (acc_hi, acc_lo) = (&mut hi[j], &mut lo[j]);
        for k in 0..N {
            let (b_hi_kj, b_lo_kj, b_split_kj) = (b_hi[j][k], b_lo[j][k], b_split[j][k]);
            let (a_hi_k, a_lo_k, a_split_k) = (&a_hi[k], &a_lo[k], &a_split[k]);
            for i in 0..N {
                let p = a_hi_k[i] * b_hi_kj;
                let (p, mut e) = if FMA {
                    (p, a_hi_k[i].mul_add(b_hi_kj, -p))
                } else {
                    two_product_split(a_split_k[i], b_split_kj, p)
                };
                e += a_hi_k[i] * b_lo_kj + a_lo_k[i] * b_hi_kj;
                let (s, t) = two_sum(acc_hi[i], p);
                acc_hi[i] = s;
                acc_lo[i] += t + e;
            }
        }
    }
    (hi, lo)
}

fma_dispatch!(fn accumulate_product<const N: usize>(a: &DoubleDoubleMatrix<N>, b: &DoubleDoubleMatrix<N>) -> (Columns<N>, Columns<N>) => product_kernel);

/// identity * I + sum_k coefficient_k * M_k accumulated in double-double, not yet normalised.
#[inline(always)]
fn combination_kernel<const N: usize, const FMA: bool>(
    identity: f64,
    terms: &[(f64, &DoubleDoubleMatrix<N>)],
) -> (Columns<N>, Columns<N>) {
    let mut hi = [[0.0; N]; N];
    let mut lo = [[0.0; N]; N];
    for (i, column) in hi.iter_mut().enumerate() {
        column[i] = identity;
    }
    for &(coefficient, m) in terms {
        let (m_hi, m_lo) = (columns(&m.hi), columns(&m.lo));
        for j in 0..N {
            for i in 0..N {
                let (p, e) = two_product::<FMA>(coefficient, m_hi[j][i]);
                let (s, t) = two_sum(hi[j][i], p);
                hi[j][i] = s;
                lo[j][i] += t + e + coefficient * m_lo[j][i];
            }
        }
    }
    (hi, lo)
}

fma_dispatch!(fn accumulate_combination<const N: usize>(identity: f64, terms: &[(f64, &DoubleDoubleMatrix<N>)]) -> (Columns<N>, Columns<N>) => combination_kernel);

/// An N x N matrix of double-double numbers: entry (i, j) is `hi[(i, j)] + lo[(i, j)]`.
#[derive(Clone, Copy, Debug)]
pub struct DoubleDoubleMatrix<const N: usize> {
    pub hi: SMatrix<f64, N, N>,
    pub lo: SMatrix<f64, N, N>,
}

impl<const N: usize> DoubleDoubleMatrix<N> {
    /// The exact double-double value of a double matrix.
    pub fn from_double(a: &SMatrix<f64, N, N>) -> Self {
        Self {
            hi: *a,
            lo: SMatrix::zeros(),
        }
    }

    /// c A, exactly (each entry's product is error-free).
    pub fn scaled(a: &SMatrix<f64, N, N>, c: f64) -> Self {
        let mut out = Self::from_double(&SMatrix::zeros());
        for i in 0..N {
            for j in 0..N {
                let (p, e) = two_product::<false>(c, a[(i, j)]);
                out.hi[(i, j)] = p;
                out.lo[(i, j)] = e;
            }
        }
        out
    }

    /// The nearest double matrix (hi + lo rounded).
    pub fn round(&self) -> SMatrix<f64, N, N> {
        let mut out = SMatrix::zeros();
        for i in 0..N {
            for j in 0..N {
                out[(i, j)] = self.hi[(i, j)] + self.lo[(i, j)];
            }
        }
        out
    }

    /// Normalises accumulated (hi, lo) pairs so that |lo| <= ulp(hi)/2.
    fn normalize(hi: Columns<N>, lo: Columns<N>) -> Self {
        let mut out = Self::from_double(&SMatrix::zeros());
        for i in 0..N {
            for j in 0..N {
                let (h, l) = quick_two_sum(hi[j][i], lo[j][i]);
                out.hi[(i, j)] = h;
                out.lo[(i, j)] = l;
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
                let (s, t) = two_sum(self.hi[(i, j)], -other.hi[(i, j)]);
                hi[j][i] = s;
                lo[j][i] = t + (self.lo[(i, j)] - other.lo[(i, j)]);
            }
        }
        Self::normalize(hi, lo)
    }

    /// self + delta for a double matrix delta.
    pub fn plus_double(&self, delta: &SMatrix<f64, N, N>) -> Self {
        let mut hi = [[0.0; N]; N];
        let mut lo = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..N {
                let (s, t) = two_sum(self.hi[(i, j)], delta[(i, j)]);
                hi[j][i] = s;
                lo[j][i] = t + self.lo[(i, j)];
            }
        }
        Self::normalize(hi, lo)
    }

    /// X with self X = rhs, to double-double accuracy when self is well conditioned: an LU
    /// solve in double, then two steps of iterative refinement with residuals rhs - self X
    /// computed in double-double. Each step gains a factor of about κ(self) u.
    pub fn solve(&self, rhs: &Self) -> Self {
        let lu = SmallLu::new(self.hi);
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
        let a = DoubleDoubleMatrix::<3>::scaled(&SMatrix::identity(), 1.0 + epsilon);
        let b = DoubleDoubleMatrix::<3>::scaled(&SMatrix::identity(), 1.0 - epsilon);
        let p = a.product(&b);
        for i in 0..3 {
            assert_eq!(p.hi[(i, i)], 1.0);
            assert_eq!(p.lo[(i, i)], -epsilon * epsilon);
        }
    }

    #[test]
    fn refined_solve_reaches_double_double_accuracy() {
        // A = [[3, 1], [1, 3]] has the exactly representable inverse [[3/8, -1/8], [-1/8, 3/8]].
        let a =
            DoubleDoubleMatrix::<2>::from_double(&SMatrix::from_row_slice(&[3.0, 1.0, 1.0, 3.0]));
        let x = a.solve(&DoubleDoubleMatrix::from_double(&SMatrix::identity()));
        assert_eq!(
            x.hi,
            SMatrix::<f64, 2, 2>::new(0.375, -0.125, -0.125, 0.375)
        );
        assert_eq!(x.lo, SMatrix::<f64, 2, 2>::zeros());
        // A 1/3 entry: 3 x = 1 has x = 1/3, whose double-double error is below 2^-105.
        let three = DoubleDoubleMatrix::<1>::from_double(&SMatrix::from_row_slice(&[3.0]));
        let x = three.solve(&DoubleDoubleMatrix::from_double(&SMatrix::from_row_slice(
            &[1.0],
        )));
        let (h, l) = (x.hi[(0, 0)], x.lo[(0, 0)]);
        // 3 (h + l) - 1 computed exactly: 3h = p + e exactly, then (p - 1) + e + 3l.
        let (p, e) = two_product::<false>(3.0, h);
        let residual = (p - 1.0) + e + 3.0 * l;
        assert!(residual.abs() < 2f64.powi(-104), "{residual}");
    }

    #[test]
    fn combination_and_difference_cancel_exactly() {
        let m = SMatrix::<f64, 2, 2>::from_row_slice(&[0.1, 0.2, 0.3, 0.7]);
        let d = DoubleDoubleMatrix::from_double(&m);
        let twice = DoubleDoubleMatrix::combination(0.0, &[(2.0, &d)]);
        let zero = twice.difference(&DoubleDoubleMatrix::combination(
            0.0,
            &[(1.0, &d), (1.0, &d)],
        ));
        assert!(crate::linalg::small_matrix::one_norm(&zero.round()) == 0.0);
        let shifted = d.plus_double(&m);
        assert_eq!(shifted.round(), twice.round());
    }
}
