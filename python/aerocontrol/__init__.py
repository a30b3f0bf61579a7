"""aerocontrol: modern linear control of flight vehicles, with a Rust core.

The package implements the course chapter "Control of Aircraft Motions": the state
transition matrix and time responses, controllability, pole placement and optimal control, on
the chapter's Boeing 747 and on any aircraft described by its derivatives.

>>> import numpy as np, aerocontrol
>>> A, B = aerocontrol.chapter.boeing747_longitudinal()
>>> Phi = aerocontrol.transition_matrix(A, [0.0, 1.0, 10.0])
>>> Phi.shape
(3, 4, 4)
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

from . import chapter, exceptions
from .exceptions import (
    AerocontrolError,
    AerocontrolLinAlgError,
    AerocontrolWarning,
    ConvergenceError,
    IllConditionedWarning,
    InvalidArgumentError,
    NonFiniteError,
    NotRealError,
    NumericalOverflowWarning,
    ShapeError,
)
from .linalg import Discretization, discretize, expm, transition_matrix

try:
    __version__ = version("aerocontrol")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = [
    "AerocontrolError",
    "AerocontrolLinAlgError",
    "AerocontrolWarning",
    "ConvergenceError",
    "Discretization",
    "IllConditionedWarning",
    "InvalidArgumentError",
    "NonFiniteError",
    "NotRealError",
    "NumericalOverflowWarning",
    "ShapeError",
    "__version__",
    "chapter",
    "discretize",
    "exceptions",
    "expm",
    "transition_matrix",
]
