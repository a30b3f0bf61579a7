"""Side-by-side timings of aerocontrol against its peers (scipy, python-control), in one process.

Every case builds its inputs once from ``numpy.random.default_rng(seed)``, checks that our
output agrees with each peer's, then times our callable and the peer's on the same inputs, with
the repeats of the two interleaved so that a burst of load on a shared machine hits both. A
timing is the MINIMUM over several repeats of the mean over an inner loop, the inner loop count
being chosen (as ``timeit`` does) so that one repeat lasts at least ``--min-time`` seconds.

Run from the repository root with the package installed::

    python benches/compare_peers.py              # full run, table
    python benches/compare_peers.py --quick      # smoke run: every case once, a few minutes
    python benches/compare_peers.py --json       # JSON list of result records on stdout
    python benches/compare_peers.py --markdown   # the table as README.md shows it
    python benches/compare_peers.py -k expm      # only the cases whose name contains "expm"

The ratio is peer time / our time: above 1 means aerocontrol is faster. Thread settings matter:
the header prints them, and ``OPENBLAS_NUM_THREADS=1 RAYON_NUM_THREADS=1`` gives a one-core
comparison. On small shared machines a multithreaded OpenBLAS has been seen to put a whole
process in a state where scipy.linalg.expm of a 4x4 matrix takes milliseconds (LAPACK inside
scipy's pade_UV_calc); a peer time of that order on a tiny case is that, not a real speed-up.

Coverage
--------
Every public numerical operation that has a peer in scipy, python-control (with slycot) or
numpy, at n = 4 (the 747 where it is natural), 16, 64 and 256 (expm also 8 and 1024; the
batch API on 1000 problems): expm (one matrix and a stack), transition_matrix, discretize,
the step, impulse, doublet, initial-condition and forced responses, steady_state, dc_gain,
frequency_response, modes, charpoly, place_bass_gura, place_ackermann, place, companion_form,
ctrb, obsv, is_controllable, is_observable, controllability, lqr, solve_care (with S and E),
batch.lqr_sweep, batch.solve_care_batch, riccati_ode, lqr_finite, schur (plain and reordered)
and solve_lyapunov. Where a size is capped (single-input placement and the companion form:
conditioning; KNV0 placement and the Riccati ODE: the peer's time and accuracy) the case's
docstring says why. Not here, having no peer: bode (frequency_response on a default grid),
default_time_grid, default_frequency_grid, augment_mode, the design module (compositions of
the above), the aircraft module (atmosphere, models; envelope_sweep is timed by
benches/batch_scaling.py) and handling.

Adding a case
-------------
Write a function that returns a list of :class:`Case` and decorate it with ``@operation``; the
registry runs the operations in the order they are defined. A case has a ``setup(rng)`` that
returns the tuple of positional inputs, ``ours(*inputs)``, and one or more :class:`Peer` whose
``compare(ours_output, peer_output)`` maps both outputs onto pairs of arrays that must agree.
Performance goals of an issue are :class:`Target` objects attached to a (case, peer) row.
"""

from __future__ import annotations

import argparse
import functools
import json
import os
import platform
import sys
import timeit
import warnings
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import control
import numpy as np
import scipy
import scipy.integrate
import scipy.linalg
import scipy.signal
import slycot

import aerocontrol
from aerocontrol import _core

THREAD_ENV_VARS = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "RAYON_NUM_THREADS",
    "MKL_NUM_THREADS",
)

RTOL = 1e-10
"""Agreement tolerance: |ours - peer| <= RTOL |peer| + RTOL max|peer| entrywise, the max being
taken per matrix (so entries that are tiny next to the rest of their matrix are compared
normwise, not relatively)."""

Pairs = list[tuple[np.ndarray, np.ndarray]]


# ---------------------------------------------------------------------------------------------
# Case description
# ---------------------------------------------------------------------------------------------


def same(ours: Any, peer: Any) -> Pairs:
    """Default comparison: both outputs are (stacks of) arrays of the same shape."""
    return [(np.asarray(ours), np.asarray(peer))]


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


OPERATIONS: list[Callable[[], list[Case]]] = []


def operation(fn: Callable[[], list[Case]]) -> Callable[[], list[Case]]:
    """Register a function that returns the cases of one operation."""
    OPERATIONS.append(fn)
    return fn


def all_cases() -> Iterator[Case]:
    """Every registered case, in registration order."""
    for op in OPERATIONS:
        yield from op()


# ---------------------------------------------------------------------------------------------
# Inputs
# ---------------------------------------------------------------------------------------------


def random_matrix(rng: np.random.Generator, n: int, norm: float = 2.0) -> np.ndarray:
    """A standard normal n x n matrix scaled to 1-norm ``norm`` (degree 13, a few squarings)."""
    A = rng.standard_normal((n, n))
    A *= norm / np.linalg.norm(A, 1)
    return A


def identity_outputs(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """C = I and D = 0, to give scipy.signal.cont2discrete a full state-space system."""
    n, m = B.shape
    return np.eye(n), np.zeros((n, m))


def stable_plant(rng: np.random.Generator, n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """A random stable n-state, m-input plant: A = G / sqrt(n) - 3/2 I (spectrum in a disc of
    radius about 1 centred at -3/2, so every mode decays by e^-10 or more over 20 s) and B
    standard normal."""
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
    return A, rng.standard_normal((n, m))


SIZES = (16, 64, 256)
"""The random sizes every operation is run at, beside n = 4 (the 747 where it is natural)."""


# ---------------------------------------------------------------------------------------------
# Operations
# ---------------------------------------------------------------------------------------------


@operation
def expm_cases() -> list[Case]:
    """e^A of one matrix: random matrices of 1-norm 2 over a ladder of sizes, and the 747.

    Peer: scipy.linalg.expm (Al-Mohy & Higham 2009, the same algorithm family).
    """
    targets = {
        4: Target("n=4 expm: ours <= 2 us and ratio >= 5", min_ratio=5.0, max_ours=2e-6),
        64: Target("n=64: ratio >= 2", min_ratio=2.0),
        256: Target("n=256, 1024: ratio >= 1", min_ratio=1.0),
        1024: Target("n=256, 1024: ratio >= 1", min_ratio=1.0),
    }
    cases = []
    for n in (4, 8, 16, 64, 256, 1024):
        cases.append(
            Case(
                op="expm",
                size=f"n={n}",
                seed=n,
                setup=functools.partial(lambda rng, n: (random_matrix(rng, n),), n=n),
                ours=aerocontrol.expm,
                peers=[Peer("scipy.linalg.expm", scipy.linalg.expm, target=targets.get(n))],
                repeat=3 if n >= 1024 else None,
            )
        )
    cases.append(
        Case(
            op="expm 747",
            size="n=4",
            seed=0,
            setup=lambda rng: (aerocontrol.chapter.boeing747_longitudinal()[0],),
            ours=aerocontrol.expm,
            peers=[Peer("scipy.linalg.expm", scipy.linalg.expm)],
        )
    )
    return cases


def _expm_loop(stack: np.ndarray) -> list[np.ndarray]:
    """The Python loop a user writes without a batched expm."""
    return [scipy.linalg.expm(a) for a in stack]


@operation
def expm_batch_cases() -> list[Case]:
    """e^A of each matrix of a stack of 10,000 4x4 matrices (ours: parallel across cores).

    Peers: a Python loop over scipy.linalg.expm, and scipy.linalg.expm on the whole stack.
    """
    k = 10_000
    return [
        Case(
            op="expm batch",
            size=f"{k}x4x4",
            seed=10_000,
            setup=lambda rng: (rng.standard_normal((k, 4, 4)) / 2,),
            ours=aerocontrol.expm,
            peers=[
                Peer(
                    "loop scipy.linalg.expm",
                    _expm_loop,
                    target=Target("batch 10,000 4x4 vs Python loop: ratio >= 50", min_ratio=50.0),
                ),
                Peer("scipy.linalg.expm(stack)", scipy.linalg.expm),
            ],
        )
    ]


def _transition_loop(A: np.ndarray, times: np.ndarray) -> list[np.ndarray]:
    """Φ(t) = e^{At} at each time, one scipy.linalg.expm per time."""
    return [scipy.linalg.expm(A * t) for t in times]


@operation
def transition_matrix_cases() -> list[Case]:
    """Φ(t) = e^{At} at 100 times in [0, 20], on random matrices and on the 747.

    Peer: a loop of scipy.linalg.expm(A * t) over the times.
    """
    times = np.linspace(0.0, 20.0, 100)
    cases = [
        Case(
            op="transition_matrix 100 t",
            size=f"n={n}",
            seed=100 + n,
            setup=functools.partial(lambda rng, n: (random_matrix(rng, n), times), n=n),
            ours=aerocontrol.transition_matrix,
            peers=[Peer("loop scipy.linalg.expm(A*t)", _transition_loop)],
            repeat=3 if n >= 256 else None,
        )
        for n in (4, *SIZES)
    ]
    cases.append(
        Case(
            op="transition_matrix 100 t 747",
            size="n=4",
            seed=0,
            setup=lambda rng: (aerocontrol.chapter.boeing747_longitudinal()[0], times),
            ours=aerocontrol.transition_matrix,
            peers=[Peer("loop scipy.linalg.expm(A*t)", _transition_loop)],
        )
    )
    return cases


def _cont2discrete(method: str) -> Callable[[np.ndarray, np.ndarray, float], Any]:
    """scipy.signal.cont2discrete on (A, B, I, 0), as a user would call it."""

    def peer(A: np.ndarray, B: np.ndarray, dt: float) -> Any:
        C, D = identity_outputs(A, B)
        return scipy.signal.cont2discrete((A, B, C, D), dt, method=method)

    return peer


def _compare_cont2discrete(method: str) -> Callable[[Any, Any], Pairs]:
    """Map our Φ, Γ0, Γ1 onto scipy's (Ad, Bd, Cd, Dd, dt).

    For "foh" scipy returns a realisation in the shifted state x - Γ1 η: Ad = Φ,
    Bd = Γ0 - Γ1 + Φ Γ1 and Dd = D + C Γ1 = Γ1 (C = I, D = 0).
    """

    def compare(ours: Any, peer: Any) -> Pairs:
        Ad, Bd, _, Dd, _ = peer
        if method == "zoh":
            return [(ours.Phi, Ad), (ours.Gamma0, Bd)]
        bd = ours.Gamma0 - ours.Gamma1 + ours.Phi @ ours.Gamma1
        return [(ours.Phi, Ad), (bd, Bd), (ours.Gamma1, Dd)]

    return compare


def _van_loan_expm(method: str) -> Callable[[np.ndarray, np.ndarray, float], Any]:
    """The bare kernel under cont2discrete: scipy.linalg.expm of the Van Loan block matrix."""

    def peer(A: np.ndarray, B: np.ndarray, dt: float) -> Any:
        n, m = B.shape
        size = n + m if method == "zoh" else n + 2 * m
        M = np.zeros((size, size))
        M[:n, :n] = A * dt
        M[:n, n : n + m] = B * dt
        if method == "foh":
            M[n : n + m, n + m :] = np.eye(m)
        return scipy.linalg.expm(M)

    return peer


def _compare_van_loan(method: str) -> Callable[[Any, Any], Pairs]:
    """Blocks of the Van Loan exponential: [[Φ, Γ0, Γ1], ...]."""

    def compare(ours: Any, E: Any) -> Pairs:
        n, m = ours.Gamma0.shape
        pairs = [(ours.Phi, E[:n, :n]), (ours.Gamma0, E[:n, n : n + m])]
        if method == "foh":
            pairs.append((ours.Gamma1, E[:n, n + m :]))
        return pairs

    return compare


@operation
def discretize_cases() -> list[Case]:
    """Exact ZOH and FOH discretisation: the 747 longitudinal (n=4, one input, dt=0.05) and
    random n=16, 64 and 256 plants with 2 inputs.

    Peers: scipy.signal.cont2discrete((A, B, I, 0)) and, to separate the kernel from the
    wrapper, scipy.linalg.expm of the same Van Loan block matrix that cont2discrete builds.
    """

    def plant747(rng: np.random.Generator) -> tuple[Any, ...]:
        A, B = aerocontrol.chapter.boeing747_longitudinal()
        return A, B, 0.05

    def plant(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
        A = random_matrix(rng, n)
        B = rng.standard_normal((n, 2))
        return A, B, 0.05

    plants = [("n=4 747", 0, plant747)]
    plants += [(f"n={n} m=2", n, functools.partial(plant, n=n)) for n in SIZES]
    cases = []
    for method in ("zoh", "foh"):
        for size, seed, setup in plants:
            cases.append(
                Case(
                    op=f"discretize {method}",
                    size=size,
                    seed=seed,
                    setup=setup,
                    ours=functools.partial(_discretize, method=method),
                    peers=[
                        Peer(
                            "scipy.signal.cont2discrete",
                            _cont2discrete(method),
                            compare=_compare_cont2discrete(method),
                        ),
                        Peer(
                            "scipy.linalg.expm(Van Loan)",
                            _van_loan_expm(method),
                            compare=_compare_van_loan(method),
                        ),
                    ],
                    repeat=3 if seed >= 256 else None,
                )
            )
    return cases


def _discretize(A: np.ndarray, B: np.ndarray, dt: float, method: str) -> Any:
    return aerocontrol.discretize(A, B, dt, method=method)  # type: ignore[arg-type]


def _boeing747_times(rng: np.random.Generator, samples: int) -> tuple[Any, ...]:
    """The 747 longitudinal model and ``samples`` times uniformly on [0, 500] s."""
    A, B = aerocontrol.chapter.boeing747_longitudinal()
    return A, B, np.linspace(0.0, 500.0, samples)


def _compare_control_time_response(ours: Any, peer: Any) -> Pairs:
    """Our outputs and states (len(t), p) and (len(t), n) against python-control's
    ``outputs`` and ``states``, (p, [1,] len(t)) and (n, [1,] len(t)) (squeezed or not)."""
    k = len(ours.t)
    return [
        (ours.y, np.asarray(peer.outputs).reshape(-1, k).T),
        (ours.x, np.asarray(peer.states).reshape(-1, k).T),
    ]


def _step_ours(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    """A unit step (eta0 = 1, as the peers' steps), not the chapter's one degree."""
    return aerocontrol.step_response((A, B), T=t, eta0=[1.0])


def _step_control(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    return control.step_response(control.ss(A, B, *identity_outputs(A, B)), T=t)


def _step_scipy(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    return scipy.signal.step((A, B, *identity_outputs(A, B)), T=t)


def _random_times(rng: np.random.Generator, n: int, samples: int = 1001) -> tuple[Any, ...]:
    """A random stable single-input plant (:func:`stable_plant`) and ``samples`` times on
    [0, 20] s. The peers step through the grid in a Python loop, so the grid is kept at 1001
    samples at every size."""
    A, B = stable_plant(rng, n, 1)
    return A, B, np.linspace(0.0, 20.0, samples)


@operation
def step_response_cases() -> list[Case]:
    """Unit step response of the 747 longitudinal model (C = I) on 5001 and 50001 samples of
    [0, 500] s, and of random stable single-input plants (n = 16, 64, 256; C = I) on 1001
    samples of [0, 20] s.

    Peers: python-control's step_response and scipy.signal.step on (A, B, I, 0).
    """
    cases = []
    for samples in (5001, 50001):
        cases.append(
            Case(
                op="step_response 747",
                size=f"{samples} samples",
                seed=0,
                setup=functools.partial(_boeing747_times, samples=samples),
                ours=_step_ours,
                peers=[
                    Peer(
                        "control.step_response",
                        _step_control,
                        compare=_compare_control_time_response,
                        target=Target("step vs control: ratio >= 50", min_ratio=50.0),
                    ),
                    Peer(
                        "scipy.signal.step",
                        _step_scipy,
                        compare=lambda ours, peer: [(ours.y, peer[1])],
                        target=Target("step vs scipy: ratio >= 30", min_ratio=30.0),
                    ),
                ],
                repeat=3 if samples >= 50001 else None,
            )
        )
    cases += [
        Case(
            op="step_response",
            size=f"n={n} 1001 samples",
            seed=n,
            setup=functools.partial(_random_times, n=n),
            ours=_step_ours,
            peers=[
                Peer(
                    "control.step_response", _step_control, compare=_compare_control_time_response
                ),
                Peer(
                    "scipy.signal.step", _step_scipy, compare=lambda ours, peer: [(ours.y, peer[1])]
                ),
            ],
            repeat=3 if n >= 256 else None,
        )
        for n in SIZES
    ]
    return cases


def _impulse_ours(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    return aerocontrol.impulse_response((A, B), T=t)


def _impulse_control(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    return control.impulse_response(control.ss(A, B, *identity_outputs(A, B)), T=t)


def _impulse_scipy(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    return scipy.signal.impulse((A, B, *identity_outputs(A, B)), T=t)


def _initial_setup(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A random stable plant, 1001 times of [0, 20] s and a standard normal x0; the 747
    longitudinal model from x0 = (1 ft/s, 0.01, 0.01 rad/s, 0.01 rad) on 5001 times of
    [0, 500] s for n = 4."""
    if n == 4:
        A, B, t = _boeing747_times(rng, 5001)
        return A, B, t, np.array([1.0, 0.01, 0.01, 0.01])
    A, B, t = _random_times(rng, n)
    return A, B, t, rng.standard_normal(n)


def _initial_ours(A: np.ndarray, B: np.ndarray, t: np.ndarray, x0: np.ndarray) -> Any:
    return aerocontrol.initial_response((A, B), x0, T=t)


def _initial_control(A: np.ndarray, B: np.ndarray, t: np.ndarray, x0: np.ndarray) -> Any:
    return control.initial_response(control.ss(A, B, *identity_outputs(A, B)), T=t, X0=x0)


def _initial_scipy(A: np.ndarray, B: np.ndarray, t: np.ndarray, x0: np.ndarray) -> Any:
    """scipy has no initial response of its own: lsim with a zero input from x0."""
    return scipy.signal.lsim((A, B, *identity_outputs(A, B)), np.zeros(len(t)), t, X0=x0)


def _doublet_ours(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    return aerocontrol.doublet_response((A, B), T=t)


def _doublet_control(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    """The response to η = δ'(t) is the free response from x(0) = A B (6.38); python-control
    has no doublet, so its initial_response from there."""
    sys = control.ss(A, B, *identity_outputs(A, B))
    return control.initial_response(sys, T=t, X0=A @ B[:, 0])


def _doublet_scipy(A: np.ndarray, B: np.ndarray, t: np.ndarray) -> Any:
    """scipy.signal.impulse of (A, A B, I, 0): its free response from A B."""
    return scipy.signal.impulse((A, A @ B, *identity_outputs(A, B)), T=t)


def _response_setup(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The 747 longitudinal model on 5001 times of [0, 500] s for n = 4, a random stable
    single-input plant on 1001 times of [0, 20] s otherwise."""
    return _boeing747_times(rng, 5001) if n == 4 else _random_times(rng, n)


@operation
def free_response_cases() -> list[Case]:
    """The impulse, doublet and initial-condition responses (C = I): the 747 longitudinal
    model on 5001 samples of [0, 500] s, random stable single-input plants (n = 16, 64, 256)
    on 1001 samples of [0, 20] s. Agreement on x and y against python-control, on y against
    scipy.

    Peers: python-control's impulse_response and initial_response (from x0, and from A B for
    the doublet, which python-control lacks); scipy.signal.impulse (of (A, A B, I, 0) for the
    doublet) and scipy.signal.lsim with a zero input for the initial response.
    """
    kinds = (
        (
            "impulse_response",
            _impulse_ours,
            _response_setup,
            ("control.impulse_response", _impulse_control),
            ("scipy.signal.impulse", _impulse_scipy),
        ),
        (
            "doublet_response",
            _doublet_ours,
            _response_setup,
            ("control.initial_response(A B)", _doublet_control),
            ("scipy.signal.impulse(A, A B)", _doublet_scipy),
        ),
        (
            "initial_response",
            _initial_ours,
            _initial_setup,
            ("control.initial_response", _initial_control),
            ("scipy.signal.lsim(u=0)", _initial_scipy),
        ),
    )
    cases = []
    for op, ours, setup, (control_name, control_fn), (scipy_name, scipy_fn) in kinds:
        for n in (4, *SIZES):
            cases.append(
                Case(
                    op=f"{op} 747" if n == 4 else op,
                    size="n=4 5001 samples" if n == 4 else f"n={n} 1001 samples",
                    seed=n,
                    setup=functools.partial(setup, n=n),
                    ours=ours,
                    peers=[
                        Peer(control_name, control_fn, compare=_compare_control_time_response),
                        Peer(scipy_name, scipy_fn, compare=lambda ours, peer: [(ours.y, peer[1])]),
                    ],
                    repeat=3 if n >= 256 else None,
                )
            )
    return cases


def _forced_setup(rng: np.random.Generator, samples: int) -> tuple[Any, ...]:
    """The 747 and one degree of sinusoidal elevator at 0.3 rad/s (between the phugoid and the
    short period) on ``samples`` times of [0, 500] s."""
    A, B, t = _boeing747_times(rng, samples)
    return A, B, t, np.sin(0.3 * t) * np.pi / 180


def _forced_ours(A: np.ndarray, B: np.ndarray, t: np.ndarray, u: np.ndarray) -> Any:
    return aerocontrol.forced_response((A, B), t, u, method="foh")


def _forced_scipy(A: np.ndarray, B: np.ndarray, t: np.ndarray, u: np.ndarray) -> Any:
    """scipy.signal.lsim with its default interp=True: a first-order hold, like ours."""
    return scipy.signal.lsim((A, B, *identity_outputs(A, B)), u, t)


def _forced_control(A: np.ndarray, B: np.ndarray, t: np.ndarray, u: np.ndarray) -> Any:
    return control.forced_response(control.ss(A, B, *identity_outputs(A, B)), t, u)


def _forced_random(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A random stable single-input plant and u = sin(t) on 1001 times of [0, 20] s."""
    A, B, t = _random_times(rng, n)
    return A, B, t, np.sin(t)


@operation
def forced_response_cases() -> list[Case]:
    """Response of the 747 (C = I) to a sampled sinusoidal elevator, first-order hold, on 50001
    samples of [0, 500] s, and of random stable single-input plants (n = 16, 64, 256) to
    u = sin(t) on 1001 samples of [0, 20] s.

    Peers: scipy.signal.lsim (interp=True, first-order hold) and python-control's
    forced_response (also linear between input samples).
    """
    samples = 50001
    cases = [
        Case(
            op="forced_response 747",
            size=f"{samples} samples",
            seed=0,
            setup=functools.partial(_forced_setup, samples=samples),
            ours=_forced_ours,
            peers=[
                Peer(
                    "scipy.signal.lsim",
                    _forced_scipy,
                    compare=lambda ours, peer: [(ours.y, peer[1]), (ours.x, peer[2])],
                    target=Target("forced (foh) vs scipy lsim: ratio >= 50", min_ratio=50.0),
                ),
                Peer(
                    "control.forced_response",
                    _forced_control,
                    compare=_compare_control_time_response,
                ),
            ],
            repeat=3,
        )
    ]
    cases += [
        Case(
            op="forced_response",
            size=f"n={n} 1001 samples",
            seed=n,
            setup=functools.partial(_forced_random, n=n),
            ours=_forced_ours,
            peers=[
                Peer(
                    "scipy.signal.lsim",
                    _forced_scipy,
                    compare=lambda ours, peer: [(ours.y, peer[1]), (ours.x, peer[2])],
                ),
                Peer(
                    "control.forced_response",
                    _forced_control,
                    compare=_compare_control_time_response,
                ),
            ],
            repeat=3 if n >= 256 else None,
        )
        for n in SIZES
    ]
    return cases


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


@operation
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


def _steady_setup(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The 747 longitudinal (C = I) and one degree of elevator for n = 4; otherwise a random
    stable plant with 2 inputs, 2 outputs (C standard normal, D = 0) and η0 = (1, -1/2)."""
    if n == 4:
        A, B = aerocontrol.chapter.boeing747_longitudinal()
        return A, B, *identity_outputs(A, B), np.array([np.pi / 180])
    A, B = stable_plant(rng, n, 2)
    return A, B, rng.standard_normal((2, n)), np.zeros((2, 2)), np.array([1.0, -0.5])


def _steady_ours(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return aerocontrol.steady_state((A, B), eta0)


def _steady_numpy(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return np.linalg.solve(A, -(B @ eta0))


def _dc_gain_ours(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return aerocontrol.dc_gain((A, B, C, D))


def _dc_gain_control(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return control.dcgain(control.ss(A, B, C, D))


def _dc_gain_numpy(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return D - C @ np.linalg.solve(A, B)


@operation
def steady_state_cases() -> list[Case]:
    """The steady state x∞ = -A^-1 B η0 of a step and the DC gain D - C A^-1 B: the 747
    longitudinal model, random stable plants with 2 inputs and 2 outputs (n = 16, 64, 256).

    Peers: numpy.linalg.solve (both), python-control's dcgain (squeezed for one input, so
    compared after a reshape).
    """
    cases = []
    for n in (4, *SIZES):
        size = "n=4 747" if n == 4 else f"n={n} m=2 p=2"
        setup = functools.partial(_steady_setup, n=n)
        cases.append(
            Case(
                op="steady_state",
                size=size,
                seed=n,
                setup=setup,
                ours=_steady_ours,
                peers=[Peer("numpy.linalg.solve", _steady_numpy)],
            )
        )
        cases.append(
            Case(
                op="dc_gain",
                size=size,
                seed=n,
                setup=setup,
                ours=_dc_gain_ours,
                peers=[
                    Peer(
                        "control.dcgain",
                        _dc_gain_control,
                        compare=lambda ours, peer: [(ours, np.reshape(peer, ours.shape))],
                    ),
                    Peer("D - C solve(A, B)", _dc_gain_numpy),
                ],
            )
        )
    return cases


def _modal_matrix(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The 747 lateral A for n = 4 (spiral, Dutch roll, roll); a standard normal A / sqrt(n),
    spectrum in about the unit disc, otherwise."""
    if n == 4:
        return (aerocontrol.chapter.boeing747_lateral()[0],)
    return (rng.standard_normal((n, n)) / np.sqrt(n),)


def _damping(eigenvalues: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ω_n and ζ of each mode (a conjugate pair counts once, by its member with Im >= 0)."""
    mode = eigenvalues[eigenvalues.imag >= 0]
    wn = np.abs(mode)
    return wn, -mode.real / wn


def _modes_numpy(A: Any) -> Any:
    """What ``modes`` computes, with numpy: eigenvalues, unit eigenvectors, κ₂ of the modal
    matrix and the damping of each mode."""
    w, V = np.linalg.eig(A)
    wn, zeta = _damping(w)
    return w, wn, zeta, np.linalg.cond(V)


def _modes_control(A: Any) -> Any:
    """python-control's damp (eigenvalues only: no modal matrix, no condition number)."""
    n = A.shape[0]
    *_, poles = control.damp(control.ss(A, np.zeros((n, 1)), np.zeros((1, n)), 0), False)
    return poles, *_damping(np.asarray(poles))


def _mode_pairs(eigenvalues: Any, wn: Any, zeta: Any) -> Pairs:
    """All eigenvalues sorted (real, imaginary parts), and ω_n, ζ per mode sorted by ω_n."""
    ev = np.sort_complex(np.asarray(eigenvalues))
    order = np.lexsort((zeta, wn))
    return [(ev.real, ev.imag), (np.asarray(wn)[order], np.asarray(zeta)[order])]


def _compare_modes(ours: Any, peer: Any) -> Pairs:
    """Eigenvalues, ω_n and ζ per mode (and κ₂(P) against numpy's cond of its eigenvectors)."""
    mine = _mode_pairs(ours.eigenvalues, ours.natural_frequency, ours.damping_ratio)
    theirs = _mode_pairs(*peer[:3])
    pairs = [(a[0], b[0]) for a, b in zip(mine, theirs, strict=True)]
    pairs += [(a[1], b[1]) for a, b in zip(mine, theirs, strict=True)]
    if len(peer) == 4:
        pairs.append((np.array([ours.modal_matrix_condition]), np.array([peer[3]])))
    return pairs


def _charpoly_case(n: int) -> Case:
    """charpoly against numpy.poly, compared coefficient by coefficient relative to
    e_k(|λ|), the elementary symmetric function of the eigenvalue moduli: each a_k is only
    determined to about u e_k(|λ|) (see aerocontrol.charpoly), and e_k(|λ|) exceeds |a_k| by
    many orders of magnitude at n = 256 where the a_k cancel (an unscaled comparison there
    measures that cancellation, 6e-8 for this matrix, not either code)."""
    scale: dict[str, np.ndarray] = {}

    def setup(rng: np.random.Generator) -> tuple[Any, ...]:
        (A,) = _modal_matrix(rng, n)
        scale["e"] = np.poly(-np.abs(np.linalg.eigvals(A))).real
        return (A,)

    def compare(ours: Any, peer: Any) -> Pairs:
        return [(ours / scale["e"], np.real(peer) / scale["e"])]

    return Case(
        op="charpoly",
        size="n=4 747 lateral" if n == 4 else f"n={n}",
        seed=n,
        setup=setup,
        ours=aerocontrol.charpoly,
        peers=[Peer("numpy.poly", np.poly, compare=compare)],
    )


@operation
def modal_cases() -> list[Case]:
    """Modal analysis and the characteristic polynomial: the 747 lateral A (n=4), random
    A / sqrt(n) at n = 16, 64, 256.

    ``modes`` is compared on the sorted eigenvalues, ω_n and ζ per mode, and (against numpy)
    κ₂ of the modal matrix. Peers: numpy.linalg.eig + numpy.linalg.cond + the damping (the
    same work as ours: ours also forms the characteristic polynomial), and python-control's
    damp (eigenvalues only).
    """
    cases = []
    for n in (4, *SIZES):
        cases.append(
            Case(
                op="modes",
                size="n=4 747 lateral" if n == 4 else f"n={n}",
                seed=n,
                setup=functools.partial(_modal_matrix, n=n),
                ours=aerocontrol.modes,
                peers=[
                    Peer("numpy eig + cond + damping", _modes_numpy, compare=_compare_modes),
                    Peer("control.damp", _modes_control, compare=_compare_modes),
                ],
                repeat=3 if n >= 256 else None,
            )
        )
        cases.append(_charpoly_case(n))
    return cases


def _dutch_roll_rudder(rng: np.random.Generator) -> tuple[Any, ...]:
    """The chapter's design (6.156)-(6.159): 747 lateral model, rudder, Dutch roll to ζ 0.3."""
    A, B = aerocontrol.chapter.boeing747_lateral()
    return A, np.ascontiguousarray(B[:, :1]), aerocontrol.augment_mode(A, 1, zeta=0.30)


def _placement_problem(rng: np.random.Generator, n: int, m: int) -> tuple[Any, ...]:
    """A random n-state, m-input plant and n distinct stable poles, a third of them in
    conjugate pairs."""
    A = rng.standard_normal((n, n))
    B = rng.standard_normal((n, m))
    poles = -rng.uniform(0.5, 3.0, n).astype(complex)
    for k in range(0, n // 3 * 2 - 1, 2):
        poles[k] = complex(poles[k].real, rng.uniform(0.5, 2.0))
        poles[k + 1] = poles[k].conjugate()
    return A, B, poles


def _lateral_poles(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 lateral model with rudder and aileron, and the poles of the example of
    aerocontrol.place: -0.5 ± 0.8j, -1.2, -0.1."""
    A, B = aerocontrol.chapter.boeing747_lateral()
    return A, B, np.array([-0.5 + 0.8j, -0.5 - 0.8j, -1.2, -0.1])


def _placement_real(rng: np.random.Generator, n: int, m: int) -> tuple[Any, ...]:
    """A random n-state, m-input plant and n distinct real stable poles (scipy's KNV0 takes
    no complex poles)."""
    A = rng.standard_normal((n, n))
    B = rng.standard_normal((n, m))
    return A, B, -rng.uniform(0.5, 3.0, n)


def _siso_butterworth(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A random single-input plant, A = G / sqrt(n), and the n Butterworth poles of radius 1:
    spread on the left half circle, the best-conditioned pole set for one input."""
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    b = rng.standard_normal((n, 1))
    k = np.arange(n)
    return A, b, np.sort_complex(np.exp(1j * np.pi * (2 * k + n + 1) / (2 * n)))


def _place_gain(A: Any, B: Any, poles: Any) -> Any:
    return aerocontrol.place_bass_gura(A, B, poles).K


def _ackermann_gain(A: Any, B: Any, poles: Any) -> Any:
    return aerocontrol.place_ackermann(A, B, poles).K


def _acker(A: Any, B: Any, poles: Any) -> Any:
    return np.atleast_2d(control.acker(A, B, poles))


def _place_ours(A: Any, B: Any, poles: Any) -> Any:
    return aerocontrol.place(A, B, poles)


def _place_scipy(A: Any, B: Any, poles: Any) -> Any:
    return scipy.signal.place_poles(A, B, poles)


def _place_scipy_knv0(A: Any, B: Any, poles: Any) -> Any:
    """scipy's KNV0. It warns "Convergence was not reached after maxiter iterations ... we got
    1.0" after its 30 sweeps whatever the progress, so the warning is silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return scipy.signal.place_poles(A, B, poles, method="KNV0")


def _compare_closed_loop_poles(ours: Any, peer: Any) -> Pairs:
    """The gains of two robust methods differ, so the check is that our closed loop has the
    poles requested (as scipy echoes them). scipy's own placement is not the reference: on
    the n=16 case its Tits-Yang gains miss by 1.4e-5 relatively, ours by 1.9e-11."""
    mine = np.sort_complex(np.linalg.eigvals(ours.closed_loop))
    requested = np.sort_complex(np.asarray(peer.requested_poles))
    return [(mine.real, requested.real), (mine.imag, requested.imag)]


@operation
def placement_cases() -> list[Case]:
    """Pole placement. Single input: Bass-Gura and Ackermann on the chapter's 747 Dutch-roll
    damper and on a random n=8 plant with Butterworth poles, against python-control's acker
    (agreement on K). Several inputs: Kautsky-Nichols-Van Dooren against scipy's place_poles
    (agreement on the closed-loop poles): its default, Tits-Yang, on the 747 lateral model
    (rudder and aileron) and at n = 4 and 16 with m = 2;
    its KNV0, the same method as ours, at n = 64 with m = 16 and real poles.

    Why single input stops at n = 8: the single-input gain is unique, and placing n poles
    with one input is exponentially ill-conditioned in n. With Butterworth poles (the kindest
    set) our gains and acker's still agree at n = 16 (2e-13 scaled) but neither places the
    poles: the closed loops miss them by 2e-5 (ours) and 2 (acker) relatively, so there is no
    meaningful answer to compare; at n = 12 the miss is already 3e-9, at n = 8 it is 3e-11.
    At n = 64 acker refuses (its ctrb is numerically singular).

    Why several inputs stop at n = 64, m = 16: with m = 2 a random n=64 problem has no
    well-conditioned solution (κ(X) ~ 5e16, both methods miss poles by O(1)); m = 16 gives
    κ(X) ~ 3e4. scipy's Tits-Yang took 12-130 s per call at n = 64 with m = 4-16 (a Python
    loop over eigenvector pairs; its KNV0 about 0.3 s), and its KNV0 rejects complex poles,
    hence KNV0 and real poles here. n = 256 would take scipy minutes per call: not run.
    """
    siso = Target("SISO n=4: <= 3 us and >= 20x control.acker", min_ratio=20.0, max_ours=3e-6)
    mimo = Target("MIMO m=2 vs scipy place_poles: ratio >= 20", min_ratio=20.0)
    cases = [
        Case(
            op=f"place SISO ({name})",
            size="n=4 747 rudder",
            seed=0,
            setup=_dutch_roll_rudder,
            ours=ours,
            peers=[Peer("control.acker", _acker, target=siso)],
        )
        for name, ours in (("Bass-Gura", _place_gain), ("Ackermann", _ackermann_gain))
    ]
    cases += [
        Case(
            op=f"place SISO ({name})",
            size="n=8 Butterworth",
            seed=8,
            setup=functools.partial(_siso_butterworth, n=8),
            ours=ours,
            peers=[Peer("control.acker", _acker)],
        )
        for name, ours in (("Bass-Gura", _place_gain), ("Ackermann", _ackermann_gain))
    ]
    cases.append(
        Case(
            op="place MIMO (KNV0)",
            size="n=4 747 lateral m=2",
            seed=0,
            setup=_lateral_poles,
            ours=_place_ours,
            peers=[
                Peer(
                    "scipy.signal.place_poles",
                    _place_scipy,
                    compare=_compare_closed_loop_poles,
                    target=mimo,
                )
            ],
        )
    )
    for n in (4, 16):
        cases.append(
            Case(
                op="place MIMO (KNV0)",
                size=f"n={n} m=2",
                seed=n,
                setup=functools.partial(_placement_problem, n=n, m=2),
                ours=_place_ours,
                peers=[
                    Peer(
                        "scipy.signal.place_poles",
                        _place_scipy,
                        compare=_compare_closed_loop_poles,
                        target=mimo,
                    )
                ],
                repeat=3 if n > 4 else None,
            )
        )
    cases.append(
        Case(
            op="place MIMO (KNV0)",
            size="n=64 m=16 real",
            seed=64,
            setup=functools.partial(_placement_real, n=64, m=16),
            ours=_place_ours,
            peers=[
                Peer(
                    "scipy place_poles KNV0",
                    _place_scipy_knv0,
                    compare=_compare_closed_loop_poles,
                )
            ],
            repeat=3,
        )
    )
    return cases


def _companion_setup(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The 747 lateral model and its rudder for n = 4; A = G / sqrt(n) and a standard normal
    b otherwise."""
    if n == 4:
        A, B = aerocontrol.chapter.boeing747_lateral()
        return A, np.ascontiguousarray(B[:, :1])
    return rng.standard_normal((n, n)) / np.sqrt(n), rng.standard_normal((n, 1))


def _companion_control(A: Any, b: Any) -> Any:
    """python-control's reachable_form (SISO only; C = 1^T is irrelevant to A and T)."""
    n = A.shape[0]
    return control.reachable_form(control.ss(A, b, np.ones((1, n)), 0))


@operation
def companion_cases() -> list[Case]:
    """The first companion form and its transformation T = (V W)^-1 of a single-input pair:
    the 747 lateral with the rudder, random pairs at n = 8 and 16.

    Peer: python-control's reachable_form (the same companion matrix and z = T x), agreement
    on both. Stops at n = 16: T is built on the controllability matrix V, κ(T) ~ 2e4 at
    n = 16, and at n = 64 reachable_form refuses ("not controllable to working precision",
    its matrix_rank of V).
    """
    return [
        Case(
            op="companion_form",
            size="n=4 747 rudder" if n == 4 else f"n={n}",
            seed=n,
            setup=functools.partial(_companion_setup, n=n),
            ours=aerocontrol.companion_form,
            peers=[
                Peer(
                    "control.reachable_form",
                    _companion_control,
                    compare=lambda ours, peer: [(ours.companion, peer[0].A), (ours.T, peer[1])],
                )
            ],
        )
        for n in (4, 8, 16)
    ]


def _random_pair(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    return rng.standard_normal((n, n)), rng.standard_normal((n, 1))


def _pair_747(rng: np.random.Generator) -> tuple[Any, ...]:
    """The 747 lateral model with both inputs (rudder, aileron)."""
    return aerocontrol.chapter.boeing747_lateral()


def _verdict_full(A: Any, B: Any) -> Any:
    return np.array([aerocontrol.is_controllable(A, B)])


def _verdict_staircase(A: Any, B: Any) -> Any:
    return np.array([aerocontrol.is_controllable(A, B, method="staircase")])


def _verdict_rank(A: Any, B: Any) -> Any:
    return np.array([np.linalg.matrix_rank(control.ctrb(A, B)) == A.shape[0]])


def _verdict_slycot(A: Any, B: Any) -> Any:
    """SLICOT AB01ND (python-control's backend, through slycot): the staircase form with its
    default rank tolerance n² u max(||A||_F, ||B||_F); controllable when ncont = n."""
    n, m = B.shape
    return np.array([slycot.ab01nd(n, m, A, B)[2] == n])


def _observable_full(A: Any, C: Any) -> Any:
    return np.array([aerocontrol.is_observable(A, C)])


def _observable_rank(A: Any, C: Any) -> Any:
    return np.array([np.linalg.matrix_rank(control.obsv(A, C)) == A.shape[0]])


def _observable_slycot(A: Any, C: Any) -> Any:
    """AB01ND on the dual pair (A^T, C^T)."""
    p, n = C.shape
    return np.array([slycot.ab01nd(n, p, A.T.copy(), C.T.copy())[2] == n])


def _random_output_pair(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A standard normal A and one standard normal output row C; the 747 lateral model
    observed through its yaw rate r alone for n = 4."""
    if n == 4:
        return aerocontrol.chapter.boeing747_lateral()[0], np.array([[0.0, 0.0, 0.0, 1.0]])
    return rng.standard_normal((n, n)), rng.standard_normal((1, n))


def _planted(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A 2-input plant with n/4 planted uncontrollable modes: [[A_c, A_12], [0, A_u]] and
    [[B_c], [0]] (A_c, A_12 standard normal / sqrt(n), A_u standard normal / sqrt(n/4), so its
    eigenvalues lie among the controllable ones), in the basis of a random orthogonal U."""
    r = n // 4
    A0 = np.zeros((n, n))
    A0[: n - r, :] = rng.standard_normal((n - r, n)) / np.sqrt(n)
    A0[n - r :, n - r :] = rng.standard_normal((r, r)) / np.sqrt(r)
    B0 = np.zeros((n, 2))
    B0[: n - r] = rng.standard_normal((n - r, 2))
    U = np.linalg.qr(rng.standard_normal((n, n)))[0]
    return U @ A0 @ U.T, U @ B0


def _uncontrollable_ours(A: Any, B: Any) -> Any:
    return aerocontrol.controllability(A, B).uncontrollable_eigenvalues


def _uncontrollable_slycot(A: Any, B: Any) -> Any:
    """The eigenvalues of the uncontrollable block A_u of AB01ND's staircase form."""
    n, m = B.shape
    Ac, _, ncont, *_ = slycot.ab01nd(n, m, A, B)
    return np.linalg.eigvals(Ac[ncont:, ncont:])


def _compare_eigenvalue_sets(ours: Any, peer: Any) -> Pairs:
    """How many, then the sorted values (real and imaginary parts)."""
    mine, theirs = np.sort_complex(np.asarray(ours)), np.sort_complex(np.asarray(peer))
    return [
        (np.array([len(mine)]), np.array([len(theirs)])),
        (mine.real, theirs.real),
        (mine.imag, theirs.imag),
    ]


@operation
def controllability_cases() -> list[Case]:
    """Controllability and observability.

    * is_controllable: the 747 lateral (both inputs) and random single-input pairs (n = 16,
      64, 256; all controllable). Peers: python-control's ctrb with numpy's matrix_rank, and
      SLICOT's staircase AB01ND (through slycot). The rank answers False at n = 64 (rank 61)
      and 256: the rows report that disagreement, which is the point of not using the rank.
    * is_observable: the dual, the 747 lateral seen through r alone and random single-output
      pairs; the same peers on obsv and on (A^T, C^T). The rank of obsv again answers False
      at n = 64 and 256.
    * controllability: the uncontrollable eigenvalues of 2-input plants with n/4 planted
      uncontrollable modes (n = 4, 16, 64, 256), against the eigenvalues of AB01ND's
      uncontrollable block. With its default tolerance AB01ND finds the planted modes up to
      n = 32 and none of them at n = 64 and 256 (ncont = n): those rows disagree, and the
      planted A_u is the arbiter (ours matches its eigenvalues, to 3e-13 at n = 256).
    """
    target = Target("verdict n=64: faster than ctrb + matrix_rank", min_ratio=1.0)
    cases = []
    for n in (4, *SIZES):
        pair = _pair_747 if n == 4 else functools.partial(_random_pair, n=n)
        for method, ours in (("full", _verdict_full), ("staircase", _verdict_staircase)):
            cases.append(
                Case(
                    op=f"is_controllable ({method})",
                    size="n=4 747 lateral" if n == 4 else f"n={n} m=1",
                    seed=0 if n == 64 else n,
                    setup=pair,
                    ours=ours,
                    peers=[
                        Peer(
                            "control.ctrb + matrix_rank",
                            _verdict_rank,
                            target=target if n == 64 else None,
                        ),
                        Peer("slycot ab01nd", _verdict_slycot),
                    ],
                )
            )
    for n in (4, *SIZES):
        cases.append(
            Case(
                op="is_observable",
                size="n=4 747 lateral, r" if n == 4 else f"n={n} p=1",
                seed=n,
                setup=functools.partial(_random_output_pair, n=n),
                ours=_observable_full,
                peers=[
                    Peer("control.obsv + matrix_rank", _observable_rank),
                    Peer("slycot ab01nd(A^T, C^T)", _observable_slycot),
                ],
            )
        )
    for n in (4, *SIZES):
        cases.append(
            Case(
                op="controllability (planted)",
                size=f"n={n} m=2, {n // 4} unreachable",
                seed=n,
                setup=functools.partial(_planted, n=n),
                ours=_uncontrollable_ours,
                peers=[
                    Peer(
                        "slycot ab01nd eig(A_u)",
                        _uncontrollable_slycot,
                        compare=_compare_eigenvalue_sets,
                    )
                ],
                repeat=3 if n >= 256 else None,
            )
        )
    return cases


def _krylov_setup(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A (n, n), B (n, 2) and C (2, n): the 747 lateral (B its two inputs, C = B^T) for n = 4;
    A = G / sqrt(n) (spectral radius about 1, so A^(n-1) B neither overflows nor underflows)
    otherwise."""
    if n == 4:
        A, B = aerocontrol.chapter.boeing747_lateral()
        return A, B, B.T.copy()
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    return A, rng.standard_normal((n, 2)), rng.standard_normal((2, n))


@operation
def krylov_cases() -> list[Case]:
    """The controllability matrix [B AB ... A^(n-1)B] and the observability matrix
    [C; CA; ...; CA^(n-1)], 2 inputs / outputs, the 747 lateral and random A / sqrt(n).

    Peers: python-control's ctrb and obsv.
    """
    cases = []
    for n in (4, *SIZES):
        size = "n=4 747 lateral" if n == 4 else f"n={n} m=2"
        setup = functools.partial(_krylov_setup, n=n)
        cases.append(
            Case(
                op="ctrb",
                size=size,
                seed=n,
                setup=setup,
                ours=lambda A, B, C: aerocontrol.ctrb(A, B),
                peers=[Peer("control.ctrb", lambda A, B, C: control.ctrb(A, B))],
            )
        )
        cases.append(
            Case(
                op="obsv",
                size=size,
                seed=n,
                setup=setup,
                ours=lambda A, B, C: aerocontrol.obsv(A, C),
                peers=[Peer("control.obsv", lambda A, B, C: control.obsv(A, C))],
            )
        )
    return cases


def _lqr_747(rng: np.random.Generator) -> tuple[Any, ...]:
    """The chapter's lateral regulator (6.224)-(6.227) at c = 1: rudder and aileron."""
    A, B = aerocontrol.chapter.boeing747_lateral()
    return A, B, np.eye(4), np.eye(2)


def _lqr_problem(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A random n-state, 2-input plant with Q = I, R = I: A = G / sqrt(n) - 3/2 I, spectrum in
    a disc of radius about 1 centred at -3/2. (A Gaussian A with only 2 inputs has dozens of
    unstable modes and a solution with κ(X) ~ 1e15 at n = 64: a test of conditioning, not
    of speed.)"""
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 1.5 * np.eye(n)
    return A, rng.standard_normal((n, 2)), np.eye(n), np.eye(2)


def _lqr_ours(A: Any, B: Any, Q: Any, R: Any) -> Any:
    return aerocontrol.lqr(A, B, Q, R)[0]


def _lqr_control(A: Any, B: Any, Q: Any, R: Any) -> Any:
    return control.lqr(A, B, Q, R)[0]


def _lqr_scipy(A: Any, B: Any, Q: Any, R: Any) -> Any:
    X = scipy.linalg.solve_continuous_are(A, B, Q, R)
    return np.linalg.solve(R, B.T @ X)


@operation
def lqr_cases() -> list[Case]:
    """LQR (CARE + gain): ours against python-control's lqr (slycot SB02MD) and
    scipy.linalg.solve_continuous_are plus the gain, agreement on K."""
    small_control = Target("lqr n=4: <= 10 us and >= 5x control.lqr", 5.0, 10e-6)
    small_scipy = Target("lqr n=4: >= 30x scipy", 30.0)
    large_control = Target("lqr n=64/256: faster than control.lqr", 1.0)
    large_scipy = Target("lqr n=64/256: >= 3x scipy", 3.0)
    cases = [
        Case(
            op="lqr",
            size="n=4 747 lateral",
            seed=0,
            setup=_lqr_747,
            ours=_lqr_ours,
            peers=[
                Peer("control.lqr", _lqr_control, target=small_control),
                Peer("scipy CARE + gain", _lqr_scipy, target=small_scipy),
            ],
        )
    ]
    for n in SIZES:
        cases.append(
            Case(
                op="lqr",
                size=f"n={n} m=2",
                seed=n,
                setup=functools.partial(_lqr_problem, n=n),
                ours=_lqr_ours,
                peers=[
                    Peer("control.lqr", _lqr_control, target=large_control if n > 16 else None),
                    Peer("scipy CARE + gain", _lqr_scipy, target=large_scipy if n > 16 else None),
                ],
                repeat=1 if n > 64 else (3 if n == 64 else None),
            )
        )
    return cases


def _care_general(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The LQR problem of :func:`_lqr_problem` with a cross weight S = 0.1 G (n x 2) and a
    descriptor E = I + 0.1 G / sqrt(n) (well conditioned)."""
    A, B, Q, R = _lqr_problem(rng, n)
    S = 0.1 * rng.standard_normal((n, 2))
    E = np.eye(n) + 0.1 * rng.standard_normal((n, n)) / np.sqrt(n)
    return A, B, Q, R, S, E


def _care_ours(A: Any, B: Any, Q: Any, R: Any, S: Any, E: Any) -> Any:
    solution = aerocontrol.solve_care(A, B, Q, R, S=S, E=E)
    return solution.X, solution.K


def _care_scipy(A: Any, B: Any, Q: Any, R: Any, S: Any, E: Any) -> Any:
    X = scipy.linalg.solve_continuous_are(A, B, Q, R, e=E, s=S)
    return X, np.linalg.solve(R, B.T @ X @ E + S.T)


def _care_control(A: Any, B: Any, Q: Any, R: Any, S: Any, E: Any) -> Any:
    """python-control's care (slycot SG02AD with E and S): X and its gain G."""
    X, _, G = control.care(A, B, Q, R, S, E)
    return X, G


@operation
def care_general_cases() -> list[Case]:
    """The general algebraic Riccati equation (6.228) with a cross weight S and a descriptor
    E, random n = 4, 16, 64, 256 with 2 inputs. Agreement on X and K.

    Peers: scipy.linalg.solve_continuous_are(e=E, s=S) plus the gain, python-control's care.
    """
    return [
        Case(
            op="solve_care S, E",
            size=f"n={n} m=2",
            seed=n,
            setup=functools.partial(_care_general, n=n),
            ours=_care_ours,
            peers=[
                Peer("scipy CARE(e, s) + gain", _care_scipy, compare=_compare_tuple),
                Peer("control.care(S, E)", _care_control, compare=_compare_tuple),
            ],
            repeat=1 if n > 64 else (3 if n == 64 else None),
        )
        for n in (4, *SIZES)
    ]


def _compare_tuple(ours: Any, peer: Any) -> Pairs:
    """Outputs that are tuples of arrays, compared element by element."""
    return [(np.asarray(a), np.asarray(b)) for a, b in zip(ours, peer, strict=True)]


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


@operation
def batch_cases() -> list[Case]:
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
                Peer("loop control.lqr", _care_batch_control, compare=_compare_tuple),
                Peer("loop scipy CARE + gain", _care_batch_scipy, compare=_compare_tuple),
            ],
            repeat=3,
        ),
    ]


def _riccati_setup(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """The 747 lateral regulator (Q = I, R = I) for n = 4, :func:`_lqr_problem` otherwise;
    S(t_f) = 0 and 201 times on [0, 20] s."""
    if n == 4:
        A, B, Q, R = _lqr_747(rng)
    else:
        A, B, Q, R = _lqr_problem(rng, n)
    return A, B, Q, R, np.linspace(0.0, 20.0, 201)


def _riccati_ours(A: Any, B: Any, Q: Any, R: Any, t: Any) -> Any:
    return aerocontrol.riccati_ode(A, B, Q, R, t).S


def _lqr_finite_ours(A: Any, B: Any, Q: Any, R: Any, t: Any) -> Any:
    return aerocontrol.lqr_finite(A, B, Q, R, t)


def _riccati_ivp(rtol: float, atol: float) -> Callable[..., Any]:
    """-dS/dt = S A + A^T S - S B R^-1 B^T S + Q from S(t_f) = 0, integrated in τ = t_f - t
    by solve_ivp (DOP853) on the n² entries and read at the grid."""

    def peer(A: Any, B: Any, Q: Any, R: Any, t: Any) -> Any:
        n = A.shape[0]
        G = B @ np.linalg.solve(R, B.T)

        def rhs(tau: float, s: np.ndarray) -> np.ndarray:
            S = s.reshape(n, n)
            SA = S @ A
            return (SA + SA.T - S @ G @ S + Q).ravel()

        span = t[-1] - t
        sol = scipy.integrate.solve_ivp(
            rhs,
            (0.0, span[0]),
            np.zeros(n * n),
            method="DOP853",
            t_eval=span[::-1],
            rtol=rtol,
            atol=atol,
        )
        return sol.y.T.reshape(-1, n, n)[::-1]

    return peer


def _gains(riccati: Callable[..., Any]) -> Callable[..., Any]:
    """K(t) = R^-1 B^T S(t) from a peer's S(t)."""

    def peer(A: Any, B: Any, Q: Any, R: Any, t: Any) -> Any:
        return np.linalg.solve(R, B.T @ riccati(A, B, Q, R, t))

    return peer


@operation
def riccati_ode_cases() -> list[Case]:
    """The finite-horizon Riccati equation S(t) and gain K(t) on 201 times of [0, 20] s:
    the 747 lateral regulator and random plants with 2 inputs at n = 16 (both) and 64
    (riccati_ode). Agreement on S (riccati_ode) and K (lqr_finite).

    Peers: scipy.integrate.solve_ivp (DOP853) on the n² entries, at rtol 1e-10 (atol 1e-12),
    the issue's setting, and at rtol 1e-13 (atol 1e-15) as the accuracy reference. Ours has
    no truncation error; the integrator's global error is not bounded by its local rtol:
    against ours it is 2.0e-10, 1.7e-9 and 9.0e-8 (scaled) at rtol 1e-10 for n = 4, 16, 64,
    and 3.7e-13, 8.5e-13 and 3.3e-11 at rtol 1e-13. So the rtol-1e-10 peer is held to 1e-6
    (it is there for its time) and the rtol-1e-13 peer to the default 1e-10.

    Stops at n = 64: at n = 256 one call takes ours about 5 s and solve_ivp at rtol 1e-13
    about 16 s (65,536 unknowns), and the integrator is then 1.2e-10 off, no longer accurate
    enough to arbitrate at 1e-10. lqr_finite stops at n = 16: at n = 64 its K(t) is exactly
    R^-1 B^T S(t) of the riccati_ode row, but B^T S cancels, so the integrator's 3.3e-11 on S
    becomes 7.2e-10 on K (scaled), past what the reference can settle.
    """
    loose = _riccati_ivp(1e-10, 1e-12)
    tight = _riccati_ivp(1e-13, 1e-15)
    cases = []
    for n in (4, 16, 64):
        size = "n=4 747 lateral" if n == 4 else f"n={n} m=2"
        setup = functools.partial(_riccati_setup, n=n)
        operations = [("riccati_ode 201 t", _riccati_ours, lambda f: f)]
        if n <= 16:
            operations.append(("lqr_finite 201 t", _lqr_finite_ours, _gains))
        for op, ours, wrap in operations:
            cases.append(
                Case(
                    op=op,
                    size=size,
                    seed=n,
                    setup=setup,
                    ours=ours,
                    peers=[
                        Peer("solve_ivp DOP853 rtol 1e-10", wrap(loose), rtol=1e-6),
                        Peer("solve_ivp DOP853 rtol 1e-13", wrap(tight)),
                    ],
                    repeat=3 if n >= 64 else None,
                )
            )
    return cases


def _stable_problem(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    A = rng.standard_normal((n, n)) - 2 * np.sqrt(n) * np.eye(n)
    C = rng.standard_normal((n, n))
    return A, C @ C.T


def _compare_stable_subspace(ours: Any, peer: Any) -> Pairs:
    """The count of eigenvalues selected and the projector onto their invariant subspace."""
    _, Q, eigenvalues = ours
    _, Z, sdim = peer
    k = int(np.count_nonzero(eigenvalues.real < 0))
    return [
        (np.array([k]), np.array([sdim])),
        (Q[:, :k] @ Q[:, :k].T, Z[:, :sdim] @ Z[:, :sdim].T),
    ]


@operation
def schur_lyapunov_cases() -> list[Case]:
    """The real Schur form (against scipy.linalg.schur, agreement on the eigenvalues'
    real parts, sorted), the Schur form reordered to put the left half-plane first (against
    scipy.linalg.schur(sort="lhp"), agreement on the number selected and on the orthogonal
    projector Q_k Q_k^T onto their invariant subspace, which unlike Q_k is unique) and the
    Lyapunov equation (against solve_continuous_lyapunov)."""
    cases = []
    for n in (4, *SIZES):
        cases.append(
            Case(
                op="schur lhp",
                size=f"n={n}",
                seed=n,
                setup=lambda rng, n=n: (rng.standard_normal((n, n)),),
                ours=lambda A: aerocontrol.schur(A, "lhp"),
                peers=[
                    Peer(
                        "scipy.linalg.schur lhp",
                        lambda A: scipy.linalg.schur(A, sort="lhp"),
                        compare=_compare_stable_subspace,
                    )
                ],
                repeat=1 if n > 64 else None,
            )
        )
        cases.append(
            Case(
                op="schur",
                size=f"n={n}",
                seed=n,
                setup=lambda rng, n=n: (rng.standard_normal((n, n)),),
                ours=lambda A: np.sort(np.diag(aerocontrol.schur(A)[0])),
                peers=[
                    Peer(
                        "scipy.linalg.schur",
                        lambda A: np.sort(np.diag(scipy.linalg.schur(A)[0])),
                    )
                ],
                repeat=1 if n > 64 else None,
            )
        )
        cases.append(
            Case(
                op="solve_lyapunov",
                size=f"n={n}",
                seed=n,
                setup=functools.partial(_stable_problem, n=n),
                ours=aerocontrol.solve_lyapunov,
                peers=[
                    Peer(
                        "scipy solve_continuous_lyapunov",
                        lambda A, Q: scipy.linalg.solve_continuous_lyapunov(A, -Q),
                    )
                ],
                repeat=1 if n > 64 else None,
            )
        )
    return cases


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


def run_case(case: Case, repeat: int, min_time: float, warn: Callable[[str], None]) -> list[dict]:
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


# ---------------------------------------------------------------------------------------------
# Reporting
# ---------------------------------------------------------------------------------------------


def environment() -> dict[str, Any]:
    """Thread settings and versions: what a timing depends on besides the code."""
    env: dict[str, Any] = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "loadavg": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
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


def format_time(seconds: float) -> str:
    """A time with a unit that keeps 3-4 significant digits readable."""
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:7.3f} {unit}"
    return f"{seconds / 1e-9:7.1f} ns"


def format_flag(record: dict, separator: str = "  ") -> str:
    """PASS or MISS and the target's label, DISAGREE when the peer's answer differs."""
    flag = ""
    if record["target"]:
        flag = f"{'PASS' if record['target_met'] else 'MISS'}{separator}{record['target']}"
    if not record["agree"]:
        flag = f"DISAGREE {flag}".strip()
    return flag


def format_markdown(records: list[dict]) -> str:
    """The results as the Markdown table of README.md's performance record."""
    lines = [
        "| operation | size | peer | aerocontrol | peer time | peer / ours | target |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in records:
        cells = (
            r["op"],
            r["size"],
            r["peer"],
            format_time(r["ours_s"]).strip(),
            format_time(r["peer_s"]).strip(),
            f"{r['ratio']:.2f}x",
            format_flag(r, " "),
        )
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def format_table(records: list[dict]) -> str:
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


# ---------------------------------------------------------------------------------------------
# Entry point
# ---------------------------------------------------------------------------------------------


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print a JSON list of records")
    parser.add_argument(
        "--markdown", action="store_true", help="print the table as README.md's Markdown"
    )
    parser.add_argument(
        "--quick", action="store_true", help="fewer, shorter repeats: a smoke run (< ~60 s)"
    )
    parser.add_argument("-k", "--filter", default="", help="run cases whose name contains this")
    parser.add_argument("--repeat", type=int, help="repeats per callable (default 7, quick 3)")
    parser.add_argument(
        "--min-time",
        type=float,
        help="minimum seconds per repeat, sets the inner loop (default 0.1, quick 0.01)",
    )
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    args = parse_args(argv)
    repeat = args.repeat or (3 if args.quick else 7)
    min_time = args.min_time if args.min_time is not None else (0.01 if args.quick else 0.1)
    # In --json and --markdown mode stdout carries only the records; the header and warnings
    # go to stderr.
    info = sys.stderr if args.json or args.markdown else sys.stdout

    def warn(message: str) -> None:
        print(message, file=info, flush=True)

    print(format_environment(environment()), file=info)
    print(
        f"timing: min over {repeat} repeats of the mean over an inner loop of >= {min_time:g} s"
        f"{' (quick)' if args.quick else ''}; ratio = peer / ours (> 1: aerocontrol faster)\n",
        file=info,
        flush=True,
    )
    records = []
    for case in all_cases():
        if args.filter not in case.name:
            continue
        case_repeat = min(case.repeat, repeat) if case.repeat else repeat
        if args.quick and case.repeat:
            case_repeat = 1
        records.extend(run_case(replace(case, repeat=case_repeat), repeat, min_time, warn))
    if args.json:
        print(json.dumps(records, indent=1))
    elif args.markdown:
        print(format_markdown(records))
    else:
        print(format_table(records))
    return 0


if __name__ == "__main__":
    sys.exit(main())
