"""Section of the report: stability augmentation by output feedback. A yaw damper (yaw rate
to rudder through a first-order actuator, with and without a washout) and a pitch damper
(pitch rate to elevator) designed on the root locus for the best damping
(:func:`~aerocontrol.design.yaw_damper`, :func:`~aerocontrol.design.pitch_damper`), their
margins against MIL-F-9490D, the yaw damper's root locus and its response to a rudder pulse
beside the open loop's, with the spiral mode that the washout leaves in place."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .. import plotting
from ..design import DAMPER_WASHOUT, Damper, pitch_damper, yaw_damper
from ..exceptions import AerocontrolError
from ..loops import root_locus
from ..modal import modes
from ..responses import forced_response
from .context import Context
from .formatting import format_complex, format_number, new_figure

__all__ = ["RUDDER_PULSE", "section"]

#: The rudder pulse of the comparison: 2 degrees for 1 second.
RUDDER_PULSE = (math.radians(2.0), 1.0)


def _slowest_real(damper: Damper, closed: bool) -> str:
    """The slowest real root (the spiral's, for the lateral loop)."""
    roots = np.linalg.eigvals((damper.closed_loop if closed else damper.open_loop).A)
    real = roots[np.abs(roots.imag) <= 1e-9 * np.abs(roots)].real
    return format_number(float(real[np.argmin(np.abs(real))]), 4) if real.size else "none"


def _row(label: str, damper: Damper) -> tuple[str, ...]:
    m = damper.margins
    return (
        label,
        f"{damper.design.gain:.4g}",
        f"{damper.design.damping_ratio:.3f}",
        f"{m.gain_margin_db:+.2f} dB" if math.isfinite(m.gain_margin) else "∞",
        f"{m.phase_margin:+.1f}°" if math.isfinite(m.phase_margin) else "∞",
        format_number(m.delay_margin, 3),
        f"{m.disk_margin:.3f}",
        _slowest_real(damper, closed=False),
        _slowest_real(damper, closed=True),
        "pass" if all(damper.check.passed.values()) else "FAIL",
    )


def section(ctx: Context) -> str:
    """Write the dampers (each one that cannot be designed is reported as such) and return
    the progress line."""
    report = ctx.report
    report.heading("Stability augmentation by output feedback")
    report.paragraph(
        "Rate dampers as flown: the measured rate is fed back through a first-order actuator "
        "(10 rad/s) and, for the yaw damper, a washout τs/(τs + 1) that passes the Dutch "
        "roll and blocks a steady yaw rate, so that the damper does not oppose a steady turn. "
        "The gain k is chosen on the root locus of 1 + kL(s) = 0 for the best damping of the "
        "least-damped oscillation (yaw) or of the short period (pitch). Margins are those of "
        "kL broken at the surface command; MIL-F-9490D's Table I values are the widely quoted "
        "ones: no cell could be verified against the specification's text."
    )
    rows, lines, designs = [], [], {}
    builds: list[tuple[str, Callable[[], Damper]]] = [
        (f"yaw damper, washout {DAMPER_WASHOUT:g} s", lambda: yaw_damper(ctx.lateral)),
        ("yaw damper, no washout", lambda: yaw_damper(ctx.lateral, washout_tau=None)),
        ("pitch damper", lambda: pitch_damper(ctx.longitudinal)),
    ]
    for label, build in builds:
        try:
            damper = build()
        except AerocontrolError as error:
            report.paragraph(f"The {label} is not available: {error}")
            lines.append(f"{label}: not available ({error})")
            continue
        designs[label] = damper
        rows.append(_row(label, damper))
        lines.append(
            f"{label}: k = {damper.design.gain:.4g}, ζ = {damper.design.damping_ratio:.3f}"
        )
    if rows:
        report.table(
            (
                "loop",
                "k",
                "ζ",
                "GM",
                "PM",
                "delay margin (s)",
                "disk α",
                "slowest real root, open",
                "closed",
                "MIL-F-9490D",
            ),
            rows,
        )
    washed = designs.get(f"yaw damper, washout {DAMPER_WASHOUT:g} s")
    if washed is not None:
        for label, damper in designs.items():
            report.paragraph(
                f"{label}: closed-loop roots "
                + ", ".join(
                    format_complex(complex(v), 4) for v in modes(damper.closed_loop).eigenvalue
                )
            )
        figure, axes = new_figure(3)
        gains = np.linspace(1e-3, 3.0, 300) * washed.design.gain
        plotting.plot_gain_root_locus(
            root_locus(washed.loop, gains), ax=axes[0][0], marked=[washed.design.gain]
        )
        size, duration = RUDDER_PULSE
        t = np.linspace(0.0, 60.0, 3001)
        u = np.where(t < duration, size, 0.0)
        unwashed = designs.get("yaw damper, no washout")
        for k, (title, model) in enumerate(
            (
                ("open loop", washed.open_loop),
                ("washout", washed.closed_loop),
                ("no washout", unwashed.closed_loop if unwashed else None),
            )
        ):
            if model is None or k == 0:
                continue
            ax = axes[0][k]
            for name, response in (("open loop", washed.open_loop), (title, model)):
                result = forced_response(response, t, u)
                ax.plot(t, result.y[:, response.output_names.index("r")], label=f"r, {name}")
            ax.set_xlabel("time (s)")
            ax.set_ylabel("yaw rate r (rad/s)")
            ax.set_title(f"2° rudder pulse: open loop and damper ({title})")
            ax.legend(fontsize=8)
        report.figure(
            "yaw-damper",
            "Yaw damper: (a) root locus of the loop with washout over k, the chosen gain "
            "marked; (b), (c) yaw rate after a 2-degree, 1-second rudder pulse, open loop and "
            "with the damper, with and without the washout (without it the steady yaw rate "
            "of the spiral is opposed and the spiral root moves).",
            figure,
        )
    return "output-feedback dampers: " + "; ".join(lines)
