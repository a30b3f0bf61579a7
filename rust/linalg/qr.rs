//! The Householder QR factorisation without pivoting (faer's blocked `qr_in_place`), and the
//! application of its Q, stopping between blocks of work when the computation is interrupted.
//!
//! faer's blocked QR (the compact WY form of Schreiber & Van Loan: each block of columns is
//! factored, its reflectors gathered into I - V T V^H, which is applied to the columns to its
//! right) is driven from here one block of columns at a time, with faer's block size, its
//! kernels and its gathering of the block's factor T, and [`interrupt::check`] between blocks;
//! the applications of Q or Q^T to another matrix go one block reflector at a time, as faer's
//! do, with a check between them. (faer's kernel of a block reflector does not round the same
//! on a part of the columns as on all of them: column panels would not be bitwise.) A block's
//! work is about 2 m n b multiply-adds for faer's block size b (64 up to order 2048, then 128):
//! 0.4 G at order 2500. Factors are
//! bitwise those of one faer call (the tests check it) with one exception that no matrix of
//! full numerical rank meets: faer skips a column whose part below the diagonal is within
//! 16 (m - k) u of its norm (a rank-deficient matrix: faer's staircase form), and its norm here
//! counts only the entries from the top of the block down. A block that skips a column makes
//! the whole factorisation be redone as one faer call (from a copy of the matrix); a column
//! that faer would skip but this driver does not is reflected like any other (a valid
//! Householder step: the factorisation is backward stable either way, to the same bound).
//!
//! R. Schreiber, C. Van Loan, "A storage-efficient WY representation for products of
//! Householder transformations", SIAM J. Sci. Stat. Comput. 10(1), 1989.

use crate::error::Error;
use crate::linalg::product::{Entry, PANEL_MULTIPLY_ADDS};
use crate::platform::interrupt;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::householder::{
    apply_block_householder_transpose_on_the_left_in_place_scratch,
    apply_block_householder_transpose_on_the_left_in_place_with_conj, upgrade_householder_factor,
};
use faer::linalg::qr::no_pivoting::factor::{
    QrParams, qr_in_place_scratch, recommended_block_size,
};
use faer::prelude::{Reborrow, ReborrowMut};
use faer::{Conj, Mat, MatMut, MatRef, Par, Spec};

/// faer's threshold (its default `QrParams`) below which a block of m x n is factored
/// without sub-blocks.
const BLOCKING_THRESHOLD: usize = 48 * 48;

/// The QR factorisation of the m x n matrix `a` in place, as faer's `qr_in_place` with its
/// recommended block size (the number of rows of `householder`, which must have min(m, n)
/// columns) and default parameters: R on and above the diagonal, the reflectors' essential
/// parts below, the blocks' triangular factors in `householder`. Returns the rank faer
/// reports. A matrix of fewer than 2 [`PANEL_MULTIPLY_ADDS`] real multiply-adds (m n^2) is
/// one faer call; a larger one is driven a block of columns at a time (see the module
/// documentation). `Err(Error::Interrupted)` leaves `a` partly factored.
pub fn qr_in_place<T: Entry>(
    mut a: MatMut<'_, T>,
    mut householder: MatMut<'_, T>,
    par: Par,
) -> Result<usize, Error> {
    let (m, n) = a.shape();
    let block_size = householder.nrows();
    let cost = m
        .saturating_mul(n)
        .saturating_mul(n)
        .saturating_mul(T::REAL_MULTIPLY_ADDS);
    // The blocks reproduce faer's sub-blocking where every block after the first has
    // m (col + 1) >= 2304 (see `factor_block`).
    if cost < 2 * PANEL_MULTIPLY_ADDS || block_size < 2 || m < BLOCKING_THRESHOLD / 2 {
        return Ok(one_call(a, householder, par));
    }
    let original = a.to_owned();
    let size = m.min(n);
    let sub_block_size = block_size / 2;
    let mut col = 0;
    while col < size {
        interrupt::check()?;
        let width = block_size.min(size - col);
        if !factor_block(
            a.rb_mut(),
            householder.rb_mut(),
            col,
            width,
            sub_block_size,
            par,
        )? {
            // A skipped column: faer's staircase form, which a block of its own cannot
            // reproduce.
            a.copy_from(&original);
            return Ok(one_call(a, householder, par));
        }
        col += width;
    }
    Ok(size)
}

/// One faer call.
fn one_call<T: Entry>(a: MatMut<'_, T>, householder: MatMut<'_, T>, par: Par) -> usize {
    let (m, n) = a.shape();
    let mut buffer = MemBuffer::new(qr_in_place_scratch::<T>(
        m,
        n,
        householder.nrows(),
        par,
        Default::default(),
    ));
    faer::linalg::qr::no_pivoting::factor::qr_in_place(
        a,
        householder,
        par,
        MemStack::new(&mut buffer),
        Default::default(),
    )
    .rank
}

/// Factors columns col..col + width of `a` (rows col..), whose columns to the left are
/// factored, as faer's blocked QR does its block at `col` when no column before it was
/// skipped: the block by faer's QR with sub-blocks of `sub_block_size` columns, its factor T
/// gathered from theirs, and I - V T^H V^H applied to the columns to its right. Returns false,
/// with `a` partly updated, if the block skipped a column.
fn factor_block<T: Entry>(
    mut a: MatMut<'_, T>,
    mut householder: MatMut<'_, T>,
    col: usize,
    width: usize,
    sub_block_size: usize,
    par: Par,
) -> Result<bool, Error> {
    let (m, n) = a.shape();
    // faer factors the block within all m rows and the columns up to its end; its tests of
    // m (columns) against the blocking threshold then hold for every sub-block except in the
    // first block (col = 0), where the block's own shape is the same as faer's.
    let mut parameters: Spec<QrParams, T> = Default::default();
    if col > 0 {
        parameters.config.blocking_threshold = 0;
    }
    let mut factor = Mat::<T>::zeros(sub_block_size.min(width).max(1), width);
    let mut buffer = MemBuffer::new(qr_in_place_scratch::<T>(
        m - col,
        width,
        factor.nrows(),
        par,
        parameters,
    ));
    let rank = faer::linalg::qr::no_pivoting::factor::qr_in_place(
        a.rb_mut().submatrix_mut(col, col, m - col, width),
        factor.as_mut(),
        par,
        MemStack::new(&mut buffer),
        parameters,
    )
    .rank;
    if rank < width {
        return Ok(false);
    }
    // faer's block holds the sub-blocks' factors in its first rows, moves each onto its
    // diagonal, then gathers them into one.
    let sub_block_size = sub_block_size.min(width);
    let mut block = householder.rb_mut().submatrix_mut(0, col, width, width);
    block
        .rb_mut()
        .subrows_mut(0, factor.nrows())
        .copy_from(factor.as_ref());
    let mut k = sub_block_size;
    while k < width {
        let columns = sub_block_size.min(width - k);
        let (top, mut bottom) = block.rb_mut().subcols_mut(k, columns).split_at_row_mut(k);
        bottom
            .rb_mut()
            .subrows_mut(0, columns)
            .copy_from_triangular_upper(top.rb().subrows(0, columns));
        k += columns;
    }
    upgrade_householder_factor(
        block.rb_mut(),
        a.rb().submatrix(col, col, m - col, width),
        width,
        sub_block_size,
        par,
    );
    let trailing = n - col - width;
    if trailing == 0 {
        return Ok(true);
    }
    let (left, right) = a
        .rb_mut()
        .subrows_mut(col, m - col)
        .split_at_col_mut(col + width);
    let mut buffer = MemBuffer::new(
        apply_block_householder_transpose_on_the_left_in_place_scratch::<T>(
            m - col,
            width,
            trailing,
        ),
    );
    apply_block_householder_transpose_on_the_left_in_place_with_conj(
        left.rb().subcols(col, width),
        block.rb(),
        Conj::Yes,
        right,
        par,
        MemStack::new(&mut buffer),
    );
    Ok(true)
}

/// Overwrites M with Q^T M (`Conj::No`; Q^H M with `Conj::Yes`) for the Q of a factorisation
/// by [`qr_in_place`] (its reflectors `basis`, its factors `householder`), as faer's
/// `apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj`: one block
/// reflector after another, from the first, each on the rows from its own down (bitwise the
/// same), with [`interrupt::check`] before each.
pub fn apply_transpose_on_the_left<T: Entry>(
    basis: MatRef<'_, T>,
    householder: MatRef<'_, T>,
    conj: Conj,
    mut matrix: MatMut<'_, T>,
    par: Par,
) -> Result<(), Error> {
    let block_size = householder.nrows();
    let size = householder.ncols();
    let mut buffer = MemBuffer::new(
        apply_block_householder_transpose_on_the_left_in_place_scratch::<T>(
            basis.nrows(),
            block_size,
            matrix.ncols(),
        ),
    );
    let mut j = 0;
    while j < size {
        interrupt::check()?;
        let width = block_size.min(size - j);
        apply_block_householder_transpose_on_the_left_in_place_with_conj(
            basis.get(j.., j..j + width),
            householder.get(.., j..j + width).subrows(0, width),
            conj,
            matrix.rb_mut().get_mut(j.., ..),
            par,
            MemStack::new(&mut buffer),
        );
        j += width;
    }
    Ok(())
}

/// Overwrites M with M Q (`Conj::No`; M conj(Q) with `Conj::Yes`), as faer's
/// `apply_block_householder_sequence_on_the_right_in_place_with_conj` (which applies Q^T to
/// M^T from the left): [`apply_transpose_on_the_left`] on M^T.
pub fn apply_on_the_right<T: Entry>(
    basis: MatRef<'_, T>,
    householder: MatRef<'_, T>,
    conj: Conj,
    matrix: MatMut<'_, T>,
    par: Par,
) -> Result<(), Error> {
    apply_transpose_on_the_left(basis, householder, conj, matrix.transpose_mut(), par)
}

/// faer's recommended block size for the QR of an m x n matrix.
pub fn block_size<T: Entry>(m: usize, n: usize) -> usize {
    recommended_block_size::<T>(m, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::platform::interrupt::{Token, within};
    use crate::test_matrices::seeded;
    use faer::dyn_stack::StackReq;
    use faer::linalg::householder::{
        apply_block_householder_sequence_on_the_right_in_place_scratch,
        apply_block_householder_sequence_on_the_right_in_place_with_conj,
        apply_block_householder_sequence_transpose_on_the_left_in_place_scratch,
        apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj,
    };

    fn bits(m: MatRef<'_, f64>) -> Vec<u64> {
        (0..m.ncols())
            .flat_map(|j| (0..m.nrows()).map(move |i| m[(i, j)].to_bits()))
            .collect()
    }

    /// faer's one call: the factored matrix and its block factors.
    fn faers(a: &Mat<f64>) -> (Mat<f64>, Mat<f64>) {
        let (m, n) = a.shape();
        let mut factored = a.clone();
        let mut householder = Mat::<f64>::zeros(block_size::<f64>(m, n), m.min(n));
        one_call(factored.as_mut(), householder.as_mut(), Par::Seq);
        (factored, householder)
    }

    #[test]
    fn blocked_factorisations_and_applications_are_bitwise_faers() {
        // Square and tall, orders not multiples of the block size; a graded matrix; one with
        // a zero column (faer skips it: redone as one call).
        let random = seeded(1400, 1400, 3);
        let graded = Mat::from_fn(1400, 1400, |i, j| {
            random[(i, j)] * 10f64.powf(-10.0 * j as f64 / 1400.0)
        });
        let mut zero_column = seeded(1350, 1350, 4);
        zero_column.col_mut(900).fill(0.0);
        for (name, a) in [
            ("square", seeded(1331, 1331, 1)),
            ("tall", seeded(2100, 1100, 2)),
            ("graded", graded),
            ("zero column", zero_column),
        ] {
            let (m, n) = a.shape();
            let (expected, expected_householder) = faers(&a);
            let mut ours = a.clone();
            let mut householder = Mat::<f64>::zeros(block_size::<f64>(m, n), m.min(n));
            qr_in_place(ours.as_mut(), householder.as_mut(), Par::Seq).unwrap();
            assert_eq!(
                bits(ours.as_ref()),
                bits(expected.as_ref()),
                "{name}: R and V"
            );
            assert_eq!(
                bits(householder.as_ref()),
                bits(expected_householder.as_ref()),
                "{name}: T"
            );
            // Q^T M and M Q block by block against one call each.
            let other = seeded(m, 1500, 5);
            let mut split = other.clone();
            apply_transpose_on_the_left(
                ours.as_ref(),
                householder.as_ref(),
                Conj::No,
                split.as_mut(),
                Par::Seq,
            )
            .unwrap();
            let mut one = other.clone();
            let bs = householder.nrows();
            let mut buffer = MemBuffer::new(StackReq::any_of(&[
                apply_block_householder_sequence_transpose_on_the_left_in_place_scratch::<f64>(
                    m, bs, 1500,
                ),
                apply_block_householder_sequence_on_the_right_in_place_scratch::<f64>(m, bs, 1500),
            ]));
            apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj(
                ours.as_ref(),
                householder.as_ref(),
                Conj::No,
                one.as_mut(),
                Par::Seq,
                MemStack::new(&mut buffer),
            );
            assert_eq!(bits(split.as_ref()), bits(one.as_ref()), "{name}: Q^T M");
            let other = seeded(1500, m, 6);
            let mut split = other.clone();
            apply_on_the_right(
                ours.as_ref(),
                householder.as_ref(),
                Conj::No,
                split.as_mut(),
                Par::Seq,
            )
            .unwrap();
            let mut one = other.clone();
            apply_block_householder_sequence_on_the_right_in_place_with_conj(
                ours.as_ref(),
                householder.as_ref(),
                Conj::No,
                one.as_mut(),
                Par::Seq,
                MemStack::new(&mut buffer),
            );
            assert_eq!(bits(split.as_ref()), bits(one.as_ref()), "{name}: M Q");
        }
    }

    #[test]
    fn an_interrupted_factorisation_stops() {
        let a = seeded(1331, 1331, 7);
        let token = Token::default();
        token.cancel();
        within(&token, || {
            let mut factored = a.clone();
            let mut householder = Mat::<f64>::zeros(block_size::<f64>(1331, 1331), 1331);
            assert_eq!(
                qr_in_place(factored.as_mut(), householder.as_mut(), Par::Seq),
                Err(Error::Interrupted)
            );
            // Small factorisations are one call, and finish.
            let mut small = seeded(200, 200, 8);
            let mut householder = Mat::<f64>::zeros(block_size::<f64>(200, 200), 200);
            assert_eq!(
                qr_in_place(small.as_mut(), householder.as_mut(), Par::Seq),
                Ok(200)
            );
        });
    }
}
