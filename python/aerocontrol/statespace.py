"""Linear time-invariant models in state-space form (chapter (6.3), (6.30)).

    x' = A x + B η,     y = C x + D η

:class:`StateSpace` holds the four matrices and the names of the states, inputs and outputs.
Every analysis function takes a StateSpace, a tuple ``(A, B)`` or ``(A, B, C, D)``, or any
object with ``A``, ``B``, ``C`` and ``D`` attributes (python-control's StateSpace works without
importing python-control); :func:`as_state_space` does the conversion.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _core
from ._validation import FloatArray, real_array
from .exceptions import ConvergenceError, InvalidArgumentError, NotRealError, ShapeError

__all__ = ["StateSpace", "as_state_space"]


def _matrix(value: Any, name: str) -> FloatArray:
    array = real_array(value, name)
    if array.ndim == 1:
        raise ShapeError(
            f"{name} must be a 2-D matrix, got an array of shape {array.shape}; "
            f"write a single column as {name}.reshape(-1, 1)"
        )
    if array.ndim != 2:
        raise ShapeError(f"{name} must be a 2-D matrix, got an array of shape {array.shape}")
    return np.array(array, dtype=np.float64, order="C")


def _names(given: Sequence[str] | None, count: int, prefix: str, argument: str) -> tuple[str, ...]:
    if given is None:
        return tuple(f"{prefix}{i}" for i in range(count))
    names = tuple(str(name) for name in given)
    if len(names) != count:
        raise ShapeError(f"{argument} must have {count} names, got {len(names)}")
    return names


class StateSpace:
    """x' = A x + B η, y = C x + D η, with names for the states, inputs and outputs.

    Parameters
    ----------
    A : array_like, shape (n, n)
        Plant matrix.
    B : array_like, shape (n, m) or (n,)
        Control matrix; a 1-D B is a single input.
    C : array_like, shape (p, n), optional
        Output matrix; the identity (every state is an output) when omitted.
    D : array_like, shape (p, m), optional
        Feedthrough; zero when omitted.
    state_names, input_names, output_names : sequence of str, optional
        Names used in tables, plots and legends (defaults x0..., u0..., y0...; the outputs take
        the state names when C is the default identity).

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
    """

    A: FloatArray
    B: FloatArray
    C: FloatArray
    D: FloatArray
    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]

    def __init__(
        self,
        A: Any,
        B: Any,
        C: Any = None,
        D: Any = None,
        state_names: Sequence[str] | None = None,
        input_names: Sequence[str] | None = None,
        output_names: Sequence[str] | None = None,
    ) -> None:
        A = _matrix(A, "A")
        B_array = real_array(B, "B")
        B = _matrix(B_array.reshape(-1, 1) if B_array.ndim == 1 else B_array, "B")
        n, m = A.shape[0], B.shape[1]
        identity_output = C is None
        C = np.eye(n) if identity_output else _matrix(C, "C")
        D = np.zeros((C.shape[0], m)) if D is None else _matrix(D, "D")
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

    def __repr__(self) -> str:
        return (
            f"StateSpace(n_states={self.n_states}, n_inputs={self.n_inputs}, "
            f"n_outputs={self.n_outputs}, states={list(self.state_names)}, "
            f"inputs={list(self.input_names)})"
        )


def is_system(value: Any) -> bool:
    """Whether ``value`` is a model rather than a matrix: a :class:`StateSpace`, or an object
    with ``A``, ``B``, ``C`` and ``D`` attributes such as python-control's StateSpace. Arrays
    are matrices, ``numpy.matrix`` included (its ``.A`` is the plain array, not a plant)."""
    if isinstance(value, StateSpace):
        return True
    if isinstance(value, np.ndarray):
        return False
    return all(hasattr(value, attribute) for attribute in "ABCD")


def as_state_space(model: Any, name: str = "sys") -> StateSpace:
    """``model`` as a :class:`StateSpace`.

    Accepts a StateSpace (returned as is), a tuple or list ``(A, B)`` or ``(A, B, C, D)``, or
    any object with ``A``, ``B``, ``C``, ``D`` attributes, such as python-control's StateSpace
    (its names are taken too when it has them).
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
        names: dict[str, Any] = {}
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
        )
    raise NotRealError(
        f"{name} must be a StateSpace, a tuple (A, B) or (A, B, C, D), or an object with A, B, "
        f"C and D attributes, got {type(model).__name__}"
    )


def plant_pair(A_or_sys: Any, second: Any, attribute: str) -> tuple[Any, Any]:
    """(A, B) or (A, C): the two matrices when ``second`` is given, else taken from a system,
    an (A, B) tuple or any object with the attributes (``attribute`` names the second one)."""
    if second is not None:
        return A_or_sys, second
    if isinstance(A_or_sys, (tuple, list)) or is_system(A_or_sys):
        sys = as_state_space(A_or_sys)
        return sys.A, getattr(sys, attribute)
    raise NotRealError(f"give a system or both A and {attribute}")


def grid_frequencies(
    models: Sequence[StateSpace], what: str
) -> tuple[NDArray[np.complex128], FloatArray]:
    """(eigenvalues, nonzero natural frequencies |λ|) of the models' A, from which the
    default time and frequency grids are chosen; |λ| within 1e-12 max(1, |λ|max) of zero
    counts as zero.

    An eigenvalue whose magnitude overflows double precision gives InvalidArgumentError
    naming ``what``: no grid of doubles resolves it, and the caller must give the grid."""
    try:
        eigenvalues = np.concatenate(
            [np.linalg.eigvals(m.A) for m in models] + [np.zeros(0, dtype=np.complex128)]
        )
    except np.linalg.LinAlgError as error:
        raise ConvergenceError(f"{what}: the eigenvalues of A did not converge ({error})") from None
    with np.errstate(over="ignore"):
        magnitudes = np.abs(eigenvalues)
    if not np.all(np.isfinite(magnitudes)):
        raise InvalidArgumentError(
            f"{what}: an eigenvalue of A overflows double precision, so no default grid can "
            "resolve it; give the grid"
        )
    largest = float(magnitudes.max(initial=0.0))
    return eigenvalues, magnitudes[magnitudes > 1e-12 * max(1.0, largest)]
