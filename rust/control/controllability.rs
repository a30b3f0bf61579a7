//! Controllability and observability (chapter §6.4): the matrices of (6.74) and (6.89), and a
//! verdict that does not rest on their rank.
//!
//! # Why not the rank of the controllability matrix
//!
//! The columns A^k B of V = [B AB ... A^{n-1}B] (6.74) line up with the dominant eigenvectors
//! as k grows, so the singular values of V decay geometrically even for a strongly controllable
//! system: the numerical rank of V understates controllability (a random controllable system
//! of order 64 has a V whose rank numpy puts at about 61). [`ctrb`] and [`obsv_transposed`] (O^T) are provided
//! for the chapter's hand analysis and for Bass–Gura; the verdict comes from the staircase form.
//!
//! # Staircase form
//!
//! An orthogonal Z brings (A, B) to
//!
//! ```text
//! Z^T A Z = [ A_c  A_cu ]      Z^T B = [ B_c ]
//!           [ 0    A_u  ]              [ 0   ]
//! ```
//!
//! with (A_c, B_c) in controllability staircase (block Hessenberg) form: B_c = [B_1; 0; ...; 0]
//! and every subdiagonal block A_{k+1,k} of full row rank r_{k+1}, so that (A_c, B_c) is
//! controllable by construction and the eigenvalues of A_u are exactly the uncontrollable ones
//! (Van Dooren 1981; Paige 1981). The form is built block by block: a Householder QR with
//! column pivoting of the current block column (B, then the part of A below the last block)
//! compresses it into its first r rows, where r is the number of pivots whose remaining column
//! norm exceeds the tolerance; the reflectors are applied to A from both sides and accumulated
//! in Z. The reduction stops when a block column has rank 0 (what remains is A_u) or when the
//! blocks fill the state.
//!
//! Orthogonal transformations make the computed form the exact form of a nearby system
//! (A + E, B + F) with ||[E F]|| = O(n u ||[A B]||). The default tolerance is therefore
//!
//! ```text
//! tol = n u max(||A||_F, ||B||_F),
//! ```
//!
//! and a verdict "uncontrollable" means that a perturbation of about that size makes the system
//! exactly uncontrollable. The smallest pivot accepted along the way is reported: it shows how
//! close the verdict came to the other answer (it bounds from above, not below, the distance to
//! the nearest uncontrollable system).
//!
//! # The staircase's blind spot, and the modal test
//!
//! The staircase is backward stable, but its pivots do not measure the distance to the nearest
//! uncontrollable system (Paige 1981). When an uncontrollable mode dominates the controllable
//! ones, rounding errors of size u put a component along it into the first block, and the
//! repeated multiplication by A amplifies that component like |λ_u / λ_c|^k until it looks like
//! a healthy pivot: a 64-state system with a planted uncontrollable eigenvalue 6 among
//! controllable ones of modulus below 2 comes out "controllable" with every pivot above 0.1.
//! [`controllability`] therefore also applies the chapter's modal test (6.61), as the
//! Popov–Belevitch–Hautus test at each eigenvalue: with w_k the unit left eigenvector of
//! λ_k (w_k^T A = λ_k w_k^T), the mode is uncontrollable when ||w_k^T B|| <= tol. Since
//! ||w_k^T (A - λ_k I)|| is at rounding level, ||w_k^T B|| bounds from above the smallest
//! singular value of [A - λ_k I, B], so a mode this test flags is within tol of being exactly
//! uncontrollable. The two tests cover each other's weakness: the modal test cannot see a
//! repeated eigenvalue whose eigenspace is only partly reachable (A = I, B = [1, 1]^T), which
//! the staircase finds at once. The verdict is "controllable" only when both agree.
//!
//! # Balanced states
//!
//! Both tests are accurate to u times the norm of the pair. Where A's states are scaled apart
//! (units 10^3 or more apart), both run on the pair (T A T^-1, T B) balanced by a diagonal T of
//! powers of two ([`balanced_pair`]), which is exact and changes no verdict; the tolerance,
//! the measures and the form are those of that pair, and the transformation is Z = T^-1 Q.
//!
//! Observability is the dual: (A, C) is observable if and only if (A^T, C^T) is controllable,
//! and the unobservable eigenvalues of (A, C) are the uncontrollable ones of (A^T, C^T).

use crate::control::modal::eigen;
use crate::error::{Error, check_finite, check_rows, check_square};
use crate::linalg::balance::{balanced_where_scaled_apart, range_scale, scale_for_largest};
use crate::linalg::dense::view_product_into;
use crate::linalg::householder::reflector;
use crate::linalg::norm::{frobenius_norm, max_abs, vector_norm};
use crate::linalg::schur::eigenvalues;
use crate::platform::parallel::parallelism_for_order;
use faer::linalg::matmul::matmul;
use faer::prelude::{IntoConst, Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par, c64};

/// The controllability matrix V = [B AB A^2B ... A^{n-1}B] (6.74), n x nm.
pub fn ctrb(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")?;
    Ok(krylov_blocks(a, b))
}

/// Checks A (square, finite) and C (one column per state, finite).
fn check_output_pair(a: MatRef<'_, f64>, c: MatRef<'_, f64>) -> Result<(), Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    if c.ncols() != a.nrows() {
        return Err(Error::Mismatch {
            arg: "C",
            what: "one column per row of",
            expected: a.nrows(),
            other: "A",
            got: c.ncols(),
        });
    }
    check_finite(c, "C")
}

/// The transpose of the observability matrix [C; CA; CA^2; ...; CA^{n-1}] (6.89): the
/// n x np matrix [C^T A^T C^T ...], whose transpose view is the observability matrix. Its
/// column-major storage is the observability matrix's row-major one, so a caller that writes
/// row-major (a numpy array) copies it contiguously instead of transposing it twice.
pub fn obsv_transposed(a: MatRef<'_, f64>, c: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    check_output_pair(a, c)?;
    Ok(krylov_blocks(a.transpose(), c.transpose()))
}

/// [B AB ... A^{n-1}B] for checked arguments. Each block is the product of A with the
/// previous one, written in place. A is copied once into a column-major matrix of its own:
/// the products with a thin block then run faer's column-major kernel whatever the caller's
/// layout (on a row-major A, as numpy passes it, they were n dot products per column, several
/// times slower at n = 256), and every layout gives the same bits.
pub(crate) fn krylov_blocks(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let (n, m) = (a.nrows(), b.ncols());
    let mut v = Mat::<f64>::zeros(n, n * m);
    if n == 0 || m == 0 {
        return v;
    }
    v.as_mut().subcols_mut(0, m).copy_from(b);
    let a = a.to_owned();
    let par = parallelism_for_order(n);
    for k in 1..n {
        let (previous, next) = v.as_mut().split_at_col_mut(k * m);
        let previous = previous.into_const().subcols((k - 1) * m, m);
        view_product_into(next.subcols_mut(0, m), a.as_ref(), previous, par);
    }
    v
}

/// The staircase form of a pair (see the module documentation).
#[derive(Debug, Clone)]
pub struct Staircase {
    /// Z^-1 A Z: block upper triangular for controllability; for observability the transpose
    /// of the dual form, block lower triangular.
    pub a: Mat<f64>,
    /// Z^-1 B (controllability) or C Z (observability).
    pub b: Mat<f64>,
    /// The transformation (empty when it was not requested): orthogonal, or T^-1 Q (T Q for
    /// observability) with Q orthogonal where the states were balanced first.
    pub z: Mat<f64>,
    /// The ranks r_1, r_2, ... of the staircase blocks; they sum to the controllable order.
    pub block_sizes: Vec<usize>,
    /// The dimension of the controllable (observable) subspace.
    pub controllable_order: usize,
    /// The eigenvalues of A_u: the uncontrollable (unobservable) eigenvalues, conjugate pairs
    /// adjacent with Im > 0 first.
    pub uncontrollable_eigenvalues: Vec<c64>,
    /// The rank tolerance used.
    pub tolerance: f64,
    /// The smallest pivot accepted as nonzero (infinite when none was needed).
    pub smallest_pivot: f64,
}

impl Staircase {
    /// Whether every mode is controllable (observable).
    pub fn is_complete(&self) -> bool {
        self.controllable_order == self.a.nrows()
    }
}

/// The controllability staircase form of (A, B); `tolerance` overrides the default rank
/// tolerance n u max(||A||_F, ||B||_F) of the balanced pair (see [`balanced_pair`]). Z is
/// accumulated only `with_transformation`.
pub fn controllability_staircase(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    tolerance: Option<f64>,
    with_transformation: bool,
) -> Result<Staircase, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")?;
    Ok(balanced_staircase(a, b, tolerance, with_transformation, Duality::Primal)?.0)
}

/// The observability staircase form of (A, C), by duality.
pub fn observability_staircase(
    a: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    tolerance: Option<f64>,
    with_transformation: bool,
) -> Result<Staircase, Error> {
    check_output_pair(a, c)?;
    Ok(dual_form(
        balanced_staircase(
            a.transpose(),
            c.transpose(),
            tolerance,
            with_transformation,
            Duality::Dual,
        )?
        .0,
    ))
}

/// The observability form from the staircase of the dual pair (A^T, C^T): its transpose.
fn dual_form(dual: Staircase) -> Staircase {
    Staircase {
        a: dual.a.transpose().to_owned(),
        b: dual.b.transpose().to_owned(),
        ..dual
    }
}

/// Whether a staircase is of a pair (A, B) itself or of the dual (A^T, C^T) of a pair (A, C).
#[derive(Clone, Copy, PartialEq)]
enum Duality {
    Primal,
    Dual,
}

/// (T A T^-1, T B) and the diagonal of T: the states of the pair balanced by powers of two
/// (`linalg/balance.rs`'s Osborne iteration on the rows of [A B] and the columns of A), where
/// A's states are scaled apart ([`balanced_where_scaled_apart`]); None where they are not (the pair
/// is analysed as given) or the scaling would not be exact. Controllability does not depend
/// on the coordinates, but the staircase's reflections and the modal test's unit eigenvectors
/// are accurate to u times the norm of the pair they are given: states in units 10^6 apart put
/// errors of the large states' size into the small states' entries, and a controllable pair
/// came out uncontrollable, with a staircase eigenvalue that A does not have.
fn balanced_pair(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Option<(Mat<f64>, Mat<f64>, Vec<f64>)> {
    let outputs = Mat::<f64>::zeros(0, a.nrows());
    balanced_where_scaled_apart(a, b, outputs.as_ref()).map(|(a, b, _, t)| (a, b, t))
}

/// A pair (A, B) of a plant matrix and its inputs (or the dual (A^T, C^T)).
type Pair = (Mat<f64>, Mat<f64>);

/// The staircase of the pair (A, B) (the dual pair, for observability) balanced first
/// ([`balanced_pair`]), its transformation Z taken back to the pair's own coordinates, with
/// the pair it was computed from (for the modal test). The form is then Z^-1 A Z: Z = T^-1 Q
/// for controllability, and for the dual Z = T Q, which makes the transposed form
/// Z^-1 A Z of (A, C) (Q the staircase's orthogonal transformation).
fn balanced_staircase(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    tolerance: Option<f64>,
    with_transformation: bool,
    duality: Duality,
) -> Result<(Staircase, Option<Pair>), Error> {
    let Some((a_balanced, b_balanced, t)) = balanced_pair(a, b) else {
        return Ok((staircase(a, b, tolerance, with_transformation)?, None));
    };
    let mut form = staircase(
        a_balanced.as_ref(),
        b_balanced.as_ref(),
        tolerance,
        with_transformation,
    )?;
    if with_transformation {
        let q = &form.z;
        form.z = Mat::from_fn(q.nrows(), q.ncols(), |i, j| match duality {
            Duality::Primal => q[(i, j)] / t[i],
            Duality::Dual => q[(i, j)] * t[i],
        });
    }
    Ok((form, Some((a_balanced, b_balanced))))
}

/// The controllability (or observability) verdict of [`controllability`].
#[derive(Debug, Clone)]
pub struct Controllability {
    /// The staircase form and its own verdict.
    pub staircase: Staircase,
    /// The eigenvalues of A, conjugate pairs adjacent with Im > 0 first (empty when the modal
    /// test was not requested).
    pub eigenvalues: Vec<c64>,
    /// ||w_k^T B|| for the unit left eigenvector w_k of each eigenvalue (||C v_k|| for the unit
    /// right eigenvector, for observability): the chapter's modal test (6.61).
    pub modal_measure: Vec<f64>,
    /// The uncontrollable (unobservable) eigenvalues found by either test.
    pub uncontrollable_eigenvalues: Vec<c64>,
    /// The rank tolerance of both tests.
    pub tolerance: f64,
}

impl Controllability {
    /// Whether every mode is controllable (observable).
    pub fn is_complete(&self) -> bool {
        self.uncontrollable_eigenvalues.is_empty()
    }
}

/// The controllability of (A, B) by the staircase form and, with `modal_test`, the modal PBH
/// test (see the module documentation), both on the balanced pair ([`balanced_pair`]);
/// `tolerance` overrides n u max(||A||_F, ||B||_F) of that pair.
pub fn controllability(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    tolerance: Option<f64>,
    modal_test: bool,
    with_transformation: bool,
) -> Result<Controllability, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")?;
    let (form, balanced) =
        balanced_staircase(a, b, tolerance, with_transformation, Duality::Primal)?;
    let (a, b) = balanced
        .as_ref()
        .map_or((a, b), |(a, b)| (a.as_ref(), b.as_ref()));
    combine_with_modal_test(form, a.transpose(), b.transpose(), modal_test)
}

/// The observability of (A, C): the controllability of the dual pair (A^T, C^T).
pub fn observability(
    a: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    tolerance: Option<f64>,
    modal_test: bool,
    with_transformation: bool,
) -> Result<Controllability, Error> {
    check_output_pair(a, c)?;
    let (form, balanced) = balanced_staircase(
        a.transpose(),
        c.transpose(),
        tolerance,
        with_transformation,
        Duality::Dual,
    )?;
    // The modal test of the dual pair (A^T, C^T) takes the eigenvectors of its transpose.
    let (a_dual, c_dual) = balanced
        .as_ref()
        .map_or((a.transpose(), c.transpose()), |(a, c)| {
            (a.as_ref(), c.as_ref())
        });
    combine_with_modal_test(
        dual_form(form),
        a_dual.transpose(),
        c_dual.transpose(),
        modal_test,
    )
}

/// Whether (A, B) is controllable: the verdict of [`controllability`] (no uncontrollable
/// eigenvalue), without the transformation. The modal test runs only where the staircase
/// finds every mode controllable: each eigenvalue of a nonempty A_u stands for an eigenvalue
/// of A among the uncontrollable ones ([`combine_with_modal_test`]), so the verdict is then
/// "not controllable" whatever the modal test adds.
pub fn is_controllable(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    tolerance: Option<f64>,
    modal_test: bool,
) -> Result<bool, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_rows(b, "B", a.nrows(), "A")?;
    check_finite(b, "B")?;
    let (form, balanced) = balanced_staircase(a, b, tolerance, false, Duality::Primal)?;
    if !modal_test || !form.is_complete() {
        return Ok(form.is_complete());
    }
    let (a, b) = balanced
        .as_ref()
        .map_or((a, b), |(a, b)| (a.as_ref(), b.as_ref()));
    Ok(combine_with_modal_test(form, a.transpose(), b.transpose(), true)?.is_complete())
}

/// Whether (A, C) is observable: [`is_controllable`] of the dual pair (A^T, C^T), the verdict
/// of [`observability`].
pub fn is_observable(
    a: MatRef<'_, f64>,
    c: MatRef<'_, f64>,
    tolerance: Option<f64>,
    modal_test: bool,
) -> Result<bool, Error> {
    check_output_pair(a, c)?;
    let (form, balanced) = balanced_staircase(
        a.transpose(),
        c.transpose(),
        tolerance,
        false,
        Duality::Dual,
    )?;
    if !modal_test || !form.is_complete() {
        return Ok(form.is_complete());
    }
    // The modal test of the dual pair (A^T, C^T) takes the eigenvectors of its transpose (the
    // form is only read for its tolerance and A_u's eigenvalues: not transposed back).
    let (a_dual, c_dual) = balanced
        .as_ref()
        .map_or((a.transpose(), c.transpose()), |(a, c)| {
            (a.as_ref(), c.as_ref())
        });
    Ok(combine_with_modal_test(form, a_dual.transpose(), c_dual.transpose(), true)?.is_complete())
}

/// Adds the modal test to a staircase verdict. The eigenvectors of `a_dual` (A^T for
/// controllability) are the left eigenvectors of the pair's plant matrix; `coupling_dual`
/// (B^T) maps them to the measures.
///
/// The uncontrollable eigenvalues are then eigenvalues λ_k of A, each at most once: each
/// eigenvalue of the staircase's A_u stands for the nearest λ_k not yet taken (A_u's are
/// eigenvalues of a nearby pair, and a mode the staircase deflates is one of A's), and the
/// modes the modal test flags are added where the staircase did not take them. So at most n
/// are listed, whatever the two tests' rounding.
fn combine_with_modal_test(
    staircase: Staircase,
    a_dual: MatRef<'_, f64>,
    coupling_dual: MatRef<'_, f64>,
    modal_test: bool,
) -> Result<Controllability, Error> {
    let tolerance = staircase.tolerance;
    if !modal_test {
        return Ok(Controllability {
            uncontrollable_eigenvalues: staircase.uncontrollable_eigenvalues.clone(),
            staircase,
            eigenvalues: Vec::new(),
            modal_measure: Vec::new(),
            tolerance,
        });
    }
    let (eigenvalues, vectors) = eigen(a_dual)?;
    // ||w^T B|| = s ||w^T (B / s)|| for the power of two s of B's largest entry, with the
    // norm scaled, so that neither the products nor their squares leave the range.
    let scale = range_scale(coupling_dual);
    let modal_measure: Vec<f64> = (0..eigenvalues.len())
        .map(|k| {
            let vector = vectors.col(k);
            let products = (0..coupling_dual.nrows()).map(|r| {
                coupling_dual
                    .row(r)
                    .iter()
                    .zip(vector.iter())
                    .map(|(&x, v)| v * (x / scale))
                    .sum::<c64>()
            });
            vector_norm(products.flat_map(|p| [p.re, p.im])) * scale
        })
        .collect();
    let mut taken = vec![false; eigenvalues.len()];
    let mut uncontrollable = Vec::with_capacity(eigenvalues.len());
    for mu in &staircase.uncontrollable_eigenvalues {
        let nearest = (0..eigenvalues.len())
            .filter(|&k| !taken[k])
            .min_by(|&i, &j| {
                (eigenvalues[i] - mu)
                    .norm()
                    .total_cmp(&(eigenvalues[j] - mu).norm())
            });
        if let Some(k) = nearest {
            taken[k] = true;
            uncontrollable.push(eigenvalues[k]);
        }
    }
    for (k, &measure) in modal_measure.iter().enumerate() {
        if measure <= tolerance && !taken[k] {
            uncontrollable.push(eigenvalues[k]);
        }
    }
    Ok(Controllability {
        staircase,
        eigenvalues,
        modal_measure,
        uncontrollable_eigenvalues: uncontrollable,
        tolerance,
    })
}

fn checked_tolerance(tolerance: Option<f64>, default: f64) -> Result<f64, Error> {
    match tolerance {
        None => Ok(default),
        Some(value) if value.is_finite() && value >= 0.0 => Ok(value),
        Some(value) => Err(Error::InvalidValue {
            arg: "tol",
            value,
            requirement: "finite and non-negative",
        }),
    }
}

/// The staircase reduction for checked arguments.
pub(crate) fn staircase(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    tolerance: Option<f64>,
    with_transformation: bool,
) -> Result<Staircase, Error> {
    let (n, m) = (a.nrows(), b.ncols());
    let tolerance = checked_tolerance(tolerance, 0.0).map(|_| tolerance)?;
    // (A, B) / s for the power of two s that brings the largest entry near 1 (exact, and the
    // same staircase with the tolerance divided by s): the reflections' products of entries
    // neither overflow nor underflow. Results are multiplied back.
    let scale = scale_for_largest(max_abs(a).max(max_abs(b)));
    let scaled = |m: MatRef<'_, f64>| Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)] / scale);
    let (a, b) = (scaled(a), scaled(b));
    let default =
        n as f64 * f64::EPSILON * frobenius_norm(a.as_ref()).max(frobenius_norm(b.as_ref()));
    let given = tolerance;
    // A given tolerance over s may overflow (1e300 beside entries of 1e-151): every norm is
    // then below it, as it is below the given one in the pair's own units, which is reported.
    let tolerance = tolerance.map_or(default, |t| t / scale);
    let z_order = if with_transformation { n } else { 0 };
    let mut reduction = Reduction {
        a,
        b,
        z: Mat::identity(z_order, z_order),
        w: Mat::zeros(n, 1),
        row_work: Mat::zeros(1, n.max(m)),
        column_work: Mat::zeros(n, 1),
        tolerance,
        smallest_pivot: f64::INFINITY,
    };
    let mut block_sizes = Vec::new();
    let mut start = 0;
    let mut block_column = BlockColumn::Inputs;
    while start < n {
        let rank = reduction.compress(start, block_column);
        if rank == 0 {
            break;
        }
        block_sizes.push(rank);
        block_column = BlockColumn::States(start, start + rank);
        start += rank;
    }
    let uncontrollable_eigenvalues = eigenvalues(reduction.a.as_ref().submatrix(
        start,
        start,
        n - start,
        n - start,
    ))?
    .into_iter()
    .map(|lambda| lambda * scale)
    .collect();
    let unscaled = |m: Mat<f64>| {
        if scale == 1.0 {
            m
        } else {
            &m * faer::Scale(scale)
        }
    };
    Ok(Staircase {
        a: unscaled(reduction.a),
        b: unscaled(reduction.b),
        z: reduction.z,
        block_sizes,
        controllable_order: start,
        uncontrollable_eigenvalues,
        tolerance: given.unwrap_or(tolerance * scale),
        smallest_pivot: reduction.smallest_pivot * scale,
    })
}

/// The block column that a staircase step compresses: the inputs (B) first, then the states
/// of the last block (columns start..end of A).
#[derive(Clone, Copy)]
enum BlockColumn {
    Inputs,
    States(usize, usize),
}

/// The working state of the staircase reduction.
struct Reduction {
    a: Mat<f64>,
    b: Mat<f64>,
    z: Mat<f64>,
    /// The reflector [1; v] and the scratch for w^T X and X w.
    w: Mat<f64>,
    row_work: Mat<f64>,
    column_work: Mat<f64>,
    tolerance: f64,
    smallest_pivot: f64,
}

impl Reduction {
    /// Compresses rows `start..` of the block column into its first r rows by Householder QR
    /// with column pivoting, applying each reflector as a similarity; returns r.
    fn compress(&mut self, start: usize, block_column: BlockColumn) -> usize {
        let n = self.a.nrows();
        let (in_b, mut unused): (bool, Vec<usize>) = match block_column {
            BlockColumn::Inputs => (true, (0..self.b.ncols()).collect()),
            BlockColumn::States(first, end) => (false, (first..end).collect()),
        };
        // Below the rows already reduced the form is block Hessenberg: rows start.. of A are
        // zero in the columns before this block column, and of B once its block is compressed.
        // A reflection of those rows leaves the zeros as they are, so it skips them.
        let first_column = match block_column {
            BlockColumn::Inputs => 0,
            BlockColumn::States(first, _) => first,
        };
        let mut rank = 0;
        while start + rank < n && !unused.is_empty() {
            let row = start + rank;
            let block = if in_b { &self.b } else { &self.a };
            // The pivot: the column with the largest norm in rows row.. .
            let (position, norm) = unused
                .iter()
                .enumerate()
                .map(|(p, &j)| (p, vector_norm(block.col_as_slice(j)[row..].iter().copied())))
                .fold((0, -1.0), |best, c| if c.1 > best.1 { c } else { best });
            if norm <= self.tolerance {
                break;
            }
            self.smallest_pivot = self.smallest_pivot.min(norm);
            let column = unused.swap_remove(position);
            let w = &mut self.w.col_as_slice_mut(0)[..n - row];
            w.copy_from_slice(&block.col_as_slice(column)[row..]);
            let (beta, tau) = reflector(w);
            if tau != 0.0 {
                w[0] = 1.0;
                let w = self.w.as_ref().subrows(0, n - row);
                let right = self.a.as_mut().subcols_mut(first_column, n - first_column);
                reflect_rows(right, row, w, tau, self.row_work.as_mut());
                if in_b {
                    reflect_rows(self.b.as_mut(), row, w, tau, self.row_work.as_mut());
                }
                reflect_columns(self.a.as_mut(), row, w, tau, self.column_work.as_mut());
                if self.z.nrows() > 0 {
                    reflect_columns(self.z.as_mut(), row, w, tau, self.column_work.as_mut());
                }
            }
            // The pivot column is now beta e_row exactly.
            let block = if in_b { &mut self.b } else { &mut self.a };
            block[(row, column)] = beta;
            for i in row + 1..n {
                block[(i, column)] = 0.0;
            }
            rank += 1;
        }
        rank
    }
}

/// Applies I - τ w w^T from the left to rows row..row+len(w) of `m`: X -= τ w (w^T X).
fn reflect_rows(
    m: MatMut<'_, f64>,
    row: usize,
    w: MatRef<'_, f64>,
    tau: f64,
    work: MatMut<'_, f64>,
) {
    let mut x = m.subrows_mut(row, w.nrows());
    let mut product = work.subcols_mut(0, x.ncols());
    matmul(
        product.rb_mut(),
        Accum::Replace,
        w.transpose(),
        x.rb(),
        1.0,
        Par::Seq,
    );
    matmul(x.rb_mut(), Accum::Add, w, product.rb(), -tau, Par::Seq);
}

/// Applies I - τ w w^T from the right to columns col..col+len(w) of `m`: X -= τ (X w) w^T.
fn reflect_columns(
    m: MatMut<'_, f64>,
    col: usize,
    w: MatRef<'_, f64>,
    tau: f64,
    work: MatMut<'_, f64>,
) {
    let mut x = m.subcols_mut(col, w.nrows());
    let mut product = work.subrows_mut(0, x.nrows());
    matmul(product.rb_mut(), Accum::Replace, x.rb(), w, 1.0, Par::Seq);
    matmul(
        x.rb_mut(),
        Accum::Add,
        product.rb(),
        w.transpose(),
        -tau,
        Par::Seq,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::balance::states_scaled_apart;
    use faer::mat;

    fn pseudo_random(n: usize, m: usize, seed: u64) -> Mat<f64> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        Mat::from_fn(n, m, |_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        })
    }

    fn assert_orthogonal_similarity(
        original: MatRef<'_, f64>,
        form: &Staircase,
        b: MatRef<'_, f64>,
    ) {
        let n = original.nrows();
        let scale = original.norm_l2().max(1.0);
        let residual = &form.z * &form.a * form.z.transpose() - original;
        assert!(residual.norm_l2() <= 50.0 * n as f64 * f64::EPSILON * scale);
        let gram = form.z.transpose() * &form.z - Mat::<f64>::identity(n, n);
        assert!(gram.norm_l2() <= 50.0 * n as f64 * f64::EPSILON);
        let b_residual = &form.z * &form.b - b;
        assert!(b_residual.norm_l2() <= 50.0 * n as f64 * f64::EPSILON * b.norm_l2().max(1.0));
    }

    #[test]
    fn chapter_controllability_example() {
        // (6.75)-(6.88): controllable with B = [0, 1]^T; with B = [-1, 1]^T the mode at -2 is
        // not (P^-1 B = [-1, 0]^T).
        let a = mat![[0.0, 1.0], [-2.0, -3.0]];
        let v = ctrb(a.as_ref(), mat![[0.0], [1.0]].as_ref()).unwrap();
        assert_eq!(v, mat![[0.0, 1.0], [1.0, -3.0]]);
        let form =
            controllability_staircase(a.as_ref(), mat![[0.0], [1.0]].as_ref(), None, true).unwrap();
        assert!(form.is_complete());
        let b = mat![[-1.0], [1.0]];
        let form = controllability_staircase(a.as_ref(), b.as_ref(), None, true).unwrap();
        assert_eq!(form.controllable_order, 1);
        assert_eq!(form.uncontrollable_eigenvalues.len(), 1);
        assert!((form.uncontrollable_eigenvalues[0] - c64::new(-2.0, 0.0)).norm() < 1e-14);
        assert_orthogonal_similarity(a.as_ref(), &form, b.as_ref());
    }

    #[test]
    fn observability_is_the_dual() {
        let a = mat![[-3.0, 8.0], [0.0, 0.0]];
        let c = mat![[1.0, 0.0]];
        let o = obsv_transposed(a.as_ref(), c.as_ref()).unwrap();
        assert_eq!(o.transpose(), mat![[1.0, 0.0], [-3.0, 8.0]]);
        assert!(
            observability_staircase(a.as_ref(), c.as_ref(), None, true)
                .unwrap()
                .is_complete()
        );
        // Measuring only the second state of a system whose first state never reaches it.
        let c = mat![[0.0, 1.0]];
        let form = observability_staircase(a.as_ref(), c.as_ref(), None, true).unwrap();
        assert_eq!(form.controllable_order, 1);
        assert!((form.uncontrollable_eigenvalues[0] - c64::new(-3.0, 0.0)).norm() < 1e-14);
        let residual = &form.z * &form.a * form.z.transpose() - &a;
        assert!(residual.norm_l2() < 1e-14);
        assert!((&c * &form.z - &form.b).norm_l2() < 1e-15);
    }

    #[test]
    fn random_systems_are_controllable_where_the_krylov_rank_fails() {
        for (n, m) in [(64, 1), (64, 2), (40, 3), (9, 9)] {
            let (a, b) = (
                pseudo_random(n, n, n as u64),
                pseudo_random(n, m, 7 + m as u64),
            );
            let form = controllability_staircase(a.as_ref(), b.as_ref(), None, true).unwrap();
            assert!(form.is_complete(), "n = {n}, m = {m}");
            assert!(form.smallest_pivot > 1e3 * form.tolerance);
            assert_eq!(form.block_sizes.iter().sum::<usize>(), n);
            assert_orthogonal_similarity(a.as_ref(), &form, b.as_ref());
            // The staircase: B_c in the first r_1 rows, subdiagonal blocks below.
            let r1 = form.block_sizes[0];
            assert!(form.b.subrows(r1, n - r1).norm_l2() == 0.0);
        }
    }

    /// A = S [[A_c, A_12], [0, diag(u1, u2)]] S^T and B = S [B_c; 0] with S orthogonal: the
    /// eigenvalues u1 and u2 cannot be reached.
    fn planted(n: usize, m: usize, uncontrollable: [f64; 2], seed: u64) -> (Mat<f64>, Mat<f64>) {
        let nc = n - 2;
        let mut a = pseudo_random(n, n, seed);
        let mut b = pseudo_random(n, m, seed + 1);
        for i in nc..n {
            a.row_mut(i).fill(0.0);
            b.row_mut(i).fill(0.0);
        }
        a[(nc, nc)] = uncontrollable[0];
        a[(nc + 1, nc + 1)] = uncontrollable[1];
        let s = pseudo_random(n, n, seed + 2).qr().compute_Q();
        (&s * &a * s.transpose(), &s * &b)
    }

    fn sorted_real_parts(values: &[c64]) -> Vec<f64> {
        let mut parts: Vec<f64> = values.iter().map(|e| e.re).collect();
        parts.sort_by(f64::total_cmp);
        parts
    }

    #[test]
    fn planted_uncontrollable_modes_are_found() {
        // A small system: the staircase alone finds them, and its Z is a similarity.
        let (a, b) = planted(8, 2, [-0.5, 0.25], 3);
        let form = controllability_staircase(a.as_ref(), b.as_ref(), None, true).unwrap();
        assert_eq!(form.controllable_order, 6);
        let found = sorted_real_parts(&form.uncontrollable_eigenvalues);
        assert!((found[0] + 0.5).abs() < 1e-12 && (found[1] - 0.25).abs() < 1e-12);
        assert_orthogonal_similarity(a.as_ref(), &form, b.as_ref());
        // n = 64: the verdict of both tests, for interior and for dominant planted modes.
        for (m, modes) in [(1, [-0.5, 0.25]), (2, [-0.5, 0.25]), (3, [-5.0, 6.0])] {
            let (a, b) = planted(64, m, modes, 3);
            let verdict = controllability(a.as_ref(), b.as_ref(), None, true, false).unwrap();
            let found = sorted_real_parts(&verdict.uncontrollable_eigenvalues);
            assert_eq!(found.len(), 2, "m = {m}");
            assert!((found[0] - modes[0]).abs() < 1e-10 && (found[1] - modes[1]).abs() < 1e-10);
        }
        // Dominant planted modes fool the staircase (see the module documentation).
        let (a, b) = planted(64, 2, [-5.0, 6.0], 3);
        let staircase_only = controllability(a.as_ref(), b.as_ref(), None, false, false).unwrap();
        assert!(staircase_only.is_complete());
    }

    #[test]
    fn states_scaled_apart_are_balanced_first() {
        // A planted pair with its states scaled by 10^±6 (D A D^-1, D B): the same two
        // uncontrollable eigenvalues as the pair itself, each listed once, and Z a similarity
        // to the form (Z^-1 A Z, Z^-1 B); the observability of the transposed pair likewise.
        let (a, b) = planted(6, 1, [-0.5, 0.25], 5);
        let d = [1e6, 1.0, 1e-6, 1e3, 1e-3, 1.0];
        let scaled_a = Mat::from_fn(6, 6, |i, j| a[(i, j)] * d[i] / d[j]);
        let scaled_b = Mat::from_fn(6, 1, |i, j| b[(i, j)] * d[i]);
        assert!(states_scaled_apart(scaled_a.as_ref()));
        for (x, y) in [(&a, &b), (&scaled_a, &scaled_b)] {
            let verdict = controllability(x.as_ref(), y.as_ref(), None, true, true).unwrap();
            let found = sorted_real_parts(&verdict.uncontrollable_eigenvalues);
            assert_eq!(found.len(), 2);
            assert!((found[0] + 0.5).abs() < 1e-9 && (found[1] - 0.25).abs() < 1e-9);
            let z = verdict.staircase.z.as_ref();
            let residual = x.as_ref() * z - z * verdict.staircase.a.as_ref();
            assert!(frobenius_norm(residual.as_ref()) <= 1e-12 * frobenius_norm(x.as_ref()));
            let residual = y.as_ref() - z * verdict.staircase.b.as_ref();
            assert!(frobenius_norm(residual.as_ref()) <= 1e-12 * frobenius_norm(y.as_ref()));
            let dual = observability(x.transpose(), y.transpose(), None, true, true).unwrap();
            assert_eq!(dual.uncontrollable_eigenvalues.len(), 2);
            let z = dual.staircase.z.as_ref();
            let residual = x.transpose() * z - z * dual.staircase.a.as_ref();
            assert!(frobenius_norm(residual.as_ref()) <= 1e-12 * frobenius_norm(x.as_ref()));
        }
    }

    #[test]
    fn the_verdicts_are_those_of_the_analyses() {
        // Random pairs (controllable) and planted ones (2 uncontrollable modes, interior or
        // dominant, which only the modal test sees at n = 64), states scaled apart or not,
        // both tests or the staircase alone: is_controllable and is_observable give the
        // verdicts of controllability and observability.
        let mut cases = 0;
        for n in [1usize, 2, 4, 8, 16, 64] {
            for seed in 0..6u64 {
                let (a, b) = match seed % 3 {
                    0 => (
                        pseudo_random(n, n, seed + 11 * n as u64),
                        pseudo_random(n, 2, seed),
                    ),
                    _ if n < 4 => (Mat::<f64>::identity(n, n), pseudo_random(n, 1, seed)),
                    1 => planted(n, 2, [-0.5, 0.25], seed),
                    _ => planted(n, 2, [-5.0, 6.0], seed),
                };
                let d = Mat::from_fn(n, 1, |i, _| {
                    if seed % 2 == 0 {
                        1.0
                    } else {
                        1e4f64.powi(i as i32 % 3 - 1)
                    }
                });
                let scaled_a = Mat::from_fn(n, n, |i, j| a[(i, j)] * d[(i, 0)] / d[(j, 0)]);
                let scaled_b = Mat::from_fn(n, b.ncols(), |i, j| b[(i, j)] * d[(i, 0)]);
                for modal_test in [true, false] {
                    let (x, y) = (scaled_a.as_ref(), scaled_b.as_ref());
                    let full = controllability(x, y, None, modal_test, false).unwrap();
                    assert_eq!(
                        is_controllable(x, y, None, modal_test).unwrap(),
                        full.is_complete()
                    );
                    let full = observability(x.transpose(), y.transpose(), None, modal_test, false)
                        .unwrap();
                    assert_eq!(
                        is_observable(x.transpose(), y.transpose(), None, modal_test).unwrap(),
                        full.is_complete()
                    );
                    cases += 1;
                }
            }
        }
        assert_eq!(cases, 72);
    }

    #[test]
    fn a_partly_reachable_repeated_eigenvalue_needs_the_staircase() {
        let (a, b) = (Mat::<f64>::identity(2, 2), mat![[1.0], [1.0]]);
        let modal_only = controllability(a.as_ref(), b.as_ref(), None, true, false).unwrap();
        assert!(modal_only.modal_measure.iter().all(|&d| d > 0.5));
        assert_eq!(modal_only.uncontrollable_eigenvalues.len(), 1);
        assert!((modal_only.uncontrollable_eigenvalues[0] - c64::new(1.0, 0.0)).norm() < 1e-15);
        assert_eq!(modal_only.staircase.controllable_order, 1);
    }

    #[test]
    fn degenerate_sizes_and_a_bad_tolerance() {
        let empty = Mat::<f64>::zeros(0, 0);
        let form =
            controllability_staircase(empty.as_ref(), Mat::<f64>::zeros(0, 1).as_ref(), None, true)
                .unwrap();
        assert!(form.is_complete());
        let a = mat![[1.0, 0.0], [0.0, 2.0]];
        let no_inputs = Mat::<f64>::zeros(2, 0);
        let form = controllability_staircase(a.as_ref(), no_inputs.as_ref(), None, true).unwrap();
        assert_eq!(form.controllable_order, 0);
        assert_eq!(form.uncontrollable_eigenvalues.len(), 2);
        let error =
            controllability_staircase(a.as_ref(), mat![[1.0], [1.0]].as_ref(), Some(-1.0), true);
        assert!(matches!(error, Err(Error::InvalidValue { arg: "tol", .. })));
        let error = ctrb(a.as_ref(), mat![[1.0], [1.0], [0.0]].as_ref());
        assert!(matches!(error, Err(Error::Mismatch { arg: "B", .. })));
    }
}
