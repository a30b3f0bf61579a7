//! The Taylor approximant "15+" of e^A: a polynomial of degree 16 whose coefficients of degree
//! 0 to 15 are those of the Taylor series (1/k!), evaluated with 4 matrix products and no solve.
//!
//! # Evaluation
//!
//! J. Sastre, "Efficient evaluation of matrix polynomials", Linear Algebra Appl. 539 (2018),
//! pp. 229-250, and J. Sastre, J. Ibáñez and E. Defez, "Boosting the computation of the matrix
//! exponential", Appl. Math. Comput. 340 (2019), pp. 206-220, (10)-(12):
//!
//! ```text
//! A2 = A A
//! y0 = A2 (c1 A2 + c2 A)
//! y1 = (y0 + c3 A2 + c4 A)(y0 + c5 A2) + c6 y0 + c7 A2
//! y2 = (y1 + c8 A2 + c9 A)(y1 + c10 y0 + c11 A) + c12 y1 + c13 y0 + c14 A2 + c15 A + c16 I
//! ```
//!
//! y0, y1 and y2 have degrees 4, 8 and 16; the 16 coefficients solve the 16 equations that make
//! the coefficients of x^0 ... x^15 of y2(x) equal to 1/k!. The degree-16 coefficient is then
//! c1^4 = (1 - 0.4543) / 16!. The coefficients below were derived, not copied:
//! `scripts/expm_taylor_coefficients.py` eliminates the equations from the highest degree down
//! at 60 digits (mpmath), which leaves one equation in c1 (two positive real roots) and one in
//! c10 (two real roots, ±); of the real solutions it takes the one whose evaluation with
//! |coefficients| at |x| exceeds e^x the least (the rounding of the evaluation is relative to
//! that), with c1 the root of least degree-16 error. It is the set published by Sastre et al.
//!
//! # Backward error
//!
//! With T(x) the polynomial, e^-x T(x) = 1 + O(x^16), and h(x) = log(e^-x T(x)) = Σ_{k>=16} h_k
//! x^k, so that T(A) = e^{A + h(A)}. Al-Mohy & Higham (2009, Theorem 4.2) bound
//! ||h(A)|| <= Σ |h_k| α_p^k with α_p = max(||A^p||^(1/p), ||A^(p+1)||^(1/(p+1))) for any p
//! with p(p - 1) <= 16; p = 4 uses d_4 and d_5. [`THETA`] is the largest x with
//! Σ |h_k| x^(k-1) <= u = 2^-53 (relative backward error at most u; the degree-16 mismatch
//! h_16 = -2.17e-14 is part of the series), computed by the same script with 220 terms at 60
//! digits (300 terms give the same value). For comparison the Taylor polynomial of degree 15
//! itself has θ = 0.641, and the Padé approximants of degree 9 and 13, which cost 5 and 6
//! products and an LU solve, 2.098 and 5.372.

use super::PadeArithmetic;

/// θ of the approximant: 2^-s α_4(A) <= θ bounds the relative backward error of T(2^-s A) by
/// u = 2^-53 (see the module documentation).
pub(crate) const THETA: f64 = 0.6764217495424514;

/// c1 ... c16 of the evaluation (see the module documentation).
const C: [f64; 16] = [
    4.0187616102010357e-4,
    2.945531440279683e-3,
    -8.709066576837676e-3,
    4.017568440673568e-1,
    3.230762888122312e-2,
    5.7689885130261445,
    2.338576034271299e-2,
    2.3810703738709874e-1,
    2.2242091724963737,
    -5.792361707073261,
    -4.130276365929783e-2,
    1.0408017352313543e1,
    -6.3317124558833704e1,
    3.484665863364574e-1,
    1.0,
    1.0,
];

/// T(A) from A and A2 = A A, by the three products of the evaluation above.
#[inline(always)]
pub(crate) fn taylor_approximant<M: PadeArithmetic>(a: &M, a2: &M) -> Result<M, M::Stop> {
    let y0 = a2.product(&M::combination(0.0, &[(C[0], a2), (C[1], a)]))?;
    let mut y1 = M::combination(0.0, &[(C[5], &y0), (C[6], a2)]);
    y1.add_product(
        &M::combination(0.0, &[(1.0, &y0), (C[2], a2), (C[3], a)]),
        &M::combination(0.0, &[(1.0, &y0), (C[4], a2)]),
    )?;
    let mut y2 = M::combination(
        C[15],
        &[(C[11], &y1), (C[12], &y0), (C[13], a2), (C[14], a)],
    );
    y2.add_product(
        &M::combination(0.0, &[(1.0, &y1), (C[7], a2), (C[8], a)]),
        &M::combination(0.0, &[(1.0, &y1), (C[9], &y0), (C[10], a)]),
    )?;
    Ok(y2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    /// The coefficients of the polynomial that the evaluation computes, from C alone (scalar
    /// polynomial arithmetic in double): 1/k! for k <= 15, and the stated degree-16 mismatch.
    #[test]
    fn the_evaluation_reproduces_the_taylor_coefficients() {
        fn product(p: &[f64], q: &[f64]) -> Vec<f64> {
            let mut out = vec![0.0; p.len() + q.len() - 1];
            for (i, x) in p.iter().enumerate() {
                for (j, y) in q.iter().enumerate() {
                    out[i + j] += x * y;
                }
            }
            out
        }
        fn sum(terms: &[(f64, &[f64])]) -> Vec<f64> {
            let mut out = vec![0.0; terms.iter().map(|(_, p)| p.len()).max().unwrap_or(0)];
            for (c, p) in terms {
                for (k, x) in p.iter().enumerate() {
                    out[k] += c * x;
                }
            }
            out
        }
        let a: &[f64] = &[0.0, 1.0];
        let a2: &[f64] = &[0.0, 0.0, 1.0];
        let one: &[f64] = &[1.0];
        let y0 = product(a2, &sum(&[(C[0], a2), (C[1], a)]));
        let y1 = sum(&[
            (
                1.0,
                &product(
                    &sum(&[(1.0, &y0), (C[2], a2), (C[3], a)]),
                    &sum(&[(1.0, &y0), (C[4], a2)]),
                ),
            ),
            (C[5], &y0),
            (C[6], a2),
        ]);
        let y2 = sum(&[
            (
                1.0,
                &product(
                    &sum(&[(1.0, &y1), (C[7], a2), (C[8], a)]),
                    &sum(&[(1.0, &y1), (C[9], &y0), (C[10], a)]),
                ),
            ),
            (C[11], &y1),
            (C[12], &y0),
            (C[13], a2),
            (C[14], a),
            (C[15], one),
        ]);
        let mut factorial = 1.0;
        for (k, &coefficient) in y2.iter().enumerate().take(16) {
            if k > 0 {
                factorial *= k as f64;
            }
            let error = (coefficient * factorial - 1.0).abs();
            assert!(error < 2e-13, "degree {k}: relative error {error:e}");
        }
        factorial *= 16.0;
        let error16 = y2[16] * factorial - 1.0;
        assert!((error16 + 0.454256).abs() < 1e-5, "degree 16: {error16}");
        assert!(y2[17..].iter().all(|&c| c == 0.0));
    }

    /// On scalars (1 x 1 matrices) in [-θ, θ], the evaluation equals e^x to a few units of
    /// rounding: the truncation is below u there and the rounding of the evaluation is small.
    #[test]
    fn scalar_values_within_theta_are_exact_to_rounding() {
        for i in -200..=200 {
            let x = THETA * i as f64 / 200.0;
            let a = SMatrix::<f64, 1, 1>::new(x);
            let value = match taylor_approximant(&a, &(a * a)) {
                Ok(value) => value[(0, 0)],
                Err(never) => match never {},
            };
            let error = (value / x.exp() - 1.0).abs();
            assert!(error <= 8.0 * f64::EPSILON, "x = {x}: {error:e}");
        }
    }
}
