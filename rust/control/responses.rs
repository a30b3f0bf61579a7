//! Time responses on a uniform grid (chapter §6.2): one exact discretisation, then a recurrence.
//!
//! Over a step h the solution (6.9) of x' = Ax + Bη is exactly
//!
//! ```text
//! x[k+1] = Φ x[k] + (Γ0 - Γ1) η[k] + Γ1 η[k+1],     y[k] = C x[k] + D η[k],
//! ```
//!
//! with Φ, Γ0, Γ1 from `discretize.rs` (Γ1 = 0 for a zero-order hold, where η is constant over
//! each step; first-order hold takes η linear between samples). The recurrence is exact up to
//! rounding for inputs of that form, so impulse (6.36), doublet (6.38) and step (6.43)
//! responses carry no discretisation error at all: the first two are free responses from
//! x(0) = Bη0 and x(0) = ABη0, the step a constant input, and the augmented exponential behind
//! Γ0 makes the step exact for a singular A, where (6.43) fails.
//!
//! Several responses of one model (initial conditions or input histories) run in parallel after
//! one discretisation; the outputs are written into caller-provided row-major buffers, so a
//! 5001-sample response allocates nothing per step.
//!
//! A discrete model ([`Sampling::Discrete`]) is its own recurrence: x[k+1] = A x[k] + B η[k],
//! y[k] = C x[k] + D η[k], with Φ = A and Γ0 = B and nothing to discretise.

use crate::control::discretize::{Discretization, Hold, discretize};
use crate::control::frequency::check_state_space;
use crate::error::{Error, check_finite, check_finite_values, check_output_len, check_positive};
use crate::linalg::lu::Lu;
use crate::linalg::norm::{Inverse, one_norm_estimate, triangular_inverse_norm_bound};
use crate::platform::dispatch::{DOT_LANES, dot_rows};
use crate::platform::interrupt;
use crate::platform::parallel::{ParallelContext, chunks, par_chunks};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

/// The input of a simulation.
#[derive(Debug, Clone, Copy)]
pub enum Input<'a> {
    /// No input: the free response.
    Free,
    /// `η[k]` = η0 for every sample (m values).
    Constant(&'a [f64]),
    /// Sampled input histories, one per response: responses x steps x m values, row-major.
    Sampled(&'a [f64]),
}

/// The step of a uniform time grid starting at 0, or an error that names `arg` and says what
/// is wrong. Uniform means `|t[k] - k h| <= 1e-9 h` for `h = (t[last] - t[0]) / (len - 1)`.
pub fn uniform_grid_step(t: &[f64], arg: &'static str) -> Result<f64, Error> {
    check_finite_values(t, arg)?;
    if t.len() < 2 {
        return Err(Error::InvalidValue {
            arg,
            value: t.len() as f64,
            requirement: "a grid of at least 2 times (the length)",
        });
    }
    if t[0] != 0.0 {
        return Err(Error::InvalidValue {
            arg,
            value: t[0],
            requirement: "a grid that starts at 0 (its first time)",
        });
    }
    let step = t[t.len() - 1] / (t.len() - 1) as f64;
    if let Some(k) = t.windows(2).position(|pair| pair[1] <= pair[0]) {
        return Err(Error::InvalidValue {
            arg,
            value: t[k + 1],
            requirement: "strictly increasing (this time follows a larger or equal one)",
        });
    }
    if let Some(k) = (0..t.len()).find(|&k| (t[k] - k as f64 * step).abs() > 1e-9 * step) {
        return Err(Error::InvalidValue {
            arg,
            value: t[k],
            requirement: "a uniform grid (this time is off the spacing of the first and last)",
        });
    }
    Ok(step)
}

/// The matrices of the recurrence, row-major for the inner loops.
struct Recurrence {
    n: usize,
    m: usize,
    p: usize,
    phi: Vec<f64>,
    /// Γ0 - Γ1, applied to `η[k]`.
    gamma_now: Vec<f64>,
    /// Γ1, applied to η[k+1] (absent for a zero-order hold).
    gamma_next: Option<Vec<f64>>,
    c: Vec<f64>,
    d: Vec<f64>,
    /// C is the identity (the outputs are the states): Y = X + D η, without the product.
    states_out: bool,
}

fn row_major(m: MatRef<'_, f64>) -> Vec<f64> {
    (0..m.nrows())
        .flat_map(|i| (0..m.ncols()).map(move |j| m[(i, j)]))
        .collect()
}

/// From this order on the outputs of a response are one matrix product; below it the
/// matrix-vector products per step are faster (the product of a long, 4-column X with a 4 x 4
/// C^T runs far below the speed of a square one).
pub const OUTPUT_PRODUCT_MIN_ORDER: usize = 16;

impl Recurrence {
    fn new(d: &Discretization, c: MatRef<'_, f64>, dd: MatRef<'_, f64>) -> Self {
        let gamma_now = match &d.gamma1 {
            Some(g1) => &d.gamma0 - g1,
            None => d.gamma0.clone(),
        };
        Recurrence {
            n: d.phi.nrows(),
            m: d.gamma0.ncols(),
            p: c.nrows(),
            phi: row_major(d.phi.as_ref()),
            gamma_now: row_major(gamma_now.as_ref()),
            gamma_next: d.gamma1.as_ref().map(|g| row_major(g.as_ref())),
            c: row_major(c),
            d: row_major(dd),
            states_out: c.nrows() == c.ncols()
                && (0..c.nrows())
                    .all(|i| (0..c.ncols()).all(|j| c[(i, j)] == if i == j { 1.0 } else { 0.0 })),
        }
    }

    /// out = M v for a row-major `rows` x len(v) matrix M.
    fn multiply(matrix: &[f64], v: &[f64], out: &mut [f64]) {
        let cols = v.len();
        if cols == 0 {
            out.fill(0.0);
            return;
        }
        if cols < DOT_LANES {
            let rows = out.iter_mut().zip(matrix.chunks_exact(cols));
            rows.for_each(|(o, row)| *o = row.iter().zip(v).map(|(a, b)| a * b).sum());
        } else {
            dot_rows(matrix, v, out, false);
        }
    }

    /// out += M v.
    fn multiply_add(matrix: &[f64], v: &[f64], out: &mut [f64]) {
        let cols = v.len();
        if cols == 0 {
            return;
        }
        if cols < DOT_LANES {
            let rows = out.iter_mut().zip(matrix.chunks_exact(cols));
            rows.for_each(|(o, row)| *o += row.iter().zip(v).map(|(a, b)| a * b).sum::<f64>());
        } else {
            dot_rows(matrix, v, out, true);
        }
    }

    /// Runs one response of `steps` samples: `x` (steps x n) and `y` (steps x p) row-major,
    /// from `x0`, with `input(k)` the m values of `η[k]` (empty for a free response). Checks for
    /// an interruption every [`STEPS_PER_CHECK`] samples.
    fn run<'a>(
        &self,
        x0: &[f64],
        input: impl Fn(usize) -> &'a [f64],
        steps: usize,
        x: &mut [f64],
        y: &mut [f64],
    ) -> Result<(), Error> {
        let (n, p) = (self.n, self.p);
        if steps > 0 {
            x[..n].copy_from_slice(x0);
        }
        // The outputs C x[k] + D η[k]: for larger models all samples at once after the
        // recurrence, Y = X C^T (one matrix product instead of a matrix-vector product per
        // step); for small ones in the same pass, while x[k] is in registers.
        let product = n >= OUTPUT_PRODUCT_MIN_ORDER && p > 0;
        for k in 0..steps {
            if k % STEPS_PER_CHECK == 0 {
                interrupt::check()?;
            }
            let (done, rest) = x.split_at_mut((k + 1) * n);
            let current = &done[k * n..];
            let eta = input(k);
            let y_k = &mut y[k * p..(k + 1) * p];
            if product {
                y_k.fill(0.0);
            } else {
                Self::multiply(&self.c, current, y_k);
            }
            if self.m > 0 && !eta.is_empty() {
                Self::multiply_add(&self.d, eta, y_k);
            }
            if k + 1 < steps {
                let next = &mut rest[..n];
                Self::multiply(&self.phi, current, next);
                if self.m > 0 && !eta.is_empty() {
                    Self::multiply_add(&self.gamma_now, eta, next);
                    if let Some(gamma_next) = &self.gamma_next {
                        Self::multiply_add(gamma_next, input(k + 1), next);
                    }
                }
            }
        }
        if product && steps > 0 && self.states_out {
            // Y already holds D η[k]; add X (the product with C = I costs as much as the
            // recurrence itself and gives the same values, up to the sign of zeros: 1 x + 0
            // for x = -0 is +0).
            for (y, &x) in y[..steps * p].iter_mut().zip(&x[..steps * n]) {
                *y += x;
            }
        } else if product && steps > 0 {
            let states = MatRef::from_row_major_slice(x, steps, n);
            let c = MatRef::from_row_major_slice(&self.c, p, n);
            let outputs = MatMut::from_row_major_slice_mut(y, steps, p);
            // Y already holds D η[k]; add X C^T.
            matmul(outputs, Accum::Add, states, c.transpose(), 1.0, Par::Seq);
        }
        Ok(())
    }
}

/// Samples of a response between two checks for an interruption.
const STEPS_PER_CHECK: usize = 4096;

/// A state-space model x' = Ax + Bη, y = Cx + Dη.
#[derive(Debug, Clone, Copy)]
pub struct Model<'a> {
    pub a: MatRef<'a, f64>,
    pub b: MatRef<'a, f64>,
    pub c: MatRef<'a, f64>,
    pub d: MatRef<'a, f64>,
}

/// How the samples of a response follow from the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampling {
    /// A continuous model x' = Ax + Bη sampled every `dt`, the input reconstructed between
    /// samples by `hold`.
    Continuous { dt: f64, hold: Hold },
    /// A discrete model x[k+1] = A x[k] + B η[k]: one sample per step of the recurrence.
    Discrete,
}

/// Simulates one response per row of `x0` (responses x n initial states) of one model over
/// `steps` samples of step `dt`, with the input and the hold between input samples. Writes the
/// states into `x` (responses x steps x n) and the outputs into `y` (responses x steps x p),
/// row-major. Any of n, m and p may be 0.
#[allow(clippy::too_many_arguments)]
pub fn simulate_into(
    model: Model<'_>,
    x0: MatRef<'_, f64>,
    input: Input<'_>,
    dt: f64,
    steps: usize,
    hold: Hold,
    x: &mut [f64],
    y: &mut [f64],
) -> Result<(), Error> {
    let sampling = Sampling::Continuous { dt, hold };
    simulate_sampled_into(model, x0, input, sampling, steps, x, y)
}

/// [`simulate_into`] for a continuous or a discrete model ([`Sampling`]).
pub fn simulate_sampled_into(
    model: Model<'_>,
    x0: MatRef<'_, f64>,
    input: Input<'_>,
    sampling: Sampling,
    steps: usize,
    x: &mut [f64],
    y: &mut [f64],
) -> Result<(), Error> {
    let Model { a, b, c, d } = model;
    check_state_space(a, b, c, d)?;
    let (n, m, p) = (a.nrows(), b.ncols(), c.nrows());
    let responses = x0.nrows();
    if x0.ncols() != n {
        return Err(Error::Mismatch {
            arg: "x0",
            what: "one initial state per response, as many values as the order of",
            expected: n,
            other: "A",
            got: x0.ncols(),
        });
    }
    check_finite(x0, "x0")?;
    match input {
        Input::Free => {}
        Input::Constant(eta) => {
            if eta.len() != m {
                return Err(Error::Mismatch {
                    arg: "eta0",
                    what: "one value per input, as many as the columns of",
                    expected: m,
                    other: "B",
                    got: eta.len(),
                });
            }
            check_finite_values(eta, "eta0")?;
        }
        Input::Sampled(u) => {
            if u.len() != responses * steps * m {
                return Err(Error::Mismatch {
                    arg: "u",
                    what: "one row of inputs per time, as many values as",
                    expected: responses * steps * m,
                    other: "times x inputs",
                    got: u.len(),
                });
            }
            check_finite_values(u, "u")?;
        }
    }
    check_output_len(x.len(), responses * steps * n)?;
    check_output_len(y.len(), responses * steps * p)?;
    if let Sampling::Continuous { dt, .. } = sampling {
        check_positive(dt, "dt")?;
    }
    if x.is_empty() && y.is_empty() {
        // Nothing to compute (no samples, or neither states nor outputs), however many steps.
        return Ok(());
    }
    let discretization = match sampling {
        Sampling::Continuous { dt, hold } => discretize(a, b, dt, hold)?,
        Sampling::Discrete => Discretization {
            phi: a.to_owned(),
            gamma0: b.to_owned(),
            gamma1: None,
        },
    };
    let recurrence = Recurrence::new(&discretization, c, d);
    let no_input: &[f64] = &[];
    // The outputs of a response of order OUTPUT_PRODUCT_MIN_ORDER or more are one product of
    // all its samples.
    let product_order = if n >= OUTPUT_PRODUCT_MIN_ORDER {
        steps.max(n)
    } else {
        0
    };
    let context = ParallelContext::capture(product_order);
    let run = |(r, (x_r, y_r)): (usize, (&mut [f64], &mut [f64]))| {
        let x0_r: Vec<f64> = (0..n).map(|j| x0[(r, j)]).collect();
        context.run(|| match input {
            Input::Free => recurrence.run(&x0_r, |_| no_input, steps, x_r, y_r),
            Input::Constant(eta) => recurrence.run(&x0_r, |_| eta, steps, x_r, y_r),
            Input::Sampled(u) => {
                let u_r = &u[r * steps * m..(r + 1) * steps * m];
                recurrence.run(&x0_r, |k| &u_r[k * m..(k + 1) * m], steps, x_r, y_r)
            }
        })
    };
    if responses > 1 {
        par_chunks(x, steps * n, responses)
            .zip(par_chunks(y, steps * p, responses))
            .enumerate()
            .try_for_each(run)
    } else {
        chunks(x, steps * n, responses)
            .zip(chunks(y, steps * p, responses))
            .enumerate()
            .try_for_each(run)
    }
}

/// Simulates one response of each of several models of one size, in parallel: model `i` has
/// the initial state in row i of `x0` (models x n), the input slice i of `input` (a constant η0 per model,
/// models x m values, or sampled inputs, models x steps x m), and writes its states and outputs
/// at index i of `x` (models x steps x n) and `y` (models x steps x p). An error names the model.
#[allow(clippy::too_many_arguments)]
pub fn simulate_models_into(
    models: &[Model<'_>],
    x0: MatRef<'_, f64>,
    input: Input<'_>,
    dt: f64,
    steps: usize,
    hold: Hold,
    x: &mut [f64],
    y: &mut [f64],
) -> Result<(), Error> {
    let sampling = Sampling::Continuous { dt, hold };
    simulate_models_sampled_into(models, x0, input, sampling, steps, x, y)
}

/// [`simulate_models_into`] for continuous or discrete models ([`Sampling`]).
pub fn simulate_models_sampled_into(
    models: &[Model<'_>],
    x0: MatRef<'_, f64>,
    input: Input<'_>,
    sampling: Sampling,
    steps: usize,
    x: &mut [f64],
    y: &mut [f64],
) -> Result<(), Error> {
    let Some(first) = models.first() else {
        return Ok(());
    };
    let (n, m, p) = (first.a.nrows(), first.b.ncols(), first.c.nrows());
    let q = models.len();
    if (x0.nrows(), x0.ncols()) != (q, n) {
        return Err(Error::Mismatch {
            arg: "x0",
            what: "one initial state per model, as many rows as",
            expected: q,
            other: "models",
            got: x0.nrows(),
        });
    }
    check_output_len(x.len(), q * steps * n)?;
    check_output_len(y.len(), q * steps * p)?;
    let per_model_input = match input {
        Input::Free => 0,
        Input::Constant(eta) => {
            check_output_len(eta.len(), q * m)?;
            m
        }
        Input::Sampled(u) => {
            check_output_len(u.len(), q * steps * m)?;
            steps * m
        }
    };
    for (index, model) in models.iter().enumerate() {
        let shapes = (model.a.nrows(), model.b.ncols(), model.c.nrows());
        if shapes != (n, m, p) {
            let error = Error::Mismatch {
                arg: "models",
                what: "the states, inputs and outputs of",
                expected: n,
                other: "the first model",
                got: model.a.nrows(),
            };
            return Err(Error::in_batch(index, error));
        }
    }
    // Each model is discretised (an exponential of order n + 2m) and simulated.
    let context = ParallelContext::capture(n + 2 * m);
    par_chunks(x, steps * n, q)
        .zip(par_chunks(y, steps * p, q))
        .enumerate()
        .try_for_each(|(i, (x_i, y_i))| {
            let range = i * per_model_input..(i + 1) * per_model_input;
            let input_i = match input {
                Input::Free => Input::Free,
                Input::Constant(eta) => Input::Constant(&eta[range]),
                Input::Sampled(u) => Input::Sampled(&u[range]),
            };
            context
                .run(|| {
                    simulate_sampled_into(
                        models[i],
                        x0.subrows(i, 1),
                        input_i,
                        sampling,
                        steps,
                        x_i,
                        y_i,
                    )
                })
                .map_err(|e| Error::in_batch(i, e))
        })
}

/// The steady states -A^-1 B η0 of steps (6.45), one for each column η0 of `eta0` (m x k; one
/// LU factorisation for all), or an error naming the eigenvalue of A that makes it singular
/// (an integrator or neutral mode has no steady state).
pub fn steady_state(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    eta0: MatRef<'_, f64>,
) -> Result<Mat<f64>, Error> {
    let empty = Mat::<f64>::zeros(0, a.nrows());
    let no_feedthrough = Mat::<f64>::zeros(0, b.ncols());
    check_state_space(a, b, empty.as_ref(), no_feedthrough.as_ref())?;
    if eta0.nrows() != b.ncols() {
        return Err(Error::Mismatch {
            arg: "eta0",
            what: "one value per input, as many as the columns of",
            expected: b.ncols(),
            other: "B",
            got: eta0.nrows(),
        });
    }
    check_finite(eta0, "eta0")?;
    solve_steady_state(a, b, eta0)
}

/// [`steady_state`] of arguments already checked.
fn solve_steady_state(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    eta0: MatRef<'_, f64>,
) -> Result<Mat<f64>, Error> {
    let n = a.nrows();
    let lu = Lu::new(a)?;
    let mut x = -(b * eta0);
    lu.solve_in_place(x.as_mut())?;
    // A has an eigenvalue within `tolerance` of zero only if σ_min(A) <= tolerance, and
    // σ_min(A) >= 1 / (sqrt(n) ||A^-1||_inf). With A = P^T L U, ||A^-1||_inf is at most the
    // product of the comparison-matrix bounds of U^-1 and L^-1 (two O(n^2) substitutions),
    // which clears a matrix far from singular at once; where that bound is too loose, the
    // 1-norm estimate of A^-1 (Higham & Tisseur 2000; O(n^2) per step with the LU factors;
    // ||A^-1||_1 in place of ||A^-1||_inf, the same bound through A^T), with a factor 10 for
    // the estimate's underestimation, within a factor 3 in practice. Only when neither
    // clears A are its eigenvalues computed, to name the one at zero.
    let tolerance = SINGULAR_EIGENVALUE * n as f64 * f64::EPSILON * a.norm_max();
    let root_n = (n as f64).sqrt();
    let bound =
        triangular_inverse_norm_bound(lu.U(), false) * triangular_inverse_norm_bound(lu.L(), true);
    let cleared = x.is_all_finite()
        && (root_n * bound * tolerance < 1.0
            || 10.0 * root_n * one_norm_estimate(&Inverse(&lu), 2) * tolerance < 1.0);
    if !cleared {
        let eigenvalues = crate::control::modal::eigen_values(a)?;
        if let Some(lambda) = eigenvalues.iter().find(|l| l.norm() <= tolerance) {
            return Err(Error::Singular {
                arg: "A",
                eigenvalue_re: lambda.re,
                eigenvalue_im: lambda.im,
            });
        }
    }
    Ok(x)
}

/// The DC gain D - C A^-1 B (p x m): the steady output per unit step of each input, from the
/// steady states (6.45) of [`steady_state`] for the m unit steps at once (one LU
/// factorisation), with its error naming the eigenvalue that makes A singular.
pub fn dc_gain(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    d: MatRef<'_, f64>,
) -> Result<Mat<f64>, Error> {
    check_state_space(a, b, c, d)?;
    let states = solve_steady_state(a, b, Mat::<f64>::identity(b.ncols(), b.ncols()).as_ref())?;
    let mut gain = d.to_owned();
    matmul(gain.as_mut(), Accum::Add, c, states.as_ref(), 1.0, Par::Seq);
    Ok(gain)
}

/// An eigenvalue of A within this many n u ||A||_max of zero makes A singular for
/// [`steady_state`]: an integrator or a neutral mode, which has no steady state.
const SINGULAR_EIGENVALUE: f64 = 100.0;

#[cfg(test)]
mod tests {
    use super::*;
    use faer::mat;

    /// `values` as initial states of order n, one per row.
    fn states(values: &[f64], n: usize) -> MatRef<'_, f64> {
        MatRef::from_row_major_slice(values, values.len() / n, n)
    }

    /// The model (A, B, C, D) viewed from owned matrices.
    fn model<'a>(a: &'a Mat<f64>, b: &'a Mat<f64>, c: &'a Mat<f64>, d: &'a Mat<f64>) -> Model<'a> {
        Model {
            a: a.as_ref(),
            b: b.as_ref(),
            c: c.as_ref(),
            d: d.as_ref(),
        }
    }

    fn lon747() -> (Mat<f64>, Mat<f64>) {
        (
            mat![
                [-0.0212, 0.0466, 0.0000, -0.1153],
                [-0.2229, -0.5839, 0.9404, 0.0000],
                [0.0150, -0.5031, -0.5015, 0.0000],
                [0.0, 0.0, 1.0, 0.0]
            ],
            mat![[0.0000], [-0.0340], [-0.5746], [0.0000]],
        )
    }

    #[test]
    fn discrete_models_step_their_own_recurrence() {
        // x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k], by hand, for sampled inputs and a
        // constant input, one model and a stack of two.
        let a = mat![[0.9, 0.2], [-0.1, 0.7]];
        let b = mat![[0.0], [1.0]];
        let c = mat![[1.0, -1.0]];
        let d = mat![[0.5]];
        let steps = 6;
        let u: Vec<f64> = (0..steps).map(|k| (k as f64).sin()).collect();
        let (mut x, mut y) = (vec![0.0; steps * 2], vec![0.0; steps]);
        let x0 = [1.0, -2.0];
        simulate_sampled_into(
            model(&a, &b, &c, &d),
            states(&x0, 2),
            Input::Sampled(&u),
            Sampling::Discrete,
            steps,
            &mut x,
            &mut y,
        )
        .unwrap();
        let mut state = x0;
        for k in 0..steps {
            assert_eq!(&x[2 * k..2 * k + 2], &state);
            let output = state[0] - state[1] + 0.5 * u[k];
            assert!((y[k] - output).abs() < 1e-15);
            state = [
                0.9 * state[0] + 0.2 * state[1],
                -0.1 * state[0] + 0.7 * state[1] + u[k],
            ];
        }
        let models = [model(&a, &b, &c, &d), model(&a, &b, &c, &d)];
        let (mut xs, mut ys) = (vec![0.0; 2 * steps * 2], vec![0.0; 2 * steps]);
        simulate_models_sampled_into(
            &models,
            states(&[0.0; 4], 2),
            Input::Constant(&[1.0, 2.0]),
            Sampling::Discrete,
            steps,
            &mut xs,
            &mut ys,
        )
        .unwrap();
        // The step of the second model is twice the first's; x[1] = B, y[0] = D.
        assert_eq!(&xs[2..4], &[0.0, 1.0]);
        assert_eq!(ys[0], 0.5);
        for k in 0..steps {
            assert!((ys[steps + k] - 2.0 * ys[k]).abs() < 1e-14);
        }
    }

    #[test]
    fn grid_checks_name_the_problem() {
        assert_eq!(uniform_grid_step(&[0.0, 0.5, 1.0], "T").unwrap(), 0.5);
        let err = uniform_grid_step(&[0.1, 0.5], "T").unwrap_err().to_string();
        assert!(err.contains("T must be a grid that starts at 0"), "{err}");
        let err = uniform_grid_step(&[0.0, 0.5, 0.4], "T")
            .unwrap_err()
            .to_string();
        assert!(err.contains("strictly increasing"), "{err}");
        let err = uniform_grid_step(&[0.0, 0.1, 0.5, 0.6], "T")
            .unwrap_err()
            .to_string();
        assert!(err.contains("uniform"), "{err}");
        assert!(uniform_grid_step(&[0.0], "T").is_err());
        let grid: Vec<f64> = (0..50001).map(|k| k as f64 * 500.0 / 50000.0).collect();
        assert!((uniform_grid_step(&grid, "T").unwrap() - 0.01).abs() < 1e-15);
    }

    #[test]
    fn step_response_reaches_the_chapter_steady_state() {
        // (6.51): one degree of elevator.
        let (a, b) = lon747();
        let c = Mat::<f64>::identity(4, 4);
        let d = Mat::<f64>::zeros(4, 1);
        let eta0 = [std::f64::consts::PI / 180.0];
        let steps = 801;
        let (mut x, mut y) = (vec![0.0; steps * 4], vec![0.0; steps * 4]);
        let model = model(&a, &b, &c, &d);
        simulate_into(
            model,
            states(&[0.0; 4], 4),
            Input::Constant(&eta0),
            10.0,
            steps,
            Hold::Zero,
            &mut x,
            &mut y,
        )
        .unwrap();
        let steady = steady_state(a.as_ref(), b.as_ref(), mat![[eta0[0]]].as_ref()).unwrap();
        let steady: Vec<f64> = steady.col_as_slice(0).to_vec();
        let last = &x[(steps - 1) * 4..];
        for (l, s) in last.iter().zip(&steady) {
            assert!((l - s).abs() < 1e-7, "{l} vs {s}");
        }
        assert!((steady[0] - 0.045965).abs() < 1e-6 && (steady[3] + 0.015954).abs() < 1e-6);
        assert_eq!(x, y);
    }

    #[test]
    fn identity_outputs_of_a_large_model_are_its_states() {
        // From OUTPUT_PRODUCT_MIN_ORDER on, C = I takes Y = X + D η instead of the product
        // X C^T: the outputs are the states plus D η, as the product path gives them for
        // C = 2 I (doubled, exactly).
        let n = OUTPUT_PRODUCT_MIN_ORDER + 4;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == j {
                -1.0 - i as f64 / n as f64
            } else {
                0.3 * ((i * 7 + j * 3) % 5) as f64 / n as f64 - 0.05
            }
        });
        let b = Mat::from_fn(n, 1, |i, _| (i % 3) as f64 - 1.0);
        let c = Mat::<f64>::identity(n, n);
        let d = Mat::from_fn(n, 1, |i, _| if i == 2 { 0.5 } else { 0.0 });
        let steps = 50;
        let run = |c: &Mat<f64>| {
            let (mut x, mut y) = (vec![0.0; steps * n], vec![0.0; steps * n]);
            simulate_into(
                model(&a, &b, c, &d),
                states(&vec![0.0; n], n),
                Input::Constant(&[1.0]),
                0.1,
                steps,
                Hold::Zero,
                &mut x,
                &mut y,
            )
            .unwrap();
            (x, y)
        };
        let (x, y) = run(&c);
        let (_, doubled) = run(&(&c * faer::Scale(2.0)));
        for k in 0..steps {
            for i in 0..n {
                let feedthrough = if i == 2 { 0.5 } else { 0.0 };
                let at = k * n + i;
                assert_eq!(y[at], x[at] + feedthrough, "k={k} i={i}");
                assert_eq!(doubled[at], 2.0 * x[at] + feedthrough, "k={k} i={i}");
            }
        }
    }

    #[test]
    fn impulse_is_the_free_response_from_b() {
        // (6.36): x(t) = e^{At} B η0, the free response from x(0) = B η0.
        let (a, b) = lon747();
        let c = Mat::<f64>::identity(4, 4);
        let d = Mat::<f64>::zeros(4, 1);
        let model = model(&a, &b, &c, &d);
        let steps = 201;
        let x0: Vec<f64> = (0..4).map(|i| b[(i, 0)]).collect();
        let (mut x, mut y) = (vec![0.0; steps * 4], vec![0.0; steps * 4]);
        simulate_into(
            model,
            states(&x0, 4),
            Input::Free,
            0.1,
            steps,
            Hold::Zero,
            &mut x,
            &mut y,
        )
        .unwrap();
        let expected = crate::linalg::expm::expm((&a * faer::Scale(20.0)).as_ref()).unwrap() * &b;
        for i in 0..4 {
            assert!((x[200 * 4 + i] - expected[(i, 0)]).abs() < 1e-13);
        }
    }

    #[test]
    fn several_responses_match_one_at_a_time() {
        let (a, b) = lon747();
        let c = Mat::from_fn(2, 4, |i, j| (i + j) as f64);
        let d = Mat::from_fn(2, 1, |i, _| i as f64);
        let model = model(&a, &b, &c, &d);
        let (responses, steps) = (3, 50);
        let x0: Vec<f64> = (0..responses * 4).map(|i| i as f64 * 0.01).collect();
        let u: Vec<f64> = (0..responses * steps)
            .map(|i| (i as f64 * 0.3).sin())
            .collect();
        let (mut x, mut y) = (
            vec![0.0; responses * steps * 4],
            vec![0.0; responses * steps * 2],
        );
        simulate_into(
            model,
            states(&x0, 4),
            Input::Sampled(&u),
            0.05,
            steps,
            Hold::First,
            &mut x,
            &mut y,
        )
        .unwrap();
        for r in 0..responses {
            let (mut x1, mut y1) = (vec![0.0; steps * 4], vec![0.0; steps * 2]);
            let u_r = &u[r * steps..(r + 1) * steps];
            simulate_into(
                model,
                states(&x0[r * 4..(r + 1) * 4], 4),
                Input::Sampled(u_r),
                0.05,
                steps,
                Hold::First,
                &mut x1,
                &mut y1,
            )
            .unwrap();
            assert_eq!(&x[r * steps * 4..(r + 1) * steps * 4], &x1[..]);
            assert_eq!(&y[r * steps * 2..(r + 1) * steps * 2], &y1[..]);
        }
    }

    #[test]
    fn a_stack_of_models_equals_one_at_a_time() {
        let (a, b) = lon747();
        let a2 = &a * faer::Scale(2.0);
        let c = Mat::<f64>::identity(4, 4);
        let d = Mat::<f64>::zeros(4, 1);
        let models = [model(&a, &b, &c, &d), model(&a2, &b, &c, &d)];
        let steps = 30;
        let eta = [0.1, -0.2];
        let (mut x, mut y) = (vec![0.0; 2 * steps * 4], vec![0.0; 2 * steps * 4]);
        simulate_models_into(
            &models,
            states(&[0.0; 8], 4),
            Input::Constant(&eta),
            0.1,
            steps,
            Hold::Zero,
            &mut x,
            &mut y,
        )
        .unwrap();
        for (i, m) in models.iter().enumerate() {
            let (mut x1, mut y1) = (vec![0.0; steps * 4], vec![0.0; steps * 4]);
            simulate_into(
                *m,
                states(&[0.0; 4], 4),
                Input::Constant(&eta[i..i + 1]),
                0.1,
                steps,
                Hold::Zero,
                &mut x1,
                &mut y1,
            )
            .unwrap();
            assert_eq!(&x[i * steps * 4..(i + 1) * steps * 4], &x1[..]);
        }
        // A non-finite model is reported with its index.
        let bad = Mat::from_fn(4, 4, |i, j| if i + j == 0 { f64::NAN } else { 0.0 });
        let models = [model(&a, &b, &c, &d), model(&bad, &b, &c, &d)];
        let err = simulate_models_into(
            &models,
            states(&[0.0; 8], 4),
            Input::Free,
            0.1,
            steps,
            Hold::Zero,
            &mut x,
            &mut y,
        )
        .unwrap_err();
        assert!(
            err.to_string()
                .starts_with("problem 1 of the batch: A must be finite"),
            "{err}"
        );
    }

    #[test]
    fn singular_a_has_no_steady_state() {
        // (6.95): A has the eigenvalue 0.
        let a = mat![[-3.0, 8.0], [0.0, 0.0]];
        let b = mat![[0.0], [4.0]];
        let err = steady_state(a.as_ref(), b.as_ref(), mat![[1.0]].as_ref()).unwrap_err();
        assert!(
            matches!(err, Error::Singular { arg: "A", eigenvalue_re, .. } if eigenvalue_re == 0.0)
        );
        assert!(err.to_string().contains("eigenvalue 0"), "{err}");
        // An eigenvalue at 1e-17 of a matrix of size 1 is zero to working precision.
        let a = mat![[-1.0, 1.0, 0.0], [0.0, 1e-17, 0.0], [0.0, 0.0, -2.0]];
        let b = mat![[0.0], [1.0], [1.0]];
        let err = steady_state(a.as_ref(), b.as_ref(), mat![[1.0]].as_ref()).unwrap_err();
        assert!(matches!(err, Error::Singular { eigenvalue_re, .. } if eigenvalue_re == 1e-17));
    }

    #[test]
    fn ill_conditioned_but_stable_a_has_a_steady_state() {
        // Eigenvalues -1, -1 but σ_min ≈ 1e-8: the cheap test cannot clear A, the eigenvalues
        // do, and x = -A^-1 b is returned.
        let a = mat![[-1.0, 1e8], [0.0, -1.0]];
        let b = mat![[0.0], [1.0]];
        let x = steady_state(a.as_ref(), b.as_ref(), mat![[1.0]].as_ref()).unwrap();
        assert_eq!(x.col_as_slice(0), [1e8, 1.0]);
    }

    #[test]
    fn input_lengths_are_checked() {
        let (a, b) = lon747();
        let c = Mat::<f64>::identity(4, 4);
        let d = Mat::<f64>::zeros(4, 1);
        let model = model(&a, &b, &c, &d);
        let (mut x, mut y) = (vec![0.0; 40], vec![0.0; 40]);
        let err = simulate_into(
            model,
            states(&[0.0; 4], 4),
            Input::Sampled(&[0.0; 9]),
            0.1,
            10,
            Hold::Zero,
            &mut x,
            &mut y,
        )
        .unwrap_err();
        assert!(
            err.to_string()
                .starts_with("u must have one row of inputs per time"),
            "{err}"
        );
        let err = simulate_into(
            model,
            states(&[0.0; 4], 4),
            Input::Constant(&[1.0, 2.0]),
            0.1,
            10,
            Hold::Zero,
            &mut x,
            &mut y,
        )
        .unwrap_err();
        assert!(
            err.to_string()
                .starts_with("eta0 must have one value per input"),
            "{err}"
        );
    }
}
