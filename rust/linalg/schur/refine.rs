//! The small eigenvalues of a graded matrix refined to their own size.
//!
//! The QR iteration is backward stable normwise: an eigenvalue comes out accurate to about
//! u ||B|| κ(λ), all of its digits for a λ of u ||B||. The states ordered by decreasing size
//! ([`crate::linalg::balance::order_graded_states`]) keep most small eigenvalues of a graded
//! matrix, not all (a companion matrix of roots spread over twenty decades lost up to 6e-6 of
//! its small ones, a diagonal of twenty decades plus a rank-one term all of them). Each
//! eigenvalue of B (balanced and ordered, of order up to [`REFINED_MAX_ORDER`], whose states
//! are graded or whose eigenvalues spread over more than 2^20: `eigenvalues` decides) below
//! 1 / [`REFINED_BELOW`] of the largest is therefore refined by the two-sided Rayleigh
//! quotient iteration (Ostrowski 1958/59; Parlett, "The Rayleigh quotient iteration and some
//! generalizations for nonnormal matrices", Math. Comp. 28, 1974): from σ = λ, the right and
//! left vectors x, y by two steps of inverse iteration each on B - σI (LU with partial
//! pivoting, complex for a complex σ), then
//!
//! ```text
//!     σ <- σ + y^H (B x - σ x) / y^H x,
//! ```
//!
//! at most [`RAYLEIGH_STEPS`] times, until it converges (below). The residual
//! B x - σ x, formed in floating point, errs by u (|B| + |σ| I)|x| componentwise, so the
//! correction errs by about u |y|^T (|B| + |σ| I) |x| / |y^H x|: the componentwise condition
//! of λ times u |λ|, the size of the eigenvalue itself where λ is well conditioned in the
//! relative sense (as it is in graded matrices: Demmel & Veselić 1992, Stewart & Zhang 1991).
//!
//! **Verification.** A refined value replaces the QR iteration's only where (1) the iteration
//! converged, its last correction at most [`CONVERGED_ULPS`] n u |σ| (a fixed point of the
//! two-sided Rayleigh quotient, x and y then the right and left null vectors of B - σI to
//! first order), (2) it is within sqrt(u) ||B||_F of the QR value (the QR iteration's error
//! bound for a double eigenvalue: the iteration did not wander to another eigenvalue), and
//! (3) no other refined value is within 8 u |σ| of it (two starts converged to one
//! eigenvalue); else the QR value stays. A real eigenvalue stays real, a pair stays
//! conjugate (its upper member refined).

use crate::linalg::matrix::{Order, Square};
use faer::c64;

/// Eigenvalues below 1 / this of the largest are refined (the QR iteration's relative error in
/// them can exceed 2^10 u).
const REFINED_BELOW: f64 = 1024.0;

/// Rayleigh quotient steps per eigenvalue, at most (the iteration converges cubically).
const RAYLEIGH_STEPS: usize = 4;

/// The last correction of a converged iteration, in units of n u |σ| (the correction itself
/// errs by u κ |σ| for a componentwise relative condition κ; after a correction this small,
/// the cubic convergence leaves the rounding alone).
const CONVERGED_ULPS: f64 = 1024.0;

/// The largest order refined: each eigenvalue costs a few LU factorisations, O(n^3).
const REFINED_MAX_ORDER: usize = 32;

/// Refines the eigenvalues `values` of B (as [`super::form::block_eigenvalues`] orders them:
/// pairs adjacent, Im > 0 first) that lie below 1 / [`REFINED_BELOW`] of the largest (see the
/// module's documentation), in place; B of order above [`REFINED_MAX_ORDER`] is left alone.
pub(crate) fn refine_small_eigenvalues<O: Order>(b: &Square<O>, values: &mut [c64]) {
    let n = b.nrows();
    if n > REFINED_MAX_ORDER {
        return;
    }
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.norm()));
    let size = b.as_slice().iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(largest.is_finite() && size.is_finite()) || n < 2 {
        return;
    }
    let entries: Vec<c64> = b.as_slice().iter().map(|&x| c64::new(x, 0.0)).collect();
    let mut refined: Vec<(usize, c64)> = Vec::new();
    let mut k = 0;
    while k < values.len() {
        let value = values[k];
        let pair = value.im > 0.0 && k + 1 < values.len();
        if value.norm() * REFINED_BELOW < largest
            && let Some(better) = rayleigh(&entries, n, value, size)
        {
            refined.push((k, better));
        }
        k += if pair { 2 } else { 1 };
    }
    for (i, &(k, better)) in refined.iter().enumerate() {
        let apart = refined.iter().enumerate().all(|(j, &(_, other))| {
            j == i || (other - better).norm() > 8.0 * f64::EPSILON * better.norm()
        });
        if !apart {
            continue;
        }
        if values[k].im > 0.0 && k + 1 < values.len() {
            values[k] = better;
            values[k + 1] = better.conj();
        } else {
            values[k] = c64::new(better.re, 0.0);
        }
    }
}

/// The two-sided Rayleigh quotient iteration from σ on the column-major n x n `b` (see the
/// module's documentation), None where it fails its checks.
fn rayleigh(b: &[c64], n: usize, start: c64, size: f64) -> Option<c64> {
    let real = start.im == 0.0;
    let mut sigma = start;
    for _ in 0..RAYLEIGH_STEPS {
        let lu = Lu::of(b, n, sigma, size)?;
        let mut x = vec![c64::new(1.0, 0.0); n];
        let mut y = x.clone();
        for _ in 0..2 {
            lu.solve(&mut x);
            normalise(&mut x)?;
            lu.solve_adjoint(&mut y);
            normalise(&mut y)?;
        }
        let residual = residual(b, n, sigma, &x);
        let numerator: c64 = y.iter().zip(&residual).map(|(u, r)| u.conj() * r).sum();
        let denominator: c64 = y.iter().zip(&x).map(|(u, v)| u.conj() * v).sum();
        let correction = numerator / denominator;
        let next = sigma + correction;
        if !(next.re.is_finite() && next.im.is_finite()) {
            return None;
        }
        sigma = if real { c64::new(next.re, 0.0) } else { next };
        if correction.norm() <= CONVERGED_ULPS * n as f64 * f64::EPSILON * sigma.norm() {
            let near = (sigma - start).norm() <= f64::EPSILON.sqrt() * size;
            return (near && (real || sigma.im > 0.0)).then_some(sigma);
        }
    }
    None
}

/// B x - σ x.
fn residual(b: &[c64], n: usize, sigma: c64, x: &[c64]) -> Vec<c64> {
    (0..n)
        .map(|i| (0..n).map(|j| b[i + j * n] * x[j]).sum::<c64>() - sigma * x[i])
        .collect()
}

/// Divides v by its largest |entry|; None where that is 0 or not finite.
fn normalise(v: &mut [c64]) -> Option<()> {
    let largest = v.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    v.iter_mut().for_each(|z| *z /= largest);
    Some(())
}

/// P (B - σI) = L U by partial pivoting, column-major; a zero pivot (σ an eigenvalue to
/// working precision) replaced by u |σ| (u ||B||_F for σ = 0): inverse iteration needs only the
/// direction of the solution, and a pivot of the matrix's size would hide a small eigenvalue's
/// direction.
struct Lu {
    n: usize,
    lu: Vec<c64>,
    pivots: Vec<usize>,
}

impl Lu {
    fn of(b: &[c64], n: usize, sigma: c64, size: f64) -> Option<Self> {
        let mut lu = b.to_vec();
        for i in 0..n {
            lu[i + i * n] -= sigma;
        }
        let mut pivots = Vec::with_capacity(n);
        for k in 0..n {
            let p =
                (k..n).max_by(|&i, &j| lu[i + k * n].norm().total_cmp(&lu[j + k * n].norm()))?;
            pivots.push(p);
            if p != k {
                for j in 0..n {
                    lu.swap(k + j * n, p + j * n);
                }
            }
            if lu[k + k * n].norm() == 0.0 {
                let scale = if sigma.norm() > 0.0 {
                    sigma.norm()
                } else {
                    size
                };
                lu[k + k * n] = c64::new(f64::EPSILON * scale.max(f64::MIN_POSITIVE), 0.0);
            }
            let pivot = lu[k + k * n];
            for i in k + 1..n {
                let l = lu[i + k * n] / pivot;
                lu[i + k * n] = l;
                for j in k + 1..n {
                    let u = lu[k + j * n];
                    lu[i + j * n] -= l * u;
                }
            }
        }
        Some(Self { n, lu, pivots })
    }

    /// v <- (B - σI)^-1 v.
    fn solve(&self, v: &mut [c64]) {
        let (n, lu) = (self.n, &self.lu);
        for (k, &p) in self.pivots.iter().enumerate() {
            v.swap(k, p);
        }
        for k in 0..n {
            let vk = v[k];
            for i in k + 1..n {
                v[i] -= lu[i + k * n] * vk;
            }
        }
        for k in (0..n).rev() {
            v[k] /= lu[k + k * n];
            let vk = v[k];
            for i in 0..k {
                v[i] -= lu[i + k * n] * vk;
            }
        }
    }

    /// v <- (B - σI)^-H v.
    fn solve_adjoint(&self, v: &mut [c64]) {
        let (n, lu) = (self.n, &self.lu);
        // U^H w = v, forward.
        for k in 0..n {
            let mut s = v[k];
            for i in 0..k {
                s -= lu[i + k * n].conj() * v[i];
            }
            v[k] = s / lu[k + k * n].conj();
        }
        // L^H z = w, backward.
        for k in (0..n).rev() {
            let mut s = v[k];
            for i in k + 1..n {
                s -= lu[i + k * n].conj() * v[i];
            }
            v[k] = s;
        }
        for (k, &p) in self.pivots.iter().enumerate().rev() {
            v.swap(k, p);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::linalg::schur::eigenvalues;
    use faer::Mat;

    /// Companion matrices (the first row -c_1 .. -c_n) of polynomials whose roots spread over
    /// twenty decades, each root against its closed form to a relative 1e-12 (the roots are
    /// well conditioned in the relative sense: the coefficients have one sign).
    #[test]
    fn small_roots_of_graded_companion_matrices_are_relatively_accurate() {
        for roots in [
            vec![-1.0, -1e10, -1e20],
            vec![-1.0, -1e5, -1e10, -1e15, -1e20],
            vec![-3.0, -2e7, -5e13, -1e20],
            vec![-2.5, -7.0, -4e4, -3e12, -8e19],
        ] {
            let n = roots.len();
            let mut c = vec![1.0];
            for r in &roots {
                let mut next = vec![0.0; c.len() + 1];
                for (k, x) in c.iter().enumerate() {
                    next[k] += x;
                    next[k + 1] -= r * x;
                }
                c = next;
            }
            let a = Mat::from_fn(n, n, |i, j| {
                if i == 0 {
                    -c[j + 1]
                } else if i == j + 1 {
                    1.0
                } else {
                    0.0
                }
            });
            let mut found: Vec<f64> = eigenvalues(a.as_ref())
                .unwrap()
                .iter()
                .map(|z| z.re)
                .collect();
            found.sort_by(f64::total_cmp);
            let mut expected = roots.clone();
            expected.sort_by(f64::total_cmp);
            for (x, y) in found.iter().zip(&expected) {
                assert!((x - y).abs() <= 1e-12 * y.abs(), "{roots:?}: {x} for {y}");
            }
        }
    }

    /// A diagonal over twenty decades plus a rank-one term of size 10: each eigenvalue near
    /// its diagonal entry to a relative 1e-12 (against the secular equation solved by
    /// bisection in the reference: the eigenvalues of D + u u^T are the roots of
    /// 1 + Σ u_i^2 / (d_i - λ)).
    #[test]
    fn diagonal_plus_rank_one_keeps_its_small_eigenvalues() {
        let d = [-1e20, -3e15, -2e10, -5e5, -7.0];
        let u = [3.0, 1.0, -2.0, 0.5, 1.5];
        let n = d.len();
        let a = Mat::from_fn(n, n, |i, j| u[i] * u[j] + if i == j { d[i] } else { 0.0 });
        let secular =
            |lambda: f64| 1.0 + (0..n).map(|i| u[i] * u[i] / (d[i] - lambda)).sum::<f64>();
        let mut found: Vec<f64> = eigenvalues(a.as_ref())
            .unwrap()
            .iter()
            .map(|z| z.re)
            .collect();
        found.sort_by(f64::total_cmp);
        // The roots interlace: d_k < λ_k < d_{k+1} (d increasing), the last above d_n.
        let mut sorted_d = d.to_vec();
        sorted_d.sort_by(f64::total_cmp);
        for k in 0..n {
            let lo = sorted_d[k];
            let hi = if k + 1 < n {
                sorted_d[k + 1]
            } else {
                sorted_d[k] + 100.0
            };
            let (mut a0, mut b0) = (lo, hi);
            for _ in 0..400 {
                let m = 0.5 * (a0 + b0);
                if m == a0 || m == b0 {
                    break;
                }
                // secular is increasing on (d_k, d_{k+1}) from -inf to +inf.
                if secular(m) < 0.0 {
                    a0 = m;
                } else {
                    b0 = m;
                }
            }
            let expected = 0.5 * (a0 + b0);
            let x = found[k];
            assert!(
                (x - expected).abs() <= 1e-12 * expected.abs(),
                "k={k}: {x} for {expected}"
            );
        }
    }
}
