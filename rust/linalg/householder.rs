//! Householder reflectors, the elementary orthogonal transformations of the Hessenberg
//! reduction, the QR iteration and Schur reordering.

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
