"""Gain scheduling over the flight envelope: a state-feedback design at every condition of an
altitude x Mach (x weight) grid, the gains as tables, and the control law they make flown
between the design points.

At each grid condition (the aircraft moved by ``Aircraft.at``, as
:func:`aerocontrol.aircraft.envelope_sweep` builds its conditions) a gain K is designed,
u = -K x: the linear-quadratic regulator minimising J = ∫ x^T Q x + (1/c²) u^T R u dt (the
chapter's (6.224)-(6.227), weighted as :func:`aerocontrol.batch.lqr_sweep` and
:class:`aerocontrol.robustness.Lqr` weight it), all conditions solved in one batch call, or the
Dutch-roll damper of (6.156) by Bass-Gura (:func:`aerocontrol.design.dutch_roll_damper`).

Between the grid points the schedule interpolates each gain entry multilinearly: with t_i the
fraction of its grid cell a coordinate covers,

    K(h, M, W) = Σ_corners Π_i (t_i or 1 - t_i) K_corner,                                (1)

linear along each grid axis, equal to the table at the grid points and exact for a table
that is itself linear in each coordinate. ``GainSchedule.evaluate`` flies the
interpolated law over a finer grid and judges the closed loop A - B K(h, M, W) against
MIL-F-8785C (3.2, 3.3), the models, eigenvalues, modes and Levels computed in bulk.

Examples
--------
>>> import aerocontrol
>>> from aerocontrol.schedule import gain_schedule
>>> b747 = aerocontrol.aircraft.load()
>>> schedule = gain_schedule(b747, altitudes=[0, 10000], machs=[0.2, 0.3])
>>> schedule.gains.shape                      # (altitudes, Machs, weights, inputs, states)
(2, 2, 1, 2, 4)
>>> fine = schedule.evaluate(altitudes=[0, 5000, 10000], machs=[0.2, 0.25, 0.3])
>>> fine.shape, sorted(fine.levels)
((3, 3, 1), ['dutch roll', 'roll', 'spiral'])
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import batch, linalg
from ._judging import AXIS_MODES, judge_stack
from ._results import Result
from ._validation import real_array, real_scalar
from .aircraft.envelope import Envelope, _grid
from .aircraft.model import Aircraft
from .design import dutch_roll_damper
from .exceptions import InvalidArgumentError, ShapeError

__all__ = ["CHUNK_SIZE", "DESIGNS", "GainSchedule", "gain_schedule"]

FloatArray = NDArray[np.float64]
Grid = Sequence[float] | FloatArray | None

#: The design rules of :func:`gain_schedule`.
DESIGNS = ("lqr", "damper")

#: Conditions per chunk of a closed-loop judgement (the unit of work on a Dask cluster; the
#: result does not depend on it, each condition being judged on its own).
CHUNK_SIZE = 4096

#: The fields of a condition's aircraft that :meth:`~aerocontrol.aircraft.Aircraft.at` changes
#: and the models read.
_CONDITION_FIELDS = ("mass", "speed", "density")


def _models(
    plane: Aircraft, axis: str, conditions: FloatArray
) -> tuple[FloatArray, FloatArray, list[Aircraft]]:
    """The state matrices A (k, 4, 4) and B (k, 4, inputs) at k conditions (rows altitude,
    Mach, weight), each equal, bitwise, to ``plane.at(...)``'s own model (the aircraft moved
    by :meth:`~aerocontrol.aircraft.Aircraft.at`, the matrices built in one
    :meth:`~aerocontrol.aircraft.Aircraft.model_stack` call)."""
    moved = [plane.at(float(h), float(m), float(w)) for h, m, w in conditions]
    values = {name: np.array([getattr(a, name) for a in moved]) for name in _CONDITION_FIELDS}
    for name in ("CL", "CD"):
        values[name] = np.array([a.derivatives[name] for a in moved])
    A, B = plane.model_stack(axis, values)
    return A, B, moved


def _conditions(altitudes: FloatArray, machs: FloatArray, weights: FloatArray) -> FloatArray:
    """The grid's conditions, (altitudes * machs * weights, 3), in C order of the grid."""
    mesh = np.meshgrid(altitudes, machs, weights, indexing="ij")
    return np.stack([axis.ravel() for axis in mesh], axis=1)


@dataclass(frozen=True)
class _Chunk:
    """Everything a chunk of a closed-loop judgement needs (shipped to a Dask worker)."""

    plane: Aircraft
    axis: str


def _judge_chunk(
    chunk: _Chunk, conditions: FloatArray, gains: FloatArray
) -> dict[str, NDArray[Any]]:
    """The closed loops A - B K at the conditions, judged: each mode's Level (0 where it was
    not judged; a roll and spiral coupled into one oscillation both carry its Level), its
    eigenvalue with Im >= 0 (the larger real root of a split pair; NaN for a coupled roll and
    spiral), and the conditions whose modes could not be judged."""
    A, B, _ = _models(chunk.plane, chunk.axis, conditions)
    closed = A - np.einsum("kij,kjl->kil", B, gains)
    judged = judge_stack(
        closed,
        linalg.eigenvalues(closed),
        chunk.axis,
        chunk.plane.aircraft_class,
        chunk.plane.category,
    )
    out: dict[str, NDArray[Any]] = {"unresolved": np.asarray(~judged.judged.all(axis=1))}
    for k, mode in enumerate(AXIS_MODES[chunk.axis]):
        out[f"level {mode}"] = np.where(judged.judged[:, k], judged.levels[:, k], 0)
        roots = judged.named[mode]
        if roots.ndim == 2:
            first, second = roots[:, 0], roots[:, 1]
            later = (second.imag > first.imag) | (
                (second.imag == first.imag) & (second.real > first.real)
            )
            roots = np.where(later, second, first)
        out[f"eigenvalue {mode}"] = roots
    return out


def _closed_loop(
    plane: Aircraft,
    axis: str,
    grids: tuple[FloatArray, FloatArray, FloatArray],
    gains: FloatArray,
    client: Any,
) -> Envelope:
    """The closed-loop Levels over a grid, the gains (grid shape + (inputs, 4)) given at each
    of its points, judged chunk by chunk (on ``client``'s workers if given)."""
    shape = tuple(len(g) for g in grids)
    conditions = _conditions(*grids)
    flat = gains.reshape(len(conditions), *gains.shape[-2:])
    starts = range(0, len(conditions), CHUNK_SIZE)
    pieces = [(conditions[s : s + CHUNK_SIZE], flat[s : s + CHUNK_SIZE]) for s in starts]
    chunk = _Chunk(plane, axis)
    if client is None:
        parts = [_judge_chunk(chunk, c, k) for c, k in pieces]
    else:
        futures = client.map(
            _judge_chunk,
            [chunk] * len(pieces),
            [c for c, _ in pieces],
            [k for _, k in pieces],
            pure=False,
        )
        parts = client.gather(futures)
    joined = {key: np.concatenate([part[key] for part in parts]) for key in parts[0]}
    modes = AXIS_MODES[axis]
    unresolved = joined["unresolved"].reshape(shape)
    reason = (
        "roll and spiral coupled, the Dutch roll not told apart: not assessed"
        if axis == "lateral"
        else "short period and phugoid not separable by size: not assessed"
    )
    return Envelope(
        *grids,
        plane.aircraft_class,
        plane.category,
        "ft" if plane.units == "english" else "m",
        "lbf" if plane.units == "english" else "N",
        {m: joined[f"level {m}"].reshape(shape).astype(np.int_) for m in modes},
        {m: joined[f"eigenvalue {m}"].reshape(shape) for m in modes},
        {(int(i), int(j), int(k)): reason for i, j, k in np.argwhere(unresolved)},
    )


def _increasing(grid: FloatArray, name: str) -> FloatArray:
    if np.any(np.diff(grid) <= 0.0):
        raise InvalidArgumentError(f"{name} must be strictly increasing, got {grid.tolist()}")
    return grid


@dataclass(frozen=True, eq=False)
class GainSchedule(Result):
    """State-feedback gains u = -K x designed over a grid of flight conditions, from
    :func:`gain_schedule`. Arrays are indexed [altitude, Mach, weight].

    Attributes
    ----------
    plane : Aircraft
        The aircraft whose conditions (:meth:`~aerocontrol.aircraft.Aircraft.at`) the gains were
        designed at.
    axis : str
        "lateral" or "longitudinal".
    design : str
        The design rule: "lqr" or "damper".
    altitudes : ndarray (a,)
        The grid's altitudes (ft or m, the aircraft's units).
    machs : ndarray (b,)
        The grid's Mach numbers.
    weights : ndarray (c,)
        The grid's weights (lbf or N); the aircraft's own weight by default.
    input_names : tuple of str
        The rows of each gain matrix.
    state_names : tuple of str
        Its columns.
    gains : ndarray (a, b, c, inputs, 4)
        K at each grid condition.
    closed_loop : Envelope
        The closed loops' Levels at the grid conditions.
    shape : tuple of int
        (a, b, c).

    Examples
    --------
    Each gain is the regulator of the aircraft moved to its condition:

    >>> import numpy as np, aerocontrol
    >>> from aerocontrol.schedule import gain_schedule
    >>> b747 = aerocontrol.aircraft.load()
    >>> s = gain_schedule(b747, altitudes=[0, 10000], machs=[0.2, 0.3])
    >>> s.shape, s.input_names, s.state_names
    ((2, 2, 1), ('rudder', 'aileron'), ('beta', 'p', 'phi', 'r'))
    >>> K, _, _ = aerocontrol.lqr(b747.at(10000, 0.3).lateral(), np.eye(4), np.eye(2))
    >>> bool(np.allclose(s.gains[1, 1, 0], K, rtol=1e-12, atol=0))
    True
    """

    plane: Aircraft
    """The aircraft whose conditions (:meth:`~aerocontrol.aircraft.Aircraft.at`) the gains were
    designed at."""
    axis: str
    design: str
    """The design rule: "lqr" or "damper"."""
    altitudes: FloatArray
    machs: FloatArray
    weights: FloatArray
    input_names: tuple[str, ...]
    """The rows of each gain matrix."""
    state_names: tuple[str, ...]
    """Its columns."""
    gains: FloatArray
    """(altitudes, machs, weights, inputs, 4): K at each grid condition."""
    closed_loop: Envelope
    """The closed loops' Levels at the grid conditions."""

    @property
    def shape(self) -> tuple[int, int, int]:
        return (len(self.altitudes), len(self.machs), len(self.weights))

    def _interpolate(self, coordinates: Sequence[tuple[ArrayLike, str, FloatArray]]) -> FloatArray:
        arrays = np.broadcast_arrays(*(real_array(v, name) for v, name, _ in coordinates))
        shape = arrays[0].shape
        lower: list[NDArray[np.intp]] = []
        fraction: list[FloatArray] = []
        for x, (_, name, grid) in zip(arrays, coordinates, strict=True):
            if not np.isfinite(x).all():
                raise InvalidArgumentError(f"{name} must be finite")
            if len(grid) == 1:  # one design point on this axis: the gains are constant along it
                lower.append(np.zeros(shape, dtype=np.intp))
                fraction.append(np.zeros(shape))
                continue
            outside = (x < grid[0]) | (x > grid[-1])
            if outside.any():
                # repr, not :g: 10000.0001 read as 10000, inside [0, 10000].
                raise InvalidArgumentError(
                    f"{name} must lie in the schedule's grid [{float(grid[0])!r}, "
                    f"{float(grid[-1])!r}], got {float(x[outside].ravel()[0])!r}"
                )
            i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, len(grid) - 2)
            lower.append(i)
            fraction.append((x - grid[i]) / (grid[i + 1] - grid[i]))
        out = np.zeros(shape + self.gains.shape[-2:])
        steps = [(0, 1) if len(grid) > 1 else (0,) for _, _, grid in coordinates]
        for corner in itertools.product(*steps):
            weight = np.ones(shape)
            for step, t in zip(corner, fraction, strict=True):
                weight = weight * (t if step else 1.0 - t)
            index = tuple(i + step for i, step in zip(lower, corner, strict=True))
            out += weight[..., np.newaxis, np.newaxis] * self.gains[index]
        return out

    def gains_at(
        self, altitude: ArrayLike, mach: ArrayLike, weight: ArrayLike | None = None
    ) -> FloatArray:
        """The scheduled gains at any conditions inside the grid, interpolated multilinearly
        (1): linear along each grid axis, the tables' values at the grid points; along an axis
        of one grid point the gains are that point's, at any value.

        Parameters
        ----------
        altitude, mach : array_like
            The conditions, in the aircraft file's units (broadcast together).
        weight : array_like, optional
            The weights; the aircraft file's weight when None.

        Returns
        -------
        ndarray
            Of shape broadcast shape + (inputs, 4).

        Raises
        ------
        InvalidArgumentError
            A condition outside the grid's range of an axis of more than one point, or not
            finite (the message names the argument and the range).
        NotRealError, ShapeError
            Conditions that are not real numbers or do not broadcast together.

        Examples
        --------
        >>> import numpy as np, aerocontrol
        >>> from aerocontrol.schedule import gain_schedule
        >>> s = gain_schedule(aerocontrol.aircraft.load(), [0, 10000], [0.2, 0.3])
        >>> middle = s.gains_at(5000, 0.25)                    # the cell's centre
        >>> bool(np.allclose(middle, s.gains[:, :, 0].mean(axis=(0, 1))))
        True
        >>> s.gains_at([0, 10000], 0.3).shape
        (2, 2, 4)
        """
        if weight is None:
            weight = self.plane.mass * self.plane.gravity
        try:
            np.broadcast_shapes(np.shape(altitude), np.shape(mach), np.shape(weight))
        except ValueError:
            raise ShapeError(
                f"altitude, mach and weight must broadcast together, got shapes "
                f"{np.shape(altitude)}, {np.shape(mach)} and {np.shape(weight)}"
            ) from None
        return self._interpolate(
            [
                (altitude, "altitude", self.altitudes),
                (mach, "mach", self.machs),
                (weight, "weight", self.weights),
            ]
        )

    def evaluate(
        self,
        altitudes: Grid = None,
        machs: Grid = None,
        weights: Grid = None,
        client: Any = None,
    ) -> Envelope:
        """The closed-loop MIL-F-8785C Levels (3.2, 3.3) over a grid of conditions, typically
        finer than the design grid, with the interpolated gains (1): at each condition the
        model of :meth:`~aerocontrol.aircraft.Aircraft.at`, the loop A - B K closed with the gains
        of :meth:`gains_at`, its eigenvalues, modes and Levels, all computed in bulk.

        Parameters
        ----------
        altitudes, machs, weights : array_like, optional
            1-D grids inside the schedule's ranges; each defaults to the aircraft file's
            value.
        client : dask.distributed.Client, optional
            Judge the conditions in chunks of :data:`CHUNK_SIZE` on this Dask cluster
            (``pip install aerocontrol[distributed]``); the result is the local run's,
            bitwise.

        Returns
        -------
        Envelope
            The Levels and eigenvalues of the axis's modes (0: not assessed, with the reason
            in ``failures``).

        Raises
        ------
        InvalidArgumentError
            A grid value outside the schedule's range (named), or not finite; a condition
            outside the plausible ranges (:meth:`~aerocontrol.aircraft.Aircraft.at`).
        ShapeError
            A grid that is not a non-empty 1-D array.

        Examples
        --------
        >>> import aerocontrol
        >>> from aerocontrol.schedule import gain_schedule
        >>> s = gain_schedule(aerocontrol.aircraft.load(), [0, 10000], [0.2, 0.3])
        >>> env = s.evaluate([0, 10000], [0.2, 0.3])         # the design points themselves
        >>> all((env.levels[m] == s.closed_loop.levels[m]).all() for m in env.levels)
        True
        """
        grids = (
            _grid(altitudes, "altitudes", self.plane.altitude),
            _grid(machs, "machs", self.plane.mach),
            _grid(weights, "weights", self.plane.mass * self.plane.gravity),
        )
        mesh = np.meshgrid(*grids, indexing="ij")
        gains = self._interpolate(
            [
                (mesh[0], "altitudes", self.altitudes),
                (mesh[1], "machs", self.machs),
                (mesh[2], "weights", self.weights),
            ]
        )
        return _closed_loop(self.plane, self.axis, grids, gains, client)

    def plot(self, ax: Any = None, weight: int = 0) -> Any:
        """Each gain entry against Mach, a line per altitude, at one weight of the grid
        (:func:`aerocontrol.plotting.plot_gain_schedule`). Returns the axes."""
        from .plotting import plot_gain_schedule

        return plot_gain_schedule(self, ax=ax, weight=weight)


def gain_schedule(
    plane: Aircraft,
    altitudes: Grid,
    machs: Grid,
    weights: Grid = None,
    design: str = "lqr",
    c: float = 1.0,
    Q: ArrayLike | None = None,
    R: ArrayLike | None = None,
    axis: str = "lateral",
    client: Any = None,
    *,
    zeta: float = 0.30,
) -> GainSchedule:
    """A state-feedback gain u = -K x designed at every condition of an altitude x Mach
    (x weight) grid, the conditions those of :func:`aerocontrol.aircraft.envelope_sweep`
    (``Aircraft.at``).

    Parameters
    ----------
    plane : Aircraft
    altitudes, machs : array_like or None
        Strictly increasing 1-D grids (altitudes in the file's length unit); the file's
        value when None.
    weights : array_like, optional
        A strictly increasing 1-D grid of weights in the file's force unit; the file's
        weight when None.
    design : {"lqr", "damper"}
        "lqr": the regulator minimising J = ∫ x^T Q x + (1/c²) u^T R u dt (6.224)-(6.227),
        K = c² R^-1 B^T X, every condition's Riccati equation solved in one parallel call
        (:func:`aerocontrol.batch.solve_care_batch`). "damper" (lateral only): the Dutch-roll
        damper through the rudder (6.156), by Bass-Gura (6.145)
        (:func:`aerocontrol.design.dutch_roll_damper`), the aileron row of K zero.
    c : float
        The LQR weight c (positive): R/c² weights the control, so a large c makes control
        cheap.
    Q, R : array_like, optional
        The LQR weights, 4 x 4 and inputs x inputs; identities when None ((6.225)-(6.226)).
    axis : {"lateral", "longitudinal"}
    client : dask.distributed.Client, optional
        Judge the closed loops at the grid conditions in chunks on this Dask cluster (as
        ``GainSchedule.evaluate``); the design itself is one batch call.
    zeta : float
        The damper's Dutch-roll damping ratio.

    Returns
    -------
    GainSchedule

    Raises
    ------
    InvalidArgumentError
        ``plane`` not an Aircraft, an unknown ``design`` or ``axis``, the damper asked of the
        longitudinal axis, ``c`` not positive, a grid not strictly increasing or not finite,
        a condition outside the plausible ranges (``Aircraft.at``); a condition whose
        design fails raises that design's error (e.g. NoStabilizingSolutionError, naming the
        problem of the batch).
    ShapeError
        A grid that is not a non-empty 1-D array, or Q or R of the wrong shape.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> from aerocontrol.schedule import gain_schedule
    >>> b747 = aerocontrol.aircraft.load()
    >>> s = gain_schedule(b747, [0, 10000], [0.2, 0.3], design="damper")
    >>> K = s.gains[0, 0, 0]                     # rudder row, zero aileron row
    >>> s.input_names, bool((K[1] == 0).all())
    (('rudder', 'aileron'), True)
    >>> s.closed_loop.levels["dutch roll"][:, :, 0]   # ζ = 0.3: Level 1 everywhere
    array([[1, 1],
           [1, 1]])
    """
    if not isinstance(plane, Aircraft):
        raise InvalidArgumentError(f"plane must be an Aircraft, got {type(plane).__name__}")
    if not isinstance(axis, str) or axis not in AXIS_MODES:
        raise InvalidArgumentError(f"axis must be 'lateral' or 'longitudinal', got {axis!r}")
    if not isinstance(design, str) or design not in DESIGNS:
        raise InvalidArgumentError(f"design must be one of {DESIGNS}, got {design!r}")
    if design == "damper" and axis != "lateral":
        raise InvalidArgumentError(
            f"design 'damper' (the Dutch-roll damper) needs axis='lateral', got axis={axis!r}"
        )
    grids = (
        _increasing(_grid(altitudes, "altitudes", plane.altitude), "altitudes"),
        _increasing(_grid(machs, "machs", plane.mach), "machs"),
        _increasing(_grid(weights, "weights", plane.mass * plane.gravity), "weights"),
    )
    shape = tuple(len(g) for g in grids)
    A, B, moved = _models(plane, axis, _conditions(*grids))
    m = B.shape[-1]
    model = plane.lateral() if axis == "lateral" else plane.longitudinal()
    input_names, state_names = tuple(model.input_names), tuple(model.state_names)
    if design == "lqr":
        weight = real_scalar(c, "c")
        if not (0.0 < weight < np.inf and 0.0 < weight * weight < np.inf):
            # R / c²: c² too must be a positive finite number (1e200 or 1e-200 is not).
            raise InvalidArgumentError(
                f"c must be positive and finite, with a positive finite square, got {c!r}"
            )
        Q_matrix = np.eye(4) if Q is None else real_array(Q, "Q")
        R_matrix = np.eye(m) if R is None else real_array(R, "R")
        if Q_matrix.shape != (4, 4):
            raise ShapeError(f"Q must be 4 x 4, got shape {Q_matrix.shape}")
        if R_matrix.shape != (m, m):
            raise ShapeError(f"R must be {m} x {m} for the {axis} model, got {R_matrix.shape}")
        K = batch.solve_care_batch(A, B, Q_matrix, R_matrix / (weight * weight)).K
    else:
        K = np.zeros((len(moved), m, 4))
        rudder = input_names.index("rudder")
        for k, condition in enumerate(moved):
            K[k, rudder] = dutch_roll_damper(condition, zeta=zeta, surface="rudder").k
    gains = np.ascontiguousarray(K.reshape(*shape, m, 4))
    return GainSchedule(
        plane,
        axis,
        design,
        *grids,
        input_names,
        state_names,
        gains,
        _closed_loop(plane, axis, grids, gains, client),
    )
