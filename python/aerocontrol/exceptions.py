"""Exceptions and warnings raised by aerocontrol.

Every error subclasses a built-in, so ``except ValueError`` and
``except numpy.linalg.LinAlgError`` keep working:

============================  ===========================================================
class                         raised when
============================  ===========================================================
``ShapeError``                an argument has the wrong shape or its dimensions disagree
``NonFiniteError``            an argument contains NaN or an infinity
``InvalidArgumentError``      any other out-of-domain argument (a step that is not positive,
                              an unknown method name); base of the two above
``NotRealError``              an argument is complex (``TypeError``): real matrices only
``AerocontrolLinAlgError``    a numerical condition makes the problem unsolvable
``ConvergenceError``          an iteration reached its limit (an ``AerocontrolLinAlgError``)
``SingularMatrixError``       a matrix to invert has a zero eigenvalue (likewise)
``UncontrollableError``       a pair (A, B) has a mode that no feedback can move (likewise)
============================  ===========================================================

Warnings (``AerocontrolWarning`` and subclasses) report results that were computed but deserve
care: overflow, ill-conditioning.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "AerocontrolError",
    "AerocontrolLinAlgError",
    "AerocontrolWarning",
    "ConvergenceError",
    "IllConditionedWarning",
    "InvalidArgumentError",
    "NonFiniteError",
    "NotRealError",
    "NumericalOverflowWarning",
    "ShapeError",
    "SingularMatrixError",
    "UncontrollableError",
]


class AerocontrolError(Exception):
    """Base class of every exception raised by aerocontrol."""


class InvalidArgumentError(AerocontrolError, ValueError):
    """An argument is outside its domain; the message names the argument."""


class ShapeError(InvalidArgumentError):
    """An argument has the wrong number of dimensions, is not square, or disagrees in size
    with another argument."""


class NonFiniteError(InvalidArgumentError):
    """An argument contains NaN or an infinity; the message names the first such entry."""


class NotRealError(AerocontrolError, TypeError):
    """An argument is complex or not numeric; aerocontrol works with real matrices only."""


class AerocontrolLinAlgError(AerocontrolError, np.linalg.LinAlgError):
    """A numerical condition (singularity, no stabilising solution, non-convergence) makes
    the problem unsolvable."""


class SingularMatrixError(AerocontrolLinAlgError):
    """A matrix that must be invertible is singular; the message names the zero eigenvalue
    (an integrator or neutral mode, for a plant matrix)."""


class UncontrollableError(AerocontrolLinAlgError):
    """A pair (A, B) is not controllable to the rank tolerance (or (A, C) not observable);
    the message names the eigenvalues that feedback cannot move."""


class ConvergenceError(AerocontrolLinAlgError):
    """An iterative algorithm (an eigenvalue iteration, a Newton refinement) reached its
    iteration limit without converging."""


class AerocontrolWarning(UserWarning):
    """Base class of the warnings issued by aerocontrol."""


class IllConditionedWarning(AerocontrolWarning, RuntimeWarning):
    """A result was computed, but its conditioning means it may carry few or no correct
    digits; the message gives the measure."""


class NumericalOverflowWarning(AerocontrolWarning, RuntimeWarning):
    """A result overflowed double precision and contains infinite (or NaN) entries."""
