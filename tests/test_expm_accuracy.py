"""Accuracy of the matrix exponential against 50-digit references, side by side with scipy.

Every matrix is given exactly in double precision; its reference exponential is computed by
mpmath at 50 significant digits (and checked against a 70-digit run, so the reference itself is
known to about 1e-40), then rounded. For each matrix the relative Frobenius error of
aerocontrol.expm must be at most twice that of scipy.linalg.expm plus 1e-15, and the table of
both errors is printed with the test output.

Sources of the classic cases (Burkardt's collection of matrix exponential tests, which scipy also
ships in scipy/sparse/linalg/tests/test_matfuncs.py; the matrices below are written from the
publications):

* C. Moler and C. Van Loan, "Nineteen dubious ways to compute the exponential of a matrix,
  twenty-five years later", SIAM Review 45(1), 2003 (cases burkardt_4 to burkardt_7).
* R. C. Ward, "Numerical computation of the matrix exponential with accuracy estimate", SIAM J.
  Numer. Anal. 14(4), 1977 (burkardt_10 to burkardt_13, Ward's examples 1-4).
* A. J. Laub, review of "Linear System Theory" by J. Hespanha, SIAM Review 52(4), 2010
  (burkardt_3).
* C. Moler, "A balancing act for the matrix exponential", Cleve's Corner, 2012 (burkardt_14).
* NAG Library, example of routine F01ECF (burkardt_9).
* Wikipedia, "Matrix exponential", worked example (burkardt_8).
"""

from __future__ import annotations

import sys
from collections.abc import Callable

import mpmath
import numpy as np
import pytest
import scipy.linalg

import aerocontrol
from aerocontrol import chapter


def _forsythe(n: int, epsilon: float) -> np.ndarray:
    """Ward's example 4: the n x n Forsythe matrix, ones on the superdiagonal and epsilon in the
    bottom-left corner; its eigenvector problem is badly conditioned."""
    A = np.diag(np.ones(n - 1), 1)
    A[-1, 0] = epsilon
    return A


def _orthogonal(n: int, seed: int) -> np.ndarray:
    Q, R = np.linalg.qr(np.random.default_rng(seed).standard_normal((n, n)))
    return Q * np.sign(np.diag(R))


def _random(n: int, norm: float, seed: int) -> np.ndarray:
    A = np.random.default_rng(seed).standard_normal((n, n))
    return A * (norm / np.linalg.norm(A, 1))


def _jordan_similar(n: int, eigenvalue: float, seed: int) -> np.ndarray:
    """A defective matrix (one Jordan block) hidden by a well-conditioned similarity."""
    J = eigenvalue * np.eye(n) + np.diag(np.ones(n - 1), 1)
    rng = np.random.default_rng(seed)
    S = np.eye(n) + 0.3 * rng.standard_normal((n, n))
    return S @ J @ np.linalg.inv(S)


def _upper_nonnormal(n: int, off_diagonal: float) -> np.ndarray:
    """Upper triangular, eigenvalues -1 ... -n, every entry above the diagonal large."""
    return np.triu(np.full((n, n), off_diagonal), 1) - np.diag(np.arange(1.0, n + 1))


A747_LON, _ = chapter.boeing747_longitudinal()
A747_LAT, _ = chapter.boeing747_lateral()

# name -> (matrix, where it comes from)
CASES: dict[str, tuple[np.ndarray, str]] = {
    "burkardt_1": (np.array([[1.0, 0], [0, 2]]), "diagonal"),
    "burkardt_2": (np.array([[1.0, 3], [3, 2]]), "symmetric"),
    "burkardt_3": (np.array([[0.0, 1], [-39, -40]]), "Laub: bad for Taylor series"),
    "burkardt_4": (np.array([[-49.0, 24], [-64, 31]]), "Moler-Van Loan: hump"),
    "burkardt_5": (
        np.array([[0.0, 6, 0, 0], [0, 0, 6, 0], [0, 0, 0, 6], [0, 0, 0, 0]]),
        "Moler-Van Loan: nilpotent",
    ),
    "burkardt_6": (np.array([[1.0, 1], [0, 1]]), "Moler-Van Loan: defective"),
    "burkardt_7": (
        np.array([[1 + np.finfo(float).eps, 1], [0, 1 - np.finfo(float).eps]]),
        "Moler-Van Loan: nearly defective",
    ),
    "burkardt_8": (
        np.array([[21.0, 17, 6], [-5, -1, -6], [4, 4, 16]]),
        "Wikipedia example",
    ),
    "burkardt_9": (
        np.array([[1.0, 2, 2, 2], [3, 1, 1, 2], [3, 2, 1, 2], [3, 3, 3, 1]]),
        "NAG F01ECF example",
    ),
    "burkardt_10": (
        np.array([[4.0, 2, 0], [1, 4, 1], [1, 1, 4]]),
        "Ward 1: defective, nonderogatory",
    ),
    "burkardt_11": (
        np.array(
            [
                [29.87942128909879, 0.7815750847907159, -2.289519314033932],
                [0.7815750847907159, 25.72656945571064, 8.680737820540137],
                [-2.289519314033932, 8.680737820540137, 34.39400925519054],
            ]
        ),
        "Ward 2: symmetric, eigenvalues 20, 30, 40",
    ),
    "burkardt_12": (
        np.array([[-131.0, 19, 18], [-390, 56, 54], [-387, 57, 52]]),
        "Ward 3: eigenvalues -20, -2, -1",
    ),
    "burkardt_13_n4": (_forsythe(4, 1e-4), "Ward 4: Forsythe matrix, n = 4"),
    "burkardt_13_n10": (_forsythe(10, 1e-10), "Ward 4: Forsythe matrix, n = 10"),
    "burkardt_14": (
        np.array(
            [
                [0.0, 1e-8, 0],
                [-(2e10 + 4e8 / 6.0), -3, 2e10],
                [200.0 / 3.0, 0, -200.0 / 3.0],
            ]
        ),
        "Moler 2012: badly scaled",
    ),
    "nilpotent_pascal_8": (np.diag(np.arange(1.0, 8.0), -1), "nilpotent, lower bidiagonal"),
    "nilpotent_random_6": (
        np.triu(np.random.default_rng(3).standard_normal((6, 6)), 1) * 5,
        "nilpotent, strictly upper triangular",
    ),
    "jordan_block_5": (
        -np.eye(5) + np.diag(np.ones(4), 1),
        "defective: one Jordan block, eigenvalue -1",
    ),
    "jordan_similar_5": (_jordan_similar(5, -0.5, 11), "defective, not triangular"),
    "triangular_nonnormal_6": (_upper_nonnormal(6, 100.0), "triangular, off-diagonal 100"),
    "triangular_nonnormal_2": (
        np.array([[-1.0, 1e4], [0.0, -2.0]]),
        "triangular, off-diagonal 1e4",
    ),
    "nonnormal_rotated_6": (
        _orthogonal(6, 5) @ _upper_nonnormal(6, 10.0) @ _orthogonal(6, 5).T,
        "non-normal, orthogonally similar to a triangular matrix",
    ),
    "large_norm_stiff_5": (
        _orthogonal(5, 8) @ np.diag([-1000.0, -300, -10, -1, -0.1]) @ _orthogonal(5, 8).T,
        "norm ~1e3, stiff, symmetric",
    ),
    "large_norm_random_4": (_random(4, 1000.0, 21), "norm 1e3, random"),
    "large_norm_rotation": (np.array([[0.0, 500.0], [-500.0, 0.0]]), "rotation by 500 rad"),
    "tiny_norm_random_5": (_random(5, 1e-10, 4), "norm 1e-10, random"),
    "tiny_norm_nonnormal_3": (
        np.array([[1e-10, 1e-8, 0], [0, -1e-10, 1e-8], [0, 0, 2e-10]]),
        "norm ~1e-8, triangular",
    ),
    "random_16": (_random(16, 5.0, 7), "random, n = 16, norm 5"),
    "chapter_6_75_t25": (
        25.0 * np.array([[0.0, 1.0], [-2.0, -3.0]]),
        "chapter (6.75) at t = 25",
    ),
    "b747_longitudinal": (A747_LON, "chapter (6.49), t = 1"),
    "b747_longitudinal_t20": (20.0 * A747_LON, "chapter (6.49), t = 20 s (Figure 6.1)"),
    "b747_longitudinal_t500": (500.0 * A747_LON, "chapter (6.49), t = 500 s (Figure 6.1)"),
    "b747_lateral": (A747_LAT, "chapter (6.150), t = 1"),
    "b747_lateral_t30": (30.0 * A747_LAT, "chapter (6.150), t = 30 s (Figure 6.5)"),
}


def _mp_expm(A: np.ndarray, digits: int) -> mpmath.matrix:
    with mpmath.workdps(digits):
        return mpmath.expm(mpmath.matrix(A.tolist()), method="taylor")


@pytest.fixture(scope="module")
def references() -> dict[str, np.ndarray]:
    """50-digit reference exponentials, each verified against a 70-digit one."""
    result = {}
    for name, (A, _) in CASES.items():
        r50 = _mp_expm(A, 50)
        r70 = _mp_expm(A, 70)
        with mpmath.workdps(70):
            agreement = mpmath.mnorm(r50 - r70, "f") / mpmath.mnorm(r70, "f")
        assert agreement < 1e-35, f"{name}: the reference is not converged ({agreement})"
        result[name] = np.array(r50.tolist(), dtype=float)
    return result


def _relative_error(X: np.ndarray, R: np.ndarray) -> float:
    return float(np.linalg.norm(X - R) / np.linalg.norm(R))


def test_there_are_at_least_thirty_cases() -> None:
    assert len(CASES) >= 30


@pytest.mark.parametrize("name", list(CASES))
def test_as_accurate_as_scipy(name: str, references: dict[str, np.ndarray]) -> None:
    A, _ = CASES[name]
    R = references[name]
    ours = _relative_error(aerocontrol.expm(A), R)
    theirs = _relative_error(scipy.linalg.expm(A), R)
    assert ours <= 2 * theirs + 1e-15, f"{name}: ours {ours:.2e}, scipy {theirs:.2e}"


def test_print_accuracy_table(
    references: dict[str, np.ndarray], capsys: pytest.CaptureFixture[str]
) -> None:
    """Prints both errors for every case (the table in the issue's closing note)."""
    rows = []
    for name, (A, origin) in CASES.items():
        R = references[name]
        ours = _relative_error(aerocontrol.expm(A), R)
        theirs = _relative_error(scipy.linalg.expm(A), R)
        rows.append((name, ours, theirs, origin))
    lines = [
        "",
        "expm relative Frobenius error against 50-digit mpmath",
        f"{'case':<26} {'aerocontrol':>12} {'scipy':>12}  origin",
    ]
    lines += [f"{n:<26} {o:12.2e} {t:12.2e}  {orig}" for n, o, t, orig in rows]
    ours_all = np.array([r[1] for r in rows])
    theirs_all = np.array([r[2] for r in rows])
    floor = 1e-17
    ratio = np.exp(np.mean(np.log(np.maximum(ours_all, floor) / np.maximum(theirs_all, floor))))
    lines.append(
        f"cases {len(rows)}; aerocontrol better on {np.sum(ours_all < theirs_all)}, "
        f"geometric-mean error ratio (ours/scipy) {ratio:.2f}, "
        f"worst ours {ours_all.max():.1e}, worst scipy {theirs_all.max():.1e}"
    )
    with capsys.disabled():
        sys.stdout.write("\n".join(lines) + "\n")
    assert len(rows) == len(CASES)


# Closed forms where they are known exactly (independent of mpmath).
CLOSED_FORMS: dict[str, tuple[np.ndarray, Callable[[], np.ndarray]]] = {
    "burkardt_3": (
        np.array([[0.0, 1], [-39, -40]]),
        lambda: np.array(
            [
                [39 / (38 * np.e) - 1 / (38 * np.exp(39)), -np.expm1(-38) / (38 * np.e)],
                [39 * np.expm1(-38) / (38 * np.e), -1 / (38 * np.e) + 39 / (38 * np.exp(39))],
            ]
        ),
    ),
    "burkardt_4": (
        np.array([[-49.0, 24], [-64, 31]]),
        lambda: (
            (np.array([[3.0, 1], [4, 2]]) * np.exp([-17.0, -1.0]))
            @ np.array([[1.0, -0.5], [-2.0, 1.5]])
        ),
    ),
    "burkardt_5": (
        np.array([[0.0, 6, 0, 0], [0, 0, 6, 0], [0, 0, 0, 6], [0, 0, 0, 0]]),
        lambda: np.array([[1.0, 6, 18, 36], [0, 1, 6, 18], [0, 0, 1, 6], [0, 0, 0, 1]]),
    ),
}


@pytest.mark.parametrize("name", list(CLOSED_FORMS))
def test_closed_forms(name: str) -> None:
    A, exact = CLOSED_FORMS[name]
    np.testing.assert_allclose(aerocontrol.expm(A), exact(), rtol=1e-14, atol=0)
