"""The real Schur form with reordering, and the Lyapunov equation solved on it.

:func:`schur` returns A = Q T Q^T with T quasi-upper-triangular (1 x 1 blocks for real
eigenvalues, standardised 2 x 2 blocks [[a, b], [c, a]], bc < 0, for complex pairs) and Q
orthogonal, optionally reordered so that chosen eigenvalues lead: the first k columns of Q
then span their invariant subspace. :func:`solve_lyapunov` solves A X + X A^T + Q = 0 by
Bartels-Stewart on that form.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _core
from ._validation import FloatArray
from .exceptions import InvalidArgumentError

__all__ = ["schur", "solve_lyapunov"]

ComplexArray = NDArray[np.complex128]

#: The named selections of :func:`schur` (scipy.linalg.schur's ``sort`` names).
SELECTIONS: dict[str, Callable[[complex], bool]] = {
    "lhp": lambda z: z.real < 0.0,
    "rhp": lambda z: z.real > 0.0,
    "iuc": lambda z: abs(z) < 1.0,
    "ouc": lambda z: abs(z) > 1.0,
}


def schur(
    A: Any, select: str | Callable[[complex], bool] | None = None
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


def solve_lyapunov(A: Any, Q: Any) -> FloatArray:
    """The solution X of the continuous Lyapunov equation A X + X A^T + Q = 0.

    Bartels-Stewart: with A = U T U^T, T Y + Y T^T = -U^T Q U is solved block by block from
    the bottom right, and X = U Y U^T (symmetric when Q is). The solution is unique unless two
    eigenvalues of A add up to zero; that case raises ``IllConditionedError``. For a stable A
    and Q = C^T C, X is the observability Gramian of (C, A^T).

    Note the sign: scipy.linalg.solve_continuous_lyapunov(A, Q) solves A X + X A^T = Q.

    >>> import numpy as np, aerocontrol
    >>> aerocontrol.solve_lyapunov([[-1.0, 0.0], [0.0, -3.0]], [[2.0, 4.0], [4.0, 6.0]])
    array([[1., 1.],
           [1., 1.]])
    """
    X: FloatArray = _core.solve_lyapunov(A, Q)
    return X
