"""Loop analysis against closed forms, python-control's stability_margins and disk_margins,
and numpy evaluations of the same formulas."""

from __future__ import annotations

import math
import warnings

import control
import mpmath
import numpy as np
import pytest
from scipy.optimize import minimize_scalar
from scipy.signal import cont2discrete, tf2ss

import aerocontrol
from aerocontrol import (
    InvalidArgumentError,
    ShapeError,
    SingularMatrixError,
    best_damping_gain,
    complementary_sensitivity,
    gain_for_damping,
    root_locus,
    sensitivity,
    stability_margins,
)


def _third_order(k: float) -> aerocontrol.StateSpace:
    """k/(s(s + 1)(s + 2))."""
    return aerocontrol.zpk([], [0.0, -1.0, -2.0], k)


def _numpy_response(sys: aerocontrol.StateSpace, w: np.ndarray) -> np.ndarray:
    """C (jωI - A)^-1 B + D by numpy.linalg.solve: an evaluation independent of the core."""
    n = sys.n_states
    return np.array(
        [(sys.C @ np.linalg.solve(1j * x * np.eye(n) - sys.A, sys.B) + sys.D)[0, 0] for x in w]
    )


def _yaw_loop(tau: float | None = 3.0) -> aerocontrol.StateSpace:
    """The 747 cruise yaw damper's loop: actuator, -r/rudder, washout."""
    plane = aerocontrol.aircraft.load("b747-cruise").lateral()
    parts = [aerocontrol.actuator(10.0), plane["r", "rudder"], aerocontrol.gain(-1.0)]
    if tau is not None:
        parts.append(aerocontrol.washout(tau))
    return aerocontrol.series(*parts)


# ----- closed forms ---------------------------------------------------------------------------


@pytest.mark.parametrize("k", [0.5, 2.0, 5.0, 10.0, 30.0])
def test_third_order_loop_closed_form(k: float) -> None:
    m = stability_margins(_third_order(k))
    # Phase crossover: Im of jω(jω + 1)(jω + 2) = ω(2 - ω²) = 0 at ω = √2, where L = -k/6.
    assert m.gain_margin == pytest.approx(6.0 / k, rel=1e-13)
    assert m.phase_crossover == pytest.approx(math.sqrt(2.0), rel=1e-13)
    # Gain crossover: ω²(ω² + 1)(ω² + 4) = k², a cubic in ω² (numpy.roots).
    x = np.roots([1.0, 5.0, 4.0, -(k**2)])
    w = math.sqrt(float(x[np.abs(x.imag) < 1e-12].real.max()))
    assert m.gain_crossover == pytest.approx(w, rel=1e-12)
    phase = -90.0 - math.degrees(math.atan(w) + math.atan(w / 2.0))
    assert m.phase_margin == pytest.approx(180.0 + phase, abs=1e-9)
    stable = k < 6.0  # Routh: s³ + 3s² + 2s + k
    assert m.closed_loop_stable is stable
    assert m.encirclements == (0 if stable else -2)
    if stable:
        assert m.phase_margin > 0
        assert m.delay_margin == pytest.approx(math.radians(m.phase_margin) / w, rel=1e-12)
    else:  # a negative phase margin, with its sign, and no delay or disk margin
        assert m.phase_margin < 0
        assert m.delay_margin == 0.0 and m.disk_margin == 0.0


@pytest.mark.parametrize("k", [0.1, 1.0, 50.0])
def test_pure_integrator(k: float) -> None:
    m = stability_margins(aerocontrol.tf([k], [1.0, 0.0]))
    assert m.gain_margin == math.inf and math.isnan(m.phase_crossover)
    assert m.phase_margin == pytest.approx(90.0, abs=1e-12)
    assert m.gain_crossover == pytest.approx(k, rel=1e-13)
    assert m.delay_margin == pytest.approx(math.pi / 2 / k, rel=1e-13)
    # |1 - k/jω| = |1 + k/jω|: |S - T|/2 = 1/2 at every frequency, so α = 2.
    assert m.disk_margin == pytest.approx(2.0, rel=1e-12)
    assert m.disk_gain_margin[1] == math.inf
    assert m.disk_phase_margin == pytest.approx(90.0, rel=1e-12)


def test_no_crossover_is_infinite_not_zero() -> None:
    # 0.5/(s + 1): |L| < 1 and ∠L > -90° everywhere.
    m = stability_margins(aerocontrol.tf([0.5], [1.0, 1.0]))
    assert m.gain_margin == math.inf and m.phase_margin == math.inf
    assert m.delay_margin == math.inf
    assert m.gain_margins.size == 0 and m.phase_margins.size == 0
    # α: |1 - L|/(2|1 + L|) is 1/6 at ω = 0 and rises to its supremum 1/2 as L → 0.
    assert m.disk_margin == pytest.approx(2.0, rel=1e-14) and m.disk_frequency == math.inf
    # A lag 2/(s + 1)^2 nears -180° only as ω → ∞, where |L| → 0: no phase crossover.
    lag = stability_margins(aerocontrol.zpk([], [-1.0, -1.0], 2.0))
    assert lag.gain_margin == math.inf
    assert lag.phase_margin == pytest.approx(180.0 - 2 * math.degrees(math.atan(1.0)), abs=1e-9)


def test_unstable_open_loop() -> None:
    # 2/(s - 1): closed-loop pole at -1; L(0) = -2, so GM = 1/2 at ω = 0 (a gain reduction
    # margin); |L| = 1 at ω = √3 with ∠L = -120°: PM = 60°.
    m = stability_margins(aerocontrol.tf([2.0], [1.0, -1.0]))
    assert m.open_loop_unstable_poles == 1
    assert m.closed_loop_stable and m.encirclements == 1
    np.testing.assert_allclose(m.closed_loop_poles, [-1.0], rtol=1e-14)
    assert m.gain_margin == pytest.approx(0.5, rel=1e-14) and m.phase_crossover == 0.0
    assert m.gain_margin_db == pytest.approx(-20 * math.log10(2.0), rel=1e-13)
    assert m.gain_crossover == pytest.approx(math.sqrt(3.0), rel=1e-13)
    assert m.phase_margin == pytest.approx(60.0, abs=1e-10)
    assert m.delay_margin == pytest.approx(math.pi / 3 / math.sqrt(3.0), rel=1e-12)
    # The same plant at gain 0.5: closed loop unstable, no encirclement.
    weak = stability_margins(aerocontrol.tf([0.5], [1.0, -1.0]))
    assert not weak.closed_loop_stable and weak.encirclements == 0 and weak.disk_margin == 0


def test_algebraic_loop_and_shapes_are_refused() -> None:
    with pytest.raises(SingularMatrixError, match="algebraic loop"):
        stability_margins(aerocontrol.gain(-1.0))
    lateral = aerocontrol.aircraft.load("b747-cruise").lateral()
    with pytest.raises(ShapeError, match="loop must have one input and one output"):
        stability_margins(lateral)
    with pytest.raises(ShapeError, match="loop must have one input"):
        root_locus(lateral, [1.0])


# ----- python-control -------------------------------------------------------------------------


def _control_all(sys: aerocontrol.StateSpace) -> tuple[np.ndarray, ...]:
    theirs = control.ss(sys.A, sys.B, sys.C, sys.D, sys.dt or 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return control.stability_margins(theirs, returnall=True)


@pytest.mark.parametrize(
    "loop",
    [
        _third_order(2.0),
        aerocontrol.zpk([-0.5], [0.0, -5.0, -0.2 + 2j, -0.2 - 2j], 8.0),
        aerocontrol.series(_yaw_loop(3.0), aerocontrol.gain(2.5)),
        aerocontrol.series(_yaw_loop(None), aerocontrol.gain(2.5)),
        aerocontrol.series(_yaw_loop(1.0), aerocontrol.gain(8.0)),
    ],
    ids=["third-order", "resonant", "yaw-washout-3s", "yaw-no-washout", "yaw-washout-1s"],
)
def test_every_crossover_against_python_control(loop: aerocontrol.StateSpace) -> None:
    m = stability_margins(loop)
    gm, pm, _, w180, wc, _ = _control_all(loop)
    # python-control counts ω = 0 as a phase crossover where a washout makes L(0) = 0 (its
    # "gain margin" there is inf): not a crossing of the negative real axis, so not ours.
    real = np.asarray(gm) < 1e10
    w180, gm = np.asarray(w180)[real], np.asarray(gm)[real]
    # python-control's polynomial crossings (ss2tf, then roots): agree to 1e-7.
    order = np.argsort(w180)
    np.testing.assert_allclose(m.phase_crossovers, np.asarray(w180)[order], rtol=1e-7)
    np.testing.assert_allclose(m.gain_margins, np.asarray(gm)[order], rtol=1e-7)
    order = np.argsort(wc)
    np.testing.assert_allclose(m.gain_crossovers, np.asarray(wc)[order], rtol=1e-7)
    np.testing.assert_allclose(m.phase_margins, np.asarray(pm)[order], atol=1e-6)


def test_discrete_loop_against_python_control() -> None:
    loop = aerocontrol.c2d(_third_order(2.0), 0.1)
    m = stability_margins(loop)
    gm, pm, _, w180, wc, _ = _control_all(loop)
    np.testing.assert_allclose(m.gain_margins, gm, rtol=1e-7)
    np.testing.assert_allclose(m.phase_crossovers, w180, rtol=1e-7)
    np.testing.assert_allclose(m.phase_margins, pm, atol=1e-6)
    np.testing.assert_allclose(m.gain_crossovers, wc, rtol=1e-7)
    assert m.closed_loop_stable


@pytest.mark.parametrize(
    "loop", [_third_order(2.0), aerocontrol.series(_yaw_loop(3.0), aerocontrol.gain(2.5))]
)
def test_disk_margin_against_python_control(loop: aerocontrol.StateSpace) -> None:
    m = stability_margins(loop)
    theirs = control.ss(loop.A, loop.B, loop.C, loop.D)
    w = np.logspace(-4, 3, 20001)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alpha = control.disk_margins(theirs, w, skew=0.0, returnall=False)[0]
    # python-control's value is on its grid: ours is the refined maximum, never below it.
    assert m.disk_margin == pytest.approx(float(alpha), rel=1e-5)
    assert m.disk_margin <= float(alpha) * (1 + 1e-12)

    # The refined peak against scipy's bounded search on a numpy evaluation.
    def peak(x: float) -> float:
        value = _numpy_response(loop, np.array([x]))[0]
        return -abs(1 - value) / (2 * abs(1 + value))

    best = minimize_scalar(
        peak,
        bounds=(m.disk_frequency * 0.8, m.disk_frequency * 1.25),
        method="bounded",
        options={"xatol": 1e-12},
    )
    assert m.disk_margin == pytest.approx(-1.0 / best.fun, rel=1e-9)


# ----- MIMO disk margins --------------------------------------------------------------------


def _matrix_response(sys: aerocontrol.StateSpace, w: float) -> np.ndarray:
    """L(jω) (L(e^{jω dt}) for a discrete loop) by numpy.linalg.solve, independent of the core."""
    point = np.exp(1j * w * sys.dt) if sys.dt else 1j * w
    n = sys.n_states
    return sys.C @ np.linalg.solve(point * np.eye(n) - sys.A, sys.B) + sys.D


def _satellite(a: float = 10.0) -> aerocontrol.StateSpace:
    """The spinning satellite (Doyle; Seiler, Packard and Gahinet 2020), K = I:
    P = [[s - a², a(s + 1)], [-a(s + 1), s - a²]]/(s² + a²)."""
    return aerocontrol.StateSpace([[0.0, a], [-a, 0.0]], np.eye(2), [[1.0, a], [-a, 1.0]])


def _stable_random_loop(
    n: int, p: int, seed: int, dt: float | None = None
) -> aerocontrol.StateSpace:
    """A seeded random loop (n states, p x p, D small) whose closed loop I + L is stable,
    checked by numpy's eigenvalues of A - B (I + D)^-1 C."""
    rng = np.random.default_rng(seed)
    while True:
        A = rng.standard_normal((n, n))
        if dt:
            A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
        else:
            A -= (np.max(np.linalg.eigvals(A).real) + 0.5) * np.eye(n)
        B, C = rng.standard_normal((n, p)), rng.standard_normal((p, n))
        D = 0.1 * rng.standard_normal((p, p))
        poles = np.linalg.eigvals(A - B @ np.linalg.solve(np.eye(p) + D, C))
        if (np.max(np.abs(poles)) < 1.0) if dt else (np.max(poles.real) < 0.0):
            return aerocontrol.StateSpace(A, B, C, D, dt=dt)


def _mu_by_slycot(M: np.ndarray) -> float:
    """AB13MD's upper bound of μ for p complex scalar blocks (python-control's oracle)."""
    from slycot import ab13md

    p = M.shape[0]
    return float(ab13md(M.astype(complex), np.ones(p, int), 2 * np.ones(p, int))[0])


def _balanced_delta(f: np.ndarray, skew: float) -> np.ndarray:
    """δ of f = (1 + (1 - σ)δ/2)/(1 - (1 + σ)δ/2), inverted:
    δ = (f - 1)/((1 - σ)/2 + (1 + σ) f/2)."""
    return (f - 1.0) / (0.5 * (1.0 - skew) + 0.5 * (1.0 + skew) * f)


def _check_certificate(
    loop: aerocontrol.StateSpace, m: aerocontrol.DiskMargins, tol: float = 1e-10
) -> None:
    """The worst perturbation makes I + L(jω) F singular (numpy's L) and lies on the
    boundary of D(α_upper, σ)."""
    L = _matrix_response(loop, m.worst_frequency)
    F = np.diag(m.worst_perturbation)
    smallest = np.linalg.svd(np.eye(L.shape[0]) + L @ F, compute_uv=False)[-1]
    assert smallest <= tol * (1.0 + np.linalg.norm(L, 2) * np.linalg.norm(F, 2))
    sizes = np.abs(_balanced_delta(m.worst_perturbation, m.skew))
    np.testing.assert_allclose(sizes, m.multiloop_bounds[1], rtol=1e-9)


def test_disk_margins_of_one_loop_are_its_stability_margins() -> None:
    # p = 1: the multiloop margin is the loop's disk margin (the Hamiltonian L∞ norm of
    # stability_margins), bit for bit, and python-control's on a dense grid within 1e-5.
    for loop in [_third_order(2.0), aerocontrol.series(_yaw_loop(3.0), aerocontrol.gain(2.5))]:
        m = aerocontrol.disk_margins(loop)
        siso = stability_margins(loop)
        assert m.multiloop.alpha == m.loop_at_a_time[0].alpha == siso.disk_margin
        assert m.multiloop.frequency == siso.disk_frequency
        assert m.multiloop_bounds == (siso.disk_margin, siso.disk_margin)
        assert m.multiloop.gain_margin == siso.disk_gain_margin
        assert m.multiloop.phase_margin == siso.disk_phase_margin
        _check_certificate(loop, m)
        w = np.logspace(-4, 3, 20001)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            alpha = control.disk_margins(control.ss(loop.A, loop.B, loop.C, loop.D), w)[0]
        assert m.multiloop.alpha == pytest.approx(float(alpha), rel=1e-5)
        # The arrays are |S - 1/2| on the grid: never above the refined peak.
        assert np.max(m.mu_upper) <= (1 + 1e-12) / m.multiloop.alpha


def test_discrete_disk_margin_is_refined_beside_conjugate_roots() -> None:
    # Regression: the grid's clusters about a conjugate pair of roots held near twins (ln z̄
    # is not exactly the conjugate of ln z), and a grid maximum beside its twin left a zoom
    # bracket of zero width, so no refinement: this discrete loop's disk margin came out
    # 1.3e-4 too large (0.219583 at the grid point 23.4601 rad/s, for 0.219555 at 23.479).
    dt = 0.05
    others = aerocontrol.gain(np.diag([0.0, 1.0, 1.0]), dt=dt)
    loop = aerocontrol.feedback(_stable_random_loop(5, 3, 6, dt), others)[0, 0]
    m = stability_margins(loop)

    def peak(x: float) -> float:
        value = _matrix_response(loop, x)[0, 0]
        return -abs(1 - value) / (2 * abs(1 + value))

    best = minimize_scalar(
        peak,
        bounds=(m.disk_frequency * 0.98, m.disk_frequency * 1.02),
        method="bounded",
        options={"xatol": 1e-12},
    )
    assert m.disk_margin == pytest.approx(-1.0 / best.fun, rel=1e-9)


def test_spinning_satellite_closed_form() -> None:
    # Loop at a time each broken loop is 1/s (α = 2, gain margin ∞, phase margin 90°), but
    # S - I/2 = [[s - 1, -2a], [2a, s - 1]]/(2(s + 1)) is normal, so μ = σ̄ = ρ and the
    # multiloop α = 2 √((1 + ω²)/(1 + (ω + 2a)²)), least at ω = √(a² + 1) - a.
    a = 10.0
    loop = _satellite(a)
    m = aerocontrol.disk_margins(loop)
    w = math.sqrt(a * a + 1.0) - a
    alpha = 2.0 * math.sqrt((1.0 + w * w) / (1.0 + (w + 2.0 * a) ** 2))
    assert m.closed_loop_stable
    np.testing.assert_allclose(m.closed_loop_poles, [-1.0, -1.0], atol=1e-12)
    for single, classical in zip(m.loop_at_a_time, m.loops, strict=True):
        assert single.alpha == pytest.approx(2.0, rel=1e-12)
        assert single.gain_margin == (0.0, math.inf)
        assert classical.gain_margin == math.inf
        assert classical.phase_margin == pytest.approx(90.0, abs=1e-9)
    assert m.multiloop.alpha == pytest.approx(alpha, rel=1e-12)
    assert m.multiloop_bounds[1] == pytest.approx(alpha, rel=1e-12)
    # A flat maximum: its place is known to about the square root of its value's accuracy.
    assert m.multiloop.frequency == pytest.approx(w, rel=1e-4)
    low, high = m.multiloop.gain_margin
    assert low == pytest.approx((2 - alpha) / (2 + alpha), rel=1e-12)
    assert high == pytest.approx((2 + alpha) / (2 - alpha), rel=1e-12)
    assert m.multiloop.phase_margin == pytest.approx(math.degrees(2 * math.atan(alpha / 2)))
    assert m.multiloop.phase_margin == pytest.approx(5.711, abs=5e-4)
    _check_certificate(loop, m)
    # python-control (AB13MD's bound of μ) on a grid through the peak.
    grid = np.unique(np.concatenate([np.logspace(-3, 3, 400), [w]]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = control.disk_margins(control.ss(loop.A, loop.B, loop.C, loop.D), grid)[0]
    assert m.multiloop.alpha == pytest.approx(float(theirs), rel=1e-9)


def test_mathworks_output_loop_example() -> None:
    # MathWorks' diskmargin page: Lo = P C with the satellite P and C = [[1, -2], [0, 1]]. Its
    # loop-at-a-time margins are 2 (printed), and its multiloop margin is printed as 0.3754
    # with bounds [0.3754, 0.3762] at ω = 0. For two loops μ equals its D-scaled bound, and
    # both are 0.376152 here: the peak is at ω = 0, where M = S(0) - I/2 is real and μ the
    # maximum over θ of ρ(M diag(1, e^{jθ})) (scipy's bounded search), and AB13MD agrees.
    loop = aerocontrol.series(aerocontrol.gain([[1.0, -2.0], [0.0, 1.0]]), _satellite())
    m = aerocontrol.disk_margins(loop)
    assert [d.alpha for d in m.loop_at_a_time] == pytest.approx([2.0, 2.0], rel=1e-12)
    M = np.linalg.inv(np.eye(2) + _matrix_response(loop, 0.0)) - 0.5 * np.eye(2)

    def minus_rho(theta: float) -> float:
        return -float(np.max(np.abs(np.linalg.eigvals(M @ np.diag([1.0, np.exp(1j * theta)])))))

    best = min(
        (
            minimize_scalar(
                minus_rho, bounds=(c - 0.5, c + 0.5), method="bounded", options={"xatol": 1e-12}
            )
            for c in np.linspace(0.0, 2.0 * math.pi, 13)
        ),
        key=lambda r: r.fun,
    )
    assert m.multiloop.frequency == 0.0
    assert m.multiloop.alpha == pytest.approx(-1.0 / best.fun, rel=1e-10)
    assert m.multiloop.alpha == pytest.approx(1.0 / _mu_by_slycot(M), rel=1e-10)
    assert 0.3754 <= m.multiloop.alpha <= 0.3762
    assert m.multiloop_bounds[1] == pytest.approx(m.multiloop.alpha, rel=1e-12)
    _check_certificate(loop, m)


@pytest.mark.parametrize(
    ("skew", "printed"),
    [(-2.0, (0.4013, 1.3745)), (0.0, (0.6273, 1.5942)), (2.0, (0.7717, 1.7247))],
)
def test_skewed_disk_margins_against_mathworks(skew: float, printed: tuple[float, float]) -> None:
    # MathWorks' diskmargin page, L = 25/(s³ + 10s² + 10s + 10): the disk-based gain margins
    # printed for σ = -2, 0, 2 (four digits).
    loop = aerocontrol.tf([25.0], [1.0, 10.0, 10.0, 10.0])
    m = aerocontrol.disk_margins(loop, skew=skew)
    np.testing.assert_allclose(m.multiloop.gain_margin, printed, atol=6e-5)
    # The phase margin against python-control's formula from the real intercepts:
    # cos φ = (1 + γmin γmax)/(γmin + γmax).
    low, high = m.multiloop.gain_margin
    assert m.multiloop.phase_margin == pytest.approx(
        math.degrees(math.acos((1 + low * high) / (low + high))), rel=1e-10
    )
    # α against python-control's grid; ours is the refined peak, never above it.
    w = np.logspace(-2, 2, 20001)
    theirs = control.ss(loop.A, loop.B, loop.C, loop.D)
    alpha = float(control.disk_margins(theirs, w, skew=skew)[0])
    assert m.multiloop.alpha == pytest.approx(alpha, rel=1e-6)
    assert m.multiloop.alpha <= alpha * (1 + 1e-12)
    _check_certificate(loop, m)


def test_skews_one_and_minus_one_are_the_sensitivity_peaks() -> None:
    # σ = 1: D(α, 1) = {1/(1 - δ)} and α = 1/||S||∞, the stability margin min|1 + L| of
    # stability_margins (the core's L∞ iteration); σ = -1: α = 1/||T||∞, against scipy's
    # bounded search on a numpy evaluation of L/(1 + L). (The zoom once stopped a step short
    # of the peak: 1/||S||∞ came out 1.8e-10 too large.)
    loop = _third_order(2.0)
    sensitive = aerocontrol.disk_margins(loop, skew=1.0)
    assert sensitive.multiloop.alpha == pytest.approx(
        stability_margins(loop).stability_margin, rel=1e-12
    )
    complementary = aerocontrol.disk_margins(loop, skew=-1.0)
    w = complementary.multiloop.frequency

    def minus_t(x: float) -> float:
        value = _numpy_response(loop, np.array([x]))[0]
        return -abs(value / (1 + value))

    best = minimize_scalar(
        minus_t, bounds=(0.9 * w, 1.1 * w), method="bounded", options={"xatol": 1e-12}
    )
    assert complementary.multiloop.alpha == pytest.approx(-1.0 / best.fun, rel=1e-12)


@pytest.mark.parametrize("skew", [-3.0, -1.0, -0.5, 0.0, 0.7, 1.0, 2.5])
@pytest.mark.parametrize("alpha", [1e-4, 0.3, 1.0, 1.9, 2.0, 3.0])
def test_disk_gain_and_phase_margins_lie_on_the_disk(alpha: float, skew: float) -> None:
    # The disk D(α, σ) = {f : |δ(f)| < α}, δ(f) = (f - 1)/((1 - σ)/2 + (1 + σ) f/2): finite
    # gain margins are on its boundary and the gains between them inside; the phase margin
    # e^{jφ} is on the boundary unless the disk holds the whole unit circle (φ = 180°).
    disk = aerocontrol.DiskMargin(alpha, skew, 1.0)
    low, high = disk.gain_margin
    assert 0.0 <= low <= 1.0 <= high
    for end in (low, high):
        if 0.0 < end < math.inf:
            assert abs(_balanced_delta(np.array(end), skew)) == pytest.approx(alpha, rel=1e-9)
    inside = np.linspace(low, min(high, 1e6), 1001)[1:-1]
    assert np.all(np.abs(_balanced_delta(inside, skew)) < alpha * (1 + 1e-12))
    if high == math.inf:  # every large gain is inside
        assert abs(_balanced_delta(np.array(1e12), skew)) < alpha
    phase = disk.phase_margin
    arc = np.exp(1j * np.radians(np.linspace(0.0, phase, 1001)[:-1]))
    assert np.all(np.abs(_balanced_delta(arc, skew)) < alpha * (1 + 1e-12))
    if phase < 180.0:
        edge = np.exp(1j * math.radians(phase))
        assert abs(_balanced_delta(edge, skew)) == pytest.approx(alpha, rel=1e-9)
    if skew == 0.0:
        assert phase == pytest.approx(math.degrees(2 * math.atan(alpha / 2)), rel=1e-14)


def test_diagonal_loop_multiloop_margin_is_the_least_loop_margin() -> None:
    # Decoupled loops: S is diagonal, μ of a diagonal matrix is its largest entry, so the
    # multiloop margin is the least loop-at-a-time margin, at that loop's frequency.
    parts = [
        _third_order(2.0),
        aerocontrol.zpk([-2.0], [-0.1 + 1j, -0.1 - 1j, -20.0], 20.0),
        aerocontrol.tf([4.0], [1.0, 3.0, 1.0]),
    ]
    m = aerocontrol.disk_margins(aerocontrol.append(*parts))
    singles = [stability_margins(part) for part in parts]
    # Each L_i is L_ii with the other loops' states (unobservable): its margin to rounding.
    for single, siso in zip(m.loop_at_a_time, singles, strict=True):
        assert single.alpha == pytest.approx(siso.disk_margin, rel=1e-12)
        assert single.frequency == pytest.approx(siso.disk_frequency, rel=1e-6)  # flat peak
    least = min(range(3), key=lambda i: singles[i].disk_margin)
    assert m.multiloop.alpha == pytest.approx(singles[least].disk_margin, rel=1e-12)
    assert m.multiloop_bounds[1] == pytest.approx(singles[least].disk_margin, rel=1e-12)
    assert m.multiloop.frequency == pytest.approx(singles[least].disk_frequency, rel=1e-6)
    _check_certificate(aerocontrol.append(*parts), m)


@pytest.mark.parametrize(
    ("n", "p", "seed", "dt"),
    [(4, 2, 1, None), (5, 3, 2, None), (6, 3, 3, None), (4, 2, 5, 0.1), (5, 3, 6, 0.05)],
)
def test_random_loops_against_python_control(n: int, p: int, seed: int, dt: float | None) -> None:
    loop = _stable_random_loop(n, p, seed, dt)
    m = aerocontrol.disk_margins(loop)
    assert m.closed_loop_stable
    # p <= 3: μ is its D-scaled bound, so the bounds meet (the lower bound's power method
    # reaches it) and no gap is reported.
    assert m.multiloop_bounds[1] == pytest.approx(m.multiloop_bounds[0], rel=1e-10)
    _check_certificate(loop, m, tol=1e-9)
    # python-control (AB13MD at each frequency) on a grid through our peak: the same margin,
    # and ours restricted to that grid agrees at every point.
    nyquist = math.pi / dt if dt else 1e3
    grid = np.unique(
        np.concatenate([np.logspace(-3, math.log10(nyquist), 300), [m.multiloop.frequency]])
    )
    theirs = control.ss(loop.A, loop.B, loop.C, loop.D, dt if dt else 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alphas = control.disk_margins(theirs, grid, returnall=True)[0]
    assert m.multiloop.alpha == pytest.approx(float(alphas.min()), rel=1e-9)
    # At every frequency our lower bound is at most AB13MD's upper bound, and our upper bound
    # at least it (for p <= 3 both it and ours are μ where the scaling is optimised: off the
    # peak only Osborne's scaling is, by design); where our bounds meet, they are AB13MD's.
    on_grid = aerocontrol.disk_margins(loop, omega=grid)
    theirs_mu = 1.0 / alphas
    assert np.all(on_grid.mu_lower <= theirs_mu * (1 + 1e-9))
    assert np.all(on_grid.mu_upper >= theirs_mu * (1 - 1e-9))
    met = on_grid.mu_upper <= on_grid.mu_lower * (1 + 1e-10)
    assert met[np.argmax(on_grid.mu_upper)]
    np.testing.assert_allclose(on_grid.mu_upper[met], theirs_mu[met], rtol=1e-9)
    assert on_grid.multiloop.alpha == pytest.approx(float(alphas.min()), rel=1e-9)
    # Loop at a time against python-control's own interconnection: loop i broken with the
    # others closed, then its disk margin on a dense grid through our peak; a peak as ω → ∞
    # (beyond any grid) against |S_ii - 1/2| of S(∞) = (I + D)^-1.
    for i, single in enumerate(m.loop_at_a_time):
        others = np.eye(p)
        others[i, i] = 0.0
        broken = control.feedback(theirs, others)[i, i]
        peak = [single.frequency] if math.isfinite(single.frequency) else []
        dense = np.unique(np.concatenate([np.logspace(-3, math.log10(nyquist), 2000), peak]))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            alpha_i = float(control.disk_margins(broken, dense)[0])
        if math.isfinite(single.frequency):
            assert single.alpha == pytest.approx(alpha_i, rel=1e-9)
        else:
            at_infinity = abs(np.linalg.inv(np.eye(p) + loop.D)[i, i] - 0.5)
            assert single.alpha == pytest.approx(1.0 / at_infinity, rel=1e-12)
            assert single.alpha <= alpha_i * (1 + 1e-12)
        assert m.multiloop.alpha <= single.alpha * (1 + 1e-12)


def test_two_and_three_loops_upper_bound_is_the_optimal_scaling() -> None:
    # At the peak, μ's upper bound against an independent minimisation of σ̄(D M D^-1) over
    # D = diag(e^x, 1) (p = 2, scipy's bounded search) and AB13MD (p = 3).
    for p, seed in [(2, 1), (3, 2)]:
        loop = _stable_random_loop(4 + p, p, seed)
        m = aerocontrol.disk_margins(loop)
        L = _matrix_response(loop, m.multiloop.frequency)
        M = np.linalg.inv(np.eye(p) + L) - 0.5 * np.eye(p)
        peak = 1.0 / m.multiloop.alpha
        if p == 2:

            def scaled_norm(x: float, M: np.ndarray = M) -> float:
                D = np.diag([math.exp(x), 1.0])
                return float(np.linalg.norm(D @ M @ np.linalg.inv(D), 2))

            best = minimize_scalar(
                scaled_norm, bounds=(-20.0, 20.0), method="bounded", options={"xatol": 1e-12}
            )
            assert peak == pytest.approx(best.fun, rel=1e-9)
        assert peak == pytest.approx(_mu_by_slycot(M), rel=1e-9)
        # Two and three scalar blocks: the bounds meet at every frequency whose upper bound
        # could set the peak (above the largest lower bound); elsewhere the scaling is
        # Osborne's, which is still an upper bound, below that level.
        settles = m.mu_upper > np.max(m.mu_lower) * (1 + 1e-10)
        met = m.mu_upper <= m.mu_lower * (1 + 1e-9)
        assert np.all(met | ~settles)


def test_unstable_closed_loop_has_no_disk_margins() -> None:
    # The satellite with K = 0.05 I: A - 0.05 C has eigenvalues -0.05 ± j√(100 - 0.25·...)...
    # any K = k I with k < 0 destabilises; numpy's closed-loop eigenvalues are the oracle.
    loop = aerocontrol.series(aerocontrol.gain(-0.5 * np.eye(2)), _satellite())
    poles = np.linalg.eigvals(loop.A - loop.B @ np.linalg.solve(np.eye(2) + loop.D, loop.C))
    assert np.max(poles.real) > 0
    m = aerocontrol.disk_margins(loop)
    assert not m.closed_loop_stable
    np.testing.assert_allclose(np.sort_complex(m.closed_loop_poles), np.sort_complex(poles))
    assert all(d.alpha == 0.0 and math.isnan(d.frequency) for d in m.loop_at_a_time)
    assert m.multiloop.alpha == 0.0 and m.multiloop_bounds == (0.0, 0.0)
    assert m.multiloop.gain_margin == (1.0, 1.0) and m.multiloop.phase_margin == 0.0
    assert all(classical.disk_margin == 0.0 for classical in m.loops)
    assert m.frequencies.size == 0 and np.all(m.worst_perturbation == 1.0)
    assert "UNSTABLE" in str(m)


def _gap_loop(M0: np.ndarray, w0: float = 2.0, zeta: float = 0.01) -> aerocontrol.StateSpace:
    """A loop whose S - I/2 is N(s) = (X s + Y)/(s² + 2ζω0 s + ω0²) with N(jω0) = M0:
    S = I/2 + N, L = S^-1 - I (state-space inverse), closed loop the stable N."""
    p = M0.shape[0]
    X, Y = 2 * zeta * w0 * M0.real, -2 * zeta * w0**2 * M0.imag
    I, Z = np.eye(p), np.zeros((p, p))
    A = np.block([[Z, I], [-(w0**2) * I, -2 * zeta * w0 * I]])
    B, C = np.vstack([Z, I]), np.hstack([Y, X])
    return aerocontrol.StateSpace(A - 2 * B @ C, 2 * B, -2 * C, I)


def test_four_loops_with_a_gap_between_the_bounds_warn() -> None:
    # A complex 4 x 4 matrix whose μ is strictly below its D-scaled bound (a search over
    # integer matrices): AB13MD's bound 8.14329, and a dense search of ρ(M0 U) over diagonal
    # unitary U (36³ grid, then Nelder-Mead) finds no more than 7.69528. Put at the peak of
    # a lightly damped loop, the multiloop margin is known within that 5.5% gap: a warning,
    # the lower end returned, and the certificate at the upper end.
    M0 = np.array(
        [
            [-2 + 1j, 3 - 1j, 3 + 3j, -2 + 3j],
            [-2 - 1j, 3 + 1j, -2 + 0j, 3 - 2j],
            [3 + 0j, -1 + 1j, -2 + 1j, -3 - 2j],
            [0 - 3j, -2 + 3j, 0 - 3j, 0 + 1j],
        ]
    )
    loop = _gap_loop(M0)
    with pytest.warns(aerocontrol.LooseBoundWarning, match="known only within"):
        m = aerocontrol.disk_margins(loop)
    low, high = m.multiloop_bounds
    assert (high - low) / high > 0.05
    L = _matrix_response(loop, m.multiloop.frequency)
    M = np.linalg.inv(np.eye(4) + L) - 0.5 * np.eye(4)
    assert 1.0 / low == pytest.approx(_mu_by_slycot(M), rel=1e-6)
    assert 1.0 / low >= _mu_by_slycot(M) * (1 - 1e-6)
    assert 1.0 / high == pytest.approx(7.69527538, rel=1e-3)
    _check_certificate(loop, m, tol=1e-9)


def test_disk_margins_refuse_bad_arguments_by_name() -> None:
    satellite = _satellite()
    with pytest.raises(ShapeError, match="loop must be square"):
        aerocontrol.disk_margins(satellite[:, 0])
    with pytest.raises(aerocontrol.NonFiniteError, match="skew"):
        aerocontrol.disk_margins(satellite, skew=math.nan)
    with pytest.raises(aerocontrol.NotRealError, match="skew"):
        aerocontrol.disk_margins(satellite, skew=1j)  # type: ignore[arg-type]
    with pytest.raises(aerocontrol.NonFiniteError, match="omega"):
        aerocontrol.disk_margins(satellite, omega=[1.0, math.inf])
    with pytest.raises(InvalidArgumentError, match="omega must be non-negative"):
        aerocontrol.disk_margins(satellite, omega=[1.0, -2.0])
    with pytest.raises(ShapeError, match="omega"):
        aerocontrol.disk_margins(satellite, omega=np.ones((2, 2)))
    with pytest.raises(ShapeError, match="omega"):
        aerocontrol.disk_margins(satellite, omega=[])
    discrete = _stable_random_loop(3, 2, 5, 0.1)
    with pytest.raises(InvalidArgumentError, match="Nyquist"):
        aerocontrol.disk_margins(discrete, omega=[1.0, 40.0])
    # I + D singular: closing the loops is an algebraic loop.
    algebraic = aerocontrol.StateSpace(-np.eye(2), np.eye(2), np.eye(2), [[-1.0, 0.0], [0.0, 0.5]])
    with pytest.raises(SingularMatrixError):
        aerocontrol.disk_margins(algebraic)


def test_disk_margins_leave_inputs_alone_and_ignore_layout() -> None:
    loop = _stable_random_loop(5, 3, 2)
    matrices = [np.asfortranarray(m) for m in (loop.A, loop.B, loop.C, loop.D)]
    copies = [m.copy() for m in matrices]
    omega = np.logspace(-2, 2, 50)[::2]  # a strided view
    omega_copy = omega.copy()
    fortran = aerocontrol.disk_margins(tuple(matrices), omega=omega)
    plain = aerocontrol.disk_margins(loop, omega=omega_copy)
    for given, copy in zip(matrices, copies, strict=True):
        np.testing.assert_array_equal(given, copy)
    np.testing.assert_array_equal(omega, omega_copy)
    assert fortran.multiloop_bounds == plain.multiloop_bounds
    np.testing.assert_array_equal(fortran.mu_upper, plain.mu_upper)
    fortran.frequencies[0] = -1.0  # the result's own arrays
    np.testing.assert_array_equal(omega, omega_copy)


def test_unit_feedthrough_and_even_loops() -> None:
    # d² = 1 (the Hamiltonian does not exist; the core takes the pencil of 1 - L(-s)L(s)):
    # L = (s² + 0.5 s + 2)/(s² + 1.5 s + 1), |num|² - |den|² = 3 - 4ω²: a crossover at √3/2.
    loop = aerocontrol.tf([1.0, 0.5, 2.0], [1.0, 1.5, 1.0])
    m = stability_margins(loop)
    np.testing.assert_allclose(m.gain_crossovers, [math.sqrt(0.75)], rtol=1e-13)
    L = _numpy_response(loop, m.gain_crossovers)
    np.testing.assert_allclose(np.abs(L), 1.0, rtol=1e-13)
    # An even loop, real on the whole axis (L(s) - L(-s) ≡ 0: the grid method decides):
    # L = -2/(s² - 1), L(jω) = 2/(ω² + 1) > 0: no phase crossover, |L| = 1 at ω = 1 with
    # ∠L = 0 (PM = 180°); the closed loop s² - 1 - 2 = 0 has a pole at +√3.
    even = stability_margins(aerocontrol.tf([-2.0], [1.0, 0.0, -1.0]))
    assert even.gain_margin == math.inf
    np.testing.assert_allclose(even.gain_crossovers, [1.0], rtol=1e-9)
    assert even.phase_margin == pytest.approx(180.0, abs=1e-9)
    assert not even.closed_loop_stable


def test_eigenvalues_of_a_stack_match_one_by_one() -> None:
    rng = np.random.default_rng(25)
    stack = rng.standard_normal((40, 5, 5))
    together = aerocontrol._core.eigenvalues(stack)
    assert together.shape == (40, 5)
    for matrix, values in zip(stack, together, strict=True):
        np.testing.assert_array_equal(values, aerocontrol._core.eigenvalues(matrix))
        np.testing.assert_allclose(
            np.sort_complex(values), np.sort_complex(np.linalg.eigvals(matrix)), rtol=1e-10
        )
    assert aerocontrol._core.eigenvalues(np.zeros((3, 0, 0))).shape == (3, 0)
    with pytest.raises(ShapeError):
        aerocontrol._core.eigenvalues(np.zeros((2, 3, 4)))
    with pytest.raises(aerocontrol.NonFiniteError):
        aerocontrol._core.eigenvalues(np.full((2, 3, 3), np.nan))


def test_sensitivities_against_numpy() -> None:
    loop = _third_order(2.0)
    w = np.logspace(-2, 2, 30)
    L = _numpy_response(loop, w)
    S = aerocontrol.frequency_response(sensitivity(loop), w).response[:, 0, 0]
    T = aerocontrol.frequency_response(complementary_sensitivity(loop), w).response[:, 0, 0]
    np.testing.assert_allclose(S, 1 / (1 + L), rtol=1e-12)
    np.testing.assert_allclose(T, L / (1 + L), rtol=1e-12)
    np.testing.assert_allclose(S + T, 1.0, rtol=1e-12)


# ----- root locus -----------------------------------------------------------------------------


def test_root_locus_closed_form_and_numpy() -> None:
    loop = aerocontrol.zpk([], [0.0, -2.0], 1.0)  # k/(s(s + 2)): -1 ± j√(k - 1)
    gains = np.array([0.0, 0.5, 1.0, 2.0, 10.0])
    locus = root_locus(loop, gains)
    for k, poles in zip(gains, locus.poles, strict=True):
        expected = np.roots([1.0, 2.0, k])
        np.testing.assert_allclose(np.sort_complex(poles), np.sort_complex(expected), atol=1e-7)
    yaw = _yaw_loop(3.0)
    k = np.linspace(0, 5, 7)
    locus = root_locus(yaw, k)
    for value, poles in zip(k, locus.poles, strict=True):
        A = yaw.A - value * yaw.B @ yaw.C / (1 + value * yaw.D[0, 0])
        np.testing.assert_allclose(
            np.sort_complex(poles), np.sort_complex(np.linalg.eigvals(A)), rtol=1e-10, atol=1e-12
        )


def test_root_locus_dense_gains_against_numpy() -> None:
    """1000 gains: most are taken by the core's continuation (Aberth's iteration from the
    previous gain), the rest by the QR iteration; every gain's poles as numpy's eigenvalues of
    the closed loop, through the breakaway points of the 747 yaw damper's locus and of
    k (s + 1)/(s (s + 2)(s + 4)) with negative gains too."""
    cases = [
        (_yaw_loop(3.0), np.linspace(0.0, 5.0, 1000)),
        (aerocontrol.zpk([-1.0], [0.0, -2.0, -4.0], 1.0), np.linspace(-10.0, 40.0, 1000)),
        (
            aerocontrol.zpk([-3.0, -0.5 + 2j, -0.5 - 2j], [-1.0, -1.0, -5.0, 1.0], 2.0),
            np.logspace(-3.0, 3.0, 1000),
        ),
    ]
    for loop, gains in cases:
        locus = root_locus(loop, gains)
        for value, poles in zip(gains, locus.poles, strict=True):
            A = loop.A - value * loop.B @ loop.C / (1 + value * loop.D[0, 0])
            expected = np.sort_complex(np.linalg.eigvals(A))
            # Near a breakaway point (a double pole) either method is accurate to about
            # sqrt(u) of the closed loop's size.
            tolerance = 2e-7 * max(1.0, float(np.abs(expected).max()))
            np.testing.assert_allclose(poles, expected, rtol=0, atol=tolerance)
        # Real poles exactly real, complex ones in exact conjugate pairs.
        for poles in locus.poles:
            upper = np.sort_complex(poles[poles.imag > 0])
            lower = np.sort_complex(np.conj(poles[poles.imag < 0]))
            np.testing.assert_array_equal(upper, lower)


def test_gain_for_damping_closed_forms() -> None:
    design = gain_for_damping(aerocontrol.zpk([], [0.0, -2.0], 1.0), 0.5)
    assert design.gain == pytest.approx(4.0, rel=1e-10)  # ζ = 1/√k
    # Rate feedback k s/(s² + 2ζ0 ω s + ω²): ζ = ζ0 + k/(2ω), for the tracked mode.
    omega, zeta0 = 2.0, 0.05
    pole = complex(-zeta0 * omega, omega * math.sqrt(1 - zeta0**2))
    loop = aerocontrol.tf([1.0, 0.0], [1.0, 2 * zeta0 * omega, omega**2])
    design = gain_for_damping(loop, 0.4, mode=pole)
    assert design.gain == pytest.approx(2 * omega * (0.4 - zeta0), rel=1e-10)
    assert design.damping_ratio == pytest.approx(0.4, abs=1e-12)
    with pytest.raises(InvalidArgumentError, match="zeta must lie in"):
        gain_for_damping(loop, 1.5)
    with pytest.raises(InvalidArgumentError, match="not reached"):
        gain_for_damping(loop, 0.9, mode=pole, gains=[0.0, 0.1, 0.2])  # ζ at most 0.1


@pytest.mark.parametrize("dt", [1e13, 1e100, 1e-13])
def test_margins_of_a_discrete_loop_sampled_every_1e13_seconds(dt: float) -> None:
    """Found by a hostile-input hunt: the default grid of a discrete loop counted every root
    ln(z)/dt below 1e-12 rad/s as at the origin (a threshold in rad/s), so for dt of 1e13 s
    the grid spanned only θ = ω dt of 0.314 to π: the gain crossover at θ = 0.0625 was missed
    (phase margin ∞, silently), the stability margin 0.95 for 0.534 and disk_margins raised.

    2/(s (s + 1)) held at 0.05 (the matrices of scipy's cont2discrete) with its period
    changed: margins are the same in θ. Oracle: python-control's stability_margins of the loop
    at dt = 1 (GM 20.16806, PM 36.88134° at θ = 0.0624747, min |1 + L| = 0.5339826 at
    θ = 0.076855), frequencies scaled by 1/dt; the disk margin that of dt = 1."""
    A = np.array([[1.0, 0.04877057549928599], [0.0, 0.951229424500714]])
    B = np.array([[0.00245884900142802], [0.09754115099857198]])
    loop = aerocontrol.StateSpace(A, B, [[1.0, 0.0]], [[0.0]], dt=dt)
    m = stability_margins(loop)
    assert m.gain_margin == pytest.approx(20.168060160150446, rel=1e-8)
    assert m.phase_margin == pytest.approx(36.88134203394145, rel=1e-8)
    assert m.gain_crossover * dt == pytest.approx(0.062474738618995544, rel=1e-8)
    assert m.stability_margin == pytest.approx(0.5339825697213723, rel=1e-8)
    assert m.stability_frequency * dt == pytest.approx(0.07685522990698192, rel=1e-5)
    reference = aerocontrol.disk_margins(
        aerocontrol.StateSpace(A, B, [[1.0, 0.0]], [[0.0]], dt=1.0)
    )
    margins = aerocontrol.disk_margins(loop)
    assert margins.multiloop.alpha == pytest.approx(reference.multiloop.alpha, rel=1e-9)
    assert m.disk_margin == pytest.approx(reference.multiloop.alpha, rel=1e-9)
    assert margins.multiloop.frequency * dt == pytest.approx(
        reference.multiloop.frequency, rel=1e-5
    )


def _cubic_gain_for_damping(a2: float, a1: float, a0: float, zeta: float) -> list[float]:
    """The gains k of s³ + a2 s² + a1 s + a0 + k = 0 with a pair of damping ratio ζ, by hand:
    the pair -ζω ± jω√(1 - ζ²) and the real root r = -a2 + 2ζω (the sum of the roots) give
    (1 - 4ζ²) ω² + 2 a2 ζ ω - a1 = 0 (the sum of the pairwise products), then
    k = -r ω² - a0 (the product)."""
    roots = np.roots([1.0 - 4.0 * zeta**2, 2.0 * a2 * zeta, -a1])
    omegas = sorted(float(w.real) for w in roots if abs(w.imag) == 0.0 and w.real > 0.0)
    return sorted((a2 - 2.0 * zeta * w) * w**2 - a0 for w in omegas)


@pytest.mark.parametrize(
    ("zeros", "poles", "zeta", "coefficients"),
    [
        # An unstable real pole (a spiral mode) beside the pair -1 ± j√3: (s - 1)(s² + 2s + 4).
        ([], [1.0, -1.0 + 1j * math.sqrt(3.0), -1.0 - 1j * math.sqrt(3.0)], 0.45, (1, 2, -4)),
        # The closed loop unstable below k = 2.5, where the pair (0.6 reached at k = 4.05) is
        # real: (s - 0.5)(s² + 4s + 5).
        ([], [0.5, -2.0 + 1j, -2.0 - 1j], 0.6, (3.5, 3.0, -2.5)),
        # A negative ζ, an unstable pair: s (s + 1)(s + 2), ζ = 0 at k = 6.
        ([], [0.0, -1.0, -2.0], -0.1, (3.0, 2.0, 0.0)),
    ],
)
def test_gain_for_damping_of_a_mode_beside_an_unstable_pole(
    zeros: list[complex], poles: list[complex], zeta: float, coefficients: tuple[float, ...]
) -> None:
    """Found by a hostile-input hunt: the damping of a gain at which another pole is unstable
    counted as -1 (best_damping_gain's objective), so the damping ratio the docstring promises
    was refused as not reached (the first two) or the stability boundary returned with a
    warning (the last: k = 6, ζ = 0). The smallest gain of the closed form (a cubic's roots by
    hand), to 1e-9."""
    expected = min(k for k in _cubic_gain_for_damping(*coefficients, zeta) if k > 0.0)
    loop = aerocontrol.zpk(zeros, poles, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        design = gain_for_damping(loop, zeta)
    assert design.gain == pytest.approx(expected, rel=1e-9)
    assert design.damping_ratio == pytest.approx(zeta, abs=1e-9)
    # The closed-loop poles of 1 + k L = 0 at that gain, from the characteristic polynomial.
    characteristic = np.poly(poles).real + np.concatenate([[0.0] * 3, [design.gain]])
    assert np.allclose(
        np.sort_complex(design.closed_loop_poles),
        np.sort_complex(np.roots(characteristic)),
        rtol=1e-9,
        atol=1e-9,
    )
    if zeta != 0.6:  # (the pair of the second meets the real axis: no branch to track)
        tracked = gain_for_damping(loop, zeta, mode=complex(poles[1]))
        assert tracked.gain == pytest.approx(expected, rel=1e-9)


def test_best_damping_gain_against_dense_search() -> None:
    loop = _yaw_loop(3.0)
    plane = aerocontrol.aircraft.load("b747-cruise").lateral()
    dutch = next(p for p in np.linalg.eigvals(plane.A) if p.imag > 0)
    design = best_damping_gain(loop, mode=dutch)

    # The oracle: numpy eigenvalues on 20,001 gains, then scipy's bounded search.
    def zeta(k: float) -> float:
        A = loop.A - k * loop.B @ loop.C
        poles = np.linalg.eigvals(A)
        near = poles[np.argmin(np.abs(poles - dutch))] if k < 1e-9 else None
        candidates = poles[poles.imag > 1e-9]
        near = candidates[np.argmin(np.abs(candidates - design.pole))]
        return float(-near.real / abs(near))

    ks = np.linspace(0, 10, 2001)
    best_k = ks[int(np.argmax([zeta(k) for k in ks]))]
    refined = minimize_scalar(
        lambda k: -zeta(k),
        bounds=(best_k - 0.01, best_k + 0.01),
        method="bounded",
        options={"xatol": 1e-10},
    )
    assert design.damping_ratio == pytest.approx(-refined.fun, abs=1e-8)
    assert design.gain == pytest.approx(refined.x, rel=1e-4)
    assert design.damping_ratio > 0.25


def test_root_locus_arguments() -> None:
    loop = _third_order(1.0)
    with pytest.raises(InvalidArgumentError, match="gains must be non-negative"):
        best_damping_gain(loop, gains=[-1.0, 1.0])
    with pytest.raises(InvalidArgumentError, match="mode must be"):
        best_damping_gain(loop, mode="dutch roll")  # type: ignore[arg-type]
    with pytest.raises(ShapeError, match="gains must be a non-empty"):
        root_locus(loop, [])


def test_yaw_damper_closed_loop_is_the_locus_at_its_gain() -> None:
    """The damper's closed loop (built with feedback()) has the poles of 1 + k L = 0 that
    numpy finds for the loop's matrices; the washout keeps a slow real (spiral) root that
    the damper without it turns into an oscillation."""
    plane = aerocontrol.aircraft.load("b747-cruise")
    damper = aerocontrol.design.yaw_damper(plane)
    loop, k = damper.loop, damper.design.gain
    expected = np.linalg.eigvals(loop.A - k * loop.B @ loop.C / (1 + k * loop.D[0, 0]))
    ours = np.linalg.eigvals(damper.closed_loop.A)
    assert _matched(ours, expected) < 1e-9
    assert damper.margins.closed_loop_stable and damper.check.passed == {"yaw damper": True}
    slow = ours[np.argmin(np.abs(ours))]
    assert slow.imag == 0 and -0.01 < slow.real < 0
    bare = aerocontrol.design.yaw_damper(plane, washout_tau=None)
    roots = np.linalg.eigvals(bare.closed_loop.A)
    assert np.all(np.abs(roots[np.abs(roots) < 0.5].imag) > 0)  # no slow real root left


def _matched(a: np.ndarray, b: np.ndarray) -> float:
    from scipy.optimize import linear_sum_assignment

    distance = np.abs(a[:, None] - b[None, :])
    rows, columns = linear_sum_assignment(distance)
    return float(np.max(distance[rows, columns]))


# ----- loops beyond the core's range ------------------------------------------------------------


def test_margins_of_a_loop_at_a_huge_frequency_scale() -> None:
    """L(s) = L0(s/σ) with L0 = 2/(s(s + 1)(s + 2)) and σ = 2^600 (A and B times σ): the same
    gain and phase margins as L0 (python-control, to 1e-9), its frequencies times σ, its delay
    margin divided by σ and its closed-loop poles times σ."""
    sigma = 2.0**600
    L0 = _third_order(2.0)
    huge = (L0.A * sigma, L0.B * sigma, L0.C, L0.D)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        margins = stability_margins(huge)
    gm, pm, _, wpc, wgc, _ = control.stability_margins(control.ss(L0.A, L0.B, L0.C, L0.D))
    assert margins.gain_margin == pytest.approx(gm, rel=1e-9)
    assert margins.gain_margin == pytest.approx(3.0, rel=1e-12)
    assert margins.phase_crossover == pytest.approx(sigma * wpc, rel=1e-9)
    assert margins.phase_margin == pytest.approx(pm, rel=1e-9)
    assert margins.gain_crossover == pytest.approx(sigma * wgc, rel=1e-9)
    reference = stability_margins(L0)
    assert margins.delay_margin == pytest.approx(reference.delay_margin / sigma, rel=1e-12)
    assert margins.closed_loop_poles == pytest.approx(
        sigma * np.sort_complex(np.linalg.eigvals(L0.A - L0.B @ L0.C)), rel=1e-12
    )


def test_root_locus_where_k_b_c_overflows() -> None:
    """A = -1, B = C = 1e200: B C = 1e400 overflows, but the poles -1 - k 1e400 are doubles
    for k = 1e-100 and 1e-300 (closed form, to 1e-15); at k = 1 the pole is beyond doubles:
    -inf with a NumericalOverflowWarning."""
    loop = (np.array([[-1.0]]), np.array([[1e200]]), np.array([[1e200]]), np.zeros((1, 1)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        poles = root_locus(loop, [0.0, 1e-300, 1e-100]).poles[:, 0]
    assert poles == pytest.approx([-1.0, -1.0 - 1e100, -1e300], rel=1e-15)
    with pytest.warns(aerocontrol.NumericalOverflowWarning):
        poles = root_locus(loop, [1.0, 1e-300]).poles[:, 0]
    assert poles[0] == -math.inf and poles[1] == pytest.approx(-1e100, rel=1e-15)


def test_half_difference_and_nearest_of_huge_values() -> None:
    """|1 - L|/(2|1 + L|) of an L near 1e308 is 1/2 (it was inf/inf: numpy's warnings), and
    the tracking of a mode among infinite poles picks a finite nearest one."""
    from aerocontrol.loops import _damping, _half_difference, _nearest

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ratio = _half_difference(np.array([1.5e308 - 1.5e308j, 1e308 + 0j, -1.0 + 0j, 0.5 + 0j]))
        assert ratio[:2] == pytest.approx([0.5, 0.5], rel=1e-15)
        assert ratio[2] == math.inf
        assert ratio[3] == pytest.approx(1.0 / 6.0, rel=1e-15)
        poles = np.array([complex(math.inf, 0.0), 1e308 + 0j, -1e308 + 0j])
        assert _nearest(poles, -1.7e308 + 0j) == 2
        assert _nearest(poles, complex(math.inf, 0.0)) == 0
        assert _damping(complex(-1.5e308, 1.5e308), 0.0) == pytest.approx(math.sqrt(0.5))


def test_stability_margins_of_a_loop_with_a_feedthrough_near_the_overflow() -> None:
    """L = 1e308 (C = 0, the grid path): |1 - L|/(2|1 + L|) was 1e308/inf = 0 (numpy's
    overflow warning) and the disk margin 1/0 = inf; it is 1/(1/2) = 2. The root locus of
    L = 1e308 + 0.0156/(s + 1.87) warned that its numerator overflows, for its poles."""
    static = (np.array([[-1.87]]), np.array([[0.125]]), np.array([[0.0]]), np.array([[1e308]]))
    model = (np.array([[-1.87]]), np.array([[0.125]]), np.array([[0.125]]), np.array([[1e308]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        margins = aerocontrol.stability_margins(static)
        assert margins.disk_margin == pytest.approx(2.0, rel=1e-12)
        assert margins.disk_phase_margin == pytest.approx(90.0, rel=1e-12)
        locus = aerocontrol.root_locus(model, [0.0, 1.0, 5.0])
        assert locus.open_loop_poles.tolist() == [-1.87 + 0j]
        assert locus.open_loop_zeros.size == 1


def test_damping_search_refuses_an_algebraic_gain_of_the_grid() -> None:
    """D = -2 and the grid 0, 0.5, ...: 1 + 0.5 D = 0 made an infinite closed-loop matrix
    (NonFiniteError blaming A, with C = 0 numpy's inf·0 warning); the gain is refused by name."""
    for c in (0.0, 0.1257):
        model = (np.array([[-1.87]]), np.array([[0.1257]]), np.array([[c]]), np.array([[-2.0]]))
        with pytest.raises(aerocontrol.SingularMatrixError, match=r"gain 0\.5 is an algebraic"):
            aerocontrol.best_damping_gain(model, gains=np.linspace(0.0, 10.0, 21))
        with pytest.raises(aerocontrol.SingularMatrixError, match=r"gain 0\.5 is an algebraic"):
            aerocontrol.gain_for_damping(model, 0.5, gains=np.linspace(0.0, 10.0, 21))
    # C = 0 and no algebraic gain: the poles stay at A's, without warnings.
    model = (np.array([[-1.87]]), np.array([[0.1257]]), np.array([[0.0]]), np.array([[-1.43]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        locus = aerocontrol.root_locus(model, [0.0, 2.0])
    assert locus.poles.tolist() == [[-1.87 + 0j], [-1.87 + 0j]]


def test_stability_margins_when_the_core_overflows_beside_a_huge_feedthrough() -> None:
    """C and D of 1e308 (or C 1e308, D 1e300): the core's margin pencils overflowed (a
    NonFiniteError 'A is NaN' for a finite loop); the grid search gives the margins: L is
    about D everywhere, so no crossovers and |S - T|/2 = 1/2 (disk margin 2), and the closed
    loop is A - B C/(1 + D)."""
    a, b = -1.8742697789066067, 0.345584192064786
    for c, d, pole in ((1e308, 1e308, a - b), (1e308, 1e300, a - b * 1e8)):
        model = (np.array([[a]]), np.array([[b]]), np.array([[c]]), np.array([[d]]))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            margins = aerocontrol.stability_margins(model)
        assert margins.disk_margin == pytest.approx(2.0, rel=1e-9)
        assert margins.gain_margins.size == 0 and margins.phase_margins.size == 0
        assert margins.closed_loop_poles.real == pytest.approx([pole], rel=1e-12)
        assert margins.closed_loop_stable


def test_stability_margins_of_loops_that_are_their_feedthrough_to_rounding() -> None:
    """Two fuzz loops of the grid path. L = 1.26e-309/(s + 1.87e-150): the grid's lowest
    frequency underflowed and high/low overflowed (numpy's warning, then int(inf)). L =
    -0.0399 + 1.6e-302/(s + 1.87): its gain margin 1/0.0399 makes 1 + k D = 0 in doubles, and
    the check of the margin formed an infinite closed-loop matrix (NonFiniteError on A)."""
    a, b, d = -1.8742697789066067, 0.1257302210933933, -0.03992465894713502
    tiny = (np.array([[a * 1e-150]]), np.array([[b]]), np.array([[1e-308]]), np.zeros((1, 1)))
    flat = (np.array([[a]]), np.array([[b]]), np.array([[b * 1e-300]]), np.array([[d]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        first = aerocontrol.stability_margins(tiny)
        second = aerocontrol.stability_margins(flat)
    assert first.disk_margin == pytest.approx(2.0, rel=1e-12)
    assert first.closed_loop_stable
    assert second.disk_margin == pytest.approx(2.0 * (1.0 + d) / (1.0 - d), rel=1e-12)
    assert second.gain_margins.tolist() == pytest.approx([-1.0 / d], rel=1e-12)
    assert second.phase_crossovers.tolist() == [0.0]


def test_open_loop_unstable_pole_that_the_frequency_scaling_underflows() -> None:
    """A = 1.26e-301 > 0 beside B C of 1.6e148: the loop slowed by 2^-492 had A = 0, so the
    unstable open-loop pole was not counted (a silent wrong answer); it is counted from A."""
    b = 0.1257302210933933
    model = (np.array([[b * 1e-300]]), np.array([[b]]), np.array([[b * 1e150]]), np.zeros((1, 1)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        margins = aerocontrol.stability_margins(model)
    assert margins.open_loop_unstable_poles == 1
    assert margins.closed_loop_stable
    assert margins.encirclements == 1
    assert margins.closed_loop_poles.real == pytest.approx([-b * b * 1e150], rel=1e-12)


def test_open_loop_poles_beyond_the_doubles_warn_as_other_results_do() -> None:
    """The open loop's poles and zeros are checked by the one check of results formed in
    Python (_validation.finite_or_warn, formerly a copy of it in loops): A = x [[1, 1], [1, 1]]
    has the poles 0 and 2x (closed form), 2e308 beyond the doubles, so inf with a
    NumericalOverflowWarning naming the poles; the zero 1e308 of C adj(sI - A) B = s - x is
    finite, and its check is silent."""
    x = 1e308
    loop = (np.array([[x, x], [x, x]]), np.array([[1.0], [0.0]]), np.array([[1.0, 0.0]]), [[0.0]])
    with pytest.warns(aerocontrol.NumericalOverflowWarning, match="closed-loop poles"):
        locus = root_locus(loop, [0.0])
    message = "infinite or NaN entries in the open loop's poles"
    with pytest.warns(aerocontrol.NumericalOverflowWarning, match=message):
        poles = locus.open_loop_poles
    assert np.array_equal(np.sort_complex(poles), [0.0, np.inf])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.array_equal(locus.open_loop_zeros, [x])


# ----- extreme scales: no NaN, no escaped numpy warning ------------------------------------------


@pytest.mark.parametrize("d", [5e-324, 1e-308, 1e308])
def test_best_damping_gain_refuses_a_default_grid_beyond_the_doubles(d: float) -> None:
    """A static loop L = D (no state: every gain gives the same, empty, closed loop): the
    default gains about 1/|D| (1/5e-324 is inf; 1e-308 gives 1e305 to 1e311) or 1e-308 about
    1/1e308 (below the normal doubles) are not representable. The subnormal D returned a NaN
    gain with no warning, 1e-308 escaped numpy's overflow warning: now refused naming the
    loop, and with the gains given the answer is the first gain (ζ = 1 for every gain)."""
    static = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[d]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InvalidArgumentError, match=r"loop: .*give the gains"):
            best_damping_gain(static)
        design = best_damping_gain(static, gains=[0.0, 1.0, 1e300])
    assert design.gain == 0.0 and design.damping_ratio == 1.0
    assert design.closed_loop_poles.shape == (0,)


def test_best_damping_gain_of_a_flat_objective_stays_on_the_grid() -> None:
    """1/(s + 1) with a D of 1e-200: no gain makes a pole oscillate, so ζ = 1 everywhere; the
    golden-section refinement drifted from the grid gain 0 towards 8.6e-46 (a gain no better
    than 0): the grid gain is kept unless the refinement damps strictly better."""
    model = (np.array([[-1.0]]), np.array([[1.0]]), np.array([[1.0]]), np.array([[1e-200]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        design = best_damping_gain(model)
    assert design.gain == 0.0 and design.damping_ratio == 1.0
    assert design.closed_loop_poles.tolist() == [-1.0 + 0j]


def test_closed_loop_gain_beyond_the_doubles_near_the_algebraic_gain() -> None:
    """D = -1e-300 and k = 1e300 (1 + 1e-14), within 1e-14 of the algebraic gain -1/D: the
    closed-loop gain k/(1 + k D) = -1e314 overflowed, and the matrix A - g B C was formed of
    inf (a NonFiniteError blaming A, which is finite). With B C = 1e-200 the pole
    -1 - 1e-200 k/(1 + k D) = 1.0008e114 is representable (closed form, with 1 + k D
    evaluated in double precision as aerocontrol does)."""
    model = (np.array([[-1.0]]), np.array([[1.0]]), np.array([[1e-200]]), np.array([[-1e-300]]))
    k = 1e300 * (1 + 1e-14)
    expected = -1.0 - 1e-200 * k / (1.0 + k * -1e-300)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        locus = root_locus(model, [k, 1.0])
        design = best_damping_gain(model, gains=[0.0, k])
    assert locus.poles[0, 0].real == pytest.approx(expected, rel=1e-12)
    assert locus.poles[1, 0] == pytest.approx(-1.0 - 1e-200, rel=1e-15)
    assert design.gain == 0.0 and design.closed_loop_poles.tolist() == [-1.0 + 0j]


def test_margins_closed_loop_poles_of_a_dominant_rank_one_loop() -> None:
    """A of 1e-8 beside B C of 1e3, B without a fifth entry (a hypothesis campaign's input,
    seed 1): the core's balanced eigenvalues of A - B C had backward errors up to 1.5e-9 for
    the four small poles (1000 n u ||A - B C||) and relative errors of 3%, though the
    eigenvector matrix has condition 11. The reference is mpmath's eigenvalues at 50 digits;
    the poles now agree to 1e-5 relatively (the condition times n u ||A - B C|| / |pole|:
    11 · 5 · 1.1e-16 · 2.7e3 / 8e-9 = 2e-5) and the large pole to 1e-13."""
    A = np.array(
        [
            [-3.1103377564063964e-08, -1.3210486329130189e-09, 6.4042265044328204e-09,
             1.0490011715303971e-09, -5.3566937316111095e-09],
            [3.6159505490948476e-09, -1.9320679323696528e-08, 9.4708096312924227e-09,
             -7.0373523580699263e-09, -1.2654214710460525e-08],
            [-6.2327446253735220e-09, 4.1325979347243599e-10, -5.5610987521386247e-08,
             -2.1879166393254573e-09, -1.2459109472530651e-08],
            [-7.3226735470345159e-09, -5.4425898285730992e-09, -3.1630015636915456e-09,
             -2.8244374411256570e-08, 1.0425133694426777e-08],
            [-1.2853466294403426e-09, 1.3664634705496860e-08, -6.6519467348661353e-09,
             3.5151007009301971e-09, -2.3325977958479811e-08],
        ]
    )  # fmt: skip
    B = np.array([[2.0], [-1.0], [-2.0], [-1.0], [0.0]])
    C = np.array(
        [[125.7302210933933, -132.10486329130188, 640.422650443282, 104.9001171530397,
          -535.6693731611109]]
    )  # fmt: skip
    mpmath_poles = np.array(
        [
            -4.225538978942033e-08,
            -3.933164096927389e-08,
            -8.491470931616548e-09 - 8.398194677560902e-09j,
            -8.491470931616548e-09 + 8.398194677560902e-09j,
            1002.1801125024798,
        ]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        margins = stability_margins((A, B, C, np.zeros((1, 1))))
    poles = margins.closed_loop_poles
    np.testing.assert_allclose(poles[:4], mpmath_poles[:4], rtol=1e-5)
    assert poles[4] == pytest.approx(mpmath_poles[4], rel=1e-13)
    M = A - B @ C
    for pole in poles:  # backward errors within n u ||M||_F, as a backward stable QR's
        smallest = np.linalg.svd(M - pole * np.eye(5), compute_uv=False)[-1]
        assert smallest <= 5 * np.finfo(float).eps * np.linalg.norm(M)
    assert not margins.closed_loop_stable


def test_margins_grid_of_a_loop_with_a_huge_feedthrough() -> None:
    """A of -1.87e-3, B of 2e8, C of 2e300, D of 1.26e299 (a campaign input, seed 0): the grid
    search's low-frequency gain K Π|z| / Π|p| overflowed (numpy's warnings, then inf/inf); it
    is formed in log2. Closed form: the closed-loop pole a - b c/(1 + d) = -3.1814e9."""
    a, b, c, d = -0.00187426977890661, 2e8, 2e300, 1.257302210933933e299
    model = (np.array([[a]]), np.array([[b]]), np.array([[c]]), np.array([[d]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        margins = stability_margins(model)
    assert margins.closed_loop_poles[0] == pytest.approx(a - (b / (1 + d)) * c, rel=1e-12)
    assert margins.closed_loop_stable


def _scaled_states(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, exponents: list[int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """T A T⁻¹, T B, C T⁻¹ with T = diag(10^e): the same transfer matrix in badly scaled states."""
    t = 10.0 ** np.array(exponents, dtype=float)
    return A * t[:, None] / t[None, :], B * t[:, None], C / t[None, :]


def test_disk_margins_of_a_multiloop_in_states_scaled_by_a_million() -> None:
    """The satellite (K = I) behind actuators 5/(s + 5), its states scaled by 10^(6, -6, 6, -6):
    the destabilising perturbation failed its check ('leaves I + L F nonsingular', smallest
    singular value 0.1 of its terms): the loop's states are now balanced by powers of two
    first. Oracle: python-control's disk_margins (slycot's AB13MD) on the unscaled loop, on
    the same grid; the refined margin lies below the grid's, within 1e-6."""
    a = 10.0
    core = np.array([[0.0, a], [-a, 0.0]])
    A1 = np.block([[core, 5.0 * np.eye(2)], [np.zeros((2, 2)), -5.0 * np.eye(2)]])
    B1 = np.vstack([np.zeros((2, 2)), np.eye(2)])
    C1 = np.hstack([np.array([[1.0, a], [-a, 1.0]]), np.zeros((2, 2))])
    D = np.zeros((2, 2))
    scaled = aerocontrol.StateSpace(*_scaled_states(A1, B1, C1, [6, -6, 6, -6]), D)
    grid = np.linspace(0.3, 0.5, 2001)
    for skew in (0.0, 0.5, -0.5):
        theirs = float(control.disk_margins(control.ss(A1, B1, C1, D), grid, skew=skew)[0])
        on_grid = aerocontrol.disk_margins(scaled, omega=grid, skew=skew)
        assert on_grid.multiloop.alpha == pytest.approx(theirs, rel=1e-12)
        refined = aerocontrol.disk_margins(scaled, skew=skew)
        assert theirs * (1 - 1e-6) <= refined.multiloop.alpha <= theirs * (1 + 1e-12)
        assert refined.closed_loop_stable


def test_disk_margins_of_a_discrete_loop_in_badly_scaled_states() -> None:
    """1.5 (s² - 2s + 2)(s² + 2s + 2)/((s + 1)(s² + 2s + 5)(s + 4)(s + 5)) (zeros ±1 ± j) held
    (ZOH, 0.1 s), its states scaled by 10^(∓6): refused ('leaves I + L F nonsingular');
    oracle python-control's disk_margins of the unscaled loop on 20001 points up to π/dt (the
    refined margin below the grid's by 7e-8 at most)."""
    num = [1.5, 0.0, 0.0, 0.0, 6.0]
    den = np.poly([-1.0, -1.0 + 2j, -1.0 - 2j, -4.0, -5.0]).real
    A0, B0, C0, D0, _ = cont2discrete(tf2ss(num, den), 0.1, method="zoh")
    grid = np.linspace(0.0, math.pi / 0.1, 20001)
    for exponents in ([-6, 6, -6, 6, -6], [6, -6, 6, -6, 6], [-6, -3, 0, 3, 6]):
        A, B, C = _scaled_states(A0, B0, C0, exponents)
        loop = aerocontrol.StateSpace(A, B, C, D0, dt=0.1)
        for skew in (0.0, 0.5, -0.5):
            theirs = float(
                control.disk_margins(control.ss(A0, B0, C0, D0, 0.1), grid, skew=skew)[0]
            )
            ours = aerocontrol.disk_margins(loop, skew=skew).multiloop.alpha
            assert theirs * (1 - 1e-6) <= ours <= theirs * (1 + 1e-12)


def test_skewed_disk_margin_of_an_integrating_loop_peaks_at_zero() -> None:
    """k (s + 3)/(s (s + 2)(s + 5)), skew -0.5: |S + (σ - 1)/2| peaks at ω = 0, where S = 0 and
    L has its pole, so α = 1/0.75 (closed form; python-control from 1e-9 rad/s agrees). The
    check of the destabilising gain (f = 0) formed I + L F with L infinite: numpy's 'SVD did
    not converge'. It is checked as I - M Δ there."""
    for k in (0.5, 2.0):
        loop = aerocontrol.zpk([-3.0], [0.0, -2.0, -5.0], k)
        grid = np.concatenate([[1e-9], np.logspace(-6, 4, 2001)])
        theirs = float(
            control.disk_margins(control.ss(loop.A, loop.B, loop.C, loop.D), grid, skew=-0.5)[0]
        )
        m = aerocontrol.disk_margins(loop, skew=-0.5)
        assert m.multiloop.alpha == pytest.approx(4.0 / 3.0, rel=1e-14)
        assert theirs == pytest.approx(4.0 / 3.0, rel=1e-8)
        assert m.multiloop.frequency == 0.0
        assert abs(m.worst_perturbation[0]) <= 1e-15  # gain 0: the open integrator


def test_pole_cancelled_at_the_origin_is_not_a_stable_closed_loop() -> None:
    """(s² + s)/(s (s + 2)(s + 3)) in controllable form: its mode at 0 is unobservable, so the
    closed loop keeps it (s (s² + 6s + 7): eigenvalues 0 and -3 ± √2). Computed as -2.7e-18,
    3.6e-16 or 1.8e-12 by the scaling of the states, its sign decided the answer:
    stability_margins called the loop stable (disk margin 0), disk_margins refused it
    ('sensitivity overflows at 0 rad/s') or called it unstable. A pole within the boundary
    tolerance of the balanced closed loop now makes it not stable, as nyquist calls it
    marginal, for every scaling."""
    A = np.array([[-5.0, -6.0, -0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    B, C, D = np.array([[1.0], [0.0], [0.0]]), np.array([[1.0, 1.0, 0.0]]), np.zeros((1, 1))
    for exponents in ([0, 0, 0], [-6, 0, 6], [6, 0, -6], [4, 0, -4]):
        loop = aerocontrol.StateSpace(*_scaled_states(A, B, C, exponents), D)
        m = aerocontrol.disk_margins(loop)
        assert not m.closed_loop_stable and m.multiloop.alpha == 0.0
        closed = np.sort(m.closed_loop_poles.real)
        np.testing.assert_allclose(closed[:2], [-3 - math.sqrt(2), -3 + math.sqrt(2)], rtol=1e-12)
        assert abs(closed[2]) <= 1e-6
        margins = stability_margins(loop)
        assert not margins.closed_loop_stable and margins.disk_margin == 0.0
        assert aerocontrol.nyquist(loop).marginal


def _numpy_damping(loop: aerocontrol.StateSpace, k: float) -> float:
    """ζ of the least-damped oscillatory pole of A - k B C (D = 0) by numpy's eigvals, -1 if a
    pole is unstable, 1 if none oscillates: the damping search's independent oracle."""
    poles = np.linalg.eigvals(loop.A - k * loop.B @ loop.C)
    if np.any(poles.real > 0):
        return -1.0
    oscillatory = poles[poles.imag > 1e-9 * np.abs(poles)]
    return float(np.min(-oscillatory.real / np.abs(oscillatory))) if oscillatory.size else 1.0


def test_root_locus_and_damping_of_the_747_yaw_loop_in_badly_scaled_states() -> None:
    """The 747 yaw damper loop, its six states scaled by 10^(±6, ∓6, ...): the core's root-locus
    QR is unbalanced, and the poles came out with errors 1800 times their size (silently);
    best_damping_gain then chose k = 0 (ζ 0.035) or k = 1.80 with ζ 0.332, above the true
    maximum. The loop's states are now balanced first. Oracle: numpy's eigvals of the
    unscaled A - k B C, on 8001 gains over the default six decades, the best refined by
    scipy's bounded minimize_scalar: k = 1.48732, ζ = 0.291199."""
    loop = aerocontrol.design.yaw_damper(aerocontrol.aircraft.load("b747-cruise")).loop
    assert not np.any(loop.D)
    gains = np.logspace(np.log10(3.9136e-3), np.log10(3.9136e3), 8001)
    grid = np.array([_numpy_damping(loop, k) for k in gains])
    i = int(np.argmax(grid))
    found = minimize_scalar(
        lambda k: -_numpy_damping(loop, k),
        bounds=(gains[i - 1], gains[i + 1]),
        method="bounded",
        options={"xatol": 1e-10},
    )
    best_k, best_zeta = float(found.x), -float(found.fun)
    assert best_zeta >= grid[i]
    for exponents in ([6, -6, 6, -6, 6, -6], [-6, 6, -6, 6, -6, 6], [-6, -6, -4, 4, 2, 5]):
        A, B, C = _scaled_states(loop.A, loop.B, loop.C, exponents)
        scaled = aerocontrol.StateSpace(A, B, C, loop.D)
        ks = np.array([0.1, 1.0, best_k, 10.0])
        locus = root_locus(scaled, ks)
        for k, poles in zip(ks, locus.poles, strict=True):
            theirs = np.sort_complex(np.linalg.eigvals(loop.A - k * loop.B @ loop.C))
            error = np.max(np.abs(np.sort_complex(poles) - theirs))
            assert error <= 1e-12 * np.max(np.abs(theirs))
        design = best_damping_gain(scaled)
        assert design.damping_ratio == pytest.approx(best_zeta, abs=1e-12)
        assert design.gain == pytest.approx(best_k, rel=1e-6)
        assert design.damping_ratio == pytest.approx(_numpy_damping(loop, design.gain), abs=1e-12)


def test_discrete_margins_in_badly_scaled_states() -> None:
    """0.5 (s + 3)/(s (s + 2)(s + 5)) held (ZOH, 0.1 s), its states scaled by 10^(6, -6, 6):
    the grid search's L(e^jωT) came from the core's unbalanced solve, and the gain margin
    came out 0.007 for 167.76 (phase margin 0.39° off), silently; the states are now balanced
    first. Oracle: python-control's stability_margins of the unscaled loop."""
    A0, B0, C0, D0, _ = cont2discrete(tf2ss([0.5, 1.5], np.poly([0.0, -2.0, -5.0])), 0.1)
    with warnings.catch_warnings():  # python-control: falling back to its 'frd' method
        warnings.simplefilter("ignore", UserWarning)
        gm, pm, _, _, _, _ = control.stability_margins(control.ss(A0, B0, C0, D0, 0.1))
    for exponents in ([6, -6, 6], [3, -6, 6], [-6, 0, 6]):
        A, B, C = _scaled_states(A0, B0, C0, exponents)
        m = stability_margins(aerocontrol.StateSpace(A, B, C, D0, dt=0.1))
        assert m.gain_margin == pytest.approx(gm, rel=1e-8)
        assert m.phase_margin == pytest.approx(pm, abs=1e-7)
        assert m.closed_loop_stable


def _mpmath_locus_roots(num: list[float], den: list[float], k: float) -> np.ndarray:
    """The roots of den(s) + k num(s) at 50 digits (coefficients highest power first)."""
    with mpmath.workdps(50):
        padded = [0.0] * (len(den) - len(num)) + list(num)
        coefficients = [
            mpmath.mpf(d) + mpmath.mpf(k) * mpmath.mpf(v) for d, v in zip(den, padded, strict=True)
        ]
        roots = mpmath.polyroots(coefficients[::-1], maxsteps=200, extraprec=200, asc=True)
    return np.sort_complex(np.array([complex(r) for r in roots]))


def test_root_locus_high_gain_relative_degree_three_against_mpmath() -> None:
    """2 (s + 3)/((s + 1)^3 (s + 5)) at k = 8.84e7 and 1e8: poles about -563, -3 and
    279 ± 486j. Oracle: mpmath's polyroots of (s + 1)^3 (s + 5) + 2 k (s + 3) at 50 digits;
    numpy's eigvals of A - k B C agrees with it to 1e-15 (relative to the largest pole). The
    QR iteration of the controller-Hessenberg form alone was 1.3e-6 off (its error is relative
    to k ||b|| ||c||); its poles are now polished by the continuation, whose pole next to the
    zero -3 converges by the Newton inclusion test."""
    loop = aerocontrol.zpk([-3.0], [-1.0, -1.0, -1.0, -5.0], 2.0)
    den = [float(c) for c in np.poly([-1.0, -1.0, -1.0, -5.0])]
    gains = np.logspace(-8, 8, 1500)
    dense = root_locus(loop, gains).poles
    for i in (1494, 1499):
        k = float(gains[i])
        exact = _mpmath_locus_roots([2.0, 6.0], den, k)
        scale = float(np.max(np.abs(exact)))
        ours = np.linalg.eigvals(loop.A - k * loop.B @ loop.C)
        assert np.max(np.abs(np.sort_complex(ours) - exact)) <= 1e-14 * scale
        for poles in (dense[i], root_locus(loop, [k]).poles[0]):
            assert np.max(np.abs(np.sort_complex(poles) - exact)) <= 1e-12 * scale


def _scaled_loop_poles(scale: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """2 (s + 3)/((s + 1)(s + 2)) realised by zpk with A and C multiplied by ``scale``: the
    closed loop is ``scale`` times the unscaled one's, whose poles at k = 1 are
    s^2 + 5 s + 8 = 0, -2.5 ± j√7/2 (a closed form). Returns that form and root_locus's poles
    at k = 1, by one gain and as the last of 200."""
    base = aerocontrol.zpk([-3.0], [-1.0, -2.0], 2.0)
    loop = aerocontrol.StateSpace(base.A * scale, base.B, base.C * scale)
    exact = np.array([complex(-2.5, -math.sqrt(7) / 2), complex(-2.5, math.sqrt(7) / 2)])
    assert np.allclose(np.sort_complex(np.linalg.eigvals(loop.A - loop.B @ loop.C)) / scale, exact)
    ours = [
        np.sort_complex(root_locus(loop, [1.0]).poles[0]) / scale,
        np.sort_complex(root_locus(loop, np.linspace(0.5, 1.0, 200)).poles[-1]) / scale,
    ]
    return exact, ours


@pytest.mark.parametrize("scale", [1e-30, 1e-60, 1e-100, 1e-150, 1e-200, 1e30, 1e100])
def test_root_locus_of_a_loop_with_a_and_c_scaled(scale: float) -> None:
    """A and C of ``scale`` beside B of 1: the states' balancing of [[A, B], [C, 0]] was steered
    by B and left a matrix whose QR lost 4e-9 (1e-30) and 2% (1e-60) of the poles; the closed
    loop's balancing (balanced_loop) balances again with B and C brought to the size of A
    balanced alone (to that of A balanced with B, the poles at 1e-100 were 6e-5 off)."""
    exact, ours = _scaled_loop_poles(scale)
    for poles in ours:
        np.testing.assert_allclose(poles, exact, rtol=1e-13)


def test_root_locus_of_a_jordan_chain_at_high_gain_closed_form() -> None:
    """x' = J x + e4 u, y = x1 with J the 4 x 4 Jordan block at -1: 1 + k/(s + 1)^4 = 0, so
    s = -1 + k^(1/4) e^(jπ(2l + 1)/4) (a closed form), about 98 in modulus at k = 9.29e7;
    numpy's eigvals of A - k B C is within 1e-15 of it (relative). A single gain (the QR
    iteration, polished by the continuation) and the dense call agree with it; the QR alone
    was 3.4e-5 off."""
    A = np.diag(-np.ones(4)) + np.diag(np.ones(3), 1)
    B, C = np.eye(4)[:, 3:], np.eye(4)[:1]
    loop = aerocontrol.StateSpace(A, B, C)
    gains = np.logspace(-8, 8, 1500)
    k = float(gains[1496])
    exact = np.sort_complex(-1 + k**0.25 * np.exp(1j * np.pi * (2 * np.arange(4) + 1) / 4))
    scale = float(np.max(np.abs(exact)))
    ours = np.sort_complex(np.linalg.eigvals(A - k * B @ C))
    assert np.max(np.abs(ours - exact)) <= 1e-14 * scale
    dense = root_locus(loop, gains).poles[1496]
    assert np.max(np.abs(dense - exact)) <= 1e-14 * scale
    single = root_locus(loop, [k]).poles[0]
    assert np.max(np.abs(single - exact)) <= 1e-12 * scale


@pytest.mark.parametrize(
    ("phase", "gain", "named"),
    [
        (([math.nan], [(1.0, 0.0)]), ([], []), "phase crossovers"),
        (([math.inf], [(-1.0, 0.0)]), ([], []), "phase crossovers"),
        (([1.0], [(-0.5, math.nan)]), ([], []), "phase crossovers"),
        (([], []), ([-1.0], [(0.0, 1.0)]), "gain crossovers"),
        (([], []), ([1.0], [(math.inf, 0.0)]), "gain crossovers"),
    ],
)
def test_core_crossover_margins_refuse_bad_crossovers_by_name(
    phase: tuple[list[float], list[tuple[float, float]]],
    gain: tuple[list[float], list[tuple[float, float]]],
    named: str,
) -> None:
    """The core's margins of crossovers divide by ω and take L's phase: a crossover at a
    negative, NaN or infinite frequency, or with a non-finite L, is an InvalidArgumentError
    naming the list, not NaN margins."""
    with pytest.raises(InvalidArgumentError, match=named) as error:
        aerocontrol._core.crossover_margins(*phase, *gain)
    assert getattr(error.value, "argument", None) == named
    # The valid crossovers of the same kinds give the margins by hand: 1/|L| = 2 at ω = 1
    # (L = -0.5), and at ω = 2 the phase margin 90° with the delay margin (π/2)/2.
    margins = aerocontrol._core.crossover_margins([1.0], [(-0.5, 0.0)], [2.0], [(0.0, -1.0)])[0]
    np.testing.assert_allclose(margins, [2.0, 1.0, 90.0, 2.0, math.pi / 4], rtol=1e-15)
