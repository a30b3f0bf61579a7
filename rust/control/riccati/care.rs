//! The continuous-time algebraic Riccati equation (chapter (6.199), and its general form
//! (6.228) as MATLAB's care(A, B, Q, R, S, E) states it):
//!
//! ```text
//! A^T X E + E^T X A - (E^T X B + S) R^-1 (B^T X E + S^T) + Q = 0,
//! K = R^-1 (B^T X E + S^T),      closed loop eig(A - B K, E),
//! ```
//!
//! for the stabilising solution X = X^T (every closed-loop eigenvalue in Re λ < 0), by the
//! Hamiltonian ordered-Schur method of Laub (1979), with scaling and Newton refinement.
//!
//! # Reduction to the standard equation
//!
//! A nonsingular E is removed by Ã = E^-1 A, B̃ = E^-1 B (LU solves): Y = E^T X E then solves
//! the equation with E = I, and X = E^-T Y E^-1. (MATLAB keeps E in a pencil and uses the QZ
//! algorithm; the LU route is as accurate when κ(E) is moderate, which is checked.) With the
//! Cholesky factor R = L L^T, B̂ = B̃ L^-T and Ŝ = S L^-T, the cross term is absorbed:
//!
//! ```text
//! Ā = Ã - B̂ Ŝ^T,   G = B̂ B̂^T,   Q̄ = Q - Ŝ Ŝ^T:     Ā^T Y + Y Ā - Y G Y + Q̄ = 0,
//! ```
//!
//! with R^-1 formed nowhere.
//!
//! # The Hamiltonian method
//!
//! H = [[Ā, -G], [-Q̄, -Ā^T]] has eigenvalues symmetric about the imaginary axis. If none lies
//! on it and the stable invariant subspace is spanned by the columns of [U11; U21] with U11
//! nonsingular, Y = U21 U11^-1 is the stabilising solution and the stable eigenvalues of H are
//! the closed-loop ones. The subspace comes from the real Schur form of H reordered to put
//! Re λ < 0 first ([`crate::linalg::schur::reorder`]); Y from U11^T Y = U21^T by an LU solve, then
//! symmetrised. Up to order [`HAMILTONIAN_SHIFT_MAX_ORDER`] the QR iteration
//! ([`crate::linalg::schur`]) estimates the eigenvalues of H from its even characteristic polynomial
//! and takes the unstable ones as its first shifts, so that the unstable half deflates first.
//! The iteration then stops ([`crate::linalg::schur`]'s `Until::UnstableHalf`): once the trailing n
//! eigenvalues have deflated, all of them with Re λ beyond the axis tolerance, the leading n
//! columns of Z span the stable subspace already, and the sweeps that would triangularise the
//! leading block (two of six on the 747's regulator) are saved; the stable eigenvalues are
//! then known as the mirror images -λ̄ of the unstable ones. Should a stable eigenvalue
//! deflate among the trailing half, the iteration completes the Schur form, which is reordered.
//! For a 4-state model H is of order 8, held on the stack with its order fixed at compile
//! time.
//!
//! Before that H is scaled twice, by similarities that keep it Hamiltonian: by ρ, a power of
//! two near sqrt(||Q̄||_F / ||G||_F), to G ρ and Q̄ / ρ (the scaling of Pandey and of Benner's
//! CAREX study: it balances the two off-diagonal blocks, whose norms can differ by 10^10 in
//! flight-control weights like R = I / c^2), and by diag(D, D^-1) with D the powers of two
//! nearest to the square roots of a Parlett–Reinsch balancing of H, as scipy's
//! solve_continuous_are balances its pencil. Both are exact in floating point and are undone
//! on Y.
//!
//! # Refinement and the reported numbers
//!
//! The Schur method is backward stable for the Hamiltonian but not for the Riccati equation
//! itself; Newton's method (Kleinman 1968) restores a small residual: with A_k = Ā - G Y_k,
//! A_k^T Δ + Δ A_k = -Res(Y_k) ([`crate::linalg::lyapunov`]), Y_{k+1} = Y_k + Δ, repeated while the
//! residual decreases and is above [`REFINEMENT_FLOOR`], a few units of rounding (at most
//! [`MAX_REFINEMENT_STEPS`] times). Up to n = [`crate::linalg::lyapunov::KRONECKER_MAX_ORDER`] each step
//! is an exact step whose Lyapunov equation is solved directly in its vectorised form (10
//! unknowns at n = 4: a fifth of the cost of the Schur route). Above, the first step needs no
//! Schur form of A_0: the Hamiltonian's Schur form already factors the closed loop of the Schur
//! solution as V T11 V^-1 (`ClosedLoopFactors`; a T11 left in Hessenberg form by the early stop
//! is triangularised first, at order n), which leaves only the quasi-triangular half of
//! Bartels–Stewart (10-13 % of the whole solve at n = 16 to 128). Reported: the relative
//! residual of the general equation,
//!
//! ```text
//! ||Res||_F / (||Q||_F + 2 ||A^T X E||_F + ||M^T K||_F),      M = B^T X E + S^T,
//! ```
//!
//! and the reciprocal 1-norm condition number of U11 (small: the subspace is nearly not a
//! graph and X is inaccurate).
//!
//! # Errors
//!
//! R not symmetric positive definite; E singular; eigenvalues of H within
//! [`AXIS_TOLERANCE`] ||H||_F of the imaginary axis (no stabilising solution: an undamped mode
//! that the input cannot move or the weight does not see); U11 singular to working precision;
//! a computed solution whose closed loop A - B K has an eigenvalue with Re λ >= 0 (the stable
//! and unstable eigenvalues of H too ill-conditioned to be told apart).

use super::AlgebraicSolution;
use super::scaling::{Equation, Scale, ScaledEquation};
use crate::error::{Error, check_finite, check_rows, check_square};
use crate::linalg::balance::{balance, nearest_power_of_two, states_scaled_apart};
use crate::linalg::dense::{
    cholesky, product, solve_lower_in_place, solve_lower_transposed_in_place, transposed_product,
};
use crate::linalg::lu::{self, solve_with_inverse};
use crate::linalg::lyapunov::{self, KRONECKER_MAX_ORDER, Singularity};
use crate::linalg::matrix::{FaerView, Order, Symmetrize, from_faer, with_order};
use crate::linalg::norm::{frobenius_norm, max_abs, one_norm};
use crate::linalg::product;
use crate::linalg::schur::reorder::reorder_schur;
use crate::linalg::schur::{
    Finished, RealSchur, Spectrum, Until, eigenvalues_near, quasi_triangular_eigenvalues,
    real_schur_with, square_schur_form,
};
use faer::{Mat, MatRef, Par, c64};
use nalgebra::DMatrix;

/// Eigenvalues of H with |Re λ| <= AXIS_TOLERANCE ||H||_F count as on the imaginary axis.
pub const AXIS_TOLERANCE: f64 = 100.0 * f64::EPSILON;

/// Up to this order of H the QR iteration uses the structure of its spectrum
/// ([`Spectrum::Hamiltonian`]): estimates of the eigenvalues from the characteristic
/// polynomial as shifts, unstable ones first, which saves sweeps and reordering swaps over
/// the mirror images of deflated eigenvalues alone. Above this order the roots of the
/// polynomial lose too much accuracy: on graded problems (entries spread over 6 decades) the
/// worst residuals grow, and on Hamiltonians whose stable eigenvalues cluster the mirror
/// images do no better than the general shifts.
pub const HAMILTONIAN_SHIFT_MAX_ORDER: usize = 16;

/// Newton steps at most; each costs one Lyapunov solve (about the price of the Schur form of
/// an n x n matrix, an eighth of that of H).
pub const MAX_REFINEMENT_STEPS: usize = 10;

/// Newton refinement stops once the relative residual is below this: a few units of rounding.
/// A speed trade, measured against 50-digit solutions on 41 weights of the 747 lateral
/// regulator (c from 1e-3 to 10): the correctly rounded solution has a residual of 0.1 to 1 u;
/// the Schur solutions had residuals of 1.5 to 37 u and forward errors of 1.3 to 23 u; a Newton
/// step brought the forward error to 0.3 to 1.9 u. Those left below the floor (no step) kept
/// forward errors of 1.3 to 12.6 u. Overall: median 1.8 u, largest 12.6 u, against scipy's
/// 15 u and 82 u and python-control's 70 u and 628 u on the same weights. A step costs about a
/// fifth of the 4-state solve, which the 747's regulator at c = 1 (1.8 u) does not pay.
pub const REFINEMENT_FLOOR: f64 = 4.0 * f64::EPSILON;

/// Asymmetry ||M - M^T||_max / ||M||_max that Q and R may carry (rounding in how the caller
/// formed them); they are then symmetrised.
pub const SYMMETRY_TOLERANCE: f64 = 1e-12;

/// The optional arguments of [`solve_care`].
#[derive(Debug, Clone, Copy, Default)]
pub struct CareOptions<'a> {
    /// The cross weight S (n x m), the N of python-control's lqr.
    pub s: Option<MatRef<'a, f64>>,
    /// The descriptor matrix E (n x n, nonsingular).
    pub e: Option<MatRef<'a, f64>>,
    /// Newton refinement after the Schur solution.
    pub refine: bool,
    /// The caller's name of the cross weight in errors (default "S").
    pub s_name: Option<&'static str>,
}

/// The data of the Hamiltonian: Ā, G and Q̄.
pub(crate) struct Standard {
    pub(crate) a: DMatrix<f64>,
    pub(crate) g: DMatrix<f64>,
    pub(crate) q: DMatrix<f64>,
}

/// The equation with E removed, Ã^T Y + Y Ã - (Y B̃ + S) R^-1 (B̃^T Y + S^T) + Q = 0, in which
/// the refinement works: its quadratic term, (Y B̃ + S) K with K from two triangular solves
/// with the Cholesky factor, keeps its accuracy when R is ill-conditioned, where
/// Y B̂ B̂^T Y (B̂ = B̃ L^-T, entries of size ||B|| / σ_min(L)) loses digits to cancellation.
struct Reduced<'a> {
    a: &'a DMatrix<f64>,
    b: &'a DMatrix<f64>,
    q: &'a DMatrix<f64>,
    /// ||Q||_F.
    q_norm: f64,
    s: Option<&'a DMatrix<f64>>,
    l: &'a DMatrix<f64>,
}

impl Reduced<'_> {
    /// The residual of Y (symmetric) and its gain K = R^-1 (B̃^T Y + S^T) = L^-T L^-1 M^T, with
    /// M = Y B̃ + S the coupling of the quadratic term, (Y B̃ + S) K.
    fn evaluate(&self, y: &DMatrix<f64>) -> Evaluation {
        let mut gain = transposed_product(self.b, y);
        if let Some(s) = self.s {
            for j in 0..gain.ncols() {
                for i in 0..gain.nrows() {
                    gain[(i, j)] += s[(j, i)];
                }
            }
        }
        // (B̃^T Y + S^T)^T = Y B̃ + S, entry by entry the same sums, Y being symmetric.
        let coupling = gain.transpose();
        solve_lower_in_place(self.l, &mut gain);
        solve_lower_transposed_in_place(self.l, &mut gain);
        let ay = transposed_product(self.a, y);
        let quadratic = product(&coupling, &gain);
        let scale =
            self.q_norm + 2.0 * frobenius_norm(ay.as_faer()) + frobenius_norm(quadratic.as_faer());
        let n = y.nrows();
        let mut residual = DMatrix::from_fn(n, n, |i, j| {
            ay[(i, j)] + ay[(j, i)] - quadratic[(i, j)] + self.q[(i, j)]
        });
        residual.symmetrize();
        Evaluation {
            residual_norm: frobenius_norm(residual.as_faer()),
            residual,
            gain,
            scale,
        }
    }

    /// Ã - B̃ K.
    fn closed_loop(&self, gain: &DMatrix<f64>) -> DMatrix<f64> {
        let mut closed_loop = product(self.b, gain);
        for (x, &a) in closed_loop.as_mut_slice().iter_mut().zip(self.a.as_slice()) {
            *x = a - *x;
        }
        closed_loop
    }
}

/// Res(Y) (symmetrised) of the reduced equation, its Frobenius norm, the gain K of Y, and the
/// size of the terms, ||Q||_F + 2 ||Ã^T Y||_F + ||(Y B̃ + S) K||_F, against which it is judged.
/// Without E this is the residual of the caller's equation and is reported as it is.
struct Evaluation {
    residual: DMatrix<f64>,
    residual_norm: f64,
    gain: DMatrix<f64>,
    scale: f64,
}

impl Evaluation {
    fn relative_residual(&self) -> f64 {
        relative(self.residual_norm, self.scale)
    }
}

/// Solves the CARE for its stabilising solution, in exactly scaled units where its states are
/// scaled apart ([`super::scaling`]); an R that is symmetric and nonsingular but not positive
/// definite goes to the extended pencil ([`super::care_pencil`]), scaled as the discrete
/// pencil is (also where B or the weights alone are far from 1).
pub fn solve_care(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: CareOptions<'_>,
) -> Result<AlgebraicSolution, Error> {
    let indefinite = indefinite_weight(b, r);
    solve_care_scaled(a, b, q, r, options, indefinite)
        .unwrap_or_else(|| solve_care_as_given(a, b, q, r, options, indefinite))
}

/// [`solve_care`] in the scaled units of [`super::scaling`], or None where the equation is
/// solved as given; `indefinite`: R is [`indefinite_weight`] (so is 2^k R, the scaled one).
pub(crate) fn solve_care_scaled(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: CareOptions<'_>,
    indefinite: bool,
) -> Option<Result<AlgebraicSolution, Error>> {
    let given = Equation {
        a,
        b,
        q,
        r,
        s: options.s,
        e: options.e,
        terminal: None,
    };
    // The extended pencil of an indefinite R, like the discrete pencil, has identity blocks
    // that set its scale, and no scaling of its own (the Hamiltonian's ρ and balancing).
    let scale = if indefinite {
        Scale::AlsoWeights
    } else {
        Scale::WhereBalanced
    };
    let scaled = ScaledEquation::of(given, scale)?;
    let equation = scaled.equation();
    let solution = solve_care_as_given(
        equation.a,
        equation.b,
        equation.q,
        equation.r,
        CareOptions {
            s: equation.s,
            e: equation.e,
            ..options
        },
        indefinite,
    );
    Some(solution.and_then(|solution| {
        scaled.unscaled(solution, |x, gain| {
            general_residual(a, b, q, options.s, options.e, x, gain)
        })
    }))
}

/// An R that is symmetric but not positive definite: the extended pencil solves the equation,
/// which needs no Cholesky factor (an asymmetric R is refused by the same check in both
/// paths).
pub(crate) fn indefinite_weight(b: MatRef<'_, f64>, r: MatRef<'_, f64>) -> bool {
    r.nrows() == r.ncols()
        && r.nrows() == b.ncols()
        && r.is_all_finite()
        && symmetric(r, "R", b.ncols(), "the columns of B")
            .map(|r| cholesky(&r).is_none())
            .unwrap_or(false)
}

/// [`solve_care`] of the equation as given (`indefinite`: R is [`indefinite_weight`]).
fn solve_care_as_given(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: CareOptions<'_>,
    indefinite: bool,
) -> Result<AlgebraicSolution, Error> {
    if indefinite {
        return super::care_pencil::solve_care_indefinite(a, b, q, r, options);
    }
    solve_care_dense(a, b, q, r, options).map(|care| AlgebraicSolution {
        x: care.x.to_faer(),
        gain: care.gain.to_faer(),
        closed_loop_eigenvalues: care.closed_loop_eigenvalues,
        residual: care.residual,
        rcond: care.rcond,
        refinement_steps: care.refinement_steps,
    })
}

/// [`AlgebraicSolution`] with X and K as the solver forms them, for callers that copy them on (the batch
/// kernels), sparing the conversion.
pub(crate) struct CareDense {
    pub(crate) x: DMatrix<f64>,
    pub(crate) gain: DMatrix<f64>,
    pub(crate) closed_loop_eigenvalues: Vec<c64>,
    pub(crate) residual: f64,
    pub(crate) rcond: f64,
    pub(crate) refinement_steps: usize,
    /// D of the symplectic balancing diag(D, D^-1) of the Hamiltonian that gave X (empty for
    /// n = 0): the coordinates of rcond(U11), for [`SharedPlant::solve_near`].
    pub(crate) balancing: Vec<f64>,
}

/// log2 of the size below which (and of its reciprocal, above which) the weights are scaled
/// before the Hamiltonian is formed ([`solve_care_dense`]).
const WEIGHT_RANGE_LOG2: f64 = 500.0;

/// [`solve_care`], returning [`CareDense`].
///
/// When B R^-1 B^T or Q would overflow (||B||^2 / ||R|| or ||Q|| beyond 2^500), or both are
/// below 2^-500, the equation is solved for (β B, Q / β², S / β) with a power of two β that
/// balances the two terms: A^T X' + X' A - X' (β² G) X' + Q / β² = 0 has X' = X / β² and
/// K' = K / β, multiplied back exactly. (B = 1e200 made G overflow, and the error blamed A.)
pub(crate) fn solve_care_dense(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: CareOptions<'_>,
) -> Result<CareDense, Error> {
    let (b_log, r_log, q_log) = (
        log2(frobenius_norm(b)),
        log2(frobenius_norm(r)),
        log2(frobenius_norm(q)),
    );
    let g_log = 2.0 * b_log - r_log;
    let finite = [a, b, q, r].iter().all(|m| m.is_all_finite())
        && options.s.is_none_or(|s| s.is_all_finite());
    // Scaled when G or Q is huge (forming them or H overflows), or both are tiny.
    if !finite || !weights_need_scaling(b_log, r_log, q_log) {
        return solve_care_balanced(a, b, q, r, options);
    }
    // B' = β B, Q' = Q / β², S' = S / β (β a power of two) give X' = X / β² and K' = K / β:
    // G' = β² G and Q' of the same size, β = (||Q|| / ||G||)^(1/4) (for Q = 0, G' of the size
    // of A). B is scaled rather than R, which is often the larger (R = 1e308 beside
    // B = 1e299 would overflow as R / σ).
    let target = if frobenius_norm(q) > 0.0 {
        (q_log - g_log) / 4.0
    } else {
        (log2(frobenius_norm(a)) - g_log) / 2.0
    };
    let beta = target.round().clamp(-500.0, 500.0).exp2();
    let scaled = |m: MatRef<'_, f64>, factor: f64| {
        Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] * factor)
    };
    let (b_scaled, q_scaled) = (scaled(b, beta), scaled(q, 1.0 / (beta * beta)));
    let s_scaled = options.s.map(|s| scaled(s, 1.0 / beta));
    if !(q_scaled.is_all_finite() && s_scaled.as_ref().is_none_or(|s| s.is_all_finite())) {
        return Err(weights_out_of_range());
    }
    let scaled_options = CareOptions {
        s: s_scaled.as_ref().map(|s| s.as_ref()),
        ..options
    };
    let mut care = solve_care_balanced(a, b_scaled.as_ref(), q_scaled.as_ref(), r, scaled_options)?;
    for x in care.x.as_mut_slice() {
        *x *= beta * beta;
    }
    for k in care.gain.as_mut_slice() {
        *k *= beta;
    }
    Ok(care)
}

/// What [`solve_care`] computes from A, B and Q alone, formed once for problems that share
/// them (a sweep over the control weight R): the checks of [`check_problem`] on A, B and Q, Q
/// symmetrised and ||Q||_F, copies of A and B, and log2 ||B||_F, log2 ||Q||_F.
///
/// Formed only where those checks pass, every entry is finite and the states are not scaled
/// apart (so [`solve_care_scaled`] solves the equation as given whenever R is positive
/// definite); [`SharedPlant::solve`] then gives, for each R, bit for bit what
/// [`solve_care_dense`] gives, with the same numbers not formed again.
pub(crate) struct SharedPlant {
    q: DMatrix<f64>,
    q_norm: f64,
    a: DMatrix<f64>,
    b: DMatrix<f64>,
    b_log: f64,
    q_log: f64,
}

impl SharedPlant {
    /// The shared data, or None where some problem could take another path than
    /// [`solve_care_dense`]'s plain one whatever its R (see the type).
    pub(crate) fn of(a: MatRef<'_, f64>, b: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Option<Self> {
        let n = a.nrows();
        let checked = n > 0
            && a.ncols() == n
            && b.nrows() == n
            && a.is_all_finite()
            && b.is_all_finite()
            && !states_scaled_apart(a);
        if !checked {
            return None;
        }
        let q_symmetric = symmetric(q, "Q", n, "A").ok()?;
        Some(Self {
            q_norm: frobenius_norm(q_symmetric.as_faer()),
            q: q_symmetric,
            a: from_faer(a),
            b: from_faer(b),
            b_log: log2(frobenius_norm(b)),
            q_log: log2(frobenius_norm(q)),
        })
    }

    /// [`solve_care`] without a cross term or E for the shared A, B, Q (`a`, `b` as given to
    /// [`SharedPlant::of`]) and this R: Some of the result where R is symmetric positive
    /// definite and the weights need no scaling (the path [`solve_care`] then takes:
    /// [`solve_care_dense`] of the equation as given), None otherwise (the caller solves it as
    /// [`solve_care`] does). R's symmetrisation and Cholesky factor serve both the test of an
    /// indefinite R and the solve.
    pub(crate) fn solve(
        &self,
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        r: MatRef<'_, f64>,
        refine: bool,
    ) -> Option<Result<CareDense, Error>> {
        let r_symmetric = symmetric(r, "R", b.ncols(), "the columns of B").ok()?;
        let l = cholesky(&r_symmetric)?;
        if weights_need_scaling(self.b_log, log2(frobenius_norm(r)), self.q_log) {
            return None;
        }
        let options = CareOptions {
            refine,
            ..CareOptions::default()
        };
        let checked = Checked {
            q: &self.q,
            q_norm: self.q_norm,
            l: &l,
            a_tilde: &self.a,
            b_tilde: &self.b,
        };
        Some(solve_checked(a, b, options, checked))
    }

    /// [`SharedPlant::solve`] with refinement for this R, by Newton's method (Kleinman 1968)
    /// started from `near`, the solution of a nearby R in the same sweep, instead of the
    /// Schur form of the Hamiltonian: Y_{k+1} = Y_k + Δ_k with
    /// (A - B K_k)^T Δ_k + Δ_k (A - B K_k) = -Res(Y_k), K_k the gain of Y_k, the step of
    /// [`refine`] (at n = 4 one Lyapunov solve of order 4 against the Schur form of the
    /// Hamiltonian of order 8). From a start close enough that A - B K_0 is stable the
    /// iteration converges quadratically to the stabilising solution. The start is the
    /// polynomial through the solutions in `history` (oldest first, at most
    /// [`EXTRAPOLATION_WEIGHTS`]'s length) at the next point ([`EXTRAPOLATION_WEIGHTS`]): on
    /// an evenly spaced sweep of 1000 weights with four solutions, one step from it reaches
    /// the floor.
    ///
    /// Some of the result where it converged: the residual fell below [`REFINEMENT_FLOOR`]
    /// within [`WARM_START_MAX_STEPS`] steps, or stopped decreasing below
    /// [`WARM_START_STAGNATION`], and the closed loop passed the same check as the Schur
    /// solution's ([`check_stabilising`], its eigenvalues found with extrapolated ones as
    /// shifts) and is [`WARM_START_AXIS_DISTANCE`] clear of the axis.
    /// None where R or the weights take another path ([`SharedPlant::solve`]'s None), and
    /// where Newton's method failed any of those tests: the caller then solves by the Schur
    /// method, which reports any failure with its own error. rcond(U11) is that of the
    /// orthonormal basis [U11; U21] = [I; Y'] C^-T of the stable subspace of the Hamiltonian
    /// scaled as the Schur method scales it (Y' = D Y D / ρ, ρ from this R, D the balancing
    /// of the group's last Schur solve; I + Y'^2 = C C^T): with the same D its U11 has the
    /// singular values of the Schur method's, and its 1-norm condition number is within a
    /// factor n^2 of it.
    pub(crate) fn solve_near(
        &self,
        b: MatRef<'_, f64>,
        r: MatRef<'_, f64>,
        history: &[CareDense],
    ) -> Option<CareDense> {
        let n = self.a.nrows();
        let fits = |solution: &CareDense| {
            solution.x.nrows() == n
                && solution.balancing.len() == n
                && solution.closed_loop_eigenvalues.len() == n
        };
        let (near, earlier) = history.split_last()?;
        if !history.iter().all(fits) || earlier.len() >= EXTRAPOLATION_WEIGHTS.len() {
            return None;
        }
        let r_symmetric = symmetric(r, "R", b.ncols(), "the columns of B").ok()?;
        let l = cholesky(&r_symmetric)?;
        if weights_need_scaling(self.b_log, log2(frobenius_norm(r)), self.q_log) {
            return None;
        }
        let reduced = Reduced {
            a: &self.a,
            b: &self.b,
            q: &self.q,
            q_norm: self.q_norm,
            s: None,
            l: &l,
        };
        // The polynomial through the last solutions, at the next point.
        let weights = EXTRAPOLATION_WEIGHTS[earlier.len()];
        let mut y = DMatrix::from_fn(n, n, |i, j| {
            history
                .iter()
                .rev()
                .zip(weights)
                .map(|(solution, w)| w * solution.x[(i, j)])
                .sum()
        });
        y.symmetrize();
        let estimates = match earlier.last() {
            Some(before) => extrapolated_eigenvalues(
                &near.closed_loop_eigenvalues,
                &before.closed_loop_eigenvalues,
            ),
            None => near.closed_loop_eigenvalues.clone(),
        };
        let mut evaluation = reduced.evaluate(&y);
        let mut steps = 0;
        while evaluation.residual_norm > REFINEMENT_FLOOR * evaluation.scale {
            if steps == WARM_START_MAX_STEPS {
                return None;
            }
            let closed_loop = reduced.closed_loop(&evaluation.gain);
            let delta = if n <= KRONECKER_MAX_ORDER {
                lyapunov::solve_kronecker(
                    &closed_loop.transpose(),
                    &evaluation.residual,
                    Singularity::Perturb,
                )
                .ok()?
            } else {
                let delta = lyapunov::solve(
                    closed_loop.as_faer().transpose(),
                    evaluation.residual.as_faer(),
                    Singularity::Perturb,
                )
                .ok()?;
                from_faer(delta.as_ref())
            };
            let mut candidate = y.clone();
            for (x, &v) in candidate.as_mut_slice().iter_mut().zip(delta.as_slice()) {
                *x += v;
            }
            candidate.symmetrize();
            let candidate_evaluation = reduced.evaluate(&candidate);
            // A NaN residual is no decrease.
            let decreased = candidate_evaluation.residual_norm < evaluation.residual_norm;
            if !decreased {
                if evaluation.relative_residual() <= WARM_START_STAGNATION {
                    break;
                }
                return None;
            }
            (y, evaluation) = (candidate, candidate_evaluation);
            steps += 1;
        }
        let gain = evaluation.gain;
        let closed_loop = reduced.closed_loop(&gain);
        let finite = |m: &DMatrix<f64>| m.as_slice().iter().all(|x| x.is_finite());
        if !(finite(&y) && finite(&gain) && finite(&closed_loop)) {
            return None;
        }
        let closed_loop_eigenvalues = eigenvalues_near(closed_loop.as_faer(), &estimates).ok()?;
        let closed_loop_norm = frobenius_norm(closed_loop.as_faer());
        check_stabilising(&closed_loop_eigenvalues, closed_loop_norm).ok()?;
        // Near the axis the Schur method decides (its separation test, or its error).
        let margin = WARM_START_AXIS_DISTANCE * closed_loop_norm;
        if closed_loop_eigenvalues.iter().any(|z| z.re >= -margin) {
            return None;
        }
        let rcond = graph_rcond(&y, self.rho(&l), &near.balancing)?;
        Some(CareDense {
            residual: relative(evaluation.residual_norm, evaluation.scale),
            x: y,
            gain,
            closed_loop_eigenvalues,
            rcond,
            refinement_steps: steps,
            balancing: near.balancing.clone(),
        })
    }

    /// The scaling ρ of [`hamiltonian_solution`] for R = L L^T: the power of two nearest to
    /// sqrt(||Q||_F / ||G||_F), G = B̂ B̂^T, B̂ = B L^-T (1 where either is zero).
    fn rho(&self, l: &DMatrix<f64>) -> f64 {
        let mut b_hat_t = self.b.transpose();
        solve_lower_in_place(l, &mut b_hat_t);
        let g_norm = frobenius_norm(transposed_product(&b_hat_t, &b_hat_t).as_faer());
        if g_norm > 0.0 && self.q_norm > 0.0 {
            nearest_power_of_two((self.q_norm / g_norm).sqrt())
        } else {
            1.0
        }
    }
}

/// Estimates of the next closed-loop eigenvalues of a sweep, 2 λ - μ for each λ of `near`
/// (Im >= 0) and the μ of `before` nearest to it: exact to second order where the sweep moves
/// them smoothly, and only shifts for the QR iteration (a poor one costs a sweep).
fn extrapolated_eigenvalues(near: &[c64], before: &[c64]) -> Vec<c64> {
    near.iter()
        .filter(|lambda| lambda.im >= 0.0)
        .map(|&lambda| {
            let nearest = before
                .iter()
                .filter(|mu| mu.im >= 0.0)
                .min_by(|x, y| {
                    (*x - lambda)
                        .norm_sqr()
                        .total_cmp(&(*y - lambda).norm_sqr())
                })
                .copied()
                .unwrap_or(lambda);
            lambda * 2.0 - nearest
        })
        .collect()
}

/// The weights of the last solutions, the latest first, in the start of
/// [`SharedPlant::solve_near`] from 1, 2, 3 or 4 of them: the polynomial of that degree - 1
/// through them at the next point of an evenly spaced sweep, X_k = sum_j w_j X_{k-1-j}
/// (Newton's backward differences; its error is O(h^p) for p solutions).
pub const EXTRAPOLATION_WEIGHTS: [&[f64]; 4] = [
    &[1.0],
    &[2.0, -1.0],
    &[3.0, -3.0, 1.0],
    &[4.0, -6.0, 4.0, -1.0],
];

/// Newton steps at most from a nearby solution ([`SharedPlant::solve_near`]) before the
/// Schur method takes over.
pub const WARM_START_MAX_STEPS: usize = 4;

/// The relative residual below which [`SharedPlant::solve_near`] accepts a solution whose
/// residual stopped decreasing above [`REFINEMENT_FLOOR`] (as [`refine`] stops), the bound
/// that refinement meets on small regulators.
pub const WARM_START_STAGNATION: f64 = 64.0 * f64::EPSILON;

/// A solution of [`SharedPlant::solve_near`] whose closed loop has an eigenvalue with
/// Re λ >= -WARM_START_AXIS_DISTANCE ||A - B K||_F is left to the Schur method: there the
/// equation is near one without a stabilising solution, and the Schur method's own tests
/// (the separation of the Hamiltonian's eigenvalues, the convergence of its QR iteration)
/// decide whether it is refused, so that a sweep refuses what the single solver refuses.
/// Weakly controllable undamped modes (A = [[0, 2], [-2, 0]], B = [0, 1e-3]^T, Q = diag(1e-6,
/// 0), c from 1e-8 to 10 in reverse) were solved by Newton's method for weights where the
/// Schur method fails.
pub const WARM_START_AXIS_DISTANCE: f64 = 1.4901161193847656e-8;

/// rcond_1(U11) of the orthonormal basis [U11; U21] = [I; Y'] C^-T of the graph of
/// Y' = D Y D / ρ, with I + Y'^2 = C C^T (C lower triangular): U11 = C^-T, and
/// rcond = 1 / (||C^-T||_1 ||C^T||_1). None where the Cholesky factorisation fails (Y not
/// finite).
fn graph_rcond(y: &DMatrix<f64>, rho: f64, d: &[f64]) -> Option<f64> {
    let n = y.nrows();
    let scaled = DMatrix::from_fn(n, n, |i, j| d[i] * y[(i, j)] * d[j] / rho);
    let mut w = transposed_product(&scaled, &scaled);
    for i in 0..n {
        w[(i, i)] += 1.0;
    }
    w.symmetrize();
    let c = cholesky(&w)?;
    let mut inverse = DMatrix::identity(n, n);
    solve_lower_in_place(&c, &mut inverse);
    let rcond = 1.0 / (one_norm(c.as_faer().transpose()) * one_norm(inverse.as_faer().transpose()));
    rcond.is_finite().then_some(rcond)
}

/// log2 of a norm, 0 for a zero or non-finite one.
fn log2(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        x.log2()
    } else {
        0.0
    }
}

/// Whether [`solve_care_dense`] scales the weights (G = B R^-1 B^T or Q beyond 2^500, or both
/// below 2^-500), from the log2 of ||B||_F, ||R||_F and ||Q||_F.
fn weights_need_scaling(b_log: f64, r_log: f64, q_log: f64) -> bool {
    let g_log = 2.0 * b_log - r_log;
    // A tiny G beside a normal Q is a negligible quadratic term, solved as it is (scaling
    // would make the gain underflow).
    let huge = g_log > WEIGHT_RANGE_LOG2 || q_log > WEIGHT_RANGE_LOG2;
    let tiny = g_log < -WEIGHT_RANGE_LOG2 && q_log < -WEIGHT_RANGE_LOG2;
    huge || tiny
}

/// The refusal of weights whose Hamiltonian leaves the range of doubles even when balanced.
fn weights_out_of_range() -> Error {
    Error::InvalidArgument {
        arg: "B, R",
        message: "B R^-1 B^T and Q are too far apart in size for double precision (their \
                  balanced Hamiltonian overflows): scale the model's units"
            .into(),
    }
}

/// The refusal of an equation whose scaled Hamiltonian, solution or closed loop leaves the
/// range of doubles.
fn hamiltonian_out_of_range() -> Error {
    Error::IllConditioned {
        message: "the Riccati equation cannot be solved in double precision: its balanced \
                  Hamiltonian (A, B R^-1 B^T and Q), its solution or the closed loop overflows; \
                  scale the model's units"
            .into(),
    }
}

/// [`solve_care_dense`] for weights that need no scaling.
fn solve_care_balanced(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: CareOptions<'_>,
) -> Result<CareDense, Error> {
    let (q, l) = check_problem(a, b, q, r)?;
    let (n, m) = (a.nrows(), b.ncols());
    if let Some(s) = options.s {
        let name = options.s_name.unwrap_or("S");
        check_rows(s, name, n, "A")?;
        if s.ncols() != m {
            return Err(Error::Mismatch {
                arg: name,
                what: "as many columns as",
                expected: m,
                other: "B",
                got: s.ncols(),
            });
        }
        check_finite(s, name)?;
    }
    let (a_tilde, b_tilde) = match options.e {
        Some(e) => remove_descriptor(a, b, e)?,
        None => (from_faer(a), from_faer(b)),
    };
    let checked = Checked {
        q: &q,
        q_norm: frobenius_norm(q.as_faer()),
        l: &l,
        a_tilde: &a_tilde,
        b_tilde: &b_tilde,
    };
    solve_checked(a, b, options, checked)
}

/// The data of [`solve_care_balanced`] once checked: Q symmetrised and ||Q||_F, the Cholesky
/// factor L of R, and Ã = E^-1 A, B̃ = E^-1 B (A and B where there is no E).
struct Checked<'a> {
    q: &'a DMatrix<f64>,
    q_norm: f64,
    l: &'a DMatrix<f64>,
    a_tilde: &'a DMatrix<f64>,
    b_tilde: &'a DMatrix<f64>,
}

/// [`solve_care_balanced`] after its checks (`a` and `b` as given, for the residual of a
/// descriptor equation).
fn solve_checked(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    options: CareOptions<'_>,
    Checked {
        q,
        q_norm,
        l,
        a_tilde,
        b_tilde,
    }: Checked<'_>,
) -> Result<CareDense, Error> {
    let (n, m) = (a.nrows(), b.ncols());
    let s = options.s.map(from_faer);
    let standard = standardize(a_tilde, b_tilde, q, l, s.as_ref());
    let finite = |m: &DMatrix<f64>| m.as_slice().iter().all(|x| x.is_finite());
    if !(finite(&standard.a) && finite(&standard.g) && finite(&standard.q)) {
        return Err(weights_out_of_range());
    }
    let reduced = Reduced {
        a: a_tilde,
        b: b_tilde,
        q_norm,
        q,
        s: s.as_ref(),
        l,
    };
    if n == 0 {
        return Ok(CareDense {
            x: DMatrix::zeros(0, 0),
            gain: DMatrix::zeros(m, 0),
            closed_loop_eigenvalues: Vec::new(),
            residual: 0.0,
            rcond: 1.0,
            refinement_steps: 0,
            balancing: Vec::new(),
        });
    }
    let HamiltonianSolution {
        mut y,
        rcond,
        stable_eigenvalues,
        closed_loop: factors,
        balancing,
    } = hamiltonian_solution(&standard)?;
    let mut evaluation = reduced.evaluate(&y);
    let refinement_steps = if options.refine {
        refine(&reduced, &mut y, &mut evaluation, factors)
    } else {
        0
    };
    let reduced_residual = evaluation.relative_residual();
    let gain = evaluation.gain;
    let closed_loop = reduced.closed_loop(&gain);
    // Y, its gain or the closed loop beyond the doubles (A near 1e308): refused as such, not
    // as a non-finite A (the eigenvalue solver's name for its argument).
    let finite = |m: &DMatrix<f64>| m.as_slice().iter().all(|x| x.is_finite());
    if !(finite(&y) && finite(&gain) && finite(&closed_loop)) {
        return Err(hamiltonian_out_of_range());
    }
    // The stable eigenvalues of H are those of the closed loop of the exact solution: as
    // shifts they make the QR iteration converge in fewer sweeps.
    let closed_loop_eigenvalues = eigenvalues_near(closed_loop.as_faer(), &stable_eigenvalues)?;
    check_stabilising(
        &closed_loop_eigenvalues,
        frobenius_norm(closed_loop.as_faer()),
    )?;
    // X = E^-T Y E^-1.
    let (x, residual) = match options.e {
        Some(e) => {
            let mut x = y.to_faer();
            let mut factors = e.transpose().to_owned();
            lu::solve(factors.as_mut(), x.as_mut(), Par::Seq)?;
            let mut xt = x.transpose().to_owned();
            let mut factors = e.transpose().to_owned();
            lu::solve(factors.as_mut(), xt.as_mut(), Par::Seq)?;
            let mut x = xt.transpose().to_owned();
            x.symmetrize();
            let gain = gain.to_faer();
            let residual = general_residual(a, b, q.as_faer(), options.s, Some(e), &x, &gain)?;
            (from_faer(x.as_ref()), residual)
        }
        None => (y, reduced_residual),
    };
    Ok(CareDense {
        x,
        gain,
        closed_loop_eigenvalues,
        residual,
        rcond,
        refinement_steps,
        balancing,
    })
}

/// The checks shared by the algebraic and differential Riccati equations: A square and finite,
/// B with n rows, Q (n x n) and R (m x m) finite and symmetric, R positive definite. Returns
/// Q symmetrised and the Cholesky factor L of R = L L^T.
pub(crate) fn check_problem(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    let n = a.nrows();
    check_rows(b, "B", n, "A")?;
    check_finite(b, "B")?;
    let q = symmetric(q, "Q", n, "A")?;
    let r = symmetric(r, "R", b.ncols(), "the columns of B")?;
    let l = cholesky(&r).ok_or_else(|| Error::NotPositiveDefinite {
        arg: "R",
        message: "R must be symmetric positive definite, but its Cholesky factorisation \
                  failed: R has an eigenvalue <= 0 (to working precision)"
            .into(),
    })?;
    Ok((q, l))
}

/// A square, finite, symmetric (to [`SYMMETRY_TOLERANCE`]) matrix, symmetrised.
pub(crate) fn symmetric(
    matrix: MatRef<'_, f64>,
    arg: &'static str,
    order: usize,
    other: &'static str,
) -> Result<DMatrix<f64>, Error> {
    check_square(matrix, arg)?;
    check_rows(matrix, arg, order, other)?;
    check_finite(matrix, arg)?;
    let mut symmetric = from_faer(matrix);
    let largest = max_abs(symmetric.as_faer());
    let asymmetry = (0..order)
        .flat_map(|j| (0..j).map(move |i| (i, j)))
        .map(|(i, j)| (symmetric[(i, j)] - symmetric[(j, i)]).abs())
        .fold(0.0, f64::max);
    if asymmetry > SYMMETRY_TOLERANCE * largest {
        let message = format!(
            "{arg} must be symmetric, but max|{arg} - {arg}^T| = {asymmetry:.3e} is more than \
             {SYMMETRY_TOLERANCE:.0e} times max|{arg}| = {largest:.3e}"
        );
        return Err(if arg == "R" {
            Error::NotPositiveDefinite { arg, message }
        } else {
            Error::InvalidArgument { arg, message }
        });
    }
    symmetric.symmetrize();
    Ok(symmetric)
}

/// (E^-1 A, E^-1 B), refusing an E that is singular to working precision.
fn remove_descriptor(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    e: MatRef<'_, f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), Error> {
    let n = a.nrows();
    check_square(e, "E")?;
    check_rows(e, "E", n, "A")?;
    check_finite(e, "E")?;
    let m = b.ncols();
    let mut plant = Mat::<f64>::zeros(n, n + m);
    plant.as_mut().subcols_mut(0, n).copy_from(a);
    plant.as_mut().subcols_mut(n, m).copy_from(b);
    let combined = solve_with_inverse(e.to_owned().as_mut(), plant.as_ref())?;
    let (solution, inverse) = combined.as_ref().split_at_col(n + m);
    let condition = one_norm(e) * one_norm(inverse);
    // (A solve that broke down gives a NaN condition number, which the finiteness test catches.)
    let singular = !inverse.is_all_finite() || condition * f64::EPSILON * n.max(1) as f64 > 1.0;
    if singular {
        return Err(Error::InvalidArgument {
            arg: "E",
            message: format!(
                "E must be nonsingular, but its condition number is {condition:.3e}: \
                 singular to working precision"
            ),
        });
    }
    Ok((
        from_faer(solution.subcols(0, n)),
        from_faer(solution.subcols(n, m)),
    ))
}

/// Ā = Ã - B̂ Ŝ^T, G = B̂ B̂^T, Q̄ = Q - Ŝ Ŝ^T with B̂ = B̃ L^-T, Ŝ = S L^-T.
pub(crate) fn standardize(
    a_tilde: &DMatrix<f64>,
    b_tilde: &DMatrix<f64>,
    q: &DMatrix<f64>,
    l: &DMatrix<f64>,
    s: Option<&DMatrix<f64>>,
) -> Standard {
    // X L^T = Y  <=>  L X^T = Y^T: returns X^T.
    let right_divide_transposed = |y: &DMatrix<f64>| {
        let mut transposed = y.transpose();
        solve_lower_in_place(l, &mut transposed);
        transposed
    };
    let b_hat_t = right_divide_transposed(b_tilde);
    let b_hat = b_hat_t.transpose();
    let mut g = product(&b_hat, &b_hat_t);
    g.symmetrize();
    let (a, q) = match s {
        Some(s) => {
            let s_hat_t = right_divide_transposed(s);
            let mut a = product(&b_hat, &s_hat_t);
            for (x, &v) in a.as_mut_slice().iter_mut().zip(a_tilde.as_slice()) {
                *x = v - *x;
            }
            let mut q_bar = product(&s_hat_t.transpose(), &s_hat_t);
            for (x, &v) in q_bar.as_mut_slice().iter_mut().zip(q.as_slice()) {
                *x = v - *x;
            }
            q_bar.symmetrize();
            (a, q_bar)
        }
        None => (a_tilde.clone(), q.clone()),
    };
    Standard { a, g, q }
}

/// Y from the ordered Schur form of the scaled Hamiltonian, rcond(U11), the stable
/// eigenvalues of H (the scalings are similarities, so they are the Hamiltonian's own), and
/// above [`KRONECKER_MAX_ORDER`] the closed loop's Schur-like factorisation for the first
/// Newton step (up to that order an exact step, solved directly, costs less).
pub(crate) struct HamiltonianSolution {
    pub(crate) y: DMatrix<f64>,
    pub(crate) rcond: f64,
    pub(crate) stable_eigenvalues: Vec<c64>,
    closed_loop: Option<ClosedLoopFactors>,
    /// D of the symplectic balancing diag(D, D^-1).
    balancing: Vec<f64>,
}

/// The closed loop of the Schur solution as V T11 V^-1.
///
/// With the reordered Schur form of the scaled Hamiltonian Ĥ [U11; U21] = [U11; U21] T11
/// (T11 quasi-triangular, its eigenvalues the stable ones) and Y' = U21 U11^-1, the top block
/// rows read (Â - Ĝ Y') U11 = U11 T11; undoing the balancing Â = D^-1 Ā D, Ĝ Y' = D^-1 G Y D
/// (the scaling by ρ cancels), the closed loop of Y is
///
/// ```text
/// Ā - G Y = V T11 V^-1,      V = D U11.
/// ```
///
/// The Newton step's Lyapunov equation (Ā - G Y)^T Δ + Δ (Ā - G Y) = -Res then becomes
/// T11^T W + W T11 = -V^T Res V with Δ = V^-T W V^-1: a quasi-triangular solve (Bartels &
/// Stewart's second half) without the Schur form of the closed loop, which is most of the
/// cost of a Lyapunov solve (at n = 64, 0.5 of 0.75 ms). The factorisation holds for the
/// Schur solution only up to rounding amplified by κ(U11); the step is therefore an inexact
/// Newton step, kept like every step only if it reduces the residual.
struct ClosedLoopFactors {
    /// T11, the leading n x n block of the reordered Schur form of the scaled Hamiltonian, or
    /// of its partial Schur form ([`Until::UnstableHalf`]), where it is upper Hessenberg.
    t11: DMatrix<f64>,
    /// For a Hessenberg T11, estimates of its eigenvalues (shifts for its Schur form).
    hessenberg: Option<Vec<c64>>,
    /// V = D U11.
    v: DMatrix<f64>,
    /// U11^-T (formed anyway for rcond(U11)).
    inverse_transposed: DMatrix<f64>,
    d: Vec<f64>,
}

impl ClosedLoopFactors {
    /// Δ solving (Ā - G Y)^T Δ + Δ (Ā - G Y) = -Res for the Schur solution's Y.
    fn newton_step(&self, residual: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
        let (n, d) = (self.d.len(), &self.d);
        // A Hessenberg T11 = Q S Q^T: V T11 V^-1 = (V Q) S (V Q)^-1, and (V Q)^-T = V^-T Q.
        let triangularised = match &self.hessenberg {
            Some(estimates) => {
                let schur = real_schur_with(self.t11.as_faer(), Spectrum::Near(estimates))?;
                let q = from_faer(schur.z.as_ref());
                Some((
                    from_faer(schur.t.as_ref()),
                    product(&self.v, &q),
                    product(&self.inverse_transposed, &q),
                ))
            }
            None => None,
        };
        let (t11, v, inverse_transposed) = match &triangularised {
            Some((t11, v, inverse_transposed)) => (t11, v, inverse_transposed),
            None => (&self.t11, &self.v, &self.inverse_transposed),
        };
        let f = product(&transposed_product(v, residual), v);
        // T11^T W + W T11 = F is T W' + W' T^T = F' for T = P T11^T P and W' = P W P, F' = P F P
        // with P the reversal permutation: T is quasi-upper-triangular with standard blocks.
        let reverse = |i: usize| n - 1 - i;
        let t = DMatrix::from_fn(n, n, |i, j| t11[(reverse(j), reverse(i))]);
        let f_reversed = DMatrix::from_fn(n, n, |i, j| -f[(reverse(i), reverse(j))]);
        let w_reversed = lyapunov::solve_quasi_triangular(&t, f_reversed, Singularity::Perturb)?;
        let w = DMatrix::from_fn(n, n, |i, j| w_reversed[(reverse(i), reverse(j))]);
        // Δ = V^-T W V^-1 = D^-1 U11^-T W U11^-1 D^-1.
        let m = product(
            &product(inverse_transposed, &w),
            &inverse_transposed.transpose(),
        );
        let mut delta = DMatrix::from_fn(n, n, |i, j| m[(i, j)] / (d[i] * d[j]));
        delta.symmetrize();
        Ok(delta)
    }
}

pub(crate) fn hamiltonian_solution(standard: &Standard) -> Result<HamiltonianSolution, Error> {
    with_order!(2 * standard.a.nrows(), order => hamiltonian_solution_in(order, standard))
}

/// [`hamiltonian_solution`] with H of the order type `order` (2n).
fn hamiltonian_solution_in<O: Order>(
    order: O,
    standard: &Standard,
) -> Result<HamiltonianSolution, Error> {
    // n from the order type: a constant at the fixed orders, so that the loops over the
    // blocks of H unroll.
    let n = order.value() / 2;
    debug_assert_eq!(n, standard.a.nrows());
    let (g_norm, q_norm) = (
        frobenius_norm(standard.g.as_faer()),
        frobenius_norm(standard.q.as_faer()),
    );
    let rho = if g_norm > 0.0 && q_norm > 0.0 {
        nearest_power_of_two((q_norm / g_norm).sqrt())
    } else {
        1.0
    };
    // Powers of two: their reciprocals are exact, and multiplying by them rounds as dividing.
    let rho_inverse = 1.0 / rho;
    let mut h = order.zeros();
    for j in 0..n {
        for i in 0..n {
            h[(i, j)] = standard.a[(i, j)];
            h[(i, n + j)] = -rho * standard.g[(i, j)];
            h[(n + i, j)] = -standard.q[(i, j)] * rho_inverse;
            h[(n + i, n + j)] = -standard.a[(j, i)];
        }
    }
    // The symplectic balancing diag(D, D^-1): d_i from the balancing of rows i and n + i.
    let scale = balance(&mut h.clone());
    let d: Vec<f64> = (0..n)
        .map(|i| nearest_power_of_two((scale[i] / scale[n + i]).sqrt()))
        .collect();
    let d_inverse: Vec<f64> = d.iter().map(|x| 1.0 / x).collect();
    for j in 0..n {
        for i in 0..n {
            h[(i, j)] *= d[j] * d_inverse[i];
            h[(i, n + j)] *= d_inverse[i] * d_inverse[j];
            h[(n + i, j)] *= d[i] * d[j];
            h[(n + i, n + j)] *= d[i] * d_inverse[j];
        }
    }
    // Entries near the largest doubles (A of 1e308) can overflow in the scalings: the
    // Hamiltonian itself then has no double-precision Schur form, and the equation is refused
    // as such (not as a non-finite A, which the caller's A is not).
    if !h.iter().all(|x| x.is_finite()) {
        return Err(hamiltonian_out_of_range());
    }
    let h_norm = frobenius_norm(h.as_faer());
    let spectrum = if 2 * n <= HAMILTONIAN_SHIFT_MAX_ORDER {
        Spectrum::Hamiltonian
    } else {
        Spectrum::General
    };
    let margin = AXIS_TOLERANCE * h_norm;
    let (schur, finished) = square_schur_form(h, spectrum, Until::UnstableHalf { margin })?;
    // Views of T / t_scale and Z: of the partial form as the iteration left it, or of the
    // complete form reordered.
    let ordered;
    let (t, z, t_scale, stable_eigenvalues) = match finished {
        // The trailing half holds the unstable eigenvalues, each with Re λ > the margin, and
        // the leading Hessenberg block the stable ones: by the symmetry of the spectrum their
        // mirror images -λ̄.
        Finished::UnstableHalf => {
            let unstable = quasi_triangular_eigenvalues(schur.t.as_faer().submatrix(n, n, n, n));
            let stable = unstable
                .iter()
                .map(|z| c64::new(-z.re, z.im) * schur.scale)
                .collect();
            (schur.t.as_faer(), schur.z.as_faer(), schur.scale, stable)
        }
        Finished::Complete => {
            let complete = RealSchur {
                t: schur.t.to_faer_scaled(schur.scale),
                z: schur.z.to_faer(),
            };
            ordered = reorder_schur(complete, |lambda| lambda.re < 0.0)?;
            check_separated(&ordered.eigenvalues, ordered.selected, n, margin)?;
            let stable = ordered.eigenvalues[..n].to_vec();
            (ordered.t.as_ref(), ordered.z.as_ref(), 1.0, stable)
        }
    };
    // U11^T Y'^T = U21^T, with U11^-T for rcond(U11): the right-hand sides [U21^T | I].
    let u11 = from_faer(z.submatrix(0, 0, n, n));
    let mut factors = u11.transpose();
    let mut combined = DMatrix::zeros(n, 2 * n);
    for j in 0..n {
        for i in 0..n {
            combined[(i, j)] = z[(n + j, i)];
        }
        combined[(j, n + j)] = 1.0;
    }
    lu::solve(factors.as_faer_mut(), combined.as_faer_mut(), Par::Seq)?;
    let inverse_transposed = DMatrix::from_fn(n, n, |i, j| combined[(i, n + j)]);
    let broke_down = !combined.as_slice().iter().all(|x| x.is_finite());
    // A solve that broke down (an exactly singular U11: inf / inf) has rcond 0.
    let rcond = match 1.0
        / (one_norm(u11.as_faer()) * one_norm(inverse_transposed.as_faer().transpose()))
    {
        _ if broke_down => 0.0,
        value if value.is_nan() => 0.0,
        value => value,
    };
    if rcond <= n as f64 * f64::EPSILON {
        return Err(Error::IllConditioned {
            message: format!(
                "the stable invariant subspace of the Hamiltonian is not the graph of a matrix \
                 (U11 is singular to working precision, rcond = {rcond:.2e}): (A, B) is \
                 probably not stabilisable, or (Q, A) not detectable"
            ),
        });
    }
    // Undo the scalings: Y = rho D^-1 Y' D^-1, Y' the transpose of the solve's first n columns.
    let mut y = DMatrix::from_fn(n, n, |i, j| {
        rho * combined[(j, i)] * (d_inverse[i] * d_inverse[j])
    });
    y.symmetrize();
    let closed_loop = (n > KRONECKER_MAX_ORDER).then(|| ClosedLoopFactors {
        t11: DMatrix::from_fn(n, n, |i, j| t[(i, j)] * t_scale),
        hessenberg: (finished == Finished::UnstableHalf).then(|| stable_eigenvalues.clone()),
        v: DMatrix::from_fn(n, n, |i, j| d[i] * u11[(i, j)]),
        inverse_transposed,
        d: d.clone(),
    });
    Ok(HamiltonianSolution {
        y,
        rcond,
        stable_eigenvalues,
        closed_loop,
        balancing: d,
    })
}

/// The error for a Hamiltonian with eigenvalues within `margin` of the imaginary axis, or whose
/// complete, reordered Schur form does not lead with exactly n stable ones (`selected`).
fn check_separated(
    eigenvalues: &[c64],
    selected: usize,
    n: usize,
    margin: f64,
) -> Result<(), Error> {
    let on_axis: Vec<c64> = eigenvalues
        .iter()
        .copied()
        .filter(|lambda| lambda.re.abs() <= margin)
        .collect();
    if on_axis.is_empty() && selected == n {
        return Ok(());
    }
    let listed: Vec<String> = on_axis
        .iter()
        .map(|z| crate::error::format_complex(*z))
        .collect();
    Err(Error::NoStabilizingSolution {
        message: format!(
            "the Riccati equation has no stabilising solution: the Hamiltonian matrix has {} \
             eigenvalue(s) on the imaginary axis to working precision ({}; |Re| <= {:.1e} \
             ||H||), so some undamped mode can be neither moved by B nor seen by Q",
            on_axis.len().max(2 * n - 2 * selected.min(n)),
            if listed.is_empty() {
                "stable and unstable eigenvalues do not pair up".to_owned()
            } else {
                listed.join(", ")
            },
            AXIS_TOLERANCE
        ),
    })
}

/// The error for a solution whose closed loop is not stable to working precision: an
/// eigenvalue of A - B K with Re λ > -[`AXIS_TOLERANCE`] ||A - B K||_F (on or beyond the
/// imaginary axis, within rounding). This happens when the Hamiltonian's eigenvalues were
/// separated by the axis but some pair was so ill-conditioned that the computed stable subspace
/// is not the stable one; typically an undamped mode that B cannot move, whose double
/// eigenvalue on the axis rounding has split into a pair just off it (a cross term S hides it
/// from the Hamiltonian's own test).
fn check_stabilising(closed_loop_eigenvalues: &[c64], closed_loop_norm: f64) -> Result<(), Error> {
    let margin = AXIS_TOLERANCE * closed_loop_norm;
    let unstable: Vec<String> = closed_loop_eigenvalues
        .iter()
        .filter(|lambda| lambda.re.is_nan() || lambda.re >= -margin)
        .map(|z| crate::error::format_complex(*z))
        .collect();
    if unstable.is_empty() {
        return Ok(());
    }
    Err(Error::NoStabilizingSolution {
        message: format!(
            "the Riccati equation has no stabilising solution to working precision: the \
             computed solution leaves the closed loop with {} eigenvalue(s) of A - B K on or \
             beyond the imaginary axis ({}; Re >= -{margin:.1e} = -{AXIS_TOLERANCE:.1e} \
             ||A - BK||), so some undamped or unstable mode can be neither moved by B nor \
             separated from its mirror image",
            unstable.len(),
            unstable.join(", ")
        ),
    })
}

/// Newton (Kleinman) steps while the residual decreases and is above [`REFINEMENT_FLOOR`] times
/// the size of the terms; returns the number accepted, and leaves `evaluation` that of the
/// final Y. The step solves (Ã - B̃ K)^T Δ + Δ (Ã - B̃ K) = -Res(Y), K the gain of Y.
///
/// The first step, from the Schur solution, uses the closed loop's factors V T11 V^-1 from the
/// Hamiltonian ([`ClosedLoopFactors`]) when they are given; should that inexact step not reduce
/// the residual, an exact one follows.
fn refine(
    reduced: &Reduced<'_>,
    y: &mut DMatrix<f64>,
    evaluation: &mut Evaluation,
    mut factors: Option<ClosedLoopFactors>,
) -> usize {
    let mut steps = 0;
    let floor = REFINEMENT_FLOOR * evaluation.scale;
    while steps < MAX_REFINEMENT_STEPS && evaluation.residual_norm > floor {
        let inexact = factors.take();
        let step = match &inexact {
            Some(factors) => factors.newton_step(&evaluation.residual),
            None => {
                let closed_loop = reduced.closed_loop(&evaluation.gain);
                lyapunov::solve(
                    closed_loop.as_faer().transpose(),
                    evaluation.residual.as_faer(),
                    Singularity::Perturb,
                )
                .map(|delta| from_faer(delta.as_ref()))
            }
        };
        let improved = step.ok().and_then(|delta| {
            let mut candidate = y.clone();
            for (x, &v) in candidate.as_mut_slice().iter_mut().zip(delta.as_slice()) {
                *x += v;
            }
            candidate.symmetrize();
            let candidate_evaluation = reduced.evaluate(&candidate);
            let norm = candidate_evaluation.residual_norm;
            (norm < evaluation.residual_norm).then_some((candidate, candidate_evaluation))
        });
        match improved {
            Some((candidate, candidate_evaluation)) => {
                *y = candidate;
                *evaluation = candidate_evaluation;
                steps += 1;
            }
            // The inexact first step did not help: an exact one instead.
            None if inexact.is_some() => {}
            None => break,
        }
    }
    steps
}

/// The relative residual of A^T X E + E^T X A - M^T K + Q = 0, M = B^T X E + S^T (E = I where
/// none is given); its products stop when the computation is interrupted.
fn general_residual(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    s: Option<MatRef<'_, f64>>,
    e: Option<MatRef<'_, f64>>,
    x: &Mat<f64>,
    gain: &Mat<f64>,
) -> Result<f64, Error> {
    let xe = match e {
        Some(e) => product::product(x.as_ref(), e)?,
        None => x.clone(),
    };
    let axe = product::product(a.transpose(), xe.as_ref())?;
    let mut m = product::product(b.transpose(), xe.as_ref())?;
    if let Some(s) = s {
        m += s.transpose();
    }
    let quadratic = product::product(m.transpose(), gain.as_ref())?;
    let residual = &axe + axe.transpose() - &quadratic + q;
    let scale = frobenius_norm(q.as_ref())
        + 2.0 * frobenius_norm(axe.as_ref())
        + frobenius_norm(quadratic.as_ref());
    Ok(relative(frobenius_norm(residual.as_ref()), scale))
}

/// ||Res|| / scale, or ||Res|| itself when every term is zero.
fn relative(residual_norm: f64, scale: f64) -> f64 {
    if scale > 0.0 {
        residual_norm / scale
    } else {
        residual_norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_matrices::seeded;

    #[test]
    fn large_regulators_through_the_multishift_schur_form() {
        // n = 40 (Hamiltonian of order 80) and 150 (order 300): the Schur form of the
        // Hamiltonian by the multishift iteration, reordered; A^T X + X A - X B B^T X + I = 0
        // and A - B K stable.
        for n in [40usize, 150] {
            let g = seeded(n, n, 3);
            let a = Mat::from_fn(n, n, |i, j| {
                g[(i, j)] / (n as f64).sqrt() - if i == j { 1.5 } else { 0.0 }
            });
            let b = seeded(n, 2, 4);
            let (q, r) = (Mat::<f64>::identity(n, n), Mat::<f64>::identity(2, 2));
            let care = solve_care(
                a.as_ref(),
                b.as_ref(),
                q.as_ref(),
                r.as_ref(),
                CareOptions::default(),
            )
            .unwrap();
            let x = &care.x;
            let equation = a.transpose() * x + x * &a - x * &b * b.transpose() * x + &q;
            let scale = q.norm_l2() + 2.0 * (a.transpose() * x).norm_l2();
            let residual = equation.norm_l2() / scale;
            assert!(residual < 1e-12, "n={n}: residual {residual}");
            assert!(
                care.closed_loop_eigenvalues.iter().all(|z| z.re < 0.0),
                "n={n}: closed loop"
            );
        }
    }

    /// Up to `KRONECKER_MAX_ORDER` the Newton steps are exact steps solved directly, above it
    /// the first goes through the Hamiltonian's factors. On random regulators of orders 1 to 7
    /// with control weights over six decades, refinement never leaves a larger residual than
    /// the Schur solution's, takes steps from order 3 on, and ends within 64 u (measured: at
    /// most 37 u, at rcond(U11) = 5e-4, from Schur solutions of up to 8600 u; 52 steps).
    #[test]
    fn refinement_reduces_the_residual_of_small_regulators() {
        let mut steps = 0;
        for n in 1..=7usize {
            for seed in 0..12u64 {
                let g = seeded(n, n, 300 + 10 * n as u64 + seed);
                let a = Mat::from_fn(n, n, |i, j| g[(i, j)] - if i == j { 0.3 } else { 0.0 });
                let b = seeded(n, 2, 400 + seed);
                let q = Mat::<f64>::identity(n, n);
                let r = Mat::<f64>::identity(2, 2) * faer::Scale(10f64.powi(seed as i32 % 7 - 3));
                let solve = |refine| {
                    let options = CareOptions {
                        refine,
                        ..CareOptions::default()
                    };
                    solve_care(a.as_ref(), b.as_ref(), q.as_ref(), r.as_ref(), options).unwrap()
                };
                let (refined, schur) = (solve(true), solve(false));
                let what = format!("n={n} seed={seed}");
                assert!(refined.residual <= schur.residual, "{what}");
                assert!(refined.residual <= 64.0 * f64::EPSILON, "{what}");
                steps += refined.refinement_steps;
            }
        }
        assert!(steps >= 20, "{steps} Newton steps in 84 problems");
    }

    #[test]
    fn an_unstable_closed_loop_is_refused() {
        assert!(check_stabilising(&[c64::new(-1.0, 2.0), c64::new(-1.0, -2.0)], 3.0).is_ok());
        let refused = check_stabilising(
            &[
                c64::new(-1.0, 0.0),
                c64::new(0.0, 0.0),
                c64::new(f64::NAN, 0.0),
                // Within rounding of the axis, for a closed loop of norm 2: on it.
                c64::new(-2.8e-17, 1.0),
            ],
            2.0,
        );
        match refused {
            Err(Error::NoStabilizingSolution { message }) => {
                assert!(message.contains("3 eigenvalue(s)"), "{message}")
            }
            other => panic!("{other:?}"),
        }
    }

    /// An undamped mode that B cannot move has no stabilising solution, with or without a
    /// cross term S (which hides it from the Hamiltonian's test: the computed closed loop
    /// keeps it at -3e-17 ± 1j).
    #[test]
    fn an_uncontrollable_undamped_mode_is_refused_with_a_cross_term() {
        let a = faer::mat![[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
        let b = faer::mat![[0.0], [0.0], [1.0]];
        let q = Mat::<f64>::identity(3, 3);
        let r = Mat::<f64>::identity(1, 1);
        for s in [None, Some(faer::mat![[0.1], [0.2], [0.3]])] {
            let options = CareOptions {
                s: s.as_ref().map(|s| s.as_ref()),
                e: None,
                refine: true,
                s_name: None,
            };
            let solved = solve_care(a.as_ref(), b.as_ref(), q.as_ref(), r.as_ref(), options);
            assert!(
                matches!(solved, Err(Error::NoStabilizingSolution { .. })),
                "{:?}",
                solved.map(|care| care.closed_loop_eigenvalues)
            );
        }
    }

    /// The first Newton step through the Hamiltonian's factors V T11 V^-1 is the exact step
    /// (a Lyapunov solve with the closed loop) up to rounding, with and without a cross term,
    /// through the double-shift (n = 6, 30) and the multishift (n = 60) Schur forms: measured
    /// 2e-15, 3e-14 and 6e-13 relative.
    #[test]
    fn newton_step_from_the_hamiltonian_factors_is_the_exact_step() {
        for (n, with_cross_term) in [(6usize, false), (6, true), (30, true), (60, false)] {
            let g = seeded(n, n, 11 + n as u64);
            let a = Mat::from_fn(n, n, |i, j| {
                g[(i, j)] / (n as f64).sqrt() - if i == j { 0.5 } else { 0.0 }
            });
            let b = seeded(n, 2, 12);
            let q = Mat::<f64>::identity(n, n);
            let r = Mat::from_fn(2, 2, |i, j| if i == j { 2.0 } else { 0.5 });
            let s = seeded(n, 2, 13) * faer::Scale(0.1);
            let s = with_cross_term.then(|| from_faer(s.as_ref()));
            let (q, l) = check_problem(a.as_ref(), b.as_ref(), q.as_ref(), r.as_ref()).unwrap();
            let (a_tilde, b_tilde) = (from_faer(a.as_ref()), from_faer(b.as_ref()));
            let standard = standardize(&a_tilde, &b_tilde, &q, &l, s.as_ref());
            let reduced = Reduced {
                a: &a_tilde,
                b: &b_tilde,
                q: &q,
                q_norm: frobenius_norm(q.as_faer()),
                s: s.as_ref(),
                l: &l,
            };
            let solution = hamiltonian_solution(&standard).unwrap();
            let evaluation = reduced.evaluate(&solution.y);
            let inexact = solution
                .closed_loop
                .expect("factors above KRONECKER_MAX_ORDER")
                .newton_step(&evaluation.residual)
                .unwrap()
                .to_faer();
            let exact = lyapunov::solve(
                reduced.closed_loop(&evaluation.gain).as_faer().transpose(),
                evaluation.residual.as_faer(),
                Singularity::Perturb,
            )
            .unwrap();
            let difference = (&inexact - &exact).norm_l2() / exact.norm_l2();
            assert!(
                difference < 1e-10,
                "n={n} cross term {with_cross_term}: steps differ by {difference:e}"
            );
        }
    }
}
