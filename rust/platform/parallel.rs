//! Parallel loops over the problems of a batch: the context their items take from the thread
//! that started them, and chunking that stays whole when the chunks are empty.

use super::interrupt::{self, TokenRef};
use super::memory;
use crate::error::Error;
use rayon::iter::Either;
use rayon::prelude::*;

/// What the items of a parallel loop take from the thread that started it: the interrupt token
/// of its computation, and the largest order of the matrices they multiply. Each item runs
/// through [`ParallelContext::run`], which installs the token on the item's thread, stops if the
/// computation was interrupted, and, if the items multiply matrices too large for faer's
/// small-product kernel, makes sure the thread holds faer's product workspace first.
#[derive(Debug, Clone, Default)]
pub struct ParallelContext {
    token: Option<TokenRef>,
    product_order: usize,
}

impl ParallelContext {
    /// The context of the calling thread's computation, for items that multiply matrices of
    /// order at most `product_order`.
    pub fn capture(product_order: usize) -> Self {
        Self {
            token: interrupt::current(),
            product_order,
        }
    }

    /// Runs one item of the loop on the current thread.
    pub fn run<T>(&self, item: impl FnOnce() -> Result<T, Error>) -> Result<T, Error> {
        interrupt::within_ref(self.token, || {
            interrupt::check()?;
            if self.product_order > memory::SMALL_PRODUCT_MAX_ORDER {
                memory::ensure_product_workspace()?;
            }
            item()
        })
    }
}

/// Matrices of at least this order use faer's multithreaded kernels (products, LU, the
/// Hessenberg reduction) within a single problem.
pub const PARALLEL_MIN_ORDER: usize = 400;

/// The threading of faer's kernels on matrices of order n: parallel from
/// [`PARALLEL_MIN_ORDER`], once every thread of the pool holds faer's product workspace
/// ([`memory::parallel_products_allowed`]).
pub fn parallelism_for_order(n: usize) -> faer::Par {
    if n >= PARALLEL_MIN_ORDER && memory::parallel_products_allowed() {
        faer::Par::rayon(0)
    } else {
        faer::Par::Seq
    }
}

/// A batch whose problems' total work count · n³ is below this runs on the calling thread:
/// splitting it costs a wake-up of rayon's pool (several microseconds, more on a loaded
/// machine) for about as much work (sixty-four 4 x 4 exponentials, eight of order 8).
pub const SEQUENTIAL_MAX_WORK: usize = 4096;

/// The fewest items a task of a parallel loop over `count` problems of order `n` takes, for
/// rayon's `with_min_len`: all of them (one task, run on the calling thread without touching
/// the pool) when count · n³ is below [`SEQUENTIAL_MAX_WORK`], else 1.
pub fn min_items_per_task(count: usize, n: usize) -> usize {
    let work = count.saturating_mul(n.saturating_pow(3));
    if work < SEQUENTIAL_MAX_WORK {
        count.max(1)
    } else {
        1
    }
}

/// The `count` consecutive chunks of `size` entries of `data` (which holds `count * size`), as
/// an indexed parallel iterator: `count` empty slices when `size` is 0, where rayon's
/// `par_chunks_mut` would yield none (and panics for a size of 0).
pub fn par_chunks<T: Send>(
    data: &mut [T],
    size: usize,
    count: usize,
) -> impl IndexedParallelIterator<Item = &mut [T]> {
    debug_assert_eq!(data.len(), size * count);
    if size == 0 {
        Either::Left((0..count).into_par_iter().map(|_| <&mut [T]>::default()))
    } else {
        Either::Right(data.par_chunks_mut(size))
    }
}

/// The sequential counterpart of [`par_chunks`].
pub fn chunks<T>(data: &mut [T], size: usize, count: usize) -> impl Iterator<Item = &mut [T]> {
    debug_assert_eq!(data.len(), size * count);
    let (empty, full) = if size == 0 {
        (count, None)
    } else {
        (0, Some(data.chunks_mut(size)))
    };
    std::iter::repeat_with(<&mut [T]>::default)
        .take(empty)
        .chain(full.into_iter().flatten())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_batches_stay_on_the_calling_thread() {
        let caller = std::thread::current().id();
        let mut out = [0u8; 8];
        out.par_chunks_mut(1)
            .with_min_len(min_items_per_task(8, 4))
            .for_each(|_| assert_eq!(std::thread::current().id(), caller));
        assert_eq!(min_items_per_task(8, 4), 8);
        assert_eq!(min_items_per_task(64, 4), 1);
        assert_eq!(min_items_per_task(1, 16), 1);
        assert_eq!(min_items_per_task(0, 4), 1);
    }

    #[test]
    fn empty_chunks_keep_their_count() {
        let mut empty: Vec<f64> = vec![];
        assert_eq!(par_chunks(&mut empty, 0, 5).count(), 5);
        assert_eq!(chunks(&mut empty, 0, 5).count(), 5);
        let mut data: Vec<usize> = (0..6).collect();
        let sums: Vec<usize> = par_chunks(&mut data, 2, 3)
            .map(|c| c.iter().sum())
            .collect();
        assert_eq!(sums, [1, 5, 9]);
        let lengths: Vec<usize> = chunks(&mut data, 3, 2).map(|c| c.len()).collect();
        assert_eq!(lengths, [3, 3]);
    }

    #[test]
    fn items_stop_once_interrupted() {
        let token = interrupt::Token::default();
        interrupt::within(&token, || {
            let context = ParallelContext::capture(4);
            assert_eq!(context.run(|| Ok(1)), Ok(1));
            token.cancel();
            assert_eq!(context.run(|| Ok(1)), Err(Error::Interrupted));
        });
    }
}
