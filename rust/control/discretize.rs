//! Exact discretisation of x' = Ax + Bη over a step h: the transition matrix and the input
//! integrals, by one exponential of an augmented block matrix (C. F. Van Loan, "Computing
//! integrals involving the matrix exponential", IEEE Trans. Automat. Control 23(3), 1978,
//! pp. 395-404).
//!
//! With the input held constant over the step (zero-order hold, ZOH) the solution (6.9) gives
//! x_{k+1} = Φ x_k + Γ0 η_k, and with the input linear between samples (first-order hold, FOH)
//! x_{k+1} = Φ x_k + (Γ0 - Γ1) η_k + Γ1 η_{k+1}, where
//!
//! ```text
//! Φ  = e^{Ah}
//! Γ0 = ∫_0^h e^{Aτ} dτ B                 = h φ1(Ah) B,  φ1(z) = (e^z - 1) / z
//! Γ1 = (1/h) ∫_0^h e^{Aτ} (h - τ) dτ B   = h φ2(Ah) B,  φ2(z) = (e^z - 1 - z) / z^2
//! ```
//!
//! Both come out of one exponential, because for the block upper triangular matrices
//!
//! ```text
//!        [ Ah  Bh ]                [ Φ  Γ0 ]          [ Ah  Bh  0 ]             [ Φ  Γ0  Γ1 ]
//! exp(   [  0   0 ] )          =   [ 0   I ],    exp( [  0   0  I ] )       =   [ 0   I   I ]
//!                                                      [  0   0  0 ]             [ 0   0   I ]
//! ```
//!
//! (the (1,2) block of the k-th power is (Ah)^{k-1} Bh, and of the (1,3) block (Ah)^{k-2} Bh).
//! Unlike the chapter's step formula (6.43), x(t) = (e^{At} - I) A^-1 B η0, this needs no
//! inverse of A, so it is exact for the singular A of (6.95) and every system with an
//! integrator or a neutral mode.
//!
//! The integrals are linear in B, so B is scaled by a power of two (exactly) to a size
//! comparable with Ah before the exponential and the blocks are scaled back: a B much larger
//! than Ah would otherwise force extra squarings on the whole augmented matrix, and B h could
//! overflow or underflow at the edges of the range of doubles.
//!
//! # The generalized bilinear transformation
//!
//! [`bilinear`] replaces s by (z - 1) / (h (α z + 1 - α)) (Zhang, Chen & Ye, "The generalized
//! bilinear transformation", Int. J. Control 82(4), 2009): α = 1/2 is Tustin's transformation,
//! α = 0 the forward and α = 1 the backward difference. With M = I - α h A, the realization is
//! that of scipy.signal.cont2discrete's "gbt":
//!
//! ```text
//! Ad = M^-1 (I + (1 - α) h A),   Bd = M^-1 h B,   Cd = C M^-1,   Dd = D + α C Bd,
//! ```
//!
//! and [`inverse_bilinear`] undoes it exactly: with W = α Ad + (1 - α) I, which equals M^-1,
//!
//! ```text
//! A = (Ad - I) W^-1 / h,   B = W^-1 Bd / h,   C = Cd W^-1,   D = Dd - α C Bd.
//! ```
//!
//! # Undoing the zero-order hold
//!
//! [`undiscretize_zoh`] recovers A and B from Φ = e^{Ah} and Γ0 as the principal logarithm of
//! the block matrix of the exponential above: log [[Φ, Γ0], [0, I]] = [[Ah, Bh], [0, 0]]. The
//! logarithm is real exactly when Φ has no eigenvalue on the closed negative real axis; it is
//! computed by the inverse scaling and squaring method on the real Schur form (Higham,
//! *Functions of Matrices*, SIAM 2008, §11.5, Algorithm 11.10, with the real square root of a
//! quasi-triangular matrix of Higham, "Computing real square roots of a real matrix", Linear
//! Algebra Appl. 88/89, 1987): square roots until ||T^(1/2^s) - I||_1 <= θ_8 = 0.34, then the
//! [8/8] Padé approximant of log(I + X) as 8-point Gauss–Legendre quadrature of
//! ∫_0^1 X (I + tX)^-1 dt, whose error is below u for ||X|| <= θ_8 (Kenney & Laub's bound,
//! SIAM J. Matrix Anal. Appl. 10(2), 1989). The diagonal blocks of T^(1/2^s) - I and of the
//! logarithm are formed from closed forms (expm1 and ln of the eigenvalues), not by
//! subtraction, so the slow modes keep their relative accuracy.

use crate::control::frequency::check_state_space;
use crate::error::{Error, check_finite, check_positive, check_rows, check_square};
use crate::linalg::balance::times_power_of_two;
use crate::linalg::expm::expm;
use crate::linalg::lu::Lu;
use crate::linalg::norm::one_norm;
use crate::linalg::product::product;
use crate::linalg::schur::real_schur;
use crate::linalg::sylvester::solve_small_sylvester;
use faer::Mat;
use faer::MatRef;

/// How the input is reconstructed between samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hold {
    /// Zero-order hold: η constant over each step.
    Zero,
    /// First-order hold: η linear between consecutive samples.
    First,
}

/// The matrices of one discretisation step.
#[derive(Debug, Clone, PartialEq)]
pub struct Discretization {
    /// Φ = e^{Ah}, n x n.
    pub phi: Mat<f64>,
    /// Γ0 = ∫_0^h e^{Aτ} dτ B, n x m.
    pub gamma0: Mat<f64>,
    /// Γ1 = (1/h) ∫_0^h e^{Aτ} (h - τ) dτ B, n x m; present for [`Hold::First`].
    pub gamma1: Option<Mat<f64>>,
}

/// Discretises x' = Ax + Bη over the step `dt` with the given hold (see the module docs).
///
/// ```
/// use faer::mat;
/// use aerocontrol::control::discretize::{discretize, Hold};
/// // A double integrator: Φ = [[1, h], [0, 1]], Γ0 = [h^2/2, h]^T.
/// let a = mat![[0.0, 1.0], [0.0, 0.0]];
/// let b = mat![[0.0], [1.0]];
/// let d = discretize(a.as_ref(), b.as_ref(), 0.5, Hold::Zero).unwrap();
/// assert!((d.gamma0[(0, 0)] - 0.125).abs() < 1e-16 && (d.gamma0[(1, 0)] - 0.5).abs() < 1e-16);
/// ```
pub fn discretize(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    dt: f64,
    hold: Hold,
) -> Result<Discretization, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")?;
    check_positive(dt, "dt")?;

    let (n, m) = (a.nrows(), b.ncols());
    let blocks = match hold {
        Hold::Zero => 1,
        Hold::First => 2,
    };
    let size = n + blocks * m;

    let mut augmented = Mat::<f64>::zeros(size, size);
    for j in 0..n {
        for i in 0..n {
            augmented[(i, j)] = a[(i, j)] * dt;
        }
    }
    let a_dt_max = augmented.get(..n, ..n).norm_max();
    if !a_dt_max.is_finite() {
        return Err(Error::InvalidValue {
            arg: "dt",
            value: dt,
            requirement: "small enough that A dt is finite",
        });
    }
    // The input block is Y = 2^(j - e) B, with 2^e the binade of max|b_ij| and 2^j the
    // binade of max(||A dt||_1, 1) (bounded through n max|A dt|, which cannot overflow):
    // exact scalings by powers of two, so Y never overflows or underflows whatever B and dt
    // are. Then Γ = (block of the exponential) dt 2^(e - j).
    let b_max = b.norm_max();
    let (b_exponent, target_exponent) = if b_max > 0.0 {
        let target = (a_dt_max * n as f64).log2().round().clamp(0.0, 1000.0);
        (b_max.log2().floor(), target)
    } else {
        (0.0, 0.0)
    };
    let input_scale = target_exponent - b_exponent;
    for j in 0..m {
        for i in 0..n {
            augmented[(i, n + j)] = times_power_of_two(b[(i, j)], input_scale);
        }
    }
    if hold == Hold::First {
        for j in 0..m {
            augmented[(n + j, n + m + j)] = 1.0;
        }
    }
    let exponential = expm(augmented.as_ref())?;

    let block = |col0: usize| {
        Mat::from_fn(n, m, |i, j| {
            times_power_of_two(exponential[(i, col0 + j)] * dt, -input_scale)
        })
    };
    Ok(Discretization {
        phi: exponential.get(..n, ..n).to_owned(),
        gamma0: block(n),
        gamma1: (hold == Hold::First).then(|| block(n + m)),
    })
}

/// The matrices A, B, C, D of a state-space model (continuous or discrete).
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpaceMatrices {
    pub a: Mat<f64>,
    pub b: Mat<f64>,
    pub c: Mat<f64>,
    pub d: Mat<f64>,
}

/// Checks the weight α of the generalized bilinear transformation.
fn check_alpha(alpha: f64) -> Result<(), Error> {
    if (0.0..=1.0).contains(&alpha) {
        Ok(())
    } else {
        Err(Error::InvalidValue {
            arg: "alpha",
            value: alpha,
            requirement: "between 0 and 1",
        })
    }
}

/// The LU factorisation with partial pivoting of a square matrix and its inverse, or None when
/// its reciprocal condition number 1 / (||M||_1 ||M^-1||_1) is below n u (singular to working
/// precision); `Err(Error::Interrupted)` if the computation was interrupted.
fn checked_inverse(m: MatRef<'_, f64>) -> Result<Option<(Lu, Mat<f64>)>, Error> {
    let n = m.nrows();
    let lu = Lu::new(m)?;
    let inverse = lu.solve(Mat::<f64>::identity(n, n).as_ref())?;
    let condition = one_norm(m) * one_norm(inverse.as_ref());
    Ok((inverse.is_all_finite()
        && condition.is_finite()
        && condition * n as f64 * f64::EPSILON < 1.0)
        .then_some((lu, inverse)))
}

/// The generalized bilinear transformation of x' = Ax + Bη, y = Cx + Dη with step `dt` and
/// weight `alpha` (see the module docs; 1/2 is Tustin's). Refuses a step for which I - α dt A
/// is singular to working precision (A has an eigenvalue at or near 1 / (α dt), which the
/// transformation sends to infinity).
pub fn bilinear(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    dt: f64,
    alpha: f64,
) -> Result<StateSpaceMatrices, Error> {
    check_state_space(a, b, c, d)?;
    check_positive(dt, "dt")?;
    check_alpha(alpha)?;
    let n = a.nrows();
    let identity = Mat::<f64>::identity(n, n);
    let m = &identity - faer::Scale(alpha * dt) * a;
    if !m.is_all_finite() {
        return Err(Error::InvalidValue {
            arg: "dt",
            value: dt,
            requirement: "small enough that A dt is finite",
        });
    }
    let Some((lu, inverse)) = checked_inverse(m.as_ref())? else {
        return Err(Error::InvalidArgument {
            arg: "dt",
            message: format!(
                "I - alpha dt A is singular to working precision for dt = {dt:?} and alpha = \
                 {alpha:?}: A has an eigenvalue at or near 1 / (alpha dt) = {:?}, which the \
                 bilinear transformation sends to infinity; choose another dt",
                1.0 / (alpha * dt)
            ),
        });
    };
    let ad = lu.solve((&identity + faer::Scale((1.0 - alpha) * dt) * a).as_ref())?;
    let bd = lu.solve((faer::Scale(dt) * b).as_ref())?;
    let cd = product(c, inverse.as_ref())?;
    let dd = d + faer::Scale(alpha) * (c * &bd);
    Ok(StateSpaceMatrices {
        a: ad,
        b: bd,
        c: cd,
        d: dd,
    })
}

/// The continuous model whose generalized bilinear transformation with step `dt` and weight
/// `alpha` is the discrete model (Ad, Bd, Cd, Dd): the exact inverse of [`bilinear`]. Refuses a
/// model for which α Ad + (1 - α) I is singular to working precision (Ad has an eigenvalue at
/// or near -(1 - α) / α, the image of s = ∞: -1 for Tustin's).
pub fn inverse_bilinear(
    ad: MatRef<'_, f64>,
    bd: MatRef<'_, f64>,
    cd: MatRef<'_, f64>,
    dd: MatRef<'_, f64>,
    dt: f64,
    alpha: f64,
) -> Result<StateSpaceMatrices, Error> {
    check_state_space(ad, bd, cd, dd)?;
    check_positive(dt, "dt")?;
    check_alpha(alpha)?;
    let n = ad.nrows();
    let identity = Mat::<f64>::identity(n, n);
    let w = faer::Scale(alpha) * ad + faer::Scale(1.0 - alpha) * &identity;
    let Some((lu, w_inverse)) = checked_inverse(w.as_ref())? else {
        return Err(Error::InvalidArgument {
            arg: "A",
            message: format!(
                "alpha A + (1 - alpha) I is singular to working precision for alpha = {alpha:?}: \
                 the discrete A has an eigenvalue at or near -(1 - alpha) / alpha = {:?}, the \
                 image of s = infinity, so no continuous model maps to it",
                -(1.0 - alpha) / alpha
            ),
        });
    };
    let a = faer::Scale(1.0 / dt) * lu.solve((ad - &identity).as_ref())?;
    let b = faer::Scale(1.0 / dt) * lu.solve(bd)?;
    let c = product(cd, w_inverse.as_ref())?;
    let d = dd - faer::Scale(alpha) * (&c * bd);
    if !(a.is_all_finite() && b.is_all_finite()) {
        return Err(Error::InvalidValue {
            arg: "dt",
            value: dt,
            requirement: "large enough that A / dt and B / dt are finite",
        });
    }
    Ok(StateSpaceMatrices { a, b, c, d })
}

/// The continuous A and B whose zero-order-hold discretisation over `dt` is (Φ, Γ0): the
/// principal real logarithm of [[Φ, Γ0], [0, I]] divided by dt (see the module docs).
///
/// Refuses a Φ with an eigenvalue on the closed negative real axis (no real logarithm: no real
/// continuous model has these samples), and verifies e^{[[A, B], [0, 0]] dt} against the block
/// matrix before returning.
pub fn undiscretize_zoh(
    phi: MatRef<'_, f64>,
    gamma: MatRef<'_, f64>,
    dt: f64,
) -> Result<(Mat<f64>, Mat<f64>), Error> {
    check_square(phi, "A")?;
    check_finite(phi, "A")?;
    check_rows(gamma, "B", phi.nrows(), "A")?;
    check_finite(gamma, "B")?;
    check_positive(dt, "dt")?;
    let (n, m) = (phi.nrows(), gamma.ncols());
    // Γ0 scaled by a power of two (exactly) to the size of Φ: the logarithm's (1, 2) block is
    // linear in Γ0, and the blocks then weigh alike in the Schur form and the norms.
    let gamma_max = gamma.norm_max();
    let phi_max = phi.norm_max().max(f64::MIN_POSITIVE);
    let input_scale = if gamma_max > 0.0 {
        (phi_max.log2() - gamma_max.log2()).round()
    } else {
        0.0
    };
    let size = n + m;
    let block = Mat::from_fn(size, size, |i, j| match (i < n, j < n) {
        (true, true) => phi[(i, j)],
        (true, false) => times_power_of_two(gamma[(i, j - n)], input_scale),
        (false, false) => f64::from(u8::from(i == j)),
        (false, true) => 0.0,
    });
    let logarithm = real_logarithm(block.as_ref())?;
    // The check: e^{log M} = M to a tolerance far above rounding (a failure is gross).
    let back = expm(logarithm.as_ref())?;
    let residual = (&back - &block).norm_max() / block.norm_max().max(f64::MIN_POSITIVE);
    if residual.is_nan() || residual > LOGARITHM_RESIDUAL {
        return Err(Error::IllConditioned {
            message: format!(
                "the logarithm of [[A, B], [0, I]] failed its check: e^(log M) differs from M \
                 by {residual:.2e} relatively, so the zero-order hold cannot be undone \
                 accurately"
            ),
        });
    }
    let a = Mat::from_fn(n, n, |i, j| logarithm[(i, j)] / dt);
    let b = Mat::from_fn(n, m, |i, j| {
        times_power_of_two(logarithm[(i, n + j)], -input_scale) / dt
    });
    if !(a.is_all_finite() && b.is_all_finite()) {
        return Err(Error::InvalidValue {
            arg: "dt",
            value: dt,
            requirement: "large enough that A / dt and B / dt are finite",
        });
    }
    Ok((a, b))
}

/// The largest relative residual ||e^(log M) - M||_max / ||M||_max that [`undiscretize_zoh`]
/// accepts.
const LOGARITHM_RESIDUAL: f64 = 1e-8;

/// θ_8: for ||X||_1 <= θ_8 the [8/8] Padé approximant of log(I + X) errs by less than u = 2^-53
/// (Kenney & Laub's bound |r_8(-||X||) - log(1 - ||X||)|, evaluated at 50 digits; Higham 2008,
/// Table 11.1 gives 3.40e-1).
const LOG_PADE_THETA: f64 = 0.340_217_233_198_529_9;

/// The nodes of 8-point Gauss–Legendre quadrature on [0, 1] (computed at 40 digits).
const LOG_PADE_NODES: [f64; 8] = [
    0.019_855_071_751_231_884,
    0.101_666_761_293_186_64,
    0.237_233_795_041_835_5,
    0.408_282_678_752_175_1,
    0.591_717_321_247_825,
    0.762_766_204_958_164_5,
    0.898_333_238_706_813_4,
    0.980_144_928_248_768_1,
];

/// The weights of 8-point Gauss–Legendre quadrature on [0, 1].
const LOG_PADE_WEIGHTS: [f64; 8] = [
    0.050_614_268_145_188_13,
    0.111_190_517_226_687_24,
    0.156_853_322_938_943_63,
    0.181_341_891_689_181,
    0.181_341_891_689_181,
    0.156_853_322_938_943_63,
    0.111_190_517_226_687_24,
    0.050_614_268_145_188_13,
];

/// The square roots [`real_logarithm`] takes at most: each halves the argument of the
/// eigenvalues and takes their moduli towards 1, so ||T^(1/2^s) - I|| falls below θ_8 within
/// about log2(|log λ|max / θ_8) roots; more means the iteration is going nowhere.
const MAX_SQUARE_ROOTS: u32 = 100;

/// A diagonal block of a quasi-triangular matrix: 1 x 1 (a real eigenvalue) or 2 x 2 in
/// standard form (a complex pair θ ± iμ).
#[derive(Debug, Clone, Copy)]
struct DiagonalBlock {
    start: usize,
    size: usize,
    /// θ, the real part of the eigenvalue(s).
    theta: f64,
    /// μ > 0 for a complex pair, 0 for a real eigenvalue.
    mu: f64,
}

fn diagonal_blocks(t: MatRef<'_, f64>) -> Vec<DiagonalBlock> {
    let n = t.nrows();
    let mut blocks = Vec::new();
    let mut k = 0;
    while k < n {
        if k + 1 < n && t[(k + 1, k)] != 0.0 {
            let (theta, mu) = pair_of(t, k);
            blocks.push(DiagonalBlock {
                start: k,
                size: 2,
                theta,
                mu,
            });
            k += 2;
        } else {
            blocks.push(DiagonalBlock {
                start: k,
                size: 1,
                theta: t[(k, k)],
                mu: 0.0,
            });
            k += 1;
        }
    }
    blocks
}

/// ln |θ + iμ|, accurate relative to its (small) size when the modulus is near 1.
fn log_modulus(theta: f64, mu: f64) -> f64 {
    let modulus = theta.hypot(mu);
    if (0.5..=2.0).contains(&modulus) {
        0.5 * ((theta - 1.0) * (theta + 1.0) + mu * mu).ln_1p()
    } else {
        modulus.ln()
    }
}

/// The principal square root of the quasi-triangular T by the block recurrence of Higham
/// (1987): R_jj = sqrt(T_jj) on the diagonal blocks, then R_ii R_ij + R_ij R_jj = T_ij -
/// Σ_k R_ik R_kj (a Sylvester equation of order <= 4) up each block column. Every eigenvalue of
/// R has a positive real part, so the Sylvester equations are nonsingular.
fn quasi_triangular_sqrt(t: MatRef<'_, f64>, blocks: &[DiagonalBlock]) -> Result<Mat<f64>, Error> {
    let n = t.nrows();
    let mut r = Mat::<f64>::zeros(n, n);
    for (column, &diagonal) in blocks.iter().enumerate() {
        let DiagonalBlock {
            start: j0, size: q, ..
        } = diagonal;
        if q == 1 {
            r[(j0, j0)] = t[(j0, j0)].sqrt();
        } else {
            // T_jj = θ I + N with N^2 = -μ^2 I; sqrt(θ + iμ) = α + iβ with α > 0 gives
            // R_jj = α I + N / (2α) (R_jj^2 = (α^2 - μ^2/(4α^2)) I + N = T_jj).
            let (theta, mu) = pair_of(t, j0);
            let modulus = theta.hypot(mu);
            let alpha = if theta >= 0.0 {
                ((theta + modulus) / 2.0).sqrt()
            } else {
                mu / (2.0 * (modulus - theta)).sqrt()
            };
            for i in 0..2 {
                for j in 0..2 {
                    let identity = if i == j { theta } else { 0.0 };
                    r[(j0 + i, j0 + j)] = (t[(j0 + i, j0 + j)] - identity) / (2.0 * alpha)
                        + if i == j { alpha } else { 0.0 };
                }
            }
        }
        for &row_block in blocks[..column].iter().rev() {
            let DiagonalBlock {
                start: i0, size: p, ..
            } = row_block;
            let mut rhs = [[0.0; 2]; 2];
            for (a, rhs_row) in rhs.iter_mut().enumerate().take(p) {
                for (b, value) in rhs_row.iter_mut().enumerate().take(q) {
                    let mut sum = t[(i0 + a, j0 + b)];
                    for k in i0 + p..j0 {
                        sum -= r[(i0 + a, k)] * r[(k, j0 + b)];
                    }
                    *value = sum;
                }
            }
            let small = |start: usize, size: usize| {
                let mut m = [[0.0; 2]; 2];
                for (a, row) in m.iter_mut().enumerate().take(size) {
                    for (b, value) in row.iter_mut().enumerate().take(size) {
                        *value = r[(start + a, start + b)];
                    }
                }
                m
            };
            let solution = solve_small_sylvester(&small(i0, p), p, &small(j0, q), q, &rhs);
            if solution.perturbed {
                return Err(Error::IllConditioned {
                    message: "the square root of the Schur form met a nearly singular Sylvester \
                              equation: A has eigenvalues too near 0 for a logarithm"
                        .to_string(),
                });
            }
            for a in 0..p {
                for b in 0..q {
                    r[(i0 + a, j0 + b)] = solution.x[a][b];
                }
            }
        }
    }
    Ok(r)
}

/// (θ, μ) of the complex pair θ ± iμ of the 2 x 2 block [[a, b], [c, d]] of T at `k`:
/// θ = (a + d)/2, μ^2 = -((a - d)^2/4 + b c).
fn pair_of(t: MatRef<'_, f64>, k: usize) -> (f64, f64) {
    let (a, b, c, d) = (t[(k, k)], t[(k, k + 1)], t[(k + 1, k)], t[(k + 1, k + 1)]);
    let half_difference = (a - d) / 2.0;
    let mu = (-(half_difference * half_difference + b * c))
        .max(0.0)
        .sqrt();
    ((a + d) / 2.0, mu)
}

/// Writes into `out` (at the block's place) the diagonal block of T^(1/2^s) - I, from the
/// eigenvalues of the block of the original T (`original`, with its N = T_jj - θ I):
/// λ^(1/2^s) - 1 = expm1(ln λ / 2^s) for a real λ > 0, and for a pair
/// e^ρ (cos ψ I + sin ψ N / μ) - I with ρ = ln|λ| / 2^s, ψ = arg λ / 2^s.
fn root_minus_identity(t: MatRef<'_, f64>, block: DiagonalBlock, s: u32, out: &mut Mat<f64>) {
    let scale = (-f64::from(s)).exp2();
    let k = block.start;
    if block.size == 1 {
        out[(k, k)] = (t[(k, k)].ln() * scale).exp_m1();
        return;
    }
    let (rho, psi) = (
        log_modulus(block.theta, block.mu) * scale,
        block.mu.atan2(block.theta) * scale,
    );
    let half_sine = (psi / 2.0).sin();
    let diagonal = rho.exp_m1() * psi.cos() - 2.0 * half_sine * half_sine;
    let off = rho.exp() * psi.sin() / block.mu;
    for i in 0..2 {
        for j in 0..2 {
            out[(k + i, k + j)] = if i == j {
                diagonal + off * (t[(k + i, k + i)] - block.theta)
            } else {
                off * t[(k + i, k + j)]
            };
        }
    }
}

/// Writes into `out` the diagonal block of log T: ln λ for a real λ, and
/// ln|λ| I + (arg λ / μ) N for a pair.
fn block_logarithm(t: MatRef<'_, f64>, block: DiagonalBlock, out: &mut Mat<f64>) {
    let k = block.start;
    if block.size == 1 {
        out[(k, k)] = t[(k, k)].ln();
        return;
    }
    let (log_modulus, angle) = (
        log_modulus(block.theta, block.mu),
        block.mu.atan2(block.theta) / block.mu,
    );
    for i in 0..2 {
        for j in 0..2 {
            out[(k + i, k + j)] = if i == j {
                log_modulus + angle * (t[(k + i, k + i)] - block.theta)
            } else {
                angle * t[(k + i, k + j)]
            };
        }
    }
}

/// The principal logarithm of a real square matrix, real when no eigenvalue lies on the closed
/// negative real axis (else an error naming the eigenvalue): inverse scaling and squaring on
/// the real Schur form (see the module docs).
fn real_logarithm(m: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    let n = m.nrows();
    let schur = real_schur(m)?;
    let t = schur.t;
    let blocks = diagonal_blocks(t.as_ref());
    if let Some(block) = blocks.iter().find(|b| b.size == 1 && b.theta <= 0.0) {
        return Err(Error::InvalidArgument {
            arg: "A",
            message: format!(
                "A has the eigenvalue {} on the closed negative real axis: it has no real \
                 logarithm, so no real continuous model has these zero-order-hold samples",
                block.theta
            ),
        });
    }
    // X = T^(1/2^s) - I: off the diagonal blocks from the computed roots, on them from the
    // closed forms.
    let mut root = t.clone();
    let mut roots = 0u32;
    let mut x = Mat::<f64>::zeros(n, n);
    loop {
        x.copy_from(&root);
        for &block in &blocks {
            root_minus_identity(t.as_ref(), block, roots, &mut x);
        }
        if one_norm(x.as_ref()) <= LOG_PADE_THETA {
            break;
        }
        if roots == MAX_SQUARE_ROOTS {
            return Err(Error::NoConvergence {
                algorithm: "the square roots of the matrix logarithm",
            });
        }
        root = quasi_triangular_sqrt(root.as_ref(), &blocks)?;
        roots += 1;
    }
    // log(I + X) = Σ_k w_k X (I + t_k X)^-1 = Σ_k w_k (I + t_k X)^-1 X (the factors commute).
    let identity = Mat::<f64>::identity(n, n);
    let mut logarithm = Mat::<f64>::zeros(n, n);
    for (&node, &weight) in LOG_PADE_NODES.iter().zip(&LOG_PADE_WEIGHTS) {
        let shifted = &identity + faer::Scale(node) * &x;
        let term = Lu::new(shifted.as_ref())?.solve(x.as_ref())?;
        logarithm += faer::Scale(weight) * term;
    }
    logarithm *= faer::Scale(f64::from(roots).exp2());
    for &block in &blocks {
        block_logarithm(t.as_ref(), block, &mut logarithm);
    }
    product(
        product(schur.z.as_ref(), logarithm.as_ref())?.as_ref(),
        schur.z.transpose(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::lu;
    use faer::{Par, mat};

    fn max_abs_difference(x: MatRef<'_, f64>, y: MatRef<'_, f64>) -> f64 {
        (x - y).norm_max()
    }

    #[test]
    fn zoh_equals_the_inverse_formula_for_nonsingular_a() {
        // Γ0 = (e^{Ah} - I) A^-1 B = A^-1 (e^{Ah} - I) B (A and e^{Ah} commute).
        let a = mat![
            [-0.0212, 0.0466, 0.0, -0.1153],
            [-0.2229, -0.5839, 0.9404, 0.0],
            [0.0150, -0.5031, -0.5015, 0.0],
            [0.0, 0.0, 1.0, 0.0]
        ];
        let b = mat![[0.0], [-0.0340], [-0.5746], [0.0]];
        for dt in [0.01, 0.5, 20.0] {
            let d = discretize(a.as_ref(), b.as_ref(), dt, Hold::Zero).unwrap();
            let rhs = (&d.phi - Mat::<f64>::identity(4, 4)) * &b;
            let mut expected = rhs;
            lu::solve(a.clone().as_mut(), expected.as_mut(), Par::Seq).unwrap();
            let scale = expected.norm_max();
            assert!(max_abs_difference(d.gamma0.as_ref(), expected.as_ref()) < 1e-12 * scale);
            assert!(d.gamma1.is_none());
        }
    }

    #[test]
    fn singular_a_of_the_state_feedback_example() {
        // (6.95): A = [[-3, 8], [0, 0]], B = [0, 4]^T has a zero eigenvalue, so (6.43) fails.
        // Closed form: x2 integrates 4η, x1' = -3 x1 + 8 x2.
        let a = mat![[-3.0, 8.0], [0.0, 0.0]];
        let b = mat![[0.0], [4.0]];
        let h = 0.7f64;
        let d = discretize(a.as_ref(), b.as_ref(), h, Hold::First).unwrap();
        let e = (-3.0 * h).exp();
        // Γ0: x2(h) = 4h, x1(h) = 32 ∫_0^h e^{-3(h-s)} s ds = 32 (h/3 - (1 - e^{-3h})/9).
        let g0 = [32.0 * (h / 3.0 - (1.0 - e) / 9.0), 4.0 * h];
        assert!((d.gamma0[(0, 0)] - g0[0]).abs() < 1e-14);
        assert!((d.gamma0[(1, 0)] - g0[1]).abs() < 1e-14);
        // Γ1 = (1/h) ∫_0^h e^{Aτ} (h - τ) dτ B; for the integrator row: (1/h) 4 h^2/2 = 2h.
        let g1 = d.gamma1.unwrap();
        assert!((g1[(1, 0)] - 2.0 * h).abs() < 1e-14);
        // For the first row: (32/h) ∫_0^h (1 - e^{-3τ})/3 (h - τ) dτ.
        let integral = (h * h / 2.0) / 3.0 - (h / 3.0 - (1.0 - e) / 9.0) / 3.0;
        assert!((g1[(0, 0)] - 32.0 / h * integral).abs() < 1e-13);
    }

    #[test]
    fn huge_input_matrix_is_scaled_exactly() {
        let a = mat![[-1.0, 0.5], [0.0, -2.0]];
        let b = mat![[1e12], [3e12]];
        let small = mat![[1.0], [3.0]];
        let big = discretize(a.as_ref(), b.as_ref(), 0.1, Hold::First).unwrap();
        let unit = discretize(a.as_ref(), small.as_ref(), 0.1, Hold::First).unwrap();
        let scaled = &unit.gamma0 * faer::Scale(1e12);
        assert!(max_abs_difference(big.gamma0.as_ref(), scaled.as_ref()) < 1e-15 * 3e12);
        let scaled = unit.gamma1.unwrap() * faer::Scale(1e12);
        assert!(max_abs_difference(big.gamma1.unwrap().as_ref(), scaled.as_ref()) < 1e-15 * 3e12);
    }

    #[test]
    fn bad_arguments_are_named() {
        let a = mat![[1.0, 0.0], [0.0, 1.0]];
        let b = mat![[1.0], [0.0], [2.0]];
        assert_eq!(
            discretize(a.as_ref(), b.as_ref(), 0.1, Hold::Zero)
                .unwrap_err()
                .to_string(),
            "B must have as many rows as A (2), got 3"
        );
        let b = mat![[1.0], [0.0]];
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = discretize(a.as_ref(), b.as_ref(), dt, Hold::Zero).unwrap_err();
            assert!(matches!(err, Error::InvalidValue { arg: "dt", .. }));
        }
    }

    #[test]
    fn extreme_magnitudes_of_b_and_dt() {
        // Γ0 of x' = -x + b u over dt is b (1 - e^-dt): check at the edges of the double range.
        let a = mat![[-1.0]];
        for (b, dt) in [
            (1e-300, 1e-10),
            (1e300, 1e-10),
            (1e300, 1.0),
            (1.0, 5e-324),
            (3.0, 1e6),
        ] {
            let d = discretize(a.as_ref(), mat![[b]].as_ref(), dt, Hold::First).unwrap();
            let expected = b * -(-dt).exp_m1();
            assert!(
                (d.gamma0[(0, 0)] / expected - 1.0).abs() < 1e-14,
                "b={b} dt={dt}: {} vs {expected}",
                d.gamma0[(0, 0)]
            );
            assert!(d.gamma1.unwrap()[(0, 0)].is_finite());
        }
        // A dt overflowing is the step's fault.
        let err = discretize(
            mat![[1e300]].as_ref(),
            mat![[1.0]].as_ref(),
            1e10,
            Hold::Zero,
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidValue { arg: "dt", .. }));
    }

    /// A seeded random matrix with entries in [-1, 1).
    fn random(rows: usize, cols: usize, seed: u64) -> Mat<f64> {
        let mut state = seed;
        Mat::from_fn(rows, cols, |_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        })
    }

    fn relative_difference(x: MatRef<'_, f64>, y: MatRef<'_, f64>) -> f64 {
        (x - y).norm_max() / y.norm_max().max(f64::MIN_POSITIVE)
    }

    #[test]
    fn tustin_of_a_first_order_lag() {
        // x' = -a x + u, y = x: Tustin gives Ad = (1 - ah/2) / (1 + ah/2), Bd = h / (1 + ah/2),
        // Cd = 1 / (1 + ah/2), Dd = (h/2) / (1 + ah/2) (scipy's realization).
        let (a, h) = (3.0, 0.1);
        let model = bilinear(
            mat![[-a]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            h,
            0.5,
        )
        .unwrap();
        let denominator = 1.0 + a * h / 2.0;
        assert!((model.a[(0, 0)] - (1.0 - a * h / 2.0) / denominator).abs() < 1e-16);
        assert!((model.b[(0, 0)] - h / denominator).abs() < 1e-16);
        assert!((model.c[(0, 0)] - 1.0 / denominator).abs() < 1e-16);
        assert!((model.d[(0, 0)] - h / 2.0 / denominator).abs() < 1e-16);
    }

    #[test]
    fn inverse_bilinear_undoes_bilinear() {
        for (n, seed) in [(1usize, 1u64), (4, 2), (9, 3)] {
            let a = random(n, n, seed) - Mat::<f64>::identity(n, n);
            let (b, c, d) = (
                random(n, 2, seed + 10),
                random(3, n, seed + 20),
                random(3, 2, 7),
            );
            for alpha in [0.0, 0.3, 0.5, 1.0] {
                let h = 0.05;
                let discrete =
                    bilinear(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), h, alpha).unwrap();
                let back = inverse_bilinear(
                    discrete.a.as_ref(),
                    discrete.b.as_ref(),
                    discrete.c.as_ref(),
                    discrete.d.as_ref(),
                    h,
                    alpha,
                )
                .unwrap();
                for (x, y) in [(&back.a, &a), (&back.b, &b), (&back.c, &c), (&back.d, &d)] {
                    let error = relative_difference(x.as_ref(), y.as_ref());
                    assert!(error < 1e-12, "n={n} alpha={alpha}: {error}");
                }
            }
        }
    }

    #[test]
    fn bilinear_refuses_a_pole_sent_to_infinity() {
        // A = 2/h: Tustin maps s = 2/h to z = infinity.
        let h = 0.5;
        let err = bilinear(
            mat![[2.0 / h]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            h,
            0.5,
        )
        .unwrap_err();
        assert!(
            matches!(err, Error::InvalidArgument { arg: "dt", .. }),
            "{err}"
        );
        let err = inverse_bilinear(
            mat![[-1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            h,
            0.5,
        )
        .unwrap_err();
        assert!(
            matches!(err, Error::InvalidArgument { arg: "A", .. }),
            "{err}"
        );
        let err = bilinear(
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            h,
            1.5,
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidValue { arg: "alpha", .. }));
    }

    #[test]
    fn logarithm_of_the_zero_order_hold_recovers_a_and_b() {
        // The 747's longitudinal model (an oscillatory pair, a real mode) and random models,
        // including a singular A (an integrator), over steps of different sizes.
        let lon = mat![
            [-0.0212, 0.0466, 0.0, -0.1153],
            [-0.2229, -0.5839, 0.9404, 0.0],
            [0.0150, -0.5031, -0.5015, 0.0],
            [0.0, 0.0, 1.0, 0.0]
        ];
        let lon_b = mat![[0.0], [-0.0340], [-0.5746], [0.0]];
        let singular = mat![[-3.0, 8.0], [0.0, 0.0]];
        let singular_b = mat![[0.0], [4.0]];
        let mut cases = vec![(lon, lon_b), (singular, singular_b)];
        for (n, seed) in [(3usize, 4u64), (6, 5), (10, 6)] {
            cases.push((random(n, n, seed), random(n, 2, seed + 1)));
        }
        for (a, b) in &cases {
            for h in [0.01, 0.3, 2.0] {
                let d = discretize(a.as_ref(), b.as_ref(), h, Hold::Zero).unwrap();
                let (a_back, b_back) =
                    undiscretize_zoh(d.phi.as_ref(), d.gamma0.as_ref(), h).unwrap();
                let error_a = relative_difference(a_back.as_ref(), a.as_ref());
                let error_b = relative_difference(b_back.as_ref(), b.as_ref());
                assert!(
                    error_a < 1e-11 && error_b < 1e-11,
                    "h={h}: {error_a} {error_b}"
                );
            }
        }
    }

    #[test]
    fn logarithm_of_a_rotation_and_of_a_large_spread() {
        // Φ a rotation by 3 rad (near the negative axis, still principal) and eigenvalues from
        // 1e-8 to 1e3: log Φ is known in closed form.
        let angle = 3.0f64;
        let phi = mat![[angle.cos(), -angle.sin()], [angle.sin(), angle.cos()]];
        let gamma = Mat::<f64>::zeros(2, 0);
        let (a, _) = undiscretize_zoh(phi.as_ref(), gamma.as_ref(), 1.0).unwrap();
        let expected = mat![[0.0, -angle], [angle, 0.0]];
        assert!(relative_difference(a.as_ref(), expected.as_ref()) < 1e-14);
        let phi = mat![[1e-8, 1.0, 0.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1e3]];
        let (a, _) = undiscretize_zoh(phi.as_ref(), Mat::<f64>::zeros(3, 0).as_ref(), 1.0)
            .unwrap_or_else(|e| panic!("{e}"));
        let back = expm(a.as_ref()).unwrap();
        assert!(relative_difference(back.as_ref(), phi.as_ref()) < 1e-12);
        assert!((a[(0, 0)] - 1e-8f64.ln()).abs() < 1e-14 * 1e-8f64.ln().abs());
    }

    #[test]
    fn no_real_logarithm_is_refused() {
        let gamma = mat![[1.0], [0.0]];
        for phi in [mat![[-0.5, 0.0], [0.0, 0.9]], mat![[0.0, 1.0], [0.0, 0.5]]] {
            let err = undiscretize_zoh(phi.as_ref(), gamma.as_ref(), 0.1).unwrap_err();
            assert!(
                err.to_string().contains("closed negative real axis"),
                "{err}"
            );
        }
    }

    #[test]
    fn no_inputs_gives_empty_integrals() {
        let a = mat![[0.0, 1.0], [-1.0, 0.0]];
        let b = Mat::<f64>::zeros(2, 0);
        let d = discretize(a.as_ref(), b.as_ref(), 0.3, Hold::First).unwrap();
        assert_eq!(d.gamma0.ncols(), 0);
        assert!((d.phi[(0, 1)] - 0.3f64.sin()).abs() < 1e-15);
    }
}
