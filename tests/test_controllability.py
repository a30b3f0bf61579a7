"""Controllability and observability: the chapter's example (6.75)-(6.88), verdicts at n = 64
where the rank of the controllability matrix fails, planted uncontrollable modes, duality, and
the characteristic polynomial against exact rational arithmetic."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import aerocontrol
from aerocontrol import ShapeError, UncontrollableError

A_EX = np.array([[0.0, 1.0], [-2.0, -3.0]])


def test_chapter_controllability_example() -> None:
    # (6.81): B = [0, 1]^T gives V = [[0, 1], [1, -3]], det V = -1: controllable.
    V = aerocontrol.ctrb(A_EX, [[0], [1]])
    np.testing.assert_array_equal(V, [[0, 1], [1, -3]])
    assert np.linalg.det(V) == pytest.approx(-1.0)
    assert aerocontrol.is_controllable(A_EX, [[0], [1]])
    # (6.84)-(6.88): B = [-1, 1]^T, det V = 0, P^-1 B = [-1, 0]^T: the mode at -2 is lost.
    assert np.linalg.det(aerocontrol.ctrb(A_EX, [[-1], [1]])) == 0.0
    result = aerocontrol.controllability(A_EX, [[-1], [1]])
    assert not result and not result.controllable
    np.testing.assert_allclose(result.uncontrollable_eigenvalues, [-2.0], atol=1e-14)
    assert result.controllable_order == 1
    # The modal measure is the chapter's zero row of P^-1 B, for unit left eigenvectors.
    order = np.argsort(result.eigenvalues.real)
    assert result.modal_measure[order[0]] < 1e-15 < 0.1 < result.modal_measure[order[1]]
    # The staircase form is an orthogonal similarity.
    Z = result.Z
    np.testing.assert_allclose(Z @ result.staircase_A @ Z.T, A_EX, atol=1e-14)
    np.testing.assert_allclose(Z @ result.staircase_B, [[-1], [1]], atol=1e-14)
    assert "not controllable: eigenvalues -2" in str(result)


def test_observability_is_the_dual() -> None:
    A, _ = aerocontrol.chapter.state_feedback_example()  # (6.95), y = x1 (6.94)
    np.testing.assert_array_equal(aerocontrol.obsv(A, [[1, 0]]), [[1, 0], [-3, 8]])
    assert aerocontrol.is_observable(A, [[1, 0]])
    # Measuring x2 only: x1 (eigenvalue -3) never reaches it.
    result = aerocontrol.observability(A, [[0, 1]])
    assert not result.controllable
    np.testing.assert_allclose(result.uncontrollable_eigenvalues, [-3.0], atol=1e-14)
    np.testing.assert_allclose(result.Z @ result.staircase_A @ result.Z.T, A, atol=1e-14)
    assert "not observable" in str(result)


@pytest.mark.parametrize("n", [5, 64, 130])
def test_krylov_matrices_are_exact_powers_and_the_same_for_every_layout(n: int) -> None:
    """[B AB ...] and [C; CA; ...] against the powers formed one product at a time in
    numpy (to rounding), bitwise the same for C, Fortran, transposed and padded layouts of A
    (n = 64 and 130 run faer's product kernel, n = 5 the plain loop)."""
    rng = np.random.default_rng(n)
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    B, C = rng.standard_normal((n, 2)), rng.standard_normal((2, n))
    blocks = [B]
    rows = [C]
    for _ in range(n - 1):
        blocks.append(A @ blocks[-1])
        rows.append(rows[-1] @ A)
    # Each block is a product of k matrices of norm about 2: relative error ~ k n u.
    expected_ctrb, expected_obsv = np.hstack(blocks), np.vstack(rows)
    got_ctrb, got_obsv = aerocontrol.ctrb(A, B), aerocontrol.obsv(A, C)
    for got, expected, axis in ((got_ctrb, expected_ctrb, 0), (got_obsv, expected_obsv, 1)):
        size = np.linalg.norm(expected, axis=axis, keepdims=True)
        assert np.all(np.abs(got - expected) <= 1e-12 * n * size)
    padded = np.zeros((n + 3, n + 5))
    padded[:n, :n] = A
    for layout in (np.asfortranarray(A), A.T.copy().T, padded[:n, :n]):
        np.testing.assert_array_equal(aerocontrol.ctrb(layout, B), got_ctrb)
        np.testing.assert_array_equal(aerocontrol.obsv(layout, C), got_obsv)


def test_systems_and_tuples_are_accepted() -> None:
    A, B = aerocontrol.chapter.boeing747_lateral()
    sys = aerocontrol.StateSpace(A, B)
    assert aerocontrol.is_controllable(sys)
    assert aerocontrol.is_controllable((A, B[:, 1:]))
    assert aerocontrol.is_observable(sys)  # C = I
    with pytest.raises(TypeError, match="both A and B"):
        aerocontrol.is_controllable(A)


def _random_system(n: int, m: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.standard_normal((n, n)), rng.standard_normal((n, m))


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("m", [1, 2])
def test_random_64_state_systems_are_controllable(seed: int, m: int) -> None:
    control = pytest.importorskip("control")
    A, B = _random_system(64, m, seed)
    assert aerocontrol.is_controllable(A, B)
    assert aerocontrol.is_controllable(A, B, method="staircase")
    result = aerocontrol.controllability(A, B)
    assert result.controllable_order == 64
    assert result.smallest_pivot > 1e3 * result.tolerance
    assert result.modal_measure.min() > 1e3 * result.tolerance
    if seed == 0 and m == 1:
        # The rank of the controllability matrix is the test that fails here.
        assert np.linalg.matrix_rank(control.ctrb(A, B)) < 64


def _planted(n: int, m: int, modes: list[float], seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A = S [[A_c, A_12], [0, diag(modes)]] S^T, B = S [B_c; 0], S orthogonal."""
    rng = np.random.default_rng(seed)
    k = len(modes)
    A = rng.standard_normal((n, n))
    A[n - k :, :] = 0.0
    A[n - k :, n - k :] = np.diag(modes)
    B = rng.standard_normal((n, m))
    B[n - k :, :] = 0.0
    S, _ = np.linalg.qr(rng.standard_normal((n, n)))
    return S @ A @ S.T, S @ B


@pytest.mark.parametrize(
    "modes",
    [[-0.5], [0.3, -1.0], [20.0], [-25.0, 30.0]],
    ids=["interior", "two interior", "dominant", "two dominant"],
)
@pytest.mark.parametrize("m", [1, 3])
def test_planted_uncontrollable_modes_are_named(modes: list[float], m: int) -> None:
    A, B = _planted(64, m, modes, seed=len(modes) + m)
    result = aerocontrol.controllability(A, B)
    assert not result.controllable
    found = np.sort(result.uncontrollable_eigenvalues.real)
    np.testing.assert_allclose(found, np.sort(modes), rtol=1e-9)
    # And the dual: (A^T, B^T) is not observable, at the same eigenvalues.
    dual = aerocontrol.observability(A.T, B.T)
    np.testing.assert_allclose(np.sort(dual.uncontrollable_eigenvalues.real), found, rtol=1e-9)


def test_dominant_planted_mode_fools_the_staircase_alone() -> None:
    # Documented blind spot of method="staircase" (see aerocontrol.controllability).
    A, B = _planted(64, 1, [20.0], seed=3)
    assert aerocontrol.is_controllable(A, B, method="staircase")
    assert not aerocontrol.is_controllable(A, B)


def test_interior_planted_block_in_a_rotated_basis_needs_the_modal_test() -> None:
    """A 16-state pair with a planted 4 x 4 uncontrollable block A_u whose eigenvalues lie
    among the controllable ones (benches/peers/controllability.py's case), in a random
    orthogonal basis. The staircase alone sees a coupling of 2.2e-14 against its tolerance
    1.8e-14 and calls all four controllable (documented under ``method``); the full analysis
    names them: the eigenvalues of A_u (numpy's eigvals of the planted block) to 1e-9."""
    rng = np.random.default_rng(16)
    n, r = 16, 4
    A0 = np.zeros((n, n))
    A0[: n - r, :] = rng.standard_normal((n - r, n)) / np.sqrt(n)
    A0[n - r :, n - r :] = rng.standard_normal((r, r)) / np.sqrt(r)
    B0 = np.zeros((n, 2))
    B0[: n - r] = rng.standard_normal((n - r, 2))
    U = np.linalg.qr(rng.standard_normal((n, n)))[0]
    A, B = U @ A0 @ U.T, U @ B0
    planted = np.sort_complex(np.linalg.eigvals(A0[n - r :, n - r :]))
    result = aerocontrol.controllability(A, B)
    assert not result.controllable
    found = np.sort_complex(result.uncontrollable_eigenvalues)
    np.testing.assert_allclose(found, planted, rtol=1e-9, atol=1e-9)
    assert aerocontrol.is_controllable(A, B, method="staircase")


def test_repeated_eigenvalue_only_partly_reachable() -> None:
    # A = I, B = [1, 1]^T: every left eigenvector test passes, but only one direction is
    # reachable; the staircase sees it.
    result = aerocontrol.controllability(np.eye(2), [[1.0], [1.0]])
    assert not result.controllable
    np.testing.assert_allclose(result.uncontrollable_eigenvalues, [1.0], atol=1e-15)


def test_tolerance_and_method_are_checked() -> None:
    with pytest.raises(aerocontrol.InvalidArgumentError, match="tol must be finite"):
        aerocontrol.controllability(A_EX, [[0], [1]], tol=-1.0)
    with pytest.raises(aerocontrol.InvalidArgumentError, match="method must be one of"):
        aerocontrol.controllability(A_EX, [[0], [1]], method="rank")
    with pytest.raises(ShapeError, match="B must have"):
        aerocontrol.ctrb(A_EX, [[0], [1], [2]])
    with pytest.raises(ShapeError, match="C must have one column per row of A"):
        aerocontrol.obsv(A_EX, [[1, 0, 0]])
    with pytest.raises(aerocontrol.NonFiniteError, match=r"A\[0, 1\]"):
        aerocontrol.is_controllable([[0, np.nan], [1, 1]], [[0], [1]])
    # A huge tolerance makes everything uncontrollable, by design.
    assert not aerocontrol.is_controllable(A_EX, [[0], [1]], tol=1e3)


def test_uncontrollable_error_is_a_linalg_error() -> None:
    assert issubclass(UncontrollableError, np.linalg.LinAlgError)


def _exact_charpoly(A: list[list[int]]) -> list[Fraction]:
    """Faddeev-LeVerrier in exact rational arithmetic: c_k = -tr(A M_k) / k."""
    n = len(A)
    M = [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    coefficients = [Fraction(1)]
    for k in range(1, n + 1):
        AM = [
            [sum(Fraction(A[i][t]) * M[t][j] for t in range(n)) for j in range(n)] for i in range(n)
        ]
        c = -sum(AM[i][i] for i in range(n)) / k
        coefficients.append(c)
        M = [[AM[i][j] + (c if i == j else 0) for j in range(n)] for i in range(n)]
    return coefficients


@pytest.mark.parametrize("seed", range(6))
def test_charpoly_against_exact_rational_arithmetic(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 3 + seed
    A = rng.integers(-9, 10, size=(n, n))
    exact = np.array([float(c) for c in _exact_charpoly(A.tolist())])
    computed = aerocontrol.charpoly(A)
    # The documented bound: |δa_k| <~ (k u + eigenvalue error) e_k(|λ|).
    moduli = np.abs(np.linalg.eigvals(A.astype(float)))
    e = np.poly(-moduli).real  # elementary symmetric functions of |λ|
    bound = 1e3 * n * np.finfo(float).eps * e
    assert np.all(np.abs(computed - exact) <= bound), (computed - exact) / e


def test_charpoly_does_not_inherit_ill_conditioned_eigenvalues() -> None:
    # The Frank matrix is upper Hessenberg with integer entries and det = 1; its small
    # eigenvalues are very ill conditioned, so multiplying out computed eigenvalues
    # (np.poly(np.linalg.eigvals(F))) misses the coefficients by about 1e-7 relatively at
    # n = 12. La Budde's recurrence on the Hessenberg form does not go through the eigenvalues.
    n = 12
    F = np.array([[n - max(i, j) if j >= i - 1 else 0 for j in range(n)] for i in range(n)])
    exact = np.array([float(c) for c in _exact_charpoly(F.tolist())])
    np.testing.assert_allclose(aerocontrol.charpoly(F), exact, rtol=1e-14)
    assert exact[-1] == 1.0


def test_charpoly_of_the_chapter_lateral_model() -> None:
    A, _ = aerocontrol.chapter.boeing747_lateral()
    np.testing.assert_allclose(
        aerocontrol.charpoly(A), [1, 1.4385, 0.8222, 0.7232, 0.0319], atol=6e-5
    )  # (6.155)
