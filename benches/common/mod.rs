//! What the criterion benches share: deterministic inputs.

use faer::Mat;

/// A deterministic pseudo-random matrix with entries in [-1, 1) (a linear congruential
/// generator, so every run and every machine times the same inputs).
pub fn seeded_matrix(rows: usize, cols: usize, seed: u64) -> Mat<f64> {
    let mut state = seed;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    Mat::from_fn(rows, cols, |_, _| next())
}
