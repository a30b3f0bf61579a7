//! A per-thread free list of scratch matrices.
//!
//! The exponential of a matrix needs about twenty temporaries. For small matrices allocating
//! each costs more than the arithmetic; for large ones a fresh allocation comes from the
//! operating system as untouched pages, and the page faults on first write (a 256 x 256
//! temporary is 128 pages) cost a third of the exponential. Algorithms take their temporaries
//! with [`scratch`] and the matrix goes back to this thread's free list when dropped, so
//! repeated calls of one size allocate nothing. The list is bounded in bytes
//! ([`MAX_POOLED_BYTES`] per thread); a matrix that does not fit is freed.

use faer::Mat;
use std::cell::RefCell;
use std::ops::{Deref, DerefMut};

/// At most this many bytes of matrices wait in a thread's free list.
pub const MAX_POOLED_BYTES: usize = 32 << 20;
/// At most this many matrices wait in a thread's free list.
const MAX_POOLED_MATRICES: usize = 32;

fn bytes(m: &Mat<f64>) -> usize {
    m.nrows() * m.ncols() * std::mem::size_of::<f64>()
}

thread_local! {
    static FREE_LIST: RefCell<Vec<Mat<f64>>> = const { RefCell::new(Vec::new()) };
}

/// A scratch matrix that returns to the thread's free list when dropped.
pub struct Scratch(Option<Mat<f64>>);

/// A `rows` x `cols` scratch matrix. Its entries are unspecified: overwrite before reading.
pub fn scratch(rows: usize, cols: usize) -> Scratch {
    let pooled = FREE_LIST
        .try_with(|list| {
            let mut list = list.try_borrow_mut().ok()?;
            let position = list
                .iter()
                .position(|m| m.nrows() == rows && m.ncols() == cols)?;
            Some(list.swap_remove(position))
        })
        .ok()
        .flatten();
    Scratch(Some(pooled.unwrap_or_else(|| Mat::zeros(rows, cols))))
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
        // During thread teardown the list may be gone; the matrix is then simply freed.
        let _ = FREE_LIST.try_with(|list| {
            if let Ok(mut list) = list.try_borrow_mut() {
                let held: usize = list.iter().map(bytes).sum();
                if list.len() < MAX_POOLED_MATRICES && held + bytes(&m) <= MAX_POOLED_BYTES {
                    list.push(m);
                }
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
    fn the_pool_stays_within_its_byte_budget() {
        // 2048 x 2048 doubles are 32 MiB: one fits, a second does not.
        let (first, second) = (scratch(2048, 2048), scratch(2048, 2048));
        drop(first);
        drop(second);
        FREE_LIST.with(|list| {
            let held: usize = list.borrow().iter().map(bytes).sum();
            assert!(held <= MAX_POOLED_BYTES);
        });
    }
}
