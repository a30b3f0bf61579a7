"""Side-by-side timings of aerocontrol against its peers (scipy, python-control), in one process.

The cases, the harness and the method are in the package ``benches/peers`` (its docstring
lists what is covered and how to add a case); this is its command line. Run from the
repository root with the package installed::

    python benches/compare_peers.py                  # full run, table
    python benches/compare_peers.py --quick          # smoke run: every case once, a few minutes
    python benches/compare_peers.py --json           # JSON list of result records on stdout
    python benches/compare_peers.py -k expm          # only the cases whose name contains "expm"
    python benches/compare_peers.py --list           # the groups and their cases
    python benches/compare_peers.py --only riccati,linalg.expm   # case files or groups
    python benches/compare_peers.py --threads both --markdown docs/performance.md
                                                     # the performance record

The ratio is peer time / our time: above 1 means aerocontrol is faster. Thread settings matter:
without ``--threads`` the run inherits the shell's (the header prints them);
``--threads one`` runs in a fresh process with RAYON_NUM_THREADS, OMP_NUM_THREADS,
OPENBLAS_NUM_THREADS and MKL_NUM_THREADS set to 1 before numpy is imported, ``--threads
default`` with them unset (every library uses every core), ``--threads both`` does the one
then the other. On small shared machines a multithreaded OpenBLAS has been seen to put a whole
process in a state where scipy.linalg.expm of a 4x4 matrix takes milliseconds (LAPACK inside
scipy's pade_UV_calc); a peer time of that order on a tiny case is that, not a real speed-up.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import peers
from peers import harness


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print a JSON list of records")
    parser.add_argument(
        "--markdown",
        nargs="?",
        const="-",
        metavar="PATH",
        help="write the performance record as Markdown to PATH (stdout without PATH)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="fewer, shorter repeats: a smoke run (< ~60 s)"
    )
    parser.add_argument("-k", "--filter", default="", help="run cases whose name contains this")
    parser.add_argument(
        "--only",
        default="",
        metavar="NAMES",
        help="comma-separated case files (riccati) or groups (riccati.lqr) to run; see --list",
    )
    parser.add_argument(
        "--list", action="store_true", help="list the groups and their cases, run nothing"
    )
    parser.add_argument(
        "--threads",
        choices=("one", "default", "both"),
        help="run in fresh processes with one thread everywhere, the default threads, or both "
        "(without it: in this process, with the threads the environment sets)",
    )
    parser.add_argument("--repeat", type=int, help="repeats per callable (default 7, quick 3)")
    parser.add_argument(
        "--min-time",
        type=float,
        help="minimum seconds per repeat, sets the inner loop (default 0.1, quick 0.01)",
    )
    # A run started by --threads: prints the run (settings, environment, records) as JSON.
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.json and args.markdown == "-":
        parser.error("--json and --markdown without a PATH both print to stdout")
    try:
        args.groups = peers.select(args.only.split(","))
    except ValueError as error:
        parser.error(str(error))
    return args


def worker_command(args: argparse.Namespace, repeat: int, min_time: float) -> list[str]:
    """The command line of one run of ``--threads``."""
    command = [sys.executable, str(Path(__file__).resolve()), "--worker"]
    command += ["--repeat", str(repeat), "--min-time", repr(min_time)]
    command += [f"--filter={args.filter}", f"--only={args.only}"]
    if args.quick:
        command.append("--quick")
    return command


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    if args.list:
        print(harness.format_listing(args.groups))
        return 0
    if not harness.selected_cases(args.groups, args.filter):
        print(f"no case's name contains {args.filter!r} (see --list)", file=sys.stderr)
        return 2
    repeat = args.repeat or (3 if args.quick else 7)
    min_time = args.min_time if args.min_time is not None else (0.01 if args.quick else 0.1)
    # When stdout carries records (JSON, Markdown, a worker's run) the header and warnings go
    # to stderr.
    quiet = args.json or args.markdown == "-" or args.worker
    info = sys.stderr if quiet else sys.stdout

    def warn(message: str) -> None:
        print(message, file=info, flush=True)

    runs: list[dict[str, Any]]
    if args.threads:
        settings = harness.THREAD_SETTINGS if args.threads == "both" else (args.threads,)
        runs = []
        for setting in settings:
            print(f"== {harness.THREAD_LABELS[setting]}: a fresh process", file=sys.stderr)
            command = worker_command(args, repeat, min_time)
            runs.append(harness.run_in_subprocess(command, setting))
    else:
        env = harness.environment()
        print(harness.format_environment(env), file=info)
        print(harness.format_settings(repeat, min_time, args.quick) + "\n", file=info, flush=True)
        run = harness.run(
            args.groups,
            repeat=repeat,
            min_time=min_time,
            quick=args.quick,
            name_filter=args.filter,
            warn=warn,
            progress=warn if args.worker else None,
            env=env,
        )
        if args.worker:
            print(json.dumps(run))
            return 0
        runs = [run]

    if args.markdown:
        words = sys.argv[1:] if argv is None else list(argv)
        command = shlex.join(["python", "benches/compare_peers.py", *words])
        record = harness.format_markdown(runs, args.groups, harness.machine(), command)
        harness.write_text(args.markdown, record)
        if args.markdown != "-":
            print(f"wrote {args.markdown}", file=sys.stderr)
    if args.json:
        records = [r for run in runs for r in run["records"]]
        if len(runs) > 1:
            records = [{**r, "threads": run["threads"]} for run in runs for r in run["records"]]
        print(json.dumps(records, indent=1))
    elif args.markdown != "-":
        for run in runs:
            if args.threads:
                print(f"== {harness.run_label(run)}, {run['started']} to {run['finished']}")
                print(harness.format_environment(run["environment"]))
                print(harness.format_settings(run["repeat"], run["min_time"], run["quick"]))
                print()
            print(harness.format_table(run["records"]))
            if len(runs) > 1:
                print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
