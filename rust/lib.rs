//! aerocontrol: the numerical core of modern linear control of flight vehicles.
//!
//! This crate is the Rust half of the `aerocontrol` Python package, and a library in its own
//! right: every algorithm is a pure function on [faer] matrices that validates its arguments and
//! returns [`Result`]`<_, `[`Error`]`>`, never panicking on bad input. The PyO3 bindings live in
//! `bindings/`, behind the `python` cargo feature, so `cargo test` and `cargo bench` need no
//! Python.
//!
//! Equation numbers such as (6.22) refer to the course chapter "Control of Aircraft Motions"
//! that the project implements.
//!
//! # Layers
//!
//! Each layer uses only the layers below it:
//!
//! ```text
//! bindings   the Python module (feature `python`): arguments in, results out
//!    |
//! flight     flight vehicles: models from stability derivatives, MIL-F-8785C Levels of modes
//!    |
//! control    control algorithms on plain matrices: discretisation, responses, frequency
//!    |       responses, modes, controllability, pole placement, Riccati equations, batches
//! linalg     numerical kernels: small fixed-order matrices, LU, norms, Hessenberg and real
//!    |       Schur forms with reordering, Sylvester and Lyapunov equations, the exponential
//! platform   the machine: SIMD dispatch, scratch pools, the allocator, interruption, memory
//! ```
//!
//! [`error`] holds the one error type, shared by all layers.
//!
//! # Threads
//!
//! Functions that work on stacks of problems use rayon and say so; every faer kernel of the
//! single-problem functions runs with an explicit `Par` where it matters for speed, except
//! faer's convenience methods (`qr()`, `partial_piv_lu()`, `singular_values()`), which follow
//! faer's global parallelism. Its default (rayon) costs more in dispatch than a 4 x 4
//! factorisation takes, so callers of the Rust API should call
//! `faer::set_global_parallelism(faer::Par::Seq)` once, as the Python module does at import.

pub mod control;
pub mod error;
pub mod flight;
pub mod linalg;
pub mod platform;
#[cfg(test)]
mod test_matrices;

#[cfg(feature = "python")]
mod bindings;

pub use error::Error;

/// See [`platform::allocator`]: for the Python extension, and for benches that measure as it
/// runs.
#[cfg(feature = "small-block-allocator")]
#[global_allocator]
static ALLOCATOR: platform::allocator::SmallBlockAllocator =
    platform::allocator::SmallBlockAllocator;
