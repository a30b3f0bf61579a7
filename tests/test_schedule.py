"""Gain schedules over the flight envelope (aerocontrol.schedule): the gains at the grid points
against the one-condition designs (aerocontrol.lqr, design.dutch_roll_damper), the multilinear
interpolation against gain tables that are themselves multilinear, the closed-loop Levels
against handling.assess of each closed loop built one condition at a time, the named errors,
the plots, and the Dask run against the local one, bitwise."""

from __future__ import annotations

import dataclasses

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import aerocontrol
from aerocontrol import aircraft, design, plotting
from aerocontrol import schedule as schedule_module
from aerocontrol.aircraft.naming import classify_modes
from aerocontrol.exceptions import InvalidArgumentError, ShapeError
from aerocontrol.handling import assess
from aerocontrol.schedule import GainSchedule, gain_schedule

PLANE = aircraft.load()  # the 747 on approach: Class III, Category C
ALTITUDES = [0.0, 8000.0, 20000.0]
MACHS = [0.2, 0.28, 0.45]
WEIGHTS = [450e3, 564032.0, 650e3]


def _relative(actual: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(actual - expected)) / np.max(np.abs(expected)))


def _one_condition(
    plane: aircraft.Aircraft, axis: str, K: np.ndarray, altitude: float, mach: float, weight: float
) -> tuple[dict[str, int], np.ndarray]:
    """The closed loop built and judged one condition at a time, as envelope_sweep judges a
    condition: the Level of each mode (0 where not assessed; a roll and spiral coupled into
    one oscillation both carry its Level, MIL-F-8785C 3.3.1.4) and the eigenvalues."""
    condition = plane.at(altitude, mach, weight)
    sys = condition.lateral() if axis == "lateral" else condition.longitudinal()
    closed = sys.A - sys.B @ K
    named = classify_modes(aerocontrol.modes(closed), axis)
    modes = ("dutch roll", "roll", "spiral") if axis == "lateral" else ("short period", "phugoid")
    judged = assess(
        {m: named[m] for m in (*modes, "roll-spiral") if m in named},
        plane.aircraft_class,
        plane.category,
    )
    levels = {m: judged.levels.get(m, 0) for m in modes}
    if "roll-spiral" in judged.levels:
        levels["roll"] = levels["spiral"] = judged.levels["roll-spiral"]
    return levels, np.linalg.eigvals(closed)


# --- The models and the design at the grid points ---------------------------------------------


@pytest.mark.parametrize("axis", ["lateral", "longitudinal"])
def test_models_in_bulk_are_bitwise_the_conditions_own(axis: str) -> None:
    conditions = schedule_module._conditions(
        np.array(ALTITUDES), np.array(MACHS), np.array(WEIGHTS)
    )
    A, B, _ = schedule_module._models(PLANE, axis, conditions)
    for k, (h, m, w) in enumerate(conditions):
        condition = PLANE.at(h, m, w)
        sys = condition.lateral() if axis == "lateral" else condition.longitudinal()
        np.testing.assert_array_equal(A[k], sys.A)
        np.testing.assert_array_equal(B[k], sys.B)


@pytest.mark.parametrize(
    ("axis", "c", "Q", "R"),
    [
        ("lateral", 1.0, None, None),
        ("lateral", 0.25, np.diag([4.0, 1.0, 2.0, 0.5]), np.diag([1.0, 3.0])),
        ("longitudinal", 3.0, np.diag([1.0, 2.0, 1.0, 5.0]), None),
    ],
)
def test_lqr_gains_at_grid_points_are_the_one_condition_design(
    axis: str, c: float, Q: np.ndarray | None, R: np.ndarray | None
) -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, c=c, Q=Q, R=R, axis=axis)
    m = 2 if axis == "lateral" else 1
    assert schedule.gains.shape == (3, 3, 3, m, 4)
    Q_ = np.eye(4) if Q is None else Q
    R_ = np.eye(m) if R is None else R
    for i, j, k in np.ndindex(3, 3, 3):
        condition = PLANE.at(ALTITUDES[i], MACHS[j], WEIGHTS[k])
        sys = condition.lateral() if axis == "lateral" else condition.longitudinal()
        K, _, _ = aerocontrol.lqr(sys.A, sys.B, Q_, R_ / c**2)
        assert _relative(schedule.gains[i, j, k], K) < 1e-12, (i, j, k)


def test_damper_gains_at_grid_points_are_the_one_condition_damper() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, design="damper", zeta=0.2)
    rudder = schedule.input_names.index("rudder")
    assert schedule.input_names == ("rudder", "aileron")
    for i, j, k in np.ndindex(schedule.shape):
        damper = design.dutch_roll_damper(
            PLANE.at(ALTITUDES[i], MACHS[j], WEIGHTS[k]), zeta=0.2, surface="rudder"
        )
        assert _relative(schedule.gains[i, j, k, rudder], damper.k) < 1e-12
        assert (schedule.gains[i, j, k, 1 - rudder] == 0.0).all()
        # The damper's Dutch roll: ζ = 0.2 at every design point.
        root = schedule.closed_loop.eigenvalues["dutch roll"][i, j, k]
        assert abs(-root.real / abs(root) - 0.2) < 1e-9


def test_defaults_are_the_file_condition() -> None:
    schedule = gain_schedule(PLANE, None, None)
    assert schedule.shape == (1, 1, 1)
    K, _, _ = aerocontrol.lqr(PLANE.lateral().A, PLANE.lateral().B, np.eye(4), np.eye(2))
    assert _relative(schedule.gains[0, 0, 0], K) < 1e-12
    # One point on every axis: the gains are constant over the envelope.
    np.testing.assert_array_equal(schedule.gains_at(15000.0, 0.4, 5e5), schedule.gains[0, 0, 0])


# --- Interpolation ------------------------------------------------------------------------------


def _multilinear_schedule() -> tuple[GainSchedule, object]:
    """A schedule over an uneven grid whose gain table is multilinear in (h, M, W), and the
    function that table samples."""
    schedule = gain_schedule(PLANE, [0.0, 3000.0, 12000.0, 20000.0], [0.2, 0.23, 0.4], WEIGHTS)
    rng = np.random.default_rng(4)
    coefficients = rng.standard_normal((8, 2, 4))

    def table(h: np.ndarray, m: np.ndarray, w: np.ndarray) -> np.ndarray:
        x, y, z = h / 20000.0, m / 0.4, w / 650e3
        terms = [1.0 + 0 * x, x, y, z, x * y, x * z, y * z, x * y * z]
        return sum(t[..., None, None] * c for t, c in zip(terms, coefficients, strict=True))

    mesh = np.meshgrid(schedule.altitudes, schedule.machs, schedule.weights, indexing="ij")
    return dataclasses.replace(schedule, gains=table(*mesh)), table


def test_interpolation_is_exact_for_a_multilinear_table() -> None:
    schedule, table = _multilinear_schedule()
    rng = np.random.default_rng(7)
    h = rng.uniform(0.0, 20000.0, 200)
    m = rng.uniform(0.2, 0.4, 200)
    w = rng.uniform(450e3, 650e3, 200)
    expected = table(h, m, w)
    actual = schedule.gains_at(h, m, w)
    assert actual.shape == (200, 2, 4)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    # The grid's ends and interior points.
    edges = schedule.gains_at([0.0, 20000.0], [0.4, 0.2], [650e3, 450e3])
    np.testing.assert_allclose(
        edges,
        table(np.array([0.0, 20000.0]), np.array([0.4, 0.2]), np.array([650e3, 450e3])),
        rtol=0,
        atol=1e-12 * np.abs(expected).max(),
    )


def test_interpolation_at_grid_points_is_the_table() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, design="damper")
    mesh = np.meshgrid(ALTITUDES, MACHS, WEIGHTS, indexing="ij")
    np.testing.assert_array_equal(schedule.gains_at(*mesh), schedule.gains)


def test_interpolation_is_linear_along_each_axis_and_broadcasts() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS)
    # A third of the way along one Mach cell, on a grid altitude and weight.
    m = MACHS[0] + (MACHS[1] - MACHS[0]) / 3.0
    expected = (2.0 * schedule.gains[1, 0, 2] + schedule.gains[1, 1, 2]) / 3.0
    np.testing.assert_allclose(schedule.gains_at(8000.0, m, 650e3), expected, rtol=1e-12)
    # Broadcasting: (5, 1) altitudes with (4,) Machs.
    h = np.linspace(0.0, 20000.0, 5)[:, None]
    mm = np.linspace(0.2, 0.45, 4)
    gains = schedule.gains_at(h, mm, 600e3)
    assert gains.shape == (5, 4, 2, 4)
    np.testing.assert_array_equal(gains[3, 2], schedule.gains_at(h[3, 0], mm[2], 600e3))
    # Without a weight: the file's weight (a grid point here).
    np.testing.assert_array_equal(schedule.gains_at(8000.0, 0.28), schedule.gains[1, 1, 1])


# --- Errors -----------------------------------------------------------------------------------


def test_conditions_outside_the_grid_raise_naming_the_argument_and_range() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS)
    with pytest.raises(InvalidArgumentError, match=r"altitude must lie .*\[0.0, 20000.0\].* -1"):
        schedule.gains_at(-1.0, 0.3, 5e5)
    # Just outside: the value as given, not 20000 (:g) beside the range's 20000.
    with pytest.raises(InvalidArgumentError, match=r"20000.0\], got 20000.0001$"):
        schedule.gains_at(20000.0001, 0.3, 5e5)
    with pytest.raises(InvalidArgumentError, match=r"mach must lie .*\[0.2, 0.45\].* 0.5"):
        schedule.gains_at(1000.0, [0.3, 0.5], 5e5)
    with pytest.raises(InvalidArgumentError, match=r"weight must lie .*\[450000.0, 650000.0\]"):
        schedule.gains_at(1000.0, 0.3, 7e5)
    with pytest.raises(InvalidArgumentError, match="mach must be finite"):
        schedule.gains_at(1000.0, np.nan, 5e5)
    with pytest.raises(ShapeError, match="broadcast"):
        schedule.gains_at([0.0, 1.0], [0.3, 0.3, 0.3], 5e5)
    with pytest.raises(aerocontrol.NotRealError, match="altitude"):
        schedule.gains_at(1j, 0.3, 5e5)
    with pytest.raises(InvalidArgumentError, match=r"machs must lie .*\[0.2, 0.45\]"):
        schedule.evaluate(ALTITUDES, [0.1, 0.3], WEIGHTS)
    with pytest.raises(ShapeError, match="altitudes must be a non-empty 1-D"):
        schedule.evaluate([[0.0, 1.0]], MACHS, WEIGHTS)


@pytest.mark.parametrize(
    ("arguments", "error", "pattern"),
    [
        ({"plane": "b747"}, InvalidArgumentError, "plane must be an Aircraft"),
        ({"design": "pid"}, InvalidArgumentError, "design must be one of"),
        ({"axis": "vertical"}, InvalidArgumentError, "axis must be"),
        ({"design": "damper", "axis": "longitudinal"}, InvalidArgumentError, "damper"),
        ({"c": 0.0}, InvalidArgumentError, "c must be positive"),
        ({"c": np.inf}, InvalidArgumentError, "c must be positive"),
        ({"c": [1.0, 2.0]}, ShapeError, "c must be a scalar"),
        ({"c": 1e200}, InvalidArgumentError, "c must be positive"),  # c² overflows
        ({"c": 1e-200}, InvalidArgumentError, "c must be positive"),  # c² underflows to 0
        ({"axis": ["lateral"]}, InvalidArgumentError, "axis must be"),
        ({"Q": np.eye(3)}, ShapeError, "Q must be 4 x 4"),
        ({"R": np.eye(1)}, ShapeError, "R must be 2 x 2"),
        ({"altitudes": [0.0, 20000.0, 8000.0]}, InvalidArgumentError, "altitudes must be strictly"),
        ({"machs": [0.3, 0.3]}, InvalidArgumentError, "machs must be strictly"),
        ({"machs": []}, ShapeError, "machs must be a non-empty 1-D"),
        ({"weights": [4e5, np.nan]}, InvalidArgumentError, "weights must be finite"),
        ({"machs": [0.2, 50.0]}, InvalidArgumentError, "mach"),
    ],
)
def test_bad_arguments_raise_named_errors(
    arguments: dict[str, object], error: type[Exception], pattern: str
) -> None:
    call: dict[str, object] = {
        "plane": PLANE,
        "altitudes": ALTITUDES,
        "machs": MACHS,
        "weights": WEIGHTS,
        **arguments,
    }
    with pytest.raises(error, match=pattern):
        gain_schedule(**call)  # type: ignore[arg-type]


# --- Closed-loop Levels -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kind", "options"),
    [("damper", {"zeta": 0.1}), ("lqr", {"c": 10.0}), ("lqr", {"axis": "longitudinal"})],
)
def test_levels_at_grid_points_are_assess_of_each_closed_loop(
    kind: str, options: dict[str, object]
) -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, design=kind, **options)
    envelope = schedule.closed_loop
    seen: set[int] = set()
    coupled_seen = False
    for i, j, k in np.ndindex(schedule.shape):
        levels, poles = _one_condition(
            PLANE, schedule.axis, schedule.gains[i, j, k], ALTITUDES[i], MACHS[j], WEIGHTS[k]
        )
        for mode, level in levels.items():
            assert envelope.levels[mode][i, j, k] == level, (mode, i, j, k)
            seen.add(level)
            value = envelope.eigenvalues[mode][i, j, k]
            coupled = mode in ("roll", "spiral") and np.all(np.iscomplex(poles))
            if coupled:  # judged as the roll-spiral: no real root of its own
                assert np.isnan(value)
                coupled_seen = True
            elif level:  # a judged mode's eigenvalue is one of the closed loop's
                assert np.min(np.abs(poles - value)) < 1e-10 * np.max(np.abs(poles))
        assert ((i, j, k) in envelope.failures) == (0 in levels.values())
    # The evaluation at the design grid is the design's own judgement.
    again = schedule.evaluate(ALTITUDES, MACHS, WEIGHTS)
    for mode in envelope.levels:
        np.testing.assert_array_equal(again.levels[mode], envelope.levels[mode])
        np.testing.assert_array_equal(again.eigenvalues[mode], envelope.eigenvalues[mode])
    assert again.failures == envelope.failures
    if kind == "damper":  # the checks met more than one Level
        assert {1, 2, 3} <= seen
    if options.get("c") == 10.0:  # and roll-spiral oscillations, judged by 3.3.1.4
        assert coupled_seen and not envelope.failures and 0 not in seen


def test_levels_between_grid_points_use_the_interpolated_gains() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, design="damper", zeta=0.1)
    altitudes = np.linspace(0.0, 20000.0, 7)
    machs = np.linspace(0.2, 0.45, 6)
    weights = [500e3, 620e3]
    envelope = schedule.evaluate(altitudes, machs, weights)
    assert envelope.shape == (7, 6, 2)
    seen = set()
    for (i, j, k), _ in np.ndenumerate(envelope.levels["dutch roll"]):
        K = schedule.gains_at(altitudes[i], machs[j], weights[k])
        levels, _ = _one_condition(PLANE, "lateral", K, altitudes[i], machs[j], weights[k])
        for mode, level in levels.items():
            assert envelope.levels[mode][i, j, k] == level, (mode, i, j, k)
            seen.add(level)
    assert {1, 2} <= seen
    # Off the design grid the interpolated damper is not the local design: ζ differs from 0.1.
    poles = envelope.eigenvalues["dutch roll"][3, 2, 0]
    assert abs(-poles.real / abs(poles) - 0.1) > 1e-4


def test_evaluate_on_chunks_and_on_a_dask_cluster_is_bitwise_the_local_run(
    monkeypatch: pytest.MonkeyPatch, dask_client: object
) -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, c=10.0)
    grids = (np.linspace(0.0, 20000.0, 5), np.linspace(0.2, 0.45, 7), [480e3, 600e3])
    whole = schedule.evaluate(*grids)
    monkeypatch.setattr(schedule_module, "CHUNK_SIZE", 9)  # 70 conditions in 8 chunks
    chunked = schedule.evaluate(*grids)
    remote = schedule.evaluate(*grids, client=dask_client)
    designed = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, c=10.0, client=dask_client)
    for other in (chunked, remote):
        for mode in whole.levels:
            np.testing.assert_array_equal(other.levels[mode], whole.levels[mode])
            np.testing.assert_array_equal(other.eigenvalues[mode], whole.eigenvalues[mode])
        assert other.failures == whole.failures
    # The comparison covers conditions whose roll and spiral coupled (judged by 3.3.1.4) too.
    coupled = np.isnan(whole.eigenvalues["roll"])
    assert coupled.any() and np.all(whole.levels["roll"][coupled] > 0)
    for mode in whole.levels:
        np.testing.assert_array_equal(
            designed.closed_loop.levels[mode], schedule.closed_loop.levels[mode]
        )


# --- Plots -------------------------------------------------------------------------------------


def test_gain_schedule_plot_draws_each_entry_against_mach() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, design="damper")
    panels = plotting.plot_gain_schedule(schedule, weight=2)
    assert len(panels) == 8
    first = panels[0]
    assert len(first.get_lines()) == len(ALTITUDES)
    np.testing.assert_array_equal(first.get_lines()[1].get_xdata(), MACHS)
    np.testing.assert_array_equal(first.get_lines()[1].get_ydata(), schedule.gains[1, :, 2, 0, 0])
    assert first.get_xlabel() == "Mach number"
    assert [t.get_text() for t in first.get_legend().get_texts()] == [
        "0 ft",
        "8000 ft",
        "20000 ft",
    ]
    assert "sideslip" in first.get_title()
    plt.close("all")
    _figure, axes = plt.subplots(2, 4)
    assert schedule.plot(ax=axes)[5] is axes[1, 1]
    with pytest.raises(InvalidArgumentError, match="ax must hold 8"):
        plotting.plot_gain_schedule(schedule, ax=axes[0])
    with pytest.raises(InvalidArgumentError, match="weight must index"):
        plotting.plot_gain_schedule(schedule, ax=axes, weight=3)
    plt.close("all")


def test_envelope_levels_plot_draws_an_image_per_mode() -> None:
    schedule = gain_schedule(PLANE, ALTITUDES, MACHS, WEIGHTS, design="damper", zeta=0.1)
    envelope = schedule.evaluate(np.linspace(0, 20000, 5), np.linspace(0.2, 0.45, 6))
    panels = plotting.plot_envelope_levels(envelope)
    assert len(panels) == 3
    for panel, mode in zip(panels, envelope.levels, strict=True):
        assert panel.get_title().startswith(mode)
        assert panel.get_ylabel() == "altitude (ft)"
        image = panel.collections[0].get_array()
        np.testing.assert_array_equal(
            np.asarray(image).reshape(5, 6), envelope.levels[mode][:, :, 0]
        )
    _figure, axes = plt.subplots(1, 2)
    with pytest.raises(InvalidArgumentError, match="ax must hold 3"):
        plotting.plot_envelope_levels(envelope, ax=axes)
    plt.close("all")
