//! Deterministic pseudo-random matrices for the unit tests.

use faer::Mat;

/// A rows x cols matrix with entries in [-1, 1) from a xorshift generator seeded by `seed`.
pub(crate) fn seeded(rows: usize, cols: usize, seed: u64) -> Mat<f64> {
    let mut state = seed.wrapping_mul(0x9E3779B97F4A7C15) | 1;
    Mat::from_fn(rows, cols, |_, _| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    })
}

/// A square [`seeded`] matrix.
pub(crate) fn seeded_square(n: usize, seed: u64) -> Mat<f64> {
    seeded(n, n, seed)
}
