"""The generalized real Schur form (QZ) against scipy.linalg.ordqz and its own backward
error: ||Q^T A Z - S||, ||Q^T B Z - T|| <= 10 n u ||(A, B)||_F on random, graded and singular
pencils, and reordering by every selection pattern at small orders."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.linalg as sl

import aerocontrol
from aerocontrol.exceptions import InvalidArgumentError, ShapeError

EPS = np.finfo(float).eps


def _check(A: np.ndarray, B: np.ndarray, form: aerocontrol.GeneralizedSchur) -> None:
    n = A.shape[0]
    scale = np.hypot(np.linalg.norm(A), np.linalg.norm(B))
    backward = np.hypot(
        np.linalg.norm(form.Q.T @ A @ form.Z - form.AA),
        np.linalg.norm(form.Q.T @ B @ form.Z - form.BB),
    )
    assert backward <= 10 * max(n, 1) * EPS * scale, backward / (EPS * scale)
    for M in (form.Q, form.Z):
        assert np.linalg.norm(M.T @ M - np.eye(n)) <= 10 * max(n, 1) * EPS
    assert np.all(np.tril(form.BB, -1) == 0)
    assert np.all(np.tril(form.AA, -2) == 0)
    assert np.all(form.beta >= 0)


def _sorted(values: np.ndarray) -> np.ndarray:
    return np.sort_complex(np.round(values, 8))


# 33 and 130: above the order where B = Q R is blocked, and column groups of the reduction's
# row rotations that do not fill four columns.
@pytest.mark.parametrize("n", [1, 2, 3, 5, 8, 20, 33, 50, 130])
def test_random_pencils(n: int) -> None:
    rng = np.random.default_rng(n)
    A, B = rng.standard_normal((n, n)), rng.standard_normal((n, n))
    form = aerocontrol.qz(A, B)
    _check(A, B, form)
    ours = form.alpha / form.beta
    theirs = sl.eigvals(A, B)
    np.testing.assert_allclose(_sorted(ours), _sorted(theirs), rtol=1e-7)


def test_graded_pencil() -> None:
    # Entries graded over 12 orders of magnitude.
    n = 8
    rng = np.random.default_rng(1)
    D = np.diag(10.0 ** -np.arange(n, dtype=float) * 1.5)
    A = D @ rng.standard_normal((n, n)) @ D
    B = D @ (np.eye(n) + 0.1 * rng.standard_normal((n, n))) @ D
    _check(A, B, aerocontrol.qz(A, B))


@pytest.mark.parametrize("n", [6, 70])
def test_singular_b_has_infinite_eigenvalues(n: int) -> None:
    rng = np.random.default_rng(2)
    U, V = (
        np.linalg.qr(rng.standard_normal((n, n)))[0],
        np.linalg.qr(rng.standard_normal((n, n)))[0],
    )
    A = U @ np.triu(rng.standard_normal((n, n)) + 3 * np.eye(n)) @ V.T
    B = U @ np.diag(np.r_[np.arange(1.0, n - 1), 0.0, 0.0]) @ V.T
    form = aerocontrol.qz(A, B)
    _check(A, B, form)
    assert np.sum(form.beta <= 1e-12 * np.linalg.norm(B)) == 2


@pytest.mark.parametrize("n", [2, 4, 6])
def test_every_selection_pattern(n: int) -> None:
    rng = np.random.default_rng(10 + n)
    A, B = rng.standard_normal((n, n)), rng.standard_normal((n, n))
    values = aerocontrol.qz(A, B)
    finite = values.alpha / values.beta
    blocks = [v for v in finite if v.imag >= 0]
    for pattern in itertools.product([False, True], repeat=len(blocks)):
        chosen = [v for v, c in zip(blocks, pattern, strict=True) if c]

        def select(alpha: complex, beta: float, chosen: list[complex] = chosen) -> bool:
            value = alpha / beta
            return any(abs(value - c) <= 1e-8 * (1 + abs(c)) for c in chosen)

        form = aerocontrol.qz(A, B, select)
        _check(A, B, form)
        expected = sum(2 if c.imag != 0 else 1 for c in chosen)
        assert form.selected == expected
        leading = form.alpha[:expected] / form.beta[:expected]
        assert all(
            min(abs(v - c) for c in chosen + [c.conjugate() for c in chosen]) < 1e-7
            for v in leading
        )


@pytest.mark.parametrize("name", ["lhp", "rhp", "iuc", "ouc"])
def test_named_selections_match_ordqz(name: str) -> None:
    rng = np.random.default_rng(4)
    A, B = rng.standard_normal((7, 7)), rng.standard_normal((7, 7))
    form = aerocontrol.qz(A, B, name)
    _check(A, B, form)
    _, _, alpha, beta, _, _ = sl.ordqz(A, B, sort=name, output="real")
    values = alpha / beta
    count = {
        "lhp": np.sum(values.real < 0),
        "rhp": np.sum(values.real > 0),
        "iuc": np.sum(np.abs(values) < 1),
        "ouc": np.sum(np.abs(values) > 1),
    }[name]
    assert form.selected == count


def test_arguments() -> None:
    with pytest.raises(ShapeError):
        aerocontrol.qz(np.eye(3), np.eye(2))
    with pytest.raises(InvalidArgumentError, match="select"):
        aerocontrol.qz(np.eye(2), np.eye(2), "inside")
    A = np.arange(9.0).reshape(3, 3)
    B = np.eye(3) + 0.1
    reference = aerocontrol.qz(A, B)
    form = aerocontrol.qz(np.asfortranarray(A), B[::-1, ::-1][::-1, ::-1])
    np.testing.assert_array_equal(form.AA, reference.AA)
    empty = aerocontrol.qz(np.zeros((0, 0)), np.zeros((0, 0)))
    assert empty.AA.shape == (0, 0) and empty.selected == 0


def test_a_select_exception_is_raised() -> None:
    def select(alpha: complex, beta: float) -> bool:
        raise RuntimeError("from select")

    with pytest.raises(RuntimeError, match="from select"):
        aerocontrol.qz(np.diag([1.0, 2.0]), np.eye(2), select)


@pytest.mark.parametrize("seed", range(40))
def test_small_eigenvalue_beside_a_nearly_singular_b_is_accurate(seed: int) -> None:
    """A real pair split from a 2 x 2 block whose B is nearly singular: the eigenvalue near the
    pencil's scale came back to a relative 1e-2 when it was taken from A B^-1 (entries of size
    1 / sigma_min(B)); against mpmath at 50 digits it is now within 1e-9 relative (the pencil's
    conditioning at sigma_min(B) down to 1e-13 allows about 1e-12)."""
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 50
    rng = np.random.default_rng(seed)
    n = 2 + seed % 3
    A = rng.standard_normal((n, n))
    U, s, Vt = np.linalg.svd(rng.standard_normal((n, n)))
    s[-1] *= 10.0 ** -(6 + seed % 8)
    B = U @ np.diag(s) @ Vt
    form = aerocontrol.qz(A, B)
    _check(A, B, form)
    with np.errstate(divide="ignore", invalid="ignore"):
        found = np.asarray(form.alpha) / np.asarray(form.beta)
    exact = mpmath.eig(mpmath.inverse(mpmath.matrix(B.tolist())) * mpmath.matrix(A.tolist()))[0]
    for value in (complex(e) for e in exact):
        if abs(value) < 1e3:
            error = np.min(np.abs(found - value)) / abs(value)
            assert error < 1e-9, (value, found)


def test_regression_pencil_with_exact_zeros_and_a_double_zero_eigenvalue() -> None:
    """Formerly a known defect: A = [[-1, 0, 0], [1, 0, 0], [0, 1, 0]] (eigenvalues -1 and a
    defective double 0 of B^-1 A), B = [[1, 0, 0], [0, 2, 0], [0, 1, 2]]: the core returned
    the eigenvalues -1, 0.217 and -0.235 with ||Q^T A Z - AA|| / ||A|| = 0.117 (scipy: 0, 0,
    -1 to 1e-16). The split of the real 2 x 2 block chose its eigenvalue by a distance that
    put every root at 1 from the estimate 0, and took the 0/0 root; it is now the chordal
    distance. Found by the qz property suite."""
    A = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    B = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 1.0, 2.0]])
    result = aerocontrol.qz(A, B)
    values = np.sort((result.alpha / result.beta).real)
    np.testing.assert_allclose(values, [-1.0, 0.0, 0.0], atol=1e-7)
    _check(A, B, aerocontrol.qz(A, B))
