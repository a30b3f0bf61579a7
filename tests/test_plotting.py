"""Plots draw with no display (Agg), label their axes with units, and name the lines; the
penalty terms integrate to the performance index."""

from __future__ import annotations

import warnings
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
import scipy.linalg

import aerocontrol
from aerocontrol import InvalidArgumentError, NotRealError, plotting
from aerocontrol.design import lqr_root_locus

A, B = aerocontrol.chapter.boeing747_longitudinal()
SYS = aerocontrol.StateSpace(A, B, state_names=["u/u0", "alpha", "q", "theta"])
LATERAL = aerocontrol.aircraft.load().lateral()
STATE_LABELS = [
    "sideslip β (rad)",
    "roll rate p (rad/s)",
    "roll angle φ (rad)",
    "yaw rate r (rad/s)",
]


@pytest.fixture(autouse=True)
def _close_figures():  # type: ignore[no-untyped-def]
    yield
    plt.close("all")


def _labels(ax) -> list[str]:  # type: ignore[no-untyped-def]
    return [line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")]


def _regulator(c: float) -> tuple[np.ndarray, np.ndarray, aerocontrol.TimeResponse]:
    """The chapter's lateral regulator at weight c and its response to a unit sideslip."""
    R = np.eye(2) / c**2
    K, S, _ = aerocontrol.lqr(LATERAL.A, LATERAL.B, np.eye(4), R)
    closed = aerocontrol.StateSpace(
        LATERAL.A - LATERAL.B @ K, LATERAL.B, state_names=LATERAL.state_names,
        input_names=LATERAL.input_names,
    )  # fmt: skip
    response = aerocontrol.initial_response(closed, [1.0, 0, 0, 0], T=np.linspace(0, 60, 12001))
    return K, S, response


def test_time_response_plot() -> None:
    ax = aerocontrol.step_response(SYS, T=20.0).plot()
    assert ax.get_xlabel() == "time (s)"
    assert ax.get_ylabel() == "states (rad, rad/s, u/u0 nondimensional)"
    assert _labels(ax) == [
        "speed u/u0",
        "angle of attack α (rad)",
        "pitch rate q (rad/s)",
        "pitch angle θ (rad)",
    ]
    _, given = plt.subplots()
    assert aerocontrol.impulse_response(SYS, T=5.0).plot(ax=given, signal="outputs") is given
    generic = aerocontrol.step_response(aerocontrol.StateSpace(A, B), T=5.0).plot()
    assert _labels(generic) == ["x0", "x1", "x2", "x3"]
    assert generic.get_ylabel() == "states (model units)"


def test_time_response_plot_rejects_bad_arguments() -> None:
    response = aerocontrol.step_response(SYS, T=5.0)
    with pytest.raises(aerocontrol.InvalidArgumentError, match="signal"):
        plotting.plot_time_response(response, signal="inputs")
    with pytest.raises(aerocontrol.InvalidArgumentError, match=r"response must be in 0 \.\.\. 0"):
        plotting.plot_time_response(response, response=1)


def test_two_time_scales_cut_the_same_response() -> None:
    """Figures 6.1, 6.2: the left axes show the first 20 s of the 500 s response."""
    response = aerocontrol.impulse_response(SYS, T=np.linspace(0, 500, 25001))
    short, long = plotting.plot_time_scales(response, 20.0)
    assert short.get_lines()[0].get_xdata().max() == pytest.approx(20.0)
    assert long.get_lines()[0].get_xdata().max() == pytest.approx(500.0)
    np.testing.assert_array_equal(
        short.get_lines()[1].get_ydata(), response.x[response.t <= 20.0, 1]
    )
    assert (short.get_title(), long.get_title()) == ("short period scale", "phugoid scale")
    # One legend, on the short scale: the phugoid's oscillation fills the long panel.
    assert short.get_legend() is not None and long.get_legend() is None
    with pytest.raises(aerocontrol.InvalidArgumentError, match="short must be between 0"):
        plotting.plot_time_scales(response, 600.0)
    with pytest.raises(aerocontrol.InvalidArgumentError, match="pair of matplotlib axes"):
        plotting.plot_time_scales(response, 20.0, axes=plt.subplots()[1])


def test_open_closed_shares_the_scale() -> None:
    damper = aerocontrol.design.dutch_roll_damper(LATERAL, surface="rudder")
    closed = aerocontrol.StateSpace(damper.closed_loop, LATERAL.B[:, :1])
    x0 = [np.radians(5.0), 0, 0, 0]
    grid = np.linspace(0, 30, 601)
    first, second = plotting.plot_open_closed(
        aerocontrol.initial_response(LATERAL, x0, T=grid),
        aerocontrol.initial_response(closed, x0, T=grid),
    )
    assert first.get_shared_y_axes().joined(first, second)
    assert (first.get_title(), second.get_title()) == ("(a) open loop", "(b) closed loop")
    # On the caller's own (unshared) axes the scale is common too: the larger of the two.
    _, given = plt.subplots(1, 2)
    first, second = plotting.plot_open_closed(
        aerocontrol.initial_response(LATERAL, x0, T=grid),
        aerocontrol.initial_response(closed, x0, T=grid),
        axes=given,
    )
    assert first.get_ylim() == second.get_ylim()
    low, high = first.get_ylim()
    for axis in (first, second):
        for line in axis.get_lines():
            assert low <= np.min(line.get_ydata()) and np.max(line.get_ydata()) <= high


def test_with_controls_draws_the_deflections() -> None:
    """(6.230): the dashed lines are η = -K x, named by the inputs."""
    K, _, response = _regulator(1.0)
    ax = plotting.plot_with_controls(response, K)
    assert _labels(ax) == [*STATE_LABELS, "rudder δr (rad)", "aileron δa (rad)"]
    lines = ax.get_lines()
    np.testing.assert_allclose(lines[4].get_ydata(), -response.x @ K[0], rtol=0, atol=1e-15)
    assert lines[5].get_linestyle() == "--"
    with pytest.raises(aerocontrol.ShapeError, match="K must be m x 4"):
        plotting.plot_with_controls(response, np.ones((2, 3)))


def test_penalty_terms_integrate_to_the_index() -> None:
    """Figure 6.11: the area between x'Qx and -η'Rη is J = x0' S x0 (to the trapezoidal
    rule's error, dt = 0.005 s over 60 s)."""
    for c in (0.5, 1.0, 2.0):
        K, S, response = _regulator(c)
        state, control = plotting.penalty_terms(response, K, np.eye(4), np.eye(2) / c**2)
        area = float(np.sum((state + control)[1:] + (state + control)[:-1]) * 0.0025)
        assert area == pytest.approx(S[0, 0], rel=1e-5)
        ax = plotting.plot_penalty(response, K, np.eye(4), np.eye(2) / c**2, name=f"c = {c:g}")
        assert f"(J = {S[0, 0]:.4g})" in _labels(ax)[0]
    with pytest.raises(aerocontrol.ShapeError, match="R must be 2 x 2"):
        plotting.penalty_terms(response, K, np.eye(4), np.eye(3))


def test_root_locus_follows_each_root() -> None:
    """Figure 6.12: one line per root, each continuous over the sweep of c."""
    weights = np.unique(np.r_[np.geomspace(1e-3, 9.0, 300), 0.5, 1.0, 2.0])
    poles = lqr_root_locus(LATERAL, weights)
    ax = plotting.plot_root_locus(weights, poles, marked=[0.5, 1.0, 2.0])
    paths = [line for line in ax.get_lines() if line.get_label().startswith("_")][:4]
    for line in paths:
        path = np.asarray(line.get_xdata()) + 1j * np.asarray(line.get_ydata())
        assert np.all(np.abs(np.diff(path)) < 0.1 * np.abs(path[1:]))  # no jumps between roots
    ends = sorted(complex(line.get_xdata()[-1], line.get_ydata()[-1]).real for line in paths)
    np.testing.assert_allclose(ends, np.sort(poles[-1].real), rtol=1e-12)
    assert _labels(ax) == ["c = 0.5", "c = 1", "c = 2"]
    # Each marked weight its own colour, darkest first.
    colours = [line.get_color() for line in ax.get_lines() if not line.get_label().startswith("_")]
    assert len({tuple(np.round(colour, 6)) for colour in colours}) == 3
    assert np.sum(colours[0][:3]) < np.sum(colours[-1][:3])
    assert ax.get_xlabel() == "real part (1/s)"
    unmarked = plotting.plot_root_locus(weights, poles)
    assert _labels(unmarked) == ["c = 0.001"]
    with pytest.raises(aerocontrol.ShapeError, match="poles must be"):
        plotting.plot_root_locus(weights[:-1], poles)


def test_bode_and_modes_plots() -> None:
    magnitude_axis, phase_axis = aerocontrol.bode(SYS).plot()
    assert magnitude_axis.get_ylabel() == "magnitude (dB)"
    assert phase_axis.get_xlabel() == "frequency (rad/s)"
    with pytest.raises(aerocontrol.InvalidArgumentError, match=r"output must be in 0 \.\.\. 3"):
        aerocontrol.bode(SYS).plot(output=4)
    ax = aerocontrol.modes(A, mode_names=["phugoid", "short period"]).plot()
    assert _labels(ax) == ["phugoid", "short period"]
    assert len(ax.get_lines()[0].get_xdata()) == 2
    # A margin of a tenth of the span beyond the extreme eigenvalues: no marker cut by the frame.
    eigenvalues = np.linalg.eigvals(A)
    low, high = ax.get_ylim()
    span = np.ptp(eigenvalues.imag)
    assert low < eigenvalues.imag.min() - 0.1 * span and high > eigenvalues.imag.max() + 0.1 * span
    plotting.plot_modes(aerocontrol.modes(A - np.outer(B, [0, 0, 1, 0])), ax=ax, marker="o",
                        suffix=" (closed)")  # fmt: skip
    assert _labels(ax)[2:] == ["mode 1 (closed)", "mode 2 (closed)"]


def test_plots_do_not_modify_the_results() -> None:
    K, _, response = _regulator(1.0)
    before = response.x.copy(), K.copy()
    plotting.plot_with_controls(response, K)
    plotting.plot_penalty(response, K, np.eye(4), np.eye(2))
    np.testing.assert_array_equal(response.x, before[0])
    np.testing.assert_array_equal(K, before[1])
    assert scipy.linalg.norm(K) > 0


def test_compared_draws_held_samples_as_steps() -> None:
    lag = aerocontrol.StateSpace([[-1.0]], [[1.0]], state_names=["beta"])
    t = np.arange(0.0, 3.0, 0.5)
    continuous = aerocontrol.initial_response(lag, [1.0], T=t)
    sampled = aerocontrol.initial_response(aerocontrol.c2d(lag, 0.5), [1.0], T=t)
    ax = plotting.plot_compared(
        {"continuous": (continuous, "beta"), "2 Hz": (sampled, "beta")}, held=["2 Hz"]
    )
    lines = ax.get_lines()
    assert [line.get_drawstyle() for line in lines] == ["default", "steps-post"]
    assert [line.get_label() for line in lines] == ["continuous", "2 Hz"]
    # The samples of e^{-t}, exactly (the zero-order hold of a free response).
    assert np.allclose(lines[1].get_ydata(), np.exp(-t), rtol=1e-14)
    with pytest.raises(aerocontrol.InvalidArgumentError, match="neither a state nor an output"):
        plotting.plot_compared({"x": (continuous, "phi")})
    plt.close("all")


def test_marked_weights_without_a_logarithm_are_marked_deliberately() -> None:
    """A gain of 0 marked on a sweep from k = 0 compared log(0) - log(0) (NaN, numpy's
    'invalid value' warning, seen in the report of an extreme aircraft). An equal weight is
    marked as it is, an infinite value at the largest weight, a negative one at the nearest
    by difference, and a NaN is not marked and says so in the legend."""
    weights = np.array([0.0, 0.5, 1.0, 2.0])
    poles = np.column_stack([-1.0 - weights, -2.0 + 1j * weights])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ax = plotting.plot_root_locus(weights, poles, marked=[0.0, np.inf, -1.0, np.nan, 0.9])
        ax.figure.canvas.draw()
    assert _labels(ax) == ["c = 0", "c = 2", "c = 0", "c = nan: not marked", "c = 1"]
    marks = [line for line in ax.get_lines() if line.get_label() == "c = 2"]
    np.testing.assert_array_equal(marks[0].get_xdata(), poles[-1].real)


def test_values_that_cannot_be_drawn_are_masked_with_a_note() -> None:
    """Roots and responses beyond ±1e300, infinite or NaN: matplotlib's autoscaling of data
    spanning ±1e308 overflowed (numpy's warning from inside matplotlib). They are left out as
    gaps, and a note on the axes counts them; finite values are drawn as they are."""
    weights = np.array([0.0, 1.0, 2.0])
    poles = np.array([[np.inf, -1.0], [np.nan, -2.0 + 1.0j], [1e308, -1e308]])
    lag = aerocontrol.StateSpace(np.array([[-20.0, 0.0], [0.0, -2.0]]), np.ones((2, 1)))
    # 1e301 e^(-20 t): beyond ±1e300 at t = 0 only (6.7e298 at t = 0.25).
    response = aerocontrol.initial_response(lag, [1e301, -1.0], T=np.linspace(0.0, 1.0, 5))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ax = plotting.plot_root_locus(weights, poles, marked=[1.0])
        ax.figure.canvas.draw()
        drawn = response.plot()
        drawn.figure.canvas.draw()
    # inf, NaN, 1e308 and -1e308 on the paths, and the NaN of the marked row.
    assert [text.get_text() for text in ax.texts] == [
        "5 values not drawn (NaN, infinite or beyond ±1e300)"
    ]
    assert drawn.texts[0].get_text().startswith("1 value not drawn")
    first = drawn.get_lines()[0].get_ydata()
    assert np.isnan(first[0]) and np.array_equal(first[1:], response.states()[1:, 0])
    assert response.states()[0, 0] == 1e301  # the result itself is not changed


@pytest.mark.parametrize(
    "call",
    [
        lambda: plotting.closed_loop_gain_contour(3.0, count=0),
        lambda: plotting.closed_loop_gain_contour(3.0, count=2.5),
        lambda: plotting.closed_loop_phase_contour(-90.0, count=True),
    ],
)
def test_nichols_contours_refuse_a_bad_count(call: Any) -> None:
    with pytest.raises(InvalidArgumentError, match="count must be a positive int"):
        call()


def test_nichols_contours_refuse_a_non_number() -> None:
    with pytest.raises(NotRealError, match="gain_db"):
        plotting.closed_loop_gain_contour("3 dB")  # type: ignore[arg-type]
    with pytest.raises(NotRealError, match="phase_deg"):
        plotting.closed_loop_phase_contour(1j)  # type: ignore[arg-type]
