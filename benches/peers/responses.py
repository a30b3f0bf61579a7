"""Peer cases of aerocontrol.responses: the step, impulse, doublet, initial-condition and
forced responses, the steady state and the DC gain, against python-control, scipy.signal and
numpy."""

from __future__ import annotations

import functools
from typing import Any

import control
import numpy as np
import scipy.signal

import aerocontrol

from .harness import Case, Pairs, Peer, Target
from .inputs import SIZES, identity_outputs, stable_plant


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


def _steady_checked_numpy(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    """What steady_state computes: the equilibrium, and whether the response reaches it
    (every eigenvalue of A in the open left half-plane; steady_state refuses it otherwise)."""
    if not np.all(np.linalg.eigvals(A).real < 0.0):
        raise ValueError("unstable: no steady state")
    return np.linalg.solve(A, -(B @ eta0))


def _dc_gain_ours(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return aerocontrol.dc_gain((A, B, C, D))


def _dc_gain_control(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return control.dcgain(control.ss(A, B, C, D))


def _dc_gain_numpy(A: Any, B: Any, C: Any, D: Any, eta0: Any) -> Any:
    return D - C @ np.linalg.solve(A, B)


def steady_state_cases() -> list[Case]:
    """The steady state x∞ = -A^-1 B η0 of a step and the DC gain D - C A^-1 B: the 747
    longitudinal model, random stable plants with 2 inputs and 2 outputs (n = 16, 64, 256).

    Peers: numpy.linalg.solve (both), python-control's dcgain (squeezed for one input, so
    compared after a reshape); for steady_state also the composite that gives what it
    computes, numpy's eigenvalues to decide that the response settles (steady_state refuses
    an unstable model) and the solve.
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
                peers=[
                    Peer("numpy.linalg.solve", _steady_numpy),
                    Peer("numpy eigvals (stable?) + solve", _steady_checked_numpy),
                ],
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


GROUPS = (
    step_response_cases,
    free_response_cases,
    forced_response_cases,
    steady_state_cases,
)
"""The case builders of this file, in the order they run."""
