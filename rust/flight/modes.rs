//! Which eigenvalues of a 4-state aircraft model belong to which classical mode, for a stack of
//! models at once (the Python package's `aircraft.naming.classify_mode_stack`; its
//! `classify_modes` names one model's modes from its eigenvectors, the same rules).
//!
//! Longitudinal: the two eigenvalues of largest magnitude are the short period, the two
//! smallest the phugoid, each a conjugate pair or two real roots; a model whose two smallest
//! are one real root and one member of a complex pair has no modes defined by magnitude
//! (unresolved).
//!
//! Lateral-directional: with one complex pair, the pair is the Dutch roll, the real root of
//! larger magnitude the roll mode and the smaller the spiral; with four real roots, the
//! largest is the roll mode, the smallest the spiral and the middle two the Dutch roll. With
//! two complex pairs (roll and spiral coupled into one oscillation) the model is unresolved by
//! eigenvalues alone; given its state matrix, the pair whose eigenvector has the larger
//! sideslip share |v_β| / ||v|| is the Dutch roll and the other the roll-spiral. The
//! eigenvector of a simple eigenvalue λ is the column of largest norm of adj(A - λI), whose
//! columns span the null space of A - λI (no factorisation, exact cofactors).
//!
//! A pair is ordered with its member of larger imaginary part first (Im > 0 of a conjugate
//! pair), keeping the given order on a tie; real roots of one mode are in increasing
//! magnitude. Modes that are not named in a model are NaN.

use super::Axis;
use super::{BLOCK, check_lengths};
use crate::error::Error;
use crate::platform::parallel::ParallelContext;
use faer::c64;
use rayon::prelude::*;

/// The named modes of one longitudinal model: phugoid and short-period pairs.
pub const LONGITUDINAL_SLOTS: usize = 4;
/// The named modes of one lateral model: spiral, the Dutch roll pair, roll, the roll-spiral
/// pair.
pub const LATERAL_SLOTS: usize = 6;

const NAN: c64 = c64 {
    re: f64::NAN,
    im: f64::NAN,
};

/// The eigenvalues in increasing magnitude (a stable sort: equal magnitudes keep their order).
fn by_size(values: &[c64; 4]) -> [c64; 4] {
    let mut sorted = *values;
    sorted.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    sorted
}

/// A pair with its member of larger imaginary part first.
fn ordered_pair(first: c64, second: c64) -> [c64; 2] {
    if first.im < second.im {
        [second, first]
    } else {
        [first, second]
    }
}

/// The longitudinal modes of one model into `out` (phugoid pair, short-period pair); whether
/// the model is unresolved (then `out` is NaN).
pub fn longitudinal(values: &[c64; 4], out: &mut [c64]) -> bool {
    let s = by_size(values);
    let complex = s.iter().filter(|v| v.im != 0.0).count();
    let unresolved = complex == 2 && ((s[0].im == 0.0) != (s[1].im == 0.0));
    if unresolved {
        out.fill(NAN);
    } else {
        out[..2].copy_from_slice(&ordered_pair(s[0], s[1]));
        out[2..].copy_from_slice(&ordered_pair(s[2], s[3]));
    }
    unresolved
}

/// The lateral modes of one model into `out` (spiral, Dutch roll pair, roll, roll-spiral
/// pair); whether the model is unresolved by its eigenvalues (two complex pairs). With `a` (its
/// state matrix, row-major), such a model's Dutch roll and roll-spiral are told apart by their
/// eigenvectors' sideslip share, and its roll and spiral stay NaN.
pub fn lateral(values: &[c64; 4], a: Option<&[f64]>, out: &mut [c64]) -> bool {
    out.fill(NAN);
    let s = by_size(values);
    let complex = s.iter().filter(|v| v.im != 0.0).count();
    if complex == 4 {
        if let Some(a) = a {
            // The two members with Im > 0, in the order of the eigenvalues given.
            let mut upper = values.iter().filter(|v| v.im > 0.0).copied();
            if let (Some(first), Some(second)) = (upper.next(), upper.next()) {
                let (dutch, other) = if sideslip_share(a, first) >= sideslip_share(a, second) {
                    (first, second)
                } else {
                    (second, first)
                };
                out[1..3].copy_from_slice(&[dutch, dutch.conj()]);
                out[4..6].copy_from_slice(&[other, other.conj()]);
            }
        }
        return true;
    }
    // The real roots first, each group in increasing magnitude: with one pair (spiral, roll,
    // pair), with four real roots (spiral, two of the Dutch roll, roll).
    let mut ordered = [NAN; 4];
    let reals = s.iter().filter(|v| v.im == 0.0);
    let complexes = s.iter().filter(|v| v.im != 0.0);
    for (slot, value) in ordered.iter_mut().zip(reals.chain(complexes)) {
        *slot = *value;
    }
    let (dutch, roll) = if complex == 2 {
        (ordered_pair(ordered[2], ordered[3]), ordered[1])
    } else {
        (ordered_pair(ordered[1], ordered[2]), ordered[3])
    };
    out[0] = ordered[0];
    out[1..3].copy_from_slice(&dutch);
    out[3] = roll;
    false
}

impl Axis {
    /// The named modes' slots of one model: [`LONGITUDINAL_SLOTS`] or [`LATERAL_SLOTS`].
    pub fn mode_slots(self) -> usize {
        match self {
            Axis::Longitudinal => LONGITUDINAL_SLOTS,
            Axis::Lateral => LATERAL_SLOTS,
        }
    }
}

/// The modes of k models of `axis` from their eigenvalues (k x 4) and, for the lateral axis,
/// optionally their state matrices `a` (k x 4 x 4, row-major): into `out` (k x
/// [`Axis::mode_slots`]) and `unresolved` (k), in parallel over blocks of models. A NaN or
/// infinite eigenvalue or entry of A is an error naming the first.
pub fn classify_stack(
    axis: Axis,
    values: &[c64],
    a: Option<&[f64]>,
    out: &mut [c64],
    unresolved: &mut [bool],
) -> Result<(), Error> {
    let count = unresolved.len();
    let slots = axis.mode_slots();
    check_lengths(
        count,
        &[
            ("eigenvalues", values.len(), 4),
            ("A", a.map_or(16 * count, <[f64]>::len), 16),
            ("named", out.len(), slots),
        ],
    )?;
    // A NaN has no magnitude to order by: no mode is named from one (never a NaN mode of a
    // model called resolved), nor from a NaN sideslip share.
    if let Some(k) = values
        .iter()
        .position(|v| !(v.re.is_finite() && v.im.is_finite()))
    {
        let v = values[k];
        return Err(Error::NonFinite {
            arg: "eigenvalues",
            index: vec![k / 4, k % 4],
            value: if v.re.is_finite() { v.im } else { v.re },
        });
    }
    if let Some(a) = a
        && let Some(k) = a.iter().position(|v| !v.is_finite())
    {
        return Err(Error::NonFinite {
            arg: "A",
            index: vec![k / 16, k % 16 / 4, k % 4],
            value: a[k],
        });
    }
    let context = ParallelContext::capture(4);
    out.par_chunks_mut(BLOCK * slots)
        .zip(unresolved.par_chunks_mut(BLOCK))
        .enumerate()
        .try_for_each(|(block, (out, unresolved))| {
            context.run(|| {
                for (k, flag) in unresolved.iter_mut().enumerate() {
                    let index = block * BLOCK + k;
                    let row: [c64; 4] = std::array::from_fn(|j| values[4 * index + j]);
                    let slot = &mut out[k * slots..(k + 1) * slots];
                    *flag = match axis {
                        Axis::Longitudinal => longitudinal(&row, slot),
                        Axis::Lateral => {
                            lateral(&row, a.map(|a| &a[16 * index..16 * (index + 1)]), slot)
                        }
                    };
                }
                Ok(())
            })
        })
}

/// |v_β| / ||v|| of the eigenvector v of A (4 x 4, row-major) for its simple eigenvalue λ:
/// the column of largest norm of adj(A - λI).
///
/// A - λI is first scaled by 2^-e, with 2^e about its largest entry: the share is the same
/// for any scaling (the adjugate scales by its cube), the scaling is exact, so the share is
/// that of the unscaled cofactors wherever those neither overflow nor underflow, and a model
/// of entries about 1e100 or 1e-120 (whose cofactors would overflow to inf or underflow to
/// 0, and leave the two pairs' shares NaN or equal) is named as one of entries about 1.
fn sideslip_share(a: &[f64], lambda: c64) -> f64 {
    let largest = a
        .iter()
        .fold(lambda.re.abs().max(lambda.im.abs()), |m, v| m.max(v.abs()));
    let e = if largest > 0.0 && largest.is_finite() {
        libm::frexp(largest).1
    } else {
        0
    };
    let lambda = c64::new(libm::scalbn(lambda.re, -e), libm::scalbn(lambda.im, -e));
    let m = |i: usize, j: usize| {
        let diagonal = if i == j { lambda } else { c64::new(0.0, 0.0) };
        c64::new(libm::scalbn(a[4 * i + j], -e), 0.0) - diagonal
    };
    // The three indices of 0..4 other than `skip`.
    let others =
        |skip: usize| -> [usize; 3] { std::array::from_fn(|k| k + usize::from(k >= skip)) };
    let mut best = [c64::new(0.0, 0.0); 4];
    let mut best_norm = -1.0;
    for j in 0..4 {
        // Column j of adj(M): entry i is the cofactor C_ji = (-1)^(i+j) det of M without row j
        // and column i.
        let column: [c64; 4] = std::array::from_fn(|i| {
            let (rows, cols) = (others(j), others(i));
            let e = |r: usize, c: usize| m(rows[r], cols[c]);
            let det = e(0, 0) * (e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1))
                - e(0, 1) * (e(1, 0) * e(2, 2) - e(1, 2) * e(2, 0))
                + e(0, 2) * (e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0));
            if (i + j) % 2 == 0 { det } else { -det }
        });
        let norm = column.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
        if norm > best_norm {
            best = column;
            best_norm = norm;
        }
    }
    best[0].norm() / best_norm.max(f64::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> c64 {
        c64::new(re, im)
    }

    #[test]
    fn lateral_modes_by_magnitude() {
        // One pair: spiral -0.01, roll -1.2, Dutch roll -0.08 ± 0.74j.
        let values = [c(-0.08, -0.74), c(-1.2, 0.0), c(-0.01, 0.0), c(-0.08, 0.74)];
        let mut out = [NAN; LATERAL_SLOTS];
        assert!(!lateral(&values, None, &mut out));
        assert_eq!(out[0], c(-0.01, 0.0));
        assert_eq!(&out[1..3], &[c(-0.08, 0.74), c(-0.08, -0.74)]);
        assert_eq!(out[3], c(-1.2, 0.0));
        assert!(out[4].re.is_nan());
        // Four real roots: the middle two are the Dutch roll.
        let values = [c(-3.0, 0.0), c(-0.5, 0.0), c(-0.01, 0.0), c(-0.7, 0.0)];
        assert!(!lateral(&values, None, &mut out));
        assert_eq!(
            [out[0], out[1], out[2], out[3]],
            [c(-0.01, 0.0), c(-0.5, 0.0), c(-0.7, 0.0), c(-3.0, 0.0)]
        );
    }

    #[test]
    fn two_pairs_are_told_apart_by_sideslip() {
        // Block diagonal: β and r oscillate at -1 ± 2j, p and φ at -0.5 ± 0.5j.
        #[rustfmt::skip]
        let a = [
            -1.0, 0.0, 0.0, 2.0,
            0.0, -0.5, 0.5, 0.0,
            0.0, -0.5, -0.5, 0.0,
            -2.0, 0.0, 0.0, -1.0,
        ];
        let values = [c(-0.5, 0.5), c(-0.5, -0.5), c(-1.0, 2.0), c(-1.0, -2.0)];
        let mut out = [NAN; LATERAL_SLOTS];
        assert!(lateral(&values, Some(&a), &mut out));
        assert_eq!(&out[1..3], &[c(-1.0, 2.0), c(-1.0, -2.0)]);
        assert_eq!(&out[4..6], &[c(-0.5, 0.5), c(-0.5, -0.5)]);
        assert!(out[0].re.is_nan() && out[3].re.is_nan());
        assert!(lateral(&values, None, &mut out) && out[1].re.is_nan());
    }

    #[test]
    fn longitudinal_split_short_period_beside_a_pair_is_unresolved() {
        let mut out = [NAN; LONGITUDINAL_SLOTS];
        let values = [c(-0.01, 0.05), c(-0.01, -0.05), c(-1.0, 0.0), c(-4.0, 0.0)];
        assert!(!longitudinal(&values, &mut out));
        assert_eq!(&out[..2], &[c(-0.01, 0.05), c(-0.01, -0.05)]);
        assert_eq!(&out[2..], &[c(-1.0, 0.0), c(-4.0, 0.0)]);
        let values = [c(-0.02, 0.0), c(-0.03, 0.04), c(-0.03, -0.04), c(-4.0, 0.0)];
        assert!(longitudinal(&values, &mut out));
        assert!(out.iter().all(|v| v.re.is_nan()));
    }
}
