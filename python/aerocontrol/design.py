"""The chapter's design studies on an aircraft model: the Dutch-roll damper by pole placement
(§6.5.1, (6.156)-(6.165)) and the lateral regulator over the control weight c (§6.6,
(6.224)-(6.227), Figure 6.12).

The regulator minimises J = ∫ x^T Q x + (1/c²) η^T R η dt: R/c² is the control weight, so a
small c makes control expensive (the closed loop stays near the open loop) and a large c cheap.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validation import real_array, real_scalar
from .aircraft.model import Aircraft
from .aircraft.naming import classify_modes
from .batch import lqr_sweep
from .exceptions import InvalidArgumentError
from .modal import modes
from .placement import Placement, augment_mode, place_bass_gura
from .riccati import lqr
from .statespace import StateSpace

__all__ = ["critical_weight", "dutch_roll_damper", "lqr_root_locus"]

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
    values = [_split(poles, mode) for poles in lqr_sweep(sys, Q=Q, R=R, weights=grid).poles]
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
