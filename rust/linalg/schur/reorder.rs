//! Reordering of the real Schur form: A = Z T Z^T becomes A = Z' T' Z'^T with a chosen set
//! of eigenvalues in the leading diagonal blocks of T', so that the leading columns of Z' span
//! their invariant subspace (what the Riccati solver needs: the stable subspace of the
//! Hamiltonian).
//!
//! # Swapping two adjacent blocks (Bai & Demmel 1993)
//!
//! Let T11 (order p) and T22 (order q) be adjacent diagonal blocks, p, q in {1, 2}, and
//!
//! ```text
//! D = [ T11  T12 ]
//!     [ 0    T22 ]
//! ```
//!
//! If X solves the Sylvester equation T11 X - X T22 = T12 (`crate::linalg::sylvester`), then
//! D [-X; I] = [-X; I] T22, so the columns of [-X; I] span the invariant subspace of T22's
//! eigenvalues. With the QR factorisation [-X; I] = Q R, the orthogonal Q gives
//!
//! ```text
//! Q^T D Q = [ T22'  *    ]      T22' = R T22 R^-1,  T11' similar to T11.
//!           [ E     T11' ]
//! ```
//!
//! E is zero in exact arithmetic and of order u ||D|| / sep(T11, T22) in floating point. The
//! swap is accepted only if it passes both stability tests of Bai & Demmel: the weak test
//! ||E||_F <= thresh and the strong test ||D - Q [T22' *; 0 T11'] Q^T||_F <= thresh, with
//! thresh = 20 u ||D||_F, the thresholds of LAPACK's dtgex2 (dtrexc applies only the weak test,
//! with 10 u max|D_ij|). The strong test's own rounding, in forming Q D' Q^T, is a few
//! u ||D||: with dtrexc's threshold it rejected well-separated blocks of a random 128 x 128
//! Hamiltonian (strong 2.8e-14 against 2.6e-14; weak 3e-15); over 60 000 swaps of random
//! Hamiltonians of order 40..200 the largest test is now half the threshold. Then E is set to zero and the
//! transformation is applied to the rest of T and to Z; the swap is backward stable. When T11
//! and T22 have (nearly) equal eigenvalues the Sylvester equation is (nearly) singular and the
//! tests fail: the swap is refused with [`Error::IllConditioned`] rather than returning an
//! inaccurate invariant subspace. Two 1 x 1 blocks are exchanged by the single plane rotation
//! whose first column is the eigenvector [t12, t22 - t11] of t22, which is always stable.
//!
//! New 2 x 2 blocks are put back in standard form ([`crate::linalg::schur::standardize_block`]); a
//! block whose eigenvalues the rounding errors have made real splits into two 1 x 1 blocks.
//!
//! # Ordering
//!
//! The blocks are scanned from the top; each selected block is moved up, one adjacent swap at
//! a time, to just below the selected ones already in place, as LAPACK's dtrsen does. A
//! complex pair is selected by its member with positive imaginary part.

use crate::error::Error;
use crate::linalg::balance::range_scale;
use crate::linalg::householder::reflector;
use crate::linalg::rotation::Rotation;
use crate::linalg::schur::form::{RealSchur, quasi_triangular_eigenvalues, standardize_block};
use crate::linalg::sylvester::solve_small_sylvester;
use crate::platform::dispatch::clear_upper_avx_state;
use crate::platform::interrupt;
use faer::{Mat, c64};
use std::ops::Range;

/// A real Schur form A = Z T Z^T whose leading `selected` eigenvalues are the chosen ones.
#[derive(Debug, Clone)]
pub struct OrderedSchur {
    pub t: Mat<f64>,
    pub z: Mat<f64>,
    /// The eigenvalues in the order of T's diagonal (pairs adjacent, Im > 0 first).
    pub eigenvalues: Vec<c64>,
    /// The number of leading eigenvalues that `select` chose.
    pub selected: usize,
}

/// Reorders a real Schur form so that the eigenvalues for which `select` is true come first.
pub fn reorder_schur(
    schur: RealSchur,
    mut select: impl FnMut(c64) -> bool,
) -> Result<OrderedSchur, Error> {
    clear_upper_avx_state();
    let RealSchur { t, mut z } = schur;
    let n = t.nrows();
    // T / s for the power of two s that brings its largest entry near 1 (exact): the swaps'
    // small Sylvester equations and their tests compare with absolute thresholds, so a form
    // of entries near 1e-300 came back with a residual of its own size. `select` sees the
    // eigenvalues of T itself.
    let scale = range_scale(t.as_ref());
    let mut t = with_padded_columns(t);
    if scale != 1.0 {
        t /= faer::Scale(scale);
    }
    // Rows and columns above `position` hold selected blocks only.
    let mut position = 0;
    let mut k = 0;
    while k < n {
        interrupt::check()?;
        let size = block_size(&t, k);
        if !select(block_eigenvalue(&t, k, size) * scale) {
            k += size;
            continue;
        }
        let mut current = k;
        let mut split = false;
        while current > position {
            let previous_size = if current >= position + 2 && t[(current - 1, current - 2)] != 0.0 {
                2
            } else {
                1
            };
            let previous = current - previous_size;
            swap_blocks(&mut t, &mut z, previous, previous_size, size)?;
            current = previous;
            if size == 2 && t[(current + 1, current)] == 0.0 {
                split = true;
                break;
            }
        }
        if split {
            // The moving pair turned into two real eigenvalues: scan again from the boundary.
            k = position;
            continue;
        }
        position += size;
        k += size;
    }
    if scale != 1.0 {
        t *= faer::Scale(scale);
    }
    let eigenvalues = quasi_triangular_eigenvalues(t.as_ref());
    Ok(OrderedSchur {
        t,
        z,
        eigenvalues,
        selected: position,
    })
}

/// From this order on, [`reorder_schur`] works on a copy of T whose columns are 8 entries
/// longer than T's (see [`with_padded_columns`]).
const PADDED_MIN_ORDER: usize = 256;

/// T itself below [`PADDED_MIN_ORDER`], else a copy whose column stride is 8 entries (one cache
/// line) more than the order.
///
/// Every swap sweeps two or four adjacent rows of T across all the columns to the right. With a
/// stride of a multiple of 512 bytes, consecutive columns fall into a handful of the L1 cache's
/// sets and each sweep misses the cache on every column; one extra cache line per column
/// spreads them over all the sets, so the rows a sweep touches stay in L1 for the next swap
/// (the bench "schur + reorder lhp" in `benches/riccati.rs` measures it).
fn with_padded_columns(t: Mat<f64>) -> Mat<f64> {
    let n = t.nrows();
    if n < PADDED_MIN_ORDER || n != t.ncols() {
        return t;
    }
    let mut padded = Mat::<f64>::with_capacity(n + 8, n);
    padded.resize_with(n, n, |_, _| 0.0);
    padded.copy_from(&t);
    padded
}

/// The order (1 or 2) of the diagonal block that starts at row k.
fn block_size(t: &Mat<f64>, k: usize) -> usize {
    if k + 1 < t.nrows() && t[(k + 1, k)] != 0.0 {
        2
    } else {
        1
    }
}

/// The eigenvalue of a block, the one with Im > 0 for a pair.
fn block_eigenvalue(t: &Mat<f64>, k: usize, size: usize) -> c64 {
    if size == 1 {
        c64::new(t[(k, k)], 0.0)
    } else {
        let im = t[(k, k + 1)].abs().sqrt() * t[(k + 1, k)].abs().sqrt();
        c64::new(t[(k, k)], im)
    }
}

/// Exchanges the adjacent diagonal blocks of orders p (at row j) and q (at row j + p) of T,
/// updating Z.
// The 4 x 4 kernels below read most clearly with indices.
#[allow(clippy::needless_range_loop)]
pub(crate) fn swap_blocks(
    t: &mut Mat<f64>,
    z: &mut Mat<f64>,
    j: usize,
    p: usize,
    q: usize,
) -> Result<(), Error> {
    if p == 1 && q == 1 {
        swap_one_by_one(t, z, j);
        return Ok(());
    }
    let order = p + q;
    let mut d = [[0.0f64; 4]; 4];
    for (r, row) in d.iter_mut().enumerate().take(order) {
        for (c, value) in row.iter_mut().enumerate().take(order) {
            *value = t[(j + r, j + c)];
        }
    }
    let d_norm = frobenius(&d, 0..order, 0..order);
    let threshold = (20.0 * f64::EPSILON * d_norm).max(f64::MIN_POSITIVE / f64::EPSILON);

    // T11 X - X T22 = T12.
    let mut t11 = [[0.0; 2]; 2];
    let mut minus_t22 = [[0.0; 2]; 2];
    let mut t12 = [[0.0; 2]; 2];
    for r in 0..2 {
        for c in 0..2 {
            if r < p && c < p {
                t11[r][c] = d[r][c];
            }
            if r < q && c < q {
                minus_t22[r][c] = -d[p + r][p + c];
            }
            if r < p && c < q {
                t12[r][c] = d[r][p + c];
            }
        }
    }
    let x = solve_small_sylvester(&t11, p, &minus_t22, q, &t12).x;

    // Q from the Householder QR of [-X; I] (order x q).
    let mut basis = [[0.0f64; 2]; 4];
    for r in 0..p {
        for c in 0..q {
            basis[r][c] = -x[r][c];
        }
    }
    for c in 0..q {
        basis[p + c][c] = 1.0;
    }
    let mut q_matrix = [[0.0f64; 4]; 4];
    for (r, row) in q_matrix.iter_mut().enumerate().take(order) {
        row[r] = 1.0;
    }
    for c in 0..q {
        let mut v = [0.0f64; 4];
        for r in c..order {
            v[r - c] = basis[r][c];
        }
        let length = order - c;
        let (_, tau) = reflector(&mut v[..length]);
        if tau == 0.0 {
            continue;
        }
        v[0] = 1.0;
        // basis <- H basis (remaining columns), Q <- Q H.
        for cc in c + 1..q {
            let dot: f64 = (0..length).map(|r| v[r] * basis[c + r][cc]).sum();
            for r in 0..length {
                basis[c + r][cc] -= tau * dot * v[r];
            }
        }
        for row in q_matrix.iter_mut().take(order) {
            let dot: f64 = (0..length).map(|r| row[c + r] * v[r]).sum();
            for r in 0..length {
                row[c + r] -= tau * dot * v[r];
            }
        }
    }

    // D' = Q^T D Q and the two stability tests.
    let product = |left: &[[f64; 4]; 4], right: &[[f64; 4]; 4], transpose_left: bool| {
        let mut out = [[0.0f64; 4]; 4];
        for (r, row) in out.iter_mut().enumerate().take(order) {
            for (c, value) in row.iter_mut().enumerate().take(order) {
                *value = (0..order)
                    .map(|s| {
                        let l = if transpose_left {
                            left[s][r]
                        } else {
                            left[r][s]
                        };
                        l * right[s][c]
                    })
                    .sum();
            }
        }
        out
    };
    let transpose = |m: &[[f64; 4]; 4]| {
        let mut out = [[0.0f64; 4]; 4];
        for r in 0..order {
            for c in 0..order {
                out[r][c] = m[c][r];
            }
        }
        out
    };
    let mut swapped = product(&q_matrix, &product(&d, &q_matrix, false), true);
    let weak = frobenius(&swapped, q..order, 0..q);
    for row in swapped.iter_mut().take(order).skip(q) {
        for value in row.iter_mut().take(q) {
            *value = 0.0;
        }
    }
    let rebuilt = product(
        &q_matrix,
        &product(&swapped, &transpose(&q_matrix), false),
        false,
    );
    let mut difference = rebuilt;
    for (difference_row, d_row) in difference.iter_mut().zip(&d) {
        for (value, original) in difference_row.iter_mut().zip(d_row) {
            *value -= original;
        }
    }
    let strong = frobenius(&difference, 0..order, 0..order);
    if !(weak <= threshold && strong <= threshold) {
        return Err(Error::IllConditioned {
            message: format!(
                "the exchange of the Schur blocks at rows {j} and {} was rejected as too \
                 ill-conditioned (their eigenvalues are too close: the swapped form would be \
                 off by {:.2e}, the threshold is {threshold:.2e})",
                j + p,
                weak.max(strong)
            ),
        });
    }

    // Apply Q to the rest of T and to Z, and write the swapped block.
    multiply_rows(t, j, &q_matrix, order);
    multiply_columns(t, j, j, &q_matrix, order);
    multiply_columns(z, z.nrows(), j, &q_matrix, order);
    for r in 0..order {
        for c in 0..order {
            t[(j + r, j + c)] = swapped[r][c];
        }
    }
    if q == 2 {
        standardize_at(t, z, j);
    }
    if p == 2 {
        standardize_at(t, z, j + q);
    }
    Ok(())
}

/// The Frobenius norm of the block rows x columns of a 4 x 4 array.
fn frobenius(m: &[[f64; 4]; 4], rows: Range<usize>, columns: Range<usize>) -> f64 {
    m[rows]
        .iter()
        .flat_map(|row| row[columns.clone()].iter())
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
}

/// The rows j..j+order of T right of column j+order times the order x order `q^T`.
fn multiply_rows(t: &mut Mat<f64>, j: usize, q: &[[f64; 4]; 4], order: usize) {
    match order {
        2 => multiply_rows_of::<2>(t, j, q),
        3 => multiply_rows_of::<3>(t, j, q),
        _ => multiply_rows_of::<4>(t, j, q),
    }
}

/// [`multiply_rows`] for `ORDER` rows, a column slice at a time.
fn multiply_rows_of<const ORDER: usize>(t: &mut Mat<f64>, j: usize, q: &[[f64; 4]; 4]) {
    for c in j + ORDER..t.ncols() {
        let rows = &mut t.col_as_slice_mut(c)[j..j + ORDER];
        let x: [f64; ORDER] = std::array::from_fn(|s| rows[s]);
        for (r, value) in rows.iter_mut().enumerate() {
            *value = (0..ORDER).map(|s| q[s][r] * x[s]).sum();
        }
    }
}

/// Rows 0..rows of columns j..j+order of `matrix` times the order x order `q`.
fn multiply_columns(matrix: &mut Mat<f64>, rows: usize, j: usize, q: &[[f64; 4]; 4], order: usize) {
    match order {
        2 => multiply_columns_of::<2>(matrix, rows, j, q),
        3 => multiply_columns_of::<3>(matrix, rows, j, q),
        _ => multiply_columns_of::<4>(matrix, rows, j, q),
    }
}

/// [`multiply_columns`] for `ORDER` columns, on the columns as slices.
fn multiply_columns_of<const ORDER: usize>(
    matrix: &mut Mat<f64>,
    rows: usize,
    j: usize,
    q: &[[f64; 4]; 4],
) {
    let mut columns = matrix
        .as_mut()
        .submatrix_mut(0, j, rows, ORDER)
        .col_iter_mut();
    let mut columns: [&mut [f64]; ORDER] = std::array::from_fn(|_| {
        let column = columns.next().expect("ORDER columns");
        column
            .try_as_col_major_mut()
            .expect("a column of a Mat is contiguous")
            .as_slice_mut()
    });
    for r in 0..rows {
        let x: [f64; ORDER] = std::array::from_fn(|s| columns[s][r]);
        let buffer: [f64; ORDER] =
            std::array::from_fn(|c| (0..ORDER).map(|s| x[s] * q[s][c]).sum());
        for (column, value) in columns.iter_mut().zip(buffer) {
            column[r] = value;
        }
    }
}

/// Exchanges two 1 x 1 blocks at rows j and j + 1 by one plane rotation.
fn swap_one_by_one(t: &mut Mat<f64>, z: &mut Mat<f64>, j: usize) {
    let (t11, t12, t22) = (t[(j, j)], t[(j, j + 1)], t[(j + 1, j + 1)]);
    if t11 == t22 {
        return;
    }
    // The first column of the rotation is the eigenvector [t12, t22 - t11] of t22.
    let (rotation, _) = Rotation::zeroing(t12, t22 - t11);
    let (cs, sn) = (rotation.c, rotation.s);
    rotate(t, z, j, cs, sn);
    t[(j, j)] = t22;
    t[(j + 1, j + 1)] = t11;
    t[(j + 1, j)] = 0.0;
}

/// Puts the 2 x 2 block at row j in standard form (or splits it) and carries the rotation.
fn standardize_at(t: &mut Mat<f64>, z: &mut Mat<f64>, j: usize) {
    let block = standardize_block(t[(j, j)], t[(j, j + 1)], t[(j + 1, j)], t[(j + 1, j + 1)]);
    rotate(t, z, j, block.cs, block.sn);
    t[(j, j)] = block.a;
    t[(j, j + 1)] = block.b;
    t[(j + 1, j)] = block.c;
    t[(j + 1, j + 1)] = block.d;
}

/// T <- G^T T G and Z <- Z G for the rotation G = [[cs, -sn], [sn, cs]] in the plane (j, j+1);
/// the 2 x 2 diagonal block itself is left to the caller.
fn rotate(t: &mut Mat<f64>, z: &mut Mat<f64>, j: usize, cs: f64, sn: f64) {
    let n = t.nrows();
    for c in j + 2..n {
        let rows = &mut t.col_as_slice_mut(c)[j..j + 2];
        let (x, y) = (rows[0], rows[1]);
        rows[0] = cs * x + sn * y;
        rows[1] = cs * y - sn * x;
    }
    rotate_columns(t, j, j, cs, sn);
    rotate_columns(z, n, j, cs, sn);
}

/// Rows 0..rows of the columns j and j + 1 of `matrix` times G = [[cs, -sn], [sn, cs]].
fn rotate_columns(matrix: &mut Mat<f64>, rows: usize, j: usize, cs: f64, sn: f64) {
    let (left, right) = matrix
        .as_mut()
        .submatrix_mut(0, j, rows, 2)
        .split_at_col_mut(1);
    let left = left
        .col_mut(0)
        .try_as_col_major_mut()
        .expect("a column of a Mat is contiguous")
        .as_slice_mut();
    let right = right
        .col_mut(0)
        .try_as_col_major_mut()
        .expect("a column of a Mat is contiguous")
        .as_slice_mut();
    for (x, y) in left.iter_mut().zip(right.iter_mut()) {
        let (a, b) = (*x, *y);
        *x = cs * a + sn * b;
        *y = cs * b - sn * a;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::schur::real_schur;

    use crate::test_matrices::seeded_square as seeded;

    #[test]
    fn left_half_plane_first_below_and_above_the_padded_order() {
        for n in [40usize, PADDED_MIN_ORDER, 300] {
            let a = seeded(n, n as u64);
            let ordered = reorder_schur(real_schur(a.as_ref()).unwrap(), |z| z.re < 0.0).unwrap();
            let OrderedSchur {
                t,
                z,
                eigenvalues,
                selected,
            } = ordered;
            let residual = (&z * &t * z.transpose() - &a).norm_l2() / a.norm_l2();
            assert!(residual < 1e-13, "n={n}: residual {residual}");
            let orthogonality = (z.transpose() * &z - Mat::<f64>::identity(n, n)).norm_l2();
            assert!(orthogonality < 1e-15 * n as f64, "n={n}: {orthogonality}");
            for j in 0..n {
                for i in j + 2..n {
                    assert_eq!(t[(i, j)], 0.0, "n={n}: T[{i}, {j}]");
                }
            }
            assert_eq!(
                selected,
                eigenvalues.iter().filter(|z| z.re < 0.0).count(),
                "n={n}"
            );
            assert!(eigenvalues[..selected].iter().all(|z| z.re < 0.0), "n={n}");
            assert_eq!(eigenvalues, quasi_triangular_eigenvalues(t.as_ref()));
        }
    }

    /// Matrices near the ends of the range reorder with the same relative residual as at 1
    /// (the swaps work on T scaled to its largest entry).
    #[test]
    fn tiny_and_huge_forms_reorder_with_a_relative_residual() {
        let base = seeded(6, 3);
        for factor in [1e-300, 1e-200, 1e200, 1e300] {
            let a = &base * faer::Scale(factor);
            let ordered = reorder_schur(real_schur(a.as_ref()).unwrap(), |z| z.re > 0.0).unwrap();
            let (t, z) = (&ordered.t, &ordered.z);
            let residual = (z * t * z.transpose() - &a).norm_l2() / a.norm_l2();
            assert!(residual < 1e-14, "{factor:e}: residual {residual:e}");
            assert!(
                ordered.eigenvalues[..ordered.selected]
                    .iter()
                    .all(|z| z.re > 0.0)
            );
        }
    }
}
