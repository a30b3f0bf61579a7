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
    let mut values: Vec<c64> = generalized_eigenvalues(form.s.as_ref(), form.t.as_ref())
        .iter()
        .map(|e| e.value())
        .collect();
    values.sort_by(|x, y| x.re.total_cmp(&y.re));
    // -1 exactly conditioned; the defective double 0 to about sqrt(u) (a real pair or a
    // complex one, as rounding has it).
    assert!((values[0] + 1.0).norm() < 1e-14, "{values:?}");
    assert!(
        values[1].norm() < 1e-7 && values[2].norm() < 1e-7,
        "{values:?}"
    );
}

/// An orthogonal matrix: the product of three Householder reflectors of random vectors.
fn orthogonal(n: usize, seed: u64) -> Mat<f64> {
    let mut q = Mat::<f64>::identity(n, n);
    for r in 0..3 {
        let v = random(n, seed * 7 + r);
        let v = v.col(0);
        let norm2: f64 = v.iter().map(|x| x * x).sum();
        let reflector = Mat::from_fn(n, n, |i, j| {
            let identity = if i == j { 1.0 } else { 0.0 };
            identity - 2.0 * v[i] * v[j] / norm2
        });
        q = &q * &reflector;
    }
    q
}

/// The backward errors ||Q^T A Z - S|| / ||A|| and ||Q^T B Z - T|| / ||B|| in units of n u
/// (u = 2^-53), after the structural checks of [`check_form`].
fn backward_errors(a: &Mat<f64>, b: &Mat<f64>, form: &GeneralizedSchur) -> (f64, f64) {
    check_form(a, b, form);
    let n = a.nrows() as f64;
    let unit = n * f64::EPSILON / 2.0;
    let ds = form.q.transpose() * a * &form.z - &form.s;
    let dt = form.q.transpose() * b * &form.z - &form.t;
    (
        frobenius_norm(ds.as_ref()) / (unit * frobenius_norm(a.as_ref())),
        frobenius_norm(dt.as_ref()) / (unit * frobenius_norm(b.as_ref())),
    )
}

/// The pencil Q (S, T) Z^T of upper triangular S (diagonal of size 0.5 to 2) and T, with the
/// diagonal entries of T at `zeros` set to zero (infinite eigenvalues).
fn triangular_pencil(n: usize, seed: u64, zeros: &[usize], same: bool) -> (Mat<f64>, Mat<f64>) {
    let q = orthogonal(n, seed);
    let z = if same {
        q.clone()
    } else {
        orthogonal(n, seed + 1000)
    };
    let (r1, r2) = (random(n, seed + 2000), random(n, seed + 3000));
    let s = Mat::from_fn(n, n, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Less => r1[(i, j)],
        std::cmp::Ordering::Equal => 1.25 + 0.75 * r1[(i, j)],
        std::cmp::Ordering::Greater => 0.0,
    });
    let t = Mat::from_fn(n, n, |i, j| {
        if i > j || (i == j && zeros.contains(&i)) {
            0.0
        } else {
            r2[(i, j)]
        }
    });
    (&q * &s * z.transpose(), &q * &t * z.transpose())
}

/// The classes of the formerly known defects qz-near-proportional-pencil (A = c B + E: the
/// first column of the double shift and the 2 x 2 blocks' eigenvalues were differences of
/// terms of c^2, with backward errors of 1e-9 and NoConvergence for E of 1e-12) and
/// qz-all-infinite-pencil (A nonsingular, B nilpotent: complex pairs near infinity made
/// diagonal through their short column, and real ones split at eigenvalues accurate only to
/// their condition, lost B's backward error), beside pencils with finite and infinite
/// eigenvalues, a triangular B with zero diagonal entries and random pencils: 200 of each, of
/// orders 2 to 8, with backward errors of A and B each below 20 n u.
#[test]
fn classes_of_pencils_are_backward_stable() {
    let classes = [
        "near-proportional",
        "all-infinite",
        "mixed",
        "zero-diagonals",
        "generic",
    ];
    for (class, name) in classes.iter().enumerate() {
        let mut worst: f64 = 0.0;
        for seed in 0..200u64 {
            let n = 2 + (seed % 7) as usize;
            let key = 10_000 * class as u64 + seed;
            let (a, b) = match *name {
                "near-proportional" => {
                    let b = random(n, key);
                    let c = [1.0, -2.5, 0.3, 1e3, 0.01][(seed % 5) as usize];
                    let size = 10f64.powi(-2 - (seed / 5 % 13) as i32);
                    let e = random(n, key + 500);
                    (&b * c + &e * (size * c), b)
                }
                "all-infinite" => {
                    let zeros: Vec<usize> = (0..n).collect();
                    triangular_pencil(n, key, &zeros, seed % 3 == 0)
                }
                "mixed" => {
                    let zeros: Vec<usize> = (0..n)
                        .filter(|i| (i + seed as usize).is_multiple_of(3))
                        .collect();
                    triangular_pencil(n, key, &zeros, seed % 3 == 0)
                }
                "zero-diagonals" => {
                    let t = random(n, key + 500);
                    let t = Mat::from_fn(n, n, |i, j| {
                        if i > j || (i == j && !(i * 5 + seed as usize).is_multiple_of(3)) {
                            0.0
                        } else {
                            t[(i, j)]
                        }
                    });
                    (random(n, key), t)
                }
                _ => (random(n, key), random(n, key + 500)),
            };
            let form =
                qz(a.as_ref(), b.as_ref()).unwrap_or_else(|e| panic!("{name}, seed {seed}: {e:?}"));
            let (ea, eb) = backward_errors(&a, &b, &form);
            assert!(ea < 20.0 && eb < 20.0, "{name}, seed {seed}: {ea} {eb} n u");
            worst = worst.max(ea).max(eb);
        }
        assert!(worst > 0.0, "{name}: every form exact");
    }
}

/// The all-infinite pencil of the regression test (A = H U H, B = H N H with H a Householder
/// reflector): det(A - λB) = 3, so every eigenvalue is infinite; B's backward error was 3e-12.
#[test]
fn an_all_infinite_pencil_is_backward_stable() {
    let v = [1.0, 1.0, -1.0];
    let h = Mat::from_fn(3, 3, |i, j| {
        (if i == j { 1.0 } else { 0.0 }) - 2.0 * v[i] * v[j] / 3.0
    });
    let u = faer::mat![[1.0, -1.0, 3.0], [0.0, 3.0, 1.0], [0.0, 0.0, 1.0]];
    let nilpotent = faer::mat![[0.0, -2.0, -2.0], [0.0, 0.0, 2.0], [0.0, 0.0, 0.0]];
    let (a, b) = (&h * &u * &h, &h * &nilpotent * &h);
    let form = qz(a.as_ref(), b.as_ref()).unwrap();
    let (ea, eb) = backward_errors(&a, &b, &form);
    assert!(ea < 20.0 && eb < 20.0, "{ea} {eb} n u");
    // Each eigenvalue within 4 (20 n u)^(1/3) of infinity in the chordal metric (a triple,
    // defective, infinite one).
    for value in generalized_eigenvalues(form.s.as_ref(), form.t.as_ref()) {
        let chordal = value.beta / value.alpha.norm().hypot(value.beta);
        assert!(chordal <= 4.0 * (30.0 * f64::EPSILON).cbrt(), "{value:?}");
    }
}

/// A pencil within float32 rounding of a proportional one (A = B + O(1e-8), both eigenvalues
/// near 1): the 2 x 2 block was split with a backward error of 9.3e-10.
#[test]
fn a_near_proportional_pencil_is_backward_stable() {
    let b = faer::mat![
        [0.1257302210933933, -0.1321048632913019],
        [0.6404226504432821, 0.10490011715303971]
    ];
    let a = Mat::from_fn(2, 2, |i, j| b[(i, j)] as f32 as f64);
    let form = qz(a.as_ref(), b.as_ref()).unwrap();
    let (ea, eb) = backward_errors(&a, &b, &form);
    assert!(ea < 20.0 && eb < 20.0, "{ea} {eb} n u");
    for value in generalized_eigenvalues(form.s.as_ref(), form.t.as_ref()) {
        assert!(
            (value.value() - c64::new(1.0, 0.0)).norm() < 1e-6,
            "{value:?}"
        );
    }
}
