//! The real Schur form A = Z T Z^T, by Hessenberg reduction and the Francis double-shift QR
//! algorithm, and the eigenvalues of a real matrix.
//!
//! T is quasi-upper-triangular: 1 x 1 diagonal blocks hold real eigenvalues, 2 x 2 blocks hold
//! complex conjugate pairs, and every 2 x 2 block is in standard form
//!
//! ```text
//! [ a  b ]
//! [ c  a ]      b c < 0,   eigenvalues a ± sqrt(-b c) i,
//! ```
//!
//! Z is orthogonal. The reduction is backward stable: Z T Z^T = A + E with ||E|| = O(u ||A||).
//!
//! # Algorithm
//!
//! A is first reduced to upper Hessenberg form H = Q^T A Q ([`crate::linalg::hessenberg`], a
//! blocked Householder reduction). The QR iteration then works on the active window H[l..=i, l..=i]
//! between negligible subdiagonal entries (the deflation test of Ahues & Tisseur, as in LAPACK's
//! small-matrix QR, which declares h_{k,k-1} negligible only when doing so perturbs the
//! eigenvalues of the neighbouring 2 x 2 block by at most u times their size). Each step is an
//! implicit double shift (Francis 1961/62) with the two eigenvalues of the trailing 2 x 2 block:
//! a 3 x 3 Householder reflector introduces a bulge at the top of the window and further
//! reflectors chase it to the bottom, so the step costs O(n^2) and keeps H real and Hessenberg.
//! Every tenth iteration without a deflation uses an exceptional shift (Wilkinson's ad hoc
//! values 3/4 s and -0.4375 s) to break the rare cycles of the standard shifts. A converged
//! 2 x 2 block is rotated into standard form by [`standardize_block`], which also splits it
//! into two 1 x 1 blocks when its eigenvalues are real.
//!
//! Known eigenvalues make better shifts than the trailing block's: an exact shift deflates in
//! one sweep in exact arithmetic, where the trailing block's shifts take two to four. The
//! first two sweeps after each deflation therefore use the known eigenvalue nearest to the
//! trailing block's (two real ones, or a conjugate pair). The nearest, not the latest: an
//! exact shift spent on an eigenvalue that has nearly split off higher up makes the sweep undo
//! the split (forward instability), and the iteration needs several sweeps more. A known eigenvalue matches a deflated one within a relative 1e-6 and is then
//! dropped; a mismatch only costs a sweep with an ordinary shift, and the transformations stay
//! orthogonal either way, so the form is as backward stable as without them. Known
//! eigenvalues come from three places:
//!
//! - A Hamiltonian matrix ([`Spectrum::Hamiltonian`], the Riccati solver's) has an even
//!   characteristic polynomial, det(λI - H) = q(λ²), whose coefficients La Budde's recurrence
//!   gives from the Hessenberg form in O(n^3) ([`crate::linalg::charpoly`]); the roots μ of q
//!   (of half the order: in closed form up to degree four, `polynomial_roots`, which costs a
//!   tenth of the five or six sweeps of q's companion matrix; else, or where the closed form
//!   fails its backward-error check, the eigenvalues of the companion matrix) give the
//!   eigenvalue pairs ±sqrt(μ). The unstable ones serve as shifts until as many eigenvalues as they number have
//!   deflated, then the stable ones join them (a stable eigenvalue that deflates early is
//!   matched against its estimate all the same, and an unstable estimate that matched nothing
//!   stays a candidate, chosen only if the trailing block comes near it). The unstable half
//!   thus deflates at the bottom first, and
//!   the form usually comes out already ordered with the stable eigenvalues leading, as the
//!   Riccati solver needs it, in fewer sweeps than with mirror images alone (below) and
//!   usually with no reordering swap. The estimates lose accuracy as the order grows (the roots of
//!   a polynomial are more sensitive than the eigenvalues of a matrix); a poor one only costs
//!   sweeps, and the Riccati solver's reordering puts right any eigenvalue left out of place.
//! - Without estimates (a polynomial that is not finite or a companion matrix whose QR
//!   iteration fails, an odd order, or a window that is not the whole matrix), the mirror
//!   images: once a block deflates, the mirror image -λ̄ of its eigenvalues is known to be an
//!   eigenvalue of the part still active.
//! - [`eigenvalues_near`] takes estimates the caller knows ([`Spectrum::Near`]): the requested
//!   poles of a placement, or the Hamiltonian's stable eigenvalues for the closed loop of a
//!   Riccati solution, which then converge in fewer sweeps.
//!
//! The single-window, double-shift iteration is the right tool at the orders of flight-control
//! models: at n = 4 it finds the eigenvalues in a fraction of the time of a general multishift
//! solver, whose set-up dominates at that size. From order 75 (`MULTISHIFT_MIN_ORDER`) on, the QR
//! iteration is instead the small-bulge multishift iteration with aggressive early deflation of
//! the `multishift` module (Braman, Byers & Mathias 2002, as LAPACK's dhseqr), whose sweeps do
//! most of their work in matrix products; it hands the active blocks it leaves below that order
//! back to the double-shift iteration. The known shifts of Hamiltonian spectra serve the
//! double-shift iteration only (the Riccati solver asks for them up to order 16).
//!
//! Since the Hamiltonian estimates deflate the unstable half first, the Riccati solver lets the
//! iteration stop there (`Until::UnstableHalf`): the leading columns of Z then span the stable
//! invariant subspace, and the leading block of T is left in Hessenberg form.
//!
//! Up to order 8 (`fixed_orders`: 2- to 4-state models, their Hamiltonians, augmented models)
//! the matrices are held on the stack with their order a compile-time constant (`Order`,
//! `Fixed`), so that index arithmetic folds and the column updates of a reflector run over
//! whole columns of constant length; the values are those of the run-time order bit for bit
//! (up to the sign of the zeros below the Hessenberg form).
//!
//! [`eigenvalues`] first balances A (Parlett & Reinsch 1969: a diagonal similarity by powers of
//! two that equalises row and column norms, exact in floating point), which can only improve
//! the computed eigenvalues of badly scaled matrices such as models in mixed units. The Schur
//! form itself is not balanced, since its Z must be orthogonal. Where the balanced states
//! are graded (their sizes spread over more than 2^20) they are ordered by decreasing size
//! (`balance::order_graded_states`: the QR iteration keeps the small eigenvalues of a matrix
//! graded downward), and where they are graded or the eigenvalues spread as far, the small
//! eigenvalues are refined to their own size by the two-sided Rayleigh quotient iteration
//! on the balanced matrix (`refine`), each kept only where it verifies; other matrices take
//! exactly the path they took before.

mod eigenvectors;
mod form;
mod francis;
pub(crate) mod multishift;
mod refine;
pub mod reorder;

pub use eigenvectors::schur_eigenvectors;
pub use form::{RealSchur, StandardBlock, quasi_triangular_eigenvalues, standardize_block};
pub use francis::Spectrum;
pub(crate) use francis::{Finished, Until, francis_qr, francis_qr_until};

use crate::error::{Error, check_finite, check_square};
use crate::linalg::balance::{GRADED_SPREAD, range_scale};
use crate::linalg::hessenberg::{
    UNBLOCKED_HESSENBERG_MAX_ORDER, balanced, hessenberg, hessenberg_matrix, reduce_in_place,
    reduce_to_hessenberg,
};
use crate::linalg::matrix::{
    FaerView, Order, Square, from_faer, from_faer_in, identity_in, with_order,
};
use faer::{MatRef, c64};
use form::block_eigenvalues;
use multishift::{MULTISHIFT_MIN_ORDER, schur_of_hessenberg};

// The unblocked orders take the double-shift iteration directly.
const _: () = assert!(UNBLOCKED_HESSENBERG_MAX_ORDER < MULTISHIFT_MIN_ORDER);

/// The real Schur form of a square, finite matrix.
pub fn real_schur(a: MatRef<'_, f64>) -> Result<RealSchur, Error> {
    real_schur_with(a, Spectrum::General)
}

/// The real Schur form of a square, finite matrix whose spectrum has the given structure.
pub fn real_schur_with(a: MatRef<'_, f64>, spectrum: Spectrum) -> Result<RealSchur, Error> {
    check_square(a, "A")?;
    with_order!(a.nrows(), order => {
        square_real_schur(from_faer_in(order, a), spectrum, Until::Complete)
            .map(|(schur, _)| schur)
    })
}

/// The eigenvalues of the real Schur form T of [`real_schur`], bit for bit and in the order
/// of its diagonal (each conjugate pair adjacent, Im > 0 first), without Z: the same reduction
/// and iteration, the transformations not accumulated. Below [`MULTISHIFT_MIN_ORDER`] the
/// double-shift iteration transforms only the active window (its entries, the shifts and the
/// deflations take the same operations as in the whole form); from that order the multishift
/// iteration forms all of T, since its path depends on whether it does. About half the work
/// of [`real_schur`] at order 64.
pub fn schur_form_eigenvalues(a: MatRef<'_, f64>) -> Result<Vec<c64>, Error> {
    check_square(a, "A")?;
    let n = a.nrows();
    with_order!(n, order => {
        schur_form_in(from_faer_in(order, a), Spectrum::General, Until::Complete, false)
            .map(|((t, _, scale), _)| block_eigenvalues(n, |i, j| t[(i, j)] * scale))
    })
}

/// [`real_schur_with`] of a matrix held as a [`Square`] (as the Riccati solver builds its
/// Hamiltonian), possibly partial (see [`Until`]; up to [`UNBLOCKED_HESSENBERG_MAX_ORDER`]):
/// checked finite, scaled into range, reduced by the unblocked Hessenberg reduction and the
/// double-shift iteration at the order type of `a` up to that order, by the blocked
/// reduction and the QR iteration of [`schur_of_hessenberg`] above it.
pub(crate) fn square_real_schur<O: Order>(
    a: Square<O>,
    spectrum: Spectrum,
    until: Until,
) -> Result<(RealSchur, Finished), Error> {
    square_schur_form(a, spectrum, until).map(|(schur, finished)| {
        let real_schur = RealSchur {
            t: schur.t.to_faer_scaled(schur.scale),
            z: schur.z.to_faer(),
        };
        (real_schur, finished)
    })
}

/// The (possibly partial) Schur form of [`square_schur_form`]: A = Z (s T) Z^T, held at the
/// order type of A.
pub(crate) struct SquareSchur<O: Order> {
    /// The Schur form of A / s.
    pub(crate) t: Square<O>,
    pub(crate) z: Square<O>,
    /// s, the power of two of [`range_scale`].
    pub(crate) scale: f64,
}

/// [`square_real_schur`] without the conversion to faer matrices, for a caller that reads a
/// few blocks of T and Z (the Riccati solver).
pub(crate) fn square_schur_form<O: Order>(
    a: Square<O>,
    spectrum: Spectrum,
    until: Until,
) -> Result<(SquareSchur<O>, Finished), Error> {
    schur_form_in(a, spectrum, until, true).map(|((t, z, scale), finished)| {
        let z = z.expect("Z is accumulated when asked for");
        (SquareSchur { t, z, scale }, finished)
    })
}

/// [`square_schur_form`] with Z accumulated only `with_z` (else None, and T formed only as
/// far as [`schur_form_eigenvalues`] needs it). The transformations of T are the same either
/// way: Z only receives them.
fn schur_form_in<O: Order>(
    mut a: Square<O>,
    spectrum: Spectrum,
    until: Until,
    with_z: bool,
) -> Result<(SquareSchurOf<O>, Finished), Error> {
    check_finite(a.as_faer(), "A")?;
    let n = a.nrows();
    let scale = range_scale(a.as_faer());
    if scale != 1.0 {
        a.as_mut_slice().iter_mut().for_each(|x| *x /= scale);
    }
    let order = a.shape_generic().0;
    let full = with_z || n >= MULTISHIFT_MIN_ORDER;
    if n <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        let mut z = with_z.then(|| identity_in(order));
        reduce_to_hessenberg(&mut a, z.as_mut());
        // The iteration works on A / scale.
        let until = match until {
            Until::UnstableHalf { margin } => Until::UnstableHalf {
                margin: margin / scale,
            },
            Until::Complete => Until::Complete,
        };
        let finished = francis_qr_until(
            &mut a,
            z.as_mut(),
            (0, n.saturating_sub(1)),
            full,
            spectrum,
            until,
        )?;
        Ok(((a, z, scale), finished))
    } else {
        // (Above the fixed orders: O is Dyn, and the copies back are O(n^2).)
        let (mut t, mut z) = if with_z {
            let reduced = hessenberg(a.as_faer())?;
            (
                from_faer(reduced.h.as_ref()),
                Some(from_faer(reduced.q.as_ref())),
            )
        } else {
            (from_faer(hessenberg_matrix(a.as_faer())?.as_ref()), None)
        };
        schur_of_hessenberg(&mut t, z.as_mut(), full, spectrum)?;
        let t = from_faer_in(order, t.as_faer());
        let z = z.map(|z| from_faer_in(order, z.as_faer()));
        Ok(((t, z, scale), Finished::Complete))
    }
}

/// T, Z (when accumulated) and the scale s of A = Z (s T) Z^T.
type SquareSchurOf<O> = (Square<O>, Option<Square<O>>, f64);

/// The eigenvalues of a square, finite matrix, in the order of the diagonal of its Schur form,
/// each conjugate pair adjacent with Im > 0 first (and exactly conjugate).
pub fn eigenvalues(a: MatRef<'_, f64>) -> Result<Vec<c64>, Error> {
    eigenvalues_with(a, Spectrum::General)
}

/// [`eigenvalues`], for a matrix whose eigenvalues are close to `estimates` (see
/// [`Spectrum::Near`]; the closed-loop eigenvalues of a design, for example).
pub fn eigenvalues_near(a: MatRef<'_, f64>, estimates: &[c64]) -> Result<Vec<c64>, Error> {
    eigenvalues_with(a, Spectrum::Near(estimates))
}

fn eigenvalues_with(a: MatRef<'_, f64>, spectrum: Spectrum<'_>) -> Result<Vec<c64>, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    let n = a.nrows();
    // A triangular matrix (an integrator chain, a cascade) has its diagonal as eigenvalues,
    // exactly; the QR iteration would split a repeated one by sqrt(u) ||A|| (a double
    // integrator's zeros came back as +-5e-9j).
    let upper = (0..n).all(|j| (j + 1..n).all(|i| a[(i, j)] == 0.0));
    let lower = upper || (0..n).all(|j| (0..j).all(|i| a[(i, j)] == 0.0));
    if upper || lower {
        return Ok((0..n).map(|k| c64::new(a[(k, k)], 0.0)).collect());
    }
    // Estimates are of the unscaled matrix's eigenvalues (and scaling is rare): dropped.
    let unscaled = |scale: f64| {
        if scale == 1.0 {
            spectrum
        } else {
            Spectrum::General
        }
    };
    if n <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        with_order!(n, order => {
            let (h, scale, graded) = balanced(from_faer_in(order, a));
            unblocked_eigenvalues(h, scale, graded, unscaled(scale))
        })
    } else {
        let (mut h, scale, _) = balanced(from_faer(a));
        reduce_in_place(&mut h)?;
        schur_of_hessenberg(&mut h, None, false, unscaled(scale))?;
        Ok(form_eigenvalues(&h, scale, None))
    }
}

/// The eigenvalues of s B for the balanced B of the unblocked orders (`graded`: whether its
/// states were graded), by the Hessenberg reduction and the double-shift iteration, B kept
/// for [`form_eigenvalues`].
fn unblocked_eigenvalues<O: Order>(
    b: Square<O>,
    scale: f64,
    graded: bool,
    spectrum: Spectrum<'_>,
) -> Result<Vec<c64>, Error> {
    let n = b.nrows();
    let mut h = b.clone();
    reduce_in_place(&mut h)?;
    francis_qr(&mut h, None, (0, n.saturating_sub(1)), false, spectrum)?;
    Ok(form_eigenvalues(&h, scale, Some((&b, graded))))
}

/// The eigenvalues of s T for the quasi-triangular T of the balanced B = D^-1 (A / s) D, those
/// of B (`balanced`: B, and whether its states were graded) refined first where its states
/// were graded or its eigenvalues' nonzero moduli span more than [`GRADED_SPREAD`]
/// ([`refine::refine_small_eigenvalues`]; the QR iteration's may then have lost more than
/// 2^20 u of the small ones).
fn form_eigenvalues<O: Order>(
    t: &Square<O>,
    scale: f64,
    balanced: Option<(&Square<O>, bool)>,
) -> Vec<c64> {
    let n = t.nrows();
    let mut values = block_eigenvalues(n, |i, j| t[(i, j)]);
    let spread = |values: &[c64]| {
        // Not spread, certainly, when the bounds max(|Re|, |Im|) <= |λ| <= |Re| + |Im| of the
        // nonzero moduli (finite, normal; with room for the rounding of the sum and of hypot)
        // are within the factor: the moduli themselves (hypot) only where they cannot decide,
        // which they then decide as before.
        let (mut lower, mut upper, mut finite) = (f64::INFINITY, 0.0f64, true);
        for v in values.iter().filter(|v| v.re != 0.0 || v.im != 0.0) {
            finite &= v.re.is_finite() && v.im.is_finite();
            lower = lower.min(v.re.abs().max(v.im.abs()));
            upper = upper.max(v.re.abs() + v.im.abs());
        }
        const ROOM: f64 = 1.0 + 1.0 / 1_099_511_627_776.0; // 1 + 2^-40
        if finite && lower >= f64::MIN_POSITIVE && upper * ROOM <= GRADED_SPREAD * (lower / ROOM) {
            return false;
        }
        let moduli = values.iter().map(|v| v.norm()).filter(|&m| m > 0.0);
        let (smallest, largest) =
            moduli.fold((f64::INFINITY, 0.0f64), |(s, l), m| (s.min(m), l.max(m)));
        largest > GRADED_SPREAD * smallest
    };
    match balanced {
        Some((b, graded)) if graded || spread(&values) => {
            refine::refine_small_eigenvalues(b, &mut values);
            values.iter_mut().for_each(|v| *v *= scale);
            values
        }
        _ if scale == 1.0 => values,
        _ => block_eigenvalues(n, |i, j| t[(i, j)] * scale),
    }
}

#[cfg(test)]
mod tests {
    use super::francis::{Mirrors, hamiltonian_estimates};
    use super::*;
    use crate::linalg::hessenberg::hessenberg_matrix;
    use crate::test_matrices::{lateral_747, lateral_747_inputs};
    use faer::Mat;
    use faer::linalg::solvers::DenseSolveCore;
    use faer::mat;
    use nalgebra::Dyn;

    use crate::test_matrices::seeded_square as seeded;

    fn assert_schur_form(a: &Mat<f64>, what: &str) {
        assert_structured_schur_form(a, Spectrum::General, what);
    }

    fn assert_structured_schur_form(a: &Mat<f64>, spectrum: Spectrum, what: &str) {
        let tolerance = 1e-14 * (a.nrows() as f64).max(1.0);
        assert_schur_form_within(a, spectrum, (tolerance, tolerance), what);
    }

    /// Checks the Schur form of `a` (||Z T Z^T - A||_2 / ||A||_2 and ||Z^T Z - I||_2 below the
    /// two `tolerances`, T quasi-triangular with standard blocks) and returns T.
    fn assert_schur_form_within(
        a: &Mat<f64>,
        spectrum: Spectrum,
        (residual_tolerance, orthogonality_tolerance): (f64, f64),
        what: &str,
    ) -> Mat<f64> {
        let n = a.nrows();
        let RealSchur { t, z } = real_schur_with(a.as_ref(), spectrum).unwrap();
        let scale = a.norm_l2().max(f64::MIN_POSITIVE);
        let residual = (&z * &t * z.transpose() - a).norm_l2() / scale;
        assert!(residual < residual_tolerance, "{what}: residual {residual}");
        let orthogonality = (z.transpose() * &z - Mat::<f64>::identity(n, n)).norm_l2();
        assert!(
            orthogonality < orthogonality_tolerance,
            "{what}: orthogonality {orthogonality}"
        );
        // Quasi-triangular, no two consecutive subdiagonal entries, blocks standard.
        for j in 0..n {
            for i in j + 2..n {
                assert_eq!(t[(i, j)], 0.0, "{what}: T[{i}, {j}]");
            }
        }
        for k in 0..n.saturating_sub(1) {
            if t[(k + 1, k)] != 0.0 {
                assert_eq!(t[(k, k)], t[(k + 1, k + 1)], "{what}: block {k} diagonal");
                assert!(
                    t[(k, k + 1)] * t[(k + 1, k)] < 0.0,
                    "{what}: block {k} signs"
                );
                if k + 2 < n {
                    assert_eq!(t[(k + 2, k + 1)], 0.0, "{what}: overlapping blocks at {k}");
                }
            }
        }
        t
    }

    /// The eigenvalues by the double-shift iteration alone, whatever the order: the reference
    /// for the multishift iteration.
    fn double_shift_eigenvalues(a: &Mat<f64>) -> Vec<c64> {
        let n = a.nrows();
        let mut h = from_faer(hessenberg_matrix(a.as_ref()).unwrap().as_ref());
        francis_qr(&mut h, None, (0, n - 1), false, Spectrum::General).unwrap();
        block_eigenvalues(n, |i, j| h[(i, j)])
    }

    /// The largest distance from an eigenvalue of `expected` to its partner in `found`, each
    /// found eigenvalue partnered once (nearest first).
    fn spectral_distance(found: &[c64], expected: &[c64]) -> f64 {
        crate::test_matrices::nearest_partners(found, expected)
            .iter()
            .map(|(y, x)| (x - y).norm())
            .fold(0.0, f64::max)
    }

    /// Q D Q^T with Q orthogonal (from a seeded QR) and D block diagonal with the given
    /// eigenvalues (pairs adjacent, Im > 0 first) as 1 x 1 and standard 2 x 2 blocks.
    fn with_spectrum(spectrum: &[c64], seed: u64) -> Mat<f64> {
        let n = spectrum.len();
        let q = seeded(n, seed).qr().compute_Q();
        let mut d = Mat::<f64>::zeros(n, n);
        let mut k = 0;
        while k < n {
            let lambda = spectrum[k];
            d[(k, k)] = lambda.re;
            if lambda.im != 0.0 {
                d[(k + 1, k + 1)] = lambda.re;
                d[(k, k + 1)] = lambda.im;
                d[(k + 1, k)] = -lambda.im;
                k += 2;
            } else {
                k += 1;
            }
        }
        &q * &d * q.transpose()
    }

    fn sorted(mut values: Vec<c64>) -> Vec<c64> {
        values.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
        values
    }

    /// Matrices near the ends of the floating-point range: scaled by a power of two into it,
    /// the form and the eigenvalues are those of the unscaled matrix times the scale (before,
    /// entries below about 1e-290 all counted as negligible and the residual was 0.7).
    #[test]
    fn couplings_whose_squares_are_subnormal_keep_the_form_orthogonal() {
        // Block lower triangular: eigenvalues ±3j and ±2j exactly. The Hessenberg form has
        // h11 = 5.5e-319 beside h10 = -h01 = 3, and the 2 x 2 block's rotation, formed from
        // a - d = -5.5e-319, was 1.7e-6 off orthogonal (±3j came back as ±2.999995j).
        for coupling in [1.26e-159, 1e-160, 3e-162, 1e-200, 1e-300] {
            let a = mat![
                [0.0, 3.0, 0.0, 0.0],
                [-3.0, 0.0, 0.0, 0.0],
                [-coupling, 1.05 * coupling, 0.0, 2.0],
                [0.0, 0.0, -2.0, 0.0],
            ];
            assert_schur_form(&a, &format!("coupling {coupling:e}"));
            let expected = sorted(vec![
                c64::new(0.0, 3.0),
                c64::new(0.0, -3.0),
                c64::new(0.0, 2.0),
                c64::new(0.0, -2.0),
            ]);
            let found = sorted(eigenvalues(a.as_ref()).unwrap());
            let distance = spectral_distance(&found, &expected);
            assert!(
                distance < 1e-14,
                "coupling {coupling:e}: off by {distance:e}"
            );
        }
    }

    #[test]
    fn tiny_and_huge_matrices_keep_their_schur_form() {
        for n in [6usize, 100] {
            let base = seeded(n, 7 + n as u64);
            let expected = sorted(eigenvalues(base.as_ref()).unwrap());
            for scale in [1e-300, 1e-200, 1e200, 1e300] {
                let a = &base * faer::Scale(scale);
                let RealSchur { t, z } = real_schur(a.as_ref()).unwrap();
                let unscale = faer::Scale(1.0 / scale);
                let residual = ((&z * (&t * unscale) * z.transpose()) - &base).norm_l2();
                assert!(
                    residual < 1e-13 * base.norm_l2(),
                    "n={n} scale={scale:e}: residual {residual:e}"
                );
                let found: Vec<c64> = sorted(eigenvalues(a.as_ref()).unwrap())
                    .iter()
                    .map(|lambda| lambda / scale)
                    .collect();
                let distance = spectral_distance(&found, &expected);
                assert!(
                    distance < 1e-12,
                    "n={n} scale={scale:e}: eigenvalues off by {distance:e}"
                );
            }
        }
    }

    #[test]
    fn random_matrices_reduce_to_standard_schur_form() {
        for n in [1usize, 2, 3, 4, 5, 8, 13, 30, 64] {
            for seed in 0..4 {
                assert_schur_form(
                    &seeded(n, seed * 100 + n as u64),
                    &format!("n={n} seed={seed}"),
                );
            }
        }
    }

    /// The bounds on ||Z T Z^T - A||_2 / ||A||_2 and ||Z^T Z - I||_2 of the multishift tests
    /// at order n: 5e-14, and 1e-15 n. Both iterations reach about 1e-14 and 4e-16 n on random
    /// matrices of orders 100 to 512 (the loss of orthogonality grows with the number of
    /// reflectors applied to Z, and forming Z^T Z alone costs about n u).
    fn multishift_tolerances(n: usize) -> (f64, f64) {
        (5e-14, 1e-15 * n as f64)
    }

    #[test]
    fn multishift_random_matrices_agree_with_the_double_shift_iteration() {
        // Orders from the crossover up: the Schur form, and the eigenvalues of both the Schur
        // form and `eigenvalues` against those of the double-shift iteration alone.
        for n in [MULTISHIFT_MIN_ORDER, 100, 160, 256, 401, 600] {
            let a = seeded(n, 1000 + n as u64);
            let what = format!("random n={n}");
            let t =
                assert_schur_form_within(&a, Spectrum::General, multishift_tolerances(n), &what);
            let reference = double_shift_eigenvalues(&a);
            let scale = a.norm_l2();
            let distance = spectral_distance(&quasi_triangular_eigenvalues(t.as_ref()), &reference);
            assert!(distance < 1e-10 * scale, "{what}: Schur form {distance}");
            let distance = spectral_distance(&eigenvalues(a.as_ref()).unwrap(), &reference);
            assert!(distance < 1e-10 * scale, "{what}: eigenvalues {distance}");
        }
    }

    #[test]
    fn multishift_finds_known_spectra() {
        // Distinct eigenvalues over five decades, complex pairs among them, in a non-normal
        // matrix Q (D + N) Q^T (N strictly upper triangular); and a normal matrix whose
        // eigenvalues are four values of multiplicity 60 (two real, a complex pair).
        let n = 300;
        let mut distinct = Vec::new();
        let mut k = 0;
        while k < n {
            let re = -1.0 - (k % 7) as f64 * 0.5 + if k % 3 == 0 { 1e-3 } else { 0.0 };
            if k + 1 < n && k % 4 == 0 {
                let im = 0.25 + k as f64 / 50.0;
                distinct.extend([c64::new(re, im), c64::new(re, -im)]);
                k += 2;
            } else {
                distinct.push(c64::new(re * 10f64.powi((k % 5) as i32 - 2), 0.0));
                k += 1;
            }
        }
        let q = seeded(n, 5).qr().compute_Q();
        let mut d = q.transpose() * with_spectrum(&distinct, 5) * &q;
        let upper = seeded(n, 6);
        for j in 0..n {
            for i in 0..j {
                if d[(i, j)] == 0.0 {
                    d[(i, j)] = 0.1 * upper[(i, j)];
                }
            }
        }
        let nonnormal = &q * &d * q.transpose();
        let repeated: Vec<c64> = (0..60)
            .flat_map(|_| {
                [
                    c64::new(1.0, 0.0),
                    c64::new(-2.0, 0.0),
                    c64::new(0.5, 1.0),
                    c64::new(0.5, -1.0),
                ]
            })
            .collect();
        let normal = with_spectrum(&repeated, 7);
        for (what, a, known, accuracy) in [
            ("distinct, non-normal", &nonnormal, &distinct, 1e-9),
            ("repeated, normal", &normal, &repeated, 1e-12),
        ] {
            let t = assert_schur_form_within(
                a,
                Spectrum::General,
                multishift_tolerances(a.nrows()),
                what,
            );
            let found = quasi_triangular_eigenvalues(t.as_ref());
            let distance = spectral_distance(&found, known);
            assert!(distance < accuracy * a.norm_l2(), "{what}: {distance}");
            let distance = spectral_distance(&eigenvalues(a.as_ref()).unwrap(), known);
            assert!(
                distance < accuracy * a.norm_l2(),
                "{what}: eigenvalues {distance}"
            );
        }
    }

    /// Matrices of order n whose structure is hard on the QR iteration: zero, the identity, a
    /// Jordan block, the cyclic shift (companion matrix of λ^n - 1: roots on the unit circle),
    /// a nilpotent upper triangle, and rotation blocks (±i, each repeated).
    fn structured_cases(n: usize) -> Vec<(&'static str, Mat<f64>)> {
        vec![
            ("zero", Mat::zeros(n, n)),
            ("identity", Mat::identity(n, n)),
            (
                "Jordan block",
                Mat::from_fn(n, n, |i, j| match j as isize - i as isize {
                    0 => 2.0,
                    1 => 1.0,
                    _ => 0.0,
                }),
            ),
            (
                "cyclic shift",
                Mat::from_fn(n, n, |i, j| if (i + 1) % n == j { 1.0 } else { 0.0 }),
            ),
            (
                "nilpotent upper",
                Mat::from_fn(n, n, |i, j| if j > i { 1.0 } else { 0.0 }),
            ),
            (
                "rotation blocks",
                Mat::from_fn(n, n, |i, j| match (i % 2, j as isize - i as isize) {
                    (0, 1) => 1.0,
                    (1, -1) => -1.0,
                    _ => 0.0,
                }),
            ),
        ]
    }

    #[test]
    fn multishift_handles_structured_and_graded_matrices() {
        let n = 150;
        let random = seeded(n, 77);
        let mut cases = structured_cases(n);
        cases.extend([
            (
                // Entries from 1 down to 1e-24 along the diagonal, growing away from it.
                "graded",
                Mat::from_fn(n, n, |i, j| {
                    random[(i, j)] * 10f64.powf(-12.0 * (i + j) as f64 / n as f64)
                }),
            ),
            (
                "graded the other way",
                Mat::from_fn(n, n, |i, j| {
                    random[(i, j)] * 10f64.powf(12.0 * (i + j) as f64 / n as f64 - 24.0)
                }),
            ),
        ]);
        for (what, a) in &cases {
            let t = assert_schur_form_within(
                a,
                Spectrum::General,
                multishift_tolerances(a.nrows()),
                what,
            );
            // Each eigenvalue against the double-shift iteration's, relative to its own size
            // for the graded ones (whose small eigenvalues are well determined).
            if what.starts_with("graded") {
                let found = quasi_triangular_eigenvalues(t.as_ref());
                let distance = spectral_distance(&found, &double_shift_eigenvalues(a));
                assert!(distance < 1e-10 * a.norm_l2(), "{what}: {distance}");
            }
        }
    }

    #[test]
    fn multishift_hamiltonian_spectra_are_symmetric() {
        // Hamiltonians of the Riccati solver's kind at orders 200, 300 and 512: the Schur form,
        // the eigenvalues against the double-shift iteration's, and the symmetry λ, -λ̄.
        for n in [100usize, 150, 256] {
            let a = Mat::from_fn(n, n, |i, j| {
                seeded(n, 3)[(i, j)] / (n as f64).sqrt() - if i == j { 1.5 } else { 0.0 }
            });
            let b = seeded(n, 4).subcols(0, 2).to_owned();
            let g = &b * b.transpose();
            let h = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                (true, true) => a[(i, j)],
                (true, false) => -g[(i, j - n)],
                (false, true) => -(if i - n == j { 1.0 } else { 0.0 }),
                (false, false) => -a[(j - n, i - n)],
            });
            let what = format!("Hamiltonian n={n}");
            let t = assert_schur_form_within(
                &h,
                Spectrum::Hamiltonian,
                multishift_tolerances(n),
                &what,
            );
            let found = quasi_triangular_eigenvalues(t.as_ref());
            let scale = h.norm_l2();
            let distance = spectral_distance(&found, &double_shift_eigenvalues(&h));
            assert!(distance < 1e-10 * scale, "{what}: {distance}");
            let mirrored: Vec<c64> = found.iter().map(|x| c64::new(-x.re, x.im)).collect();
            let distance = spectral_distance(&found, &mirrored);
            assert!(distance < 1e-10 * scale, "{what}: symmetry {distance}");
        }
    }

    #[test]
    fn multishift_handles_skew_symmetric_matrices() {
        // Eigenvalues in pairs ±iω (and 0 at odd orders): the double-shift iteration can stall
        // on the blocks the multishift one leaves it, which then takes them on itself (it does
        // for (84, 2), (115, 0) and (152, 0), found by a search over orders 75-230).
        let cases = [
            (75usize, 0u64),
            (84, 2),
            (115, 0),
            (121, 1),
            (152, 0),
            (200, 3),
        ];
        for (n, seed) in cases {
            let g = seeded(n, 40 * seed + n as u64);
            let a = Mat::from_fn(n, n, |i, j| g[(i, j)] - g[(j, i)]);
            let what = format!("skew-symmetric n={n} seed={seed}");
            let t =
                assert_schur_form_within(&a, Spectrum::General, multishift_tolerances(n), &what);
            let found = quasi_triangular_eigenvalues(t.as_ref());
            assert!(
                found.iter().all(|x| x.re.abs() < 1e-12 * a.norm_l2()),
                "{what}: real parts"
            );
            let values = eigenvalues(a.as_ref()).unwrap();
            let distance = spectral_distance(&values, &found);
            assert!(
                distance < 1e-10 * a.norm_l2(),
                "{what}: eigenvalues {distance}"
            );
        }
    }

    #[test]
    fn structured_matrices_reduce_to_standard_schur_form() {
        let n = 12;
        let mut cases = structured_cases(n);
        cases.push((
            "graded",
            Mat::from_fn(n, n, |i, j| {
                10f64.powi(i as i32 - j as i32) * ((i + 2 * j) % 5) as f64
            }),
        ));
        for (what, a) in &cases {
            assert_schur_form(a, what);
        }
    }

    #[test]
    fn hamiltonian_matrices_reduce_to_standard_schur_form_with_known_shifts() {
        // Real, complex and clustered pairs. The estimated shifts degrade with the order (at
        // n = 24 a polynomial of degree 48): poor ones must cost sweeps only.
        for n in [1usize, 2, 3, 4, 6, 10, 24] {
            for seed in 0..6 {
                let h = seeded_hamiltonian(n, seed);
                let what = format!("Hamiltonian n={n} seed={seed}");
                assert_structured_schur_form(&h, Spectrum::Hamiltonian, &what);
                let t = real_schur_with(h.as_ref(), Spectrum::Hamiltonian)
                    .unwrap()
                    .t;
                let ours = sorted(quasi_triangular_eigenvalues(t.as_ref()));
                let general = sorted(eigenvalues(h.as_ref()).unwrap());
                for (x, y) in ours.iter().zip(&general) {
                    assert!((x - y).norm() < 1e-10 * h.norm_l2(), "{what}: {x} vs {y}");
                }
            }
        }
    }

    /// [[A, -B B^T], [-C^T C, -A^T]] from seeded A, B, C.
    fn seeded_hamiltonian(n: usize, seed: u64) -> Mat<f64> {
        let a = seeded(n, 11 * seed + n as u64);
        let b = seeded(n, 13 * seed + 1);
        let c = seeded(n, 17 * seed + 2);
        let (g, q) = (&b * b.transpose(), c.transpose() * &c);
        Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => a[(i, j)],
            (true, false) => -g[(i, j - n)],
            (false, true) => -q[(i - n, j)],
            (false, false) => -a[(j - n, i - n)],
        })
    }

    #[test]
    fn hamiltonian_estimates_are_the_stable_eigenvalues() {
        for n in [1usize, 2, 3, 4, 6] {
            for seed in 0..6 {
                let h = seeded_hamiltonian(n, seed);
                let mut hessenberg = from_faer(h.as_ref());
                reduce_to_hessenberg(&mut hessenberg, None);
                let estimates = hamiltonian_estimates(&hessenberg);
                let stable: Vec<c64> = eigenvalues(h.as_ref())
                    .unwrap()
                    .into_iter()
                    .filter(|z| z.re < 0.0 && z.im >= 0.0)
                    .collect();
                let distance = spectral_distance(&sorted(estimates), &sorted(stable));
                assert!(
                    distance < 1e-9 * h.norm_l2(),
                    "n={n} seed={seed}: {distance:e}"
                );
            }
        }
        // Odd orders are not Hamiltonian (the polynomial of I_3 is not even; read as one it
        // would give an estimate).
        assert!(hamiltonian_estimates(&nalgebra::DMatrix::<f64>::identity(3, 3)).is_empty());
    }

    /// The Hamiltonian [[A, G], [Q, -A^T]] of order 2n from its blocks.
    fn hamiltonian(a: &Mat<f64>, g: &Mat<f64>, q: &Mat<f64>) -> Mat<f64> {
        let n = a.nrows();
        Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => a[(i, j)],
            (true, false) => g[(i, j - n)],
            (false, true) => q[(i - n, j)],
            (false, false) => -a[(j - n, i - n)],
        })
    }

    /// Eigenvalues on the imaginary axis (a root μ < 0 of q) are estimated once, not as an
    /// unstable and a stable estimate of the same eigenvalue; and the form still converges.
    #[test]
    fn imaginary_axis_estimates_are_pending_once() {
        // A = diag(0, -1), G = diag(1, 0), Q = diag(-4, -3): eigenvalues ±2i and ±1.
        let a = Mat::from_fn(2, 2, |i, j| if (i, j) == (1, 1) { -1.0 } else { 0.0 });
        let g = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 0) { 1.0 } else { 0.0 });
        let q = Mat::from_fn(2, 2, |i, j| [[-4.0, 0.0], [0.0, -3.0]][i][j]);
        // An orthogonal symplectic similarity (a rotation of each state with its co-state)
        // makes the Hessenberg form non-trivial.
        let (c, s) = (0.6, 0.8);
        let rotation = Mat::from_fn(4, 4, |i, j| match (i % 2 == j % 2, i / 2 == j / 2) {
            (true, true) => c,
            (true, false) => {
                if i < j {
                    s
                } else {
                    -s
                }
            }
            _ => 0.0,
        });
        let h = rotation.transpose() * hamiltonian(&a, &g, &q) * &rotation;
        let mut hessenberg = from_faer(h.as_ref());
        reduce_to_hessenberg(&mut hessenberg, None);
        let mirrors = Mirrors::for_spectrum(Spectrum::Hamiltonian, Some(&hessenberg)).unwrap();
        assert_eq!(mirrors.pending.len(), 2, "{:?}", mirrors.pending);
        assert_eq!(mirrors.later.len(), 1, "{:?}", mirrors.later);
        assert!((mirrors.later[0] - c64::new(-1.0, 0.0)).norm() < 1e-12);
        let t = real_schur_with(h.as_ref(), Spectrum::Hamiltonian)
            .unwrap()
            .t;
        let found = sorted(quasi_triangular_eigenvalues(t.as_ref()));
        let expected = sorted(vec![
            c64::new(0.0, 2.0),
            c64::new(0.0, -2.0),
            c64::new(-1.0, 0.0),
            c64::new(1.0, 0.0),
        ]);
        assert!(spectral_distance(&found, &expected) < 1e-7, "{found:?}");
    }

    /// A double root of q (a Jordan block in A, with Q = 0): the estimates repeat, and the
    /// form still comes out with the stable pair leading.
    #[test]
    fn repeated_estimates_are_each_spent() {
        let a = faer::mat![[-1.0, 1.0], [0.0, -1.0]];
        let g = Mat::<f64>::identity(2, 2);
        let h = hamiltonian(&a, &g, &Mat::zeros(2, 2));
        let t = real_schur_with(h.as_ref(), Spectrum::Hamiltonian)
            .unwrap()
            .t;
        let values = quasi_triangular_eigenvalues(t.as_ref());
        // A defective double eigenvalue is found to about sqrt(u).
        for (k, value) in values.iter().enumerate() {
            let expected = if k < 2 { -1.0 } else { 1.0 };
            assert!(
                (value - c64::new(expected, 0.0)).norm() < 1e-7,
                "{values:?}"
            );
        }
    }

    /// With the unstable estimates as the first shifts, the unstable half deflates at the
    /// bottom and the Schur form needs no reordering (a performance property of these
    /// well-separated cases; the Riccati solver reorders whatever comes out).
    #[test]
    fn hamiltonian_schur_form_comes_out_ordered() {
        let (lateral, b) = (lateral_747(), lateral_747_inputs());
        let g = &b * b.transpose();
        let h747 = Mat::from_fn(8, 8, |i, j| match (i < 4, j < 4) {
            (true, true) => lateral[(i, j)],
            (true, false) => -g[(i, j - 4)],
            (false, true) => -f64::from(u8::from(i == j + 4)),
            (false, false) => -lateral[(j - 4, i - 4)],
        });
        let mut cases = vec![("747 lateral, Q = I, R = I".to_owned(), h747)];
        for seed in 0..4 {
            cases.push((
                format!("random n=3 seed={seed}"),
                seeded_hamiltonian(3, seed),
            ));
        }
        for (what, h) in &cases {
            let n = h.nrows() / 2;
            let t = real_schur_with(h.as_ref(), Spectrum::Hamiltonian)
                .unwrap()
                .t;
            let values = quasi_triangular_eigenvalues(t.as_ref());
            assert!(
                values[..n].iter().all(|z| z.re < 0.0) && values[n..].iter().all(|z| z.re > 0.0),
                "{what}: {values:?}"
            );
        }
    }

    /// A Schur form stopped once the unstable half deflated: Z orthogonal, H Z = Z T, T's
    /// trailing block quasi-triangular with the unstable eigenvalues, zeros below the leading
    /// Hessenberg block, and Z's leading columns spanning the stable invariant subspace of the
    /// complete, reordered form. Of these random Hamiltonians of orders 2 to 16, 42 of 48 stop
    /// early with the Hamiltonian estimates and 7 of 48 with general shifts; the others go on
    /// to the complete form, which must then equal the one formed without stopping.
    #[test]
    fn schur_form_stops_once_the_unstable_half_deflated() {
        let mut stopped = [0, 0];
        for (n, seed, spectrum) in (1..=8usize).flat_map(|n| {
            (0..6u64).flat_map(move |seed| {
                [
                    (n, seed, Spectrum::Hamiltonian),
                    (n, seed, Spectrum::General),
                ]
            })
        }) {
            let h = seeded_hamiltonian(n, seed);
            let what = format!("n={n} seed={seed} {spectrum:?}");
            let margin = crate::control::riccati::care::AXIS_TOLERANCE * h.norm_l2();
            let (schur, finished) = with_order!(2 * n, order => square_real_schur(
                from_faer_in(order, h.as_ref()),
                spectrum,
                Until::UnstableHalf { margin },
            ))
            .unwrap();
            let (t, z) = (&schur.t, &schur.z);
            let identity = Mat::<f64>::identity(2 * n, 2 * n);
            assert!((z.transpose() * z - &identity).norm_max() < 1e-14, "{what}");
            assert!((&h * z - z * t).norm_max() < 1e-13 * h.norm_l2(), "{what}");
            let complete = reorder_stable_first(&h, spectrum);
            if finished == Finished::Complete {
                assert_eq!(
                    schur.t,
                    real_schur_with(h.as_ref(), spectrum).unwrap().t,
                    "{what}"
                );
                continue;
            }
            stopped[usize::from(spectrum == Spectrum::General)] += 1;
            for j in 0..2 * n {
                for i in j + 2..2 * n {
                    assert_eq!(t[(i, j)], 0.0, "{what}: below the Hessenberg form");
                }
            }
            assert_eq!(t[(n, n - 1)], 0.0, "{what}: the halves are decoupled");
            let unstable = quasi_triangular_eigenvalues(t.as_ref().submatrix(n, n, n, n));
            assert!(
                unstable.iter().all(|z| z.re > margin),
                "{what}: {unstable:?}"
            );
            // The same subspace: equal orthogonal projectors onto it.
            let projector = |u: MatRef<'_, f64>| u * u.transpose();
            let difference = (projector(z.as_ref().subcols(0, n))
                - projector(complete.as_ref().subcols(0, n)))
            .norm_max();
            assert!(
                difference < 1e-11,
                "{what}: subspaces differ by {difference:e}"
            );
        }
        assert!(
            stopped[0] >= 40,
            "Hamiltonian estimates: stopped {} of 48",
            stopped[0]
        );
    }

    /// The Schur vectors of H with the stable eigenvalues first.
    fn reorder_stable_first(h: &Mat<f64>, spectrum: Spectrum) -> Mat<f64> {
        let schur = real_schur_with(h.as_ref(), spectrum).unwrap();
        crate::linalg::schur::reorder::reorder_schur(schur, |z| z.re < 0.0)
            .unwrap()
            .z
    }

    /// Estimates only steer the shifts: exact, perturbed, wrong or partial ones all give the
    /// eigenvalues the plain iteration gives.
    #[test]
    fn estimates_steer_the_shifts_but_not_the_eigenvalues() {
        for n in [2usize, 4, 7, 12, 40] {
            for seed in 0..5 {
                let a = seeded(n, 1000 + 10 * n as u64 + seed);
                let reference = sorted(eigenvalues(a.as_ref()).unwrap());
                let scale = a.norm_l2();
                let perturbed: Vec<c64> = reference
                    .iter()
                    .map(|z| z * (1.0 + 1e-3) + c64::new(1e-4, 0.0))
                    .collect();
                let wrong: Vec<c64> = (0..n).map(|k| c64::new(k as f64 * 10.0, 0.0)).collect();
                let partial = &reference[..n / 2];
                let non_finite = [c64::new(f64::NAN, 0.0), c64::new(f64::INFINITY, 1.0)];
                for (what, estimates) in [
                    ("non-finite", &non_finite[..]),
                    ("exact", &reference[..]),
                    ("perturbed", &perturbed[..]),
                    ("wrong", &wrong[..]),
                    ("partial", partial),
                    ("none", &[][..]),
                ] {
                    let found = sorted(eigenvalues_near(a.as_ref(), estimates).unwrap());
                    let distance = spectral_distance(&found, &reference);
                    assert!(
                        distance < 1e-12 * scale,
                        "n={n} seed={seed} {what}: off by {distance:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn unstable_estimates_are_spent_before_stable_ones() {
        let mut mirrors = Mirrors {
            pending: vec![c64::new(1.0, 0.0), c64::new(0.5, 2.0)],
            later: vec![c64::new(-1.0, 0.0), c64::new(-0.5, 2.0)],
            deflations_before_later: 2,
            mirrored: false,
        };
        let trailing = [c64::new(-1.0, 0.0), c64::new(-0.9, 0.0)];
        // The stable -1 is nearer the trailing block, but unstable estimates come first.
        assert_eq!(
            mirrors.shifts(trailing),
            Some((c64::new(1.0, 0.0), c64::new(1.0, 0.0)))
        );
        mirrors.found(c64::new(1.0, 1e-9));
        mirrors.found(c64::new(0.5, 2.0));
        assert_eq!(
            mirrors.shifts(trailing),
            Some((c64::new(-1.0, 0.0), c64::new(-1.0, 0.0)))
        );
        // An eigenvalue that matches no estimate changes nothing.
        mirrors.found(c64::new(7.0, 0.0));
        assert_eq!(mirrors.pending.len(), 2);
        assert!(mirrors.later.is_empty());
    }

    /// Deflations out of order: a stable eigenvalue that deflates while the unstable
    /// estimates are pending is struck from the stable ones, and an unstable estimate that
    /// matched nothing does not hold the stable ones back.
    #[test]
    fn stale_estimates_do_not_block_the_stable_half() {
        let mut mirrors = Mirrors {
            pending: vec![c64::new(1.0, 0.0), c64::new(0.5, 2.0)],
            later: vec![c64::new(-1.0, 0.0), c64::new(-0.5, 2.0)],
            deflations_before_later: 2,
            mirrored: false,
        };
        mirrors.found(c64::new(-0.5, 2.0));
        assert_eq!(mirrors.later, vec![c64::new(-1.0, 0.0)]);
        // The unstable 0.5 + 2i deflates as 0.5 + 2.1i, too far off to match; the two
        // deflations bring in the rest of the stable half.
        mirrors.found(c64::new(0.5, 2.1));
        assert!(mirrors.later.is_empty());
        assert_eq!(
            mirrors.pending,
            vec![c64::new(1.0, 0.0), c64::new(0.5, 2.0), c64::new(-1.0, 0.0)]
        );
        // Chosen by proximity: near the stable -1, the stale estimates are not spent.
        assert_eq!(
            mirrors.shifts([c64::new(-0.9, 0.0), c64::new(-0.2, 0.0)]),
            Some((c64::new(-1.0, 0.0), c64::new(1.0, 0.0)))
        );
    }

    #[test]
    fn mirror_images_are_paired_off() {
        let mut mirrors = Mirrors::for_spectrum::<Dyn>(Spectrum::Hamiltonian, None).unwrap();
        let trailing = |a: f64, b: f64| [c64::new(a, b), c64::new(a, -b)];
        mirrors.found(c64::new(0.5, 0.0));
        mirrors.found(c64::new(-0.3, 0.8));
        // Pending: -0.5 and 0.3 ± 0.8i; the one nearer the trailing block's eigenvalues.
        assert_eq!(
            mirrors.shifts(trailing(0.2, 0.7)),
            Some((c64::new(0.3, 0.8), c64::new(0.3, -0.8)))
        );
        assert_eq!(
            mirrors.shifts(trailing(-0.4, 0.1)),
            Some((c64::new(-0.5, 0.0), c64::new(-0.5, 0.0)))
        );
        mirrors.found(c64::new(0.3, 0.8));
        assert_eq!(
            mirrors.shifts(trailing(0.2, 0.7)),
            Some((c64::new(-0.5, 0.0), c64::new(-0.5, 0.0)))
        );
        // Two real ones pending: both, nearest first.
        mirrors.found(c64::new(2.0, 0.0));
        assert_eq!(
            mirrors.shifts([c64::new(-1.9, 0.0), c64::new(0.0, 0.0)]),
            Some((c64::new(-2.0, 0.0), c64::new(-0.5, 0.0)))
        );
        assert_eq!(
            mirrors.shifts([c64::new(-0.6, 0.0), c64::new(-1.0, 0.0)]),
            Some((c64::new(-0.5, 0.0), c64::new(-2.0, 0.0)))
        );
        mirrors.found(c64::new(-0.5, 0.0));
        mirrors.found(c64::new(-2.0, 0.0));
        assert_eq!(mirrors.shifts(trailing(0.2, 0.7)), None);
    }

    #[test]
    fn eigenvalues_agree_with_faer() {
        for n in [2usize, 3, 4, 7, 16, 40] {
            let a = seeded(n, 7 * n as u64);
            let ours = sorted(eigenvalues(a.as_ref()).unwrap());
            let theirs = sorted(a.eigenvalues().unwrap());
            for (x, y) in ours.iter().zip(&theirs) {
                assert!((x - y).norm() < 1e-12 * (n as f64), "n={n}: {x} vs {y}");
            }
        }
    }

    #[test]
    fn eigenvalues_of_the_747_lateral_model() {
        // (6.150), (6.152).
        let a = lateral_747();
        let values = eigenvalues(a.as_ref()).unwrap();
        let expected = [
            c64::new(-0.08066, 0.7433),
            c64::new(-1.2308, 0.0),
            c64::new(-0.04641, 0.0),
        ];
        for e in expected {
            assert!(
                values.iter().any(|v| (v - e).norm() < 2e-4),
                "{e} in {values:?}"
            );
        }
        // Pairs adjacent, Im > 0 first, exactly conjugate.
        let k = values.iter().position(|v| v.im != 0.0).unwrap();
        assert!(values[k].im > 0.0 && values[k + 1] == values[k].conj());
    }

    #[test]
    fn balancing_recovers_eigenvalues_of_a_badly_scaled_matrix() {
        // D^-1 M D with D = diag(1, 1e6, 1e-6): the eigenvalues of M are 1, 2, 3.
        let d = [1.0, 1e6, 1e-6];
        let m = mat![[1.0, 1.0, 1.0], [0.0, 2.0, 1.0], [0.0, 0.0, 3.0]];
        let p = mat![[1.0, 0.5, 0.25], [0.3, 1.0, 0.7], [0.2, 0.1, 1.0]];
        let similar = &p * &m * p.partial_piv_lu().inverse();
        let a = Mat::from_fn(3, 3, |i, j| similar[(i, j)] * d[j] / d[i]);
        let values = sorted(eigenvalues(a.as_ref()).unwrap());
        for (v, e) in values.iter().zip([1.0, 2.0, 3.0]) {
            assert!((v.re - e).abs() < 1e-12 && v.im == 0.0, "{v} vs {e}");
        }
    }

    #[test]
    fn standard_blocks() {
        let cases = [
            (1.0, 2.0, 3.0, 4.0),        // real eigenvalues
            (1.0, -2.0, 3.0, 4.0),       // complex
            (0.0, 1.0, -1.0, 0.0),       // already standard
            (2.0, 0.0, 5.0, 3.0),        // b = 0: swap
            (1.0, 1e-20, -1e-20, 1.0),   // tiny coupling
            (1e300, 1e300, -1e300, 0.0), // large entries
            (3.0, 1.0, 1e-18, 3.0),      // nearly equal real eigenvalues
        ];
        for (a, b, c, d) in cases {
            let s = standardize_block(a, b, c, d);
            let g = mat![[s.cs, -s.sn], [s.sn, s.cs]];
            let m = mat![[a, b], [c, d]];
            let rotated = g.transpose() * &m * &g;
            let scale = m.norm_l2();
            let result = mat![[s.a, s.b], [s.c, s.d]];
            assert!(
                (&rotated - &result).norm_l2() <= 4e-16 * scale,
                "{a} {b} {c} {d}: {s:?}"
            );
            assert!((s.cs * s.cs + s.sn * s.sn - 1.0).abs() < 4e-16);
            assert!(s.c == 0.0 || (s.a == s.d && s.b * s.c < 0.0), "{s:?}");
        }
    }
}
