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
//! over the gains. (The previous gain's poles as shift estimates, [`Spectrum::Near`], did not
//! reduce the number of sweeps: about 10 per gain at n = 6 either way.)
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
//! Reference: G. H. Golub and C. F. Van Loan, *Matrix Computations*, 4th ed., 2013, §7.4-7.5
//! (the Hessenberg reduction and the Francis double-shift iteration); the controller-Hessenberg
//! form of a single-input system is that of §7.4.8's staircase with one input.

use crate::error::{Error, check_finite, check_finite_values, check_output_len, check_square};
use crate::linalg::balance::range_scale;
use crate::linalg::hessenberg::reduce_to_hessenberg;
use crate::linalg::householder::reflector;
use crate::linalg::matrix::{
    FaerView, Order, Square, Transformations, from_faer_in, identity_in, with_order,
};
use crate::linalg::schur::{Spectrum, eigenvalues, francis_qr, quasi_triangular_eigenvalues};
use crate::platform::parallel::{ParallelContext, par_chunks};
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
/// form (see the module's documentation): normwise backward stable, and the same as
/// [`root_locus`] gives at that gain.
pub fn closed_loop_poles(
    a: MatRef<'_, f64>,
    b: &[f64],
    c: &[f64],
    g: f64,
) -> Result<Vec<c64>, Error> {
    let n = a.nrows();
    if g == 0.0 || n == 0 {
        return eigenvalues(a);
    }
    with_order!(n, order => closed_loop_eigenvalues(&controller_hessenberg(order, a, b, c), g))
}

/// Sorted by real part, then imaginary part (as `numpy.sort_complex`).
fn sorted(mut values: Vec<c64>) -> Vec<c64> {
    values.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
    values
}

/// The closed-loop poles of the SISO loop (A n x n, b n x 1, c 1 x n) at each closed-loop gain
/// g of `gains` (the eigenvalues of A - g b c), written into `out` (n per gain, sorted by real
/// part, then imaginary part, as `numpy.sort_complex`), in parallel over chunks of gains. See
/// the module's documentation.
pub fn root_locus(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    gains: &[f64],
    out: &mut [c64],
) -> Result<(), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
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
    let context = ParallelContext::capture(0);
    with_order!(n, order => {
        let form = controller_hessenberg(order, a, &bv, &cv);
        par_chunks(out, n, gains.len())
            .zip(gains.par_iter())
            .enumerate()
            .try_for_each(|(index, (poles, &g))| {
                context.run(|| {
                    if g == 0.0 {
                        poles.copy_from_slice(&open_loop);
                    } else {
                        let values = closed_loop_eigenvalues(&form, g)
                            .map_err(|e| Error::in_batch(index, e))?;
                        poles.copy_from_slice(&sorted(values));
                    }
                    Ok(())
                })
            })
    })
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
}
