//! Linear solves by LU with partial pivoting (faer), real or complex, without ever forming an
//! inverse, stopping between blocks of work when the computation is interrupted.
//!
//! A thin layer over faer's in-place factorisation. For small systems the pivot vectors and
//! faer's scratch live on the stack, so a solve allocates nothing. For large ones (more than
//! about [`PANEL_MULTIPLY_ADDS`] multiply-adds) faer's recursive factorisation (Toledo's
//! left-and-right recursion: factor the left half of the columns, update the right half by a
//! triangular solve and a product, factor its lower part) is driven from here, one level of
//! recursion at a time, with the same split of the columns as faer's and faer's kernels for
//! every step, so that [`interrupt::check`] runs between steps, the product and the triangular
//! solve of each level are split into column panels ([`crate::linalg::product`]), and the
//! factors are bitwise those of one faer call. The substitutions of many right-hand sides go
//! in column panels too (each column is solved independently, so bitwise as one call). Real
//! and complex matrices ([`Entry`]) take the same steps, their blocks of work sized in real
//! multiply-adds. The tests below check both against faer's calls, for both.
//!
//! S. Toledo, "Locality of reference in LU decomposition with partial pivoting", SIAM J.
//! Matrix Anal. Appl. 18(4), 1997.

use crate::error::Error;
use crate::linalg::matrix::with_order;
use crate::linalg::product::{Entry, PANEL_MULTIPLY_ADDS, multiply, panel_columns};
use crate::platform::interrupt;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::linalg::triangular_solve::solve_unit_lower_triangular_in_place;
use faer::perm::{Perm, PermRef};
use faer::prelude::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par, Spec};
use std::mem::MaybeUninit;

/// The order below which faer's recursive LU switches to its unblocked kernel. faer's default
/// is 16; 8 is faster at n = 32 to 256 on current x86-64 cores.
const LU_RECURSION_THRESHOLD: usize = 8;

fn lu_parameters() -> Spec<PartialPivLuParams, f64> {
    let mut parameters: Spec<PartialPivLuParams, f64> = Default::default();
    parameters.config.recursion_threshold = LU_RECURSION_THRESHOLD;
    parameters
}

/// Systems up to this order are solved by [`eliminate_and_substitute`]: below it the set-up of
/// faer's recursive factorisation (scratch, permutations, dispatch) costs more than the
/// arithmetic.
const UNBLOCKED_MAX_ORDER: usize = 12;

/// Systems up to this order keep their pivots and scratch on the stack.
const STACK_ORDER: usize = 64;
const STACK_BYTES: usize = 4096;

/// The LU factorisation with partial pivoting P A = L U of a square matrix, as faer's
/// `PartialPivLu` (faer's default parameters and global parallelism, bitwise the same
/// factors), formed and applied with stops between blocks of work when the computation is
/// interrupted (see the module documentation), for real (`f64`) or complex (`c64`) entries. A
/// singular A gives a zero or non-finite pivot and non-finite solutions, never a panic or an
/// error: callers check the conditioning.
#[derive(Debug, Clone)]
pub struct Lu<T: Entry = f64> {
    /// Unit lower triangular (its unit diagonal stored).
    l: Mat<T>,
    /// Upper triangular.
    u: Mat<T>,
    perm: Perm<usize>,
    /// Whether P is an odd permutation.
    odd: bool,
}

impl<T: Entry> Lu<T> {
    /// Factors the square matrix `a`; `Err(Error::Interrupted)` if the computation was
    /// interrupted.
    pub fn new(a: MatRef<'_, T>) -> Result<Self, Error> {
        let n = a.nrows();
        debug_assert_eq!(n, a.ncols());
        let mut factors = a.to_owned();
        let forward = factor_in_place(
            factors.as_mut(),
            faer::get_global_parallelism(),
            Default::default(),
        )?;
        let mut inverse = vec![0; n];
        for (i, &row) in forward.iter().enumerate() {
            inverse[row] = i;
        }
        // The parity of P: a cycle of length k is k - 1 transpositions.
        let mut seen = vec![false; n];
        let mut transpositions = 0;
        for start in 0..n {
            let mut i = start;
            while !seen[i] {
                seen[i] = true;
                i = forward[i];
                transpositions += usize::from(i != start);
            }
        }
        // L takes the multipliers below the diagonal and a unit diagonal, U keeps the rest.
        let mut l = Mat::<T>::zeros(n, n);
        let mut u = factors;
        for j in 0..n {
            let lower = &mut u.col_as_slice_mut(j)[j + 1..];
            let column = l.col_as_slice_mut(j);
            column[j] = T::ONE;
            column[j + 1..].copy_from_slice(lower);
            lower.fill(T::ZERO);
        }
        let perm = Perm::new_checked(forward.into_boxed_slice(), inverse.into_boxed_slice(), n);
        Ok(Self {
            l,
            u,
            perm,
            odd: transpositions % 2 == 1,
        })
    }

    /// det A = ±(the product of U's diagonal, in order), as faer's `determinant` forms it from
    /// the same factors (bitwise the same).
    pub fn determinant(&self) -> T {
        let mut det = T::ONE;
        for i in 0..self.nrows() {
            det *= self.u[(i, i)];
        }
        if self.odd { -det } else { det }
    }

    /// The order of A.
    pub fn nrows(&self) -> usize {
        self.l.nrows()
    }

    /// The unit lower triangular factor L.
    #[allow(non_snake_case)]
    pub fn L(&self) -> MatRef<'_, T> {
        self.l.as_ref()
    }

    /// The upper triangular factor U.
    #[allow(non_snake_case)]
    pub fn U(&self) -> MatRef<'_, T> {
        self.u.as_ref()
    }

    /// Overwrites B with A^-1 B (P B, then L Y = P B, U X = Y), in column panels of B.
    pub fn solve_in_place(&self, b: MatMut<'_, T>) -> Result<(), Error> {
        let n = self.nrows();
        let par = faer::get_global_parallelism();
        in_column_panels(n, b, |panel| {
            let k = panel.ncols();
            let mut buffer = MemBuffer::new(solve::solve_in_place_scratch::<usize, T>(n, k, par));
            solve::solve_in_place(
                self.L(),
                self.U(),
                self.perm.as_ref(),
                panel,
                par,
                MemStack::new(&mut buffer),
            );
        })
    }

    /// A^-1 B.
    pub fn solve(&self, b: MatRef<'_, T>) -> Result<Mat<T>, Error> {
        let mut x = b.to_owned();
        self.solve_in_place(x.as_mut())?;
        Ok(x)
    }

    /// Overwrites B with A^-T B, in column panels of B.
    pub fn solve_transpose_in_place(&self, b: MatMut<'_, T>) -> Result<(), Error> {
        let n = self.nrows();
        let par = faer::get_global_parallelism();
        in_column_panels(n, b, |panel| {
            let k = panel.ncols();
            let mut buffer = MemBuffer::new(solve::solve_transpose_in_place_scratch::<usize, T>(
                n, k, par,
            ));
            solve::solve_transpose_in_place(
                self.L(),
                self.U(),
                self.perm.as_ref(),
                panel,
                par,
                MemStack::new(&mut buffer),
            );
        })
    }
}

/// Runs `substitute` (two triangular substitutions with an order-n factor, 2 n^2
/// multiply-adds a column, on columns independently) on column panels of `b`, with
/// [`interrupt::check`] between them.
fn in_column_panels<T: Entry>(
    n: usize,
    mut b: MatMut<'_, T>,
    mut substitute: impl FnMut(MatMut<'_, T>),
) -> Result<(), Error> {
    let k = b.ncols();
    let width = panel_columns::<T>(n, 2 * n, k);
    let mut first = 0;
    while first < k {
        let columns = width.min(k - first);
        if first > 0 {
            interrupt::check()?;
        }
        substitute(b.rb_mut().subcols_mut(first, columns));
        first += columns;
    }
    Ok(())
}

/// Factors the m x w panel `a` (m >= w) in place, P a = L U with L unit lower trapezoidal and
/// U upper triangular sharing its storage, as faer's `lu_in_place` with `parameters` and `par`
/// (bitwise the same), and returns P as forward indices: row i of P a is row `perm[i]` of a.
/// A panel of at most [`PANEL_MULTIPLY_ADDS`] (m w^2 real multiply-adds) is one faer call; a
/// larger one is split
/// at faer's column split of its recursion (half of w, rounded up to a multiple of
/// min(16, its next power of two)) into the factorisation of the left columns, the row swaps
/// and the unit lower triangular solve of the top right block, the product updating the
/// bottom right block, and the factorisation of that block, with the triangular solve and the
/// product in column panels and a check of the interruption between every step.
fn factor_in_place<T: Entry>(
    mut a: MatMut<'_, T>,
    par: Par,
    parameters: Spec<PartialPivLuParams, T>,
) -> Result<Vec<usize>, Error> {
    let (m, w) = a.shape();
    debug_assert!(m >= w);
    if m.saturating_mul(w)
        .saturating_mul(w)
        .saturating_mul(T::REAL_MULTIPLY_ADDS)
        <= PANEL_MULTIPLY_ADDS
        || w <= parameters.config.recursion_threshold
    {
        let mut perm = vec![0; m];
        let mut perm_inverse = vec![0; m];
        let mut buffer = MemBuffer::new(factor::lu_in_place_scratch::<usize, T>(
            m, w, par, parameters,
        ));
        factor::lu_in_place(
            a,
            &mut perm,
            &mut perm_inverse,
            par,
            MemStack::new(&mut buffer),
            parameters,
        );
        return Ok(perm);
    }
    interrupt::check()?;
    let half = w / 2;
    let split = half.next_multiple_of(16.min(half.next_power_of_two()));
    let left = factor_in_place(a.rb_mut().subcols_mut(0, split), par, parameters)?;
    permute_rows(a.rb_mut().subcols_mut(split, w - split), &left);
    let (a00, mut a01, a10, mut a11) = a.rb_mut().split_at_mut(split, split);
    let rhs_width = panel_columns::<T>(split, split, w - split);
    let mut first = 0;
    while first < w - split {
        interrupt::check()?;
        let columns = rhs_width.min(w - split - first);
        solve_unit_lower_triangular_in_place(
            a00.rb(),
            a01.rb_mut().subcols_mut(first, columns),
            par,
        );
        first += columns;
    }
    multiply(a11.rb_mut(), Accum::Add, a10.rb(), a01.rb(), -T::ONE, par)?;
    let right = factor_in_place(a11, par, parameters)?;
    permute_rows(a.rb_mut().submatrix_mut(split, 0, m - split, split), &right);
    let mut perm = left.clone();
    for (i, &row) in right.iter().enumerate() {
        perm[split + i] = left[split + row];
    }
    Ok(perm)
}

/// Replaces the rows of `a` by their permutation: row i becomes row `perm[i]`, moving only
/// the rows that change (a panel's pivoting moves at most twice its width of rows).
fn permute_rows<T: Entry>(mut a: MatMut<'_, T>, perm: &[usize]) {
    let moved: Vec<(usize, usize)> = perm
        .iter()
        .enumerate()
        .filter(|&(i, &row)| i != row)
        .map(|(i, &row)| (i, row))
        .collect();
    let mut values = vec![T::ZERO; moved.len()];
    for j in 0..a.ncols() {
        let mut column = a.rb_mut().col_mut(j);
        for (value, &(_, row)) in values.iter_mut().zip(&moved) {
            *value = column[row];
        }
        for (&value, &(i, _)) in values.iter().zip(&moved) {
            column[i] = value;
        }
    }
}

/// Solves A X = B for X, overwriting B, by LU factorisation of A with partial pivoting
/// (P A = L U, then L Y = P B, U X = Y); A is overwritten by its factors. Large systems stop
/// with `Err(Error::Interrupted)` between blocks of work (see the module documentation) when
/// the computation is interrupted; that is the only error.
///
/// A singular A gives infinite or NaN entries, never a panic. (The exponential's Padé
/// denominators are well conditioned by the choice of degree and scaling, Higham 2005, §3;
/// other callers that can meet a singular matrix must check its conditioning.)
pub fn solve(mut a: MatMut<'_, f64>, b: MatMut<'_, f64>, par: Par) -> Result<(), Error> {
    let n = a.nrows();
    debug_assert_eq!(n, a.ncols());
    debug_assert_eq!(n, b.nrows());
    if n <= UNBLOCKED_MAX_ORDER {
        eliminate_and_substitute(a, b);
        return Ok(());
    }
    let requirement = factor::lu_in_place_scratch::<usize, f64>(n, n, par, lu_parameters()).or(
        solve::solve_in_place_scratch::<usize, f64>(n, b.ncols(), par),
    );
    if n <= STACK_ORDER && requirement.unaligned_bytes_required() <= STACK_BYTES {
        let mut perm = [0usize; STACK_ORDER];
        let mut perm_inverse = [0usize; STACK_ORDER];
        let mut bytes = [MaybeUninit::<u8>::uninit(); STACK_BYTES];
        factor_and_solve(
            a,
            b,
            &mut perm[..n],
            &mut perm_inverse[..n],
            MemStack::new(&mut bytes),
            par,
        );
        return Ok(());
    }
    let perm = factor_in_place(a.rb_mut(), par, lu_parameters())?;
    let mut perm_inverse = vec![0; n];
    for (i, &row) in perm.iter().enumerate() {
        perm_inverse[row] = i;
    }
    let perm = PermRef::new_checked(&perm, &perm_inverse, n);
    let factors = a.rb();
    in_column_panels(n, b, |panel| {
        let k = panel.ncols();
        let mut buffer = MemBuffer::new(
            solve::solve_in_place_scratch::<usize, f64>(n, k, par).or(StackReq::EMPTY),
        );
        // The unit lower factor L and the upper factor U share the storage of `a`.
        solve::solve_in_place(
            factors,
            factors,
            perm,
            panel,
            par,
            MemStack::new(&mut buffer),
        );
    })
}

/// Solves A X = B together with A X' = I, in one factorisation: returns [X | A^-1] (split it
/// with `split_at_col(B.ncols())`). For callers
/// that need a condition number of A beside the solution; the inverse costs what n more
/// right-hand sides cost, and is used for its norm, never to form X. A is overwritten by its
/// factors; a singular A gives non-finite entries. Stops as [`solve`] does when the
/// computation is interrupted.
pub fn solve_with_inverse(a: MatMut<'_, f64>, b: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    let (n, k) = (a.nrows(), b.ncols());
    let mut rhs = Mat::<f64>::zeros(n, k + n);
    rhs.as_mut().subcols_mut(0, k).copy_from(b);
    for i in 0..n {
        rhs[(i, k + i)] = 1.0;
    }
    solve(a, rhs.as_mut(), Par::Seq)?;
    Ok(rhs)
}

/// Gaussian elimination with partial pivoting (LAPACK's dgetf2 order: at step k the largest
/// |a_ik|, i >= k, is swapped into the pivot position, the multipliers l_ik = a_ik / a_kk are
/// stored below the diagonal and the trailing columns are updated), then for each column of B
/// the row swaps, L Y = P B and U X = Y (dgetrs). The factors are formed in a copy on the
/// stack, where the loops index plain arrays, and written back to A. A zero pivot, which only
/// an exactly singular A produces, is skipped, and the substitution then yields non-finite
/// entries.
fn eliminate_and_substitute(a: MatMut<'_, f64>, b: MatMut<'_, f64>) {
    // At its order as a constant: the loops over a column unroll.
    with_order!(
        a.nrows(),
        [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12],
        N => eliminate_and_substitute_in::<N>(a, b),
        n => assert_eq!(n, 0, "eliminate_and_substitute of order {n} > UNBLOCKED_MAX_ORDER")
    )
}

/// [`eliminate_and_substitute`] at the order N.
fn eliminate_and_substitute_in<const N: usize>(mut a: MatMut<'_, f64>, mut b: MatMut<'_, f64>) {
    const { assert!(N <= UNBLOCKED_MAX_ORDER) };
    let n = N;
    debug_assert_eq!(a.nrows(), N);
    // Column-major: lu[k][i] = a_ik.
    let mut lu = [[0.0; N]; N];
    for (k, column) in lu.iter_mut().enumerate() {
        for (i, entry) in column.iter_mut().enumerate() {
            *entry = a[(i, k)];
        }
    }
    let mut pivots = [0usize; N];
    for k in 0..n {
        let mut pivot_row = k;
        for i in k + 1..n {
            if lu[k][i].abs() > lu[k][pivot_row].abs() {
                pivot_row = i;
            }
        }
        pivots[k] = pivot_row;
        if pivot_row != k {
            for column in lu.iter_mut() {
                column.swap(k, pivot_row);
            }
        }
        let pivot = lu[k][k];
        if pivot == 0.0 {
            continue;
        }
        for multiplier in &mut lu[k][k + 1..n] {
            *multiplier /= pivot;
        }
        let (done, trailing) = lu.split_at_mut(k + 1);
        let multipliers = &done[k];
        for column in trailing.iter_mut().take(n - k - 1) {
            let upper = column[k];
            for i in k + 1..n {
                column[i] -= multipliers[i] * upper;
            }
        }
    }
    for (k, column) in lu.iter().enumerate() {
        for (i, &entry) in column.iter().enumerate() {
            a[(i, k)] = entry;
        }
    }
    // The right-hand sides in groups: each step of the substitutions then updates every column
    // of the group, so that their divisions by the pivot overlap instead of each column's
    // waiting on its previous step (the operations on each entry are those of one column at a
    // time).
    const GROUP: usize = 8;
    let mut x = [[0.0; N]; GROUP];
    for first in (0..b.ncols()).step_by(GROUP) {
        let group = GROUP.min(b.ncols() - first);
        let x = &mut x[..group];
        for (c, column) in x.iter_mut().enumerate() {
            for (i, entry) in column.iter_mut().enumerate() {
                *entry = b[(i, first + c)];
            }
            for (k, &pivot_row) in pivots.iter().enumerate() {
                column.swap(k, pivot_row);
            }
        }
        for k in 0..n {
            for column in x.iter_mut() {
                let solved = column[k];
                for i in k + 1..n {
                    column[i] -= lu[k][i] * solved;
                }
            }
        }
        for k in (0..n).rev() {
            for column in x.iter_mut() {
                column[k] /= lu[k][k];
                let solved = column[k];
                for i in 0..k {
                    column[i] -= lu[k][i] * solved;
                }
            }
        }
        for (c, column) in x.iter().enumerate() {
            for (i, &entry) in column.iter().enumerate() {
                b[(i, first + c)] = entry;
            }
        }
    }
}

fn factor_and_solve(
    mut a: MatMut<'_, f64>,
    b: MatMut<'_, f64>,
    perm: &mut [usize],
    perm_inverse: &mut [usize],
    stack: &mut MemStack,
    par: Par,
) {
    let (_, row_perm) =
        factor::lu_in_place(a.as_mut(), perm, perm_inverse, par, stack, lu_parameters());
    // The unit lower factor L and the upper factor U share the storage of `a`.
    solve::solve_in_place(a.as_ref(), a.as_ref(), row_perm, b, par, stack);
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::{Mat, c64, mat};

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = mat![[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        let x_true = mat![[1.0, -2.0], [2.0, 0.5], [-1.0, 4.0]];
        let mut b = &a * &x_true;
        solve(a.clone().as_mut(), b.as_mut(), Par::Seq).unwrap();
        assert!((&b - &x_true).norm_l2() < 1e-14);
    }

    /// B <- A^-1 B by one faer factorisation and solve on one thread (A overwritten).
    fn one_factor_and_solve(a: MatMut<'_, f64>, b: MatMut<'_, f64>) {
        let (n, k) = (a.nrows(), b.ncols());
        let (mut perm, mut perm_inverse) = (vec![0; n], vec![0; n]);
        let mut buffer = MemBuffer::new(
            factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, lu_parameters())
                .or(solve::solve_in_place_scratch::<usize, f64>(n, k, Par::Seq)),
        );
        factor_and_solve(
            a,
            b,
            &mut perm,
            &mut perm_inverse,
            MemStack::new(&mut buffer),
            Par::Seq,
        );
    }

    #[test]
    fn small_systems_agree_with_the_blocked_factorisation() {
        for n in 1..=UNBLOCKED_MAX_ORDER {
            let a = crate::test_matrices::seeded(n, n, n as u64);
            let b = crate::test_matrices::seeded(n, 3, 100 + n as u64);
            // A transposed view (row stride 1), as the pole placement passes V^T.
            let mut small = b.clone();
            let mut factors = a.transpose().to_owned();
            eliminate_and_substitute(factors.as_mut(), small.as_mut());
            let mut blocked = b.clone();
            let mut transposed = a.clone();
            one_factor_and_solve(transposed.as_mut().transpose_mut(), blocked.as_mut());
            let residual = (a.transpose() * &small - &b).norm_max();
            assert!(
                residual <= 1e-13 * (1.0 + small.norm_max()),
                "n = {n}: {residual:e}"
            );
            assert!(
                (&small - &blocked).norm_max() <= 1e-12 * small.norm_max(),
                "n = {n}"
            );
        }
    }

    #[test]
    fn singular_small_systems_give_non_finite_entries() {
        let a = mat![[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]];
        let mut b = mat![[1.0], [1.0], [1.0]];
        solve(a.clone().as_mut(), b.as_mut(), Par::Seq).unwrap();
        assert!(!b.is_all_finite());
        let mut b = Mat::<f64>::ones(2, 1);
        solve(Mat::<f64>::zeros(2, 2).as_mut(), b.as_mut(), Par::Seq).unwrap();
        assert!(!b.is_all_finite());
    }

    /// Bit patterns, so that NaNs compare equal to themselves.
    fn bits(m: MatRef<'_, f64>) -> Vec<u64> {
        (0..m.ncols())
            .flat_map(|j| (0..m.nrows()).map(move |i| m[(i, j)].to_bits()))
            .collect()
    }

    /// Orders above the one-call limit (n^3 > 2^30), one not a multiple of 16; a matrix with
    /// graded columns, and rank-deficient and singular ones.
    fn large_cases() -> Vec<(String, Mat<f64>)> {
        let mut cases = Vec::new();
        for (n, seed) in [(1100, 1), (1531, 2)] {
            let a = crate::test_matrices::seeded(n, n, seed);
            cases.push((format!("random {n}"), a.clone()));
            let graded = Mat::from_fn(n, n, |i, j| {
                a[(i, j)] * 10f64.powf(-12.0 * j as f64 / n as f64)
            });
            cases.push((format!("graded {n}"), graded));
            // Rank n - 40: the last columns repeat earlier ones.
            let deficient =
                Mat::from_fn(n, n, |i, j| a[(i, if j + 40 >= n { j - 600 } else { j })]);
            cases.push((format!("rank-deficient {n}"), deficient));
            let mut zero_column = a.clone();
            zero_column.col_mut(700).fill(0.0);
            cases.push((format!("zero column {n}"), zero_column));
        }
        cases
    }

    #[test]
    fn large_factorisations_and_solves_are_bitwise_faers() {
        for (name, a) in large_cases() {
            let n = a.nrows();
            let b = crate::test_matrices::seeded(n, 300, n as u64);
            let ours = Lu::new(a.as_ref()).unwrap();
            let faers = a.partial_piv_lu();
            assert_eq!(bits(ours.L()), bits(faers.L()), "{name}: L");
            assert_eq!(bits(ours.U()), bits(faers.U()), "{name}: U");
            assert_eq!(
                ours.perm.as_ref().arrays().0,
                faers.P().arrays().0,
                "{name}: P"
            );
            use faer::linalg::solvers::Solve;
            assert_eq!(
                bits(ours.solve(b.as_ref()).unwrap().as_ref()),
                bits(faers.solve(&b).as_ref()),
                "{name}: solve"
            );
            let mut transposed = b.clone();
            ours.solve_transpose_in_place(transposed.as_mut()).unwrap();
            assert_eq!(
                bits(transposed.as_ref()),
                bits(faers.solve_transpose(&b).as_ref()),
                "{name}: solve_transpose"
            );
            // `solve`, against the one faer factorisation and solve of before.
            let mut x = b.clone();
            solve(a.clone().as_mut(), x.as_mut(), Par::Seq).unwrap();
            let mut expected = b.clone();
            one_factor_and_solve(a.clone().as_mut(), expected.as_mut());
            assert_eq!(bits(x.as_ref()), bits(expected.as_ref()), "{name}: solve");
            if name.starts_with("random") {
                let residual = (&a * &x - &b).norm_max();
                assert!(residual < 1e-9, "{name}: {residual:e}");
            } else if name.starts_with("zero") {
                assert!(!x.is_all_finite(), "{name}");
            }
        }
    }

    /// A complex matrix from two seeded real ones.
    fn complex(n: usize, seed: u64) -> Mat<c64> {
        let (re, im) = (
            crate::test_matrices::seeded(n, n, seed),
            crate::test_matrices::seeded(n, n, seed + 1),
        );
        Mat::from_fn(n, n, |i, j| c64::new(re[(i, j)], im[(i, j)]))
    }

    #[test]
    fn large_complex_factorisations_and_solves_are_bitwise_faers() {
        // Complex multiply-adds count four real ones: orders above 645 are split. A random
        // matrix, one with graded columns and a singular one (a zero column).
        let a = complex(700, 11);
        let graded = Mat::from_fn(700, 700, |i, j| {
            a[(i, j)] * 10f64.powf(-12.0 * j as f64 / 700.0)
        });
        let mut zero_column = complex(900, 13);
        zero_column.col_mut(400).fill(c64::new(0.0, 0.0));
        for (name, a) in [
            ("random", a),
            ("graded", graded),
            ("zero column", zero_column),
        ] {
            let n = a.nrows();
            let b = complex(n, 20).subcols(0, 40).to_owned();
            let ours = Lu::new(a.as_ref()).unwrap();
            let faers = a.partial_piv_lu();
            let complex_bits = |m: MatRef<'_, c64>| {
                let re = Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)].re);
                let im = Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)].im);
                (bits(re.as_ref()), bits(im.as_ref()))
            };
            assert_eq!(complex_bits(ours.L()), complex_bits(faers.L()), "{name}: L");
            assert_eq!(complex_bits(ours.U()), complex_bits(faers.U()), "{name}: U");
            assert_eq!(
                ours.perm.as_ref().arrays().0,
                faers.P().arrays().0,
                "{name}: P"
            );
            use faer::linalg::solvers::Solve;
            let x = ours.solve(b.as_ref()).unwrap();
            assert_eq!(
                complex_bits(x.as_ref()),
                complex_bits(faers.solve(&b).as_ref()),
                "{name}"
            );
            let (det, expected) = (ours.determinant(), a.determinant());
            assert_eq!(
                (det.re.to_bits(), det.im.to_bits()),
                (expected.re.to_bits(), expected.im.to_bits()),
                "{name}: determinant"
            );
            if name == "random" {
                let residual = (&a * &x - &b).norm_max();
                assert!(residual < 1e-9, "{name}: {residual:e}");
            } else if name == "zero column" {
                assert!(!x.is_all_finite(), "{name}");
            }
        }
    }

    #[test]
    fn determinants_are_faers() {
        for (n, seed) in [(1, 1), (5, 2), (40, 3), (300, 4)] {
            let a = crate::test_matrices::seeded(n, n, seed);
            let det = Lu::new(a.as_ref()).unwrap().determinant();
            assert_eq!(det.to_bits(), a.determinant().to_bits(), "n = {n}");
            let a = complex(n, seed + 10);
            let (det, expected) = (Lu::new(a.as_ref()).unwrap().determinant(), a.determinant());
            assert_eq!(
                (det.re.to_bits(), det.im.to_bits()),
                (expected.re.to_bits(), expected.im.to_bits())
            );
        }
        // A permutation of parity odd: det = -1.
        let swap = faer::mat![[0.0, 1.0], [1.0, 0.0]];
        assert_eq!(Lu::new(swap.as_ref()).unwrap().determinant(), -1.0);
        assert_eq!(
            Lu::<f64>::new(Mat::zeros(0, 0).as_ref())
                .unwrap()
                .determinant(),
            1.0
        );
    }

    #[test]
    fn an_interrupted_factorisation_stops() {
        let a = crate::test_matrices::seeded(1100, 1100, 5);
        let token = crate::platform::interrupt::Token::default();
        token.cancel();
        crate::platform::interrupt::within(&token, || {
            assert_eq!(Lu::new(a.as_ref()).err(), Some(Error::Interrupted));
            let mut b = Mat::<f64>::zeros(1100, 1);
            assert_eq!(
                solve(a.clone().as_mut(), b.as_mut(), Par::Seq),
                Err(Error::Interrupted)
            );
            assert_eq!(
                Lu::new(complex(700, 7).as_ref()).err(),
                Some(Error::Interrupted)
            );
            // Small factorisations are one call, and finish.
            let small = crate::test_matrices::seeded(100, 100, 6);
            assert!(Lu::new(small.as_ref()).is_ok());
        });
    }

    #[test]
    fn large_systems_use_the_heap() {
        let n = 80;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == j {
                4.0
            } else {
                1.0 / (1 + i + j) as f64
            }
        });
        let x_true = Mat::from_fn(n, 1, |i, _| i as f64 - 7.0);
        let mut b = &a * &x_true;
        solve(a.clone().as_mut(), b.as_mut(), Par::Seq).unwrap();
        assert!((&b - &x_true).norm_max() < 1e-12);
    }
}
