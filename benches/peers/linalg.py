"""Peer cases of aerocontrol.linalg: the matrix exponential of one matrix and of a stack, the
transition matrix, exact ZOH and FOH discretisation, and the real Schur form (plain and
reordered), against scipy."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.linalg
import scipy.signal

import aerocontrol

from .harness import Case, Pairs, Peer, Target
from .inputs import SIZES, identity_outputs, random_matrix


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


def _compare_stable_subspace(ours: Any, peer: Any) -> Pairs:
    """The count of eigenvalues selected and the projector onto their invariant subspace."""
    _, Q, eigenvalues = ours
    _, Z, sdim = peer
    k = int(np.count_nonzero(eigenvalues.real < 0))
    return [
        (np.array([k]), np.array([sdim])),
        (Q[:, :k] @ Q[:, :k].T, Z[:, :sdim] @ Z[:, :sdim].T),
    ]


def schur_cases() -> list[Case]:
    """The real Schur form (against scipy.linalg.schur, agreement on the eigenvalues'
    real parts, sorted) and the Schur form reordered to put the left half-plane first (against
    scipy.linalg.schur(sort="lhp"), agreement on the number selected and on the orthogonal
    projector Q_k Q_k^T onto their invariant subspace, which unlike Q_k is unique), of standard
    normal matrices at n = 4, 16, 64 and 256."""
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
    return cases


def _compare_deflating_subspace(ours: Any, peer: Any) -> Pairs:
    """The count of eigenvalues selected and the projector onto their right deflating
    subspace (unique, unlike the basis)."""
    k = ours.selected
    Z = peer[5]
    alpha, beta = peer[2], peer[3]
    sdim = int(np.count_nonzero(np.abs(alpha) < np.abs(beta)))
    return [
        (np.array([k]), np.array([sdim])),
        (ours.Z[:, :k] @ ours.Z[:, :k].T, Z[:, :sdim] @ Z[:, :sdim].T),
    ]


def qz_cases() -> list[Case]:
    """The generalized Schur form reordered to put the eigenvalues inside the unit circle first
    (against scipy.linalg.ordqz(sort="iuc"); agreement on the number selected and the projector
    onto their deflating subspace) of standard normal pencils at n = 4, 16, 64 and 256."""
    target = Target("qz n=4..256: faster than scipy.linalg.ordqz", 1.0)
    return [
        Case(
            op="qz iuc",
            size=f"n={n}",
            seed=n,
            setup=lambda rng, n=n: (rng.standard_normal((n, n)), rng.standard_normal((n, n))),
            ours=lambda A, B: aerocontrol.qz(A, B, "iuc"),
            peers=[
                Peer(
                    "scipy.linalg.ordqz iuc",
                    lambda A, B: scipy.linalg.ordqz(A, B, sort="iuc", output="real"),
                    compare=_compare_deflating_subspace,
                    target=target,
                )
            ],
            repeat=1 if n > 64 else None,
        )
        for n in (4, *SIZES)
    ]


GROUPS = (
    expm_cases,
    expm_batch_cases,
    transition_matrix_cases,
    discretize_cases,
    schur_cases,
    qz_cases,
)
"""The case builders of this file, in the order they run."""
