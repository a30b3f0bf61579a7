"""Type aliases of the public signatures: what kind of object each argument may be.

They are for type checkers only; the wrappers and the core check shapes, dtypes and values at
run time and name the argument in their errors.

* Matrices, vectors, time grids, weights and poles are ``numpy.typing.ArrayLike``: nested
  lists and tuples of numbers, numpy arrays of any real dtype, layout or strides, and scalars.
* :data:`SystemObject` is a model given as an object: a :class:`~aerocontrol.StateSpace`, or
  anything with ``A``, ``B``, ``C`` and ``D`` attributes (python-control's StateSpace).
* :data:`System` adds the sequences :func:`~aerocontrol.as_state_space` takes, ``(A, B)`` and
  ``(A, B, C, D)``.
* :data:`Systems` adds a list of models of one size, which the time responses compute in one
  call. It says ``Sequence``, not ``list``, because a list is invariant (a ``list[Foreign]``
  is not a ``list[StateSpaceLike]``); at run time the models must come as a list.
* :data:`ModeKey` names a mode of :func:`~aerocontrol.augment_mode`.
* :data:`SignalSelection` picks inputs or outputs of a model (``sys[outputs, inputs]``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias, Union

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:
    from .statespace import StateSpace

__all__ = ["ModeKey", "SignalSelection", "StateSpaceLike", "System", "SystemObject", "Systems"]


class StateSpaceLike(Protocol):
    """Any object with the four state-space matrices as attributes, such as python-control's
    StateSpace (read-only properties, so plain attributes and properties both qualify)."""

    @property
    def A(self) -> ArrayLike: ...
    @property
    def B(self) -> ArrayLike: ...
    @property
    def C(self) -> ArrayLike: ...
    @property
    def D(self) -> ArrayLike: ...


#: A model given as an object (what :func:`~aerocontrol.statespace.is_system` recognises).
SystemObject: TypeAlias = Union["StateSpace", StateSpaceLike]

#: A model: an object, or the matrices ``(A, B)`` or ``(A, B, C, D)`` as a tuple or a list.
System: TypeAlias = Union[
    "StateSpace",
    StateSpaceLike,
    tuple[ArrayLike, ArrayLike],
    tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike],
    list[ArrayLike],
]

#: One model, or a list of models of one size (the time responses then have a leading axis).
Systems: TypeAlias = System | Sequence[SystemObject]

#: A mode of :func:`~aerocontrol.augment_mode`: its index in mode order, its name, or an
#: eigenvalue near it (Python or numpy numbers; ``Any`` is numpy's precision parameter).
ModeKey: TypeAlias = int | str | complex | np.number[Any]

#: Inputs or outputs of a model: a name, an index, a slice, or a list of names and indices.
SignalSelection: TypeAlias = str | int | np.integer[Any] | slice | Sequence[str | int]
