//! Pole placement by state feedback (chapter §6.5): the gain K of the control law
//! η = -K x + η' (6.91) that gives the closed-loop matrix A* = A - B K (6.93) the requested
//! eigenvalues.
//!
//! # Single input: Bass–Gura and Ackermann
//!
//! With V = [b Ab ... A^{n-1}b] (6.125), W the upper triangular Toeplitz matrix of the open-loop
//! coefficients a_i (6.131) and T = (VW)^-1 (6.144) the transformation to the first companion
//! form (6.116), the gains in companion coordinates are k̄_i = ā_i - a_i (6.137) and in the
//! original ones (Bass–Gura, (6.145))
//!
//! ```text
//! k = ((VW)^-1)^T k̄,   computed as   W^T z = k̄ (forward substitution),  V^T k = z (LU).
//! ```
//!
//! Ackermann's formula k^T = e_n^T V^-1 φ(A), with φ the desired characteristic polynomial, is
//! computed as V^T w = e_n (the same LU) and k = φ(A)^T w by Horner's rule on vectors, so that
//! φ(A) is never formed. Both are as accurate as V is well conditioned: the computed gains are
//! the exact gains of a system perturbed by about u κ(V) relatively, and κ(V) grows
//! geometrically with n. Each result therefore reports κ_1(V) (the norm of V^-1 is taken from
//! the LU solves, for the condition number only; the gains never use an inverse) and the poles
//! of the computed A - b k^T.
//!
//! # Several inputs: Kautsky–Nichols–Van Dooren
//!
//! With m inputs the gain is not unique, and the robust method of Kautsky, Nichols & Van Dooren
//! (1985, method 0) uses the freedom to make the closed-loop eigenvector matrix X as well
//! conditioned as it can, which makes the placed poles insensitive to perturbations. With
//! B = [U0 U1] [Z; 0] (QR, Z invertible when B has full column rank), the eigenvector x_j of
//! λ_j must lie in S_j, the null space of U1^T (A - λ_j I); an orthonormal basis is the last m
//! columns of the full QR factor of (A - λ_j I)^H U1. Method 0 sweeps over the columns: x_j is
//! replaced by the normalised projection onto S_j of the vector orthogonal to all other
//! columns (the j-th column of X^-H), which maximises |det X| over x_j. A complex pair is one
//! step: x_{j+1} = conj(x_j), so X Λ X^-1 stays real. The sweeps stop when |det X| changes by
//! less than [`KNV_RELATIVE_TOLERANCE`] (or after [`KNV_MAX_SWEEPS`]; the result then says it
//! did not converge, and is still a valid placement). Finally M = X Λ X^-1 and
//! K = Z^-1 U0^T (A - M).
//!
//! A pole may be repeated at most rank(B) = m times (S_j has dimension m, and the eigenvectors
//! of a repeated pole must be independent).
//!
//! # Achieved poles
//!
//! Every result carries the eigenvalues of the computed A - B K, each matched to the nearest
//! requested pole, and the largest relative error |λ_achieved - λ| / |λ| (relative to
//! ||A - BK||_F for a pole at 0).

use crate::control::controllability::{controllability, controllability_staircase, krylov_blocks};
use crate::control::modal::polynomial_from_roots;
use crate::error::{Error, check_finite, check_rows, check_square, format_complex};
use crate::linalg::balance::{balanced_where_scaled_apart, range_scale, scale_for_largest};
use crate::linalg::charpoly::charpoly;
use crate::linalg::lu::{Lu, solve_with_inverse};
use crate::linalg::norm::{frobenius_norm, max_abs, one_norm};
use crate::linalg::product::product;
use crate::linalg::schur::eigenvalues_near;
use crate::platform::interrupt;
use faer::{Mat, MatRef, c64};

/// Sweeps of method 0 stop when |det X| grows by less than this, relatively. Method 0
/// converges linearly and, after the first few sweeps, slowly (on the 747 lateral model with
/// two inputs |det X| grows 0.506, 0.632, 0.6337, then by 3e-5 per sweep); the conditioning
/// it buys beyond 1e-3 is negligible. (scipy's place_poles uses the same default.)
pub const KNV_RELATIVE_TOLERANCE: f64 = 1e-3;

/// κ_1(V) from which a single-input design is flagged (the Python layer warns): beyond 1e8
/// about half the digits of the gains may be lost to the conditioning of the controllability
/// matrix.
pub const ILL_CONDITIONED_CONTROLLABILITY: f64 = 1e8;

/// Achieved-pole relative error from which any design is flagged.
pub const POLE_ERROR_WARNING: f64 = 1e-6;
/// The most sweeps of method 0.
pub const KNV_MAX_SWEEPS: usize = 100;

/// Which algorithm placed the poles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    BassGura,
    Ackermann,
    KautskyNicholsVanDooren,
}

/// A state-feedback design u = -K x.
#[derive(Debug, Clone)]
pub struct Placement {
    /// K, m x n.
    pub gain: Mat<f64>,
    /// A - B K (6.93).
    pub closed_loop: Mat<f64>,
    /// The requested poles, conjugate pairs adjacent with Im > 0 first.
    pub poles: Vec<c64>,
    /// The eigenvalues of the computed A - B K, in the order of `poles`.
    pub achieved_poles: Vec<c64>,
    /// The largest relative error of an achieved pole.
    pub max_relative_error: f64,
    /// Sweeps of the robust method (0 for the single-input formulas).
    pub iterations: usize,
    /// Whether the robust method met its tolerance (always true for the others).
    pub converged: bool,
    /// κ_1(V) of the controllability matrix (single-input methods; NaN otherwise).
    pub controllability_condition: f64,
    /// κ_2(X) of the closed-loop eigenvector matrix (robust method; NaN otherwise).
    pub eigenvector_condition: f64,
    pub method: Method,
}

/// The transformation to the first companion form (6.116)-(6.145).
#[derive(Debug, Clone)]
pub struct CompanionForm {
    /// The controllability matrix V (6.125).
    pub v: Mat<f64>,
    /// W (6.131).
    pub w: Mat<f64>,
    /// T = (VW)^-1 (6.144), so that z = T x.
    pub t: Mat<f64>,
    /// The first companion form T A T^-1 (6.116), built from the coefficients.
    pub companion: Mat<f64>,
    /// The coefficients [1, a_1, ..., a_n] of det(λI - A) (6.106).
    pub coefficients: Vec<f64>,
}

/// The requested poles, checked and ordered: `n` finite values, every complex pole with its
/// conjugate (matched within 100 u |λ| and made exactly conjugate), each pair adjacent with
/// Im > 0 first, in the order the caller gave them.
pub fn normalize_poles(poles: &[c64], n: usize) -> Result<Vec<c64>, Error> {
    if poles.len() != n {
        return Err(Error::Mismatch {
            arg: "poles",
            what: "one entry per state of",
            expected: n,
            other: "A",
            got: poles.len(),
        });
    }
    for (i, p) in poles.iter().enumerate() {
        if !p.re.is_finite() || !p.im.is_finite() {
            let value = if p.re.is_finite() { p.im } else { p.re };
            return Err(Error::NonFinite {
                arg: "poles",
                index: vec![i],
                value,
            });
        }
    }
    let mut used = vec![false; n];
    let mut ordered = Vec::with_capacity(n);
    for i in 0..n {
        if used[i] {
            continue;
        }
        used[i] = true;
        let p = poles[i];
        if p.im == 0.0 {
            ordered.push(p);
            continue;
        }
        let tolerance = 100.0 * f64::EPSILON * p.norm();
        let partner = (i + 1..n)
            .filter(|&j| !used[j] && poles[j].im != 0.0)
            .find(|&j| (poles[j] - p.conj()).norm() <= tolerance);
        let Some(j) = partner else {
            return Err(Error::InvalidArgument {
                arg: "poles",
                message: format!(
                    "poles[{i}] = {} has no complex conjugate among the poles: a real gain \
                     places complex poles in conjugate pairs",
                    format_complex(p)
                ),
            });
        };
        used[j] = true;
        let upper = c64::new(0.5 * (p.re + poles[j].re), 0.5 * (p.im - poles[j].im).abs());
        ordered.push(upper);
        ordered.push(upper.conj());
    }
    Ok(ordered)
}

fn check_plant(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<(), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")
}

fn check_single_input(b: MatRef<'_, f64>, function: &str) -> Result<(), Error> {
    if b.ncols() == 1 {
        return Ok(());
    }
    Err(Error::InvalidArgument {
        arg: "B",
        message: format!(
            "B has {} columns, but {function} is for a single input (B of shape (n, 1)); use \
             place() for several inputs",
            b.ncols()
        ),
    })
}

/// Fails with the uncontrollable eigenvalues unless the staircase form of (A, b) fills the
/// state (the single-input check; [`place`] also applies the modal test).
fn require_controllable_single_input(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<(), Error> {
    let form = controllability_staircase(a, b, None, false)?;
    if form.is_complete() {
        return Ok(());
    }
    Err(Error::Uncontrollable {
        pair: "(A, B)",
        eigenvalues: form.uncontrollable_eigenvalues,
        tolerance: form.tolerance,
    })
}

/// The companion-form transformation of a controllable single-input pair.
pub fn companion_form(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<CompanionForm, Error> {
    check_plant(a, b)?;
    check_single_input(b, "companion_form")?;
    require_controllable_single_input(a, b)?;
    let n = a.nrows();
    let coefficients = charpoly(a)?;
    let v = krylov_blocks(a, b);
    let w = Mat::from_fn(n, n, |i, j| if j >= i { coefficients[j - i] } else { 0.0 });
    let t = Lu::new(product(v.as_ref(), w.as_ref())?.as_ref())?
        .solve(Mat::<f64>::identity(n, n).as_ref())?;
    let companion = Mat::from_fn(n, n, |i, j| match i {
        0 => -coefficients[j + 1],
        _ if j + 1 == i => 1.0,
        _ => 0.0,
    });
    Ok(CompanionForm {
        v,
        w,
        t,
        companion,
        coefficients,
    })
}

/// Single-input pole placement by the Bass–Gura formula (6.145), on balanced states
/// ([`on_balanced_states`]).
pub fn place_bass_gura(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    poles: &[c64],
) -> Result<Placement, Error> {
    on_balanced_states(a, b, |a, b| {
        place_single_input(a, b, poles, Method::BassGura)
    })
}

/// Single-input pole placement by Ackermann's formula, on balanced states
/// ([`on_balanced_states`]).
pub fn place_ackermann(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    poles: &[c64],
) -> Result<Placement, Error> {
    on_balanced_states(a, b, |a, b| {
        place_single_input(a, b, poles, Method::Ackermann)
    })
}

/// The design `placer` makes for (A, B), made for the pair with its states balanced where A's
/// states are scaled apart ([`balanced_where_scaled_apart`]: units 10^3 or more apart): with A' = T A T^-1 and B' = T B (T diagonal, of powers of two: exact), the gain K'
/// of the same poles gives K = K' T and A - B K = T^-1 (A' - B' K') T, while the methods'
/// errors are relative to the size of A' rather than of A (states scaled by 1e±6 came back
/// with poles 147 % off, or were refused as uncontrollable). The conditions reported are
/// those of the balanced problem, which bound the errors.
fn on_balanced_states(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    placer: impl FnOnce(MatRef<'_, f64>, MatRef<'_, f64>) -> Result<Placement, Error>,
) -> Result<Placement, Error> {
    let outputs = Mat::<f64>::zeros(0, a.nrows());
    let conformal = a.nrows() == a.ncols() && b.nrows() == a.nrows();
    let Some((a2, b2, _, t)) = conformal
        .then(|| balanced_where_scaled_apart(a, b, outputs.as_ref()))
        .flatten()
    else {
        return placer(a, b);
    };
    let mut design = placer(a2.as_ref(), b2.as_ref())?;
    let n = t.len();
    for j in 0..n {
        for i in 0..design.gain.nrows() {
            design.gain[(i, j)] *= t[j];
        }
        for i in 0..n {
            design.closed_loop[(i, j)] *= t[j] / t[i];
        }
    }
    Ok(design)
}

fn place_single_input(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    poles: &[c64],
    method: Method,
) -> Result<Placement, Error> {
    check_plant(a, b)?;
    let function = match method {
        Method::Ackermann => "place_ackermann",
        _ => "place_bass_gura",
    };
    check_single_input(b, function)?;
    let n = a.nrows();
    let poles = normalize_poles(poles, n)?;
    if n == 0 {
        return finish(
            a,
            b,
            Mat::zeros(1, 0),
            poles,
            method,
            1.0,
            f64::NAN,
            0,
            true,
        );
    }
    if let Some(scaled) = ScaledPlant::of(a, b, &poles, false) {
        let design =
            place_single_input(scaled.a.as_ref(), scaled.b.as_ref(), &scaled.poles, method)?;
        return scaled.unscale(a, b, poles, design);
    }
    let desired = polynomial_from_roots(&poles);
    if let Some(k) = desired.iter().position(|c| !c.is_finite()) {
        return Err(Error::InvalidArgument {
            arg: "poles",
            message: format!(
                "the characteristic polynomial of the poles overflows double precision (the \
                 coefficient of s^{} is {}): the poles are too large for a polynomial-based \
                 method; place() works without one",
                n - k,
                desired[k]
            ),
        });
    }
    let v = krylov_blocks(a, b);
    // One LU solve with V^T for the right-hand side and I: the first gives the gains, the
    // second V^-T, whose norm (and nothing else) gives κ_1(V).
    let mut rhs = Mat::<f64>::zeros(n, 1);
    match method {
        // Ackermann: V^T w = e_n.
        Method::Ackermann => rhs[(n.saturating_sub(1), 0)] = 1.0,
        // Bass–Gura: W^T z = k̄ (unit lower triangular Toeplitz), then V^T k = z.
        _ => {
            let open_loop = charpoly(a)?;
            for i in 0..n {
                let mut value = desired[i + 1] - open_loop[i + 1];
                for j in 0..i {
                    value -= open_loop[i - j] * rhs[(j, 0)];
                }
                rhs[(i, 0)] = value;
            }
        }
    }
    let v_norm = one_norm(v.as_ref());
    let mut factors = v;
    let combined = solve_with_inverse(factors.as_mut().transpose_mut(), rhs.as_ref())?;
    let (solution, inverse) = combined.as_ref().split_at_col(1);
    let condition = v_norm * one_norm(inverse);
    // V is exactly singular for an uncontrollable pair, but its computed condition number can
    // stay well below 1/u when A^k b loses digits to cancellation; from SCREEN_CONDITION on the
    // staircase decides (and names the eigenvalues it cannot move).
    // (A NaN condition number, from a V singular in floating point, also takes this branch.)
    if condition.is_nan() || condition >= SCREEN_CONDITION {
        require_controllable_single_input(a, b)?;
    }
    if !solution.is_all_finite() {
        return Err(Error::InvalidArgument {
            arg: "B",
            message: format!(
                "the controllability matrix of (A, b) is numerically singular (condition number \
                 {condition:.2e}): the pair is too close to uncontrollable for {function}; \
                 place() is more robust"
            ),
        });
    }
    let w = solution.col(0);
    let gain = match method {
        Method::Ackermann => {
            // k = φ(A)^T w by Horner's rule: y <- A^T y + ā_i w.
            let mut y: Vec<f64> = w.iter().copied().collect();
            let mut next = vec![0.0; n];
            for &coefficient in &desired[1..] {
                for (j, entry) in next.iter_mut().enumerate() {
                    let column = a.col(j);
                    *entry =
                        coefficient * w[j] + column.iter().zip(&y).map(|(x, z)| x * z).sum::<f64>();
                }
                std::mem::swap(&mut y, &mut next);
            }
            Mat::from_fn(1, n, |_, j| y[j])
        }
        _ => Mat::from_fn(1, n, |_, j| w[j]),
    };
    finish(a, b, gain, poles, method, condition, f64::NAN, 0, true)
}

/// κ_1(V) below which a single-input pair counts as controllable without the staircase test:
/// V is then at relative distance 1/κ >= 1e-6 from the nearest singular matrix, which no
/// rounding error in forming it explains.
const SCREEN_CONDITION: f64 = 1e6;

/// A plant whose largest entry (or pole) is outside [2^-100, 2^100], divided by the power of two s that
/// brings it near 1, with the poles likewise: A - B K has the eigenvalues p exactly when
/// A / s - (B / s) K has p / s, so the gain is the same, and the methods' products of entries
/// (A^k b, X Λ X^-1, U0^T (A - M)) stay in range. Plants in range are designed as they are.
struct ScaledPlant {
    a: Mat<f64>,
    b: Mat<f64>,
    poles: Vec<c64>,
}

impl ScaledPlant {
    /// The scaled plant, if it needs scaling; by the poles too when `by_poles` (for the robust
    /// method: the polynomial methods form A^k b, which a plant scaled to poles far from its
    /// eigenvalues would underflow, and check the poles' polynomial instead).
    fn of(a: MatRef<'_, f64>, b: MatRef<'_, f64>, poles: &[c64], by_poles: bool) -> Option<Self> {
        let largest_pole = poles
            .iter()
            .fold(0.0f64, |m, p| m.max(p.re.abs()).max(p.im.abs()));
        let largest = max_abs(a).max(max_abs(b));
        let scale = scale_for_largest(if by_poles {
            largest.max(largest_pole)
        } else {
            largest
        });
        (scale != 1.0).then(|| Self {
            a: Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] / scale),
            b: Mat::from_fn(b.nrows(), b.ncols(), |i, j| b[(i, j)] / scale),
            poles: poles.iter().map(|p| p / scale).collect(),
        })
    }

    /// The design of the scaled plant as a design of (A, B): the same gain, verified on A - B K.
    fn unscale(
        &self,
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        poles: Vec<c64>,
        design: Placement,
    ) -> Result<Placement, Error> {
        finish(
            a,
            b,
            design.gain,
            poles,
            design.method,
            design.controllability_condition,
            design.eigenvector_condition,
            design.iterations,
            design.converged,
        )
    }
}

/// The closed loop, its poles matched to the requested ones, and the result.
#[allow(clippy::too_many_arguments)]
fn finish(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    gain: Mat<f64>,
    poles: Vec<c64>,
    method: Method,
    controllability_condition: f64,
    eigenvector_condition: f64,
    iterations: usize,
    converged: bool,
) -> Result<Placement, Error> {
    if !gain.is_all_finite() {
        return Err(gain_overflow("the gain K"));
    }
    // A - B K entry by entry: at these sizes a general product costs more to dispatch than to
    // compute.
    let closed_loop = Mat::from_fn(a.nrows(), a.ncols(), |i, j| {
        a[(i, j)]
            - (0..gain.nrows())
                .map(|k| b[(i, k)] * gain[(k, j)])
                .sum::<f64>()
    });
    if !closed_loop.is_all_finite() {
        return Err(gain_overflow("the closed loop A - B K"));
    }
    // The requested poles as the QR iteration's shifts: near the eigenvalues when the design
    // succeeded, it then converges in fewer sweeps (and finds them as accurately either way).
    let computed = eigenvalues_near(closed_loop.as_ref(), &poles)?;
    let scale = frobenius_norm(closed_loop.as_ref());
    let mut taken = vec![false; computed.len()];
    let mut achieved_poles = Vec::with_capacity(poles.len());
    let mut max_relative_error = 0.0f64;
    for &pole in &poles {
        // Greedy matching: the nearest eigenvalue not yet taken.
        let nearest = nearest_untaken(&computed, &taken, pole);
        let distance = (computed[nearest] - pole).norm();
        taken[nearest] = true;
        achieved_poles.push(computed[nearest]);
        // Relative to the pole; a pole below u ||A - B K||_F (which no design places more
        // accurately) relative to ||A - B K||_F, as a zero pole is (a pole of 1e-301 beside a
        // closed loop of 1e149 made the relative error overflow).
        let reference = if pole.norm() > f64::EPSILON * scale {
            pole.norm()
        } else if scale > 0.0 {
            scale
        } else {
            1.0
        };
        max_relative_error = max_relative_error.max(distance / reference);
    }
    Ok(Placement {
        gain,
        closed_loop,
        poles,
        achieved_poles,
        max_relative_error,
        iterations,
        converged,
        controllability_condition,
        eigenvector_condition,
        method,
    })
}

/// The index of the value not yet taken nearest to `target` (the first of equally near ones).
/// Distances are compared by their squares when every square is a normal number (the same
/// order up to a rounding of the squares, without a hypot per pair), and by the distances
/// themselves when a square over- or underflows.
fn nearest_untaken(values: &[c64], taken: &[bool], target: c64) -> usize {
    let mut best = (usize::MAX, f64::INFINITY);
    for (k, &value) in values.iter().enumerate() {
        if taken[k] {
            continue;
        }
        let square = (value - target).norm_sqr();
        if !square.is_normal() {
            return values
                .iter()
                .enumerate()
                .filter(|&(k, _)| !taken[k])
                .map(|(k, &value)| (k, (value - target).norm()))
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .expect("a value not yet taken")
                .0;
        }
        if square < best.1 || best.0 == usize::MAX {
            best = (k, square);
        }
    }
    best.0
}

/// The error of a design whose gain or closed loop overflows double precision.
fn gain_overflow(what: &str) -> Error {
    Error::IllConditioned {
        message: format!(
            "{what} overflows double precision: the poles are too far from A's eigenvalues for \
             inputs as weak as B's (a gain beyond 1.8e308 would be needed)"
        ),
    }
}

/// Multi-input pole placement by the robust method of Kautsky, Nichols & Van Dooren, on
/// balanced states ([`on_balanced_states`]).
pub fn place(a: MatRef<'_, f64>, b: MatRef<'_, f64>, poles: &[c64]) -> Result<Placement, Error> {
    on_balanced_states(a, b, |a, b| place_robust(a, b, poles))
}

/// [`place`] of the pair as given.
fn place_robust(a: MatRef<'_, f64>, b: MatRef<'_, f64>, poles: &[c64]) -> Result<Placement, Error> {
    check_plant(a, b)?;
    let (n, m) = (a.nrows(), b.ncols());
    let poles = normalize_poles(poles, n)?;
    if n == 0 {
        // Nothing to place (and a 0 x m B has no columns to check).
        return finish(
            a,
            b,
            Mat::zeros(m, 0),
            poles,
            Method::KautskyNicholsVanDooren,
            f64::NAN,
            1.0,
            0,
            true,
        );
    }
    if let Some(scaled) = ScaledPlant::of(a, b, &poles, true) {
        let design = place(scaled.a.as_ref(), scaled.b.as_ref(), &scaled.poles)?;
        return scaled.unscale(a, b, poles, design);
    }
    let InputBasis { u0, u1, z } = input_basis(b)?;
    check_multiplicities(&poles, m)?;
    let verdict = controllability(a, b, None, true, false)?;
    if !verdict.is_complete() {
        return Err(Error::Uncontrollable {
            pair: "(A, B)",
            eigenvalues: verdict.uncontrollable_eigenvalues,
            tolerance: verdict.tolerance,
        });
    }
    let subspaces: Vec<Mat<c64>> = poles
        .iter()
        .map(|&p| {
            interrupt::check()?;
            eigenvector_subspace(a, u1.as_ref(), p)
        })
        .collect::<Result<_, _>>()?;
    let (x, iterations, converged) = knv_method_0(&poles, &subspaces)?;
    // M = X Λ X^-1 from X^T M^T = (X Λ)^T; real up to rounding.
    let x_lambda = Mat::from_fn(n, n, |i, j| x[(i, j)] * poles[j]);
    let m_transpose = Lu::new(x.transpose())?.solve(x_lambda.transpose())?;
    let target = Mat::from_fn(n, n, |i, j| m_transpose[(j, i)].re);
    // Z K = U0^T (A - M).
    let rhs = product(u0.transpose(), (a - &target).as_ref())?;
    let mut gain = rhs;
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        z.as_ref(),
        gain.as_mut(),
        faer::Par::Seq,
    );
    let condition = condition_number(&x);
    finish(
        a,
        b,
        gain,
        poles,
        Method::KautskyNicholsVanDooren,
        f64::NAN,
        condition,
        iterations,
        converged,
    )
}

/// B = [U0 U1] [Z; 0].
struct InputBasis {
    /// n x m: the range of B.
    u0: Mat<f64>,
    /// n x (n - m): its orthogonal complement.
    u1: Mat<f64>,
    /// m x m, upper triangular.
    z: Mat<f64>,
}

/// The QR basis of B, after checking that B has no zero column and full column rank.
fn input_basis(b: MatRef<'_, f64>) -> Result<InputBasis, Error> {
    let (n, m) = (b.nrows(), b.ncols());
    if m == 0 {
        return Err(Error::InvalidArgument {
            arg: "B",
            message: "B has no columns: there is no input to feed back to".into(),
        });
    }
    if let Some(j) = (0..m).find(|&j| b.col(j).iter().all(|&x| x == 0.0)) {
        return Err(Error::InvalidArgument {
            arg: "B",
            message: format!("column {j} of B is zero: that input acts on no state; remove it"),
        });
    }
    // The QR factors of B / s for the power of two s of B's largest entry (exact: the same Q,
    // and R times s), so that faer's reflectors see entries near 1 (a B of 1e-310 had rank 0).
    let scale = range_scale(b);
    let scaled = Mat::from_fn(n, m, |i, j| b[(i, j)] / scale);
    let qr = scaled.qr();
    let q = qr.compute_Q();
    let r = qr.R() * faer::Scale(scale);
    let tolerance = n.max(m) as f64 * f64::EPSILON * frobenius_norm(scaled.as_ref()) * scale;
    let rank = (0..m.min(n))
        .filter(|&k| r[(k, k)].abs() > tolerance)
        .count();
    if m > n || rank < m {
        return Err(Error::InvalidArgument {
            arg: "B",
            message: format!(
                "B has {m} columns but rank {rank}: its inputs are linearly dependent \
                 (tolerance {tolerance:.3e}); combine or remove the redundant ones"
            ),
        });
    }
    Ok(InputBasis {
        u0: q.subcols(0, m).to_owned(),
        u1: q.subcols(m, n - m).to_owned(),
        z: r.subrows(0, m).to_owned(),
    })
}

fn check_multiplicities(poles: &[c64], m: usize) -> Result<(), Error> {
    for (i, p) in poles.iter().enumerate() {
        let count = poles.iter().filter(|q| *q == p).count();
        if count > m {
            return Err(Error::InvalidArgument {
                arg: "poles",
                message: format!(
                    "poles[{i}] = {} is repeated {count} times, but B has rank {m}: state \
                     feedback can repeat a pole at most rank(B) times (place_bass_gura and \
                     place_ackermann accept any multiplicity for a single input)",
                    format_complex(*p)
                ),
            });
        }
    }
    Ok(())
}

/// An orthonormal basis S (n x m) of the null space of U1^T (A - λI): the last m columns of
/// the full QR factor of (A - λI)^H U1 = (A^T - conj(λ) I) U1.
fn eigenvector_subspace(
    a: MatRef<'_, f64>,
    u1: MatRef<'_, f64>,
    lambda: c64,
) -> Result<Mat<c64>, Error> {
    let n = a.nrows();
    let m = n - u1.ncols();
    if lambda.im == 0.0 {
        let shifted = Mat::from_fn(n, n, |i, j| {
            a[(j, i)] - if i == j { lambda.re } else { 0.0 }
        });
        let q = product(shifted.as_ref(), u1)?.qr().compute_Q();
        return Ok(Mat::from_fn(n, m, |i, j| c64::new(q[(i, n - m + j)], 0.0)));
    }
    let shifted = Mat::from_fn(n, n, |i, j| {
        let entry = c64::new(a[(j, i)], 0.0);
        if i == j { entry - lambda.conj() } else { entry }
    });
    let u1 = Mat::from_fn(n, u1.ncols(), |i, j| c64::new(u1[(i, j)], 0.0));
    let q = product(shifted.as_ref(), u1.as_ref())?.qr().compute_Q();
    Ok(q.subcols(n - m, m).to_owned())
}

/// A deterministic pseudo-random complex vector (the starting directions of method 0).
fn start_vector(n: usize, seed: usize) -> Mat<c64> {
    let mut state = (seed as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    Mat::from_fn(n, 1, |_, _| c64::new(next(), next()))
}

/// x <- S S^H y / ||S S^H y||; for a real pole (S real) the projection of Re y, so that its
/// eigenvector stays real.
fn project(s: &Mat<c64>, y: MatRef<'_, c64>, real: bool) -> Mat<c64> {
    let y = if real {
        Mat::from_fn(y.nrows(), 1, |i, _| c64::new(y[(i, 0)].re, 0.0))
    } else {
        y.to_owned()
    };
    let mut x = s * (s.adjoint() * &y);
    let norm = x.norm_l2();
    if norm > 0.0 {
        x *= faer::Scale(c64::new(1.0 / norm, 0.0));
    }
    x
}

/// KNV method 0 on the subspaces S_j: returns X, the sweeps made and whether |det X|
/// settled.
fn knv_method_0(poles: &[c64], subspaces: &[Mat<c64>]) -> Result<(Mat<c64>, usize, bool), Error> {
    let n = poles.len();
    let mut x = Mat::<c64>::zeros(n, n);
    // The columns that are free: a real pole, or the first of a pair (its partner follows).
    let free: Vec<usize> = (0..n).filter(|&j| poles[j].im >= 0.0).collect();
    let set_column = |x: &mut Mat<c64>, j: usize, column: &Mat<c64>| {
        for i in 0..n {
            x[(i, j)] = column[(i, 0)];
            if poles[j].im > 0.0 {
                x[(i, j + 1)] = column[(i, 0)].conj();
            }
        }
    };
    for &j in &free {
        let start = start_vector(n, j);
        let column = project(&subspaces[j], start.as_ref(), poles[j].im == 0.0);
        set_column(&mut x, j, &column);
    }
    let dimension = subspaces.first().map_or(0, |s| s.ncols());
    if dimension <= 1 {
        return Ok((x, 0, true));
    }
    let mut previous = Lu::new(x.as_ref())?.determinant().norm();
    for sweep in 1..=KNV_MAX_SWEEPS {
        for &j in &free {
            interrupt::check()?;
            // y = X^-H e_j is orthogonal to every other column of X.
            let mut e_j = Mat::<c64>::zeros(n, 1);
            e_j[(j, 0)] = c64::new(1.0, 0.0);
            let y = Lu::new(x.adjoint().to_owned().as_ref())?.solve(e_j.as_ref())?;
            let column = project(&subspaces[j], y.as_ref(), poles[j].im == 0.0);
            set_column(&mut x, j, &column);
        }
        let determinant = Lu::new(x.as_ref())?.determinant().norm();
        if (determinant - previous).abs() <= KNV_RELATIVE_TOLERANCE * determinant {
            return Ok((x, sweep, true));
        }
        previous = determinant;
    }
    Ok((x, KNV_MAX_SWEEPS, false))
}

fn condition_number(x: &Mat<c64>) -> f64 {
    match x.singular_values() {
        Ok(s) if !s.is_empty() && s[s.len() - 1] > 0.0 => s[0] / s[s.len() - 1],
        Ok(s) if s.is_empty() => 1.0,
        _ => f64::INFINITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::balance::states_scaled_apart;
    use crate::linalg::schur::eigenvalues;
    use faer::mat;

    fn real(values: &[f64]) -> Vec<c64> {
        values.iter().map(|&v| c64::new(v, 0.0)).collect()
    }

    use crate::test_matrices::lateral_747 as lateral;

    /// (6.156): the Dutch roll pair moved to ζ = 0.30 at its ω_n, the other roots kept.
    fn dutch_roll_request(a: MatRef<'_, f64>) -> Vec<c64> {
        eigenvalues(a)
            .unwrap()
            .into_iter()
            .map(|e| {
                if e.im == 0.0 {
                    return e;
                }
                let (omega, zeta) = (e.norm(), 0.30);
                c64::new(
                    -zeta * omega,
                    omega * (1.0 - zeta * zeta).sqrt() * e.im.signum(),
                )
            })
            .collect()
    }

    fn assert_close(got: MatRef<'_, f64>, expected: &[f64], tolerance: f64) {
        for (j, e) in expected.iter().enumerate() {
            assert!(
                (got[(0, j)] - e).abs() <= tolerance,
                "k[{j}] = {} against {e}",
                got[(0, j)]
            );
        }
    }

    #[test]
    fn chapter_state_feedback_example() {
        // (6.95)-(6.102): ω_n = 25, ζ = 0.707 for A = [[-3, 8], [0, 0]], b = [0, 4]^T.
        let (a, b) = (mat![[-3.0, 8.0], [0.0, 0.0]], mat![[0.0], [4.0]]);
        let (omega, zeta) = (25.0f64, 0.707f64);
        let root = c64::new(-zeta * omega, omega * (1.0 - zeta * zeta).sqrt());
        let poles = [root, root.conj()];
        for method in [place_bass_gura, place_ackermann, place] {
            let design = method(a.as_ref(), b.as_ref(), &poles).unwrap();
            // (6.100)-(6.102): 3 + 4 k2 = 2 ζ ω_n, 32 k1 + 12 k2 = ω_n^2.
            let k2 = (2.0 * zeta * omega - 3.0) / 4.0;
            assert_close(
                design.gain.as_ref(),
                &[(omega * omega - 12.0 * k2) / 32.0, k2],
                1e-12,
            );
            assert!(design.max_relative_error < 1e-14);
        }
    }

    #[test]
    fn boeing_747_dutch_roll_damper() {
        let a = lateral();
        let poles = dutch_roll_request(a.as_ref());
        let rudder = mat![[0.0182], [0.0868], [0.0], [-0.2440]];
        let aileron = mat![[0.0], [0.3215], [0.0], [-0.0017]];
        for (b, gains) in [
            (rudder, [0.13836, 0.09439, 0.12508, -1.13364]),
            (aileron, [-3.54833, 0.87228, 0.67487, -4.04805]),
        ] {
            let bass_gura = place_bass_gura(a.as_ref(), b.as_ref(), &poles).unwrap();
            assert_close(bass_gura.gain.as_ref(), &gains, 5e-6);
            let ackermann = place_ackermann(a.as_ref(), b.as_ref(), &poles).unwrap();
            let difference = (&bass_gura.gain - &ackermann.gain).norm_l2();
            assert!(difference < 1e-12 * bass_gura.gain.norm_l2());
            assert!(bass_gura.max_relative_error < 1e-12);
            assert!(bass_gura.controllability_condition > 1.0);
        }
    }

    #[test]
    fn companion_form_of_the_747() {
        let a = lateral();
        let b = mat![[0.0182], [0.0868], [0.0], [-0.2440]];
        let form = companion_form(a.as_ref(), b.as_ref()).unwrap();
        // (6.155) at printed precision.
        for (c, e) in form
            .coefficients
            .iter()
            .zip([1.0, 1.4385, 0.8222, 0.7232, 0.0319])
        {
            assert!((c - e).abs() < 1e-4);
        }
        // T A T^-1 = companion: T A = companion T.
        let residual = &form.t * &a - &form.companion * &form.t;
        assert!(residual.norm_l2() < 1e-10 * form.t.norm_l2());
        // T b = e_1 (6.109).
        let tb = &form.t * &b;
        assert!(
            (tb[(0, 0)] - 1.0).abs() < 1e-12 && tb.col(0).iter().skip(1).all(|x| x.abs() < 1e-12)
        );
    }

    #[test]
    fn robust_placement_of_a_multi_input_system() {
        let a = lateral();
        let b = mat![
            [0.0, 0.0182],
            [0.3215, 0.0868],
            [0.0, 0.0],
            [-0.0017, -0.2440]
        ];
        let poles = [
            c64::new(-0.5, 0.8),
            c64::new(-0.5, -0.8),
            c64::new(-1.2, 0.0),
            c64::new(-0.1, 0.0),
        ];
        let design = place(a.as_ref(), b.as_ref(), &poles).unwrap();
        assert_eq!((design.gain.nrows(), design.gain.ncols()), (2, 4));
        assert!(design.max_relative_error < 1e-12);
        assert!(design.converged && design.iterations >= 1, "{design:?}");
        assert!(design.eigenvector_condition >= 1.0 && design.eigenvector_condition < 1e3);
        // A pole repeated twice is allowed with two inputs, three times is not.
        let repeated = real(&[-1.0, -1.0, -2.0, -3.0]);
        let design = place(a.as_ref(), b.as_ref(), &repeated).unwrap();
        assert!(design.max_relative_error < 1e-7);
        let error = place(a.as_ref(), b.as_ref(), &real(&[-1.0, -1.0, -1.0, -3.0])).unwrap_err();
        assert!(error.to_string().contains("repeated 3 times"), "{error}");
    }

    #[test]
    fn states_scaled_apart_are_balanced_first() {
        // The 747 with rudder and aileron in states scaled by 10^±6 (D A D^-1, D B): every
        // method places the requested poles (to 1e-9 relatively), and the single-input gains
        // (unique) are K = K0 D^-1 for the gain K0 of the unscaled pair.
        let a = lateral();
        let b = mat![
            [0.0182, 0.0],
            [0.0868, -0.2266],
            [0.0, 0.0],
            [-0.2440, 0.0027]
        ];
        let d = [1e6, 1e-6, 1.0, 1e3];
        let scaled_a = Mat::from_fn(4, 4, |i, j| a[(i, j)] * d[i] / d[j]);
        let scaled_b = Mat::from_fn(4, 2, |i, j| b[(i, j)] * d[i]);
        assert!(states_scaled_apart(scaled_a.as_ref()));
        let poles = dutch_roll_request(a.as_ref());
        let placers: [(crate::control::batch::Placer, usize); 3] =
            [(place_bass_gura, 1), (place_ackermann, 1), (place, 2)];
        for (placer, m) in placers {
            let given = placer(a.as_ref(), b.as_ref().subcols(0, m), &poles).unwrap();
            let scaled =
                placer(scaled_a.as_ref(), scaled_b.as_ref().subcols(0, m), &poles).unwrap();
            assert!(
                scaled.max_relative_error < 1e-9,
                "{}",
                scaled.max_relative_error
            );
            if m > 1 {
                continue;
            }
            let size = frobenius_norm(given.gain.as_ref());
            for (j, &dj) in d.iter().enumerate() {
                let expected = given.gain[(0, j)] / dj;
                assert!((scaled.gain[(0, j)] - expected).abs() <= 1e-9 * size / dj);
            }
        }
    }

    #[test]
    fn bad_requests_are_named() {
        let (a, b) = (mat![[0.0, 1.0], [-2.0, -3.0]], mat![[0.0], [1.0]]);
        let error = place_bass_gura(a.as_ref(), b.as_ref(), &real(&[-1.0])).unwrap_err();
        assert!(matches!(error, Error::Mismatch { arg: "poles", .. }));
        let lonely = [c64::new(-1.0, 1.0), c64::new(-2.0, 0.0)];
        let error = place_bass_gura(a.as_ref(), b.as_ref(), &lonely).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("poles[0] = -1+1j has no complex conjugate"),
            "{error}"
        );
        let error = place_bass_gura(
            a.as_ref(),
            b.as_ref(),
            &[c64::new(f64::NAN, 0.0), c64::new(-1.0, 0.0)],
        );
        assert!(matches!(error, Err(Error::NonFinite { arg: "poles", .. })));
        // (6.84): B = [-1, 1]^T cannot move the eigenvalue -2.
        let error = place_ackermann(
            a.as_ref(),
            mat![[-1.0], [1.0]].as_ref(),
            &real(&[-3.0, -4.0]),
        )
        .unwrap_err();
        match &error {
            Error::Uncontrollable { eigenvalues, .. } => {
                assert!((eigenvalues[0] - c64::new(-2.0, 0.0)).norm() < 1e-14)
            }
            other => panic!("{other}"),
        }
        let two_inputs = mat![[1.0, 0.0], [0.0, 1.0]];
        let error =
            place_bass_gura(a.as_ref(), two_inputs.as_ref(), &real(&[-3.0, -4.0])).unwrap_err();
        assert!(error.to_string().contains("use place()"), "{error}");
        let zero_column = mat![[1.0, 0.0], [0.0, 0.0]];
        let error = place(a.as_ref(), zero_column.as_ref(), &real(&[-3.0, -4.0])).unwrap_err();
        assert!(
            error.to_string().contains("column 1 of B is zero"),
            "{error}"
        );
        let dependent = mat![[1.0, 2.0], [1.0, 2.0]];
        let error = place(a.as_ref(), dependent.as_ref(), &real(&[-3.0, -4.0])).unwrap_err();
        assert!(error.to_string().contains("rank 1"), "{error}");
    }
}
