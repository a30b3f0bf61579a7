//! Batches: one operation over a stack of independent problems, in parallel across cores.
//!
//! A stack of k matrices of one shape is stored contiguously in row-major order, exactly as
//! numpy stores a C-ordered k x rows x cols array, so a batch crosses from Python without a
//! copy per matrix. Each problem runs on one rayon task (small problems sequentially inside),
//! which is the efficient split for many small problems; an error names the index of the problem.

use crate::control::placement::Placement;
use crate::control::riccati::AlgebraicSolution;
use crate::control::riccati::care::{
    CareDense, CareOptions, EXTRAPOLATION_WEIGHTS, SharedPlant, indefinite_weight, solve_care,
    solve_care_dense, solve_care_scaled,
};
use crate::control::riccati::dare::{DareOptions, solve_dare};
use crate::error::{Error, check_finite, check_output_len};
use crate::linalg::expm::expm_stack_into_validated;
use crate::platform::parallel::{ParallelContext, min_items_per_task, par_chunks};
use faer::{Mat, MatMut, MatRef, c64};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// A read-only stack of `count` matrices of shape `rows` x `cols`, row-major and contiguous.
#[derive(Debug, Clone, Copy)]
pub struct MatrixStack<'a> {
    data: &'a [f64],
    count: usize,
    rows: usize,
    cols: usize,
}

impl<'a> MatrixStack<'a> {
    /// Views `data` (length count * rows * cols) as a stack of matrices.
    pub fn new(data: &'a [f64], count: usize, rows: usize, cols: usize) -> Result<Self, Error> {
        let expected = count
            .checked_mul(rows)
            .and_then(|x| x.checked_mul(cols))
            .unwrap_or(usize::MAX);
        if data.len() != expected {
            return Err(Error::Mismatch {
                arg: "data",
                what: "as many entries as",
                expected,
                other: "count x rows x cols",
                got: data.len(),
            });
        }
        Ok(Self {
            data,
            count,
            rows,
            cols,
        })
    }

    /// The number of matrices in the stack.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when the stack holds no matrix.
    /// Every member finite, or the NonFinite error of the first one that is not, naming its
    /// index in the batch: one branch-free pass over the whole stack (vectorised), the member
    /// at fault found only when there is one.
    pub fn check_finite(&self, arg: &'static str) -> Result<(), Error> {
        if self
            .data
            .iter()
            .fold(true, |finite, v| finite & v.is_finite())
        {
            return Ok(());
        }
        for index in 0..self.len() {
            check_finite(self.get(index), arg).map_err(|e| Error::in_batch(index, e))?;
        }
        Ok(())
    }

    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The `index`-th matrix.
    pub fn get(&self, index: usize) -> MatRef<'a, f64> {
        let size = self.rows * self.cols;
        MatRef::from_row_major_slice(
            &self.data[index * size..(index + 1) * size],
            self.rows,
            self.cols,
        )
    }
}

/// e^{A_i} for every matrix of a stack of square matrices, written row-major into `out`
/// (length k n^2), in parallel. A non-finite entry is reported with the index of its matrix
/// before anything is computed.
pub fn expm_batch(stack: MatrixStack<'_>, out: &mut [f64]) -> Result<(), Error> {
    let n = stack.rows;
    if stack.rows != stack.cols {
        return Err(Error::NotSquare {
            arg: "A",
            rows: stack.rows,
            cols: stack.cols,
        });
    }
    check_output_len(out.len(), stack.len() * n * n)?;
    stack.check_finite("A")?;
    if n == 0 {
        return Ok(());
    }
    let context = ParallelContext::capture(n);
    // Consecutive matrices are grouped so that the per-item work of the parallel loop (the
    // interrupt token installed and checked) is paid once per group of about
    // EXPM_GROUP_WORK / n^3 matrices rather than once per matrix.
    let group = (EXPM_GROUP_WORK / n.saturating_pow(3)).max(1);
    out.par_chunks_mut(group * n * n)
        .enumerate()
        .with_min_len(min_items_per_task(stack.len(), n).div_ceil(group).max(1))
        .try_for_each(|(group_index, matrices)| {
            context.run(|| {
                let first = group_index * group;
                let count = matrices.len() / (n * n);
                // Validated above: every matrix is square and finite.
                expm_stack_into_validated(
                    n,
                    &stack.data[first * n * n..(first + count) * n * n],
                    matrices,
                )
                .map_err(|(offset, e)| Error::in_batch(first + offset, e))
            })
        })
}

/// The work (in units of n^3) of one group of [`expm_batch`]'s parallel loop: sixteen 4 x 4
/// exponentials (a few microseconds, so that an interrupt still stops the loop promptly and
/// the groups still balance across threads), two of order 8, one of any larger order.
const EXPM_GROUP_WORK: usize = 1024;

/// The eigenvalues of every matrix of a stack of square matrices, written into `out` (length
/// k n, n per matrix in the order of its Schur form's diagonal, each conjugate pair adjacent
/// with Im > 0 first), in parallel. A non-finite entry is reported with the index of its
/// matrix before anything is computed.
pub fn eigenvalues_batch(stack: MatrixStack<'_>, out: &mut [c64]) -> Result<(), Error> {
    let n = stack.rows;
    if stack.rows != stack.cols {
        return Err(Error::NotSquare {
            arg: "A",
            rows: stack.rows,
            cols: stack.cols,
        });
    }
    check_output_len(out.len(), stack.len() * n)?;
    stack.check_finite("A")?;
    if n == 0 {
        return Ok(());
    }
    let context = ParallelContext::capture(n);
    out.par_chunks_mut(n)
        .enumerate()
        .with_min_len(min_items_per_task(stack.len(), n))
        .try_for_each(|(index, chunk)| {
            context.run(|| {
                let values = crate::linalg::schur::eigenvalues(stack.get(index))
                    .map_err(|e| Error::in_batch(index, e))?;
                chunk.copy_from_slice(&values);
                Ok(())
            })
        })
}

/// The data of a batch of Riccati equations A^T X + X A - X B R^-1 B^T X + Q = 0 (6.199).
/// Each stack holds either one matrix, shared by every problem, or one per problem; so a
/// sweep of one model over k weights is A, B, Q of one matrix each and a stack of k R's.
#[derive(Debug, Clone, Copy)]
pub struct CareStacks<'a> {
    pub a: MatrixStack<'a>,
    pub b: MatrixStack<'a>,
    pub q: MatrixStack<'a>,
    pub r: MatrixStack<'a>,
}

impl CareStacks<'_> {
    /// B with n rows, Q n x n and R m x m, for A n x n and B n x m: checked before any problem
    /// (an empty batch or a problem of order 0 has no member that would check them).
    fn check_shapes(&self) -> Result<(), Error> {
        let (n, m) = (self.a.rows, self.b.cols);
        if self.a.cols != n {
            return Err(Error::NotSquare {
                arg: "A",
                rows: n,
                cols: self.a.cols,
            });
        }
        for (arg, stack, order, other) in [
            ("B", &self.b, n, "A"),
            ("Q", &self.q, n, "A"),
            ("R", &self.r, m, "the columns of B"),
        ] {
            if stack.rows != order {
                return Err(Error::Mismatch {
                    arg,
                    what: "as many rows as",
                    expected: order,
                    other,
                    got: stack.rows,
                });
            }
        }
        for (arg, stack) in [("Q", &self.q), ("R", &self.r)] {
            if stack.cols != stack.rows {
                return Err(Error::NotSquare {
                    arg,
                    rows: stack.rows,
                    cols: stack.cols,
                });
            }
        }
        Ok(())
    }

    /// The number of problems k: the stacks that do not hold one matrix must all hold k (an
    /// empty stack makes an empty batch); k = 1 when every stack holds one.
    pub fn count(&self) -> Result<usize, Error> {
        batch_count(&[
            ("A", self.a.len()),
            ("B", self.b.len()),
            ("Q", self.q.len()),
            ("R", self.r.len()),
        ])
    }
}

/// The number of problems k of arguments that each hold one member (shared by every problem)
/// or k: the arguments that do not hold one must all hold k (an empty argument makes an
/// empty batch); k = 1 when every argument holds one.
pub fn batch_count(lengths: &[(&'static str, usize)]) -> Result<usize, Error> {
    let Some(&(first, count)) = lengths.iter().find(|&&(_, len)| len != 1) else {
        return Ok(1);
    };
    for &(arg, len) in lengths {
        if len != 1 && len != count {
            return Err(Error::Mismatch {
                arg,
                what: "1 (shared by every problem) or as many problems as",
                expected: count,
                other: first,
                got: len,
            });
        }
    }
    Ok(count)
}

/// A matrix's entries, row by row.
fn write_row_major(matrix: &DMatrix<f64>, out: &mut [f64]) {
    let cols = matrix.ncols();
    for (i, row) in out.chunks_exact_mut(cols.max(1)).enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = matrix[(i, j)];
        }
    }
}

/// The k-th matrix of a stack that holds one (shared) or k.
fn member<'a>(stack: &MatrixStack<'a>, index: usize) -> MatRef<'a, f64> {
    stack.get(if stack.len() == 1 { 0 } else { index })
}

/// Err naming the lowest failing index of a batch (with its error), or Ok when none failed.
fn lowest_failure(failure: Option<(usize, Error)>) -> Result<(), Error> {
    match failure {
        Some((index, error)) => Err(Error::in_batch(index, error)),
        None => Ok(()),
    }
}

/// Where [`care_batch`] writes: for problem k, X (n x n) and K (m x n) row-major at
/// k n^2 and k m n, the closed-loop eigenvalues at k n, the relative residual and rcond(U11)
/// at k.
pub struct CareBatchOutput<'a> {
    pub x: &'a mut [f64],
    pub gain: &'a mut [f64],
    pub poles: &'a mut [c64],
    pub residual: &'a mut [f64],
    pub rcond: &'a mut [f64],
}

/// Which algebraic Riccati equation a batch solves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RiccatiKind {
    /// The continuous equation (6.199) by [`solve_care_dense`], refined by Newton's method or
    /// not.
    Continuous { refine: bool },
    /// The discrete equation by [`solve_dare`].
    Discrete,
}

/// Solves every Riccati equation of a batch, in parallel (one problem per rayon task, each
/// exactly as [`crate::control::riccati::care::solve_care`] solves it alone, so the results are bitwise those of single
/// calls), except a refined sweep over R alone, solved in groups by Newton's method from the
/// problems before (`care_sweep`). If any problem fails, the error of the lowest index is
/// returned, naming that index, and the outputs are unspecified.
pub fn care_batch(
    stacks: CareStacks<'_>,
    refine: bool,
    out: CareBatchOutput<'_>,
) -> Result<(), Error> {
    riccati_batch(stacks, RiccatiKind::Continuous { refine }, out)
}

/// [`care_batch`] for either equation: the discrete one solved as
/// [`crate::control::riccati::dare::solve_dare`] solves it alone.
pub fn riccati_batch(
    stacks: CareStacks<'_>,
    kind: RiccatiKind,
    out: CareBatchOutput<'_>,
) -> Result<(), Error> {
    let count = stacks.count()?;
    let (n, m) = (stacks.a.rows, stacks.b.cols);
    check_output_len(out.x.len(), count * n * n)?;
    check_output_len(out.gain.len(), count * m * n)?;
    check_output_len(out.poles.len(), count * n)?;
    check_output_len(out.residual.len(), count)?;
    check_output_len(out.rcond.len(), count)?;
    stacks.check_shapes()?;
    if count == 0 {
        // No problem to solve, but shared members are still the caller's arguments.
        for (arg, stack) in [
            ("A", &stacks.a),
            ("B", &stacks.b),
            ("Q", &stacks.q),
            ("R", &stacks.r),
        ] {
            for index in 0..stack.len() {
                check_finite(stack.get(index), arg)?;
            }
        }
        return Ok(());
    }
    if n == 0 {
        // Nothing to write but the diagnostics; each problem still checked (R above all) and
        // reported as the single solver reports it.
        let failure = (0..count).find_map(|index| {
            let problem = (
                member(&stacks.a, index),
                member(&stacks.b, index),
                member(&stacks.q, index),
                member(&stacks.r, index),
            );
            match solve_one(problem, kind, None) {
                Ok(solved) => {
                    (out.residual[index], out.rcond[index]) = (solved.residual, solved.rcond);
                    None
                }
                Err(error) => Some((index, error)),
            }
        });
        return lowest_failure(failure);
    }
    // A sweep over R (A, B and Q shared): their part of the continuous solve formed once.
    let shared = match kind {
        RiccatiKind::Continuous { .. }
            if [&stacks.a, &stacks.b, &stacks.q]
                .iter()
                .all(|s| s.len() == 1) =>
        {
            SharedPlant::of(stacks.a.get(0), stacks.b.get(0), stacks.q.get(0))
        }
        _ => None,
    };
    // The Hamiltonian (or the compressed symplectic pencil) is of order 2n.
    let context = ParallelContext::capture(2 * n);
    if let (RiccatiKind::Continuous { refine: true }, Some(plant)) = (kind, shared.as_ref())
        && m > 0
    {
        return care_sweep(stacks, plant, count, &context, out);
    }
    let failure = out
        .x
        .par_chunks_mut(n * n)
        .zip(par_chunks(out.gain, m * n, count))
        .zip(out.poles.par_chunks_mut(n))
        .zip(out.residual.par_iter_mut())
        .zip(out.rcond.par_iter_mut())
        .enumerate()
        .filter_map(|(index, ((((x, gain), poles), residual), rcond))| {
            let (a, b, q, r) = (
                member(&stacks.a, index),
                member(&stacks.b, index),
                member(&stacks.q, index),
                member(&stacks.r, index),
            );
            let solved = context.run(|| solve_one((a, b, q, r), kind, shared.as_ref()));
            match solved {
                Ok(solved) => {
                    solved.write(x, gain, n, m);
                    poles.copy_from_slice(&solved.poles);
                    (*residual, *rcond) = (solved.residual, solved.rcond);
                    None
                }
                Err(error) => Some((index, error)),
            }
        })
        .min_by_key(|(index, _)| *index);
    lowest_failure(failure)
}

/// Consecutive problems of a sweep over R solved one after the other by one task of
/// `care_sweep`. Fixed, so that the result does not depend on the number of threads, and a
/// divisor of the Python package's DISTRIBUTED_CHUNK (4096), so that a sweep cut into chunks
/// for a cluster is solved bit for bit as here.
pub const SWEEP_GROUP: usize = 32;

/// [`riccati_batch`] of the continuous equation with refinement where A, B and Q are shared
/// (`plant`) and m > 0: a sweep over R. The problems are cut into groups of [`SWEEP_GROUP`]
/// consecutive ones, in parallel; in a group the first is solved by the Schur method and
/// each next one by Newton's method from the solution before it
/// ([`SharedPlant::solve_near`]), or by the Schur method where Newton's method does not
/// converge or its solution fails the checks. Every result is verified as the Schur
/// method's is; a failure is reported as the Schur method reports it, naming the lowest
/// failing index.
fn care_sweep(
    stacks: CareStacks<'_>,
    plant: &SharedPlant,
    count: usize,
    context: &ParallelContext,
    out: CareBatchOutput<'_>,
) -> Result<(), Error> {
    let (n, m, group) = (stacks.a.rows, stacks.b.cols, SWEEP_GROUP);
    let kind = RiccatiKind::Continuous { refine: true };
    let failure = out
        .x
        .par_chunks_mut(group * n * n)
        .zip(out.gain.par_chunks_mut(group * m * n))
        .zip(out.poles.par_chunks_mut(group * n))
        .zip(out.residual.par_chunks_mut(group))
        .zip(out.rcond.par_chunks_mut(group))
        .enumerate()
        .with_min_len(min_items_per_task(count, 2 * n).div_ceil(group).max(1))
        .filter_map(|(group_index, ((((x, gain), poles), residual), rcond))| {
            // The solutions of the last problems, oldest first, while they were solved in
            // turn, and how many of the steps between them are smooth ([`smooth_step`]).
            let mut history: Vec<CareDense> = Vec::with_capacity(EXTRAPOLATION_WEIGHTS.len());
            let mut smooth = 0;
            for offset in 0..residual.len() {
                let index = group_index * group + offset;
                let (a, b, q, r) = (
                    member(&stacks.a, index),
                    member(&stacks.b, index),
                    member(&stacks.q, index),
                    member(&stacks.r, index),
                );
                let solved = context.run(|| {
                    // Extrapolated through as many solutions as the steps are smooth.
                    smooth = if offset >= 2 && smooth_step(&stacks.r, index) {
                        smooth + 1
                    } else {
                        0
                    };
                    let used = history.len().min(smooth + 1);
                    let warm = (used > 0)
                        .then(|| plant.solve_near(b, r, &history[history.len() - used..]))
                        .flatten();
                    match warm.map(Ok).or_else(|| plant.solve(a, b, r, true)) {
                        Some(care) => care.map(Ok),
                        None => solve_one((a, b, q, r), kind, None).map(Err),
                    }
                });
                let (x, gain) = (
                    &mut x[offset * n * n..(offset + 1) * n * n],
                    &mut gain[offset * m * n..(offset + 1) * m * n],
                );
                let poles = &mut poles[offset * n..(offset + 1) * n];
                match solved {
                    Ok(Ok(care)) => {
                        write_row_major(&care.x, x);
                        write_row_major(&care.gain, gain);
                        poles.copy_from_slice(&care.closed_loop_eigenvalues);
                        (residual[offset], rcond[offset]) = (care.residual, care.rcond);
                        if history.len() == EXTRAPOLATION_WEIGHTS.len() {
                            history.remove(0);
                        }
                        history.push(care);
                    }
                    Ok(Err(solved)) => {
                        solved.write(x, gain, n, m);
                        poles.copy_from_slice(&solved.poles);
                        (residual[offset], rcond[offset]) = (solved.residual, solved.rcond);
                        history.clear();
                    }
                    // The lowest failing index of the group: those after it cannot be lower.
                    Err(error) => return Some((index, error)),
                }
            }
            None
        })
        .min_by_key(|(index, _)| *index);
    lowest_failure(failure)
}

/// Whether R of problems `index` - 2, `index` - 1 and `index` lie nearly evenly along a line:
/// ||R_k - 2 R_{k-1} + R_{k-2}||_F <= ||R_k - R_{k-1}||_F / 2 (a geometric sweep of c by a
/// ratio q per step has q - 1 on the left of the 1/2), where X_k is extrapolated as
/// 2 X_{k-1} - X_{k-2} for Newton's method.
fn smooth_step(r: &MatrixStack<'_>, index: usize) -> bool {
    let (now, last, first) = (r.get(index), r.get(index - 1), r.get(index - 2));
    let (mut second, mut step) = (0.0, 0.0);
    for j in 0..now.ncols() {
        for i in 0..now.nrows() {
            let d = now[(i, j)] - last[(i, j)];
            let e = d - (last[(i, j)] - first[(i, j)]);
            (second, step) = (second + e * e, step + d * d);
        }
    }
    second <= 0.25 * step
}

/// One problem's solution as a batch writes it.
struct Solved {
    solution: Solution,
    poles: Vec<c64>,
    residual: f64,
    rcond: f64,
}

/// X and K as the solver that found them holds them.
enum Solution {
    Small { x: DMatrix<f64>, gain: DMatrix<f64> },
    Faer { x: Mat<f64>, gain: Mat<f64> },
}

impl From<AlgebraicSolution> for Solved {
    fn from(solution: AlgebraicSolution) -> Self {
        Self {
            solution: Solution::Faer {
                x: solution.x,
                gain: solution.gain,
            },
            poles: solution.closed_loop_eigenvalues,
            residual: solution.residual,
            rcond: solution.rcond,
        }
    }
}

impl Solved {
    /// X (n x n) and K (m x n), row-major, into `x` and `gain`.
    fn write(&self, x: &mut [f64], gain: &mut [f64], n: usize, m: usize) {
        match &self.solution {
            Solution::Small { x: xd, gain: kd } => {
                write_row_major(xd, x);
                write_row_major(kd, gain);
            }
            Solution::Faer { x: xm, gain: km } => {
                MatMut::from_row_major_slice_mut(x, n, n).copy_from(xm);
                MatMut::from_row_major_slice_mut(gain, m, n).copy_from(km);
            }
        }
    }
}

impl From<CareDense> for Solved {
    fn from(care: CareDense) -> Self {
        Self {
            solution: Solution::Small {
                x: care.x,
                gain: care.gain,
            },
            poles: care.closed_loop_eigenvalues,
            residual: care.residual,
            rcond: care.rcond,
        }
    }
}

/// One problem of a batch, solved exactly as the single solver solves it: the continuous
/// equation in scaled units where [`solve_care_scaled`] scales it, else by the Cholesky path
/// (through `shared`, the part of A, B and Q that every problem shares, where it is given and
/// applies), or (an R symmetric but not positive definite) by [`solve_care`]'s extended
/// pencil; the discrete one by [`solve_dare`].
fn solve_one(
    (a, b, q, r): (
        MatRef<'_, f64>,
        MatRef<'_, f64>,
        MatRef<'_, f64>,
        MatRef<'_, f64>,
    ),
    kind: RiccatiKind,
    shared: Option<&SharedPlant>,
) -> Result<Solved, Error> {
    match kind {
        RiccatiKind::Continuous { refine } => {
            if let Some(solved) = shared.and_then(|plant| plant.solve(a, b, r, refine)) {
                return solved.map(Solved::from);
            }
            let options = CareOptions {
                refine,
                ..CareOptions::default()
            };
            if let Some(scaled) = solve_care_scaled(a, b, q, r, options, indefinite_weight(b, r)) {
                return scaled.map(Solved::from);
            }
            match solve_care_dense(a, b, q, r, options) {
                Ok(care) => Ok(Solved::from(care)),
                // solve_care routes such an R to the extended pencil (or refuses it as the
                // single call does).
                Err(Error::NotPositiveDefinite { arg: "R", .. }) => {
                    solve_care(a, b, q, r, options).map(Solved::from)
                }
                Err(error) => Err(error),
            }
        }
        RiccatiKind::Discrete => solve_dare(a, b, q, r, DareOptions::default()).map(Solved::from),
    }
}

/// A pole-placement algorithm of [`crate::control::placement`].
pub type Placer = fn(MatRef<'_, f64>, MatRef<'_, f64>, &[c64]) -> Result<Placement, Error>;

/// Where [`place_batch`] writes: for problem k, K (m x n) row-major at k m n, the achieved
/// poles (in the order of the requested ones) at k n, the largest relative pole error and
/// the condition number that bounds it (κ(V) of the single-input formulas, κ(X) of the
/// robust method) at k.
pub struct PlaceBatchOutput<'a> {
    pub gain: &'a mut [f64],
    pub achieved: &'a mut [c64],
    pub max_relative_error: &'a mut [f64],
    pub condition: &'a mut [f64],
}

/// Places the poles of every problem of a batch, in parallel, each exactly as `placer`
/// places them alone. `a` and `b` hold one matrix (shared) or one per problem, `poles` holds
/// `rows` rows of n requested poles, row-major: one (shared) or one per problem. If any problem
/// fails, the error of the lowest index is returned, naming it.
pub fn place_batch(
    a: MatrixStack<'_>,
    b: MatrixStack<'_>,
    poles: &[c64],
    rows: usize,
    placer: Placer,
    out: PlaceBatchOutput<'_>,
) -> Result<(), Error> {
    let (n, m) = (a.rows, b.cols);
    if a.cols != n {
        return Err(Error::NotSquare {
            arg: "A",
            rows: n,
            cols: a.cols,
        });
    }
    if b.rows != n {
        return Err(Error::Mismatch {
            arg: "B",
            what: "as many rows as",
            expected: n,
            other: "A",
            got: b.rows,
        });
    }
    if n == 0 || m == 0 {
        return Err(Error::InvalidArgument {
            arg: "A, B",
            message: format!(
                "pole placement needs at least one state and one input, got n = {n}, m = {m}"
            ),
        });
    }
    if poles.len() != rows.saturating_mul(n) {
        return Err(Error::Mismatch {
            arg: "poles",
            what: "one row of poles per problem, rows x n values with n the order of",
            expected: rows.saturating_mul(n),
            other: "A",
            got: poles.len(),
        });
    }
    let count = batch_count(&[("A", a.len()), ("B", b.len()), ("poles", rows)])?;
    check_output_len(out.gain.len(), count * m * n)?;
    check_output_len(out.achieved.len(), count * n)?;
    check_output_len(out.max_relative_error.len(), count)?;
    check_output_len(out.condition.len(), count)?;
    let context = ParallelContext::capture(n.max(m));
    let failure = out
        .gain
        .par_chunks_mut(m * n)
        .zip(out.achieved.par_chunks_mut(n))
        .zip(out.max_relative_error.par_iter_mut())
        .zip(out.condition.par_iter_mut())
        .enumerate()
        .filter_map(|(index, (((gain, achieved), error), condition))| {
            let row = if rows == 1 { 0 } else { index };
            let placed = context.run(|| {
                placer(
                    member(&a, index),
                    member(&b, index),
                    &poles[row * n..(row + 1) * n],
                )
            });
            match placed {
                Ok(design) => {
                    MatMut::from_row_major_slice_mut(gain, m, n).copy_from(&design.gain);
                    achieved.copy_from_slice(&design.achieved_poles);
                    *error = design.max_relative_error;
                    *condition = if design.controllability_condition.is_nan() {
                        design.eigenvector_condition
                    } else {
                        design.controllability_condition
                    };
                    None
                }
                Err(error) => Some((index, error)),
            }
        })
        .min_by_key(|(index, _)| *index);
    lowest_failure(failure)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::riccati::care::solve_care;
    use crate::linalg::expm::expm;

    #[test]
    fn batch_equals_one_at_a_time() {
        let (k, n) = (37, 5);
        let data: Vec<f64> = (0..k * n * n)
            .map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0)
            .collect();
        let stack = MatrixStack::new(&data, k, n, n).unwrap();
        let mut out = vec![0.0; k * n * n];
        expm_batch(stack, &mut out).unwrap();
        for index in 0..k {
            let single = expm(stack.get(index)).unwrap();
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(out[index * n * n + i * n + j], single[(i, j)]);
                }
            }
        }
    }

    #[test]
    fn error_names_the_failing_index() {
        let (k, n) = (4, 2);
        let mut data = vec![0.5; k * n * n];
        data[2 * n * n + 3] = f64::INFINITY;
        let mut out = vec![0.0; k * n * n];
        let err = expm_batch(MatrixStack::new(&data, k, n, n).unwrap(), &mut out).unwrap_err();
        assert_eq!(
            err.to_string(),
            "problem 2 of the batch: A must be finite, but A[1, 1] is inf"
        );
    }

    #[test]
    fn error_in_a_later_group_names_its_index() {
        // 40 matrices of order 4 run in groups of 16: a rotation by 1e50 rad at index 37 (the
        // sixth of the third group) is refused as ill-conditioned, with its own index.
        let (k, n) = (40, 4);
        let mut data = vec![0.0; k * n * n];
        for (index, matrix) in data.chunks_exact_mut(n * n).enumerate() {
            for i in 0..n {
                matrix[i * n + i] = -0.1 * (index + i) as f64;
            }
        }
        data[37 * n * n + 1] = 1e50;
        data[37 * n * n + n] = -1e50;
        let mut out = vec![0.0; k * n * n];
        let err = expm_batch(MatrixStack::new(&data, k, n, n).unwrap(), &mut out).unwrap_err();
        assert!(
            err.to_string().starts_with("problem 37 of the batch: "),
            "{err}"
        );
    }

    #[test]
    fn empty_stacks() {
        let mut out = vec![];
        expm_batch(MatrixStack::new(&[], 0, 3, 3).unwrap(), &mut out).unwrap();
        expm_batch(MatrixStack::new(&[], 5, 0, 0).unwrap(), &mut out).unwrap();
    }

    /// The 747 lateral model (6.150) with B = [rudder, aileron] (6.158), (6.163).
    fn lateral() -> (Vec<f64>, Vec<f64>) {
        let a = vec![
            -0.0999, 0.0, 0.1153, -1.0, -1.6038, -1.0932, 0.0, 0.2850, 0.0, 1.0, 0.0, 0.0, 0.4089,
            -0.0395, 0.0, -0.2454,
        ];
        let b = vec![0.0182, 0.0, 0.0868, 0.3215, 0.0, 0.0, -0.2440, -0.0017];
        (a, b)
    }

    fn identity(n: usize) -> Vec<f64> {
        (0..n * n)
            .map(|i| if i % (n + 1) == 0 { 1.0 } else { 0.0 })
            .collect()
    }

    struct Outputs {
        x: Vec<f64>,
        gain: Vec<f64>,
        poles: Vec<c64>,
        residual: Vec<f64>,
        rcond: Vec<f64>,
    }

    fn run(stacks: CareStacks<'_>, count: usize, n: usize, m: usize) -> Result<Outputs, Error> {
        let mut o = Outputs {
            x: vec![0.0; count * n * n],
            gain: vec![0.0; count * m * n],
            poles: vec![c64::new(0.0, 0.0); count * n],
            residual: vec![0.0; count],
            rcond: vec![0.0; count],
        };
        let out = CareBatchOutput {
            x: &mut o.x,
            gain: &mut o.gain,
            poles: &mut o.poles,
            residual: &mut o.residual,
            rcond: &mut o.rcond,
        };
        care_batch(stacks, true, out).map(|()| o)
    }

    /// A sweep of the chapter's weight c (R = I / c^2, (6.226)) over one model.
    fn weights(cs: &[f64]) -> Vec<f64> {
        cs.iter()
            .flat_map(|c| [1.0 / (c * c), 0.0, 0.0, 1.0 / (c * c)])
            .collect()
    }

    /// A sweep over R: its first problem solved by the Schur method bit for bit as alone, the
    /// others by Newton's method from the solutions before them, within 1e-13 of the Schur
    /// method's and with as small a residual; the eigenvalues the same set to 1e-12.
    #[test]
    fn care_sweep_agrees_with_one_at_a_time() {
        let (a, b) = lateral();
        let q = identity(4);
        let cs = [0.001, 0.5, 1.0, 2.0, 9.7727, 10.0, 50.0];
        let r = weights(&cs);
        let stacks = CareStacks {
            a: MatrixStack::new(&a, 1, 4, 4).unwrap(),
            b: MatrixStack::new(&b, 1, 4, 2).unwrap(),
            q: MatrixStack::new(&q, 1, 4, 4).unwrap(),
            r: MatrixStack::new(&r, cs.len(), 2, 2).unwrap(),
        };
        let o = run(stacks, cs.len(), 4, 2).unwrap();
        for (k, _) in cs.iter().enumerate() {
            let single = solve_care(
                stacks.a.get(0),
                stacks.b.get(0),
                stacks.q.get(0),
                stacks.r.get(k),
                CareOptions {
                    refine: true,
                    ..CareOptions::default()
                },
            )
            .unwrap();
            let x = MatRef::from_row_major_slice(&o.x[k * 16..(k + 1) * 16], 4, 4);
            let gain = MatRef::from_row_major_slice(&o.gain[k * 8..(k + 1) * 8], 2, 4);
            if k == 0 {
                assert_eq!(x, single.x.as_ref());
                assert_eq!(gain, single.gain.as_ref());
                assert_eq!(&o.poles[..4], &single.closed_loop_eigenvalues[..]);
                assert_eq!((o.residual[0], o.rcond[0]), (single.residual, single.rcond));
                continue;
            }
            let relative = |m: MatRef<'_, f64>, reference: MatRef<'_, f64>| {
                (m - reference).norm_l2() / reference.norm_l2()
            };
            assert!(relative(x, single.x.as_ref()) < 1e-13, "k={k}");
            assert!(relative(gain, single.gain.as_ref()) < 1e-13, "k={k}");
            assert!(
                o.residual[k] <= (4.0 * f64::EPSILON).max(single.residual),
                "k={k}"
            );
            let sorted = |poles: &[c64]| {
                let mut poles = poles.to_vec();
                poles.sort_by(|x, y| x.re.total_cmp(&y.re).then(x.im.total_cmp(&y.im)));
                poles
            };
            for (p, s) in sorted(&o.poles[k * 4..(k + 1) * 4])
                .iter()
                .zip(sorted(&single.closed_loop_eigenvalues))
            {
                assert!((p - s).norm() <= 1e-12 * s.norm(), "k={k}: {p} vs {s}");
            }
            // rcond(U11) of another orthonormal basis of the same subspace: within n^2.
            let ratio = o.rcond[k] / single.rcond;
            assert!((1.0 / 16.0..=16.0).contains(&ratio), "k={k}: {ratio}");
        }
    }

    #[test]
    fn care_batch_reports_the_lowest_failing_index() {
        let (a, b) = lateral();
        let q = identity(4);
        let mut r = weights(&[1.0, 1.0, 1.0, 1.0, 1.0]);
        r[3 * 4] = 0.0; // R of problem 3 is singular (an indefinite one is solved)
        r[4 * 4 + 1] = 0.5; // R of problem 4 is not symmetric
        let stacks = CareStacks {
            a: MatrixStack::new(&a, 1, 4, 4).unwrap(),
            b: MatrixStack::new(&b, 1, 4, 2).unwrap(),
            q: MatrixStack::new(&q, 1, 4, 4).unwrap(),
            r: MatrixStack::new(&r, 5, 2, 2).unwrap(),
        };
        let error = run(stacks, 5, 4, 2).err().unwrap();
        assert!(matches!(error, Error::InBatch { index: 3, .. }));
        assert!(
            error
                .to_string()
                .starts_with("problem 3 of the batch: R must be nonsingular")
        );
    }

    #[test]
    fn care_batch_stacks_must_agree() {
        let (a, b) = lateral();
        let q = [identity(4), identity(4)].concat();
        let r = weights(&[1.0, 2.0, 3.0]);
        let stacks = CareStacks {
            a: MatrixStack::new(&a, 1, 4, 4).unwrap(),
            b: MatrixStack::new(&b, 1, 4, 2).unwrap(),
            q: MatrixStack::new(&q, 2, 4, 4).unwrap(),
            r: MatrixStack::new(&r, 3, 2, 2).unwrap(),
        };
        let error = run(stacks, 3, 4, 2).err().unwrap();
        assert_eq!(
            error.to_string(),
            "R must have 1 (shared by every problem) or as many problems as Q (2), got 3"
        );
    }

    #[test]
    fn care_batch_without_inputs_solves_lyapunov_equations() {
        // m = 0: A^T X + X A + Q = 0; for A = -I, Q = I, X = I / 2.
        let a = [-1.0, 0.0, 0.0, -1.0];
        let q = identity(2);
        let stacks = CareStacks {
            a: MatrixStack::new(&a, 1, 2, 2).unwrap(),
            b: MatrixStack::new(&[], 1, 2, 0).unwrap(),
            q: MatrixStack::new(&q, 1, 2, 2).unwrap(),
            r: MatrixStack::new(&[], 3, 0, 0).unwrap(),
        };
        let o = run(stacks, 3, 2, 0).unwrap();
        assert_eq!(o.x, [0.5, 0.0, 0.0, 0.5].repeat(3));
    }

    #[test]
    fn place_batch_equals_one_at_a_time_and_names_the_failing_index() {
        use crate::control::placement::{place, place_bass_gura};
        let (a, b) = lateral();
        let rudder: Vec<f64> = b.chunks(2).map(|row| row[0]).collect();
        // Two designs per problem: move the Dutch roll to each damping ratio, keep the rest.
        let designs = [0.2, 0.3, 0.5];
        let poles: Vec<c64> = designs
            .iter()
            .flat_map(|zeta: &f64| {
                let omega = 0.7477;
                let (re, im) = (-zeta * omega, omega * (1.0 - zeta * zeta).sqrt());
                [
                    c64::new(re, im),
                    c64::new(re, -im),
                    c64::new(-1.2308, 0.0),
                    c64::new(-0.04641, 0.0),
                ]
            })
            .collect();
        let a_stack = MatrixStack::new(&a, 1, 4, 4).unwrap();
        for (input, placer, m) in [
            (&rudder[..], place_bass_gura as Placer, 1),
            (&b[..], place as Placer, 2),
        ] {
            let b_stack = MatrixStack::new(input, 1, 4, m).unwrap();
            let (mut gain, mut achieved) = (vec![0.0; 3 * m * 4], vec![c64::new(0.0, 0.0); 12]);
            let (mut error, mut condition) = (vec![0.0; 3], vec![0.0; 3]);
            let out = PlaceBatchOutput {
                gain: &mut gain,
                achieved: &mut achieved,
                max_relative_error: &mut error,
                condition: &mut condition,
            };
            place_batch(a_stack, b_stack, &poles, 3, placer, out).unwrap();
            for k in 0..3 {
                let single =
                    placer(a_stack.get(0), b_stack.get(0), &poles[4 * k..4 * k + 4]).unwrap();
                for row in 0..m {
                    for col in 0..4 {
                        assert_eq!(gain[k * m * 4 + row * 4 + col], single.gain[(row, col)]);
                    }
                }
                assert_eq!(&achieved[4 * k..4 * k + 4], &single.achieved_poles[..]);
                assert_eq!(error[k], single.max_relative_error);
                assert!(error[k] < 1e-10 && condition[k].is_finite());
            }
        }
        // A complex pole without its conjugate in problem 1 of 3.
        let mut broken = poles.clone();
        broken[5] = c64::new(-0.2, 0.5);
        let b_stack = MatrixStack::new(&rudder, 1, 4, 1).unwrap();
        let (mut gain, mut achieved) = (vec![0.0; 12], vec![c64::new(0.0, 0.0); 12]);
        let (mut error, mut condition) = (vec![0.0; 3], vec![0.0; 3]);
        let out = PlaceBatchOutput {
            gain: &mut gain,
            achieved: &mut achieved,
            max_relative_error: &mut error,
            condition: &mut condition,
        };
        let failure = place_batch(a_stack, b_stack, &broken, 3, place_bass_gura, out).unwrap_err();
        assert!(
            matches!(failure, Error::InBatch { index: 1, .. }),
            "{failure}"
        );
    }
}
