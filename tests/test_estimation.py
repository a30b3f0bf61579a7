"""Kalman filters, observers and the LQG compensator (aerocontrol.estimation) against
python-control (lqe, dlqe, lqr, place, feedback), scipy's Riccati solvers, the Kalman
recursion iterated to its fixed point, and closed forms.

python-control's ``lqe`` and ``dlqe`` refuse a cross covariance NN; the cases with NN use the
standard decorrelation as the oracle: with w̄ = w - NN RN^-1 v, uncorrelated with v, the
plant is x' = (A - G NN RN^-1 C) x + G NN RN^-1 (y - D u) + B u + G w̄, so python-control's
filter for (A - G NN RN^-1 C, G (QN - NN RN^-1 NN^T) G^T) has the same P, and
L = L̄ + G NN RN^-1. python-control also requires G QN G^T exactly symmetric, which a
product of random matrices rarely is; the oracle is therefore called with G = I and the
symmetrised G QN G^T (aerocontrol symmetrises the same way).
"""

from __future__ import annotations

import warnings
from typing import Any

import control
import mpmath
import numpy as np
import pytest
import scipy.linalg as sl

import aerocontrol
from aerocontrol.exceptions import (
    IllConditionedWarning,
    InvalidArgumentError,
    NonFiniteError,
    NoStabilizingSolutionError,
    NotPositiveDefiniteError,
    NotRealError,
    ShapeError,
    UncontrollableError,
)

Array = np.ndarray[Any, Any]

# The 747's lateral motion, x = (β, p, φ, r), measured by roll rate, yaw rate and bank angle:
# the sideslip is not measured.
A747, B747 = aerocontrol.chapter.boeing747_lateral()
C_PRP = np.eye(4)[[1, 3, 2]]


def relative(ours: Array, theirs: Array) -> float:
    return float(np.linalg.norm(ours - theirs) / np.linalg.norm(theirs))


def matched_distance(ours: Array, theirs: Array) -> float:
    """The largest relative distance between two eigenvalue sets, matched greedily."""
    remaining = list(np.asarray(theirs, dtype=complex))
    worst = 0.0
    for value in np.asarray(ours, dtype=complex):
        distances = [abs(value - other) for other in remaining]
        k = int(np.argmin(distances))
        worst = max(worst, distances[k] / max(1.0, abs(remaining[k])))
        remaining.pop(k)
    return worst


def symmetric(M: Array) -> Array:
    return 0.5 * (M + M.T)


def random_noise_model(
    rng: np.random.Generator, n: int, discrete: bool = False
) -> tuple[Array, Array, Array, Array, Array]:
    """(A, G, C, QN, RN): a generic (so detectable) random problem with definite
    covariances; a discrete A has spectral radius 0.9 or 1.3."""
    g, p = int(rng.integers(1, n + 1)), int(rng.integers(1, n + 1))
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    if discrete:
        radius = max(np.abs(np.linalg.eigvals(A)))
        A = A / radius * (0.9 if rng.random() < 0.5 else 1.3)
    G, C = rng.standard_normal((n, g)), rng.standard_normal((p, n))
    X, Y = rng.standard_normal((g, g)), rng.standard_normal((p, p))
    return A, G, C, X @ X.T + 0.1 * np.eye(g), Y @ Y.T + 0.1 * np.eye(p)


def continuous_residual(A: Array, C: Array, W: Array, RN: Array, P: Array) -> float:
    """Relative residual of A P + P A^T - P C^T RN^-1 C P + W = 0."""
    quadratic = P @ C.T @ np.linalg.solve(RN, C @ P)
    residual = A @ P + P @ A.T - quadratic + W
    scale = np.linalg.norm(W) + 2 * np.linalg.norm(A @ P) + np.linalg.norm(quadratic)
    return float(np.linalg.norm(residual) / scale)


# --- lqe -------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(30))
def test_lqe_matches_python_control(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 13))
    A, G, C, QN, RN = random_noise_model(rng, n)
    W = symmetric(G @ QN @ G.T)
    L, P, E = aerocontrol.lqe(A, G, C, QN, RN)
    assert L.shape == (n, C.shape[0]) and P.shape == (n, n) and E.dtype == np.complex128
    assert np.all(E.real < 0)
    assert continuous_residual(A, C, W, RN, P) < 1e-12
    # python-control's default (slycot's SB02MD, unrefined) leaves residuals up to 1e-9 on
    # the worse-conditioned draws, and is then off by up to 1e-8; its scipy method is not.
    # Agreement to 1e-10 with the better of the two, and with each within its residual.
    # (python-control returns slycot's poles in single precision: they are recomputed.)
    errors = []
    for method in ("slycot", "scipy"):
        L2, P2, _ = control.lqe(A, np.eye(n), C, W, RN, method=method)
        slack = 1e-10 + 1e4 * continuous_residual(A, C, W, RN, P2)
        assert relative(P, P2) < slack and relative(L, L2) < slack, method
        errors.append(max(relative(P, P2), relative(L, L2)))
        # The poles as far as their conditioning allows (Bauer-Fike: the eigenvector matrix's
        # condition times the perturbation of A - L C).
        E2 = np.linalg.eigvals(A - L2 @ C)
        perturbation = np.linalg.norm(L - L2) * np.linalg.norm(C) + 1e-15 * np.linalg.norm(A)
        bound = 10 * eigenvector_condition(A - L @ C) * perturbation
        assert matched_distance(E, E2) < max(1e-10, bound), method
    assert min(errors) < 1e-10


def newton_refined(A: Array, C: Array, W: Array, RN: Array, P0: Array) -> Array:
    """One Newton (Kleinman) step of the filter's Riccati equation from P0 in 32-digit
    arithmetic: (A - L C) P + P (A - L C)^T = -(W + L RN L^T), L = P0 C^T RN^-1, solved by
    its Kronecker form. From a P0 accurate to 1e-13 the step is accurate to rounding."""
    n = A.shape[0]
    with mpmath.workdps(32):
        Am, Cm, Wm, Rm, P = (mpmath.matrix(M.tolist()) for M in (A, C, W, RN, P0))
        L = P * Cm.T * mpmath.inverse(Rm)
        F = Am - L * Cm
        rhs = -(Wm + L * Rm * L.T)
        kron = mpmath.zeros(n * n, n * n)
        for i in range(n):
            for j in range(n):
                for k in range(n):
                    kron[i * n + j, k * n + j] += F[i, k]
                    kron[i * n + j, i * n + k] += F[j, k]
        x = mpmath.lu_solve(kron, mpmath.matrix([rhs[i, j] for i in range(n) for j in range(n)]))
        return np.array([[float(x[i * n + j]) for j in range(n)] for i in range(n)])


@pytest.mark.parametrize("seed", [5, 17])
def test_lqe_on_the_ill_conditioned_draws_against_32_digits(seed: int) -> None:
    # The draws of test_lqe_matches_python_control with one output and ||P|| ~ 1e6, where
    # python-control's default method is off by 1.6e-8 (seed 5) and 6.4e-10 (seed 17).
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 13))
    A, G, C, QN, RN = random_noise_model(rng, n)
    W = symmetric(G @ QN @ G.T)
    _, P, _ = aerocontrol.lqe(A, G, C, QN, RN)
    assert relative(P, newton_refined(A, C, W, RN, P)) < 1e-12


def test_lqe_with_g_matches_python_control_where_g_qn_gt_is_symmetric() -> None:
    # G = diag(1, 2) and a diagonal QN: G QN G^T is exactly symmetric, so python-control takes
    # G itself.
    A = np.array([[0.0, 1.0], [-2.0, -0.5]])
    G, C = np.diag([1.0, 2.0]), np.array([[1.0, 0.0]])
    L, P, E = aerocontrol.lqe(A, G, C, np.diag([0.5, 3.0]), [[0.1]])
    L2, P2, _ = control.lqe(A, G, C, np.diag([0.5, 3.0]), [[0.1]])
    np.testing.assert_allclose(L, L2, rtol=1e-12)
    np.testing.assert_allclose(P, P2, rtol=1e-12)
    assert matched_distance(E, np.linalg.eigvals(A - L2 @ C)) < 1e-12


def test_lqe_scalar_closed_form() -> None:
    # x' = a x + w, y = x + v: 2 a p - p^2 / r + q = 0, p = r (a + sqrt(a^2 + q / r)),
    # l = p / r, and the estimator's pole a - l = -sqrt(a^2 + q / r).
    a, q, r = 0.7, 2.0, 0.5
    L, P, E = aerocontrol.lqe([[a]], [[1.0]], [[1.0]], q, r)
    p = r * (a + np.sqrt(a * a + q / r))
    assert P[0, 0] == pytest.approx(p, rel=1e-15)
    assert L[0, 0] == pytest.approx(p / r, rel=1e-15)
    assert E[0] == pytest.approx(-np.sqrt(a * a + q / r), rel=1e-15)


def test_lqe_747_lateral_without_sideslip() -> None:
    # Process noise on rudder and aileron (G = B, python-control's lqe(sys, ...)).
    sys = control.ss(A747, B747, C_PRP, 0)
    QN, RN = np.diag([1.0, 2.0]), np.diag([1e-2, 1e-2, 1e-3])
    L, P, E = aerocontrol.lqe(sys, QN, RN)
    L2, P2, _ = control.lqe(A747, np.eye(4), C_PRP, symmetric(B747 @ QN @ B747.T), RN)
    np.testing.assert_allclose(L, L2, rtol=1e-10, atol=1e-10 * np.linalg.norm(L2))
    np.testing.assert_allclose(P, P2, rtol=1e-10, atol=1e-10 * np.linalg.norm(P2))
    assert matched_distance(E, np.linalg.eigvals(A747 - L2 @ C_PRP)) < 1e-10
    assert L.shape == (4, 3) and np.all(E.real < 0)
    # The same through aerocontrol's StateSpace and the matrices.
    L3, _, _ = aerocontrol.lqe(aerocontrol.StateSpace(A747, B747, C_PRP), QN, RN)
    L4, _, _ = aerocontrol.lqe(A747, B747, C_PRP, QN, RN)
    np.testing.assert_array_equal(L, L3)
    np.testing.assert_array_equal(L, L4)


@pytest.mark.parametrize("seed", range(8))
def test_lqe_cross_covariance_against_decorrelated_python_control(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 9))
    A, G, C, QN, RN = random_noise_model(rng, n)
    g, p = G.shape[1], C.shape[0]
    # NN small enough that [[QN, NN], [NN^T, RN]] stays positive definite.
    NN = 0.2 * np.linalg.cholesky(QN) @ rng.uniform(-1, 1, (g, p)) @ np.linalg.cholesky(RN).T
    NN *= 0.5 / max(1.0, np.linalg.norm(np.linalg.solve(np.linalg.cholesky(QN), NN), 2))
    L, P, E = aerocontrol.lqe(A, G, C, QN, RN, NN)
    F = G @ NN @ np.linalg.inv(RN)
    A_bar = A - F @ C
    W_bar = symmetric(G @ (QN - NN @ np.linalg.solve(RN, NN.T)) @ G.T)
    L_bar, P2, _ = control.lqe(A_bar, np.eye(n), C, W_bar, RN, method="scipy")
    np.testing.assert_allclose(P, P2, rtol=0, atol=1e-10 * np.linalg.norm(P2))
    np.testing.assert_allclose(L, L_bar + F, rtol=0, atol=1e-10 * np.linalg.norm(L))
    assert matched_distance(E, np.linalg.eigvals(A - L @ C)) < 1e-9
    # And scipy's equation with the cross weight directly.
    P3 = sl.solve_continuous_are(A.T, C.T, symmetric(G @ QN @ G.T), RN, s=G @ NN)
    np.testing.assert_allclose(P, P3, rtol=0, atol=1e-10 * np.linalg.norm(P3))
    # By keyword, the same bits.
    np.testing.assert_array_equal(aerocontrol.lqe(A, G, C, QN, RN, NN=NN)[0], L)


def test_lqe_passes_a_discrete_python_control_system_to_dlqe() -> None:
    plant = aerocontrol.discretize(A747, B747, dt=0.05)
    sys = control.ss(plant.Phi, plant.Gamma0, C_PRP, 0, dt=0.05)
    ours = aerocontrol.lqe(sys, np.eye(2), 1e-3 * np.eye(3))
    theirs = aerocontrol.dlqe(plant.Phi, plant.Gamma0, C_PRP, np.eye(2), 1e-3 * np.eye(3))
    for mine, reference in zip(ours, theirs, strict=True):
        np.testing.assert_array_equal(mine, reference)
    assert np.all(np.abs(ours[2]) < 1)


# --- dlqe ------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(30))
def test_dlqe_matches_python_control(seed: int) -> None:
    rng = np.random.default_rng(1000 + seed)
    n = int(rng.integers(1, 13))
    A, G, C, QN, RN = random_noise_model(rng, n, discrete=True)
    L, P, E = aerocontrol.dlqe(A, G, C, QN, RN)
    L2, P2, E2 = control.dlqe(A, np.eye(n), C, symmetric(G @ QN @ G.T), RN)
    assert L.shape == (n, C.shape[0]) and np.all(np.abs(E) < 1)
    np.testing.assert_allclose(P, P2, rtol=0, atol=1e-10 * np.linalg.norm(P2))
    np.testing.assert_allclose(L, L2, rtol=0, atol=1e-10 * np.linalg.norm(L2))
    assert matched_distance(E, E2) < 1e-10


def kalman_recursion(
    A: Array, G: Array, C: Array, QN: Array, RN: Array, NN: Array | None = None
) -> tuple[Array, Array, Array, Array]:
    """The time-varying Kalman filter iterated from P = G QN G^T to its fixed point: an oracle
    independent of any Riccati solver. Returns (P a priori, M, L, posterior)."""
    W = G @ QN @ G.T
    S = np.zeros((A.shape[0], C.shape[0])) if NN is None else G @ NN
    P = W.copy()
    # Until the step is 0 to 1e-16, or has not shrunk in 200 iterations (rounding's floor).
    smallest, since = np.inf, 0
    for _ in range(100_000):
        innovation = C @ P @ C.T + RN
        L = (A @ P @ C.T + S) @ np.linalg.inv(innovation)
        P_next = symmetric(A @ P @ A.T + W - L @ innovation @ L.T)
        step = np.linalg.norm(P_next - P)
        if step <= 1e-16 * np.linalg.norm(P):
            break
        smallest, since = (step, 0) if step < smallest else (smallest, since + 1)
        if since == 200:
            break
        P = P_next
    innovation = C @ P @ C.T + RN
    M = P @ C.T @ np.linalg.inv(innovation)
    L = (A @ P @ C.T + S) @ np.linalg.inv(innovation)
    return P, M, L, P - M @ C @ P


@pytest.mark.parametrize("seed", range(6))
def test_discrete_kalman_filter_is_the_fixed_point_of_the_recursion(seed: int) -> None:
    rng = np.random.default_rng(2000 + seed)
    n = int(rng.integers(2, 9))
    A, G, C, QN, RN = random_noise_model(rng, n, discrete=True)
    NN = None
    if seed % 2:
        NN = 0.1 * rng.standard_normal((G.shape[1], C.shape[0]))
    kf = aerocontrol.kalman((A, np.zeros((n, 1)), C), QN, RN, NN, dt=0.1, G=G)
    P, M, L, posterior = kalman_recursion(A, G, C, QN, RN, NN)
    scale = np.linalg.norm(P)
    np.testing.assert_allclose(kf.P, P, rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(kf.filter_gain, M, rtol=0, atol=1e-10 * np.linalg.norm(M))
    np.testing.assert_allclose(kf.predictor_gain, L, rtol=0, atol=1e-10 * np.linalg.norm(L))
    np.testing.assert_allclose(kf.posterior_covariance, posterior, rtol=0, atol=1e-10 * scale)
    if NN is None:
        np.testing.assert_allclose(kf.predictor_gain, A @ kf.filter_gain, rtol=0, atol=1e-12)


def test_dlqe_cross_covariance_against_decorrelated_python_control() -> None:
    rng = np.random.default_rng(3)
    A, G, C, QN, RN = random_noise_model(rng, 6, discrete=True)
    NN = 0.1 * rng.standard_normal((G.shape[1], C.shape[0]))
    L, P, E = aerocontrol.dlqe(A, G, C, QN, RN, NN)
    F = G @ NN @ np.linalg.inv(RN)
    W_bar = symmetric(G @ (QN - NN @ np.linalg.solve(RN, NN.T)) @ G.T)
    L_bar, P2, _ = control.dlqe(A - F @ C, np.eye(6), C, W_bar, RN)
    np.testing.assert_allclose(P, P2, rtol=0, atol=1e-10 * np.linalg.norm(P2))
    np.testing.assert_allclose(L, L_bar + F, rtol=0, atol=1e-10 * np.linalg.norm(L))
    assert matched_distance(E, np.linalg.eigvals(A - L @ C)) < 1e-10


def test_dlqe_random_walk_closed_form() -> None:
    # x[k+1] = x[k] + w, y = x + v, QN = RN = 1: P^2 - P - 1 = 0 (the golden ratio φ),
    # M = L = φ / (φ + 1) = 1 / φ, posterior M, pole 1 - 1 / φ.
    golden = (1 + np.sqrt(5)) / 2
    kf = aerocontrol.kalman(([[1.0]], [[0.0]], [[1.0]]), 1.0, 1.0, dt=1.0, G=[[1.0]])
    assert kf.P[0, 0] == pytest.approx(golden, rel=1e-15)
    assert kf.filter_gain[0, 0] == pytest.approx(1 / golden, rel=1e-15)
    assert kf.predictor_gain[0, 0] == pytest.approx(1 / golden, rel=1e-15)
    assert kf.posterior_covariance[0, 0] == pytest.approx(1 / golden, rel=1e-14)
    assert kf.closed_loop_poles[0] == pytest.approx(1 - 1 / golden, rel=1e-14)


def test_dlqe_refuses_a_continuous_python_control_system() -> None:
    with pytest.raises(InvalidArgumentError, match="discrete-time"):
        aerocontrol.dlqe(control.ss(A747, B747, C_PRP, 0), np.eye(2), np.eye(3))


# --- kalman ----------------------------------------------------------------------------------


def test_kalman_continuous_names_one_gain_and_the_estimator() -> None:
    D = np.array([[0.0, 0.1], [0.2, 0.0], [0.0, 0.0]])
    QN, RN = np.eye(2), 1e-2 * np.eye(3)
    kf = aerocontrol.kalman((A747, B747, C_PRP, D), QN, RN)
    L, P, E = aerocontrol.lqe(A747, B747, C_PRP, QN, RN)
    assert not kf.discrete and kf.dt is None
    np.testing.assert_array_equal(kf.gain, L)
    np.testing.assert_array_equal(kf.P, P)
    np.testing.assert_array_equal(kf.closed_loop_poles, E)
    np.testing.assert_array_equal(kf.estimator_A, A747 - L @ C_PRP)
    np.testing.assert_array_equal(kf.estimator_B, np.hstack([B747 - L @ D, L]))
    np.testing.assert_array_equal(kf.estimator_C, np.eye(4))
    np.testing.assert_array_equal(kf.estimator_D, np.zeros((4, 5)))
    for name in ("filter_gain", "predictor_gain", "posterior_covariance"):
        with pytest.raises(AttributeError, match="continuous"):
            getattr(kf, name)
    assert "continuous" in repr(kf)


def test_kalman_discrete_names_both_gains() -> None:
    plant = aerocontrol.discretize(A747, B747, dt=0.02)
    QN, RN = np.eye(2), 1e-4 * np.eye(3)
    kf = aerocontrol.kalman((plant.Phi, plant.Gamma0, C_PRP), QN, RN, dt=0.02)
    L, P, _ = control.dlqe(
        plant.Phi, np.eye(4), C_PRP, symmetric(plant.Gamma0 @ plant.Gamma0.T), RN
    )
    assert kf.discrete and kf.dt == 0.02
    np.testing.assert_allclose(kf.predictor_gain, L, rtol=0, atol=1e-10 * np.linalg.norm(L))
    np.testing.assert_allclose(kf.P, P, rtol=0, atol=1e-10 * np.linalg.norm(P))
    M = kf.P @ C_PRP.T @ np.linalg.inv(C_PRP @ kf.P @ C_PRP.T + RN)
    np.testing.assert_allclose(kf.filter_gain, M, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(kf.predictor_gain, plant.Phi @ kf.filter_gain, atol=1e-13)
    with pytest.raises(AttributeError, match=r"filter_gain .* predictor_gain"):
        _ = kf.gain
    assert "dt=0.02" in repr(kf)
    # A python-control model brings its dt; True (discrete, period unknown) is refused by
    # name, as every aerocontrol model needs its sampling period.
    sys = control.ss(plant.Phi, plant.Gamma0, C_PRP, 0, dt=0.02)
    other = aerocontrol.kalman(sys, QN, RN)
    assert other.discrete and other.dt == 0.02
    np.testing.assert_array_equal(other.predictor_gain, kf.predictor_gain)
    with pytest.raises(InvalidArgumentError, match="dt=True"):
        aerocontrol.kalman(control.ss(plant.Phi, plant.Gamma0, C_PRP, 0, dt=True), QN, RN)


def test_the_discrete_estimator_tracks_the_plant() -> None:
    # A noise-free plant with a feedthrough and a known input, the estimator started wrong:
    # whatever u is, the prediction error must follow e[k+1] = (A - L C) e[k] and the
    # current estimate's error must be (I - M C) e[k], which holds only if the estimator's
    # inputs [u; y] and its B - L D are wired as documented.
    plant = aerocontrol.discretize(A747, B747, dt=0.05)
    D = np.array([[0.0, 0.05], [0.1, 0.0], [0.0, 0.0]])
    kf = aerocontrol.kalman(
        (plant.Phi, plant.Gamma0, C_PRP, D), np.eye(2), 1e-2 * np.eye(3), dt=0.05
    )
    L, M = kf.predictor_gain, kf.filter_gain
    rng = np.random.default_rng(5)
    x, x_hat = np.array([0.1, 0.0, 0.05, -0.02]), np.zeros(4)
    e = x - x_hat
    for _ in range(300):
        u = 0.1 * rng.standard_normal(2)
        y = C_PRP @ x + D @ u
        current = x_hat + M @ (y - C_PRP @ x_hat - D @ u)
        np.testing.assert_allclose(x - current, (np.eye(4) - M @ C_PRP) @ e, rtol=0, atol=1e-12)
        x_hat = kf.estimator_A @ x_hat + kf.estimator_B @ np.concatenate([u, y])
        x = plant.Phi @ x + plant.Gamma0 @ u
        e = (plant.Phi - L @ C_PRP) @ e
        np.testing.assert_allclose(x - x_hat, e, rtol=0, atol=1e-12)
    assert np.linalg.norm(e) < 0.1 * np.linalg.norm([0.1, 0.0, 0.05, -0.02])


def test_kalman_dt_is_checked() -> None:
    args = ((A747 * 0.01 + np.eye(4), B747, C_PRP), np.eye(2), np.eye(3))
    for bad in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(InvalidArgumentError, match="dt must be a positive"):
            aerocontrol.kalman(*args, dt=bad)
    with pytest.raises(NotRealError):
        aerocontrol.kalman(*args, dt=1j)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="does not discretise"):
        aerocontrol.kalman(control.ss(A747, B747, C_PRP, 0), np.eye(2), np.eye(3), dt=0.1)
    sampled = control.ss(A747 * 0.01 + np.eye(4), B747, C_PRP, 0, dt=0.1)
    with pytest.raises(InvalidArgumentError, match="disagrees"):
        aerocontrol.kalman(sampled, np.eye(2), np.eye(3), dt=0.2)
    assert aerocontrol.kalman(sampled, np.eye(2), np.eye(3), dt=0.1).dt == 0.1


# --- place_observer --------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(20))
def test_single_output_observer_matches_python_control(seed: int) -> None:
    # One output: the gain is unique. Single-output placement loses digits quickly with the
    # order (both aerocontrol and python-control are off by ~1e-9 from 60-digit Ackermann
    # gains at n = 6..10 on such draws), so n <= 5 here.
    rng = np.random.default_rng(3000 + seed)
    n = int(rng.integers(1, 6))
    A, C = rng.standard_normal((n, n)), rng.standard_normal((1, n))
    poles = -np.sort(rng.uniform(0.5, 3.0, n)).astype(complex)
    if n >= 2 and seed % 2:
        poles[:2] = [-1 + 1j, -1 - 1j]
    L = aerocontrol.place_observer(A, C, poles)
    L2 = control.place(A.T, C.T, poles).T
    assert L.shape == (n, 1)
    np.testing.assert_allclose(L, L2, rtol=0, atol=1e-10 * np.linalg.norm(L2))
    assert matched_distance(np.linalg.eigvals(A - L @ C), poles) < 1e-10


@pytest.mark.parametrize("seed", range(12))
def test_multi_output_observer_places_the_poles(seed: int) -> None:
    # Several outputs: the gain is not unique (KNV0 and python-control's Tits-Yang choose
    # differently); both must put eig(A - L C) at the poles. The observer is the transpose of
    # place's gain for (A^T, C^T), bit for bit.
    rng = np.random.default_rng(4000 + seed)
    n = int(rng.integers(2, 13))
    p = int(rng.integers(2, n + 1))
    A, C = rng.standard_normal((n, n)) / np.sqrt(n), rng.standard_normal((p, n))
    poles = -np.linspace(0.5, 3.0, n).astype(complex)
    poles[:2] = [-1 + 0.5j, -1 - 0.5j]
    L = aerocontrol.place_observer(A, C, poles)
    np.testing.assert_array_equal(L, aerocontrol.place(A.T, C.T, poles).K.T)
    # Each pole moves by about κ(X) u ||A - L C||, κ(X) the eigenvector matrix's condition.
    closed = A - L @ C
    design = aerocontrol.place(A.T, C.T, poles)
    spread = 1e-15 * design.eigenvector_condition * np.linalg.norm(closed)
    assert matched_distance(np.linalg.eigvals(closed), poles) < max(1e-10, 100 * spread)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's Tits-Yang may stop before its tolerance
        L2 = control.place(A.T, C.T, poles).T
    assert matched_distance(np.linalg.eigvals(A - L2 @ C), poles) < 1e-6


def test_observer_of_the_747_and_call_forms() -> None:
    poles = [-2.0 + 1.0j, -2.0 - 1.0j, -3.0, -4.0]
    L = aerocontrol.place_observer(A747, C_PRP, poles)
    assert matched_distance(np.linalg.eigvals(A747 - L @ C_PRP), poles) < 1e-12
    for model in (aerocontrol.StateSpace(A747, B747, C_PRP), (A747, B747, C_PRP, np.zeros((3, 2)))):
        np.testing.assert_array_equal(aerocontrol.place_observer(model, poles), L)
    # Yaw rate alone: the single-output gain is unique, as python-control's.
    r_only = C_PRP[1:2]
    L1 = aerocontrol.place_observer(A747, r_only, poles)
    L2 = control.place(A747.T, r_only.T, poles).T
    np.testing.assert_allclose(L1, L2, rtol=0, atol=1e-10 * np.linalg.norm(L2))


def test_unobservable_pair_is_refused_by_name() -> None:
    A = np.diag([1.0, 2.0, 3.0])
    with pytest.raises(UncontrollableError, match=r"\(C, A\) is not observable") as caught:
        aerocontrol.place_observer(A, [[1.0, 1.0, 0.0]], [-1, -2, -3])
    assert caught.value.eigenvalues == [3]
    with pytest.raises(InvalidArgumentError, match="C is refused") as refused:
        aerocontrol.place_observer(A, [[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]], [-1, -2, -3])
    assert refused.value.argument == "C"
    with pytest.raises(ShapeError, match="poles"):
        aerocontrol.place_observer(A, [[1.0, 1.0, 1.0]], [-1, -2])
    with pytest.raises(ShapeError, match="C must have as many columns as A"):
        aerocontrol.place_observer(A, [[1.0, 1.0]], [-1, -2, -3])
    with pytest.raises(InvalidArgumentError, match="place_observer needs"):
        aerocontrol.place_observer(A, [[1.0, 1.0, 1.0]])
    # A pole repeated beyond the outputs' rank: the refusal named "B", which the caller never
    # gave; it says that B is C^T, and keeps naming the poles as the argument at fault.
    with pytest.raises(InvalidArgumentError, match=r"its B is C\^T\)$") as repeated:
        aerocontrol.place_observer(A, [[1.0, 1.0, 1.0]], [-1, -1, -1])
    assert "repeated 3 times, but B has rank 1" in str(repeated.value)
    assert repeated.value.argument == "poles"


def test_ill_conditioned_observer_warns_as_place_does() -> None:
    # Twelve states seen through one output: the achieved poles miss by more than 1e-6.
    A = np.diag(np.arange(1.0, 13.0))
    C = np.ones((1, 12))
    poles = -3.0 * np.arange(1.0, 13.0)
    with pytest.warns(IllConditionedWarning, match="miss the requested") as record:
        aerocontrol.place_observer(A, C, poles)
    assert len(record) == 1
    assert record[0].filename == __file__


# --- lqg -------------------------------------------------------------------------------------


def test_lqg_747_against_python_control() -> None:
    D = np.zeros((3, 2))
    plant = aerocontrol.StateSpace(A747, B747, C_PRP, D)
    Q, R, QN, RN = np.eye(4), np.eye(2), np.diag([1.0, 2.0]), np.diag([1e-2, 1e-2, 1e-3])
    design = aerocontrol.lqg(plant, Q, R, QN, RN)
    K, _, _ = control.lqr(A747, B747, Q, R)
    L, _, _ = control.lqe(A747, np.eye(4), C_PRP, symmetric(B747 @ QN @ B747.T), RN)
    np.testing.assert_allclose(design.K, K, rtol=1e-10)
    np.testing.assert_allclose(design.L, L, rtol=0, atol=1e-10 * np.linalg.norm(L))
    compensator = control.ss(A747 - B747 @ K - L @ C_PRP, L, -K, 0)
    np.testing.assert_allclose(design.compensator.A, compensator.A, atol=1e-10)
    np.testing.assert_array_equal(design.compensator.B, design.L)
    np.testing.assert_array_equal(design.compensator.C, -design.K)
    # The loop: the compensator maps y to u with its sign, so positive feedback.
    loop = control.feedback(control.ss(A747, B747, C_PRP, D), compensator, sign=1)
    np.testing.assert_allclose(design.closed_loop.A, loop.A, atol=1e-10)
    assert matched_distance(design.closed_loop_poles, np.linalg.eigvals(loop.A)) < 1e-9
    assert np.all(design.closed_loop_poles.real < 0)
    assert design.compensator.input_names == plant.output_names
    assert design.closed_loop.n_states == 8 and design.closed_loop.n_outputs == 5


def eigenvector_condition(M: Array) -> float:
    return float(np.linalg.cond(np.linalg.eig(M)[1]))


@pytest.mark.parametrize("seed", range(16))
def test_separation_principle(seed: int) -> None:
    # With a feedthrough D. In the coordinates (x, e = x - x̂) the loop's matrix is
    # [[A - B K, B K], [0, A - L C]]: checked block by block to rounding, so its poles are the
    # regulator's and the filter's. Their computed values agree to 1e-9 where the 2n x 2n
    # eigenproblem is well enough conditioned to tell (eigenvector condition < 1e6); a
    # random 12-state single-input draw can reach 1e11, where numpy's eigenvalues of the
    # loop are themselves off by more. Some draws are nearly unstabilisable (warned).
    rng = np.random.default_rng(5000 + seed)
    n = int(rng.integers(1, 13))
    m, p = int(rng.integers(1, 4)), int(rng.integers(1, n + 1))
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    B, C, D = (rng.standard_normal(shape) for shape in ((n, m), (p, n), (p, m)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IllConditionedWarning)
        design = aerocontrol.lqg((A, B, C, D), np.eye(n), np.eye(m), np.eye(m), np.eye(p))
    K, L, loop = design.K, design.L, design.closed_loop.A
    T = np.block([[np.eye(n), np.zeros((n, n))], [np.eye(n), -np.eye(n)]])  # T^-1 = T
    triangular = T @ loop @ T
    scale = 1e-14 * np.linalg.norm(loop)
    np.testing.assert_allclose(triangular[n:, :n], 0, rtol=0, atol=scale)
    np.testing.assert_allclose(triangular[:n, :n], A - B @ K, rtol=0, atol=scale)
    np.testing.assert_allclose(triangular[:n, n:], B @ K, rtol=0, atol=scale)
    np.testing.assert_allclose(triangular[n:, n:], A - L @ C, rtol=0, atol=scale)
    # The poles the Riccati solvers report are eig(A - B K) and eig(A - L C) up to the
    # conditioning of those eigenproblems (Bauer-Fike).
    for poles, matrix in ((design.regulator_poles, A - B @ K), (design.estimator_poles, A - L @ C)):
        bound = 1e-13 * eigenvector_condition(matrix) * np.linalg.norm(matrix)
        assert matched_distance(poles, np.linalg.eigvals(matrix)) < max(1e-9, bound)
    condition = eigenvector_condition(loop)
    if condition < 1e6:
        # Bauer-Fike for both computations: 2n u kappa(V) ||loop|| each.
        bound = 4 * (2 * n) * 1.1e-16 * condition * np.linalg.norm(loop)
        distance = matched_distance(np.linalg.eigvals(loop), design.closed_loop_poles)
        assert distance < max(1e-9, bound)
    # The loop as python-control builds it from the plant and the compensator.
    compensator = design.compensator
    closed = control.feedback(
        control.ss(A, B, C, D),
        control.ss(compensator.A, compensator.B, compensator.C, compensator.D),
        sign=1,
    )
    np.testing.assert_allclose(loop, closed.A, rtol=0, atol=1e-12 * np.linalg.norm(closed.A))


def test_lqg_keywords_and_refusals() -> None:
    plant = (A747, B747, C_PRP, np.zeros((3, 2)))
    base = aerocontrol.lqg(plant, np.eye(4), np.eye(2), np.eye(4), np.eye(3), G=np.eye(4))
    np.testing.assert_array_equal(
        base.L, aerocontrol.lqe(A747, np.eye(4), C_PRP, np.eye(4), np.eye(3))[0]
    )
    N, NN = 0.01 * np.ones((4, 2)), 0.01 * np.ones((2, 3))
    crossed = aerocontrol.lqg(plant, np.eye(4), np.eye(2), np.eye(2), np.eye(3), N=N, NN=NN)
    np.testing.assert_array_equal(
        crossed.K, aerocontrol.lqr(A747, B747, np.eye(4), np.eye(2), N)[0]
    )
    np.testing.assert_array_equal(
        crossed.L, aerocontrol.lqe(A747, B747, C_PRP, np.eye(2), np.eye(3), NN)[0]
    )
    with pytest.raises(ShapeError, match="N must be 4 x 2"):
        aerocontrol.lqg(plant, np.eye(4), np.eye(2), np.eye(2), np.eye(3), N=np.ones((2, 4)))
    with pytest.raises(InvalidArgumentError, match="continuous-time compensator"):
        aerocontrol.lqg(control.ss(*plant, dt=0.1), np.eye(4), np.eye(2), np.eye(2), np.eye(3))
    # An unstable mode that the measurement cannot see: the filter, not the regulator, fails.
    unseen = (np.diag([1.0, -2.0]), np.eye(2), [[0.0, 1.0]], [[0.0, 0.0]])
    with pytest.raises(NoStabilizingSolutionError, match="not detectable"):
        aerocontrol.lqg(unseen, np.eye(2), np.eye(2), np.eye(2), [[1.0]])
    assert "closed_loop_poles" in repr(base)


# --- Errors ----------------------------------------------------------------------------------


def test_undetectable_pair_has_no_filter() -> None:
    # An unstable mode (continuous: +1; discrete: 2) that C cannot see.
    C = np.array([[0.0, 1.0]])
    with pytest.raises(NoStabilizingSolutionError, match="not detectable") as caught:
        aerocontrol.lqe(np.diag([1.0, -2.0]), np.eye(2), C, np.eye(2), [[1.0]])
    assert caught.value.eigenvalues == [1]
    with pytest.raises(NoStabilizingSolutionError, match="unit circle") as caught:
        aerocontrol.dlqe(np.diag([2.0, 0.5]), np.eye(2), C, np.eye(2), [[1.0]])
    assert caught.value.eigenvalues == [2]
    with pytest.raises(NoStabilizingSolutionError):
        aerocontrol.kalman((np.diag([2.0, 0.5]), np.eye(2), C), np.eye(2), [[1.0]], dt=1.0)
    # An undamped oscillation that C cannot see.
    A = sl.block_diag([[0.0, 1.0], [-1.0, 0.0]], [[-1.0]])
    with pytest.raises(NoStabilizingSolutionError, match="not detectable"):
        aerocontrol.lqe(A, np.eye(3), [[0.0, 0.0, 1.0]], np.eye(3), [[1.0]])
    # An undamped oscillation that C sees but no noise excites: no stable optimal filter.
    A = np.array([[0.0, 1.0], [-1.0, 0.0]])
    with pytest.raises(NoStabilizingSolutionError, match="not excited by the process noise"):
        aerocontrol.lqe(A, np.zeros((2, 1)), [[1.0, 0.0]], [[1.0]], [[1.0]])


def test_nearly_undetectable_pairs_warn_at_the_callers_line() -> None:
    # An unstable mode seen through C with weight 1e-6: solved, but rcond(U11) ~ 1e-12.
    A, C = np.diag([1.0, -2.0]), [[1e-6, 1.0]]
    with pytest.warns(IllConditionedWarning, match="rcond") as record:
        aerocontrol.lqe(A, np.eye(2), C, np.eye(2), [[1.0]])
    with pytest.warns(IllConditionedWarning, match="rcond") as more:
        aerocontrol.lqg(
            (A, [[1e-6], [1.0]], np.eye(2), np.zeros((2, 1))), np.eye(2), 1, 1, np.eye(2)
        )
    assert [w.filename for w in [*record, *more]] == [__file__] * (len(record) + len(more))
    # Weighted 1e-8, the discrete filter is solved with a warning (P near 1e17, as scipy's).
    # Weighted 1e-12 too (P near 9e24), by the doubling path, where scipy fails to find a
    # finite solution: a true solution, its residual in 50 digits within 4 u of its size, and
    # the filter stable. Weighted 1e-20 it cannot be told from an undetectable one.
    with pytest.warns(IllConditionedWarning, match="rcond"):
        _, P, _ = aerocontrol.dlqe(
            np.diag([2.0, 0.5]), np.eye(2), [[1e-8, 1.0]], np.eye(2), [[1.0]]
        )
    reference = sl.solve_discrete_are(
        np.diag([2.0, 0.5]), np.array([[1e-8], [1.0]]), np.eye(2), np.eye(1)
    )
    np.testing.assert_allclose(P, reference, rtol=0, atol=1e-8 * np.linalg.norm(reference))
    with pytest.warns(IllConditionedWarning, match="rcond"):
        _, P, E = aerocontrol.dlqe(
            np.diag([2.0, 0.5]), np.eye(2), [[1e-12, 1.0]], np.eye(2), [[1.0]]
        )
    assert P[0, 0] == pytest.approx(8.864462207e24, rel=1e-9) and np.all(np.abs(E) < 1)
    with mpmath.workdps(50):
        A_mp = mpmath.diag([2, mpmath.mpf("0.5")])
        C_mp = mpmath.matrix([[mpmath.mpf(1e-12), 1]])
        P_mp = mpmath.matrix(P.tolist())
        gain = A_mp * P_mp * C_mp.T * (C_mp * P_mp * C_mp.T + mpmath.eye(1)) ** -1
        residual = A_mp * P_mp * A_mp.T - gain * C_mp * P_mp * A_mp.T + mpmath.eye(2) - P_mp
        assert mpmath.mnorm(residual, "F") <= 4 * np.finfo(float).eps * mpmath.mnorm(P_mp, "F")
    with pytest.raises(NoStabilizingSolutionError, match="not detectable"):
        aerocontrol.dlqe(np.diag([2.0, 0.5]), np.eye(2), [[1e-20, 1.0]], np.eye(2), [[1.0]])


def test_bad_arguments_are_named() -> None:
    A, G, C, QN, RN = A747, B747, C_PRP, np.eye(2), np.eye(3)
    cases: list[tuple[tuple[Any, ...], type[Exception], str, str]] = [
        ((A[:3], G, C, QN, RN), ShapeError, "A", "A must be square"),
        ((A, G[:3], C, QN, RN), ShapeError, "G", "G must have as many rows as A"),
        ((A, G, C[:, :3], QN, RN), ShapeError, "C", "C must have as many columns as A"),
        ((A, G, C, np.eye(3), RN), ShapeError, "QN", r"QN must be 2 x 2 \(G has 2 columns\)"),
        ((A, G, C, QN, np.eye(2)), ShapeError, "RN", r"RN must be 3 x 3 \(C has 3 rows\)"),
        ((A, G, C, QN, RN, np.ones((3, 2))), ShapeError, "NN", "NN must be 2 x 3"),
        ((A[0], G, C, QN, RN), ShapeError, "A", "A must be a 2-D matrix"),  # 1-D: ambiguous
        ((A, G, C[None], QN, RN), ShapeError, "C", "C must be a 2-D matrix"),
        ((A, G, C, [[1.0, 0.5], [0.0, 1.0]], RN), InvalidArgumentError, "QN", "QN must be sym"),
        ((A, G, C, QN, np.diag([1.0, -1.0, 1.0])), NotPositiveDefiniteError, "RN", "RN must"),
        ((A, G, C, QN, np.diag([1.0, np.nan, 1.0])), NonFiniteError, "RN", r"RN\[1, 1\] is NaN"),
        ((A, G * 1j, C, QN, RN), NotRealError, "G", "G must be real"),
    ]
    for args, error, name, message in cases:
        with pytest.raises(error, match=message) as caught:
            aerocontrol.lqe(*args)
        assert caught.value.argument == name
    with pytest.raises(InvalidArgumentError, match="five or six"):
        aerocontrol.lqe(A, G, C, QN)
    with pytest.raises(InvalidArgumentError, match="two or three covariances"):
        aerocontrol.lqe(aerocontrol.StateSpace(A, G, C), QN)
    with pytest.raises(InvalidArgumentError, match="both by position and by keyword"):
        aerocontrol.dlqe(A * 0.1, G, C, QN, RN, np.zeros((2, 3)), NN=np.zeros((2, 3)))
    # The discrete filter does not need RN definite, only C P C^T + RN nonsingular.
    L, _, E = aerocontrol.dlqe(0.5 * np.eye(2), np.eye(2), np.eye(2), np.eye(2), np.zeros((2, 2)))
    assert np.all(np.abs(E) < 1) and L.shape == (2, 2)


# --- Layouts and inputs ----------------------------------------------------------------------


def _layouts(matrix: Array) -> list[Array]:
    """The same matrix C-ordered, Fortran-ordered, and as a strided view into a bigger array."""
    strided = np.zeros((2 * matrix.shape[0], 3 * matrix.shape[1]))
    strided[::2, ::3] = matrix
    return [np.ascontiguousarray(matrix), np.asfortranarray(matrix), strided[::2, ::3]]


def _frozen(*matrices: Array) -> list[Array]:
    copies = [np.array(m) for m in matrices]
    for copy in copies:
        copy.setflags(write=False)
    return copies


def test_layouts_give_identical_results_and_inputs_are_left_alone() -> None:
    rng = np.random.default_rng(11)
    A, G, C, QN, RN = random_noise_model(rng, 6)
    NN = 0.05 * rng.standard_normal((G.shape[1], C.shape[0]))
    B, D = rng.standard_normal((6, 2)), rng.standard_normal((C.shape[0], 2))
    originals = [np.array(m) for m in (A, G, C, QN, RN, NN, B, D)]
    results = []
    for layout in zip(*(_layouts(m) for m in (A, G, C, QN, RN, NN, B, D)), strict=True):
        a, g, c, qn, rn, nn, b, d = _frozen(*layout)
        kf = aerocontrol.kalman((0.3 * a, b, c, d), qn, rn, nn, dt=0.5, G=g)
        results.append(
            [
                *aerocontrol.lqe(a, g, c, qn, rn, nn),
                *aerocontrol.dlqe(0.3 * a, g, c, qn, rn, nn),
                kf.filter_gain,
                kf.predictor_gain,
                kf.estimator_B,
                aerocontrol.place_observer(a, b.T, [-1.0, -1.5, -2.0, -2.5, -3.0, -3.5]),
                aerocontrol.lqg((a, b, c, d), np.eye(6), np.eye(2), qn, rn, G=g).compensator.A,
            ]
        )
    for other in results[1:]:
        for first, second in zip(results[0], other, strict=True):
            np.testing.assert_array_equal(first, second)
    for original, now in zip(originals, (A, G, C, QN, RN, NN, B, D), strict=True):
        np.testing.assert_array_equal(original, now)


def test_lists_and_integer_arrays_are_accepted() -> None:
    L, P, _ = aerocontrol.lqe([[0, 1], [-2, -3]], [[0], [1]], [[1, 0]], 1, 1)
    L2, P2, _ = aerocontrol.lqe(
        np.array([[0.0, 1.0], [-2.0, -3.0]]),
        np.array([[0.0], [1.0]]),
        np.array([[1.0, 0.0]]),
        [[1.0]],
        [[1.0]],
    )
    np.testing.assert_array_equal(L, L2)
    np.testing.assert_array_equal(P, P2)


def test_no_warning_on_the_747() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        aerocontrol.lqe(A747, B747, C_PRP, np.eye(2), 1e-2 * np.eye(3))
        aerocontrol.lqg(
            (A747, B747, C_PRP, np.zeros((3, 2))), np.eye(4), np.eye(2), np.eye(2), np.eye(3)
        )
