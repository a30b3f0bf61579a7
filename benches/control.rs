//! Criterion benches of controllability and pole placement, the kernels behind
//! `is_controllable`, `place_bass_gura` and `place` (`benches/compare_peers.py` times them
//! against python-control and scipy).
//!
//! Verdicts: a seeded random 64-state single-input system, staircase alone and with the modal
//! test. Placement: the chapter's 747 Dutch-roll damper by Bass–Gura and Ackermann (n = 4, the
//! rudder), and Kautsky–Nichols–Van Dooren on the 747 with both inputs and on a seeded random
//! 16-state, 2-input plant.

use aerocontrol::control::controllability::{controllability, controllability_staircase};
use aerocontrol::control::placement::{place, place_ackermann, place_bass_gura};
use criterion::{Criterion, criterion_group, criterion_main};
use faer::{Mat, c64, mat};
use std::hint::black_box;

mod common;
use common::seeded_matrix;

/// The 747 lateral plant (6.150) with rudder and aileron (6.158), (6.163).
fn boeing747_lateral() -> (Mat<f64>, Mat<f64>) {
    (
        mat![
            [-0.0999, 0.0, 0.1153, -1.0],
            [-1.6038, -1.0932, 0.0, 0.2850],
            [0.0, 1.0, 0.0, 0.0],
            [0.4089, -0.0395, 0.0, -0.2454],
        ],
        mat![
            [0.0182, 0.0],
            [0.0868, 0.3215],
            [0.0, 0.0],
            [-0.2440, -0.0017]
        ],
    )
}

/// (6.156): Dutch roll at ζ = 0.30 and its ω_n, spiral and roll kept.
fn dutch_roll_poles() -> Vec<c64> {
    let root = c64::new(-0.224302672, 0.713237036);
    vec![
        c64::new(-0.046425394, 0.0),
        root,
        root.conj(),
        c64::new(-1.230789, 0.0),
    ]
}

fn verdicts(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let (a, b) = (seeded_matrix(64, 64, 1), seeded_matrix(64, 1, 2));
    c.bench_function("staircase verdict n=64 m=1", |bench| {
        bench.iter(|| controllability_staircase(black_box(a.as_ref()), b.as_ref(), None, false))
    });
    c.bench_function("staircase + modal verdict n=64 m=1", |bench| {
        bench.iter(|| controllability(black_box(a.as_ref()), b.as_ref(), None, true, false))
    });
}

fn placement(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let (a, b) = boeing747_lateral();
    let rudder = b.subcols(0, 1).to_owned();
    let poles = dutch_roll_poles();
    c.bench_function("place_bass_gura 747 rudder", |bench| {
        bench.iter(|| place_bass_gura(black_box(a.as_ref()), rudder.as_ref(), &poles))
    });
    c.bench_function("place_ackermann 747 rudder", |bench| {
        bench.iter(|| place_ackermann(black_box(a.as_ref()), rudder.as_ref(), &poles))
    });
    c.bench_function("place KNV0 747 rudder+aileron", |bench| {
        bench.iter(|| place(black_box(a.as_ref()), b.as_ref(), &poles))
    });
    let (a, b) = (seeded_matrix(16, 16, 3), seeded_matrix(16, 2, 4));
    let poles: Vec<c64> = (0..16)
        .map(|k| c64::new(-0.5 - 0.2 * k as f64, 0.0))
        .collect();
    c.bench_function("place KNV0 n=16 m=2", |bench| {
        bench.iter(|| place(black_box(a.as_ref()), b.as_ref(), &poles))
    });
}

criterion_group!(benches, verdicts, placement);
criterion_main!(benches);
