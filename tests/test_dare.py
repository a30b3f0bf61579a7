"""The discrete algebraic Riccati equation and dlqr against closed forms, scipy,
python-control, SLICOT (SB02OD through slycot) and the DAREX benchmark collection.

DAREX: P. Benner, A. J. Laub, V. Mehrmann, "A collection of benchmark examples for the
numerical solution of algebraic Riccati equations II: discrete-time case", Tech. Report
SPC 95_23, TU Chemnitz-Zwickau, 1995. The 19 cases (default parameters) are read from scipy's
own test file scipy/linalg/tests/test_solvers.py (class TestSolveDiscreteAre), as installed
with scipy; case 2 has a complex B, which aerocontrol (real matrices only) refuses by name.
"""

from __future__ import annotations

import os
import pathlib
import warnings
from typing import Any

import control
import numpy as np
import pytest
import scipy
import scipy.linalg as sl

import aerocontrol
from aerocontrol.exceptions import (
    InvalidArgumentError,
    NoStabilizingSolutionError,
    ShapeError,
)

EPS = np.finfo(float).eps


def _darex_cases() -> list[tuple[Any, ...]]:
    """(A, B, Q, R) of the 19 DAREX cases, from scipy's installed test module."""
    tests = os.path.join(os.path.dirname(scipy.__file__), "linalg", "tests")
    source = pathlib.Path(tests, "test_solvers.py").read_text(encoding="utf-8")
    start = source.index("class TestSolveDiscreteAre")
    end = source.index("    # Makes the minimum precision", start)
    namespace: dict[str, Any] = {
        "np": np,
        "block_diag": sl.block_diag,
        "_load_data": lambda name: np.load(os.path.join(tests, "data", name)),
    }
    exec(source[start:end].replace("class TestSolveDiscreteAre:", "if True:"), namespace)
    cases = [tuple(np.atleast_2d(np.asarray(m)) for m in case[:4]) for case in namespace["cases"]]
    assert len(cases) == 19
    return cases


DAREX = _darex_cases()


def relative_residual(
    A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray, X: np.ndarray
) -> float:
    """||A'XA - X - (A'XB)(R + B'XB)^-1 (B'XA) + Q||_F over the size of its terms."""
    axa = A.T @ X @ A
    mixed = B.T @ X @ A
    quadratic = mixed.T @ np.linalg.solve(R + B.T @ X @ B, mixed)
    residual = axa - X - quadratic + Q
    scale = sum(np.linalg.norm(m) for m in (Q, axa, X, quadratic))
    return float(np.linalg.norm(residual) / scale)


@pytest.mark.parametrize("index", range(19))
def test_darex_residual_at_or_below_scipy(index: int) -> None:
    A, B, Q, R = DAREX[index]
    if np.any(np.imag(B) != 0):
        with pytest.raises(aerocontrol.exceptions.AerocontrolError, match="B must be real"):
            aerocontrol.solve_dare(A, B, Q, R)
        return
    A, B, Q, R = (np.real(m).astype(float) for m in (A, B, Q, R))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        solution = aerocontrol.solve_dare(A, B, Q, R)
    # Warned exactly when the subspace basis is ill-conditioned (case 16: X = diag(1, 1e12)).
    assert bool(caught) == (solution.rcond < 1e-8), [str(w.message) for w in caught]
    ours = relative_residual(A, B, Q, R, solution.X)
    theirs = relative_residual(A, B, Q, R, sl.solve_discrete_are(A, B, Q, R))
    # At or below scipy's, or below four units of rounding, where both are exact to rounding and
    # the comparison is noise: in case 7 the exact solution is X = Q, and Q itself measures
    # 5.9e-16 (ours differs from it by 1.5 u, scipy's by 3.5 u).
    assert ours <= max(theirs, 4 * EPS), (ours, theirs)
    assert ours < 1e-15
    assert np.all(np.abs(solution.closed_loop_poles) < 1)
    np.testing.assert_allclose(solution.X, solution.X.T, rtol=0, atol=0)


def test_scalar_closed_form() -> None:
    # a = 2, b = q = r = 1: x^2 - 4x - 1 = 0, x = 2 + sqrt(5), k = a b x / (r + b^2 x).
    solution = aerocontrol.solve_dare([[2.0]], [[1.0]], [[1.0]], [[1.0]])
    x = 2 + np.sqrt(5)
    assert solution.X[0, 0] == pytest.approx(x, rel=4 * EPS)
    assert solution.K[0, 0] == pytest.approx(2 * x / (1 + x), rel=4 * EPS)
    assert solution.closed_loop_poles[0] == pytest.approx(2 - 2 * x / (1 + x), rel=1e-14)


def _sorted(values: np.ndarray) -> np.ndarray:
    """Eigenvalues in an order that rounding cannot change: by real part rounded, then
    imaginary part."""
    values = np.asarray(values, dtype=complex)
    return values[np.lexsort((values.imag, np.round(values.real, 9)))]


def _random_stabilisable(rng: np.random.Generator, n: int, m: int) -> tuple[np.ndarray, ...]:
    A = rng.standard_normal((n, n)) / np.sqrt(n) * 1.3
    B = rng.standard_normal((n, m))
    C = rng.standard_normal((n, n))
    return A, B, C @ C.T + 0.1 * np.eye(n), np.eye(m) + 0.1 * np.ones((m, m))


@pytest.mark.parametrize("seed", range(20))
def test_dlqr_matches_python_control(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(1, 13)), int(rng.integers(1, 4))
    A, B, Q, R = _random_stabilisable(rng, n, m)
    N = 0.1 * rng.standard_normal((n, m))
    K, S, E = aerocontrol.dlqr(A, B, Q, R, N)
    K2, S2, E2 = control.dlqr(A, B, Q, R, N)
    assert K.shape == (m, n) and S.shape == (n, n) and E.dtype == np.complex128
    np.testing.assert_allclose(S, S2, rtol=1e-10, atol=1e-10 * np.linalg.norm(S2))
    np.testing.assert_allclose(K, K2, rtol=1e-10, atol=1e-10 * np.linalg.norm(K2))
    np.testing.assert_allclose(_sorted(E), _sorted(E2), atol=1e-10)


def test_dlqr_accepts_a_system_and_refuses_a_continuous_one() -> None:
    A = np.array([[1.0, 0.1], [0.0, 1.0]])
    B = np.array([[0.005], [0.1]])
    K, _, _ = aerocontrol.dlqr(A, B, np.eye(2), 1.0)
    K2, _, _ = aerocontrol.dlqr(
        aerocontrol.StateSpace(A, B, np.eye(2), np.zeros((2, 1))), np.eye(2), 1.0
    )
    np.testing.assert_array_equal(K, K2)
    with pytest.raises(InvalidArgumentError, match="discrete-time"):
        aerocontrol.dlqr(control.ss(A, B, np.eye(2), 0), np.eye(2), 1.0)
    with pytest.raises(InvalidArgumentError, match="four or five"):
        aerocontrol.dlqr(A, B, np.eye(2))


def test_cross_weight_and_descriptor_match_scipy() -> None:
    # The generalized equation with E nonsingular is the standard one for A E^-1, E^-T Q E^-1
    # and E^-T S (the bracket that E^T ... E encloses); scipy solves that one (its own E path
    # refuses this well-conditioned problem as "too close to the unit circle").
    rng = np.random.default_rng(7)
    A, B, Q, R = _random_stabilisable(rng, 5, 2)
    S = 0.1 * rng.standard_normal((5, 2))
    E = np.eye(5) + 0.1 * rng.standard_normal((5, 5))
    solution = aerocontrol.solve_dare(A, B, Q, R, S=S, E=E)
    Ei = np.linalg.inv(E)
    reference = sl.solve_discrete_are(A @ Ei, B, Ei.T @ Q @ Ei, R, s=Ei.T @ S)
    np.testing.assert_allclose(
        solution.X, reference, rtol=0, atol=1e-10 * np.linalg.norm(reference)
    )
    poles = sl.eigvals(A - B @ solution.K, E)
    np.testing.assert_allclose(_sorted(solution.closed_loop_poles), _sorted(poles), atol=1e-12)
    assert np.all(np.abs(poles) < 1)
    with_s = aerocontrol.solve_dare(A, B, Q, R, S=S).X
    np.testing.assert_allclose(with_s, sl.solve_discrete_are(A, B, Q, R, s=S), rtol=1e-11)


@pytest.mark.parametrize("n", [17, 24, 40])
def test_descriptor_above_the_vectorised_order_is_refined(n: int) -> None:
    # Above order 16 the Newton step's Stein equation with E is solved by doubling on the
    # equation with E removed: each solve here takes at least one step and ends within a few
    # units of rounding (the pencil alone left 1e-15 to 1e-14 on these).
    rng = np.random.default_rng(n)
    A = 1.2 * rng.standard_normal((n, n)) / np.sqrt(n)
    B, Q, R = rng.standard_normal((n, 2)), np.eye(n), np.eye(2)
    E = np.eye(n) + 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    solution = aerocontrol.solve_dare(A, B, Q, R, E=E)
    assert solution.refinement_steps >= 1
    assert solution.residual < 4 * EPS
    Ei = np.linalg.inv(E)
    reference = sl.solve_discrete_are(A @ Ei, B, Ei.T @ Q @ Ei, R)
    np.testing.assert_allclose(
        solution.X, reference, rtol=0, atol=1e-10 * np.linalg.norm(reference)
    )
    assert np.all(np.abs(sl.eigvals(A - B @ solution.K, E)) < 1)


def test_singular_a_is_solved() -> None:
    # A deadbeat-like plant: A nilpotent, so the symplectic pencil has infinite eigenvalues.
    A = np.diag([1.0, 1.0], 1)
    B = np.array([[0.0], [0.0], [1.0]])
    solution = aerocontrol.solve_dare(A, B, np.eye(3), [[1.0]])
    reference = sl.solve_discrete_are(A, B, np.eye(3), [[1.0]])
    np.testing.assert_allclose(solution.X, reference, rtol=0, atol=1e-13)
    assert solution.residual < 1e-15


def test_indefinite_r_where_a_stabilising_solution_exists() -> None:
    # a = 2, b = q = 1, r = -5: x = a^2 x r / (r + x) + q, i.e. x^2 + 14 x + 5 = 0; the root
    # -7 - sqrt(44) leaves the closed loop a - a x / (r + x) = 0.537 inside the unit circle.
    solution = aerocontrol.solve_dare([[2.0]], [[1.0]], [[1.0]], [[-5.0]])
    assert solution.X[0, 0] == pytest.approx(-7 - np.sqrt(44), rel=1e-14)
    assert abs(solution.closed_loop_poles[0]) < 1


def test_indefinite_r_without_a_real_solution_is_refused() -> None:
    # a = 1.5, r = -0.2: x^2 - 0.75 x + 0.2 = 0 has no real root. scipy returns X = -16.56,
    # whose residual is O(1); aerocontrol refuses.
    A, B, Q, R = (np.array([[v]]) for v in (1.5, 1.0, 1.0, -0.2))
    scipy_x = sl.solve_discrete_are(A, B, Q, R)
    assert relative_residual(A, B, Q, R, scipy_x) > 0.01
    with pytest.raises(NoStabilizingSolutionError):
        aerocontrol.solve_dare(A, B, Q, R)


def test_an_uncontrollable_mode_on_the_unit_circle_has_no_stabilising_solution() -> None:
    # A rotation by 90 degrees that B cannot touch; with and without a cross weight.
    A = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.5]])
    B = np.array([[0.0], [0.0], [1.0]])
    for S in (None, np.array([[0.1], [0.0], [0.2]])):
        with pytest.raises(NoStabilizingSolutionError, match="unit circle"):
            aerocontrol.solve_dare(A, B, np.eye(3), [[1.0]], S=S)


def test_an_unstabilisable_plant_is_refused() -> None:
    A = np.diag([2.0, 0.5])
    B = np.array([[0.0], [1.0]])
    with pytest.raises(NoStabilizingSolutionError):
        aerocontrol.solve_dare(A, B, np.eye(2), [[1.0]])


def test_bad_arguments_are_named() -> None:
    A = np.eye(2) * 0.5
    with pytest.raises(ShapeError, match="B"):
        aerocontrol.solve_dare(A, np.ones((3, 1)), np.eye(2), [[1.0]])
    with pytest.raises(ShapeError, match="R"):
        aerocontrol.solve_dare(A, np.ones((2, 1)), np.eye(2), np.eye(2))
    with pytest.raises(InvalidArgumentError, match="Q must be symmetric"):
        aerocontrol.solve_dare(A, np.ones((2, 1)), [[1.0, 1.0], [0.0, 1.0]], [[1.0]])
    with pytest.raises(aerocontrol.exceptions.AerocontrolError, match="A"):
        aerocontrol.solve_dare([[np.nan]], [[1.0]], [[1.0]], [[1.0]])


def test_weights_are_shaped_as_atleast_2d_by_every_riccati_solver() -> None:
    """A scalar or 1-D weight means what numpy.atleast_2d makes of it (python-control's
    R = 1), identically in the continuous, discrete and finite-horizon solvers; an array of
    more than two dimensions is refused by name."""
    A = np.array([[1.0, 0.1], [0.0, 1.0]])
    B = np.array([[0.005], [0.1]])
    for name, solve in (
        ("dlqr", lambda R, S: aerocontrol.dlqr(A, B, np.eye(2), R, S)[0]),
        ("lqr", lambda R, S: aerocontrol.lqr(A - np.eye(2), B, np.eye(2), R, S)[0]),
        ("riccati_ode", lambda R, S: aerocontrol.riccati_ode(A, B, np.eye(2), R, [0, 1], S).S),
        (
            "riccati_difference",
            lambda R, S: aerocontrol.riccati_difference(A, B, np.eye(2), R, 5, N=S).S,
        ),
    ):
        N = None if name == "riccati_ode" else np.array([[0.1], [0.0]])
        reference = solve(np.array([[2.0]]), N)
        for weight in (2.0, 2, np.float32(2.0), [2.0], np.array(2.0)):
            np.testing.assert_array_equal(solve(weight, N), reference, err_msg=name)
        with pytest.raises(ShapeError, match="R must be a 2-D matrix or a scalar"):
            solve(np.full((1, 1, 1), 2.0), N)


def test_layouts_and_inputs_left_alone() -> None:
    rng = np.random.default_rng(3)
    A, B, Q, R = _random_stabilisable(rng, 4, 2)
    reference = aerocontrol.solve_dare(A, B, Q, R).X
    copies = [m.copy() for m in (A, B, Q, R)]
    F = [np.asfortranarray(m) for m in (A, B, Q, R)]
    np.testing.assert_array_equal(aerocontrol.solve_dare(*F).X, reference)
    big = np.zeros((8, 8))
    big[::2, ::2] = A
    np.testing.assert_array_equal(aerocontrol.solve_dare(big[::2, ::2], B, Q, R).X, reference)
    for m, c in zip((A, B, Q, R), copies, strict=True):
        np.testing.assert_array_equal(m, c)


def test_no_warning_on_a_well_conditioned_problem() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        aerocontrol.solve_dare(np.eye(2) * 0.9, np.eye(2), np.eye(2), np.eye(2))


def test_batch_is_bitwise_the_single_solves_and_names_the_failing_problem() -> None:
    rng = np.random.default_rng(11)
    A = rng.standard_normal((40, 4, 4)) / 3
    B = rng.standard_normal((4, 2))
    batch = aerocontrol.batch.solve_dare_batch(A, B, np.eye(4), np.eye(2))
    for i in range(40):
        single = aerocontrol.solve_dare(A[i], B, np.eye(4), np.eye(2))
        np.testing.assert_array_equal(batch.X[i], single.X)
        np.testing.assert_array_equal(batch.K[i], single.K)
    assert np.all(np.abs(batch.closed_loop_poles) < 1)
    # Problem 1 cannot be stabilised (the mode 2 is not reachable).
    stack = np.stack([0.5 * np.eye(2), np.diag([2.0, 0.5])])
    with pytest.raises(NoStabilizingSolutionError) as caught:
        aerocontrol.batch.solve_dare_batch(stack, np.array([[0.0], [1.0]]), np.eye(2), [[1.0]])
    assert caught.value.batch_index == 1
    empty = aerocontrol.batch.solve_dare_batch(
        np.zeros((0, 2, 2)), np.ones((2, 1)), np.eye(2), [[1.0]]
    )
    assert empty.X.shape == (0, 2, 2)


def test_dlqr_sweep_matches_dlqr_per_weight() -> None:
    A, B = aerocontrol.chapter.boeing747_lateral()
    sampled = aerocontrol.c2d(aerocontrol.StateSpace(A, B), 0.1)
    weights = np.geomspace(1e-2, 10, 7)
    sweep = aerocontrol.batch.dlqr_sweep(sampled, weights=weights)
    for k, c in enumerate(weights):
        K, _, _ = aerocontrol.dlqr(sampled.A, sampled.B, np.eye(4), np.eye(2) / c**2)
        np.testing.assert_array_equal(sweep.K[k], K)
    with pytest.raises(InvalidArgumentError, match="continuous"):
        aerocontrol.batch.dlqr_sweep(aerocontrol.StateSpace(A, B, dt=0), weights=weights)
    with pytest.raises(InvalidArgumentError, match="discrete"):
        aerocontrol.batch.lqr_sweep(sampled, weights=weights)


# ----- the discrete finite horizon: riccati_difference and dlqr_finite -------------------------


def _difference_oracle(
    A: np.ndarray,
    B: np.ndarray,
    Q: np.ndarray,
    R: np.ndarray,
    N: np.ndarray,
    Sf: np.ndarray,
    steps: int,
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """S_k and K_k by the textbook recursion S = A^T S A - (A^T S B + N) K + Q in 40-digit
    arithmetic (mpmath): an independent form and precision."""
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 40
    a, b, q, r, cross = (mpmath.matrix(M.tolist()) for M in (A, B, Q, R, N))
    s = mpmath.matrix(Sf.tolist())
    S, K = [s], []
    for _ in range(steps):
        gain = (r + b.T * s * b) ** -1 * (b.T * s * a + cross.T)
        s = a.T * s * a - (a.T * s * b + cross) * gain + q
        S.append(s)
        K.append(gain)
    as_array = lambda M: np.array(M.tolist(), dtype=float)  # noqa: E731
    return [as_array(M) for M in reversed(S)], [as_array(M) for M in reversed(K)]


def test_riccati_difference_against_40_digits() -> None:
    rng = np.random.default_rng(11)
    n, m, steps = 4, 2, 30
    A, B, Q, R = _random_stabilisable(rng, n, m)
    A = 1.3 * A  # a plant that grows: the early S_k are large
    N = 0.1 * rng.standard_normal((n, m))
    G = rng.standard_normal((n, n))
    Sf = G @ G.T
    solution = aerocontrol.riccati_difference(A, B, Q, R, steps, Sf=Sf, N=N)
    S, K = _difference_oracle(A, B, Q, R, N, Sf, steps)
    assert solution.S.shape == (steps + 1, n, n) and solution.K.shape == (steps, m, n)
    np.testing.assert_array_equal(solution.S[-1], Sf)
    for k in range(steps):
        np.testing.assert_allclose(solution.S[k], S[k], rtol=0, atol=1e-12 * np.linalg.norm(S[k]))
        np.testing.assert_allclose(solution.K[k], K[k], rtol=0, atol=1e-12 * np.linalg.norm(K[k]))
        np.testing.assert_array_equal(solution.S[k], solution.S[k].T)
    np.testing.assert_array_equal(
        aerocontrol.dlqr_finite(A, B, Q, R, steps, Sf=Sf, N=N), solution.K
    )


@pytest.mark.parametrize("seed", range(6))
def test_riccati_difference_in_states_scaled_apart(seed: int) -> None:
    """Found by a hunt: in states x0 = T x with T of 10^±6 the normwise error estimate (u ||A||
    set by the largest unit) warned on 47 of 50 random models of errors up to 2e2, where S_k
    was right to 4e-13. The recursion now runs on the balanced states: no warning, the estimate
    below 1e-12, and S_k = T S0_k T, K_k = K0_k T against the 40-digit recursion of the
    unscaled model (with N and S_f scaled alike: T N, T S_f T), 1e-11 relative to
    sqrt(S_ii S_jj) and to each gain's largest entry."""
    rng = np.random.default_rng(seed)
    n, m, steps = 4, 2, 20
    A0, B0, Q0, R = _random_stabilisable(rng, n, m)
    N0 = 0.1 * rng.standard_normal((n, m))
    G = rng.standard_normal((n, n))
    Sf0 = G @ G.T
    T = 10.0 ** rng.uniform(-6.0, 6.0, n)
    A, B = A0 * (T[np.newaxis, :] / T[:, np.newaxis]), B0 / T[:, np.newaxis]
    Q, Sf, N = Q0 * np.outer(T, T), Sf0 * np.outer(T, T), N0 * T[:, np.newaxis]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        solution = aerocontrol.riccati_difference(A, B, Q, R, steps, Sf=Sf, N=N)
    assert solution.error_estimate < 1e-12
    S0, K0 = _difference_oracle(A0, B0, Q0, R, N0, Sf0, steps)
    for k in range(steps):
        expected = S0[k] * np.outer(T, T)
        size = np.sqrt(np.outer(np.diag(expected), np.diag(expected)))
        assert np.max(np.abs(solution.S[k] - expected) / size) < 1e-11
        gain = K0[k] * T[np.newaxis, :]
        scale = np.max(np.abs(gain), axis=1, keepdims=True)
        assert np.max(np.abs(solution.K[k] - gain) / scale) < 1e-11


def test_riccati_difference_converges_to_the_dare() -> None:
    # The chapter's lateral regulator sampled at 50 Hz: 3000 steps (60 s) reach the DARE.
    A, B = aerocontrol.chapter.boeing747_lateral()
    sampled = aerocontrol.discretize(A, B, 0.02)
    Q, R = np.eye(4), np.eye(2)
    solution = aerocontrol.riccati_difference(sampled.Phi, sampled.Gamma0, Q, R, 3000)
    K, X, _ = aerocontrol.dlqr(sampled.Phi, sampled.Gamma0, Q, R)
    np.testing.assert_allclose(solution.S[0], X, rtol=0, atol=1e-12 * np.linalg.norm(X))
    np.testing.assert_allclose(solution.K[0], K, rtol=0, atol=1e-12 * np.linalg.norm(K))
    # A discrete system gives the same; a continuous one is refused.
    system = aerocontrol.StateSpace(
        sampled.Phi, sampled.Gamma0, np.eye(4), np.zeros((4, 2)), dt=0.02
    )
    by_system = aerocontrol.riccati_difference(system, Q, R, 50)
    np.testing.assert_array_equal(
        by_system.K, aerocontrol.riccati_difference(sampled.Phi, sampled.Gamma0, Q, R, 50).K
    )
    continuous = control.ss(A, B, np.eye(4), np.zeros((4, 2)))  # dt = 0
    with pytest.raises(InvalidArgumentError, match="discrete-time system"):
        aerocontrol.riccati_difference(continuous, Q, R, 50)


@pytest.mark.parametrize("steps", [-1, 2.5, True, "3", None])
def test_riccati_difference_refuses_a_bad_step_count(steps: Any) -> None:
    with pytest.raises(InvalidArgumentError, match=r"steps|number of steps"):
        aerocontrol.riccati_difference([[1.0]], [[1.0]], [[1.0]], [[1.0]], steps)


def test_riccati_difference_edges_and_errors() -> None:
    # No step: S = [Sf], no gain.
    solution = aerocontrol.riccati_difference(
        np.eye(2), np.ones((2, 1)), np.eye(2), [[1.0]], np.int64(0), Sf=2 * np.eye(2)
    )
    assert solution.S.shape == (1, 2, 2) and solution.K.shape == (0, 1, 2)
    np.testing.assert_array_equal(solution.S[0], 2 * np.eye(2))
    # R = 0 with Sf = 0: the last step's R + B^T S B is zero, named with its step.
    with pytest.raises(aerocontrol.exceptions.IllConditionedError, match="step 2"):
        aerocontrol.riccati_difference([[1.0]], [[1.0]], [[1.0]], [[0.0]], 3)
    # Nearly singular: warned.
    with pytest.warns(aerocontrol.exceptions.IllConditionedWarning, match="rcond"):
        aerocontrol.riccati_difference(np.eye(2), np.eye(2), np.eye(2), np.diag([1.0, 1e-12]), 1)
    with pytest.raises(InvalidArgumentError, match="Sf must be symmetric"):
        aerocontrol.riccati_difference(
            np.eye(2), np.eye(2), np.eye(2), np.eye(2), 2, Sf=[[1.0, 1.0], [0.0, 1.0]]
        )
    with pytest.raises(ShapeError, match="N"):
        aerocontrol.riccati_difference(np.eye(2), np.eye(2), np.eye(2), np.eye(2), 2, N=np.eye(3))
    # A plant that outgrows the doubles over the horizon.
    with pytest.raises(aerocontrol.exceptions.IllConditionedError, match="range of doubles"):
        aerocontrol.riccati_difference([[1e10]], [[0.0]], [[1.0]], [[1.0]], 40)


def test_riccati_difference_layouts_and_inputs_left_alone() -> None:
    rng = np.random.default_rng(3)
    A, B, Q, R = _random_stabilisable(rng, 3, 2)
    reference = aerocontrol.riccati_difference(A, B, Q, R, 7)
    arguments = [np.asfortranarray(A), B[:, ::-1][:, ::-1], Q.copy(), np.asfortranarray(R)]
    copies = [M.copy() for M in arguments]
    again = aerocontrol.riccati_difference(*arguments, 7)
    np.testing.assert_array_equal(again.S, reference.S)
    np.testing.assert_array_equal(again.K, reference.K)
    for M, copy in zip(arguments, copies, strict=True):
        np.testing.assert_array_equal(M, copy)


def test_cross_weight_errors_name_the_callers_argument() -> None:
    # python-control's lqr and dlqr call the cross weight N, MATLAB's care and dare S: each
    # error names the argument as the caller wrote it.
    A, B = np.array([[0.9, 0.1], [0.0, 0.8]]), np.array([[0.0], [1.0]])
    Q, R = np.eye(2), np.eye(1)
    for regulator in (aerocontrol.lqr, aerocontrol.dlqr):
        with pytest.raises(ShapeError, match=r"^N must have as many rows as A"):
            regulator(A, B, Q, R, np.ones((3, 1)))
        with pytest.raises(aerocontrol.exceptions.NonFiniteError, match=r"^N\b"):
            regulator(A, B, Q, R, N=np.array([[np.nan], [0.0]]))
    for solver in (aerocontrol.solve_care, aerocontrol.solve_dare):
        with pytest.raises(ShapeError, match=r"^S must have as many rows as A"):
            solver(A, B, Q, R, S=np.ones((3, 1)))


# ----- equations scaled far from 1 (an exact scaling before the core's solve) ---------------


def _sampled_model(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A random 4-state, 1-input model sampled (ZOH) at 0.1 s."""
    rng = np.random.default_rng(seed)
    A, B = rng.standard_normal((4, 4)), rng.standard_normal((4, 1))
    sampled = aerocontrol.discretize(A, B, dt=0.1)
    return sampled.Phi, sampled.Gamma0


@pytest.mark.parametrize(
    ("seed", "t", "alpha"),
    [
        # Found by a hunt: each refused by the unscaled core (too few pencil eigenvalues
        # inside the unit circle, or a swap of the reordering refused).
        (23, [1e-6, 1e6, 1e-3, 1e3], 1.0),  # states scaled one by one
        (54, [1e6, 1e6, 1e6, 1e6], 1.0),  # all states scaled together
        (41, [1.0, 1.0, 1.0, 1.0], 1e12),  # Q and R both multiplied by 1e12
        (5, [1e8, 1e-8, 1e4, 1e-4], 1e-12),
    ],
)
def test_scaled_states_and_weights(seed: int, t: list[float], alpha: float) -> None:
    """The regulator of x0 = T x (A = T^-1 A0 T, B = T^-1 B0, Q = alpha T Q0 T, R = alpha R0)
    is that of the unscaled equation: X = alpha T X0 T, K = K0 T, the same closed loop
    (X0, K0 by scipy's solve_discrete_are on the unscaled model). Tolerances: 1e-9 relative
    for K (column by column) and for X (entry by entry relative to sqrt(X_ii X_jj)), 1e-10
    for the closed-loop moduli."""
    A0, B0 = _sampled_model(seed)
    Q0, R0 = np.eye(4), np.eye(1)
    X0 = sl.solve_discrete_are(A0, B0, Q0, R0)
    K0 = np.linalg.solve(R0 + B0.T @ X0 @ B0, B0.T @ X0 @ A0)
    T = np.array(t)
    A, B = A0 * (T[np.newaxis, :] / T[:, np.newaxis]), B0 / T[:, np.newaxis]
    Q, R = alpha * Q0 * np.outer(T, T), alpha * R0
    solution = aerocontrol.solve_dare(A, B, Q, R)
    K_expected, X_expected = K0 * T[np.newaxis, :], alpha * X0 * np.outer(T, T)
    np.testing.assert_allclose(solution.K, K_expected, rtol=1e-9)
    size = np.sqrt(np.outer(np.diag(X_expected), np.diag(X_expected)))
    assert np.max(np.abs(solution.X - X_expected) / size) < 1e-9
    np.testing.assert_array_equal(solution.X, solution.X.T)
    np.testing.assert_allclose(
        np.sort(np.abs(solution.closed_loop_poles)),
        np.sort(np.abs(np.linalg.eigvals(A0 - B0 @ K0))),
        rtol=1e-10,
    )
    # The reported residual is that of the caller's equation.
    assert solution.residual < 1e-12
    K, X, poles = aerocontrol.dlqr(A, B, Q, R)
    np.testing.assert_array_equal(K, solution.K)
    np.testing.assert_array_equal(X, solution.X)
    np.testing.assert_array_equal(poles, solution.closed_loop_poles)


def test_scaled_equation_with_cross_weight_and_descriptor() -> None:
    """S and E take the same exact scaling (S -> T S, E -> T^-1 E T): the solution with a cross
    weight and a descriptor matrix E in states scaled by 1e±6 is that of the unscaled one
    (scipy's solve_discrete_are with s and e), to 1e-9 as above."""
    A0, B0 = _sampled_model(23)
    rng = np.random.default_rng(7)
    E0 = np.eye(4) + 0.1 * rng.standard_normal((4, 4))
    S0 = 0.1 * rng.standard_normal((4, 1))
    Q0, R0 = np.eye(4), np.eye(1)
    X0 = sl.solve_discrete_are(A0, B0, Q0, R0, e=E0, s=S0)
    K0 = np.linalg.solve(R0 + B0.T @ X0 @ B0, B0.T @ X0 @ A0 + S0.T)
    T = np.array([1e-6, 1e6, 1e-3, 1e3])
    similar = T[np.newaxis, :] / T[:, np.newaxis]
    solution = aerocontrol.solve_dare(
        A0 * similar,
        B0 / T[:, np.newaxis],
        Q0 * np.outer(T, T),
        R0,
        S0 * T[:, np.newaxis],
        E0 * similar,
    )
    np.testing.assert_allclose(solution.K, K0 * T[np.newaxis, :], rtol=1e-9)
    X_expected = X0 * np.outer(T, T)
    size = np.sqrt(np.outer(np.diag(X_expected), np.diag(X_expected)))
    assert np.max(np.abs(solution.X - X_expected) / size) < 1e-9
