"""Linear time-invariant models in state-space form (chapter (6.3), (6.30)).

    x' = A x + B η,     y = C x + D η                         (continuous, dt = 0)
    x[k+1] = A x[k] + B η[k],     y[k] = C x[k] + D η[k]       (discrete, sampled every dt)

:class:`StateSpace` holds the four matrices, the sampling period and the names of the states,
inputs and outputs.
Every analysis function takes a StateSpace, a tuple ``(A, B)`` or ``(A, B, C, D)``, or any
object with ``A``, ``B``, ``C`` and ``D`` attributes (python-control's StateSpace works without
importing python-control); :func:`as_state_space` does the conversion.
"""

from __future__ import annotations

import functools
import importlib
import operator
import warnings
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._validation import FloatArray, as_matrix, real_array, real_scalar
from .exceptions import InvalidArgumentError, NotRealError, NumericalOverflowWarning, ShapeError

if TYPE_CHECKING:
    from typing_extensions import TypeIs

    from ._typing import SignalSelection, System, SystemObject

__all__ = ["StateSpace", "as_state_space"]


def _matrix(value: object, name: str, vector: str | None = None) -> FloatArray:
    return np.array(matrix_view(value, name, vector), dtype=np.float64, order="C")


def _feedthrough(D: object, outputs: int, inputs: int) -> FloatArray:
    """D of a model with ``outputs`` outputs and ``inputs`` inputs: a vector is a row of a
    single-output model or a column of a single-input one (ambiguous otherwise), and a scalar
    zero is the zero matrix, as python-control reads them."""
    if not is_float_matrix(D):
        D = real_array(D, "D")
        if D.ndim == 0 and float(D) == 0.0:
            return _constant(outputs, inputs, identity=False)
    vector = "row" if outputs == 1 else "column" if inputs == 1 else None
    return matrix_view(D, "D", vector)


def is_float_matrix(value: object) -> TypeIs[FloatArray]:
    """Whether ``value`` is already what :func:`matrix_view` makes of it."""
    return (
        type(value) is np.ndarray
        and value.ndim == 2
        and value.dtype == np.float64
        and value.flags.aligned
    )


def matrix_view(value: object, name: str, vector: str | None = None) -> FloatArray:
    """``value`` as a 2-D float64 array, or ShapeError naming ``name``: the array itself when
    it is one already (no copy; see :func:`~aerocontrol._validation.real_array`). Scalars,
    vectors and ``numpy.matrix`` are read by :func:`~aerocontrol._validation.as_matrix` (a
    1-D B a column, a 1-D C a row, by the argument's role or ``vector``)."""
    if is_float_matrix(value):
        return value
    return real_array(as_matrix(value, name, vector), name)


#: Default C = I and D = 0 up to this many entries are made once and shared (read-only).
_SHARED_CONSTANT_MAX_ENTRIES = 64 * 64


def _constant(rows: int, columns: int, identity: bool) -> FloatArray:
    """The default C (the identity) or D (zeros) of a model, read-only: shared between models
    up to :data:`_SHARED_CONSTANT_MAX_ENTRIES` entries (``np.eye`` costs a fifth of a small
    model's construction), made afresh above."""
    if rows * columns <= _SHARED_CONSTANT_MAX_ENTRIES:
        return _shared_constant(rows, columns, identity)
    return _made_constant(rows, columns, identity)


def identity(order: int) -> FloatArray:
    """The identity of ``order`` (read-only; shared up to
    :data:`_SHARED_CONSTANT_MAX_ENTRIES` entries)."""
    return _constant(order, order, identity=True)


@functools.lru_cache(maxsize=256)
def _shared_constant(rows: int, columns: int, identity: bool) -> FloatArray:
    return _made_constant(rows, columns, identity)


def _made_constant(rows: int, columns: int, identity: bool) -> FloatArray:
    matrix = np.eye(rows, columns) if identity else np.zeros((rows, columns))
    matrix.setflags(write=False)
    return matrix


@functools.lru_cache(maxsize=256)
def _default_names(prefix: str, count: int) -> tuple[str, ...]:
    """x0, x1, ... (a tuple of strings, immutable: shared by the models that use it; made
    once, as it costs a quarter of a small model's construction)."""
    return tuple(f"{prefix}{i}" for i in range(count))


def name_sequence(given: object, argument: str) -> tuple[str, ...]:
    """Signal or mode names as given: one string is one name, else a sequence of strings;
    anything else is InvalidArgumentError naming ``argument``."""
    if isinstance(given, str):
        return (given,)
    names: tuple[object, ...] | None = None
    if isinstance(given, Iterable):
        names = tuple(given)
    if names is None or not all(isinstance(name, str) for name in names):
        raise InvalidArgumentError(
            f"{argument} must be a string or a sequence of strings, got {given!r:.80}"
        )
    return cast("tuple[str, ...]", names)


def _names(given: Sequence[str] | None, count: int, prefix: str, argument: str) -> tuple[str, ...]:
    if given is None:
        return _default_names(prefix, count)
    names = name_sequence(given, argument)
    if len(names) != count:
        raise ShapeError(f"{argument} must have {count} names, got {len(names)}")
    return names


def sampling_period(dt: object, name: str = "dt") -> float:
    """``dt`` as a sampling period: 0.0 for a continuous model (None, 0 or False), else a
    positive, finite number of seconds; anything else is refused by name."""
    if dt is None or dt is False:
        return 0.0
    if dt is True:
        raise InvalidArgumentError(
            f"{name}=True (a discrete model of unspecified sampling period, as python-control "
            "writes it) is not supported: give the sampling period in seconds"
        )
    period = real_scalar(dt, name)
    if not (np.isfinite(period) and period >= 0.0):
        raise InvalidArgumentError(
            f"{name} must be None or 0 for a continuous model, or a positive, finite sampling "
            f"period in seconds, got {period}"
        )
    return period


class StateSpace:
    """x' = A x + B η, y = C x + D η, with names for the states, inputs and outputs; or, with
    a sampling period ``dt``, the discrete x[k+1] = A x[k] + B η[k], y[k] = C x[k] + D η[k].

    Parameters
    ----------
    A : array_like, shape (n, n)
        Plant matrix; a scalar is a first-order system's 1 x 1 A.
    B : array_like, shape (n, m) or (n,)
        Control matrix; a 1-D B is a single input (a column).
    C : array_like, shape (p, n) or (n,), optional
        Output matrix; a 1-D C is a single output (a row); the identity (every state is an
        output) when omitted.
    D : array_like, shape (p, m), optional
        Feedthrough; zero when omitted (or given as the scalar 0). A 1-D D is the row of a
        single-output model or the column of a single-input one.

    Scalars, vectors and ``numpy.matrix`` are read as python-control reads them; a vector
    where no reading is unambiguous is refused by name.
    state_names, input_names, output_names : sequence of str, optional
        Names used in tables, plots and legends (defaults x0..., u0..., y0...; the outputs take
        the state names when C is the default identity).
    dt : float, optional
        None (the default) or 0: a continuous model. A positive, finite number: a discrete
        model sampled every ``dt`` seconds, whose responses are taken at t = k dt and whose
        frequency response is G(e^{jω dt}). A negative or non-finite ``dt``, and
        python-control's ``dt=True`` (a discrete model of unspecified period), are refused.
        As in python-control, ``dt=None`` leaves the time base unsaid (every analysis treats
        the model as continuous, but the discrete designs such as :func:`~aerocontrol.dlqr`
        accept it) while ``dt=0`` marks it continuous.

    Every matrix is checked at construction, by name: shapes that disagree or entries that
    are not finite raise ShapeError or NonFiniteError. The matrices are read-only copies:
    changing the arrays given does not change the model.

    Examples
    --------
    >>> import aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> sys = aerocontrol.StateSpace(A, B, state_names=["u/u0", "alpha", "q", "theta"],
    ...                              input_names=["elevator"])
    >>> sys.n_states, sys.n_inputs, sys.n_outputs
    (4, 1, 4)
    >>> sys.output_names
    ('u/u0', 'alpha', 'q', 'theta')
    >>> aerocontrol.StateSpace([[0.9]], [[0.1]], dt=0.05)
    StateSpace(n_states=1, n_inputs=1, n_outputs=1, states=['x0'], inputs=['u0'], dt=0.05)
    """

    A: FloatArray
    B: FloatArray
    C: FloatArray
    D: FloatArray
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    dt: float | None
    """The sampling period in seconds; None or 0.0 for a continuous model."""

    def __init__(
        self,
        A: ArrayLike,
        B: ArrayLike,
        C: ArrayLike | None = None,
        D: ArrayLike | None = None,
        state_names: Sequence[str] | None = None,
        input_names: Sequence[str] | None = None,
        output_names: Sequence[str] | None = None,
        dt: float | None = None,
    ) -> None:
        self.dt = None if dt is None else sampling_period(dt)
        A = _matrix(A, "A")
        B = _matrix(B, "B")
        n, m = A.shape[0], B.shape[1]
        identity_output = C is None
        C = _constant(n, n, identity=True) if identity_output else _matrix(C, "C")
        if D is None:
            D = _constant(C.shape[0], m, identity=False)
        else:
            D = np.array(_feedthrough(D, C.shape[0], m), dtype=np.float64, order="C")
        _core.check_model(A, B, C, D)
        for matrix in (A, B, C, D):
            matrix.setflags(write=False)
        self.A, self.B, self.C, self.D = A, B, C, D
        self.state_names = _names(state_names, n, "x", "state_names")
        self.input_names = _names(input_names, m, "u", "input_names")
        if identity_output and output_names is None:
            self.output_names = self.state_names
        else:
            self.output_names = _names(output_names, C.shape[0], "y", "output_names")

    def __getitem__(self, key: tuple[SignalSelection, SignalSelection]) -> StateSpace:
        """The model from some inputs to some outputs: ``sys[outputs, inputs]``.

        Each of the two is a signal name, an index, a slice, or a list of names and indices;
        the states are kept (no reduction), and so are the names and ``dt``. A name must
        belong to exactly one signal, and an index must be in range.

        Examples
        --------
        >>> import aerocontrol
        >>> lateral = aerocontrol.aircraft.load("b747-approach").lateral()
        >>> lateral.output_names, lateral.input_names
        (('beta', 'p', 'phi', 'r'), ('rudder', 'aileron'))
        >>> yaw = lateral["r", "rudder"]
        >>> yaw
        StateSpace(n_states=4, n_inputs=1, n_outputs=1, states=['beta', 'p', 'phi', 'r'],
                   inputs=['rudder'])
        >>> yaw.output_names
        ('r',)
        >>> lateral[["p", 3], :].output_names
        ('p', 'r')
        """
        if not (isinstance(key, tuple) and len(key) == 2):
            raise InvalidArgumentError(
                "select signals as sys[outputs, inputs] (each a name, an index, a slice or a "
                f"list of them; sys[name, :] keeps every input), got sys[{key!r}]"
            )
        rows = signal_indices(key[0], self.output_names, "output")
        columns = signal_indices(key[1], self.input_names, "input")
        return StateSpace(
            self.A,
            self.B[:, columns],
            self.C[rows, :],
            self.D[np.ix_(rows, columns)],
            state_names=self.state_names,
            input_names=[self.input_names[j] for j in columns],
            output_names=[self.output_names[i] for i in rows],
            dt=self.dt,
        )

    @property
    def is_discrete(self) -> bool:
        """Whether the model is discrete (sampled every ``dt`` > 0 seconds)."""
        return period(self) > 0.0

    @property
    def n_states(self) -> int:
        """The order n."""
        return int(self.A.shape[0])

    @property
    def n_inputs(self) -> int:
        """The number of inputs m."""
        return int(self.B.shape[1])

    @property
    def n_outputs(self) -> int:
        """The number of outputs p."""
        return int(self.C.shape[0])

    def to_control(self) -> Any:
        """This model as python-control's ``StateSpace`` (python-control imported only here).

        The matrices are copied; the state, input and output names become python-control's
        labels, and ``dt`` is kept as it is (None, 0 or the sampling period), so that
        :meth:`from_control` gives back an equal model.

        Returns
        -------
        control.StateSpace

        Raises
        ------
        ImportError
            python-control is not installed.

        Examples
        --------
        >>> import aerocontrol
        >>> lateral = aerocontrol.aircraft.load("b747-approach").lateral()
        >>> sys = lateral.to_control()
        >>> type(sys).__name__, sys.input_labels
        ('StateSpace', ['rudder', 'aileron'])
        >>> aerocontrol.StateSpace.from_control(sys).input_names
        ('rudder', 'aileron')
        """
        control = _optional_import("control", "python-control", "StateSpace.to_control")
        return control.ss(
            np.array(self.A),
            np.array(self.B),
            np.array(self.C),
            np.array(self.D),
            dt=self.dt,
            states=list(self.state_names),
            inputs=list(self.input_names),
            outputs=list(self.output_names),
        )

    @classmethod
    def from_control(cls, sys: object) -> StateSpace:
        """A model from python-control's ``StateSpace`` (or any of its LTI systems, realised
        by ``control.ss``), with its labels as names and its ``dt`` (None, 0 or the period).

        Parameters
        ----------
        sys : control.StateSpace or control.TransferFunction

        Returns
        -------
        StateSpace

        Raises
        ------
        ImportError
            python-control is not installed.
        NotRealError
            ``sys`` is not a python-control system.
        InvalidArgumentError
            its ``dt`` is True (a discrete system of unspecified period).

        Examples
        --------
        >>> import control, aerocontrol
        >>> sys = aerocontrol.StateSpace.from_control(control.tf([1], [1, 2, 3], dt=0.1))
        >>> sys.n_states, sys.dt
        (2, 0.1)
        """
        control = _optional_import("control", "python-control", "StateSpace.from_control")
        if isinstance(sys, control.LTI) and not isinstance(sys, control.StateSpace):
            sys = control.ss(sys)
        if not isinstance(sys, control.StateSpace):
            raise NotRealError(f"sys must be a python-control system, got {type(sys).__name__}")
        return as_state_space(sys)

    def to_scipy(self) -> Any:
        """This model as ``scipy.signal.StateSpace`` (scipy imported only here): continuous
        for ``dt`` None or 0, else discrete with ``dt`` (scipy keeps no names).

        Returns
        -------
        scipy.signal.StateSpace

        Raises
        ------
        ImportError
            scipy is not installed.

        Examples
        --------
        >>> import aerocontrol
        >>> sys = aerocontrol.StateSpace([[0.9]], [[0.1]], dt=0.05).to_scipy()
        >>> type(sys).__name__, sys.dt
        ('StateSpaceDiscrete', 0.05)
        """
        signal = _optional_import("scipy.signal", "scipy", "StateSpace.to_scipy")
        matrices = (np.array(self.A), np.array(self.B), np.array(self.C), np.array(self.D))
        if self.is_discrete:
            return signal.StateSpace(*matrices, dt=period(self))
        return signal.StateSpace(*matrices)

    @classmethod
    def from_scipy(cls, sys: object) -> StateSpace:
        """A model from ``scipy.signal``'s ``StateSpace`` (or any of its ``lti``/``dlti``
        systems, realised by their ``to_ss``), continuous or discrete with its ``dt``.

        Parameters
        ----------
        sys : scipy.signal.StateSpace, TransferFunction or ZerosPolesGain

        Returns
        -------
        StateSpace

        Raises
        ------
        ImportError
            scipy is not installed.
        NotRealError
            ``sys`` is not a scipy.signal system.

        Examples
        --------
        >>> import scipy.signal, aerocontrol
        >>> sys = aerocontrol.StateSpace.from_scipy(scipy.signal.TransferFunction([1], [1, 1]))
        >>> sys.A, sys.dt is None
        (array([[-1.]]), True)
        """
        signal = _optional_import("scipy.signal", "scipy", "StateSpace.from_scipy")
        if isinstance(sys, (signal.lti, signal.dlti)) and not isinstance(sys, signal.StateSpace):
            sys = sys.to_ss()
        if not isinstance(sys, signal.StateSpace):
            raise NotRealError(f"sys must be a scipy.signal system, got {type(sys).__name__}")
        return as_state_space(sys)

    def __repr__(self) -> str:
        return (
            f"StateSpace(n_states={self.n_states}, n_inputs={self.n_inputs}, "
            f"n_outputs={self.n_outputs}, states={list(self.state_names)}, "
            f"inputs={list(self.input_names)}"
            + (f", dt={period(self):g})" if self.is_discrete else ")")
        )


def _optional_import(module: str, package: str, caller: str) -> Any:
    """``module``, imported when first needed, or ImportError naming the package to install."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        raise ImportError(
            f"{caller} needs {package}, which is not installed (pip install {package}): {error}"
        ) from error


def signal_indices(key: object, names: Sequence[str], what: str) -> list[int]:
    """The positions in ``names`` (a model's ``what`` names: "input", "output") that ``key``
    selects: a name, an index (negative counts from the end), a slice, or a list of names and
    indices. An unknown or ambiguous name, an index out of range and anything else are
    refused by name."""
    if isinstance(key, slice):
        return list(range(len(names)))[_index_slice(key, what)]
    if isinstance(key, (str, int, np.integer)):
        return [_signal_index(key, names, what)]
    if isinstance(key, (list, tuple, np.ndarray)):
        return [_signal_index(item, names, what) for item in key]
    raise InvalidArgumentError(
        f"an {what} selection must be a name, an index, a slice or a list of them, "
        f"got {type(key).__name__}"
    )


def _index_slice(key: slice, what: str) -> slice:
    """``key`` if its bounds and step are integers or None and its step is not zero; else
    InvalidArgumentError. Python's slicing raised a bare TypeError for sys["a":"c", :] or a
    float bound, and ValueError for a zero step; and took a bool bound as 0 or 1, which a
    single index refuses."""
    for part in (key.start, key.stop, key.step):
        if part is not None and (
            isinstance(part, (bool, np.bool_)) or not isinstance(part, (int, np.integer))
        ):
            raise InvalidArgumentError(
                f"an {what} slice must have integer bounds (select names with a list), got {key!r}"
            )
    if key.step == 0:
        raise InvalidArgumentError(f"an {what} slice must have a nonzero step, got {key!r}")
    return key


def _signal_index(item: object, names: Sequence[str], what: str) -> int:
    if isinstance(item, (str, np.str_)):
        found = [i for i, name in enumerate(names) if name == item]
        if not found:
            known = ", ".join(repr(name) for name in names) or "none"
            raise InvalidArgumentError(f"no {what} is named {str(item)!r}; the {what}s are {known}")
        if len(found) > 1:
            raise InvalidArgumentError(
                f"{len(found)} {what}s are named {str(item)!r} (positions {found}); select by index"
            )
        return found[0]
    if isinstance(item, (bool, np.bool_)) or not isinstance(item, (int, np.integer)):
        raise InvalidArgumentError(
            f"an {what} must be selected by name or by integer index, got {item!r}"
        )
    index = operator.index(item)
    if not -len(names) <= index < len(names):
        raise InvalidArgumentError(
            f"{what} index {index} is out of range for a model with {len(names)} {what}s"
        )
    return index % len(names)


def period(model: StateSpace) -> float:
    """The sampling period of a model in seconds: 0.0 for a continuous one (dt None or 0)."""
    return model.dt or 0.0


def _foreign_period(dt: object, name: str) -> float | None:
    """A foreign model's ``dt`` checked under its own name; None stays None."""
    return None if dt is None else sampling_period(dt, name)


def require_continuous(model: StateSpace, function: str, instead: str) -> None:
    """Refuses a discrete model in a continuous-time design function, which would otherwise
    solve the continuous problem for the matrices of the sampled one without a word."""
    if model.is_discrete:
        raise InvalidArgumentError(
            f"{function} designs in continuous time, but the system is discrete (sampled every "
            f"{period(model):g} s); {instead}"
        )


def is_continuous_model(value: object) -> bool:
    """Whether a model object is marked continuous-time: ``dt = 0`` (a :class:`StateSpace` or
    python-control's), or a continuous scipy.signal system (whose ``dt`` is None). ``dt =
    None`` elsewhere leaves the time base unsaid, as in python-control: such a model is taken
    as continuous by the continuous functions and is not refused by the discrete ones."""
    dt = getattr(value, "dt", None)
    if dt is None:
        return type(value).__module__.startswith("scipy.signal")
    return not isinstance(dt, bool) and dt == 0


def require_discrete(model: object, function: str, instead: str) -> None:
    """Refuses a model marked continuous in a discrete-time design function, which would
    otherwise solve the discrete problem for the matrices of the continuous one."""
    if is_continuous_model(model):
        raise InvalidArgumentError(
            f"{function} needs a discrete-time system, got one marked continuous-time; {instead}"
        )


def continuous_eigenvalues(model: StateSpace) -> NDArray[np.complex128]:
    """The eigenvalues of A for a continuous model; for a discrete one, those of the equivalent
    continuous model, s = ln(z) / dt (principal logarithm: a real z < 0 gives the Nyquist
    frequency π/dt, and z = 0 gives s = -inf)."""
    eigenvalues = _core.eigenvalues(model.A) if model.n_states else np.zeros(0, np.complex128)
    if not model.is_discrete:
        return eigenvalues
    s = np.full(eigenvalues.shape, complex(-np.inf, 0.0), dtype=np.complex128)
    nonzero = eigenvalues != 0
    s[nonzero] = np.log(eigenvalues[nonzero]) / period(model)
    return s


def is_system(value: object) -> TypeIs[SystemObject]:
    """Whether ``value`` is a model rather than a matrix: a :class:`StateSpace`, or an object
    with ``A``, ``B``, ``C`` and ``D`` attributes such as python-control's StateSpace. Arrays
    are matrices, ``numpy.matrix`` included (its ``.A`` is the plain array, not a plant)."""
    if isinstance(value, StateSpace):
        return True
    if isinstance(value, np.ndarray):
        return False
    return all(hasattr(value, attribute) for attribute in "ABCD")


def as_state_space(model: System, name: str = "sys") -> StateSpace:
    """``model`` as a :class:`StateSpace`.

    Accepts a StateSpace (returned as is), a tuple or list ``(A, B)`` or ``(A, B, C, D)``
    (continuous), or any object with ``A``, ``B``, ``C``, ``D`` attributes, such as
    python-control's StateSpace (its names and its sampling period ``dt`` are taken too when it
    has them; python-control's ``dt=True``, an unspecified period, is refused).

    Parameters
    ----------
    model : StateSpace, tuple or system object
        The model.
    name : str, optional
        The argument's name in error messages (default "sys").

    Returns
    -------
    StateSpace
        The model itself, or a new one with the given matrices.

    Raises
    ------
    ShapeError
        A sequence of other than 2 or 4 matrices, or matrices whose shapes disagree.
    NotRealError
        ``model`` is none of these, or a matrix is complex.
    InvalidArgumentError
        A sampling period that is not a positive number (``dt=True``).

    Examples
    --------
    >>> import aerocontrol
    >>> sys = aerocontrol.as_state_space(([[0.0, 1.0], [-2.0, -3.0]], [[0.0], [1.0]]))
    >>> sys.n_states, sys.n_inputs, sys.dt
    (2, 1, None)
    """
    if isinstance(model, StateSpace):
        return model
    if isinstance(model, (tuple, list)):
        if len(model) not in (2, 4):
            raise ShapeError(
                f"{name} as a sequence must be (A, B) or (A, B, C, D), got {len(model)} items"
            )
        return StateSpace(*model)
    if is_system(model):
        names: dict[str, list[str]] = {}
        for ours, theirs in [
            ("state_names", "state_labels"),
            ("input_names", "input_labels"),
            ("output_names", "output_labels"),
        ]:
            labels = getattr(model, theirs, None)
            if labels is not None:
                names[ours] = list(labels)
        return StateSpace(
            np.asarray(model.A),
            np.asarray(model.B),
            np.asarray(model.C),
            np.asarray(model.D),
            **names,
            dt=_foreign_period(getattr(model, "dt", None), f"{name}.dt"),
        )
    raise NotRealError(
        f"{name} must be a StateSpace, a tuple (A, B) or (A, B, C, D), or an object with A, B, "
        f"C and D attributes, got {type(model).__name__}"
    )


def plant_arrays(
    model: System, name: str = "sys", check: bool = True
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float]:
    """(A, B, C, D, dt) of ``model``, without building a :class:`StateSpace` from a tuple: for
    a function that passes the matrices to the core once, where the read-only copies a model
    makes cost more than the work on a small one.

    A StateSpace gives its own matrices and any other system (python-control's) is converted
    by :func:`as_state_space`. A tuple ``(A, B)`` or ``(A, B, C, D)`` gives its arrays as they
    are (float64 views: no copy; a 1-D B as one column; C = I and D = 0 where absent, as
    StateSpace makes them, shared and read-only), continuous (dt = 0.0). Given C and D are
    checked against A and B here (the core's ``check_model``, as StateSpace checks them) unless
    ``check`` is False, for a caller that passes all four to a core function which checks them
    (a second pass over A costs a fifth of a solve of order 64); the A and B of an ``(A, B)``
    tuple are not: the caller must pass them to a core function, which checks its arguments by
    name (shapes and finiteness) as StateSpace would.
    """
    if isinstance(model, StateSpace):
        return model.A, model.B, model.C, model.D, period(model)
    if isinstance(model, (tuple, list)) and len(model) in (2, 4):
        A = matrix_view(model[0], "A")
        B = matrix_view(model[1], "B")
        given = len(model) == 4 and (model[2] is not None or model[3] is not None)
        C = _constant(A.shape[0], A.shape[0], True)
        if len(model) == 4 and model[2] is not None:
            C = matrix_view(model[2], "C")
        D = _constant(C.shape[0], B.shape[1], False)
        if len(model) == 4 and model[3] is not None:
            D = _feedthrough(model[3], C.shape[0], B.shape[1])
        if given and check:
            _core.check_model(A, B, C, D)
        return A, B, C, D, 0.0
    sys = as_state_space(model, name)
    return sys.A, sys.B, sys.C, sys.D, period(sys)


def plant_pair(
    A_or_sys: ArrayLike | System, second: ArrayLike | None, attribute: str
) -> tuple[ArrayLike, ArrayLike]:
    """(A, B) or (A, C): the two matrices when ``second`` is given, else taken from a system,
    an (A, B) tuple or any object with the attributes (``attribute`` names the second one)."""
    if second is not None:
        # With both given the first is the plant matrix (a system there is refused by name:
        # it carries its own second matrix); a vector for the second is a column of B or a
        # row of C, by its role.
        if is_system(A_or_sys):
            error = InvalidArgumentError(
                f"A_or_sys is a system, which has its own {attribute}; give the system "
                f"without {attribute}, or the matrices A and {attribute}"
            )
            error.argument = attribute
            raise error
        return matrix_view(A_or_sys, "A"), matrix_view(second, attribute)
    if isinstance(A_or_sys, (tuple, list)) or is_system(A_or_sys):
        sys = as_state_space(A_or_sys)
        return sys.A, getattr(sys, attribute)
    raise NotRealError(f"give a system or both A and {attribute}")


def grid_frequencies(
    models: Sequence[StateSpace], what: str
) -> tuple[NDArray[np.complex128], FloatArray]:
    """(eigenvalues, nonzero natural frequencies |λ|) of the models' A (for a discrete model,
    of its continuous equivalent, s = ln(z)/dt), by aerocontrol's own eigensolver, from which the
    default time and frequency grids are chosen; |λ| within 1e-12 max(1, |λ|max) of zero
    counts as zero.

    An eigenvalue whose magnitude overflows double precision gives InvalidArgumentError
    naming ``what``: no grid of doubles resolves it, and the caller must give the grid."""
    with warnings.catch_warnings():
        # An eigenvalue that overflows is refused below, by name.
        warnings.simplefilter("ignore", NumericalOverflowWarning)
        eigenvalues = np.concatenate(
            [continuous_eigenvalues(m) for m in models] + [np.zeros(0, dtype=np.complex128)]
        )
    # z = 0 of a discrete model (s = -inf) sets no time scale.
    eigenvalues = eigenvalues[~np.isneginf(eigenvalues.real)]
    with np.errstate(over="ignore"):
        magnitudes = np.abs(eigenvalues)
    if not np.all(np.isfinite(magnitudes)):
        raise InvalidArgumentError(
            f"{what}: an eigenvalue of A overflows double precision, so no default grid can "
            "resolve it; give the grid"
        )
    largest = float(magnitudes.max(initial=0.0))
    return eigenvalues, magnitudes[magnitudes > 1e-12 * max(1.0, largest)]
