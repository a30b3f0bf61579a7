use super::*;
use crate::linalg::norm::frobenius_norm;
use faer::Mat;

/// A deterministic pseudo-random matrix (a linear congruential sequence).
fn random(n: usize, seed: u64) -> Mat<f64> {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    Mat::from_fn(n, n, |_, _| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    })
}

/// Checks the form's structure and backward error; returns the backward error in units of
/// u ||(A, B)||_F.
fn check_form(a: &Mat<f64>, b: &Mat<f64>, form: &GeneralizedSchur) -> f64 {
    let n = a.nrows();
    let scale = (frobenius_norm(a.as_ref()).powi(2) + frobenius_norm(b.as_ref()).powi(2)).sqrt();
    let ds = form.q.transpose() * a * &form.z - &form.s;
    let dt = form.q.transpose() * b * &form.z - &form.t;
    let backward = (frobenius_norm(ds.as_ref()).powi(2) + frobenius_norm(dt.as_ref()).powi(2))
        .sqrt()
        / (f64::EPSILON * scale.max(f64::MIN_POSITIVE));
    let identity = Mat::<f64>::identity(n, n);
    for m in [&form.q, &form.z] {
        let e = m.transpose() * m - &identity;
        assert!(frobenius_norm(e.as_ref()) < 10.0 * n as f64 * f64::EPSILON);
    }
    for j in 0..n {
        for i in j + 1..n {
            assert_eq!(form.t[(i, j)], 0.0, "T[{i},{j}]");
            if i > j + 1 {
                assert_eq!(form.s[(i, j)], 0.0, "S[{i},{j}]");
            }
        }
    }
    let mut k = 0;
    while k < n {
        if k + 1 < n && form.s[(k + 1, k)] != 0.0 {
            // A standard pair: T's block diagonal and positive, eigenvalues complex.
            assert_eq!(form.t[(k, k + 1)], 0.0);
            assert!(form.t[(k, k)] > 0.0 && form.t[(k + 1, k + 1)] > 0.0);
            assert!(
                k + 2 >= n || form.s[(k + 2, k + 1)] == 0.0,
                "adjacent pairs at {k}"
            );
            k += 2;
        } else {
            assert!(form.t[(k, k)] >= 0.0);
            k += 1;
        }
    }
    backward
}

#[test]
fn random_pencils_have_a_backward_stable_form() {
    for n in [1, 2, 3, 4, 5, 8, 16, 40, 64] {
        for seed in 0..4 {
            let a = random(n, seed);
            let b = random(n, seed + 100);
            let form = qz(a.as_ref(), b.as_ref()).unwrap();
            let backward = check_form(&a, &b, &form);
            assert!(backward < 10.0 * n as f64, "n = {n}: {backward} u");
        }
    }
}

#[test]
fn eigenvalues_of_a_diagonal_b_are_those_of_b_inverse_a() {
    // B = I: the eigenvalues of A; compare with the real Schur form's.
    let a = random(7, 3);
    let b = Mat::<f64>::identity(7, 7);
    let form = qz(a.as_ref(), b.as_ref()).unwrap();
    let mut ours: Vec<c64> = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref())
        .iter()
        .map(|e| e.value())
        .collect();
    let mut reference = crate::linalg::schur::eigenvalues(a.as_ref()).unwrap();
    let key = |z: &c64| (z.re * 1e6).round() as i64 * 1_000_000 + (z.im * 1e6).round() as i64;
    ours.sort_by_key(key);
    reference.sort_by_key(key);
    for (x, y) in ours.iter().zip(&reference) {
        assert!((x - y).norm() < 1e-12, "{x:?} {y:?}");
    }
}

#[test]
fn singular_b_gives_infinite_eigenvalues() {
    // B of rank 3 at n = 5: two infinite eigenvalues, three finite ones; the pencil
    // (A, B) = (I, diag(1, 2, 4, 0, 0)) permuted by random orthogonal-ish mixing.
    let n = 5;
    let mixing = random(n, 7) + Mat::<f64>::identity(n, n) * 3.0;
    let mixing2 = random(n, 8) + Mat::<f64>::identity(n, n) * 3.0;
    let d = Mat::from_fn(n, n, |i, j| {
        if i == j && i < 3 {
            [1.0, 2.0, 4.0][i]
        } else {
            0.0
        }
    });
    let a = &mixing * Mat::<f64>::identity(n, n) * &mixing2;
    let b = &mixing * &d * &mixing2;
    let form = qz(a.as_ref(), b.as_ref()).unwrap();
    assert!(check_form(&a, &b, &form) < 50.0);
    let values = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref());
    let scale = frobenius_norm(b.as_ref());
    let infinite = values.iter().filter(|e| e.beta <= 1e-12 * scale).count();
    assert_eq!(infinite, 2, "{values:?}");
    let mut finite: Vec<f64> = values
        .iter()
        .filter(|e| e.beta > 1e-12 * scale)
        .map(|e| e.value().re)
        .collect();
    finite.sort_by(f64::total_cmp);
    for (x, y) in finite.iter().zip([0.25, 0.5, 1.0]) {
        assert!((x - y).abs() < 1e-10, "{finite:?}");
    }
}

#[test]
fn zero_and_one_by_one_pencils() {
    let empty = Mat::<f64>::zeros(0, 0);
    let form = qz(empty.as_ref(), empty.as_ref()).unwrap();
    assert_eq!(form.s.nrows(), 0);
    let a = Mat::from_fn(1, 1, |_, _| 3.0);
    let b = Mat::from_fn(1, 1, |_, _| -2.0);
    let form = qz(a.as_ref(), b.as_ref()).unwrap();
    let values = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref());
    assert_eq!(values[0].value(), c64::new(-1.5, 0.0));
    assert!(values[0].beta > 0.0);
}

#[test]
fn reordering_brings_every_selection_to_the_top() {
    for n in 1..=8 {
        for seed in 0..3u64 {
            let a = random(n, 50 + seed);
            let b = random(n, 80 + seed);
            let form = qz(a.as_ref(), b.as_ref()).unwrap();
            let values = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref());
            // Every pattern over the blocks (pairs chosen together).
            let mut blocks = vec![];
            let mut k = 0;
            while k < n {
                let size = reorder::block_size(&form.s, k);
                blocks.push(values[k].value());
                k += size;
            }
            for pattern in 0..(1u32 << blocks.len()) {
                let chosen: Vec<c64> = blocks
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| pattern & (1 << i) != 0)
                    .map(|(_, v)| *v)
                    .collect();
                let near = |v: c64| {
                    chosen
                        .iter()
                        .any(|c| (c - v).norm() <= 1e-8 * (1.0 + c.norm()))
                };
                let (ordered, count) = reorder_qz(form.clone(), |e| near(e.value())).unwrap();
                let backward = check_form(&a, &b, &ordered);
                assert!(backward < 40.0 * n as f64, "n = {n}: {backward} u");
                let new = generalized_eigenvalues(ordered.s.as_ref(), ordered.t.as_ref());
                let expected: usize = chosen.iter().map(|c| if c.im != 0.0 { 2 } else { 1 }).sum();
                assert_eq!(count, expected);
                for (i, e) in new.iter().enumerate() {
                    let v = e.value();
                    let v = if i > 0 && v.im < 0.0 { v.conj() } else { v };
                    assert_eq!(
                        near(v) || near(v.conj()),
                        i < count,
                        "n = {n}, pattern {pattern}"
                    );
                }
            }
        }
    }
}

#[test]
fn bad_arguments_are_named() {
    let a = Mat::<f64>::zeros(3, 3);
    let b = Mat::<f64>::zeros(2, 2);
    assert!(matches!(
        qz(a.as_ref(), b.as_ref()),
        Err(Error::Mismatch { arg: "B", .. })
    ));
    let mut c = Mat::<f64>::zeros(3, 3);
    c[(1, 1)] = f64::NAN;
    assert!(matches!(
        qz(c.as_ref(), a.as_ref()),
        Err(Error::NonFinite { arg: "A", .. })
    ));
}

/// A defective double zero with exact zeros in A (A = [[-1, 0, 0], [1, 0, 0], [0, 1, 0]]): the
/// 2 x 2 block's real eigenvalue was chosen by a distance that put every root at 1 from the
/// estimate 0, and the 0/0 root 0.67 was split off with a backward error of 0.2.
#[test]
fn a_defective_double_zero_is_split_backward_stably() {
    let a = faer::mat![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let b = faer::mat![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 1.0, 2.0]];
    let form = qz(a.as_ref(), b.as_ref()).unwrap();
    let backward = check_form(&a, &b, &form);
    assert!(backward < 10.0, "backward error {backward} u");
    let mut values: Vec<f64> = (0..3).map(|k| form.s[(k, k)] / form.t[(k, k)]).collect();
    values.sort_by(f64::total_cmp);
    // -1 exactly conditioned; the defective double 0 to about sqrt(u).
    assert!((values[0] + 1.0).abs() < 1e-14, "{values:?}");
    assert!(
        values[1].abs() < 1e-7 && values[2].abs() < 1e-7,
        "{values:?}"
    );
}
