//! Modal analysis: eigenvalues, modes and their characteristics, the modal matrix, the
//! characteristic polynomial (chapter §6.4, (6.58)-(6.62); the mode characteristics of the
//! earlier chapter's unforced response, used in (6.152)-(6.154)).
//!
//! The eigenvalues and eigenvectors come from the real Schur form A = Z T Z^T
//! (`linalg/schur`: Hessenberg reduction and the double-shift or multishift QR iteration) and
//! the eigenvectors of T by back substitution, conjugate pairs adjacent. A conjugate pair is one mode, an
//! oscillation; a real eigenvalue is one mode, a subsidence or divergence. For a mode with
//! eigenvalue λ = σ ± jω_d:
//!
//! ```text
//! natural frequency   ω_n = |λ|
//! damping ratio       ζ   = -σ / |λ|           (NaN for λ = 0)
//! damped frequency    ω_d = |Im λ|
//! period              T   = 2π / ω_d           (oscillations)
//! time to half        t½  = ln 2 / |σ|  for σ < 0;  time to double t₂ = ln 2 / σ for σ > 0
//! cycles to half      N½  = t½ / T              (oscillations)
//! time constant       τ   = 1 / |λ|             (real modes)
//! ```
//!
//! The modal matrix P holds the eigenvectors (unit 2-norm) as columns, P^-1 A P = Λ (6.59), and
//! P^-1 B (6.61) shows which modes each input reaches. A repeated eigenvalue without a full set
//! of eigenvectors (a defective matrix, such as a double integrator) has no modal matrix: P is
//! then numerically singular, which [`ModalAnalysis::modal_matrix_condition`] reports, and
//! P^-1 B is not formed.
//!
//! The characteristic polynomial det(λI - A) comes from the balanced Hessenberg form by La
//! Budde's recurrence over its leading principal submatrices (see [`crate::linalg::charpoly`]), in real
//! arithmetic and without computing eigenvalues.

use crate::error::{Error, check_finite, check_rows, check_square};
use crate::linalg::balance::balance;
use crate::linalg::lu::Lu;
use crate::linalg::matrix::{FaerView, Square, from_faer};
use crate::linalg::norm::vector_norm;
use crate::linalg::schur::{real_schur, schur_eigenvectors, schur_form_eigenvalues};
use faer::{Mat, MatRef, c64};
use nalgebra::Dyn;

/// The modal matrix counts as singular (no modal decomposition) above this condition number,
/// about 1/sqrt(u): beyond it P^-1 B would carry no correct digits in the worst case.
pub const SINGULAR_MODAL_MATRIX_CONDITION: f64 = 1e8;

/// One mode: a real eigenvalue, or a conjugate pair represented by its member with Im λ > 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    pub eigenvalue: c64,
    /// True for a conjugate pair (an oscillation).
    pub oscillatory: bool,
    pub natural_frequency: f64,
    pub damping_ratio: f64,
    pub damped_frequency: f64,
    /// 2π / ω_d; infinite for a real mode.
    pub period: f64,
    /// ln 2 / |σ| for a decaying mode; NaN otherwise.
    pub time_to_half: f64,
    /// ln 2 / σ for a growing mode; NaN otherwise.
    pub time_to_double: f64,
    /// t½ / T for a decaying oscillation; NaN otherwise.
    pub cycles_to_half: f64,
    /// 1 / |λ| for a real mode; NaN for an oscillation.
    pub time_constant: f64,
    /// Indices of this mode's eigenvalues (one, or the pair) in the eigenvalue list.
    pub indices: [usize; 2],
}

impl Mode {
    fn new(eigenvalue: c64, oscillatory: bool, indices: [usize; 2]) -> Self {
        let (sigma, omega_d) = (eigenvalue.re, eigenvalue.im.abs());
        let natural_frequency = eigenvalue.norm();
        let ln2 = std::f64::consts::LN_2;
        let period = if oscillatory {
            2.0 * std::f64::consts::PI / omega_d
        } else {
            f64::INFINITY
        };
        let time_to_half = if sigma < 0.0 { ln2 / -sigma } else { f64::NAN };
        Mode {
            eigenvalue,
            oscillatory,
            natural_frequency,
            damping_ratio: if natural_frequency > 0.0 {
                -sigma / natural_frequency
            } else {
                f64::NAN
            },
            damped_frequency: omega_d,
            period,
            time_to_half,
            time_to_double: if sigma > 0.0 { ln2 / sigma } else { f64::NAN },
            cycles_to_half: if oscillatory {
                time_to_half / period
            } else {
                f64::NAN
            },
            time_constant: if oscillatory || natural_frequency == 0.0 {
                f64::NAN
            } else {
                1.0 / natural_frequency
            },
            indices,
        }
    }
}

/// Eigenvalues, modes, modal matrix and characteristic polynomial of a square matrix.
#[derive(Debug, Clone)]
pub struct ModalAnalysis {
    /// The eigenvalues, each conjugate pair adjacent (Im > 0 first), in the order of `modes`.
    pub eigenvalues: Vec<c64>,
    /// The modes, by increasing natural frequency (then by decreasing damping).
    pub modes: Vec<Mode>,
    /// The modal matrix P (unit eigenvectors as columns, in the order of `eigenvalues`).
    pub modal_matrix: Mat<c64>,
    /// κ_2(P) = σ_max / σ_min; infinite when P is exactly singular.
    pub modal_matrix_condition: f64,
    /// κ_2(P_b) of the modal matrix P_b of A with its states balanced (D^-1 A D, as [`eigen`]
    /// balances it): how near A is to a defective matrix, in any units of its states (κ_2(P)
    /// grows with their spread: 1.3e12 for three simple, well-separated eigenvalues of states
    /// in units 10^±6 apart). Infinite when P_b is exactly singular.
    pub balanced_modal_matrix_condition: f64,
    /// P^-1 B (6.61), when B was given and P is not singular.
    pub modal_input: Option<Mat<c64>>,
    /// Coefficients of det(λI - A), highest power first: [1, a_1, ..., a_n].
    pub characteristic_polynomial: Vec<f64>,
}

impl ModalAnalysis {
    /// Whether P is too ill-conditioned to be a modal matrix in any units of the states (a
    /// defective or nearly defective eigenvalue): by the balanced modal matrix's condition.
    pub fn modal_matrix_is_singular(&self) -> bool {
        self.balanced_modal_matrix_condition.is_nan()
            || self.balanced_modal_matrix_condition >= SINGULAR_MODAL_MATRIX_CONDITION
    }
}

/// The eigenvalues and unit eigenvectors of a real square matrix, conjugate pairs adjacent with
/// Im > 0 first: A balanced, B = D^-1 A D (D diagonal of powers of two, [`balance`], exact),
/// the real Schur form B = Z T Z^T, the eigenvectors x of T by back substitution
/// ([`schur_eigenvectors`]), and those of A as D Z x, normalised (as LAPACK's xGEEV with
/// scaling). The balancing makes the eigenvalues' errors relative to the balanced matrix:
/// states in units 10^±6 apart put them 3e-4 off without it.
///
/// A matrix whose largest entry is outside [2^-100, 2^100] is first divided by the power of
/// two nearest to it ([`crate::linalg::balance::range_scale`], exact; the eigenvectors are
/// those of A, the eigenvalues are multiplied back), so that the back substitution's products
/// and its pivot threshold stay well inside the normal range.
pub fn eigen(a: MatRef<'_, f64>) -> Result<(Vec<c64>, Mat<c64>), Error> {
    eigen_and_balancing(a).map(|(values, vectors, _)| (values, vectors))
}

/// The eigenvalues, the unit eigenvectors and the diagonal of the balancing D of [`eigen`].
type EigenAndBalancing = (Vec<c64>, Mat<c64>, Vec<f64>);

/// [`eigen`] with the diagonal of its balancing D (D^-1 A D balanced).
fn eigen_and_balancing(a: MatRef<'_, f64>) -> Result<EigenAndBalancing, Error> {
    let (balanced, d, scale) = balanced_for_eigen(a)?;
    // D^-1 A D = Z T Z^T: the eigenvectors of A are D Z x.
    let (values, vectors) = schur_eigenvectors(&real_schur(balanced.as_faer())?, &d)?;
    Ok((values.into_iter().map(|v| v * scale).collect(), vectors, d))
}

/// The eigenvalues of [`eigen`], bit for bit and in its order, without the eigenvectors: the
/// same balancing and real Schur form, its transformation Z not accumulated
/// ([`schur_form_eigenvalues`]), read from T's diagonal blocks as [`schur_eigenvectors`]
/// reads them.
pub fn eigen_values(a: MatRef<'_, f64>) -> Result<Vec<c64>, Error> {
    let (balanced, _, scale) = balanced_for_eigen(a)?;
    Ok(schur_form_eigenvalues(balanced.as_faer())?
        .into_iter()
        .map(|v| v * scale)
        .collect())
}

/// The balanced D^-1 (A / s) D of [`eigen`], the diagonal of D and s (A checked square and
/// finite).
fn balanced_for_eigen(a: MatRef<'_, f64>) -> Result<(Square<Dyn>, Vec<f64>, f64), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    let scale = crate::linalg::balance::range_scale(a);
    let mut balanced = from_faer(a);
    if scale != 1.0 {
        balanced.as_mut_slice().iter_mut().for_each(|x| *x /= scale);
    }
    let d = balance(&mut balanced);
    Ok((balanced, d, scale))
}

/// The coefficients of prod (λ - λ_i), highest power first, multiplied out in real arithmetic
/// with each conjugate pair as one real quadratic. `eigenvalues` must hold conjugate pairs
/// adjacent (as [`eigen`] returns them).
pub fn polynomial_from_roots(eigenvalues: &[c64]) -> Vec<f64> {
    let mut coefficients = Vec::with_capacity(eigenvalues.len() + 1);
    coefficients.push(1.0);
    // Multiplies by the monic factor [1, f...] in place, highest power first.
    let mut multiply = |factor: &[f64]| {
        coefficients.extend(factor.iter().map(|_| 0.0));
        for i in (1..coefficients.len()).rev() {
            for (j, &f) in factor.iter().enumerate().take(i) {
                coefficients[i] += f * coefficients[i - j - 1];
            }
        }
    };
    let mut k = 0;
    while k < eigenvalues.len() {
        let lambda = eigenvalues[k];
        if lambda.im == 0.0 {
            multiply(&[-lambda.re]);
            k += 1;
        } else {
            multiply(&[
                -2.0 * lambda.re,
                lambda.re * lambda.re + lambda.im * lambda.im,
            ]);
            k += 2;
        }
    }
    coefficients
}

/// κ₂(P) of a modal matrix of unit columns whose conjugate pairs are adjacent (Im λ > 0
/// first, as [`eigen`] returns them), from a real matrix of the same singular values: a pair
/// [v, v̄] = [√2 Re v, √2 Im v] U with U = [[1, 1], [i, -i]]/√2 unitary, so P = R diag(U, ...)
/// and κ₂(P) = κ₂(R) for R real (its singular values cost a quarter of the complex ones').
fn condition_number(p: &Mat<c64>, eigenvalues: &[c64]) -> f64 {
    let n = p.nrows();
    if n == 0 {
        return 1.0;
    }
    let root2 = std::f64::consts::SQRT_2;
    let r = Mat::from_fn(n, n, |i, j| {
        let lambda = eigenvalues[j];
        if lambda.im == 0.0 {
            p[(i, j)].re
        } else if lambda.im > 0.0 {
            root2 * p[(i, j)].re
        } else {
            root2 * p[(i, j - 1)].im
        }
    });
    match r.singular_values() {
        Ok(s) => {
            let (largest, smallest) = (s[0], s[s.len() - 1]);
            if smallest > 0.0 {
                largest / smallest
            } else {
                f64::INFINITY
            }
        }
        Err(_) => f64::INFINITY,
    }
}

/// The modes of A without its eigenvectors: the eigenvalues, the modes and the characteristic
/// polynomial of [`modal_analysis`], bit for bit, from the real Schur form without Z
/// ([`eigen_values`]). `b` (n x m) is checked as [`modal_analysis`] checks it, with the same
/// errors, though P^-1 B is not formed.
pub fn mode_spectrum(
    a: MatRef<'_, f64>,
    b: Option<MatRef<'_, f64>>,
) -> Result<ModeSpectrum, Error> {
    let values = eigen_values(a)?;
    if let Some(b) = b {
        check_rows(b, "B", a.nrows(), "A")?;
        check_finite(b, "B")?;
    }
    let (eigenvalues, modes, _) = ordered_modes(&values);
    let characteristic_polynomial = polynomial_from_roots(&eigenvalues);
    Ok(ModeSpectrum {
        eigenvalues,
        modes,
        characteristic_polynomial,
    })
}

/// The part of a [`ModalAnalysis`] that needs no eigenvector.
#[derive(Debug, Clone)]
pub struct ModeSpectrum {
    /// The eigenvalues, each conjugate pair adjacent (Im > 0 first), in the order of `modes`.
    pub eigenvalues: Vec<c64>,
    /// The modes, by increasing natural frequency (then by decreasing damping).
    pub modes: Vec<Mode>,
    /// Coefficients of det(λI - A), highest power first: [1, a_1, ..., a_n].
    pub characteristic_polynomial: Vec<f64>,
}

/// The modes of the eigenvalues `values` (conjugate pairs adjacent, Im > 0 first), ordered by
/// natural frequency, then by decreasing damping: the eigenvalues in that order, the modes
/// (their indices into it) and, for each, its position in `values`.
fn ordered_modes(values: &[c64]) -> (Vec<c64>, Vec<Mode>, Vec<usize>) {
    let mut modes = Vec::new();
    let mut k = 0;
    while k < values.len() {
        let oscillatory = values[k].im != 0.0;
        let indices = if oscillatory { [k, k + 1] } else { [k, k] };
        modes.push(Mode::new(values[k], oscillatory, indices));
        k += if oscillatory { 2 } else { 1 };
    }
    modes.sort_by(|x, y| {
        x.natural_frequency
            .total_cmp(&y.natural_frequency)
            .then(y.damping_ratio.total_cmp(&x.damping_ratio))
            .then(x.eigenvalue.re.total_cmp(&y.eigenvalue.re))
    });
    let order: Vec<usize> = modes
        .iter()
        .flat_map(|m| {
            if m.oscillatory {
                vec![m.indices[0], m.indices[1]]
            } else {
                vec![m.indices[0]]
            }
        })
        .collect();
    let eigenvalues: Vec<c64> = order.iter().map(|&i| values[i]).collect();
    let mut position = 0;
    for mode in &mut modes {
        mode.indices = if mode.oscillatory {
            [position, position + 1]
        } else {
            [position, position]
        };
        position += if mode.oscillatory { 2 } else { 1 };
    }
    (eigenvalues, modes, order)
}

/// The modal analysis of A, and P^-1 B when `b` is given (n x m).
pub fn modal_analysis(
    a: MatRef<'_, f64>,
    b: Option<MatRef<'_, f64>>,
) -> Result<ModalAnalysis, Error> {
    let (values, vectors, balancing) = eigen_and_balancing(a)?;
    if let Some(b) = b {
        check_rows(b, "B", a.nrows(), "A")?;
        check_finite(b, "B")?;
    }
    let n = values.len();
    let (eigenvalues, modes, order) = ordered_modes(&values);
    let modal_matrix = Mat::from_fn(n, n, |i, j| vectors[(i, order[j])]);
    // P = D P_b S with P_b the unit eigenvectors of the balanced D^-1 A D and S diagonal (the
    // columns' norms): P^-1 B = S^-1 P_b^-1 D^-1 B, solved with the better conditioned P_b.
    let mut balanced_modal = Mat::from_fn(n, n, |i, j| modal_matrix[(i, j)] / balancing[i]);
    let column_norms: Vec<f64> = (0..n)
        .map(|j| {
            let parts: Vec<f64> = balanced_modal
                .col(j)
                .iter()
                .flat_map(|v| [v.re, v.im])
                .collect();
            let norm = vector_norm(parts.iter().copied());
            balanced_modal
                .col_mut(j)
                .iter_mut()
                .for_each(|v| *v /= norm);
            norm
        })
        .collect();
    let modal_matrix_condition = condition_number(&modal_matrix, &eigenvalues);
    let balanced_modal_matrix_condition = if balancing.iter().all(|&d| d == 1.0) {
        modal_matrix_condition
    } else {
        condition_number(&balanced_modal, &eigenvalues)
    };
    let characteristic_polynomial = polynomial_from_roots(&eigenvalues);
    let mut analysis = ModalAnalysis {
        eigenvalues,
        modes,
        modal_matrix,
        modal_matrix_condition,
        balanced_modal_matrix_condition,
        modal_input: None,
        characteristic_polynomial,
    };
    if let Some(b) = b
        && !analysis.modal_matrix_is_singular()
    {
        let rhs = Mat::from_fn(n, b.ncols(), |i, j| c64::new(b[(i, j)] / balancing[i], 0.0));
        let mut input = Lu::new(balanced_modal.as_ref())?.solve(rhs.as_ref())?;
        for (i, norm) in column_norms.iter().enumerate() {
            input.row_mut(i).iter_mut().for_each(|v| *v /= *norm);
        }
        analysis.modal_input = Some(input);
    }
    Ok(analysis)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_matrices::lateral_747;
    use faer::mat;

    #[test]
    fn lateral_747_matches_the_chapter() {
        // (6.150)-(6.155): roll -1.2308, Dutch roll -0.08066 ± 0.7433i, spiral -0.04641, from
        // the unrounded matrix; the printed one gives slightly different last digits.
        let a = lateral_747();
        let analysis = modal_analysis(a.as_ref(), None).unwrap();
        let modes = &analysis.modes;
        assert_eq!(modes.len(), 3);
        let (spiral, dutch_roll, roll) = (&modes[0], &modes[1], &modes[2]);
        assert!(!spiral.oscillatory && dutch_roll.oscillatory && !roll.oscillatory);
        assert!((spiral.eigenvalue.re + 0.04641).abs() < 2e-5);
        assert!((roll.eigenvalue.re + 1.2308).abs() < 2e-4);
        assert!((dutch_roll.eigenvalue.re + 0.08066).abs() < 5e-5);
        assert!((dutch_roll.eigenvalue.im - 0.7433).abs() < 1e-4);
        assert!((dutch_roll.natural_frequency - 0.7477).abs() < 1e-4);
        assert!((dutch_roll.damping_ratio - 0.1079).abs() < 2e-4);
        assert!((roll.time_to_half - 0.56).abs() < 5e-3);
        assert!((spiral.time_to_half - 14.93).abs() < 1e-2);
        let expected = [1.0, 1.4385, 0.8222, 0.7232, 0.0319];
        for (c, e) in analysis.characteristic_polynomial.iter().zip(expected) {
            assert!((c - e).abs() < 2e-4, "{c} vs {e}");
        }
        // P^-1 A P = Λ.
        assert!(analysis.modal_matrix_condition < 100.0);
    }

    #[test]
    fn the_real_form_gives_the_condition_number_of_the_complex_modal_matrix() {
        // Random matrices of orders 1 to 40 (real modes and pairs, A / sqrt(n) and graded by
        // 10^±3): κ₂(P) from R against faer's complex singular values of P itself.
        let mut seed = 0x5EED_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for n in [1usize, 2, 3, 7, 16, 40] {
            let grade = |i: usize| 10f64.powf(6.0 * i as f64 / n as f64 - 3.0);
            let a = Mat::from_fn(n, n, |i, j| next() * grade(i) / grade(j));
            let (values, vectors) = eigen(a.as_ref()).unwrap();
            assert!(
                values.iter().any(|v| v.im != 0.0) || n < 3,
                "n = {n}: no pair"
            );
            let complex = vectors.singular_values().unwrap();
            let expected = complex[0] / complex[n - 1];
            let got = condition_number(&vectors, &values);
            // σ_min is computed to about u σ_max: κ to a relative error of about u κ.
            let tolerance = 1e-14 * expected * expected.max(1e2);
            assert!(
                (got - expected).abs() <= tolerance,
                "n = {n}: {got} vs {expected}"
            );
        }
    }

    #[test]
    fn the_spectrum_without_vectors_is_that_of_the_full_analysis_bit_for_bit() {
        // Random matrices of orders 1 to 120 (both QR iterations and both Hessenberg
        // reductions), plain, graded by 10^±4, with repeated eigenvalues (a block diagonal of
        // equal blocks) and scaled near the ends of the range: the eigenvalues, the modes and
        // the characteristic polynomial of mode_spectrum are those of modal_analysis exactly.
        let mut seed = 0xC0FFEE_u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut cases = 0;
        for n in [1usize, 2, 3, 4, 5, 8, 9, 16, 33, 64, 80, 120] {
            for variant in 0..4 {
                let grade = |i: usize| match variant {
                    1 => 10f64.powf(8.0 * i as f64 / n as f64 - 4.0),
                    _ => 1.0,
                };
                let factor = if variant == 3 { 1e-200 } else { 1.0 };
                let mut a = Mat::from_fn(n, n, |i, j| next() * grade(i) / grade(j) * factor);
                if variant == 2 && n >= 4 {
                    let half = n / 2;
                    for i in 0..n {
                        for j in 0..n {
                            a[(i, j)] = if (i < half) == (j < half) {
                                a[(i % half, j % half)]
                            } else {
                                0.0
                            };
                        }
                    }
                }
                let b = Mat::from_fn(n, 2, |_, _| next());
                let full = modal_analysis(a.as_ref(), Some(b.as_ref())).unwrap();
                let spectrum = mode_spectrum(a.as_ref(), Some(b.as_ref())).unwrap();
                let bits = |v: &[c64]| -> Vec<(u64, u64)> {
                    v.iter().map(|x| (x.re.to_bits(), x.im.to_bits())).collect()
                };
                assert_eq!(
                    bits(&spectrum.eigenvalues),
                    bits(&full.eigenvalues),
                    "n = {n}"
                );
                // (Debug prints each f64 exactly, NaN included, which == would not match.)
                assert_eq!(
                    format!("{:?}", spectrum.modes),
                    format!("{:?}", full.modes),
                    "n = {n}, variant {variant}"
                );
                let polynomial = |p: &[f64]| p.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    polynomial(&spectrum.characteristic_polynomial),
                    polynomial(&full.characteristic_polynomial)
                );
                cases += 1;
            }
        }
        assert_eq!(cases, 48);
        // B is refused as the full analysis refuses it.
        let error = mode_spectrum(
            Mat::<f64>::identity(2, 2).as_ref(),
            Some(Mat::<f64>::zeros(3, 1).as_ref()),
        );
        assert_eq!(
            error.unwrap_err().to_string(),
            "B must have as many rows as A (2), got 3"
        );
    }

    #[test]
    fn modal_input_of_the_controllability_example() {
        // (6.75)-(6.88): modes -1 and -2; with B = [-1, 1]^T the second mode is not reached.
        let a = mat![[0.0, 1.0], [-2.0, -3.0]];
        let b = mat![[-1.0], [1.0]];
        let analysis = modal_analysis(a.as_ref(), Some(b.as_ref())).unwrap();
        let modal_input = analysis.modal_input.unwrap();
        // Modes ordered by natural frequency: λ = -1 first, then λ = -2.
        assert!((analysis.eigenvalues[0].re + 1.0).abs() < 1e-14);
        assert!(modal_input[(0, 0)].norm() > 0.1);
        assert!(modal_input[(1, 0)].norm() < 1e-14);
    }

    #[test]
    fn defective_matrix_has_no_modal_matrix() {
        // The double integrator: a double eigenvalue 0 with one eigenvector.
        let a = mat![[0.0, 1.0], [0.0, 0.0]];
        let b = mat![[0.0], [1.0]];
        let analysis = modal_analysis(a.as_ref(), Some(b.as_ref())).unwrap();
        assert!(analysis.modal_matrix_is_singular());
        assert!(analysis.modal_input.is_none());
        assert!(analysis.modes[0].damping_ratio.is_nan());
        assert_eq!(analysis.characteristic_polynomial, vec![1.0, 0.0, 0.0]);
    }

    #[test]
    fn states_scaled_apart_are_not_defective() {
        // Three simple eigenvalues (-0.8647 and -2.5676 ± 0.4082i, by numpy) in states scaled
        // by 10^±6: P in those units has κ_2 near 4e11, the balanced one a few units; P^-1 B
        // is formed, and P (P^-1 B) = B.
        let base = [[-1.0, 0.5, -0.25], [0.3, -2.0, 0.75], [0.2, -0.4, -3.0]];
        let t = [1e-6, 1.0, 1e6];
        let a = Mat::from_fn(3, 3, |i, j| base[i][j] * t[i] / t[j]);
        let b = Mat::from_fn(3, 1, |i, _| t[i]);
        let analysis = modal_analysis(a.as_ref(), Some(b.as_ref())).unwrap();
        assert!(analysis.modal_matrix_condition > 1e10);
        assert!(analysis.balanced_modal_matrix_condition < 1e2);
        assert!(!analysis.modal_matrix_is_singular());
        let input = analysis.modal_input.unwrap();
        for (i, &ti) in t.iter().enumerate() {
            let row: c64 = (0..3)
                .map(|k| analysis.modal_matrix[(i, k)] * input[(k, 0)])
                .sum();
            assert!((row - c64::new(ti, 0.0)).norm() <= 1e-12 * ti, "{row:?}");
        }
    }

    #[test]
    fn mode_characteristics() {
        // λ = -1 ± 2i: ω_n = √5, ζ = 1/√5, T = π, t½ = ln 2, N½ = ln 2 / π.
        let a = mat![[-1.0, 2.0], [-2.0, -1.0]];
        let mode = modal_analysis(a.as_ref(), None).unwrap().modes[0];
        assert!(mode.oscillatory && mode.eigenvalue.im > 0.0);
        assert!((mode.natural_frequency - 5f64.sqrt()).abs() < 1e-15);
        assert!((mode.damping_ratio - 1.0 / 5f64.sqrt()).abs() < 1e-15);
        assert!((mode.period - std::f64::consts::PI).abs() < 1e-14);
        assert!((mode.time_to_half - std::f64::consts::LN_2).abs() < 1e-15);
        assert!(mode.time_to_double.is_nan() && mode.time_constant.is_nan());
        // An unstable real mode doubles.
        let mode = modal_analysis(mat![[0.5]].as_ref(), None).unwrap().modes[0];
        assert!((mode.time_to_double - 2.0 * std::f64::consts::LN_2).abs() < 1e-15);
        assert!((mode.time_constant - 2.0).abs() < 1e-15 && mode.time_to_half.is_nan());
        assert_eq!(mode.damping_ratio, -1.0);
    }

    #[test]
    fn polynomial_from_conjugate_roots_is_real() {
        let roots = [
            c64::new(-1.0, 2.0),
            c64::new(-1.0, -2.0),
            c64::new(3.0, 0.0),
        ];
        // (λ^2 + 2λ + 5)(λ - 3) = λ^3 - λ^2 - λ - 15.
        assert_eq!(polynomial_from_roots(&roots), vec![1.0, -1.0, -1.0, -15.0]);
        assert_eq!(polynomial_from_roots(&[]), vec![1.0]);
    }

    #[test]
    fn bad_input() {
        assert!(matches!(
            modal_analysis(Mat::<f64>::zeros(2, 3).as_ref(), None),
            Err(Error::NotSquare { .. })
        ));
        let b = Mat::<f64>::zeros(3, 1);
        assert_eq!(
            modal_analysis(Mat::<f64>::identity(2, 2).as_ref(), Some(b.as_ref()))
                .unwrap_err()
                .to_string(),
            "B must have as many rows as A (2), got 3"
        );
    }
}

#[cfg(test)]
mod scaling_tests {
    use super::*;

    #[test]
    fn eigenvalues_of_tiny_and_huge_matrices_scale() {
        // 1e-301 [[1.26, -1.32], [6.40, 1.05]]: eigenvalues 1e-301 (1.155 ± 2.9045 i).
        for factor in [1e-301, 1e-160, 1e160, 1e300] {
            let a = Mat::from_fn(2, 2, |i, j| [[1.26, -1.32], [6.40, 1.05]][i][j] * factor);
            let (values, _) = eigen(a.as_ref()).unwrap();
            let re = 0.5 * (1.26 + 1.05);
            let im = (1.32 * 6.40 - 0.25 * (1.26f64 - 1.05).powi(2)).sqrt();
            for v in &values {
                assert!((v.re / factor - re).abs() < 1e-13, "{factor}: {values:?}");
                assert!(
                    (v.im.abs() / factor - im).abs() < 1e-13,
                    "{factor}: {values:?}"
                );
            }
        }
    }

    #[test]
    fn eigenvectors_of_matrices_near_1e_150_satisfy_a_p_equals_p_lambda() {
        // A random 4 x 4 matrix times 1e-150, 1e-120 and 1e120: the residual ||A P - P Λ||
        // within 100 n u ||A|| ||P||.
        let base = crate::test_matrices::seeded_square(4, 7);
        for factor in [1e-150, 1e-120, 1e120, 1e150] {
            let a = &base * faer::Scale(factor);
            let (values, vectors) = eigen(a.as_ref()).unwrap();
            let a = Mat::from_fn(4, 4, |i, j| c64::new(a[(i, j)], 0.0));
            let lambda = Mat::from_fn(4, 4, |i, j| {
                if i == j {
                    values[i]
                } else {
                    c64::new(0.0, 0.0)
                }
            });
            let residual = (&a * &vectors - &vectors * &lambda).norm_l2();
            let bound = 400.0 * f64::EPSILON * a.norm_l2() * vectors.norm_l2();
            assert!(residual <= bound, "{factor:e}: {residual:e} > {bound:e}");
        }
    }
}
