//! What the numerical code needs from the machine: interruption of long computations, memory
//! requested so that a shortage is an error, and the plumbing of parallel loops.

pub mod interrupt;
pub mod memory;
pub mod parallel;
