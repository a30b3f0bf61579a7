"""Peer cases of aerocontrol.riccati: LQR, the general algebraic Riccati equation, the
finite-horizon Riccati equation and the Lyapunov equation, against python-control (slycot)
and scipy."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import control
import numpy as np
import scipy.integrate
import scipy.linalg

import aerocontrol

from .harness import Case, Peer, Target, compare_tuple
from .inputs import SIZES


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
                Peer("scipy CARE(e, s) + gain", _care_scipy, compare=compare_tuple),
                Peer("control.care(S, E)", _care_control, compare=compare_tuple),
            ],
            repeat=1 if n > 64 else (3 if n == 64 else None),
        )
        for n in (4, *SIZES)
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
    """A = G - 2 sqrt(n) I (stable: G's spectrum lies in a disc of radius about sqrt(n)) and
    Q = C C^T, G and C standard normal."""
    A = rng.standard_normal((n, n)) - 2 * np.sqrt(n) * np.eye(n)
    C = rng.standard_normal((n, n))
    return A, C @ C.T


def lyapunov_cases() -> list[Case]:
    """The Lyapunov equation A X + X A^T + Q = 0 with A = G - 2 sqrt(n) I (stable) and
    Q = C C^T (G, C standard normal), n = 4, 16, 64 and 256, agreement on X.

    Peer: scipy.linalg.solve_continuous_lyapunov (of A and -Q).
    """
    cases = []
    for n in (4, *SIZES):
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


def _dlqr_problem(rng: np.random.Generator, n: int) -> tuple[Any, ...]:
    """A random n-state, 2-input discrete plant with Q = I, R = I: A = 0.9 G / sqrt(n), its
    spectrum in a disc of radius about 0.9 (a sampled stable plant, as a flight computer sees
    one)."""
    A = 0.9 * rng.standard_normal((n, n)) / np.sqrt(n)
    return A, rng.standard_normal((n, 2)), np.eye(n), np.eye(2)


def _dlqr_747(rng: np.random.Generator) -> tuple[Any, ...]:
    """The chapter's lateral regulator at c = 1, sampled at 50 Hz (zero-order hold)."""
    A, B = aerocontrol.chapter.boeing747_lateral()
    d = aerocontrol.discretize(A, B, 0.02)
    return d.Phi, d.Gamma0, np.eye(4), np.eye(2)


def _dlqr_scipy(A: Any, B: Any, Q: Any, R: Any) -> Any:
    X = scipy.linalg.solve_discrete_are(A, B, Q, R)
    return np.linalg.solve(R + B.T @ X @ B, B.T @ X @ A)


def dlqr_cases() -> list[Case]:
    """The discrete LQR (DARE + gain): ours against python-control's dlqr (slycot SB02OD) and
    scipy.linalg.solve_discrete_are plus the gain, agreement on K."""
    small_control = Target("dlqr n=4: >= 10x control.dlqr", 10.0)
    small_scipy = Target("dlqr n=4: >= 50x scipy", 50.0)
    large = Target("dlqr n=64/256: faster", 1.0)
    cases = [
        Case(
            op="dlqr",
            size="n=4 747 lateral 50 Hz",
            seed=0,
            setup=_dlqr_747,
            ours=lambda A, B, Q, R: aerocontrol.dlqr(A, B, Q, R)[0],
            peers=[
                Peer("control.dlqr", lambda *a: control.dlqr(*a)[0], target=small_control),
                Peer("scipy DARE + gain", _dlqr_scipy, target=small_scipy),
            ],
        )
    ]
    for n in SIZES:
        cases.append(
            Case(
                op="dlqr",
                size=f"n={n} m=2",
                seed=n,
                setup=functools.partial(_dlqr_problem, n=n),
                ours=lambda A, B, Q, R: aerocontrol.dlqr(A, B, Q, R)[0],
                peers=[
                    Peer(
                        "control.dlqr",
                        lambda *a: control.dlqr(*a)[0],
                        target=large if n > 16 else None,
                    ),
                    Peer("scipy DARE + gain", _dlqr_scipy, target=large if n > 16 else None),
                ],
                repeat=1 if n > 16 else None,
            )
        )
    return cases


GROUPS = (lqr_cases, care_general_cases, dlqr_cases, riccati_ode_cases, lyapunov_cases)
"""The case builders of this file, in the order they run."""
