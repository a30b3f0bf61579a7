//! The matrix exponential e^A and the state transition matrix Φ(t) = e^{At} (chapter §6.1.2,
//! (6.19)-(6.22)), by Padé scaling and squaring.
//!
//! # Method
//!
//! e^A = (r_m(2^-s A))^(2^s), where r_m = p_m(x) / p_m(-x) is the diagonal [m/m] Padé
//! approximant of e^x,
//!
//! ```text
//! p_m(x) = sum_{j=0}^{m} b_j x^j,   b_j ∝ (2m - j)! m! / ((2m)! j! (m - j)!),
//! ```
//!
//! with m in {3, 5, 7, 9, 13} and the scaling s chosen as in Algorithm 5.1 of A. H. Al-Mohy and
//! N. J. Higham, "A new scaling and squaring algorithm for the matrix exponential", SIAM J.
//! Matrix Anal. Appl. 31(3), 2009, pp. 970-989, which refines N. J. Higham, "The scaling and
//! squaring method for the matrix exponential revisited", SIAM J. Matrix Anal. Appl. 26(4),
//! 2005, pp. 1179-1193:
//!
//! * The backward error of r_m(2^-s A) is at most the unit roundoff u = 2^-53 when
//!   2^-s α_p(A) <= θ_m, where α_p(A) = max(||A^p||^(1/p), ||A^(p+1)||^(1/(p+1))) and θ_m is the
//!   constant of Higham (2005), Table 2.3 (except θ13, lowered to 4.25 for the reason given at
//!   `THETA_13`). Using ||A^k||^(1/k), which can be far smaller than ||A|| for non-normal A,
//!   instead of ||A|| avoids the overscaling that loses accuracy in the squaring phase. The
//!   d_k = ||A^k||_1^(1/k) for k = 4, 6 are exact norms of formed powers; d_8 and d_10 are exact
//!   (products formed) for n <= [`EXACT_NORM_MAX_ORDER`] and estimated above it by the block
//!   1-norm estimator of Higham & Tisseur (2000), see `norm.rs`. A test d_k <= θ is first
//!   tried on the bound ||A^k||_1 <= ||A^i||_1 ||A^j||_1 (i + j = k) from the exact norms at
//!   hand: the bound within θ implies d_k within θ, so the choice is that of the norms, and a
//!   power is formed (or a norm estimated) only when the bound cannot decide or the chosen
//!   degree needs it. For a matrix of degree 7 with d_4 <= θ_7, A^8 is not formed at all.
//!   (Above [`SMALL_MAX_ORDER`]; at the small orders a product costs what the bound does.)
//! * The ℓ(A, m) correction (Al-Mohy & Higham 2009, (5.1)-(5.2)) adds squarings when the
//!   relative forward error bound |c_{2m+1}| || |A|^{2m+1} ||_1 / ||A||_1 exceeds u, with
//!   |c_{2m+1}| = (m!)^2 / ((2m)! (2m+1)!), the leading coefficient of the error series.
//! * The denominator is never inverted: with U the odd and V the even part of p_m,
//!   r_m = (V - U)^-1 (V + U) = I + 2 (V - U)^-1 U, and the second form is evaluated (one LU
//!   solve with partial pivoting for the right-hand side U), so that the identity is exact and
//!   the rounding of the solve is relative to the correction U.
//! * For upper triangular A (and lower triangular, through the transpose), the result is kept
//!   triangular, and in double-precision evaluation the diagonal and the first superdiagonal of
//!   every intermediate square are recomputed exactly (Code Fragment 2.1 of Al-Mohy & Higham
//!   2009), with the divided difference (e^λ2 - e^λ1)/(λ2 - λ1) = e^((λ1+λ2)/2) sinh(δ)/δ,
//!   δ = (λ2 - λ1)/2. (The double-double evaluation needs no such repair: its squarings lose
//!   nothing at double precision.)
//!
//! The Padé evaluation for m = 13 costs 6 matrix products plus one LU solve, and m = 3, 5, 7, 9
//! cost 2, 3, 4, 5 products; each squaring is one product.
//!
//! Above [`SMALL_MAX_ORDER`], the Taylor approximant "15+" of `taylor.rs` (Sastre, Ibáñez &
//! Defez 2019: degree 16, exact through degree 15, 4 products and no solve, θ = 0.676 by the
//! same backward error analysis with α_4 = max(d_4, d_5)) replaces the Padé degrees 5 to 13
//! wherever it needs at most [`TAYLOR_MAX_SQUARINGS`] squarings (see
//! [`ExponentialPlan::choose`]); d_4 and d_5 are bounded first, then exact at the orders of
//! exact norms and estimated above them.
//!
//! # Small orders, and accuracy beyond double precision
//!
//! Orders up to [`SMALL_MAX_ORDER`] run on stack matrices of constant size (nalgebra's `SMatrix`):
//! flight models are that small, and at these orders a general-order library call costs more
//! than its arithmetic. For them, an exponential that needs [`DOUBLE_DOUBLE_MIN_SQUARINGS`] or
//! more squarings is evaluated in double-double arithmetic (`double_double.rs`). Measured against
//! 50-digit references, the Padé truncation itself is below double-precision resolution on every
//! test matrix; the error of a double evaluation is the rounding in forming r_m and in the
//! squarings, which the squarings amplify on stiff and non-normal matrices ("humps") to 1e-13
//! and more. In double-double those roundings drop below 1e-30 and the result is correct to a
//! few units in the last place. The cost (about four times a double evaluation) is paid only
//! where squarings make it worthwhile.
//!
//! `ExponentialPlan` holds the powers and norms of one matrix so that e^{tA} at many times t
//! (the transition matrices of a response) reuses them: ||(tA)^k|| = |t|^k ||A^k||, so only the
//! final Padé evaluation and squaring are repeated per time.

pub mod double_double;
pub mod taylor;

use crate::error::{Error, check_finite, check_finite_values, check_output_len, check_square};
use crate::linalg::expm::double_double::DoubleDoubleMatrix;
use crate::linalg::lu;
use crate::linalg::matrix::{from_faer_in, with_order};
use crate::linalg::norm::{MatrixProduct, absolute_power_norm, one_norm, one_norm_estimate};
use crate::linalg::product::multiply;
use crate::linalg::small_matrix::{self, CacheAligned, Columns, StackColumns};
use crate::platform::dispatch::{add_scaled, fma_dispatch, multiply_add};
use crate::platform::interrupt;
use crate::platform::parallel::{PARALLEL_MIN_ORDER, ParallelContext, parallelism_for_order};
use crate::platform::pool::{Scratch, scratch};
use faer::{Accum, Mat, MatMut, MatRef};
use nalgebra::{Const, SMatrix};
use rayon::prelude::*;
use std::convert::Infallible;

/// For n up to this order the norms ||A^8||_1 and ||A^10||_1 of the degree selection are exact
/// (from formed products); above it they are estimated (Higham & Tisseur 2000), which costs
/// O(n^2) instead of a matrix product.
pub const EXACT_NORM_MAX_ORDER: usize = 150;

/// Orders up to this run on fixed-size stack matrices; larger ones on faer.
pub const SMALL_MAX_ORDER: usize = 8;

/// Small-order exponentials that need at least this many squarings are evaluated in
/// double-double arithmetic (see the module documentation).
pub const DOUBLE_DOUBLE_MIN_SQUARINGS: u32 = 2;

/// Matrices whose 1-norm may exceed 2^64 (n max|a_ij| > 2^64) are first scaled down below it,
/// with the difference made up by extra squarings, so that neither the norms nor the powers
/// A^2 ... A^12 of the degree selection can overflow.
const MAX_UNSCALED_NORM_LOG2: f64 = 64.0;

/// Matrices whose largest entry is below 2^-64 are first scaled up to it, with the difference
/// moved into the time: e^{tA} = e^{(t 2^e) (2^-e A)}. Otherwise the powers of a tiny A
/// underflow while the powers of the scalar (t 2^-s) that multiply them overflow, and their
/// product (0 · inf) is NaN: A = -I / t at t = 1e100 gave NaN for e^{-I}.
const MIN_UNSCALED_ENTRY_LOG2: f64 = -64.0;

/// 2^-63 and 2^63: a matrix whose largest entry is at least the first, and whose order times
/// that entry is at most the second, is within both bounds above by a factor of 2, so that it
/// is known to need no scaling without computing a logarithm.
const ORDINARY_ENTRY_MIN: f64 = 1.0842021724855044e-19;
const ORDINARY_NORM_MAX: f64 = 9_223_372_036_854_775_808.0;

/// ln of the largest double (about 709.78), less a margin: e^{tA} with ||e^{tA}||_2 below
/// e^this has finite entries.
const LOG_FINITE_BOUND: f64 = 700.0;

/// Squarings are capped here: 2^-2200 underflows every double, so more can only repeat inf.
const MAX_SQUARINGS: u32 = 2200;

/// Unit roundoff of IEEE double precision, u = 2^-53.
const UNIT_ROUNDOFF_LOG2: f64 = -53.0;

/// A diagonal Padé approximant r_m: its degree, the bound θ_m on the scaled norm for which its
/// backward error is at most u (Higham 2005, Table 2.3), the coefficients b_0 ... b_m of p_m,
/// log2 |c_{2m+1}| = log2((m!)^2 / ((2m)! (2m+1)!)), the leading coefficient of the series of its
/// backward error function (Al-Mohy & Higham 2009, Section 5), and the norm below which that
/// leading term alone is below u, (u / |c_{2m+1}|)^(1/(2m)), so that ℓ = 0 needs no work.
struct PadeApproximant {
    degree: usize,
    theta: f64,
    coefficients: &'static [f64],
    log2_error_coefficient: f64,
    /// 2^(log2 |c_{2m+1}| - log2 u), |c_{2m+1}| / u.
    error_coefficient_over_u: f64,
    norm_without_extra_squarings: f64,
}

const PADE_3: [f64; 4] = [120.0, 60.0, 12.0, 1.0];
const PADE_5: [f64; 6] = [30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0];
const PADE_7: [f64; 8] = [
    17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0,
];
const PADE_9: [f64; 10] = [
    17643225600.0,
    8821612800.0,
    2075673600.0,
    302702400.0,
    30270240.0,
    2162160.0,
    110880.0,
    3960.0,
    90.0,
    1.0,
];
const PADE_13: [f64; 14] = [
    64764752532480000.0,
    32382376266240000.0,
    7771770303897600.0,
    1187353796428800.0,
    129060195264000.0,
    10559470521600.0,
    670442572800.0,
    33522128640.0,
    1323241920.0,
    40840800.0,
    960960.0,
    16380.0,
    182.0,
    1.0,
];

/// The scaled-norm bound θ13 for degree 13. Higham (2005) derives θ13 = 5.37 from the backward
/// error alone; near that norm the rounding errors of evaluating r13 (coefficients up to 6e16
/// against powers of norm up to 5.4^6) dominate, and one more squaring is the cheaper error.
/// Measured on 600 random matrices (n = 3..8, norms 1e-2..3e2, general, nearly triangular and
/// badly scaled) against 40-digit references: θ13 = 5.37 was more than twice as inaccurate as
/// scipy.linalg.expm on 2 of them, θ13 = 4.25 on none, and 3.5 gained only 5% more accuracy
/// for more squarings. scipy makes the same choice, 4.25.
const THETA_13: f64 = 4.25;

const APPROXIMANTS: [PadeApproximant; 5] = [
    PadeApproximant {
        degree: 3,
        theta: 1.495585217958292e-2,
        coefficients: &PADE_3,
        log2_error_coefficient: -16.62113611327464,
        error_coefficient_over_u: 89357135463.7001,
        norm_without_extra_squarings: 0.014955873861991669,
    },
    PadeApproximant {
        degree: 5,
        theta: 0.253939833006323,
        coefficients: &PADE_5,
        log2_error_coefficient: -33.227772656854167,
        error_coefficient_over_u: 895433.8570596895,
        norm_without_extra_squarings: 0.25397832160209977,
    },
    PadeApproximant {
        degree: 7,
        theta: 9.504178996162932e-1,
        coefficients: &PADE_7,
        log2_error_coefficient: -51.994974307382167,
        error_coefficient_over_u: 2.0069792385235985,
        norm_without_extra_squarings: 0.95145837728564,
    },
    PadeApproximant {
        degree: 9,
        theta: 2.097847961257068e0,
        coefficients: &PADE_9,
        log2_error_coefficient: -72.32471809893495,
        error_coefficient_over_u: 1.5229308857855229e-6,
        norm_without_extra_squarings: 2.1046720498232245,
    },
    PadeApproximant {
        degree: 13,
        theta: THETA_13,
        coefficients: &PADE_13,
        log2_error_coefficient: -116.447004251763,
        error_coefficient_over_u: 7.953322356109394e-20,
        norm_without_extra_squarings: 5.427430678754456,
    },
];

/// Index of each degree in [`APPROXIMANTS`].
const M3: usize = 0;
const M5: usize = 1;
const M7: usize = 2;
const M9: usize = 3;
const M13: usize = 4;
/// The index of the Taylor approximant 15+ (`taylor.rs`) in [`ApproximantChoice`], past the Padé table.
const TAYLOR_15: usize = APPROXIMANTS.len();

/// The most squarings with which the Taylor approximant 15+ is chosen (see
/// [`ExponentialPlan::choose`]). Measured against long-double references on 496 matrices
/// (n = 9..160, norms 1e-3..1e3): routing every order above 8 to Taylor, whatever its
/// squarings, was up to 15 times less accurate than Padé 13 on symmetric matrices of norm
/// 1e3 (10 squarings against 8).
const TAYLOR_MAX_SQUARINGS: u32 = 2;

/// The degree and the number of squarings chosen for one scaled matrix tA.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ApproximantChoice {
    /// Index into the table of approximants (degrees 3, 5, 7, 9, 13), or [`TAYLOR_15`].
    approximant: usize,
    /// Number of squarings s (including any pre-scaling of a matrix of huge norm).
    pub squarings: u32,
}

impl ApproximantChoice {
    /// The degree m of the Padé approximant, or 15 for the Taylor approximant 15+.
    pub fn degree(&self) -> usize {
        match APPROXIMANTS.get(self.approximant) {
            Some(pade) => pade.degree,
            None => 15,
        }
    }
}

/// The arithmetic of evaluating r_m and squaring: implemented by double matrices of small and
/// of any order, and by double-double matrices.
pub(crate) trait PadeArithmetic: Sized {
    /// Why a product or solve stopped short: [`Error::Interrupted`] for matrices of any order,
    /// whose products and solves answer an interruption ([`interrupt`]); [`Infallible`] for
    /// stack matrices, whose operations always complete, so that the compiled small
    /// exponentials carry no error path.
    type Stop: Into<Error>;
    /// self * rhs.
    fn product(&self, rhs: &Self) -> Result<Self, Self::Stop>;
    /// self += lhs * rhs.
    fn add_product(&mut self, lhs: &Self, rhs: &Self) -> Result<(), Self::Stop>;
    /// identity * I + sum_k coefficient_k * M_k, for at least one term.
    fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self;
    /// r_m = I + 2 (V - U)^-1 U from the even part V and the odd part U.
    fn pade_quotient(even: Self, odd: Self) -> Result<Self, Self::Stop>;
}

/// The operations the degree selection and the double evaluation need besides arithmetic.
pub(crate) trait ExpmMatrix: PadeArithmetic + Send + Sync {
    fn from_ref(a: MatRef<'_, f64>) -> Self;
    fn order(&self) -> usize;
    fn get(&self, i: usize, j: usize) -> f64;
    fn is_upper_triangular(&self) -> bool;
    fn is_lower_triangular(&self) -> bool;
    fn transpose(&self) -> Self;
    fn set(&mut self, i: usize, j: usize, value: f64);
    fn one_norm(&self) -> f64;
    /// max |a_ij|.
    fn max_abs(&self) -> f64;
    /// Whether every entry is finite.
    fn is_finite(&self) -> bool;
    /// A lower bound (usually the value) of ||F_1 ... F_k||_1 without forming the product.
    fn estimate_product_norm(factors: &[&Self]) -> f64;
    /// ||(|A| / scale)^p||_1.
    fn absolute_power_norm(&self, scale: f64, p: usize) -> f64;
    /// Writes the matrix (transposed if asked) into `out`.
    fn write_to(&self, out: MatMut<'_, f64>, transpose: bool);
    /// r_m(cA) squared `squarings` times, in double-double arithmetic, if this representation
    /// supports it; None otherwise (or if the result overflowed).
    fn double_double_exponential(
        &self,
        _c: f64,
        _approximant: usize,
        _squarings: u32,
    ) -> Option<Self> {
        None
    }
}

/// r_m(A) = I + 2 (V - U)^-1 U for the approximant given A, A^2 and the higher even powers
/// [A^4, A^6, A^8] that the degree needs (the others may be None).
#[inline(always)]
fn pade_approximant<M: PadeArithmetic>(
    approximant: usize,
    a: &M,
    a2: &[&M; 1],
    higher: [&Option<M>; 3],
) -> Result<M, M::Stop> {
    // One copy of the evaluation per degree, each with its number of terms a constant.
    match approximant {
        M3 => pade_approximant_of(M3, a, a2, higher),
        M5 => pade_approximant_of(M5, a, a2, higher),
        M7 => pade_approximant_of(M7, a, a2, higher),
        M9 => pade_approximant_of(M9, a, a2, higher),
        _ => pade_approximant_of(approximant, a, a2, higher),
    }
}

/// [`pade_approximant`], for a degree that inlining makes a constant.
#[inline(always)]
fn pade_approximant_of<M: PadeArithmetic>(
    approximant: usize,
    a: &M,
    a2: &[&M; 1],
    higher: [&Option<M>; 3],
) -> Result<M, M::Stop> {
    let mut powers = [a2[0]; 4];
    for (slot, power) in powers[1..].iter_mut().zip(higher) {
        if let Some(p) = power {
            *slot = p;
        }
    }
    let b = APPROXIMANTS[approximant].coefficients;
    let degree = APPROXIMANTS[approximant].degree;
    let (odd_inner, even) = if degree < 13 {
        // U = A (b_1 I + b_3 A^2 + ...), V = b_0 I + b_2 A^2 + ...
        let terms = degree / 2;
        let mut odd_terms = [(0.0, powers[0]); 4];
        let mut even_terms = [(0.0, powers[0]); 4];
        for k in 1..=terms {
            odd_terms[k - 1] = (b[2 * k + 1], powers[k - 1]);
            even_terms[k - 1] = (b[2 * k], powers[k - 1]);
        }
        (
            M::combination(b[1], &odd_terms[..terms]),
            M::combination(b[0], &even_terms[..terms]),
        )
    } else {
        // U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I],
        // V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I.
        let (a2, a4, a6) = (powers[0], powers[1], powers[2]);
        let odd_high = M::combination(0.0, &[(b[13], a6), (b[11], a4), (b[9], a2)]);
        let even_high = M::combination(0.0, &[(b[12], a6), (b[10], a4), (b[8], a2)]);
        let mut odd = M::combination(b[1], &[(b[7], a6), (b[5], a4), (b[3], a2)]);
        let mut even = M::combination(b[0], &[(b[6], a6), (b[4], a4), (b[2], a2)]);
        odd.add_product(a6, &odd_high)?;
        even.add_product(a6, &even_high)?;
        (odd, even)
    };
    M::pade_quotient(even, a.product(&odd_inner)?)
}

/// X <- X^2, `squarings` times; `refine(X, i)` may correct X, which then approximates
/// e^{2^-i tA}, after each square (and before the first).
#[inline(always)]
fn square_repeatedly<M: PadeArithmetic>(
    mut x: M,
    squarings: u32,
    mut refine: impl FnMut(&mut M, u32),
) -> Result<M, M::Stop> {
    refine(&mut x, squarings);
    for i in (0..squarings).rev() {
        x = x.product(&x)?;
        refine(&mut x, i);
    }
    Ok(x)
}

/// c^k P for P = A^k, given `factor` = c^k: when c^k overflows (a large c, which only a matrix
/// whose powers vanish or are small allows, a nilpotent A), c is applied k times instead, so
/// that a zero entry stays zero instead of becoming 0 · inf = NaN.
#[inline(always)]
fn scaled_power<M: PadeArithmetic>(power: &M, c: f64, k: usize, factor: f64) -> M {
    if factor.is_finite() {
        return M::combination(0.0, &[(factor, power)]);
    }
    let mut scaled = M::combination(0.0, &[(c, power)]);
    for _ in 1..k {
        scaled = M::combination(0.0, &[(c, &scaled)]);
    }
    scaled
}

/// [`scaled_power`] of a power that may not have been formed.
#[inline(always)]
fn scaled_formed_power<M: PadeArithmetic>(
    power: &Option<M>,
    c: f64,
    k: usize,
    factor: f64,
) -> Option<M> {
    match power {
        Some(p) => Some(scaled_power(p, c, k, factor)),
        None => None,
    }
}

/// Whether e^{tA} is certainly finite, by the logarithmic norm: ||e^{tA}||_2 <= e^{|t| μ},
/// μ = λ_max(sign(t) (A + A^T) / 2) (Dahlquist 1958; Higham 2008, Theorem 10.11), bounded by
/// the Gershgorin discs of the symmetric part. A rotation, however fast, has μ = 0.
fn exponential_is_finite(a: MatRef<'_, f64>, t: f64) -> bool {
    let n = a.nrows();
    let sign = t.signum();
    let mu = (0..n)
        .map(|i| {
            let radius: f64 = (0..n)
                .filter(|&j| j != i)
                .map(|j| (0.5 * a[(i, j)] + 0.5 * a[(j, i)]).abs())
                .sum();
            sign * a[(i, i)] + radius
        })
        .fold(f64::NEG_INFINITY, f64::max);
    t.abs() * mu.max(0.0) <= LOG_FINITE_BOUND
}

/// ||tA||_1 from which the rounding of the input alone can change every digit of e^{tA}:
/// 2^53 = 1/u (the exponential's relative condition number is at least ||tA||_2).
pub const ILL_CONDITIONED_NORM: f64 = 9_007_199_254_740_992.0;

/// Refuses a computed e^{tA} with infinite or NaN entries that cannot be its value: where the
/// exact value is certainly finite ([`exponential_is_finite`]), or NaN where ||tA||_1 is
/// beyond [`ILL_CONDITIONED_NORM`] while e^{tA} need not overflow. There the squarings of the scaled matrix amplify rounding
/// until it overflows (a rotation by 1e50 rad came back all NaN). An exponential that does
/// overflow is returned as it is, for the caller to warn.
fn check_computed_exponential(
    a: MatRef<'_, f64>,
    t: f64,
    out: MatRef<'_, f64>,
) -> Result<(), Error> {
    let entries = || (0..out.ncols()).flat_map(move |j| (0..out.nrows()).map(move |i| out[(i, j)]));
    if entries().all(f64::is_finite) {
        return Ok(());
    }
    let scaled_norm = t.abs() * one_norm(a);
    let cause = "the squarings that the scaling of ||tA|| needs amplified rounding errors until \
                 they overflowed";
    if exponential_is_finite(a, t) {
        return Err(Error::IllConditioned {
            message: format!(
                "e^(tA) at t = {t:e} is finite (its logarithmic norm bounds it), but could not \
                 be computed in double precision: ||tA||_1 = {scaled_norm:.3e}, and {cause}"
            ),
        });
    }
    // The spectral radius, e^{t max Re λ} >= e^{t tr(A) / n}, shows where e^{tA} overflows.
    let n = a.nrows() as f64;
    let mean_growth = t * (0..a.nrows()).map(|i| a[(i, i)] / n).sum::<f64>();
    let overflows = mean_growth > f64::MAX.ln();
    if scaled_norm >= ILL_CONDITIONED_NORM && !overflows && entries().any(f64::is_nan) {
        return Err(Error::IllConditioned {
            message: format!(
                "e^(tA) at t = {t:e} could not be computed in double precision: ||tA||_1 = \
                 {scaled_norm:.3e} exceeds 1/u = 2^53, where the rounding of the input alone \
                 changes every digit, and {cause} into NaN"
            ),
        });
    }
    Ok(())
}

/// (e^b - e^a) / (b - a), the exponential's divided difference, without cancellation or
/// inf - inf: for close arguments e^((a+b)/2) sinh(δ)/δ, δ = (b - a)/2; otherwise
/// e^max(a,b) (1 - e^-|b-a|) / |b - a|, which overflows only when the value does.
fn exp_divided_difference(a: f64, b: f64) -> f64 {
    let half_difference = 0.5 * (b - a);
    if half_difference == 0.0 {
        a.exp()
    } else if half_difference.abs() <= 1.0 {
        (0.5 * (a + b)).exp() * (half_difference.sinh() / half_difference)
    } else {
        let distance = (b - a).abs();
        a.max(b).exp() * (-(-distance).exp_m1() / distance)
    }
}

/// x^k for a small integer k, by repeated multiplication (inlined, unlike `powi` with a
/// variable exponent, which is a library call).
#[inline(always)]
fn integer_power(x: f64, k: usize) -> f64 {
    let mut result = 1.0;
    let mut base = x;
    let mut exponent = k;
    while exponent > 0 {
        if exponent & 1 == 1 {
            result *= base;
        }
        base *= base;
        exponent >>= 1;
    }
    result
}

/// 2^-k, exactly as `(-(k as f64)).exp2()` gives it, without the library call where it is a
/// normal number (its bits built directly).
#[inline(always)]
fn inverse_power_of_two(k: u32) -> f64 {
    if k <= 1022 {
        f64::from_bits(u64::from(1023 - k) << 52)
    } else {
        (-(k as f64)).exp2()
    }
}

fn is_upper_triangular(a: MatRef<'_, f64>) -> bool {
    (0..a.ncols()).all(|j| (j + 1..a.nrows()).all(|i| a[(i, j)] == 0.0))
}

/// The powers and norms of one matrix A, from which e^{tA} is computed for any real t.
///
/// Building the plan costs one product (A^2); the powers A^4, A^6, A^8 are formed when a chosen
/// degree needs them, and the norms are cached, so that e^{tA} at many times pays the selection
/// once and, per time, only the Padé evaluation and the squarings.
pub(crate) struct ExponentialPlan<M> {
    /// The matrix the plan works on: A, transposed if A is lower triangular, and scaled by
    /// 2^-prescale if its norm is huge.
    a: M,
    /// True when `a` holds A^T (A lower triangular): results are transposed back.
    transposed: bool,
    /// For triangular A, the diagonal and first superdiagonal of `a` before pre-scaling, for
    /// Code Fragment 2.1.
    diagonals: Option<(Vec<f64>, Vec<f64>)>,
    /// Extra squarings that undo the pre-scaling of a matrix of huge norm.
    prescale: u32,
    /// 2^e for a matrix of tiny entries stored as 2^-e A ([`MIN_UNSCALED_ENTRY_LOG2`]): times
    /// are multiplied by it. 1 otherwise.
    time_scale: f64,
    a_norm: f64,
    exact_norms: bool,
    /// Whether the degree tests try [`Self::power_norm_bound`] first: above
    /// [`SMALL_MAX_ORDER`]. Below it a product of stack matrices costs about what the bound's
    /// bookkeeping does, and the tests use the norms alone.
    bound_norms: bool,
    a2: M,
    /// Cached ||A^2||_1, for the bounds of the higher powers' norms.
    a2_norm: Option<f64>,
    a4: Option<M>,
    a6: Option<M>,
    a8: Option<M>,
    /// Cached ||A^k||_1 for k = 4, 6, 8, 10, with whether the value is exact.
    power_norms: [Option<(f64, bool)>; 4],
    /// Cached ||A^4||_1 and ||A^5||_1 of the Taylor degree test: exact if A^4 is formed,
    /// estimated otherwise (never forming a power for its norm).
    taylor_norms: [Option<f64>; 2],
    /// Cached || (|A| / ||A||_1)^{2m+1} ||_1 for each approximant.
    abs_power_norms: [Option<f64>; 5],
}

impl<M: ExpmMatrix> ExponentialPlan<M> {
    /// Prepares e^{tA} for a square, finite A of order at least 2 (the caller validates).
    #[inline(always)]
    pub fn new(a: MatRef<'_, f64>) -> Result<Self, M::Stop> {
        let mut a = M::from_ref(a);
        let mut transposed = false;
        let mut triangular = a.is_upper_triangular();
        if !triangular && a.is_lower_triangular() {
            (a, transposed, triangular) = (a.transpose(), true, true);
        }
        let n = a.order();
        let diagonals = triangular.then(|| {
            let diagonal = (0..n).map(|i| a.get(i, i)).collect();
            let superdiagonal = (0..n - 1).map(|i| a.get(i, i + 1)).collect();
            (diagonal, superdiagonal)
        });
        // ||A||_1 <= n max|a_ij|, a bound that cannot overflow (the column sums can).
        let largest = a.max_abs();
        let (mut prescale, mut time_scale) = (0, 1.0);
        // Entries in [2^-63, 2^63 / n] need neither scaling (the logarithms below are then
        // certainly within (-64, 64)); only others pay for them.
        let ordinary = largest == 0.0
            || (largest >= ORDINARY_ENTRY_MIN && largest * n as f64 <= ORDINARY_NORM_MAX);
        let log2_norm_bound = if ordinary {
            MAX_UNSCALED_NORM_LOG2
        } else {
            largest.log2() + (n as f64).log2()
        };
        if log2_norm_bound > MAX_UNSCALED_NORM_LOG2 {
            prescale = (log2_norm_bound - MAX_UNSCALED_NORM_LOG2).ceil() as u32;
            a = M::combination(0.0, &[((-(prescale as f64)).exp2(), &a)]);
        } else if !ordinary && largest > 0.0 && largest.log2() < MIN_UNSCALED_ENTRY_LOG2 {
            // largest in [2^e, 2^(e+1)); 2^-e is applied in two halves, as 2^1074 overflows.
            let exponent = largest.log2().floor();
            let half = (-exponent / 2.0).floor();
            a = M::combination(0.0, &[(half.exp2(), &a)]);
            a = M::combination(0.0, &[((-exponent - half).exp2(), &a)]);
            time_scale = exponent.exp2();
        }
        let a_norm = a.one_norm();
        let a2 = a.product(&a)?;
        Ok(Self {
            a,
            transposed,
            diagonals,
            prescale,
            time_scale,
            a_norm,
            exact_norms: n <= EXACT_NORM_MAX_ORDER,
            bound_norms: n > SMALL_MAX_ORDER,
            a2,
            a2_norm: None,
            a4: None,
            a6: None,
            a8: None,
            power_norms: [None; 4],
            taylor_norms: [None; 2],
            abs_power_norms: [None; 5],
        })
    }

    #[inline(always)]
    fn ensure_a4(&mut self) -> Result<(), M::Stop> {
        if self.a4.is_none() {
            self.a4 = Some(self.a2.product(&self.a2)?);
        }
        Ok(())
    }

    #[inline(always)]
    fn ensure_a6(&mut self) -> Result<(), M::Stop> {
        self.ensure_a4()?;
        if self.a6.is_none() {
            self.a6 = Some(self.a4.as_ref().expect("formed above").product(&self.a2)?);
        }
        Ok(())
    }

    #[inline(always)]
    fn ensure_a8(&mut self) -> Result<(), M::Stop> {
        self.ensure_a4()?;
        if self.a8.is_none() {
            let a4 = self.a4.as_ref().expect("formed above");
            self.a8 = Some(a4.product(a4)?);
        }
        Ok(())
    }

    /// ||A^k||_1 for k in {4, 6, 8, 10}: exact from a formed power when there is one (forming it
    /// if norms are exact at this order), otherwise estimated from the product of the powers at
    /// hand. Bounded by ||A||_1^k, which also stands in for a power that overflowed.
    #[inline(always)]
    fn power_norm(&mut self, k: usize) -> Result<f64, M::Stop> {
        let slot = k / 2 - 2;
        let formed = |plan: &Self| match k {
            4 => plan.a4.is_some(),
            6 => plan.a6.is_some(),
            8 => plan.a8.is_some(),
            _ => false,
        };
        if let Some((value, exact)) = self.power_norms[slot]
            && (exact || !formed(self))
        {
            return Ok(value);
        }
        if self.exact_norms {
            match k {
                4 => self.ensure_a4()?,
                6 => self.ensure_a6()?,
                8 => self.ensure_a8()?,
                _ => self.ensure_a6()?,
            }
        }
        let (norm, exact) = match k {
            4 if self.a4.is_some() => (self.a4.as_ref().unwrap().one_norm(), true),
            6 if self.a6.is_some() => (self.a6.as_ref().unwrap().one_norm(), true),
            8 if self.a8.is_some() => (self.a8.as_ref().unwrap().one_norm(), true),
            10 if self.exact_norms => {
                let (a4, a6) = (self.a4.as_ref().unwrap(), self.a6.as_ref().unwrap());
                (a4.product(a6)?.one_norm(), true)
            }
            _ => {
                let a2 = &self.a2;
                let factors: Vec<&M> = match (k, &self.a4, &self.a6) {
                    (4, _, _) => vec![a2, a2],
                    (6, Some(a4), _) => vec![a4, a2],
                    (6, None, _) => vec![a2, a2, a2],
                    (8, Some(a4), _) => vec![a4, a4],
                    (8, None, _) => vec![a2, a2, a2, a2],
                    (_, Some(a4), Some(a6)) => vec![a4, a6],
                    _ => vec![a2, a2, a2, a2, a2],
                };
                (M::estimate_product_norm(&factors), false)
            }
        };
        // ||A^k|| <= ||A||^k, which stands in for a power that overflowed.
        let norm = if norm.is_finite() {
            norm
        } else {
            integer_power(self.a_norm, k)
        };
        self.power_norms[slot] = Some((norm, exact));
        Ok(norm)
    }

    /// An upper bound of ||A^k||_1 for k in {4, 6, 8, 10} from the norms at hand, by
    /// submultiplicativity: the least of ||A^i||_1 ||A^j||_1 over i + j = k, with ||A^2||_1 and
    /// the exact cached norms of the higher even powers (an estimate is a lower bound, and is
    /// never used). Costs no product; infinite if a norm overflowed.
    #[inline(always)]
    fn power_norm_bound(&mut self, k: usize) -> f64 {
        let a2_norm = match self.a2_norm {
            Some(norm) => norm,
            None => {
                let norm = self.a2.one_norm();
                self.a2_norm = Some(norm);
                norm
            }
        };
        // bounds[i] bounds ||A^(2i + 2)||_1.
        let mut bounds = [a2_norm; 5];
        for i in 1..k / 2 {
            let mut bound = f64::INFINITY;
            for (low, high) in bounds[..i].iter().zip(bounds[..i].iter().rev()) {
                bound = bound.min(low * high);
            }
            if let Some((norm, true)) = self.power_norms[i - 1] {
                bound = bound.min(norm);
            }
            bounds[i] = bound;
        }
        bounds[k / 2 - 1]
    }

    /// Whether τ max(||A^p||^(1/p), ||A^q||^(1/q)) <= θ, i.e. τ^k ||A^k|| <= θ^k for k = p, q:
    /// the selection compares powers, so that it needs no roots or logarithms. A norm is
    /// computed (and its power formed, at orders of exact norms) only when its bound
    /// [`Self::power_norm_bound`] does not already decide: the bound within θ implies the norm
    /// within θ, so the answer is that of the norms themselves (Al-Mohy & Higham 2009 likewise
    /// form a power only for a degree that needs it).
    #[inline(always)]
    fn scaled_root_norms_within(
        &mut self,
        p: usize,
        q: usize,
        tau: f64,
        theta: f64,
    ) -> Result<bool, M::Stop> {
        let ratio = tau / theta;
        Ok(self.scaled_power_norm_within(p, ratio)? && self.scaled_power_norm_within(q, ratio)?)
    }

    /// Whether ratio^k ||A^k||_1 <= 1, by the bound first (see above).
    #[inline(always)]
    fn scaled_power_norm_within(&mut self, k: usize, ratio: f64) -> Result<bool, M::Stop> {
        let scale = integer_power(ratio, k);
        Ok(
            (self.bound_norms && self.power_norm_bound(k) * scale <= 1.0)
                || self.power_norm(k)? * scale <= 1.0,
        )
    }

    /// log2 τ d_k, d_k = ||A^k||_1^(1/k).
    #[inline(always)]
    fn log2_scaled_root_norm(&mut self, k: usize, tau: f64) -> Result<f64, M::Stop> {
        Ok(tau.log2() + self.power_norm(k)?.log2() / k as f64)
    }

    /// ℓ(τA, m) of Al-Mohy & Higham (2009, (5.1)): the extra squarings needed so that the
    /// truncation of the backward error series at its leading term is below u, for scale τ > 0:
    ///
    /// ```text
    /// ℓ = max(⌈log2(α / u) / (2m)⌉, 0),   α = |c_{2m+1}| || |τA|^{2m+1} ||_1 / ||τA||_1.
    /// ```
    ///
    /// Since || |A|^p ||_1 <= ||A||_1^p, α <= |c_{2m+1}| ||τA||_1^{2m}; when that bound is
    /// already below u (||τA||_1 below the approximant's `norm_without_extra_squarings`),
    /// ℓ = 0 without computing the power norm. Otherwise α / u = |c_{2m+1}| / u ||τA||^{2m} N,
    /// N = ||(|A| / ||A||_1)^{2m+1}||_1 <= 1, is formed directly (logarithms only when ℓ > 0 or
    /// the product leaves the range of doubles).
    #[inline(always)]
    fn extra_squarings(&mut self, approximant: usize, tau: f64) -> u32 {
        let pade = &APPROXIMANTS[approximant];
        let scaled_norm = tau * self.a_norm;
        if scaled_norm <= pade.norm_without_extra_squarings {
            return 0;
        }
        let m = pade.degree;
        // No closures here or below where a kernel runs: a closure is compiled on its own,
        // without the target features of [`small_exponential`] (see `Inlined`).
        let power_norm = match self.abs_power_norms[approximant] {
            Some(norm) => norm,
            None => {
                let norm = self.a.absolute_power_norm(self.a_norm, 2 * m + 1);
                self.abs_power_norms[approximant] = Some(norm);
                norm
            }
        };
        if power_norm == 0.0 {
            return 0;
        }
        let alpha_over_u =
            pade.error_coefficient_over_u * integer_power(scaled_norm, 2 * m) * power_norm;
        let log2_alpha_over_u = if alpha_over_u.is_finite() && alpha_over_u > 0.0 {
            if alpha_over_u <= 1.0 {
                return 0;
            }
            alpha_over_u.log2()
        } else {
            pade.log2_error_coefficient - UNIT_ROUNDOFF_LOG2
                + 2.0 * m as f64 * scaled_norm.log2()
                + power_norm.log2()
        };
        let value = (log2_alpha_over_u / (2 * m) as f64).ceil();
        if value > 0.0 { value as u32 } else { 0 }
    }

    /// ||A^k||_1 for k in {4, 5}, for the Taylor degree test: exact at the orders of exact norms
    /// ([`EXACT_NORM_MAX_ORDER`]: A^4 formed, and ||A^4 A||_1 from the product, which there cost
    /// less than the block 1-norm estimates), above them the estimate of the product A^2 A^2 (A)
    /// (exact ||A^4|| if A^4 is formed); at most the bound ||A^4|| <=
    /// [`Self::power_norm_bound`], ||A^5|| <= ||A^4|| ||A|| (an estimate is a lower bound), and
    /// that bound where the norm overflowed.
    #[inline(always)]
    fn taylor_power_norm(&mut self, k: usize) -> Result<f64, M::Stop> {
        if let Some(norm) = self.taylor_norms[k - 4] {
            return Ok(norm);
        }
        let bound4 = self.power_norm_bound(4);
        let bound = if k == 4 { bound4 } else { bound4 * self.a_norm };
        if self.exact_norms {
            self.ensure_a4()?;
        }
        let norm = match (&self.a4, k) {
            (Some(a4), 4) => a4.one_norm(),
            (Some(a4), _) if self.exact_norms => a4.product(&self.a)?.one_norm(),
            (Some(a4), _) => M::estimate_product_norm(&[a4, &self.a]),
            (None, 4) => M::estimate_product_norm(&[&self.a2, &self.a2]),
            (None, _) => M::estimate_product_norm(&[&self.a2, &self.a2, &self.a]),
        };
        let norm = if norm.is_finite() {
            norm.min(bound)
        } else {
            bound.min(integer_power(self.a_norm, k))
        };
        self.taylor_norms[k - 4] = Some(norm);
        Ok(norm)
    }

    /// The squarings s for the Taylor approximant 15+: the least s with 2^-s τ α_4(A) <= θ,
    /// α_4 = max(||A^4||^(1/4), ||A^5||^(1/5)) (`taylor.rs`). Tried first on the bounds of the
    /// norms (no product, no estimate) and, if they need squarings, on ||A^4|| with the bound
    /// ||A^5|| <= ||A^4|| ||A||, and on ||A^5|| only if that bound needs more squarings than
    /// d_4 alone.
    #[inline(always)]
    fn taylor_squarings(&mut self, tau: f64) -> Result<u32, M::Stop> {
        let squarings = |log2_norm4: f64, log2_norm5: f64| {
            let log2_alpha = (log2_norm4 / 4.0).max(log2_norm5 / 5.0) + tau.log2();
            (log2_alpha - taylor::THETA.log2())
                .ceil()
                .clamp(0.0, MAX_SQUARINGS as f64) as u32
        };
        let bound4 = self.power_norm_bound(4);
        if bound4 == 0.0 {
            return Ok(0);
        }
        let bounded = squarings(bound4.log2(), bound4.log2() + self.a_norm.log2());
        if bounded == 0 {
            return Ok(0);
        }
        let norm4 = self.taylor_power_norm(4)?;
        if norm4 == 0.0 {
            return Ok(0);
        }
        // ||A^5|| <= ||A^4|| ||A||: when that bound needs no more squarings than d_4 alone,
        // ||A^5|| itself is not needed.
        let least = squarings(norm4.log2(), f64::NEG_INFINITY);
        let bounded = squarings(norm4.log2(), norm4.log2() + self.a_norm.log2());
        if bounded == least {
            return Ok(least);
        }
        Ok(squarings(norm4.log2(), self.taylor_power_norm(5)?.log2()))
    }

    /// The approximant and number of squarings for e^{tA} (Al-Mohy & Higham 2009, Algorithm 5.1,
    /// with every norm scaled by τ = |t|).
    ///
    /// Above [`SMALL_MAX_ORDER`] the Taylor approximant 15+ (`taylor.rs`: 4 products, no solve)
    /// is taken with its s_T squarings when s_T <= [`TAYLOR_MAX_SQUARINGS`]. It then costs at
    /// most 6 products, less than the Padé degrees 9 and 13 (5 and 6 products and an LU solve
    /// with n right-hand sides, 4/3 of a product: 6.33 and 7.33) that the norms it covers would
    /// otherwise need; the Padé degrees 5 and 7 (4.33, 5.33) cover norms below θ5 = 0.25 and
    /// θ7 = 0.95, where Taylor needs no squaring (4) or one (5). Only a matrix that the bounds
    /// alone admit to degree 3 (2 products and a solve) takes that first. Beyond, Taylor would
    /// save a third of a product at most (its θ is 2.65 squarings below θ13 = 4.25) and square
    /// 2 to 3 times more, so the Padé choice below is kept. At the small orders the choice is
    /// the Padé one alone.
    #[inline(always)]
    pub fn choose(&mut self, t: f64) -> Result<ApproximantChoice, M::Stop> {
        let tau = t.abs() * self.time_scale;
        if tau == 0.0 || self.a_norm == 0.0 {
            return Ok(ApproximantChoice {
                approximant: M3,
                squarings: self.prescale.min(MAX_SQUARINGS),
            });
        }
        if !self.bound_norms {
            return self.choose_pade(tau);
        }
        let theta3 = APPROXIMANTS[M3].theta;
        if self.power_norm_bound(4) * integer_power(tau / theta3, 4) <= 1.0
            && self.power_norm_bound(6) * integer_power(tau / theta3, 6) <= 1.0
            && self.extra_squarings(M3, tau) == 0
        {
            return Ok(ApproximantChoice {
                approximant: M3,
                squarings: self.prescale.min(MAX_SQUARINGS),
            });
        }
        let taylor_squarings = self.taylor_squarings(tau)?;
        let taylor = ApproximantChoice {
            approximant: TAYLOR_15,
            squarings: taylor_squarings
                .saturating_add(self.prescale)
                .min(MAX_SQUARINGS),
        };
        if taylor_squarings <= TAYLOR_MAX_SQUARINGS {
            return Ok(taylor);
        }
        self.choose_pade(tau)
    }

    /// The Padé degree and number of squarings for scale τ > 0 (Al-Mohy & Higham 2009,
    /// Algorithm 5.1).
    #[inline(always)]
    fn choose_pade(&mut self, tau: f64) -> Result<ApproximantChoice, M::Stop> {
        let choice = |approximant, squarings: u32| ApproximantChoice {
            approximant,
            squarings: squarings.min(MAX_SQUARINGS),
        };
        // η1 = τ max(d4, d6) <= θ3 (d4 and d6 estimated at large orders, before A4 is formed).
        if self.scaled_root_norms_within(4, 6, tau, APPROXIMANTS[M3].theta)?
            && self.extra_squarings(M3, tau) == 0
        {
            return Ok(choice(M3, self.prescale));
        }
        // η2 = τ max(d4, d6) <= θ5, with A4 formed (d4 exact).
        self.ensure_a4()?;
        if self.scaled_root_norms_within(4, 6, tau, APPROXIMANTS[M5].theta)?
            && self.extra_squarings(M5, tau) == 0
        {
            return Ok(choice(M5, self.prescale));
        }
        // η3 = τ max(d6, d8) <= θ7 or θ9, with A6 formed.
        self.ensure_a6()?;
        for approximant in [M7, M9] {
            if self.scaled_root_norms_within(6, 8, tau, APPROXIMANTS[approximant].theta)?
                && self.extra_squarings(approximant, tau) == 0
            {
                return Ok(choice(approximant, self.prescale));
            }
        }
        // η5 = min(η3, η4), η4 = τ max(d8, d10); s = ⌈log2(η5 / θ13)⌉ plus ℓ.
        let (d6, d8, d10) = (
            self.log2_scaled_root_norm(6, tau)?,
            self.log2_scaled_root_norm(8, tau)?,
            self.log2_scaled_root_norm(10, tau)?,
        );
        let eta5 = d6.max(d8).min(d8.max(d10));
        let squarings = (eta5 - THETA_13.log2())
            .ceil()
            .clamp(0.0, MAX_SQUARINGS as f64) as u32;
        let squarings =
            squarings + self.extra_squarings(M13, tau * inverse_power_of_two(squarings));
        Ok(choice(M13, squarings.saturating_add(self.prescale)))
    }

    /// Forms the powers that evaluating `choice` needs; call before evaluating it.
    #[inline(always)]
    pub fn prepare(&mut self, choice: ApproximantChoice) -> Result<(), M::Stop> {
        match choice.approximant {
            M3 | TAYLOR_15 => Ok(()),
            M5 => self.ensure_a4(),
            M9 => {
                self.ensure_a6()?;
                self.ensure_a8()
            }
            _ => self.ensure_a6(),
        }
    }

    /// Writes e^{tA}, with the given (prepared) choice of degree and squarings, into `out`.
    /// Returns true when every entry written is certainly finite (false may also mean that
    /// only entries cleared afterwards, outside a triangular result, were not).
    #[inline(always)]
    pub fn exponential_into(
        &self,
        t: f64,
        choice: ApproximantChoice,
        mut out: MatMut<'_, f64>,
    ) -> Result<bool, M::Stop> {
        let n = self.a.order();
        if t == 0.0 {
            out.fill(0.0);
            out.diagonal_mut().fill(1.0);
            return Ok(true);
        }
        // r_m is evaluated at c * (pre-scaled A); the squarings undo both scalings.
        let c = t
            * self.time_scale
            * inverse_power_of_two(choice.squarings.saturating_sub(self.prescale));
        let accurate = choice.squarings >= DOUBLE_DOUBLE_MIN_SQUARINGS;
        let accurate = if accurate {
            self.a
                .double_double_exponential(c, choice.approximant, choice.squarings)
        } else {
            None
        };
        let x = match accurate {
            Some(x) => x,
            None => self.double_exponential(t, c, choice)?,
        };
        x.write_to(out.as_mut(), self.transposed);
        let finite = x.is_finite();
        if self.diagonals.is_some() {
            // The exponential of a triangular matrix is triangular: clear any rounding (or NaN
            // from an overflowed square) in the other triangle.
            for j in 0..n {
                for i in 0..n {
                    if (i > j) != self.transposed && i != j {
                        out[(i, j)] = 0.0;
                    }
                }
            }
        }
        Ok(finite)
    }

    /// r_m(cA) squared in double precision, refining triangular structure on the way.
    #[inline(always)]
    fn double_exponential(&self, t: f64, c: f64, choice: ApproximantChoice) -> Result<M, M::Stop> {
        let x = if choice.approximant == TAYLOR_15 {
            if c == 1.0 {
                taylor::taylor_approximant(&self.a, &self.a2)?
            } else {
                let a = M::combination(0.0, &[(c, &self.a)]);
                taylor::taylor_approximant(&a, &scaled_power(&self.a2, c, 2, c * c))?
            }
        } else if c == 1.0 {
            pade_approximant(
                choice.approximant,
                &self.a,
                &[&self.a2],
                [&self.a4, &self.a6, &self.a8],
            )?
        } else {
            // The powers of cA: c^k A^k.
            let c2 = c * c;
            let a = M::combination(0.0, &[(c, &self.a)]);
            let a2 = scaled_power(&self.a2, c, 2, c2);
            let a4 = scaled_formed_power(&self.a4, c, 4, c2 * c2);
            let a6 = scaled_formed_power(&self.a6, c, 6, c2 * c2 * c2);
            let a8 = scaled_formed_power(&self.a8, c, 8, (c2 * c2) * (c2 * c2));
            pade_approximant(choice.approximant, &a, &[&a2], [&a4, &a6, &a8])?
        };
        square_repeatedly(x, choice.squarings, |x, i| {
            if let Some((diagonal, superdiagonal)) = &self.diagonals {
                let scale = t * (-(i as f64)).exp2();
                for (k, &d) in diagonal.iter().enumerate() {
                    x.set(k, k, (scale * d).exp());
                }
                for (k, (&s, pair)) in superdiagonal.iter().zip(diagonal.windows(2)).enumerate() {
                    // A zero entry stays zero (not 0 * inf when the diagonal overflows).
                    let value = if s == 0.0 {
                        0.0
                    } else {
                        scale * s * exp_divided_difference(scale * pair[0], scale * pair[1])
                    };
                    x.set(k, k + 1, value);
                }
            }
        })
    }
}

// ----- faer matrices (any order), pooled ----------------------------------------------------

/// Entries of a column that [`combination_into_kernel`] accumulates in registers at a time.
const COMBINATION_CHUNK: usize = 32;

/// The most terms of a combination (the Taylor approximant's longest has 5).
const COMBINATION_MAX_TERMS: usize = 6;

/// out = identity * I + Σ_k coefficient_k M_k for square matrices of one order: each entry is
/// c_1 m_1, to which c_k m_k is added for k = 2, 3, ... (a fused multiply-add in the FMA
/// variant), and then the identity's coefficient on the diagonal, in that order (the order of
/// a pass over the output per term). The entries of a chunk of a column stay in registers
/// through all the terms: one load per term and entry (folded into the multiply-add) and one
/// store, instead of a load and a store of the output per term.
#[inline(always)]
fn combination_into_kernel<const FMA: bool>(
    out: &mut Mat<f64>,
    identity: f64,
    terms: &[(f64, &Scratch)],
) {
    assert!(
        (1..=COMBINATION_MAX_TERMS).contains(&terms.len()),
        "1 to {COMBINATION_MAX_TERMS} terms"
    );
    let n = out.nrows();
    let full = n - n % COMBINATION_CHUNK;
    let mut columns = [(0.0, &[][..]); COMBINATION_MAX_TERMS];
    for j in 0..out.ncols() {
        for (column, &(coefficient, matrix)) in columns.iter_mut().zip(terms) {
            *column = (coefficient, &matrix.col_as_slice(j)[..n]);
        }
        let ((first_coefficient, first), rest) = (columns[0], &columns[1..terms.len()]);
        let column = &mut out.col_as_slice_mut(j)[..n];
        for start in (0..full).step_by(COMBINATION_CHUNK) {
            let chunk = start..start + COMBINATION_CHUNK;
            let mut sums = [0.0; COMBINATION_CHUNK];
            for (sum, &value) in sums.iter_mut().zip(&first[chunk.clone()]) {
                *sum = first_coefficient * value;
            }
            for &(coefficient, x) in rest {
                for (sum, &value) in sums.iter_mut().zip(&x[chunk.clone()]) {
                    *sum = multiply_add::<FMA>(coefficient, value, *sum);
                }
            }
            column[chunk].copy_from_slice(&sums);
        }
        for i in full..n {
            let mut sum = first_coefficient * first[i];
            for &(coefficient, x) in rest {
                sum = multiply_add::<FMA>(coefficient, x[i], sum);
            }
            column[i] = sum;
        }
        column[j] += identity;
    }
}

fma_dispatch!(
    /// [`combination_into_kernel`].
    fn combination_into(out: &mut Mat<f64>, identity: f64, terms: &[(f64, &Scratch)]) => combination_into_kernel
);

/// Whether every entry is finite: an entry is inf or NaN exactly when its exponent bits are
/// all ones, i.e. when |x| as an integer is at least 0x7FF0...0, and adding 2^52 then sets the
/// sign bit; the OR of those sums over a column (integer operations that vectorise) has its
/// sign bit clear exactly when the column is finite.
#[inline(always)]
fn all_finite_kernel<const FMA: bool>(m: &Mat<f64>) -> bool {
    const MAGNITUDE: u64 = !(1 << 63);
    const EXPONENT_STEP: u64 = 1 << 52;
    (0..m.ncols()).all(|j| {
        let flags = m.col_as_slice(j).iter().fold(0u64, |flags, x| {
            flags | ((x.to_bits() & MAGNITUDE) + EXPONENT_STEP)
        });
        flags >> 63 == 0
    })
}

fma_dispatch!(
    /// [`all_finite_kernel`].
    fn all_finite(m: &Mat<f64>) -> bool => all_finite_kernel
);

/// Each product and solve checks for an interruption before it starts, and those of large
/// orders between their panels too ([`multiply`], [`lu::solve`]).
impl PadeArithmetic for Scratch {
    type Stop = Error;

    fn product(&self, rhs: &Self) -> Result<Self, Error> {
        interrupt::check()?;
        let mut out = scratch(self.nrows(), rhs.ncols());
        let par = parallelism_for_order(self.nrows());
        multiply(
            out.as_mut(),
            Accum::Replace,
            self.as_ref(),
            rhs.as_ref(),
            1.0,
            par,
        )?;
        Ok(out)
    }

    fn add_product(&mut self, lhs: &Self, rhs: &Self) -> Result<(), Error> {
        interrupt::check()?;
        let par = parallelism_for_order(self.nrows());
        multiply(
            self.as_mut(),
            Accum::Add,
            lhs.as_ref(),
            rhs.as_ref(),
            1.0,
            par,
        )
    }

    fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self {
        let n = terms.first().expect("at least one term").1.nrows();
        let mut out = scratch(n, n);
        combination_into(&mut out, identity, terms);
        out
    }

    fn pade_quotient(mut even: Self, mut odd: Self) -> Result<Self, Error> {
        interrupt::check()?;
        let n = even.nrows();
        for j in 0..n {
            add_scaled(even.col_as_slice_mut(j), -1.0, odd.col_as_slice(j));
        }
        lu::solve(even.as_mut(), odd.as_mut(), parallelism_for_order(n))?;
        for j in 0..n {
            let column = odd.col_as_slice_mut(j);
            for value in column.iter_mut() {
                *value *= 2.0;
            }
            column[j] += 1.0;
        }
        Ok(odd)
    }
}

impl ExpmMatrix for Scratch {
    fn from_ref(a: MatRef<'_, f64>) -> Self {
        let mut m = scratch(a.nrows(), a.ncols());
        m.copy_from(a);
        m
    }

    fn order(&self) -> usize {
        self.nrows()
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        self[(i, j)]
    }

    fn is_upper_triangular(&self) -> bool {
        is_upper_triangular(self.as_ref())
    }

    fn is_lower_triangular(&self) -> bool {
        is_upper_triangular(self.as_ref().transpose())
    }

    fn transpose(&self) -> Self {
        Self::from_ref(self.as_ref().transpose())
    }

    fn set(&mut self, i: usize, j: usize, value: f64) {
        self[(i, j)] = value;
    }

    fn one_norm(&self) -> f64 {
        one_norm(self.as_ref())
    }

    fn max_abs(&self) -> f64 {
        self.as_ref().norm_max()
    }

    fn is_finite(&self) -> bool {
        all_finite(self)
    }

    fn estimate_product_norm(factors: &[&Self]) -> f64 {
        one_norm_estimate(
            &MatrixProduct::new(factors.iter().map(|f| f.as_ref()).collect()),
            2,
        )
    }

    fn absolute_power_norm(&self, scale: f64, p: usize) -> f64 {
        absolute_power_norm(self.as_ref(), scale, p)
    }

    fn write_to(&self, mut out: MatMut<'_, f64>, transpose: bool) {
        if transpose {
            out.copy_from(self.as_ref().transpose());
        } else {
            out.copy_from(self.as_ref());
        }
    }
}

// ----- stack matrices of a small order, with the double-double evaluation --------------------

impl<const N: usize> PadeArithmetic for SMatrix<f64, N, N> {
    type Stop = Infallible;

    fn product(&self, rhs: &Self) -> Result<Self, Infallible> {
        Ok(small_matrix::product(self, rhs))
    }

    fn add_product(&mut self, lhs: &Self, rhs: &Self) -> Result<(), Infallible> {
        small_matrix::add_product(self, lhs, rhs);
        Ok(())
    }

    fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self {
        small_matrix::combination(identity, terms)
    }

    fn pade_quotient(even: Self, odd: Self) -> Result<Self, Infallible> {
        let denominator = small_matrix::combination(0.0, &[(1.0, &even), (-1.0, &odd)]);
        Ok(small_matrix::combination(
            1.0,
            &[(2.0, &small_matrix::solve(denominator, odd))],
        ))
    }
}

impl<const N: usize> PadeArithmetic for DoubleDoubleMatrix<N> {
    type Stop = Infallible;

    fn product(&self, rhs: &Self) -> Result<Self, Infallible> {
        Ok(DoubleDoubleMatrix::product(self, rhs))
    }

    fn add_product(&mut self, lhs: &Self, rhs: &Self) -> Result<(), Infallible> {
        let product = DoubleDoubleMatrix::product(lhs, rhs);
        *self = DoubleDoubleMatrix::combination(0.0, &[(1.0, self), (1.0, &product)]);
        Ok(())
    }

    fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self {
        DoubleDoubleMatrix::combination(identity, terms)
    }

    fn pade_quotient(even: Self, odd: Self) -> Result<Self, Infallible> {
        let quotient = even.difference(&odd).solve(&odd);
        Ok(DoubleDoubleMatrix::combination(1.0, &[(2.0, &quotient)]))
    }
}

impl<const N: usize> ExpmMatrix for SMatrix<f64, N, N> {
    #[inline(always)]
    fn from_ref(a: MatRef<'_, f64>) -> Self {
        from_faer_in(Const::<N>, a)
    }

    fn order(&self) -> usize {
        N
    }

    fn get(&self, i: usize, j: usize) -> f64 {
        self[(i, j)]
    }

    fn is_upper_triangular(&self) -> bool {
        small_matrix::is_upper_triangular(self)
    }

    fn is_lower_triangular(&self) -> bool {
        small_matrix::is_lower_triangular(self)
    }

    fn transpose(&self) -> Self {
        SMatrix::transpose(self)
    }

    fn set(&mut self, i: usize, j: usize, value: f64) {
        self[(i, j)] = value;
    }

    fn one_norm(&self) -> f64 {
        small_matrix::one_norm(self)
    }

    #[inline(always)]
    fn max_abs(&self) -> f64 {
        small_matrix::max_abs(self)
    }

    fn is_finite(&self) -> bool {
        small_matrix::is_finite(self)
    }

    fn estimate_product_norm(factors: &[&Self]) -> f64 {
        // Small orders always use exact norms; the product is cheap.
        let (first, rest) = factors.split_first().expect("at least one factor");
        rest.iter()
            .fold(**first, |product, factor| {
                small_matrix::product(&product, factor)
            })
            .one_norm()
    }

    fn absolute_power_norm(&self, scale: f64, p: usize) -> f64 {
        small_matrix::absolute_power_norm(self, scale, p)
    }

    #[inline(always)]
    fn write_to(&self, mut out: MatMut<'_, f64>, transpose: bool) {
        for (j, column) in small_matrix::columns(self).iter().enumerate() {
            for (i, &value) in column.iter().enumerate() {
                if transpose {
                    out[(j, i)] = value;
                } else {
                    out[(i, j)] = value;
                }
            }
        }
    }

    fn double_double_exponential(
        &self,
        c: f64,
        approximant: usize,
        squarings: u32,
    ) -> Option<Self> {
        // Powers of B = cA, formed in double-double from the exactly scaled matrix.
        let b = DoubleDoubleMatrix::scaled(self, c);
        let b2 = b.product(&b);
        let degree = APPROXIMANTS[approximant].degree;
        let b4 = (degree >= 5).then(|| b2.product(&b2));
        let b6 = (degree >= 7).then(|| b4.as_ref().expect("degree >= 5").product(&b2));
        let b8 = (degree == 9).then(|| {
            let b4 = b4.as_ref().expect("degree >= 5");
            b4.product(b4)
        });
        let Ok(x) = pade_approximant(approximant, &b, &[&b2], [&b4, &b6, &b8]);
        let Ok(x) = square_repeatedly(x, squarings, |_, _| {});
        let x = x.round();
        x.as_slice().iter().all(|v| v.is_finite()).then_some(x)
    }
}

// ----- stack matrices in one compiled exponential ----------------------------------------------

/// A stack matrix whose arithmetic calls the small-order kernels of one instruction set (`FMA`:
/// the AVX2 + FMA variant) directly instead of through their run-time dispatch, so that a whole
/// exponential, from the degree selection to the written result, compiles into one function
/// ([`small_exponential`]) with one dispatch, its kernels inlined. Each operation is the kernel
/// that the `SMatrix` implementation dispatches to, on the same operands in the same order, so
/// the results are equal bit for bit; everything else is delegated to that implementation.
#[derive(Clone, Copy)]
struct Inlined<const N: usize, const FMA: bool>(SMatrix<f64, N, N>);

impl<const N: usize, const FMA: bool> StackColumns<N> for Inlined<N, FMA> {
    #[inline(always)]
    fn stack_columns(&self) -> &Columns<N> {
        small_matrix::columns(&self.0)
    }
}

impl<const N: usize, const FMA: bool> PadeArithmetic for Inlined<N, FMA> {
    type Stop = Infallible;

    #[inline(always)]
    fn product(&self, rhs: &Self) -> Result<Self, Infallible> {
        let mut out = Self(SMatrix::zeros());
        let Ok(()) = out.add_product(self, rhs);
        Ok(out)
    }

    #[inline(always)]
    fn add_product(&mut self, lhs: &Self, rhs: &Self) -> Result<(), Infallible> {
        small_matrix::add_product_kernel::<N, FMA>(
            small_matrix::columns(&lhs.0),
            small_matrix::columns(&rhs.0),
            small_matrix::columns_mut(&mut self.0),
        );
        Ok(())
    }

    #[inline(always)]
    fn combination(identity: f64, terms: &[(f64, &Self)]) -> Self {
        Self(small_matrix::from_columns(
            small_matrix::combination_kernel::<N, FMA>(identity, terms),
        ))
    }

    #[inline(always)]
    fn pade_quotient(even: Self, odd: Self) -> Result<Self, Infallible> {
        let denominator = Self::combination(0.0, &[(1.0, &even), (-1.0, &odd)]);
        // The matrix factored by rows and the N right-hand sides solved together as rows (the
        // operations of the column-wise factorisation and solve that SMatrix uses, in the same
        // order on each entry, as vector instructions).
        let mut factors = CacheAligned(small_matrix::transposed(small_matrix::columns(
            &denominator.0,
        )));
        let mut pivots = [0; N];
        small_matrix::lu_rows_kernel::<N, FMA>(&mut factors.0, &mut pivots);
        let mut rows = CacheAligned(small_matrix::transposed(small_matrix::columns(&odd.0)));
        small_matrix::lu_rows_solve_rows_kernel::<N, FMA>(&factors.0, &pivots, &mut rows.0);
        let quotient = Self(small_matrix::from_columns(small_matrix::transposed(
            &rows.0,
        )));
        Ok(Self::combination(1.0, &[(2.0, &quotient)]))
    }
}

impl<const N: usize, const FMA: bool> ExpmMatrix for Inlined<N, FMA> {
    /// A row-major A (the layout of numpy's arrays) is copied a row at a time: its rows are
    /// the columns of the storage of A^T.
    #[inline(always)]
    fn from_ref(a: MatRef<'_, f64>) -> Self {
        match a.try_as_row_major() {
            Some(by_rows) => {
                let mut rows = [[0.0; N]; N];
                for (i, row) in rows.iter_mut().enumerate() {
                    row.copy_from_slice(by_rows.row(i).as_slice());
                }
                Self(small_matrix::from_columns(small_matrix::transposed(&rows)))
            }
            None => Self(<SMatrix<f64, N, N> as ExpmMatrix>::from_ref(a)),
        }
    }

    #[inline(always)]
    fn order(&self) -> usize {
        N
    }

    #[inline(always)]
    fn get(&self, i: usize, j: usize) -> f64 {
        self.0[(i, j)]
    }

    #[inline(always)]
    fn is_upper_triangular(&self) -> bool {
        small_matrix::is_upper_triangular(&self.0)
    }

    #[inline(always)]
    fn is_lower_triangular(&self) -> bool {
        small_matrix::is_lower_triangular(&self.0)
    }

    #[inline(always)]
    fn transpose(&self) -> Self {
        Self(self.0.transpose())
    }

    #[inline(always)]
    fn set(&mut self, i: usize, j: usize, value: f64) {
        self.0[(i, j)] = value;
    }

    #[inline(always)]
    fn one_norm(&self) -> f64 {
        small_matrix::one_norm(&self.0)
    }

    #[inline(always)]
    fn max_abs(&self) -> f64 {
        small_matrix::max_abs(&self.0)
    }

    #[inline(always)]
    fn is_finite(&self) -> bool {
        small_matrix::is_finite(&self.0)
    }

    #[inline(always)]
    fn estimate_product_norm(factors: &[&Self]) -> f64 {
        let (first, rest) = factors.split_first().expect("at least one factor");
        let mut product = **first;
        for factor in rest {
            let Ok(next) = product.product(factor);
            product = next;
        }
        product.one_norm()
    }

    #[inline(always)]
    fn absolute_power_norm(&self, scale: f64, p: usize) -> f64 {
        small_matrix::absolute_power_norm_kernel::<N, FMA>(small_matrix::columns(&self.0), scale, p)
    }

    /// Into a row-major `out`, a row at a time: the rows of the matrix are the columns of its
    /// transposed storage, and those of its transpose its columns.
    #[inline(always)]
    fn write_to(&self, mut out: MatMut<'_, f64>, transpose: bool) {
        match out.as_mut().try_as_row_major_mut() {
            Some(mut by_rows) => {
                let rows = if transpose {
                    *small_matrix::columns(&self.0)
                } else {
                    small_matrix::transposed(small_matrix::columns(&self.0))
                };
                for (i, row) in rows.iter().enumerate() {
                    by_rows
                        .as_mut()
                        .row_mut(i)
                        .as_slice_mut()
                        .copy_from_slice(row);
                }
            }
            None => self.0.write_to(out, transpose),
        }
    }

    fn double_double_exponential(
        &self,
        c: f64,
        approximant: usize,
        squarings: u32,
    ) -> Option<Self> {
        self.0
            .double_double_exponential(c, approximant, squarings)
            .map(Self)
    }
}

/// e^A for A of order N (2 to [`SMALL_MAX_ORDER`]) on [`Inlined`] stack matrices: the plan of
/// [`single_exponential`] compiled as one function for each instruction set.
#[inline(always)]
fn small_exponential_kernel<const N: usize, const FMA: bool>(
    a: MatRef<'_, f64>,
    out: MatMut<'_, f64>,
) -> bool {
    let Ok(finite) = single_exponential::<Inlined<N, FMA>>(a, out);
    finite
}

fma_dispatch!(fn small_exponential<const N: usize>(a: MatRef<'_, f64>, out: MatMut<'_, f64>) -> bool => small_exponential_kernel);

/// e^{A_k} for the N x N matrices of a row-major stack (`out` of the same length) on
/// [`Inlined`] stack matrices, the loop compiled with them ([`small_exponentials`], one
/// dispatch for the whole stack). Stops after the first matrix whose result is not certainly
/// finite and returns its index; None when every result is.
#[inline(always)]
fn small_exponentials_kernel<const N: usize, const FMA: bool>(
    stack: &[f64],
    out: &mut [f64],
) -> Option<usize> {
    let matrices = stack.chunks_exact(N * N).zip(out.chunks_exact_mut(N * N));
    for (index, (a, x)) in matrices.enumerate() {
        let Ok(finite) = single_exponential::<Inlined<N, FMA>>(
            MatRef::from_row_major_slice(a, N, N),
            MatMut::from_row_major_slice_mut(x, N, N),
        );
        if !finite {
            return Some(index);
        }
    }
    None
}

fma_dispatch!(fn small_exponentials<const N: usize>(stack: &[f64], out: &mut [f64]) -> Option<usize> => small_exponentials_kernel);

/// The `index`-th n x n matrix of a row-major stack.
fn stack_member(data: &[f64], index: usize, n: usize) -> MatRef<'_, f64> {
    MatRef::from_row_major_slice(&data[index * n * n..(index + 1) * n * n], n, n)
}

/// Writes e^{A_k} for every n x n matrix A_k of a row-major stack into `out` (of the same
/// length), for matrices already known to be square and finite (as [`expm_into_validated`]
/// each). An error carries the index of its matrix in the stack.
pub(crate) fn expm_stack_into_validated(
    n: usize,
    stack: &[f64],
    out: &mut [f64],
) -> Result<(), (usize, Error)> {
    let size = n * n;
    if size == 0 {
        return Ok(());
    }
    let count = stack.len() / size;
    let mut start = 0;
    while start < count {
        let (rest, rest_out) = (&stack[start * size..], &mut out[start * size..]);
        let stopped = with_order!(
            n,
            [2, 3, 4, 5, 6, 7, 8],
            N => small_exponentials::<N>(rest, rest_out),
            _ => {
                for (index, x) in rest_out.chunks_exact_mut(size).enumerate() {
                    expm_into_validated(
                        stack_member(rest, index, n),
                        MatMut::from_row_major_slice_mut(x, n, n),
                    )
                    .map_err(|e| (start + index, e))?;
                }
                None
            }
        );
        let Some(offset) = stopped else {
            return Ok(());
        };
        let index = start + offset;
        check_computed_exponential(
            stack_member(stack, index, n),
            1.0,
            stack_member(out, index, n),
        )
        .map_err(|e| (index, e))?;
        start = index + 1;
    }
    Ok(())
}

// ----- public functions ---------------------------------------------------------------------

/// Runs `$body` with `$m` bound to the matrix type for order `$n`: a stack matrix for orders
/// 2 to [`SMALL_MAX_ORDER`], a pooled faer matrix otherwise.
macro_rules! with_matrix_type {
    ($n:expr, $m:ident => $body:expr) => {
        with_order!(
            $n,
            [2, 3, 4, 5, 6, 7, 8],
            N => {
                type $m = SMatrix<f64, N, N>;
                $body
            },
            _ => {
                type $m = Scratch;
                $body
            }
        )
    };
}

/// Checks that `a` is a square matrix of finite entries.
fn check_square_finite(a: MatRef<'_, f64>, arg: &'static str) -> Result<(), Error> {
    check_square(a, arg)?;
    check_finite(a, arg)
}

/// Writes e^A into `out`; true when every entry is certainly finite (see
/// [`ExponentialPlan::exponential_into`]).
#[inline(always)]
fn single_exponential<M: ExpmMatrix>(
    a: MatRef<'_, f64>,
    out: MatMut<'_, f64>,
) -> Result<bool, M::Stop> {
    let mut plan = ExponentialPlan::<M>::new(a)?;
    let choice = plan.choose(1.0)?;
    plan.prepare(choice)?;
    plan.exponential_into(1.0, choice, out)
}

/// Writes e^A into `out` (n x n), for a square A of finite entries.
pub fn expm_into(a: MatRef<'_, f64>, out: MatMut<'_, f64>) -> Result<(), Error> {
    check_square_finite(a, "A")?;
    check_output_len(out.nrows() * out.ncols(), a.nrows() * a.nrows())?;
    check_output_len(out.nrows(), a.nrows())?;
    expm_into_validated(a, out)
}

/// [`expm_into`] for an A already known to be square and finite, with `out` of its order.
pub(crate) fn expm_into_validated(
    a: MatRef<'_, f64>,
    mut out: MatMut<'_, f64>,
) -> Result<(), Error> {
    let finite = match a.nrows() {
        0 => true,
        1 => {
            out[(0, 0)] = a[(0, 0)].exp();
            out[(0, 0)].is_finite()
        }
        n => with_order!(
            n,
            [2, 3, 4, 5, 6, 7, 8],
            N => small_exponential::<N>(a, out.as_mut()),
            _ => single_exponential::<Scratch>(a, out.as_mut())?
        ),
    };
    if finite {
        return Ok(());
    }
    check_computed_exponential(a, 1.0, out.as_ref())
}

/// The matrix exponential e^A (6.19) of a square matrix of finite entries.
///
/// A result that overflows double precision has infinite (or NaN) entries; the caller decides
/// how to report it. Infinite or NaN entries where the exact value is finite (a matrix of
/// norm beyond 2^53, whose squarings amplify rounding until it overflows) are
/// [`Error::IllConditioned`].
///
/// ```
/// use faer::mat;
/// let a = mat![[0.0, 1.0], [-2.0, -3.0]];
/// let phi = aerocontrol::linalg::expm::expm(a.as_ref()).unwrap();
/// // e^A = [[2e^-1 - e^-2, e^-1 - e^-2], [-2e^-1 + 2e^-2, -e^-1 + 2e^-2]]
/// let (e1, e2) = ((-1.0f64).exp(), (-2.0f64).exp());
/// assert!((phi[(0, 0)] - (2.0 * e1 - e2)).abs() < 1e-15);
/// assert!((phi[(1, 1)] - (2.0 * e2 - e1)).abs() < 1e-15);
/// ```
pub fn expm(a: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    let n = a.nrows();
    let mut out = Mat::zeros(n, n);
    expm_into(a, out.as_mut())?;
    Ok(out)
}

/// The degree m and number of squarings s that [`expm`] uses for A: m in {3, 5, 7, 9, 13} for
/// the Padé approximants, 15 for the Taylor approximant 15+ (for a 1 x 1 or empty A, which
/// need no approximant, (0, 0)).
pub fn approximant_choice(a: MatRef<'_, f64>) -> Result<(usize, u32), Error> {
    check_square_finite(a, "A")?;
    if a.nrows() <= 1 {
        return Ok((0, 0));
    }
    let choice = with_matrix_type!(a.nrows(), M => chosen_approximant::<M>(a))?;
    Ok((choice.degree(), choice.squarings))
}

/// The choice of [`ExponentialPlan::choose`] for e^A.
fn chosen_approximant<M: ExpmMatrix>(a: MatRef<'_, f64>) -> Result<ApproximantChoice, Error> {
    let mut plan = ExponentialPlan::<M>::new(a).map_err(Into::into)?;
    plan.choose(1.0).map_err(Into::into)
}

fn transition_matrices_with<M: ExpmMatrix>(
    a: MatRef<'_, f64>,
    times: &[f64],
    out: &mut [f64],
) -> Result<(), Error> {
    let n = a.nrows();
    let mut plan = ExponentialPlan::<M>::new(a).map_err(Into::into)?;
    let choices = times
        .iter()
        .map(|&t| plan.choose(t))
        .collect::<Result<Vec<ApproximantChoice>, M::Stop>>()
        .map_err(Into::into)?;
    for &choice in &choices {
        plan.prepare(choice).map_err(Into::into)?;
    }
    let plan = &plan;
    let context = ParallelContext::capture(n);
    let evaluate = |((&t, &choice), chunk): ((&f64, &ApproximantChoice), &mut [f64])| {
        context.run(|| {
            plan.exponential_into(t, choice, MatMut::from_row_major_slice_mut(chunk, n, n))
                .map_err(Into::into)?;
            check_computed_exponential(a, t, MatRef::from_row_major_slice(chunk, n, n))
        })
    };
    if n < PARALLEL_MIN_ORDER && times.len() > 1 {
        times
            .par_iter()
            .zip(&choices)
            .zip(out.par_chunks_mut(n * n))
            .try_for_each(evaluate)
    } else {
        times
            .iter()
            .zip(&choices)
            .zip(out.chunks_mut(n * n))
            .try_for_each(evaluate)
    }
}

/// Writes Φ(t_k) = e^{A t_k} for every time of `times` into `out`, a row-major stack of
/// len(times) n x n matrices (the layout of a C-ordered numpy array).
pub fn transition_matrices_into(
    a: MatRef<'_, f64>,
    times: &[f64],
    out: &mut [f64],
) -> Result<(), Error> {
    check_square_finite(a, "A")?;
    check_finite_values(times, "t")?;
    let n = a.nrows();
    check_output_len(out.len(), times.len() * n * n)?;
    match n {
        0 => {}
        1 => {
            for (value, &t) in out.iter_mut().zip(times) {
                *value = (t * a[(0, 0)]).exp();
            }
        }
        n => with_matrix_type!(n, M => transition_matrices_with::<M>(a, times, out))?,
    }
    Ok(())
}

/// The state transition matrices Φ(t_k) = e^{A t_k} (6.22) at every time of `times`.
///
/// The powers of A and their norms are computed once; each time then costs one Padé evaluation
/// and its squarings. Times may be negative (e^{-At} = (e^{At})^-1, (6.27)). Computed in
/// parallel over the times when the matrices are small.
pub fn transition_matrices(a: MatRef<'_, f64>, times: &[f64]) -> Result<Vec<Mat<f64>>, Error> {
    let n = a.nrows();
    let mut stack = vec![0.0; times.len() * n * n];
    transition_matrices_into(a, times, &mut stack)?;
    Ok(stack
        .chunks(n * n)
        .map(|chunk| MatRef::from_row_major_slice(chunk, n, n).to_owned())
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::matrix::FaerView;
    use faer::mat;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;

    fn random_matrix(n: usize, scale: f64, rng: &mut StdRng) -> Mat<f64> {
        Mat::from_fn(n, n, |_, _| scale * rng.sample::<f64, _>(StandardNormal))
    }

    fn relative_difference(x: &Mat<f64>, y: &Mat<f64>) -> f64 {
        (x - y).norm_l2() / y.norm_l2()
    }

    /// e^A by its Taylor series on A / 2^s, with s chosen so the series converges fast, then
    /// squared: an independent (if slower and less careful) reference for A of moderate norm.
    fn taylor_reference(a: &Mat<f64>) -> Mat<f64> {
        let n = a.nrows();
        let s = (one_norm(a.as_ref()).log2().ceil() + 4.0).max(0.0) as i32;
        let scaled = a * faer::Scale(2f64.powi(-s));
        let mut term = Mat::<f64>::identity(n, n);
        let mut sum = Mat::<f64>::identity(n, n);
        for k in 1..30 {
            term = &term * &scaled * faer::Scale(1.0 / k as f64);
            sum += &term;
        }
        for _ in 0..s {
            sum = &sum * &sum;
        }
        sum
    }

    /// e^A for symmetric A = Q diag(λ) Q^T as Q diag(e^λ) Q^T: exact up to rounding, for any norm.
    fn symmetric_case(eigenvalues: &[f64], seed: u64) -> (Mat<f64>, Mat<f64>) {
        let n = eigenvalues.len();
        let mut rng = StdRng::seed_from_u64(seed);
        let v = random_matrix(n, 1.0, &mut rng);
        // Householder reflector Q = I - 2 w w^T / (w^T w) from the first column of v.
        let w = v.col(0).to_owned();
        let q = Mat::<f64>::identity(n, n)
            - &w * w.transpose() * faer::Scale(2.0 / w.squared_norm_l2());
        let d = Mat::from_fn(n, n, |i, j| if i == j { eigenvalues[i] } else { 0.0 });
        let e = Mat::from_fn(n, n, |i, j| if i == j { eigenvalues[i].exp() } else { 0.0 });
        (&q * &d * q.transpose(), &q * &e * q.transpose())
    }

    #[test]
    fn pade_coefficients_follow_the_factorial_formula() {
        // b_j ∝ (2m - j)! m! / ((2m)! j! (m - j)!), normalised so that b_m = 1.
        let factorial = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
        for approximant in &APPROXIMANTS {
            let m = approximant.degree;
            let formula = |j: usize| {
                factorial(2 * m - j) * factorial(m)
                    / (factorial(2 * m) * factorial(j) * factorial(m - j))
            };
            for (j, &b) in approximant.coefficients.iter().enumerate() {
                let expected = formula(j) / formula(m);
                assert!((b - expected).abs() <= 1e-15 * expected, "m={m} j={j}");
            }
        }
    }

    #[test]
    fn error_coefficients_over_u_are_their_powers_of_two_bit_for_bit() {
        for approximant in &APPROXIMANTS {
            let expected = (approximant.log2_error_coefficient - UNIT_ROUNDOFF_LOG2).exp2();
            assert_eq!(
                approximant.error_coefficient_over_u.to_bits(),
                expected.to_bits()
            );
        }
        for k in (0..1100).chain([2200, u32::MAX]) {
            assert_eq!(
                inverse_power_of_two(k).to_bits(),
                (-(k as f64)).exp2().to_bits(),
                "{k}"
            );
        }
    }

    #[test]
    fn norms_without_extra_squarings_follow_from_the_error_coefficients() {
        // (u / |c_{2m+1}|)^(1/(2m)), and close to θ_m: θ_m is where the whole backward error
        // series, not only its leading term, reaches u.
        for approximant in &APPROXIMANTS {
            let m = approximant.degree as f64;
            let expected =
                ((UNIT_ROUNDOFF_LOG2 - approximant.log2_error_coefficient) / (2.0 * m)).exp2();
            assert!((approximant.norm_without_extra_squarings / expected - 1.0).abs() < 1e-14);
            if approximant.degree < 13 {
                assert!(
                    (approximant.norm_without_extra_squarings / approximant.theta - 1.0).abs()
                        < 0.01
                );
            }
        }
    }

    #[test]
    fn leading_error_coefficients_match_their_definition() {
        // log2((m!)^2 / ((2m)! (2m+1)!)) summed term by term.
        let log2_factorial = |k: usize| (1..=k).map(|i| (i as f64).log2()).sum::<f64>();
        for approximant in &APPROXIMANTS {
            let m = approximant.degree;
            let expected =
                2.0 * log2_factorial(m) - log2_factorial(2 * m) - log2_factorial(2 * m + 1);
            assert!(
                (approximant.log2_error_coefficient - expected).abs() < 1e-12,
                "m={m}"
            );
        }
        // The familiar m = 3 value: 1/|c_7| = 6! 7! / (3!)^2 = 100800.
        assert!((APPROXIMANTS[M3].log2_error_coefficient + 100800f64.log2()).abs() < 1e-12);
    }

    #[test]
    fn empty_and_scalar_matrices() {
        assert_eq!(expm(Mat::<f64>::zeros(0, 0).as_ref()).unwrap().nrows(), 0);
        let e = expm(mat![[2.5]].as_ref()).unwrap();
        assert_eq!(e[(0, 0)], 2.5f64.exp());
        let phi = transition_matrices(mat![[-0.5]].as_ref(), &[0.0, 2.0]).unwrap();
        assert_eq!((phi[0][(0, 0)], phi[1][(0, 0)]), (1.0, (-1.0f64).exp()));
    }

    #[test]
    fn rejects_non_square_and_non_finite() {
        assert_eq!(
            expm(Mat::<f64>::zeros(2, 3).as_ref()),
            Err(Error::NotSquare {
                arg: "A",
                rows: 2,
                cols: 3
            })
        );
        let a = mat![[1.0, f64::NAN], [0.0, 1.0]];
        assert!(matches!(
            expm(a.as_ref()),
            Err(Error::NonFinite { arg: "A", .. })
        ));
        assert!(matches!(
            transition_matrices(mat![[1.0]].as_ref(), &[0.0, f64::NAN]),
            Err(Error::NonFinite { arg: "t", .. })
        ));
    }

    #[test]
    fn closed_form_two_by_two() {
        // A = [[0, 1], [-2, -3]] (chapter (6.75)) has eigenvalues -1 and -2. At t = 25 the
        // exponential's condition number is 275: double evaluation loses digits, double-double
        // does not.
        let a = mat![[0.0, 1.0], [-2.0, -3.0]];
        for t in [0.0, 0.01, 0.7, 3.0, 25.0, -1.5] {
            let phi = &transition_matrices(a.as_ref(), &[t]).unwrap()[0];
            let (e1, e2) = ((-t).exp(), (-2.0 * t).exp());
            let expected = mat![
                [2.0 * e1 - e2, e1 - e2],
                [-2.0 * e1 + 2.0 * e2, -e1 + 2.0 * e2]
            ];
            let err = relative_difference(phi, &expected);
            // Double evaluation (fewer than two squarings) is within ten times the condition
            // number (at most 18 here) times u; double-double is correct to the last bits.
            let (_, squarings) = approximant_choice((&a * faer::Scale(t)).as_ref()).unwrap();
            let tolerance = if squarings >= DOUBLE_DOUBLE_MIN_SQUARINGS {
                4e-16
            } else {
                1e-14
            };
            assert!(err < tolerance, "t={t}: {err}");
        }
    }

    #[test]
    fn every_degree_is_exercised_and_accurate() {
        // Scaling one symmetric matrix walks the selection through every degree and many
        // squarings (Padé 3 to 13 at order 6, Taylor 15+ and Padé 3 and 13 at order 12); its
        // exponential is known from the eigendecomposition.
        let eigenvalues = [-1.0, -0.5, 0.1, 0.4, 0.9, 1.0];
        let mut degrees = std::collections::BTreeSet::new();
        for (order, matrix_type) in [(6, "small"), (12, "faer")] {
            for scale in [1e-3, 1e-2, 0.1, 0.2, 0.8, 1.8, 4.0, 30.0, 200.0] {
                let lambda: Vec<f64> = (0..order)
                    .map(|i| scale * eigenvalues[i % 6] * (1.0 + 0.01 * i as f64))
                    .collect();
                let (a, expected) = symmetric_case(&lambda, 3);
                degrees.insert(approximant_choice(a.as_ref()).unwrap().0);
                let got = expm(a.as_ref()).unwrap();
                let err = relative_difference(&got, &expected);
                assert!(
                    err < 1e-14 * scale.max(10.0),
                    "{matrix_type} scale {scale}: {err}"
                );
            }
        }
        assert_eq!(
            degrees.into_iter().collect::<Vec<_>>(),
            vec![3, 5, 7, 9, 13, 15]
        );
    }

    #[test]
    fn several_orders_against_the_taylor_reference() {
        let mut rng = StdRng::seed_from_u64(5);
        for n in [2, 3, 4, 5, 7, 8, 9, 16, 33, 64, 100] {
            let a = random_matrix(n, 2.0 / (n as f64).sqrt(), &mut rng);
            let got = expm(a.as_ref()).unwrap();
            let err = relative_difference(&got, &taylor_reference(&a));
            assert!(err < 1e-13, "n={n}: {err}");
        }
    }

    #[test]
    fn small_and_faer_engines_agree() {
        // The same algorithm on stack matrices and on faer matrices (forced by calling the
        // generic path directly) differs only by rounding.
        let mut rng = StdRng::seed_from_u64(13);
        for scale in [0.05, 1.0, 3.0] {
            let a = random_matrix(5, scale, &mut rng);
            let (mut small, mut general) = (Mat::zeros(5, 5), Mat::zeros(5, 5));
            let Ok(_) = single_exponential::<SMatrix<f64, 5, 5>>(a.as_ref(), small.as_mut());
            single_exponential::<Scratch>(a.as_ref(), general.as_mut()).unwrap();
            assert!(
                relative_difference(&small, &general) < 1e-14,
                "scale {scale}"
            );
        }
    }

    #[test]
    fn the_compiled_small_exponential_equals_the_dispatched_plan_bit_for_bit() {
        // `small_exponential` (the plan on `Inlined`, one dispatch) against the same plan on
        // SMatrix (a dispatch per kernel): general matrices through every degree, none to many
        // squarings (double-double from two), triangular ones, and entries small and large
        // enough for the time scaling and the pre-scaling.
        let mut rng = StdRng::seed_from_u64(31);
        let mut cases = 0;
        for n in 2..=SMALL_MAX_ORDER {
            for scale in [1e-30, 1e-3, 0.05, 0.4, 1.0, 3.0, 20.0, 300.0, 1e25] {
                for structure in 0..3 {
                    let mut a = random_matrix(n, scale, &mut rng);
                    for j in 0..n {
                        for i in 0..n {
                            if (structure == 1 && i > j) || (structure == 2 && i < j) {
                                a[(i, j)] = 0.0;
                            }
                        }
                    }
                    let (mut compiled, mut dispatched) = (Mat::zeros(n, n), Mat::zeros(n, n));
                    let (finite_compiled, finite_dispatched) = with_order!(
                        n,
                        [2, 3, 4, 5, 6, 7, 8],
                        N => {
                            let Ok(finite_dispatched) = single_exponential::<SMatrix<f64, N, N>>(
                                a.as_ref(),
                                dispatched.as_mut(),
                            );
                            (
                                small_exponential::<N>(a.as_ref(), compiled.as_mut()),
                                finite_dispatched,
                            )
                        },
                        _ => unreachable!("orders up to SMALL_MAX_ORDER")
                    );
                    assert_eq!(finite_compiled, finite_dispatched);
                    for j in 0..n {
                        for i in 0..n {
                            assert_eq!(
                                compiled[(i, j)].to_bits(),
                                dispatched[(i, j)].to_bits(),
                                "n = {n}, scale {scale:e}, structure {structure}"
                            );
                        }
                    }
                    cases += 1;
                }
            }
        }
        assert_eq!(cases, 7 * 9 * 3);
    }

    /// The register-blocked combination of pooled matrices gives the bits of one pass over the
    /// output per term (c_1 m_1, then += c_k m_k, then the identity on the diagonal), for
    /// orders with and without a partial chunk and 1 to 6 terms; the finiteness scan finds an
    /// inf or NaN anywhere and only those (not f64::MAX, subnormals or -0).
    #[test]
    fn pooled_combinations_and_finiteness_scan() {
        let mut rng = StdRng::seed_from_u64(33);
        for n in [9, 32, 33, 64, 70] {
            let matrices: Vec<Scratch> = (0..6)
                .map(|_| Scratch::from_ref(random_matrix(n, 1.0, &mut rng).as_ref()))
                .collect();
            for count in 1..=6 {
                let terms: Vec<(f64, &Scratch)> = matrices[..count]
                    .iter()
                    .map(|m| (rng.random_range(-3.0..3.0), m))
                    .collect();
                let identity = if count % 2 == 0 { 0.0 } else { 1.5 };
                let combined = Scratch::combination(identity, &terms);
                let mut expected = Mat::<f64>::zeros(n, n);
                for j in 0..n {
                    let column = expected.col_as_slice_mut(j);
                    for (value, &x) in column.iter_mut().zip(terms[0].1.col_as_slice(j)) {
                        *value = terms[0].0 * x;
                    }
                    for &(coefficient, matrix) in &terms[1..] {
                        add_scaled(column, coefficient, matrix.col_as_slice(j));
                    }
                    column[j] += identity;
                }
                for j in 0..n {
                    for i in 0..n {
                        assert_eq!(
                            combined[(i, j)].to_bits(),
                            expected[(i, j)].to_bits(),
                            "n = {n}, {count} terms"
                        );
                    }
                }
            }
            let mut m = Scratch::from_ref(Mat::<f64>::zeros(n, n).as_ref());
            m[(1, 0)] = -0.0;
            m[(n - 1, n - 1)] = f64::MAX;
            m[(2, n / 2)] = -f64::MAX;
            m[(0, 1)] = 4.9e-324;
            assert!(ExpmMatrix::is_finite(&m));
            for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -f64::NAN] {
                for (i, j) in [(0, 0), (n - 1, 3), (n / 2, n - 1)] {
                    let saved = m[(i, j)];
                    m[(i, j)] = bad;
                    assert!(!ExpmMatrix::is_finite(&m), "n = {n}, {bad} at ({i}, {j})");
                    m[(i, j)] = saved;
                }
            }
        }
    }

    #[test]
    fn a_stack_equals_its_members_bit_for_bit_and_names_a_refused_one() {
        let mut rng = StdRng::seed_from_u64(41);
        for n in [2, 4, 8, 9] {
            let scales = [0.3, 2.0, 800.0, 1e-30, 1.0];
            let mut stack = Vec::new();
            for scale in scales {
                let mut a = random_matrix(n, if scale == 800.0 { 1.0 } else { scale }, &mut rng);
                if scale == 800.0 {
                    // e^A = e^800 e^(A - 800 I) overflows.
                    for i in 0..n {
                        a[(i, i)] += scale;
                    }
                }
                stack.extend((0..n * n).map(|k| a[(k / n, k % n)]));
            }
            let mut out = vec![0.0; stack.len()];
            expm_stack_into_validated(n, &stack, &mut out).unwrap();
            let mut overflowed = 0;
            for k in 0..scales.len() {
                let mut expected = Mat::zeros(n, n);
                expm_into_validated(stack_member(&stack, k, n), expected.as_mut()).unwrap();
                let got = stack_member(&out, k, n);
                overflowed += usize::from(!got[(0, 0)].is_finite());
                for j in 0..n {
                    for i in 0..n {
                        assert_eq!(got[(i, j)].to_bits(), expected[(i, j)].to_bits());
                    }
                }
            }
            // The results after an overflowed one are computed too.
            assert!(overflowed >= 1, "n = {n}");
        }
        // The rotation by 1e50 rad, refused, is named by its index.
        let mut stack = vec![
            0.0, 1.0, -1.0, 0.0, 0.0, 1e50, -1e50, 0.0, 1.0, 0.0, 0.0, 1.0,
        ];
        let mut out = vec![0.0; stack.len()];
        let Err((index, error)) = expm_stack_into_validated(2, &stack, &mut out) else {
            panic!("the rotation by 1e50 rad was not refused");
        };
        assert_eq!(index, 1);
        assert!(matches!(error, Error::IllConditioned { .. }));
        (stack[5], stack[6]) = (1.0, -1.0);
        expm_stack_into_validated(2, &stack, &mut out).unwrap();
        assert!((out[8] - 1f64.exp()).abs() < 1e-15);
    }

    #[test]
    fn double_double_evaluation_beats_double_on_a_hump() {
        // Moler & Van Loan's [[-49, 24], [-64, 31]]: eigenvalues -17 and -1, a large hump.
        // Closed form: e^A = U diag(e^-17, e^-1) V, U = [[3, 1], [4, 2]], V = [[1, -1/2], [-2, 3/2]].
        let a = mat![[-49.0, 24.0], [-64.0, 31.0]];
        let (e17, e1) = ((-17.0f64).exp(), (-1.0f64).exp());
        let expected = mat![
            [3.0 * e17 - 2.0 * e1, -1.5 * e17 + 1.5 * e1],
            [4.0 * e17 - 4.0 * e1, -2.0 * e17 + 3.0 * e1]
        ];
        let Ok(mut plan) = ExponentialPlan::<SMatrix<f64, 2, 2>>::new(a.as_ref());
        let Ok(choice) = plan.choose(1.0);
        assert!(choice.squarings >= DOUBLE_DOUBLE_MIN_SQUARINGS);
        let Ok(()) = plan.prepare(choice);
        let mut accurate = Mat::zeros(2, 2);
        let Ok(_) = plan.exponential_into(1.0, choice, accurate.as_mut());
        let c = (-(choice.squarings as f64)).exp2();
        let Ok(double) = plan.double_exponential(1.0, c, choice);
        let double = double.to_faer();
        let (err_dd, err_double) = (
            relative_difference(&accurate, &expected),
            relative_difference(&double, &expected),
        );
        assert!(err_dd < 2e-16, "double-double {err_dd}");
        assert!(err_double > 4.0 * err_dd, "double {err_double} vs {err_dd}");
    }

    #[test]
    fn exact_and_estimated_norms_choose_alike() {
        // Above EXACT_NORM_MAX_ORDER the norms of A^8, A^10 are estimated; the result must not
        // lose accuracy against the exact-norm choice.
        let mut rng = StdRng::seed_from_u64(9);
        let n = EXACT_NORM_MAX_ORDER + 20;
        for scale in [0.5, 3.0, 40.0] {
            let a = random_matrix(n, scale / (n as f64).sqrt(), &mut rng);
            let mut estimated = ExponentialPlan::<Scratch>::new(a.as_ref()).unwrap();
            let mut exact = ExponentialPlan::<Scratch>::new(a.as_ref()).unwrap();
            exact.exact_norms = true;
            let (ce, cx) = (estimated.choose(1.0).unwrap(), exact.choose(1.0).unwrap());
            assert_eq!(ce.degree(), cx.degree());
            assert!(ce.squarings.abs_diff(cx.squarings) <= 1, "{ce:?} vs {cx:?}");
            estimated.prepare(ce).unwrap();
            exact.prepare(cx).unwrap();
            let (mut x1, mut x2) = (Mat::zeros(n, n), Mat::zeros(n, n));
            estimated.exponential_into(1.0, ce, x1.as_mut()).unwrap();
            exact.exponential_into(1.0, cx, x2.as_mut()).unwrap();
            assert!(relative_difference(&x1, &x2) < 1e-12);
        }
    }

    #[test]
    fn norm_bounds_choose_as_the_exact_norms_and_skip_unneeded_powers() {
        // The Padé degree tests try the submultiplicative bound of ||A^k|| before forming A^k:
        // the choice must be the one from all exact norms (formed and cached beforehand, which
        // makes every bound the norm itself), for general, non-normal and graded matrices over
        // norms 1e-3..1e3 and several times, and a degree-7 choice with d4 <= θ7 (the bound
        // ||A^8|| <= ||A^4||^2 decides) must not form A^8.
        let mut rng = StdRng::seed_from_u64(26);
        let (mut cases, mut skipped) = (0, 0);
        for case in 0..400 {
            let n = [9, 12, 16, 24, 40, 64][case % 6];
            let norm = 10f64.powf(rng.random_range(-3.0..3.0));
            let mut a = random_matrix(n, 1.0, &mut rng);
            match case % 3 {
                // Strictly upper triangular part amplified: non-normal, with humps.
                1 => {
                    for j in 0..n {
                        for i in 0..j {
                            a[(i, j)] *= 30.0;
                        }
                    }
                }
                // Graded rows and columns.
                2 => {
                    for j in 0..n {
                        for i in 0..n {
                            a[(i, j)] *= 2f64.powi(i as i32 - j as i32);
                        }
                    }
                }
                _ => {}
            }
            let a = &a * faer::Scale(norm / one_norm(a.as_ref()));
            for t in [1.0f64, -0.3, 2.5] {
                let mut lazy = ExponentialPlan::<Scratch>::new(a.as_ref()).unwrap();
                let mut exact = ExponentialPlan::<Scratch>::new(a.as_ref()).unwrap();
                exact.ensure_a6().unwrap();
                exact.ensure_a8().unwrap();
                for k in [4, 6, 8, 10] {
                    exact.power_norm(k).unwrap();
                }
                let (cl, cx) = (
                    lazy.choose_pade(t.abs()).unwrap(),
                    exact.choose_pade(t.abs()).unwrap(),
                );
                assert_eq!(cl, cx, "case {case} n={n} norm={norm:e} t={t}");
                cases += 1;
                if cl.degree() == 7 {
                    let d4 = lazy.power_norm(4).unwrap().powf(0.25) * t.abs();
                    if d4 <= APPROXIMANTS[M7].theta * (1.0 - 1e-12) {
                        assert!(lazy.a8.is_none(), "case {case}: A^8 formed for its norm");
                        skipped += 1;
                    }
                }
            }
        }
        assert_eq!(cases, 1200);
        assert!(
            skipped >= 20,
            "only {skipped} degree-7 choices decided by the bound"
        );
    }

    #[test]
    fn taylor_is_chosen_up_to_its_squarings_limit_and_agrees_with_pade() {
        // Above the small orders, Taylor 15+ is chosen when it needs at most
        // TAYLOR_MAX_SQUARINGS squarings, the Padé choice otherwise; on general, non-normal and
        // graded matrices of norms 1e-3..1e3 (and both signs of t), its e^{tA} agrees with the
        // Padé evaluation of the same plan. The bench's matrix (order 64, 1-norm 2) needs no
        // squaring.
        let mut rng = StdRng::seed_from_u64(15);
        let (mut taylor, mut pade) = (0, 0);
        for case in 0..300 {
            let n = [9, 16, 33, 64][case % 4];
            let norm = 10f64.powf(rng.random_range(-3.0..3.0));
            let mut a = random_matrix(n, 1.0, &mut rng);
            for j in 0..n {
                for i in 0..n {
                    match case % 3 {
                        1 if i < j => a[(i, j)] *= 30.0,
                        2 => a[(i, j)] *= 2f64.powi(i as i32 - j as i32),
                        _ => {}
                    }
                }
            }
            let a = &a * faer::Scale(norm / one_norm(a.as_ref()));
            let t = if case % 2 == 0 { 1.0 } else { -1.0 };
            let mut plan = ExponentialPlan::<Scratch>::new(a.as_ref()).unwrap();
            let choice = plan.choose(t).unwrap();
            let squarings = plan.taylor_squarings(1.0).unwrap();
            let pade_choice = plan.choose_pade(1.0).unwrap();
            if choice.degree() == 3 {
                // Admitted to Padé 3 by the norm bounds alone, before Taylor is considered.
                assert_eq!(pade_choice.degree(), 3);
                continue;
            }
            if squarings <= TAYLOR_MAX_SQUARINGS {
                assert_eq!((choice.degree(), choice.squarings), (15, squarings));
                taylor += 1;
            } else {
                assert_eq!(choice, pade_choice, "case {case}");
                pade += 1;
                continue;
            }
            plan.prepare(pade_choice).unwrap();
            let (mut x, mut y) = (Mat::zeros(n, n), Mat::zeros(n, n));
            plan.exponential_into(t, choice, x.as_mut()).unwrap();
            plan.exponential_into(t, pade_choice, y.as_mut()).unwrap();
            let difference = relative_difference(&x, &y);
            assert!(
                difference < 1e-14,
                "case {case} n={n} norm={norm:e}: {difference:e}"
            );
        }
        assert!(
            taylor >= 90 && pade >= 50,
            "{taylor} Taylor, {pade} Padé choices"
        );
        let mut rng = StdRng::seed_from_u64(64);
        let a = random_matrix(64, 1.0, &mut rng);
        let a = &a * faer::Scale(2.0 / one_norm(a.as_ref()));
        assert_eq!(approximant_choice(a.as_ref()).unwrap(), (15, 0));
    }

    #[test]
    fn nilpotent_and_triangular_are_exact() {
        // Strictly upper triangular (Moler & Van Loan): e^A is a finite sum.
        let a = mat![
            [0.0, 6.0, 0.0, 0.0],
            [0.0, 0.0, 6.0, 0.0],
            [0.0, 0.0, 0.0, 6.0],
            [0.0, 0.0, 0.0, 0.0]
        ];
        let expected = mat![
            [1.0, 6.0, 18.0, 36.0],
            [0.0, 1.0, 6.0, 18.0],
            [0.0, 0.0, 1.0, 6.0],
            [0.0, 0.0, 0.0, 1.0]
        ];
        assert!(relative_difference(&expm(a.as_ref()).unwrap(), &expected) < 1e-15);
        // The lower triangular transpose goes through the same path.
        let lower = expm(a.transpose()).unwrap();
        assert!(relative_difference(&lower, &expected.transpose().to_owned()) < 1e-15);
        // A huge superdiagonal entry: e^A = [[e, 1e40 e], [0, e]].
        let a = mat![[1.0, 1e40], [0.0, 1.0]];
        let e = expm(a.as_ref()).unwrap();
        let one = 1f64.exp();
        assert!((e[(0, 1)] / (1e40 * one) - 1.0).abs() < 1e-15);
        assert!((e[(0, 0)] - one).abs() < 1e-15 && e[(1, 0)] == 0.0);
        // Triangular of order above the small engine's.
        let n = 12;
        let t = Mat::from_fn(n, n, |i, j| {
            if j >= i {
                1.0 / (1 + j - i) as f64
            } else {
                0.0
            }
        });
        let e = expm(t.as_ref()).unwrap();
        for k in 0..n {
            assert!((e[(k, k)] - 1f64.exp()).abs() < 1e-15);
        }
        assert!((0..n).all(|j| (j + 1..n).all(|i| e[(i, j)] == 0.0)));
    }

    #[test]
    fn huge_norms_overflow_to_infinity_without_hanging() {
        let e = expm(mat![[1000.0]].as_ref()).unwrap();
        assert_eq!(e[(0, 0)], f64::INFINITY);
        let a = mat![[1e300, 1.0], [-1.0, 1e300]];
        let e = expm(a.as_ref()).unwrap();
        assert!(e.col_as_slice(0).iter().any(|v| !v.is_finite()));
        let big = Mat::from_fn(12, 12, |i, j| if i == j { 1e300 } else { 1.0 });
        let e = expm(big.as_ref()).unwrap();
        assert!(e.col_as_slice(0).iter().any(|v| !v.is_finite()));
        // A hugely negative diagonal decays to exactly zero.
        let a = mat![[-1e200, 3.0], [0.0, -2e200]];
        let e = expm(a.as_ref()).unwrap();
        assert_eq!(e[(0, 0)], 0.0);
        assert_eq!(e[(1, 1)], 0.0);
    }

    #[test]
    fn transition_matrices_satisfy_the_semigroup_property() {
        // Φ(t1 + t2) = Φ(t1) Φ(t2) (6.25) and Φ(-t) = Φ(t)^-1 (6.27), for both engines.
        let mut rng = StdRng::seed_from_u64(21);
        for n in [5, 11] {
            let a = random_matrix(n, 0.6, &mut rng);
            let times = [0.3, 1.1, 1.4, -1.4];
            let phi = transition_matrices(a.as_ref(), &times).unwrap();
            assert!(relative_difference(&(&phi[0] * &phi[1]), &phi[2]) < 1e-14);
            let identity = Mat::<f64>::identity(n, n);
            assert!((&phi[2] * &phi[3] - &identity).norm_l2() < 1e-13);
            // The shared plan gives the same matrices as separate calls.
            for (t, p) in times.iter().zip(&phi) {
                let single = expm((&a * faer::Scale(*t)).as_ref()).unwrap();
                assert!(relative_difference(p, &single) < 1e-14);
            }
        }
    }

    #[test]
    fn integer_powers_are_exact_for_small_exponents() {
        for k in 0..12 {
            assert_eq!(integer_power(2.0, k), 2f64.powi(k as i32));
            assert!((integer_power(1.1, k) / 1.1f64.powi(k as i32) - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn divided_difference_is_accurate_across_regimes() {
        for &(a, b) in &[
            (1.0, 1.0),
            (1.0, 1.0 + 1e-12),
            (-3.0, 2.0),
            (0.1, 0.3),
            (50.0, -40.0),
        ] {
            let got = exp_divided_difference(a, b);
            let expected = if a == b {
                f64::exp(a)
            } else if (a - b).abs() < 1e-6 {
                f64::exp(0.5 * (a + b))
            } else {
                (f64::exp(b) - f64::exp(a)) / (b - a)
            };
            assert!((got - expected).abs() <= 1e-13 * expected.abs(), "{a} {b}");
        }
    }

    /// Times far beyond 1 / ||A||: the powers of A and of the time are not formed apart, so a
    /// zero or tiny A gives the exact exponential, not 0 · inf = NaN.
    #[test]
    fn huge_times_of_zero_tiny_and_nilpotent_matrices() {
        let identity = Mat::<f64>::identity(3, 3);
        let zero = Mat::<f64>::zeros(3, 3);
        let phi = transition_matrices(zero.as_ref(), &[1e155, -1e300]).unwrap();
        for p in &phi {
            assert_eq!(p, &identity);
        }
        for t in [1e100, 1e200, 1e300] {
            let a = &identity * faer::Scale(-1.0 / t);
            let phi = &transition_matrices(a.as_ref(), &[t]).unwrap()[0];
            let expected = &identity * faer::Scale((-1.0f64).exp());
            assert!(
                (phi - &expected).norm_max() <= 4.0 * f64::EPSILON,
                "t = {t:e}: {phi:?}"
            );
        }
        // A^3 = 0 and |A|^3 = 0: no squarings, and e^{tA} = I + tA + t^2 A^2 / 2 from the Padé
        // approximant at c = t, whose scalars c^4 ... c^8 overflow while A^4 = 0.
        let nilpotent = mat![[0.0, 1.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]];
        for t in [1e3, 1e60, 1e100] {
            let phi = &transition_matrices(nilpotent.as_ref(), &[t]).unwrap()[0];
            let expected = mat![[1.0, t, t + 0.5 * t * t], [0.0, 1.0, t], [0.0, 0.0, 1.0]];
            let error = (phi - &expected).norm_max() / expected.norm_max();
            assert!(error <= 4.0 * f64::EPSILON, "t = {t:e}: {phi:?}");
        }
    }

    /// A rotation by 1e50 rad: e^A is orthogonal, but the squarings overflow; refused as
    /// ill-conditioned instead of returned as NaN, alone, in a stack and as a transition matrix.
    #[test]
    fn exponentials_that_cannot_be_computed_are_refused() {
        let rotation = mat![[0.0, 1e50], [-1e50, 0.0]];
        assert!(matches!(
            expm(rotation.as_ref()),
            Err(Error::IllConditioned { .. })
        ));
        assert!(matches!(
            transition_matrices(rotation.as_ref(), &[0.5, 1.0]),
            Err(Error::IllConditioned { .. })
        ));
        // An exponential that does overflow is returned, with its infinities.
        let growth = mat![[800.0, 0.0], [1.0, 800.0]];
        let phi = expm(growth.as_ref()).unwrap();
        assert!(phi[(0, 0)].is_infinite());
    }
}
