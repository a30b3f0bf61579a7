//! The continuous Lyapunov equation A X + X A^T + Q = 0, by the method of Bartels & Stewart
//! (1972).
//!
//! With the real Schur form A = Z T Z^T ([`crate::schur`]) the equation becomes
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
//! at most 4 (`crate::sylvester`). The solution exists and is unique exactly when no two
//! eigenvalues of A add up to zero (λ_i + λ_j ≠ 0); a stable A qualifies. Near that
//! singularity a pivot of the small systems is perturbed and the solver refuses the result
//! ([`Error::IllConditioned`]). The method is backward stable in the sense of Higham (1993):
//! the residual is O(u ||A|| ||X||), and the forward error is bounded by the condition number
//! of the Lyapunov operator, 1 / sep(A, -A^T).
//!
//! The cost is that of the Schur form, about 25 n^3 flops, plus 4 n^3 for the transformations
//! and n^3 for the triangular solve (the updates are column operations, as in LAPACK's dtrsyl).

use crate::dense::Dense;
use crate::dispatch::clear_upper_avx_state;
use crate::error::{Error, check_finite, check_rows, check_square};
use crate::schur::real_schur;
use crate::small_matrix::product;
use crate::sylvester::solve_small_sylvester;
use faer::{Accum, Mat, MatRef, Par};

/// The solution X of A X + X A^T + Q = 0 (symmetric when Q is).
pub fn solve_lyapunov(a: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Result<Mat<f64>, Error> {
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
    let schur = real_schur(a)?;
    let (t, z) = (schur.t.as_ref(), schur.z.as_ref());
    let mut f = Dense::from_ref(product(product(z.transpose(), q).as_ref(), z).as_ref());
    for x in f.as_mut_slice() {
        *x = -*x;
    }
    let y = solve_quasi_triangular(&Dense::from_ref(t), f, singularity)?;
    let mut x = product(product(z, y.as_ref()).as_ref(), z.transpose());
    if is_symmetric(q) {
        symmetrize(&mut x);
    }
    Ok(x)
}

/// Solves T Y + Y T^T = F for quasi-upper-triangular T (2 x 2 blocks in standard form).
pub(crate) fn solve_quasi_triangular(
    t: &Dense,
    mut f: Dense,
    singularity: Singularity,
) -> Result<Dense, Error> {
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
    let mut y = Dense::zeros(n, n);
    for &(j0, q) in blocks.iter().rev() {
        let after = j0 + q;
        if after < n {
            // F[:, J] -= Y[:, after..] T[J, after..]^T (the columns of Y already known).
            let known = y.as_ref().subcols(after, n - after);
            let coupling = t.as_ref().submatrix(j0, after, q, n - after);
            faer::linalg::matmul::matmul(
                f.as_mut().subcols_mut(j0, q),
                Accum::Add,
                known,
                coupling.transpose(),
                -1.0,
                Par::Seq,
            );
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
                        let column = &t.col(i0 + a)[..i0];
                        let target = &mut f.col_mut(j0 + c)[..i0];
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

/// X <- (X + X^T) / 2.
pub(crate) fn symmetrize(x: &mut Mat<f64>) {
    let n = x.nrows();
    for i in 0..n {
        for j in 0..i {
            let mean = 0.5 * (x[(i, j)] + x[(j, i)]);
            x[(i, j)] = mean;
            x[(j, i)] = mean;
        }
    }
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
    fn diagonal_closed_form() {
        // a_i x_ij + x_ij a_j = -q_ij.
        let a = mat![[-1.0, 0.0], [0.0, -3.0]];
        let q = mat![[2.0, 4.0], [4.0, 6.0]];
        let x = solve_lyapunov(a.as_ref(), q.as_ref()).unwrap();
        let expected = mat![[1.0, 1.0], [1.0, 1.0]];
        assert!((&x - &expected).norm_max() < 1e-15);
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
