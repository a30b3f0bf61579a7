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
//! * [`balancing_exponents`]: integer exponents e of the nodes that bring the largest scaled
//!   entry max_ij G[i, j] + e_j - e_i to the least value any scaling reaches (the maximum
//!   cycle mean, to within one for the rounding to integers), the others evened out below it:
//!   longest-walk potentials of G minus that mean (Bellman-Ford in the (max, +) algebra), then
//!   sweeps in the manner of Osborne's balancing, each exponent in turn lowering the largest
//!   entry of its row and column (the max-balancing of Schneider and Schneider, "Max-balancing
//!   weighted directed graphs", Mathematics of Operations Research 16, 1991).
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

/// Independent running maxima of [`largest_sum`]: enough to fill the vector registers.
const LANES: usize = 8;

/// max_j a[j] + b[j] (-inf for empty slices), or max_j a[j] - b[j] when `DIFFERENCE`, in
/// [`LANES`] running maxima (maxima are exact: the same value in any order).
#[inline(always)]
fn largest_sum_kernel<const DIFFERENCE: bool, const FMA: bool>(a: &[f64], b: &[f64]) -> f64 {
    let term = |x: f64, y: f64| if DIFFERENCE { x - y } else { x + y };
    let mut lanes = [f64::NEG_INFINITY; LANES];
    let (a_chunks, b_chunks) = (a.chunks_exact(LANES), b.chunks_exact(LANES));
    let tail = a_chunks
        .remainder()
        .iter()
        .zip(b_chunks.remainder())
        .fold(f64::NEG_INFINITY, |m, (&x, &y)| m.max(term(x, y)));
    for (x, y) in a_chunks.zip(b_chunks) {
        for lane in 0..LANES {
            let value = term(x[lane], y[lane]);
            lanes[lane] = if value > lanes[lane] {
                value
            } else {
                lanes[lane]
            };
        }
    }
    lanes.iter().fold(tail, |m, &x| m.max(x))
}

#[inline(always)]
fn largest_sum_of<const FMA: bool>(a: &[f64], b: &[f64]) -> f64 {
    largest_sum_kernel::<false, FMA>(a, b)
}

#[inline(always)]
fn largest_difference_of<const FMA: bool>(a: &[f64], b: &[f64]) -> f64 {
    largest_sum_kernel::<true, FMA>(a, b)
}

fma_dispatch!(fn largest_sum(a: &[f64], b: &[f64]) -> f64 => largest_sum_of);
fma_dispatch!(fn largest_difference(a: &[f64], b: &[f64]) -> f64 => largest_difference_of);

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

/// Refuses a graph that is not square or has a size that is +inf or NaN.
fn check_graph(g: MatRef<'_, f64>) -> Result<(), Error> {
    check_sizes(g, "G")?;
    if g.nrows() != g.ncols() {
        return Err(Error::NotSquare {
            arg: "G",
            rows: g.nrows(),
            cols: g.ncols(),
        });
    }
    Ok(())
}

/// The largest mean weight of a cycle of the graph G (square), by Karp's algorithm (see the
/// module documentation); -inf for a graph without a cycle (and for N = 0).
pub fn max_cycle_mean(g: MatRef<'_, f64>) -> Result<f64, Error> {
    check_graph(g)?;
    cycle_mean_of_rows(&rows_of(g), g.nrows())
}

/// [`max_cycle_mean`] of the checked graph of order n held row by row in `g`.
fn cycle_mean_of_rows(g: &[f64], n: usize) -> Result<f64, Error> {
    if n == 0 {
        return Ok(f64::NEG_INFINITY);
    }
    // walks[k * n + v] = D_k(v).
    let mut walks = vec![f64::NEG_INFINITY; (n + 1) * n];
    walks[..n].fill(0.0);
    for k in 1..=n {
        interrupt::check()?;
        let (done, rest) = walks.split_at_mut(k * n);
        let (previous, next) = (&done[(k - 1) * n..], &mut rest[..n]);
        for (u, &walk) in previous.iter().enumerate() {
            if walk > f64::NEG_INFINITY {
                raise_to(next, walk, &g[u * n..(u + 1) * n]);
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

/// Sweeps of the max-balancing at most (each one pass over the nodes).
pub const SWEEPS: usize = 100;

/// max_ij G[i, j] + e_j - e_i: the log2 of the largest entry under the scaling (-inf for an
/// empty graph). `g` row-major, of order e.len().
/// (Subtracting e_i is monotone in floating point, so it commutes with the row's maximum:
/// max_j (G[i, j] + e_j) - e_i is the same number.)
fn largest_scaled(g: &[f64], exponents: &[f64]) -> f64 {
    let n = exponents.len();
    exponents
        .iter()
        .enumerate()
        .map(|(i, &e_i)| largest_sum(&g[i * n..(i + 1) * n], exponents) - e_i)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Exponents with G[i, j] + e_j - e_i <= bound wherever the graph has no cycle of mean above
/// `bound`: e_i the longest walk from i in G - bound (at least 0), by at most N + 1 rounds of
/// e_i <- max(0, max_j (G[i, j] - bound) + e_j).
fn potentials(g: &[f64], n: usize, bound: f64) -> Result<Vec<f64>, Error> {
    let weights: Vec<f64> = g.iter().map(|&x| x - bound).collect();
    let mut exponents = vec![0.0; n];
    let mut longer = vec![0.0; n];
    for _ in 0..=n {
        interrupt::check()?;
        for (i, value) in longer.iter_mut().enumerate() {
            *value = largest_sum(&weights[i * n..(i + 1) * n], &exponents).max(0.0);
        }
        if longer == exponents {
            break;
        }
        std::mem::swap(&mut exponents, &mut longer);
    }
    Ok(exponents)
}

/// One pass of max-balancing over the nodes 0 .. movable - 1; true if an exponent moved.
///
/// Node i's row entries are G[i, j] + e_j - e_i and its column entries G[j, i] + e_i - e_j
/// (j != i); the best e_i makes the largest of each equal, and is taken (as an integer) only
/// where it lowers the largest entry of the node's row and column. A node with entries on one
/// side only brings their largest to the size of 1 (or to the largest entry of the graph, if
/// that is smaller), so that nothing is left far above or below the rest.
fn sweep(g: &[f64], g_transposed: &[f64], exponents: &mut [f64], movable: usize) -> bool {
    let n = exponents.len();
    let mut changed = false;
    let largest = largest_scaled(g, exponents);
    let ceiling = if largest < 0.0 { largest } else { 0.0 };
    for i in 0..movable {
        // Over j != i: the entries before and after the diagonal.
        let (g_row, g_column) = (&g[i * n..(i + 1) * n], &g_transposed[i * n..(i + 1) * n]);
        let (before, after) = (&exponents[..i], &exponents[i + 1..]);
        let row = largest_sum(&g_row[..i], before).max(largest_sum(&g_row[i + 1..], after));
        let column = largest_difference(&g_column[..i], before)
            .max(largest_difference(&g_column[i + 1..], after));
        let current = exponents[i];
        let best = match (row.is_finite(), column.is_finite()) {
            (true, true) => {
                let middle = (row - column) / 2.0;
                let (mut best, mut best_size) = (current, (row - current).max(column + current));
                for candidate in [middle.floor(), middle.ceil()] {
                    let size = (row - candidate).max(column + candidate);
                    if size < best_size {
                        (best, best_size) = (candidate, size);
                    }
                }
                best
            }
            (true, false) => (row - ceiling).ceil(),
            (false, true) => (ceiling - column).floor(),
            (false, false) => continue,
        };
        if best != current {
            exponents[i] = best;
            changed = true;
        }
    }
    changed
}

/// Integer exponents e of the nodes of G (square, log2 sizes) that bring its largest scaled
/// entry max_ij G[i, j] + e_j - e_i to the least value any scaling reaches, to within one (the
/// rounding to integers), the others evened out below it; and that largest entry (see the
/// module documentation).
///
/// With `outside` the last node is the outside of a model (the rows of B and the columns of
/// C; its exponent 0, left out of the answer); otherwise the exponents are centred on 0 (the
/// scaling of a square matrix alone is unchanged by adding a constant to all of them).
pub fn balancing_exponents(g: MatRef<'_, f64>, outside: bool) -> Result<(Vec<i64>, f64), Error> {
    check_graph(g)?;
    let n = g.nrows();
    let movable = if outside { n.saturating_sub(1) } else { n };
    let g_rows = rows_of(g);
    if !g_rows.iter().any(|x| x.is_finite()) {
        return Ok((vec![0; movable], f64::NEG_INFINITY));
    }
    let least = cycle_mean_of_rows(&g_rows, n)?;
    let mut exponents = if least.is_finite() {
        let bound = least + 1e-9 * (1.0 + least.abs());
        let mut e = potentials(&g_rows, n, bound)?;
        e.iter_mut().for_each(|x| *x = x.round_ties_even());
        e
    } else {
        // No cycle: every entry can be made as small as wished; start unscaled.
        vec![0.0; n]
    };
    if outside {
        let last = exponents[n - 1];
        exponents.iter_mut().for_each(|x| *x -= last);
    }
    let g_transposed = rows_of(g.transpose());
    for _ in 0..SWEEPS {
        interrupt::check()?;
        if !sweep(&g_rows, &g_transposed, &mut exponents, movable) {
            break;
        }
    }
    if !outside && movable > 0 {
        let (high, low) = exponents
            .iter()
            .fold((f64::NEG_INFINITY, f64::INFINITY), |(h, l), &x| {
                (h.max(x), l.min(x))
            });
        let centre = ((high + low) / 2.0).round_ties_even();
        exponents.iter_mut().for_each(|x| *x -= centre);
    }
    let largest = largest_scaled(&g_rows, &exponents);
    Ok((
        exponents[..movable].iter().map(|&x| x as i64).collect(),
        largest,
    ))
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
    fn balancing_reaches_the_cycle_mean_of_a_graded_cascade() {
        // A cycle 0 -> 1 -> 2 -> 3 -> 0 of sizes 2^30, 2^30, 2^30 and 2^-90 (mean 0): states
        // scaled 2^30 apart. The balanced entries are all within one of 2^0.
        let g = mat![
            [0.0, 30.0, NONE, NONE],
            [NONE, 0.0, 30.0, NONE],
            [NONE, NONE, 0.0, 30.0],
            [-90.0, NONE, NONE, 0.0]
        ];
        let (exponents, largest) = balancing_exponents(g.as_ref(), false).unwrap();
        assert_eq!(max_cycle_mean(g.as_ref()).unwrap(), 0.0);
        assert!((0.0..=1.0).contains(&largest), "{largest}");
        let e: Vec<f64> = exponents.iter().map(|&x| x as f64).collect();
        let scaled = (0..4)
            .flat_map(|i| (0..4).map(move |j| (i, j)))
            .filter(|&(i, j)| g[(i, j)] > NONE)
            .map(|(i, j)| g[(i, j)] + e[j] - e[i])
            .fold(NONE, f64::max);
        assert_eq!(scaled, largest);
        // Centred: the exponents span 0 symmetrically (to within one).
        let (high, low) = (
            exponents.iter().max().unwrap(),
            exponents.iter().min().unwrap(),
        );
        assert!((high + low).abs() <= 1, "{exponents:?}");
        // With an outside node (the last) its exponent is 0 and left out.
        let (outside, _) = balancing_exponents(g.as_ref(), true).unwrap();
        assert_eq!(outside.len(), 3);
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
