"""The chapter's design studies on an aircraft model: the Dutch-roll damper by pole placement
(§6.5.1, (6.156)-(6.165)) and the lateral regulator over the control weight c (§6.6,
(6.224)-(6.227), Figure 6.12); and the regulator designed for a flight computer that samples
the state and holds its command (:func:`sampled_weights`, :func:`sampled_data_lqr`).

The regulator minimises J = ∫ x^T Q x + (1/c²) η^T R η dt: R/c² is the control weight, so a
small c makes control expensive (the closed loop stays near the open loop) and a large c cheap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _scaling
from ._results import Result, register_model
from ._validation import real_array, real_scalar
from .aircraft.model import Aircraft
from .aircraft.naming import classify_modes
from .batch import lqr_sweep
from .exceptions import AerocontrolLinAlgError, InvalidArgumentError
from .handling import MarginsCheck, margins_check
from .interconnect import actuator, feedback, gain, series, washout
from .linalg import c2d, expm
from .loops import DampingDesign, StabilityMargins, best_damping_gain, stability_margins
from .modal import modes
from .placement import Placement, augment_mode, place_bass_gura
from .riccati import dlqr, lqr
from .statespace import StateSpace, require_continuous, sampling_period

__all__ = [
    "DAMPER_ACTUATOR_BANDWIDTH",
    "DAMPER_WASHOUT",
    "Damper",
    "SampledWeights",
    "critical_weight",
    "dutch_roll_damper",
    "lqr_root_locus",
    "pitch_damper",
    "sampled_data_lqr",
    "sampled_weights",
    "yaw_damper",
]

# The designs hold their models (JSON form and equality of the results).
register_model(StateSpace)

ComplexArray = NDArray[np.complex128]


def _lateral(plane_or_sys: Aircraft | StateSpace) -> StateSpace:
    if isinstance(plane_or_sys, Aircraft):
        return plane_or_sys.lateral()
    if isinstance(plane_or_sys, StateSpace):
        return plane_or_sys
    raise InvalidArgumentError(
        f"expected an Aircraft or a lateral StateSpace, got {type(plane_or_sys).__name__}"
    )


def dutch_roll_damper(
    plane_or_sys: Aircraft | StateSpace, zeta: float = 0.30, surface: str = "rudder"
) -> Placement:
    """State feedback through one surface that raises the Dutch roll's damping ratio to
    ``zeta`` at the same natural frequency and keeps the roll and spiral roots (6.156), by
    Bass-Gura (6.145).

    Parameters
    ----------
    plane_or_sys : Aircraft or StateSpace
        The aircraft (its lateral model is used) or a lateral model x = (β, p, φ, r) with
        named inputs.
    zeta : float, optional
        The Dutch roll's new damping ratio, non-negative (default 0.30, the chapter's).
    surface : str, optional
        The input fed back, "rudder" (default) or "aileron".

    Returns
    -------
    Placement
        The single-input design: ``k`` (6.159), ``K`` (1 x 4), the closed loop and the
        achieved poles (:func:`~aerocontrol.place_bass_gura`).

    Raises
    ------
    InvalidArgumentError
        ``plane_or_sys`` is neither an Aircraft nor a StateSpace, ``surface`` is not one of
        its inputs, or ``zeta`` is negative or not finite.
    UncontrollableError
        The surface cannot move a lateral mode.

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol import aircraft, design
    >>> damper = design.dutch_roll_damper(aircraft.load(), zeta=0.30, surface="rudder")
    >>> np.round(damper.k, 4)                                  # (6.159), as printed
    array([ 0.1383,  0.0943,  0.125 , -1.1333])
    """
    sys = _lateral(plane_or_sys)
    if surface not in sys.input_names:
        raise InvalidArgumentError(
            f"surface must be one of the model's inputs {sys.input_names}, got {surface!r}"
        )
    named = classify_modes(modes(sys.A), "lateral")
    dutch_roll = named["dutch roll"][0]
    poles = augment_mode(sys.A, dutch_roll, zeta=real_scalar(zeta, "zeta"))
    return place_bass_gura(sys.A, sys.B[:, sys.input_names.index(surface)], poles)


def _weights(
    n: int, m: int, Q: ArrayLike | None, R: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    Q_matrix = np.eye(n) if Q is None else real_array(Q, "Q")
    R_matrix = np.eye(m) if R is None else real_array(R, "R")
    return Q_matrix, R_matrix


def lqr_root_locus(
    sys: StateSpace, weights: ArrayLike, Q: ArrayLike | None = None, R: ArrayLike | None = None
) -> ComplexArray:
    """The closed-loop eigenvalues of the regulator for each control weight c (Figure 6.12):
    an array (len(weights), n), each row as :func:`aerocontrol.lqr` returns its E.

    Q and R default to identities (the chapter's (6.225)-(6.226)). The weights are solved in
    one parallel call (:func:`aerocontrol.batch.lqr_sweep`).

    Parameters
    ----------
    sys : StateSpace
        The continuous plant.
    weights : array_like (k,)
        The control weights c (R/c² is the control weight), positive and finite.
    Q : array_like (n, n), optional
        The state weight (default the identity).
    R : array_like (m, m), optional
        The control weight before division by c² (default the identity).

    Returns
    -------
    ndarray (k, n) of complex128
        The closed-loop eigenvalues for each c.

    Raises
    ------
    InvalidArgumentError
        A weight is not positive and finite, or ``sys`` is discrete.
    ShapeError
        ``weights`` is not 1-D, or Q or R disagrees in size with the plant.
    AerocontrolError
        The first failing weight's own error (NoStabilizingSolutionError, ...), as
        :func:`aerocontrol.batch.lqr_sweep`.

    Examples
    --------
    At c = 1 the 747's lateral regulator (6.224)-(6.227), as :func:`aerocontrol.lqr` gives it:

    >>> import numpy as np
    >>> from aerocontrol import aircraft, design
    >>> np.round(design.lqr_root_locus(aircraft.load().lateral(), [1.0])[0], 4)
    array([-0.3141+0.8153j, -0.3141-0.8153j, -0.4236+0.j    , -1.2443+0.j    ])
    """
    return lqr_sweep(sys, Q=Q, R=R, weights=weights).poles


def _split(poles: ComplexArray, mode: str) -> float:
    """((λ1 - λ2) / 2)² of the mode's two roots: -ω_d² while complex, >= 0 once split."""
    members = classify_modes(poles, "lateral").get(mode)
    if members is None or len(members) != 2:
        raise InvalidArgumentError(
            f"mode must name an oscillatory lateral mode ('dutch roll'), got {mode!r}"
        )
    return float((((members[0] - members[1]) / 2) ** 2).real)


def critical_weight(
    sys: StateSpace,
    mode: str = "dutch roll",
    Q: ArrayLike | None = None,
    R: ArrayLike | None = None,
    bounds: tuple[float, float] = (1e-3, 1e3),
) -> float:
    """The control weight c at which a lateral ``mode`` of the regulated aircraft becomes
    critically damped (its two roots meet on the real axis), to a relative 1e-12.

    The measure g(c) = ((λ1 - λ2) / 2)², negative while the pair is complex (-ω_d²) and positive
    once it has split, is bracketed on a logarithmic grid of c within ``bounds`` and its first
    sign change refined by bisection in log c.

    Parameters
    ----------
    sys : StateSpace
        The continuous lateral model.
    mode : str, optional
        The oscillatory lateral mode, "dutch roll" (default).
    Q : array_like (n, n), optional
        The state weight (default the identity, (6.225)).
    R : array_like (m, m), optional
        The control weight before division by c² (default the identity, (6.226)).
    bounds : (float, float), optional
        The range of c searched, 0 < low < high (default (1e-3, 1e3)).

    Returns
    -------
    float
        The weight c, to a relative 1e-12.

    Raises
    ------
    InvalidArgumentError
        ``bounds`` not 0 < low < high finite, or so wide that R / c^2 leaves the doubles;
        ``mode`` not an oscillatory lateral mode; or the mode does not become critically
        damped within ``bounds``.
    ShapeError
        Q or R is not of the plant's size.
    AerocontrolError
        A regulator of the grid fails (NoStabilizingSolutionError, ...).

    Examples
    --------
    The chapter gives this c twice, as 9.7227 < c < 9.7228 in the caption of Figure 6.12 and
    through the figure's symbols at 9.7727 and 9.7728; the model built from the coefficients
    settles it:

    >>> from aerocontrol import aircraft, design
    >>> round(design.critical_weight(aircraft.load().lateral()), 4)
    9.7727
    """
    Q_matrix, R_matrix = _weights(sys.n_states, sys.n_inputs, Q, R)
    low, high = (real_scalar(b, "bounds") for b in bounds)
    if not 0 < low < high or not math.isfinite(high):
        raise InvalidArgumentError(f"bounds must satisfy 0 < low < high, got {bounds}")

    def measure(c: float) -> float:
        return _split(lqr(sys.A, sys.B, Q_matrix, R_matrix / c**2)[2], mode)

    grid = np.geomspace(low, high, 61)
    try:
        sweep = lqr_sweep(sys, Q=Q, R=R, weights=grid)
    except InvalidArgumentError as error:
        if getattr(error, "argument", None) != "weights":
            raise
        refused = InvalidArgumentError(
            f"bounds ({low:g}, {high:g}) reach weights c for which R / c^2 leaves the range "
            "of double precision (narrow the bounds, or scale R)"
        )
        refused.argument = "bounds"
        raise refused from error
    values = [_split(poles, mode) for poles in sweep.poles]
    for k in range(len(grid) - 1):
        if values[k] < 0 <= values[k + 1]:
            a, b = math.log(grid[k]), math.log(grid[k + 1])
            while b - a > 1e-13:
                middle = 0.5 * (a + b)
                if measure(math.exp(middle)) < 0:
                    a = middle
                else:
                    b = middle
            return math.exp(0.5 * (a + b))
    raise InvalidArgumentError(
        f"the {mode} does not become critically damped for c in [{low:g}, {high:g}]"
    )


class SampledWeights(NamedTuple):
    """The weights of the discrete regulator whose cost is the continuous one, from
    :func:`sampled_weights`.

    Attributes
    ----------
    Q : ndarray (n, n)
        The weight of x_k.
    R : ndarray (m, m)
        The weight of the held command η_k.
    N : ndarray (n, m)
        The cross weight of x_k and η_k.

    Examples
    --------
    The double integrator's rate weighted over a hold of T = 0.5 s: Q = diag(0, T),
    N = [0, T²/2], R = T + T³/3:

    >>> import numpy as np, aerocontrol
    >>> from aerocontrol import design
    >>> sys = aerocontrol.StateSpace([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]])
    >>> Q, R, N = design.sampled_weights(sys, 0.5, Q=np.diag([0.0, 1.0]), R=[[1.0]])
    >>> np.round(np.diag(Q), 12), np.round(N.ravel(), 12), np.round(R, 12)
    (array([0. , 0.5]), array([0.   , 0.125]), array([[0.54166667]]))
    """

    Q: NDArray[np.float64]
    """n x n, the weight of x_k."""
    R: NDArray[np.float64]
    """m x m, the weight of the held command η_k."""
    N: NDArray[np.float64]
    """n x m, the cross weight of x_k and η_k."""


def sampled_weights(
    sys: StateSpace, dt: float, Q: ArrayLike | None = None, R: ArrayLike | None = None
) -> SampledWeights:
    """The weights (Q_d, R_d, N_d) of the discrete cost that equals the continuous cost
    J = ∫ x^T Q x + η^T R η dt of the plant driven by commands held over each period ``dt``
    (zero-order hold), as MATLAB's ``lqrd`` forms them.

    Between samples, [x(t_k + τ); η_k] = e^{F τ} [x_k; η_k] with F = [[A, B], [0, 0]], so the
    cost over one period is [x_k; η_k]^T W [x_k; η_k] with

        W = ∫_0^dt e^{F^T τ} diag(Q, R) e^{F τ} dτ = [[Q_d, N_d], [N_d^T, R_d]],

    computed by Van Loan's method (1978) from one exponential of order 2 (n + m):
    e^{[[-F^T, H], [0, F]] h} = [[., G12], [0, G22]] gives W(h) = G22^T G12, H = diag(Q, R),
    over a step h = dt / 2^k short enough that ||F|| h <= 1 (over a long step the block
    e^{-F^T h} of a fast stable mode overflows), then doubled k times,
    W(2h) = W(h) + e^{F^T h} W(h) e^{F h}: sums of positive semidefinite terms, without
    cancellation.
    ``dlqr(c2d(sys, dt), Q_d, R_d, N=N_d)`` then minimises the continuous cost exactly over
    held commands (:func:`sampled_data_lqr`), and tends to the continuous design as dt -> 0.

    Parameters
    ----------
    sys : StateSpace
        The continuous plant.
    dt : float
        The sampling period in seconds.
    Q, R : array_like, optional
        The continuous weights, identities by default (the chapter's (6.225)-(6.226)).

    Returns
    -------
    SampledWeights
        (Q, R, N), W symmetrised.

    Raises
    ------
    InvalidArgumentError
        ``sys`` is discrete, ``dt`` is not a positive finite period, Q or R is not of the
        plant's size, or the weights overflow double precision.

    Examples
    --------
    A double integrator with the velocity weighted, v(t_k + τ) = v_k + η_k τ: the cost of one
    period, ∫ (v_k + η_k τ)² + η_k² dτ, gives Q_d = diag(0, dt), N_d = (0, dt²/2) and
    R_d = dt + dt³/3 in closed form:

    >>> import numpy as np, aerocontrol
    >>> from aerocontrol import design
    >>> sys = aerocontrol.StateSpace([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]])
    >>> w = design.sampled_weights(sys, 0.5, Q=np.diag([0.0, 1.0]), R=[[1.0]])
    >>> np.round(w.Q, 12), np.round(w.N.ravel(), 12), np.round(w.R, 12)
    (array([[0. , 0. ],
           [0. , 0.5]]), array([0.   , 0.125]), array([[0.54166667]]))
    """
    require_continuous(sys, "sampled_weights", "its weights are those of a continuous cost")
    period = sampling_period(dt)
    if period == 0.0:
        raise InvalidArgumentError(f"dt must be a positive sampling period, got {dt}")
    n, m = sys.n_states, sys.n_inputs
    Q_matrix, R_matrix = _weights(n, m, Q, R)
    if Q_matrix.shape != (n, n) or R_matrix.shape != (m, m):
        raise InvalidArgumentError(
            f"Q must be {n} x {n} and R {m} x {m}, got {Q_matrix.shape} and {R_matrix.shape}"
        )
    size = n + m
    # The states balanced first, x = T x̃ with T = diag(2^e) (exact): W̃ = [[T Q_d T, T N_d],
    # [N_d^T T, R_d]] is that of T^-1 A T, T^-1 B and T Q T. The Van Loan exponential's
    # errors are relative to ||F||, so that states scaled by 1e±6 otherwise lose Q_d's small
    # entries (3e-7 relative to sqrt(Q_ii Q_jj), 4e-3 at 1e±8).
    e = _weight_balancing(sys.A, sys.B, Q_matrix)
    A_matrix, B_matrix = sys.A, sys.B
    if e is not None:
        A_matrix = np.ldexp(A_matrix, e[np.newaxis, :] - e[:, np.newaxis])
        B_matrix = np.ldexp(B_matrix, -e[:, np.newaxis])
        Q_matrix = np.ldexp(Q_matrix, e[:, np.newaxis] + e[np.newaxis, :])
    F = np.zeros((size, size))
    F[:n, :n], F[:n, n:] = A_matrix, B_matrix
    H = np.zeros((size, size))
    H[:n, :n], H[n:, n:] = Q_matrix, R_matrix
    norm = float(np.abs(F).sum(axis=0).max()) * period
    doublings = max(0, math.ceil(math.log2(norm))) if norm > 1.0 else 0
    step = period / 2.0**doublings
    block = np.block([[-F.T, H], [np.zeros((size, size)), F]])
    exponential = expm(block * step)
    transition = exponential[size:, size:]
    W = transition.T @ exponential[:size, size:]
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused below
        for _ in range(doublings):
            W = W + transition.T @ W @ transition
            transition = transition @ transition
    W = 0.5 * (W + W.T)
    Q_d, R_d, N_d = W[:n, :n], W[n:, n:], W[:n, n:]
    if e is not None:
        with np.errstate(over="ignore", under="ignore"):
            Q_d = np.ldexp(Q_d, -(e[:, np.newaxis] + e[np.newaxis, :]))
            N_d = np.ldexp(N_d, -e[:, np.newaxis])
    if not (np.all(np.isfinite(Q_d)) and np.all(np.isfinite(R_d)) and np.all(np.isfinite(N_d))):
        raise InvalidArgumentError(
            "the sampled weights overflow double precision (the continuous cost over one "
            f"period dt = {period:g} s leaves the range of doubles): sys, Q or R is too "
            "large for this dt"
        )
    return SampledWeights(
        np.ascontiguousarray(Q_d), np.ascontiguousarray(R_d), np.ascontiguousarray(N_d)
    )


def _weight_balancing(
    A: NDArray[np.float64], B: NDArray[np.float64], Q: NDArray[np.float64]
) -> NDArray[np.int64] | None:
    """Exponents e of the state scaling T = diag(2^e) that balances A
    (:func:`~aerocontrol._scaling.state_balancing`), or None where A is balanced well enough
    or a scaled entry of A, B (T^-1 B) or Q (T Q T) would leave the normal doubles."""
    e = _scaling.state_balancing(A, inputs=(B,))
    if e is None or not np.all(np.isfinite(Q)):
        return None
    sizes = _scaling.log2_sizes(Q) + e[:, np.newaxis] + e[np.newaxis, :]
    finite = sizes[np.isfinite(sizes)]
    if finite.size and (finite.min() < -1020.0 or finite.max() > 1020.0):
        return None
    return e


def sampled_data_lqr(
    sys: StateSpace, dt: float, Q: ArrayLike | None = None, R: ArrayLike | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64], ComplexArray]:
    """The regulator of a flight computer sampling every ``dt`` seconds that minimises the
    continuous cost J = ∫ x^T Q x + η^T R η dt over commands η_k = -K x_k held between samples
    (MATLAB's ``lqrd``): :func:`~aerocontrol.dlqr` of the zero-order-hold plant
    (:func:`~aerocontrol.c2d`) with the weights of :func:`sampled_weights`.

    Parameters
    ----------
    sys : StateSpace
        The continuous plant.
    dt : float
        The sampling period in seconds, positive.
    Q : array_like (n, n), optional
        The continuous state weight (default the identity, (6.225)).
    R : array_like (m, m), optional
        The continuous control weight (default the identity, (6.226)).

    Returns
    -------
    K : ndarray (m, n)
        The gain of η_k = -K x_k.
    S : ndarray (n, n)
        The discrete Riccati solution: x_0^T S x_0 is the continuous cost J of the sampled-data
        loop from x_0 (between the samples included).
    E : ndarray (n,) of complex128
        The closed-loop eigenvalues z, inside the unit circle; ln(z)/dt are the continuous
        roots they sample.

    Raises
    ------
    InvalidArgumentError
        As :func:`sampled_weights`: ``sys`` discrete, ``dt`` not positive and finite, Q or R
        of the wrong size, or weights that overflow double precision.
    NoStabilizingSolutionError, SingularMatrixError
        As :func:`~aerocontrol.dlqr`: the sampled plant is not stabilisable.

    Examples
    --------
    The lateral regulator of (6.224) (c = 1) at 50 Hz is the continuous one to 0.7 %:

    >>> import numpy as np, aerocontrol
    >>> from aerocontrol import design
    >>> lateral = aerocontrol.aircraft.load().lateral()
    >>> K, S, E = design.sampled_data_lqr(lateral, 0.02)
    >>> Kc, Sc, _ = aerocontrol.lqr(lateral.A, lateral.B, np.eye(4), np.eye(2))
    >>> round(float(np.linalg.norm(K - Kc) / np.linalg.norm(Kc)), 4)
    0.0064
    >>> bool(np.all(abs(E) < 1))
    True
    """
    weights = sampled_weights(sys, dt, Q, R)
    plant = c2d(sys, dt)
    return dlqr(plant.A, plant.B, weights.Q, weights.R, N=weights.N)


# ----- classical dampers: output feedback through an actuator and a washout --------------------

#: The bandwidth of the first-order surface actuators of the dampers (rad/s).
DAMPER_ACTUATOR_BANDWIDTH = 10.0
#: The yaw damper's washout time constant (s).
DAMPER_WASHOUT = 3.0


@dataclass(frozen=True, eq=False)
class Damper(Result):
    """A rate damper designed on the root locus: the loop, the gain, its margins against
    MIL-F-9490D and the closed loop.

    The feedback is surface command = sign·k·filter(rate) + pilot command, with the loop
    L = -sign·filter·(rate/surface)·actuator broken at the surface command (negative feedback
    1 + k L = 0).

    Attributes
    ----------
    name : str
        The damper: "yaw damper" or "pitch damper".
    loop : StateSpace
        L for k = 1 (actuator, plant channel, sign, washout).
    design : DampingDesign
        The gain k and the damping it gives the mode.
    margins : StabilityMargins
        The margins of k·L.
    check : MarginsCheck
        The margins against MIL-F-9490D 3.1.3.6 (:func:`~aerocontrol.handling.margins_check`).
    open_loop : StateSpace
        Actuator and aircraft, from the surface command to every state.
    closed_loop : StateSpace
        The same with the damper engaged.
    washout : float or None
        The washout's time constant (s), None without one.

    Examples
    --------
    >>> from aerocontrol import aircraft, design
    >>> damper = design.yaw_damper(aircraft.load("b747-cruise"))
    >>> damper.name, damper.washout, round(damper.design.gain, 2)
    ('yaw damper', 3.0, 1.49)
    >>> round(damper.margins.gain_margin_db, 2), damper.check.passed
    (12.61, {'yaw damper': True})
    """

    name: str
    loop: StateSpace
    """L for k = 1 (actuator, plant channel, sign, washout)."""
    design: DampingDesign
    """The gain k and the damping it gives the mode."""
    margins: StabilityMargins
    """The margins of k·L."""
    check: MarginsCheck
    open_loop: StateSpace
    """Actuator and aircraft, from the surface command to every state."""
    closed_loop: StateSpace
    """The same with the damper engaged."""
    washout: float | None
    """The washout's time constant (s), None without one."""


def _damper(
    name: str,
    sys: StateSpace,
    rate: str,
    surface: str,
    mode: complex | None,
    washout_tau: float | None,
    bandwidth: float,
) -> Damper:
    servo = actuator(bandwidth, input_names=f"{surface} command", output_names=surface)
    open_loop = series(servo, sys[:, surface])
    channel = series(servo, sys[rate, surface])
    filters = [] if washout_tau is None else [washout(washout_tau)]
    best: tuple[DampingDesign, float] | None = None
    for sign in (1.0, -1.0):  # the sign that damps the mode
        loop = series(channel, gain(-sign), *filters)
        design = best_damping_gain(loop, mode=mode)
        if best is None or design.damping_ratio > best[0].damping_ratio:
            best = (design, sign)
    assert best is not None
    design, sign = best
    loop = series(channel, gain(-sign), *filters)
    loop = StateSpace(
        loop.A,
        loop.B,
        loop.C,
        loop.D,
        state_names=loop.state_names,
        input_names=[f"{surface} command"],
        output_names=[f"{rate} fed back"],
    )
    margins = stability_margins(series(loop, gain(design.gain)))
    if not margins.closed_loop_stable:
        raise AerocontrolLinAlgError(
            f"{name}: the loop closed with the best gain {design.gain:.4g} is unstable"
        )
    check = margins_check({name: margins})
    selector = gain(
        [[1.0 if out == rate else 0.0 for out in open_loop.output_names]],
        output_names=rate,
    )
    feedback_path = series(selector, *filters, gain(sign * design.gain))
    closed = feedback(open_loop, feedback_path, sign=+1)
    return Damper(name, loop, design, margins, check, open_loop, closed, washout_tau)


def yaw_damper(
    plane_or_sys: Aircraft | StateSpace,
    washout_tau: float | None = DAMPER_WASHOUT,
    bandwidth: float = DAMPER_ACTUATOR_BANDWIDTH,
) -> Damper:
    """A yaw damper: yaw rate r fed back to the rudder through a first-order actuator of
    ``bandwidth`` rad/s and a washout of ``washout_tau`` seconds (None: without one), at the
    gain that gives the least-damped oscillatory mode (the Dutch roll, at first) its best
    damping (:func:`~aerocontrol.best_damping_gain`: no gain that makes a new, less damped
    oscillation of two other roots), with its margins against MIL-F-9490D.

    The washout passes the Dutch roll's yaw rate and blocks a steady one, so the damper
    does not oppose a steady turn and leaves the spiral mode nearly where it was; without
    it the feedback of r moves the spiral root.

    Parameters
    ----------
    plane_or_sys : Aircraft or StateSpace
        The aircraft (its lateral model is used) or a lateral model with the output "r" and
        the input "rudder".
    washout_tau : float or None, optional
        The washout's time constant in seconds, positive (default 3 s); None for no washout.
    bandwidth : float, optional
        The actuator's bandwidth in rad/s, positive (default 10).

    Returns
    -------
    Damper
        The ``loop`` L (k = 1), the ``design`` (gain and damping, a
        :class:`~aerocontrol.DampingDesign`), the ``margins`` of k L and their ``check``
        against MIL-F-9490D, the ``open_loop`` (actuator and aircraft) and the ``closed_loop``.

    Raises
    ------
    InvalidArgumentError
        ``plane_or_sys`` is neither an Aircraft nor a StateSpace (or lacks "r" or "rudder"),
        ``washout_tau`` is not positive, or ``bandwidth`` is not positive.
    AerocontrolLinAlgError
        The loop closed with the best gain is unstable.

    Examples
    --------
    >>> from aerocontrol import aircraft, design
    >>> damper = design.yaw_damper(aircraft.load("b747-cruise"))
    >>> round(damper.design.gain, 2), round(damper.design.damping_ratio, 3)
    (1.49, 0.291)
    >>> damper.check.passed
    {'yaw damper': True}
    """
    sys = _lateral(plane_or_sys)
    tau = None if washout_tau is None else real_scalar(washout_tau, "washout_tau")
    if tau is not None and not (math.isfinite(tau) and tau > 0):
        raise InvalidArgumentError(f"washout_tau must be positive or None, got {tau}")
    # The least-damped oscillation, not the Dutch roll tracked: without a washout the roll
    # and spiral roots join in an oscillation that the tracked design would leave lightly
    # damped.
    return _damper("yaw damper", sys, "r", "rudder", None, tau, bandwidth)


def pitch_damper(
    plane_or_sys: Aircraft | StateSpace, bandwidth: float = DAMPER_ACTUATOR_BANDWIDTH
) -> Damper:
    """A pitch damper: pitch rate q fed back to the elevator through a first-order actuator,
    at the gain that gives the short period, tracked along the locus, its best damping (the
    phugoid is left to the pilot), with its margins against MIL-F-9490D.

    Parameters
    ----------
    plane_or_sys : Aircraft or StateSpace
        The aircraft (its longitudinal model is used) or a longitudinal model with the output
        "q" and the input "elevator".
    bandwidth : float, optional
        The actuator's bandwidth in rad/s, positive (default 10).

    Returns
    -------
    Damper
        The ``loop`` L (k = 1), the ``design`` (gain and damping, a
        :class:`~aerocontrol.DampingDesign`), the ``margins`` of k L and their ``check``
        against MIL-F-9490D, the ``open_loop`` (actuator and aircraft) and the ``closed_loop``.

    Raises
    ------
    InvalidArgumentError
        ``plane_or_sys`` is neither an Aircraft nor a StateSpace, or lacks "q" or "elevator";
        ``bandwidth`` is not positive.
    AerocontrolLinAlgError
        The loop closed with the best gain is unstable.

    Examples
    --------
    >>> from aerocontrol import aircraft, design
    >>> damper = design.pitch_damper(aircraft.load("b747-cruise"))
    >>> damper.design.damping_ratio > 0.5
    True
    """
    if isinstance(plane_or_sys, Aircraft):
        sys = plane_or_sys.longitudinal()
    elif isinstance(plane_or_sys, StateSpace):
        sys = plane_or_sys
    else:
        raise InvalidArgumentError(
            f"expected an Aircraft or a longitudinal StateSpace, got {type(plane_or_sys).__name__}"
        )
    named = classify_modes(modes(sys.A), "longitudinal")
    short = [p for p in named.get("short period", ()) if p.imag > 0]
    return _damper(
        "pitch damper", sys, "q", "elevator", short[0] if short else None, None, bandwidth
    )
