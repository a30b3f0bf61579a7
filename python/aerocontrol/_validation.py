"""Conversion of caller arguments to the float64 arrays the native core expects.

The core checks shapes and finiteness and names the argument in its errors; this module only
turns array-likes into float64 ndarrays and rejects what is not a real number, by name.
Inputs are never modified: a conversion that needs a new array makes one, and the core only
reads its inputs (copying them before it releases the GIL).
"""

from __future__ import annotations

import warnings
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from .exceptions import (
    InvalidArgumentError,
    NonFiniteError,
    NotRealError,
    NumericalOverflowWarning,
    ShapeError,
)

FloatArray = NDArray[np.float64]
ArrayT = TypeVar("ArrayT", bound=NDArray[Any])


def real_array(value: object, name: str) -> FloatArray:
    """``value`` as a float64 ndarray, or NotRealError naming ``name``.

    Accepts any real array-like: lists, integer, boolean and float32 arrays, Fortran-ordered
    and non-contiguous views (the core reads any strides). A misaligned float64 array (a view
    into a byte buffer at an odd offset) is copied, since the core reads aligned memory only.
    """
    if type(value) is np.ndarray and value.dtype == np.float64 and value.flags.aligned:
        return value
    try:
        array = np.asarray(value)
    except ValueError as error:  # ragged nested sequences
        raise ShapeError(f"{name} must be a rectangular array of numbers: {error}") from None
    if array.dtype.kind == "c":
        raise NotRealError(
            f"{name} must be real, got a complex array (dtype {array.dtype}); "
            "aerocontrol works with real matrices only"
        )
    if array.dtype.kind not in "biuf":
        raise NotRealError(f"{name} must be an array of real numbers, got dtype {array.dtype}")
    array = array.astype(np.float64, copy=False)
    if not array.flags.aligned:
        array = np.array(array, dtype=np.float64)
    return array


def complex_array(value: object, name: str) -> NDArray[np.complex128]:
    """``value`` as a complex128 ndarray (real numbers as complex), or an error naming ``name``:
    ShapeError for a ragged sequence, InvalidArgumentError for anything else that is not an
    array of numbers (strings, objects)."""
    if type(value) is np.ndarray and value.dtype == np.complex128:
        return value
    try:
        array = np.asarray(value)
    except ValueError as error:  # ragged nested sequences
        raise ShapeError(f"{name} must be a rectangular array of numbers: {error}") from None
    if array.dtype.kind not in "biufc":
        refusal = InvalidArgumentError(
            f"{name} must be a number or an array of numbers, got dtype {array.dtype}"
        )
        refusal.argument = name
        raise refusal
    return array.astype(np.complex128, copy=False)


#: How a 1-D array given for a matrix argument is read, by the argument's role (as
#: python-control reads it): an input matrix (B, G, b) as one column, an output matrix (C, c)
#: as one row. Any other matrix has no single reading of a vector and refuses one by name.
VECTOR_ROLES: dict[str, str] = {"B": "column", "G": "column", "b": "column", "C": "row", "c": "row"}


def as_matrix(value: object, name: str, vector: str | None = None) -> FloatArray:
    """``value`` as a 2-D array for the matrix argument ``name``, or ShapeError naming it.

    The one reading of array-likes as matrices that every function taking A, B, C, D or a
    weight shares, accepting what python-control accepts where the meaning is unambiguous:

    * a 2-D ndarray is returned as it is (no copy; the core reads any dtype and layout);
      ``numpy.matrix`` is read as its plain array;
    * a scalar is the 1 x 1 matrix (A = -1 of a first-order system);
    * a 1-D array is a column (``vector="column"``) or a row (``"row"``); by default the
      role is that of the argument's name (:data:`VECTOR_ROLES`: B and G are columns, C a
      row), and any other argument refuses a vector with a ShapeError naming it;
    * anything of more dimensions is refused by name, and what is not an array of real
      numbers as :func:`real_array` refuses it.
    """
    if type(value) is np.ndarray and value.ndim == 2:
        return value
    if isinstance(value, np.matrix):
        value = value.view(np.ndarray)
    array = real_array(value, name)
    if array.ndim == 2:
        return array
    if array.ndim == 0:
        return array.reshape(1, 1)
    role = VECTOR_ROLES.get(name) if vector is None else vector
    if array.ndim == 1 and role == "column":
        return array.reshape(-1, 1)
    if array.ndim == 1 and role == "row":
        return array.reshape(1, -1)
    if array.ndim == 1:
        raise _shape_error(
            name,
            f"{name} must be a 2-D matrix, got an array of shape {array.shape}; a vector is "
            f"ambiguous here: write a single column as {name}.reshape(-1, 1) or a single row "
            f"as {name}.reshape(1, -1)",
        )
    raise _shape_error(name, f"{name} must be a 2-D matrix, got an array of shape {array.shape}")


def _shape_error(name: str, message: str) -> ShapeError:
    error = ShapeError(message)
    error.argument = name
    return error


def real_scalar(value: object, name: str) -> float:
    """``value`` as a Python float, rejecting arrays, complex numbers, non-numbers and bools
    by name (True is no tolerance, weight or frequency: numpy would read it as 1, and
    ``tol=True`` gave a verdict for the tolerance 1 without a word)."""
    if isinstance(value, (bool, np.bool_)) or (
        isinstance(value, np.ndarray) and value.dtype == np.bool_
    ):
        error = InvalidArgumentError(f"{name} must be a number, got the bool {value!r}")
        error.argument = name
        raise error
    array = real_array(value, name)
    if array.ndim != 0:
        raise ShapeError(f"{name} must be a scalar, got an array of shape {array.shape}")
    return float(array)


def check_finite(values: FloatArray, name: str) -> FloatArray:
    """``values``, or NonFiniteError naming ``name`` and its first NaN or infinite entry (the
    check the core makes of its own arguments, for arguments used only in Python)."""
    if np.isfinite(values).all():
        return values
    bad = np.argwhere(~np.isfinite(values))
    if bad.size:
        entry = [int(k) for k in bad[0]]
        value = float(values[tuple(entry)])
        where = f"{name}[{', '.join(map(str, entry))}]" if entry else name
        shown = "NaN" if np.isnan(value) else str(value)
        error = NonFiniteError(f"{name} must be finite, but {where} is {shown}")
        error.argument, error.entry, error.value = name, entry, value
        raise error
    return values


def finite_or_warn(values: ArrayT, what: str, *, stacklevel: int = 3) -> ArrayT:
    """``values``, with a NumericalOverflowWarning naming ``what`` if any entry is not finite
    (the warning the core issues for its own results, for results formed in Python).

    ``stacklevel`` is that of ``warnings.warn`` seen from here: 3, the default, names the
    caller of the function that calls this one; a private helper one call deeper passes 4.
    """
    if not np.isfinite(values).all():
        warnings.warn(
            f"the result overflowed double precision: infinite or NaN entries in {what}",
            NumericalOverflowWarning,
            stacklevel=stacklevel,
        )
    return values


def positive_int(value: object, name: str) -> int:
    """``value`` as a positive int (a Python or numpy integer, not a bool), or
    InvalidArgumentError naming ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise InvalidArgumentError(f"{name} must be a positive int, got {value!r:.80}")
    if value <= 0:
        raise InvalidArgumentError(f"{name} must be a positive int, got {value!r}")
    return int(value)


def optional_callable(value: object, name: str) -> None:
    """InvalidArgumentError naming ``name`` unless ``value`` is None or callable: checked
    before the work whose progress it reports starts, not at its first call (after a chunk
    of a Monte Carlo run, or a report's first section)."""
    if value is not None and not callable(value):
        raise InvalidArgumentError(f"{name} must be callable or None, got {value!r:.80}")


def check_choice(value: object, name: str, choices: tuple[str, ...]) -> str:
    """``value`` if it is one of ``choices``, else InvalidArgumentError naming ``name``."""
    if not isinstance(value, str) or value not in choices:
        allowed = ", ".join(repr(c) for c in choices)
        raise InvalidArgumentError(f"{name} must be one of {allowed}, got {value!r}")
    return str(value)
