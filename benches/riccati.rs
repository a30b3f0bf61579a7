//! Criterion benches of the optimal-control kernels: the real Schur form and its reordering,
//! the Lyapunov solver and the CARE (`benches/compare_peers.py` times them against scipy and
//! python-control). Seeded random matrices at n = 4, 16, 64 and 256; the CARE also on the
//! chapter's 747 lateral regulator (6.224)-(6.227) with Q = I, R = I.

use aerocontrol::control::riccati::care::{CareOptions, solve_care};
use aerocontrol::linalg::lyapunov::solve_lyapunov;
use aerocontrol::linalg::schur::real_schur;
use aerocontrol::linalg::schur::reorder::reorder_schur;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use std::hint::black_box;

mod common;
use common::seeded_matrix;

/// G / sqrt(n) - 3/2 I: a stable matrix with a spectrum in a disc of radius about 1.
fn stable(n: usize, seed: u64) -> Mat<f64> {
    let g = seeded_matrix(n, n, seed);
    Mat::from_fn(n, n, |i, j| {
        g[(i, j)] / (n as f64).sqrt() - if i == j { 1.5 } else { 0.0 }
    })
}

fn schur_and_lyapunov(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("schur");
    group.sample_size(10);
    for n in [4, 16, 64, 256] {
        let a = seeded_matrix(n, n, n as u64);
        group.bench_with_input(BenchmarkId::new("real_schur", n), &a, |bench, a| {
            bench.iter(|| real_schur(black_box(a.as_ref())))
        });
        group.bench_with_input(
            BenchmarkId::new("schur + reorder lhp", n),
            &a,
            |bench, a| {
                bench.iter(|| {
                    reorder_schur(real_schur(black_box(a.as_ref())).unwrap(), |z| z.re < 0.0)
                })
            },
        );
        let (s, q) = (stable(n, 7), Mat::<f64>::identity(n, n));
        group.bench_with_input(BenchmarkId::new("solve_lyapunov", n), &s, |bench, s| {
            bench.iter(|| solve_lyapunov(black_box(s.as_ref()), q.as_ref()))
        });
    }
    group.finish();
}

fn care(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("care");
    group.sample_size(10);
    let options = CareOptions {
        refine: true,
        ..Default::default()
    };
    let lateral = faer::mat![
        [-0.0999, 0.0, 0.1153, -1.0],
        [-1.6038, -1.0932, 0.0, 0.285],
        [0.0, 1.0, 0.0, 0.0],
        [0.4089, -0.0395, 0.0, -0.2454]
    ];
    let rudder_aileron = faer::mat![
        [0.0182, 0.0],
        [0.0868, 0.3215],
        [0.0, 0.0],
        [-0.244, -0.0017]
    ];
    let (q, r) = (Mat::<f64>::identity(4, 4), Mat::<f64>::identity(2, 2));
    group.bench_function("solve_care 747 lateral", |bench| {
        bench.iter(|| {
            solve_care(
                black_box(lateral.as_ref()),
                rudder_aileron.as_ref(),
                q.as_ref(),
                r.as_ref(),
                options,
            )
        })
    });
    for n in [4, 16, 64, 256] {
        let (a, b) = (stable(n, 11), seeded_matrix(n, 2, 12));
        let (q, r) = (Mat::<f64>::identity(n, n), Mat::<f64>::identity(2, 2));
        group.bench_with_input(BenchmarkId::new("solve_care m=2", n), &n, |bench, _| {
            bench.iter(|| {
                solve_care(
                    black_box(a.as_ref()),
                    b.as_ref(),
                    q.as_ref(),
                    r.as_ref(),
                    options,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, schur_and_lyapunov, care);
criterion_main!(benches);
