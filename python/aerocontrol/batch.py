"""Sweeps: many Riccati equations in one call, solved in parallel in the native core.

Design work is sweeps: gains over weights, models over the flight envelope, Monte Carlo over
uncertain derivatives. A loop over :func:`aerocontrol.lqr` pays the Python crossing per
problem; here the whole stack crosses once, the GIL is released, and the problems are spread
over the cores (one problem per task, each solved exactly as :func:`aerocontrol.solve_care`
solves it alone, so the results are bitwise the one-at-a-time results). A sweep over R alone
(A, B and Q shared, refinement on: :func:`lqr_sweep`) is the exception: its weights are cut
into groups of 32 consecutive ones, in parallel; the first of a group is solved by the Schur
method as alone, each next one by Newton's method started from the polynomial through the
solutions before it, which converges in about one step where the weights are evenly spaced
(the Schur method where Newton's method does not converge or its solution fails the checks).
Those solutions agree with the Schur method's to rounding (within 1e-13 on the 747's sweep),
with residuals as small, and pass the same checks (residual, closed-loop stability); their
rcond(U11) is that of another orthonormal basis of the same subspace (within n² of the Schur
method's). The groups do not depend on the threads, so neither do the bits.

* :func:`solve_care_batch`: stacks of (A, B, Q, R); any of them may be one matrix shared by
  every problem;
* :func:`lqr_sweep`: one model over an array of the chapter's weights c, R/c² (6.226);
* :func:`place_batch`: pole placement over stacks of (A, B, poles), by Bass-Gura (6.145),
  Ackermann or Kautsky-Nichols-Van Dooren method 0.

An error in one problem raises the exception of that problem with its index ("problem 7 of
the batch: ..."), the lowest failing index when several fail; nothing partial is returned.

:func:`solve_care_batch`, :func:`solve_dare_batch`, :func:`lqr_sweep` and :func:`dlqr_sweep`
take an optional ``client`` (a ``dask.distributed.Client``): the batch is cut into chunks of
:data:`DISTRIBUTED_CHUNK` problems, each solved by the same kernel on a worker, and joined in
order, so the result is bitwise the local one.
"""

from __future__ import annotations

import contextlib
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._results import Result
from ._validation import FloatArray, positive_int, real_array
from .exceptions import AerocontrolError, IllConditionedWarning, InvalidArgumentError, ShapeError
from .placement import ILL_CONDITIONED_CONTROLLABILITY, POLE_ERROR_WARNING
from .riccati import RCOND_WARNING, RESIDUAL_WARNING
from .statespace import as_state_space, is_system, require_continuous, require_discrete
from .threads import limit_threads

if TYPE_CHECKING:
    from ._typing import SystemObject

__all__ = [
    "DISTRIBUTED_CHUNK",
    "CareBatch",
    "DareBatch",
    "LqrSweep",
    "PlaceBatch",
    "dlqr_sweep",
    "lqr_sweep",
    "place_batch",
    "solve_care_batch",
    "solve_dare_batch",
]

ComplexArray = NDArray[np.complex128]

#: Problems per task when a batch runs on a Dask cluster (``client=``).
DISTRIBUTED_CHUNK = 4096


@dataclass(frozen=True, eq=False)
class CareBatch(Result):
    """The solutions of a batch of Riccati equations, problem index first.

    Attributes
    ----------
    X : ndarray (k, n, n)
        The stabilising solutions.
    K : ndarray (k, m, n)
        The gains R^-1 B^T X (6.200).
    closed_loop_poles : ndarray (k, n), complex
        eig(A - B K) of each problem, as :func:`aerocontrol.lqr` returns its E.
    residual : ndarray (k,)
        The relative residual of each equation.
    rcond : ndarray (k,)
        rcond(U11) of each problem: small means X is sensitive.

    Examples
    --------
    x' = u with Q = 1 and R = r: X = √r, K = 1/√r:

    >>> import numpy as np
    >>> from aerocontrol import batch
    >>> ones, R = np.ones((2, 1, 1)), np.array([[[1.0]], [[4.0]]])
    >>> sol = batch.solve_care_batch(np.zeros((2, 1, 1)), ones, ones, R)
    >>> len(sol), np.round(sol.X.ravel(), 12), np.round(sol.K.ravel(), 12)
    (2, array([1., 2.]), array([1. , 0.5]))
    """

    X: FloatArray
    """The stabilising solutions, (k, n, n)."""
    K: FloatArray
    """The gains R^-1 B^T X, (k, m, n)."""
    closed_loop_poles: ComplexArray
    """eig(A - B K) of each problem, (k, n), as :func:`aerocontrol.lqr` returns its E."""
    residual: FloatArray
    """The relative residual of each equation, (k,)."""
    rcond: FloatArray
    """rcond(U11) of each problem, (k,)."""

    def __len__(self) -> int:
        return int(self.X.shape[0])


@dataclass(frozen=True, eq=False)
class DareBatch(Result):
    """The solutions of a batch of discrete Riccati equations, problem index first.

    Attributes
    ----------
    X : ndarray (k, n, n)
        The stabilising solutions.
    K : ndarray (k, m, n)
        The gains (R + B^T X B)^-1 B^T X A.
    closed_loop_poles : ndarray (k, n), complex
        eig(A - B K) of each problem, inside the unit circle, as :func:`aerocontrol.dlqr` returns
        its E.
    residual : ndarray (k,)
        The relative residual of each equation.
    rcond : ndarray (k,)
        rcond(U11) of each problem: small means X is sensitive.

    Examples
    --------
    x[k+1] = a x[k] + u[k] with Q = R = 1: X² - a² X - 1 = 0, so for a = 1 X is the golden ratio
    (1 + √5)/2, for a = 2, 2 + √5:

    >>> import numpy as np
    >>> from aerocontrol import batch
    >>> A = np.array([[[1.0]], [[2.0]]])
    >>> ones = np.ones((2, 1, 1))
    >>> sol = batch.solve_dare_batch(A, ones, ones, ones)
    >>> np.round(sol.X.ravel(), 6), np.round(sol.K.ravel(), 6)
    (array([1.618034, 4.236068]), array([0.618034, 1.618034]))
    """

    X: FloatArray
    """The stabilising solutions, (k, n, n)."""
    K: FloatArray
    """The gains (R + B^T X B)^-1 B^T X A, (k, m, n)."""
    closed_loop_poles: ComplexArray
    """eig(A - B K) of each problem, inside the unit circle, (k, n), as
    :func:`aerocontrol.dlqr` returns its E."""
    residual: FloatArray
    """The relative residual of each equation, (k,)."""
    rcond: FloatArray
    """rcond(U11) of each problem, (k,)."""

    def __len__(self) -> int:
        return int(self.X.shape[0])


@dataclass(frozen=True, eq=False)
class LqrSweep(Result):
    """The regulator of one model for each weight c of a sweep (Figure 6.12).

    Attributes
    ----------
    weights : ndarray (k,)
        The weights c of J = ∫ x^T Q x + (1/c²) η^T R η dt (6.224)-(6.227).
    K : ndarray (k, m, n)
        The gains.
    poles : ndarray (k, n), complex
        The closed-loop eigenvalues: the root locus over c.
    X : ndarray (k, n, n)
        The Riccati solutions.
    residual : ndarray (k,)
        The relative residual of each equation.
    rcond : ndarray (k,)
        rcond(U11) of each problem.

    Examples
    --------
    x' = η with Q = R = 1: X = 1/c, K = c, the pole at -c:

    >>> import numpy as np
    >>> from aerocontrol import batch
    >>> sweep = batch.lqr_sweep([[0.0]], [[1.0]], [[1.0]], [[1.0]], weights=[1.0, 4.0])
    >>> np.round(sweep.X.ravel(), 12), np.round(sweep.K.ravel(), 12)
    (array([1.  , 0.25]), array([1., 4.]))
    >>> np.round(sweep.poles.ravel().real, 12)
    array([-1., -4.])
    """

    weights: FloatArray
    """The weights c, (k,)."""
    K: FloatArray
    """The gains, (k, m, n)."""
    poles: ComplexArray
    """The closed-loop eigenvalues, (k, n): the root locus over c."""
    X: FloatArray
    """The Riccati solutions, (k, n, n)."""
    residual: FloatArray
    """The relative residual of each equation, (k,)."""
    rcond: FloatArray
    """rcond(U11) of each problem, (k,)."""

    def __len__(self) -> int:
        return len(self.weights)


@dataclass(frozen=True, eq=False)
class PlaceBatch(Result):
    """State-feedback designs η = -K_i x over a batch, problem index first.

    Attributes
    ----------
    K : ndarray (k, m, n)
        The gains.
    achieved_poles : ndarray (k, n), complex
        The eigenvalues of A_i - B_i K_i in the order of the requested poles (conjugate pairs
        adjacent, Im > 0 first).
    max_relative_error : ndarray (k,)
        The largest relative error of an achieved pole, per problem.
    condition : ndarray (k,)
        κ(V) of the single-input formulas or κ_2(X) of the robust method, per problem.

    Examples
    --------
    The double integrator placed at (-1, -2) and at (-2, -3): K = [2, 3] and [6, 5]:

    >>> import numpy as np
    >>> from aerocontrol import batch
    >>> A = np.tile([[0.0, 1.0], [0.0, 0.0]], (2, 1, 1))
    >>> B = np.tile([[0.0], [1.0]], (2, 1, 1))
    >>> designs = batch.place_batch(A, B, [[-1.0, -2.0], [-2.0, -3.0]])
    >>> np.round(designs.K[:, 0], 12)
    array([[2., 3.],
           [6., 5.]])
    """

    K: FloatArray
    """The gains, (k, m, n)."""
    achieved_poles: ComplexArray
    """The eigenvalues of A_i - B_i K_i in the order of the requested poles (conjugate pairs
    adjacent, Im > 0 first), (k, n)."""
    max_relative_error: FloatArray
    """The largest relative error of an achieved pole, per problem, (k,)."""
    condition: FloatArray
    """κ(V) of the single-input formulas or κ_2(X) of the robust method, per problem, (k,)."""

    def __len__(self) -> int:
        return int(self.K.shape[0])


_METHODS = {"bass-gura": "bass-gura", "ackermann": "ackermann", "knv": "knv0"}


def place_batch(A: ArrayLike, B: ArrayLike, poles: ArrayLike, method: str = "knv") -> PlaceBatch:
    """Pole placement for every problem of a batch, in parallel, each exactly as the single
    function places it (:func:`aerocontrol.place_bass_gura`, :func:`aerocontrol.place_ackermann`
    or :func:`aerocontrol.place`).

    Parameters
    ----------
    A : array_like (n, n) or (k, n, n)
    B : array_like (n, m) or (k, n, m); (n,) for one input
    poles : array_like (n,) or (k, n)
        The requested poles, complex ones in conjugate pairs; one row shared or one per
        problem.
    method : "knv" (default, any m), "bass-gura" or "ackermann" (one input)

    Returns
    -------
    PlaceBatch
        ``K`` (k, m, n), ``achieved_poles`` (k, n), ``max_relative_error`` (k,) and
        ``condition`` (k,): κ(V) of the single-input formulas or κ_2(X) of the robust method.

    Raises
    ------
    InvalidArgumentError
        ``method`` is not one of the three.
    ShapeError
        A stack that is neither one matrix nor k of them, or ``poles`` not (n,) or (k, n).
    AerocontrolError
        The first failing problem's own error (UncontrollableError, InvalidArgumentError for
        a pole without its conjugate, ...), its message starting "problem i of the batch".

    Warns
    -----
    IllConditionedWarning
        Naming the problems whose achieved poles miss by more than 1e-6 relatively or whose
        controllability matrix has κ(V) >= 1e8 (single input), as the single functions do.

    Examples
    --------
    The 747's Dutch-roll damper (6.156)-(6.159) for ten damping ratios at once:

    >>> import numpy as np, aerocontrol
    >>> sys = aerocontrol.aircraft.load().lateral()
    >>> zeta, wn = np.linspace(0.15, 0.6, 10), 0.74767
    >>> dutch = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
    >>> poles = np.stack([dutch, dutch.conj(), np.full(10, -1.23079), np.full(10, -0.046413)], 1)
    >>> designs = aerocontrol.batch.place_batch(sys.A, sys.B[:, 0], poles, "bass-gura")
    >>> designs.K.shape, bool(designs.max_relative_error.max() < 1e-10)
    ((10, 1, 4), True)
    """
    if method not in _METHODS:
        allowed = ", ".join(repr(m) for m in _METHODS)
        raise InvalidArgumentError(f"method must be one of {allowed}, got {method!r}")
    try:
        requested = np.asarray(poles, dtype=np.complex128)
    except (TypeError, ValueError) as error:
        raise InvalidArgumentError(f"poles must be numbers: {error}") from None
    if requested.ndim not in (1, 2):
        raise ShapeError(f"poles must be (n,) or (k, n), got shape {requested.shape}")
    requested = np.ascontiguousarray(np.atleast_2d(requested))
    batch = PlaceBatch(
        *_core.place_batch(_stack(A, "A"), _stack(B, "B"), requested, _METHODS[method])
    )
    single_input = method != "knv"
    flagged = np.flatnonzero(
        (batch.max_relative_error > POLE_ERROR_WARNING)
        | (single_input & (batch.condition >= ILL_CONDITIONED_CONTROLLABILITY))
    )
    _warn(
        flagged,
        f"of the {len(batch)} placements may be inaccurate (achieved poles off by more than "
        f"{POLE_ERROR_WARNING:.0e} relatively, or an ill-conditioned controllability matrix)",
    )
    return batch


def _stack(value: object, name: str) -> FloatArray:
    array = real_array(value, name)
    if array.ndim == 2:
        return array[np.newaxis]
    if array.ndim == 1 and name == "B":  # one input, as the single-problem functions take it
        return array.reshape(1, -1, 1)
    if array.ndim != 3:
        raise ShapeError(
            f"{name} must be a matrix (shared by every problem) or a 3-D stack of matrices, "
            f"got shape {array.shape}"
        )
    return array


def _solved(
    kernel: str,
    stacks: tuple[FloatArray, ...],
    extra: tuple[Any, ...],
    client: Any,
    worker_threads: int | None,
) -> Any:
    """The core's ``kernel`` on the stacks (each of one matrix, shared, or k of them): in one
    call, or with a Dask ``client`` in chunks of :data:`DISTRIBUTED_CHUNK` problems, each on
    ``worker_threads`` threads of its worker when given, joined in order (the first failing
    problem's error raised with its index in the whole batch)."""
    if worker_threads is not None:
        worker_threads = positive_int(worker_threads, "worker_threads")
        if client is None:
            raise InvalidArgumentError(
                "worker_threads sets the threads of a Dask worker's chunk: give it with a "
                "client (on this machine, use aerocontrol.limit_threads)"
            )
    if client is None:
        return getattr(_core, kernel)(*stacks, *extra)
    if any(len(stack) == 0 for stack in stacks):
        # No problem to solve (k = 0): the core's empty result, as without a client (whose
        # shape checks, with a shared matrix of one, it makes).
        return getattr(_core, kernel)(*stacks, *extra)
    count = max(len(stack) for stack in stacks)
    for name, stack in zip("ABQR", stacks, strict=True):
        if len(stack) not in (1, count):
            raise ShapeError(
                f"{name} holds {len(stack)} matrices; the batch has {count} problems (give one "
                "matrix, shared, or one per problem)"
            )
    starts = list(range(0, count, DISTRIBUTED_CHUNK)) or [0]
    futures = client.map(
        _solved_chunk,
        [kernel] * len(starts),
        [stacks] * len(starts),
        [extra] * len(starts),
        starts,
        [start + DISTRIBUTED_CHUNK for start in starts],
        [worker_threads] * len(starts),
        pure=False,
    )
    parts = [future.result() for future in futures]
    for start, part in zip(starts, parts, strict=True):
        if isinstance(part, AerocontrolError):
            index = start + int(getattr(part, "batch_index", 0))
            message = str(part).replace(
                f"problem {getattr(part, 'batch_index', 0)} of the batch",
                f"problem {index} of the batch",
                1,
            )
            error = type(part)(message)
            error.__dict__.update(part.__dict__)
            error.batch_index = index
            raise error
    return tuple(np.concatenate(arrays) for arrays in zip(*parts, strict=True))


def _solved_chunk(
    kernel: str,
    stacks: tuple[FloatArray, ...],
    extra: tuple[Any, ...],
    start: int,
    stop: int,
    worker_threads: int | None,
) -> Any:
    """Problems start to stop of :func:`_solved`, run on a worker (on ``worker_threads``
    threads when given): their results, or their error (returned, so that the caller can name
    the problem in the whole batch)."""
    chunk = tuple(stack if len(stack) == 1 else stack[start:stop] for stack in stacks)
    threads = contextlib.nullcontext() if worker_threads is None else limit_threads(worker_threads)
    try:
        with threads:
            return getattr(_core, kernel)(*chunk, *extra)
    except AerocontrolError as error:
        return error


def _warn(flagged: NDArray[np.intp], what: str) -> None:
    """One IllConditionedWarning naming the flagged problems (the first ten)."""
    if flagged.size:
        shown = ", ".join(str(i) for i in flagged[:10]) + (" ..." if flagged.size > 10 else "")
        warnings.warn(
            f"{flagged.size} {what}: problems {shown}", IllConditionedWarning, stacklevel=3
        )


def solve_care_batch(
    A: ArrayLike,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    refine: bool = True,
    client: Any = None,
    worker_threads: int | None = None,
) -> CareBatch:
    """Solve A_i^T X_i + X_i A_i - X_i B_i R_i^-1 B_i^T X_i + Q_i = 0 for every problem i of a
    batch, in parallel.

    Each of A (k, n, n), B (k, n, m), Q (k, n, n) and R (k, m, m) is a 3-D stack of k
    matrices or a single matrix shared by every problem. The method, checks and diagnostics
    are those of :func:`aerocontrol.solve_care` (without the cross weight and E); a sweep
    over R alone is solved by Newton's method from the weights before (see the module
    notes). With a Dask
    ``client``, the batch is solved in chunks on the cluster, bitwise as here (see the module
    notes).

    Parameters
    ----------
    A : array_like (n, n) or (k, n, n)
    B : array_like (n, m) or (k, n, m)
    Q : array_like (n, n) or (k, n, n)
    R : array_like (m, m) or (k, m, m)
    refine : bool, optional
        Newton refinement, as :func:`aerocontrol.solve_care` (default True).
    client : dask.distributed.Client, optional
        Solve in chunks on the Dask cluster, bitwise as here (default None: this machine's
        threads).
    worker_threads : int, optional
        With a ``client``: each chunk's parallel work runs on this many threads of its worker
        (:func:`aerocontrol.limit_threads`), so that workers do not oversubscribe their
        machine. The setting is the task thread's own, so a worker of several task threads
        runs each chunk on that many threads.

    Returns
    -------
    CareBatch
        ``X`` (k, n, n), ``K`` (k, m, n), ``closed_loop_poles`` (k, n), and the ``residual``
        and ``rcond`` of each problem (k,).

    Raises
    ------
    ShapeError
        A stack that is neither one matrix nor k matrices, or shapes that disagree.
    AerocontrolError
        The first failing problem's own error (NotPositiveDefiniteError,
        NoStabilizingSolutionError, ...), its message starting "problem i of the batch".

    Warns
    -----
    IllConditionedWarning
        Naming the problems whose rcond(U11) < 1e-8 or residual > 1e-8.

    Examples
    --------
    Monte Carlo over an uncertain derivative: the 747's lateral regulator (c = 1) with its
    (β, r) entry of A, the weathercock stability, scattered by 10 %:

    >>> import numpy as np, aerocontrol
    >>> sys = aerocontrol.aircraft.load().lateral()
    >>> rng = np.random.default_rng(1)
    >>> A = np.repeat(sys.A[np.newaxis], 500, axis=0)
    >>> A[:, 3, 0] *= 1 + 0.1 * rng.standard_normal(500)
    >>> batch = aerocontrol.batch.solve_care_batch(A, sys.B, np.eye(4), np.eye(2))
    >>> batch.K.shape, bool(np.all(batch.closed_loop_poles.real < 0))
    ((500, 2, 4), True)
    """
    stacks = (_stack(A, "A"), _stack(B, "B"), _stack(Q, "Q"), _stack(R, "R"))
    batch = CareBatch(*_solved("care_batch", stacks, (bool(refine),), client, worker_threads))
    _warn(
        np.flatnonzero((batch.rcond < RCOND_WARNING) | (batch.residual > RESIDUAL_WARNING)),
        f"of the {len(batch)} Riccati solutions may be inaccurate (rcond(U11) < "
        f"{RCOND_WARNING:.0e} or relative residual > {RESIDUAL_WARNING:.0e})",
    )
    return batch


def solve_dare_batch(
    A: ArrayLike,
    B: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    client: Any = None,
    worker_threads: int | None = None,
) -> DareBatch:
    """Solve A_i^T X_i A_i - X_i - A_i^T X_i B_i (R_i + B_i^T X_i B_i)^-1 B_i^T X_i A_i + Q_i = 0
    for every problem i of a batch, in parallel, each exactly as :func:`aerocontrol.solve_dare`
    solves it alone (without the cross weight and E).

    The stacks are as in :func:`solve_care_batch`: each of A, B, Q and R one matrix shared by
    every problem or k of them.

    Parameters
    ----------
    A : array_like (n, n) or (k, n, n)
    B : array_like (n, m) or (k, n, m)
    Q : array_like (n, n) or (k, n, n)
    R : array_like (m, m) or (k, m, m)
    client : dask.distributed.Client, optional
        Solve in chunks on the Dask cluster, bitwise as here (default None: this machine's
        threads).
    worker_threads : int, optional
        With a ``client``: each chunk's parallel work runs on this many threads of its worker
        (:func:`aerocontrol.limit_threads`), so that workers do not oversubscribe their
        machine. The setting is the task thread's own, so a worker of several task threads
        runs each chunk on that many threads.

    Returns
    -------
    DareBatch
        ``X`` (k, n, n), ``K`` (k, m, n), ``closed_loop_poles`` (k, n, inside the unit
        circle), and the ``residual`` and ``rcond`` of each problem (k,).

    Raises
    ------
    ShapeError
        A stack that is neither one matrix nor k matrices, or shapes that disagree.
    AerocontrolError
        The first failing problem's own error (NoStabilizingSolutionError,
        SingularMatrixError, ...), its message starting "problem i of the batch".

    Warns
    -----
    IllConditionedWarning
        Naming the problems whose rcond(E U11) < 1e-8 or residual > 1e-8.

    Examples
    --------
    The 747's lateral regulator on a 50 Hz flight computer, over 200 weights:

    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()
    >>> d = aerocontrol.discretize(A, B, dt=0.02)
    >>> R = np.eye(2)[np.newaxis] / np.geomspace(1e-2, 10, 200)[:, np.newaxis, np.newaxis] ** 2
    >>> batch = aerocontrol.batch.solve_dare_batch(d.Phi, d.Gamma0, np.eye(4), R)
    >>> batch.K.shape, bool(np.all(abs(batch.closed_loop_poles) < 1))
    ((200, 2, 4), True)
    """
    stacks = (_stack(A, "A"), _stack(B, "B"), _stack(Q, "Q"), _stack(R, "R"))
    batch = DareBatch(*_solved("dare_batch", stacks, (), client, worker_threads))
    _warn(
        np.flatnonzero((batch.rcond < RCOND_WARNING) | (batch.residual > RESIDUAL_WARNING)),
        f"of the {len(batch)} discrete Riccati solutions may be inaccurate (rcond(U11) < "
        f"{RCOND_WARNING:.0e} or relative residual > {RESIDUAL_WARNING:.0e})",
    )
    return batch


def dlqr_sweep(
    sys_or_A: ArrayLike | SystemObject,
    B: ArrayLike | None = None,
    Q: ArrayLike | None = None,
    R: ArrayLike | None = None,
    weights: ArrayLike | None = None,
    client: Any = None,
    worker_threads: int | None = None,
) -> LqrSweep:
    """The discrete regulator of one sampled model for each weight c:
    J = Σ x_k^T Q x_k + (1/c²) u_k^T R u_k, as :func:`lqr_sweep` for continuous models, all
    solved in one parallel call (:func:`solve_dare_batch`).

    Parameters
    ----------
    sys_or_A : StateSpace or array_like (n, n)
        The sampled model (then B is not given), or its A.
    B : array_like (n, m) or (n,), optional
        Required with a matrix A.
    Q : array_like (n, n), optional
        The state weight (default the identity).
    R : array_like (m, m), optional
        The control weight before division by c² (default the identity).
    weights : array_like (k,)
        The weights c, positive and finite. Required.
    client : dask.distributed.Client, optional
        Solve in chunks on the Dask cluster, bitwise as here (default None: this machine's
        threads).
    worker_threads : int, optional
        With a ``client``: each chunk's parallel work runs on this many threads of its worker
        (:func:`aerocontrol.limit_threads`), so that workers do not oversubscribe their
        machine. The setting is the task thread's own, so a worker of several task threads
        runs each chunk on that many threads.

    Returns
    -------
    LqrSweep
        The ``weights`` (k,), gains ``K`` (k, m, n), closed-loop ``poles`` (k, n), Riccati
        solutions ``X`` (k, n, n), and the ``residual`` and ``rcond`` of each (k,).

    Raises
    ------
    InvalidArgumentError
        ``weights`` missing, not positive and finite, or so extreme that R / c² leaves the
        range of doubles; B missing with a matrix, or given with a system; a model of the
        other time base (a continuous system, dt = 0: use :func:`lqr_sweep`).
    ShapeError
        ``weights`` not 1-D, R not one matrix, or shapes that disagree.
    AerocontrolError
        The first failing weight's own error (NoStabilizingSolutionError, ...), its message
        starting "problem i of the batch".

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()
    >>> sampled = aerocontrol.c2d(aerocontrol.StateSpace(A, B), 0.1)
    >>> sweep = aerocontrol.batch.dlqr_sweep(sampled, weights=np.geomspace(1e-3, 10, 100))
    >>> sweep.K.shape, bool(np.all(abs(sweep.poles) < 1))
    ((100, 2, 4), True)
    """
    return _sweep("dlqr_sweep", True, sys_or_A, B, Q, R, weights, client, worker_threads)


def lqr_sweep(
    sys_or_A: ArrayLike | SystemObject,
    B: ArrayLike | None = None,
    Q: ArrayLike | None = None,
    R: ArrayLike | None = None,
    weights: ArrayLike | None = None,
    client: Any = None,
    worker_threads: int | None = None,
) -> LqrSweep:
    """The regulator of one model for each weight c: J = ∫ x^T Q x + (1/c²) η^T R η dt
    ((6.224)-(6.227); R/c² is the control weight), all solved in one parallel call.

    ``lqr_sweep(sys, Q=..., R=..., weights=c)`` or ``lqr_sweep(A, B, Q, R, weights=c)``; Q and
    R default to identities, as in the chapter. Returns the gains (k, m, n), the closed-loop
    poles (k, n) (each row as :func:`aerocontrol.lqr` returns its E), X, the residuals and the
    weights.

    Parameters
    ----------
    sys_or_A : StateSpace or array_like (n, n)
        The model (then B is not given), or its A.
    B : array_like (n, m) or (n,), optional
        Required with a matrix A.
    Q : array_like (n, n), optional
        The state weight (default the identity).
    R : array_like (m, m), optional
        The control weight before division by c² (default the identity).
    weights : array_like (k,)
        The weights c, positive and finite. Required.
    client : dask.distributed.Client, optional
        Solve in chunks on the Dask cluster, bitwise as here (default None: this machine's
        threads).
    worker_threads : int, optional
        With a ``client``: each chunk's parallel work runs on this many threads of its worker
        (:func:`aerocontrol.limit_threads`), so that workers do not oversubscribe their
        machine. The setting is the task thread's own, so a worker of several task threads
        runs each chunk on that many threads.

    Returns
    -------
    LqrSweep
        The ``weights`` (k,), gains ``K`` (k, m, n), closed-loop ``poles`` (k, n), Riccati
        solutions ``X`` (k, n, n), and the ``residual`` and ``rcond`` of each (k,).

    Raises
    ------
    InvalidArgumentError
        ``weights`` missing, not positive and finite, or so extreme that R / c² leaves the
        range of doubles; B missing with a matrix, or given with a system; a model of the
        other time base (a discrete system: use :func:`dlqr_sweep`).
    ShapeError
        ``weights`` not 1-D, R not one matrix, or shapes that disagree.
    AerocontrolError
        The first failing weight's own error (NoStabilizingSolutionError, ...), its message
        starting "problem i of the batch".

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> sweep = aerocontrol.batch.lqr_sweep(aerocontrol.aircraft.load().lateral(),
    ...                                     weights=np.geomspace(1e-3, 10, 1000))
    >>> sweep.K.shape, sweep.poles.shape
    ((1000, 2, 4), (1000, 4))
    """
    return _sweep("lqr_sweep", False, sys_or_A, B, Q, R, weights, client, worker_threads)


def _sweep(
    name: str,
    discrete: bool,
    sys_or_A: ArrayLike | SystemObject,
    B: ArrayLike | None,
    Q: ArrayLike | None,
    R: ArrayLike | None,
    weights: ArrayLike | None,
    client: Any,
    worker_threads: int | None,
) -> LqrSweep:
    """The sweep of :func:`lqr_sweep` (continuous) or :func:`dlqr_sweep` (discrete)."""
    if is_system(sys_or_A):
        if B is not None:
            raise InvalidArgumentError(f"{name}(sys, Q=..., R=..., weights=...) takes no B")
        sys = as_state_space(sys_or_A)
        if not discrete:
            require_continuous(sys, name, "use dlqr_sweep")
        else:
            require_discrete(sys_or_A, name, "use lqr_sweep, or discretise the model first (c2d)")
        A_matrix, B_matrix = sys.A, sys.B
    else:
        if B is None:
            raise InvalidArgumentError(f"{name}(A, B, Q, R, weights) needs B")
        A_matrix, B_matrix = real_array(sys_or_A, "A"), real_array(B, "B")
        if B_matrix.ndim == 1:
            B_matrix = B_matrix.reshape(-1, 1)
    if weights is None:
        raise InvalidArgumentError("weights must be given: a 1-D array of positive numbers c")
    c = np.atleast_1d(real_array(weights, "weights")).copy()  # the result's own
    if c.ndim != 1:
        raise ShapeError(f"weights must be a 1-D array, got shape {c.shape}")
    bad = np.flatnonzero(~(np.isfinite(c) & (c > 0)))
    if bad.size:
        raise InvalidArgumentError(
            f"weights must be positive and finite, but weights[{bad[0]}] = {c[bad[0]]}"
        )
    n = A_matrix.shape[0] if A_matrix.ndim == 2 else 0
    m = B_matrix.shape[1] if B_matrix.ndim == 2 else 0
    Q_matrix = np.eye(n) if Q is None else real_array(Q, "Q")
    R_matrix = np.eye(m) if R is None else np.atleast_2d(real_array(R, "R"))
    if R_matrix.ndim != 2:
        raise ShapeError(f"R must be one m x m matrix, got shape {R_matrix.shape}")
    # R / c², as lqr(A, B, Q, R / c**2) forms it, where c² is a normal double; where c²
    # underflows into the subnormals (losing digits) or overflows, R / c / c, which is an
    # ordinary double whenever R / c² is one.
    with np.errstate(over="ignore", under="ignore", divide="ignore", invalid="ignore"):
        square = c * c
        normal = np.isfinite(square) & (square >= np.finfo(np.float64).tiny)
        scale = c[:, np.newaxis, np.newaxis]
        R_stack = np.where(
            normal[:, np.newaxis, np.newaxis],
            R_matrix[np.newaxis] / square[:, np.newaxis, np.newaxis],
            R_matrix[np.newaxis] / scale / scale,
        )
    if np.all(np.isfinite(R_matrix)):
        # R / c^2 overflowed, or a nonzero entry of R underflowed to zero.
        lost = ~np.all(np.isfinite(R_stack), axis=(1, 2)) | np.any(
            (R_stack == 0) & (R_matrix != 0), axis=(1, 2)
        )
        if np.any(lost):
            k = int(np.flatnonzero(lost)[0])
            error = InvalidArgumentError(
                f"weights[{k}] = {c[k]:g} is out of range for R: R / c^2 leaves the range of "
                "double precision (scale R or the weights)"
            )
            error.argument = "weights"
            raise error
    solve = solve_dare_batch if discrete else solve_care_batch
    batch = solve(
        A_matrix, B_matrix, Q_matrix, R_stack, client=client, worker_threads=worker_threads
    )
    return LqrSweep(c, batch.K, batch.closed_loop_poles, batch.X, batch.residual, batch.rcond)
