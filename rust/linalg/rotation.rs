//! Plane (Givens) rotations and small Householder reflectors applied to rows and columns of
//! dense matrices: the elementary orthogonal transformations of the QZ algorithm.
//!
//! One convention throughout: a rotation (c, s) maps a pair of rows (or columns) (x, y) to
//! (c x + s y, -s x + c y). Applied to rows i, k of a matrix it is G^T M with
//! G = [[c, -s], [s, c]] acting in the (i, k) plane; applied to columns i, k it is M G. So a
//! transformation Q^T M recorded as rows is accumulated into Q as the same rotation on its
//! columns.

use crate::platform::dispatch::{fma_dispatch, multiply_add};
use faer::Mat;
use std::ops::Range;

/// x and y times one power of two that brings the larger magnitude into [2^-500, 2^500]
/// (exact; unchanged where it is there, or zero, or not finite). A rotation depends only on
/// the ratio of the pair it is formed from, and formed from subnormal numbers it loses
/// orthogonality (their quotients and halves round to a few digits).
pub(crate) fn in_normal_range(x: f64, y: f64) -> (f64, f64) {
    const LOW: f64 = 3.054936363499605e-151; // 2^-500
    const HIGH: f64 = 3.273390607896142e150; // 2^500
    let largest = x.abs().max(y.abs());
    if largest == 0.0 || !largest.is_finite() || (LOW..=HIGH).contains(&largest) {
        return (x, y);
    }
    // 2^±1000 at most (2^1074 overflows); that brings any finite number to a normal one.
    let scale = 2f64.powi(-(largest.log2().round() as i32).clamp(-1000, 1000));
    (x * scale, y * scale)
}

/// A plane rotation, c^2 + s^2 = 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rotation {
    pub c: f64,
    pub s: f64,
}

impl Rotation {
    /// The rotation that maps (f, g) to (r, 0), r = hypot(f, g) >= 0; the identity when both
    /// are zero.
    pub fn zeroing(f: f64, g: f64) -> (Rotation, f64) {
        // The plain square root unless the squares leave the normal range (hypot is slow).
        let squares = f * f + g * g;
        if (f64::MIN_POSITIVE..f64::MAX).contains(&squares) {
            let r = squares.sqrt();
            return (Rotation { c: f / r, s: g / r }, r);
        }
        // c and s from (f, g) scaled into range: divided by a subnormal r (f and g near
        // 1e-318) they came out with a few digits, and the rotation off orthogonal.
        let (f_r, g_r) = in_normal_range(f, g);
        let r_r = f_r.hypot(g_r);
        if r_r == 0.0 {
            (Rotation { c: 1.0, s: 0.0 }, 0.0)
        } else {
            (
                Rotation {
                    c: f_r / r_r,
                    s: g_r / r_r,
                },
                f.hypot(g),
            )
        }
    }

    /// The rotation of columns (i, k) that maps the row entries (x, y) to (0, r): it zeroes the
    /// entry of the first column.
    pub fn zeroing_first(x: f64, y: f64) -> (Rotation, f64) {
        Rotation::zeroing(y, -x)
    }

    /// Rows i and k of `m`, over `columns`.
    #[inline]
    pub fn rows(self, m: &mut Mat<f64>, i: usize, k: usize, columns: Range<usize>) {
        assert!(i < m.nrows() && k < m.nrows() && columns.end <= m.ncols());
        let stride = m.col_stride();
        let base = m.as_ptr_mut();
        for j in columns {
            // SAFETY: i, k < nrows and j < ncols (asserted above), so both entries are inside
            // the matrix, and they are distinct when i != k.
            unsafe {
                let pi = base.offset(i as isize + j as isize * stride);
                let pk = base.offset(k as isize + j as isize * stride);
                let (x, y) = (*pi, *pk);
                *pi = self.c * x + self.s * y;
                *pk = -self.s * x + self.c * y;
            }
        }
    }

    /// Columns i and k of `m`, over `rows`.
    #[inline]
    pub fn columns(self, m: &mut Mat<f64>, i: usize, k: usize, rows: Range<usize>) {
        assert!(i < m.ncols() && k < m.ncols() && rows.end <= m.nrows() && i != k);
        let (ci, ck) = if i < k {
            let (left, right) = m.as_mut().split_at_col_mut(k);
            (
                left.col_mut(i).try_as_col_major_mut(),
                right.col_mut(0).try_as_col_major_mut(),
            )
        } else {
            let (left, right) = m.as_mut().split_at_col_mut(i);
            (
                right.col_mut(0).try_as_col_major_mut(),
                left.col_mut(k).try_as_col_major_mut(),
            )
        };
        let (ci, ck) = (
            ci.expect("a Mat's columns are contiguous"),
            ck.expect("contiguous"),
        );
        let (ci, ck) = (ci.as_slice_mut(), ck.as_slice_mut());
        rotate_pair(self.c, self.s, &mut ci[rows.clone()], &mut ck[rows]);
    }
}

/// (x, y) <- (c x + s y, -s x + c y) entrywise, for slices of one length.
#[inline(always)]
fn rotate_pair_kernel<const FMA: bool>(c: f64, s: f64, x: &mut [f64], y: &mut [f64]) {
    for (x, y) in x.iter_mut().zip(y) {
        let (a, b) = (*x, *y);
        *x = multiply_add::<FMA>(c, a, s * b);
        *y = multiply_add::<FMA>(c, b, -(s * a));
    }
}

fma_dispatch!(fn rotate_pair(c: f64, s: f64, x: &mut [f64], y: &mut [f64]) => rotate_pair_kernel);

/// A reflector I - τ u u^T of length 2 or 3 acting on consecutive rows or columns from
/// `first`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SmallReflector {
    pub u: [f64; 3],
    pub tau: f64,
    pub len: usize,
}

impl SmallReflector {
    /// The reflector that maps x (length 2 or 3) to (β, 0, ...): u = (1, v); returns it and β.
    pub fn to_first(x: &[f64]) -> (SmallReflector, f64) {
        let mut work = [0.0; 3];
        let len = x.len();
        work[..len].copy_from_slice(x);
        let (beta, tau) = crate::linalg::householder::reflector(&mut work[..len]);
        let mut u = [0.0; 3];
        u[0] = 1.0;
        u[1..len].copy_from_slice(&work[1..len]);
        (SmallReflector { u, tau, len }, beta)
    }

    /// The reflector that maps the row vector x (length 2 or 3) to (..., 0, β) when applied
    /// from the right: the reflector of x reversed, reversed.
    pub fn to_last(x: &[f64]) -> (SmallReflector, f64) {
        let len = x.len();
        let mut reversed = [0.0; 3];
        for (r, v) in reversed.iter_mut().zip(x.iter().rev()) {
            *r = *v;
        }
        let (first, beta) = SmallReflector::to_first(&reversed[..len]);
        let mut u = [0.0; 3];
        for (k, v) in first.u[..len].iter().rev().enumerate() {
            u[k] = *v;
        }
        (
            SmallReflector {
                u,
                tau: first.tau,
                len,
            },
            beta,
        )
    }

    /// Rows first.. first + len of `m`, over `columns`.
    #[inline]
    pub fn rows(&self, m: &mut Mat<f64>, first: usize, columns: Range<usize>) {
        if self.tau == 0.0 {
            return;
        }
        assert!(first + self.len <= m.nrows() && columns.end <= m.ncols());
        let stride = m.col_stride();
        let base = m.as_ptr_mut();
        let u = self.u;
        for j in columns {
            // SAFETY: rows first..first + len and column j are inside the matrix (asserted).
            unsafe {
                let p = base.offset(first as isize + j as isize * stride);
                if self.len == 3 {
                    let w = self.tau * (u[0] * *p + u[1] * *p.add(1) + u[2] * *p.add(2));
                    *p -= w * u[0];
                    *p.add(1) -= w * u[1];
                    *p.add(2) -= w * u[2];
                } else {
                    let w = self.tau * (u[0] * *p + u[1] * *p.add(1));
                    *p -= w * u[0];
                    *p.add(1) -= w * u[1];
                }
            }
        }
    }

    /// Columns first.. first + len of `m`, over `rows`.
    #[inline]
    pub fn columns(&self, m: &mut Mat<f64>, first: usize, rows: Range<usize>) {
        if self.tau == 0.0 {
            return;
        }
        assert!(first + self.len <= m.ncols() && rows.end <= m.nrows() && rows.start <= rows.end);
        let stride = m.col_stride();
        let base = m.as_ptr_mut();
        let length = rows.end - rows.start;
        // SAFETY: columns first..first + len of m are distinct (asserted in range), so the
        // slices over their rows `rows` are disjoint and inside the matrix.
        let column = |c: usize| unsafe {
            std::slice::from_raw_parts_mut(
                base.offset((first + c) as isize * stride + rows.start as isize),
                length,
            )
        };
        if self.len == 3 {
            reflect_three(self.u, self.tau, column(0), column(1), column(2));
        } else {
            reflect_two(self.u, self.tau, column(0), column(1));
        }
    }
}

/// (x, y, z) <- (x, y, z) - τ (u · (x, y, z)) u row by row: a reflector of length 3 applied to
/// three columns.
#[inline(always)]
fn reflect_three_kernel<const FMA: bool>(
    u: [f64; 3],
    tau: f64,
    x: &mut [f64],
    y: &mut [f64],
    z: &mut [f64],
) {
    let [v0, v1, v2] = u;
    for ((x, y), z) in x.iter_mut().zip(y.iter_mut()).zip(z.iter_mut()) {
        let w = tau * multiply_add::<FMA>(v2, *z, multiply_add::<FMA>(v1, *y, v0 * *x));
        *x = multiply_add::<FMA>(-w, v0, *x);
        *y = multiply_add::<FMA>(-w, v1, *y);
        *z = multiply_add::<FMA>(-w, v2, *z);
    }
}

fma_dispatch!(fn reflect_three(u: [f64; 3], tau: f64, x: &mut [f64], y: &mut [f64], z: &mut [f64]) => reflect_three_kernel);

/// [`reflect_three_kernel`] for a reflector of length 2.
#[inline(always)]
fn reflect_two_kernel<const FMA: bool>(u: [f64; 3], tau: f64, x: &mut [f64], y: &mut [f64]) {
    let [v0, v1, _] = u;
    for (x, y) in x.iter_mut().zip(y.iter_mut()) {
        let w = tau * multiply_add::<FMA>(v1, *y, v0 * *x);
        *x = multiply_add::<FMA>(-w, v0, *x);
        *y = multiply_add::<FMA>(-w, v1, *y);
    }
}

fma_dispatch!(fn reflect_two(u: [f64; 3], tau: f64, x: &mut [f64], y: &mut [f64]) => reflect_two_kernel);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_from_subnormal_pairs_are_orthogonal() {
        for (f, g) in [
            (1e-318, 3e-319),
            (5e-324, 1e-323),
            (-2.7e-319, 5.5e-319),
            (1e300, 1e300),
        ] {
            let (rotation, r) = Rotation::zeroing(f, g);
            let deviation = (rotation.c * rotation.c + rotation.s * rotation.s - 1.0).abs();
            assert!(
                deviation <= 4.0 * f64::EPSILON,
                "({f:e}, {g:e}): {deviation:e}"
            );
            assert_eq!(r, f.hypot(g));
            assert!(
                rotation.c * g - rotation.s * f == 0.0
                    || (rotation.c * g - rotation.s * f).abs() <= 4.0 * f64::EPSILON * r
            );
        }
    }

    #[test]
    fn rotations_zero_what_they_say() {
        let (g, r) = Rotation::zeroing(3.0, 4.0);
        assert_eq!(r, 5.0);
        let mut m = Mat::from_fn(2, 1, |i, _| [3.0, 4.0][i]);
        g.rows(&mut m, 0, 1, 0..1);
        assert!((m[(0, 0)] - 5.0).abs() < 1e-15 && m[(1, 0)].abs() < 1e-15);
        let (g, r) = Rotation::zeroing_first(3.0, 4.0);
        let mut m = Mat::from_fn(1, 2, |_, j| [3.0, 4.0][j]);
        g.columns(&mut m, 0, 1, 0..1);
        assert!(m[(0, 0)].abs() < 1e-15 && (m[(0, 1)] - r).abs() < 1e-15);
    }

    #[test]
    fn reflectors_zero_what_they_say() {
        let x = [1.0, -2.0, 2.0];
        let (h, beta) = SmallReflector::to_first(&x);
        let mut m = Mat::from_fn(3, 1, |i, _| x[i]);
        h.rows(&mut m, 0, 0..1);
        assert!((m[(0, 0)] - beta).abs() < 1e-15 && beta.abs() == 3.0);
        assert!(m[(1, 0)].abs() < 1e-15 && m[(2, 0)].abs() < 1e-15);
        let (h, beta) = SmallReflector::to_last(&x);
        let mut m = Mat::from_fn(1, 3, |_, j| x[j]);
        h.columns(&mut m, 0, 0..1);
        assert!((m[(0, 2)] - beta).abs() < 1e-15);
        assert!(m[(0, 0)].abs() < 1e-15 && m[(0, 1)].abs() < 1e-15);
    }
}
