"""Optimal control: the algebraic and differential Riccati equations and LQR (chapter §6.6),
and the Lyapunov equation that Newton's method for the Riccati equation solves at each step.

The regulator that minimises J = ∫ (x^T Q x + η^T R η) dt (6.190) is η = -K x with
K = R^-1 B^T S (6.200), where S solves the Riccati differential equation (6.196) backward from
S(t_f) = S_f, or, for an infinite horizon, the algebraic equation (6.199).

* :func:`solve_care`: the algebraic equation in the general form of MATLAB's care (6.228),
  with a cross weight S and a descriptor matrix E, by the Hamiltonian ordered-Schur method
  (scaled, then refined by Newton's method), with its residual and conditioning;
* :func:`lqr`: python-control's ``lqr`` call and return convention, (K, S, E);
* :func:`solve_dare` and :func:`dlqr`: the discrete-time equation and regulator, by the
  extended symplectic pencil and the QZ algorithm;
* :func:`solve_lyapunov`: A X + X A^T + Q = 0 by Bartels-Stewart;
* :func:`riccati_ode` and :func:`lqr_finite`: the finite-horizon solution S(t) and gain K(t)
  on a time grid, exact up to rounding at any step (the Hamiltonian transition matrix,
  re-normalised every step);
* :func:`riccati_difference` and :func:`dlqr_finite`: the discrete finite-horizon solution S_k
  and gain K_k over a number of steps (the Riccati difference equation in Joseph form).
"""

from __future__ import annotations

import operator
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._results import Result, Tabular, format_complex, format_number
from ._validation import FloatArray, real_array
from .exceptions import (
    IllConditionedWarning,
    InvalidArgumentError,
)
from .statespace import (
    as_state_space,
    is_system,
    matrix_view,
    require_continuous,
    require_discrete,
)

_FLOAT64 = np.dtype(np.float64)

if TYPE_CHECKING:
    from ._typing import SystemObject

__all__ = [
    "CareSolution",
    "DareSolution",
    "RiccatiDifferenceSolution",
    "RiccatiSolution",
    "dlqr",
    "dlqr_finite",
    "lqr",
    "lqr_finite",
    "riccati_difference",
    "riccati_ode",
    "solve_care",
    "solve_dare",
    "solve_lyapunov",
]

ComplexArray = NDArray[np.complex128]

#: rcond(U11) below which the solution is flagged: about half the digits of X may be lost
#: to the basis of the invariant subspace before refinement.
RCOND_WARNING = 1e-8
#: Relative residual above which the solution is flagged.
RESIDUAL_WARNING = 1e-8


@dataclass(frozen=True, eq=False)
class CareSolution(Result):
    """The stabilising solution of a continuous algebraic Riccati equation.

    The equation is A^T X E + E^T X A - (E^T X B + S) R^-1 (B^T X E + S^T) + Q = 0 (6.228),
    with E = I and S = 0 by default.

    Attributes
    ----------
    X : ndarray (n, n)
        The stabilising solution, symmetric.
    K : ndarray (m, n)
        The optimal gain R^-1 (B^T X E + S^T) (6.200); u = -K x.
    closed_loop_poles : ndarray (n,), complex
        The eigenvalues of (A - B K, E) (rad/s), all with Re < 0; pairs adjacent, Im > 0 first.
    residual : float
        The relative residual ||Res||_F / (||Q||_F + 2 ||A^T X E||_F + ||(E^T X B + S) K||_F);
        above ``RESIDUAL_WARNING`` (1e-8) the solution is flagged.
    rcond : float
        Reciprocal 1-norm condition number of U11, the top half of the stable invariant
        subspace's basis: small means X is sensitive (flagged below ``RCOND_WARNING``, 1e-8).
    refinement_steps : int
        Newton steps taken after the Schur solution.

    Examples
    --------
    The double integrator with Q = I and R = 1 has X = [[√3, 1], [1, √3]] and K = [1, √3]:

    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.solve_care([[0, 1], [0, 0]], [[0], [1]], np.eye(2), [[1.0]])
    >>> np.round(sol.X, 6)
    array([[1.732051, 1.      ],
           [1.      , 1.732051]])
    >>> np.round(sol.K, 6)
    array([[1.      , 1.732051]])
    >>> np.round(sol.closed_loop_poles, 6)              # s^2 + √3 s + 1 = 0
    array([-0.866025+0.5j, -0.866025-0.5j])
    >>> bool(sol.residual < 1e-14)
    True
    """

    X: FloatArray
    """The stabilising solution, symmetric, n x n."""
    K: FloatArray
    """The optimal gain R^-1 (B^T X E + S^T), m x n (6.200)."""
    closed_loop_poles: ComplexArray
    """The eigenvalues of (A - B K, E), all with Re < 0; pairs adjacent, Im > 0 first."""
    residual: float
    """||Res||_F / (||Q||_F + 2 ||A^T X E||_F + ||(E^T X B + S) K||_F)."""
    rcond: float
    """Reciprocal 1-norm condition number of U11, the top half of the stable invariant
    subspace's basis: small means X is sensitive."""
    refinement_steps: int
    """Newton steps taken after the Schur solution."""

    def _tables(self) -> list[Tabular]:
        return _solution_tables(self, "continuous")


def _solution_tables(solution: CareSolution | DareSolution, kind: str) -> list[Tabular]:
    """The gain K and the closed-loop poles of a Riccati solution, for a notebook."""
    title = (
        f"{kind} algebraic Riccati equation: relative residual {solution.residual:.2e}, "
        f"rcond {solution.rcond:.2e}, {solution.refinement_steps} Newton step(s)"
    )
    gain = [(f"u{i + 1}", *(format_number(v, 6) for v in row)) for i, row in enumerate(solution.K)]
    header = ("K", *(f"x{j + 1}" for j in range(solution.K.shape[1])))
    poles = [(format_complex(complex(p), 6),) for p in solution.closed_loop_poles]
    return [Tabular(title, header, gain), Tabular("", ("closed-loop poles",), poles)]


def solve_care(
    A: ArrayLike,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    S: ArrayLike | None = None,
    E: ArrayLike | None = None,
    refine: bool = True,
) -> CareSolution:
    """The stabilising solution of the continuous algebraic Riccati equation (6.199, 6.228).

    Solves A^T X E + E^T X A - (E^T X B + S) R^-1 (B^T X E + S^T) + Q = 0 for the X that
    makes every eigenvalue of (A - B K, E) stable, K = R^-1 (B^T X E + S^T).

    Method: the Hamiltonian matrix [[Ā, -G], [-Q̄, -Ā^T]] of the equation reduced to E = I,
    S = 0 (Ā = E^-1 A - B̂ Ŝ^T, G = B̂ B̂^T with B̂ = E^-1 B L^-T, R = L L^T), scaled by exact
    powers of two that balance it and keep it Hamiltonian; its real Schur form, reordered to
    put the stable eigenvalues first; X from the stable invariant subspace [U11; U21] as
    U21 U11^-1 by an LU solve; then Newton (Kleinman) steps, each a Lyapunov solve (the first
    through the closed loop's factors V T11 V^-1 that the Hamiltonian's Schur form already
    gives, so without a Schur form of its own), while the residual decreases and is above 4 u
    (relative). On the 747's lateral regulator over c = 1e-3..10 the relative error of X
    against 50-digit solutions is then 1.8 u in the median and 12.6 u at worst (scipy's: 15 u
    and 82 u; python-control's: 70 u and 628 u).
    Where the states are measured in units 1e3 or more apart, the equation is first taken
    to balanced states by an exact diagonal similarity of powers of two (x = T x̃:
    T^-1 A T, T^-1 B, T Q T, T S, T^-1 E T), solved there, and X and K taken back; the
    residual reported is that of the equation as given.

    Parameters
    ----------
    A, Q : array_like (n, n); a scalar is 1 x 1
    B : array_like (n, m); a 1-D B is a single input (a column)
    R : array_like (m, m), symmetric and nonsingular
        Positive definite: the Hamiltonian method above. Indefinite (as the H-infinity
        equations have): the extended Hamiltonian pencil of order 2n + m, compressed and
        reduced by aerocontrol's QZ algorithm (:func:`~aerocontrol.qz`), X = U21 (E U11)^-1
        from its stable deflating subspace, with the same checks (no refinement); the
        equation is first scaled exactly as above, and also where B or the weights alone are
        far from 1 (the pencil's identity blocks set its scale).
    S : array_like (n, m), optional; the cross weight (python-control's N)
    E : array_like (n, n), optional; nonsingular
    refine : bool, optional
        Newton refinement (default True).

    Returns
    -------
    CareSolution
        The stabilising solution ``X``, the gain ``K``, the closed-loop eigenvalues, the
        relative residual, rcond(U11) and the number of Newton steps taken.

    Raises
    ------
    ShapeError
        A, Q or E is not square, or B, R, S disagree in size with A (the message names the
        argument).
    NonFiniteError
        An argument contains NaN or an infinity.
    NotRealError
        An argument is complex or not numeric.
    NotPositiveDefiniteError
        R is not symmetric.
    InvalidArgumentError
        R is singular to working precision.
    NoStabilizingSolutionError
        The Hamiltonian has eigenvalues on the imaginary axis to working precision: some
        undamped mode is neither controllable nor penalised; or the computed solution leaves
        an eigenvalue of A - B K in Re >= 0 (stable and unstable eigenvalues of the Hamiltonian
        too ill-conditioned to be told apart).
    IllConditionedError
        U11 is singular: (A, B) is not stabilisable or (Q, A) not detectable.

    Warns
    -----
    IllConditionedWarning
        rcond(U11) < 1e-8 or relative residual > 1e-8.

    Examples
    --------
    The chapter's inverted pendulum (6.202)-(6.218), γ = 1, c = 1:

    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.solve_care([[0, 1], [1, 0]], [[0], [1]], np.diag([1.0, 0.0]), [[1.0]])
    >>> np.round(sol.K, 6)                       # [γ + √2, √2 (γ + √2)^½]
    array([[2.414214, 2.197368]])
    >>> bool(sol.residual < 1e-15)
    True
    """
    # The frozen dataclass's __init__ sets each field through object.__setattr__, which costs
    # a tenth of a 4-state solve; filling the instance dictionary directly is the same object.
    X, K, poles, residual, rcond, steps = _solve_care(A, B, Q, R, S, E, refine)
    solution = object.__new__(CareSolution)
    vars(solution).update(
        X=X, K=K, closed_loop_poles=poles, residual=residual, rcond=rcond, refinement_steps=steps
    )
    return solution


def _solve_care(
    A: ArrayLike,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    S: ArrayLike | None,
    E: ArrayLike | None,
    refine: bool,
    cross: str = "S",
) -> tuple[FloatArray, FloatArray, ComplexArray, float, float, int]:
    """The native solve, as (X, K, poles, residual, rcond, steps), warning (at the caller of
    :func:`solve_care` or :func:`lqr`) when the solution may be inaccurate. ``cross`` is the
    caller's name of the cross weight (N for lqr), used in errors."""
    # The core shapes the weights (a scalar R as 1 x 1, as numpy.atleast_2d); A and B are
    # read here (a scalar as 1 x 1, a 1-D B as a column).
    A_matrix, B_matrix = matrix_view(A, "A"), matrix_view(B, "B")
    result = _core.solve_care(A_matrix, B_matrix, Q, R, S, E, bool(refine), cross == "N")
    rcond, residual = result[4], result[3]
    if rcond < RCOND_WARNING or residual > RESIDUAL_WARNING:
        warnings.warn(
            f"the Riccati solution may be inaccurate: rcond(U11) = {rcond:.2e}, relative "
            f"residual {residual:.2e} (the closed loop is close to losing stabilisability "
            "or detectability, or the weights differ by many orders of magnitude)",
            IllConditionedWarning,
            stacklevel=3,
        )
    return result


def lqr(
    sys_or_A: ArrayLike | SystemObject, *args: ArrayLike, N: ArrayLike | None = None
) -> tuple[FloatArray, FloatArray, ComplexArray]:
    """The linear-quadratic regulator, called and returning as python-control's ``lqr``.

    ``lqr(sys, Q, R)``, ``lqr(A, B, Q, R)`` or ``lqr(A, B, Q, R, N)`` minimise
    J = ∫ (x^T Q x + η^T R η + 2 x^T N η) dt (6.190) for x' = A x + B η; K = R^-1 (B^T S + N^T)
    (6.200) with S the stabilising solution of the algebraic Riccati equation (6.199).

    Parameters
    ----------
    sys_or_A : StateSpace or array_like (n, n)
        A continuous-time system (its A and B are used), or the plant matrix A.
    *args : array_like
        With a system: ``Q, R[, N]``. With a matrix: ``B, Q, R[, N]``: B (n, m), the state
        weight Q (n, n), the control weight R (m, m) (positive definite), the cross weight
        N (n, m).
    N : array_like (n, m), optional
        The cross weight, by keyword (default none, i.e. zero).

    Returns
    -------
    K : ndarray (m, n)
        The gain of η = -K x.
    S : ndarray (n, n)
        The solution of the Riccati equation.
    E : ndarray (n,) of complex128
        The closed-loop eigenvalues, eig(A - B K).

    Raises
    ------
    InvalidArgumentError
        The wrong number of matrices, N given both by position and by keyword, or R singular.
        Also a discrete-time system (use :func:`dlqr`).
    ShapeError, NonFiniteError, NotRealError, NotPositiveDefiniteError
        As :func:`solve_care`: a matrix of the wrong size, with NaN or infinite entries,
        complex, or an R that is not symmetric.
    NoStabilizingSolutionError
        Some undamped mode is neither controllable nor penalised by Q.
    IllConditionedError
        (A, B) is not stabilisable or (Q, A) not detectable.

    Warns
    -----
    IllConditionedWarning
        As :func:`solve_care`.

    See Also
    --------
    solve_care : the method, the errors and the diagnostics (which ``lqr`` drops, as
        python-control does; call :func:`solve_care` to see them).

    Examples
    --------
    The 747's lateral regulator (6.224)-(6.227), c = 1:

    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()
    >>> K, S, E = aerocontrol.lqr(A, B, np.eye(4), np.eye(2))
    >>> bool(np.all(E.real < 0))
    True

    The chapter's inverted pendulum (6.218), γ = 1, c = 1:

    >>> K, S, E = aerocontrol.lqr([[0, 1], [1, 0]], [[0], [1]], np.diag([1.0, 0.0]), [[1.0]])
    >>> np.round(K, 6)
    array([[2.414214, 2.197368]])
    """
    A, B, Q, R, N = _regulator_arguments("lqr", sys_or_A, args, N)
    result = _solve_care(A, B, Q, R, N, None, True, "N")
    return result[1], result[0], result[2]


@dataclass(frozen=True, eq=False)
class DareSolution(Result):
    """The stabilising solution of a discrete algebraic Riccati equation.

    The equation is A^T X A - E^T X E - (A^T X B + S)(R + B^T X B)^-1 (B^T X A + S^T) + Q = 0,
    with E = I and S = 0 by default.

    Attributes
    ----------
    X : ndarray (n, n)
        The stabilising solution, symmetric.
    K : ndarray (m, n)
        The optimal gain (R + B^T X B)^-1 (B^T X A + S^T); u[k] = -K x[k].
    closed_loop_poles : ndarray (n,), complex
        The eigenvalues of (A - B K, E), all with modulus below 1.
    residual : float
        The relative residual ||Res||_F / (||Q||_F + ||A^T X A||_F + ||E^T X E||_F +
        ||(B^T X A + S^T)^T K||_F); above ``RESIDUAL_WARNING`` (1e-8) the solution is flagged.
    rcond : float
        Reciprocal 1-norm condition number of E U11 (U11 the top half of the stable deflating
        subspace's basis): small means X is sensitive.
    refinement_steps : int
        Newton steps taken after the Schur solution.

    Examples
    --------
    For the scalar x[k+1] = 2 x[k] + u[k] with Q = R = 1, X solves x^2 - 4x - 1 = 0 and the gain
    is the golden ratio:

    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.solve_dare([[2.0]], [[1.0]], [[1.0]], [[1.0]])
    >>> np.round(sol.X, 6), np.round(sol.K, 6)               # 2 + √5, (1 + √5)/2
    (array([[4.236068]]), array([[1.618034]]))
    >>> np.round(sol.closed_loop_poles.real, 6)
    array([0.381966])
    """

    X: FloatArray
    """The stabilising solution, symmetric, n x n."""
    K: FloatArray
    """The optimal gain (R + B^T X B)^-1 (B^T X A + S^T), m x n."""
    closed_loop_poles: ComplexArray
    """The eigenvalues of (A - B K, E), all with abs(z) < 1."""
    residual: float
    """||Res||_F / (||Q||_F + ||A^T X A||_F + ||E^T X E||_F + ||(B^T X A + S^T)^T K||_F)."""
    rcond: float
    """Reciprocal 1-norm condition number of E U11 (U11 the top half of the stable deflating
    subspace's basis): small means X is sensitive."""
    refinement_steps: int
    """Newton steps taken after the pencil's solution."""

    def _tables(self) -> list[Tabular]:
        return _solution_tables(self, "discrete")


def solve_dare(
    A: ArrayLike,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    S: ArrayLike | None = None,
    E: ArrayLike | None = None,
) -> DareSolution:
    """The stabilising solution of the discrete algebraic Riccati equation.

    Solves A^T X A - E^T X E - (A^T X B + S)(R + B^T X B)^-1 (B^T X A + S^T) + Q = 0 for the X
    that puts every eigenvalue of (A - B K, E) inside the unit circle,
    K = (R + B^T X B)^-1 (B^T X A + S^T) (MATLAB's dare; scipy's solve_discrete_are).

    Method: the extended symplectic pencil of order 2n + m (Van Dooren 1981), its last m
    columns compressed away by a QR factorisation, then aerocontrol's own QZ algorithm
    (:func:`~aerocontrol.qz`) reordered to put the eigenvalues inside the unit circle first;
    X = U21 (E U11)^-1 from that deflating subspace, then Newton steps (Hewer 1971; each a
    Stein equation; with E only up to n = 16) while the residual decreases. Where the states
    are measured in units 1e3 or more apart, or B or the weights are far from 1, the equation
    is solved in exactly scaled units (states balanced and shifted by powers of two, the costs
    multiplied by one), whose X and K are taken back. Neither A nor R need be
    invertible, and R need not be definite (only R + B^T X B nonsingular). Before it is
    returned the solution is verified: no eigenvalue of the pencil on the unit circle,
    exactly n inside, E U11 nonsingular, and every closed-loop eigenvalue inside the unit
    circle.

    Parameters
    ----------
    A, Q : array_like (n, n); a scalar is 1 x 1
    B : array_like (n, m); a 1-D B is a single input (a column)
    R : array_like (m, m), symmetric
    S : array_like (n, m), optional; the cross weight (python-control's N)
    E : array_like (n, n), optional

    Returns
    -------
    DareSolution
        The stabilising solution ``X``, the gain ``K``, the closed-loop eigenvalues (inside
        the unit circle), the relative residual, rcond(E U11) and the Newton steps taken.

    Raises
    ------
    ShapeError
        A, Q or E is not square, or B, R, S disagree in size with A.
    NonFiniteError
        An argument contains NaN or an infinity.
    NotRealError
        An argument is complex or not numeric.
    NoStabilizingSolutionError
        The pencil has eigenvalues on the unit circle (a mode on it is neither controllable
        nor penalised), its stable subspace is not a graph, or the computed closed loop is not
        inside the unit circle.
    SingularMatrixError
        R + B^T X B is singular.

    Warns
    -----
    IllConditionedWarning
        rcond(E U11) < 1e-8 or relative residual > 1e-8.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.solve_dare([[2.0]], [[1.0]], [[1.0]], [[1.0]])
    >>> round(float(sol.X[0, 0]), 12), round(2 + 5 ** 0.5, 12)     # x^2 - 4x - 1 = 0
    (4.2360679775, 4.2360679775)
    >>> bool(np.all(abs(sol.closed_loop_poles) < 1))
    True
    """
    return DareSolution(*_solve_dare(A, B, Q, R, S, E))


def _solve_dare(
    A: ArrayLike,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    S: ArrayLike | None,
    E: ArrayLike | None,
    cross: str = "S",
) -> tuple[FloatArray, FloatArray, ComplexArray, float, float, int]:
    """The native solve, warning (at the caller of :func:`solve_dare` or :func:`dlqr`) when
    the solution may be inaccurate; ``cross`` names the cross weight in errors (N for dlqr)."""
    # A float64 matrix goes to the core as it is (the core reads every layout of one); anything
    # else is read by matrix_view (a 1-D B is a column).
    if not (type(A) is np.ndarray and A.ndim == 2 and A.dtype == _FLOAT64):
        A = matrix_view(A, "A")
    if not (type(B) is np.ndarray and B.ndim == 2 and B.dtype == _FLOAT64):
        B = matrix_view(B, "B")
    result = _core.solve_dare(A, B, Q, R, S, E, cross == "N")
    residual, rcond = result[3], result[4]
    if rcond < RCOND_WARNING or residual > RESIDUAL_WARNING:
        warnings.warn(
            f"the discrete Riccati solution may be inaccurate: rcond(E U11) = {rcond:.2e}, "
            f"relative residual {residual:.2e}",
            IllConditionedWarning,
            stacklevel=3,
        )
    return result


def dlqr(
    sys_or_A: ArrayLike | SystemObject, *args: ArrayLike, N: ArrayLike | None = None
) -> tuple[FloatArray, FloatArray, ComplexArray]:
    """The discrete-time linear-quadratic regulator, called and returning as python-control's
    ``dlqr``.

    ``dlqr(sys, Q, R)``, ``dlqr(A, B, Q, R)`` or ``dlqr(A, B, Q, R, N)`` minimise
    J = Σ (x_k^T Q x_k + u_k^T R u_k + 2 x_k^T N u_k) for x_{k+1} = A x_k + B u_k.

    Parameters
    ----------
    sys_or_A : StateSpace or array_like (n, n)
        A discrete-time system (its A and B are used; a continuous one, dt = 0, is refused),
        or the transition matrix A.
    *args : array_like
        With a system: ``Q, R[, N]``. With a matrix: ``B, Q, R[, N]``: B (n, m), the state
        weight Q (n, n), the control weight R (m, m), the cross weight N (n, m).
    N : array_like (n, m), optional
        The cross weight, by keyword (default none, i.e. zero).

    Returns
    -------
    K : ndarray (m, n)
        The gain of u_k = -K x_k.
    S : ndarray (n, n)
        The solution of the discrete Riccati equation.
    E : ndarray (n,) of complex128
        The closed-loop eigenvalues, eig(A - B K), inside the unit circle.

    Raises
    ------
    InvalidArgumentError
        The wrong number of matrices, N given both by position and by keyword, or a
        continuous-time system (use :func:`lqr`).
    ShapeError, NonFiniteError, NotRealError
        As :func:`solve_dare`: a matrix of the wrong size, with NaN or infinite entries, or
        complex.
    NoStabilizingSolutionError
        A mode on the unit circle is neither controllable nor penalised, (A, B) is not
        stabilisable, or the computed closed loop is not inside the unit circle.
    SingularMatrixError
        R + B^T S B is singular.

    Warns
    -----
    IllConditionedWarning
        As :func:`solve_dare`.

    See Also
    --------
    solve_dare : the method, the errors and the diagnostics.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A = np.array([[1.0, 0.1], [0.0, 1.0]]); B = np.array([[0.005], [0.1]])
    >>> K, S, E = aerocontrol.dlqr(A, B, np.eye(2), [[1.0]])
    >>> bool(np.all(abs(E) < 1)), K.shape
    (True, (1, 2))

    The scalar x_{k+1} = 2 x_k + u_k, Q = R = 1: S = 2 + √5 solves S^2 - 4 S - 1 = 0 and
    K = 2 S / (1 + S):

    >>> K, S, E = aerocontrol.dlqr([[2.0]], [[1.0]], [[1.0]], [[1.0]])
    >>> round(float(S[0, 0]), 10), round(float(K[0, 0]), 10)
    (4.2360679775, 1.6180339887)
    """
    A, B, Q, R, N = _regulator_arguments("dlqr", sys_or_A, args, N)
    solution = _solve_dare(A, B, Q, R, N, None, "N")
    return solution[1], solution[0], solution[2]


def _regulator_arguments(
    name: str, sys_or_A: ArrayLike | SystemObject, args: tuple[ArrayLike, ...], N: ArrayLike | None
) -> tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike, ArrayLike | None]:
    """(A, B, Q, R, N) from python-control's ``name(sys, Q, R[, N])`` or
    ``name(A, B, Q, R[, N])``."""
    # Plain indexing, not star-unpacking: this wrapper's own cost is part of a 4-state lqr's.
    count = len(args)
    A: ArrayLike  # the system's matrices or the caller's
    B: ArrayLike
    if is_system(sys_or_A):
        if count not in (2, 3):
            raise InvalidArgumentError(f"{name}(sys, Q, R[, N]) takes a system and two weights")
        sys = as_state_space(sys_or_A)
        if name == "lqr":
            require_continuous(sys, "lqr", "use dlqr for the discrete regulator")
        else:
            require_discrete(sys_or_A, "dlqr", "use lqr, or discretise the model first (c2d)")
        A, B, Q, R = sys.A, sys.B, args[0], args[1]
        weights_given = 2
    else:
        if count not in (3, 4):
            raise InvalidArgumentError(f"{name}(A, B, Q, R[, N]) takes four or five matrices")
        A, B, Q, R = sys_or_A, args[0], args[1], args[2]
        weights_given = 3
    if count > weights_given:
        if N is not None:
            raise InvalidArgumentError("N given both by position and by keyword")
        N = args[weights_given]
    return A, B, Q, R, N


@dataclass(frozen=True, eq=False)
class RiccatiSolution(Result):
    """S(t) and K(t) of the finite-horizon regulator on a time grid (6.196)-(6.200).

    Attributes
    ----------
    t : ndarray (k,)
        The times (s), increasing; S(t[-1]) = Sf.
    S : ndarray (k, n, n)
        S(t_k), symmetric.
    K : ndarray (k, m, n)
        K(t_k) = R^-1 B^T S(t_k) (6.200).
    substeps : int
        Steps of the transition-matrix recursion over the horizon (each interval of t is
        divided so that the Hamiltonian's modes grow by at most e across a step).

    Examples
    --------
    For x' = u with Q = R = 1 and S(2) = 0, -S' = 1 - S² gives S(t) = tanh(2 - t):

    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.riccati_ode([[0.0]], [[1.0]], [[1.0]], [[1.0]], [0.0, 1.0, 2.0])
    >>> np.round(sol.S[:, 0, 0], 6), np.round(np.tanh([2.0, 1.0, 0.0]), 6)
    (array([0.964028, 0.761594, 0.      ]), array([0.964028, 0.761594, 0.      ]))
    >>> sol.K.shape
    (3, 1, 1)
    """

    t: FloatArray
    """The times, increasing; S(t[-1]) = Sf."""
    S: FloatArray
    """S(t_k), shape (len(t), n, n), symmetric."""
    K: FloatArray
    """K(t_k) = R^-1 B^T S(t_k), shape (len(t), m, n)."""
    substeps: int
    """Steps of the transition-matrix recursion over the horizon (each interval of t is
    divided so that the Hamiltonian's modes grow by at most e across a step)."""


def riccati_ode(
    A_or_sys: ArrayLike | SystemObject,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike | None = None,
    t: ArrayLike | None = None,
    Sf: ArrayLike | None = None,
) -> RiccatiSolution:
    """The Riccati differential equation -dS/dt = S A + A^T S - S B R^-1 B^T S + Q (6.196),
    integrated backward from S(t_f) = Sf (default 0, (6.197)) over the grid ``t``.

    Called as ``riccati_ode(A, B, Q, R, t, Sf=None)`` or ``riccati_ode(sys, Q, R, t, Sf=None)``.

    Method: with H the Hamiltonian [[A, -G], [-Q, -A^T]] (G = B R^-1 B^T), S = Y X^-1 where
    [X; Y] follows the linear equation d/dτ [X; Y] = -H [X; Y] in reverse time; each step
    propagates [I; S] by the transition matrix e^{-Hh} and forms S = Y X^-1 anew (the modified
    Davison-Maki method). There is no truncation error, so the accuracy (about 1e-13
    relative) does not depend on the grid; a long horizon converges to the algebraic solution.
    A grid uniform to rounding (every t_k within ``8u max(abs(t[0]), abs(t[-1]))`` of evenly
    spaced times, as ``numpy.linspace`` and ``numpy.arange`` make) is integrated with its one
    step, one exponential for the whole horizon.

    Parameters
    ----------
    A_or_sys : array_like (n, n) or StateSpace
        The plant matrix A, or a continuous-time system (then the arguments that follow shift
        one place left: ``Q, R, t[, Sf]``).
    B : array_like (n, m)
        The input matrix (with a system: Q).
    Q : array_like (n, n)
        The state weight, symmetric positive semidefinite (with a system: R).
    R : array_like (m, m)
        The control weight, symmetric positive definite (with a system: t). Required.
    t : array_like (k,), s
        The time grid, strictly increasing; t[-1] is the final time t_f. Required.
    Sf : array_like (n, n), optional
        The terminal weight S(t_f) (default 0).

    Returns
    -------
    RiccatiSolution
        ``t``, S(t_k) of shape (k, n, n), K(t_k) = R^-1 B^T S(t_k) of shape (k, m, n) and the
        number of transition-matrix steps taken.

    Raises
    ------
    InvalidArgumentError
        R or t missing, t not 1-D or not strictly increasing, Q or Sf not symmetric (to 1e-12
        of its largest entry), or a discrete-time system (use :func:`riccati_difference`).
    ShapeError
        A, Q, Sf not square, or B, R, Sf disagreeing in size with A (named).
    NonFiniteError, NotRealError
        An argument contains NaN or an infinity, or is complex.
    NotPositiveDefiniteError
        R is not symmetric positive definite.

    Warns
    -----
    IllConditionedWarning
        Q or Sf is not positive semidefinite: S(t) may then escape to infinity in finite
        time, and the values beyond the escape are not a solution.

    See Also
    --------
    lqr_finite : the gains K(t) alone.
    solve_care : the algebraic equation (6.199) that a long horizon converges to.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.riccati_ode([[0, 1], [1, 0]], [[0], [1]], np.diag([1.0, 0]), [[1.0]],
    ...                                np.linspace(0, 20, 5))
    >>> np.round(sol.K[0], 6)            # the algebraic (steady-state) gain, t_f - t = 20
    array([[2.414214, 2.197368]])

    The integrator x' = u with Q = R = 1 has S(t) = tanh(t_f - t):

    >>> sol = aerocontrol.riccati_ode([[0.0]], [[1.0]], [[1.0]], [[1.0]], [0.0, 1.0, 2.0])
    >>> np.round(sol.S[:, 0, 0], 6), np.round(np.tanh([2.0, 1.0, 0.0]), 6)
    (array([0.964028, 0.761594, 0.      ]), array([0.964028, 0.761594, 0.      ]))
    """
    A: ArrayLike  # the system's plant matrix or the caller's
    if is_system(A_or_sys):
        sys = as_state_space(A_or_sys)
        require_continuous(
            sys, "riccati_ode", "use riccati_difference for the discrete finite horizon"
        )
        # riccati_ode(sys, Q, R, t, Sf): every argument shifts one place to the left.
        A, B, Q, R, t, Sf = sys.A, sys.B, B, Q, R, (t if t is not None else Sf)
    else:
        A = A_or_sys
    if t is None or R is None:
        raise InvalidArgumentError("riccati_ode needs the weights Q, R and the time grid t")
    times = np.atleast_1d(real_array(t, "t"))
    if times.ndim != 1:
        raise InvalidArgumentError(f"t must be 1-D, got an array of shape {times.shape}")
    if Sf is not None:
        _require_symmetric_terminal_weight(Sf)
    S, K, substeps = _core.riccati_ode(
        matrix_view(A, "A"),
        matrix_view(B, "B"),
        Q,
        R,
        times,
        Sf,
    )
    indefinite = [name for name, weight in (("Q", Q), ("Sf", Sf)) if _indefinite(weight)]
    if indefinite:
        warnings.warn(
            f"{' and '.join(indefinite)} {'is' if len(indefinite) == 1 else 'are'} not positive "
            "semidefinite, so S(t) may escape to infinity in finite time: before the first "
            "such time S is the solution of (6.196), after it the values are its continuation "
            "through the pole, not a solution of the terminal-value problem (check S)",
            IllConditionedWarning,
            stacklevel=2,
        )
    return RiccatiSolution(np.array(times, dtype=np.float64), S, K, substeps)


def _indefinite(weight: ArrayLike | None) -> bool:
    """Whether the symmetric ``weight`` (checked by the core) has an eigenvalue below
    -n u max|weight| (rounding of a semidefinite one is not indefinite). With Q and Sf
    positive semidefinite, S(t) is a cost to go, bounded by that of the zero control, and
    cannot escape to infinity (chapter (6.196)-(6.197)); otherwise it can (the scalar
    -dS/dt = -5 - 2 S - S², S(t_f) = 0 has a pole at t_f - 1.017)."""
    if weight is None:
        return False
    matrix = real_array(weight, "weight")
    matrix = matrix.reshape(1, 1) if matrix.ndim == 0 else matrix
    if matrix.ndim != 2 or matrix.size == 0:
        return False
    size = float(np.max(np.abs(matrix)))
    lowest = float(np.linalg.eigvalsh((matrix + matrix.T) / 2)[0])
    return bool(lowest < -matrix.shape[0] * np.finfo(np.float64).eps * size)


def _require_symmetric_terminal_weight(Sf: ArrayLike) -> None:
    """Refuse a terminal weight that is not symmetric, as :func:`riccati_difference` does
    (to 1e-12 of its largest entry): S(t_f) = Sf is a symmetric solution of (6.196), and
    the Hamiltonian propagation of [I; Sf] would otherwise return a symmetrized S(t_f) that
    is not Sf. The core checks the shape and finiteness of anything else."""
    matrix = real_array(Sf, "Sf")
    if matrix.ndim != 2 or matrix.shape[0] != matrix.shape[1] or matrix.size == 0:
        return
    with np.errstate(invalid="ignore", over="ignore"):
        asymmetry = float(np.max(np.abs(matrix - matrix.T)))
        scale = float(np.max(np.abs(matrix)))
    if asymmetry > 1e-12 * scale:  # False for NaN, refused by the core by name
        error = InvalidArgumentError(
            f"Sf must be symmetric, but max|Sf - Sf^T| = {asymmetry:.3e} is more than 1e-12 "
            f"times max|Sf| = {scale:.3e}"
        )
        error.argument = "Sf"
        raise error


def lqr_finite(
    A_or_sys: ArrayLike | SystemObject,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike | None = None,
    t: ArrayLike | None = None,
    Sf: ArrayLike | None = None,
) -> FloatArray:
    """The time-varying gain K(t) = R^-1 B^T S(t) of the finite-horizon regulator (6.200), shape
    (len(t), m, n); arguments as :func:`riccati_ode`.

    Parameters
    ----------
    A_or_sys : array_like (n, n) or StateSpace
        The plant matrix A, or a continuous-time system (then the arguments that follow shift
        one place left: ``Q, R, t[, Sf]``).
    B : array_like (n, m)
        The input matrix (with a system: Q).
    Q : array_like (n, n)
        The state weight (with a system: R).
    R : array_like (m, m)
        The control weight, symmetric positive definite (with a system: t). Required.
    t : array_like (k,), s
        The time grid, strictly increasing; t[-1] is the final time t_f. Required.
    Sf : array_like (n, n), optional
        The terminal weight S(t_f) (default 0, (6.197)).

    Returns
    -------
    ndarray (k, m, n)
        K(t_k) on the grid; the control is η = -K(t) x.

    Raises
    ------
    InvalidArgumentError, ShapeError, NonFiniteError, NotRealError, NotPositiveDefiniteError
        As :func:`riccati_ode`.

    Warns
    -----
    IllConditionedWarning
        As :func:`riccati_ode` (Q or Sf not positive semidefinite).

    Examples
    --------
    The integrator x' = u with Q = R = 1: K(t) = tanh(t_f - t), zero at t_f.

    >>> import numpy as np, aerocontrol
    >>> K = aerocontrol.lqr_finite([[0.0]], [[1.0]], [[1.0]], [[1.0]], [0.0, 1.0, 2.0])
    >>> K.shape, np.round(K[:, 0, 0], 6)
    ((3, 1, 1), array([0.964028, 0.761594, 0.      ]))
    """
    gains: FloatArray = riccati_ode(A_or_sys, B, Q, R, t, Sf).K
    return gains


@dataclass(frozen=True, eq=False)
class RiccatiDifferenceSolution(Result):
    """S_k and K_k of the discrete finite-horizon regulator over N steps.

    Attributes
    ----------
    S : ndarray (N + 1, n, n)
        S_0 .. S_N, symmetric; S_N = Sf. x_k^T S_k x_k is the optimal cost from step k to the end.
    K : ndarray (N, m, n)
        K_0 .. K_{N-1}: u_k = -K_k x_k.
    rcond : float
        The smallest reciprocal condition number of R + B^T S_{k+1} B over the horizon (the
        matrix each gain solves with); 1 when N = 0.
    error_estimate : float
        The largest estimated relative error of a step S_k from the rounding of A - B K_k.

    Examples
    --------
    x[k+1] = 2 x[k] + u[k], Q = R = 1, S_3 = 0: S_k = (5 S_{k+1} + 1)/(S_{k+1} + 1) and
    K_k = 2 S_{k+1}/(S_{k+1} + 1), backward from 0:

    >>> import numpy as np, aerocontrol
    >>> sol = aerocontrol.riccati_difference([[2.0]], [[1.0]], [[1.0]], [[1.0]], 3)
    >>> np.round(sol.S[:, 0, 0], 12), np.round(sol.K[:, 0, 0], 12)
    (array([4., 3., 1., 0.]), array([1.5, 1. , 0. ]))
    """

    S: FloatArray
    """S_0 .. S_N, shape (N + 1, n, n), symmetric; S_N = Sf. x_k^T S_k x_k is the optimal cost
    from step k to the end."""
    K: FloatArray
    """K_0 .. K_{N-1}, shape (N, m, n): u_k = -K_k x_k."""
    rcond: float
    """The smallest reciprocal condition number of R + B^T S_{k+1} B over the horizon (the
    matrix each gain solves with); 1 when N = 0."""
    error_estimate: float
    """The largest estimated relative error of a step S_k from the rounding of A - B K_k:
    (n + m) δ (2 ||A - B K_k|| + δ) ||S_{k+1}|| / ||S_k||, δ = u (||A|| + ||B|| ||K_k||)."""


def riccati_difference(
    A_or_sys: ArrayLike | SystemObject,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike | int | None = None,
    steps: int | None = None,
    Sf: ArrayLike | None = None,
    N: ArrayLike | None = None,
) -> RiccatiDifferenceSolution:
    """The Riccati difference equation of the discrete finite-horizon regulator, backward from
    S_N = Sf (default 0) over ``steps`` = N steps.

    Called as ``riccati_difference(A, B, Q, R, steps, Sf=None, N=None)`` or
    ``riccati_difference(sys, Q, R, steps, Sf=None, N=None)`` (a discrete system). For
    x_{k+1} = A x_k + B u_k and J = x_N^T Sf x_N + Σ_{k<N} (x_k^T Q x_k + 2 x_k^T N u_k +
    u_k^T R u_k), the optimal control is u_k = -K_k x_k with

        K_k = (R + B^T S_{k+1} B)^-1 (B^T S_{k+1} A + N^T),
        S_k = (A - B K_k)^T S_{k+1} (A - B K_k) + K_k^T R K_k - N K_k - K_k^T N^T + Q,

    the discrete counterpart of the chapter's (6.196)-(6.200). The second line (the Joseph
    form of S_k = A^T S A - (A^T S B + N) K_k + Q) keeps S_k symmetric positive semidefinite
    under rounding where the weights are. Where A and B K are far larger than A - B K the
    rounding of that difference can swamp S_k in any double-precision form; the estimate of
    that error is returned (``error_estimate``) and warned about. A long horizon converges to
    :func:`solve_dare`'s X.

    Parameters
    ----------
    A_or_sys : array_like (n, n) or StateSpace
        The transition matrix A, or a discrete-time system (then the arguments that follow
        shift one place left: ``Q, R, steps[, Sf]``).
    B : array_like (n, m)
        The input matrix (with a system: Q).
    Q : array_like (n, n)
        The state weight (with a system: R).
    R : array_like (m, m)
        The control weight (with a system: steps). Required.
    steps : int
        The horizon N, a non-negative integer. Required.
    Sf : array_like (n, n), optional
        The terminal weight S_N (default 0).
    N : array_like (n, m), optional
        The cross weight (default 0).

    Returns
    -------
    RiccatiDifferenceSolution
        S_0 .. S_N of shape (N + 1, n, n), K_0 .. K_{N-1} of shape (N, m, n), the smallest
        rcond(R + B^T S_{k+1} B) and the largest estimated relative error of a step.

    Raises
    ------
    InvalidArgumentError
        R or steps missing, steps not a non-negative integer (a bool or a float is refused),
        or a continuous-time system (dt = 0: use :func:`riccati_ode`).
    ShapeError
        A, Q, Sf not square, or B, R, Sf, N disagreeing in size with A (named).
    NonFiniteError, NotRealError
        An argument contains NaN or an infinity, or is complex.
    IllConditionedError
        R + B^T S_{k+1} B is singular to working precision at some step (named), or S_k
        leaves the range of doubles.

    Warns
    -----
    IllConditionedWarning
        rcond(R + B^T S_{k+1} B) < 1e-8 at some step (the gains may have lost digits), or the
        error estimate is above 1e-8 (S_k may have).

    See Also
    --------
    dlqr_finite : the gains K_k alone.
    solve_dare : the algebraic equation a long horizon converges to.

    Examples
    --------
    >>> import aerocontrol
    >>> sol = aerocontrol.riccati_difference([[2.0]], [[1.0]], [[1.0]], [[1.0]], 4)
    >>> [round(float(s), 12) for s in sol.S[:, 0, 0]]     # (5 s + 1) / (1 + s) backward from 0
    [4.2, 4.0, 3.0, 1.0, 0.0]
    >>> float(sol.K[0, 0, 0])                                # 2 S_1 / (1 + S_1)
    1.6
    """
    A: ArrayLike  # the system's plant matrix or the caller's
    if is_system(A_or_sys):
        require_discrete(A_or_sys, "riccati_difference", "use riccati_ode")
        sys = as_state_space(A_or_sys)
        # riccati_difference(sys, Q, R, steps, Sf, N): every argument shifts one place left.
        horizon: object = R
        A, B, Q, R, Sf = sys.A, sys.B, B, Q, (steps if steps is not None else Sf)
    else:
        A, horizon = A_or_sys, steps
    if horizon is None or R is None:
        raise InvalidArgumentError(
            "riccati_difference needs the weights Q, R and the number of steps"
        )
    count = _steps(horizon)
    S, K, rcond, error_estimate = _core.riccati_difference(
        matrix_view(A, "A"),
        matrix_view(B, "B"),
        Q,
        R,
        count,
        Sf,
        N,
    )
    if rcond < RCOND_WARNING or error_estimate > RESIDUAL_WARNING:
        warnings.warn(
            "the finite-horizon solution may be inaccurate: rcond(R + B^T S B) = "
            f"{rcond:.2e} and estimated relative error {error_estimate:.2e} at the worst step "
            "(A and B K far larger than A - B K: scale the model)",
            IllConditionedWarning,
            stacklevel=2,
        )
    return RiccatiDifferenceSolution(S, K, rcond, error_estimate)


def _steps(steps: object) -> int:
    """The number of steps as a non-negative int (a bool, a float or a negative count is
    refused, naming ``steps``)."""
    if isinstance(steps, (bool, np.bool_)):
        raise InvalidArgumentError(f"steps must be a non-negative integer, got {steps!r}")
    try:
        count = operator.index(steps)  # type: ignore[arg-type]
    except TypeError:
        raise InvalidArgumentError(f"steps must be a non-negative integer, got {steps!r}") from None
    if count < 0:
        raise InvalidArgumentError(f"steps must be a non-negative integer, got {count}")
    return count


def dlqr_finite(
    A_or_sys: ArrayLike | SystemObject,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike | int | None = None,
    steps: int | None = None,
    Sf: ArrayLike | None = None,
    N: ArrayLike | None = None,
) -> FloatArray:
    """The time-varying gains K_0 .. K_{N-1} of the discrete finite-horizon regulator, shape
    (steps, m, n); arguments as :func:`riccati_difference`.

    Parameters
    ----------
    A_or_sys : array_like (n, n) or StateSpace
        The transition matrix A, or a discrete-time system (then the arguments that follow
        shift one place left: ``Q, R, steps[, Sf]``).
    B : array_like (n, m)
        The input matrix (with a system: Q).
    Q : array_like (n, n)
        The state weight (with a system: R).
    R : array_like (m, m)
        The control weight (with a system: steps). Required.
    steps : int
        The horizon N, a non-negative integer. Required.
    Sf : array_like (n, n), optional
        The terminal weight S_N (default 0).
    N : array_like (n, m), optional
        The cross weight (default 0).

    Returns
    -------
    ndarray (steps, m, n)
        K_0 .. K_{N-1}; the control is u_k = -K_k x_k.

    Raises
    ------
    InvalidArgumentError, ShapeError, NonFiniteError, NotRealError, IllConditionedError
        As :func:`riccati_difference`.

    Warns
    -----
    IllConditionedWarning
        As :func:`riccati_difference`.

    Examples
    --------
    x_{k+1} = 2 x_k + u_k, Q = R = 1, three steps: K_k = 2 S_{k+1} / (1 + S_{k+1}) with
    S = 3, 1, 0.

    >>> import aerocontrol
    >>> aerocontrol.dlqr_finite([[2.0]], [[1.0]], [[1.0]], [[1.0]], 3)[:, 0, 0].tolist()
    [1.5, 1.0, 0.0]
    """
    gains: FloatArray = riccati_difference(A_or_sys, B, Q, R, steps, Sf, N).K
    return gains


def solve_lyapunov(A: ArrayLike, Q: ArrayLike) -> FloatArray:
    """The solution X of the continuous Lyapunov equation A X + X A^T + Q = 0.

    Bartels-Stewart: with A = U T U^T, T Y + Y T^T = -U^T Q U is solved block by block from
    the bottom right, and X = U Y U^T (symmetric when Q is). Where A's states are scaled far
    apart (units 10^3 or more apart), A is first balanced by an exact diagonal similarity D of
    powers of two (A = D Â D^-1, then X = D X̂ D for the equation in Â and D^-1 Q D^-1), so
    that every entry of X stays accurate. The
    solution is unique unless two eigenvalues of A add up to zero; that case raises
    ``IllConditionedError``. For a stable A and Q = C^T C, X is the observability Gramian of
    (C, A^T).

    Parameters
    ----------
    A : array_like (n, n)
        Real, with no two eigenvalues adding up to zero.
    Q : array_like (n, n)
        Real, usually symmetric.

    Returns
    -------
    ndarray (n, n)
        X, symmetric when Q is.

    Raises
    ------
    ShapeError
        A or Q is not square, or their sizes differ.
    NonFiniteError, NotRealError
        A or Q contains NaN or an infinity, or is complex.
    IllConditionedError
        Two eigenvalues of A add up to zero to working precision (a mode on the imaginary
        axis, or a pair mirrored about it): the solution is not unique.

    Notes
    -----
    Note the sign: scipy.linalg.solve_continuous_lyapunov(A, Q) solves A X + X A^T = Q.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> aerocontrol.solve_lyapunov([[-1.0, 0.0], [0.0, -3.0]], [[2.0, 4.0], [4.0, 6.0]])
    array([[1., 1.],
           [1., 1.]])
    """
    X: FloatArray = _core.solve_lyapunov(matrix_view(A, "A"), matrix_view(Q, "Q"))
    return X
