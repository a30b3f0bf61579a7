"""How the batch API scales: time per problem, parallel speed-up, peak memory, and the
envelope sweep (issue 7).

Run from the repository root with the package installed::

    python benches/batch_scaling.py           # tables and the PASS/MISS of each target
    python benches/batch_scaling.py --json    # the same measurements as one JSON object

What is measured
----------------
(a) ``aerocontrol.batch.lqr_sweep`` of the 747 lateral regulator
    (``aerocontrol.aircraft.load().lateral()``, Q = I, R = I, weights c log-spaced on
    [1e-3, 10], control weight R / c²) at k = 1,000, 10,000 and 100,000 weights. Each
    (k, threads) point runs in a fresh subprocess, once with ``RAYON_NUM_THREADS=1`` and once
    with the default thread count (RAYON_NUM_THREADS removed from the environment: rayon then
    uses every core the process may run on). In the subprocess one small sweep starts the
    thread pool, then the time is the best of ``--repeat`` sweeps. Printed: the time, the
    time per problem (constant when the cost grows linearly in k) and the speed-up of the
    default over one thread.
(b) The peak memory of the 100,000-weight sweep, in a fresh subprocess with the default
    threads: ``resource.getrusage(RUSAGE_SELF).ru_maxrss`` just after
    ``import aerocontrol, numpy`` and again after the sweep (its result still alive), and
    their difference. ru_maxrss is the high-water mark of the process's resident set size,
    in KiB on Linux (in bytes on macOS; both are converted to MB, 10^6 bytes, here). The
    difference is what the sweep added to the peak: its inputs, outputs and any transient
    working memory. Target: < 200 MB.
(c) ``aerocontrol.aircraft.envelope_sweep(aerocontrol.aircraft.load(),
    altitudes=np.linspace(0, 20000, 10), machs=np.linspace(0.2, 0.5, 10))``: 100 flight
    conditions, each a longitudinal and a lateral model, their modes and Levels. The best of
    ``--envelope-runs`` runs after one warm-up run, in this process. Target: < 50 ms.

On a shared machine the times carry the load of other users; the header prints the load
average, and best-of timing filters most of it.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from collections.abc import Sequence
from typing import Any

SIZES = (1_000, 10_000, 100_000)
MEMORY_SIZE = 100_000
MEMORY_TARGET_MB = 200.0
ENVELOPE_TARGET_S = 0.050


# ---------------------------------------------------------------------------------------------
# Subprocess workers: each prints one JSON object on stdout
# ---------------------------------------------------------------------------------------------


def _weights(k: int) -> Any:
    import numpy as np

    return np.geomspace(1e-3, 10.0, k)


def worker_time(k: int, repeat: int) -> dict[str, Any]:
    """Best-of-``repeat`` time of one k-weight sweep, after a small sweep starts the pool."""
    import numpy as np

    import aerocontrol

    sys_ = aerocontrol.aircraft.load().lateral()
    Q, R = np.eye(4), np.eye(2)
    aerocontrol.batch.lqr_sweep(sys_, Q=Q, R=R, weights=_weights(100))
    c = _weights(k)
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        sweep = aerocontrol.batch.lqr_sweep(sys_, Q=Q, R=R, weights=c)
        times.append(time.perf_counter() - start)
        if sweep.K.shape != (k, 2, 4) or not np.all(np.isfinite(sweep.K)):
            raise RuntimeError(f"sweep of {k} weights returned bad gains")
    return {"k": k, "times_s": times, "best_s": min(times)}


def _maxrss_mb(maxrss: int) -> float:
    """ru_maxrss in MB (10^6 bytes): KiB on Linux, bytes on macOS."""
    return maxrss / 1e6 if sys.platform == "darwin" else maxrss * 1024 / 1e6


def worker_memory(k: int) -> dict[str, Any]:
    """ru_maxrss after the imports and after a k-weight sweep (result kept alive)."""
    import resource

    import numpy as np

    import aerocontrol

    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    sweep = aerocontrol.batch.lqr_sweep(
        aerocontrol.aircraft.load().lateral(), Q=np.eye(4), R=np.eye(2), weights=_weights(k)
    )
    after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    result_bytes = sum(
        getattr(sweep, name).nbytes for name in ("weights", "K", "poles", "X", "residual", "rcond")
    )
    return {
        "k": k,
        "maxrss_after_import_raw": before,
        "maxrss_after_sweep_raw": after,
        "after_import_mb": _maxrss_mb(before),
        "after_sweep_mb": _maxrss_mb(after),
        "sweep_mb": _maxrss_mb(after) - _maxrss_mb(before),
        "result_arrays_mb": result_bytes / 1e6,
    }


def run_worker(args: list[str], threads: int | None) -> dict[str, Any]:
    """Run this script as a worker in a fresh interpreter; ``threads=None``: rayon's default."""
    env = dict(os.environ)
    env.pop("RAYON_NUM_THREADS", None)
    if threads is not None:
        env["RAYON_NUM_THREADS"] = str(threads)
    completed = subprocess.run(
        [sys.executable, os.path.abspath(__file__), "--worker", *args],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if completed.returncode != 0:
        raise RuntimeError(f"worker {args} failed:\n{completed.stderr}")
    result: dict[str, Any] = json.loads(completed.stdout)
    return result


# ---------------------------------------------------------------------------------------------
# Measurements
# ---------------------------------------------------------------------------------------------


def measure_sweeps(repeat: int) -> list[dict[str, Any]]:
    """(a): one record per k with the one-thread and default-thread times."""
    records = []
    for k in SIZES:
        runs = max(1, repeat if k < 100_000 else min(repeat, 3))
        one = run_worker(["time", str(k), str(runs)], threads=1)
        default = run_worker(["time", str(k), str(runs)], threads=None)
        records.append(
            {
                "k": k,
                "one_thread_s": one["best_s"],
                "default_s": default["best_s"],
                "one_thread_per_problem_s": one["best_s"] / k,
                "default_per_problem_s": default["best_s"] / k,
                "speedup": one["best_s"] / default["best_s"],
                "repeats": runs,
            }
        )
    return records


def measure_envelope(runs: int) -> dict[str, Any]:
    """(c): best of ``runs`` envelope sweeps after a warm-up."""
    import numpy as np

    import aerocontrol

    plane = aerocontrol.aircraft.load()
    altitudes, machs = np.linspace(0, 20000, 10), np.linspace(0.2, 0.5, 10)
    envelope = aerocontrol.aircraft.envelope_sweep(plane, altitudes=altitudes, machs=machs)
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        aerocontrol.aircraft.envelope_sweep(plane, altitudes=altitudes, machs=machs)
        times.append(time.perf_counter() - start)
    return {
        "conditions": int(np.prod(envelope.shape)),
        "failures": len(envelope.failures),
        "times_s": times,
        "best_s": min(times),
        "median_s": float(np.median(times)),
    }


# ---------------------------------------------------------------------------------------------
# Reporting
# ---------------------------------------------------------------------------------------------


def environment() -> dict[str, Any]:
    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "loadavg": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
        "RAYON_NUM_THREADS (parent)": os.environ.get("RAYON_NUM_THREADS"),
    }


def fmt_time(seconds: float) -> str:
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3f} {unit}"
    return f"{seconds / 1e-9:.1f} ns"


def report(results: dict[str, Any]) -> str:
    env = results["environment"]
    lines = [
        f"python {env['python']} on {env['platform']}",
        f"os.cpu_count() = {env['cpu_count']}, usable cores (affinity) = {env['affinity']}, "
        f"load average = {env['loadavg']}",
        "",
        "(a) lqr_sweep, 747 lateral, Q = I, R = I, c log-spaced on [1e-3, 10]; "
        "each point a fresh process, best of its repeats",
    ]
    header = f"{'k':>8}  {'1 thread':>11}  {'per problem':>11}  {'default':>11}  "
    header += f"{'per problem':>11}  {'speed-up':>8}"
    lines += [header, "-" * len(header)]
    for r in results["sweeps"]:
        lines.append(
            f"{r['k']:>8,}  {fmt_time(r['one_thread_s']):>11}  "
            f"{fmt_time(r['one_thread_per_problem_s']):>11}  {fmt_time(r['default_s']):>11}  "
            f"{fmt_time(r['default_per_problem_s']):>11}  {r['speedup']:>7.2f}x"
        )
    first, last = results["sweeps"][0], results["sweeps"][-1]
    lines.append(
        f"per-problem time at k = {last['k']:,} / at k = {first['k']:,}: "
        f"{last['one_thread_per_problem_s'] / first['one_thread_per_problem_s']:.2f} "
        f"(1 thread), {last['default_per_problem_s'] / first['default_per_problem_s']:.2f} "
        "(default); 1.00 is exactly linear growth"
    )
    memory = results["memory"]
    lines += [
        "",
        f"(b) peak memory of the {memory['k']:,}-weight sweep (ru_maxrss, fresh process, "
        "default threads)",
        f"    after import aerocontrol, numpy: {memory['after_import_mb']:.1f} MB "
        f"(ru_maxrss {memory['maxrss_after_import_raw']})",
        f"    after the sweep:                 {memory['after_sweep_mb']:.1f} MB "
        f"(ru_maxrss {memory['maxrss_after_sweep_raw']})",
        f"    added by the sweep:              {memory['sweep_mb']:.1f} MB "
        f"(its result arrays: {memory['result_arrays_mb']:.1f} MB)",
    ]
    envelope = results["envelope"]
    lines += [
        "",
        f"(c) envelope_sweep, 747, 10 altitudes x 10 Machs = {envelope['conditions']} "
        f"conditions ({envelope['failures']} failures): best {fmt_time(envelope['best_s'])}, "
        f"median {fmt_time(envelope['median_s'])} over {len(envelope['times_s'])} runs",
        "",
        "targets:",
    ]
    for target in results["targets"]:
        verdict = "PASS" if target["met"] else "MISS"
        lines.append(f"  {verdict}  {target['label']:<52} measured {target['measured']}")
    return "\n".join(lines)


def targets(results: dict[str, Any]) -> list[dict[str, Any]]:
    memory, envelope = results["memory"], results["envelope"]
    return [
        {
            "label": f"(b) {memory['k']:,}-weight sweep adds < {MEMORY_TARGET_MB:g} MB to the peak",
            "measured": f"{memory['sweep_mb']:.1f} MB",
            "met": memory["sweep_mb"] < MEMORY_TARGET_MB,
        },
        {
            "label": f"(c) envelope_sweep of 100 conditions < {ENVELOPE_TARGET_S * 1e3:g} ms",
            "measured": fmt_time(envelope["best_s"]),
            "met": envelope["best_s"] < ENVELOPE_TARGET_S,
        },
    ]


# ---------------------------------------------------------------------------------------------
# Entry point
# ---------------------------------------------------------------------------------------------


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--repeat", type=int, default=5, help="sweeps per point (at most 3 at k = 100,000)"
    )
    parser.add_argument("--envelope-runs", type=int, default=10, help="envelope sweeps timed")
    parser.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    if args.worker:
        kind, *rest = args.worker
        if kind == "time":
            print(json.dumps(worker_time(int(rest[0]), int(rest[1]))))
        elif kind == "memory":
            print(json.dumps(worker_memory(int(rest[0]))))
        else:
            raise SystemExit(f"unknown worker {kind!r}")
        return 0
    results: dict[str, Any] = {"environment": environment()}
    results["sweeps"] = measure_sweeps(args.repeat)
    results["memory"] = run_worker(["memory", str(MEMORY_SIZE)], threads=None)
    results["envelope"] = measure_envelope(args.envelope_runs)
    results["targets"] = targets(results)
    if args.json:
        print(json.dumps(results, indent=1))
    else:
        print(report(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
