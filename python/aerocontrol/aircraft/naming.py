"""Which eigenvalues of an aircraft model belong to which classical mode.

Longitudinal (4 states): the two eigenvalues of largest magnitude are the short period, the two
smallest the phugoid, whether each pair is complex or has split into two real roots (a heavily
damped short period, an unstable phugoid at low speed).

Lateral-directional (4 states): with one complex pair and two real roots, the pair is the Dutch
roll, the real root of larger magnitude the roll mode and the smaller the spiral. With four real
roots (a Dutch roll damped past critical), the largest is the roll mode, the smallest the spiral
and the middle two the Dutch roll. With two complex pairs (the roll and spiral coupled into one
oscillation, as at high angle of attack), the pair whose eigenvector has the larger sideslip
share is the Dutch roll and the other is named "roll-spiral".

Keys are lower case ("short period", "phugoid", "dutch roll", "roll", "spiral",
"roll-spiral"), as :func:`aerocontrol.handling.assess` takes them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ..exceptions import InvalidArgumentError
from ..modal import Modes

__all__ = ["DISPLAY_NAMES", "classify_modes", "name_modes"]

DISPLAY_NAMES = {
    "short period": "short period",
    "phugoid": "phugoid",
    "dutch roll": "Dutch roll",
    "roll": "roll",
    "spiral": "spiral",
    "roll-spiral": "roll-spiral",
}


def classify_modes(modes: Modes | ArrayLike, axis: str) -> dict[str, tuple[complex, ...]]:
    """The eigenvalues of each classical mode of a 4-state longitudinal or lateral model.

    ``modes`` is a :class:`~aerocontrol.Modes` or the 4 eigenvalues themselves (then a lateral
    model with two complex pairs, which needs the eigenvectors, raises InvalidArgumentError).

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> named = classify_modes(aircraft.load().modes("lateral"), "lateral")
    >>> sorted(named), round(named["roll"][0].real, 4)
    (['dutch roll', 'roll', 'spiral'], -1.2308)
    """
    values = np.asarray(modes.eigenvalues if isinstance(modes, Modes) else modes, dtype=complex)
    if values.shape != (4,):
        raise InvalidArgumentError(
            f"mode naming needs the 4 eigenvalues of an aircraft model, got {values.shape[0]}"
        )
    by_size = [complex(v) for v in values[np.argsort(np.abs(values), kind="stable")]]
    if axis == "longitudinal":
        return {"phugoid": _pair(by_size[:2]), "short period": _pair(by_size[2:])}
    if axis != "lateral":
        raise InvalidArgumentError(f"axis must be 'longitudinal' or 'lateral', got {axis!r}")
    complex_values = [v for v in by_size if v.imag != 0.0]
    real_values = [v for v in by_size if v.imag == 0.0]
    if len(complex_values) == 2:
        return {
            "spiral": (real_values[0],),
            "dutch roll": _pair(complex_values),
            "roll": (real_values[1],),
        }
    if not complex_values:
        return {
            "spiral": (by_size[0],),
            "dutch roll": _pair(by_size[1:3]),
            "roll": (by_size[3],),
        }
    if not isinstance(modes, Modes):
        raise InvalidArgumentError(
            "the lateral eigenvalues form two complex pairs: telling the Dutch roll from the "
            "coupled roll-spiral needs the eigenvectors, so pass aerocontrol.modes(A)"
        )
    return _two_pairs(modes)


def _pair(values: list[complex]) -> tuple[complex, ...]:
    """A conjugate pair with Im > 0 first, or two real roots in increasing magnitude."""
    first, second = values
    if first.imag < second.imag:
        first, second = second, first
    return (first, second)


def _two_pairs(modes: Modes) -> dict[str, tuple[complex, ...]]:
    vectors = modes.modal_matrix
    values = list(modes.eigenvalues)
    upper = [k for k, v in enumerate(values) if v.imag > 0]
    if vectors is None:
        raise InvalidArgumentError("the lateral model is defective: its modes cannot be separated")
    # Sideslip share of each unit eigenvector (state 0 is β).
    share = [abs(vectors[0, k]) / np.linalg.norm(vectors[:, k]) for k in upper]
    dutch, coupled = (upper[0], upper[1]) if share[0] >= share[1] else (upper[1], upper[0])
    return {
        "dutch roll": (complex(values[dutch]), complex(values[dutch]).conjugate()),
        "roll-spiral": (complex(values[coupled]), complex(values[coupled]).conjugate()),
    }


def name_modes(modes: Modes, axis: str) -> tuple[str, ...]:
    """Display names for the entries of ``modes`` (one per mode, in its order); a mode split into
    two real roots gives both entries its name with "(1)" and "(2)"."""
    classified = classify_modes(modes, axis)
    names = []
    for value in modes.eigenvalue:
        for key, members in classified.items():
            if any(_same(value, member) for member in members):
                split = len(members) == 2 and members[0].imag == 0.0
                label = DISPLAY_NAMES[key]
                if split:
                    label += " (1)" if _same(value, members[0]) else " (2)"
                names.append(label)
                break
    return tuple(names)


def _same(a: complex, b: complex) -> bool:
    return a == b or (a.real == b.real and abs(a.imag) == abs(b.imag))
