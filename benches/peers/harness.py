"""The harness of the peer comparison: what a case is, how it is checked and timed, the thread
settings of a run, and the text, JSON and Markdown reports.

Timing
------
A case's inputs are built once from ``numpy.random.default_rng(seed)``; our output is checked
against each peer's (:func:`agreement`), then our callable and the peers' are timed on the same
inputs with their repeats interleaved (:func:`measure`), so that a burst of load on a shared
machine hits all of them. A timing is the MINIMUM over the repeats of the mean over an inner
loop, the loop count chosen (as ``timeit`` does) so that one repeat lasts at least ``min_time``
seconds. The ratio is peer time / our time: above 1 means aerocontrol is faster.

Threads
-------
A run either inherits the thread variables of its process (``THREAD_ENV_VARS``) or is started
in a fresh process with them set (:func:`thread_environment`): ``one`` sets all four to 1
before numpy is imported, so that rayon, OpenBLAS, OpenMP and MKL, ours and the peers', use one
thread; ``default`` removes them, so that each library uses every core.
"""

from __future__ import annotations

import datetime
import functools
import inspect
import json
import os
import platform
import re
import subprocess
import sys
import timeit
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

THREAD_ENV_VARS = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "RAYON_NUM_THREADS",
    "MKL_NUM_THREADS",
)

THREAD_SETTINGS = ("one", "default")
"""The thread settings a run can be started with in a fresh process (see the module doc)."""

THREAD_LABELS = {"one": "1 thread", "default": "default threads"}
THREAD_COLUMNS = {"one": "1 thread", "default": "default"}
"""The thread settings as the record's column headers name them."""

RTOL = 1e-10
"""Agreement tolerance: |ours - peer| <= RTOL |peer| + RTOL max|peer| entrywise, the max being
taken per matrix (so entries that are tiny next to the rest of their matrix are compared
normwise, not relatively)."""

Pairs = list[tuple[np.ndarray, np.ndarray]]

REPOSITORY = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------------------------------------
# Case description
# ---------------------------------------------------------------------------------------------


def same(ours: Any, peer: Any) -> Pairs:
    """Default comparison: both outputs are (stacks of) arrays of the same shape."""
    return [(np.asarray(ours), np.asarray(peer))]


def compare_tuple(ours: Any, peer: Any) -> Pairs:
    """Outputs that are tuples of arrays, compared element by element."""
    return [(np.asarray(a), np.asarray(b)) for a, b in zip(ours, peer, strict=True)]


@dataclass(frozen=True)
class Target:
    """A performance goal from an issue, judged on one (case, peer) row.

    ``max_ours`` is a bound in seconds on our time, ``min_ratio`` a bound on peer/ours.
    """

    label: str
    min_ratio: float | None = None
    max_ours: float | None = None

    def met(self, ours: float, ratio: float) -> bool:
        """Whether the measured time and ratio meet the goal."""
        ok = True
        if self.min_ratio is not None:
            ok = ok and ratio >= self.min_ratio
        if self.max_ours is not None:
            ok = ok and ours <= self.max_ours
        return ok


@dataclass(frozen=True)
class Peer:
    """A reference implementation of the same operation, and how to compare its output.

    ``rtol`` replaces RTOL for a peer whose own answer is only that accurate by design (an
    ODE integrator run at a tolerance); the docstring of its case says why.
    """

    name: str
    fn: Callable[..., Any]
    compare: Callable[[Any, Any], Pairs] = same
    target: Target | None = None
    rtol: float = 0.0

    @property
    def tolerance(self) -> float:
        """The agreement tolerance of this peer: ``rtol``, or RTOL when not set."""
        return self.rtol or RTOL


@dataclass(frozen=True)
class Case:
    """One benchmark: an operation at one size, our callable and its peers.

    ``repeat`` overrides the number of repeats for expensive cases (a call of a tenth of a
    second or more); ``None`` uses the run's default.
    """

    op: str
    size: str
    seed: int
    setup: Callable[[np.random.Generator], tuple[Any, ...]]
    ours: Callable[..., Any]
    peers: Sequence[Peer]
    repeat: int | None = None

    @property
    def name(self) -> str:
        """The case's name in the table: operation and size."""
        return f"{self.op} {self.size}".strip()


@dataclass(frozen=True)
class Group:
    """The cases of one operation (or a few related ones), built by ``build``.

    ``name`` is ``module.operation``, the module being the case file (named after the
    aerocontrol module of the operation); its docstring describes the inputs and the peers.
    """

    name: str
    build: Callable[[], list[Case]]

    @property
    def module(self) -> str:
        """The case file the group is defined in."""
        return self.name.split(".", 1)[0]

    @property
    def description(self) -> str:
        """The docstring of the builder, dedented."""
        return inspect.cleandoc(self.build.__doc__ or "")

    @property
    def summary(self) -> str:
        """The first sentence of the description, on one line, cut at 100 characters."""
        first = " ".join(self.description.split("\n\n")[0].split())
        sentence = re.split(r"(?<=[a-z0-9)\]])\. (?=[A-Z])", first)[0].rstrip(".")
        return sentence if len(sentence) <= 100 else sentence[:97].rstrip() + "..."

    def cases(self) -> list[Case]:
        """The group's cases, in the order they run."""
        return self.build()


def group_of(module: str, build: Callable[[], list[Case]]) -> Group:
    """The group of a case builder ``<operation>_cases`` defined in the case file ``module``."""
    name = build.__name__.removesuffix("_cases")
    return Group(f"{module}.{name}", build)


# ---------------------------------------------------------------------------------------------
# Measurement
# ---------------------------------------------------------------------------------------------


def agreement(pairs: Pairs, rtol: float = RTOL) -> tuple[bool, float]:
    """Whether every pair agrees to ``rtol`` (RTOL by default; see its docstring), and the worst
    scaled error."""
    ok = True
    worst = 0.0
    for ours, ref in pairs:
        ours = np.asarray(ours, dtype=float)
        ref = np.asarray(ref, dtype=float)
        if ours.shape != ref.shape:
            return False, float("inf")
        if ref.size == 0:  # two empty results (no uncontrollable eigenvalue found) agree
            continue
        # Per-matrix scale for the absolute part of the tolerance.
        axes = tuple(range(max(ref.ndim - 2, 0), ref.ndim))
        scale = np.max(np.abs(ref), axis=axes, keepdims=True) if ref.ndim else np.abs(ref)
        ok = ok and bool(np.all(np.abs(ours - ref) <= rtol * np.abs(ref) + rtol * scale))
        diff = np.abs(ours - ref)
        bound = np.abs(ref) + scale
        err = np.divide(diff, bound, out=np.where(diff > 0, np.inf, 0.0), where=bound > 0)
        if err.size:
            e = float(np.max(err))
            worst = max(worst, np.inf if np.isnan(e) else e)
    return ok, worst


@dataclass
class Timing:
    """Per-call times of the repeats of one callable, and the inner loop count."""

    number: int = 0
    samples: list[float] = field(default_factory=list)

    @property
    def best(self) -> float:
        """The minimum over repeats of the mean per call."""
        return min(self.samples)


def calibrate(timer: timeit.Timer, min_time: float) -> tuple[int, float]:
    """The inner loop count (1, 2, 5, 10, 20, ...) for which one repeat lasts >= min_time.

    Returns the count and the per-call time of that last trial, which is a valid repeat.
    """
    i = 1
    while True:
        for j in (1, 2, 5):
            number = i * j
            elapsed = timer.timeit(number)
            if elapsed >= min_time:
                return number, elapsed / number
        i *= 10


def measure(fns: Sequence[Callable[[], Any]], repeat: int, min_time: float) -> list[Timing]:
    """Time the callables with their repeats interleaved: ours, peer 1, ..., ours, peer 1, ...

    Interleaving spreads any burst of load from other users of the machine over all of them.
    """
    timers = [timeit.Timer(fn) for fn in fns]
    timings = []
    for timer in timers:
        number, first = calibrate(timer, min_time)
        timings.append(Timing(number, [first]))
    for _ in range(repeat - 1):
        for timer, timing in zip(timers, timings, strict=True):
            timing.samples.append(timer.timeit(timing.number) / timing.number)
    return timings


def run_case(
    case: Case, repeat: int, min_time: float, warn: Callable[[str], None], group: str = ""
) -> list[dict[str, Any]]:
    """Check agreement, then time ``case``; one result record per peer."""
    inputs = case.setup(np.random.default_rng(case.seed))
    ours_out = case.ours(*inputs)
    checks = []
    for peer in case.peers:
        ok, err = agreement(peer.compare(ours_out, peer.fn(*inputs)), peer.tolerance)
        if not ok:
            warn(
                f"WARNING: {case.name}: ours and {peer.name} disagree "
                f"(worst scaled error {err:.3g} > rtol {peer.tolerance:g})"
            )
        checks.append((ok, err))
    fns = [functools.partial(case.ours, *inputs)]
    fns += [functools.partial(peer.fn, *inputs) for peer in case.peers]
    ours, *peers = measure(fns, case.repeat or repeat, min_time)
    records = []
    for peer, timing, (ok, err) in zip(case.peers, peers, checks, strict=True):
        ratio = timing.best / ours.best
        target = peer.target
        records.append(
            {
                "group": group,
                "case": case.name,
                "op": case.op,
                "size": case.size,
                "seed": case.seed,
                "peer": peer.name,
                "ours_s": ours.best,
                "peer_s": timing.best,
                "ratio": ratio,
                "ours_number": ours.number,
                "peer_number": timing.number,
                "repeats": len(ours.samples),
                "agree": ok,
                "max_scaled_error": err,
                "rtol": peer.tolerance,
                "target": target.label if target else None,
                "target_met": target.met(ours.best, ratio) if target else None,
            }
        )
    return records


def case_repeat(case: Case, repeat: int, quick: bool) -> int:
    """The repeats of ``case`` in a run of ``repeat``: its own count if lower, 1 in a quick
    run for the expensive cases that have one."""
    if case.repeat and quick:
        return 1
    return min(case.repeat, repeat) if case.repeat else repeat


def selected_cases(groups: Iterable[Group], name_filter: str = "") -> list[tuple[Group, Case]]:
    """The cases of ``groups`` whose name contains ``name_filter``, in order."""
    return [(group, case) for group in groups for case in group.cases() if name_filter in case.name]


def run(
    groups: Iterable[Group],
    *,
    repeat: int,
    min_time: float,
    quick: bool = False,
    name_filter: str = "",
    warn: Callable[[str], None] = print,
    progress: Callable[[str], None] | None = None,
    env: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Run the selected cases in this process: the run's settings, environment (``env`` if
    given, else read now) and records."""
    cases = selected_cases(groups, name_filter)
    started = now()
    env = environment() if env is None else env
    records: list[dict[str, Any]] = []
    for index, (group, case) in enumerate(cases, 1):
        if progress is not None:
            progress(f"[{index}/{len(cases)}] {group.name}: {case.name}")
        adjusted = replace(case, repeat=case_repeat(case, repeat, quick))
        records.extend(run_case(adjusted, repeat, min_time, warn, group.name))
    return {
        "threads": inherited_threads(),
        "repeat": repeat,
        "min_time": min_time,
        "quick": quick,
        "started": started,
        "finished": now(),
        "loadavg_after": loadavg(),
        "environment": env,
        "records": records,
    }


# ---------------------------------------------------------------------------------------------
# Threads
# ---------------------------------------------------------------------------------------------


def thread_environment(setting: str, base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment of a fresh process that runs with ``setting`` ("one" or "default")."""
    if setting not in THREAD_SETTINGS:
        raise ValueError(f"thread setting must be one of {THREAD_SETTINGS}, got {setting!r}")
    env = {k: v for k, v in (os.environ if base is None else base).items()}
    for name in THREAD_ENV_VARS:
        env.pop(name, None)
        if setting == "one":
            env[name] = "1"
    return env


def inherited_threads() -> str:
    """The thread setting of this process, read from its environment: "one" when every
    variable is 1, "default" when none is set, else "inherited"."""
    values = [os.environ.get(name) for name in THREAD_ENV_VARS]
    if all(v == "1" for v in values):
        return "one"
    if all(v is None for v in values):
        return "default"
    return "inherited"


def run_in_subprocess(command: Sequence[str], setting: str) -> dict[str, Any]:
    """Run ``command`` (a worker that prints one run as JSON on stdout) in a fresh process
    with the thread setting ``setting``; its stderr passes through."""
    done = subprocess.run(
        list(command),
        env=thread_environment(setting),
        stdout=subprocess.PIPE,
        text=True,
        check=True,
    )
    result: dict[str, Any] = json.loads(done.stdout)
    if result["threads"] != setting:
        raise RuntimeError(f"the worker ran with threads {result['threads']!r}, not {setting!r}")
    return result


# ---------------------------------------------------------------------------------------------
# Environment
# ---------------------------------------------------------------------------------------------


def now() -> str:
    """The current UTC time, to the second, ISO 8601."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")


def loadavg() -> list[float] | None:
    """The 1, 5 and 15 minute load averages, where the system has them."""
    return [round(x, 2) for x in os.getloadavg()] if hasattr(os, "getloadavg") else None


def environment() -> dict[str, Any]:
    """Thread settings and versions: what a timing depends on besides the code."""
    import control
    import scipy

    import aerocontrol
    from aerocontrol import _core

    env: dict[str, Any] = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "loadavg": loadavg(),
        "env": {name: os.environ.get(name) for name in THREAD_ENV_VARS},
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "control": control.__version__,
        "aerocontrol": aerocontrol.__version__,
        "FMA_KERNELS": getattr(_core, "FMA_KERNELS", None),
    }
    try:
        from threadpoolctl import threadpool_info  # type: ignore[import-not-found]
    except ImportError:
        env["threadpoolctl"] = None
    else:
        env["threadpoolctl"] = [
            {k: info.get(k) for k in ("user_api", "internal_api", "num_threads", "version")}
            for info in threadpool_info()
        ]
    return env


def _cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo, else what platform knows."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Processor", "cpu model"):
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def _cpu_flags() -> list[str]:
    """The vector instruction sets of /proc/cpuinfo that our kernels or BLAS may use."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "flags":
                    flags = set(value.split())
                    return [f for f in ("avx2", "fma", "avx512f") if f in flags]
    except OSError:
        pass
    return []


def _os_name() -> str:
    """The distribution's name (/etc/os-release) and the kernel, or platform's summary."""
    pretty = ""
    try:
        with open("/etc/os-release", encoding="utf-8") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    pretty = line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    kernel = f"{platform.system()} {platform.release()} {platform.machine()}"
    return f"{pretty}, {kernel}" if pretty else platform.platform()


def _git(*args: str) -> str | None:
    try:
        done = subprocess.run(
            ["git", "-C", str(REPOSITORY), *args],
            capture_output=True,
            text=True,
            check=True,
            timeout=30,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip()


def git_commit() -> str:
    """The commit of this checkout, with "+ uncommitted changes" when the tree differs."""
    commit = _git("log", "-1", "--format=%h (%cs) %s")
    if commit is None:
        return "unknown (not a git checkout)"
    if len(commit) > 90:
        commit = commit[:87].rstrip() + "..."
    dirty = _git("status", "--porcelain", "--untracked-files=no")
    return f"{commit} + uncommitted changes" if dirty else commit


def _blas() -> str:
    """The BLAS numpy was built against, from numpy's build configuration."""
    try:
        config = np.show_config(mode="dicts")  # type: ignore[call-arg]
        blas = config["Build Dependencies"]["blas"]
        return f"{blas.get('name', '?')} {blas.get('version', '')}".strip()
    except Exception:
        return "unknown"


def machine() -> dict[str, Any]:
    """The machine, software and checkout a record was measured on."""
    import control
    import scipy
    import slycot

    import aerocontrol
    from aerocontrol import _core

    return {
        "cpu": _cpu_model(),
        "cpu_flags": _cpu_flags(),
        "cpu_count": os.cpu_count(),
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "os": _os_name(),
        "python": f"{platform.python_version()} ({platform.python_implementation()})",
        "numpy": np.__version__,
        "blas": _blas(),
        "scipy": scipy.__version__,
        "control": control.__version__,
        "slycot": slycot.__version__,
        "aerocontrol": aerocontrol.__version__,
        "FMA_KERNELS": getattr(_core, "FMA_KERNELS", None),
        "commit": git_commit(),
    }


# ---------------------------------------------------------------------------------------------
# Text report
# ---------------------------------------------------------------------------------------------


def format_environment(env: dict[str, Any]) -> str:
    """The header printed above the table."""
    lines = [
        f"python {env['python']} on {env['platform']}",
        f"os.cpu_count() = {env['cpu_count']}, usable cores (affinity) = {env['affinity']}, "
        f"load average = {env['loadavg']}",
    ]
    lines += [f"{name} = {value!r}" for name, value in env["env"].items()]
    if env["threadpoolctl"] is None:
        lines.append("threadpoolctl: not installed")
    else:
        for pool in env["threadpoolctl"]:
            lines.append(
                f"threadpoolctl: {pool['user_api']}/{pool['internal_api']} "
                f"{pool['version']} num_threads={pool['num_threads']}"
            )
    lines.append(f"aerocontrol._core.FMA_KERNELS = {env['FMA_KERNELS']}")
    lines.append(
        f"numpy {env['numpy']}, scipy {env['scipy']}, control {env['control']}, "
        f"aerocontrol {env['aerocontrol']}"
    )
    return "\n".join(lines)


def format_settings(repeat: int, min_time: float, quick: bool) -> str:
    """The line that says how a run times."""
    return (
        f"timing: min over {repeat} repeats of the mean over an inner loop of >= {min_time:g} s"
        f"{' (quick)' if quick else ''}; ratio = peer / ours (> 1: aerocontrol faster)"
    )


def format_time(seconds: float) -> str:
    """A time with a unit that keeps 3-4 significant digits readable."""
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:7.3f} {unit}"
    return f"{seconds / 1e-9:7.1f} ns"


def format_flag(record: dict[str, Any], separator: str = "  ") -> str:
    """PASS or MISS and the target's label, DISAGREE when the peer's answer differs."""
    flag = ""
    if record["target"]:
        flag = f"{'PASS' if record['target_met'] else 'MISS'}{separator}{record['target']}"
    if not record["agree"]:
        flag = f"DISAGREE {flag}".strip()
    return flag


def format_table(records: list[dict[str, Any]]) -> str:
    """The results, one row per (case, peer), then the targets."""
    headers = ("case", "size", "peer", "ours", "peer time", "peer/ours", "target")
    rows = []
    for r in records:
        rows.append(
            (
                r["op"],
                r["size"],
                r["peer"],
                format_time(r["ours_s"]),
                format_time(r["peer_s"]),
                f"{r['ratio']:8.2f}x",
                format_flag(r),
            )
        )
    widths = [max(len(h), *(len(row[i]) for row in rows)) for i, h in enumerate(headers)]
    right = {3, 4, 5}

    def line(cells: Sequence[str]) -> str:
        out = [
            c.rjust(w) if i in right else c.ljust(w)
            for i, (c, w) in enumerate(zip(cells, widths, strict=True))
        ]
        return "  ".join(out).rstrip()

    lines = [line(headers), line(["-" * w for w in widths])]
    lines += [line(row) for row in rows]
    targets = [r for r in records if r["target"]]
    if targets:
        lines.append("")
        lines.append("targets:")
        for r in targets:
            verdict = "PASS" if r["target_met"] else "MISS"
            ours = format_time(r["ours_s"]).strip()
            lines.append(
                f"  {verdict}  {r['target']:<48} ({r['case']}: ours {ours}, ratio {r['ratio']:.2f})"
            )
    return "\n".join(lines)


def format_listing(groups: Iterable[Group]) -> str:
    """Every group, its summary and its cases (name and peers)."""
    lines = []
    for group in groups:
        cases = group.cases()
        count = f"{len(cases)} case{'s' if len(cases) != 1 else ''}"
        lines.append(f"{group.name} ({count}): {group.summary}")
        for case in cases:
            peers = ", ".join(peer.name for peer in case.peers)
            lines.append(f"    {case.name}  [{peers}]")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# Markdown record
# ---------------------------------------------------------------------------------------------


def run_label(run: dict[str, Any]) -> str:
    """How a run's thread setting is named in the record."""
    if run["threads"] in THREAD_LABELS:
        return THREAD_LABELS[run["threads"]]
    env = run["environment"]["env"]
    return "threads: " + ", ".join(f"{k}={v}" for k, v in env.items() if v is not None)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def machine_table(info: dict[str, Any]) -> list[str]:
    """The Markdown table of the machine a record was measured on (:func:`machine`)."""
    affinity = info["affinity"]
    cores = f"{info['cpu_count']} logical (os.cpu_count), {affinity} usable by this process"
    flags = ", ".join(info["cpu_flags"]) or "none of avx2, fma, avx512f"
    rows = [
        ("CPU", f"{info['cpu']} ({flags})"),
        ("cores", cores),
        ("OS", info["os"]),
        ("Python", info["python"]),
        ("numpy", f"{info['numpy']} (BLAS: {info['blas']})"),
        ("scipy", info["scipy"]),
        ("python-control", f"{info['control']} (slycot {info['slycot']})"),
        ("aerocontrol", f"{info['aerocontrol']}, FMA kernels: {info['FMA_KERNELS']}"),
        ("aerocontrol commit", info["commit"]),
    ]
    lines = ["| | |", "| --- | --- |"]
    lines += [f"| {key} | {_cell(str(value))} |" for key, value in rows]
    return lines


def run_lines(runs: Sequence[dict[str, Any]]) -> list[str]:
    """One Markdown bullet per run: its thread setting, start and end, thread variables,
    thread pools and the load average at both ends."""
    lines = []
    for run in runs:
        env = run["environment"]
        threads = ", ".join(f"{k}={v}" for k, v in env["env"].items() if v is not None)
        pools = env.get("threadpoolctl")
        pool_text = (
            "; threadpoolctl: "
            + ", ".join(f"{p['internal_api']} num_threads={p['num_threads']}" for p in pools)
            if pools
            else ""
        )
        lines.append(
            f"- **{run_label(run)}**: {run['started']} to {run['finished']}; "
            f"{threads or 'no thread variable set'}{pool_text}; load average "
            f"{env['loadavg']} at the start, {run['loadavg_after']} at the end."
        )
    return lines


def machine_and_runs(info: dict[str, Any], runs: Sequence[dict[str, Any]]) -> list[str]:
    """The "Machine" and "Runs" sections of a record (performance.md, growth.md)."""
    return ["## Machine", "", *machine_table(info), "", "## Runs", "", *run_lines(runs)]


def _verdict(record: dict[str, Any] | None) -> str:
    if record is None:
        return "-"
    flag = "PASS" if record["target_met"] else "MISS"
    return f"{flag} ({record['ratio']:.2f}x, ours {format_time(record['ours_s']).strip()})"


def format_markdown(
    runs: Sequence[dict[str, Any]],
    groups: Sequence[Group],
    info: dict[str, Any],
    command: str,
) -> str:
    """The performance record: the machine, the runs, and per group a table with, for each
    run, our time, the peer's time and the ratio; then the targets of the issues."""
    if not runs:
        raise ValueError("a record needs at least one run")
    keyed = [{(r["group"], r["case"], r["peer"]): r for r in run["records"]} for run in runs]
    first = runs[0]
    settings = format_settings(first["repeat"], first["min_time"], first["quick"])
    lines = [
        "# Performance record",
        "",
        "aerocontrol against its peers (scipy, python-control with slycot, numpy), timed in one",
        "process on the same seeded inputs after checking that the answers agree. Written by",
        "",
        f"    {command}",
        "",
        "(regenerate it rather than edit it). Absolute times drift with the machine and its load",
        "(these are shared machines): compare ratios, and only within one record.",
        "",
        "The stochastic robustness targets (10^6 Monte Carlo samples, a local Dask cluster,",
        "peak memory) are recorded in [robustness.md](robustness.md), written by",
        "`python benches/robustness.py --markdown docs/robustness.md`.",
        "",
        "How the cost grows with the order n (expm, CARE and a response at n = 4 to 1024)",
        "and with the batch size (1 to 10^6 problems), with log-log plots and the sizes where",
        "ours and the peer cross, is recorded in [growth.md](growth.md), written by",
        "`python benches/growth.py`.",
        "",
        f"{settings[0].upper()}{settings[1:]}.",
        "",
        *machine_and_runs(info, runs),
        "",
        "'1 thread' sets RAYON_NUM_THREADS, OMP_NUM_THREADS, OPENBLAS_NUM_THREADS and",
        "MKL_NUM_THREADS to 1 in a fresh process before numpy is imported, so that ours and the",
        "peers each use one core; 'default threads' unsets them, so that rayon (ours) and the BLAS",
        "(the peers') use every core. With the default threads a multithreaded OpenBLAS on a small",
        "shared machine has been seen to make a peer's call of microseconds (scipy.linalg.expm of",
        "a 4x4 matrix) take milliseconds: a ratio in the hundreds on a small case measures that.",
        "",
        "In the tables, 'target' is PASS or MISS of an issue's performance goal (listed under",
        "Targets) in each run, and DISAGREE marks a row where the answers differ by more than the",
        "tolerance (1e-10, scaled; the group's description says which side is wrong).",
        "",
        "## Results",
    ]
    many = len(runs) > 1
    headers = ["operation", "size", "peer"]
    for run in runs:
        suffix = f", {THREAD_COLUMNS.get(run['threads'], run_label(run))}" if many else ""
        headers += [f"ours{suffix}", f"peer{suffix}", f"peer / ours{suffix}"]
    headers.append("target")
    module = ""
    for group in groups:
        rows = [r for r in first["records"] if r["group"] == group.name]
        if not rows:
            continue
        if group.module != module:
            module = group.module
            lines += ["", f"### {module}"]
        lines += ["", f"#### {group.name}", "", group.description, ""]
        lines.append("| " + " | ".join(headers) + " |")
        lines.append("|" + " --- |" * len(headers))
        for r in rows:
            key = (r["group"], r["case"], r["peer"])
            cells = [r["op"], r["size"], r["peer"]]
            flags = []
            disagree = False
            for table in keyed:
                other = table.get(key)
                if other is None:
                    cells += ["-", "-", "-"]
                    continue
                cells += [
                    format_time(other["ours_s"]).strip(),
                    format_time(other["peer_s"]).strip(),
                    f"{other['ratio']:.2f}x",
                ]
                if other["target"]:
                    flags.append("PASS" if other["target_met"] else "MISS")
                disagree = disagree or not other["agree"]
            flag = " / ".join(flags)
            if disagree:
                flag = f"DISAGREE {flag}".strip()
            cells.append(flag)
            lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    targets = [r for r in first["records"] if r["target"]]
    if targets:
        lines += ["", "## Targets", ""]
        header = ["target", "case", "peer", *(run_label(run) for run in runs)]
        lines.append("| " + " | ".join(header) + " |")
        lines.append("|" + " --- |" * len(header))
        for r in targets:
            key = (r["group"], r["case"], r["peer"])
            cells = [r["target"], r["case"], r["peer"]]
            cells += [_verdict(table.get(key)) for table in keyed]
            lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


def write_text(path: str, text: str) -> None:
    """Write ``text`` to ``path``, or to stdout when path is "-"."""
    if path == "-":
        sys.stdout.write(text)
    else:
        Path(path).write_text(text, encoding="utf-8")
