//! The number of threads parallel work runs on: rayon's global pool (`RAYON_NUM_THREADS`, else
//! one thread per core) unless a caller chose a count, for the process ([`set_num_threads`])
//! or for the calling thread ([`set_thread_num_threads`], which takes precedence), in which
//! case the work runs on a pool of that many threads. A process that runs several
//! computations side by side (a Dask worker's task threads, a multiprocessing pool) chooses
//! one or a few threads for each, so that together they do not oversubscribe the cores.
//!
//! Each pool records whether every one of its threads holds faer's product workspace
//! ([`crate::platform::memory::ensure_pool_product_workspace`]).

use crate::error::Error;
use std::cell::RefCell;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, RwLock};

/// A pool of threads chosen by [`set_num_threads`].
pub struct Pool {
    pub threads: rayon::ThreadPool,
    /// Whether every thread of the pool holds faer's product workspace.
    pub product_workspace: AtomicBool,
}

static CHOSEN: RwLock<Option<Arc<Pool>>> = RwLock::new(None);

thread_local! {
    /// The calling thread's own choice ([`set_thread_num_threads`]): None where it made none;
    /// Some(None) for rayon's global pool.
    static THREAD_CHOSEN: RefCell<Option<Option<Arc<Pool>>>> = const { RefCell::new(None) };
}

/// Whether every thread of rayon's global pool holds faer's product workspace.
pub static GLOBAL_PRODUCT_WORKSPACE: AtomicBool = AtomicBool::new(false);

/// The pool chosen for the calling thread ([`set_thread_num_threads`]), else for the process
/// ([`set_num_threads`]); None for rayon's global pool.
pub fn chosen() -> Option<Arc<Pool>> {
    if let Some(own) = THREAD_CHOSEN.with(|own| own.borrow().clone()) {
        return own;
    }
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
    let pool = chosen_pool(count)?;
    *CHOSEN
        .write()
        .unwrap_or_else(|poisoned| poisoned.into_inner()) = pool;
    Ok(())
}

/// [`set_num_threads`] for the parallel work the calling thread starts, whatever the process's
/// choice: Some(count) (0: rayon's global pool), or None to follow the process's choice
/// again.
pub fn set_thread_num_threads(count: Option<usize>) -> Result<(), Error> {
    let own = count.map(chosen_pool).transpose()?;
    THREAD_CHOSEN.with(|chosen| *chosen.borrow_mut() = own);
    Ok(())
}

/// The pool of `count` threads (None for 0: rayon's global pool), refusing more than
/// [`max_threads`].
fn chosen_pool(count: usize) -> Result<Option<Arc<Pool>>, Error> {
    let most = max_threads();
    if count > most {
        return Err(Error::InvalidArgument {
            arg: "count",
            message: format!(
                "count must be at most {most} (four threads per core, at least 256), got {count}"
            ),
        });
    }
    if count == 0 {
        Ok(None)
    } else {
        pool_of(count).map(Some)
    }
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

    #[test]
    fn a_thread_choice_is_the_threads_own() {
        // Another thread's choice does not change this one's, and follows the process's
        // choice again when cleared.
        std::thread::spawn(|| {
            set_thread_num_threads(Some(2)).unwrap();
            assert_eq!(num_threads(), 2);
            let other = std::thread::spawn(num_threads).join().unwrap();
            assert_eq!(other, rayon::current_num_threads());
            set_thread_num_threads(None).unwrap();
            assert_eq!(num_threads(), rayon::current_num_threads());
            assert!(set_thread_num_threads(Some(max_threads() + 1)).is_err());
        })
        .join()
        .unwrap();
    }
}
