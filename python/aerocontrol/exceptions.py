"""Exceptions and warnings raised by aerocontrol.

Every error subclasses a built-in, so ``except ValueError`` and
``except numpy.linalg.LinAlgError`` keep working:

================================  ===========================================================
class                             raised when
================================  ===========================================================
``ShapeError``                    an argument has the wrong shape or its dimensions disagree
``NonFiniteError``                an argument contains NaN or an infinity
``InvalidArgumentError``          any other out-of-domain argument (a step that is not positive,
                                  an unknown method name); base of the two above
``NotRealError``                  an argument is complex (``TypeError``): real matrices only
``AerocontrolLinAlgError``        a numerical condition makes the problem unsolvable
``ConvergenceError``              an iteration reached its limit (an ``AerocontrolLinAlgError``)
``SingularMatrixError``           a matrix to invert has a zero eigenvalue (likewise)
``UncontrollableError``           a pair (A, B) has a mode that no feedback can move (likewise)
``NoStabilizingSolutionError``    a Riccati equation has no stabilising solution (likewise)
``IllConditionedError``           a step would lose every digit and was refused (likewise)
``NoContinuousEquivalentError``   a discrete model has no real continuous model behind it under
                                  the method asked (likewise, and an ``InvalidArgumentError``
                                  naming the model: the argument is outside ``d2c``'s domain)
``NotPositiveDefiniteError``      a weight such as R is not symmetric positive definite
                                  (an ``InvalidArgumentError``)
================================  ===========================================================

Warnings (``AerocontrolWarning`` and subclasses) report results that were computed but deserve
care: overflow, underflow, ill-conditioning, bounds that leave a gap (``LooseBoundWarning``).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "AerocontrolError",
    "AerocontrolLinAlgError",
    "AerocontrolWarning",
    "ConvergenceError",
    "IllConditionedError",
    "IllConditionedWarning",
    "InvalidArgumentError",
    "LooseBoundWarning",
    "NoContinuousEquivalentError",
    "NoStabilizingSolutionError",
    "NonFiniteError",
    "NotPositiveDefiniteError",
    "NotRealError",
    "NumericalOverflowWarning",
    "NumericalUnderflowWarning",
    "OutputFolderError",
    "ShapeError",
    "SingularMatrixError",
    "UncontrollableError",
]


class AerocontrolError(Exception):
    """Base class of every exception raised by aerocontrol.

    Errors raised by the native core carry their data as attributes; an attribute that does
    not apply is None.
    """

    argument: str | None = None
    """The name of the argument at fault (``"B"``, ``"poles"``), if one is."""
    batch_index: int | None = None
    """For a batch function: the index of the first problem that failed."""
    entry: list[int] | None = None
    """For a NonFiniteError: the index of the first entry that is NaN or infinite."""
    value: float | None = None
    """The value at fault: the non-finite entry, or the scalar out of its domain."""
    eigenvalues: list[complex] | None = None
    """For an UncontrollableError: the eigenvalues that no feedback can move."""


class InvalidArgumentError(AerocontrolError, ValueError):
    """An argument is outside its domain; the message names the argument."""


class ShapeError(InvalidArgumentError):
    """An argument has the wrong number of dimensions, is not square, or disagrees in size
    with another argument."""


class NonFiniteError(InvalidArgumentError):
    """An argument contains NaN or an infinity; the message names the first such entry."""


class NotPositiveDefiniteError(InvalidArgumentError):
    """A matrix that must be symmetric positive definite (the control weight R) is not; the
    message names it and says whether symmetry or definiteness fails."""


class NotRealError(AerocontrolError, TypeError):
    """An argument is complex or not numeric; aerocontrol works with real matrices only. Also
    raised where a model is expected and the argument is none (a number, a bare matrix)."""


class AerocontrolLinAlgError(AerocontrolError, np.linalg.LinAlgError):
    """A numerical condition (singularity, no stabilising solution, non-convergence) makes
    the problem unsolvable."""


class SingularMatrixError(AerocontrolLinAlgError):
    """A matrix that must be invertible is singular; the message names the zero eigenvalue
    (an integrator or neutral mode, for a plant matrix)."""


class UncontrollableError(AerocontrolLinAlgError):
    """A pair (A, B) is not controllable to the rank tolerance (or (A, C) not observable);
    the message names the eigenvalues that feedback cannot move."""


class NoStabilizingSolutionError(AerocontrolLinAlgError):
    """A Riccati equation has no stabilising solution: its Hamiltonian has eigenvalues on or
    too near the imaginary axis (an undamped mode that is neither controllable nor penalised),
    or its stable invariant subspace is not the graph of a matrix."""


class IllConditionedError(AerocontrolLinAlgError):
    """A step would lose every digit to ill-conditioning and was refused, for example the
    exchange of two Schur blocks with nearly equal eigenvalues."""


class NoContinuousEquivalentError(AerocontrolLinAlgError, InvalidArgumentError):
    """A discrete model has no real continuous model that the method asked maps to it: for the
    zero-order hold, A has an eigenvalue on the closed negative real axis (e^{A dt} never has
    one, and such an A has no real logarithm); for the bilinear transformation, A has an
    eigenvalue at the image of s = ∞ (-1 for Tustin's). The message names the eigenvalue.

    Both a ``LinAlgError`` (the matrix condition that fails) and an
    :class:`InvalidArgumentError` (the model is outside the domain of ``d2c``): ``argument``
    names the model (``"sys"``) and ``eigenvalues`` holds the eigenvalue at fault."""


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


class LooseBoundWarning(AerocontrolWarning, RuntimeWarning):
    """A quantity computable only within bounds (the structured singular value of a
    multiloop disk margin) has bounds further apart than the tolerance; the conservative
    bound was returned and the message gives both."""


class NumericalUnderflowWarning(AerocontrolWarning, RuntimeWarning):
    """A result is below the range of normal doubles: it was rounded to a subnormal number
    (fewer significant digits) or to zero. The message names the result, its size (as a
    power of ten) and what was returned in its place."""


class OutputFolderError(AerocontrolError, OSError):
    """An output folder cannot be written without touching files the command did not write
    (an ``OSError``): it is not empty and holds no earlier report, a file of the earlier
    report was changed since, a file is in the way, or another run is writing into it. The
    message is one line and names the folder or the file; nothing in the folder was changed."""
