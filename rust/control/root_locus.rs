//! The root locus of a SISO loop: the closed-loop poles of 1 + k L(s) = 0 over many gains, the
//! eigenvalues of A - g b c with g = k (1 + k d)^-1 (the caller forms g).
//!
//! **Controller-Hessenberg form.** One orthogonal similarity Q, computed once, brings the loop
//! to H = Q^T A Q upper Hessenberg with Q^T b = β e_1: a Householder reflection P with
//! P b = β e_1, then the Householder reduction of P A P to Hessenberg form, whose reflections
//! act on rows and columns 2..n and leave e_1 alone. Then for every gain
//!
//! ```text
//!     Q^T (A - g b c) Q = H - g β e_1 (c Q),
//! ```
//!
//! which differs from H in its first row only and is again upper Hessenberg: each gain costs
//! the double-shift QR iteration alone, with no reduction (and no balancing), in parallel
//! over runs of gains (a single run on the calling thread where the pool has one thread).
//!
//! **Backward stability.** The reduction and the QR iteration are orthogonal and unbalanced:
//! each gain's eigenvalues are those of A - g b c + E with ||E|| = O(n u (||A|| + |g| ||b|| ||c||)),
//! the normwise backward stability that a balanced QR does not guarantee for a closed loop
//! dominated by its rank-one term (see `loops.py`'s `_backward_stable_eigenvalues`).
//! **Verification.** Each gain's eigenvalues must sum to the trace of its Hessenberg matrix M
//! to within 8 n^2 u ||M||_F (the trace of a backward error E of O(n u ||M||) is at most
//! n ||E||); a miss is [`Error::IllConditioned`].
//! The gain 0 (the open loop) is taken by [`eigenvalues`] itself, which returns the diagonal of
//! a triangular A exactly (a repeated pole would otherwise split by sqrt(u) ||A||).
//!
//! **Continuation.** Along a run of gains, each gain's poles are found from the previous
//! gains' (extrapolated by the parabola through the last three, or the secant through the last
//! two where the parabola departs from the secant by more than the secant's step) by Aberth's
//! simultaneous iteration on the closed-loop characteristic polynomial in factored form,
//!
//! ```text
//!     χ_g(s) = det(sI - A + g b c) = Π(s - p_i) + g K Π(s - z_j) = D(s) (1 + R(s)),
//!     R(s) = g K Π(s - z_j) / Π(s - p_i),   χ'/χ = (S_p + R S_z) / (1 + R),
//! ```
//!
//! with the open-loop poles p_i, the zeros z_j and the gain K of c (sI - A)^-1 b from
//! [`transfer::transfer_channels`], and S_p = Σ 1/(s - p_i), S_z = Σ 1/(s - z_j). Each
//! approximation x_i moves by 1 / (χ'/χ(x_i) - Σ_{j≠i} 1/(x_i - x_j)) (Aberth 1973, eq. 2),
//! formed as Q / (P - Q Σ_{j≠i} 1/(x_i - x_j)) with χ'/χ = P / Q = (D S_p + G N S_z) / (D + G N)
//! (one complex division; by R where D or G N leaves the normal range), and stops once |1 + R(x_i)| <= η max(1, |R(x_i)|), η = 32 (n + m + 1) u (tested as
//! |D + G N| <= η max(|D|, |G N|) with D = Π(x_i - p_i) and G N = g K Π(x_i - z_j), in squares
//! without a division where they are in range): x_i is then a root of
//! the factored χ_g with its factors perturbed by O(η); or once the disk about x_i of radius
//! deg χ |χ(x_i) / χ'(x_i)|, which holds a root of χ_g, is within 8 ulps of x_i (a pole next to
//! a zero, where the rounding of x_i itself keeps the residual above η). The iteration keeps the real
//! structure: a real pole is iterated on the real axis, a complex pair as its upper member
//! (its conjugate counted in the sums). Every run starts at a gain solved by the QR
//! iteration, and a gain whose continuation does not converge in [`ABERTH_ITERATIONS`]
//! sweeps (a breakaway point, where a real pair becomes complex, or a step too long) is solved
//! by the QR iteration, which restarts the run. The QR iteration's poles are themselves
//! polished by the continuation at their gain (their error is relative to g ||b|| ||c||, which
//! dominates A at high gain: 1/(s + 1)^4 at g = 9.3e7 lost 3.4e-5 of its poles' size), and kept
//! where that fails. Each continued gain is verified against the
//! state space: its poles must sum to tr(A - g b c) = tr A - g c b to within 8 n^2 u ||M||_F, and
//! their squares to tr((A - g b c)^2) = tr A^2 - 2 g c A b + g^2 (c b)^2 to within
//! 16 n^2 u ||M||_F^2 (M = A - g b c); a miss falls back to the QR iteration, as does a point
//! where R is 0 or leaves the doubles. A zero within 8 n u ||A||_F of a pole (the accuracy of
//! the poles themselves) cancels it: that pole is a closed-loop pole at every gain, taken out
//! of both products. Loops whose transfer function the fast path defers, or whose poles or
//! zeros are not exactly closed under conjugation, use the QR iteration at every gain.
//!
//! Reference: G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013, §7.4-7.5
//! (the Hessenberg reduction and the Francis double-shift iteration); the controller-Hessenberg
//! form of a single-input system is that of §7.4.8's staircase with one input. O. Aberth,
//! "Iteration methods for finding all zeros of a polynomial simultaneously", Mathematics of
//! Computation 27(122), 339-344, 1973; D. A. Bini, "Numerical computation of polynomial zeros
//! by means of Aberth's method", Numerical Algorithms 13, 179-200, 1996 (the stopping rule).

use crate::control::margins::RESCALE_EXPONENT;
use crate::control::transfer::transfer_channels;
use crate::error::{Error, check_finite, check_finite_values, check_output_len, check_square};
use crate::linalg::balance::{GRADED_SPREAD, balanced_loop, range_scale};
use crate::linalg::hessenberg::reduce_to_hessenberg;
use crate::linalg::householder::reflector;
use crate::linalg::matrix::{
    FaerView, Order, Square, Transformations, from_faer_in, identity_in, with_order,
};
use crate::linalg::norm::max_abs;
use crate::linalg::schur::{Spectrum, eigenvalues, francis_qr, quasi_triangular_eigenvalues};
use crate::platform::dispatch::fma_dispatch;
use crate::platform::parallel::ParallelContext;
use faer::{MatRef, c64};
use rayon::prelude::*;

/// H, β and the row c Q: the closed loop at gain g is H - g β e_1 (c Q).
struct ControllerHessenberg<O: Order> {
    h: Square<O>,
    beta: f64,
    row: Vec<f64>,
}

fn controller_hessenberg<O: Order>(
    order: O,
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
) -> ControllerHessenberg<O> {
    let n = b.len();
    let mut h = from_faer_in(order, a);
    let mut w = b.to_vec();
    let (beta, tau) = reflector(&mut w);
    w[0] = 1.0;
    let mut c_reflected = c.to_vec();
    if tau != 0.0 {
        h.reflect_rows(0, &w, tau, 0..n);
        h.reflect_columns(0, &w, tau, 0..n);
        let dot: f64 = c.iter().zip(&w).map(|(x, v)| x * v).sum();
        for (x, v) in c_reflected.iter_mut().zip(&w) {
            *x -= tau * dot * v;
        }
    }
    let mut q = identity_in(order);
    reduce_to_hessenberg(&mut h, Some(&mut q));
    let row = (0..n)
        .map(|j| (0..n).map(|i| c_reflected[i] * q[(i, j)]).sum::<f64>())
        .collect();
    ControllerHessenberg { h, beta, row }
}

/// The eigenvalues of H - g e_1 r (upper Hessenberg), scaled into range.
fn closed_loop_eigenvalues<O: Order>(
    form: &ControllerHessenberg<O>,
    g: f64,
) -> Result<Vec<c64>, Error> {
    let n = form.row.len();
    let mut m = form.h.clone();
    // g β c Q is in range (the caller's scaling) where g β or β c Q alone may not be: the
    // product is formed in the order that does not overflow.
    let g_beta = g * form.beta;
    for (j, r) in form.row.iter().enumerate() {
        m[(0, j)] -= if g_beta.is_finite() {
            g_beta * r
        } else {
            g * (form.beta * r)
        };
    }
    let scale = range_scale(m.as_faer());
    if scale != 1.0 {
        m.as_mut_slice().iter_mut().for_each(|x| *x /= scale);
    }
    let trace: f64 = (0..n).map(|i| m[(i, i)]).sum();
    let size = m.as_slice().iter().map(|x| x * x).sum::<f64>().sqrt();
    francis_qr(&mut m, None, (0, n - 1), false, Spectrum::General)?;
    let values = quasi_triangular_eigenvalues(m.as_faer());
    let sum: f64 = values.iter().map(|v| v.re).sum();
    if !sum.is_finite() || (sum - trace).abs() > 8.0 * (n * n) as f64 * f64::EPSILON * size {
        return Err(Error::IllConditioned {
            message: format!(
                "root_locus: the closed-loop poles at the gain {g:.6e} do not sum to the \
                 trace of the closed loop ({sum:.6e} against {trace:.6e})"
            ),
        });
    }
    Ok(values.into_iter().map(|v| v * scale).collect())
}

/// The eigenvalues of A - g b c (A n x n, b and c of length n) by the controller-Hessenberg
/// form (see the module's documentation), normwise backward stable, and, where their moduli
/// span more than [`GRADED_SPREAD`] (so that the small ones, accurate to u ||A - g b c|| only,
/// may have lost all their digits: L = 1/(s + 2^60) + 1/(s + 1) closed to -2^60 and +64 for
/// -2), polished as [`root_locus`] polishes the QR iteration's poles at the start of a run
/// ([`polished`]: Aberth's iteration on the factored characteristic polynomial, verified by
/// the traces of the closed loop and its square; kept as they are where that fails).
pub fn closed_loop_poles(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    g: f64,
) -> Result<Vec<c64>, Error> {
    let mut poles = closed_loop_poles_at(a, b, c, &[g])?;
    Ok(poles.pop().unwrap_or_default())
}

/// [`closed_loop_poles`] at each of the `gains`, from one controller-Hessenberg form (and one
/// factored form where a spectrum needs polishing): each the same, bit for bit, as
/// [`closed_loop_poles`] at that gain alone.
pub fn closed_loop_poles_at(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    gains: &[f64],
) -> Result<Vec<Vec<c64>>, Error> {
    let n = a.nrows();
    if n == 0 {
        return gains.iter().map(|_| eigenvalues(a)).collect();
    }
    let spectra = with_order!(n, order => {
        let form = controller_hessenberg(order, a, b, c);
        gains
            .iter()
            .map(|&g| {
                if g == 0.0 {
                    eigenvalues(a)
                } else {
                    closed_loop_eigenvalues(&form, g)
                }
            })
            .collect::<Result<Vec<_>, Error>>()
    })?;
    let mut factored = None;
    let mut out = Vec::with_capacity(gains.len());
    for (values, &g) in spectra.into_iter().zip(gains) {
        let moduli = values.iter().map(|v| v.norm()).filter(|&m| m > 0.0);
        let (smallest, largest) =
            moduli.fold((f64::INFINITY, 0.0f64), |(s, l), m| (s.min(m), l.max(m)));
        if g == 0.0 || largest <= GRADED_SPREAD * smallest {
            out.push(values);
            continue;
        }
        if factored.is_none() {
            factored = Some(factored_loop(a, b, c)?);
        }
        let mut poles = values.clone();
        polished(
            factored.as_ref().and_then(Option::as_ref),
            g,
            &values,
            &mut poles,
        );
        out.push(poles);
    }
    Ok(out)
}

/// [`Factored::of`] the loop, None where it fails (its eigenvalues, say: that only forgoes
/// the polishing and the continuation), an interruption passed on.
fn factored_loop(a: MatRef<'_, f64>, b: &[f64], c: &[f64]) -> Result<Option<Factored>, Error> {
    match Factored::of(a, b, c) {
        Ok(factored) => Ok(factored),
        Err(Error::Interrupted) => Err(Error::Interrupted),
        Err(_) => Ok(None),
    }
}

/// The QR iteration's poles `values` at the gain g polished by Aberth's iteration at the same
/// gain (their errors are relative to g ||b|| ||c||, which dominates at high gain, and to
/// ||A||, which hides a small pole), into `out`, each as it is where that fails (no factored
/// form, no convergence, or the traces' check missed); returns the continuation that starts a
/// run there.
fn polished(factored: Option<&Factored>, g: f64, values: &[c64], out: &mut [c64]) -> Continuation {
    let mut continuation = match factored {
        Some(f) => Continuation::restart(g, values, &f.fixed),
        None => Continuation::default(),
    };
    if !factored.is_some_and(|f| continuation.next(f, g, out)) {
        out.copy_from_slice(values);
    }
    continuation
}

/// Sorted by real part, then imaginary part (as `numpy.sort_complex`).
fn sorted(mut values: Vec<c64>) -> Vec<c64> {
    sort(&mut values);
    values
}

/// Sorts by real part, then imaginary part (as `numpy.sort_complex`).
pub(crate) fn sort(values: &mut [c64]) {
    values.sort_unstable_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
}

/// `values` sorted as [`sort`] sorts them, into `out`: an insertion sort of the permutation
/// `order` by the values (kept from the call before, where the values keep their order from gain
/// to gain, it costs one comparison a value), then `out` gathered through it.
fn sort_into(values: &[c64], order: &mut Vec<usize>, out: &mut [c64]) {
    if order.len() != values.len() {
        order.clear();
        order.extend(0..values.len());
    }
    // Distinct real parts decide by `<` (as `total_cmp` does for numbers); equal ones (a pair,
    // or -0 beside +0) and NaNs by `total_cmp` of both parts.
    let before = |x: c64, y: c64| {
        if x.re < y.re {
            true
        } else if x.re > y.re {
            false
        } else {
            x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)).is_lt()
        }
    };
    for k in 1..order.len() {
        let item = order[k];
        let mut j = k;
        while j > 0 && before(values[item], values[order[j - 1]]) {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = item;
    }
    for (slot, &k) in out.iter_mut().zip(order.iter()) {
        *slot = values[k];
    }
}

/// InvalidArgument unless A is n x n, b n x 1 and c 1 x n.
fn check_loop(a: MatRef<'_, f64>, b: MatRef<'_, f64>, c: MatRef<'_, f64>) -> Result<(), Error> {
    check_square(a, "A")?;
    let n = a.nrows();
    if b.nrows() != n || b.ncols() != 1 || c.nrows() != 1 || c.ncols() != n {
        return Err(Error::InvalidArgument {
            arg: "loop",
            message: format!(
                "loop must have one input and one output, B {n} x 1 and C 1 x {n}, got B {} x {} \
                 and C {} x {}",
                b.nrows(),
                b.ncols(),
                c.nrows(),
                c.ncols()
            ),
        });
    }
    Ok(())
}

/// The closed-loop poles of the SISO loop (A n x n, b n x 1, c 1 x n) at each closed-loop gain
/// g of `gains` (the eigenvalues of A - g b c), written into `out` (n per gain, sorted by real
/// part, then imaginary part, as `numpy.sort_complex`), in parallel over runs of gains (one
/// run on the calling thread where rayon's pool has one thread). See the module's
/// documentation.
pub fn root_locus(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    gains: &[f64],
    out: &mut [c64],
) -> Result<(), Error> {
    check_loop(a, b, c)?;
    check_finite(a, "A")?;
    let n = a.nrows();
    check_finite(b, "B")?;
    check_finite(c, "C")?;
    check_finite_values(gains, "gains")?;
    check_output_len(out.len(), gains.len() * n)?;
    if n == 0 || gains.is_empty() {
        return Ok(());
    }
    let bv: Vec<f64> = (0..n).map(|i| b[(i, 0)]).collect();
    let cv: Vec<f64> = (0..n).map(|j| c[(0, j)]).collect();
    let open_loop = if gains.contains(&0.0) {
        sorted(eigenvalues(a)?)
    } else {
        Vec::new()
    };
    let factored = factored_loop(a, &bv, &cv)?;
    // Runs of consecutive gains, a few per thread, each starting with the QR iteration; on one
    // thread a single run, on the calling thread.
    let threads = rayon::current_num_threads();
    let runs = if threads > 1 { threads * 4 } else { 1 };
    let run_length = gains.len().div_ceil(runs).max(MIN_RUN);
    let context = ParallelContext::capture(0);
    with_order!(n, order => {
        let form = controller_hessenberg(order, a, &bv, &cv);
        let solve = |(run, (poles, run_gains)): (usize, (&mut [c64], &[f64]))| {
            context.run(|| {
                let mut continuation = Continuation::default();
                for (k, (poles, &g)) in poles.chunks_mut(n).zip(run_gains).enumerate() {
                    crate::platform::interrupt::check()?;
                    if g == 0.0 {
                        poles.copy_from_slice(&open_loop);
                        continuation = Continuation::default();
                        continue;
                    }
                    if factored.as_ref().is_some_and(|f| continuation.next(f, g, poles)) {
                        continue;
                    }
                    let values = closed_loop_eigenvalues(&form, g)
                        .map_err(|e| Error::in_batch(run * run_length + k, e))?;
                    // The QR iteration's poles start a run, polished.
                    continuation = polished(factored.as_ref(), g, &values, poles);
                    sort(poles);
                }
                Ok(())
            })
        };
        if threads > 1 {
            out.par_chunks_mut(run_length * n)
                .zip(gains.par_chunks(run_length))
                .enumerate()
                .try_for_each(solve)
        } else {
            out.chunks_mut(run_length * n)
                .zip(gains.chunks(run_length))
                .enumerate()
                .try_for_each(solve)
        }
    })
}

/// The closed-loop gain g = k (1 + k d)^-1 of the loop gain k, formed as 1 / (1/k + d) where
/// k d overflows (as `loops._closed_loop_gains`).
pub fn closed_loop_gain(k: f64, d: f64) -> f64 {
    let denominator = 1.0 + k * d;
    if denominator.is_finite() {
        k / denominator
    } else {
        1.0 / (1.0 / k + d)
    }
}

/// log2 of the largest |entry| of M; -inf for a zero or empty M (as `loops._log2_size`).
fn log2_size(m: MatRef<'_, f64>) -> f64 {
    let largest = max_abs(m);
    if largest > 0.0 {
        largest.log2()
    } else {
        f64::NEG_INFINITY
    }
}

/// The root locus of the open loop L = (A, b, c, d) (A n x n, b n x 1, c 1 x n) at the loop
/// gains `gains` (1 + k L = 0), as `aerocontrol.root_locus` takes it in one call: the states
/// balanced for the closed loops ([`balanced_loop`]), each closed-loop gain
/// g = k (1 + k d)^-1 ([`closed_loop_gain`]), then [`root_locus`] of the balanced loop at the
/// gains g, into `out`. Returns false, with `out` untouched, where a term of a closed loop may
/// exceed 2^[`RESCALE_EXPONENT`]: max(log2 max|A|, log2 max|g| + log2 max|b| + log2 max|c|,
/// log2 max|b| + log2 max|c|) above it, a g not finite, or b c = 0 (the caller scales those
/// closed loops by powers of two first).
pub fn loop_root_locus(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: f64,
    gains: &[f64],
    out: &mut [c64],
) -> Result<bool, Error> {
    check_loop(a, b, c)?;
    check_finite_values(gains, "gains")?;
    let (a, b, c) = balanced_loop(a, b, c);
    let closed: Vec<f64> = gains.iter().map(|&k| closed_loop_gain(k, d)).collect();
    let (size_a, size_b, size_c) = (
        log2_size(a.as_ref()),
        log2_size(b.as_ref()),
        log2_size(c.as_ref()),
    );
    if !(closed.iter().all(|g| g.is_finite()) && (size_b + size_c).is_finite()) {
        return Ok(false);
    }
    let largest = closed.iter().fold(0.0f64, |m, g| m.max(g.abs()));
    let size = if largest > 0.0 {
        largest.log2()
    } else {
        f64::NEG_INFINITY
    };
    if size_a.max(size + size_b + size_c).max(size_b + size_c) > RESCALE_EXPONENT {
        return Ok(false);
    }
    root_locus(a.as_ref(), b.as_ref(), c.as_ref(), &closed, out)?;
    Ok(true)
}

/// Gains per run of the continuation, at least (each run starts with a QR iteration).
const MIN_RUN: usize = 16;

/// A pole is converged where the inclusion disk of its Newton step (radius deg χ |χ / χ'|) is
/// within this many units in the last place of it.
const INCLUSION_ULPS: f64 = 8.0;

/// Sweeps of Aberth's iteration before a gain falls back to the QR iteration.
const ABERTH_ITERATIONS: usize = 12;

/// A set of roots closed under conjugation: the real ones, and the upper member (Im > 0) of
/// each complex pair.
#[derive(Debug, Default, PartialEq)]
struct Conjugates {
    real: Vec<f64>,
    upper: Vec<c64>,
}

impl Clone for Conjugates {
    fn clone(&self) -> Self {
        Self {
            real: self.real.clone(),
            upper: self.upper.clone(),
        }
    }

    /// Into the buffers already held (the continuation copies the last gain's roots into its
    /// work buffers at every gain; derived, this would allocate both anew).
    fn clone_from(&mut self, source: &Self) {
        self.real.clone_from(&source.real);
        self.upper.clone_from(&source.upper);
    }
}

impl Conjugates {
    /// None unless every complex value has its exact conjugate among `values`.
    fn of(values: &[c64]) -> Option<Self> {
        let real = values
            .iter()
            .filter(|x| x.im == 0.0)
            .map(|x| x.re)
            .collect();
        let mut upper: Vec<c64> = values.iter().filter(|x| x.im > 0.0).copied().collect();
        let mut lower: Vec<c64> = values
            .iter()
            .filter(|x| x.im < 0.0)
            .map(|x| x.conj())
            .collect();
        let order = |x: &c64, y: &c64| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im));
        upper.sort_by(order);
        lower.sort_by(order);
        (upper == lower).then_some(Self { real, upper })
    }

    /// Σ 1/(x_i - v) over every root v but x_i itself (its conjugate included), x_i the i-th
    /// real root or, from i = real.len(), the upper member of the (i - real.len())-th pair.
    #[inline(always)]
    fn repulsion(&self, i: usize) -> c64 {
        let reals = self.real.len();
        if i < reals {
            let x = self.real[i];
            let mut sum = 0.0;
            for (j, v) in self.real.iter().enumerate() {
                if j != i {
                    sum += 1.0 / (x - v);
                }
            }
            for v in &self.upper {
                let d = x - v.re;
                sum += 2.0 * d / (d * d + v.im * v.im);
            }
            return c64::new(sum, 0.0);
        }
        let x = self.upper[i - reals];
        let mut sum = c64::new(0.0, 1.0) * (-0.5 / x.im); // 1/(x - x̄) = 1/(2i Im x)
        for v in &self.real {
            sum += reciprocal(c64::new(x.re - v, x.im));
        }
        for (j, v) in self.upper.iter().enumerate() {
            if j + reals != i {
                sum += pair_reciprocals(x - v, x - v.conj());
            }
        }
        sum
    }

    fn len(&self) -> usize {
        self.real.len() + 2 * self.upper.len()
    }

    /// Π (x - v) over the roots v (for a real x, in real arithmetic).
    #[inline(always)]
    fn product(&self, x: c64) -> c64 {
        if x.im == 0.0 {
            let x = x.re;
            let mut product = 1.0;
            for v in &self.real {
                product *= x - v;
            }
            for v in &self.upper {
                // (x - v)(x - v̄) = (x - Re v)^2 + (Im v)^2.
                let d = x - v.re;
                product *= d * d + v.im * v.im;
            }
            return c64::new(product, 0.0);
        }
        let mut product = c64::new(1.0, 0.0);
        for v in &self.real {
            product *= c64::new(x.re - v, x.im);
        }
        for v in &self.upper {
            // Not (x - Re v)^2 + (Im v)^2: it cancels where x is near v.
            product *= (x - v) * (x - v.conj());
        }
        product
    }

    /// Σ 1/(x - v) over the roots v (for a real x, in real arithmetic).
    #[inline(always)]
    fn sum(&self, x: c64) -> c64 {
        if x.im == 0.0 {
            let x = x.re;
            let mut sum = 0.0;
            for v in &self.real {
                sum += 1.0 / (x - v);
            }
            for v in &self.upper {
                // The pair's reciprocals sum to 2 (x - Re v) / ((x - Re v)^2 + (Im v)^2).
                let d = x - v.re;
                sum += 2.0 * d / (d * d + v.im * v.im);
            }
            return c64::new(sum, 0.0);
        }
        let mut sum = c64::new(0.0, 0.0);
        for v in &self.real {
            sum += reciprocal(c64::new(x.re - v, x.im));
        }
        for v in &self.upper {
            sum += pair_reciprocals(x - v, x - v.conj());
        }
        sum
    }

    /// [`Conjugates::product`] and [`Conjugates::sum`] at x in one pass over the roots, each
    /// by the same operations in the same order (so bit for bit the same), the differences
    /// x - v and a pair's product (x - v)(x - v̄) formed once for both.
    #[inline(always)]
    fn product_and_sum(&self, x: c64) -> (c64, c64) {
        if x.im == 0.0 {
            let x = x.re;
            let (mut product, mut sum) = (1.0, 0.0);
            for v in &self.real {
                let d = x - v;
                product *= d;
                sum += 1.0 / d;
            }
            for v in &self.upper {
                let d = x - v.re;
                let pair = d * d + v.im * v.im;
                product *= pair;
                sum += 2.0 * d / pair;
            }
            return (c64::new(product, 0.0), c64::new(sum, 0.0));
        }
        let (mut product, mut sum) = (c64::new(1.0, 0.0), c64::new(0.0, 0.0));
        for v in &self.real {
            let d = c64::new(x.re - v, x.im);
            product *= d;
            sum += reciprocal(d);
        }
        for v in &self.upper {
            let (d, e) = (x - v, x - v.conj());
            let pair = d * e;
            product *= pair;
            sum += pair_reciprocals_of_product(d, e, pair);
        }
        (product, sum)
    }
}

/// The loop in the factored form of the continuation (see the module's documentation), and
/// the state-space invariants that verify each gain's poles.
struct Factored {
    /// The open-loop poles and the zeros, common factors taken out.
    poles: Conjugates,
    zeros: Conjugates,
    /// K of c (sI - A)^-1 b = K Π(s - z_j) / Π(s - p_i).
    gain: f64,
    /// The common factors: poles of the closed loop at every gain.
    fixed: Vec<c64>,
    /// tr A, tr A^2, c b, c A b, ||A||_F^2, b^T A c^T and ||b||^2 ||c||^2.
    trace: f64,
    trace_square: f64,
    cb: f64,
    cab: f64,
    size_a: f64,
    bac: f64,
    size_bc: f64,
}

impl Factored {
    /// None where the transfer function's fast path defers the loop, or where its poles or
    /// zeros are not exactly closed under conjugation.
    fn of(a: MatRef<'_, f64>, b: &[f64], c: &[f64]) -> Result<Option<Self>, Error> {
        let n = b.len();
        let d = [0.0];
        let transfer = transfer_channels(
            a,
            MatRef::from_column_major_slice(b, n, 1),
            MatRef::from_row_major_slice(c, 1, n),
            MatRef::from_column_major_slice(&d, 1, 1),
            0.0,
            &[(0, 0)],
        )?;
        let Some(Some(channel)) = transfer.channels.into_iter().next() else {
            return Ok(None);
        };
        // A zero within 8 n u ||A||_F of a pole (the accuracy of the poles themselves) cancels
        // it: the closed loop keeps the pole at every gain.
        let size = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| a[(i, j)] * a[(i, j)])
            .sum::<f64>()
            .sqrt();
        let tolerance = 8.0 * n as f64 * f64::EPSILON * size;
        let mut poles = transfer.poles;
        let mut zeros = Vec::with_capacity(channel.zeros.len());
        let mut fixed = Vec::new();
        for z in channel.zeros {
            let nearest = (0..poles.len())
                .min_by(|&i, &j| (poles[i] - z).norm().total_cmp(&(poles[j] - z).norm()));
            match nearest.filter(|&i| {
                (poles[i] - z).norm() <= tolerance && (poles[i].im == 0.0) == (z.im == 0.0)
            }) {
                Some(i) => fixed.push(poles.remove(i)),
                None => zeros.push(z),
            }
        }
        let (Some(poles), Some(zeros)) = (Conjugates::of(&poles), Conjugates::of(&zeros)) else {
            return Ok(None);
        };
        let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(u, v)| u * v).sum::<f64>();
        let times = |v: &[f64]| -> Vec<f64> {
            (0..n)
                .map(|i| (0..n).map(|j| a[(i, j)] * v[j]).sum())
                .collect()
        };
        let entries = || (0..n).flat_map(|j| (0..n).map(move |i| (i, j)));
        Ok(Some(Self {
            poles,
            zeros,
            gain: channel.gain,
            fixed,
            trace: (0..n).map(|i| a[(i, i)]).sum(),
            trace_square: entries().map(|(i, j)| a[(i, j)] * a[(j, i)]).sum(),
            cb: dot(c, b),
            cab: dot(c, &times(b)),
            size_a: entries().map(|(i, j)| a[(i, j)] * a[(i, j)]).sum(),
            bac: dot(b, &times(c)),
            size_bc: dot(b, b) * dot(c, c),
        }))
    }

    /// Whether x is a root of the factored χ_g ([`is_root`]), and where it is not D and G N
    /// (G = g K, N = Π(x - z_j), D = Π(x - p_i)), or R(x) = G N / D where they leave the
    /// normal range. Where |D|^2 and |G N|^2 are in the normal range the test is
    /// |D + G N| <= η max(|D|, |G N|) (that of [`is_root`] times |D|), squared, without a
    /// division; a failure where R is not finite or is 0 (x on a pole or a zero, or a product
    /// beyond the doubles).
    #[inline(always)]
    fn residual(&self, x: c64, g: f64, eta: f64) -> Residual {
        residual_of(
            self.poles.product(x),
            self.zeros.product(x) * (g * self.gain),
            eta,
        )
    }

    /// [`Factored::residual`] and the sums S_p and S_z at x, in one pass over the poles and
    /// one over the zeros ([`Conjugates::product_and_sum`]): for the first sweep at a gain,
    /// where a predicted point is rarely a root already and both are needed.
    #[inline(always)]
    fn residual_and_sums(&self, x: c64, g: f64, eta: f64) -> (Residual, c64, c64) {
        let (d, s_p) = self.poles.product_and_sum(x);
        let (n, s_z) = self.zeros.product_and_sum(x);
        (residual_of(d, n * (g * self.gain), eta), s_p, s_z)
    }

    /// Whether `roots` (every closed-loop pole at g) pass the trace and trace-of-square checks
    /// (see the module's documentation).
    fn verified(&self, roots: &[c64], g: f64) -> bool {
        let n = roots.len() as f64;
        let size = (self.size_a - 2.0 * g * self.bac + g * g * self.size_bc).max(0.0);
        let sum: f64 = roots.iter().map(|x| x.re).sum();
        let square: f64 = roots.iter().map(|x| (x * x).re).sum();
        let trace = self.trace - g * self.cb;
        let trace_square = self.trace_square - 2.0 * g * self.cab + g * g * self.cb * self.cb;
        let u = f64::EPSILON;
        (sum - trace).abs() <= 8.0 * n * n * u * size.sqrt()
            && (square - trace_square).abs() <= 16.0 * n * n * u * size
    }
}

/// The test of [`Factored::residual`] on D = Π(x - p_i) and G N = g K Π(x - z_j).
#[inline(always)]
fn residual_of(d: c64, n: c64, eta: f64) -> Residual {
    let square = |z: c64| z.re * z.re + z.im * z.im;
    let (d2, n2) = (square(d), square(n));
    let range = 1e-290..=1e290;
    if range.contains(&d2) && range.contains(&n2) {
        if square(d + n) <= eta * eta * d2.max(n2) {
            return Residual::Root;
        }
        return Residual::Off(d, n);
    }
    let r = n * reciprocal(d);
    if !(r.re.is_finite() && r.im.is_finite() && r != c64::new(0.0, 0.0)) {
        Residual::Failed
    } else if is_root(r, eta) {
        Residual::Root
    } else {
        Residual::OffRatio(r)
    }
}

/// χ'/χ = (S_p + R S_z) / (1 + R) from S_p, S_z and R, formed as (S_p / R + S_z) / (1 / R + 1)
/// where |R| > 1; not finite where 1 + R = 0 exactly.
#[inline(always)]
fn logarithmic_derivative_of(s_p: c64, s_z: c64, r: c64) -> c64 {
    if r.re * r.re + r.im * r.im <= 1.0 {
        (s_p + r * s_z) * reciprocal(r + 1.0)
    } else {
        let inverse = reciprocal(r);
        (s_p * inverse + s_z) * reciprocal(inverse + 1.0)
    }
}

/// [`Factored::residual`] at a point.
enum Residual {
    /// A root of the factored χ_g.
    Root,
    /// Not a root: D and G N at the point, both in the normal range.
    Off(c64, c64),
    /// Not a root, D or G N beyond the normal range: R = G N / D at the point.
    OffRatio(c64),
    /// R is not finite or is 0.
    Failed,
}

/// Whether |1 + R| <= η max(1, |R|) (squared, without a root or a division): a point where
/// R(x) = r is then a root of the factored χ_g with its factors perturbed by O(η) (relative).
#[inline(always)]
fn is_root(r: c64, eta: f64) -> bool {
    if r.re.abs().max(r.im.abs()) > 1e150 {
        return false; // |1 + R| is |R| to rounding: far from a root, and the squares overflow
    }
    let one_plus = (r.re + 1.0) * (r.re + 1.0) + r.im * r.im;
    one_plus <= eta * eta * (r.re * r.re + r.im * r.im).max(1.0)
}

/// What Aberth's iteration does with an approximation x_i that is not a root by the residual.
enum Correction {
    /// Converged: the inclusion disk about x_i is within [`INCLUSION_ULPS`] of it.
    Included,
    /// Moves by -step: step = 1 / (χ'/χ(x_i) - Σ_{j≠i} 1/(x_i - x_j)).
    Step(c64),
}

/// The [`Correction`] of x from D and G N (in the normal range, not a root) and the sums S_p and
/// S_z at x, `repulsion` giving Σ_{j≠i} 1/(x - x_j): χ'/χ = (D S_p + G N S_z) / (D + G N)
/// (the common factors of χ and χ' cancel) kept as its numerator P and denominator Q, so that
/// the inclusion test is deg χ |Q| <= ε |x| |P| (in squares) and the step is
/// Q / (P - Q Σ_{j≠i} 1/(x - x_j)), one complex division where the quotient R = G N / D, then
/// χ'/χ, then the step took three; by the quotient R ([`correction_of_ratio`]) where P, Q or x
/// squared leave [1e-100, 1e100].
#[inline(always)]
fn correction(
    d: c64,
    n: c64,
    s_p: c64,
    s_z: c64,
    degree: f64,
    x: c64,
    repulsion: impl FnOnce() -> c64,
) -> Correction {
    let numerator = d * s_p + n * s_z;
    let denominator = d + n;
    let square = |z: c64| z.re * z.re + z.im * z.im;
    let (p2, q2, x2) = (square(numerator), square(denominator), square(x));
    let range = 1e-100..=1e100;
    if range.contains(&p2) && range.contains(&q2) && range.contains(&x2) {
        let units = INCLUSION_ULPS * f64::EPSILON;
        if degree * degree * q2 <= units * units * x2 * p2 {
            return Correction::Included;
        }
        return Correction::Step(denominator * reciprocal(numerator - repulsion() * denominator));
    }
    let r = n * reciprocal(d);
    correction_of_ratio(logarithmic_derivative_of(s_p, s_z, r), degree, x, repulsion)
}

/// The [`Correction`] of x from `ratio` = χ'/χ(x): [`included`], or the step
/// 1 / (χ'/χ - Σ_{j≠i} 1/(x - x_j)).
#[inline(always)]
fn correction_of_ratio(
    ratio: c64,
    degree: f64,
    x: c64,
    repulsion: impl FnOnce() -> c64,
) -> Correction {
    if included(degree, ratio, x) {
        Correction::Included
    } else {
        Correction::Step(reciprocal(ratio - repulsion()))
    }
}

/// Whether deg χ / |χ'/χ| (the radius of a disk about x that holds a root of χ) is within
/// [`INCLUSION_ULPS`] units in the last place of |x|; compared in squares, without a root or a
/// division, where they stay in the normal range.
#[inline(always)]
fn included(degree: f64, ratio: c64, x: c64) -> bool {
    let square = |z: c64| z.re * z.re + z.im * z.im;
    let (r2, x2) = (square(ratio), square(x));
    let units = INCLUSION_ULPS * f64::EPSILON;
    if (1e-100..=1e100).contains(&r2) && (1e-100..=1e100).contains(&x2) {
        return degree * degree <= units * units * x2 * r2;
    }
    degree * modulus(reciprocal(ratio)) <= units * modulus(x)
}

/// |z|, by a square root where |z|^2 stays in the normal range.
#[inline(always)]
fn modulus(z: c64) -> f64 {
    let norm = z.re * z.re + z.im * z.im;
    if (1e-290..=1e290).contains(&norm) {
        norm.sqrt()
    } else {
        z.re.hypot(z.im)
    }
}

/// 1/z by one real division, its parts scaled first only where |z|^2 would leave the normal
/// range.
#[inline(always)]
fn reciprocal(z: c64) -> c64 {
    let norm = z.re * z.re + z.im * z.im;
    if (1e-290..=1e290).contains(&norm) {
        let inverse = 1.0 / norm;
        return c64::new(z.re * inverse, -z.im * inverse);
    }
    let scale = z.re.abs().max(z.im.abs());
    let (re, im) = (z.re / scale, z.im / scale);
    let denominator = scale * (re * re + im * im);
    c64::new(re / denominator, -im / denominator)
}

/// 1/d + 1/e as (d + e) / (d e), by one real division (|1/d + 1/e| <= 1/|d| + 1/|e|: no
/// less accurate than the two reciprocals, which it takes where |d e|^2 would leave the normal
/// range).
#[inline(always)]
fn pair_reciprocals(d: c64, e: c64) -> c64 {
    pair_reciprocals_of_product(d, e, d * e)
}

/// [`pair_reciprocals`] with the product d e already formed.
#[inline(always)]
fn pair_reciprocals_of_product(d: c64, e: c64, product: c64) -> c64 {
    let norm = product.re * product.re + product.im * product.im;
    if (1e-290..=1e290).contains(&norm) {
        return (d + e) * product.conj() * (1.0 / norm);
    }
    reciprocal(d) + reciprocal(e)
}

/// A run of the continuation: the approximations at its last three gains, and the buffers of
/// the next gain's.
#[derive(Default)]
struct Continuation {
    last: Option<(f64, Conjugates)>,
    before: Option<(f64, Conjugates)>,
    earlier: Option<(f64, Conjugates)>,
    work: Conjugates,
    converged: Vec<bool>,
    /// The last gain's poles, unsorted (the common factors, the real roots, then each pair),
    /// and the permutation that sorted them.
    roots: Vec<c64>,
    order: Vec<usize>,
}

impl Continuation {
    /// A run starting from the poles `values` at the gain g (the QR iteration's: real poles
    /// exactly real, complex pairs exactly conjugate), less those nearest the common factors
    /// `fixed`.
    fn restart(g: f64, values: &[c64], fixed: &[c64]) -> Self {
        let Some(mut x) = Conjugates::of(values) else {
            return Self::default();
        };
        for f in fixed.iter().filter(|f| f.im >= 0.0) {
            let distance = |v: c64| (v - f).norm();
            let removed = if f.im == 0.0 {
                let far = |i: usize| distance(c64::new(x.real[i], 0.0));
                let nearest = (0..x.real.len()).min_by(|&i, &j| far(i).total_cmp(&far(j)));
                nearest.map(|i| x.real.swap_remove(i))
            } else {
                let far = |i: usize| distance(x.upper[i]);
                let nearest = (0..x.upper.len()).min_by(|&i, &j| far(i).total_cmp(&far(j)));
                nearest.map(|i| x.upper.swap_remove(i).re)
            };
            if removed.is_none() {
                return Self::default();
            }
        }
        Self {
            last: Some((g, x)),
            ..Self::default()
        }
    }

    /// The closed-loop poles at g by Aberth's iteration from the run's last gain, written
    /// into `out` sorted (as [`sort`]); false where the caller must take the QR iteration.
    /// Compiled also for AVX2 and chosen by the CPU ([`advance`]): the same operations (no
    /// fused multiply-adds), in three-operand instructions.
    fn next(&mut self, factored: &Factored, g: f64, out: &mut [c64]) -> bool {
        advance(self, factored, g, out)
    }

    /// [`Continuation::next`] in the body of [`advance`].
    #[inline(always)]
    fn next_kernel(&mut self, factored: &Factored, g: f64, out: &mut [c64]) -> bool {
        let Some((g1, last)) = &self.last else {
            return false;
        };
        if factored.fixed.len() + last.len() != out.len() {
            return false;
        }
        let x = &mut self.work;
        x.clone_from(last);
        if let Some((g0, before)) = &self.before {
            let t = (g - g1) / (g1 - g0);
            if t.is_finite() && t.abs() <= 4.0 {
                // The secant through the two previous gains' poles, and the parabola through
                // the three where the run has them (Lagrange's weights, formed once for every
                // pole): the parabola where it departs from the secant by less than the
                // secant's own step (its curvature a correction, not the turn of a path near
                // a breakaway point).
                let weights = self.earlier.as_ref().and_then(|(g2, _)| {
                    let w = [
                        (g - g0) * (g - g2) / ((g1 - g0) * (g1 - g2)),
                        (g - g1) * (g - g2) / ((g0 - g1) * (g0 - g2)),
                        (g - g1) * (g - g0) / ((g2 - g1) * (g2 - g0)),
                    ];
                    w.iter().all(|w| w.is_finite()).then_some(w)
                });
                let earlier = self.earlier.as_ref().map(|(_, roots)| roots);
                for (i, (y, y0)) in x.real.iter_mut().zip(&before.real).enumerate() {
                    let secant = *y + (*y - y0) * t;
                    let parabola = match (weights, earlier) {
                        (Some(w), Some(e)) => e
                            .real
                            .get(i)
                            .map_or(secant, |y2| w[0] * *y + w[1] * y0 + w[2] * y2),
                        _ => secant,
                    };
                    *y = if (parabola - secant).abs() < (secant - *y).abs() {
                        parabola
                    } else {
                        secant
                    };
                }
                for (i, (y, y0)) in x.upper.iter_mut().zip(&before.upper).enumerate() {
                    let secant = *y + (*y - y0) * t;
                    let parabola = match (weights, earlier) {
                        (Some(w), Some(e)) => e
                            .upper
                            .get(i)
                            .map_or(secant, |y2| *y * w[0] + y0 * w[1] + y2 * w[2]),
                        _ => secant,
                    };
                    let predicted = if (parabola - secant).norm_sqr() < (secant - *y).norm_sqr() {
                        parabola
                    } else {
                        secant
                    };
                    if predicted.im > 0.0 {
                        *y = predicted;
                    }
                }
            }
        }
        if !aberth(factored, g, x, &mut self.converged) {
            return false;
        }
        let roots = &mut self.roots;
        roots.clear();
        roots.extend_from_slice(&factored.fixed);
        for &v in &x.real {
            roots.push(c64::new(v, 0.0));
        }
        for &y in &x.upper {
            roots.push(y);
            roots.push(y.conj());
        }
        if !factored.verified(roots, g) {
            return false;
        }
        sort_into(roots, &mut self.order, out);
        // The work buffer becomes the last gain's, the earliest's is reused as the next work.
        let previous = self.last.replace((g, std::mem::take(&mut self.work)));
        let previous = std::mem::replace(&mut self.before, previous);
        if let Some((_, mut reused)) = std::mem::replace(&mut self.earlier, previous) {
            std::mem::swap(&mut self.work, &mut reused);
        }
        true
    }
}

/// [`Continuation::next`], its variant chosen by the CPU ([`fma_dispatch`]).
#[inline(always)]
fn advance_kernel<const FMA: bool>(
    continuation: &mut Continuation,
    factored: &Factored,
    g: f64,
    out: &mut [c64],
) -> bool {
    continuation.next_kernel(factored, g, out)
}

fma_dispatch!(fn advance(continuation: &mut Continuation, factored: &Factored, g: f64, out: &mut [c64]) -> bool => advance_kernel);

/// Aberth's iteration on the approximations `x` of the roots of χ_g (a real one kept real, a
/// pair iterated as its upper member), updated in place; false if they do not all converge
/// within [`ABERTH_ITERATIONS`] sweeps.
#[inline(always)]
fn aberth(factored: &Factored, g: f64, x: &mut Conjugates, converged: &mut Vec<bool>) -> bool {
    let eta = 32.0 * (factored.poles.len() + factored.zeros.len() + 1) as f64 * f64::EPSILON;
    let reals = x.real.len();
    let degree = factored.poles.len() as f64;
    converged.clear();
    converged.resize(reals + x.upper.len(), false);
    for sweep in 0..ABERTH_ITERATIONS {
        let mut done = true;
        for (i, converged) in converged.iter_mut().enumerate() {
            if *converged {
                continue;
            }
            let xi = if i < reals {
                c64::new(x.real[i], 0.0)
            } else {
                x.upper[i - reals]
            };
            // The first sweep forms the sums with the products (a predicted point is rarely a
            // root already); later ones only where the residual asks for a step.
            let (residual, sums) = if sweep == 0 {
                let (residual, s_p, s_z) = factored.residual_and_sums(xi, g, eta);
                (residual, Some((s_p, s_z)))
            } else {
                (factored.residual(xi, g, eta), None)
            };
            // The sums where the residual asks for a step (formed already in the first sweep).
            let sums = || sums.unwrap_or_else(|| (factored.poles.sum(xi), factored.zeros.sum(xi)));
            let repulsion = || x.repulsion(i);
            let correction = match residual {
                Residual::Root => {
                    *converged = true;
                    continue;
                }
                Residual::Off(d, n) => {
                    let (s_p, s_z) = sums();
                    correction(d, n, s_p, s_z, degree, xi, repulsion)
                }
                Residual::OffRatio(r) => {
                    let (s_p, s_z) = sums();
                    let ratio = logarithmic_derivative_of(s_p, s_z, r);
                    correction_of_ratio(ratio, degree, xi, repulsion)
                }
                Residual::Failed => return false,
            };
            let Correction::Step(step) = correction else {
                // A disk about x_i of radius deg χ |χ / χ'| holds a root of χ: within a few
                // units of x_i's last place, so x_i is that root to working precision (near a
                // zero, where the rounding of x_i - z bounds the residual, not the root).
                *converged = true;
                continue;
            };
            done = false;
            let next = xi - step;
            if !(next.re.is_finite() && next.im.is_finite()) {
                return false;
            }
            if i < reals {
                x.real[i] = next.re;
            } else if next.im > 0.0 {
                x.upper[i - reals] = next;
            } else {
                return false; // the pair has met the real axis: a breakaway point
            }
        }
        if done {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// Against the eigenvalues of each closed-loop matrix formed directly.
    #[test]
    fn matches_the_eigenvalues_of_each_closed_loop() {
        for n in [1usize, 2, 3, 6, 9, 14] {
            let a = Mat::from_fn(n, n, |i, j| ((i * 7 + j * 13) % 17) as f64 / 8.0 - 1.0);
            let b = Mat::from_fn(n, 1, |i, _| ((i * 5 + 3) % 7) as f64 / 3.0 - 1.0);
            let c = Mat::from_fn(1, n, |_, j| ((j * 3 + 1) % 5) as f64 / 2.0 - 1.0);
            let gains: Vec<f64> = (0..40).map(|i| -2.0 + 0.1 * i as f64).collect();
            let mut out = vec![c64::new(0.0, 0.0); gains.len() * n];
            root_locus(a.as_ref(), b.as_ref(), c.as_ref(), &gains, &mut out).unwrap();
            for (k, g) in gains.iter().enumerate() {
                let closed = Mat::from_fn(n, n, |i, j| a[(i, j)] - g * b[(i, 0)] * c[(0, j)]);
                let expected = sorted(eigenvalues(closed.as_ref()).unwrap());
                let got = sorted(out[k * n..(k + 1) * n].to_vec());
                for (x, y) in got.iter().zip(&expected) {
                    // Eigenvalue condition numbers of these matrices are modest; a defective
                    // cluster could split by sqrt(u), which these do not have.
                    assert!(
                        (x - y).norm() <= 1e-9 * (1.0 + y.norm()),
                        "n={n} g={g}: {x} vs {y}"
                    );
                }
            }
        }
    }

    /// The continuation against the QR iteration at every gain: loops with real and complex
    /// poles and zeros, relative degrees 1 to 3, gains of both signs through breakaway
    /// points; most gains must be taken by the continuation.
    #[test]
    fn the_continuation_agrees_with_the_qr_iteration() {
        for (n, seed) in [
            (2usize, 1usize),
            (3, 2),
            (4, 3),
            (6, 4),
            (6, 5),
            (8, 6),
            (12, 7),
        ] {
            let a = Mat::from_fn(n, n, |i, j| {
                let x = ((i * 7 + j * 13 + seed * 5) % 17) as f64 / 8.0 - 1.0;
                if i == j { x - 1.5 } else { x }
            });
            let b = Mat::from_fn(n, 1, |i, _| ((i * 5 + seed) % 7) as f64 / 3.0 - 1.0);
            let c = Mat::from_fn(1, n, |_, j| ((j * 3 + seed) % 5) as f64 / 2.0 - 1.0);
            let (bv, cv): (Vec<f64>, Vec<f64>) = (
                (0..n).map(|i| b[(i, 0)]).collect(),
                c.row(0).iter().copied().collect(),
            );
            let factored = Factored::of(a.as_ref(), &bv, &cv)
                .unwrap()
                .expect("not deferred");
            let gains: Vec<f64> = (0..400)
                .map(|i| -2.0 + 0.0125 * i as f64)
                .filter(|g| *g != 0.0)
                .collect();
            let mut continuation = Continuation::default();
            let mut continued = 0;
            let mut out = vec![c64::new(0.0, 0.0); n];
            for &g in &gains {
                let expected = sorted(closed_loop_poles(a.as_ref(), &bv, &cv, g).unwrap());
                if continuation.next(&factored, g, &mut out) {
                    continued += 1;
                    sort(&mut out);
                    let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.norm()));
                    for (x, y) in out.iter().zip(&expected) {
                        // A pole near a breakaway point (a double root) is accurate to about
                        // sqrt(u) by either method.
                        assert!((x - y).norm() <= 1e-7 * scale, "n={n} g={g}: {x} vs {y}");
                    }
                } else {
                    continuation = Continuation::restart(g, &expected, &factored.fixed);
                }
            }
            assert!(
                continued * 10 >= gains.len() * 9,
                "n={n}: {continued} of {}",
                gains.len()
            );
        }
    }

    /// The step from P / Q (one division) against the step by R, χ'/χ and their reciprocals
    /// (the form kept where P or Q leave the range), on seeded D, G N, sums and repulsions over
    /// twelve decades: the same step to rounding, and the same inclusion decision away from its
    /// boundary; and the quotient form taken where P or Q leave the range.
    #[test]
    fn the_step_by_one_division_is_the_step_by_the_quotient() {
        let mut draw = crate::test_matrices::xorshift(0x9e37_79b9_7f4a_7c15);
        let mut complex = |decades: f64| {
            let scale = 10f64.powf(decades * draw());
            c64::new(draw(), draw()) * scale
        };
        let mut steps = 0;
        for _ in 0..20_000 {
            let (d, n) = (complex(6.0), complex(6.0));
            let (s_p, s_z, repulsion, x) = (complex(3.0), complex(3.0), complex(3.0), complex(3.0));
            let degree = 6.0;
            let ratio = logarithmic_derivative_of(s_p, s_z, n * reciprocal(d));
            let by_ratio = correction_of_ratio(ratio, degree, x, || repulsion);
            match (
                correction(d, n, s_p, s_z, degree, x, || repulsion),
                by_ratio,
            ) {
                (Correction::Step(step), Correction::Step(expected)) => {
                    // Both are 1 / (χ'/χ - Σ) to a few units of its condition: that of
                    // χ'/χ - Σ, and of χ'/χ through the cancellations in P and Q.
                    let (p, q) = (d * s_p + n * s_z, d + n);
                    let cancellation = (d.norm() * s_p.norm() + n.norm() * s_z.norm()) / p.norm()
                        + (d.norm() + n.norm()) / q.norm();
                    let condition =
                        (ratio.norm() * cancellation + repulsion.norm()) * expected.norm();
                    assert!(
                        (step - expected).norm()
                            <= 64.0 * f64::EPSILON * condition * expected.norm(),
                        "{d} {n} {s_p} {s_z}: {step} vs {expected}"
                    );
                    steps += 1;
                }
                (Correction::Included, Correction::Included) => {}
                _ => {
                    // Only where deg χ / |χ'/χ| is at the inclusion radius to rounding.
                    let radius = degree / ratio.norm();
                    let limit = INCLUSION_ULPS * f64::EPSILON * x.norm();
                    assert!(
                        (radius - limit).abs() <= 1e-12 * limit,
                        "{radius} vs {limit}"
                    );
                }
            }
        }
        assert!(steps > 19_000, "{steps}");
        // P and Q beyond 1e50 in modulus: the quotient form, bit for bit.
        let (d, n) = (c64::new(3e60, 1e60), c64::new(-1e60, 2e60));
        let (s_p, s_z, x, repulsion) = (
            c64::new(0.5, 0.1),
            c64::new(-0.2, 0.3),
            c64::new(1.5, 0.5),
            c64::new(0.1, -0.4),
        );
        let ratio = logarithmic_derivative_of(s_p, s_z, n * reciprocal(d));
        let (Correction::Step(step), Correction::Step(expected)) = (
            correction(d, n, s_p, s_z, 4.0, x, || repulsion),
            correction_of_ratio(ratio, 4.0, x, || repulsion),
        ) else {
            panic!("a step expected");
        };
        assert_eq!(
            (step.re.to_bits(), step.im.to_bits()),
            (expected.re.to_bits(), expected.im.to_bits())
        );
    }

    /// A mode the loop does not see (a pole cancelled by an equal zero) stays at its place for
    /// every gain (taken out of the continuation as a common factor).
    #[test]
    fn a_cancelled_mode_stays_put() {
        // (s + 5) / ((s + 5)(s + 1)(s + 3)): the state at -5 is unobservable through c.
        let a = faer::mat![[-5.0, 0.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -3.0]];
        let b = faer::mat![[1.0], [0.0], [1.0]];
        let c = faer::mat![[0.0, 1.0, 0.0]];
        let gains: Vec<f64> = (1..200).map(|i| 0.05 * i as f64).collect();
        let n = 3;
        let mut out = vec![c64::new(0.0, 0.0); gains.len() * n];
        root_locus(a.as_ref(), b.as_ref(), c.as_ref(), &gains, &mut out).unwrap();
        for (k, g) in gains.iter().enumerate() {
            let poles = &out[k * n..(k + 1) * n];
            assert!(
                poles
                    .iter()
                    .any(|p| (p - c64::new(-5.0, 0.0)).norm() <= 1e-14),
                "{g}: {poles:?}"
            );
            // (s + 1)(s + 3) + g = 0: s = -2 ± sqrt(1 - g).
            let root = c64::new(1.0 - g, 0.0).sqrt();
            for root in [c64::new(-2.0, 0.0) + root, c64::new(-2.0, 0.0) - root] {
                assert!(
                    poles.iter().any(|p| (p - root).norm() <= 1e-7),
                    "{g}: {poles:?} {root}"
                );
            }
        }
    }

    /// The loop's root locus in one call: the states balanced, the closed-loop gains formed
    /// from the loop gains and d, against the eigenvalues of A - k b (1 + k d)^-1 c formed
    /// directly; a loop whose closed-loop terms leave the range is left to the caller.
    #[test]
    fn the_loop_root_locus_balances_and_forms_the_closed_loop_gains() {
        // States scaled by 10^±4: unbalanced, the closed loops have entries of 1e8 beside 1e-8.
        let n = 4;
        let s = [1e4, 1e-4, 1.0, 10.0];
        let a = Mat::from_fn(n, n, |i, j| {
            let x = ((i * 7 + j * 13) % 17) as f64 / 8.0 - 1.0;
            (if i == j { x - 2.0 } else { x }) * s[i] / s[j]
        });
        let b = Mat::from_fn(n, 1, |i, _| (((i * 5 + 3) % 7) as f64 / 3.0 - 1.0) * s[i]);
        let c = Mat::from_fn(1, n, |_, j| (((j * 3 + 1) % 5) as f64 / 2.0 - 1.0) / s[j]);
        let d = 0.25;
        let gains: Vec<f64> = (0..60).map(|i| -1.5 + 0.1 * i as f64).collect();
        let mut out = vec![c64::new(0.0, 0.0); gains.len() * n];
        let done =
            loop_root_locus(a.as_ref(), b.as_ref(), c.as_ref(), d, &gains, &mut out).unwrap();
        assert!(done);
        for (k, gain) in gains.iter().enumerate() {
            let g = gain / (1.0 + gain * d);
            assert_eq!(closed_loop_gain(*gain, d), g);
            let closed = Mat::from_fn(n, n, |i, j| a[(i, j)] - g * b[(i, 0)] * c[(0, j)]);
            let expected = sorted(eigenvalues(closed.as_ref()).unwrap());
            let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.norm()));
            for (x, y) in out[k * n..(k + 1) * n].iter().zip(&expected) {
                assert!((x - y).norm() <= 1e-9 * scale, "k={gain}: {x} vs {y}");
            }
        }
        // k d overflows: g = 1 / (1/k + d), finite.
        assert_eq!(closed_loop_gain(1e300, 1e10), 1.0 / (1e-300 + 1e10));
        // A closed-loop term beyond 2^RESCALE_EXPONENT, and b c = 0: left to the caller.
        let mut untouched = vec![c64::new(7.0, 0.0); n];
        let large = loop_root_locus(
            a.as_ref(),
            b.as_ref(),
            c.as_ref(),
            0.0,
            &[1e100],
            &mut untouched,
        );
        assert!(!large.unwrap());
        let zero = Mat::<f64>::zeros(1, n);
        let none = loop_root_locus(
            a.as_ref(),
            b.as_ref(),
            zero.as_ref(),
            0.0,
            &[1.0],
            &mut untouched,
        );
        assert!(!none.unwrap());
        assert!(untouched.iter().all(|x| *x == c64::new(7.0, 0.0)));
    }

    /// On one thread the gains form a single run on the calling thread; its poles agree with
    /// those of the runs of the parallel path (the same gains, other run starts) to rounding.
    #[test]
    fn one_thread_takes_one_run_with_the_same_poles() {
        let n = 6;
        let a = Mat::from_fn(n, n, |i, j| {
            let x = ((i * 7 + j * 13 + 3) % 17) as f64 / 8.0 - 1.0;
            if i == j { x - 1.5 } else { x }
        });
        let b = Mat::from_fn(n, 1, |i, _| ((i * 5 + 2) % 7) as f64 / 3.0 - 1.0);
        let c = Mat::from_fn(1, n, |_, j| ((j * 3 + 2) % 5) as f64 / 2.0 - 1.0);
        let gains: Vec<f64> = (0..500).map(|i| 0.01 * i as f64).collect();
        let mut parallel = vec![c64::new(0.0, 0.0); gains.len() * n];
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        pool.install(|| root_locus(a.as_ref(), b.as_ref(), c.as_ref(), &gains, &mut parallel))
            .unwrap();
        let mut single = vec![c64::new(0.0, 0.0); gains.len() * n];
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| root_locus(a.as_ref(), b.as_ref(), c.as_ref(), &gains, &mut single))
            .unwrap();
        for (k, (x, y)) in single.chunks(n).zip(parallel.chunks(n)).enumerate() {
            let scale = y.iter().fold(1.0f64, |m, v| m.max(v.norm()));
            for (x, y) in x.iter().zip(y) {
                assert!((x - y).norm() <= 1e-12 * scale, "gain {k}: {x} vs {y}");
            }
        }
    }

    /// The permutation kept from call to call sorts exactly as `sort` does: values in any
    /// order, ties, conjugate pairs, -0 beside +0.
    #[test]
    fn sort_into_sorts_as_sort_does() {
        let mut order = Vec::new();
        let mut out = vec![c64::new(0.0, 0.0); 7];
        for shift in 0..40 {
            let values: Vec<c64> = (0..7)
                .map(|i| {
                    let re = [(i * 5 + shift) % 7, 3, 0][i % 3] as f64 - 3.0;
                    let im = if i % 2 == 0 {
                        0.0
                    } else {
                        (shift % 3) as f64 - 1.0
                    };
                    c64::new(if i == 6 { -0.0 } else { re }, im)
                })
                .collect();
            sort_into(&values, &mut order, &mut out);
            let expected = sorted(values.clone());
            for (x, y) in out.iter().zip(&expected) {
                assert_eq!(
                    (x.re.to_bits(), x.im.to_bits()),
                    (y.re.to_bits(), y.im.to_bits())
                );
            }
        }
    }

    #[test]
    fn the_gain_zero_is_the_open_loop_exactly() {
        // A double integrator: the QR iteration would split the double pole at 0.
        let a = Mat::from_fn(2, 2, |i, j| if i == 0 && j == 1 { 1.0 } else { 0.0 });
        let b = Mat::from_fn(2, 1, |i, _| i as f64);
        let c = Mat::from_fn(1, 2, |_, j| if j == 0 { 1.0 } else { 0.0 });
        let mut out = vec![c64::new(1.0, 1.0); 4];
        root_locus(a.as_ref(), b.as_ref(), c.as_ref(), &[0.0, 4.0], &mut out).unwrap();
        assert_eq!(&out[..2], &[c64::new(0.0, 0.0); 2]);
        // s^2 + 4 = 0.
        let mut second = sorted(out[2..].to_vec());
        second.sort_by(|x, y| x.im.total_cmp(&y.im));
        assert!((second[0] - c64::new(0.0, -2.0)).norm() < 1e-15);
        assert!((second[1] - c64::new(0.0, 2.0)).norm() < 1e-15);
    }

    #[test]
    fn refuses_a_non_finite_gain_by_name() {
        let a = Mat::from_fn(1, 1, |_, _| -1.0);
        let b = Mat::from_fn(1, 1, |_, _| 1.0);
        let mut out = vec![c64::new(0.0, 0.0); 2];
        let error = root_locus(
            a.as_ref(),
            b.as_ref(),
            b.as_ref(),
            &[1.0, f64::NAN],
            &mut out,
        );
        assert!(matches!(error, Err(Error::NonFinite { arg: "gains", .. })));
        let wide = Mat::from_fn(1, 2, |_, _| 1.0);
        let error = root_locus(a.as_ref(), wide.as_ref(), b.as_ref(), &[1.0], &mut out)
            .unwrap_err()
            .to_string();
        assert!(error.starts_with("loop must have one input"), "{error}");
    }

    /// The poles at several gains from one form are those at each gain alone, bit for bit: on
    /// seeded loops of orders 1 to 8 and on a graded loop whose poles are polished (one
    /// factored form shared), with a zero gain among the others.
    #[test]
    fn poles_at_several_gains_are_those_at_each_alone() {
        let mut draw = crate::test_matrices::xorshift(0x2545_f491_4f6c_dd1d);
        let mut loops = Vec::new();
        for n in 1..=8 {
            for _ in 0..8 {
                let a = Mat::from_fn(n, n, |_, _| draw());
                let b: Vec<f64> = (0..n).map(|_| draw()).collect();
                let c: Vec<f64> = (0..n).map(|_| draw()).collect();
                loops.push((a, b, c));
            }
        }
        // 1/(s + 2^60) + 1/(s + 1): poles spanning more than GRADED_SPREAD.
        let big = 2f64.powi(60);
        loops.push((
            Mat::from_fn(2, 2, |i, j| match (i, j) {
                (0, 0) => -big,
                (1, 1) => -1.0,
                _ => 0.0,
            }),
            vec![1.0, 1.0],
            vec![1.0, 1.0],
        ));
        let gains = [1.0, 0.0, -2.0, 0.37, 25.0];
        for (a, b, c) in &loops {
            let together = closed_loop_poles_at(a.as_ref(), b, c, &gains).unwrap();
            assert_eq!(together.len(), gains.len());
            for (poles, &g) in together.iter().zip(&gains) {
                let alone = closed_loop_poles(a.as_ref(), b, c, g).unwrap();
                let bits = |x: &[c64]| {
                    x.iter()
                        .map(|v| (v.re.to_bits(), v.im.to_bits()))
                        .collect::<Vec<_>>()
                };
                assert_eq!(bits(poles), bits(&alone), "n={} g={g}", b.len());
            }
        }
    }
}
