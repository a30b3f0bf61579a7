//! Householder reflectors, the elementary orthogonal transformations of the Hessenberg
//! reduction, the QR iteration and Schur reordering.

/// The Householder reflector I - τ [1; v][1; v]^T that maps x to β e1: returns (β, τ) and
/// leaves v in x[1..]. τ = 0 (the identity) when x[1..] is zero. Norms are formed from plain
/// sums of squares in the normal range and rescaled otherwise, so entries of any magnitude
/// are annihilated.
#[inline(always)]
pub(crate) fn reflector(x: &mut [f64]) -> (f64, f64) {
    let alpha = x[0];
    // The identity only when the tail is exactly zero: squares of entries below 1e-162
    // underflow to zero, and such entries must still be annihilated.
    if x[1..].iter().all(|v| *v == 0.0) {
        return (alpha, 0.0);
    }
    // A NaN or infinite entry has no reflector (and max would skip a NaN): the identity, and
    // the caller's own checks see the non-finite entry.
    if !x.iter().all(|v| v.is_finite()) {
        return (alpha, 0.0);
    }
    let largest = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(RANGE_LOW..=RANGE_HIGH).contains(&largest) {
        return scaled_reflector(x, largest);
    }
    // Entries within 2^±500: the sum of squares neither overflows nor loses more than rounding
    // to underflow.
    let tail_squares: f64 = x[1..].iter().map(|v| v * v).sum();
    let norm = (alpha * alpha + tail_squares).sqrt();
    let beta = -alpha.signum() * norm;
    let tau = (beta - alpha) / beta;
    let scale = 1.0 / (alpha - beta);
    for v in &mut x[1..] {
        *v *= scale;
    }
    (beta, tau)
}

/// [`reflector`] for an x whose largest entry is outside 2^±500. The reflector depends only on
/// the direction of x: it is computed for x times a power of two (exact; 2^±1000 at most, so
/// that one step brings any finite x into range) and β scaled back. Kept out of line, so that
/// [`reflector`] itself (not recursive) inlines into the sweeps.
#[cold]
#[inline(never)]
fn scaled_reflector(x: &mut [f64], largest: f64) -> (f64, f64) {
    let exponent = (-largest.log2().round()).clamp(-1000.0, 1000.0) as i32;
    let (up, down) = (2f64.powi(exponent), 2f64.powi(-exponent));
    for v in x.iter_mut() {
        *v *= up;
    }
    let (beta, tau) = reflector(x);
    (beta * down, tau)
}

/// The range of the largest entry in which [`reflector`] forms the norm without scaling.
const RANGE_LOW: f64 = 3.054936363499605e-151; // 2^-500
const RANGE_HIGH: f64 = 3.273390607896142e150; // 2^500

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_vectors_give_the_identity() {
        for x in [
            [f64::NAN, 1e-320, 0.0],
            [0.0, f64::NAN, 0.0],
            [1.0, f64::INFINITY, 1.0],
        ] {
            let mut y = x;
            assert_eq!(reflector(&mut y).1, 0.0);
        }
    }

    #[test]
    fn tiny_and_huge_tails_are_annihilated() {
        for (head, tail) in [
            (1.0, 2e-162),
            (0.0, 3e-320),
            (1e200, 1e200),
            (1e-300, 1e-310),
        ] {
            let mut x = [head, tail, -tail];
            let (beta, tau) = reflector(&mut x);
            assert!(tau > 0.0, "{head} {tail}");
            // H x = x - τ w w^T x with w = [1; v]: the tail of H x is zero to rounding.
            let w = [1.0, x[1], x[2]];
            let original = [head, tail, -tail];
            let dot: f64 = w.iter().zip(original).map(|(a, b)| a * b).sum();
            for k in 1..3 {
                let image = original[k] - tau * dot * w[k];
                // (Subnormal arithmetic resolves only multiples of 5e-324.)
                assert!(
                    image.abs() <= (1e-15 * beta.abs()).max(5e-323),
                    "{head} {tail}: {image}"
                );
            }
        }
    }
}
