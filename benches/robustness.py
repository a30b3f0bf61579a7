"""Stochastic robustness at scale (issue 27): the Monte Carlo run of the 747 in cruise,
locally and on a local Dask cluster, against the issue's targets.

Run from the repository root with the package and the ``distributed`` extra installed::

    python benches/robustness.py                               # tables and PASS/MISS
    python benches/robustness.py --markdown docs/robustness.md # the record

What is measured (each in a fresh subprocess, so that the peak memory is the run's own)
----------------------------------------------------------------------------------------
The uncertainty is what ``aerocontrol robustness b747-cruise`` uses for a file without an
[uncertainty] table: every nonzero lateral derivative with a relative normal scatter of 15 %.

(a) ``monte_carlo`` of 10^6 samples with the chapter's Dutch roll damper (fixed gains): open
    and closed loop, Levels of the three lateral modes. Target: <= 10 s on this machine.
(b) The same with the regulator (Q = I, R = I, c = 1) re-designed for every sample.
    Target: <= 30 s.
(c) Run (a) on a ``LocalCluster`` of 2 worker processes of one thread each
    (``RAYON_NUM_THREADS=1``), the cluster started beforehand; the result compared bitwise
    with the local one. Target: within 25 % of the local time.
(d) The peak resident memory of the process of (a): ``ru_maxrss`` after the run. Target:
    < 500 MB.

The per-chunk cost (65,536 samples on one core) is the basis of the record's note on
scaling out.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

SAMPLES = 1_000_000

_RUN = r"""
import json, os, resource, sys, time
import numpy as np
import aerocontrol
from aerocontrol import design
from aerocontrol.aircraft.tables import LATERAL_DERIVATIVES
from aerocontrol.robustness import CHUNK_SIZE, Lqr, Normal, Uncertainty, monte_carlo

kind, samples, workers = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
plane = aerocontrol.aircraft.load("b747-cruise")
uncertainty = Uncertainty(
    {n: Normal(0.15) for n in LATERAL_DERIVATIVES if plane.derivatives[n] != 0.0}
)
gains = np.vstack([design.dutch_roll_damper(plane).k, np.zeros(4)])
controller = Lqr(1.0) if kind == "lqr" else gains
client = None
if workers:
    from distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, env={"RAYON_NUM_THREADS": "1"})
    client = Client(cluster)
    client.submit(sum, [1]).result()  # the workers are up
monte_carlo(plane, uncertainty, 1000, controller, seed=1, client=client)  # warm-up
start = time.perf_counter()
result = monte_carlo(plane, uncertainty, samples, controller, seed=1, client=client)
elapsed = time.perf_counter() - start
with aerocontrol.limit_threads(1):
    chunk_start = time.perf_counter()
    monte_carlo(plane, uncertainty, CHUNK_SIZE, controller, seed=2)
    chunk = time.perf_counter() - chunk_start
import hashlib
digest = hashlib.sha256(result.failed.tobytes() + result.closed_loop.levels.tobytes()
                        + result.open_loop.max_real.tobytes()).hexdigest()
print(json.dumps({
    "seconds": elapsed,
    "chunk_seconds_one_core": chunk,
    "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e6,
    "digest": digest,
    "p_failed": result.probability("failed").value,
    "p_unstable_open": result.probability("unstable", loop="open").value,
}))
if client is not None:
    client.close(); cluster.close()
"""


def _measure(kind: str, samples: int, workers: int) -> dict[str, Any]:
    done = subprocess.run(
        [sys.executable, "-c", _RUN, kind, str(samples), str(workers)],
        capture_output=True,
        text=True,
        check=True,
    )
    measured: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    return measured


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=SAMPLES)
    parser.add_argument("--markdown", metavar="PATH", help="write the record to PATH")
    args = parser.parse_args()
    started = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    load = os.getloadavg()
    fixed = _measure("fixed", args.samples, 0)
    lqr = _measure("lqr", args.samples, 0)
    dask = _measure("fixed", args.samples, 2)
    same = dask["digest"] == fixed["digest"]
    rows = [
        (
            "(a) fixed gains, open and closed loop",
            fixed["seconds"],
            "<= 10 s",
            fixed["seconds"] <= 10,
        ),
        ("(b) LQR re-designed per sample", lqr["seconds"], "<= 30 s", lqr["seconds"] <= 30),
        (
            "(c) (a) on a LocalCluster of 2 workers",
            dask["seconds"],
            f"<= 1.25 x (a) = {1.25 * fixed['seconds']:.2f} s, identical",
            dask["seconds"] <= 1.25 * fixed["seconds"] and same,
        ),
    ]
    lines = [
        f"{args.samples:,} samples of the 747 cruise lateral model; {os.cpu_count()} cores, "
        f"load average {load[0]:.2f} at the start ({started})",
        "",
        "| run | seconds | target | |",
        "| --- | ---: | --- | --- |",
    ]
    for name, seconds, target, met in rows:
        lines.append(f"| {name} | {seconds:.2f} | {target} | {'PASS' if met else 'MISS'} |")
    peak = fixed["peak_mb"]
    lines.append(
        f"| (d) peak resident memory of (a) | {peak:.0f} MB | < 500 MB | "
        f"{'PASS' if peak < 500 else 'MISS'} |"
    )
    lines += [
        "",
        f"Dask result bitwise the local one: {same}. P(failed) = {fixed['p_failed']:.4f}, "
        f"P(unstable, open loop) = {fixed['p_unstable_open']:.4f}.",
        f"One chunk of 65,536 samples on one core: {fixed['chunk_seconds_one_core']:.3f} s "
        f"(fixed gains), {lqr['chunk_seconds_one_core']:.3f} s (LQR re-designed).",
    ]
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        chunk = fixed["chunk_seconds_one_core"]
        chunk_lqr = lqr["chunk_seconds_one_core"]
        text = _RECORD.format(
            table=table,
            chunk=chunk,
            chunk_lqr=chunk_lqr,
            cluster=1e9 / 65536 * chunk / 1600,
            cluster_lqr=1e9 / 65536 * chunk_lqr / 1600,
        )
        Path(args.markdown).write_text(text, encoding="utf-8")
        print(f"wrote {args.markdown}", file=sys.stderr)
    return 0


_RECORD = """# Stochastic robustness at scale

Written by `python benches/robustness.py --markdown docs/robustness.md` (regenerate it rather
than edit it).

## Measured on this machine

{table}

## Spreading the same run over 100 machines

`monte_carlo(..., client=client)` cuts the samples into chunks of 65,536
(`aerocontrol.robustness.CHUNK_SIZE`). Chunk i draws from `SeedSequence(seed,
spawn_key=(i,))`, so the chunks are independent of one another and of where they run: a
cluster of any size gives the local result, bitwise. Each chunk is one Dask task. Its cost
measured above, on one core, is {chunk:.3f} s with fixed gains and {chunk_lqr:.3f} s with the
LQR re-designed per sample.

Take 100 machines of 16 cores, 1,600 worker processes of one thread each, started with
`RAYON_NUM_THREADS=1` (or with `aerocontrol.set_num_threads(1)` in a worker plugin), so that
no worker oversubscribes its cores. 10^9 samples are then 15,259 tasks, about 10 per worker:

- **compute**: 10^9 / 65,536 x {chunk:.3f} s / 1,600 = {cluster:.1f} s of work per worker with
  fixed gains, {cluster_lqr:.1f} s with the LQR re-designed;
- **scheduler**: Dask's scheduler spends on the order of a millisecond per task, about 15 s
  for 15,259 tasks, spread over the run; larger chunks (`chunk_size=2**20`) cut it 16-fold and
  change the draws (the chunk size is part of the result's identity, the worker count is not);
- **the reduction**: each chunk sends back its per-sample arrays, about 90 bytes a sample
  (the Levels of each mode open and closed, stability, the largest real part, the mode
  quantities). That is 6 MB a chunk and 90 GB for 10^9 samples: at that size, run with
  `keep="counts"`, which reduces each chunk on its worker to the counts the probabilities
  and the sensitivity ranking are made of (a few hundred integers a chunk, 15,259 chunks:
  a few MB in all; sums over chunks, exact in any order, so the result is bitwise that of
  the full run's counts). Up to about 10^7 samples (1 GB), gathering the per-sample arrays
  to the client (the default, `keep="samples"`) keeps the histograms and the failed
  samples' indices.
"""


if __name__ == "__main__":
    raise SystemExit(main())
