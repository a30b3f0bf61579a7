//! Linear solves by LU with partial pivoting (faer), without ever forming an inverse.
//!
//! A thin layer over faer's in-place factorisation. For small systems the pivot vectors and
//! faer's scratch live on the stack, so a solve allocates nothing.

use crate::linalg::matrix::with_order;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::{Mat, MatMut, MatRef, Par, Spec};
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

/// Solves A X = B for X, overwriting B, by LU factorisation of A with partial pivoting
/// (P A = L U, then L Y = P B, U X = Y); A is overwritten by its factors.
///
/// A singular A gives infinite or NaN entries, never a panic. (The exponential's Padé
/// denominators are well conditioned by the choice of degree and scaling, Higham 2005, §3;
/// other callers that can meet a singular matrix must check its conditioning.)
pub fn solve_in_place(a: MatMut<'_, f64>, b: MatMut<'_, f64>, par: Par) {
    let n = a.nrows();
    debug_assert_eq!(n, a.ncols());
    debug_assert_eq!(n, b.nrows());
    if n <= UNBLOCKED_MAX_ORDER {
        return eliminate_and_substitute(a, b);
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
    } else {
        let mut perm = vec![0usize; n];
        let mut perm_inverse = vec![0usize; n];
        let mut buffer = MemBuffer::new(requirement.or(StackReq::EMPTY));
        factor_and_solve(
            a,
            b,
            &mut perm,
            &mut perm_inverse,
            MemStack::new(&mut buffer),
            par,
        );
    }
}

/// Solves A X = B together with A X' = I, in one factorisation: returns [X | A^-1] (split it
/// with `split_at_col(B.ncols())`). For callers
/// that need a condition number of A beside the solution; the inverse costs what n more
/// right-hand sides cost, and is used for its norm, never to form X. A is overwritten by its
/// factors; a singular A gives non-finite entries.
pub fn solve_with_inverse(a: MatMut<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let (n, k) = (a.nrows(), b.ncols());
    let mut rhs = Mat::<f64>::zeros(n, k + n);
    rhs.as_mut().subcols_mut(0, k).copy_from(b);
    for i in 0..n {
        rhs[(i, k + i)] = 1.0;
    }
    solve_in_place(a, rhs.as_mut(), Par::Seq);
    rhs
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
    use faer::{Mat, mat};

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = mat![[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        let x_true = mat![[1.0, -2.0], [2.0, 0.5], [-1.0, 4.0]];
        let mut b = &a * &x_true;
        solve_in_place(a.clone().as_mut(), b.as_mut(), Par::Seq);
        assert!((&b - &x_true).norm_l2() < 1e-14);
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
            let mut perm = vec![0; n];
            let mut perm_inverse = vec![0; n];
            let requirement =
                factor::lu_in_place_scratch::<usize, f64>(n, n, Par::Seq, lu_parameters())
                    .or(solve::solve_in_place_scratch::<usize, f64>(n, 3, Par::Seq));
            let mut buffer = MemBuffer::new(requirement);
            let mut transposed = a.clone();
            factor_and_solve(
                transposed.as_mut().transpose_mut(),
                blocked.as_mut(),
                &mut perm,
                &mut perm_inverse,
                MemStack::new(&mut buffer),
                Par::Seq,
            );
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
        solve_in_place(a.clone().as_mut(), b.as_mut(), Par::Seq);
        assert!(!b.is_all_finite());
        let mut b = Mat::<f64>::ones(2, 1);
        solve_in_place(Mat::<f64>::zeros(2, 2).as_mut(), b.as_mut(), Par::Seq);
        assert!(!b.is_all_finite());
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
        solve_in_place(a.clone().as_mut(), b.as_mut(), Par::Seq);
        assert!((&b - &x_true).norm_max() < 1e-12);
    }
}
