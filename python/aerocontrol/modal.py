"""Modal analysis: eigenvalues, modes and their characteristics (chapter §6.4, (6.58)-(6.62),
(6.152)-(6.155)).

A conjugate pair of eigenvalues σ ± jω_d is one mode, an oscillation; a real eigenvalue is one
mode, a subsidence (σ < 0) or a divergence (σ > 0). For each mode:

==================  ======================================  =================================
natural frequency   ω_n = |λ|                               rad/s
damping ratio       ζ = -σ / |λ|                            (NaN for λ = 0)
damped frequency    ω_d = |Im λ|                            rad/s
period              T = 2π / ω_d                            s (inf for a real mode)
time to half        t½ = ln 2 / |σ|, decaying modes          s
time to double      t₂ = ln 2 / σ, growing modes             s
cycles to half      N½ = t½ / T                             (oscillations)
time constant       τ = 1 / |λ|                             s (real modes)
==================  ======================================  =================================

For a discrete model (a StateSpace with ``dt`` > 0) the eigenvalues z of A are reported as
they are, and the characteristics are those of the equivalent continuous mode s = ln(z)/dt
(principal logarithm): ω_n = |s|, ζ = -Re s/|s|, and so on, with the modes ordered by that
ω_n. A real z < 0 is an oscillation at the Nyquist frequency π/dt (period 2 dt) on its own; z
= 0 (a pure delay, a deadbeat mode) has s = -inf: infinite ω_n, ζ = 1, and a time to half and
a time constant of 0.

The modal matrix P (unit eigenvectors as columns) diagonalises A, P^-1 A P = Λ (6.59), and
P^-1 B (6.61) shows which modes each input reaches: a zero row is a mode no input excites. A
defective A (a repeated eigenvalue without a full set of eigenvectors, such as a double
integrator) has no modal matrix: then ``modal_matrix`` and ``modal_input`` are None, and a
warning gives the condition number that showed it.

Up to 16 states (``EAGER_VECTORS_MAX_ORDER``) one call computes everything. Above, ``modes``
computes the eigenvalues alone (the real Schur form without its transformation, about half the
work), and the modal matrix, its condition number and P^-1 B come on the first access to any
of the three, from a second analysis with the eigenvectors: the warning of a singular P is then
given at that access, not at the call.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._results import Result, Tabular
from ._validation import FloatArray, real_array
from .exceptions import AerocontrolError, IllConditionedWarning, ShapeError
from .statespace import is_system, name_sequence, plant_arrays

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ._typing import System

__all__ = ["Modes", "charpoly", "modes"]

ComplexArray = NDArray[np.complex128]


#: Up to this order ``modes`` computes the modal matrix, its condition number and P^-1 B with
#: the modes, in one call; above it, on the first access to any of the three (the
#: eigenvectors cost about as much again as the eigenvalues).
EAGER_VECTORS_MAX_ORDER = 16

#: The fields of :class:`Modes` that need the eigenvectors.
_MODAL_FIELDS = frozenset({"modal_matrix", "modal_matrix_condition", "modal_input"})


@dataclass(frozen=True, eq=False)
class Modes(Result):
    """The modes of a plant matrix, ordered by increasing natural frequency.

    Per-mode arrays (one entry per mode; a conjugate pair counts once, by its member with
    Im λ > 0) sit beside the full eigenvalue list and the modal matrix. ``print(modes)`` shows
    a table like MATLAB's ``damp``, with time to half (or double) amplitude.

    Attributes
    ----------
    eigenvalues : ndarray (n,), complex
        All n eigenvalues, each conjugate pair adjacent (Im > 0 first), in mode order.
    eigenvalue : ndarray (k,), complex
        One eigenvalue per mode (rad/s).
    oscillatory : ndarray (k,), bool
        Whether the mode is a complex pair.
    natural_frequency : ndarray (k,)
        ω_n = abs(λ) (rad/s).
    damping_ratio : ndarray (k,)
        ζ = -Re λ / ω_n.
    damped_frequency : ndarray (k,)
        ω_d = Im λ (rad/s); 0 for a real mode.
    period : ndarray (k,)
        2π/ω_d (s); inf for a real mode.
    time_to_half, time_to_double : ndarray (k,)
        ln 2 / abs(Re λ) (s) for a decaying (growing) mode; NaN otherwise.
    cycles_to_half : ndarray (k,)
        ``time_to_half`` / ``period``; NaN for a real mode.
    time_constant : ndarray (k,)
        1/abs(λ) of a real mode (s); NaN for a pair.
    modal_matrix : ndarray (n, n), complex, or None
        P, unit eigenvectors as columns in the order of ``eigenvalues``; None if A is defective.
    modal_matrix_condition : float
        κ₂(P), in the model's units. P counts as singular (None, with a warning) when the
        modal matrix of A with its states balanced (D⁻¹AD, D diagonal of powers of two) has
        κ₂ above 1e8: how near A is to a defective matrix in any units of the states, where
        κ₂(P) also grows with their spread (1e12 for simple, well-separated eigenvalues of
        states in units 10^±6 apart).
    modal_input : ndarray (n, m), complex, or None
        P^-1 B (6.61), when B was given and P is not singular. Above 16 states these three
        are computed on the first access to any of them (see the module documentation).
    characteristic_polynomial : ndarray (n + 1,)
        Coefficients of det(λI - A), highest power first.
    mode_names : tuple of str
        Labels for the table: 'mode 1', ... (aircraft models name them).

    Examples
    --------
    x'' + 0.4 x' + 4 x = 0: ω_n = 2 rad/s, ζ = 0.1, ω_d = √3.96, t½ = ln 2 / 0.2:

    >>> import numpy as np, aerocontrol
    >>> m = aerocontrol.modes([[0.0, 1.0], [-4.0, -0.4]])
    >>> m.natural_frequency, np.round(m.damping_ratio, 6), np.round(m.damped_frequency, 6)
    (array([2.]), array([0.1]), array([1.989975]))
    >>> np.round(m.time_to_half, 6), m.characteristic_polynomial
    (array([3.465736]), array([1. , 0.4, 4. ]))
    """

    eigenvalues: ComplexArray
    """All n eigenvalues, each conjugate pair adjacent (Im > 0 first), in mode order."""
    eigenvalue: ComplexArray
    """One eigenvalue per mode."""
    oscillatory: NDArray[np.bool_]
    natural_frequency: FloatArray
    damping_ratio: FloatArray
    damped_frequency: FloatArray
    period: FloatArray
    time_to_half: FloatArray
    time_to_double: FloatArray
    cycles_to_half: FloatArray
    time_constant: FloatArray
    modal_matrix: ComplexArray | None
    """P, unit eigenvectors as columns in the order of ``eigenvalues``; None if A is defective."""
    modal_matrix_condition: float
    """κ₂(P) in the model's units (P counts as singular by its balanced states' modal matrix)."""
    modal_input: ComplexArray | None
    """P^-1 B (6.61), when B was given and P is not singular."""
    characteristic_polynomial: FloatArray
    """Coefficients of det(λI - A), highest power first."""
    mode_names: tuple[str, ...]
    """Labels for the table: 'mode 1', ... (aircraft models name them)."""

    def __len__(self) -> int:
        return len(self.eigenvalue)

    def __getattr__(self, name: str) -> Any:
        """The modal matrix, its condition number and P^-1 B of an analysis of more than
        ``EAGER_VECTORS_MAX_ORDER`` states, computed on the first access to any of them (a
        second analysis with the eigenvectors, whose eigenvalues are checked to be these bit
        for bit), with the warning of a singular P then."""
        state = vars(self)
        if name not in _MODAL_FIELDS or "_plant" not in state:
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        A, B, dt = state["_plant"]
        result = _core.modal_analysis(A, B, True)
        if dt > 0.0:
            result = _equivalent_continuous(result, dt)
        if not np.array_equal(result["eigenvalues"], self.eigenvalues):
            raise AerocontrolError(
                "internal error: the eigenvalues of the analysis with eigenvectors differ from "
                "those of the modes"
            )  # pragma: no cover
        state.update(_modal_fields(result, stacklevel=3))
        del state["_plant"]
        return state[name]

    _HEADER = ("mode", "eigenvalue", "damping", "freq (rad/s)", "period (s)", "t½ / t₂ (s)")

    def _cells(self) -> list[tuple[str, ...]]:
        """The table's rows as text: name, eigenvalue, ζ, ω_n, period, t½ (or t₂) and τ."""
        rows: list[tuple[str, ...]] = []
        for k in range(len(self)):
            lam = self.eigenvalue[k]
            if self.oscillatory[k] and lam.imag != 0:
                pole = f"{lam.real:.5g} ± {abs(lam.imag):.5g}j"
            else:
                pole = f"{lam.real:.5g}"
            half = self.time_to_half[k]
            double = self.time_to_double[k]
            timing = (
                f"{half:.4g}"
                if np.isfinite(half)
                else (f"{double:.4g} (x2)" if np.isfinite(double) else "-")
            )
            period = f"{self.period[k]:.4g}" if np.isfinite(self.period[k]) else "-"
            tau = f"{self.time_constant[k]:.4g}" if np.isfinite(self.time_constant[k]) else "-"
            zeta = self.damping_ratio[k]
            rows.append(
                (
                    self.mode_names[k],
                    pole,
                    f"{zeta:.4f}" if np.isfinite(zeta) else "-",
                    f"{self.natural_frequency[k]:.4f}",
                    period,
                    timing,
                    tau,
                )
            )
        return rows

    def table(self) -> str:
        """The table that ``str()`` prints."""
        widths = (14, 26, 10, 14, 12, 14, 10)

        def line(cells: tuple[str, ...]) -> str:
            return f"{cells[0]:<14}" + "".join(
                f"{cell:>{width}}" for cell, width in zip(cells[1:], widths[1:], strict=True)
            )

        lines = [line((*self._HEADER, "tau (s)"))]
        lines.append("-" * len(lines[0]))
        lines += [line(row) for row in self._cells()]
        return "\n".join(lines)

    def _tables(self) -> list[Tabular]:
        return [Tabular("modes", (*self._HEADER, "τ (s)"), self._cells())]

    def __str__(self) -> str:
        return self.table()

    def plot(self, ax: Axes | None = None) -> Axes:
        """The eigenvalues in the complex plane, labelled by mode (matplotlib)."""
        from .plotting import plot_modes

        return plot_modes(self, ax=ax)


def _plant(A_or_sys: ArrayLike | System) -> tuple[FloatArray, FloatArray | None, float]:
    """(A, B or None, the sampling period: 0.0 for a continuous system or a matrix) from a
    plant matrix or a system."""
    if is_system(A_or_sys) or isinstance(A_or_sys, tuple):
        # The core checks A and B (see plant_arrays).
        A, B, _, _, dt = plant_arrays(A_or_sys)
        return A, B, dt
    return real_array(A_or_sys, "A"), None, 0.0


@functools.lru_cache(maxsize=64)
def _default_names(count: int) -> tuple[str, ...]:
    """'mode 1', 'mode 2', ... (an immutable tuple, shared by the results that use it)."""
    return tuple(f"mode {k + 1}" for k in range(count))


def _equivalent_continuous(result: dict[str, Any], dt: float) -> dict[str, Any]:
    """The modal analysis of a discrete A (eigenvalues z) with the characteristics of the
    equivalent continuous modes s = ln(z)/dt, reordered by their natural frequency (then by
    decreasing damping), eigenvalues, modal matrix columns and modal input rows alike (when the
    analysis has them)."""
    eigenvalues = result["eigenvalues"]
    groups = [list(range(first, last + 1)) for first, last in result["mode_indices"]]
    z = np.array([eigenvalues[group[0]] for group in groups], dtype=np.complex128)
    s = np.full(z.shape, complex(-np.inf, 0.0), dtype=np.complex128)
    s[z != 0] = np.log(z[z != 0]) / dt
    with np.errstate(invalid="ignore", divide="ignore"):
        sigma, omega_d = s.real, np.abs(s.imag)
        natural = np.abs(s)
        oscillatory = omega_d > 0
        damping = np.where(np.isinf(sigma), 1.0, -sigma / natural)
        damping = np.where(natural == 0, np.nan, damping)
        period = np.where(oscillatory, 2 * np.pi / np.where(oscillatory, omega_d, 1.0), np.inf)
        half = np.where(sigma < 0, np.log(2) / -sigma, np.nan)
        double = np.where(sigma > 0, np.log(2) / sigma, np.nan)
        cycles = np.where(oscillatory, half / period, np.nan)
        constant = np.where(oscillatory | (natural == 0), np.nan, 1.0 / natural)
    order = np.lexsort((-np.nan_to_num(damping, nan=-np.inf), natural))
    columns = [index for k in order for index in groups[k]]
    reordered = dict(result)
    if "modal_matrix" in result:
        modal_input = result["modal_input"]
        reordered["modal_matrix"] = result["modal_matrix"][:, columns]
        reordered["modal_input"] = None if modal_input is None else modal_input[columns]
    return {
        **reordered,
        "eigenvalues": eigenvalues[columns],
        "mode_eigenvalue": z[order],
        "oscillatory": oscillatory[order],
        "natural_frequency": natural[order],
        "damping_ratio": damping[order],
        "damped_frequency": omega_d[order],
        "period": period[order],
        "time_to_half": half[order],
        "time_to_double": double[order],
        "cycles_to_half": cycles[order],
        "time_constant": constant[order],
    }


def modes(A_or_sys: ArrayLike | System, mode_names: list[str] | None = None) -> Modes:
    """The modes of A, or of a system's A (then with P^-1 B). For a discrete system, the
    eigenvalues z of A with the characteristics of the equivalent continuous modes
    s = ln(z)/dt (see the module documentation).

    Parameters
    ----------
    A_or_sys : array_like (n, n), StateSpace, (A, B) tuple, or object with A, B, C, D
        The plant matrix or the system.
    mode_names : list of str, optional
        Names for the modes in mode order, for the table.

    Returns
    -------
    Modes
        Per mode (a conjugate pair once), ordered by increasing natural frequency: the
        eigenvalue, natural frequency, damping ratio, damped frequency, period, times to half
        (double) amplitude, cycles to half and time constant; with all n eigenvalues, the
        modal matrix P and its condition number, P^-1 B (6.61) for a system, and the
        characteristic polynomial.

    Raises
    ------
    ShapeError
        A is not square, or ``mode_names`` does not name every mode.
    NonFiniteError, NotRealError
        A contains NaN or an infinity, or is complex or not numeric.

    Examples
    --------
    >>> import aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()          # (6.150)
    >>> m = aerocontrol.modes(A, mode_names=["spiral", "Dutch roll", "roll"])
    >>> [round(float(w), 4) for w in m.natural_frequency]
    [0.0464, 0.7477, 1.2308]
    >>> round(float(m.damping_ratio[1]), 4)                      # Dutch roll, (6.153)
    0.1079
    >>> lateral = aerocontrol.c2d(aerocontrol.StateSpace(A, B), 0.05)   # sampled at 20 Hz
    >>> [round(float(w), 4) for w in aerocontrol.modes(lateral).natural_frequency]
    [0.0464, 0.7477, 1.2308]
    """
    A, B, dt = _plant(A_or_sys)
    vectors = A.shape[0] <= EAGER_VECTORS_MAX_ORDER
    result = _core.modal_analysis(A, B, vectors)
    if dt > 0.0:
        result = _equivalent_continuous(result, dt)
    count = len(result["mode_eigenvalue"])
    if mode_names is None:
        names = _default_names(count)
    else:
        names = name_sequence(mode_names, "mode_names")
        if len(names) != count:
            raise ShapeError(f"mode_names must name {count} modes, got {len(names)}")
    # The frozen dataclass's __init__ sets each of the 16 fields through object.__setattr__,
    # which costs half of the analysis of a 4-state A; filling the instance dictionary
    # directly is the same object.
    analysis = object.__new__(Modes)
    vars(analysis).update(
        eigenvalues=result["eigenvalues"],
        eigenvalue=result["mode_eigenvalue"],
        oscillatory=np.asarray(result["oscillatory"], dtype=bool),
        natural_frequency=result["natural_frequency"],
        damping_ratio=result["damping_ratio"],
        damped_frequency=result["damped_frequency"],
        period=result["period"],
        time_to_half=result["time_to_half"],
        time_to_double=result["time_to_double"],
        cycles_to_half=result["cycles_to_half"],
        time_constant=result["time_constant"],
        characteristic_polynomial=result["characteristic_polynomial"],
        mode_names=names,
    )
    if vectors:
        vars(analysis).update(_modal_fields(result, stacklevel=3))
    else:
        # Copies: the caller may change its arrays before the first access.
        vars(analysis)["_plant"] = (A.copy(), None if B is None else B.copy(), dt)
    return analysis


def _modal_fields(result: dict[str, Any], stacklevel: int) -> dict[str, Any]:
    """The modal matrix, its condition number and P^-1 B of a full analysis, with the warning
    of a singular P (at ``stacklevel``)."""
    singular = bool(result["modal_matrix_is_singular"])
    if singular:
        warnings.warn(
            f"the modal matrix P is singular (condition number "
            f"{result['balanced_modal_matrix_condition']:.2e} with the states balanced): A has "
            "a repeated eigenvalue without a "
            "full set of eigenvectors, so there is no modal decomposition; modal_matrix and "
            "modal_input are None",
            IllConditionedWarning,
            stacklevel=stacklevel,
        )
    return {
        "modal_matrix": None if singular else result["modal_matrix"],
        "modal_matrix_condition": float(result["modal_matrix_condition"]),
        "modal_input": result["modal_input"],
    }


def charpoly(A: ArrayLike) -> FloatArray:
    """Coefficients of det(λI - A), highest power first ([1, a_1, ..., a_n], (6.106)).

    Computed by La Budde's method (Rehman & Ipsen 2011): the balanced A is reduced to upper
    Hessenberg form H by orthogonal similarity, and det(λI - H) follows in real arithmetic from
    the characteristic polynomials of H's leading principal submatrices. No eigenvalues are
    computed, so ill-conditioned eigenvalues do not spoil the coefficients (for the Frank
    matrix of order 12 the result is exact, where multiplying out its computed eigenvalues
    errs by 1e-7 relatively). Accuracy: each a_k carries an absolute error of a modest
    multiple of u e_k(abs(λ)) on typical matrices (e_k the elementary symmetric function of the
    eigenvalue moduli; measured against 80-digit arithmetic on random, graded and non-normal
    matrices of orders 2 to 10); a coefficient that is small only by cancellation is
    correspondingly less accurate relatively. Never formed from powers of A (the Krylov or
    Faddeev-LeVerrier recurrences lose digits geometrically with n).

    Parameters
    ----------
    A : array_like (n, n)

    Returns
    -------
    ndarray (n + 1,)
        [1, a_1, ..., a_n].

    Raises
    ------
    ShapeError
        A is not square.
    NonFiniteError, NotRealError
        A contains NaN or an infinity, or is complex.

    References
    ----------
    R. Rehman and I. C. F. Ipsen, "La Budde's method for computing characteristic
    polynomials", 2011.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> aerocontrol.charpoly([[0, 1], [-2, -3]])     # λ² + 3λ + 2
    array([1., 3., 2.])
    >>> A, _ = aerocontrol.chapter.boeing747_lateral()
    >>> np.round(aerocontrol.charpoly(A), 4)    # (6.155)
    array([1.    , 1.4385, 0.8222, 0.7232, 0.0319])
    """
    return _core.charpoly(A)
