//! Batches: one operation over a stack of independent problems, in parallel across cores.
//!
//! A stack of k matrices of one shape is stored contiguously in row-major order, exactly as
//! numpy stores a C-ordered k x rows x cols array, so a batch crosses from Python without a
//! copy per matrix. Each problem runs on one rayon task (small problems sequentially inside),
//! which is the efficient split for many small problems; an error names the index of the problem.

use crate::error::{Error, check_finite, check_output_len};
use crate::expm::expm_into_validated;
use faer::{MatMut, MatRef};
use rayon::prelude::*;

/// A read-only stack of `count` matrices of shape `rows` x `cols`, row-major and contiguous.
#[derive(Debug, Clone, Copy)]
pub struct MatrixStack<'a> {
    data: &'a [f64],
    count: usize,
    rows: usize,
    cols: usize,
}

impl<'a> MatrixStack<'a> {
    /// Views `data` (length count * rows * cols) as a stack of matrices.
    pub fn new(data: &'a [f64], count: usize, rows: usize, cols: usize) -> Result<Self, Error> {
        let expected = count
            .checked_mul(rows)
            .and_then(|x| x.checked_mul(cols))
            .unwrap_or(usize::MAX);
        if data.len() != expected {
            return Err(Error::Mismatch {
                arg: "data",
                what: "as many entries as",
                expected,
                other: "count x rows x cols",
                got: data.len(),
            });
        }
        Ok(Self {
            data,
            count,
            rows,
            cols,
        })
    }

    /// The number of matrices in the stack.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when the stack holds no matrix.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The `index`-th matrix.
    pub fn get(&self, index: usize) -> MatRef<'a, f64> {
        let size = self.rows * self.cols;
        MatRef::from_row_major_slice(
            &self.data[index * size..(index + 1) * size],
            self.rows,
            self.cols,
        )
    }
}

/// e^{A_i} for every matrix of a stack of square matrices, written row-major into `out`
/// (length k n^2), in parallel. A non-finite entry is reported with the index of its matrix
/// before anything is computed.
pub fn expm_batch(stack: MatrixStack<'_>, out: &mut [f64]) -> Result<(), Error> {
    let n = stack.rows;
    if stack.rows != stack.cols {
        return Err(Error::NotSquare {
            arg: "A",
            rows: stack.rows,
            cols: stack.cols,
        });
    }
    check_output_len(out.len(), stack.len() * n * n)?;
    // One branch-free pass over the whole stack (vectorised); the matrix at fault is found
    // only when there is one.
    if !stack
        .data
        .iter()
        .fold(true, |finite, v| finite & v.is_finite())
    {
        for index in 0..stack.len() {
            check_finite(stack.get(index), "A").map_err(|e| Error::in_batch(index, e))?;
        }
    }
    if n == 0 {
        return Ok(());
    }
    out.par_chunks_mut(n * n)
        .enumerate()
        .for_each(|(index, chunk)| {
            // Validated above: every matrix is square and finite.
            expm_into_validated(
                stack.get(index),
                MatMut::from_row_major_slice_mut(chunk, n, n),
            );
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expm::expm;

    #[test]
    fn batch_equals_one_at_a_time() {
        let (k, n) = (37, 5);
        let data: Vec<f64> = (0..k * n * n)
            .map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0)
            .collect();
        let stack = MatrixStack::new(&data, k, n, n).unwrap();
        let mut out = vec![0.0; k * n * n];
        expm_batch(stack, &mut out).unwrap();
        for index in 0..k {
            let single = expm(stack.get(index)).unwrap();
            for i in 0..n {
                for j in 0..n {
                    assert_eq!(out[index * n * n + i * n + j], single[(i, j)]);
                }
            }
        }
    }

    #[test]
    fn error_names_the_failing_index() {
        let (k, n) = (4, 2);
        let mut data = vec![0.5; k * n * n];
        data[2 * n * n + 3] = f64::INFINITY;
        let mut out = vec![0.0; k * n * n];
        let err = expm_batch(MatrixStack::new(&data, k, n, n).unwrap(), &mut out).unwrap_err();
        assert_eq!(
            err.to_string(),
            "problem 2 of the batch: A must be finite, but A[1, 1] is inf"
        );
    }

    #[test]
    fn empty_stacks() {
        let mut out = vec![];
        expm_batch(MatrixStack::new(&[], 0, 3, 3).unwrap(), &mut out).unwrap();
        expm_batch(MatrixStack::new(&[], 5, 0, 0).unwrap(), &mut out).unwrap();
    }
}
