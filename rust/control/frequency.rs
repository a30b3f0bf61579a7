//! Frequency response G(jω) = C (jωI - A)^-1 B + D at many frequencies (chapter §6.3).
//!
//! One Hessenberg reduction A = Q H Q^T (`hessenberg.rs`) turns every shifted solve into a
//! Hessenberg one:
//!
//! ```text
//! G(jω) = (C Q) (jωI - H)^-1 (Q^T B) + D,
//! ```
//!
//! and jωI - H is reduced to upper triangular form by eliminating its subdiagonal one entry at
//! a time, with partial pivoting between the two rows involved (the only rows with an entry in
//! that column). Each frequency then costs O(n^2 + n^2 m + p n m) instead of the O(n^3) of a
//! dense solve. The elimination is backward stable for each frequency, as Gaussian elimination
//! with partial pivoting is. Frequencies run in parallel.
//!
//! Entries and frequencies of any magnitude: A, B and C are divided by the powers of two of
//! their largest entries (exact; the point s by A's, G - D multiplied back at the end), pivots
//! are chosen by |re| + |im| and complex divisions are Smith's (1962), so no square of an
//! entry is formed: G(jω) of 1 / (s - 0.1257) at ω = 1e155 is -1e-155j, not 0.
//!
//! A frequency at an eigenvalue of A on the imaginary axis (a pole of G) gives infinite or NaN
//! entries, never an error: the caller decides how to report them.
//!
//! Models of order [`PARTIAL_FRACTION_MIN_ORDER`] and more at many points are summed from their
//! partial-fraction form instead ([`crate::control::partial_fraction`]), at every point where
//! that form is trustworthy, to rounding of the Hessenberg solve's value.
//!
//! A discrete model x[k+1] = A x[k] + B η[k] sampled every h seconds has the frequency response
//! G(e^{jωh}) = C (e^{jωh} I - A)^-1 B + D ([`discrete_frequency_response_into`]): the same
//! kernel at the point z = cos ωh + j sin ωh of the unit circle instead of jω, periodic in ω
//! with period 2π/h (a pole on the unit circle gives infinite or NaN entries likewise).

use crate::control::partial_fraction::PartialFractions;
use crate::error::{
    Error, check_finite, check_finite_values, check_output_len, check_positive, check_rows,
    check_square,
};
use crate::linalg::balance::{range_scale, times_power_of_two};
use crate::linalg::hessenberg::{Hessenberg, hessenberg};
use crate::platform::dispatch::{fma_dispatch, multiply_add};
use crate::platform::parallel::ParallelContext;
use faer::{Mat, MatRef, c64};
use rayon::prelude::*;

/// 2^600: |s| / σ (σ the power of two A is divided by) beyond which G(s) is taken from its
/// expansion at infinity ([`HessenbergModel::far`]).
const FAR: f64 = 4.149515568880993e180;

/// Checks A (n x n), B (n x m), C (p x n) and D (p x m) of a state-space model.
pub fn check_state_space(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
) -> Result<(), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    let n = a.nrows();
    check_rows(b, "B", n, "A")?;
    check_finite(b, "B")?;
    if c.ncols() != n {
        return Err(Error::Mismatch {
            arg: "C",
            what: "as many columns as",
            expected: n,
            other: "A",
            got: c.ncols(),
        });
    }
    check_finite(c, "C")?;
    check_rows(d, "D", c.nrows(), "C")?;
    if d.ncols() != b.ncols() {
        return Err(Error::Mismatch {
            arg: "D",
            what: "as many columns as",
            expected: b.ncols(),
            other: "B",
            got: d.ncols(),
        });
    }
    check_finite(d, "D")
}

/// A / σ, B / β and C / γ, each divided by the power of two of its largest entry where that is
/// outside [2^-100, 2^100] ([`range_scale`], exact): C (sI - A)^-1 B = 2^`exponent`
/// C' (s/σ I - A')^-1 B', `exponent` = log2(γ β / σ).
pub(crate) struct RangeScaled {
    pub a: Mat<f64>,
    pub b: Mat<f64>,
    pub c: Mat<f64>,
    pub sigma: f64,
    pub exponent: f64,
}

impl RangeScaled {
    pub fn new(a: MatRef<'_, f64>, b: MatRef<'_, f64>, c: MatRef<'_, f64>) -> Self {
        let (sigma, beta, gamma) = (range_scale(a), range_scale(b), range_scale(c));
        let scaled =
            |x: MatRef<'_, f64>, s: f64| Mat::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)] / s);
        RangeScaled {
            a: scaled(a, sigma),
            b: scaled(b, beta),
            c: scaled(c, gamma),
            sigma,
            exponent: gamma.log2() + beta.log2() - sigma.log2(),
        }
    }
}

/// The model in Hessenberg coordinates, laid out for the per-frequency kernel: H row-major,
/// Q^T B column by column, C Q and D row-major.
struct HessenbergModel {
    n: usize,
    m: usize,
    p: usize,
    h: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    d: Vec<f64>,
    /// A / σ, B / β and C / γ are held (the point s is divided by σ): C (sI - A)^-1 B is
    /// multiplied by 2^`exponent` = γ β / σ.
    exponent: f64,
    /// σ, the power of two the point s is divided by.
    sigma: f64,
}

impl HessenbergModel {
    /// The model of a checked (A, B, C, D), scaled and reduced once.
    fn new(
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        c: MatRef<'_, f64>,
        d: MatRef<'_, f64>,
    ) -> Result<Self, Error> {
        let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
        let RangeScaled {
            a,
            b,
            c,
            sigma,
            exponent,
        } = RangeScaled::new(a, b, c);
        let Hessenberg { h, q } = hessenberg(a.as_ref())?;
        let (qb, cq) = (q.transpose() * &b, &c * &q);
        let row_major = |x: &Mat<f64>| -> Vec<f64> {
            (0..x.nrows())
                .flat_map(|i| (0..x.ncols()).map(move |j| x[(i, j)]))
                .collect()
        };
        Ok(HessenbergModel {
            n,
            m,
            p,
            h: row_major(&h),
            b: (0..m)
                .flat_map(|j| (0..n).map(move |i| (j, i)))
                .map(|(j, i)| qb[(i, j)])
                .collect(),
            c: row_major(&cq),
            d: row_major(&d.to_owned()),
            exponent,
            sigma,
        })
    }

    /// G at the point s: by the Hessenberg solve at s / σ, or where |s| / σ exceeds
    /// [`FAR`] by the leading term of G's expansion at infinity
    /// ([`HessenbergModel::far`]).
    fn evaluate(&self, point: c64, ws: &mut Workspace, g: &mut [c64]) {
        // |s| <= √2 max(|Re s|, |Im s|): the modulus (a hypot) is formed only near FAR.
        let largest = point.re.abs().max(point.im.abs());
        if largest > 0.5 * FAR * self.sigma && point.norm() / self.sigma > FAR {
            self.far(point, g);
        } else {
            let s = if self.sigma == 1.0 {
                point
            } else {
                point / self.sigma
            };
            if self.m == 1 && self.p == 1 && self.n <= SISO_ORDER {
                g[0] = evaluate_siso(self, s);
            } else {
                evaluate_frequency(self, s, ws, g);
            }
        }
    }

    /// G(s) far beyond A's scale, from its expansion at infinity
    ///
    /// ```text
    ///     G(s) = D + Σ_k C A^k B / s^(k+1) = D + (γ β / σ) Σ_k M_k t^(k+1),   t = σ / s,
    /// ```
    ///
    /// M_k = C' A'^k B' the Markov parameters of the scaled model (A' = A / σ, largest entry
    /// about 1 or at most 2^100). With |t| < 1 / [`FAR`] = 2^-600, each term is below the one
    /// before by n 2^100 |t| or less, so each entry of G - D is its first nonzero term to
    /// rounding (none among the first n: G = D there, by Cayley-Hamilton). Solving at s / σ
    /// instead overflowed s / σ for |s| beyond σ 2^1024 (G = D returned), or took the
    /// solution B' / (s / σ) below the normal doubles (G = 0 for -1.26e-201j).
    /// t^(k+1) is formed as 2^((e_σ - E)(k+1)) / v^(k+1) with s = 2^E v, 1 <= |v| < 2, and the
    /// power of two applied last (exactly), so that no intermediate leaves the doubles.
    fn far(&self, point: c64, g: &mut [c64]) {
        let (n, m, p) = (self.n, self.m, self.p);
        let e = point.norm().log2().floor();
        let v = c64::new(
            times_power_of_two(point.re, -e),
            times_power_of_two(point.im, -e),
        );
        let step = self.sigma.log2() - e;
        let inverse = c64::new(1.0, 0.0) / v;
        for (g, &d) in g.iter_mut().zip(&self.d) {
            *g = c64::new(d, 0.0);
        }
        let mut pending = vec![true; p * m];
        // V = H^k (Q^T B') column by column; M_k = (C' Q) V.
        let mut columns = self.b.clone();
        let mut power = inverse;
        for k in 0..n {
            for column in 0..m {
                let x = &columns[column * n..(column + 1) * n];
                for i in 0..p {
                    let entry = i * m + column;
                    if !pending[entry] {
                        continue;
                    }
                    let markov: f64 = self.c[i * n..(i + 1) * n]
                        .iter()
                        .zip(x)
                        .map(|(c, x)| c * x)
                        .sum();
                    if markov != 0.0 {
                        let term = power * markov;
                        let scale = self.exponent + step * (k + 1) as f64;
                        g[entry] += c64::new(
                            times_power_of_two(term.re, scale),
                            times_power_of_two(term.im, scale),
                        );
                        pending[entry] = false;
                    }
                }
            }
            if !pending.contains(&true) {
                break;
            }
            power *= inverse;
            for column in 0..m {
                let x = columns[column * n..(column + 1) * n].to_vec();
                for i in 0..n {
                    let row = &self.h[i * n..(i + 1) * n];
                    columns[column * n + i] = row[i.saturating_sub(1)..]
                        .iter()
                        .zip(&x[i.saturating_sub(1)..])
                        .map(|(h, x)| h * x)
                        .sum();
                }
            }
        }
    }

    /// Scratch for one evaluation at a time.
    fn workspace(&self) -> Workspace {
        let (n, m) = (self.n, self.m);
        Workspace {
            re: vec![0.0; n * n],
            im: vec![0.0; n * n],
            x_re: vec![0.0; n * m],
            x_im: vec![0.0; n * m],
        }
    }
}

/// G(s) of one model at many points one at a time (a root finder's evaluations): the
/// Hessenberg reduction is made once, each point costs O(n^2 m + p n m).
pub struct FrequencyEvaluator {
    model: HessenbergModel,
    workspace: Workspace,
    g: Vec<c64>,
}

impl FrequencyEvaluator {
    /// Checks and reduces (A, B, C, D) once.
    pub fn new(
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        c: MatRef<'_, f64>,
        d: MatRef<'_, f64>,
    ) -> Result<Self, Error> {
        check_state_space(a, b, c, d)?;
        let model = HessenbergModel::new(a, b, c, d)?;
        let workspace = model.workspace();
        let g = vec![c64::new(0.0, 0.0); model.p * model.m];
        Ok(Self {
            model,
            workspace,
            g,
        })
    }

    /// G(s) (p x m, row-major) at the complex point s: infinite or NaN entries at a pole.
    pub fn at(&mut self, point: c64) -> &[c64] {
        self.model.evaluate(point, &mut self.workspace, &mut self.g);
        &self.g
    }

    /// The (0, 0) entry of G(jω): the loop L(jω) of a SISO model.
    pub fn siso(&mut self, omega: f64) -> c64 {
        self.at(c64::new(0.0, omega))[0]
    }

    /// [L(jω), dL/dω, d²L/dω², d³L/dω³] of a SISO model of order at most [`SISO_ORDER`] (L
    /// the value [`FrequencyEvaluator::siso`] gives, bit for bit; the derivatives from three
    /// more solves with the same elimination: dL/dω = j G'(jω), d²L/dω² = -G''(jω),
    /// d³L/dω³ = -j G'''(jω)), or None for another model or where |ω| is within a factor of
    /// two of the expansion at infinity's range.
    pub fn siso_derivatives(&mut self, omega: f64) -> Option<[c64; 4]> {
        let model = &self.model;
        if model.m != 1 || model.p != 1 || model.n > SISO_ORDER {
            return None;
        }
        if omega.abs() > 0.5 * FAR * model.sigma {
            return None;
        }
        let point = c64::new(0.0, omega);
        let s = if model.sigma == 1.0 {
            point
        } else {
            point / model.sigma
        };
        let [value, first, second, third] = evaluate_siso_derivatives(model, s);
        Some([
            value,
            c64::new(-first.im, first.re),
            -second,
            c64::new(third.im, -third.re),
        ])
    }
}

/// (a + jb) / (c + jd) by Smith's algorithm (Smith 1962): the ratio of the smaller to the
/// larger part of the divisor scales it, so that no square is formed and nothing overflows
/// or underflows unless the quotient does.
#[inline(always)]
fn complex_divide(a: f64, b: f64, c: f64, d: f64) -> (f64, f64) {
    if d.abs() <= c.abs() {
        let r = d / c;
        let denominator = c + d * r;
        ((a + b * r) / denominator, (b - a * r) / denominator)
    } else {
        let r = c / d;
        let denominator = c * r + d;
        ((a * r + b) / denominator, (b * r - a) / denominator)
    }
}

/// One frequency's scratch: the real and imaginary planes of the eliminated jωI - H
/// (row-major) and of the solution X (column by column), kept apart so that every inner loop
/// is a vectorisable pass over contiguous reals.
struct Workspace {
    re: Vec<f64>,
    im: Vec<f64>,
    x_re: Vec<f64>,
    x_im: Vec<f64>,
}

/// Σ u_i v_i for complex vectors given as real and imaginary planes, in four independent lanes
/// (a single running sum is a chain of dependent fused multiply-adds; lanes let the compiler
/// vectorise and overlap them).
#[inline(always)]
fn complex_dot<const FMA: bool>(ur: &[f64], ui: &[f64], vr: &[f64], vi: &[f64]) -> (f64, f64) {
    const LANES: usize = 4;
    let (mut re, mut im) = ([0.0; LANES], [0.0; LANES]);
    let chunks = ur.len() / LANES;
    for c in 0..chunks {
        let range = c * LANES..(c + 1) * LANES;
        let (ur, ui, vr, vi) = (
            &ur[range.clone()],
            &ui[range.clone()],
            &vr[range.clone()],
            &vi[range],
        );
        for l in 0..LANES {
            re[l] = multiply_add::<FMA>(ur[l], vr[l], multiply_add::<FMA>(-ui[l], vi[l], re[l]));
            im[l] = multiply_add::<FMA>(ur[l], vi[l], multiply_add::<FMA>(ui[l], vr[l], im[l]));
        }
    }
    let (mut sum_re, mut sum_im) = (
        (re[0] + re[1]) + (re[2] + re[3]),
        (im[0] + im[1]) + (im[2] + im[3]),
    );
    for i in chunks * LANES..ur.len() {
        sum_re = multiply_add::<FMA>(ur[i], vr[i], multiply_add::<FMA>(-ui[i], vi[i], sum_re));
        sum_im = multiply_add::<FMA>(ur[i], vi[i], multiply_add::<FMA>(ui[i], vr[i], sum_im));
    }
    (sum_re, sum_im)
}

/// G(s) into `g` (p x m row-major) at the complex point s (jω, or e^{jωh} for a discrete
/// model): fill sI - H, eliminate its subdiagonal with pivoting between the two rows
/// involved, back-substitute each right-hand side, and form C Q X + D.
#[inline(always)]
fn evaluate_kernel<const FMA: bool>(
    model: &HessenbergModel,
    point: c64,
    ws: &mut Workspace,
    g: &mut [c64],
) {
    let (n, m, p) = (model.n, model.m, model.p);
    let Workspace { re, im, x_re, x_im } = ws;
    // sI - H; entries left of the subdiagonal are never read. A zero real part (s = jω) is not
    // added, so that -h keeps its sign of zero.
    for i in 0..n {
        let start = i * n + i.saturating_sub(1);
        let end = (i + 1) * n;
        for (r, &h) in re[start..end].iter_mut().zip(&model.h[start..end]) {
            *r = -h;
        }
        if point.re != 0.0 {
            re[i * n + i] += point.re;
        }
        im[start..end].fill(0.0);
        im[i * n + i] = point.im;
    }
    x_re.copy_from_slice(&model.b);
    x_im.fill(0.0);
    for k in 0..n.saturating_sub(1) {
        let (this, next) = (k * n, (k + 1) * n);
        let magnitude = |row: usize, re: &[f64], im: &[f64]| re[row + k].abs() + im[row + k].abs();
        if magnitude(next, re, im) > magnitude(this, re, im) {
            for j in k..n {
                re.swap(this + j, next + j);
                im.swap(this + j, next + j);
            }
            for column in 0..m {
                x_re.swap(column * n + k, column * n + k + 1);
                x_im.swap(column * n + k, column * n + k + 1);
            }
        }
        let (pr, pi) = (re[this + k], im[this + k]);
        let (sr, si) = (re[next + k], im[next + k]);
        if sr == 0.0 && si == 0.0 {
            continue;
        }
        // factor = sub / pivot (the pivot is not zero: it is the larger of the two).
        let (fr, fi) = complex_divide(sr, si, pr, pi);
        let (upper_re, lower_re) = re.split_at_mut(next);
        let (upper_im, lower_im) = im.split_at_mut(next);
        let (row_re, row_im) = (&upper_re[this + k + 1..], &upper_im[this + k + 1..]);
        let (next_re, next_im) = (&mut lower_re[k + 1..n], &mut lower_im[k + 1..n]);
        for j in 0..n - k - 1 {
            let (a, b) = (row_re[j], row_im[j]);
            next_re[j] = multiply_add::<FMA>(-fr, a, multiply_add::<FMA>(fi, b, next_re[j]));
            next_im[j] = multiply_add::<FMA>(-fr, b, multiply_add::<FMA>(-fi, a, next_im[j]));
        }
        for column in 0..m {
            let (a, b) = (x_re[column * n + k], x_im[column * n + k]);
            let i = column * n + k + 1;
            x_re[i] -= fr * a - fi * b;
            x_im[i] -= fr * b + fi * a;
        }
    }
    // Back substitution, x_k = (b_k - U_k,k+1.. x_k+1..) / U_kk, row by row; every right-hand
    // side uses a row while it is in the fastest cache.
    for k in (0..n).rev() {
        let (row_re, row_im) = (
            &re[k * n + k + 1..(k + 1) * n],
            &im[k * n + k + 1..(k + 1) * n],
        );
        let (pr, pi) = (re[k * n + k], im[k * n + k]);
        for column in 0..m {
            let (xr, xi) = (
                &mut x_re[column * n..(column + 1) * n],
                &mut x_im[column * n..(column + 1) * n],
            );
            let (dr, di) = complex_dot::<FMA>(row_re, row_im, &xr[k + 1..], &xi[k + 1..]);
            let (sr, si) = (xr[k] - dr, xi[k] - di);
            (xr[k], xi[k]) = complex_divide(sr, si, pr, pi);
        }
    }
    // G = C Q X + D.
    for i in 0..p {
        let c_row = &model.c[i * n..(i + 1) * n];
        for column in 0..m {
            let (xr, xi) = (
                &x_re[column * n..(column + 1) * n],
                &x_im[column * n..(column + 1) * n],
            );
            let (mut gr, mut gi) = (0.0, 0.0);
            for ((&c, &vr), &vi) in c_row.iter().zip(xr).zip(xi) {
                gr = multiply_add::<FMA>(c, vr, gr);
                gi = multiply_add::<FMA>(c, vi, gi);
            }
            if model.exponent != 0.0 {
                gr = times_power_of_two(gr, model.exponent);
                gi = times_power_of_two(gi, model.exponent);
            }
            g[i * m + column] = c64::new(gr + model.d[i * m + column], gi);
        }
    }
}

/// The largest order [`evaluate_siso_kernel`] takes (its arrays live on the stack).
const SISO_ORDER: usize = 8;

/// [`evaluate_kernel`] for one input and one output of order at most [`SISO_ORDER`]: the same
/// operations in the same order (the same value, bit for bit), on stack arrays of row stride
/// [`SISO_ORDER`] instead of the workspace's vectors. A loop's margins evaluate L(jω) some sixty
/// times a call (root finders, peak searches), where the vectors' bounds checks and fills
/// cost as much as the arithmetic.
#[inline(always)]
fn evaluate_siso_kernel<const FMA: bool>(model: &HessenbergModel, point: c64) -> c64 {
    siso_solve::<FMA, false>(model, point)[0]
}

/// [`evaluate_siso_kernel`] with the first three derivatives: [G(s), G'(s), G''(s), G'''(s)],
/// G the same value bit for bit, G' = -C (sI - A)^-2 B, G'' = 2 C (sI - A)^-3 B and
/// G''' = -6 C (sI - A)^-4 B from three more solves with the same elimination (its
/// multipliers and row exchanges applied to the previous solution, then the back
/// substitution).
#[inline(always)]
fn evaluate_siso_derivatives_kernel<const FMA: bool>(
    model: &HessenbergModel,
    point: c64,
) -> [c64; 4] {
    siso_solve::<FMA, true>(model, point)
}

/// x_k = (x_k - U_k,k+1.. x_k+1..) / U_kk for k = n - 1 down to 0, U the eliminated sI - H
/// (rows of stride [`SISO_ORDER`]).
#[inline(always)]
fn siso_back_substitute<const FMA: bool>(
    re: &[f64; SISO_ORDER * SISO_ORDER],
    im: &[f64; SISO_ORDER * SISO_ORDER],
    n: usize,
    x_re: &mut [f64; SISO_ORDER],
    x_im: &mut [f64; SISO_ORDER],
) {
    const S: usize = SISO_ORDER;
    for k in (0..n).rev() {
        let row = k * S;
        let (dr, di) = complex_dot::<FMA>(
            &re[row + k + 1..row + n],
            &im[row + k + 1..row + n],
            &x_re[k + 1..n],
            &x_im[k + 1..n],
        );
        let (sr, si) = (x_re[k] - dr, x_im[k] - di);
        (x_re[k], x_im[k]) = complex_divide(sr, si, re[row + k], im[row + k]);
    }
}

/// c x multiplied back by 2^`exponent` (c of length n <= [`SISO_ORDER`]).
#[inline(always)]
fn siso_output<const FMA: bool>(
    c: &[f64],
    x_re: &[f64; SISO_ORDER],
    x_im: &[f64; SISO_ORDER],
    exponent: f64,
) -> c64 {
    let (mut gr, mut gi) = (0.0, 0.0);
    for ((&c, &vr), &vi) in c.iter().zip(x_re).zip(x_im) {
        gr = multiply_add::<FMA>(c, vr, gr);
        gi = multiply_add::<FMA>(c, vi, gi);
    }
    if exponent != 0.0 {
        gr = times_power_of_two(gr, exponent);
        gi = times_power_of_two(gi, exponent);
    }
    c64::new(gr, gi)
}

/// C (sI - H)^-1 B + D of a SISO model of order at most [`SISO_ORDER`], and with `DERIVATIVES`
/// its first three derivatives in s, (-1)^k k! C (sI - H)^-(k+1) B (else zeros), each
/// multiplied back by its power of two of the scaling.
#[inline(always)]
fn siso_solve<const FMA: bool, const DERIVATIVES: bool>(
    model: &HessenbergModel,
    point: c64,
) -> [c64; 4] {
    const S: usize = SISO_ORDER;
    let n = model.n.min(S);
    let mut re = [0.0f64; S * S];
    let mut im = [0.0f64; S * S];
    for i in 0..n {
        for j in i.saturating_sub(1)..n {
            re[i * S + j] = -model.h[i * n + j];
        }
        if point.re != 0.0 {
            re[i * S + i] += point.re;
        }
        im[i * S + i] = point.im;
    }
    let (mut x_re, mut x_im) = ([0.0f64; S], [0.0f64; S]);
    x_re[..n].copy_from_slice(&model.b[..n]);
    // The elimination's row exchanges and multipliers (zero where a step had nothing to
    // eliminate), kept for the derivatives' solves.
    let mut swapped = [false; S];
    let mut factors = [(0.0f64, 0.0f64); S];
    for k in 0..n.saturating_sub(1) {
        let (this, next) = (k * S, (k + 1) * S);
        if re[next + k].abs() + im[next + k].abs() > re[this + k].abs() + im[this + k].abs() {
            for j in k..n {
                re.swap(this + j, next + j);
                im.swap(this + j, next + j);
            }
            x_re.swap(k, k + 1);
            x_im.swap(k, k + 1);
            if DERIVATIVES {
                swapped[k] = true;
            }
        }
        let (pr, pi) = (re[this + k], im[this + k]);
        let (sr, si) = (re[next + k], im[next + k]);
        if sr == 0.0 && si == 0.0 {
            continue;
        }
        let (fr, fi) = complex_divide(sr, si, pr, pi);
        if DERIVATIVES {
            factors[k] = (fr, fi);
        }
        for j in k + 1..n {
            let (a, b) = (re[this + j], im[this + j]);
            re[next + j] = multiply_add::<FMA>(-fr, a, multiply_add::<FMA>(fi, b, re[next + j]));
            im[next + j] = multiply_add::<FMA>(-fr, b, multiply_add::<FMA>(-fi, a, im[next + j]));
        }
        let (a, b) = (x_re[k], x_im[k]);
        x_re[k + 1] -= fr * a - fi * b;
        x_im[k + 1] -= fr * b + fi * a;
    }
    siso_back_substitute::<FMA>(&re, &im, n, &mut x_re, &mut x_im);
    let value = siso_output::<FMA>(&model.c[..n], &x_re, &x_im, model.exponent);
    let mut out = [
        c64::new(value.re + model.d[0], value.im),
        c64::new(0.0, 0.0),
        c64::new(0.0, 0.0),
        c64::new(0.0, 0.0),
    ];
    if DERIVATIVES {
        // d^k/ds^k C (sI - A)^-1 B = (-1)^k k! C (sI - A)^-(k+1) B; the solves are at s / σ, so
        // the k-th term is divided by σ^k once more.
        let log_sigma = model.sigma.log2();
        for (order, coefficient) in [(1usize, -1.0f64), (2, 2.0), (3, -6.0)] {
            for k in 0..n.saturating_sub(1) {
                if swapped[k] {
                    x_re.swap(k, k + 1);
                    x_im.swap(k, k + 1);
                }
                let (fr, fi) = factors[k];
                if fr != 0.0 || fi != 0.0 {
                    let (a, b) = (x_re[k], x_im[k]);
                    x_re[k + 1] -= fr * a - fi * b;
                    x_im[k + 1] -= fr * b + fi * a;
                }
            }
            siso_back_substitute::<FMA>(&re, &im, n, &mut x_re, &mut x_im);
            let exponent = model.exponent - order as f64 * log_sigma;
            let term = siso_output::<FMA>(&model.c[..n], &x_re, &x_im, exponent);
            out[order] = term * coefficient;
        }
    }
    out
}

fma_dispatch!(fn evaluate_siso(model: &HessenbergModel, point: c64) -> c64 => evaluate_siso_kernel);

fma_dispatch!(fn evaluate_siso_derivatives(model: &HessenbergModel, point: c64) -> [c64; 4] => evaluate_siso_derivatives_kernel);

fma_dispatch!(fn evaluate_frequency(model: &HessenbergModel, point: c64, ws: &mut Workspace, g: &mut [c64]) => evaluate_kernel);

/// Writes G(jω_k) = C (jω_k I - A)^-1 B + D for every ω_k into `out`, a row-major
/// len(omega) x p x m stack.
pub fn frequency_response_into(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    omega: &[f64],
    out: &mut [c64],
) -> Result<(), Error> {
    transfer_function_into(a, b, c, d, omega, |w| c64::new(0.0, w), out)
}

/// Writes G(e^{jω_k dt}) = C (e^{jω_k dt} I - A)^-1 B + D for every ω_k into `out`, a
/// row-major len(omega) x p x m stack: the frequency response of the discrete model
/// x[k+1] = A x[k] + B η[k], y[k] = C x[k] + D η[k] sampled every `dt`.
pub fn discrete_frequency_response_into(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    omega: &[f64],
    dt: f64,
    out: &mut [c64],
) -> Result<(), Error> {
    check_positive(dt, "dt")?;
    check_finite_values(omega, "omega")?;
    if let Some(k) = omega.iter().position(|w| !(w * dt).is_finite()) {
        return Err(Error::InvalidValue {
            arg: "omega",
            value: omega[k],
            requirement: "small enough that omega dt is finite",
        });
    }
    transfer_function_into(
        a,
        b,
        c,
        d,
        omega,
        |w| {
            let (sine, cosine) = (w * dt).sin_cos();
            c64::new(cosine, sine)
        },
        out,
    )
}

/// G(s_k) = C (s_k I - A)^-1 B + D at the points s_k = point(ω_k), into `out`.
fn transfer_function_into(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    omega: &[f64],
    point: impl Fn(f64) -> c64 + Sync,
    out: &mut [c64],
) -> Result<(), Error> {
    check_state_space(a, b, c, d)?;
    check_finite_values(omega, "omega")?;
    let (m, p) = (b.ncols(), c.nrows());
    check_output_len(out.len(), omega.len() * p * m)?;
    if p * m == 0 {
        return Ok(());
    }
    // The evaluations multiply by their own kernels, not faer's.
    let context = ParallelContext::capture(0);
    let mut taken = vec![false; omega.len()];
    let form = if a.nrows() >= PARTIAL_FRACTION_MIN_ORDER && omega.len() >= 2 * a.nrows() {
        PartialFractions::new(a, b, c, d)
    } else {
        None
    };
    if let Some(form) = &form {
        omega
            .par_iter()
            .zip(out.par_chunks_mut(p * m))
            .zip(taken.par_iter_mut())
            .with_min_len(64)
            .try_for_each_init(
                || form.workspace(),
                |ws, ((&w, g), taken)| {
                    context.run(|| {
                        *taken = form.evaluate(point(w), ws, g);
                        Ok(())
                    })
                },
            )?;
        if taken.iter().all(|&t| t) {
            return Ok(());
        }
    }
    let model = HessenbergModel::new(a, b, c, d)?;
    let workspace = || model.workspace();
    omega
        .par_iter()
        .zip(out.par_chunks_mut(p * m))
        .zip(taken.par_iter())
        .with_min_len(32)
        .filter(|(_, taken)| !**taken)
        .try_for_each_init(workspace, |ws, ((&w, g), _)| {
            context.run(|| {
                model.evaluate(point(w), ws, g);
                Ok(())
            })
        })
}

/// Models of at least this order, at twice as many points as their order or more, are
/// evaluated by their partial-fraction form ([`PartialFractions`]) where it is trustworthy:
/// its set-up (an eigen-decomposition, about the cost of 2.5 n Hessenberg solves at n = 16
/// and 64) then costs less than the solves it saves, at a tenth of a solve a point.
pub const PARTIAL_FRACTION_MIN_ORDER: usize = 12;

/// G(jω) for every ω, as a vector of p x m complex matrices.
pub fn frequency_response(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
    omega: &[f64],
) -> Result<Vec<Mat<c64>>, Error> {
    let (p, m) = (c.nrows(), b.ncols());
    let mut out = vec![c64::new(0.0, 0.0); omega.len() * p * m];
    frequency_response_into(a, b, c, d, omega, &mut out)?;
    Ok((0..omega.len())
        .map(|k| Mat::from_fn(p, m, |i, j| out[k * p * m + i * m + j]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::Solve;
    use faer::mat;

    /// G(jω) by a dense complex solve, as the reference.
    fn dense(a: &Mat<f64>, b: &Mat<f64>, c: &Mat<f64>, d: &Mat<f64>, w: f64) -> Mat<c64> {
        let n = a.nrows();
        let shifted = Mat::from_fn(n, n, |i, j| {
            c64::new(-a[(i, j)], if i == j { w } else { 0.0 })
        });
        let rhs = Mat::from_fn(n, b.ncols(), |i, j| c64::new(b[(i, j)], 0.0));
        let x = shifted.partial_piv_lu().solve(&rhs);
        let cc = Mat::from_fn(c.nrows(), n, |i, j| c64::new(c[(i, j)], 0.0));
        let dd = Mat::from_fn(d.nrows(), d.ncols(), |i, j| c64::new(d[(i, j)], 0.0));
        cc * x + dd
    }

    #[test]
    fn siso_kernel_is_the_general_kernel_bit_for_bit() {
        // Seeded SISO models of orders 0 to SISO_ORDER, entries of several sizes, at points
        // on and off the axis (and near the poles' size): the stack kernel's value must be
        // the workspace kernel's, bit for bit, with and without fused multiply-adds.
        let mut next = crate::test_matrices::xorshift(0x2545f4914f6cdd1d);
        let mut compared = 0;
        for n in 0..=SISO_ORDER {
            for trial in 0..40 {
                let size = [1.0, 1e-3, 1e4][trial % 3];
                let a = Mat::from_fn(n, n, |_, _| next() * size);
                let b = Mat::from_fn(n, 1, |_, _| next());
                let c = Mat::from_fn(1, n, |_, _| next() * 7.0);
                let d = Mat::from_fn(1, 1, |_, _| if trial % 2 == 0 { next() } else { 0.0 });
                let model =
                    HessenbergModel::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
                let mut ws = model.workspace();
                let mut g = vec![c64::new(0.0, 0.0); 1];
                for k in 0..25 {
                    let w = size * (k as f64 / 4.0 - 2.0).exp2() * next().abs();
                    let re = if k % 5 == 0 { next() * size } else { 0.0 };
                    let point = c64::new(re, w);
                    for fma in [false, true] {
                        if fma && !crate::platform::dispatch::fma_available() {
                            continue;
                        }
                        if fma {
                            #[cfg(target_arch = "x86_64")]
                            {
                                #[target_feature(enable = "avx2,fma")]
                                fn both(
                                    model: &HessenbergModel,
                                    point: c64,
                                    ws: &mut Workspace,
                                    g: &mut [c64],
                                ) -> c64 {
                                    evaluate_kernel::<true>(model, point, ws, g);
                                    evaluate_siso_kernel::<true>(model, point)
                                }
                                // SAFETY: the CPU supports AVX2 and FMA, checked above.
                                let siso = unsafe { both(&model, point, &mut ws, &mut g) };
                                assert_eq!(siso.re.to_bits(), g[0].re.to_bits());
                                assert_eq!(siso.im.to_bits(), g[0].im.to_bits());
                            }
                        } else {
                            evaluate_kernel::<false>(&model, point, &mut ws, &mut g);
                            let siso = evaluate_siso_kernel::<false>(&model, point);
                            assert_eq!(siso.re.to_bits(), g[0].re.to_bits(), "n = {n}");
                            assert_eq!(siso.im.to_bits(), g[0].im.to_bits(), "n = {n}");
                        }
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared >= 9 * 40 * 25);
    }

    /// [L, dL/dω, d²L/dω², d³L/dω³] against dense complex solves, dL/dω = -j C (jωI - A)^-2 B,
    /// d²L/dω² = -2 C (jωI - A)^-3 B and d³L/dω³ = 6j C (jωI - A)^-4 B, on seeded SISO
    /// models of orders 1 to SISO_ORDER with entries of sizes 1e-3 to 1e4 and scaled by
    /// 2^±200 (the range scaling's powers of two applied to each term); L is the value `siso`
    /// gives, bit for bit. A model of another shape or order has no derivatives here.
    #[test]
    fn siso_derivatives_match_dense_solves() {
        let mut next = crate::test_matrices::xorshift(0x9e3779b97f4a7c15);
        let mut compared = 0;
        for n in 1..=SISO_ORDER {
            for trial in 0..24 {
                let size = [1.0, 1e-3, 1e4][trial % 3];
                let range = [1.0, 2f64.powi(200), 2f64.powi(-200)][(trial / 3) % 3];
                let a = Mat::from_fn(n, n, |_, _| next() * size * range);
                let b = Mat::from_fn(n, 1, |_, _| next());
                let c = Mat::from_fn(1, n, |_, _| next() * 7.0);
                let d = Mat::from_fn(1, 1, |_, _| next());
                let mut evaluator =
                    FrequencyEvaluator::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref())
                        .unwrap();
                for k in 0..6 {
                    let w = size * range * (k as f64 / 2.0 - 1.5).exp2() * (0.5 + next().abs());
                    let [value, first, second, third] = evaluator.siso_derivatives(w).unwrap();
                    let plain = evaluator.siso(w);
                    assert_eq!(value.re.to_bits(), plain.re.to_bits());
                    assert_eq!(value.im.to_bits(), plain.im.to_bits());
                    let shifted = Mat::from_fn(n, n, |i, j| {
                        c64::new(-a[(i, j)], if i == j { w } else { 0.0 })
                    });
                    let lu = shifted.partial_piv_lu();
                    let x1 = lu.solve(&Mat::from_fn(n, 1, |i, _| c64::new(b[(i, 0)], 0.0)));
                    let x2 = lu.solve(&x1);
                    let x3 = lu.solve(&x2);
                    let x4 = lu.solve(&x3);
                    let cx = |x: &Mat<c64>| {
                        (0..n).fold(c64::new(0.0, 0.0), |s, i| s + x[(i, 0)] * c[(0, i)])
                    };
                    let expected_first = cx(&x2) * c64::new(0.0, -1.0);
                    let expected_second = cx(&x3) * -2.0;
                    let expected_third = cx(&x4) * c64::new(0.0, 6.0);
                    // Relative to the terms' sizes: |C| |x_k| bounds the sums' cancellation.
                    let scale =
                        |x: &Mat<c64>| (0..n).map(|i| (x[(i, 0)] * c[(0, i)]).norm()).sum::<f64>();
                    let cond = 1e-10;
                    assert!(
                        (first - expected_first).norm() <= cond * scale(&x2),
                        "n={n} trial={trial}: {first} vs {expected_first}"
                    );
                    assert!(
                        (second - expected_second).norm() <= 2.0 * cond * scale(&x3),
                        "n={n} trial={trial}: {second} vs {expected_second}"
                    );
                    assert!(
                        (third - expected_third).norm() <= 6.0 * cond * scale(&x4),
                        "n={n} trial={trial}: {third} vs {expected_third}"
                    );
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, SISO_ORDER * 24 * 6);
        let (a, b, c, d) = (
            Mat::<f64>::identity(9, 9),
            Mat::<f64>::zeros(9, 1),
            Mat::<f64>::zeros(1, 9),
            Mat::<f64>::zeros(1, 1),
        );
        let mut large =
            FrequencyEvaluator::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
        assert!(large.siso_derivatives(1.0).is_none());
    }

    #[test]
    fn matches_a_dense_solve() {
        for n in [1usize, 2, 4, 9, 30] {
            let mut state = n as u64;
            let a = Mat::from_fn(n, n, |_, _| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            });
            let b = Mat::from_fn(n, 2, |i, j| (i + 3 * j) as f64 / n as f64 - 0.5);
            let c = Mat::from_fn(3, n, |i, j| ((i + j) % 4) as f64 - 1.5);
            let d = Mat::from_fn(3, 2, |i, j| (i as f64) - (j as f64));
            let omega = [0.0, 0.01, 0.7, 3.0, 100.0, -2.0];
            let g =
                frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &omega).unwrap();
            for (k, &w) in omega.iter().enumerate() {
                let expected = dense(&a, &b, &c, &d, w);
                let err = (&g[k] - &expected).norm_l2() / expected.norm_l2().max(1e-300);
                assert!(err < 1e-12, "n={n} w={w}: {err}");
            }
        }
    }

    #[test]
    fn first_order_lag() {
        // G(s) = 1 / (s + 2): |G(2j)| = 1 / (2 sqrt 2), phase -45 degrees.
        let g = frequency_response(
            mat![[-2.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            &[2.0],
        )
        .unwrap();
        let value = g[0][(0, 0)];
        assert!((value.norm() - 1.0 / 8f64.sqrt()).abs() < 1e-16);
        assert!((value.arg().to_degrees() + 45.0).abs() < 1e-13);
    }

    #[test]
    fn points_far_beyond_a_tiny_state_matrix() {
        // A = [[0, a], [-a, 0]] with a = 1e-200, B = b e_2, C = c e_1^T: G(s) = c a b / (s^2 + a^2)
        // (relative degree 2: C B = 0), -1e-100 at s = 1e100 j, where jω / σ overflows; and a
        // first-order 0.126 / (s - 1.26e-151) at ω = 1e200, -1.26e-201j, where it underflowed.
        let (a, b, c) = (1e-200, 1e150, 1e150);
        let g = frequency_response(
            mat![[0.0, a], [-a, 0.0]].as_ref(),
            mat![[0.0], [b]].as_ref(),
            mat![[c, 0.0]].as_ref(),
            mat![[0.0]].as_ref(),
            &[1e100],
        )
        .unwrap();
        let value = g[0][(0, 0)];
        assert!(
            (value.re + 1e-100).abs() <= 1e-15 * 1e-100 && value.im == 0.0,
            "{value}"
        );
        let (pole, gain) = (1.257302210933933e-151, 0.1257302210933933);
        let g = frequency_response(
            mat![[pole]].as_ref(),
            mat![[gain]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            &[1e200],
        )
        .unwrap();
        // b / (jω - a) = -b (a + jω) / (a^2 + ω^2): its real part, -b a / ω^2, underflows.
        let expected = c64::new(0.0, -gain / 1e200);
        assert!((g[0][(0, 0)] - expected).norm() <= 1e-15 * expected.norm());
    }

    #[test]
    fn discrete_response_is_taken_on_the_unit_circle() {
        // G(z) at z = e^{jωh} against a dense solve at that point, and the discrete first-order
        // lag 1 / (z - a) by hand.
        let n = 5;
        let mut state = 11u64;
        let a = Mat::from_fn(n, n, |_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        });
        let b = Mat::from_fn(n, 2, |i, j| (i + 2 * j) as f64 / n as f64 - 0.5);
        let c = Mat::from_fn(2, n, |i, j| ((i * j) % 3) as f64 - 1.0);
        let d = Mat::from_fn(2, 2, |i, j| (i + j) as f64);
        let h = 0.05;
        let omega = [0.0, 1.0, 30.0, std::f64::consts::PI / h, 200.0];
        let mut out = vec![c64::new(0.0, 0.0); omega.len() * 4];
        discrete_frequency_response_into(
            a.as_ref(),
            b.as_ref(),
            c.as_ref(),
            d.as_ref(),
            &omega,
            h,
            &mut out,
        )
        .unwrap();
        for (k, &w) in omega.iter().enumerate() {
            let z = c64::new((w * h).cos(), (w * h).sin());
            let shifted = Mat::from_fn(n, n, |i, j| {
                c64::new(
                    if i == j { z.re } else { 0.0 } - a[(i, j)],
                    if i == j { z.im } else { 0.0 },
                )
            });
            let rhs = Mat::from_fn(n, 2, |i, j| c64::new(b[(i, j)], 0.0));
            let x = shifted.partial_piv_lu().solve(&rhs);
            let cc = Mat::from_fn(2, n, |i, j| c64::new(c[(i, j)], 0.0));
            let dd = Mat::from_fn(2, 2, |i, j| c64::new(d[(i, j)], 0.0));
            let expected = cc * x + dd;
            let got = Mat::from_fn(2, 2, |i, j| out[k * 4 + i * 2 + j]);
            let err = (&got - &expected).norm_l2() / expected.norm_l2();
            assert!(err < 1e-13, "w={w}: {err}");
        }
        let mut lag = [c64::new(0.0, 0.0)];
        discrete_frequency_response_into(
            mat![[0.5]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            &[0.0],
            h,
            &mut lag,
        )
        .unwrap();
        assert!((lag[0] - c64::new(2.0, 0.0)).norm() < 1e-15);
        let err = discrete_frequency_response_into(
            mat![[0.5]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[1.0]].as_ref(),
            mat![[0.0]].as_ref(),
            &[0.0],
            -1.0,
            &mut lag,
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidValue { arg: "dt", .. }));
    }

    #[test]
    fn dimension_errors_name_the_matrix() {
        let a = Mat::<f64>::identity(3, 3);
        let b = Mat::<f64>::zeros(3, 1);
        let c = Mat::<f64>::zeros(2, 4);
        let d = Mat::<f64>::zeros(2, 1);
        let err =
            frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[1.0]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "C must have as many columns as A (3), got 4"
        );
        let c = Mat::<f64>::zeros(2, 3);
        let d = Mat::<f64>::zeros(2, 2);
        let err =
            frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[1.0]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "D must have as many columns as B (1), got 2"
        );
        let d = Mat::<f64>::zeros(2, 1);
        let err = frequency_response(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref(), &[f64::NAN])
            .unwrap_err();
        assert!(matches!(err, Error::NonFinite { arg: "omega", .. }));
    }
}
