"""Nyquist and Nichols analysis against python-control's nyquist_response and
frequency_response, numpy's eigenvalues of the open and closed loops (the Nyquist criterion
N = P - Z), numpy evaluations of L on the contour, and closed forms of the gain and phase."""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Iterator

import control
import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt

import aerocontrol
from aerocontrol import (
    AerocontrolLinAlgError,
    InvalidArgumentError,
    NonFiniteError,
    NotRealError,
    ShapeError,
    SingularMatrixError,
    loops,
    nichols,
    nyquist,
    plotting,
)


@pytest.fixture(autouse=True)
def _close_figures() -> Iterator[None]:
    yield
    plt.close("all")


def _scaled(k: float, loop: aerocontrol.StateSpace) -> aerocontrol.StateSpace:
    return aerocontrol.series(aerocontrol.gain(k), loop)


@functools.cache
def _yaw_damper() -> aerocontrol.design.Damper:
    """The 747 cruise yaw damper (its loop: actuator, -r/rudder, washout, for k = 1)."""
    return aerocontrol.design.yaw_damper(aerocontrol.aircraft.load())


def _yaw_loop() -> aerocontrol.StateSpace:
    return _yaw_damper().loop


def _control_system(loop: aerocontrol.StateSpace) -> control.StateSpace:
    return control.ss(loop.A, loop.B, loop.C, loop.D, loop.dt or 0)


def _numpy_counts(loop: aerocontrol.StateSpace) -> tuple[int, int]:
    """(P, Z) from numpy's eigenvalues of A and of A - B (1 + D)^-1 C."""
    closed = loop.A - loop.B @ loop.C / (1.0 + loop.D[0, 0])
    open_poles, closed_poles = np.linalg.eigvals(loop.A), np.linalg.eigvals(closed)
    if loop.is_discrete:
        return int(np.sum(np.abs(open_poles) > 1)), int(np.sum(np.abs(closed_poles) > 1))
    return int(np.sum(open_poles.real > 0)), int(np.sum(closed_poles.real > 0))


def _numpy_loop_at(loop: aerocontrol.StateSpace, points: np.ndarray) -> np.ndarray:
    """C (xI - A)^-1 B + D at complex points x (s, or z) by numpy.linalg.solve; D at ∞."""
    n = loop.n_states
    values = np.empty(points.size, np.complex128)
    for i, x in enumerate(points):
        if np.isinf(x.imag):
            values[i] = loop.D[0, 0]
        else:
            values[i] = (loop.C @ np.linalg.solve(x * np.eye(n) - loop.A, loop.B) + loop.D)[0, 0]
    return values


# Loops of the brief, with P, N (counterclockwise) and Z worked out by hand (Routh, or the
# closed-loop characteristic polynomial).
CASES: dict[str, tuple[aerocontrol.StateSpace, int, int, int]] = {
    # s³ + 3s² + 3s + 1 + k: stable below k = 8.
    "4/(s + 1)^3": (aerocontrol.zpk([], [-1.0, -1.0, -1.0], 4.0), 0, 0, 0),
    "10/(s + 1)^3": (aerocontrol.zpk([], [-1.0, -1.0, -1.0], 10.0), 0, -2, 2),
    # s³ + 3s² + 2s + k: stable below k = 6; an integrator (indented).
    "2/(s(s + 1)(s + 2))": (aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0), 0, 0, 0),
    "10/(s(s + 1)(s + 2))": (aerocontrol.zpk([], [0.0, -1.0, -2.0], 10.0), 0, -2, 2),
    # k(s + 2)/((s - 1)(s + 5)): s² + (4 + k)s + 2k - 5, stable for k > 2.5.
    "10(s + 2)/((s - 1)(s + 5))": (aerocontrol.zpk([-2.0], [1.0, -5.0], 10.0), 1, 1, 0),
    "(s + 2)/((s - 1)(s + 5))": (aerocontrol.zpk([-2.0], [1.0, -5.0], 1.0), 1, 0, 1),
    # Double integrator with a lead: s³ + 10s² + 5s + 5, stable (50 > 5).
    "5(s + 1)/(s²(s + 10))": (aerocontrol.zpk([-1.0], [0.0, 0.0, -10.0], 5.0), 0, 0, 0),
    # Undamped pair with a lead: s³ + 5s² + 4s + 6.5, stable (20 > 6.5); poles ±j indented.
    "3(s + 0.5)/((s² + 1)(s + 5))": (aerocontrol.zpk([-0.5], [1j, -1j, -5.0], 3.0), 0, 0, 0),
    # The same with a lag instead: s³ + 0.5 s² + 4 s + 15 (0.5·4 < 15), unstable.
    "3(s + 5)/((s² + 1)(s + 0.5))": (aerocontrol.zpk([-5.0], [1j, -1j, -0.5], 3.0), 0, -2, 2),
}


@pytest.mark.parametrize("name", list(CASES))
def test_encirclements_of_the_brief_loops(name: str) -> None:
    loop, P, N, Z = CASES[name]
    r = nyquist(loop)
    assert (r.open_loop_unstable_poles, r.encirclements, r.closed_loop_unstable_poles) == (P, N, Z)
    assert _numpy_counts(loop) == (P, Z)
    assert r.closed_loop_stable is (Z == 0) and not r.marginal
    # python-control counts clockwise encirclements: N_control = Z - P = -N. Its own check of
    # the criterion must pass (no warning), so that the oracle is self-consistent.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert control.nyquist_response(_control_system(loop)).count == -N
    # stability_margins counts the same way, from the poles.
    assert aerocontrol.stability_margins(loop).encirclements == N


def test_yaw_damper_loop_at_its_gain_and_beyond() -> None:
    damper = _yaw_damper()
    for k, N, Z in ((damper.design.gain, 0, 0), (10.0, 0, 0), (100.0, -2, 2)):
        loop = _scaled(k, damper.loop)
        r = nyquist(loop)
        assert (r.open_loop_unstable_poles, r.encirclements) == (0, N)
        assert (r.closed_loop_unstable_poles, _numpy_counts(loop)) == (Z, (0, Z))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert control.nyquist_response(_control_system(loop)).count == -N
    assert damper.margins.closed_loop_stable


def _discrete_cases() -> dict[str, tuple[aerocontrol.StateSpace, int, int, int]]:
    plant = aerocontrol.c2d(aerocontrol.zpk([], [0.0, -1.0], 1.0), 0.1)  # a pole at z = 1
    rotation = 0.5  # a pair on the unit circle at e^{±0.5j}
    oscillator = aerocontrol.StateSpace(
        [[math.cos(rotation), -math.sin(rotation)], [math.sin(rotation), math.cos(rotation)]],
        [[1.0], [0.0]],
        [[0.2, 0.1]],
        [[0.1]],
        dt=0.1,
    )
    # A pole at z = -1 (ω = π/dt, the end of the half contour) and one at 0.5.
    alternating = aerocontrol.StateSpace(
        [[-1.0, 0.0], [1.0, 0.5]], [[1.0], [0.0]], [[0.3, 1.0]], [[0.0]], dt=0.05
    )
    unstable = aerocontrol.StateSpace([[1.5]], [[1.0]], [[1.0]], [[0.0]], dt=0.2)
    return {
        "ZOH 1/(s(s + 1)), k = 5": (_scaled(5.0, plant), 0, 0, 0),
        "ZOH 1/(s(s + 1)), k = 30": (_scaled(30.0, plant), 0, -2, 2),
        "pair on the unit circle": (oscillator, 0, 0, 0),
        "pole at z = -1": (alternating, 0, 0, 0),
        "1/(z - 1.5), k = 1": (unstable, 1, 1, 0),  # closed loop z - 0.5
        "1/(z - 1.5), k = 0.2": (_scaled(0.2, unstable), 1, 0, 1),  # z - 1.3
    }


@pytest.mark.parametrize("name", list(_discrete_cases()))
def test_discrete_loops(name: str) -> None:
    loop, P, N, Z = _discrete_cases()[name]
    r = nyquist(loop)
    assert (r.open_loop_unstable_poles, r.encirclements, r.closed_loop_unstable_poles) == (P, N, Z)
    assert _numpy_counts(loop) == (P, Z)
    assert r.dt == loop.dt and r.omega.max() <= math.pi / r.dt
    # The contour is the unit circle, from z = 1 to z = -1, pushed outside round its poles.
    assert np.all(np.abs(r.contour[~r.indented]) == pytest.approx(1.0, abs=1e-15))
    assert np.all(np.abs(r.contour[r.indented]) >= 1.0 - 1e-15)
    assert r.contour[-1].real < 0 and abs(r.contour[-1].imag) == 0.0
    if name.startswith("ZOH") or name.startswith("1/"):  # python-control handles these
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert control.nyquist_response(_control_system(loop)).count == -N


def test_curve_against_python_control_and_numpy() -> None:
    """L on the axis against control.frequency_response; L on the whole contour (the
    indentations off the axis, the unit circle) against numpy's solve at the same points.

    The tolerance is 1e-12 of |L| plus 1e-14 of the curve's largest |L|: near a zero of L
    (the washout's, at s = 0) L is a cancelling sum, and the three evaluations differ by
    1e-12 of |L| among themselves there (the yaw loop at ω = 5e-4, |L| = 5e-3), and at the
    zero itself by their rounding noise (L(0) is -4.5e-15 by the core, -1.8e-15 by
    python-control, beside max |L| = 2.5); elsewhere the worst is 2e-14 (near the poles on
    the unit circle)."""
    loops_ = [case[0] for case in CASES.values()] + [_scaled(2.4, _yaw_loop())]
    loops_ += [case[0] for case in _discrete_cases().values()]
    for loop in loops_:
        r = nyquist(loop)
        oracle = control.frequency_response(_control_system(loop), r.omega).complex.ravel()
        allowed = 1e-12 * np.abs(r.response) + 1e-14 * np.max(np.abs(r.response))
        assert np.all(np.abs(oracle - r.response) <= allowed)
        direct = _numpy_loop_at(loop, r.contour)
        allowed = 1e-12 * np.abs(r.curve) + 1e-14 * np.max(np.abs(r.curve))
        assert np.all(np.abs(direct - r.curve) <= allowed)


def test_indentation_around_an_integrator_is_a_large_clockwise_arc() -> None:
    r = nyquist(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0))
    ((w0, radius, count),) = r.indentations
    assert (w0, count) == (0.0, 1) and 0.0 < radius <= 0.01
    arc = r.contour[r.indented]
    np.testing.assert_allclose(np.abs(arc), radius, rtol=1e-14)
    assert arc[0] == radius and arc[-1] == pytest.approx(1j * radius, abs=1e-18)
    # L ≈ K0/s on the arc: K0 = 2/2 = 1, so |L| ≈ 1/ε and ∠L turns from 0° to -90°.
    values = r.curve[r.indented]
    np.testing.assert_allclose(np.abs(values) * radius, 1.0, rtol=2 * radius)
    assert np.angle(values[0]) == 0.0
    assert math.degrees(np.angle(values[-1])) == pytest.approx(-90.0, abs=2 * math.degrees(radius))
    # The whole curve closes: the mirror half is the conjugate, joined at both ends.
    closed = r.closed_curve
    assert closed.size == 2 * r.curve.size and closed[0] == r.curve[-1] == 0.0


def test_marginal_loop_is_flagged_not_counted() -> None:
    # 6/(s(s + 1)(s + 2)): s³ + 3s² + 2s + 6 = (s + 3)(s² + 2), poles ±j√2 on the axis.
    r = nyquist(aerocontrol.zpk([], [0.0, -1.0, -2.0], 6.0))
    assert r.marginal and r.encirclements is None and not r.closed_loop_stable
    np.testing.assert_allclose(np.sort(r.boundary_poles.imag), [-math.sqrt(2), math.sqrt(2)])
    assert r.closed_loop_unstable_poles == 0
    # The curve passes through -1 at ω = √2 (L(j√2) = -1), which the grid holds.
    assert np.min(np.abs(r.curve + 1.0)) < 1e-6
    text = str(r)
    assert "N undefined" in text and "MARGINAL" in text


def test_an_inconsistent_count_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(loops._Contour, "winding", lambda self, centre: 1.0)
    with pytest.raises(AerocontrolLinAlgError, match="P - Z"):
        nyquist(aerocontrol.zpk([], [-1.0, -1.0, -1.0], 4.0))


def test_a_count_that_disagrees_once_is_retried_on_a_finer_contour(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[int] = []
    winding = loops._Contour.winding

    def wrong_once(self: loops._Contour, centre: complex) -> float:
        calls.append(self.values.size)
        return 3.0 if len(calls) == 1 else winding(self, centre)

    monkeypatch.setattr(loops._Contour, "winding", wrong_once)
    r = nyquist(aerocontrol.zpk([], [0.0, -1.0, -2.0], 10.0))
    assert r.encirclements == -2 and len(calls) == 2
    assert calls[1] > calls[0]  # twice the points (and indentations 100 times smaller)
    # The nearest other root of the origin is the open-loop pole -1: radius 1e-2, then 1e-4.
    assert r.indentations[0][1] == pytest.approx(1e-4, rel=1e-12)


def test_python_control_state_space_is_accepted() -> None:
    loop = control.ss(control.tf([10.0], [1.0, 3.0, 3.0, 1.0]))
    assert nyquist(loop).encirclements == -2
    assert nichols(loop, [math.sqrt(3.0)]).phase_deg[0] == pytest.approx(-180.0, abs=1e-11)


def _random_loop(rng: np.random.Generator, discrete: bool) -> aerocontrol.StateSpace:
    """A loop of order 1 to 6 with random real and complex poles (some unstable), in a random
    basis, random B, C and D, and a gain over three decades."""
    n = int(rng.integers(1, 7))
    blocks: list[np.ndarray] = []
    while sum(b.shape[0] for b in blocks) < n:
        if n - sum(b.shape[0] for b in blocks) >= 2 and rng.random() < 0.5:
            if discrete:
                radius, angle = rng.uniform(0.2, 1.4), rng.uniform(0.1, 3.0)
                a, b = radius * math.cos(angle), radius * math.sin(angle)
            else:
                a, b = rng.uniform(-3.0, 1.0), rng.uniform(0.1, 4.0)
            blocks.append(np.array([[a, b], [-b, a]]))
        else:
            blocks.append(
                np.array([[rng.uniform(-1.4, 1.4) if discrete else rng.uniform(-4, 1.5)]])
            )
    J = np.zeros((n, n))
    i = 0
    for block in blocks:
        J[i : i + block.shape[0], i : i + block.shape[0]] = block
        i += block.shape[0]
    S = rng.standard_normal((n, n)) + 2 * np.eye(n)
    A = S @ J @ np.linalg.inv(S)
    B, C = rng.standard_normal((n, 1)), rng.standard_normal((1, n))
    D = np.array([[rng.uniform(-0.5, 0.5) if rng.random() < 0.3 else 0.0]])
    k = 10.0 ** rng.uniform(-1.0, 2.0)
    return aerocontrol.StateSpace(A, k * B, C, k * D, dt=0.1 if discrete else None)


def _away_from_the_boundary(loop: aerocontrol.StateSpace) -> bool:
    closed = loop.A - loop.B @ loop.C / (1.0 + loop.D[0, 0])
    roots = np.concatenate([np.linalg.eigvals(loop.A), np.linalg.eigvals(closed)])
    distance = np.abs(np.abs(roots) - 1.0) if loop.is_discrete else np.abs(roots.real)
    return bool(np.min(distance) > 1e-6)


@pytest.mark.parametrize("discrete", [False, True])
def test_random_loops_satisfy_the_nyquist_criterion(discrete: bool) -> None:
    rng = np.random.default_rng(25 + discrete)
    checked = encircling = 0
    while checked < 80:
        loop = _random_loop(rng, discrete)
        if not _away_from_the_boundary(loop):
            continue
        r = nyquist(loop)
        P, Z = _numpy_counts(loop)
        assert (r.open_loop_unstable_poles, r.closed_loop_unstable_poles) == (P, Z)
        assert r.encirclements == P - Z
        # The count from the curve itself, by an independent angle sum on the closed curve.
        turns = np.diff(np.unwrap(np.angle(r.closed_curve + 1.0)))
        assert round(float(turns.sum()) / (2 * math.pi)) == P - Z
        checked += 1
        encircling += P - Z != 0
    assert encircling >= 10  # the set exercises encirclements, not only N = 0


# ----- Nichols ----------------------------------------------------------------------------


def _atan(x: np.ndarray) -> np.ndarray:
    return np.degrees(np.arctan(x))


def test_nichols_against_closed_forms() -> None:
    w = np.array([0.01, 0.3, 1.0, math.sqrt(2.0), 3.0, 20.0])
    # 10/(s + 1)³: -3 atan ω, through -180° at ω = √3 and on to -270°.
    n = nichols(aerocontrol.zpk([], [-1.0, -1.0, -1.0], 10.0), w)
    np.testing.assert_allclose(n.phase_deg, -3 * _atan(w), rtol=0, atol=1e-11)
    expected = 20 * np.log10(10.0) - 30 * np.log10(1 + w**2)
    np.testing.assert_allclose(n.gain_db, expected, rtol=0, atol=1e-11)
    # 2/(s(s + 1)(s + 2)): the integrator's -90° from the start.
    n = nichols(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0), w)
    np.testing.assert_allclose(n.phase_deg, -90 - _atan(w) - _atan(w / 2), rtol=0, atol=1e-11)
    expected = 20 * np.log10(2.0 / w) - 10 * np.log10(1 + w**2) - 10 * np.log10(4 + w**2)
    np.testing.assert_allclose(n.gain_db, expected, rtol=0, atol=1e-11)
    # 10(s + 2)/((s - 1)(s + 5)): L(0) = -4 < 0 starts at -180°; ∠(jω - 1) = 180° - atan ω.
    n = nichols(aerocontrol.zpk([-2.0], [1.0, -5.0], 10.0), np.concatenate([[0.0], w]))
    x = np.concatenate([[0.0], w])
    np.testing.assert_allclose(
        n.phase_deg, _atan(x / 2) - 180 + _atan(x) - _atan(x / 5), rtol=0, atol=1e-11
    )
    # 5(s + 1)/(s²(s + 10)): a double integrator starts at -180°.
    n = nichols(aerocontrol.zpk([-1.0], [0.0, 0.0, -10.0], 5.0), w)
    np.testing.assert_allclose(n.phase_deg, -180 + _atan(w) - _atan(w / 10), rtol=0, atol=1e-11)


def test_nichols_phase_across_poles_and_zeros_on_the_axis() -> None:
    # 3(s + 0.5)/((s² + 1)(s + 5)): the indentation to the right of j takes -180° (the
    # default grid, so the phase is unwrapped across the pole along the contour).
    n = nichols(aerocontrol.zpk([-0.5], [1j, -1j, -5.0], 3.0))
    phase = _atan(2 * n.omega) - _atan(n.omega / 5) - 180.0 * (n.omega > 1.0)
    np.testing.assert_allclose(n.phase_deg, phase, rtol=0, atol=1e-9)
    assert n.omega.min() == 0.0 and not np.any(np.abs(n.omega - 1.0) < 1e-4)
    # A frequency at the pole: the core's L there (not finite), and no phase.
    at_pole = nichols(aerocontrol.zpk([-0.5], [1j, -1j, -5.0], 3.0), [0.5, 1.0, 2.0])
    assert math.isnan(at_pole.phase_deg[1]) and not np.isfinite(at_pole.response[1])
    np.testing.assert_allclose(at_pole.phase_deg[[0, 2]], phase_at([0.5, 2.0]), atol=1e-11)
    # A washout s/(s + 1/3) on 1/(s + 1): the zero at s = 0 gives +90° at ω → 0+ (indented
    # to the right, not the noise of L(0) = 0), then 90° - atan 3ω - atan ω.
    washed = aerocontrol.series(aerocontrol.washout(3.0), aerocontrol.tf([1.0], [1.0, 1.0]))
    n = nichols(washed)
    assert n.omega.min() > 0.0
    np.testing.assert_allclose(
        n.phase_deg, 90 - _atan(3 * n.omega) - _atan(n.omega), rtol=0, atol=1e-9
    )


def phase_at(w: list[float]) -> np.ndarray:
    x = np.array(w)
    return _atan(2 * x) - _atan(x / 5) - 180.0 * (x > 1.0)


def test_nichols_of_a_discrete_loop_against_its_closed_form() -> None:
    # 0.5/(z - 0.8): ∠L = -atan2(sin θ, cos θ - 0.8), θ = ω dt, from 0° to -180° at z = -1.
    dt = 0.1
    loop = aerocontrol.StateSpace([[0.8]], [[1.0]], [[0.5]], [[0.0]], dt=dt)
    n = nichols(loop)
    theta = n.omega * dt
    z = np.exp(1j * theta)
    np.testing.assert_allclose(
        n.phase_deg, -np.degrees(np.arctan2(np.sin(theta), np.cos(theta) - 0.8)), atol=1e-11
    )
    np.testing.assert_allclose(n.gain_db, 20 * np.log10(0.5 / np.abs(z - 0.8)), atol=1e-11)
    assert n.omega[-1] == pytest.approx(math.pi / dt) and n.phase_deg[-1] == pytest.approx(-180)


def test_nichols_yaw_damper_against_python_control() -> None:
    loop = _scaled(2.4, _yaw_loop())
    n = nichols(loop)
    oracle = control.frequency_response(_control_system(loop), n.omega)
    np.testing.assert_allclose(n.gain_db, 20 * np.log10(oracle.magnitude.ravel()), atol=1e-10)
    # The washout's zero at 0 starts the phase at +90°; two poles more than zeros and the
    # right-half-plane pair of zeros of r/rudder end it at -540° (180° mod 360°).
    assert n.phase_deg[0] == pytest.approx(90.0, abs=1.0)
    assert n.phase_deg[-1] == pytest.approx(-540.0, abs=1.0)
    wrapped = (n.phase_deg - np.degrees(oracle.phase.ravel()) + 180.0) % 360.0 - 180.0
    np.testing.assert_allclose(wrapped, 0.0, atol=1e-9)


# ----- arguments, layouts, tables ---------------------------------------------------------


def test_bad_arguments_are_refused_by_name() -> None:
    loop = aerocontrol.zpk([], [-1.0, -1.0, -1.0], 4.0)
    mimo = aerocontrol.StateSpace(-np.eye(2), np.eye(2), np.eye(2), np.zeros((2, 2)))
    for function in (nyquist, nichols):
        with pytest.raises(ShapeError, match="loop must have one input and one output"):
            function(mimo)
        with pytest.raises(NonFiniteError, match=r"omega must be finite, but omega\[1\] is NaN"):
            function(loop, [0.1, math.nan])
        with pytest.raises(NonFiniteError, match="omega"):
            function(loop, [math.inf])
        with pytest.raises(InvalidArgumentError, match=r"omega must be non-negative.*omega\[2\]"):
            function(loop, [0.1, 1.0, -2.0])
        with pytest.raises(ShapeError, match="omega must be a non-empty 1-D array"):
            function(loop, np.ones((2, 2)))
        with pytest.raises(ShapeError, match="omega"):
            function(loop, [])
        with pytest.raises(NotRealError, match="omega must be real"):
            function(loop, [1j])
        discrete = aerocontrol.StateSpace([[0.5]], [[1.0]], [[1.0]], [[0.0]], dt=0.1)
        with pytest.raises(InvalidArgumentError, match="Nyquist frequency"):
            function(discrete, [1.0, 40.0])
    with pytest.raises(SingularMatrixError, match="algebraic loop"):
        nyquist(aerocontrol.StateSpace([[-1.0]], [[1.0]], [[1.0]], [[-1.0]]))
    r = nyquist(loop)
    with pytest.raises(InvalidArgumentError, match="max_magnitude"):
        r.plot(max_magnitude=0.0)
    with pytest.raises(InvalidArgumentError, match="phases_deg"):
        plotting.plot_nichols(nichols(loop), phases_deg=[-400.0])


def test_asked_frequencies_are_reported_sorted_and_not_modified() -> None:
    loop = aerocontrol.zpk([-0.5], [1j, -1j, -5.0], 3.0)
    omega = np.array([2.0, 0.1, 1.0, 0.5])
    kept = omega.copy()
    r = nyquist(loop, omega)
    np.testing.assert_array_equal(omega, kept)
    np.testing.assert_array_equal(r.omega, [0.1, 0.5, 1.0, 2.0])
    assert r.encirclements == 0 and r.closed_loop_stable
    direct = _numpy_loop_at(loop, 1j * np.array([0.1, 0.5, 2.0]))
    np.testing.assert_allclose(r.response[[0, 1, 3]], direct, rtol=1e-13)
    assert not np.isfinite(r.response[2]) or abs(r.response[2]) > 1e12  # the pole at j
    # The asked frequencies off the pole lie on the contour.
    for w in (0.1, 0.5, 2.0):
        assert np.any(r.contour == 1j * w)


def test_any_memory_layout_gives_the_same_curve() -> None:
    loop = aerocontrol.zpk([-2.0], [1.0, -5.0, -0.3 + 2j, -0.3 - 2j], 10.0)
    strided = np.zeros((1, 2 * loop.n_states))
    strided[:, ::2] = loop.C
    other = (np.asfortranarray(loop.A), np.asfortranarray(loop.B), strided[:, ::2], loop.D)
    assert not other[0].flags.c_contiguous and not other[2].flags.c_contiguous
    first, second = nyquist(loop), nyquist(other)
    np.testing.assert_array_equal(first.curve, second.curve)
    P, Z = _numpy_counts(loop)
    assert first.encirclements == second.encirclements == P - Z == -2


def test_table_says_p_n_z_and_the_verdict() -> None:
    text = nyquist(aerocontrol.zpk([-2.0], [1.0, -5.0], 10.0)).table()
    assert "P = 1" in text and "N = 1" in text and "Z = 0" in text
    assert "closed loop stable" in text and "open right half plane" in text
    text = str(nyquist(aerocontrol.zpk([], [0.0, -1.0, -2.0], 10.0)))
    assert "N = -2" in text and "UNSTABLE" in text and "indented around 1 open-loop pole" in text
    discrete = str(nyquist(_discrete_cases()["1/(z - 1.5), k = 1"][0]))
    assert "outside the unit circle" in discrete
    assert "gain" in str(nichols(_yaw_loop())) and "phase" in str(nichols(_yaw_loop()))


# ----- plots ------------------------------------------------------------------------------


def test_nyquist_plot_renders_with_arrows_and_compression() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        figure, ax = plt.subplots()
        r = nyquist(aerocontrol.zpk([-1.0], [0.0, 0.0, -10.0], 5.0))
        returned = r.plot(ax=ax, unit_circle=True, max_magnitude=10.0)
        figure.canvas.draw()
    assert returned is ax
    labels = [line.get_label() for line in ax.get_lines()]
    assert {"ω ≥ 0", "ω ≤ 0 (mirror image)", "-1", "|L| = 1"} <= set(labels)
    assert "|L| = 10, compressed beyond" in labels
    assert ax.get_xlabel() == "Re L" and ax.get_ylabel() == "Im L"
    assert ax.get_title() == "Nyquist: P = 0, N = 0, Z = 0, closed loop stable"
    # Two arrows on each half (annotations without text).
    assert len(ax.texts) == 4
    assert all(t.arrow_patch is not None and t.get_text() == "" for t in ax.texts)
    # The double integrator's arcs (|L| near 1e4) are drawn between R and 2R.
    half = ax.get_lines()[0]
    radius = np.hypot(half.get_xdata(), half.get_ydata())
    assert np.max(np.abs(r.curve)) > 5e3 and 15.0 < radius.max() < 20.0
    # The solid half is the curve itself where |L| <= R.
    inside = np.abs(r.curve) <= 10.0
    np.testing.assert_allclose(np.asarray(half.get_xdata())[inside], r.curve.real[inside])


def test_compression_is_continuous_logarithmic_and_bounded() -> None:
    R = 20.0
    r = np.array([1.0, 19.999999, 20.0, 20.000001, 200.0, 1e12, 1e300])
    drawn = np.abs(plotting._compressed(r.astype(np.complex128), R))
    np.testing.assert_allclose(drawn[:3], r[:3])
    assert drawn[3] == pytest.approx(20.000001, rel=1e-9)  # slope 1 at R
    x = np.log(r[4:] / R)
    np.testing.assert_allclose(drawn[4:], R * (1 + x / (1 + x)), rtol=1e-15)
    assert np.all(np.diff(drawn) > 0) and drawn[-1] < 2 * R
    # The angle is kept.
    point = 1e9 * np.exp(1j * 2.0)
    assert np.angle(plotting._compressed(np.array([point]), R))[0] == pytest.approx(2.0)


def test_nichols_plot_renders_its_grid_and_critical_points() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ax = nichols(_scaled(2.4, _yaw_loop())).plot()
        ax.figure.canvas.draw()
    assert ax.get_xlabel() == "open-loop phase (deg)"
    assert ax.get_ylabel() == "open-loop gain (dB)"
    lines = {line.get_label(): line for line in ax.get_lines()}
    low, high = ax.get_xlim()
    assert (low, high) == (-720.0, 360.0)  # the phase runs from +90° to -540°
    critical = lines["critical points"]
    np.testing.assert_array_equal(critical.get_xdata(), [-540.0, -180.0, 180.0])
    np.testing.assert_array_equal(critical.get_ydata(), [0.0, 0.0, 0.0])
    # Every grid contour is what it says: |T| or ∠T of T = L/(1 + L) at each of its points.
    gains = [line for line in ax.get_lines() if str(line.get_gid()).startswith("closed-loop gain")]
    phases = [line for line in ax.get_lines() if str(line.get_gid()).startswith("closed-loop ph")]
    assert len(gains) == 3 * len(plotting.NICHOLS_GAINS_DB)
    assert len(phases) == 3 * len(plotting.NICHOLS_PHASES_DEG)
    for line in gains + phases:
        x, y = np.asarray(line.get_xdata()), np.asarray(line.get_ydata())
        ok = np.isfinite(x)
        L = 10 ** (y[ok] / 20) * np.exp(1j * np.radians(x[ok]))
        T = L / (1 + L)
        value = float(str(line.get_gid()).split()[2])
        if "gain" in str(line.get_gid()):
            np.testing.assert_allclose(20 * np.log10(np.abs(T)), value, atol=1e-9)
        else:
            difference = (np.degrees(np.angle(T)) - value + 180.0) % 360.0 - 180.0
            np.testing.assert_allclose(difference, 0.0, atol=1e-8)
    bare = nichols(_scaled(2.4, _yaw_loop())).plot(grid=False)
    assert not any(line.get_gid() for line in bare.get_lines())


def test_nichols_curve_breaks_across_a_pole_on_the_axis() -> None:
    ax = nichols(aerocontrol.zpk([-0.5], [1j, -1j, -5.0], 3.0)).plot(grid=False)
    curve = next(line for line in ax.get_lines() if line.get_label() == "L(jω)")
    x = np.asarray(curve.get_xdata())
    assert np.sum(np.isnan(x)) == 1
    steps = np.abs(np.diff(x))
    assert np.nanmax(steps) < 90.0


# ----- inputs a campaign found ------------------------------------------------------------


def test_regression_pole_at_the_origin_beside_poles_of_1e_300() -> None:
    """A companion A of 1e-300 with poles 0, -1e-300, -2e-300, -3e-300 ± 3e-307j (the core
    gives 2.2e-318 for 0): numpy's Frobenius norm of A underflowed to 0, so the boundary band
    was 0, the pole at 2.2e-318 counted as unstable, the contour ran through it and L
    overflowed there (an AerocontrolLinAlgError). Its norm is now formed scaled."""
    A = np.zeros((5, 5))
    A[0, :4] = [-9e-300, -2.9e-299, -3.9e-299, -1.8e-299]
    A[1, 0] = A[2, 1] = A[3, 2] = A[4, 3] = 1e-300
    B = np.array([[0.0], [0.0], [0.0], [0.0], [0.001]])
    C = np.array([[-626.951350505633] * 3 + [515.378818, -626.951350505633]])
    D = np.array([[-1.442720466450946]])
    r = nyquist((A, B, C, D))
    assert r.open_loop_unstable_poles == 0
    ((w0, radius, count),) = r.indentations
    assert (w0, count) == (0.0, 1) and 0.0 < radius < 1e-301
    assert np.all(np.isfinite(r.curve[:-1]))
    # A - B C/(1 + D) has poles of 1e-300 beside -1.416: on the axis to its accuracy.
    assert r.marginal and r.encirclements is None


def test_regression_closed_loop_poles_beyond_the_doubles_are_refused_by_name() -> None:
    """L = 1e600/s (A = 0, B and C of 1e300): the closed-loop pole overflows; refused as such,
    without the overflow warning of the poles before the error."""
    B = np.zeros((4, 1))
    B[3, 0] = 1e300
    loop = (np.zeros((4, 4)), B, np.full((1, 4), 1e300), np.zeros((1, 1)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(AerocontrolLinAlgError, match="closed-loop poles overflow"):
            nyquist(loop)


def test_regression_hidden_modes_on_the_axis_beside_a_large_c() -> None:
    """B = 0 (every mode hidden, L = D = 2) with modes at 0, ±3j (twice) and C of 2e8: the
    band for the zeros on the axis was taken from the size of the system pencil (5.4, from
    C), which merged the roots at 0 and 3j into one indentation at 0 and left the contour
    through the modes at ±3j, where the core's L is 0/0 (an AerocontrolLinAlgError)."""
    A = np.zeros((5, 5))
    A[0, 1] = A[2, 3] = 3.0
    A[1, 0] = A[3, 2] = -3.0
    loop = (A, np.zeros((5, 1)), np.array([[-2e8, -2e8, 0.0, -1e8, -2e8]]), np.array([[2.0]]))
    n = nichols(loop)
    np.testing.assert_array_equal(n.response, 2.0)
    np.testing.assert_array_equal(n.phase_deg, 0.0)
    r = nyquist(loop)
    assert [(w, count) for w, _, count in r.indentations] == [(0.0, 1), (pytest.approx(3.0), 2)]
    # The modes are closed-loop poles too, on the axis: marginal, however the curve runs.
    assert r.marginal and r.encirclements is None
    np.testing.assert_array_equal(r.curve, 2.0)


def test_regression_closed_loop_pole_near_the_largest_double() -> None:
    """L = -1e308/(s + 1.56): the closed-loop pole is +1e308, and the points clustered about
    it (|Re s| times up to 10) overflowed with numpy's RuntimeWarning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = nyquist(([[-1.5636496689062018]], [[-1e308]], [[1.0]], [[0.0]]))
    assert (r.open_loop_unstable_poles, r.encirclements, r.closed_loop_unstable_poles) == (0, -1, 1)


def test_regression_poles_near_the_largest_double() -> None:
    """A pole at -1e308 (B of 1e308): the grid reaches the largest doubles, where the
    midpoint (a + b)/2 and the step 10 ω towards ∞ overflowed with numpy's RuntimeWarning.
    Midpoints are now a/2 + b/2, the step towards ∞ stops at the largest double, and L there
    is checked against L = C/(s/1e308 + 1) + D, formed scaled."""
    C, D = 12573022.10933933, -65179115.261168964
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = nyquist(([[-1e308]], [[1e308]], [[C]], [[D]]))
    assert (r.open_loop_unstable_poles, r.encirclements, r.closed_loop_unstable_poles) == (0, 0, 0)
    assert 1e308 < r.omega.max() <= np.finfo(float).max
    exact = C / (1j * (r.omega / 1e308) + 1.0) + D
    np.testing.assert_allclose(r.response, exact, rtol=1e-14)
    assert r.curve[-1] == D


def test_unstable_closed_loop_of_badly_scaled_states_is_not_marginal() -> None:
    # Found by an oracle hunt: zeros ±4, ±4j over poles -1 ... -5 in states scaled by 10^±6
    # (A from 5e-22 to 2e11). The closed loop has a real pole at +0.3683 (numpy's eigvals of
    # A - B C), so Z = 1 and N = P - Z = -1; the boundary tolerance was taken from the
    # unbalanced size of A - B C (2e11), so every closed-loop pole counted as on the axis:
    # marginal, Z = 0 and no encirclement count, silently.
    A = np.array(
        [
            [-15.000000000000002, 13099999.999999998, -225000000000.0, 1079999.9999999998,
             -1200000.0000000002],
            [1e-05, 0.0, -20000.0, 0.0, 0.0],
            [0.0, -3.333333333333333e-05, 0.0, -6.666666666666667e-06, 5.551115123125783e-22],
            [-0.0002, 0.0, 100000.0, 0.0, 0.0],
            [0.0, -6.666666666666665, 100000.0, -0.33333333333333326, 1.1102230246251565e-16],
        ]
    )  # fmt: skip
    B = np.array([[100000.0], [0.0], [0.0], [0.0], [0.0]])
    C = np.array([[1e-05, -170.66666666666663, 0.0, -8.533333333333331, -25.599999999999998]])
    expected = np.linalg.eigvals(A - B @ C)
    assert np.sum(expected.real > 0.0) == 1
    result = aerocontrol.nyquist((A, B, C, np.zeros((1, 1))))
    assert not result.marginal
    assert result.closed_loop_unstable_poles == 1
    assert result.open_loop_unstable_poles == 0
    assert result.encirclements == -1
    assert not result.closed_loop_stable


@pytest.mark.parametrize("angle", [0.0, 0.3, 0.9273, 2.0, 3.0])
@pytest.mark.parametrize("discrete", [False, True])
def test_a_double_pole_on_the_boundary_is_counted_alike_in_any_coordinates(
    angle: float, discrete: bool
) -> None:
    """1/s² (the discrete double integrator, poles at z = 1) after a lag, in states rotated by
    the angle: its poles come out ±1e-8 or so off the boundary, on a side set by the rotation.
    On the boundary to their accuracy, they are neither P nor Z, and stability_margins and
    nyquist count alike: P = 0, and N = -Z."""
    Q = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    if discrete:
        A, dt, lag = np.array([[1.0, 1.0], [0.0, 1.0]]), 0.1, [[0.5]]
    else:
        A, dt, lag = np.array([[0.0, 1.0], [0.0, 0.0]]), None, [[-10.0]]
    double = aerocontrol.StateSpace(Q @ A @ Q.T, Q @ [[0.0], [1.0]], [[1.0, 0.0]] @ Q.T, dt=dt)
    loop = aerocontrol.series(double, aerocontrol.StateSpace(lag, [[1.0]], [[2.0]], dt=dt))
    margins = aerocontrol.stability_margins(loop)
    curve = aerocontrol.nyquist(loop)
    assert margins.open_loop_unstable_poles == curve.open_loop_unstable_poles == 0
    assert margins.encirclements == curve.encirclements == -curve.closed_loop_unstable_poles
    # The closed loop: s²(s + 10) + 2 = 0, or (z - 1)²(z - 0.5) + 2 = 0 (numpy's roots).
    if discrete:
        expected = int(np.sum(np.abs(np.roots([1.0, -2.5, 2.0, 1.5])) > 1.0))
    else:
        expected = int(np.sum(np.roots([1.0, 10.0, 0.0, 2.0]).real > 0.0))
    assert expected == 2
    assert curve.closed_loop_unstable_poles == expected and not margins.closed_loop_stable


@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e6, 1e9, 1e12])
def test_an_unstable_pole_in_badly_scaled_states_is_counted(scale: float) -> None:
    """3/((s - 0.001)(s + 2)) with its second state scaled: ||A|| grows to 1e12, and a tolerance
    of √u ||A|| (1.5e4) put the pole at +0.001 on the axis: P = N = 0, silently. Counted from
    the balanced loop: P = 1, N = 1, Z = 0 at every scale (the closed loop s² + 1.999 s + 2.998
    is stable)."""
    T = np.diag([1.0, scale])
    A = T @ np.array([[0.001, 0.0], [1.0, -2.0]]) @ np.linalg.inv(T)
    loop = aerocontrol.StateSpace(A, T @ [[1.0], [0.0]], [[0.0, 3.0]] @ np.linalg.inv(T))
    curve = aerocontrol.nyquist(loop)
    margins = aerocontrol.stability_margins(loop)
    counts = (curve.open_loop_unstable_poles, curve.encirclements, curve.closed_loop_unstable_poles)
    assert counts == (1, 1, 0)
    assert (margins.open_loop_unstable_poles, margins.encirclements) == (1, 1)
    assert margins.closed_loop_stable
