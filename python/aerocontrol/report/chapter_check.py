"""Section 7 of the report, for the embedded 747 only: the chapter's two small examples (the
controllability example (6.75)-(6.88), Figures 6.4 and 6.8) and its printed numbers beside
ours, collected by every section in :attr:`Context.checks`."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .. import chapter, plotting
from ..controllability import controllability, ctrb
from ..design import lqr_root_locus
from ..placement import place_bass_gura
from ..responses import initial_response
from ..riccati import solve_care
from ..statespace import StateSpace
from .context import Context
from .formatting import format_complex, format_vector, new_figure

__all__ = ["section"]


def _controllability_example(ctx: Context) -> None:
    """The controllability example (6.75)-(6.88): V = [B, AB] and the modes each input
    reaches, for B = [0, 1]^T and B = [-1, 1]^T."""
    A, B = chapter.controllability_example()
    lost = np.array([[-1.0], [1.0]])
    verdict = controllability(A, lost)
    reached = f"det V = {np.linalg.det(ctrb(A, B)):.4g}"
    lost_modes = ", ".join(format_complex(v) for v in verdict.uncontrollable_eigenvalues)
    ctx.checks += [
        ("controllability (6.81), B = [0, 1]", "det V = -1", reached),
        (
            "controllability (6.84)-(6.88), B = [-1, 1]",
            "det V = 0; the mode at -2 not controllable",
            f"det V = {np.linalg.det(ctrb(A, lost)):.4g}; not controllable: {lost_modes}",
        ),
    ]


def _feedback_example(ctx: Context) -> None:
    """Figure 6.4: the second-order example (6.94)-(6.102), original system and with the
    feedback that places ω_n = 25 1/s, ζ = 0.707, from two initial states."""
    A, B = np.array([[-3.0, 8.0], [0.0, 0.0]]), np.array([0.0, 4.0])
    zeta, omega_n = 0.707, 25.0
    pole = complex(-zeta * omega_n, omega_n * math.sqrt(1.0 - zeta**2))
    poles = np.array([pole, pole.conjugate()])
    design = place_bass_gura(A, B, poles)
    original = StateSpace(A, B, state_names=["x1", "x2"])
    feedback = StateSpace(design.closed_loop, B, state_names=["x1", "x2"])
    figure, axes = new_figure(2)
    for column, (x0, final) in enumerate((([1.0, 0.0], 2.0), ([1.0, 0.1], 5.0))):
        grid = np.linspace(0.0, final, 2001)
        ax = axes[0, column]
        plotting.plot_time_response(
            initial_response(original, x0, T=grid), ax=ax, suffix=", original system"
        )
        plotting.plot_time_response(
            initial_response(feedback, x0, T=grid),
            ax=ax,
            suffix=", with feedback",
            linestyle="--",
            title=f"({'ab'[column]}) x(0) = {x0}",
        )
    ctx.report.figure(
        "feedback-example",
        "Figure 6.4: the second-order system with λ = -3, 0, original and with state feedback "
        "placing ω_n = 25 1/s, ζ = 0.707 (k = "
        + format_vector(design.k, 7)
        + "); (a) x(0) = [1, 0], (b) x(0) = [1, 0.1].",
        figure,
    )
    ctx.checks.append(("feedback gains (6.95)-(6.102)", "[16.5, 8.09]", format_vector(design.k, 7)))
    determinant = np.linalg.det(ctrb(A, B.reshape(-1, 1)))
    ctx.checks.append(("controllability matrix (6.98)", "det V = -128", f"det V = {determinant:g}"))


def _pendulum_example(ctx: Context) -> None:
    """Figure 6.8: the inverted pendulum's regulator (6.202)-(6.223) with γ = 1, the roots over
    c/γ and their asymptotes ζ = 1/√2 for large c."""
    gamma = 1.0
    pendulum = StateSpace(np.array([[0.0, 1.0], [gamma, 0.0]]), np.array([0.0, 1.0]))
    Q, R = np.diag([1.0, 0.0]), np.eye(1)
    weights = np.unique(np.r_[np.geomspace(1e-3, 1e3, 400), 1.0, 10.0, 100.0])
    poles = lqr_root_locus(pendulum, weights, Q, R)
    figure, axes = new_figure(2, width=9.0, height=5.5)
    reach = 1.1 * float(np.abs(poles).max())
    # (a) the whole locus, to c/γ = 1000; (b) its start near the origin, squeezed in (a).
    for ax, title, half_width in (
        (axes[0, 0], "(a) c/γ from 0.001 to 1000", reach),
        (axes[0, 1], "(b) near the origin", 3.0),
    ):
        plotting.plot_root_locus(
            weights, poles, ax=ax, marked=[1e-3, 1.0, 10.0, 100.0, 1000.0], weight_name="c/γ",
            title=title,
        )  # fmt: skip
        for sign in (1.0, -1.0):
            ax.plot([0.0, -reach / math.sqrt(2)], [0.0, sign * reach / math.sqrt(2)], color="c",
                    linewidth=0.8, label="asymptotes, ζ = 1/√2" if sign > 0 else None)  # fmt: skip
        ax.set_xlim(-half_width, 0.1 * half_width)
        ax.set_ylim(-half_width, half_width)
        ax.set_aspect("equal")
    # Between the branches, which the equal aspect leaves empty.
    axes[0, 0].legend(loc="center left", fontsize="small")
    axes[0, 1].get_legend().remove()
    ctx.report.figure(
        "pendulum-root-locus",
        "Figure 6.8: the inverted pendulum's closed-loop roots (units of γ) for c/γ from 0.001 "
        "(the double root at -√γ) to 1000, with the asymptotes of large c/γ; (b) the start of "
        "the locus.",
        figure,
    )
    c = 1.0
    closed_form = [
        gamma + math.sqrt(gamma**2 + c**2),
        math.sqrt(2 * (gamma + math.sqrt(gamma**2 + c**2))),
    ]
    K = solve_care(pendulum.A, pendulum.B, Q, R / c**2).K[0]
    ctx.checks.append(
        ("pendulum gain (6.218), γ = c = 1", format_vector(closed_form, 10), format_vector(K, 10))
    )


def _longitudinal_matrix_check(ctx: Context) -> None:
    """The largest difference between the model and the printed (6.49), at the printed chord
    and at the unrounded one the chapter evidently used."""
    A, B = chapter.boeing747_longitudinal()
    printed = np.c_[A, B]

    def largest_difference(sys: StateSpace) -> float:
        return float(np.abs(np.c_[sys.A, sys.B] - printed).max())

    unrounded = replace(ctx.plane, cbar=27.31).longitudinal()
    ctx.checks.insert(
        0,
        (
            "longitudinal A, B (6.49)",
            "four decimals",
            f"largest difference {largest_difference(ctx.longitudinal):.1e} (c̄ = 27.3 ft), "
            f"{largest_difference(unrounded):.1e} (c̄ = 27.31 ft)",
        ),
    )


def section(ctx: Context) -> str:
    """Write the chapter's examples and the table of ``ctx.checks``, its printed values
    beside ours; the progress line."""
    report = ctx.report
    report.heading("The chapter's examples and numbers")
    report.paragraph(
        "The chapter's two small examples, then its printed values beside ours, computed from "
        "the coefficients (6.47), (6.147). The printed matrices (6.49) were evidently computed "
        "with the unrounded chord c̄ = 27.31 ft (the 747's mean aerodynamic chord, 8.324 m) "
        "where (6.46) prints 27.3 ft: with it every entry is reproduced to its last printed "
        "digit except A21 (-0.2230 against -0.2229), while from 27.3 ft the q row differs in "
        "the fourth digit (Mq and Mδe scale with c̄² and c̄). The printed aileron gains (6.164) "
        "came from unrounded matrices; the chapter states the critical c twice, differently "
        "(the caption's 9.7227 is evidently a slip for the figure's 9.7727, which the "
        "unrounded model reproduces)."
    )
    _longitudinal_matrix_check(ctx)
    _controllability_example(ctx)
    _feedback_example(ctx)
    _pendulum_example(ctx)
    report.table(("result", "chapter", "aerocontrol"), [tuple(row) for row in ctx.checks])
    return (
        f"chapter check: Figures 6.4 and 6.8, {len(ctx.checks)} results beside the printed values"
    )
