//! Square matrices of a fixed small order N, on the stack.
//!
//! Flight-dynamics models are small (4 states for each of the longitudinal and lateral motions,
//! 8 to 12 for coupled or augmented models), and many algorithms here run thousands of them in
//! a sweep. At these orders the cost of a general-order library call (dispatch, allocation,
//! blocking decisions) exceeds the arithmetic: a 4 x 4 product costs 23 ns through faer and
//! 7 ns as a fixed-size loop. This type gives the compiler constant trip counts, so its loops
//! unroll and vectorise, and it allocates nothing. Larger orders use faer.
//!
//! Each kernel is compiled twice: for the baseline target and, on x86-64, for AVX2 with fused
//! multiply-add, chosen at run time by the CPU's features (see `dispatch.rs`), so that one
//! portable wheel runs at full speed on current CPUs. (Fused multiply-adds round once instead of
//! twice, so the two variants can differ in the last bit.)
//!
//! Storage is row-major, `rows[i][j]` = a_ij. The LU solve uses partial pivoting and divides
//! by the pivots (as LAPACK's dgetrs does) rather than multiplying by reciprocals.

use faer::{Mat, MatRef};

use crate::platform::dispatch::{fma_dispatch, multiply_add};

type Rows<const N: usize> = [[f64; N]; N];

/// out += lhs * rhs, each row of the result a sum of scaled rows of rhs.
#[inline(always)]
fn add_product_kernel<const N: usize, const FMA: bool>(
    lhs: &Rows<N>,
    rhs: &Rows<N>,
    out: &mut Rows<N>,
) {
    for (out_row, lhs_row) in out.iter_mut().zip(lhs) {
        for (&coefficient, rhs_row) in lhs_row.iter().zip(rhs) {
            for (o, &r) in out_row.iter_mut().zip(rhs_row) {
                *o = multiply_add::<FMA>(coefficient, r, *o);
            }
        }
    }
}

fma_dispatch!(fn add_product<const N: usize>(lhs: &Rows<N>, rhs: &Rows<N>, out: &mut Rows<N>) => add_product_kernel);

/// identity * I + sum_k coefficient_k * M_k.
#[inline(always)]
fn combination_kernel<const N: usize, const FMA: bool>(
    identity: f64,
    terms: &[(f64, &SmallMatrix<N>)],
) -> Rows<N> {
    let (&(first_coefficient, first), rest) = terms.split_first().expect("at least one term");
    let mut out = [[0.0; N]; N];
    for (out_row, row) in out.iter_mut().zip(&first.rows) {
        for (o, &v) in out_row.iter_mut().zip(row) {
            *o = first_coefficient * v;
        }
    }
    for &(coefficient, m) in rest {
        for (out_row, row) in out.iter_mut().zip(&m.rows) {
            for (o, &v) in out_row.iter_mut().zip(row) {
                *o = multiply_add::<FMA>(coefficient, v, *o);
            }
        }
    }
    for (i, row) in out.iter_mut().enumerate() {
        row[i] += identity;
    }
    out
}

fma_dispatch!(fn combination<const N: usize>(identity: f64, terms: &[(f64, &SmallMatrix<N>)]) -> Rows<N> => combination_kernel);

/// ||(|A| / scale)^p||_1 by p row-vector products (for B >= 0, ||B^p||_1 = max 1^T B^p).
#[inline(always)]
fn absolute_power_norm_kernel<const N: usize, const FMA: bool>(
    a: &Rows<N>,
    scale: f64,
    p: usize,
) -> f64 {
    let inverse = 1.0 / scale;
    let mut b = [[0.0; N]; N];
    for (b_row, row) in b.iter_mut().zip(a) {
        for (x, value) in b_row.iter_mut().zip(row) {
            *x = value.abs() * inverse;
        }
    }
    let mut vector = [1.0; N];
    for _ in 0..p {
        let mut next = [0.0; N];
        for (&weight, b_row) in vector.iter().zip(&b) {
            for (n, &x) in next.iter_mut().zip(b_row) {
                *n = multiply_add::<FMA>(weight, x, *n);
            }
        }
        vector = next;
    }
    vector.into_iter().fold(0.0, f64::max)
}

fma_dispatch!(fn absolute_power_norm<const N: usize>(a: &Rows<N>, scale: f64, p: usize) -> f64 => absolute_power_norm_kernel);

/// Gaussian elimination with partial pivoting in place: the unit lower factor below the
/// diagonal, the upper factor on and above it; row k was swapped with row `pivots[k]`.
#[inline(always)]
fn lu_kernel<const N: usize, const FMA: bool>(a: &mut Rows<N>, pivots: &mut [usize; N]) {
    for k in 0..N {
        let mut pivot_row = k;
        for i in k + 1..N {
            if a[i][k].abs() > a[pivot_row][k].abs() {
                pivot_row = i;
            }
        }
        pivots[k] = pivot_row;
        a.swap(k, pivot_row);
        let pivot = a[k][k];
        let (upper, lower) = a.split_at_mut(k + 1);
        let pivot_row_values = &upper[k];
        for row in lower.iter_mut() {
            let factor = row[k] / pivot;
            row[k] = factor;
            for j in k + 1..N {
                row[j] = multiply_add::<FMA>(-factor, pivot_row_values[j], row[j]);
            }
        }
    }
}

fma_dispatch!(fn lu_in_place<const N: usize>(a: &mut Rows<N>, pivots: &mut [usize; N]) => lu_kernel);

/// Solves with the factors of [`lu_kernel`] for N right-hand sides in place.
#[inline(always)]
fn lu_solve_kernel<const N: usize, const FMA: bool>(
    lu: &Rows<N>,
    pivots: &[usize; N],
    rhs: &mut Rows<N>,
) {
    for (k, &pivot_row) in pivots.iter().enumerate() {
        rhs.swap(k, pivot_row);
    }
    // Forward substitution with the unit lower factor.
    for k in 0..N {
        let (done, rest) = rhs.split_at_mut(k + 1);
        let solved = &done[k];
        for (i, row) in rest.iter_mut().enumerate() {
            let factor = lu[k + 1 + i][k];
            for (x, &s) in row.iter_mut().zip(solved) {
                *x = multiply_add::<FMA>(-factor, s, *x);
            }
        }
    }
    // Back substitution with the upper factor, dividing by each pivot.
    for k in (0..N).rev() {
        let pivot = lu[k][k];
        for x in &mut rhs[k] {
            *x /= pivot;
        }
        let (above, from_k) = rhs.split_at_mut(k);
        let solved = &from_k[0];
        for (i, row) in above.iter_mut().enumerate() {
            let factor = lu[i][k];
            for (x, &s) in row.iter_mut().zip(solved) {
                *x = multiply_add::<FMA>(-factor, s, *x);
            }
        }
    }
}

fma_dispatch!(fn lu_solve<const N: usize>(lu: &Rows<N>, pivots: &[usize; N], rhs: &mut Rows<N>) => lu_solve_kernel);

/// Products of at most this many multiply-adds are formed by [`product`]'s plain loop: below
/// it faer's dispatch and blocking decisions cost more than the arithmetic.
const LOOP_PRODUCT_MAX_WORK: usize = 16 * 16 * 16;

/// lhs * rhs for matrices of any (conforming) shapes and strides: a plain column-by-column
/// loop when the product is small (the Riccati and Lyapunov solvers form a dozen products of
/// order n and m at n = 4), faer's blocked kernel otherwise.
pub fn product(lhs: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> Mat<f64> {
    let (rows, inner, cols) = (lhs.nrows(), lhs.ncols(), rhs.ncols());
    debug_assert_eq!(inner, rhs.nrows());
    if rows * inner * cols > LOOP_PRODUCT_MAX_WORK {
        return lhs * rhs;
    }
    let mut out = Mat::<f64>::zeros(rows, cols);
    for j in 0..cols {
        let column = out.col_as_slice_mut(j);
        for k in 0..inner {
            let coefficient = rhs[(k, j)];
            // Contiguous columns (faer's own matrices) as slices: no per-entry index checks.
            match lhs.col(k).try_as_col_major() {
                Some(lhs_column) => {
                    for (entry, x) in column.iter_mut().zip(lhs_column.as_slice()) {
                        *entry += x * coefficient;
                    }
                }
                None => {
                    for (i, entry) in column.iter_mut().enumerate() {
                        *entry += lhs[(i, k)] * coefficient;
                    }
                }
            }
        }
    }
    out
}

/// An N x N matrix stored on the stack, row-major.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmallMatrix<const N: usize> {
    pub rows: [[f64; N]; N],
}

impl<const N: usize> SmallMatrix<N> {
    /// The zero matrix.
    pub const fn zeros() -> Self {
        Self {
            rows: [[0.0; N]; N],
        }
    }

    /// The identity matrix.
    pub fn identity() -> Self {
        let mut m = Self::zeros();
        for i in 0..N {
            m.rows[i][i] = 1.0;
        }
        m
    }

    /// Copies an N x N faer matrix (any strides).
    pub fn from_ref(a: MatRef<'_, f64>) -> Self {
        debug_assert_eq!((a.nrows(), a.ncols()), (N, N));
        let mut m = Self::zeros();
        for i in 0..N {
            for j in 0..N {
                m.rows[i][j] = a[(i, j)];
            }
        }
        m
    }

    /// A new faer matrix holding the same values.
    pub fn to_mat(&self) -> Mat<f64> {
        Mat::from_fn(N, N, |i, j| self.rows[i][j])
    }

    /// self * rhs.
    pub fn product(&self, rhs: &Self) -> Self {
        let mut out = Self::zeros();
        add_product(&self.rows, &rhs.rows, &mut out.rows);
        out
    }

    /// self += lhs * rhs.
    pub fn add_product(&mut self, lhs: &Self, rhs: &Self) {
        add_product(&lhs.rows, &rhs.rows, &mut self.rows);
    }

    /// identity * I + sum_k coefficient_k * M_k, for at least one term.
    pub fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self {
        Self {
            rows: combination(identity, terms),
        }
    }

    /// Whether every entry below the diagonal is zero.
    pub fn is_upper_triangular(&self) -> bool {
        self.rows
            .iter()
            .enumerate()
            .all(|(i, row)| row[..i].iter().all(|&v| v == 0.0))
    }

    /// Whether every entry above the diagonal is zero.
    pub fn is_lower_triangular(&self) -> bool {
        self.rows
            .iter()
            .enumerate()
            .all(|(i, row)| row[i + 1..].iter().all(|&v| v == 0.0))
    }

    /// The transpose.
    pub fn transpose(&self) -> Self {
        let mut t = Self::zeros();
        for (i, row) in self.rows.iter().enumerate() {
            for (j, &value) in row.iter().enumerate() {
                t.rows[j][i] = value;
            }
        }
        t
    }

    /// The 1-norm, max_j sum_i |a_ij|.
    pub fn one_norm(&self) -> f64 {
        let mut sums = [0.0; N];
        for row in &self.rows {
            for (sum, value) in sums.iter_mut().zip(row) {
                *sum += value.abs();
            }
        }
        sums.into_iter().fold(0.0, f64::max)
    }

    /// ||(|A| / scale)^p||_1 by p row-vector products (for B >= 0, ||B^p||_1 = max 1^T B^p).
    pub fn absolute_power_norm(&self, scale: f64, p: usize) -> f64 {
        absolute_power_norm(&self.rows, scale, p)
    }

    /// Factors self = P^T L U by Gaussian elimination with partial pivoting. Exactly singular
    /// pivots give infinities in later solves.
    pub fn lu(mut self) -> SmallLu<N> {
        let mut pivots = [0usize; N];
        lu_in_place(&mut self.rows, &mut pivots);
        SmallLu {
            factors: self,
            pivots,
        }
    }

    /// Solves self * X = rhs by LU with partial pivoting.
    pub fn solve(self, rhs: Self) -> Self {
        self.lu().solve(rhs)
    }
}

/// An LU factorisation with partial pivoting of a [`SmallMatrix`], for repeated solves.
#[derive(Clone, Copy, Debug)]
pub struct SmallLu<const N: usize> {
    /// Unit lower factor below the diagonal, upper factor on and above it.
    factors: SmallMatrix<N>,
    /// Row k was swapped with row `pivots[k]` at step k.
    pivots: [usize; N],
}

impl<const N: usize> SmallLu<N> {
    /// X with A X = rhs.
    pub fn solve(&self, mut rhs: SmallMatrix<N>) -> SmallMatrix<N> {
        lu_solve(&self.factors.rows, &self.pivots, &mut rhs.rows);
        rhs
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::norm::one_norm;

    fn sample<const N: usize>(seed: u64) -> SmallMatrix<N> {
        let mut state = seed;
        let mut m = SmallMatrix::<N>::zeros();
        for row in &mut m.rows {
            for value in row {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                *value = ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0;
            }
        }
        m
    }

    fn check_order<const N: usize>() {
        let (a, b) = (sample::<N>(1), sample::<N>(2));
        let expected = a.to_mat() * b.to_mat();
        let got = a.product(&b).to_mat();
        assert!((&got - &expected).norm_max() < 1e-14);

        let mut d = sample::<N>(3);
        let before = d.to_mat();
        d.add_product(&a, &b);
        assert!((d.to_mat() - (&before + &expected)).norm_max() < 1e-14);

        let combined = SmallMatrix::combination(2.0, &[(3.0, &a), (-1.0, &b)]);
        let expected = Mat::<f64>::identity(N, N) * faer::Scale(2.0)
            + a.to_mat() * faer::Scale(3.0)
            - b.to_mat();
        assert!((combined.to_mat() - expected).norm_max() < 1e-14);

        assert!((a.one_norm() - one_norm(a.to_mat().as_ref())).abs() <= 1e-15 * a.one_norm());

        // Reversing the rows of a random matrix makes pivoting necessary.
        let mut system = sample::<N>(4);
        system.rows.reverse();
        let x_true = sample::<N>(5);
        let rhs = system.product(&x_true);
        let x = system.solve(rhs);
        assert!((x.to_mat() - x_true.to_mat()).norm_max() < 1e-10);
    }

    #[test]
    fn operations_agree_with_faer_at_every_order() {
        check_order::<1>();
        check_order::<2>();
        check_order::<3>();
        check_order::<4>();
        check_order::<5>();
        check_order::<8>();
    }

    #[test]
    fn fused_and_plain_kernels_agree() {
        // Both variants of a kernel run here regardless of the CPU the test runs on (the fused
        // one only where it is supported).
        let (a, b) = (sample::<6>(7), sample::<6>(8));
        let mut plain = [[0.0; 6]; 6];
        add_product_kernel::<6, false>(&a.rows, &b.rows, &mut plain);
        let mut dispatched = [[0.0; 6]; 6];
        add_product(&a.rows, &b.rows, &mut dispatched);
        for (p, d) in plain.as_flattened().iter().zip(dispatched.as_flattened()) {
            assert!((p - d).abs() <= 1e-15);
        }
    }

    #[test]
    fn absolute_power_norm_equals_the_formed_power() {
        let a = sample::<5>(9);
        let mut abs = SmallMatrix::<5>::zeros();
        for i in 0..5 {
            for j in 0..5 {
                abs.rows[i][j] = a.rows[i][j].abs() / 2.0;
            }
        }
        let mut power = SmallMatrix::<5>::identity();
        for p in 0..10 {
            let expected = power.one_norm();
            assert!((a.absolute_power_norm(2.0, p) - expected).abs() <= 1e-14 * expected);
            power = power.product(&abs);
        }
    }

    #[test]
    fn lu_solves_repeatedly_and_needs_pivoting() {
        let a = SmallMatrix::<3> {
            rows: [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]],
        };
        let lu = a.lu();
        for seed in 0..3 {
            let x_true = sample::<3>(seed);
            let x = lu.solve(a.product(&x_true));
            assert!((x.to_mat() - x_true.to_mat()).norm_max() < 1e-14);
        }
    }
}
