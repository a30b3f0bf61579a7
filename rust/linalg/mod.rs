//! Numerical kernels, knowing nothing of control: they take matrices and return matrices.
//!
//! * `matrix`: the one matrix type of the small-order kernels (nalgebra's, with the order a
//!   compile-time constant or known at run time) and the one dispatch between them;
//!   `small_matrix` and `dense`: products, solves and factorisations on it, for kernels whose
//!   arithmetic is cheaper than a general library's call.
//! * [`product`]: matrix products of any size that stop between column panels when the
//!   computation is interrupted.
//! * [`lu`]: LU factorisation with partial pivoting and linear solves, stopping between blocks
//!   of work when the computation is interrupted.
//! * [`norm`]: exact and estimated (Higham & Tisseur 2000) matrix 1-norms.
//! * [`hessenberg`]: the Hessenberg form and its transformation.
//! * [`hamiltonian`]: the squared eigenvalues of a Hamiltonian matrix with rank-one
//!   off-diagonal blocks, from one matrix of half its order.
//! * [`schur`]: the real Schur form (Francis double-shift QR, and small-bulge multishift QR with
//!   aggressive early deflation at large orders), its eigenvalues, and reordering.
//! * `polynomial_roots`: closed-form roots of polynomials of degree <= 4 (QR shifts).
//! * `sylvester`: small Sylvester equations, the kernel of reordering and of Bartels–Stewart.
//! * [`qz`]: the generalized real Schur form of a pencil (QZ) and its reordering.
//! * [`stein`]: the symmetric Stein (discrete Lyapunov) equation at small orders.
//! * [`lyapunov`]: the continuous Lyapunov equation.
//! * [`max_plus`]: the (max, +) product of matrices of log2 sizes and Karp's maximum cycle mean,
//!   for diagonal scalings by powers of two.
//! * [`expm`]: the matrix exponential, with double-double arithmetic where squarings amplify
//!   rounding.

pub(crate) mod balance;
pub mod charpoly;
pub(crate) mod dense;
pub mod expm;
pub mod hamiltonian;
pub mod hessenberg;
pub(crate) mod householder;
pub mod lu;
pub mod lyapunov;
pub(crate) mod matrix;
pub mod max_plus;
pub mod norm;
pub(crate) mod polynomial_roots;
pub mod product;
pub mod qr;
pub mod qz;
pub(crate) mod rotation;
pub mod schur;
pub(crate) mod small_matrix;

pub mod stein;
pub(crate) mod sylvester;
