"""Time responses of x' = Ax + Bη, y = Cx + Dη (chapter §6.2).

Every response is one exact discretisation and a recurrence in the Rust core (see
``rust/response.rs``), so there is no integration error on the grid:

* :func:`impulse_response`: η = η0 δ(t), x(t) = e^{At} B η0 (6.36), the free response from
  x(0) = B η0 (the impulse of the feedthrough D at t = 0 is not part of y);
* :func:`doublet_response`: η = η0 δ'(t), x(t) = e^{At} A B η0 (6.38);
* :func:`step_response`: η = η0 H(t), exact for singular A, where (6.43) fails;
* :func:`initial_response`: the free response from x0;
* :func:`forced_response`: a sampled input, held constant (ZOH) or linear (FOH) between samples.

η0 weights the inputs as in the chapter. Without it, a single-input system gets η0 = 1 and a
multi-input system one response per input (η0 the unit vectors).

Time grids must be uniform and start at 0 (anything else is an error that says what is wrong;
resample yourself with ``numpy.interp`` if needed). ``T`` may be a grid, a final time, or None
for the default grid: a step of 1/(20 |λ|max), twenty samples per time constant of the fastest
mode, and a final time of 7 time constants 1/|σ| of the slowest decaying mode (to 0.1 % of its
amplitude), or 10/|λ|min when no mode decays; at most 100,001 samples (the step grows to fit).
The default grid is made for any |λ|max up to 2.2e306, where 1/(20 |λ|max) is still a normal
double; beyond, it is refused by name (InvalidArgumentError: give the grid T). The step is
also at most 2^52 / ||A||_1 (for an A far from normal, whose norm exceeds its eigenvalues:
e^{hA} is refused beyond h ||A||_1 = 2^53), and where that needs more than 100,001 samples
the default grid is refused likewise. A final time T
whose 100 steps would be below the normal doubles (2.2e-306 s) is refused likewise, as is a
step of T too long for A (A times the step overflows).

Several responses come in one call: several initial states x0 (r, n), several input histories
u (r, k, m), or a list of models of one size (``[sys1, sys2, ...]``); the result then has a
leading response axis, ``x.shape == (r, k, n)``.

A discrete model (a :class:`~aerocontrol.StateSpace` with ``dt`` > 0) is its own recurrence,
x[k+1] = A x[k] + B η[k], y[k] = C x[k] + D η[k], on t = k dt; every time of a grid must be
a multiple of dt (a step of q dt gives every q-th sample, from the powers A^q and
Σ_{i<q} A^i B). The default grid then steps by dt up to the final time above (for the modes
of the equivalent continuous model s = ln(z)/dt), every q-th sample beyond 100,001. The
impulse of a discrete model is the unit-area pulse η[0] = η0/dt, η[k] = 0 after (as MATLAB's
and python-control's, so that it tends to the continuous impulse response as dt → 0; y[0]
holds D η0/dt). A doublet has no sampled equivalent and is refused. A list of models must
share their sampling period.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core, _scaling
from ._results import Result, Tabular
from ._validation import FloatArray, check_choice, check_finite, finite_or_warn, real_array
from .exceptions import (
    InvalidArgumentError,
    ShapeError,
    SingularMatrixError,
)
from .statespace import (
    StateSpace,
    as_state_space,
    grid_frequencies,
    identity,
    is_system,
    period,
    plant_arrays,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ._typing import System, Systems

__all__ = [
    "TimeResponse",
    "dc_gain",
    "default_time_grid",
    "doublet_response",
    "forced_response",
    "impulse_response",
    "initial_response",
    "steady_state",
    "step_response",
]

MAX_DEFAULT_SAMPLES = 100_001


@dataclass(frozen=True, eq=False)
class TimeResponse(Result):
    """States, outputs and inputs of one or several responses on a uniform time grid.

    With a single response ``x`` is (len(t), n); with several, (r, len(t), n), and likewise
    ``y`` and ``u`` (r is 0 for the impulse or step responses of a model without inputs).
    ``u`` is None for free, impulse and doublet responses.

    Attributes
    ----------
    t : ndarray (k,)
        The times (s), uniformly spaced.
    x : ndarray (k, n) or (r, k, n)
        The states.
    y : ndarray (k, p) or (r, k, p)
        The outputs.
    u : ndarray (k, m) or (r, k, m), or None
        The inputs; None for free, impulse and doublet responses.
    kind : str
        What the response is: ``"step"``, ``"impulse"``, ``"doublet"``, ``"initial"`` or
        ``"forced"``.
    state_names, input_names, output_names : tuple of str
        The model's names of its states, inputs and outputs.
    response_names : tuple of str
        One label per response (the input driven, the model index, or 'response k').
    n_responses : int
        The number of responses r (1 for a single one).

    Examples
    --------
    The unit step response of x' = -x + u, y = x is 1 - e^-t:

    >>> import numpy as np, aerocontrol
    >>> r = aerocontrol.step_response(aerocontrol.StateSpace([[-1.0]], [[1.0]], [[1.0]]),
    ...                               [0.0, 1.0, 2.0])
    >>> r.kind, r.n_responses, r.x.shape
    ('step', 1, (3, 1))
    >>> np.round(r.y[:, 0], 6), np.round(1 - np.exp(-r.t), 6)
    (array([0.      , 0.632121, 0.864665]), array([0.      , 0.632121, 0.864665]))
    """

    t: FloatArray
    x: FloatArray
    y: FloatArray
    u: FloatArray | None
    kind: str
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    response_names: tuple[str, ...]
    """One label per response (the input driven, the model index, or 'response k')."""

    @property
    def n_responses(self) -> int:
        return 1 if self.x.ndim == 2 else int(self.x.shape[0])

    def states(self, response: int = 0) -> FloatArray:
        """The (len(t), n) states of one response."""
        return self.x if self.x.ndim == 2 else self.x[response]

    def outputs(self, response: int = 0) -> FloatArray:
        """The (len(t), p) outputs of one response."""
        return self.y if self.y.ndim == 2 else self.y[response]

    def _cells(self) -> tuple[str, list[tuple[str, str, str, str]]]:
        """The title, and (response, state, final value, peak |x|) per state, as text."""
        title = (
            f"{self.kind} response: {self.n_responses} response(s), {len(self.t)} samples, "
            f"t = 0 ... {self.t[-1]:g} s (step {self.t[1] - self.t[0]:g} s)"
        )
        rows = []
        for r in range(self.n_responses):
            x = self.states(r)
            for name, value, peak in zip(
                self.state_names, x[-1], np.abs(x).max(axis=0), strict=True
            ):
                rows.append((self.response_names[r], name, f"{value:+.6g}", f"{peak:.4g}"))
        return title, rows

    def __str__(self) -> str:
        title, rows = self._cells()
        lines = [title]
        for k, (response, name, value, peak) in enumerate(rows):
            if k == 0 or rows[k - 1][0] != response:
                lines.append(f"  {response}: final state")
            lines.append(f"    {name:<14} {value}   (peak |x| {peak})")
        return "\n".join(lines)

    def _tables(self) -> list[Tabular]:
        title, rows = self._cells()
        return [Tabular(title, ("response", "state", "final", "peak |x|"), rows)]

    def _png(self) -> bytes | None:
        """The states of the first response, small (:func:`~aerocontrol.plotting.response_png`)."""
        if self.n_responses == 0 or len(self.t) < 2:
            return None
        from .plotting import response_png

        return response_png(self)

    def plot(self, ax: Axes | None = None, signal: str = "states", response: int = 0) -> Axes:
        """Plot the states (or ``signal="outputs"``) of one response against time."""
        from .plotting import plot_time_response

        return plot_time_response(self, ax=ax, signal=signal, response=response)


def _systems(sys: Systems) -> tuple[list[StateSpace], bool]:
    """The models, and whether several were given as a list."""
    if isinstance(sys, list) and sys and is_system(sys[0]):
        models = [as_state_space(s, f"sys[{k}]") for k, s in enumerate(sys)]
        first = models[0]
        for k, model in enumerate(models[1:], start=1):
            if (model.n_states, model.n_inputs, model.n_outputs) != (
                first.n_states,
                first.n_inputs,
                first.n_outputs,
            ):
                raise ShapeError(
                    f"sys[{k}] must have the states, inputs and outputs of sys[0] "
                    f"({first.n_states}, {first.n_inputs}, {first.n_outputs}), got "
                    f"({model.n_states}, {model.n_inputs}, {model.n_outputs})"
                )
        return models, True
    # Not a list of models: one model, whose conversion refuses an empty list by name.
    return [as_state_space(cast("System", sys))], False


def default_time_grid(sys: Systems) -> FloatArray:
    """The default grid of the responses (see the module documentation).

    A step of a twentieth of 1/ρ_max, ρ_max the largest modulus of an eigenvalue, and a final
    time of 7 time constants -1/σ of the slowest decaying mode (σ its real part; 10/ρ_min when
    no mode decays), at most 100,001 samples; a discrete model steps by its dt. A decaying
    mode slower than 1e-12 ρ_max, which the eigenvalues of A do not resolve from an
    integrator, is found from the largest eigenvalues of A^-1 (for a discrete model, of
    (A - I)^-1), of A on the complement of its null space where A is singular.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, system object, or list of them
        One model, or a list of models of one size and one sampling period (one response
        each, on a leading axis). Without C and D the output is the state.

    Returns
    -------
    ndarray (k,), s
        The times, uniform, from 0.

    Raises
    ------
    InvalidArgumentError
        An eigenvalue is so large (modulus ρ > 2e306) that the step 1/(20 ρ) would not be a
        normal double, or ||A||_1 is so far beyond the modes (a nilpotent A of 1e149) that a step
        with h ||A||_1 <= 2^52 needs more than 100,001 samples to the final time: give the
        grid T instead. Also a list of models of different sampling periods.
    NotRealError
        ``sys`` is not a model (a number, a string), or a matrix is complex.
    ShapeError
        The models of a list differ in size, or the matrices disagree in size.
    NonFiniteError
        A matrix contains NaN or an infinity.

    Examples
    --------
    x' = -x: steps of 1/20 s to 7 time constants.

    >>> import aerocontrol
    >>> t = aerocontrol.default_time_grid(([[-1.0]], [[1.0]]))
    >>> len(t), float(t[1]), float(t[-1])
    (141, 0.05, 7.0)
    """
    models, _ = _systems(sys)
    dt = _sampling_period(models)
    if dt > 0.0:
        return _discrete_grid(None, models, dt)[0]
    step, final = _default_step_and_final(models)
    step = _within_the_exponential(step, final, models)
    samples = _steps_within(final / step, MAX_DEFAULT_SAMPLES - 1) + 1
    return np.linspace(0.0, (samples - 1) * step, samples)


#: The largest ||h A||_1 of a default step h: the core refuses e^{hA} beyond 2^53 = 1/u
#: (IllConditionedError: the rounding of A alone changes every digit), and half of it keeps
#: the grid clear of that limit.
LARGEST_STEP_NORM = 2.0**52


def _within_the_exponential(step: float, final: float, models: list[StateSpace]) -> float:
    """The default step of continuous models, made smaller where h ||A||_1 exceeds
    :data:`LARGEST_STEP_NORM` (an A far from normal: a nilpotent A of 1e149 has no mode to
    set the step, yet e^{hA} is refused at h = 0.01), or refused by name where the final
    time would then need more than the samples allowed."""
    with np.errstate(over="ignore"):
        norm = max(float(np.abs(m.A).sum(axis=0).max(initial=0.0)) for m in models)
    if not step * norm > LARGEST_STEP_NORM:
        return step
    limit = LARGEST_STEP_NORM / norm
    if limit >= np.finfo(np.float64).tiny and final / limit <= MAX_DEFAULT_SAMPLES - 1:
        return limit
    raise InvalidArgumentError(
        f"the default time grid: A has the norm ||A||_1 = {norm:.3g}, far beyond its modes "
        f"(a final time of {final:.3g} s), so a step short enough for e^(hA) (h ||A||_1 at "
        f"most 2^52, h = {limit:.3g} s) needs more than {MAX_DEFAULT_SAMPLES} samples; give "
        "the grid T"
    )


def _steps_within(ratio: float, cap: int) -> int:
    """ceil(ratio) steps, at most ``cap``: the number of steps of a grid, from a ratio of
    times that may be huge or infinite (a final time of 1e300 over a step of 1e-300), which
    ``int`` cannot take (an OverflowError for an infinity); a ratio beyond the cap (or NaN,
    which the callers' finite positive times exclude) gives the cap."""
    if not ratio < cap:
        return cap
    return max(int(np.ceil(ratio)), 0)


def _sampling_period(models: list[StateSpace]) -> float:
    """The sampling period the models share (0.0 for continuous models); mixing is refused."""
    dt = period(models[0])

    def describe(period: float) -> str:
        return f"dt = {period:g} s" if period > 0 else "continuous"

    for k, model in enumerate(models[1:], start=1):
        if period(model) != dt:
            raise InvalidArgumentError(
                f"sys[{k}] must have the sampling period of sys[0] ({describe(dt)}), "
                f"got {describe(period(model))}"
            )
    return dt


def _default_step_and_final(models: list[StateSpace]) -> tuple[float, float]:
    eigenvalues, nonzero = grid_frequencies(models, "the default time grid")
    if nonzero.size == 0:
        return 0.01, 10.0
    fastest = float(nonzero.max())
    step = 0.05 / fastest  # 1/(20 |λ|max), without overflow in 20 |λ|max
    if step < np.finfo(np.float64).tiny:
        raise InvalidArgumentError(
            f"the default time grid: the fastest mode (|λ| = {fastest:.3g}) needs a step "
            f"of {step:.3g}, below the normal doubles; give the grid T"
        )
    resolved = eigenvalues.real < -1e-12 * fastest
    decaying = -eigenvalues.real[resolved]
    if not np.all(resolved):
        # Modes within 1e-12 |λ|max of the imaginary axis, where the eigenvalues of A are
        # rounding: those that decay, found from the largest eigenvalues of A^-1.
        decaying = np.concatenate([decaying, *(_slow_decay_rates(m, fastest) for m in models)])
    final = 7.0 / decaying.min() if decaying.size else 10.0 / nonzero.min()
    final = max(final, 100 * step)
    with np.errstate(over="ignore"):  # 7e11 s over a step of 5e-302 s: inf, beyond the cap
        ratio = final / step
    if ratio > MAX_DEFAULT_SAMPLES - 1:
        step = final / (MAX_DEFAULT_SAMPLES - 1)
    return step, final


def _slow_modes(model: StateSpace, fastest: float) -> NDArray[np.complex128]:
    """The model's nonzero modes slower than 1e-12 ``fastest`` (continuous eigenvalues; for a
    discrete model s = ln(z)/dt), which the eigenvalues of A (errors of u ||A||) do not
    resolve from zero: the eigenvalues of M = A (discrete: A - I) are 1/μ for μ those of
    M^-1, whose largest are resolved to a relative u. M^-1 is solved as the steady state is
    (equilibrated where the core refuses M), block by block (:func:`_inverse_eigenvalues_of`),
    so that an integrator is set apart exactly."""
    n = model.n_states
    none = np.zeros(0, dtype=np.complex128)
    if n == 0:
        return none
    dt = period(model)
    M = model.A - np.eye(n) if dt else model.A
    mu = _inverse_eigenvalues_of(M)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        slow = 1.0 / mu[mu != 0]
        if dt:
            slow = np.log1p(slow) / dt
    keep = np.isfinite(slow) & (slow != 0) & (np.abs(slow) < 1e-12 * fastest)
    return np.asarray(slow[keep], dtype=np.complex128)


def _inverse_eigenvalues(M: FloatArray) -> NDArray[np.complex128] | None:
    """The eigenvalues of M^-1, or None where M is singular to working precision after
    equilibration (refused, or an inverse beyond the doubles)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            inverse = -_equilibrated_solve(M, np.eye(len(M)), np.eye(len(M)), False)
    except SingularMatrixError:
        return None
    if not np.all(np.isfinite(inverse)):
        return None
    return np.asarray(_core.eigenvalues(inverse), dtype=np.complex128)


def _inverse_eigenvalues_of(M: FloatArray) -> NDArray[np.complex128]:
    """The eigenvalues of M^-1, M on the complement of its zero eigenvalues where it is
    singular. M is first split, exactly, into its irreducible diagonal blocks
    (:func:`_irreducible_blocks`: the eigenvalues of M are theirs); an integrator is a block
    [0], dropped. A block singular to working precision is deflated (:func:`_deflated`),
    again while it is singular, before it is inverted. The exact split keeps the slow modes
    of a model whose integrator is coupled one way (x_i' = c x_j), which an orthogonal
    deflation of all of M would blur by u ||M||, and which an LU solve of all of M (an exactly
    singular triangular M, permuted) may not even find singular."""
    found = [np.zeros(0, dtype=np.complex128)]
    for block in _irreducible_blocks(M):
        if block.shape == (1, 1) and block[0, 0] == 0.0:
            continue
        for _ in range(len(block)):  # each deflation removes one state
            mu = _inverse_eigenvalues(block)
            if mu is not None:
                found.append(mu)
                break
            deflated = _deflated(block)
            if deflated is None:
                break
            block = deflated
    return np.concatenate(found)


def _irreducible_blocks(M: FloatArray) -> list[FloatArray]:
    """The diagonal blocks of M's block triangular form by a permutation: the states of each
    strongly connected component of the graph with an edge j -> i where M_ij != 0. In that
    form M is block triangular, so its eigenvalues are the blocks' (a permutation: exact)."""
    n = len(M)
    reach = (M != 0) | np.eye(n, dtype=bool)
    for k in range(n):  # Warshall's transitive closure
        reach |= reach[:, k : k + 1] & reach[k : k + 1, :]
    component = reach & reach.T
    blocks = []
    assigned = np.zeros(n, dtype=bool)
    for i in range(n):
        if not assigned[i]:
            members = np.flatnonzero(component[i])
            assigned[members] = True
            blocks.append(M[np.ix_(members, members)])
    return blocks


def _deflated(M: FloatArray) -> FloatArray | None:
    """W^T M W for W an orthonormal basis of the complement of M's most nearly null direction
    v_0 (the right singular vector of its smallest singular value), or None for a single
    state. M v_0 = 0 for an integrator's state, so in the orthogonal basis [W v_0],
    M = [[W^T M W, 0], [v_0^T M W, 0]]: the eigenvalues of M are those of W^T M W and a zero
    (a chain or several of them leave W^T M W singular, and it is deflated again). One
    direction at a time: a threshold on the singular values (n u σ_max) would take a decaying
    mode slower than it for null space too, the very modes the inverse is to resolve."""
    n = len(M)
    if n < 2:
        return None
    W = np.linalg.svd(M)[2][:-1].T
    return np.asarray(W.T @ M @ W, dtype=np.float64)


def _slow_decay_rates(model: StateSpace, fastest: float) -> FloatArray:
    """The decay rates -Re λ of the ``_slow_modes`` that decay (Re λ < -1e-12 |λ|: an
    undamped one with a real part of rounding does not)."""
    slow = _slow_modes(model, fastest)
    decaying = slow.real < -1e-12 * np.abs(slow)
    return np.asarray(-slow.real[decaying], dtype=np.float64)


def _grid(T: ArrayLike | None, models: list[StateSpace]) -> tuple[FloatArray, float]:
    """(t, step) for the T given: a grid, a final time, or None."""
    if T is None:
        t = default_time_grid(models)
        return t, float(t[1] - t[0])
    times = real_array(T, "T")
    if times.ndim == 0:
        final = float(times)
        if not np.isfinite(final) or final <= 0:
            raise InvalidArgumentError(
                f"T as a final time must be positive and finite, got {final}"
            )
        step, _ = _default_step_and_final(models)
        samples = max(_steps_within(final / step, MAX_DEFAULT_SAMPLES - 1), 100) + 1
        if final / (samples - 1) < np.finfo(np.float64).tiny:
            raise InvalidArgumentError(
                f"T as a final time ({final:g} s) is too short for a grid: its {samples - 1} "
                f"steps of {final / (samples - 1):.3g} s would be below the normal doubles "
                f"({np.finfo(np.float64).tiny:.3g}), where a uniform grid cannot be "
                "represented; give a final time of at least "
                f"{(samples - 1) * np.finfo(np.float64).tiny:.3g} s"
            )
        t = np.linspace(0.0, final, samples)
        return t, float(t[1] - t[0])
    step = _core.grid_step(times)
    return times, step


#: A grid step within this relative distance of q dt is q dt.
GRID_MULTIPLE_TOLERANCE = 1e-9


def _discrete_grid(
    T: ArrayLike | None, models: list[StateSpace], dt: float
) -> tuple[FloatArray, int]:
    """(t, q) for discrete models sampled every dt: the times, q dt apart.

    A final time or a step more than 2^1023 sampling periods long (a dt of 1e-300 against a
    final time of 1e10) has no count of periods in doubles: refused by name, T (or the
    default grid, which is given the final time of the slowest mode), not an OverflowError."""
    if T is None:
        _, final = _default_step_and_final(models)
        periods = _periods(
            final / dt - GRID_MULTIPLE_TOLERANCE,
            dt,
            f"the default time grid's final time of {final:g} s (7 time constants)",
        )
        steps = max(int(np.ceil(periods)), 100)
    else:
        times = real_array(T, "T")
        if times.ndim == 0:
            final = float(times)
            if not (np.isfinite(final) and final >= dt * (1.0 - GRID_MULTIPLE_TOLERANCE)):
                raise InvalidArgumentError(
                    f"T as a final time must be finite and at least the sampling period "
                    f"dt = {dt:g} s, got {final}"
                )
            periods = _periods(final / dt + GRID_MULTIPLE_TOLERANCE, dt, f"T = {final:g} s")
            steps = int(np.floor(periods))
        else:
            step = _core.grid_step(times)
            q = round(_periods(step / dt, dt, f"T's step of {step:g} s"))
            if q < 1 or abs(step - q * dt) > GRID_MULTIPLE_TOLERANCE * step:
                raise InvalidArgumentError(
                    f"T must be a grid of multiples of the sampling period dt = {dt:g} s "
                    f"(t = k dt), got a step of {step:g} s"
                )
            return np.array(times, dtype=np.float64), q
    q = max(1, int(np.ceil(steps / (MAX_DEFAULT_SAMPLES - 1))))
    samples = steps // q + 1
    return np.arange(samples, dtype=np.float64) * (q * dt), q


def _periods(ratio: float, dt: float, what: str) -> float:
    """A number of sampling periods, refused by name when it overflows (the ratio of a time
    to a tiny dt): no count of periods then exists in doubles, and ``int`` would raise an
    OverflowError."""
    if not np.isfinite(ratio):
        raise InvalidArgumentError(
            f"{what} is more than {np.finfo(np.float64).max:.3g} sampling periods of "
            f"dt = {dt:g} s: the number of steps overflows double precision; give a grid "
            "T of fewer sampling periods"
        )
    return ratio


def _every_qth(model: StateSpace, q: int) -> tuple[FloatArray, FloatArray]:
    """(A^q, Σ_{i<q} A^i B): the recurrence of a discrete model between every q-th sample, the
    blocks of M^q for M = [[A, B], [0, I]].

    Binary powering on E_k = M^k - I (E_{j+k} = E_j E_k + E_j + E_k), not on M^k: a slow mode
    has A^q close to I, and M^k itself would carry its difference from I, which sets the
    steady state, with an absolute error of q u instead of u.

    Where q is so large that A^q or the sum overflows (an unstable or marginal mode over
    10^k sampling periods), the recurrence between the samples of T does not exist in
    doubles: refused by name (T), where numpy would warn and the core refuse the infinite
    matrices as if they were the caller's."""
    if q == 1:
        return model.A, model.B
    n, m = model.n_states, model.n_inputs
    base = np.zeros((n + m, n + m))
    base[:n, :n], base[:n, n:] = model.A - np.eye(n), model.B
    power = np.zeros_like(base)
    steps = q
    with np.errstate(all="ignore"):
        while q:
            if q & 1:
                power = power @ base + power + base
            q >>= 1
            if q:
                base = base @ base + 2.0 * base
    if not np.all(np.isfinite(power)):
        raise InvalidArgumentError(
            f"T steps by q = {float(steps):.6g} sampling periods, and the recurrence over one "
            "step "
            "(A^q and the sum of A^i B for i < q) overflows double precision: give a grid "
            "with a smaller step"
        )
    return np.eye(n) + power[:n, :n], power[:n, n:]


def _simulate(
    models: list[StateSpace],
    several: bool,
    x0: FloatArray,
    u: FloatArray | None,
    eta0: FloatArray | None,
    step: float,
    samples: int,
    q: int,
    method: str = "zoh",
) -> tuple[FloatArray, FloatArray]:
    """The core's simulation of one model or of a stack: continuous with the hold ``method``
    (q = 0), or discrete, every q-th sample."""
    if q:
        pairs = [_every_qth(model, q) for model in models]
        method, step = "discrete", period(models[0])
    else:
        pairs = [(model.A, model.B) for model in models]
    if several:
        with _grid_step_named_T(step):
            return _core.simulate_models(
                np.stack([a for a, _ in pairs]),
                np.stack([b for _, b in pairs]),
                np.stack([m.C for m in models]),
                np.stack([m.D for m in models]),
                x0,
                u,
                eta0,
                step,
                samples,
                method,
            )
    (A, B), model = pairs[0], models[0]
    with _grid_step_named_T(step):
        return _core.simulate(A, B, model.C, model.D, x0, u, eta0, step, samples, method)


@contextmanager
def _grid_step_named_T(step: float) -> Iterator[None]:
    """The core's refusal of its step ``dt`` (A dt overflows: a step of 1e300 for an A of
    1e10) as the refusal of the caller's argument, T, whose step it is."""
    try:
        yield
    except InvalidArgumentError as error:
        if error.argument != "dt":
            raise
        refusal = InvalidArgumentError(
            f"T steps by {step:.6g} s, too long for the model: A times the step overflows "
            "double precision (the exponential e^{A h} of one step cannot be formed); give a "
            "grid with a smaller step"
        )
        refusal.argument, refusal.value = "T", step
        raise refusal from error


def _time_grid(T: ArrayLike | None, models: list[StateSpace]) -> tuple[FloatArray, float, int]:
    """(t, step, q): the times and, for continuous models, the step (q = 0); for discrete
    ones, the number q of recurrence steps per sample (step = q dt)."""
    dt = _sampling_period(models)
    if dt > 0.0:
        t, q = _discrete_grid(T, models, dt)
        return t, q * dt, q
    t, step = _grid(T, models)
    return t, step, 0


def _input_weights(eta0: ArrayLike | None, m: int) -> tuple[FloatArray, tuple[str, ...] | None]:
    """The η0 of each response (r, m) and, for the unit vectors, None (names from inputs)."""
    if eta0 is None:
        return np.eye(m), None
    weights = real_array(eta0, "eta0")
    if weights.ndim == 0 and m == 1:  # a number for the one input
        weights = weights.reshape(1)
    if weights.ndim != 1 or weights.shape[0] != m:
        raise ShapeError(f"eta0 must have one weight per input ({m}), got shape {weights.shape}")
    # C-ordered: the products with B (an impulse's B η0) must not depend on the caller's
    # layout (a matmul on negative strides rounds differently from one on a C array).
    return np.ascontiguousarray(check_finite(weights, "eta0").reshape(1, m)), ("eta0",)


def _assemble(
    kind: str,
    t: FloatArray,
    x: FloatArray,
    y: FloatArray,
    u: FloatArray | None,
    model: StateSpace,
    names: Sequence[str],
    several: bool,
) -> TimeResponse:
    """The result; x, y and u are (r, len(t), ...) stacks, given as one response unless
    ``several`` was asked for or there is not exactly one (r = 0: a model without inputs has
    no impulse or step responses). The result owns its arrays: t and u are copied, since
    they may be the caller's."""
    if not several and x.shape[0] == 1:
        x, y = x[0], y[0]
        u = None if u is None else u[0]
    return TimeResponse(
        t=np.array(t, dtype=np.float64),
        x=x,
        y=y,
        u=None if u is None else np.array(u, dtype=np.float64),
        kind=kind,
        state_names=model.state_names,
        input_names=model.input_names,
        output_names=model.output_names,
        response_names=tuple(names),
    )


def _free_responses(
    kind: str,
    sys: Systems,
    T: ArrayLike | None,
    initial: Callable[[StateSpace], FloatArray],
    names: Sequence[str] | None = None,
) -> TimeResponse:
    """Free responses from initial states computed per model by ``initial(model)`` (r, n)."""
    models, several_models = _systems(sys)
    t, step, q = _time_grid(T, models)
    first = models[0]
    if several_models:
        x0 = np.stack([_first(initial(m), kind) for m in models])
        x, y = _simulate(models, True, x0, None, None, step, len(t), q)
        model_labels = [f"model {k}" for k in range(len(models))]
        return _assemble(kind, t, x, y, None, first, model_labels, True)
    x0 = initial(first)
    x, y = _simulate(models, False, x0, None, None, step, len(t), q)
    labels: Sequence[str] = (
        names if names is not None else [f"response {k}" for k in range(len(x0))]
    )
    return _assemble(kind, t, x, y, None, first, labels, len(x0) > 1)


def _first(rows: FloatArray, kind: str) -> FloatArray:
    """The first row: a list of models has one response per model, from the first input
    weight (or initial state); there is none for a model without inputs."""
    if rows.shape[0] == 0:
        raise ShapeError(
            f"a list of models has one {kind} response per model, to its first input (or "
            "from the first initial state); there is none: the models have no inputs, or x0 "
            "no rows"
        )
    first: FloatArray = rows[0]
    return first


def impulse_response(
    sys: Systems, T: ArrayLike | None = None, eta0: ArrayLike | None = None
) -> TimeResponse:
    """Response to η = η0 δ(t): x(t) = e^{At} B η0, y = C x (chapter (6.36)).

    Equal to the free response from x(0) = B η0. Without ``eta0`` a multi-input system gives
    one response per input.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, system object, or list of them
        One model, or a list of models of one size and one sampling period (one response
        each, on a leading axis). Without C and D the output is the state.
    T : array_like (k,) or float, s, optional
        A uniform grid starting at 0, a final time, or None (default) for the default grid
        (:func:`default_time_grid`).
    eta0 : array_like (m,) or (r, m), optional
        The input weights η0, one vector or r of them; default 1 for a single input, the m
        unit vectors (one response per input) for several.

    Returns
    -------
    TimeResponse
        ``t`` (k,), states ``x`` (k, n), outputs ``y`` (k, p) and inputs ``u``, with a
        leading response axis (r, k, ...) for several responses or models.

    Raises
    ------
    InvalidArgumentError
        T is not uniform, does not start at 0, is not a positive finite final time, is not a
        multiple of a discrete model's dt, or its step is too long for A; a list mixes
        sampling periods; or the default grid cannot be made (an eigenvalue beyond 2e306:
        give T).
        Also x(0) = B η0 overflowing.
    ShapeError
        ``eta0`` has not one weight per input.
    NotRealError
        ``sys`` is not a model (a number, a string), or a matrix is complex.
    ShapeError
        The models of a list differ in size, or the matrices disagree in size.
    NonFiniteError
        A matrix or an input weight contains NaN or an infinity.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> r = aerocontrol.impulse_response((A, B), T=np.linspace(0, 20, 201))
    >>> r.x.shape
    (201, 4)
    >>> np.allclose(r.x[0], B[:, 0])
    True

    A discrete model gets the unit-area pulse η[0] = η0/dt (see the module documentation):

    >>> d = aerocontrol.StateSpace([[0.5]], [[1.0]], [[1.0]], [[0.0]], dt=0.1)
    >>> aerocontrol.impulse_response(d, T=0.3).y[:, 0]
    array([ 0. , 10. ,  5. ,  2.5])
    """
    models, several_models = _systems(sys)
    weights, names = _input_weights(eta0, models[0].n_inputs)
    labels = names or models[0].input_names
    if _sampling_period(models) > 0.0:
        return _discrete_impulse(models, several_models, T, weights, labels)
    return _free_responses(
        "impulse", sys, T, lambda m: _initial_state(lambda: weights @ m.B.T, "B eta0"), labels
    )


def _discrete_impulse(
    models: list[StateSpace],
    several: bool,
    T: ArrayLike | None,
    weights: FloatArray,
    labels: Sequence[str],
) -> TimeResponse:
    """The response of discrete models to the pulse η[0] = η0/dt: x[0] = 0, y[0] = D η0/dt,
    then the free response from x[q] = A^(q-1) B η0/dt."""
    dt = period(models[0])
    t, q = _discrete_grid(T, models, dt)
    pulses = weights[:1] if several else weights

    def start(model: StateSpace) -> FloatArray:
        # A^(q-1) may overflow for a step of many periods: refused by _initial_state.
        return _initial_state(
            lambda: pulses @ (np.linalg.matrix_power(model.A, q - 1) @ model.B).T / dt,
            "A^(q-1) B eta0 / dt",
        )

    x0 = np.stack([start(m)[0] for m in models]) if several else start(models[0])
    x, y = _simulate(models, several, x0, None, None, q * dt, len(t) - 1, q)
    with np.errstate(over="ignore", invalid="ignore"):
        first_outputs = np.stack([pulses @ m.D.T / dt for m in models])
    first_outputs = first_outputs[:, 0] if several else first_outputs[0]
    x = np.concatenate([np.zeros((x.shape[0], 1, x.shape[2])), x], axis=1)
    y = np.concatenate([first_outputs[:, None, :], y], axis=1)
    names = [f"model {k}" for k in range(len(models))] if several else labels
    return _assemble("impulse", t, x, y, None, models[0], names, several or len(pulses) > 1)


def doublet_response(
    sys: Systems, T: ArrayLike | None = None, eta0: ArrayLike | None = None
) -> TimeResponse:
    """Response to η = η0 δ'(t): x(t) = e^{At} A B η0, y = C x (chapter (6.38)).

    Equal to the free response from x(0) = A B η0. Continuous models only: a doublet has no
    sampled equivalent.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, system object, or list of them
        One model, or a list of models of one size and one sampling period (one response
        each, on a leading axis). Without C and D the output is the state.
    T : array_like (k,) or float, s, optional
        A uniform grid starting at 0, a final time, or None (default) for the default grid
        (:func:`default_time_grid`).
    eta0 : array_like (m,) or (r, m), optional
        The input weights η0, one vector or r of them; default 1 for a single input, the m
        unit vectors (one response per input) for several.

    Returns
    -------
    TimeResponse
        ``t`` (k,), states ``x`` (k, n), outputs ``y`` (k, p) and inputs ``u``, with a
        leading response axis (r, k, ...) for several responses or models.

    Raises
    ------
    InvalidArgumentError
        A discrete model (use :func:`forced_response`); x(0) = A B η0 overflows; or T is not
        uniform, does not start at 0, or is not a positive finite final time.
    ShapeError
        ``eta0`` has not one weight per input.
    NotRealError
        ``sys`` is not a model (a number, a string), or a matrix is complex.
    ShapeError
        The models of a list differ in size, or the matrices disagree in size.
    NonFiniteError
        A matrix or an input weight contains NaN or an infinity.

    Examples
    --------
    x' = -x + η, y = x: the doublet response is y = -e^{-t}.

    >>> import numpy as np, aerocontrol
    >>> r = aerocontrol.doublet_response(([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), T=[0, 1, 2])
    >>> np.round(r.y[:, 0], 6)
    array([-1.      , -0.367879, -0.135335])
    """
    models, _ = _systems(sys)
    if _sampling_period(models) > 0.0:
        raise InvalidArgumentError(
            "a doublet (the derivative of an impulse) has no sampled equivalent: "
            "doublet_response takes continuous models; give a discrete model its input "
            "sequence with forced_response"
        )
    weights, names = _input_weights(eta0, models[0].n_inputs)
    labels = names or models[0].input_names
    return _free_responses(
        "doublet",
        sys,
        T,
        # A (B η0), the order of the definition: (A B) η0 underflowed A B of 1e-452 to
        # zero where A (B η0) with an η0 of 1e149 is 2e-303.
        lambda m: _initial_state(lambda: (weights @ m.B.T) @ m.A.T, "A B eta0"),
        labels,
    )


def _initial_state(form: Callable[[], FloatArray], what: str) -> FloatArray:
    """The initial states of an impulse or doublet, refused if forming them overflowed."""
    with np.errstate(over="ignore", invalid="ignore"):
        states = form()
    if not np.all(np.isfinite(states)):
        raise InvalidArgumentError(
            f"the response starts from x(0) = {what}, which overflows double precision "
            "(infinite entries): scale the model or the input weights eta0"
        )
    return states


def initial_response(sys: Systems, x0: ArrayLike, T: ArrayLike | None = None) -> TimeResponse:
    """The free response x(t) = e^{At} x0 (6.31), y = C x; for a discrete model
    x[k] = A^k x0.

    ``x0`` is one initial state (n,) or several (r, n), computed in one call.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, system object, or list of them
        One model, or a list of models of one size and one sampling period (one response
        each, on a leading axis). Without C and D the output is the state.
    x0 : array_like (n,) or (r, n)
        The initial state, or r of them.
    T : array_like (k,) or float, s, optional
        A uniform grid starting at 0, a final time, or None (default) for the default grid
        (:func:`default_time_grid`).

    Returns
    -------
    TimeResponse
        ``t`` (k,), states ``x`` (k, n), outputs ``y`` (k, p) and inputs ``u``, with a
        leading response axis (r, k, ...) for several responses or models.

    Raises
    ------
    ShapeError
        ``x0`` has not n values per state.
    InvalidArgumentError
        T is not uniform, does not start at 0, is not a positive finite final time, is not a
        multiple of a discrete model's dt, or its step is too long for A; a list mixes
        sampling periods; or the default grid cannot be made (an eigenvalue beyond 2e306:
        give T).
    NotRealError
        ``sys`` is not a model (a number, a string), or a matrix is complex.
    ShapeError
        The models of a list differ in size, or the matrices disagree in size.
    NonFiniteError
        A matrix or an input weight contains NaN or an infinity.

    Examples
    --------
    x' = -x from x(0) = 1 and 2: y = x0 e^{-t}.

    >>> import numpy as np, aerocontrol
    >>> r = aerocontrol.initial_response(([[-1.0]], [[1.0]]), [[1.0], [2.0]], T=[0, 1, 2])
    >>> r.x.shape
    (2, 3, 1)
    >>> np.round(r.x[:, :, 0], 6)
    array([[1.      , 0.367879, 0.135335],
           [2.      , 0.735759, 0.270671]])
    """
    models, _ = _systems(sys)
    n = models[0].n_states
    states = np.ascontiguousarray(real_array(x0, "x0"))
    if states.ndim == 1:
        states = states.reshape(1, -1)
    if states.ndim != 2 or states.shape[1] != n:
        raise ShapeError(
            f"x0 must be one initial state of {n} values or an (r, {n}) array, "
            f"got shape {real_array(x0, 'x0').shape}"
        )
    return _free_responses("initial", sys, T, lambda m: states)


def step_response(
    sys: Systems, T: ArrayLike | None = None, eta0: ArrayLike | None = None
) -> TimeResponse:
    """Response to η = η0 H(t) from rest (chapter (6.39)-(6.45)).

    Computed exactly through the augmented exponential, so it is right for singular A (an
    integrator), where the chapter's x(t) = (e^{At} - I) A^-1 B η0 (6.43) cannot be used. A
    discrete model steps x[k+1] = A x[k] + B η0 from x[0] = 0 (scipy.signal.dstep's).

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, system object, or list of them
        One model, or a list of models of one size and one sampling period (one response
        each, on a leading axis). Without C and D the output is the state.
    T : array_like (k,) or float, s, optional
        A uniform grid starting at 0, a final time, or None (default) for the default grid
        (:func:`default_time_grid`).
    eta0 : array_like (m,) or (r, m), optional
        The input weights η0, one vector or r of them; default 1 for a single input, the m
        unit vectors (one response per input) for several.

    Returns
    -------
    TimeResponse
        ``t`` (k,), states ``x`` (k, n), outputs ``y`` (k, p) and inputs ``u``, with a
        leading response axis (r, k, ...) for several responses or models.

    Raises
    ------
    InvalidArgumentError
        T is not uniform, does not start at 0, is not a positive finite final time, is not a
        multiple of a discrete model's dt, or its step is too long for A; a list mixes
        sampling periods; or the default grid cannot be made (an eigenvalue beyond 2e306:
        give T).
    ShapeError
        ``eta0`` has not one weight per input.
    NotRealError
        ``sys`` is not a model (a number, a string), or a matrix is complex.
    ShapeError
        The models of a list differ in size, or the matrices disagree in size.
    NonFiniteError
        A matrix or an input weight contains NaN or an infinity.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> r = aerocontrol.step_response((A, B), T=np.linspace(0, 8000, 4001), eta0=[np.pi / 180])
    >>> np.round(r.x[-1], 4)                                      # (6.51)
    array([ 0.046 , -0.0186,  0.    , -0.016 ])

    x' = -x + η: y = 1 - e^{-t}.

    >>> r = aerocontrol.step_response(([[-1.0]], [[1.0]], [[1.0]], [[0.0]]), T=[0, 1, 2])
    >>> np.round(r.y[:, 0], 6)
    array([0.      , 0.632121, 0.864665])
    """
    models, several_models = _systems(sys)
    first = models[0]
    t, step, q = _time_grid(T, models)
    weights, names = _input_weights(eta0, first.n_inputs)
    if several_models:
        x, y = _simulate(
            models,
            True,
            np.zeros((len(models), first.n_states)),
            None,
            np.repeat(_first(weights, "step")[np.newaxis], len(models), axis=0),
            step,
            len(t),
            q,
        )
        u = np.broadcast_to(weights[:1], (len(models), len(t), first.n_inputs))
        return _assemble(
            "step", t, x, y, np.array(u), first, [f"model {k}" for k in range(len(models))], True
        )
    responses = weights.shape[0]
    x0 = np.zeros((responses, first.n_states))
    if responses == 1:
        x, y = _simulate(models, False, x0, None, weights[0], step, len(t), q)
    else:
        u_all = np.repeat(weights[:, None, :], len(t), axis=1)
        x, y = _simulate(models, False, x0, u_all, None, step, len(t), q)
    u = np.repeat(weights[:, None, :], len(t), axis=1)
    labels: Sequence[str] = names or first.input_names
    return _assemble("step", t, x, y, u, first, labels, responses > 1)


def forced_response(
    sys: System,
    T: ArrayLike,
    u: ArrayLike,
    x0: ArrayLike | None = None,
    method: Literal["zoh", "foh"] = "zoh",
) -> TimeResponse:
    """Response to a sampled input u on the uniform grid T, from x0 (default rest).

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, or system object
        One model.
    T : array_like, shape (k,), s
        Uniform time grid starting at 0.
    u : array_like, shape (k,), (k, m) or (r, k, m)
        Input samples: one input, several inputs, or r input histories at once.
    x0 : array_like, shape (n,) or (r, n), optional
    method : {"zoh", "foh"}
        Input held constant between samples (zero-order hold) or linear between them
        (first-order hold, as scipy.signal.lsim's default interpolation). A discrete model
        takes one input per sample, T steps by its dt, and "foh" is refused.

    Returns
    -------
    TimeResponse
        ``t`` (k,), states ``x`` (k, n), outputs ``y`` (k, p) and inputs ``u``, with a
        leading response axis (r, k, ...) for several responses or models.

    Raises
    ------
    ShapeError
        A list of models, T not 1-D, u not of shape (k,), (k, m) or (r, k, m), or x0 not of
        n values per response (or not one per input history).
    InvalidArgumentError
        ``method`` is not "zoh" or "foh" ("foh" with a discrete model), T is not uniform or
        does not start at 0, or T does not step by a discrete model's dt.
    NotRealError, NonFiniteError
        ``sys`` is not a model, or an argument is complex, NaN or infinite.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> t = np.linspace(0, 10, 101)
    >>> r = aerocontrol.forced_response((A, B), t, np.sin(t) * np.pi / 180, method="foh")
    >>> r.y.shape
    (101, 4)
    """
    models, several_models = _systems(sys)
    if several_models:
        raise ShapeError("forced_response takes one model; call it per model for several")
    model = models[0]
    hold = check_choice(method, "method", ("zoh", "foh"))
    if model.is_discrete and hold != "zoh":
        raise InvalidArgumentError(
            f"method={hold!r} is a hold between samples of a continuous model; a discrete "
            "model takes one input per sample (leave method at 'zoh')"
        )
    times = real_array(T, "T")
    if times.ndim != 1:
        raise ShapeError(f"T must be a 1-D grid of times, got shape {times.shape}")
    step = _core.grid_step(times)
    dt = period(model)
    if model.is_discrete and abs(step - dt) > GRID_MULTIPLE_TOLERANCE * dt:
        raise InvalidArgumentError(
            f"T must step by the sampling period dt = {dt:g} s of the discrete model "
            f"(one input per sample, t = k dt), got a step of {step:g} s"
        )
    k, m, n = len(times), model.n_inputs, model.n_states
    inputs = real_array(u, "u")
    if inputs.ndim == 1 and m == 1:
        inputs = inputs.reshape(1, -1, 1)
    elif inputs.ndim == 2:
        inputs = inputs.reshape(1, *inputs.shape)
    if inputs.ndim != 3 or inputs.shape[1:] != (k, m):
        raise ShapeError(
            f"u must have one row of {m} input(s) per time ({k} times): shape ({k},) for one "
            f"input, ({k}, {m}) or (r, {k}, {m}), got {real_array(u, 'u').shape}"
        )
    responses = inputs.shape[0]
    if x0 is None:
        states = np.zeros((responses, n))
    else:
        states = real_array(x0, "x0")
        states = states.reshape(1, -1) if states.ndim == 1 else states
        if states.shape[-1] != n or states.ndim != 2:
            raise ShapeError(f"x0 must have {n} values per response, got shape {states.shape}")
        if states.shape[0] == 1 and responses > 1:
            states = np.repeat(states, responses, axis=0)
        if states.shape[0] != responses:
            raise ShapeError(
                f"x0 must have one initial state per input history ({responses}), "
                f"got {states.shape[0]}"
            )
    if inputs.shape[0] == 1 and states.shape[0] > 1:
        inputs = np.repeat(inputs, states.shape[0], axis=0)
        responses = states.shape[0]
    x, y = _simulate(
        models,
        False,
        states,
        np.ascontiguousarray(inputs),
        None,
        step,
        k,
        1 if model.is_discrete else 0,
        hold,
    )
    labels = [f"response {r}" for r in range(responses)]
    return _assemble("forced", times, x, y, inputs, model, labels, responses > 1)


def steady_state(sys: System, eta0: ArrayLike) -> FloatArray:
    """The state a step η0 settles to, x∞ = -A^-1 B η0 (6.45), for a stable system; for a
    discrete model, x∞ = (I - A)^-1 B η0. An unstable system has none, and is refused
    (:func:`dc_gain` gives the output of the equilibrium -A^-1 B η0 whatever the stability).

    Raises SingularMatrixError naming the zero eigenvalue when A is singular (an integrator
    has no steady state); for a discrete model, the eigenvalue 1 of A. The core refuses an A
    with an eigenvalue within 100 n u ||A|| of zero; where it does, A is equilibrated (rows
    and columns scaled by powers of two, exactly, to put its largest entries on a transversal
    at size 1, as MC64 does) and solved again, so that an A merely badly scaled (a closed
    loop with couplings of 1e231 beside eigenvalues of 1.5) is solved, and only one whose
    equilibrated matrix is singular too is refused, with the core's error for A. The entries
    of A are taken as exact: a row or column of tiny entries is a slow mode, solved, even
    where they are the rounding errors of an integrator's zeros (A = [[1e-17, 0.1],
    [2e-17, -0.5]] has the eigenvalue 1.4e-17, and -A^-1 B of 9e16 for B = (1, 1)); an
    integrator whose zeros are zeros is refused.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, or system object
    eta0 : array_like (m,), or float for a single input
        The step's input weights.

    Returns
    -------
    ndarray (n,)
        x∞.

    Raises
    ------
    InvalidArgumentError
        ``sys`` is unstable: an eigenvalue with Re s > 1e-12 abs(s) (for a discrete model,
        abs(z) > 1: s = ln(z)/dt); the step then never settles.
    SingularMatrixError
        A (for a discrete model A - I) is singular, even equilibrated.
    ShapeError
        ``eta0`` is not 1-D with one value per input.
    NotRealError, NonFiniteError
        ``sys`` is not a model, or an argument is complex, NaN or infinite.

    Warns
    -----
    NumericalOverflowWarning
        x∞ overflows double precision.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> np.round(aerocontrol.steady_state((A, B), [np.pi / 180]), 6)   # (6.51)
    array([ 0.045965, -0.018563,  0.      , -0.015954])
    """
    A, B, _, _, dt = plant_arrays(sys)
    weights = real_array(eta0, "eta0")
    if weights.ndim == 0 and B.shape[1] == 1:  # a number for the one input
        weights = weights.reshape(1)
    if weights.ndim != 1:
        raise ShapeError(
            f"eta0 must be a 1-D array of one value per input, got an array of shape "
            f"{weights.shape}"
        )
    x = _steady_state(A, B, dt, weights) if dt else _equilibrated_solve(A, B, weights, True)
    _require_settling(A, dt)  # after the solve: a singular A is refused as such
    return x


#: A mode counts as unstable where Re s > UNSTABLE_MARGIN |s| (s = ln(z)/dt for a discrete
#: model): an undamped mode computed with a real part of rounding size is not one.
UNSTABLE_MARGIN = 1e-12


def _require_settling(A: FloatArray, dt: float) -> None:
    """InvalidArgumentError naming ``sys`` where a mode of A grows (Re s > 1e-12 |s|; for a
    discrete model s = ln(z)/dt, |z| > 1): x∞ = -A^-1 B η0 is then an equilibrium that a step
    never reaches. The margin is relative to each mode's own modulus, so that the slow mode
    of a stiff model (-1e-7 beside -1e6) and a decaying mode of a badly scaled one (-1.25 ±
    2e231 j) pass, and an undamped mode whose real part is rounding (±1e-17 beside j) is not
    called unstable. A zero eigenvalue is left to the solve, which refuses it as singular."""
    if A.shape[0] == 0:
        return
    eigenvalues = _core.eigenvalues(A)
    if dt:
        eigenvalues = eigenvalues[eigenvalues != 0]
        if not eigenvalues.size or float(np.abs(eigenvalues).max()) <= 1.0:
            return
        eigenvalues = np.log(eigenvalues) / dt
    elif max(eigenvalues.real.tolist()) <= 0.0:
        # (Python's max of a short list: numpy's reduction costs a quarter of a 4-state
        # steady state. A NaN makes it NaN or is passed over; either way the test below,
        # for which a NaN is not growing, gives the same answer.)
        return
    with np.errstate(over="ignore", invalid="ignore"):
        growing = eigenvalues.real > UNSTABLE_MARGIN * np.abs(eigenvalues)
    if not np.any(growing):
        return
    worst = eigenvalues[growing][np.argmax(eigenvalues.real[growing])]
    mode = f"z = {complex(np.exp(worst * dt)):.6g}" if dt else f"s = {complex(worst):.6g}"
    error = InvalidArgumentError(
        f"sys is unstable (a mode at {mode}), so a step never settles and has no steady "
        "state (-A^-1 B η0 is an equilibrium it grows away from; dc_gain gives the output "
        "there)"
    )
    error.argument = "sys"
    raise error


def _steady_state(
    A: FloatArray, B: FloatArray, dt: float, weights: ArrayLike, warn: bool = True
) -> FloatArray:
    """-A^-1 B η0 for a continuous model (dt = 0); for a discrete one, -(A - I)^-1 B η0, with
    the error of a singular A - I naming the eigenvalue 1 of A. The core checks A and B (the
    matrices of :func:`~aerocontrol.statespace.plant_arrays`); a discrete model's are those of
    a StateSpace, checked when it was made."""
    if not dt:
        return _equilibrated_solve(A, B, weights, warn)
    try:
        return _equilibrated_solve(A - np.eye(A.shape[0]), B, weights, warn)
    except SingularMatrixError as error:
        raise SingularMatrixError(
            "A - I is singular: A has the eigenvalue 1 (a discrete integrator or neutral "
            "mode), so the discrete model has no steady state"
        ) from error


def _equilibrated_solve(M: FloatArray, B: FloatArray, weights: ArrayLike, warn: bool) -> FloatArray:
    """-M^-1 B η0 by the core, which refuses an M with an eigenvalue within 100 n u ||M|| of
    zero; where it does, the same solve of R M S y = -R B η0, x = S y, with M equilibrated by
    powers of two (R, S diagonal: ``_scaling.matching_equilibration``), and the core's error
    only if that matrix is singular too (or M has no transversal of nonzero entries, such as
    the zero column of an integrator).

    A matrix merely badly scaled, such as the closed loop of a loop gain of 1e462 (entries of
    4e231 beside eigenvalues of 1.5), is then solved; the scalings are exact, so x is the
    solution of the same equations, to the conditioning of the equilibrated matrix. ``weights``
    is one input vector (1-D; x is 1-D) or one per column (2-D; x is n x k, one factorisation).
    An x that overflows comes with a NumericalOverflowWarning if ``warn``."""
    try:
        result: FloatArray = _core.steady_state(M, B, weights, warn)
        return result
    except SingularMatrixError:
        scalings = _scaling.matching_equilibration(M)
        if scalings is None or not (np.any(scalings[0]) or np.any(scalings[1])):
            raise
        rows, columns = scalings
        forcing = _scaling.log2_sizes(B) + rows[:, None]
        largest = float(np.max(forcing, initial=-np.inf))
        # R B divided by a power of two to size 1 (so that it neither over- nor underflows),
        # and x multiplied by it again.
        shift = round(largest) if np.isfinite(largest) else 0
        with np.errstate(over="ignore", under="ignore"):
            scaled = np.ldexp(M, rows[:, None] + columns[None, :])
            scaled_B = np.ldexp(B, rows[:, None] - shift)
        try:
            y = _core.steady_state(scaled, scaled_B, weights, False)
        except SingularMatrixError:
            pass
        else:
            exponents = columns + shift
            with np.errstate(over="ignore", under="ignore"):
                x = np.ldexp(y, exponents if y.ndim == 1 else exponents[:, None])
            return finite_or_warn(x, "the steady state") if warn else x
        raise


def dc_gain(sys: System) -> FloatArray:
    """The zero-frequency gain D - C A^-1 B (p, m): the steady output per unit step input;
    for a discrete model, G(z = 1) = D + C (I - A)^-1 B.

    Raises SingularMatrixError naming the zero eigenvalue when A is singular (the eigenvalue
    1 for a discrete model). An A merely badly scaled is not singular: where the core finds
    an eigenvalue within 100 n u ||A|| of zero, the solve is made again with the rows and
    columns of A scaled by powers of two (exact) to entries of size 1, and only an A whose
    equilibrated matrix is singular too is refused (see :func:`steady_state`).

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, or system object

    Returns
    -------
    ndarray (p, m)
        The DC gain; entry (i, j) is output i's steady value per unit step of input j.

    Raises
    ------
    SingularMatrixError
        A (for a discrete model I - A) is singular, even equilibrated: an integrator.
    NotRealError, NonFiniteError
        ``sys`` is not a model, or a matrix is complex, NaN or infinite.

    Warns
    -----
    NumericalOverflowWarning
        The gain overflows double precision.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> C = np.array([[0.0, 0.0, 0.0, 1.0]])                       # theta per unit elevator
    >>> np.round(aerocontrol.dc_gain((A, B, C, [[0.0]])), 6)
    array([[-0.914106]])
    >>> # A closed loop of loop gain 2^1536: eigenvalues of 1.5 beside entries of 2^769.
    >>> a, b = 2.0**767, 2.0**769
    >>> loop = aerocontrol.StateSpace([[-1, -a, -a], [b, -1, 0], [b, 0, -2]], [[1], [1], [0]],
    ...                               [[0, 1, 2]], [[0]])
    >>> aerocontrol.dc_gain(loop)                                    # -1/3, exactly
    array([[-0.33333333]])
    >>> integrator = ([[0.0, 1.0], [0.0, -1.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    >>> aerocontrol.dc_gain(integrator)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aerocontrol.exceptions.SingularMatrixError: A is singular: it has the eigenvalue 0 ...
    """
    # A tuple is continuous, and its four matrices are checked by the core's dc_gain (before
    # any SingularMatrixError); a discrete model is a StateSpace, checked when it was made.
    A, B, C, D, dt = plant_arrays(sys, check=False)
    if not dt:
        try:
            gain: FloatArray = _core.dc_gain(A, B, C, D)  # one call: a small model's cost
            return gain
        except SingularMatrixError:
            pass  # singular, or merely badly scaled: the equilibrated solve below decides
    # Every input's steady state from one factorisation; one warning, for the gain.
    weights = identity(B.shape[1])
    states = (
        _steady_state(A, B, dt, weights, warn=False)
        if dt
        else _equilibrated_solve(A, B, weights, False)
    )
    with np.errstate(over="ignore", invalid="ignore"):
        gain = C @ states + D
    return finite_or_warn(gain, "the DC gain")
