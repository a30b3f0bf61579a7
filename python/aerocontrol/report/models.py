"""Section 1 of the report: the aircraft, its flight condition and the two state-space
models, longitudinal (6.49, 6.50) and lateral-directional (6.150, 6.151)."""

from __future__ import annotations

from ..statespace import StateSpace
from .context import Context

__all__ = ["matrix_table", "section"]


def matrix_table(ctx: Context, sys: StateSpace) -> None:
    """A table of A and B side by side, a row per state, to four decimals (as the chapter
    prints them)."""
    header = ("", *sys.state_names, "", *sys.input_names)
    rows = [
        (name, *(f"{v:.4f}" for v in sys.A[i]), "", *(f"{v:.4f}" for v in sys.B[i]))
        for i, name in enumerate(sys.state_names)
    ]
    ctx.report.table(header, rows)


def section(ctx: Context) -> str:
    """Write the aircraft, its flight condition and the models; the progress line."""
    plane, report = ctx.plane, ctx.report
    report.heading("Aircraft and flight condition")
    report.paragraph(plane.summary())
    if plane.description:
        report.paragraph(plane.description + ".")
    report.heading("Models", 3)
    report.paragraph(
        "Longitudinal x' = A x + B η with x = (u/u0, α, q, θ) and the elevator (6.49, 6.50); "
        "lateral-directional with x = (β, p, φ, r) and the rudder and aileron (6.150, 6.151). "
        "Angles in radians, rates in rad/s, the stability-axis derivatives of the chapter's "
        "normalisation (6.48, 6.148)."
    )
    matrix_table(ctx, ctx.longitudinal)
    matrix_table(ctx, ctx.lateral)
    return (
        f"models: {plane.name}, longitudinal {ctx.longitudinal.state_names}, "
        f"lateral {ctx.lateral.state_names}"
    )
