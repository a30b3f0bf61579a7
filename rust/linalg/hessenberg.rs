//! Reduction to upper Hessenberg form, A = Q H Q^T, by Householder reflections (faer).
//!
//! H is zero below its first subdiagonal and Q is orthogonal. Shifted systems (sI - A) x = b,
//! solved at many shifts s (the frequency response), then cost O(n^2) each instead of O(n^3):
//! (sI - A) = Q (sI - H) Q^T, and sI - H is Hessenberg. The reduction is backward stable:
//! Q H Q^T = A + E with ||E|| = O(u ||A||).

use crate::error::Error;
use crate::linalg::balance::{balance, order_graded_states, range_scale};
use crate::linalg::householder::reflector;
use crate::linalg::matrix::{
    FaerView, Order, Square, Transformations, from_faer_in, identity_in, with_order,
};
use crate::platform::dispatch::clear_upper_avx_state;
use crate::platform::interrupt;
use crate::platform::pool::scratch;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::evd::hessenberg::{hessenberg_in_place, hessenberg_in_place_scratch};
use faer::linalg::householder::{
    apply_block_householder_sequence_on_the_right_in_place_scratch,
    apply_block_householder_sequence_on_the_right_in_place_with_conj,
};
use faer::linalg::qr::no_pivoting::factor::recommended_block_size;
use faer::{Conj, Mat, MatMut, MatRef, Par};

/// The Hessenberg form of a square matrix: A = Q H Q^T.
#[derive(Debug, Clone)]
pub struct Hessenberg {
    /// Upper Hessenberg (exact zeros below the first subdiagonal).
    pub h: Mat<f64>,
    /// Orthogonal.
    pub q: Mat<f64>,
}

/// The Hessenberg form of a square matrix (the caller checks that it is square and finite).
/// Between the reduction and the forming of Q (two long steps at large orders) it stops if the
/// computation was interrupted.
pub fn hessenberg(a: MatRef<'_, f64>) -> Result<Hessenberg, Error> {
    let n = a.nrows();
    if n <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        // The plain Householder loop at a fixed order: faer's blocked reduction (its set-up
        // and workspace) costs several times the arithmetic at these orders.
        return Ok(with_order!(n, order => {
            let mut h = from_faer_in(order, a);
            let mut q = identity_in(order);
            reduce_to_hessenberg(&mut h, Some(&mut q));
            Hessenberg {
                h: h.to_faer(),
                q: q.to_faer(),
            }
        }));
    }
    let mut h = a.to_owned();
    let mut q = Mat::<f64>::identity(n, n);
    reduce(h.as_mut(), Some(q.as_mut()))?;
    Ok(Hessenberg { h, q })
}

/// H alone, when the transformation is not needed (eigenvalues).
pub fn hessenberg_matrix(a: MatRef<'_, f64>) -> Mat<f64> {
    let mut h = a.to_owned();
    // Without Q there is one step only: nothing to interrupt between.
    let _ = reduce(h.as_mut(), None);
    h
}

/// Reduces `h` to Hessenberg form in place and, if given, overwrites `q` (the identity on
/// entry) with the transformation.
fn reduce(mut h: MatMut<'_, f64>, q: Option<MatMut<'_, f64>>) -> Result<(), Error> {
    let n = h.nrows();
    if n <= 2 {
        // Already Hessenberg.
        return Ok(());
    }
    // Sequential at every order: faer's parallel reduction rounds differently with the
    // number of threads, and the Schur forms and eigenvalues would depend on the machine.
    let par = Par::Seq;
    let block_size = recommended_block_size::<f64>(n - 1, n - 1);
    let mut householder = scratch(block_size, n - 1);
    let requirement = StackReq::any_of(&[
        hessenberg_in_place_scratch::<f64>(n, block_size, par, Default::default()),
        apply_block_householder_sequence_on_the_right_in_place_scratch::<f64>(
            n - 1,
            block_size,
            n - 1,
        ),
    ]);
    let mut buffer = MemBuffer::new(requirement);
    let stack = MemStack::new(&mut buffer);
    hessenberg_in_place(
        h.as_mut(),
        householder.as_mut(),
        par,
        stack,
        Default::default(),
    );
    if let Some(q) = q {
        interrupt::check()?;
        // The reflectors act on rows and columns 1..n; Q = diag(1, Q1).
        apply_block_householder_sequence_on_the_right_in_place_with_conj(
            h.as_ref().submatrix(1, 0, n - 1, n - 1),
            householder.as_ref(),
            Conj::No,
            q.submatrix_mut(1, 1, n - 1, n - 1),
            par,
            stack,
        );
    }
    for j in 0..n {
        for i in j + 2..n {
            h[(i, j)] = 0.0;
        }
    }
    Ok(())
}

/// Up to this order the Hessenberg reduction is the plain Householder loop below; above it,
/// faer's blocked reduction (whose set-up costs more than the whole reduction at n = 4).
pub(crate) const UNBLOCKED_HESSENBERG_MAX_ORDER: usize = 32;

/// The upper Hessenberg form H of the balanced D^-1 (A / s) D, its states ordered by decreasing
/// size where they are graded ([`order_graded_states`]), with s the power of two that brings
/// A's entries into range ([`range_scale`]): returns (H, s). H is similar to A / s, so
/// it has the eigenvalues and the characteristic polynomial of A / s (the balancing is exact,
/// the reduction backward stable). The caller checks that A is finite.
pub(crate) fn balanced_hessenberg<O: Order>(a: Square<O>) -> (Square<O>, f64) {
    let (mut h, scale, _) = balanced(a);
    reduce_in_place(&mut h);
    (h, scale)
}

/// D^-1 (A / s) D of [`balanced_hessenberg`] before its reduction: returns it, s, and whether
/// its states were graded (and ordered).
pub(crate) fn balanced<O: Order>(mut h: Square<O>) -> (Square<O>, f64, bool) {
    let scale = range_scale(h.as_faer());
    if scale != 1.0 {
        h.as_mut_slice().iter_mut().for_each(|x| *x /= scale);
    }
    let _ = balance(&mut h);
    let graded = order_graded_states(&mut h);
    (h, scale, graded)
}

/// H alone, in place: the plain reduction up to [`UNBLOCKED_HESSENBERG_MAX_ORDER`], faer's
/// blocked one above.
pub(crate) fn reduce_in_place<O: Order>(h: &mut Square<O>) {
    if h.nrows() <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        reduce_to_hessenberg(h, None);
    } else {
        *h = from_faer_in(
            h.shape_generic().0,
            hessenberg_matrix(h.to_faer().as_ref()).as_ref(),
        );
    }
}

/// Householder reduction to upper Hessenberg form in place, H = Q^T A Q; `q` (the identity on
/// entry) becomes Q. Reflector k maps column k below the subdiagonal onto e_{k+1}. Any order
/// (the reflectors on the stack up to [`UNBLOCKED_HESSENBERG_MAX_ORDER`], on the heap beyond);
/// above that order faer's blocked reduction is faster, where the caller can take it.
pub(crate) fn reduce_to_hessenberg<O: Order>(h: &mut Square<O>, mut q: Option<&mut Square<O>>) {
    clear_upper_avx_state();
    let n = h.nrows();
    let mut on_stack = [0.0; UNBLOCKED_HESSENBERG_MAX_ORDER];
    let mut on_heap = Vec::new();
    let buffer: &mut [f64] = if n <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        &mut on_stack
    } else {
        on_heap.resize(n, 0.0);
        &mut on_heap
    };
    for k in 0..n.saturating_sub(2) {
        let length = n - k - 1;
        let w = &mut buffer[..length];
        for (r, x) in w.iter_mut().enumerate() {
            *x = h[(k + 1 + r, k)];
        }
        let (beta, tau) = reflector(w);
        if tau == 0.0 {
            continue;
        }
        w[0] = 1.0;
        // The short reflectors of the small orders with their length a constant, so that
        // each column's product unrolls (the same operations: w_0 = 1 is not multiplied).
        let columns = k + 1..n;
        match length {
            2 => h.reflect_rows_fixed::<2>(k + 1, fixed(w), tau, columns),
            3 => h.reflect_rows_fixed::<3>(k + 1, fixed(w), tau, columns),
            4 => h.reflect_rows_fixed::<4>(k + 1, fixed(w), tau, columns),
            5 => h.reflect_rows_fixed::<5>(k + 1, fixed(w), tau, columns),
            6 => h.reflect_rows_fixed::<6>(k + 1, fixed(w), tau, columns),
            7 => h.reflect_rows_fixed::<7>(k + 1, fixed(w), tau, columns),
            _ => h.reflect_rows(k + 1, w, tau, columns),
        }
        h.reflect_columns(k + 1, w, tau, 0..n);
        h[(k + 1, k)] = beta;
        for r in k + 2..n {
            h[(r, k)] = 0.0;
        }
        if let Some(q) = q.as_deref_mut() {
            q.reflect_columns(k + 1, w, tau, 0..n);
        }
    }
}

/// The first `L` entries of `w` as an array.
#[inline(always)]
fn fixed<const L: usize>(w: &[f64]) -> [f64; L] {
    std::array::from_fn(|r| w[r])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plain_reduction_reconstructs_at_every_order() {
        use crate::linalg::matrix::from_faer;
        // Past the stack buffer's order too (the root locus reduces loops of any order).
        for n in [1usize, 2, 32, 33, 34, 40, 70] {
            let a = Mat::from_fn(n, n, |i, j| ((i * 7 + j * 13) % 17) as f64 / 8.0 - 1.0);
            let mut h = from_faer(a.as_ref());
            let mut q = from_faer(Mat::<f64>::identity(n, n).as_ref());
            reduce_to_hessenberg(&mut h, Some(&mut q));
            let (h, q) = (h.to_faer(), q.to_faer());
            for j in 0..n {
                for i in j + 2..n {
                    assert_eq!(h[(i, j)], 0.0);
                }
            }
            let residual = (&q * &h * q.transpose() - &a).norm_l2() / a.norm_l2().max(1.0);
            assert!(residual < 1e-14, "n={n}: {residual}");
        }
    }

    #[test]
    fn reconstructs_and_is_orthogonal() {
        for n in [1usize, 2, 3, 5, 12, 40] {
            let a = Mat::from_fn(n, n, |i, j| ((i * 7 + j * 13) % 17) as f64 / 8.0 - 1.0);
            let Hessenberg { h, q } = hessenberg(a.as_ref()).unwrap();
            for j in 0..n {
                for i in j + 2..n {
                    assert_eq!(h[(i, j)], 0.0);
                }
            }
            let residual = (&q * &h * q.transpose() - &a).norm_l2() / a.norm_l2().max(1.0);
            assert!(residual < 1e-14, "n={n}: {residual}");
            let orthogonality = (q.transpose() * &q - Mat::<f64>::identity(n, n)).norm_l2();
            assert!(orthogonality < 1e-14, "n={n}: {orthogonality}");
        }
    }
}
