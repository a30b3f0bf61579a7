//! The roots of real monic polynomials of degree at most four, in closed form.
//!
//! The Riccati solver's QR iteration takes its shifts from the roots of the even characteristic
//! polynomial of the Hamiltonian, det(λI - H) = q(λ²) ([`crate::linalg::schur`]); for 1- to 4-state
//! models q has degree 1 to 4. The eigenvalues of q's companion matrix cost about five
//! double-shift sweeps, a tenth of a 4-state Riccati solve; the closed forms below cost a few
//! square and cube roots. Closed forms lose accuracy through cancellation (depressing the
//! polynomial when its roots are spread over many magnitudes, the discriminant near a multiple
//! root), so each root is then polished by Newton's method on the polynomial itself, and the
//! result is verified: expanded again, Π (x - x_i) must reproduce every coefficient to within
//! [`BACKWARD_TOLERANCE`] of the size its terms can have, Σ over products of |x_i| (a
//! coefficientwise backward error). Where it does not, [`monic_roots`] returns `None` and the
//! caller falls back to the companion matrix.
//!
//! The closed forms (for x⁴ + a x³ + b x² + c x + d, after scaling x by a power of two so that
//! the coefficients are of order one):
//!
//! - quadratic x² + b x + c: x₁ = -(b + sign(b) √(b² - 4c)) / 2 and x₂ = c / x₁ (no
//!   cancellation), or the pair -b/2 ± i √(4c - b²) / 2;
//! - cubic x³ + a x² + b x + c: with x = z - a/3, z³ + P z + Q = 0 (P = b - a²/3,
//!   Q = 2a³/27 - ab/3 + c) and Δ = (Q/2)² + (P/3)³; for Δ > 0 the one real root is
//!   z = u - P/(3u), u = ∛(-Q/2 - sign(Q) √Δ) (Cardano), and the pair follows by deflation;
//!   for Δ <= 0 the three real roots are z_k = 2 √(-P/3) cos((θ + 2πk)/3),
//!   cos θ = -(Q/2) / (-P/3)^(3/2) (Viète);
//! - quartic: with x = y - a/4, y⁴ + p y² + q y + r = 0 (p = b - 3a²/8, q = c - ab/2 + a³/8,
//!   r = d - ac/4 + a²b/16 - 3a⁴/256); for a root m > 0 of the resolvent cubic
//!   m³ + p m² + (p²/4 - r) m - q²/8 = 0 (Ferrari), y⁴ + p y² + q y + r =
//!   (y² - √(2m) y + p/2 + m + q/(2√(2m))) (y² + √(2m) y + p/2 + m - q/(2√(2m))), two
//!   quadratics; for q = 0 it is the quadratic in y².

use faer::c64;

/// The largest coefficientwise backward error accepted, relative to the size of the terms
/// (see the module documentation). Shifts need no more: a shift within a relative 1e-10 of an
/// eigenvalue deflates it in one sweep.
pub const BACKWARD_TOLERANCE: f64 = 1e-10;

/// At most this many Newton steps per root.
const MAX_NEWTON_STEPS: usize = 4;

/// The roots of a polynomial of degree at most four, complex ones in conjugate pairs (exact
/// conjugates, Im > 0 first).
#[derive(Clone, Copy, Debug)]
pub struct Roots {
    values: [c64; 4],
    count: usize,
}

impl Roots {
    fn new() -> Self {
        Self {
            values: [c64::new(0.0, 0.0); 4],
            count: 0,
        }
    }

    fn push_real(&mut self, x: f64) {
        self.values[self.count] = c64::new(x, 0.0);
        self.count += 1;
    }

    /// The pair z, z̄ of z with Im z > 0.
    fn push_pair(&mut self, z: c64) {
        self.values[self.count] = z;
        self.values[self.count + 1] = z.conj();
        self.count += 2;
    }

    pub fn as_slice(&self) -> &[c64] {
        &self.values[..self.count]
    }
}

/// The roots of x^d + c_1 x^(d-1) + ... + c_d (`coefficients` = [c_1, ..., c_d], d <= 4),
/// or `None` when d > 4, a coefficient is not finite, or the polished roots fail the
/// backward-error check (near-multiple roots of a badly scaled polynomial, say).
///
/// ```text
/// // (x - 1)(x - 2)(x² + 1) = x⁴ - 3x³ + 3x² - 3x + 2
/// let roots = monic_roots(&[-3.0, 3.0, -3.0, 2.0]).unwrap();
/// ```
pub fn monic_roots(coefficients: &[f64]) -> Option<Roots> {
    let degree = coefficients.len();
    if degree > 4 || !coefficients.iter().all(|c| c.is_finite()) {
        return None;
    }
    // x = s t, s a power of two (exact) with |c_k| / s^k < 1 for every k: 2^e, e the
    // largest ceil(e_k / k), |c_k| < 2^(e_k).
    let exponent = coefficients
        .iter()
        .zip(1..)
        .filter(|(c, _)| **c != 0.0)
        .map(|(c, k)| -(-binary_exponent(*c)).div_euclid(k))
        .max();
    let mut roots = Roots::new();
    let Some(exponent) = exponent else {
        (0..degree).for_each(|_| roots.push_real(0.0));
        return Some(roots);
    };
    let s = 2f64.powi(exponent);
    let mut scaled = [0.0; 4];
    let mut power = 1.0;
    for (x, &c) in scaled.iter_mut().zip(coefficients) {
        power *= s;
        // s^k out of range (coefficients spread over more than the exponent range): the
        // scaled coefficients would lose the small roots.
        if !(power.is_finite() && power > 0.0) {
            return None;
        }
        *x = c / power;
    }
    let scaled = &scaled[..degree];
    let t = match degree {
        0 => Roots::new(),
        1 => {
            let mut r = Roots::new();
            r.push_real(-scaled[0]);
            r
        }
        2 => quadratic(scaled[0], scaled[1]),
        3 => cubic(scaled[0], scaled[1], scaled[2]),
        _ => quartic(scaled[0], scaled[1], scaled[2], scaled[3]),
    };
    let t = polish(scaled, t);
    if !backward_error_is_small(scaled, &t) {
        return None;
    }
    let mut k = 0;
    while k < t.count {
        let z = t.values[k];
        if z.im > 0.0 {
            roots.push_pair(z * s);
            k += 2;
        } else {
            roots.push_real(z.re * s);
            k += 1;
        }
    }
    Some(roots)
}

/// x² + b x + c = 0.
fn quadratic(b: f64, c: f64) -> Roots {
    let mut roots = Roots::new();
    let discriminant = b * b - 4.0 * c;
    if discriminant >= 0.0 {
        let first = -(b + b.signum() * discriminant.sqrt()) / 2.0;
        roots.push_real(first);
        roots.push_real(if first != 0.0 { c / first } else { 0.0 });
    } else {
        roots.push_pair(c64::new(-b / 2.0, (-discriminant).sqrt() / 2.0));
    }
    roots
}

/// The depressed form of x³ + a x² + b x + c: x = z - a/3 turns it into z³ + P z + Q; returns
/// (a/3, P/3, Q/2) and the discriminant (Q/2)² + (P/3)³ (> 0: one real root).
fn depressed_cubic(a: f64, b: f64, c: f64) -> (f64, f64, f64, f64) {
    let third = a / 3.0;
    let p_third = (b - a * third) / 3.0;
    let half_q = ((2.0 * third * third - b) * third + c) / 2.0;
    let discriminant = half_q * half_q + p_third * p_third * p_third;
    (third, p_third, half_q, discriminant)
}

/// Cardano's real root z = u - (P/3)/u, u = ∛(-Q/2 - sign(Q) √Δ), of z³ + P z + Q (Δ > 0).
fn cardano(p_third: f64, half_q: f64, discriminant: f64) -> f64 {
    let u = (-half_q - half_q.signum() * discriminant.sqrt()).cbrt();
    if u != 0.0 { u - p_third / u } else { 0.0 }
}

/// Viète's real roots 2 √(-P/3) cos((θ + 2πk)/3) of z³ + P z + Q (Δ <= 0), k = 0, 1, 2, the
/// first the largest.
fn viete(p_third: f64, half_q: f64, k: usize) -> f64 {
    let radius = (-p_third).max(0.0).sqrt();
    let cos_theta = if radius > 0.0 {
        (-half_q / (radius * radius * radius)).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let angle = (cos_theta.acos() + 2.0 * std::f64::consts::PI * k as f64) / 3.0;
    2.0 * radius * angle.cos()
}

/// The largest real root of x³ + a x² + b x + c.
fn largest_real_cubic_root([a, b, c]: [f64; 3]) -> f64 {
    let (third, p_third, half_q, discriminant) = depressed_cubic(a, b, c);
    if discriminant > 0.0 {
        cardano(p_third, half_q, discriminant) - third
    } else {
        viete(p_third, half_q, 0) - third
    }
}

/// x³ + a x² + b x + c = 0: Cardano's one real root and the deflated pair, or Viète's three
/// real roots.
fn cubic(a: f64, b: f64, c: f64) -> Roots {
    let (third, p_third, half_q, discriminant) = depressed_cubic(a, b, c);
    let mut roots = Roots::new();
    if discriminant > 0.0 {
        let real = newton_real(&[a, b, c], cardano(p_third, half_q, discriminant) - third);
        // x³ + a x² + b x + c = (x - r)(x² + e x + f): e = a + r, and f = -c / r when r is the
        // largest root (|r|³ >= |c|, the product of the other two), else f = b + r e.
        let e = a + real;
        let f = if real != 0.0 && real.abs().powi(3) >= c.abs() {
            -c / real
        } else {
            b + real * e
        };
        roots.push_real(real);
        for &z in quadratic(e, f).as_slice() {
            if z.im > 0.0 {
                roots.push_pair(z);
            } else if z.im == 0.0 {
                roots.push_real(z.re);
            }
        }
    } else {
        for k in 0..3 {
            roots.push_real(viete(p_third, half_q, k) - third);
        }
    }
    roots
}

/// x⁴ + a x³ + b x² + c x + d = 0 by Ferrari's factorisation into two quadratics.
fn quartic(a: f64, b: f64, c: f64, d: f64) -> Roots {
    let quarter = a / 4.0;
    let a2 = quarter * quarter;
    let p = b - 6.0 * a2;
    let q = c - 2.0 * quarter * (b - 4.0 * a2);
    let r = d - quarter * c + a2 * b - 3.0 * a2 * a2;
    // The largest real root of the resolvent, polished; m > 0 whenever q != 0.
    let resolvent = [p, p * p / 4.0 - r, -q * q / 8.0];
    let m = newton_real(&resolvent, largest_real_cubic_root(resolvent));
    // The roots y, shifted back to x = y - a/4.
    let mut roots = Roots::new();
    let mut add = |factor: Roots| {
        for &y in factor.as_slice() {
            if y.im > 0.0 {
                roots.push_pair(y - quarter);
            } else if y.im == 0.0 {
                roots.push_real(y.re - quarter);
            }
        }
    };
    if m > 0.0 && q != 0.0 {
        let root = (2.0 * m).sqrt();
        let offset = q / (2.0 * root);
        add(quadratic(-root, p / 2.0 + m + offset));
        add(quadratic(root, p / 2.0 + m - offset));
    } else {
        // y⁴ + p y² + r: y² = w for the roots w of w² + p w + r.
        let squares = quadratic(p, r);
        if squares.values[0].im > 0.0 {
            // A pair w, w̄: y = ±√w, ±√w̄, the pairs of √w (taken with Im > 0) and of -√w̄.
            let y = squares.values[0].sqrt();
            let first = if y.im > 0.0 { y } else { y.conj() };
            let mut pairs = Roots::new();
            pairs.push_pair(first);
            pairs.push_pair(c64::new(-first.re, first.im));
            add(pairs);
        } else {
            for &w in squares.as_slice() {
                let mut pair = Roots::new();
                if w.re >= 0.0 {
                    pair.push_real(w.re.sqrt());
                    pair.push_real(-w.re.sqrt());
                } else {
                    pair.push_pair(c64::new(0.0, (-w.re).sqrt()));
                }
                add(pair);
            }
        }
    }
    roots
}

/// e with 2^(e-1) <= |x| < 2^e for a finite x != 0 (the exponent of frexp; approximate for
/// subnormal x, which only makes the scaling less even).
fn binary_exponent(x: f64) -> i32 {
    ((x.to_bits() >> 52) & 0x7ff) as i32 - 1022
}

/// Newton's method for a real root of the monic polynomial with `coefficients`, from `x`,
/// while the steps shrink |p| and are above the rounding of x.
fn newton_real(coefficients: &[f64], x: f64) -> f64 {
    let (mut x, (mut p, mut dp)) = (x, horner_real(coefficients, x));
    for _ in 0..MAX_NEWTON_STEPS {
        let step = p / dp;
        if !step.is_finite() || step.abs() <= 2.0 * f64::EPSILON * x.abs() {
            return if step.is_finite() { x - step } else { x };
        }
        let candidate = x - step;
        let (p_candidate, dp_candidate) = horner_real(coefficients, candidate);
        if p_candidate.abs() >= p.abs() {
            break;
        }
        (x, p, dp) = (candidate, p_candidate, dp_candidate);
    }
    x
}

/// [`newton_real`] for a complex root z (Im z > 0), which stays in the upper half plane.
fn newton_complex(coefficients: &[f64], z: c64) -> c64 {
    let (mut z, (mut p, mut dp)) = (z, horner_complex(coefficients, z));
    for _ in 0..MAX_NEWTON_STEPS {
        let step = p / dp;
        if !(step.re.is_finite() && step.im.is_finite()) {
            break;
        }
        if step.norm_sqr() <= (2.0 * f64::EPSILON).powi(2) * z.norm_sqr() {
            let last = z - step;
            return if last.im > 0.0 { last } else { z };
        }
        let candidate = z - step;
        let (p_candidate, dp_candidate) = horner_complex(coefficients, candidate);
        if candidate.im <= 0.0 || p_candidate.norm_sqr() >= p.norm_sqr() {
            break;
        }
        (z, p, dp) = (candidate, p_candidate, dp_candidate);
    }
    z
}

/// The monic polynomial and its derivative at x.
fn horner_real(coefficients: &[f64], x: f64) -> (f64, f64) {
    let (mut p, mut dp) = (1.0, 0.0);
    for &c in coefficients {
        dp = dp * x + p;
        p = p * x + c;
    }
    (p, dp)
}

/// The monic polynomial and its derivative at z.
fn horner_complex(coefficients: &[f64], z: c64) -> (c64, c64) {
    let (mut p, mut dp) = (c64::new(1.0, 0.0), c64::new(0.0, 0.0));
    for &c in coefficients {
        dp = dp * z + p;
        p = p * z + c;
    }
    (p, dp)
}

/// Newton steps on every root (of a pair, on the member with Im > 0, its conjugate following).
/// A pair whose imaginary part the steps would remove stays a pair: the check judges it.
fn polish(coefficients: &[f64], roots: Roots) -> Roots {
    let mut polished = Roots::new();
    let mut k = 0;
    while k < roots.count {
        let z = roots.values[k];
        if z.im > 0.0 {
            polished.push_pair(newton_complex(coefficients, z));
            k += 2;
        } else {
            polished.push_real(newton_real(coefficients, z.re));
            k += 1;
        }
    }
    polished
}

/// Whether Π (x - x_i) reproduces each coefficient c_k within [`BACKWARD_TOLERANCE`] times
/// e_k(|x_1|, ..., |x_d|), the largest its terms can be.
fn backward_error_is_small(coefficients: &[f64], roots: &Roots) -> bool {
    let degree = coefficients.len();
    if roots.count != degree {
        return false;
    }
    // Coefficients highest power first, [1, c_1, ..., c_d], built factor by factor.
    let mut expanded = [1.0, 0.0, 0.0, 0.0, 0.0];
    let mut bound = [1.0, 0.0, 0.0, 0.0, 0.0];
    let mut filled = 0;
    let multiply = |poly: &mut [f64; 5], filled: usize, factor: &[f64]| {
        // poly · (x^len + factor[0] x^(len-1) + ...), poly of degree `filled`.
        let mut result = [0.0; 5];
        for i in 0..=filled {
            result[i] += poly[i];
            for (j, &f) in factor.iter().enumerate() {
                result[i + j + 1] += poly[i] * f;
            }
        }
        *poly = result;
    };
    let mut k = 0;
    while k < roots.count {
        let z = roots.values[k];
        if !(z.re.is_finite() && z.im.is_finite()) {
            return false;
        }
        if z.im > 0.0 {
            multiply(&mut expanded, filled, &[-2.0 * z.re, z.norm_sqr()]);
            multiply(&mut bound, filled, &[2.0 * z.norm(), z.norm_sqr()]);
            filled += 2;
            k += 2;
        } else {
            multiply(&mut expanded, filled, &[-z.re]);
            multiply(&mut bound, filled, &[z.re.abs()]);
            filled += 1;
            k += 1;
        }
    }
    coefficients
        .iter()
        .enumerate()
        .all(|(i, &c)| (expanded[i + 1] - c).abs() <= BACKWARD_TOLERANCE * bound[i + 1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The monic polynomial with the given roots (a pair given by its member with Im > 0).
    fn from_roots(real: &[f64], pairs: &[c64]) -> Vec<f64> {
        let mut poly = vec![1.0];
        let mut times = |factor: &[f64]| {
            let mut result = vec![0.0; poly.len() + factor.len()];
            for (i, &p) in poly.iter().enumerate() {
                result[i] += p;
                for (j, &f) in factor.iter().enumerate() {
                    result[i + j + 1] += p * f;
                }
            }
            poly = result;
        };
        for &x in real {
            times(&[-x]);
        }
        for z in pairs {
            times(&[-2.0 * z.re, z.norm_sqr()]);
        }
        poly[1..].to_vec()
    }

    /// Each expected root is matched by a computed one within `tolerance` relative to its
    /// modulus, one to one.
    fn assert_roots(computed: &Roots, real: &[f64], pairs: &[c64], tolerance: f64, what: &str) {
        let mut expected: Vec<c64> = real.iter().map(|&x| c64::new(x, 0.0)).collect();
        for z in pairs {
            expected.push(*z);
            expected.push(z.conj());
        }
        let partners = crate::test_matrices::nearest_partners(computed.as_slice(), &expected);
        for (e, z) in partners {
            assert!(
                (z - e).norm() <= tolerance * e.norm().max(f64::MIN_POSITIVE),
                "{what}: root {e} computed as {z} ({:?})",
                computed.as_slice()
            );
        }
    }

    #[test]
    fn closed_forms_reproduce_known_roots() {
        let cases: Vec<(&str, Vec<f64>, Vec<c64>)> = vec![
            ("linear", vec![-2.5], vec![]),
            ("two reals", vec![3.0, -0.5], vec![]),
            ("a pair", vec![], vec![c64::new(-0.5, 2.0)]),
            ("three reals", vec![1.0, -2.0, 7.0], vec![]),
            ("a real and a pair", vec![-3.0], vec![c64::new(0.25, 1.5)]),
            ("four reals", vec![1.0, 2.0, -3.0, 0.5], vec![]),
            (
                "two reals, a pair",
                vec![1.0, 2.0],
                vec![c64::new(0.0, 1.0)],
            ),
            (
                "two pairs",
                vec![],
                vec![c64::new(-0.08, 0.74), c64::new(-1.2, 0.3)],
            ),
            // The 747 lateral regulator's Hamiltonian: μ = λ² of its closed-loop poles.
            (
                "the 747's squares",
                vec![1.2308f64.powi(2), 0.04642f64.powi(2)],
                vec![c64::new(-0.0807, 0.7433).powi(2).conj()],
            ),
            // Biquadratic (q = 0 in Ferrari's depressed form): ±1, ±2i.
            ("biquadratic", vec![1.0, -1.0], vec![c64::new(0.0, 2.0)]),
            // Spread over six orders of magnitude: the depressed forms cancel, Newton restores
            // the small roots.
            ("spread reals", vec![1e3, 1.0, 1e-3, -0.1], vec![]),
            ("spread pair", vec![1e-2, 3e3], vec![c64::new(-2e-2, 5e-2)]),
        ];
        for (what, real, pairs) in &cases {
            let coefficients = from_roots(real, pairs);
            let roots = monic_roots(&coefficients).unwrap_or_else(|| panic!("{what}: None"));
            assert_roots(&roots, real, pairs, 1e-9, what);
        }
    }

    #[test]
    fn random_polynomials_match_the_companion_eigenvalues() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let mut accepted = 0;
        for trial in 0..2000 {
            let degree = 1 + trial % 4;
            let mut real = Vec::new();
            let mut pairs = Vec::new();
            while real.len() + 2 * pairs.len() < degree {
                let modulus = 10f64.powf(rng.random_range(-3.0..3.0));
                if degree - real.len() - 2 * pairs.len() >= 2 && rng.random_bool(0.5) {
                    let angle: f64 = rng.random_range(0.05..3.09);
                    pairs.push(c64::from_polar(modulus, angle));
                } else {
                    real.push(if rng.random_bool(0.5) {
                        modulus
                    } else {
                        -modulus
                    });
                }
            }
            let coefficients = from_roots(&real, &pairs);
            if let Some(roots) = monic_roots(&coefficients) {
                accepted += 1;
                // Roots within six orders of magnitude of each other keep relative accuracy
                // ~1e-10 / separation; the check bounds backward error, so compare loosely.
                assert_roots(&roots, &real, &pairs, 1e-6, &format!("trial {trial}"));
            }
        }
        // Refusals are for near-multiple roots only: rare among random ones.
        assert!(accepted >= 1990, "accepted {accepted} of 2000");
    }

    #[test]
    fn multiple_and_zero_roots() {
        // x⁴: all zero; x² (x - 1)²: a double zero and a double one.
        let roots = monic_roots(&[0.0; 4]).unwrap();
        assert!(roots.as_slice().iter().all(|z| z.norm() == 0.0));
        let roots = monic_roots(&[-2.0, 1.0, 0.0, 0.0]).unwrap();
        assert_roots(&roots, &[0.0, 0.0, 1.0, 1.0], &[], 1e-7, "double roots");
        // (x - 1)⁴: roots within u^(1/4) only, but a backward error of rounding.
        let roots = monic_roots(&[-4.0, 6.0, -4.0, 1.0]).unwrap();
        assert_roots(&roots, &[1.0; 4], &[], 1e-3, "quadruple root");
    }

    #[test]
    fn roots_spread_too_far_are_refused_not_wrong() {
        // Over twelve orders of magnitude Ferrari's depressed quartic has lost the small roots
        // (Newton from there finds others): the check refuses them.
        let coefficients = from_roots(&[1e6, 1.0, 1e-3, 1e-6], &[]);
        assert!(monic_roots(&coefficients).is_none());
    }

    #[test]
    fn refused_inputs() {
        // x² + 1e300 x + 1: scaling by s ~ 1e300 would take s² past the overflow threshold.
        assert!(monic_roots(&[1e300, 1.0]).is_none());
        assert!(monic_roots(&[1.0; 5]).is_none());
        assert!(monic_roots(&[f64::NAN, 1.0]).is_none());
        assert!(monic_roots(&[1.0, f64::INFINITY, 0.0]).is_none());
        assert!(monic_roots(&[]).unwrap().as_slice().is_empty());
    }
}
