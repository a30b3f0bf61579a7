"""Properties of modal analysis and the characteristic polynomial (aerocontrol.modal).

Oracles: eigenvalue backward errors and the characteristic polynomial of numpy's eigenvalues
(oracles.assert_spectrum); the modes' characteristics by their formulas; the modal matrix by
its residual A P - P Λ and P^-1 B by its residual; the coefficients against numpy.poly within
the perturbation bound of the coefficients.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import IllConditionedWarning

from .harness import Warned, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U,
    assert_coefficients,
    assert_spectrum,
    characteristic_tolerance,
    finite,
    norm,
    silenced,
)
from .strategies import (
    canonical,
    model_matrices,
    orders,
    presented,
    presented_system,
    rectangular,
    square,
)

COVERED = {"modes", "charpoly"}

#: Fields of Modes that are infinite or NaN by definition (a real mode has no period, λ = 0
#: no damping ratio, a growing mode no time to half, a singular modal matrix an infinite
#: condition number).
BY_DEFINITION = (
    "damping_ratio",
    "period",
    "time_to_half",
    "time_to_double",
    "cycles_to_half",
    "time_constant",
    "modal_matrix_condition",
)


def _plant(args: dict[str, Any]) -> tuple[np.ndarray, np.ndarray | None]:
    given_ = args["A_or_sys"]
    if isinstance(given_, np.ndarray):
        return given_, None
    A, B, _, _ = model_matrices(given_)
    return A, B


def _modes_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B = _plant(args)
    n = A.shape[0]
    lam = result.eigenvalues
    assert_spectrum(A, lam, "modes")
    if n == 0 or not finite(A, lam):
        return
    # Pairs adjacent, Im > 0 first; one entry per mode, by increasing natural frequency.
    k, modes = 0, []
    while k < n:
        modes.append(lam[k])
        if lam[k].imag == 0:
            k += 1
            continue
        assert lam[k].imag > 0 and k + 1 < n and lam[k + 1] == np.conj(lam[k]), f"{k}: {lam}"
        k += 2
    assert np.array_equal(result.eigenvalue, np.array(modes)), "one eigenvalue per mode"
    magnitudes = np.abs(result.eigenvalue)
    assert np.all(np.diff(magnitudes) >= -4 * U * magnitudes[1:]), "not by natural frequency"
    # The characteristics, by their definitions (a few roundings each).
    with silenced():
        sigma, wd = result.eigenvalue.real, np.abs(result.eigenvalue.imag)
        expected = {
            "natural_frequency": magnitudes,
            "damping_ratio": -sigma / magnitudes,
            "damped_frequency": wd,
            "period": np.where(wd > 0, 2 * np.pi / wd, np.inf),
        }
    for name, value in expected.items():
        got = getattr(result, name)
        close = np.isclose(got, value, rtol=16 * U, atol=0.0, equal_nan=True)
        assert np.all(close | (np.isinf(got) & np.isinf(value))), f"{name}: {got} != {value}"
    assert np.array_equal(result.oscillatory, wd > 0)
    # The modal matrix: unit columns with A P = P Λ, or None with a warning.
    P = result.modal_matrix
    if P is None:
        assert IllConditionedWarning in warned, "no modal matrix, and no warning"
        return
    assert P.shape == (n, n)
    assert np.allclose(np.linalg.norm(P, axis=0), 1.0, rtol=0, atol=SLACK * n * U)
    residual = norm(A @ P - P * lam[None, :])
    assert residual <= SLACK * n * (U * norm(A) * norm(P) + TINY), "A P != P Λ"
    if B is not None and result.modal_input is not None:
        M = result.modal_input
        assert M.shape == B.shape
        with silenced():
            scale = norm(P) * norm(M) + norm(B)
        if finite(M) and np.isfinite(scale):
            assert norm(P @ M - B) <= SLACK * n * (U * scale + TINY), "P (P^-1 B) != B"
    assert isinstance(str(result), str)


@given(st.data())
def test_modes(data: st.DataObject) -> None:
    n = data.draw(orders())
    A = data.draw(square(n))
    kind = data.draw(st.sampled_from(("matrix", "matrix", "system")))
    if kind == "matrix":
        plant = data.draw(presented(A))
    else:
        plant = data.draw(presented_system((A, data.draw(rectangular(n, 2)))))
    names = data.draw(st.sampled_from(("none", "right", "too few")))
    mode_names = None
    if names != "none" and finite(A):
        eigenvalues = np.linalg.eigvals(A) if n else np.zeros(0)
        count = n - int(np.sum(eigenvalues.imag != 0)) // 2
        mode_names = [f"m{k}" for k in range(count - (names == "too few"))]
    exercise(
        "modes",
        aerocontrol.modes,
        {"A_or_sys": plant, "mode_names": plain(mode_names)},
        _modes_oracle,
        nonfinite_by_definition=BY_DEFINITION,
    )


def _charpoly_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A = args["A"]
    n = A.shape[0]
    assert result.shape == (n + 1,) and result.dtype == np.float64
    assert result[0] == 1.0, "the polynomial is monic"
    with silenced():
        expected = np.real(np.poly(A)) if n else np.ones(1)
    assert_coefficients(result, expected, characteristic_tolerance(A), "charpoly")


@given(st.data())
def test_charpoly(data: st.DataObject) -> None:
    A = data.draw(square(data.draw(orders())))
    exercise("charpoly", aerocontrol.charpoly, {"A": data.draw(presented(A))}, _charpoly_oracle)


# ----- inputs a campaign found (regressions) -----------------------------------------------------


def test_modes_of_tiny_matrices() -> None:
    """Entries near 1e-301 (the Schur form once returned the diagonal as the eigenvalues)."""
    A = 1e-301 * np.array([[1.257, -1.321], [6.404, 1.049]])
    exercise(
        "modes",
        aerocontrol.modes,
        {"A_or_sys": canonical(A), "mode_names": plain(None)},
        _modes_oracle,
        nonfinite_by_definition=BY_DEFINITION,
    )


def test_modes_of_states_scaled_far_apart() -> None:
    """A random stable 3-state A with its states scaled by 1e-6, 1 and 1e6 (A = T A0 T^-1):
    the modes' eigenvalues are those of A0 to 1e-12 relatively (numpy's eigvals of A0), as
    aerocontrol.linalg.eigenvalues(A) gives them (the core's eigen balances A first: without
    it they were 3e-4 off)."""
    rng = np.random.default_rng(5)
    A0 = rng.standard_normal((3, 3)) - np.eye(3)
    T = np.diag([1e-6, 1.0, 1e6])
    A = T @ A0 @ np.linalg.inv(T)
    exact = np.sort_complex(np.linalg.eigvals(A0))
    np.testing.assert_allclose(
        np.sort_complex(aerocontrol.linalg.eigenvalues(A)), exact, rtol=1e-12
    )
    found = aerocontrol.modes(A)
    np.testing.assert_allclose(np.sort_complex(found.eigenvalues), exact, rtol=1e-12)


def test_modes_of_states_scaled_far_apart_are_not_defective() -> None:
    """The same A, with B = T B0: no warning of a defective eigenvalue (the condition number
    of P in the model's units, 1.3e12, made three simple, well-separated eigenvalues look
    defective and withheld P and P^-1 B, which is judged by the modal matrix of the balanced
    states); P's own condition is reported (as numpy's cond of P, to 1e-2: σ_min of P is
    known to u κ₂(P), 3e-4 relatively), and P (P^-1 B) = B
    componentwise to 1e-12 of |P| |P^-1 B| while A P = P Λ to 1e-12 of |A| |P|."""
    rng = np.random.default_rng(5)
    A0 = rng.standard_normal((3, 3)) - np.eye(3)
    B0 = rng.standard_normal((3, 2))
    T = np.diag([1e-6, 1.0, 1e6])
    A, B = T @ A0 @ np.linalg.inv(T), T @ B0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = aerocontrol.modes((A, B, np.eye(3), np.zeros((3, 2))))
    assert found.modal_matrix is not None and found.modal_input is not None
    P, X = found.modal_matrix, found.modal_input
    assert found.modal_matrix_condition == pytest.approx(np.linalg.cond(P), rel=1e-2, abs=0)
    assert found.modal_matrix_condition > 1e11
    assert np.all(np.abs(P @ X - B) <= 1e-12 * (np.abs(P) @ np.abs(X)))
    residual = np.abs(A @ P - P * found.eigenvalues[None, :])
    assert np.all(residual <= 1e-12 * (np.abs(A) @ np.abs(P)))
