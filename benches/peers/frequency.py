"""Peer cases of aerocontrol.frequency: the frequency response at 1000 frequencies, against
python-control."""

from __future__ import annotations

import functools
from typing import Any

import control
import numpy as np

import aerocontrol

from .harness import Case, Pairs, Peer, Target
from .inputs import SIZES, identity_outputs


def _bode747(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 longitudinal (C = I, D = 0) over 10^-3 ... 10 rad/s (phugoid to short period)."""
    A, B = aerocontrol.chapter.boeing747_longitudinal()
    return A, B, *identity_outputs(A, B), np.logspace(-3, 1, 1000)


def _bode_random(rng: np.random.Generator, n: int, m: int, p: int) -> tuple[Any, ...]:
    """A random stable model: A standard normal shifted so that its rightmost eigenvalue has
    real part -0.1; B, C standard normal, D = 0; 10^-2 ... 10^2 rad/s."""
    A = rng.standard_normal((n, n))
    A -= (np.max(np.linalg.eigvals(A).real) + 0.1) * np.eye(n)
    B = rng.standard_normal((n, m))
    C = rng.standard_normal((p, n))
    return A, B, C, np.zeros((p, m)), np.logspace(-2, 2, 1000)


def _frequency_ours(A: Any, B: Any, C: Any, D: Any, omega: np.ndarray) -> Any:
    return aerocontrol.frequency_response((A, B, C, D), omega)


def _frequency_control(A: Any, B: Any, C: Any, D: Any, omega: np.ndarray) -> Any:
    """python-control's frequency_response: with slycot installed, TB05AD (Laub's Hessenberg
    method, the same algorithm as ours) called once per frequency from a Python loop."""
    return control.frequency_response(control.ss(A, B, C, D), omega)


def _compare_magnitudes(ours: Any, peer: Any) -> Pairs:
    """|G(jω)|: ours (len(omega), p, m) against control's magnitude (p, m, len(omega)), which
    is squeezed to (len(omega),) for a SISO system."""
    k, p, m = ours.response.shape
    magnitude = np.asarray(peer.magnitude).reshape(p, m, k)
    return [(ours.magnitude, np.moveaxis(magnitude, -1, 0))]


def bode_cases() -> list[Case]:
    """G(jω) at 1000 log-spaced frequencies: the 747 longitudinal (n=4, 4 outputs, 1 input)
    and random stable n=16, 64 and 256 models with 2 inputs and 2 outputs. Agreement is on |G|.
    The issue's target was set on the 747 and n = 64; the other sizes carry none.

    Peer: python-control's frequency_response.
    """
    target = Target("bode 1000 w vs control: ratio >= 10", min_ratio=10.0)
    setups = [("n=4 747", 0, _bode747, target)]
    setups += [
        (
            f"n={n} m=2 p=2",
            n,
            functools.partial(_bode_random, n=n, m=2, p=2),
            target if n == 64 else None,
        )
        for n in SIZES
    ]
    return [
        Case(
            op="bode 1000 frequencies",
            size=size,
            seed=seed,
            setup=setup,
            ours=_frequency_ours,
            peers=[
                Peer(
                    "control.frequency_response",
                    _frequency_control,
                    compare=_compare_magnitudes,
                    target=goal,
                )
            ],
            repeat=3 if seed >= 256 else None,
        )
        for size, seed, setup, goal in setups
    ]


GROUPS = (bode_cases,)
"""The case builders of this file, in the order they run."""
