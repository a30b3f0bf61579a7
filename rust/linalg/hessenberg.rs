//! Reduction to upper Hessenberg form, A = Q H Q^T, by Householder reflections.
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
use crate::platform::dispatch::{add_scaled, clear_upper_avx_state, dot_rows};
use crate::platform::interrupt;
use faer::linalg::matmul::matmul;
use faer::prelude::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};

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
        // The plain Householder loop at a fixed order: the blocked reduction (its set-up and
        // workspace) costs several times the arithmetic at these orders.
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
    reduce(&mut h, Some(&mut q))?;
    Ok(Hessenberg { h, q })
}

/// H alone, when the transformation is not needed (eigenvalues); stops between panels if the
/// computation was interrupted.
pub fn hessenberg_matrix(a: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    let mut h = a.to_owned();
    reduce(&mut h, None)?;
    Ok(h)
}

/// Reduces `h` to Hessenberg form in place and, if given, overwrites `q` (the identity on
/// entry) with the transformation: the blocked reduction of LAPACK's DGEHRD (G. Quintana-Ortí
/// and R. van de Geijn, "Improving the performance of reduction to Hessenberg form", ACM TOMS
/// 32(2), 2006, the panel factorization of LAPACK's DLAHR2), written here rather than taken
/// from faer so that it stops between panels when the computation is interrupted: faer's
/// reduction is one call (about a second at n = 1500 on two cores, growing as n^3), during
/// which Ctrl-C could not be answered. It is as fast as faer's from n = 64 to 1024.
///
/// Each panel of [`PANEL`] columns k..k+b is reduced with its reflectors accumulated as
/// Q_p = I - V T V^T (V unit lower trapezoidal, T upper triangular; Schreiber & Van Loan's
/// compact WY form), so that the trailing matrix is updated once per panel by matrix products,
///
/// ```text
/// Q_p^T A Q_p = (I - V T^T V^T) (A - Y V^T),   Y = A V T,
/// ```
///
/// and column k + i of the panel, before its own reflector is formed, is brought up to date
/// with the first i reflectors only: b = (I - V_i T_i^T V_i^T) (A e_{k+i} - Y_i V_i^T e_{k+i}).
/// Y's column i comes from one matrix-vector product with the not yet updated trailing columns,
/// Y e_i = τ_i (A v_i - Y_i V_i^T v_i), and T's from T e_i = -τ_i T_i V_i^T v_i, τ_i e_i. Q is
/// accumulated backwards (Q = Q_0 (Q_1 (... Q_last))), each panel acting on the trailing rows
/// and columns only. Sequential: the rounding does not depend on the number of threads.
fn reduce(h: &mut Mat<f64>, q: Option<&mut Mat<f64>>) -> Result<(), Error> {
    let n = h.nrows();
    let mut work = PanelWork::new(n);
    // The V and T of each panel, kept to form Q.
    let mut panels = Vec::new();
    let mut k = 0;
    while k + 2 < n {
        interrupt::check()?;
        let b = PANEL.min(n - 2 - k);
        reduce_panel(h, k, b, &mut work);
        if q.is_some() {
            panels.push((k, work.v[..(n - k - 1) * b].to_vec(), work.t.clone()));
        }
        k += PANEL;
    }
    if let Some(q) = q {
        for (k, v, t) in panels.iter().rev() {
            interrupt::check()?;
            // Q[k+1.., k+1..] <- (I - V T V^T) Q[k+1.., k+1..].
            let m = n - k - 1;
            let v = MatRef::from_column_major_slice(v, m, t.nrows());
            let q = q.as_mut().submatrix_mut(k + 1, k + 1, m, m);
            subtract_block_reflection(v, t.as_ref(), q, &mut work.products);
        }
    }
    Ok(())
}

/// The workspace of [`reduce_panel`], allocated once for all panels of an order-n reduction.
struct PanelWork {
    /// V (rows k+1..n) and the rows k+1.. of Y, column by column without padding, so that
    /// V_i^T x is one `dot_rows` over i columns.
    v: Vec<f64>,
    y: Vec<f64>,
    /// T of the last panel (b x b).
    t: Mat<f64>,
    column: Vec<f64>,
    w: Vec<f64>,
    /// Two b x n blocks for the products of the updates.
    products: [Vec<f64>; 2],
}

impl PanelWork {
    fn new(n: usize) -> Self {
        let block = n * PANEL;
        Self {
            v: vec![0.0; block],
            y: vec![0.0; block],
            t: Mat::zeros(0, 0),
            column: vec![0.0; n],
            w: vec![0.0; PANEL],
            products: [vec![0.0; block], vec![0.0; block]],
        }
    }
}

/// Reduces columns k..k+b of `h` (b of them, k + b <= n - 2) and applies their reflectors to
/// the rest of `h` (see [`reduce`]); leaves V (rows k+1..n, unit entries and zeros explicit)
/// and T of Q_p = I - V T V^T in `work`.
fn reduce_panel(h: &mut Mat<f64>, k: usize, b: usize, work: &mut PanelWork) {
    let n = h.nrows();
    // Rows k+1..n: the rows the reflectors act on.
    let m = n - k - 1;
    let v = &mut work.v[..m * b];
    let y = &mut work.y[..m * b];
    v.fill(0.0);
    work.t = Mat::zeros(b, b);
    let t = &mut work.t;
    let column = &mut work.column[..m];
    let w = &mut work.w;
    for i in 0..b {
        let j = k + i;
        column.copy_from_slice(&h.col_as_slice(j)[k + 1..]);
        if i > 0 {
            // b <- b - Y_i V_i^T e_j (row j of V is its local row i - 1), then
            // b <- (I - V_i T_i^T V_i^T) b.
            for l in 0..i {
                add_scaled(column, -v[l * m + i - 1], &y[l * m..(l + 1) * m]);
            }
            dot_rows(&v[..i * m], column, &mut w[..i], false);
            upper_transpose_times(t.as_ref().submatrix(0, 0, i, i), &mut w[..i]);
            for l in 0..i {
                add_scaled(column, -w[l], &v[l * m..(l + 1) * m]);
            }
        }
        let x = &mut column[i..];
        let (beta, tau) = reflector(x);
        if tau == 0.0 {
            x[1..].fill(0.0);
        }
        x[0] = 1.0;
        // Column j of H: rows k+1..=j as updated, β, zeros; V's column i: 0, 1, v.
        let target = &mut h.col_as_slice_mut(j)[k + 1..];
        target[..i].copy_from_slice(&column[..i]);
        target[i] = beta;
        target[i + 1..].fill(0.0);
        let (previous, current) = v.split_at_mut(i * m);
        let vi = &mut current[..m];
        vi[i..].copy_from_slice(&column[i..]);
        // Y e_i = τ (A[k+1.., j+1..] v_i - Y_i (V_i^T v_i)), T e_i = (-τ T_i V_i^T v_i, τ).
        let (y_previous, y_current) = y.split_at_mut(i * m);
        let yi = &mut y_current[..m];
        matmul(
            MatMut::from_column_major_slice_mut(yi, m, 1),
            Accum::Replace,
            h.as_ref().submatrix(k + 1, j + 1, m, m - i),
            MatRef::from_column_major_slice(&vi[i..], m - i, 1),
            tau,
            Par::Seq,
        );
        if i > 0 {
            let z = &mut w[..i];
            dot_rows(previous, vi, z, false);
            for l in 0..i {
                add_scaled(yi, -tau * z[l], &y_previous[l * m..(l + 1) * m]);
            }
            for r in 0..i {
                let tz: f64 = (r..i).map(|l| t[(r, l)] * z[l]).sum();
                t[(r, i)] = -tau * tz;
            }
        }
        t[(i, i)] = tau;
    }
    let v = MatRef::from_column_major_slice(v, m, b);
    let y = MatRef::from_column_major_slice(y, m, b);
    // Rows 0..=k of Y, from the columns k+1.. as they were before the panel: A V T.
    let [top_v, top] = &mut work.products;
    let mut top_v = MatMut::from_column_major_slice_mut(&mut top_v[..(k + 1) * b], k + 1, b);
    let mut top = MatMut::from_column_major_slice_mut(&mut top[..(k + 1) * b], k + 1, b);
    let above = h.as_ref().submatrix(0, k + 1, k + 1, m);
    matmul(top_v.rb_mut(), Accum::Replace, above, v, 1.0, Par::Seq);
    matmul(
        top.rb_mut(),
        Accum::Replace,
        top_v.rb(),
        t.as_ref(),
        1.0,
        Par::Seq,
    );
    // A <- A - Y V^T: rows 0..=k of every column after k, rows k+1.. of the columns after the
    // panel (the panel's own were updated as they were reduced).
    let right = h.as_mut().submatrix_mut(0, k + 1, k + 1, m);
    matmul(right, Accum::Add, top.rb(), v.transpose(), -1.0, Par::Seq);
    let rest = m + 1 - b;
    let right = h.as_mut().submatrix_mut(k + 1, k + b, m, rest);
    let v_rest = v.submatrix(b - 1, 0, rest, b);
    matmul(right, Accum::Add, y, v_rest.transpose(), -1.0, Par::Seq);
    // A <- (I - V T^T V^T) A on rows k+1.. of the columns after the panel.
    let trailing = h.as_mut().submatrix_mut(k + 1, k + b, m, rest);
    subtract_block_reflection(v, t.transpose(), trailing, &mut work.products);
}

/// X <- (I - V S V^T) X: a product of reflectors in compact WY form (S = T) or its transpose
/// (S = T^T) applied from the left, with two blocks of `products` (of at least
/// cols(V) cols(X) entries each) as workspace.
fn subtract_block_reflection(
    v: MatRef<'_, f64>,
    s: MatRef<'_, f64>,
    mut x: MatMut<'_, f64>,
    products: &mut [Vec<f64>; 2],
) {
    let (b, cols) = (v.ncols(), x.ncols());
    let [vt_x, w] = products;
    let mut vt_x = MatMut::from_column_major_slice_mut(&mut vt_x[..b * cols], b, cols);
    let mut w = MatMut::from_column_major_slice_mut(&mut w[..b * cols], b, cols);
    matmul(
        vt_x.rb_mut(),
        Accum::Replace,
        v.transpose(),
        x.rb(),
        1.0,
        Par::Seq,
    );
    matmul(w.rb_mut(), Accum::Replace, s, vt_x.rb(), 1.0, Par::Seq);
    matmul(x.rb_mut(), Accum::Add, v, w.rb(), -1.0, Par::Seq);
}

/// w <- T^T w for an upper triangular T.
fn upper_transpose_times(t: MatRef<'_, f64>, w: &mut [f64]) {
    for r in (0..t.nrows()).rev() {
        w[r] = (0..=r).map(|l| t[(l, r)] * w[l]).sum();
    }
}

/// Columns per panel of the blocked reduction (LAPACK's block size for DGEHRD is 32; 24 was
/// the fastest of 16, 24, 32 and 48 at n = 128 and 512 here).
const PANEL: usize = 24;

/// Up to this order the Hessenberg reduction is the plain Householder loop below; above it,
/// blocked reduction (whose set-up costs more than the whole reduction at n = 4).
pub(crate) const UNBLOCKED_HESSENBERG_MAX_ORDER: usize = 32;

/// The upper Hessenberg form H of the balanced D^-1 (A / s) D, its states ordered by decreasing
/// size where they are graded ([`order_graded_states`]), with s the power of two that brings
/// A's entries into range ([`range_scale`]): returns (H, s). H is similar to A / s, so
/// it has the eigenvalues and the characteristic polynomial of A / s (the balancing is exact,
/// the reduction backward stable). The caller checks that A is finite.
pub(crate) fn balanced_hessenberg<O: Order>(a: Square<O>) -> Result<(Square<O>, f64), Error> {
    let (mut h, scale, _) = balanced(a);
    reduce_in_place(&mut h)?;
    Ok((h, scale))
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

/// H alone, in place: the plain reduction up to [`UNBLOCKED_HESSENBERG_MAX_ORDER`], the
/// blocked one above (which may stop when interrupted).
pub(crate) fn reduce_in_place<O: Order>(h: &mut Square<O>) -> Result<(), Error> {
    if h.nrows() <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        reduce_to_hessenberg(h, None);
    } else {
        *h = from_faer_in(
            h.shape_generic().0,
            hessenberg_matrix(h.to_faer().as_ref())?.as_ref(),
        );
    }
    Ok(())
}

/// Householder reduction to upper Hessenberg form in place, H = Q^T A Q; `q` (the identity on
/// entry) becomes Q. Reflector k maps column k below the subdiagonal onto e_{k+1}. Any order
/// (the reflectors on the stack up to [`UNBLOCKED_HESSENBERG_MAX_ORDER`], on the heap beyond);
/// above that order the blocked reduction is faster, where the caller can take it.
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

    #[test]
    fn the_blocked_reduction_reconstructs_and_is_orthogonal() {
        // Orders around the panel width and several panels, a graded matrix, and a matrix whose
        // columns are already partly reduced (zero reflectors).
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut random = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut cases = Vec::new();
        for n in [33usize, 34, 35, 63, 64, 65, 66, 97, 130, 200] {
            cases.push(Mat::from_fn(n, n, |_, _| random()));
        }
        cases.push(Mat::from_fn(150, 150, |i, j| {
            random() * 2f64.powi(i as i32 / 4 - j as i32 / 4)
        }));
        cases.push(Mat::from_fn(100, 100, |i, j| {
            if i > j + 1 && j % 3 == 0 {
                0.0
            } else {
                random()
            }
        }));
        for a in cases {
            let n = a.nrows();
            let Hessenberg { h, q } = hessenberg(a.as_ref()).unwrap();
            for j in 0..n {
                for i in j + 2..n {
                    assert_eq!(h[(i, j)], 0.0);
                }
            }
            let residual = (&q * &h * q.transpose() - &a).norm_l2() / a.norm_l2();
            assert!(residual < 1e-14, "n={n}: {residual}");
            let orthogonality = (q.transpose() * &q - Mat::<f64>::identity(n, n)).norm_l2();
            assert!(orthogonality < 1e-13, "n={n}: {orthogonality}");
            // H alone is the same matrix.
            assert_eq!(hessenberg_matrix(a.as_ref()).unwrap(), h, "n={n}");
        }
    }

    #[test]
    fn the_blocked_reduction_stops_when_interrupted() {
        let a = Mat::from_fn(100, 100, |i, j| ((i * 7 + j * 13) % 17) as f64 / 8.0 - 1.0);
        let token = interrupt::Token::default();
        token.cancel();
        interrupt::within(&token, || {
            assert_eq!(hessenberg(a.as_ref()).unwrap_err(), Error::Interrupted);
            assert_eq!(
                hessenberg_matrix(a.as_ref()).unwrap_err(),
                Error::Interrupted
            );
        });
    }
}
