"""Section 4 of the report: the Dutch-roll damper by Bass-Gura pole placement, with the rudder
and with the aileron: gains, responses to a sideslip perturbation (Figures 6.5, 6.6), the
characteristic polynomials and companion-form gains (6.155-6.157) and the closed-loop
matrices (6.162, 6.165)."""

from __future__ import annotations

import math

import numpy as np

from .. import chapter, plotting
from ..aircraft.naming import classify_modes
from ..design import dutch_roll_damper
from ..exceptions import AerocontrolError
from ..modal import charpoly, modes
from ..placement import Placement
from ..responses import initial_response
from .context import Context, closed_loop
from .formatting import format_complex, format_vector, new_figure
from .models import matrix_table

__all__ = ["DAMPER_SIDESLIP", "DAMPER_ZETA", "section"]

#: The sideslip perturbation of the damper figures (Figures 6.5, 6.6): 5 degrees.
DAMPER_SIDESLIP = math.radians(5.0)
#: The Dutch-roll damping ratio the damper is designed for (6.156).
DAMPER_ZETA = 0.30


def section(ctx: Context) -> str:
    """Write the damper with each surface, or why it is not available (the rest of the
    report goes on), and leave the closed-loop modes in ``ctx.augmented``; the progress line."""
    report, sys = ctx.report, ctx.lateral
    report.heading("Dutch-roll damper by pole placement")
    report.paragraph(
        f"State feedback η = -k^T x through one surface that raises the Dutch roll's damping "
        f"ratio to ζ = {DAMPER_ZETA} at the same natural frequency and keeps the roll and spiral "
        "roots (6.156), by Bass-Gura through the companion form (6.145). The response is to a "
        "5-degree sideslip perturbation (Figures 6.5, 6.6)."
    )
    x0 = np.zeros(sys.n_states)
    x0[sys.state_names.index("beta")] = DAMPER_SIDESLIP
    grid = np.linspace(0.0, 30.0, 1501)
    open_response = initial_response(sys, x0, T=grid)
    rows, lines = [], []
    designs: dict[str, Placement] = {}
    for surface, number in (("rudder", "6.5"), ("aileron", "6.6")):
        try:
            design = dutch_roll_damper(sys, zeta=DAMPER_ZETA, surface=surface)
        except AerocontrolError as error:
            report.paragraph(f"The damper with the {surface} alone is not available: {error}")
            lines.append(f"{surface}: not available ({error})")
            continue
        designs[surface] = design
        closed = closed_loop(sys, design.K, [surface])
        named = classify_modes(modes(closed.A), "lateral")
        ctx.augmented[f"damper ({surface})"] = named
        dutch = named.get("dutch roll", ())
        rows.append(
            (
                surface,
                *(f"{v:.4f}" for v in design.k),
                ", ".join(format_complex(v, 4) for v in design.achieved_poles),
                f"{design.max_relative_error:.1e}",
                f"{design.controllability_condition:.3g}",
            )
        )
        figure, axes = new_figure(2)
        plotting.plot_open_closed(
            open_response,
            initial_response(closed, x0, T=grid),
            axes=axes[0],
            titles=("(a) open loop", f"(b) damper, {surface} feedback"),
        )
        report.figure(
            f"damper-{surface}",
            f"Figure {number}: response to a 5-degree sideslip perturbation, (a) open loop, "
            f"(b) with the Dutch roll damped to ζ = {DAMPER_ZETA} by {surface} feedback.",
            figure,
        )
        lines.append(f"{surface} k = {format_vector(design.k)}")
        ctx.checks.append(
            (
                f"{surface} damper gains " + ("(6.159)" if surface == "rudder" else "(6.164)"),
                "[0.1383, 0.0943, 0.1250, -1.1333]"
                if surface == "rudder"
                else "[-3.5417, 0.8715, 0.6746, -4.0504]",
                format_vector(design.k, 5),
            )
        )
        if dutch:
            lines[-1] += f", Dutch roll {format_complex(dutch[0], 4)}"
    if rows:
        report.table(
            (
                "surface",
                *(f"k_{n}" for n in sys.state_names),
                "closed-loop poles",
                "largest relative pole error",
                "κ(V)",
            ),
            rows,
        )
    if designs:
        _damper_polynomials_and_closed_loops(ctx, designs)
    return "Dutch-roll damper (Bass-Gura): " + "; ".join(lines)


def _damper_polynomials_and_closed_loops(ctx: Context, designs: dict[str, Placement]) -> None:
    """The characteristic polynomials (6.155), (6.156), the companion-form gains (6.157) and
    the closed-loop matrices A - b k^T (6.162), (6.165) of the dampers."""
    report, sys = ctx.report, ctx.lateral
    n = sys.n_states
    open_loop = charpoly(sys.A)
    # Every design aims at the same roots, so at the same polynomial.
    target = np.real(np.poly(next(iter(designs.values())).poles))
    companion_gains = target - open_loop
    report.paragraph(
        "The characteristic polynomials, open loop (6.155) and the target (6.156), and the "
        "gains of the companion form (6.157), k̄ = ā - a, the difference of their coefficients:"
    )
    powers = [f"s^{k}" if k > 1 else ("s" if k == 1 else "1") for k in range(n - 1, -1, -1)]
    report.table(
        ("", *powers),
        [
            (label, *(f"{v:.4f}" for v in values[1:]))
            for label, values in (
                ("a (open loop)", open_loop),
                ("ā (target)", target),
                ("k̄ = ā - a", companion_gains),
            )
        ],
    )
    for surface, design in designs.items():
        number = "6.162" if surface == "rudder" else "6.165"
        report.paragraph(f"The closed loop A - b k^T with the {surface} ({number}):")
        closed = closed_loop(sys, design.K, [surface])
        matrix_table(ctx, closed)
    printed = chapter.boeing747_damper_closed_loops()
    ctx.checks += [
        ("characteristic polynomial (6.155)", "[1.4385, 0.8222, 0.7232, 0.0319]",
         format_vector(open_loop[1:], 5)),
        ("target polynomial (6.156)", "[1.7258, 1.1891, 0.7396, 0.0319]",
         format_vector(target[1:], 5)),
        ("companion-form gains (6.157)", "[0.2873, 0.3669, 0.0164, 0.0000]",
         "[" + ", ".join(f"{v:.4f}" for v in companion_gains[1:]) + "]"),
    ]  # fmt: skip
    for surface, design in designs.items():
        if design.closed_loop.shape == printed[surface].shape:
            difference = float(np.abs(design.closed_loop - printed[surface]).max())
            ctx.checks.append(
                (
                    f"{surface} closed loop " + ("(6.162)" if surface == "rudder" else "(6.165)"),
                    "four decimals",
                    f"largest difference {difference:.1e}",
                )
            )
