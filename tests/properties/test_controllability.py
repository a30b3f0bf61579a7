"""Properties of the controllability and observability matrices and tests
(aerocontrol.controllability).

Oracles: the Krylov blocks A V_k against numpy's products; the staircase form by its
definition (Z = T^-1 Q for the pair's state balancing T, Q orthogonal, Q^T A Q and Q^T B of the
balanced pair, nothing below the staircase but what the rank decisions judged negligible,
within the tolerance); each mode
declared uncontrollable by the Popov-Belevitch-Hautus test, sigma_min([A - λI, B]) within the
tolerance the verdict used; pairs planted exactly uncontrollable declared so; the verdict of
is_controllable and is_observable equal to that of the full analysis; observability as the
dual.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol

from .harness import Warned, exercise, plain
from .oracles import SLACK, TINY, U, assert_spectrum, finite, norm, quietly, silenced
from .strategies import (
    canonical,
    model_matrices,
    orders,
    planted_uncontrollable,
    presented,
    presented_system,
    rectangular,
    scalar,
    square,
)

COVERED = {"ctrb", "obsv", "controllability", "observability", "is_controllable", "is_observable"}

TOLERANCES = st.sampled_from((None, None, None, 0.0, 1e-8, 1e-3, 1e300, -1.0, np.nan))
METHODS = st.sampled_from(("full", "full", "staircase", "modal"))


def _pair(args: dict[str, Any], second: str) -> tuple[np.ndarray, np.ndarray]:
    """(A, B) or (A, C) from A_or_sys and the second matrix, canonical."""
    given_ = args["A_or_sys"]
    other = args.get(second)
    if other is None:  # a model (a tuple)
        A, other = given_[0], given_[1]
    else:
        A = given_
    A, other = np.asarray(A, float), np.asarray(other, float)
    return A, other.reshape(-1, 1) if other.ndim == 1 and second == "B" else other


def _krylov_oracle(dual: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        A = np.asarray(args["A"], float)
        X = np.asarray(args["C" if dual else "B"], float)
        if dual:  # [C; CA; ...] is the transpose of the controllability matrix of (A^T, C^T)
            A, X, result = A.T, X.T, result.T
        n, m = X.shape
        assert result.shape == (n, n * m)
        if n:
            assert np.array_equal(result[:, :m], X), "the first block is B (C)"
        for k in range(1, n):
            previous, block = result[:, (k - 1) * m : k * m], result[:, k * m : (k + 1) * m]
            with silenced():
                expected = A @ previous
                bound = SLACK * n * (U * norm(A) * norm(previous) + TINY)
            if finite(expected, block) and np.isfinite(bound):
                assert norm(block - expected) <= bound, f"block {k} is not A times block {k - 1}"

    return oracle


@given(st.data())
def test_ctrb_and_obsv(data: st.DataObject) -> None:
    n, m = data.draw(orders()), data.draw(st.integers(0, 3))
    A = data.draw(square(n))
    dual = data.draw(st.booleans())
    X = data.draw(rectangular(m, n) if dual else rectangular(n, m))
    name, key = ("obsv", "C") if dual else ("ctrb", "B")
    exercise(
        name,
        getattr(aerocontrol, name),
        {"A": data.draw(presented(A)), key: data.draw(presented(X))},
        _krylov_oracle(dual),
    )


def _pbh_distance(A: np.ndarray, X: np.ndarray, eigenvalue: complex) -> float:
    """sigma_min([A - λI, X]): how far (A, X) is from having λ as an uncontrollable mode."""
    n = A.shape[0]
    stacked = np.hstack([A - eigenvalue * np.eye(n), X]).astype(complex)
    return float(np.linalg.svd(stacked, compute_uv=False)[-1]) if n else 0.0


def _balancing_of(Z: np.ndarray, dual: bool) -> np.ndarray:
    """The diagonal T of the pair's state balancing from the staircase's transformation
    Z = T^-1 Q (controllability) or T Q (observability), Q orthogonal: Z Z^T = T^∓2, diagonal,
    and T of powers of two (the identity where the states were not scaled apart)."""
    n = Z.shape[0]
    gram = Z @ Z.T
    if not finite(gram) or n == 0:
        return np.ones(n)
    diagonal = np.sqrt(np.diag(gram))
    off = gram - np.diag(np.diag(gram))
    assert np.all(np.abs(off) <= SLACK * n * U * np.outer(diagonal, diagonal)), "Z Z^T diagonal"
    powers = np.exp2(np.round(np.log2(diagonal)))
    assert np.all(np.abs(diagonal - powers) <= SLACK * n * U * powers), "T of powers of two"
    return powers if dual else 1.0 / powers


def _analysis_oracle(dual: bool, planted: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        A, X = _pair(args, "C" if dual else "B")
        if dual:
            A, X = A.T, X.T
        n = A.shape[0]
        assert result.kind == ("observability" if dual else "controllability")
        assert result.controllable == (len(result.uncontrollable_eigenvalues) == 0)
        SA, SB, Z = result.staircase_A, result.staircase_B, result.Z
        if dual:
            SA, SB = SA.T, SB.T
        # Both tests run on the pair (T A T^-1, T B) of balanced states (T = I unless A's
        # states are scaled apart); the orthogonal Q of the staircase is T Z or T^-1 Z.
        T = _balancing_of(Z, dual)
        if not np.all(T == 1.0):
            A, X = T[:, None] * A / T[None, :], T[:, None] * X
            Z = (T[:, None] * Z) if not dual else Z / T[:, None]
        tol = result.tolerance
        if args["tol"] is None:  # n ε max(||A||_F, ||B||_F), ε = 2u
            with silenced():
                default = n * 2 * U * max(norm(A), norm(X))
            assert abs(tol - default) <= 8 * U * default, f"tolerance {tol}, not {default}"
        else:
            assert tol == float(args["tol"])
        # The staircase: Q orthogonal, Q^T A Q and Q^T B (transposed for observability), exact
        # zeros below the steps and under the controllable part.
        order = result.controllable_order
        assert sum(result.block_sizes) == order <= n
        assert Z.shape == (n, n) and SA.shape == (n, n) and SB.shape == X.shape
        if finite(A, X, Z, SA, SB):
            with silenced():
                size = norm(A) + norm(X)
            assert norm(Z.T @ Z - np.eye(n)) <= SLACK * n * U, "Z is not orthogonal"
            assert norm(Z.T @ A @ Z - SA) <= SLACK * n * (U * size + TINY), "Z^T A Z"
            assert norm(Z.T @ X - SB) <= SLACK * n * (U * size + TINY), "Z^T B"
        # Below the steps: only what the rank decisions judged negligible (norm <= tol).
        first = result.block_sizes[0] if result.block_sizes else 0
        negligible = tol * (1 + SLACK * U) + SLACK * n * TINY
        if finite(SB, SA):
            assert norm(SB[first:]) <= negligible, "Z^T B is not zero below its first block"
            assert norm(SA[order:, :order]) <= negligible, "the uncontrollable part is coupled"
        offsets = np.concatenate([[0], np.cumsum(result.block_sizes)]).astype(int)
        for j, size_j in enumerate(result.block_sizes):
            below = offsets[min(j + 2, len(offsets) - 1)]
            block = SA[below:order, offsets[j] : offsets[j] + size_j]
            if finite(block):
                assert norm(block) <= negligible, f"not a staircase under block {j}"
        # Each mode declared unreachable is within about tol of being exactly so (PBH).
        for eigenvalue in result.uncontrollable_eigenvalues:
            if finite(A, X):
                distance = _pbh_distance(A, X, complex(eigenvalue))
                bound = SLACK * max(n, 1) * (tol + U * (norm(A) + norm(X)) + TINY)
                assert distance <= bound, f"{eigenvalue} is reachable: PBH distance {distance:.2e}"
        assert len(result.uncontrollable_eigenvalues) >= n - order
        if args["method"] == "full":
            assert_spectrum(A, result.eigenvalues, "the eigenvalues of the modal test")
            assert result.modal_measure.shape == (n,)
            if planted and finite(A, X) and args["tol"] is None:
                assert not result.controllable, "an exactly uncontrollable pair was passed"
        # The verdict alone is the same.
        alone = quietly(
            getattr(aerocontrol, "is_observable" if dual else "is_controllable"),
            args["A_or_sys"],
            args.get("C" if dual else "B"),
            tol=args["tol"],
            method=args["method"],
        )
        assert alone == result.controllable, "is_controllable disagrees with controllability"
        assert isinstance(str(result), str)

    return oracle


def _verdict_oracle(dual: bool, planted: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        assert type(result) is bool
        full = quietly(
            getattr(aerocontrol, "observability" if dual else "controllability"),
            args["A_or_sys"],
            args.get("C" if dual else "B"),
            tol=args["tol"],
            method=args["method"],
        )
        assert result == full.controllable
        if planted and args["method"] == "full" and args["tol"] is None:
            A, X = _pair(args, "C" if dual else "B")
            if finite(A, X):
                assert not result, "an exactly uncontrollable pair was passed"

    return oracle


@given(st.data())
def test_controllability_and_observability(data: st.DataObject) -> None:
    n, m = data.draw(orders()), data.draw(st.integers(0, 3))
    planted = data.draw(st.booleans())
    if planted:
        A, X, _ = data.draw(planted_uncontrollable(n, m))
        n = A.shape[0]
    else:
        A, X = data.draw(square(n)), data.draw(rectangular(n, m))
    dual = data.draw(st.booleans())
    if dual:
        A, X = A.T.copy(), X.T.copy()
    verdict_only = data.draw(st.booleans())
    name = {
        (False, False): "controllability",
        (True, False): "observability",
        (False, True): "is_controllable",
        (True, True): "is_observable",
    }[(dual, verdict_only)]
    key = "C" if dual else "B"
    if data.draw(st.sampled_from((False, False, True))):
        arguments = {
            "A_or_sys": data.draw(presented_system((A, X.T if dual else X))),
            key: plain(None),
        }
        if dual:  # a model (A, B) gives C = I to observability; pass (A, B, C, D) instead
            p = X.shape[0]
            model = (A, np.zeros((A.shape[0], 1)), X, np.zeros((p, 1)))
            arguments = {"A_or_sys": data.draw(presented_system(model)), key: plain(None)}
    else:
        arguments = {"A_or_sys": data.draw(presented(A)), key: data.draw(presented(X))}
    tol = data.draw(TOLERANCES)
    arguments["tol"] = plain(tol, finite=False) if tol is None else data.draw(scalar(tol))
    arguments["method"] = plain(data.draw(METHODS))
    oracle = (_verdict_oracle if verdict_only else _analysis_oracle)(dual, planted)
    outcome = exercise(
        name,
        getattr(aerocontrol, name),
        arguments,
        _through_models(oracle, key),
        nonfinite_by_definition=("smallest_pivot",),  # inf when no pivot was accepted
    )
    if arguments["method"].value == "modal" or (tol is not None and not tol >= 0):
        assert outcome.error is not None, f"method {arguments['method'].value}, tol {tol}"


def _through_models(oracle: Any, key: str) -> Any:
    """The oracle, with a model argument unpacked into A and B (or A and C)."""

    def unpacked(result: Any, args: dict[str, Any], warned: Warned) -> None:
        if args.get(key) is None:
            A, B, C, _ = model_matrices(args["A_or_sys"])
            args = {**args, "A_or_sys": A, key: C if key == "C" else B}
        oracle(result, args, warned)

    return unpacked


# ----- inputs a campaign found (regressions) -----------------------------------------------------


CONTROLLABLE_EXTREME_PAIRS = {
    "huge": (np.array([[0.125]]), np.array([[1e308]]), None),
    "tiny": (np.array([[1.0]]), np.array([[1e-170]]), 0.0),
    "all tiny": (np.array([[1e-301]]), np.array([[1e-301]]), None),
    "huge A": (np.array([[1e300, 1e300], [0.0, 2e300]]), np.array([[0.0], [1e300]]), None),
}


@pytest.mark.parametrize("example", CONTROLLABLE_EXTREME_PAIRS)
def test_controllability_extreme_entries(example: str) -> None:
    """Pairs whose squares leave the normal range (once declared uncontrollable: the norms
    were formed from unscaled sums of squares)."""
    A, B, tol = CONTROLLABLE_EXTREME_PAIRS[example]
    outcome = exercise(
        "controllability",
        aerocontrol.controllability,
        {
            "A_or_sys": canonical(A),
            "B": canonical(B),
            "tol": plain(tol),
            "method": plain("full"),
        },
        _through_models(_analysis_oracle(False, False), "B"),
        nonfinite_by_definition=("smallest_pivot",),
    )
    # Both pairs are controllable in exact arithmetic and far from any uncontrollable one
    # relative to their tolerance.
    assert outcome.result.controllable, "a controllable pair was declared uncontrollable"


def test_regression_controllability_tolerance_beyond_the_scaled_doubles() -> None:
    """A tolerance whose ratio to the pair's size is beyond the doubles (1e300 beside
    1.26e-151) is reported as given, not as the overflow of its scaled copy (it was inf)."""
    arguments = {
        "A_or_sys": plain(np.array([[1.257302210933933e-151]])),
        "B": plain(np.zeros((1, 0))),
        "tol": plain(1e300),
        "method": plain("full"),
    }
    outcome = exercise(
        "controllability",
        aerocontrol.controllability,
        arguments,
        _through_models(_analysis_oracle(False, False), "B"),
        nonfinite_by_definition=("smallest_pivot",),
    )
    assert outcome.result.tolerance == 1e300
    assert not outcome.result.controllable


def test_regression_uncontrollable_eigenvalues_within_the_order() -> None:
    """A pair of order 2, states scaled by 1e5 (the similarity of a well-scaled controllable
    pair): the staircase's uncontrollable block had the eigenvalue -0.2577, which is no
    eigenvalue of A (0.8635 ± 0.6537j, by numpy), and the modal test, under the tolerance
    5.8e-6, flagged both eigenvalues (measure 5.4e-6); the list had 3 entries. Whatever the
    verdict, the uncontrollable eigenvalues are at most n eigenvalues of A (to 1e-6
    relatively), and the full method agrees with is_controllable. Balanced first, the pair
    is controllable, as its unscaled original."""
    A = np.array([[0.822, 3.3e-11], [-1.3e10, 0.905]])
    B = np.array([[4.46e-6], [-53700.0]])
    analysis = aerocontrol.controllability(A, B)
    listed = np.asarray(analysis.uncontrollable_eigenvalues)
    eigenvalues = np.linalg.eigvals(A)
    assert listed.size <= 2
    for value in listed:
        assert np.min(np.abs(eigenvalues - value)) <= 1e-6 * max(abs(value), 1.0)
    assert analysis.controllable == aerocontrol.is_controllable(A, B)
    assert analysis.controllable


def test_regression_controllability_of_badly_scaled_states() -> None:
    """A controllable pair with its states scaled by D = diag(1e6, 1, 1e-6) (D A D^-1, D B)
    was declared uncontrollable with 5 uncontrollable eigenvalues for 3 states: the default
    tolerance n ε max(||A||_F, ||B||_F) = 4.0e-4 is not invariant under the scaling, and the
    unit left eigenvectors' measures all fell below it."""
    A = np.array([[0.1, -0.1, 0.6], [0.1, -0.5, 0.4], [1.3, 0.9, -0.7]])
    B = np.array([[-1.3], [-0.6], [0.0]])
    # The oracle, in the unscaled coordinates: every left eigenvector reaches B, and the
    # Krylov matrix is far from rank deficient; a diagonal similarity changes neither verdict.
    _, left = np.linalg.eig(A.T)
    assert np.min(np.abs(left.T @ B)) > 0.14
    krylov = np.hstack([np.linalg.matrix_power(A, k) @ B for k in range(3)])
    assert np.linalg.svd(krylov, compute_uv=False)[-1] > 0.11
    assert aerocontrol.controllability(A, B).controllable
    d = np.array([1e6, 1.0, 1e-6])
    scaled = aerocontrol.controllability(d[:, None] * A / d[None, :], d[:, None] * B)
    hidden = scaled.uncontrollable_eigenvalues
    assert len(hidden) <= 3, f"{len(hidden)} uncontrollable eigenvalues for 3 states: {hidden}"
    assert scaled.controllable


@pytest.mark.parametrize("dual", [False, True])
@pytest.mark.parametrize("seed", range(12))
def test_regression_verdicts_invariant_under_state_scaling(seed: int, dual: bool) -> None:
    """The class of the two regressions above: a pair (controllable, or with one planted
    uncontrollable mode, by an orthogonal similarity of a block triangular pair) and the same
    pair with its states scaled by D of 10^±6 (D A D^-1, D B; for observability A, C D^-1)
    get the same verdict, and the same uncontrollable eigenvalue (to 1e-8 relatively); the
    transformation satisfies Z^-1 A Z = the form, Z^-1 B (C Z) = its input (output) block."""
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(3, 7)), int(rng.integers(1, 3))
    planted = seed % 2 == 1
    A = rng.standard_normal((n, n))
    X = rng.standard_normal((n, m))
    hidden = -0.5 - seed / 10.0
    if planted:
        A[-1, :] = 0.0
        A[-1, -1] = hidden
        X[-1, :] = 0.0
        Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
        A, X = Q @ A @ Q.T, Q @ X
    if dual:
        A, X = A.T.copy(), X.T.copy()
    d = np.exp(rng.uniform(-6.0, 6.0, n) * np.log(10.0))
    scaled_A = d[:, None] * A / d[None, :]
    scaled_X = X / d[None, :] if dual else d[:, None] * X
    analyse = aerocontrol.observability if dual else aerocontrol.controllability
    given, scaled = analyse(A, X), analyse(scaled_A, scaled_X)
    assert given.controllable == scaled.controllable == (not planted)
    if planted:
        assert len(scaled.uncontrollable_eigenvalues) == 1
        assert abs(scaled.uncontrollable_eigenvalues[0] - hidden) <= 1e-8 * abs(hidden)
    Z = scaled.Z
    size = np.linalg.norm(np.linalg.solve(Z, scaled_A @ Z))
    assert np.linalg.norm(np.linalg.solve(Z, scaled_A @ Z) - scaled.staircase_A) <= 1e-12 * size
    block = scaled_X @ Z if dual else np.linalg.solve(Z, scaled_X)
    assert np.linalg.norm(block - scaled.staircase_B) <= 1e-12 * np.linalg.norm(block)
    verdict = aerocontrol.is_observable if dual else aerocontrol.is_controllable
    assert verdict(scaled_A, scaled_X) == (not planted)
