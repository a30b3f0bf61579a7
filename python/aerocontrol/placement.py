"""Pole placement by state feedback (chapter §6.5, (6.90)-(6.165)).

The control law η = -K x + η' (6.91) turns x' = A x + B η into x' = (A - B K) x + B η'
(6.93). Given the desired closed-loop poles:

* :func:`place_bass_gura`: the chapter's single-input method, k = ((VW)^-1)^T (ā - a)
  (6.145), by a triangular solve and an LU solve, never an inverse;
* :func:`place_ackermann`: k^T = e_n^T V^-1 φ(A), an independent single-input check;
* :func:`place`: several inputs, by the robust method of Kautsky, Nichols & Van Dooren (1985,
  method 0), which spends the freedom of a multi-input gain on a well-conditioned closed-loop
  eigenvector matrix; a pole may repeat up to rank(B) times.

Every function returns a :class:`Placement` with K (m x n), A - BK, the achieved poles and
their largest relative error. The single-input formulas are only as accurate as the
controllability matrix V is well conditioned; they warn (``IllConditionedWarning``) when
κ(V) >= 1e8 or an achieved pole misses by more than 1e-6 relatively. A pair whose states are
scaled far apart (a state's largest off-diagonal entries of A in its row and its column more
than 2^10 apart: units 10^3 or more apart) is placed by the core in balanced coordinates,
T A T^-1 and T B with T diagonal of powers of two (exact), and K = K' T (the same closed-loop
poles; κ and the errors are those of the balanced problem);
:func:`aerocontrol.batch.place_batch` balances each problem alike.

:func:`augment_mode` builds the chapter's design request (6.156): the pole set that moves one
mode (the Dutch roll to ζ = 0.30 at its ω_n, say) and keeps every other pole.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._results import Result, Tabular, attach
from ._validation import FloatArray, real_array, real_scalar
from .exceptions import InvalidArgumentError, ShapeError
from .modal import Modes, modes
from .statespace import (
    StateSpace,
    as_state_space,
    is_float_matrix,
    is_system,
    plant_pair,
    require_continuous,
)

if TYPE_CHECKING:
    from ._typing import ModeKey, System

__all__ = [
    "CompanionForm",
    "Placement",
    "augment_mode",
    "companion_form",
    "place",
    "place_ackermann",
    "place_bass_gura",
]

ComplexArray = NDArray[np.complex128]

#: κ(V) from which the single-input gains are flagged: beyond 1e8 about half the digits of
#: the gains may be lost to the conditioning of the controllability matrix.
ILL_CONDITIONED_CONTROLLABILITY: float = _core.ILL_CONDITIONED_CONTROLLABILITY
#: Achieved-pole relative error from which any placement is flagged.
POLE_ERROR_WARNING: float = _core.POLE_ERROR_WARNING


#: The result of every placement function: a state-feedback design η = -K x (6.91), with
#: K (m x n), ``closed_loop`` A - BK (6.93), the requested ``poles`` and the
#: ``achieved_poles`` matched to them, ``max_relative_error``, ``iterations`` and ``converged``
#: of the robust method, the ``method``'s name, ``controllability_condition`` κ_1(V) (the
#: single-input formulas) and ``eigenvector_condition`` κ_2(X) (the robust method), and ``k``,
#: the gain vector of a single-input design. Built by the core (a frozen class; pickles).
Placement = _core.Placement


def _describe(design: Placement) -> str:
    """``str(design)``: the gains and the requested and achieved poles side by side."""
    lines = [f"pole placement ({design.method}), K = {np.array2string(design.K, precision=6)}"]
    lines.append(f"{'requested':>28}{'achieved':>28}")
    for want, got in zip(design.poles, design.achieved_poles, strict=True):
        lines.append(f"{complex(want):>28.6g}{complex(got):>28.6g}")
    lines.append(f"largest relative pole error {design.max_relative_error:.2e}")
    return "\n".join(lines)


def _placement_tables(design: Placement) -> list[Tabular]:
    """The gains and the requested and achieved poles as tables, formatted as ``str`` does."""
    # K's entries as ``str`` prints them: numpy's array2string of the whole K at precision 6
    # (one notation for every entry), split into its entries.
    text = np.array2string(design.K, precision=6, threshold=design.K.size + 1)
    entries = np.array(text.replace("[", " ").replace("]", " ").split()).reshape(design.K.shape)
    gain = [(f"u{i + 1}", *row) for i, row in enumerate(entries.tolist())]
    header = ("K", *(f"x{j + 1}" for j in range(design.K.shape[1])))
    poles = [
        (f"{complex(want):.6g}", f"{complex(got):.6g}")
        for want, got in zip(design.poles, design.achieved_poles, strict=True)
    ]
    return [
        Tabular(f"pole placement ({design.method})", header, gain),
        Tabular(
            "",
            ("requested", "achieved"),
            poles,
            [f"largest relative pole error {design.max_relative_error:.2e}"],
        ),
    ]


Placement._tables = _placement_tables  # type: ignore[attr-defined]
attach(
    Placement,
    (
        "K",
        "closed_loop",
        "poles",
        "achieved_poles",
        "max_relative_error",
        "iterations",
        "converged",
        "method",
        "controllability_condition",
        "eigenvector_condition",
    ),
)
Placement.__doc__ = """A state-feedback design η = -K x (6.91), from :func:`place`,
:func:`place_ackermann` or :func:`place_bass_gura`.

Attributes
----------
K : ndarray (m, n)
    The gain: η = -K x places the eigenvalues of A - B K.
k : ndarray (n,)
    The gain vector of a single-input design (the chapter's k^T = ``K[0]``).
closed_loop : ndarray (n, n)
    A - B K (6.93).
poles : ndarray (n,), complex
    The requested poles.
achieved_poles : ndarray (n,), complex
    The eigenvalues of A - B K, matched to ``poles``.
max_relative_error : float
    max abs(achieved - requested) / abs(requested) (relative to ||A - BK||_F for a pole
    at 0).
iterations : int
    Sweeps of the robust method (0 for a direct one).
converged : bool
    Whether the robust method's sweeps converged.
method : str
    The method that computed K.
controllability_condition : float
    κ_1(V) of the controllability matrix, from the single-input formulas (NaN for the
    robust method).
eigenvector_condition : float
    κ_2(X) of the closed loop's eigenvectors, from the robust method: large means the placed
    poles are sensitive.

Examples
--------
The double integrator placed at -1 and -2: A - B K has the characteristic polynomial
s² + 3 s + 2, so K = [2, 3]:

>>> import numpy as np, aerocontrol
>>> design = aerocontrol.place([[0, 1], [0, 0]], [[0], [1]], [-1.0, -2.0])
>>> design.K, design.k
(array([[2., 3.]]), array([2., 3.]))
>>> design.closed_loop
array([[ 0.,  1.],
       [-2., -3.]])
>>> design.achieved_poles, bool(design.max_relative_error < 1e-14)
(array([-1.+0.j, -2.+0.j]), True)
"""


def _poles(poles: object) -> ComplexArray:
    """Requested poles as a contiguous complex vector (the core calls this for anything that
    is not one already). As python-control reads them, a single number is one pole and a 2-D
    array of one row or one column (``numpy.matrix`` included) is the list of its entries;
    any other 2-D array is refused by name."""
    if isinstance(poles, np.matrix):
        poles = poles.view(np.ndarray)
    try:
        array = np.asarray(poles, dtype=np.complex128)
    except (TypeError, ValueError) as error:
        raise InvalidArgumentError(f"poles must be numbers: {error}") from None
    if array.ndim == 0 or (array.ndim == 2 and 1 in array.shape):
        array = array.reshape(-1)
    if array.ndim != 1:
        raise ShapeError(
            f"poles must be a 1-D sequence (or one row or column), got an array of shape "
            f"{array.shape}"
        )
    return np.ascontiguousarray(array)


def _placement_arguments(
    A_or_sys: ArrayLike | System, B: ArrayLike | None, poles: ArrayLike | None
) -> tuple[FloatArray, FloatArray, ArrayLike]:
    """(A, B, poles) of ``place*(A, B, poles)`` or ``place*(sys, poles)``: A and B read as
    matrices (a 1-D B a column), the poles as a vector (:func:`_poles`). The core calls this
    for any call but the common one, of two 2-D float64 arrays and the poles as a sequence or
    a vector, which it reads as given."""
    A: ArrayLike
    B_matrix: ArrayLike
    if poles is not None and is_float_matrix(A_or_sys) and is_float_matrix(B):
        A, B_matrix = A_or_sys, B  # the common call, of two float matrices: no conversion
    elif poles is None:
        A, B_given = plant_pair(A_or_sys, None, "B")
        A, B_matrix = plant_pair(A, B_given, "B")
        poles = B
    else:
        A, B_matrix = plant_pair(A_or_sys, B, "B")
    if isinstance(poles, np.ndarray) and poles.dtype == np.complex128 and poles.ndim != 1:
        # The core reads a complex128 array as it is; anything else it converts by _poles
        # itself, after copying A and B (a conversion that runs the caller's code cannot
        # change them under it).
        poles = _poles(poles)
    return cast("FloatArray", A), cast("FloatArray", B_matrix), cast("ArrayLike", poles)


def place_bass_gura(
    A_or_sys: ArrayLike | System, b: ArrayLike | None = None, poles: ArrayLike | None = None
) -> Placement:
    """Single-input pole placement by the Bass-Gura formula (6.145).

    k = ((VW)^-1)^T (ā - a), with V the controllability matrix (6.125), W the Toeplitz matrix of
    the open-loop coefficients a (6.131) and ā the desired coefficients (6.114), computed as
    W^T z = ā - a and V^T k = z.

    Parameters
    ----------
    A_or_sys : array_like (n, n), or a system with A and a single-input B
        With a system, the poles come second: ``place_bass_gura(sys, poles)``.
    b : array_like (n,) or (n, 1)
    poles : sequence of n numbers; complex ones in conjugate pairs
        Any multiplicity is accepted.

    Returns
    -------
    Placement
        The gain ``K`` (1 x n) and the vector ``k`` of η = -k^T x (6.91), the closed loop
        A - b k^T (6.93), the requested and achieved poles, their largest relative error and
        κ_1(V) (``controllability_condition``).

    Raises
    ------
    UncontrollableError
        naming the eigenvalues that b cannot move.
    InvalidArgumentError
        b has more than one column (use :func:`place`), a pole is not a number, a complex
        pole has no conjugate among the poles, or b is given with a system.
    ShapeError
        A is not square, b has not n rows, or ``poles`` is not a 1-D sequence of n numbers.
    NonFiniteError, NotRealError
        A, b or a pole is NaN or infinite, or A or b is complex.

    Warns
    -----
    IllConditionedWarning
        κ(V) >= 1e8, or an achieved pole misses by more than 1e-6 relatively.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, b = [[-3, 8], [0, 0]], [0, 4]                     # (6.95)
    >>> wn, zeta = 25.0, 0.707
    >>> s = complex(-zeta * wn, wn * np.sqrt(1 - zeta**2))
    >>> design = aerocontrol.place_bass_gura(A, b, [s, s.conjugate()])
    >>> np.round(design.k, 5)                                # (6.102)
    array([16.49844,  8.0875 ])
    """
    return _core.place(A_or_sys, b, poles, "bass-gura")


def place_ackermann(
    A_or_sys: ArrayLike | System, b: ArrayLike | None = None, poles: ArrayLike | None = None
) -> Placement:
    """Single-input pole placement by Ackermann's formula k^T = e_n^T V^-1 φ(A).

    φ is the desired characteristic polynomial; V^T w = e_n is solved by LU and φ(A)^T w is
    evaluated by Horner's rule on vectors, so φ(A) is never formed. Same arguments as
    :func:`place_bass_gura`, and the same gains in exact arithmetic.

    Parameters
    ----------
    A_or_sys : array_like (n, n), or a system with A and a single-input B
        With a system, the poles come second: ``place_ackermann(sys, poles)``.
    b : array_like (n,) or (n, 1)
    poles : sequence of n numbers; complex ones in conjugate pairs
        Any multiplicity is accepted.

    Returns
    -------
    Placement
        The gain ``K`` (1 x n) and the vector ``k``, the closed loop A - b k^T, the requested
        and achieved poles, their largest relative error and κ_1(V).

    Raises
    ------
    UncontrollableError
        naming the eigenvalues that b cannot move.
    InvalidArgumentError
        b has more than one column (use :func:`place`), a pole is not a number, a complex
        pole has no conjugate among the poles, or b is given with a system.
    ShapeError
        A is not square, b has not n rows, or ``poles`` is not a 1-D sequence of n numbers.
    NonFiniteError, NotRealError
        A, b or a pole is NaN or infinite, or A or b is complex.

    Warns
    -----
    IllConditionedWarning
        κ(V) >= 1e8, or an achieved pole misses by more than 1e-6 relatively.

    See Also
    --------
    place_bass_gura : the chapter's formula (6.145), the same gains.

    Examples
    --------
    s^2 + 3 s + 2 to (s + 5)(s + 6) = s^2 + 11 s + 30: this A is in companion form, so
    k = [30 - 2, 11 - 3].

    >>> import aerocontrol
    >>> design = aerocontrol.place_ackermann([[0, 1], [-2, -3]], [0, 1], [-5, -6])
    >>> design.k
    array([28.,  8.])
    """
    return _core.place(A_or_sys, b, poles, "ackermann")


def place(
    A_or_sys: ArrayLike | System, B: ArrayLike | None = None, poles: ArrayLike | None = None
) -> Placement:
    """Pole placement for one or several inputs, by Kautsky-Nichols-Van Dooren method 0.

    The eigenvector of each pole is chosen in its admissible subspace to make the closed-loop
    eigenvector matrix X as well conditioned as the method can (abs(det X) maximised column by
    column, sweeps until it grows by less than 1e-3 relatively, at most 100); a robustly
    placed pole moves little under perturbations of A and B. ``eigenvector_condition`` reports
    κ_2(X).

    Parameters
    ----------
    A_or_sys : array_like (n, n), or a system with A and B
        With a system, the poles come second: ``place(sys, poles)``.
    B : array_like (n, m), full column rank, no zero column
    poles : sequence of n numbers; complex ones in conjugate pairs; each at most rank(B) times

    Returns
    -------
    Placement
        The gain ``K`` (m x n) of η = -K x, the closed loop A - B K, the requested and
        achieved poles, their largest relative error, the sweeps taken (``iterations``,
        ``converged``) and κ_2(X) (``eigenvector_condition``).

    Raises
    ------
    UncontrollableError
        naming the eigenvalues that B cannot move.
    InvalidArgumentError
        B has a zero column or dependent columns, a pole is repeated more than rank(B) times,
        a pole is not a number, a complex pole has no conjugate among the poles, or B is
        given with a system.
    ShapeError
        A is not square, B is not 2-D with n rows, or ``poles`` is not a 1-D sequence of n
        numbers.
    NonFiniteError, NotRealError
        A, B or a pole is NaN or infinite, or A or B is complex.

    Warns
    -----
    IllConditionedWarning
        An achieved pole misses by more than 1e-6 relatively.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()      # rudder and aileron
    >>> design = aerocontrol.place(A, B, [-0.5 + 0.8j, -0.5 - 0.8j, -1.2, -0.1])
    >>> design.K.shape, bool(design.max_relative_error < 1e-12)
    ((2, 4), True)
    """
    return _core.place(A_or_sys, B, poles, "knv0")


@dataclass(frozen=True, eq=False)
class CompanionForm(Result):
    """The transformation z = T x to the first companion form (6.116)-(6.145).

    Attributes
    ----------
    V : ndarray (n, n)
        The controllability matrix [b, A b, ..., A^(n-1) b] (6.125).
    W : ndarray (n, n)
        The upper triangular Toeplitz matrix of the coefficients (6.131).
    T : ndarray (n, n)
        (VW)^-1 (6.144), so that z = T x.
    companion : ndarray (n, n)
        T A T^-1, the first companion form (6.116), built from the coefficients: first row
        [-a_1, ..., -a_n], ones on the subdiagonal.
    coefficients : ndarray (n + 1,)
        [1, a_1, ..., a_n] of det(λI - A) (6.106).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> form = aerocontrol.companion_form([[-1, 0], [0, -2]], [1, 1])
    >>> form.coefficients                                 # (λ + 1)(λ + 2)
    array([1., 3., 2.])
    >>> np.round(form.companion, 6)
    array([[-3., -2.],
           [ 1.,  0.]])
    >>> np.round(form.T, 6)
    array([[-1.,  2.],
           [ 1., -1.]])
    """

    V: FloatArray
    """The controllability matrix (6.125)."""
    W: FloatArray
    """The upper triangular Toeplitz matrix of the coefficients (6.131)."""
    T: FloatArray
    """(VW)^-1 (6.144)."""
    companion: FloatArray
    """T A T^-1, the first companion form (6.116), built from the coefficients."""
    coefficients: FloatArray
    """[1, a_1, ..., a_n] of det(λI - A) (6.106)."""


def companion_form(A_or_sys: ArrayLike | System, b: ArrayLike | None = None) -> CompanionForm:
    """The first companion form of a controllable single-input pair (6.116)-(6.145).

    Parameters
    ----------
    A_or_sys : array_like (n, n), or a system with A and a single-input B
    b : array_like (n,) or (n, 1), optional
        Required with a matrix A; taken from the system otherwise.

    Returns
    -------
    CompanionForm
        V (6.125), W (6.131), T = (VW)^-1 (6.144), the companion form T A T^-1 (6.116) and
        the coefficients [1, a_1, ..., a_n] of det(λI - A) (6.106).

    Raises
    ------
    UncontrollableError
        (A, b) is not controllable (the eigenvalues b cannot move are named): T does not exist.
    InvalidArgumentError
        b has more than one column, or is given with a system.
    ShapeError
        A is not square or b has not n rows.
    NonFiniteError, NotRealError
        A or b contains NaN or an infinity, or is complex.

    Examples
    --------
    det(λI - A) = λ^2 + 3 λ + 2:

    >>> import aerocontrol
    >>> form = aerocontrol.companion_form([[0, 1], [-2, -3]], [0, 1])
    >>> form.companion
    array([[-3., -2.],
           [ 1.,  0.]])
    >>> form.coefficients
    array([1., 3., 2.])
    """
    A, b = plant_pair(A_or_sys, b, "B")
    result = _core.companion_form(A, b)
    return CompanionForm(
        V=result["V"],
        W=result["W"],
        T=result["T"],
        companion=result["companion"],
        coefficients=result["coefficients"],
    )


def _select_mode(analysis: Modes, mode: object) -> int:
    """The index of a mode given by index, name, or (approximate) eigenvalue."""
    count = len(analysis)
    if count == 0:
        raise InvalidArgumentError("the system has no modes (no states): nothing to augment")
    if isinstance(mode, str):
        names = [name.lower() for name in analysis.mode_names]
        if mode.lower() not in names:
            raise InvalidArgumentError(
                f"mode {mode!r} is not one of the modes {list(analysis.mode_names)}"
            )
        return names.index(mode.lower())
    if isinstance(mode, (int, np.integer)) and not isinstance(mode, bool):
        if not -count <= mode < count:
            raise InvalidArgumentError(f"mode index {mode} is out of range for {count} modes")
        return int(mode) % count
    if isinstance(mode, (float, complex, np.floating, np.complexfloating)):
        value = complex(mode)
        distances = np.abs(analysis.eigenvalue - complex(value.real, abs(value.imag)))
        return int(np.argmin(distances))
    raise InvalidArgumentError(
        f"mode must be a mode index, a mode name or an eigenvalue, got {mode!r}"
    )


def augment_mode(
    sys_or_A: ArrayLike | System | Modes,
    mode: ModeKey,
    zeta: float | None = None,
    omega_n: float | None = None,
) -> ComplexArray:
    """The desired pole set of (6.156): one mode changed, every other pole kept.

    Parameters
    ----------
    sys_or_A : system, plant matrix, or :class:`~aerocontrol.Modes`
    mode : int, str or complex
        The mode to change: its index in mode order (increasing natural frequency), its name
        (with named modes), or an eigenvalue near it.
    zeta, omega_n : float, optional
        The new damping ratio and natural frequency of an oscillatory mode; either defaults to
        the mode's present value. For a real mode give ``omega_n`` only: the new pole is
        -omega_n. A ζ >= 1 splits the pair into two real poles -ζω_n ± ω_n sqrt(ζ² - 1).

    Returns
    -------
    ndarray (n,) of complex128
        The open-loop eigenvalues with the chosen ones replaced.

    Raises
    ------
    InvalidArgumentError
        ``mode`` names no mode, is out of range or is of another type; ``omega_n`` is not
        positive and finite; ``zeta`` is negative or not finite, or given for a real mode;
        the system has no states; or the system is discrete (place z = e^{s dt} instead).
    ShapeError
        A is not square.
    NonFiniteError, NotRealError
        A contains NaN or an infinity, or is complex.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, _ = aerocontrol.chapter.boeing747_lateral()
    >>> poles = aerocontrol.augment_mode(A, 1, zeta=0.30)           # the Dutch roll
    >>> np.round(np.poly(poles).real, 4)                            # (6.156)
    array([1.    , 1.7258, 1.1891, 0.7396, 0.0319])

    A real mode moves to -omega_n:

    >>> aerocontrol.augment_mode([[0, 1], [-2, -3]], 0, omega_n=4.0)      # poles -1, -2
    array([-4.+0.j, -2.+0.j])
    """
    analysis = sys_or_A if isinstance(sys_or_A, Modes) else modes(_plant_matrix(sys_or_A))
    k = _select_mode(analysis, mode)
    eigenvalue = complex(analysis.eigenvalue[k])
    wn = analysis.natural_frequency[k] if omega_n is None else real_scalar(omega_n, "omega_n")
    if wn <= 0 or not np.isfinite(wn):
        raise InvalidArgumentError(f"omega_n must be positive and finite, got {wn}")
    if analysis.oscillatory[k]:
        z = analysis.damping_ratio[k] if zeta is None else real_scalar(zeta, "zeta")
        if not np.isfinite(z) or z < 0:
            raise InvalidArgumentError(f"zeta must be finite and non-negative, got {z}")
        if z < 1:
            root = complex(-z * wn, wn * np.sqrt(1 - z * z))
            new = [root, root.conjugate()]
        else:
            spread = wn * np.sqrt(z * z - 1)
            new = [complex(-z * wn + spread), complex(-z * wn - spread)]
        old = [eigenvalue, eigenvalue.conjugate()]
    else:
        if zeta is not None:
            raise InvalidArgumentError(
                f"mode {k} is real (eigenvalue {eigenvalue.real:.6g}): it has no damping "
                "ratio; give omega_n (the new pole is -omega_n)"
            )
        new, old = [complex(-wn)], [eigenvalue]
    poles = np.array(analysis.eigenvalues, dtype=np.complex128)
    for before, after in zip(old, new, strict=True):
        position = int(np.argmin(np.abs(poles - before)))
        poles[position] = after
    return poles


def _plant_matrix(sys_or_A: ArrayLike | System) -> FloatArray:
    """A of a continuous system, or the matrix given (augment_mode's new poles are in the s
    plane)."""
    if (isinstance(sys_or_A, (StateSpace, tuple, list)) and not _is_matrix(sys_or_A)) or (
        is_system(sys_or_A)
    ):
        model = as_state_space(sys_or_A)
        require_continuous(model, "augment_mode", "place the poles z = e^{s dt} instead")
        return model.A
    return real_array(sys_or_A, "A")


def _is_matrix(value: object) -> bool:
    """Whether a list or tuple is a nested list of numbers (a matrix), not (A, B)."""
    try:
        return np.asarray(value, dtype=np.float64).ndim == 2
    except (TypeError, ValueError):
        return False
