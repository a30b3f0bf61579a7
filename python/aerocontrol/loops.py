"""Loop analysis of a single-input, single-output loop: stability margins, sensitivities and
the root locus over a scalar gain; and the disk margins of a multi-loop (MIMO) loop.

The loop L(s) is the open-loop transfer around the loop break point, in the negative feedback
convention: the loop is closed as u = -y, the closed loop's characteristic equation is
1 + L(s) = 0, and over a gain k it is 1 + k L(s) = 0. (A loop whose feedback is positive is
given as -L.) Every frequency response is the Rust core's G(jω) = C (jωI - A)⁻¹ B + D
(:func:`~aerocontrol.frequency_response`; G(e^{jω dt}) for a discrete loop).

Margins (:func:`stability_margins`)
    ================  =====================================================================
    gain margins      1/|L(jω)| at each phase crossover, where L(jω) is real and negative
                      (ω = 0 and the Nyquist frequency included); the factor by which the
                      loop gain may grow (> 1) or shrink (< 1) before the closed loop has a
                      pole at jω. The one reported is the closest to 0 dB.
    phase margins     180° + ∠L(jω) at each gain crossover |L(jω)| = 1, wrapped to
                      (-180°, 180°]: the phase lag that brings L(jω) to -1 (negative: a
                      lead). The one reported has the least magnitude.
    delay margin      min over the gain crossovers ω > 0 of (PM in rad, taken in [0, 2π))/ω:
                      the smallest pure delay that destabilises the loop; 0 when the closed
                      loop is unstable, ∞ without a crossover.
    disk margin       the balanced (σ = 0) disk margin of Seiler, Packard and Gahinet:
                      α = 1/max_ω |S(jω) - T(jω)|/2 = 1/max_ω |1 - L|/(2|1 + L|): the loop
                      stays stable for every simultaneous gain and phase change f in the disk
                      D(α) = {(1 + δα/2)/(1 - δα/2) : |δ| < 1}, i.e. gains in
                      [(2 - α)/(2 + α), (2 + α)/(2 - α)] with no phase change, or phase
                      changes up to ±2 arctan(α/2) at unit gain. 0 when the closed loop is
                      unstable.
    ================  =====================================================================

Crossovers are computed by eigenvalue methods in the Rust core, in one call
(``rust/control/margins.rs``): the gain crossovers are the imaginary-axis eigenvalues of the
Hamiltonian of 1 - L(-s) L(s), the phase crossovers the imaginary-axis zeros of
L(s) - L(-s); each candidate is polished by the secant method on the exact L(jω) and kept only
if |L| = 1, respectively Im L = 0, holds to 1e-8. The disk margin's and the stability margin's
extrema are L∞ norms, computed by the Boyd-Balakrishnan/Bruinsma-Steinbuch Hamiltonian
iteration. A crossover "at infinity" is not reported: a loop with no gain crossover has phase
margin ∞ and delay margin ∞, and one with no phase crossover has gain margin ∞ (python-control
reports 0 in some such cases). A discrete loop, and a loop real on the whole imaginary axis
(for which L(s) - L(-s) vanishes identically), are analysed on a dense logarithmic grid instead
(spanning the loop's poles and zeros and its asymptotic crossovers, clustered around lightly
damped roots) refined by Brent's method on the exact L(jω).

Closed-loop stability is decided from the closed-loop poles, the eigenvalues of
A - B (1 + D)⁻¹ C, never from the plot; the number of counterclockwise encirclements of -1 by
the Nyquist plot follows from the principle of the argument: N = P - Z, with P and Z the open-
and closed-loop poles in the open right half plane (outside the unit circle).

Disk margins of a MIMO loop (:func:`disk_margins`)
    L is square (p x p), closed as u = -y (I + L). Loop at a time, loop i is broken with the
    others closed and has the SISO disk margin above (of skew σ: 1/sup_ω |S_ii + (σ - 1)/2|).
    The multiloop margin allows independent changes f_i in every loop at once: α =
    1/sup_ω μ(S + (σ - 1)/2 I) for diagonal complex perturbations, computed within bounds
    (an upper bound of μ by optimal diagonal scaling, a lower bound by the power method),
    both reported; the destabilising perturbation of the lower bound is checked to make
    I + L F singular.

Root locus (:func:`root_locus`, :func:`best_damping_gain`, :func:`gain_for_damping`)
    The closed-loop poles of 1 + k L(s) = 0 are the eigenvalues of A - k B (1 + k D)⁻¹ C; the
    matrices of every gain are formed as one (k, n, n) stack and their eigenvalues computed in
    one parallel call of the core.

Loops of huge size
    A closed-loop matrix whose terms exceed 2^256 is formed divided by a power of two and its
    eigenvalues multiplied back; the margins of a continuous loop of that size are those of
    L(2^e s) (A and B divided by 2^e, B and C then balanced by a state scaling), with the
    frequencies and poles multiplied by 2^e and the delays divided by it. Both are exact but
    for the underflow of terms far below the largest; a pole or frequency beyond the doubles is
    infinite, with a NumericalOverflowWarning.

References
----------
P. Seiler, A. Packard and P. Gahinet, "An introduction to disk margins", IEEE Control Systems
Magazine 40(5), 78-95, 2020 (the disk margin, eqs. (9)-(12)). R. P. Brent, *Algorithms for
Minimization without Derivatives*, 1973 (the root finder). S. Boyd and V. Balakrishnan,
Systems & Control Letters 15, 1990, and N. A. Bruinsma and M. Steinbuch, Systems & Control
Letters 14, 1990 (the L∞ iteration). J. D. Blight, R. L. Dailey and D. Gangsaas, "Practical
control law design for aircraft using multivariable techniques", International Journal of
Control 59(1), 93-137, 1994 (multiloop margins). A. Packard and J. Doyle, "The complex
structured singular value", Automatica 29(1), 71-109, 1993 (μ and its D-scaled bound, equal
for 2S + F <= 3 blocks). A. Packard, M. K. H. Fan and J. Doyle, "A power method for the
structured singular value", 27th IEEE Conference on Decision and Control, 1988 (the lower
bound). R. Sezginer and M. Overton, "The largest singular value of e^X A e^-X is convex on
convex sets of commuting matrices", IEEE Transactions on Automatic Control 35(2), 1990 (the
scaling search is convex). E. E. Osborne, "On pre-conditioning of matrices", Journal of the
ACM 7(4), 1960 (its start).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core
from ._balance import balanced_matrix, balanced_states
from ._results import Result, Tabular, from_fields, set_at_once
from ._validation import FloatArray, check_finite, finite_or_warn, real_array, real_scalar
from .exceptions import (
    AerocontrolLinAlgError,
    IllConditionedWarning,
    InvalidArgumentError,
    LooseBoundWarning,
    NonFiniteError,
    NumericalOverflowWarning,
    NumericalUnderflowWarning,
    ShapeError,
    SingularMatrixError,
)
from .interconnect import _closed, _time_base, feedback, gain
from .statespace import StateSpace, as_state_space, period
from .transfer import TransferFunction, transfer_function

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ._typing import System

__all__ = [
    "DampingDesign",
    "DiskMargin",
    "DiskMargins",
    "NicholsResponse",
    "NyquistResponse",
    "RootLocus",
    "StabilityMargins",
    "best_damping_gain",
    "complementary_sensitivity",
    "disk_margins",
    "gain_for_damping",
    "nichols",
    "nyquist",
    "root_locus",
    "sensitivity",
    "stability_margins",
]

ComplexArray = NDArray[np.complex128]

#: Grid points per decade of frequency before refinement.
POINTS_PER_DECADE = 120
_EPS = float(np.finfo(float).eps)


# ----- the loop -----------------------------------------------------------------------------


def _siso(loop: System, name: str = "loop") -> StateSpace:
    model = as_state_space(loop, name)
    if (model.n_inputs, model.n_outputs) != (1, 1):
        raise ShapeError(
            f"{name} must have one input and one output (a loop broken at one point), got "
            f"{model.n_outputs} outputs and {model.n_inputs} inputs; select the channel with "
            f"{name}[output, input]"
        )
    return model


#: Closed-loop matrices (and loops, for the margins) with terms beyond 2^RESCALE_EXPONENT are
#: formed divided by a power of two and their eigenvalues (frequencies) multiplied back: the
#: core squares entries (Hamiltonians, norms), so it works within the square root of the range
#: of doubles.
RESCALE_EXPONENT = _core.RESCALE_EXPONENT


def _log2_size(M: FloatArray) -> float:
    """log2 of the largest |entry| of M; -inf for a zero or empty matrix."""
    largest = float(abs(M).max()) if M.size else 0.0
    return math.log2(largest) if largest > 0.0 else -math.inf


def _refuse_algebraic(model: StateSpace, k: float = 1.0) -> None:
    """SingularMatrixError for 1 + k D = 0: the loop closed with gain k is an algebraic loop."""
    d = float(model.D[0, 0])
    with np.errstate(over="ignore"):
        product = np.float64(k) * d
    denominator = 1.0 + float(product)
    if math.isfinite(product) and abs(denominator) <= 8 * _EPS * max(1.0, abs(product)):
        raise SingularMatrixError(
            f"the loop closed with gain {k:g} is an algebraic loop: 1 + k D = 0 (D = {d:g}), "
            "so it has no solution"
        )


def _closed_loop_gains(model: StateSpace, k: FloatArray) -> FloatArray:
    """k (1 + k D)^-1 for each gain, as 1/(1/k + D) where k D overflows."""
    d = float(model.D[0, 0])
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        denominators = 1.0 + k * d
        g = k / denominators
        far = ~np.isfinite(denominators)
        g[far] = 1.0 / (1.0 / k[far] + d)
    return np.asarray(g, dtype=np.float64)


def _closed_loop_gain_parts(model: StateSpace, k: FloatArray) -> tuple[FloatArray, FloatArray]:
    """k (1 + k D)^-1 for each gain as a mantissa and a power of two (m 2^e), which do not
    overflow where the gain does: a k within 1e-14 of the algebraic gain -1/D, with D of
    1e-300, has a closed-loop gain of 1e314, times a B C that may be small."""
    d = float(model.D[0, 0])
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        denominators = 1.0 + k * d
        near = np.isfinite(denominators)
        mk, ek = np.frexp(k)
        md, ed = np.frexp(denominators)
        far_m, far_e = np.frexp(1.0 / k + d)  # k/(1 + k D) = 1/(1/k + D) where k D overflows
        mantissa = np.where(near, mk / md, 1.0 / far_m)
        exponent = np.where(near, ek - ed, -far_e).astype(np.float64)
    zero = k == 0.0
    return np.where(zero, 0.0, mantissa), np.where(zero, 0.0, exponent)


def _closed_loop_poles(model: StateSpace, k: FloatArray) -> ComplexArray:
    """The eigenvalues of A - k B (1 + k D)^-1 C for each gain, each row sorted; the gains are
    free of algebraic loops (:func:`_refuse_algebraic`).

    The poles of every gain come from one parallel call of the core (``_core.loop_root_locus``,
    which forms the gains g = k/(1 + k D) itself: one controller-Hessenberg form of (A, B, C)
    and the QR iteration of a gain's Hessenberg matrix, normwise backward stable, at the first
    gain of each run of gains; from there Aberth's iteration on the factored characteristic
    polynomial from gain to gain, each gain's poles verified against the traces of the closed
    loop and its square, and the QR iteration wherever that fails; see
    ``rust/control/root_locus.rs``) on the loop with its states balanced for the closed loops
    (``_core.balanced_loop``, ``rust/linalg/balance.rs``): the QR is not balanced itself, so
    its errors are relative to the matrix it is given, and states scaled by 10^±6 gave poles
    wrong by 1800 times their size. Where a term of a matrix (A, or g B C, bounded by
    |g| max|B| max|C|) exceeds 2^RESCALE_EXPONENT, the matrix is
    formed divided by the power of two 2^e nearest its size, from B and C normalised by
    powers of two (so that neither B C nor g B C overflows), and its eigenvalues multiplied by
    2^e: exact but for the underflow of terms far below the largest. Poles beyond the range
    of doubles are infinite, with a NumericalOverflowWarning."""
    n = model.n_states
    if n == 0:
        return np.zeros((k.size, 0), np.complex128)
    located = _core.loop_root_locus(model.A, model.B, model.C, float(model.D[0, 0]), k)
    if located is not None:  # every term in range, each row sorted by the core
        return located
    A, B, C = _core.balanced_loop(model.A, model.B, model.C)
    g = _closed_loop_gains(model, k)
    size_A, size_B, size_C = _log2_size(A), _log2_size(B), _log2_size(C)
    mantissa, power = _closed_loop_gain_parts(model, k)
    if not math.isfinite(size_B + size_C):  # B C = 0: the loop does not move the poles
        g = np.zeros_like(g)
        mantissa = np.zeros_like(mantissa)
        size_B = size_C = 0.0
    with np.errstate(divide="ignore"):
        terms = np.maximum(size_A, np.log2(np.abs(mantissa)) + power + size_B + size_C)
    plain = (terms <= RESCALE_EXPONENT) & (size_B + size_C <= RESCALE_EXPONENT) & np.isfinite(g)
    exponents = np.where(plain | ~np.isfinite(terms), 0, np.round(terms)).astype(np.int64)
    if np.all(plain):
        return _core.root_locus(A, B, C, g)  # each row sorted by the core
    poles = np.empty((k.size, n), np.complex128)
    if np.any(plain):
        poles[plain] = _core.root_locus(A, B, C, g[plain])
    rescaled = np.flatnonzero(~plain)
    if rescaled.size:
        eb, ec = int(np.frexp(np.max(np.abs(B)))[1]), int(np.frexp(np.max(np.abs(C)))[1])
        normalised = np.ldexp(B, -eb) @ np.ldexp(C, -ec)
        stack = np.empty((rescaled.size, n, n))
        for row, i in enumerate(rescaled):
            e = int(exponents[i])
            shift = int(power[i]) + eb + ec - e
            stack[row] = np.ldexp(A, -e) - np.ldexp(mantissa[i], shift) * normalised
        poles[rescaled] = _core.eigenvalues(stack)
        # The balanced eigenvalues of a rescaled matrix are checked for backward stability
        # (in one batch; only the matrices whose worst bound exceeds the allowance one by one).
        if n <= CHECKED_MAX_ORDER:
            rows, columns = np.nonzero(poles[rescaled].imag >= 0.0)
            with np.errstate(all="ignore"):
                bounds = _residual_bounds(stack[rows], poles[rescaled][rows, columns])
                allowed = (
                    BACKWARD_ERROR_UNITS * n * (_EPS / 2.0) * np.linalg.norm(stack, axis=(1, 2))
                )
            worst = np.zeros(rescaled.size)
            np.maximum.at(worst, rows, bounds)
            for failed in np.flatnonzero(worst > allowed):
                poles[rescaled[failed]] = _backward_stable_eigenvalues(
                    stack[failed], poles[rescaled[failed]]
                )
    if np.any(exponents):
        with np.errstate(over="ignore", invalid="ignore"):
            scale = exponents[:, None]
            poles = np.ldexp(poles.real, scale) + 1j * np.ldexp(poles.imag, scale)
        if not np.all(np.isfinite(poles)):
            warnings.warn(
                "the closed-loop poles overflow double precision at the gains "
                f"{k[~np.all(np.isfinite(poles), axis=1)]}: they are infinite",
                NumericalOverflowWarning,
                stacklevel=3,
            )
    return np.sort_complex(poles).astype(np.complex128)


def _unstable(roots: ComplexArray, discrete: bool) -> NDArray[np.bool_]:
    return np.abs(roots) > 1.0 if discrete else roots.real > 0.0


def _unstable_count(
    roots: ComplexArray, discrete: bool, size: float, matrix: Callable[[], FloatArray]
) -> int:
    """The number of roots outside the stability region and not on its boundary
    (:func:`_census`)."""
    return _census(roots, discrete, size, matrix)[0]


def _census(
    roots: ComplexArray, discrete: bool, size: float, matrix: Callable[[], FloatArray]
) -> tuple[int, bool]:
    """(the number of roots outside the stability region and not on its boundary, whether
    every root lies strictly inside it and none on its boundary), both from
    :func:`_boundary_flags` with the balanced ``size`` of their ``matrix``: a root on the
    boundary to its accuracy is on the side rounding put it, which is not a property of the
    loop (the double integrator 1/s² in rotated coordinates has its poles computed as
    ±1.5e-8, and was counted one unstable pole or none by the rotation). As :func:`nyquist`
    counts P and Z. A NaN root is neither outside nor inside. Scalar arithmetic: a loop's few
    poles; where every root is farther from the boundary than :func:`_boundary_tolerance`
    (none flagged, no NaN), the count is taken from the distances alone, as the flags would
    give it."""
    distances = _outward_distances(roots, discrete)
    if math.isfinite(size):
        tolerance = _boundary_tolerance(size, discrete)
        if all(abs(x) > tolerance for x in distances):
            unstable = sum(x > 0.0 for x in distances)
            return unstable, unstable == 0
    flags = _boundary_flags(roots, distances, discrete, size, matrix)
    unstable, inside = 0, True
    for x, on in zip(distances, flags, strict=True):
        if on or not x < 0.0:
            inside = False
            unstable += x > 0.0 and not on
    return unstable, inside


def _eigenvalues(A: FloatArray) -> ComplexArray:
    return _core.eigenvalues(A) if A.shape[0] else np.zeros(0, np.complex128)


#: The normwise backward error, in units of n u ||M||_F, beyond which the balanced eigenvalues
#: of a closed-loop matrix are checked against those of its unbalanced Schur form.
BACKWARD_ERROR_UNITS = 10.0

#: Closed-loop matrices of at most this order have their balanced eigenvalues checked (about
#: 2 n^4 flops for the n residuals of a matrix: within the cost of the core's eigenvalues for
#: the orders of flight models). Larger ones take the core's eigenvalues as they are.
CHECKED_MAX_ORDER = 32


def _residual_bounds(M: FloatArray, values: ComplexArray) -> FloatArray:
    """For each eigenvalue λ, an upper bound on its backward error σ_min(M - λI) (the norm of
    the least perturbation of M of which λ is an eigenvalue): ||(M - λI) x|| / ||x|| for x
    from two steps of inverse iteration from a fixed start (deterministic). M is one matrix,
    or a stack of one matrix per value. A shift that is singular to working precision (its
    solution overflows) has bound 0."""
    n = M.shape[-1]
    shifted = M.astype(np.complex128) - values[:, None, None] * np.eye(n)
    x = np.broadcast_to(np.random.default_rng(0).standard_normal(n), (values.size, n))
    x = x.astype(np.complex128)
    singular = np.zeros(values.size, dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(2):
            try:
                x = np.linalg.solve(shifted, x[:, :, None])[:, :, 0]
            except np.linalg.LinAlgError:  # an exactly singular shift: λ is exact
                return np.zeros(values.size)
            largest = np.max(np.abs(x), axis=1)
            singular |= ~(np.isfinite(largest) & (largest > 0.0))
            x = np.where(singular[:, None], 1.0, x / np.where(singular, 1.0, largest)[:, None])
        residual = np.linalg.norm(np.einsum("kij,kj->ki", shifted, x), axis=1)
        bounds = residual / np.linalg.norm(x, axis=1)
    return np.asarray(np.where(singular, 0.0, bounds), dtype=np.float64)


def _backward_stable_eigenvalues(M: FloatArray, values: ComplexArray) -> ComplexArray:
    """The core's (balanced) eigenvalues ``values`` of M, or those of M's unbalanced Schur
    form where the balanced ones are not backward stable for M itself.

    The core balances M (a diagonal similarity D^-1 M D) before its QR iteration; its
    eigenvalues are then those of M + D E D^-1 with E of about u ||D^-1 M D||, which is
    small next to ||M|| for most badly scaled matrices but not for all: a closed-loop matrix
    A - B C dominated by its rank-one term, with a state that B does not reach (A of 1e-8, B C
    of 1e3), is balanced by a D of wide range, and its small eigenvalues came out with
    backward errors of 1e-9 (1.5e-9 / (n u ||M||) = 1000) and relative errors of 3%, where the
    unbalanced Schur form's QR, backward stable for M, has backward errors of 1e-14 and agrees
    with mpmath to 1e-7. So the balanced eigenvalues are kept where their backward errors
    (bounded by :func:`_residual_bounds`) are within BACKWARD_ERROR_UNITS n u ||M||_F, and
    otherwise the set (balanced or unbalanced) whose largest backward error is less."""
    n = M.shape[0]
    if n == 0 or n > CHECKED_MAX_ORDER or not np.all(np.isfinite(values)):
        return values
    size = float(np.linalg.norm(M))
    if not math.isfinite(size):
        return values
    allowed = BACKWARD_ERROR_UNITS * n * (_EPS / 2.0) * size
    upper = values.imag >= 0.0  # a conjugate has the same backward error (M is real)
    balanced = float(np.max(_residual_bounds(M, values[upper]), initial=0.0))
    if balanced <= allowed:
        return values
    unbalanced_values = _core.schur(M, None)[2]
    if not np.all(np.isfinite(unbalanced_values)):
        return values
    upper = unbalanced_values.imag >= 0.0
    unbalanced = float(np.max(_residual_bounds(M, unbalanced_values[upper]), initial=0.0))
    return unbalanced_values if unbalanced < balanced else values


# ----- one-dimensional searches -------------------------------------------------------------


def _brent(
    f: Callable[[float], float], a: float, b: float, fa: float, fb: float, xtol: float
) -> float:
    """A root of f in [a, b] (f(a), f(b) of opposite signs), by Brent's method (zeroin)."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    c, fc = a, fa
    d = e = b - a
    for _ in range(200):
        if (fb > 0) == (fc > 0):
            c, fc = a, fa
            d = e = b - a
        if abs(fc) < abs(fb):
            a, b, c = b, c, b
            fa, fb, fc = fb, fc, fb
        tol = 2 * _EPS * abs(b) + 0.5 * xtol
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                p, q = 2 * m * s, 1 - s
            else:
                q, r = fa / fc, fb / fc
                p = s * (2 * m * q * (q - r) - (b - a) * (r - 1))
                q = (q - 1) * (r - 1) * (s - 1)
            if p > 0:
                q = -q
            p = abs(p)
            if 2 * p < min(3 * m * q - abs(tol * q), abs(e * q)):
                e, d = d, p / q
            else:
                d = e = m
        else:
            d = e = m
        a, fa = b, fb
        b += d if abs(d) > tol else math.copysign(tol, m)
        fb = f(b)
    return b  # pragma: no cover - Brent's method converges in far fewer steps


def _golden_max(f: Callable[[float], float], a: float, b: float) -> tuple[float, float]:
    """(x, f(x)) at a maximum of f on [a, b] by golden-section search (to 1e-12 relative)."""
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(200):
        if abs(b - a) <= 1e-12 * max(abs(a), abs(b), 1e-300):
            break
        if fc >= fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = f(d)
    return (c, fc) if fc >= fd else (d, fd)


# ----- the frequency grid -------------------------------------------------------------------


def _magnitude(values: ComplexArray) -> FloatArray:
    """|values|, infinite only where the true modulus exceeds the doubles (numpy's hypot
    overflows only then; its warning is the honest inf, not a defect)."""
    with np.errstate(over="ignore"):
        return np.asarray(np.abs(values), dtype=np.float64)


def _half_difference(values: ComplexArray) -> FloatArray:
    """|1 - L|/(2|1 + L|) without overflow: for |L| > 1 the same ratio of 1/L (both moduli
    divided by |L|), so an L near 1e308 gives about 1/2, not inf/inf; inf where L = -1."""
    L = np.asarray(values, dtype=np.complex128)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore", under="ignore"):
        big = _magnitude(L) > 1.0
        w = np.where(big, 1.0 / np.where(big, L, 1.0), L)
        return np.asarray(np.abs(1.0 - w) / (2.0 * np.abs(1.0 + w)), dtype=np.float64)


def _nearest(points: ComplexArray, target: complex) -> int:
    """The index of the point nearest ``target``; a difference beyond the doubles (an
    infinite pole) is infinitely far, and an infinite target matches an equal point."""
    with np.errstate(over="ignore", invalid="ignore"):
        distance = np.abs(points - target)
    distance = np.where(points == target, 0.0, np.nan_to_num(distance, nan=np.inf))
    return int(np.argmin(distance))


class _Response:
    """L(jω) of a SISO model through the core, one frequency or many, from the model with its
    states balanced (:func:`balanced_states`: the core's solve has errors relative to the
    matrix it is given, and states scaled by 10^±6 moved a discrete loop's phase margin by
    1.2e-3 degrees)."""

    def __init__(self, model: StateSpace) -> None:
        self.model = balanced_states(model)
        self.dt = period(model) if model.is_discrete else None

    def many(self, omega: FloatArray) -> ComplexArray:
        """L at each frequency; infinite at a pole on the axis (not a warning here: the
        searches drop such points)."""
        m = self.model
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NumericalOverflowWarning)
            return _core.frequency_response(m.A, m.B, m.C, m.D, omega, self.dt)[:, 0, 0]

    def one(self, omega: float) -> complex:
        return complex(self.many(np.array([omega]))[0])


def _roots_of(model: StateSpace) -> TransferFunction:
    """L's transfer function for its poles, zeros and gain only: its polynomial coefficients
    may overflow (a gain near 1e308 times a zero) with a NumericalOverflowWarning, and a gain
    below the doubles makes it zero with a NumericalUnderflowWarning (L is then negligible
    at every gain k of the doubles); neither is a concern of a caller who asked for roots or
    margins, so neither is passed on."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NumericalOverflowWarning)
        warnings.simplefilter("ignore", NumericalUnderflowWarning)
        g = transfer_function(model)
    for roots, what in ((g.poles, "poles"), (g.zeros, "zeros")):
        finite_or_warn(roots, f"the open loop's {what}", stacklevel=4)
    return g


def _grid(model: StateSpace) -> FloatArray:
    """Frequencies from below the slowest to beyond the fastest pole or zero of the loop and
    beyond its asymptotic crossovers, with points clustered at lightly damped roots."""
    g = _roots_of(model)
    dt = period(model) if model.is_discrete else 0.0
    roots = np.concatenate([g.poles, g.zeros])
    if dt:
        # In radians per sample (θ = ω dt), the grid scaled to rad/s at the end: the
        # thresholds below are relative to max(scale, 1), which in rad/s made the grid depend
        # on the unit of time (sampled every 1e13 s, every root counted as at the origin and
        # the grid spanned θ of 0.314 to π only: a gain crossover at θ = 0.06 was missed).
        nonzero = roots[roots != 0]
        s = np.log(nonzero.astype(np.complex128))
    else:
        s = roots
    sizes = np.abs(s[np.isfinite(s)])
    scale = float(sizes.max()) if sizes.size else 1.0
    origin = sizes <= 1e-12 * max(scale, 1.0)
    nonzero_sizes = sizes[~origin]
    if nonzero_sizes.size:
        low, high = float(nonzero_sizes.min()) / 100.0, float(nonzero_sizes.max()) * 100.0
    else:
        low, high = 1e-2, 1e2
    if not dt and g.gain != 0.0:
        # High frequency: L ~ K s^-r; low frequency: L ~ K0 s^-q (q integrators net).
        r = len(g.poles) - len(g.zeros)
        if r > 0:
            high = max(high, 100.0 * abs(g.gain) ** (1.0 / r))
        at_origin_poles = int(np.sum(np.abs(g.poles) <= 1e-12 * max(scale, 1.0)))
        at_origin_zeros = int(np.sum(np.abs(g.zeros) <= 1e-12 * max(scale, 1.0)))
        q = at_origin_poles - at_origin_zeros
        if q > 0:
            far_poles = g.poles[np.abs(g.poles) > 1e-12 * max(scale, 1.0)]
            far_zeros = g.zeros[np.abs(g.zeros) > 1e-12 * max(scale, 1.0)]
            # |K0| = |K| Π|z| / Π|p| in log2: the products overflow (a D of 1e299 beside a
            # zero near 3e306: numpy's overflow, then inf/inf) where K0^(1/q) need not.
            with np.errstate(divide="ignore", over="ignore"):
                log_k0 = (
                    math.log2(abs(g.gain))
                    + float(np.sum(np.log2(_magnitude(far_zeros))))
                    - float(np.sum(np.log2(_magnitude(far_poles))))
                )
            if math.isfinite(log_k0):
                low = min(low, 2.0 ** min(log_k0 / q, 1023.0) / 100.0)
    if dt:
        return _clustered_grid(s, low, high, 1.0) / dt
    return _clustered_grid(s, low, high, dt)


def _clustered_grid(s: ComplexArray, low: float, high: float, dt: float) -> FloatArray:
    """POINTS_PER_DECADE log-spaced frequencies from ``low`` to ``high`` (capped at the
    Nyquist frequency π/dt and 1e300), with 81 points within ±10ζ of the damped and natural
    frequencies of each lightly damped root of ``s`` (continuous-time roots), and the Nyquist
    frequency of a discrete loop."""
    nyquist = math.pi / dt if dt else math.inf
    high = min(high, nyquist, 1e300)
    # Not below 1e-300 (roots and gains near 1e-300 put low at a subnormal or 0, and high/low
    # overflowed: numpy's warning, then int(inf)).
    low = max(min(low, high / 10.0), 1e-300)
    decades = math.log10(high) - math.log10(low)
    grid = [np.logspace(math.log10(low), math.log10(high), int(decades * POINTS_PER_DECADE) + 2)]
    for root in s[np.isfinite(s)]:
        omega_n = abs(root)
        if omega_n == 0 or abs(root.imag) <= 1e-12 * omega_n:
            continue
        zeta = min(abs(root.real) / omega_n, 1.0)
        spread = np.linspace(-10.0, 10.0, 81) * max(zeta, 1e-6)
        grid.append(abs(root.imag) * (1.0 + spread))
        grid.append(omega_n * (1.0 + spread))
    omega = np.concatenate(grid)
    omega = omega[(omega > 0) & (omega <= high)]
    return _separated(np.concatenate([omega, [nyquist]]) if dt else omega)


def _separated(omega: FloatArray) -> FloatArray:
    """``omega`` sorted, keeping the first of points within 1e-9 of each other (relative):
    the clusters about a conjugate pair of roots differ in their last bits (ln z̄ is not
    exactly the conjugate of ln z), and a grid maximum whose neighbour is its near twin left
    :func:`_extremum` a bracket of zero width, so no refinement (a discrete loop's disk margin
    came out 1.3e-4 too large)."""
    ordered = np.sort(omega)
    if ordered.size == 0:
        return np.asarray(ordered, dtype=np.float64)
    keep = [0]
    for i in range(1, ordered.size):
        if ordered[i] == math.inf or ordered[i] - ordered[keep[-1]] > 1e-9 * ordered[i]:
            keep.append(i)
    return np.asarray(ordered[keep], dtype=np.float64)


# ----- margins ------------------------------------------------------------------------------


@set_at_once
@dataclass(frozen=True, eq=False)
class StabilityMargins(Result):
    """The margins of a SISO loop, negative feedback (1 + L = 0); ``print`` shows a table.

    Single values are the critical ones (as python-control's ``stability_margins``): the gain
    margin closest to 0 dB, the phase margin of least magnitude; the arrays hold every
    crossover, by increasing frequency.

    Attributes
    ----------
    gain_margin : float
        The critical gain margin (factor; ∞ without a phase crossover).
    gain_margin_db : float
        The critical gain margin in dB (negative: a gain reduction margin).
    phase_crossover : float
        Its frequency (rad/s; NaN without one).
    phase_margin : float
        The critical phase margin (degrees, signed; ∞ without a gain crossover).
    gain_crossover : float
        Its frequency (rad/s; NaN without one).
    delay_margin : float
        The critical delay margin (s); 0 if the closed loop is unstable, ∞ without a gain
        crossover above 0.
    disk_margin : float
        α of the balanced disk margin (σ = 0); 0 if the closed loop is unstable.
    disk_frequency : float
        Where abs(S - T)/2 peaks (rad/s).
    disk_gain_margin : tuple of float
        The gain range [(2 - α)/(2 + α), (2 + α)/(2 - α)] of the disk margin.
    disk_phase_margin : float
        ±2 arctan(α/2) in degrees: the phase change at unit gain the disk allows.
    stability_margin : float
        min abs(1 + L(jω)), the distance from the Nyquist plot to -1 (1/||S||∞).
    stability_frequency : float
        Where that minimum is (rad/s).
    gain_margins, phase_crossovers : ndarray (g,)
        Every gain margin (factor) and its phase crossover (rad/s), by increasing frequency.
    phase_margins, gain_crossovers : ndarray (c,)
        Every phase margin (degrees) and its gain crossover (rad/s), by increasing frequency.
    delay_margins : ndarray
        (PM_i in rad, in [0, 2π))/ω_i at each gain crossover above 0 (s).
    closed_loop_poles : ndarray (n,), complex
        The poles of the loop closed with negative unit feedback.
    closed_loop_stable : bool
        Whether every closed-loop pole is in the open left half plane (inside the unit circle).
    open_loop_unstable_poles : int
        P: open-loop poles in the open right half plane (outside the unit circle).
    encirclements : int
        Counterclockwise encirclements of -1 by the Nyquist plot: P - Z.

    Examples
    --------
    2/(s(s + 1)(s + 2)) crosses -180° at ω = √2, where abs(L) = 1/3: a gain margin of 3
    (9.54 dB):

    >>> import numpy as np, aerocontrol
    >>> m = aerocontrol.stability_margins(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0))
    >>> round(m.gain_margin, 10), round(m.gain_margin_db, 4), round(m.phase_crossover**2, 10)
    (3.0, 9.5424, 2.0)
    >>> m.closed_loop_stable, m.encirclements
    (True, 0)
    """

    gain_margin: float
    """The critical gain margin (factor; ∞ without a phase crossover)."""
    phase_crossover: float
    """Its frequency (rad/s; NaN without one)."""
    phase_margin: float
    """The critical phase margin (degrees, signed; ∞ without a gain crossover)."""
    gain_crossover: float
    """Its frequency (rad/s; NaN without one)."""
    delay_margin: float
    """Seconds; 0 if the closed loop is unstable, ∞ without a gain crossover above 0."""
    disk_margin: float
    """α of the balanced disk margin (σ = 0); 0 if the closed loop is unstable."""
    disk_frequency: float
    """Where abs(S - T)/2 peaks (rad/s)."""
    stability_margin: float
    """min abs(1 + L(jω)), the distance from the Nyquist plot to -1 (1/||S||∞)."""
    stability_frequency: float
    gain_margins: FloatArray
    phase_crossovers: FloatArray
    phase_margins: FloatArray
    gain_crossovers: FloatArray
    delay_margins: FloatArray
    """(PM_i in rad, in [0, 2π))/ω_i at each gain crossover above 0."""
    closed_loop_poles: ComplexArray
    closed_loop_stable: bool
    open_loop_unstable_poles: int
    """P: open-loop poles in the open right half plane (outside the unit circle)."""
    encirclements: int
    """Counterclockwise encirclements of -1 by the Nyquist plot: P - Z."""

    @property
    def gain_margin_db(self) -> float:
        """The critical gain margin in dB (negative: a gain reduction margin)."""
        return _db(self.gain_margin)

    @property
    def disk_gain_margin(self) -> tuple[float, float]:
        """The gain range [(2 - α)/(2 + α), (2 + α)/(2 - α)] of the disk margin; from α >= 2
        every positive gain: [0, ∞]."""
        return _disk_gain_interval(self.disk_margin, 0.0)

    @property
    def disk_phase_margin(self) -> float:
        """±2 arctan(α/2) in degrees: the phase change at unit gain the disk allows."""
        return _disk_phase_margin(self.disk_margin, 0.0)

    def _cells(self) -> tuple[str, list[tuple[str, str, str, str]]]:
        """The closed loop's line, and (margin, value, unit, frequency) per margin."""
        status = "stable" if self.closed_loop_stable else "UNSTABLE"
        title = (
            f"closed loop {status}: {self.open_loop_unstable_poles} unstable open-loop poles, "
            f"{self.encirclements} counterclockwise encirclements of -1"
        )
        rows = [
            ("gain margin", f"{_db(gm):+.3f}", "dB", f"{w:.5g}")
            for gm, w in zip(self.gain_margins, self.phase_crossovers, strict=True)
        ]
        rows += [
            ("phase margin", f"{pm:+.3f}", "deg", f"{w:.5g}")
            for pm, w in zip(self.phase_margins, self.gain_crossovers, strict=True)
        ]
        rows.append(("delay margin", f"{self.delay_margin:.5g}", "s", ""))
        low, high = self.disk_gain_margin
        rows.append(
            (
                "disk margin",
                f"alpha = {self.disk_margin:.4g}: gain {_db(low):+.2f}/{_db(high):+.2f} dB, "
                f"phase ±{self.disk_phase_margin:.2f} deg",
                "",
                f"{self.disk_frequency:.4g}",
            )
        )
        return title, rows

    def table(self) -> str:
        """The margins and the closed loop, one line each."""
        title, rows = self._cells()
        lines = [title]
        for name, value, unit, frequency in rows:
            if name == "delay margin":
                lines.append(f"{name:<14}{value} {unit}")
            elif name == "disk margin":
                lines.append(f"{name:<14}{value} (at {frequency} rad/s)")
            else:
                lines.append(f"{name:<14}{value:>9} {unit:<3} at {frequency} rad/s")
        return "\n".join(lines)

    def _tables(self) -> list[Tabular]:
        title, rows = self._cells()
        cells = [
            (name, f"{value} {unit}".rstrip(), frequency) for name, value, unit, frequency in rows
        ]
        return [Tabular(title, ("margin", "value", "at (rad/s)"), cells)]

    def __str__(self) -> str:
        return self.table()


def _db(factor: float) -> float:
    if factor == 0.0:
        return -math.inf
    return 20.0 * math.log10(factor) if math.isfinite(factor) else math.inf


def stability_margins(loop: System) -> StabilityMargins:
    """Gain, phase, delay and disk margins of a SISO loop, with every crossover, and the
    closed loop's stability from its poles (negative feedback: 1 + L(s) = 0).

    See the module's documentation for the definitions. Integrators (poles at 0) are
    allowed; an unstable open loop is allowed (the encirclement count and closed-loop
    stability are reported, and a stable closed loop needs P counterclockwise
    encirclements); discrete loops are evaluated on the unit circle up to the Nyquist
    frequency.

    Parameters
    ----------
    loop : StateSpace or (A, B, C, D)
        The open-loop transfer L, one input and one output.

    Returns
    -------
    StabilityMargins

    Raises
    ------
    ShapeError
        The loop is not single-input, single-output.
    SingularMatrixError
        1 + D = 0: closing the loop is an algebraic loop.
    AerocontrolLinAlgError
        A gain margin failed its check: the loop closed with that gain has no pole at the
        phase crossover.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # k/(s(s + 1)(s + 2)) with k = 2: GM = 6/k = 3 at ω = √2 (a closed form).
    >>> m = aerocontrol.stability_margins(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0))
    >>> round(m.gain_margin, 12), round(m.phase_crossover**2, 12)
    (3.0, 2.0)
    >>> round(m.phase_margin, 4), m.closed_loop_stable
    (32.6131, True)
    >>> aerocontrol.stability_margins(aerocontrol.tf([1.0], [1.0, 0.0])).gain_margin  # 1/s
    inf
    """
    model = _siso(loop)
    if model.is_discrete:
        return _grid_margins(model)
    d = float(model.D[0, 0])
    if abs(1.0 + d) <= 8 * _EPS * max(1.0, abs(d)):
        _refuse_algebraic(model)
    try:
        core = _core.loop_margins(model.A, model.B, model.C, model.D)
        if core is not None:
            return _continuous_margins(model, core)
        # A term beyond 2^RESCALE_EXPONENT: the core took no step.
        size_B, size_C = _log2_size(model.B), _log2_size(model.C)
        exponent = _frequency_exponent(model, size_B, size_C)
        slowed = _slowed(model, exponent)
        core = _core.loop_margins(slowed.A, slowed.B, slowed.C, slowed.D)
        if core is None:
            return _grid_margins(model)
        margins = _in_frequency_units(_continuous_margins(slowed, core), exponent)
        # The open-loop poles of the slowed loop, A 2^-e, may underflow (a pole 1.3e-301
        # beside B C of 1.6e148 became 0, not unstable): counted from A itself.
        open_matrix = balanced_states(model).A
        unstable_open = _unstable_count(
            _eigenvalues(open_matrix), False, _balanced_size(open_matrix), lambda: open_matrix
        )
        unstable_closed = margins.open_loop_unstable_poles - margins.encirclements
        return dataclasses.replace(
            margins,
            open_loop_unstable_poles=unstable_open,
            encirclements=unstable_open - unstable_closed,
        )
    except NonFiniteError:
        # The loop is finite (checked above), so this is an overflow inside the core's
        # pencils: B and C near 1e154 beside D near 1e308 (after the balancing of _slowed)
        # overflow in its products with D. The grid search needs only L(jω) and the
        # closed-loop eigenvalues, formed with the scalings that keep them finite.
        return _grid_margins(model)


def _frequency_exponent(model: StateSpace, size_B: float, size_C: float) -> int:
    """e such that the loop's matrices (A, and B C/(1 + D) of the closed loop) are of size
    about 2^e, where that is beyond 2^RESCALE_EXPONENT; else 0 (``size_B``, ``size_C``: the
    :func:`_log2_size` of B and C)."""
    d = float(model.D[0, 0])
    size = max(_log2_size(model.A), size_B + size_C - math.log2(abs(1.0 + d)))
    return round(size) if size > RESCALE_EXPONENT else 0


def _slowed(model: StateSpace, exponent: int) -> StateSpace:
    """The loop L(2^e s): (A 2^-e, B 2^-e, C, D), whose frequencies are those of L divided by
    2^e (exact), with its state then scaled by a power of two so that B and C are of one size,
    or the nonzero one of unit size (which changes no transfer function)."""
    B = np.ldexp(model.B, -exponent)
    size_B, size_C = _log2_size(B), _log2_size(model.C)
    if math.isfinite(size_B) and math.isfinite(size_C):
        balance = round((size_C - size_B) / 2.0)
    elif math.isfinite(size_B) or math.isfinite(size_C):  # L = D: the other to unit size
        balance = -round(size_B) if math.isfinite(size_B) else round(size_C)
    else:
        balance = 0
    return StateSpace(
        np.ldexp(model.A, -exponent),
        np.ldexp(B, balance),
        np.ldexp(model.C, -balance),
        model.D,
        dt=model.dt,
    )


def _in_frequency_units(margins: StabilityMargins, exponent: int) -> StabilityMargins:
    """The margins of L from those of L(2^e s) (:func:`_slowed`): frequencies and poles times
    2^e, delays divided by it, gains and phases unchanged; values beyond the range of doubles
    are infinite, with a NumericalOverflowWarning."""

    def faster(x: FloatArray) -> FloatArray:
        return np.asarray(np.ldexp(x, exponent), dtype=np.float64)

    with np.errstate(over="ignore", invalid="ignore"):
        poles = margins.closed_loop_poles
        result = dataclasses.replace(
            margins,
            phase_crossover=float(faster(np.float64(margins.phase_crossover))),
            gain_crossover=float(faster(np.float64(margins.gain_crossover))),
            delay_margin=float(np.ldexp(margins.delay_margin, -exponent)),
            disk_frequency=float(faster(np.float64(margins.disk_frequency))),
            stability_frequency=float(faster(np.float64(margins.stability_frequency))),
            phase_crossovers=faster(margins.phase_crossovers),
            gain_crossovers=faster(margins.gain_crossovers),
            delay_margins=np.ldexp(margins.delay_margins, -exponent),
            closed_loop_poles=(faster(poles.real) + 1j * faster(poles.imag)).astype(np.complex128),
        )
    moved = np.concatenate(
        [result.phase_crossovers, result.gain_crossovers, result.closed_loop_poles.view(float)]
    )
    if not np.all(np.isfinite(moved)):
        warnings.warn(
            "stability_margins: a crossover frequency or a closed-loop pole of the loop "
            "overflows double precision: it is infinite",
            NumericalOverflowWarning,
            stacklevel=3,
        )
    return result


def _continuous_margins(model: StateSpace, core: _core._LoopMarginsOutput) -> StabilityMargins:
    """:func:`stability_margins` of a continuous loop from the core's eigenvalue methods'
    results on it, ``core``: the crossovers' margins, the peaks, the poles, and the census of
    the poles where each is farther from the axis than :func:`_boundary_tolerance` (else
    None, and :func:`_census` decides with the poles' error bounds)."""
    (
        crossovers,
        disk,
        (stab_w, sensitivity_peak),
        closed,
        open_poles,
        degenerate,
        closed_size,
        open_size,
        closed_census,
        open_census,
    ) = core
    if degenerate:
        # L(s) - L(-s) vanishes identically (L real on the whole axis): no pencil to locate
        # the phase crossovers, so the grid search decides.
        return _grid_margins(model)
    if closed_census is None:
        closed_census = _census(
            closed, False, closed_size, functools.partial(_closed_matrix, model)
        )
    if open_census is None:
        open_census = _census(open_poles, False, open_size, lambda: model.A)
    unstable_closed, stable = closed_census
    return _assemble(
        crossovers,
        disk=disk,
        stability=(stab_w, 1.0 / sensitivity_peak),
        closed=closed,
        stable=stable,
        unstable_open=open_census[0],
        unstable_closed=unstable_closed,
    )


def _grid_margins(model: StateSpace) -> StabilityMargins:
    """:func:`stability_margins` on a dense frequency grid refined by Brent's method: the
    method for discrete loops (the eigenvalue method of the core is continuous only) and for
    a loop real on the whole imaginary axis (its phase-crossover pencil is singular)."""
    discrete = model.is_discrete
    closed = _closed_loop_poles(model, np.ones(1))[0]
    open_matrix = balanced_states(model).A
    open_poles = _eigenvalues(open_matrix)
    closed_matrix = _closed_matrix(model)
    closed_size = _balanced_size(closed_matrix)
    stable = _closed_loop_stable(closed, discrete, closed_size, lambda: closed_matrix)
    unstable_open = _unstable_count(
        open_poles, discrete, _balanced_size(open_matrix), lambda: open_matrix
    )
    unstable_closed = _unstable_count(closed, discrete, closed_size, lambda: closed_matrix)

    response = _Response(model)
    omega = _grid(model)
    values = response.many(omega)
    finite = np.isfinite(values) & (values != 0)
    omega, values = omega[finite], values[finite]

    # Phase crossovers: angle(-L) changes sign where L crosses the negative real axis.
    def minus_angle(w: float) -> float:
        return float(np.angle(-response.one(w)))

    phase_w: list[float] = []
    angles = np.angle(-values)
    for i in np.nonzero(np.sign(angles[:-1]) != np.sign(angles[1:]))[0]:
        if abs(angles[i]) > math.pi / 2 or abs(angles[i + 1]) > math.pi / 2:
            continue  # a crossing of the positive real axis (angle jumps by 2π)
        w = _brent(minus_angle, omega[i], omega[i + 1], angles[i], angles[i + 1], 0.0)
        if response.one(w).real < 0:
            phase_w.append(float(w))
    ends = [0.0] + ([math.pi / period(model)] if discrete else [])
    largest = float(_magnitude(values).max(initial=0.0))
    for w in ends:
        value = response.one(w)
        # Not where L vanishes (a zero at the origin, a washout): no crossing there.
        if (
            np.isfinite(value)
            and value.real < -1e-10 * largest
            and abs(value.imag) <= 1e-12 * math.hypot(value.real, value.imag)
        ):
            phase_w.append(float(w))
    phase_crossings = [(w, response.one(w)) for w in sorted(set(phase_w))]

    # Gain crossovers: log|L| changes sign.
    def log_magnitude(w: float) -> float:
        return math.log(float(_magnitude(np.array([response.one(w)]))[0]))

    logs = np.log(_magnitude(values))
    gain_w: list[float] = []
    for i in np.nonzero(np.sign(logs[:-1]) != np.sign(logs[1:]))[0]:
        gain_w.append(
            float(_brent(log_magnitude, omega[i], omega[i + 1], logs[i], logs[i + 1], 0.0))
        )
    gain_crossings = [(w, response.one(w)) for w in sorted(set(gain_w))]

    # |S - T|/2 = |1 - L|/(2|1 + L|) and |1 + L|, peak and minimum refined.
    def half_difference(w: FloatArray) -> FloatArray:
        return _half_difference(response.many(w))

    def distance(w: FloatArray) -> FloatArray:
        return -_magnitude(1 + response.many(w))

    # ω = 0 too, where L is finite (the grid starts above it).
    at_zero = response.one(0.0)
    if np.isfinite(at_zero) and omega.size:
        omega, values = np.concatenate([[0.0], omega]), np.concatenate([[at_zero], values])
    disk_w, disk_peak = _extremum(omega, _half_difference(values), half_difference)
    if not discrete:  # the supremum may be approached as ω → ∞, where L = D
        d = float(model.D[0, 0])
        at_infinity = float(_half_difference(np.array([d]))[0])
        if at_infinity > disk_peak:
            disk_w, disk_peak = math.inf, at_infinity
    stab_w, stab_peak = _extremum(omega, -_magnitude(1 + values), distance)

    result = _assemble(
        _core.crossover_margins(
            [w for w, _ in phase_crossings],
            [(value.real, value.imag) for _, value in phase_crossings],
            [w for w, _ in gain_crossings],
            [(value.real, value.imag) for _, value in gain_crossings],
        ),
        disk=(disk_w, disk_peak),
        stability=(stab_w, -stab_peak),
        closed=closed,
        stable=stable,
        unstable_open=unstable_open,
        unstable_closed=unstable_closed,
    )
    _verify_gain_margins(model, result)
    return result


def _assemble(
    crossovers: _core._CrossoverMarginsOutput,
    *,
    disk: tuple[float, float],
    stability: tuple[float, float],
    closed: ComplexArray,
    stable: bool,
    unstable_open: int,
    unstable_closed: int,
) -> StabilityMargins:
    """The result object from the margins of the crossovers (the core's
    ``crossover_margins``: the gain margins 1/|L| at the phase crossovers where L < 0, the
    phase margins 180° + ∠L in (-180°, 180°] at the gain crossovers and the delay margins
    (phase margin mod 360°)/ω, in one array, with the critical ones), the peaks and the
    ``closed``-loop poles sorted as ``numpy.sort_complex``. The five arrays are views of
    disjoint parts of the core's one."""
    array, (g, c), (gm, w_gm, pm, w_pm, delay) = crossovers
    if not stable:
        delay, alpha = 0.0, 0.0
    else:
        alpha = 1.0 / disk[1] if disk[1] > 0 else math.inf
    return from_fields(
        StabilityMargins,
        {
            "gain_margin": gm,
            "phase_crossover": w_gm,
            "phase_margin": pm,
            "gain_crossover": w_pm,
            "delay_margin": delay,
            "disk_margin": alpha,
            "disk_frequency": disk[0],
            "stability_margin": stability[1],
            "stability_frequency": stability[0],
            "gain_margins": array[:g],
            "phase_crossovers": array[g : 2 * g],
            "phase_margins": array[2 * g : 2 * g + c],
            "gain_crossovers": array[2 * g + c : 2 * g + 2 * c],
            "delay_margins": array[2 * g + 2 * c :],
            "closed_loop_poles": closed,
            "closed_loop_stable": stable,
            "open_loop_unstable_poles": unstable_open,
            "encirclements": unstable_open - unstable_closed,
        },
    )


def _extremum(
    omega: FloatArray,
    values: FloatArray,
    f: Callable[[FloatArray], FloatArray],
    intervals: int = 64,
) -> tuple[float, float]:
    """(ω, f(ω)) at the grid's maximum of ``values``, refined between its neighbours by
    zooming: ``intervals`` + 1 points in one call of the core, then again within a step of
    the best point so far, until the bracket is 1e-9 of ω wide (of the first bracket, for a
    maximum at ω = 0; near a smooth maximum f is then within about 1e-16 of it). A round that
    finds nothing better still narrows the bracket about the best point: the maximum may lie
    within a step of it (stopping there left 1/||S||∞ of k/(s(s + 1)(s + 2)) 1.8e-10 too
    large, 5e-6 off in ω)."""
    if omega.size == 0:
        return math.nan, math.nan
    i = int(np.argmax(values))
    best_w, best_value = float(omega[i]), float(values[i])
    low, high = float(omega[max(i - 1, 0)]), float(omega[min(i + 1, omega.size - 1)])
    first = high - low
    while high - low > 1e-9 * max(best_w, first, 1e-300):
        points = np.linspace(low, high, intervals + 1)
        found = f(points)
        j = int(np.nanargmax(found)) if np.any(np.isfinite(found)) else 0
        if found[j] > best_value:
            best_w, best_value = float(points[j]), float(found[j])
        step = (high - low) / intervals
        low, high = max(best_w - step, low), min(best_w + step, high)
    return best_w, best_value


def _verify_gain_margins(model: StateSpace, margins: StabilityMargins) -> None:
    """Each gain margin k must put a closed-loop pole of 1 + k L = 0 at the phase crossover
    (jω, or e^{jω dt}); a miss beyond 1e-6 of the pole's size is an error."""
    dt = period(model) if model.is_discrete else 0.0
    scale = 1.0 + float(np.abs(model.A).max(initial=0.0))
    d = float(model.D[0, 0])
    for k, w in zip(margins.gain_margins, margins.phase_crossovers, strict=True):
        if not math.isfinite(k):
            continue
        if abs(1.0 + k * d) <= 8 * _EPS * max(1.0, abs(k * d)):
            # L is D to rounding (a dynamic part of 1e-302 beside D of -0.04): 1 + k D = 0 in
            # doubles, an algebraic loop whose poles cannot be formed, so nothing to check.
            continue
        point = np.exp(1j * w * dt) if dt else 1j * w
        poles = _closed_loop_poles(model, np.array([k]))[0]
        with np.errstate(over="ignore", invalid="ignore"):
            gaps = np.nan_to_num(_magnitude(poles - point), nan=np.inf)
        miss = float(gaps.min(initial=0.0)) if poles.size else 0.0
        if poles.size and miss > 1e-6 * max(scale, math.hypot(point.real, point.imag)):
            raise AerocontrolLinAlgError(
                f"stability_margins: the loop closed with its gain margin {k:.6g} has no pole "
                f"at the phase crossover {w:.6g} rad/s (nearest at distance {miss:.3g})"
            )


def sensitivity(loop: System) -> StateSpace:
    """S = 1/(1 + L): from a disturbance at the loop's output to the output, negative
    feedback; the state space of :func:`~aerocontrol.feedback` (unity forward, L in the
    return path).

    Parameters
    ----------
    loop : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The open loop L, one input and one output (continuous or discrete).

    Returns
    -------
    StateSpace
        S, of the loop's order and time base.

    Raises
    ------
    ShapeError
        ``loop`` has not one input and one output (select the channel with
        ``loop[output, input]``).
    NotRealError
        ``loop`` is not a model.
    SingularMatrixError
        1 + D = 0: an algebraic loop.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> S = aerocontrol.sensitivity(aerocontrol.tf([2.0], [1.0, 1.0]))   # (s + 1)/(s + 3)
    >>> round(float(aerocontrol.dc_gain(S)[0, 0]), 12)
    0.333333333333
    """
    model = _siso(loop)
    unity = gain(1.0, dt=model.dt)
    dt = _time_base([unity, model], ["1", "loop"], "sensitivity")
    return _closed(unity, model, -1.0, dt, "sensitivity", "loop")


def complementary_sensitivity(loop: System) -> StateSpace:
    """T = L/(1 + L): the closed loop from the reference to the output, negative feedback
    (:func:`~aerocontrol.feedback` with unity return). S + T = 1.

    Parameters
    ----------
    loop : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The open loop L, one input and one output (continuous or discrete).

    Returns
    -------
    StateSpace
        T, of the loop's order and time base.

    Raises
    ------
    ShapeError
        ``loop`` has not one input and one output (select the channel with
        ``loop[output, input]``).
    NotRealError
        ``loop`` is not a model.
    SingularMatrixError
        1 + D = 0: an algebraic loop.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> T = aerocontrol.complementary_sensitivity(aerocontrol.tf([2.0], [1.0, 1.0]))
    >>> round(float(aerocontrol.dc_gain(T)[0, 0]), 12)                   # 2/(s + 3)
    0.666666666667
    """
    model = _siso(loop)
    unity = gain(1.0, dt=model.dt)
    dt = _time_base([model, unity], ["loop", "1"], "complementary_sensitivity")
    return _closed(model, unity, -1.0, dt, "complementary_sensitivity", "loop")


# ----- disk margins of a MIMO loop ----------------------------------------------------------


def _disk_gain_interval(alpha: float, skew: float) -> tuple[float, float]:
    """The positive gains [γ_min, γ_max] of the disk D(α, σ) that contain 1 (its real
    intercepts, Seiler, Packard and Gahinet): γ_min = (2 - α(1 - σ))/(2 + α(1 + σ)), γ_max =
    (2 + α(1 - σ))/(2 - α(1 + σ)); γ_max = ∞ once α(1 + σ) >= 2 (the disk holds every large
    gain) and γ_min = 0 once the disk holds 0 (the loop may be opened)."""
    if alpha == 0.0:
        return (1.0, 1.0)
    if not math.isfinite(alpha):
        return (0.0, math.inf)
    low_denominator = 2.0 + alpha * (1.0 + skew)
    low = (
        0.0 if low_denominator <= 0.0 else max(0.0, (2.0 - alpha * (1.0 - skew)) / low_denominator)
    )
    high_denominator = 2.0 - alpha * (1.0 + skew)
    high = math.inf if high_denominator <= 0.0 else (2.0 + alpha * (1.0 - skew)) / high_denominator
    return (low, high)


def _disk_phase_margin(alpha: float, skew: float) -> float:
    """The phase change (degrees) at unit gain that the disk D(α, σ) allows: the unit circle
    meets the disk's boundary at cos φ = (1 + γ_min γ_max)/(γ_min + γ_max), which is
    φ = 2 arctan(α/√(4 - α²σ²)) (2 arctan(α/2) for σ = 0); 180° once |ασ| >= 2, where the
    disk holds the whole unit circle."""
    if not math.isfinite(alpha) or abs(alpha * skew) >= 2.0:
        return 180.0
    return math.degrees(2.0 * math.atan(alpha / math.sqrt(4.0 - (alpha * skew) ** 2)))


@dataclass(frozen=True, eq=False)
class DiskMargin(Result):
    """A disk margin α of skew σ: the loop stays stable for every multiplicative gain and phase
    change f (in every loop at once, independently, for a multiloop margin) in the disk

        D(α, σ) = {(1 + (1 - σ) δ/2)/(1 - (1 + σ) δ/2) : abs(δ) < α},

    whose real intercepts are :attr:`gain_margin` and which holds the phase changes of up to
    :attr:`phase_margin` either way at unit gain (Seiler, Packard and Gahinet 2020).

    Attributes
    ----------
    alpha : float
        α = 1/sup_ω abs(S + (σ - 1)/2) (a structured singular value for a multiloop margin); 0
        when the closed loop is unstable.
    skew : float
        σ: 0 balances gain increase and decrease; σ > 0 favours increase, σ < 0 decrease.
    frequency : float
        Where the peak is (rad/s; ∞ as ω → ∞, NaN when the closed loop is unstable).
    gain_margin : tuple of float
        [γ_min, γ_max]: the gains (factors) the loop tolerates with no phase change.
    gain_margin_db : tuple of float
        ``gain_margin`` in dB.
    phase_margin : float
        ± this many degrees of phase change at unit gain are tolerated.

    Examples
    --------
    The integrator loop 1/s has S - T = (s - 1)/(s + 1), of modulus 1 at every frequency, so
    α = 2: any gain increase or decrease, and ±90°:

    >>> import aerocontrol
    >>> disk = aerocontrol.disk_margins(aerocontrol.zpk([], [0.0], 1.0)).loop_at_a_time[0]
    >>> disk.alpha, disk.gain_margin, disk.phase_margin
    (2.0, (0.0, inf), 90.0)
    """

    alpha: float
    """α = 1/sup_ω abs(S + (σ - 1)/2) (a structured singular value for a multiloop margin); 0
    when the closed loop is unstable."""
    skew: float
    """σ: 0 balances gain increase and decrease; σ > 0 favours increase, σ < 0 decrease."""
    frequency: float
    """Where the peak is (rad/s; ∞ as ω → ∞, NaN when the closed loop is unstable)."""

    @property
    def gain_margin(self) -> tuple[float, float]:
        """[γ_min, γ_max]: the gains (factors) the loop tolerates with no phase change."""
        return _disk_gain_interval(self.alpha, self.skew)

    @property
    def gain_margin_db(self) -> tuple[float, float]:
        """:attr:`gain_margin` in dB."""
        low, high = self.gain_margin
        return (_db(low), _db(high))

    @property
    def phase_margin(self) -> float:
        """± this many degrees of phase change at unit gain are tolerated."""
        return _disk_phase_margin(self.alpha, self.skew)

    def describe(self) -> str:
        """One line: α, the gain range in dB, the phase range and the frequency."""
        low, high = self.gain_margin_db
        return (
            f"alpha = {self.alpha:.4g}: gain {low:+.2f}/{high:+.2f} dB, phase "
            f"±{self.phase_margin:.2f} deg (at {self.frequency:.4g} rad/s)"
        )


@dataclass(frozen=True, eq=False)
class DiskMargins(Result):
    """Loop-at-a-time and multiloop disk margins of a square MIMO loop; ``print`` shows a
    table.

    The multiloop margin is computed within bounds (a structured singular value): its
    :attr:`multiloop` α is the guaranteed one (from the upper bound of μ), and
    :attr:`multiloop_bounds` gives it with the α of a destabilising perturbation found (from
    the lower bound), which the true margin cannot exceed.

    Attributes
    ----------
    skew : float
        σ of every disk (0 balances gain increase and decrease).
    names : tuple of str
        The loop break points: the loop's input names.
    loop_at_a_time : tuple of DiskMargin
        The disk margin of each loop broken with the others closed.
    multiloop : DiskMargin
        Simultaneous independent changes f_i in D(α, σ) in every loop: α = 1/sup_ω μ̄, the
        guaranteed (lower) bound of the margin.
    multiloop_bounds : tuple of float
        (α guaranteed, α of ``worst_perturbation``): the true multiloop margin lies between them.
    worst_perturbation : ndarray (p,), complex
        The gains f_i that put a closed-loop pole at j ``worst_frequency``: the certificate that
        the margin is no larger (ones when the closed loop is unstable; NaN when μ = 0).
    worst_frequency : float
        The frequency of ``worst_perturbation`` (rad/s).
    frequencies : ndarray (k,)
        The frequencies (rad/s, increasing; ∞ last for a continuous loop on the default grid) at
        which the bounds of μ were computed.
    mu_upper, mu_lower : ndarray (k,)
        Upper and lower bounds of μ_Δ(S + (σ - 1)/2 I) at each frequency.
    loops : tuple of StabilityMargins
        The classical margins of each loop broken with the others closed
        (:func:`~aerocontrol.stability_margins`).
    closed_loop_poles : ndarray (n,), complex
        The poles of the loop closed as u = -y (rad/s, or z for a discrete loop).
    closed_loop_stable : bool
        Whether every closed-loop pole is in the open left half plane (inside the unit circle).

    Examples
    --------
    >>> import aerocontrol
    >>> margins = aerocontrol.disk_margins(aerocontrol.zpk([], [0.0], 1.0))     # 1/s
    >>> margins.names, margins.closed_loop_stable
    (('u0',), True)
    >>> margins.multiloop.alpha, margins.multiloop_bounds        # one loop: α = 2 both ways
    (2.0, (2.0, 2.0))
    """

    skew: float
    names: tuple[str, ...]
    """The loop break points: the loop's input names."""
    loop_at_a_time: tuple[DiskMargin, ...]
    """The disk margin of each loop broken with the others closed."""
    multiloop: DiskMargin
    """Simultaneous independent changes f_i in D(α, σ) in every loop: α = 1/sup_ω μ̄, the
    guaranteed (lower) bound of the margin."""
    multiloop_bounds: tuple[float, float]
    """(α guaranteed, α of :attr:`worst_perturbation`): the true multiloop margin lies
    between them; equal for p <= 3 loops to the accuracy of the computation."""
    worst_perturbation: ComplexArray
    """The gains f_i (complex: gain and phase per loop), each on the boundary of
    D(multiloop_bounds[1], σ), that put a closed-loop pole at j·:attr:`worst_frequency`: the
    certificate that the margin is no larger (ones when the closed loop is unstable; NaN
    when μ = 0, as no perturbation destabilises the loop)."""
    worst_frequency: float
    frequencies: FloatArray
    """The frequencies (rad/s, increasing; ∞ last for a continuous loop on the default grid)
    at which the bounds of μ were computed."""
    mu_upper: FloatArray
    """An upper bound of μ_Δ(S + (σ - 1)/2 I) at each frequency (the D-scaling optimised where
    it could set the peak, Osborne's scaling elsewhere)."""
    mu_lower: FloatArray
    """A lower bound of μ at each frequency (a destabilising perturbation of size 1/μ)."""
    loops: tuple[StabilityMargins, ...]
    """The classical margins of each loop broken with the others closed
    (:func:`stability_margins`)."""
    closed_loop_poles: ComplexArray
    closed_loop_stable: bool

    def table(self) -> str:
        """The closed loop, each loop's margins and the multiloop margin, one line each."""
        status = "stable" if self.closed_loop_stable else "UNSTABLE"
        labels = [f"loop {name}" for name in self.names] + ["multiloop"]
        width = max(len(label) for label in labels)
        lines = [f"closed loop {status}; disk margins of skew {self.skew:g}"]
        for label, disk, classical in zip(labels, self.loop_at_a_time, self.loops, strict=False):
            lines.append(
                f"{label:<{width}}  {disk.describe()}; classical gain margin "
                f"{classical.gain_margin_db:+.2f} dB, phase margin "
                f"{classical.phase_margin:+.2f} deg"
            )
        low, high = self.multiloop_bounds
        lines.append(
            f"{labels[-1]:<{width}}  {self.multiloop.describe()}; alpha within "
            f"[{low:.4g}, {high:.4g}]"
        )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()


#: A gap between the bounds of the peak of μ above this fraction of the upper bound warns
#: (LooseBoundWarning): the multiloop margin is then known only within that gap.
MU_GAP_TOLERANCE = 0.02

#: The destabilising perturbation must leave σ_min(I + L + (aL - b)Δ) within this fraction of
#: the size of its terms (I + L F, times the nonsingular (1 - bΔ), is singular), else the
#: computation failed its check.
CERTIFICATE_TOLERANCE = 1e-6

#: Bounds of μ that agree to this relative tolerance are taken as converged.
_TIGHT = 1e-12

#: The D-scaling search keeps log d_i within ± this (a loop that no scaling couples, such as
#: a triangular M, has its infimum at d → ∞; e^-60 leaves its coupling below rounding).
_LOG_SCALING_RANGE = 30.0

#: The exponents t of the smoothed objective (1/t) log Σ_k σ_k(D M D^-1)^t, in turn; it is
#: within log(p)/t of log σ̄ (a non-smooth optimum, where σ̄ is multiple, is reached to
#: about 1e-6: against AB13MD's bound on 300 random 4 x 4 and 5 x 5 matrices, from 4e-11
#: below to 6.4e-7 above; 3 x 3 within 4e-12).
_SMOOTHING = (16.0, 256.0, 4096.0, 65536.0, 1048576.0)

#: Newton steps per smoothing exponent (a stage ends sooner once a step lowers φ_t by less
#: than _STALLED: where σ̄ is multiple the steps then only zigzag), iterations of the power
#: method per start, and the seeded random starts of the power method where its first start
#: leaves a gap.
_NEWTON_STEPS = 20
_STALLED = 1e-10
_POWER_STEPS = 60
_POWER_RESTARTS = 3

#: Frequencies optimised before the others are screened: those of largest Osborne bound,
#: whose lower bounds then set the level below which a frequency cannot set the peak.
_SCREEN_FIRST = 8


@dataclass(frozen=True)
class _MuBounds:
    """Bounds of μ of a stack of matrices M (k, p, p) for diagonal complex Δ."""

    upper: FloatArray
    lower: FloatArray
    delta: ComplexArray
    """(k, p): the diagonal of a Δ with max|δ_i| = 1/lower and det(I - M Δ) = 0."""
    scaling: FloatArray
    """(k, p): log d of the D with σ̄(D M D^-1) = upper."""


def _scaled(M: ComplexArray, x: FloatArray) -> ComplexArray:
    """D M D^-1 with D = diag(e^x), for a stack."""
    return np.asarray(M * np.exp(x[:, :, None] - x[:, None, :]), dtype=np.complex128)


def _osborne(M: ComplexArray, sweeps: int = 20) -> FloatArray:
    """log d of the diagonal D that balances the off-diagonal row and column norms of
    D M D^-1 (Osborne's iteration, which minimises its Frobenius norm): the start of the
    D-scaling search."""
    k, p, _ = M.shape
    P = np.abs(M) ** 2
    P[:, np.arange(p), np.arange(p)] = 0.0
    x = np.zeros((k, p))
    for _ in range(sweeps):
        previous = x.copy()
        for i in range(p):
            e = np.exp(2.0 * x)
            column = np.einsum("kj,kj->k", P[:, :, i], e)
            row = np.einsum("kj,kj->k", P[:, i, :], 1.0 / e)
            both = (column > 0.0) & (row > 0.0)
            x[both, i] = 0.25 * (np.log(column[both]) - np.log(row[both]))
            x[(column > 0.0) & (row == 0.0), i] = _LOG_SCALING_RANGE
            x[(column == 0.0) & (row > 0.0), i] = -_LOG_SCALING_RANGE
        x = np.clip(x - x.mean(axis=1, keepdims=True), -_LOG_SCALING_RANGE, _LOG_SCALING_RANGE)
        if np.max(np.abs(x - previous), initial=0.0) <= 1e-12:
            break
    return x


def _smoothed(
    M: ComplexArray, x: FloatArray, t: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """φ_t(x) = (1/t) log Σ_k σ_k^t of D M D^-1 (D = diag(e^x)), its largest singular value,
    and the gradient of φ_t: Σ_k w_k (|u_k|² - |v_k|²) with w_k = σ_k^t / Σ σ^t (the
    derivative of log σ_k along x_i is |u_ki|² - |v_ki|², u_k and v_k its singular
    vectors)."""
    U, s, Vh = np.linalg.svd(_scaled(M, x))
    top = s[:, 0]
    safe = np.where(top > 0.0, top, 1.0)
    w = (s / safe[:, None]) ** t
    total = w.sum(axis=1)
    phi = np.log(safe) + np.log(total) / t
    w /= total[:, None]
    gradient = np.einsum("kj,kij->ki", w, np.abs(U) ** 2) - np.einsum(
        "kj,kji->ki", w, np.abs(Vh) ** 2
    )
    return phi, top, np.asarray(gradient, dtype=np.float64)


def _smoothed_value(M: ComplexArray, x: FloatArray, t: float) -> tuple[FloatArray, FloatArray]:
    """φ_t(x) and σ̄ of :func:`_smoothed`, without the singular vectors."""
    s = np.linalg.svd(_scaled(M, x), compute_uv=False)
    top = s[:, 0]
    safe = np.where(top > 0.0, top, 1.0)
    phi = np.log(safe) + np.log(((s / safe[:, None]) ** t).sum(axis=1)) / t
    return np.asarray(phi, dtype=np.float64), np.asarray(top, dtype=np.float64)


def _newton_step(M: ComplexArray, x: FloatArray, t: float) -> tuple[FloatArray, ...]:
    """φ_t, σ̄, the gradient, and the Newton direction of φ_t (Hessian by forward differences
    of the exact gradient, its eigenvalues floored to keep it positive definite; along
    (1, ..., 1), where φ_t is constant, no step)."""
    p = M.shape[1]
    phi, top, g = _smoothed(M, x, t)
    h = 1e-7
    H = np.empty((x.shape[0], p, p))
    for j in range(p):
        shifted = x.copy()
        shifted[:, j] += h
        H[:, :, j] = (_smoothed(M, shifted, t)[2] - g) / h
    values, vectors = np.linalg.eigh(0.5 * (H + H.transpose(0, 2, 1)))
    floor = 1e-10 * np.maximum(np.abs(values).max(axis=1, keepdims=True), 1.0)
    values = np.maximum(values, floor)
    direction = -np.einsum("kij,kj,klj,kl->ki", vectors, 1.0 / values, vectors, g)
    direction -= direction.mean(axis=1, keepdims=True)
    return phi, top, g, direction


def _descend(M: ComplexArray, bounds: _MuBounds) -> _MuBounds:
    """Minimise σ̄(D M D^-1) over positive diagonal D = diag(e^x), a convex function of x
    (Sezginer and Overton 1990), from the bounds' scaling: damped Newton steps (Armijo
    backtracking) on the smoothed φ_t for each t of _SMOOTHING in turn. Returns the bounds
    with the least σ̄ met as the upper bound, and its scaling; after each stage the lower
    bound is raised by the power method from the best scaling, and a matrix stops once its
    bounds are within _TIGHT (then both are μ)."""
    best, best_x = bounds.upper.copy(), bounds.scaling.copy()
    lower, delta = bounds.lower.copy(), bounds.delta.copy()
    x = bounds.scaling.copy()
    for t in _SMOOTHING:
        active = np.flatnonzero(best > lower * (1.0 + _TIGHT))
        for _ in range(_NEWTON_STEPS):
            if active.size == 0:
                break
            Ma, xa = M[active], x[active]
            phi, _, g, direction = _newton_step(Ma, xa, t)
            slope = np.einsum("ki,ki->k", g, direction)
            step = np.ones(active.size)
            moved = np.zeros(active.size, dtype=bool)
            reached = phi.copy()
            pending = np.flatnonzero(slope < -1e-15)
            for _ in range(40):
                if pending.size == 0:
                    break
                trial = xa[pending] + step[pending, None] * direction[pending]
                trial = np.clip(
                    trial - trial.mean(axis=1, keepdims=True),
                    -_LOG_SCALING_RANGE,
                    _LOG_SCALING_RANGE,
                )
                value, top = _smoothed_value(Ma[pending], trial, t)
                ok = value <= phi[pending] + 1e-4 * step[pending] * slope[pending]
                accepted = pending[ok]
                moved[accepted] = True
                reached[accepted] = value[ok]
                xa[accepted] = trial[ok]
                where = active[accepted]
                better = top[ok] < best[where]
                best[where[better]] = top[ok][better]
                best_x[where[better]] = trial[ok][better]
                step[pending[~ok]] *= 0.5
                pending = pending[~ok]
            x[active] = xa
            finished = (
                ~moved
                | (-slope < 1e-14)
                | (phi - reached < _STALLED)
                | (best[active] <= lower[active] * (1 + _TIGHT))
            )
            active = active[~finished]
        still = np.flatnonzero(best > lower * (1.0 + _TIGHT))
        if still.size:
            found, perturbation = _power_from_scaling(M[still], best_x[still])
            better = found > lower[still]
            lower[still[better]] = found[better]
            delta[still[better]] = perturbation[better]
    return _MuBounds(best, lower, delta, best_x)


def _unit(v: ComplexArray) -> ComplexArray:
    norms = np.linalg.norm(v, axis=1, keepdims=True)
    return np.asarray(v / np.where(norms > 0.0, norms, 1.0), dtype=np.complex128)


def _phase(v: ComplexArray) -> ComplexArray:
    return np.asarray(np.exp(1j * np.angle(v)), dtype=np.complex128)


def _power_bound(
    M: ComplexArray, a: ComplexArray, b: ComplexArray, z: ComplexArray, w: ComplexArray
) -> tuple[FloatArray, ComplexArray]:
    """A lower bound of μ from the power method for complex scalar blocks (after Packard,
    Fan and Doyle 1988): alternately a ∝ M b, z_i = |w_i| e^{j∠a_i}, w ∝ M^H z,
    b_i = |a_i| e^{j∠w_i}; at a fixed point M U a = β a with the diagonal unitary
    U = diag(e^{j(∠w_i - ∠a_i)}). Whatever the iteration reached, the eigenvalue λ of M U of
    largest modulus gives μ >= |λ| with Δ = U/λ (det(I - M Δ) = 0, max|δ_i| = 1/|λ|).
    Returns |λ| and the diagonal of Δ."""
    Mh = np.conj(np.swapaxes(M, 1, 2))
    for _ in range(_POWER_STEPS):
        previous = b
        a = _unit((M @ b[:, :, None])[:, :, 0])
        z = np.abs(w) * _phase(a)
        w = _unit((Mh @ z[:, :, None])[:, :, 0])
        b = np.abs(a) * _phase(w)
        if np.max(np.abs(b - previous), initial=0.0) <= 1e-14:
            break
    U = _phase(w) / _phase(a)
    eigenvalues = np.linalg.eigvals(M * U[:, None, :])
    largest = eigenvalues[np.arange(M.shape[0]), np.argmax(np.abs(eigenvalues), axis=1)]
    safe = np.where(largest == 0.0, 1.0, largest)
    delta = np.where(largest[:, None] == 0.0, 0.0, U / safe[:, None])
    return np.abs(largest), np.asarray(delta, dtype=np.complex128)


def _power_from_scaling(M: ComplexArray, x: FloatArray) -> tuple[FloatArray, ComplexArray]:
    """:func:`_power_bound` started from the top singular vectors of D M D^-1 (D = diag(e^x)):
    with D M D^-1 v = σ̄ u, the vectors b = D^-1 v, a = D^-1 u, z = D u, w = D v satisfy
    M b = σ̄ a and M^H z = σ̄ w, a fixed point wherever |u_i| = |v_i| (where the D-scaling is
    optimal and σ̄ simple, so that the bounds meet)."""
    U, _, Vh = np.linalg.svd(_scaled(M, x))
    u = np.asarray(U[:, :, 0], dtype=np.complex128)
    v = np.asarray(np.conj(Vh[:, 0, :]), dtype=np.complex128)
    d = np.exp(x)
    return _power_bound(M, u / d, v / d, u * d, v * d)


def _mu_bounds(M: ComplexArray, floor: float = 0.0, start: FloatArray | None = None) -> _MuBounds:
    """Upper and lower bounds of μ_Δ(M) for Δ = diag(δ_1, ..., δ_p), δ_i complex, for each
    matrix of the stack M (k, p, p) (one per frequency), sharp where they may set the peak.

    Upper bound: min over positive diagonal D of σ̄(D M D^-1) (equal to μ for p <= 3: Packard
    and Doyle 1993, 2S + F <= 3), from Osborne's balancing (or the scaling ``start``, log d,
    where it does better: that of a nearby frequency), then by :func:`_descend` where that
    bound exceeds the lower bound. Lower bound: the power method (:func:`_power_bound`) from
    the scaling's singular vectors, and from _POWER_RESTARTS seeded random starts where a
    gap remains. The _SCREEN_FIRST matrices of largest starting bound are optimised first;
    then those whose starting bound is at most the largest lower bound, or ``floor`` (an
    upper bound of the peak found already), keep it: they cannot set the peak. Each matrix
    is scaled by its largest entry first (μ is homogeneous)."""
    size = np.max(np.abs(M), axis=(1, 2), initial=0.0)
    scale = np.where(size == 0.0, 1.0, size)
    N = M / scale[:, None, None]
    x = _osborne(N)
    upper = np.asarray(np.linalg.svd(_scaled(N, x), compute_uv=False)[:, 0], dtype=np.float64)
    if start is not None:
        given = np.broadcast_to(start, x.shape)
        warm = np.linalg.svd(_scaled(N, given), compute_uv=False)[:, 0]
        better = warm < upper
        x[better], upper[better] = given[better], warm[better]
    lower, delta = _power_from_scaling(N, x)
    bounds = _MuBounds(upper, lower, delta, x)
    candidates = np.flatnonzero(upper > lower * (1.0 + _TIGHT))
    candidates = candidates[np.argsort(-(upper * size)[candidates], kind="stable")]
    for chosen in (candidates[:_SCREEN_FIRST], candidates[_SCREEN_FIRST:]):
        ceiling = max(floor, float(np.max(bounds.lower * size, initial=0.0)))
        chosen = chosen[bounds.upper[chosen] * size[chosen] > ceiling]
        if chosen.size:
            found = _sharpened(N[chosen], _subset(bounds, chosen))
            bounds.upper[chosen], bounds.lower[chosen] = found.upper, found.lower
            bounds.delta[chosen], bounds.scaling[chosen] = found.delta, found.scaling
    return _MuBounds(
        upper=bounds.upper * size,
        lower=bounds.lower * size,
        delta=np.asarray(bounds.delta / scale[:, None], dtype=np.complex128),
        scaling=bounds.scaling,
    )


def _subset(bounds: _MuBounds, chosen: NDArray[np.intp]) -> _MuBounds:
    return _MuBounds(
        bounds.upper[chosen], bounds.lower[chosen], bounds.delta[chosen], bounds.scaling[chosen]
    )


def _sharpened(M: ComplexArray, bounds: _MuBounds) -> _MuBounds:
    """The bounds of :func:`_descend`, with the lower bound raised by the power method from
    _POWER_RESTARTS seeded random starts."""
    found = _descend(M, bounds)
    lower, delta = found.lower.copy(), found.delta.copy()
    rng = np.random.default_rng(0)
    k, p, _ = M.shape
    for _ in range(_POWER_RESTARTS):
        b, w = rng.standard_normal((2, k, p)) + 1j * rng.standard_normal((2, k, p))
        value, perturbation = _power_bound(M, b, b, w, w)
        better = value > lower
        lower[better] = value[better]
        delta[better] = perturbation[better]
    return _MuBounds(found.upper, lower, delta, found.scaling)


def _square_loop(loop: System) -> StateSpace:
    model = as_state_space(loop, "loop")
    if model.n_inputs != model.n_outputs or model.n_inputs == 0:
        raise ShapeError(
            "loop must be square, with as many outputs as inputs (one per loop break "
            f"point), got {model.n_outputs} outputs and {model.n_inputs} inputs"
        )
    return model


def _broken_loop(model: StateSpace, i: int) -> StateSpace:
    """L_i: from the input of loop i to its output with every other loop closed (u_j = -y_j),
    by :func:`~aerocontrol.feedback` of L with diag(1, ..., 0, ..., 1) in its return path."""
    p = model.n_inputs
    if p == 1:
        return model
    others = np.eye(p)
    others[i, i] = 0.0
    try:
        closed = feedback(model, gain(others, dt=model.dt))
    except SingularMatrixError as error:
        raise SingularMatrixError(
            f"disk_margins: loop {model.input_names[i]!r} cannot be broken alone: closing the "
            f"other loops is an algebraic loop ({error})"
        ) from None
    return closed[i, i]


class _Sensitivity:
    """M(ω) = S(jω) + (σ - 1)/2 I of the closed loop S = (I + L)^-1, formed in state space
    (:func:`~aerocontrol.feedback` of I with L in the return path)."""

    def __init__(self, model: StateSpace, skew: float) -> None:
        p = model.n_inputs
        unity = gain(np.eye(p), dt=model.dt)
        dt = _time_base([unity, model], ["1", "loop"], "disk_margins")
        self.model = _closed(unity, model, -1.0, dt, "disk_margins", "loop")
        self.dt = period(model) if model.is_discrete else None
        self.shift = 0.5 * (skew - 1.0) * np.eye(p)

    def at(self, omega: FloatArray) -> ComplexArray:
        """M at each frequency; ∞ gives the feedthrough's (I + D)^-1 + (σ - 1)/2 I."""
        m = self.model
        finite = np.isfinite(omega)
        values = np.empty((omega.size, *self.shift.shape), dtype=np.complex128)
        values[~finite] = m.D + self.shift
        if np.any(finite):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NumericalOverflowWarning)
                response = _core.frequency_response(m.A, m.B, m.C, m.D, omega[finite], self.dt)
            values[finite] = response + self.shift
        bad = ~np.all(np.isfinite(values), axis=(1, 2))
        if np.any(bad):
            raise InvalidArgumentError(
                "loop: its sensitivity (I + L)^-1 overflows double precision at "
                f"{omega[bad][0]:.6g} rad/s, so its disk margins cannot be computed"
            )
        return values


@dataclass
class _Evaluated:
    """The frequencies at which μ was bounded, with the bounds (filled as the search goes)."""

    omega: list[FloatArray] = field(default_factory=list)
    upper: list[FloatArray] = field(default_factory=list)
    lower: list[FloatArray] = field(default_factory=list)
    delta: list[ComplexArray] = field(default_factory=list)
    best: tuple[float, FloatArray] = (-math.inf, np.zeros(0))
    """The largest upper bound so far and the scaling (log d) at it."""

    def add(self, omega: FloatArray, bounds: _MuBounds) -> None:
        self.omega.append(omega)
        self.upper.append(bounds.upper)
        self.lower.append(bounds.lower)
        self.delta.append(bounds.delta)
        i = int(np.argmax(bounds.upper))
        if bounds.upper[i] > self.best[0]:
            self.best = (float(bounds.upper[i]), bounds.scaling[i])

    def arrays(self) -> tuple[FloatArray, FloatArray, FloatArray, ComplexArray]:
        """The frequencies in increasing order; at one evaluated twice (a zoom's end is a
        grid point), the least upper and the greatest lower bound."""
        omega = np.concatenate(self.omega)
        order = np.argsort(omega, kind="stable")
        omega = omega[order]
        upper = np.concatenate(self.upper)[order]
        lower = np.concatenate(self.lower)[order]
        delta = np.concatenate(self.delta)[order]
        starts = np.flatnonzero(np.concatenate([[True], omega[1:] != omega[:-1]]))
        best = np.array(
            [
                start + int(np.argmax(group))
                for start, group in zip(starts, np.split(lower, starts[1:]), strict=True)
            ]
        )
        return (
            omega[starts],
            np.minimum.reduceat(upper, starts),
            lower[best],
            delta[best],
        )


def _frequencies(omega: ArrayLike, model: StateSpace) -> FloatArray:
    values = real_array(omega, "omega")
    if values.ndim == 0:
        values = values.reshape(1)
    if values.ndim != 1 or values.size == 0:
        raise ShapeError(
            f"omega must be a non-empty 1-D array of frequencies, got shape {values.shape}"
        )
    check_finite(values, "omega")
    if np.any(values < 0.0):
        raise InvalidArgumentError(
            f"omega must be non-negative (rad/s), but omega[{int(np.argmax(values < 0.0))}] "
            f"is {float(values[values < 0.0][0]):g}"
        )
    if model.is_discrete:
        nyquist = math.pi / period(model)
        beyond = values > nyquist * (1.0 + 4.0 * _EPS)
        if np.any(beyond):
            raise InvalidArgumentError(
                f"omega[{int(np.argmax(beyond))}] = {float(values[beyond][0]):g} rad/s is beyond "
                f"the discrete loop's Nyquist frequency π/dt = {nyquist:g} rad/s"
            )
    return np.array(values, dtype=np.float64)  # the result's own copy


def _default_frequencies(model: StateSpace, closed: ComplexArray) -> FloatArray:
    """0, the grid of :func:`_clustered_grid` over two decades beyond the open- and
    closed-loop poles (where S varies), and ∞ for a continuous loop."""
    dt = period(model) if model.is_discrete else 0.0
    # A discrete loop's grid in radians per sample (θ = ω dt), as :func:`_grid`'s.
    s = _continuous(np.concatenate([_eigenvalues(model.A), closed]), 1.0 if dt else 0.0)
    sizes = _magnitude(s[np.isfinite(s)])
    scale = float(sizes.max(initial=0.0))
    nonzero = sizes[sizes > 1e-12 * max(scale, 1.0)]
    low, high = (
        (float(nonzero.min()) / 100.0, float(nonzero.max()) * 100.0)
        if nonzero.size
        else (1e-2, 1e2)
    )
    grid = _clustered_grid(s, low, high, 1.0) / dt if dt else _clustered_grid(s, low, high, 0.0)
    ends = [np.zeros(1), grid] + ([] if dt else [np.full(1, math.inf)])
    return np.asarray(np.concatenate(ends), dtype=np.float64)


def _refined_peak(
    omega: FloatArray, values: FloatArray, f: Callable[[FloatArray], FloatArray]
) -> tuple[float, float]:
    """(ω, f(ω)) at the largest of ``values`` on ``omega`` (which may end with ∞), refined by
    :func:`_extremum` on the finite frequencies, 16 intervals at a time (each point may be a
    D-scaling search)."""
    finite = np.isfinite(omega)
    w, value = _extremum(omega[finite], values[finite], f, intervals=16)
    if not finite.all() and float(values[~finite].max()) > value:
        return math.inf, float(values[~finite].max())
    return w, value


def _certify(
    model: StateSpace,
    sensitivity: _Sensitivity,
    frequency: float,
    delta: ComplexArray,
    skew: float,
) -> ComplexArray:
    """The gains f_i = (1 + (1 - σ)δ_i/2)/(1 - (1 + σ)δ_i/2) of the destabilising Δ, checked:
    with L = L(jω) from the loop itself (not from the sensitivity the bound came from),
    (I + L + (aL - bI)Δ) = (I + L F)(I - bΔ), a = (1 - σ)/2, b = (1 + σ)/2, must be singular
    to CERTIFICATE_TOLERANCE of the size of its terms, else AerocontrolLinAlgError. Where L
    has a pole at ω (not finite), the equivalent I - M Δ (M = S - aI, finite) is checked."""
    a, b = 0.5 * (1.0 - skew), 0.5 * (1.0 + skew)
    p = model.n_inputs
    if math.isfinite(frequency):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NumericalOverflowWarning)
            L = _core.frequency_response(
                model.A,
                model.B,
                model.C,
                model.D,
                np.array([frequency]),
                period(model) if model.is_discrete else None,
            )[0]
    else:
        L = model.D.astype(np.complex128)
    identity = np.eye(p)
    Delta = np.diag(delta)
    largest = float(np.max(np.abs(delta), initial=0.0))
    if np.all(np.isfinite(L)):
        pencil = identity + L + (a * L - b * identity) @ Delta
        size = (
            float(np.linalg.norm(identity + L, 2))
            + float(np.linalg.norm(a * L - b * identity, 2)) * largest
        )
    else:  # a pole of L at ω (an integrator at 0): I - M Δ, from the finite M = S - aI
        M = sensitivity.at(np.array([frequency]))[0]
        pencil = identity - M @ Delta
        size = 1.0 + float(np.linalg.norm(M, 2)) * largest
    smallest = float(np.linalg.svd(pencil, compute_uv=False)[-1])
    if not smallest <= CERTIFICATE_TOLERANCE * size:
        raise AerocontrolLinAlgError(
            f"disk_margins: the destabilising perturbation found at {frequency:.6g} rad/s "
            f"leaves I + L F nonsingular (smallest singular value {smallest:.3g}, "
            f"{smallest / size:.3g} of its terms): the bounds of the multiloop margin failed "
            "their check"
        )
    denominator = 1.0 - b * delta
    infinite = denominator == 0.0  # f_i = ∞: the disk's boundary through infinity
    gains = (1.0 + a * delta) / np.where(infinite, 1.0, denominator)
    return np.asarray(np.where(infinite, complex(math.inf, 0.0), gains), dtype=np.complex128)


def disk_margins(loop: System, omega: ArrayLike | None = None, skew: float = 0.0) -> DiskMargins:
    """Disk margins of a square MIMO loop L (p x p, negative feedback u = -y, closed loop
    I + L): loop-at-a-time, and multiloop for simultaneous independent changes in every loop.

    A change f_i in loop i is a gain and phase factor in the disk D(α, σ) of
    :class:`DiskMargin` (Seiler, Packard and Gahinet 2020); with F = diag(f_i),
    f_i = (1 + aδ_i)/(1 - bδ_i), a = (1 - σ)/2, b = (1 + σ)/2,

        I + L F = (I + L)(I - M Δ)(I - bΔ)^-1,   M = S - aI = S + (σ - 1)/2 I,

    with S = (I + L)^-1 and Δ = diag(δ_i), so the perturbed loop stays stable for every F
    with each f_i in D(α, σ) iff α < 1/sup_ω μ_Δ(M), μ the structured singular value for
    diagonal complex Δ (the multiloop margin of Blight, Dailey and Gangsaas 1994; Seiler,
    Packard and Gahinet).

    * Loop at a time: loop i broken with the others closed, L_i from the input of loop i to
      its output (state space, by :func:`~aerocontrol.feedback`), whose sensitivity is
      S_ii. Its margin is 1/sup_ω abs(S_ii + (σ - 1)/2): for σ = 0, on the default grid, the
      disk margin of :func:`stability_margins` (L∞ norm by the Hamiltonian iteration); for
      σ ≠ 0, the peak on the grid refined by zooming. Each loop's classical margins are
      returned too (``DiskMargins.loops``).
    * Multiloop: μ has no closed form for p >= 2; at each frequency an upper bound,
      min over positive diagonal D of σ̄(D M D^-1) (Osborne's scaling, then damped Newton
      steps on a smoothed σ̄, a convex problem in log D), and a lower bound from the power
      method (abs(λ) of M U, U diagonal unitary) are computed. The upper bound is μ itself for
      p <= 3 (Packard and Doyle 1993). The peak is refined by zooming in frequency. The
      margin returned is the guaranteed one, 1/sup μ_upper; both bounds are reported, and a
      gap beyond MU_GAP_TOLERANCE warns (LooseBoundWarning). For p = 1 the multiloop
      margin is the loop's disk margin.

    The loop's states are first balanced by a diagonal similarity of powers of two (exact,
    the same L; ``balanced_states``), so that states scaled by 10^±6 give the margins
    of the well-scaled loop. The results are checked: the destabilising perturbation of the
    lower bound must make I + L(jω) F singular (I - M Δ where L has a pole at ω;
    AerocontrolLinAlgError otherwise), and the lower bound may not exceed the upper. A
    closed loop that is not stable (from the eigenvalues of A - B (I + D)^-1 C, one within
    √u of the balanced matrix's size of the boundary, such as a mode at the origin that the
    loop cancels, counting as not stable) has every disk margin 0.

    Parameters
    ----------
    loop : StateSpace or (A, B, C, D)
        The loop transfer L, square (continuous or discrete).
    omega : array_like, optional
        Frequencies (rad/s, non-negative, up to π/dt for a discrete loop) to which the
        analysis is restricted, as python-control's ``disk_margins``: the margins are those
        of the peaks on this grid, unrefined. Default: a grid over the open- and
        closed-loop poles with 0 and ∞, refined near each peak.
    skew : float
        σ of the disk D(α, σ) (default 0, balanced; 1 for the sensitivity S, -1 for the
        complementary sensitivity T).

    Returns
    -------
    DiskMargins

    Raises
    ------
    ShapeError
        The loop is not square, or ``omega`` not a 1-D array.
    NonFiniteError
        ``skew`` or ``omega`` is not finite (the loop's matrices are checked by StateSpace).
    SingularMatrixError
        I + D is singular (an algebraic loop), or closing all but one loop is.
    AerocontrolLinAlgError
        The destabilising perturbation fails its check.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # The spinning satellite with K = I (Seiler, Packard and Gahinet): each loop broken
    >>> # alone is 1/s (α = 2: any gain, ±90°), but S - I/2 = [[s - 1, -2a], [2a, s - 1]]
    >>> # / (2(s + 1)) is normal, so μ = σ̄ and α = 2 √((1 + ω²)/(1 + (ω + 2a)²)) at
    >>> # ω = √(a² + 1) - a (closed forms).
    >>> a = 10.0
    >>> L = aerocontrol.StateSpace([[0, a], [-a, 0]], np.eye(2), [[1, a], [-a, 1]])
    >>> m = aerocontrol.disk_margins(L)
    >>> [round(d.alpha, 12) for d in m.loop_at_a_time]
    [2.0, 2.0]
    >>> round(m.multiloop.alpha, 6), round(m.multiloop.frequency, 4)
    (0.099751, 0.0499)
    >>> np.round(m.multiloop.gain_margin_db, 3), round(m.multiloop.phase_margin, 3)
    (array([-0.867,  0.867]), 5.711)
    """
    model = balanced_states(_square_loop(loop))
    sigma = real_scalar(skew, "skew")
    check_finite(np.array([sigma]), "skew")
    grid = None if omega is None else _frequencies(omega, model)
    p = model.n_inputs
    sensitivity = _Sensitivity(model, sigma)
    A_closed = sensitivity.model.A
    closed = _backward_stable_eigenvalues(A_closed, _eigenvalues(A_closed))
    stable = _closed_loop_stable(
        closed, model.is_discrete, _balanced_size(A_closed), lambda: A_closed
    )
    loops = tuple(stability_margins(_broken_loop(model, i)) for i in range(p))
    names = model.input_names
    if not stable:
        nothing = DiskMargin(0.0, sigma, math.nan)
        empty = np.zeros(0)
        return DiskMargins(
            skew=sigma,
            names=names,
            loop_at_a_time=(nothing,) * p,
            multiloop=nothing,
            multiloop_bounds=(0.0, 0.0),
            worst_perturbation=np.ones(p, dtype=np.complex128),
            worst_frequency=math.nan,
            frequencies=empty,
            mu_upper=empty,
            mu_lower=empty.copy(),
            loops=loops,
            closed_loop_poles=np.sort_complex(closed),
            closed_loop_stable=False,
        )

    refine = grid is None
    frequencies = _default_frequencies(model, closed) if grid is None else grid
    values = sensitivity.at(frequencies)

    # Loop at a time: the peaks of |M_ii|.
    singles: list[DiskMargin] = []
    for i in range(p):
        if refine and sigma == 0.0:
            singles.append(DiskMargin(loops[i].disk_margin, sigma, loops[i].disk_frequency))
            continue
        diagonal = _magnitude(values[:, i, i])
        if refine:

            def entry(w: FloatArray, i: int = i) -> FloatArray:
                return _magnitude(sensitivity.at(w)[:, i, i])

            w_i, peak = _refined_peak(frequencies, diagonal, entry)
        else:
            j = int(np.argmax(diagonal))
            w_i, peak = float(frequencies[j]), float(diagonal[j])
        singles.append(DiskMargin(1.0 / peak if peak > 0.0 else math.inf, sigma, w_i))

    # The loop-at-a-time peaks are suprema: no grid value of |M_ii| may exceed them.
    for i, single in enumerate(singles):
        grid_peak = float(np.max(_magnitude(values[:, i, i])))
        if single.alpha > 0.0 and grid_peak * single.alpha > 1.0 + 1e-6:
            raise AerocontrolLinAlgError(
                f"disk_margins: loop {names[i]!r}: |S_ii + (σ - 1)/2| reaches {grid_peak:.9g} on "
                f"the frequency grid, above the peak {1.0 / single.alpha:.9g} found for it: the "
                "loop-at-a-time margin failed its check"
            )

    # Multiloop: bounds of μ on the grid (and at the loop-at-a-time peaks), then refined.
    if refine:
        extra = np.array([d.frequency for d in singles if math.isfinite(d.frequency)])
        frequencies = _separated(np.concatenate([extra, frequencies]))
        values = sensitivity.at(frequencies)
    evaluated = _Evaluated()
    bounds = _mu_bounds(values)
    evaluated.add(frequencies, bounds)
    if refine:

        def refined_upper(w: FloatArray) -> FloatArray:
            peak, scaling = evaluated.best
            found = _mu_bounds(sensitivity.at(w), floor=peak, start=scaling)
            evaluated.add(w, found)
            return found.upper

        _refined_peak(frequencies, bounds.upper, refined_upper)
    frequencies, mu_upper, mu_lower, deltas = evaluated.arrays()
    top, worst = int(np.argmax(mu_upper)), int(np.argmax(mu_lower))
    peak, found = float(mu_upper[top]), float(mu_lower[worst])
    if found > peak * (1.0 + 1e-8):
        raise AerocontrolLinAlgError(
            f"disk_margins: the lower bound of μ ({found:.9g}) exceeds the upper bound "
            f"({peak:.9g}): the bounds failed their check"
        )
    # Where both bounds are μ (p <= 3), the lower one may exceed the upper by rounding.
    mu_lower = np.minimum(mu_lower, mu_upper)
    found = min(found, peak)
    if p == 1:  # μ = |M|: the loop's own disk margin
        multiloop = singles[0]
        alpha_bounds = (multiloop.alpha, multiloop.alpha)
        worst_frequency = multiloop.frequency
        if math.isnan(worst_frequency):
            worst_frequency = float(frequencies[top])
        at_worst = sensitivity.at(np.array([worst_frequency]))[0]
        delta = np.where(
            at_worst[0] == 0.0, 0.0, 1.0 / np.where(at_worst[0] == 0.0, 1.0, at_worst[0])
        )
    else:
        multiloop = DiskMargin(
            1.0 / peak if peak > 0.0 else math.inf, sigma, float(frequencies[top])
        )
        alpha_bounds = (multiloop.alpha, 1.0 / found if found > 0.0 else math.inf)
        worst_frequency, delta = float(frequencies[worst]), deltas[worst]
        if (peak - found) > MU_GAP_TOLERANCE * peak:
            warnings.warn(
                f"disk_margins: the multiloop margin is known only within [{alpha_bounds[0]:.4g}, "
                f"{alpha_bounds[1]:.4g}] (bounds of the peak of μ {found:.4g} and {peak:.4g}, a "
                f"gap of {(peak - found) / peak:.1%}); the lower end is returned",
                LooseBoundWarning,
                stacklevel=2,
            )
    if np.any(delta != 0.0):
        perturbation = _certify(model, sensitivity, worst_frequency, delta, sigma)
    else:  # μ = 0: no perturbation of any size destabilises the loop
        perturbation, worst_frequency = np.full(p, complex(math.nan, math.nan)), math.nan
    return DiskMargins(
        skew=sigma,
        names=names,
        loop_at_a_time=tuple(singles),
        multiloop=multiloop,
        multiloop_bounds=alpha_bounds,
        worst_perturbation=perturbation,
        worst_frequency=worst_frequency,
        frequencies=frequencies,
        mu_upper=mu_upper,
        mu_lower=mu_lower,
        loops=loops,
        closed_loop_poles=np.sort_complex(closed),
        closed_loop_stable=True,
    )


# ----- root locus ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class RootLocus(Result):
    """The closed-loop poles of 1 + k L(s) = 0 over the gains k.

    Attributes
    ----------
    gains : ndarray (k,)
        The gains k.
    poles : ndarray (k, n), complex
        The eigenvalues of A - k B (1 + k D)⁻¹ C for each gain, each row sorted.
    dt : float
        The sampling period (s), 0 for a continuous loop.
    loop : StateSpace
        The open loop L.
    open_loop_poles : ndarray, complex
        The poles of L's transfer function (computed on first use).
    open_loop_zeros : ndarray, complex
        The zeros of L's transfer function (computed on first use).

    Examples
    --------
    k/(s(s + 2)) closes to s² + 2s + k: poles 0 and -2 at k = 0, a double pole at -1 at
    k = 1, -1 ± 2j at k = 5:

    >>> import numpy as np, aerocontrol
    >>> locus = aerocontrol.root_locus(aerocontrol.zpk([], [0.0, -2.0], 1.0), [0.0, 1.0, 5.0])
    >>> np.round(locus.poles, 6)
    array([[-2.+0.j,  0.+0.j],
           [-1.+0.j, -1.+0.j],
           [-1.-2.j, -1.+2.j]])
    >>> locus.open_loop_zeros.size
    0
    """

    gains: FloatArray
    poles: ComplexArray
    """Shape (len(gains), n): the eigenvalues of A - k B (1 + k D)⁻¹ C, each row sorted."""
    dt: float
    loop: StateSpace = field(repr=False)
    """The open loop L."""

    @cached_property
    def _transfer(self) -> TransferFunction:
        return _roots_of(self.loop)

    @property
    def open_loop_poles(self) -> ComplexArray:
        """The poles of L's transfer function (computed on first use: the locus itself needs
        only the closed-loop eigenvalues)."""
        return self._transfer.poles

    @property
    def open_loop_zeros(self) -> ComplexArray:
        """The zeros of L's transfer function (computed on first use)."""
        return self._transfer.zeros

    def plot(self, ax: Axes | None = None, marked: list[float] | None = None) -> Axes:
        """The locus with a ζ/ω_n grid (matplotlib); see
        :func:`~aerocontrol.plotting.plot_gain_root_locus`."""
        from .plotting import plot_gain_root_locus

        return plot_gain_root_locus(self, ax=ax, marked=marked)


def _gains(gains: ArrayLike, name: str = "gains") -> FloatArray:
    values = real_array(gains, name)
    if values.ndim == 0:
        values = values.reshape(1)
    if values.ndim != 1 or values.size == 0:
        raise ShapeError(f"{name} must be a non-empty 1-D array of gains, got shape {values.shape}")
    check_finite(values, name)
    return np.array(values, dtype=np.float64)  # the result's own copy


def _closed_poles(model: StateSpace, k: float) -> ComplexArray:
    """The closed-loop poles at one gain of a damping search; a gain of the search (one the
    caller listed in ``gains``) that closes an algebraic loop, 1 + k D = 0, is refused by
    name (the loop has no solution there, so no poles)."""
    _refuse_algebraic(model, k)
    poles: ComplexArray = _closed_loop_poles(model, np.array([k]))[0]
    return poles


def root_locus(loop: System, gains: ArrayLike) -> RootLocus:
    """The closed-loop poles of 1 + k L(s) = 0 for each gain k of ``gains`` (negative
    feedback for k > 0), as the eigenvalues of A - k B (1 + k D)⁻¹ C.

    Parameters
    ----------
    loop : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The open loop L, one input and one output (continuous or discrete).
    gains : array_like (k,)
        The gains, a non-empty 1-D array (negative gains: positive feedback).

    Returns
    -------
    RootLocus
        ``gains`` and ``poles`` of shape (k, n), each row the sorted closed-loop
        eigenvalues, with the loop, its ``dt`` and ``plot()``.

    Raises
    ------
    ShapeError
        ``loop`` has not one input and one output (select the channel with
        ``loop[output, input]``).
    NotRealError
        ``loop`` is not a model.
        Also ``gains`` not a non-empty 1-D array.
    NonFiniteError
        A gain is NaN or infinite.
    SingularMatrixError
        1 + k D = 0 at a gain of ``gains``: an algebraic loop (named).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # k/(s(s + 2)): poles -1 ± j√(k - 1) beyond k = 1.
    >>> locus = aerocontrol.root_locus(aerocontrol.zpk([], [0.0, -2.0], 1.0), [0.0, 1.0, 5.0])
    >>> np.round(locus.poles[2], 12)
    array([-1.-2.j, -1.+2.j])
    """
    model = _siso(loop)
    k = _gains(gains)
    d = float(model.D[0, 0])
    if d != 0.0:
        with np.errstate(over="ignore", invalid="ignore"):
            products = k * d
            algebraic = np.isfinite(products) & (
                np.abs(1.0 + products) <= 8 * _EPS * np.maximum(1.0, np.abs(products))
            )
        if np.any(algebraic):
            _refuse_algebraic(model, float(k[np.argmax(algebraic)]))  # raises, naming the gain
    return RootLocus(
        gains=k,
        poles=_closed_loop_poles(model, k),
        dt=period(model) if model.is_discrete else 0.0,
        loop=model,
    )


@dataclass(frozen=True, eq=False)
class DampingDesign(Result):
    """A gain of a root-locus design and the mode it sets.

    Attributes
    ----------
    gain : float
        The loop gain k of the design (the loop is closed as 1 + k L(s) = 0).
    damping_ratio : float
        ζ of the mode (of s = ln(z)/dt for a discrete loop); 1 when no pole oscillates.
    pole : complex
        The mode's closed-loop pole (Im ≥ 0; rad/s, or z for a discrete loop); NaN when no pole
        oscillates.
    closed_loop_poles : ndarray (n,), complex
        Every closed-loop pole at ``gain``.

    Examples
    --------
    k/(s(s + 2)) closes to s² + 2s + k: ζ = 1/√k, so ζ = 0.5 at k = 4, with the poles -1 ± j√3:

    >>> import numpy as np, aerocontrol
    >>> design = aerocontrol.gain_for_damping(aerocontrol.zpk([], [0.0, -2.0], 1.0), 0.5)
    >>> round(design.gain, 10), round(design.damping_ratio, 10)
    (4.0, 0.5)
    >>> complex(np.round(design.pole, 6))
    (-1+1.732051j)
    """

    gain: float
    damping_ratio: float
    """ζ of the mode (of s = ln(z)/dt for a discrete loop); 1 when no pole oscillates."""
    pole: complex
    """The mode's pole (Im ≥ 0); NaN when no pole oscillates."""
    closed_loop_poles: ComplexArray


def _continuous(poles: ComplexArray, dt: float) -> ComplexArray:
    if not dt:
        return poles
    s = np.full(poles.shape, complex(-np.inf, 0.0), dtype=np.complex128)
    nonzero = poles != 0
    s[nonzero] = np.log(poles[nonzero]) / dt
    return s


def _least_damped(poles: ComplexArray, dt: float) -> tuple[float, complex]:
    s = _continuous(poles, dt)
    oscillatory = np.isfinite(s) & (s.imag > 1e-9 * _magnitude(s))
    if not np.any(oscillatory):
        return 1.0, complex(math.nan, math.nan)
    candidates = s[oscillatory]
    # ζ = -Re/|s| of the candidates scaled to parts at most 1 (|s| may exceed the doubles).
    size = np.maximum(np.abs(candidates.real), np.abs(candidates.imag))
    zetas = -(candidates.real / size) / np.abs(candidates / size)
    i = int(np.argmin(zetas))
    return float(zetas[i]), complex(poles[oscillatory][i])


def _damping(pole: complex, dt: float) -> float:
    s = complex(np.log(pole)) / dt if dt else pole
    # |s| by a hypot of the parts scaled to at most 1 (Python's abs of a complex beyond the
    # doubles raises OverflowError): ζ is a ratio, so the scale cancels.
    size = max(abs(s.real), abs(s.imag))
    if not (math.isfinite(size) and size > 0.0):
        return 1.0
    re, im = s.real / size, s.imag / size
    modulus = math.hypot(re, im)
    return -re / modulus if abs(im) > 1e-9 * modulus else 1.0


class _Objective:
    """ζ(k) of the least-damped oscillatory mode, or of the mode tracked from ``mode``."""

    def __init__(self, model: StateSpace, mode: complex | None, gains: FloatArray) -> None:
        self.model = model
        self.dt = period(model) if model.is_discrete else 0.0
        self.gains = gains
        self.track: list[complex] = []
        if mode is not None:
            if model.n_states == 0:
                raise InvalidArgumentError(
                    "mode: the loop has no states, so no closed-loop mode to track"
                )
            current = complex(mode)
            for k in gains:
                poles = _closed_poles(model, float(k))
                current = complex(poles[_nearest(poles, current)])
                current = complex(current.real, abs(current.imag))
                self.track.append(current)

    def pole(self, k: float) -> tuple[float, complex, ComplexArray]:
        poles = _closed_poles(self.model, k)
        if not self.track:
            zeta, pole = _least_damped(poles, self.dt)
            return zeta, pole, poles
        nearest = self.track[int(np.argmin(np.abs(self.gains - k)))]
        pole = complex(poles[_nearest(poles, nearest)])
        pole = complex(pole.real, abs(pole.imag))
        return _damping(pole, self.dt), pole, poles

    def __call__(self, k: float) -> float:
        zeta, _, poles = self.pole(k)
        if np.any(_unstable(poles, bool(self.dt))):
            return -1.0  # a gain that leaves the closed loop unstable is never the best
        return zeta

    def damping(self, k: float) -> float:
        """ζ(k) itself, whether or not another pole is unstable (for gain_for_damping)."""
        return self.pole(k)[0]


#: Decades of the default gain grid on each side of 1/|L| at the loop's modes.
GAIN_DECADES = 3.0


def _default_gains(model: StateSpace) -> FloatArray:
    """0, then 400 gains log-spaced over six decades about 1/|L| at the loop's modes.

    The grid is formed in log2: 1/|L| itself overflows for an |L| below 2^-1024 (a subnormal
    D of 5e-324 gave an infinite grid and a NaN gain), and the grid's ends over- or underflow
    within three decades of the range. A grid that is not within the normal doubles
    [2^-1022, 2^1024) is refused naming the loop (its gains, and the gain sought, are not
    representable, or only to a few digits), with the advice to give the gains."""
    poles = _continuous(_eigenvalues(model.A), period(model) if model.is_discrete else 0.0)
    with np.errstate(over="ignore"):
        sizes = _magnitude(poles[np.isfinite(poles)])
    sizes = sizes[np.isfinite(sizes) & (sizes > 0)]
    omega = sizes if sizes.size else np.array([1.0])
    magnitude = _magnitude(_Response(model).many(omega))
    magnitude = magnitude[np.isfinite(magnitude) & (magnitude > 0)]
    if not magnitude.size:
        return np.concatenate([[0.0], np.logspace(-GAIN_DECADES, GAIN_DECADES, 400)])
    centre = -math.log2(float(np.median(magnitude)))  # log2 of 1/|L|, finite for |L| > 0
    spread = GAIN_DECADES * math.log2(10.0)
    low, high = centre - spread, centre + spread
    tiny, largest = np.finfo(float).tiny, np.finfo(float).max
    if not (math.log2(tiny) <= low and high < math.log2(largest)):
        raise InvalidArgumentError(
            f"loop: its gain |L| at its modes is about 2^{-centre:.0f} "
            f"({float(np.median(magnitude)):.3g}), so the default gains about 1/|L| "
            f"(2^{low:.0f} to 2^{high:.0f}) are not within the normal doubles "
            f"({tiny:.3g} to {largest:.3g}); give the gains to search"
        )
    reference = 1.0 / float(np.median(magnitude))
    return np.concatenate([[0.0], reference * np.logspace(-GAIN_DECADES, GAIN_DECADES, 400)])


def _mode(mode: complex | None) -> complex | None:
    if mode is None:
        return None
    try:
        value = complex(mode)
    except (TypeError, ValueError):
        raise InvalidArgumentError(
            f"mode must be an open-loop pole (a complex number) or None, got {mode!r}"
        ) from None
    if not (math.isfinite(value.real) and math.isfinite(value.imag)):
        raise InvalidArgumentError(f"mode must be finite, got {value}")
    return value


def _search_gains(model: StateSpace, gains: ArrayLike | None) -> FloatArray:
    if gains is None:
        return _default_gains(model)
    values = np.sort(_gains(gains))
    if values[0] < 0:
        raise InvalidArgumentError(f"gains must be non-negative, got {values[0]:g}")
    return values


def best_damping_gain(
    loop: System, mode: complex | None = None, gains: ArrayLike | None = None
) -> DampingDesign:
    """The gain k ≥ 0 of 1 + k L(s) = 0 that maximises the damping ratio of the least-damped
    oscillatory closed-loop mode or, with ``mode`` (an open-loop pole), of that mode tracked
    by continuity along the locus.

    The damping is computed on a grid of gains (``gains``, or 0 and 400 gains over six
    decades about 1/abs(L) at the loop's modes), then refined by golden-section search between
    the best grid gain's neighbours. A gain at which a closed-loop pole is unstable is never
    chosen (its damping counts as -1).

    Parameters
    ----------
    loop : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The open loop L, one input and one output (continuous or discrete).
    mode : complex, optional
        An open-loop pole whose branch is tracked; default the least-damped oscillatory
        closed-loop mode at each gain.
    gains : array_like (k,), optional
        The non-negative gains searched; default 0 and 400 gains over six decades about
        1/abs(L) at the loop's modes.

    Returns
    -------
    DampingDesign
        The ``gain``, the mode's ``damping_ratio`` (of s = ln(z)/dt for a discrete loop; 1
        when no pole oscillates) and ``pole``, and the ``closed_loop_poles``.

    Raises
    ------
    InvalidArgumentError
        ``mode`` is not a finite complex number, or a gain is negative.
    ShapeError
        ``loop`` has not one input and one output (select the channel with
        ``loop[output, input]``).
    NotRealError
        ``loop`` is not a model.
        Also ``gains`` not a non-empty 1-D array.
    SingularMatrixError
        1 + k D = 0 at a searched gain: an algebraic loop.

    See Also
    --------
    gain_for_damping : the smallest gain that gives a chosen damping ratio.

    Examples
    --------
    A lightly damped pair -0.1 ± j with a lead zero at -2 and a pole at -20,
    20 k (s + 2)/((s² + 0.2 s + 1.01)(s + 20)): the best gain makes every closed-loop pole
    real (ζ counts as 1).

    >>> import numpy as np, aerocontrol
    >>> loop = aerocontrol.zpk([-2.0], [-0.1 + 1j, -0.1 - 1j, -20.0], 20.0)
    >>> best = aerocontrol.best_damping_gain(loop, mode=-0.1 + 1j)
    >>> best.damping_ratio > 0.7
    True
    >>> bool(np.all(best.closed_loop_poles.imag == 0))
    True
    """
    model = _siso(loop)
    tracked = _mode(mode)
    k = _search_gains(model, gains)
    objective = _Objective(model, tracked, k)
    values = np.array([objective(float(g)) for g in k])
    i = int(np.argmax(values))
    best_k, best_zeta = float(k[i]), float(values[i])
    if k.size > 2:
        a, b = float(k[max(i - 1, 0)]), float(k[min(i + 1, k.size - 1)])
        refined_k, refined_zeta = _golden_max(objective, a, b)
        # Only a better damping moves the gain off the grid: where ζ is flat (no pole
        # oscillates, or a static loop) the search drifts towards a = 0, to gains of 1e-46
        # or subnormal ones (3e-313 beside a D of 1e308).
        if refined_zeta > best_zeta:
            best_k, best_zeta = refined_k, refined_zeta
    zeta, pole, poles = objective.pole(best_k)
    return DampingDesign(best_k, zeta, pole, poles)


def gain_for_damping(
    loop: System, zeta: float, mode: complex | None = None, gains: ArrayLike | None = None
) -> DampingDesign:
    """The smallest gain k ≥ 0 of 1 + k L(s) = 0 at which the least-damped oscillatory mode
    (or the mode tracked from the open-loop pole ``mode``) has damping ratio ``zeta``.

    The damping ratio counts as 1 where no pole oscillates. It is that mode's alone: another
    pole may leave the closed loop unstable at the gain found (an unstable real pole, as an
    aircraft's spiral mode, beside the Dutch roll a damper is for; and a negative ``zeta`` is
    itself an unstable mode), so check ``closed_loop_poles``. The first grid interval where the
    damping crosses ``zeta`` (rising, as a damper's, or falling, as a high-gain loop's) is
    refined by Brent's method. A damping that no gain of the grid reaches is refused, naming
    the nearest one.

    Parameters
    ----------
    loop : StateSpace, TransferFunction, (A, B, C, D) tuple, or system object
        The open loop L, one input and one output (continuous or discrete).
    zeta : float
        The damping ratio wanted, in (-1, 1).
    mode : complex, optional
        An open-loop pole whose branch is tracked; default the least-damped oscillatory
        closed-loop mode at each gain.
    gains : array_like (k,), optional
        The non-negative gains searched; default 0 and 400 gains over six decades about
        1/abs(L) at the loop's modes.

    Returns
    -------
    DampingDesign
        The ``gain``, the mode's ``damping_ratio`` (``zeta`` to about 1e-10), its ``pole``
        and the ``closed_loop_poles``.

    Raises
    ------
    InvalidArgumentError
        ``zeta`` outside (-1, 1) or not finite; no gain of the grid reaches ``zeta`` (the
        nearest damping and its gain are named); ``mode`` not a finite complex number; a
        negative gain.
    ShapeError
        ``loop`` has not one input and one output (select the channel with
        ``loop[output, input]``).
    NotRealError
        ``loop`` is not a model.
    SingularMatrixError
        1 + k D = 0 at a searched gain: an algebraic loop.

    Warns
    -----
    IllConditionedWarning
        The damping ratio jumps at the gain found (from one mode to another) and is not
        ``zeta`` there.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # k/(s(s + 2)): ζ = 1/√k beyond k = 1, so ζ = 0.5 at k = 4 (a closed form).
    >>> design = aerocontrol.gain_for_damping(aerocontrol.zpk([], [0.0, -2.0], 1.0), 0.5)
    >>> round(design.gain, 10), round(design.damping_ratio, 10)
    (4.0, 0.5)
    """
    model = _siso(loop)
    target = real_scalar(zeta, "zeta")
    if not (math.isfinite(target) and -1.0 < target < 1.0):
        raise InvalidArgumentError(f"zeta must lie in (-1, 1), got {target}")
    tracked = _mode(mode)
    k = _search_gains(model, gains)
    objective = _Objective(model, tracked, k)
    values = np.array([objective.damping(float(g)) for g in k]) - target
    if values[0] == 0:
        z, pole, poles = objective.pole(float(k[0]))
        return DampingDesign(float(k[0]), z, pole, poles)
    crossed = np.nonzero(np.sign(values[1:]) != np.sign(values[0]))[0]
    if crossed.size == 0:
        best = int(np.argmin(np.abs(values)))
        raise InvalidArgumentError(
            f"zeta = {target:g} is not reached for gains up to {k[-1]:.4g}: the nearest is "
            f"zeta = {values[best] + target:.4g} at k = {k[best]:.4g}"
        )
    j = int(crossed[0]) + 1

    def shifted(g: float) -> float:
        return objective.damping(g) - target

    found = _brent(
        shifted, float(k[j - 1]), float(k[j]), float(values[j - 1]), float(values[j]), 0.0
    )
    z, pole, poles = objective.pole(found)
    if abs(z - target) > 1e-6:
        warnings.warn(
            f"gain_for_damping: the damping ratio jumps at k = {found:.6g} (from one mode to "
            f"another): it is {z:.6g} there, not {target:g}",
            IllConditionedWarning,
            stacklevel=2,
        )
    return DampingDesign(found, z, pole, poles)


# ----- Nyquist and Nichols ------------------------------------------------------------------

BoolArray = NDArray[np.bool_]
IntArray = NDArray[np.int64]

#: The widest turn (radians) of the curve about its centre (-1 for the Nyquist count, 0 for the
#: Nichols phase) between neighbouring points of the contour; a wider step is bisected.
MAX_TURN = math.pi / 8

#: Rounds of bisection of the contour, and the most points it may reach.
REFINE_ROUNDS = 40
MAX_CONTOUR_POINTS = 100_000

#: An indentation's radius as a fraction of the distance from the pole it avoids to the
#: nearest other open- or closed-loop pole (or asked frequency).
INDENT_FRACTION = 1e-2

#: Points on each quarter turn of an indentation, per unit of the pole's multiplicity, before
#: bisection.
ARC_POINTS = 16

#: Retries of a winding number that disagrees with P - Z, each with indentations a hundred
#: times smaller and twice the points, before the count is refused.
COUNT_RETRIES = 2


def _asked_frequencies(omega: ArrayLike | None, dt: float) -> FloatArray | None:
    """The caller's frequencies, checked by name and returned sorted without repeats."""
    if omega is None:
        return None
    values = real_array(omega, "omega")
    if values.ndim == 0:
        values = values.reshape(1)
    if values.ndim != 1 or values.size == 0:
        raise ShapeError(
            f"omega must be a non-empty 1-D array of frequencies (rad/s), got shape {values.shape}"
        )
    check_finite(values, "omega")
    negative = np.flatnonzero(values < 0.0)
    if negative.size:
        i = int(negative[0])
        raise InvalidArgumentError(
            f"omega must be non-negative (the curve for ω < 0 is the mirror image of the curve "
            f"for ω > 0), but omega[{i}] is {values[i]:g}"
        )
    if dt:
        beyond = np.flatnonzero(values > math.pi / dt)
        if beyond.size:
            i = int(beyond[0])
            raise InvalidArgumentError(
                f"omega must not exceed the Nyquist frequency π/dt = {math.pi / dt:.6g} rad/s "
                f"of the discrete loop, but omega[{i}] is {values[i]:.6g}"
            )
    return np.unique(values)


def _boundary_tolerance(size: float, discrete: bool) -> float:
    """How near the stability boundary a computed root may be and still be taken to lie on
    it: √u times the size of its matrix (the error of an eigenvalue of a 2 x 2 Jordan block,
    a double integrator, computed backward stably); at least √u for the unit circle."""
    return math.sqrt(_EPS) * (max(size, 1.0) if discrete else size)


def _on_boundary(roots: ComplexArray, discrete: bool, tolerance: float) -> BoolArray:
    """Which roots lie on the imaginary axis (on the unit circle) to ``tolerance``."""
    with np.errstate(over="ignore", invalid="ignore"):
        distance = np.abs(np.abs(roots) - 1.0) if discrete else np.abs(roots.real)
    return np.asarray(distance <= tolerance, dtype=np.bool_)


def _balanced_size(M: FloatArray) -> float:
    """:func:`_matrix_size` of M balanced (:func:`balanced_matrix`): the size of the matrix
    whose eigenvalues are computed, not of coordinates scaled by 10^±6 (whose size, 1e12 for a
    well-conditioned model, would put every root within √u size of the axis)."""
    if M.shape[0] == 0 or not np.all(np.isfinite(M)):
        return _matrix_size(M)
    return _matrix_size(balanced_matrix(M))


def _closed_matrix(model: StateSpace) -> FloatArray:
    """A - B (1 + D)⁻¹ C of a SISO loop (entries beyond the range of doubles infinite)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return np.asarray(
            model.A - np.outer(model.B[:, 0], model.C[0]) / (1.0 + float(model.D[0, 0])),
            dtype=np.float64,
        )


def _closed_loop_stable(
    closed: ComplexArray, discrete: bool, size: float, matrix: Callable[[], FloatArray]
) -> bool:
    """Whether every closed-loop pole lies strictly inside the stability region, none of them
    on its boundary (:func:`_census` with ``size``, the balanced closed-loop matrix's
    (:func:`_balanced_size`, or the core's), and the closed-loop ``matrix``): a mode at the
    origin that the loop does not reach (a pole of L cancelled by a zero there) stays at 0,
    computed as ±1e-16 or so, and its sign is rounding, so such a loop is not stable rather
    than stable or unstable by chance. (A NaN pole is neither inside nor on the boundary: not
    stable.)"""
    return _census(closed, discrete, size, matrix)[1]


def _outward_distances(roots: ComplexArray, discrete: bool) -> list[float]:
    """Each root's signed distance outward from the stability boundary: Re s, or |z| - 1."""
    if discrete:
        return [math.hypot(r.real, r.imag) - 1.0 for r in roots.tolist()]
    return [r.real for r in roots.tolist()]


def _boundary_flags(
    roots: ComplexArray,
    distances: list[float],
    discrete: bool,
    size: float,
    matrix: Callable[[], FloatArray],
) -> list[bool]:
    """Which roots (eigenvalues of ``matrix``, at the outward ``distances``) lie on the
    stability boundary to their accuracy: within :func:`_boundary_tolerance` of ``size`` (the
    error of a double root, the worst a flight loop has), and, for those, within their
    first-order error bound n u ||M|| κ(λ) in the balanced coordinates M the eigenvalues are
    computed in, with κ(λ) = 1/|yᴴx| from the left and right singular vectors of M - λI
    (Golub & Van Loan, Matrix Computations, §7.2.2), and, for those, within the
    componentwise bound of :func:`_componentwise_reach` (which takes -2 beside -2^60 off the
    axis, as the core computes it on the graded ordering or polishes it). A defective root
    (the double integrator's, κ ~ 1/√u) stays on the boundary; a simple one in badly scaled
    coordinates (+0.001 beside an entry of 1e6, √u ||M|| = 0.015) is off it, as it is
    computed. The ``matrix`` is formed only when a root is near the boundary; where it is not
    finite, the tolerance alone decides. A size beyond the doubles (B C overflows) is replaced
    by the roots' own."""
    if not math.isfinite(size):
        size = max((math.hypot(r.real, r.imag) for r in roots.tolist()), default=0.0)
    tolerance = _boundary_tolerance(size, discrete)
    flags = [abs(x) <= tolerance for x in distances]
    if not any(flags):
        return flags
    formed = matrix()
    if not np.all(np.isfinite(formed)):
        return flags
    balanced = balanced_matrix(formed)
    n = balanced.shape[0]
    unit = n * _EPS * _matrix_size(balanced)
    for i in (i for i, flag in enumerate(flags) if flag):
        shifted = balanced - roots[i] * np.eye(n)
        if not np.all(np.isfinite(shifted)):
            continue
        left, _, right = np.linalg.svd(shifted)
        overlap = abs(complex(np.vdot(left[:, -1], right[-1].conj())))
        if overlap == 0.0 or abs(distances[i]) <= unit / overlap:
            flags[i] = abs(distances[i]) <= _componentwise_reach(
                balanced, roots[i], left[:, -1], right[-1].conj()
            )
        else:
            flags[i] = False
    return flags


def _componentwise_reach(M: FloatArray, root: complex, y: ComplexArray, x: ComplexArray) -> float:
    """A first-order bound on the error of the computed eigenvalue ``root`` of M measured
    componentwise, a posteriori: with x and y the right and left null vectors of M - λI
    refined by a step of inverse iteration (from the singular vectors ``x``, ``y``), the
    componentwise backward error η = max_i |(M x - λ x)_i| / ((|M| + |λ| I) |x|)_i of the pair
    (Oettli & Prager's measure, rounding included), and the bound
    (η + n u) |y|ᵀ (|M| + |λ| I) |x| / |yᴴx| (the componentwise condition of a simple
    eigenvalue; Golub & Van Loan, Matrix Computations, §7.2.2, with |M| in place of ||M||).
    It is at most the normwise bound where the root is computed to a small relative backward
    error, the small roots of a graded M (-2 beside -2^60, which the normwise bound puts on
    the axis), and at least |λ| where it is not (a root at 0 computed as -5e-18 beside a zero
    column of M, whose exact eigenvalue 0 the rounding of M cannot move: η = 1). Infinite
    where the vectors are not finite or orthogonal."""
    n = M.shape[0]
    shifted = M - root * np.eye(n)
    with np.errstate(all="ignore"):
        try:
            x = np.asarray(np.linalg.solve(shifted, x), dtype=np.complex128)
            y = np.asarray(np.linalg.solve(shifted.conj().T, y), dtype=np.complex128)
        except np.linalg.LinAlgError:
            pass  # M - λI singular to working precision: the singular vectors are its null vectors
        x, y = x / np.max(np.abs(x)), y / np.max(np.abs(y))
        size = np.abs(M) + abs(root) * np.eye(n)
        scale = size @ np.abs(x)
        residual = np.abs(M @ x - root * x)
        ratios = np.where(scale > 0.0, residual / np.where(scale > 0.0, scale, 1.0), np.inf)
        eta = float(np.max(np.where(residual == 0.0, 0.0, ratios)))
        overlap = abs(complex(np.vdot(y, x)))
        spread = (eta + n * _EPS) * float(np.abs(y) @ size @ np.abs(x))
    if not (overlap > 0.0 and math.isfinite(spread)):
        return math.inf
    return float(spread / overlap)


def _matrix_size(M: FloatArray) -> float:
    """||M||_F, formed from M divided by its largest |entry| (the squares of entries below
    1e-154 underflow: numpy's norm of a matrix of 1e-300 is 0), or that entry where the norm
    overflows."""
    largest = float(np.max(np.abs(M), initial=0.0))
    if not (0.0 < largest < math.inf):
        return largest
    with np.errstate(over="ignore"):
        size = largest * float(np.linalg.norm(M / largest))
    return size if math.isfinite(size) else largest


@dataclass(frozen=True)
class _Indentation:
    """A small half circle s = jω0 + ε e^{jφ} (z = e^{s dt}) to the right of open-loop poles
    (for the Nichols phase, also zeros) on the imaginary axis (outside the unit circle)."""

    frequency: float
    """ω0 (rad/s), at least 0."""
    radius: float
    """ε (rad/s)."""
    multiplicity: int
    """The number of roots at jω0."""
    low: float
    """The first angle φ of the ω ≥ 0 half (0 for ω0 = 0, else -π/2)."""
    high: float
    """The last angle φ (0 for ω0 = π/dt, else π/2)."""


def _indentations(
    poles: ComplexArray,
    clear_of: ComplexArray,
    asked: FloatArray | None,
    dt: float,
    tolerance: float,
    fraction: float,
) -> list[_Indentation]:
    """One indentation per distinct frequency of the roots ``poles`` on the boundary, of
    radius ``fraction`` times the distance from its centre to the nearest other root of
    ``clear_of`` (the open- and closed-loop poles, or the open loop's poles and zeros) or
    asked frequency."""
    if poles.size == 0:
        return []
    nyquist = math.pi / dt if dt else math.inf
    w_tolerance = tolerance / dt if dt else tolerance
    w = np.abs(np.angle(poles) / dt if dt else poles.imag)
    w = np.sort(w)
    groups = np.split(w, np.flatnonzero(np.diff(w) > 2.0 * w_tolerance) + 1)
    result = []
    for group in groups:
        centre = float(np.mean(group))
        spread = float(group[-1] - group[0])
        if centre <= w_tolerance + spread:
            centre = 0.0
        elif dt and abs(centre - nyquist) <= w_tolerance + spread:
            centre = nyquist
        on_real_axis = centre == 0.0 or centre == nyquist
        multiplicity = group.size if on_real_axis else max(group.size // 2, 1)
        if dt:
            point = complex(np.exp(1j * centre * dt))
            with np.errstate(over="ignore", invalid="ignore"):
                distances = _magnitude(clear_of - point) / dt
        else:
            with np.errstate(over="ignore", invalid="ignore"):
                distances = _magnitude(clear_of - 1j * centre)
        if asked is not None:
            distances = np.concatenate([distances, np.abs(asked - centre)])
        distances = distances[distances > 4.0 * w_tolerance + spread]
        nearest = float(np.min(distances, initial=math.inf))
        if not math.isfinite(nearest):
            nearest = nyquist if dt else max(centre, 1.0)
        radius = fraction * nearest
        if dt:
            radius = min(radius, fraction * nyquist)
        low = 0.0 if centre == 0.0 else -math.pi / 2
        high = 0.0 if centre == nyquist else math.pi / 2
        result.append(_Indentation(centre, radius, multiplicity, low, high))
    return result


def _contour_frequencies(
    model: StateSpace,
    indentations: list[_Indentation],
    closed: ComplexArray,
    asked: FloatArray | None,
) -> FloatArray:
    """The frequencies of the contour's points on the axis: the loop's grid (:func:`_grid`),
    0 (and π/dt), points clustered at the closed-loop poles (spaced |Re s|/4 about Im s, where
    the curve passes -1 nearest), points from each indentation's radius out to the pole's
    neighbours, and the asked frequencies."""
    dt = period(model) if model.is_discrete else 0.0
    with warnings.catch_warnings():  # roots beyond the doubles only leave the grid shorter
        warnings.simplefilter("ignore", NumericalOverflowWarning)
        parts = [_grid(model), np.zeros(1)]
    if dt:
        parts.append(np.array([math.pi / dt]))
    s = _continuous(closed, dt)
    s = s[np.isfinite(s)]
    spread = np.linspace(-10.0, 10.0, 81)
    with np.errstate(over="ignore", invalid="ignore"):  # beyond the doubles: dropped below
        for root in s:
            parts.append(abs(root.imag) + abs(root.real) * spread)
        for indentation in indentations:
            reach = indentation.radius * np.logspace(0.05, math.log10(1.0 / INDENT_FRACTION), 25)
            parts.append(indentation.frequency + reach)
            parts.append(indentation.frequency - reach)
    if asked is not None:
        parts.append(asked)
    omega = np.unique(np.concatenate(parts))
    omega = omega[np.isfinite(omega) & (omega >= 0.0)]
    if dt:
        omega = omega[omega <= math.pi / dt]
    return np.asarray(omega, dtype=np.float64)


class _Contour:
    """The ω ≥ 0 half of the Nyquist contour of a SISO loop and L at its points.

    Its pieces alternate: piece 2k lies on the imaginary axis (for a discrete loop, the unit
    circle z = e^{jω dt}), with the frequency ω as parameter (ω = ∞ is the point at infinity of
    a continuous loop, where L = D); piece 2k + 1 is indentation k, s = jω0 + ε e^{jφ} with the
    angle φ as parameter (z = e^{s dt}). The mirror half, ω ≤ 0, is the complex conjugate."""

    def __init__(
        self, model: StateSpace, indentations: list[_Indentation], omega: FloatArray
    ) -> None:
        self.model = model
        self.dt = period(model) if model.is_discrete else 0.0
        self.indentations = indentations
        self.response = _Response(model)
        self.piece = np.zeros(0, np.int64)
        self.parameter = np.zeros(0)
        self.s = np.zeros(0, np.complex128)
        self.values = np.zeros(0, np.complex128)
        outside = np.ones(omega.size, dtype=bool)
        for indentation in indentations:
            outside &= np.abs(omega - indentation.frequency) > indentation.radius
        axis = omega[outside]
        if not self.dt:
            axis = np.concatenate([axis, [math.inf]])
        centres = np.array([indentation.frequency for indentation in indentations])
        pieces = [2 * np.searchsorted(centres, axis).astype(np.int64)]
        parameters = [axis]
        for k, indentation in enumerate(indentations):
            quarters = round((indentation.high - indentation.low) / (math.pi / 2))
            count = quarters * ARC_POINTS * indentation.multiplicity + 1
            pieces.append(np.full(count, 2 * k + 1, dtype=np.int64))
            parameters.append(np.linspace(indentation.low, indentation.high, count))
        self.add(np.concatenate(pieces), np.concatenate(parameters))

    def _points(self, piece: IntArray, parameter: FloatArray) -> ComplexArray:
        """s at each (piece, parameter)."""
        s = np.zeros(piece.size, np.complex128)
        axis = piece % 2 == 0
        s.imag[axis] = parameter[axis]
        for k, indentation in enumerate(self.indentations):
            on = piece == 2 * k + 1
            phi = parameter[on]
            # φ = ±π/2 is on the axis: cos(π/2) = 6e-17 is not 0.
            s.real[on] = np.where(np.abs(phi) == math.pi / 2, 0.0, indentation.radius * np.cos(phi))
            s.imag[on] = indentation.frequency + indentation.radius * np.sin(phi)
        return s

    def _evaluate(self, s: ComplexArray) -> ComplexArray:
        """L(s) (L(e^{s dt})): on the axis by one call of the core; off it (on an indentation,
        s = σ + jω) from the shifted loop, L(σ + jω) = C (jωI - (A - σI))⁻¹ B + D, or for a
        discrete loop with r = e^{σ dt}, L(r e^{jω dt}) = C (e^{jω dt} I - A/r)⁻¹ (B/r) + D."""
        m = self.model
        values = np.empty(s.size, np.complex128)
        infinite = np.isinf(s.imag)
        values[infinite] = m.D[0, 0]
        axis = (s.real == 0.0) & ~infinite
        values[axis] = self.response.many(np.array(s.imag[axis]))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NumericalOverflowWarning)
            for i in np.flatnonzero(~axis & ~infinite):
                sigma, w = float(s.real[i]), np.array([s.imag[i]])
                if self.dt:
                    shrink = math.exp(-sigma * self.dt)
                    response = _core.frequency_response(
                        m.A * shrink, m.B * shrink, m.C, m.D, w, self.dt
                    )
                else:
                    shifted = m.A - sigma * np.eye(m.n_states)
                    response = _core.frequency_response(shifted, m.B, m.C, m.D, w, None)
                values[i] = response[0, 0, 0]
        return values

    def add(self, piece: IntArray, parameter: FloatArray) -> None:
        """Adds points, evaluating L at them, and keeps the points in contour order."""
        s = self._points(piece, parameter)
        values = self._evaluate(s)
        self.piece = np.concatenate([self.piece, piece])
        self.parameter = np.concatenate([self.parameter, parameter])
        self.s = np.concatenate([self.s, s])
        self.values = np.concatenate([self.values, values])
        order = np.lexsort((self.parameter, self.piece))
        self.piece, self.parameter = self.piece[order], self.parameter[order]
        self.s, self.values = self.s[order], self.values[order]

    def bisect(self, steps: BoolArray) -> None:
        """Adds the midpoint of each step (between points i and i + 1) marked in ``steps``:
        the mean angle on an indentation; on the axis the mean frequency (geometric for a step
        over more than a factor of 4; ten times the last frequency towards ω = ∞)."""
        i = np.flatnonzero(steps)
        piece_a, piece_b = self.piece[i], self.piece[i + 1]
        a, b = self.parameter[i], self.parameter[i + 1]
        piece = np.where(
            piece_a == piece_b, piece_a, np.where(piece_a % 2 == 0, piece_a, piece_a + 1)
        )
        axis = piece % 2 == 0
        w_a = np.where(piece_a % 2 == 0, a, self.s.imag[i])
        w_b = np.where(piece_b % 2 == 0, b, self.s.imag[i + 1])
        with np.errstate(over="ignore", invalid="ignore"):
            geometric = np.sqrt(w_a) * np.sqrt(w_b)
            towards_infinity = np.minimum(10.0 * w_a, np.finfo(float).max)
            middle = np.where(
                np.isinf(w_b),
                np.where(w_a > 0.0, towards_infinity, 1.0),
                np.where((w_a > 0.0) & (w_b > 4.0 * w_a), geometric, 0.5 * w_a + 0.5 * w_b),
            )
        parameter = np.where(axis, middle, 0.5 * a + 0.5 * b)
        # A step that cannot be split (between neighbouring doubles, or from the largest
        # double to ∞) is left as it is.
        new = (parameter != a) & (parameter != b)
        self.add(piece[new].astype(np.int64), parameter[new].astype(np.float64))

    def turns(self, centre: complex) -> FloatArray:
        """The angle (radians, in [-π, π)) that the curve turns about ``centre`` over each
        step of the half contour."""
        with np.errstate(invalid="ignore"):
            angles = np.angle(self.values - centre)
        steps = np.diff(angles)
        return np.asarray((steps + math.pi) % (2.0 * math.pi) - math.pi, dtype=np.float64)

    def refine(self, centres: list[complex]) -> None:
        """Bisects every step over which the curve turns by more than MAX_TURN about one of
        ``centres``, for REFINE_ROUNDS rounds or up to MAX_CONTOUR_POINTS points. Steps from
        a point at a centre (L = 0 at a zero on the axis, for the phase) are left alone."""
        for _ in range(REFINE_ROUNDS):
            wide = np.zeros(max(self.values.size - 1, 0), dtype=bool)
            for centre in centres:
                at = self.values == centre
                wide |= (np.abs(self.turns(centre)) > MAX_TURN) & ~at[:-1] & ~at[1:]
            count = int(np.sum(wide))
            if count == 0 or self.values.size + count > MAX_CONTOUR_POINTS:
                return
            size = self.values.size
            self.bisect(wide)
            if self.values.size == size:  # no step could be split
                return

    def winding(self, centre: complex) -> float:
        """The number of counterclockwise turns about ``centre`` of the closed curve: the
        mirror half (ω from -∞ to 0, the conjugates in reverse) then the half ω ≥ 0."""
        closed = np.concatenate([np.conj(self.values[::-1]), self.values])
        angles = np.angle(closed - centre)
        steps = np.diff(np.concatenate([angles, angles[:1]]))
        wrapped = (steps + math.pi) % (2.0 * math.pi) - math.pi
        return float(np.sum(wrapped) / (2.0 * math.pi))

    @property
    def axis(self) -> BoolArray:
        """The points on the axis at finite frequencies."""
        return np.asarray((self.piece % 2 == 0) & np.isfinite(self.parameter), dtype=np.bool_)

    @property
    def points(self) -> ComplexArray:
        """The contour in the loop's variable: s, or z = e^{s dt} (exactly ±1 at the ends)."""
        if not self.dt:
            return self.s
        z = np.exp(self.s * self.dt)
        real = self.s.imag == 0.0
        z.imag[real] = 0.0
        nyquist = self.s.imag == math.pi / self.dt
        z.imag[nyquist] = 0.0
        return np.asarray(z, dtype=np.complex128)


def _check_finite_curve(contour: _Contour, function: str) -> None:
    bad = ~np.isfinite(contour.values)
    if np.any(bad):
        where = contour.points[np.argmax(bad)]
        raise AerocontrolLinAlgError(
            f"{function}: the loop's response overflows double precision on its Nyquist "
            f"contour (at {where:.6g}), so the curve cannot be followed"
        )


@dataclass(frozen=True)
class _Poles:
    """The open- and closed-loop poles of a loop and which lie on the stability boundary."""

    open: ComplexArray
    open_boundary: BoolArray
    closed: ComplexArray
    closed_boundary: BoolArray
    tolerance: float
    """The open loop's boundary tolerance (:func:`_boundary_tolerance`)."""


def _poles(model: StateSpace, closed_loop: bool) -> _Poles:
    """The open- and closed-loop poles and which lie on the stability boundary
    (:func:`_boundary_flags`), all from the loop with its states balanced with B and C
    (:func:`balanced_states`), as :func:`stability_margins` computes them: a tolerance from
    the unbalanced size (1e6 for states scaled by 10^±6) put an open-loop pole at +0.001 on
    the axis, and P and N at 0; and the closed-loop poles' tolerance from the size of that
    closed loop: the core's root-locus QR is unbalanced, so its errors are relative to the
    matrix it is given, and a tolerance from the unbalanced size (2e11 for states scaled by
    10^±6) counted a closed-loop pole at +0.37 as on the axis."""
    discrete = model.is_discrete
    model = balanced_states(model)
    open_poles = _eigenvalues(model.A)
    open_size = _balanced_size(model.A)
    open_matrix = model.A
    open_boundary = _boundary_flags(
        open_poles,
        _outward_distances(open_poles, discrete),
        discrete,
        open_size,
        lambda: open_matrix,
    )
    if closed_loop:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NumericalOverflowWarning)
            closed = _closed_loop_poles(model, np.ones(1))[0]
        if not np.all(np.isfinite(closed)):
            raise AerocontrolLinAlgError(
                "nyquist: the closed-loop poles overflow double precision, so the unstable "
                "ones (Z) cannot be counted"
            )
        matrix = _closed_matrix(model)
        closed_boundary = _boundary_flags(
            closed,
            _outward_distances(closed, discrete),
            discrete,
            _matrix_size(matrix),
            lambda: matrix,
        )
    else:
        closed, closed_boundary = np.zeros(0, np.complex128), []
    return _Poles(
        open=open_poles,
        open_boundary=np.array(open_boundary, dtype=np.bool_),
        closed=closed,
        closed_boundary=np.array(closed_boundary, dtype=np.bool_),
        tolerance=_boundary_tolerance(open_size, discrete),
    )


def _half_contour(
    model: StateSpace,
    indented: ComplexArray,
    clear_of: ComplexArray,
    closed: ComplexArray,
    asked: FloatArray | None,
    tolerance: float,
    fraction: float,
) -> _Contour:
    """The half contour with indentations around the roots ``indented`` (on the boundary),
    clear of the roots ``clear_of``, through the asked frequencies (but those at an indented
    root), with points clustered at the closed-loop poles ``closed``."""
    dt = period(model) if model.is_discrete else 0.0
    indentations = _indentations(indented, clear_of, asked, dt, tolerance, fraction)
    if asked is not None:  # an asked frequency at an indented root is not on the contour
        at_root = np.zeros(asked.size, dtype=bool)
        for indentation in indentations:
            at_root |= np.abs(asked - indentation.frequency) <= indentation.radius
        asked = asked[~at_root]
    omega = _contour_frequencies(model, indentations, closed, asked)
    return _Contour(model, indentations, omega)


@dataclass(frozen=True, eq=False)
class NyquistResponse(Result):
    """The Nyquist curve of a SISO loop, negative feedback (1 + L = 0), and its count of
    encirclements of -1 checked against the open- and closed-loop poles; ``print`` shows P, N,
    Z and the verdict.

    The Nyquist contour runs up the imaginary axis, ω from -∞ to ∞, and is closed by the half
    circle at infinity, where L = D (L is proper); a discrete loop's contour is the unit
    circle z = e^{jω dt}, ω from -π/dt to π/dt. Open-loop poles on the axis (the circle) are
    passed by small half circles to their right (outside the circle), so they count as stable
    in P; the image of such an indentation is a large arc, turning clockwise by 180° times the
    poles' multiplicity. The arrays hold the half ω ≥ 0: the half ω ≤ 0 is its mirror image,
    the complex conjugate (:attr:`closed_curve` joins them).

    Attributes
    ----------
    omega : ndarray (k,)
        The frequencies asked for (rad/s, increasing), or by default every frequency of the
        contour's points on the axis.
    response : ndarray (k,), complex
        L(jω) (L(e^{jω dt})) at ``omega``; infinite (or huge) at a pole on the axis.
    contour : ndarray, complex
        The half ω ≥ 0 of the Nyquist contour in order, in the loop's variable (s, or z),
        indentations included.
    curve : ndarray, complex
        L on ``contour``: the half ω ≥ 0 of the Nyquist curve (ending at L(j∞) = D).
    indented : ndarray, bool
        Which points of ``contour`` lie on an indentation.
    indentations : tuple of (float, float, int)
        (ω0 in rad/s, radius ε in rad/s, number of poles) of each indentation.
    open_loop_unstable_poles : int
        P: open-loop poles in the open right half plane (outside the unit circle).
    encirclements : int or None
        N: counterclockwise encirclements of -1 by the closed curve, P - Z; None when the curve
        passes through -1 (``marginal``).
    closed_loop_unstable_poles : int
        Z: closed-loop poles (eigenvalues of A - B (1 + D)⁻¹ C) in the open right half plane
        (outside the unit circle).
    closed_loop_poles : ndarray (n,), complex
        All closed-loop poles.
    boundary_poles : ndarray, complex
        The closed-loop poles on the imaginary axis (the unit circle); empty unless ``marginal``.
    dt : float
        The sampling period (s), 0 for a continuous loop.
    loop : StateSpace
        The loop L.
    marginal : bool
        True when closed-loop poles lie on the stability boundary: N is then not defined.
    closed_loop_stable : bool
        Every closed-loop pole in the open left half plane (inside the unit circle).
    closed_curve : ndarray, complex
        The whole closed Nyquist curve: the mirror half (ω from -∞ to 0), then the half ω ≥ 0.

    Examples
    --------
    10 (s + 2)/((s - 1)(s + 5)) has P = 1 and circles -1 once counterclockwise, so Z = 0: the
    closed loop s² + 14 s + 15 has the poles -7 ± √34:

    >>> import numpy as np, aerocontrol
    >>> r = aerocontrol.nyquist(aerocontrol.zpk([-2.0], [1.0, -5.0], 10.0))
    >>> r.open_loop_unstable_poles, r.encirclements, r.closed_loop_unstable_poles
    (1, 1, 0)
    >>> np.round(r.closed_loop_poles.real, 6), r.closed_loop_stable
    (array([-12.830952,  -1.169048]), True)
    """

    omega: FloatArray
    """The frequencies asked for (rad/s, increasing), or by default every frequency of the
    contour's points on the axis."""
    response: ComplexArray
    """L(jω) (L(e^{jω dt})) at ``omega``; infinite (or huge) at a pole on the axis."""
    contour: ComplexArray
    """The half ω ≥ 0 of the Nyquist contour in order, in the loop's variable: s from 0 (or
    from the indentation about a pole at 0) to j∞ (``complex(0, inf)``, the last point), or
    z from 1 to -1; indentations included."""
    curve: ComplexArray
    """L on ``contour``: the half ω ≥ 0 of the Nyquist curve (ending at L(j∞) = D)."""
    indented: BoolArray
    """Which points of ``contour`` lie on an indentation."""
    indentations: tuple[tuple[float, float, int], ...]
    """(ω0 in rad/s, radius ε in rad/s, number of poles) of each indentation, s = jω0 + ε e^{jφ}
    (z = e^{s dt})."""
    open_loop_unstable_poles: int
    """P: open-loop poles in the open right half plane (outside the unit circle)."""
    encirclements: int | None
    """N: counterclockwise encirclements of -1 by the closed curve, P - Z (the convention of
    :attr:`StabilityMargins.encirclements`; python-control counts clockwise ones, Z - P). None
    when the curve passes through -1 (:attr:`marginal`)."""
    closed_loop_unstable_poles: int
    """Z: closed-loop poles (eigenvalues of A - B (1 + D)⁻¹ C) in the open right half plane
    (outside the unit circle)."""
    closed_loop_poles: ComplexArray
    boundary_poles: ComplexArray
    """The closed-loop poles on the imaginary axis (the unit circle), to √u times the size of
    the closed-loop matrix; empty unless :attr:`marginal`."""
    dt: float
    """The sampling period (s), 0 for a continuous loop."""
    loop: StateSpace = field(repr=False)

    @property
    def marginal(self) -> bool:
        """True when closed-loop poles lie on the imaginary axis (the unit circle): the curve
        passes through -1 (unless they are hidden modes), N is not defined, and the closed
        loop is not asymptotically stable."""
        return bool(self.boundary_poles.size)

    @property
    def closed_loop_stable(self) -> bool:
        """Every closed-loop pole in the open left half plane (inside the unit circle)."""
        return not self.marginal and self.closed_loop_unstable_poles == 0

    @property
    def closed_curve(self) -> ComplexArray:
        """The whole closed Nyquist curve in the order of the contour: the mirror half (ω from
        -∞ to 0) then the half ω ≥ 0."""
        return np.concatenate([np.conj(self.curve[::-1]), self.curve])

    def table(self) -> str:
        """P, N and Z, the verdict and the indentations, one line each."""
        region = "outside the unit circle" if self.dt else "in the open right half plane"
        boundary = "unit circle" if self.dt else "imaginary axis"
        lines = [
            "Nyquist criterion, negative feedback (1 + L = 0): Z = P - N",
            f"  P = {self.open_loop_unstable_poles:<4d} open-loop poles {region}",
        ]
        if self.encirclements is None:
            shown = ", ".join(f"{p:.6g}" for p in self.boundary_poles)
            lines.append(
                f"  N undefined: the curve passes through -1 (closed-loop poles on the "
                f"{boundary}: {shown})"
            )
        else:
            lines.append(f"  N = {self.encirclements:<4d} counterclockwise encirclements of -1")
        lines.append(
            f"  Z = {self.closed_loop_unstable_poles:<4d} closed-loop poles {region} "
            "(from the closed-loop eigenvalues)"
        )
        if self.closed_loop_stable:
            verdict = "closed loop stable"
        elif self.closed_loop_unstable_poles:
            verdict = "closed loop UNSTABLE"
        else:
            verdict = f"closed loop MARGINAL: poles on the {boundary}, not asymptotically stable"
        lines.append(verdict)
        for w0, radius, count in self.indentations:
            lines.append(
                f"indented around {count} open-loop pole{'s' if count > 1 else ''} at "
                f"ω = {w0:.6g} rad/s, radius {radius:.3g} rad/s"
            )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.table()

    def plot(
        self, ax: Axes | None = None, unit_circle: bool = False, max_magnitude: float = 20.0
    ) -> Axes:
        """The curve, solid for ω ≥ 0 and dashed for its mirror, with arrows, -1 and (with
        ``unit_circle``) the unit circle; radii beyond ``max_magnitude`` are compressed (see
        :func:`~aerocontrol.plotting.plot_nyquist`)."""
        from .plotting import plot_nyquist

        return plot_nyquist(self, ax=ax, unit_circle=unit_circle, max_magnitude=max_magnitude)


def nyquist(loop: System, omega: ArrayLike | None = None) -> NyquistResponse:
    """The Nyquist curve of a SISO loop and the encirclements of -1 (negative feedback,
    1 + L(s) = 0), checked against the open- and closed-loop poles.

    The principle of the argument applied to 1 + L(s) = (1 + D) det(sI - A_cl)/det(sI - A),
    with A_cl = A - B (1 + D)⁻¹ C, gives N = P - Z: the counterclockwise encirclements of -1
    by L along the Nyquist contour (up the imaginary axis and round the right half plane, or
    counterclockwise round the unit circle) are the open-loop poles P less the closed-loop
    poles Z in the open right half plane (outside the unit circle). Uncontrollable or
    unobservable modes are poles of both and cancel.

    The curve is L on the contour (the core's frequency response on the axis, and the shifted
    loop's on the indentations): on the loop's grid of frequencies (clustered at lightly
    damped open-loop roots and at the closed-loop poles, where the curve passes -1 nearest),
    every step over which the curve turns more than 22.5° about -1 bisected. N is its winding
    number about -1. It is returned only if it equals P - Z with Z counted from the closed-loop
    eigenvalues; otherwise the contour is tried again with indentations a hundred times
    smaller and twice the points, and a count that still disagrees is refused.

    Roots within √u ||A||_F of the boundary (the error of a double integrator's computed
    eigenvalues) are taken to lie on it: open-loop ones are indented and do not count in P;
    closed-loop ones make the loop ``marginal``, its curve passes
    through -1 and N is None (the result is still returned, for the plot).

    Parameters
    ----------
    loop : StateSpace or (A, B, C, D)
        The open-loop transfer L, one input and one output; continuous or discrete.
    omega : array_like, optional
        Frequencies (rad/s, non-negative, at most π/dt for a discrete loop) at which to
        report L, sorted and without repeats; the contour passes through them (but through
        none at a pole on the axis, where L is the core's, not finite). By default every
        frequency of the contour on the axis is reported.

    Returns
    -------
    NyquistResponse

    Raises
    ------
    ShapeError
        The loop is not single-input, single-output, or ``omega`` is not a 1-D array.
    NonFiniteError, InvalidArgumentError
        ``omega`` has a NaN or infinite, negative, or (discrete loop) beyond π/dt entry.
    SingularMatrixError
        1 + D = 0: closing the loop is an algebraic loop.
    AerocontrolLinAlgError
        The winding number disagrees with P - Z after the retries (the curve passes too near
        -1 to count), or L overflows on the contour.

    Examples
    --------
    >>> import aerocontrol
    >>> # k/(s + 1)³ is stable for k < 8; at k = 10 the curve circles -1 twice clockwise.
    >>> r = aerocontrol.nyquist(aerocontrol.zpk([], [-1.0, -1.0, -1.0], 10.0))
    >>> r.open_loop_unstable_poles, r.encirclements, r.closed_loop_unstable_poles
    (0, -2, 2)
    >>> # 10 (s + 2)/((s - 1)(s + 5)): one open-loop pole in the right half plane, one
    >>> # counterclockwise encirclement, so the closed loop s² + 14 s + 15 is stable.
    >>> r = aerocontrol.nyquist(aerocontrol.zpk([-2.0], [1.0, -5.0], 10.0))
    >>> r.encirclements, r.closed_loop_stable
    (1, True)
    >>> # 6/(s (s + 1)(s + 2)) is at its gain margin: closed-loop poles ±j√2.
    >>> r = aerocontrol.nyquist(aerocontrol.zpk([], [0.0, -1.0, -2.0], 6.0))
    >>> r.marginal, r.encirclements
    (True, None)
    """
    model = _siso(loop)
    _refuse_algebraic(model)
    discrete = model.is_discrete
    dt = period(model) if discrete else 0.0
    asked = _asked_frequencies(omega, dt)
    poles = _poles(model, closed_loop=True)
    unstable_open = int(np.sum(_unstable(poles.open, discrete) & ~poles.open_boundary))
    unstable_closed = int(np.sum(_unstable(poles.closed, discrete) & ~poles.closed_boundary))
    marginal = bool(np.any(poles.closed_boundary))
    expected = unstable_open - unstable_closed
    encirclements: int | None = None
    indented = poles.open[poles.open_boundary]
    clear_of = np.concatenate([poles.open, poles.closed])
    for attempt in range(COUNT_RETRIES + 1):
        fraction = INDENT_FRACTION * 0.01**attempt
        contour = _half_contour(
            model, indented, clear_of, poles.closed, asked, poles.tolerance, fraction
        )
        if attempt:
            contour.bisect(np.ones(contour.values.size - 1, dtype=bool))
        contour.refine([] if marginal else [-1.0])
        _check_finite_curve(contour, "nyquist")
        if marginal:
            break
        winding = contour.winding(-1.0)
        count = round(winding)
        if abs(winding - count) <= 1e-3 and count == expected:
            encirclements = count
            break
    else:
        distance = float(np.min(_magnitude(1.0 + contour.values)))
        raise AerocontrolLinAlgError(
            f"nyquist: the curve's winding number about -1 is {winding:.4g}, not P - Z = "
            f"{unstable_open} - {unstable_closed} = {expected} from the open- and closed-loop "
            f"poles, with {contour.values.size} points and indentations of radius down to "
            f"{INDENT_FRACTION * 0.01**COUNT_RETRIES:g} of the poles' distances: the curve "
            f"passes within {distance:.3g} of -1, too near to count"
        )
    if asked is None:
        axis = contour.axis
        frequencies, response = contour.parameter[axis], contour.values[axis]
    else:
        frequencies, response = asked, _Response(model).many(asked)
    return NyquistResponse(
        omega=np.array(frequencies, dtype=np.float64),
        response=np.array(response, dtype=np.complex128),
        contour=contour.points,
        curve=contour.values,
        indented=np.asarray(contour.piece % 2 == 1, dtype=np.bool_),
        indentations=tuple((i.frequency, i.radius, i.multiplicity) for i in contour.indentations),
        open_loop_unstable_poles=unstable_open,
        encirclements=encirclements,
        closed_loop_unstable_poles=unstable_closed,
        closed_loop_poles=np.sort_complex(poles.closed).astype(np.complex128),
        boundary_poles=np.sort_complex(poles.closed[poles.closed_boundary]).astype(np.complex128),
        dt=dt,
        loop=model,
    )


@dataclass(frozen=True, eq=False)
class NicholsResponse(Result):
    """The open-loop gain (dB) against the phase (degrees) of a SISO loop over frequency, for
    the Nichols chart; ``print`` shows the ranges.

    Attributes
    ----------
    omega : ndarray (k,)
        Frequencies (rad/s, increasing).
    response : ndarray (k,), complex
        L(jω) (L(e^{jω dt}) for a discrete loop).
    gain_db : ndarray (k,)
        20 log10 abs(L) (∞ at a pole on the axis, -∞ at a zero).
    phase_deg : ndarray (k,)
        ∠L in degrees, continuous along the Nyquist contour.
    dt : float
        The sampling period (s); 0 for a continuous loop.
    loop : StateSpace
        The loop L.

    Examples
    --------
    2/(s(s + 1)(s + 2)) crosses -180° at ω = √2, where L = -1/3 (gain margin 9.54 dB):

    >>> import numpy as np, aerocontrol
    >>> n = aerocontrol.nichols(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0), [np.sqrt(2.0)])
    >>> np.round(n.gain_db, 4), np.round(n.phase_deg, 6)
    (array([-9.5424]), array([-180.]))
    """

    omega: FloatArray
    """Frequencies (rad/s, increasing)."""
    response: ComplexArray
    """L(jω) (L(e^{jω dt}))."""
    gain_db: FloatArray
    """20 log10 abs(L) (∞ at a pole on the axis, -∞ at a zero)."""
    phase_deg: FloatArray
    """∠L in degrees, continuous along the Nyquist contour with indentations to the right of
    the poles and zeros on the axis (so the phase steps by -180° per pole and +180° per zero
    there, the indentations' turns), starting in [-180°, 180°) at the contour's first point
    (ω = 0, or the start of the indentation at s = 0); NaN at a frequency asked at such a
    pole or zero."""
    dt: float
    """The sampling period (s), 0 for a continuous loop."""
    loop: StateSpace = field(repr=False)

    def table(self) -> str:
        """The frequency, gain and phase ranges."""
        finite = np.isfinite(self.gain_db) & np.isfinite(self.phase_deg)
        if not np.any(finite):
            return f"Nichols: {self.omega.size} frequencies, no finite gain and phase"
        gain, phase = self.gain_db[finite], self.phase_deg[finite]
        return "\n".join(
            [
                f"Nichols: {self.omega.size} frequencies, {self.omega.min():.4g} ... "
                f"{self.omega.max():.4g} rad/s",
                f"  gain  {gain.min():+.2f} ... {gain.max():+.2f} dB",
                f"  phase {phase.min():+.2f} ... {phase.max():+.2f} deg",
            ]
        )

    def __str__(self) -> str:
        return self.table()

    def plot(self, ax: Axes | None = None, grid: bool = True) -> Axes:
        """The Nichols chart: the curve, the critical points (-180° + k 360°, 0 dB) and, with
        ``grid``, contours of constant closed-loop gain and phase (see
        :func:`~aerocontrol.plotting.plot_nichols`)."""
        from .plotting import plot_nichols

        return plot_nichols(self, ax=ax, grid=grid)


def _contour_phase(values: ComplexArray) -> FloatArray:
    """∠L in radians along the contour, unwrapped, the first in [-π, π); NaN where L is 0 or
    not finite."""
    usable = np.isfinite(values) & (values != 0)
    phase = np.full(values.size, math.nan)
    if np.any(usable):
        unwrapped = np.unwrap(np.angle(values[usable]))
        if unwrapped[0] >= math.pi - 1e-12:
            unwrapped -= 2.0 * math.pi
        phase[usable] = unwrapped
    return phase


def nichols(loop: System, omega: ArrayLike | None = None) -> NicholsResponse:
    """The open-loop gain (dB) and phase (degrees) of a SISO loop over frequency, for the
    Nichols chart (negative feedback, 1 + L = 0: the critical points are 0 dB at
    -180° + k 360°).

    L is evaluated along the ω ≥ 0 half of the Nyquist contour of :func:`nyquist`, indented
    to the right of the open loop's poles and zeros on the imaginary axis (the unit circle),
    every step over which its phase turns more than 22.5° bisected, and the phase is
    unwrapped along it: across such a pole it falls by 180° per pole and across such a zero
    it rises by 180° per zero, as along the indentations. It starts in [-180°, 180°) at the
    contour's first point, so a loop with q integrators starts at -90° q, a washout (a zero
    at s = 0) at +90°, and an open loop with L(0) < 0 at -180°. (The indentation keeps the
    phase off L(0) = 0, which the core computes as rounding noise of random sign.)

    Parameters
    ----------
    loop : StateSpace or (A, B, C, D)
        The open-loop transfer L, one input and one output; continuous or discrete.
    omega : array_like, optional
        Frequencies (rad/s, non-negative, at most π/dt for a discrete loop), reported sorted;
        the contour passes through them. A frequency at a pole or zero on the axis has the
        core's L there (not finite at a pole) and phase NaN. By default the contour's
        frequencies on the axis.

    Returns
    -------
    NicholsResponse

    Raises
    ------
    ShapeError, NonFiniteError, InvalidArgumentError
        As :func:`nyquist`, for the loop and ``omega``.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> # 2/(s (s + 1)(s + 2)): -90° - atan ω - atan(ω/2), so -180° at ω = √2, at 20 log10(1/3) dB.
    >>> n = aerocontrol.nichols(aerocontrol.zpk([], [0.0, -1.0, -2.0], 2.0), [np.sqrt(2.0)])
    >>> round(float(n.phase_deg[0]), 10), round(float(n.gain_db[0]), 10)
    (-180.0, -9.5424250944)
    """
    model = _siso(loop)
    dt = period(model) if model.is_discrete else 0.0
    asked = _asked_frequencies(omega, dt)
    poles = _poles(model, closed_loop=False)
    # The zeros on the axis by the poles' band: a band from the size of the system pencil
    # would grow with B and C, which do not move the zeros.
    with warnings.catch_warnings():  # a zero beyond the doubles is not on the axis
        warnings.simplefilter("ignore", NumericalOverflowWarning)
        zeros = _roots_of(model).zeros
    boundary_zeros = zeros[_on_boundary(zeros, model.is_discrete, poles.tolerance)]
    contour = _half_contour(
        model,
        np.concatenate([poles.open[poles.open_boundary], boundary_zeros]),
        np.concatenate([poles.open, zeros]),
        np.zeros(0, np.complex128),
        asked,
        poles.tolerance,
        INDENT_FRACTION,
    )
    contour.refine([0.0])
    _check_finite_curve(contour, "nichols")
    phase = _contour_phase(contour.values)
    axis = contour.axis
    if asked is None:
        keep = axis & ~np.isnan(phase)
        frequencies, response, phases = contour.parameter[keep], contour.values[keep], phase[keep]
    else:
        frequencies, response = asked, _Response(model).many(asked)
        on_axis = contour.parameter[axis]
        index = np.minimum(np.searchsorted(on_axis, asked), on_axis.size - 1)
        found = on_axis[index] == asked
        phases = np.where(found, phase[axis][index], math.nan)
    with np.errstate(divide="ignore", over="ignore"):
        gain_db = 20.0 * np.log10(_magnitude(response))
    return NicholsResponse(
        omega=np.array(frequencies, dtype=np.float64),
        response=np.array(response, dtype=np.complex128),
        gain_db=np.asarray(gain_db, dtype=np.float64),
        phase_deg=np.degrees(phases).astype(np.float64),
        dt=dt,
        loop=model,
    )
