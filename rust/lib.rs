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
//! # Modules
//!
//! * [`expm`]: the matrix exponential and transition matrices Φ(t) = e^{At}, by Padé scaling and
//!   squaring (Al-Mohy & Higham 2009).
//! * [`discretize`]: Φ, Γ0 and Γ1 over a step by one exponential of an augmented matrix
//!   (Van Loan 1978), exact for singular A.
//! * [`response`]: time responses on a uniform grid, by one discretisation and a recurrence.
//! * [`freq`]: frequency responses through one Hessenberg reduction ([`hessenberg`]).
//! * [`modes`]: eigenvalues, modes and their characteristics, the characteristic polynomial.
//! * [`schur`]: the real Schur form and eigenvalues (Francis double-shift QR, and the
//!   small-bulge multishift QR with aggressive early deflation of `multishift` at large orders).
//! * [`ctrb`]: controllability and observability matrices and the staircase verdict.
//! * [`place`]: pole placement: Bass–Gura, Ackermann and the robust multi-input method.
//! * `polynomial_roots`: closed-form roots of polynomials of degree <= 4 (QR shifts).
//! * [`reorder`]: reordering of the real Schur form by direct block swaps (Bai & Demmel 1993).
//! * [`lyapunov`]: the continuous Lyapunov equation by Bartels–Stewart.
//! * [`care`]: the algebraic Riccati equation by the Hamiltonian ordered-Schur method, and LQR.
//! * [`riccati_ode`]: the Riccati differential equation of finite-horizon LQR.
//! * [`batch`]: the same operations over stacks of problems, in parallel.
//! * [`norm`]: exact and estimated (Higham & Tisseur 2000) matrix 1-norms.
//! * [`lu`]: linear solves by LU with partial pivoting.
//! * `dense`: small dense temporaries, lent to faer as views.
//! * [`small_matrix`]: fixed-size stack matrices for the small orders of flight models.
//! * [`double_double`]: double-double arithmetic, for results accurate beyond double precision.
//! * [`pool`]: a per-thread free list of scratch matrices.
//! * [`platform`]: cooperative interruption of long computations, and memory requested so that
//!   a shortage is an error rather than an abort.
//! * `allocator` (feature `small-block-allocator`, on in the Python extension): mimalloc for
//!   small blocks as the global allocator.
//! * [`dispatch`]: run-time choice of AVX2 + FMA kernels.
//! * [`error`]: the error type and the argument checks.
//!
//! # Threads
//!
//! Functions that work on stacks of problems use rayon and say so; every faer kernel of the
//! single-problem functions runs with an explicit `Par::Seq` where it matters for speed, except
//! faer's convenience methods (`qr()`, `partial_piv_lu()`, `singular_values()`), which follow
//! faer's global parallelism. Its default (rayon) costs more in dispatch than a 4 x 4
//! factorisation takes, so callers of the Rust API should call
//! `faer::set_global_parallelism(faer::Par::Seq)` once, as the Python module does at import.
//!
//! # Which linear algebra library where
//!
//! faer does all dense kernels: products, LU, and later QR, Hessenberg and eigenvalues. It is
//! fast from n = 4 to n = 1024 and lets us pick sequential or parallel execution per call, which
//! the batch kernels need. nalgebra is not used yet; it enters only where it serves better
//! (small fixed-size blocks).

#[cfg(feature = "small-block-allocator")]
pub mod allocator;
pub mod batch;
pub mod care;
pub mod ctrb;
mod dense;
pub mod discretize;
pub mod dispatch;
pub mod double_double;
pub mod error;
pub mod expm;
pub mod freq;
pub mod hessenberg;
pub mod lu;
pub mod lyapunov;
pub mod modes;
mod multishift;
pub mod norm;
pub mod place;
pub mod platform;
mod polynomial_roots;
pub mod pool;
pub mod reorder;
pub mod response;
pub mod riccati_ode;
pub mod schur;
pub mod small_matrix;
mod sylvester;
#[cfg(test)]
mod test_matrices;

#[cfg(feature = "python")]
mod bindings;

pub use error::Error;

/// See [`allocator`]: for the Python extension, and for benches that measure as it runs.
#[cfg(feature = "small-block-allocator")]
#[global_allocator]
static ALLOCATOR: allocator::SmallBlockAllocator = allocator::SmallBlockAllocator;
