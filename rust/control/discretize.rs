//! Exact discretisation of x' = Ax + Bη over a step h: the transition matrix and the input
//! integrals, by one exponential of an augmented block matrix (C. F. Van Loan, "Computing
//! integrals involving the matrix exponential", IEEE Trans. Automat. Control 23(3), 1978,
//! pp. 395-404).
//!
//! With the input held constant over the step (zero-order hold, ZOH) the solution (6.9) gives
//! x_{k+1} = Φ x_k + Γ0 η_k, and with the input linear between samples (first-order hold, FOH)
//! x_{k+1} = Φ x_k + (Γ0 - Γ1) η_k + Γ1 η_{k+1}, where
//!
//! ```text
//! Φ  = e^{Ah}
//! Γ0 = ∫_0^h e^{Aτ} dτ B                 = h φ1(Ah) B,  φ1(z) = (e^z - 1) / z
//! Γ1 = (1/h) ∫_0^h e^{Aτ} (h - τ) dτ B   = h φ2(Ah) B,  φ2(z) = (e^z - 1 - z) / z^2
//! ```
//!
//! Both come out of one exponential, because for the block upper triangular matrices
//!
//! ```text
//!        [ Ah  Bh ]                [ Φ  Γ0 ]          [ Ah  Bh  0 ]             [ Φ  Γ0  Γ1 ]
//! exp(   [  0   0 ] )          =   [ 0   I ],    exp( [  0   0  I ] )       =   [ 0   I   I ]
//!                                                      [  0   0  0 ]             [ 0   0   I ]
//! ```
//!
//! (the (1,2) block of the k-th power is (Ah)^{k-1} Bh, and of the (1,3) block (Ah)^{k-2} Bh).
//! Unlike the chapter's step formula (6.43), x(t) = (e^{At} - I) A^-1 B η0, this needs no
//! inverse of A, so it is exact for the singular A of (6.95) and every system with an
//! integrator or a neutral mode.
//!
//! The integrals are linear in B, so B is scaled by a power of two (exactly) to a size
//! comparable with Ah before the exponential and the blocks are scaled back: a B much larger
//! than Ah would otherwise force extra squarings on the whole augmented matrix, and B h could
//! overflow or underflow at the edges of the range of doubles.

use crate::error::{Error, check_finite, check_positive, check_rows, check_square};
use crate::linalg::expm::expm;
use faer::Mat;
use faer::MatRef;

/// How the input is reconstructed between samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hold {
    /// Zero-order hold: η constant over each step.
    Zero,
    /// First-order hold: η linear between consecutive samples.
    First,
}

/// The matrices of one discretisation step.
#[derive(Debug, Clone, PartialEq)]
pub struct Discretization {
    /// Φ = e^{Ah}, n x n.
    pub phi: Mat<f64>,
    /// Γ0 = ∫_0^h e^{Aτ} dτ B, n x m.
    pub gamma0: Mat<f64>,
    /// Γ1 = (1/h) ∫_0^h e^{Aτ} (h - τ) dτ B, n x m; present for [`Hold::First`].
    pub gamma1: Option<Mat<f64>>,
}

/// x 2^e for an integer e of any size, in two exact steps where one power would leave the range
/// of doubles.
fn times_power_of_two(x: f64, exponent: f64) -> f64 {
    let half = (exponent / 2.0).trunc();
    x * half.exp2() * (exponent - half).exp2()
}

/// Discretises x' = Ax + Bη over the step `dt` with the given hold (see the module docs).
///
/// ```
/// use faer::mat;
/// use aerocontrol::control::discretize::{discretize, Hold};
/// // A double integrator: Φ = [[1, h], [0, 1]], Γ0 = [h^2/2, h]^T.
/// let a = mat![[0.0, 1.0], [0.0, 0.0]];
/// let b = mat![[0.0], [1.0]];
/// let d = discretize(a.as_ref(), b.as_ref(), 0.5, Hold::Zero).unwrap();
/// assert!((d.gamma0[(0, 0)] - 0.125).abs() < 1e-16 && (d.gamma0[(1, 0)] - 0.5).abs() < 1e-16);
/// ```
pub fn discretize(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    dt: f64,
    hold: Hold,
) -> Result<Discretization, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")?;
    check_positive(dt, "dt")?;

    let (n, m) = (a.nrows(), b.ncols());
    let blocks = match hold {
        Hold::Zero => 1,
        Hold::First => 2,
    };
    let size = n + blocks * m;

    let mut augmented = Mat::<f64>::zeros(size, size);
    for j in 0..n {
        for i in 0..n {
            augmented[(i, j)] = a[(i, j)] * dt;
        }
    }
    let a_dt_max = augmented.get(..n, ..n).norm_max();
    if !a_dt_max.is_finite() {
        return Err(Error::InvalidValue {
            arg: "dt",
            value: dt,
            requirement: "small enough that A dt is finite",
        });
    }
    // The input block is Y = 2^(j - e) B, with 2^e the binade of max|b_ij| and 2^j the
    // binade of max(||A dt||_1, 1) (bounded through n max|A dt|, which cannot overflow):
    // exact scalings by powers of two, so Y never overflows or underflows whatever B and dt
    // are. Then Γ = (block of the exponential) dt 2^(e - j).
    let b_max = b.norm_max();
    let (b_exponent, target_exponent) = if b_max > 0.0 {
        let target = (a_dt_max * n as f64).log2().round().clamp(0.0, 1000.0);
        (b_max.log2().floor(), target)
    } else {
        (0.0, 0.0)
    };
    let input_scale = target_exponent - b_exponent;
    for j in 0..m {
        for i in 0..n {
            augmented[(i, n + j)] = times_power_of_two(b[(i, j)], input_scale);
        }
    }
    if hold == Hold::First {
        for j in 0..m {
            augmented[(n + j, n + m + j)] = 1.0;
        }
    }
    let exponential = expm(augmented.as_ref())?;

    let block = |col0: usize| {
        Mat::from_fn(n, m, |i, j| {
            times_power_of_two(exponential[(i, col0 + j)] * dt, -input_scale)
        })
    };
    Ok(Discretization {
        phi: exponential.get(..n, ..n).to_owned(),
        gamma0: block(n),
        gamma1: (hold == Hold::First).then(|| block(n + m)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::lu::solve_in_place;
    use faer::{Par, mat};

    fn max_abs_difference(x: MatRef<'_, f64>, y: MatRef<'_, f64>) -> f64 {
        (x - y).norm_max()
    }

    #[test]
    fn zoh_equals_the_inverse_formula_for_nonsingular_a() {
        // Γ0 = (e^{Ah} - I) A^-1 B = A^-1 (e^{Ah} - I) B (A and e^{Ah} commute).
        let a = mat![
            [-0.0212, 0.0466, 0.0, -0.1153],
            [-0.2229, -0.5839, 0.9404, 0.0],
            [0.0150, -0.5031, -0.5015, 0.0],
            [0.0, 0.0, 1.0, 0.0]
        ];
        let b = mat![[0.0], [-0.0340], [-0.5746], [0.0]];
        for dt in [0.01, 0.5, 20.0] {
            let d = discretize(a.as_ref(), b.as_ref(), dt, Hold::Zero).unwrap();
            let rhs = (&d.phi - Mat::<f64>::identity(4, 4)) * &b;
            let mut expected = rhs;
            solve_in_place(a.clone().as_mut(), expected.as_mut(), Par::Seq);
            let scale = expected.norm_max();
            assert!(max_abs_difference(d.gamma0.as_ref(), expected.as_ref()) < 1e-12 * scale);
            assert!(d.gamma1.is_none());
        }
    }

    #[test]
    fn singular_a_of_the_state_feedback_example() {
        // (6.95): A = [[-3, 8], [0, 0]], B = [0, 4]^T has a zero eigenvalue, so (6.43) fails.
        // Closed form: x2 integrates 4η, x1' = -3 x1 + 8 x2.
        let a = mat![[-3.0, 8.0], [0.0, 0.0]];
        let b = mat![[0.0], [4.0]];
        let h = 0.7f64;
        let d = discretize(a.as_ref(), b.as_ref(), h, Hold::First).unwrap();
        let e = (-3.0 * h).exp();
        // Γ0: x2(h) = 4h, x1(h) = 32 ∫_0^h e^{-3(h-s)} s ds = 32 (h/3 - (1 - e^{-3h})/9).
        let g0 = [32.0 * (h / 3.0 - (1.0 - e) / 9.0), 4.0 * h];
        assert!((d.gamma0[(0, 0)] - g0[0]).abs() < 1e-14);
        assert!((d.gamma0[(1, 0)] - g0[1]).abs() < 1e-14);
        // Γ1 = (1/h) ∫_0^h e^{Aτ} (h - τ) dτ B; for the integrator row: (1/h) 4 h^2/2 = 2h.
        let g1 = d.gamma1.unwrap();
        assert!((g1[(1, 0)] - 2.0 * h).abs() < 1e-14);
        // For the first row: (32/h) ∫_0^h (1 - e^{-3τ})/3 (h - τ) dτ.
        let integral = (h * h / 2.0) / 3.0 - (h / 3.0 - (1.0 - e) / 9.0) / 3.0;
        assert!((g1[(0, 0)] - 32.0 / h * integral).abs() < 1e-13);
    }

    #[test]
    fn huge_input_matrix_is_scaled_exactly() {
        let a = mat![[-1.0, 0.5], [0.0, -2.0]];
        let b = mat![[1e12], [3e12]];
        let small = mat![[1.0], [3.0]];
        let big = discretize(a.as_ref(), b.as_ref(), 0.1, Hold::First).unwrap();
        let unit = discretize(a.as_ref(), small.as_ref(), 0.1, Hold::First).unwrap();
        let scaled = &unit.gamma0 * faer::Scale(1e12);
        assert!(max_abs_difference(big.gamma0.as_ref(), scaled.as_ref()) < 1e-15 * 3e12);
        let scaled = unit.gamma1.unwrap() * faer::Scale(1e12);
        assert!(max_abs_difference(big.gamma1.unwrap().as_ref(), scaled.as_ref()) < 1e-15 * 3e12);
    }

    #[test]
    fn bad_arguments_are_named() {
        let a = mat![[1.0, 0.0], [0.0, 1.0]];
        let b = mat![[1.0], [0.0], [2.0]];
        assert_eq!(
            discretize(a.as_ref(), b.as_ref(), 0.1, Hold::Zero)
                .unwrap_err()
                .to_string(),
            "B must have as many rows as A (2), got 3"
        );
        let b = mat![[1.0], [0.0]];
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let err = discretize(a.as_ref(), b.as_ref(), dt, Hold::Zero).unwrap_err();
            assert!(matches!(err, Error::InvalidValue { arg: "dt", .. }));
        }
    }

    #[test]
    fn extreme_magnitudes_of_b_and_dt() {
        // Γ0 of x' = -x + b u over dt is b (1 - e^-dt): check at the edges of the double range.
        let a = mat![[-1.0]];
        for (b, dt) in [
            (1e-300, 1e-10),
            (1e300, 1e-10),
            (1e300, 1.0),
            (1.0, 5e-324),
            (3.0, 1e6),
        ] {
            let d = discretize(a.as_ref(), mat![[b]].as_ref(), dt, Hold::First).unwrap();
            let expected = b * -(-dt).exp_m1();
            assert!(
                (d.gamma0[(0, 0)] / expected - 1.0).abs() < 1e-14,
                "b={b} dt={dt}: {} vs {expected}",
                d.gamma0[(0, 0)]
            );
            assert!(d.gamma1.unwrap()[(0, 0)].is_finite());
        }
        // A dt overflowing is the step's fault.
        let err = discretize(
            mat![[1e300]].as_ref(),
            mat![[1.0]].as_ref(),
            1e10,
            Hold::Zero,
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidValue { arg: "dt", .. }));
    }

    #[test]
    fn no_inputs_gives_empty_integrals() {
        let a = mat![[0.0, 1.0], [-1.0, 0.0]];
        let b = Mat::<f64>::zeros(2, 0);
        let d = discretize(a.as_ref(), b.as_ref(), 0.3, Hold::First).unwrap();
        assert_eq!(d.gamma0.ncols(), 0);
        assert!((d.phi[(0, 1)] - 0.3f64.sin()).abs() < 1e-15);
    }
}
