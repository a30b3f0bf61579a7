//! Exact scalings of a Riccati equation, continuous ([`super::care`]) or discrete
//! ([`super::dare`], and the difference equation of [`super::difference`]), to the sizes its
//! Hamiltonian matrix, symplectic pencil or recursion resolves.
//!
//! Three changes of units leave the regulator unchanged: the states x = T x̃ with
//! T = diag(2^e), and the costs multiplied by 2^k. The equation in those units is
//!
//! ```text
//! Ã = T^-1 A T,  B̃ = T^-1 B,  Q̃ = 2^k T Q T,  R̃ = 2^k R,  S̃ = 2^k T S,  Ẽ = T^-1 E T,
//! ```
//!
//! whose solution is X̃ = 2^k T X T and gain K̃ = K T, with the same closed-loop eigenvalues.
//! Powers of two make every step exact (no rounding, only over- or underflow, which is
//! refused). The exponents are, in turn:
//!
//! 1. the balancing of the states (Osborne's iteration on |A| + |E|,
//!    [`crate::linalg::balance::balanced_where_scaled_apart`]) where some state's row and
//!    column of A are scaled apart and the balancing spans [`BALANCING_SPREAD`] powers of two
//!    or more;
//! 2. one shift 2^c of all the states that brings max |B̃| to about 1;
//! 3. the cost factor 2^k that brings max |Q̃| to about 1 (max |R̃| for Q = 0).
//!
//! The Schur and QZ algorithms' errors are relative to the norm of the Hamiltonian
//! [[A, -G], [-Q, -A^T]] or the symplectic pencil, whose blocks are A, B, Q, R and the identity:
//! states scaled by 10^±6 (one by one, or, for the discrete equation, all together), or discrete
//! weights Q and R both multiplied by 1e12, lose the small eigenvalues (too few found in the
//! stable half, or a swap refused), where the same equation in these units is solved to
//! rounding. The continuous solver scales its Hamiltonian's blocks itself (the factor ρ and the
//! balancing of H in [`super::care`]), so it is scaled here only where the states are balanced;
//! the discrete one also where B or Q alone is far from 1 (2^10, 2^20 or more).
//!
//! The solution is taken back, X = 2^-k T^-1 X̃ T^-1 and K = K̃ T^-1, and its relative residual
//! is that of the caller's equation, recomputed in the caller's units. The difference
//! equation's terminal weight S_f scales as Q; its recursion is scaled where the states are
//! balanced: its error estimate, normwise in A and B K, is then that of the balanced
//! recursion, not of the units.

use super::AlgebraicSolution;
use super::care::SYMMETRY_TOLERANCE;
use crate::error::Error;
use crate::linalg::balance::{
    balanced_where_scaled_apart, states_scaled_apart, times_power_of_two,
};
use crate::linalg::matrix::Symmetrize;
use crate::linalg::norm::max_abs;
use faer::{Mat, MatRef};

/// The balancing of the states is applied where its exponents span at least this many powers
/// of two (states scaled apart by about 1e3 or more); below, it would change the solution only
/// by rounding.
pub const BALANCING_SPREAD: i32 = 10;

/// The equation as the caller gave it: A, B, Q, R, the cross weight S and the descriptor E;
/// for the difference equation ([`super::difference`]) also the terminal weight S_f.
#[derive(Clone, Copy)]
pub(crate) struct Equation<'a> {
    pub(crate) a: MatRef<'a, f64>,
    pub(crate) b: MatRef<'a, f64>,
    pub(crate) q: MatRef<'a, f64>,
    pub(crate) r: MatRef<'a, f64>,
    pub(crate) s: Option<MatRef<'a, f64>>,
    pub(crate) e: Option<MatRef<'a, f64>>,
    pub(crate) terminal: Option<MatRef<'a, f64>>,
}

/// Where an equation is scaled.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scale {
    /// Only where its states are balanced (the continuous solver, which scales its
    /// Hamiltonian's blocks itself, and the difference equation, whose steps are products).
    WhereBalanced,
    /// Also where B or the weights alone are far from 1 (the discrete solver's pencil, whose
    /// identity blocks set the scale).
    AlsoWeights,
}

/// The equation in scaled units (module documentation) and the exponents that scaled it.
pub(crate) struct ScaledEquation {
    /// e of T = diag(2^e), the shift of all the states included.
    exponents: Vec<i32>,
    /// k of the costs' factor 2^k.
    cost: i32,
    pub(crate) a: Mat<f64>,
    pub(crate) b: Mat<f64>,
    pub(crate) q: Mat<f64>,
    pub(crate) r: Mat<f64>,
    pub(crate) s: Option<Mat<f64>>,
    pub(crate) e: Option<Mat<f64>>,
    pub(crate) terminal: Option<Mat<f64>>,
}

/// round(max_ij log2 |M_ij| + row_i + col_j) (ties to even) over the nonzero entries, None
/// where every entry is zero.
fn log2_size(
    m: MatRef<'_, f64>,
    row: impl Fn(usize) -> i32,
    col: impl Fn(usize) -> i32,
) -> Option<i32> {
    let mut largest = f64::NEG_INFINITY;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            let x = m[(i, j)].abs();
            if x > 0.0 {
                largest = largest.max(x.log2() + f64::from(row(i) + col(j)));
            }
        }
    }
    largest
        .is_finite()
        .then(|| largest.round_ties_even() as i32)
}

/// M with entry (i, j) multiplied by 2^(row_i + col_j); None where a nonzero entry would leave
/// the normal doubles (the scaling would not be exact).
fn exactly_scaled(
    m: MatRef<'_, f64>,
    row: impl Fn(usize) -> i32,
    col: impl Fn(usize) -> i32,
) -> Option<Mat<f64>> {
    let scaled = Mat::from_fn(m.nrows(), m.ncols(), |i, j| {
        times_power_of_two(m[(i, j)], f64::from(row(i) + col(j)))
    });
    let exact = (0..m.ncols()).all(|j| {
        (0..m.nrows()).all(|i| {
            let (x, y) = (m[(i, j)], scaled[(i, j)]);
            x == 0.0 || (y.is_finite() && y.abs() >= f64::MIN_POSITIVE)
        })
    });
    exact.then_some(scaled)
}

/// Q symmetrised where it is symmetric to [`SYMMETRY_TOLERANCE`] in the caller's units, the
/// check the solvers make: Q̃ = 2^k T Q T weighs its entries unequally, so the check made on
/// Q̃ would refuse an asymmetry the caller's Q may carry (or accept one it may not), and name
/// sizes the caller never gave. None where Q is refused: the solver then refuses it as given.
fn symmetrized(q: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let n = q.nrows();
    let asymmetry = (0..n)
        .flat_map(|j| (0..j).map(move |i| (q[(i, j)] - q[(j, i)]).abs()))
        .fold(0.0, f64::max);
    (asymmetry <= SYMMETRY_TOLERANCE * max_abs(q)).then(|| {
        let mut symmetric = q.to_owned();
        symmetric.symmetrize();
        symmetric
    })
}

/// The exponents of Osborne's balancing of |A| + |E| (e with T^-1 A T balanced), where the
/// states are scaled apart and the exponents span [`BALANCING_SPREAD`] or more.
fn balancing(a: MatRef<'_, f64>, e: Option<MatRef<'_, f64>>) -> Option<Vec<i32>> {
    let n = a.nrows();
    let pattern = match e {
        Some(e) => Mat::from_fn(n, n, |i, j| a[(i, j)].abs() + e[(i, j)].abs()),
        None => a.to_owned(),
    };
    let none = Mat::<f64>::zeros(n, 0);
    // The balancing forms T' A T'^-1 with T' = diag(scaling): T = T'^-1, e = -log2 scaling.
    let (_, _, _, scaling) =
        balanced_where_scaled_apart(pattern.as_ref(), none.as_ref(), none.transpose())?;
    let exponents: Vec<i32> = scaling.iter().map(|t| -(t.log2().round() as i32)).collect();
    let (low, high) = exponents
        .iter()
        .fold((i32::MAX, i32::MIN), |(l, h), &x| (l.min(x), h.max(x)));
    (high - low >= BALANCING_SPREAD).then_some(exponents)
}

impl ScaledEquation {
    /// The equation in scaled units, or None where it is scaled well enough already, an
    /// argument is not a finite matrix of the right shape (the solver then refuses it by
    /// name), or a scaled entry would leave the normal doubles.
    pub(crate) fn of(given: Equation<'_>, scale: Scale) -> Option<Self> {
        let Equation {
            a,
            b,
            q,
            r,
            s,
            e,
            terminal,
        } = given;
        let (n, m) = (a.nrows(), b.ncols());
        if n == 0 || a.ncols() != n || b.nrows() != n {
            return None;
        }
        if scale == Scale::WhereBalanced && e.is_none() && !states_scaled_apart(a) {
            return None; // the balancing's own first test, before the weights are read
        }
        let shapes = q.nrows() == n
            && q.ncols() == n
            && r.nrows() == m
            && r.ncols() == m
            && s.is_none_or(|s| s.nrows() == n && s.ncols() == m)
            && e.is_none_or(|e| e.nrows() == n && e.ncols() == n)
            && terminal.is_none_or(|t| t.nrows() == n && t.ncols() == n);
        let finite = [Some(a), Some(b), Some(q), Some(r), s, e, terminal]
            .into_iter()
            .flatten()
            .all(|m| m.is_all_finite());
        if !(shapes && finite) {
            return None;
        }
        // R and S_f are scaled by one factor or congruently as Q; only Q's check depends on
        // the units (R's is unchanged by 2^k, S_f's is the bindings').
        let q = symmetrized(q)?;
        let q = q.as_ref();
        let balancing = balancing(a, e);
        if balancing.is_none() && scale == Scale::WhereBalanced {
            return None;
        }
        let mut exponents = balancing.clone().unwrap_or_else(|| vec![0; n]);
        let shift = log2_size(b, |i| -exponents[i], |_| 0).unwrap_or(0);
        for x in &mut exponents {
            *x += shift;
        }
        let cost = match log2_size(q, |i| exponents[i], |j| exponents[j]) {
            Some(size) => -size,
            None => log2_size(r, |_| 0, |_| 0).map_or(0, |size| -size),
        };
        if balancing.is_none()
            && shift.abs() < BALANCING_SPREAD
            && cost.abs() < 2 * BALANCING_SPREAD
        {
            return None;
        }
        let t = &exponents;
        Some(Self {
            a: exactly_scaled(a, |i| -t[i], |j| t[j])?,
            b: exactly_scaled(b, |i| -t[i], |_| 0)?,
            q: exactly_scaled(q, |i| cost + t[i], |j| t[j])?,
            r: exactly_scaled(r, |_| cost, |_| 0)?,
            s: match s {
                Some(s) => Some(exactly_scaled(s, |i| cost + t[i], |_| 0)?),
                None => None,
            },
            e: match e {
                Some(e) => Some(exactly_scaled(e, |i| -t[i], |j| t[j])?),
                None => None,
            },
            terminal: match terminal {
                Some(sf) => Some(exactly_scaled(sf, |i| cost + t[i], |j| t[j])?),
                None => None,
            },
            exponents,
            cost,
        })
    }

    /// The scaled equation's arguments, as the solvers take them.
    pub(crate) fn equation(&self) -> Equation<'_> {
        Equation {
            a: self.a.as_ref(),
            b: self.b.as_ref(),
            q: self.q.as_ref(),
            r: self.r.as_ref(),
            s: self.s.as_ref().map(|s| s.as_ref()),
            e: self.e.as_ref().map(|e| e.as_ref()),
            terminal: self.terminal.as_ref().map(|t| t.as_ref()),
        }
    }

    /// A solution X̃ of the scaled equation in the caller's units, X = 2^-k T^-1 X̃ T^-1.
    pub(crate) fn unscaled_solution(&self, x: &Mat<f64>) -> Mat<f64> {
        let t = &self.exponents;
        Mat::from_fn(x.nrows(), x.ncols(), |i, j| {
            times_power_of_two(x[(i, j)], f64::from(-self.cost - t[i] - t[j]))
        })
    }

    /// A gain K̃ of the scaled equation in the caller's units, K = K̃ T^-1.
    pub(crate) fn unscaled_gain(&self, gain: &Mat<f64>) -> Mat<f64> {
        let t = &self.exponents;
        Mat::from_fn(gain.nrows(), gain.ncols(), |i, j| {
            times_power_of_two(gain[(i, j)], f64::from(-t[j]))
        })
    }

    /// The scaled equation's solution in the caller's units: X = 2^-k T^-1 X̃ T^-1,
    /// K = K̃ T^-1, with the relative residual `residual(X, K)` of the caller's equation where
    /// that is finite (the closed-loop eigenvalues, rcond and the steps are the scaled
    /// solve's). X or K beyond the doubles are returned as they are (the bindings warn).
    pub(crate) fn unscaled(
        &self,
        solution: AlgebraicSolution,
        residual: impl FnOnce(&Mat<f64>, &Mat<f64>) -> Result<f64, Error>,
    ) -> Result<AlgebraicSolution, Error> {
        let x = self.unscaled_solution(&solution.x);
        let gain = self.unscaled_gain(&solution.gain);
        let mut residual_of_given = solution.residual;
        if x.is_all_finite() && gain.is_all_finite() {
            let unscaled = residual(&x, &gain)?;
            if unscaled.is_finite() {
                residual_of_given = unscaled;
            }
        }
        Ok(AlgebraicSolution {
            x,
            gain,
            residual: residual_of_given,
            ..solution
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest |entry| of a matrix.
    fn largest(m: &Mat<f64>) -> f64 {
        max_abs(m.as_ref())
    }

    /// The equation (A, B, Q, R) without cross weight, descriptor or terminal weight.
    fn plain<'a>(
        a: &'a Mat<f64>,
        b: &'a Mat<f64>,
        q: &'a Mat<f64>,
        r: &'a Mat<f64>,
    ) -> Equation<'a> {
        Equation {
            a: a.as_ref(),
            b: b.as_ref(),
            q: q.as_ref(),
            r: r.as_ref(),
            s: None,
            e: None,
            terminal: None,
        }
    }

    /// A 3-state model scaled by s: A_ij s_i / s_j, B_i s_i.
    fn scaled_model(s: [f64; 3]) -> (Mat<f64>, Mat<f64>) {
        let base = [[-1.0, 2.0, 0.5], [-3.0, -2.0, 1.0], [0.25, -1.0, -4.0]];
        let a = Mat::from_fn(3, 3, |i, j| base[i][j] * s[i] / s[j]);
        let b = Mat::from_fn(3, 1, |i, _| [1.0, 0.5, -1.0][i] * s[i]);
        (a, b)
    }

    #[test]
    fn well_scaled_equations_are_left_alone() {
        let (a, b) = scaled_model([1.0, 1.0, 1.0]);
        let (q, r) = (Mat::<f64>::identity(3, 3), Mat::<f64>::identity(1, 1));
        let given = plain(&a, &b, &q, &r);
        assert!(ScaledEquation::of(given, Scale::WhereBalanced).is_none());
        assert!(ScaledEquation::of(given, Scale::AlsoWeights).is_none());
    }

    #[test]
    fn states_scaled_apart_are_balanced_exactly() {
        // States in units 10^±6 apart: the scaled A and B are of one size, every entry an
        // exact power-of-two multiple of the given one.
        let (a, b) = scaled_model([1e6, 1e-6, 1.0]);
        let (q, r) = (Mat::<f64>::identity(3, 3), Mat::<f64>::identity(1, 1));
        let given = plain(&a, &b, &q, &r);
        for scale in [Scale::WhereBalanced, Scale::AlsoWeights] {
            let scaled = ScaledEquation::of(given, scale).expect("scaled apart");
            assert!(largest(&scaled.a) < 64.0 && largest(&scaled.b) < 4.0);
            let t = &scaled.exponents;
            for i in 0..3 {
                assert_eq!(scaled.b[(i, 0)], b[(i, 0)] * 2f64.powi(-t[i]));
                for j in 0..3 {
                    assert_eq!(scaled.a[(i, j)], a[(i, j)] * 2f64.powi(t[j] - t[i]));
                    let factor = 2f64.powi(scaled.cost + t[i] + t[j]);
                    assert_eq!(scaled.q[(i, j)], q[(i, j)] * factor);
                }
            }
            assert_eq!(scaled.r[(0, 0)], 2f64.powi(scaled.cost));
        }
    }

    #[test]
    fn discrete_weights_far_from_one_are_scaled() {
        // Q and R both of 1e12: the discrete equation's costs are brought to 1, the continuous
        // one is left to its own Hamiltonian scaling.
        let (a, b) = scaled_model([1.0, 1.0, 1.0]);
        let q = Mat::<f64>::identity(3, 3) * 1e12;
        let r = Mat::<f64>::identity(1, 1) * 1e12;
        let given = plain(&a, &b, &q, &r);
        assert!(ScaledEquation::of(given, Scale::WhereBalanced).is_none());
        let scaled = ScaledEquation::of(given, Scale::AlsoWeights).expect("costs far from 1");
        assert_eq!(scaled.cost, -40);
        assert!(scaled.exponents.iter().all(|&x| x == 0));
        assert_eq!(scaled.q[(0, 0)], 1e12 * 2f64.powi(-40));
    }

    #[test]
    fn an_inexact_scaling_is_refused() {
        // A state balanced by 2^±60 beside a Q entry of 1e-300: Q̃ would underflow.
        let (a, b) = scaled_model([1e18, 1e-18, 1.0]);
        let mut q = Mat::<f64>::identity(3, 3);
        q[(1, 1)] = 1e-300;
        let r = Mat::<f64>::identity(1, 1);
        let given = plain(&a, &b, &q, &r);
        assert!(ScaledEquation::of(given, Scale::AlsoWeights).is_none());
    }
}
