"""Stacks of models judged in bulk: the modes named (:func:`classify_mode_stack`) and each
mode's MIL-F-8785C Level (:func:`aerocontrol.handling.level_arrays`), shared by the stochastic
robustness analysis and the gain schedule's envelope evaluation."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from .aircraft.naming import classify_mode_stack
from .handling import level_arrays

#: The modes of each axis, in the order of the judgement's Level columns.
AXIS_MODES = {
    "lateral": ("dutch roll", "roll", "spiral"),
    "longitudinal": ("short period", "phugoid"),
}


class Judgement(NamedTuple):
    """The judgement of k models of one axis."""

    named: dict[str, NDArray[np.complex128]]
    """Each mode's eigenvalues, (k, 2) or (k,), NaN where the mode is unresolved."""
    levels: NDArray[np.int8]
    """(k, modes), the modes in the order of :data:`AXIS_MODES`: each mode's Level (4 where
    the mode could not be judged)."""
    known: NDArray[np.bool_]
    """(k, modes): the mode was named, so its quantities are known."""
    judged: NDArray[np.bool_]
    """(k, modes): the mode's Level was judged: the mode was named, or (roll and spiral) the
    two coupled into a roll-spiral oscillation, whose Level (MIL-F-8785C 3.3.1.4) both then
    carry."""
    stable: NDArray[np.bool_]
    """(k,): every eigenvalue in the open left half-plane."""
    unresolved: NDArray[np.bool_]
    """(k,): the modes are not the classical ones (see :func:`classify_mode_stack`)."""
    max_real: NDArray[np.float64]
    """(k,): the largest real part of the eigenvalues."""


def judge_stack(
    A: NDArray[np.float64],
    eigenvalues: NDArray[np.complex128],
    axis: str,
    aircraft_class: str,
    category: str,
) -> Judgement:
    """Stability, named modes and Levels of k models of ``axis``: state matrices A (k, 4, 4)
    and their eigenvalues (k, 4)."""
    mode_names = AXIS_MODES[axis]
    count = A.shape[0]
    named, unresolved = classify_mode_stack(eigenvalues, axis, A)
    levels = np.full((count, len(mode_names)), 4, dtype=np.int8)
    known = np.zeros((count, len(mode_names)), dtype=bool)
    for k, name in enumerate(mode_names):
        known[:, k] = ~np.isnan(named[name]).reshape(count, -1).any(axis=1)
        judged = level_arrays({name: named[name][known[:, k]]}, aircraft_class, category)
        levels[known[:, k], k] = judged[name]
    assessed = known.copy()
    if "roll-spiral" in named:
        coupled = ~np.isnan(named["roll-spiral"]).any(axis=1)
        if coupled.any():
            pairs = {"roll-spiral": named["roll-spiral"][coupled]}
            level = level_arrays(pairs, aircraft_class, category)["roll-spiral"]
            for k in (mode_names.index("roll"), mode_names.index("spiral")):
                levels[coupled, k] = level
                assessed[coupled, k] = True
    return Judgement(
        named,
        levels,
        known,
        assessed,
        np.asarray((eigenvalues.real < 0.0).all(axis=1)),
        unresolved,
        eigenvalues.real.max(axis=1),
    )
