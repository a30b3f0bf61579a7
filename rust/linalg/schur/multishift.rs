//! The small-bulge multishift QR iteration with aggressive early deflation, for the real Schur
//! form of large upper Hessenberg matrices (from order [`MULTISHIFT_MIN_ORDER`]).
//!
//! The double-shift iteration of [`crate::linalg::schur`] chases one bulge at a time and applies each
//! 3 x 3 reflector as a rank-1 update of whole rows and columns: O(n^2) memory traffic per
//! sweep for O(n^2) flops, so at orders of a few hundred it runs at the speed of memory, not of
//! the arithmetic units. This module does what Braman, Byers & Mathias (2002) proposed and
//! LAPACK's dhseqr (dlaqr0, dlaqr3, dlaqr5) does:
//!
//! * **Aggressive early deflation** (Braman, Byers & Mathias 2002, part II). The trailing
//!   w x w block of the active window is reduced to Schur form S = V^T H_ww V (recursively,
//!   by this same iteration when w is large). Its coupling to the rest of the window is the
//!   spike s = h[top, top-1] V[0, :]; every diagonal block of S whose spike entries are below
//!   u times its eigenvalue has converged and deflates where it stands, and the others are moved
//!   to the top of S by Schur swaps. The spike of the undeflated part is folded into one entry by
//!   a reflector and the undeflated part is returned to Hessenberg form. Many eigenvalues
//!   deflate at once, long before a subdiagonal entry becomes small, and the eigenvalues of the
//!   undeflated part are the shifts of the next sweep.
//! * **A chain of small bulges** (part I). A sweep uses `2 b` shifts at once as b bulges of
//!   the ordinary double-shift kind, introduced at the top one after another and chased down
//!   together, three rows apart. All the reflectors of one step are independent (they act on
//!   disjoint rows and columns), and the chase proceeds in slabs: the chain moves about its own
//!   length down the diagonal while every reflector is applied only within the near-diagonal
//!   window it lives in and accumulated into one orthogonal U. The rows above the window, the
//!   columns to its right and Z are then updated by three matrix products (faer's, sequential)
//!   with U. Most of the flops thereby become level-3 products.
//!
//! Each iteration of [`multishift_qr`] first looks for negligible subdiagonal entries (the
//! test of [`negligible_subdiagonal`]), then runs aggressive early deflation on the bottom of the
//! active block; unless that deflated much (then it runs again instead), a sweep follows with the
//! smallest of its undeflated eigenvalues as shifts. An active block smaller than
//! [`MULTISHIFT_MIN_ORDER`] is finished by the double-shift iteration, on a copy whose
//! transformation then updates the rest of H and Z by products (should that iteration fail,
//! the multishift one goes on down to blocks of order 3). Every sixth iteration without a
//! deflation uses exceptional shifts (Wilkinson's ad hoc ones), and after five the deflation
//! window doubles.
//!
//! The sweep's shift count and the deflation window follow LAPACK's iparmq (about n / log2 n
//! shifts) except that the window is never larger than the shift count (measured below). The
//! time goes, at order 512, about equally to the Hessenberg reduction, the deflation passes
//! (the window's Schur form and the swaps) and the sweeps; against the double-shift iteration
//! alone the Schur form is 1.5 times faster at order 128, 4 times at 256 and 12 times at 512
//! (whose column stride of 4 KiB made the one-bulge sweeps miss the cache on every column).
//!
//! Every transformation is an orthogonal similarity (reflectors, Schur swaps that passed the
//! stability tests of Bai & Demmel, and rotations), and what is set to zero is either negligible
//! by the Ahues-Tisseur test or a spike entry below u |λ|, so the form is backward stable as the
//! double-shift one: Z T Z^T = A + E with ||E|| = O(u ||A||).
//!
//! References: K. Braman, R. Byers, R. Mathias, The multishift QR algorithm. Part I:
//! Maintaining well-focused shifts and level 3 performance; Part II: Aggressive early
//! deflation. SIAM J. Matrix Anal. Appl. 23 (2002) 929-947 and 948-973.

use crate::error::Error;
use crate::linalg::hessenberg::hessenberg;
use crate::linalg::householder::reflector;
use crate::linalg::matrix::{FaerView, Square};
use crate::linalg::schur::form::{block_eigenvalues, quasi_triangular_eigenvalues};
use crate::linalg::schur::francis::{
    Spectrum, double_shift, francis_qr, negligible_subdiagonal, shift_polynomial_column,
};
use crate::linalg::schur::reorder::swap_blocks;
use crate::platform::dispatch::{clear_upper_avx_state, fma_dispatch, multiply_add};
use crate::platform::interrupt;
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par, c64};
use std::ops::Range;

/// From this order on the QR iteration is the small-bulge multishift iteration with aggressive
/// early deflation ([`crate::linalg::schur::multishift`]); below it, and on the active blocks below it that the
/// multishift iteration leaves, the double-shift iteration of this module, whose set-up is
/// nothing. LAPACK's crossover is 75 (its NMIN); measured here, see the module docs.
pub(crate) const MULTISHIFT_MIN_ORDER: usize = 75;

/// The QR iteration of an upper Hessenberg `h`, in place: the double-shift iteration below
/// [`MULTISHIFT_MIN_ORDER`], the small-bulge multishift iteration ([`crate::linalg::schur::multishift`]) from
/// there.
///
/// With `full` the whole of `h` is transformed into the Schur form T (and `z`, if given, is
/// multiplied on the right by the orthogonal transformations); without it only the diagonal
/// blocks are formed, which suffices for the eigenvalues. The known shifts of a Hamiltonian
/// `spectrum` serve the double-shift iteration only.
pub(crate) fn schur_of_hessenberg(
    h: &mut Square,
    z: Option<&mut Square>,
    full: bool,
    spectrum: Spectrum,
) -> Result<(), Error> {
    if h.nrows() < MULTISHIFT_MIN_ORDER {
        francis_qr(h, z, (0, h.nrows().saturating_sub(1)), full, spectrum)
    } else {
        multishift_qr(h, z, full)
    }
}

/// The iteration limit is this many iterations (deflation passes, each with at most one sweep)
/// per row, as in the double-shift iteration and LAPACK.
const ITERATIONS_PER_ORDER: usize = 30;

/// Every this many iterations without a deflation, the sweep uses exceptional shifts.
const EXCEPTIONAL_SHIFT_INTERVAL: usize = 6;

/// After this many iterations without a deflation, the deflation window doubles.
const WIDEN_WINDOW_AFTER: usize = 5;

/// A deflation pass that deflated more than this percentage of its window is followed by
/// another pass instead of a sweep: the next pass is likely to deflate as much for a fraction
/// of a sweep's cost (LAPACK's "nibble" crossover, 14 %).
const NIBBLE_PERCENT: usize = 14;

/// The smallest active block the multishift iteration takes on after the double-shift iteration
/// failed on a block of order below [`MULTISHIFT_MIN_ORDER`]: any block with room for a
/// deflation window below a row and for one bulge. (On skew-symmetric matrices of orders 90 to
/// 200 the double-shift iteration can stall on a block of order 4 whose two pairs ±iω are
/// coupled by a subdiagonal entry of 1e-162 that the Ahues-Tisseur test, with the block's zero
/// diagonal, will not neglect; a sweep that starts its bulge at the top of the block does
/// deflate it.)
const FALLBACK_MIN_ORDER: usize = 3;

/// Rows between consecutive bulges of a chain: a bulge's reflector spans three rows, and with
/// this spacing the reflectors of one step touch disjoint rows and columns.
const BULGE_SPACING: usize = 3;

/// The number of shifts of a sweep on an active block of the given order (even): about
/// order / log2(order), between 10 and 64 (the values of LAPACK's iparmq, which balance the
/// sweep's level-3 efficiency against the convergence lost to a long chain).
fn shift_count(order: usize) -> usize {
    let count = if order < 150 {
        10
    } else if order < 590 {
        let log2 = (order as f64).log2().round() as usize;
        (order / log2).max(10)
    } else {
        64
    };
    count - count % 2
}

/// The Schur form of the upper Hessenberg `h` (of order at least 3), in place, with `z`
/// multiplied on the right by the transformations; `full` as in [`schur_of_hessenberg`].
pub(crate) fn multishift_qr(
    h: &mut Square,
    mut z: Option<&mut Square>,
    full: bool,
) -> Result<(), Error> {
    let n = h.nrows();
    let small = f64::MIN_POSITIVE * (n as f64 / f64::EPSILON);
    let nominal_shifts = shift_count(n);
    // The deflation window has as many rows as the sweep has shifts. (LAPACK's iparmq makes it
    // half as large again above order 500; here the window's own Schur form then costs more
    // than the deflations it adds: see the bench "schur" in benches/riccati.rs.)
    let nominal_window = nominal_shifts;
    // Rows end.. have converged; `stalls` counts the iterations since the last deflation.
    let mut end = n;
    let mut stalls = 0;
    // Blocks of this order and more stay with the multishift iteration; lowered for good should
    // the double-shift iteration fail on a block.
    let mut multishift_floor = MULTISHIFT_MIN_ORDER;
    for _ in 0..ITERATIONS_PER_ORDER * n.max(10) {
        if end == 0 {
            return Ok(());
        }
        interrupt::check()?;
        let kbot = end - 1;
        // The active block ktop..=kbot: below the lowest negligible subdiagonal entry.
        let mut ktop = kbot;
        while ktop > 0 && !negligible_subdiagonal(h, ktop, (0, kbot), small) {
            ktop -= 1;
        }
        if ktop > 0 {
            h[(ktop, ktop - 1)] = 0.0;
        }
        let order = kbot + 1 - ktop;
        if order < multishift_floor {
            match finish_small_block(h, z.as_deref_mut(), full, (ktop, kbot)) {
                Ok(()) => {
                    end = ktop;
                    stalls = 0;
                }
                // The double-shift iteration stagnated (as it can on skew-symmetric
                // matrices, whose eigenvalues come in pairs ±iω): continue on this block with
                // aggressive early deflation and sweeps, which see a wider set of shifts.
                Err(_) if multishift_floor > FALLBACK_MIN_ORDER => {
                    multishift_floor = FALLBACK_MIN_ORDER;
                }
                Err(error) => return Err(error),
            }
            continue;
        }

        // Aggressive early deflation on a window that leaves a row of the block above it,
        // one row larger where that puts its top at the smaller of two subdiagonal entries.
        let widened = if stalls >= WIDEN_WINDOW_AFTER { 2 } else { 1 };
        let mut window = (widened * nominal_window).min(order - 1);
        let top = kbot + 1 - window;
        if window + 1 < order && h[(top, top - 1)].abs() > h[(top - 1, top - 2)].abs() {
            window += 1;
        }
        let deflation =
            aggressive_early_deflation(h, z.as_deref_mut(), full, (ktop, kbot), window)?;
        end -= deflation.deflated;
        if deflation.deflated > 0 {
            stalls = 0;
        } else {
            stalls += 1;
        }
        let remaining = end - ktop;
        let nibbled = 100 * deflation.deflated > NIBBLE_PERCENT * window;
        if (deflation.deflated > 0 && nibbled) || remaining < multishift_floor {
            continue;
        }

        // A sweep over the active block with the smallest undeflated eigenvalues as shifts.
        let kbot = end - 1;
        let count = nominal_shifts.min(remaining - 1);
        let count = count - count % 2;
        let shifts = if stalls > 0 && stalls % EXCEPTIONAL_SHIFT_INTERVAL == 0 {
            exceptional_shifts(h, (ktop, kbot), count)
        } else if deflation.shifts.len() > count / 2 {
            select_shifts(&deflation.shifts, count, h[(kbot, kbot)])
        } else {
            select_shifts(
                &trailing_eigenvalues(h, kbot, count),
                count,
                h[(kbot, kbot)],
            )
        };
        let shifts = if shifts.is_empty() {
            // Too few candidates (a lone real one): the shifts of the trailing 2 x 2 block.
            vec![trailing_double_shift(h, kbot)]
        } else {
            shifts
        };
        small_bulge_sweep(h, z.as_deref_mut(), full, (ktop, kbot), &shifts);
    }
    Err(Error::NoConvergence {
        algorithm: "the multishift QR iteration",
    })
}

/// The Schur form of the active block ktop..=kbot, of order below [`MULTISHIFT_MIN_ORDER`], by
/// the double-shift iteration. With `full`, on a copy of the block with its own transformation
/// V, which then updates the rest of H and Z by matrix products ([`apply_outside_window`]):
/// the double-shift iteration would otherwise apply each reflector to whole rows of H and Z,
/// and finishing the last blocks of order 512 that way took a quarter of the time.
fn finish_small_block(
    h: &mut Square,
    z: Option<&mut Square>,
    full: bool,
    (ktop, kbot): (usize, usize),
) -> Result<(), Error> {
    let n = h.nrows();
    let order = kbot + 1 - ktop;
    if !full || order == n {
        return francis_qr(h, z, (ktop, kbot), full, Spectrum::General);
    }
    let mut block = hessenberg_block(h, ktop, order);
    let mut v = nalgebra::DMatrix::<f64>::identity(order, order);
    francis_qr(
        &mut block,
        Some(&mut v),
        (0, order - 1),
        true,
        Spectrum::General,
    )?;
    for c in 0..order {
        for r in 0..order {
            h[(ktop + r, ktop + c)] = block[(r, c)];
        }
    }
    let v = MatRef::from_column_major_slice(v.as_slice(), order, order);
    apply_outside_window(h, z, (0, n - 1), (ktop, kbot), v, &mut Vec::new());
    clear_upper_avx_state();
    Ok(())
}

/// A copy of the diagonal block of `h` of the given order from row and column `top`, with the
/// entries below its subdiagonal zero.
fn hessenberg_block(h: &Square, top: usize, order: usize) -> Square {
    let mut block = nalgebra::DMatrix::<f64>::identity(order, order);
    for c in 0..order {
        block[(c, c)] = 0.0;
        for r in 0..=(c + 1).min(order - 1) {
            block[(r, c)] = h[(top + r, top + c)];
        }
    }
    block
}

/// What a pass of aggressive early deflation found: how many eigenvalues at the bottom of the
/// window converged, and the eigenvalues of the rest of the window (pairs adjacent, Im > 0
/// first), the shifts of the next sweep.
struct EarlyDeflation {
    deflated: usize,
    shifts: Vec<c64>,
}

/// Aggressive early deflation on the bottom `window` rows of the active block ktop..=kbot of
/// `h` (window <= kbot - ktop, so the spike h[top, top-1] is inside the block).
///
/// The window W is reduced to Schur form S = V^T W V. The spike column h[top.., top-1] becomes
/// s = h[top, top-1] V[0, :]^T; from the bottom, each diagonal block of S whose spike entries are
/// at most max(small, u |λ|) deflates (its spike entries are set to zero, a backward error of
/// that size), and each other block is moved by Schur swaps to the top of the part not yet
/// judged. A refused swap (nearly equal eigenvalues) ends the scan. Then a reflector P with
/// P s_u = β e1 folds the spike of the undeflated part into one entry, P S_uu P (and the
/// columns to its right) is reduced back to Hessenberg form, and V, updated alike, is applied
/// to the rows above the window, the columns to its right and Z.
fn aggressive_early_deflation(
    h: &mut Square,
    z: Option<&mut Square>,
    full: bool,
    (ktop, kbot): (usize, usize),
    window: usize,
) -> Result<EarlyDeflation, Error> {
    let n = h.nrows();
    let top = kbot + 1 - window;
    debug_assert!(
        top > ktop,
        "a row of the block stays above the deflation window"
    );
    let spike = h[(top, top - 1)];
    let mut t = hessenberg_block(h, top, window);
    let mut v = nalgebra::DMatrix::<f64>::identity(window, window);
    if schur_of_hessenberg(&mut t, Some(&mut v), true, Spectrum::General).is_err() {
        // The window's iteration failed: no deflation this time (H is untouched), and the
        // shifts come from elsewhere.
        return Ok(EarlyDeflation {
            deflated: 0,
            shifts: Vec::new(),
        });
    }
    let (mut t, mut v) = (t.to_faer(), v.to_faer());
    clear_upper_avx_state();

    // The scan from the bottom: t[..unjudged] is not yet judged, and of it t[..undeflated]
    // holds the blocks judged not deflatable.
    let ulp = f64::EPSILON;
    let small = f64::MIN_POSITIVE * (n as f64 / ulp);
    let (mut unjudged, mut undeflated) = (window, 0);
    while undeflated < unjudged {
        let size = if unjudged >= 2 && t[(unjudged - 1, unjudged - 2)] != 0.0 {
            2
        } else {
            1
        };
        let k = unjudged - size;
        let mut magnitude = if size == 1 {
            t[(k, k)].abs()
        } else {
            t[(k + 1, k + 1)].abs() + t[(k + 1, k)].abs().sqrt() * t[(k, k + 1)].abs().sqrt()
        };
        if magnitude == 0.0 {
            magnitude = spike.abs();
        }
        let coupling = (k..unjudged).fold(0.0f64, |m, c| m.max((spike * v[(0, c)]).abs()));
        if coupling <= small.max(ulp * magnitude) {
            unjudged = k;
            continue;
        }
        // Not converged: move the block up to the top of the unjudged part.
        let mut current = k;
        while current > undeflated {
            let above = if current >= undeflated + 2 && t[(current - 1, current - 2)] != 0.0 {
                2
            } else {
                1
            };
            let previous = current - above;
            if swap_blocks(&mut t, &mut v, previous, above, size).is_err() {
                break;
            }
            current = previous;
        }
        if current > undeflated {
            // A refused swap: leave the rest of the window undeflated.
            break;
        }
        undeflated += size;
    }
    let kept = unjudged;
    let deflated = window - kept;
    let shifts = quasi_triangular_eigenvalues(t.as_ref().submatrix(0, 0, kept, kept));
    if deflated == 0 {
        return Ok(EarlyDeflation { deflated, shifts });
    }

    // The spike of the undeflated part, s = spike V[0, ..kept], folded into its first entry.
    let mut coupling_entry = 0.0;
    if kept > 0 {
        let mut s: Vec<f64> = (0..kept).map(|c| spike * v[(0, c)]).collect();
        let (beta, tau) = reflector(&mut s);
        coupling_entry = beta;
        if tau != 0.0 {
            s[0] = 1.0;
            // T <- P T on the leading rows, then T <- T P and V <- V P on the leading columns.
            for c in 0..window {
                let dot: f64 = (0..kept).map(|r| s[r] * t[(r, c)]).sum();
                for r in 0..kept {
                    t[(r, c)] -= tau * dot * s[r];
                }
            }
            for r in 0..kept {
                let dot: f64 = (0..kept).map(|c| t[(r, c)] * s[c]).sum();
                for c in 0..kept {
                    t[(r, c)] -= tau * dot * s[c];
                }
            }
            for r in 0..window {
                let dot: f64 = (0..kept).map(|c| v[(r, c)] * s[c]).sum();
                for c in 0..kept {
                    v[(r, c)] -= tau * dot * s[c];
                }
            }
        }
        if kept > 2 {
            let reduced = hessenberg(t.as_ref().submatrix(0, 0, kept, kept))?;
            let right = reduced.q.transpose() * t.as_ref().submatrix(0, kept, kept, window - kept);
            t.as_mut()
                .submatrix_mut(0, 0, kept, kept)
                .copy_from(&reduced.h);
            t.as_mut()
                .submatrix_mut(0, kept, kept, window - kept)
                .copy_from(&right);
            let columns = v.as_ref().submatrix(0, 0, window, kept) * &reduced.q;
            v.as_mut()
                .submatrix_mut(0, 0, window, kept)
                .copy_from(&columns);
        }
    }

    // Back into H: the window, the coupling entry, and V applied to the rest.
    h[(top, top - 1)] = coupling_entry;
    for c in 0..window {
        for r in 0..window {
            h[(top + r, top + c)] = t[(r, c)];
        }
    }
    let outside = if full { (0, n - 1) } else { (ktop, kbot) };
    let mut scratch = Vec::new();
    apply_outside_window(h, z, outside, (top, kbot), v.as_ref(), &mut scratch);
    clear_upper_avx_state();
    Ok(EarlyDeflation { deflated, shifts })
}

/// Completes an orthogonal similarity U^T H U whose U acts on rows and columns w0..=w1 and
/// which has already been applied to the window H[w0..=w1, w0..=w1] itself: the rows
/// first..w0 above the window become H U, the columns w1+1..=last to its right U^T H, and the
/// columns w0..=w1 of Z become Z U. (H is zero left of and below the window, outside the
/// active block, so nothing else changes.)
fn apply_outside_window(
    h: &mut Square,
    z: Option<&mut Square>,
    (first, last): (usize, usize),
    (w0, w1): (usize, usize),
    u: MatRef<'_, f64>,
    scratch: &mut Vec<f64>,
) {
    let n = h.nrows();
    let w = w1 + 1 - w0;
    let mut full_h = MatMut::from_column_major_slice_mut(h.as_mut_slice(), n, n);
    if w0 > first {
        multiply_on_the_right(
            full_h.as_mut().submatrix_mut(first, w0, w0 - first, w),
            u,
            scratch,
        );
    }
    if last > w1 {
        let block = full_h.as_mut().submatrix_mut(w0, w1 + 1, w, last - w1);
        let copy = copy_to_scratch(block.as_ref(), scratch);
        matmul(block, Accum::Replace, u.transpose(), copy, 1.0, Par::Seq);
    }
    if let Some(z) = z {
        let rows = z.nrows();
        let mut full_z = MatMut::from_column_major_slice_mut(z.as_mut_slice(), rows, rows);
        multiply_on_the_right(full_z.as_mut().submatrix_mut(0, w0, rows, w), u, scratch);
    }
}

/// block <- block U, through a copy of the block in `scratch`.
fn multiply_on_the_right(block: MatMut<'_, f64>, u: MatRef<'_, f64>, scratch: &mut Vec<f64>) {
    let copy = copy_to_scratch(block.as_ref(), scratch);
    matmul(block, Accum::Replace, copy, u, 1.0, Par::Seq);
}

/// A column-major copy of `block` in `scratch`, written once (not zeroed first).
fn copy_to_scratch<'a>(block: MatRef<'_, f64>, scratch: &'a mut Vec<f64>) -> MatRef<'a, f64> {
    scratch.clear();
    for column in block.col_iter() {
        scratch.extend(column.iter().copied());
    }
    MatRef::from_column_major_slice(scratch, block.nrows(), block.ncols())
}

/// One small-bulge multishift QR sweep over the active block ktop..=kbot (at least 3 rows)
/// with one bulge per pair of shifts, the first pair's bulge introduced first.
///
/// Bulge m (0-based) is introduced at step 3m and at step t has its reflector on rows p..p+2,
/// p = ktop + t - 3m, while ktop <= p <= kbot - 1 (the last one, at kbot - 1, spans 2 rows).
/// The steps are grouped into slabs of 3 b steps (b bulges), the chain's own length, which
/// minimises the flops of the products: the reflectors of a slab are applied within the slab's
/// diagonal window ([`chase_slab`]) and accumulated into U, which then updates the rest of H
/// and Z by matrix products ([`apply_outside_window`]).
fn small_bulge_sweep(
    h: &mut Square,
    mut z: Option<&mut Square>,
    full: bool,
    (ktop, kbot): (usize, usize),
    shifts: &[(c64, c64)],
) {
    let n = h.nrows();
    if shifts.is_empty() || kbot < ktop + 2 {
        return;
    }
    let outside = if full { (0, n - 1) } else { (ktop, kbot) };
    let chain = Chain { ktop, kbot, shifts };
    let slab_steps = BULGE_SPACING * shifts.len();
    let mut scratch = Vec::new();
    let mut reflectors = Vec::with_capacity(shifts.len());
    let mut t0 = 0;
    while t0 <= chain.last_step() {
        let t1 = (t0 + slab_steps - 1).min(chain.last_step());
        // The slab's window: from the column left of the highest reflector (or ktop) to the
        // row below the lowest.
        let (mut p_top, mut p_bottom) = (usize::MAX, 0);
        for t in t0..=t1 {
            if let Some((lowest, highest)) = chain.active(t) {
                p_top = p_top.min(chain.position(t, highest));
                p_bottom = p_bottom.max(chain.position(t, lowest));
            }
        }
        let w0 = if p_top > ktop { p_top - 1 } else { ktop };
        let w1 = (p_bottom + 3).min(kbot);
        let w = w1 + 1 - w0;
        let mut u = nalgebra::DMatrix::<f64>::identity(w, w);
        chase_slab(h, &mut u, &chain, (t0, t1), (w0, w1), &mut reflectors);
        let u = MatRef::from_column_major_slice(u.as_slice(), w, w);
        apply_outside_window(h, z.as_deref_mut(), outside, (w0, w1), u, &mut scratch);
        t0 = t1 + 1;
    }
    clear_upper_avx_state();
}

/// A chain of bulges over the active block ktop..=kbot, one per pair of shifts.
struct Chain<'a> {
    ktop: usize,
    kbot: usize,
    shifts: &'a [(c64, c64)],
}

impl Chain<'_> {
    /// The last step of the sweep, when the highest bulge leaves the block.
    fn last_step(&self) -> usize {
        self.kbot - 1 - self.ktop + BULGE_SPACING * (self.shifts.len() - 1)
    }

    /// The top row of bulge m's reflector at step t (when it is active).
    fn position(&self, t: usize, m: usize) -> usize {
        self.ktop + t - BULGE_SPACING * m
    }

    /// The bulges active at step t, (lowest, highest): m in lowest..=highest, the lowest with
    /// the largest position.
    fn active(&self, t: usize) -> Option<(usize, usize)> {
        let highest = (t / BULGE_SPACING).min(self.shifts.len() - 1);
        let lowest = t
            .saturating_sub(self.kbot - 1 - self.ktop)
            .div_ceil(BULGE_SPACING);
        (lowest <= highest).then_some((lowest, highest))
    }
}

/// One reflector I - τ v v^T of a chase step, on rows p..p+len, with the first row of U it
/// can reach.
#[derive(Clone, Copy)]
struct StepReflector {
    p: usize,
    len: usize,
    v: [f64; 3],
    tau: f64,
    first_row_of_u: usize,
}

/// The steps t0..=t1 of a sweep, within the window w0..=w1 of H, accumulating the reflectors
/// into U (of the window's order, the identity on entry).
///
/// A step first computes the reflectors of all its bulges, from the bottom up: a bulge's
/// reflector comes from column p - 1 (at p = ktop, from its shifts), which the right
/// multiplication of the bulge above reaches. With the bulges three rows apart, the reflectors
/// of a step then act on disjoint rows and on disjoint columns, and commute: the left
/// multiplications go column by column through all the bulges (one pass over each column's
/// rows), the right multiplications reflector by reflector over the rows of the window above
/// and the rows of U. The columns of U that a bulge's reflector combines are nonzero only from
/// the row where that bulge entered the slab down to the lowest row any reflector of the slab
/// has reached so far (by induction: a reflector only mixes columns within its own reach), and
/// only those rows are updated.
///
/// Always inlined into the dispatch's wrappers: compiled on its own, without the wrapper's
/// target features, each fused multiply-add of the FMA variant would be a call of the
/// software fma.
#[inline(always)]
fn chase_slab_kernel<const FMA: bool>(
    h: &mut Square,
    u: &mut Square,
    chain: &Chain<'_>,
    (t0, t1): (usize, usize),
    (w0, w1): (usize, usize),
    reflectors: &mut Vec<StepReflector>,
) {
    let (ktop, kbot) = (chain.ktop, chain.kbot);
    let n = h.nrows();
    let w = u.nrows();
    // The rows of U below this one are still those of the identity.
    let mut u_rows_end = 0;
    for t in t0..=t1 {
        let Some((lowest, highest)) = chain.active(t) else {
            continue;
        };
        reflectors.clear();
        for (m, &pair) in chain
            .shifts
            .iter()
            .enumerate()
            .take(highest + 1)
            .skip(lowest)
        {
            let p = chain.position(t, m);
            let len = if p + 2 <= kbot { 3 } else { 2 };
            let mut v = if p == ktop {
                shift_polynomial_column(h, p, pair)
            } else if len == 3 {
                [h[(p, p - 1)], h[(p + 1, p - 1)], h[(p + 2, p - 1)]]
            } else {
                [h[(p, p - 1)], h[(p + 1, p - 1)], 0.0]
            };
            let (beta, tau) = reflector(&mut v[..len]);
            if p > ktop {
                h[(p, p - 1)] = beta;
                for r in 1..len {
                    h[(p + r, p - 1)] = 0.0;
                }
            }
            if tau != 0.0 {
                let first_step = t0.max(BULGE_SPACING * m);
                reflectors.push(StepReflector {
                    p,
                    len,
                    v: [1.0, v[1], if len == 3 { v[2] } else { 0.0 }],
                    tau,
                    first_row_of_u: chain.position(first_step, m) - w0,
                });
            }
        }
        let (Some(top), Some(bottom)) = (reflectors.last().copied(), reflectors.first().copied())
        else {
            continue;
        };
        // From the left, column by column: the reflectors with p <= j, the highest first.
        for j in top.p..=w1 {
            let column = &mut h.as_mut_slice()[j * n..(j + 1) * n];
            for r in reflectors.iter().rev().take_while(|r| r.p <= j) {
                reflect_entries::<FMA>(column, r);
            }
        }
        // From the right, on the rows of the window above each reflector and on U.
        u_rows_end = u_rows_end.max((bottom.p + 3 - w0).min(w));
        for r in reflectors.iter() {
            let rows = w0..(r.p + 3).min(kbot) + 1;
            reflect_columns::<FMA>(h.as_mut_slice(), n, r.p, r, rows);
            reflect_columns::<FMA>(
                u.as_mut_slice(),
                w,
                r.p - w0,
                r,
                r.first_row_of_u..u_rows_end,
            );
        }
    }
}

fma_dispatch!(
    /// [`chase_slab_kernel`], compiled for AVX2 and FMA where the CPU has them.
    fn chase_slab(h: &mut Square, u: &mut Square, chain: &Chain<'_>, steps: (usize, usize), window: (usize, usize), reflectors: &mut Vec<StepReflector>) => chase_slab_kernel
);

/// x[p..p+len] <- (I - τ v v^T) x[p..p+len] for one column x.
#[inline(always)]
fn reflect_entries<const FMA: bool>(column: &mut [f64], r: &StepReflector) {
    let p = r.p;
    let [_, v1, v2] = r.v;
    if r.len == 3 {
        let x = &mut column[p..p + 3];
        let sum = multiply_add::<FMA>(v2, x[2], multiply_add::<FMA>(v1, x[1], x[0]));
        let s = r.tau * sum;
        x[0] -= s;
        x[1] = multiply_add::<FMA>(-s, v1, x[1]);
        x[2] = multiply_add::<FMA>(-s, v2, x[2]);
    } else {
        let x = &mut column[p..p + 2];
        let s = r.tau * multiply_add::<FMA>(v1, x[1], x[0]);
        x[0] -= s;
        x[1] = multiply_add::<FMA>(-s, v1, x[1]);
    }
}

/// Columns c..c+len of the column-major matrix `data` (leading dimension `ld`), rows `rows`,
/// multiplied on the right by I - τ v v^T.
#[inline(always)]
fn reflect_columns<const FMA: bool>(
    data: &mut [f64],
    ld: usize,
    c: usize,
    r: &StepReflector,
    rows: Range<usize>,
) {
    let [_, v1, v2] = r.v;
    let tau = r.tau;
    let block = &mut data[c * ld..(c + r.len) * ld];
    let (x0, rest) = block.split_at_mut(ld);
    let (x1, x2) = rest.split_at_mut(ld);
    let (x0, x1) = (&mut x0[rows.clone()], &mut x1[rows.clone()]);
    if r.len == 3 {
        let x2 = &mut x2[rows];
        for ((a, b), c) in x0.iter_mut().zip(x1.iter_mut()).zip(x2.iter_mut()) {
            let sum = multiply_add::<FMA>(v2, *c, multiply_add::<FMA>(v1, *b, *a));
            let s = tau * sum;
            *a -= s;
            *b = multiply_add::<FMA>(-s, v1, *b);
            *c = multiply_add::<FMA>(-s, v2, *c);
        }
    } else {
        for (a, b) in x0.iter_mut().zip(x1.iter_mut()) {
            let s = tau * multiply_add::<FMA>(v1, *b, *a);
            *a -= s;
            *b = multiply_add::<FMA>(-s, v1, *b);
        }
    }
}

/// Shifts for a sweep of `count` (even) from `candidates` (conjugate pairs adjacent, Im > 0
/// first): those of smallest magnitude, complex ones as conjugate pairs and real ones paired,
/// ordered by decreasing magnitude (the first bulge introduced gets the largest). Two real
/// shifts alone are replaced by the one nearer the corner entry h[kbot, kbot], twice.
fn select_shifts(candidates: &[c64], count: usize, corner: f64) -> Vec<(c64, c64)> {
    // Each candidate as (eigenvalue, whether it stands for a conjugate pair).
    let mut units = Vec::with_capacity(candidates.len());
    let mut k = 0;
    while k < candidates.len() {
        let lambda = candidates[k];
        if lambda.im != 0.0 && k + 1 < candidates.len() {
            units.push((c64::new(lambda.re, lambda.im.abs()), true));
            k += 2;
        } else {
            units.push((c64::new(lambda.re, 0.0), false));
            k += 1;
        }
    }
    units.sort_by(|x, y| x.0.norm().total_cmp(&y.0.norm()));
    let mut taken = 0;
    let mut pairs = Vec::new();
    let mut reals = Vec::new();
    for &(lambda, pair) in &units {
        if pair && taken + 2 <= count {
            pairs.push((lambda, lambda.conj()));
            taken += 2;
        } else if !pair && taken < count {
            reals.push(lambda);
            taken += 1;
        }
    }
    // An odd number of real shifts: drop the largest.
    if reals.len() % 2 == 1 {
        reals.pop();
    }
    if pairs.is_empty() && reals.len() == 2 {
        let nearer = if (reals[0].re - corner).abs() <= (reals[1].re - corner).abs() {
            reals[0]
        } else {
            reals[1]
        };
        return vec![(nearer, nearer)];
    }
    pairs.extend(reals.chunks_exact(2).map(|two| (two[1], two[0])));
    pairs.sort_by(|x, y| y.0.norm().total_cmp(&x.0.norm()));
    pairs
}

/// Exceptional shifts for a sweep of `count` (even) after iterations without a deflation:
/// for each pair, a conjugate pair built from the size of two subdiagonal entries near the
/// bottom (Wilkinson's ad hoc 3/4 s and -0.4375 s, as in the double-shift iteration), which
/// breaks the rare cycles of the ordinary shifts.
fn exceptional_shifts(h: &Square, (ktop, kbot): (usize, usize), count: usize) -> Vec<(c64, c64)> {
    (0..count / 2)
        .map(|j| 2 * j)
        .take_while(|&offset| kbot >= ktop + 2 + offset)
        .map(|offset| {
            let i = kbot - offset;
            let s = h[(i, i - 1)].abs() + h[(i - 1, i - 2)].abs();
            let d = 0.75 * s + h[(i, i)];
            double_shift(d, -0.4375 * s, s, d)
        })
        .collect()
}

/// The eigenvalues of the trailing `count` x `count` block of the Hessenberg `h` ending at row
/// kbot (pairs adjacent, Im > 0 first): shifts when a deflation pass left too few. Should
/// their iteration fail, the eigenvalues of the trailing 2 x 2 block.
fn trailing_eigenvalues(h: &Square, kbot: usize, count: usize) -> Vec<c64> {
    let mut block = hessenberg_block(h, kbot + 1 - count, count);
    match schur_of_hessenberg(&mut block, None, false, Spectrum::General) {
        Ok(()) => block_eigenvalues(count, |i, j| block[(i, j)]),
        Err(_) => {
            let (s1, s2) = trailing_double_shift(h, kbot);
            vec![s1, s2]
        }
    }
}

/// The shifts of the double-shift iteration: those of the trailing 2 x 2 block.
fn trailing_double_shift(h: &Square, kbot: usize) -> (c64, c64) {
    double_shift(
        h[(kbot - 1, kbot - 1)],
        h[(kbot - 1, kbot)],
        h[(kbot, kbot - 1)],
        h[(kbot, kbot)],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifts_are_the_smallest_in_pairs() {
        let candidates = [
            c64::new(-1.0, 2.0),
            c64::new(-1.0, -2.0),
            c64::new(-3.0, 0.0),
            c64::new(-4.0, 0.0),
            c64::new(-5.0, 0.0),
            c64::new(0.5, 0.0),
        ];
        // The four smallest: 0.5, the pair of modulus 2.24, -3; two reals pair up.
        let shifts = select_shifts(&candidates, 4, 0.0);
        assert_eq!(
            shifts,
            vec![
                (c64::new(-3.0, 0.0), c64::new(0.5, 0.0)),
                (c64::new(-1.0, 2.0), c64::new(-1.0, -2.0)),
            ]
        );
        // Two real shifts: the one nearer the corner, twice.
        let reals = [c64::new(1.0, 0.0), c64::new(3.0, 0.0)];
        assert_eq!(
            select_shifts(&reals, 2, 2.9),
            vec![(c64::new(3.0, 0.0), c64::new(3.0, 0.0))]
        );
        assert!(select_shifts(&[], 4, 0.0).is_empty());
    }
}
