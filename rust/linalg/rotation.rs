//! Plane (Givens) rotations and small Householder reflectors applied to rows and columns of
//! dense matrices: the elementary orthogonal transformations of the QZ algorithm.
//!
//! One convention throughout: a rotation (c, s) maps a pair of rows (or columns) (x, y) to
//! (c x + s y, -s x + c y). Applied to rows i, k of a matrix it is G^T M with
//! G = [[c, -s], [s, c]] acting in the (i, k) plane; applied to columns i, k it is M G. So a
//! transformation Q^T M recorded as rows is accumulated into Q as the same rotation on its
//! columns.

use faer::Mat;
use std::ops::Range;

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
        let r = f.hypot(g);
        if r == 0.0 {
            (Rotation { c: 1.0, s: 0.0 }, 0.0)
        } else {
            (Rotation { c: f / r, s: g / r }, r)
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
        for j in columns {
            let (x, y) = (m[(i, j)], m[(k, j)]);
            m[(i, j)] = self.c * x + self.s * y;
            m[(k, j)] = -self.s * x + self.c * y;
        }
    }

    /// Columns i and k of `m`, over `rows`.
    #[inline]
    pub fn columns(self, m: &mut Mat<f64>, i: usize, k: usize, rows: Range<usize>) {
        for r in rows {
            let (x, y) = (m[(r, i)], m[(r, k)]);
            m[(r, i)] = self.c * x + self.s * y;
            m[(r, k)] = -self.s * x + self.c * y;
        }
    }
}

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
        let u = &self.u[..self.len];
        for j in columns {
            let w: f64 = u
                .iter()
                .enumerate()
                .map(|(k, uk)| uk * m[(first + k, j)])
                .sum();
            let w = self.tau * w;
            for (k, uk) in u.iter().enumerate() {
                m[(first + k, j)] -= w * uk;
            }
        }
    }

    /// Columns first.. first + len of `m`, over `rows`.
    #[inline]
    pub fn columns(&self, m: &mut Mat<f64>, first: usize, rows: Range<usize>) {
        if self.tau == 0.0 {
            return;
        }
        let u = &self.u[..self.len];
        for r in rows {
            let w: f64 = u
                .iter()
                .enumerate()
                .map(|(k, uk)| uk * m[(r, first + k)])
                .sum();
            let w = self.tau * w;
            for (k, uk) in u.iter().enumerate() {
                m[(r, first + k)] -= w * uk;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
