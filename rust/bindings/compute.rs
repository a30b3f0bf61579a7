//! How a binding runs its computation: with the GIL held, released, or released and
//! interruptible, by its cost; after the memory it needs has been requested.
//!
//! * Work below [`DETACH_MIN_FLOPS`] (a 12 x 12 exponential) runs with the GIL held: releasing
//!   and re-acquiring it would cost more than other threads gain.
//! * Work below [`INTERRUPTIBLE_MIN_FLOPS`] (about a millisecond) runs with the GIL released.
//! * Longer work runs on a thread of rayon's pool while the calling thread waits with the GIL
//!   released and, every [`SIGNAL_POLL`], takes the GIL to run Python's signal handlers. If a
//!   handler raises (Ctrl-C: `KeyboardInterrupt`), the computation's interrupt token is
//!   cancelled, the calling thread waits for it to stop at its next check (a fraction of a
//!   second), and the handler's exception is raised. No computation outlives the call.
//!
//! Before any of this, the memory the computation will need is requested
//! ([`crate::platform::memory::reserve`]): a shortage is MemoryError before the work starts, not
//! an abort in the middle of it. A panic that escaped the core (a bug) becomes RuntimeError
//! instead of unwinding into the interpreter.

use super::errors::to_py_err;
use crate::error::Error;
use crate::platform::interrupt::{self, Token};
use crate::platform::memory;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::mpsc::{RecvTimeoutError, sync_channel};
use std::time::Duration;

/// Work (in floating-point operations) below which the GIL is kept.
pub const DETACH_MIN_FLOPS: f64 = 4e3;
/// Work above which the computation can be interrupted.
pub const INTERRUPTIBLE_MIN_FLOPS: f64 = 2e6;
/// How often a waiting caller runs Python's signal handlers.
pub const SIGNAL_POLL: Duration = Duration::from_millis(20);

/// The cost of a computation: its floating-point operations and the bytes of working memory it
/// will allocate (beyond its arguments and results), both estimates.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cost {
    pub flops: f64,
    pub bytes: f64,
}

impl Cost {
    /// A computation of `flops` operations on `matrices` temporaries of `order` x `order`.
    pub fn of(flops: f64, matrices: f64, order: usize) -> Self {
        let order = order as f64;
        Self {
            flops,
            bytes: matrices * order * order * 8.0,
        }
    }

    /// `count` computations of this cost one after another (the temporaries reused).
    pub fn times(self, count: usize) -> Self {
        Self {
            flops: self.flops * count.max(1) as f64,
            bytes: self.bytes,
        }
    }

    /// With `bytes` more of working memory.
    pub fn plus_bytes(self, bytes: f64) -> Self {
        Self {
            flops: self.flops,
            bytes: self.bytes + bytes,
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
    memory::reserve(bytes).map_err(|e| to_py_err(py, e))?;
    let outcome = if cost.flops < DETACH_MIN_FLOPS {
        guarded(f)?
    } else if cost.flops < INTERRUPTIBLE_MIN_FLOPS {
        py.detach(|| {
            guarded(|| {
                memory::ensure_product_workspace()?;
                f()
            })
        })?
    } else {
        return interruptible(py, f);
    };
    outcome.map_err(|e| to_py_err(py, e))
}

/// Runs `f` on rayon's pool with an interrupt token, while this thread runs Python's signal
/// handlers every [`SIGNAL_POLL`].
fn interruptible<T, F>(py: Python<'_>, f: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> Result<T, Error> + Send,
{
    let token = Arc::new(Token::default());
    let (outcome, interruption) = py.detach(|| {
        let (sender, receiver) = sync_channel(1);
        let job_token = token.clone();
        let mut interruption: Option<PyErr> = None;
        let outcome = rayon::in_place_scope(|scope| {
            scope.spawn(move |_| {
                let outcome = guarded(|| {
                    interrupt::within(Some(job_token), || {
                        memory::ensure_product_workspace()?;
                        f()
                    })
                });
                // The receiver waits for this message; it cannot be gone.
                let _ = sender.send(outcome);
            });
            loop {
                match receiver.recv_timeout(SIGNAL_POLL) {
                    Ok(outcome) => break outcome,
                    Err(RecvTimeoutError::Timeout) if interruption.is_none() => {
                        if let Err(error) = Python::attach(|py| py.check_signals()) {
                            token.cancel();
                            interruption = Some(error);
                        }
                    }
                    Err(RecvTimeoutError::Timeout) => {}
                    Err(RecvTimeoutError::Disconnected) => {
                        break Err(PyRuntimeError::new_err(
                            "internal error in aerocontrol: a computation ended without a result",
                        ));
                    }
                }
            }
        });
        (outcome, interruption)
    });
    if let Some(error) = interruption {
        return Err(error);
    }
    outcome?.map_err(|e| to_py_err(py, e))
}
