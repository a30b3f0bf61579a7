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
//! A is first reduced to upper Hessenberg form H = Q^T A Q ([`crate::linalg::hessenberg`], faer's blocked
//! Householder reduction). The QR iteration then works on the active window H[l..=i, l..=i]
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
//! the split (forward instability; the 747's closed loop at c = 0.5 took 8 sweeps that way, and
//! takes 2). A known eigenvalue matches a deflated one within a relative 1e-6 and is then
//! dropped; a mismatch only costs a sweep with an ordinary shift, and the transformations stay
//! orthogonal either way, so the form is as backward stable as without them. Known
//! eigenvalues come from three places:
//!
//! - A Hamiltonian matrix ([`Spectrum::Hamiltonian`], the Riccati solver's) has an even
//!   characteristic polynomial, det(λI - H) = q(λ²), whose coefficients La Budde's recurrence
//!   gives from the Hessenberg form in O(n^3) ([`crate::control::modes::charpoly`]); the roots μ of q
//!   (of half the order: in closed form up to degree four, `polynomial_roots`, which costs a
//!   tenth of the five or six sweeps of q's companion matrix; else, or where the closed form
//!   fails its backward-error check, the eigenvalues of the companion matrix) give the
//!   eigenvalue pairs ±sqrt(μ). The unstable ones serve as shifts until as many eigenvalues as they number have
//!   deflated, then the stable ones join them (a stable eigenvalue that deflates early is
//!   matched against its estimate all the same, and an unstable estimate that matched nothing
//!   stays a candidate, chosen only if the trailing block comes near it). The unstable half
//!   thus deflates at the bottom first, and
//!   the form usually comes out already ordered with the stable eigenvalues leading, as the
//!   Riccati solver needs it: on the 747 lateral regulator's Hamiltonian of order 8 over
//!   200 weights, 6 sweeps each and no reordering swap, where mirror images alone (below)
//!   took 10 sweeps and 3.6 swaps. The estimates lose accuracy as the order grows (the roots of
//!   a polynomial are more sensitive than the eigenvalues of a matrix); a poor one only costs
//!   sweeps, and the Riccati solver's reordering puts right any eigenvalue left out of place.
//! - Without estimates (a polynomial that is not finite or a companion matrix whose QR
//!   iteration fails, an odd order, or a window that is not the whole matrix), the mirror
//!   images: once a block deflates, the mirror image -λ̄ of its eigenvalues is known to be an
//!   eigenvalue of the part still active.
//! - [`eigenvalues_near`] takes estimates the caller knows ([`Spectrum::Near`]): the requested
//!   poles of a placement, or the Hamiltonian's stable eigenvalues for the closed loop of a
//!   Riccati solution (the 747 regulator's closed-loop eigenvalues in 0.72 µs instead of 1.17).
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
//! form itself is not balanced, since its Z must be orthogonal.

pub(crate) mod multishift;
pub mod reorder;

use crate::control::modes::hessenberg_characteristic_polynomial;
use crate::error::{Error, check_finite, check_square};
use crate::linalg::hessenberg::{hessenberg, hessenberg_matrix};
use crate::linalg::norm::max_abs;
use crate::linalg::polynomial_roots::monic_roots;
use crate::linalg::schur::multishift::multishift_qr;
use crate::platform::dispatch::clear_upper_avx_state;
use crate::platform::interrupt;
use faer::{Mat, MatRef, c64};
use std::ops::{Index, IndexMut, Range};

/// The Schur form A = Z T Z^T.
#[derive(Debug, Clone)]
pub struct RealSchur {
    /// Quasi-upper-triangular, 2 x 2 blocks in standard form, exact zeros elsewhere below the
    /// diagonal.
    pub t: Mat<f64>,
    /// Orthogonal.
    pub z: Mat<f64>,
}

/// Iterations without a deflation after which an exceptional shift is used.
const EXCEPTIONAL_SHIFT_INTERVAL: usize = 10;

/// What the QR iteration may assume about the spectrum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spectrum<'a> {
    /// No structure.
    General,
    /// Symmetric about the imaginary axis, λ and -λ̄ eigenvalues together with equal
    /// multiplicities: the spectrum of a (real) Hamiltonian matrix. The double-shift QR
    /// iteration (below `MULTISHIFT_MIN_ORDER`) estimates the eigenvalues from the
    /// characteristic polynomial and deflates the unstable half first (see the module
    /// documentation); the multishift iteration ignores the structure.
    Hamiltonian,
    /// Close to these estimates (conjugate pairs given by either member or both): the
    /// eigenvalues of a closed loop whose poles were requested or come from a Hamiltonian.
    /// The double-shift iteration takes the one nearest the trailing block's eigenvalues as
    /// its shifts in the first two sweeps after each deflation: an accurate shift deflates in
    /// one sweep where the trailing block's shifts take two or three. The estimates steer only the convergence; the eigenvalues are those of the
    /// matrix, as backward stable as without them.
    Near(&'a [c64]),
}

/// Known eigenvalues (mirror images, estimates) serve as shifts in this many sweeps after each
/// deflation; then the trailing block's eigenvalues take over.
const KNOWN_SHIFT_SWEEPS: usize = 2;

/// A deflated eigenvalue and a pending known one match within this relative distance.
/// A false match or a missed one only costs a sweep with an ordinary shift.
const MIRROR_MATCH: f64 = 1e-6;

/// Eigenvalues known to be in the active part of H and not deflated yet (complex pairs by
/// their member with Im > 0): for a Hamiltonian spectrum the estimates of its unstable half
/// not yet matched, then of its stable half (or, without estimates, the mirror images -λ̄ of
/// the eigenvalues deflated so far whose own mirror image has not deflated yet); for
/// [`Spectrum::Near`] the estimates not yet matched.
struct Mirrors {
    pending: Vec<c64>,
    /// Known eigenvalues that join `pending` once `deflations_before_later` eigenvalues have
    /// deflated (the stable half of a Hamiltonian spectrum, after the unstable half; estimates
    /// on the imaginary axis are in `pending` only).
    later: Vec<c64>,
    /// Deflations (each real eigenvalue and each complex pair counts one) left before `later`
    /// joins `pending`: at first, the number of unstable estimates.
    deflations_before_later: usize,
    /// Whether an eigenvalue that matches no pending one adds its mirror image (a Hamiltonian
    /// spectrum without estimates; with them, the estimate of the mirror image is in `later`
    /// already, and measured on graded Riccati problems adding it cost sweeps).
    mirrored: bool,
}

impl Mirrors {
    fn for_spectrum<O: Order>(spectrum: Spectrum<'_>, h: Option<&Square<O>>) -> Option<Self> {
        match spectrum {
            Spectrum::General => None,
            Spectrum::Hamiltonian => {
                let stable = h.map_or_else(Vec::new, hamiltonian_estimates);
                let unstable: Vec<c64> = stable.iter().map(|z| c64::new(-z.re, z.im)).collect();
                Some(Self {
                    deflations_before_later: unstable.len(),
                    pending: unstable,
                    mirrored: stable.is_empty(),
                    // An estimate on the imaginary axis is its own mirror image: once is enough.
                    later: stable.into_iter().filter(|z| z.re != 0.0).collect(),
                })
            }
            Spectrum::Near(estimates) => Some(Self {
                // Non-finite estimates would carry NaN into H through the shifts: dropped.
                pending: estimates
                    .iter()
                    .filter(|z| z.im >= 0.0 && z.re.is_finite() && z.im.is_finite())
                    .copied()
                    .collect(),
                later: Vec::new(),
                deflations_before_later: 0,
                mirrored: false,
            }),
        }
    }

    /// Records a deflated eigenvalue (of a pair, the member with Im > 0).
    fn found(&mut self, lambda: c64) {
        // Squared distances: no hypot in the iteration's inner loop (overflow only past
        // 1e154, where a missed match costs a sweep).
        let tolerance = MIRROR_MATCH * MIRROR_MATCH * lambda.norm_sqr();
        let matches = |p: &c64| (p - lambda).norm_sqr() <= tolerance;
        if let Some(k) = self.pending.iter().position(matches) {
            self.pending.remove(k);
        } else if let Some(k) = self.later.iter().position(matches) {
            self.later.remove(k);
        } else if self.mirrored {
            self.pending.push(c64::new(-lambda.re, lambda.im));
        }
        self.deflations_before_later = self.deflations_before_later.saturating_sub(1);
        if self.deflations_before_later == 0 {
            self.pending.append(&mut self.later);
        }
    }

    /// The shifts of the next double-shift step, given the eigenvalues of the window's
    /// trailing 2 x 2 block (toward which the iteration converges anyway): the pending
    /// eigenvalue nearest to them, with its conjugate if complex; if real, with the real
    /// pending one nearest to them after it (or itself again). Choosing by proximity rather
    /// than by age keeps an exact shift from being spent on an eigenvalue that has nearly
    /// split off higher up, where the sweep would undo that split (forward instability).
    fn shifts(&self, trailing: [c64; 2]) -> Option<(c64, c64)> {
        let distance = |p: &c64| {
            trailing
                .iter()
                .map(|t| (*p - c64::new(t.re, t.im.abs())).norm_sqr())
                .fold(f64::INFINITY, f64::min)
        };
        let nearest = |candidates: &mut dyn Iterator<Item = (usize, &c64)>| {
            candidates
                .map(|(k, p)| (k, distance(p)))
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .map(|(k, _)| k)
        };
        let first = nearest(&mut self.pending.iter().enumerate())?;
        let shift = self.pending[first];
        if shift.im != 0.0 {
            return Some((shift, shift.conj()));
        }
        let mut other_reals = self
            .pending
            .iter()
            .enumerate()
            .filter(|&(k, p)| k != first && p.im == 0.0);
        let second = nearest(&mut other_reals).map_or(shift, |k| self.pending[k]);
        Some((shift, second))
    }
}

/// From this order on the QR iteration is the small-bulge multishift iteration with aggressive
/// early deflation ([`crate::linalg::schur::multishift`]); below it, and on the active blocks below it that the
/// multishift iteration leaves, the double-shift iteration of this module, whose set-up is
/// nothing. LAPACK's crossover is 75 (its NMIN); measured here, see the module docs.
pub(crate) const MULTISHIFT_MIN_ORDER: usize = 75;

/// Up to this order the Hessenberg reduction is the plain Householder loop below; above it,
/// faer's blocked reduction (whose set-up costs more than the whole reduction at n = 4).
const UNBLOCKED_HESSENBERG_MAX_ORDER: usize = 32;

// The unblocked orders take the double-shift iteration directly.
const _: () = assert!(UNBLOCKED_HESSENBERG_MAX_ORDER < MULTISHIFT_MIN_ORDER);

/// The order of a [`Square`] matrix: fixed at compile time ([`Fixed`]) for the small orders
/// of flight models, or known at run time ([`Dynamic`]).
///
/// With the order a constant, the index arithmetic of the QR iteration folds, its loops over
/// whole rows and columns unroll, and the matrix lives on the stack; the arithmetic, and so
/// every result, is the same bit for bit as with the run-time order. [`with_order`] picks
/// the order type for n.
pub(crate) trait Order: Copy {
    /// Storage for the order^2 entries.
    type Data: AsRef<[f64]> + AsMut<[f64]> + Clone;
    /// Whether the order is a compile-time constant.
    const FIXED: bool;
    /// The order.
    fn get(self) -> usize;
    /// Zeroed storage.
    fn zeros(self) -> Self::Data;
}

/// An order known at run time; the entries on the heap.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dynamic(pub(crate) usize);

impl Order for Dynamic {
    type Data = Vec<f64>;
    const FIXED: bool = false;
    #[inline(always)]
    fn get(self) -> usize {
        self.0
    }
    fn zeros(self) -> Vec<f64> {
        vec![0.0; self.0 * self.0]
    }
}

/// An order fixed at compile time; the entries in an array.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fixed<const N: usize>;

/// The fixed orders: those of 2- to 4-state models, their Hamiltonians (twice the states)
/// and 5- to 8-state augmented models.
macro_rules! fixed_orders {
    ($($n:literal),*) => {
        $(
            impl Order for Fixed<$n> {
                type Data = [f64; $n * $n];
                const FIXED: bool = true;
                #[inline(always)]
                fn get(self) -> usize {
                    $n
                }
                #[inline(always)]
                fn zeros(self) -> Self::Data {
                    [0.0; $n * $n]
                }
            }
        )*
    };
}

fixed_orders!(2, 3, 4, 5, 6, 7, 8);

/// Evaluates `$body` with `$order` bound to the [`Order`] of an n x n matrix: [`Fixed`] for
/// the orders of [`fixed_orders`], [`Dynamic`] otherwise (the body is compiled for each).
macro_rules! with_order {
    ($n:expr, $order:ident => $body:expr) => {
        with_order!(@orders $n, $order, $body; 2 3 4 5 6 7 8)
    };
    (@orders $n:expr, $order:ident, $body:expr; $($fixed:literal)*) => {
        match $n {
            $($fixed => {
                let $order = Fixed::<$fixed>;
                $body
            })*
            n => {
                let $order = Dynamic(n);
                $body
            }
        }
    };
}
pub(crate) use with_order;

/// A square matrix stored by columns in one contiguous buffer: the QR iteration touches single
/// entries in tight loops, where a plain slice index is cheaper than a strided view.
#[derive(Clone)]
pub(crate) struct Square<O: Order = Dynamic> {
    order: O,
    pub(crate) data: O::Data,
}

impl Square {
    pub(crate) fn from_mat(a: MatRef<'_, f64>) -> Self {
        Self::from_mat_in(Dynamic(a.nrows()), a)
    }

    pub(crate) fn identity(n: usize) -> Self {
        Self::identity_in(Dynamic(n))
    }
}

impl<O: Order> Square<O> {
    /// The order.
    #[inline(always)]
    pub(crate) fn n(&self) -> usize {
        self.order.get()
    }

    /// A copy of the square matrix `a`, whose order is `order`.
    pub(crate) fn from_mat_in(order: O, a: MatRef<'_, f64>) -> Self {
        let n = order.get();
        debug_assert!(a.nrows() == n && a.ncols() == n);
        let mut data = order.zeros();
        for (j, column) in data.as_mut().chunks_exact_mut(n.max(1)).enumerate() {
            for (i, x) in column.iter_mut().enumerate() {
                *x = a[(i, j)];
            }
        }
        Self { order, data }
    }

    pub(crate) fn zeros_in(order: O) -> Self {
        Self {
            order,
            data: order.zeros(),
        }
    }

    pub(crate) fn identity_in(order: O) -> Self {
        let n = order.get();
        let mut data = order.zeros();
        for i in 0..n {
            data.as_mut()[i * (n + 1)] = 1.0;
        }
        Self { order, data }
    }

    pub(crate) fn to_mat(&self) -> Mat<f64> {
        self.to_mat_scaled(1.0)
    }

    /// A faer matrix of the entries times `scale`.
    pub(crate) fn to_mat_scaled(&self, scale: f64) -> Mat<f64> {
        let n = self.n();
        let mut out = Mat::zeros(n, n);
        for j in 0..n {
            let column = &self.data.as_ref()[j * n..(j + 1) * n];
            for (x, &value) in out.col_as_slice_mut(j).iter_mut().zip(column) {
                *x = value * scale;
            }
        }
        out
    }

    /// A faer view of the matrix.
    pub(crate) fn as_ref(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(self.data.as_ref(), self.n(), self.n())
    }

    /// Rows r and r + 1, columns `columns`: x <- cs x + sn y, y <- cs y - sn x.
    pub(crate) fn rotate_rows(&mut self, r: usize, columns: Range<usize>, cs: f64, sn: f64) {
        for j in columns {
            let (x, y) = (self[(r, j)], self[(r + 1, j)]);
            self[(r, j)] = cs * x + sn * y;
            self[(r + 1, j)] = cs * y - sn * x;
        }
    }

    /// Columns c and c + 1, rows `rows`: x <- cs x + sn y, y <- cs y - sn x.
    pub(crate) fn rotate_columns(&mut self, c: usize, rows: Range<usize>, cs: f64, sn: f64) {
        let n = self.n();
        let (left, right) = self.data.as_mut().split_at_mut((c + 1) * n);
        let (x_column, y_column) = (&mut left[c * n..], &mut right[..n]);
        for i in rows {
            let (x, y) = (x_column[i], y_column[i]);
            x_column[i] = cs * x + sn * y;
            y_column[i] = cs * y - sn * x;
        }
    }

    /// Applies I - τ w w^T (w = [1, v...], 2 or 3 long) from the left to rows k.. of the
    /// columns `columns`.
    pub(crate) fn reflect_rows(&mut self, k: usize, w: &[f64], tau: f64, columns: Range<usize>) {
        let n = self.n();
        for j in columns {
            let column = &mut self.data.as_mut()[j * n + k..j * n + k + w.len()];
            let sum: f64 = column.iter().zip(w).map(|(x, v)| x * v).sum();
            let scaled = tau * sum;
            for (x, v) in column.iter_mut().zip(w) {
                *x -= scaled * v;
            }
        }
    }

    /// Applies I - τ w w^T from the right to columns k.. of the rows `rows`: y = τ H w is
    /// accumulated column by column (contiguous in storage, so the loops vectorise), in
    /// chunks of rows, then column k + r loses w_r y. (The operations of the row-by-row
    /// order, in the same order for each entry, so the same rounding.)
    pub(crate) fn reflect_columns(&mut self, k: usize, w: &[f64], tau: f64, rows: Range<usize>) {
        const CHUNK: usize = 32;
        let n = self.n();
        let columns = &mut self.data.as_mut()[k * n..(k + w.len()) * n];
        let mut start = rows.start;
        while start < rows.end {
            let chunk = start..(start + CHUNK).min(rows.end);
            let mut y = [0.0; CHUNK];
            let y = &mut y[..chunk.len()];
            for (r, v) in w.iter().enumerate() {
                let column = &columns[r * n + chunk.start..r * n + chunk.end];
                for (sum, x) in y.iter_mut().zip(column) {
                    *sum += v * x;
                }
            }
            for sum in y.iter_mut() {
                *sum *= tau;
            }
            for (r, v) in w.iter().enumerate() {
                let column = &mut columns[r * n + chunk.start..r * n + chunk.end];
                for (x, scaled) in column.iter_mut().zip(y.iter()) {
                    *x -= scaled * v;
                }
            }
            start = chunk.end;
        }
    }
}

/// The reflectors of the bulge chase are 3 long (2 at the bottom of the window): with the
/// length fixed at compile time the updates unroll and the column update vectorises, which
/// roughly halves the cost of a QR sweep at the small orders of flight-control models.
impl<O: Order> Square<O> {
    /// [`Square::reflect_rows`] for a reflector of length `N` whose w_0 = 1 (as every
    /// reflector of the bulge chase): the products with w_0 are left out, as LAPACK's dlahqr
    /// leaves them (the same values, up to the sign of a zero).
    #[inline(always)]
    pub(crate) fn reflect_rows_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        columns: Range<usize>,
    ) {
        let n = self.n();
        for j in columns {
            let column: &mut [f64; N] = (&mut self.data.as_mut()[j * n + k..j * n + k + N])
                .try_into()
                .expect("N entries");
            debug_assert_eq!(w[0], 1.0);
            let mut sum = column[0];
            for r in 1..N {
                sum += column[r] * w[r];
            }
            let scaled = tau * sum;
            column[0] -= scaled;
            for r in 1..N {
                column[r] -= scaled * w[r];
            }
        }
    }

    /// [`Square::reflect_columns`] for a reflector of length `N` whose w_0 = 1 (see
    /// [`Square::reflect_rows_fixed`]).
    // Row i of N column slices at once: an index, not an iterator, is the natural form.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    pub(crate) fn reflect_columns_fixed<const N: usize>(
        &mut self,
        k: usize,
        w: [f64; N],
        tau: f64,
        rows: Range<usize>,
    ) {
        let n = self.n();
        let columns = &mut self.data.as_mut()[k * n..(k + N) * n];
        debug_assert_eq!(w[0], 1.0);
        for i in rows {
            let mut sum = columns[i];
            for r in 1..N {
                sum += w[r] * columns[r * n + i];
            }
            let scaled = tau * sum;
            columns[i] -= scaled;
            for r in 1..N {
                columns[r * n + i] -= scaled * w[r];
            }
        }
    }
}

impl<O: Order> Index<(usize, usize)> for Square<O> {
    type Output = f64;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &f64 {
        &self.data.as_ref()[i + j * self.order.get()]
    }
}

impl<O: Order> IndexMut<(usize, usize)> for Square<O> {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut f64 {
        &mut self.data.as_mut()[i + j * self.order.get()]
    }
}

/// The real Schur form of a square, finite matrix.
pub fn real_schur(a: MatRef<'_, f64>) -> Result<RealSchur, Error> {
    real_schur_with(a, Spectrum::General)
}

/// The real Schur form of a square, finite matrix whose spectrum has the given structure.
pub fn real_schur_with(a: MatRef<'_, f64>, spectrum: Spectrum) -> Result<RealSchur, Error> {
    check_square(a, "A")?;
    with_order!(a.nrows(), order => {
        square_real_schur(Square::from_mat_in(order, a), spectrum, Until::Complete)
            .map(|(schur, _)| schur)
    })
}

/// [`real_schur_with`] of a matrix held as a [`Square`] (as the Riccati solver builds its
/// Hamiltonian), possibly partial (see [`Until`]; up to [`UNBLOCKED_HESSENBERG_MAX_ORDER`]):
/// checked finite, scaled into range, reduced by the unblocked Hessenberg reduction and the
/// double-shift iteration at the order type of `a` up to that order, by faer's blocked
/// reduction and the QR iteration of [`schur_of_hessenberg`] above it.
pub(crate) fn square_real_schur<O: Order>(
    a: Square<O>,
    spectrum: Spectrum,
    until: Until,
) -> Result<(RealSchur, Finished), Error> {
    square_schur_form(a, spectrum, until).map(|(schur, finished)| {
        let real_schur = RealSchur {
            t: schur.t.to_mat_scaled(schur.scale),
            z: schur.z.to_mat(),
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
    mut a: Square<O>,
    spectrum: Spectrum,
    until: Until,
) -> Result<(SquareSchur<O>, Finished), Error> {
    check_finite(a.as_ref(), "A")?;
    let n = a.n();
    let scale = range_scale(a.as_ref());
    if scale != 1.0 {
        a.data.as_mut().iter_mut().for_each(|x| *x /= scale);
    }
    if n <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        let mut z = Square::identity_in(a.order);
        reduce_to_hessenberg(&mut a, Some(&mut z));
        // The iteration works on A / scale.
        let until = match until {
            Until::UnstableHalf { margin } => Until::UnstableHalf {
                margin: margin / scale,
            },
            Until::Complete => Until::Complete,
        };
        let finished = francis_qr_until(
            &mut a,
            Some(&mut z),
            (0, n.saturating_sub(1)),
            true,
            spectrum,
            until,
        )?;
        Ok((SquareSchur { t: a, z, scale }, finished))
    } else {
        // (Above the fixed orders: O is Dynamic, and the copies back are O(n^2).)
        let reduced = hessenberg(a.as_ref())?;
        let (mut t, mut z) = (
            Square::from_mat(reduced.h.as_ref()),
            Square::from_mat(reduced.q.as_ref()),
        );
        schur_of_hessenberg(&mut t, Some(&mut z), true, spectrum)?;
        let (t, z) = (
            Square::from_mat_in(a.order, t.as_ref()),
            Square::from_mat_in(a.order, z.as_ref()),
        );
        Ok((SquareSchur { t, z, scale }, Finished::Complete))
    }
}

/// Entries of the largest magnitude outside [`SMALL_ENTRY`], 1 / [`SMALL_ENTRY`] are brought
/// to 1 first (as LAPACK's dgees scales): the deflation tests compare entries with the
/// smallest normal number, so a matrix whose entries are all below about 1e-290 would
/// otherwise count as negligible everywhere and come back as a wrong Schur form (residual
/// 0.7), and one near the overflow threshold would overflow in the shifts.
const SMALL_ENTRY: f64 = 1.0e-150;

/// The power of two by which `a` is divided before its Schur form, 1 when its largest entry
/// is in range (the scaling is exact, and A = Z (s T) Z^T with the same Z).
fn range_scale(a: MatRef<'_, f64>) -> f64 {
    let largest = max_abs(a);
    if largest > 0.0 && !(SMALL_ENTRY..=1.0 / SMALL_ENTRY).contains(&largest) {
        2f64.powi(largest.log2().round() as i32)
    } else {
        1.0
    }
}

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
            let (mut h, scale) = balanced_hessenberg(Square::from_mat_in(order, a));
            francis_qr(&mut h, None, (0, n.saturating_sub(1)), false, unscaled(scale))?;
            Ok(block_eigenvalues(n, |i, j| h[(i, j)] * scale))
        })
    } else {
        let (mut h, scale) = balanced_hessenberg(Square::from_mat(a));
        schur_of_hessenberg(&mut h, None, false, unscaled(scale))?;
        Ok(block_eigenvalues(n, |i, j| h[(i, j)] * scale))
    }
}

/// The upper Hessenberg form H of the balanced D^-1 (A / s) D, with s the power of two that
/// brings A's entries into range ([`range_scale`]): returns (H, s). H is similar to A / s, so
/// it has the eigenvalues and the characteristic polynomial of A / s (the balancing is exact,
/// the reduction backward stable). The caller checks that A is finite.
pub(crate) fn balanced_hessenberg<O: Order>(mut h: Square<O>) -> (Square<O>, f64) {
    let scale = range_scale(h.as_ref());
    if scale != 1.0 {
        h.data.as_mut().iter_mut().for_each(|x| *x /= scale);
    }
    let _ = balance(&mut h);
    if h.n() <= UNBLOCKED_HESSENBERG_MAX_ORDER {
        reduce_to_hessenberg(&mut h, None);
    } else {
        h = Square::from_mat_in(h.order, hessenberg_matrix(h.to_mat().as_ref()).as_ref());
    }
    (h, scale)
}

/// The eigenvalues of a quasi-upper-triangular matrix whose 2 x 2 blocks are in standard form.
pub fn quasi_triangular_eigenvalues(t: MatRef<'_, f64>) -> Vec<c64> {
    block_eigenvalues(t.nrows(), |i, j| t[(i, j)])
}

pub(crate) fn block_eigenvalues(n: usize, t: impl Fn(usize, usize) -> f64) -> Vec<c64> {
    let mut values = Vec::with_capacity(n);
    let mut k = 0;
    while k < n {
        if k + 1 < n && t(k + 1, k) != 0.0 {
            let (re, b, c) = (t(k, k), t(k, k + 1), t(k + 1, k));
            let im = b.abs().sqrt() * c.abs().sqrt();
            values.push(c64::new(re, im));
            values.push(c64::new(re, -im));
            k += 2;
        } else {
            values.push(c64::new(t(k, k), 0.0));
            k += 1;
        }
    }
    values
}

/// Householder reduction to upper Hessenberg form in place, H = Q^T A Q; `q` (the identity on
/// entry) becomes Q. Reflector k maps column k below the subdiagonal onto e_{k+1}.
fn reduce_to_hessenberg<O: Order>(h: &mut Square<O>, mut q: Option<&mut Square<O>>) {
    clear_upper_avx_state();
    let n = h.n();
    let mut w = [0.0; UNBLOCKED_HESSENBERG_MAX_ORDER];
    for k in 0..n.saturating_sub(2) {
        let length = n - k - 1;
        let w = &mut w[..length];
        for (r, x) in w.iter_mut().enumerate() {
            *x = h[(k + 1 + r, k)];
        }
        let (beta, tau) = reflector(w);
        if tau == 0.0 {
            continue;
        }
        w[0] = 1.0;
        h.reflect_rows(k + 1, w, tau, k + 1..n);
        h.reflect_columns(k + 1, w, tau, 0..n);
        h[(k + 1, k)] = beta;
        for r in k + 2..n {
            h[(r, k)] = 0.0;
        }
        if let Some(q) = q.as_deref_mut() {
            q.reflect_columns(k + 1, w, tau, 0..n);
        }
    }
}

/// Balances A in place by a diagonal similarity D^-1 A D with powers of two (no permutations):
/// row and column i are scaled until their off-diagonal 2-norms are within a factor of two, and
/// the sweep repeats while a scaling reduces the sum of the two norms by 5 % or more. Returns
/// the diagonal of D.
pub(crate) fn balance<O: Order>(a: &mut Square<O>) -> Vec<f64> {
    clear_upper_avx_state();
    let n = a.n();
    let mut scale = vec![1.0; n];
    let mut changed = true;
    let mut sweeps = 0;
    while changed && sweeps < 100 {
        changed = false;
        sweeps += 1;
        for i in 0..n {
            let (mut column_squares, mut row_squares) = (0.0, 0.0);
            for k in 0..n {
                if k != i {
                    column_squares += a[(k, i)] * a[(k, i)];
                    row_squares += a[(i, k)] * a[(i, k)];
                }
            }
            if column_squares == 0.0
                || row_squares == 0.0
                || !(column_squares + row_squares).is_finite()
            {
                continue;
            }
            // The scaling by powers of two works on the squared norms (exactly, by fours).
            let (mut c, mut r, mut f) = (column_squares, row_squares, 1.0f64);
            while c < r / 4.0 && f < 2f64.powi(500) {
                (c, r, f) = (c * 4.0, r / 4.0, f * 2.0);
            }
            while c >= r * 4.0 && f > 2f64.powi(-500) {
                (c, r, f) = (c / 4.0, r * 4.0, f / 2.0);
            }
            if f != 1.0 && c.sqrt() + r.sqrt() < 0.95 * (column_squares.sqrt() + row_squares.sqrt())
            {
                changed = true;
                scale[i] *= f;
                // f is a power of two: multiplying by 1 / f rounds as dividing by f.
                let f_inverse = 1.0 / f;
                for k in 0..n {
                    a[(i, k)] *= f_inverse;
                    a[(k, i)] *= f;
                }
            }
        }
    }
    scale
}

/// A 2 x 2 block [[a, b], [c, d]] rotated into standard form by the rotation
/// G = [[cs, -sn], [sn, cs]]: G^T [[a0, b0], [c0, d0]] G = [[a, b], [c, d]].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandardBlock {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub cs: f64,
    pub sn: f64,
}

/// The Schur factorisation of a real 2 x 2 matrix in standard form: upper triangular (c = 0)
/// when the eigenvalues are real, equal diagonal and b c < 0 when they are complex.
///
/// With p = (a - d)/2 and bcmis = min(|b|, |c|) sign(b) sign(c), the discriminant
/// z = p^2 + b c is formed as p (p / s) + max(|b|, |c|) (bcmis / s) s, scaled by s = max(|p|,
/// max(|b|, |c|)) against overflow. Real eigenvalues (z >= 4u): a rotation through the
/// eigenvector [z, c] triangularises the block, and the eigenvalue of larger magnitude is
/// formed as d + z' with z' = p + sign(p) sqrt(s) sqrt(z) (no cancellation), the other from
/// the determinant. Otherwise a rotation by the angle that equalises the diagonal, after which
/// b and c have opposite signs (complex pair) or, when the eigenvalues are real but close,
/// a second rotation triangularises.
pub fn standardize_block(a: f64, b: f64, c: f64, d: f64) -> StandardBlock {
    let eps = f64::EPSILON;
    let identity = |a, b, c, d| StandardBlock {
        a,
        b,
        c,
        d,
        cs: 1.0,
        sn: 0.0,
    };
    if c == 0.0 {
        return identity(a, b, c, d);
    }
    if b == 0.0 {
        // Swap rows and columns.
        return StandardBlock {
            a: d,
            b: -c,
            c: 0.0,
            d: a,
            cs: 0.0,
            sn: 1.0,
        };
    }
    if a - d == 0.0 && b.signum() != c.signum() {
        return identity(a, b, c, d);
    }
    let temp = a - d;
    let p = 0.5 * temp;
    let bcmax = b.abs().max(c.abs());
    let bcmis = b.abs().min(c.abs()) * b.signum() * c.signum();
    let scale = p.abs().max(bcmax);
    let z = p / scale * p + bcmax / scale * bcmis;
    if z >= 4.0 * eps {
        // Real eigenvalues.
        let z = p + p.signum() * scale.sqrt() * z.sqrt();
        let a_new = d + z;
        let d_new = d - bcmax / z * bcmis;
        let tau = c.hypot(z);
        return StandardBlock {
            a: a_new,
            b: b - c,
            c: 0.0,
            d: d_new,
            cs: z / tau,
            sn: c / tau,
        };
    }
    // Complex or nearly equal real eigenvalues: equalise the diagonal.
    let sigma = b + c;
    let tau = sigma.hypot(temp);
    let mut cs = (0.5 * (1.0 + sigma.abs() / tau)).sqrt();
    let mut sn = -(p / (tau * cs)) * sigma.signum();
    // [aa bb; cc dd] = [a b; c d] G, then G^T [aa bb; cc dd].
    let (aa, bb) = (a * cs + b * sn, -a * sn + b * cs);
    let (cc, dd) = (c * cs + d * sn, -c * sn + d * cs);
    let mut b = bb * cs + dd * sn;
    let mut c = -aa * sn + cc * cs;
    let mean = 0.5 * ((aa * cs + cc * sn) + (-bb * sn + dd * cs));
    let (mut a, mut d) = (mean, mean);
    if c != 0.0 {
        if b != 0.0 {
            if b.signum() == c.signum() {
                // Real eigenvalues: triangularise with a second rotation.
                let sab = b.abs().sqrt();
                let sac = c.abs().sqrt();
                let p = sab * sac * c.signum();
                let tau = 1.0 / (b + c).abs().sqrt();
                a = mean + p;
                d = mean - p;
                b -= c;
                c = 0.0;
                let (cs1, sn1) = (sab * tau, sac * tau);
                (cs, sn) = (cs * cs1 - sn * sn1, cs * sn1 + sn * cs1);
            }
        } else {
            b = -c;
            c = 0.0;
            (cs, sn) = (-sn, cs);
        }
    }
    StandardBlock { a, b, c, d, cs, sn }
}

/// The Householder reflector I - τ [1; v][1; v]^T that maps x to β e1: returns (β, τ) and
/// leaves v in x[1..]. τ = 0 (the identity) when x[1..] is zero.
#[inline(always)]
pub(crate) fn reflector(x: &mut [f64]) -> (f64, f64) {
    let alpha = x[0];
    let tail_squares: f64 = x[1..].iter().map(|v| v * v).sum();
    if tail_squares == 0.0 {
        return (alpha, 0.0);
    }
    let squares = alpha * alpha + tail_squares;
    // Plain sums of squares unless they left the normal range (then rescale; hypot is slow).
    let norm =
        if (f64::MIN_POSITIVE..f64::MAX).contains(&squares) && tail_squares >= f64::MIN_POSITIVE {
            squares.sqrt()
        } else {
            let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            scale * x.iter().map(|v| (v / scale).powi(2)).sum::<f64>().sqrt()
        };
    let beta = -alpha.signum() * norm;
    let tau = (beta - alpha) / beta;
    let scale = 1.0 / (alpha - beta);
    for v in &mut x[1..] {
        *v *= scale;
    }
    (beta, tau)
}

/// The QR iteration on an upper Hessenberg `h`, in place: the double-shift iteration below
/// [`MULTISHIFT_MIN_ORDER`], the small-bulge multishift iteration ([`crate::linalg::schur::multishift`]) from
/// there.
///
/// With `full` the whole of `h` is transformed into the Schur form T (and `z`, if given, is
/// multiplied on the right by the orthogonal transformations); without it only the diagonal
/// blocks are formed, which suffices for the eigenvalues. The known shifts of a Hamiltonian
/// `spectrum` serve the double-shift iteration only.
pub(crate) fn schur_of_hessenberg(
    h: &mut Square,
    z: Option<&mut Square>,
    full: bool,
    spectrum: Spectrum,
) -> Result<(), Error> {
    if h.n() < MULTISHIFT_MIN_ORDER {
        francis_qr(h, z, (0, h.n().saturating_sub(1)), full, spectrum)
    } else {
        multishift_qr(h, z, full)
    }
}

/// The Francis double-shift QR iteration on the diagonal block `lo..=hi` of an upper Hessenberg
/// `h`, in place, whose subdiagonal entries h[lo, lo-1] and h[hi+1, hi] are zero.
///
/// With `full` the whole of `h` is transformed (the rows above and the columns to the right of
/// the block too, toward the Schur form T; and `z`, if given, is multiplied on the right by the
/// orthogonal transformations); without it only the block itself, which suffices for the
/// eigenvalues.
pub(crate) fn francis_qr<O: Order>(
    h: &mut Square<O>,
    z: Option<&mut Square<O>>,
    window: (usize, usize),
    full: bool,
    spectrum: Spectrum,
) -> Result<(), Error> {
    francis_qr_until(h, z, window, full, spectrum, Until::Complete).map(|_| ())
}

/// How much of the Schur form the QR iteration forms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Until {
    /// All of it.
    Complete,
    /// Only until the trailing half of the eigenvalues of the whole matrix (even order) has
    /// deflated, if those all have Re λ > `margin`: the unstable half of a Hamiltonian
    /// spectrum, which the estimated shifts of [`Spectrum::Hamiltonian`] deflate first. The
    /// leading columns of Z then span the stable invariant subspace, which is all the Riccati
    /// solver needs, and the leading half of T stays upper Hessenberg (the sweeps that would
    /// triangularise it, a fifth of the iteration at order 8, are saved). Should any other
    /// eigenvalue deflate among the trailing half, the iteration goes on to the complete form.
    UnstableHalf { margin: f64 },
}

/// Whether the QR iteration stopped early ([`Until::UnstableHalf`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Finished {
    Complete,
    UnstableHalf,
}

/// [`francis_qr`] that may stop early (see [`Until`]).
pub(crate) fn francis_qr_until<O: Order>(
    h: &mut Square<O>,
    mut z: Option<&mut Square<O>>,
    (lo, hi): (usize, usize),
    full: bool,
    spectrum: Spectrum,
    until: Until,
) -> Result<Finished, Error> {
    clear_upper_avx_state();

    let n = h.n();
    if n == 0 {
        return Ok(Finished::Complete);
    }
    let ulp = f64::EPSILON;
    let small = f64::MIN_POSITIVE * (n as f64 / ulp);
    let max_iterations = 30 * (hi + 1 - lo).max(10);
    let mut iterations_since_deflation = 0;
    let whole = (lo, hi) == (0, n - 1);
    let mut mirrors = Mirrors::for_spectrum(spectrum, whole.then_some(&*h));
    // Until::UnstableHalf: the margin, while every eigenvalue deflated so far exceeds it.
    let mut unstable_margin = match until {
        Until::UnstableHalf { margin } if whole && n.is_multiple_of(2) => Some(margin),
        _ => None,
    };
    // The window is rows and columns l..=i; the eigenvalues below i have converged.
    let mut i = hi;
    loop {
        let mut l = lo;
        let mut converged = false;
        for _ in 0..=max_iterations {
            interrupt::check()?;
            // Find the lowest negligible subdiagonal entry h[k, k-1], l < k <= i.
            let mut k = i;
            while k > l && !negligible_subdiagonal(h, k, (l, i), small) {
                k -= 1;
            }
            l = k;
            if l > 0 {
                h[(l, l - 1)] = 0.0;
            }
            if l + 1 >= i {
                converged = true;
                break;
            }
            iterations_since_deflation += 1;
            let (first, last) = if full { (0, n - 1) } else { (l, i) };

            // The shifts: in the first sweeps after a deflation the known eigenvalue nearest to
            // the trailing block's (Hamiltonian mirror images, estimates), else the
            // eigenvalues of the trailing 2 x 2 block, or exceptional ones.
            let known = match (iterations_since_deflation, mirrors.as_ref()) {
                (1..=KNOWN_SHIFT_SWEEPS, Some(mirrors)) => mirrors.shifts(block_eigenvalues_2x2(
                    h[(i - 1, i - 1)],
                    h[(i - 1, i)],
                    h[(i, i - 1)],
                    h[(i, i)],
                )),
                _ => None,
            };
            let (shift1, shift2) = if let Some(shifts) = known {
                shifts
            } else {
                let (h11, h12, h21, h22) =
                    if iterations_since_deflation % (2 * EXCEPTIONAL_SHIFT_INTERVAL) == 0 {
                        let s = h[(i, i - 1)].abs() + h[(i - 1, i - 2)].abs();
                        (0.75 * s + h[(i, i)], -0.4375 * s, s, 0.75 * s + h[(i, i)])
                    } else if iterations_since_deflation % EXCEPTIONAL_SHIFT_INTERVAL == 0 {
                        let s = h[(l + 1, l)].abs() + h[(l + 2, l + 1)].abs();
                        (0.75 * s + h[(l, l)], -0.4375 * s, s, 0.75 * s + h[(l, l)])
                    } else {
                        (h[(i - 1, i - 1)], h[(i - 1, i)], h[(i, i - 1)], h[(i, i)])
                    };
                double_shift(h11, h12, h21, h22)
            };

            // Start the bulge at the highest m >= l where two consecutive small subdiagonal
            // entries make the first column of (H - s1)(H - s2) nearly a multiple of e_m.
            let mut m = i - 2;
            let mut v;
            loop {
                v = shift_polynomial_column(h, m, (shift1, shift2));
                if m == l {
                    break;
                }
                let h00 = h[(m, m - 1)].abs() * (v[1].abs() + v[2].abs());
                let h01 = v[0].abs()
                    * (h[(m - 1, m - 1)].abs() + h[(m, m)].abs() + h[(m + 1, m + 1)].abs());
                if h00 <= ulp * h01 {
                    break;
                }
                m -= 1;
            }

            // Chase the bulge from row m to the bottom of the window.
            for k in m..i {
                let rows = 3.min(i - k + 1);
                if k > m {
                    for (r, x) in v.iter_mut().enumerate().take(rows) {
                        *x = h[(k + r, k - 1)];
                    }
                }
                // Lengths fixed at compile time: the reflector's loops unroll.
                let (beta, tau) = if rows == 3 {
                    reflector(&mut v[..3])
                } else {
                    reflector(&mut v[..2])
                };
                if k > m {
                    h[(k, k - 1)] = beta;
                    h[(k + 1, k - 1)] = 0.0;
                    if k + 2 <= i {
                        h[(k + 2, k - 1)] = 0.0;
                    }
                } else if m > l {
                    // = -h[k, k-1] in exact arithmetic; this form stays right when v underflows.
                    h[(k, k - 1)] *= 1.0 - tau;
                }
                // Rows below k + 3 and below the window hold zeros in these columns, and stay
                // zero (up to sign); at a fixed order all rows are updated, in loops of
                // constant length that vectorise.
                let column_rows = if O::FIXED {
                    0..n
                } else {
                    first..(k + 3).min(i) + 1
                };
                if rows == 3 {
                    let w = [1.0, v[1], v[2]];
                    h.reflect_rows_fixed(k, w, tau, k..last + 1);
                    h.reflect_columns_fixed(k, w, tau, column_rows);
                    if let Some(z) = z.as_deref_mut() {
                        z.reflect_columns_fixed(k, w, tau, 0..n);
                    }
                } else {
                    let w = [1.0, v[1]];
                    h.reflect_rows_fixed(k, w, tau, k..last + 1);
                    h.reflect_columns_fixed(k, w, tau, column_rows);
                    if let Some(z) = z.as_deref_mut() {
                        z.reflect_columns_fixed(k, w, tau, 0..n);
                    }
                }
            }
        }
        if !converged {
            return Err(Error::NoConvergence {
                algorithm: "the Francis double-shift QR iteration",
            });
        }
        if l + 1 == i {
            // A 2 x 2 block: standardise it, and carry its rotation through the rest.
            let block =
                standardize_block(h[(i - 1, i - 1)], h[(i - 1, i)], h[(i, i - 1)], h[(i, i)]);
            h[(i - 1, i - 1)] = block.a;
            h[(i - 1, i)] = block.b;
            h[(i, i - 1)] = block.c;
            h[(i, i)] = block.d;
            if full {
                h.rotate_rows(i - 1, i + 1..n, block.cs, block.sn);
                h.rotate_columns(i - 1, 0..i - 1, block.cs, block.sn);
            }
            if let Some(z) = z.as_deref_mut() {
                z.rotate_columns(i - 1, 0..n, block.cs, block.sn);
            }
        }
        if let Some(mirrors) = mirrors.as_mut() {
            if l == i {
                mirrors.found(c64::new(h[(i, i)], 0.0));
            } else if h[(i, i - 1)] == 0.0 {
                mirrors.found(c64::new(h[(i - 1, i - 1)], 0.0));
                mirrors.found(c64::new(h[(i, i)], 0.0));
            } else {
                let im = h[(i - 1, i)].abs().sqrt() * h[(i, i - 1)].abs().sqrt();
                mirrors.found(c64::new(h[(i, i)], im));
            }
        }
        iterations_since_deflation = 0;
        if let Some(margin) = unstable_margin {
            // Re λ of the block's eigenvalues: its diagonal (a standard 2 x 2 block's is a, a).
            if (l..=i).all(|k| h[(k, k)] > margin) {
                if l == n / 2 {
                    return Ok(Finished::UnstableHalf);
                }
            } else {
                unstable_margin = None;
            }
        }
        if l == lo {
            return Ok(Finished::Complete);
        }
        i = l - 1;
    }
}

/// Whether the subdiagonal entry h[k, k-1] of the active window l..=i (l < k <= i) is
/// negligible: at most `small` (underflow), or at most u times its diagonal neighbours and such
/// that setting it to zero moves the eigenvalues of the 2 x 2 block h[k-1..=k, k-1..=k] by at
/// most u times their size (Ahues & Tisseur 1997, as LAPACK's dlahqr).
#[inline]
pub(crate) fn negligible_subdiagonal<O: Order>(
    h: &Square<O>,
    k: usize,
    (l, i): (usize, usize),
    small: f64,
) -> bool {
    let ulp = f64::EPSILON;
    let sub = h[(k, k - 1)].abs();
    if sub <= small {
        return true;
    }
    let mut test = h[(k - 1, k - 1)].abs() + h[(k, k)].abs();
    if test == 0.0 {
        if k >= l + 2 {
            test += h[(k - 1, k - 2)].abs();
        }
        if k < i {
            test += h[(k + 1, k)].abs();
        }
    }
    if sub > ulp * test {
        return false;
    }
    let sup = h[(k - 1, k)].abs();
    let (ab, ba) = (sub.max(sup), sub.min(sup));
    let diff = (h[(k - 1, k - 1)] - h[(k, k)]).abs();
    let (aa, bb) = (h[(k, k)].abs().max(diff), h[(k, k)].abs().min(diff));
    let s = aa + ab;
    ba * (ab / s) <= small.max(ulp * (bb * (aa / s)))
}

/// The first column of (H - s1)(H - s2) restricted to rows m..m+3 (its only nonzero entries
/// when the block starts at row m), scaled to unit 1-norm: the vector whose reflector starts a
/// double-shift bulge at row m. With s1, s2 real or a conjugate pair it is real. Zero (no
/// bulge) in the degenerate case where all three entries vanish.
#[inline]
pub(crate) fn shift_polynomial_column<O: Order>(
    h: &Square<O>,
    m: usize,
    (shift1, shift2): (c64, c64),
) -> [f64; 3] {
    let h21s = h[(m + 1, m)];
    let s = (h[(m, m)] - shift2.re).abs() + shift2.im.abs() + h21s.abs();
    if s == 0.0 {
        return [0.0; 3];
    }
    let h21s = h21s / s;
    let mut v = [
        h21s * h[(m, m + 1)] + (h[(m, m)] - shift1.re) * ((h[(m, m)] - shift2.re) / s)
            - shift1.im * (shift2.im / s),
        h21s * (h[(m, m)] + h[(m + 1, m + 1)] - shift1.re - shift2.re),
        h21s * h[(m + 2, m + 1)],
    ];
    let norm = v[0].abs() + v[1].abs() + v[2].abs();
    if !(norm > 0.0 && norm.is_finite()) {
        return [0.0; 3];
    }
    let inverse = 1.0 / norm;
    for x in &mut v {
        *x *= inverse;
    }
    v
}

/// Estimates of the stable eigenvalues (Re λ <= 0; of a pair, the member with Im >= 0) of a
/// Hamiltonian matrix in upper Hessenberg form, from its characteristic polynomial, which is
/// even: det(λI - H) = q(λ²), and each root μ of q gives the pair ±sqrt(μ). Empty for an odd
/// order, or if the polynomial is not finite or the companion matrix's QR iteration fails.
/// A root μ < 0 gives an estimate on the imaginary axis (Re = -0).
fn hamiltonian_estimates<O: Order>(h: &Square<O>) -> Vec<c64> {
    let order = h.n() / 2;
    if order == 0 || !h.n().is_multiple_of(2) {
        return Vec::new();
    }
    let p = hessenberg_characteristic_polynomial(h);
    if !p.iter().all(|c| c.is_finite()) {
        return Vec::new();
    }
    // The roots of q(μ) = μ^order + p_2 μ^(order-1) + ... + p_2order: in closed form up to
    // degree four, else (or if those fail their check) the eigenvalues of q's companion matrix
    // (upper Hessenberg already; its reduction costs a scan).
    let q: Vec<f64> = (1..=order).map(|j| p[2 * j]).collect();
    let roots = match monic_roots(&q) {
        Some(roots) => Ok(roots.as_slice().to_vec()),
        None => with_order!(order, companion_order => {
            let mut companion = Square::zeros_in(companion_order);
            for j in 0..order {
                companion[(0, j)] = -q[j];
                if j + 1 < order {
                    companion[(j + 1, j)] = 1.0;
                }
            }
            let (mut companion, scale) = balanced_hessenberg(companion);
            francis_qr(&mut companion, None, (0, order - 1), false, Spectrum::General)
                .map(|()| block_eigenvalues(order, |i, j| companion[(i, j)] * scale))
        }),
    };
    match roots {
        Ok(roots) => roots
            .iter()
            .filter(|mu| mu.im >= 0.0)
            .map(|mu| {
                // |Im|: an Im sqrt(μ) that underflowed to -0 would otherwise give the member
                // with Im < 0.
                let root = mu.sqrt();
                c64::new(-root.re, root.im.abs())
            })
            .filter(|z| z.re.is_finite() && z.im.is_finite())
            .collect(),
        Err(_) => Vec::new(),
    }
}

/// The two shifts of a double-shift step: the eigenvalues of [[h11, h12], [h21, h22]] when
/// they are complex; when they are real, the one nearer h22, twice.
pub(crate) fn double_shift(h11: f64, h12: f64, h21: f64, h22: f64) -> (c64, c64) {
    let [first, second] = block_eigenvalues_2x2(h11, h12, h21, h22);
    if first.im != 0.0 {
        return (first, second);
    }
    let nearer = if (first.re - h22).abs() <= (second.re - h22).abs() {
        first
    } else {
        second
    };
    (nearer, nearer)
}

/// The eigenvalues of [[h11, h12], [h21, h22]]: a conjugate pair (Im > 0 first) or two reals,
/// from the scaled trace and determinant (a shift needs no more accuracy than this).
fn block_eigenvalues_2x2(h11: f64, h12: f64, h21: f64, h22: f64) -> [c64; 2] {
    let s = h11.abs() + h12.abs() + h21.abs() + h22.abs();
    if s == 0.0 {
        return [c64::new(0.0, 0.0); 2];
    }
    let inverse = 1.0 / s;
    let (h11, h12, h21, h22) = (h11 * inverse, h12 * inverse, h21 * inverse, h22 * inverse);
    let trace_half = (h11 + h22) / 2.0;
    let det = (h11 - trace_half) * (h22 - trace_half) - h12 * h21;
    let root = det.abs().sqrt();
    if det >= 0.0 {
        let re = trace_half * s;
        [c64::new(re, root * s), c64::new(re, -root * s)]
    } else {
        [
            c64::new((trace_half + root) * s, 0.0),
            c64::new((trace_half - root) * s, 0.0),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_matrices::{lateral_747, lateral_747_inputs};
    use faer::linalg::solvers::DenseSolveCore;
    use faer::mat;

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
        let mut h = Square::from_mat(hessenberg_matrix(a.as_ref()).as_ref());
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
                let mut hessenberg = Square::from_mat(h.as_ref());
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
        assert!(hamiltonian_estimates(&Square::identity(3)).is_empty());
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
        let mut hessenberg = Square::from_mat(h.as_ref());
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
                Square::from_mat_in(order, h.as_ref()),
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
        let mut mirrors = Mirrors::for_spectrum::<Dynamic>(Spectrum::Hamiltonian, None).unwrap();
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
