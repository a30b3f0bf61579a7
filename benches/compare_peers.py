"""Side-by-side timings of aerocontrol against its peers (scipy, python-control), in one process.

Every case builds its inputs once from ``numpy.random.default_rng(seed)``, checks that our
output agrees with each peer's, then times our callable and the peer's on the same inputs, with
the repeats of the two interleaved so that a burst of load on a shared machine hits both. A
timing is the MINIMUM over several repeats of the mean over an inner loop, the inner loop count
being chosen (as ``timeit`` does) so that one repeat lasts at least ``--min-time`` seconds.

Run from the repository root with the package installed::

    python benches/compare_peers.py              # full run, table
    python benches/compare_peers.py --quick      # smoke run, well under a minute
    python benches/compare_peers.py --json       # JSON list of result records on stdout
    python benches/compare_peers.py -k expm      # only the cases whose name contains "expm"

The ratio is peer time / our time: above 1 means aerocontrol is faster. Thread settings matter:
the header prints them, and ``OPENBLAS_NUM_THREADS=1 RAYON_NUM_THREADS=1`` gives a one-core
comparison. On small shared machines a multithreaded OpenBLAS has been seen to put a whole
process in a state where scipy.linalg.expm of a 4x4 matrix takes milliseconds (LAPACK inside
scipy's pade_UV_calc); a peer time of that order on a tiny case is that, not a real speed-up.

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
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import control
import numpy as np
import scipy
import scipy.linalg
import scipy.signal

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
    """A reference implementation of the same operation, and how to compare its output."""

    name: str
    fn: Callable[..., Any]
    compare: Callable[[Any, Any], Pairs] = same
    target: Target | None = None


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
        )
        for n in (4, 64)
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
    """Exact ZOH and FOH discretisation: the 747 longitudinal (n=4, one input, dt=0.05) and a
    random n=64 plant with 2 inputs.

    Peers: scipy.signal.cont2discrete((A, B, I, 0)) and, to separate the kernel from the
    wrapper, scipy.linalg.expm of the same Van Loan block matrix that cont2discrete builds.
    """

    def plant747(rng: np.random.Generator) -> tuple[Any, ...]:
        A, B = aerocontrol.chapter.boeing747_longitudinal()
        return A, B, 0.05

    def plant64(rng: np.random.Generator) -> tuple[Any, ...]:
        A = random_matrix(rng, 64)
        B = rng.standard_normal((64, 2))
        return A, B, 0.05

    cases = []
    for method in ("zoh", "foh"):
        for size, seed, setup in (("n=4 747", 0, plant747), ("n=64 m=2", 64, plant64)):
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


@operation
def step_response_cases() -> list[Case]:
    """Unit step response of the 747 longitudinal model (C = I) on 5001 and 50001 samples of
    [0, 500] s.

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


@operation
def forced_response_cases() -> list[Case]:
    """Response of the 747 (C = I) to a sampled sinusoidal elevator, first-order hold, on 50001
    samples of [0, 500] s.

    Peers: scipy.signal.lsim (interp=True, first-order hold) and python-control's
    forced_response (also linear between input samples).
    """
    samples = 50001
    return [
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
    and a random stable n=64 model with 2 inputs and 2 outputs. Agreement is on |G|.

    Peer: python-control's frequency_response.
    """
    target = Target("bode 1000 w vs control: ratio >= 10", min_ratio=10.0)
    setups = (
        ("n=4 747", 0, _bode747),
        ("n=64 m=2 p=2", 64, functools.partial(_bode_random, n=64, m=2, p=2)),
    )
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
                    target=target,
                )
            ],
        )
        for size, seed, setup in setups
    ]


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


def _compare_closed_loop_poles(ours: Any, peer: Any) -> Pairs:
    """The gains of two robust methods differ, so the check is that our closed loop has the
    poles requested (as scipy echoes them). scipy's own placement is not the reference: on
    the n=16 case its Tits-Yang gains miss by 1.4e-5 relatively, ours by 1.9e-11."""
    mine = np.sort_complex(np.linalg.eigvals(ours.closed_loop))
    requested = np.sort_complex(np.asarray(peer.requested_poles))
    return [(mine.real, requested.real), (mine.imag, requested.imag)]


@operation
def placement_cases() -> list[Case]:
    """Pole placement. Single input: Bass-Gura on the chapter's 747 Dutch-roll damper against
    python-control's acker (agreement on K). Several inputs: Kautsky-Nichols-Van Dooren
    against scipy's place_poles (its default, Tits-Yang; agreement on the closed-loop poles).
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
    return cases


def _random_pair(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    return rng.standard_normal((n, n)), rng.standard_normal((n, 1))


def _verdict_full(A: Any, B: Any) -> Any:
    return np.array([aerocontrol.is_controllable(A, B)])


def _verdict_staircase(A: Any, B: Any) -> Any:
    return np.array([aerocontrol.is_controllable(A, B, method="staircase")])


def _verdict_rank(A: Any, B: Any) -> Any:
    return np.array([np.linalg.matrix_rank(control.ctrb(A, B)) == A.shape[0]])


@operation
def controllability_cases() -> list[Case]:
    """The controllability verdict of a random 64-state single-input system (controllable).
    The peer, python-control's ctrb with numpy's matrix_rank, answers False here (rank 61):
    the rows report that disagreement, which is the point of not using the rank.
    """
    target = Target("verdict n=64: faster than ctrb + matrix_rank", min_ratio=1.0)
    peer = Peer("control.ctrb + matrix_rank", _verdict_rank, target=target)
    return [
        Case(
            op=f"is_controllable ({method})",
            size="n=64 m=1",
            seed=0,
            setup=functools.partial(_random_pair, n=64),
            ours=ours,
            peers=[peer],
        )
        for method, ours in (("full", _verdict_full), ("staircase", _verdict_staircase))
    ]


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
    for n in (64, 256):
        cases.append(
            Case(
                op="lqr",
                size=f"n={n} m=2",
                seed=n,
                setup=functools.partial(_lqr_problem, n=n),
                ours=_lqr_ours,
                peers=[
                    Peer("control.lqr", _lqr_control, target=large_control),
                    Peer("scipy CARE + gain", _lqr_scipy, target=large_scipy),
                ],
                repeat=1 if n > 64 else 3,
            )
        )
    return cases


def _stable_problem(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    A = rng.standard_normal((n, n)) - 2 * np.sqrt(n) * np.eye(n)
    C = rng.standard_normal((n, n))
    return A, C @ C.T


@operation
def schur_lyapunov_cases() -> list[Case]:
    """The real Schur form (against scipy.linalg.schur, agreement on the eigenvalues'
    real parts, sorted) and the Lyapunov equation (against solve_continuous_lyapunov)."""
    cases = []
    for n in (4, 64, 256):
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


def agreement(pairs: Pairs) -> tuple[bool, float]:
    """Whether every pair agrees to RTOL (see its docstring), and the worst scaled error."""
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
        ok = ok and bool(np.all(np.abs(ours - ref) <= RTOL * np.abs(ref) + RTOL * scale))
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
        ok, err = agreement(peer.compare(ours_out, peer.fn(*inputs)))
        if not ok:
            warn(
                f"WARNING: {case.name}: ours and {peer.name} disagree "
                f"(worst scaled error {err:.3g} > rtol {RTOL:g})"
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


def format_table(records: list[dict]) -> str:
    """The results, one row per (case, peer), then the targets."""
    headers = ("case", "size", "peer", "ours", "peer time", "peer/ours", "target")
    rows = []
    for r in records:
        flag = ""
        if r["target"]:
            flag = f"{'PASS' if r['target_met'] else 'MISS'}  {r['target']}"
        if not r["agree"]:
            flag = f"DISAGREE {flag}".strip()
        rows.append(
            (
                r["op"],
                r["size"],
                r["peer"],
                format_time(r["ours_s"]),
                format_time(r["peer_s"]),
                f"{r['ratio']:8.2f}x",
                flag,
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
    # In --json mode stdout carries only the JSON list; the header and warnings go to stderr.
    info = sys.stderr if args.json else sys.stdout

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
    else:
        print(format_table(records))
    return 0


if __name__ == "__main__":
    sys.exit(main())
