//! Diagonal similarities that scale a matrix before its eigenvalues are computed: a power of
//! two that brings its entries into range, and balancing (Parlett & Reinsch 1969), a diagonal
//! of powers of two that equalises row and column norms. Both are exact in floating point.

use crate::linalg::matrix::{Order, Square};
use crate::linalg::norm::{max_abs, vector_norm};
use crate::platform::dispatch::clear_upper_avx_state;
use faer::MatRef;

/// Entries of the largest magnitude outside [`SMALL_ENTRY`], 1 / [`SMALL_ENTRY`] are brought
/// to 1 first (as LAPACK's dgees scales): the deflation tests compare entries with the
/// smallest normal number and the eigensolvers square entries and multiply pairs of them, so
/// a matrix whose entries are all below about 1e-146 (where a product of two entries, times
/// 1 / u, is no longer a normal number) would count as negligible in places and come back
/// with wrong eigenvalues or eigenvectors, and one whose squares overflow would overflow in
/// the shifts. 2^-100 leaves a margin of 2^100 on both sides for the n-term sums of products.
const SMALL_ENTRY: f64 = 7.888_609_052_210_118e-31; // 2^-100

/// The power of two by which `a` is divided before its Schur form, 1 when its largest entry
/// is in range (the scaling is exact, and A = Z (s T) Z^T with the same Z).
pub(crate) fn range_scale(a: MatRef<'_, f64>) -> f64 {
    scale_for_largest(max_abs(a))
}

/// The power of two of [`range_scale`] for a matrix whose largest magnitude is `largest`.
pub(crate) fn scale_for_largest(largest: f64) -> f64 {
    if largest > 0.0 && !(SMALL_ENTRY..=1.0 / SMALL_ENTRY).contains(&largest) {
        // 2^±1000 at most: 2^-1074 (the smallest subnormal) would be 1 / 2^1074 = 1 / inf = 0,
        // and a division by it NaN everywhere; 2^1000 brings any entry into range.
        2f64.powi((largest.log2().round() as i32).clamp(-1000, 1000))
    } else {
        1.0
    }
}

/// The power of two nearest to x > 0 (1 for 0 or a non-finite x): an exact scale factor.
pub(crate) fn nearest_power_of_two(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        2f64.powi(x.log2().round() as i32)
    } else {
        1.0
    }
}

/// x 2^e for an integer e of any size, in two exact steps where one power would leave the range
/// of doubles.
pub(crate) fn times_power_of_two(x: f64, exponent: f64) -> f64 {
    let half = (exponent / 2.0).trunc();
    x * half.exp2() * (exponent - half).exp2()
}

/// Balances the states of a single-input, single-output system (A, b, c) in place by a diagonal
/// similarity of powers of two, (T A T^-1, T b, c T^-1), which changes no transfer function:
/// Osborne's iteration on the system matrix [[A, b], [c, 0]] over the state indices (the row i
/// of [A b] and the column i of [A; c], without the diagonal, brought within a factor of 2 of
/// each other), while a scaling reduces the sum of the two norms by 5 % or more. The norms are
/// formed without overflow ([`vector_norm`]); a row or column that is zero is left alone.
pub(crate) fn balance_siso_states(a: &mut faer::Mat<f64>, b: &mut [f64], c: &mut [f64]) {
    let n = a.nrows();
    for _ in 0..100 {
        let mut changed = false;
        for i in 0..n {
            let row = vector_norm((0..n).filter(|&k| k != i).map(|k| a[(i, k)]).chain([b[i]]));
            let col = vector_norm((0..n).filter(|&k| k != i).map(|k| a[(k, i)]).chain([c[i]]));
            if row == 0.0 || col == 0.0 || !(row + col).is_finite() {
                continue;
            }
            // T_ii = 2^k with 2^k row ≈ 2^-k col: k = round(log2(col / row) / 2), at most 2^±500.
            let k = ((col.log2() - row.log2()) / 2.0)
                .round()
                .clamp(-500.0, 500.0);
            if k == 0.0 {
                continue;
            }
            let f = k.exp2();
            if row * f + col / f >= 0.95 * (row + col) {
                continue;
            }
            changed = true;
            let f_inverse = 1.0 / f;
            for j in (0..n).filter(|&j| j != i) {
                a[(i, j)] *= f;
                a[(j, i)] *= f_inverse;
            }
            b[i] *= f;
            c[i] *= f_inverse;
        }
        if !changed {
            break;
        }
    }
}

/// Balances A in place by a diagonal similarity D^-1 A D with powers of two (no permutations):
/// row and column i are scaled until their off-diagonal 2-norms are within a factor of two, and
/// the sweep repeats while a scaling reduces the sum of the two norms by 5 % or more. Returns
/// the diagonal of D.
pub(crate) fn balance<O: Order>(a: &mut Square<O>) -> Vec<f64> {
    clear_upper_avx_state();
    let n = a.nrows();
    let mut scale = vec![1.0; n];
    let mut changed = true;
    let mut sweeps = 0;
    while changed && sweeps < 100 {
        changed = false;
        sweeps += 1;
        for i in 0..n {
            let (mut column_squares, mut row_squares) = (0.0, 0.0);
            for k in 0..n {
                if k != i {
                    column_squares += a[(k, i)] * a[(k, i)];
                    row_squares += a[(i, k)] * a[(i, k)];
                }
            }
            if column_squares == 0.0
                || row_squares == 0.0
                || !(column_squares + row_squares).is_finite()
            {
                continue;
            }
            // The scaling by powers of two works on the squared norms (exactly, by fours).
            let (mut c, mut r, mut f) = (column_squares, row_squares, 1.0f64);
            while c < r / 4.0 && f < 2f64.powi(500) {
                (c, r, f) = (c * 4.0, r / 4.0, f * 2.0);
            }
            while c >= r * 4.0 && f > 2f64.powi(-500) {
                (c, r, f) = (c / 4.0, r * 4.0, f / 2.0);
            }
            if f != 1.0 && c.sqrt() + r.sqrt() < 0.95 * (column_squares.sqrt() + row_squares.sqrt())
            {
                changed = true;
                scale[i] *= f;
                // f is a power of two: multiplying by 1 / f rounds as dividing by f.
                let f_inverse = 1.0 / f;
                for k in 0..n {
                    a[(i, k)] *= f_inverse;
                    a[(k, i)] *= f;
                }
            }
        }
    }
    scale
}
