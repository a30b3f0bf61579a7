//! The Hessenberg-triangular reduction of a pencil (Moler & Stewart 1973; Golub & Van Loan,
//! *Matrix Computations*, 4th ed., Algorithm 7.7.1): orthogonal Q, Z with Q^T A Z upper
//! Hessenberg and Q^T B Z upper triangular.
//!
//! First B = Q R by Householder reflectors, applied to A from the left. Then, column by column
//! from the left and from the bottom up, a rotation of rows (i - 1, i) zeroes A[i, j], which
//! puts a fill-in at B[i, i - 1], and a rotation of columns (i - 1, i) zeroes that again. About
//! 8 n^3 flops for A and B and 3 n^3 each for Q and Z. Every transformation is orthogonal, so the
//! reduction is backward stable.

use crate::error::Error;
use crate::linalg::householder::reflector;
use crate::linalg::qr::{apply_on_the_right, apply_transpose_on_the_left, block_size, qr_in_place};
use crate::linalg::rotation::Rotation;
use crate::platform::dispatch::clear_upper_avx_state;
use crate::platform::interrupt;
use crate::platform::pool::scratch;
use faer::{Conj, Mat, Par};
use std::ops::Range;

/// Reduces (a, b) in place and accumulates the transformations into q and z (from the left
/// and right: on return the original A is Q a Z^T when q and z entered as identities).
///
/// The rotations of one column j are applied in the order that keeps memory access down
/// columns (the matrices are column-major, and a rotation of rows walks across them):
/// - the row rotations G_i (rows i - 1, i; i = n - 1 down to j + 2) depend on column j of A
///   alone, so they are formed first, and applied to A's other columns one column at a time;
/// - the column rotation Z_i depends on B's entries (i - 1..=i, i - 1..=i) after G_i and
///   Z_(i+1), and only columns i - 1 and i of B need G_i before it (a column c > i takes no
///   further column rotation in this sweep), so B's columns beyond take G_i afterwards, again
///   one column at a time;
/// - left and right transformations commute, so A takes the Z_i after all of the G_i.
pub(crate) fn hessenberg_triangular(
    a: &mut Mat<f64>,
    b: &mut Mat<f64>,
    q: &mut Mat<f64>,
    z: &mut Mat<f64>,
) -> Result<(), Error> {
    let n = a.nrows();
    triangularize(b, a, q)?;
    // gs[k] and zs[k] act on rows / columns (i - 1, i) with i = n - 1 - k.
    let mut gs = Vec::with_capacity(n);
    let mut zs = Vec::with_capacity(n);
    for j in 0..n.saturating_sub(2) {
        interrupt::check()?;
        gs.clear();
        zs.clear();
        for i in (j + 2..n).rev() {
            let (g, r) = Rotation::zeroing(a[(i - 1, j)], a[(i, j)]);
            a[(i - 1, j)] = r;
            a[(i, j)] = 0.0;
            gs.push(g);
        }
        rotate_columns_down(a, j + 1..n, &gs, |_| 0);
        for (k, g) in gs.iter().enumerate() {
            let i = n - 1 - k;
            g.rows(b, i - 1, i, i - 1..i + 1);
            let (g, r) = Rotation::zeroing_first(b[(i, i - 1)], b[(i, i)]);
            b[(i, i)] = r;
            b[(i, i - 1)] = 0.0;
            g.columns(b, i - 1, i, 0..i);
            zs.push(g);
        }
        rotate_columns_down(b, j + 3..n, &gs, |c| n - c);
        for (k, (g, zk)) in gs.iter().zip(&zs).enumerate() {
            let i = n - 1 - k;
            g.columns(q, i - 1, i, 0..n);
            zk.columns(a, i - 1, i, 0..n);
            zk.columns(z, i - 1, i, 0..n);
        }
    }
    Ok(())
}

/// Applies the row rotations gs[first(c)..] in order to each column c in `columns`, gs[k]
/// acting on rows (i - 1, i) with i = n - 1 - k. Four columns at a time, so that their
/// independent chains of rotations overlap (one column's chain is bound by the latency of its
/// multiply-adds): each column first takes the rotations that the others of its group skip.
fn rotate_columns_down(
    m: &mut Mat<f64>,
    columns: Range<usize>,
    gs: &[Rotation],
    first: impl Fn(usize) -> usize,
) {
    const WIDTH: usize = 4;
    let n = m.nrows();
    assert!(columns.end <= m.ncols() && gs.len() < n.max(1));
    let stride = m.col_stride();
    let base = m.as_ptr_mut();
    let rotate = |p: *mut f64, k: usize, g: &Rotation| {
        let i = n - 1 - k;
        // SAFETY: p addresses a column of m, and k < gs.len() < n gives rows i - 1 and i
        // inside it.
        unsafe {
            let (u, v) = (*p.add(i - 1), *p.add(i));
            *p.add(i - 1) = g.c * u + g.s * v;
            *p.add(i) = -g.s * u + g.c * v;
        }
    };
    let mut c = columns.start;
    while c < columns.end {
        let width = WIDTH.min(columns.end - c);
        // SAFETY: c + l < ncols: distinct columns of m.
        let x: [*mut f64; WIDTH] = std::array::from_fn(|l| unsafe {
            base.offset((c + l.min(width - 1)) as isize * stride)
        });
        let starts: [usize; WIDTH] = std::array::from_fn(|l| first(c + l.min(width - 1)));
        let common = starts.iter().copied().max().unwrap_or(0).min(gs.len());
        for (p, &start) in x.iter().zip(&starts).take(width) {
            for (k, g) in gs.iter().enumerate().take(common).skip(start) {
                rotate(*p, k, g);
            }
        }
        if width == WIDTH {
            for (k, g) in gs.iter().enumerate().skip(common) {
                for p in x {
                    rotate(p, k, g);
                }
            }
        } else {
            for p in &x[..width] {
                for (k, g) in gs.iter().enumerate().skip(common) {
                    rotate(*p, k, g);
                }
            }
        }
        c += width;
    }
}

/// Up to this order B = Q R is the plain Householder loop of [`triangularize_unblocked`];
/// above it, faer's blocked QR (whose set-up costs more than the whole loop at small orders).
const UNBLOCKED_QR_MAX_ORDER: usize = 32;

/// B = Q R by Householder reflectors; `other` (A) is multiplied by Q^T and Q accumulated.
/// Above [`UNBLOCKED_QR_MAX_ORDER`], faer's blocked QR and applications of Q, driven in
/// blocks that answer an interruption ([`crate::linalg::qr`], bitwise one faer call each).
fn triangularize(b: &mut Mat<f64>, other: &mut Mat<f64>, q: &mut Mat<f64>) -> Result<(), Error> {
    let n = b.nrows();
    if n <= UNBLOCKED_QR_MAX_ORDER {
        return triangularize_unblocked(b, other, q);
    }
    // Sequential, as the Hessenberg reduction: the result must not depend on the machine.
    let par = Par::Seq;
    let mut householder = scratch(block_size::<f64>(n, n), n);
    qr_in_place(b.as_mut(), householder.as_mut(), par)?;
    interrupt::check()?;
    apply_transpose_on_the_left(
        b.as_ref(),
        householder.as_ref(),
        Conj::No,
        other.as_mut(),
        par,
    )?;
    apply_on_the_right(b.as_ref(), householder.as_ref(), Conj::No, q.as_mut(), par)?;
    for j in 0..n {
        for i in j + 1..n {
            b[(i, j)] = 0.0;
        }
    }
    // The rotations that follow are SSE code: without this, after faer's AVX kernels, each of
    // their instructions pays the AVX-SSE transition.
    clear_upper_avx_state();
    Ok(())
}

/// [`triangularize`] by one reflector at a time.
fn triangularize_unblocked(
    b: &mut Mat<f64>,
    other: &mut Mat<f64>,
    q: &mut Mat<f64>,
) -> Result<(), Error> {
    let n = b.nrows();
    let mut v = Vec::new();
    let mut w = vec![0.0; n];
    for j in 0..n.saturating_sub(1) {
        interrupt::check()?;
        v.clear();
        v.extend((j..n).map(|i| b[(i, j)]));
        let (beta, tau) = reflector(&mut v);
        v[0] = 1.0;
        b[(j, j)] = beta;
        for i in j + 1..n {
            b[(i, j)] = 0.0;
        }
        if tau == 0.0 {
            continue;
        }
        let reflect_column = |m: &mut Mat<f64>, col: usize| {
            let s: f64 = v
                .iter()
                .enumerate()
                .map(|(k, vk)| vk * m[(j + k, col)])
                .sum();
            let s = tau * s;
            for (k, vk) in v.iter().enumerate() {
                m[(j + k, col)] -= s * vk;
            }
        };
        for col in j + 1..n {
            reflect_column(b, col);
        }
        for col in 0..n {
            reflect_column(other, col);
        }
        // Q <- Q (I - τ v v^T): w = Q v, then Q -= τ w v^T, column by column.
        w.iter_mut().for_each(|x| *x = 0.0);
        for (k, vk) in v.iter().enumerate() {
            for (r, wr) in w.iter_mut().enumerate() {
                *wr += vk * q[(r, j + k)];
            }
        }
        for (k, vk) in v.iter().enumerate() {
            for (r, wr) in w.iter().enumerate() {
                q[(r, j + k)] -= tau * wr * vk;
            }
        }
    }
    Ok(())
}
