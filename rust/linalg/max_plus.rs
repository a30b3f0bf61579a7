//! The (max, +) algebra of the sizes of matrix entries, for the choice of diagonal scalings by
//! powers of two (`aerocontrol._scaling`).
//!
//! A matrix of log2 sizes G (entry -inf where the entry it measures is zero) is read as a
//! weighted graph, with an edge i -> j of weight G[i, j] wherever that is finite. In the
//! (max, +) algebra, products are sums and sums are maxima:
//!
//! * [`product`]: (P ⊗ Q)[i, j] = max_k P[i, k] + Q[k, j], the log2 of the largest term of the
//!   product of the matrices that P and Q measure;
//! * [`max_cycle_mean`]: the largest mean weight of a cycle of the graph, by Karp's algorithm
//!   (R. M. Karp, "A characterization of the minimum cycle mean in a digraph", Discrete
//!   Mathematics 23, 1978), with D_k(v) the largest weight of a walk of k edges ending at v:
//!
//! ```text
//! λ = max_v min_{0 <= k < N} (D_N(v) - D_k(v)) / (N - k),   D_0 = 0,
//! D_k(v) = max_u D_{k-1}(u) + G[u, v]   (D_k = D_{k-1} ⊗ G).
//! ```
//!
//! Maxima and single sums are exact in floating point, so both results are the same bits as
//! any evaluation order gives (numpy's included). Both cost O(N^3) at order N, work in O(N^2)
//! memory, and answer Ctrl-C between rows or walk lengths.
//!
//! Entries are finite or -inf: +inf or NaN (a size no scaling concerns) is refused by name.

use crate::error::Error;
use crate::platform::dispatch::fma_dispatch;
use crate::platform::interrupt;
use faer::{Mat, MatRef};

/// Refuses an entry that is +inf or NaN.
fn check_sizes(m: MatRef<'_, f64>, arg: &'static str) -> Result<(), Error> {
    let bad = (0..m.ncols())
        .any(|j| (0..m.nrows()).any(|i| m[(i, j)].is_nan() || m[(i, j)] == f64::INFINITY));
    if bad {
        return Err(Error::InvalidArgument {
            arg,
            message: format!(
                "{arg} must hold log2 sizes, finite or -inf (a zero entry); it has +inf or NaN"
            ),
        });
    }
    Ok(())
}

/// The entries of `m` in row-major order.
fn rows_of(m: MatRef<'_, f64>) -> Vec<f64> {
    let (rows, cols) = (m.nrows(), m.ncols());
    let mut values = Vec::with_capacity(rows * cols);
    for i in 0..rows {
        values.extend((0..cols).map(|j| m[(i, j)]));
    }
    values
}

/// row[j] <- max(row[j], p + q[j]) for every j (the select compiles to vector maxima: no
/// entry is NaN).
#[inline(always)]
fn raise_to_kernel<const FMA: bool>(row: &mut [f64], p: f64, q: &[f64]) {
    for (entry, &x) in row.iter_mut().zip(q) {
        let sum = p + x;
        *entry = if sum > *entry { sum } else { *entry };
    }
}

fma_dispatch!(fn raise_to(row: &mut [f64], p: f64, q: &[f64]) => raise_to_kernel);

/// The (max, +) product P ⊗ Q: entry (i, j) is max_k P[i, k] + Q[k, j] (-inf where every
/// term is -inf, and for an inner dimension of 0).
pub fn product(p: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    check_sizes(p, "P")?;
    check_sizes(q, "Q")?;
    if p.ncols() != q.nrows() {
        return Err(Error::InvalidArgument {
            arg: "Q",
            message: format!(
                "Q must have as many rows as P has columns ({}), got {}",
                p.ncols(),
                q.nrows()
            ),
        });
    }
    let (rows, inner, cols) = (p.nrows(), p.ncols(), q.ncols());
    let q_rows = rows_of(q);
    let mut out = Mat::<f64>::zeros(rows, cols);
    let mut row = vec![f64::NEG_INFINITY; cols];
    for i in 0..rows {
        if i % 64 == 0 {
            interrupt::check()?;
        }
        row.fill(f64::NEG_INFINITY);
        for k in 0..inner {
            let entry = p[(i, k)];
            if entry > f64::NEG_INFINITY {
                raise_to(&mut row, entry, &q_rows[k * cols..(k + 1) * cols]);
            }
        }
        for (j, &value) in row.iter().enumerate() {
            out[(i, j)] = value;
        }
    }
    Ok(out)
}

/// The largest mean weight of a cycle of the graph G (square), by Karp's algorithm (see the
/// module documentation); -inf for a graph without a cycle (and for N = 0).
pub fn max_cycle_mean(g: MatRef<'_, f64>) -> Result<f64, Error> {
    check_sizes(g, "G")?;
    if g.nrows() != g.ncols() {
        return Err(Error::NotSquare {
            arg: "G",
            rows: g.nrows(),
            cols: g.ncols(),
        });
    }
    let n = g.nrows();
    if n == 0 {
        return Ok(f64::NEG_INFINITY);
    }
    let g_rows = rows_of(g);
    // walks[k * n + v] = D_k(v).
    let mut walks = vec![f64::NEG_INFINITY; (n + 1) * n];
    walks[..n].fill(0.0);
    for k in 1..=n {
        interrupt::check()?;
        let (done, rest) = walks.split_at_mut(k * n);
        let (previous, next) = (&done[(k - 1) * n..], &mut rest[..n]);
        for (u, &walk) in previous.iter().enumerate() {
            if walk > f64::NEG_INFINITY {
                raise_to(next, walk, &g_rows[u * n..(u + 1) * n]);
            }
        }
    }
    let last = &walks[n * n..];
    let mut best = f64::NEG_INFINITY;
    for (v, &longest) in last.iter().enumerate() {
        if !longest.is_finite() {
            continue;
        }
        let least = (0..n)
            .map(|k| (k, walks[k * n + v]))
            .filter(|&(_, earlier)| earlier.is_finite())
            .map(|(k, earlier)| (longest - earlier) / (n - k) as f64)
            .fold(f64::INFINITY, f64::min);
        best = best.max(least);
    }
    Ok(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::mat;

    const NONE: f64 = f64::NEG_INFINITY;

    #[test]
    fn product_takes_the_largest_term() {
        let p = mat![[1.0, NONE], [0.0, 2.0]];
        let q = mat![[3.0, NONE, 0.5], [-1.0, NONE, 4.0]];
        let out = product(p.as_ref(), q.as_ref()).unwrap();
        assert_eq!(out, mat![[4.0, NONE, 1.5], [3.0, NONE, 6.0]]);
        // An inner dimension of 0: every entry -inf.
        let empty = product(Mat::zeros(2, 0).as_ref(), Mat::zeros(0, 3).as_ref()).unwrap();
        assert!(empty.col_iter().all(|c| c.iter().all(|&x| x == NONE)));
    }

    #[test]
    fn cycle_means_of_known_graphs() {
        // A 2-cycle of weights 3 and -1 (mean 1) beside a self-loop of 0.5.
        let g = mat![[NONE, 3.0, NONE], [-1.0, NONE, NONE], [NONE, NONE, 0.5]];
        assert_eq!(max_cycle_mean(g.as_ref()).unwrap(), 1.0);
        // A 3-cycle of mean 2 and a 2-cycle of mean 3.5 sharing node 0.
        let g = mat![[NONE, 1.0, 4.0], [NONE, NONE, 2.0], [3.0, NONE, NONE]];
        assert_eq!(max_cycle_mean(g.as_ref()).unwrap(), 3.5);
        // No cycle: a path.
        let g = mat![[NONE, 1.0], [NONE, NONE]];
        assert_eq!(max_cycle_mean(g.as_ref()).unwrap(), NONE);
        assert_eq!(max_cycle_mean(Mat::zeros(0, 0).as_ref()).unwrap(), NONE);
    }

    #[test]
    fn cycle_mean_is_invariant_under_scaling_and_bounds_the_entries() {
        // Diagonal scaling changes G[i, j] by e_j - e_i: every cycle's mean is unchanged, and
        // the largest scaled entry is never below it.
        let g = mat![
            [0.0, 7.0, NONE, 1.0],
            [-3.0, NONE, 2.0, NONE],
            [NONE, 5.0, -1.0, 9.0],
            [-8.0, NONE, NONE, NONE]
        ];
        let e = [3.0, -2.0, 0.0, 5.0];
        let scaled = Mat::from_fn(4, 4, |i, j| g[(i, j)] + e[j] - e[i]);
        let (mean, scaled_mean) = (
            max_cycle_mean(g.as_ref()).unwrap(),
            max_cycle_mean(scaled.as_ref()).unwrap(),
        );
        assert_eq!(mean, scaled_mean);
        let largest = scaled
            .col_iter()
            .flat_map(|c| c.iter().copied().collect::<Vec<_>>())
            .fold(NONE, f64::max);
        assert!(largest >= mean);
    }

    #[test]
    fn infinite_and_nan_sizes_are_refused_by_name() {
        let g = mat![[0.0, f64::INFINITY], [1.0, 0.0]];
        assert!(matches!(
            max_cycle_mean(g.as_ref()),
            Err(Error::InvalidArgument { arg: "G", .. })
        ));
        let p = mat![[f64::NAN]];
        assert!(matches!(
            product(p.as_ref(), p.as_ref()),
            Err(Error::InvalidArgument { arg: "P", .. })
        ));
        assert!(matches!(
            max_cycle_mean(Mat::zeros(2, 3).as_ref()),
            Err(Error::NotSquare { arg: "G", .. })
        ));
    }
}
