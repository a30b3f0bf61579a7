"""Plots of the chapter's figures: responses, frequency responses, modes and root loci.

The only module that imports matplotlib, and only when a plot is asked for. Every function
takes ``ax=`` (or ``axes=`` for a pair; new axes when None), labels its axes with units, names
each line in a legend, and returns what it drew on. Nothing needs a display: give axes of a
``matplotlib.figure.Figure`` (as the report does) or select a non-interactive backend.

=============================  ===============================================================
function                       the chapter's figure
=============================  ===============================================================
:func:`plot_time_response`     one response, states or outputs against time
:func:`response_png`           a small picture of a response, for a notebook
:func:`plot_time_scales`       one response at two time scales, short period and phugoid
                               (Figures 6.1, 6.2)
:func:`plot_open_closed`       open loop beside closed loop (Figures 6.4, 6.5, 6.6)
:func:`plot_with_controls`     a regulated response with the control deflections η = -K x
                               (6.230; Figures 6.9, 6.10)
:func:`plot_penalty`           x^T Q x and -η^T R η against time; the area between is J
                               (Figure 6.11)
:func:`plot_compared`          one variable of several designs on the same axes, sampled ones
                               as held samples (the report's digital designs)
:func:`plot_root_locus`        closed-loop roots over a weight c (Figures 6.8, 6.12)
:func:`plot_bode`              magnitude and phase of one input-output pair
:func:`plot_nyquist`           the Nyquist curve of a loop, with -1 and the direction of ω
:func:`plot_nichols`           the Nichols chart of a loop, with closed-loop gain and phase
                               contours
:func:`plot_modes`             the eigenvalues in the complex plane, by mode
:func:`plot_levels`            MIL-F-8785C Levels over a grid of flight conditions
:func:`plot_envelope_levels`   the Levels of each mode over the envelope, an image per mode
:func:`plot_gain_schedule`     a gain schedule's entries against Mach, a line per altitude
=============================  ===============================================================

States, inputs and outputs with the names of the aircraft models (``u/u0``, ``alpha``, ...,
``rudder``) are labelled with their physical names and units; other names are used as given.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validation import FloatArray, positive_int, real_array, real_scalar
from .exceptions import InvalidArgumentError, ShapeError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.legend import Legend

    from .aircraft.envelope import Envelope
    from .frequency import FrequencyResponse
    from .loops import NicholsResponse, NyquistResponse, RootLocus
    from .modal import Modes
    from .responses import TimeResponse
    from .robustness import MonteCarlo
    from .schedule import GainSchedule

__all__ = [
    "closed_loop_gain_contour",
    "closed_loop_phase_contour",
    "label",
    "penalty_terms",
    "plot_bode",
    "plot_compared",
    "plot_envelope_levels",
    "plot_gain_root_locus",
    "plot_gain_schedule",
    "plot_levels",
    "plot_modes",
    "plot_nichols",
    "plot_nyquist",
    "plot_open_closed",
    "plot_penalty",
    "plot_probability_convergence",
    "plot_robustness_histogram",
    "plot_root_locus",
    "plot_sensitivity",
    "plot_time_response",
    "plot_time_scales",
    "plot_with_controls",
    "response_png",
]

# The aircraft models' variable names: what they are, and their unit.
_DESCRIPTIONS: dict[str, tuple[str, str]] = {
    "u/u0": ("speed u/u0", ""),
    "alpha": ("angle of attack α", "rad"),
    "q": ("pitch rate q", "rad/s"),
    "theta": ("pitch angle θ", "rad"),
    "beta": ("sideslip β", "rad"),
    "p": ("roll rate p", "rad/s"),
    "phi": ("roll angle φ", "rad"),
    "r": ("yaw rate r", "rad/s"),
    "elevator": ("elevator δe", "rad"),
    "rudder": ("rudder δr", "rad"),
    "aileron": ("aileron δa", "rad"),
}


def label(name: str) -> str:
    """The legend label of a variable: its description and unit for the aircraft models'
    names, the name itself otherwise.

    Parameters
    ----------
    name : str
        A state, input or output name (``"alpha"``, ``"rudder"``, ...).

    Returns
    -------
    str
        "description (unit)" for a known name, the name itself otherwise.

    Raises
    ------
    None
        Any name is accepted.

    Examples
    --------
    >>> label("alpha"), label("u/u0"), label("x3")
    ('angle of attack α (rad)', 'speed u/u0', 'x3')
    """
    description, unit = _DESCRIPTIONS.get(name, (name, ""))
    return f"{description} ({unit})" if unit else description


def _axis_label(names: Sequence[str], what: str) -> str:
    """A y-axis label that lists the units present, e.g. 'states (rad, rad/s)'."""
    units = list(dict.fromkeys(_DESCRIPTIONS[n][1] for n in names if n in _DESCRIPTIONS))
    units = [u for u in units if u]
    if any(n not in _DESCRIPTIONS for n in names):
        units.append("model units")
    elif "u/u0" in names:
        units.append("u/u0 nondimensional")
    return f"{what} ({', '.join(units)})" if units else what


# Any: the options are matplotlib's subplots keywords, of any type; the result is one Axes or
# an array of them by rows and columns (matplotlib's own stubs type it Any).
def _new_axes(rows: int = 1, columns: int = 1, **options: Any) -> Any:
    import matplotlib.pyplot as plt

    _, axes = plt.subplots(rows, columns, squeeze=True, **options)
    return axes


#: The largest |value| drawn: matplotlib's autoscaling subtracts the limits and adds margins,
#: which overflows (numpy's warning, from inside matplotlib) for data spanning ±1e308.
PLOT_LIMIT = 1e300


def _drawable(ax: Axes, values: ArrayLike) -> FloatArray:
    """``values`` as floats with every entry that cannot be drawn (NaN, infinite, or beyond
    ±PLOT_LIMIT) masked as NaN (a gap in a line), counted on ``ax`` for the note that
    :func:`_note_hidden` writes; the caller's array is not modified."""
    array = np.array(values, dtype=np.float64, copy=True)
    with np.errstate(invalid="ignore"):
        hidden = ~(np.abs(array) <= PLOT_LIMIT)
    if np.any(hidden):
        array[hidden] = np.nan
        count = int(getattr(ax, "_aerocontrol_hidden", 0)) + int(np.count_nonzero(hidden))
        ax._aerocontrol_hidden = count  # type: ignore[attr-defined]
        _note_hidden(ax)
    return array


def _drawable_complex(ax: Axes, values: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Real and imaginary parts of complex ``values``, each :func:`_drawable`; a point with
    either part hidden is hidden whole."""
    points = np.asarray(values, dtype=np.complex128)
    with np.errstate(invalid="ignore"):
        hidden = ~((np.abs(points.real) <= PLOT_LIMIT) & (np.abs(points.imag) <= PLOT_LIMIT))
    real = np.where(hidden, np.inf, points.real)
    return _drawable(ax, real), _drawable(ax, np.where(hidden, 0.0, points.imag))


def _note_hidden(ax: Axes) -> None:
    """One note in the corner of ``ax``: how many values were not drawn, and why."""
    count = int(getattr(ax, "_aerocontrol_hidden", 0))
    text = f"{count} value{'s' if count > 1 else ''} not drawn (NaN, infinite or beyond ±1e300)"
    note = getattr(ax, "_aerocontrol_note", None)
    if note is None:
        note = ax.text(
            0.01, 0.01, text, transform=ax.transAxes, fontsize="x-small", color="0.35", va="bottom"
        )
        ax._aerocontrol_note = note  # type: ignore[attr-defined]
    else:
        note.set_text(text)


def _finish(ax: Axes, xlabel: str, ylabel: str, title: str | None = None) -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")


def _pair(axes: Iterable[Axes], name: str) -> tuple[Axes, Axes]:
    try:
        first, second = axes
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"{name} must be a pair of matplotlib axes") from None
    return first, second


def _signal(result: TimeResponse, signal: str, response: int) -> tuple[FloatArray, tuple[str, ...]]:
    if signal == "states":
        return result.states(response), result.state_names
    if signal == "outputs":
        return result.outputs(response), result.output_names
    raise InvalidArgumentError(f"signal must be 'states' or 'outputs', got {signal!r}")


def _response_index(result: TimeResponse, response: int) -> int:
    if not 0 <= response < result.n_responses:
        raise InvalidArgumentError(
            f"response must be in 0 ... {result.n_responses - 1}, got {response}"
        )
    return response


def plot_time_response(
    result: TimeResponse,
    ax: Axes | None = None,
    signal: str = "states",
    response: int = 0,
    t_max: float | None = None,
    title: str | None = None,
    suffix: str = "",
    linestyle: str = "-",
) -> Axes:
    """States (``signal="states"``) or outputs of one response against time, one named line
    each, up to ``t_max`` seconds (the whole grid when None). Returns the axes.

    ``suffix`` (appended to the legend labels) and ``linestyle`` tell two responses apart on
    the same axes, as Figure 6.4 shows the original system and the one with feedback.

    Parameters
    ----------
    result : TimeResponse
        A response of :func:`~aerocontrol.step_response`, :func:`~aerocontrol.initial_response`
        or another response function.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    signal : {"states", "outputs"}, optional
        What to draw (default "states").
    response : int, optional
        Which response of a result with several (default 0).
    t_max : float, optional
        The last time drawn, s (default the whole grid).
    title : str, optional
        The title (default the response's kind, and its name if there are several).
    suffix : str, optional
        Appended to each legend label (default "").
    linestyle : str, optional
        The matplotlib line style (default "-").

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    InvalidArgumentError
        ``signal`` is not "states" or "outputs", or ``response`` is out of range.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from aerocontrol import aircraft, step_response
    >>> ax = step_response(aircraft.load().longitudinal(), T=20.0).plot()
    >>> ax.get_ylabel()
    'states (rad, rad/s, u/u0 nondimensional)'
    """
    values, names = _signal(result, signal, _response_index(result, response))
    ax = _new_axes() if ax is None else ax
    shown = slice(None) if t_max is None else result.t <= t_max
    for column, name in zip(values.T, names, strict=True):
        ax.plot(
            result.t[shown], _drawable(ax, column[shown]), linestyle, label=label(name) + suffix
        )
    if title is None:
        title = f"{result.kind} response"
        if result.n_responses > 1:
            title += f": {result.response_names[response]}"
    _finish(ax, "time (s)", _axis_label(names, signal), title)
    return ax


def response_png(result: TimeResponse, width: float = 5.0, height: float = 2.6) -> bytes:
    """A small PNG of the states of the first response (``width`` x ``height`` inches at 72
    dpi), as a notebook shows a :class:`~aerocontrol.TimeResponse` under its table.

    Drawn on a ``matplotlib.figure.Figure`` with the Agg canvas, never through pyplot: no
    window opens, the current backend and pyplot's figures are left alone, and the figure is
    released once the PNG is written.

    Parameters
    ----------
    result : TimeResponse
        The response to draw (states of its first response).
    width, height : float
        The size of the picture in inches.

    Returns
    -------
    bytes
        The PNG.

    Raises
    ------
    InvalidArgumentError
        ``width`` or ``height`` is not a positive finite number.

    Examples
    --------
    >>> from aerocontrol import aircraft, step_response
    >>> png = response_png(step_response(aircraft.load().longitudinal(), T=20.0))
    >>> png[1:4]
    b'PNG'
    """
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    for name, value in (("width", width), ("height", height)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise InvalidArgumentError(f"{name} must be a positive number of inches, got {value!r}")
    figure = Figure(figsize=(width, height), dpi=72, layout="constrained")
    FigureCanvasAgg(figure)
    ax = figure.subplots()
    plot_time_response(result, ax=ax)
    legend = ax.get_legend()
    if legend is not None:
        legend.set(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    figure.clear()
    return buffer.getvalue()


def plot_time_scales(
    result: TimeResponse,
    short: float,
    axes: Iterable[Axes] | None = None,
    signal: str = "states",
    response: int = 0,
) -> tuple[Axes, Axes]:
    """One response at two time scales, as the chapter shows the longitudinal motions: the
    first ``short`` seconds (the short period) and the whole grid (the phugoid), Figures 6.1
    and 6.2. Returns the pair of axes.

    Compute the response on a grid fine enough for the short scale and long enough for the
    long one, e.g. ``T=np.arange(0, 500.0, 0.02)``.

    Parameters
    ----------
    result : TimeResponse
        A response of :func:`~aerocontrol.step_response`, :func:`~aerocontrol.initial_response`
        or another response function.
    short : float
        The short time scale, s, between 0 and the response's final time.
    axes : pair of matplotlib.axes.Axes, optional
        The two axes to draw on (default a new pair side by side, by pyplot).
    signal : {"states", "outputs"}, optional
        What to draw (default "states").
    response : int, optional
        Which response of a result with several (default 0).

    Returns
    -------
    (matplotlib.axes.Axes, matplotlib.axes.Axes)
        The pair drawn on.

    Raises
    ------
    InvalidArgumentError
        ``short`` is not between 0 and the final time, ``axes`` is not a pair of axes,
        ``signal`` is not "states" or "outputs", or ``response`` is out of range.

    Examples
    --------
    The 747's elevator step response: the first 10 s and 200 s.

    >>> import numpy as np
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, plotting, step_response
    >>> r = step_response(aircraft.load().longitudinal(), T=np.arange(0, 200.0, 0.1))
    >>> short, long = plotting.plot_time_scales(r, 10.0, axes=Figure().subplots(1, 2))
    >>> short.get_title(), long.get_title()
    ('short period scale', 'phugoid scale')
    """
    if not 0 < short < result.t[-1]:
        raise InvalidArgumentError(
            f"short must be between 0 and the response's final time {result.t[-1]:g} s, got {short}"
        )
    first, second = _pair(_new_axes(1, 2, figsize=(11, 4)) if axes is None else axes, "axes")
    plot_time_response(result, first, signal, response, t_max=short, title="short period scale")
    plot_time_response(result, second, signal, response, title="phugoid scale")
    # One legend for both (the same lines): the long panel's oscillation leaves no corner free.
    # (plot_time_response gave each axes a legend, so there is one to remove.)
    cast("Legend", second.get_legend()).remove()
    return first, second


def plot_open_closed(
    open_loop: TimeResponse,
    closed_loop: TimeResponse,
    axes: Iterable[Axes] | None = None,
    titles: tuple[str, str] = ("(a) open loop", "(b) closed loop"),
    signal: str = "states",
) -> tuple[Axes, Axes]:
    """The open-loop response beside the closed-loop one on a common scale (Figures 6.4-6.6).
    Returns the pair of axes.

    Parameters
    ----------
    open_loop, closed_loop : TimeResponse
        The two responses (their first response is drawn).
    axes : pair of matplotlib.axes.Axes, optional
        The two axes to draw on (default a new pair side by side, by pyplot).
    titles : (str, str), optional
        The two titles (default "(a) open loop", "(b) closed loop").
    signal : {"states", "outputs"}, optional
        What to draw (default "states").

    Returns
    -------
    (matplotlib.axes.Axes, matplotlib.axes.Axes)
        The pair drawn on.

    Raises
    ------
    InvalidArgumentError
        ``axes`` is not a pair of axes, or ``signal`` is not "states" or "outputs".

    Examples
    --------
    The 747's lateral motion from β = 0.1 rad, open and with the LQR of (6.224), c = 1:

    >>> import numpy as np, aerocontrol
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import plotting
    >>> lat = aerocontrol.aircraft.load().lateral()
    >>> K, _, _ = aerocontrol.lqr(lat.A, lat.B, np.eye(4), np.eye(2))
    >>> closed = aerocontrol.StateSpace(lat.A - lat.B @ K, lat.B, state_names=lat.state_names,
    ...                                 input_names=lat.input_names)
    >>> T = np.arange(0, 20.0, 0.05)
    >>> o = aerocontrol.initial_response(lat, [0.1, 0, 0, 0], T=T)
    >>> c = aerocontrol.initial_response(closed, [0.1, 0, 0, 0], T=T)
    >>> a, b = plotting.plot_open_closed(o, c, axes=Figure().subplots(1, 2))
    >>> a.get_title(), b.get_title(), a.get_ylim() == b.get_ylim()
    ('(a) open loop', '(b) closed loop', True)
    """
    first, second = _pair(
        _new_axes(1, 2, figsize=(11, 4), sharey=True) if axes is None else axes, "axes"
    )
    plot_time_response(open_loop, first, signal, title=titles[0])
    plot_time_response(closed_loop, second, signal, title=titles[1])
    # A common scale on the caller's axes too (those made here share it already).
    limits = (*first.get_ylim(), *second.get_ylim())
    for axis in (first, second):
        axis.set_ylim(min(limits), max(limits))
    return first, second


def _gain(K: ArrayLike, result: TimeResponse) -> FloatArray:
    gain = real_array(K, "K")
    gain = gain.reshape(1, -1) if gain.ndim == 1 else gain
    n = len(result.state_names)
    if gain.ndim != 2 or gain.shape[1] != n:
        raise ShapeError(f"K must be m x {n} (one column per state), got shape {gain.shape}")
    return gain


def _control_names(result: TimeResponse, m: int) -> tuple[str, ...]:
    names = result.input_names
    return names if len(names) == m else tuple(f"u{j}" for j in range(m))


def plot_with_controls(
    result: TimeResponse,
    K: ArrayLike,
    ax: Axes | None = None,
    response: int = 0,
    title: str | None = None,
) -> Axes:
    """A regulated response with the control deflections η = -K x (6.230) that produce it,
    dashed, on the same axes (Figures 6.9, 6.10). ``result`` is a response of the closed loop
    A - B K whose input names (if it has one per row of K) name the controls. Returns the axes.

    Parameters
    ----------
    result : TimeResponse
        A response of the closed loop.
    K : array_like (m, n) or (n,)
        The state-feedback gain.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    response : int, optional
        Which response of a result with several (default 0).
    title : str, optional
        The title (default the response's kind).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    ShapeError
        K has not one column per state.
    InvalidArgumentError
        ``response`` is out of range.
    NotRealError
        K is complex or not numeric (entries beyond the doubles are not drawn).

    Examples
    --------
    The 747's lateral regulator (6.224), c = 1, from β = 0.1 rad (Figure 6.9):

    >>> import numpy as np, aerocontrol
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import plotting
    >>> lat = aerocontrol.aircraft.load().lateral()
    >>> K, _, _ = aerocontrol.lqr(lat.A, lat.B, np.eye(4), np.eye(2))
    >>> closed = aerocontrol.StateSpace(lat.A - lat.B @ K, lat.B, state_names=lat.state_names,
    ...                                 input_names=lat.input_names)
    >>> c = aerocontrol.initial_response(closed, [0.1, 0, 0, 0], T=np.arange(0, 20.0, 0.05))
    >>> ax = plotting.plot_with_controls(c, K, ax=Figure().subplots())
    >>> [line.get_label() for line in ax.get_lines()][4:]
    ['rudder δr (rad)', 'aileron δa (rad)']
    """
    gain = _gain(K, result)
    states = result.states(_response_index(result, response))
    with np.errstate(over="ignore", invalid="ignore"):  # beyond the doubles: not drawn
        controls = -states @ gain.T
    ax = plot_time_response(result, ax, "states", response, title=title)
    names = _control_names(result, gain.shape[0])
    for column, name in zip(controls.T, names, strict=True):
        ax.plot(result.t, _drawable(ax, column), "--", label=label(name))
    _finish(ax, "time (s)", _axis_label((*result.state_names, *names), "states and controls"))
    return ax


def plot_compared(
    curves: Mapping[str, tuple[TimeResponse, str]],
    ax: Axes | None = None,
    held: Iterable[str] = (),
    title: str | None = None,
) -> Axes:
    """One variable of several responses on the same axes, as the designs of a flight
    computer are compared with the continuous one. ``curves`` maps each legend label to a
    response and the name of the state or output to draw (states first); the labels in
    ``held`` are drawn as a staircase (the samples of a discrete model, held until the next).
    The y label is the first variable's. Returns the axes.

    Parameters
    ----------
    curves : mapping of str to (TimeResponse, str)
        Legend label to (response, state or output name).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    held : iterable of str, optional
        The labels drawn as a staircase (default none).
    title : str, optional
        The title (default none).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    InvalidArgumentError
        A curve names a variable that is neither a state nor an output of its response.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from aerocontrol import StateSpace, c2d, initial_response, plotting
    >>> lag = StateSpace([[-1.0]], [[1.0]], state_names=["beta"])
    >>> t = np.arange(0.0, 5.0, 0.5)
    >>> ax = plotting.plot_compared(
    ...     {"continuous": (initial_response(lag, [1.0], T=t), "beta"),
    ...      "2 Hz": (initial_response(c2d(lag, 0.5), [1.0], T=t), "beta")},
    ...     held=["2 Hz"])
    >>> [line.get_drawstyle() for line in ax.get_lines()], ax.get_ylabel()
    (['default', 'steps-post'], 'sideslip β (rad)')
    """
    ax = _new_axes() if ax is None else ax
    staircase = set(held)
    first = None
    for name, (result, variable) in curves.items():
        if variable in result.state_names:
            values = result.states()[:, result.state_names.index(variable)]
        elif variable in result.output_names:
            values = result.outputs()[:, result.output_names.index(variable)]
        else:
            raise InvalidArgumentError(
                f"curves[{name!r}] names {variable!r}, which is neither a state nor an output "
                f"of its response (states {result.state_names})"
            )
        style = "steps-post" if name in staircase else "default"
        ax.plot(result.t, _drawable(ax, values), label=name, drawstyle=style)
        first = variable if first is None else first
    _finish(ax, "time (s)", label(first) if first is not None else "", title)
    return ax


def penalty_terms(
    result: TimeResponse, K: ArrayLike, Q: ArrayLike, R: ArrayLike, response: int = 0
) -> tuple[FloatArray, FloatArray]:
    """The integrands of the performance index along a regulated response: x^T Q x and
    η^T R η with η = -K x (the terms of J, (6.198); R includes the weight 1/c²).

    The integral of their sum over a long response is J = x0^T S x0.

    Parameters
    ----------
    result : TimeResponse
        A response of the closed loop A - B K.
    K : array_like (m, n) or (n,)
        The state-feedback gain.
    Q : array_like (n, n)
        The state weight.
    R : array_like (m, m)
        The control weight (including 1/c²).
    response : int, optional
        Which response of a result with several (default 0).

    Returns
    -------
    state_term : ndarray (k,)
        x^T Q x at each time.
    control_term : ndarray (k,)
        η^T R η at each time; infinite (or NaN) where a term overflows.

    Raises
    ------
    ShapeError
        K has not one column per state, Q is not n x n or R not m x m.
    InvalidArgumentError
        ``response`` is out of range.
    NotRealError
        K, Q or R is complex or not numeric (a non-finite entry gives non-finite terms).

    Examples
    --------
    x' = -2 x from x(0) = 1 (the loop x' = -x + η, η = -x): x = e^{-2t}, so
    x^T Q x = e^{-4t} and η^T R η = 3 e^{-4t} for Q = 1, R = 3.

    >>> import numpy as np, aerocontrol
    >>> from aerocontrol import plotting
    >>> x = aerocontrol.initial_response(([[-2.0]], [[1.0]]), [1.0], T=[0.0, 0.5, 1.0])
    >>> state, control = plotting.penalty_terms(x, [[1.0]], [[1.0]], [[3.0]])
    >>> np.round(state, 6), np.round(control, 6)
    (array([1.      , 0.135335, 0.018316]), array([3.      , 0.406006, 0.054947]))
    """
    gain = _gain(K, result)
    states = result.states(_response_index(result, response))
    n, m = gain.shape[1], gain.shape[0]
    Q_matrix, R_matrix = real_array(Q, "Q"), real_array(R, "R")
    if Q_matrix.shape != (n, n):
        raise ShapeError(f"Q must be {n} x {n}, got shape {Q_matrix.shape}")
    if R_matrix.shape != (m, m):
        raise ShapeError(f"R must be {m} x {m}, got shape {R_matrix.shape}")
    # A term beyond the doubles is infinite (or NaN), as its sum is; the plot does not draw it.
    with np.errstate(over="ignore", invalid="ignore"):
        controls = -states @ gain.T
        state_term = np.einsum("ti,ij,tj->t", states, Q_matrix, states)
        control_term = np.einsum("ti,ij,tj->t", controls, R_matrix, controls)
    return state_term, control_term


def plot_penalty(
    result: TimeResponse,
    K: ArrayLike,
    Q: ArrayLike,
    R: ArrayLike,
    ax: Axes | None = None,
    name: str = "",
    response: int = 0,
) -> Axes:
    """x^T Q x above the axis and -η^T R η below it along a regulated response, the area
    between them shaded: it is the performance index J (Figure 6.11). The legend gives J by
    the trapezoidal rule. Call once per design on the same axes to compare. Returns the axes.

    Parameters
    ----------
    result : TimeResponse
        A response of the closed loop A - B K.
    K : array_like (m, n) or (n,)
        The state-feedback gain.
    Q : array_like (n, n)
        The state weight.
    R : array_like (m, m)
        The control weight (including 1/c²).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    name : str, optional
        The design's name, prefixed to the legend labels (default "").
    response : int, optional
        Which response of a result with several (default 0).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    ShapeError
        K has not one column per state, Q is not n x n or R not m x m.
    InvalidArgumentError
        ``response`` is out of range.

    Examples
    --------
    The 747's lateral regulator (6.224), c = 1, from β = 0.1 rad: J = x0^T S x0 = 0.0709.

    >>> import numpy as np, aerocontrol
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import plotting
    >>> lat = aerocontrol.aircraft.load().lateral()
    >>> K, S, _ = aerocontrol.lqr(lat.A, lat.B, np.eye(4), np.eye(2))
    >>> closed = aerocontrol.StateSpace(lat.A - lat.B @ K, lat.B)
    >>> c = aerocontrol.initial_response(closed, [0.1, 0, 0, 0], T=np.arange(0, 20.0, 0.05))
    >>> ax = plotting.plot_penalty(c, K, np.eye(4), np.eye(2), ax=Figure().subplots())
    >>> ax.get_lines()[0].get_label(), round(float(S[0, 0] * 0.1**2), 4)
    ("x'Qx (J = 0.07089)", 0.0709)
    """
    state_term, control_term = penalty_terms(result, K, Q, R, response)
    with np.errstate(over="ignore", invalid="ignore"):  # J beyond the doubles: said so
        total = state_term + control_term
        J = float(0.5 * np.sum((total[1:] + total[:-1]) * np.diff(result.t)))
    index = f"J = {J:.4g}" if np.isfinite(J) else "J beyond the doubles"
    ax = _new_axes() if ax is None else ax
    prefix = f"{name}: " if name else ""
    upper, lower = _drawable(ax, state_term), _drawable(ax, -control_term)
    (line,) = ax.plot(result.t, upper, label=f"{prefix}x'Qx ({index})")
    ax.plot(result.t, lower, "--", color=line.get_color(), label=f"{prefix}-η'Rη")
    ax.fill_between(result.t, lower, upper, color=line.get_color(), alpha=0.12)
    ax.axhline(0.0, color="black", linewidth=0.8)
    _finish(ax, "time (s)", "penalty terms (model units)", "penalty terms of J")
    return ax


def _tracks(poles: NDArray[np.generic]) -> NDArray[np.complex128]:
    """Reorder each row of ``poles`` so that column j follows one root from row to row:
    greedy nearest matching to the previous row.

    A root beyond the doubles (inf, NaN) is at an infinite distance from every other (inf -
    inf is NaN, and numpy's 'invalid value' warning), so it is matched last, and a
    difference of two huge roots that overflows is infinite, not a warning; matplotlib
    leaves a gap at a non-finite point."""
    tracked = np.array(poles, dtype=np.complex128, copy=True)
    for k in range(1, len(tracked)):
        previous, current = tracked[k - 1], tracked[k].copy()
        with np.errstate(over="ignore", invalid="ignore"):
            distance = np.abs(previous[:, None] - current[None, :])
        distance[~np.isfinite(distance)] = np.inf
        order = np.empty(len(current), dtype=int)
        for _ in range(len(current)):
            i, j = np.unravel_index(np.argmin(distance), distance.shape)
            order[i] = j
            distance[i, :] = np.inf
            distance[:, j] = np.inf
        tracked[k] = current[order]
    return tracked


def _nearest_weight(weights: FloatArray, value: float) -> int | None:
    """The index of the weight nearest ``value``, or None where there is none to mark (NaN,
    or no finite weight).

    An equal weight first; else, for a positive value among positive weights, the nearest by
    ratio (log |w / value|, the distance on a logarithmic sweep), and otherwise by difference.
    Weights of 0 (k = 0 of a gain sweep) and infinite values (the largest weight is the
    nearest) have no logarithm to compare: log(0) - log(0) was NaN with numpy's 'invalid
    value' warning, leaked to the user by the report of an extreme aircraft."""
    finite = np.flatnonzero(np.isfinite(weights))
    if np.isnan(value) or finite.size == 0:
        return None
    equal = np.flatnonzero(weights == value)
    if equal.size:
        return int(equal[0])
    candidates = weights[finite]
    if np.isinf(value):
        return int(finite[np.argmax(candidates) if value > 0 else np.argmin(candidates)])
    positive = candidates > 0
    if value > 0 and np.any(positive):
        ratios = np.abs(np.log(candidates[positive]) - np.log(value))
        return int(finite[np.flatnonzero(positive)[np.argmin(ratios)]])
    with np.errstate(over="ignore"):  # a difference beyond the doubles is infinitely far
        return int(finite[np.argmin(np.abs(candidates - value))])


def plot_root_locus(
    weights: ArrayLike,
    poles: ArrayLike,
    ax: Axes | None = None,
    marked: Sequence[float] | None = None,
    weight_name: str = "c",
    title: str = "closed-loop roots over the weight",
) -> Axes:
    """The closed-loop roots as the weight varies (Figures 6.8, 6.12): one line per root
    through ``poles`` (shape (len(weights), n), e.g. from
    :func:`aerocontrol.design.lqr_root_locus`), a symbol per value in ``marked`` (at the
    nearest computed weight; its colour runs from dark to light as the weight grows), or an
    open circle at the smallest weight when none is marked. Returns the axes.

    Parameters
    ----------
    weights : array_like (k,)
        The weights.
    poles : array_like (k, n)
        The closed-loop roots at each weight.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    marked : sequence of float, optional
        Weights to mark (at the nearest computed one).
    weight_name : str, optional
        The weight's symbol in the legend (default "c").
    title : str, optional
        The title.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    ShapeError
        ``poles`` is not (len(weights), n).
    NotRealError
        ``weights`` is complex or not numeric.

    Examples
    --------
    The 747's lateral regulator over c (Figure 6.12), c = 1 marked:

    >>> import numpy as np
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, design, plotting
    >>> lat = aircraft.load().lateral()
    >>> c = np.geomspace(1e-2, 10, 50)
    >>> ax = plotting.plot_root_locus(c, design.lqr_root_locus(lat, c), ax=Figure().subplots(),
    ...                               marked=[1.0])
    >>> [line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")]
    ['c = 1.04811']
    """
    from matplotlib import colormaps

    c_values = np.atleast_1d(real_array(weights, "weights"))
    roots = np.asarray(poles)
    if roots.ndim != 2 or roots.shape[0] != len(c_values):
        raise ShapeError(
            f"poles must be (len(weights), n) = ({len(c_values)}, n), got shape {roots.shape}"
        )
    ax = _new_axes() if ax is None else ax
    tracked = _tracks(roots)
    for j in range(tracked.shape[1]):
        ax.plot(*_drawable_complex(ax, tracked[:, j]), color="0.55", linewidth=1.0)
    if not marked:  # the start of each root's path
        ax.plot(
            *_drawable_complex(ax, tracked[0]),
            "o",
            mfc="none",
            color="black",
            label=f"{weight_name} = {c_values[0]:g}",
        )
    markers = "sD^v<>ph*+x"
    marked = list(marked or ())
    # viridis up to 0.85: its last yellows are too light on white.
    colours = colormaps["viridis"](np.linspace(0.0, 0.85, len(marked)))
    for index, value in enumerate(marked):
        nearest = _nearest_weight(c_values, float(value))
        if nearest is None:  # nothing to mark: said in the legend
            ax.plot([], [], " ", label=f"{weight_name} = {value:g}: not marked")
            continue
        row = nearest
        symbol = markers[index % len(markers)]
        ax.plot(
            *_drawable_complex(ax, tracked[row]),
            symbol,
            mfc="none",
            color=colours[index],
            label=f"{weight_name} = {c_values[row]:.6g}",
        )
    ax.axvline(0.0, color="black", linewidth=0.8)
    ax.axhline(0.0, color="black", linewidth=0.8)
    _finish(ax, "real part (1/s)", "imaginary part (rad/s)", title)
    return ax


def plot_gain_root_locus(
    locus: RootLocus,
    ax: Axes | None = None,
    marked: Sequence[float] | None = None,
    zetas: Sequence[float] = (0.1, 0.2, 0.3, 0.4, 0.5, 0.7, 0.9),
    title: str = "root locus over the loop gain k",
) -> Axes:
    """The closed-loop poles of 1 + k L(s) = 0 over the gains of a
    :class:`~aerocontrol.loops.RootLocus` (like the chapter's Figure 6.8, for a classical
    loop): one line per root, the open-loop poles (x) and zeros (o), a symbol per gain in
    ``marked``, and a grid of constant damping ratio (rays, labelled ζ) and natural frequency
    (arcs, labelled ω_n). A discrete locus is drawn in the z-plane with the unit circle.
    Returns the axes.

    Parameters
    ----------
    locus : RootLocus
        From :func:`aerocontrol.root_locus`.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    marked : sequence of float, optional
        Gains to mark (at the nearest computed one).
    zetas : sequence of float, optional
        The damping ratios of the grid's rays (default 0.1 ... 0.9).
    title : str, optional
        The title.

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    None
        A :class:`~aerocontrol.loops.RootLocus` is consistent by construction.

    Examples
    --------
    k/(s(s + 2)), k = 4 marked (poles -1 ± j√3, ζ = 0.5):

    >>> import numpy as np, aerocontrol
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import plotting
    >>> loop = aerocontrol.zpk([], [0.0, -2.0], 1.0)
    >>> locus = aerocontrol.root_locus(loop, np.linspace(0, 10, 51))
    >>> ax = plotting.plot_gain_root_locus(locus, ax=Figure().subplots(), marked=[4.0])
    >>> [line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")]
    ['k = 4', 'open-loop poles']
    """
    ax = plot_root_locus(
        locus.gains,
        locus.poles,
        ax=ax,
        marked=marked,
        weight_name="k",
        title=title,
    )
    ax.plot(
        *_drawable_complex(ax, locus.open_loop_poles),
        "x",
        color="black",
        label="open-loop poles",
    )
    if locus.open_loop_zeros.size:
        ax.plot(
            *_drawable_complex(ax, locus.open_loop_zeros),
            "o",
            mfc="none",
            color="black",
            label="zeros",
        )
    if locus.dt:
        t = np.linspace(0.0, 2.0 * np.pi, 361)
        ax.plot(np.cos(t), np.sin(t), color="0.7", linewidth=0.8)
        ax.legend(fontsize=8)
        return ax
    x_low, x_high = ax.get_xlim()
    y_low, y_high = ax.get_ylim()
    reach = max(abs(x_low), abs(x_high), abs(y_low), abs(y_high))
    for zeta in zetas:
        angle = np.arccos(zeta)
        x, y = -reach * np.cos(angle), reach * np.sin(angle)
        ax.plot([0.0, x], [0.0, y], ":", color="0.6", linewidth=0.7)
        ax.plot([0.0, x], [0.0, -y], ":", color="0.6", linewidth=0.7)
        if x_low <= 0.9 * x and 0.9 * y <= y_high:
            ax.annotate(f"ζ={zeta:g}", (0.9 * x, 0.9 * y), fontsize=7, color="0.4")
    ticks = [v for v in ax.get_yticks() if 0 < v <= reach]
    t = np.linspace(np.pi / 2, 3 * np.pi / 2, 91)
    for radius in ticks:
        ax.plot(radius * np.cos(t), radius * np.sin(t), ":", color="0.6", linewidth=0.7)
        ax.annotate(f"ω_n={radius:g}", (-radius, 0.0), fontsize=7, color="0.4")
    ax.set_xlim(x_low, x_high)
    ax.set_ylim(y_low, y_high)
    ax.legend(fontsize=8)
    return ax


def plot_bode(
    result: FrequencyResponse, ax: Iterable[Axes] | None = None, output: int = 0, input: int = 0
) -> tuple[Axes, Axes]:
    """Magnitude (dB) and phase (degrees) against frequency (rad/s, log scale) of one
    input-output pair, on a pair of axes. Returns the pair.

    Parameters
    ----------
    result : FrequencyResponse
        From :func:`aerocontrol.bode` or :func:`aerocontrol.frequency_response`.
    ax : pair of matplotlib.axes.Axes, optional
        Magnitude and phase axes (default a new pair, one above the other).
    output, input : int, optional
        The channel (default 0, 0).

    Returns
    -------
    (matplotlib.axes.Axes, matplotlib.axes.Axes)
        The magnitude and phase axes.

    Raises
    ------
    InvalidArgumentError
        ``output`` or ``input`` is out of range, or ``ax`` is not a pair of axes.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import aerocontrol
    >>> from aerocontrol import plotting
    >>> b = aerocontrol.bode(([[-2.0]], [[2.0]]))                  # 2/(s + 2)
    >>> magnitude, phase = plotting.plot_bode(b, ax=Figure().subplots(2, 1))
    >>> magnitude.get_ylabel(), phase.get_ylabel(), phase.get_xlabel()
    ('magnitude (dB)', 'phase (deg)', 'frequency (rad/s)')
    """
    for value, names, argument in (
        (output, result.output_names, "output"),
        (input, result.input_names, "input"),
    ):
        if not 0 <= value < len(names):
            raise InvalidArgumentError(f"{argument} must be in 0 ... {len(names) - 1}, got {value}")
    magnitude_axis, phase_axis = _pair(_new_axes(2, 1, sharex=True) if ax is None else ax, "ax")
    text = f"{result.input_names[input]} -> {result.output_names[output]}"
    magnitude = _drawable(magnitude_axis, result.magnitude_db[:, output, input])
    magnitude_axis.semilogx(result.omega, magnitude, label=text)
    phase = _drawable(phase_axis, result.phase_deg[:, output, input])
    phase_axis.semilogx(result.omega, phase, label=text)
    magnitude_axis.set_ylabel("magnitude (dB)")
    phase_axis.set_ylabel("phase (deg)")
    phase_axis.set_xlabel("frequency (rad/s)")
    for axis in (magnitude_axis, phase_axis):
        axis.grid(True, which="both", alpha=0.3)
    magnitude_axis.legend(loc="best", fontsize="small")
    return magnitude_axis, phase_axis


def _compressed(values: NDArray[np.complex128], limit: float) -> NDArray[np.complex128]:
    """``values`` with each radius r beyond ``limit`` (R) drawn at R (1 + x/(1 + x)),
    x = ln(r/R): continuous with slope 1 at R, logarithmic in r, below 2R."""
    radius = np.abs(values)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        x = np.log(radius / limit)
        drawn = np.where(radius > limit, limit * (1.0 + x / (1.0 + x)), radius)
        scale = np.where(radius > 0.0, drawn / radius, 0.0)
    return np.asarray(values * scale, dtype=np.complex128)


def _arrow(ax: Axes, points: NDArray[np.complex128], fraction: float, colour: str) -> None:
    """An arrowhead on the polyline ``points`` at ``fraction`` of its length, pointing along
    it."""
    lengths = np.abs(np.diff(points))
    if not np.any(lengths > 0.0):
        return
    cumulative = np.cumsum(lengths)
    i = int(np.searchsorted(cumulative, fraction * cumulative[-1]))
    i = min(i, lengths.size - 1)
    while lengths[i] == 0.0 and i > 0:
        i -= 1
    if lengths[i] == 0.0:
        return
    start, end = points[i], points[i + 1]
    ax.annotate(
        "",
        xy=(end.real, end.imag),
        xytext=(start.real, start.imag),
        arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.0, "mutation_scale": 14},
    )


def plot_nyquist(
    result: NyquistResponse,
    ax: Axes | None = None,
    unit_circle: bool = False,
    max_magnitude: float = 20.0,
) -> Axes:
    """The Nyquist curve of a :class:`~aerocontrol.loops.NyquistResponse`: the half ω ≥ 0
    solid, its mirror image (ω ≤ 0) dashed, arrows in the direction of increasing ω, the
    critical point -1 (a red +) and, with ``unit_circle``, the unit circle (dotted: its
    crossings are the gain crossovers). The title gives P, N and Z. Returns the axes.

    Radii beyond ``max_magnitude`` (R) are compressed: a point with abs(L) = r > R is drawn at
    radius R (1 + x/(1 + x)), x = ln(r/R), at its true angle. The map is continuous with
    slope 1 at R, logarithmic in r and bounded by 2R, so the large arcs that are the images of
    the indentations around poles on the imaginary axis (abs(L) of 1e4 to 1e12 and more) are
    drawn between R and 2R and the curve closes as it does in the plane: its encirclements of
    -1 can be counted on the plot. (python-control and MATLAB clip such arcs at a
    ``max_curve_magnitude`` instead.) The circle abs(L) = R is drawn, dotted, when a point is
    compressed.

    Parameters
    ----------
    result : NyquistResponse
        From :func:`aerocontrol.nyquist`.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    unit_circle : bool, optional
        Draw the unit circle (default False).
    max_magnitude : float, optional
        The radius R beyond which radii are compressed, positive (default 20).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    InvalidArgumentError
        ``max_magnitude`` is not positive and finite.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import aerocontrol
    >>> ax = aerocontrol.nyquist(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0)).plot()
    >>> ax.get_xlabel(), ax.get_title()
    ('Re L', 'Nyquist: P = 0, N = 0, Z = 0, closed loop stable')
    """
    from matplotlib.colors import to_hex

    limit = float(max_magnitude)
    if not (math.isfinite(limit) and limit > 0.0):
        raise InvalidArgumentError(f"max_magnitude must be positive and finite, got {limit}")
    ax = _new_axes() if ax is None else ax
    half = _compressed(result.curve, limit)
    mirror = np.conj(half[::-1])
    (line,) = ax.plot(half.real, half.imag, "-", label="ω ≥ 0")
    colour = to_hex(line.get_color())
    ax.plot(mirror.real, mirror.imag, "--", color=colour, label="ω ≤ 0 (mirror image)")
    for fraction in (0.3, 0.7):
        _arrow(ax, half, fraction, colour)
        _arrow(ax, mirror, fraction, colour)
    ax.plot([-1.0], [0.0], "+", color="red", markersize=12, markeredgewidth=2, label="-1")
    turn = np.linspace(0.0, 2.0 * math.pi, 361)
    if unit_circle:
        ax.plot(np.cos(turn), np.sin(turn), ":", color="0.5", linewidth=0.8, label="|L| = 1")
    if np.any(np.abs(result.curve) > limit):
        ax.plot(
            limit * np.cos(turn),
            limit * np.sin(turn),
            ":",
            color="0.75",
            linewidth=0.8,
            label=f"|L| = {limit:g}, compressed beyond",
        )
    ax.axhline(0.0, color="black", linewidth=0.6)
    ax.axvline(0.0, color="black", linewidth=0.6)
    ax.set_aspect("equal", adjustable="datalim")
    if result.encirclements is None:
        counts = f"P = {result.open_loop_unstable_poles}, N undefined (curve through -1)"
    else:
        counts = (
            f"P = {result.open_loop_unstable_poles}, N = {result.encirclements}, "
            f"Z = {result.closed_loop_unstable_poles}"
        )
    verdict = (
        "closed loop stable"
        if result.closed_loop_stable
        else ("closed loop unstable" if result.closed_loop_unstable_poles else "marginal")
    )
    _finish(ax, "Re L", "Im L", f"Nyquist: {counts}, {verdict}")
    return ax


#: Closed-loop gains (dB) and phases (degrees) of the Nichols chart's grid.
NICHOLS_GAINS_DB = (-20.0, -12.0, -6.0, -3.0, -1.0, 0.0, 1.0, 3.0, 6.0, 12.0)
NICHOLS_PHASES_DEG = (
    -5.0,
    -15.0,
    -30.0,
    -60.0,
    -90.0,
    -120.0,
    -150.0,
    -180.0,
    -210.0,
    -240.0,
    -270.0,
    -300.0,
    -330.0,
    -345.0,
    -355.0,
)


def _open_loop_points(T: NDArray[np.complex128]) -> tuple[FloatArray, FloatArray]:
    """(phase in (-360°, 0°], gain in dB) of L = T/(1 - T), the open loop whose closed loop
    L/(1 + L) is T, with NaN between neighbours whose phases differ by more than 180° (where
    the phase wraps), so that a line drawn through them breaks there."""
    L = T / (1.0 - T)
    phase = np.degrees(np.angle(L))
    phase = np.where(phase > 0.0, phase - 360.0, phase)
    gain = 20.0 * np.log10(np.abs(L))
    jumps = np.flatnonzero(np.abs(np.diff(phase)) > 180.0) + 1
    return (
        np.asarray(np.insert(phase, jumps, np.nan), dtype=np.float64),
        np.asarray(np.insert(gain, jumps, np.nan), dtype=np.float64),
    )


def closed_loop_gain_contour(gain_db: float, count: int = 721) -> tuple[FloatArray, FloatArray]:
    """The open-loop (phase in (-360°, 0°], gain in dB) at which the closed loop
    T = L/(1 + L) has the gain ``gain_db``: L = T/(1 - T) for T = M e^{jθ},
    M = 10^(gain_db/20), θ over the circle (θ = 0 left out for M = 1, where L = ∞). NaN
    separates the pieces where the phase wraps.

    Parameters
    ----------
    gain_db : float
        The closed-loop gain, dB.
    count : int, optional
        The points on the circle of θ (default 721).

    Returns
    -------
    phase : ndarray, deg
        The open-loop phases, in (-360°, 0°], NaN between pieces.
    gain : ndarray, dB
        The open-loop gains.

    Raises
    ------
    InvalidArgumentError
        ``count`` is not a positive int.
    NotRealError
        ``gain_db`` is not a real number.

    Examples
    --------
    >>> import numpy as np
    >>> phase, gain = closed_loop_gain_contour(0.0)   # |T| = 1: Re L = -1/2
    >>> L = 10 ** (gain / 20) * np.exp(1j * np.radians(phase))
    >>> bool(np.allclose(L[np.isfinite(L)].real, -0.5))
    True
    """
    magnitude = 10.0 ** (real_scalar(gain_db, "gain_db") / 20.0)
    theta = np.linspace(0.0, 2.0 * math.pi, positive_int(count, "count"))
    if magnitude == 1.0:
        theta = theta[1:-1]
    return _open_loop_points(magnitude * np.exp(1j * theta))


def closed_loop_phase_contour(
    phase_deg: float, low_db: float = -20.0, high_db: float = 32.0, count: int = 721
) -> tuple[FloatArray, FloatArray]:
    """The open-loop (phase in (-360°, 0°], gain in dB) at which the closed loop
    T = L/(1 + L) has the phase ``phase_deg`` (in (-360°, 0°)): L = T/(1 - T) for
    T = m e^{j phase}, the closed-loop gain 20 log10 m from ``low_db`` to ``high_db`` (L then
    runs from about ``low_db`` at that phase towards the critical point -1).

    Parameters
    ----------
    phase_deg : float
        The closed-loop phase, degrees, in (-360°, 0°).
    low_db, high_db : float, optional
        The range of closed-loop gains, dB (default -20 to 32).
    count : int, optional
        The points (default 721).

    Returns
    -------
    phase : ndarray, deg
        The open-loop phases, in (-360°, 0°], NaN between pieces.
    gain : ndarray, dB
        The open-loop gains.

    Raises
    ------
    InvalidArgumentError
        ``count`` is not a positive int.
    NotRealError
        ``phase_deg``, ``low_db`` or ``high_db`` is not a real number.

    Examples
    --------
    Every point of the contour ∠T = -90° has T = L/(1 + L) at -90°:

    >>> import numpy as np
    >>> phase, gain = closed_loop_phase_contour(-90.0)
    >>> L = 10 ** (gain / 20) * np.exp(1j * np.radians(phase))
    >>> bool(np.allclose(np.degrees(np.angle(L / (1 + L))), -90.0))
    True
    """
    low, high = real_scalar(low_db, "low_db"), real_scalar(high_db, "high_db")
    magnitudes = np.logspace(low / 20.0, high / 20.0, positive_int(count, "count"))
    phase = math.radians(real_scalar(phase_deg, "phase_deg"))
    return _open_loop_points(magnitudes * np.exp(1j * phase))


def plot_nichols(
    result: NicholsResponse,
    ax: Axes | None = None,
    grid: bool = True,
    gains_db: Sequence[float] = NICHOLS_GAINS_DB,
    phases_deg: Sequence[float] = NICHOLS_PHASES_DEG,
) -> Axes:
    """The Nichols chart of a :class:`~aerocontrol.loops.NicholsResponse`: open-loop gain (dB)
    against phase (degrees), the critical points (-180° + k 360°, 0 dB) as red +, and with
    ``grid`` the contours of constant closed-loop gain abs(T) (``gains_db``) and phase ∠T
    (``phases_deg``, in (-360°, 0°)) of T = L/(1 + L), dotted (from
    :func:`closed_loop_gain_contour` and :func:`closed_loop_phase_contour`, the phase
    contours over the closed-loop gains from the least of ``gains_db`` to 20 dB beyond the
    largest), repeated every 360° over the phases shown and labelled about the critical point
    nearest the curve's gain crossover. The curve is broken where its phase steps by more
    than 90° between neighbouring frequencies: across a pole on the imaginary axis, where the
    gain passes through infinity. Returns the axes.

    Parameters
    ----------
    result : NicholsResponse
        From :func:`aerocontrol.nichols`.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    grid : bool, optional
        Draw the closed-loop contours (default True).
    gains_db : sequence of float, optional
        The closed-loop gains of the contours, dB (default -20 ... 12).
    phases_deg : sequence of float, optional
        The closed-loop phases of the contours, degrees, each in (-360°, 0°) (default -5 ...
        -355).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    InvalidArgumentError
        A phase of ``phases_deg`` outside (-360°, 0°).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import aerocontrol
    >>> ax = aerocontrol.nichols(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0)).plot()
    >>> ax.get_xlabel(), ax.get_ylabel()
    ('open-loop phase (deg)', 'open-loop gain (dB)')
    """
    from matplotlib.ticker import MultipleLocator

    for value in phases_deg:
        if not -360.0 < float(value) < 0.0:
            raise InvalidArgumentError(f"phases_deg must lie in (-360, 0), got {value}")
    ax = _new_axes() if ax is None else ax
    finite = np.isfinite(result.gain_db) & np.isfinite(result.phase_deg)
    phase = np.where(finite, result.phase_deg, np.nan)
    gain = np.where(finite, result.gain_db, np.nan)
    breaks = np.flatnonzero(np.abs(np.diff(phase)) > 90.0) + 1
    ax.plot(np.insert(phase, breaks, np.nan), np.insert(gain, breaks, np.nan), "-", label="L(jω)")
    shown_phase = phase[finite] if np.any(finite) else np.array([-180.0])
    shown_gain = gain[finite] if np.any(finite) else np.array([0.0])
    low = 360.0 * math.floor(float(shown_phase.min()) / 360.0)
    high = 360.0 * math.ceil(float(shown_phase.max()) / 360.0)
    if high <= low:  # every phase a multiple of 360°: the period below it
        low = high - 360.0
    lowest, highest = min(gains_db, default=-20.0), max(gains_db, default=12.0)
    bottom = min(float(shown_gain.min()), lowest - 6.0) - 3.0
    top = max(float(shown_gain.max()), highest + 6.0) + 3.0
    periods = list(range(round(low / 360.0) + 1, round(high / 360.0) + 1))
    # Labels about the critical point nearest the phase where the gain is nearest 0 dB.
    crossover = float(shown_phase[np.argmin(np.abs(shown_gain))])
    labelled = min(periods, key=lambda k: abs(crossover - (360.0 * k - 180.0)))
    if grid:
        for k in periods:
            offset = 360.0 * k
            for m_db in gains_db:
                x, y = closed_loop_gain_contour(m_db)
                (line,) = ax.plot(x + offset, y, ":", color="0.6", linewidth=0.7)
                line.set_gid(f"closed-loop gain {m_db:g} dB")
                if k == labelled:
                    _label_gain_contour(ax, m_db, offset)
            for n_deg in phases_deg:
                x, y = closed_loop_phase_contour(n_deg, lowest, highest + 20.0)
                (line,) = ax.plot(x + offset, y, ":", color="0.75", linewidth=0.7)
                line.set_gid(f"closed-loop phase {n_deg:g} deg")
                if k == labelled and n_deg % 60.0 == 0.0:
                    ax.annotate(
                        f"{n_deg:g}°",
                        (x[0] + offset, y[0]),
                        fontsize=6,
                        color="0.5",
                        ha="center",
                        va="top",
                    )
    critical = [360.0 * k - 180.0 for k in periods]
    ax.plot(
        critical,
        np.zeros(len(critical)),
        "+",
        color="red",
        markersize=12,
        markeredgewidth=2,
        label="critical points",
    )
    ax.set_xlim(low, high)
    ax.set_ylim(bottom, top)
    ax.xaxis.set_major_locator(MultipleLocator(45.0 if high - low <= 720.0 else 90.0))
    _finish(ax, "open-loop phase (deg)", "open-loop gain (dB)", "Nichols chart")
    return ax


def _label_gain_contour(ax: Axes, gain_db: float, offset: float) -> None:
    """The label of the closed-loop gain contour ``gain_db``: for |T| = M > 1 at the top of
    its oval about the critical point (phase -180°, L = -M/(M - 1)); for M ≤ 1 at phase 0°
    (the period's right edge), where L = M/(1 - M) (M = 1 at -180°, where L = -1/2)."""
    magnitude = 10.0 ** (gain_db / 20.0)
    if magnitude > 1.0:
        x, g = offset - 180.0, magnitude / (magnitude - 1.0)
    elif magnitude < 1.0:
        x, g = offset - 2.0, magnitude / (1.0 - magnitude)
    else:
        x, g = offset - 180.0, 0.5
    ax.annotate(
        f"{gain_db:g} dB",
        (x, 20.0 * math.log10(g)),
        fontsize=6,
        color="0.4",
        ha="right" if magnitude < 1.0 else "center",
        va="bottom",
    )


_LEVEL_COLOURS = ("0.8", "#4daf4a", "#ffd92f", "#ff7f00", "#e41a1c")
_LEVEL_NAMES = ("not assessed", "Level 1", "Level 2", "Level 3", "worse than Level 3")


def _edges(centres: FloatArray) -> FloatArray:
    """Cell edges around grid points: midpoints, the ends mirrored (±5 % for one point)."""
    if len(centres) == 1:
        half = 0.05 * abs(centres[0]) or 0.5
        return np.array([centres[0] - half, centres[0] + half])
    middle = 0.5 * (centres[1:] + centres[:-1])
    return np.concatenate([[2 * centres[0] - middle[0]], middle, [2 * centres[-1] - middle[-1]]])


def plot_levels(
    machs: ArrayLike,
    altitudes: ArrayLike,
    levels: ArrayLike,
    ax: Axes | None = None,
    title: str = "Levels",
) -> Axes:
    """MIL-F-8785C Levels over a grid of flight conditions: one cell per (Mach, altitude),
    coloured and labelled by its Level (0: not assessed). ``levels`` is (len(altitudes),
    len(machs)). Returns the axes.

    Parameters
    ----------
    machs : array_like (j,)
        The Mach numbers of the columns.
    altitudes : array_like (i,)
        The altitudes of the rows.
    levels : array_like (i, j) of int
        The Level of each condition, 0 (not assessed) to 4 (worse than Level 3).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    title : str, optional
        The title (default "Levels").

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    ShapeError
        ``levels`` is not (len(altitudes), len(machs)).
    NotRealError
        ``machs`` or ``altitudes`` is complex or not numeric.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import plotting
    >>> ax = plotting.plot_levels([0.2, 0.3], [0, 10000], [[1, 2], [1, 3]],
    ...                           ax=Figure().subplots())
    >>> [text.get_text() for text in ax.texts]
    ['1', '2', '1', '3']
    >>> [patch.get_label() for patch in ax.get_legend().legend_handles]
    ['Level 1', 'Level 2', 'Level 3']
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    x, y = np.asarray(real_array(machs, "machs")), np.asarray(real_array(altitudes, "altitudes"))
    values = np.asarray(levels)
    if values.shape != (len(y), len(x)):
        raise ShapeError(
            f"levels must be (len(altitudes), len(machs)) = ({len(y)}, {len(x)}), "
            f"got shape {values.shape}"
        )
    ax = _new_axes() if ax is None else ax
    colours = ListedColormap(_LEVEL_COLOURS)
    ax.pcolormesh(
        _edges(x), _edges(y), values, cmap=colours, norm=BoundaryNorm(np.arange(-0.5, 5), 5)
    )
    if values.size <= 400:
        for (i, j), level in np.ndenumerate(values):
            ax.text(x[j], y[i], str(level), ha="center", va="center", fontsize="small")
    present = sorted(set(values.ravel().tolist()))
    handles = [Patch(color=_LEVEL_COLOURS[v], label=_LEVEL_NAMES[v]) for v in present]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.set_xlabel("Mach number")
    ax.set_ylabel("altitude")
    ax.set_title(title)
    return ax


def plot_modes(modes: Modes, ax: Axes | None = None, marker: str = "x", suffix: str = "") -> Axes:
    """The eigenvalues in the complex plane (rad/s), one marker and label per mode; give
    ``marker`` and ``suffix`` (appended to the labels) to overlay two sets, e.g. open and
    closed loop.

    Parameters
    ----------
    modes : Modes
        From :func:`aerocontrol.modes`.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    marker : str, optional
        The matplotlib marker (default "x").
    suffix : str, optional
        Appended to each label (default "").

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    None
        Any :class:`~aerocontrol.Modes` is drawn (values beyond the doubles are not drawn).

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import aerocontrol
    >>> from aerocontrol import plotting
    >>> A, _ = aerocontrol.chapter.boeing747_lateral()
    >>> m = aerocontrol.modes(A, mode_names=["spiral", "dutch roll", "roll"])
    >>> ax = plotting.plot_modes(m, ax=Figure().subplots())
    >>> [line.get_label() for line in ax.get_lines()][:3]
    ['spiral', 'dutch roll', 'roll']
    """
    ax = _new_axes() if ax is None else ax
    for k, name in enumerate(modes.mode_names):
        lam = modes.eigenvalue[k]
        points = np.array([lam, np.conj(lam)]) if modes.oscillatory[k] else np.array([lam])
        ax.plot(
            *_drawable_complex(ax, points), marker, markersize=9, mfc="none", label=name + suffix
        )
    ax.margins(0.12)  # the extreme markers whole, not cut by the frame
    ax.axvline(0.0, color="black", linewidth=0.8)
    ax.axhline(0.0, color="black", linewidth=0.8)
    _finish(ax, "real part (1/s)", "imaginary part (rad/s)", "modes")
    return ax


# --- Stochastic robustness ---------------------------------------------------------------------


def plot_robustness_histogram(
    result: MonteCarlo,
    mode: str,
    quantity: str,
    loop: str = "auto",
    ax: Axes | None = None,
    bins: int = 60,
) -> Axes:
    """The distribution of one mode quantity over the samples of a Monte Carlo run (e.g.
    ``"dutch roll", "zeta"``), with the MIL-F-8785C limit of each Level as a vertical line.
    Non-finite values (a split mode's ζ, a spiral that does not grow) are counted in the title.
    Returns the axes.

    Parameters
    ----------
    result : MonteCarlo
        From :func:`aerocontrol.robustness.monte_carlo`.
    mode : str
        The mode ("dutch roll", "roll", "spiral", "short period", "phugoid").
    quantity : str
        Its quantity ("zeta", "omega_n", "time constant", "time to double").
    loop : {"auto", "open", "closed"}, optional
        The loop (default the closed loop if there is one).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    bins : int, optional
        The histogram's bins (default 60).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    InvalidArgumentError
        The run has no quantity "mode: quantity", or ``loop`` is not one of the three (or
        "closed" for a run without a controller).

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, plotting
    >>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load("b747-cruise"),
    ...                   Uncertainty({"Cn_beta": Normal(0.5), "Cn_r": Normal(0.2)}), 500, seed=3)
    >>> ax = plotting.plot_robustness_histogram(run, "dutch roll", "zeta",
    ...                                         ax=Figure().subplots())
    >>> ax.get_title(), [line.get_label() for line in ax.get_lines()]
    ('dutch roll: 500 samples', ['Level 1 limit 0.08', 'Level 2 limit 0.02', 'Level 3 limit 0'])
    """
    from .handling import level_limits

    key = f"{mode}: {quantity}"
    outcome = result.outcome(loop)
    if key not in outcome.quantities:
        raise InvalidArgumentError(
            f"no quantity {key!r} in this run; it has {', '.join(outcome.quantities)}"
        )
    values = outcome.quantities[key]
    finite = values[np.isfinite(values)]
    ax = _new_axes() if ax is None else ax
    spread = finite.size and finite.min() > 0 and finite.max() > 100 * finite.min()
    if spread:  # times to double near a neutral spiral: decades apart, on a log axis
        edges: Any = np.geomspace(finite.min(), finite.max(), bins + 1)
        ax.set_xscale("log")
    else:
        edges = bins
    ax.hist(finite, bins=edges, color="tab:blue", alpha=0.75)
    for level, bound in level_limits(mode, quantity, result.aircraft_class, result.category):
        ax.axvline(
            bound,
            color=_LEVEL_COLOURS[level],
            linestyle="--",
            label=f"Level {level} limit {bound:g}",
        )
    hidden = values.size - finite.size
    title = f"{mode}: {values.size} samples"
    if hidden:
        title += f", {hidden} not shown (mode unresolved, or inf)"
    unit = {"omega_n": "rad/s", "time constant": "s", "time to double": "s"}.get(quantity)
    _finish(ax, f"{quantity} ({unit})" if unit else quantity, "samples", title)
    return ax


def plot_probability_convergence(
    result: MonteCarlo,
    event: str = "failed",
    mode: str | None = None,
    level: int = 1,
    loop: str = "auto",
    ax: Axes | None = None,
    points: int = 60,
) -> Axes:
    """The estimate of a probability (as ``MonteCarlo.probability`` takes it) against the
    number of samples used, with its 95 % Clopper-Pearson band: how many samples the estimate
    needed. Returns the axes.

    Parameters
    ----------
    result : MonteCarlo
        From :func:`aerocontrol.robustness.monte_carlo`.
    event : {"failed", "unstable", "unresolved", "level"}, optional
        The event (default "failed").
    mode : str, optional
        The mode of a "level" event.
    level : int, optional
        The Level of a "level" event (default 1).
    loop : {"auto", "open", "closed"}, optional
        The loop (default the closed loop if there is one).
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).
    points : int, optional
        The sample sizes drawn, log-spaced (default 60).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    InvalidArgumentError
        An unknown event, mode or loop, as ``MonteCarlo.probability`` refuses them.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, plotting
    >>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load("b747-cruise"),
    ...                   Uncertainty({"Cn_beta": Normal(0.5), "Cn_r": Normal(0.2)}), 500, seed=3)
    >>> plotting.plot_probability_convergence(run, ax=Figure().subplots()).get_title()
    'P(failed)'
    """
    from .robustness import clopper_pearson

    indicator = result.indicator(event, mode, level, loop)
    counts = np.cumsum(indicator)
    sizes = np.unique(np.geomspace(min(10, indicator.size), indicator.size, points).astype(int))
    estimates = [clopper_pearson(int(counts[n - 1]), int(n)) for n in sizes]
    ax = _new_axes() if ax is None else ax
    ax.fill_between(
        sizes,
        [e.low for e in estimates],
        [e.high for e in estimates],
        alpha=0.25,
        label="95 % interval",
    )
    ax.plot(sizes, [e.value for e in estimates], label="estimate")
    ax.set_xscale("log")
    what = event if event != "level" else f"{mode} Level {level} or better"
    _finish(ax, "samples", "probability", f"P({what})")
    return ax


def plot_sensitivity(result: MonteCarlo, ax: Axes | None = None) -> Axes:
    """A tornado chart: for each uncertain parameter, the failure rate among the samples in
    the lowest and in the highest tenth of its draw, as bars from the overall failure rate,
    the parameter the failures depend on most at the top. Returns the axes.

    Parameters
    ----------
    result : MonteCarlo
        From :func:`aerocontrol.robustness.monte_carlo`.
    ax : matplotlib.axes.Axes, optional
        The axes to draw on (default new axes, by pyplot).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on.

    Raises
    ------
    None
        Any run is drawn (a decile without samples has no bar).

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, plotting
    >>> from aerocontrol.robustness import Normal, Uncertainty, monte_carlo
    >>> run = monte_carlo(aircraft.load("b747-cruise"),
    ...                   Uncertainty({"Cn_beta": Normal(0.5), "Cn_r": Normal(0.2)}), 500, seed=3)
    >>> ax = plotting.plot_sensitivity(run, ax=Figure().subplots())
    >>> [tick.get_text() for tick in ax.get_yticklabels()]
    ['Cn_beta', 'Cn_r']
    """
    ranking = [name for name, _ in result.sensitivity()]
    with np.errstate(invalid="ignore", divide="ignore"):
        rates = result.failures_by_bin / result.samples_by_bin
    overall = float(result.failed.mean())
    ax = _new_axes() if ax is None else ax
    rows = np.arange(len(ranking))[::-1]
    index = [result.parameters.index(name) for name in ranking]
    low = rates[index, 0] - overall
    high = rates[index, -1] - overall
    ax.barh(rows, low, left=overall, color="tab:blue", label="lowest tenth of the draw")
    ax.barh(rows, high, left=overall, color="tab:red", alpha=0.7, label="highest tenth")
    ax.axvline(overall, color="black", linewidth=0.8)
    ax.set_yticks(rows, ranking)
    _finish(ax, "failure rate", "", f"sensitivity of P(failed) = {overall:.3g}")
    return ax


# --- Gain schedules over the envelope ------------------------------------------------------


def _panels(ax: Any, count: int, name: str, shape: tuple[int, int]) -> list[Axes]:
    """``count`` axes: new ones in a grid of ``shape`` when ``ax`` is None, else the given
    ones (any sequence or array of axes, flattened)."""
    if ax is None:
        ax = _new_axes(*shape, figsize=(3.2 * shape[1], 2.6 * shape[0]))
    panels = list(np.ravel(np.asarray(ax, dtype=object)))
    if len(panels) != count:
        raise InvalidArgumentError(f"{name} must hold {count} matplotlib axes, got {len(panels)}")
    return panels


def _weight_index(weight: int, weights: FloatArray) -> int:
    if isinstance(weight, bool) or not isinstance(weight, (int, np.integer)):
        raise InvalidArgumentError(f"weight must be an index into the weights, got {weight!r}")
    if not -len(weights) <= weight < len(weights):
        raise InvalidArgumentError(
            f"weight must index the {len(weights)} weights of the grid, got {weight}"
        )
    return int(weight) % len(weights)


def plot_gain_schedule(schedule: GainSchedule, ax: Any = None, weight: int = 0) -> Any:
    """A gain schedule (:func:`aerocontrol.schedule.gain_schedule`) over the envelope: each
    entry K[i, j] of u = -K x in a panel of its own (rows inputs, columns states), against
    Mach, a line per altitude of the grid, at the grid's ``weight``-th weight.

    ``ax`` is None (a new grid of panels) or inputs x 4 axes (any sequence or array, in
    row-major order). Returns the axes as a list.

    Parameters
    ----------
    schedule : GainSchedule
        From :func:`aerocontrol.schedule.gain_schedule`.
    ax : sequence or array of matplotlib.axes.Axes, optional
        inputs x 4 axes (default a new grid).
    weight : int, optional
        The index of the grid's weight (default 0; negative from the end).

    Returns
    -------
    list of matplotlib.axes.Axes
        The panels, row-major.

    Raises
    ------
    InvalidArgumentError
        ``weight`` is not an index into the weights, or ``ax`` does not hold one axes per
        entry of K.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, plotting
    >>> from aerocontrol.schedule import gain_schedule
    >>> s = gain_schedule(aircraft.load(), [0, 10000], [0.2, 0.3], design="damper")
    >>> panels = plotting.plot_gain_schedule(s, ax=Figure().subplots(2, 4))
    >>> len(panels), len(panels[0].get_lines()), panels[0].get_xlabel()
    (8, 2, 'Mach number')
    """
    k = _weight_index(weight, schedule.weights)
    rows, columns = schedule.gains.shape[-2:]
    panels = _panels(ax, rows * columns, "ax", (rows, columns))
    length, force = schedule.closed_loop.length_unit, schedule.closed_loop.force_unit
    states = schedule.state_names
    for index, panel in enumerate(panels):
        i, j = divmod(index, columns)
        for a, altitude in enumerate(schedule.altitudes):
            panel.plot(
                schedule.machs,
                _drawable(panel, schedule.gains[a, :, k, i, j]),
                "o-",
                markersize=3,
                label=f"{altitude:g} {length}",
            )
        _finish(
            panel,
            "Mach number",
            f"K[{schedule.input_names[i]}, {states[j]}]",
            f"{schedule.input_names[i]} from {label(states[j])}",
        )
        panel.title.set_fontsize("small")
    panels[0].figure.suptitle(
        f"{schedule.design} gains, W = {schedule.weights[k]:g} {force}", fontsize="medium"
    )
    return panels


def plot_envelope_levels(envelope: Envelope, ax: Any = None, weight: int = 0) -> Any:
    """The MIL-F-8785C Levels of an :class:`~aerocontrol.aircraft.Envelope` (an envelope
    sweep, or a gain schedule's closed loop evaluated by
    ``GainSchedule.evaluate``): an image per mode over Mach (x) and
    altitude (y) (:func:`plot_levels`), at the grid's ``weight``-th weight.

    ``ax`` is None (new axes, one per mode in a row) or one axes per mode, in the order of
    ``envelope.levels``. Returns the axes as a list.

    Parameters
    ----------
    envelope : Envelope
        From :func:`aerocontrol.aircraft.envelope_sweep` or a gain schedule's ``evaluate``.
    ax : sequence or array of matplotlib.axes.Axes, optional
        One axes per mode (default a new row).
    weight : int, optional
        The index of the grid's weight (default 0; negative from the end).

    Returns
    -------
    list of matplotlib.axes.Axes
        One panel per mode.

    Raises
    ------
    InvalidArgumentError
        ``weight`` is not an index into the weights, or ``ax`` does not hold one axes per
        mode.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from aerocontrol import aircraft, plotting
    >>> from aerocontrol.schedule import gain_schedule
    >>> s = gain_schedule(aircraft.load(), [0, 10000], [0.2, 0.3], design="damper", zeta=0.1)
    >>> envelope = s.evaluate([0, 5000, 10000], [0.2, 0.25, 0.3])
    >>> panels = plotting.plot_envelope_levels(envelope, ax=Figure().subplots(1, 3))
    >>> [panel.get_title() for panel in panels]
    ['dutch roll, W = 564032 lbf', 'roll, W = 564032 lbf', 'spiral, W = 564032 lbf']
    """
    k = _weight_index(weight, envelope.weights)
    names = list(envelope.levels)
    panels = _panels(ax, len(names), "ax", (1, len(names)))
    for panel, mode in zip(panels, names, strict=True):
        plot_levels(
            envelope.machs,
            envelope.altitudes,
            envelope.levels[mode][:, :, k],
            ax=panel,
            title=f"{mode}, W = {envelope.weights[k]:g} {envelope.force_unit}",
        )
        panel.set_ylabel(f"altitude ({envelope.length_unit})")
    return panels
