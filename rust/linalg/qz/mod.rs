//! The generalized real Schur form (QZ) of a pencil A - λB and its reordering:
//!
//! ```text
//! A = Q S Z^T,   B = Q T Z^T,   Q, Z orthogonal,
//! ```
//!
//! S quasi-upper-triangular with 2 x 2 blocks for complex pairs, T upper triangular with
//! t_kk >= 0 and diagonal 2 x 2 blocks under S's (LAPACK's dgges form). The eigenvalues are
//! α_k / β_k: β_k = t_kk, α_k = s_kk for a 1 x 1 block, α = λ β for a pair; β = 0 is an
//! infinite eigenvalue (B singular).
//!
//! The method: the Hessenberg-triangular reduction ([`reduction`]), the double-shift QZ
//! iteration with deflation of infinite eigenvalues and standard 2 x 2 blocks ([`iteration`]),
//! and reordering by adjacent swaps ([`reorder`]). All transformations are orthogonal, so the
//! computed form is the exact form of a pencil within a small multiple of u ||(A, B)||_F; the
//! tests check ||Q^T A Z - S||, ||Q^T B Z - T|| <= 10 n u ||(A, B)||_F. It is the base of the
//! discrete Riccati solver ([`crate::control::riccati::dare`]).

pub(crate) mod iteration;
pub(crate) mod reduction;
pub(crate) mod reorder;

use crate::error::{Error, check_finite, check_square};
use faer::{Mat, MatRef, c64};
use iteration::Pencil;

/// The generalized real Schur form (A, B) = Q (S, T) Z^T.
#[derive(Debug, Clone)]
pub struct GeneralizedSchur {
    pub s: Mat<f64>,
    pub t: Mat<f64>,
    pub q: Mat<f64>,
    pub z: Mat<f64>,
}

/// One generalized eigenvalue α / β: α complex, β >= 0 real (0 for an infinite eigenvalue).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedEigenvalue {
    pub alpha: c64,
    pub beta: f64,
}

impl GeneralizedEigenvalue {
    /// α / β, with an infinite real part when β = 0 (and α is not).
    pub fn value(self) -> c64 {
        if self.beta == 0.0 {
            c64::new(f64::INFINITY, 0.0)
        } else {
            self.alpha / self.beta
        }
    }
}

/// The generalized real Schur form of (A, B).
pub fn qz(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<GeneralizedSchur, Error> {
    check_square(a, "A")?;
    check_square(b, "B")?;
    if b.nrows() != a.nrows() {
        return Err(Error::Mismatch {
            arg: "B",
            what: "order",
            expected: a.nrows(),
            other: "A",
            got: b.nrows(),
        });
    }
    check_finite(a, "A")?;
    check_finite(b, "B")?;
    let n = a.nrows();
    // S, T, Q, Z and the temporaries of the reduction.
    crate::platform::memory::reserve(n.saturating_mul(n).saturating_mul(6 * 8))?;
    // A / α and B / β for the powers of two of their largest entries (exact: the same Q and
    // Z, S = α S', T = β T', the eigenvalues α/β times those of the scaled pencil): the
    // iteration's decisions compare entries of the two matrices and their tests are
    // relative to each, so a B of 1e-11 beside an A of 1 lost B's backward error (1e14 u).
    let (alpha, beta) = (unit_scale(a), unit_scale(b));
    // The callers form the pencil with faer's AVX products; the kernels here are SSE.
    crate::platform::dispatch::clear_upper_avx_state();
    let mut s = padded(n, |i, j| a[(i, j)] / alpha);
    let mut t = padded(n, |i, j| b[(i, j)] / beta);
    let mut q = padded(n, |i, j| if i == j { 1.0 } else { 0.0 });
    let mut z = padded(n, |i, j| if i == j { 1.0 } else { 0.0 });
    reduction::hessenberg_triangular(&mut s, &mut t, &mut q, &mut z)?;
    iteration::qz_iteration(&mut Pencil {
        h: &mut s,
        t: &mut t,
        q: &mut q,
        z: &mut z,
    })?;
    s *= faer::Scale(alpha);
    t *= faer::Scale(beta);
    Ok(GeneralizedSchur { s, t, q, z })
}

/// An n x n matrix whose column stride is an odd number of 64-byte cache lines.
///
/// The iteration rotates rows of column-major matrices: with a stride of a power of two
/// (n = 512: 4 KiB) every entry of a row falls in the same cache set and a row pair is
/// fetched from memory again by each rotation; an odd stride spreads a row over all sets.
fn padded(n: usize, f: impl FnMut(usize, usize) -> f64) -> Mat<f64> {
    const LINE: usize = 8;
    let mut stride = n.next_multiple_of(LINE);
    if (stride / LINE).is_multiple_of(2) {
        stride += LINE;
    }
    let mut m = Mat::with_capacity(stride, n);
    m.resize_with(n, n, f);
    m
}

/// The power of two nearest the largest magnitude of `m` (1 for a zero matrix), at most
/// 2^±1000 so that its reciprocal is finite.
fn unit_scale(m: MatRef<'_, f64>) -> f64 {
    let largest = crate::linalg::norm::max_abs(m);
    if largest > 0.0 {
        largest.log2().round().clamp(-1000.0, 1000.0).exp2()
    } else {
        1.0
    }
}

/// The eigenvalues of a generalized real Schur form, in the order of its diagonal (a pair with
/// Im > 0 first).
pub fn generalized_eigenvalues(
    s: MatRef<'_, f64>,
    t: MatRef<'_, f64>,
) -> Vec<GeneralizedEigenvalue> {
    let n = s.nrows();
    // The pairs from S / σ and T / τ (the powers of two of their largest entries), α and β
    // multiplied back: a pair's block S_kk T_kk^-1 of a pencil with T near 1e-300 beside S
    // near 1 overflowed when it was standardised.
    let (sigma, tau) = (unit_scale(s), unit_scale(t));
    let mut values = Vec::with_capacity(n);
    let mut k = 0;
    while k < n {
        if k + 1 < n && s[(k + 1, k)] != 0.0 {
            let (t11, t22) = (t[(k, k)] / tau, t[(k + 1, k + 1)] / tau);
            let entry = |i: usize, j: usize| s[(i, j)] / sigma;
            let m = [
                [entry(k, k) / t11, entry(k, k + 1) / t22],
                [entry(k + 1, k) / t11, entry(k + 1, k + 1) / t22],
            ];
            let block = crate::linalg::schur::standardize_block(m[0][0], m[0][1], m[1][0], m[1][1]);
            let im = block.b.abs().sqrt() * block.c.abs().sqrt();
            values.push(GeneralizedEigenvalue {
                alpha: c64::new(block.a, im) * t11 * sigma,
                beta: t11 * tau,
            });
            values.push(GeneralizedEigenvalue {
                alpha: c64::new(block.a, -im) * t22 * sigma,
                beta: t22 * tau,
            });
            k += 2;
        } else {
            values.push(GeneralizedEigenvalue {
                alpha: c64::new(s[(k, k)], 0.0),
                beta: t[(k, k)],
            });
            k += 1;
        }
    }
    values
}

/// Reorders a generalized Schur form so that the eigenvalues for which `select` is true come
/// first; returns the form and the number of selected eigenvalues. A complex pair is selected
/// when its member with Im > 0 is.
pub fn reorder_qz(
    mut schur: GeneralizedSchur,
    mut select: impl FnMut(GeneralizedEigenvalue) -> bool,
) -> Result<(GeneralizedSchur, usize), Error> {
    let values = generalized_eigenvalues(schur.s.as_ref(), schur.t.as_ref());
    let n = values.len();
    let mut selected = vec![false; n];
    let mut k = 0;
    while k < n {
        let size = reorder::block_size(&schur.s, k);
        let chosen = select(values[k]);
        selected[k..k + size].fill(chosen);
        k += size;
    }
    // The swaps on the pencil scaled as in [`qz`], for the same reasons.
    let (alpha, beta) = (unit_scale(schur.s.as_ref()), unit_scale(schur.t.as_ref()));
    schur.s *= faer::Scale(1.0 / alpha);
    schur.t *= faer::Scale(1.0 / beta);
    let count = reorder::reorder(
        &mut Pencil {
            h: &mut schur.s,
            t: &mut schur.t,
            q: &mut schur.q,
            z: &mut schur.z,
        },
        &selected,
    );
    schur.s *= faer::Scale(alpha);
    schur.t *= faer::Scale(beta);
    Ok((schur, count?))
}

#[cfg(test)]
mod tests;
