"""What the sections of a report share: the aircraft and its two models, the report being
written, and what each section leaves for the later ones (the open-loop modes and Levels, the
augmented designs' modes, the chapter's numbers beside ours)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import handling
from ..aircraft.model import Aircraft
from ..statespace import StateSpace
from .document import Report

__all__ = ["Context", "assess", "closed_loop"]


@dataclass
class Context:
    """The aircraft and its models, the report the sections write into, and the results one
    section leaves for the later ones."""

    plane: Aircraft
    report: Report
    longitudinal: StateSpace = field(init=False)
    lateral: StateSpace = field(init=False)
    open_loop: handling.HandlingQualities | None = None
    open_loop_named: dict[str, tuple[complex, ...]] = field(default_factory=dict)
    augmented: dict[str, dict[str, tuple[complex, ...]]] = field(default_factory=dict)
    checks: list[tuple[str, str, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.longitudinal = self.plane.longitudinal()
        self.lateral = self.plane.lateral()


def closed_loop(
    sys: StateSpace, K: np.ndarray[Any, Any], inputs: Sequence[str] | None = None
) -> StateSpace:
    """x' = (A - B K) x with the feedback through ``inputs`` (every input when None)."""
    names = tuple(sys.input_names if inputs is None else inputs)
    B = sys.B[:, [sys.input_names.index(name) for name in names]]
    return StateSpace(sys.A - B @ K, B, state_names=sys.state_names, input_names=names)


def assess(ctx: Context, named: dict[str, tuple[complex, ...]]) -> handling.HandlingQualities:
    """The Levels of the named modes (a coupled roll-spiral oscillation by MIL-F-8785C
    3.3.1.4)."""
    return handling.assess(named, ctx.plane.aircraft_class, ctx.plane.category)
