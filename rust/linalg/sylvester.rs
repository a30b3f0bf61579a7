//! The small Sylvester equation L X + X R = C with L of order p and R of order q, p, q in
//! {1, 2}: the kernel of Schur reordering ([`crate::linalg::schur::reorder`], with L = T11, R = -T22) and of
//! the Bartels–Stewart Lyapunov solver ([`crate::linalg::lyapunov`], with L = T_ii, R = T_jj^T).
//!
//! The equation is solved in its Kronecker form
//!
//! ```text
//! (I_q ⊗ L + R^T ⊗ I_p) vec X = vec C,        vec X = [x_11, x_21, x_12, x_22]
//! ```
//!
//! an order pq <= 4 linear system, by Gaussian elimination with complete pivoting (Demmel's
//! recommendation for these tiny, possibly nearly singular systems: the growth factor stays
//! small and a tiny pivot signals near-singularity reliably). The system is singular exactly
//! when L and -R share an eigenvalue. A pivot below `smin = max(u max|M|, tiny)` is replaced by
//! `smin`, as LAPACK's dlasy2 does, so the solution stays finite; the result says so, and the
//! callers decide whether that is acceptable (a Schur swap then fails its stability test, a
//! Lyapunov solve reports the near-singularity).

/// X (p x q, row-major in a 2 x 2 array) and whether a pivot had to be perturbed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SmallSylvester {
    pub x: [[f64; 2]; 2],
    pub perturbed: bool,
}

/// Solves L X + X R = C; only the leading p x p, q x q and p x q parts of the arrays are read.
// Gaussian elimination on a 4 x 4 array reads most clearly with indices.
#[allow(clippy::needless_range_loop)]
pub(crate) fn solve_small_sylvester(
    l: &[[f64; 2]; 2],
    p: usize,
    r: &[[f64; 2]; 2],
    q: usize,
    c: &[[f64; 2]; 2],
) -> SmallSylvester {
    let size = p * q;
    if size == 1 {
        // l x + x r = c: the general elimination below, with nothing to eliminate.
        let mut pivot = l[0][0] + r[0][0];
        let smin = (f64::EPSILON * pivot.abs()).max(f64::MIN_POSITIVE / f64::EPSILON);
        let perturbed = pivot.abs() < smin;
        if perturbed {
            pivot = smin;
        }
        return SmallSylvester {
            x: [[c[0][0] / pivot, 0.0], [0.0, 0.0]],
            perturbed,
        };
    }
    let unknown = |i: usize, k: usize| i + p * k;
    let mut m = [[0.0f64; 4]; 4];
    let mut rhs = [0.0f64; 4];
    for k in 0..q {
        for i in 0..p {
            let row = unknown(i, k);
            rhs[row] = c[i][k];
            for s in 0..p {
                m[row][unknown(s, k)] += l[i][s];
            }
            for s in 0..q {
                m[row][unknown(i, s)] += r[s][k];
            }
        }
    }
    let largest = m
        .iter()
        .take(size)
        .flat_map(|row| row.iter().take(size))
        .fold(0.0f64, |acc, v| acc.max(v.abs()));
    let smin = (f64::EPSILON * largest).max(f64::MIN_POSITIVE / f64::EPSILON);
    let mut perturbed = false;
    // Column permutation: column `columns[j]` of the original system sits at position j.
    let mut columns = [0, 1, 2, 3];
    for step in 0..size {
        let (mut pivot_row, mut pivot_column, mut pivot) = (step, step, 0.0f64);
        for (i, row) in m.iter().enumerate().take(size).skip(step) {
            for (j, value) in row.iter().enumerate().take(size).skip(step) {
                if value.abs() > pivot {
                    (pivot_row, pivot_column, pivot) = (i, j, value.abs());
                }
            }
        }
        m.swap(step, pivot_row);
        rhs.swap(step, pivot_row);
        for row in m.iter_mut() {
            row.swap(step, pivot_column);
        }
        columns.swap(step, pivot_column);
        if m[step][step].abs() < smin {
            m[step][step] = smin;
            perturbed = true;
        }
        for i in step + 1..size {
            let factor = m[i][step] / m[step][step];
            for j in step..size {
                m[i][j] -= factor * m[step][j];
            }
            rhs[i] -= factor * rhs[step];
        }
    }
    let mut solution = [0.0f64; 4];
    for i in (0..size).rev() {
        let mut value = rhs[i];
        for j in i + 1..size {
            value -= m[i][j] * solution[j];
        }
        solution[i] = value / m[i][i];
    }
    let mut x = [[0.0; 2]; 2];
    for (position, &column) in columns.iter().enumerate().take(size) {
        x[column % p][column / p] = solution[position];
    }
    SmallSylvester { x, perturbed }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn residual(
        l: &[[f64; 2]; 2],
        p: usize,
        r: &[[f64; 2]; 2],
        q: usize,
        c: &[[f64; 2]; 2],
        x: &[[f64; 2]; 2],
    ) -> f64 {
        let mut worst = 0.0f64;
        for i in 0..p {
            for k in 0..q {
                let mut value = -c[i][k];
                for s in 0..p {
                    value += l[i][s] * x[s][k];
                }
                for s in 0..q {
                    value += x[i][s] * r[s][k];
                }
                worst = worst.max(value.abs());
            }
        }
        worst
    }

    #[test]
    fn solves_every_block_shape() {
        let l = [[1.5, -2.0], [0.7, 1.5]];
        let r = [[-0.3, 4.0], [-1.0, -0.3]];
        let c = [[1.0, -2.0], [3.0, 0.5]];
        for p in 1..=2 {
            for q in 1..=2 {
                let solved = solve_small_sylvester(&l, p, &r, q, &c);
                assert!(!solved.perturbed);
                assert!(
                    residual(&l, p, &r, q, &c, &solved.x) < 1e-14,
                    "p = {p}, q = {q}"
                );
            }
        }
    }

    #[test]
    fn flags_a_singular_system() {
        // L and -R share the eigenvalue 2.
        let solved = solve_small_sylvester(
            &[[2.0, 0.0], [0.0, 0.0]],
            1,
            &[[-2.0, 0.0], [0.0, 0.0]],
            1,
            &[[1.0, 0.0], [0.0, 0.0]],
        );
        assert!(solved.perturbed);
        assert!(solved.x[0][0].is_finite());
    }
}
