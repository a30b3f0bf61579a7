"""Transfer functions and zeros of a state-space model, computed from the state space.

The zeros of a model are where its system matrix (Rosenbrock's pencil)

    S(λ) = [[A - λI, B], [C, D]]                                              (1)

loses rank. :func:`transmission_zeros` finds them as Emami-Naeini and Van Dooren do (SLICOT's
AB08ND): orthogonal, rank-revealing steps (singular value decompositions) remove the part of
the pencil that has no finite zeros until D is square and invertible, first on the model, then
on its dual (Aᵀ, Cᵀ, Bᵀ, Dᵀ); a last orthogonal compression of the columns of [C D] leaves a
regular pencil Af - λBf whose generalized eigenvalues, computed by aerocontrol's own QZ
(:func:`~aerocontrol.qz`), are the finite zeros. Every step is orthogonal, so the zeros are
those of a pencil within a few units of rounding of (1): no polynomial is formed.

:func:`transfer_function` gives one channel G(s) = C (sI - A)⁻¹ B + D as

    G(s) = K Π(s - z_i) / Π(s - p_j),

with the poles p_j the eigenvalues of A (all n of them: the denominator is det(sI - A), as
flight dynamics texts write Δ(s), whatever cancels), the zeros z_i those of the channel's
pencil (for one input and one output det S(s) = ±det(sI - A) G(s), so they are exactly the
roots of the numerator over that denominator), and the gain K evaluated from G at a point
away from every pole and zero. Nothing is obtained by cancelling characteristic polynomials.
The result prints in the factored "aircraft" form, with (s + 1/T) and
(s² + 2ζωs + ω²) factors.

References
----------
A. Emami-Naeini and P. Van Dooren, "Computation of zeros of linear multivariable systems",
Automatica 18(4), 415-430, 1982. P. Misra, P. Van Dooren and A. Varga, "Computation of
structural invariants of generalized state-space systems", Automatica 30(12), 1921-1936, 1994
(the rank tolerance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from . import _core
from ._validation import FloatArray, real_scalar
from .exceptions import InvalidArgumentError
from .linalg import qz
from .statespace import StateSpace, as_state_space, period, signal_indices

if TYPE_CHECKING:
    from ._typing import SignalSelection, System

__all__ = ["Factor", "TransferFunction", "transfer_function", "transmission_zeros"]

ComplexArray = NDArray[np.complex128]


# ----- the reduction of the system pencil -------------------------------------------------------


def _tolerance(A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray) -> float:
    """The rank tolerance: (n + p)(n + m) ε ||S||_F (as SLICOT's AB08ND)."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    size = math.sqrt(sum(float(np.sum(M * M)) for M in (A, B, C, D)))
    return float((n + p) * (n + m) * np.finfo(float).eps * max(size, np.finfo(float).tiny))


def _svd(M: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    U, s, Vt = np.linalg.svd(M, full_matrices=True)
    return U, s, Vt


def _reduce(
    A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray, tol: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """A model with the same finite zeros as (A, B, C, D) and D of full row rank
    (Emami-Naeini and Van Dooren's procedure "reduce").

    With U orthogonal such that U D = [[0], [D̄]] (D̄ of full row rank r) and U C = [[C1],
    [C2]], and V orthogonal such that C1 V = [0, C̄] (C̄ of full column rank ρ), the pencil is
    equivalent to the direct sum of ρ rows and columns of full rank and of the model

        A' = A11,  B' = B1,  C' = [[A21], [C2 V1]],  D' = [[B2], [D̄]],

    with VᵀAV = [[A11, A12], [A21, A22]] and VᵀB = [[B1], [B2]] split at n - ρ. Each step
    removes ρ > 0 states; it stops when D has full row rank, or when C1 = 0 (the rows of
    zeros are dropped: they lower the normal rank and hold no finite zero)."""
    while True:
        n, p = A.shape[0], C.shape[0]
        if p == 0:
            return A, B, C, D
        U, s, _ = _svd(D)
        r = int(np.sum(s > tol))
        if r == p:
            return A, B, C, D
        order = np.concatenate([np.arange(r, p), np.arange(r)])
        U = U[:, order]
        sigma = p - r
        D_bar = (U.T @ D)[sigma:]
        C_rotated = U.T @ C
        C1, C2 = C_rotated[:sigma], C_rotated[sigma:]
        if n == 0:
            return A, B, C2, D_bar
        _, s1, Vt = _svd(C1)
        rho = int(np.sum(s1 > tol))
        if rho == 0:
            return A, B, C2, D_bar
        V = np.concatenate([Vt[rho:], Vt[:rho]]).T
        k = n - rho
        AV = V.T @ A @ V
        BV = V.T @ B
        CV = C2 @ V
        A, B = AV[:k, :k], BV[:k]
        C = np.vstack([AV[k:, :k], CV[:, :k]])
        D = np.vstack([BV[k:], D_bar])


@dataclass(frozen=True)
class _Reduced:
    """The finite zeros and the normal rank of the pencil's transfer matrix."""

    zeros: ComplexArray
    normal_rank: int


def _pencil_zeros(model: StateSpace, tol: float | None) -> _Reduced:
    A, B, C, D = (np.array(M, dtype=np.float64) for M in (model.A, model.B, model.C, model.D))
    tolerance = _tolerance(A, B, C, D) if tol is None else tol
    A, B, C, D = _reduce(A, B, C, D, tolerance)
    At, Bt, Ct, Dt = _reduce(A.T, C.T, B.T, D.T, tolerance)
    A, B, C, D = At.T, Ct.T, Bt.T, Dt.T
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    rank = min(m, p)
    if m != p:
        # Both reductions leave D of full row and column rank: square. This is reached only
        # when the rank decisions disagree at the tolerance (a nearly degenerate model).
        raise InvalidArgumentError(  # pragma: no cover - defensive
            f"transmission_zeros: the reduced model has D of shape {D.shape}, not square; "
            "the model is too close to a degenerate one at the rank tolerance (give tol)"
        )
    if n == 0:
        return _Reduced(np.zeros(0, dtype=np.complex128), rank)
    # [C D] W = [0, Df]: W from the QR factorisation of [C D]ᵀ, its null space first.
    Q, _ = np.linalg.qr(np.hstack([C, D]).T, mode="complete")
    W = np.hstack([Q[:, m:], Q[:, :m]])
    Af = np.hstack([A, B]) @ W[:, :n]
    Bf = W[:n, :n]
    form = qz(Af, Bf)
    alpha, beta = form.alpha, form.beta
    scale = np.maximum(np.abs(np.diag(form.AA)), np.abs(np.diag(form.BB))).max(initial=0.0)
    finite = beta > tolerance * max(scale, 1.0) * 1e-3
    zeros = np.asarray(alpha[finite] / beta[finite], dtype=np.complex128)
    zeros[np.abs(zeros) <= tolerance] = 0.0  # a zero at the origin, to rounding (a washout)
    return _Reduced(_conjugate_clean(zeros), rank)


def _conjugate_clean(roots: ComplexArray) -> ComplexArray:
    """Roots with a negligible imaginary part made real, and sorted (by real part, then
    imaginary part)."""
    cleaned = roots.copy()
    tiny = np.abs(cleaned.imag) <= 8 * np.finfo(float).eps * np.abs(cleaned)
    cleaned[tiny] = cleaned[tiny].real
    return np.sort_complex(cleaned)


def _tol(tol: float | None) -> float | None:
    if tol is None:
        return None
    value = real_scalar(tol, "tol")
    if not (math.isfinite(value) and value >= 0.0):
        raise InvalidArgumentError(f"tol must be a non-negative, finite number, got {value}")
    return value


def transmission_zeros(sys: System, tol: float | None = None) -> ComplexArray:
    """The finite transmission (invariant) zeros of a model: where the system matrix
    [[A - λI, B], [C, D]] loses rank below its normal rank.

    Emami-Naeini and Van Dooren's reduction (as SLICOT's AB08ND): orthogonal rank-revealing
    steps bring the pencil to a regular one of the same finite zeros, whose generalized
    eigenvalues aerocontrol's QZ computes. For any number of inputs and outputs; a model whose
    transfer matrix has lower normal rank (two equal outputs) has the zeros where the rank
    drops below it. Decoupling zeros (uncontrollable or unobservable modes) are among the
    invariant zeros, as in SLICOT and python-control. For a discrete model the zeros are in
    the z-plane.

    Parameters
    ----------
    sys : StateSpace or (A, B, C, D)
    tol : float, optional
        The tolerance of the rank decisions; default (n + p)(n + m) ε ||S||_F.

    Returns
    -------
    ndarray of complex128
        The finite zeros, sorted by real part.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> g = aerocontrol.zpk([-3.0], [-1.0, -2.0], 1.0)     # (s + 3)/((s + 1)(s + 2))
    >>> aerocontrol.transmission_zeros(g)
    array([-3.+0.j])
    >>> # Yaw rate and sideslip of the 747 from rudder and aileron: a 2 x 2 model.
    >>> lateral = aerocontrol.aircraft.load("b747-cruise").lateral()
    >>> z = aerocontrol.transmission_zeros(lateral[["r", "beta"], ["rudder", "aileron"]])
    >>> len(z)
    2
    """
    model = as_state_space(sys)
    return _pencil_zeros(model, _tol(tol)).zeros


# ----- transfer functions -----------------------------------------------------------------------


@dataclass(frozen=True)
class Factor:
    """One factor of a factored polynomial: (s - root) or, for a complex pair,
    (s² + 2ζω s + ω²) (in z for a discrete model)."""

    roots: tuple[complex, ...]
    """One real root, or the pair (Im > 0 first)."""
    zeta: float
    """Damping ratio of a pair (for a discrete model: of s = ln(z)/dt); NaN for a real root."""
    omega: float
    """ω of a pair (rad/s; for a discrete model of s = ln(z)/dt); |root| for a real one."""
    time_constant: float
    """T of a real root -1/T (s; continuous only): 1/|root|, inf for a root at 0."""

    @property
    def coefficients(self) -> FloatArray:
        """The monic factor, highest power first."""
        if len(self.roots) == 1:
            return np.array([1.0, -self.roots[0].real])
        r = self.roots[0]
        return np.array([1.0, -2.0 * r.real, abs(r) ** 2])


def _factors(roots: ComplexArray, dt: float) -> list[Factor]:
    """Real roots then pairs, each ordered by increasing |root|."""
    factors: list[Factor] = []
    for r in sorted((r for r in roots if r.imag == 0.0), key=lambda r: (abs(r), r.real)):
        value = float(r.real)
        tau = math.inf if value == 0.0 or dt else 1.0 / abs(value)
        factors.append(Factor((complex(value),), math.nan, abs(value), tau))
    for r in sorted((r for r in roots if r.imag > 0.0), key=abs):
        s = complex(np.log(r)) / dt if dt else complex(r)
        omega = abs(s)
        zeta = -s.real / omega if omega > 0 else math.nan
        factors.append(Factor((complex(r), complex(r).conjugate()), zeta, omega, math.nan))
    return factors


def _format_factors(factors: list[Factor], variable: str, digits: int) -> str:
    parts = []
    for f in factors:
        if len(f.roots) == 1:
            root = f.roots[0].real
            if root == 0.0:
                parts.append(variable)
            else:
                sign = "-" if root > 0 else "+"
                parts.append(f"({variable} {sign} {abs(root):.{digits}g})")
        elif variable == "s":
            zeta, omega = f"{f.zeta:.{digits}g}", f"{f.omega:.{digits}g}"
            parts.append(f"({variable}² + 2({zeta})({omega}){variable} + ({omega})²)")
        else:
            c = f.coefficients
            sign = "-" if c[1] < 0 else "+"
            parts.append(
                f"({variable}² {sign} {abs(c[1]):.{digits}g}{variable} + {c[2]:.{digits}g})"
            )
    return "".join(parts) if parts else "1"


@dataclass(frozen=True, eq=False)
class TransferFunction:
    """One channel G(s) = K Π(s - z_i)/Π(s - p_j) of a model (in z for a discrete model).

    ``print(tf)`` shows the factored "aircraft" form, (s + 1/T) for a real root -1/T and
    (s² + 2(ζ)(ω)s + (ω)²) for a pair, as flight dynamics texts print a numerator N(s) over
    the characteristic polynomial Δ(s).
    """

    numerator: FloatArray
    """K Π(s - z_i), highest power first."""
    denominator: FloatArray
    """det(sI - A) = Π(s - p_j), monic, highest power first."""
    zeros: ComplexArray
    """The finite zeros of the channel's pencil, sorted."""
    poles: ComplexArray
    """The eigenvalues of A (all n), sorted."""
    gain: float
    """K, the leading coefficient of the numerator (the high-frequency gain over s^(n - m))."""
    dt: float
    """0.0 for a continuous model, else the sampling period in seconds."""
    output_name: str
    input_name: str

    @property
    def variable(self) -> str:
        """ "s", or "z" for a discrete model."""
        return "z" if self.dt else "s"

    @property
    def zero_factors(self) -> list[Factor]:
        """The numerator's factors: real zeros by |z|, then pairs by ω."""
        return _factors(self.zeros, self.dt)

    @property
    def pole_factors(self) -> list[Factor]:
        """The denominator's factors: real poles by |p|, then pairs by ω."""
        return _factors(self.poles, self.dt)

    def __call__(self, s: complex | ComplexArray) -> complex | ComplexArray:
        """G at ``s`` (or at z for a discrete model), from the factored form."""
        value = np.asarray(s, dtype=np.complex128)
        result = (
            self.gain
            * np.prod(value[..., None] - self.zeros, axis=-1)
            / np.prod(value[..., None] - self.poles, axis=-1)
        )
        return complex(result) if result.ndim == 0 else result

    def aircraft_form(self, digits: int = 4) -> str:
        """The factored form on one line: ``K (s + 1/T)(s² + 2(ζ)(ω)s + (ω)²) / (...)``."""
        v = self.variable
        numerator = _format_factors(self.zero_factors, v, digits)
        denominator = _format_factors(self.pole_factors, v, digits)
        gain = f"{self.gain:.{digits}g}"
        top = gain if numerator == "1" else f"{gain} {numerator}"
        return f"{top} / {denominator}" if denominator != "1" else top

    def __str__(self) -> str:
        lines = [f"{self.output_name}/{self.input_name}({self.variable}) = {self.aircraft_form()}"]
        for what, factors in (("zero", self.zero_factors), ("pole", self.pole_factors)):
            for f in factors:
                if len(f.roots) == 1:
                    tau = f"T = {f.time_constant:.4g} s" if math.isfinite(f.time_constant) else ""
                    lines.append(f"  {what} {f.roots[0].real:.6g} {tau}".rstrip())
                else:
                    r = f.roots[0]
                    lines.append(
                        f"  {what}s {r.real:.6g} ± {r.imag:.6g}j: "
                        f"zeta = {f.zeta:.4g}, omega = {f.omega:.4g} rad/s"
                    )
        return "\n".join(lines)


def _evaluation_point(roots: ComplexArray, dt: float) -> tuple[float, complex]:
    """A frequency ω whose point s = jω (z = e^{jω dt}) is far from every root."""
    if dt:
        candidates = np.linspace(0.05, 0.95, 19) * math.pi / dt
        points = np.exp(1j * candidates * dt)
    else:
        sizes = np.abs(roots[np.abs(roots) > 0])
        centre = float(np.exp(np.mean(np.log(sizes)))) if sizes.size else 1.0
        candidates = centre * np.logspace(-1.5, 1.5, 31)
        points = 1j * candidates
    if roots.size == 0:
        best = len(candidates) // 2
    else:
        distance = np.min(
            np.abs(points[:, None] - roots[None, :]) / np.maximum(np.abs(points[:, None]), 1e-300),
            axis=1,
        )
        best = int(np.argmax(distance))
    return float(candidates[best]), complex(points[best])


def _single(key: SignalSelection | None, names: tuple[str, ...], what: str) -> int:
    if key is None:
        if len(names) != 1:
            raise InvalidArgumentError(
                f"the model has {len(names)} {what}s: name the {what} ({', '.join(names)})"
            )
        return 0
    indices = signal_indices(key, names, what)
    if len(indices) != 1:
        raise InvalidArgumentError(f"{what} must select one {what}, got {len(indices)}")
    return indices[0]


def transfer_function(
    sys: System,
    output: SignalSelection | None = None,
    input: SignalSelection | None = None,
) -> TransferFunction:
    """The transfer function of one channel of a model, from its state space.

    The poles are the eigenvalues of A (all of them: the denominator is det(sI - A)); the
    zeros are those of the channel's system pencil (:func:`transmission_zeros`), never the
    roots of a numerator polynomial obtained by cancelling; the gain K is G evaluated at a
    point away from every pole and zero, times Π(s - p)/Π(s - z). A channel that is zero
    has numerator [0.] and gain 0.

    Parameters
    ----------
    sys : StateSpace or (A, B, C, D)
    output, input : name or index, optional
        The channel; may be omitted for a model with one output (input).

    Returns
    -------
    TransferFunction
        ``numerator``, ``denominator``, ``zeros``, ``poles``, ``gain``, and the factored
        form (``print``).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> lateral = aerocontrol.aircraft.load("b747-approach").lateral()
    >>> g = aerocontrol.transfer_function(lateral, "r", "rudder")
    >>> print(g.aircraft_form(3))   # doctest: +NORMALIZE_WHITESPACE
    -0.244 (s + 1.23)(s² + 2(-0.0707)(0.37)s + (0.37)²) /
        (s + 0.0464)(s + 1.23)(s² + 2(0.108)(0.748)s + (0.748)²)
    >>> np.round(g.numerator / g.gain, 4)         # python-control's ss2tf gives the same
    array([1.    , 1.1767, 0.0725, 0.1681])
    """
    model = as_state_space(sys)
    i = _single(output, model.output_names, "output")
    j = _single(input, model.input_names, "input")
    channel = model[[i], [j]]
    dt = period(model) if model.is_discrete else 0.0
    poles = (
        _conjugate_clean(_core.eigenvalues(channel.A))
        if channel.n_states
        else np.zeros(0, np.complex128)
    )
    reduced = _pencil_zeros(channel, None)
    denominator = np.real(np.poly(poles)) if poles.size else np.ones(1)
    if reduced.normal_rank == 0:
        zeros = np.zeros(0, np.complex128)
        gain = 0.0
        numerator = np.zeros(1)
    else:
        zeros = reduced.zeros
        omega, point = _evaluation_point(np.concatenate([zeros, poles]), dt)
        response = _core.frequency_response(
            channel.A, channel.B, channel.C, channel.D, np.array([omega]), dt or None
        )[0, 0, 0]
        value = response * np.prod(point - poles) / np.prod(point - zeros)
        gain = float(value.real)
        numerator = gain * np.real(np.poly(zeros)) if zeros.size else np.array([gain])
    return TransferFunction(
        numerator=np.asarray(numerator, dtype=np.float64),
        denominator=np.asarray(denominator, dtype=np.float64),
        zeros=zeros,
        poles=poles,
        gain=gain,
        dt=dt,
        output_name=model.output_names[i],
        input_name=model.input_names[j],
    )
