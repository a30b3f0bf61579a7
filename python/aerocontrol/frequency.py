"""Frequency response G(jω) = C (jωI - A)^-1 B + D and Bode plots (chapter §6.3).

The Rust core reduces A to Hessenberg form once and solves each frequency in O(n^2) (see
``rust/freq.rs``). :func:`bode` chooses a default grid from the modes: 1000 log-spaced
frequencies from a tenth of the slowest to ten times the fastest natural frequency.

A discrete model sampled every dt has the frequency response G(e^{jω dt}) =
C (e^{jω dt} I - A)^-1 B + D, periodic in ω with period 2π/dt; its default grid runs from a
tenth of the slowest natural frequency of the equivalent continuous model s = ln(z)/dt to the
Nyquist frequency π/dt.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._balance import balanced_matrices
from ._results import Result
from ._validation import FloatArray, real_array
from .exceptions import InvalidArgumentError, ShapeError
from .responses import _slow_modes
from .statespace import (
    StateSpace,
    as_state_space,
    continuous_eigenvalues,
    grid_frequencies,
    period,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ._typing import System

__all__ = ["FrequencyResponse", "bode", "default_frequency_grid", "frequency_response"]

DEFAULT_FREQUENCIES = 1000


@dataclass(frozen=True, eq=False)
class FrequencyResponse(Result):
    """G(jω) at the frequencies ``omega`` (rad/s): ``response`` is (len(omega), p, m).

    Attributes
    ----------
    omega : ndarray (k,)
        The frequencies (rad/s).
    response : ndarray (k, p, m), complex
        G(jω) (G(e^{jω dt}) for a discrete model), output by input at each frequency.
    input_names, output_names : tuple of str
        The model's channel names.
    magnitude : ndarray (k, p, m)
        abs(G(jω)).
    magnitude_db : ndarray (k, p, m)
        20 log10 abs(G(jω)) in decibels.
    phase : ndarray (k, p, m)
        arg G(jω) in radians, unwrapped along the frequencies.
    phase_deg : ndarray (k, p, m)
        The unwrapped phase in degrees.

    Examples
    --------
    1/(s + 1) at ω = 0 and at its corner ω = 1 rad/s (-3.01 dB, -45°):

    >>> import numpy as np, aerocontrol
    >>> r = aerocontrol.frequency_response(aerocontrol.tf([1.0], [1.0, 1.0]), [0.0, 1.0])
    >>> r.response.shape
    (2, 1, 1)
    >>> np.round(r.magnitude_db[:, 0, 0], 4), np.round(r.phase_deg[:, 0, 0], 6)
    (array([ 0.    , -3.0103]), array([  0., -45.]))
    """

    omega: FloatArray
    response: NDArray[np.complex128]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]

    @property
    def magnitude(self) -> FloatArray:
        """abs(G(jω)), the magnitude."""
        return np.abs(self.response)

    @property
    def magnitude_db(self) -> FloatArray:
        """20 log10 abs(G(jω)) in decibels."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(self.magnitude)

    @property
    def phase(self) -> FloatArray:
        """arg G(jω) in radians, unwrapped along the frequencies."""
        return np.unwrap(np.angle(self.response), axis=0)

    @property
    def phase_deg(self) -> FloatArray:
        """The unwrapped phase in degrees."""
        return np.degrees(self.phase)

    def __str__(self) -> str:
        if len(self.omega) == 0:
            return "frequency response: no frequencies"
        lines = [
            f"frequency response: {len(self.omega)} frequencies, "
            f"{self.omega.min():.4g} ... {self.omega.max():.4g} rad/s"
        ]
        for i, out in enumerate(self.output_names):
            for j, inp in enumerate(self.input_names):
                k = int(np.argmax(self.magnitude[:, i, j]))
                lines.append(
                    f"  {inp} -> {out}: peak {self.magnitude_db[k, i, j]:.2f} dB "
                    f"at {self.omega[k]:.4g} rad/s"
                )
        return "\n".join(lines)

    def plot(
        self, ax: Iterable[Axes] | None = None, output: int = 0, input: int = 0
    ) -> tuple[Axes, Axes]:
        """Bode plot (magnitude in dB and phase in degrees) of one input-output pair;
        ``ax`` is a pair of axes."""
        from .plotting import plot_bode

        return plot_bode(self, ax=ax, output=output, input=input)


#: A discrete model's A is evaluated about z = 1 (:func:`_response_about_one`) where
#: ||A - I||_1 is below 2^-CLUSTER_EXPONENT ||A||_1.
CLUSTER_EXPONENT = 10


def _clustered_at_one(A: FloatArray) -> bool:
    """Whether A is within 2^-10 of the identity relative to its norm (1-norms): a model
    sampled fast against its modes (A = e^{A_c dt} with ||A_c|| dt small), whose
    eigenvalues cluster about z = 1."""
    n = A.shape[0]
    if n == 0 or not np.all(np.isfinite(A)):
        return False
    norm = float(np.abs(A).sum(axis=0).max())
    distance = float(np.abs(A - np.eye(n)).sum(axis=0).max())
    return distance < norm * 2.0**-CLUSTER_EXPONENT


def _response_about_one(model: StateSpace, frequencies: FloatArray) -> NDArray[np.complex128]:
    """G(z) = C ((z - 1) I - (A - I))^-1 B + D of a discrete model whose A clusters about 1.

    The core's solve reduces the matrix it is given to Hessenberg form with errors relative
    to its norm: for A = I + dt A_c those are u ||A|| = u beside the entries of A - I of
    size dt ||A_c||, and G at low frequencies (z - 1 of size ω dt) lost a relative
    u / (ω dt²) (1.7e-4 at dt = 1e-10, ω = 1e-3 rad/s; a plain LU solve of zI - A: 1e-14).
    Here A - I (its diagonal exact by Sterbenz's lemma where the entries of A lie in [1/2, 2])
    is balanced and given to the core's continuous solve, one frequency at a time, as
    jν I - (A - I - σ I) with z - 1 = σ + jν, σ = -2 sin²(ω dt / 2) and ν = sin(ω dt)
    (formed without the cancellation of cos(ω dt) - 1)."""
    n = model.n_states
    dt = period(model)
    A, B, C = balanced_matrices(model.A - np.eye(n), model.B, model.C)
    angles = frequencies * dt
    half = np.sin(0.5 * angles)
    shifts, imaginary = -2.0 * half * half, np.sin(angles)
    response = np.empty((len(frequencies), *model.D.shape), dtype=np.complex128)
    diagonal = np.arange(n)
    for k in range(len(frequencies)):
        shifted = A.copy()
        shifted[diagonal, diagonal] -= shifts[k]
        response[k] = _core.frequency_response(shifted, B, C, model.D, imaginary[k : k + 1], None)[
            0
        ]
    return response


def frequency_response(sys: System, omega: ArrayLike) -> FrequencyResponse:
    """G(jω) = C (jωI - A)^-1 B + D at each frequency of ``omega`` (rad/s); for a discrete
    model, G(e^{jω dt}) = C (e^{jω dt} I - A)^-1 B + D.

    The states are first balanced by an exact diagonal similarity of powers of two
    (Parlett and Reinsch's iteration on [[A, B], [C, 0]] over the states), so that a model in
    badly scaled coordinates has the response of the well-scaled one: the core's Hessenberg
    solve has errors relative to the size of the matrix it is given (relative errors of 1.6e-3
    for a well-conditioned 4-state model in states scaled by 10^(-4, -3, 4, 6)).

    A model of 12 states or more at twice as many frequencies as states or more is summed from
    its partial-fraction form, G(s) = D + Σ_k R_k / (s - λ_k) over the eigenvalues of A (one
    eigen-decomposition, then O(n p m) a frequency instead of the Hessenberg solve's
    O(n² m)), wherever that form is trustworthy: A's real eigenvector matrix W is well
    conditioned (κ₁(W) <= 2^14) with a residual ||A W - W Λ|| at rounding level, and the
    frequency is farther from every eigenvalue than the form's error bound. Elsewhere, and
    for a defective or nearly defective A, the Hessenberg solve takes the frequency. The form's
    error bound is within κ₁(W) of the solve's; the two agree to rounding, not bit for bit.

    A discrete model whose A is within 2^-10 of the identity (sampled fast against its
    modes) is evaluated about z = 1, as C ((z - 1) I - (A - I))^-1 B + D, so that its low
    frequencies keep their digits.

    A frequency at an imaginary-axis pole (a pole on the unit circle, for a discrete model)
    gives infinite or NaN entries.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, or system object
        Without C and D the outputs are the states.
    omega : array_like (k,) or float, rad/s
        The frequencies (any real values; G(-jω) is the conjugate of G(jω)).

    Returns
    -------
    FrequencyResponse
        ``omega`` (k,) and ``response`` (k, p, m) of complex G, with ``magnitude``,
        ``magnitude_db``, ``phase`` (unwrapped, rad), ``phase_deg`` and ``plot()``.

    Raises
    ------
    ShapeError
        ``omega`` is not 1-D (or a number), or the model's matrices disagree in size.
    NonFiniteError
        A frequency or a matrix entry is NaN or infinite.
    NotRealError
        ``sys`` is not a model, or ``omega`` or a matrix is complex.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> g = aerocontrol.frequency_response(([[-2.0]], [[1.0]]), [0.0, 2.0])
    >>> np.round(g.response[:, 0, 0], 4)            # 1 / (jω + 2)
    array([0.5 +0.j  , 0.25-0.25j])
    >>> d = aerocontrol.StateSpace([[0.5]], [[1.0]], [[1.0]], [[0.0]], dt=0.1)
    >>> g = aerocontrol.frequency_response(d, [0.0, np.pi / 0.1])   # z = 1 and z = -1
    >>> np.round(g.response[:, 0, 0].real, 4)                        # 1 / (z - 0.5)
    array([ 2.    , -0.6667])
    """
    model = as_state_space(sys)
    frequencies = real_array(omega, "omega")
    if frequencies.ndim == 0:
        frequencies = frequencies.reshape(1)
    if frequencies.ndim != 1:
        raise ShapeError(f"omega must be a 1-D array of frequencies, got {frequencies.shape}")
    if model.is_discrete and _clustered_at_one(model.A):
        response = _response_about_one(model, frequencies)
    else:
        A, B, C = balanced_matrices(model.A, model.B, model.C)
        response = _core.frequency_response(
            A,
            B,
            C,
            model.D,
            frequencies,
            period(model) if model.is_discrete else None,
        )
    return FrequencyResponse(
        omega=np.array(frequencies, dtype=np.float64),
        response=response,
        input_names=model.input_names,
        output_names=model.output_names,
    )


def default_frequency_grid(sys: System, count: int = DEFAULT_FREQUENCIES) -> FloatArray:
    """``count`` (at least 1) log-spaced frequencies from a tenth of the slowest to ten times
    the fastest nonzero natural frequency of the modes (0.01 to 100 rad/s when every
    eigenvalue is zero; at most 1e308). For a discrete model: from a tenth of the slowest
    natural frequency of s = ln(z)/dt (or a thousandth of the Nyquist frequency, if lower) to
    the Nyquist frequency π/dt. A mode slower than 1e-12 of the fastest (or of the Nyquist
    frequency), which the eigenvalues of A do not resolve from zero, is found from the
    eigenvalues of A^-1 (discrete: (A - I)^-1) where that matrix is nonsingular.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, or system object
        Without C and D the outputs are the states.
    count : int, optional
        The number of frequencies, at least 1 (default 1000).

    Returns
    -------
    ndarray (count,), rad/s
        The frequencies, log-spaced and increasing.

    Raises
    ------
    InvalidArgumentError
        ``count`` is not a positive integer.
    NotRealError, NonFiniteError, ShapeError
        ``sys`` is not a model, or its matrices are complex, not finite or of inconsistent
        sizes.

    Examples
    --------
    Modes at 1 and 100 rad/s: the grid spans 0.1 to 1000 rad/s.

    >>> import aerocontrol
    >>> aerocontrol.default_frequency_grid(([[-1.0, 0.0], [0.0, -100.0]], [[1.0], [1.0]]), 5)
    array([1.e-01, 1.e+00, 1.e+01, 1.e+02, 1.e+03])
    """
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise InvalidArgumentError(f"count must be a positive integer, got {count!r}")
    model = as_state_space(sys)
    if model.is_discrete:
        nyquist = np.pi / period(model)
        s = continuous_eigenvalues(model)
        magnitudes = np.abs(s[np.isfinite(s)])
        nonzero = magnitudes[magnitudes > 1e-12 * nyquist]
        if nonzero.size < magnitudes.size:  # modes below 1e-12 of it: resolved from (A - I)^-1
            nonzero = np.concatenate([nonzero, np.abs(_slow_modes(model, nyquist))])
        low = min(nonzero.min() / 10, nyquist / 1000) if nonzero.size else nyquist / 1000
        return np.logspace(np.log10(low), np.log10(nyquist), int(count))
    eigenvalues, nonzero = grid_frequencies([model], "the default frequency grid")
    if nonzero.size < eigenvalues.size and nonzero.size:
        # Modes below 1e-12 of the fastest, which the eigenvalues of A do not resolve from
        # zero: resolved from A^-1 where A is nonsingular.
        nonzero = np.concatenate([nonzero, np.abs(_slow_modes(model, float(nonzero.max())))])
    if nonzero.size == 0:
        return np.logspace(-2.0, 2.0, int(count))
    return np.logspace(
        np.log10(nonzero.min()) - 1, min(np.log10(nonzero.max()) + 1, 308.0), int(count)
    )


def bode(sys: System, omega: ArrayLike | None = None) -> FrequencyResponse:
    """The frequency response for a Bode plot: ``.magnitude_db``, ``.phase_deg`` (unwrapped),
    ``.plot()``. Without ``omega``, the default grid of :func:`default_frequency_grid`.

    Parameters
    ----------
    sys : StateSpace, (A, B) or (A, B, C, D) tuple, or system object
        Without C and D the outputs are the states.
    omega : array_like (k,), rad/s, optional
        The frequencies; default :func:`default_frequency_grid` (1000 frequencies).

    Returns
    -------
    FrequencyResponse
        ``omega`` (k,) and ``response`` (k, p, m) of complex G, with ``magnitude``,
        ``magnitude_db``, ``phase`` (unwrapped, rad), ``phase_deg`` and ``plot()``.

    Raises
    ------
    ShapeError
        ``omega`` is not 1-D (or a number), or the model's matrices disagree in size.
    NonFiniteError
        A frequency or a matrix entry is NaN or infinite.
    NotRealError
        ``sys`` is not a model, or ``omega`` or a matrix is complex.

    See Also
    --------
    frequency_response : the same response at given frequencies.

    Examples
    --------
    >>> import aerocontrol
    >>> A, B = aerocontrol.chapter.boeing747_longitudinal()
    >>> b = aerocontrol.bode((A, B))
    >>> b.magnitude_db.shape
    (1000, 4, 1)

    2 / (s + 2) at its corner frequency: -3.01 dB and -45°.

    >>> b = aerocontrol.bode(([[-2.0]], [[2.0]]), [2.0])
    >>> round(float(b.magnitude_db[0, 0, 0]), 2), round(float(b.phase_deg[0, 0, 0]), 2)
    (-3.01, -45.0)
    """
    frequencies = default_frequency_grid(sys) if omega is None else omega
    return frequency_response(sys, frequencies)
