//! Matrix 1-norms: exact, and estimated by the block algorithm of Higham & Tisseur.
//!
//! The 1-norm ||A||_1 = max_j sum_i |a_ij| (the largest column sum) is the norm of the matrix
//! exponential's degree selection and, later, of condition estimates. Three tools:
//!
//! * [`one_norm`]: the exact norm, O(n^2).
//! * [`absolute_power_norm`]: the exact norm of a power of |A| (entrywise absolute value), by
//!   row-vector products: for B >= 0, ||B^p||_1 = max(1^T B^p), so O(p n^2) instead of the
//!   O(n^3 log p) of forming the power.
//! * [`one_norm_estimate`]: a lower bound of ||Op||_1 for any operator that can be applied to an
//!   n x t block and to its transpose, by Algorithm 2.4 of N. J. Higham and F. Tisseur, "A block
//!   algorithm for matrix 1-norm estimation, with an application to 1-norm pseudospectra",
//!   SIAM J. Matrix Anal. Appl. 21(4), 2000, pp. 1185-1201. With t = 2 columns the estimate is
//!   exact in the large majority of cases and rarely more than a factor 3 low (their Table 6.1);
//!   each iteration costs two applications of the operator to an n x t block, so estimating the
//!   norm of a product of k n x n matrices costs O(k t n^2) instead of the O(k n^3) of forming it.

use crate::linalg::lu::Lu;
use crate::platform::interrupt;
use crate::platform::pool::scratch;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// Matrices of up to this many entries take [`frobenius_norm`]'s plain sum of squares.
const PLAIN_FROBENIUS_MAX_ENTRIES: usize = 256;

/// The Frobenius norm ||A||_F = sqrt(sum a_ij^2). Small matrices (the 4-state Riccati solve
/// takes seven such norms) use a plain sum of squares when it stays in the normal range:
/// relative error at most about (mn/2 + 1) u, which is all a scale or a residual needs, where
/// faer's pairwise sum costs more to set up than the arithmetic. Larger matrices use faer's
/// `norm_l2`, and matrices whose squares leave the range [`vector_norm`].
pub fn frobenius_norm(a: MatRef<'_, f64>) -> f64 {
    if a.nrows() * a.ncols() <= PLAIN_FROBENIUS_MAX_ENTRIES {
        let mut squares = 0.0;
        for j in 0..a.ncols() {
            for x in a.col(j).iter() {
                squares += x * x;
            }
        }
        if (f64::MIN_POSITIVE..f64::MAX).contains(&squares) {
            return squares.sqrt();
        }
    }
    // faer's sum for entries whose squares stay in range; otherwise the scaled sum (faer's
    // overflowed to inf for entries near 1e154, and a Hamiltonian's axis margin with it).
    let largest = max_abs(a);
    if (VECTOR_RANGE_LOW..=VECTOR_RANGE_HIGH).contains(&largest) {
        return a.norm_l2();
    }
    let (rows, cols) = (a.nrows(), a.ncols());
    vector_norm((0..rows * cols).map(move |k| a[(k % rows, k / rows)]))
}

/// The Euclidean norm of a vector of finite entries, without overflow or underflow in its
/// squares (as LAPACK's dnrm2): a plain sum of squares when the largest entry is within
/// 2^±500, where no square overflows and those that underflow are below u times the largest;
/// otherwise the sum for the entries divided by the power of two nearest the largest (exact),
/// multiplied back. A vector of entries near 1e-170 has its norm, not 0.
pub fn vector_norm(x: impl Iterator<Item = f64> + Clone) -> f64 {
    let largest = x.clone().fold(0.0f64, |m, v| m.max(v.abs()));
    if largest == 0.0 || (VECTOR_RANGE_LOW..=VECTOR_RANGE_HIGH).contains(&largest) {
        return x.map(|v| v * v).sum::<f64>().sqrt();
    }
    // 2^±1000 at most: 1 / 2^-1074 would overflow.
    let exponent = largest.log2().round().clamp(-1000.0, 1000.0);
    let (down, up) = ((-exponent).exp2(), exponent.exp2());
    x.map(|v| (v * down) * (v * down)).sum::<f64>().sqrt() * up
}

/// The range of the largest entry in which [`vector_norm`] sums squares unscaled.
const VECTOR_RANGE_LOW: f64 = 3.054936363499605e-151; // 2^-500
const VECTOR_RANGE_HIGH: f64 = 3.273390607896142e150; // 2^500

/// The larger of a and b, NaN if either is: a norm of a matrix with a NaN entry is NaN, not
/// the norm of its other entries (`f64::max` drops NaN).
fn max_or_nan(a: f64, b: f64) -> f64 {
    if b > a || b.is_nan() { b } else { a }
}

/// The exact 1-norm, max_j sum_i |a_ij|: plain column sums up to
/// `PLAIN_FROBENIUS_MAX_ENTRIES` entries, faer's vectorised ones beyond. NaN if an entry is.
pub fn one_norm(a: MatRef<'_, f64>) -> f64 {
    if a.nrows() * a.ncols() <= PLAIN_FROBENIUS_MAX_ENTRIES {
        (0..a.ncols())
            .map(|j| a.col(j).iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, max_or_nan)
    } else {
        (0..a.ncols())
            .map(|j| a.col(j).norm_l1())
            .fold(0.0, max_or_nan)
    }
}

/// An upper bound on ||T^-1||_inf of a triangular T (upper, or lower with `lower`) from its
/// comparison matrix M(T), |t_ii| on the diagonal and -|t_ij| off it: |T^-1| <= M(T)^-1
/// entrywise, so ||T^-1||_inf <= ||M(T)^-1 e||_inf with e the vector of ones (Higham,
/// Accuracy and Stability of Numerical Algorithms, 2nd ed., §8.3), one column-oriented
/// substitution of O(n^2) in nonnegative terms. Equal to ||T^-1||_inf when T = M(T); may
/// exceed it by up to 2^(n-1) (Higham's Theorem 8.12 case), so a certificate, not an estimate.
/// Infinite for a zero (or NaN) on the diagonal.
pub fn triangular_inverse_norm_bound(t: MatRef<'_, f64>, lower: bool) -> f64 {
    let n = t.nrows();
    let mut y = vec![1.0; n];
    if lower {
        for j in 0..n {
            y[j] /= t[(j, j)].abs();
            let (yj, column) = (y[j], t.col(j));
            for i in j + 1..n {
                y[i] += column[i].abs() * yj;
            }
        }
    } else {
        for j in (0..n).rev() {
            y[j] /= t[(j, j)].abs();
            let (yj, column) = (y[j], t.col(j));
            for i in 0..j {
                y[i] += column[i].abs() * yj;
            }
        }
    }
    if y.iter().any(|v| v.is_nan()) {
        return f64::INFINITY; // 0 x inf after a zero pivot
    }
    y.iter().fold(0.0, |m: f64, &v| m.max(v))
}

/// The largest magnitude max |a_ij| (0 for an empty matrix): a plain scan up to
/// `PLAIN_FROBENIUS_MAX_ENTRIES` entries, where faer's vectorised reduction costs more to
/// set up than the scan (the 4-state Riccati solve takes five), faer's `norm_max` beyond.
/// For finite matrices.
pub fn max_abs(a: MatRef<'_, f64>) -> f64 {
    if a.nrows() * a.ncols() <= PLAIN_FROBENIUS_MAX_ENTRIES {
        (0..a.ncols())
            .flat_map(|j| a.col(j).iter().map(|x| x.abs()))
            .fold(0.0, f64::max)
    } else {
        a.norm_max()
    }
}

/// ||(|A| / scale)^p||_1, exactly, for square A: for B = |A| / scale >= 0 entrywise, every
/// column sum of B^p is an entry of the row vector 1^T B^p, so ||B^p||_1 = max(1^T B^p): p
/// vector-matrix products (faer's, vectorised), O(p n^2), instead of forming the power.
/// Choosing scale = ||A||_1 keeps every entry of B^p at most 1, so the iteration cannot
/// overflow.
pub fn absolute_power_norm(a: MatRef<'_, f64>, scale: f64, p: usize) -> f64 {
    let n = a.nrows();
    debug_assert_eq!(n, a.ncols());
    let inverse = 1.0 / scale;
    let mut b = scratch(n, n);
    for j in 0..n {
        for (x, i) in b.col_as_slice_mut(j).iter_mut().zip(0..n) {
            *x = a[(i, j)].abs() * inverse;
        }
    }
    // The row vector is kept as a column v, and v <- B^T v.
    let mut v = scratch(n, 1);
    let mut next = scratch(n, 1);
    v.fill(1.0);
    for _ in 0..p {
        matmul(
            next.as_mut(),
            Accum::Replace,
            b.transpose(),
            v.as_ref(),
            1.0,
            Par::Seq,
        );
        std::mem::swap(&mut v, &mut next);
    }
    v.col_as_slice(0).iter().copied().fold(0.0, f64::max)
}

/// A square linear operator known only through its action on blocks of vectors.
pub trait LinearOperator {
    /// The order n of the operator.
    fn dim(&self) -> usize;
    /// `out = Op * x` for an n x t block `x`.
    fn apply(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>);
    /// `out = Op^T * x` for an n x t block `x`.
    fn apply_transpose(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>);
}

/// The product F_1 F_2 ... F_k of square matrices of one order, never formed explicitly.
pub struct MatrixProduct<'a> {
    factors: Vec<MatRef<'a, f64>>,
}

impl<'a> MatrixProduct<'a> {
    /// The product of `factors`, in order; all must be square of one order.
    pub fn new(factors: Vec<MatRef<'a, f64>>) -> Self {
        assert!(!factors.is_empty(), "a product needs at least one factor");
        let n = factors[0].nrows();
        assert!(
            factors.iter().all(|f| f.nrows() == n && f.ncols() == n),
            "the factors of a product must be square of one order"
        );
        Self { factors }
    }
}

impl MatrixProduct<'_> {
    /// out = G_1 (G_2 (... (G_k x))) for the factors G in the order given, sequentially and
    /// through two scratch blocks (faer's `*` operator would use the global thread pool, whose
    /// start-up dwarfs products of n x 2 blocks).
    fn apply_factors<'b>(
        factors: impl DoubleEndedIterator<Item = MatRef<'b, f64>>,
        x: MatRef<'_, f64>,
        mut out: MatMut<'_, f64>,
    ) {
        let (n, t) = (x.nrows(), x.ncols());
        let mut current = scratch(n, t);
        let mut next = scratch(n, t);
        current.copy_from(x);
        for factor in factors.rev() {
            matmul(
                next.as_mut(),
                Accum::Replace,
                factor,
                current.as_ref(),
                1.0,
                Par::Seq,
            );
            std::mem::swap(&mut current, &mut next);
        }
        out.copy_from(current.as_ref());
    }
}

impl LinearOperator for MatrixProduct<'_> {
    fn dim(&self) -> usize {
        self.factors[0].nrows()
    }

    fn apply(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>) {
        // F_1 (F_2 (... (F_k x))): apply the factors right to left.
        Self::apply_factors(self.factors.iter().copied(), x, out);
    }

    fn apply_transpose(&self, x: MatRef<'_, f64>, out: MatMut<'_, f64>) {
        // (F_1 ... F_k)^T x = F_k^T (... (F_1^T x)): the transposes, left to right.
        Self::apply_factors(self.factors.iter().rev().map(|f| f.transpose()), x, out);
    }
}

/// A^-1 as an operator, applied through the LU factors of A (for [`one_norm_estimate`] of
/// ||A^-1||_1 at O(n^2) a step).
pub struct Inverse<'a>(pub &'a Lu);

impl LinearOperator for Inverse<'_> {
    fn dim(&self) -> usize {
        self.0.nrows()
    }

    fn apply(&self, x: MatRef<'_, f64>, mut out: MatMut<'_, f64>) {
        out.copy_from(x);
        // A few columns: one panel, which runs to its end.
        let _uninterrupted = interrupt::within_ref(None, || self.0.solve_in_place(out));
    }

    fn apply_transpose(&self, x: MatRef<'_, f64>, mut out: MatMut<'_, f64>) {
        out.copy_from(x);
        let _uninterrupted = interrupt::within_ref(None, || self.0.solve_transpose_in_place(out));
    }
}

/// The maximum number of iterations of the estimator (Higham & Tisseur use 5).
const ESTIMATOR_MAX_ITERATIONS: usize = 5;

/// A deterministic source of random signs (SplitMix64), so that estimates are reproducible.
struct RandomSigns(u64);

impl RandomSigns {
    fn next_sign(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        if z & 1 == 0 { 1.0 } else { -1.0 }
    }
}

/// Two vectors of +-1 entries are parallel when |x^T y| = n.
fn parallel(x: &[f64], y: &[f64]) -> bool {
    let dot: f64 = x.iter().zip(y).map(|(a, b)| a * b).sum();
    dot.abs() == x.len() as f64
}

fn column(m: &Mat<f64>, j: usize) -> Vec<f64> {
    (0..m.nrows()).map(|i| m[(i, j)]).collect()
}

/// A lower bound of ||op||_1 by the block 1-norm estimator with `t` columns (Higham & Tisseur
/// 2000, Algorithm 2.4). For n <= 4 or t >= n the norm is computed exactly by applying the
/// operator to the identity.
pub fn one_norm_estimate(op: &dyn LinearOperator, t: usize) -> f64 {
    let n = op.dim();
    if n == 0 {
        return 0.0;
    }
    let t = t.max(1);
    if n <= 4 || t >= n {
        let mut image = Mat::<f64>::zeros(n, n);
        op.apply(Mat::<f64>::identity(n, n).as_ref(), image.as_mut());
        return one_norm(image.as_ref());
    }

    let mut signs = RandomSigns(0x005E_ED0F_A3C0_u64);
    // Starting block: the first column is the vector of ones, the others random +-1 columns not
    // parallel to an earlier one; all scaled to unit 1-norm.
    let mut x = Mat::<f64>::zeros(n, t);
    for i in 0..n {
        x[(i, 0)] = 1.0;
    }
    for j in 1..t {
        loop {
            for i in 0..n {
                x[(i, j)] = signs.next_sign();
            }
            let candidate = column(&x, j);
            if !(0..j).any(|k| parallel(&candidate, &column(&x, k))) {
                break;
            }
        }
    }
    for j in 0..t {
        for i in 0..n {
            x[(i, j)] /= n as f64;
        }
    }

    let mut y = Mat::<f64>::zeros(n, t);
    let mut z = Mat::<f64>::zeros(n, t);
    let mut s = Mat::<f64>::zeros(n, t);
    let mut s_old: Option<Mat<f64>> = None;
    let mut estimate_old = 0.0;
    let mut index_best: Option<usize> = None;
    let mut indices: Vec<usize> = (0..n).collect();
    let mut history: Vec<usize> = Vec::new();
    let mut estimate = 0.0;

    for iteration in 1.. {
        op.apply(x.as_ref(), y.as_mut());
        let column_norms: Vec<f64> = (0..t)
            .map(|j| (0..n).map(|i| y[(i, j)].abs()).sum())
            .collect();
        let (best_column, &best_norm) = column_norms
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .expect("t >= 1");
        estimate = best_norm;
        if estimate > estimate_old || iteration == 2 {
            // In the first iteration the columns of X are not unit vectors; only later ones are.
            if iteration >= 2 {
                index_best = Some(indices[best_column]);
            }
        }
        // (1) No improvement: the previous estimate stands.
        if iteration >= 2 && estimate <= estimate_old {
            estimate = estimate_old;
            break;
        }
        estimate_old = estimate;
        if iteration > ESTIMATOR_MAX_ITERATIONS {
            break;
        }
        for j in 0..t {
            for i in 0..n {
                s[(i, j)] = if y[(i, j)] >= 0.0 { 1.0 } else { -1.0 };
            }
        }
        // (2) Every column of S parallel to a column of S_old: converged.
        if let Some(previous) = &s_old {
            let all_parallel = (0..t).all(|j| {
                let sj = column(&s, j);
                (0..t).any(|k| parallel(&sj, &column(previous, k)))
            });
            if all_parallel {
                break;
            }
        }
        // (3) Replace columns of S parallel to an earlier column of S or to one of S_old.
        if t > 1 {
            for j in 0..t {
                let mut attempts = 0;
                loop {
                    let sj = column(&s, j);
                    let repeated = (0..j).any(|k| parallel(&sj, &column(&s, k)))
                        || s_old
                            .as_ref()
                            .is_some_and(|p| (0..t).any(|k| parallel(&sj, &column(p, k))));
                    // Give up resampling after n tries (possible only for tiny n).
                    if !repeated || attempts >= n {
                        break;
                    }
                    for i in 0..n {
                        s[(i, j)] = signs.next_sign();
                    }
                    attempts += 1;
                }
            }
        }
        op.apply_transpose(s.as_ref(), z.as_mut());
        let h: Vec<f64> = (0..n)
            .map(|i| (0..t).map(|j| z[(i, j)].abs()).fold(0.0, f64::max))
            .collect();
        let h_max = h.iter().copied().fold(0.0, f64::max);
        // (4) The largest gradient entry is at the best index already tried: converged.
        if iteration >= 2 && index_best.is_some_and(|best| h[best] == h_max) {
            break;
        }
        indices = (0..n).collect();
        indices.sort_by(|&a, &b| h[b].total_cmp(&h[a]));
        if t > 1 {
            // (5) The t most promising unit vectors were all tried before: converged.
            if indices[..t].iter().all(|i| history.contains(i)) {
                break;
            }
            let fresh: Vec<usize> = indices
                .iter()
                .copied()
                .filter(|i| !history.contains(i))
                .take(t)
                .collect();
            let rest: Vec<usize> = indices
                .iter()
                .copied()
                .filter(|i| !fresh.contains(i))
                .collect();
            indices = fresh.into_iter().chain(rest).collect();
        }
        x.fill(0.0);
        for j in 0..t.min(n) {
            x[(indices[j], j)] = 1.0;
        }
        history.extend_from_slice(&indices[..t.min(n)]);
        s_old = Some(s.clone());
    }
    estimate
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::DenseSolveCore;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn random_matrix(n: usize, rng: &mut StdRng) -> Mat<f64> {
        Mat::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0))
    }

    /// ||T^-1||_inf from T's inverse by faer's LU (a triangular T: exact up to rounding).
    fn inverse_infinity_norm(t: &Mat<f64>) -> f64 {
        let inverse = t.partial_piv_lu().inverse();
        one_norm(inverse.transpose())
    }

    #[test]
    fn the_comparison_matrix_bound_holds_and_is_exact_for_an_m_matrix() {
        let mut rng = StdRng::seed_from_u64(21);
        for n in [1usize, 2, 5, 16, 40] {
            for lower in [false, true] {
                let inside = |i: usize, j: usize| if lower { i >= j } else { i <= j };
                let t = Mat::from_fn(n, n, |i, j| {
                    if i == j {
                        rng.random_range(0.5..2.0) * if rng.random_bool(0.5) { 1.0 } else { -1.0 }
                    } else if inside(i, j) {
                        rng.random_range(-1.0..1.0)
                    } else {
                        0.0
                    }
                });
                let exact = inverse_infinity_norm(&t);
                let bound = triangular_inverse_norm_bound(t.as_ref(), lower);
                assert!(bound >= exact * (1.0 - 1e-8), "n = {n}: {bound} < {exact}");
                // M(T) itself: its inverse is nonnegative, and the bound is its norm.
                let m = Mat::from_fn(n, n, |i, j| {
                    if i == j {
                        t[(i, j)].abs()
                    } else {
                        -t[(i, j)].abs()
                    }
                });
                let exact = inverse_infinity_norm(&m);
                let bound = triangular_inverse_norm_bound(m.as_ref(), lower);
                // Both within rounding: the inverse by LU errs by about κ u (κ up to 1e7 here).
                assert!(
                    (bound - exact).abs() <= 1e-8 * exact,
                    "n = {n}: {bound} != {exact}"
                );
            }
        }
        let mut singular = Mat::<f64>::identity(3, 3);
        singular[(1, 1)] = 0.0;
        singular[(0, 1)] = 0.0;
        assert_eq!(
            triangular_inverse_norm_bound(singular.as_ref(), false),
            f64::INFINITY
        );
        assert_eq!(
            triangular_inverse_norm_bound(Mat::<f64>::zeros(0, 0).as_ref(), true),
            0.0
        );
    }

    #[test]
    fn frobenius_norm_agrees_with_faer_and_survives_extreme_scales() {
        let mut rng = StdRng::seed_from_u64(11);
        for n in [1usize, 4, 8, 16, 17] {
            let a = random_matrix(n, &mut rng);
            let (ours, faer) = (frobenius_norm(a.as_ref()), a.norm_l2());
            assert!((ours - faer).abs() <= 1e-14 * faer, "n = {n}");
            // Squares that overflow or underflow go to faer's scaled sum.
            for scale in [1e200, 1e-200] {
                let scaled = &a * faer::Scale(scale);
                let expected = faer * scale;
                let got = frobenius_norm(scaled.as_ref());
                assert!(
                    (got - expected).abs() <= 1e-13 * expected,
                    "n = {n}, {scale:e}"
                );
            }
        }
        assert_eq!(frobenius_norm(Mat::<f64>::zeros(3, 3).as_ref()), 0.0);
        assert_eq!(frobenius_norm(Mat::<f64>::zeros(0, 2).as_ref()), 0.0);
        let mut nan = Mat::<f64>::identity(2, 2);
        nan[(0, 1)] = f64::NAN;
        assert!(frobenius_norm(nan.as_ref()).is_nan());
    }

    #[test]
    fn small_and_large_matrices_give_the_same_max_and_one_norms() {
        let mut rng = StdRng::seed_from_u64(12);
        // 16 x 16 is the last plain scan, 17 x 17 the first of faer's reductions.
        for n in [1usize, 3, 16, 17] {
            let a = random_matrix(n, &mut rng);
            assert_eq!(max_abs(a.as_ref()), a.norm_max(), "n = {n}");
            // The reference sums each column from the bottom up, unlike either path.
            let column_sums = (0..n)
                .map(|j| (0..n).rev().map(|i| a[(i, j)].abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let ours = one_norm(a.as_ref());
            assert!((ours - column_sums).abs() <= 1e-14 * column_sums, "n = {n}");
            // A NaN entry makes the norm NaN in both paths (it once hid its column: a
            // singular solve then looked well-conditioned).
            let mut with_nan = a.clone();
            with_nan[(n / 2, 0)] = f64::NAN;
            assert!(one_norm(with_nan.as_ref()).is_nan(), "n = {n}");
        }
        let a = faer::mat![[1.0, -7.5], [3.0, 2.0]];
        assert_eq!(max_abs(a.as_ref()), 7.5);
        assert_eq!(one_norm(a.as_ref()), 9.5);
        assert_eq!(max_abs(Mat::<f64>::zeros(0, 3).as_ref()), 0.0);
        assert_eq!(one_norm(Mat::<f64>::zeros(0, 3).as_ref()), 0.0);
    }

    #[test]
    fn exact_norm_is_the_largest_column_sum() {
        let a = Mat::from_fn(2, 3, |i, j| [[1.0, -7.0, 2.0], [-3.0, 1.0, 2.0]][i][j]);
        assert_eq!(one_norm(a.as_ref()), 8.0);
        assert_eq!(one_norm(Mat::<f64>::zeros(0, 0).as_ref()), 0.0);
    }

    #[test]
    fn absolute_power_norm_equals_the_formed_power() {
        let mut rng = StdRng::seed_from_u64(11);
        for n in [1, 3, 8, 17] {
            let a = random_matrix(n, &mut rng);
            let scale = 0.5;
            let abs = Mat::from_fn(n, n, |i, j| a[(i, j)].abs() / scale);
            let mut power = Mat::<f64>::identity(n, n);
            for p in 0..9 {
                let expected = one_norm(power.as_ref());
                let got = absolute_power_norm(a.as_ref(), scale, p);
                assert!(
                    (got - expected).abs() <= 1e-13 * expected.max(1.0),
                    "n={n} p={p}: {got} vs {expected}"
                );
                power = &abs * &power;
            }
        }
    }

    #[test]
    fn estimate_is_a_lower_bound_and_usually_close() {
        // Products of two dense random matrices have many columns of nearly equal norm, a hard
        // case: scipy's onenormest (same algorithm) is exact on 44% of these and within 7% on
        // average.
        let mut rng = StdRng::seed_from_u64(7);
        let mut exact_count = 0;
        let mut ratio_sum = 0.0;
        let trials = 60;
        for trial in 0..trials {
            let n = [5, 12, 40, 100][trial % 4];
            let a = random_matrix(n, &mut rng);
            let b = random_matrix(n, &mut rng);
            let exact = one_norm((&a * &b).as_ref());
            let estimate = one_norm_estimate(&MatrixProduct::new(vec![a.as_ref(), b.as_ref()]), 2);
            assert!(estimate <= exact * (1.0 + 1e-14), "estimate above the norm");
            // Higham & Tisseur (Table 6.1): t = 2 is rarely worse than a factor 3 low.
            assert!(estimate >= exact / 3.0, "n={n}: {estimate} vs {exact}");
            if (estimate - exact).abs() <= 1e-12 * exact {
                exact_count += 1;
            }
            ratio_sum += estimate / exact;
        }
        assert!(
            exact_count * 10 >= trials * 3,
            "exact in only {exact_count} of {trials}"
        );
        assert!(
            ratio_sum / trials as f64 >= 0.9,
            "mean ratio {}",
            ratio_sum / trials as f64
        );
    }

    #[test]
    fn estimate_finds_a_single_large_column() {
        // The norm is carried by one column that the starting vector of ones averages away.
        let n = 50;
        let mut a = Mat::<f64>::zeros(n, n);
        for i in 0..n {
            a[(i, 31)] = if i % 2 == 0 { 1.0 } else { -1.0 };
            a[(i, i)] += 1e-3;
        }
        let exact = one_norm(a.as_ref());
        let estimate = one_norm_estimate(&MatrixProduct::new(vec![a.as_ref()]), 2);
        assert!(
            (estimate - exact).abs() <= 1e-12 * exact,
            "{estimate} vs {exact}"
        );
    }

    #[test]
    fn small_operators_are_normed_exactly() {
        let mut rng = StdRng::seed_from_u64(3);
        for n in 1..=4 {
            let a = random_matrix(n, &mut rng);
            let estimate = one_norm_estimate(&MatrixProduct::new(vec![a.as_ref()]), 2);
            assert!((estimate - one_norm(a.as_ref())).abs() <= 1e-15 * n as f64);
        }
    }

    #[test]
    fn estimate_finds_the_norm_of_a_rank_one_product() {
        // u v^T has 1-norm max|v| * ||u||_1 and the estimator finds it exactly.
        let n = 30;
        let u: Vec<f64> = (0..n).map(|i| (i as f64 - 10.0) / 7.0).collect();
        let v: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64 - 5.0).collect();
        let a = Mat::from_fn(n, n, |i, j| u[i] * v[j]);
        let identity = Mat::<f64>::identity(n, n);
        let estimate =
            one_norm_estimate(&MatrixProduct::new(vec![a.as_ref(), identity.as_ref()]), 2);
        let expected = u.iter().map(|x| x.abs()).sum::<f64>() * 5.0;
        assert!((estimate - expected).abs() <= 1e-12 * expected);
    }

    #[test]
    fn vector_norms_of_any_magnitude() {
        for scale in [1e-320, 1e-300, 1e-170, 1e-150, 1.0, 1e150, 1e170, 1e300] {
            let x = [3.0 * scale, -4.0 * scale, 0.0];
            let norm = vector_norm(x.iter().copied());
            let expected = 5.0 * scale;
            let tolerance = if scale < f64::MIN_POSITIVE {
                1e-3
            } else {
                4.0 * f64::EPSILON
            };
            assert!(
                (norm - expected).abs() <= tolerance * expected,
                "{scale:e}: {norm:e}"
            );
        }
        assert_eq!(vector_norm([1e308, 1e308].into_iter()), 1e308 * 2f64.sqrt());
        assert_eq!(vector_norm([0.0, 0.0].into_iter()), 0.0);
        assert_eq!(vector_norm([1.0, 1e-170].into_iter()), 1.0);
    }
}
