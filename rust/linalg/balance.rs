//! Diagonal similarities that scale a matrix before its eigenvalues are computed: a power of
//! two that brings its entries into range, and balancing (Parlett & Reinsch 1969), a diagonal
//! of powers of two that equalises row and column norms. Both are exact in floating point.

use crate::linalg::matrix::{Order, Square};
use crate::linalg::norm::{max_abs, vector_norm};
use crate::platform::dispatch::clear_upper_avx_state;
use faer::{Mat, MatRef};

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

/// The states of the system (A, B, C) (A n x n, B n x m, C p x n) balanced by a diagonal
/// similarity of powers of two, (T A T^-1, T B, C T^-1), which changes no transfer matrix:
/// Osborne's iteration on the system matrix [[A, B], [C, 0]] over the state indices (the row i
/// of [A B] and the column i of [A; C], without the diagonal, brought within a factor of 2 of
/// each other), while a scaling reduces the sum of the two norms by 5 % or more. The norms are
/// formed without overflow ([`vector_norm`]); a state whose row or column is zero is left
/// alone. None when the scaling is not exact: a nonzero entry would leave the normal doubles
/// (an A of 1e-300 beside B of 0.1 and C of 1e-151 is balanced by 2^±250, and an entry of
/// 1.3e-301 would underflow).
pub(crate) fn balanced_states(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> Option<(Mat<f64>, Mat<f64>, Mat<f64>)> {
    balanced_states_with_scaling(a, b, c).map(|(a, b, c, _)| (a, b, c))
}

/// (T A T^-1, T B, C T^-1) and the diagonal of T.
pub(crate) type ScaledStates = (Mat<f64>, Mat<f64>, Mat<f64>, Vec<f64>);

/// [`balanced_states`] with the diagonal of T.
pub(crate) fn balanced_states_with_scaling(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> Option<ScaledStates> {
    let n = a.nrows();
    let (mut a2, mut b2, mut c2) = (a.to_owned(), b.to_owned(), c.to_owned());
    let mut scaling = vec![1.0; n];
    for _ in 0..100 {
        let mut changed = false;
        for i in 0..n {
            let row = vector_norm(
                (0..n)
                    .filter(|&k| k != i)
                    .map(|k| a2[(i, k)])
                    .chain((0..b2.ncols()).map(|k| b2[(i, k)])),
            );
            let col = vector_norm(
                (0..n)
                    .filter(|&k| k != i)
                    .map(|k| a2[(k, i)])
                    .chain((0..c2.nrows()).map(|k| c2[(k, i)])),
            );
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
            scaling[i] *= f;
            let f_inverse = 1.0 / f;
            for j in (0..n).filter(|&j| j != i) {
                a2[(i, j)] *= f;
                a2[(j, i)] *= f_inverse;
            }
            for j in 0..b2.ncols() {
                b2[(i, j)] *= f;
            }
            for j in 0..c2.nrows() {
                c2[(j, i)] *= f_inverse;
            }
        }
        if !changed {
            break;
        }
    }
    let exact = |before: MatRef<'_, f64>, after: &Mat<f64>| {
        (0..before.ncols()).all(|j| {
            (0..before.nrows()).all(|i| {
                let (x, y) = (before[(i, j)], after[(i, j)]);
                x == 0.0 || (y.is_finite() && y.abs() >= f64::MIN_POSITIVE) || !x.is_finite()
            })
        })
    };
    (exact(a, &a2) && exact(b, &b2) && exact(c, &c2)).then_some((a2, b2, c2, scaling))
}

/// Whether some state of A is scaled apart from the others: its row's and its column's
/// largest off-diagonal magnitudes (both nonzero) more than 2^10 apart. A diagonal similarity
/// T A T^-1 multiplies state i's row by t_i and divides its column by it, so states measured in
/// units 10^3 or more apart fail the test, while a matrix of one scale whose entries spread
/// over decades (a random one) passes it. The test costs one pass over A, where the balancing
/// costs several.
pub(crate) fn states_scaled_apart(a: MatRef<'_, f64>) -> bool {
    const SPREAD: f64 = 1024.0;
    let n = a.nrows();
    (0..n).any(|i| {
        let (mut row, mut column) = (0.0f64, 0.0f64);
        for k in (0..n).filter(|&k| k != i) {
            row = row.max(a[(i, k)].abs());
            column = column.max(a[(k, i)].abs());
        }
        let (low, high) = (row.min(column), row.max(column));
        low > 0.0 && high > SPREAD * low
    })
}

/// [`balanced_states`], or the system as given where that scaling is not exact.
fn balanced_or_given(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
    balanced_states(a, b, c).unwrap_or_else(|| (a.to_owned(), b.to_owned(), c.to_owned()))
}

/// The largest |entry| of M (0 for an empty M).
fn largest_magnitude(m: &Mat<f64>) -> f64 {
    max_abs(m.as_ref())
}

/// The exponent e with 2^e max|M| nearest `target` (e = round(log2 target - log2 max|M|), ties
/// to even); 0 where M or the target is 0, or where 2^e M would have a nonzero entry outside
/// 2^±1000 (the scaling must be exact both ways).
fn normalising_exponent(m: &Mat<f64>, target: f64) -> i64 {
    let magnitudes = (0..m.ncols())
        .flat_map(|j| (0..m.nrows()).map(move |i| (i, j)))
        .map(|(i, j)| m[(i, j)].abs())
        .filter(|x| *x != 0.0);
    let (smallest, largest) =
        magnitudes.fold((f64::INFINITY, 0.0f64), |(s, l), x| (s.min(x), l.max(x)));
    if target.is_nan() || target <= 0.0 || largest == 0.0 {
        return 0;
    }
    let (largest, smallest) = (largest.log2(), smallest.log2());
    let e = (target.log2() - largest).round_ties_even();
    if -1000.0 < smallest + e && largest + e < 1000.0 {
        e as i64
    } else {
        0
    }
}

/// M 2^e, exactly (every nonzero entry of the result is a normal double).
fn scaled(m: &Mat<f64>, e: i64) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| {
        times_power_of_two(m[(i, j)], e as f64)
    })
}

/// The states of a loop (A, B, C) balanced for the closed loops A - g B C
/// (`aerocontrol.loops`'s root locus and margins): [`balanced_states`] once, then again with B
/// and C each multiplied by the power of two 2^p, 2^q that brings its largest entry nearest
/// the size of A balanced alone (max|D^-1 A D| with [`balanced_states`] of A without inputs and
/// outputs; sqrt(max|B|) sqrt(max|C|) where that is 0), that scaling then undone on B and C:
///
/// ```text
///     (T A T^-1, 2^-p T (2^p B), (C 2^q) T^-1 2^-q),
/// ```
///
/// the same A - g B C for every g (exact: powers of two). The split of the loop's gain between
/// B and C does not change A - g B C, but it steers the balancing: A and C of 1e-60 beside B of
/// 1 balanced to a QR that lost 2% of the poles. The size is that of A balanced alone, the
/// scale of its eigenvalues, not of A balanced with B and C: at 1e-100, B had steered that one
/// to entries of 1e-75 beside eigenvalues of 1e-100, and B and C brought to 1e-75 steered the
/// second balancing as much (poles 6e-5 off). The loop as given where it has no states or an
/// entry is not finite; each balancing as given where its scaling would not be exact.
pub(crate) fn balanced_loop(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> (Mat<f64>, Mat<f64>, Mat<f64>) {
    let finite =
        |m: MatRef<'_, f64>| (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)].is_finite()));
    let n = a.nrows();
    if n == 0 || !(finite(a) && finite(b) && finite(c)) {
        return (a.to_owned(), b.to_owned(), c.to_owned());
    }
    let (a1, b1, c1) = balanced_or_given(a, b, c);
    let alone = balanced_or_given(
        a1.as_ref(),
        Mat::zeros(n, 0).as_ref(),
        Mat::zeros(0, n).as_ref(),
    )
    .0;
    let mut size = largest_magnitude(&alone);
    if size == 0.0 {
        size = largest_magnitude(&b1).sqrt() * largest_magnitude(&c1).sqrt();
    }
    let (p, q) = (
        normalising_exponent(&b1, size),
        normalising_exponent(&c1, size),
    );
    if p == 0 && q == 0 {
        return (a1, b1, c1);
    }
    let (a2, b2, c2) = balanced_or_given(
        a1.as_ref(),
        scaled(&b1, p).as_ref(),
        scaled(&c1, q).as_ref(),
    );
    (a2, scaled(&b2, -p), scaled(&c2, -q))
}

/// [`balanced_states_with_scaling`] of (A, B, C) (A square, B with n rows, C with n
/// columns) where A's states are scaled apart ([`states_scaled_apart`]); None where they are
/// not, or where the scaling would not be exact: the caller then works on the system as
/// given, so that a well-scaled system's results do not change.
pub(crate) fn balanced_where_scaled_apart(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
) -> Option<ScaledStates> {
    if !states_scaled_apart(a) {
        return None;
    }
    balanced_states_with_scaling(a, b, c)
}

/// States of a balanced matrix whose sizes ([`state_size`]) span more than this factor are
/// ordered by [`order_graded_states`]; a matrix of one scale is left exactly as it is. Also the
/// spread of eigenvalue moduli beyond which the QR iteration's small ones (accurate to
/// u ||A|| only) are refined (`schur::eigenvalues`) or polished
/// (`root_locus::closed_loop_poles`).
pub(crate) const GRADED_SPREAD: f64 = 1_048_576.0; // 2^20

/// The size of state i of A: the 1-norms of its row and of its column, diagonal included.
fn state_size<O: Order>(a: &Square<O>, i: usize) -> f64 {
    (0..a.nrows())
        .map(|k| a[(i, k)].abs() + a[(k, i)].abs())
        .sum()
}

/// Orders the states of a balanced matrix by decreasing size ([`state_size`]), a symmetric
/// permutation P A P^T (exact), where the nonzero sizes span more than [`GRADED_SPREAD`]; else
/// leaves A alone. The QR algorithm computes the small eigenvalues of a matrix graded
/// downward (its large entries in the leading rows and columns) to about their own size, where
/// graded upward it loses them to u ||A|| (the LAPACK Users' Guide's notes on balancing,
/// dgebal; G. W. Stewart and G. Zhang, "Eigenvalues of graded matrices and the condition
/// numbers of a multiple eigenvalue", Numer. Math. 58, 1991): tf's
/// companion form of 1e-20 s^2 + s + 1, [[0, -2^33.4], [2^33, -1e20]], gave the poles -1e20
/// and 0, and ordered [[-1e20, 2^33], [-2^33.4, 0]] gives -1e20 and -1. States of equal size
/// keep their order (a stable sort), and a state of size 0 (a zero row and column) goes last.
/// Returns whether A was graded (and ordered).
pub(crate) fn order_graded_states<O: Order>(a: &mut Square<O>) -> bool {
    let n = a.nrows();
    let (mut largest, mut smallest) = (0.0f64, f64::INFINITY);
    for i in 0..n {
        let size = state_size(a, i);
        if size > 0.0 {
            largest = largest.max(size);
            smallest = smallest.min(size);
        }
    }
    if largest <= GRADED_SPREAD * smallest || !largest.is_finite() {
        return false;
    }
    let sizes: Vec<f64> = (0..n).map(|i| state_size(a, i)).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| sizes[j].total_cmp(&sizes[i]));
    let given = a.clone();
    for (i, &p) in order.iter().enumerate() {
        for (j, &q) in order.iter().enumerate() {
            a[(i, j)] = given[(p, q)];
        }
    }
    true
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balanced_states_is_an_exact_similarity() {
        // States scaled by 10^±6: the balanced system's rows and columns are of one size, and
        // T is a power of two, so C (sI - A)^-1 B at s = 0 (C A^-1 B here) is unchanged.
        let s = [1e6, 1e-6, 1.0];
        let base = [[-1.0, 2.0, 0.5], [-3.0, -2.0, 1.0], [0.25, -1.0, -4.0]];
        let a = Mat::from_fn(3, 3, |i, j| base[i][j] * s[i] / s[j]);
        let b = Mat::from_fn(3, 1, |i, _| [1.0, 0.5, -1.0][i] * s[i]);
        let c = Mat::from_fn(1, 3, |_, j| [1.0, -2.0, 0.5][j] / s[j]);
        let (a2, b2, c2) = balanced_states(a.as_ref(), b.as_ref(), c.as_ref()).unwrap();
        let largest = max_abs(a2.as_ref())
            .max(max_abs(b2.as_ref()))
            .max(max_abs(c2.as_ref()));
        assert!(largest < 64.0, "{largest}");
        for i in 0..3 {
            // T_ii = b2_i / b_i, a power of two; T A T^-1 exactly.
            let t = b2[(i, 0)] / b[(i, 0)];
            assert_eq!(t, 2f64.powi(t.log2().round() as i32));
            for j in 0..3 {
                let tj = b2[(j, 0)] / b[(j, 0)];
                assert_eq!(a2[(i, j)], a[(i, j)] * t / tj);
            }
            assert_eq!(c2[(0, i)], c[(0, i)] / t);
        }
    }

    #[test]
    fn balanced_loop_scales_b_and_c_to_the_size_of_a() {
        // A of 1e-60 (states scaled by 10^±3) beside B of 1 and C of 1e-60: B and C are brought
        // to the size of A balanced alone for the second balancing, then scaled back, so that
        // A - g B C is unchanged for every g (exact: T and the split are powers of two).
        let s = [1e3, 1e-3, 1.0];
        let base = [[-1.0, 2.0, 0.5], [-3.0, -2.0, 1.0], [0.25, -1.0, -4.0]];
        let a = Mat::from_fn(3, 3, |i, j| 1e-60 * base[i][j] * s[i] / s[j]);
        let b = Mat::from_fn(3, 1, |i, _| [1.0, 0.5, -1.0][i] * s[i]);
        let c = Mat::from_fn(1, 3, |_, j| 1e-60 * [1.0, -2.0, 0.5][j] / s[j]);
        let (a2, b2, c2) = balanced_loop(a.as_ref(), b.as_ref(), c.as_ref());
        for i in 0..3 {
            // T_ii = b2_i / b_i, a power of two, and T A T^-1, C T^-1 exactly.
            let t = b2[(i, 0)] / b[(i, 0)];
            assert_eq!(t, 2f64.powi(t.log2().round() as i32));
            for j in 0..3 {
                let tj = b2[(j, 0)] / b[(j, 0)];
                assert_eq!(a2[(i, j)], a[(i, j)] * t / tj);
            }
            assert_eq!(c2[(0, i)], c[(0, i)] / t);
        }
        // The balanced A has rows and columns of one size (within 2^2 of each other).
        let largest = max_abs(a2.as_ref());
        let smallest = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .filter(|(i, j)| i != j)
            .map(|(i, j)| a2[(i, j)].abs())
            .fold(f64::INFINITY, f64::min);
        assert!(largest / smallest < 256.0, "{largest} {smallest}");
        // Not finite, or no states: as given.
        let mut bad = a.clone();
        bad[(0, 0)] = f64::NAN;
        let (a3, b3, _) = balanced_loop(bad.as_ref(), b.as_ref(), c.as_ref());
        assert!(a3[(0, 0)].is_nan() && a3[(0, 1)] == a[(0, 1)] && b3 == b);
    }

    #[test]
    fn balanced_states_refuses_an_inexact_scaling() {
        // A of 1e-300 beside B of 0.1 and C of 1e-151: the balancing scales by 2^±250 and an
        // entry of 1.3e-301 would leave the normal doubles.
        let a = Mat::from_fn(2, 2, |i, j| if i == j { -1e-300 } else { 1.3e-301 });
        let b = Mat::from_fn(2, 1, |_, _| 0.1);
        let c = Mat::from_fn(1, 2, |_, _| 1e-151);
        assert!(balanced_states(a.as_ref(), b.as_ref(), c.as_ref()).is_none());
    }
}
