//! Criterion benches of the analysis kernels that `benches/compare_peers.py` times against
//! numpy, scipy and python-control: modal analysis and the characteristic polynomial, the
//! controllability and observability matrices and the staircase verdict, the companion form,
//! the steady state of a step, and the Riccati differential equation. Seeded random matrices
//! at n = 4, 16, 64 and 256 (the companion form and the Riccati ODE stop where their peers do:
//! 16 and 64), the crossovers and peaks of a SISO loop (loop_margins) at n = 4, 8 and 16, and
//! its root locus over 1000 gains (root_locus) at n = 4, 8 and 16, and the transfer functions
//! of every channel of two-input, two-output models (transfer_channels) at n = 4, 8 and 16.

use aerocontrol::control::controllability::{controllability_staircase, ctrb, obsv_transposed};
use aerocontrol::control::margins::loop_margins;
use aerocontrol::control::modal::modal_analysis;
use aerocontrol::control::placement::companion_form;
use aerocontrol::control::responses::steady_state;
use aerocontrol::control::riccati::ode::riccati_ode;
use aerocontrol::control::root_locus::root_locus;
use aerocontrol::control::transfer::transfer_channels;
use aerocontrol::linalg::charpoly::charpoly;
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::Mat;
use std::hint::black_box;

mod common;
use common::seeded_matrix;

/// G - 2 sqrt(n) I: a stable random matrix (no eigenvalue near zero, for the steady state).
fn stable(n: usize, seed: u64) -> Mat<f64> {
    let g = seeded_matrix(n, n, seed);
    Mat::from_fn(n, n, |i, j| {
        g[(i, j)] - if i == j { 2.0 * (n as f64).sqrt() } else { 0.0 }
    })
}

fn spectra(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("analysis");
    group.sample_size(10);
    for n in [4, 16, 64, 256] {
        let (a, b) = (stable(n, n as u64), seeded_matrix(n, 2, 3));
        let c_out = seeded_matrix(2, n, 4);
        group.bench_with_input(BenchmarkId::new("modal_analysis", n), &a, |bench, a| {
            bench.iter(|| modal_analysis(black_box(a.as_ref()), Some(b.as_ref())))
        });
        group.bench_with_input(BenchmarkId::new("charpoly", n), &a, |bench, a| {
            bench.iter(|| charpoly(black_box(a.as_ref())))
        });
        group.bench_with_input(BenchmarkId::new("ctrb", n), &a, |bench, a| {
            bench.iter(|| ctrb(black_box(a.as_ref()), b.as_ref()))
        });
        group.bench_with_input(BenchmarkId::new("obsv", n), &a, |bench, a| {
            bench.iter(|| obsv_transposed(black_box(a.as_ref()), c_out.as_ref()))
        });
        group.bench_with_input(BenchmarkId::new("staircase verdict", n), &a, |bench, a| {
            bench.iter(|| controllability_staircase(black_box(a.as_ref()), b.as_ref(), None, false))
        });
        let eta0 = faer::mat![[1.0], [0.5]];
        group.bench_with_input(BenchmarkId::new("steady_state", n), &a, |bench, a| {
            bench.iter(|| steady_state(black_box(a.as_ref()), b.as_ref(), eta0.as_ref()))
        });
        if n <= 16 {
            let b1 = seeded_matrix(n, 1, 5);
            group.bench_with_input(BenchmarkId::new("companion_form", n), &a, |bench, a| {
                bench.iter(|| companion_form(black_box(a.as_ref()), b1.as_ref()))
            });
        }
        if n <= 64 {
            let (q, r) = (Mat::<f64>::identity(n, n), Mat::<f64>::identity(2, 2));
            let times: Vec<f64> = (0..101).map(|k| 0.1 * k as f64).collect();
            group.bench_with_input(
                BenchmarkId::new("riccati_ode 101 times", n),
                &a,
                |bench, a| {
                    bench.iter(|| {
                        riccati_ode(
                            black_box(a.as_ref()),
                            b.as_ref(),
                            q.as_ref(),
                            r.as_ref(),
                            &times,
                            None,
                        )
                    })
                },
            );
        }
    }
    group.finish();
}

/// The crossovers and peaks of a SISO loop (control/margins.rs): seeded random stable loops of
/// the orders of flight-control loops (4 and 8) and beyond (16), D = 0.
fn margins(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("analysis");
    group.sample_size(20);
    for n in [4, 8, 16] {
        let a = stable(n, 10 + n as u64);
        let (b, c_out) = (seeded_matrix(n, 1, 11), seeded_matrix(1, n, 12));
        // A loop gain that puts the crossovers among the poles.
        let c_out = Mat::from_fn(1, n, |_, j| 4.0 * (n as f64).sqrt() * c_out[(0, j)]);
        let d = Mat::<f64>::zeros(1, 1);
        group.bench_with_input(BenchmarkId::new("loop_margins", n), &a, |bench, a| {
            bench.iter(|| {
                loop_margins(
                    black_box(a.as_ref()),
                    b.as_ref(),
                    c_out.as_ref(),
                    d.as_ref(),
                )
            })
        });
    }
    group.finish();
}

/// The closed-loop poles of the same loops over 1000 gains in [0, 5] (control/root_locus.rs).
fn locus(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("analysis");
    group.sample_size(20);
    let gains: Vec<f64> = (0..1000).map(|i| 5.0 * i as f64 / 999.0).collect();
    for n in [4, 8, 16] {
        let a = stable(n, 10 + n as u64);
        let (b, c_out) = (seeded_matrix(n, 1, 11), seeded_matrix(1, n, 12));
        let mut out = vec![faer::c64::new(0.0, 0.0); gains.len() * n];
        group.bench_with_input(BenchmarkId::new("root_locus", n), &a, |bench, a| {
            bench.iter(|| {
                root_locus(
                    black_box(a.as_ref()),
                    b.as_ref(),
                    c_out.as_ref(),
                    &gains,
                    &mut out,
                )
            })
        });
    }
    group.finish();
}

/// Every channel's transfer function of the same models with two inputs and two outputs
/// (control/transfer.rs), D = 0.
fn transfer(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("analysis");
    group.sample_size(20);
    let channels = [(0, 0), (0, 1), (1, 0), (1, 1)];
    for n in [4, 8, 16] {
        let a = stable(n, 10 + n as u64);
        let (b, c_out) = (seeded_matrix(n, 2, 11), seeded_matrix(2, n, 12));
        let d = Mat::<f64>::zeros(2, 2);
        group.bench_with_input(BenchmarkId::new("transfer_channels", n), &a, |bench, a| {
            bench.iter(|| {
                transfer_channels(
                    black_box(a.as_ref()),
                    b.as_ref(),
                    c_out.as_ref(),
                    d.as_ref(),
                    0.0,
                    &channels,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, spectra, margins, locus, transfer);
criterion_main!(benches);
