"""The report of the chapter's analyses on one aircraft: what ``aerocontrol report`` writes.

:func:`build_report` runs the analyses of the course chapter on an aircraft (the embedded 747
by default) and collects the results as a :class:`Report` of headings, paragraphs, tables and
matplotlib figures; :func:`write_report` renders it into a folder as ``report.html`` (self-
contained: the figures are embedded) and ``report.md`` with ``figures/*.png``. The sections:

1. the flight condition and the models (6.49, 6.150);
2. the modes (6.152-6.154) and their MIL-F-8785C Levels;
3. the elevator impulse and step at the chapter's two time scales (Figures 6.1, 6.2), the
   steady state of the step (6.51), rudder and aileron steps, and Bode plots;
4. the Dutch-roll damper by Bass-Gura with rudder and with aileron: the characteristic
   polynomials, companion-form gains, gains and closed-loop matrices (6.155-6.165, Figures 6.5,
   6.6);
5. the lateral regulator at the chapter's weights c (6.224-6.227, Figures 6.9-6.11), its root
   locus over c with the weight at which the Dutch roll becomes critically damped (Figure 6.12);
6. the Levels after augmentation, and the open-loop Levels over Mach and altitude around the
   file's condition;
7. for the embedded 747, the chapter's small examples (controllability (6.75-6.88), Figures 6.4
   and 6.8) and its printed numbers beside ours, among them the static check (6.52-6.55).

A design that does not apply to an aircraft (for example a lateral model without an
oscillatory Dutch roll) is reported as such and the rest of the report goes on.

Examples
--------
>>> from aerocontrol.report import build_report
>>> report = build_report("b747-approach", progress=print)   # doctest: +ELLIPSIS
models: Boeing 747, powered approach, longitudinal ('u/u0', 'alpha', 'q', 'theta'), ...
modes: phugoid -0.001774 + 0.1339j; short period -0.5514 + 0.6879j; spiral -0.04641; ...
handling qualities (Levels): short period 1, phugoid 2, dutch roll 2, roll 1, spiral 1
responses: elevator impulse and step over 20 s and 500 s (Figures 6.1, 6.2), ...
Dutch-roll damper (Bass-Gura): rudder k = [0.1383, 0.09435, 0.125, -1.133], ...
LQR (Figures 6.9-6.11): c = 0.001: J∞ = 16.57; c = 0.5: J∞ = 10.56; c = 1: J∞ = 7.088; ...
root locus (Figure 6.12): The Dutch roll becomes critically damped at c = 9.772714 ...
levels after augmentation: dutch roll 2 -> damper (rudder) 1, damper (aileron) 1, ...
envelope: 63 conditions around the file's (Level 2: 41, Level 3: 20, Level 4: 2)
chapter check: Figures 6.4 and 6.8, 16 results beside the printed values
>>> len(report.figures)
14
"""

from __future__ import annotations

import base64
import html
import io
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from . import chapter, handling, plotting
from ._report_folder import ReportFolder, termination_exits
from .aircraft.envelope import envelope_sweep
from .aircraft.model import Aircraft, load
from .aircraft.naming import DISPLAY_NAMES, classify_modes
from .controllability import controllability, ctrb
from .design import critical_weight, dutch_roll_damper, lqr_root_locus
from .exceptions import AerocontrolError, InvalidArgumentError, OutputFolderError
from .frequency import bode
from .modal import Modes, charpoly, modes
from .placement import Placement, place_bass_gura
from .responses import impulse_response, initial_response, steady_state, step_response
from .riccati import solve_care
from .statespace import StateSpace

__all__ = ["CHAPTER_WEIGHTS", "LOCUS_WEIGHTS", "Report", "build_report", "write_report"]

#: The weights c of the chapter's regulator responses (Figures 6.9-6.11).
CHAPTER_WEIGHTS = (0.001, 0.5, 1.0, 2.0)
#: The weights marked on the chapter's root locus (Figure 6.12).
LOCUS_WEIGHTS = (0.001, 0.5, 1.0, 2.0, 5.0, 8.0, 9.0, 9.7, 9.76, 9.7727, 9.7728, 10.0)
#: The sideslip perturbation of the damper figures (Figures 6.5, 6.6): 5 degrees.
DAMPER_SIDESLIP = math.radians(5.0)
#: The Dutch-roll damping ratio the damper is designed for (6.156).
DAMPER_ZETA = 0.30

ONE_DEGREE = math.pi / 180.0
#: The most samples of a time response in the report.
_MAX_SAMPLES = 200_001


# --- The document -----------------------------------------------------------------------------


@dataclass
class _Heading:
    text: str
    level: int


@dataclass
class _Paragraph:
    text: str


@dataclass
class _Table:
    header: tuple[str, ...]
    rows: list[tuple[str, ...]]


@dataclass
class _Figure:
    name: str
    caption: str
    figure: Any


@dataclass
class Report:
    """A report as a list of blocks, rendered to Markdown and to self-contained HTML."""

    title: str
    blocks: list[Any] = field(default_factory=list)

    def heading(self, text: str, level: int = 2) -> None:
        self.blocks.append(_Heading(text, level))

    def paragraph(self, text: str) -> None:
        self.blocks.append(_Paragraph(text))

    def table(self, header: Sequence[str], rows: Sequence[Sequence[str]]) -> None:
        self.blocks.append(_Table(tuple(header), [tuple(row) for row in rows]))

    def figure(self, name: str, caption: str, figure: Any) -> None:
        self.blocks.append(_Figure(name, caption, figure))

    @property
    def figures(self) -> list[tuple[str, Any]]:
        """(file name, matplotlib figure) of every figure, in order."""
        return [(f"{b.name}.png", b.figure) for b in self.blocks if isinstance(b, _Figure)]

    def markdown(self, figure_folder: str = "figures") -> str:
        """The report in Markdown, the figures linked from ``figure_folder``."""
        lines = [f"# {self.title}", ""]
        for block in self.blocks:
            if isinstance(block, _Heading):
                lines += ["#" * block.level + " " + block.text, ""]
            elif isinstance(block, _Paragraph):
                lines += [block.text, ""]
            elif isinstance(block, _Table):
                lines.append("| " + " | ".join(block.header) + " |")
                lines.append("|" + "|".join(" --- " for _ in block.header) + "|")
                for row in block.rows:
                    lines.append("| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |")
                lines.append("")
            else:
                lines += [f"![{block.caption}]({figure_folder}/{block.name}.png)", ""]
                lines += [f"*{block.caption}*", ""]
        return "\n".join(lines)

    def html(self, images: dict[str, bytes]) -> str:
        """The report as one HTML page; ``images`` maps file names to PNG bytes, embedded."""
        body = [f"<h1>{html.escape(self.title)}</h1>"]
        for block in self.blocks:
            if isinstance(block, _Heading):
                body.append(f"<h{block.level}>{html.escape(block.text)}</h{block.level}>")
            elif isinstance(block, _Paragraph):
                body.append(f"<p>{html.escape(block.text)}</p>")
            elif isinstance(block, _Table):
                head = "".join(f"<th>{html.escape(cell)}</th>" for cell in block.header)
                rows = "".join(
                    "<tr>" + "".join(f"<td>{html.escape(cell)}</td>" for cell in row) + "</tr>"
                    for row in block.rows
                )
                body.append(f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>")
            else:
                data = base64.b64encode(images[f"{block.name}.png"]).decode("ascii")
                caption = html.escape(block.caption)
                body.append(
                    f'<figure><img alt="{caption}" src="data:image/png;base64,{data}">'
                    f"<figcaption>{caption}</figcaption></figure>"
                )
        return _HTML_PAGE.format(title=html.escape(self.title), body="\n".join(body))


_HTML_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto;
        padding: 0 1em; line-height: 1.45; color: #1a1a1a; }}
table {{ border-collapse: collapse; margin: 0.8em 0 1.4em; font-size: 0.92em; }}
th, td {{ border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; }}
th {{ background: #f2f2f2; }}
td {{ font-variant-numeric: tabular-nums; }}
figure {{ margin: 1em 0 2em; }}
img {{ max-width: 100%; }}
figcaption {{ font-size: 0.9em; color: #444; }}
</style>
</head>
<body>
{body}
</body>
</html>
"""


# --- Formatting -------------------------------------------------------------------------------


def _number(value: float, digits: int = 4) -> str:
    if not math.isfinite(value):
        return "-" if math.isnan(value) else ("∞" if value > 0 else "-∞")
    return f"{value:.{digits}g}"


def _complex(value: complex, digits: int = 5) -> str:
    if value.imag == 0.0:
        return f"{value.real:.{digits}g}"
    sign = "+" if value.imag > 0 else "-"
    return f"{value.real:.{digits}g} {sign} {abs(value.imag):.{digits}g}j"


def _vector(values: Any, digits: int = 4) -> str:
    return "[" + ", ".join(f"{v:.{digits}g}" for v in np.asarray(values).ravel()) + "]"


def _nice_ceiling(value: float) -> float:
    """The smallest of 1, 2, 5 x 10^k not below ``value``."""
    exponent = math.floor(math.log10(value))
    for mantissa in (1.0, 2.0, 5.0, 10.0):
        candidate = mantissa * 10.0**exponent
        if candidate >= value * (1 - 1e-12):
            return candidate
    return 10.0 ** (exponent + 1)  # pragma: no cover - the loop always returns


def _new_figure(
    columns: int = 1,
    rows: int = 1,
    width: float = 11.0,
    height: float = 4.2,
    sharey: bool = False,
) -> Any:
    """A figure of rows x columns axes; ``sharey`` for panels that compare designs."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), layout="constrained")
    axes = figure.subplots(rows, columns, squeeze=False, sharey=sharey)
    return figure, axes


# --- The analyses -----------------------------------------------------------------------------


@dataclass
class _Context:
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


def _mode_rows(modes: Modes, named: dict[str, tuple[complex, ...]]) -> list[tuple[str, ...]]:
    rows: list[tuple[str, ...]] = []
    for key, members in named.items():
        lam = members[0]
        k = int(np.argmin(np.abs(modes.eigenvalue - lam)))
        if len(members) == 2 and members[0].imag == 0.0:
            text = f"{_complex(members[0])}, {_complex(members[1])}"
        elif lam.imag != 0.0:
            text = f"{lam.real:.5g} ± {abs(lam.imag):.5g}j"
        else:
            text = _complex(lam)
        half, double = modes.time_to_half[k], modes.time_to_double[k]
        timing = f"{half:.4g}" if np.isfinite(half) else f"{_number(double)} (doubles)"
        # A first-order mode (one real root) has a time constant, not a damping ratio, a
        # natural frequency or a period.
        first_order = len(members) == 1 and lam.imag == 0.0
        oscillation = (
            ("-", "-", "-")
            if first_order
            else (
                _number(modes.damping_ratio[k]),
                _number(modes.natural_frequency[k]),
                _number(modes.period[k]),
            )
        )
        rows.append(
            (
                DISPLAY_NAMES[key],
                text,
                *oscillation,
                timing,
                _number(modes.time_constant[k]),
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


def _matrix_table(ctx: _Context, sys: StateSpace) -> None:
    header = ("", *sys.state_names, "", *sys.input_names)
    rows = [
        (name, *(f"{v:.4f}" for v in sys.A[i]), "", *(f"{v:.4f}" for v in sys.B[i]))
        for i, name in enumerate(sys.state_names)
    ]
    ctx.report.table(header, rows)


def _section_models(ctx: _Context) -> str:
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
    _matrix_table(ctx, ctx.longitudinal)
    _matrix_table(ctx, ctx.lateral)
    return (
        f"models: {plane.name}, longitudinal {ctx.longitudinal.state_names}, "
        f"lateral {ctx.lateral.state_names}"
    )


def _section_modes(ctx: _Context) -> str:
    report = ctx.report
    report.heading("Modes and handling qualities")
    named: dict[str, tuple[complex, ...]] = {}
    figure, axes = _new_figure(2, height=4.4)
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
            f"{DISPLAY_NAMES[key]} {_complex(members[0], 4)}" for key, members in axis_named.items()
        ]
    report.figure("modes", "The modes in the complex plane.", figure)
    ctx.open_loop_named = named
    ctx.open_loop = _assess(ctx, named)
    report.heading("MIL-F-8785C Levels", 3)
    report.paragraph(
        f"Class {ctx.plane.aircraft_class}, Flight Phase Category {ctx.plane.category}: each "
        "quantity against the limits of the specification (Level 4: worse than Level 3)."
    )
    report.table(
        ("mode", "quantity", "value", "Level", "limits", "reference"),
        [
            (r.mode, r.quantity, _number(r.value), str(r.level), r.limits, r.reference)
            for r in ctx.open_loop.requirements
        ],
    )
    levels = ", ".join(f"{mode} {level}" for mode, level in ctx.open_loop.levels.items())
    return f"modes: {'; '.join(summary)}\nhandling qualities (Levels): {levels}"


def _time_scales(ctx: _Context) -> tuple[float, float]:
    """The short and long time scales of the longitudinal figures: ten time constants of the
    short period, and ten periods of the phugoid (or five time constants when it has split),
    rounded up to 1, 2 or 5 x 10^k; 20 s and 500 s for the 747, as in Figures 6.1 and 6.2."""
    named = classify_modes(ctx.plane.modes("longitudinal"), "longitudinal")
    short_period = named["short period"]
    fast = max(abs(min(v.real for v in short_period)), 1e-3)
    short = _nice_ceiling(10.0 / fast)
    phugoid = named["phugoid"]
    if phugoid[0].imag != 0.0:
        long = _nice_ceiling(10.0 * 2.0 * math.pi / abs(phugoid[0].imag))
    else:
        slow = max(min(abs(v.real) for v in phugoid), 1e-3)
        long = _nice_ceiling(5.0 / slow)
    long = min(max(long, 2.0 * short), 5000.0)
    return short, long


def _section_responses(ctx: _Context) -> str:
    report, sys = ctx.report, ctx.longitudinal
    report.heading("Responses")
    short, long = _time_scales(ctx)
    # 400 steps per short scale, at most 0.05 s, and at most _MAX_SAMPLES samples (an aircraft
    # with a very fast short period over a long phugoid scale would need billions).
    spacing = max(min(short / 400.0, 0.05), long / (_MAX_SAMPLES - 1))
    grid = np.linspace(0.0, long, round(long / spacing) + 1)
    impulse = impulse_response(sys, T=grid)
    figure, axes = _new_figure(2)
    plotting.plot_time_scales(impulse, short, axes=axes[0])
    report.figure(
        "elevator-impulse",
        f"Figure 6.1: response to a unit elevator impulse (1 rad s), over {short:g} s (short "
        f"period) and {long:g} s (phugoid).",
        figure,
    )
    step = step_response(sys, T=grid, eta0=ONE_DEGREE)
    figure, axes = _new_figure(2)
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
    ctx.checks.append(("steady state (6.51)", "[0.0459, -0.0186, 0, -0.0160]", _vector(final)))
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
    figure, axes = _new_figure(2)
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
    figure, axes = _new_figure(2, 2, height=6.0)
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


def _closed_loop(
    sys: StateSpace, K: np.ndarray[Any, Any], inputs: Sequence[str] | None = None
) -> StateSpace:
    """x' = (A - B K) x with the feedback through ``inputs`` (every input when None)."""
    names = tuple(sys.input_names if inputs is None else inputs)
    B = sys.B[:, [sys.input_names.index(name) for name in names]]
    return StateSpace(sys.A - B @ K, B, state_names=sys.state_names, input_names=names)


def _section_damper(ctx: _Context) -> str:
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
        closed = _closed_loop(sys, design.K, [surface])
        named = classify_modes(modes(closed.A), "lateral")
        ctx.augmented[f"damper ({surface})"] = named
        dutch = named.get("dutch roll", ())
        rows.append(
            (
                surface,
                *(f"{v:.4f}" for v in design.k),
                ", ".join(_complex(v, 4) for v in design.achieved_poles),
                f"{design.max_relative_error:.1e}",
                f"{design.controllability_condition:.3g}",
            )
        )
        figure, axes = _new_figure(2)
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
        lines.append(f"{surface} k = {_vector(design.k)}")
        ctx.checks.append(
            (
                f"{surface} damper gains " + ("(6.159)" if surface == "rudder" else "(6.164)"),
                "[0.1383, 0.0943, 0.1250, -1.1333]"
                if surface == "rudder"
                else "[-3.5417, 0.8715, 0.6746, -4.0504]",
                _vector(design.k, 5),
            )
        )
        if dutch:
            lines[-1] += f", Dutch roll {_complex(dutch[0], 4)}"
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


def _damper_polynomials_and_closed_loops(ctx: _Context, designs: dict[str, Placement]) -> None:
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
        closed = _closed_loop(sys, design.K, [surface])
        _matrix_table(ctx, closed)
    printed = chapter.boeing747_damper_closed_loops()
    ctx.checks += [
        ("characteristic polynomial (6.155)", "[1.4385, 0.8222, 0.7232, 0.0319]",
         _vector(open_loop[1:], 5)),
        ("target polynomial (6.156)", "[1.7258, 1.1891, 0.7396, 0.0319]",
         _vector(target[1:], 5)),
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


def _section_regulator(ctx: _Context) -> str:
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
        closed = _closed_loop(sys, solution.K)
        ctx.augmented[f"LQR c = {c:g}"] = classify_modes(modes(closed.A), "lateral")
        rows.append(
            (
                f"{c:g}",
                *(_vector(row) for row in solution.K),
                ", ".join(_complex(v, 4) for v in solution.closed_loop_poles),
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
        c: initial_response(_closed_loop(sys, designs[c].K), x0, T=grid) for c in CHAPTER_WEIGHTS
    }
    figure, axes = _new_figure(2, height=4.4, sharey=True)
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
    figure, axes = _new_figure(len(others), height=4.4, width=15.0, sharey=True)
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
    figure, axes = _new_figure(1, width=9.0, height=4.8)
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
    ctx: _Context, ax: Any, critical: float | None, critical_roots: np.ndarray[Any, Any] | None
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


def _root_locus(ctx: _Context, Q: np.ndarray[Any, Any], R: np.ndarray[Any, Any]) -> str:
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
    figure, axes = _new_figure(1, width=9.0, height=5.5)
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


def _assess(ctx: _Context, named: dict[str, tuple[complex, ...]]) -> handling.HandlingQualities:
    """The Levels of the named modes; a coupled roll-spiral oscillation (MIL-F-8785C 3.3.1.4)
    is left out (it is shown as such in the tables)."""
    kept = {key: value for key, value in named.items() if key != "roll-spiral"}
    return handling.assess(kept, ctx.plane.aircraft_class, ctx.plane.category)


def _level(assessment: handling.HandlingQualities, named: dict[str, Any], mode: str) -> str:
    if mode == "roll-spiral":
        return "coupled (3.3.1.4), not assessed" if mode in named else "-"
    return str(assessment.levels.get(mode, "-"))


def _section_levels(ctx: _Context) -> str:
    report = ctx.report
    report.heading("Levels after augmentation")
    if ctx.open_loop is None:  # pragma: no cover - the modes section always runs first
        raise InvalidArgumentError("the modes must be assessed before the augmented designs")
    longitudinal = {
        key: value
        for key, value in ctx.open_loop_named.items()
        if key in ("short period", "phugoid")
    }
    columns = {"open loop": (ctx.open_loop, ctx.open_loop_named)}
    for label, lateral in ctx.augmented.items():
        named = {**longitudinal, **lateral}
        columns[label] = (_assess(ctx, named), named)
    modes = [*handling.MODES]
    if any("roll-spiral" in named for _, named in columns.values()):
        modes.append("roll-spiral")
    rows = [
        (mode, *(_level(hq, named, mode) for hq, named in columns.values()))
        for mode in modes
        if any(mode in named for _, named in columns.values())
    ]
    rows.append(("all modes", *(str(max(hq.levels.values())) for hq, _ in columns.values())))
    report.paragraph(
        f"MIL-F-8785C Levels, Class {ctx.plane.aircraft_class}, Flight Phase Category "
        f"{ctx.plane.category}, open loop and with each design of the lateral motion (the "
        "longitudinal modes are not changed)."
        + (
            " A coupled roll-spiral oscillation (3.3.1.4) is listed but not assessed."
            if "roll-spiral" in modes
            else ""
        )
    )
    report.table(("mode", *columns), rows)
    changed = [
        f"{row[0]} {row[1]} -> "
        + ", ".join(
            f"{label} {cell}" for label, cell in zip(list(columns)[1:], row[2:], strict=True)
        )
        for row in rows[:-1]
        if any(cell != row[1] for cell in row[2:])
    ]
    return "levels after augmentation: " + ("; ".join(changed) or "no Level changes")


def _section_envelope(ctx: _Context) -> str:
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
    figure, axes = _new_figure(1, width=9.0, height=5.0)
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


def _controllability_example(ctx: _Context) -> None:
    """The controllability example (6.75)-(6.88): V = [B, AB] and the modes each input
    reaches, for B = [0, 1]^T and B = [-1, 1]^T."""
    A, B = chapter.controllability_example()
    lost = np.array([[-1.0], [1.0]])
    verdict = controllability(A, lost)
    reached = f"det V = {np.linalg.det(ctrb(A, B)):.4g}"
    lost_modes = ", ".join(_complex(v) for v in verdict.uncontrollable_eigenvalues)
    ctx.checks += [
        ("controllability (6.81), B = [0, 1]", "det V = -1", reached),
        (
            "controllability (6.84)-(6.88), B = [-1, 1]",
            "det V = 0; the mode at -2 not controllable",
            f"det V = {np.linalg.det(ctrb(A, lost)):.4g}; not controllable: {lost_modes}",
        ),
    ]


def _feedback_example(ctx: _Context) -> None:
    """Figure 6.4: the second-order example (6.94)-(6.102), original system and with the
    feedback that places ω_n = 25 1/s, ζ = 0.707, from two initial states."""
    A, B = np.array([[-3.0, 8.0], [0.0, 0.0]]), np.array([0.0, 4.0])
    zeta, omega_n = 0.707, 25.0
    pole = complex(-zeta * omega_n, omega_n * math.sqrt(1.0 - zeta**2))
    poles = np.array([pole, pole.conjugate()])
    design = place_bass_gura(A, B, poles)
    original = StateSpace(A, B, state_names=["x1", "x2"])
    feedback = StateSpace(design.closed_loop, B, state_names=["x1", "x2"])
    figure, axes = _new_figure(2)
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
        + _vector(design.k, 7)
        + "); (a) x(0) = [1, 0], (b) x(0) = [1, 0.1].",
        figure,
    )
    ctx.checks.append(("feedback gains (6.95)-(6.102)", "[16.5, 8.09]", _vector(design.k, 7)))
    determinant = np.linalg.det(ctrb(A, B.reshape(-1, 1)))
    ctx.checks.append(("controllability matrix (6.98)", "det V = -128", f"det V = {determinant:g}"))


def _pendulum_example(ctx: _Context) -> None:
    """Figure 6.8: the inverted pendulum's regulator (6.202)-(6.223) with γ = 1, the roots over
    c/γ and their asymptotes ζ = 1/√2 for large c."""
    gamma = 1.0
    pendulum = StateSpace(np.array([[0.0, 1.0], [gamma, 0.0]]), np.array([0.0, 1.0]))
    Q, R = np.diag([1.0, 0.0]), np.eye(1)
    weights = np.unique(np.r_[np.geomspace(1e-3, 1e3, 400), 1.0, 10.0, 100.0])
    poles = lqr_root_locus(pendulum, weights, Q, R)
    figure, axes = _new_figure(2, width=9.0, height=5.5)
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
        ("pendulum gain (6.218), γ = c = 1", _vector(closed_form, 10), _vector(K, 10))
    )


def _longitudinal_matrix_check(ctx: _Context) -> None:
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


def _section_chapter(ctx: _Context) -> str:
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


# --- Entry points -----------------------------------------------------------------------------


def build_report(
    plane: Aircraft | str = "b747-approach", progress: Callable[[str], None] | None = None
) -> Report:
    """Run the analyses on an aircraft (an :class:`~aerocontrol.aircraft.Aircraft`, a shipped
    identifier or a TOML path) and collect them as a :class:`Report`. ``progress`` receives
    one line per step."""
    aircraft = plane if isinstance(plane, Aircraft) else load(plane)
    say = progress if progress is not None else (lambda line: None)
    report = Report(f"aerocontrol {_version()}: {aircraft.name}")
    ctx = _Context(aircraft, report)
    steps: list[Callable[[_Context], str]] = [
        _section_models,
        _section_modes,
        _section_responses,
        _section_damper,
        _section_regulator,
        _section_levels,
        _section_envelope,
    ]
    if aircraft.identifier == "b747-approach":
        steps.append(_section_chapter)
    for step in steps:
        for line in step(ctx).splitlines():
            say(line)
    return report


def write_report(
    plane: Aircraft | str = "b747-approach",
    out: str | Path = "aerocontrol-report",
    progress: Callable[[str], None] | None = None,
    force: bool = False,
) -> Path:
    """Build the report of an aircraft and write it into the folder ``out``: ``report.html``
    (self-contained), ``report.md``, ``figures/*.png`` and the manifest
    ``.aerocontrol-report.json`` (each file with its size and SHA-256). Returns the path of
    ``report.html``.

    The report never deletes, renames or overwrites a file it did not write itself:

    - a new or empty ``out`` is used (missing parent folders are created);
    - an ``out`` holding an earlier report (its manifest) is replaced if every file the
      manifest lists is unchanged or deleted: only those files are replaced or removed, and
      files it does not list (your notes, your images in ``figures/``) are never touched;
      a listed file changed since stops the run, named (it is yours now);
    - an ``out`` that is not empty and holds no manifest is refused, unless ``force``: then
      the report is written beside the files there, and a file in its way (your own
      ``report.md``, say) stops the run, named;
    - a symbolic link inside ``out`` (``report.md``, ``figures``) is never written through;
      ``out`` itself may be a link to a folder;
    - a manifest that is not one this function wrote (not JSON, entries other than the
      report's own file names, such as ``../x`` or absolute paths) refuses the run.

    The aircraft is loaded and the folder checked before anything is built, so a refusal is
    immediate. The files are rendered into a staging folder inside ``out`` and moved into
    place at the end, with SIGINT, SIGTERM and SIGHUP held back for those moves. On any
    failure, and on KeyboardInterrupt or SIGTERM (in the main thread, while SIGTERM has its
    default action, it raises SystemExit(143) for the duration of the call), the run undoes
    exactly what it did: the staging folder, its files, the folders it created (if empty);
    the earlier report's files, kept as backups until the end, are put back. Another run
    writing into the same folder at the same time is refused.

    Raises
    ------
    AircraftDataError
        The aircraft cannot be loaded (nothing is written).
    OutputFolderError
        An ``OSError``: ``out`` cannot be used (not empty and no earlier report, a changed
        or unlisted file in the way, a bad manifest, another run, not a folder, not
        writable, out of space); one line naming the folder and the file.

    Examples
    --------
    ``write_report("navion", "navion-report")`` writes the Navion's report into
    ./navion-report; ``aerocontrol report navion --out navion-report`` does the same, and
    running either again replaces that report.
    """
    aircraft = plane if isinstance(plane, Aircraft) else load(plane)
    say = progress if progress is not None else (lambda line: None)
    folder = ReportFolder(Path(out), force=force)
    with termination_exits():
        folder.prepare()
        try:
            report = build_report(aircraft, say)
            earlier = " (replacing the earlier report)" if folder.replacing else ""
            say(f"writing {len(report.figures)} figures and the report{earlier}")
            folder.write(_render(report, say))
        except BaseException as error:
            problems = folder.rollback()
            if problems and isinstance(error, Exception):
                raise OutputFolderError(f"{error}; moreover {'; '.join(problems)}") from error
            raise
        finally:
            folder.release()
    return Path(out) / "report.html"


def _render(report: Report, say: Callable[[str], None]) -> dict[str, bytes]:
    """The report's files by name: ``figures/*.png``, ``report.md``, ``report.html``.

    A figure that matplotlib cannot draw (the responses of an aircraft whose numbers are each
    plausible but together absurd can overflow to values no axis can hold) is replaced by a
    picture that says so, and the rest of the report goes on."""
    images = {}
    for name, figure in report.figures:
        buffer = io.BytesIO()
        try:
            figure.savefig(buffer, format="png", dpi=100)
        except (ArithmeticError, ValueError, RuntimeError) as error:
            reason = " ".join(f"{type(error).__name__}: {error}".split())
            say(f"figure {name} could not be drawn ({reason})")
            buffer = io.BytesIO()
            _undrawable(name, reason).savefig(buffer, format="png", dpi=100)
        images[name] = buffer.getvalue()
    files = {f"figures/{name}": data for name, data in images.items()}
    files["report.md"] = report.markdown().encode("utf-8")
    files["report.html"] = report.html(images).encode("utf-8")
    return files


def _undrawable(name: str, reason: str) -> Any:
    """A small figure that says why the figure ``name`` could not be drawn."""
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.0, 1.5))
    text = f"{name}: this figure could not be drawn\n({reason[:200]})"
    figure.text(0.5, 0.5, text, ha="center", va="center", wrap=True, fontsize=9)
    return figure


def _version() -> str:
    from . import __version__

    return __version__
