"""Identities of the state transition matrix (chapter §6.1.2) that must hold for every A.

Property tests with hypothesis, on random matrices of orders 1 to 12 (both the stack-matrix
engine, n <= 8, and the general one) and norms from 1e-3 to 10:

* Φ(0) = I (6.24);
* Φ(t1 + t2) = Φ(t1) Φ(t2) (6.25, 6.26);
* e^{-At} = (e^{At})^-1 (6.27);
* A e^{At} = e^{At} A (6.28);
* det e^A = e^{tr A}.

Tolerances scale with the size of the quantities compared and with the exponential's condition
(through ||A||), since the identities are exact only in exact arithmetic.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import aerocontrol


@st.composite
def matrices(draw: st.DrawFn, max_norm: float = 10.0) -> np.ndarray:
    n = draw(st.integers(1, 12))
    seed = draw(st.integers(0, 2**32 - 1))
    norm = draw(st.floats(1e-3, max_norm))
    A = np.random.default_rng(seed).standard_normal((n, n))
    return A * (norm / np.linalg.norm(A, 1))


times = st.floats(-3.0, 3.0, allow_nan=False)


@given(matrices())
@settings(max_examples=60, deadline=None)
def test_exponential_of_zero_time_is_identity(A: np.ndarray) -> None:
    np.testing.assert_array_equal(aerocontrol.transition_matrix(A, 0.0), np.eye(len(A)))
    np.testing.assert_array_equal(aerocontrol.expm(np.zeros_like(A)), np.eye(len(A)))


@given(matrices(max_norm=3.0), times, times)
@settings(max_examples=100, deadline=None)
def test_semigroup(A: np.ndarray, t1: float, t2: float) -> None:
    phi1, phi2, phi12 = aerocontrol.transition_matrix(A, [t1, t2, t1 + t2])
    scale = np.linalg.norm(phi1) * np.linalg.norm(phi2)
    growth = 1.0 + np.linalg.norm(A, 1) * (abs(t1) + abs(t2))
    assert np.linalg.norm(phi1 @ phi2 - phi12) <= 1e-14 * growth * scale * len(A)


@given(matrices(max_norm=3.0), times)
@settings(max_examples=100, deadline=None)
def test_inverse_is_the_negative_time(A: np.ndarray, t: float) -> None:
    forward, backward = aerocontrol.transition_matrix(A, [t, -t])
    scale = np.linalg.norm(forward) * np.linalg.norm(backward)
    growth = 1.0 + np.linalg.norm(A, 1) * abs(t)
    assert np.linalg.norm(forward @ backward - np.eye(len(A))) <= 1e-14 * growth * scale * len(A)


@given(matrices(), times)
@settings(max_examples=100, deadline=None)
def test_commutes_with_a(A: np.ndarray, t: float) -> None:
    phi = aerocontrol.transition_matrix(A, t)
    scale = np.linalg.norm(A) * np.linalg.norm(phi)
    growth = 1.0 + np.linalg.norm(A, 1) * abs(t)
    assert np.linalg.norm(A @ phi - phi @ A) <= 1e-14 * growth * scale * len(A)


@given(matrices(max_norm=5.0))
@settings(max_examples=100, deadline=None)
def test_determinant_is_exponential_of_trace(A: np.ndarray) -> None:
    sign, log_det = np.linalg.slogdet(aerocontrol.expm(A))
    assert sign == 1.0
    cond = np.linalg.cond(aerocontrol.expm(A))
    assert abs(log_det - np.trace(A)) <= 1e-14 * (1.0 + cond) * len(A) * (1 + np.linalg.norm(A, 1))
