//! The Francis double-shift QR iteration on an upper Hessenberg matrix, and its shift
//! strategies: the trailing block's eigenvalues, exceptional shifts, and known eigenvalues
//! (mirror images of a Hamiltonian spectrum, estimates from its characteristic polynomial,
//! estimates given by the caller). See [`crate::linalg::schur`] for the method.

use crate::error::Error;
use crate::linalg::charpoly::hessenberg_characteristic_polynomial;
use crate::linalg::hessenberg::balanced_hessenberg;
use crate::linalg::householder::reflector;
use crate::linalg::matrix::{Order, Square, Transformations, with_order};
use crate::linalg::polynomial_roots::monic_roots;
use crate::linalg::schur::form::{block_eigenvalues, standardize_block};
use crate::platform::dispatch::clear_upper_avx_state;
use crate::platform::interrupt;
use faer::c64;

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
pub(super) struct Mirrors {
    pub(super) pending: Vec<c64>,
    /// Known eigenvalues that join `pending` once `deflations_before_later` eigenvalues have
    /// deflated (the stable half of a Hamiltonian spectrum, after the unstable half; estimates
    /// on the imaginary axis are in `pending` only).
    pub(super) later: Vec<c64>,
    /// Deflations (each real eigenvalue and each complex pair counts one) left before `later`
    /// joins `pending`: at first, the number of unstable estimates.
    pub(super) deflations_before_later: usize,
    /// Whether an eigenvalue that matches no pending one adds its mirror image (a Hamiltonian
    /// spectrum without estimates; with them, the estimate of the mirror image is in `later`
    /// already, and measured on graded Riccati problems adding it cost sweeps).
    pub(super) mirrored: bool,
}

impl Mirrors {
    pub(super) fn for_spectrum<O: Order>(
        spectrum: Spectrum<'_>,
        h: Option<&Square<O>>,
    ) -> Option<Self> {
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
    pub(super) fn found(&mut self, lambda: c64) {
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
    pub(super) fn shifts(&self, trailing: [c64; 2]) -> Option<(c64, c64)> {
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

    let n = h.nrows();
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
pub(super) fn hamiltonian_estimates<O: Order>(h: &Square<O>) -> Vec<c64> {
    let order = h.nrows() / 2;
    if order == 0 || !h.nrows().is_multiple_of(2) {
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
            let mut companion = companion_order.zeros();
            for j in 0..order {
                companion[(0, j)] = -q[j];
                if j + 1 < order {
                    companion[(j + 1, j)] = 1.0;
                }
            }
            balanced_hessenberg(companion).and_then(|(mut companion, scale)| {
                francis_qr(&mut companion, None, (0, order - 1), false, Spectrum::General)
                    .map(|()| block_eigenvalues(order, |i, j| companion[(i, j)] * scale))
            })
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
