"""The matrix exponential, state transition matrices, exact discretisation, discrete models of
continuous ones and back (:func:`c2d`, :func:`d2c`), and the real Schur form with reordering.

Chapter §6.1.2: the transition matrix of x' = Ax + Bη is Φ(t) = e^{At} (6.22), and the
response to an input held over a step follows from Φ and two integrals of it (6.9).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _scaling
from ._results import Result
from ._validation import FloatArray, check_choice, real_array, real_scalar
from .exceptions import (
    IllConditionedWarning,
    InvalidArgumentError,
    NoContinuousEquivalentError,
    NumericalOverflowWarning,
    ShapeError,
)
from .statespace import StateSpace, as_state_space, period, sampling_period

if TYPE_CHECKING:
    from ._typing import System

__all__ = [
    "Discretization",
    "GeneralizedSchur",
    "c2d",
    "d2c",
    "discretize",
    "expm",
    "qz",
    "schur",
    "transition_matrix",
]

ComplexArray = NDArray[np.complex128]

#: :func:`d2c` with ``method="zoh"`` warns when a pole's angle exceeds this fraction of π: its
#: continuous frequency is above 90 % of the Nyquist frequency π/dt, near its alias.
NYQUIST_FRACTION_WARNING = 0.9
#: :func:`d2c` with a bilinear method warns when α Ad + (1 - α) I has a reciprocal condition
#: number (relative to its terms) below this: a pole near the image of s = ∞.
BILINEAR_RCOND_WARNING = 1e-8


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
    IllConditionedError
        e^A could not be computed in double precision although it does not overflow: the
        squarings that a norm beyond 2^53 needs amplified rounding until it overflowed (a
        rotation by 1e50 rad). NaN is never returned for such a matrix.

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
        Overflow and ill-conditioning are reported as by :func:`expm`.

    Raises
    ------
    IllConditionedError
        As :func:`expm`, for a time at which e^{At} could not be computed.

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


@dataclass(frozen=True, eq=False)
class Discretization(Result):
    """The matrices that advance x' = Ax + Bη exactly over one step of length ``dt``.

    Zero-order hold (η constant over the step)::

        x[k+1] = Phi x[k] + Gamma0 η[k]

    First-order hold (η linear between samples)::

        x[k+1] = Phi x[k] + (Gamma0 - Gamma1) η[k] + Gamma1 η[k+1]

    with Phi = e^{A dt}, Gamma0 = ∫_0^dt e^{Aτ} dτ B and
    Gamma1 = (1/dt) ∫_0^dt e^{Aτ} (dt - τ) dτ B.

    Attributes
    ----------
    Phi : ndarray (n, n)
        e^{A dt}, the transition matrix over one step.
    Gamma0 : ndarray (n, m)
        ∫_0^dt e^{Aτ} dτ B.
    Gamma1 : ndarray (n, m) or None
        (1/dt) ∫_0^dt e^{Aτ} (dt - τ) dτ B for ``method="foh"``; None for ``"zoh"``.
    dt : float
        The step (s).
    method : str
        The hold: ``"zoh"`` or ``"foh"``.

    Examples
    --------
    The double integrator over 0.1 s: Phi = [[1, dt], [0, 1]], Gamma0 = [dt^2/2, dt] and
    Gamma1 = [dt^2/6, dt/2]:

    >>> import numpy as np, aerocontrol
    >>> step = aerocontrol.discretize([[0, 1], [0, 0]], [[0], [1]], 0.1, "foh")
    >>> step.Phi
    array([[1. , 0.1],
           [0. , 1. ]])
    >>> np.round(step.Gamma0, 6)
    array([[0.005],
           [0.1  ]])
    >>> np.round(step.Gamma1, 6)
    array([[0.001667],
           [0.05    ]])
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
        :func:`c2d` turns them into a discrete :class:`~aerocontrol.StateSpace` (and has the
        bilinear and matched methods).

    Raises
    ------
    InvalidArgumentError
        ``dt`` is not positive and finite, or so large that A dt overflows; ``method`` is not
        "zoh" or "foh" (a method of :func:`c2d` is named as such).
    ShapeError
        A is not square, or B has not n rows.
    NonFiniteError, NotRealError
        A or B contains NaN or an infinity, or is complex.

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
    if isinstance(method, str) and method in C2D_METHODS and method not in ("zoh", "foh"):
        raise InvalidArgumentError(
            f"method must be one of 'zoh', 'foh', got {method!r}: discretize gives the "
            f"matrices of a hold, and method={method!r} changes C and D as well; use "
            "aerocontrol.c2d(sys, dt, method=...) for it"
        )
    hold: Literal["zoh", "foh"] = (
        "zoh" if check_choice(method, "method", ("zoh", "foh")) == "zoh" else "foh"
    )
    Phi, Gamma0, Gamma1 = _core.discretize(A, B, step, hold)
    return Discretization(Phi=Phi, Gamma0=Gamma0, Gamma1=Gamma1, dt=step, method=hold)


#: The methods of :func:`c2d`.
C2D_METHODS = ("zoh", "foh", "tustin", "bilinear", "gbt", "euler", "backward_diff", "matched")

#: The methods of :func:`d2c`.
D2C_METHODS = ("zoh", "tustin", "bilinear", "gbt", "euler", "backward_diff")

#: The weight α of each named generalized bilinear transformation.
_BILINEAR_WEIGHTS = {"tustin": 0.5, "bilinear": 0.5, "euler": 0.0, "backward_diff": 1.0}


def _bilinear_weight(method: str, alpha: float | None) -> float:
    """α of a bilinear method: fixed by its name, or given (between 0 and 1) for "gbt"."""
    if method == "gbt":
        if alpha is None:
            raise InvalidArgumentError("method='gbt' needs the weight alpha, between 0 and 1")
        weight = real_scalar(alpha, "alpha")
        if not 0.0 <= weight <= 1.0:
            raise InvalidArgumentError(f"alpha must be between 0 and 1, got {weight}")
        return weight
    if alpha is not None:
        raise InvalidArgumentError(
            f"alpha is the weight of method='gbt'; method={method!r} has its own "
            f"({_BILINEAR_WEIGHTS.get(method, 'none')})"
        )
    return _BILINEAR_WEIGHTS[method]


def _warped_step(method: str, weight: float, dt: float, prewarp: float | None) -> float:
    """The step of the bilinear transformation: dt, or 2 tan(ω dt / 2) / ω with frequency
    prewarping at ω, so that the discrete model's response at ω equals the continuous one's."""
    if prewarp is None:
        return dt
    if method not in ("tustin", "bilinear", "gbt") or weight != 0.5:
        raise InvalidArgumentError(
            f"prewarp applies to Tustin's transformation (method='tustin', or 'gbt' with "
            f"alpha=0.5), not to method={method!r}"
        )
    omega = real_scalar(prewarp, "prewarp")
    nyquist = np.pi / dt
    if not (np.isfinite(omega) and 0.0 < omega < nyquist):
        raise InvalidArgumentError(
            f"prewarp must be a frequency in rad/s between 0 and the Nyquist frequency "
            f"pi/dt = {nyquist:g}, got {omega}"
        )
    return float(2.0 * np.tan(omega * dt / 2.0) / omega)


def c2d(
    sys: System,
    dt: float,
    method: str = "zoh",
    prewarp: float | None = None,
    alpha: float | None = None,
) -> StateSpace:
    """The discrete model of a continuous one, sampled every ``dt`` seconds (MATLAB's ``c2d``,
    python-control's ``sample_system``).

    Methods (the realizations are scipy.signal.cont2discrete's, so the matrices agree with
    scipy and python-control, not only the transfer functions):

    ``"zoh"``
        Zero-order hold, exact for inputs constant over each step: Ad = e^{A dt},
        Bd = ∫_0^dt e^{Aτ} dτ B, C and D unchanged (:func:`discretize`, exact for singular A).
    ``"foh"``
        First-order (triangle) hold, exact for inputs linear between samples: with Φ, Γ0, Γ1
        of :func:`discretize`, Ad = Φ, Bd = Γ0 - Γ1 + Φ Γ1, Cd = C, Dd = D + C Γ1 (the state
        is x - Γ1 η, so that the model is causal).
    ``"tustin"`` (or ``"bilinear"``), ``"euler"``, ``"backward_diff"``, ``"gbt"``
        The generalized bilinear transformation s ← (z - 1) / (dt (α z + 1 - α)) with α = 1/2,
        0, 1, or ``alpha``: Ad = M^-1 (I + (1 - α) dt A), Bd = M^-1 dt B, Cd = C M^-1,
        Dd = D + α C Bd with M = I - α dt A (of the states balanced first by an exact
        diagonal similarity of powers of two where they are scaled far apart; the map
        commutes with it). ``prewarp`` (rad/s, below π/dt) replaces dt by 2 tan(ω dt/2)/ω in
        Tustin's map, so that the frequency responses agree at ω.
    ``"matched"``
        Matched pole-zero (single input, single output): each pole and finite zero s maps to
        e^{s dt}, and the gain matches the continuous one at low frequency (the DC gain when
        there is no pole or zero at s = 0), as python-control's ``sample_system``. The result
        is a controllable canonical realization, with new state names.

    Parameters
    ----------
    sys : system
        A continuous model (a discrete one is refused).
    dt : float
        Sampling period in seconds, positive and finite.
    method : str
        One of the above; default ``"zoh"``.
    prewarp : float, optional
        Frequency in rad/s at which Tustin's map is exact.
    alpha : float, optional
        The weight of ``method="gbt"``, between 0 and 1.

    Returns
    -------
    StateSpace
        The discrete model (``dt`` set), with the names of ``sys`` (except for
        ``"matched"``, whose states are new).

    Raises
    ------
    InvalidArgumentError
        ``sys`` is already discrete, ``dt`` is not positive, an unknown method, ``prewarp`` or
        ``alpha`` given to a method that has none, or a bilinear step that sends an eigenvalue
        of A to infinity (A has the eigenvalue 1 / (α dt)).
    ShapeError
        ``method="matched"`` on a model with more than one input or output.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> lag = aerocontrol.StateSpace([[-2.0]], [[2.0]], [[1.0]], [[0.0]])     # 2 / (s + 2)
    >>> d = aerocontrol.c2d(lag, 0.1)
    >>> round(float(d.A[0, 0]), 6), round(float(d.B[0, 0]), 6), d.dt
    (0.818731, 0.181269, 0.1)
    >>> t = aerocontrol.c2d(lag, 0.1, "tustin")
    >>> round(float(t.A[0, 0]), 6)                                    # (1 - 0.1) / (1 + 0.1)
    0.818182
    """
    model = as_state_space(sys)
    if model.is_discrete:
        raise InvalidArgumentError(
            f"sys must be a continuous model, got a discrete one (dt = {period(model):g}); "
            "use d2c to undo a discretisation"
        )
    step = sampling_period(dt)
    if step == 0.0:
        raise InvalidArgumentError("dt must be a positive sampling period in seconds, got 0")
    chosen = check_choice(method, "method", C2D_METHODS)
    if chosen in ("zoh", "foh", "matched") and (prewarp is not None or alpha is not None):
        raise InvalidArgumentError(
            f"prewarp and alpha apply to the bilinear methods, not to method={chosen!r}"
        )
    if chosen == "matched":
        return _matched(model, step)
    if chosen in ("zoh", "foh"):
        Phi, Gamma0, Gamma1 = _core.discretize(model.A, model.B, step, chosen)
        if Gamma1 is None:
            return _discrete_like(model, (Phi, Gamma0, model.C, model.D), step)
        with np.errstate(all="ignore"):  # an overflow is refused by name below
            matrices = (Phi, Gamma0 - Gamma1 + Phi @ Gamma1, model.C, model.D + model.C @ Gamma1)
        return _discrete_like(model, matrices, step)
    weight = _bilinear_weight(chosen, alpha)
    warped = _warped_step(chosen, weight, step, prewarp)
    Ad, Bd, Cd, Dd = _balanced_bilinear(_core.bilinear, model, warped, weight)
    return _discrete_like(model, (Ad, Bd, Cd, Dd), step)


def _balanced_bilinear(
    transform: Callable[..., tuple[FloatArray, FloatArray, FloatArray, FloatArray]],
    model: StateSpace,
    step: float,
    weight: float,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The core's (inverse) bilinear transformation of ``model``'s matrices, of the states
    balanced first where that changes them (:func:`~aerocontrol._scaling.state_balancing`):
    both maps commute with a similarity T (A, B, C, D to T^-1 A T, T^-1 B, C T, D, exact for
    T = diag(2^e)), and their solves with I - α dt A and α Ad + (1 - α) I have errors
    relative to the norm of A: unbalanced, states scaled by 1e±6 were refused as having an
    eigenvalue at 1 / (α dt)."""
    A, B, C, D = model.A, model.B, model.C, model.D
    exponents = _scaling.state_balancing(A, (B,), (C,))
    if exponents is None:
        return transform(A, B, C, D, step, weight)
    e = exponents
    Ab, Bb, Cb = _scaling.similarity(A, B, C, e)
    Ad, Bd, Cd, Dd = transform(Ab, Bb, Cb, D, step, weight)
    with np.errstate(over="ignore", under="ignore"):  # an overflow is refused by the caller
        return (
            np.ldexp(Ad, e[:, np.newaxis] - e[np.newaxis, :]),
            np.ldexp(Bd, e[:, np.newaxis]),
            np.ldexp(Cd, -e[np.newaxis, :]),
            Dd,
        )


def _discrete_like(model: StateSpace, matrices: tuple[FloatArray, ...], dt: float) -> StateSpace:
    """The sampled model of :func:`c2d`, with the names of ``model``."""
    _refuse_overflow(matrices, dt)
    A, B, C, D = matrices
    return _named_like(model, A, B, C, D, dt)


def _refuse_overflow(matrices: tuple[FloatArray, ...], dt: float) -> None:
    """Refuses a sampled model whose matrix overflowed double precision, naming dt (instead
    of a NonFiniteError from StateSpace blaming the model the caller gave)."""
    for name, matrix in zip("ABCD", matrices, strict=True):
        if not np.all(np.isfinite(matrix)):
            error = InvalidArgumentError(
                f"the sampled model's {name} overflows double precision: dt = {dt:g} is too "
                "long for this model (e^(A dt) or its integral leaves the range of doubles), "
                "or its entries are too large"
            )
            error.argument = "dt"
            raise error


def d2c(
    sys: System,
    method: str = "zoh",
    prewarp: float | None = None,
    alpha: float | None = None,
) -> StateSpace:
    """The continuous model whose discretisation by ``method`` is the discrete model ``sys``
    (MATLAB's ``d2c``): the inverse of :func:`c2d`, so ``d2c(c2d(sys, dt, m), m)`` is ``sys``
    to rounding.

    ``"zoh"``
        A dt and B dt are the blocks of the principal logarithm of [[Ad, Bd], [0, I]]
        (inverse scaling and squaring on the real Schur form, in the core), of the block
        matrix balanced first by an exact diagonal similarity of powers of two over the
        states and inputs (log(D^-1 M D) = D^-1 log(M) D), so that states scaled far apart
        keep their digits; C and D are unchanged. The logarithm is real only if Ad has no
        eigenvalue on the closed negative real axis: e^{A dt} never has one, so such a model
        (a pole at z <= 0, such as a one-step delay z = 0) has no continuous equivalent and
        is refused. Each pole
        z = r e^{jθ} (r > 0) becomes s = (ln r + jθ)/dt with -π < θ < π: the samples are equally
        those of s + 2πjk/dt for every integer k (aliasing), and the principal one is chosen.
        When abs(θ) > 0.9 π (``NYQUIST_FRACTION_WARNING``: a continuous frequency above 90 %
        of the Nyquist frequency π/dt) the choice is doubtful: the alias (2π - abs(θ))/dt is
        near, and the real logarithm of the pair z, z̄ is sensitive to A by the factor
        θ / sin θ, which grows without bound as θ → π. It is computed, with a warning.
    ``"tustin"`` (``"bilinear"``), ``"euler"``, ``"backward_diff"``, ``"gbt"``
        The inverse of the generalized bilinear transformation of :func:`c2d`, with the same
        ``prewarp`` and ``alpha``: A = (Ad - I)(α Ad + (1 - α) I)^-1 / dt (and B, C, D
        likewise). It needs Ad free of the eigenvalue -(1 - α)/α (-1 for Tustin's), the
        image of s = ∞: such a model is refused, and one whose α Ad + (1 - α) I has a
        reciprocal condition number below 1e-8 relative to its terms,
        σ_min / (α ||Ad|| + 1 - α) (an eigenvalue near -1 for Tustin's, a pole near s = ∞),
        is computed with a warning.

    First-order hold and matched pole-zero have no inverse here.

    Parameters
    ----------
    sys : StateSpace, or another discrete system
        A discrete model (``dt`` > 0; a continuous one is refused).
    method : str
        ``"zoh"`` (default), ``"tustin"``, ``"bilinear"``, ``"euler"``, ``"backward_diff"`` or
        ``"gbt"``: the method ``sys`` was discretised by.
    prewarp : float, optional
        Frequency in rad/s (below π/dt) at which Tustin's map was made exact; Tustin's only.
    alpha : float, optional
        The weight of ``method="gbt"``, between 0 and 1; "gbt" only.

    Returns
    -------
    StateSpace
        The continuous model (``dt`` = 0), with the names of ``sys``.

    Raises
    ------
    NoContinuousEquivalentError
        No real continuous model maps to ``sys``: an eigenvalue of its A at z = 0 or on the
        negative real axis (``"zoh"``), or at -(1 - α)/α (the bilinear methods). An
        :class:`~aerocontrol.exceptions.InvalidArgumentError` as well, with ``argument``
        ``"sys"`` and the eigenvalue in ``eigenvalues``; the message names both.
    InvalidArgumentError
        ``sys`` is continuous, an unknown method, or ``prewarp``/``alpha`` where they do not
        apply; or the continuous model overflows double precision (``argument`` ``"sys"``:
        a C of 1e308 under Tustin's inverse).

    Warns
    -----
    IllConditionedWarning
        ``"zoh"``: a pole's angle is within 0.1 π of ±π (near the Nyquist frequency, where
        the continuous frequency is ambiguous); the bilinear methods: α Ad + (1 - α) I is
        nearly singular. The message gives the pole and the measure.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> sys = aerocontrol.StateSpace(A, B)
    >>> back = aerocontrol.d2c(aerocontrol.c2d(sys, 0.05))
    >>> bool(np.allclose(back.A, A, rtol=1e-12, atol=1e-14)), back.dt
    (True, 0.0)

    A sampled mode that alternates in sign (z = -0.5) has no continuous model behind it:

    >>> try:
    ...     aerocontrol.d2c(aerocontrol.StateSpace([[-0.5]], [[1.0]], dt=0.1))
    ... except aerocontrol.InvalidArgumentError as error:
    ...     print(error.argument, error.eigenvalues)
    sys [(-0.5+0j)]
    """
    model = as_state_space(sys)
    if not model.is_discrete:
        raise InvalidArgumentError(
            "sys must be a discrete model (a StateSpace with dt > 0), got a continuous one"
        )
    if isinstance(method, str) and method in ("foh", "matched"):
        raise InvalidArgumentError(
            f"d2c has no inverse of method={method!r}; it undoes 'zoh' and the bilinear "
            "methods ('tustin', 'euler', 'backward_diff', 'gbt')"
        )
    chosen = check_choice(method, "method", D2C_METHODS)
    if chosen == "zoh":
        if prewarp is not None or alpha is not None:
            raise InvalidArgumentError(
                "prewarp and alpha apply to the bilinear methods, not to method='zoh'"
            )
        _check_zoh_logarithm(model.A, period(model))
        try:
            A, B = _undiscretized_zoh(model.A, model.B, period(model))
        except InvalidArgumentError as error:
            if error.argument != "A":
                raise
            raise _no_equivalent(f"sys.A: {error}", None) from None
        _refuse_continuous_overflow((A, B))
        return _named_like(model, A, B, model.C, model.D, 0.0)
    weight = _bilinear_weight(chosen, alpha)
    warped = _warped_step(chosen, weight, period(model), prewarp)
    try:
        with warnings.catch_warnings():  # a result beyond the doubles is refused below
            warnings.simplefilter("ignore", NumericalOverflowWarning)
            A, B, C, D = _balanced_bilinear(_core.inverse_bilinear, model, warped, weight)
    except InvalidArgumentError as error:
        if error.argument != "A":
            raise
        infinity = -(1.0 - weight) / weight if weight else None
        raise _no_equivalent(f"sys.A: {error}", infinity) from None
    _refuse_continuous_overflow((A, B, C, D))
    _check_bilinear_condition(model.A, weight, chosen)
    return _named_like(model, A, B, C, D, 0.0)


def _undiscretized_zoh(Ad: FloatArray, Bd: FloatArray, dt: float) -> tuple[FloatArray, FloatArray]:
    """A and B of the principal logarithm of M = [[Ad, Bd], [0, I]] (the core's
    ``undiscretize_zoh``), of M balanced first: with D = diag(2^e) over the states and the
    inputs (:func:`~aerocontrol._scaling.balancing_exponents`, the largest off-diagonal
    entries evened out), log(D^-1 M D) = D^-1 log(M) D, so A = D_x A' D_x^-1 and
    B = D_x B' D_u^-1 exactly. The logarithm's errors are relative to ||M||: unbalanced, a
    model whose states are scaled by 1e±3 came back with entries of A wrong at 1e-9, and
    one scaled by 1e±6 failed the logarithm's check. Where the scaling spans fewer than
    ``_scaling.BALANCING_SPREAD`` powers of two (a model scaled well enough, whose logarithm
    it would change only by rounding), or would push an entry out of the normal doubles, M
    as given."""
    n, m = Bd.shape if Bd.ndim == 2 else (0, 0)
    exponents = None
    if n > 1 and Ad.shape == (n, n) and np.all(np.isfinite(Ad)) and np.all(np.isfinite(Bd)):
        M = np.block([[Ad, Bd], [np.zeros((m, n)), np.eye(m)]])
        sizes = _scaling.log2_sizes(M)
        np.fill_diagonal(sizes, -np.inf)
        found, _ = _scaling.balancing_exponents(sizes, outside=False)
        shift = found[np.newaxis, :] - found[:, np.newaxis]
        scaled = (_scaling.log2_sizes(M) + shift)[M != 0.0]
        in_range = scaled.size == 0 or (scaled.min() > -1000 and scaled.max() < 1000)
        if np.ptp(found) >= _scaling.BALANCING_SPREAD and in_range:
            exponents = found.astype(np.int64)
    if exponents is None:
        A, B = _core.undiscretize_zoh(Ad, Bd, dt)
        return A, B
    states, inputs = exponents[:n], exponents[n:]
    A, B = _core.undiscretize_zoh(
        np.ldexp(Ad, states[np.newaxis, :] - states[:, np.newaxis]),
        np.ldexp(Bd, inputs[np.newaxis, :] - states[:, np.newaxis]),
        dt,
    )
    with np.errstate(over="ignore", under="ignore"):  # an overflow is refused by the caller
        return (
            np.ldexp(A, states[:, np.newaxis] - states[np.newaxis, :]),
            np.ldexp(B, states[:, np.newaxis] - inputs[np.newaxis, :]),
        )


def _refuse_continuous_overflow(matrices: tuple[ArrayLike, ...]) -> None:
    """Refuses, naming sys, a continuous model from d2c whose matrix overflowed double
    precision (a C of 1e308 with Tustin's inverse, C (I + Ad)^-1 times 2: inf), instead of a
    NonFiniteError from StateSpace blaming a C that the caller never gave."""
    for name, matrix in zip("ABCD"[: len(matrices)], matrices, strict=True):
        if not np.all(np.isfinite(np.asarray(matrix))):
            error = InvalidArgumentError(
                f"the continuous model's {name} overflows double precision: sys is beyond the "
                "range of doubles under this inverse map (its entries, or those of "
                "(I + (1 - alpha) Ad)^-1, are too large)"
            )
            error.argument = "sys"
            raise error


def _named_like(
    model: StateSpace,
    A: ArrayLike,
    B: ArrayLike,
    C: ArrayLike,
    D: ArrayLike,
    dt: float | None,
) -> StateSpace:
    """A model with the matrices given and the names of ``model``."""
    return StateSpace(
        A,
        B,
        C,
        D,
        state_names=model.state_names,
        input_names=model.input_names,
        output_names=model.output_names,
        dt=dt,
    )


def _no_equivalent(message: str, eigenvalue: complex | None) -> NoContinuousEquivalentError:
    """The refusal of a discrete model without a continuous equivalent, naming ``sys``."""
    error = NoContinuousEquivalentError(message)
    error.argument = "sys"
    error.eigenvalues = None if eigenvalue is None else [complex(eigenvalue)]
    return error


def _check_zoh_logarithm(A: FloatArray, dt: float) -> None:
    """Refuses an A with an eigenvalue on the closed negative real axis (or at 0 to working
    precision), which no e^{A_c dt} has; warns of a pole whose angle is near ±π (see
    :func:`d2c`)."""
    eigenvalues = _core.eigenvalues(A)
    if eigenvalues.size == 0:
        return
    zero = A.shape[0] * np.finfo(float).eps * float(np.abs(A).max())
    for value in eigenvalues:
        if abs(value) <= zero:
            raise _no_equivalent(
                f"sys.A has the eigenvalue 0 (computed as {complex(value):.3g}), a pole at z = 0 "
                "(a pure delay or a deadbeat mode): e^(A_c dt) is never singular, so no "
                "continuous model has these zero-order-hold samples",
                0.0,
            )
        if value.imag == 0.0 and value.real < 0.0:
            raise _no_equivalent(
                f"sys.A has the eigenvalue {value.real:.6g} on the negative real axis: "
                "e^(A_c dt) never has one (A has no real logarithm), so no real continuous "
                "model has these zero-order-hold samples",
                complex(value.real, 0.0),
            )
    angles = np.abs(np.angle(eigenvalues))
    worst = int(np.argmax(angles))
    theta = float(angles[worst])
    if theta > NYQUIST_FRACTION_WARNING * np.pi:
        nyquist = np.pi / dt
        warnings.warn(
            f"sys.A has the pole {complex(eigenvalues[worst]):.6g} at the angle "
            f"{theta / np.pi:.4f} pi, near the Nyquist frequency: its continuous frequency "
            f"{theta / dt:.6g} rad/s is {theta / np.pi:.1%} of pi/dt = {nyquist:.6g} rad/s, "
            f"and the samples are equally those of {(2 * np.pi - theta) / dt:.6g} rad/s "
            f"(aliasing); the real logarithm's sensitivity theta/sin(theta) is "
            f"{theta / np.sin(theta):.3g}",
            IllConditionedWarning,
            stacklevel=3,
        )


def _check_bilinear_condition(A: FloatArray, weight: float, method: str) -> None:
    """Warns when α A + (1 - α) I, inverted by the bilinear inverse, is nearly singular
    relative to its terms: σ_min(α A + (1 - α) I) / (α ||A||_2 + 1 - α) below
    :data:`BILINEAR_RCOND_WARNING`. (Relative to the terms, not to the sum's own norm: the sum
    of a scalar -1 + 1e-10 and 1 is well conditioned but has lost ten digits in the sum.)"""
    if A.shape[0] == 0 or weight == 0.0:
        return
    exponents = _scaling.state_balancing(A)
    if exponents is not None:  # the measure of the balanced A, as the inverse solves it
        A = np.ldexp(A, exponents[np.newaxis, :] - exponents[:, np.newaxis])
    denominator = weight * A + (1.0 - weight) * np.eye(A.shape[0])
    smallest = float(np.linalg.svd(denominator, compute_uv=False)[-1])
    largest = float(np.linalg.svd(A, compute_uv=False)[0])
    # The terms' size as α ||A|| + (1 - α): formed left to right, (α ||A|| + 1) - α lost a
    # ||A|| of 1.3e-151 beside 1 (backward_diff, α = 1) and divided by zero.
    terms = weight * largest + (1.0 - weight)
    rcond = smallest / terms if terms > 0.0 else 0.0
    if rcond < BILINEAR_RCOND_WARNING:
        eigenvalues = _core.eigenvalues(A)
        infinity = -(1.0 - weight) / weight
        nearest = complex(eigenvalues[int(np.argmin(np.abs(eigenvalues - infinity)))])
        warnings.warn(
            f"sys.A has the eigenvalue {nearest:.12g} near {infinity:g}, the image of "
            f"s = infinity under method={method!r}: alpha A + (1 - alpha) I has the reciprocal "
            f"condition number {rcond:.2e}, so the continuous model may carry few correct "
            "digits (its pole is near infinity)",
            IllConditionedWarning,
            stacklevel=3,
        )


def _matched(model: StateSpace, dt: float) -> StateSpace:
    """Matched pole-zero discretisation of a single-input, single-output model."""
    if (model.n_inputs, model.n_outputs) != (1, 1):
        raise ShapeError(
            "method='matched' needs a single-input, single-output model, got "
            f"{model.n_inputs} input(s) and {model.n_outputs} output(s); discretise each "
            "input-output pair, or use another method"
        )
    # G = K Π(s - z)/Π(s - p): the poles are the eigenvalues of A, the zeros those of the
    # system pencil and K as a mantissa and a power of two (the transfer function's own
    # computation). Formed from characteristic polynomials (det(sI - A + b c) - det(sI - A)),
    # they overflowed for A of 1e200 (coefficients of 1e400: a NaN companion matrix blamed
    # on A, and numpy's warnings), and the relative degree from the powers A^k b.
    from .transfer import _roots_and_gain

    _, zeros, k, e = _roots_and_gain(model)
    # The poles in the order of the core's Schur form (the sections pair them in it).
    poles = _core.eigenvalues(model.A) if model.n_states else np.zeros(0, dtype=np.complex128)
    if k == 0.0:  # G = 0
        return StateSpace(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[0.0]], dt=dt)
    _refuse_exponential_overflow(poles, zeros, dt)
    # Poles and zeros at s = 0 map to z = 1; the gain is matched on the rest (their low
    # frequency asymptotes agree, with z - 1 ≈ s dt).
    with np.errstate(over="ignore"):  # |root| beyond the doubles is inf, still "not zero"
        tiny = 1e-12 * max(1.0, float(np.abs(poles).max(initial=0.0)))
        nonzero_poles, nonzero_zeros = poles[np.abs(poles) > tiny], zeros[np.abs(zeros) > tiny]
    excess = (len(zeros) - len(nonzero_zeros)) - (len(poles) - len(nonzero_poles))
    # gain = K prod(-z) / prod(-p) * prod(1 - e^{p dt}) / prod(1 - e^{z dt}) / dt^excess, as
    # a mantissa times a power of two: each product may overflow (or underflow) where the
    # gain, or the model it scales, does not (e^{p dt} of 1e200, or K of 1e-400).
    dt_mantissa, dt_exponent = np.frexp(dt)
    gain_factors = [
        (complex(k), e),
        *(_scaled(complex(-z)) for z in nonzero_zeros),
        *(_reciprocal(_scaled(complex(-p))) for p in nonzero_poles),
        *(_one_minus_exp_scaled(complex(p * dt)) for p in nonzero_poles),
        *(_reciprocal(_one_minus_exp_scaled(complex(z * dt))) for z in nonzero_zeros),
        (complex(dt_mantissa) ** -excess, -int(dt_exponent) * excess),
    ]
    gain_mantissa, gain_exponent = _scaled_product(gain_factors)
    gain = float(gain_mantissa.real)
    # A cascade of first- and second-order sections, each a factor (z - e^{z_i dt}) ... over
    # (z - e^{p_i dt}) ...: the poles sit exactly in the sections' matrices, where the
    # coefficients of one polynomial of degree n would lose digits as the poles crowd towards
    # z = 1 (small dt).
    numerators = _real_factors(zeros, dt)
    # Each factor is given scaled to unit size, with the power of two it was divided by.
    quadratic = [f for f in numerators if len(f[0]) == 3]
    linear = [f for f in numerators if len(f[0]) == 2]
    Ad, Bd, Cd, Dd = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.ones((1, 1))
    for A_k, B_k, denominator, scale in _pole_sections(poles, dt):
        order = len(denominator) - 1
        factor, exponent = np.ones(1), 0
        if order == 2 and quadratic:
            factor, exponent = quadratic.pop()
        elif linear:
            factor, exponent = linear.pop()
        if order == 2 and len(factor) == 2 and linear:
            other, other_exponent = linear.pop()
            factor, exponent = np.convolve(factor, other), exponent + other_exponent
        # A zero far outside the unit circle (e^{z dt} of a right-half-plane zero) makes its
        # factor's coefficients huge: scaled to unit size, its size goes into the gain.
        size = float(np.abs(factor).max())
        factor = factor / size
        gain_mantissa, gain_exponent = _scaled_product(
            [(gain_mantissa, gain_exponent), (complex(size), exponent)]
        )
        gain = float(gain_mantissa.real)
        num = np.concatenate([np.zeros(order + 1 - len(factor)), factor])
        # The section in w = z / R (R = 4^k, a power of two near its poles' magnitude, 1
        # below 2^256): the numerator's and denominator's coefficients of w^(order - i)
        # divided by R^i keep unit size where those of z overflow (|z|^2 beyond 1e154). The
        # realisation (A_k, B_k, R C_w), C_w the output row of A_k / R, has the transfer
        # function wanted: (zI - A_k)^-1 = (wI - A_k/R)^-1 / R. Its states are then scaled by
        # a power of two that gives B_k and C_k the same size (R C_w alone may overflow).
        # The numerator in w is scaled by 2^lift to unit size too (a constant numerator
        # would underflow as R^-order), and C_w by 2^-lift after.
        powers = -scale * np.arange(order + 1)
        lift = _unit_lift(num, powers) if scale else 0
        with np.errstate(under="ignore"):
            num_w = np.ldexp(num, powers + lift)
            remainder = num_w[1:] - num_w[0] * denominator[1:]  # of the strictly proper part
            C_k = _output_row(np.ldexp(A_k, -scale), B_k, remainder)
            if scale:
                shift = _balancing_shift(B_k, C_k, scale - lift)
                B_k, C_k = np.ldexp(B_k, shift), np.ldexp(C_k, scale - lift - shift)
        D_k = num[:1].reshape(1, 1)
        # The section after the cascade so far: its input is the cascade's output.
        size_so_far = Ad.shape[0]
        Ad = np.block([[Ad, np.zeros((size_so_far, order))], [B_k @ Cd, A_k]])
        Bd = np.vstack([Bd, B_k @ Dd])
        Cd = np.hstack([D_k @ Cd, C_k])
        Dd = D_k @ Dd
    if quadratic or linear:  # pragma: no cover - a proper G has no more zeros than poles
        raise AssertionError("matched: zeros left over after the sections")
    with np.errstate(all="ignore"):  # an overflow is refused by name below
        Bd, Dd = gain * Bd, np.ldexp(gain * Dd, gain_exponent)
        shift = 0
        if not np.all(np.isfinite(np.ldexp(Bd, gain_exponent))):
            # The gain 2^e overflows B alone: the states scaled by 2^-shift, B by 2^(e - shift)
            # and C by 2^shift, each of the size of sqrt(|gain B| |C|).
            shift = gain_exponent - _balancing_shift(Bd, Cd, gain_exponent)
        matrices = (Ad, np.ldexp(Bd, gain_exponent - shift), np.ldexp(Cd, shift), Dd)
    _refuse_overflow(matrices, dt)
    return StateSpace(
        *matrices,
        input_names=model.input_names,
        output_names=model.output_names,
        dt=dt,
    )


def _pole_sections(
    poles: ComplexArray, dt: float
) -> list[tuple[FloatArray, FloatArray, FloatArray, int]]:
    """(A_k, B_k, denominator, scale) of each section with poles e^{p dt}: [[α, -β], [β, α]]
    and B = [0, 1] for a pair α ± jβ, [[p1, 0], [R, p2]] and B = [1, 0] for two real poles,
    [[p]] and B = [1] for the last real one; second-order sections first.

    ``scale`` is log2 R, R = 4^k the power of four nearest the largest magnitude of the
    section's poles where it exceeds 2^256 (else R = 1), and ``denominator`` the monic one
    in w = z / R: [1, -2α/R, (α/R)² + (β/R)²] for a pair, [1, -(p1 + p2)/R, p1 p2 / R²] for
    two real poles. Its coefficients then have the size of the poles over R, where those in
    z, |e^{p dt}|², overflow beyond 1e154 (the section's matrices hold only e^{p dt} itself,
    and the subdiagonal R keeps the output row of two real poles at their size)."""
    sections = []
    # A pair mapped to a real double pole (β = 0: e^{σ dt} below the doubles, or ω dt a
    # multiple of π) goes with the real poles: the pair's section α I with B = [0, 1] is not
    # controllable, and its output row divided by zero (NaN, numpy's warning, then a refusal
    # that blamed dt for A of 1e100 sampled at 1000 s, whose poles all map to z = 0).
    reals = [float(np.exp(r.real * dt)) for r in poles if r.imag == 0]
    with np.errstate(under="ignore"):
        for r in poles[poles.imag > 0]:
            z = np.exp(r.real * dt) * np.array([np.cos(r.imag * dt), np.sin(r.imag * dt)])
            alpha, beta = float(z[0]), float(z[1])
            if beta == 0.0:
                reals += [alpha, alpha]
                continue
            scale = _section_scale(np.hypot(alpha, beta))
            a, b = np.ldexp(alpha, -scale), np.ldexp(beta, -scale)
            sections.append(
                (
                    np.array([[alpha, -beta], [beta, alpha]]),
                    np.array([[0.0], [1.0]]),
                    np.array([1.0, -2.0 * a, a * a + b * b]),
                    scale,
                )
            )
        for first, second in zip(reals[0::2], reals[1::2], strict=False):
            # The larger pole first: the coupling R (of the larger's size) then feeds the
            # state of the larger pole from that of the smaller, and no output row has to
            # cancel terms of R's size (e^{-1} before e^{300} gave a DC gain of 2e27 for 2:
            # the output row's two terms of 7e43 cancelled).
            if abs(first) < abs(second):
                first, second = second, first
            scale = _section_scale(max(abs(first), abs(second)))
            f, g = np.ldexp(first, -scale), np.ldexp(second, -scale)
            sections.append(
                (
                    np.array([[first, 0.0], [np.ldexp(1.0, scale), second]]),
                    np.array([[1.0], [0.0]]),
                    np.array([1.0, -(f + g), f * g]),
                    scale,
                )
            )
        if len(reals) % 2:
            scale = _section_scale(abs(reals[-1]))
            sections.append(
                (
                    np.array([[reals[-1]]]),
                    np.ones((1, 1)),
                    np.array([1.0, -np.ldexp(reals[-1], -scale)]),
                    scale,
                )
            )
    return sections


def _unit_lift(coefficients: FloatArray, powers: NDArray[np.int_]) -> int:
    """The power of two that gives the coefficients c_i 2^(powers_i) a largest entry of
    size 1 (0 when they are all zero)."""
    nonzero = coefficients != 0.0
    if not np.any(nonzero):
        return 0
    exponents = np.frexp(np.abs(coefficients[nonzero]))[1] + powers[nonzero]
    return -int(np.max(exponents))


def _balancing_shift(B: FloatArray, C: FloatArray, exponent: int) -> int:
    """The power of two s for which B 2^s and C 2^(exponent - s) have the same largest
    entry, to the nearest power (0 where B or C is zero): the state scaling that splits a
    factor 2^exponent of C (or of B C) evenly, computed without forming it."""
    largest_B, largest_C = (
        float(np.max(np.abs(B), initial=0.0)),
        float(np.max(np.abs(C), initial=0.0)),
    )
    if not (largest_B > 0.0 and largest_C > 0.0) or not np.isfinite(largest_B + largest_C):
        return 0
    size_B, size_C = int(np.frexp(largest_B)[1]), int(np.frexp(largest_C)[1])
    return (size_C + exponent - size_B) // 2


#: Sections whose poles are larger than this are formed in w = z / R (see _pole_sections).
_SECTION_SCALING_THRESHOLD = 2.0**256


def _section_scale(magnitude: float) -> int:
    """log2 R for a section whose largest pole has ``magnitude``: R = 4^k nearest it beyond
    :data:`_SECTION_SCALING_THRESHOLD`, else 0 (R = 1: the section exactly as in z)."""
    if not magnitude > _SECTION_SCALING_THRESHOLD:
        return 0
    return 2 * round(float(np.log2(magnitude)) / 2)


def _output_row(A: FloatArray, B: FloatArray, remainder: FloatArray) -> FloatArray:
    """The row C with C (zI - A)^-1 B = (remainder as a polynomial in z) / det(zI - A), for a
    section of order 1 or 2: adj(zI - A) B = z B + (A - tr(A) I) B, so C B and
    C (A - tr(A) I) B are the coefficients (Cramer's rule on the 2 x 2 system)."""
    if A.shape[0] == 1:
        return np.asarray(remainder.reshape(1, 1) / B[0, 0], dtype=np.float64)
    V = (A - np.trace(A) * np.eye(2)) @ B
    b0, b1, v0, v1 = B[0, 0], B[1, 0], V[0, 0], V[1, 0]
    n1, n0 = remainder
    determinant = b0 * v1 - b1 * v0
    return np.array([[(n1 * v1 - b1 * n0) / determinant, (b0 * n0 - v0 * n1) / determinant]])


def _one_minus_exp(s: ComplexArray) -> ComplexArray:
    """1 - e^s without cancellation for small |s|: -(expm1(a) cos b - 2 sin²(b/2)) - j e^a sin b
    for s = a + jb."""
    a, b = s.real, s.imag
    real = np.expm1(a) * np.cos(b) - 2.0 * np.sin(b / 2.0) ** 2
    return np.asarray(-(real + 1j * np.exp(a) * np.sin(b)), dtype=np.complex128)


def _real_factors(roots: ComplexArray, dt: float) -> list[tuple[FloatArray, int]]:
    """The monic real factors of prod (z - e^{r dt}) over the roots r (conjugate pairs exact):
    z^2 - 2 e^{σ dt} cos(ω dt) z + e^{2σ dt} for each pair σ ± jω, real roots two to a
    quadratic, and at most one linear factor z - e^{r dt} left; each as (f, e), the factor
    equal to 2^e f, e even and f of the size of 1 or less: where e^{r dt} exceeds 2^256, f
    is the factor in w = z / S scaled by S^degree (S = 2^(e/degree)), whose coefficients do
    not overflow where e^{2σ dt} does (beyond 1e154)."""

    def factor(coefficients_in_w: list[float], scale: int) -> tuple[FloatArray, int]:
        degree = len(coefficients_in_w) - 1
        powers = scale * (degree - np.arange(degree + 1))  # S^(degree - i) z^i ... / S^degree
        with np.errstate(under="ignore"):
            return np.ldexp(np.array(coefficients_in_w), -powers), scale * degree

    factors = []
    with np.errstate(under="ignore"):
        for r in roots[roots.imag > 0]:
            magnitude = float(np.exp(r.real * dt))
            scale = _section_scale(magnitude)
            m = np.ldexp(magnitude, -scale)
            square = np.exp(2 * r.real * dt) if scale == 0 else m * m
            factors.append(factor([1.0, -2.0 * m * np.cos(r.imag * dt), square], scale))
        reals = [float(np.exp(r.real * dt)) for r in roots if r.imag == 0]
        for first, second in zip(reals[0::2], reals[1::2], strict=False):
            scale = _section_scale(max(abs(first), abs(second)))
            f, g = np.ldexp(first, -scale), np.ldexp(second, -scale)
            factors.append(factor([1.0, -(f + g), f * g], scale))
        if len(reals) % 2:
            scale = _section_scale(abs(reals[-1]))
            factors.append(factor([1.0, -np.ldexp(reals[-1], -scale)], scale))
    return factors


def _refuse_exponential_overflow(poles: ComplexArray, zeros: ComplexArray, dt: float) -> None:
    """Refuses, naming dt, a matched model whose pole or zero e^{r dt} overflows double
    precision (Re r dt beyond ln(2^1024) = 709.78): no section can hold it; or whose angle
    Im r dt does (a frequency of 1e300 over a step of 1e10)."""
    with np.errstate(over="ignore", invalid="ignore"):
        exponents = np.concatenate([poles.real, zeros.real, np.zeros(1)]) * dt
        angles = np.concatenate([poles.imag, zeros.imag, np.zeros(1)]) * dt
    largest = float(np.max(np.abs(exponents)))  # also Re r dt = +-inf or NaN
    if not np.all(np.isfinite(angles)):
        error = InvalidArgumentError(
            f"the sampled model's poles or zeros e^(r dt) cannot be formed: dt = {dt:g} is "
            "too long for this model (a frequency Im r times dt overflows double precision)"
        )
        error.argument = "dt"
        raise error
    if not np.all(exponents < np.log(np.finfo(np.float64).max)):
        error = InvalidArgumentError(
            f"the sampled model's poles or zeros e^(r dt) overflow double precision: "
            f"dt = {dt:g} is too long for this model (Re r dt reaches {largest:.6g}, beyond "
            f"{np.log(np.finfo(np.float64).max):.6g})"
        )
        error.argument = "dt"
        raise error


def _scaled(value: complex) -> tuple[complex, int]:
    """(m, e) with value = m 2^e and the larger part of m in [0.5, 1) (m = 0, e = 0 for
    zero). By the larger part, not |value|, which overflows (Python's abs raises
    OverflowError) for parts near 1e308."""
    size = max(abs(value.real), abs(value.imag))
    if size == 0.0 or not np.isfinite(size):
        return value, 0
    _, exponent = np.frexp(size)
    return complex(value.real * 2.0 ** -int(exponent), value.imag * 2.0 ** -int(exponent)), int(
        exponent
    )


def _reciprocal(scaled: tuple[complex, int]) -> tuple[complex, int]:
    mantissa, exponent = scaled
    with np.errstate(divide="ignore", invalid="ignore"):
        return 1.0 / mantissa if mantissa != 0 else complex(np.inf), -exponent


def _scaled_product(factors: list[tuple[complex, int]]) -> tuple[complex, int]:
    """The product of values m 2^e, as (m, e) with |m| in [0.5, 1): renormalised after each
    factor, so that no intermediate product over- or underflows."""
    mantissa, exponent = 1.0 + 0.0j, 0
    for m, e in factors:
        m_scaled, m_exponent = _scaled(complex(m))
        mantissa, shift = _scaled(mantissa * m_scaled)
        exponent += e + m_exponent + shift
    return mantissa, exponent


def _one_minus_exp_scaled(s: complex) -> tuple[complex, int]:
    """1 - e^s as (m, e), m 2^e (e^s itself fits: Re s < 709.78 was checked)."""
    return _scaled(complex(_one_minus_exp(np.array([s]))[0]))


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
        The eigenvalues to put first: Re < 0, Re > 0, abs(λ) < 1, abs(λ) > 1, or those for which
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
    ``scipy.linalg.ordqz``'s results: ``AA, BB, alpha, beta, Q, Z = qz(A, B)`` unpacks it.

    Attributes
    ----------
    AA : ndarray (n, n)
        Quasi-upper-triangular: 1 x 1 blocks and 2 x 2 blocks for complex pairs.
    BB : ndarray (n, n)
        Upper triangular with a nonnegative diagonal, diagonal under AA's 2 x 2 blocks.
    alpha : ndarray (n,), complex
        The eigenvalues are alpha / beta, in the order of the diagonal.
    beta : ndarray (n,)
        Nonnegative; 0 for an infinite eigenvalue (B singular).
    Q, Z : ndarray (n, n)
        Orthogonal; with ``select``, the leading ``selected`` columns of Z span the right
        deflating subspace of the selected eigenvalues.
    selected : int
        The number of leading eigenvalues chosen by ``select`` (n without it).

    Examples
    --------
    The pencil (diag(1, -2), diag(2, 1)) has the eigenvalues 1/2 and -2; "lhp" moves -2 first:

    >>> import numpy as np, aerocontrol
    >>> form = aerocontrol.qz(np.diag([1.0, -2.0]), np.diag([2.0, 1.0]), "lhp")
    >>> form.alpha / form.beta, form.selected
    (array([-2. +0.j,  0.5+0.j]), 1)
    """

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
        The eigenvalues to put first: Re λ < 0, Re λ > 0, abs(λ) < 1, abs(λ) > 1 (λ = α/β; an
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
