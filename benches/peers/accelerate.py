"""Peer cases of aerocontrol.accelerate: python-control's own functions with aerocontrol's
kernels swapped in (:func:`aerocontrol.accelerate_control`) against the same functions as
installed (slycot and scipy inside), called the same way on the same arguments.

The accelerated functions are taken once, between ``accelerate_control()`` and
``restore_control()``, and called directly: they are the objects a patched program calls, and
the other case files' python-control peers stay unpatched."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import control
import numpy as np

import aerocontrol

from .harness import Case, Peer

NAMES = ("lqr", "lqe", "place", "ctrb", "dlqr")


def _accelerated() -> dict[str, Callable[..., Any]]:
    originals = {name: getattr(control, name) for name in NAMES}
    aerocontrol.accelerate_control()
    try:
        swapped = {name: getattr(control, name) for name in NAMES}
    finally:
        aerocontrol.restore_control()
    assert all(swapped[name] is not originals[name] for name in NAMES)
    return swapped


def _lateral(rng: np.random.Generator) -> tuple[Any, ...]:
    """The chapter's 747 lateral model (6.150, 6.151): rudder and aileron."""
    return aerocontrol.chapter.boeing747_lateral()


def _first(result: Any) -> Any:
    return result[0] if isinstance(result, tuple) else result


def accelerated_cases() -> list[Case]:
    """python-control's lqr (Q = I, R = I), lqe (G = B, QN = I, RN = I, C = the first two
    states), place (the rudder alone, the chapter's damper poles), ctrb and dlqr (the model
    held at 0.05 s) on the 747 lateral model: accelerated against as installed, agreement on
    the gain (or the controllability matrix)."""
    swapped = _accelerated()
    A, B = aerocontrol.chapter.boeing747_lateral()
    C = np.eye(4)[:2]
    poles = aerocontrol.place_bass_gura(A, B[:, :1], [-0.2 + 0.8j, -0.2 - 0.8j, -0.56, -0.0073])
    sampled = aerocontrol.c2d(aerocontrol.StateSpace(A, B), 0.05)
    calls: dict[str, tuple[Any, ...]] = {
        "lqr": (A, B, np.eye(4), np.eye(2)),
        "lqe": (A, B, C, np.eye(2), np.eye(2)),
        "place": (A, B[:, :1], poles.achieved_poles),
        "ctrb": (A, B),
        "dlqr": (sampled.A, sampled.B, np.eye(4), np.eye(2)),
    }
    cases = []
    for name in NAMES:
        arguments = calls[name]
        original = getattr(control, name)
        cases.append(
            Case(
                op=f"control.{name} accelerated",
                size="n=4 747 lateral",
                seed=0,
                setup=lambda rng, arguments=arguments: arguments,
                ours=lambda *a, fn=swapped[name]: _first(fn(*a)),
                peers=[Peer(f"control.{name}", lambda *a, fn=original: _first(fn(*a)))],
            )
        )
    return cases


GROUPS = (accelerated_cases,)
"""The case builders of this file, in the order they run."""
