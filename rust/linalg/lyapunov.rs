//! The continuous Lyapunov equation A X + X A^T + Q = 0, by the method of Bartels & Stewart
//! (1972).
//!
//! With the real Schur form A = Z T Z^T ([`crate::linalg::schur`]) the equation becomes
//!
//! ```text
//! T Y + Y T^T = F,      F = -Z^T Q Z,      X = Z Y Z^T.
//! ```
//!
//! Partitioned conformally with the 1 x 1 and 2 x 2 diagonal blocks of T, block (i, j) reads
//!
//! ```text
//! T_ii Y_ij + Y_ij T_jj^T = F_ij - sum_{k > i} T_ik Y_kj - sum_{l > j} Y_il T_jl^T,
//! ```
//!
//! so the blocks follow one another from the bottom right, each a Sylvester equation of order
//! at most 4 (`crate::linalg::sylvester`). The solution exists and is unique exactly when no two
//! eigenvalues of A add up to zero (λ_i + λ_j ≠ 0); a stable A qualifies. Near that
//! singularity a pivot of the small systems is perturbed and the solver refuses the result
//! ([`Error::IllConditioned`]). The method is backward stable in the sense of Higham (1993):
//! the residual is O(u ||A|| ||X||), and the forward error is bounded by the condition number
//! of the Lyapunov operator, 1 / sep(A, -A^T).
//!
//! The cost is that of the Schur form, about 25 n^3 flops, plus 4 n^3 for the transformations
//! and n^3 for the triangular solve (the updates are column operations, as in LAPACK's dtrsyl).
//!
//! Up to order [`KRONECKER_MAX_ORDER`] a symmetric Q is instead solved for directly: the
//! n(n+1)/2 distinct entries of X satisfy a linear system of that order (`solve_kronecker`),
//! whose elimination costs O(n^6) flops but fewer than the Schur form's constant factor at
//! these orders (the 4-state models of flight dynamics, and the Riccati solver's Newton steps).

use crate::error::{Error, check_finite, check_rows, check_square};
use crate::linalg::balance::{balanced_where_scaled_apart, range_scale};
use crate::linalg::dense::view_product;
use crate::linalg::matrix::{FaerView, Symmetrize, from_faer, with_order};
use crate::linalg::schur::real_schur;
use crate::linalg::sylvester::solve_small_sylvester;
use crate::platform::dispatch::clear_upper_avx_state;
use crate::platform::interrupt;
use faer::{Accum, Mat, MatRef, Par};
use nalgebra::DMatrix;

/// The solution X of A X + X A^T + Q = 0 (symmetric when Q is).
///
/// Where A's states are scaled apart ([`balanced_where_scaled_apart`]: units 10^3 or more apart) the
/// equation is solved in balanced states, exactly: with A' = T A T^-1 (T diagonal, of powers
/// of two), X' = T X T solves A' X' + X' A'^T + T Q T = 0, and X = T^-1 X' T^-1. The method's
/// errors are relative to ||A|| and ||X||: unbalanced, states scaled by 1e±6 had entries of X
/// wrong in the third digit (in balanced states they are right to 1e-15). An entry of X beyond
/// the doubles is then infinite (the caller warns).
pub fn solve_lyapunov(a: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
    let n = a.nrows();
    let conformal = a.ncols() == n && q.nrows() == n && q.ncols() == n;
    if conformal
        && let Some((a2, _, _, t)) = balanced_where_scaled_apart(
            a,
            Mat::<f64>::zeros(n, 0).as_ref(),
            Mat::<f64>::zeros(0, n).as_ref(),
        )
    {
        let q2 = Mat::from_fn(n, n, |i, j| q[(i, j)] * t[i] * t[j]);
        // The scaling must be exact: no nonzero entry of Q may leave the normal doubles.
        let exact = (0..n).all(|j| {
            (0..n).all(|i| {
                let (x, y) = (q[(i, j)], q2[(i, j)]);
                x == 0.0 || !x.is_finite() || (y.is_finite() && y.abs() >= f64::MIN_POSITIVE)
            })
        });
        if exact {
            let y = solve(a2.as_ref(), q2.as_ref(), Singularity::Refuse)?;
            return Ok(Mat::from_fn(n, n, |i, j| y[(i, j)] / t[i] / t[j]));
        }
    }
    solve(a, q, Singularity::Refuse)
}

/// What to do when a pivot of the small systems falls below u times their size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Singularity {
    /// Fail with [`Error::IllConditioned`]: a public solve must not return a solution that
    /// may have no correct digit.
    Refuse,
    /// Replace the pivot by u times the system's size and go on (LAPACK's dtrsyl does this):
    /// a correction whose effect the caller measures, such as a Newton step that is kept only
    /// if it reduces the residual.
    Perturb,
}

/// [`solve_lyapunov`] with a choice of what a near-singular equation does.
pub(crate) fn solve(
    a: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
    singularity: Singularity,
) -> Result<Mat<f64>, Error> {
    check_square(a, "A")?;
    check_finite(a, "A")?;
    check_square(q, "Q")?;
    check_rows(q, "Q", a.nrows(), "A")?;
    check_finite(q, "Q")?;
    // A / s and Q / s for the power of two s of A's largest entry give the same X (exactly),
    // and keep the pivots' test relative to A: A = [[-1e-295]] was refused as singular, its
    // pivot below the smallest normal number over u.
    let scale = range_scale(a);
    if scale != 1.0 {
        let a = Mat::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] / scale);
        let q = Mat::from_fn(q.nrows(), q.ncols(), |i, j| q[(i, j)] / scale);
        if !q.is_all_finite() {
            return Err(Error::InvalidArgument {
                arg: "Q",
                message: "the solution X overflows double precision: Q is too large for a \
                          matrix A this small (||Q|| / ||A|| beyond the largest double)"
                    .into(),
            });
        }
        return solve(a.as_ref(), q.as_ref(), singularity);
    }
    if a.nrows() <= KRONECKER_MAX_ORDER && is_symmetric(q) {
        let x = solve_kronecker(&from_faer(a), &from_faer(q), singularity)?;
        return Ok(x.to_faer());
    }
    let schur = real_schur(a)?;
    let (t, z) = (schur.t.as_ref(), schur.z.as_ref());
    let mut f = from_faer(view_product(view_product(z.transpose(), q)?.as_ref(), z)?.as_ref());
    for x in f.as_mut_slice() {
        *x = -*x;
    }
    let y = solve_quasi_triangular(&from_faer(t), f, singularity)?;
    let mut x = view_product(view_product(z, y.as_faer())?.as_ref(), z.transpose())?;
    if is_symmetric(q) {
        x.symmetrize();
    }
    Ok(x)
}

/// Up to this order a Lyapunov equation with symmetric Q is solved in its vectorised form
/// (`solve_kronecker`): the n(n+1)/2 unknowns on and above the diagonal of X, by one LU
/// factorisation of their order-n(n+1)/2 system. That costs O(n^6) flops against the O(n^3) of
/// Bartels–Stewart, but needs no Schur form; at n = 4 (a 10 x 10 system) it takes a fifth of
/// the instructions, at n = 5 (15 x 15) about a third.
pub const KRONECKER_MAX_ORDER: usize = 5;

/// Solves A X + X A^T + Q = 0 for symmetric Q (only its upper triangle is read) and order up
/// to [`KRONECKER_MAX_ORDER`], directly: with x = (x_ij, i <= j) by columns, equation (i, j),
/// i <= j, reads
///
/// ```text
/// sum_k a_ik x_kj + sum_k a_jk x_ik = -q_ij,        x_kj = x_jk,
/// ```
///
/// an order-n(n+1)/2 linear system solved by Gaussian elimination with partial pivoting. It is
/// singular exactly when two eigenvalues of A add up to zero. A pivot below
/// `smin = max(u max|M|, tiny)` signals that: [`Singularity::Refuse`] fails, and
/// [`Singularity::Perturb`] replaces it by `smin`, as the small Sylvester systems of
/// Bartels–Stewart do.
pub(crate) fn solve_kronecker(
    a: &DMatrix<f64>,
    q: &DMatrix<f64>,
    singularity: Singularity,
) -> Result<DMatrix<f64>, Error> {
    // The order N and the system's order S = N(N+1)/2 as constants: the loops over rows of S
    // entries unroll, and the system takes no more stack than it needs.
    with_order!(
        a.nrows(),
        [1, 2, 3, 4, 5],
        N => solve_kronecker_in::<N, { N * (N + 1) / 2 }>(a, q, singularity),
        n => {
            assert_eq!(n, 0, "solve_kronecker of order {n} > KRONECKER_MAX_ORDER");
            Ok(DMatrix::zeros(0, 0))
        }
    )
}

/// [`solve_kronecker`] at the order N, S = N(N+1)/2.
// The system's rows and columns are indexed by unknowns: indices read most clearly.
#[allow(clippy::needless_range_loop)]
fn solve_kronecker_in<const N: usize, const S: usize>(
    a: &DMatrix<f64>,
    q: &DMatrix<f64>,
    singularity: Singularity,
) -> Result<DMatrix<f64>, Error> {
    const { assert!(S == N * (N + 1) / 2) };
    let n = N;
    debug_assert_eq!(a.nrows(), N);
    let size = S;
    // unknown[i][j]: the position of x_ij = x_ji, by columns of the upper triangle.
    let mut unknown = [[0usize; N]; N];
    for j in 0..n {
        for i in 0..=j {
            unknown[i][j] = j * (j + 1) / 2 + i;
            unknown[j][i] = unknown[i][j];
        }
    }
    let mut m = [[0.0f64; S]; S];
    let mut rhs = [0.0f64; S];
    let mut largest = 0.0f64;
    for j in 0..n {
        for i in 0..=j {
            let row = &mut m[unknown[i][j]];
            rhs[unknown[i][j]] = -q[(i, j)];
            for k in 0..n {
                row[unknown[k][j]] += a[(i, k)];
                row[unknown[i][k]] += a[(j, k)];
            }
            largest = row[..size].iter().fold(largest, |acc, v| acc.max(v.abs()));
        }
    }
    let smin = (f64::EPSILON * largest).max(f64::MIN_POSITIVE / f64::EPSILON);
    for step in 0..size {
        let mut pivot_row = step;
        for i in step + 1..size {
            if m[i][step].abs() > m[pivot_row][step].abs() {
                pivot_row = i;
            }
        }
        m.swap(step, pivot_row);
        rhs.swap(step, pivot_row);
        if m[step][step].abs() < smin {
            if singularity == Singularity::Refuse {
                return Err(Error::IllConditioned {
                    message: "the Lyapunov equation is singular to working precision: A has \
                              two eigenvalues whose sum is (nearly) zero (a mode on the \
                              imaginary axis, or a pair mirrored across it)"
                        .into(),
                });
            }
            m[step][step] = smin;
        }
        let (done, below) = m.split_at_mut(step + 1);
        let pivot = &done[step][step..size];
        for (offset, row) in below[..size - step - 1].iter_mut().enumerate() {
            let factor = row[step] / pivot[0];
            if factor != 0.0 {
                for (x, &p) in row[step..size].iter_mut().zip(pivot) {
                    *x -= factor * p;
                }
                rhs[step + 1 + offset] -= factor * rhs[step];
            }
        }
    }
    let mut solution = [0.0f64; S];
    for i in (0..size).rev() {
        let mut value = rhs[i];
        for j in i + 1..size {
            value -= m[i][j] * solution[j];
        }
        solution[i] = value / m[i][i];
    }
    Ok(DMatrix::from_fn(n, n, |i, j| solution[unknown[i][j]]))
}

/// Up to this order the quasi-triangular solve updates the right-hand side by plain column
/// operations; above it by faer's product.
const SMALL_UPDATE_MAX_ORDER: usize = 16;

/// Solves T Y + Y T^T = F for quasi-upper-triangular T (2 x 2 blocks in standard form).
pub(crate) fn solve_quasi_triangular(
    t: &DMatrix<f64>,
    mut f: DMatrix<f64>,
    singularity: Singularity,
) -> Result<DMatrix<f64>, Error> {
    clear_upper_avx_state();
    let n = t.nrows();
    let mut blocks = Vec::with_capacity(n);
    let mut k = 0;
    while k < n {
        let size = if k + 1 < n && t[(k + 1, k)] != 0.0 {
            2
        } else {
            1
        };
        blocks.push((k, size));
        k += size;
    }
    let mut y = DMatrix::zeros(n, n);
    for &(j0, q) in blocks.iter().rev() {
        interrupt::check()?;
        let after = j0 + q;
        // F[:, J] -= Y[:, after..] T[J, after..]^T (the columns of Y already known): column
        // updates for small orders, where faer's product costs more to set up than it saves.
        if after < n && n > SMALL_UPDATE_MAX_ORDER {
            let known = y.as_faer().subcols(after, n - after);
            let coupling = t.as_faer().submatrix(j0, after, q, n - after);
            faer::linalg::matmul::matmul(
                f.as_faer_mut().subcols_mut(j0, q),
                Accum::Add,
                known,
                coupling.transpose(),
                -1.0,
                Par::Seq,
            );
        } else {
            for c in j0..after {
                for s in after..n {
                    let coefficient = t[(c, s)];
                    for (x, &known) in f.column_slice_mut(c).iter_mut().zip(y.column_slice(s)) {
                        *x -= known * coefficient;
                    }
                }
            }
        }
        let mut r = [[0.0; 2]; 2];
        for c in 0..q {
            for s in 0..q {
                r[s][c] = t[(j0 + c, j0 + s)];
            }
        }
        for &(i0, p) in blocks.iter().rev() {
            let mut l = [[0.0; 2]; 2];
            let mut rhs = [[0.0; 2]; 2];
            for a in 0..p {
                for b in 0..p {
                    l[a][b] = t[(i0 + a, i0 + b)];
                }
                for c in 0..q {
                    rhs[a][c] = f[(i0 + a, j0 + c)];
                }
            }
            let solved = solve_small_sylvester(&l, p, &r, q, &rhs);
            if solved.perturbed && singularity == Singularity::Refuse {
                return Err(Error::IllConditioned {
                    message: "the Lyapunov equation is singular to working precision: A has \
                              two eigenvalues whose sum is (nearly) zero (a mode on the \
                              imaginary axis, or a pair mirrored across it)"
                        .into(),
                });
            }
            // Y[I, J], and the column updates F[0..i0, J] -= T[0..i0, I] Y[I, J].
            for c in 0..q {
                for a in 0..p {
                    let value = solved.x[a][c];
                    y[(i0 + a, j0 + c)] = value;
                    if value != 0.0 {
                        let column = &t.column_slice(i0 + a)[..i0];
                        let target = &mut f.column_slice_mut(j0 + c)[..i0];
                        for (x, &t_entry) in target.iter_mut().zip(column) {
                            *x -= value * t_entry;
                        }
                    }
                }
            }
        }
    }
    Ok(y)
}

fn is_symmetric(q: MatRef<'_, f64>) -> bool {
    (0..q.nrows()).all(|i| (0..i).all(|j| q[(i, j)] == q[(j, i)]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::mat;

    fn residual(a: MatRef<'_, f64>, x: MatRef<'_, f64>, q: MatRef<'_, f64>) -> f64 {
        (a * x + x * a.transpose() + q).norm_max()
    }

    #[test]
    fn solves_a_stable_system_with_complex_modes() {
        let a = mat![
            [-0.0558, -0.9968, 0.0802, 0.0415],
            [0.598, -0.115, -0.0318, 0.0],
            [-3.05, 0.388, -0.465, 0.0],
            [0.0, 0.0805, 1.0, 0.0]
        ];
        let q = mat![
            [2.0, 0.5, 0.0, 0.0],
            [0.5, 1.0, 0.0, 0.1],
            [0.0, 0.0, 3.0, 0.0],
            [0.0, 0.1, 0.0, 1.0]
        ];
        let x = solve_lyapunov(a.as_ref(), q.as_ref());
        // This A has an eigenvalue near 0 but none mirrored: a unique solution exists.
        let x = x.expect("solvable");
        assert!(residual(a.as_ref(), x.as_ref(), q.as_ref()) < 1e-10 * x.norm_max());
        assert_eq!(x, x.transpose().to_owned());
    }

    #[test]
    fn states_scaled_apart_keep_every_entry() {
        // X0 of a stable A0 with Q0 = I; the same equation in states scaled by 10^±6
        // (A = D A0 D^-1, Q = D Q0 D) has X = D X0 D, entry by entry to 1e-13 relatively.
        let a0 = mat![[-1.0, 0.5, -0.25], [0.3, -2.0, 0.75], [0.2, -0.4, -3.0]];
        let q0 = Mat::<f64>::identity(3, 3);
        let x0 = solve_lyapunov(a0.as_ref(), q0.as_ref()).unwrap();
        let d = [1e-6, 1.0, 1e6];
        let a = Mat::from_fn(3, 3, |i, j| a0[(i, j)] * d[i] / d[j]);
        let q = Mat::from_fn(3, 3, |i, j| q0[(i, j)] * d[i] * d[j]);
        let x = solve_lyapunov(a.as_ref(), q.as_ref()).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let expected = x0[(i, j)] * d[i] * d[j];
                assert!(
                    (x[(i, j)] - expected).abs() <= 1e-13 * expected.abs(),
                    "{i} {j}"
                );
            }
        }
    }

    #[test]
    fn diagonal_closed_form() {
        // a_i x_ij + x_ij a_j = -q_ij.
        let a = mat![[-1.0, 0.0], [0.0, -3.0]];
        let q = mat![[2.0, 4.0], [4.0, 6.0]];
        let x = solve_lyapunov(a.as_ref(), q.as_ref()).unwrap();
        let expected = mat![[1.0, 1.0], [1.0, 1.0]];
        assert!((&x - &expected).norm_max() < 1e-15);
    }

    /// The direct solve of small orders agrees with Bartels–Stewart (forced through the
    /// quasi-triangular solve by a non-symmetric Q of the same upper triangle plus its
    /// transpose's correction) to rounding, and refuses or perturbs a singular equation as
    /// the Schur route does.
    #[test]
    fn direct_small_solves_agree_with_bartels_stewart() {
        for n in 1..=KRONECKER_MAX_ORDER {
            for seed in 0..20u64 {
                let g = crate::test_matrices::seeded(n, n, 40 + 7 * seed + n as u64);
                let a = Mat::from_fn(n, n, |i, j| g[(i, j)] - if i == j { 1.5 } else { 0.0 });
                let h = crate::test_matrices::seeded(n, n, 90 + seed);
                let q = &h * h.transpose();
                let direct = solve_kronecker(
                    &from_faer(a.as_ref()),
                    &from_faer(q.as_ref()),
                    Singularity::Refuse,
                )
                .unwrap()
                .to_faer();
                // The Schur route: real_schur, then the quasi-triangular solve.
                let schur = real_schur(a.as_ref()).unwrap();
                let (t, z) = (schur.t.as_ref(), schur.z.as_ref());
                let mut f = from_faer((z.transpose() * &q * z).as_ref());
                for x in f.as_mut_slice() {
                    *x = -*x;
                }
                let y = solve_quasi_triangular(&from_faer(t), f, Singularity::Refuse).unwrap();
                let schur_route = z * y.to_faer() * z.transpose();
                let scale = direct.norm_max();
                assert!(
                    (&direct - &schur_route).norm_max() <= 1e-12 * scale,
                    "n={n} seed={seed}"
                );
                assert!(residual(a.as_ref(), direct.as_ref(), q.as_ref()) <= 1e-13 * scale);
                assert_eq!(direct, direct.transpose().to_owned());
            }
        }
        let rotation = mat![[0.0, 1.0], [-1.0, 0.0]];
        let q = Mat::<f64>::identity(2, 2);
        let (a, q) = (from_faer(rotation.as_ref()), from_faer(q.as_ref()));
        assert!(matches!(
            solve_kronecker(&a, &q, Singularity::Refuse),
            Err(Error::IllConditioned { .. })
        ));
        let perturbed = solve_kronecker(&a, &q, Singularity::Perturb).unwrap();
        assert!(perturbed.as_slice().iter().all(|x| x.is_finite()));
    }

    #[test]
    fn refuses_a_mode_on_the_imaginary_axis() {
        let a = mat![[0.0, 1.0], [-1.0, 0.0]];
        let q = Mat::<f64>::identity(2, 2);
        assert!(matches!(
            solve_lyapunov(a.as_ref(), q.as_ref()),
            Err(Error::IllConditioned { .. })
        ));
    }
}
