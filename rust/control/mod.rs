//! Control algorithms on plain matrices: what the chapter and the design loop compute.
//!
//! * [`discretize`]: Φ, Γ0 and Γ1 over a step by one exponential of an augmented matrix
//!   (Van Loan 1978), exact for singular A.
//! * [`responses`]: time responses on a uniform grid, by one discretisation and a recurrence.
//! * [`frequency`]: frequency responses through one Hessenberg reduction.
//! * [`modal`]: eigenvalues, modes and their characteristics, the modal matrix.
//! * [`partial_fraction`]: the partial-fraction form of a model, for frequency responses at
//!   many points.
//! * [`controllability`]: controllability and observability matrices, the staircase and modal
//!   verdicts.
//! * [`placement`]: pole placement: Bass–Gura, Ackermann and the robust multi-input method.
//! * [`riccati`]: the algebraic Riccati equation and LQR, and the Riccati differential equation.
//! * [`root_locus`]: the closed-loop poles of a SISO loop over many gains, from one
//!   controller-Hessenberg form.
//! * [`transfer`]: transfer functions of SISO channels from the state space, and their
//!   factored evaluation.
//! * [`batch`]: the same operations over stacks of problems, in parallel.

pub mod batch;
pub mod controllability;
pub mod discretize;
pub mod frequency;
pub mod margins;
pub mod modal;
pub mod partial_fraction;
pub mod placement;
pub mod responses;
pub mod riccati;
pub mod root_locus;
pub mod transfer;
