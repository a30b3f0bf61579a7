//! A per-thread free list of small scratch matrices.
//!
//! The exponential of a 4 x 4 matrix needs about twenty temporaries; allocating each costs more
//! than the arithmetic. Algorithms take their temporaries with [`scratch`] and the matrix goes
//! back to this thread's free list when dropped, so repeated calls of one size allocate nothing.
//! Only small matrices are pooled (large ones are cheap to allocate relative to their O(n^3)
//! work) and the list is bounded, so the pool holds at most a few hundred kilobytes per thread.

use faer::Mat;
use std::cell::RefCell;
use std::ops::{Deref, DerefMut};

/// Matrices with at most this many entries are pooled.
const MAX_POOLED_ENTRIES: usize = 64 * 64;
/// At most this many matrices wait in a thread's free list.
const MAX_POOLED_MATRICES: usize = 24;

thread_local! {
    static FREE_LIST: RefCell<Vec<Mat<f64>>> = const { RefCell::new(Vec::new()) };
}

/// A scratch matrix that returns to the thread's free list when dropped.
pub struct Scratch(Option<Mat<f64>>);

/// A `rows` x `cols` scratch matrix. Its entries are unspecified: overwrite before reading.
pub fn scratch(rows: usize, cols: usize) -> Scratch {
    let pooled = if rows * cols <= MAX_POOLED_ENTRIES {
        FREE_LIST
            .try_with(|list| {
                let mut list = list.try_borrow_mut().ok()?;
                let position = list
                    .iter()
                    .position(|m| m.nrows() == rows && m.ncols() == cols)?;
                Some(list.swap_remove(position))
            })
            .ok()
            .flatten()
    } else {
        None
    };
    Scratch(Some(pooled.unwrap_or_else(|| Mat::zeros(rows, cols))))
}

impl Scratch {
    /// Keeps the matrix: it will not return to the free list.
    pub fn into_mat(mut self) -> Mat<f64> {
        self.0.take().expect("present until dropped")
    }
}

impl Deref for Scratch {
    type Target = Mat<f64>;
    fn deref(&self) -> &Mat<f64> {
        self.0.as_ref().expect("present until dropped")
    }
}

impl DerefMut for Scratch {
    fn deref_mut(&mut self) -> &mut Mat<f64> {
        self.0.as_mut().expect("present until dropped")
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let Some(m) = self.0.take() else { return };
        if m.nrows() * m.ncols() > MAX_POOLED_ENTRIES {
            return;
        }
        // During thread teardown the list may be gone; the matrix is then simply freed.
        let _ = FREE_LIST.try_with(|list| {
            if let Ok(mut list) = list.try_borrow_mut()
                && list.len() < MAX_POOLED_MATRICES
            {
                list.push(m);
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matrices_are_reused_by_shape() {
        let first = scratch(3, 3);
        let address = first.as_ptr();
        drop(first);
        let again = scratch(3, 3);
        assert_eq!(again.as_ptr(), address);
        let other = scratch(3, 4);
        assert_ne!(other.as_ptr(), address);
        assert_eq!((other.nrows(), other.ncols()), (3, 4));
    }

    #[test]
    fn kept_matrices_leave_the_pool() {
        let kept = scratch(2, 2).into_mat();
        let next = scratch(2, 2);
        assert_ne!(next.as_ptr(), kept.as_ptr());
    }

    #[test]
    fn large_matrices_are_not_pooled() {
        let big = scratch(100, 100);
        let address = big.as_ptr();
        drop(big);
        let mut others = Vec::new();
        for _ in 0..3 {
            others.push(scratch(100, 100));
        }
        // Freed and reallocated: the pool never held it (the address may coincide by chance
        // in the allocator, so only the list length is checked).
        let _ = address;
        FREE_LIST.with(|list| {
            assert!(
                list.borrow()
                    .iter()
                    .all(|m| m.nrows() * m.ncols() <= MAX_POOLED_ENTRIES)
            )
        });
    }
}
