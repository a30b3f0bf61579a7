"""Stochastic robustness: the probability that an aircraft, with or without a control law,
is stable and meets each MIL-F-8785C Level when its derivatives are uncertain.

Stengel and Ray (IEEE TAC 36, 1991, "Stochastic robustness of linear time-invariant control
systems") estimate such probabilities by Monte Carlo evaluation: draw the uncertain parameters
from their distributions, build each model, judge it, count. With N samples of which x meet a
criterion, the estimate is x / N and its exact (Clopper-Pearson) confidence interval is

    [B(α/2; x, N - x + 1), B(1 - α/2; x + 1, N - x)]                                     (1)

with B(q; a, b) the q-quantile of the beta distribution (Clopper and Pearson, Biometrika 26,
1934); the interval never depends on a normal approximation, so it holds at x = 0 and for
rare failures.

The draws are reproducible by construction: the samples are cut into chunks of a fixed size,
chunk i draws from numpy's ``SeedSequence(seed, spawn_key=(i,))`` (the i-th child of the seed),
and each chunk is judged by the same batch kernels wherever it runs. So a run gives the same
result, bitwise, on one core, on all local cores, or chunk by chunk on a Dask cluster
(``client=``) of any size.

A chunk runs in the Rust core, each step one parallel call over its samples: the models from
the drawn derivatives (``Aircraft.model_stack``), their eigenvalues, the modes named
(``classify_mode_stack``), each mode's quantities and MIL-F-8785C Level
(:func:`aerocontrol.handling.level_arrays`), and for a controller the closed loops (a Riccati
solve or a Bass-Gura placement per sample). What Python does is draw (numpy's generator, for
the seeds' sake) and move arrays between the calls.

Examples
--------
>>> import aerocontrol
>>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
>>> b747 = aerocontrol.aircraft.load("b747-cruise")
>>> uncertainty = Uncertainty({"Cn_beta": Normal(0.2), "Cn_r": Normal(0.2)})
>>> result = monte_carlo(b747, uncertainty, samples=2000, axis="lateral", seed=1)
>>> result.samples, result.open_loop.levels.shape
(2000, (2000, 3))
>>> estimate = result.probability("unstable")
>>> 0.0 <= estimate.low <= estimate.value <= estimate.high <= 1.0
True
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import batch, linalg
from ._judging import AXIS_MODES, judge_stack
from ._results import Result, Tabular, register
from ._validation import check_finite, optional_callable, positive_int, real_array, real_scalar
from .aircraft.model import _POSITIVE_FIELDS, SAMPLED_FIELDS, Aircraft
from .aircraft.naming import classify_mode_stack
from .aircraft.schema import AircraftDataError
from .exceptions import AerocontrolError, ConvergenceError, InvalidArgumentError, ShapeError
from .handling import mode_quantities

__all__ = [
    "CHUNK_SIZE",
    "MAX_SAMPLES",
    "Damper",
    "Estimate",
    "LogNormal",
    "LoopOutcome",
    "Lqr",
    "MonteCarlo",
    "MonteCarloCounts",
    "Normal",
    "Uncertainty",
    "Uniform",
    "clopper_pearson",
    "monte_carlo",
]

FloatArray = NDArray[np.float64]

# A run's aircraft is part of its result's JSON form (MonteCarlo.to_dict).
register(Aircraft)

#: Samples per chunk: each chunk draws from its own child seed, so the result does not depend
#: on how the chunks are spread over cores or machines.
CHUNK_SIZE = 1 << 16

#: The number of bins of each parameter's standard-normal draw over which the failure rate is
#: counted for the sensitivity ranking: deciles.
SENSITIVITY_BINS = 10

#: The prefix of a mode quantity's key among a chunk's arrays.
_QUANTITY = "quantity: "

_AXIS_MODES = AXIS_MODES


# --- Distributions ----------------------------------------------------------------------------


def _standard_normal_cdf(z: FloatArray) -> FloatArray:
    """Φ(z) = erfc(-z / √2) / 2, elementwise."""
    values = np.asarray(np.frompyfunc(math.erfc, 1, 1)(-z / math.sqrt(2.0)), dtype=np.float64)
    return 0.5 * values


@register
@dataclass(frozen=True)
class Normal:
    """A normal scatter of standard deviation ``sigma``: of the nominal value's magnitude
    (``relative``, the default: 0.1 is ±10 % at one sigma) or in the parameter's units.

    Attributes
    ----------
    sigma : float
        The standard deviation: of the nominal value's magnitude when ``relative``, else in the
        parameter's units.
    relative : bool
        Whether ``sigma`` is relative to the nominal value's magnitude (default True).

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol.robustness import Normal
    >>> z = np.array([-1.0, 0.0, 1.0])                   # standard-normal draws
    >>> np.round(Normal(0.1).values(-2.0, z), 12)     # ±10 % of abs(-2) at one sigma
    array([-2.2, -2. , -1.8])
    >>> np.round(Normal(0.1, relative=False).values(-2.0, z), 12)
    array([-2.1, -2. , -1.9])
    """

    sigma: float
    relative: bool = True

    def values(self, nominal: float, z: FloatArray) -> FloatArray:
        """The parameter's values for standard-normal draws ``z``."""
        scale = abs(nominal) if self.relative else 1.0
        return nominal + (self.sigma * scale) * z


@register
@dataclass(frozen=True)
class Uniform:
    """A uniform scatter over nominal ± ``half_width`` (of the nominal's magnitude when
    ``relative``), drawn as Φ(z) of the parameter's standard-normal draw.

    Attributes
    ----------
    half_width : float
        The half width of the interval: of the nominal value's magnitude when ``relative``, else
        in the parameter's units.
    relative : bool
        Whether ``half_width`` is relative to the nominal value's magnitude (default True).

    Examples
    --------
    The draws z = 0 and ±∞ map to the centre and the ends, z = 1 to 2 Φ(1) - 1 = 0.682689 of
    the half width:

    >>> import numpy as np
    >>> from aerocontrol.robustness import Uniform
    >>> np.round(Uniform(0.5).values(2.0, np.array([-np.inf, 0.0, 1.0, np.inf])), 6)
    array([1.      , 2.      , 2.682689, 3.      ])
    """

    half_width: float
    relative: bool = True

    def values(self, nominal: float, z: FloatArray) -> FloatArray:
        scale = abs(nominal) if self.relative else 1.0
        return nominal + (self.half_width * scale) * (2.0 * _standard_normal_cdf(z) - 1.0)


@register
@dataclass(frozen=True)
class LogNormal:
    """A log-normal scatter about the nominal value (its median): nominal · e^(sigma z), which
    keeps the sign of the nominal value (for masses, inertias and damping derivatives).

    Attributes
    ----------
    sigma : float
        The standard deviation of the logarithm: nominal · e^(sigma z) for a standard-normal
        draw z.

    Examples
    --------
    >>> import numpy as np
    >>> from aerocontrol.robustness import LogNormal
    >>> np.round(LogNormal(0.1).values(-2.0, np.array([-1.0, 0.0, 1.0])), 6)
    array([-1.809675, -2.      , -2.210342])
    """

    sigma: float

    def values(self, nominal: float, z: FloatArray) -> FloatArray:
        return nominal * np.exp(self.sigma * z)


class Distribution(Protocol):
    def values(self, nominal: float, z: FloatArray) -> FloatArray: ...


@register
@dataclass(frozen=True)
class Uncertainty:
    """The uncertain parameters: a distribution per name (a nondimensional derivative, or one of
    ``aerocontrol.aircraft.SAMPLED_FIELDS``), and correlations between them.

    Each parameter is driven by one standard-normal draw; ``correlations`` gives the
    correlation of two parameters' draws (a Gaussian copula: for normal parameters, their
    correlation), ``{("Cn_beta", "Cn_r"): 0.5}``. The correlation matrix must be positive
    definite.

    Attributes
    ----------
    distributions : Mapping[str, Normal or Uniform or LogNormal]
        The distribution of each uncertain parameter (a copy of the mapping given).
    correlations : Mapping[tuple of (str, str), float]
        The correlation of two parameters' standard-normal draws, in (-1, 1); empty by default.
    names : tuple of str
        The uncertain parameters, in the order given.

    Examples
    --------
    >>> from aerocontrol.robustness import LogNormal, Normal, Uncertainty, Uniform
    >>> u = Uncertainty(
    ...     {"Cn_beta": Normal(0.2), "Cl_p": Uniform(0.3), "Iz": LogNormal(0.05)},
    ...     correlations={("Cn_beta", "Cl_p"): 0.5},
    ... )
    >>> u.names
    ('Cn_beta', 'Cl_p', 'Iz')
    """

    distributions: Mapping[str, Distribution]
    correlations: Mapping[tuple[str, str], float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for argument, given in (
            ("distributions", self.distributions),
            ("correlations", self.correlations),
        ):
            if not isinstance(given, Mapping):
                raise InvalidArgumentError(
                    f"uncertainty: {argument} must be a mapping (a dict), got "
                    f"{type(given).__name__}"
                )
            # A copy: the caller's dict, changed later, changes neither this nor a run's draws.
            object.__setattr__(self, argument, dict(given))
        if not self.distributions:
            raise InvalidArgumentError("uncertainty: give at least one uncertain parameter")
        for name, distribution in self.distributions.items():
            if not isinstance(name, str):
                raise InvalidArgumentError(f"uncertainty: parameter names are str, got {name!r}")
            if not isinstance(distribution, (Normal, Uniform, LogNormal)):
                raise InvalidArgumentError(
                    f"uncertainty[{name!r}] must be a Normal, Uniform or LogNormal, got "
                    f"{type(distribution).__name__}"
                )
            relative = getattr(distribution, "relative", True)
            if not isinstance(relative, (bool, np.bool_)):
                raise InvalidArgumentError(
                    f"uncertainty[{name!r}]: relative must be True or False, got {relative!r}"
                )
            spread = next(iter(vars(distribution).values()))
            spread = real_scalar(spread, f"uncertainty[{name!r}]")
            if not (math.isfinite(spread) and spread >= 0.0):
                raise InvalidArgumentError(
                    f"uncertainty[{name!r}]: the spread must be finite and >= 0, got {spread}"
                )
        self.cholesky()  # checks the correlations

    @classmethod
    def of(cls, plane: Aircraft) -> Uncertainty:
        """The uncertainty an aircraft file declares in its [uncertainty] table::

            [uncertainty]
            Cn_beta = { distribution = "normal", sigma = 0.2 }       # relative: ±20 % at 1σ
            Cl_p = { distribution = "uniform", half_width = 0.3 }
            Iz = { distribution = "lognormal", sigma = 0.05 }
            speed = { distribution = "normal", sigma = 5.0, relative = false }   # ft/s or m/s
            correlations = [["Cn_beta", "Cl_p", 0.5]]

        Raises InvalidArgumentError if the aircraft declares none.
        """
        if not isinstance(plane, Aircraft):
            raise InvalidArgumentError(f"plane must be an Aircraft, got {type(plane).__name__}")
        if not plane.uncertainty:
            raise InvalidArgumentError(f"{plane.name} declares no [uncertainty]")
        kinds: dict[str, Callable[[float, bool], Distribution]] = {
            "normal": lambda spread, relative: Normal(spread, relative),
            "uniform": lambda spread, relative: Uniform(spread, relative),
            "lognormal": lambda spread, relative: LogNormal(spread),
        }
        distributions = {
            name: kinds[entry["distribution"]](entry["spread"], entry["relative"])
            for name, entry in plane.uncertainty["parameters"].items()
        }
        correlations = {(a, b): rho for a, b, rho in plane.uncertainty["correlations"]}
        return cls(distributions, correlations)

    @property
    def names(self) -> tuple[str, ...]:
        """The uncertain parameters, in the order given."""
        return tuple(self.distributions)

    def cholesky(self) -> FloatArray:
        """The lower Cholesky factor L of the draws' correlation matrix (z = L ε)."""
        names = self.names
        matrix = np.eye(len(names))
        given: set[tuple[int, int]] = set()
        for pair, value in self.correlations.items():
            if not (isinstance(pair, tuple) and len(pair) == 2 and all(p in names for p in pair)):
                raise InvalidArgumentError(
                    f"correlations: {pair!r} is not a pair of the uncertain parameters {names}"
                )
            i, j = names.index(pair[0]), names.index(pair[1])
            rho = real_scalar(value, f"correlations[{pair!r}]")
            if i == j or not -1.0 < rho < 1.0:
                raise InvalidArgumentError(
                    f"correlations[{pair!r}] must be in (-1, 1) between two parameters, got {rho}"
                )
            if (min(i, j), max(i, j)) in given:  # ("a", "b") and ("b", "a"): which one holds?
                raise InvalidArgumentError(
                    f"correlations: the pair {pair!r} is given twice (in either order)"
                )
            given.add((min(i, j), max(i, j)))
            matrix[i, j] = matrix[j, i] = rho
        try:
            return np.asarray(np.linalg.cholesky(matrix), dtype=np.float64)
        except np.linalg.LinAlgError:
            raise InvalidArgumentError(
                "correlations: the correlation matrix is not positive definite"
            ) from None


# --- Controllers --------------------------------------------------------------------------------


@register
@dataclass(frozen=True)
class Lqr:
    """The linear-quadratic regulator re-designed for every sample: u = -K x minimising
    J = ∫ x^T Q x + (1/c²) u^T R u dt, the chapter's (6.224)-(6.227) as ``aerocontrol lqr``
    and :func:`aerocontrol.batch.lqr_sweep` weight it (Q and R identities when not given),
    solved for all samples of a chunk in one parallel call.

    Attributes
    ----------
    c : float
        The weight c: the control weight is R/c² (default 1).
    Q : ndarray (n, n) or None
        The state weight; None for the identity.
    R : ndarray (m, m) or None
        The control weight before division by c²; None for the identity.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> from aerocontrol.robustness import Lqr, Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load(), Uncertainty({"Cn_beta": Normal(0.3)}), 1000, Lqr(c=1.0),
    ...                   axis="lateral", seed=1)
    >>> bool(run.closed_loop.stable.all()), int(run.failed.sum())
    (True, 0)
    """

    c: float = 1.0
    Q: ArrayLike | None = None
    R: ArrayLike | None = None

    def __post_init__(self) -> None:
        c = real_scalar(self.c, "c")
        # The control weight is R / c²: c² itself must be a positive finite number (a c of
        # 1e200 or 1e-200 squares to inf or 0).
        if not (math.isfinite(c) and c > 0.0 and 0.0 < c * c < math.inf):
            raise InvalidArgumentError(
                f"c must be a positive finite weight whose square is a positive finite number, "
                f"got {c}"
            )
        object.__setattr__(self, "c", c)
        for name in ("Q", "R"):
            given = getattr(self, name)
            if given is not None:
                # Checked now, and copied: an array changed by the caller later changes nothing.
                matrix = np.array(real_array(given, name))
                if matrix.ndim != 2 or matrix.shape[0] != matrix.shape[1]:
                    raise ShapeError(f"{name} must be a square matrix, got shape {matrix.shape}")
                check_finite(matrix, name)
                matrix.setflags(write=False)
                object.__setattr__(self, name, matrix)


@functools.partial(register, name="robustness.Damper")
@dataclass(frozen=True)
class Damper:
    """The chapter's Dutch roll damper re-designed for every sample: state feedback through
    one surface that moves the sample's own Dutch roll to the damping ratio ``zeta`` at its
    natural frequency and keeps its roll and spiral roots ((6.156), by Bass-Gura (6.145)), all
    samples of a chunk in one parallel call (:func:`aerocontrol.batch.place_batch`). Lateral
    models only. A sample whose Dutch roll is not an oscillation (split into two real roots,
    or coupled with roll and spiral) has no such damper: its closed loop is its open loop,
    and :attr:`LoopOutcome.controlled` is False for it.

    Attributes
    ----------
    zeta : float
        The Dutch roll damping ratio the damper sets, in (0, 1) (default 0.30).
    surface : str
        The surface it acts through: "rudder" (default) or "aileron".

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> from aerocontrol.robustness import Damper, Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load(), Uncertainty({"Cn_beta": Normal(0.3)}), 1000, Damper(),
    ...                   axis="lateral", seed=1)
    >>> bool(run.open_loop.controlled.any()), bool(run.closed_loop.controlled.all())
    (False, True)
    """

    zeta: float = 0.30
    surface: str = "rudder"

    def __post_init__(self) -> None:
        zeta = real_scalar(self.zeta, "zeta")
        if not 0.0 < zeta < 1.0:
            raise InvalidArgumentError(f"zeta must lie in (0, 1), got {zeta}")
        if self.surface not in ("rudder", "aileron"):
            raise InvalidArgumentError(
                f"surface must be 'rudder' or 'aileron', got {self.surface!r}"
            )


def _closed_loop(
    A: FloatArray,
    B: FloatArray,
    controller: FloatArray | Lqr | Damper,
    open_eigenvalues: NDArray[np.complex128],
) -> tuple[FloatArray, NDArray[np.complex128], NDArray[np.bool_]]:
    """The closed-loop matrices A - B K of a chunk, their eigenvalues, and which samples the
    controller acts on."""
    everywhere = np.ones(A.shape[0], dtype=bool)
    if isinstance(controller, Lqr):
        n, m = A.shape[-1], B.shape[-1]
        Q = np.eye(n) if controller.Q is None else real_array(controller.Q, "Q")
        R = np.eye(m) if controller.R is None else real_array(controller.R, "R")
        solution = batch.solve_care_batch(A, B, Q, R / (controller.c * controller.c))
        closed = A - np.einsum("kij,kjl->kil", B, solution.K)
        return closed, solution.closed_loop_poles, everywhere
    if isinstance(controller, Damper):
        named, _ = classify_mode_stack(open_eigenvalues, "lateral", A)
        dutch = named["dutch roll"][:, 0]
        designed = (
            np.isfinite(dutch)
            & (dutch.imag != 0.0)
            & np.isfinite(named["roll"])
            & np.isfinite(named["spiral"])
        )
        K = np.zeros((A.shape[0], B.shape[-1], A.shape[-1]))
        if designed.any():
            wn = np.abs(dutch[designed])
            zeta = controller.zeta
            pole = -zeta * wn + 1j * wn * math.sqrt(1.0 - zeta * zeta)
            poles = np.stack(
                [pole, pole.conj(), named["roll"][designed], named["spiral"][designed]], axis=1
            )
            column = ("rudder", "aileron").index(controller.surface)
            one_input = B[designed][:, :, column : column + 1]
            try:
                placed = batch.place_batch(A[designed], one_input, poles, "bass-gura")
            except AerocontrolError as error:  # its problem among the designed: the chunk's
                if error.batch_index is None:
                    raise
                rows = np.flatnonzero(designed)
                raise _renumbered(
                    error, int(rows[error.batch_index]), "problem {} of the batch"
                ) from None
            K[designed, column] = placed.K[:, 0]
        closed = A - np.einsum("kij,kjl->kil", B, K)
        return closed, linalg.eigenvalues(closed), designed
    closed = A - np.einsum("kij,jl->kil", B, controller)
    return closed, linalg.eigenvalues(closed), everywhere


# --- One chunk --------------------------------------------------------------------------------


@functools.partial(register, name="robustness.Run")
@dataclass(frozen=True)
class _Run:
    """Everything a chunk needs (shipped to a Dask worker as it is)."""

    aircraft: Aircraft
    uncertainty: Uncertainty
    axis: str
    controller: FloatArray | Lqr | Damper | None
    samples: int
    seed: int
    chunk_size: int
    required_level: int
    worker_threads: int | None = None
    counts_only: bool = False
    """Each chunk is reduced to its counts where it runs (``keep="counts"``)."""

    def chunk_bounds(self, index: int) -> tuple[int, int]:
        start = index * self.chunk_size
        return start, min(start + self.chunk_size, self.samples)

    @property
    def chunk_count(self) -> int:
        return -(-self.samples // self.chunk_size)

    def draws(self, index: int) -> FloatArray:
        """The chunk's standard-normal draws z (rows: samples; columns: parameters),
        correlated."""
        start, stop = self.chunk_bounds(index)
        rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(index,)))
        epsilon = rng.standard_normal((stop - start, len(self.uncertainty.names)))
        if self.uncertainty.correlations:
            return np.asarray(epsilon @ self.uncertainty.cholesky().T)
        return epsilon

    def values(self, z: FloatArray, start: int = 0) -> dict[str, FloatArray]:
        """The parameters' values for the draws ``z`` of the samples from ``start`` on.

        Raises InvalidArgumentError naming the parameter and the first sample whose value is
        not finite (a spread so wide that the value overflows), or not positive for a mass,
        inertia, speed or density (a normal or uniform scatter reaching zero: a log-normal
        one never does)."""
        out = {}
        for k, (name, distribution) in enumerate(self.uncertainty.distributions.items()):
            with np.errstate(over="ignore", invalid="ignore"):
                values = distribution.values(_nominal(self.aircraft, name), z[:, k])
            bad = ~np.isfinite(values)
            problem = "is not finite"
            if not bad.any() and name in _POSITIVE_FIELDS:
                bad, problem = ~(values > 0.0), "is not positive (use a LogNormal scatter)"
            if bad.any():
                first = int(np.flatnonzero(bad)[0])
                raise InvalidArgumentError(
                    f"uncertainty[{name!r}]: the value of sample {start + first} {problem}: "
                    f"{values[first]:g}"
                )
            out[name] = values
        return out


def _nominal(plane: Aircraft, name: str) -> float:
    """The aircraft's own value of an uncertain parameter."""
    return float(getattr(plane, name) if name in SAMPLED_FIELDS else plane.derivatives[name])


def _judge(
    run: _Run, A: FloatArray, eigenvalues: NDArray[np.complex128]
) -> dict[str, NDArray[Any]]:
    """Stability, Levels and mode quantities of a chunk's models."""
    judged = judge_stack(
        A, eigenvalues, run.axis, run.aircraft.aircraft_class, run.aircraft.category
    )
    out: dict[str, NDArray[Any]] = {}
    for k, name in enumerate(_AXIS_MODES[run.axis]):
        known = judged.known[:, k]
        for quantity, values in mode_quantities(name, judged.named[name][known]).items():
            column = np.full(A.shape[0], np.nan)
            column[known] = values
            out[f"{_QUANTITY}{name}: {quantity}"] = column
    return {
        "levels": judged.levels,
        "stable": judged.stable,
        "unresolved": judged.unresolved,
        "max_real": judged.max_real,
        **out,
    }


def _run_chunk_on_worker(run: _Run, index: int) -> dict[str, NDArray[Any]]:
    """:func:`_chunk_result` on a Dask worker, its parallel work on ``run.worker_threads``
    threads when given."""
    if run.worker_threads is None:
        return _chunk_result(run, index)
    from .threads import limit_threads

    with limit_threads(run.worker_threads):
        return _chunk_result(run, index)


def _chunk_result(run: _Run, index: int) -> dict[str, NDArray[Any]]:
    """What a chunk sends back: its per-sample results (:func:`_run_chunk`), or their counts
    (:func:`_counted`) for a run that keeps the counts alone."""
    part = _run_chunk(run, index)
    if not run.counts_only:
        return part
    return _counted(part, ("open", "closed") if run.controller is not None else ("open",))


def _run_chunk(run: _Run, index: int) -> dict[str, NDArray[Any]]:
    """One chunk: draw, build, judge (open and closed loop), and count failures per bin of
    each parameter's draw."""
    z = run.draws(index)
    start = run.chunk_bounds(index)[0]
    try:
        A, B = run.aircraft.model_stack(run.axis, run.values(z, start))
    except AircraftDataError as error:  # a singular sample: named by its index in the run
        message = re.sub(
            r"\(sample (\d+) of the values\)",
            lambda found: f"(sample {start + int(found.group(1))} of the run)",
            str(error),
        )
        raise type(error)(message) from None
    eigenvalues = linalg.eigenvalues(A)
    out = {f"open_{k}": v for k, v in _judge(run, A, eigenvalues).items()}
    out["open_controlled"] = np.zeros(A.shape[0], dtype=bool)
    failed = (out["open_levels"] > run.required_level).any(axis=1)
    if run.controller is not None:
        try:
            closed, poles, controlled = _closed_loop(A, B, run.controller, eigenvalues)
        except AerocontrolError as error:  # a sample's design failed: named by its index in the run
            if error.batch_index is None:
                raise
            raise _renumbered(error, start + error.batch_index, "sample {} of the run") from None
        out.update({f"closed_{k}": v for k, v in _judge(run, closed, poles).items()})
        out["closed_controlled"] = controlled
        failed = (out["closed_levels"] > run.required_level).any(axis=1)
    # Decile bins of each standard-normal draw (edges Φ^-1(k / 10)).
    edges = _decile_edges()
    bins = np.searchsorted(edges, z)  # (samples, parameters)
    parameters = z.shape[1]
    flat = bins + SENSITIVITY_BINS * np.arange(parameters)
    size = parameters * SENSITIVITY_BINS
    out["bin_total"] = np.bincount(flat.ravel(), minlength=size).reshape(parameters, -1)
    out["bin_failed"] = np.bincount(flat[failed].ravel(), minlength=size).reshape(parameters, -1)
    out["failed"] = np.asarray(failed)
    return out


def _renumbered(error: AerocontrolError, index: int, phrase: str) -> AerocontrolError:
    """``error`` (of a batch kernel, "problem i of the batch") with ``phrase`` filled with
    ``index`` for the problem, and ``index`` as its batch_index: a failed design of a sample
    named by where it is, not by its place in the batch (one chunk, or the Damper's designed
    samples of one)."""
    local = error.batch_index
    message = str(error).replace(f"problem {local} of the batch", phrase.format(index), 1)
    renamed = type(error)(message)
    renamed.__dict__.update(error.__dict__)
    renamed.batch_index = index
    return renamed


@functools.cache
def _decile_edges() -> FloatArray:
    """Φ^-1(k / 10), k = 1..9: the edges of the sensitivity bins (computed once)."""
    return np.array([_normal_quantile(k / SENSITIVITY_BINS) for k in range(1, SENSITIVITY_BINS)])


def _normal_quantile(p: float) -> float:
    """Φ^-1(p) by bisection on Φ (to the doubles' resolution)."""
    low, high = -40.0, 40.0
    for _ in range(200):
        middle = 0.5 * (low + high)
        if middle in (low, high):
            break
        if 0.5 * math.erfc(-middle / math.sqrt(2.0)) < p:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


# --- Statistics --------------------------------------------------------------------------------


def _log_beta(a: float, b: float) -> float:
    """ln B(a, b). For an integer min(a, b) = s up to 10^6 (a rare event, or a rare non-event,
    the interval's parameters being integers), exactly as ln Γ(s) - Σ_{i<s} ln(t + i) with
    t the other one, Γ(t) / Γ(t + s) = 1 / Π (t + i): lgamma of a large t would lose its
    last digits to cancellation (ln Γ(10^12) ≈ 3·10^13)."""
    small, large = min(a, b), max(a, b)
    if small == int(small) and small <= 1e6 and large > 1e6:
        steps = np.arange(int(small), dtype=np.float64) / large
        return math.lgamma(small) - (small * math.log(large) + math.fsum(np.log1p(steps)))
    return math.lgamma(a) + math.lgamma(b) - math.lgamma(a + b)


def _incomplete_beta(
    x: float, a: float, b: float, log_beta: float | None = None, y: float | None = None
) -> float:
    """The regularized incomplete beta function I_x(a, b): its continued fraction (DLMF 8.17.22)
    evaluated by the modified Lentz method, on the side of the mean where it converges fast
    (I_x(a, b) = 1 - I_{1-x}(b, a)). ``y`` is 1 - x, exact where x is not (the swapped side):
    the logarithms are taken of whichever of x and y is not rounded, so that b ln(1 - x)
    keeps its digits for a tiny x and a huge b (10^12 samples)."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    log_beta = _log_beta(a, b) if log_beta is None else log_beta  # B(a, b) = B(b, a)
    y = 1.0 - x if y is None else y
    if x > (a + 1.0) / (a + b + 2.0):
        return 1.0 - _incomplete_beta(y, b, a, log_beta, x)
    log_x, log_y = (math.log(x), math.log1p(-x)) if x <= 0.5 else (math.log1p(-y), math.log(y))
    front = math.exp(a * log_x + b * log_y - log_beta) / a
    tiny = 1e-300
    f, c, d = 1.0, 1.0, 0.0
    for i in range(0, 100_000):
        m = i // 2
        if i == 0:
            numerator = 1.0
        elif i % 2 == 0:
            numerator = m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m))
        else:
            numerator = -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))
        d = 1.0 + numerator * d
        d = tiny if abs(d) < tiny else d
        d = 1.0 / d
        c = 1.0 + numerator / c
        c = tiny if abs(c) < tiny else c
        f *= c * d
        if abs(1.0 - c * d) < 1e-15:
            return front * (f - 1.0)
    raise ConvergenceError(f"the incomplete beta function I_{x}({a}, {b}) did not converge")


#: The most terms of a binomial tail summed term by term (:func:`_binomial_lower_tail`).
_BINOMIAL_TERMS = 10_000


def _binomial_lower_tail(x: float, n: int, k: int) -> float:
    """P(X <= k) for X ~ Binomial(n, x), the sum of its k + 1 terms (fsum), each term from the
    one before by the ratio (n - j) / (j + 1) · x / (1 - x) in logarithms: for integers,
    1 - I_x(k + 1, n - k) (DLMF 8.17.5), without the subtraction and without the continued
    fraction, which converges in O(sqrt(n)) steps of relative size far below its stopping
    test when one parameter is huge (n = 10^12)."""
    if x <= 0.0:
        return 1.0
    if x >= 1.0:
        return 0.0 if k < n else 1.0
    log_odds = math.log(x) - math.log1p(-x)
    log_term = n * math.log1p(-x)  # ln P(X = 0)
    carry = 0.0  # the running logarithm's rounding errors (Neumaier's compensated sum): it
    # starts near -n x, far larger than the terms near the quantile
    terms = [math.exp(log_term)]
    for j in range(k):
        step = math.log((n - j) / (j + 1)) + log_odds
        total = log_term + step
        if abs(log_term) >= abs(step):
            carry += (log_term - total) + step
        else:
            carry += (step - total) + log_term
        log_term = total
        terms.append(math.exp(log_term + carry))
    return min(math.fsum(terms), 1.0)


def _beta_quantile(q: float, a: float, b: float, upper: bool = False) -> float:
    """The x at which I_x(a, b) = q, or, ``upper``, at which the upper tail 1 - I_x(a, b) = q
    (the tail probability given itself, not 1 - q rounded: q = α/2 of a confidence of
    1 - 10^-12 keeps its digits), by bisection. For integers a and b with a <= 10^4 the
    upper tail is the binomial sum P(Binomial(a + b - 1, x) <= a - 1) where b > 10^6 or
    q < 10^-4."""
    low, high = 0.0, 1.0
    log_beta = _log_beta(a, b)
    # The sum where the continued fraction stalls (b > 10^6) or 1 - I_x would lose the tail's
    # digits (q < 10^-4); elsewhere the continued fraction is as exact and faster.
    summed = (
        upper and a == int(a) and b == int(b) and a <= _BINOMIAL_TERMS and (b > 1e6 or q < 1e-4)
    )
    for _ in range(2000):
        middle = 0.5 * (low + high)
        if middle in (low, high):
            break
        if summed:
            below = _binomial_lower_tail(middle, int(a + b - 1), int(a - 1)) > q
        elif upper:
            below = 1.0 - _incomplete_beta(middle, a, b, log_beta) > q
        else:
            below = _incomplete_beta(middle, a, b, log_beta) < q
        if below:
            low = middle
        else:
            high = middle
    return 0.5 * (low + high)


@register
@dataclass(frozen=True)
class Estimate:
    """A probability estimated from ``count`` of ``samples``, with its Clopper-Pearson interval
    at ``confidence``.

    Attributes
    ----------
    count : int
        The samples that had the event.
    samples : int
        All samples.
    value : float
        count / samples.
    low, high : float
        The Clopper-Pearson interval of the probability at ``confidence``.
    confidence : float
        The interval's confidence level, e.g. 0.95.

    Examples
    --------
    >>> from aerocontrol.robustness import clopper_pearson
    >>> e = clopper_pearson(0, 1000)           # no event in 1000: at most 0.37 %
    >>> e.value, e.low, round(e.high, 5), e.confidence
    (0.0, 0.0, 0.00368, 0.95)
    """

    count: int
    samples: int
    value: float
    low: float
    high: float
    confidence: float

    def __str__(self) -> str:
        return (
            f"{self.value:.4g} ({self.count} of {self.samples}; {self.confidence:.0%} interval "
            f"[{self.low:.6g}, {self.high:.6g}])"
        )


#: The most samples :func:`clopper_pearson` takes: beyond, an end below 1e-16 has 1 - x = 1
#: in doubles, and the continued fraction's error grows past 1e-3 of the interval's width.
MAX_SAMPLES = 10**12


def clopper_pearson(count: int, samples: int, confidence: float = 0.95) -> Estimate:
    """The estimate count / samples and its exact (Clopper-Pearson) interval (1), its ends to
    about 1e-9 relative at a million samples (ln B(a, b) from lgamma values near 1e7); up to
    :data:`MAX_SAMPLES` = 10^12 samples, to 1e-12 relative where the count is within 10^4 of
    0 or of ``samples``, and to 1e-3 of the interval's width for other counts (the continued
    fraction converging in O(sqrt(samples)) steps).

    Parameters
    ----------
    count : int
        The samples in which the event happened, 0 <= count <= samples.
    samples : int
        The samples drawn, positive, at most :data:`MAX_SAMPLES`.
    confidence : float, optional
        The confidence of the two-sided interval, in (0, 1) (default 0.95).

    Returns
    -------
    Estimate
        ``value`` = count / samples and the interval [``low``, ``high``], each end the
        quantile of a beta distribution (B(α/2; k, N - k + 1) and B(1 - α/2; k + 1, N - k),
        α = 1 - confidence; closed forms at k = 0 and k = N).

    Raises
    ------
    InvalidArgumentError
        ``count`` or ``samples`` not an int or out of order, ``samples`` above
        :data:`MAX_SAMPLES`, ``confidence`` outside (0, 1).

    Examples
    --------
    >>> from aerocontrol.robustness import clopper_pearson
    >>> e = clopper_pearson(0, 1000)           # no failure seen in 1000: at most 0.37 %
    >>> e.low, round(e.high, 5)
    (0.0, 0.00368)
    """
    for name, value in (("count", count), ("samples", samples)):
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
            raise InvalidArgumentError(f"{name} must be an int, got {value!r}")
    count = int(count)
    samples = int(samples)
    if samples <= 0 or not 0 <= count <= samples:
        raise InvalidArgumentError(
            f"count and samples must satisfy 0 <= count <= samples, samples > 0; got "
            f"{count} of {samples}"
        )
    if samples > MAX_SAMPLES:
        # 3 of 10^18 gave [5.6e-17, 8.8e-18] (1 - x rounded to 1), 10^7 of 10^15 an interval
        # 1e-3 off that did not hold the estimate, 10^17 of 10^18 an ArithmeticError.
        raise InvalidArgumentError(
            f"samples must be at most {MAX_SAMPLES:.0e} for an interval computed in doubles, "
            f"got {samples}"
        )
    confidence = real_scalar(confidence, "confidence")
    if not 0.0 < confidence < 1.0:
        raise InvalidArgumentError(f"confidence must be in (0, 1), got {confidence}")
    alpha = 1.0 - confidence
    # At count 0 (and count = samples) the quantile has the closed form 1 - (α/2)^(1/N)
    # (and (α/2)^(1/N)): B(q; 1, N) = 1 - (1 - q)^(1/N), exact where the continued fraction
    # loses digits next to the mean of a huge run.
    # (α/2)^(1/N) itself, not 1 - edge: at N = 1 and α = 10^-12 that would lose four digits.
    root = math.log(alpha / 2) / samples
    if count == 0:
        low, high = 0.0, -math.expm1(root)  # 1 - (α/2)^(1/N)
    elif count == samples:
        low, high = (alpha / 2) ** (1.0 / samples), 1.0
    else:
        low = _beta_quantile(alpha / 2, count, samples - count + 1)
        high = _beta_quantile(alpha / 2, count + 1, samples - count, upper=True)
    return Estimate(count, samples, count / samples, low, high, confidence)


# --- Results ----------------------------------------------------------------------------------


@register
@dataclass(frozen=True)
class LoopOutcome:
    """The judgement of every sample of one loop (open or closed).

    Attributes
    ----------
    levels : ndarray (samples, modes) of int8
        The MIL-F-8785C Level of each mode (4: worse than Level 3, or a mode that could not be
        judged), modes in the order of :attr:`MonteCarlo.modes`.
    stable : ndarray (samples,) of bool
        Every eigenvalue in the open left half-plane.
    unresolved : ndarray (samples,) of bool
        Models whose modes are not the classical ones: a roll and spiral coupled into one
        oscillation (both carry its Level, MIL-F-8785C 3.3.1.4), or interleaved longitudinal
        roots (both longitudinal modes Level 4).
    max_real : ndarray (samples,)
        The largest real part of the eigenvalues (1/s).
    quantities : dict of str to ndarray (samples,)
        The quantities the Levels judge ("dutch roll: zeta", "roll: time constant", ...), as
        :func:`aerocontrol.handling.mode_quantities` gives them; NaN for an unresolved mode.
    controlled : ndarray (samples,) of bool
        The controller acts on the sample (False in the open loop, and where a ``Damper`` has
        no Dutch roll oscillation to damp).

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> from aerocontrol.robustness import Damper, Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load(), Uncertainty({"Cn_beta": Normal(0.3)}), 1000, Damper(),
    ...                   axis="lateral", seed=1)
    >>> run.modes
    ('dutch roll', 'roll', 'spiral')
    >>> int((run.open_loop.levels[:, 0] > 1).sum()), int((run.closed_loop.levels[:, 0] > 1).sum())
    (999, 0)
    >>> sorted(run.open_loop.quantities)[:2]
    ['dutch roll: omega_n', 'dutch roll: zeta']
    """

    levels: NDArray[np.int8]
    """(samples, modes): the MIL-F-8785C Level of each mode (4: worse than Level 3, or a mode
    that could not be judged)."""
    stable: NDArray[np.bool_]
    """(samples,): every eigenvalue in the open left half-plane."""
    unresolved: NDArray[np.bool_]
    """(samples,): models whose modes are not the classical ones: a roll and spiral coupled
    into one oscillation (both carry its Level, MIL-F-8785C 3.3.1.4), or interleaved
    longitudinal roots (both longitudinal modes Level 4)."""
    max_real: FloatArray
    """(samples,): the largest real part of the eigenvalues."""
    quantities: dict[str, FloatArray]
    """(samples,) each: the quantities the Levels judge, "dutch roll: zeta", "dutch roll:
    omega_n", "roll: time constant", "spiral: time to double" (lateral) or "short period:
    zeta", ..., "phugoid: omega_n" (longitudinal), as
    :func:`aerocontrol.handling.mode_quantities` gives them; NaN for an unresolved mode."""
    controlled: NDArray[np.bool_]
    """(samples,): the controller acts on the sample (False in the open loop, and where a
    :class:`Damper` has no Dutch roll oscillation to damp)."""


class _RunSummary:
    """The probabilities, the sensitivity ranking and the text of a Monte Carlo run, from its
    counts (:class:`MonteCarlo` counts its per-sample arrays, :class:`MonteCarloCounts` holds
    the counts alone)."""

    aircraft: str
    axis: str
    parameters: tuple[str, ...]
    samples: int
    seed: int
    modes: tuple[str, ...]
    failures_by_bin: NDArray[np.int64]
    samples_by_bin: NDArray[np.int64]

    def _count(self, event: str, mode: str | None, level: int, loop: str) -> int:
        raise NotImplementedError

    def _has_closed_loop(self) -> bool:
        raise NotImplementedError

    def probability(
        self,
        event: str,
        mode: str | None = None,
        level: int = 1,
        loop: str = "auto",
        confidence: float = 0.95,
    ) -> Estimate:
        """The probability of ``event``: "unstable", "unresolved" (modes that are not the
        classical ones, such as a roll and spiral coupled into one oscillation, judged by
        3.3.1.4), "failed", or "level" (``mode`` meets ``level`` or better), for the closed loop if
        there is one (``loop="auto"``) or the loop named ("open", "closed"), with its
        Clopper-Pearson interval."""
        count = self._count(event, mode, level, loop)
        return clopper_pearson(count, self.samples, confidence)

    def sensitivity(self) -> list[tuple[str, float]]:
        """The parameters ranked by how much the failure rate depends on them: the spread
        (highest minus lowest) of the failure rate over the deciles of each parameter's draw,
        largest first."""
        with np.errstate(invalid="ignore", divide="ignore"):
            rates = self.failures_by_bin / self.samples_by_bin
        spread = np.nanmax(rates, axis=1) - np.nanmin(rates, axis=1)
        order = np.argsort(-spread, kind="stable")
        return [(self.parameters[k], float(spread[k])) for k in order]

    def _cells(self) -> tuple[str, list[tuple[str, str, str]], list[tuple[str, str]]]:
        """The title, (loop, event, estimate) per probability, and (parameter, spread) by
        decreasing failure-rate spread, as text."""
        title = (
            f"Monte Carlo: {self.aircraft}, {self.axis}, {self.samples} samples (seed "
            f"{self.seed}), parameters {', '.join(self.parameters)}"
        )
        loops = [("open loop", "open")] + (
            [("closed loop", "closed")] if self._has_closed_loop() else []
        )
        rows = []
        for label, loop in loops:
            rows.append((label, "P(unstable)", str(self.probability("unstable", loop=loop))))
            for mode in self.modes:
                estimate = self.probability("level", mode, 1, loop=loop)
                rows.append((label, f"P({mode} Level 1)", str(estimate)))
        rows.append(("", "P(failed)", str(self.probability("failed"))))
        ranked = [(name, f"{spread:.3g}") for name, spread in self.sensitivity()]
        return title, rows, ranked

    def __str__(self) -> str:
        title, rows, ranked = self._cells()
        lines = [title]
        for k, (label, event, estimate) in enumerate(rows):
            if not label:
                lines.append(f"  {event} = {estimate}")
            elif k == 0 or rows[k - 1][0] != label:
                lines.append(f"  {label}: {event} = {estimate}")
            else:
                lines.append(f"    {event} = {estimate}")
        listed = ", ".join(f"{name} {spread}" for name, spread in ranked)
        lines.append(f"  sensitivity (failure-rate spread over deciles): {listed}")
        return "\n".join(lines)

    def _tables(self) -> list[Tabular]:
        title, rows, ranked = self._cells()
        return [
            Tabular(title, ("loop", "event", "probability (interval)"), rows),
            Tabular(
                "sensitivity: failure-rate spread over the deciles of each parameter",
                ("parameter", "spread"),
                ranked,
            ),
        ]


@dataclass(frozen=True, eq=False)
class MonteCarlo(_RunSummary, Result):
    """The result of :func:`monte_carlo`.

    Attributes
    ----------
    aircraft : str
        The aircraft's name.
    aircraft_class, category : str
        The MIL-F-8785C Class and Flight Phase Category the Levels were judged for.
    axis : str
        "lateral" or "longitudinal".
    parameters : tuple of str
        The uncertain parameters, in the order of ``failures_by_bin``.
    modes : tuple of str
        The modes judged, in the order of the columns of each ``LoopOutcome.levels``.
    samples : int
        The number of samples.
    seed : int
        The seed of the draws.
    required_level : int
        The worst Level that does not count as a failure.
    open_loop : LoopOutcome
        The judgement of every sample without the controller.
    closed_loop : LoopOutcome or None
        The judgement with the controller; None without one.
    failed : ndarray (samples,) of bool
        A mode worse than ``required_level`` (of the closed loop when there is a controller).
    failures_by_bin : ndarray (parameters, 10) of int
        Failures among the samples in each decile of a parameter's draw.
    samples_by_bin : ndarray (parameters, 10) of int
        The samples in each decile.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> from aerocontrol.robustness import Damper, Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load(), Uncertainty({"Cn_beta": Normal(0.3)}), 1000, Damper(),
    ...                   axis="lateral", seed=1)
    >>> run.parameters, run.samples, int(run.failed.sum())
    (('Cn_beta',), 1000, 0)
    >>> int(run.samples_by_bin.sum())
    1000
    """

    aircraft: str
    aircraft_class: str
    category: str
    axis: str
    parameters: tuple[str, ...]
    modes: tuple[str, ...]
    samples: int
    seed: int
    required_level: int
    open_loop: LoopOutcome
    closed_loop: LoopOutcome | None
    failed: NDArray[np.bool_]
    """(samples,): a mode worse than ``required_level`` (of the closed loop when there is a
    controller). Instability alone is not failure: the specification allows a slow spiral or
    phugoid divergence (Tables VIII and 3.2.1.2), and every faster one is Level 4."""
    failures_by_bin: NDArray[np.int64]
    """(parameters, 10): failures among the samples in each decile of a parameter's draw."""
    samples_by_bin: NDArray[np.int64]
    source: _Run = field(repr=False, compare=False)
    """What the run drew from (to draw a sample's values again: :meth:`values`)."""

    def values(self, indices: ArrayLike) -> dict[str, FloatArray]:
        """The uncertain parameters' values of the samples ``indices`` (for instance
        ``np.flatnonzero(result.failed)``), drawn again from the seed: name to array.

        Examples
        --------
        >>> import numpy as np, aerocontrol
        >>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
        >>> plane = aerocontrol.aircraft.load("b747-cruise")
        >>> result = monte_carlo(plane, Uncertainty({"Cn_beta": Normal(0.5)}), 1000, seed=3)
        >>> failing = result.values(np.flatnonzero(result.failed)[:3])
        >>> failing["Cn_beta"].shape
        (3,)
        """
        wanted = np.asarray(indices)
        if wanted.ndim != 1 or not np.issubdtype(wanted.dtype, np.integer):
            raise InvalidArgumentError(
                f"indices must be a 1-D array of sample indices, got {wanted.dtype} of shape "
                f"{wanted.shape}"
            )
        if wanted.size and (wanted.min() < 0 or wanted.max() >= self.samples):
            raise InvalidArgumentError(
                f"indices must lie in [0, {self.samples}), got {wanted.min()} to {wanted.max()}"
            )
        run = self.source
        out = {name: np.empty(wanted.size) for name in self.parameters}
        chunks = wanted // run.chunk_size
        for chunk in np.unique(chunks):
            rows = np.flatnonzero(chunks == chunk)
            drawn = run.values(run.draws(int(chunk)), run.chunk_bounds(int(chunk))[0])
            for name in self.parameters:
                out[name][rows] = drawn[name][wanted[rows] - int(chunk) * run.chunk_size]
        return out

    def indicator(
        self, event: str, mode: str | None = None, level: int = 1, loop: str = "auto"
    ) -> NDArray[np.bool_]:
        """Per sample, whether ``event`` happened (as :meth:`probability` counts it)."""
        outcome = self.outcome(loop)
        if event == "unstable":
            return ~outcome.stable
        if event == "failed":
            return self.failed
        if event == "unresolved":
            return outcome.unresolved
        if event == "level":
            if mode not in self.modes:
                raise InvalidArgumentError(f"mode must be one of {self.modes}, got {mode!r}")
            level = _level(level, "level")
            met: NDArray[np.bool_] = outcome.levels[:, self.modes.index(mode)] <= level
            return met
        raise InvalidArgumentError(
            f"event must be 'unstable', 'unresolved', 'failed' or 'level', got {event!r}"
        )

    def outcome(self, loop: str = "auto") -> LoopOutcome:
        """The open loop (``"open"``), the closed loop (``"closed"``), or the closed loop if
        there is one (``"auto"``)."""
        if loop == "open" or (loop == "auto" and self.closed_loop is None):
            return self.open_loop
        if loop in ("closed", "auto"):
            if self.closed_loop is None:
                raise InvalidArgumentError("this run has no controller: no closed loop")
            return self.closed_loop
        raise InvalidArgumentError(f"loop must be 'auto', 'open' or 'closed', got {loop!r}")

    def _count(self, event: str, mode: str | None, level: int, loop: str) -> int:
        return int(self.indicator(event, mode, level, loop).sum())

    def _has_closed_loop(self) -> bool:
        return self.closed_loop is not None


@dataclass(frozen=True, eq=False)
class MonteCarloCounts(_RunSummary, Result):
    """The result of :func:`monte_carlo` with ``keep="counts"``: the counts its probabilities
    and sensitivity ranking are made of, without the per-sample arrays (each chunk is reduced
    where it runs, so a run of 10^9 samples on a cluster ships a few hundred integers a
    chunk). Its probabilities, sensitivity ranking and tables are those of the
    :class:`MonteCarlo` of the same run, to the bit.

    Attributes
    ----------
    aircraft, aircraft_class, category, axis, parameters, modes, samples, seed, required_level
        As for :class:`MonteCarlo`.
    level_counts : dict of str to ndarray (modes, 4) of int
        For "open" (and "closed", with a controller): the samples whose mode (a row, in the
        order of ``modes``) is at Level 1, 2, 3 and 4 (the columns).
    unstable, unresolved : dict of str to int
        For each loop: the samples with an eigenvalue in Re s >= 0, and those whose modes are
        not the classical ones (:attr:`LoopOutcome.unresolved`).
    failed : int
        The samples with a mode worse than ``required_level`` (of the closed loop when there
        is a controller).
    failures_by_bin, samples_by_bin : ndarray (parameters, 10) of int
        As for :class:`MonteCarlo`.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
    >>> uncertainty = Uncertainty({"Cn_beta": Normal(0.3)})
    >>> counts = monte_carlo(aircraft.load(), uncertainty, 4000, seed=1, keep="counts")
    >>> full = monte_carlo(aircraft.load(), uncertainty, 4000, seed=1)
    >>> counts.probability("level", "dutch roll") == full.probability("level", "dutch roll")
    True
    >>> counts.level_counts["open"][0].tolist()      # dutch roll at Levels 1, 2, 3, 4
    [1, 3973, 26, 0]
    """

    aircraft: str
    aircraft_class: str
    category: str
    axis: str
    parameters: tuple[str, ...]
    modes: tuple[str, ...]
    samples: int
    seed: int
    required_level: int
    level_counts: dict[str, NDArray[np.int64]]
    unstable: dict[str, int]
    unresolved: dict[str, int]
    failed: int
    failures_by_bin: NDArray[np.int64]
    samples_by_bin: NDArray[np.int64]

    def _has_closed_loop(self) -> bool:
        return "closed" in self.level_counts

    def _count(self, event: str, mode: str | None, level: int, loop: str) -> int:
        if loop not in ("auto", "open", "closed"):
            raise InvalidArgumentError(f"loop must be 'auto', 'open' or 'closed', got {loop!r}")
        if loop == "auto":
            loop = "closed" if self._has_closed_loop() else "open"
        elif loop == "closed" and not self._has_closed_loop():
            raise InvalidArgumentError("this run has no controller: no closed loop")
        if event == "unstable":
            return self.unstable[loop]
        if event == "failed":
            return self.failed
        if event == "unresolved":
            return self.unresolved[loop]
        if event == "level":
            if mode not in self.modes:
                raise InvalidArgumentError(f"mode must be one of {self.modes}, got {mode!r}")
            level = _level(level, "level")
            return int(self.level_counts[loop][self.modes.index(mode), :level].sum())
        raise InvalidArgumentError(
            f"event must be 'unstable', 'unresolved', 'failed' or 'level', got {event!r}"
        )


def _counted(part: Mapping[str, NDArray[Any]], loops: Sequence[str]) -> dict[str, NDArray[Any]]:
    """A chunk's per-sample results (:func:`_run_chunk`) reduced to the counts of
    :class:`MonteCarloCounts`, as int64 arrays (sums over chunks in any order are exact)."""
    counts: dict[str, NDArray[Any]] = {
        "failed": np.array(int(part["failed"].sum())),
        "bin_total": part["bin_total"],
        "bin_failed": part["bin_failed"],
    }
    for loop in loops:
        levels = part[f"{loop}_levels"]
        counts[f"{loop}_levels"] = np.stack(
            [np.bincount(levels[:, k] - 1, minlength=4)[:4] for k in range(levels.shape[1])]
        ).astype(np.int64)
        counts[f"{loop}_unstable"] = np.array(int((~part[f"{loop}_stable"]).sum()))
        counts[f"{loop}_unresolved"] = np.array(int(part[f"{loop}_unresolved"].sum()))
    return counts


def _outcome(parts: Sequence[dict[str, NDArray[Any]]], prefix: str) -> LoopOutcome:
    def joined(key: str) -> NDArray[Any]:
        return np.concatenate([part[f"{prefix}_{key}"] for part in parts])

    start = f"{prefix}_{_QUANTITY}"
    names = [key[len(start) :] for key in parts[0] if key.startswith(start)]
    return LoopOutcome(
        levels=joined("levels"),
        stable=joined("stable"),
        unresolved=joined("unresolved"),
        max_real=joined("max_real"),
        quantities={name: joined(_QUANTITY + name) for name in names},
        controlled=joined("controlled"),
    )


@overload
def monte_carlo(
    aircraft: Aircraft,
    uncertainty: Uncertainty,
    samples: int,
    controller: ArrayLike | Lqr | Damper | None = None,
    *,
    axis: str = "lateral",
    seed: int = 0,
    required_level: int = 1,
    chunk_size: int = CHUNK_SIZE,
    client: Any = None,
    progress: Callable[[int, int], object] | None = None,
    worker_threads: int | None = None,
    keep: Literal["samples"] = "samples",
) -> MonteCarlo: ...


@overload
def monte_carlo(
    aircraft: Aircraft,
    uncertainty: Uncertainty,
    samples: int,
    controller: ArrayLike | Lqr | Damper | None = None,
    *,
    axis: str = "lateral",
    seed: int = 0,
    required_level: int = 1,
    chunk_size: int = CHUNK_SIZE,
    client: Any = None,
    progress: Callable[[int, int], object] | None = None,
    worker_threads: int | None = None,
    keep: Literal["counts"],
) -> MonteCarloCounts: ...


def monte_carlo(
    aircraft: Aircraft,
    uncertainty: Uncertainty,
    samples: int,
    controller: ArrayLike | Lqr | Damper | None = None,
    *,
    axis: str = "lateral",
    seed: int = 0,
    required_level: int = 1,
    chunk_size: int = CHUNK_SIZE,
    client: Any = None,
    progress: Callable[[int, int], object] | None = None,
    worker_threads: int | None = None,
    keep: str = "samples",
) -> MonteCarlo | MonteCarloCounts:
    """Stochastic robustness by Monte Carlo evaluation: draw ``samples`` variants of
    ``aircraft`` from ``uncertainty``, and judge each one's modes (stability, MIL-F-8785C
    Levels), open loop and, with a ``controller``, closed loop.

    Parameters
    ----------
    aircraft : Aircraft
    uncertainty : Uncertainty
    samples : int
    controller : array_like (inputs, 4), Lqr, Damper or None
        Fixed state-feedback gains K (u = -K x, the same for every sample), or a design rule
        re-run per sample (:class:`Lqr`, :class:`Damper`).
    axis : {"lateral", "longitudinal"}
    seed : int
        The root of every draw: the same seed gives the same result, bitwise, however the
        chunks are run.
    required_level : int
        A sample fails when a mode is worse than this Level (see :attr:`MonteCarlo.failed`).
    chunk_size : int
        Samples per chunk (the unit of work and of the draws); part of the result's identity.
    client : dask.distributed.Client, optional
        Run the chunks on this Dask cluster (``pip install aerocontrol[distributed]``); only
        arrays of per-sample judgements come back. Start the workers with one thread each and
        ``RAYON_NUM_THREADS`` set to the cores each may use, so that they do not
        oversubscribe the machine.
    progress : callable, optional
        Called as ``progress(samples_done, samples)`` after each chunk (for a progress bar).
    worker_threads : int, optional
        With a ``client``: each chunk's parallel work runs on this many threads of its worker
        (:func:`aerocontrol.limit_threads`), so that workers do not oversubscribe their
        machine. The setting is the task thread's own, so a worker of several task threads
        runs each chunk on that many threads.
    keep : {"samples", "counts"}
        "samples": the judgement of every sample (:class:`MonteCarlo`, about 90 bytes a
        sample). "counts": only the counts the probabilities and the sensitivity ranking are
        made of (:class:`MonteCarloCounts`, the same numbers to the bit), each chunk reduced
        where it runs: for runs whose per-sample arrays would not fit, such as 10^9 samples
        on a cluster.

    Returns
    -------
    MonteCarlo or MonteCarloCounts

    Raises
    ------
    InvalidArgumentError
        A bad argument (named; ``progress`` neither callable nor None), or an uncertain
        parameter the aircraft does not have.
    ShapeError
        Gains of the wrong shape.
    MemoryError
        The per-sample results of ``samples`` would not fit in the memory left (measured
        after the first chunk, before the others run).
    AerocontrolError
        A sample whose :class:`Lqr` or :class:`Damper` design fails raises that design's
        error (NoStabilizingSolutionError, ...), its message starting "sample i of the run"
        and its ``batch_index`` i (:meth:`MonteCarlo.values` of a rerun without it draws
        the same values).

    Examples
    --------
    The 747's Dutch roll with Cn_beta known to 30 %: open loop it misses Level 1 in about one
    sample of 4000, and it is never unstable.

    >>> from aerocontrol import aircraft
    >>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load(), Uncertainty({"Cn_beta": Normal(0.3)}), 4000,
    ...                   axis="lateral", seed=1)
    >>> print(run.probability("unstable"))
    0 (0 of 4000; 95% interval [0, 0.000921795])
    """
    if not isinstance(aircraft, Aircraft):
        raise InvalidArgumentError(
            f"aircraft must be an aerocontrol.aircraft.Aircraft, got {type(aircraft).__name__}"
        )
    if not isinstance(uncertainty, Uncertainty):
        raise InvalidArgumentError(
            f"uncertainty must be an Uncertainty, got {type(uncertainty).__name__}"
        )
    if not isinstance(axis, str) or axis not in _AXIS_MODES:
        raise InvalidArgumentError(f"axis must be 'longitudinal' or 'lateral', got {axis!r}")
    for name in uncertainty.names:
        if name not in aircraft.derivatives and name not in SAMPLED_FIELDS:
            raise InvalidArgumentError(
                f"uncertainty: {name!r} is neither a derivative of {aircraft.name} nor one of "
                f"{', '.join(SAMPLED_FIELDS)}"
            )
        distribution = uncertainty.distributions[name]
        relative = getattr(distribution, "relative", True)  # LogNormal: relative to the nominal
        spread = next(iter(vars(distribution).values()))
        if relative and spread != 0.0 and _nominal(aircraft, name) == 0.0:
            # A scatter relative to a nominal value of zero would leave it at zero: not what
            # an uncertain parameter means.
            raise InvalidArgumentError(
                f"uncertainty[{name!r}]: a scatter relative to {aircraft.name}'s value 0 is no "
                "scatter; give it in the parameter's units (Normal or Uniform with "
                "relative=False)"
            )
    samples = positive_int(samples, "samples")
    if samples > MAX_SAMPLES:  # no interval for its probabilities (clopper_pearson)
        raise InvalidArgumentError(f"samples must be at most {MAX_SAMPLES:.0e}, got {samples}")
    chunk_size = positive_int(chunk_size, "chunk_size")
    optional_callable(progress, "progress")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InvalidArgumentError(f"seed must be a nonnegative int, got {seed!r}")
    required_level = _level(required_level, "required_level")
    gains: FloatArray | Lqr | Damper | None = None
    if isinstance(controller, Damper) and axis != "lateral":
        raise InvalidArgumentError("controller: a Damper damps the Dutch roll of the lateral model")
    if isinstance(controller, Lqr):
        inputs = 1 if axis == "longitudinal" else 2
        for name, size in (("Q", 4), ("R", inputs)):
            weight = getattr(controller, name)
            if weight is not None and weight.shape != (size, size):
                raise ShapeError(
                    f"controller.{name} must be {size} x {size} for the {axis} model, got shape "
                    f"{weight.shape}"
                )
    if isinstance(controller, (Lqr, Damper)):
        gains = controller
    elif controller is not None:
        gains = np.array(real_array(controller, "controller"))  # a copy, C-ordered
        check_finite(gains, "controller")
        inputs = 1 if axis == "longitudinal" else 2
        if gains.shape != (inputs, 4):
            raise ShapeError(
                f"controller gains must have shape ({inputs}, 4) for the {axis} model, got "
                f"{gains.shape}"
            )
    if worker_threads is not None:
        worker_threads = positive_int(worker_threads, "worker_threads")
    if keep not in ("samples", "counts"):
        raise InvalidArgumentError(f"keep must be 'samples' or 'counts', got {keep!r}")
    run = _Run(
        aircraft,
        uncertainty,
        axis,
        gains,
        samples,
        int(seed),
        chunk_size,
        required_level,
        worker_threads,
        keep == "counts",
    )
    indices = range(run.chunk_count)
    done = 0

    def advanced(index: int) -> None:
        nonlocal done
        start, stop = run.chunk_bounds(index)
        done += stop - start
        if progress is not None:
            progress(done, samples)

    parts: list[dict[str, NDArray[Any]]] = []
    if client is None:
        for i in indices:
            parts.append(_chunk_result(run, i))
            if i == 0 and not run.counts_only:
                _check_results_fit(parts[0], run)
            advanced(i)
    else:
        futures = client.map(
            _run_chunk_on_worker, [run] * run.chunk_count, list(indices), pure=False
        )
        for i, future in enumerate(futures):  # in chunk order; the cluster runs them all
            parts.append(future.result())
            if i == 0 and not run.counts_only:
                try:
                    _check_results_fit(parts[0], run)
                except MemoryError:
                    client.cancel(futures)
                    raise
            advanced(i)
    if run.counts_only:
        return _counts(parts, run)
    return MonteCarlo(
        aircraft=aircraft.name,
        aircraft_class=aircraft.aircraft_class,
        category=aircraft.category,
        axis=axis,
        parameters=uncertainty.names,
        modes=_AXIS_MODES[axis],
        samples=samples,
        seed=run.seed,
        required_level=required_level,
        open_loop=_outcome(parts, "open"),
        closed_loop=_outcome(parts, "closed") if gains is not None else None,
        failed=np.concatenate([part["failed"] for part in parts]),
        failures_by_bin=np.sum([part["bin_failed"] for part in parts], axis=0),
        samples_by_bin=np.sum([part["bin_total"] for part in parts], axis=0),
        source=run,
    )


def _counts(parts: Sequence[Mapping[str, NDArray[Any]]], run: _Run) -> MonteCarloCounts:
    """The chunks' counts (:func:`_counted`) summed into the run's."""
    loops = ("open", "closed") if run.controller is not None else ("open",)

    def total(key: str) -> Any:
        return np.sum([part[key] for part in parts], axis=0)

    return MonteCarloCounts(
        aircraft=run.aircraft.name,
        aircraft_class=run.aircraft.aircraft_class,
        category=run.aircraft.category,
        axis=run.axis,
        parameters=run.uncertainty.names,
        modes=_AXIS_MODES[run.axis],
        samples=run.samples,
        seed=run.seed,
        required_level=run.required_level,
        level_counts={loop: np.asarray(total(f"{loop}_levels"), dtype=np.int64) for loop in loops},
        unstable={loop: int(total(f"{loop}_unstable")) for loop in loops},
        unresolved={loop: int(total(f"{loop}_unresolved")) for loop in loops},
        failed=int(total("failed")),
        failures_by_bin=np.asarray(total("bin_failed"), dtype=np.int64),
        samples_by_bin=np.asarray(total("bin_total"), dtype=np.int64),
    )


def _check_results_fit(part: Mapping[str, NDArray[Any]], run: _Run) -> None:
    """MemoryError, before the other chunks run, when the run's per-sample results (measured
    on its first chunk, ``part``) would not fit in the memory this process may still use: the
    chunks' arrays and the joined ones are both held for a moment, so twice their size."""
    rows = run.chunk_bounds(0)[1]
    per_sample = sum(
        array.nbytes for key, array in part.items() if not key.startswith("bin_")
    ) / max(rows, 1)
    needed = 2.0 * per_sample * run.samples
    available = _available_memory()
    if available is not None and needed > available:
        raise MemoryError(
            f"samples={run.samples:,} keeps {per_sample:.0f} bytes of results per sample, "
            f"about {needed / 2**30:,.1f} GiB with the joining of the chunks, and this process "
            f"may use about {available / 2**30:,.1f} GiB more: run fewer samples (the "
            "probabilities' intervals narrow as 1/sqrt(samples)), or several runs of other "
            "seeds"
        )


def _available_memory() -> float | None:
    """The bytes of memory this process may still take: the kernel's MemAvailable, less
    where a cgroup's limit is nearer; None where neither is known (not Linux)."""
    available: float | None = None
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    available = float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    try:
        with open("/sys/fs/cgroup/memory.max", encoding="ascii") as limit_file:
            limit = limit_file.read().strip()
        with open("/sys/fs/cgroup/memory.current", encoding="ascii") as current_file:
            current = float(current_file.read().strip())
        if limit != "max":
            room = float(limit) - current
            available = room if available is None else min(available, room)
    except (OSError, ValueError):
        pass
    return available


def _level(value: object, name: str) -> int:
    """A MIL-F-8785C Level, 1, 2 or 3 (an int, not a bool or an array), by name."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InvalidArgumentError(f"{name} must be 1, 2 or 3, got {value!r}")
    if value not in (1, 2, 3):
        raise InvalidArgumentError(f"{name} must be 1, 2 or 3, got {value!r}")
    return int(value)
