//! Criterion benches of time and frequency responses, the kernels behind `step_response`,
//! `forced_response` and `bode` (`benches/compare_peers.py` times them against scipy and
//! python-control).
//!
//! Time responses: the 747 longitudinal model (C = I, D = 0) under a constant unit input with a
//! zero-order hold, on 5001 and 50001 samples of [0, 500] s, written into buffers allocated once.
//! Frequency responses: 1000 log-spaced frequencies for the 747 (n = 4, 4 outputs, 1 input) and
//! a seeded random stable model (n = 64, 2 inputs, 2 outputs).

use aerocontrol::control::discretize::Hold;
use aerocontrol::control::frequency::frequency_response_into;
use aerocontrol::control::modal::eigen;
use aerocontrol::control::responses::{Input, Model, simulate_into};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::{Mat, MatRef, c64, mat};
use std::hint::black_box;

mod common;
use common::seeded_matrix;

/// The 747 in powered approach: longitudinal A and elevator B (chapter (6.49)).
fn boeing747_longitudinal() -> (Mat<f64>, Mat<f64>) {
    (
        mat![
            [-0.0212, 0.0466, 0.0000, -0.1153],
            [-0.2229, -0.5839, 0.9404, 0.0000],
            [0.0150, -0.5031, -0.5015, 0.0000],
            [0.0, 0.0, 1.0, 0.0]
        ],
        mat![[0.0000], [-0.0340], [-0.5746], [0.0000]],
    )
}

/// A random model (A, B, C, D) with A shifted so that its rightmost eigenvalue has real part
/// -0.1, as `compare_peers.py` builds its n = 64 case (with other random numbers).
fn stable_model(n: usize, m: usize, p: usize, seed: u64) -> [Mat<f64>; 4] {
    let mut a = seeded_matrix(n, n, seed);
    let (eigenvalues, _) = eigen(a.as_ref()).unwrap();
    let shift = eigenvalues.iter().map(|l| l.re).fold(f64::MIN, f64::max) + 0.1;
    for i in 0..n {
        a[(i, i)] -= shift;
    }
    [
        a,
        seeded_matrix(n, m, seed + 1),
        seeded_matrix(p, n, seed + 2),
        Mat::zeros(p, m),
    ]
}

/// `count` frequencies from 10^low to 10^high, log-spaced.
fn logspace(low: f64, high: f64, count: usize) -> Vec<f64> {
    (0..count)
        .map(|k| 10f64.powf(low + (high - low) * k as f64 / (count - 1) as f64))
        .collect()
}

fn bench_step_response(c: &mut Criterion) {
    let mut group = c.benchmark_group("step_response_747_zoh");
    let (a, b) = boeing747_longitudinal();
    let (cc, d) = (Mat::<f64>::identity(4, 4), Mat::<f64>::zeros(4, 1));
    let model = Model {
        a: a.as_ref(),
        b: b.as_ref(),
        c: cc.as_ref(),
        d: d.as_ref(),
    };
    for steps in [5001usize, 50001] {
        let dt = 500.0 / (steps - 1) as f64;
        let (mut x, mut y) = (vec![0.0; steps * 4], vec![0.0; steps * 4]);
        group.bench_function(BenchmarkId::from_parameter(steps), |bench| {
            bench.iter(|| {
                simulate_into(
                    black_box(model),
                    MatRef::from_row_major_slice(&[0.0; 4], 1, 4),
                    Input::Constant(&[1.0]),
                    dt,
                    steps,
                    Hold::Zero,
                    &mut x,
                    &mut y,
                )
                .unwrap()
            })
        });
    }
    group.finish();
}

fn bench_frequency_response(c: &mut Criterion) {
    let mut group = c.benchmark_group("frequency_response_1000");
    let (a, b) = boeing747_longitudinal();
    let lon747 = [a, b, Mat::identity(4, 4), Mat::zeros(4, 1)];
    let cases = [
        ("4", lon747, logspace(-3.0, 1.0, 1000)),
        ("64", stable_model(64, 2, 2, 64), logspace(-2.0, 2.0, 1000)),
    ];
    for (name, [a, b, cc, d], omega) in &cases {
        let mut out = vec![c64::new(0.0, 0.0); omega.len() * cc.nrows() * b.ncols()];
        group.bench_function(BenchmarkId::from_parameter(name), |bench| {
            bench.iter(|| {
                frequency_response_into(
                    black_box(a.as_ref()),
                    b.as_ref(),
                    cc.as_ref(),
                    d.as_ref(),
                    black_box(omega),
                    &mut out,
                )
                .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_step_response, bench_frequency_response);
criterion_main!(benches);
