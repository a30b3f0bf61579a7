"""Peer cases of aerocontrol.batch: the LQR sweep over weights and the batch of Riccati
equations, against Python loops over python-control and scipy."""

from __future__ import annotations

from typing import Any

import control
import numpy as np
import scipy.linalg

import aerocontrol

from .harness import Case, Peer, Target, compare_tuple


def _sweep_747(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 lateral model of the aircraft file (aerocontrol.aircraft.load().lateral()),
    Q = I, R = I and 1000 weights c log-spaced on [1e-3, 10] (control weight R / c²)."""
    sys = aerocontrol.aircraft.load().lateral()
    return sys.A, sys.B, np.eye(4), np.eye(2), np.geomspace(1e-3, 10.0, 1000)


def _sweep_ours(A: Any, B: Any, Q: Any, R: Any, c: Any) -> Any:
    return aerocontrol.batch.lqr_sweep(A, B, Q, R, weights=c).K


def _sweep_control(A: Any, B: Any, Q: Any, R: Any, c: Any) -> Any:
    return np.stack([control.lqr(A, B, Q, R / w**2)[0] for w in c])


def _sweep_scipy(A: Any, B: Any, Q: Any, R: Any, c: Any) -> Any:
    gains = []
    for w in c:
        Rw = R / w**2
        X = scipy.linalg.solve_continuous_are(A, B, Q, Rw)
        gains.append(np.linalg.solve(Rw, B.T @ X))
    return np.stack(gains)


def _monte_carlo_747(rng: np.random.Generator) -> tuple[Any, ...]:
    """1000 copies of the 747 lateral A with its (r, β) entry, the weathercock stability,
    scattered by 10 % (the example of solve_care_batch); B, Q = I, R = I shared."""
    sys = aerocontrol.aircraft.load().lateral()
    A = np.repeat(sys.A[np.newaxis], 1000, axis=0)
    A[:, 3, 0] *= 1 + 0.1 * rng.standard_normal(1000)
    return A, sys.B, np.eye(4), np.eye(2)


def _care_batch_ours(A: Any, B: Any, Q: Any, R: Any) -> Any:
    batch = aerocontrol.batch.solve_care_batch(A, B, Q, R)
    return batch.X, batch.K


def _care_batch_control(A: Any, B: Any, Q: Any, R: Any) -> Any:
    K, X, _ = zip(*(control.lqr(a, B, Q, R) for a in A), strict=True)
    return np.stack(X), np.stack(K)


def _care_batch_scipy(A: Any, B: Any, Q: Any, R: Any) -> Any:
    X = np.stack([scipy.linalg.solve_continuous_are(a, B, Q, R) for a in A])
    return X, np.linalg.solve(R, B.T @ X)


def riccati_cases() -> list[Case]:
    """The batch Riccati API. lqr_sweep: the 747 lateral regulator over 1000 weights c
    (R / c²), against Python loops over control.lqr and over scipy's CARE + gain (agreement
    on the 1000 gains). solve_care_batch: 1000 perturbed 747 lateral models (agreement on X
    and K). Ours uses every core (rayon); the loops one (plus what BLAS threads).

    The loops' times depend on OpenBLAS's threads far more than ours: on a shared 2-core
    machine a 4x4 control.lqr took 48 us per call with OPENBLAS_NUM_THREADS=1 and from 50 us
    to 0.9 ms per call with OpenBLAS's default threads, which moves the ratios by up to 20x.
    Judge the targets with OPENBLAS_NUM_THREADS=1 (and RAYON_NUM_THREADS unset, as the
    parallel sweep is the point); benches/batch_scaling.py gives the sweep's own scaling.
    """
    return [
        Case(
            op="lqr_sweep 747 lateral",
            size="1000 weights",
            seed=0,
            setup=_sweep_747,
            ours=_sweep_ours,
            peers=[
                Peer(
                    "loop control.lqr",
                    _sweep_control,
                    target=Target("lqr_sweep 1000 vs loop control.lqr: >= 25x", 25.0),
                ),
                Peer(
                    "loop scipy CARE + gain",
                    _sweep_scipy,
                    target=Target("lqr_sweep 1000 vs loop scipy: >= 100x", 100.0),
                ),
            ],
            # The targets' row: the minimum of the default repeats, as for the fast cases, so
            # that one burst of load on the shared machine does not decide it.
            repeat=None,
        ),
        Case(
            op="solve_care_batch 747 lateral",
            size="1000 models",
            seed=1,
            setup=_monte_carlo_747,
            ours=_care_batch_ours,
            peers=[
                Peer("loop control.lqr", _care_batch_control, compare=compare_tuple),
                Peer("loop scipy CARE + gain", _care_batch_scipy, compare=compare_tuple),
            ],
            repeat=3,
        ),
    ]


GROUPS = (riccati_cases,)
"""The case builders of this file, in the order they run."""
