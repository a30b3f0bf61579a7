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
from numpy.typing import ArrayLike, NDArray

from .. import _core
from .._validation import real_array
from ..exceptions import InvalidArgumentError
from ..modal import Modes

__all__ = ["DISPLAY_NAMES", "classify_mode_stack", "classify_modes", "name_modes"]

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

    Parameters
    ----------
    modes : Modes or array_like (4,)
        The modes of the model (:func:`aerocontrol.modes`), or its four eigenvalues.
    axis : {"longitudinal", "lateral"}
        The model's axis.

    Returns
    -------
    dict of str to tuple of complex
        Each mode's eigenvalues by name: "short period" and "phugoid" (longitudinal), "dutch
        roll", "roll" and "spiral", or "roll-spiral" for a coupled oscillation (lateral).

    Raises
    ------
    InvalidArgumentError
        ``axis`` is neither, the model has not 4 states, or a lateral model with two complex
        pairs is given by its eigenvalues alone.

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


def classify_mode_stack(
    eigenvalues: ArrayLike, axis: str, A: ArrayLike | None = None
) -> tuple[dict[str, NDArray[np.complex128]], NDArray[np.bool_]]:
    """:func:`classify_modes` for the eigenvalues of k models at once, shape (k, 4).

    Returns the modes, "short period" and "phugoid" or "dutch roll", "roll" and "spiral", as
    arrays of shape (k, 2) (pairs, ordered as :func:`classify_modes` orders them) or (k,),
    and a mask of the models left unresolved, whose entries here are NaN: lateral models
    whose eigenvalues form two complex pairs (telling the Dutch roll from the coupled
    roll-spiral needs the eigenvectors: :func:`classify_modes` of :func:`aerocontrol.modes`
    decides them), and longitudinal models whose two smallest eigenvalues are neither a
    conjugate pair nor two real roots (a split short period and a phugoid of interleaved
    magnitudes: no mode is defined by magnitude). Given the state matrices ``A`` (k, 4, 4),
    the Dutch roll of a lateral model with two complex pairs is the pair whose eigenvector has
    the larger sideslip share, as :func:`classify_modes` decides it (the eigenvectors from the
    adjugate of A - λI, whose columns span its null space), and the other pair is its
    "roll-spiral" (NaN for every other model); its roll and spiral stay NaN. A NaN or
    infinite eigenvalue, or entry of ``A``, is NonFiniteError (checked in the core).

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol import aircraft, linalg
    >>> A, _ = aircraft.load().model_stack("lateral", {"Cn_beta": [0.1, 0.2]})
    >>> named, unresolved = classify_mode_stack(linalg.eigenvalues(A), "lateral")
    >>> named["dutch roll"].shape, named["roll"].shape, unresolved.tolist()
    ((2, 2), (2,), [False, False])
    """
    values = np.asarray(eigenvalues, dtype=np.complex128)
    if values.ndim != 2 or values.shape[1] != 4:
        raise InvalidArgumentError(
            f"eigenvalues must have shape (k, 4) (4 per aircraft model), got {values.shape}"
        )
    if axis not in ("longitudinal", "lateral"):
        raise InvalidArgumentError(f"axis must be 'longitudinal' or 'lateral', got {axis!r}")
    # real_array: a complex A is NotRealError, not its real part with a ComplexWarning.
    matrices = None if A is None or axis == "longitudinal" else real_array(A, "A")
    slots, unresolved = _core.classify_mode_stack(axis, values, matrices)
    if axis == "longitudinal":
        return {"phugoid": slots[:, 0:2].copy(), "short period": slots[:, 2:4].copy()}, unresolved
    named = {
        "spiral": slots[:, 0].copy(),
        "dutch roll": slots[:, 1:3].copy(),
        "roll": slots[:, 3].copy(),
    }
    if matrices is not None and unresolved.any():
        named["roll-spiral"] = slots[:, 4:6].copy()
    return named, unresolved


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
    two real roots gives both entries its name with "(1)" and "(2)".

    Parameters
    ----------
    modes : Modes
        The modes of a 4-state model (:func:`aerocontrol.modes`).
    axis : {"longitudinal", "lateral"}
        The model's axis.

    Returns
    -------
    tuple of str
        One display name per entry of ``modes``.

    Raises
    ------
    InvalidArgumentError
        As :func:`classify_modes`.

    Examples
    --------
    >>> import aerocontrol
    >>> from aerocontrol import aircraft
    >>> aircraft.name_modes(aerocontrol.modes(aircraft.load().lateral()), "lateral")
    ('spiral', 'Dutch roll', 'roll')"""
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
