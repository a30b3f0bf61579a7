//! The discrete-time algebraic Riccati equation, in its general form (MATLAB's
//! dare(A, B, Q, R, S, E)):
//!
//! ```text
//! A^T X A - E^T X E - (A^T X B + S)(R + B^T X B)^-1 (B^T X A + S^T) + Q = 0,
//! K = (R + B^T X B)^-1 (B^T X A + S^T),     closed loop eig(A - B K, E),
//! ```
//!
//! for the stabilising solution X = X^T (every closed-loop eigenvalue inside the unit circle),
//! by the extended symplectic pencil and the QZ algorithm (Van Dooren 1981; Arnold & Laub
//! 1984), which needs neither A nor R invertible.
//!
//! # The pencil
//!
//! The state, costate and input of the optimal sequence (x_{k+1} = A x_k + B u_k,
//! E^T λ_k = Q x_k + A^T λ_{k+1} + S u_k, 0 = S^T x_k + B^T λ_{k+1} + R u_k) with x_{k+1} = z x_k
//! are the generalized eigenvectors of the pencil of order 2n + m
//!
//! ```text
//! M - z N = [ A   0    B ]  - z [ E  0    0 ]
//!           [ -Q  E^T -S ]      [ 0  A^T  0 ]
//!           [ S^T 0    R ]      [ 0  -B^T 0 ],
//! ```
//!
//! whose finite eigenvalues come in pairs (z, 1/z). The last m columns are compressed away by
//! the QR factorisation of M's last block column (orthogonal rows transformations of both
//! matrices), leaving a 2n x 2n pencil with the same finite eigenvalues. Its generalized Schur
//! form ([`crate::linalg::qz`]) reordered to put |z| < 1 first gives the stable deflating
//! subspace [U11; U21]: X = U21 (E U11)^-1, symmetrised. Exactly n eigenvalues must lie inside
//! the unit circle and none within 100 u of it; else the equation has no stabilising solution.
//!
//! # The fast paths
//!
//! For E = I and R positive definite the equation is first solved, up to order
//! [`super::doubling::MAX_ORDER`], by the structure-preserving doubling algorithm
//! ([`super::doubling`]), then through the Cayley transform of the pencil (without its input
//! block) to a Hamiltonian matrix and the continuous solver's Hamiltonian Schur method
//! ([`super::cayley`]). A fast path's solution is kept when, after the refinement below, it
//! passes every check of this module with a relative residual of at most
//! [`FAST_PATH_MAX_RESIDUAL`]. Otherwise (the doubling diverged, M + N ill-conditioned, an
//! eigenvalue near z = -1, R indefinite or singular, a descriptor E) the pencil and QZ decide.
//!
//! # Checks and the reported numbers
//!
//! The gain's matrix R + B^T X B must be nonsingular; the closed loop A - B K (with E: the
//! pencil) must have every eigenvalue with |λ| < 1 - 100 u max(1, ||A - B K||_F); the relative
//! residual
//!
//! ```text
//! ||Res||_F / (||Q||_F + ||A^T X A||_F + ||E^T X E||_F + ||M^T K||_F),   M = B^T X A + S^T,
//! ```
//!
//! and the reciprocal 1-norm condition number of E U11 are reported.
//!
//! The pencil method is backward stable for the pencil, not for the equation; Newton steps
//! (Hewer 1971; each a Stein equation, [`crate::linalg::stein`]) restore a residual of a few
//! units of rounding where the pencil's solution lost digits to a badly conditioned subspace
//! basis (with a descriptor E above order [`crate::linalg::stein::KRONECKER_MAX_ORDER`], on
//! the equation with E removed, E^-T (·) E^-1).
//!
//! R need not be positive definite (only symmetric): indefinite weights, as the H-infinity
//! equations have, are solved where a stabilising solution exists.

use super::AlgebraicSolution;
use super::cayley::{cayley_solution, standard_form};
use super::doubling::doubling_solution;
use super::pencil::{checked_weights, compress, graph_solution};
use super::scaling::{Equation, Scale, ScaledEquation};
use crate::error::Error;
use crate::linalg::dense::view_product;
use crate::linalg::lu::{self, solve_with_inverse};
use crate::linalg::matrix::Symmetrize;
use crate::linalg::norm::{frobenius_norm, one_norm};
use crate::linalg::product::product;
use crate::linalg::qz::{generalized_eigenvalues, qz, reorder_qz};
use crate::linalg::stein::{KRONECKER_MAX_ORDER, solve_stein_kronecker, solve_stein_smith};
use crate::platform::interrupt;
use faer::{Mat, MatRef, Par, c64};

/// Distance from the unit circle, relative, within which an eigenvalue counts as on it.
pub const CIRCLE_TOLERANCE: f64 = 100.0 * f64::EPSILON;

/// Relative residual at which refinement stops: one unit of rounding (a step costs a tenth of
/// a 4-state solve).
pub const REFINEMENT_FLOOR: f64 = f64::EPSILON;

/// The largest relative residual, after refinement, at which a fast path's solution
/// ([`super::doubling`], [`super::cayley`]) is kept; above it the pencil decides.
pub const FAST_PATH_MAX_RESIDUAL: f64 = 4.0 * f64::EPSILON;

/// Newton steps at most.
pub const MAX_REFINEMENT_STEPS: usize = 3;

/// Above this order (and E = I) a Newton step solves its Stein equation by Smith's doubling:
/// the vectorised system's (n^2 / 2)^3 / 3 flops outgrow the doubling's few dozen products.
const SMITH_MIN_ORDER: usize = 8;

/// The optional arguments of [`solve_dare`].
#[derive(Debug, Clone, Copy, Default)]
pub struct DareOptions<'a> {
    /// The cross weight S (n x m), the N of python-control's dlqr.
    pub s: Option<MatRef<'a, f64>>,
    /// The descriptor matrix E (n x n).
    pub e: Option<MatRef<'a, f64>>,
    /// The caller's name of the cross weight in errors (default "S").
    pub s_name: Option<&'static str>,
}

/// Solves the DARE for its stabilising solution, verified (see the module documentation), in
/// exactly scaled units where its states, or B or the weights, are far from the sizes of the
/// identity blocks of the pencil ([`super::scaling`]).
pub fn solve_dare(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: DareOptions<'_>,
) -> Result<AlgebraicSolution, Error> {
    let given = Equation {
        a,
        b,
        q,
        r,
        s: options.s,
        e: options.e,
        terminal: None,
    };
    let Some(scaled) = ScaledEquation::of(given, Scale::AlsoWeights) else {
        return solve_dare_as_given(a, b, q, r, options);
    };
    let equation = scaled.equation();
    let solution = solve_dare_as_given(
        equation.a,
        equation.b,
        equation.q,
        equation.r,
        DareOptions {
            s: equation.s,
            e: equation.e,
            ..options
        },
    )?;
    scaled.unscaled(solution, |x, gain| general_residual(given, x, gain))
}

/// The relative residual of the caller's equation (module documentation) for X and its gain K:
/// ||A^T X A - E^T X E - M^T K + Q||_F / (||Q||_F + ||A^T X A||_F + ||E^T X E||_F +
/// ||M^T K||_F), M = B^T X A + S^T.
fn general_residual(given: Equation<'_>, x: &Mat<f64>, gain: &Mat<f64>) -> Result<f64, Error> {
    let Equation { a, b, q, s, e, .. } = given;
    let xa = product(x.as_ref(), a)?;
    let axa = product(a.transpose(), xa.as_ref())?;
    let mut mixed = product(b.transpose(), xa.as_ref())?;
    if let Some(s) = s {
        mixed += s.transpose();
    }
    let quadratic = product(mixed.transpose(), gain.as_ref())?;
    let exe = match e {
        Some(e) => product(e.transpose(), product(x.as_ref(), e)?.as_ref())?,
        None => x.clone(),
    };
    let residual = &axa - &exe - &quadratic + q;
    let scale = frobenius_norm(q)
        + frobenius_norm(axa.as_ref())
        + frobenius_norm(exe.as_ref())
        + frobenius_norm(quadratic.as_ref());
    let size = frobenius_norm(residual.as_ref());
    Ok(if scale > 0.0 { size / scale } else { size })
}

/// [`solve_dare`] of the equation as given.
fn solve_dare_as_given(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: DareOptions<'_>,
) -> Result<AlgebraicSolution, Error> {
    let (q, r) = checked_weights(
        a,
        b,
        q,
        r,
        options.s.map(|s| (s, options.s_name.unwrap_or("S"))),
        options.e,
    )?;
    let (n, m) = (a.nrows(), b.ncols());
    let identity = Mat::<f64>::identity(n, n);
    let e = options.e.unwrap_or(identity.as_ref());
    if n == 0 {
        return Ok(AlgebraicSolution {
            x: Mat::zeros(0, 0),
            gain: Mat::zeros(m, 0),
            closed_loop_eigenvalues: vec![],
            residual: 0.0,
            rcond: 1.0,
            refinement_steps: 0,
        });
    }
    crate::platform::memory::reserve((2 * n + m).pow(2).saturating_mul(8 * 8))?;
    let problem = Problem {
        a,
        b,
        q: q.as_ref(),
        r: r.as_ref(),
        s: options.s,
        e,
        identity_e: options.e.is_none(),
    };
    if options.e.is_none()
        && let Some(solution) = fast_solution(&problem)
    {
        return Ok(solution);
    }
    interrupt::check()?;
    let (pencil_m, pencil_n) = compressed_pencil(a, b, q.as_ref(), r.as_ref(), options.s, e);
    if !pencil_m.is_all_finite() || !pencil_n.is_all_finite() {
        return Err(out_of_range("its symplectic pencil"));
    }
    interrupt::check()?;
    let form = qz(pencil_m.as_ref(), pencil_n.as_ref())?;
    let values = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref());
    check_separated(&values, n)?;
    let (form, selected) = reorder_qz(form, |v| v.alpha.norm() < v.beta)?;
    if selected != n {
        return Err(no_solution(format!(
            "{selected} of the 2n = {} finite eigenvalues of the symplectic pencil lie inside \
             the unit circle, not n = {n}",
            2 * n
        )));
    }
    let (x, rcond) = graph_solution(&form, e, n).ok_or_else(|| {
        no_solution(
            "the stable deflating subspace is not a graph: E U11 is singular to working \
             precision"
                .into(),
        )
    })?;
    finish(&problem, x, rcond, &[])
}

/// The solution by the fast paths (module documentation), or `None` where neither gives one
/// that passes.
fn fast_solution(problem: &Problem<'_>) -> Option<AlgebraicSolution> {
    let plant = standard_form(problem.a, problem.b, problem.q, problem.r, problem.s)?;
    let kept = |x, rcond, estimates: &[c64]| {
        finish(problem, x, rcond, estimates)
            .ok()
            .filter(|solution| solution.residual <= FAST_PATH_MAX_RESIDUAL)
    };
    if let Some(candidate) = doubling_solution(&plant)
        && let Some(solution) = kept(candidate.x, candidate.rcond, &[])
    {
        return Some(solution);
    }
    let candidate = cayley_solution(&plant)?;
    kept(
        candidate.x,
        candidate.rcond,
        &candidate.closed_loop_estimates,
    )
}

/// The refinement and the checks of a candidate solution X with its rcond; `estimates` of
/// the closed-loop eigenvalues, if known, are the shifts of their computation.
fn finish(
    problem: &Problem<'_>,
    mut x: Mat<f64>,
    rcond: f64,
    estimates: &[c64],
) -> Result<AlgebraicSolution, Error> {
    let mut evaluation = problem.evaluate(&x)?;
    let refinement_steps = refine(problem, &mut x, &mut evaluation)?;
    if !x.is_all_finite() || !evaluation.closed_loop.is_all_finite() {
        return Err(out_of_range("the solution X or its closed loop A - B K"));
    }
    let descriptor = (!problem.identity_e).then_some(problem.e);
    let closed_loop_eigenvalues =
        closed_loop_eigenvalues(evaluation.closed_loop.as_ref(), descriptor, estimates)?;
    check_stabilising(
        &closed_loop_eigenvalues,
        frobenius_norm(evaluation.closed_loop.as_ref()),
    )?;
    Ok(AlgebraicSolution {
        x,
        gain: evaluation.gain,
        closed_loop_eigenvalues,
        residual: evaluation.relative,
        rcond,
        refinement_steps,
    })
}

/// The data of the equation.
struct Problem<'a> {
    a: MatRef<'a, f64>,
    b: MatRef<'a, f64>,
    q: MatRef<'a, f64>,
    r: MatRef<'a, f64>,
    s: Option<MatRef<'a, f64>>,
    e: MatRef<'a, f64>,
    /// No descriptor matrix was given (E = I).
    identity_e: bool,
}

/// The gain, closed loop and residual of a candidate X.
struct Evaluation {
    gain: Mat<f64>,
    closed_loop: Mat<f64>,
    residual: Mat<f64>,
    /// ||Res||_F over the size of the terms (module documentation).
    relative: f64,
}

impl Problem<'_> {
    /// K = (R + B^T X B)^-1 (B^T X A + S^T), A - B K and the residual; R + B^T X B must be
    /// nonsingular.
    fn evaluate(&self, x: &Mat<f64>) -> Result<Evaluation, Error> {
        let (a, b) = (self.a, self.b);
        let m = b.ncols();
        let xb = view_product(x.as_ref(), b)?;
        let mut weight = view_product(b.transpose(), xb.as_ref())?;
        weight += self.r;
        let mut mixed = view_product(xb.transpose(), a)?;
        if let Some(s) = self.s {
            mixed += s.transpose();
        }
        let norm = one_norm(weight.as_ref());
        let combined = solve_with_inverse(weight.as_mut(), mixed.as_ref())?;
        let (gain, inverse) = combined.as_ref().split_at_col(a.nrows());
        let rcond = 1.0 / (norm * one_norm(inverse));
        if m > 0 && (!gain.is_all_finite() || rcond.is_nan() || rcond <= f64::EPSILON) {
            return Err(Error::Singular {
                arg: "R + B^T X B",
                eigenvalue_re: 0.0,
                eigenvalue_im: 0.0,
            });
        }
        let gain = gain.to_owned();
        // A - B K, in the product's storage.
        let mut closed_loop = view_product(b, gain.as_ref())?;
        for j in 0..a.ncols() {
            for (i, entry) in closed_loop.col_as_slice_mut(j).iter_mut().enumerate() {
                *entry = a[(i, j)] - *entry;
            }
        }
        let mut residual = view_product(view_product(a.transpose(), x.as_ref())?.as_ref(), a)?;
        let axa_norm = frobenius_norm(residual.as_ref());
        let quadratic = view_product(mixed.transpose(), gain.as_ref())?;
        let exe_norm = if self.identity_e {
            residual -= x;
            frobenius_norm(x.as_ref())
        } else {
            let exe = view_product(
                view_product(self.e.transpose(), x.as_ref())?.as_ref(),
                self.e,
            )?;
            residual -= &exe;
            frobenius_norm(exe.as_ref())
        };
        residual -= &quadratic;
        residual += self.q;
        let scale =
            frobenius_norm(self.q) + axa_norm + exe_norm + frobenius_norm(quadratic.as_ref());
        let size = frobenius_norm(residual.as_ref());
        let relative = if scale > 0.0 { size / scale } else { size };
        Ok(Evaluation {
            gain,
            closed_loop,
            residual,
            relative,
        })
    }
}

/// Newton steps (Hewer 1971) after the pencil's solution: with A_c = A - B K the closed loop of
/// X, the correction solves A_c^T Δ A_c - E^T Δ E = -Res(X) (the derivative of the Riccati
/// operator at X applied to Δ), in vectorised form up to order [`SMITH_MIN_ORDER`] (with a
/// descriptor E up to [`crate::linalg::stein::KRONECKER_MAX_ORDER`]) and above it by Smith's
/// doubling (with E: on the equation [`without_descriptor`] forms); taken while the residual
/// decreases and is
/// above [`REFINEMENT_FLOOR`], at most [`MAX_REFINEMENT_STEPS`] times. Returns the steps taken.
fn refine(
    problem: &Problem<'_>,
    x: &mut Mat<f64>,
    evaluation: &mut Evaluation,
) -> Result<usize, Error> {
    let mut steps = 0;
    while steps < MAX_REFINEMENT_STEPS && evaluation.relative > REFINEMENT_FLOOR {
        interrupt::check()?;
        let rhs = -&evaluation.residual;
        let n = x.nrows();
        let delta = if n <= SMITH_MIN_ORDER || (!problem.identity_e && n <= KRONECKER_MAX_ORDER) {
            solve_stein_kronecker(evaluation.closed_loop.as_ref(), problem.e, rhs.as_ref())?
        } else if problem.identity_e {
            // A_c^T Δ A_c - Δ = -Res  <=>  Δ - A_c^T Δ A_c = Res.
            solve_stein_smith(
                evaluation.closed_loop.as_ref(),
                evaluation.residual.as_ref(),
            )?
        } else {
            let (a, c) = without_descriptor(
                evaluation.closed_loop.as_ref(),
                problem.e,
                evaluation.residual.as_ref(),
            )?;
            solve_stein_smith(a.as_ref(), c.as_ref())?
        };
        let Some(delta) = delta else {
            break;
        };
        let mut candidate = &*x + &delta;
        candidate.symmetrize();
        let Ok(candidate_evaluation) = problem.evaluate(&candidate) else {
            break;
        };
        if candidate_evaluation.relative.is_nan()
            || candidate_evaluation.relative >= evaluation.relative
        {
            break;
        }
        *x = candidate;
        *evaluation = candidate_evaluation;
        steps += 1;
    }
    Ok(steps)
}

/// The Stein equation of a Newton step with E removed: A_c^T Δ A_c - E^T Δ E = -Res is, with
/// Ã = A_c E^-1 and C̃ = E^-T Res E^-1 (E is nonsingular: its pencil with A_c has the
/// closed-loop eigenvalues, all finite), Δ - Ã^T Δ Ã = C̃. Returns (Ã, C̃), C̃ symmetrised; both
/// by LU solves with E^T. An inaccurate Δ from a badly conditioned E is harmless: the step is
/// taken only if it lowers the residual.
fn without_descriptor(
    closed_loop: MatRef<'_, f64>,
    e: MatRef<'_, f64>,
    residual: MatRef<'_, f64>,
) -> Result<(Mat<f64>, Mat<f64>), Error> {
    let n = e.nrows();
    // E^T [Y | W] = [A_c^T | Res]: Ã = Y^T, W = E^-T Res.
    let mut rhs = Mat::<f64>::zeros(n, 2 * n);
    rhs.as_mut()
        .subcols_mut(0, n)
        .copy_from(closed_loop.transpose());
    rhs.as_mut().subcols_mut(n, n).copy_from(residual);
    lu::solve(e.transpose().to_owned().as_mut(), rhs.as_mut(), Par::Seq)?;
    let a_tilde = rhs.as_ref().subcols(0, n).transpose().to_owned();
    // E^T V = W^T: C̃ = W E^-1 = V^T.
    let mut c_tilde = rhs.as_ref().subcols(n, n).transpose().to_owned();
    lu::solve(
        e.transpose().to_owned().as_mut(),
        c_tilde.as_mut(),
        Par::Seq,
    )?;
    let mut c_tilde = c_tilde.transpose().to_owned();
    c_tilde.symmetrize();
    Ok((a_tilde, c_tilde))
}

/// The pencil of order 2n + m (module documentation) with its last m columns compressed away:
/// reflectors from the QR factorisation of M's last block column, applied to the rows of both
/// matrices; the rows m.. and columns ..2n remain.
fn compressed_pencil(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    s: Option<MatRef<'_, f64>>,
    e: MatRef<'_, f64>,
) -> (Mat<f64>, Mat<f64>) {
    let (n, m) = (a.nrows(), b.ncols());
    let size = 2 * n + m;
    let mut big_m = Mat::<f64>::zeros(size, size);
    let mut big_n = Mat::<f64>::zeros(size, size);
    for j in 0..n {
        for i in 0..n {
            big_m[(i, j)] = a[(i, j)];
            big_m[(n + i, j)] = -q[(i, j)];
            big_m[(n + i, n + j)] = e[(j, i)];
            big_n[(i, j)] = e[(i, j)];
            big_n[(n + i, n + j)] = a[(j, i)];
        }
    }
    for j in 0..m {
        for i in 0..n {
            big_m[(i, 2 * n + j)] = b[(i, j)];
            big_n[(2 * n + j, n + i)] = -b[(i, j)];
            let sij = s.map_or(0.0, |s| s[(i, j)]);
            big_m[(n + i, 2 * n + j)] = -sij;
            big_m[(2 * n + j, i)] = sij;
        }
        for i in 0..m {
            big_m[(2 * n + i, 2 * n + j)] = r[(i, j)];
        }
    }
    compress(big_m, big_n, 2 * n)
}

/// The error when eigenvalues of the pencil lie on the unit circle to working precision.
fn check_separated(
    values: &[crate::linalg::qz::GeneralizedEigenvalue],
    n: usize,
) -> Result<(), Error> {
    let on_circle: Vec<String> = values
        .iter()
        .filter(|v| v.beta > 0.0 && (v.alpha.norm() / v.beta - 1.0).abs() <= CIRCLE_TOLERANCE)
        .map(|v| crate::error::format_complex(v.value()))
        .collect();
    if on_circle.is_empty() {
        return Ok(());
    }
    Err(no_solution(format!(
        "the symplectic pencil (order 2n = {}) has {} eigenvalue(s) on the unit circle to \
         working precision ({}; ||z| - 1| <= {CIRCLE_TOLERANCE:.1e}), so some mode on the unit \
         circle can be neither moved by B nor seen by Q",
        2 * n,
        on_circle.len(),
        on_circle.join(", ")
    )))
}

/// The refusal of an equation whose `what` leaves the range of doubles.
fn out_of_range(what: &str) -> Error {
    Error::IllConditioned {
        message: format!(
            "the discrete Riccati equation cannot be solved in double precision: {what} \
             exceeds the range of doubles (the model's entries and weights are too far apart \
             in size); scale the model's units"
        ),
    }
}

fn no_solution(evidence: String) -> Error {
    Error::NoStabilizingSolution {
        message: format!("the discrete Riccati equation has no stabilising solution: {evidence}"),
    }
}

/// The eigenvalues of A - B K, or of the pencil (A - B K, E).
fn closed_loop_eigenvalues(
    closed_loop: MatRef<'_, f64>,
    e: Option<MatRef<'_, f64>>,
    estimates: &[c64],
) -> Result<Vec<c64>, Error> {
    match e {
        None if estimates.len() == closed_loop.nrows() => {
            crate::linalg::schur::eigenvalues_near(closed_loop, estimates)
        }
        None => crate::linalg::schur::eigenvalues(closed_loop),
        Some(e) => {
            let form = qz(closed_loop, e)?;
            Ok(generalized_eigenvalues(form.s.as_ref(), form.t.as_ref())
                .iter()
                .map(|v| v.value())
                .collect())
        }
    }
}

/// The error for a closed loop with an eigenvalue on or outside the unit circle to working
/// precision.
fn check_stabilising(eigenvalues: &[c64], closed_loop_norm: f64) -> Result<(), Error> {
    let limit = 1.0 - CIRCLE_TOLERANCE * closed_loop_norm.max(1.0);
    let unstable: Vec<String> = eigenvalues
        .iter()
        .filter(|z| z.norm().is_nan() || z.norm() >= limit)
        .map(|z| crate::error::format_complex(*z))
        .collect();
    if unstable.is_empty() {
        return Ok(());
    }
    Err(no_solution(format!(
        "the computed solution leaves {} eigenvalue(s) of the closed loop A - B K on or \
         outside the unit circle ({}; |z| >= {limit}), so some mode on or outside the unit \
         circle can be neither moved by B nor separated from its mirror image",
        unstable.len(),
        unstable.join(", ")
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat(rows: &[&[f64]]) -> Mat<f64> {
        Mat::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
    }

    #[test]
    fn scalar_equation_has_its_closed_form() {
        // a^2 x - x - a^2 b^2 x^2 / (r + b^2 x) + q = 0 with a = 2, b = 1, q = 1, r = 1:
        // x^2 - 4x - 1 = 0 -> x = 2 + sqrt(5).
        let (a, b, q, r) = (
            mat(&[&[2.0]]),
            mat(&[&[1.0]]),
            mat(&[&[1.0]]),
            mat(&[&[1.0]]),
        );
        let d = solve_dare(
            a.as_ref(),
            b.as_ref(),
            q.as_ref(),
            r.as_ref(),
            DareOptions::default(),
        )
        .unwrap();
        assert!((d.x[(0, 0)] - (2.0 + 5f64.sqrt())).abs() < 1e-14);
        assert!(d.residual < 1e-15);
        assert!(d.closed_loop_eigenvalues[0].norm() < 1.0);
    }

    #[test]
    fn singular_a_is_solved() {
        // A nilpotent: the pencil has infinite eigenvalues.
        let a = mat(&[&[0.0, 1.0], &[0.0, 0.0]]);
        let b = mat(&[&[0.0], &[1.0]]);
        let q = mat(&[&[1.0, 0.0], &[0.0, 1.0]]);
        let r = mat(&[&[1.0]]);
        let d = solve_dare(
            a.as_ref(),
            b.as_ref(),
            q.as_ref(),
            r.as_ref(),
            DareOptions::default(),
        )
        .unwrap();
        assert!(d.residual < 1e-14, "{}", d.residual);
        // X = diag(1, 2)? A^T X A = [[0,0],[0,x11]]: x12 = 0, x11 = 1, x22 = 1 + x11 - x11^2... check residual only.
        assert!(d.closed_loop_eigenvalues.iter().all(|z| z.norm() < 1.0));
    }

    #[test]
    fn an_uncontrollable_mode_on_the_unit_circle_is_refused() {
        let a = mat(&[&[0.0, 1.0, 0.0], &[-1.0, 0.0, 0.0], &[0.0, 0.0, 0.5]]);
        let b = mat(&[&[0.0], &[0.0], &[1.0]]);
        let q = Mat::<f64>::identity(3, 3);
        let r = mat(&[&[1.0]]);
        let error = solve_dare(
            a.as_ref(),
            b.as_ref(),
            q.as_ref(),
            r.as_ref(),
            DareOptions::default(),
        )
        .unwrap_err();
        assert!(
            matches!(error, Error::NoStabilizingSolution { .. }),
            "{error:?}"
        );
    }
}
