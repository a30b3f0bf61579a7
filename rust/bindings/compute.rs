//! How a binding runs its computation: with the GIL held, released, or on rayon's pool and
//! interruptible, by its cost; after the memory it needs has been requested.
//!
//! * Work below [`DETACH_MIN_FLOPS`] (some tens of microseconds) runs with the GIL held:
//!   releasing and re-acquiring it would cost more than other threads gain.
//! * Work below [`INTERRUPTIBLE_MIN_FLOPS`] (a few milliseconds) runs on the calling thread with
//!   the GIL released. It ends long before a Ctrl-C would be missed.
//! * Longer work runs on a thread of rayon's pool while the calling thread waits with the GIL
//!   released and, every [`SIGNAL_POLL`], takes the GIL to run Python's signal handlers. If a
//!   handler raises (Ctrl-C: `KeyboardInterrupt`), the computation's interrupt token is
//!   cancelled, the calling thread waits for it to stop at its next check (a fraction of a
//!   second), and the handler's exception is raised. No computation outlives the call. (Handing
//!   the work to another thread costs 0.1 to 0.2 ms, which is why shorter work stays.)
//!
//! Before any of this, the memory the computation will need is requested
//! ([`crate::platform::memory::reserve`]), and a thread that will multiply matrices larger than
//! [`SMALL_PRODUCT_MAX_ORDER`] takes faer's product workspace first (a calling thread that
//! cannot have it hands the work to the pool, whose threads may hold one already): a shortage is
//! MemoryError before the work starts, not an abort in the middle of it. A panic that escaped
//! the core (a bug) becomes RuntimeError instead of unwinding into the interpreter.

use super::errors::to_py_err;
use crate::error::Error;
use crate::platform::interrupt::{self, Token};
use crate::platform::memory::{self, SMALL_PRODUCT_MAX_ORDER};
use crate::platform::parallel::PARALLEL_MIN_ORDER;
use crate::platform::threads;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::mpsc::{RecvTimeoutError, sync_channel};
use std::time::Duration;

/// Work (in floating-point operations) below which the GIL is kept.
pub const DETACH_MIN_FLOPS: f64 = 2e5;
/// Work above which the computation can be interrupted.
pub const INTERRUPTIBLE_MIN_FLOPS: f64 = 1e7;
/// Working memory below this is not requested beforehand (mimalloc's small blocks: if they
/// cannot be had, neither can Python's own objects).
pub const RESERVE_MIN_BYTES: usize = 1 << 16;
/// How often a waiting caller runs Python's signal handlers.
pub const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// The cost of a computation: its floating-point operations, the bytes of working memory it
/// will allocate (beyond its arguments and results), both estimates, and the largest order of
/// the matrices it multiplies.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cost {
    pub flops: f64,
    pub bytes: f64,
    pub order: usize,
}

impl Cost {
    /// A computation of `flops` operations on `matrices` temporaries of `order` x `order`.
    pub fn of(flops: f64, matrices: f64, order: usize) -> Self {
        let size = order as f64;
        Self {
            flops,
            bytes: matrices * size * size * 8.0,
            order,
        }
    }

    /// A computation of `flops` operations on `bytes` of working memory that multiplies no
    /// matrices, so that it needs no product workspace.
    pub fn without_products(flops: f64, bytes: f64) -> Self {
        Self {
            flops,
            bytes,
            order: 0,
        }
    }

    /// `count` computations of this cost one after another (the temporaries reused).
    pub fn times(self, count: usize) -> Self {
        Self {
            flops: self.flops * count.max(1) as f64,
            ..self
        }
    }

    /// Both computations, one after the other.
    pub fn then(self, other: Cost) -> Self {
        Self {
            flops: self.flops + other.flops,
            bytes: self.bytes.max(other.bytes),
            order: self.order.max(other.order),
        }
    }
}

/// Runs `f`, turning a panic that escaped the core into RuntimeError.
fn guarded<T>(f: impl FnOnce() -> Result<T, Error>) -> Result<Result<T, Error>, PyErr> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        PyRuntimeError::new_err(format!("internal error in aerocontrol: {message}"))
    })
}

/// Runs the computation `f` as its `cost` warrants (see the module documentation).
pub fn compute<T, F>(py: Python<'_>, cost: Cost, f: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> Result<T, Error> + Send,
{
    let bytes = if cost.bytes.is_finite() && cost.bytes < usize::MAX as f64 {
        cost.bytes as usize
    } else {
        usize::MAX
    };
    if bytes >= RESERVE_MIN_BYTES {
        memory::reserve(bytes).map_err(|e| to_py_err(py, e))?;
    }
    let small_products = cost.order <= SMALL_PRODUCT_MAX_ORDER;
    // From a thread of the pool (Python code run by a computation, such as the `select` of a
    // Schur form) the work stays: a job of the pool must not wait for another.
    let on_pool = rayon::current_thread_index().is_some();
    let here = on_pool || cost.flops < INTERRUPTIBLE_MIN_FLOPS;
    let outcome = if cost.flops < DETACH_MIN_FLOPS && small_products {
        // (Not moved to a chosen pool: with the GIL held, a callback into Python from its
        // thread would wait for the GIL forever.)
        guarded(f)?
    } else if here
        && (small_products || on_pool || py.detach(memory::ensure_product_workspace).is_ok())
    {
        py.detach(|| {
            threads::install(|| {
                guarded(|| {
                    if !small_products {
                        memory::ensure_product_workspace()?;
                    }
                    f()
                })
            })
        })?
    } else {
        if cost.order >= PARALLEL_MIN_ORDER {
            // faer's kernels may run on every thread of the pool, if each can hold the product
            // workspace; else they run on one thread (`parallel_products_allowed`).
            let _ = py.detach(memory::ensure_pool_product_workspace);
        }
        return interruptible(py, small_products, f);
    };
    outcome.map_err(|e| to_py_err(py, e))
}

/// What the pool's thread sends back: the outcome, or the work itself when the thread cannot
/// take faer's product workspace.
enum Job<T, F> {
    Done(Result<Result<T, Error>, PyErr>),
    NoWorkspace(F, Error),
}

/// Runs `f` on rayon's pool with an interrupt token, while this thread runs Python's signal
/// handlers every [`SIGNAL_POLL`]. If the pool's thread cannot take the product workspace
/// that `f` needs (`small_products` false), the calling thread runs `f` itself, if it holds
/// one, without interruption.
fn interruptible<T, F>(py: Python<'_>, small_products: bool, f: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> Result<T, Error> + Send,
{
    let token = Token::default();
    let (job, interruption) = py.detach(|| {
        let (sender, receiver) = sync_channel(1);
        let job_token = &token;
        let mut interruption: Option<PyErr> = None;
        let job = threads::in_place_scope(|scope| {
            scope.spawn(move |_| {
                let job = match small_products {
                    false => memory::ensure_product_workspace().err(),
                    true => None,
                };
                let job = match job {
                    Some(error) => Job::NoWorkspace(f, error),
                    None => Job::Done(guarded(|| interrupt::within(job_token, f))),
                };
                // The receiver waits for this message; it cannot be gone.
                let _ = sender.send(job);
            });
            loop {
                match receiver.recv_timeout(SIGNAL_POLL) {
                    Ok(job) => break job,
                    Err(RecvTimeoutError::Timeout) if interruption.is_none() => {
                        if let Err(error) = Python::attach(|py| py.check_signals()) {
                            token.cancel();
                            interruption = Some(error);
                        }
                    }
                    Err(RecvTimeoutError::Timeout) => {}
                    Err(RecvTimeoutError::Disconnected) => {
                        break Job::Done(Err(PyRuntimeError::new_err(
                            "internal error in aerocontrol: a computation ended without a result",
                        )));
                    }
                }
            }
        });
        (job, interruption)
    });
    if let Some(error) = interruption {
        return Err(error);
    }
    let outcome = match job {
        Job::Done(outcome) => outcome,
        Job::NoWorkspace(f, error) if memory::has_product_workspace() => {
            drop(error);
            py.detach(|| guarded(f))
        }
        Job::NoWorkspace(_, error) => Ok(Err(error)),
    };
    outcome?.map_err(|e| to_py_err(py, e))
}

/// Runs parallel work on `count` threads from now on (0: rayon's global pool, of
/// `RAYON_NUM_THREADS` or one thread per core).
#[pyfunction]
pub fn set_num_threads(py: Python<'_>, count: usize) -> PyResult<()> {
    threads::set_num_threads(count).map_err(|e| to_py_err(py, e))
}

/// Runs the parallel work the calling thread starts on `count` threads (0: rayon's global
/// pool), whatever the process's choice; None follows the process's choice again.
#[pyfunction]
#[pyo3(signature = (count, /))]
pub fn set_thread_num_threads(py: Python<'_>, count: Option<usize>) -> PyResult<()> {
    threads::set_thread_num_threads(count).map_err(|e| to_py_err(py, e))
}

/// The number of threads parallel work runs on.
#[pyfunction]
pub fn get_num_threads() -> usize {
    threads::num_threads()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(set_thread_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(get_num_threads, m)?)?;
    Ok(())
}
