//! The number of threads parallel work runs on: rayon's global pool (`RAYON_NUM_THREADS`, else
//! one thread per core) unless a caller chose a count ([`set_num_threads`]), in which case the
//! work runs on a pool of that many threads. A process that runs several computations side by
//! side (a Dask worker, a multiprocessing pool) chooses one or a few threads for each, so that
//! together they do not oversubscribe the cores.
//!
//! Each pool records whether every one of its threads holds faer's product workspace
//! ([`crate::platform::memory::ensure_pool_product_workspace`]).

use crate::error::Error;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, RwLock};

/// A pool of threads chosen by [`set_num_threads`].
pub struct Pool {
    pub threads: rayon::ThreadPool,
    /// Whether every thread of the pool holds faer's product workspace.
    pub product_workspace: AtomicBool,
}

static CHOSEN: RwLock<Option<Arc<Pool>>> = RwLock::new(None);

/// Whether every thread of rayon's global pool holds faer's product workspace.
pub static GLOBAL_PRODUCT_WORKSPACE: AtomicBool = AtomicBool::new(false);

/// The pool chosen by [`set_num_threads`], None for rayon's global pool.
pub fn chosen() -> Option<Arc<Pool>> {
    CHOSEN
        .read()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
        .clone()
}

/// The most threads [`set_num_threads`] starts: four per core, and at least 256 (more only
/// oversubscribe the cores, and starting millions would exhaust the machine).
pub fn max_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    cores.saturating_mul(4).max(256)
}

/// Runs parallel work on `count` threads from now on; 0 returns to rayon's global pool.
/// Computations already running finish on the pool they started on.
pub fn set_num_threads(count: usize) -> Result<(), Error> {
    let most = max_threads();
    if count > most {
        return Err(Error::InvalidArgument {
            arg: "count",
            message: format!(
                "count must be at most {most} (four threads per core, at least 256), got {count}"
            ),
        });
    }
    let pool = if count == 0 {
        None
    } else {
        Some(pool_of(count)?)
    };
    *CHOSEN
        .write()
        .unwrap_or_else(|poisoned| poisoned.into_inner()) = pool;
    Ok(())
}

/// The pools started so far, at most [`KEPT_POOLS`], the most recently chosen last: choosing
/// a count again (a `with limit_threads(n)` block in a loop) reuses its pool and the threads'
/// product workspaces instead of starting new threads.
static STARTED: Mutex<Vec<Arc<Pool>>> = Mutex::new(Vec::new());
const KEPT_POOLS: usize = 4;

/// A pool of `count` threads: one started before, else a new one.
fn pool_of(count: usize) -> Result<Arc<Pool>, Error> {
    let mut started = STARTED
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let pool = match started
        .iter()
        .position(|pool| pool.threads.current_num_threads() == count)
    {
        Some(position) => started.remove(position),
        None => {
            let threads = rayon::ThreadPoolBuilder::new()
                .num_threads(count)
                .thread_name(|index| format!("aerocontrol-{index}"))
                .build()
                .map_err(|error| Error::InvalidArgument {
                    arg: "count",
                    message: format!("cannot start {count} threads: {error}"),
                })?;
            Arc::new(Pool {
                threads,
                product_workspace: AtomicBool::new(false),
            })
        }
    };
    started.push(Arc::clone(&pool));
    if started.len() > KEPT_POOLS {
        started.remove(0);
    }
    Ok(pool)
}

/// The number of threads parallel work started now would run on.
pub fn num_threads() -> usize {
    if rayon::current_thread_index().is_some() {
        return rayon::current_num_threads();
    }
    chosen().map_or_else(rayon::current_num_threads, |pool| {
        pool.threads.current_num_threads()
    })
}

/// Runs `f` so that its parallel loops use the chosen pool: on a thread of that pool, or
/// where it is called when no count was chosen or it is already on a pool's thread.
pub fn install<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    match chosen() {
        Some(pool) if rayon::current_thread_index().is_none() => pool.threads.install(f),
        _ => f(),
    }
}

/// [`rayon::in_place_scope`] on the chosen pool: `op` runs on the calling thread and what it
/// spawns runs on that pool.
pub fn in_place_scope<'scope, R>(op: impl FnOnce(&rayon::Scope<'scope>) -> R) -> R {
    match chosen() {
        Some(pool) => pool.threads.in_place_scope(op),
        None => rayon::in_place_scope(op),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn work_runs_on_the_chosen_number_of_threads() {
        set_num_threads(3).unwrap();
        assert_eq!(num_threads(), 3);
        let seen = install(|| {
            (0..64)
                .into_par_iter()
                .map(|_| rayon::current_num_threads())
                .max()
        });
        assert_eq!(seen, Some(3));
        set_num_threads(0).unwrap();
        assert_eq!(num_threads(), rayon::current_num_threads());
        assert!(set_num_threads(max_threads() + 1).is_err());
        assert_eq!(num_threads(), rayon::current_num_threads());
    }
}
