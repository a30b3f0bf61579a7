//! The discrete Riccati equation by the structure-preserving doubling algorithm (SDA): the
//! first fast path of [`super::dare`], for E = I, R positive definite and the orders of flight
//! models (at most [`MAX_ORDER`] states).
//!
//! With R = L L^T and the cross weight absorbed as in [`super::cayley`] (Ã = A - B R^-1 S^T,
//! Q̃ = Q - S R^-1 S^T, G = B R^-1 B^T), the equation reads X = Ã^T X (I + G X)^-1 Ã + Q̃, and
//! its stabilising solution is the limit of the Riccati difference equation run from Q̃. The
//! doubling recursion takes that equation 2^k steps at a time (Chu, Fan, Lin & Wang 2004; the
//! convergence analysis is Lin & Xu 2006):
//!
//! ```text
//! W_k     = I + G_k H_k
//! A_{k+1} = A_k W_k^-1 A_k
//! G_{k+1} = G_k + A_k W_k^-1 G_k A_k^T
//! H_{k+1} = H_k + A_k^T H_k W_k^-1 A_k,        A_0 = Ã, G_0 = G, H_0 = Q̃,
//! ```
//!
//! with H_k -> X and A_k -> 0 as ρ(A - B K)^(2^k): a closed loop sampled at 50 Hz, whose
//! eigenvalues have |z| ≈ 0.99, takes about a dozen doublings, each six products and one LU
//! factorisation of order n, on the stack, in one kernel compiled for the order, in vector
//! form (the two solves with W_k on the rows of their right-hand sides:
//! [`doubling_step_kernel`]). Where G and H_k are positive semidefinite W_k is nonsingular.
//! The iteration stops when the increment of H no longer changes it at working precision and
//! A_k has decayed.
//!
//! The result is a candidate only: [`super::dare`] refines it by Newton's method and keeps it
//! only if its residual is within a few units of rounding and its closed loop passes every
//! check; otherwise (a plant that is not stabilisable or detectable, for which the recursion
//! may converge to a solution that does not stabilise, or diverge; Q̃ indefinite) the Cayley
//! transform and then the pencil decide.
//!
//! E. K.-W. Chu, H.-Y. Fan, W.-W. Lin, C.-S. Wang, "Structure-preserving algorithms for
//! periodic discrete-time algebraic Riccati equations", Int. J. Control 77 (2004) 767-788.
//! W.-W. Lin, S.-F. Xu, "Convergence analysis of structure-preserving doubling algorithms for
//! Riccati-type matrix equations", SIAM J. Matrix Anal. Appl. 28 (2006) 26-39.

use super::care::Standard;
use crate::linalg::matrix::{FaerView, with_order};
use crate::linalg::small_matrix::{
    self, CacheAligned, Columns, SmallLu, add_product_kernel, add_product_rows_kernel, columns,
    lu_kernel, lu_solve_rows_kernel, transposed,
};
use crate::platform::dispatch::fma_dispatch;
use faer::Mat;
use nalgebra::{DMatrix, SMatrix};

/// The largest order solved by doubling (the fixed orders of the small-matrix kernels).
pub const MAX_ORDER: usize = 8;

/// Doublings at most: 2^40 steps of the difference equation. A closed loop whose spectral
/// radius is so close to 1 that they do not suffice is left to the Cayley transform.
pub const MAX_DOUBLINGS: usize = 40;

/// The doubling's candidate solution of the DARE.
pub(crate) struct DoublingSolution {
    /// X, symmetric.
    pub(crate) x: Mat<f64>,
    /// The reciprocal condition number of U11 in the orthonormal basis [U11; U21] of the
    /// graph of X (the subspace the pencil's method finds), estimated from X ([`graph_rcond`]).
    pub(crate) rcond: f64,
}

/// The solution by doubling of the equation in standard form `plant`
/// ([`super::cayley::standard_form`]), or `None` where it does not apply (order above
/// [`MAX_ORDER`]) or the recursion does not converge within [`MAX_DOUBLINGS`].
pub(crate) fn doubling_solution(plant: &Standard) -> Option<DoublingSolution> {
    let n = plant.a.nrows();
    if n == 0 || n > MAX_ORDER {
        return None;
    }
    with_order!(
        n,
        [1, 2, 3, 4, 5, 6, 7, 8],
        N => {
            let fixed = |m: &DMatrix<f64>| SMatrix::<f64, N, N>::from_fn(|i, j| m[(i, j)]);
            let (x, _) = double::<N>(fixed(&plant.a), fixed(&plant.g), fixed(&plant.q))?;
            Some(DoublingSolution {
                x: x.to_faer(),
                rcond: graph_rcond(&x),
            })
        },
        _ => None
    )
}

/// The recursion at the order N (module documentation), each doubling one fused kernel: the
/// limit of H and the doublings taken, or `None` if it diverged or did not converge.
fn double<const N: usize>(
    a: SMatrix<f64, N, N>,
    g: SMatrix<f64, N, N>,
    h: SMatrix<f64, N, N>,
) -> Option<(SMatrix<f64, N, N>, usize)> {
    let mut state = CacheAligned([*columns(&a), *columns(&g), *columns(&h)]);
    for doublings in 1..=MAX_DOUBLINGS {
        let [increment, h_norm, a_norm] = doubling_step(&mut state);
        // The norms are NaN or infinite exactly when an entry is.
        if !(increment.is_finite() && h_norm.is_finite() && a_norm.is_finite()) {
            return None;
        }
        if increment <= f64::EPSILON * h_norm && a_norm <= 1.0 {
            return Some((small_matrix::from_columns(state.0[2]), doublings));
        }
    }
    None
}

/// One doubling in place (module documentation): A, G, H <- A_{k+1}, G_{k+1}, H_{k+1}, G and
/// H symmetrised. Returns the 1-norms of H's increment, of the new H and of the new A (NaN
/// or infinite when an entry is).
///
/// W^-1 A and W^-1 G are solved for as their rows (from the rows of A and G, the columns of
/// A^T and G^T), all columns at once ([`lu_solve_rows_kernel`]), and the products take them,
/// and A^T in G's update, by their rows ([`add_product_rows_kernel`]): every entry is formed
/// by the same operations in the same order as with column storage. The kernel's matrices are
/// cache-aligned ([`CacheAligned`]), and A^T is stored whole before the products read it, so
/// that they load its columns as vectors (the optimiser would otherwise gather A's rows lane
/// by lane into the products, as scalar and partial-vector multiply-adds).
#[inline(always)]
fn doubling_step_kernel<const N: usize, const FMA: bool>(
    state: &mut CacheAligned<[Columns<N>; 3]>,
) -> [f64; 3] {
    let [a, g, h] = &mut state.0;
    let zeros = CacheAligned([[0.0; N]; N]);
    let mut w = zeros;
    for (k, column) in w.0.iter_mut().enumerate() {
        column[k] = 1.0;
    }
    add_product_kernel::<N, FMA>(g, h, &mut w.0);
    let mut pivots = [0usize; N];
    lu_kernel::<N, FMA>(&mut w.0, &mut pivots);
    let mut a_transposed = CacheAligned(transposed(a));
    std::hint::black_box(&mut a_transposed);
    // The rows of W^-1 A and W^-1 G.
    let (mut wa, mut wg) = (a_transposed, CacheAligned(transposed(g)));
    lu_solve_rows_kernel::<N, FMA>(&w.0, &pivots, &mut wa.0);
    lu_solve_rows_kernel::<N, FMA>(&w.0, &pivots, &mut wg.0);
    // H += A^T (H W^-1 A).
    let mut hwa = zeros;
    add_product_rows_kernel::<N, FMA>(h, &wa.0, &mut hwa.0);
    let mut increment = zeros;
    add_product_kernel::<N, FMA>(&a_transposed.0, &hwa.0, &mut increment.0);
    // G += (A W^-1 G) A^T.
    let mut awg = zeros;
    add_product_rows_kernel::<N, FMA>(a, &wg.0, &mut awg.0);
    add_product_rows_kernel::<N, FMA>(&awg.0, a, g);
    // A <- A W^-1 A.
    let mut next = zeros;
    add_product_rows_kernel::<N, FMA>(a, &wa.0, &mut next.0);
    *a = next.0;
    for (h_column, increment_column) in h.iter_mut().zip(&increment.0) {
        for (x, &d) in h_column.iter_mut().zip(increment_column) {
            *x += d;
        }
    }
    symmetrize(g);
    symmetrize(h);
    [one_norm(&increment.0), one_norm(h), one_norm(a)]
}

fma_dispatch!(fn doubling_step<const N: usize>(state: &mut CacheAligned<[Columns<N>; 3]>) -> [f64; 3] => doubling_step_kernel);

/// (M + M^T) / 2 in place.
#[inline(always)]
// Row and column indices of a triangle: indices read most clearly.
#[allow(clippy::needless_range_loop)]
fn symmetrize<const N: usize>(m: &mut Columns<N>) {
    for j in 0..N {
        for i in 0..j {
            let mean = 0.5 * (m[j][i] + m[i][j]);
            m[j][i] = mean;
            m[i][j] = mean;
        }
    }
}

/// The 1-norm max_j sum_i |m_ij|, NaN or infinite when an entry is (a NaN column sum is not
/// lost to `max`).
#[inline(always)]
fn one_norm<const N: usize>(m: &Columns<N>) -> f64 {
    let mut norm = 0.0f64;
    for column in m {
        let sum: f64 = column.iter().map(|x| x.abs()).sum();
        if sum.is_nan() || sum > norm {
            norm = sum;
        }
        if norm.is_nan() {
            return norm;
        }
    }
    norm
}

/// The reciprocal condition number of U11 in the orthonormal basis [U11; U21] of the graph of
/// X: U11^T U11 = (I + X^2)^-1, so that for symmetric X it is
/// sqrt(1 + λ_min^2) / sqrt(1 + λ_max^2) (λ the eigenvalues of X by magnitude), here with
/// ||X||_1 for |λ_max| and 1 / ||X^-1||_1 for |λ_min| (each within a factor n; 0 for a
/// singular X). hypot keeps it in range for X near the largest doubles.
fn graph_rcond<const N: usize>(x: &SMatrix<f64, N, N>) -> f64 {
    let inverse = SmallLu::new(*x).solve(SMatrix::identity());
    let inverse_norm = small_matrix::one_norm(&inverse);
    let smallest = if inverse.iter().all(|v| v.is_finite()) && inverse_norm > 0.0 {
        1.0 / inverse_norm
    } else {
        0.0
    };
    (1.0f64.hypot(smallest) / 1.0f64.hypot(small_matrix::one_norm(x))).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::mat;

    /// The solution by doubling of the DARE (A, B, Q, R), through its standard form.
    fn doubled(a: &Mat<f64>, b: &Mat<f64>, q: &Mat<f64>, r: &Mat<f64>) -> Option<DoublingSolution> {
        let plant = super::super::cayley::standard_form(
            a.as_ref(),
            b.as_ref(),
            q.as_ref(),
            r.as_ref(),
            None,
        )?;
        doubling_solution(&plant)
    }

    /// The scalar recursion from (a, g, q): its limit and doublings.
    fn scalar(a: f64, g: f64, q: f64) -> Option<(f64, usize)> {
        let m = |v: f64| SMatrix::<f64, 1, 1>::new(v);
        double::<1>(m(a), m(g), m(q)).map(|(x, doublings)| (x[(0, 0)], doublings))
    }

    #[test]
    fn scalar_equation_has_its_closed_form() {
        // x = a^2 x / (1 + g x) + q with a = 2, g = 1, q = 1: x^2 - 4 x - 1 = 0, x = 2 + sqrt 5.
        let (a, b, q, r) = (mat![[2.0]], mat![[1.0]], mat![[1.0]], mat![[1.0]]);
        let solution = doubled(&a, &b, &q, &r).unwrap();
        let exact = 2.0 + 5.0f64.sqrt();
        assert!((solution.x[(0, 0)] - exact).abs() <= 4.0 * f64::EPSILON * exact);
        // The closed loop a / (1 + g x) = 0.236: a handful of doublings.
        let (_, doublings) = scalar(2.0, 1.0, 1.0).unwrap();
        assert!(doublings <= 6, "{doublings}");
    }

    #[test]
    fn a_slow_closed_loop_takes_a_logarithmic_number_of_doublings() {
        // A sampled integrator weighted lightly: the closed loop's pole is about 0.999, and
        // 2^k must exceed about 36 / (1 - 0.999) steps, k about 15.
        // (a = 1, b = 0.01, r = 1: g = 1e-4.)
        let (x, doublings) = scalar(1.0, 1e-4, 1e-2).unwrap();
        // x = x / (1 + 1e-4 x) + 1e-2: 1e-4 x^2 - 1e-2 (1 + 1e-4 x) = 0.
        let exact = (1e-6 + (1e-12f64 + 4.0 * 1e-4 * 1e-2).sqrt()) / 2e-4;
        assert!((x - exact).abs() <= 1e-13 * exact);
        assert!((12..=20).contains(&doublings), "{doublings}");
    }

    #[test]
    fn graph_rcond_is_finite_from_identity_to_the_largest_doubles() {
        let diag = |a: f64, b: f64| SMatrix::<f64, 2, 2>::new(a, 0.0, 0.0, b);
        assert_eq!(graph_rcond(&diag(1.0, 1.0)), 1.0);
        // sqrt(1 + 0) / sqrt(1 + 25) for a singular X.
        assert!((graph_rcond(&diag(0.0, 5.0)) - 1.0 / 26f64.sqrt()).abs() < 1e-15);
        // X near 1e303 (X^2 would overflow): 1 / 1e303 to rounding.
        let tiny = graph_rcond(&diag(1.8e303, 0.4));
        assert!(
            (tiny * 1.8e303 - 0.4f64.hypot(1.0)).abs() < 1e-12,
            "{tiny:e}"
        );
    }

    #[test]
    fn an_unstabilisable_plant_diverges_to_none() {
        // An unstable mode that B cannot move: A_k grows as 2^(2^k) and leaves the doubles.
        let a = mat![[2.0, 0.0], [0.0, 0.5]];
        let b = mat![[0.0], [1.0]];
        let (q, r) = (Mat::<f64>::identity(2, 2), mat![[1.0]]);
        assert!(doubled(&a, &b, &q, &r).is_none());
    }

    #[test]
    fn an_undetectable_unstable_mode_does_not_stop_at_zero() {
        // Q = 0 and A unstable: H stays 0, but A_k does not decay, so the iteration does not
        // report the non-stabilising X = 0 as converged (it diverges instead).
        let (a, b, q, r) = (mat![[2.0]], mat![[1.0]], mat![[0.0]], mat![[1.0]]);
        let outcome = doubled(&a, &b, &q, &r);
        assert!(outcome.is_none_or(|s| s.x[(0, 0)] != 0.0));
    }

    #[test]
    fn above_the_fixed_orders_or_with_r_indefinite_it_declines() {
        let a = Mat::<f64>::identity(9, 9) * 0.5;
        let b = Mat::<f64>::identity(9, 1);
        let (q, r) = (Mat::<f64>::identity(9, 9), mat![[1.0]]);
        assert!(doubled(&a, &b, &q, &r).is_none());
        let (a, b, q) = (mat![[0.5]], mat![[1.0]], mat![[1.0]]);
        let r = mat![[-1.0]];
        assert!(doubled(&a, &b, &q, &r).is_none());
    }
}
