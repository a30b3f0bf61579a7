"""Plots of responses, frequency responses and modes (matplotlib).

The only module that imports matplotlib, and only when a plot is asked for. Every function
takes ``ax=`` (a new figure when None), labels its axes with units, and returns what it drew.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .frequency import FrequencyResponse
    from .modal import Modes
    from .responses import TimeResponse

__all__ = ["plot_bode", "plot_modes", "plot_time_response"]


def _new_axes(rows: int = 1) -> Any:
    import matplotlib.pyplot as plt

    _, axes = plt.subplots(rows, 1, sharex=True, squeeze=True)
    return axes


def plot_time_response(
    result: TimeResponse, ax: Any = None, signal: str = "states", response: int = 0
) -> Any:
    """States (``signal="states"``) or outputs of one response against time, one named line
    each. Returns the axes."""
    if signal not in ("states", "outputs"):
        raise ValueError(f"signal must be 'states' or 'outputs', got {signal!r}")
    ax = _new_axes() if ax is None else ax
    if signal == "states":
        values, names = result.states(response), result.state_names
    else:
        values, names = result.outputs(response), result.output_names
    for column, name in zip(values.T, names, strict=True):
        ax.plot(result.t, column, label=name)
    ax.set_xlabel("time (s)")
    ax.set_ylabel(f"{signal} (model units: rad, rad/s, or normalised speed)")
    title = f"{result.kind} response"
    if result.n_responses > 1:
        title += f": {result.response_names[response]}"
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_bode(result: FrequencyResponse, ax: Any = None, output: int = 0, input: int = 0) -> Any:
    """Magnitude (dB) and phase (degrees) against frequency (rad/s, log scale) of one
    input-output pair, on a pair of axes. Returns the pair."""
    axes = _new_axes(2) if ax is None else ax
    magnitude_axis, phase_axis = axes
    label = f"{result.input_names[input]} -> {result.output_names[output]}"
    magnitude_axis.semilogx(result.omega, result.magnitude_db[:, output, input], label=label)
    phase_axis.semilogx(result.omega, result.phase_deg[:, output, input], label=label)
    magnitude_axis.set_ylabel("magnitude (dB)")
    phase_axis.set_ylabel("phase (deg)")
    phase_axis.set_xlabel("frequency (rad/s)")
    for axis in axes:
        axis.grid(True, which="both", alpha=0.3)
    magnitude_axis.legend(loc="best", fontsize="small")
    return axes


def plot_modes(modes: Modes, ax: Any = None) -> Any:
    """The eigenvalues in the complex plane (rad/s), one marker and label per mode."""
    ax = _new_axes() if ax is None else ax
    for k, name in enumerate(modes.mode_names):
        lam = modes.eigenvalue[k]
        points = np.array([lam, np.conj(lam)]) if modes.oscillatory[k] else np.array([lam])
        ax.plot(points.real, points.imag, "x", markersize=9, label=name)
    ax.axvline(0.0, color="black", linewidth=0.8)
    ax.axhline(0.0, color="black", linewidth=0.8)
    ax.set_xlabel("real part (1/s)")
    ax.set_ylabel("imaginary part (rad/s)")
    ax.set_title("modes")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return ax
