//! Riccati equations: the algebraic equation of the infinite-horizon regulator ([`care`]) and
//! the differential equation of the finite-horizon one ([`ode`]).

pub mod care;
pub mod dare;
pub mod ode;
