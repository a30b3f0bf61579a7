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

The modal matrix P (unit eigenvectors as columns) diagonalises A, P^-1 A P = Λ (6.59), and
P^-1 B (6.61) shows which modes each input reaches: a zero row is a mode no input excites. A
defective A (a repeated eigenvalue without a full set of eigenvectors, such as a double
integrator) has no modal matrix: then ``modal_matrix`` and ``modal_input`` are None, and a
warning gives the condition number that showed it.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _core
from ._validation import FloatArray, real_array
from .exceptions import IllConditionedWarning, ShapeError
from .statespace import as_state_space, is_system

__all__ = ["Modes", "charpoly", "modes"]

ComplexArray = NDArray[np.complex128]


@dataclass(frozen=True, eq=False)
class Modes:
    """The modes of a plant matrix, ordered by increasing natural frequency.

    Per-mode arrays (one entry per mode; a conjugate pair counts once, by its member with
    Im λ > 0) sit beside the full eigenvalue list and the modal matrix. ``print(modes)`` shows
    a table like MATLAB's ``damp``, with time to half (or double) amplitude.
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
    """κ₂(P); above 1e8 P counts as singular."""
    modal_input: ComplexArray | None
    """P^-1 B (6.61), when B was given and P is not singular."""
    characteristic_polynomial: FloatArray
    """Coefficients of det(λI - A), highest power first."""
    mode_names: tuple[str, ...]
    """Labels for the table: 'mode 1', ... (aircraft models name them)."""

    def __len__(self) -> int:
        return len(self.eigenvalue)

    def table(self) -> str:
        """The table that ``str()`` prints."""
        header = (
            f"{'mode':<14}{'eigenvalue':>26}{'damping':>10}{'freq (rad/s)':>14}"
            f"{'period (s)':>12}{'t½ / t₂ (s)':>14}{'tau (s)':>10}"
        )
        lines = [header, "-" * len(header)]
        for k in range(len(self)):
            lam = self.eigenvalue[k]
            if self.oscillatory[k]:
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
            lines.append(
                f"{self.mode_names[k]:<14}{pole:>26}"
                f"{(f'{zeta:.4f}' if np.isfinite(zeta) else '-'):>10}"
                f"{self.natural_frequency[k]:>14.4f}{period:>12}{timing:>14}{tau:>10}"
            )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()

    def plot(self, ax: Any = None) -> Any:
        """The eigenvalues in the complex plane, labelled by mode (matplotlib)."""
        from .plotting import plot_modes

        return plot_modes(self, ax=ax)


def _plant(A_or_sys: Any) -> tuple[FloatArray, FloatArray | None]:
    """(A, B or None) from a plant matrix or a system."""
    if is_system(A_or_sys):
        sys = as_state_space(A_or_sys)
        return sys.A, sys.B
    if isinstance(A_or_sys, tuple):
        sys = as_state_space(A_or_sys)
        return sys.A, sys.B
    return real_array(A_or_sys, "A"), None


def modes(A_or_sys: Any, mode_names: list[str] | None = None) -> Modes:
    """The modes of A, or of a system's A (then with P^-1 B).

    Parameters
    ----------
    A_or_sys : array_like (n, n), StateSpace, (A, B) tuple, or object with A, B, C, D
        The plant matrix or the system.
    mode_names : list of str, optional
        Names for the modes in mode order, for the table.

    Examples
    --------
    >>> import aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_lateral()          # (6.150)
    >>> m = aerocontrol.modes(A, mode_names=["spiral", "Dutch roll", "roll"])
    >>> [round(float(w), 4) for w in m.natural_frequency]
    [0.0464, 0.7477, 1.2308]
    >>> round(float(m.damping_ratio[1]), 4)                      # Dutch roll, (6.153)
    0.1079
    """
    A, B = _plant(A_or_sys)
    result = _core.modal_analysis(A, B)
    count = len(result["mode_eigenvalue"])
    if mode_names is None:
        names = tuple(f"mode {k + 1}" for k in range(count))
    else:
        if len(mode_names) != count:
            raise ShapeError(f"mode_names must name {count} modes, got {len(mode_names)}")
        names = tuple(mode_names)
    singular = bool(result["modal_matrix_is_singular"])
    if singular:
        warnings.warn(
            f"the modal matrix P is singular (condition number "
            f"{result['modal_matrix_condition']:.2e}): A has a repeated eigenvalue without a "
            "full set of eigenvectors, so there is no modal decomposition; modal_matrix and "
            "modal_input are None",
            IllConditionedWarning,
            stacklevel=2,
        )
    return Modes(
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
        modal_matrix=None if singular else result["modal_matrix"],
        modal_matrix_condition=float(result["modal_matrix_condition"]),
        modal_input=result["modal_input"],
        characteristic_polynomial=result["characteristic_polynomial"],
        mode_names=names,
    )


def charpoly(A: Any) -> FloatArray:
    """Coefficients of det(λI - A), highest power first ([1, a_1, ..., a_n], (6.106)).

    Computed by La Budde's method (Rehman & Ipsen 2011): the balanced A is reduced to upper
    Hessenberg form H by orthogonal similarity, and det(λI - H) follows in real arithmetic from
    the characteristic polynomials of H's leading principal submatrices. No eigenvalues are
    computed, so ill-conditioned eigenvalues do not spoil the coefficients (for the Frank
    matrix of order 12 the result is exact, where multiplying out its computed eigenvalues
    errs by 1e-7 relatively). Accuracy: each a_k carries an absolute error of a modest
    multiple of u e_k(|λ|) on typical matrices (e_k the elementary symmetric function of the
    eigenvalue moduli; measured against 80-digit arithmetic on random, graded and non-normal
    matrices of orders 2 to 10); a coefficient that is small only by cancellation is
    correspondingly less accurate relatively. Never formed from powers of A (the Krylov or
    Faddeev-LeVerrier recurrences lose digits geometrically with n).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> A, _ = aerocontrol.chapter.boeing747_lateral()
    >>> np.round(aerocontrol.charpoly(A), 4)    # (6.155)
    array([1.    , 1.4385, 0.8222, 0.7232, 0.0319])
    """
    return _core.charpoly(A)
