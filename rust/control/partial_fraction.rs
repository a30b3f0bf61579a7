//! The partial-fraction (modal) form of a model, for its frequency response at many points.
//!
//! With A = W Λ W^-1 in real modal coordinates (W's columns the real eigenvectors and the real
//! and imaginary parts Re v, Im v of each complex pair's eigenvector v, Λ block diagonal with
//! 1 x 1 blocks λ and 2 x 2 blocks [[a, b], [-b, a]] for λ = a ± ib),
//!
//! ```text
//! G(s) = D + (C W) (sI - Λ)^-1 (W^-1 B)
//!      = D + Σ_real  r_k / (s - λ_k)
//!          + Σ_pairs [ (s - a) S_k + b T_k ] / ((s - λ_k)(s - conj λ_k)),
//! ```
//!
//! with the real coefficients r_k = c_k b_k of each channel (c = C W, b = W^-1 B), and
//! S_k = c_k b_k + c_k+1 b_k+1, T_k = c_k b_k+1 - c_k+1 b_k of each pair, from the inverse
//! of the block, [[s - a, b], [-b, s - a]] / ((s - a)^2 + b^2). Each point then costs O(n)
//! weights and O(n p m) real-by-complex products instead of the Hessenberg solve's O(n^2 m)
//! complex ones ([`crate::control::frequency`]): at n = 64, m = p = 2, a tenth.
//!
//! Accuracy. The form is used only where it is as trustworthy as the Hessenberg solve up to a
//! bounded factor, checked once per model and once per point:
//!
//! * the residual of the real modal decomposition is at rounding level,
//!   ||A W - W Λ||_1 <= [`RESIDUAL_SLACK`] n u ||A||_1 ||W||_1, so that the form is exact for
//!   A - E, E = (A W - W Λ) W^-1 of ||E||_1 <= [`RESIDUAL_SLACK`] n u ||A||_1 κ_1(W);
//! * κ_1(W) = ||W||_1 ||W^-1||_1 <= [`MAX_CONDITION`] (||W^-1||_1 by the block 1-norm
//!   estimator, Higham & Tisseur 2000, times 3 for its underestimation), so that this
//!   backward error, and the rounding of C W, of W^-1 B and of the sum (each at most
//!   √n ||W^-1|| times the Hessenberg solve's own rounding in C X), stay within a factor
//!   [`MAX_CONDITION`] of the backward-stable solve's error bound: results agree with the
//!   Hessenberg solve to rounding, not bit for bit;
//! * a point is taken only where the first-order error analysis holds,
//!   ||(sI - Λ)^-1|| ||W^-1 (A W - W Λ)|| <= 1/2, i.e. its distance to the nearest eigenvalue
//!   is at least twice ||W^-1||_1 ||A W - W Λ||_1 (a point nearer a pole goes to the
//!   Hessenberg solve), and where |s| / σ <= 2^100, so that no weight leaves the normal range.
//!
//! Defective or nearly defective A (a chain of integrators, repeated actuator poles), a failed
//! eigen-decomposition, or a conjugate pair not adjacent: no form, the Hessenberg solve takes
//! every point.

use crate::control::frequency::RangeScaled;
use crate::control::modal::eigen;
use crate::linalg::balance::times_power_of_two;
use crate::linalg::lu::Lu;
use crate::linalg::norm::{Inverse, one_norm, one_norm_estimate};
use crate::linalg::product::{multiply, product};
use crate::platform::dispatch::{fma_dispatch, multiply_add};
use faer::{Accum, Mat, MatRef, Par, c64};

/// The largest κ_1(W) of a form in use (2^14): its results stay within this factor of the
/// Hessenberg solve's error bound.
pub const MAX_CONDITION: f64 = 16384.0;

/// The residual of the real modal decomposition must be within this many n u ||A||_1 ||W||_1.
pub const RESIDUAL_SLACK: f64 = 8.0;

/// The estimator's ||W^-1||_1 is multiplied by this for its underestimation (rarely more than
/// a factor 3, Higham & Tisseur 2000, Table 6.1).
const ESTIMATE_SAFETY: f64 = 3.0;

/// Points of modulus beyond this (A scaled to its range) go to the Hessenberg solve (2^100).
const FAR_POINT: f64 = 1.2676506002282294e30;

/// The smallest squared distance of a point to an eigenvalue (A scaled to its range) at
/// which the form is evaluated (2^-200): the weights' squares stay normal numbers.
const NEAREST_POINT: f64 = 6.223015277861142e-61;

/// One block of Λ.
#[derive(Clone, Copy)]
enum Block {
    /// A real eigenvalue λ.
    Real(f64),
    /// The pair a ± ib, b > 0, block [[a, b], [-b, a]].
    Pair(f64, f64),
}

/// The partial-fraction form of (A, B, C, D), with what its points' checks need.
pub struct PartialFractions {
    n: usize,
    /// The real eigenvalues λ_k.
    reals: Vec<f64>,
    /// The pairs a_k ± i b_k (b_k > 0): a_k, then b_k.
    pairs: (Vec<f64>, Vec<f64>),
    /// The real coefficients, channel by channel (p m rows of n, row-major), each row laid out
    /// as the weights are: the r_k of the real eigenvalues, then the S_k of the pairs, then
    /// their T_k.
    coefficients: Vec<f64>,
    d: Vec<f64>,
    /// A / σ, B / β and C / γ are held (the point s is divided by σ): the sum is multiplied
    /// by 2^`exponent` = γ β / σ.
    exponent: f64,
    sigma: f64,
    /// The smallest squared distance |s / σ - λ|^2 to an eigenvalue at which a point is taken.
    nearest: f64,
}

impl PartialFractions {
    /// The form of a checked model, or `None` where it is not trustworthy (see the module's
    /// checks) or A has no eigen-decomposition.
    pub fn new(
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        c: MatRef<'_, f64>,
        d: MatRef<'_, f64>,
    ) -> Option<Self> {
        let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
        let RangeScaled {
            a,
            b,
            c,
            sigma,
            exponent,
        } = RangeScaled::new(a, b, c);
        let (values, vectors) = eigen(a.as_ref()).ok()?;
        let (blocks, w, lambda) = real_modal_form(&values, vectors.as_ref())?;
        // R = A W - W Λ. An interruption refuses the form (the caller's next check stops).
        let mut residual = Mat::<f64>::zeros(n, n);
        multiply(
            residual.as_mut(),
            Accum::Replace,
            a.as_ref(),
            w.as_ref(),
            1.0,
            Par::Seq,
        )
        .ok()?;
        multiply(
            residual.as_mut(),
            Accum::Add,
            w.as_ref(),
            lambda.as_ref(),
            -1.0,
            Par::Seq,
        )
        .ok()?;
        let residual_norm = one_norm(residual.as_ref());
        let w_norm = one_norm(w.as_ref());
        let unit = f64::EPSILON / 2.0;
        // Comparisons that are false for NaN: a NaN norm refuses the form.
        let decomposed =
            residual_norm <= RESIDUAL_SLACK * n as f64 * unit * one_norm(a.as_ref()) * w_norm;
        if !decomposed {
            return None;
        }
        let lu = Lu::new(w.as_ref()).ok()?;
        let inverse_norm = ESTIMATE_SAFETY * one_norm_estimate(&Inverse(&lu), 2);
        let conditioned = w_norm * inverse_norm <= MAX_CONDITION;
        if !conditioned {
            return None;
        }
        let modal_b = lu.solve(b.as_ref()).ok()?;
        let modal_c = product(c.as_ref(), w.as_ref()).ok()?;
        let reals: Vec<f64> = blocks
            .iter()
            .filter_map(|block| match block {
                Block::Real(lambda) => Some(*lambda),
                Block::Pair(..) => None,
            })
            .collect();
        let pairs: (Vec<f64>, Vec<f64>) = blocks
            .iter()
            .filter_map(|block| match block {
                Block::Real(_) => None,
                Block::Pair(a, b) => Some((*a, *b)),
            })
            .unzip();
        let pair_count = pairs.0.len();
        let mut coefficients = vec![0.0; p * m * n];
        for i in 0..p {
            for j in 0..m {
                let row = &mut coefficients[(i * m + j) * n..(i * m + j + 1) * n];
                let (mut column, mut real, mut pair) = (0, 0, 0);
                for block in &blocks {
                    match *block {
                        Block::Real(_) => {
                            row[real] = modal_c[(i, column)] * modal_b[(column, j)];
                            real += 1;
                            column += 1;
                        }
                        Block::Pair(..) => {
                            let (c1, c2) = (modal_c[(i, column)], modal_c[(i, column + 1)]);
                            let (b1, b2) = (modal_b[(column, j)], modal_b[(column + 1, j)]);
                            row[reals.len() + pair] = c1 * b1 + c2 * b2;
                            row[reals.len() + pair_count + pair] = c1 * b2 - c2 * b1;
                            pair += 1;
                            column += 2;
                        }
                    }
                }
            }
        }
        if !coefficients.iter().all(|x| x.is_finite()) {
            return None;
        }
        let reach = 2.0 * inverse_norm * residual_norm;
        Some(PartialFractions {
            n,
            reals,
            pairs,
            coefficients,
            d: (0..p * m).map(|k| d[(k / m, k % m)]).collect(),
            exponent,
            sigma,
            nearest: (reach * reach).max(NEAREST_POINT),
        })
    }

    /// Scratch of the weights for one point at a time.
    pub fn workspace(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![0.0; self.n], vec![0.0; self.n])
    }

    /// G(s) into `g` (p x m row-major), or false (g unspecified) where the point is too near
    /// an eigenvalue or too far for the form (the Hessenberg solve takes it).
    pub fn evaluate(&self, point: c64, weights: &mut (Vec<f64>, Vec<f64>), g: &mut [c64]) -> bool {
        evaluate(self, point, weights, g)
    }
}

/// W, Λ (real modal form) and the blocks from the eigenvalues (conjugate pairs adjacent,
/// Im > 0 first) and unit eigenvectors; `None` when a pair is not adjacent and conjugate.
fn real_modal_form(
    values: &[c64],
    vectors: MatRef<'_, c64>,
) -> Option<(Vec<Block>, Mat<f64>, Mat<f64>)> {
    let n = values.len();
    let mut w = Mat::<f64>::zeros(n, n);
    let mut lambda = Mat::<f64>::zeros(n, n);
    let mut blocks = Vec::with_capacity(n);
    let mut k = 0;
    while k < n {
        let value = values[k];
        if value.im == 0.0 {
            for i in 0..n {
                w[(i, k)] = vectors[(i, k)].re;
            }
            lambda[(k, k)] = value.re;
            blocks.push(Block::Real(value.re));
            k += 1;
        } else {
            if !(value.im > 0.0 && k + 1 < n && values[k + 1] == value.conj()) {
                return None;
            }
            for i in 0..n {
                w[(i, k)] = vectors[(i, k)].re;
                w[(i, k + 1)] = vectors[(i, k)].im;
            }
            // A [Re v, Im v] = [Re v, Im v] [[a, b], [-b, a]].
            let (a, b) = (value.re, value.im);
            lambda[(k, k)] = a;
            lambda[(k + 1, k + 1)] = a;
            lambda[(k, k + 1)] = b;
            lambda[(k + 1, k)] = -b;
            blocks.push(Block::Pair(a, b));
            k += 2;
        }
    }
    Some((blocks, w, lambda))
}

/// The weights of the point, then each channel's real-by-complex dot product with its
/// coefficients: 1 / (s - λ) for a real eigenvalue; (s - a) q and b q,
/// q = 1 / ((s - λ)(s - conj λ)), for a pair (the product of the two factors, each exact to
/// rounding, has relative error of a few u even where its real part cancels).
#[inline(always)]
fn evaluate_kernel<const FMA: bool>(
    form: &PartialFractions,
    point: c64,
    weights: &mut (Vec<f64>, Vec<f64>),
    g: &mut [c64],
) -> bool {
    let n = form.n;
    let s = if form.sigma == 1.0 {
        point
    } else {
        point / form.sigma
    };
    if !(s.re.abs() <= FAR_POINT && s.im.abs() <= FAR_POINT) {
        return false;
    }
    let (w_re, w_im) = weights;
    let (w_re, w_im) = (&mut w_re[..n], &mut w_im[..n]);
    let (real_count, pair_count) = (form.reals.len(), form.pairs.0.len());
    let (real_re, pair_re) = w_re.split_at_mut(real_count);
    let (real_im, pair_im) = w_im.split_at_mut(real_count);
    let (u_re, v_re) = pair_re.split_at_mut(pair_count);
    let (u_im, v_im) = pair_im.split_at_mut(pair_count);
    // Comparisons false for NaN: a point is refused only where it is near an eigenvalue.
    let mut near = false;
    let y = s.im;
    for ((&lambda, w_re), w_im) in form.reals.iter().zip(real_re).zip(real_im) {
        let x = s.re - lambda;
        let squared = x * x + y * y;
        near |= squared < form.nearest;
        let reciprocal = 1.0 / squared;
        *w_re = x * reciprocal;
        *w_im = -y * reciprocal;
    }
    let pairs = form.pairs.0.iter().zip(&form.pairs.1);
    let weights = u_re.iter_mut().zip(u_im).zip(v_re.iter_mut().zip(v_im));
    for ((&a, &b), ((u_re, u_im), (v_re, v_im))) in pairs.zip(weights) {
        let x = s.re - a;
        let (below, above) = (y - b, y + b);
        near |= (x * x + below * below < form.nearest) | (x * x + above * above < form.nearest);
        // (s - λ)(s - conj λ) = (x + i below)(x + i above).
        let (pr, pi) = (x * x - below * above, x * (below + above));
        let reciprocal = 1.0 / (pr * pr + pi * pi);
        let (qr, qi) = (pr * reciprocal, -pi * reciprocal);
        // (s - a) q = (x + i Im s) q.
        *u_re = x * qr - y * qi;
        *u_im = x * qi + y * qr;
        *v_re = b * qr;
        *v_im = b * qi;
    }
    if near {
        return false;
    }
    for (channel, g) in g.iter_mut().enumerate() {
        let row = &form.coefficients[channel * n..(channel + 1) * n];
        let (gr, gi) = real_complex_dot::<FMA>(row, w_re, w_im);
        let (gr, gi) = if form.exponent != 0.0 {
            (
                times_power_of_two(gr, form.exponent),
                times_power_of_two(gi, form.exponent),
            )
        } else {
            (gr, gi)
        };
        *g = c64::new(gr + form.d[channel], gi);
    }
    true
}

/// Σ r_k (u_k + i v_k) in four independent lanes (so that the compiler vectorises them).
#[inline(always)]
fn real_complex_dot<const FMA: bool>(r: &[f64], u: &[f64], v: &[f64]) -> (f64, f64) {
    const LANES: usize = 4;
    let (mut re, mut im) = ([0.0; LANES], [0.0; LANES]);
    let chunks = r.len() / LANES;
    for c in 0..chunks {
        let range = c * LANES..(c + 1) * LANES;
        let (r, u, v) = (&r[range.clone()], &u[range.clone()], &v[range]);
        for l in 0..LANES {
            re[l] = multiply_add::<FMA>(r[l], u[l], re[l]);
            im[l] = multiply_add::<FMA>(r[l], v[l], im[l]);
        }
    }
    let (mut sum_re, mut sum_im) = (
        (re[0] + re[1]) + (re[2] + re[3]),
        (im[0] + im[1]) + (im[2] + im[3]),
    );
    for k in chunks * LANES..r.len() {
        sum_re = multiply_add::<FMA>(r[k], u[k], sum_re);
        sum_im = multiply_add::<FMA>(r[k], v[k], sum_im);
    }
    (sum_re, sum_im)
}

fma_dispatch!(fn evaluate(form: &PartialFractions, point: c64, weights: &mut (Vec<f64>, Vec<f64>), g: &mut [c64]) -> bool => evaluate_kernel);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::frequency::FrequencyEvaluator;
    use crate::test_matrices::seeded;

    /// ||x - y||_F / ||y||_F of two p x m row-major stacks.
    fn relative_difference(x: &[c64], y: &[c64]) -> f64 {
        let difference: f64 = x.iter().zip(y).map(|(a, b)| (a - b).norm_sqr()).sum();
        let size: f64 = y.iter().map(|b| b.norm_sqr()).sum();
        (difference / size).sqrt()
    }

    #[test]
    fn agrees_with_the_hessenberg_solve() {
        // Seeded models of orders 12 to 40 (entries of three sizes, 1 to 3 inputs and outputs,
        // a D term), at points on the imaginary axis and on the unit circle: where the form
        // takes a point, G(s) is the Hessenberg solve's to 1e-11 relative.
        let (mut models, mut taken) = (0, 0);
        for (trial, n) in [12usize, 13, 16, 20, 27, 33, 40].into_iter().enumerate() {
            for (size, scale) in [1.0f64, 1e-5, 3e4].into_iter().enumerate() {
                let seed = (trial * 10 + size) as u64;
                let random = seeded(n, n, seed);
                let a = Mat::from_fn(n, n, |i, j| {
                    random[(i, j)] * scale - if i == j { 0.8 * scale } else { 0.0 }
                });
                let (m, p) = (1 + trial % 3, 1 + (trial + 1) % 3);
                let (b, c, d) = (
                    seeded(n, m, seed + 1),
                    seeded(p, n, seed + 2),
                    seeded(p, m, seed + 3),
                );
                let form =
                    PartialFractions::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
                let mut reference =
                    FrequencyEvaluator::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref())
                        .unwrap();
                let mut weights = form.workspace();
                let mut g = vec![c64::new(0.0, 0.0); p * m];
                models += 1;
                for k in 0..60 {
                    let w = scale * (k as f64 / 6.0 - 4.0).exp2();
                    let point = if k % 4 == 3 {
                        c64::new((w / scale).cos(), (w / scale).sin()) * scale
                    } else {
                        c64::new(0.0, w)
                    };
                    if form.evaluate(point, &mut weights, &mut g) {
                        taken += 1;
                        let expected = reference.at(point);
                        let error = relative_difference(&g, expected);
                        assert!(error < 1e-11, "n = {n}, s = {point}: {error:e}");
                    }
                }
            }
        }
        assert_eq!(models, 21);
        assert!(taken >= 21 * 55, "{taken}");
    }

    #[test]
    fn defective_and_nearly_defective_matrices_have_no_form() {
        // A Jordan block of order 12 (a chain of twelve equal lags), and the same block with
        // its eigenvalues split by 1e-9: eigenvectors nearly parallel, κ(W) far beyond the
        // bound.
        let n = 12;
        let (b, c, d) = (seeded(n, 1, 5), seeded(1, n, 6), Mat::<f64>::zeros(1, 1));
        for split in [0.0, 1e-9] {
            let a = Mat::from_fn(n, n, |i, j| {
                if i == j {
                    -1.0 - split * i as f64
                } else if j == i + 1 {
                    1.0
                } else {
                    0.0
                }
            });
            assert!(
                PartialFractions::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).is_none()
            );
        }
    }

    #[test]
    fn points_at_or_near_an_eigenvalue_or_far_beyond_are_refused() {
        // A diagonal A (an exact decomposition, residual 0) with an integrator and a pair at
        // ±2j: the points 0, 2j, 2j + 1e-40 and 1e40 j go to the Hessenberg solve; 1j is taken.
        let n = 12;
        let a = Mat::from_fn(n, n, |i, j| match (i, j) {
            (0, 0) | (1, 1) | (2, 2) => 0.0,
            (1, 2) => 2.0,
            (2, 1) => -2.0,
            _ if i == j => -(i as f64),
            _ => 0.0,
        });
        let (b, c, d) = (seeded(n, 2, 7), seeded(2, n, 8), Mat::<f64>::zeros(2, 2));
        let form = PartialFractions::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
        let mut weights = form.workspace();
        let mut g = vec![c64::new(0.0, 0.0); 4];
        for point in [0.0, 2.0, 2.0 + 1e-40, 1e40] {
            assert!(
                !form.evaluate(c64::new(0.0, point), &mut weights, &mut g),
                "{point}"
            );
        }
        assert!(form.evaluate(c64::new(0.0, 1.0), &mut weights, &mut g));
        let mut reference =
            FrequencyEvaluator::new(a.as_ref(), b.as_ref(), c.as_ref(), d.as_ref()).unwrap();
        assert!(relative_difference(&g, reference.at(c64::new(0.0, 1.0))) < 1e-14);
    }
}
