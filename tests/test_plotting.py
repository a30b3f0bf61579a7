"""Plots draw with no display (Agg), label their axes, and name the lines."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import aerocontrol

A, B = aerocontrol.chapter.boeing747_longitudinal()
SYS = aerocontrol.StateSpace(A, B, state_names=["u/u0", "alpha", "q", "theta"])


@pytest.fixture(autouse=True)
def _close_figures():  # type: ignore[no-untyped-def]
    yield
    plt.close("all")


def test_time_response_plot() -> None:
    ax = aerocontrol.step_response(SYS, T=20.0).plot()
    assert ax.get_xlabel() == "time (s)"
    assert [line.get_label() for line in ax.get_lines()] == ["u/u0", "alpha", "q", "theta"]
    _, given = plt.subplots()
    assert aerocontrol.impulse_response(SYS, T=5.0).plot(ax=given, signal="outputs") is given


def test_bode_and_modes_plots() -> None:
    magnitude_axis, phase_axis = aerocontrol.bode(SYS).plot()
    assert magnitude_axis.get_ylabel() == "magnitude (dB)"
    assert phase_axis.get_xlabel() == "frequency (rad/s)"
    ax = aerocontrol.modes(A, mode_names=["phugoid", "short period"]).plot()
    labels = [line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")]
    assert labels == ["phugoid", "short period"]
    assert np.isclose(len(ax.get_lines()[0].get_xdata()), 2)
