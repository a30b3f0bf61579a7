//! Criterion benches of the matrix exponential and its relatives, over a ladder of sizes.
//!
//! Inputs are seeded random matrices scaled to 1-norm about 2 (degree 13 with a few squarings,
//! the common case), the same family that `benches/compare_peers.py` uses against scipy.

use aerocontrol::control::batch::{MatrixStack, expm_batch};
use aerocontrol::control::discretize::{Hold, discretize};
use aerocontrol::linalg::expm::{expm, transition_matrices};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use std::hint::black_box;

mod common;
use common::seeded_matrix;

/// [`seeded_matrix`] scaled to 1-norm `norm`.
fn seeded_matrix_with_norm(rows: usize, cols: usize, seed: u64, norm: f64) -> Mat<f64> {
    let m = seeded_matrix(rows, cols, seed);
    let current = (0..cols)
        .map(|j| (0..rows).map(|i| m[(i, j)].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    &m * faer::Scale(norm / current)
}

fn bench_expm(c: &mut Criterion) {
    let mut group = c.benchmark_group("expm");
    for n in [4usize, 8, 16, 64, 256, 1024] {
        let a = seeded_matrix_with_norm(n, n, n as u64, 2.0);
        if n >= 256 {
            group.sample_size(10);
        }
        group.bench_with_input(BenchmarkId::from_parameter(n), &a, |b, a| {
            b.iter(|| expm(black_box(a.as_ref())).unwrap())
        });
    }
    group.finish();
}

fn bench_transition_matrices(c: &mut Criterion) {
    let mut group = c.benchmark_group("transition_matrices_100_times");
    for n in [4usize, 16, 64] {
        let a = seeded_matrix_with_norm(n, n, 3 + n as u64, 2.0);
        let times: Vec<f64> = (0..100).map(|k| 0.05 * k as f64).collect();
        group.bench_with_input(BenchmarkId::from_parameter(n), &a, |b, a| {
            b.iter(|| transition_matrices(black_box(a.as_ref()), black_box(&times)).unwrap())
        });
    }
    group.finish();
}

fn bench_discretize(c: &mut Criterion) {
    let mut group = c.benchmark_group("discretize_foh");
    for n in [4usize, 16, 64] {
        let a = seeded_matrix_with_norm(n, n, 7 + n as u64, 2.0);
        let b = seeded_matrix_with_norm(n, 2, 11 + n as u64, 1.0);
        group.bench_with_input(BenchmarkId::from_parameter(n), &(a, b), |bench, (a, b)| {
            bench.iter(|| discretize(a.as_ref(), b.as_ref(), 0.01, Hold::First).unwrap())
        });
    }
    group.finish();
}

fn bench_batch(c: &mut Criterion) {
    let mut group = c.benchmark_group("expm_batch_10000");
    group.sample_size(10);
    let (k, n) = (10_000usize, 4usize);
    let mut data = Vec::with_capacity(k * n * n);
    for index in 0..k {
        let m = seeded_matrix_with_norm(n, n, index as u64, 2.0);
        for i in 0..n {
            for j in 0..n {
                data.push(m[(i, j)]);
            }
        }
    }
    let mut out = vec![0.0; k * n * n];
    group.bench_function("4x4", |b| {
        b.iter(|| {
            expm_batch(
                MatrixStack::new(black_box(&data), k, n, n).unwrap(),
                &mut out,
            )
            .unwrap()
        })
    });
    group.finish();
}

criterion_group!(
    benches,
    bench_expm,
    bench_transition_matrices,
    bench_discretize,
    bench_batch
);
criterion_main!(benches);
