//! Reordering of the generalized real Schur form: (A, B) = Q (S, T) Z^T becomes
//! Q' (S', T') Z'^T with chosen eigenvalues in the leading diagonal blocks, so that the leading
//! columns of Z' span their right deflating subspace (what the discrete Riccati solver needs).
//!
//! # Swapping two adjacent blocks (Kågström 1993; Kågström & Poromaa 1996)
//!
//! With adjacent diagonal blocks of orders p and q (in {1, 2}),
//!
//! ```text
//! (A, B) = ([A11 A12], [B11 B12])       A11 R - L A22 = -A12
//!           [0   A22]  [0   B22]        B11 R - L B22 = -B12
//! ```
//!
//! the coupled Sylvester equation for (L, R) (2pq <= 8 unknowns, solved in its Kronecker form by
//! Gaussian elimination with complete pivoting) gives the deflating subspaces of (A22, B22):
//! (A, B) [R; I] = [L; I] (A22, B22). With the QR factorisations [R; I] = Z_s [*; 0] and
//! [L; I] = Q_s [*; 0], Q_s^T (A, B) Z_s has the eigenvalues of (A22, B22) in its leading block
//! and a lower-left block E that is zero in exact arithmetic. The swap is accepted only if it
//! passes the weak test ||E||_F <= thresh and the strong test
//! ||(A, B) - Q_s (A', B') Z_s^T||_F <= thresh (E set to zero in (A', B')), with
//! thresh = 20 u ||(A, B)||_F, as LAPACK's dtgex2; else it is refused with
//! [`Error::IllConditioned`] (eigenvalues too close to be told apart). The new 2 x 2 blocks are
//! put back in standard form.
//!
//! # Ordering
//!
//! Blocks are scanned from the top; each selected block moves up by adjacent swaps to just
//! below the selected ones already in place (LAPACK's dtgsen). A pair that rounding splits into
//! two real eigenvalues on the way is moved as two.

use super::iteration::{Pencil, standardize_pair};
use crate::error::Error;
use crate::linalg::householder::reflector;
use crate::platform::interrupt;
use faer::Mat;

/// The order of the diagonal block that starts at k.
pub(crate) fn block_size(s: &Mat<f64>, k: usize) -> usize {
    if k + 1 < s.nrows() && s[(k + 1, k)] != 0.0 {
        2
    } else {
        1
    }
}

/// Moves the blocks whose `selected[k]` is true (k the block's first row; both rows of a pair
/// carry the pair's choice) to the top, in their order. Returns the number of leading
/// eigenvalues selected.
pub(crate) fn reorder(p: &mut Pencil<'_>, selected: &[bool]) -> Result<usize, Error> {
    let n = p.n();
    let mut selected = selected.to_vec();
    let mut position = 0;
    let mut k = 0;
    while k < n {
        interrupt::check()?;
        let mut size = block_size(p.h, k);
        if !selected[k] {
            k += size;
            continue;
        }
        let mut current = k;
        let mut split = false;
        while current > position {
            let previous_size = if current >= position + 2 && p.h[(current - 1, current - 2)] != 0.0
            {
                2
            } else {
                1
            };
            let previous = current - previous_size;
            swap_blocks(p, previous, previous_size, size)?;
            selected[previous..current + size].rotate_left(previous_size);
            current = previous;
            let now = block_size(p.h, current);
            if now != size {
                size = now;
                split = true;
                break;
            }
        }
        if split {
            k = position;
            continue;
        }
        position += size;
        k = current + size;
    }
    Ok(position)
}

/// A matrix of order <= 4 on the stack (the swapped blocks and their transformations).
type Small = [[f64; 4]; 4];

/// x^T y z for matrices of order m.
fn congruence(x: &Small, y: &Small, z: &Small, m: usize) -> Small {
    let mut yz = [[0.0; 4]; 4];
    for i in 0..m {
        for j in 0..m {
            yz[i][j] = (0..m).map(|k| y[i][k] * z[k][j]).sum();
        }
    }
    let mut out = [[0.0; 4]; 4];
    for i in 0..m {
        for j in 0..m {
            out[i][j] = (0..m).map(|k| x[k][i] * yz[k][j]).sum();
        }
    }
    out
}

/// Sum of squares of x - q y z^T over order m.
fn back_error(q: &Small, y: &Small, z: &Small, original: &Small, m: usize) -> f64 {
    let mut yz = [[0.0; 4]; 4];
    for i in 0..m {
        for j in 0..m {
            yz[i][j] = (0..m).map(|k| y[i][k] * z[j][k]).sum();
        }
    }
    let mut sum = 0.0;
    for i in 0..m {
        for j in 0..m {
            let v: f64 = (0..m).map(|k| q[i][k] * yz[k][j]).sum();
            sum += (v - original[i][j]).powi(2);
        }
    }
    sum
}

/// Rows first..first + m of `x` over `columns`, replaced by f^T times them.
fn rows_times(
    x: &mut Mat<f64>,
    f: &Small,
    m: usize,
    first: usize,
    columns: std::ops::Range<usize>,
) {
    for c in columns {
        let old: [f64; 4] = std::array::from_fn(|r| if r < m { x[(first + r, c)] } else { 0.0 });
        for r in 0..m {
            x[(first + r, c)] = (0..m).map(|k| f[k][r] * old[k]).sum();
        }
    }
}

/// Columns first..first + m of `x` over `rows`, replaced by them times f.
fn columns_times(
    x: &mut Mat<f64>,
    f: &Small,
    m: usize,
    first: usize,
    rows: std::ops::Range<usize>,
) {
    match m {
        2 => columns_times_order::<2>(x, f, first, rows),
        3 => columns_times_order::<3>(x, f, first, rows),
        _ => columns_times_order::<4>(x, f, first, rows),
    }
}

/// [`columns_times`] for m = M, down the M contiguous columns.
fn columns_times_order<const M: usize>(
    x: &mut Mat<f64>,
    f: &Small,
    first: usize,
    rows: std::ops::Range<usize>,
) {
    assert!(first + M <= x.ncols() && rows.end <= x.nrows());
    let stride = x.col_stride();
    let base = x.as_ptr_mut();
    // SAFETY: columns first..first + M of x (asserted in range) are distinct columns; each
    // pointer addresses one of them, and r < nrows.
    let columns: [*mut f64; M] =
        std::array::from_fn(|c| unsafe { base.offset((first + c) as isize * stride) });
    for r in rows {
        // SAFETY: r < nrows (asserted), inside each column.
        let old: [f64; M] = std::array::from_fn(|c| unsafe { *columns[c].add(r) });
        for (c, column) in columns.iter().enumerate() {
            let mut sum = 0.0;
            for k in 0..M {
                sum += old[k] * f[k][c];
            }
            // SAFETY: as above.
            unsafe { *column.add(r) = sum };
        }
    }
}

/// Swaps the adjacent blocks at j (order p1) and j + p1 (order p2).
pub(crate) fn swap_blocks(
    pencil: &mut Pencil<'_>,
    j: usize,
    p1: usize,
    p2: usize,
) -> Result<(), Error> {
    let n = pencil.n();
    let m = p1 + p2;
    let block = |x: &Mat<f64>| -> Small {
        std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if r < m && c < m {
                    x[(j + r, j + c)]
                } else {
                    0.0
                }
            })
        })
    };
    let (a, b) = (block(pencil.h), block(pencil.t));
    let norm = a
        .iter()
        .chain(b.iter())
        .flatten()
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt();
    let threshold = (20.0 * f64::EPSILON * norm).max(f64::MIN_POSITIVE);

    let (l, r) = solve_coupled_sylvester(&a, &b, p1, p2)?;
    // [R; I] and [L; I] (m x p2), their full orthogonal QR factors.
    let basis = |x: &[[f64; 2]; 2]| -> Small {
        std::array::from_fn(|row| {
            std::array::from_fn(|col| {
                if col >= p2 || row >= m {
                    0.0
                } else if row < p1 {
                    x[row][col]
                } else if row - p1 == col {
                    1.0
                } else {
                    0.0
                }
            })
        })
    };
    let zs = orthogonal_factor(basis(&r), m, p2);
    let qs = orthogonal_factor(basis(&l), m, p2);
    let mut a_new = congruence(&qs, &a, &zs, m);
    let mut b_new = congruence(&qs, &b, &zs, m);
    // Weak test: the block below the new leading one; then it is set to zero.
    let mut weak = 0.0;
    for row in p2..m {
        for col in 0..p2 {
            weak += a_new[row][col].powi(2) + b_new[row][col].powi(2);
            a_new[row][col] = 0.0;
            b_new[row][col] = 0.0;
        }
    }
    let weak = weak.sqrt();
    let strong = (back_error(&qs, &a_new, &zs, &a, m) + back_error(&qs, &b_new, &zs, &b, m)).sqrt();
    if !(weak <= threshold && strong <= threshold) {
        return Err(Error::IllConditioned {
            message: format!(
                "a swap of the generalized Schur form was refused: its error {:.1e} exceeds \
                 {threshold:.1e} (eigenvalues too close to be reordered reliably)",
                weak.max(strong)
            ),
        });
    }
    // Apply: the block itself, the rows to its right, the columns above it, Q and Z.
    for r in 0..m {
        for c in 0..m {
            pencil.h[(j + r, j + c)] = a_new[r][c];
            pencil.t[(j + r, j + c)] = b_new[r][c];
        }
    }
    for x in [&mut *pencil.h, &mut *pencil.t] {
        rows_times(x, &qs, m, j, j + m..n);
        columns_times(x, &zs, m, j, 0..j);
    }
    columns_times(pencil.q, &qs, m, j, 0..n);
    columns_times(pencil.z, &zs, m, j, 0..n);
    // The new blocks in standard form: (A22, B22)'s at j, (A11, B11)'s at j + p2.
    for (start, size) in [(j, p2), (j + p2, p1)] {
        if size == 2 {
            standardize_pair(pencil, start)?;
        } else {
            pencil.make_positive(start);
        }
    }
    Ok(())
}

/// The orthogonal factor Q of the full QR factorisation of x (m x k, m <= 4), by reflectors.
fn orthogonal_factor(mut x: Small, m: usize, k: usize) -> Small {
    let mut q: Small =
        std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }));
    for c in 0..k.min(m - 1) {
        let mut v = [0.0; 4];
        for r in c..m {
            v[r - c] = x[r][c];
        }
        let (_, tau) = reflector(&mut v[..m - c]);
        v[0] = 1.0;
        let v = &v[..m - c];
        // x <- H x (columns c..k); q <- q H.
        // Gaussian-elimination-like updates of a 4 x 4 array read most clearly with indices.
        #[allow(clippy::needless_range_loop)]
        for col in c..k {
            let s: f64 = v.iter().enumerate().map(|(i, vi)| vi * x[c + i][col]).sum();
            for (i, vi) in v.iter().enumerate() {
                x[c + i][col] -= tau * s * vi;
            }
        }
        for row in q.iter_mut().take(m) {
            let s: f64 = v.iter().enumerate().map(|(i, vi)| vi * row[c + i]).sum();
            for (i, vi) in v.iter().enumerate() {
                row[c + i] -= tau * s * vi;
            }
        }
    }
    q
}

/// Solves A11 R - L A22 = -A12, B11 R - L B22 = -B12 for the p1 x p2 matrices (L, R), in its
/// Kronecker form, by Gaussian elimination with complete pivoting. A pivot below
/// u max|M| is refused: the blocks share an eigenvalue to working precision.
// Gaussian elimination on an 8 x 8 array reads most clearly with indices.
#[allow(clippy::needless_range_loop, clippy::type_complexity)]
fn solve_coupled_sylvester(
    a: &Small,
    b: &Small,
    p1: usize,
    p2: usize,
) -> Result<([[f64; 2]; 2], [[f64; 2]; 2]), Error> {
    let size = 2 * p1 * p2;
    let half = p1 * p2;
    // Unknowns: R[i][c] at i + p1 c, L[i][c] at half + i + p1 c.
    let mut m = [[0.0f64; 8]; 8];
    let mut rhs = [0.0f64; 8];
    for (offset, x) in [(0, a), (half, b)] {
        for c in 0..p2 {
            for i in 0..p1 {
                let row = offset + i + p1 * c;
                rhs[row] = -x[i][p1 + c];
                for s in 0..p1 {
                    m[row][s + p1 * c] += x[i][s];
                }
                for s in 0..p2 {
                    m[row][half + i + p1 * s] -= x[p1 + s][p1 + c];
                }
            }
        }
    }
    let scale = m.iter().flatten().fold(0.0f64, |acc, v| acc.max(v.abs()));
    let small = (f64::EPSILON * scale).max(f64::MIN_POSITIVE);
    let mut columns: [usize; 8] = std::array::from_fn(|i| i);
    for k in 0..size {
        let (mut pr, mut pc, mut best) = (k, k, 0.0);
        for r in k..size {
            for c in k..size {
                if m[r][c].abs() > best {
                    (pr, pc, best) = (r, c, m[r][c].abs());
                }
            }
        }
        if best <= small {
            return Err(Error::IllConditioned {
                message: "a swap of the generalized Schur form was refused: the two blocks \
                          share an eigenvalue to working precision"
                    .into(),
            });
        }
        m.swap(k, pr);
        rhs.swap(k, pr);
        for row in m.iter_mut() {
            row.swap(k, pc);
        }
        columns.swap(k, pc);
        for r in k + 1..size {
            let f = m[r][k] / m[k][k];
            if f != 0.0 {
                for c in k..size {
                    m[r][c] -= f * m[k][c];
                }
                rhs[r] -= f * rhs[k];
            }
        }
    }
    let mut y = [0.0f64; 8];
    for k in (0..size).rev() {
        let s: f64 = (k + 1..size).map(|c| m[k][c] * y[c]).sum();
        y[k] = (rhs[k] - s) / m[k][k];
    }
    let mut x = [0.0f64; 8];
    for k in 0..size {
        x[columns[k]] = y[k];
    }
    let mut l = [[0.0; 2]; 2];
    let mut r = [[0.0; 2]; 2];
    for c in 0..p2 {
        for i in 0..p1 {
            r[i][c] = x[i + p1 * c];
            l[i][c] = x[half + i + p1 * c];
        }
    }
    if !x[..size].iter().all(|v| v.is_finite()) {
        return Err(Error::IllConditioned {
            message: "a swap of the generalized Schur form was refused: its Sylvester \
                      equation overflowed"
                .into(),
        });
    }
    Ok((l, r))
}
