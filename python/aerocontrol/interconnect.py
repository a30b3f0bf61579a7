"""Systems as building blocks: the elements of a flight-control loop and their interconnection.

Every element is a :class:`~aerocontrol.StateSpace` with named inputs and outputs, and every
interconnection is formed from the four matrices of its parts, never through polynomials (whose
coefficients lose the roots of a loop of any order to rounding):

* :func:`series` (``sys2`` after ``sys1``), :func:`parallel`, :func:`feedback` and
  :func:`append` combine models by position, like python-control's functions of those names;
* :func:`connect` wires models by signal name, like python-control's ``interconnect``: an
  output feeds every input of the same name, outputs of one name are summed, and explicit
  connections may add signs and gains; :func:`summing_junction` is the usual comparator;
* :func:`washout`, :func:`first_order_lag`, :func:`actuator`, :func:`second_order`,
  :func:`pade_delay` and :func:`gain` are the elements of a stability augmentation system, and
  :func:`tf` and :func:`zpk` turn a transfer function, given by polynomial coefficients or by
  zeros, poles and gain, into a state-space model.

With the interconnection's signals stacked, u the inputs of the blocks, y their outputs, w the
external inputs and z the external outputs,

    x' = A x + B u,   y = C x + D u,   u = K y + E w,   z = F y + G u + H w,

eliminating u gives u = M^-1 (K C x + E w) with M = I - K D. M singular is an algebraic loop
(a loop of feedthrough with no dynamics whose gain is one): it has no solution and is refused
by name. Continuous and discrete models combine alike; the sampling periods must agree (a
static model, with no states, goes with either).

Where products of the parts (B2 C1, D2 C1, the closed loop's B W C, ...) would overflow double
precision, or underflow to nothing (5e-324 times 0.1), the interconnection is formed again from
parts whose states are scaled by powers of two, state by state (exact, and no transfer function
changes). The scaling is chosen on the entries of the interconnection actually formed, the
closed loop's A + B W C among them, not on the parts one by one: it brings the largest to the
least that any such scaling reaches (the maximum cycle mean of their sizes, ``_scaling``) and
evens out the others. An interconnection that no such scaling brings within range (D2 D1
beyond the doubles, a closed-loop A_ii beyond them, which no scaling changes) is refused with
InvalidArgumentError naming the arguments.

:func:`zpk` forms no product of two roots as a double: a second-order section holds the
constant r1 r2 (or |r|²) as a mantissa and a power of two, and its realisation the scaled
entries a0/t and t, so that roots of 1e200 give entries of 1e200, and roots of 1e-200 entries
of 1e-200 where their product, 1e-400, is below the doubles.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from math import comb
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _scaling
from ._validation import FloatArray, check_finite, real_array, real_scalar
from .exceptions import (
    IllConditionedWarning,
    InvalidArgumentError,
    NonFiniteError,
    NotRealError,
    ShapeError,
    SingularMatrixError,
)
from .statespace import StateSpace, as_state_space, name_sequence, period

if TYPE_CHECKING:
    from ._typing import System

__all__ = [
    "actuator",
    "append",
    "connect",
    "feedback",
    "first_order_lag",
    "gain",
    "pade_delay",
    "parallel",
    "second_order",
    "series",
    "summing_junction",
    "tf",
    "washout",
    "zpk",
]

Names = str | Sequence[str] | None
"""Signal names of a constructor: one name as a string, or a sequence of names."""

Matrices = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""A, B, C and D of a model."""

Source = str | tuple[str, float]
"""A signal feeding an input in :func:`connect`: ``"name"``, ``"-name"`` or ``("name", gain)``."""

#: A loop whose M = I - K D has a condition number above this warns that it lost digits.
ILL_CONDITIONED = 1e8

#: The highest order of :func:`pade_delay`: at 20 its response is within 1.2e-12 of the
#: approximant's (computed at 50 digits) from 1e-3 to 1e3 rad/s for T = 0.3 s.
MAX_PADE_ORDER = 20


# ----- arguments --------------------------------------------------------------------------------


def _finite(value: object, name: str) -> float:
    """``value`` as a finite float, or the package's error naming ``name``."""
    number = real_scalar(value, name)
    if not np.isfinite(number):
        error = NonFiniteError(f"{name} must be finite, got {number}")
        error.argument, error.value = name, number
        raise error
    return number


def _positive(value: object, name: str) -> float:
    """``value`` as a positive, finite float, or the package's error naming ``name``."""
    number = _finite(value, name)
    if number <= 0.0:
        raise InvalidArgumentError(f"{name} must be positive, got {number}")
    return number


def _realisable(matrices: Sequence[FloatArray], function: str, argument: str, why: str) -> None:
    """Refuses a realisation whose matrices overflowed double precision although every
    argument is finite, by an InvalidArgumentError naming ``argument`` (numpy's overflow
    warning, or a NonFiniteError blaming an A the caller never gave, otherwise)."""
    for name, matrix in zip("ABCD", matrices, strict=True):
        if not np.all(np.isfinite(matrix)):
            error = InvalidArgumentError(
                f"{function}: the realisation's {name} overflows double precision: {why}"
            )
            error.argument = argument
            raise error


def _reciprocal(value: float, name: str, function: str) -> float:
    """1/value of a positive time, refused by name where it overflows (tau of 1e-310)."""
    inverse = 1.0 / value
    if not math.isfinite(inverse):
        error = InvalidArgumentError(
            f"{function}: {name} = {value:g} is too small: 1/{name} overflows double precision"
        )
        error.argument = name
        raise error
    return inverse


def _signal_names(given: Names, count: int, default: str, argument: str) -> tuple[str, ...]:
    """Constructor names: a string is one name; None gives ``default`` numbered (``u0``, ...)
    or, for a single signal, ``default`` followed by 0."""
    if given is None:
        return tuple(f"{default}{i}" for i in range(count))
    names = tuple(_name_list(given, argument, unique=False))
    if len(names) != count:
        raise ShapeError(f"{argument} must have {count} names, got {len(names)}")
    return names


def _model(
    A: FloatArray,
    B: FloatArray,
    C: FloatArray,
    D: FloatArray,
    *,
    input_names: Names,
    output_names: Names,
    state_names: Names,
    states: str | Sequence[str] = "x{k}",
    dt: float | None = None,
) -> StateSpace:
    """The model with its names; without ``state_names``, the states are named by
    ``states``: one template for each (or one for all), formatted with the element's
    ``input`` and ``output`` names (single-input, single-output) and the state's index ``k``."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    inputs = _signal_names(input_names, m, "u", "input_names")
    outputs = _signal_names(output_names, p, "y", "output_names")
    if state_names is None and m == 1 and p == 1:
        templates = [states] * n if isinstance(states, str) else list(states)
        state_names = [
            template.format(input=inputs[0], output=outputs[0], k=k)
            for k, template in enumerate(templates)
        ]
    return StateSpace(
        A,
        B,
        C,
        D,
        state_names=_signal_names(state_names, n, "x", "state_names"),
        input_names=inputs,
        output_names=outputs,
        dt=dt,
    )


def _models(systems: Sequence[System], function: str) -> list[StateSpace]:
    return [as_state_space(s, f"{function}: sys{k + 1}") for k, s in enumerate(systems)]


def _time_base(models: Sequence[StateSpace], labels: Sequence[str], function: str) -> float | None:
    """The common ``dt`` of ``models``: their sampling period if discrete, else 0.0 if any is
    marked continuous (dt = 0), else None. A model without states fits any time base; the
    others must agree, or InvalidArgumentError names the two that differ."""
    dynamic = [(m, label) for m, label in zip(models, labels, strict=True) if m.n_states] or list(
        zip(models, labels, strict=True)
    )
    first, first_label = dynamic[0]
    for model, label in dynamic[1:]:
        if period(model) != period(first):

            def describe(m: StateSpace) -> str:
                # repr, not :g: periods that differ in the 7th digit read the same in :g.
                return f"discrete (dt = {period(m)!r} s)" if m.is_discrete else "continuous"

            raise InvalidArgumentError(
                f"{function}: {first_label} is {describe(first)} but {label} is "
                f"{describe(model)}; bring them to one time base first (c2d, d2c)"
            )
    if first.is_discrete:
        return period(first)
    return 0.0 if any(m.dt == 0.0 for m in models) else None


def _block_diagonal(matrices: Sequence[FloatArray]) -> FloatArray:
    rows = sum(m.shape[0] for m in matrices)
    columns = sum(m.shape[1] for m in matrices)
    result = np.zeros((rows, columns))
    i = j = 0
    for m in matrices:
        result[i : i + m.shape[0], j : j + m.shape[1]] = m
        i, j = i + m.shape[0], j + m.shape[1]
    return result


def _solve_loop(loop: FloatArray, right: FloatArray, what: str, function: str) -> FloatArray:
    """(I - loop)^-1 right, for the loop matrix M = I - loop named ``what``.

    Its conditioning is measured relative to the terms it is formed from,
    κ = (1 + ||loop||) ||M^-1|| (2-norms): M singular (an algebraic loop) or κ beyond
    1/(size·u) is SingularMatrixError; κ above 1e8 warns IllConditionedWarning with κ."""
    size = loop.shape[0]
    if size == 0:
        return right
    if not np.all(np.isfinite(loop)):
        error = InvalidArgumentError(
            f"{function}: {what} overflows double precision: the feedthroughs (D) in the loop "
            "are too large together"
        )
        error.argument = "D"
        raise error
    M = np.eye(size) - loop
    smallest = float(np.linalg.svd(M, compute_uv=False)[-1])
    size_of_terms = 1.0 + float(np.linalg.norm(loop, 2))
    condition = size_of_terms / smallest if smallest > 0.0 else np.inf
    if not np.isfinite(condition) or condition * np.finfo(float).eps * size >= 1.0:
        raise SingularMatrixError(
            f"{function}: algebraic loop: {what} is singular (relative condition number "
            f"{condition:.3g}), so the loop of direct feedthrough has no solution; add dynamics "
            "(an actuator, a filter) or change a gain in the loop"
        )
    if condition > ILL_CONDITIONED:
        warnings.warn(
            f"{function}: {what} has relative condition number {condition:.3g}: the algebraic "
            "loop is nearly singular and the closed loop may have lost that many digits",
            IllConditionedWarning,
            stacklevel=3,
        )
    with np.errstate(over="ignore", invalid="ignore"):
        solution = np.asarray(np.linalg.solve(M, right), dtype=np.float64)
    return solution


# ----- overflow: power-of-two state scalings -------------------------------------------------


@dataclass(frozen=True)
class _TermSizes:
    """log2 of the largest term of each entry of an interconnection (``_term_sizes``)."""

    graph: FloatArray
    """The graph of ``_scaling``: the states, then the outside."""
    A: FloatArray
    B: FloatArray
    C: FloatArray
    terms: float
    """log2 of a bound of the number of terms in a sum."""


def _term_sizes(
    A: FloatArray,
    B: FloatArray,
    C: FloatArray,
    D: FloatArray,
    K: FloatArray,
    E: FloatArray,
    F: FloatArray,
    G: FloatArray,
) -> _TermSizes | None:
    """The log2 sizes of the terms of the interconnection u = K y + E w, z = F y + G u of
    parts stacked as A, B, C, D (block diagonal); None where the loop's own matrices W, V, Z
    overflow, which no state scaling changes.

    With M = I - K D, W = M^-1 K, V = M^-1 E and Z = F + (F D + G) W, the interconnection is
    A + B W C, B V, Z C (and a D that has no states). Entry (i, j) of its A has the terms of
    A_ij and of B_ik W_kl C_lj; row i of its B those of B_ik V_kl; column j of its C those of
    Z_rl C_lj. In the graph (see ``_scaling``), the intermediate products formed on the way
    (K C, W C, D W C, B W D) and the parts' own B and C, which are scaled as well, are bounded
    too, and the terms' sizes are multiplied by the number of terms summed (a bound of the
    sums)."""
    with np.errstate(all="ignore"):
        M = np.eye(K.shape[0]) - K @ D
        if not np.all(np.isfinite(M)):
            return None
        try:
            solved = np.linalg.solve(M, np.hstack([K, E]))
        except np.linalg.LinAlgError:
            return None
        W, V = solved[:, : K.shape[1]], solved[:, K.shape[1] :]
        Z = F + (F @ D + G) @ W
    if not (np.all(np.isfinite(W)) and np.all(np.isfinite(V)) and np.all(np.isfinite(Z))):
        return None
    n = A.shape[0]
    a, b, c, d = (_scaling.log2_sizes(X) for X in (A, B, C, D))
    w, v, z, k = (_scaling.log2_sizes(X) for X in (W, V, Z, K))
    terms = math.log2(n + K.shape[0] + K.shape[1] + 2) + 1.0
    wc = _scaling.max_plus(w, c)  # W C: (inputs, states), columns scaled by 2^e_j
    wd = _scaling.max_plus(w, d)  # W D: (inputs, inputs), not scaled
    closed_A = np.maximum(a, _scaling.max_plus(b, wc))
    closed_B = _scaling.max_plus(b, v)
    closed_C = _scaling.max_plus(z, c)
    column_terms = [
        np.max(c, axis=0, initial=-math.inf),
        np.max(wc, axis=0, initial=-math.inf) + terms,
        np.max(_scaling.max_plus(k, c), axis=0, initial=-math.inf) + terms,
        np.max(_scaling.max_plus(d, wc), axis=0, initial=-math.inf) + terms,
        np.max(closed_C, axis=0, initial=-math.inf) + terms,
    ]
    row_terms = [
        np.max(b, axis=1, initial=-math.inf),
        np.max(closed_B, axis=1, initial=-math.inf) + terms,
        np.max(_scaling.max_plus(b, wd), axis=1, initial=-math.inf) + terms,
    ]
    graph = np.full((n + 1, n + 1), -math.inf)
    graph[:n, :n] = closed_A + terms
    graph[:n, n] = np.max(row_terms, axis=0)
    graph[n, :n] = np.max(column_terms, axis=0)
    return _TermSizes(graph, closed_A, closed_B, closed_C, terms)


def _stacked(models: Sequence[StateSpace]) -> Matrices:
    A, B, C, D = (_block_diagonal([getattr(m, name) for m in models]) for name in "ABCD")
    return A, B, C, D


#: log2 of the smallest normal double: an entry whose terms are all below it has lost digits
#: to underflow, or all of them (5e-324 times 0.13 is 0).
SMALLEST_EXPONENT = math.log2(np.finfo(np.float64).tiny)


def _needs_scaling(
    models: Sequence[StateSpace],
    matrices: Matrices,
    K: FloatArray,
    E: FloatArray,
    F: FloatArray,
    G: FloatArray,
) -> bool:
    """Whether the interconnection formed in the parts' own states lost entries that a
    scaling of the states would keep: an overflow (an infinite or NaN entry), or an entry of
    its A, B or C that is zero or subnormal although its terms are not zero, because every
    one of them is below the normal range (underflow, not cancellation)."""
    if not all(np.all(np.isfinite(M)) for M in matrices):
        return True
    tiny = np.finfo(np.float64).tiny
    if not any(np.any(np.abs(M) < tiny) for M in matrices[:3]):
        return False
    # Only a product of tiny factors underflows: skip the sizes when none is small enough.
    A, B, C, D = _stacked(models)

    def smallest(M: FloatArray) -> float:
        nonzero = np.abs(M[M != 0.0])
        return math.log2(float(nonzero.min())) if nonzero.size else 0.0

    gains = min(0.0, *(smallest(M) for M in (D, K, E, F, G)))
    if smallest(B) + smallest(C) + 2.0 * gains > SMALLEST_EXPONENT / 2.0:
        return False
    sizes = _term_sizes(A, B, C, D, K, E, F, G)
    if sizes is None:
        return False
    for formed, largest in zip(matrices[:3], (sizes.A, sizes.B, sizes.C), strict=True):
        lost = (
            (np.abs(formed) < tiny)
            & np.isfinite(largest)
            & (largest < SMALLEST_EXPONENT + sizes.terms)
        )
        if np.any(lost):
            return True
    return False


def _kept(unscaled: Matrices, scaled: Matrices) -> Matrices:
    """The interconnection formed in scaled states, unless it overflows where the one formed
    unscaled did not (which lost only digits to underflow)."""
    finite = all(np.all(np.isfinite(M)) for M in scaled)
    return scaled if finite or not all(np.all(np.isfinite(M)) for M in unscaled) else unscaled


def _state_exponents(
    models: Sequence[StateSpace],
    K: FloatArray,
    E: FloatArray,
    F: FloatArray,
    G: FloatArray,
) -> list[NDArray[np.int64]]:
    """Exponents of state scalings x = 2^e x̃ of the parts, state by state (exact in floating
    point, and no transfer function changes: ``_scaling``), under which the largest term of
    the interconnection u = K y + E w, z = F y + G u is the least that any such scaling
    reaches, the others evened out below it; all 0 where the loop's own matrices overflow
    (no state scaling helps).

    The terms are those of the matrices actually formed, the closed loop's A + B W C among
    them (``_term_sizes``): a balancing of each part on its own would even out the parts'
    entries and leave the couplings B_i W_ij C_j of the loop as large as before."""
    sizes = [m.n_states for m in models]
    unscaled = [np.zeros(size, dtype=np.int64) for size in sizes]
    terms = _term_sizes(*_stacked(models), K, E, F, G)
    if terms is None:
        return unscaled
    exponents, _ = _scaling.balancing_exponents(terms.graph, outside=True)
    bounds = np.cumsum([0, *sizes])
    return [exponents[bounds[k] : bounds[k + 1]] for k in range(len(models))]


def _rescaled(model: StateSpace, exponents: NDArray[np.int64]) -> StateSpace:
    """``model`` in the states x = 2^e x̃: T^-1 A T, T^-1 B, C T (exact); ``model`` itself
    where that leaves the doubles (an interconnection no scaling brings within range, which
    is then refused by name)."""
    if model.n_states == 0 or not np.any(exponents):
        return model
    A, B, C = _scaling.similarity(model.A, model.B, model.C, exponents)
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B)) and np.all(np.isfinite(C))):
        return model
    return StateSpace(
        A,
        B,
        C,
        model.D,
        state_names=model.state_names,
        input_names=model.input_names,
        output_names=model.output_names,
        dt=model.dt,
    )


def _representable(matrices: Sequence[FloatArray], function: str, arguments: str) -> None:
    """Refuses an interconnection whose matrices overflowed double precision although every
    part is finite, naming the arguments whose products overflow (a NonFiniteError would
    blame a matrix the caller gave finite)."""
    for name, matrix in zip("ABCD", matrices, strict=True):
        if not np.all(np.isfinite(matrix)):
            error = InvalidArgumentError(
                f"{function}: the interconnection's {name} overflows double precision: the "
                f"entries of {arguments} are too large together, and no scaling of the states "
                "brings it within range (scale the models' units)"
            )
            error.argument = arguments.split(",")[0]
            raise error


# ----- interconnections by position -------------------------------------------------------------


def series(sys1: System, sys2: System, *systems: System) -> StateSpace:
    """``sys2`` after ``sys1`` (and so on along ``systems``): the outputs of each feed the
    inputs of the next, by position.

    With x = (x1, x2):

        A = [[A1, 0], [B2 C1, A2]],  B = [[B1], [B2 D1]],  C = [D2 C1, C2],  D = D2 D1.

    The model has the inputs of the first, the outputs of the last and the states of all, with
    their names. The same as python-control's ``series(sys1, sys2)`` (``sys2 * sys1``).

    Parameters
    ----------
    sys1, sys2 : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The first model and the one after it.
    *systems : models
        Further models, in order.

    Returns
    -------
    StateSpace
        The cascade, with the inputs of ``sys1``, the outputs of the last model and the states
        of all.

    Raises
    ------
    ShapeError
        A model has not as many inputs as the one before it has outputs.
    NotRealError
        An argument is not a model.
    InvalidArgumentError
        The models are not on one time base (continuous and discrete, or two sampling
        periods): bring them to one first (c2d, d2c).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> servo = aerocontrol.actuator(20.0, input_names="rudder command", output_names="rudder")
    >>> plant = aerocontrol.aircraft.load("b747-approach").lateral()["r", "rudder"]
    >>> loop = aerocontrol.series(servo, plant)
    >>> loop.input_names, loop.output_names, loop.n_states
    (('rudder command',), ('r',), 5)
    """
    models = _models([sys1, sys2, *systems], "series")
    labels = [f"sys{k + 1}" for k in range(len(models))]
    dt = _time_base(models, labels, "series")
    result = models[0]
    for k in range(1, len(models)):
        second = models[k]
        if second.n_inputs != result.n_outputs:
            raise ShapeError(
                f"series: {labels[k]} has {second.n_inputs} inputs but the model before it has "
                f"{result.n_outputs} outputs"
            )
        result = _series_step(result, second, dt, "series", ", ".join(labels[: k + 1]))
    return result


def _series_step(
    first: StateSpace, second: StateSpace, dt: float | None, function: str, arguments: str
) -> StateSpace:
    """``second`` after ``first``, formed from the parts with their states rescaled by powers
    of two where its products overflow or underflow (:func:`_needs_scaling`,
    :func:`_state_exponents`); beyond the range of doubles under every such scaling, refused
    naming ``arguments``."""
    m1, p1, p2 = first.n_inputs, first.n_outputs, second.n_outputs
    # u2 = y1, z = y2: the connection matrices of _state_exponents.
    K = np.zeros((m1 + p1, p1 + p2))
    K[m1:, :p1] = np.eye(p1)
    E = np.vstack([np.eye(m1), np.zeros((p1, m1))])
    F = np.hstack([np.zeros((p2, p1)), np.eye(p2)])
    G = np.zeros((p2, m1 + p1))
    matrices = _series_matrices(first, second)
    if _needs_scaling([first, second], matrices, K, E, F, G):
        exponents = _state_exponents([first, second], K, E, F, G)
        scaled = _series_matrices(_rescaled(first, exponents[0]), _rescaled(second, exponents[1]))
        matrices = _kept(matrices, scaled)
    _representable(matrices, function, arguments)
    return StateSpace(
        *matrices,
        state_names=first.state_names + second.state_names,
        input_names=first.input_names,
        output_names=second.output_names,
        dt=dt,
    )


def _series_matrices(first: StateSpace, second: StateSpace) -> Matrices:
    """A, B, C, D of ``second`` after ``first`` (non-finite where a product overflows)."""
    n1, n2 = first.n_states, second.n_states
    with np.errstate(over="ignore", invalid="ignore"):
        return (
            np.block([[first.A, np.zeros((n1, n2))], [second.B @ first.C, second.A]]),
            np.vstack([first.B, second.B @ first.D]),
            np.hstack([second.D @ first.C, second.C]),
            second.D @ first.D,
        )


def parallel(sys1: System, sys2: System, *systems: System) -> StateSpace:
    """The sum of models driven by the same inputs: y = y1 + y2 (+ ...).

    With x = (x1, x2): A = diag(A1, A2), B = [[B1], [B2]], C = [C1, C2], D = D1 + D2. The
    names of the inputs and outputs are those of ``sys1``. The same as python-control's
    ``parallel``.

    Parameters
    ----------
    sys1, sys2 : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        Models of the same numbers of inputs and outputs.
    *systems : models
        Further models to add.

    Returns
    -------
    StateSpace
        The sum, with the names of ``sys1``'s inputs and outputs and the states of all.

    Raises
    ------
    ShapeError
        The models differ in their numbers of inputs or outputs.
    NotRealError
        An argument is not a model.
    InvalidArgumentError
        The models are not on one time base (continuous and discrete, or two sampling
        periods): bring them to one first (c2d, d2c).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # A washout is one minus a first-order lag of the same time constant.
    >>> lag = aerocontrol.first_order_lag(2.0, gain=-1.0)
    >>> difference = aerocontrol.parallel(aerocontrol.gain(1.0), lag)
    >>> w = [0.0, 0.5, 10.0]
    >>> g1 = aerocontrol.frequency_response(difference, w).response
    >>> g2 = aerocontrol.frequency_response(aerocontrol.washout(2.0), w).response
    >>> bool(np.allclose(g1, g2, rtol=1e-14, atol=1e-15))
    True
    """
    models = _models([sys1, sys2, *systems], "parallel")
    labels = [f"sys{k + 1}" for k in range(len(models))]
    dt = _time_base(models, labels, "parallel")
    first = models[0]
    for model, label in zip(models[1:], labels[1:], strict=True):
        if (model.n_outputs, model.n_inputs) != (first.n_outputs, first.n_inputs):
            raise ShapeError(
                f"parallel: {label} has {model.n_outputs} outputs and {model.n_inputs} inputs "
                f"but sys1 has {first.n_outputs} and {first.n_inputs}"
            )
    with np.errstate(over="ignore", invalid="ignore"):  # refused by name below
        D = np.sum([m.D for m in models], axis=0)
    matrices = (
        _block_diagonal([m.A for m in models]),
        np.vstack([m.B for m in models]),
        np.hstack([m.C for m in models]),
        D,
    )
    # y = D1 u + D2 u + ...: a sum of feedthroughs beyond the doubles is beyond every state
    # scaling too.
    _representable(matrices, "parallel", ", ".join(labels))
    return StateSpace(
        *matrices,
        state_names=sum((m.state_names for m in models), ()),
        input_names=first.input_names,
        output_names=first.output_names,
        dt=dt,
    )


def append(*systems: System) -> StateSpace:
    """The models side by side, unconnected: inputs, outputs and states stacked in order,
    A, B, C, D block diagonal, the names kept. The same as python-control's ``append``.

    Parameters
    ----------
    *systems : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        One model or more.

    Returns
    -------
    StateSpace
        The block-diagonal model.

    Raises
    ------
    InvalidArgumentError
        No model is given, or the models are not on one time base.
    NotRealError
        An argument is not a model.

    Examples
    --------
    >>> import aerocontrol
    >>> both = aerocontrol.append(
    ...     aerocontrol.actuator(20.0, input_names="rudder command", output_names="rudder"),
    ...     aerocontrol.actuator(15.0, input_names="aileron command", output_names="aileron"),
    ... )
    >>> both.input_names, both.output_names
    (('rudder command', 'aileron command'), ('rudder', 'aileron'))
    """
    if not systems:
        raise InvalidArgumentError("append needs at least one model")
    models = _models(systems, "append")
    dt = _time_base(models, [f"sys{k + 1}" for k in range(len(models))], "append")
    return StateSpace(
        _block_diagonal([m.A for m in models]),
        _block_diagonal([m.B for m in models]),
        _block_diagonal([m.C for m in models]),
        _block_diagonal([m.D for m in models]),
        state_names=sum((m.state_names for m in models), ()),
        input_names=sum((m.input_names for m in models), ()),
        output_names=sum((m.output_names for m in models), ()),
        dt=dt,
    )


def feedback(sys1: System, sys2: System | None = None, sign: float = -1) -> StateSpace:
    """The loop of ``sys1`` (forward) closed through ``sys2`` (return), by position: u1 = r +
    sign·y2, u2 = y1, from the reference r to y1.

    ``sys2`` defaults to unity feedback (y2 = y1, which needs as many outputs as inputs), and
    ``sign`` is -1 (negative feedback) or +1. Eliminating u1 with F = I - sign·D2·D1:

        u1 = F^-1 (r + sign·D2·C1 x1 + sign·C2 x2),

    and the closed loop has the states (x1, x2), the inputs and outputs of ``sys1`` and their
    names. A singular F (an algebraic loop, such as unity positive feedback around a unit
    gain) is refused with SingularMatrixError naming it; a nearly singular one warns
    IllConditionedWarning with its condition number. A loop whose products leave the range
    of doubles is formed in states scaled by powers of two chosen on the closed loop's own
    entries (see the module's documentation). The same as python-control's ``feedback``.

    Parameters
    ----------
    sys1 : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The forward path.
    sys2 : model, optional
        The return path, with as many inputs as ``sys1`` has outputs and as many outputs as it
        has inputs; default unity feedback.
    sign : {-1, +1}, optional
        -1 (default) for negative feedback, +1 for positive.

    Returns
    -------
    StateSpace
        The closed loop from r to y1, states (x1, x2), with ``sys1``'s inputs and outputs.

    Raises
    ------
    SingularMatrixError
        F = I - sign·D2·D1 is singular: an algebraic loop.
    ShapeError
        ``sys2`` does not fit ``sys1``, or unity feedback around a model with more outputs
        than inputs (or fewer).
    InvalidArgumentError
        ``sign`` is not -1 or +1, or the models are not on one time base.
    NotRealError
        An argument is not a model.

    Warns
    -----
    IllConditionedWarning
        F is nearly singular (its condition number is given).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # k/(s + a) in a negative unity loop: one pole at -(a + k).
    >>> closed = aerocontrol.feedback(aerocontrol.tf([3.0], [1.0, 2.0]))
    >>> np.linalg.eigvals(closed.A)
    array([-5.])
    >>> aerocontrol.feedback(aerocontrol.gain(1.0), sign=+1)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aerocontrol.exceptions.SingularMatrixError: feedback: algebraic loop: I - sign·D2·D1 ...
    """
    s = None if isinstance(sign, bool) else real_scalar(sign, "sign")
    if s not in (-1.0, 1.0):
        raise InvalidArgumentError(f"sign must be -1 (negative feedback) or +1, got {sign!r}")
    forward = as_state_space(sys1, "feedback: sys1")
    if sys2 is None:
        if forward.n_inputs != forward.n_outputs:
            raise ShapeError(
                f"feedback: unity feedback needs as many outputs as inputs, but sys1 has "
                f"{forward.n_outputs} outputs and {forward.n_inputs} inputs; give sys2"
            )
        back = StateSpace(
            np.zeros((0, 0)),
            np.zeros((0, forward.n_outputs)),
            np.zeros((forward.n_inputs, 0)),
            np.eye(forward.n_inputs),
            dt=forward.dt,
        )
    else:
        back = as_state_space(sys2, "feedback: sys2")
    dt = _time_base([forward, back], ["sys1", "sys2"], "feedback")
    if back.n_inputs != forward.n_outputs or back.n_outputs != forward.n_inputs:
        raise ShapeError(
            f"feedback: sys2 must have as many inputs as sys1 has outputs ({forward.n_outputs}) "
            f"and as many outputs as sys1 has inputs ({forward.n_inputs}), got "
            f"{back.n_inputs} inputs and {back.n_outputs} outputs"
        )
    return _closed(forward, back, s, dt, "feedback", "sys1, sys2")


def _closed(
    forward: StateSpace,
    back: StateSpace,
    s: float,
    dt: float | None,
    function: str,
    arguments: str,
) -> StateSpace:
    """The loop of :func:`feedback`, formed from the parts with their states rescaled by
    powers of two where its products overflow or underflow (:func:`_needs_scaling`,
    :func:`_state_exponents`); an interconnection beyond the range of doubles is refused
    naming ``arguments``."""
    m1, p1 = forward.n_inputs, forward.n_outputs
    # u1 = w + sign·y2, u2 = y1, z = y1: the connection matrices of _state_exponents.
    K = np.zeros((m1 + p1, p1 + m1))
    K[:m1, p1:] = s * np.eye(m1)
    K[m1:, :p1] = np.eye(p1)
    E = np.vstack([np.eye(m1), np.zeros((p1, m1))])
    F = np.hstack([np.eye(p1), np.zeros((p1, m1))])
    G = np.zeros((p1, m1 + p1))
    matrices = _loop_matrices(forward, back, s, function)
    if _needs_scaling([forward, back], matrices, K, E, F, G):
        exponents = _state_exponents([forward, back], K, E, F, G)
        first, second = _rescaled(forward, exponents[0]), _rescaled(back, exponents[1])
        matrices = _kept(matrices, _loop_matrices(first, second, s, function))
    _representable(matrices, function, arguments)
    return StateSpace(
        *matrices,
        state_names=forward.state_names + back.state_names,
        input_names=forward.input_names,
        output_names=forward.output_names,
        dt=dt,
    )


def _loop_matrices(first: StateSpace, second: StateSpace, s: float, function: str) -> Matrices:
    """A, B, C, D of :func:`feedback` (non-finite where a product overflows)."""
    m1 = first.n_inputs
    A1, B1, C1, D1 = first.A, first.B, first.C, first.D
    A2, B2, C2, D2 = second.A, second.B, second.C, second.D
    n1, n2 = first.n_states, second.n_states
    with np.errstate(over="ignore", invalid="ignore"):
        # u1 = U_x x + U_r r, from one solve with F = I - sign·D2·D1.
        loop_state = s * np.hstack([D2 @ C1, C2])
        loop = s * D2 @ D1
    solved = _solve_loop(loop, np.hstack([loop_state, np.eye(m1)]), "I - sign·D2·D1", function)
    with np.errstate(over="ignore", invalid="ignore"):
        U_x, U_r = solved[:, : n1 + n2], solved[:, n1 + n2 :]
        B_u = np.vstack([B1, B2 @ D1])
        A = np.block([[A1, np.zeros((n1, n2))], [B2 @ C1, A2]]) + B_u @ U_x
        C = np.hstack([C1, np.zeros((C1.shape[0], n2))]) + D1 @ U_x
        return (A, B_u @ U_r, C, D1 @ U_r)


# ----- interconnection by name ------------------------------------------------------------------


def summing_junction(
    inputs: str | Sequence[str], output: str, *, dt: float | None = None
) -> StateSpace:
    """A static comparator: ``output`` = the sum of ``inputs``, a name written ``"-name"``
    entering with a minus sign (as python-control's ``summing_junction``). The inputs are named
    without their signs.

    Parameters
    ----------
    inputs : str or sequence of str
        The names of the summed signals, a leading "-" for those subtracted; at least one.
    output : str
        The name of the sum.
    dt : float, optional
        The sampling period in seconds of a discrete model (default None).

    Returns
    -------
    StateSpace
        A model with no states and D a row of ±1.

    Raises
    ------
    InvalidArgumentError
        No input is given, ``output`` is not a string, or a bad ``dt``.

    Examples
    --------
    >>> import aerocontrol
    >>> error = aerocontrol.summing_junction(["r command", "-r washed"], "e")
    >>> error.input_names, error.output_names, error.D
    (('r command', 'r washed'), ('e',), array([[ 1., -1.]]))
    """
    specs = name_sequence(inputs, "inputs")
    if not specs:
        raise InvalidArgumentError("summing_junction needs at least one input")
    names, signs = [], []
    for spec in specs:
        if not isinstance(spec, str) or spec in ("", "-"):
            raise InvalidArgumentError(f"inputs must be signal names, got {spec!r}")
        negative = spec.startswith("-")
        names.append(spec[1:] if negative else spec)
        signs.append(-1.0 if negative else 1.0)
    if not isinstance(output, str):
        raise InvalidArgumentError(f"output must be a signal name, got {output!r}")
    return StateSpace(
        np.zeros((0, 0)),
        np.zeros((0, len(names))),
        np.zeros((1, 0)),
        np.array([signs]),
        input_names=names,
        output_names=[output],
        dt=dt,
    )


def _source(spec: object, where: str) -> tuple[str, float]:
    if isinstance(spec, str):
        if spec.startswith("-") and len(spec) > 1:
            return spec[1:], -1.0
        return spec, 1.0
    if isinstance(spec, tuple) and len(spec) == 2 and isinstance(spec[0], str):
        return spec[0], _finite(spec[1], f"the gain of {spec[0]!r} in {where}")
    raise InvalidArgumentError(
        f"{where}: a signal must be 'name', '-name' or ('name', gain), got {spec!r}"
    )


def _name_list(value: str | Sequence[str], argument: str, unique: bool = True) -> list[str]:
    """A name or a sequence of names as a list, each a string (and, if ``unique``, once)."""
    try:
        names = [value] if isinstance(value, str) else list(value)
    except TypeError:
        names = [value]  # type: ignore[list-item]  # refused just below, by name
    for name in names:
        if not isinstance(name, str):
            raise InvalidArgumentError(
                f"{argument} must be a name or a sequence of names, got {name!r}"
            )
    duplicates = sorted({name for name in names if names.count(name) > 1})
    if unique and duplicates:
        raise InvalidArgumentError(f"{argument} names {duplicates[0]!r} more than once")
    return names


def connect(
    systems: Sequence[System],
    connections: Sequence[Sequence[Source]] | None = None,
    inputs: str | Sequence[str] | None = None,
    outputs: str | Sequence[str] | None = None,
) -> StateSpace:
    """The block diagram of ``systems`` wired by signal name, as one model (python-control's
    ``interconnect`` for linear systems, with signals named as aerocontrol names them).

    Signals are names: every input of the blocks with a given name receives the same signal,
    and outputs of one name are summed.

    Parameters
    ----------
    systems : sequence of models
        The blocks, with named inputs and outputs (constructors take ``input_names`` and
        ``output_names``; ``sys[outputs, inputs]`` selects signals of a plant).
    connections : sequence of sequences, optional
        None (the default): every block input is fed by the sum of the block outputs of the
        same name, as python-control does when it is given no connections. Otherwise only the
        connections listed are made, each ``[input, source, source, ...]``: the block inputs
        named ``input`` receive the sum of the sources, each a block output name (outputs of
        that name summed) or an external input name, written ``"name"``, ``"-name"`` (times
        -1) or ``("name", gain)``.
    inputs : str or sequence of str, optional
        The external inputs, by name: each is added to the block inputs of its name (and may
        be a source of a connection). None: every block input that nothing feeds, in order.
        When given, a block input that nothing feeds is an error.
    outputs : str or sequence of str, optional
        The external outputs: a block output name (outputs of that name summed), or else a
        block input name (the signal entering it) or an external input; ``"-name"`` negates.
        None: every block output name, in order.

    Returns
    -------
    StateSpace
        The states of every block in order (with their names), the external inputs and
        outputs with their names, and the common ``dt``.

    Raises
    ------
    InvalidArgumentError
        A name that matches no signal, a block input that nothing feeds (with ``inputs``
        given), an external input that feeds nothing, a name listed twice, time bases that
        differ.
    SingularMatrixError
        An algebraic loop: I - K·D singular (see the module's documentation).

    Examples
    --------
    A yaw damper: the yaw rate, washed out, drives the rudder through its actuator.

    >>> import numpy as np, aerocontrol
    >>> plant = aerocontrol.aircraft.load("b747-approach").lateral()
    >>> damper = aerocontrol.connect(
    ...     [
    ...         plant["r", "rudder"],
    ...         aerocontrol.washout(2.0, input_names="r", output_names="r washed"),
    ...         aerocontrol.gain(1.5, input_names="r washed", output_names="u"),
    ...         aerocontrol.summing_junction(["rudder command", "u"], "servo input"),
    ...         aerocontrol.actuator(20.0, input_names="servo input", output_names="rudder"),
    ...     ],
    ...     inputs="rudder command",
    ...     outputs=["r", "rudder"],
    ... )
    >>> damper.state_names
    ('beta', 'p', 'phi', 'r', 'r lagged', 'rudder')
    >>> damper.input_names, damper.output_names
    (('rudder command',), ('r', 'rudder'))

    The same loop with explicit connections and the gain written into them:

    >>> same = aerocontrol.connect(
    ...     [
    ...         plant["r", "rudder"],
    ...         aerocontrol.washout(2.0, input_names="r", output_names="r washed"),
    ...         aerocontrol.actuator(20.0, input_names="servo input", output_names="rudder"),
    ...     ],
    ...     [
    ...         ["r", "r"],
    ...         ["servo input", "rudder command", ("r washed", 1.5)],
    ...         ["rudder", "rudder"],
    ...     ],
    ...     inputs="rudder command",
    ...     outputs=["r", "rudder"],
    ... )
    >>> w = np.linspace(0.1, 3.0, 5)
    >>> g1 = aerocontrol.frequency_response(damper, w).response
    >>> g2 = aerocontrol.frequency_response(same, w).response
    >>> bool(np.allclose(g1, g2, rtol=1e-12, atol=0.0))
    True
    """
    if isinstance(systems, (str, bytes)) or not isinstance(systems, Sequence) or not systems:
        raise InvalidArgumentError("systems must be a non-empty list of models")
    models = [as_state_space(s, f"connect: systems[{k}]") for k, s in enumerate(systems)]
    labels = [f"systems[{k}]" for k in range(len(models))]
    dt = _time_base(models, labels, "connect")
    stacked = append(*models)
    A, B, C, D = stacked.A, stacked.B, stacked.C, stacked.D
    block_inputs, block_outputs = stacked.input_names, stacked.output_names
    mu, py = len(block_inputs), len(block_outputs)

    def where(names: Sequence[str], name: str) -> list[int]:
        return [i for i, n in enumerate(names) if n == name]

    # u = K y + E w: first the internal feeds, in columns of y and of the named sources.
    K = np.zeros((mu, py))
    external: list[str] = [] if inputs is None else _name_list(inputs, "inputs")
    explicit_sources: dict[int, list[tuple[int, float]]] = {}  # input row -> (w index, gain)
    fed = np.zeros(mu, dtype=bool)
    if connections is None:
        for j, name in enumerate(block_inputs):
            sources = where(block_outputs, name)
            K[j, sources] = 1.0
            fed[j] = bool(sources)
    else:
        if isinstance(connections, str) or not isinstance(connections, Sequence):
            raise InvalidArgumentError(
                "connections must be a list of [input, source, ...] lists, or None"
            )
        seen: set[str] = set()
        for k, connection in enumerate(connections):
            label = f"connections[{k}]"
            if isinstance(connection, str) or not isinstance(connection, Sequence):
                raise InvalidArgumentError(
                    f"{label} must be a list [input, source, ...], got {connection!r}"
                )
            if len(connection) < 2 or not isinstance(connection[0], str):
                raise InvalidArgumentError(
                    f"{label} must be [input, source, ...]: an input name and at least one "
                    f"source, got {connection!r}"
                )
            destination = connection[0]
            rows = where(block_inputs, destination)
            if not rows:
                raise InvalidArgumentError(
                    f"{label}: no block has an input named {destination!r}; the inputs are "
                    + ", ".join(repr(n) for n in dict.fromkeys(block_inputs))
                )
            if destination in seen:
                raise InvalidArgumentError(
                    f"{label}: the input {destination!r} is fed by an earlier connection too; "
                    "list all its sources in one"
                )
            seen.add(destination)
            for spec in connection[1:]:
                name, factor = _source(spec, label)
                columns = where(block_outputs, name)
                if columns and name in external:
                    raise InvalidArgumentError(
                        f"{label}: {name!r} is both a block output and an external input; "
                        "rename one"
                    )
                if columns:
                    for j in rows:
                        K[j, columns] += factor
                elif name in external:
                    for j in rows:
                        explicit_sources.setdefault(j, []).append((external.index(name), factor))
                else:
                    raise InvalidArgumentError(
                        f"{label}: no block output and no external input is named {name!r}"
                    )
            fed[rows] = True

    if inputs is None:
        external = list(dict.fromkeys(n for j, n in enumerate(block_inputs) if not fed[j]))
    E = np.zeros((mu, len(external)))
    for row, entries in explicit_sources.items():
        for column, weight in entries:
            E[row, column] += weight
    for index, name in enumerate(external):
        rows = where(block_inputs, name)
        E[rows, index] += 1.0
        fed[rows] = True
        if not rows and not any(index == i for e in explicit_sources.values() for i, _ in e):
            raise InvalidArgumentError(
                f"connect: the external input {name!r} feeds nothing: no block input has its "
                "name" + ("" if connections is None else " and no connection uses it")
            )
    if not np.all(fed):
        unfed = list(dict.fromkeys(n for j, n in enumerate(block_inputs) if not fed[j]))
        raise InvalidArgumentError(
            "connect: nothing feeds the block input(s) "
            + ", ".join(repr(n) for n in unfed)
            + "; connect them, list them in inputs, or leave inputs=None to make them external"
        )

    # z = F y + G u + H w.
    wanted = (
        list(dict.fromkeys(block_outputs)) if outputs is None else _name_list(outputs, "outputs")
    )
    F = np.zeros((len(wanted), py))
    G = np.zeros((len(wanted), mu))
    H = np.zeros((len(wanted), len(external)))
    for row, spec in enumerate(wanted):
        name, factor = (spec[1:], -1.0) if spec.startswith("-") and len(spec) > 1 else (spec, 1.0)
        if where(block_outputs, name):
            F[row, where(block_outputs, name)] = factor
        elif where(block_inputs, name):
            G[row, where(block_inputs, name)[0]] = factor
        elif name in external:
            H[row, external.index(name)] = factor
        else:
            raise InvalidArgumentError(
                f"connect: the output {spec!r} names no block output, block input or external input"
            )

    def formed(A: FloatArray, B: FloatArray, C: FloatArray) -> Matrices:
        n = A.shape[0]
        with np.errstate(over="ignore", invalid="ignore"):
            loop, right = K @ D, np.hstack([K @ C, E])
        solved = _solve_loop(loop, right, "I - K·D", "connect")
        with np.errstate(over="ignore", invalid="ignore"):
            U_x, U_w = solved[:, :n], solved[:, n:]
            return (
                A + B @ U_x,
                B @ U_w,
                F @ (C + D @ U_x) + G @ U_x,
                F @ D @ U_w + G @ U_w + H,
            )

    matrices = formed(A, B, C)
    if _needs_scaling(models, matrices, K, E, F, G):
        exponents = _state_exponents(models, K, E, F, G)
        rescaled = append(*(_rescaled(m, e) for m, e in zip(models, exponents, strict=True)))
        matrices = _kept(matrices, formed(rescaled.A, rescaled.B, rescaled.C))
    _representable(matrices, "connect", "systems")
    result = StateSpace(
        *matrices,
        state_names=stacked.state_names,
        input_names=external,
        output_names=wanted,
        dt=dt,
    )
    return result


# ----- realisations -----------------------------------------------------------------------------


def _balance(A: FloatArray, B: FloatArray, C: FloatArray) -> tuple[FloatArray, ...]:
    """A diagonal similarity by powers of two (exact in floating point) that makes each state's
    row of [A B] and column of [A; C] of similar size, as SLICOT's TB01ID does: the
    companion forms of polynomial coefficients spread over many orders of magnitude."""
    A, B, C = A.copy(), B.copy(), C.copy()
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(B)) and np.all(np.isfinite(C))):
        return A, B, C  # refused by the caller (_realisable)
    n = A.shape[0]
    for _ in range(100):
        changed = False
        for i in range(n):
            off_column = np.concatenate([np.delete(A[:, i], i), C[:, i]])
            off_row = np.concatenate([np.delete(A[i, :], i), B[i, :]])
            with np.errstate(over="ignore"):  # sums near 1e308: their largest terms instead
                column, row = float(np.abs(off_column).sum()), float(np.abs(off_row).sum())
            if not (math.isfinite(column) and math.isfinite(row)):
                column, row = float(np.abs(off_column).max()), float(np.abs(off_row).max())
            if column == 0.0 or row == 0.0:
                continue
            # A difference of logarithms: row/column itself overflows (1e308/0.0158).
            exponent = int(np.round(0.5 * (math.log2(row) - math.log2(column))))
            # Never so far that an entry of the column (times 2^exponent) or of the row
            # (divided by it) leaves the normal range: a tiny a0 beside a large b0 in a row
            # was divided into 0, which moves a pole.
            column_sizes = _scaling.log2_sizes(off_column[off_column != 0.0])
            row_sizes = _scaling.log2_sizes(off_row[off_row != 0.0])
            lowest = math.ceil(
                max(SMALLEST_EXPONENT - column_sizes.min(), row_sizes.max() - 1023.0)
            )
            highest = math.floor(
                min(1023.0 - column_sizes.max(), row_sizes.min() - SMALLEST_EXPONENT)
            )
            exponent = min(max(exponent, min(lowest, 0)), max(highest, 0))
            if exponent == 0:
                continue
            # ldexp, not 2.0**exponent (an OverflowError beyond 2^1023), and the diagonal
            # kept: A_ii times then divided by 2^exponent overflowed for A_ii of 1e308.
            diagonal = A[i, i]
            with np.errstate(over="ignore", under="ignore"):
                A[:, i] = np.ldexp(A[:, i], exponent)
                C[:, i] = np.ldexp(C[:, i], exponent)
                A[i, :] = np.ldexp(A[i, :], -exponent)
                B[i, :] = np.ldexp(B[i, :], -exponent)
            A[i, i] = diagonal
            changed = True
        if not changed:
            break
    return A, B, C


def _observable_form(
    numerator: FloatArray, denominator: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The observable canonical form of numerator/denominator (coefficients from the highest
    power, denominator monic, numerator of the same length), balanced.

    With den = s^n + a1 s^(n-1) + ... + an and num = b0 s^n + ... + bn, the states in the
    order that makes A upper Hessenberg (ones on the subdiagonal, -an ... -a1 in the last
    column), B = (bn - b0 an, ..., b1 - b0 a1), C = (0, ..., 0, 1), D = b0. An A already in
    Hessenberg form is kept as it is by the frequency response's own Hessenberg reduction, so
    the response is computed from the coefficients without mixing them: at high frequency,
    where the response of a model of high relative degree is tiny, this keeps its relative
    accuracy (a full first column lost 5 digits at 50 times the fastest pole of a fifth-order
    lag)."""
    n = len(denominator) - 1
    a = denominator[1:]
    D = np.array([[numerator[0]]])
    A = np.zeros((n, n))
    A[np.arange(1, n), np.arange(n - 1)] = 1.0
    with np.errstate(over="ignore", invalid="ignore"):  # refused by the callers
        B = (numerator[1:] - numerator[0] * a)[::-1].reshape(n, 1)
    C = np.zeros((1, n))
    if n:
        A[:, -1] = -a[::-1]
        C[0, -1] = 1.0
    A, B, C = _balance(A, B, C)
    return A, B, C, D


def _coefficients(value: object, name: str) -> FloatArray:
    array = real_array(value, name)
    if array.ndim == 0:
        array = array.reshape(1)
    if array.ndim != 1:
        raise ShapeError(
            f"{name} must be a 1-D array of polynomial coefficients (highest power first), "
            f"got shape {array.shape}"
        )
    check_finite(array, name)
    nonzero = np.flatnonzero(array)
    return array[nonzero[0] :] if nonzero.size else np.zeros(0)


def tf(
    num: ArrayLike,
    den: ArrayLike,
    *,
    dt: float | None = None,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """The single-input, single-output model num(s)/den(s) (num(z)/den(z) with ``dt``), as a
    state-space model.

    The coefficients come highest power first, as numpy's and python-control's (leading zeros
    are dropped). The realisation is the observable canonical form of the monic denominator,
    balanced by a diagonal similarity in powers of two; its order is the degree of ``den``:
    a factor common to num and den is kept, as a mode that the input does not reach. An
    improper num/den (degree of num above that of den) has no state-space model and is
    refused.

    Parameters
    ----------
    num : array_like (k,)
        The numerator's coefficients, highest power first; degree at most that of ``den``.
    den : array_like (l,)
        The denominator's coefficients, highest power first, not all zero.
    dt : float, optional
        The sampling period in seconds of a discrete model (default None: continuous; 0 is
        continuous too).
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The model, of order deg(den), one input and one output.

    Raises
    ------
    InvalidArgumentError
        num/den is improper, den is zero, ``dt`` is negative or not finite, or a name is not a
        string.
    ShapeError
        num or den is not 1-D, or a sequence of names has the wrong length.
    NonFiniteError, NotRealError
        A coefficient is NaN or infinite, or complex.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> g = aerocontrol.tf([2.0, 1.0], [1.0, 3.0, 2.0], input_names="e", output_names="u")
    >>> g.n_states, g.input_names, g.output_names
    (2, ('e',), ('u',))
    >>> np.sort(np.linalg.eigvals(g.A))
    array([-2., -1.])
    >>> aerocontrol.dc_gain(g)
    array([[0.5]])
    >>> aerocontrol.tf([1.0, 0.0, 0.0], [1.0, 1.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aerocontrol.exceptions.InvalidArgumentError: tf: num/den is improper ...
    """
    numerator = _coefficients(num, "num")
    denominator = _coefficients(den, "den")
    if denominator.size == 0:
        raise InvalidArgumentError("den must have a nonzero coefficient")
    if numerator.size > denominator.size:
        raise InvalidArgumentError(
            f"tf: num/den is improper (num of degree {numerator.size - 1} over den of degree "
            f"{denominator.size - 1}): it has no state-space model; add poles (a first-order "
            "lag) to make it proper"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        numerator = np.concatenate([np.zeros(denominator.size - numerator.size), numerator])
        leading = denominator[0]
        monic_den, monic_num = denominator / leading, numerator / leading
        A, B, C, D = _observable_form(monic_num, monic_den)
    # The coefficients divided by den's leading one are those of the realisation: beyond the
    # doubles (den of 1e-300 s + 1e200), no state scaling of the companion form helps.
    _realisable(
        (A, B, C, D),
        "tf",
        "den" if not np.all(np.isfinite(monic_den)) else "num",
        f"num and den divided by den's leading coefficient {leading:g} exceed the doubles "
        "(scale the units of time or of the signals)",
    )
    return _model(
        A,
        B,
        C,
        D,
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states="{output} x{k}",
        dt=dt,
    )


def _roots(value: object, name: str) -> np.ndarray:
    try:
        array = np.asarray(value)
    except ValueError as error:
        raise ShapeError(f"{name} must be a 1-D array of numbers: {error}") from None
    if array.dtype.kind not in "biufc":
        raise NotRealError(f"{name} must be an array of numbers, got dtype {array.dtype}")
    array = array.astype(np.complex128).reshape(-1) if array.ndim == 0 else array
    if array.ndim != 1:
        raise ShapeError(f"{name} must be a 1-D array of roots, got shape {array.shape}")
    array = array.astype(np.complex128)
    check_finite(np.concatenate([array.real, array.imag]), name)
    return array


@dataclass(frozen=True)
class _Factor:
    """A real monic factor s - root, or s² + linear·s + constant of a pair of roots, the
    constant held as mantissa·2^exponent: the product of two roots of 1e200 (1e400) is kept
    to the rounding the doubles would give it, were their range wide enough."""

    degree: int
    linear: float
    """The coefficient of s^(degree - 1): -root, -(r1 + r2) or -2 Re r."""
    mantissa: float = 0.0
    exponent: int = 0
    roots: tuple[float, float] | None = None
    """The two real roots of a quadratic formed from them, else None."""

    def log2_constant(self) -> float:
        """log2 of the constant's modulus (-inf for 0)."""
        return math.log2(abs(self.mantissa)) + self.exponent if self.mantissa else -math.inf

    def constant_over(self, power: int) -> float:
        """constant / 2^power (inf where that overflows)."""
        with np.errstate(over="ignore", under="ignore"):
            return float(np.ldexp(self.mantissa, self.exponent - power))


def _product(r1: float, r2: float) -> _Factor:
    """(s - r1)(s - r2) of two real roots: r1 r2 from the roots' mantissas."""
    (m1, e1), (m2, e2) = np.frexp(r1), np.frexp(r2)
    with np.errstate(over="ignore"):  # r1 + r2 beyond the doubles: refused by the caller
        linear = -(r1 + r2)
    return _Factor(2, float(linear), float(m1 * m2), int(e1) + int(e2), (r1, r2))


def _conjugate_pair(r: complex) -> _Factor:
    """(s - r)(s - conj r) = s² - 2 Re r s + |r|²: |r|² = hypot(Re r, Im r)² from the
    hypotenuse of the parts divided by a power of two, so that it is never squared beyond the
    doubles (roots beyond 1e154 in modulus)."""
    _, scale = np.frexp(max(abs(r.real), abs(r.imag)))
    modulus = math.hypot(math.ldexp(r.real, -int(scale)), math.ldexp(r.imag, -int(scale)))
    with np.errstate(over="ignore"):  # 2 Re r beyond the doubles: refused by the caller
        linear = -2.0 * np.float64(r.real)
    return _Factor(2, float(linear), modulus * modulus, 2 * int(scale))


def _real_factors(roots: np.ndarray, name: str) -> list[_Factor]:
    """The roots as real monic factors: one quadratic per complex pair (each complex root
    must come with its conjugate, to 1e-10 relative), then quadratics of two real roots, then
    at most one linear factor."""
    real = sorted(float(r.real) for r in roots if r.imag == 0.0)
    upper = sorted((r for r in roots if r.imag > 0.0), key=lambda r: (r.real, r.imag))
    lower = [r for r in roots if r.imag < 0.0]
    factors: list[_Factor] = []
    for r in upper:
        _pair(r, lower, name)
        factors.append(_conjugate_pair(complex(r)))
    for k in range(0, len(real) - 1, 2):
        factors.append(_product(real[k], real[k + 1]))
    if lower:
        raise InvalidArgumentError(
            f"{name} has the complex root {complex(lower[0])} without its conjugate: a real "
            "model has complex roots in conjugate pairs"
        )
    if len(real) % 2:
        factors.append(_Factor(1, -real[-1]))
    return factors


def _pair(r: complex, lower: list[complex], name: str) -> None:
    """Takes the conjugate of r from ``lower``, or refuses r as unpaired."""
    # Compared divided by a power of two of r's size, so that |r| does not overflow.
    _, power = np.frexp(max(abs(r.real), abs(r.imag)))
    with np.errstate(over="ignore", invalid="ignore"):  # beyond the doubles: not a match
        given = np.ldexp([r.real, -r.imag], -int(power))
        others = [np.ldexp([q.real, q.imag], -int(power)) for q in lower]
        limit = 1e-10 * math.hypot(*given)
        match = [k for k, q in enumerate(others) if math.hypot(*(q - given)) <= limit]
    if not match:
        raise InvalidArgumentError(
            f"{name} has the complex root {complex(r)} without its conjugate: a real model "
            "has complex roots in conjugate pairs"
        )
    lower.pop(match[0])


def _split(numerator: _Factor | None, denominator: _Factor) -> tuple[float, float] | None:
    """(p, q) where a quadratic of two real poles more than 2^26 apart in size (the smaller
    lost to half its digits or more in the eigenvalues of A) holds one real zero z no
    smaller than the smaller pole: the section is then (s - z)/(s - p) and 1/(s - q), p the
    larger pole not beyond z, whose p - z keeps z to its own rounding. None otherwise (a zero
    smaller than both stays in the strictly proper quadratic, which holds it exactly)."""
    if numerator is None or numerator.degree != 1 or denominator.roots is None:
        return None
    small, large = sorted(denominator.roots, key=abs)
    if not (abs(small) * 2.0**26 < abs(large) and abs(numerator.linear) >= abs(small)):
        return None
    return (large, small) if abs(numerator.linear) >= abs(large) else (small, large)


def _sections(zeros: np.ndarray, poles: np.ndarray) -> list[tuple[_Factor | None, _Factor]]:
    """The (numerator, denominator) of each section of :func:`zpk`'s cascade: quadratic zero
    factors (complex pairs, pairs of real zeros) with the quadratic pole factors (complex
    pairs, then pairs of real poles adjacent in value), a linear zero factor with a quadratic
    left over, else with the linear pole factor; and a pair of real poles that no zero needs
    as two first-order sections, as is a pair far apart whose zero allows it (:func:`_split`).

    A quadratic of two real poles far apart in size loses the smaller to the eigenvalues of
    its A (their backward error is u ||A||): the poles -1 and -1e20 came back as 0 and -1e20,
    a pole at the origin for a stable one, silently. The first-order sections make A
    triangular, its eigenvalues the poles given. Pairs that hold a zero smaller than both
    poles, or two zeros, are kept: the strictly proper quadratic holds a zero much smaller
    than its poles exactly (in B = (n0, n1)), where a first-order (s - z)/(s - p) forms
    p - z, which keeps z only to the rounding of p, and the realisation's transfer function
    would lose it (of 600 random models with roots across 10^±20, 106 have better poles
    than with every real pair a quadratic, and none a worse pole or response).
    """
    sections: list[tuple[_Factor | None, _Factor]] = []
    pole_factors = _real_factors(poles, "p")
    zero_factors = _real_factors(zeros, "z")
    # Quadratic zero factors go with quadratic pole factors; a linear zero factor with a
    # quadratic one left over, else with the linear pole factor (there is one when the
    # quadratics are used up, since there are no more zeros than poles).
    numerators: list[_Factor | None] = [None for _ in pole_factors]
    quadratic = [i for i, f in enumerate(pole_factors) if f.degree == 2]
    linear = [i for i, f in enumerate(pole_factors) if f.degree == 1]
    for f in (f for f in zero_factors if f.degree == 2):
        numerators[quadratic.pop(0)] = f
    for f in (f for f in zero_factors if f.degree == 1):
        numerators[(quadratic or linear).pop(0)] = f
    for numerator, denominator in zip(numerators, pole_factors, strict=True):
        if numerator is None and denominator.roots is not None:
            sections.extend((None, _Factor(1, -r)) for r in denominator.roots)
        elif (split := _split(numerator, denominator)) is not None:
            near, far = split
            sections.extend([(numerator, _Factor(1, -near)), (None, _Factor(1, -far))])
        else:
            sections.append((numerator, denominator))
    return sections


def _section(numerator: _Factor | None, denominator: _Factor, argument: str) -> Matrices:
    """numerator/denominator (numerator 1 for None) in the observable form of
    :func:`_observable_form`, with its first state scaled by a power of two t chosen so that
    no coefficient is formed beyond the doubles; balanced.

    Of den = s² + a1 s + a0 and num = n2 s² + n1 s + n0 the observable form is
    A = [[0, -a0], [1, -a1]], B = (n0 - n2 a0, n1 - n2 a1), C = (0, 1), D = n2; the scaling
    makes it A = [[0, -a0/t], [t, -a1]], B = ((n0 - n2 a0)/t, n1 - n2 a1), with a0/t and n0/t
    formed from the constants' mantissas, t about the square root of the larger of |a0|,
    |n0|: roots of 1e200 give entries of 1e200, never their product 1e400. A first-order
    section (s - z)/(s - p) is A = p, B = p - z, C = 1, D = 1 (B = C = 1, D = 0 without a
    zero). Where no t keeps t, a0/t and (n0 - n2 a0)/t within the doubles, InvalidArgumentError
    names ``argument``."""
    if denominator.degree == 1:
        A = np.array([[-denominator.linear]])
        if numerator is None:
            B, D = np.array([[1.0]]), np.array([[0.0]])
        else:
            with np.errstate(over="ignore"):  # refused by the caller
                B = np.array([[numerator.linear - denominator.linear]])
            D = np.array([[1.0]])
        A, B, C = _balance(A, B, np.array([[1.0]]))
        return A, B, C, D
    n2 = 1.0 if numerator is not None and numerator.degree == 2 else 0.0
    n1 = 0.0 if numerator is None else (1.0 if numerator.degree == 1 else numerator.linear)
    size_a0 = denominator.log2_constant()
    if numerator is None:
        size_n0 = 0.0
    elif numerator.degree == 1:
        size_n0 = math.log2(abs(numerator.linear)) if numerator.linear else -math.inf
    else:
        size_n0 = numerator.log2_constant()
    largest = max(size_a0, size_n0)
    power = 0
    if math.isfinite(largest):
        # t = 2^power, within what keeps t and (n0 - n2 a0)/t below the overflow threshold
        # and t and a0/t above the underflow threshold.
        lowest = max(math.ceil(largest + 1.0 - 1023.0), -1022)
        highest = 1023 if math.isinf(size_a0) else min(1023, math.floor(size_a0 + 1022.0))
        if lowest > highest:
            why = (
                "its roots are beyond about 6e307 in modulus (2^1022.5), the largest that its "
                "scaled coefficients hold (scale the units of time)"
                if largest > 2045.0
                else "its zeros and poles are too far apart in size (the products of its "
                "zeros and of its poles more than 2^2045 apart)"
            )
            error = InvalidArgumentError(
                f"zpk: a second-order section has no realisation in doubles: {why}"
            )
            error.argument = argument
            raise error
        power = min(max(round(largest / 2), lowest), highest)
    with np.errstate(over="ignore", under="ignore"):  # overflow refused by the caller
        t, n0 = float(np.ldexp(1.0, power)), float(np.ldexp(1.0, -power))
        if numerator is not None and numerator.degree == 1:
            n0 = float(np.ldexp(numerator.linear, -power))
        elif numerator is not None:
            n0 = numerator.constant_over(power)
        a0 = denominator.constant_over(power)
    with np.errstate(over="ignore", invalid="ignore"):  # refused by the caller
        A = np.array([[0.0, -a0], [t, -denominator.linear]])
        B = np.array([[n0 - n2 * a0], [n1 - n2 * denominator.linear]])
    C = np.array([[0.0, 1.0]])
    A, B, C = _balance(A, B, C)
    return A, B, C, np.array([[n2]])


def zpk(
    z: ArrayLike,
    p: ArrayLike,
    k: float,
    *,
    dt: float | None = None,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """The single-input, single-output model k·Π(s - z_i)/Π(s - p_i) (in z with ``dt``), as
    a state-space model.

    Complex zeros and poles come in conjugate pairs. The model is a cascade of first- and
    second-order sections (each complex pole pair, or pair of real poles, with up to two
    zeros; a real pole that no zero needs in a quadratic is a section of its own, so that the
    eigenvalues of A are the poles given), each in balanced observable form, so that no
    polynomial of high degree is ever formed. More zeros than poles (an improper model) is
    refused.

    No coefficient of a section is formed as the product of two roots: the constant r1 r2 (or
    abs(r)²) is kept as a mantissa and a power of two and enters the realisation divided by a
    power of two t near its square root (``_section``), so that roots anywhere up to about
    6e307 in modulus, and down to the smallest doubles, are realised, and sections of very
    different sizes are chained in states scaled by powers of two (as :func:`series`). A
    section beyond that (roots of 1e308, or zeros and poles whose products are more than
    2^2045 apart) is refused with InvalidArgumentError naming ``z`` or ``p``.

    Parameters
    ----------
    z : array_like (q,)
        The zeros; complex ones in conjugate pairs; at most as many as the poles.
    p : array_like (n,)
        The poles; complex ones in conjugate pairs.
    k : float
        The gain (of the highest power of s in the numerator).
    dt : float, optional
        The sampling period in seconds of a discrete model (default None: continuous).
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The model, of order len(p), one input and one output.

    Raises
    ------
    InvalidArgumentError
        More zeros than poles, a complex root without its conjugate, a section beyond the
        range of doubles (naming ``z`` or ``p``), a bad ``dt``, or a name that is not a
        string (or a sequence of them).
    NonFiniteError, NotRealError
        A root or the gain is NaN or infinite, or the gain is complex.
    ShapeError
        A sequence of names of the wrong length.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # A yaw damper's filter: washout zero at 0, poles of the washout and of a lag.
    >>> g = aerocontrol.zpk([0.0], [-0.5, -10.0], 10.0)
    >>> np.sort(np.linalg.eigvals(g.A).real)
    array([-10. ,  -0.5])
    >>> # A lightly damped pair of 1e200 rad/s: |p|^2 = 2e400 is beyond the doubles, the poles
    >>> # are not.
    >>> fast = aerocontrol.zpk([], [-1e198 + 1e200j, -1e198 - 1e200j], 1e300)
    >>> np.sort_complex(np.linalg.eigvals(fast.A))
    array([-1.e+198-1.e+200j, -1.e+198+1.e+200j])
    >>> aerocontrol.zpk([1 + 2j], [-1.0, -2.0], 1.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    aerocontrol.exceptions.InvalidArgumentError: z has the complex root (1+2j) without ...
    """
    zeros = _roots(z, "z")
    poles = _roots(p, "p")
    factor = _finite(k, "k")
    if zeros.size > poles.size:
        raise InvalidArgumentError(
            f"zpk: {zeros.size} zeros over {poles.size} poles is improper: it has no state-space "
            "model; add poles to make it proper"
        )
    sections = _sections(zeros, poles)
    n = poles.size
    # The argument to blame for a section beyond the doubles: the larger roots.
    with np.errstate(over="ignore"):
        largest_zero = np.max(np.abs(zeros), initial=0.0)
        larger = "z" if largest_zero > np.max(np.abs(poles), initial=0.0) else "p"
    chain: StateSpace | None = None
    for numerator, denominator in sections:
        section = _section(numerator, denominator, larger)
        _realisable(
            section,
            "zpk",
            larger,
            f"{larger} has roots too large for a second-order section of them (beyond about "
            "1e307: scale the units of time)",
        )
        model = StateSpace(*section)
        # Sections beyond one another's range are formed in states scaled by powers of two.
        chain = model if chain is None else _series_step(chain, model, None, "zpk", "p, z")
    if chain is None:
        A, B, C, D = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[1.0]])
    else:
        # The last section's states first: A is then upper Hessenberg (see _observable_form).
        blocks = np.cumsum([0] + [denominator.degree for _, denominator in sections])
        order = np.concatenate(
            [np.arange(blocks[i], blocks[i + 1]) for i in reversed(range(len(sections)))]
        )
        A, B, C, D = chain.A[np.ix_(order, order)], chain.B[order], chain.C[:, order], chain.D
    with np.errstate(over="ignore", invalid="ignore"):  # refused by name below
        C, D = factor * C, factor * D
    _realisable(
        (A, B, C, D),
        "zpk",
        "k",
        "the gain k and the sections' coefficients are too large together (scale the units)",
    )
    A, B, C = _balance(A, B, C)
    assert A.shape == (n, n)
    return _model(
        A,
        B,
        C,
        D,
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states="{output} x{k}",
        dt=dt,
    )


# ----- elements ---------------------------------------------------------------------------------


def gain(
    K: ArrayLike, *, input_names: Names = None, output_names: Names = None, dt: float | None = None
) -> StateSpace:
    """A static gain y = K u (a scalar, or a p x m matrix), with no states.

    A model without states fits any time base in an interconnection; ``dt`` marks it all the
    same.

    Parameters
    ----------
    K : float or array_like (p, m)
        The gain.
    input_names, output_names : str or sequence of str, optional
        One name per input (column of K) and per output (row).
    dt : float, optional
        The sampling period in seconds of a discrete model (default None).

    Returns
    -------
    StateSpace
        A model with no states and D = K.

    Raises
    ------
    ShapeError
        K is neither a scalar nor 2-D, or a sequence of names has the wrong length.
    NonFiniteError, NotRealError
        K contains NaN or an infinity, or is complex.
    InvalidArgumentError
        A bad ``dt``, or a name that is not a string.

    Examples
    --------
    >>> import aerocontrol
    >>> k = aerocontrol.gain(-1.5, input_names="r", output_names="rudder command")
    >>> k.D, k.n_states
    (array([[-1.5]]), 0)
    """
    matrix = real_array(K, "K")
    if matrix.ndim == 0:
        matrix = matrix.reshape(1, 1)
    if matrix.ndim != 2:
        raise ShapeError(f"K must be a scalar or a 2-D matrix, got shape {matrix.shape}")
    check_finite(matrix, "K")
    p, m = matrix.shape
    return _model(
        np.zeros((0, 0)),
        np.zeros((0, m)),
        np.zeros((p, 0)),
        matrix,
        input_names=input_names,
        output_names=output_names,
        state_names=None,
        dt=dt,
    )


def first_order_lag(
    tau: float,
    *,
    gain: float = 1.0,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """gain/(tau s + 1): a first-order lag of time constant ``tau`` seconds (positive).

    The state is the output divided by ``gain`` (x' = (u - x)/tau, y = gain·x).

    Parameters
    ----------
    tau : float
        The time constant in seconds, positive.
    gain : float, optional
        The gain at rest (default 1).
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The model, continuous, one input and one output, of the stated order.

    Raises
    ------
    InvalidArgumentError
        ``tau`` is not positive, or a name is not a string (or a sequence of
        them).
    NonFiniteError, NotRealError
        ``tau`` or ``gain`` is not finite, or complex.
    ShapeError
        A sequence of names of the wrong length.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> lag = aerocontrol.first_order_lag(0.5)
    >>> lag.A, aerocontrol.dc_gain(lag)
    (array([[-2.]]), array([[1.]]))
    """
    time_constant = _positive(tau, "tau")
    k = _finite(gain, "gain")
    rate = _reciprocal(time_constant, "tau", "first_order_lag")
    return _model(
        np.array([[-rate]]),
        np.array([[rate]]),
        np.array([[k]]),
        np.zeros((1, 1)),
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states="{input} lagged",
    )


def actuator(
    bandwidth: float,
    *,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """A first-order actuator of ``bandwidth`` rad/s (positive): bandwidth/(s + bandwidth),
    unit gain at rest; its state is the surface deflection.

    Parameters
    ----------
    bandwidth : float
        The bandwidth (the pole's magnitude) in rad/s, positive.
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The model, continuous, one input and one output, of the stated order.

    Raises
    ------
    InvalidArgumentError
        ``bandwidth`` is not positive, or a name is not a string (or a sequence of
        them).
    NonFiniteError, NotRealError
        ``bandwidth`` is not finite, or complex.
    ShapeError
        A sequence of names of the wrong length.

    Examples
    --------
    >>> import aerocontrol
    >>> servo = aerocontrol.actuator(20.0, input_names="rudder command", output_names="rudder")
    >>> servo.A, servo.input_names, servo.output_names
    (array([[-20.]]), ('rudder command',), ('rudder',))
    """
    omega = _positive(bandwidth, "bandwidth")
    return _model(
        np.array([[-omega]]),
        np.array([[omega]]),
        np.ones((1, 1)),
        np.zeros((1, 1)),
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states="{output}",
    )


def washout(
    tau: float,
    *,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """tau s/(tau s + 1): a washout filter of time constant ``tau`` seconds (positive), which
    passes changes and blocks a steady signal (so that a yaw damper does not oppose a steady
    turn): gain 0 at rest and 1 at high frequency.

    The state is the input lagged by ``tau`` and the output is the input minus it
    (x' = (u - x)/tau, y = u - x).

    Parameters
    ----------
    tau : float
        The time constant in seconds, positive.
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The model, continuous, one input and one output, of the stated order.

    Raises
    ------
    InvalidArgumentError
        ``tau`` is not positive, or a name is not a string (or a sequence of
        them).
    NonFiniteError, NotRealError
        ``tau`` is not finite, or complex.
    ShapeError
        A sequence of names of the wrong length.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> filt = aerocontrol.washout(2.0, input_names="r", output_names="r washed")
    >>> g = aerocontrol.frequency_response(filt, [0.0, 0.5, 1e6]).response[:, 0, 0]
    >>> np.round(np.abs(g), 6)
    array([0.      , 0.707107, 1.      ])
    """
    time_constant = _positive(tau, "tau")
    rate = _reciprocal(time_constant, "tau", "washout")
    return _model(
        np.array([[-rate]]),
        np.array([[rate]]),
        -np.ones((1, 1)),
        np.ones((1, 1)),
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states="{input} lagged",
    )


def second_order(
    omega_n: float,
    zeta: float,
    *,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """ω_n²/(s² + 2ζω_n s + ω_n²): a second-order element (an actuator, a sensor, a structural
    filter) of natural frequency ``omega_n`` rad/s (positive) and damping ratio ``zeta``
    (non-negative), unit gain at rest.

    The states are the output y and its rate divided by ω_n (x1' = ω_n x2,
    x2' = ω_n (u - x1) - 2ζω_n x2), which keeps the matrices of size ω_n.

    Parameters
    ----------
    omega_n : float
        The natural frequency in rad/s, positive.
    zeta : float
        The damping ratio, non-negative.
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The model, continuous, one input and one output, of the stated order.

    Raises
    ------
    InvalidArgumentError
        ``omega_n`` is not positive or ``zeta`` is negative, or a name is not a string (or
        a sequence of them).
    NonFiniteError, NotRealError
        An argument is not finite, or complex.
    ShapeError
        A sequence of names of the wrong length.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> servo = aerocontrol.second_order(30.0, 0.7)
    >>> poles = np.linalg.eigvals(servo.A)
    >>> np.round(np.abs(poles), 12), np.round(-poles.real / np.abs(poles), 12)
    (array([30., 30.]), array([0.7, 0.7]))
    """
    omega = _positive(omega_n, "omega_n")
    damping = _finite(zeta, "zeta")
    if damping < 0.0:
        raise InvalidArgumentError(f"zeta must be non-negative, got {damping}")
    if not math.isfinite(2.0 * damping * omega):
        error = InvalidArgumentError(
            f"second_order: 2 zeta omega_n = 2·{damping:g}·{omega:g} overflows double precision"
        )
        error.argument = "zeta"
        raise error
    return _model(
        np.array([[0.0, omega], [-omega, -2.0 * damping * omega]]),
        np.array([[0.0], [omega]]),
        np.array([[1.0, 0.0]]),
        np.zeros((1, 1)),
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states=["{output}", "{output} rate/omega_n"],
    )


def pade_delay(
    T: float,
    order: int = 1,
    *,
    input_names: Names = None,
    output_names: Names = None,
    state_names: Names = None,
) -> StateSpace:
    """The Padé approximant of order ``order`` (numerator and denominator degree, 1 to 20) of
    a time delay e^{-sT} of ``T`` seconds (positive), as a state-space model; python-control's
    ``pade(T, order)`` in state space.

    With x = sT the approximant is P(-x)/P(x), P(x) = Σ_k c_k x^k,
    c_k = (2n - k)! n! / ((2n)! k! (n - k)!) (Golub and Van Loan, §9.3.1), computed exactly in
    rational arithmetic; its balanced observable form in x is then scaled to seconds. An
    all-pass: abs(G(jω)) = 1 at every frequency, with the phase -ωT at low frequency.

    Parameters
    ----------
    T : float
        The delay in seconds, positive.
    order : int, optional
        The degree of numerator and denominator, 1 (default) to 20.
    input_names, output_names : str or sequence of str, optional
        The names of the input and the output (default "u0" and "y0", as
        :class:`~aerocontrol.StateSpace` gives).
    state_names : str or sequence of str, optional
        The names of the states, one per state.

    Returns
    -------
    StateSpace
        The approximant, continuous, of ``order`` states.

    Raises
    ------
    InvalidArgumentError
        ``T`` is not positive, or ``order`` is not an integer from 1 to 20 (beyond 20 the
        realisation loses digits), or a name is not a string (or a sequence of them).
    NonFiniteError, NotRealError
        ``T`` is not finite, or complex.
    ShapeError
        A sequence of names of the wrong length.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> delay = aerocontrol.pade_delay(0.1, 3)
    >>> g = aerocontrol.frequency_response(delay, [1.0, 10.0]).response[:, 0, 0]
    >>> np.round(np.abs(g), 12), np.round(np.angle(g), 6)     # e^{-jωT}: -0.1, then -1 rad
    (array([1., 1.]), array([-0.1    , -0.99999]))
    """
    delay = _positive(T, "T")
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 1:
        raise InvalidArgumentError(f"order must be a positive integer, got {order!r}")
    if order > MAX_PADE_ORDER:
        raise InvalidArgumentError(
            f"order must be at most {MAX_PADE_ORDER}, got {order}: beyond it the realisation "
            "from the approximant's coefficients loses digits (the all-pass magnitude is off by "
            "4e-11 at order 30, 4e-9 at order 40)"
        )
    n = int(order)
    exact = [
        Fraction(comb(n, k) * _falling(2 * n - k, n - k), _falling(2 * n, n)) for k in range(n + 1)
    ]
    # Highest power first, monic: P(x) / c_n and P(-x) / c_n.
    denominator = np.array([float(c / exact[n]) for c in reversed(exact)])
    numerator = np.array(
        [float((-1) ** k * c / exact[n]) for k, c in reversed(list(enumerate(exact)))]
    )
    A, B, C, D = _observable_form(numerator, denominator)
    with np.errstate(over="ignore"):  # refused by name below
        A, B = A / delay, B / delay
    _realisable(
        (A, B, C, D),
        "pade_delay",
        "T",
        f"T = {delay:g} is too small: the approximant's poles, of size {order}/T, are beyond "
        "the doubles",
    )
    A, B, C = _balance(A, B, C)
    return _model(
        A,
        B,
        C,
        D,
        input_names=input_names,
        output_names=output_names,
        state_names=state_names,
        states="{input} delay x{k}",
    )


def _falling(top: int, count: int) -> int:
    """top! / (top - count)!."""
    result = 1
    for factor in range(top - count + 1, top + 1):
        result *= factor
    return result
