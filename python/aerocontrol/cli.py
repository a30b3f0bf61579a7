"""The ``aerocontrol`` command (also ``python -m aerocontrol``).

=====================================  ======================================================
``aerocontrol``                        the report on the embedded 747 into ./aerocontrol-report
``aerocontrol report [AIRCRAFT]``      the report on a shipped aircraft or a TOML file
``--out DIR``                          (default ./aerocontrol-report)
``aerocontrol aircraft``               the shipped aircraft
``aerocontrol modes AIRCRAFT``         the modes and their MIL-F-8785C Levels
``aerocontrol lqr AIRCRAFT --c 1.0``   the lateral (or ``--axis longitudinal``) regulator
=====================================  ======================================================

A bad argument, an unknown aircraft, a file that does not validate or an output folder that
cannot be written gives one line on standard error and exit status 2 (usage) or 1 (the
rest), never a traceback; a report that fails is not left half-written.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from typing import NoReturn

import numpy as np

from . import __version__, handling
from .aircraft.model import Aircraft, available, load
from .aircraft.naming import classify_modes, name_modes
from .exceptions import AerocontrolError
from .modal import modes
from .riccati import solve_care

DEFAULT_AIRCRAFT = "b747-approach"
DEFAULT_OUT = "aerocontrol-report"


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: the message and where to find the usage."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="aerocontrol",
        description="Linear control of flight vehicles. Without a command, writes the report of "
        "the course chapter's analyses on the embedded Boeing 747 into ./aerocontrol-report.",
    )
    parser.add_argument("--version", action="version", version=f"aerocontrol {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    aircraft_help = (
        f"a shipped aircraft (see 'aerocontrol aircraft') or a TOML file; "
        f"default {DEFAULT_AIRCRAFT}"
    )

    report = commands.add_parser(
        "report",
        help="write the report of the chapter's analyses (HTML, Markdown, PNG figures)",
        description="The models, modes and handling-quality Levels, responses, the Dutch-roll "
        "damper, the lateral regulator with its root locus and critical c, and the Levels "
        "after augmentation, written as report.html, report.md and figures/*.png.",
    )
    report.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)
    report.add_argument(
        "--out", default=DEFAULT_OUT, metavar="DIR", help=f"output folder (default {DEFAULT_OUT})"
    )

    commands.add_parser(
        "aircraft",
        help="list the shipped aircraft",
        description="The shipped aircraft: identifier and description.",
    )

    modes_command = commands.add_parser(
        "modes",
        help="the modes of an aircraft and their MIL-F-8785C Levels",
        description="The longitudinal and lateral-directional modes and their Levels.",
    )
    modes_command.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)

    lqr = commands.add_parser(
        "lqr",
        help="the optimal regulator of an aircraft for a weight c",
        description="LQR with Q = I and R = I/c^2 (the chapter's (6.224)-(6.227)): the gain, "
        "the closed-loop modes, the Riccati residual and the Levels.",
    )
    lqr.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)
    lqr.add_argument(
        "--c", type=float, default=1.0, help="control weight c > 0 (default 1.0): R = I/c^2"
    )
    lqr.add_argument(
        "--axis",
        choices=("lateral", "longitudinal"),
        default="lateral",
        help="which model (default lateral, with rudder and aileron)",
    )
    return parser


def _report(arguments: argparse.Namespace) -> int:
    from .report import write_report

    path = write_report(arguments.aircraft, arguments.out, progress=print)
    print(f"report: {path}")
    return 0


def _aircraft(_: argparse.Namespace) -> int:
    for identifier in available():
        plane = load(identifier)
        marker = " (default)" if identifier == DEFAULT_AIRCRAFT else ""
        print(f"{identifier:<16} {plane.name}{marker}")
        print(f"{'':<16} {plane.description}")
    return 0


def _levels(plane: Aircraft) -> handling.HandlingQualities:
    named = {
        **classify_modes(plane.modes("longitudinal"), "longitudinal"),
        **classify_modes(plane.modes("lateral"), "lateral"),
    }
    return handling.assess(named, plane.aircraft_class, plane.category)


def _modes(arguments: argparse.Namespace) -> int:
    plane = load(arguments.aircraft)
    print(plane.summary())
    for axis in ("longitudinal", "lateral"):
        print(f"\n{axis} modes")
        print(plane.modes(axis).table())
    print()
    print(_levels(plane).table())
    return 0


def _lqr(arguments: argparse.Namespace) -> int:
    c = arguments.c
    if not (math.isfinite(c) and c > 0):
        raise _UsageError(f"--c must be a positive number, got {c:g}")
    plane = load(arguments.aircraft)
    sys_ = plane.lateral() if arguments.axis == "lateral" else plane.longitudinal()
    R = np.eye(sys_.n_inputs) / c**2
    solution = solve_care(sys_.A, sys_.B, np.eye(sys_.n_states), R)
    print(plane.summary())
    print(f"\n{arguments.axis} regulator: Q = I, R = I/c^2 with c = {c:g} (6.224)-(6.227)")
    print(f"states {', '.join(sys_.state_names)}; inputs {', '.join(sys_.input_names)}")
    print("gain K (eta = -K x):")
    for name, row in zip(sys_.input_names, solution.K, strict=True):
        print(f"  {name:<9}" + "".join(f"{value:+12.5f}" for value in row))
    print(f"Riccati relative residual {solution.residual:.1e}, rcond(U11) {solution.rcond:.1e}")
    closed_loop = sys_.A - sys_.B @ solution.K
    names = name_modes(modes(closed_loop), arguments.axis)
    print("\nclosed-loop modes")
    print(modes(closed_loop, mode_names=list(names)).table())
    named = classify_modes(modes(closed_loop), arguments.axis)
    print()
    print(handling.assess(named, plane.aircraft_class, plane.category).table())
    return 0


class _UsageError(Exception):
    """A bad option value found after parsing: reported like argparse's own errors."""


_COMMANDS = {"report": _report, "aircraft": _aircraft, "modes": _modes, "lqr": _lqr}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``aerocontrol`` command; returns the exit status."""
    parser = _parser()
    arguments = parser.parse_args(argv)
    if arguments.command is None:
        arguments = parser.parse_args(["report"])
    try:
        return _COMMANDS[arguments.command](arguments)
    except _UsageError as error:
        print(f"aerocontrol: error: {error} (see aerocontrol --help)", file=sys.stderr)
        return 2
    except (AerocontrolError, OSError) as error:
        print(f"aerocontrol: error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("aerocontrol: interrupted", file=sys.stderr)
        return 130
