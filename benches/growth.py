"""How cost grows with size: the order n of one problem and the number k of problems in a batch,
ours against the peer, on log-log plots (issue 26).

Run from the repository root with the package installed::

    python benches/growth.py                  # the record: docs/growth.md and its two plots
    python benches/growth.py --json           # also print the measurements as one JSON object
    python benches/growth.py --threads one    # one thread setting only
    python benches/growth.py --quick --markdown /tmp/g.md --size-plot /tmp/s.png \\
        --batch-plot /tmp/b.png               # smoke run: n = 4, 8 and k = 1, 10

What is measured
----------------
(a) Against the order n = 4, 8, 16, ..., 1024, on the random stable plant of
    ``peers.inputs.stable_plant`` drawn from ``numpy.random.default_rng(n)``: A = G / sqrt(n) -
    3/2 I (spectrum in a disc of radius about 1 centred at -3/2), B standard normal n x 2, then
    x0 standard normal. The same A serves the three operations:

    - ``aerocontrol.expm(A)`` against ``scipy.linalg.expm(A)``;
    - ``aerocontrol.solve_care(A, B, I, I)`` (X and K) against
      ``scipy.linalg.solve_continuous_are(A, B, I, I)`` plus the gain K = R^-1 B^T X;
    - ``aerocontrol.initial_response((A, B), x0, T=t)`` (C = I) against
      ``scipy.signal.lsim`` with a zero input from x0, t = 201 times on [0, 20] s (200 steps).

(b) Against the batch size k = 1, 10, 100, ..., 10^6 of 4 x 4 problems, the first k of one
    stack drawn from ``default_rng(0)`` (the n = 4 plant above, drawn as a stack: A_i = G_i / 2
    - 3/2 I, B_i standard normal 4 x 2, Q = I and R = I shared):

    - ``aerocontrol.expm`` of the (k, 4, 4) stack against a Python loop of
      ``scipy.linalg.expm``;
    - ``aerocontrol.batch.solve_care_batch`` (X and K) against a Python loop of
      ``scipy.linalg.solve_continuous_are`` and the gains.

Each thread setting runs in a fresh process (``--threads``): "one" sets RAYON_NUM_THREADS,
OMP_NUM_THREADS, OPENBLAS_NUM_THREADS and MKL_NUM_THREADS to 1 before numpy is imported,
"default" unsets them (ours and the BLAS under the peer use every core).

How a cell is timed
-------------------
Ours and the peer are first called once each (a warm-up), and their answers compared with the
peer harness's ``agreement`` (1e-10, scaled per matrix). The warm-up's duration t sets the
repeats: 5 when t < 0.1 s, 3 when t < 1 s, 2 when t < 10 s, else 1 (of the slower of the two,
as their repeats are interleaved). The time is then the peer harness's ``measure``: the minimum
over the repeats of the mean over an inner loop of at least ``--min-time`` seconds.

A size is not run when the time predicted from the previous size (its time times
(n' / n)^3, or (k' / k) for a batch) exceeds the limit: 60 s for one call (the peer's CARE at
n = 1024 predicts minutes), 2.5 s for the peer's Python loop (so the loop is timed up to about
2 s). Such a cell is marked "not run" and nothing is extrapolated into it.

Reported
--------
Per operation and thread setting: the times, ours / n^3 (or per problem), the ratio peer /
ours, the log-log slope from the previous size, and least-squares slopes over all sizes and
over the largest three; where the ratio crosses 1 (log-log interpolated n or k). The Markdown
record (``--markdown``), the two PNG plots (``--size-plot``, ``--batch-plot``) and, with
``--json``, the measurements on stdout. On a shared machine the times carry the load of
other users: the record gives the load average at the start and end of each run.
"""

from __future__ import annotations

import argparse
import functools
import itertools
import json
import math
import os
import shlex
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from peers import harness
from peers.inputs import identity_outputs, stable_plant

ORDERS = (4, 8, 16, 32, 64, 128, 256, 512, 1024)
BATCH_SIZES = tuple(10**p for p in range(7))
QUICK_ORDERS = (4, 8)
QUICK_BATCH_SIZES = (1, 10)

STEPS = 200
"""Steps of the response's time grid (STEPS + 1 times on [0, 20] s)."""

CALL_LIMIT_S = 60.0
"""A call predicted to take longer than this (from the previous size) is not run."""
LOOP_LIMIT_S = 2.5
"""A peer's Python loop over a batch predicted to take longer than this is not run."""

DEFAULT_MARKDOWN = "docs/growth.md"
DEFAULT_SIZE_PLOT = "docs/growth-size.png"
DEFAULT_BATCH_PLOT = "docs/growth-batch.png"

THREAD_STYLE = {"one": "-", "default": "--"}
"""The line style of each thread setting on the plots."""


def repeats_for(seconds: float) -> int:
    """The repeats of a cell whose warm-up call took ``seconds`` (see the module doc)."""
    if seconds < 0.1:
        return 5
    if seconds < 1.0:
        return 3
    if seconds < 10.0:
        return 2
    return 1


# ---------------------------------------------------------------------------------------------
# Operations
# ---------------------------------------------------------------------------------------------


def _care_ours(A: Any, B: Any, Q: Any, R: Any) -> Any:
    import aerocontrol

    solution = aerocontrol.solve_care(A, B, Q, R)
    return solution.X, solution.K


def _care_scipy(A: Any, B: Any, Q: Any, R: Any) -> Any:
    import scipy.linalg

    X = scipy.linalg.solve_continuous_are(A, B, Q, R)
    return X, np.linalg.solve(R, B.T @ X)


def _initial_ours(A: Any, B: Any, t: Any, x0: Any) -> Any:
    import aerocontrol

    return aerocontrol.initial_response((A, B), x0, T=t).y


def _initial_lsim(A: Any, B: Any, t: Any, x0: Any) -> Any:
    import scipy.signal

    u = np.zeros((len(t), B.shape[1]))
    return scipy.signal.lsim((A, B, *identity_outputs(A, B)), u, t, X0=x0)[1]


def _expm_loop(stack: Any) -> Any:
    import scipy.linalg

    return [scipy.linalg.expm(a) for a in stack]


def _care_batch_ours(A: Any, B: Any, Q: Any, R: Any) -> Any:
    import aerocontrol

    batch = aerocontrol.batch.solve_care_batch(A, B, Q, R)
    return batch.X, batch.K


def _care_batch_loop(A: Any, B: Any, Q: Any, R: Any) -> Any:
    import scipy.linalg

    X = np.stack([scipy.linalg.solve_continuous_are(a, b, Q, R) for a, b in zip(A, B, strict=True)])
    return X, np.linalg.solve(R, B.transpose(0, 2, 1) @ X)


def _expm(A: Any) -> Any:
    import aerocontrol

    return aerocontrol.expm(A)


def _scipy_expm(A: Any) -> Any:
    import scipy.linalg

    return scipy.linalg.expm(A)


@dataclass(frozen=True)
class Operation:
    """One operation of the bench: ours and the peer, both called with ``args(inputs)``."""

    key: str
    title: str
    short: str
    ours_name: str
    peer_name: str
    ours: Callable[..., Any]
    peer: Callable[..., Any]
    args: Callable[[dict[str, Any]], tuple[Any, ...]]
    compare: Callable[[Any, Any], harness.Pairs]


SIZE_OPERATIONS = (
    Operation(
        "expm",
        "Matrix exponential",
        "expm",
        "aerocontrol.expm",
        "scipy.linalg.expm",
        _expm,
        _scipy_expm,
        lambda d: (d["A"],),
        harness.same,
    ),
    Operation(
        "care",
        "Continuous algebraic Riccati equation (m = 2, Q = I, R = I)",
        "CARE, m = 2",
        "aerocontrol.solve_care (X, K)",
        "scipy.linalg.solve_continuous_are + gain",
        _care_ours,
        _care_scipy,
        lambda d: (d["A"], d["B"], d["Q"], d["R"]),
        harness.compare_tuple,
    ),
    Operation(
        "response",
        f"Initial-condition response, C = I, {STEPS} steps",
        f"initial response, {STEPS} steps",
        "aerocontrol.initial_response",
        "scipy.signal.lsim (u = 0)",
        _initial_ours,
        _initial_lsim,
        lambda d: (d["A"], d["B"], d["t"], d["x0"]),
        harness.same,
    ),
)

BATCH_OPERATIONS = (
    Operation(
        "expm_batch",
        "Matrix exponential of a stack of 4 x 4 matrices",
        "expm of k 4 x 4 matrices",
        "aerocontrol.expm(stack)",
        "loop scipy.linalg.expm",
        _expm,
        _expm_loop,
        lambda d: (d["A"],),
        harness.same,
    ),
    Operation(
        "care_batch",
        "Riccati equations of a batch of 4 x 4 problems (m = 2)",
        "CARE of k 4 x 4 problems, m = 2",
        "aerocontrol.batch.solve_care_batch (X, K)",
        "loop scipy.linalg.solve_continuous_are + gains",
        _care_batch_ours,
        _care_batch_loop,
        lambda d: (d["A"], d["B"], d["Q"], d["R"]),
        harness.compare_tuple,
    ),
)


def size_inputs(n: int) -> dict[str, Any]:
    """The plant of order n (see the module doc)."""
    rng = np.random.default_rng(n)
    A, B = stable_plant(rng, n, 2)
    return {
        "A": A,
        "B": B,
        "Q": np.eye(n),
        "R": np.eye(2),
        "t": np.linspace(0.0, 20.0, STEPS + 1),
        "x0": rng.standard_normal(n),
    }


def batch_inputs(k: int) -> dict[str, Any]:
    """k 4 x 4 problems drawn as one stack (see the module doc)."""
    rng = np.random.default_rng(0)
    A = rng.standard_normal((k, 4, 4)) / 2.0 - 1.5 * np.eye(4)
    return {"A": A, "B": rng.standard_normal((k, 4, 2)), "Q": np.eye(4), "R": np.eye(2)}


def _first(inputs: dict[str, Any], k: int) -> dict[str, Any]:
    """The first k problems of a batch's inputs (views; Q and R are shared)."""
    return {"A": inputs["A"][:k], "B": inputs["B"][:k], "Q": inputs["Q"], "R": inputs["R"]}


# ---------------------------------------------------------------------------------------------
# Measurement (in a worker: the thread setting is its process's)
# ---------------------------------------------------------------------------------------------


def _warm(fn: Callable[[], Any]) -> tuple[Any, float, list[str]]:
    """Call ``fn`` once: its output, its duration (to choose the repeats) and its warnings."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        start = time.perf_counter()
        out = fn()
        elapsed = time.perf_counter() - start
    return out, elapsed, sorted({f"{w.category.__name__}: {w.message}" for w in caught})


def measure_cell(
    op: Operation,
    args: tuple[Any, ...],
    size: int,
    run_ours: bool,
    run_peer: bool,
    min_time: float,
    max_repeat: int,
) -> dict[str, Any]:
    """Warm up, compare, and time ours and (if ``run_peer``) the peer on ``args``."""
    cell: dict[str, Any] = {"size": size, "ours_s": None, "peer_s": None, "agree": None}
    cell.update({"max_scaled_error": None, "repeats": 0, "ours_number": 0, "peer_number": 0})
    fns, durations = [], []
    ours_out = peer_out = None
    if run_ours:
        fns.append(functools.partial(op.ours, *args))
        ours_out, seconds, cell["ours_warnings"] = _warm(fns[-1])
        durations.append(seconds)
    if run_peer:
        fns.append(functools.partial(op.peer, *args))
        peer_out, seconds, cell["peer_warnings"] = _warm(fns[-1])
        durations.append(seconds)
    if run_ours and run_peer:
        ok, err = harness.agreement(op.compare(ours_out, peer_out))
        cell["agree"], cell["max_scaled_error"] = ok, err
        if not ok:
            print(
                f"WARNING: {op.key} {size}: ours and the peer disagree ({err:.3g})", file=sys.stderr
            )
    del ours_out, peer_out
    if not fns:
        return cell
    repeat = min(repeats_for(max(durations)), max_repeat)
    timings = harness.measure(fns, repeat, min_time)
    cell["repeats"] = repeat
    if run_ours:
        cell["ours_s"], cell["ours_number"] = timings[0].best, timings[0].number
    if run_peer:
        cell["peer_s"], cell["peer_number"] = timings[-1].best, timings[-1].number
    return cell


def _predicted(previous: dict[str, Any] | None, key: str, size: int, exponent: int) -> float:
    """The time of ``key`` at ``size`` predicted from the previous cell (0 when there is none;
    infinite when the previous one was not run)."""
    if previous is None:
        return 0.0
    seconds = previous[key]
    if seconds is None:
        return math.inf
    return float(seconds * (size / previous["size"]) ** exponent)


def sweep(
    op: Operation,
    sizes: Sequence[int],
    args_at: Callable[[int], tuple[Any, ...]],
    exponent: int,
    peer_limit: float,
    min_time: float,
    max_repeat: int,
) -> list[dict[str, Any]]:
    """The cells of ``op`` over ``sizes``, each size run while its prediction is in bounds."""
    cells: list[dict[str, Any]] = []
    for size in sizes:
        previous = cells[-1] if cells else None
        ours_predicted = _predicted(previous, "ours_s", size, exponent)
        peer_predicted = _predicted(previous, "peer_s", size, exponent)
        run_ours, run_peer = ours_predicted <= CALL_LIMIT_S, peer_predicted <= peer_limit
        print(f"  {op.key} {size:,}", file=sys.stderr, flush=True)
        cell = measure_cell(op, args_at(size), size, run_ours, run_peer, min_time, max_repeat)
        cell["ours_predicted_s"] = None if run_ours else ours_predicted
        cell["peer_predicted_s"] = None if run_peer else peer_predicted
        cells.append(cell)
    return cells


def worker(quick: bool, min_time: float) -> dict[str, Any]:
    """Every measurement of one thread setting, in this process."""
    started = harness.now()
    env = harness.environment()
    orders = QUICK_ORDERS if quick else ORDERS
    batch_sizes = QUICK_BATCH_SIZES if quick else BATCH_SIZES
    max_repeat = 2 if quick else 5
    size = {
        op.key: sweep(
            op,
            orders,
            lambda n, op=op: op.args(size_inputs(n)),
            3,
            CALL_LIMIT_S,
            min_time,
            max_repeat,
        )
        for op in SIZE_OPERATIONS
    }
    stack = batch_inputs(max(batch_sizes))
    batch = {
        op.key: sweep(
            op,
            batch_sizes,
            lambda k, op=op: op.args(_first(stack, k)),
            1,
            LOOP_LIMIT_S,
            min_time,
            max_repeat,
        )
        for op in BATCH_OPERATIONS
    }
    return {
        "threads": harness.inherited_threads(),
        "quick": quick,
        "min_time": min_time,
        "started": started,
        "finished": harness.now(),
        "loadavg_after": harness.loadavg(),
        "environment": env,
        "size": size,
        "batch": batch,
    }


# ---------------------------------------------------------------------------------------------
# Analysis
# ---------------------------------------------------------------------------------------------


def slope(a: tuple[float, float], b: tuple[float, float]) -> float:
    """The log-log slope from the point (size, time) ``a`` to ``b``."""
    return math.log(b[1] / a[1]) / math.log(b[0] / a[0])


def fitted_slope(points: Sequence[tuple[float, float]]) -> float | None:
    """The least-squares slope of log time on log size (None under two points)."""
    if len(points) < 2:
        return None
    x = np.log([p[0] for p in points])
    y = np.log([p[1] for p in points])
    return float(np.polyfit(x, y, 1)[0])


def points(cells: Sequence[dict[str, Any]], key: str) -> list[tuple[float, float]]:
    """The (size, time) of the cells where ``key`` ("ours_s" or "peer_s") was run."""
    return [(c["size"], c[key]) for c in cells if c[key] is not None]


def successive_slopes(cells: Sequence[dict[str, Any]], key: str) -> list[float | None]:
    """Per cell, the slope from the previous cell (None where either was not run)."""
    out: list[float | None] = [None]
    for a, b in itertools.pairwise(cells):
        both = a[key] is not None and b[key] is not None
        out.append(slope((a["size"], a[key]), (b["size"], b[key])) if both else None)
    return out


def crossings(cells: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Where the ratio peer / ours crosses 1 between successive sizes run by both: the two
    sizes, the size where the log-log interpolation of the ratio is 1, and who is faster
    beyond it."""
    both = [c for c in cells if c["ours_s"] is not None and c["peer_s"] is not None]
    out = []
    for a, b in itertools.pairwise(both):
        ra, rb = math.log(a["peer_s"] / a["ours_s"]), math.log(b["peer_s"] / b["ours_s"])
        if (ra > 0) != (rb > 0):
            la, lb = math.log(a["size"]), math.log(b["size"])
            at = math.exp(la + (0.0 - ra) * (lb - la) / (rb - ra))
            out.append(
                {
                    "from": a["size"],
                    "to": b["size"],
                    "at": at,
                    "beyond": "ours" if rb > 0 else "peer",
                }
            )
    return out


def analyse(cells: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Slopes (successive, overall, over the largest three sizes) and crossings."""
    summary: dict[str, Any] = {"crossings": crossings(cells)}
    for key in ("ours_s", "peer_s"):
        pts = points(cells, key)
        summary[key] = {
            "successive": successive_slopes(cells, key),
            "overall": fitted_slope(pts),
            "largest": fitted_slope(pts[-3:]),
            "largest_sizes": [p[0] for p in pts[-3:]],
        }
    return summary


# ---------------------------------------------------------------------------------------------
# Reports
# ---------------------------------------------------------------------------------------------


def fmt_time(seconds: float | None) -> str:
    return "not run" if seconds is None else harness.format_time(seconds).strip()


def fmt_slope(value: float | None) -> str:
    return "" if value is None else f"{value:.2f}"


def fmt_size(size: float) -> str:
    return f"{size:,.0f}"


def fmt_per(seconds: float | None, scale: float) -> str:
    if seconds is None:
        return ""
    per = float(f"{seconds / scale:.3g}")
    for unit, factor in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if per >= factor:
            return f"{per / factor:.3g} {unit}"
    return f"{per / 1e-12:.3g} ps"


def cell_table(cells: Sequence[dict[str, Any]], kind: str) -> list[str]:
    """The Markdown table of one operation in one run."""
    summary = analyse(cells)
    size_name, per_name = ("n", "/ n³") if kind == "size" else ("k", "per problem")
    header = [
        size_name,
        "ours",
        "peer",
        "peer / ours",
        f"ours {per_name}",
        f"peer {per_name}",
        "slope ours",
        "slope peer",
        "repeats",
    ]
    lines = ["| " + " | ".join(header) + " |", "|" + " ---: |" * len(header)]
    for index, c in enumerate(cells):
        scale = float(c["size"]) ** 3 if kind == "size" else float(c["size"])
        both = c["ours_s"] is not None and c["peer_s"] is not None
        ratio = f"{c['peer_s'] / c['ours_s']:.2f}x" if both else ""
        if c["agree"] is False:
            ratio += " DISAGREE"
        row = [
            fmt_size(c["size"]),
            fmt_time(c["ours_s"]),
            fmt_time(c["peer_s"]),
            ratio,
            fmt_per(c["ours_s"], scale),
            fmt_per(c["peer_s"], scale),
            fmt_slope(summary["ours_s"]["successive"][index]),
            fmt_slope(summary["peer_s"]["successive"][index]),
            str(c["repeats"]),
        ]
        lines.append("| " + " | ".join(row) + " |")
    return lines


def _fits(summary: dict[str, Any], size_name: str) -> str:
    parts = []
    for key, who in (("ours_s", "ours"), ("peer_s", "peer")):
        fit = summary[key]
        if fit["overall"] is None:
            continue
        sizes = ", ".join(fmt_size(s) for s in fit["largest_sizes"])
        parts.append(
            f"{who} {fit['overall']:.2f} over all sizes run, {fit['largest']:.2f} over "
            f"{size_name} = {sizes}"
        )
    return "Least-squares slopes: " + "; ".join(parts) + "."


def _not_run(cells: Sequence[dict[str, Any]], size_name: str, peer_limit: float) -> list[str]:
    notes = []
    for key, who, limit in (
        ("ours_predicted_s", "ours", CALL_LIMIT_S),
        ("peer_predicted_s", "the peer", peer_limit),
    ):
        skipped = [c for c in cells if c[key] is not None]
        if skipped:
            first = skipped[0]
            notes.append(
                f"Not run: {who} from {size_name} = {fmt_size(first['size'])} (predicted "
                f"{first[key]:.3g} s from the size before, over the {limit:g} s limit)."
            )
    return notes


def _crossing_text(cells: Sequence[dict[str, Any]], size_name: str) -> str:
    both = [c for c in cells if c["ours_s"] is not None and c["peer_s"] is not None]
    if not both:
        return "No size was run by both."
    found = crossings(cells)
    span = f"{size_name} = {fmt_size(both[0]['size'])} to {fmt_size(both[-1]['size'])}"
    if not found:
        faster = "ours" if both[0]["peer_s"] > both[0]["ours_s"] else "the peer"
        return f"No crossing: {faster} faster at every size run by both ({span})."
    parts = [
        f"between {fmt_size(x['from'])} and {fmt_size(x['to'])} (about {size_name} = "
        f"{x['at']:,.0f}; {'ours' if x['beyond'] == 'ours' else 'the peer'} faster above)"
        for x in found
    ]
    return "Ratio crosses 1 " + "; ".join(parts) + f" ({span} run by both)."


def operation_section(
    op: Operation, runs: Sequence[dict[str, Any]], kind: str, peer_limit: float
) -> list[str]:
    size_name = "n" if kind == "size" else "k"
    lines = ["", f"### {op.title}", "", f"Ours: `{op.ours_name}`; peer: `{op.peer_name}`."]
    for run in runs:
        cells = run[kind][op.key]
        summary = analyse(cells)
        lines += ["", f"**{harness.run_label(run)}**", "", *cell_table(cells, kind), ""]
        lines.append(_fits(summary, size_name))
        lines.append(_crossing_text(cells, size_name))
        lines += _not_run(cells, size_name, peer_limit)
        disagree = [c for c in cells if c["agree"] is False]
        if disagree:
            worst = max(c["max_scaled_error"] for c in disagree)
            lines.append(
                f"DISAGREE at {', '.join(fmt_size(c['size']) for c in disagree)} (worst "
                f"scaled error {worst:.3g} > 1e-10)."
            )
        warned = sorted(
            {w for c in cells for w in c.get("ours_warnings", []) + c.get("peer_warnings", [])}
        )
        lines += [f"Warning during the warm-up: {w}" for w in warned]
    return lines


READING = """\
## Reading the slopes

The slope between two sizes is d log(time) / d log(size): the exponent p of a cost that
grows like size^p there.

- **Dense kernels against n.** The matrix exponential is a few n x n products and one LU
  solve (Padé degree 13 at these norms, possibly squarings), the Riccati solution a real
  Schur form of the 2n x 2n Hamiltonian (or, for scipy, a QZ of a 2n + m pencil), its
  reordering and an n x n solve: O(n³) flops each, so once the flops dominate the slope
  tends to 3 and the time / n³ settles at a constant, the inverse of the flop rate reached.
  Below that, the cost of a call that does not grow with n (the Python call, argument
  checks and conversion, allocation, the result's checks) flattens the curve: a slope near
  0 at the smallest n, rising through 1 and 2 as the flops take over. A slope above 3
  between two sizes means the flop rate fell (the working set left a cache level, or
  another user took the core); below 3 at large n, that it rose (blocked kernels reach
  their speed, or the default threads found a second core).
- **The response against n** is one discretisation (an exponential of order about n, O(n³))
  and 200 steps of a matrix-vector recurrence (200 x 2n² flops): the steps dominate while
  n is below about a hundred (a slope near 2), the exponential beyond (a slope tending
  to 3).
- **Against the batch size k**, every problem costs the same, so the time of a batch grows
  like k (slope 1, time per problem constant) once the fixed cost of the call is spread
  thin: while that cost dominates, the slope is below 1. A slope above 1 at small k is a
  fixed cost that a batch of one does not pay and a batch of several does (handing the
  batch to the parallel machinery): the per-problem column shows its size. The peer's
  Python loop pays a full call per problem and has slope 1 from k = 1. With the default
  threads ours spreads a large batch over every core, which lowers the constant, not the
  slope.
- **The default threads and the peer.** On a small shared machine OpenBLAS with its default
  threads has been seen to make a peer's call of microseconds take milliseconds (see
  performance.md): a ratio in the hundreds or thousands at small sizes in a default-thread
  table measures that, not the algorithms; the one-thread run compares the algorithms.
- **Crossings** of the ratio peer / ours through 1 are where the faster side changes; the
  crossings listed below with the peer faster above them are the rows issue 26 still has
  to win.
"""


def _onset(cells: Sequence[dict[str, Any]], threshold: float) -> str:
    """Where our successive slope first reaches ``threshold``: the two sizes, or "-"."""
    slopes = successive_slopes(cells, "ours_s")
    for index, value in enumerate(slopes):
        if value is not None and value >= threshold:
            return f"{fmt_size(cells[index - 1]['size'])} to {fmt_size(cells[index]['size'])}"
    return "-"


def _per_problem(cells: Sequence[dict[str, Any]]) -> str:
    """Our time per problem at the two smallest and the largest batch run."""
    run = [c for c in cells if c["ours_s"] is not None]
    chosen = run[:2] + run[2:][-1:]
    return ", ".join(f"{fmt_per(c['ours_s'], c['size'])} at {fmt_size(c['size'])}" for c in chosen)


def _crossing_cell(cells: Sequence[dict[str, Any]]) -> str:
    found = crossings(cells)
    if not found:
        return "none"
    return "; ".join(
        f"~{x['at']:,.0f} ({'ours' if x['beyond'] == 'ours' else 'peer'} faster above)"
        for x in found
    )


def _ratio_span(cells: Sequence[dict[str, Any]]) -> str:
    both = [c for c in cells if c["ours_s"] is not None and c["peer_s"] is not None]
    if not both:
        return "-"
    first, last = both[0], both[-1]
    return (
        f"{first['peer_s'] / first['ours_s']:.2f}x at {fmt_size(first['size'])}, "
        f"{last['peer_s'] / last['ours_s']:.2f}x at {fmt_size(last['size'])}"
    )


def summary_table(runs: Sequence[dict[str, Any]], kind: str) -> list[str]:
    """One row per operation and run: the slopes over the largest three sizes; against n,
    where our slope first reaches 2 (below it, fixed costs flatten the curve), against k our
    time per problem at the smallest and largest batches (the fixed cost of a call spread
    over k); the ratio at the ends and its crossings of 1."""
    size_name = "n" if kind == "size" else "k"
    operations = SIZE_OPERATIONS if kind == "size" else BATCH_OPERATIONS
    header = ["operation", "run", "slope ours, largest 3", "slope peer, largest 3"]
    header.append("ours' slope first >= 2" if kind == "size" else "ours per problem")
    header += [f"peer / ours, smallest and largest {size_name}", f"ratio crosses 1 at {size_name}"]
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    for op in operations:
        for run in runs:
            cells = run[kind][op.key]
            summary = analyse(cells)
            row = [
                op.key,
                harness.run_label(run),
                fmt_slope(summary["ours_s"]["largest"]) or "-",
                fmt_slope(summary["peer_s"]["largest"]) or "-",
                _onset(cells, 2.0) if kind == "size" else _per_problem(cells),
                _ratio_span(cells),
                _crossing_cell(cells),
            ]
            lines.append("| " + " | ".join(row) + " |")
    return lines


def format_markdown(
    runs: Sequence[dict[str, Any]],
    info: dict[str, Any],
    command: str,
    size_plot: str | None,
    batch_plot: str | None,
) -> str:
    """The growth record: the machine, the runs, the plots and a table per operation and run."""
    quick = any(run["quick"] for run in runs)
    lines = [
        "# How cost grows with size",
        "",
        "aerocontrol and its peer against the order n of one problem and the number k of 4 x 4",
        "problems in a batch, on log-log axes, in one-thread and default-thread runs. Written by",
        "",
        f"    {command}",
        "",
        "(regenerate it rather than edit it; the method is the docstring of `benches/growth.py`).",
        "The fixed-size comparison of every operation is [performance.md](performance.md).",
    ]
    if quick:
        lines += ["", "**A quick smoke run (n = 4, 8; k = 1, 10): not a record.**"]
    lines += [
        "",
        f"Timing: after a warm-up call of each (its answers compared, 1e-10 scaled), the minimum "
        f"over 1-5 repeats (fewer for slower calls: the tables' last column) of the mean over an "
        f"inner loop of >= {runs[0]['min_time']:g} s; ratio = peer / ours (> 1: aerocontrol "
        f"faster). A call predicted from the size before to take over {CALL_LIMIT_S:g} s, and a "
        f"peer loop over a batch predicted over {LOOP_LIMIT_S:g} s, is not run (and not "
        "extrapolated).",
        "",
        *harness.machine_and_runs(info, runs),
        "",
        READING,
        "## Summary",
        "",
        *summary_table(runs, "size"),
        "",
        *summary_table(runs, "batch"),
    ]
    lines += ["", "## Cost against the order n", ""]
    lines.append(
        "Random stable plants A = G / sqrt(n) - 3/2 I, B standard normal n x 2, seed n; the "
        f"response from a standard normal x0 on {STEPS + 1} times of [0, 20] s."
    )
    if size_plot:
        lines += ["", f"![time against n, log-log]({size_plot})"]
    for op in SIZE_OPERATIONS:
        lines += operation_section(op, runs, "size", CALL_LIMIT_S)
    lines += ["", "## Cost against the batch size k", ""]
    lines.append(
        "The first k problems of one stack: A_i = G_i / 2 - 3/2 I, B_i standard normal 4 x 2, "
        "Q = I, R = I, seed 0."
    )
    if batch_plot:
        lines += ["", f"![time against k, log-log]({batch_plot})"]
    for op in BATCH_OPERATIONS:
        lines += operation_section(op, runs, "batch", LOOP_LIMIT_S)
    return "\n".join(lines) + "\n"


def plot(runs: Sequence[dict[str, Any]], kind: str, path: str) -> None:
    """The log-log plot of time against n (``kind`` "size") or k ("batch"), one panel per
    operation: ours and the peer in each run, and a reference slope (3 or 1) through our
    largest size of the first run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    operations = SIZE_OPERATIONS if kind == "size" else BATCH_OPERATIONS
    exponent, label = (3, "slope 3 (n³)") if kind == "size" else (1, "slope 1 (k)")
    fig, axes = plt.subplots(1, len(operations), figsize=(5.0 * len(operations), 4.8))
    for ax, op in zip(np.atleast_1d(axes), operations, strict=True):
        reference: tuple[float, float] | None = None
        for run in runs:
            cells = run[kind][op.key]
            style = THREAD_STYLE.get(run["threads"], ":")
            marker = "o" if run["threads"] == "one" else "s"
            for key, color, who in (("ours_s", "C0", "aerocontrol"), ("peer_s", "C1", "peer")):
                pts = points(cells, key)
                if not pts:
                    continue
                x, y = zip(*pts, strict=True)
                ax.loglog(
                    x,
                    y,
                    style,
                    color=color,
                    marker=marker,
                    markersize=3.5,
                    label=f"{who}, {harness.run_label(run)}",
                )
                if key == "ours_s" and reference is None:
                    reference = pts[-1]
        sizes = np.array([c["size"] for c in runs[0][kind][op.key]], dtype=float)
        if reference is not None:
            line = reference[1] * (sizes / reference[0]) ** exponent
            ax.loglog(sizes, line, ":", color="grey", label=label)
        ax.set_xticks(sizes, [fmt_size(size) for size in sizes], fontsize=7)
        ax.minorticks_off()
        ax.set_title(f"{op.short}\nours: {op.ours_name}\npeer: {op.peer_name}", fontsize=8)
        ax.set_xlabel("n" if kind == "size" else "k (problems in the batch)")
        ax.set_ylabel("time of one call (s)")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def format_text(runs: Sequence[dict[str, Any]]) -> str:
    """The tables and crossings of every run, as printed on stdout."""
    lines = []
    for run in runs:
        env = run["environment"]
        lines.append(
            f"== {harness.run_label(run)}, {run['started']} to {run['finished']}; load average "
            f"{env['loadavg']} at the start, {run['loadavg_after']} at the end"
        )
        for kind, operations in (("size", SIZE_OPERATIONS), ("batch", BATCH_OPERATIONS)):
            for op in operations:
                cells = run[kind][op.key]
                lines += [
                    "",
                    f"{op.key}: {op.ours_name} vs {op.peer_name}",
                    *cell_table(cells, kind),
                ]
                lines.append(_fits(analyse(cells), "n" if kind == "size" else "k"))
                lines.append(_crossing_text(cells, "n" if kind == "size" else "k"))
        lines.append("")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# Entry point
# ---------------------------------------------------------------------------------------------


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--threads",
        choices=("one", "default", "both"),
        default="both",
        help="thread settings, each run in a fresh process (default: both)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="smoke run: n = 4, 8 and k = 1, 10, short repeats"
    )
    parser.add_argument(
        "--min-time", type=float, help="minimum seconds per repeat (default 0.05, quick 0.001)"
    )
    parser.add_argument(
        "--markdown", metavar="PATH", help=f"the record (default {DEFAULT_MARKDOWN}; quick: none)"
    )
    parser.add_argument(
        "--size-plot", metavar="PATH", help=f"time against n (default {DEFAULT_SIZE_PLOT})"
    )
    parser.add_argument(
        "--batch-plot", metavar="PATH", help=f"time against k (default {DEFAULT_BATCH_PLOT})"
    )
    parser.add_argument("--json", action="store_true", help="print the runs as JSON on stdout")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if not args.quick:
        args.markdown = args.markdown or DEFAULT_MARKDOWN
        args.size_plot = args.size_plot or DEFAULT_SIZE_PLOT
        args.batch_plot = args.batch_plot or DEFAULT_BATCH_PLOT
    if args.min_time is None:
        args.min_time = 0.001 if args.quick else 0.05
    return args


def _relative(path: str, markdown: str | None) -> str:
    """``path`` as the Markdown file at ``markdown`` links to it."""
    if markdown is None:
        return path
    start = Path(markdown).resolve().parent
    return os.path.relpath(Path(path).resolve(), start)


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    if args.worker:
        print(json.dumps(worker(args.quick, args.min_time)))
        return 0
    settings = harness.THREAD_SETTINGS if args.threads == "both" else (args.threads,)
    runs = []
    for setting in settings:
        print(f"== {harness.THREAD_LABELS[setting]}: a fresh process", file=sys.stderr)
        command = [sys.executable, str(Path(__file__).resolve()), "--worker"]
        command += ["--min-time", repr(args.min_time)] + (["--quick"] if args.quick else [])
        runs.append(harness.run_in_subprocess(command, setting))
    if args.size_plot:
        plot(runs, "size", args.size_plot)
    if args.batch_plot:
        plot(runs, "batch", args.batch_plot)
    if args.markdown:
        words = sys.argv[1:] if argv is None else list(argv)
        command_line = shlex.join(["python", "benches/growth.py", *words])
        size_plot = _relative(args.size_plot, args.markdown) if args.size_plot else None
        batch_plot = _relative(args.batch_plot, args.markdown) if args.batch_plot else None
        text = format_markdown(runs, harness.machine(), command_line, size_plot, batch_plot)
        harness.write_text(args.markdown, text)
        print(f"wrote {args.markdown}", file=sys.stderr)
    if args.json:
        print(json.dumps({"runs": runs}, indent=1))
    else:
        print(format_text(runs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
