"""Discrete-time models (issue 24): StateSpace(dt=...), c2d and d2c, and the responses,
frequency responses and modes of discrete models.

Oracles: scipy.signal.cont2discrete (zoh, foh, bilinear, euler, backward_diff, gbt with alpha),
python-control's sample_system (tustin with prewarp; matched pole-zero, through its transfer
function), scipy.linalg.logm (the zero-order hold undone), scipy.signal.dstep, dimpulse and
dlsim and python-control's step_response, impulse_response, initial_response and
forced_response on discrete models, python-control's frequency_response and damp and
scipy.signal.dfreqresp, and closed forms (a first-order lag, the matched form of an
integrator). Tolerances are relative to the largest entry of the reference unless said
otherwise.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import control
import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

import aerocontrol
from aerocontrol import (
    InvalidArgumentError,
    NoContinuousEquivalentError,
    NotRealError,
    ShapeError,
    SingularMatrixError,
    StateSpace,
)

A_LON, B_LON = aerocontrol.chapter.boeing747_longitudinal()
A_LAT, B_LAT = aerocontrol.chapter.boeing747_lateral()
A_SINGULAR, B_SINGULAR = aerocontrol.chapter.state_feedback_example()  # (6.95), λ = 0


def _relative(x: np.ndarray, reference: np.ndarray) -> float:
    scale = float(np.abs(reference).max()) if np.size(reference) else 0.0
    return float(np.abs(x - reference).max() / scale) if scale else float(np.abs(x).max())


def _random_stable(n: int, m: int, p: int, seed: int) -> StateSpace:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A -= (np.abs(np.linalg.eigvals(A).real).max() + 0.1) * np.eye(n)
    return StateSpace(
        A, rng.standard_normal((n, m)), rng.standard_normal((p, n)), rng.standard_normal((p, m))
    )


def _continuous_models() -> dict[str, StateSpace]:
    """The models the oracles are run on: the chapter's 747 (one and two inputs, full state and
    chosen outputs), the singular plant of (6.95), and random stable models."""
    return {
        "747 longitudinal": StateSpace(A_LON, B_LON),
        "747 lateral": StateSpace(
            A_LAT, B_LAT, np.array([[1.0, 0, 0, 0], [0, 0, 1.0, 0]]), np.zeros((2, 2))
        ),
        "(6.95) singular": StateSpace(A_SINGULAR, B_SINGULAR, [[1.0, 0.0]], [[0.5]]),
        "random n=6": _random_stable(6, 2, 3, 1),
        "random n=9": _random_stable(9, 3, 2, 2),
    }


MODELS = _continuous_models()


def _matrices(sys: StateSpace) -> tuple[np.ndarray, ...]:
    return sys.A, sys.B, sys.C, sys.D


# ----- StateSpace(dt) -------------------------------------------------------------------------


def test_dt_sets_a_discrete_model() -> None:
    continuous = StateSpace(A_LON, B_LON)
    assert continuous.dt is None and not continuous.is_discrete
    for unset in (0, 0.0, False):
        model = StateSpace(A_LON, B_LON, dt=unset)
        assert model.dt == 0.0 and not model.is_discrete
        assert repr(model) == repr(continuous)
    sampled = StateSpace(A_LON, B_LON, dt=0.05)
    assert sampled.dt == 0.05 and sampled.is_discrete
    assert repr(sampled).endswith("inputs=['u0'], dt=0.05)")
    assert isinstance(np.float32(0.5), np.floating)
    assert StateSpace([[0.5]], [[1.0]], dt=np.float32(0.5)).dt == 0.5  # type: ignore[arg-type]


@pytest.mark.parametrize("dt", [-0.1, float("nan"), float("inf"), -float("inf")])
def test_bad_sampling_periods_are_refused_by_name(dt: float) -> None:
    with pytest.raises(InvalidArgumentError, match=r"^dt must be None or 0"):
        StateSpace(A_LON, B_LON, dt=dt)


def test_unspecified_period_and_non_numbers_are_refused() -> None:
    with pytest.raises(InvalidArgumentError, match=r"dt=True .* unspecified sampling period"):
        StateSpace(A_LON, B_LON, dt=True)
    with pytest.raises(NotRealError, match="dt must be"):
        StateSpace(A_LON, B_LON, dt=0.1j)  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="dt must be a scalar"):
        StateSpace(A_LON, B_LON, dt=[0.1, 0.2])  # type: ignore[arg-type]


def test_python_control_models_keep_their_sampling_period() -> None:
    C, D = np.eye(4), np.zeros((4, 1))
    sampled = aerocontrol.as_state_space(control.ss(A_LON, B_LON, C, D, 0.02))
    assert sampled.dt == 0.02 and sampled.is_discrete
    assert sampled.state_names == ("x[0]", "x[1]", "x[2]", "x[3]")
    assert aerocontrol.as_state_space(control.ss(A_LON, B_LON, C, D)).dt == 0.0
    with pytest.raises(InvalidArgumentError, match=r"sys\.dt=True"):
        aerocontrol.as_state_space(control.ss(A_LON, B_LON, C, D, True))
    assert aerocontrol.as_state_space((A_LON, B_LON)).dt is None
    unset = control.ss(A_LON, B_LON, C, D, None)
    assert aerocontrol.as_state_space(unset).dt is None


def test_an_unsaid_time_base_is_continuous_but_not_refused_by_dlqr() -> None:
    # As python-control: dt=None leaves the time base open, dt=0 says continuous.
    A, B = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    K, _, _ = aerocontrol.dlqr(A, B, np.eye(2), 1.0)
    unsaid = StateSpace(A, B)
    assert np.array_equal(aerocontrol.dlqr(unsaid, np.eye(2), 1.0)[0], K)
    with pytest.raises(InvalidArgumentError, match="discrete-time"):
        aerocontrol.dlqr(StateSpace(A, B, dt=0), np.eye(2), 1.0)
    assert np.array_equal(aerocontrol.dlqr(StateSpace(A, B, dt=0.1), np.eye(2), 1.0)[0], K)
    t = np.linspace(0.0, 1.0, 11)
    assert np.array_equal(
        aerocontrol.step_response(unsaid, T=t).y,
        aerocontrol.step_response(StateSpace(A, B, dt=0), T=t).y,
    )
    # d2c marks its result continuous.
    assert aerocontrol.d2c(aerocontrol.c2d(StateSpace(A_LON, B_LON), 0.1)).dt == 0.0


# ----- c2d against scipy and python-control ---------------------------------------------------


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("method", ["zoh", "foh", "bilinear", "euler", "backward_diff"])
@pytest.mark.parametrize("dt", [0.01, 0.2])
def test_c2d_equals_scipy_cont2discrete(name: str, method: str, dt: float) -> None:
    sys = MODELS[name]
    ours = aerocontrol.c2d(sys, dt, method)
    expected = scipy.signal.cont2discrete(_matrices(sys), dt, method=method)
    assert ours.dt == dt and ours.is_discrete
    for got, reference in zip(_matrices(ours), expected[:4], strict=True):
        assert _relative(got, reference) < 1e-12, (name, method)
    assert ours.state_names == sys.state_names and ours.input_names == sys.input_names


@pytest.mark.parametrize("alpha", [0.0, 0.25, 0.5, 0.8, 1.0])
def test_c2d_gbt_equals_scipy(alpha: float) -> None:
    for name, sys in MODELS.items():
        ours = aerocontrol.c2d(sys, 0.1, "gbt", alpha=alpha)
        expected = scipy.signal.cont2discrete(_matrices(sys), 0.1, method="gbt", alpha=alpha)
        for got, reference in zip(_matrices(ours), expected[:4], strict=True):
            assert _relative(got, reference) < 1e-12, (name, alpha)


@pytest.mark.parametrize("prewarp", [None, 0.5, 5.0, 60.0])
def test_tustin_with_prewarp_equals_python_control(prewarp: float | None) -> None:
    for name, sys in MODELS.items():
        ours = aerocontrol.c2d(sys, 0.05, "tustin", prewarp=prewarp)
        theirs = control.sample_system(
            control.ss(*_matrices(sys)), 0.05, "tustin", prewarp_frequency=prewarp
        )
        assert theirs.dt == 0.05
        for got, reference in zip(
            _matrices(ours), (theirs.A, theirs.B, theirs.C, theirs.D), strict=True
        ):
            assert _relative(got, reference) < 1e-12, (name, prewarp)


def test_prewarping_makes_the_responses_agree_at_its_frequency() -> None:
    sys = MODELS["747 lateral"]
    for omega in (0.3, 1.0, 20.0):
        warped = aerocontrol.c2d(sys, 0.1, "tustin", prewarp=omega)
        discrete = aerocontrol.frequency_response(warped, [omega]).response
        continuous = aerocontrol.frequency_response(sys, [omega]).response
        assert _relative(discrete, continuous) < 1e-12


def test_first_order_lag_in_closed_form() -> None:
    # G = a / (s + a): ZOH Ad = e^{-a h}, Bd = 1 - e^{-a h}; Tustin Ad = (2 - a h)/(2 + a h).
    a, h = 2.0, 0.1
    lag = StateSpace([[-a]], [[a]], [[1.0]], [[0.0]])
    zoh = aerocontrol.c2d(lag, h)
    assert abs(zoh.A[0, 0] - np.exp(-a * h)) < 1e-16
    assert abs(zoh.B[0, 0] + np.expm1(-a * h)) < 1e-16
    tustin = aerocontrol.c2d(lag, h, "tustin")
    assert abs(tustin.A[0, 0] - (2 - a * h) / (2 + a * h)) < 1e-16
    assert abs(aerocontrol.dc_gain(tustin)[0, 0] - 1.0) < 1e-14


# ----- matched pole-zero ----------------------------------------------------------------------


def _siso(C: list[float], D: float = 0.0) -> StateSpace:
    return StateSpace(A_LON, B_LON, [C], [[D]])


SISO = {
    "theta / elevator": _siso([0, 0, 0, 1.0]),
    "alpha / elevator, D = 0.3": _siso([0, 1.0, 0, 0], 0.3),
    "u / elevator (zero at s = +26)": _siso([1.0, 0, 0, 0]),
    "q / elevator (zero at s = 0)": _siso([0, 0, 1.0, 0]),
}


@pytest.mark.parametrize("name", [name for name in SISO if "s = 0" not in name])
@pytest.mark.parametrize("dt", [0.5, 1.0, 2.0])
def test_matched_equals_python_control(name: str, dt: float) -> None:
    # python-control maps the zeros and poles of its transfer function and matches the DC gain;
    # compared as frequency responses (the realizations differ), at steps where the transfer
    # function's coefficients are well conditioned (at dt = 0.02 its poles crowd at z = 1 and
    # its response is off by 2e-7). Without q / elevator, whose zero at s = 0 makes
    # python-control's gain 0/0.
    sys = SISO[name]
    ours = aerocontrol.c2d(sys, dt, "matched")
    theirs = control.sample_system(control.ss2tf(control.ss(*_matrices(sys))), dt, "matched")
    omega = np.array([0.0, 1e-3, 0.05, 0.5, 1.0, 0.99 * np.pi / dt])
    response = aerocontrol.frequency_response(ours, omega).response[:, 0, 0]
    expected = theirs(np.exp(1j * omega * dt))
    assert np.max(np.abs(response - expected) / np.abs(expected)) < 1e-11
    assert ours.dt == dt and ours.n_states == 4


@pytest.mark.parametrize("name", list(SISO))
@pytest.mark.parametrize("dt", [0.05, 1.0])
def test_matched_equals_its_definition(name: str, dt: float) -> None:
    # K prod(z - e^{z_i dt}) / prod(z - e^{p_i dt}) with the zeros of python-control (slycot's
    # ab08nd) and the eigenvalues of A, K matching the low-frequency asymptote: the DC gain, or
    # for the zero at s = 0, g prod'(-z_i) / prod(-p_i) s against K prod'(1 - e^{z_i dt}) /
    # prod(1 - e^{p_i dt}) (z - 1) with z - 1 ≈ s dt.
    sys = SISO[name]
    zeros = control.zeros(control.ss(*_matrices(sys)))
    poles = np.linalg.eigvals(A_LON)
    at_origin = np.abs(zeros) < 1e-10
    leading = float(sys.D[0, 0]) or float(control.ss2tf(control.ss(*_matrices(sys))).num[0][0][0])
    continuous = leading * np.prod(-zeros[~at_origin]) / np.prod(-poles)
    discrete = np.prod(1 - np.exp(zeros[~at_origin] * dt)) / np.prod(1 - np.exp(poles * dt))
    gain = (continuous / discrete).real / dt ** int(at_origin.sum())
    omega = np.array([0.01, 0.3, 2.0])
    z = np.exp(1j * omega * dt)
    expected = np.array(
        [gain * np.prod(w - np.exp(zeros * dt)) / np.prod(w - np.exp(poles * dt)) for w in z]
    )
    response = aerocontrol.frequency_response(aerocontrol.c2d(sys, dt, "matched"), omega)
    # The frequency response of any realization with poles near z = 1 is conditioned like
    # 1 / |z - e^{p dt}| (3e3 at dt = 0.05): the tolerance allows it.
    tolerance = 1e-12 if dt == 1.0 else 1e-10
    assert np.max(np.abs(response.response[:, 0, 0] - expected) / np.abs(expected)) < tolerance


@pytest.mark.parametrize("name", list(SISO))
def test_matched_poles_are_the_exponentials_at_small_steps(name: str) -> None:
    # At dt = 0.02 the poles crowd at z = 1, where a polynomial's coefficients lose digits
    # (python-control's differ from e^{p dt} by 3e-9): the sections hold them exactly.
    sys, dt = SISO[name], 0.02
    ours = aerocontrol.c2d(sys, dt, "matched")
    poles = np.sort_complex(aerocontrol.schur(ours.A)[2])
    expected = np.sort_complex(np.exp(np.linalg.eigvals(A_LON) * dt))
    assert np.max(np.abs(poles - expected)) < 1e-14
    # The gain at low frequency equals the continuous DC gain (to the conditioning of the
    # solve at z = 1, 1/|1 - z_phugoid| ~ 1e4).
    assert _relative(aerocontrol.dc_gain(ours), aerocontrol.dc_gain(sys)) < 1e-10


def test_matched_integrator_matches_the_low_frequency_asymptote() -> None:
    # G = 32 / (s (s + 3)) (the (6.95) plant's x1): poles 1 and e^{-3h}, no finite zero; near
    # z = 1, G_d ≈ K / ((z - 1)(1 - e^{-3h})) with z - 1 ≈ s h, so K = 32 h (1 - e^{-3h}) / 3.
    # python-control divides 0 by 0 here (its gain is NaN).
    h = 0.1
    ours = aerocontrol.c2d(StateSpace(A_SINGULAR, B_SINGULAR, [[1.0, 0.0]], [[0.0]]), h, "matched")
    z = np.exp(1j * np.array([0.3, 2.0]) * h)
    gain = 32 * h * -np.expm1(-3 * h) / 3
    expected = gain / ((z - 1) * (z - np.exp(-3 * h)))
    response = aerocontrol.frequency_response(ours, [0.3, 2.0]).response[:, 0, 0]
    assert np.max(np.abs(response - expected) / np.abs(expected)) < 1e-13


def test_matched_refuses_several_inputs_or_outputs() -> None:
    with pytest.raises(ShapeError, match=r"single-input, single-output.* 2 input"):
        aerocontrol.c2d(MODELS["747 lateral"], 0.1, "matched")
    with pytest.raises(ShapeError, match="4 output"):
        aerocontrol.c2d(MODELS["747 longitudinal"], 0.1, "matched")


# ----- d2c ------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("dt", [0.01, 0.3, 1.5])
def test_d2c_undoes_the_zero_order_hold(name: str, dt: float) -> None:
    # dt below π / max|Im λ| for every model (1.7 for the random n = 9): beyond it the samples
    # alias and the principal logarithm is another continuous model with the same samples.
    sys = MODELS[name]
    discrete = aerocontrol.c2d(sys, dt)
    back = aerocontrol.d2c(discrete)
    assert not back.is_discrete and back.state_names == sys.state_names
    for got, reference in zip(_matrices(back), _matrices(sys), strict=True):
        assert _relative(got, reference) < 1e-12, name
    # And the other way round: c2d(d2c(sysd)) = sysd.
    again = aerocontrol.c2d(back, dt)
    for got, reference in zip(_matrices(again), _matrices(discrete), strict=True):
        assert _relative(got, reference) < 1e-12, name


def test_d2c_equals_scipy_logm_of_the_block_matrix() -> None:
    for name, sys in MODELS.items():
        discrete = aerocontrol.c2d(sys, 0.25)
        n, m = sys.n_states, sys.n_inputs
        block = np.block([[discrete.A, discrete.B], [np.zeros((m, n)), np.eye(m)]])
        logarithm = np.real(scipy.linalg.logm(block)) / 0.25
        back = aerocontrol.d2c(discrete)
        assert _relative(back.A, logarithm[:n, :n]) < 1e-12, name
        assert _relative(back.B, logarithm[:n, n:]) < 1e-12, name


@pytest.mark.parametrize("scale", [1e3, 1e6, 1e8])
def test_d2c_zoh_of_states_scaled_far_apart(scale: float) -> None:
    """States scaled by 1/scale, 1 and scale (A = T A0 T^-1, B = T B0): the samples Ad, Bd
    are the blocks of e^{[[A, B], [0, 0]] dt} in 50-digit arithmetic, rounded, and d2c gives
    back every entry of A and B to 1e-12 relatively (the logarithm of the unbalanced block
    matrix had entries of A wrong at 6e-10 for 1e3, and failed its own check beyond)."""
    mpmath = pytest.importorskip("mpmath")
    rng = np.random.default_rng(31)
    A0, B0 = rng.standard_normal((3, 3)) - np.eye(3), rng.standard_normal((3, 1))
    T = np.diag([1.0 / scale, 1.0, scale])
    A, B = T @ A0 @ np.linalg.inv(T), T @ B0
    dt = 0.1
    with mpmath.workdps(50):
        block = mpmath.matrix(np.block([[A, B], [np.zeros((1, 4))]]).tolist()) * dt
        exact = mpmath.expm(block)
        samples = np.array([[float(exact[i, j]) for j in range(4)] for i in range(4)])
    discrete = aerocontrol.StateSpace(samples[:3, :3], samples[:3, 3:], np.ones((1, 3)), dt=dt)
    back = aerocontrol.d2c(discrete)
    np.testing.assert_allclose(back.A, A, rtol=1e-12, atol=0)
    np.testing.assert_allclose(back.B, B, rtol=1e-12, atol=0)


@pytest.mark.parametrize("scale", [1e3, 1e6, 1e8])
def test_bilinear_of_states_scaled_far_apart(scale: float) -> None:
    """Tustin's map of states scaled by 1/scale, 1 and scale, against the formulas of c2d's
    docstring in 50-digit arithmetic: every entry of Ad, Bd, Cd to 1e-13 relatively, and
    d2c's inverse of the exact samples gives A, B, C back to 1e-13, without a warning (the
    solve with I - dt A / 2 refused the model scaled by 1e6 as having an eigenvalue at
    2 / dt = 20, and d2c warned of an eigenvalue 0.86 "near -1")."""
    mpmath = pytest.importorskip("mpmath")
    rng = np.random.default_rng(31)
    A0, B0, C0 = (
        rng.standard_normal((3, 3)) - np.eye(3),
        rng.standard_normal((3, 1)),
        rng.standard_normal((1, 3)),
    )
    T = np.diag([1.0 / scale, 1.0, scale])
    A, B, C = T @ A0 @ np.linalg.inv(T), T @ B0, C0 @ np.linalg.inv(T)
    dt = 0.1

    def doubles(M: Any) -> np.ndarray:
        return np.array([[float(M[i, j]) for j in range(M.cols)] for i in range(M.rows)])

    with mpmath.workdps(50):
        Am, Bm, Cm = (mpmath.matrix(M.tolist()) for M in (A, B, C))
        inverse = (mpmath.eye(3) - Am * dt / 2) ** -1
        Ad = doubles(inverse * (mpmath.eye(3) + Am * dt / 2))
        Bd, Cd = doubles(inverse * Bm * dt), doubles(Cm * inverse)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sampled = aerocontrol.c2d((A, B, C, np.zeros((1, 1))), dt, "tustin")
        back = aerocontrol.d2c(aerocontrol.StateSpace(Ad, Bd, Cd, sampled.D, dt=dt), "tustin")
    for got, exact in ((sampled.A, Ad), (sampled.B, Bd), (sampled.C, Cd)):
        np.testing.assert_allclose(got, exact, rtol=1e-13, atol=0)
    for got, exact in ((back.A, A), (back.B, B), (back.C, C)):
        np.testing.assert_allclose(got, exact, rtol=1e-13, atol=0)


@pytest.mark.parametrize("method", ["tustin", "euler", "backward_diff"])
@pytest.mark.parametrize("prewarp", [None, 2.0])
def test_d2c_undoes_the_bilinear_transformations(method: str, prewarp: float | None) -> None:
    if prewarp is not None and method != "tustin":
        return
    for name, sys in MODELS.items():
        discrete = aerocontrol.c2d(sys, 0.1, method, prewarp=prewarp)
        back = aerocontrol.d2c(discrete, method, prewarp=prewarp)
        for got, reference in zip(_matrices(back), _matrices(sys), strict=True):
            assert _relative(got, reference) < 1e-12, (name, method)
    for alpha in (0.2, 0.7):
        discrete = aerocontrol.c2d(MODELS["random n=6"], 0.1, "gbt", alpha=alpha)
        back = aerocontrol.d2c(discrete, "gbt", alpha=alpha)
        assert _relative(back.A, MODELS["random n=6"].A) < 1e-12


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(1, 8),
    seed=st.integers(0, 2**32 - 1),
    dt=st.floats(1e-3, 3.0),
    method=st.sampled_from(["zoh", "tustin"]),
)
def test_round_trips_are_the_identity(n: int, seed: int, dt: float, method: str) -> None:
    # Eigenvalues of A dt kept within |Im| < 2.5 so that e^{A dt} has a principal logarithm
    # equal to A dt (the zero-order hold aliases frequencies beyond the Nyquist frequency).
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    radius = float(np.abs(np.linalg.eigvals(A)).max())
    A *= min(1.0, 2.5 / (radius * dt))
    sys = StateSpace(A, rng.standard_normal((n, 2)), rng.standard_normal((2, n)), np.zeros((2, 2)))
    back = aerocontrol.d2c(aerocontrol.c2d(sys, dt, method), method)
    for got, reference in zip(_matrices(back), _matrices(sys), strict=True):
        assert _relative(got, reference) < 1e-10


def test_d2c_refuses_models_without_a_continuous_equivalent() -> None:
    B = np.array([[1.0], [1.0]])
    negative = StateSpace(np.diag([-0.5, 0.9]), B, dt=0.1)
    with pytest.raises(NoContinuousEquivalentError, match=r"eigenvalue -0\.5 on the negative"):
        aerocontrol.d2c(negative)
    delay = StateSpace([[0.0, 1.0], [0.0, 0.0]], B, dt=0.1)  # a two-step delay: z = 0
    with pytest.raises(NoContinuousEquivalentError, match=r"eigenvalue 0 .* z = 0"):
        aerocontrol.d2c(delay)
    at_minus_one = StateSpace(np.diag([-1.0, 0.5]), B, dt=0.1)
    with pytest.raises(NoContinuousEquivalentError, match="image of s = infinity"):
        aerocontrol.d2c(at_minus_one, "tustin")
    assert issubclass(NoContinuousEquivalentError, np.linalg.LinAlgError)
    # A negative eigenvalue is fine for Tustin's inverse (only -1 is not).
    assert not aerocontrol.d2c(negative, "tustin").is_discrete


def _rotation(radius: float, angle: float) -> np.ndarray:
    """radius times the rotation by ``angle``: the discrete pair radius e^{±j angle}."""
    c, s = np.cos(angle), np.sin(angle)
    return radius * np.array([[c, -s], [s, c]])


@pytest.mark.parametrize("a", [-0.5, -1.0, -3.0, -1e-300, 0.0])
def test_d2c_zoh_refuses_a_scalar_pole_on_the_closed_negative_axis_naming_sys(a: float) -> None:
    # Closed form: ln(a) = ln|a| + jπ for a < 0 and ln(0) = -∞: no real logarithm, as scipy's
    # logm (the oracle) confirms with its imaginary part π.
    if -1e3 < a < -1e-3:  # (scipy's logm warns of its own accuracy at a = -1e-300)
        assert scipy.linalg.logm(np.array([[a]]))[0, 0].imag == pytest.approx(np.pi, rel=1e-15)
    with pytest.raises(InvalidArgumentError, match=r"^sys\.A has the eigenvalue") as error:
        aerocontrol.d2c(StateSpace([[a]], [[1.0]], [[1.0]], [[0.0]], dt=0.1))
    assert isinstance(error.value, NoContinuousEquivalentError)
    assert isinstance(error.value, np.linalg.LinAlgError)
    assert error.value.argument == "sys"
    assert error.value.eigenvalues == [complex(a, 0.0)]


def test_d2c_zoh_refuses_negative_real_pairs_and_a_delay_in_a_larger_model() -> None:
    # Two distinct negative eigenvalues (no real logarithm at all, Culver 1966), a repeated one
    # (a real logarithm ln 0.5 I + π J exists, but no principal one: an oscillation at exactly
    # the Nyquist frequency, whose sign is undecidable), a one-step delay inside a stable model.
    B = np.eye(2)
    for A, eigenvalue in (
        (np.diag([-0.5, -0.3]), -0.5),
        (-0.5 * np.eye(2), -0.5),
        (np.array([[0.9, 1.0], [0.0, 0.0]]), 0.0),
    ):
        with pytest.raises(NoContinuousEquivalentError) as error:
            aerocontrol.d2c(StateSpace(A, B, dt=0.02))
        assert error.value.argument == "sys"
        assert error.value.eigenvalues is not None
        assert error.value.eigenvalues[0] == pytest.approx(eigenvalue, abs=1e-15)


@pytest.mark.parametrize("fraction", [0.5, 0.85, 0.89])
def test_d2c_zoh_of_a_rotation_below_the_warning_angle_is_the_closed_form(fraction: float) -> None:
    # Closed form: the real logarithm of r R(θ) is ln r I + θ J, J = [[0, -1], [1, 0]]; scipy's
    # logm is the second oracle. No warning (the suite makes aerocontrol's warnings errors).
    dt, radius, angle = 0.1, 0.9, fraction * np.pi
    back = aerocontrol.d2c(StateSpace(_rotation(radius, angle), np.eye(2), dt=dt))
    closed_form = (np.log(radius) * np.eye(2) + angle * np.array([[0.0, -1.0], [1.0, 0.0]])) / dt
    assert _relative(back.A, closed_form) < 1e-14
    assert _relative(back.A, np.real(scipy.linalg.logm(_rotation(radius, angle))) / dt) < 1e-13


@pytest.mark.parametrize("gap", [0.05 * np.pi, 1e-3, 1e-8])
def test_d2c_zoh_warns_near_the_nyquist_angle_and_still_returns_the_principal_logarithm(
    gap: float,
) -> None:
    # A pole at the angle π - gap: the continuous frequency is (π - gap)/dt, the alias
    # (π + gap)/dt. The result is still the closed form ln r I + θ J, to the logarithm's
    # sensitivity θ / sin θ (about π / gap) times the rounding of A.
    dt, radius, angle = 0.02, 0.95, np.pi - gap
    sensitivity = angle / np.sin(angle)
    with pytest.warns(aerocontrol.IllConditionedWarning, match=r"near the Nyquist") as record:
        back = aerocontrol.d2c(StateSpace(_rotation(radius, angle), np.eye(2), dt=dt))
    message = str(record[0].message)
    assert f"at the angle {angle / np.pi:.4f} pi" in message
    assert f"{(np.pi + gap) / dt:.6g} rad/s (aliasing)" in message
    assert f"theta/sin(theta) is {sensitivity:.3g}" in message
    closed_form = (np.log(radius) * np.eye(2) + angle * np.array([[0.0, -1.0], [1.0, 0.0]])) / dt
    assert _relative(back.A, closed_form) < 10 * sensitivity * np.finfo(float).eps


def test_d2c_zoh_cannot_tell_a_mode_above_nyquist_from_its_alias() -> None:
    # Round trips: a mode at 0.95 Nyquist comes back (with the warning); one at 1.05 Nyquist
    # comes back as its alias: e^{j 1.05 π} = e^{-j 0.95 π}, the mode at 0.95 Nyquist turning
    # the other way (A transposed), whose samples are the same (c2d of both agree).
    dt = 0.1
    nyquist = np.pi / dt
    below = StateSpace([[-0.3, -0.95 * nyquist], [0.95 * nyquist, -0.3]], [[1.0], [0.0]])
    above = StateSpace([[-0.3, -1.05 * nyquist], [1.05 * nyquist, -0.3]], [[1.0], [0.0]])
    with pytest.warns(aerocontrol.IllConditionedWarning, match=r"0\.9500 pi"):
        back = aerocontrol.d2c(aerocontrol.c2d(below, dt))
    assert _relative(back.A, below.A) < 1e-12
    sampled = aerocontrol.c2d(above, dt)
    with pytest.warns(aerocontrol.IllConditionedWarning, match=r"0\.9500 pi"):
        alias = aerocontrol.d2c(sampled)
    assert _relative(alias.A, below.A.T) < 1e-12  # not above.A: the samples cannot tell
    assert _relative(aerocontrol.c2d(alias, dt).A, sampled.A) < 1e-12


def test_d2c_bilinear_refuses_the_image_of_infinity_and_warns_near_it() -> None:
    B = np.array([[1.0], [1.0]])
    # Tustin's: z = -1 is the image of s = ∞; the generalized weights' image is -(1 - α)/α.
    for method, alpha, image in (("tustin", None, -1.0), ("gbt", 0.25, -3.0)):
        with pytest.raises(
            InvalidArgumentError, match=r"^sys\.A: .*image of s = infinity"
        ) as error:
            aerocontrol.d2c(StateSpace(np.diag([image, 0.5]), B, dt=0.1), method, alpha=alpha)
        assert isinstance(error.value, NoContinuousEquivalentError)
        assert error.value.argument == "sys"
        assert error.value.eigenvalues == [complex(image)]
    # Near -1: Tustin's inverse s = (2/dt)(z - 1)/(z + 1) has a pole near infinity. The closed
    # form is exact in floating point (z + 1 is exact for z in [-2, -1/2], Sterbenz).
    dt = 0.1
    for gap in (1e-9, 1e-12):
        z = -1.0 + gap
        with pytest.warns(aerocontrol.IllConditionedWarning, match=r"reciprocal condition"):
            back = aerocontrol.d2c(StateSpace([[z]], [[1.0]], [[1.0]], [[0.0]], dt=dt), "tustin")
        exact = (2.0 / dt) * (z - 1.0) / (z + 1.0)
        assert back.A[0, 0] == pytest.approx(exact, rel=1e4 * np.finfo(float).eps / gap)
    # Far from it: no warning, and the round trip holds.
    sys = StateSpace([[-0.9, 0.2], [0.0, 0.3]], B, dt=dt)
    again = aerocontrol.c2d(aerocontrol.d2c(sys, "tustin"), dt, "tustin")
    assert _relative(again.A, sys.A) < 1e-13


def test_c2d_and_d2c_arguments_are_checked_by_name() -> None:
    sys, discrete = MODELS["747 longitudinal"], aerocontrol.c2d(MODELS["747 longitudinal"], 0.1)
    with pytest.raises(InvalidArgumentError, match="sys must be a continuous model"):
        aerocontrol.c2d(discrete, 0.1)
    with pytest.raises(InvalidArgumentError, match="sys must be a discrete model"):
        aerocontrol.d2c(sys)
    for dt in (0.0, -1.0, float("nan")):
        with pytest.raises(InvalidArgumentError, match="dt must be"):
            aerocontrol.c2d(sys, dt)
    with pytest.raises(InvalidArgumentError, match="method must be one of 'zoh', 'foh'"):
        aerocontrol.c2d(sys, 0.1, "impulse")
    with pytest.raises(InvalidArgumentError, match="prewarp applies to Tustin"):
        aerocontrol.c2d(sys, 0.1, "euler", prewarp=1.0)
    with pytest.raises(InvalidArgumentError, match="prewarp and alpha apply"):
        aerocontrol.c2d(sys, 0.1, "zoh", prewarp=1.0)
    with pytest.raises(InvalidArgumentError, match=r"Nyquist frequency pi/dt = 31\.4159"):
        aerocontrol.c2d(sys, 0.1, "tustin", prewarp=40.0)
    with pytest.raises(InvalidArgumentError, match="needs the weight alpha"):
        aerocontrol.c2d(sys, 0.1, "gbt")
    with pytest.raises(InvalidArgumentError, match="alpha must be between 0 and 1"):
        aerocontrol.c2d(sys, 0.1, "gbt", alpha=1.5)
    with pytest.raises(InvalidArgumentError, match="alpha is the weight of method='gbt'"):
        aerocontrol.c2d(sys, 0.1, "tustin", alpha=0.5)
    with pytest.raises(InvalidArgumentError, match="d2c has no inverse of method='foh'"):
        aerocontrol.d2c(discrete, "foh")
    with pytest.raises(InvalidArgumentError, match=r"method must be one of 'zoh', 'foh'.*c2d"):
        aerocontrol.discretize(A_LON, B_LON, 0.1, "tustin")  # type: ignore[arg-type]
    # Tustin's map sends s = 2/dt to infinity.
    with pytest.raises(InvalidArgumentError, match="sends to infinity") as error:
        aerocontrol.c2d(StateSpace([[20.0]], [[1.0]]), 0.1, "tustin")
    assert error.value.argument == "dt"


# ----- time responses -------------------------------------------------------------------------

DT = 0.05
DISCRETE = {
    "747 longitudinal zoh": aerocontrol.c2d(
        StateSpace(A_LON, B_LON, np.eye(4)[[1, 3]], np.zeros((2, 1))), DT
    ),
    "747 lateral tustin": aerocontrol.c2d(MODELS["747 lateral"], DT, "tustin"),
    "random n=6 foh": aerocontrol.c2d(MODELS["random n=6"], DT, "foh"),
}


@pytest.mark.parametrize("name", list(DISCRETE))
def test_step_and_impulse_equal_scipy_dstep_and_dimpulse(name: str) -> None:
    sys, samples = DISCRETE[name], 400
    t = np.arange(samples) * DT
    step = aerocontrol.step_response(sys, T=t)
    impulse = aerocontrol.impulse_response(sys, T=t)
    _, steps = scipy.signal.dstep((*_matrices(sys), DT), n=samples)
    _, pulses = scipy.signal.dimpulse((*_matrices(sys), DT), n=samples)
    for j in range(sys.n_inputs):
        step_y = step.outputs(j)
        assert _relative(step_y, steps[j]) < 1e-12
        # Unit-area pulse η[0] = 1/dt (MATLAB, python-control); scipy's pulse is 1.
        assert _relative(impulse.outputs(j), pulses[j] / DT) < 1e-12
    assert np.array_equal(step.t, t)


@pytest.mark.parametrize("name", list(DISCRETE))
def test_forced_response_equals_scipy_dlsim(name: str) -> None:
    sys = DISCRETE[name]
    t = np.arange(300) * DT
    rng = np.random.default_rng(3)
    u = np.column_stack([np.sin(0.7 * t), np.sign(np.sin(0.2 * t))])[:, : sys.n_inputs]
    x0 = rng.standard_normal(sys.n_states)
    ours = aerocontrol.forced_response(sys, t, u, x0=x0)
    _, y, x = scipy.signal.dlsim((*_matrices(sys), DT), u, t, x0=x0)
    assert _relative(ours.y, y) < 1e-12
    assert _relative(ours.x, x) < 1e-12


@pytest.mark.parametrize("name", list(DISCRETE))
def test_responses_equal_python_control(name: str) -> None:
    sys = DISCRETE[name]
    theirs = control.ss(*_matrices(sys), DT)
    t = np.arange(200) * DT
    step = control.step_response(theirs, T=t)
    impulse = control.impulse_response(theirs, T=t)
    ours_step = aerocontrol.step_response(sys, T=t)
    ours_impulse = aerocontrol.impulse_response(sys, T=t)
    for j in range(sys.n_inputs):
        # python-control: outputs (p, m, k).
        assert _relative(ours_step.outputs(j), step.outputs[:, j, :].T) < 1e-12
        assert _relative(ours_impulse.outputs(j), impulse.outputs[:, j, :].T) < 1e-12
    x0 = np.linspace(-1.0, 1.0, sys.n_states)
    initial = control.initial_response(theirs, T=t, X0=x0)
    assert _relative(aerocontrol.initial_response(sys, x0, T=t).y, initial.outputs.T) < 1e-12
    u = np.cos(np.outer(t, np.arange(1, sys.n_inputs + 1)))
    forced = control.forced_response(theirs, T=t, U=u.T, X0=x0)
    ours = aerocontrol.forced_response(sys, t, u, x0=x0)
    assert _relative(ours.y, forced.outputs.T) < 1e-12
    assert _relative(ours.x, forced.states.T) < 1e-12


def test_a_grid_of_multiples_gives_every_qth_sample() -> None:
    sys = DISCRETE["747 lateral tustin"]
    fine = np.arange(601) * DT
    coarse = np.arange(121) * 5 * DT
    for response in (aerocontrol.step_response, aerocontrol.impulse_response):
        every = response(sys, T=fine)
        fifth = response(sys, T=coarse)
        assert _relative(fifth.y, every.y[:, ::5]) < 1e-12
        assert _relative(fifth.x, every.x[:, ::5]) < 1e-12
    x0 = np.ones(4)
    every = aerocontrol.initial_response(sys, x0, T=fine)
    assert _relative(aerocontrol.initial_response(sys, x0, T=coarse).x, every.x[::5]) < 1e-12


def test_default_grids_step_by_dt() -> None:
    sys = DISCRETE["747 longitudinal zoh"]
    t = aerocontrol.default_time_grid(sys)
    k = np.round(t / DT)
    assert np.array_equal(t, k * DT) and np.array_equal(k, np.arange(len(t)))
    # Seven time constants of the slowest decaying mode (the phugoid, σ = -0.00329).
    sigma = np.linalg.eigvals(A_LON).real.max()
    assert abs(t[-1] - 7 / -sigma) <= DT
    final = aerocontrol.step_response(sys, T=1.02)
    assert np.allclose(final.t, np.arange(21) * DT)
    # Beyond 100,001 samples every q-th sample is kept: σ = -1e-5 at dt = 1 ms needs 7e8 steps
    # to 7 time constants, so q = 7001.
    slow = StateSpace([[np.exp(-1e-5 * 0.001)]], [[1.0]], dt=0.001)
    t = aerocontrol.default_time_grid(slow)
    assert len(t) <= 100_001 and t[1] == pytest.approx(7.001, rel=1e-14)
    assert t[-1] > 7e5 - t[1]
    # The step response, by A^q and Σ A^i B every 7001 steps: y[k] = (1 - z^k) / (1 - z).
    z, steps = slow.A[0, 0], np.round(t / 0.001)
    expected = -np.expm1(steps * np.log(z)) / (1 - z)
    assert _relative(aerocontrol.step_response(slow).y[:, 0], expected) < 1e-11


def test_discrete_lists_and_models_without_inputs() -> None:
    models = [DISCRETE["747 lateral tustin"], aerocontrol.c2d(MODELS["747 lateral"], DT)]
    t = np.arange(50) * DT
    both = aerocontrol.step_response(models, T=t, eta0=[1.0, -0.5])
    for k, model in enumerate(models):
        alone = aerocontrol.step_response(model, T=t, eta0=[1.0, -0.5])
        assert _relative(both.x[k], alone.x) < 1e-15
    impulses = aerocontrol.impulse_response(models, T=t, eta0=[1.0, 0.0])
    assert _relative(impulses.y[1], aerocontrol.impulse_response(models[1], T=t).y[0]) < 1e-15
    with pytest.raises(InvalidArgumentError, match=r"sys\[1\] must have the sampling period"):
        aerocontrol.step_response([models[0], MODELS["747 lateral"]], T=t)
    free = StateSpace([[0.5]], np.zeros((1, 0)), dt=0.1)
    assert np.allclose(
        aerocontrol.initial_response(free, [1.0], T=0.3).x[:, 0], 0.5 ** np.arange(4)
    )


def test_discrete_response_errors_are_named() -> None:
    sys = DISCRETE["747 longitudinal zoh"]
    with pytest.raises(InvalidArgumentError, match=r"T must be a grid of multiples .* dt = 0.05"):
        aerocontrol.step_response(sys, T=np.arange(10) * 0.03)
    with pytest.raises(InvalidArgumentError, match="T must be a grid of multiples"):
        aerocontrol.impulse_response(sys, T=np.arange(10) * 0.075)
    with pytest.raises(InvalidArgumentError, match=r"T must step by the sampling period"):
        aerocontrol.forced_response(sys, np.arange(10) * 0.1, np.ones(10))
    with pytest.raises(InvalidArgumentError, match="method='foh' is a hold"):
        aerocontrol.forced_response(sys, np.arange(10) * DT, np.ones(10), method="foh")
    with pytest.raises(InvalidArgumentError, match=r"doublet .* no sampled equivalent"):
        aerocontrol.doublet_response(sys)
    with pytest.raises(InvalidArgumentError, match="at least the sampling period"):
        aerocontrol.step_response(sys, T=0.01)


# ----- steady state, DC gain, frequency response, modes ---------------------------------------


def test_dc_gain_and_steady_state_of_discrete_models() -> None:
    for name, sys in DISCRETE.items():
        theirs = control.dcgain(control.ss(*_matrices(sys), DT))
        assert _relative(aerocontrol.dc_gain(sys), np.atleast_2d(theirs)) < 1e-12, name
        # The zero-order hold keeps the DC gain.
    sys = MODELS["747 longitudinal"]
    assert _relative(aerocontrol.dc_gain(aerocontrol.c2d(sys, 0.1)), aerocontrol.dc_gain(sys)) < (
        1e-11
    )
    discrete = aerocontrol.c2d(sys, 0.1)
    expected = np.linalg.solve(np.eye(4) - discrete.A, discrete.B[:, 0])
    assert _relative(aerocontrol.steady_state(discrete, 1.0), expected) < 1e-12
    integrator = StateSpace([[1.0, 0.1], [0.0, 0.5]], [[0.0], [1.0]], dt=0.1)
    with pytest.raises(SingularMatrixError, match="A has the eigenvalue 1"):
        aerocontrol.dc_gain(integrator)


@pytest.mark.parametrize("name", list(DISCRETE))
def test_frequency_response_equals_python_control(name: str) -> None:
    sys = DISCRETE[name]
    omega = np.concatenate([[0.0], np.logspace(-3, np.log10(np.pi / DT), 200)])
    ours = aerocontrol.frequency_response(sys, omega).response
    theirs = np.moveaxis(
        control.frequency_response(control.ss(*_matrices(sys), DT), omega).complex, -1, 0
    )
    # Normwise per frequency; Tustin's map has G(z = -1) = D = 0 at the Nyquist frequency, so
    # the reference norm is floored at 1e-3 of its largest value.
    norms = np.linalg.norm(theirs, axis=(1, 2))
    errors = np.linalg.norm(ours - theirs, axis=(1, 2)) / np.maximum(norms, 1e-3 * norms.max())
    assert errors.max() < 1e-12


@pytest.mark.filterwarnings("ignore::scipy.signal.BadCoefficients")
def test_frequency_response_equals_scipy_dfreqresp() -> None:
    # scipy evaluates the transfer function's polynomials (ss2tf), whose coefficients are badly
    # conditioned with the poles crowded at z = 1 (scipy warns so): agreement to 3e-8.
    sys = DISCRETE["747 longitudinal zoh"]
    omega = np.logspace(-2, np.log10(np.pi / DT), 50)
    ours = aerocontrol.frequency_response(sys, omega).response
    for i in range(sys.n_outputs):
        siso = scipy.signal.StateSpace(sys.A, sys.B, sys.C[i : i + 1], sys.D[i : i + 1], dt=DT)
        _, expected = scipy.signal.dfreqresp(siso, w=omega * DT)
        assert np.max(np.abs(ours[:, i, 0] - expected) / np.abs(expected)) < 1e-7


def test_frequency_grid_reaches_nyquist_and_response_is_periodic() -> None:
    sys = DISCRETE["747 lateral tustin"]
    grid = aerocontrol.default_frequency_grid(sys)
    assert grid[-1] == pytest.approx(np.pi / DT, rel=1e-14)
    slowest = np.abs(np.log(np.linalg.eigvals(sys.A)) / DT).min()
    assert grid[0] == pytest.approx(slowest / 10, rel=1e-12)
    bode = aerocontrol.bode(sys)
    assert np.array_equal(bode.omega, grid)
    omega = np.array([0.1, 1.0, 10.0])
    shifted = aerocontrol.frequency_response(sys, omega + 2 * np.pi / DT).response
    assert _relative(shifted, aerocontrol.frequency_response(sys, omega).response) < 1e-11
    # At ω = 0 the response is the DC gain.
    at_zero = aerocontrol.frequency_response(sys, [0.0]).response[0].real
    assert _relative(at_zero, aerocontrol.dc_gain(sys)) < 1e-12


def test_modes_of_a_discrete_model_are_the_continuous_ones() -> None:
    continuous = aerocontrol.modes(MODELS["747 lateral"])
    for method in ("zoh", "matched"):
        model = MODELS["747 lateral"] if method == "zoh" else _siso([0, 0, 0, 1.0])
        if method == "matched":
            continuous = aerocontrol.modes(A_LON)
        sampled = aerocontrol.modes(aerocontrol.c2d(model, 0.05, method))
        assert _relative(sampled.natural_frequency, continuous.natural_frequency) < 1e-12
        assert _relative(sampled.damping_ratio, continuous.damping_ratio) < 1e-11
        assert np.array_equal(sampled.oscillatory, continuous.oscillatory)
    discrete = DISCRETE["747 lateral tustin"]
    wn, _, _ = control.damp(control.ss(*_matrices(discrete), DT), doprint=False)
    ours = aerocontrol.modes(discrete)
    assert _relative(np.sort(ours.natural_frequency), np.unique(np.round(wn, 12))) < 1e-10
    assert ours.eigenvalues.shape == (4,)
    P, modal_input = ours.modal_matrix, ours.modal_input
    assert P is not None and modal_input is not None
    assert _relative(P @ np.diag(ours.eigenvalues) @ np.linalg.inv(P), discrete.A) < 1e-12
    assert _relative(P @ modal_input, discrete.B) < 1e-12


def test_modes_of_negative_and_zero_discrete_eigenvalues() -> None:
    sys = StateSpace(np.diag([0.9, -0.5, 0.0]), np.ones((3, 1)), dt=0.1)
    m = aerocontrol.modes(sys)
    assert list(m.eigenvalue) == [0.9, -0.5, 0.0]
    nyquist = np.pi / 0.1
    assert m.oscillatory.tolist() == [False, True, False]
    assert m.period[1] == pytest.approx(0.2) and m.damped_frequency[1] == pytest.approx(nyquist)
    assert m.natural_frequency[0] == pytest.approx(-np.log(0.9) / 0.1)
    assert np.isinf(m.natural_frequency[2]) and m.damping_ratio[2] == 1.0
    assert m.time_to_half[2] == 0.0 and m.time_constant[2] == 0.0
    assert "-0.5 " in str(m) and "±" not in str(m)


# ----- layouts and inputs ---------------------------------------------------------------------


def _layouts(a: np.ndarray) -> dict[str, np.ndarray]:
    big = np.zeros(tuple(2 * d for d in a.shape))
    strided = big[(slice(None, None, 2),) * a.ndim]
    strided[...] = a
    return {
        "fortran": np.asfortranarray(a),
        "strided": strided,
        "big-endian": a.astype(">f8"),
        "read-only": np.frombuffer(a.tobytes(), dtype=np.float64).reshape(a.shape),
    }


def test_every_layout_gives_the_c_ordered_result() -> None:
    sys = MODELS["random n=6"]
    discrete = aerocontrol.c2d(sys, DT)
    t = np.arange(40) * DT
    calls: dict[str, Callable[[np.ndarray], Any]] = {
        "c2d zoh": lambda a: aerocontrol.c2d(StateSpace(a, sys.B, sys.C, sys.D), DT).A,
        "c2d tustin": lambda a: aerocontrol.c2d(StateSpace(a, sys.B, sys.C, sys.D), DT, "tustin").B,
        "d2c": lambda a: (
            aerocontrol.d2c(StateSpace(a, discrete.B, discrete.C, discrete.D, dt=DT)).A
        ),
        "step": lambda a: (
            aerocontrol.step_response(
                StateSpace(a, discrete.B, discrete.C, discrete.D, dt=DT), T=t
            ).y
        ),
        "frequency": lambda a: (
            aerocontrol.frequency_response(
                StateSpace(a, discrete.B, discrete.C, discrete.D, dt=DT), [0.1, 3.0]
            ).response
        ),
    }
    for name, call in calls.items():
        value = discrete.A if name in ("d2c", "step", "frequency") else sys.A
        expected = call(np.ascontiguousarray(value))
        for layout, array in _layouts(np.ascontiguousarray(value)).items():
            assert np.array_equal(call(array), expected), (name, layout)


def test_inputs_are_not_modified() -> None:
    rng = np.random.default_rng(5)
    A = np.asfortranarray(rng.standard_normal((5, 5)) - 4 * np.eye(5))
    B, C, D = rng.standard_normal((5, 2)), rng.standard_normal((3, 5)), np.zeros((3, 2))
    before = [array.copy(order="K") for array in (A, B, C, D)]
    sys = StateSpace(A, B, C, D)
    for method in ("zoh", "foh", "tustin"):
        discrete = aerocontrol.c2d(sys, 0.1, method)
        aerocontrol.d2c(discrete, "zoh" if method == "foh" else method)
        aerocontrol.step_response(discrete, T=np.arange(5) * 0.1)
        aerocontrol.frequency_response(discrete, [1.0])
    for array, copy in zip((A, B, C, D), before, strict=True):
        assert np.array_equal(array, copy)
    assert A.flags.f_contiguous
    assert not sys.A.flags.writeable and sys.dt is None


def test_continuous_designs_refuse_a_discrete_system() -> None:
    # lqr on a sampled model would solve the continuous problem for its matrices, silently.
    A, B = aerocontrol.chapter.boeing747_lateral()
    sampled = aerocontrol.c2d(aerocontrol.StateSpace(A, B), 0.02)
    Q, R = np.eye(4), np.eye(2)
    for call in (
        lambda: aerocontrol.lqr(sampled, Q, R),
        lambda: aerocontrol.riccati_ode(sampled, Q, R, np.linspace(0, 1, 3)),
        lambda: aerocontrol.batch.lqr_sweep(sampled, Q=Q, R=R, weights=[1.0]),
        lambda: aerocontrol.augment_mode(sampled, 1, zeta=0.3),
    ):
        with pytest.raises(InvalidArgumentError, match="discrete"):
            call()
    _, _, poles = aerocontrol.dlqr(sampled, Q, R)
    assert np.all(np.abs(poles) < 1)


# ----- sampled-data regulator (design.sampled_weights, design.sampled_data_lqr) -----------------


def _quadrature_weights(sys: StateSpace, dt: float, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """The oracle: W = ∫_0^dt e^{F^T t} diag(Q, R) e^{F t} dt by scipy's adaptive quadrature."""
    n, m = sys.n_states, sys.n_inputs
    F = np.zeros((n + m, n + m))
    F[:n, :n], F[:n, n:] = sys.A, sys.B
    H = scipy.linalg.block_diag(Q, R)

    def integrand(t: float) -> np.ndarray:
        E = scipy.linalg.expm(F * t)
        return E.T @ H @ E

    W, _ = scipy.integrate.quad_vec(integrand, 0.0, dt, epsabs=1e-15, epsrel=1e-13)
    return 0.5 * (W + W.T)


@pytest.mark.parametrize("name", ["747 lateral", "747 longitudinal", "random n=6"])
@pytest.mark.parametrize("dt", [0.02, 0.1, 1.0])
def test_sampled_weights_equal_the_quadrature_of_the_continuous_cost(name: str, dt: float) -> None:
    sys = MODELS[name]
    n, m = sys.n_states, sys.n_inputs
    rng = np.random.default_rng(3)
    root = rng.standard_normal((n, n))
    Q, R = root @ root.T, np.diag(rng.uniform(0.5, 2.0, m))
    w = aerocontrol.design.sampled_weights(sys, dt, Q, R)
    W = _quadrature_weights(sys, dt, Q, R)
    assert _relative(w.Q, W[:n, :n]) < 1e-11
    assert _relative(w.R, W[n:, n:]) < 1e-11
    assert _relative(w.N, W[:n, n:]) < 1e-11


def test_sampled_data_lqr_is_python_controls_dlqr_and_tends_to_lqr() -> None:
    sys = MODELS["747 lateral"]
    Kc = np.asarray(control.lqr(sys.A, sys.B, np.eye(4), np.eye(2))[0])
    previous = np.inf
    for dt in (0.1, 0.02, 0.004):
        K, S, E = aerocontrol.design.sampled_data_lqr(sys, dt)
        W = _quadrature_weights(sys, dt, np.eye(4), np.eye(2))
        Phi, Gamma, *_ = scipy.signal.cont2discrete((sys.A, sys.B, sys.C, sys.D), dt)
        K_ref, S_ref, _ = control.dlqr(Phi, Gamma, W[:4, :4], W[4:, 4:], W[:4, 4:])
        assert _relative(K, np.asarray(K_ref)) < 1e-9
        assert _relative(S, np.asarray(S_ref)) < 1e-9
        assert np.all(np.abs(E) < 1)
        # O(dt): the difference from the continuous gain shrinks with the period.
        difference = float(np.linalg.norm(K - Kc) / np.linalg.norm(Kc))
        assert difference < previous
        previous = difference
    assert previous < 2e-3


def test_sampled_weights_of_a_stiff_plant_do_not_overflow() -> None:
    # A mode at -1e4 rad/s held for 0.02 s: e^{+200} in one Van Loan step; by doublings, the
    # closed form ∫ e^{-2e4 t} dt = 1/2e4 (to e^{-400}) for the state weight.
    sys = StateSpace([[-1e4]], [[1.0]])
    w = aerocontrol.design.sampled_weights(sys, 0.02, [[1.0]], [[0.0]])
    assert w.Q[0, 0] == pytest.approx(1.0 / 2e4, rel=1e-12)
    with pytest.raises(InvalidArgumentError, match="sampled_weights designs in continuous time"):
        aerocontrol.design.sampled_weights(aerocontrol.c2d(sys, 0.1), 0.1)


@pytest.mark.parametrize("scale", [1e6, 1e8])
def test_sampled_weights_and_regulator_of_states_scaled_apart(scale: float) -> None:
    """Found by a hunt: in states x = T x̃ scaled apart (T = diag(1/s, s, s^-1/2, s^1/2)) the
    Van Loan exponential's errors, relative to ||F||, left Q_d wrong by 5e-7 (s = 1e6) and
    4e-3 (s = 1e8) relative to sqrt(Q_ii Q_jj), and K by 0.6 % at 1e8, silently. Now the
    states are balanced exactly first: the weights are those of the unscaled plant
    transformed (Q_d -> T Q_d T, N_d -> T N_d), against scipy's quadrature of the unscaled
    cost (1e-11 relative, as above), and the gain K0 T against python-control's dlqr of the
    unscaled problem (1e-9)."""
    sys = MODELS["random n=6"]
    n, m = sys.n_states, sys.n_inputs
    dt = 0.1
    W = _quadrature_weights(sys, dt, np.eye(n), np.eye(m))
    t = np.array([1 / scale, scale, scale**-0.5, scale**0.5, 1.0, 3.0])[:n]
    scaled = StateSpace(sys.A * (t[np.newaxis, :] / t[:, np.newaxis]), sys.B / t[:, np.newaxis])
    w = aerocontrol.design.sampled_weights(scaled, dt, np.diag(t**2), np.eye(m))
    Q_expected = W[:n, :n] * np.outer(t, t)
    size = np.sqrt(np.outer(np.diag(Q_expected), np.diag(Q_expected)))
    assert np.max(np.abs(w.Q - Q_expected) / size) < 1e-11
    assert _relative(w.R, W[n:, n:]) < 1e-11
    N_size = np.sqrt(np.outer(np.diag(Q_expected), np.diag(W[n:, n:])))
    assert np.max(np.abs(w.N - W[:n, n:] * t[:, np.newaxis]) / N_size) < 1e-11
    Phi, Gamma, *_ = scipy.signal.cont2discrete((sys.A, sys.B, sys.C, sys.D), dt)
    K0 = np.asarray(control.dlqr(Phi, Gamma, W[:n, :n], W[n:, n:], W[:n, n:])[0])
    K, _, _ = aerocontrol.design.sampled_data_lqr(scaled, dt, np.diag(t**2), np.eye(m))
    K_expected = K0 * t[np.newaxis, :]
    assert np.max(np.abs(K - K_expected) / np.abs(K_expected).max(axis=0)) < 1e-9


def test_sampled_weights_that_overflow_are_refused() -> None:
    """Found by a hunt: a B of 1e300 gave weights of NaN (with numpy's overflow warnings) and
    sampled_data_lqr then blamed Q ("Q must be finite, but Q[0, 0] is NaN"), which the caller
    had not given. Refused by name."""
    sys = StateSpace([[-1.0, 0.5], [0.0, -2.0]], [[1e300], [1e300]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidArgumentError, match="sampled weights overflow"):
            aerocontrol.design.sampled_weights(sys, 0.05)
        with pytest.raises(InvalidArgumentError, match="sampled weights overflow"):
            aerocontrol.design.sampled_data_lqr(sys, 0.05)


# ----- matched pole-zero beyond |z| = 1e154 (trust fixes) ------------------------------------


def _sampled_gain_at_one(sys: StateSpace) -> float:
    n = sys.A.shape[0]
    return float((sys.C @ np.linalg.solve(np.eye(n) - sys.A, sys.B))[0, 0] + sys.D[0, 0])


@pytest.mark.parametrize("sigma", [300.0, 400.0, 700.0, 709.0])
@pytest.mark.parametrize(
    "case", ["complex pair", "real pair", "real pair with feedthrough", "stable and unstable"]
)
def test_matched_poles_beyond_1e154(sigma: float, case: str) -> None:
    """Poles e^{σ dt} of 1e130 to 1e308: |z|^2 and the products of the gain overflowed beyond
    |z| = 1e154 (numpy's RuntimeWarnings, then a B of inf refused) although the model fits.
    Closed form: the poles are e^{p dt} (to the rounding of the exponential) and the DC gains
    agree, G_d(1) = G(0) (the matched method's gain), to 1e-13 relatively."""
    A, B, C, D = {
        "complex pair": ([[sigma, 1.0], [-1.0, sigma]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]),
        "real pair": ([[sigma, 0.0], [0.0, sigma - 1]], [[1.0], [1.0]], [[1.0, 0.0]], [[0.0]]),
        "real pair with feedthrough": (
            [[sigma, 0.0], [0.0, sigma - 1]],
            [[1.0], [1.0]],
            [[1.0, 0.0]],
            [[1.0]],
        ),
        "stable and unstable": ([[sigma, 0.0], [0.0, -1.0]], [[1.0], [1.0]], [[1.0, 2.0]], [[0.0]]),
    }[case]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sampled = aerocontrol.c2d(StateSpace(A, B, C, D), 1.0, "matched")
    assert np.all(np.isfinite(sampled.B)) and np.all(np.isfinite(sampled.C))
    poles = np.sort_complex(np.log(np.linalg.eigvals(sampled.A).astype(complex)))
    expected = np.sort_complex(np.linalg.eigvals(np.asarray(A)).astype(complex))
    assert np.allclose(poles, expected, rtol=1e-13, atol=0.0)
    continuous = float(
        (np.asarray(C) @ np.linalg.solve(-np.asarray(A), np.asarray(B)))[0, 0] + D[0][0]
    )
    assert _sampled_gain_at_one(sampled) == pytest.approx(continuous, rel=1e-13)


def test_matched_refuses_poles_whose_exponential_overflows() -> None:
    """e^{710} is beyond the doubles: refused naming dt, without numpy warnings."""
    sys = StateSpace([[710.0, 1.0], [-1.0, 710.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidArgumentError, match="e\\^\\(r dt\\) overflow") as caught:
            aerocontrol.c2d(sys, 1.0, "matched")
    assert caught.value.argument == "dt"


def test_matched_is_unchanged_below_the_scaling_threshold() -> None:
    """Poles below 2^256 keep the sections as before: a real pair's subdiagonal 1, poles
    e^{-dt}, e^{-2 dt} exactly."""
    sampled = aerocontrol.c2d(
        StateSpace([[-1.0, 0.0], [0.0, -2.0]], [[1.0], [1.0]], [[1.0, -1.0]], [[0.0]]),
        0.1,
        "matched",
    )
    assert sampled.A[1, 0] == 1.0
    assert sorted(np.diag(sampled.A)) == sorted([np.exp(-0.1), np.exp(-0.2)])
    assert _sampled_gain_at_one(sampled) == pytest.approx(0.5, rel=1e-14)


# ----- matched pole-zero of huge or tiny dynamics (defects found by fuzzing) -------------------


def _continuous_dc_gain(A: Any, B: Any, C: Any, D: Any) -> float:
    """G(0) = D - C A^-1 B in 400-bit arithmetic (mpmath)."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workprec(400):
        x = mpmath.lu_solve(-mpmath.matrix(np.asarray(A).tolist()), mpmath.matrix(B))
        return float((mpmath.matrix(C) * x)[0, 0] + D[0][0])


@pytest.mark.parametrize("scale", [1e100, 1e200, 1e300])
def test_matched_of_a_huge_a(scale: float) -> None:
    """A of 1e100 to 1e300 sampled at dt = 0.2 / scale (Re p dt near -0.3): the numerator was
    formed from characteristic polynomials, whose coefficients (of 1e400 and more) overflowed:
    numpy's warnings, then a NaN companion matrix refused as 'A must be finite' (blaming the
    caller's finite A). The zeros and the gain now come from the system pencil; the poles are
    e^{p dt} and the DC gains agree with mpmath's G(0)."""
    A = scale * np.array([[-1.0, 0.5, 0.0], [-0.3, -2.0, 0.4], [0.0, 0.2, -1.5]])
    B, C, D = [[1.0], [0.0], [2.0]], [[1.0, -1.0, 0.5]], [[0.0]]
    dt = 0.2 / scale
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sampled = aerocontrol.c2d(StateSpace(A, B, C, D), dt, "matched")
    expected = np.sort_complex(np.exp(np.linalg.eigvals(A / scale) * 0.2))
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(sampled.A)), expected, rtol=1e-13)
    continuous = _continuous_dc_gain(A, B, C, D)
    assert _sampled_gain_at_one(sampled) == pytest.approx(continuous, rel=1e-12)


def test_matched_pair_whose_exponential_underflows() -> None:
    """Poles -2e100 ± 1.4e100j and -2.8e100 sampled at 1000 s: every e^{p dt} underflows to 0
    (to within the smallest double, as exactly as it can be), so the pair's section was
    0 I with B = [0, 1], not controllable: its output row divided by zero (numpy's warning)
    and the model was refused blaming dt. The pair now goes with the real poles, and the
    sampled model z^3-poles at the origin has the continuous DC gain."""
    A = 1e100 * np.array([[-2.0, 1.4, 0.0], [-1.4, -2.0, 0.0], [0.3, 0.0, -2.8]])
    B, C, D = [[1.0], [0.5], [1.0]], [[0.2, -1.0, 1.0]], [[1.0]]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sampled = aerocontrol.c2d(StateSpace(A, B, C, D), 1000.0, "matched")
    assert np.all(np.linalg.eigvals(sampled.A) == 0.0)
    assert _sampled_gain_at_one(sampled) == pytest.approx(
        _continuous_dc_gain(A, B, C, D), rel=1e-12
    )


def test_matched_real_pair_is_realised_larger_pole_first() -> None:
    """Poles -1 and 300 (in that order from the Schur form): the real pair's section fed the
    state of e^{300} from that of e^{-1} through R = 1e130 with the smaller first, and the
    output row's two terms of 7e43 cancelled to the DC gain: 2.2e27 for 1.9967 (a silent
    wrong answer). The larger pole comes first now, whatever the order of the eigenvalues."""
    for A, C in (
        ([[-1.0, 0.0], [0.0, 300.0]], [[2.0, 1.0]]),
        ([[300.0, 0.0], [0.0, -1.0]], [[1.0, 2.0]]),
    ):
        sampled = aerocontrol.c2d(StateSpace(A, [[1.0], [1.0]], C, [[0.0]]), 1.0, "matched")
        assert _sampled_gain_at_one(sampled) == pytest.approx(
            _continuous_dc_gain(A, [[1.0], [1.0]], C, [[0.0]]), rel=1e-13
        )


def test_d2c_backward_difference_of_a_tiny_pole() -> None:
    """Ad = 1.26e-151 (dt = 0.1, no inputs or outputs), backward difference: the condition
    check formed (α ||A|| + 1) - α = (1.26e-151 + 1) - 1 = 0 and divided by it (a bare
    ZeroDivisionError, found by the property suite). The continuous pole is
    (z - 1)/(z dt) = -7.95e151 and samples back to Ad."""
    a = 1.257302210933933e-151
    sampled = StateSpace([[a]], np.zeros((1, 0)), np.zeros((0, 1)), np.zeros((0, 0)), dt=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        continuous = aerocontrol.d2c(sampled, "backward_diff")
    assert continuous.A[0, 0] == pytest.approx((a - 1.0) / (a * 0.1), rel=1e-14)
    again = aerocontrol.c2d(continuous, 0.1, "backward_diff")
    assert again.A[0, 0] == pytest.approx(a, rel=1e-14)


def test_d2c_refuses_a_continuous_model_beyond_the_doubles_by_name() -> None:
    """Tustin's inverse of Ad = 0 with C of 1e308: C (I + Ad)^-1 scaled by 2 is inf, and the
    model was refused as 'C must be finite, but C[0, 0] is inf' (a NonFiniteError blaming a C
    the caller never gave, found by the property suite). It is refused naming sys."""
    sampled = StateSpace([[0.0]], np.zeros((1, 0)), [[1e308]], np.zeros((1, 0)), dt=0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidArgumentError, match="continuous model's C overflows") as caught:
            aerocontrol.d2c(sampled, "tustin")
    assert caught.value.argument == "sys"
    assert not isinstance(caught.value, aerocontrol.NonFiniteError)


@pytest.mark.parametrize(
    "call",
    [
        lambda sys: aerocontrol.dlqr(sys, np.eye(2), 1.0),
        lambda sys: aerocontrol.dlqe(sys, np.eye(1), np.eye(1)),
        lambda sys: aerocontrol.riccati_difference(sys, np.eye(2), [[1.0]], 5),
        lambda sys: aerocontrol.batch.dlqr_sweep(sys, Q=np.eye(2), R=[[1.0]], weights=[1.0]),
        lambda sys: aerocontrol.kalman(sys, np.eye(1), np.eye(1), dt=0.1),
    ],
    ids=["dlqr", "dlqe", "riccati_difference", "dlqr_sweep", "kalman"],
)
def test_discrete_designs_refuse_a_model_marked_continuous(call: Any) -> None:
    A, B = np.array([[1.0, 0.1], [0.0, 1.0]]), np.array([[0.005], [0.1]])
    C = np.array([[1.0, 0.0]])
    scipy_signal = pytest.importorskip("scipy.signal")
    for continuous in (
        StateSpace(A, B, C, dt=0),
        control.ss(A, B, C, 0),
        scipy_signal.StateSpace(A, B, C, np.zeros((1, 1))),
    ):
        with pytest.raises(InvalidArgumentError, match="discrete-time"):
            call(continuous)
    call(StateSpace(A, B, C, dt=0.1))  # a sampled model is designed for
    call(scipy_signal.StateSpace(A, B, C, np.zeros((1, 1)), dt=0.1))
