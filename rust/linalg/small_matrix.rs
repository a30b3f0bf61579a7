//! Kernels on nalgebra's `SMatrix<f64, N, N>` (a [`crate::linalg::matrix::Square`] of a
//! fixed order, on the stack): products, linear combinations, an LU solve and norms, for the
//! matrix exponential's Padé evaluation at the orders of flight models.
//!
//! Flight-dynamics models are small (4 states for each of the longitudinal and lateral motions,
//! 8 to 12 for coupled or augmented models), and the exponential runs thousands of them in a
//! sweep. At these orders the cost of a general-order library call (dispatch, allocation,
//! blocking decisions) exceeds the arithmetic; with the order a constant the loops unroll and
//! vectorise, and nothing is allocated. Larger orders use faer.
//!
//! The kernels are free functions, not methods, so that none is confused with nalgebra's own
//! `product` (of the entries) or `lu`. They read the storage as its N columns of N entries
//! (`columns[j][i]` = a_ij). Each is compiled twice: for the baseline target and, on x86-64,
//! for AVX2 with fused multiply-add, chosen at run time by the CPU's features (see
//! `dispatch.rs`), so that one portable wheel runs at full speed on current CPUs. (Fused
//! multiply-adds round once instead of twice, so the two variants can differ in the last bit.)
//!
//! The LU solve uses partial pivoting and divides by the pivots (as LAPACK's dgetrs does)
//! rather than multiplying by reciprocals.

use nalgebra::SMatrix;

use crate::platform::dispatch::{fma_dispatch, multiply_add};

/// The storage of an N x N matrix: N columns of N entries.
pub(crate) type Columns<const N: usize> = [[f64; N]; N];

/// A value on a 64-byte boundary, the start of a cache line. A kernel's column arrays that stay
/// in memory (those indexed at run time, as by the LU's pivots) are read and written as whole
/// AVX vectors, and a vector that straddles two cache lines costs a split access; a local of
/// this type also makes the kernel's prologue align its frame, so that the kernel's speed does
/// not depend on the depth of its caller's stack.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct CacheAligned<T>(pub(crate) T);

/// The columns of `m`.
#[inline(always)]
pub(crate) fn columns<const N: usize>(m: &SMatrix<f64, N, N>) -> &Columns<N> {
    &m.data.0
}

/// The columns of `m`, mutably.
#[inline(always)]
pub(crate) fn columns_mut<const N: usize>(m: &mut SMatrix<f64, N, N>) -> &mut Columns<N> {
    &mut m.data.0
}

/// The matrix whose columns are `columns`.
#[inline(always)]
pub(crate) fn from_columns<const N: usize>(columns: Columns<N>) -> SMatrix<f64, N, N> {
    SMatrix::from_data(nalgebra::ArrayStorage(columns))
}

/// out += lhs * rhs: column j of the result gains rhs_kj times column k of lhs, k in order
/// (each entry the sum over k, in order, of lhs_ik rhs_kj).
#[inline(always)]
pub(crate) fn add_product_kernel<const N: usize, const FMA: bool>(
    lhs: &Columns<N>,
    rhs: &Columns<N>,
    out: &mut Columns<N>,
) {
    for (out_column, rhs_column) in out.iter_mut().zip(rhs) {
        for (&coefficient, lhs_column) in rhs_column.iter().zip(lhs) {
            for (o, &x) in out_column.iter_mut().zip(lhs_column) {
                *o = multiply_add::<FMA>(x, coefficient, *o);
            }
        }
    }
}

fma_dispatch!(fn add_product_columns<const N: usize>(lhs: &Columns<N>, rhs: &Columns<N>, out: &mut Columns<N>) => add_product_kernel);

/// A matrix stored as the N columns of N entries of an `SMatrix`: the stack matrix itself, or a
/// type that wraps one.
pub(crate) trait StackColumns<const N: usize> {
    fn stack_columns(&self) -> &Columns<N>;
}

impl<const N: usize> StackColumns<N> for SMatrix<f64, N, N> {
    #[inline(always)]
    fn stack_columns(&self) -> &Columns<N> {
        columns(self)
    }
}

/// identity * I + sum_k coefficient_k * M_k.
#[inline(always)]
pub(crate) fn combination_kernel<const N: usize, const FMA: bool>(
    identity: f64,
    terms: &[(f64, &impl StackColumns<N>)],
) -> Columns<N> {
    let (&(first_coefficient, first), rest) = terms.split_first().expect("at least one term");
    let mut out = [[0.0; N]; N];
    for (out_column, column) in out.iter_mut().zip(first.stack_columns()) {
        for (o, &v) in out_column.iter_mut().zip(column) {
            *o = first_coefficient * v;
        }
    }
    for &(coefficient, m) in rest {
        for (out_column, column) in out.iter_mut().zip(m.stack_columns()) {
            for (o, &v) in out_column.iter_mut().zip(column) {
                *o = multiply_add::<FMA>(coefficient, v, *o);
            }
        }
    }
    for (i, column) in out.iter_mut().enumerate() {
        column[i] += identity;
    }
    out
}

fma_dispatch!(fn combination_columns<const N: usize>(identity: f64, terms: &[(f64, &SMatrix<f64, N, N>)]) -> Columns<N> => combination_kernel);

/// ||(|A| / scale)^p||_1 by p row-vector products (for B >= 0, ||B^p||_1 = max 1^T B^p):
/// entry j of the next row vector is the sum over i, in order, of v_i b_ij. B is stored by rows,
/// so that the next vector is formed as the sum of the rows of B weighted by v, whole rows at a
/// time (vector operations, each entry's terms in the same order).
#[inline(always)]
pub(crate) fn absolute_power_norm_kernel<const N: usize, const FMA: bool>(
    a: &Columns<N>,
    scale: f64,
    p: usize,
) -> f64 {
    let inverse = 1.0 / scale;
    let mut b_rows = [[0.0; N]; N];
    for (j, column) in a.iter().enumerate() {
        for (row, value) in b_rows.iter_mut().zip(column) {
            row[j] = value.abs() * inverse;
        }
    }
    let mut vector = [1.0; N];
    for _ in 0..p {
        let mut next = [0.0; N];
        for (&weight, b_row) in vector.iter().zip(&b_rows) {
            for (n, &x) in next.iter_mut().zip(b_row) {
                *n = multiply_add::<FMA>(weight, x, *n);
            }
        }
        vector = next;
    }
    vector.into_iter().fold(0.0, f64::max)
}

fma_dispatch!(fn absolute_power_norm_columns<const N: usize>(a: &Columns<N>, scale: f64, p: usize) -> f64 => absolute_power_norm_kernel);

/// Gaussian elimination with partial pivoting in place: the unit lower factor below the
/// diagonal, the upper factor on and above it; row k was swapped with row `pivots[k]`.
#[inline(always)]
pub(crate) fn lu_kernel<const N: usize, const FMA: bool>(
    a: &mut Columns<N>,
    pivots: &mut [usize; N],
) {
    for k in 0..N {
        let mut pivot_row = k;
        for i in k + 1..N {
            if a[k][i].abs() > a[k][pivot_row].abs() {
                pivot_row = i;
            }
        }
        pivots[k] = pivot_row;
        for column in a.iter_mut() {
            column.swap(k, pivot_row);
        }
        let (done, rest) = a.split_at_mut(k + 1);
        let pivot_column = &mut done[k];
        let pivot = pivot_column[k];
        for factor in &mut pivot_column[k + 1..] {
            *factor /= pivot;
        }
        for column in rest.iter_mut() {
            let pivot_row_value = column[k];
            for (x, &factor) in column[k + 1..].iter_mut().zip(&pivot_column[k + 1..]) {
                *x = multiply_add::<FMA>(-factor, pivot_row_value, *x);
            }
        }
    }
}

fma_dispatch!(fn lu_in_place<const N: usize>(a: &mut Columns<N>, pivots: &mut [usize; N]) => lu_kernel);

/// [`lu_kernel`] on the matrix stored by rows (`rows[i][j]` = a_ij): the same pivots and the
/// same operations on each entry in the same order (equal bit for bit), with the factors left
/// by rows. A row interchange moves two whole rows, and each elimination step updates a whole
/// row with one vector operation, where the column storage swaps and updates entry by entry.
#[inline(always)]
pub(crate) fn lu_rows_kernel<const N: usize, const FMA: bool>(
    rows: &mut Columns<N>,
    pivots: &mut [usize; N],
) {
    for k in 0..N {
        let mut pivot_row = k;
        for i in k + 1..N {
            if rows[i][k].abs() > rows[pivot_row][k].abs() {
                pivot_row = i;
            }
        }
        pivots[k] = pivot_row;
        rows.swap(k, pivot_row);
        let (done, rest) = rows.split_at_mut(k + 1);
        let pivot_row_values = &done[k];
        let pivot = pivot_row_values[k];
        for row in rest.iter_mut() {
            let factor = row[k] / pivot;
            // Entries left of k hold factors already; only those right of it are updated.
            for (j, (x, &value)) in row.iter_mut().zip(pivot_row_values).enumerate() {
                let updated = multiply_add::<FMA>(-factor, value, *x);
                *x = if j > k { updated } else { *x };
            }
            row[k] = factor;
        }
    }
}

/// [`lu_solve_rows_kernel`] with the factors of [`lu_rows_kernel`] (stored by rows): the same
/// operations on each entry in the same order.
#[inline(always)]
pub(crate) fn lu_rows_solve_rows_kernel<const N: usize, const FMA: bool>(
    lu_rows: &Columns<N>,
    pivots: &[usize; N],
    rows: &mut Columns<N>,
) {
    for (k, &pivot_row) in pivots.iter().enumerate() {
        rows.swap(k, pivot_row);
    }
    // Forward substitution with the unit lower factor.
    for k in 0..N {
        let (solved, rest) = rows.split_at_mut(k + 1);
        let solved = &solved[k];
        for (row, lu_row) in rest.iter_mut().zip(&lu_rows[k + 1..]) {
            let factor = lu_row[k];
            for (entry, &x) in row.iter_mut().zip(solved) {
                *entry = multiply_add::<FMA>(-factor, x, *entry);
            }
        }
    }
    // Back substitution with the upper factor, dividing by each pivot.
    for k in (0..N).rev() {
        let (rest, solved) = rows.split_at_mut(k);
        let solved = &mut solved[0];
        let pivot = lu_rows[k][k];
        for x in solved.iter_mut() {
            *x /= pivot;
        }
        for (row, lu_row) in rest.iter_mut().zip(lu_rows) {
            let factor = lu_row[k];
            for (entry, &x) in row.iter_mut().zip(solved.iter()) {
                *entry = multiply_add::<FMA>(-factor, x, *entry);
            }
        }
    }
}

/// Solves with the factors of [`lu_kernel`] for N right-hand sides in place, column by column.
#[inline(always)]
pub(crate) fn lu_solve_kernel<const N: usize, const FMA: bool>(
    lu: &Columns<N>,
    pivots: &[usize; N],
    rhs: &mut Columns<N>,
) {
    for x in rhs.iter_mut() {
        for (k, &pivot_row) in pivots.iter().enumerate() {
            x.swap(k, pivot_row);
        }
        // Forward substitution with the unit lower factor.
        for k in 0..N {
            let solved = x[k];
            for (entry, &factor) in x[k + 1..].iter_mut().zip(&lu[k][k + 1..]) {
                *entry = multiply_add::<FMA>(-factor, solved, *entry);
            }
        }
        // Back substitution with the upper factor, dividing by each pivot.
        for k in (0..N).rev() {
            x[k] /= lu[k][k];
            let solved = x[k];
            for (entry, &factor) in x[..k].iter_mut().zip(&lu[k][..k]) {
                *entry = multiply_add::<FMA>(-factor, solved, *entry);
            }
        }
    }
}

fma_dispatch!(fn lu_solve_columns<const N: usize>(lu: &Columns<N>, pivots: &[usize; N], rhs: &mut Columns<N>) => lu_solve_kernel);

/// Solves with the factors of [`lu_kernel`] in place for the N right-hand sides stored as the
/// rows of `rows` (`rows[i][j]` = b_ij, the storage of B^T), giving the rows of the solution
/// X. Each entry of X gets the operations of [`lu_solve_kernel`] in the same order (equal bit
/// for bit); the N columns advance together, one vector operation per row, so that the
/// substitutions' divisions and multiply-adds are vector instructions rather than N chains
/// of scalar ones.
#[inline(always)]
pub(crate) fn lu_solve_rows_kernel<const N: usize, const FMA: bool>(
    lu: &Columns<N>,
    pivots: &[usize; N],
    rows: &mut Columns<N>,
) {
    for (k, &pivot_row) in pivots.iter().enumerate() {
        rows.swap(k, pivot_row);
    }
    // Forward substitution with the unit lower factor.
    for k in 0..N {
        let (solved, rest) = rows.split_at_mut(k + 1);
        let solved = &solved[k];
        for (row, &factor) in rest.iter_mut().zip(&lu[k][k + 1..]) {
            for (entry, &x) in row.iter_mut().zip(solved) {
                *entry = multiply_add::<FMA>(-factor, x, *entry);
            }
        }
    }
    // Back substitution with the upper factor, dividing by each pivot.
    for k in (0..N).rev() {
        let (rest, solved) = rows.split_at_mut(k);
        let solved = &mut solved[0];
        let pivot = lu[k][k];
        for x in solved.iter_mut() {
            *x /= pivot;
        }
        for (row, &factor) in rest.iter_mut().zip(&lu[k][..k]) {
            for (entry, &x) in row.iter_mut().zip(solved.iter()) {
                *entry = multiply_add::<FMA>(-factor, x, *entry);
            }
        }
    }
}

/// out += lhs * rhs with rhs given by its rows (`rhs_rows[k][j]` = rhs_kj): each entry the
/// sum over k, in order, of lhs_ik rhs_kj, as [`add_product_kernel`] forms it.
#[inline(always)]
pub(crate) fn add_product_rows_kernel<const N: usize, const FMA: bool>(
    lhs: &Columns<N>,
    rhs_rows: &Columns<N>,
    out: &mut Columns<N>,
) {
    for (j, out_column) in out.iter_mut().enumerate() {
        for (lhs_column, rhs_row) in lhs.iter().zip(rhs_rows) {
            let coefficient = rhs_row[j];
            for (o, &x) in out_column.iter_mut().zip(lhs_column) {
                *o = multiply_add::<FMA>(x, coefficient, *o);
            }
        }
    }
}

/// The storage of M^T: M's rows as columns.
#[inline(always)]
pub(crate) fn transposed<const N: usize>(m: &Columns<N>) -> Columns<N> {
    let mut out = [[0.0; N]; N];
    for (j, column) in m.iter().enumerate() {
        for (i, &value) in column.iter().enumerate() {
            out[i][j] = value;
        }
    }
    out
}

/// lhs * rhs.
pub(crate) fn product<const N: usize>(
    lhs: &SMatrix<f64, N, N>,
    rhs: &SMatrix<f64, N, N>,
) -> SMatrix<f64, N, N> {
    let mut out = SMatrix::zeros();
    add_product(&mut out, lhs, rhs);
    out
}

/// out += lhs * rhs.
pub(crate) fn add_product<const N: usize>(
    out: &mut SMatrix<f64, N, N>,
    lhs: &SMatrix<f64, N, N>,
    rhs: &SMatrix<f64, N, N>,
) {
    add_product_columns(columns(lhs), columns(rhs), columns_mut(out));
}

/// identity * I + sum_k coefficient_k * M_k, for at least one term.
pub(crate) fn combination<const N: usize>(
    identity: f64,
    terms: &[(f64, &SMatrix<f64, N, N>)],
) -> SMatrix<f64, N, N> {
    from_columns(combination_columns(identity, terms))
}

/// The 1-norm, max_j sum_i |a_ij|. The N column sums are formed together, row by row (each
/// sum's terms in order i = 0, 1, ..., so as a sum down its column), as vector operations.
#[inline(always)]
pub(crate) fn one_norm<const N: usize>(a: &SMatrix<f64, N, N>) -> f64 {
    let mut sums = [0.0; N];
    for i in 0..N {
        for (sum, column) in sums.iter_mut().zip(columns(a)) {
            *sum += column[i].abs();
        }
    }
    sums.into_iter().fold(0.0, f64::max)
}

/// max |a_ij| (entries that are NaN ignored, as by `f64::max`), the maxima of the rows formed
/// together as vector operations.
#[inline(always)]
pub(crate) fn max_abs<const N: usize>(a: &SMatrix<f64, N, N>) -> f64 {
    let mut largest = [0.0; N];
    for column in columns(a) {
        for (m, value) in largest.iter_mut().zip(column) {
            *m = f64::max(*m, value.abs());
        }
    }
    largest.into_iter().fold(0.0, f64::max)
}

/// ||(|A| / scale)^p||_1 by p row-vector products (for B >= 0, ||B^p||_1 = max 1^T B^p).
pub(crate) fn absolute_power_norm<const N: usize>(
    a: &SMatrix<f64, N, N>,
    scale: f64,
    p: usize,
) -> f64 {
    absolute_power_norm_columns(columns(a), scale, p)
}

/// Whether every entry is finite (one pass without early exit, which vectorises).
#[inline]
pub(crate) fn is_finite<const N: usize>(a: &SMatrix<f64, N, N>) -> bool {
    a.as_slice()
        .iter()
        .fold(true, |finite, value| finite & value.is_finite())
}

/// Whether every entry below the diagonal is zero.
#[inline]
pub(crate) fn is_upper_triangular<const N: usize>(a: &SMatrix<f64, N, N>) -> bool {
    columns(a)
        .iter()
        .enumerate()
        .all(|(j, column)| column[j + 1..].iter().all(|&v| v == 0.0))
}

/// Whether every entry above the diagonal is zero.
#[inline]
pub(crate) fn is_lower_triangular<const N: usize>(a: &SMatrix<f64, N, N>) -> bool {
    columns(a)
        .iter()
        .enumerate()
        .all(|(j, column)| column[..j].iter().all(|&v| v == 0.0))
}

/// An LU factorisation with partial pivoting of an N x N matrix, for repeated solves.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SmallLu<const N: usize> {
    /// Unit lower factor below the diagonal, upper factor on and above it.
    factors: SMatrix<f64, N, N>,
    /// Row k was swapped with row `pivots[k]` at step k.
    pivots: [usize; N],
}

impl<const N: usize> SmallLu<N> {
    /// Factors a = P^T L U by Gaussian elimination with partial pivoting. Exactly singular
    /// pivots give infinities in later solves.
    pub(crate) fn new(mut a: SMatrix<f64, N, N>) -> Self {
        let mut pivots = [0usize; N];
        lu_in_place(columns_mut(&mut a), &mut pivots);
        Self { factors: a, pivots }
    }

    /// X with A X = rhs.
    pub(crate) fn solve(&self, mut rhs: SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
        lu_solve_columns(columns(&self.factors), &self.pivots, columns_mut(&mut rhs));
        rhs
    }
}

/// X with a X = rhs, by LU with partial pivoting.
pub(crate) fn solve<const N: usize>(
    a: SMatrix<f64, N, N>,
    rhs: SMatrix<f64, N, N>,
) -> SMatrix<f64, N, N> {
    SmallLu::new(a).solve(rhs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::matrix::FaerView;
    use crate::linalg::norm;
    use faer::Mat;

    fn sample<const N: usize>(seed: u64) -> SMatrix<f64, N, N> {
        let mut state = seed;
        SMatrix::from_fn(|_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
    }

    fn check_order<const N: usize>() {
        let (a, b) = (sample::<N>(1), sample::<N>(2));
        let expected = a.to_faer() * b.to_faer();
        let got = product(&a, &b).to_faer();
        assert!((&got - &expected).norm_max() < 1e-14);

        let mut d = sample::<N>(3);
        let before = d.to_faer();
        add_product(&mut d, &a, &b);
        assert!((d.to_faer() - (&before + &expected)).norm_max() < 1e-14);

        let combined = combination(2.0, &[(3.0, &a), (-1.0, &b)]);
        let expected = Mat::<f64>::identity(N, N) * faer::Scale(2.0)
            + a.to_faer() * faer::Scale(3.0)
            - b.to_faer();
        assert!((combined.to_faer() - expected).norm_max() < 1e-14);

        let exact = norm::one_norm(a.to_faer().as_ref());
        assert!((one_norm(&a) - exact).abs() <= 1e-15 * exact);

        // Reversing the rows of a random matrix makes pivoting necessary.
        let system = SMatrix::<f64, N, N>::from_fn(|i, j| sample::<N>(4)[(N - 1 - i, j)]);
        let x_true = sample::<N>(5);
        let rhs = product(&system, &x_true);
        let x = solve(system, rhs);
        assert!((x.to_faer() - x_true.to_faer()).norm_max() < 1e-10);
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
        add_product_kernel::<6, false>(columns(&a), columns(&b), &mut plain);
        let dispatched = product(&a, &b);
        for (p, d) in plain.as_flattened().iter().zip(dispatched.as_slice()) {
            assert!((p - d).abs() <= 1e-15);
        }
    }

    /// The row-storage solve and product against the column-storage ones, bit for bit, in
    /// both variants, at the order N over seeded matrices (pivoting forced by reversed rows).
    /// (Inlined as every function generic over `FMA` is: `fma_kernels_are_always_inlined`.)
    #[inline(always)]
    fn check_row_kernels<const N: usize, const FMA: bool>() {
        for seed in 0..20 {
            let system = SMatrix::<f64, N, N>::from_fn(|i, j| sample::<N>(seed)[(N - 1 - i, j)]);
            let mut lu = *columns(&system);
            let mut pivots = [0usize; N];
            lu_kernel::<N, FMA>(&mut lu, &mut pivots);
            let rhs = sample::<N>(seed + 100);
            let mut by_columns = *columns(&rhs);
            lu_solve_kernel::<N, FMA>(&lu, &pivots, &mut by_columns);
            let mut by_rows = transposed(columns(&rhs));
            lu_solve_rows_kernel::<N, FMA>(&lu, &pivots, &mut by_rows);
            assert_eq!(
                transposed(&by_rows),
                by_columns,
                "solve, N = {N}, seed {seed}"
            );
            // Factored by rows too.
            let mut lu_rows = transposed(columns(&system));
            let mut row_pivots = [0usize; N];
            lu_rows_kernel::<N, FMA>(&mut lu_rows, &mut row_pivots);
            assert_eq!(row_pivots, pivots, "pivots, N = {N}, seed {seed}");
            assert_eq!(transposed(&lu_rows), lu, "factors, N = {N}, seed {seed}");
            let mut by_rows = transposed(columns(&rhs));
            lu_rows_solve_rows_kernel::<N, FMA>(&lu_rows, &row_pivots, &mut by_rows);
            assert_eq!(
                transposed(&by_rows),
                by_columns,
                "solve with the row factors, N = {N}, seed {seed}"
            );

            let (lhs, start) = (sample::<N>(seed + 200), sample::<N>(seed + 300));
            let mut expected = *columns(&start);
            add_product_kernel::<N, FMA>(columns(&lhs), columns(&rhs), &mut expected);
            let mut got = *columns(&start);
            add_product_rows_kernel::<N, FMA>(columns(&lhs), &transposed(columns(&rhs)), &mut got);
            assert_eq!(got, expected, "product, N = {N}, seed {seed}");
        }
    }

    #[test]
    fn row_storage_kernels_equal_the_column_ones_bit_for_bit() {
        check_row_kernels::<1, false>();
        check_row_kernels::<2, false>();
        check_row_kernels::<3, false>();
        check_row_kernels::<4, false>();
        check_row_kernels::<5, false>();
        check_row_kernels::<8, false>();
        // The fused variant's multiply-adds are mul_add: exact on every CPU.
        check_row_kernels::<1, true>();
        check_row_kernels::<4, true>();
        check_row_kernels::<7, true>();
        check_row_kernels::<8, true>();
    }

    #[test]
    fn absolute_power_norm_equals_the_formed_power() {
        let a = sample::<5>(9);
        let abs = a.map(|x| x.abs() / 2.0);
        let mut power = SMatrix::<f64, 5, 5>::identity();
        for p in 0..10 {
            let expected = one_norm(&power);
            assert!((absolute_power_norm(&a, 2.0, p) - expected).abs() <= 1e-14 * expected);
            power = product(&power, &abs);
        }
    }

    #[test]
    fn norms_equal_their_entrywise_definitions() {
        for seed in 0..10 {
            let mut a = sample::<5>(seed);
            a[(2, 3)] = f64::NAN;
            let by_columns = columns(&a)
                .iter()
                .map(|column| column.iter().fold(0.0, |sum, value| sum + value.abs()))
                .fold(0.0, f64::max);
            assert_eq!(one_norm(&a).to_bits(), by_columns.to_bits());
            let largest = a.as_slice().iter().fold(0.0, |m: f64, v| m.max(v.abs()));
            assert_eq!(max_abs(&a).to_bits(), largest.to_bits());
            assert!(largest.is_finite());
        }
    }

    #[test]
    fn triangular_structure() {
        let upper = SMatrix::<f64, 3, 3>::new(1.0, 2.0, 3.0, 0.0, 4.0, 5.0, 0.0, 0.0, 6.0);
        assert!(is_upper_triangular(&upper) && !is_lower_triangular(&upper));
        let lower = upper.transpose();
        assert!(is_lower_triangular(&lower) && !is_upper_triangular(&lower));
    }

    #[test]
    fn lu_solves_repeatedly_and_needs_pivoting() {
        let a = SMatrix::<f64, 3, 3>::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let lu = SmallLu::new(a);
        for seed in 0..3 {
            let x_true = sample::<3>(seed);
            let x = lu.solve(product(&a, &x_true));
            assert!((x.to_faer() - x_true.to_faer()).norm_max() < 1e-14);
        }
    }
}
