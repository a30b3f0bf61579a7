//! The continuous algebraic Riccati equation (the general form of [`super::care`]) by the
//! extended Hamiltonian pencil, for a weight R that is symmetric and nonsingular but not
//! positive definite (the H-infinity Riccati equations have such R), where the Cholesky-based
//! reduction of [`super::care`] does not apply.
//!
//! The state, costate and input of the optimal trajectory (E x' = A x + B u,
//! E^T λ' = -Q x - A^T λ - S u, 0 = S^T x + B^T λ + R u) are the generalized eigenvectors of
//!
//! ```text
//! M - s N = [ A    0    B ]  - s [ E  0    0 ]
//!           [ -Q  -A^T -S ]      [ 0  E^T  0 ]
//!           [ S^T  B^T  R ]      [ 0  0    0 ],
//! ```
//!
//! compressed to order 2n ([`super::pencil::compress`]); its generalized Schur form reordered
//! to put Re s < 0 first gives X = U21 (E U11)^-1 ([`super::pencil::graph_solution`]). The
//! checks are those of [`super::care`]: no eigenvalue of the pencil within 100 u of the
//! imaginary axis (relative to its modulus), exactly n stable ones, E U11 nonsingular, and the
//! closed loop (A - B K, E) with K = R^-1 (B^T X E + S^T) stable to working precision; the
//! relative residual and rcond(E U11) are reported.

use super::AlgebraicSolution;
use super::care::{AXIS_TOLERANCE, CareOptions};
use super::pencil::{checked_weights, compress, graph_solution};
use crate::error::Error;
use crate::linalg::lu::solve_with_inverse;
use crate::linalg::norm::{frobenius_norm, one_norm};
use crate::linalg::product::product;
use crate::linalg::qz::{generalized_eigenvalues, qz, reorder_qz};
use faer::{Mat, MatRef, c64};

/// Solves the CARE with a symmetric, nonsingular, indefinite R (see the module documentation).
pub(crate) fn solve_care_indefinite(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    r: MatRef<'_, f64>,
    options: CareOptions<'_>,
) -> Result<AlgebraicSolution, Error> {
    let (q, r) = checked_weights(
        a,
        b,
        q,
        r,
        options.s.map(|s| (s, options.s_name.unwrap_or("S"))),
        options.e,
    )?;
    let (n, m) = (a.nrows(), b.ncols());
    // R must be invertible (the gain is R^-1 (B^T X E + S^T)).
    let r_norm = one_norm(r.as_ref());
    let r_inverse = solve_with_inverse(r.clone().as_mut(), Mat::<f64>::zeros(m, 0).as_ref())?;
    // An inverse that is not finite is that of an exactly singular R: rcond 0 (not the NaN
    // of inf / inf, which the message printed).
    let r_rcond = if r_inverse.is_all_finite() {
        1.0 / (r_norm * one_norm(r_inverse.as_ref()))
    } else {
        0.0
    };
    if m > 0 && (r_rcond.is_nan() || r_rcond <= f64::EPSILON) {
        return Err(Error::InvalidArgument {
            arg: "R",
            message: format!(
                "R must be nonsingular (positive definite or indefinite), but its reciprocal \
                 condition number is {r_rcond:.1e}: singular to working precision"
            ),
        });
    }
    let identity = Mat::<f64>::identity(n, n);
    let e = options.e.unwrap_or(identity.as_ref());
    crate::platform::memory::reserve((2 * n + m).pow(2).saturating_mul(8 * 8))?;
    let size = 2 * n + m;
    let mut big_m = Mat::<f64>::zeros(size, size);
    let mut big_n = Mat::<f64>::zeros(size, size);
    for j in 0..n {
        for i in 0..n {
            big_m[(i, j)] = a[(i, j)];
            big_m[(n + i, j)] = -q[(i, j)];
            big_m[(n + i, n + j)] = -a[(j, i)];
            big_n[(i, j)] = e[(i, j)];
            big_n[(n + i, n + j)] = e[(j, i)];
        }
    }
    for j in 0..m {
        for i in 0..n {
            big_m[(i, 2 * n + j)] = b[(i, j)];
            big_m[(2 * n + j, n + i)] = b[(i, j)];
            let sij = options.s.map_or(0.0, |s| s[(i, j)]);
            big_m[(n + i, 2 * n + j)] = -sij;
            big_m[(2 * n + j, i)] = sij;
        }
        for i in 0..m {
            big_m[(2 * n + i, 2 * n + j)] = r[(i, j)];
        }
    }
    let (pencil_m, pencil_n) = compress(big_m, big_n, 2 * n);
    let form = qz(pencil_m.as_ref(), pencil_n.as_ref())?;
    let values = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref());
    let on_axis: Vec<String> = values
        .iter()
        .filter(|v| v.beta > 0.0)
        .map(|v| v.value())
        .filter(|s| s.re.abs() <= AXIS_TOLERANCE * s.norm().max(1.0))
        .map(crate::error::format_complex)
        .collect();
    if !on_axis.is_empty() {
        return Err(no_solution(format!(
            "the Hamiltonian pencil has {} eigenvalue(s) on the imaginary axis to working \
             precision ({})",
            on_axis.len(),
            on_axis.join(", ")
        )));
    }
    let (form, selected) = reorder_qz(form, |v| v.beta > 0.0 && v.alpha.re / v.beta < 0.0)?;
    if selected != n {
        return Err(no_solution(format!(
            "{selected} of the 2n = {} eigenvalues of the Hamiltonian pencil are stable, not n",
            2 * n
        )));
    }
    let (x, rcond) = graph_solution(&form, e, n).ok_or_else(|| {
        no_solution("the stable deflating subspace is not a graph: E U11 is singular".into())
    })?;
    // K = R^-1 (B^T X E + S^T).
    let xe = product(x.as_ref(), e)?;
    let mut mixed = product(b.transpose(), xe.as_ref())?;
    if let Some(s) = options.s {
        mixed += s.transpose();
    }
    let combined = solve_with_inverse(r.clone().as_mut(), mixed.as_ref())?;
    let gain = combined.as_ref().split_at_col(n).0.to_owned();
    let closed_loop = a - product(b, gain.as_ref())?;
    let closed_loop_eigenvalues: Vec<c64> = match options.e {
        None => crate::linalg::schur::eigenvalues(closed_loop.as_ref())?,
        Some(e) => {
            let form = qz(closed_loop.as_ref(), e)?;
            generalized_eigenvalues(form.s.as_ref(), form.t.as_ref())
                .iter()
                .map(|v| v.value())
                .collect()
        }
    };
    let margin = AXIS_TOLERANCE * frobenius_norm(closed_loop.as_ref()).max(1.0);
    let unstable: Vec<String> = closed_loop_eigenvalues
        .iter()
        .filter(|z| z.re.is_nan() || z.re >= -margin)
        .map(|z| crate::error::format_complex(*z))
        .collect();
    if !unstable.is_empty() {
        return Err(no_solution(format!(
            "the computed solution leaves the closed loop with eigenvalue(s) {} on or beyond \
             the imaginary axis",
            unstable.join(", ")
        )));
    }
    let axe = product(a.transpose(), xe.as_ref())?;
    let quadratic = product(mixed.transpose(), gain.as_ref())?;
    let residual = &axe + axe.transpose() - &quadratic + &q;
    let scale = frobenius_norm(q.as_ref())
        + 2.0 * frobenius_norm(axe.as_ref())
        + frobenius_norm(quadratic.as_ref());
    let size = frobenius_norm(residual.as_ref());
    Ok(AlgebraicSolution {
        x,
        gain,
        closed_loop_eigenvalues,
        residual: if scale > 0.0 { size / scale } else { size },
        rcond,
        refinement_steps: 0,
    })
}

fn no_solution(evidence: String) -> Error {
    Error::NoStabilizingSolution {
        message: format!(
            "the Riccati equation (with an indefinite R) has no stabilising solution: {evidence}"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scipy_example_with_negative_r() {
        // A = -1, B = 1, Q = 0.5, R = -1: -2x + x^2 + 0.5 = 0, the stabilising root
        // x = 1 - sqrt(0.5) (closed loop -1 + x < 0).
        let one = |v: f64| Mat::from_fn(1, 1, |_, _| v);
        let care = solve_care_indefinite(
            one(-1.0).as_ref(),
            one(1.0).as_ref(),
            one(0.5).as_ref(),
            one(-1.0).as_ref(),
            CareOptions::default(),
        )
        .unwrap();
        assert!((care.x[(0, 0)] - (1.0 - 0.5f64.sqrt())).abs() < 1e-15);
        assert!(care.closed_loop_eigenvalues[0].re < 0.0);
        let singular = solve_care_indefinite(
            one(-1.0).as_ref(),
            one(1.0).as_ref(),
            one(0.5).as_ref(),
            one(0.0).as_ref(),
            CareOptions::default(),
        );
        assert!(matches!(
            singular,
            Err(Error::InvalidArgument { arg: "R", .. })
        ));
    }
}
