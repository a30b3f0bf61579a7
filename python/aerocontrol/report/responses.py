"""Section 3 of the report: the elevator impulse and step at the chapter's two time scales
(Figures 6.1, 6.2), the step's steady state (6.51) and the static check (6.52-6.55), the rudder
and aileron steps, and Bode plots."""

from __future__ import annotations

import math

import numpy as np

from .. import plotting
from ..aircraft.naming import classify_modes
from ..frequency import bode
from ..responses import impulse_response, steady_state, step_response
from .context import Context
from .formatting import format_vector, new_figure, nice_ceiling

__all__ = ["ONE_DEGREE", "section"]

#: One degree in radians: the elevator step of Figure 6.2.
ONE_DEGREE = math.pi / 180.0
#: The most samples of a time response in the report.
_MAX_SAMPLES = 200_001


def _time_scales(ctx: Context) -> tuple[float, float]:
    """The short and long time scales of the longitudinal figures: ten time constants of the
    short period, and ten periods of the phugoid (or five time constants when it has split),
    rounded up to 1, 2 or 5 x 10^k; 20 s and 500 s for the 747, as in Figures 6.1 and 6.2."""
    named = classify_modes(ctx.plane.modes("longitudinal"), "longitudinal")
    short_period = named["short period"]
    fast = max(abs(min(v.real for v in short_period)), 1e-3)
    short = nice_ceiling(10.0 / fast)
    phugoid = named["phugoid"]
    if phugoid[0].imag != 0.0:
        long = nice_ceiling(10.0 * 2.0 * math.pi / abs(phugoid[0].imag))
    else:
        slow = max(min(abs(v.real) for v in phugoid), 1e-3)
        long = nice_ceiling(5.0 / slow)
    long = min(max(long, 2.0 * short), 5000.0)
    return short, long


def section(ctx: Context) -> str:
    """Write the time and frequency responses, and add the steady state and the static
    check to ``ctx.checks``; the progress line."""
    report, sys = ctx.report, ctx.longitudinal
    report.heading("Responses")
    short, long = _time_scales(ctx)
    # 400 steps per short scale, at most 0.05 s, and at most _MAX_SAMPLES samples (an aircraft
    # with a very fast short period over a long phugoid scale would need billions).
    spacing = max(min(short / 400.0, 0.05), long / (_MAX_SAMPLES - 1))
    grid = np.linspace(0.0, long, round(long / spacing) + 1)
    impulse = impulse_response(sys, T=grid)
    figure, axes = new_figure(2)
    plotting.plot_time_scales(impulse, short, axes=axes[0])
    report.figure(
        "elevator-impulse",
        f"Figure 6.1: response to a unit elevator impulse (1 rad s), over {short:g} s (short "
        f"period) and {long:g} s (phugoid).",
        figure,
    )
    step = step_response(sys, T=grid, eta0=ONE_DEGREE)
    figure, axes = new_figure(2)
    plotting.plot_time_scales(step, short, axes=axes[0])
    report.figure(
        "elevator-step",
        f"Figure 6.2: response to a one-degree elevator step, over {short:g} s and {long:g} s.",
        figure,
    )
    final = steady_state(sys, ONE_DEGREE)
    report.paragraph(
        "Steady state of the one-degree elevator step, x = -A^-1 B η0 (6.45, 6.51): "
        + ", ".join(f"{n} = {v:.4g}" for n, v in zip(sys.state_names, final, strict=True))
        + f"; the step response at {long:g} s: "
        + ", ".join(f"{n} = {v:.4g}" for n, v in zip(sys.state_names, step.x[-1], strict=True))
        + "."
    )
    ctx.checks.append(
        ("steady state (6.51)", "[0.0459, -0.0186, 0, -0.0160]", format_vector(final))
    )
    # The static check (6.52)-(6.55): the lift change of the new trim, from the steady state's
    # α and the elevator, against the chapter's static moment-and-lift balance (determinant Δ).
    c = ctx.plane.derivatives
    determinant = -c["CL_alpha"] * c["Cm_de"] + c["Cm_alpha"] * c["CL_de"]
    lift_change = c["CL_alpha"] * final[sys.state_names.index("alpha")] + c["CL_de"] * ONE_DEGREE
    ctx.checks.append(
        (
            "static check (6.52)-(6.55)",
            "Δ = 7.212, ΔCL = -0.100",
            f"Δ = {determinant:.4g}, ΔCL = {lift_change:.3f}",
        )
    )

    lateral_time = 30.0
    lateral_step = step_response(ctx.lateral, T=np.linspace(0, lateral_time, 1501), eta0=None)
    figure, axes = new_figure(2)
    for column in range(lateral_step.n_responses):
        plotting.plot_time_response(lateral_step, ax=axes[0, column], response=column, title=None)
    for column, name in enumerate(lateral_step.response_names[:2]):
        axes[0, column].set_title(f"step of 1 rad of {name}")
    report.figure(
        "lateral-steps",
        "Lateral-directional responses to unit steps of rudder and of aileron (linear model; "
        "scale to the deflection of interest).",
        figure,
    )
    figure, axes = new_figure(2, 2, height=6.0)
    frequency = bode(sys)
    plotting.plot_bode(frequency, ax=(axes[0, 0], axes[1, 0]), output=sys.state_names.index("q"))
    lateral_frequency = bode(ctx.lateral)
    plotting.plot_bode(
        lateral_frequency,
        ax=(axes[0, 1], axes[1, 1]),
        output=ctx.lateral.state_names.index("r"),
        input=ctx.lateral.input_names.index("rudder"),
    )
    report.figure("bode", "Bode plots: pitch rate to elevator, and yaw rate to rudder.", figure)
    return (
        f"responses: elevator impulse and step over {short:g} s and {long:g} s "
        "(Figures 6.1, 6.2), rudder and aileron steps, Bode plots"
    )
