"""Properties of the frequency response (aerocontrol.frequency).

Oracles: G(jω) = C (jωI - A)^-1 B + D by numpy's complex solve at each frequency, within the
solve's conditioning; bode as frequency_response on the default grid, bitwise; the default
grid's definition.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol

from .harness import Arg, Warned, exercise, plain
from .oracles import SLACK, TINY, U, eigenvalue_conditions, finite, norm, quietly, silenced
from .oracles import condition as condition_number
from .strategies import (
    ALL_PRESENTATIONS,
    model_matrices,
    orders,
    presented,
    presented_system,
    system,
)

COVERED = {"frequency_response", "bode", "default_frequency_grid"}

#: Frequencies, with the imaginary-axis poles of the "imaginary axis" plants (1, 2, 3 rad/s).
FREQUENCIES = (0.0, 0.1, 1.0, 2.0, 3.0, 0.5, 10.0, 1e3, 1e-300, 1e300, -1.0, np.inf, np.nan)


def _check_response(
    result: Any, A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray
) -> None:
    """G(jω) against a complex solve: the computed response is that of a model within
    n u ||jωI - A|| of the given one, so it may differ from the exact by
    cond(jωI - A) n u ||C|| ||X|| (X = (jωI - A)^-1 B); frequencies nearer a pole than that
    are skipped."""
    n = A.shape[0]
    omega = result.omega
    assert result.response.shape == (len(omega), C.shape[0], B.shape[1])
    kb, kc = (
        int(np.frexp(float(np.max(np.abs(M), initial=0.0)))[1]) if finite(M) else 0 for M in (B, C)
    )
    assert result.response.dtype == np.complex128
    for k, w in enumerate(omega):
        M = 1j * w * np.eye(n) - A
        condition = condition_number(M)
        if not np.isfinite(condition) or condition * U > 1e-3:
            continue
        with silenced():
            # B and C scaled to unit size by powers of two, and C X scaled back once: the solve
            # with B of 1.3e-301 beside jω - A of 1e149 underflowed X to 0, and the reference
            # G = 0 blamed aerocontrol's correct -1.24e-301.
            X = np.linalg.solve(M, np.ldexp(B, -kb).astype(complex)) if n else B[:0] * 0j
            product = np.ldexp(C, -kc) @ X
            expected = np.ldexp(product.real, kb + kc) + 1j * np.ldexp(product.imag, kb + kc) + D
        if not finite(expected) or np.max(np.abs(expected), initial=0.0) > 1e300:
            continue  # near or beyond overflow: the harness checks the warning
        got = result.response[k]
        assert finite(got), f"NaN or Inf at ω = {w}, where G is finite (cond {condition:.2e})"
        with silenced():
            terms = np.ldexp(condition * norm(np.ldexp(C, -kc)) * norm(X), kb + kc)
            bound = SLACK * max(n, 1) * (U * (terms + norm(D)) + TINY)
        if not np.isfinite(bound):
            continue  # C X overflows in the reference: no measure of the error
        error = norm(got - expected)
        assert error <= bound, f"G(j{w}): error {error:.3e} exceeds {bound:.3e}"
    # The derived quantities exist for any response.
    with silenced():
        assert result.magnitude_db.shape == result.phase_deg.shape == result.response.shape
    assert isinstance(str(result), str)


def _frequency_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    omega = np.atleast_1d(np.asarray(args["omega"], float))
    assert np.array_equal(result.omega, omega), "omega is not the frequencies given"
    _check_response(result, *model_matrices(args["sys"]))


@st.composite
def frequencies(draw: st.DrawFn) -> Arg:
    shape = draw(st.sampled_from(("vector", "vector", "vector", "scalar", "empty", "2-D")))
    values = np.array([draw(st.sampled_from(FREQUENCIES)) for _ in range(4)])
    if shape == "scalar":
        return plain(float(values[0]))
    array = {"vector": values, "empty": values[:0], "2-D": values.reshape(2, 2)}[shape]
    return draw(presented(array))


@given(st.data())
def test_frequency_response(data: st.DataObject) -> None:
    n, m, p = data.draw(orders()), data.draw(st.integers(0, 3)), data.draw(st.integers(0, 3))
    matrices = data.draw(system(n, m, p))
    pair = data.draw(st.sampled_from((False, False, True)))
    exercise(
        "frequency_response",
        aerocontrol.frequency_response,
        {
            "sys": data.draw(presented_system(matrices[:2] if pair else matrices)),
            "omega": data.draw(frequencies()),
        },
        _frequency_oracle,
    )


def _bode_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    omega = args["omega"]
    if omega is None:
        omega = quietly(aerocontrol.default_frequency_grid, args["sys"])
    direct = quietly(aerocontrol.frequency_response, args["sys"], omega)
    assert np.array_equal(result.omega, direct.omega)
    assert np.array_equal(result.response, direct.response, equal_nan=True)
    _check_response(result, *model_matrices(args["sys"]))


@given(st.data())
def test_bode(data: st.DataObject) -> None:
    n, m, p = data.draw(orders()), data.draw(st.integers(0, 2)), data.draw(st.integers(0, 2))
    matrices = data.draw(system(n, m, p))
    omega = plain(None) if data.draw(st.booleans()) else data.draw(frequencies())
    exercise(
        "bode",
        aerocontrol.bode,
        {"sys": data.draw(presented_system(matrices)), "omega": omega},
        _bode_oracle,
    )


def _grid_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A = model_matrices(args["sys"])[0]
    count = args["count"]
    assert result.shape == (count,) and finite(result) and np.all(result > 0)
    assert np.all(np.diff(result) >= 0), "not increasing"
    with silenced():
        magnitudes = np.abs(np.linalg.eigvals(A)) if len(A) else np.zeros(0)
        nonzero = magnitudes[magnitudes > 1e-12 * max(1.0, magnitudes.max(initial=0.0))]
        low, high = (nonzero.min() / 10, nonzero.max() * 10) if nonzero.size else (0.01, 100.0)
    # numpy's and the grid's eigenvalues agree to their backward error: relatively for a
    # well-conditioned slowest mode, and within sqrt(u) ||A||_F for a near-defective one close
    # to zero (whose magnitude neither solver determines better).
    allowed = 1e-6 * low + 0.1 * np.sqrt(np.finfo(float).eps) * float(np.linalg.norm(A))
    # A defective eigenvalue at 0 (a Jordan block of order k) is determined only to
    # u^(1/k) ||A||: one solver may return it as 0 (left out of the grid's range) and the
    # other as 1.4e-8 (the grid then starts at 1.4e-9: a companion matrix of s^2 (s + 1)(s + 2),
    # where numpy's eigenvalues are exactly 0). Such a start is allowed where numpy also has
    # an eigenvalue within that uncertainty of 0.
    with silenced():
        uncertainty = np.finfo(float).eps ** (1.0 / max(len(A), 1)) * float(np.linalg.norm(A))
    near_zero = bool(np.any(magnitudes <= uncertainty)) and 10 * result[0] <= uncertainty
    # And each mode is known to its condition number times its backward error (a 9 x 9 A
    # whose slowest |λ| the core and numpy give 5.6e-6 apart relatively); a near-defective
    # one (κ u above 1e-8: the companion matrix of a root of multiplicity 4) only to the
    # Hölder bound u^(1/n) ||A|| (30.0138 for 30, ten times its largest root).
    spread = 0.0
    if len(A):
        with silenced():
            _, conditions = eigenvalue_conditions(A)
            worst = float(np.max(conditions[np.isfinite(conditions)], initial=np.inf))
            spread = SLACK * len(A) * U * float(np.linalg.norm(A)) * min(worst, 1e300)
            if not worst * U <= 1e-8:
                spread += uncertainty
            allowed += spread / 10
    assert abs(result[0] - low) <= allowed or near_zero, f"starts at {result[0]}, not {low}"
    if count > 1:
        end = min(high, 1e308)
        assert abs(result[-1] - end) <= 1e-6 * end + 10 * spread, f"ends at {result[-1]}"


@given(st.data())
def test_default_frequency_grid(data: st.DataObject) -> None:
    matrices = data.draw(system(data.draw(orders()), 1, 1))
    count = data.draw(st.sampled_from((1000, 1, 2, 17, 0, -3, 2.5, True)))
    outcome = exercise(
        "default_frequency_grid",
        aerocontrol.default_frequency_grid,
        {"sys": data.draw(presented_system(matrices, ALL_PRESENTATIONS)), "count": plain(count)},
        _grid_oracle,
    )
    if count in (0, -3, 2.5) or count is True:
        assert outcome.error is not None, f"count={count!r} was accepted"


# ----- inputs a campaign found (regressions) -----------------------------------------------------

FREQUENCY_EXAMPLES = {
    "huge frequency": ((np.array([[0.1257]]), np.array([[1.0]])), [1e155, 1e200, 1e300]),
    "huge A": ((np.array([[1e200]]), np.array([[1.0]])), [0.0, 1.0]),
    "largest A": ((np.array([[1e308]]), np.array([[0.126]])), [0.0]),
    "tiny A": ((1e-160 * np.array([[-1.0, 2.0], [0.0, -3.0]]), np.ones((2, 1))), [0.0]),
    "tinier A": ((1e-200 * np.array([[-1.0, 2.0], [0.0, -3.0]]), np.ones((2, 1))), [0.0, 1e-200]),
    "huge B": ((np.array([[-1.87e8]]), np.array([[2e300]]), np.array([[0.126]])), [0.0, 1e8]),
    "tiny frequency": ((np.array([[0.0]]), np.array([[0.126]])), [1e-300, 1e-320]),
}


@pytest.mark.parametrize("example", FREQUENCY_EXAMPLES)
def test_frequency_extreme_scale(example: str) -> None:
    """Models and frequencies whose squares leave the normal range (G was 0 or NaN: the
    Hessenberg solve squared entries)."""
    sys, omega = FREQUENCY_EXAMPLES[example]
    exercise(
        "frequency_response",
        aerocontrol.frequency_response,
        {"sys": plain(sys), "omega": plain(omega)},
        _frequency_oracle,
    )


def test_regression_grid_oracle_of_a_defective_zero_eigenvalue() -> None:
    """The companion matrix of s^2 (s + 1)(s + 2): numpy's eigenvalues include 0 twice
    exactly, the core's ±1.4e-8 (within sqrt(u) ||A|| of the defective eigenvalue): the grid
    began at 1.4e-9 and the oracle, which left out numpy's zeros, wanted 0.1."""
    A = np.array(
        [[-3.0, -2.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]
    )
    B = np.array([[0.1257302210933933], [-0.1321048632913019], [0.6404226504432821], [0.1049]])
    model = (A, B, B.T.copy(), np.zeros((1, 1)))
    outcome = exercise(
        "default_frequency_grid",
        aerocontrol.default_frequency_grid,
        {"sys": plain(model), "count": plain(1000)},
        _grid_oracle,
    )
    assert outcome.result[0] < 1e-6 and outcome.result[-1] == pytest.approx(20.0, rel=1e-6)


def test_regression_frequency_response_of_a_tiny_pole_at_a_huge_frequency() -> None:
    """A = [[1.26e-151]], B = 0.126, C = 1: G(jω) = B C / (jω - a) = -1.26e-201j at ω = 1e200
    and -1.26e-301j at 1e300 (to 1e-15), normal doubles, was 0 (the core's solve at
    jω / σ, σ the power of two of A's largest entry, overflowed or underflowed; the point is
    now beyond 2^600 σ and G is the leading term of its expansion at infinity)."""
    a, b = 1.257302210933933e-151, 0.1257302210933933
    model = (np.array([[a]]), np.array([[b]]))
    outcome = exercise(
        "frequency_response",
        aerocontrol.frequency_response,
        {"sys": plain(model), "omega": plain(np.array([0.0, 1e200, 1e300]))},
        _frequency_oracle,
    )
    response = outcome.result.response[:, 0, 0]
    for w, value in zip((1e200, 1e300), response[1:], strict=True):
        assert value == pytest.approx(b / complex(-a, w), rel=1e-15)
    assert response[0] == pytest.approx(-b / a, rel=1e-15)


def test_regression_frequency_oracle_of_a_response_below_its_factors() -> None:
    """A of 1.26e149, B of 1.26e-301, C of 1.26e149 at ω = 1.26e148: the reference solve
    (jωI - A) X = B underflowed X (1e-450) to 0, and its G = 0 blamed aerocontrol's correct
    G = B C / (jω - A) = -1.245e-301 - 1.245e-302j (closed form)."""
    a, b, c = 1.257302210933933e149, 1.257302210933933e-301, 1.257302210933933e149
    w = 1.2573022109339299e148
    outcome = exercise(
        "frequency_response",
        aerocontrol.frequency_response,
        {"sys": plain(([[a]], [[b]], [[c]], [[0.0]])), "omega": plain(np.array([w]))},
        _frequency_oracle,
    )
    expected = (b * c) / complex(-a, w)
    assert outcome.result.response[0, 0, 0] == pytest.approx(expected, rel=1e-14)
