"""Section 6 of the report, second part: the open-loop Levels over Mach and altitude around
the file's flight condition."""

from __future__ import annotations

import numpy as np

from ..aircraft.envelope import envelope_sweep
from .context import Context
from .formatting import new_figure

__all__ = ["section"]


def section(ctx: Context) -> str:
    """The open-loop Levels around the file's condition: Mach from 0.8 to 1.4 times the file's,
    altitude within 10,000 ft (3,000 m) of it, at the file's weight (derivatives held)."""
    plane = ctx.plane
    span = 10_000.0 if plane.units == "english" else 3_000.0
    altitudes = np.linspace(max(plane.altitude - span, 0.0), plane.altitude + span, 9)
    machs = plane.mach * np.linspace(0.8, 1.4, 7)
    envelope = envelope_sweep(plane, altitudes=altitudes, machs=machs)
    ctx.report.heading("Levels around the flight condition")
    ctx.report.paragraph(
        "The open-loop Levels (worst mode) as the Mach number and altitude move away from the "
        "file's condition at its weight: each condition trimmed (CL), with the drag from the "
        "file's polar and every other derivative held at the file's values, so the map is a "
        "first look at the sensitivity, not a substitute for the derivatives of each condition."
    )
    figure, axes = new_figure(1, width=9.0, height=5.0)
    envelope.plot(ax=axes[0, 0])
    ctx.report.figure(
        "envelope",
        "Open-loop MIL-F-8785C Levels (worst mode) over Mach and altitude around the file's "
        "condition, derivatives held.",
        figure,
    )
    counts = np.bincount(envelope.worst.ravel(), minlength=5)
    summary = ", ".join(f"Level {lvl}: {counts[lvl]}" for lvl in range(1, 5) if counts[lvl])
    return f"envelope: {envelope.worst.size} conditions around the file's ({summary})"
