"""Section 2 of the report: the modes of both models (6.152-6.154), in a table and in the
complex plane, and their MIL-F-8785C Levels."""

from __future__ import annotations

import numpy as np

from .. import plotting
from ..aircraft.naming import DISPLAY_NAMES, classify_modes
from ..modal import Modes
from .context import Context, assess
from .formatting import format_complex, format_number, new_figure

__all__ = ["section"]


def _mode_rows(modes: Modes, named: dict[str, tuple[complex, ...]]) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = []
    for key, members in named.items():
        lam = members[0]
        k = int(np.argmin(np.abs(modes.eigenvalue - lam)))
        if len(members) == 2 and members[0].imag == 0.0:
            text = f"{format_complex(members[0])}, {format_complex(members[1])}"
        elif lam.imag != 0.0:
            text = f"{lam.real:.5g} ± {abs(lam.imag):.5g}j"
        else:
            text = format_complex(lam)
        half, double = modes.time_to_half[k], modes.time_to_double[k]
        timing = f"{half:.4g}" if np.isfinite(half) else f"{format_number(double)} (doubles)"
        # A first-order mode (one real root) has a time constant, not a damping ratio, a
        # natural frequency or a period.
        first_order = len(members) == 1 and lam.imag == 0.0
        oscillation = (
            ("-", "-", "-")
            if first_order
            else (
                format_number(modes.damping_ratio[k]),
                format_number(modes.natural_frequency[k]),
                format_number(modes.period[k]),
            )
        )
        rows.append(
            (
                DISPLAY_NAMES[key],
                text,
                *oscillation,
                timing,
                format_number(modes.time_constant[k]),
            )
        )
    return rows


_MODE_HEADER = (
    "mode",
    "eigenvalue (1/s)",
    "ζ",
    "ω_n (rad/s)",
    "period (s)",
    "time to half (s)",
    "τ (s)",
)


def section(ctx: Context) -> str:
    """Write the modes and their open-loop Levels, and leave both in ``ctx`` for the
    Levels after augmentation; the progress lines."""
    report = ctx.report
    report.heading("Modes and handling qualities")
    named: dict[str, tuple[complex, ...]] = {}
    figure, axes = new_figure(2, height=4.4)
    summary = []
    for column, axis in enumerate(("longitudinal", "lateral")):
        axis_modes = ctx.plane.modes(axis)
        axis_named = classify_modes(axis_modes, axis)
        named.update(axis_named)
        report.heading(f"{axis.capitalize()} modes", 3)
        report.table(_MODE_HEADER, _mode_rows(axis_modes, axis_named))
        plotting.plot_modes(axis_modes, ax=axes[0, column])
        axes[0, column].set_title(f"{axis} modes")
        summary += [
            f"{DISPLAY_NAMES[key]} {format_complex(members[0], 4)}"
            for key, members in axis_named.items()
        ]
    report.figure("modes", "The modes in the complex plane.", figure)
    ctx.open_loop_named = named
    ctx.open_loop = assess(ctx, named)
    report.heading("MIL-F-8785C Levels", 3)
    report.paragraph(
        f"Class {ctx.plane.aircraft_class}, Flight Phase Category {ctx.plane.category}: each "
        "quantity against the limits of the specification (Level 4: worse than Level 3)."
    )
    report.table(
        ("mode", "quantity", "value", "Level", "limits", "reference"),
        [
            (r.mode, r.quantity, format_number(r.value), str(r.level), r.limits, r.reference)
            for r in ctx.open_loop.requirements
        ],
    )
    levels = ", ".join(f"{mode} {level}" for mode, level in ctx.open_loop.levels.items())
    return f"modes: {'; '.join(summary)}\nhandling qualities (Levels): {levels}"
