//! The eigenvalues of a real Hamiltonian matrix with rank-one off-diagonal blocks, from their
//! squares: the eigenvalues of one real n x n matrix.
//!
//! A real 2n x 2n matrix H is Hamiltonian when J H is symmetric (J = [[0, I], [-I, 0]]); its
//! eigenvalues come in pairs ±λ (and conjugates), so they are known from their squares
//! μ = λ^2, which Van Loan (1984) computes as the eigenvalues of an n x n block of the
//! square-reduced form of H^2 (a symplectic orthogonal reduction of the 2n x 2n square). Where
//! the off-diagonal blocks are of rank one,
//!
//! ```text
//!     H = [ F              σ u u^T ]
//!         [ -σ v v^T       -F^T    ],
//! ```
//!
//! (the Hamiltonians of 1 - G(-s) G(s) for a SISO G = (A, b, c, d): F = A + (d/r) b c,
//! σ = 1/r, r = 1 - d^2), the squares are the eigenvalues of an n x n matrix formed directly,
//! with no reduction of order 2n:
//!
//! ```text
//!     N = F^2 - σ^2 (u^T v) u v^T + σ (w v^T - u z^T),     w = F u,   z = F^T v.
//! ```
//!
//! **Derivation.** An eigenvector [x; y] of H gives x = -σ (F - λ)^-1 u (u^T y) and
//! y = -σ (F^T + λ)^-1 v (v^T x), so λ is an eigenvalue where 1 - σ^2 φ(λ) φ(-λ) = 0 with
//! φ(λ) = v^T (λI - F)^-1 u, and det(λI - H) = ±det(μI - F^2) (1 - σ^2 φ(λ) φ(-λ)). With
//! R = (μI - F^2)^-1, φ(λ) = p + λ q for p = v^T F R u and q = v^T R u, so
//! φ(λ) φ(-λ) = p^2 - μ q^2. The 2 x 2 transfer T(μ) = C_2 R B_2 of B_2 = [u, F u] and
//! C_2 = [v^T; v^T F] is [[q, p], [p, μ q - v^T u]] (F and R commute, F^2 R = μ R - I), with
//! det T = μ q^2 - (v^T u) q - p^2. For K = [[σ^2 v^T u, σ], [-σ, 0]] (det K = σ^2),
//! det(I + K T) = 1 + σ^2 (v^T u) q + σ^2 det T = 1 - σ^2 (p^2 - μ q^2), and by the
//! determinant lemma det(I + K C_2 R B_2) = det(μI - F^2 + B_2 K C_2) / det(μI - F^2).
//! Hence det(λI - H) = ±det(μI - N) with N = F^2 - B_2 K C_2, the matrix above: each μ_i,
//! an eigenvalue of N, gives the pair ±√μ_i of H.
//!
//! **Accuracy.** N is formed from products of the entries of H (F^2 to n u |F| |F|
//! entrywise; the rank-one terms, of the size of the off-diagonal blocks of H^2, to a few u),
//! and its eigenvalues come from the Householder reduction to Hessenberg form and the QR
//! iteration, which are backward stable: the μ_i are those of N + E with ||E|| = O(n u ||H||^2)
//! (||H||^2, not ||H^2||, which may be far smaller), as for Van Loan's method (1984, §4). An
//! eigenvalue λ of H then has an error of about u ||H||^2 / |λ| (times its condition), against
//! u ||H|| for the QR iteration on H itself: as good for |λ| of the order of ||H||, worse for
//! small ones; the caller decides from the returned ||H||_F^2 which μ_i it can take (see
//! `control/margins.rs`). The cost is that of one n x n eigenvalue problem and n^3
//! multiplications for F^2 (against the reduction of a 2n x 2n matrix for the square-reduced
//! form).
//!
//! **Verification.** The μ_i must sum to half the trace of H^2 (tr H^2 = 2 tr(F^2 - σ^2
//! (u^T v) u v^T); the trace of N is the same, as v^T w = z^T u) to within
//! 8 (2n)^2 u ||H||_F^2; a miss is [`Error::IllConditioned`].
//!
//! Reference: C. F. Van Loan, "A symplectic method for approximating all the eigenvalues of a
//! Hamiltonian matrix", Linear Algebra and its Applications 61, 233-251, 1984 (the squared
//! Hamiltonian and its error analysis).

use crate::error::{Error, check_finite, check_square};
use crate::linalg::hessenberg::reduce_to_hessenberg;
use crate::linalg::matrix::{FaerView, Order, with_order};
use crate::linalg::schur::{Spectrum, francis_qr, quasi_triangular_eigenvalues};
use faer::{MatRef, c64};

/// The eigenvalues μ_i of H^2 (one of each double pair: n values for H of order 2n) and
/// ||H||_F^2, the size their errors are relative to.
#[derive(Debug, Clone)]
pub struct SquaredSpectrum {
    pub squares: Vec<c64>,
    pub size: f64,
}

/// The squares of the eigenvalues of the Hamiltonian matrix
/// H = [[F, σ u u^T], [-σ v v^T, -F^T]] (F n x n) as the eigenvalues of the n x n matrix N
/// (see the module's documentation), with the size ||H||_F^2 =
/// 2 ||F||_F^2 + σ^2 (||u||^4 + ||v||^4) their errors are relative to; verified by their sum
/// against the trace of H^2 (a miss is [`Error::IllConditioned`]). None where N or the size
/// overflows.
pub fn squared_eigenvalues_rank_one(
    f: MatRef<'_, f64>,
    u: &[f64],
    v: &[f64],
    sigma: f64,
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
    let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>();
    let squares = |x: &[f64]| dot(x, x);
    let (nu, nv) = (squares(u), squares(v));
    let mut nf = 0.0;
    for j in 0..n {
        for i in 0..n {
            nf += f[(i, j)] * f[(i, j)];
        }
    }
    let size = 2.0 * nf + sigma * sigma * (nu * nu + nv * nv);
    let coupling = -sigma * sigma * dot(u, v);
    let w: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|k| f[(i, k)] * u[k]).sum())
        .collect();
    let z: Vec<f64> = (0..n)
        .map(|j| (0..n).map(|k| f[(k, j)] * v[k]).sum())
        .collect();
    let result = with_order!(n, order => {
        let mut m = order.zeros();
        // M = F^2 - σ^2 (u^T v) u v^T, column by column; its trace is half that of H^2.
        for j in 0..n {
            for k in 0..n {
                let x = f[(k, j)];
                if x != 0.0 {
                    for i in 0..n {
                        m[(i, j)] += f[(i, k)] * x;
                    }
                }
            }
            let scale = coupling * v[j];
            for i in 0..n {
                m[(i, j)] += u[i] * scale;
            }
        }
        let trace: f64 = (0..n).map(|i| m[(i, i)]).sum();
        // N = M + σ (w v^T - u z^T).
        for j in 0..n {
            let (vj, zj) = (sigma * v[j], sigma * z[j]);
            for i in 0..n {
                m[(i, j)] += w[i] * vj - u[i] * zj;
            }
        }
        if !(size.is_finite() && trace.is_finite() && m.as_slice().iter().all(|x| x.is_finite())) {
            None
        } else {
            reduce_to_hessenberg(&mut m, None);
            Some(francis_qr(&mut m, None, (0, n - 1), false, Spectrum::General)
                .map(|()| (quasi_triangular_eigenvalues(m.as_faer()), trace)))
        }
    });
    let Some(result) = result else {
        return Ok(None);
    };
    let (squares, trace) = result?;
    // tr H^2 = 2 tr M = 2 Σ μ_i.
    let sum: f64 = squares.iter().map(|mu| mu.re).sum();
    let order = 2 * n;
    if !sum.is_finite()
        || (2.0 * sum - 2.0 * trace).abs() > 8.0 * (order * order) as f64 * f64::EPSILON * size
    {
        return Err(Error::IllConditioned {
            message: format!(
                "squared_eigenvalues: the squares sum to {sum:.6e}, not half the trace of H^2 \
                 ({trace:.6e})"
            ),
        });
    }
    Ok(Some(SquaredSpectrum { squares, size }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::schur::eigenvalues;
    use faer::Mat;

    /// H = [[F, σ u u^T], [-σ v v^T, -F^T]] formed densely.
    fn dense(f: &Mat<f64>, u: &[f64], v: &[f64], sigma: f64) -> Mat<f64> {
        let n = f.nrows();
        Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => f[(i, j)],
            (true, false) => sigma * u[i] * u[j - n],
            (false, true) => -sigma * v[i - n] * v[j],
            (false, false) => -f[(j - n, i - n)],
        })
    }

    /// ±√μ_i against the eigenvalues of H formed densely, by the QR iteration of order 2n,
    /// each matched to the nearest within the error bound u ||H||^2 / |λ| (with room for
    /// conditioning), and the size against ||H||_F^2 of the dense matrix: orders 1-9, σ of
    /// both signs, F and the vectors from seeded entries of sizes spread over 10^±2.
    #[test]
    fn the_square_roots_are_the_eigenvalues_of_h() {
        for n in 1..=9 {
            for seed in 0..12u64 {
                let mut next = crate::test_matrices::xorshift(seed.wrapping_mul(0x9E37) + n as u64);
                let spread = 10f64.powf(4.0 * next() - 2.0);
                let f = Mat::from_fn(n, n, |_, _| next() * spread);
                let u: Vec<f64> = (0..n).map(|_| next()).collect();
                let v: Vec<f64> = (0..n).map(|_| next()).collect();
                let sigma = if seed % 2 == 0 { 0.7 } else { -1.3 };
                let h = dense(&f, &u, &v, sigma);
                let squared = squared_eigenvalues_rank_one(f.as_ref(), &u, &v, sigma)
                    .unwrap()
                    .unwrap();
                let frobenius: f64 = (0..2 * n)
                    .flat_map(|j| (0..2 * n).map(move |i| (i, j)))
                    .map(|(i, j)| h[(i, j)] * h[(i, j)])
                    .sum();
                assert!((squared.size - frobenius).abs() <= 1e-13 * frobenius);
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
                    let bound = 1e-10 * size * size / e.norm().max(1e-3 * size) + 1e-12 * size;
                    assert!(distance <= bound, "n={n} seed={seed}: {e} ({distance:e})");
                    found.swap_remove(index);
                }
            }
        }
    }

    /// The size is ||H||_F^2, not ||H^2||_F: for H dominated by a nilpotent rank-one term
    /// ([[1, 1e8], [0, -1]]) the square is small and its rounding errors are not.
    #[test]
    fn the_size_is_that_of_h_squared_entrywise() {
        let f = faer::mat![[1.0]];
        let squared = squared_eigenvalues_rank_one(f.as_ref(), &[1e4], &[0.0], 1.0)
            .unwrap()
            .unwrap();
        assert!(squared.size >= 1e16, "{}", squared.size);
        assert_eq!(squared.squares, vec![c64::new(1.0, 0.0)]);
    }

    /// An eigenvalue on the imaginary axis stays on it: H of 1 - G(-s) G(s) for
    /// G = 2/(s + 1), [[-1, 2], [-2, 1]], whose gain crossover is at ω = √3 (|G(j√3)| = 1):
    /// N = 1 - 4 = -3 exactly.
    #[test]
    fn an_axis_eigenvalue_squares_to_a_negative_real() {
        let f = faer::mat![[-1.0]];
        let squared = squared_eigenvalues_rank_one(f.as_ref(), &[1.0], &[1.0], 2.0)
            .unwrap()
            .unwrap();
        assert_eq!(squared.squares, vec![c64::new(-3.0, 0.0)]);
    }

    /// G = 1/(s^2 + s + 1) (F = [[0, 1], [-1, -1]], u = e_2, v = e_1, σ = 1): G(s) G(-s) =
    /// 1/(μ^2 + μ + 1) for μ = s^2, so 1 - G(-s) G(s) vanishes at μ = 0 and μ = -1 (the gain
    /// crossover ω = 1); N = [[0, -1], [0, -1]] exactly.
    #[test]
    fn a_second_order_loop_has_the_closed_form_squares() {
        let f = faer::mat![[0.0, 1.0], [-1.0, -1.0]];
        let squared = squared_eigenvalues_rank_one(f.as_ref(), &[0.0, 1.0], &[1.0, 0.0], 1.0)
            .unwrap()
            .unwrap();
        let mut found: Vec<f64> = squared.squares.iter().map(|mu| mu.re).collect();
        found.sort_by(f64::total_cmp);
        assert!(squared.squares.iter().all(|mu| mu.im == 0.0));
        assert_eq!(found, vec![-1.0, 0.0]);
    }

    #[test]
    fn the_empty_matrix_has_no_eigenvalues() {
        let squared = squared_eigenvalues_rank_one(Mat::<f64>::zeros(0, 0).as_ref(), &[], &[], 1.0)
            .unwrap()
            .unwrap();
        assert!(squared.squares.is_empty());
    }

    #[test]
    fn refuses_vectors_of_another_length_and_overflows_to_none() {
        let f = Mat::<f64>::identity(2, 2);
        assert!(matches!(
            squared_eigenvalues_rank_one(f.as_ref(), &[1.0], &[1.0, 2.0], 1.0),
            Err(Error::InvalidArgument { .. })
        ));
        assert!(
            squared_eigenvalues_rank_one(f.as_ref(), &[1e200, 0.0], &[1.0, 0.0], 1.0)
                .unwrap()
                .is_none()
        );
        let big = faer::mat![[1e200, 0.0], [0.0, -1e200]];
        assert!(
            squared_eigenvalues_rank_one(big.as_ref(), &[0.0, 0.0], &[0.0, 0.0], 1.0)
                .unwrap()
                .is_none()
        );
        let mut nan = Mat::<f64>::identity(2, 2);
        nan[(0, 1)] = f64::NAN;
        assert!(matches!(
            squared_eigenvalues_rank_one(nan.as_ref(), &[1.0, 0.0], &[1.0, 0.0], 1.0),
            Err(Error::NonFinite { .. })
        ));
    }
}
