//! Riccati equations: the algebraic equation of the infinite-horizon regulator ([`care`]) and
//! the differential equation of the finite-horizon one ([`ode`]).

pub mod care;
pub(crate) mod care_pencil;
pub mod dare;
pub mod ode;
pub(crate) mod pencil;
