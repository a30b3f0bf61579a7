//! What the numerical code needs from the machine: run-time choice of vectorised kernels, scratch
//! matrices, the allocator of the Python extension, interruption of long computations, memory
//! requested so that a shortage is an error, the plumbing of parallel loops, and the number of
//! threads they run on.

// Compiled for the unit tests too: they call the allocator directly, without installing it.
#[cfg(any(test, feature = "small-block-allocator"))]
pub mod allocator;
pub mod dispatch;
pub mod interrupt;
pub mod memory;
pub mod parallel;
pub mod pool;
pub mod threads;
