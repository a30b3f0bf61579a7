"""Other flight conditions of an aircraft (Aircraft.at) and the envelope sweep of its Levels."""

from __future__ import annotations

import dataclasses
import math
import re

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import aerocontrol
from aerocontrol import aircraft, handling
from aerocontrol.aircraft.naming import classify_modes

B747 = aircraft.load()
WEIGHT = B747.mass * B747.gravity


def _levels(plane: aircraft.Aircraft) -> dict[str, int]:
    named = {
        **classify_modes(plane.modes("longitudinal"), "longitudinal"),
        **classify_modes(plane.modes("lateral"), "lateral"),
    }
    return handling.assess(named, plane.aircraft_class, plane.category).levels


def test_at_its_own_condition_is_the_file() -> None:
    same = B747.at()
    assert same.derivatives == B747.derivatives
    assert np.array_equal(same.longitudinal().A, B747.longitudinal().A)
    assert np.array_equal(same.lateral().B, B747.lateral().B)


def test_at_another_condition_trims_and_follows_the_polar() -> None:
    """Standard atmosphere at the new altitude, u0 = M a, CL ∝ W / q̄, CD on the polar through
    the file's point with the file's slope dCD/dCL = CD_alpha / CL_alpha."""
    moved = B747.at(altitude=15_000.0, mach=0.4, weight=0.8 * WEIGHT)
    air = aircraft.standard_atmosphere(15_000.0, "english")
    assert moved.density == air.density
    assert moved.speed == pytest.approx(0.4 * air.speed_of_sound, rel=1e-15)
    q_file = 0.5 * B747.density * B747.speed**2
    q_new = 0.5 * air.density * moved.speed**2
    assert moved.derivatives["CL"] * q_new == pytest.approx(
        0.8 * B747.derivatives["CL"] * q_file, rel=1e-14
    )
    c = B747.derivatives
    k = c["CD_alpha"] / (2 * c["CL"] * c["CL_alpha"])
    CD0 = c["CD"] - k * c["CL"] ** 2
    assert moved.derivatives["CD"] == pytest.approx(CD0 + k * moved.derivatives["CL"] ** 2)
    unchanged = {key for key in c if key not in ("CL", "CD")}
    assert all(moved.derivatives[key] == c[key] for key in unchanged)
    assert (moved.Ix, moved.Iz, moved.S) == (B747.Ix, B747.Iz, B747.S)
    assert moved.name == "Boeing 747, powered approach @ M = 0.4, 15000 ft, W = 451226 lbf"
    assert moved.published == {}
    # The chapter's Xu = -ρ S u0 CD / m (6.48 with CD_M = 0) at the new condition.
    Xu = -moved.density * moved.S * moved.speed * moved.derivatives["CD"] / moved.mass
    assert moved.dimensional_longitudinal()["Xu"] == pytest.approx(Xu, rel=1e-14)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"mach": -0.2}, "mach must be positive, got -0.2"),
        ({"weight": 0.0}, "weight must be positive, got 0"),
        ({"altitude": math.nan}, "altitude must be finite"),
        ({"altitude": "high"}, "altitude must be an array of real numbers"),
    ],
)
def test_at_rejects_bad_conditions(arguments: dict[str, object], message: str) -> None:
    with pytest.raises(aerocontrol.AerocontrolError, match=message):
        B747.at(**arguments)  # type: ignore[arg-type]


def test_envelope_sweep_matches_each_condition_alone() -> None:
    altitudes, machs, weights = [0.0, 8_000.0, 16_000.0], [0.2, B747.mach, 0.4], [WEIGHT]
    env = aircraft.envelope_sweep(B747, altitudes, machs, weights)
    assert env.shape == (3, 3, 1) and env.failures == {}
    for index in np.ndindex(env.shape):
        i, j, k = index
        expected = _levels(B747.at(altitudes[i], machs[j], weights[k]))
        assert {mode: int(env.levels[mode][index]) for mode in expected} == expected
        assert env.worst[index] == max(expected.values())
    # The chapter's own condition: Dutch roll Level 2 (ζ ω_n = 0.081 < 0.10), eigenvalue (6.152).
    assert env.levels["dutch roll"][0, 1, 0] == 2
    assert env.eigenvalues["dutch roll"][0, 1, 0] == pytest.approx(-0.08066 + 0.74331j, abs=1e-5)
    assert "dutch roll" in env.table().splitlines()[0]
    assert len(env.table().splitlines()) == 1 + 9


def test_envelope_sweep_with_derivatives_and_failures() -> None:
    """The caller's derivatives per condition are used, and a condition that fails is
    recorded with its reason while the sweep goes on."""

    def bigger_fin(plane: aircraft.Aircraft) -> aircraft.Aircraft:
        if plane.mach > 0.35:
            raise aerocontrol.InvalidArgumentError("no data above M = 0.35")
        return dataclasses.replace(
            plane, derivatives={**plane.derivatives, "Cn_beta": 1.2 * plane.derivatives["Cn_beta"]}
        )

    env = aircraft.envelope_sweep(B747, machs=[B747.mach, 0.4], derivatives=bigger_fin)
    direct = dataclasses.replace(
        B747, derivatives={**B747.derivatives, "Cn_beta": 1.2 * B747.derivatives["Cn_beta"]}
    )
    named = classify_modes(direct.modes("lateral"), "lateral")
    assert env.eigenvalues["dutch roll"][0, 0, 0] == named["dutch roll"][0]
    assert env.failures == {(0, 1, 0): "no data above M = 0.35"}
    assert env.worst[0, 1, 0] == 0


def test_envelope_plot() -> None:
    env = aircraft.envelope_sweep(B747, altitudes=[0.0, 10_000.0], machs=[0.2, 0.3, 0.4])
    ax = env.plot()
    assert ax.get_ylabel() == "altitude (ft)" and ax.get_xlabel() == "Mach number"
    assert sorted(t.get_text() for t in ax.texts) == sorted(
        str(v) for v in env.worst[:, :, 0].ravel()
    )
    assert "worst mode" in ax.get_title()
    ax = env.plot(mode="dutch roll")
    assert ax.get_title().startswith("dutch roll")
    with pytest.raises(aerocontrol.ShapeError, match="levels must be"):
        aerocontrol.plotting.plot_levels([0.2], [0.0, 1.0], np.ones((3, 3)))
    plt.close("all")


def test_envelope_rejects_bad_grids() -> None:
    with pytest.raises(aerocontrol.ShapeError, match="machs must be a non-empty 1-D array"):
        aircraft.envelope_sweep(B747, machs=[])
    with pytest.raises(aerocontrol.InvalidArgumentError, match="plane must be an Aircraft"):
        aircraft.envelope_sweep("b747-approach")  # type: ignore[arg-type]


def test_nonsense_conditions_are_failures_and_the_sweep_goes_on() -> None:
    """machs=[1e300] once stopped the whole sweep with an OverflowError; now each such
    condition is a failure with its reason, and the others are assessed."""
    env = aircraft.envelope_sweep(
        B747, altitudes=[0.0, 1e300], machs=[B747.mach, 1e300, 1e-300], weights=[WEIGHT, 1e300]
    )
    assert env.shape == (2, 3, 2)
    # The file's own condition is assessed as alone: Dutch roll Level 2.
    assert env.levels["dutch roll"][0, 0, 0] == 2 and (0, 0, 0) not in env.failures
    assert env.failures[(0, 1, 0)] == "mach = 1e+300 is outside the plausible range 0.001 to 12"
    assert env.failures[(0, 2, 0)] == "mach = 1e-300 is outside the plausible range 0.001 to 12"
    assert env.failures[(0, 0, 1)] == (
        "weight = 1e+300 lbf is outside the plausible range 0.1 to 4.5e+06 lbf"
    )
    assert env.failures[(1, 0, 0)] == (
        "altitude = 1e+300 ft is outside the plausible range -16400 to 282000 ft"
    )
    assert set(env.failures) == set(np.ndindex(env.shape)) - {(0, 0, 0)}
    assert all(env.worst[index] == 0 for index in env.failures)


@pytest.mark.parametrize(
    ("failure", "reason"),
    [
        (lambda plane: 1e300**2, r"OverflowError: \(34, 'Numerical result out of range'\)"),
        (lambda plane: np.float64(1.0) / np.float64(0.0), "FloatingPointError: divide by zero.*"),
        (lambda plane: math.sqrt(-1.0), "ValueError: math domain error"),
        (lambda plane: 1 / 0, "ZeroDivisionError: division by zero"),
        # Named where the model is built (it was Python's OverflowError of u0**2).
        (
            lambda plane: dataclasses.replace(plane, speed=plane.speed * 1e200),
            r"Boeing 747, powered approach @ .*: the longitudinal model overflows",
        ),
        # Refused when the aircraft is made (it was a ZeroDivisionError in the model).
        (
            lambda plane: dataclasses.replace(plane, Ix=0.0),
            "Aircraft: Ix must be positive, got 0.0",
        ),
        (
            lambda plane: dataclasses.replace(plane, Iy=1e-320),
            r"Boeing 747, powered approach @ .*: the longitudinal model overflows",
        ),
        (
            lambda plane: aerocontrol.linalg.expm(np.array([[1.0, math.nan], [0.0, 1.0]])),
            r"A must be finite, but A\[0, 1\] is NaN",
        ),
        (lambda plane: np.linalg.inv(np.zeros((2, 2))), "LinAlgError: Singular matrix"),
    ],
    ids=[
        "overflow",
        "floating-point",
        "domain",
        "zero-division",
        "speed",
        "no-inertia",
        "tiny-inertia",
        "core",
        "linalg",
    ],
)
def test_an_arithmetic_or_numerical_failure_of_one_condition_is_recorded(
    failure: object, reason: str
) -> None:
    def derivatives(plane: aircraft.Aircraft) -> aircraft.Aircraft:
        if plane.mach > 0.3:
            with np.errstate(all="raise"):
                return failure(plane)  # type: ignore[operator, no-any-return]
        return plane

    env = aircraft.envelope_sweep(B747, machs=[B747.mach, 0.4], derivatives=derivatives)
    assert (0, 0, 0) not in env.failures and env.worst[0, 0, 0] == 2
    assert list(env.failures) == [(0, 1, 0)]
    assert re.fullmatch(reason, env.failures[(0, 1, 0)]), env.failures


def test_what_is_wrong_with_the_call_as_a_whole_raises() -> None:
    with pytest.raises(aerocontrol.InvalidArgumentError, match="machs must be finite"):
        aircraft.envelope_sweep(B747, machs=[0.2, math.nan])
    with pytest.raises(aerocontrol.InvalidArgumentError, match="altitudes must be finite"):
        aircraft.envelope_sweep(B747, altitudes=[math.inf])
    with pytest.raises(
        aerocontrol.InvalidArgumentError, match="derivatives must return an Aircraft, got NoneType"
    ):
        aircraft.envelope_sweep(B747, derivatives=lambda plane: None)  # type: ignore[arg-type, return-value]

    def buggy(plane: aircraft.Aircraft) -> aircraft.Aircraft:
        return plane.derivatives["no such key"]  # type: ignore[return-value]

    with pytest.raises(KeyError, match="no such key"):  # a bug in the callback is not hidden
        aircraft.envelope_sweep(B747, derivatives=buggy)
