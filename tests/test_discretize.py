"""Exact discretisation by Van Loan's augmented exponential.

Oracles: the chapter's formula Γ0 = (e^{Ah} - I) A^-1 B (6.42-6.43) where A is nonsingular,
adaptive Gauss-Kronrod quadrature of ∫ e^{Aτ} dτ B (scipy.integrate.quad_vec, with
scipy.linalg.expm inside) where it is singular, and scipy.signal.cont2discrete.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
import scipy.signal

import aerocontrol
from aerocontrol import InvalidArgumentError, NonFiniteError, NotRealError, ShapeError

A747, B747 = aerocontrol.chapter.boeing747_longitudinal()
A_SINGULAR, B_SINGULAR = aerocontrol.chapter.state_feedback_example()  # (6.95), λ = 0


def _quadrature(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Γ0 and Γ1 by adaptive quadrature, independent of the augmented matrix."""
    gamma0, _ = scipy.integrate.quad_vec(
        lambda tau: scipy.linalg.expm(A * tau) @ B, 0.0, h, epsabs=1e-15, epsrel=1e-13
    )
    gamma1, _ = scipy.integrate.quad_vec(
        lambda tau: scipy.linalg.expm(A * tau) @ B * (h - tau) / h,
        0.0,
        h,
        epsabs=1e-15,
        epsrel=1e-13,
    )
    return gamma0, gamma1


@pytest.mark.parametrize("h", [1e-3, 0.05, 1.0, 20.0])
def test_zoh_equals_the_chapter_formula_for_nonsingular_a(h: float) -> None:
    d = aerocontrol.discretize(A747, B747, h)
    expected = np.linalg.solve(A747, (scipy.linalg.expm(A747 * h) - np.eye(4)) @ B747)
    np.testing.assert_allclose(d.Gamma0, expected, rtol=1e-11, atol=1e-15)
    np.testing.assert_allclose(d.Phi, scipy.linalg.expm(A747 * h), rtol=1e-13, atol=1e-16)
    assert d.Gamma1 is None and d.method == "zoh" and d.dt == h


@pytest.mark.parametrize(("A", "B"), [(A_SINGULAR, B_SINGULAR), (np.zeros((2, 2)), np.eye(2))])
@pytest.mark.parametrize("h", [0.01, 0.7, 5.0])
def test_singular_a_against_quadrature(A: np.ndarray, B: np.ndarray, h: float) -> None:
    d = aerocontrol.discretize(A, B, h, method="foh")
    gamma0, gamma1 = _quadrature(A, B, h)
    scale = np.abs(gamma0).max()
    np.testing.assert_allclose(d.Gamma0, gamma0, rtol=1e-11, atol=1e-13 * scale)
    np.testing.assert_allclose(d.Gamma1, gamma1, rtol=1e-11, atol=1e-13 * scale)


def test_foh_matches_scipy_cont2discrete() -> None:
    # scipy's FOH system uses the state ξ = x - Γ1 η, so that ξ[k+1] = Φ ξ[k] + Bd η[k] with
    # Bd = Γ0 - Γ1 + Φ Γ1, and y = C ξ + (D + C Γ1) η.
    rng = np.random.default_rng(2)
    A, B = rng.standard_normal((6, 6)), rng.standard_normal((6, 2))
    C, D = np.eye(6), np.zeros((6, 2))
    h = 0.3
    d = aerocontrol.discretize(A, B, h, method="foh")
    Ad, Bd, _, Dd, _ = scipy.signal.cont2discrete((A, B, C, D), h, method="foh")
    assert d.Gamma1 is not None
    np.testing.assert_allclose(d.Phi, Ad, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(d.Gamma0 - d.Gamma1 + d.Phi @ d.Gamma1, Bd, rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(d.Gamma1, Dd, rtol=1e-11, atol=1e-13)
    Ad, Bd, _, _, _ = scipy.signal.cont2discrete((A, B, C, D), h, method="zoh")
    zoh = aerocontrol.discretize(A, B, h)
    np.testing.assert_allclose(zoh.Gamma0, Bd, rtol=1e-11, atol=1e-13)


def test_one_dimensional_b_is_one_input() -> None:
    d = aerocontrol.discretize(A747, B747[:, 0], 0.1)
    assert d.Gamma0.shape == (4, 1)
    np.testing.assert_array_equal(d.Gamma0, aerocontrol.discretize(A747, B747, 0.1).Gamma0)


def test_step_response_steady_state_of_the_chapter() -> None:
    # A long step converges to -A^-1 B η0 (6.45); the chapter prints (6.51) for one degree.
    # The print truncates (0.045965 appears as 0.0459); seed-values.md gives the computed
    # [0.045965, -0.018563, 0, -0.015954]. After 8000 s the phugoid (σ = -0.00176) has decayed
    # to e^-14 of its amplitude.
    steady = aerocontrol.discretize(A747, B747, 8000.0).Gamma0[:, 0] * np.pi / 180
    np.testing.assert_allclose(steady, [0.045965, -0.018563, 0.0, -0.015954], atol=1e-6)
    np.testing.assert_allclose(steady, [0.0459, -0.0186, 0.0, -0.0160], atol=1e-4)
    exact = -np.linalg.solve(A747, B747[:, 0]) * np.pi / 180
    np.testing.assert_allclose(steady, exact, rtol=2e-6, atol=1e-8)


@pytest.mark.parametrize("dt", [0.0, -0.1, np.nan, np.inf])
def test_bad_step(dt: float) -> None:
    with pytest.raises(InvalidArgumentError, match="dt must be positive and finite"):
        aerocontrol.discretize(A747, B747, dt)


def test_an_extreme_step_is_quoted_in_exponent_form() -> None:
    """A dt of 1e300 that makes A dt overflow is refused with the value as 1e300, not as the
    301-digit decimal expansion the core's messages used to print."""
    with pytest.raises(InvalidArgumentError) as raised:
        aerocontrol.c2d(([[1e10]], [[1.0]]), 1e300)
    assert str(raised.value) == "dt must be small enough that A dt is finite, got 1e300"


def test_bad_arguments_are_named() -> None:
    with pytest.raises(ShapeError, match=r"B must have as many rows as A \(4\), got 3"):
        aerocontrol.discretize(A747, np.ones((3, 1)), 0.1)
    with pytest.raises(ShapeError, match="A must be square"):
        aerocontrol.discretize(np.ones((3, 4)), np.ones((3, 1)), 0.1)
    with pytest.raises(ShapeError, match="B must be a 2-D matrix"):
        aerocontrol.discretize(A747, np.ones((4, 1, 1)), 0.1)
    bad_b = B747.copy()
    bad_b[2, 0] = np.nan
    with pytest.raises(NonFiniteError, match=r"B\[2, 0\]"):
        aerocontrol.discretize(A747, bad_b, 0.1)
    with pytest.raises(NotRealError, match="B must be real"):
        aerocontrol.discretize(A747, B747 * 1j, 0.1)
    with pytest.raises(InvalidArgumentError, match="method must be one of 'zoh', 'foh'"):
        aerocontrol.discretize(A747, B747, 0.1, method="tustin")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="dt must be a scalar"):
        aerocontrol.discretize(A747, B747, [0.1, 0.2])  # type: ignore[arg-type]
