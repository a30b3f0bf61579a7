//! Criterion benches of the batch kernels (issue 7): the chapter's 747 lateral regulator
//! (6.224)-(6.227) swept over 1,000 and 10,000 weights c (R = I / c^2) in one `care_batch`
//! call, and 1,000 Dutch-roll dampers (6.156) by Bass-Gura and by KNV in one `place_batch`
//! call. Rayon uses every core; `RAYON_NUM_THREADS=1 cargo bench --bench batch` gives the
//! one-core time, and the ratio the parallel speed-up.

use aerocontrol::control::batch::{
    CareBatchOutput, CareStacks, MatrixStack, PlaceBatchOutput, care_batch, place_batch,
};
use aerocontrol::control::placement::{place, place_bass_gura};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use faer::c64;
use std::hint::black_box;

/// The 747 lateral plant (6.150) and B = [rudder, aileron] (6.158), (6.163), row-major.
const A: [f64; 16] = [
    -0.0999, 0.0, 0.1153, -1.0, -1.6038, -1.0932, 0.0, 0.2850, 0.0, 1.0, 0.0, 0.0, 0.4089, -0.0395,
    0.0, -0.2454,
];
const B: [f64; 8] = [0.0182, 0.0, 0.0868, 0.3215, 0.0, 0.0, -0.2440, -0.0017];
const IDENTITY: [f64; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];

fn weights(count: usize) -> Vec<f64> {
    (0..count)
        .flat_map(|k| {
            // c log-spaced over 1e-3 .. 10.
            let c = 10f64.powf(-3.0 + 4.0 * k as f64 / (count - 1) as f64);
            [1.0 / (c * c), 0.0, 0.0, 1.0 / (c * c)]
        })
        .collect()
}

fn lqr_sweep(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("care_batch 747 lateral");
    group.sample_size(10);
    for count in [1_000, 10_000] {
        let r = weights(count);
        let stacks = CareStacks {
            a: MatrixStack::new(&A, 1, 4, 4).unwrap(),
            b: MatrixStack::new(&B, 1, 4, 2).unwrap(),
            q: MatrixStack::new(&IDENTITY, 1, 4, 4).unwrap(),
            r: MatrixStack::new(&r, count, 2, 2).unwrap(),
        };
        let mut x = vec![0.0; count * 16];
        let mut gain = vec![0.0; count * 8];
        let mut poles = vec![c64::new(0.0, 0.0); count * 4];
        let (mut residual, mut rcond) = (vec![0.0; count], vec![0.0; count]);
        group.bench_function(BenchmarkId::new("weights", count), |bench| {
            bench.iter(|| {
                let out = CareBatchOutput {
                    x: &mut x,
                    gain: &mut gain,
                    poles: &mut poles,
                    residual: &mut residual,
                    rcond: &mut rcond,
                };
                care_batch(black_box(stacks), true, out).unwrap()
            })
        });
    }
    group.finish();
}

fn dampers(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("place_batch 747 dampers");
    group.sample_size(10);
    let count = 1_000;
    let omega = 0.7477;
    let poles: Vec<c64> = (0..count)
        .flat_map(|k| {
            let zeta = 0.15 + 0.45 * k as f64 / count as f64;
            let (re, im) = (-zeta * omega, omega * (1.0 - zeta * zeta).sqrt());
            [
                c64::new(re, im),
                c64::new(re, -im),
                c64::new(-1.2308, 0.0),
                c64::new(-0.04641, 0.0),
            ]
        })
        .collect();
    let rudder: Vec<f64> = B.chunks(2).map(|row| row[0]).collect();
    let a = MatrixStack::new(&A, 1, 4, 4).unwrap();
    for (name, b, m, placer) in [
        (
            "bass-gura rudder",
            &rudder[..],
            1,
            place_bass_gura as aerocontrol::control::batch::Placer,
        ),
        ("knv rudder + aileron", &B[..], 2, place),
    ] {
        let b = MatrixStack::new(b, 1, 4, m).unwrap();
        let mut gain = vec![0.0; count * m * 4];
        let mut achieved = vec![c64::new(0.0, 0.0); count * 4];
        let (mut error, mut condition) = (vec![0.0; count], vec![0.0; count]);
        group.bench_function(BenchmarkId::new(name, count), |bench| {
            bench.iter(|| {
                let out = PlaceBatchOutput {
                    gain: &mut gain,
                    achieved: &mut achieved,
                    max_relative_error: &mut error,
                    condition: &mut condition,
                };
                place_batch(black_box(a), b, &poles, count, placer, out).unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, lqr_sweep, dampers);
criterion_main!(benches);
