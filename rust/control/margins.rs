//! Crossovers and margins of a continuous SISO loop L(s) = C (sI - A)^-1 B + d, by eigenvalue
//! methods (no frequency grid).
//!
//! **Gain crossovers** (|L(jω)| = 1) are the imaginary-axis eigenvalues jω of the Hamiltonian
//! of 1 - L(-s) L(s) (Boyd, Balakrishnan and Kabamba 1989, Theorem 1 with γ = 1): with
//! r = 1 - d^2 != 0,
//!
//! ```text
//!     H = [ A + (d/r) B C        (1/r) B B^T         ]
//!         [ -(1/r) C^T C        -(A + (d/r) B C)^T   ],
//! ```
//!
//! whose eigenvalues are the zeros of 1 - L(-s) L(s) (plus any uncontrollable or unobservable
//! modes). They are computed as ±√μ from the squares μ = λ^2 (Van Loan's squared
//! Hamiltonian), the eigenvalues of one n x n matrix formed from the blocks, whose off-diagonal
//! ones are of rank one (`linalg/hamiltonian.rs`: a fraction of the cost of the QR iteration of
//! order 2n, and of the square-reduced form of H^2) wherever those decide which eigenvalues lie
//! within [`AXIS_TOLERANCE`] of the axis (their error, about n u ||H||^2, at most 1e-8 of |μ|,
//! or smaller than μ's distance from the negative real axis); otherwise (a small eigenvalue
//! near the axis beside large ones: a crossover far below the loop's size) by the QR iteration
//! on H. When d^2 = 1 to rounding (r = 0, the Hamiltonian does not exist) the zeros are the
//! finite generalized eigenvalues of the system pencil of 1 - L(-s) L(s), the realisation
//! A_f = [[A, 0], [B C, -A]], B_f = [B; d B], C_f = [-d C, C], D_f = 1 - d^2 (the series
//! connection of L(s) and L(-s) = d - C (sI + A)^-1 B).
//!
//! **Phase crossovers** (L(jω) real, ω >= 0) are the imaginary-axis zeros of the odd function
//! L(s) - L(-s) = C (sI - A)^-1 B + C (sI + A)^-1 B (for a real loop L(-jω) = conj L(jω), so
//! L(jω) - L(-jω) = 2j Im L(jω)): the finite generalized eigenvalues of the system pencil
//!
//! ```text
//!     [ diag(A, -A)  [B; B] ]       [ I  0 ]
//!     [ [C, C]        0     ]  - s  [ 0  0 ]
//! ```
//!
//! of Emami-Naeini and Van Dooren, reduced for one input and one output to an ordinary
//! eigenvalue problem of order at most 2n - 1 ([`siso_zeros`]: orthogonal reflections that
//! peel off the relative degree, the equivalent of QZ on the deflated pencil, at a fraction of
//! its cost). Since L(jω) = d - c A (A^2 + ω^2 I)^-1 b - jω c (A^2 + ω^2 I)^-1 b, that odd
//! function is -2s Q(-s^2) with Q(μ) = c (μI + A^2)^-1 b: its zeros other than 0 are ±√(-μ)
//! for the zeros μ of Q, a realisation of order n, taken as the squares of the Hamiltonian's
//! are (where they decide the test of the axis, with the error of forming A^2), and from the
//! pencil of order 2n otherwise. ω = 0 is always a candidate (the odd function vanishes there when L(0)
//! is finite). A pencil that is singular (L(s) - L(-s) vanishing identically: L even, real on
//! the whole axis) is reported as [`LoopMargins::degenerate`] and no phase crossover is given.
//! A phase crossover beyond 1e8 times the largest pole's modulus counts as at infinity (a zero
//! pushed there by the reduction's division, where L is its feedthrough).
//!
//! **Acceptance.** An eigenvalue λ with |Re λ| <= 1e-6 |λ| (and Im λ >= 0) is a candidate; it
//! is polished by the secant method on the exact L(jω) (f = ln|L| or f = Im L / |L|, evaluated
//! by `control/frequency.rs`'s Hessenberg kernel on a model reduced once; it stops where the
//! next correction of its best point is below 1e-13 of ω), and kept only if
//! it then satisfies | |L| - 1 | <= 1e-8, respectively |Im L| <= 1e-8 |L|; candidates within
//! 1e-9 of each other (relative) are merged. A phase crossover where L vanishes (|L| below
//! 1e-10 of the loop's scale, a zero on the axis or at the origin) is not one.
//!
//! **Peaks** (the disk margin and the stability margin) are L∞ norms of SISO transfers, by the
//! Boyd-Balakrishnan / Bruinsma-Steinbuch iteration: a lower bound γ from ω = 0, ω = ∞ and the
//! frequencies of the poles; the imaginary eigenvalues jω_i of the Hamiltonian of G/γ' with
//! γ' = (1 + 2ε) γ (ε = 1e-8); in the interval [ω_i, ω_i+1] whose midpoint is highest, the
//! maximum found from that midpoint is the new γ; until no imaginary eigenvalue remains
//! (usually the second Hamiltonian). Each maximum is found by Halley's method (Newton's where
//! Halley's step is not trusted) on d ln|G|/dω = 0, the first three derivatives of L(jω) from
//! three more solves with the evaluator's elimination (d/dω (jωI - H)^-k =
//! -jk (jωI - H)^-(k+1)), safeguarded by a bracket that the sign of the derivative narrows,
//! the last step's end evaluated without derivatives; where it does not converge in 16
//! steps, or the derivatives are not available (an order above 8), Brent's method (golden
//! section and parabolic interpolation, to 1e-8 in ω) searches the bracket left. The disk
//! margin's transfer is
//! (1 - L)/(2 (1 + L)) = S - 1/2, with S = 1/(1 + L) realised for the Hamiltonians as
//! (A - B C/(1 + d), B/(1 + d), -C/(1 + d), 1/(1 + d)); the stability margin min |1 + L| is
//! 1/max |S|. The magnitudes the search evaluates, 1/|1 + L| and |1 - L|/(2 |1 + L|), come
//! from L(jω) by the loop's own evaluator (no second Hessenberg reduction, of the closed
//! loop): their relative error, about u |L| |S|, is that of evaluating the closed loop's
//! realisation near its resonance, and a peak found lower than the true one by more than the
//! iteration's ε leaves an imaginary eigenvalue in the next Hamiltonian, which then goes on.
//!
//! **Scaling.** The loop's states are balanced first by a diagonal similarity of powers of two
//! (`linalg/balance.rs`'s balanced_states: Osborne's iteration on [[A, b], [c, 0]] over the
//! states; the transfer function is unchanged), so that the eigenvalue problems below are solved to a backward error relative
//! to a system whose rows and columns are of one size.
//!
//! **Verification.** Every phase crossover with L(jω) < 0 gives a gain margin k = 1/|L(jω)|;
//! the loop closed with k must have a pole at jω (the eigenvalues of A - k B (1 + k d)^-1 C
//! by the root locus's controller-Hessenberg form, `control/root_locus.rs`,
//! within 1e-6 of max(1 + max|A|, ω)), else [`Error::IllConditioned`]. The closed loop's
//! poles and those of every such check come from one form of (A, b, c)
//! (`closed_loop_poles_at`: the same poles, bit for bit, as one form per gain).
//!
//! References: S. Boyd, V. Balakrishnan and P. Kabamba, "A bisection method for computing the
//! H∞ norm of a transfer matrix and related problems", Math. Control Signals Systems 2, 1989;
//! S. Boyd and V. Balakrishnan, "A regularity result for the singular values of a transfer
//! matrix and a quadratically convergent algorithm for computing its L∞-norm", Systems &
//! Control Letters 15, 1990; N. A. Bruinsma and M. Steinbuch, "A fast algorithm to compute the
//! H∞-norm of a transfer function matrix", Systems & Control Letters 14, 1990; A. Emami-Naeini
//! and P. Van Dooren, "Computation of zeros of linear multivariable systems", Automatica 18,
//! 1982 (zeros as generalized eigenvalues of the system pencil); P. Seiler, A. Packard and
//! P. Gahinet, "An introduction to disk margins", IEEE Control Systems 40(5), 2020; C. F. Van
//! Loan, "A symplectic method for approximating all the eigenvalues of a Hamiltonian matrix",
//! Linear Algebra and its Applications 61, 1984 (the squared Hamiltonian).

use crate::control::frequency::{FrequencyEvaluator, check_state_space};
use crate::control::root_locus;
use crate::error::Error;
use crate::linalg::balance::{GRADED_SPREAD, balanced_states, nearest_power_of_two};
use crate::linalg::hamiltonian::squared_eigenvalues_rank_one;
use crate::linalg::norm::{frobenius_norm, max_abs};
use crate::linalg::schur::eigenvalues;
use faer::{Mat, MatRef, c64};

/// A crossover: the frequency and the loop's value there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossover {
    pub omega: f64,
    pub value: c64,
}

/// The supremum over ω in [0, ∞] of |G(jω)| and where it is attained (∞ for the limit
/// ω -> ∞; NaN with an infinite value when G has a pole on the axis).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    pub omega: f64,
    pub value: f64,
}

/// Crossovers, peaks and poles of a SISO loop (see the module's documentation).
#[derive(Debug, Clone)]
pub struct LoopMargins {
    /// |L(jω)| = 1, by increasing ω.
    pub gain_crossovers: Vec<Crossover>,
    /// L(jω) real and not vanishing, by increasing ω (both signs of L).
    pub phase_crossovers: Vec<Crossover>,
    /// max |1 - L|/(2 |1 + L|).
    pub disk: Peak,
    /// max |S| = 1/min |1 + L|.
    pub sensitivity: Peak,
    /// Eigenvalues of A - B (1 + d)^-1 C, by [`root_locus::closed_loop_poles`] (normwise
    /// backward stable, the small ones of a graded spectrum polished), sorted by real part,
    /// then imaginary part (as `numpy.sort_complex`).
    pub closed_loop_poles: Vec<c64>,
    /// Eigenvalues of A.
    pub open_loop_poles: Vec<c64>,
    /// L(s) - L(-s) vanishes identically (or its pencil is singular): the phase crossovers
    /// could not be located by the pencil.
    pub degenerate: bool,
    /// ||A - B (1 + d)^-1 C||_F of the closed loop balanced alone ([`balanced_states`]): the
    /// size the closed-loop poles' errors are relative to (the boundary tolerance); where
    /// every pole is off the axis against an upper bound of it, that bound instead (the
    /// census is then the same: [`census_size`]).
    pub closed_loop_size: f64,
    /// ||A||_F of A balanced alone: the size the open-loop poles' errors are relative to (an
    /// upper bound of it where that decides the census, as for the closed loop).
    pub open_loop_size: f64,
}

/// Relative distance from the imaginary axis within which an eigenvalue is a candidate.
const AXIS_TOLERANCE: f64 = 1e-6;
/// Relative residual a polished crossover must reach.
const CROSSOVER_TOLERANCE: f64 = 1e-8;
/// ε of the L∞ iteration: γ' = (1 + 2ε) γ.
const PEAK_TOLERANCE: f64 = 1e-8;

/// The log2 of the largest term [`loop_margins`] takes as given: it squares entries (the
/// Hamiltonians, norms), so it works within the square root of the range of doubles. A loop
/// with a larger term is first slowed by a power of two (`loops.py`'s `_slowed`: its
/// frequencies divided by 2^e, exactly).
pub const RESCALE_EXPONENT: f64 = 256.0;

/// Whether [`loop_margins`] takes the loop (A, B, C, d) as given (1 + d != 0): max|A|, max|B|,
/// max|C| and the closed loop's term max|B| max|C| / |1 + d| all at most 2^[`RESCALE_EXPONENT`].
pub fn within_range(a: MatRef<'_, f64>, b: MatRef<'_, f64>, c: MatRef<'_, f64>, d: f64) -> bool {
    let log2 = |m: MatRef<'_, f64>| {
        let largest = max_abs(m);
        if largest > 0.0 {
            largest.log2()
        } else {
            f64::NEG_INFINITY
        }
    };
    let (size_a, size_b, size_c) = (log2(a), log2(b), log2(c));
    let closed = size_b + size_c - (1.0 + d).abs().log2();
    size_a.max(size_b).max(size_c).max(closed) <= RESCALE_EXPONENT
}

/// The frequencies ω >= 0 of the eigenvalues within [`AXIS_TOLERANCE`] of the imaginary axis
/// of the Hamiltonian of 1 - G(-s) G(s) for G = (A, B, C, d), r = 1 - d^2 != 0.
///
/// From the squares μ = λ^2 of the eigenvalues (`linalg/hamiltonian.rs`: an eigenvalue problem
/// of order n, H = [[F, G], [K, -F^T]] with F = A + (d/r) B C, G = B B^T / r and
/// K = -C^T C / r, its matrix formed from these blocks by `squared_eigenvalues_rank_one`)
/// where the squares decide the test of the
/// axis ([`squares_decide`]); otherwise (a small eigenvalue near the axis beside large ones,
/// an H^2 beyond the doubles, or squares that fail their check) by the QR iteration on H
/// itself.
fn hamiltonian_axis_frequencies(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    d: f64,
) -> Result<Vec<f64>, Error> {
    let n = a.nrows();
    let r = 1.0 - d * d;
    // B β and C / β leave G unchanged; β balances B B^T against C^T C.
    let (nb, nc) = (
        b.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        c.iter().fold(0.0f64, |m, v| m.max(v.abs())),
    );
    let beta = if nb > 0.0 && nc > 0.0 {
        nearest_power_of_two((nc / nb).sqrt())
    } else {
        1.0
    };
    let f = Mat::from_fn(n, n, |i, j| a[(i, j)] + (d / r) * b[i] * c[j]);
    let u: Vec<f64> = b.iter().map(|x| x * beta).collect();
    let v: Vec<f64> = c.iter().map(|x| x / beta).collect();
    match squared_eigenvalues_rank_one(f.as_ref(), &u, &v, 1.0 / r) {
        Ok(Some(squared)) if squares_decide(&squared.squares, squared.size) => {
            Ok(squared_axis_candidates(&squared.squares))
        }
        Err(Error::Interrupted) => Err(Error::Interrupted),
        _ => {
            let h = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                (true, true) => f[(i, j)],
                (true, false) => u[i] * u[j - n] / r,
                (false, true) => -v[i - n] * v[j] / r,
                (false, false) => -f[(j - n, i - n)],
            });
            Ok(axis_candidates(&eigenvalues(h.as_ref())?))
        }
    }
}

/// The error of a computed square, in units of n u times the size of the matrix it is an
/// eigenvalue of (the backward error of orthogonal transformations, with room for the
/// eigenvalue's condition).
const SQUARED_ERROR_UNITS: f64 = 64.0;

/// Whether the computed squares μ (n of them, eigenvalues of a matrix formed with errors
/// relative to `size`: ||H||_F^2 for H^2) decide the test of the axis for their roots ±√μ as
/// exactly known squares would: with
/// e = [`SQUARED_ERROR_UNITS`] n u `size` the error of each, every μ either has e <= 1e-8 |μ|
/// (√μ then has a relative error of at most about 5e-9, far inside [`AXIS_TOLERANCE`]), or
/// lies farther than 2 e (and 4 [`AXIS_TOLERANCE`] |μ|) from the negative real axis, where
/// the squares of the imaginary numbers are: no μ within its error is then the square of a
/// root near the axis. A small μ near that axis (a crossover at a frequency far below the
/// size of the loop: its root's error is about e / √|μ|) is not decided.
fn squares_decide(squares: &[c64], size: f64) -> bool {
    let error = SQUARED_ERROR_UNITS * squares.len() as f64 * f64::EPSILON * size;
    squares.iter().all(|mu| {
        let modulus = mu.norm();
        let from_axis = if mu.re <= 0.0 { mu.im.abs() } else { modulus };
        error <= 1e-8 * modulus || from_axis > 2.0 * error + 4.0 * AXIS_TOLERANCE * modulus
    })
}

/// [`axis_candidates`] of the roots ±√μ of the squares μ: the frequencies ω >= 0 of those
/// within [`AXIS_TOLERANCE`] of the imaginary axis (√μ with Im >= 0 of a negative real μ).
fn squared_axis_candidates(squares: &[c64]) -> Vec<f64> {
    let roots: Vec<c64> = squares
        .iter()
        .map(|mu| {
            let root = mu.sqrt();
            if root.im >= 0.0 { root } else { -root }
        })
        .collect();
    axis_candidates(&roots)
}

/// The finite zeros of the strictly proper SISO realisation (A, b, c, 0), with the size their
/// errors are relative to, or None when its transfer vanishes identically (the system pencil
/// is singular).
///
/// The reduction of Emami-Naeini and Van Dooren (1982) for one input and one output: a
/// Householder reflection H with H b = β e_N brings the input onto the last state; the last
/// state equation then only determines u. If c̃_N = (c H)_N is not zero (to 1e-10 of |c|,
/// the relative degree is reached), x_N = -c̃_1 x_1 / c̃_N and the zeros are the eigenvalues of
/// Ã_11 - ã_12 c̃_1 / c̃_N (order N - 1); otherwise x_N is the input of the system
/// (Ã_11, ã_12, c̃_1, 0) of order N - 1, which has the same zeros, and the step repeats. The
/// reflections are orthogonal; the one division is by the largest Markov parameter direction
/// left, and a zero it makes large is a candidate the caller verifies like any other. The size
/// is ||A||_F + ||ã_12|| ||c̃_1|| / |c̃_N|: the reflections' errors are relative to A, and the
/// division's to the rank-one term before it cancels against Ã_11.
fn siso_zeros(a: MatRef<'_, f64>, b: &[f64], c: &[f64]) -> Result<Option<(Vec<c64>, f64)>, Error> {
    let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
    let a_scale = max_abs(a).max(f64::MIN_POSITIVE);
    let a_size = frobenius_norm(a);
    let c_scale = norm(c);
    let b_scale = norm(b);
    let mut a = a.to_owned();
    let mut b = b.to_vec();
    let mut c = c.to_vec();
    // The first input is b itself; later ones are columns of A, measured against A.
    let mut input_scale = b_scale;
    loop {
        let n = a.nrows();
        if n == 0 {
            return Ok(None); // every Markov parameter vanishes: the transfer is 0
        }
        let (nb, nc) = (norm(&b), norm(&c));
        if nb <= 1e-13 * input_scale || nc <= 1e-13 * c_scale || nb == 0.0 || nc == 0.0 {
            return Ok(None);
        }
        // v = b + sign(b_N) |b| e_N; H = I - 2 v v^T / v^T v maps b to -sign(b_N) |b| e_N.
        let mut v = b.clone();
        let sign = if b[n - 1] >= 0.0 { 1.0 } else { -1.0 };
        v[n - 1] += sign * nb;
        let vv: f64 = v.iter().map(|x| x * x).sum();
        // A <- H A H, c <- c H.
        for j in 0..n {
            let dot: f64 = (0..n).map(|i| v[i] * a[(i, j)]).sum();
            let f = 2.0 * dot / vv;
            for i in 0..n {
                a[(i, j)] -= f * v[i];
            }
        }
        for i in 0..n {
            let dot: f64 = (0..n).map(|j| a[(i, j)] * v[j]).sum();
            let f = 2.0 * dot / vv;
            for j in 0..n {
                a[(i, j)] -= f * v[j];
            }
        }
        let dot: f64 = c.iter().zip(&v).map(|(x, y)| x * y).sum();
        let f = 2.0 * dot / vv;
        for (x, y) in c.iter_mut().zip(&v) {
            *x -= f * y;
        }
        let last = c[n - 1];
        let m = n - 1;
        if last.abs() > 1e-10 * nc {
            let reduced = Mat::from_fn(m, m, |i, j| a[(i, j)] - a[(i, m)] * c[j] / last);
            let column = norm(&(0..m).map(|i| a[(i, m)]).collect::<Vec<_>>());
            let size = a_size + column * norm(&c[..m]) / last.abs();
            return Ok(Some((eigenvalues(reduced.as_ref())?, size)));
        }
        b = (0..m).map(|i| a[(i, m)]).collect();
        c.truncate(m);
        a = Mat::from_fn(m, m, |i, j| a[(i, j)]);
        input_scale = a_scale;
    }
}

/// The frequencies ω >= 0 of the eigenvalues within [`AXIS_TOLERANCE`] of the imaginary axis.
fn axis_candidates(values: &[c64]) -> Vec<f64> {
    values
        .iter()
        .filter(|v| v.im >= 0.0 && v.re.abs() <= AXIS_TOLERANCE * v.norm())
        .map(|v| v.im)
        .collect()
}

/// Relative correction below which the secant method stops without evaluating the next point.
const SECANT_TOLERANCE: f64 = 1e-13;

/// The secant method on f(ω) = objective(L(jω)) from ω0 (its first step through
/// ω0 (1 + 1e-7) and ω0, the later point), at most 12 steps, staying within 1e-3 of ω0
/// (relative), until a step is within 4u of ω or the next correction of the best point is
/// within [`SECANT_TOLERANCE`] of it (an accurate ω0 takes two values); returns the point of
/// smallest |f| met (not
/// below 0) and L there (the value already evaluated, or L(0) where the best point was
/// negative).
fn secant(
    mut evaluate: impl FnMut(f64) -> c64,
    objective: impl Fn(c64) -> f64,
    omega: f64,
) -> (f64, c64) {
    let mut f = |w: f64| {
        let value = evaluate(w);
        (objective(value), value)
    };
    let step = if omega > 0.0 { 1e-7 * omega } else { 1e-7 };
    let ((fa, va), (fb, vb)) = (f(omega), f(omega + step));
    // ω itself is the later point: where the first correction of it is below the tolerance,
    // the candidate is already the root to that accuracy and no third value is needed.
    let (mut x0, mut f0, mut x1, mut f1) = (omega + step, fb, omega, fa);
    let (mut best, mut best_f, mut best_value) = if fb.abs() < fa.abs() {
        (x0, fb, vb)
    } else {
        (x1, fa, va)
    };
    if !best_f.is_finite() {
        return (
            omega,
            if best == omega {
                best_value
            } else {
                evaluate(omega)
            },
        );
    }
    for _ in 0..12 {
        if f1 == f0 || best_f == 0.0 {
            break;
        }
        let x2 = x1 - f1 * (x1 - x0) / (f1 - f0);
        if !x2.is_finite() || (x2 - omega).abs() > 1e-3 * omega.max(1e-300) + step {
            break;
        }
        if best == x1 && (x2 - x1).abs() <= SECANT_TOLERANCE * x1.abs() {
            // The correction the step would make: x1, the best point, is that close to the
            // root (the method converges superlinearly), and the value there is kept.
            break;
        }
        let (f2, v2) = f(x2);
        if !f2.is_finite() {
            break;
        }
        if f2.abs() < best_f.abs() {
            (best, best_f, best_value) = (x2, f2, v2);
        }
        if (x2 - x1).abs() <= 4.0 * f64::EPSILON * x2.abs() {
            break;
        }
        (x0, f0, x1, f1) = (x1, f1, x2, f2);
    }
    if best < 0.0 {
        (0.0, evaluate(0.0))
    } else {
        (best, best_value)
    }
}

/// Sorted, with crossovers within 1e-9 of each other (relative) merged.
fn merged(mut found: Vec<Crossover>) -> Vec<Crossover> {
    found.sort_by(|x, y| x.omega.total_cmp(&y.omega));
    let mut out: Vec<Crossover> = Vec::with_capacity(found.len());
    for x in found {
        match out.last() {
            Some(last) if (x.omega - last.omega).abs() <= 1e-9 * x.omega.max(1e-300) => {}
            _ => out.push(x),
        }
    }
    out
}

/// The SISO loop's vectors and its evaluator.
struct Loop<'a> {
    a: MatRef<'a, f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: f64,
    evaluator: FrequencyEvaluator,
}

impl Loop<'_> {
    fn at(&mut self, omega: f64) -> c64 {
        self.evaluator.siso(omega)
    }

    fn gain_crossovers(&mut self) -> Result<Vec<Crossover>, Error> {
        let n = self.a.nrows();
        let d = self.d;
        let candidates = if (1.0 - d * d).abs() > 1e-12 {
            hamiltonian_axis_frequencies(self.a, &self.b, &self.c, d)?
        } else {
            // d^2 = 1: the system pencil of 1 - L(-s) L(s).
            let a2 = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                (true, true) => self.a[(i, j)],
                (true, false) => 0.0,
                (false, true) => self.b[i - n] * self.c[j],
                (false, false) => -self.a[(i - n, j - n)],
            });
            let b2: Vec<f64> = (0..2 * n)
                .map(|i| if i < n { self.b[i] } else { d * self.b[i - n] })
                .collect();
            let c2: Vec<f64> = (0..2 * n)
                .map(|j| if j < n { -d * self.c[j] } else { self.c[j - n] })
                .collect();
            match siso_zeros(a2.as_ref(), &b2, &c2)? {
                Some((zeros, _)) => axis_candidates(&zeros),
                None => Vec::new(),
            }
        };
        let mut found = Vec::with_capacity(candidates.len());
        for omega in candidates {
            let (w, value) = secant(|w| self.at(w), |v| v.norm().ln(), omega);
            if (value.norm() - 1.0).abs() <= CROSSOVER_TOLERANCE {
                found.push(Crossover { omega: w, value });
            }
        }
        Ok(merged(found))
    }

    /// The loop's magnitude scale: |d| and |L| between and beyond the poles' frequencies
    /// (geometric means of consecutive moduli above 1e-10 of the largest, half the smallest, twice the largest;
    /// ω = 1 without a nonzero pole), never at a pole.
    fn scale(&mut self, poles: &[c64]) -> f64 {
        let largest = poles.iter().fold(0.0f64, |m, p| m.max(p.norm()));
        let mut moduli: Vec<f64> = poles
            .iter()
            .map(|p| p.norm())
            .filter(|&m| m > 1e-10 * largest)
            .collect();
        moduli.sort_by(f64::total_cmp);
        let mut points: Vec<f64> = moduli.windows(2).map(|w| (w[0] * w[1]).sqrt()).collect();
        match (moduli.first(), moduli.last()) {
            (Some(&low), Some(&high)) => points.extend([0.5 * low, 2.0 * high]),
            _ => points.push(1.0),
        }
        let mut scale = self.d.abs();
        for omega in points {
            let value = self.at(omega).norm();
            if value.is_finite() {
                scale = scale.max(value);
            }
        }
        scale
    }

    /// The frequencies ω >= 0 of the zeros within [`AXIS_TOLERANCE`] of the imaginary axis of
    /// the odd function L(s) - L(-s), and whether it vanishes identically (degenerate).
    ///
    /// L(jω) = d - c A (A^2 + ω^2 I)^-1 b - jω c (A^2 + ω^2 I)^-1 b, so L(s) - L(-s) =
    /// -2s Q(-s^2) with Q(μ) = c (μI - M)^-1 b, M = -A^2: its zeros other than 0 are ±√(-μ)
    /// for the zeros μ of Q, a realisation of order n where the pencil of L(s) - L(-s) has
    /// order 2n. The squares s^2 = -μ are taken where they decide the test of the axis
    /// ([`squares_decide`], with the size ||A||_F^2 of forming M and that of the reduction's
    /// division); otherwise
    /// (a zero near the axis at a frequency far below the loop's size, or Q vanishing
    /// identically to the reduction's tolerance) the zeros of the pencil of order 2n decide.
    fn phase_axis_frequencies(&self) -> Result<(Vec<f64>, bool), Error> {
        let n = self.a.nrows();
        let m = Mat::from_fn(n, n, |i, j| {
            -(0..n).map(|k| self.a[(i, k)] * self.a[(k, j)]).sum::<f64>()
        });
        if let Some((zeros, size)) = siso_zeros(m.as_ref(), &self.b, &self.c)? {
            let squares: Vec<c64> = zeros.iter().map(|z| -z).collect();
            let product = frobenius_norm(self.a).powi(2);
            if squares_decide(&squares, size + product) {
                return Ok((squared_axis_candidates(&squares), false));
            }
        }
        let a2 = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => self.a[(i, j)],
            (false, false) => -self.a[(i - n, j - n)],
            _ => 0.0,
        });
        let b2: Vec<f64> = (0..2 * n).map(|i| self.b[i % n.max(1)]).collect();
        let c2: Vec<f64> = (0..2 * n).map(|j| self.c[j % n.max(1)]).collect();
        Ok(match siso_zeros(a2.as_ref(), &b2, &c2)? {
            Some((zeros, _)) => (axis_candidates(&zeros), false),
            None => (Vec::new(), true),
        })
    }

    fn phase_crossovers(&mut self, poles: &[c64]) -> Result<(Vec<Crossover>, bool), Error> {
        let (frequencies, degenerate) = self.phase_axis_frequencies()?;
        let frequency_scale = poles.iter().fold(max_abs(self.a), |m, p| m.max(p.norm()));
        let mut candidates = vec![0.0];
        candidates.extend(
            frequencies
                .into_iter()
                .filter(|&w| w > 1e-10 * frequency_scale && w < 1e8 * frequency_scale),
        );
        let vanishing = 1e-10 * self.scale(poles);
        let mut found = Vec::with_capacity(candidates.len());
        for omega in candidates {
            let (w, value) = if omega == 0.0 {
                (0.0, self.at(0.0))
            } else {
                secant(|w| self.at(w), |v| v.im / v.norm(), omega)
            };
            if value.re.is_finite()
                && value.im.is_finite()
                && value.norm() > vanishing
                && value.im.abs() <= CROSSOVER_TOLERANCE * value.norm()
            {
                found.push(Crossover {
                    omega: w,
                    value: c64::new(value.re, if w == 0.0 { 0.0 } else { value.im }),
                });
            }
        }
        Ok((merged(found), degenerate))
    }
}

/// (ω, f(ω)) at a maximum of f on [lo, hi] by Brent's method (golden section with
/// successive parabolic interpolation; Brent 1973, ch. 5, procedure localmin), to 1e-8 of ω:
/// near a smooth maximum f changes by a relative u over a relative step of about √u, so no
/// evaluation tells closer points apart (Brent's tolerance must be at least √u |x|), and the
/// value found is already within rounding of the maximum's (the best point met is kept).
fn golden_maximum(f: &mut impl FnMut(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    let golden = (3.0 - 5f64.sqrt()) / 2.0;
    let mut g = |x: f64| {
        let v = f(x);
        if v.is_nan() { f64::INFINITY } else { -v }
    };
    let mut x = lo + golden * (hi - lo);
    let (mut w, mut v) = (x, x);
    let mut fx = g(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..100 {
        let middle = 0.5 * (lo + hi);
        let tol = 1e-8 * x.abs() + 1e-300;
        let tol2 = 2.0 * tol;
        if (x - middle).abs() <= tol2 - 0.5 * (hi - lo) {
            break;
        }
        let mut golden_step = true;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let previous = e;
            e = d;
            if p.abs() < (0.5 * q * previous).abs() && p > q * (lo - x) && p < q * (hi - x) {
                d = p / q;
                let u = x + d;
                if u - lo < tol2 || hi - u < tol2 {
                    d = if x < middle { tol } else { -tol };
                }
                golden_step = false;
            }
        }
        if golden_step {
            e = if x < middle { hi - x } else { lo - x };
            d = golden * e;
        }
        let u = if d.abs() >= tol {
            x + d
        } else if d > 0.0 {
            x + tol
        } else {
            x - tol
        };
        let fu = g(u);
        if fu <= fx {
            if u < x {
                hi = x;
            } else {
                lo = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                lo = u;
            } else {
                hi = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, -fx)
}

/// The L∞ norm over ω in [0, ∞] of the SISO G = (A, B, C, d) (see the module's
/// documentation), with `poles` the eigenvalues of A.
pub fn peak_gain(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    d: f64,
    poles: &[c64],
) -> Result<Peak, Error> {
    let n = a.nrows();
    let bm = Mat::from_fn(n, 1, |i, _| b[i]);
    let cm = Mat::from_fn(1, n, |_, j| c[j]);
    let dm = Mat::from_fn(1, 1, |_, _| d);
    let mut evaluator = FrequencyEvaluator::new(a, bm.as_ref(), cm.as_ref(), dm.as_ref())?;
    let mut evaluated = Vec::new();
    let mut transfer = LoopTransfer {
        evaluator: &mut evaluator,
        evaluated: &mut evaluated,
        kind: Transfer::Loop,
    };
    peak(a, b, c, d, poles, &mut transfer)
}

/// Which transfer of the loop L a peak search measures.
#[derive(Clone, Copy)]
enum Transfer {
    /// L itself.
    Loop,
    /// S = 1/(1 + L).
    Sensitivity,
    /// (1 - L)/(2 (1 + L)), the disk margin's.
    Disk,
}

/// A transfer of the loop at points of the imaginary axis, from L(jω) and its derivatives by
/// the loop's evaluator; the values of L at the points already met are looked up, not
/// evaluated again (the two peaks share their test frequencies).
struct LoopTransfer<'a> {
    evaluator: &'a mut FrequencyEvaluator,
    evaluated: &'a mut Vec<(f64, c64)>,
    kind: Transfer,
}

impl LoopTransfer<'_> {
    /// |G(jω)|.
    fn magnitude(&mut self, omega: f64) -> f64 {
        let value = match self
            .evaluated
            .iter()
            .find(|(x, _)| x.to_bits() == omega.to_bits())
        {
            Some(&(_, value)) => value,
            None => {
                let value = self.evaluator.siso(omega);
                self.evaluated.push((omega, value));
                value
            }
        };
        self.kind.magnitude(value)
    }

    /// (|G(jω)|, ψ'(ω), ψ''(ω), ψ'''(ω)) for ψ = ln |G(jω)|, from [L, L', L'', L'''] (derivatives
    /// in ω): with r_k = G^(k)/G, ψ' = Re r_1, ψ'' = Re(r_2 - r_1^2) and
    /// ψ''' = Re(r_3 - 3 r_1 r_2 + 2 r_1^3), each G a product of powers of L, 1 - L and 1 + L,
    /// so that these are sums of the same expressions of f^(k)/f over those factors f. None
    /// where the evaluator gives no derivatives (see [`FrequencyEvaluator::siso_derivatives`]).
    fn curvature(&mut self, omega: f64) -> Option<(f64, [f64; 3])> {
        let [value, first, second, third] = self.evaluator.siso_derivatives(omega)?;
        // The terms of e ln |f|, f = p + q L.
        let term = |q: f64, f: c64, e: f64| {
            let (r1, r2, r3) = ((first * q) / f, (second * q) / f, (third * q) / f);
            [
                e * r1.re,
                e * (r2 - r1 * r1).re,
                e * (r3 - r1 * r2 * 3.0 + r1 * r1 * r1 * 2.0).re,
            ]
        };
        let one = c64::new(1.0, 0.0);
        let derivatives = match self.kind {
            Transfer::Loop => term(1.0, value, 1.0),
            Transfer::Sensitivity => term(1.0, one + value, -1.0),
            Transfer::Disk => {
                let (x, y) = (term(-1.0, one - value, 1.0), term(1.0, one + value, -1.0));
                [x[0] + y[0], x[1] + y[1], x[2] + y[2]]
            }
        };
        Some((self.kind.magnitude(value), derivatives))
    }
}

impl Transfer {
    /// |G| from L.
    fn magnitude(self, value: c64) -> f64 {
        match self {
            Transfer::Loop => value.norm(),
            Transfer::Sensitivity => 1.0 / (1.0 + value).norm(),
            Transfer::Disk => (1.0 - value).norm() / (2.0 * (1.0 + value).norm()),
        }
    }
}

/// Steps [`newton_maximum`] takes before it hands the bracket to [`golden_maximum`].
const NEWTON_STEPS: usize = 16;

/// The gain in ln |G| Newton's step predicts below which [`newton_maximum`] takes its last
/// step: the error after a Newton step is of order that before it squared, so the gain left
/// is of order this squared (1e-18 times a modest ratio of the third derivative to the
/// second), below rounding, and less after Halley's step.
const FINAL_GAIN: f64 = 1e-9;

/// (ω, |G(jω)|) at a maximum of |G| on [lo, hi] from `start` in it, by Halley's method on
/// ψ' = 0 for ψ = ln |G| (ψ', ψ'' and ψ''' from [`LoopTransfer::curvature`]; Halley 1694,
/// the step -2 ψ' ψ'' / (2 ψ''^2 - ψ' ψ'''), cubically convergent), safeguarded: the step is
/// Halley's where it goes the way of Newton's step -ψ'/ψ'' and at most twice as far, else
/// Newton's; each point where ψ' > 0 becomes the bracket's lower end, each where ψ' < 0 its
/// upper end (the maximum the steps approach lies between), and a step that is not an ascent
/// (ψ'' >= 0) or leaves the bracket is replaced by its midpoint. Where the gain Newton's step
/// predicts for ψ, ψ'^2/(2|ψ''|) (relative, for |G|), is below [`FINAL_GAIN`], the step is the
/// last: |G| alone is evaluated at its end (not at all where the gain is within 4u: no
/// evaluation tells the points apart). It also stops where the bracket is within 4u of ω.
/// After [`NEWTON_STEPS`] steps, or where the derivatives are not available or not finite,
/// [`golden_maximum`] searches the bracket left. The best point met is returned.
fn newton_maximum(transfer: &mut LoopTransfer<'_>, lo: f64, hi: f64, start: f64) -> (f64, f64) {
    let (mut lo, mut hi, mut x) = (lo, hi, start);
    let mut best = (x, f64::NEG_INFINITY);
    let mut converged = false;
    for _ in 0..NEWTON_STEPS {
        let Some((value, [slope, bend, twist])) = transfer.curvature(x) else {
            break;
        };
        if !(value.is_finite() && slope.is_finite() && bend.is_finite() && twist.is_finite()) {
            break;
        }
        if value > best.1 {
            best = (x, value);
        }
        if slope > 0.0 {
            lo = x;
        } else if slope < 0.0 {
            hi = x;
        }
        let newton = -slope / bend;
        // Halley's step is Newton's divided by 1 - ψ' ψ''' / (2 ψ''^2).
        let divisor = 1.0 - slope * twist / (2.0 * bend * bend);
        let step = if divisor >= 0.5 {
            newton / divisor
        } else {
            newton
        };
        let next = x + step;
        let inside = bend < 0.0 && next > lo && next < hi;
        let gain = (0.5 * slope * newton).abs();
        if inside && gain <= FINAL_GAIN {
            // The step's end is within rounding of the maximum: its value is the maximum's,
            // and no derivative is needed there.
            if gain > 4.0 * f64::EPSILON {
                let value = transfer.magnitude(next);
                if value > best.1 {
                    best = (next, value);
                }
            }
            converged = true;
            break;
        }
        x = if inside { next } else { 0.5 * (lo + hi) };
        if hi - lo <= 4.0 * f64::EPSILON * x.abs() {
            converged = true;
            break;
        }
    }
    if converged || hi <= lo {
        return best;
    }
    let found = golden_maximum(&mut |w| transfer.magnitude(w), lo, hi);
    if found.1 > best.1 { found } else { best }
}

/// [`peak_gain`] of the `transfer` (|G(jω)| and its derivatives by the loop's evaluator).
///
/// The lower bound before the first Hamiltonian is the best of ω = ∞, ω = 0 and the poles'
/// frequencies (|p| and |Im p|), refined by [`newton_maximum`] from that frequency, within its
/// neighbours among them: where the peak is a resonance near a pole (the usual case), the
/// first Hamiltonian then has no imaginary eigenvalue and confirms it.
fn peak(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    d: f64,
    poles: &[c64],
    transfer: &mut LoopTransfer<'_>,
) -> Result<Peak, Error> {
    let n = a.nrows();
    let scale = poles.iter().fold(max_abs(a), |m, p| m.max(p.norm()));
    // A pole on the axis to its accuracy makes the peak infinite: u ||A|| in general, its own
    // size where the nonzero poles' moduli span more than GRADED_SPREAD (the small ones are
    // then computed on the graded ordering, or polished, to about their own size).
    let smallest = poles
        .iter()
        .map(|p| p.norm())
        .filter(|&m| m > 0.0)
        .fold(f64::INFINITY, f64::min);
    let graded = scale > GRADED_SPREAD * smallest;
    let size = |p: &c64| if graded { p.norm() } else { scale };
    if let Some(p) = poles
        .iter()
        .find(|p| p.re.abs() <= 1e-14 * size(p).max(f64::MIN_POSITIVE) && n > 0)
    {
        return Ok(Peak {
            omega: p.im.abs(),
            value: f64::INFINITY,
        });
    }
    // The lower bound: ∞ first (ties keep it), then 0, then the poles' frequencies.
    let mut best = Peak {
        omega: f64::INFINITY,
        value: d.abs(),
    };
    let mut tests = std::iter::once(0.0)
        .chain(poles.iter().flat_map(|p| [p.im.abs(), p.norm()]))
        .collect::<Vec<_>>();
    tests.sort_by(f64::total_cmp);
    tests.dedup();
    let mut best_test = None;
    for (index, &w) in tests.iter().enumerate() {
        let value = transfer.magnitude(w);
        if value > best.value * (1.0 + 1e-12) {
            best = Peak { omega: w, value };
            best_test = Some(index);
        }
    }
    if best.value == 0.0 {
        return Ok(best);
    }
    if let Some(index) = best_test {
        let lo = if index > 0 { tests[index - 1] } else { 0.0 };
        let hi = tests.get(index + 1).copied().unwrap_or(2.0 * tests[index]);
        if hi > lo {
            let (w, value) = newton_maximum(transfer, lo, hi, tests[index]);
            if value > best.value {
                best = Peak { omega: w, value };
            }
        }
    }
    for _ in 0..60 {
        crate::platform::interrupt::check()?;
        let gamma = (1.0 + 2.0 * PEAK_TOLERANCE) * best.value;
        let scaled: Vec<f64> = c.iter().map(|v| v / gamma).collect();
        let mut omegas = hamiltonian_axis_frequencies(a, b, &scaled, d / gamma)?;
        if omegas.is_empty() {
            break;
        }
        omegas.sort_by(f64::total_cmp);
        if omegas.len() % 2 == 1 {
            omegas.insert(0, 0.0);
        }
        // The interval whose midpoint is highest, then its maximum by golden section.
        let mut chosen: Option<(f64, f64, f64)> = None;
        for pair in omegas.windows(2) {
            let value = transfer.magnitude(0.5 * (pair[0] + pair[1]));
            if chosen.is_none_or(|(_, _, v)| value > v) {
                chosen = Some((pair[0], pair[1], value));
            }
        }
        let Some((lo, hi, _)) = chosen else { break };
        let (w, value) = newton_maximum(transfer, lo, hi, 0.5 * (lo + hi));
        if value.is_nan() || value <= best.value {
            break;
        }
        best = Peak { omega: w, value };
    }
    Ok(best)
}

/// The margins of a SISO loop's crossovers (negative feedback, 1 + L = 0), as
/// `StabilityMargins` holds them.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossoverMargins {
    /// The gain margins 1/|L| at the phase crossovers where L < 0 (∞ where L = 0, 0 where |L|
    /// overflows), those crossovers, the phase margins 180° + ∠L in (-180°, 180°] at the gain
    /// crossovers, those crossovers, and the delay margins (phase margin mod 360°, in
    /// radians)/ω at the gain crossovers above 0: five parts of one array, by increasing ω.
    pub values: Vec<f64>,
    /// The number of gain margins (of phase crossovers where L < 0).
    pub gain_margins: usize,
    /// The number of phase margins (of gain crossovers).
    pub phase_margins: usize,
    /// The critical gain margin (the nearest 0 dB, the first of equals; ∞ without one) and
    /// its crossover (NaN without one).
    pub gain_margin: (f64, f64),
    /// The critical phase margin (of least magnitude, the first of equals; ∞ without one)
    /// and its crossover (NaN without one).
    pub phase_margin: (f64, f64),
    /// The least delay margin (∞ without a gain crossover above 0).
    pub delay_margin: f64,
}

/// ``angle`` in [0°, 360°] wrapped to (-180°, 180°] (Python's `math.remainder(angle, 360)`
/// with -180 taken as 180: exact, as 360 - angle is by Sterbenz's lemma).
fn wrap_degrees(angle: f64) -> f64 {
    if angle > 180.0 { angle - 360.0 } else { angle }
}

/// The gain, phase and delay margins of the `phase` and `gain` crossovers (each by
/// increasing ω; see [`CrossoverMargins`]): 1/|L| at each phase crossover with L < 0,
/// 180° + atan2(Im L, Re L) in degrees wrapped to (-180°, 180°] at each gain crossover, and
/// (PM mod 360°)/ω in radians per second for those with ω > 0.
pub fn crossover_margins(phase: &[Crossover], gain: &[Crossover]) -> CrossoverMargins {
    let negative: Vec<&Crossover> = phase.iter().filter(|x| x.value.re < 0.0).collect();
    let mut values = Vec::with_capacity(2 * negative.len() + 3 * gain.len());
    let (mut gm, mut w_gm, mut nearest) = (f64::INFINITY, f64::NAN, f64::INFINITY);
    for (index, x) in negative.iter().enumerate() {
        let modulus = x.value.norm();
        let g = if modulus > 0.0 {
            1.0 / modulus
        } else {
            f64::INFINITY
        };
        values.push(g);
        let distance = if g > 0.0 { g.ln().abs() } else { f64::INFINITY };
        if distance < nearest || index == 0 {
            (gm, w_gm, nearest) = (g, x.omega, distance);
        }
    }
    values.extend(negative.iter().map(|x| x.omega));
    let (mut pm, mut w_pm, mut nearest) = (f64::INFINITY, f64::NAN, f64::INFINITY);
    let mut delays = Vec::with_capacity(gain.len());
    for (index, x) in gain.iter().enumerate() {
        let phase = wrap_degrees(180.0 + x.value.im.atan2(x.value.re).to_degrees());
        values.push(phase);
        if x.omega > 0.0 {
            // Python's phase % 360: in [0, 360).
            let turned = if phase < 0.0 {
                phase + 360.0
            } else {
                phase % 360.0
            };
            delays.push(turned.to_radians() / x.omega);
        }
        if phase.abs() < nearest || index == 0 {
            (pm, w_pm, nearest) = (phase, x.omega, phase.abs());
        }
    }
    values.extend(gain.iter().map(|x| x.omega));
    let delay_margin = delays.iter().copied().fold(f64::INFINITY, f64::min);
    values.extend(delays);
    CrossoverMargins {
        values,
        gain_margins: negative.len(),
        phase_margins: gain.len(),
        gain_margin: (gm, w_gm),
        phase_margin: (pm, w_pm),
        delay_margin,
    }
}

/// (the number of roots in the open right half plane, whether every root is in the open left
/// half plane) where every root is farther from the imaginary axis than √u `size` (the
/// boundary tolerance of `loops.py`'s `_census`, `size` the balanced matrix's Frobenius
/// norm); None where one is not (or is NaN, or `size` is not finite), for the caller's
/// census with the roots' own error bounds.
pub fn census_off_axis(roots: &[c64], size: f64) -> Option<(usize, bool)> {
    if !size.is_finite() {
        return None;
    }
    let tolerance = f64::EPSILON.sqrt() * size;
    if roots.iter().all(|r| r.re.abs() > tolerance) {
        let unstable = roots.iter().filter(|r| r.re > 0.0).count();
        Some((unstable, unstable == 0))
    } else {
        None
    }
}

/// Crossovers, disk and stability peaks, and poles of the continuous SISO loop
/// L(s) = C (sI - A)^-1 B + D (A n x n, B n x 1, C 1 x n, D 1 x 1), with every gain margin
/// verified by a closed-loop pole (see the module's documentation). 1 + D = 0 (an algebraic
/// loop) is [`Error::Singular`].
pub fn loop_margins(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
) -> Result<LoopMargins, Error> {
    check_state_space(a, b, c, d)?;
    if b.ncols() != 1 || c.nrows() != 1 {
        return Err(Error::InvalidArgument {
            arg: "loop",
            message: format!(
                "loop must have one input and one output, got {} outputs and {} inputs",
                c.nrows(),
                b.ncols()
            ),
        });
    }
    let n = a.nrows();
    let d0 = d[(0, 0)];
    let denominator = 1.0 + d0;
    if denominator.abs() <= 8.0 * f64::EPSILON * d0.abs().max(1.0) {
        return Err(Error::Singular {
            arg: "1 + D (the closed loop is an algebraic loop)",
            eigenvalue_re: denominator,
            eigenvalue_im: 0.0,
        });
    }
    // The states balanced first (T A T^-1, T b, c T^-1: the same loop): the pencils' zeros and
    // the Hamiltonians' eigenvalues are computed to a backward error relative to the system's
    // size, and states scaled by 10^±6 put the phase crossovers' zeros off the axis.
    let (am, bm, cm) =
        balanced_states(a, b, c).unwrap_or_else(|| (a.to_owned(), b.to_owned(), c.to_owned()));
    let (a, b, c) = (am.as_ref(), bm.as_ref(), cm.as_ref());
    let bv: Vec<f64> = (0..n).map(|i| b[(i, 0)]).collect();
    let cv: Vec<f64> = (0..n).map(|j| c[(0, j)]).collect();
    let open_loop_poles = eigenvalues(a)?;
    let closed = Mat::from_fn(n, n, |i, j| a[(i, j)] - bv[i] * cv[j] / denominator);
    let mut this = Loop {
        a,
        b: bv.clone(),
        c: cv.clone(),
        d: d0,
        evaluator: FrequencyEvaluator::new(a, b, c, d)?,
    };
    // S = 1/(1 + L) and (1 - L)/(2 (1 + L)) = S - 1/2 share the closed loop's realisation.
    let bs: Vec<f64> = bv.iter().map(|v| v / denominator).collect();
    let cs: Vec<f64> = cv.iter().map(|v| -v / denominator).collect();
    // The crossovers and the two peaks are independent, but each is a few tens of µs at n = 6:
    // split between two threads, the worker left spinning after the join slowed the caller's
    // Python (on a sibling hyperthread) by more than the split saved.
    let gain_crossovers = this.gain_crossovers()?;
    let (phase_crossovers, degenerate) = this.phase_crossovers(&open_loop_poles)?;
    // The closed loop's poles (gain 1/(1 + d)) and those of the loops closed with the gain
    // margins (verified below) from one controller-Hessenberg form of (A, b, c).
    let margin_gains: Vec<(&Crossover, f64)> = phase_crossovers
        .iter()
        .filter(|x| x.value.re < 0.0)
        .filter_map(|crossover| {
            let k = 1.0 / crossover.value.norm();
            let shifted = 1.0 + k * d0;
            if shifted.abs() <= 8.0 * f64::EPSILON * (k * d0).abs().max(1.0) || n == 0 {
                None
            } else {
                Some((crossover, k))
            }
        })
        .collect();
    let gains: Vec<f64> = std::iter::once(1.0 / denominator)
        .chain(margin_gains.iter().map(|&(_, k)| k / (1.0 + k * d0)))
        .collect();
    let mut spectra = root_locus::closed_loop_poles_at(a, &bv, &cv, &gains)?.into_iter();
    let closed_loop_poles = spectra.next().unwrap_or_default();
    // Both peaks start from L at the same test frequencies (0 and the closed-loop poles'):
    // each value is computed once and looked up the second time (the same value, so the
    // same peaks bit for bit).
    let mut evaluated: Vec<(f64, c64)> = Vec::with_capacity(8 * n + 8);
    let (s_d, disk_d) = (1.0 / denominator, 1.0 / denominator - 0.5);
    let sensitivity = peak(
        closed.as_ref(),
        &bs,
        &cs,
        s_d,
        &closed_loop_poles,
        &mut LoopTransfer {
            evaluator: &mut this.evaluator,
            evaluated: &mut evaluated,
            kind: Transfer::Sensitivity,
        },
    )?;
    let disk = peak(
        closed.as_ref(),
        &bs,
        &cs,
        disk_d,
        &closed_loop_poles,
        &mut LoopTransfer {
            evaluator: &mut this.evaluator,
            evaluated: &mut evaluated,
            kind: Transfer::Disk,
        },
    )?;

    // Each gain margin k puts a closed-loop pole at its crossover.
    let size = 1.0 + max_abs(a);
    for ((crossover, k), poles) in margin_gains.into_iter().zip(spectra) {
        let point = c64::new(0.0, crossover.omega);
        let miss = poles
            .iter()
            .map(|p| (p - point).norm())
            .fold(f64::INFINITY, f64::min);
        if miss.is_nan() || miss > 1e-6 * size.max(crossover.omega) {
            return Err(Error::IllConditioned {
                message: format!(
                    "stability_margins: the loop closed with its gain margin {k:.6e} has no pole \
                     at the phase crossover {:.6} rad/s (nearest at distance {miss:.3e})",
                    crossover.omega
                ),
            });
        }
    }
    let closed_loop_size = census_size(closed.as_ref(), &closed_loop_poles);
    let open_loop_size = census_size(a, &open_loop_poles);
    let mut closed_loop_poles = closed_loop_poles;
    root_locus::sort(&mut closed_loop_poles);
    Ok(LoopMargins {
        gain_crossovers,
        phase_crossovers,
        disk,
        sensitivity,
        closed_loop_poles,
        open_loop_poles,
        degenerate,
        closed_loop_size,
        open_loop_size,
    })
}

/// The size of `m` that the census of its eigenvalues `poles` is taken against
/// ([`census_off_axis`]): ||m||_F of m balanced alone ([`balanced_states`]; of m itself where
/// that scaling is not exact), or, where every pole clears the census's tolerance for a bound
/// of it, that bound, ||m||_F of m as given (with room for the two norms' rounding, 4 (n^2 + 2)
/// u): each step Osborne's iteration takes multiplies the off-diagonal row and column of one
/// index, of norms r and c, by 2^k and 2^-k with r 2^k + c 2^-k below r + c and the product
/// r c unchanged, so their sum of squares, (r 2^k + c 2^-k)^2 - 2 r c, and with it ||m||_F
/// decrease. The census is then the same as against the balanced size, which is not needed.
fn census_size(m: MatRef<'_, f64>, poles: &[c64]) -> f64 {
    let n = m.nrows();
    let bound = frobenius_norm(m) * (1.0 + 4.0 * (n * n + 2) as f64 * f64::EPSILON);
    if census_off_axis(poles, bound).is_some() {
        return bound;
    }
    let empty = Mat::<f64>::zeros(n, 0);
    balanced_states(m, empty.as_ref(), empty.transpose())
        .map_or_else(|| frobenius_norm(m), |(b, _, _)| frobenius_norm(b.as_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// (A, B, C, D) of the controllable canonical form of num/den (den monic, deg num < deg den).
    fn canonical(num: &[f64], den: &[f64], d: f64) -> (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>) {
        let n = den.len() - 1;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == 0 {
                -den[j + 1]
            } else if i == j + 1 {
                1.0
            } else {
                0.0
            }
        });
        let b = Mat::from_fn(n, 1, |i, _| if i == 0 { 1.0 } else { 0.0 });
        // num padded on the left to n coefficients (s^(n-1) ... s^0).
        let mut padded = vec![0.0; n - num.len()];
        padded.extend_from_slice(num);
        let c = Mat::from_fn(1, n, |_, j| padded[j]);
        (a, b, c, Mat::from_fn(1, 1, |_, _| d))
    }

    fn margins(num: &[f64], den: &[f64], d: f64) -> LoopMargins {
        let (a, b, c, dd) = canonical(num, den, d);
        loop_margins(a.as_ref(), b.as_ref(), c.as_ref(), dd.as_ref()).unwrap()
    }

    fn close(x: f64, y: f64, tol: f64) {
        assert!((x - y).abs() <= tol * y.abs().max(1e-300), "{x} vs {y}");
    }

    #[test]
    fn phase_crossover_of_badly_scaled_states() {
        // (s - 1)^2/((s + 2)(s + 3)(s + 4)) in states scaled by 10^±6: Im L(jω) = 0 at
        // ω^4 - 45 ω^2 + 74 = 0, L(j1.3074) = -0.0823 (by hand). Missed before the balancing.
        let rows = [
            [4.0, -270000.0, -200000000.0],
            [-0.0003999999999999999, 26.000000000000004, 20000.0],
            [9.000000000000001e-07, -0.051, -39.0],
        ];
        let a = Mat::from_fn(3, 3, |i, j| rows[i][j]);
        let b = Mat::from_fn(3, 1, |i, _| [10.0, -0.001, 2e-06][i]);
        let c = Mat::from_fn(1, 3, |_, j| [-0.09999999999999999, -2000.0, 0.0][j]);
        let d = Mat::<f64>::zeros(1, 1);
        let m = loop_margins(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
        let w = ((45.0 - 1729f64.sqrt()) / 2.0).sqrt();
        let s = c64::new(0.0, w);
        let one = c64::new(1.0, 0.0);
        let l = (s - one) * (s - one) / ((s + 2.0 * one) * (s + 3.0 * one) * (s + 4.0 * one));
        let found = m
            .phase_crossovers
            .iter()
            .find(|x| (x.omega - w).abs() <= 1e-9 * w)
            .expect("the phase crossover");
        assert!((found.value - l).norm() <= 1e-9 * l.norm());
    }

    #[test]
    fn range_of_the_loop_taken_as_given() {
        // 2^256 is the limit for max|A|, max|B|, max|C| and max|B| max|C| / |1 + d|.
        let (a, b, c, d) = canonical(&[1.0], &[1.0, 3.0, 2.0, 0.0], 0.0);
        let d0 = d[(0, 0)];
        assert!(within_range(a.as_ref(), b.as_ref(), c.as_ref(), d0));
        let big = |m: &Mat<f64>, e: i32| {
            Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] * 2f64.powi(e))
        };
        assert!(within_range(
            big(&a, 254).as_ref(),
            b.as_ref(),
            c.as_ref(),
            d0
        ));
        assert!(!within_range(
            big(&a, 258).as_ref(),
            b.as_ref(),
            c.as_ref(),
            d0
        ));
        // B and C of 2^130 each: their product 2^260 is the closed loop's term; with
        // 1 + d = 2^10 it is back within range.
        let (bb, cb) = (big(&b, 130), big(&c, 130));
        assert!(!within_range(a.as_ref(), bb.as_ref(), cb.as_ref(), d0));
        assert!(within_range(a.as_ref(), bb.as_ref(), cb.as_ref(), 1023.0));
        // B of 2^300 beside C of 2^-300: the product is 1, B alone is beyond.
        assert!(!within_range(
            a.as_ref(),
            big(&b, 300).as_ref(),
            big(&c, -300).as_ref(),
            d0
        ));
        // A zero B (L = d): no closed-loop term.
        let zero = Mat::<f64>::zeros(3, 1);
        assert!(within_range(a.as_ref(), zero.as_ref(), c.as_ref(), d0));
    }

    #[test]
    fn third_order_loop() {
        // k/(s(s + 1)(s + 2)) = k/(s^3 + 3 s^2 + 2 s): phase crossover at √2, L = -k/6.
        for k in [0.5, 2.0, 5.0, 10.0, 30.0] {
            let m = margins(&[k], &[1.0, 3.0, 2.0, 0.0], 0.0);
            let negative: Vec<_> = m
                .phase_crossovers
                .iter()
                .filter(|x| x.value.re < 0.0)
                .collect();
            assert_eq!(negative.len(), 1);
            close(negative[0].omega, 2f64.sqrt(), 1e-13);
            close(1.0 / negative[0].value.norm(), 6.0 / k, 1e-13);
            // ω^2 (ω^2 + 1)(ω^2 + 4) = k^2 at the gain crossover.
            assert_eq!(m.gain_crossovers.len(), 1);
            let w2 = m.gain_crossovers[0].omega.powi(2);
            close(w2 * (w2 + 1.0) * (w2 + 4.0), k * k, 1e-12);
        }
    }

    #[test]
    fn integrator() {
        // k/s: |L| = 1 at ω = k, never real; |S - T|/2 = 1/2 everywhere (peak kept at ∞).
        for k in [0.1, 1.0, 50.0] {
            let m = margins(&[k], &[1.0, 0.0], 0.0);
            assert!(m.phase_crossovers.is_empty());
            assert_eq!(m.gain_crossovers.len(), 1);
            close(m.gain_crossovers[0].omega, k, 1e-13);
            close(m.disk.value, 0.5, 1e-12);
            assert_eq!(m.disk.omega, f64::INFINITY);
        }
    }

    #[test]
    fn unstable_first_order() {
        // 2/(s - 1): L(0) = -2 (GM 1/2 at ω = 0), |L| = 1 at √3 with ∠L = -120°.
        let m = margins(&[2.0], &[1.0, -1.0], 0.0);
        assert_eq!(m.phase_crossovers.len(), 1);
        assert_eq!(m.phase_crossovers[0].omega, 0.0);
        close(m.phase_crossovers[0].value.re, -2.0, 1e-14);
        assert_eq!(m.gain_crossovers.len(), 1);
        close(m.gain_crossovers[0].omega, 3f64.sqrt(), 1e-13);
        let phase = m.gain_crossovers[0].value.arg().to_degrees();
        close(phase, -120.0, 1e-12);
        close(m.closed_loop_poles[0].re, -1.0, 1e-14);
    }

    #[test]
    fn no_crossover() {
        // 0.5/(s + 1): |L| < 1, L real only at ω = 0 (positive); disk peak 1/2 at ∞.
        let m = margins(&[0.5], &[1.0, 1.0], 0.0);
        assert!(m.gain_crossovers.is_empty());
        assert!(m.phase_crossovers.iter().all(|x| x.value.re > 0.0));
        assert_eq!(m.disk.omega, f64::INFINITY);
        close(m.disk.value, 0.5, 1e-14);
        // min |1 + L| = 1 as ω -> ∞ (|1 + L(jω)|^2 = 1 + (1 + ω^2)^-1 (1.25 - ... ) > 1).
        close(m.sensitivity.value, 1.0, 1e-12);
    }

    #[test]
    fn lightly_damped_second_order() {
        // L = 0.5/(s^2 + 0.02 s + 1): L(jω) = 0.5/(1 - ω^2 + 0.02 jω); |L| = 1 where
        // (1 - ω^2)^2 + 0.0004 ω^2 = 0.25; L real at ω = 0 (positive) only, ∞ excluded.
        let m = margins(&[0.5], &[1.0, 0.02, 1.0], 0.0);
        assert_eq!(m.gain_crossovers.len(), 2);
        for x in &m.gain_crossovers {
            let w2 = x.omega * x.omega;
            close((1.0 - w2).powi(2) + 0.0004 * w2, 0.25, 1e-12);
        }
        assert!(m.phase_crossovers.iter().all(|x| x.value.re > 0.0));
        // The peak of |S| = |s^2 + 0.02 s + 1| / |s^2 + 0.02 s + 1.5| at ω ≈ √1.5 (a closed
        // form by dense evaluation).
        let mut best = 0.0f64;
        for i in 0..200_001 {
            let w = 1.0 + 0.5 * i as f64 / 200_000.0;
            let s = c64::new(0.0, w);
            let v = ((s * s + s * 0.02 + 1.0) / (s * s + s * 0.02 + 1.5)).norm();
            best = best.max(v);
        }
        close(m.sensitivity.value, best, 1e-8);
    }

    /// The peak of ω0^2/(s^2 + 2ζω0 s + ω0^2), 1/(2ζ √(1 - ζ^2)) at ω0 √(1 - 2ζ^2) (a closed
    /// form), by the Newton search from the poles' frequencies, for damping ratios from 1e-4
    /// to 0.6 and ω0 from 1e-3 to 1e3: the value to 1e-14 + 4u/ζ (the evaluation's error near
    /// the resonance, u times the condition 1/ζ of jωI - A), its frequency to 1e-7 (the peak
    /// is flat there: a relative error δ in ω changes the value by about (δ/ζ)^2).
    #[test]
    fn resonance_peaks_have_the_closed_form() {
        for &zeta in &[1e-4, 1e-3, 0.01, 0.05, 0.1, 0.3, 0.6] {
            for &w0 in &[1e-3, 0.37, 1.0, 25.0, 1e3] {
                let (a, b, c, _) = canonical(&[w0 * w0], &[1.0, 2.0 * zeta * w0, w0 * w0], 0.0);
                let poles = eigenvalues(a.as_ref()).unwrap();
                let bv: Vec<f64> = (0..2).map(|i| b[(i, 0)]).collect();
                let cv: Vec<f64> = (0..2).map(|j| c[(0, j)]).collect();
                let found = peak_gain(a.as_ref(), &bv, &cv, 0.0, &poles).unwrap();
                let value = 1.0 / (2.0 * zeta * (1.0 - zeta * zeta).sqrt());
                close(found.value, value, 1e-14 + 4.0 * f64::EPSILON / zeta);
                close(found.omega, w0 * (1.0 - 2.0 * zeta * zeta).sqrt(), 1e-7);
            }
        }
    }

    #[test]
    fn unit_feedthrough_uses_the_pencil() {
        // d^2 = 1: L = 1 + (1 - s)/(s^2 + 1.5 s + 1) = (s^2 + 0.5 s + 2)/(s^2 + 1.5 s + 1);
        // |num|^2 - |den|^2 = 3 - 4 ω^2 vanishes at ω = √3/2.
        let m = margins(&[-1.0, 1.0], &[1.0, 1.5, 1.0], 1.0);
        assert_eq!(m.gain_crossovers.len(), 1);
        close(m.gain_crossovers[0].omega, 0.75f64.sqrt(), 1e-13);
    }

    /// The 747 cruise yaw damper's loop (design.yaw_damper): n = 6.
    fn yaw_loop() -> (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>) {
        let rows = |r: &[&[f64]]| Mat::from_fn(r.len(), r[0].len(), |i, j| r[i][j]);
        (
            rows(&[
                &[-10.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                &[
                    0.0072901450026690105,
                    -0.055813198525633184,
                    0.0,
                    0.041568475452196385,
                    -1.0,
                    0.0,
                ],
                &[
                    0.11435968546764091,
                    -2.9925363785056502,
                    -0.4342638422254207,
                    0.0,
                    0.413658731720881,
                    0.0,
                ],
                &[0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
                &[
                    -0.4855530880759152,
                    0.8406324424627803,
                    -0.00591530768795045,
                    0.0,
                    -0.14574121621033306,
                    0.0,
                ],
                &[0.0, 0.0, 0.0, 0.0, -0.3333333333333333, -0.3333333333333333],
            ]),
            rows(&[&[10.0], &[0.0], &[0.0], &[0.0], &[0.0], &[0.0]]),
            rows(&[&[0.0, 0.0, 0.0, 0.0, -1.0, -1.0]]),
            rows(&[&[0.0]]),
        )
    }

    #[test]
    fn yaw_damper_loop_matches_python_control() {
        // python-control 0.10 stability_margins(returnall=True) on the same matrices: GM
        // 6.35517022 at 0.46389296 rad/s; PM -66.10486781° at 0.78037584, 114.65090329° at
        // 1.18732058 (printed to 9 digits). Its extra GM 1.25e13 at ω = 0 is L(0) = 8e-14, the
        // washout's zero at the origin, which is not a crossover.
        let (a, b, c, d) = yaw_loop();
        let m = loop_margins(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
        let negative: Vec<_> = m
            .phase_crossovers
            .iter()
            .filter(|x| x.value.re < 0.0)
            .collect();
        assert_eq!(negative.len(), 1);
        close(1.0 / negative[0].value.norm(), 6.35517022, 1e-8);
        close(negative[0].omega, 0.46389296, 1e-7);
        assert_eq!(m.gain_crossovers.len(), 2);
        close(m.gain_crossovers[0].omega, 0.78037584, 1e-7);
        close(m.gain_crossovers[1].omega, 1.18732058, 1e-7);
        let pm = |x: &Crossover| 180.0 + x.value.arg().to_degrees();
        close(pm(&m.gain_crossovers[0]), -66.10486781 + 360.0, 1e-9);
        close(pm(&m.gain_crossovers[1]), 114.65090329, 1e-9);
    }

    /// The yaw damper's margins from its crossovers against python-control's (as above):
    /// GM 6.35517022, PM -66.10486781° and 114.65090329°, and the delay margins
    /// ((PM mod 360°) in rad)/ω; the critical ones are the only gain margin and the phase
    /// margin of least magnitude.
    #[test]
    fn crossover_margins_of_the_yaw_damper() {
        let (a, b, c, d) = yaw_loop();
        let m = loop_margins(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
        let x = crossover_margins(&m.phase_crossovers, &m.gain_crossovers);
        assert_eq!((x.gain_margins, x.phase_margins), (1, 2));
        assert_eq!(x.values.len(), 2 + 3 * 2);
        close(x.values[0], 6.35517022, 1e-8);
        close(x.values[1], 0.46389296, 1e-7);
        close(x.values[2], -66.10486781, 1e-9);
        close(x.values[3], 114.65090329, 1e-9);
        let delays = [
            (-66.10486781 + 360.0f64).to_radians() / 0.78037584,
            114.65090329f64.to_radians() / 1.18732058,
        ];
        close(x.values[6], delays[0], 1e-7);
        close(x.values[7], delays[1], 1e-7);
        assert_eq!(x.gain_margin, (x.values[0], x.values[1]));
        assert_eq!(x.phase_margin, (x.values[2], x.values[4]));
        assert_eq!(x.delay_margin, x.values[7]);
    }

    /// Without crossovers every critical margin is infinite and its frequency NaN; a phase
    /// crossover where L >= 0 gives no gain margin, one where 1/|L| overflows an infinite
    /// one; a gain crossover at ω = 0 has no delay margin; of margins equally far from 0 dB
    /// the first is critical; L = -1 is a phase margin of 0° and L = 1 one of 180° (not
    /// -180°).
    #[test]
    fn crossover_margins_edge_cases() {
        let none = crossover_margins(&[], &[]);
        assert!(none.values.is_empty());
        assert_eq!(none.gain_margin.0, f64::INFINITY);
        assert!(none.gain_margin.1.is_nan() && none.phase_margin.1.is_nan());
        assert_eq!(none.phase_margin.0, f64::INFINITY);
        assert_eq!(none.delay_margin, f64::INFINITY);
        let at = |omega: f64, re: f64, im: f64| Crossover {
            omega,
            value: c64::new(re, im),
        };
        let phase = [at(1.0, 0.5, 0.0), at(2.0, -0.5, 0.0), at(3.0, -2.0, 0.0)];
        let gain = [at(0.0, 1.0, 0.0), at(4.0, -1.0, 0.0), at(5.0, 0.0, -1.0)];
        let x = crossover_margins(&phase, &gain);
        // Gain margins 2 and 0.5 (equally far from 0 dB: the first), at 2 and 3 rad/s.
        assert_eq!(x.values[..4], [2.0, 0.5, 2.0, 3.0]);
        assert_eq!(x.gain_margin, (2.0, 2.0));
        // L = 1: 180°; L = -1: 0°; L = -j: 90°.
        assert_eq!(x.values[4..7], [180.0, 0.0, 90.0]);
        assert_eq!(x.values[7..10], [0.0, 4.0, 5.0]);
        assert_eq!(x.phase_margin, (0.0, 4.0));
        // No delay margin at ω = 0; 0° at 4 rad/s; 90° = π/2 at 5 rad/s.
        assert_eq!(x.values[10..], [0.0, std::f64::consts::FRAC_PI_2 / 5.0]);
        assert_eq!(x.delay_margin, 0.0);
        let zero = crossover_margins(&[at(1.0, -0.0, 0.0)], &[]);
        assert!(zero.values.is_empty(), "L = -0 is not below 0");
        let vanishing = crossover_margins(&[at(1.0, -1e-320, 0.0)], &[]);
        assert_eq!(vanishing.gain_margin.0, f64::INFINITY);
    }

    /// The bound census_size takes in place of the balanced size is at least that size
    /// (Osborne's iteration lowers the Frobenius norm) on 600 seeded matrices n = 1..=8 with
    /// states scaled apart by up to 10^±8, and the census against it, where it decides, is the
    /// census against the balanced size; poles within √u of the bound from the axis (a shift
    /// that puts one there, or states so far apart that the bound is too large) take the
    /// balanced size itself.
    #[test]
    fn census_size_bounds_the_balanced_size() {
        let (mut bounded, mut balanced_taken) = (0, 0);
        for seed in 0..600u64 {
            let n = 1 + (seed % 8) as usize;
            let mut next = crate::test_matrices::xorshift(seed.wrapping_mul(0x9E37) | 1);
            let exponents: Vec<f64> = (0..n).map(|_| (8.0 * next()).round()).collect();
            let a = Mat::from_fn(n, n, |i, j| {
                next() * 10f64.powf(exponents[i] - exponents[j])
            });
            let empty = Mat::<f64>::zeros(n, 0);
            let balanced = balanced_states(a.as_ref(), empty.as_ref(), empty.transpose())
                .map_or_else(
                    || frobenius_norm(a.as_ref()),
                    |(m, _, _)| frobenius_norm(m.as_ref()),
                );
            let poles = eigenvalues(a.as_ref()).unwrap();
            let size = census_size(a.as_ref(), &poles);
            assert!(size >= balanced, "seed {seed}: {size} < {balanced}");
            let census = census_off_axis(&poles, size);
            if size == balanced {
                balanced_taken += 1;
                continue;
            }
            bounded += 1;
            assert!(census.is_some(), "seed {seed}");
            assert_eq!(census, census_off_axis(&poles, balanced), "seed {seed}");
            // A pole moved onto the axis: the balanced size, not the bound.
            let shift = poles[0].re;
            let shifted = Mat::from_fn(n, n, |i, j| a[(i, j)] - if i == j { shift } else { 0.0 });
            let moved: Vec<c64> = poles.iter().map(|p| p - shift).collect();
            let balanced_shifted =
                balanced_states(shifted.as_ref(), empty.as_ref(), empty.transpose()).map_or_else(
                    || frobenius_norm(shifted.as_ref()),
                    |(m, _, _)| frobenius_norm(m.as_ref()),
                );
            assert_eq!(census_size(shifted.as_ref(), &moved), balanced_shifted);
        }
        // Both ways are taken: the bound of states scaled far apart is too large to decide.
        assert!(
            bounded >= 100 && balanced_taken >= 100,
            "{bounded} {balanced_taken}"
        );
    }

    /// The census is taken only where every root is farther than √u size from the axis.
    #[test]
    fn census_off_axis_defers_roots_near_the_axis() {
        let roots = [
            c64::new(-1.0, 2.0),
            c64::new(-1.0, -2.0),
            c64::new(0.5, 0.0),
        ];
        assert_eq!(census_off_axis(&roots, 1.0), Some((1, false)));
        assert_eq!(census_off_axis(&roots[..2], 1.0), Some((0, true)));
        // 1e-9 from the axis beside a size of 1: within √u = 1.5e-8.
        let near = [c64::new(-1.0, 0.0), c64::new(1e-9, 1.0)];
        assert_eq!(census_off_axis(&near, 1.0), None);
        assert_eq!(census_off_axis(&near, 1e-2), Some((1, false)));
        assert_eq!(census_off_axis(&roots, f64::INFINITY), None);
        assert_eq!(census_off_axis(&[c64::new(f64::NAN, 0.0)], 1.0), None);
        assert_eq!(census_off_axis(&[], 0.0), Some((0, true)));
    }
}
