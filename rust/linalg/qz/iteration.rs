//! The QZ iteration (Moler & Stewart 1973; Golub & Van Loan, 4th ed., Section 7.7): implicit
//! double-shift steps on a Hessenberg-triangular pencil (H, T) until H is quasi-triangular,
//! with deflation of infinite eigenvalues, and the 2 x 2 blocks put in standard form.
//!
//! # The step
//!
//! The shifts are the eigenvalues of the trailing 2 x 2 block of M = H T^-1 (formed from the
//! trailing 3 x 3 of T^-1, which is the inverse of T's trailing 3 x 3); the first column of
//! (M - σ1)(M - σ2) has three nonzero entries and is formed without M, about the shift
//! s = h_ll / t_ll at the top of the active block (as (M - s)^2 - (σ1 + σ2 - 2 s)(M - s) +
//! (σ1 - s)(σ2 - s), from differences of diagonal ratios: Moler and Stewart's formula), so
//! that a pencil near a proportional one, M = s I + O(E), has a first column of E^2 formed
//! from terms of E, not of s^2. A reflector on rows
//! (k, k+1, k+2) creates the bulge; each step of the chase restores T with a reflector on
//! columns (k, k+1, k+2) that zeroes T[k+2, k..k+2] (the reflector of the row reversed) and a
//! rotation of columns (k, k+1) that zeroes T[k+1, k], and moves the bulge of H one row down.
//! Ten steps without a deflation bring an exceptional shift; 30 n steps in all without
//! convergence is [`Error::NoConvergence`].
//!
//! # Deflation
//!
//! A subdiagonal entry of H is negligible when |h_{k,k-1}| <= u (|h_{k-1,k-1}| + |h_{k,k}|)
//! (or u ||H||_F when both are zero); a diagonal entry of T when |t_kk| <= u ||T||_F. A zero
//! t_kk means an infinite eigenvalue: at the top of the active block a row rotation zeroes
//! h_{k+1,k}; elsewhere the zero is chased to the bottom of the block by row rotations (each
//! followed by a column rotation that removes the fill-in of H), where a column rotation
//! zeroes h_{hi,hi-1}. All of these are orthogonal, so the computed form is the exact form of
//! a pencil within a few units of rounding of (A, B).
//!
//! # Standard form
//!
//! A deflated 2 x 2 block's eigenvalues are real or complex by the sign of the discriminant of
//! det(H - λ T) about the shift (0 or a diagonal ratio) that forms it most accurately. A block
//! with real eigenvalues is split (a rotation through the right eigenvector of the pencil from
//! the right, through H z or T z from the left), at the root and with the rotation that leave
//! the smallest remainders below the diagonal, which are its backward error; one with complex
//! eigenvalues keeps H's block full and makes T's block diagonal with positive entries (two
//! rotations: the columns of T's block made orthogonal, then the longer aligned with its axis,
//! which leaves u ||T_kk|| off the diagonal even where T's block is nearly singular). Every 1 x 1
//! block has t_kk >= 0 (a column of S, T and Z negated where needed), as LAPACK's dgges returns.

use crate::error::Error;
use crate::linalg::rotation::Rotation;
use crate::linalg::schur::standardize_block;
use crate::platform::interrupt;
use faer::Mat;

const U: f64 = f64::EPSILON;

/// The pencil under iteration and its accumulated transformations.
pub(crate) struct Pencil<'m> {
    pub h: &'m mut Mat<f64>,
    pub t: &'m mut Mat<f64>,
    pub q: &'m mut Mat<f64>,
    pub z: &'m mut Mat<f64>,
}

impl Pencil<'_> {
    pub(crate) fn n(&self) -> usize {
        self.h.nrows()
    }

    /// A rotation of rows (i, k) of H and T from column `from`, accumulated into Q.
    fn rotate_rows(&mut self, g: Rotation, i: usize, k: usize, from: usize) {
        let n = self.n();
        g.rows(self.h, i, k, from..n);
        g.rows(self.t, i, k, from..n);
        g.columns(self.q, i, k, 0..n);
    }

    /// A rotation of columns (i, k) of H (rows 0..h_rows) and T (rows 0..t_rows), accumulated
    /// into Z.
    fn rotate_columns(&mut self, g: Rotation, i: usize, k: usize, h_rows: usize, t_rows: usize) {
        let n = self.n();
        g.columns(self.h, i, k, 0..h_rows);
        g.columns(self.t, i, k, 0..t_rows);
        g.columns(self.z, i, k, 0..n);
    }

    /// Makes t_kk >= 0 by negating column k of H, T and Z.
    pub(crate) fn make_positive(&mut self, k: usize) {
        if self.t[(k, k)] < 0.0 {
            let n = self.n();
            for r in 0..=k.min(n - 1) {
                self.t[(r, k)] = -self.t[(r, k)];
            }
            for r in 0..n {
                self.h[(r, k)] = -self.h[(r, k)];
                self.z[(r, k)] = -self.z[(r, k)];
            }
        }
    }
}

/// Runs the QZ iteration on a Hessenberg-triangular pencil until H is quasi-triangular with
/// standard 2 x 2 blocks.
pub(crate) fn qz_iteration(p: &mut Pencil<'_>) -> Result<(), Error> {
    let n = p.n();
    if n == 0 {
        return Ok(());
    }
    let h_norm = crate::linalg::norm::frobenius_norm(p.h.as_ref());
    let t_norm = crate::linalg::norm::frobenius_norm(p.t.as_ref());
    let t_tolerance = (U * t_norm).max(f64::MIN_POSITIVE);
    let max_steps = 30 * n.max(1);
    let mut steps = 0;
    let mut since_deflation = 0;
    let mut hi = n - 1;
    loop {
        // The active block lo..=hi: the first negligible subdiagonal from the bottom.
        let mut lo = 0;
        for k in (1..=hi).rev() {
            let mut neighbours = p.h[(k - 1, k - 1)].abs() + p.h[(k, k)].abs();
            if neighbours == 0.0 {
                neighbours = h_norm;
            }
            if p.h[(k, k - 1)].abs() <= (U * neighbours).max(f64::MIN_POSITIVE) {
                p.h[(k, k - 1)] = 0.0;
                lo = k;
                break;
            }
        }
        if lo == hi {
            p.make_positive(hi);
            since_deflation = 0;
            if hi == 0 {
                return Ok(());
            }
            hi -= 1;
            continue;
        }
        if let Some(j) = (lo..=hi).find(|&j| p.t[(j, j)].abs() <= t_tolerance) {
            deflate_infinite(p, lo, j, hi);
            continue;
        }
        if hi - lo == 1 {
            if standardize_pair(p, lo)? {
                // Complex pair: both deflate.
                since_deflation = 0;
                if lo == 0 {
                    return Ok(());
                }
                hi = lo - 1;
            }
            continue;
        }
        steps += 1;
        since_deflation += 1;
        if steps > max_steps {
            return Err(Error::NoConvergence {
                algorithm: "QZ iteration",
            });
        }
        if steps % 64 == 0 {
            interrupt::check()?;
        }
        double_shift_step(p, lo, hi, since_deflation % 10 == 0);
    }
}

/// t_jj = 0 in the active block lo..=hi: deflates an infinite eigenvalue at the top (j = lo)
/// or chases the zero to the bottom and deflates it there.
fn deflate_infinite(p: &mut Pencil<'_>, lo: usize, j: usize, hi: usize) {
    p.t[(j, j)] = 0.0;
    if j == lo {
        let (g, r) = Rotation::zeroing(p.h[(lo, lo)], p.h[(lo + 1, lo)]);
        p.h[(lo, lo)] = r;
        p.h[(lo + 1, lo)] = 0.0;
        p.rotate_rows(g, lo, lo + 1, lo + 1);
        // Rows lo, lo+1 of T at column lo were (0, 0) and stay so.
        p.t[(lo + 1, lo)] = 0.0;
        return;
    }
    for k in j..hi {
        let (g, r) = Rotation::zeroing(p.t[(k, k + 1)], p.t[(k + 1, k + 1)]);
        p.t[(k, k + 1)] = r;
        p.t[(k + 1, k + 1)] = 0.0;
        let n = p.n();
        g.rows(p.t, k, k + 1, k + 2..n);
        g.rows(p.h, k, k + 1, k - 1..n);
        g.columns(p.q, k, k + 1, 0..n);
        // The rotation put a fill-in at h_{k+1,k-1}; a column rotation removes it.
        let (g, r) = Rotation::zeroing_first(p.h[(k + 1, k - 1)], p.h[(k + 1, k)]);
        p.h[(k + 1, k)] = r;
        p.h[(k + 1, k - 1)] = 0.0;
        p.rotate_columns(g, k - 1, k, k + 1, k + 1);
        p.t[(k, k - 1)] = 0.0;
    }
    let (g, r) = Rotation::zeroing_first(p.h[(hi, hi - 1)], p.h[(hi, hi)]);
    p.h[(hi, hi)] = r;
    p.h[(hi, hi - 1)] = 0.0;
    p.rotate_columns(g, hi - 1, hi, hi, hi + 1);
    p.t[(hi, hi - 1)] = 0.0;
}

/// One implicit double-shift QZ step on the active block lo..=hi (at least 3 x 3).
fn double_shift_step(p: &mut Pencil<'_>, lo: usize, hi: usize, exceptional: bool) {
    let n = p.n();
    let (h, t) = (&*p.h, &*p.t);
    // Everything in terms of M - s I = (H - s T) T^-1, s = h_aa / t_aa the ratio at the top
    // of the block: the shifts as σ - s, and h_aa - s t_aa taken as 0. Where the pencil is
    // near a proportional one (H = c T + E), M = c I + O(E) and the first column of
    // (M - σ1)(M - σ2), of size E^2, is a difference of terms of size c^2 formed directly;
    // shifted, its terms are differences of ratios h_ii / t_ii (errors of u c) times O(E).
    let (a, b, c) = (lo, lo + 1, lo + 2);
    let shift = h[(a, a)] / t[(a, a)];
    // The trailing 2 x 2 of M - s I from the trailing 3 x 3 of T^-1.
    let (i0, i1, i2) = (hi - 2, hi - 1, hi);
    let (t00, t01, t02) = (t[(i0, i0)], t[(i0, i1)], t[(i0, i2)]);
    let (t11, t12, t22) = (t[(i1, i1)], t[(i1, i2)], t[(i2, i2)]);
    let inv01 = -t01 / (t00 * t11);
    let inv02 = (t01 * t12 - t02 * t11) / (t00 * t11 * t22);
    let inv12 = -t12 / (t11 * t22);
    let m11 = (h[(i1, i1)] / t11 - shift) + h[(i1, i0)] * inv01;
    let m12 = h[(i1, i0)] * inv02 + h[(i1, i1)] * inv12 + h[(i1, i2)] / t22;
    let m21 = h[(i2, i1)] / t11;
    let m22 = (h[(i2, i2)] / t22 - shift) + h[(i2, i1)] * inv12;
    let (sum, product) = if exceptional {
        let e = m21.abs() + (h[(i1, i0)] / t00).abs();
        let d = 0.75 * e + m22;
        (2.0 * d, d * d + 0.4375 * e * e)
    } else {
        (m11 + m22, m11 * m22 - m12 * m21)
    };
    // The first column of (M - s - σ1')(M - s - σ2') = (M - s)^2 - sum (M - s) + product:
    // (M - s) e1 = m2 e_b with m2 = h_ba / t_aa, and (M - s) e_b m2 is (H - s T) times
    // T^-1 m2 e_b = (-t_ab / t_aa, 1, 0) m2 / t_bb.
    let m2 = h[(b, a)] / t[(a, a)];
    let zb = m2 / t[(b, b)];
    let mut v = [
        (h[(a, b)] - shift * t[(a, b)]) * zb + product,
        m2 * ((h[(b, b)] / t[(b, b)] - shift) - m2 * t[(a, b)] / t[(b, b)] - sum),
        h[(c, b)] * zb,
    ];
    let scale = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if scale > 0.0 && scale.is_finite() {
        v.iter_mut().for_each(|x| *x /= scale);
    }
    use crate::linalg::rotation::SmallReflector;
    for k in lo..hi - 1 {
        // The bulge: rows k..k+2.
        let x = if k == lo {
            v
        } else {
            [p.h[(k, k - 1)], p.h[(k + 1, k - 1)], p.h[(k + 2, k - 1)]]
        };
        let (reflector, beta) = SmallReflector::to_first(&x);
        let from = if k == lo {
            lo
        } else {
            p.h[(k, k - 1)] = beta;
            p.h[(k + 1, k - 1)] = 0.0;
            p.h[(k + 2, k - 1)] = 0.0;
            k
        };
        reflector.rows(p.h, k, from..n);
        reflector.rows(p.t, k, k..n);
        reflector.columns(p.q, k, 0..n);
        // Restore T: zero T[k+2, k..k+2], then T[k+1, k].
        let row = [p.t[(k + 2, k)], p.t[(k + 2, k + 1)], p.t[(k + 2, k + 2)]];
        let (reflector, beta) = SmallReflector::to_last(&row);
        let h_rows = (k + 4).min(hi + 1);
        reflector.columns(p.h, k, 0..h_rows);
        reflector.columns(p.t, k, 0..k + 2);
        reflector.columns(p.z, k, 0..n);
        p.t[(k + 2, k)] = 0.0;
        p.t[(k + 2, k + 1)] = 0.0;
        p.t[(k + 2, k + 2)] = beta;
        let (g, r) = Rotation::zeroing_first(p.t[(k + 1, k)], p.t[(k + 1, k + 1)]);
        p.t[(k + 1, k + 1)] = r;
        p.t[(k + 1, k)] = 0.0;
        p.rotate_columns(g, k, k + 1, h_rows, k + 1);
    }
    // The last row pair: a rotation zeroes h_{hi,hi-2}, another restores T.
    let k = hi - 1;
    let (g, r) = Rotation::zeroing(p.h[(k, k - 1)], p.h[(hi, k - 1)]);
    p.h[(k, k - 1)] = r;
    p.h[(hi, k - 1)] = 0.0;
    p.rotate_rows(g, k, hi, k);
    let (g, r) = Rotation::zeroing_first(p.t[(hi, k)], p.t[(hi, hi)]);
    p.t[(hi, hi)] = r;
    p.t[(hi, k)] = 0.0;
    p.rotate_columns(g, k, hi, hi + 1, hi);
}

/// Puts the 2 x 2 block at rows and columns (k, k+1) in standard form; T's block may be any
/// 2 x 2 matrix with nonzero singular values. Returns whether the eigenvalues are complex (the
/// block stays); real ones are split, leaving h_{k+1,k} = 0 and T's block upper triangular.
pub(crate) fn standardize_pair(p: &mut Pencil<'_>, k: usize) -> Result<bool, Error> {
    let l = k + 1;
    let n = p.n();
    // T's block upper triangular first.
    if p.t[(l, k)] != 0.0 {
        let (g, r) = Rotation::zeroing(p.t[(k, k)], p.t[(l, k)]);
        p.t[(k, k)] = r;
        p.t[(l, k)] = 0.0;
        g.rows(p.t, k, l, l..n);
        g.rows(p.h, k, l, k..n);
        g.columns(p.q, k, l, 0..n);
    }
    let quadratics = Quadratic::of_block(p, k)?;
    if quadratics[0].discriminant >= 0.0 {
        split_real_pair(p, k, &quadratics);
        return Ok(false);
    }
    // Complex: T's block diagonal and positive. Columns of T's block made orthogonal (a
    // one-sided Jacobi rotation), then a row rotation aligns the longer with its axis: the
    // Jacobi rotation leaves the columns' inner product at u ||T_kk||^2, and the entry that
    // the alignment leaves off the diagonal is that product over the aligned column's length
    // (over the shorter one's, it grew to u ||T_kk||^2 / σ_min: a pair near infinity, σ_min of
    // 1e-4, lost B's backward error).
    let (a, b, d) = (
        p.t[(k, k)].powi(2) + p.t[(l, k)].powi(2),
        p.t[(k, l)].powi(2) + p.t[(l, l)].powi(2),
        p.t[(k, k)] * p.t[(k, l)] + p.t[(l, k)] * p.t[(l, l)],
    );
    if d != 0.0 {
        let zeta = (b - a) / (2.0 * d);
        let sign = if zeta >= 0.0 { 1.0 } else { -1.0 };
        let tan = -1.0 / (zeta + sign * (1.0 + zeta * zeta).sqrt());
        let c = 1.0 / (1.0 + tan * tan).sqrt();
        p.rotate_columns(Rotation { c, s: c * tan }, k, l, l + 1, l + 1);
    }
    let first = p.t[(k, k)].hypot(p.t[(l, k)]);
    let second = p.t[(k, l)].hypot(p.t[(l, l)]);
    if first >= second {
        let (g, _) = Rotation::zeroing(p.t[(k, k)], p.t[(l, k)]);
        p.rotate_rows(g, k, l, k);
    } else {
        let (g, _) = Rotation::zeroing(p.t[(l, l)], p.t[(k, l)]);
        p.rotate_rows(g, l, k, k);
    }
    p.t[(l, k)] = 0.0;
    p.t[(k, l)] = 0.0;
    for r in [k, l] {
        if p.t[(r, r)] < 0.0 {
            for j in k..n {
                p.t[(r, j)] = -p.t[(r, j)];
                p.h[(r, j)] = -p.h[(r, j)];
            }
            for i in 0..n {
                p.q[(i, r)] = -p.q[(i, r)];
            }
        }
    }
    // The rotations can leave a pair whose eigenvalues, formed again from the final blocks
    // (as generalized_eigenvalues forms them), are real: a nearly defective real pair, such
    // as a double eigenvalue of (M, M). Split it, so that 2 x 2 blocks hold complex pairs only
    // (LAPACK's dlagv2 likewise).
    let (t11, t22) = (p.t[(k, k)], p.t[(l, l)]);
    let block = standardize_block(
        p.h[(k, k)] / t11,
        p.h[(k, l)] / t22,
        p.h[(l, k)] / t11,
        p.h[(l, l)] / t22,
    );
    if block.c == 0.0 {
        split_real_pair(p, k, &Quadratic::of_block(p, k)?);
        return Ok(false);
    }
    Ok(true)
}

/// The characteristic polynomial of the 2 x 2 block at (k, k+1) (T's block upper triangular,
/// nonsingular) about a shift s: det(H' - μ T) = a μ^2 - b μ + c with H' = H - s T and
/// λ = s + μ,
///
/// ```text
/// a = t11 t22,   b = h'11 t22 + h'22 t11 - h21 t12,   c = h'11 h'22 - h'12 h21,
/// ```
///
/// for s = 0 and for the diagonal ratios s = h_ii / t_ii (with h'_ii taken as 0, a change of
/// u |h_ii|). The discriminant b^2 - 4 a c is the same for every shift in exact arithmetic; in
/// floating point its error is about u (b^2 + 4 |a c|), so the shift with the smallest of these
/// terms tells real from complex. A pencil near a proportional one, H = s T + E, has terms of
/// ||E||^2 about s = h_ii / t_ii against terms of s^2 ||T||^2 unshifted (its pair was split
/// with backward errors of sqrt(u)); a pair with one eigenvalue near infinity and the other
/// far below the diagonal ratios needs s = 0. (LAPACK's dlag2 shifts by a diagonal ratio.)
#[derive(Debug, Clone, Copy)]
struct Quadratic {
    shift: f64,
    a: f64,
    b: f64,
    c: f64,
    discriminant: f64,
}

impl Quadratic {
    /// The quadratics of the block about the three shifts, the most accurate first.
    fn of_block(p: &Pencil<'_>, k: usize) -> Result<[Quadratic; 3], Error> {
        let l = k + 1;
        let (t11, t12, t22) = (p.t[(k, k)], p.t[(k, l)], p.t[(l, l)]);
        let (h11, h12, h21, h22) = (p.h[(k, k)], p.h[(k, l)], p.h[(l, k)], p.h[(l, l)]);
        let about = |shift: f64, h11: f64, h22: f64| {
            let h12 = h12 - shift * t12;
            let (a, b, c) = (
                t11 * t22,
                h11 * t22 + h22 * t11 - h21 * t12,
                h11 * h22 - h12 * h21,
            );
            Quadratic {
                shift,
                a,
                b,
                c,
                discriminant: b * b - 4.0 * a * c,
            }
        };
        let (s1, s2) = (h11 / t11, h22 / t22);
        let mut quadratics = [
            about(0.0, h11, h22),
            about(s1, 0.0, h22 - s1 * t22),
            about(s2, h11 - s2 * t11, 0.0),
        ];
        let error = |q: &Quadratic| {
            let terms = q.b * q.b + 4.0 * (q.a * q.c).abs();
            if [q.shift, q.a, q.b, q.c, q.discriminant, terms]
                .iter()
                .all(|x| x.is_finite())
            {
                terms
            } else {
                f64::INFINITY
            }
        };
        quadratics.sort_by(|x, y| error(x).total_cmp(&error(y)));
        if error(&quadratics[0]).is_finite() {
            Ok(quadratics)
        } else {
            Err(Error::NoConvergence {
                algorithm: "QZ iteration (a 2 x 2 block overflowed)",
            })
        }
    }

    /// The real roots λ = s + μ as homogeneous pairs (α, β), λ = α / β: μ = q / a and c / q
    /// with q = (b + sign(b) sqrt(b^2 - 4 a c)) / 2 (no cancellation), so that a root at
    /// infinity (a = 0) is (q, 0); where the discriminant is negative (a pair found real only
    /// after standardisation), the real part b / (2 a). Empty if not finite.
    fn real_roots(&self) -> impl Iterator<Item = (f64, f64)> {
        let roots = if self.discriminant < 0.0 {
            [Some((self.b, 2.0 * self.a)), None]
        } else {
            let q = 0.5 * (self.b + self.b.signum() * self.discriminant.sqrt());
            if q == 0.0 {
                [Some((0.0, 1.0)), None]
            } else {
                [Some((self.c, q)), Some((q, self.a))]
            }
        };
        let shift = self.shift;
        roots
            .into_iter()
            .flatten()
            .map(move |(alpha, beta)| (shift * beta + alpha, beta))
            .filter(|(alpha, beta)| alpha.is_finite() && beta.is_finite())
    }
}

/// Splits the 2 x 2 block at (k, k+1) (T's block upper triangular) at a real eigenvalue: a
/// column rotation through its right eigenvector (the null vector of β H - α T, λ = α / β)
/// and a row rotation along T z or H z, leaving h_{k+1,k} = t_{k+1,k} = 0.
///
/// The entry that the row rotation leaves below the diagonal of the other matrix is the
/// backward error of the split (H z = λ T z + r: along T z it leaves r_2 in H, along H z it
/// leaves r_2 / λ in T). The real roots of the `quadratics` (the most accurate first) are
/// tried with both row rotations until a split leaves remainders of rounding (2 u relative
/// to the block norms of H and T); else the split whose larger remainder is smallest is
/// taken. The remainders are set to zero. (LAPACK's dlagv2 chooses the row
/// rotation by the block norms and the eigenvalue alone; an eigenvalue with a forward error
/// of κ u, far below a diagonal ratio or beside a near-infinite one, left a remainder of
/// κ u.)
fn split_real_pair(p: &mut Pencil<'_>, k: usize, quadratics: &[Quadratic; 3]) {
    let l = k + 1;
    let h = [[p.h[(k, k)], p.h[(k, l)]], [p.h[(l, k)], p.h[(l, l)]]];
    let t = [[p.t[(k, k)], p.t[(k, l)]], [0.0, p.t[(l, l)]]];
    let block_norm = |m: &[[f64; 2]; 2]| {
        let norm = (m[0][0].abs() + m[0][1].abs()).max(m[1][0].abs() + m[1][1].abs());
        norm.max(f64::MIN_POSITIVE)
    };
    let (h_norm, t_norm) = (block_norm(&h), block_norm(&t));
    let norm = |r: &[f64; 2]| r[0].hypot(r[1]);
    // Column k of a 2 x 2 block after the column rotation g.
    let first_column = |m: &[[f64; 2]; 2], g: Rotation| {
        [g.c * m[0][0] + g.s * m[0][1], g.c * m[1][0] + g.s * m[1][1]]
    };
    let mut best: Option<(f64, Rotation, Rotation)> = None;
    for (alpha, beta) in quadratics.iter().flat_map(Quadratic::real_roots) {
        // (α, β) scaled to the larger of unit size: the rows keep the size of H and T.
        let size = alpha.abs().max(beta.abs());
        if size == 0.0 {
            continue;
        }
        let (alpha, beta) = (alpha / size, beta / size);
        let rows = [
            [
                beta * h[0][0] - alpha * t[0][0],
                beta * h[0][1] - alpha * t[0][1],
            ],
            [beta * h[1][0], beta * h[1][1] - alpha * t[1][1]],
        ];
        let row = if norm(&rows[0]) >= norm(&rows[1]) {
            rows[0]
        } else {
            rows[1]
        };
        // z ⟂ row: the right eigenvector; the column rotation's first column is z.
        let (g, _) = if row == [0.0, 0.0] {
            Rotation::zeroing(1.0, 0.0)
        } else {
            Rotation::zeroing(row[1], -row[0])
        };
        let (hz, tz) = (first_column(&h, g), first_column(&t, g));
        for w in [tz, hz] {
            let (rows_g, _) = Rotation::zeroing(w[0], w[1]);
            let below = |x: [f64; 2]| (-rows_g.s * x[0] + rows_g.c * x[1]).abs();
            let remainder = (below(hz) / h_norm).max(below(tz) / t_norm);
            if best.is_none_or(|(least, _, _)| remainder < least) {
                best = Some((remainder, g, rows_g));
            }
        }
        // Remainders of rounding (2 u) with the most accurate quadratic's root: the others
        // cannot do better.
        if best.is_some_and(|(least, _, _)| least <= U) {
            break;
        }
    }
    // Without a finite root (not reached: the quadratic of s = 0 is finite), the identity.
    let identity = Rotation { c: 1.0, s: 0.0 };
    let (_, g, rows_g) = best.unwrap_or((0.0, identity, identity));
    p.rotate_columns(g, k, l, l + 1, l + 1);
    p.rotate_rows(rows_g, k, l, k);
    p.h[(l, k)] = 0.0;
    p.t[(l, k)] = 0.0;
    p.make_positive(k);
    p.make_positive(l);
}
