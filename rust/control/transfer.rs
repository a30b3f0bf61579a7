//! Transfer functions of single-input, single-output channels from the state space, and the
//! evaluation of a factored transfer function G(s) = K Π(s - z_i) / Π(s - p_j).
//!
//! [`transfer_channels`] is the fast path of `aerocontrol.transfer_function` and
//! `aerocontrol.transfer_matrix`: for each channel G = c (sI - A)^-1 b + d it computes the same
//! zeros, gain and numerator as the package's reference path (`transfer.py`: the system matrix
//! S = [[A, b], [c, d]] equilibrated by powers of two, Emami-Naeini and Van Dooren's reduction,
//! the gain from G at a point away from every root), and defers a channel to that path
//! (returns None for it) wherever the two could differ or the result could not be confirmed:
//!
//! 1. **Equilibration** as `transfer._balance` (Ruiz's sweeps on the output row and the input
//!    column, the unit of frequency from ||A||, Osborne's balancing per state, by powers of
//!    two), applied to the entries as it goes (the reference works on their logarithms: the
//!    fast path takes only channels whose nonzero entries lie within 2^±250), then S divided
//!    by the power of two above ||S||_F.
//! 2. **Reduction** (Emami-Naeini and Van Dooren 1982, procedure "reduce", for one output):
//!    while |d| <= tol = (n + 1)^2 ε ||S||_F, a Householder reflection H with c H = ±||c|| e_N
//!    moves the output onto the last state, and the system becomes
//!    (A11, b1, [H A H]_{N,1:N-1}, (H b)_N) of order N - 1, with the same finite zeros. A norm
//!    ||c|| <= tol (or no state left) is a channel of normal rank 0: G = 0. A decision value
//!    within a factor of 8 of tol is deferred (the reference's equilibration and rotations
//!    round differently).
//! 3. **Zeros.** With d̂ = |d| > tol, the zeros are the eigenvalues of A - b c / d: backward
//!    stable for the pencil when ||[c, d]|| <= 16 |d|; up to 2^10 |d| the generalized
//!    eigenvalues of the compressed pencil (Af, Bf) = ([A b] W, W_11) by QZ (W a reflection with
//!    [c d] W = ±||[c d]|| e_N); beyond, deferred (a zero far beyond the system's scale, which
//!    the reference takes from the better of two QZ forms). Zeros within tol of the origin are
//!    0 (a washout's) where the equilibrated system matrix at the origin is singular. The same reduction on the unequilibrated S must find no more zeros
//!    (the reference then adds those beyond the equilibrated pencil's reach), else deferred.
//! 4. **Gain** K = d where d != 0 and there are n zeros; otherwise K = G(s0) Π(s0 - p)/Π(s0 - z)
//!    at the point s0 = jω (z = e^{jωh}) of a grid farthest from every root (as
//!    `transfer._evaluation_points`), G(s0) solved on the equilibrated system and the product
//!    renormalised by powers of two.
//! 5. **Verification.** G at the best point of a second grid (around max|A|; the next point of
//!    the unit circle for a discrete model), from the state space, must agree with the
//!    factored form to 1e-8 (relative); a G(s0) of 0 or below the normal range, a gain or a
//!    numerator beyond the doubles, and a channel whose entries make products leave the range
//!    of doubles are deferred.
//!
//! [`factored_response`] evaluates K Π(s - z_i) / Π(s - p_j) with the product held as a mantissa
//! and a power of two, the factors taken a zero's, then a pole's, by increasing modulus, the
//! mantissa renormalised whenever it leaves 2^±200, and scaled once at the end: nothing
//! overflows or underflows where the result does not.
//!
//! Reference: A. Emami-Naeini and P. Van Dooren, "Computation of zeros of linear multivariable
//! systems", Automatica 18(4), 415-430, 1982.

use crate::error::Error;
use crate::linalg::householder::reflector;
use crate::linalg::matrix::with_order;
use crate::linalg::norm::max_abs;
use crate::linalg::qz::{generalized_eigenvalues, qz};
use crate::linalg::schur::eigenvalues;
use faer::{Mat, MatRef, c64};
use nalgebra::DMatrix;

/// One channel's zeros (sorted, as `numpy.sort_complex`), the same by increasing modulus (the
/// order in which [`factored_response_sorted`] takes them), gain K and numerator K Π(s - z_i)
/// (highest power first).
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    pub zeros: Vec<c64>,
    pub zeros_by_modulus: Vec<c64>,
    pub gain: f64,
    pub numerator: Vec<f64>,
}

/// The poles (the eigenvalues of A, sorted), the same by increasing modulus, the denominator
/// Π(s - p_j) and each requested channel (None: deferred to the reference path).
#[derive(Debug, Clone)]
pub struct Transfer {
    pub poles: Vec<c64>,
    pub poles_by_modulus: Vec<c64>,
    pub denominator: Vec<f64>,
    pub channels: Vec<Option<Channel>>,
}

/// The channels (output i, input j) of the model (A, B, C, D) (see the module's
/// documentation); `dt` is 0 for a continuous model, else the sampling period.
pub fn transfer_channels(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    dt: f64,
    channels: &[(usize, usize)],
) -> Result<Transfer, Error> {
    crate::control::frequency::check_state_space(a, b, c, d)?;
    for &(i, j) in channels {
        if i >= c.nrows() || j >= b.ncols() {
            return Err(Error::InvalidArgument {
                arg: "channels",
                message: format!(
                    "channel ({i}, {j}) is not one of the model's {} x {} channels",
                    c.nrows(),
                    b.ncols()
                ),
            });
        }
    }
    let n = a.nrows();
    let poles = if n > 0 {
        cleaned(eigenvalues(a)?)
    } else {
        Vec::new()
    };
    let denominator = polynomial(&poles, 1.0).unwrap_or_default();
    let shared = Shared::of(a, dt, &poles);
    let mut lu = ShiftedLu::default();
    let mut out = Vec::with_capacity(channels.len());
    for &(i, j) in channels {
        crate::platform::interrupt::check()?;
        let bv: Vec<f64> = (0..n).map(|k| b[(k, j)]).collect();
        let cv: Vec<f64> = (0..n).map(|k| c[(i, k)]).collect();
        out.push(channel(a, &bv, &cv, d[(i, j)], &poles, &shared, &mut lu)?);
    }
    Ok(Transfer {
        poles,
        poles_by_modulus: shared.sorted_poles,
        denominator,
        channels: out,
    })
}

/// Roots with an imaginary part below 8 ε max(|Re|, |Im|) made real, sorted by real part,
/// then imaginary part (as `transfer._conjugate_clean`).
fn cleaned(mut roots: Vec<c64>) -> Vec<c64> {
    for r in &mut roots {
        let part = r.re.abs().max(r.im.abs());
        if r.re.is_finite() && r.im.is_finite() && r.im.abs() <= 8.0 * f64::EPSILON * part {
            r.im = 0.0;
        }
    }
    roots.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    roots
}

/// k Π(s - r) for roots in conjugate pairs (a real factor per real root, a quadratic per pair),
/// highest power first; None when a root has no conjugate partner or a coefficient is not
/// finite.
fn polynomial(roots: &[c64], k: f64) -> Option<Vec<f64>> {
    let upper = roots.iter().filter(|r| r.im > 0.0).count();
    let lower = roots.iter().filter(|r| r.im < 0.0).count();
    if upper != lower {
        return None;
    }
    // Two buffers of the final length, the product so far in one, the next formed in the other.
    let mut p = Vec::with_capacity(roots.len() + 1);
    p.push(k);
    let mut next = Vec::with_capacity(roots.len() + 1);
    for r in roots {
        if r.im < 0.0 {
            continue;
        }
        let factor: &[f64] = if r.im == 0.0 {
            &[1.0, -r.re]
        } else {
            &[1.0, -2.0 * r.re, r.re * r.re + r.im * r.im]
        };
        next.clear();
        next.resize(p.len() + factor.len() - 1, 0.0);
        for (x, &pi) in p.iter().enumerate() {
            for (y, &fi) in factor.iter().enumerate() {
                next[x + y] += pi * fi;
            }
        }
        std::mem::swap(&mut p, &mut next);
    }
    p.iter().all(|v| v.is_finite()).then_some(p)
}

// ----- powers of two ---------------------------------------------------------------------------

/// 2^k for k in the normal range [-1022, 1023], exactly.
fn two_to(k: i64) -> f64 {
    debug_assert!((-1022..=1023).contains(&k));
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// x 2^e, rounded once (x of magnitude in [1/2, 1), as a renormalised mantissa is).
fn ldexp(x: f64, e: i64) -> f64 {
    let e = e.clamp(-2200, 2200);
    if e > 1023 {
        x * two_to(1023) * two_to((e - 1023).min(1023))
    } else if e < -1021 {
        // x 2^(e + 1000) is normal (exact), then one rounding into the subnormals.
        x * two_to((e + 1000).max(-1022)) * two_to(-1000)
    } else {
        x * two_to(e)
    }
}

/// The exponent e with |x| = f 2^e, f in [1/2, 1) (0 for 0 and non-finite x).
fn exponent_of(x: f64) -> i64 {
    if x == 0.0 || !x.is_finite() {
        return 0;
    }
    let bits = x.abs().to_bits();
    let biased = (bits >> 52) as i64;
    if biased == 0 {
        exponent_of(x * two_to(64)) - 64
    } else {
        biased - 1022
    }
}

/// Multiples of (n + 1) u within which the smallest pivot of the equilibrated system matrix
/// at the origin makes it singular ([`singular_at_origin`]).
const ORIGIN_SINGULARITY: f64 = 100.0;

/// Whether the system matrix at the origin, S0 = [[A, b], [c, d]], is singular to rounding once
/// each row and then each column is scaled by a power of two to largest magnitude 1 (as
/// LAPACK's DGEEQU): the smallest pivot of its LU factorisation with complete pivoting at most
/// 100 (n + 1) u times the first (the reference's test of σ_min, to a factor of n + 1). A
/// computed zero within the rank tolerance of
/// the origin is the origin only then (a washout's, computed as 1e-17); otherwise it is a zero
/// at the scale of small poles beside large ones, which the pencil scaled to the large ones
/// puts below its tolerance: 1/(s + 1) + 1e15/(s + 1e15) has the zero -2, which was returned
/// as 0. `transfer._singular_at_origin` is the reference path's.
fn singular_at_origin(a: MatRef<'_, f64>, b: &[f64], c: &[f64], d: f64) -> bool {
    // S0 column-major (entry (i, j) at i + j size) and its pivots: on the stack for the orders
    // of flight models, the size then a constant of the loops.
    with_order!(
        a.nrows() + 1,
        [2, 3, 4, 5, 6, 7, 8, 9],
        S => {
            let mut s0 = [[0.0; S]; S];
            let mut pivots = [0.0; S];
            singular_origin_matrix(a, b, c, d, s0.as_flattened_mut(), &mut pivots)
        },
        size => {
            let (mut s0, mut pivots) = (vec![0.0; size * size], vec![0.0; size]);
            singular_origin_matrix(a, b, c, d, &mut s0, &mut pivots)
        }
    )
}

/// [`singular_at_origin`] with S0's storage `m` (zero, column-major, n + 1 squared entries)
/// and its pivots' (n + 1).
#[inline(always)]
fn singular_origin_matrix(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    d: f64,
    m: &mut [f64],
    pivots: &mut [f64],
) -> bool {
    let n = a.nrows();
    let size = pivots.len();
    for (j, column) in m.chunks_exact_mut(size).enumerate() {
        if j < n {
            for (i, x) in column[..n].iter_mut().enumerate() {
                *x = a[(i, j)];
            }
            column[n] = c[j];
        } else {
            column[..n].copy_from_slice(b);
            column[n] = d;
        }
    }
    // The largest magnitude by selects (a NaN is never taken, as by f64::max).
    let larger = |x: f64, v: &f64| if v.abs() > x { v.abs() } else { x };
    for i in 0..size {
        let e = exponent_of(m[i..].iter().step_by(size).fold(0.0, larger));
        scale_by_power_of_two(m[i..].iter_mut().step_by(size), -e);
    }
    for column in m.chunks_exact_mut(size) {
        let e = exponent_of(column.iter().fold(0.0, larger));
        scale_by_power_of_two(column.iter_mut(), -e);
    }
    // The smallest pivot of Gaussian elimination with complete pivoting bounds σ_min above
    // (σ_min(S0) <= ||L||_2 σ_min(U) <= (n + 1) min |u_ii|, |l_ij| <= 1): a small pivot is a
    // singular S0, at a fraction of the SVD's cost (the reference path takes the SVD).
    complete_pivots(m, pivots);
    if pivots.iter().any(|u| u.is_nan()) {
        return true; // no verdict: the rank tolerance alone, as before
    }
    let smallest = pivots.iter().fold(f64::INFINITY, |m, &u| m.min(u));
    let largest = pivots.iter().fold(0.0_f64, |m, &u| m.max(u));
    smallest <= ORIGIN_SINGULARITY * (n + 1) as f64 * f64::EPSILON * largest
}

/// Each value v <- v 2^e as [`ldexp_any`] gives it: one multiplication by 2^e where that is a
/// normal double (the same value for 0 and non-finite v).
fn scale_by_power_of_two<'a>(values: impl Iterator<Item = &'a mut f64>, e: i64) {
    if (-1022..=1023).contains(&e) {
        let factor = two_to(e);
        values.for_each(|v| *v *= factor);
    } else {
        values.for_each(|v| *v = ldexp_any(*v, e));
    }
}

/// The magnitudes |u_kk| of the pivots of Gaussian elimination with complete pivoting on M
/// (square, column-major in `m`: entry (i, j) at i + j size) into `pivots` (size of them): at
/// step k the largest |m_ij| of the trailing block (the first in column order) is brought to
/// (k, k), then m_ij -= (m_ik / m_kk) m_kj below and right of it. The pivots after a zero one
/// are 0. Only the trailing block is read after step k, so the swaps and the elimination touch
/// only it (the multipliers m_ik / m_kk are kept in column k).
#[inline(always)]
fn complete_pivots(m: &mut [f64], pivots: &mut [f64]) {
    let size = pivots.len();
    for k in 0..size {
        // The first largest magnitude; a NaN anywhere in the block is the pivot NaN.
        let (mut row, mut col, mut largest, mut unordered) = (k, k, -1.0f64, false);
        for j in k..size {
            for (i, x) in m[j * size + k..(j + 1) * size].iter().enumerate() {
                let x = x.abs();
                unordered |= x.is_nan();
                if x > largest {
                    (row, col, largest) = (k + i, j, x);
                }
            }
        }
        if unordered || largest == 0.0 {
            pivots[k] = if unordered { f64::NAN } else { largest };
            pivots[k + 1..].fill(0.0);
            return;
        }
        if row != k {
            for j in k..size {
                m.swap(j * size + k, j * size + row);
            }
        }
        if col != k {
            let (left, right) = m.split_at_mut(col * size);
            left[k * size + k..(k + 1) * size].swap_with_slice(&mut right[k..size]);
        }
        let pivot = m[k * size + k];
        pivots[k] = pivot.abs();
        let (head, tail) = m.split_at_mut((k + 1) * size);
        let multipliers = &mut head[k * size + k + 1..];
        for l in multipliers.iter_mut() {
            *l /= pivot;
        }
        for column in tail.chunks_exact_mut(size) {
            let t = column[k];
            for (x, &l) in column[k + 1..].iter_mut().zip(multipliers.iter()) {
                *x -= l * t;
            }
        }
    }
}

/// A complex value m 2^e, m of largest part in [1/2, 1) (or 0, or not finite).
#[derive(Debug, Clone, Copy)]
struct Scaled {
    m: c64,
    e: i64,
}

/// The range of the largest part within which a [`Scaled`] mantissa is left as it is: a product
/// or quotient of two such values stays normal (2^±400), and a part 2^-600 below the other,
/// which could fall into the subnormals there, is negligible beside it.
const MANTISSA_RANGE: (f64, f64) = (6.223015277861142e-61, 1.6069380442589903e60);

// The operations of a factor are inlined into the loops of [`factored`] (a few instructions each
// where the mantissa stays in range); the renormalisation itself is kept out of line.
impl Scaled {
    #[inline(always)]
    fn new(m: c64, e: i64) -> Self {
        let mut s = Scaled { m, e };
        s.renormalize();
        s
    }

    /// Brings the largest part to [1/2, 1) by a power of two (exact) when it has left
    /// [`MANTISSA_RANGE`]: multiplications by powers of two commute with the rounding of
    /// the products in between, so renormalising less often changes nothing else.
    #[inline(always)]
    fn renormalize(&mut self) {
        // Non-negative doubles are ordered as their bits, and a NaN's lie above infinity's: the
        // larger magnitude's bits within the range's is the common case, decided by one
        // comparison; anything else is decided as below, out of line.
        let magnitude = |v: f64| v.to_bits() & !(1u64 << 63);
        let largest = magnitude(self.m.re).max(magnitude(self.m.im));
        let (low, high) = (MANTISSA_RANGE.0.to_bits(), MANTISSA_RANGE.1.to_bits());
        if largest.wrapping_sub(low) > high - low {
            self.renormalize_outside_range();
        }
    }

    /// [`Scaled::renormalize`] where the larger magnitude's bits are not within the range's:
    /// 0, a NaN and the infinities are left as they are.
    #[cold]
    #[inline(never)]
    fn renormalize_outside_range(&mut self) {
        let part = self.m.re.abs().max(self.m.im.abs());
        if part > 0.0 && part.is_finite() && !(MANTISSA_RANGE.0..=MANTISSA_RANGE.1).contains(&part)
        {
            self.rescale(part);
        }
    }

    /// The mantissa divided by the power of two of `part`, its largest part, and the exponent
    /// raised by it.
    fn rescale(&mut self, part: f64) {
        let k = exponent_of(part);
        self.m = c64::new(ldexp(self.m.re, -k), ldexp(self.m.im, -k));
        self.e += k;
    }

    /// (point - root) as a scaled value: both divided by the power of two of their largest
    /// part first when that is near the overflow threshold, so that the difference of two
    /// numbers near ±1e308 stays finite.
    #[inline(always)]
    fn difference(point: c64, root: c64) -> Self {
        // No part at or beyond 1e300 (a NaN part is none), tested without a branch per part.
        let large = |v: f64| v.abs() >= 1e300;
        if !(large(point.re) | large(point.im) | large(root.re) | large(root.im)) {
            return Scaled::new(point - root, 0);
        }
        let largest = [point.re, point.im, root.re, root.im]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        Scaled::large_difference(point, root, largest)
    }

    /// [`Scaled::difference`] where the largest part, `largest`, is at least 1e300.
    #[cold]
    #[inline(never)]
    fn large_difference(point: c64, root: c64, largest: f64) -> Self {
        let q = if largest.is_finite() {
            exponent_of(largest)
        } else {
            0
        };
        let scale = |z: c64| c64::new(ldexp(z.re, -q), ldexp(z.im, -q));
        Scaled::new(scale(point) - scale(root), q)
    }

    #[inline(always)]
    fn times(&mut self, other: Scaled) {
        self.m *= other.m;
        self.e += other.e;
        self.renormalize();
    }

    #[inline(always)]
    fn divided_by(&mut self, other: Scaled) {
        self.m = quotient(self.m, other.m);
        self.e -= other.e;
        self.renormalize();
    }

    fn value(self) -> c64 {
        if self.e == 0 {
            return self.m;
        }
        // Renormalised first, so that the one scaling rounds once (into the subnormals).
        let mut s = self;
        let part = s.m.re.abs().max(s.m.im.abs());
        if part > 0.0 && part.is_finite() {
            let k = exponent_of(part);
            s.m = c64::new(ldexp(s.m.re, -k), ldexp(s.m.im, -k));
            s.e += k;
        }
        c64::new(ldexp(s.m.re, s.e), ldexp(s.m.im, s.e))
    }
}

/// x / y as numpy divides complex numbers (Smith's method; x / 0 is inf or NaN, never an
/// error).
#[inline]
fn quotient(x: c64, y: c64) -> c64 {
    if y.re == 0.0 && y.im == 0.0 {
        return c64::new(x.re / 0.0, x.im / 0.0);
    }
    if y.re.abs() >= y.im.abs() {
        let ratio = y.im / y.re;
        let denominator = y.re + y.im * ratio;
        c64::new(
            (x.re + x.im * ratio) / denominator,
            (x.im - x.re * ratio) / denominator,
        )
    } else {
        let ratio = y.re / y.im;
        let denominator = y.re * ratio + y.im;
        c64::new(
            (x.re * ratio + x.im) / denominator,
            (x.im * ratio - x.re) / denominator,
        )
    }
}

/// The roots by increasing modulus (an overflowing modulus is infinite).
fn by_modulus(roots: &[c64]) -> Vec<c64> {
    let mut keyed: Vec<(f64, c64)> = roots.iter().map(|r| (r.norm(), *r)).collect();
    keyed.sort_by(|x, y| x.0.total_cmp(&y.0));
    keyed.into_iter().map(|(_, r)| r).collect()
}

/// `start` Π(point - multiply_i) / Π(point - divide_j), renormalised after each factor (the
/// roots already sorted by modulus; a zero's factor, then a pole's).
fn factored(start: Scaled, point: c64, multiply: &[c64], divide: &[c64]) -> Scaled {
    let mut value = start;
    for k in 0..multiply.len().max(divide.len()) {
        if let Some(&r) = multiply.get(k) {
            value.times(Scaled::difference(point, r));
        }
        if let Some(&r) = divide.get(k) {
            value.divided_by(Scaled::difference(point, r));
        }
    }
    value
}

/// K Π(s - z_i) / Π(s - p_j) at each point into `out`, K = mantissa 2^exponent (see the
/// module's documentation). A point at a pole gives an infinite or NaN value.
pub fn factored_response(
    mantissa: f64,
    exponent: i64,
    zeros: &[c64],
    poles: &[c64],
    points: &[c64],
    out: &mut [c64],
) {
    let (zeros, poles) = (by_modulus(zeros), by_modulus(poles));
    factored_response_sorted(mantissa, exponent, &zeros, &poles, points, out);
}

/// [`factored_response`] with the zeros and the poles already by increasing modulus (as
/// [`Channel::zeros_by_modulus`] and [`Transfer::poles_by_modulus`] hold them).
pub fn factored_response_sorted(
    mantissa: f64,
    exponent: i64,
    zeros: &[c64],
    poles: &[c64],
    points: &[c64],
    out: &mut [c64],
) {
    let start = Scaled::new(c64::new(mantissa, 0.0), exponent);
    let (point_chunks, point_rest) = points.as_chunks::<LANES>();
    let (out_chunks, out_rest) = out.as_chunks_mut::<LANES>();
    for (chunk, values) in point_chunks.iter().zip(out_chunks) {
        for (value, lane) in values
            .iter_mut()
            .zip(factored_lanes(start, chunk, zeros, poles))
        {
            *value = lane.value();
        }
    }
    for (point, value) in point_rest.iter().zip(out_rest) {
        *value = factored(start, *point, zeros, poles).value();
    }
}

/// The number of points [`factored_lanes`] takes at once.
const LANES: usize = 4;

/// [`factored`] at `LANES` points at once: the same operations on each point's value in the
/// same order (bit for bit), the points' products interleaved factor by factor, so that their
/// chains of dependent multiplications and divisions overlap.
#[inline(always)]
fn factored_lanes(
    start: Scaled,
    points: &[c64; LANES],
    multiply: &[c64],
    divide: &[c64],
) -> [Scaled; LANES] {
    let mut values = [start; LANES];
    for k in 0..multiply.len().max(divide.len()) {
        if let Some(&r) = multiply.get(k) {
            for (value, &point) in values.iter_mut().zip(points) {
                value.times(Scaled::difference(point, r));
            }
        }
        if let Some(&r) = divide.get(k) {
            for (value, &point) in values.iter_mut().zip(points) {
                value.divided_by(Scaled::difference(point, r));
            }
        }
    }
    values
}

/// (m, e) with x = m 2^e and |m| in [1/2, 1) (as C's frexp; (0, 0) for 0), for a finite x.
pub fn mantissa_and_exponent(x: f64) -> (f64, i64) {
    let e = exponent_of(x);
    (ldexp_any(x, -e), e)
}

// ----- equilibration ---------------------------------------------------------------------------

/// The range of the magnitudes of a channel's nonzero entries in which the fast path forms sums
/// of squares and products of entries directly: 2^±250.
const ENTRY_RANGE: (f64, f64) = (5.527147875260445e-76, 1.8092513943330656e75);

/// The integer nearest -log2(norm) / 2, ties to even (Python's round); 0 for a zero norm, and
/// without a logarithm for a norm within [0.51, 1.96] (|log2| / 2 below 0.49 there) and
/// wherever [`nearest_quotient`] decides it from [`log2_estimate`].
fn half_exponent(norm: f64) -> i64 {
    if (0.51..=1.96).contains(&norm) {
        0
    } else if norm > 0.0 {
        -nearest_quotient(log2_estimate(norm), 2.0, || norm.log2())
    } else {
        0
    }
}

/// log2(x) to within 1.4e-3 for a positive normal x (the exponent, and on the significand f in
/// [1, 2) the cubic nearest log2 f in the maximum norm, by Chebyshev interpolation); NaN for any
/// other x.
fn log2_estimate(x: f64) -> f64 {
    if !x.is_normal() || x < 0.0 {
        return f64::NAN;
    }
    let bits = x.to_bits();
    let exponent = (bits >> 52) as i64 - 1023;
    let f = f64::from_bits((bits & ((1u64 << 52) - 1)) | 1f64.to_bits());
    let cubic = ((0.1539124216258583 * f - 1.0294861821765071) * f + 3.0107182106126817) * f
        - 2.133809518617733;
    exponent as f64 + cubic
}

/// The integer nearest `exact()` / q, ties to even, as the integer nearest `estimate` / q where
/// the estimate (within 3e-3 of the exact value, q >= 2) lies more than 0.01 from halfway
/// between two integers (the exact value then rounds to the same integer): `exact`, a
/// difference of logarithms, is computed only near halfway (or for a NaN estimate).
fn nearest_quotient(estimate: f64, q: f64, exact: impl FnOnce() -> f64) -> i64 {
    let r = estimate / q;
    // floor(r + 1/2) by truncation (|r| < 2^11 here; a NaN r falls through to `exact`).
    let t = r + 0.5;
    let mut k = t as i64;
    if k as f64 > t {
        k -= 1;
    }
    if (r - k as f64).abs() < 0.49 {
        k
    } else {
        (exact() / q).round_ties_even() as i64
    }
}

/// A SISO system (A, b, c, d), A in nalgebra's column-major storage (`linalg/matrix.rs`: at
/// these orders the index arithmetic of one contiguous buffer, not a general view).
#[derive(Debug, Clone)]
struct Siso {
    a: DMatrix<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: f64,
}

impl Siso {
    /// A copy of the model's channel (A, b, c, d).
    fn of(a: MatRef<'_, f64>, b: &[f64], c: &[f64], d: f64) -> Self {
        Siso {
            a: DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)]),
            b: b.to_vec(),
            c: c.to_vec(),
            d,
        }
    }
}

fn squares(values: impl Iterator<Item = f64>) -> f64 {
    values.map(|v| v * v).sum()
}

/// The system equilibrated as `transfer._balance` does for one input and one output (Ruiz's
/// sweeps on the output row [c d] and the input column [b; d], the unit of frequency from
/// ||A||, then Osborne's balancing of each state's row of [A b] against its column of [A; c],
/// without the diagonal; every scaling the power of two nearest the square root of the norms'
/// ratio), here applied to the entries as it goes (exact: the entries lie in [`ENTRY_RANGE`]);
/// returns it with f, A and b having been multiplied by 2^-f (its zeros times 2^f are the
/// model's), and o + i, the output's and input's exponents (G(s) = 2^-(o + i) G_e(s 2^-f)).
fn equilibrated(s: Siso) -> (Siso, i64, i64) {
    // The order a constant of the loops for the orders of flight models (unrolled, the
    // indices checked once).
    with_order!(
        s.a.nrows(),
        [1, 2, 3, 4, 5, 6, 7, 8],
        N => equilibrated_of_order(s, N),
        n => equilibrated_of_order(s, n)
    )
}

/// [`equilibrated`] of a system of order n.
#[inline(always)]
fn equilibrated_of_order(mut s: Siso, n: usize) -> (Siso, i64, i64) {
    let (mut frequency, mut units) = (0i64, 0i64);
    let scale = |x: &mut f64, k: i64| *x *= two_to(k);
    for _ in 0..40 {
        let mut changed = false;
        let k = half_exponent(squares(s.c.iter().copied().chain([s.d])).sqrt());
        if k != 0 {
            s.c.iter_mut().for_each(|x| scale(x, k));
            scale(&mut s.d, k);
            units += k;
            changed = true;
        }
        let k = half_exponent(squares(s.b.iter().copied().chain([s.d])).sqrt());
        if k != 0 {
            s.b.iter_mut().for_each(|x| scale(x, k));
            scale(&mut s.d, k);
            units += k;
            changed = true;
        }
        let mut size = squares(s.a.as_slice().iter().copied()).sqrt();
        if size == 0.0 {
            size = squares(s.b.iter().copied()).sqrt();
        }
        let k = half_exponent(size);
        if k != 0 {
            s.a.as_mut_slice().iter_mut().for_each(|x| scale(x, k));
            s.b.iter_mut().for_each(|x| scale(x, k));
            frequency -= k;
            changed = true;
        }
        let (entries, b, c) = (
            &mut s.a.as_mut_slice()[..n * n],
            &mut s.b[..n],
            &mut s.c[..n],
        );
        for i in 0..n {
            // The sums of squares of the other states' entries, in order, then b_i's (c_i's):
            // two runs around the diagonal, no test per entry. A is column-major: column i is
            // contiguous, row i every n-th entry from i.
            let column = &entries[i * n..(i + 1) * n];
            let (mut row, mut col) = (0.0, 0.0);
            for j in 0..i {
                let v = entries[i + j * n];
                row += v * v;
            }
            for j in i + 1..n {
                let v = entries[i + j * n];
                row += v * v;
            }
            for v in &column[..i] {
                col += v * v;
            }
            for v in &column[i + 1..] {
                col += v * v;
            }
            row += b[i] * b[i];
            col += c[i] * c[i];
            if row == 0.0 || col == 0.0 {
                continue;
            }
            // k = 0 without logarithms where col / row lies within [1/3.9, 3.9] (|log2| / 4
            // below 0.491 there).
            let k = if col <= 3.9 * row && row <= 3.9 * col {
                0
            } else {
                nearest_quotient(log2_estimate(col) - log2_estimate(row), 4.0, || {
                    col.log2() - row.log2()
                })
            };
            if k != 0 {
                for j in (0..n).filter(|&j| j != i) {
                    scale(&mut entries[i + j * n], k);
                    scale(&mut entries[j + i * n], -k);
                }
                scale(&mut b[i], k);
                scale(&mut c[i], -k);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    (s, frequency, units)
}

/// The entries of the system matrix [[A, b], [c, d]] in parts: A's (column-major), b's, c's
/// and d.
fn entries(s: &Siso) -> [&[f64]; 4] {
    [s.a.as_slice(), &s.b, &s.c, std::slice::from_ref(&s.d)]
}

/// ||[[A, b], [c, d]]||_F, the squares summed in the order of [`entries`].
fn frobenius(s: &Siso) -> f64 {
    let mut total = 0.0;
    for part in entries(s) {
        for v in part {
            total += v * v;
        }
    }
    total.sqrt()
}

/// The system divided by the power of two 2^e above ||S||_F (exactly), and e.
fn unit_scaled(mut s: Siso) -> (Siso, i64) {
    let e = exponent_of(frobenius(&s));
    let factor = two_to(-e);
    for part in [s.a.as_mut_slice(), &mut s.b, &mut s.c] {
        for x in part {
            *x *= factor;
        }
    }
    s.d *= factor;
    (s, e)
}

/// x 2^e for any finite x, rounded once: one multiplication by 2^e where that is a normal
/// double, else renormalised first, then [`ldexp`].
fn ldexp_any(x: f64, e: i64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    if (-1022..=1023).contains(&e) {
        return x * two_to(e);
    }
    let k = exponent_of(x);
    ldexp(ldexp(x, -k), e + k)
}

// ----- the reduction ---------------------------------------------------------------------------

/// The outcome of the reduction.
enum Reduced {
    /// A system with the same finite zeros and |d| > tol.
    Regular(Siso),
    /// Normal rank 0: the channel is zero.
    Zero,
    /// A decision value within a factor of 2 of the tolerance.
    Ambiguous,
}

/// Whether `value` is above `tol`, or None within a factor of 8 of it (the reference's
/// equilibration, in logarithms, and its rotations round differently).
fn above(value: f64, tol: f64) -> Option<bool> {
    if value > 8.0 * tol {
        Some(true)
    } else if value <= 0.125 * tol {
        Some(false)
    } else {
        None
    }
}

/// H = I - τ u u^T with c H = β e_N (u_N = 1): the reflector of `transfer._reduce`'s V.
fn output_reflector(c: &[f64]) -> (Vec<f64>, f64) {
    let mut x: Vec<f64> = c.iter().rev().copied().collect();
    let (_, tau) = reflector(&mut x);
    x[0] = 1.0;
    x.reverse();
    (x, tau)
}

/// A <- H A H, b <- H b for H = I - τ u u^T.
fn reflect(s: &mut Siso, u: &[f64], tau: f64) {
    // The order a constant of the loops for the orders of flight models.
    with_order!(
        u.len(),
        [1, 2, 3, 4, 5, 6, 7, 8],
        N => reflect_of_order(s, u, tau, N),
        n => reflect_of_order(s, u, tau, n)
    )
}

/// [`reflect`] for a system of order n (A's column-major storage indexed directly; the same
/// products and sums in the same order).
#[inline(always)]
fn reflect_of_order(s: &mut Siso, u: &[f64], tau: f64, n: usize) {
    let (a, u) = (&mut s.a.as_mut_slice()[..n * n], &u[..n]);
    for j in 0..n {
        let column = &mut a[j * n..(j + 1) * n];
        let dot: f64 = (0..n).map(|i| u[i] * column[i]).sum();
        for (x, ui) in column.iter_mut().zip(u) {
            *x -= tau * dot * ui;
        }
    }
    for i in 0..n {
        let dot: f64 = (0..n).map(|j| a[i + j * n] * u[j]).sum();
        for (j, uj) in u.iter().enumerate() {
            a[i + j * n] -= tau * dot * uj;
        }
    }
    let dot: f64 = u.iter().zip(&s.b).map(|(x, y)| x * y).sum();
    for (bi, ui) in s.b.iter_mut().zip(u) {
        *bi -= tau * dot * ui;
    }
}

/// Emami-Naeini and Van Dooren's reduction for one output (see the module's documentation).
fn reduce(mut s: Siso, tol: f64) -> Reduced {
    loop {
        match above(s.d.abs(), tol) {
            None => return Reduced::Ambiguous,
            Some(true) => return Reduced::Regular(s),
            Some(false) => {}
        }
        let n = s.a.nrows();
        if n == 0 {
            return Reduced::Zero;
        }
        let norm = s.c.iter().map(|v| v * v).sum::<f64>().sqrt();
        match above(norm, tol) {
            None => return Reduced::Ambiguous,
            Some(false) => return Reduced::Zero,
            Some(true) => {}
        }
        let (u, tau) = output_reflector(&s.c);
        reflect(&mut s, &u, tau);
        let m = n - 1;
        for (j, cj) in s.c.iter_mut().enumerate().take(m) {
            *cj = s.a[(m, j)];
        }
        s.c.truncate(m);
        s.d = s.b[m];
        s.b.truncate(m);
        s.a = DMatrix::from_fn(m, m, |i, j| s.a[(i, j)]);
    }
}

/// The finite zeros of a reduced system (|d| > tol), or None when ||[c d]|| > 2^10 |d|.
fn regular_zeros(s: &Siso) -> Result<Option<Vec<c64>>, Error> {
    let n = s.a.nrows();
    if n == 0 {
        return Ok(Some(Vec::new()));
    }
    let norm = (s.c.iter().map(|v| v * v).sum::<f64>() + s.d * s.d).sqrt();
    if norm <= 16.0 * s.d.abs() {
        let m = Mat::from_fn(n, n, |i, j| s.a[(i, j)] - s.b[i] * (s.c[j] / s.d));
        return Ok(Some(eigenvalues(m.as_ref())?));
    }
    if norm > 1024.0 * s.d.abs() {
        return Ok(None);
    }
    // [c d] W = [0, β]: W = I - τ u u^T with u_{N+1} = 1.
    let row: Vec<f64> = s.c.iter().copied().chain(std::iter::once(s.d)).collect();
    let (u, tau) = output_reflector(&row);
    let w = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 } - tau * u[i] * u[j];
    let af = Mat::from_fn(n, n, |i, j| {
        (0..n).map(|k| s.a[(i, k)] * w(k, j)).sum::<f64>() + s.b[i] * w(n, j)
    });
    let bf = Mat::from_fn(n, n, w);
    let schur = qz(af.as_ref(), bf.as_ref())?;
    let values = generalized_eigenvalues(schur.s.as_ref(), schur.t.as_ref());
    if values.iter().any(|v| v.beta == 0.0) {
        return Ok(None);
    }
    Ok(Some(values.into_iter().map(|v| v.value()).collect()))
}

/// The number of finite zeros the reduction of `s` as given leaves, None if ambiguous.
fn zero_count(s: Siso) -> Option<usize> {
    let n = s.a.nrows();
    let tol = ((n + 1) * (n + 1)) as f64 * f64::EPSILON * frobenius(&s).max(f64::MIN_POSITIVE);
    match reduce(s, tol) {
        Reduced::Regular(r) => Some(r.a.nrows()),
        Reduced::Zero => Some(0),
        Reduced::Ambiguous => None,
    }
}

// ----- one channel -----------------------------------------------------------------------------

/// The LU factorisation with partial pivoting (by |re| + |im|) of point I - A, row-major, in
/// buffers reused from point to point and channel to channel.
#[derive(Default)]
struct ShiftedLu {
    m: Vec<c64>,
    rows: Vec<usize>,
    x: Vec<c64>,
}

impl ShiftedLu {
    /// Factorises point I - A; false when a pivot vanishes (point is an eigenvalue of A to
    /// rounding).
    fn factor(&mut self, a: &DMatrix<f64>, point: c64) -> bool {
        let n = a.nrows();
        let (m, rows) = (&mut self.m, &mut self.rows);
        m.clear();
        m.resize(n * n, c64::new(0.0, 0.0));
        // Row-major from A's column-major storage; 0 - a_ij off the diagonal (as point - a_ij
        // with a point of 0: a_ij = 0 gives +0).
        let entries = a.as_slice();
        for (i, row) in m.chunks_exact_mut(n).enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = c64::new(0.0 - entries[i + j * n], 0.0);
            }
            row[i] = c64::new(point.re - entries[i + i * n], point.im);
        }
        rows.clear();
        rows.extend(0..n);
        // |re| + |im| is never negative (a NaN's sign is cleared too), so its bits are in the
        // order of f64::total_cmp: the last largest, as Iterator::max_by gives it.
        let size = |z: c64| (z.re.abs() + z.im.abs()).to_bits();
        for k in 0..n {
            let (mut pivot, mut largest) = (k, size(m[k * n + k]));
            for p in k + 1..n {
                let candidate = size(m[p * n + k]);
                if candidate >= largest {
                    (pivot, largest) = (p, candidate);
                }
            }
            if f64::from_bits(largest) == 0.0 {
                return false;
            }
            if pivot != k {
                let (upper, lower) = m.split_at_mut(pivot * n);
                upper[k * n..(k + 1) * n].swap_with_slice(&mut lower[..n]);
                rows.swap(k, pivot);
            }
            // Row i -= l_ik row k below the pivot, l_ik = m_ik / m_kk kept in place.
            let (top, below) = m.split_at_mut((k + 1) * n);
            let pivot_row = &top[k * n..];
            for row in below.chunks_exact_mut(n) {
                let l = quotient(row[k], pivot_row[k]);
                row[k] = l;
                for (x, &t) in row[k + 1..].iter_mut().zip(&pivot_row[k + 1..]) {
                    *x -= l * t;
                }
            }
        }
        true
    }

    /// c (point I - A)^-1 b + d, from the factors of [`ShiftedLu::factor`].
    fn response(&mut self, b: &[f64], c: &[f64], d: f64) -> c64 {
        let (m, x) = (&self.m, &mut self.x);
        let n = self.rows.len();
        x.clear();
        x.extend(self.rows.iter().map(|&r| c64::new(b[r], 0.0)));
        for i in 0..n {
            let row = &m[i * n..i * n + i];
            let mut total = x[i];
            for (&l, &t) in row.iter().zip(x.iter()) {
                total -= l * t;
            }
            x[i] = total;
        }
        for i in (0..n).rev() {
            let row = &m[i * n..(i + 1) * n];
            let mut total = x[i];
            for (&u, &t) in row[i + 1..].iter().zip(&x[i + 1..]) {
                total -= u * t;
            }
            x[i] = quotient(total, row[i]);
        }
        x.iter().zip(c).map(|(&xj, &cj)| xj * cj).sum::<c64>() + d
    }
}

/// [`ShiftedLu::factor`] and [`ShiftedLu::response`] for a system of order N at P points at
/// once: for each point the same operations on the same values in the same order (bit for bit),
/// on arrays on the stack, the loops of known length unrolled and without bounds checks, and
/// the points' eliminations interleaved step by step, so that their chains of dependent
/// divisions overlap. None for a point where a pivot vanishes (its lane runs on to the end on
/// the infinities or NaNs of the division by 0, never read), and for every point when the
/// system is not of order N (never at these call sites).
fn fixed_responses<const N: usize, const P: usize>(s: &Siso, points: [c64; P]) -> [Option<c64>; P] {
    // A's columns (column-major storage), b and c as arrays of order N.
    let (columns, rest) = s.a.as_slice().as_chunks::<N>();
    let (Ok(columns), true, Ok(b), Ok(c)) = (
        <&[[f64; N]; N]>::try_from(columns),
        rest.is_empty(),
        <&[f64; N]>::try_from(s.b.as_slice()),
        <&[f64; N]>::try_from(s.c.as_slice()),
    ) else {
        return [None; P];
    };
    // Row-major, 0 - a_ij off the diagonal, as in ShiftedLu::factor.
    let mut lanes = [[[c64::new(0.0, 0.0); N]; N]; P];
    for (m, point) in lanes.iter_mut().zip(points) {
        for (i, row) in m.iter_mut().enumerate() {
            for (x, column) in row.iter_mut().zip(columns) {
                *x = c64::new(0.0 - column[i], 0.0);
            }
            row[i] = c64::new(point.re - columns[i][i], point.im);
        }
    }
    let mut rows = [std::array::from_fn::<usize, N, _>(|i| i); P];
    let mut vanished = [false; P];
    let size = |z: c64| (z.re.abs() + z.im.abs()).to_bits();
    for k in 0..N {
        for ((m, rows), vanished) in lanes.iter_mut().zip(&mut rows).zip(&mut vanished) {
            let (mut pivot, mut largest) = (k, size(m[k][k]));
            // Index loops over constant ranges: unrolled, no bounds checks.
            #[allow(clippy::needless_range_loop)]
            for p in k + 1..N {
                let candidate = size(m[p][k]);
                if candidate >= largest {
                    (pivot, largest) = (p, candidate);
                }
            }
            *vanished |= f64::from_bits(largest) == 0.0;
            m.swap(k, pivot);
            rows.swap(k, pivot);
        }
        #[allow(clippy::needless_range_loop)]
        for i in k + 1..N {
            for m in &mut lanes {
                let pivot_row = m[k];
                let l = quotient(m[i][k], pivot_row[k]);
                m[i][k] = l;
                for j in k + 1..N {
                    m[i][j] -= l * pivot_row[j];
                }
            }
        }
    }
    let mut xs: [[c64; N]; P] =
        std::array::from_fn(|l| std::array::from_fn(|i| c64::new(b[rows[l][i]], 0.0)));
    for i in 0..N {
        for (x, m) in xs.iter_mut().zip(&lanes) {
            let mut total = x[i];
            for j in 0..i {
                total -= m[i][j] * x[j];
            }
            x[i] = total;
        }
    }
    for i in (0..N).rev() {
        for (x, m) in xs.iter_mut().zip(&lanes) {
            let mut total = x[i];
            for j in i + 1..N {
                total -= m[i][j] * x[j];
            }
            x[i] = quotient(total, m[i][i]);
        }
    }
    std::array::from_fn(|l| {
        (!vanished[l]).then(|| xs[l].iter().zip(c).map(|(&xj, &cj)| xj * cj).sum::<c64>() + s.d)
    })
}

/// G(point) = c (point I - A)^-1 b + d of a SISO system at each of `points`, None where a
/// pivot vanishes: by [`fixed_responses`] for orders 1 to 8, else by [`ShiftedLu`] point by
/// point (the same arithmetic).
fn responses<const P: usize>(s: &Siso, points: [c64; P], lu: &mut ShiftedLu) -> [Option<c64>; P] {
    with_order!(
        s.a.nrows(),
        [1, 2, 3, 4, 5, 6, 7, 8],
        N => fixed_responses::<N, P>(s, points),
        _ => points.map(|point| lu.factor(&s.a, point).then(|| lu.response(&s.b, &s.c, s.d)))
    )
}

/// log10 of the roots' finite, nonzero moduli, in their order.
fn log_moduli(roots: &[c64]) -> Vec<f64> {
    roots
        .iter()
        .map(|r| r.norm())
        .filter(|m| m.is_finite() && *m != 0.0)
        .map(f64::log10)
        .collect()
}

/// The mean of the zeros' and then the poles' log10 moduli ([`log_moduli`]; 0 without one):
/// the centre of the grid of evaluation points, as `transfer._evaluation_points` takes it.
fn log_centre(zero_logs: &[f64], pole_logs: &[f64]) -> f64 {
    let count = zero_logs.len() + pole_logs.len();
    if count == 0 {
        0.0
    } else {
        zero_logs.iter().chain(pole_logs).sum::<f64>() / count as f64
    }
}

/// 10^0.1 (the double `10f64.powf(0.1)` gives: a unit test checks), the ratio of neighbouring
/// frequencies of a continuous model's grid.
const GRID_STEP: f64 = 1.2589254117941673;

/// The number of points of a continuous model's grid (a discrete model's has 19).
const GRID_POINTS: usize = 31;

/// The points of a grid of `transfer._evaluation_points`, held on the stack, and for a
/// continuous model's grid (on the imaginary axis) their imaginary parts apart.
struct Grid {
    points: [c64; GRID_POINTS],
    heights: [f64; GRID_POINTS],
    len: usize,
    on_axis: bool,
}

impl Grid {
    fn points(&self) -> &[c64] {
        &self.points[..self.len]
    }
}

/// The grid of `transfer._evaluation_points`: s = jω at 31 frequencies
/// 10^(centre - 1.5 + k/10), or z = e^{jθ} at 19 angles of the unit circle for a discrete
/// model.
fn grid(dt: f64, centre: f64) -> Grid {
    let mut grid = Grid {
        points: [c64::new(0.0, 0.0); GRID_POINTS],
        heights: [0.0; GRID_POINTS],
        len: 0,
        on_axis: dt.is_nan() || dt <= 0.0,
    };
    if grid.on_axis {
        // One power, then steps of 10^0.1: any point of the grid serves (the gain does not
        // depend on it).
        let mut omega = 10f64.powf(centre - 1.5);
        for (point, height) in grid.points.iter_mut().zip(&mut grid.heights) {
            *height = omega.clamp(1e-300, 1e307);
            *point = c64::new(0.0, *height);
            omega *= GRID_STEP;
        }
        grid.len = GRID_POINTS;
    } else {
        for (k, point) in grid.points.iter_mut().take(19).enumerate() {
            let theta = (0.05 + 0.05 * k as f64) * std::f64::consts::PI;
            *point = c64::new(theta.cos(), theta.sin());
        }
        grid.len = 19;
    }
    grid
}

/// `nearest[k]` lowered to min |p_k - r|^2 over the roots r, for the points p_k of a grid.
/// Every point lies in the upper half-plane, where a root below the real axis is no nearer than
/// its conjugate, also after rounding (|Im p + b| >= |Im p - b| for b >= 0): such a root is
/// left out when its conjugate is one of `roots`, which leaves every minimum as it is (so the
/// minima over two sets of roots, each filtered so, are those over their union). The minimum
/// is exact, so it is taken root by root over every point at once (independent comparisons,
/// not one chain per point). On the imaginary axis (a continuous model's grid) the first term
/// of |jω - r|^2 = (0 - Re r)^2 + (ω - Im r)^2 is (Re r)^2 exactly, the same at every point,
/// and the second is taken from the heights ω alone.
fn lower_to_nearest(grid: &Grid, roots: &[c64], nearest: &mut [f64]) {
    for r in roots
        .iter()
        .filter(|r| r.im >= 0.0 || !roots.contains(&r.conj()))
    {
        // min(m, x) as a select: the same value (m is never NaN: it starts infinite and takes
        // only smaller values; a NaN x leaves it).
        if grid.on_axis {
            let real = r.re * r.re;
            for (m, &height) in nearest.iter_mut().zip(&grid.heights[..grid.len]) {
                let y = height - r.im;
                let x = real + y * y;
                *m = if x < *m { x } else { *m };
            }
        } else {
            for (m, p) in nearest.iter_mut().zip(grid.points()) {
                let x = (p - r).norm_sqr();
                *m = if x < *m { x } else { *m };
            }
        }
    }
}

/// The two points of a grid farthest from the roots by relative distance to the nearest,
/// min |p - r|^2 / |p|^2 (`nearest`: the numerators; no hypot, and one division, which as a
/// monotone rounding gives the same value as dividing each term), best first, ties in grid
/// order.
fn farthest_two(points: &[c64], nearest: &[f64]) -> (c64, c64) {
    let (mut first, mut second) = (
        (f64::NEG_INFINITY, points[0]),
        (f64::NEG_INFINITY, points[1]),
    );
    for (&p, &m) in points.iter().zip(nearest) {
        let value = m / p.norm_sqr();
        if value > first.0 {
            second = first;
            first = (value, p);
        } else if value > second.0 {
            second = (value, p);
        }
    }
    (first.1, second.1)
}

/// The two points of the grid ([`grid`]) farthest from the zeros and the poles (the poles'
/// minima `pole_nearest` over its points, None to take them here), best first; without roots,
/// the middle of the grid and the point after it.
fn best_points(
    grid: &Grid,
    zeros: &[c64],
    poles: &[c64],
    pole_nearest: Option<&[f64]>,
) -> (c64, c64) {
    let points = grid.points();
    if zeros.is_empty() && poles.is_empty() {
        let middle = points.len() / 2;
        return (points[middle], points[middle + 1]);
    }
    let mut minima = [f64::INFINITY; GRID_POINTS];
    let nearest = &mut minima[..points.len()];
    match pole_nearest {
        Some(pole_minima) => nearest.copy_from_slice(pole_minima),
        None => lower_to_nearest(grid, poles, nearest),
    }
    lower_to_nearest(grid, zeros, nearest);
    farthest_two(points, nearest)
}

/// What the channels of a model share: the sampling period (0: continuous), the poles by
/// modulus, their log10 moduli, and for a continuous model the check grid (around max|A|,
/// else around 1) with each point's minimum over the poles ([`lower_to_nearest`]).
struct Shared {
    dt: f64,
    sorted_poles: Vec<c64>,
    pole_logs: Vec<f64>,
    check: Option<(Grid, Vec<f64>)>,
}

impl Shared {
    fn of(a: MatRef<'_, f64>, dt: f64, poles: &[c64]) -> Self {
        let check = (dt.is_nan() || dt <= 0.0).then(|| {
            let size = max_abs(a);
            let points = grid(dt, if size > 0.0 { size.log10() } else { 0.0 });
            let mut nearest = vec![f64::INFINITY; points.len];
            lower_to_nearest(&points, poles, &mut nearest);
            (points, nearest)
        });
        Shared {
            dt,
            sorted_poles: by_modulus(poles),
            pole_logs: log_moduli(poles),
            check,
        }
    }
}

/// One channel (see the module's documentation), None when deferred.
fn channel(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    d: f64,
    poles: &[c64],
    shared: &Shared,
    lu: &mut ShiftedLu,
) -> Result<Option<Channel>, Error> {
    let n = a.nrows();
    let dt = shared.dt;
    let given = Siso::of(a, b, c, d);
    let in_range = |v: &f64| *v == 0.0 || (ENTRY_RANGE.0..=ENTRY_RANGE.1).contains(&v.abs());
    if !entries(&given).iter().all(|part| part.iter().all(in_range)) {
        return Ok(None);
    }
    let (s, frequency, units) = equilibrated(given);
    let (s, e) = unit_scaled(s);
    // Products of up to n + 1 entries must stay normal: no entry below 2^(-1000 / (n + 1)).
    let smallest = entries(&s)
        .iter()
        .flat_map(|part| part.iter())
        .filter(|v| **v != 0.0)
        .fold(f64::INFINITY, |m, v| m.min(v.abs()));
    if smallest < (-1000.0 / (n as f64 + 1.0)).exp2() {
        return Ok(None);
    }
    let tol = ((n + 1) * (n + 1)) as f64 * f64::EPSILON * frobenius(&s).max(f64::MIN_POSITIVE);
    let reduced = match reduce(s.clone(), tol) {
        Reduced::Ambiguous => return Ok(None),
        Reduced::Zero => {
            return Ok(Some(Channel {
                zeros: Vec::new(),
                zeros_by_modulus: Vec::new(),
                gain: 0.0,
                numerator: vec![0.0],
            }));
        }
        Reduced::Regular(r) => r,
    };
    let Some(mut zeros) = regular_zeros(&reduced)? else {
        return Ok(None);
    };
    // The reference adds the zeros of the unequilibrated pencil beyond the equilibrated one's
    // reach: there must be none. (With d = 0 exactly the unequilibrated pencil has at most
    // n - 1 zeros, so n - 1 here needs no second reduction.)
    let at_most = d == 0.0 && zeros.len() + 1 == n;
    if zeros.len() < n
        && !at_most
        && zero_count(Siso::of(a, b, c, d)).is_none_or(|k| k > zeros.len())
    {
        return Ok(None);
    }
    let scale = frequency + e;
    // |z| <= tol, without the hypot where a part exceeds tol (|z| >= either part, also rounded).
    let within_tol = |z: &c64| z.re.abs().max(z.im.abs()) <= tol && z.norm() <= tol;
    let at_origin = zeros.iter().any(within_tol) && singular_at_origin(a, b, c, d);
    for z in &mut zeros {
        if at_origin && within_tol(z) {
            *z = c64::new(0.0, 0.0);
        }
        *z = c64::new(ldexp_any(z.re, scale), ldexp_any(z.im, scale));
    }
    if zeros
        .iter()
        .any(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        return Ok(None);
    }
    let zeros = cleaned(zeros);
    let zeros_by_modulus = by_modulus(&zeros);
    let gain = if d != 0.0 && zeros.len() == n {
        d
    } else {
        // G(point) = 2^-(o + i) 2^e G_s(point 2^-(f + e)) on the equilibrated system.
        let centre = log_centre(&log_moduli(&zeros), &shared.pole_logs);
        let (first, next) = best_points(&grid(dt, centre), &zeros, poles, None);
        // The check point is the best of another grid (around max|A|, else around 1): the
        // next point of the same grid shares the first's rounding where the terms of
        // c (sI - A)^-1 b cancel. A discrete model's one grid is the unit circle.
        let check = match &shared.check {
            None => next,
            Some((points, pole_nearest)) => {
                let (best, after) = best_points(points, &zeros, poles, Some(pole_nearest));
                if best != first { best } else { after }
            }
        };
        // G at both points from the state space (their eliminations interleaved).
        let [g0, g1] = responses(
            &s,
            [first, check]
                .map(|point| c64::new(ldexp_any(point.re, -scale), ldexp_any(point.im, -scale))),
            lu,
        )
        .map(|value| {
            let value = value?;
            let part = value.re.abs().max(value.im.abs());
            (part.is_finite() && part >= f64::MIN_POSITIVE).then(|| Scaled::new(value, e - units))
        });
        let (sorted_zeros, sorted_poles) = (&zeros_by_modulus[..], &shared.sorted_poles[..]);
        let Some(g0) = g0 else {
            return Ok(None);
        };
        let k = factored(g0, first, sorted_poles, sorted_zeros).value().re;
        if !(k.is_finite() && k.abs() >= f64::MIN_POSITIVE) {
            return Ok(None);
        }
        // The check: G at the second point from the state space and from the factored form.
        let Some(g1) = g1 else {
            return Ok(None);
        };
        let start = Scaled::new(c64::new(k, 0.0), 0);
        let mut factored_value = factored(start, check, sorted_zeros, sorted_poles);
        factored_value.divided_by(g1);
        let ratio = factored_value.value();
        let agrees = (ratio - 1.0).norm() <= 1e-8; // false for NaN
        if !agrees {
            return Ok(None);
        }
        k
    };
    let Some(numerator) = polynomial(&zeros, gain) else {
        return Ok(None);
    };
    Ok(Some(Channel {
        zeros,
        zeros_by_modulus,
        gain,
        numerator,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_channel(a: &[&[f64]], b: &[f64], c: &[f64], d: f64) -> Option<Channel> {
        let n = b.len();
        let am = Mat::from_fn(n, n, |i, j| a[i][j]);
        let bm = Mat::from_fn(n, 1, |i, _| b[i]);
        let cm = Mat::from_fn(1, n, |_, j| c[j]);
        let dm = Mat::from_fn(1, 1, |_, _| d);
        let t = transfer_channels(
            am.as_ref(),
            bm.as_ref(),
            cm.as_ref(),
            dm.as_ref(),
            0.0,
            &[(0, 0)],
        )
        .unwrap();
        t.channels.into_iter().next().unwrap()
    }

    #[test]
    fn canonical_form_of_a_known_transfer_function() {
        // (s + 3)/((s + 1)(s + 2)) = (s + 3)/(s^2 + 3 s + 2): zero -3, gain 1.
        let g = one_channel(&[&[-3.0, -2.0], &[1.0, 0.0]], &[1.0, 0.0], &[1.0, 3.0], 0.0).unwrap();
        assert_eq!(g.zeros.len(), 1);
        assert!((g.zeros[0] - c64::new(-3.0, 0.0)).norm() <= 4.0 * f64::EPSILON * 3.0);
        assert!((g.gain - 1.0).abs() <= 4.0 * f64::EPSILON);
        assert!((g.numerator[1] - 3.0).abs() <= 16.0 * f64::EPSILON);
        // With a feedthrough 2: 2 + (s + 3)/(s^2 + 3 s + 2) = (2 s^2 + 7 s + 7)/(...), K = D.
        let g = one_channel(&[&[-3.0, -2.0], &[1.0, 0.0]], &[1.0, 0.0], &[1.0, 3.0], 2.0).unwrap();
        assert_eq!(g.gain, 2.0);
        let expected = [2.0, 7.0, 7.0];
        for (x, y) in g.numerator.iter().zip(expected) {
            assert!((x - y).abs() <= 32.0 * f64::EPSILON * y, "{x} vs {y}");
        }
    }

    #[test]
    fn the_origin_is_a_zero_only_where_the_system_matrix_is_singular_there() {
        // 1/(s + 1) + L/(s + L): the zero -2 L/(L + 1), far inside the rank tolerance of the
        // pencil scaled to L, but S0 equilibrated is [[-1, 0, 1], [0, -1, 1], [1, 1, 0]]-like.
        for large in [1.0, 1e5, 1e15, 1e100] {
            let a = faer::mat![[-1.0, 0.0], [0.0, -large]];
            assert!(!singular_at_origin(
                a.as_ref(),
                &[1.0, large],
                &[1.0, 1.0],
                0.0
            ));
        }
        // A washout s/(s + 1) = 1 - 1/(s + 1), at any scale of its state: S0 singular.
        for scale in [1.0, 1e-100, 1e100] {
            let a = faer::mat![[-1.0]];
            assert!(singular_at_origin(
                a.as_ref(),
                &[scale],
                &[-1.0 / scale],
                1.0
            ));
        }
    }

    /// [`complete_pivots`] of a matrix.
    fn pivots_of(mut m: DMatrix<f64>) -> Vec<f64> {
        let mut pivots = vec![f64::INFINITY; m.nrows()];
        complete_pivots(m.as_mut_slice(), &mut pivots);
        pivots
    }

    #[test]
    fn complete_pivots_of_known_matrices() {
        // [[1, 2], [3, 4]]: pivot 4, then 1 - 2·3/4 = ... with rows and columns swapped:
        // [[4, 3], [2, 1]] -> 1 - (2/4)·3 = -0.5; |det| = 4 · 0.5 = 2.
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(pivots_of(m), vec![4.0, 0.5]);
        // A rank-one matrix: the second pivot is 0 to rounding, a zero matrix all 0.
        let m = DMatrix::from_fn(3, 3, |i, j| (i + 1) as f64 * (j + 2) as f64);
        let pivots = pivots_of(m);
        assert_eq!(pivots[0], 12.0);
        assert!(pivots[1] <= 4.0 * f64::EPSILON * 12.0 && pivots[2] <= 4.0 * f64::EPSILON * 12.0);
        assert_eq!(pivots_of(DMatrix::zeros(2, 2)), vec![0.0, 0.0]);
        // The product of the pivots is |det| (a permuted triangular factorisation).
        let m = DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.5, 0.25, 3.0, 1.0, -1.5, 0.75, 4.0]);
        let det: f64 =
            2.0 * (3.0 * 4.0 - 0.75) + 1.0 * (0.25 * 4.0 + 1.5) + 0.5 * (0.25 * 0.75 + 4.5);
        let product: f64 = pivots_of(m).iter().product();
        assert!(
            (product - det.abs()).abs() <= 16.0 * f64::EPSILON * det.abs(),
            "{product} {det}"
        );
    }

    /// Gaussian elimination with complete pivoting as written out in full (every row and
    /// column swapped whole, a NaN taken as the pivot where it is met): the oracle of
    /// [`complete_pivots`], which swaps and eliminates only the trailing block.
    fn complete_pivots_in_full(mut m: DMatrix<f64>) -> Vec<f64> {
        let size = m.nrows();
        let mut pivots = Vec::new();
        for k in 0..size {
            let (mut row, mut col, mut largest) = (k, k, -1.0f64);
            for j in k..size {
                for i in k..size {
                    let x = m[(i, j)].abs();
                    if x > largest || x.is_nan() {
                        (row, col, largest) = (i, j, x);
                    }
                }
            }
            if largest.is_nan() || largest == 0.0 {
                pivots.push(largest);
                pivots.resize(size, 0.0);
                break;
            }
            m.swap_rows(k, row);
            m.swap_columns(k, col);
            let pivot = m[(k, k)];
            pivots.push(pivot.abs());
            for i in k + 1..size {
                let l = m[(i, k)] / pivot;
                for j in k + 1..size {
                    m[(i, j)] -= l * m[(k, j)];
                }
            }
        }
        pivots
    }

    #[test]
    fn complete_pivots_equal_the_full_elimination_bit_for_bit() {
        // Seeded matrices of orders 1-13: plain, with zero rows and columns, rank-deficient
        // (a repeated column), graded over 2^±200, and with a NaN or an infinity.
        let mut count = 0;
        for seed in 1..=600u64 {
            let size = 1 + (seed % 13) as usize;
            let mut next = crate::test_matrices::xorshift(seed.wrapping_mul(0x9E37_79B9) | 1);
            let mut m = DMatrix::from_fn(size, size, |_, _| next());
            match seed % 6 {
                1 => m.row_mut((seed as usize / 6) % size).fill(0.0),
                2 if size > 1 => {
                    let first = m.column(0).clone_owned();
                    m.set_column(size - 1, &first);
                }
                3 => {
                    for ((i, j), x) in (0..size)
                        .flat_map(|j| (0..size).map(move |i| (i, j)))
                        .zip(m.iter_mut())
                    {
                        *x *= 2f64.powi(((i * 37 + j * 11) % 401) as i32 - 200);
                    }
                }
                4 => m[((seed as usize) % size, (seed as usize / 7) % size)] = f64::NAN,
                5 => m[((seed as usize / 3) % size, 0)] = f64::INFINITY,
                _ => {}
            }
            let (fast, full) = (pivots_of(m.clone()), complete_pivots_in_full(m));
            assert_eq!(fast.len(), full.len());
            for (x, y) in fast.iter().zip(&full) {
                assert!(
                    x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()),
                    "{seed}"
                );
            }
            count += 1;
        }
        assert_eq!(count, 600);
    }

    #[test]
    fn renormalization_is_the_rule_as_written() {
        // The bit test of Scaled::renormalize against "rescale where 0 < part < inf lies outside
        // the range", at the range's ends and their neighbours, 0, subnormals, infinities and
        // NaN, in either part and both signs.
        let (low, high) = MANTISSA_RANGE;
        let step =
            |x: f64, up: bool| f64::from_bits(if up { x.to_bits() + 1 } else { x.to_bits() - 1 });
        let values = [
            0.0,
            5e-324,
            f64::MIN_POSITIVE,
            step(low, false),
            low,
            step(low, true),
            1e-30,
            0.75,
            1e30,
            step(high, false),
            high,
            step(high, true),
            f64::MAX,
            f64::INFINITY,
            f64::NAN,
        ];
        for &re in &values {
            for &im in &values {
                for (sr, si) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
                    let m = c64::new(sr * re, si * im);
                    let mut fast = Scaled { m, e: 3 };
                    fast.renormalize();
                    let mut rule = Scaled { m, e: 3 };
                    let part = m.re.abs().max(m.im.abs());
                    if part > 0.0 && part.is_finite() && !(low..=high).contains(&part) {
                        rule.rescale(part);
                    }
                    let same =
                        |x: f64, y: f64| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan());
                    assert!(
                        same(fast.m.re, rule.m.re)
                            && same(fast.m.im, rule.m.im)
                            && fast.e == rule.e,
                        "{m:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn fixed_order_responses_equal_the_general_lu_bit_for_bit() {
        // Seeded systems of orders 1-8 (plain, graded over 2^±60, sparse, diagonal with the
        // point at an eigenvalue: a zero pivot; a NaN or an infinity in A), each at points on
        // the axis, off it and at 0: responses (fixed_responses at these orders, one point
        // alone or two at once) and ShiftedLu agree bit for bit, None together.
        let mut lu = ShiftedLu::default();
        let (mut count, mut vanished) = (0, 0);
        for seed in 1..=1600u64 {
            let n = 1 + (seed % 8) as usize;
            let mut next = crate::test_matrices::xorshift(seed.wrapping_mul(0x9E37_79B9) | 1);
            let mut a = DMatrix::from_fn(n, n, |_, _| next());
            let b: Vec<f64> = (0..n).map(|_| next()).collect();
            let c: Vec<f64> = (0..n).map(|_| next()).collect();
            let mut points = vec![
                c64::new(0.0, next().abs() + 0.1),
                c64::new(next(), next()),
                c64::new(0.0, 0.0),
            ];
            match (seed / 8) % 6 {
                1 => {
                    for j in 0..n {
                        for i in 0..n {
                            a[(i, j)] *= 2f64.powi(((i * 37 + j * 11) % 121) as i32 - 60);
                        }
                    }
                }
                2 => a.iter_mut().step_by(3).for_each(|x| *x = 0.0),
                3 => {
                    a.fill_lower_triangle(0.0, 1);
                    a.fill_upper_triangle(0.0, 1);
                    points.push(c64::new(a[(n - 1, n - 1)], 0.0));
                }
                4 => a[((seed as usize) % n, (seed as usize / 5) % n)] = f64::NAN,
                5 => a[((seed as usize / 3) % n, 0)] = f64::INFINITY,
                _ => {}
            }
            let s = Siso { a, b, c, d: next() };
            for (q, &point) in points.iter().enumerate() {
                let general = lu.factor(&s.a, point).then(|| lu.response(&s.b, &s.c, s.d));
                // Alone, and as either lane beside another point (its pivots, a vanishing
                // one included, its own).
                let other = points[(q + 1) % points.len()];
                let [first, _] = responses(&s, [point, other], &mut lu);
                let [_, second] = responses(&s, [other, point], &mut lu);
                for fixed in [responses(&s, [point], &mut lu)[0], first, second] {
                    match (general, fixed) {
                        (None, None) => vanished += 1,
                        (Some(x), Some(y)) => {
                            // (A NaN's payload is not compared.)
                            let same = |u: f64, v: f64| {
                                u.to_bits() == v.to_bits() || u.is_nan() && v.is_nan()
                            };
                            assert!(same(x.re, y.re) && same(x.im, y.im), "{seed} {x} {y}");
                        }
                        _ => panic!("{seed}: {general:?} {fixed:?}"),
                    }
                    count += 1;
                }
            }
        }
        assert!(count > 14400 && vanished > 0, "{count} {vanished}");
    }

    #[test]
    fn powers_of_two_scale_as_ldexp_any() {
        let values = [
            0.0,
            -0.0,
            5e-324,
            -3e-310,
            f64::MIN_POSITIVE,
            0.3,
            -1.5,
            1e300,
            f64::MAX,
        ];
        for e in [-1100, -1074, -1023, -1022, -5, 0, 7, 1023, 1024, 1100] {
            let mut scaled = values;
            scale_by_power_of_two(scaled.iter_mut(), e);
            for (x, y) in values.iter().zip(scaled) {
                assert_eq!(ldexp_any(*x, e).to_bits(), y.to_bits(), "{x} {e}");
            }
        }
    }

    #[test]
    fn best_points_split_between_zeros_and_poles() {
        // The poles' minima taken once (as for the shared check grid) and the zeros' added give
        // the points of the minimum over every root, conjugates below the axis included.
        let poles = [
            c64::new(-0.5, 0.0),
            c64::new(-0.03, -0.9),
            c64::new(-0.03, 0.9),
            c64::new(-2.0, 0.0),
        ];
        let zeros = [c64::new(0.1, -0.4), c64::new(0.1, 0.4), c64::new(0.0, 0.0)];
        for (dt, centre) in [(0.0, -1.0), (0.0, 0.0), (0.0, 0.3), (0.1, 0.0)] {
            let g = grid(dt, centre);
            let points = g.points();
            assert_eq!(g.on_axis, points.iter().all(|p| p.re == 0.0));
            let mut pole_nearest = vec![f64::INFINITY; points.len()];
            lower_to_nearest(&g, &poles, &mut pole_nearest);
            let split = best_points(&g, &zeros, &poles, Some(&pole_nearest));
            assert_eq!(split, best_points(&g, &zeros, &poles, None));
            let all: Vec<f64> = points
                .iter()
                .map(|p| {
                    zeros
                        .iter()
                        .chain(&poles)
                        .map(|r| (p - r).norm_sqr())
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            assert_eq!(split, farthest_two(points, &all));
            // The first is a point of the grid no nearer to a root than any other.
            let value = |q: c64| all[points.iter().position(|p| *p == q).unwrap()] / q.norm_sqr();
            assert!(points.iter().all(|p| value(*p) <= value(split.0)));
        }
        // Without roots: the middle of the grid and the point after it.
        let g = grid(0.0, 0.0);
        assert_eq!(
            best_points(&g, &[], &[], None),
            (g.points[15], g.points[16])
        );
    }

    #[test]
    fn zero_channel_and_deferred_channel() {
        // The output does not see the input: G = 0.
        let g = one_channel(&[&[-1.0, 0.0], &[0.0, -2.0]], &[1.0, 0.0], &[0.0, 1.0], 0.0).unwrap();
        assert_eq!(
            (g.gain, g.zeros.len(), g.numerator.clone()),
            (0.0, 0, vec![0.0])
        );
        // An entry beyond 2^250 is left to the reference path.
        assert!(one_channel(&[&[-1.0]], &[1e300], &[1.0], 0.0).is_none());
    }

    #[test]
    fn powers_of_two_are_exact() {
        assert_eq!(exponent_of(1.0), 1);
        assert_eq!(exponent_of(0.75), 0);
        assert_eq!(exponent_of(f64::MIN_POSITIVE / 8.0), -1024);
        // Rounded once, to nearest even: 2^-1075 is a tie (to 0), 1.5 2^-1074 one to 2^-1073
        // (a double rounding through 2^-1022 would have given other values).
        assert_eq!(ldexp(0.5, -1074), 0.0);
        assert_eq!(ldexp(0.75, -1074), 5e-324);
        assert_eq!(ldexp(0.75, -1073), 1e-323);
        assert_eq!(ldexp(0.5, 1024), 8.98846567431158e307);
        assert_eq!(ldexp(0.5, 1025), f64::INFINITY);
        assert_eq!(GRID_STEP, 10f64.powf(0.1));
        for x in [1.0, -0.75, 3e-300, 1e300, 5e-324] {
            let (m, e) = mantissa_and_exponent(x);
            assert!(
                (0.5..1.0).contains(&m.abs()) && ldexp_any(m, e) == x,
                "{x}: {m} {e}"
            );
        }
        assert_eq!(mantissa_and_exponent(0.0), (0.0, 0));
    }

    #[test]
    fn estimated_exponents_equal_the_logarithms() {
        // half_exponent and the Osborne step's exponent from log2_estimate equal the rounded
        // logarithms, at seeded values over 2^±1000, at every power of two and its neighbours
        // (where the quotients lie at or next to halfway), and at subnormals, 0, inf and NaN.
        let exact_half = |x: f64| -((x.log2() / 2.0).round_ties_even() as i64);
        let exact_quarter =
            |col: f64, row: f64| ((col.log2() - row.log2()) / 4.0).round_ties_even() as i64;
        let mut values = vec![0.0, 5e-324, 1e-310, f64::INFINITY, f64::NAN, f64::MAX];
        for e in -1021..=1023 {
            let p = 2f64.powi(e);
            values.extend([p, p.next_up(), p.next_down(), 1.5 * p]);
        }
        let mut next = crate::test_matrices::xorshift(0x5EED);
        values.extend((0..20000).map(|_| 2f64.powf(next() * 1000.0)));
        for &x in &values {
            if x > 0.0 && x.is_finite() {
                assert_eq!(half_exponent(x), exact_half(x), "{x:e}");
            }
            for &y in values.iter().step_by(97) {
                let (Some(col), Some(row)) = ((x > 0.0).then_some(x), (y > 0.0).then_some(y))
                else {
                    continue;
                };
                if !(col.is_finite() && row.is_finite()) {
                    continue;
                }
                let estimated =
                    nearest_quotient(log2_estimate(col) - log2_estimate(row), 4.0, || {
                        col.log2() - row.log2()
                    });
                assert_eq!(estimated, exact_quarter(col, row), "{col:e} {row:e}");
            }
        }
    }

    #[test]
    fn factored_response_in_lanes_equals_point_by_point_bit_for_bit() {
        // Seeded roots (0-6 zeros, 0-8 poles) of moduli over 2^±400, points on the axis, off
        // it, at a root and beyond 1e300, in counts 0-11 (whole lanes and a remainder):
        // factored_response_sorted (LANES points at once) equals factored point by point.
        let mut checked = 0;
        for seed in 1..=600u64 {
            let mut next = crate::test_matrices::xorshift(seed.wrapping_mul(0x9E37_79B9) | 1);
            let root = |next: &mut dyn FnMut() -> f64| {
                let scale = 2f64.powi((next() * 400.0) as i32);
                c64::new(next() * scale, next() * scale)
            };
            let zeros = by_modulus(&(0..seed % 7).map(|_| root(&mut next)).collect::<Vec<_>>());
            let poles = by_modulus(&(0..seed % 9).map(|_| root(&mut next)).collect::<Vec<_>>());
            let mut points: Vec<c64> = (0..seed % 12).map(|_| root(&mut next)).collect();
            if let (Some(p), Some(&r)) = (points.first_mut(), poles.first()) {
                *p = r;
            }
            if seed % 5 == 0 && points.len() > 1 {
                points[1] = c64::new(0.0, 1.5e308);
            }
            let (mantissa, exponent) = mantissa_and_exponent(next() + 2.0);
            let mut out = vec![c64::new(0.0, 0.0); points.len()];
            factored_response_sorted(mantissa, exponent, &zeros, &poles, &points, &mut out);
            let start = Scaled::new(c64::new(mantissa, 0.0), exponent);
            for (&point, value) in points.iter().zip(&out) {
                let alone = factored(start, point, &zeros, &poles).value();
                let same = |u: f64, v: f64| u.to_bits() == v.to_bits() || u.is_nan() && v.is_nan();
                assert!(
                    same(alone.re, value.re) && same(alone.im, value.im),
                    "{seed}"
                );
                checked += 1;
            }
        }
        assert!(checked > 3000, "{checked}");
    }

    #[test]
    fn factored_response_beyond_the_doubles() {
        // (s - 1e200)/(s - 2e200) at 0 is 1/2, though both products overflow in doubles
        // squared: K = 1e300 (as 2^997 m) times 1/2.
        let (m, e) = (1e300 / 2f64.powi(997), 997);
        let mut out = [c64::new(0.0, 0.0); 2];
        factored_response(
            m,
            e,
            &[c64::new(1e200, 0.0)],
            &[c64::new(2e200, 0.0)],
            &[c64::new(0.0, 0.0), c64::new(2e200, 0.0)],
            &mut out,
        );
        assert!((out[0].re - 0.5e300).abs() <= 4.0 * f64::EPSILON * 0.5e300);
        assert!(!out[1].re.is_finite()); // at the pole
    }
}
