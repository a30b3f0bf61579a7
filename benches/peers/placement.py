"""Peer cases of aerocontrol.placement: single-input (Bass-Gura, Ackermann) and robust
multi-input pole placement and the companion form, against python-control and scipy."""

from __future__ import annotations

import functools
import warnings
from typing import Any

import control
import numpy as np
import scipy.signal

import aerocontrol

from .harness import Case, Pairs, Peer, Target


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


def place_cases() -> list[Case]:
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


GROUPS = (place_cases, companion_cases)
"""The case builders of this file, in the order they run."""
