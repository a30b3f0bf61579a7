//! The eigenvalues of a real Hamiltonian matrix by Van Loan's square-reduced method.
//!
//! A real 2n x 2n matrix H is Hamiltonian when J H is symmetric (J = [[0, I], [-I, 0]]):
//! H = [[F, G], [K, -F^T]] with G and K symmetric. Its eigenvalues come in pairs ±λ (and
//! conjugates), and its square H^2 is skew-Hamiltonian: H^2 = [[M, X], [Y, M^T]] with X and Y
//! skew-symmetric. A symplectic orthogonal similarity Q (Q^T J Q = J) keeps that structure,
//! and one built from reflections diag(P, P) (P a Householder reflection) and plane rotations
//! in the planes (k, n + k) brings H^2 to the square-reduced form
//!
//! ```text
//!     Q^T H^2 Q = [ W  X' ]
//!                 [ 0  W^T ],     W upper Hessenberg,
//! ```
//!
//! (for k = 1, ..., n - 1: a reflection zeroing Y(k+2:n, k), a rotation in the plane
//! (k + 1, n + k + 1) zeroing Y(k+1, k), a reflection zeroing M(k+2:n, k); Y stays
//! skew-symmetric, so its row k vanishes with its column, and the later steps do not refill
//! either). The eigenvalues μ_i of W (each a double eigenvalue of H^2) are the squares of the
//! eigenvalues of H, which are ±√μ_i. The QR iteration then runs on an n x n Hessenberg matrix
//! instead of a 2n x 2n one: about an eighth of the flops of the general eigenvalue problem of
//! H, and the ± pairing is exact.
//!
//! **Accuracy.** Forming H^2 in floating point errs by up to n u |H| |H| entrywise, and the
//! transformations are orthogonal, so the μ_i are those of H^2 + E with ||E|| = O(n u ||H||^2)
//! (||H||^2, not ||H^2||, which may be far smaller: H of 1e9 dominated by a rank-one term
//! whose square vanishes): an eigenvalue λ of H has an error of about u ||H||^2 / |λ| (times
//! its condition), against u ||H|| for the QR iteration on H itself (Van Loan 1984, §4). That is
//! as good for |λ| of the order of ||H|| and worse for small ones; the caller decides from the
//! returned ||H||_F^2 which μ_i it can take (see `control/margins.rs`).
//!
//! Where the off-diagonal blocks are of rank one (the Hamiltonians of 1 - G(-s) G(s) for a SISO
//! G), [`squared_eigenvalues_rank_one`] forms H^2 from F and the two vectors in n^3
//! multiplications instead of the (2n)^3 of the product.
//!
//! **Verification.** The μ_i must sum to half the trace of H^2 (which the similarity keeps)
//! to within 8 (2n)^2 u ||H||_F^2; a miss is [`Error::IllConditioned`].
//!
//! Reference: C. F. Van Loan, "A symplectic method for approximating all the eigenvalues of a
//! Hamiltonian matrix", Linear Algebra and its Applications 61, 233-251, 1984.

use crate::error::{Error, check_finite, check_square};
use crate::linalg::householder::reflector;
use crate::linalg::matrix::{FaerView, Order, with_order};
use crate::linalg::rotation::Rotation;
use crate::linalg::schur::{Spectrum, francis_qr, quasi_triangular_eigenvalues};
use faer::{MatRef, c64};

/// The eigenvalues μ_i of H^2 (one of each double pair: n values for H of order 2n) and
/// ||H||_F^2, the size their errors are relative to.
#[derive(Debug, Clone)]
pub struct SquaredSpectrum {
    pub squares: Vec<c64>,
    pub size: f64,
}

/// The squares of the eigenvalues of the Hamiltonian matrix `h` (2n x 2n) by Van Loan's
/// square-reduced method (see the module's documentation), verified by their sum (a miss is
/// [`Error::IllConditioned`]); None where H^2 overflows. The
/// structure is not checked as such: a matrix that is not Hamiltonian has a reduced square
/// whose block W does not hold half its trace, and fails the check. The tests' reference for
/// [`squared_eigenvalues_rank_one`], which the margins use.
#[cfg(test)]
pub fn squared_eigenvalues(h: MatRef<'_, f64>) -> Result<Option<SquaredSpectrum>, Error> {
    check_square(h, "H")?;
    check_finite(h, "H")?;
    let order = h.nrows();
    if order % 2 != 0 {
        return Err(Error::InvalidArgument {
            arg: "H",
            message: format!("a Hamiltonian matrix has an even order, got {order}"),
        });
    }
    let n = order / 2;
    if n == 0 {
        return Ok(Some(SquaredSpectrum {
            squares: Vec::new(),
            size: 0.0,
        }));
    }
    let entries: Vec<f64> = (0..order * order)
        .map(|x| h[(x % order, x / order)])
        .collect();
    // H^2, column-major: column j is the sum of the columns k of H times h_kj.
    let mut m = vec![0.0; order * order];
    for (j, out) in m.chunks_exact_mut(order).enumerate() {
        for (k, &x) in entries[j * order..(j + 1) * order].iter().enumerate() {
            if x != 0.0 {
                for (y, &z) in out.iter_mut().zip(&entries[k * order..(k + 1) * order]) {
                    *y += z * x;
                }
            }
        }
    }
    let size = entries.iter().map(|x| x * x).sum::<f64>();
    square_reduced_eigenvalues(m, n, size)
}

/// The squares of the eigenvalues of the Hamiltonian matrix with rank-one off-diagonal blocks,
///
/// ```text
///     H = [ F              σ_g u u^T ]
///         [ σ_k v v^T      -F^T      ],
/// ```
///
/// (F n x n; the Hamiltonian of 1 - G(-s) G(s) for a SISO G is of this form), with H^2 formed
/// from its blocks instead of as a product of order 2n:
///
/// ```text
///     H^2 = [ M                        σ_g (w u^T - u w^T) ]
///           [ σ_k (v z^T - z v^T)      M^T                 ],
///     M = F^2 + σ_g σ_k (u^T v) u v^T,   w = F u,   z = F^T v,
/// ```
///
/// n^3 multiplications for F^2 and O(n^2) for the rest, against 8 n^3 for the product; the
/// off-diagonal blocks are skew-symmetric exactly (their diagonals are zero, as the reduction
/// takes them to be). The squares' errors are those of the product (each entry is formed from
/// the same terms, up to n u |H| |H| entrywise), and so is the size ||H||_F^2 =
/// 2 ||F||_F^2 + σ_g^2 ||u||^4 + σ_k^2 ||v||^4 returned with them; verified by the sum of
/// the squares against the trace (see the module's documentation). None where H^2 or the size
/// overflows.
pub fn squared_eigenvalues_rank_one(
    f: MatRef<'_, f64>,
    u: &[f64],
    sigma_g: f64,
    v: &[f64],
    sigma_k: f64,
) -> Result<Option<SquaredSpectrum>, Error> {
    check_square(f, "F")?;
    check_finite(f, "F")?;
    let n = f.nrows();
    if u.len() != n || v.len() != n {
        return Err(Error::InvalidArgument {
            arg: "u, v",
            message: format!(
                "u and v must have as many entries as F has rows ({n}), got {} and {}",
                u.len(),
                v.len()
            ),
        });
    }
    if n == 0 {
        return Ok(Some(SquaredSpectrum {
            squares: Vec::new(),
            size: 0.0,
        }));
    }
    let order = 2 * n;
    // F column-major.
    let entries: Vec<f64> = (0..n * n).map(|x| f[(x % n, x / n)]).collect();
    let column = |k: usize| &entries[k * n..(k + 1) * n];
    let mut m = vec![0.0; order * order];
    // F^2 + σ_g σ_k (u^T v) u v^T into the upper left block, column by column.
    let coupling = sigma_g * sigma_k * u.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
    for j in 0..n {
        let out = &mut m[j * order..j * order + n];
        for (k, &x) in column(j).iter().enumerate() {
            if x != 0.0 {
                for (y, &z) in out.iter_mut().zip(column(k)) {
                    *y += z * x;
                }
            }
        }
        let scale = coupling * v[j];
        for (y, &x) in out.iter_mut().zip(u) {
            *y += x * scale;
        }
    }
    let mut w = vec![0.0; n];
    for (k, &x) in u.iter().enumerate() {
        for (y, &e) in w.iter_mut().zip(column(k)) {
            *y += e * x;
        }
    }
    let z: Vec<f64> = (0..n)
        .map(|i| column(i).iter().zip(v).map(|(e, x)| e * x).sum())
        .collect();
    for j in 0..n {
        for i in 0..n {
            // Upper right: σ_g (w_i u_j - u_i w_j); lower left: σ_k (v_i z_j - z_i v_j);
            // lower right: M^T.
            m[i + (n + j) * order] = sigma_g * (w[i] * u[j] - u[i] * w[j]);
            m[(n + i) + j * order] = sigma_k * (v[i] * z[j] - z[i] * v[j]);
            m[(n + i) + (n + j) * order] = m[j + i * order];
        }
    }
    let squares = |x: &[f64]| x.iter().map(|y| y * y).sum::<f64>();
    let (nf, nu, nv) = (squares(&entries), squares(u), squares(v));
    let size = 2.0 * nf + sigma_g * sigma_g * nu * nu + sigma_k * sigma_k * nv * nv;
    square_reduced_eigenvalues(m, n, size)
}

/// The reduction of the formed square `m` (column-major, of order 2n) of a Hamiltonian matrix
/// whose entries have the squared Frobenius norm `size` to Van Loan's square-reduced form, the
/// eigenvalues of its block W and their check against the trace (see the module's
/// documentation); None where `m` or `size` is not finite.
fn square_reduced_eigenvalues(
    mut m: Vec<f64>,
    n: usize,
    size: f64,
) -> Result<Option<SquaredSpectrum>, Error> {
    let order = 2 * n;
    if !(size.is_finite() && m.iter().all(|x| x.is_finite())) {
        return Ok(None);
    }
    let trace: f64 = (0..order).map(|i| m[i + i * order]).sum();
    let mut v = vec![0.0; n];
    let mut work = vec![0.0; order];
    for k in 0..n.saturating_sub(1) {
        // A reflection diag(P, P) on the indices k+1..n (and n+k+1..2n) zeroing Y(k+2:n, k).
        let length = n - k - 1;
        v[..length].copy_from_slice(&m[(n + k + 1) + k * order..(2 * n) + k * order]);
        let (_, tau) = reflector(&mut v[..length]);
        if tau != 0.0 {
            v[0] = 1.0;
            reflect_both(&mut m, order, n, k + 1, &v[..length], tau, &mut work);
        }
        // A rotation in the plane (k + 1, n + k + 1) zeroing Y(k+1, k).
        let (p, q) = (k + 1, n + k + 1);
        let (rotation, _) = Rotation::zeroing(m[p + k * order], m[q + k * order]);
        if rotation.s != 0.0 {
            rotate_both(&mut m, order, p, q, rotation);
        }
        // A reflection diag(P, P) zeroing M(k+2:n, k).
        v[..length].copy_from_slice(&m[(k + 1) + k * order..n + k * order]);
        let (_, tau) = reflector(&mut v[..length]);
        if tau != 0.0 {
            v[0] = 1.0;
            reflect_both(&mut m, order, n, k + 1, &v[..length], tau, &mut work);
        }
    }
    let squares = with_order!(n, size_n => {
        let mut w = size_n.zeros();
        for j in 0..n {
            for i in 0..n.min(j + 2) {
                w[(i, j)] = m[i + j * order];
            }
        }
        francis_qr(&mut w, None, (0, n - 1), false, Spectrum::General)?;
        quasi_triangular_eigenvalues(w.as_faer())
    });
    // The similarity keeps the trace: tr H^2 = tr W + tr W^T = 2 Σ μ_i.
    let sum: f64 = squares.iter().map(|mu| mu.re).sum();
    if !sum.is_finite()
        || (2.0 * sum - trace).abs() > 8.0 * (order * order) as f64 * f64::EPSILON * size
    {
        return Err(Error::IllConditioned {
            message: format!(
                "squared_eigenvalues: the squares sum to {sum:.6e}, not half the trace of H^2 \
                 ({:.6e})",
                trace / 2.0
            ),
        });
    }
    Ok(Some(SquaredSpectrum { squares, size }))
}

/// The columns of M read again from step `first - 1` of the reduction on: column
/// `first - 1` (being reduced) and those after it in each half, except the right half's
/// column n + first - 1. The others are never read again (the later steps' right-hand
/// transformations and rotations combine columns `first`.. and n + `first`.. only, and W
/// takes rows up to j + 1 of its column j, above the rows the later steps change), so the
/// left-hand transformations skip them: W is the same bit for bit.
fn live_columns(n: usize, first: usize) -> [std::ops::Range<usize>; 2] {
    [first - 1..n, n + first..2 * n]
}

/// M <- D M D for D = diag(P, P), P = I - τ v v^T acting on the indices first..first + len of
/// each half (column-major M of order `order` = 2n; `work` of length `order`), from the left
/// on the columns still read ([`live_columns`]).
fn reflect_both(
    m: &mut [f64],
    order: usize,
    n: usize,
    first: usize,
    v: &[f64],
    tau: f64,
    work: &mut [f64],
) {
    for offset in [first, n + first] {
        // From the left: rows offset.. of every column still read.
        for range in live_columns(n, first) {
            for column in m[range.start * order..range.end * order].chunks_exact_mut(order) {
                let part = &mut column[offset..offset + v.len()];
                let f = tau * part.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
                for (x, y) in part.iter_mut().zip(v) {
                    *x -= f * y;
                }
            }
        }
        // From the right: w = M[:, offset..] v, then M[:, offset + t] -= τ v_t w.
        work.fill(0.0);
        for (t, &y) in v.iter().enumerate() {
            let column = &m[(offset + t) * order..(offset + t + 1) * order];
            for (w, x) in work.iter_mut().zip(column) {
                *w += x * y;
            }
        }
        for (t, &y) in v.iter().enumerate() {
            let f = tau * y;
            let column = &mut m[(offset + t) * order..(offset + t + 1) * order];
            for (x, w) in column.iter_mut().zip(work.iter()) {
                *x -= f * w;
            }
        }
    }
}

/// M <- G^T M G for the rotation G in the plane (p, q = n + p) that maps (x_p, x_q) to
/// (c x_p + s x_q, -s x_p + c x_q) (symplectic), from the left on the columns still read
/// ([`live_columns`] with first = p).
fn rotate_both(m: &mut [f64], order: usize, p: usize, q: usize, r: Rotation) {
    for j in live_columns(order / 2, p).into_iter().flatten() {
        let (x, y) = (m[p + j * order], m[q + j * order]);
        m[p + j * order] = r.c * x + r.s * y;
        m[q + j * order] = -r.s * x + r.c * y;
    }
    for i in 0..order {
        let (x, y) = (m[i + p * order], m[i + q * order]);
        m[i + p * order] = r.c * x + r.s * y;
        m[i + q * order] = -r.s * x + r.c * y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::schur::eigenvalues;
    use faer::Mat;

    /// A Hamiltonian matrix [[F, G], [K, -F^T]] from seeded entries.
    fn hamiltonian(n: usize, seed: usize) -> Mat<f64> {
        let entry = |i: usize, j: usize, t: usize| {
            (((i * 7 + j * 13 + t * 5 + seed * 11) % 23) as f64) / 11.0 - 1.0
        };
        let f = Mat::from_fn(n, n, |i, j| entry(i, j, 0));
        let g = Mat::from_fn(n, n, |i, j| entry(i.min(j), i.max(j), 1));
        let k = Mat::from_fn(n, n, |i, j| entry(i.min(j), i.max(j), 2));
        Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => f[(i, j)],
            (true, false) => g[(i, j - n)],
            (false, true) => k[(i - n, j)],
            (false, false) => -f[(j - n, i - n)],
        })
    }

    /// ±√μ_i against the eigenvalues of H by the QR iteration, each matched to the nearest.
    #[test]
    fn the_square_roots_are_the_eigenvalues() {
        for n in 1..=9 {
            for seed in 0..6 {
                let h = hamiltonian(n, seed);
                let squared = squared_eigenvalues(h.as_ref()).unwrap().unwrap();
                let expected = eigenvalues(h.as_ref()).unwrap();
                let size = squared.size.sqrt();
                let mut found: Vec<c64> = squared
                    .squares
                    .iter()
                    .flat_map(|&mu| {
                        let root = mu.sqrt();
                        [root, -root]
                    })
                    .collect();
                assert_eq!(found.len(), expected.len());
                for e in &expected {
                    let (index, distance) = found
                        .iter()
                        .enumerate()
                        .map(|(i, x)| (i, (x - e).norm()))
                        .min_by(|x, y| x.1.total_cmp(&y.1))
                        .unwrap();
                    // The error bound u ||H||^2 / |λ|, with room for conditioning.
                    let bound = 1e-10 * size * size / e.norm().max(1e-3 * size) + 1e-12 * size;
                    assert!(distance <= bound, "n={n} seed={seed}: {e} ({distance:e})");
                    found.swap_remove(index);
                }
            }
        }
    }

    /// The size is ||H||_F^2, not ||H^2||_F: for H dominated by a nilpotent rank-one term the
    /// square is small and its rounding errors are not.
    #[test]
    fn the_size_is_that_of_h_squared_entrywise() {
        let h = faer::mat![[1.0, 1e8], [0.0, -1.0]];
        let squared = squared_eigenvalues(h.as_ref()).unwrap().unwrap();
        assert!(squared.size >= 1e16, "{}", squared.size);
        assert_eq!(squared.squares, vec![c64::new(1.0, 0.0)]);
    }

    /// An eigenvalue on the imaginary axis stays on it: H of 1 - G(-s) G(s) for
    /// G = 2/(s + 1), whose gain crossover is at ω = √3 (|G(j√3)| = 1).
    #[test]
    fn an_axis_eigenvalue_squares_to_a_negative_real() {
        // [[a, b^2], [-c^2, -a]] with a = -1, b = √2, c = √2.
        let h = faer::mat![[-1.0, 2.0], [-2.0, 1.0]];
        let squared = squared_eigenvalues(h.as_ref()).unwrap().unwrap();
        assert_eq!(squared.squares.len(), 1);
        let mu = squared.squares[0];
        assert_eq!(mu.im, 0.0);
        assert!((mu.re + 3.0).abs() <= 4.0 * f64::EPSILON * 3.0, "{mu}");
    }

    #[test]
    fn the_empty_matrix_has_no_eigenvalues() {
        let squared = squared_eigenvalues(Mat::<f64>::zeros(0, 0).as_ref())
            .unwrap()
            .unwrap();
        assert!(squared.squares.is_empty());
    }

    #[test]
    fn an_overflowing_square_is_none() {
        let h = faer::mat![[1e200, 0.0], [0.0, -1e200]];
        assert!(squared_eigenvalues(h.as_ref()).unwrap().is_none());
    }

    /// A matrix that is not Hamiltonian fails the check of the trace: [[1, 2], [3, 4]] has
    /// the square [[7, 10], [15, 22]], whose W = [7] is not half of its trace 29.
    #[test]
    fn a_matrix_that_is_not_hamiltonian_fails_the_check() {
        let h = faer::mat![[1.0, 2.0], [3.0, 4.0]];
        assert!(matches!(
            squared_eigenvalues(h.as_ref()),
            Err(Error::IllConditioned { .. })
        ));
    }

    #[test]
    fn refuses_an_odd_order_and_non_finite_entries() {
        let odd = Mat::<f64>::zeros(3, 3);
        assert!(matches!(
            squared_eigenvalues(odd.as_ref()),
            Err(Error::InvalidArgument { arg: "H", .. })
        ));
        let mut h = hamiltonian(2, 0);
        h[(1, 2)] = f64::NAN;
        assert!(matches!(
            squared_eigenvalues(h.as_ref()),
            Err(Error::NonFinite { arg: "H", .. })
        ));
    }

    /// The rank-one form against the product of the same H formed densely: the same squares
    /// (to the error bound of either, n u ||H||_F^2), the same size to rounding, over orders
    /// 1-9 and off-diagonal signs of both kinds (the Hamiltonians of 1 - G(-s) G(s) have
    /// σ_g = -σ_k).
    #[test]
    fn the_rank_one_form_matches_the_dense_square() {
        for n in 1..=9 {
            for seed in 0..6 {
                let entry =
                    |i: usize, t: usize| (((i * 7 + t * 13 + seed * 11) % 23) as f64) / 11.0 - 1.0;
                let f = Mat::from_fn(n, n, |i, j| entry(i * n + j, 0));
                let u: Vec<f64> = (0..n).map(|i| entry(i, 1)).collect();
                let v: Vec<f64> = (0..n).map(|i| entry(i, 2)).collect();
                let (sg, sk) = if seed % 2 == 0 {
                    (0.7, -0.7)
                } else {
                    (-1.3, -0.4)
                };
                let h = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                    (true, true) => f[(i, j)],
                    (true, false) => sg * u[i] * u[j - n],
                    (false, true) => sk * v[i - n] * v[j],
                    (false, false) => -f[(j - n, i - n)],
                });
                let dense = squared_eigenvalues(h.as_ref()).unwrap().unwrap();
                let rank_one = squared_eigenvalues_rank_one(f.as_ref(), &u, sg, &v, sk)
                    .unwrap()
                    .unwrap();
                assert!((dense.size - rank_one.size).abs() <= 1e-13 * dense.size);
                let bound = 64.0 * n as f64 * f64::EPSILON * dense.size;
                let mut left = dense.squares.clone();
                for mu in &rank_one.squares {
                    let (index, distance) = left
                        .iter()
                        .enumerate()
                        .map(|(i, x)| (i, (x - mu).norm()))
                        .min_by(|x, y| x.1.total_cmp(&y.1))
                        .unwrap();
                    assert!(distance <= bound, "n={n} seed={seed}: {mu} ({distance:e})");
                    left.swap_remove(index);
                }
            }
        }
    }

    #[test]
    fn the_rank_one_form_refuses_vectors_of_another_length() {
        let f = Mat::<f64>::identity(2, 2);
        assert!(matches!(
            squared_eigenvalues_rank_one(f.as_ref(), &[1.0], 1.0, &[1.0, 2.0], -1.0),
            Err(Error::InvalidArgument { .. })
        ));
        assert!(
            squared_eigenvalues_rank_one(f.as_ref(), &[1e200, 0.0], 1.0, &[1.0, 0.0], -1.0)
                .unwrap()
                .is_none()
        );
    }
}
