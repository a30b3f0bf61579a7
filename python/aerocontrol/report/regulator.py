"""Section 5 of the report: the lateral regulator (LQR with both surfaces) at the chapter's
weights c (6.224-6.227, Figures 6.9-6.11), and its root locus over c with the weight at which
the Dutch roll becomes critically damped (Figure 6.12)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import plotting
from ..aircraft.naming import DISPLAY_NAMES, classify_modes
from ..design import critical_weight, lqr_root_locus
from ..exceptions import AerocontrolError
from ..modal import modes
from ..responses import initial_response
from ..riccati import solve_care
from .context import Context, closed_loop
from .formatting import format_complex, format_vector, new_figure

__all__ = ["CHAPTER_WEIGHTS", "LOCUS_WEIGHTS", "section"]

#: The weights c of the chapter's regulator responses (Figures 6.9-6.11).
CHAPTER_WEIGHTS = (0.001, 0.5, 1.0, 2.0)
#: The weights marked on the chapter's root locus (Figure 6.12).
LOCUS_WEIGHTS = (0.001, 0.5, 1.0, 2.0, 5.0, 8.0, 9.0, 9.7, 9.76, 9.7727, 9.7728, 10.0)


def section(ctx: Context) -> str:
    """Write the regulator at each of :data:`CHAPTER_WEIGHTS` and its root locus, and
    leave the closed-loop modes in ``ctx.augmented``; the progress lines."""
    report, sys = ctx.report, ctx.lateral
    n, m = sys.n_states, sys.n_inputs
    Q, R = np.eye(n), np.eye(m)
    report.heading("Optimal regulator")
    report.paragraph(
        "LQR with both surfaces, minimising J = ∫ x^T Q x + (1/c²) η^T R η dt with Q = I and "
        "R = I (6.224-6.227), for the chapter's weights c; a small c makes control expensive. "
        "J∞ = x0^T S x0 is the index of the response to a unit sideslip perturbation, the "
        "residual is the Riccati equation's relative residual."
    )
    x0 = np.zeros(n)
    x0[sys.state_names.index("beta")] = 1.0
    grid = np.linspace(0.0, 30.0, 1501)
    open_response = initial_response(sys, x0, T=grid)
    rows, designs = [], {}
    for c in CHAPTER_WEIGHTS:
        solution = solve_care(sys.A, sys.B, Q, R / c**2)
        designs[c] = solution
        closed = closed_loop(sys, solution.K)
        ctx.augmented[f"LQR c = {c:g}"] = classify_modes(modes(closed.A), "lateral")
        rows.append(
            (
                f"{c:g}",
                *(format_vector(row) for row in solution.K),
                ", ".join(format_complex(v, 4) for v in solution.closed_loop_poles),
                f"{float(x0 @ solution.X @ x0):.5g}",
                f"{solution.residual:.1e}",
            )
        )
    report.table(
        (
            "c",
            *(f"K row {name}" for name in sys.input_names),
            "closed-loop poles",
            "J∞",
            "residual",
        ),
        rows,
    )
    responses = {
        c: initial_response(closed_loop(sys, designs[c].K), x0, T=grid) for c in CHAPTER_WEIGHTS
    }
    figure, axes = new_figure(2, height=4.4, sharey=True)
    plotting.plot_time_response(open_response, ax=axes[0, 0], title="(a) no feedback")
    first = CHAPTER_WEIGHTS[0]
    plotting.plot_with_controls(
        responses[first], designs[first].K, ax=axes[0, 1], title=f"(b) c = {first:g}"
    )
    report.figure(
        "lqr-small-c",
        f"Figure 6.9: response to a unit sideslip perturbation, (a) open loop, (b) optimal "
        f"closed loop with c = {first:g}, with the control deflections η = -K x (dashed).",
        figure,
    )
    others = CHAPTER_WEIGHTS[1:]
    figure, axes = new_figure(len(others), height=4.4, width=15.0, sharey=True)
    for column, c in enumerate(others):
        plotting.plot_with_controls(
            responses[c], designs[c].K, ax=axes[0, column], title=f"c = {c:g}"
        )
        if column:  # the scale, the label and the legend are the first panel's
            axes[0, column].set_ylabel("")
            axes[0, column].get_legend().remove()
    report.figure(
        "lqr-responses",
        "Figure 6.10: optimal closed-loop responses to a unit sideslip perturbation for c = "
        + ", ".join(f"{c:g}" for c in others)
        + ", with the control deflections η = -K x (dashed).",
        figure,
    )
    figure, axes = new_figure(1, width=9.0, height=4.8)
    for c in others:
        plotting.plot_penalty(
            responses[c], designs[c].K, Q, R / c**2, ax=axes[0, 0], name=f"c = {c:g}"
        )
    report.figure(
        "lqr-penalty",
        "Figure 6.11: x^T Q x (solid, above) and -η^T R η / c² (dashed, below) against time; "
        "the shaded area between them is J (the legend's J is the area over the plotted 30 s).",
        figure,
    )
    locus_line = _root_locus(ctx, Q, R)
    gains = "; ".join(f"c = {c:g}: J∞ = {float(x0 @ designs[c].X @ x0):.4g}" for c in designs)
    return f"LQR (Figures 6.9-6.11): {gains}\n{locus_line}"


def _label_locus(
    ctx: Context, ax: Any, critical: float | None, critical_roots: np.ndarray[Any, Any] | None
) -> None:
    """Names the lateral modes where their branches start (the open-loop roots, which those
    of c = 0.001 match to the plot's resolution) and marks the Dutch roll's double root at the
    critical c."""
    lateral = {"dutch roll", "roll", "spiral", "roll-spiral"}
    for key, members in ctx.open_loop_named.items():
        if key in lateral:
            root = members[0]
            ax.annotate(
                DISPLAY_NAMES[key],
                (root.real, abs(root.imag)),
                textcoords="offset points",
                # Inside the Dutch roll's arc (below its start); above a real root.
                xytext=(-6, -14) if root.imag else (-4, 9),
                ha="right",
                fontsize="small",
            )
    if critical is not None and critical_roots is not None:
        # The two roots nearest each other: the Dutch roll's, met on the real axis.
        roots = list(critical_roots)
        pairs = [(abs(a - b), a, b) for i, a in enumerate(roots) for b in roots[i + 1 :]]
        _, a, b = min(pairs, key=lambda pair: pair[0])
        meeting = (a + b) / 2
        ax.plot(meeting.real, 0.0, "*", color="black", markersize=11, zorder=5)
        ax.annotate(
            f"critical c = {critical:.4f}",
            (meeting.real, 0.0),
            textcoords="offset points",
            xytext=(-70, -45),
            ha="center",
            fontsize="small",
            arrowprops={"arrowstyle": "->", "linewidth": 0.8},
        )


def _root_locus(ctx: Context, Q: np.ndarray[Any, Any], R: np.ndarray[Any, Any]) -> str:
    report, sys = ctx.report, ctx.lateral
    try:
        critical: float | None = critical_weight(sys, "dutch roll", Q, R, bounds=(1e-3, 1e3))
    except AerocontrolError as error:
        critical = None
        reason = str(error)
    top = 1.2 * critical if critical else 20.0
    weights = np.unique(
        np.concatenate([np.geomspace(1e-3, top, 400), [c for c in LOCUS_WEIGHTS if c <= top]])
    )
    poles = lqr_root_locus(sys, weights, Q, R)
    marked = [c for c in LOCUS_WEIGHTS if c <= top]
    figure, axes = new_figure(1, width=9.0, height=5.5)
    ax = axes[0, 0]
    plotting.plot_root_locus(weights, poles, ax=ax, marked=marked, title="closed-loop roots over c")
    _label_locus(ctx, ax, critical, lqr_root_locus(sys, [critical], Q, R)[0] if critical else None)
    if critical:
        text = (
            f"The Dutch roll becomes critically damped at c = {critical:.6f} (the weight at "
            "which its two roots meet on the real axis, found by bisection to 1e-12). It is "
            "sensitive to the model's fifth digit: from the chapter's four-digit matrices "
            "(6.150, 6.151) it is 9.7749."
        )
        ctx.checks.append(
            (
                "critical c (Figure 6.12)",
                "caption 9.7227 < c < 9.7228; text c ≈ 9.973; symbols 9.7727, 9.7728",
                f"{critical:.6f}",
            )
        )
    else:
        text = f"No critically damped Dutch roll was found for c in [0.001, 1000]: {reason}."
    report.paragraph(text)
    report.figure(
        "root-locus",
        "Figure 6.12: the closed-loop roots as c grows from 0.001; symbols at the chapter's "
        "values of c.",
        figure,
    )
    return f"root locus (Figure 6.12): {text}"
