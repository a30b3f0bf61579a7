"""The matrix exponential, state transition matrices, exact discretisation, and the real Schur
form with reordering.

Chapter §6.1.2: the transition matrix of x' = Ax + Bη is Φ(t) = e^{At} (6.22), and the
response to an input held over a step follows from Φ and two integrals of it (6.9).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._validation import FloatArray, check_choice, real_array, real_scalar
from .exceptions import InvalidArgumentError, ShapeError

__all__ = [
    "Discretization",
    "GeneralizedSchur",
    "discretize",
    "expm",
    "qz",
    "schur",
    "transition_matrix",
]

ComplexArray = NDArray[np.complex128]


def expm(A: ArrayLike) -> FloatArray:
    """The matrix exponential e^A of a real square matrix, or of each matrix of a stack.

    Padé scaling and squaring with the degree (3, 5, 7, 9 or 13) and scaling chosen as in
    Al-Mohy & Higham (2009), which avoids the overscaling of older algorithms on non-normal
    matrices; triangular matrices keep their structure. For orders up to 8, an exponential
    that needs squarings is evaluated in double-double arithmetic and is correct to a few
    units in the last place. A 3-D stack of k matrices is exponentiated in parallel across
    cores in one call.

    Parameters
    ----------
    A : array_like, shape (n, n) or (k, n, n)
        Real, finite matrix or stack of matrices (any real dtype, order or strides).

    Returns
    -------
    ndarray of float64, same shape as ``A``
        e^A. A result that overflows double precision has infinite entries and comes with a
        :class:`~aerocontrol.exceptions.NumericalOverflowWarning`, as in scipy. When
        ||A||_1 >= 2^53 the rounding of A alone can change every digit of e^A (its relative
        condition number is at least ||A||_2), and an
        :class:`~aerocontrol.exceptions.IllConditionedWarning` says so.

    Raises
    ------
    ShapeError
        ``A`` is not a square matrix or a stack of square matrices.
    NonFiniteError
        ``A`` contains NaN or an infinity (the message names the entry).
    NotRealError
        ``A`` is complex.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A = np.array([[0.0, 1.0], [-2.0, -3.0]])   # chapter (6.75)
    >>> np.round(aerocontrol.expm(A), 6)
    array([[ 0.600424,  0.232544],
           [-0.465088, -0.097209]])
    >>> aerocontrol.expm(np.zeros((3, 2, 2))).shape
    (3, 2, 2)
    """
    return _core.expm(A)


def transition_matrix(A: ArrayLike, t: ArrayLike) -> FloatArray:
    """The state transition matrix Φ(t) = e^{At} (6.22) at one time or at each of many.

    The powers of A and their norms are computed once for all times; each time then costs a
    Padé evaluation and its squarings, in parallel across times for small n. Negative times
    are allowed: Φ(-t) = Φ(t)^-1 (6.27).

    Parameters
    ----------
    A : array_like, shape (n, n)
        Real, finite plant matrix.
    t : float or array_like, shape (k,)
        Time or times.

    Returns
    -------
    ndarray of float64, shape (n, n) for a scalar ``t``, else (k, n, n)

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A = np.array([[0.0, 1.0], [0.0, 0.0]])     # double integrator: Φ(t) = [[1, t], [0, 1]]
    >>> aerocontrol.transition_matrix(A, 2.5)
    array([[1. , 2.5],
           [0. , 1. ]])
    >>> aerocontrol.transition_matrix(A, [0.0, 1.0, 2.0]).shape
    (3, 2, 2)
    """
    times = real_array(t, "t")
    if times.ndim == 0:
        single: FloatArray = _core.transition_matrices(A, times.reshape(1))[0]
        return single
    if times.ndim != 1:
        raise ShapeError(f"t must be a scalar or a 1-D array of times, got shape {times.shape}")
    return _core.transition_matrices(A, times)


@dataclass(frozen=True)
class Discretization:
    """The matrices that advance x' = Ax + Bη exactly over one step of length ``dt``.

    Zero-order hold (η constant over the step)::

        x[k+1] = Phi x[k] + Gamma0 η[k]

    First-order hold (η linear between samples)::

        x[k+1] = Phi x[k] + (Gamma0 - Gamma1) η[k] + Gamma1 η[k+1]

    with Phi = e^{A dt}, Gamma0 = ∫_0^dt e^{Aτ} dτ B and
    Gamma1 = (1/dt) ∫_0^dt e^{Aτ} (dt - τ) dτ B.
    """

    Phi: FloatArray
    """e^{A dt}, shape (n, n)."""
    Gamma0: FloatArray
    """∫_0^dt e^{Aτ} dτ B, shape (n, m)."""
    Gamma1: FloatArray | None
    """(1/dt) ∫_0^dt e^{Aτ} (dt - τ) dτ B, shape (n, m), for ``method="foh"``; else None."""
    dt: float
    """The step."""
    method: Literal["zoh", "foh"]
    """The hold: ``"zoh"`` or ``"foh"``."""


def discretize(
    A: ArrayLike, B: ArrayLike, dt: float, method: Literal["zoh", "foh"] = "zoh"
) -> Discretization:
    """Exact discretisation of x' = Ax + Bη over a step ``dt``.

    Φ, Γ0 and Γ1 come from one exponential of an augmented block matrix (Van Loan 1978), so
    no inverse of A is needed: the result is exact for singular A, where the chapter's step
    formula (6.43), x(t) = (e^{At} - I) A^-1 B η0, fails (the example (6.95) has a zero
    eigenvalue).

    Parameters
    ----------
    A : array_like, shape (n, n)
        Plant matrix.
    B : array_like, shape (n, m) or (n,)
        Control matrix; a 1-D B is one input column.
    dt : float
        Step, positive and finite.
    method : {"zoh", "foh"}
        Zero-order hold (input constant over the step) or first-order hold (input linear
        between samples).

    Returns
    -------
    Discretization
        ``Phi``, ``Gamma0`` and, for ``"foh"``, ``Gamma1`` (see :class:`Discretization`).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A = np.array([[-3.0, 8.0], [0.0, 0.0]]); B = np.array([0.0, 4.0])   # (6.95): singular
    >>> d = aerocontrol.discretize(A, B, 0.1)
    >>> np.round(d.Gamma0, 6)
    array([[0.145131],
           [0.4     ]])
    """
    B = real_array(B, "B")
    if B.ndim == 1:
        B = B.reshape(-1, 1)
    step = real_scalar(dt, "dt")
    hold: Literal["zoh", "foh"] = (
        "zoh" if check_choice(method, "method", ("zoh", "foh")) == "zoh" else "foh"
    )
    Phi, Gamma0, Gamma1 = _core.discretize(A, B, step, hold)
    return Discretization(Phi=Phi, Gamma0=Gamma0, Gamma1=Gamma1, dt=step, method=hold)


#: The named selections of :func:`schur` (scipy.linalg.schur's ``sort`` names).
SELECTIONS: dict[str, Callable[[complex], bool]] = {
    "lhp": lambda z: z.real < 0.0,
    "rhp": lambda z: z.real > 0.0,
    "iuc": lambda z: abs(z) < 1.0,
    "ouc": lambda z: abs(z) > 1.0,
}


def schur(
    A: ArrayLike, select: str | Callable[[complex], bool] | None = None
) -> tuple[FloatArray, FloatArray, ComplexArray]:
    """The real Schur form A = Q T Q^T, optionally reordered.

    Hessenberg reduction, then the Francis double-shift QR iteration with Ahues-Tisseur
    deflation and exceptional shifts (an iteration bound turns a failure into
    ``ConvergenceError``, never a hang). With ``select``, the diagonal blocks are exchanged
    (Bai & Demmel's direct swap with its stability tests, as LAPACK's dtrsen) until every
    selected eigenvalue comes first.

    Parameters
    ----------
    A : array_like (n, n), real and finite
    select : None, "lhp", "rhp", "iuc", "ouc", or a callable
        The eigenvalues to put first: Re < 0, Re > 0, |λ| < 1, |λ| > 1, or those for which
        ``select(λ)`` is true (called with the member of a complex pair that has Im > 0; the
        pair moves together).

    Returns
    -------
    T : ndarray (n, n)
        Quasi-upper-triangular, exact zeros below the 1 x 1 and 2 x 2 diagonal blocks.
    Q : ndarray (n, n)
        Orthogonal.
    eigenvalues : ndarray (n,) of complex128
        In the order of T's diagonal, pairs adjacent with Im > 0 first.

    Raises
    ------
    IllConditionedError
        A swap was rejected: two blocks to exchange have nearly equal eigenvalues.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A = np.array([[1.0, 2.0, 0.0], [0.0, -1.0, 3.0], [0.0, 0.0, 2.0]])
    >>> T, Q, w = aerocontrol.schur(A, "lhp")
    >>> w.real
    array([-1.,  1.,  2.])
    >>> bool(np.allclose(Q @ T @ Q.T, A))
    True
    """
    if isinstance(select, str):
        if select not in SELECTIONS:
            raise InvalidArgumentError(
                f"select must be one of {', '.join(map(repr, SELECTIONS))} or a callable, "
                f"got {select!r}"
            )
        select = SELECTIONS[select]
    elif select is not None and not callable(select):
        raise InvalidArgumentError(f"select must be a name or a callable, got {select!r}")
    T, Q, eigenvalues, _ = _core.schur(A, select)
    return T, Q, eigenvalues


def eigenvalues(A: ArrayLike) -> ComplexArray:
    """The eigenvalues of a real square matrix, by aerocontrol's own Schur form (never through
    numpy's LAPACK, whose buffers may end the process when memory is short), pairs adjacent
    with Im > 0 first."""
    return _core.eigenvalues(A)


class GeneralizedSchur(NamedTuple):
    """The generalized real Schur form (A, B) = Q (AA, BB) Z^T, in the order of
    ``scipy.linalg.ordqz``'s results: ``AA, BB, alpha, beta, Q, Z = qz(A, B)`` unpacks it."""

    AA: FloatArray
    """Quasi-upper-triangular: 1 x 1 blocks and 2 x 2 blocks for complex pairs."""
    BB: FloatArray
    """Upper triangular with a nonnegative diagonal, diagonal under AA's 2 x 2 blocks."""
    alpha: ComplexArray
    """The eigenvalues are alpha / beta, in the order of the diagonal."""
    beta: FloatArray
    """Nonnegative; 0 for an infinite eigenvalue (B singular)."""
    Q: FloatArray
    """Orthogonal."""
    Z: FloatArray
    """Orthogonal; with ``select``, its leading ``selected`` columns span the right deflating
    subspace of the selected eigenvalues."""
    selected: int
    """The number of leading eigenvalues chosen by ``select`` (n without it)."""


def _generalized_selection(name: str) -> Callable[[complex, float], bool]:
    """scipy.linalg.ordqz's named sorts on (alpha, beta); an infinite eigenvalue (beta = 0)
    is in neither half plane and outside the unit circle."""

    def finite(alpha: complex, beta: float) -> complex | None:
        return None if beta == 0.0 else alpha / beta

    def lhp(alpha: complex, beta: float) -> bool:
        value = finite(alpha, beta)
        return value is not None and value.real < 0.0

    def rhp(alpha: complex, beta: float) -> bool:
        value = finite(alpha, beta)
        return value is not None and value.real > 0.0

    def iuc(alpha: complex, beta: float) -> bool:
        return abs(alpha) < abs(beta)

    def ouc(alpha: complex, beta: float) -> bool:
        return abs(alpha) > abs(beta)

    return {"lhp": lhp, "rhp": rhp, "iuc": iuc, "ouc": ouc}[name]


def qz(
    A: ArrayLike, B: ArrayLike, select: str | Callable[[complex, float], bool] | None = None
) -> GeneralizedSchur:
    """The generalized real Schur (QZ) form of the pencil A - λB, optionally reordered.

    Hessenberg-triangular reduction, then the double-shift QZ iteration of Moler and Stewart
    with deflation of infinite eigenvalues (B singular is allowed); 2 x 2 blocks in LAPACK's
    standard form (BB's block diagonal and positive). With ``select``, adjacent blocks are
    swapped (Kågström's direct method with its weak and strong stability tests, as LAPACK's
    dtgsen) until every selected eigenvalue comes first. All transformations are orthogonal:
    the result is the exact form of a pencil within a few units of rounding of (A, B).

    Parameters
    ----------
    A, B : array_like (n, n), real and finite
    select : None, "lhp", "rhp", "iuc", "ouc", or a callable
        The eigenvalues to put first: Re λ < 0, Re λ > 0, |λ| < 1, |λ| > 1 (λ = α/β; an
        infinite eigenvalue counts as outside the unit circle and in neither half plane), or
        those for which ``select(alpha, beta)`` is true (as scipy.linalg.ordqz's ``sort``; for
        a complex pair it is called with the member with Im > 0, and the pair moves together).

    Returns
    -------
    GeneralizedSchur
        ``(AA, BB, alpha, beta, Q, Z, selected)`` with A = Q AA Z^T and B = Q BB Z^T.

    Raises
    ------
    ShapeError
        A or B not square, or of different orders.
    IllConditionedError
        A swap was refused: two blocks to exchange have nearly equal eigenvalues.
    ConvergenceError
        The iteration did not converge (30 n steps).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A = np.array([[1.0, 2.0], [3.0, 4.0]])
    >>> B = np.array([[2.0, 0.0], [0.0, 1.0]])
    >>> AA, BB, alpha, beta, Q, Z, k = aerocontrol.qz(A, B, "lhp")
    >>> k, np.round((alpha / beta).real, 6)
    (1, array([-0.212214,  4.712214]))
    >>> bool(np.allclose(Q @ AA @ Z.T, A) and np.allclose(Q @ BB @ Z.T, B))
    True
    """
    if isinstance(select, str):
        if select not in SELECTIONS:
            raise InvalidArgumentError(
                f"select must be one of {', '.join(map(repr, SELECTIONS))} or a callable, "
                f"got {select!r}"
            )
        select = _generalized_selection(select)
    elif select is not None and not callable(select):
        raise InvalidArgumentError(f"select must be a name or a callable, got {select!r}")
    return GeneralizedSchur(*_core.qz(A, B, select))
