"""The flight envelope swept in one call: a grid of flight conditions (altitude, Mach, weight)
-> the models -> the modes -> the MIL-F-8785C Levels.

Each condition is the aircraft file's condition moved by
:meth:`~aerocontrol.aircraft.Aircraft.at` (standard atmosphere, trimmed CL, CD from the polar,
the other derivatives held), or the aircraft a caller's ``derivatives`` function returns for it
(for derivatives tabulated over Mach, say).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import handling
from .._results import Result, Tabular
from .._validation import real_array
from ..exceptions import AerocontrolError, AerocontrolWarning, InvalidArgumentError, ShapeError
from ..modal import modes
from .model import Aircraft
from .naming import classify_modes

__all__ = ["Envelope", "envelope_sweep"]

#: What a condition's Level is when it could not be assessed (see ``Envelope.failures``).
NOT_ASSESSED = 0

#: The exceptions that make one condition a failure of the sweep rather than of the call: a
#: condition outside the plausible ranges or the standard atmosphere (ValueError), arithmetic
#: that overflows (OverflowError, FloatingPointError, ZeroDivisionError), and a model the core
#: cannot analyse (AerocontrolError, numpy's LinAlgError; an AerocontrolWarning where the
#: caller has turned warnings into errors).
CONDITION_FAILURES: tuple[type[BaseException], ...] = (
    ArithmeticError,
    ValueError,
    np.linalg.LinAlgError,
    AerocontrolError,
    AerocontrolWarning,
)


@dataclass(frozen=True, eq=False)
class Envelope(Result):
    """The Levels of each mode over a grid of flight conditions.

    Arrays are indexed [altitude, Mach, weight].

    Attributes
    ----------
    altitudes : ndarray (a,)
        The altitudes of the grid (``length_unit``).
    machs : ndarray (b,)
        The Mach numbers of the grid.
    weights : ndarray (c,)
        The weights of the grid (``force_unit``).
    aircraft_class : str
        MIL-F-8785C class the Levels were judged for.
    category : str
        MIL-F-8785C flight-phase category the Levels were judged for.
    length_unit : str
        The unit of the altitudes ("ft" or "m").
    force_unit : str
        The unit of the weights ("lbf" or "N").
    levels : dict of str to ndarray (a, b, c) of int
        The Level of each mode (1-4) at each condition; 0 where it was not assessed. Where the
        roll and spiral couple into one oscillation, both carry its Level (MIL-F-8785C
        3.3.1.4).
    eigenvalues : dict of str to ndarray (a, b, c), complex
        Each mode's eigenvalue with Im >= 0 (rad/s; the larger real root of a split pair; NaN
        for a roll and spiral coupled into one oscillation).
    failures : dict of (int, int, int) to str
        Conditions whose model or modes could not be assessed, with the reason.
    worst : ndarray (a, b, c) of int
        The worst Level over the modes at each condition (0 where none was assessed).
    shape : tuple of int
        (a, b, c).

    Examples
    --------
    The 747 at the chapter's condition alone (sea level, M = 0.25, 564,032 lbf):

    >>> from aerocontrol import aircraft
    >>> env = aircraft.envelope_sweep(aircraft.load(), altitudes=[0], machs=[0.25],
    ...                               weights=[564032])
    >>> env.shape, env.length_unit, env.force_unit
    ((1, 1, 1), 'ft', 'lbf')
    >>> {mode: int(level[0, 0, 0]) for mode, level in env.levels.items()}
    {'short period': 1, 'phugoid': 2, 'dutch roll': 2, 'roll': 1, 'spiral': 1}
    >>> int(env.worst[0, 0, 0]), env.failures
    (2, {})
    """

    altitudes: NDArray[np.float64]
    machs: NDArray[np.float64]
    weights: NDArray[np.float64]
    aircraft_class: str
    category: str
    length_unit: str
    """The unit of the altitudes ("ft" or "m")."""
    force_unit: str
    """The unit of the weights ("lbf" or "N")."""
    levels: dict[str, NDArray[np.int_]]
    """The Level of each mode (1-4) at each condition; 0 where it was not assessed."""
    eigenvalues: dict[str, NDArray[np.complex128]]
    """Each mode's eigenvalue with Im >= 0 (the larger real root of a split pair)."""
    failures: dict[tuple[int, int, int], str]
    """Conditions whose model or modes could not be assessed, with the reason."""

    @property
    def worst(self) -> NDArray[np.int_]:
        """The worst Level over the modes at each condition (0 where none was assessed)."""
        worst: NDArray[np.int_] = np.stack(list(self.levels.values())).max(axis=0)
        return worst

    @property
    def shape(self) -> tuple[int, int, int]:
        return (len(self.altitudes), len(self.machs), len(self.weights))

    def _cells(self) -> tuple[list[str], list[list[str]]]:
        """The header and one row per condition: altitude, Mach, weight, each mode's Level
        and the worst."""
        modes_ = list(self.levels)
        header = ["altitude", "Mach", "weight", *modes_, "worst"]
        worst = self.worst
        rows = []
        for index in np.ndindex(self.shape):
            i, j, k = index
            cells = [f"{self.altitudes[i]:g}", f"{self.machs[j]:.3g}", f"{self.weights[k]:g}"]
            cells += [f"{self.levels[m][index]:d}" for m in modes_]
            cells.append(f"{worst[index]:d}")
            rows.append(cells)
        return header, rows

    def table(self) -> str:
        """One row per condition: altitude, Mach, weight and each mode's Level."""
        header, rows = self._cells()
        return "\n".join("  ".join(f"{cell:>12}" for cell in row) for row in [header, *rows])

    def _tables(self) -> list[Tabular]:
        header, rows = self._cells()
        header[0] += f" ({self.length_unit})"
        header[2] += f" ({self.force_unit})"
        title = (
            f"MIL-F-8785C Levels over the envelope: Class {self.aircraft_class}, Flight Phase "
            f"Category {self.category} (0: not assessed)"
        )
        notes = [
            f"not assessed at altitude {self.altitudes[i]:g}, Mach {self.machs[j]:.3g}, weight "
            f"{self.weights[k]:g}: {reason}"
            for (i, j, k), reason in self.failures.items()
        ]
        return [Tabular(title, header, rows, notes)]

    def plot(self, ax: Any = None, mode: str | None = None, weight: int = 0) -> Any:
        """The Levels over Mach (x) and altitude (y) at one weight of the grid: the worst over
        the modes, or one ``mode``'s. Returns the axes."""
        from ..plotting import plot_levels

        values = self.worst if mode is None else self.levels[mode]
        title = (
            f"{'worst mode' if mode is None else mode}, "
            f"W = {self.weights[weight]:g} {self.force_unit}"
        )
        ax = plot_levels(self.machs, self.altitudes, values[:, :, weight], ax=ax, title=title)
        ax.set_ylabel(f"altitude ({self.length_unit})")
        return ax


class _NotAnAircraft(InvalidArgumentError):
    """``derivatives`` returned something other than an Aircraft: wrong for every condition."""


def _reason(error: BaseException) -> str:
    """The reason of a failed condition, on one line; the exception's type where it has no
    message of its own (an OverflowError from arithmetic)."""
    text = " ".join(str(error).split())
    if isinstance(error, AerocontrolError) and text:
        return text
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


def _grid(values: Any, name: str, default: float) -> NDArray[np.float64]:
    if values is None:
        return np.array([default])
    grid = np.atleast_1d(real_array(values, name)).astype(np.float64)
    if grid.ndim != 1 or grid.size == 0:
        raise ShapeError(f"{name} must be a non-empty 1-D array, got shape {grid.shape}")
    if not np.all(np.isfinite(grid)):
        raise InvalidArgumentError(f"{name} must be finite")
    return grid


def envelope_sweep(
    plane: Aircraft,
    altitudes: Sequence[float] | NDArray[np.float64] | None = None,
    machs: Sequence[float] | NDArray[np.float64] | None = None,
    weights: Sequence[float] | NDArray[np.float64] | None = None,
    derivatives: Callable[[Aircraft], Aircraft] | None = None,
) -> Envelope:
    """The modes and MIL-F-8785C Levels of ``plane`` at every combination of the given
    altitudes, Mach numbers and weights (each defaults to the file's own value).

    ``derivatives``, if given, receives each condition's aircraft (from
    :meth:`~aerocontrol.aircraft.Aircraft.at`) and returns the aircraft to analyse there, e.g.
    with Mach-dependent derivatives put in with ``dataclasses.replace``.

    A condition that fails is recorded in ``failures`` with its reason (Level 0) and the
    sweep goes on: a Mach number, altitude or weight outside its plausible range
    (:data:`~aerocontrol.aircraft.PLAUSIBLE_RANGES`, e.g. ``machs=[1e300]``) or outside the
    standard atmosphere, arithmetic that overflows, a model whose modes cannot be computed or
    named, or any of these raised by ``derivatives`` (the exceptions of
    ``CONDITION_FAILURES``). What is wrong with the call as a whole raises at once:
    ``plane`` not an Aircraft, a grid that is not a non-empty 1-D array of real numbers or
    holds NaN or an infinity (a grid point that is not a number is no flight condition),
    ``derivatives`` returning something other than an Aircraft, and any other exception of
    ``derivatives`` (a TypeError or KeyError is a bug in it, not a property of the
    condition).

    Parameters
    ----------
    plane : Aircraft
        The aircraft whose condition is moved.
    altitudes, machs, weights : array_like (k,), optional
        The grid, in the file's units (default: the file's own value, a grid of one).
    derivatives : callable, optional
        ``derivatives(aircraft) -> Aircraft``: the aircraft to analyse at each condition.

    Returns
    -------
    Envelope
        ``levels`` and ``eigenvalues`` per mode over the (altitude, Mach, weight) grid, the
        worst Level, and the ``failures`` with their reasons.

    Raises
    ------
    InvalidArgumentError
        ``plane`` not an Aircraft, a grid that is empty, not 1-D, not real or not finite, or
        ``derivatives`` returning something other than an Aircraft.

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol import aircraft
    >>> b747 = aircraft.load()
    >>> env = aircraft.envelope_sweep(b747, altitudes=[0, 5000, 10000],
    ...                               machs=[0.2, 0.25, 0.3], weights=[500e3, 564032])
    >>> env.shape, env.levels["dutch roll"][0, 1, 1]     # the chapter's condition: Level 2
    ((3, 3, 2), np.int64(2))
    """
    if not isinstance(plane, Aircraft):
        raise InvalidArgumentError(f"plane must be an Aircraft, got {type(plane).__name__}")
    altitude_grid = _grid(altitudes, "altitudes", plane.altitude)
    mach_grid = _grid(machs, "machs", plane.mach)
    weight_grid = _grid(weights, "weights", plane.mass * plane.gravity)
    shape = (len(altitude_grid), len(mach_grid), len(weight_grid))
    # A roll and spiral coupled into one oscillation are judged as it (3.3.1.4): both carry
    # its Level, and have no eigenvalue of their own.
    separate = [mode for mode in handling.MODES if mode != "roll-spiral"]
    levels = {mode: np.zeros(shape, dtype=np.int_) for mode in separate}
    eigenvalues = {mode: np.full(shape, np.nan + 0j) for mode in separate}
    failures: dict[tuple[int, int, int], str] = {}
    for index in np.ndindex(shape):
        i, j, k = index
        try:
            condition = plane.at(altitude_grid[i], mach_grid[j], weight_grid[k])
            if derivatives is not None:
                condition = derivatives(condition)
                if not isinstance(condition, Aircraft):
                    raise _NotAnAircraft(
                        f"derivatives must return an Aircraft, got {type(condition).__name__}"
                    )
            named = {
                **classify_modes(modes(condition.longitudinal().A), "longitudinal"),
                **classify_modes(modes(condition.lateral().A), "lateral"),
            }
            assessed = handling.assess(named, plane.aircraft_class, plane.category)
        except _NotAnAircraft:
            raise
        except CONDITION_FAILURES as error:
            failures[index] = _reason(error)
            continue
        for mode, level in assessed.levels.items():
            if mode == "roll-spiral":
                levels["roll"][index] = levels["spiral"][index] = level
                continue
            levels[mode][index] = level
            eigenvalues[mode][index] = max(named[mode], key=lambda v: (v.imag, v.real))
    return Envelope(
        altitude_grid,
        mach_grid,
        weight_grid,
        plane.aircraft_class,
        plane.category,
        "ft" if plane.units == "english" else "m",
        "lbf" if plane.units == "english" else "N",
        levels,
        eigenvalues,
        failures,
    )
