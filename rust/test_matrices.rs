//! Deterministic pseudo-random matrices for the unit tests.

use faer::{Mat, c64};

/// Values in [-1, 1) from Marsaglia's xorshift generator (shifts 13, 7, 17) started at
/// `state` (nonzero).
pub(crate) fn xorshift(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// A rows x cols matrix with entries in [-1, 1) from a xorshift generator seeded by `seed`.
pub(crate) fn seeded(rows: usize, cols: usize, seed: u64) -> Mat<f64> {
    let mut next = xorshift(seed.wrapping_mul(0x9E3779B97F4A7C15) | 1);
    Mat::from_fn(rows, cols, |_, _| next())
}

/// A square [`seeded`] matrix.
pub(crate) fn seeded_square(n: usize, seed: u64) -> Mat<f64> {
    seeded(n, n, seed)
}

/// The chapter's 747 lateral model (6.150): state [β, p, φ, r].
pub(crate) fn lateral_747() -> Mat<f64> {
    faer::mat![
        [-0.0999, 0.0, 0.1153, -1.0],
        [-1.6038, -1.0932, 0.0, 0.2850],
        [0.0, 1.0, 0.0, 0.0],
        [0.4089, -0.0395, 0.0, -0.2454],
    ]
}

/// Its input matrix (6.224): columns rudder and aileron.
pub(crate) fn lateral_747_inputs() -> Mat<f64> {
    faer::mat![
        [0.0182, 0.0],
        [0.0868, 0.3215],
        [0.0, 0.0],
        [-0.2440, -0.0017],
    ]
}

/// Each value of `expected` with its partner in `found`, nearest first, each found value
/// partnered once (the same count).
pub(crate) fn nearest_partners(found: &[c64], expected: &[c64]) -> Vec<(c64, c64)> {
    assert_eq!(
        found.len(),
        expected.len(),
        "{found:?} against {expected:?}"
    );
    let mut unused: Vec<c64> = found.to_vec();
    expected
        .iter()
        .map(|y| {
            let (k, _) = unused
                .iter()
                .map(|x| (x - y).norm())
                .enumerate()
                .min_by(|p, q| p.1.total_cmp(&q.1))
                .expect("as many found as expected");
            (*y, unused.swap_remove(k))
        })
        .collect()
}
