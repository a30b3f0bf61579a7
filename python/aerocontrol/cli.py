"""The ``aerocontrol`` command (also ``python -m aerocontrol``).

=====================================  ======================================================
``aerocontrol``                        the report on the embedded 747 into ./aerocontrol-report
``aerocontrol report [AIRCRAFT]``      the report on a shipped aircraft or a TOML file
``--out DIR [--force]``                (default ./aerocontrol-report; see ``report --help``)
``aerocontrol aircraft``               the shipped aircraft
``aerocontrol modes AIRCRAFT``         the modes and their MIL-F-8785C Levels
``aerocontrol check FILE.toml``        every problem of an aircraft file (key, line, hint),
                                       or its modes and Levels if it is valid
``aerocontrol schema``                 the JSON Schema of the aircraft file (draft 2020-12)
``aerocontrol lqr AIRCRAFT --c 1.0``   the lateral (or ``--axis longitudinal``) regulator
``aerocontrol damper AIRCRAFT``        a yaw (or ``--loop pitch``) damper and its margins
``aerocontrol --debug COMMAND ...``    a traceback instead of the one-line error
=====================================  ======================================================

Every error, whatever its kind, is one line on standard error, ``aerocontrol: error: ...``,
and exit status 2 for a usage error (a bad option or option value) or 1 for the rest (an
unknown aircraft, a file that cannot be read or does not validate, an output folder that
cannot be used, a problem the mathematics cannot solve, and any unexpected error, which says
so); ``--debug`` prints the traceback instead. Ctrl-C (SIGINT) ends the command with
``aerocontrol: interrupted`` and status 130, SIGTERM and SIGHUP with ``aerocontrol:
terminated`` and 128 + the signal number; a report in progress is undone first. Warnings are
one line each, ``aerocontrol: warning: ...``.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import signal
import sys
import threading
import traceback
import warnings
from collections.abc import Iterator, Sequence
from types import FrameType
from typing import Any, NoReturn

import numpy as np

from . import __version__, handling
from .aircraft.keys import schema_text
from .aircraft.model import Aircraft, available, load, problems
from .aircraft.naming import classify_modes, name_modes
from .aircraft.schema import AircraftDataError
from .exceptions import AerocontrolError
from .modal import modes
from .riccati import solve_care

DEFAULT_AIRCRAFT = "b747-approach"
DEFAULT_OUT = "aerocontrol-report"
#: The weights c that ``lqr --c`` accepts: R = I/c^2 then lies within 1e-16 to 1e16 of Q = I,
#: the range of double precision; beyond it the regulator has no meaning in floating point.
C_RANGE = (1e-8, 1e8)

REPORT_DESCRIPTION = """\
The models, modes and handling-quality Levels, responses, the Dutch-roll damper, the lateral
regulator with its root locus and critical c, and the Levels after augmentation, written into
DIR as report.html (self-contained), report.md and figures/*.png, with the manifest
.aerocontrol-report.json listing each of these files with its size and SHA-256.

The report never deletes, renames or overwrites a file it did not write:
  - a new or empty DIR is used (missing parent folders are created);
  - a DIR holding an earlier report (its manifest) is replaced if every file the manifest
    lists is unchanged or deleted, so running the same command again just works; files the
    manifest does not list (your notes, your images in figures/) are never touched, and a
    listed file you changed stops the run with its name (move it away first);
  - a DIR that is not empty and holds no manifest is refused, unless --force: then the
    report is written beside the files there, and a file in its way (your own report.md)
    stops the run with its name;
  - symbolic links inside DIR are never written through (DIR itself may be one);
  - on an error, Ctrl-C or SIGTERM the run is undone: nothing half-written, the earlier
    report as it was, no staging folder, no folders left that the run created.
"""


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
    debug_help = "on an error, print the traceback instead of the one-line message"
    parser.add_argument("--debug", action="store_true", help=debug_help)
    # --debug also after the command; SUPPRESS keeps the top level's value when it is absent.
    common = _Parser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=debug_help)
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    aircraft_help = (
        f"a shipped aircraft (see 'aerocontrol aircraft') or a TOML file; "
        f"default {DEFAULT_AIRCRAFT}"
    )

    report = commands.add_parser(
        "report",
        parents=[common],
        help="write the report of the chapter's analyses (HTML, Markdown, PNG figures)",
        description=REPORT_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    report.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)
    report.add_argument(
        "--out",
        default=DEFAULT_OUT,
        metavar="DIR",
        help=f"output folder (default {DEFAULT_OUT}); run again to replace its report",
    )
    report.add_argument(
        "--force",
        action="store_true",
        help="also write into a non-empty folder that holds no earlier report, beside its "
        "files (none of them is ever replaced)",
    )

    commands.add_parser(
        "aircraft",
        parents=[common],
        help="list the shipped aircraft",
        description="The shipped aircraft: identifier and description.",
    )

    modes_command = commands.add_parser(
        "modes",
        parents=[common],
        help="the modes of an aircraft and their MIL-F-8785C Levels",
        description="The longitudinal and lateral-directional modes and their Levels.",
    )
    modes_command.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)

    check = commands.add_parser(
        "check",
        parents=[common],
        help="validate an aircraft file: every problem, or its modes and Levels",
        description="Reads an aircraft file and prints every problem, one a line: "
        "FILE:LINE: KEY: what is wrong (hint: how to mend it), with exit status 1; a valid "
        "file prints its flight condition, its modes and their MIL-F-8785C Levels (as "
        "'aerocontrol modes'). A file that is not valid TOML has one problem, where the "
        "parser stopped.",
    )
    check.add_argument("aircraft", metavar="FILE.toml", help=aircraft_help)

    commands.add_parser(
        "schema",
        parents=[common],
        help="print the JSON Schema of the aircraft file (for editors)",
        description="The JSON Schema (draft 2020-12) of the aircraft file, generated from the "
        "reader's definitions: every key with its unit, sign convention and description, "
        "which keys are required and the plausible ranges. The same text ships as "
        "aerocontrol/aircraft/aircraft.schema.json.",
    )

    lqr = commands.add_parser(
        "lqr",
        parents=[common],
        help="the optimal regulator of an aircraft for a weight c",
        description="LQR with Q = I and R = I/c^2 (the chapter's (6.224)-(6.227)): the gain, "
        "the closed-loop modes, the Riccati residual and the Levels.",
    )
    lqr.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)
    lqr.add_argument(
        "--c",
        type=float,
        default=1.0,
        help=f"control weight c, from {C_RANGE[0]:g} to {C_RANGE[1]:g} (default 1.0): R = I/c^2",
    )
    lqr.add_argument(
        "--axis",
        choices=("lateral", "longitudinal"),
        default="lateral",
        help="which model (default lateral, with rudder and aileron)",
    )

    damper = commands.add_parser(
        "damper",
        parents=[common],
        help="a yaw or pitch damper designed on the root locus, and its margins",
        description="A rate damper through a first-order actuator (and, for yaw, a washout) "
        "at the gain of best damping; its loop's transfer function, margins against "
        "MIL-F-9490D (Table I as widely quoted, every cell unverified) and closed-loop modes.",
    )
    damper.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)
    damper.add_argument(
        "--loop",
        choices=("yaw", "pitch"),
        default="yaw",
        help="yaw: yaw rate to rudder with a washout; pitch: pitch rate to elevator",
    )
    damper.add_argument(
        "--washout",
        type=float,
        default=None,
        metavar="TAU",
        help="the yaw damper's washout time constant in seconds (default 3; 0 for none)",
    )
    robustness = commands.add_parser(
        "robustness",
        parents=[common],
        help="the probability of instability and of each Level under uncertain derivatives",
        description="Stochastic robustness by Monte Carlo (Stengel and Ray, 1991): draws the "
        "uncertain parameters (the aircraft file's [uncertainty] table, else every derivative "
        "of the model with a relative normal scatter of --sigma), judges each sample's modes "
        "against MIL-F-8785C, open loop and with the --controller, and prints the "
        "probabilities with their 95 %% Clopper-Pearson intervals and the parameters the "
        "failures depend on most. The same --seed gives the same numbers on any machine or "
        "cluster.",
    )
    robustness.add_argument("aircraft", nargs="?", default=DEFAULT_AIRCRAFT, help=aircraft_help)
    robustness.add_argument(
        "--samples", type=int, default=100_000, help="number of samples (default 100000)"
    )
    robustness.add_argument(
        "--axis", choices=("lateral", "longitudinal"), default="lateral", help="which model"
    )
    robustness.add_argument(
        "--controller",
        choices=("none", "damper", "lqr"),
        default="none",
        help="none; damper: the chapter's Dutch roll damper (6.156), fixed gains (lateral); "
        "lqr: the regulator with Q = I, R = I/c^2 re-designed for every sample",
    )
    robustness.add_argument(
        "--c", type=float, default=1.0, help="the regulator's weight c (default 1.0)"
    )
    robustness.add_argument(
        "--sigma",
        type=float,
        default=0.15,
        help="relative standard deviation of every derivative when the file has no "
        "[uncertainty] table (default 0.15)",
    )
    robustness.add_argument("--seed", type=int, default=0, help="the root seed (default 0)")
    robustness.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="run the chunks on the Dask cluster at this scheduler address "
        "(pip install aerocontrol[distributed])",
    )
    robustness.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="also write the page with the plots into this folder (report.html, report.md, "
        "figures/), under the rules of 'aerocontrol report'",
    )
    robustness.add_argument(
        "--force",
        action="store_true",
        help="with --out: also write into a non-empty folder that holds no earlier report, "
        "beside its files (none of them is ever replaced)",
    )
    return parser


def _robustness(arguments: argparse.Namespace) -> int:
    import time

    from .aircraft.tables import LATERAL_DERIVATIVES, LONGITUDINAL_DERIVATIVES
    from .design import dutch_roll_damper
    from .report.build import write_document
    from .report.document import Report
    from .report.robustness import robustness_report
    from .robustness import MAX_SAMPLES, Lqr, Normal, Uncertainty, monte_carlo

    if not 0 < arguments.samples <= MAX_SAMPLES:
        raise _UsageError(
            f"--samples must be a positive number up to {MAX_SAMPLES:.0e}, got {arguments.samples}"
        )
    if arguments.seed < 0:
        raise _UsageError(f"--seed must be >= 0, got {arguments.seed}")
    sigma, c = arguments.sigma, arguments.c
    if not (math.isfinite(sigma) and sigma >= 0):
        raise _UsageError(f"--sigma must be a number >= 0, got {sigma:g}")
    if not (math.isfinite(c) and C_RANGE[0] <= c <= C_RANGE[1]):
        raise _UsageError(f"--c must lie between {C_RANGE[0]:g} and {C_RANGE[1]:g}, got {c:g}")
    if arguments.controller == "damper" and arguments.axis != "lateral":
        raise _UsageError("--controller damper is the lateral Dutch roll damper")
    plane = load(arguments.aircraft)
    if plane.uncertainty:
        uncertainty = Uncertainty.of(plane)
    else:
        names = LATERAL_DERIVATIVES if arguments.axis == "lateral" else LONGITUDINAL_DERIVATIVES
        # Derivatives the file gives as 0 have no relative scatter: left out.
        uncertainty = Uncertainty(
            {name: Normal(sigma) for name in names if plane.derivatives[name] != 0.0}
        )
    controller: Any = None
    if arguments.controller == "damper":
        controller = np.vstack([dutch_roll_damper(plane).k, np.zeros(4)])
    elif arguments.controller == "lqr":
        controller = Lqr(c)
    client: Any = None
    if arguments.scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise _UsageError(
                "--scheduler needs Dask: pip install aerocontrol[distributed]"
            ) from None
        client = Client(arguments.scheduler)  # type: ignore[no-untyped-call]  # (untyped package)
    start = time.perf_counter()
    show = sys.stderr.isatty()

    def progress(done: int, total: int) -> None:
        if not show:
            return
        elapsed = time.perf_counter() - start
        rate = done / elapsed if elapsed > 0 else 0.0
        left = (total - done) / rate if rate > 0 else 0.0
        bar = "#" * (30 * done // total)
        print(
            f"\r[{bar:<30}] {done}/{total} samples, {rate:,.0f}/s, {left:.0f} s left",
            end="",
            file=sys.stderr,
            flush=True,
        )

    def run(_: object = None) -> Report:
        print(plane.summary())
        try:
            result = monte_carlo(
                plane,
                uncertainty,
                arguments.samples,
                controller,
                axis=arguments.axis,
                seed=arguments.seed,
                client=client,
                progress=progress,
            )
        finally:
            if client is not None:
                client.close()
        if show:
            print(file=sys.stderr)
        elapsed = time.perf_counter() - start
        print(f"\n{result}")
        print(f"\n{result.samples} samples in {elapsed:.1f} s")
        title = f"aerocontrol {__version__}: stochastic robustness of {plane.name}"
        return robustness_report(result, uncertainty, title)

    if arguments.out is None:
        run()
    else:
        path = write_document(run, arguments.out, print, force=arguments.force)
        print(f"report: {path}")
    return 0


def _damper(arguments: argparse.Namespace) -> int:
    from .design import DAMPER_WASHOUT, pitch_damper, yaw_damper
    from .transfer import transfer_function

    tau = arguments.washout
    if tau is not None and not (math.isfinite(tau) and tau >= 0):
        raise _UsageError(f"--washout must be a non-negative number of seconds, got {tau:g}")
    if tau is not None and arguments.loop == "pitch":
        raise _UsageError("--washout applies to the yaw damper only")
    plane = load(arguments.aircraft)
    if arguments.loop == "yaw":
        washout_tau = DAMPER_WASHOUT if tau is None else (tau or None)
        design = yaw_damper(plane, washout_tau=washout_tau)
    else:
        design = pitch_damper(plane)
    print(plane.summary())
    filters = f", washout {design.washout:g} s" if design.washout else ""
    print(f"\n{design.name}{filters}: gain k = {design.design.gain:.5g}")
    print(f"loop L(s) at k = 1: {transfer_function(design.loop).aircraft_form()}")
    print(f"\nmargins of k L (negative feedback)\n{design.margins.table()}")
    print(f"\n{design.check.table()}")
    print("\nopen-loop modes (with the actuator)")
    print(modes(design.open_loop).table())
    print("\nclosed-loop modes")
    print(modes(design.closed_loop).table())
    return 0


def _report(arguments: argparse.Namespace) -> int:
    from .report import write_report

    path = write_report(arguments.aircraft, arguments.out, progress=print, force=arguments.force)
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


def _problem_line(problem: AircraftDataError) -> str:
    """One problem of ``check`` on one line: FILE:LINE: KEY: message (hint: ...)."""
    message = str(problem)
    origin, _, body = message.partition(": ")
    if not body:
        origin, body = "", message
    where = f"{origin}:{problem.line}" if problem.line is not None else origin
    key = f"{problem.key}: " if problem.key else ""
    hint = f" (hint: {problem.hint})" if problem.hint else ""
    return _one_line(f"{where}: {key}{body}{hint}" if where else f"{key}{body}{hint}")


def _check(arguments: argparse.Namespace) -> int:
    found = problems(arguments.aircraft)
    if found:
        for problem in found:
            print(_problem_line(problem))
        count = len(found)
        print(f"{count} problem{'s' if count > 1 else ''}")
        return 1
    return _modes(arguments)


def _schema(_: argparse.Namespace) -> int:
    sys.stdout.write(schema_text())
    return 0


def _lqr(arguments: argparse.Namespace) -> int:
    c = arguments.c
    if not (math.isfinite(c) and c > 0):
        raise _UsageError(f"--c must be a positive number, got {c:g}")
    if not C_RANGE[0] <= c <= C_RANGE[1]:
        raise _UsageError(
            f"--c must lie between {C_RANGE[0]:g} and {C_RANGE[1]:g} (R = I/c^2 within the "
            f"range of double precision of Q = I), got {c:g}"
        )
    plane = load(arguments.aircraft)
    sys_ = plane.lateral() if arguments.axis == "lateral" else plane.longitudinal()
    R = np.eye(sys_.n_inputs) / (c * c)
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


class _Terminated(BaseException):
    """SIGTERM or SIGHUP arrived: raised in the main thread so that work in progress (a report
    being written) is undone before the command ends."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


_COMMANDS = {
    "report": _report,
    "aircraft": _aircraft,
    "modes": _modes,
    "check": _check,
    "schema": _schema,
    "lqr": _lqr,
    "damper": _damper,
    "robustness": _robustness,
}
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u200e\u200f\u2028-\u202e\u2066-\u2069]")


def _one_line(text: str) -> str:
    """``text`` on one line: control characters (a newline in a file name, say) escaped."""
    return _CONTROL.sub(lambda match: repr(match.group())[1:-1], text.strip())


def _message(error: BaseException) -> str:
    """The one-line message of an error: its own text for the errors aerocontrol expects
    (its exceptions, the operating system's), the type and a pointer to --debug for the rest."""
    text = _one_line(str(error))
    if isinstance(error, (AerocontrolError, OSError, Warning)) and text:
        return text
    if isinstance(error, MemoryError):
        return f"out of memory ({text or 'no detail'})"
    kind = type(error).__name__
    detail = f"{kind}: {text}" if text else kind
    return f"unexpected error ({detail}); run 'aerocontrol --debug ...' for the traceback"


def _on_signal(signum: int, frame: FrameType | None) -> None:
    raise _Terminated(signum)


@contextlib.contextmanager
def _termination_raises() -> Iterator[None]:
    """SIGTERM and SIGHUP raise _Terminated while the command runs (main thread only, and
    only where the signal still has its default action: an ignored SIGHUP stays ignored)."""
    installed: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for name in ("SIGTERM", "SIGHUP"):
            number = getattr(signal, name, None)
            if number is not None and signal.getsignal(number) == signal.SIG_DFL:
                installed[number] = signal.signal(number, _on_signal)
    try:
        yield
    finally:
        for number, previous in installed.items():
            signal.signal(number, previous)


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    print(f"aerocontrol: warning: {_one_line(str(message))}", file=sys.stderr)


def _error(text: str) -> None:
    with contextlib.suppress(OSError, ValueError):
        print(f"aerocontrol: {text}", file=sys.stderr)
        sys.stderr.flush()


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``aerocontrol`` command; returns the exit status.

    Every exception ends in one line on standard error and a non-zero status (2 for usage
    errors, 1 for the rest, 130 for Ctrl-C, 128 + n for signal n); with ``--debug``, the
    traceback is printed instead of the line.
    """
    debug = False
    try:
        with _termination_raises(), warnings.catch_warnings():
            warnings.showwarning = _show_warning
            parser = _parser()
            arguments = parser.parse_args(argv)
            debug = arguments.debug
            if arguments.command is None:
                arguments = parser.parse_args(["report"])
                arguments.debug = debug
            return _COMMANDS[arguments.command](arguments)
    except SystemExit:
        raise  # argparse: --help, --version and usage errors (status 2, one line)
    except BaseException as error:
        if debug:
            traceback.print_exc()
        if isinstance(error, _UsageError):
            if not debug:
                _error(f"error: {_one_line(str(error))} (see aerocontrol --help)")
            return 2
        if isinstance(error, KeyboardInterrupt):
            _error("interrupted")
            return 130
        if isinstance(error, _Terminated):
            _error("terminated")
            return 128 + error.signum
        if isinstance(error, BrokenPipeError):
            # The reader of standard output went away (``aerocontrol aircraft | head -1``):
            # nothing more to say to it; keep Python from complaining at exit.
            with contextlib.suppress(OSError, ValueError):
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, sys.stdout.fileno())
            return 1
        if not debug:
            _error(f"error: {_message(error)}")
        return 1
