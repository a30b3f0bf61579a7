"""State estimation: the Kalman filter, observers by pole placement, and the LQG compensator.

The plant, with process noise w and measurement noise v (white, zero mean),

    x' = A x + B u + G w,     y = C x + D u + v,
    E{w w^T} = QN,  E{v v^T} = RN,  E{w v^T} = NN,

or its discrete-time form x[k+1] = A x[k] + B u[k] + G w[k], y[k] = C x[k] + D u[k] + v[k].
Every estimator here is an observer x̂' = A x̂ + B u + L (y - C x̂ - D u): its error
e = x - x̂ obeys e' = (A - L C) e + G w - L v, so the poles of the estimator are eig(A - L C).
The gains come from the regulator's algorithms by duality: (A - L C)^T = A^T - C^T L^T is a
state-feedback loop of the pair (A^T, C^T), so

* :func:`lqe` (continuous Kalman-Bucy filter) solves, with :func:`~aerocontrol.solve_care`,
  A P + P A^T - (P C^T + G NN) RN^-1 (C P + NN^T G^T) + G QN G^T = 0 and returns
  L = (P C^T + G NN) RN^-1;
* :func:`dlqe` (discrete Kalman filter) solves, with :func:`~aerocontrol.solve_dare`,
  A P A^T - P - (A P C^T + G NN)(C P C^T + RN)^-1 (C P A^T + NN^T G^T) + G QN G^T = 0;
* :func:`kalman` returns both of these as a :class:`KalmanFilter` with the estimator's
  matrices, and names the two gains of the discrete filter apart;
* :func:`place_observer` puts eig(A - L C) where asked, through :func:`~aerocontrol.place`;
* :func:`lqg` joins a Kalman filter to an LQR regulator (η = -K x̂): by the separation
  principle the closed loop's poles are those of the regulator and of the filter together.

:func:`lqe` and :func:`dlqe` are called and return as python-control's functions of those
names; unlike python-control they accept the cross covariance NN.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._results import Result, register_model
from ._validation import FloatArray, as_matrix, real_array, real_scalar
from .controllability import observability
from .exceptions import (
    AerocontrolError,
    IllConditionedError,
    IllConditionedWarning,
    InvalidArgumentError,
    NonFiniteError,
    NoStabilizingSolutionError,
    NotPositiveDefiniteError,
    ShapeError,
    SingularMatrixError,
    UncontrollableError,
)
from .placement import POLE_ERROR_WARNING, place
from .riccati import CareSolution, DareSolution, solve_care, solve_dare
from .statespace import (
    StateSpace,
    as_state_space,
    is_continuous_model,
    is_system,
    require_discrete,
)

if TYPE_CHECKING:
    from ._typing import System, SystemObject

__all__ = [
    "KalmanFilter",
    "LqgDesign",
    "dlqe",
    "kalman",
    "lqe",
    "lqg",
    "place_observer",
]

# The designs hold their models (JSON form and equality of the results).
register_model(StateSpace)

ComplexArray = NDArray[np.complex128]
_Result = TypeVar("_Result")

#: Relative asymmetry max|M - M^T| / max|M| above which a covariance is refused (the
#: Riccati solvers' own test of Q and R).
SYMMETRY_TOLERANCE = 1e-12


# --- Arguments -------------------------------------------------------------------------------


def _matrix(value: object, name: str, scalar_ok: bool = False) -> FloatArray:
    """``value`` as a finite, C-ordered 2-D float64 array (a copy when it was not one: the
    caller's array is never written, and every layout gives the same bits), or the error
    naming ``name`` (also in its ``argument``). Scalars, vectors (a 1-D G a column, a 1-D C a
    row) and ``numpy.matrix`` are read by :func:`~aerocontrol._validation.as_matrix`; with
    ``scalar_ok`` a vector of one number is a 1 x 1 matrix too."""
    try:
        if isinstance(value, np.matrix):
            value = value.view(np.ndarray)
        array = real_array(value, name)
        if scalar_ok and array.ndim < 2 and array.size == 1:
            array = array.reshape(1, 1)
        array = real_array(as_matrix(array, name), name)
    except AerocontrolError as refused:
        refused.argument = name
        raise
    finite = np.isfinite(array)
    if not finite.all():
        row, column = (int(k) for k in np.argwhere(~finite)[0])
        entry = float(array[row, column])
        shown = "NaN" if np.isnan(entry) else str(entry)
        error = NonFiniteError(f"{name} must be finite, but {name}[{row}, {column}] is {shown}")
        error.argument, error.entry, error.value = name, [row, column], entry
        raise error
    return np.ascontiguousarray(array)


def _shape_error(name: str, message: str) -> ShapeError:
    error = ShapeError(message)
    error.argument = name
    return error


def _square(matrix: FloatArray, name: str, order: int, why: str) -> None:
    """``matrix`` must be order x order (``why`` says where the order comes from)."""
    if matrix.shape != (order, order):
        raise _shape_error(name, f"{name} must be {order} x {order} ({why}), got {matrix.shape}")


def _symmetric(matrix: FloatArray, name: str) -> None:
    """``matrix`` must be symmetric to the Riccati solvers' tolerance."""
    if matrix.size == 0:
        return
    asymmetry = float(np.abs(matrix - matrix.T).max())
    scale = float(np.abs(matrix).max())
    if asymmetry > SYMMETRY_TOLERANCE * scale:
        error = InvalidArgumentError(
            f"{name} must be symmetric (a covariance), but max|{name} - {name}^T| = "
            f"{asymmetry:.3e} is more than {SYMMETRY_TOLERANCE:.0e} times max|{name}| = "
            f"{scale:.3e}"
        )
        error.argument = name
        raise error


def _positive_definite(matrix: FloatArray, name: str) -> None:
    """``matrix`` (symmetric) must be positive definite: the continuous filter divides by
    the measurement noise's covariance."""
    try:
        np.linalg.cholesky(matrix)
    except np.linalg.LinAlgError:
        error = NotPositiveDefiniteError(
            f"{name} must be symmetric positive definite (every measurement noisy), but its "
            f"Cholesky factorisation failed: {name} has an eigenvalue <= 0 (to working "
            "precision)"
        )
        error.argument = name
        raise error from None


@dataclass(frozen=True)
class _NoiseModel:
    """The checked matrices of an estimation problem, each C-ordered float64."""

    A: FloatArray
    G: FloatArray
    C: FloatArray
    QN: FloatArray
    RN: FloatArray
    NN: FloatArray | None


def _noise_model(
    A: object, G: object, C: object, QN: object, RN: object, NN: object | None
) -> _NoiseModel:
    """Check every matrix by name: shapes against A, G and C, finiteness, symmetry."""
    A = _matrix(A, "A")
    if A.shape[0] != A.shape[1]:
        raise _shape_error("A", f"A must be square, got {A.shape}")
    n = A.shape[0]
    G = _matrix(G, "G")
    if G.shape[0] != n:
        raise _shape_error("G", f"G must have as many rows as A ({n}), got {G.shape[0]}")
    C = _matrix(C, "C")
    if C.shape[1] != n:
        raise _shape_error("C", f"C must have as many columns as A ({n}), got {C.shape[1]}")
    g, p = G.shape[1], C.shape[0]
    QN = _matrix(QN, "QN", scalar_ok=True)
    _square(QN, "QN", g, f"G has {g} columns")
    _symmetric(QN, "QN")
    RN = _matrix(RN, "RN", scalar_ok=True)
    _square(RN, "RN", p, f"C has {p} rows")
    _symmetric(RN, "RN")
    if NN is not None:
        NN = _matrix(NN, "NN", scalar_ok=True)
        if NN.shape != (g, p):
            raise _shape_error(
                "NN", f"NN must be {g} x {p} (G has {g} columns, C {p} rows), got {NN.shape}"
            )
    return _NoiseModel(A, G, C, QN, RN, NN)


def _system_time(sys: object) -> tuple[bool, float | None]:
    """(discrete, dt) of a model's sampling time: python-control's ``dt`` (0 continuous,
    True discrete with an unspecified period, a number the period); None or no ``dt``
    attribute is continuous."""
    dt = getattr(sys, "dt", None)
    if dt is None or (not isinstance(dt, bool) and dt == 0):
        return False, None
    if dt is True:
        return True, None
    return True, real_scalar(dt, "sys.dt")


def _estimator_arguments(
    name: str, sys_or_A: ArrayLike | SystemObject, args: tuple[ArrayLike, ...], NN: object | None
) -> _NoiseModel:
    """The checked matrices of python-control's ``name(sys, QN, RN[, NN])`` or
    ``name(A, G, C, QN, RN[, NN])``; a system's B is G."""
    count = len(args)
    A: ArrayLike  # the system's matrices or the caller's
    G: ArrayLike
    C: ArrayLike
    if is_system(sys_or_A):
        if count not in (2, 3):
            raise InvalidArgumentError(
                f"{name}(sys, QN, RN[, NN]) takes a system and two or three covariances"
            )
        sys = as_state_space(sys_or_A)
        A, G, C, QN, RN = sys.A, sys.B, sys.C, args[0], args[1]
        given = 2
    else:
        if count not in (4, 5):
            raise InvalidArgumentError(f"{name}(A, G, C, QN, RN[, NN]) takes five or six matrices")
        A, G, C, QN, RN = sys_or_A, args[0], args[1], args[2], args[3]
        given = 4
    if count > given:
        if NN is not None:
            raise InvalidArgumentError("NN given both by position and by keyword")
        NN = args[given]
    return _noise_model(A, G, C, QN, RN, NN)


# --- The filter Riccati equations ------------------------------------------------------------


def _reissuing_warnings(call: Callable[[], _Result], stacklevel: int) -> _Result:
    """``call()``, with the warnings it issues re-issued at ``stacklevel`` as seen from this
    function (2 is its caller): the Riccati solvers point theirs at their own caller, which
    here is this module, not the user's code."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = call()
    for warning in caught:
        warnings.warn(warning.message, warning.category, stacklevel=stacklevel)
    return result


def _undetectable_modes(model: _NoiseModel, discrete: bool) -> ComplexArray:
    """The eigenvalues of A that C does not see and that are not stable."""
    hidden = observability(model.A, model.C).uncontrollable_eigenvalues
    margin = np.sqrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(hidden))
    unstable = np.abs(hidden) >= 1 - margin if discrete else hidden.real >= -margin
    return np.asarray(hidden[unstable], dtype=np.complex128)


def _no_filter(model: _NoiseModel, discrete: bool, error: Exception) -> Exception:
    """The error to raise when the filter's Riccati equation has no stabilising solution:
    NoStabilizingSolutionError naming the undetectable modes when there are any; else
    NoStabilizingSolutionError for the solver's own, and the solver's error unchanged when
    it is of another kind (an IllConditionedError that detectability does not explain)."""
    hidden = _undetectable_modes(model, discrete)
    reported = f"(the filter's Riccati equation, the regulator's for (A^T, C^T), reported: {error})"
    if hidden.size:
        region = "on or outside the unit circle" if discrete else "with Re >= 0"
        listed = ", ".join(f"{complex(e):.6g}" for e in hidden)
        result = NoStabilizingSolutionError(
            f"the Kalman filter does not exist: (C, A) is not detectable; the eigenvalue(s) "
            f"{listed} of A, {region}, cannot be seen in C x, so no gain L moves them in "
            f"A - L C {reported}"
        )
        result.eigenvalues = [complex(e) for e in hidden]
        return result
    if isinstance(error, NoStabilizingSolutionError):
        boundary = "the unit circle" if discrete else "the imaginary axis"
        return NoStabilizingSolutionError(
            f"the Kalman filter does not exist to working precision: a mode of A on "
            f"{boundary} is not excited by the process noise G w, or a mode that is not "
            f"stable is seen in C x too weakly to be told apart from an undetectable one "
            f"{reported}"
        )
    return error


@dataclass(frozen=True)
class _FilterSolution:
    L: FloatArray
    """The observer gain: L of x̂' = A x̂ + ... + L (y - C x̂ - D u), the predictor gain of a
    discrete filter."""
    P: FloatArray
    """The Riccati solution: the error covariance (a priori for a discrete filter)."""
    poles: ComplexArray
    """eig(A - L C)."""
    M: FloatArray | None
    """The discrete filter's measurement-update gain P C^T (C P C^T + RN)^-1."""
    posterior: FloatArray | None
    """The discrete filter's a posteriori covariance (I - M C) P."""


#: The user's frame seen from :func:`_reissuing_warnings` when it is called by
#: :func:`_solve_filter`, called by a public function.
_USER_FRAME_VIA_SOLVE_FILTER = 4


_Formed = TypeVar("_Formed")


def _formed(what: str, arguments: str, compute: Callable[[], _Formed]) -> _Formed:
    """A product of the caller's matrices, refused by name if it overflows double precision
    (numpy's own overflow warning never reaches the caller)."""
    with np.errstate(over="raise", invalid="raise"):
        try:
            return compute()
        except FloatingPointError:
            error = InvalidArgumentError(
                f"{what} overflows double precision: the entries of {arguments} are too large "
                "together (scale the model's units)"
            )
            error.argument = arguments.split(",")[0]
            raise error from None


def _symmetric_part(M: FloatArray) -> FloatArray:
    """(M + M^T) / 2, halved before the sum so that it overflows only if M does."""
    half: FloatArray = 0.5 * M
    symmetric: FloatArray = half + half.T
    return symmetric


def _solve_filter(model: _NoiseModel, discrete: bool) -> _FilterSolution:
    """The stationary Kalman filter of ``model`` by the dual Riccati equation. Only call it
    directly from a public function (its warnings are re-issued at that function's caller)."""
    A, G, C, RN = model.A, model.G, model.C, model.RN
    # Exactly symmetric, as the solvers require.
    process = _formed("G QN G^T", "G, QN", lambda: _symmetric_part(G @ model.QN @ G.T))
    NN = model.NN
    cross = None if NN is None else _formed("G NN", "G, NN", lambda: G @ NN)
    if not discrete:
        _positive_definite(RN, "RN")
    try:
        if discrete:
            solution: CareSolution | DareSolution = _reissuing_warnings(
                lambda: solve_dare(A.T, C.T, process, RN, cross), _USER_FRAME_VIA_SOLVE_FILTER
            )
        else:
            solution = _reissuing_warnings(
                lambda: solve_care(A.T, C.T, process, RN, cross), _USER_FRAME_VIA_SOLVE_FILTER
            )
    except (NoStabilizingSolutionError, IllConditionedError) as error:
        replacement = _no_filter(model, discrete, error)
        if replacement is error:
            raise
        raise replacement from error
    X, poles = solution.X, solution.closed_loop_poles
    L = np.ascontiguousarray(solution.K.T)
    if not discrete:
        return _FilterSolution(L, X, poles, None, None)
    CP = _formed("C P", "C", lambda: C @ X)
    innovation = _formed("C P C^T + RN", "C, RN", lambda: _symmetric_part(CP @ C.T + RN))
    try:
        M = np.ascontiguousarray(np.linalg.solve(innovation, CP).T)
    except np.linalg.LinAlgError:
        raise SingularMatrixError(
            "C P C^T + RN, the covariance of the innovation y - C x̂, is singular: some "
            "measurement is noise-free and repeats what P already knows exactly"
        ) from None
    posterior = _formed("(I - M C) P", "C", lambda: _symmetric_part(X - M @ CP))
    return _FilterSolution(L, X, poles, M, posterior)


# --- lqe, dlqe -------------------------------------------------------------------------------


def lqe(
    sys_or_A: ArrayLike | SystemObject, *args: ArrayLike, NN: ArrayLike | None = None
) -> tuple[FloatArray, FloatArray, ComplexArray]:
    """The continuous-time Kalman filter's gain, called and returning as python-control's
    ``lqe``.

    ``lqe(A, G, C, QN, RN[, NN])`` or ``lqe(sys, QN, RN[, NN])`` (then G is the system's B
    and C its C) give the stationary filter x̂' = A x̂ + B u + L (y - C x̂ - D u) of
    x' = A x + B u + G w, y = C x + D u + v with E{w w^T} = QN, E{v v^T} = RN and
    E{w v^T} = NN (zero by default; python-control does not accept it). A discrete-time
    system (python-control's ``dt`` not 0) is passed on to :func:`dlqe`, as python-control
    does.

    Method: by duality, :func:`~aerocontrol.solve_care` for (A^T, C^T) with the weights
    G QN G^T and RN and the cross weight G NN: the stabilising P of
    A P + P A^T - (P C^T + G NN) RN^-1 (C P + NN^T G^T) + G QN G^T = 0, and
    L = (P C^T + G NN) RN^-1.

    Parameters
    ----------
    sys_or_A : StateSpace or array_like (n, n)
        A system (its B is G, its C the measurement), or the plant matrix A.
    *args : array_like
        With a system: ``QN, RN[, NN]``. With a matrix: ``G, C, QN, RN[, NN]``: G (n, g) how
        the process noise enters, C (p, n), the process noise covariance QN (g, g), the
        measurement noise covariance RN (p, p) (positive definite), the cross covariance
        NN (g, p).
    NN : array_like (g, p), optional
        The cross covariance, by keyword (default zero).

    Returns
    -------
    L : ndarray (n, p)
        The filter gain.
    P : ndarray (n, n)
        The steady-state covariance of the estimation error x - x̂.
    E : ndarray (n,) of complex128
        The estimator's poles, eig(A - L C), all with Re < 0.

    Raises
    ------
    ShapeError, NonFiniteError, InvalidArgumentError
        A matrix has the wrong shape or is not finite, or QN or RN is not symmetric; the
        message names it.
    NotPositiveDefiniteError
        RN is not positive definite.
    NoStabilizingSolutionError
        (C, A) is not detectable (the message names the modes C cannot see), or a mode on
        the imaginary axis is neither measured nor excited by the noise.

    Warns
    -----
    IllConditionedWarning
        As :func:`~aerocontrol.solve_care`.

    Examples
    --------
    The 747's lateral motion measured by roll rate, yaw rate and bank angle (not sideslip),
    with process noise on both control surfaces:

    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()       # x = (β, p, φ, r)
    >>> C = np.eye(4)[[1, 3, 2]]                             # y = (p, r, φ)
    >>> L, P, E = aerocontrol.lqe(A, B, C, np.eye(2), 1e-2 * np.eye(3))
    >>> L.shape, bool(np.all(E.real < 0))
    ((4, 3), True)
    """
    discrete = is_system(sys_or_A) and _system_time(sys_or_A)[0]
    model = _estimator_arguments("dlqe" if discrete else "lqe", sys_or_A, args, NN)
    solution = _solve_filter(model, discrete)
    return solution.L, solution.P, solution.poles


def dlqe(
    sys_or_A: ArrayLike | SystemObject, *args: ArrayLike, NN: ArrayLike | None = None
) -> tuple[FloatArray, FloatArray, ComplexArray]:
    """The discrete-time Kalman filter's gain, called and returning as python-control's
    ``dlqe``.

    ``dlqe(A, G, C, QN, RN[, NN])`` or ``dlqe(sys, QN, RN[, NN])`` for
    x[k+1] = A x[k] + B u[k] + G w[k], y[k] = C x[k] + D u[k] + v[k], with
    E{w w^T} = QN, E{v v^T} = RN and E{w[k] v[k]^T} = NN (zero by default).

    The gain returned is python-control's: the *predictor* gain L of the one-step predictor
    x̂[k+1|k] = A x̂[k|k-1] + B u[k] + L (y[k] - C x̂[k|k-1] - D u[k]), and P is the
    covariance of its error x[k] - x̂[k|k-1] (the a priori covariance). With NN = 0,
    L = A M, where M = P C^T (C P C^T + RN)^-1 is the gain of the measurement update
    x̂[k|k] = x̂[k|k-1] + M (y[k] - C x̂[k|k-1] - D u[k]) that MATLAB's ``dlqe`` returns;
    :func:`kalman` returns both, by name.

    Method: by duality, :func:`~aerocontrol.solve_dare` for (A^T, C^T) with the weights
    G QN G^T and RN and the cross weight G NN: the stabilising P of
    A P A^T - P - (A P C^T + G NN)(C P C^T + RN)^-1 (C P A^T + NN^T G^T) + G QN G^T = 0,
    and L = (A P C^T + G NN)(C P C^T + RN)^-1. RN need not be definite, only C P C^T + RN
    nonsingular.

    Parameters
    ----------
    sys_or_A : StateSpace or array_like (n, n)
        A discrete-time system (its B is G, its C the measurement), or the transition matrix A.
    *args : array_like
        With a system: ``QN, RN[, NN]``. With a matrix: ``G, C, QN, RN[, NN]``: G (n, g), C
        (p, n), the process noise covariance QN (g, g), the measurement noise covariance
        RN (p, p), the cross covariance NN (g, p).
    NN : array_like (g, p), optional
        The cross covariance, by keyword (default zero).

    Returns
    -------
    L : ndarray (n, p)
        The predictor gain.
    P : ndarray (n, n)
        The a priori error covariance.
    E : ndarray (n,) of complex128
        The estimator's poles, eig(A - L C), inside the unit circle.

    Raises
    ------
    NoStabilizingSolutionError
        (C, A) is not detectable (the message names the modes C cannot see), or a mode on
        the unit circle is neither measured nor excited by the noise.
    InvalidArgumentError
        ``sys`` is a continuous-time python-control model (dt = 0); and as :func:`lqe` for
        shapes and values.

    Examples
    --------
    A random walk x[k+1] = x[k] + w[k] measured as y = x + v, QN = 1, RN = 1: P solves
    P^2 - P - 1 = 0 (the golden ratio), and L = M = P / (P + 1):

    >>> import aerocontrol
    >>> L, P, E = aerocontrol.dlqe([[1.0]], [[1.0]], [[1.0]], [[1.0]], [[1.0]])
    >>> round(float(P[0, 0]), 12), round((1 + 5**0.5) / 2, 12)
    (1.61803398875, 1.61803398875)
    >>> round(float(L[0, 0]), 12), round(float(E[0].real), 12)
    (0.61803398875, 0.38196601125)
    """
    if is_system(sys_or_A):
        require_discrete(sys_or_A, "dlqe", "use lqe, or discretise the model first (c2d)")
    model = _estimator_arguments("dlqe", sys_or_A, args, NN)
    solution = _solve_filter(model, True)
    return solution.L, solution.P, solution.poles


# --- kalman ----------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class KalmanFilter(Result):
    """A stationary Kalman filter and its estimator, from :func:`kalman`.

    Continuous time (``discrete`` False): x̂' = A x̂ + B u + L (y - C x̂ - D u), with
    L = :attr:`gain`.

    Discrete time (``discrete`` True) has two gains, named apart (``gain`` is refused):

    * the measurement update (current estimate), with M = :attr:`filter_gain`:
      x̂[k|k] = x̂[k|k-1] + M (y[k] - C x̂[k|k-1] - D u[k]), M = P C^T (C P C^T + RN)^-1;
    * the one-step predictor, with L = :attr:`predictor_gain`:
      x̂[k+1|k] = A x̂[k|k-1] + B u[k] + L (y[k] - C x̂[k|k-1] - D u[k]),
      L = (A P C^T + G NN)(C P C^T + RN)^-1, which is A M when NN = 0.

    The estimator is the model (``estimator_A``, ``estimator_B``, ``estimator_C``,
    ``estimator_D``) = (A - L C, [B - L D, L], I, 0): its input is [u; y], its state and
    output x̂ (x̂[k|k-1] in discrete time). For a discrete filter the current estimate is
    (I - M C) x̂[k|k-1] + M (y[k] - D u[k]).

    Attributes
    ----------
    P : ndarray (n, n)
        The steady-state covariance of the estimation error (discrete time: of x[k] - x̂[k|k-1],
        the a priori covariance).
    closed_loop_poles : ndarray (n,), complex
        The estimator's poles, eig(A - L C) (L the predictor gain in discrete time).
    estimator_A : ndarray (n, n)
        A - L C.
    estimator_B : ndarray (n, m + p)
        [B - L D, L]: the inputs are the known inputs u, then the outputs y.
    estimator_C : ndarray (n, n)
        The identity: the estimator's output is its state.
    estimator_D : ndarray (n, m + p)
        Zero.
    discrete : bool
        Whether the filter is a discrete-time one.
    dt : float or None
        The sampling period of a discrete filter (s) when known; None for a continuous one.
    gain : ndarray (n, p)
        L of the continuous filter (refused for a discrete one).
    filter_gain : ndarray (n, p)
        M of the discrete filter's measurement update x̂[k|k].
    predictor_gain : ndarray (n, p)
        L of the discrete filter's one-step prediction x̂[k+1|k] (python-control's ``dlqe``
        gain).
    posterior_covariance : ndarray (n, n)
        (I - M C) P, the covariance of x[k] - x̂[k|k] of the discrete filter.

    Examples
    --------
    x' = -x + w, y = x + v with unit intensities: P solves 1 - 2P - P² = 0, so P = L = √2 - 1
    and the estimator's pole is -√2:

    >>> import numpy as np, aerocontrol
    >>> kf = aerocontrol.kalman(([[-1.0]], [[1.0]], [[1.0]]), [[1.0]], [[1.0]])
    >>> np.round(kf.P, 6), np.round(kf.gain, 6)
    (array([[0.414214]]), array([[0.414214]]))
    >>> np.round(kf.closed_loop_poles.real, 6), kf.estimator_B.shape
    (array([-1.414214]), (1, 2))
    """

    P: FloatArray
    """The steady-state covariance of the estimation error, n x n (discrete time: of
    x[k] - x̂[k|k-1], the a priori covariance)."""
    closed_loop_poles: ComplexArray
    """The estimator's poles, eig(A - L C) (L the predictor gain in discrete time)."""
    estimator_A: FloatArray
    """A - L C, n x n."""
    estimator_B: FloatArray
    """[B - L D, L], n x (m + p): the inputs are the known inputs u, then the outputs y."""
    estimator_C: FloatArray
    """The identity, n x n: the estimator's output is its state."""
    estimator_D: FloatArray
    """Zero, n x (m + p)."""
    discrete: bool
    """Whether the filter is a discrete-time one."""
    dt: float | None
    """The sampling period of a discrete filter when known; None for a continuous one."""
    _observer_gain: FloatArray
    _update_gain: FloatArray | None
    _posterior: FloatArray | None

    def __repr__(self) -> str:
        n, p = self._observer_gain.shape
        if not self.discrete:
            kind = "continuous"
        else:
            kind = "discrete" + ("" if self.dt is None else f", dt={self.dt:g}")
        return (
            f"KalmanFilter({kind}, n_states={n}, n_outputs={p}, closed_loop_poles="
            f"{np.array2string(self.closed_loop_poles, precision=4)})"
        )

    @property
    def gain(self) -> FloatArray:
        """L of the continuous filter, n x p (a discrete filter has two gains:
        :attr:`filter_gain` and :attr:`predictor_gain`)."""
        if self.discrete:
            raise AttributeError(
                "a discrete Kalman filter has two gains: filter_gain (M, the measurement "
                "update x̂[k|k]) and predictor_gain (L, the one-step prediction x̂[k+1|k])"
            )
        return self._observer_gain

    @property
    def filter_gain(self) -> FloatArray:
        """M of the discrete filter's measurement update x̂[k|k], n x p."""
        if self._update_gain is None:
            raise AttributeError("a continuous Kalman filter has one gain: gain")
        return self._update_gain

    @property
    def predictor_gain(self) -> FloatArray:
        """L of the discrete filter's one-step prediction x̂[k+1|k], n x p (python-control's
        ``dlqe`` gain)."""
        if not self.discrete:
            raise AttributeError("a continuous Kalman filter has one gain: gain")
        return self._observer_gain

    @property
    def posterior_covariance(self) -> FloatArray:
        """(I - M C) P, the covariance of x[k] - x̂[k|k] of the discrete filter."""
        if self._posterior is None:
            raise AttributeError(
                "a continuous Kalman filter has one covariance: P (there is no measurement update)"
            )
        return self._posterior


def _sampling_time(sys: object, dt: object) -> tuple[bool, float | None]:
    """(discrete, dt) from the model's own ``dt`` and the ``dt`` argument."""
    own_discrete, own_dt = _system_time(sys) if is_system(sys) else (False, None)
    if dt is None:
        return own_discrete, own_dt
    period = real_scalar(dt, "dt")
    if not (np.isfinite(period) and period > 0):
        error = InvalidArgumentError(f"dt must be a positive sampling period, got {period}")
        error.argument, error.value = "dt", period
        raise error
    if is_system(sys) and is_continuous_model(sys):
        raise InvalidArgumentError(
            "sys is a continuous-time model: dt marks the given matrices as discrete-time, it "
            "does not discretise them; discretise the model first (aerocontrol.c2d)"
        )
    if own_dt is not None and own_dt != period:
        raise InvalidArgumentError(f"dt = {period} disagrees with the model's dt = {own_dt}")
    return True, period


def kalman(
    sys_or_matrices: System | tuple[ArrayLike, ArrayLike, ArrayLike],
    QN: ArrayLike,
    RN: ArrayLike,
    NN: ArrayLike | None = None,
    dt: float | None = None,
    *,
    G: ArrayLike | None = None,
) -> KalmanFilter:
    """The stationary Kalman filter of a plant with known inputs, and its estimator.

    The plant is x' = A x + B u + G w, y = C x + D u + v (continuous time), or
    x[k+1] = A x[k] + B u[k] + G w[k], y[k] = C x[k] + D u[k] + v[k] (discrete time), with
    E{w w^T} = QN, E{v v^T} = RN, E{w v^T} = NN (zero by default).

    Continuous time: the filter x̂' = A x̂ + B u + L (y - C x̂ - D u), L as :func:`lqe`.

    Discrete time: the one-step predictor
    x̂[k+1|k] = A x̂[k|k-1] + B u[k] + L (y[k] - C x̂[k|k-1] - D u[k]) and the measurement
    update x̂[k|k] = x̂[k|k-1] + M (y[k] - C x̂[k|k-1] - D u[k]), with
    M = P C^T (C P C^T + RN)^-1 and L = (A P C^T + G NN)(C P C^T + RN)^-1 (= A M when
    NN = 0), P the a priori covariance, as :func:`dlqe`.

    Parameters
    ----------
    sys_or_matrices : system, or (A, B, C) or (A, B, C, D)
        The plant; D is zero when not given. A python-control model brings its ``dt``.
    QN, RN : array_like
        The covariances of w and v.
    NN : array_like, optional
        Their cross covariance.
    dt : float, optional
        The sampling period: the matrices are then those of the discrete-time plant. It does
        not discretise a continuous model (use :func:`~aerocontrol.discretize` first).
    G : array_like (n, g), optional
        How the process noise enters; B by default (the noise adds to the inputs, as
        python-control's ``lqe(sys, ...)`` takes it).

    Returns
    -------
    KalmanFilter
        ``gain`` (continuous), or ``filter_gain`` and ``predictor_gain`` (discrete); ``P``;
        ``closed_loop_poles``; the estimator's matrices.

    Raises
    ------
    As :func:`lqe` and :func:`dlqe`; InvalidArgumentError for a ``dt`` that is not a
    positive number, that disagrees with the model's, or given with a continuous-time
    python-control model.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()
    >>> plant = aerocontrol.discretize(A, B, dt=0.02)
    >>> C = np.eye(4)[[1, 3, 2]]                             # measure p, r, φ
    >>> kf = aerocontrol.kalman((plant.Phi, plant.Gamma0, C), np.eye(2), 1e-4 * np.eye(3),
    ...                         dt=0.02)
    >>> np.allclose(kf.predictor_gain, plant.Phi @ kf.filter_gain)      # L = A M
    True
    >>> kf.estimator_B.shape, bool(np.all(abs(kf.closed_loop_poles) < 1))
    ((4, 5), True)
    """
    discrete, period = _sampling_time(sys_or_matrices, dt)
    if isinstance(sys_or_matrices, (tuple, list)) and len(sys_or_matrices) == 3:
        plant = StateSpace(*sys_or_matrices)
    else:
        plant = as_state_space(sys_or_matrices, "sys_or_matrices")
    A, B, C, D = plant.A, plant.B, plant.C, plant.D
    model = _noise_model(A, B if G is None else G, C, QN, RN, NN)
    solution = _solve_filter(model, discrete)
    L = solution.L
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    return KalmanFilter(
        P=solution.P,
        closed_loop_poles=solution.poles,
        estimator_A=A - L @ C,
        estimator_B=np.hstack([B - L @ D, L]),
        estimator_C=np.eye(n),
        estimator_D=np.zeros((n, m + p)),
        discrete=discrete,
        dt=period,
        _observer_gain=L,
        _update_gain=solution.M,
        _posterior=solution.posterior,
    )


# --- place_observer --------------------------------------------------------------------------


def _pole_error(requested: ComplexArray, closed_loop: FloatArray) -> float:
    """The largest relative distance from a requested pole to the nearest eigenvalue of
    ``closed_loop`` not yet matched (greedy, as :func:`~aerocontrol.place` matches them)."""
    computed = list(np.linalg.eigvals(closed_loop))
    scale = float(np.linalg.norm(closed_loop)) or 1.0
    worst = 0.0
    for pole in requested:
        distances = [abs(value - pole) for value in computed]
        nearest = int(np.argmin(distances))
        worst = max(worst, distances[nearest] / (abs(pole) or scale))
        computed.pop(nearest)
    return worst


def place_observer(
    A_or_sys: ArrayLike | System, C: ArrayLike | None = None, poles: ArrayLike | None = None
) -> FloatArray:
    """The observer gain L that puts the eigenvalues of A - L C at ``poles``.

    By duality: (A - L C)^T = A^T - C^T L^T, so L = K^T for the state-feedback gain K that
    :func:`~aerocontrol.place` (Kautsky-Nichols-Van Dooren) computes for (A^T, C^T). The
    achieved poles, eig(A - L C), are checked against the requested ones.

    Parameters
    ----------
    A_or_sys : array_like (n, n), or a system with A and C
    C : array_like (p, n), full row rank, no zero row
    poles : sequence of n numbers; complex ones in conjugate pairs; each at most rank(C)
        times

    Returns
    -------
    L : ndarray (n, p)

    Raises
    ------
    UncontrollableError
        (C, A) is not observable; the message and ``eigenvalues`` name the modes that no
        gain L can move.
    ShapeError, NonFiniteError, InvalidArgumentError
        As :func:`~aerocontrol.place`, naming A, C or the poles.

    Warns
    -----
    IllConditionedWarning
        As :func:`~aerocontrol.place`, or when an eigenvalue of A - L C misses its pole by
        more than 1e-6 relatively.

    Examples
    --------
    An observer of the 747's lateral motion from p, r and φ:

    >>> import numpy as np, aerocontrol
    >>> A, _ = aerocontrol.chapter.boeing747_lateral()
    >>> C = np.eye(4)[[1, 3, 2]]
    >>> L = aerocontrol.place_observer(A, C, [-2.0 + 1.0j, -2.0 - 1.0j, -3.0, -4.0])
    >>> np.round(np.sort_complex(np.linalg.eigvals(A - L @ C)), 10)
    array([-4.+0.j, -3.+0.j, -2.-1.j, -2.+1.j])
    """
    if poles is None:
        if isinstance(A_or_sys, (tuple, list)) or is_system(A_or_sys):
            sys = as_state_space(A_or_sys, "A_or_sys")
            A_or_sys, C, poles = sys.A, sys.C, C
        else:
            raise InvalidArgumentError("place_observer needs A, C and the poles, or a system")
    if C is None or poles is None:
        raise InvalidArgumentError("place_observer needs A, C and the poles, or a system")
    A = _matrix(A_or_sys, "A")
    if A.shape[0] != A.shape[1]:
        raise _shape_error("A", f"A must be square, got {A.shape}")
    C = _matrix(C, "C")
    if C.shape[1] != A.shape[0]:
        raise _shape_error(
            "C", f"C must have as many columns as A ({A.shape[0]}), got {C.shape[1]}"
        )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            design = place(A.T, C.T, poles)
        except UncontrollableError as error:
            hidden = list(error.eigenvalues or [])
            listed = ", ".join(f"{complex(e):.6g}" for e in hidden)
            unobservable = UncontrollableError(
                f"(C, A) is not observable: no observer gain L can move the eigenvalue(s) "
                f"{listed} of A - L C (place for (A^T, C^T) reported: {error})"
            )
            unobservable.eigenvalues = hidden
            raise unobservable from error
        except InvalidArgumentError as error:
            if error.argument != "B":
                # A refusal of the poles names the dual placement's B ("B has rank 1"):
                # say which matrix of the caller's that is.
                dual = type(error)(
                    f"{error} (the observer's poles are placed as state feedback for "
                    "(A^T, C^T): its B is C^T)"
                )
                dual.__dict__.update(error.__dict__)
                raise dual from error
            refused = type(error)(
                f"C is refused: its transpose is the input matrix of the dual placement, "
                f"which reported: {error}"
            )
            refused.argument = "C"
            raise refused from error
    for warning in caught:
        warnings.warn(warning.message, warning.category, stacklevel=2)
    L = np.ascontiguousarray(design.K.T)
    miss = _pole_error(design.poles, A - L @ C)
    if miss > POLE_ERROR_WARNING and not caught:
        warnings.warn(
            f"the observer's poles, eig(A - L C), miss the requested ones by up to {miss:.2e} "
            "relatively; the gain may be inaccurate",
            IllConditionedWarning,
            stacklevel=2,
        )
    return L


# --- lqg -------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False, repr=False)
class LqgDesign(Result):
    """A continuous-time LQG compensator and its loop with the plant, from :func:`lqg`.

    The compensator is the Kalman filter driven by the regulator's own command,
    x̂' = A x̂ + B u + L (y - C x̂ - D u), u = -K x̂, that is the model from y to u

        (A - B K - L C + L D K,  L,  -K,  0).

    In the closed loop, with e = x - x̂, x' = (A - B K) x + B K e and e' = (A - L C) e: the
    poles are those of the regulator and of the filter (the separation principle).

    Attributes
    ----------
    K : ndarray (m, n)
        The regulator's gain (as :func:`~aerocontrol.lqr`).
    L : ndarray (n, p)
        The Kalman filter's gain (as :func:`~aerocontrol.lqe`).
    S : ndarray (n, n)
        The regulator's Riccati solution.
    P : ndarray (n, n)
        The filter's Riccati solution (the error covariance).
    compensator : StateSpace
        The compensator from the plant's outputs y to its inputs u, with states x̂.
    closed_loop : StateSpace
        The plant and compensator in feedback, state (x, x̂), input d added to the plant's input
        (u = -K x̂ + d), outputs (y, u).
    regulator_poles : ndarray (n,), complex
        eig(A - B K).
    estimator_poles : ndarray (n,), complex
        eig(A - L C).
    closed_loop_poles : ndarray (2n,), complex
        The regulator's poles, then the estimator's: the poles of the closed loop.

    Examples
    --------
    The unstable x' = x + u, y = x with unit weights and intensities: both Riccati equations
    read 1 + 2X - X² = 0, so K = L = 1 + √2 and every closed-loop pole is at -√2:

    >>> import numpy as np, aerocontrol
    >>> plant = aerocontrol.StateSpace([[1.0]], [[1.0]], [[1.0]])
    >>> design = aerocontrol.lqg(plant, [[1.0]], [[1.0]], [[1.0]], [[1.0]])
    >>> np.round(design.K, 6), np.round(design.L, 6)
    (array([[2.414214]]), array([[2.414214]]))
    >>> np.round(design.closed_loop_poles.real, 6)
    array([-1.414214, -1.414214])
    """

    K: FloatArray
    """The regulator's gain, m x n (as :func:`~aerocontrol.lqr`)."""
    L: FloatArray
    """The Kalman filter's gain, n x p (as :func:`lqe`)."""
    S: FloatArray
    """The regulator's Riccati solution, n x n."""
    P: FloatArray
    """The filter's Riccati solution (the error covariance), n x n."""
    compensator: StateSpace
    """The compensator from the plant's outputs y to its inputs u, with states x̂."""
    closed_loop: StateSpace
    """The plant and compensator in feedback, state (x, x̂), input d added to the plant's
    input (u = -K x̂ + d), outputs (y, u)."""
    regulator_poles: ComplexArray
    """eig(A - B K)."""
    estimator_poles: ComplexArray
    """eig(A - L C)."""
    closed_loop_poles: ComplexArray
    """The regulator's poles, then the estimator's: the poles of the closed loop."""

    def __repr__(self) -> str:
        return (
            f"LqgDesign(n_states={self.K.shape[1]}, n_inputs={self.K.shape[0]}, "
            f"n_outputs={self.L.shape[1]}, closed_loop_poles="
            f"{np.array2string(self.closed_loop_poles, precision=4)})"
        )


def lqg(
    sys: System,
    Q: ArrayLike,
    R: ArrayLike,
    QN: ArrayLike,
    RN: ArrayLike,
    *,
    N: ArrayLike | None = None,
    G: ArrayLike | None = None,
    NN: ArrayLike | None = None,
) -> LqgDesign:
    """The continuous-time linear-quadratic-Gaussian compensator of a plant.

    The regulator η = -K x minimises ∫ (x^T Q x + η^T R η + 2 x^T N η) dt
    (:func:`~aerocontrol.lqr`); the Kalman filter estimates x from y = C x + D η + v for
    x' = A x + B η + G w with E{w w^T} = QN, E{v v^T} = RN, E{w v^T} = NN (:func:`lqe`; G is
    B unless given). The compensator feeds the estimate back, η = -K x̂:

        x̂' = (A - B K - L C + L D K) x̂ + L y,    η = -K x̂.

    Before it is returned the closed loop with the plant is checked: every eigenvalue of its
    2n x 2n matrix [[A, -B K], [L C, A - B K - L C]] has Re < 0.

    Parameters
    ----------
    sys : system, or (A, B, C, D)
        The plant (continuous time); its C says what is measured.
    Q, R : array_like
        The regulator's weights (n x n, m x m).
    QN, RN : array_like
        The covariances of the process noise (g x g, g the columns of G) and of the
        measurement noise (p x p).
    N : array_like (n, m), optional
        The regulator's cross weight.
    G : array_like (n, g), optional
        How the process noise enters; B by default.
    NN : array_like (g, p), optional
        The noises' cross covariance.

    Returns
    -------
    LqgDesign
        The gains ``K`` and ``L``, the Riccati solutions ``S`` and ``P``, the ``compensator``
        (y to η, states x̂), the ``closed_loop`` with the plant (states (x, x̂)) and the
        regulator, estimator and closed-loop poles.

    Raises
    ------
    IllConditionedError, NoStabilizingSolutionError
        As :func:`~aerocontrol.lqr` for the regulator ((A, B) not stabilisable) and
        :func:`lqe` for the filter ((C, A) not detectable); NoStabilizingSolutionError also if
        the computed closed loop is not stable.
    ShapeError, NonFiniteError, NotPositiveDefiniteError
        A weight or covariance of the wrong size or not finite, R not symmetric, or RN not
        positive definite (named).
    InvalidArgumentError
        A discrete-time model (an aerocontrol or python-control model with dt > 0).

    Examples
    --------
    The 747's lateral regulator of (6.224) with sideslip not measured (y = p, r, φ):

    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()
    >>> plant = aerocontrol.StateSpace(A, B, np.eye(4)[[1, 3, 2]])
    >>> design = aerocontrol.lqg(plant, np.eye(4), np.eye(2), np.eye(2), 1e-2 * np.eye(3))
    >>> design.compensator.n_inputs, design.compensator.n_outputs     # y -> (δr, δa)
    (3, 2)
    >>> bool(np.all(design.closed_loop_poles.real < 0))
    True
    """
    if is_system(sys) and _system_time(sys)[0]:
        raise InvalidArgumentError(
            "lqg designs a continuous-time compensator, but sys is a discrete-time model "
            f"(dt = {getattr(sys, 'dt', None)})"
        )
    plant = as_state_space(sys)
    A, B, C, D = plant.A, plant.B, plant.C, plant.D
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    if N is not None:
        N = _matrix(N, "N", scalar_ok=True)
        if N.shape != (n, m):
            raise _shape_error("N", f"N must be {n} x {m} (as B), got {N.shape}")
    regulator = _reissuing_warnings(lambda: solve_care(A, B, Q, R, N), 3)  # lqg's caller
    model = _noise_model(A, B if G is None else G, C, QN, RN, NN)
    estimator = _solve_filter(model, False)
    K, L = regulator.K, estimator.L
    hats = [f"{name}_hat" for name in plant.state_names]
    compensator_A = _formed(
        "the compensator's A - B K - L C + L D K", "sys", lambda: A - B @ K - L @ C + L @ D @ K
    )
    compensator = StateSpace(
        compensator_A,
        L,
        -K,
        np.zeros((m, p)),
        state_names=hats,
        input_names=plant.output_names,
        output_names=plant.input_names,
    )
    loop_matrices = _formed(
        "the closed loop's matrices",
        "sys",
        lambda: (
            np.block([[A, -B @ K], [L @ C, A - B @ K - L @ C]]),
            np.vstack([B, L @ D]),
            np.block([[C, -D @ K], [np.zeros((m, n)), -K]]),
        ),
    )
    closed_loop = StateSpace(
        *loop_matrices,
        np.vstack([D, np.eye(m)]),
        state_names=[*plant.state_names, *hats],
        input_names=plant.input_names,
        output_names=[*plant.output_names, *plant.input_names],
    )
    computed = np.linalg.eigvals(closed_loop.A)
    if computed.size and not np.all(computed.real < 0):
        worst = computed[np.argmax(computed.real)]
        raise NoStabilizingSolutionError(
            f"the LQG closed loop is not stable as computed: its eigenvalue {worst:.6g} has "
            "Re >= 0, although the regulator's and the filter's poles are stable (the "
            "closed-loop matrix is too ill-conditioned to separate them)"
        )
    return LqgDesign(
        K=K,
        L=L,
        S=regulator.X,
        P=estimator.P,
        compensator=compensator,
        closed_loop=closed_loop,
        regulator_poles=regulator.closed_loop_poles,
        estimator_poles=estimator.poles,
        closed_loop_poles=np.concatenate([regulator.closed_loop_poles, estimator.poles]),
    )
