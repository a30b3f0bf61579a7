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
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from . import _core
from ._validation import FloatArray, finite_or_warn, real_scalar
from .exceptions import ConvergenceError, InvalidArgumentError, NumericalOverflowWarning
from .linalg import qz
from .statespace import StateSpace, as_state_space, period, signal_indices

if TYPE_CHECKING:
    from ._typing import SignalSelection, System

__all__ = ["Factor", "TransferFunction", "transfer_function", "transmission_zeros"]

ComplexArray = NDArray[np.complex128]


# ----- the reduction of the system pencil -------------------------------------------------------


def _frobenius(*matrices: FloatArray) -> float:
    """||[M1, M2, ...]||_F without overflow or underflow in the squares: each entry is divided
    by the largest |entry| first (entries beyond 1e154 square to infinity, below 1e-154 to
    zero)."""
    largest = max((float(np.max(np.abs(M), initial=0.0)) for M in matrices), default=0.0)
    if largest == 0.0:
        return 0.0
    total = sum(float(np.sum(np.square(M / largest))) for M in matrices)
    return largest * math.sqrt(total)


def _tolerance(A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray) -> float:
    """The rank tolerance: (n + p)(n + m) ε ||S||_F (as SLICOT's AB08ND), of the balanced
    system matrix S."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    size = _frobenius(A, B, C, D)
    return float((n + p) * (n + m) * np.finfo(float).eps * max(size, np.finfo(float).tiny))


def _exponents(norms: FloatArray) -> NDArray[np.int64]:
    """The exponents e of 2^e of positive norms (frexp's: norm = f 2^e, 1/2 <= f < 1); 0 for a
    zero norm."""
    _, e = np.frexp(norms)
    return np.where(norms > 0.0, e, 0).astype(np.int64)


def _log2_norm(*vectors: FloatArray) -> float:
    """log2 of the 2-norm of the vectors joined, without overflow or underflow; -inf for zero."""
    largest = max((float(np.max(np.abs(v), initial=0.0)) for v in vectors), default=0.0)
    if largest == 0.0:
        return -math.inf
    total = sum(float(np.sum(np.square(v / largest))) for v in vectors)
    return math.log2(largest) + 0.5 * math.log2(total)


def _half_exponent(log2_size: float) -> int:
    """The integer nearest -log2(size) / 2: 2^k of it brings size halfway to 1 (0 for -inf)."""
    return -round(log2_size / 2) if math.isfinite(log2_size) else 0


def _balance(
    A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, int]:
    """The system matrix [[A, B], [C, D]] equilibrated by exact powers of two, and the exponent
    f such that the zeros of the model are 2^f times those of the equilibrated one.

    The zeros of (1) are those of (T A T⁻¹, T B Q, P C T⁻¹, P D Q) for any nonsingular
    diagonal T (a change of state coordinates), P (of output units) and Q (of input units),
    and 2^-s times those of (2^s A, 2^s B, C, D) (a change of the unit of frequency). The rank
    decisions of the reduction compare singular values with ε ||S||, so a block much smaller
    than the largest (D of 1 beside a C of 1e9) would be judged at the scale of the largest:
    equilibrated, every row and column of S has about unit norm where the scalings allow.
    Sweeps as Ruiz's equilibration (each output row of [C D] and input column of [B; D]
    divided by the square root of its norm; A, with B, by the square root of ||A||, the unit
    of frequency, so that the poles are near 1 and zeros of their size resolved) and, for
    each state, Osborne's balancing of its row and column (the power of two nearest
    sqrt(c / r), r and c the norms of the row of [A B] and the column of [A; C] without the
    diagonal, which the similarity leaves unchanged), as LAPACK's xGEBAL does for a matrix.
    Norms are formed as logarithms of scaled sums (no overflow, no underflow), and every
    factor is applied with ``np.ldexp``, exactly.

    References: D. Ruiz, "A scaling algorithm to equilibrate both rows and columns norms in
    matrices", RAL-TR-2001-034, 2001; E. E. Osborne, J. ACM 7, 338-345, 1960."""
    n, p, m = A.shape[0], C.shape[0], B.shape[1]
    A, B, C, D = (np.array(M, dtype=np.float64) for M in (A, B, C, D))
    frequency = 0
    for _ in range(40):
        changed = False
        for i in range(p):
            k = _half_exponent(_log2_norm(C[i], D[i]))
            if k:
                C[i], D[i] = np.ldexp(C[i], k), np.ldexp(D[i], k)
                changed = True
        for j in range(m):
            k = _half_exponent(_log2_norm(B[:, j], D[:, j]))
            if k:
                B[:, j], D[:, j] = np.ldexp(B[:, j], k), np.ldexp(D[:, j], k)
                changed = True
        # The unit of frequency: A of unit norm (the poles near 1), else the rows of B.
        size = _log2_norm(A)
        if not math.isfinite(size):
            size = _log2_norm(B) if n else -math.inf
        k = _half_exponent(size)
        if k:
            A, B = np.ldexp(A, k), np.ldexp(B, k)
            frequency -= k
            changed = True
        for i in range(n):
            r = _log2_norm(np.delete(A[i], i), B[i])
            c = _log2_norm(np.delete(A[:, i], i), C[:, i])
            if not (math.isfinite(r) and math.isfinite(c)):
                continue
            k = round((c - r) / 2)
            if k:
                diagonal = A[i, i]  # unchanged by the similarity (scaled twice, it underflows)
                # Only the diagonal, restored below, may overflow here (A of 1e308 beside B of
                # 1e-151 and C of 1e149): the off-diagonal entries move toward their mean size.
                with np.errstate(over="ignore"):
                    A[i], B[i] = np.ldexp(A[i], k), np.ldexp(B[i], k)
                    A[:, i], C[:, i] = np.ldexp(A[:, i], -k), np.ldexp(C[:, i], -k)
                A[i, i] = diagonal
                changed = True
        if not changed:
            break
    return A, B, C, D, frequency


def _svd(M: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    try:
        U, s, Vt = np.linalg.svd(M, full_matrices=True)
    except np.linalg.LinAlgError as failed:
        raise ConvergenceError(
            "transmission_zeros: the singular value decomposition of the system matrix's "
            "blocks did not converge"
        ) from failed
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
    """The finite zeros of the model's pencil.

    With a tolerance given, those of the pencil as given (:func:`_scaled_pencil_zeros`).
    Otherwise those of the pencil equilibrated (:func:`_balance`), where blocks of very
    different sizes are each judged at their own scale (C of 1e9 beside A, B and D of 1: the
    zeros 1e9 and 2e-9), and, beyond the largest zero that the equilibrated pencil resolves
    from infinity, those of the pencil as given (a D that is small only beside the
    equilibrated blocks: A of 1e-8 beside B of 1, C of 1e8 and D of 1 has a zero near 1e8,
    at 1e16 times its poles)."""
    As, Bs, Cs, Ds = (np.array(M, dtype=np.float64) for M in (model.A, model.B, model.C, model.D))
    if tol is not None:
        zeros, rank, _ = _scaled_pencil_zeros(As, Bs, Cs, Ds, 0, tol)
        return _Reduced(_conjugate_clean(zeros), rank)
    A, B, C, D, frequency = _balance(model.A, model.B, model.C, model.D)
    zeros, rank, limit = _scaled_pencil_zeros(A, B, C, D, frequency, None)
    if zeros.size < A.shape[0]:
        more, _, _ = _scaled_pencil_zeros(As, Bs, Cs, Ds, 0, None)
        with np.errstate(over="ignore"):
            beyond = more[np.abs(more) > limit]
        zeros = np.concatenate([zeros, beyond[: A.shape[0] - zeros.size]])
    return _Reduced(_conjugate_clean(zeros), rank)


def _scaled_pencil_zeros(
    A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray, frequency: int, tol: float | None
) -> tuple[ComplexArray, int, float]:
    """(the finite zeros times 2^frequency, the normal rank, the modulus beyond which a zero
    is infinite to the tolerance) of the pencil, scaled to unit size by a power of two 2^e
    (the zeros of (2^-e A, 2^-e B, 2^-e C, 2^-e D) are 2^-e times those of (A, B, C, D),
    exactly), reduced, and its regular part's generalized eigenvalues scaled back."""
    log_size = _log2_norm(A, B, C, D)  # ||S|| itself may overflow (entries near 1e308)
    e = math.floor(log_size) + 1 if math.isfinite(log_size) else 0
    A, B, C, D = (np.ldexp(M, -e) for M in (A, B, C, D))
    size = _frobenius(A, B, C, D)
    tolerance = _tolerance(A, B, C, D) if tol is None else math.ldexp(tol, -e)
    ratio = tolerance / max(size, np.finfo(float).tiny)
    e += frequency
    with np.errstate(over="ignore"):
        limit = float(np.ldexp(1.0 / ratio, e)) if ratio > 0 else math.inf
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
        return np.zeros(0, dtype=np.complex128), rank, limit
    # [C D] W = [0, Df]: W from the QR factorisation of [C D]ᵀ, its null space first.
    Q, _ = np.linalg.qr(np.hstack([C, D]).T, mode="complete")
    W = np.hstack([Q[:, m:], Q[:, :m]])
    Af = np.hstack([A, B]) @ W[:, :n]
    Bf = W[:n, :n]
    zeros = _regular_pencil_zeros(Af, Bf, ratio)
    zeros[np.abs(zeros) <= tolerance] = 0.0  # a zero at the origin, to rounding (a washout)
    zeros = _scaled_by_power_of_two(zeros, e)
    finite_or_warn(zeros, "a transmission zero")
    return zeros, rank, limit


def _scaled_by_power_of_two(values: ComplexArray, exponent: int) -> ComplexArray:
    """values 2^exponent, part by part: a part beyond the range of doubles is ±inf and the
    other keeps its value (not ``real + 1j * imag``, where 1j times an infinite part is
    NaN + inf j: numpy's 'invalid value' warning, and a NaN real part)."""
    scaled = np.empty(values.shape, dtype=np.complex128)
    with np.errstate(over="ignore"):  # a zero beyond the range of doubles is warned of
        scaled.real = np.ldexp(values.real, exponent)
        scaled.imag = np.ldexp(values.imag, exponent)
    return scaled


def _paired(values: ComplexArray, count: int) -> bool:
    """Whether the first ``count`` of ``values`` leave no complex pair split between them and
    the rest."""
    if count <= 0 or count >= len(values):
        return True
    first, rest = values[:count], values[count:]
    return all(np.any(first == np.conj(v)) for v in first if v.imag != 0.0) and all(
        np.any(rest == np.conj(v)) for v in rest if v.imag != 0.0
    )


def _backward_error(Af: FloatArray, Bf: FloatArray, alpha: complex, beta: float) -> float:
    """The relative backward error of the eigenvalue α/β of Af - λBf: σ_min(β Af - α Bf) /
    (|β| ||Af|| + |α| ||Bf||) (Frobenius norms), formed as σ_min(b A' - a B') / (|a| + |b|)
    with A' = Af / ||Af||, B' = Bf / ||Bf||, b = β ||Af||, a = α ||Bf|| scaled to
    max(|a|, |b|) = 1, so that nothing overflows; inf where it cannot be formed."""
    size_a, size_b = _frobenius(Af), _frobenius(Bf)
    unit_a = Af / size_a if size_a > 0.0 else Af
    unit_b = Bf / size_b if size_b > 0.0 else Bf
    with np.errstate(over="ignore", under="ignore"):
        a = alpha / max(abs(alpha), abs(beta), np.finfo(float).tiny)
        b = beta / max(abs(alpha), abs(beta), np.finfo(float).tiny)
        a, b = a * (size_b if size_b > 0.0 else 1.0), b * (size_a if size_a > 0.0 else 1.0)
        largest = max(abs(a), abs(b))
        if not (math.isfinite(largest) and largest > 0.0):
            return math.inf
        a, b = a / largest, b / largest
    try:
        smallest = float(np.linalg.svd(b * unit_a - a * unit_b, compute_uv=False)[-1])
    except np.linalg.LinAlgError:  # LAPACK's SVD failed: no measure, so not chosen
        return math.inf
    return smallest / (abs(a) + abs(b))


def _regular_pencil_zeros(Af: FloatArray, Bf: FloatArray, ratio: float) -> ComplexArray:
    """The finite eigenvalues of the regular pencil Af - λBf (of unit size): the largest from
    the QZ form of Af - λBf, the others from that of the reversed pencil Bf - μAf (λ = 1/μ),
    split where the largest backward error of the chosen eigenvalues is least.

    A zero far beyond the others (a D small beside C B) makes Bf nearly singular. In exact
    arithmetic every eigenvalue is finite (the reduced D is invertible); one with |α| ratio >=
    |β| (ratio = tolerance / ||S||) is infinite to the tolerance: a change of S of the
    tolerance's size moves it to infinity. The core's QZ standardizes a 2 x 2 block through
    H T⁻¹, which loses the small eigenvalue of a block whose T is nearly singular (an absolute
    error of u times the large one), so each eigenvalue is taken from the form in which it is
    among the large ones: of the n + 1 ways to take the k largest of Af - λBf and the n - k
    smallest of the reversed pencil (a complex pair kept together), the one whose worst
    backward error σ_min(β Af - α Bf) / (|β| ||Af|| + |α| ||Bf||) is least."""
    n = Af.shape[0]
    forward, backward = qz(Af, Bf), qz(Bf, Af)
    # Forward: (α, β) of λ = α/β, largest |λ| first; reversed: (β', α') of λ = β'/α',
    # smallest |λ| first (β' >= 0 real, α' complex: the homogeneous pair is (β', α')).
    pairs_forward = sorted(
        zip(forward.alpha, forward.beta, strict=True),
        key=lambda ab: -abs(ab[0]) / max(ab[1], abs(ab[0]), np.finfo(float).tiny),
    )
    pairs_backward = sorted(
        ((complex(b), complex(a)) for a, b in zip(backward.alpha, backward.beta, strict=True)),
        key=lambda ab: abs(ab[0]) / max(abs(ab[1]), abs(ab[0]), np.finfo(float).tiny),
    )

    def value(alpha: complex, beta: complex) -> complex:
        return complex(alpha / beta) if beta != 0 else complex(math.inf)

    large = np.array([value(a, b) for a, b in pairs_forward], dtype=np.complex128)
    small = np.array([value(a, b) for a, b in pairs_backward], dtype=np.complex128)
    errors_large = [_backward_error(Af, Bf, complex(a), abs(b)) for a, b in pairs_forward]
    # The reversed pencil's β' is real and >= 0, α' complex: λ = β'/α' has the homogeneous
    # pair (β'·conj(α')/|α'|, |α'|), of real second entry.
    errors_small = [
        _backward_error(Af, Bf, b * a.conjugate() / abs(a), abs(a))
        if a != 0
        else _backward_error(Af, Bf, 1.0, 0.0)
        for b, a in pairs_backward
    ]
    best, best_error = n, math.inf
    for count in range(n, -1, -1):
        if not (_paired(large, count) and _paired(small, n - count)):
            continue
        worst = max(errors_large[:count] + errors_small[: n - count], default=0.0)
        if worst < best_error:
            best, best_error = count, worst
    infinite = np.array([abs(a) * ratio >= b for a, b in pairs_forward], dtype=bool)
    chosen = np.concatenate([large[:best][~infinite[:best]], small[: n - best]])
    return np.asarray(chosen[np.isfinite(chosen)], dtype=np.complex128)


def _conjugate_clean(roots: ComplexArray) -> ComplexArray:
    """Roots with a negligible imaginary part made real, and sorted (by real part, then
    imaginary part; -inf first and +inf last).

    Negligible is |Im| <= 8 ε max(|Re|, |Im|) (8 ε |root| to rounding, with no modulus to
    overflow), judged of finite roots only: a root with an infinite part (beyond the doubles)
    is kept as computed, since its modulus, and so what is negligible beside it, is unknown.
    (|root| <= inf held for every root with an infinite part, so h (1 + j) beyond the doubles
    became the real h, and 1j * inf had made a NaN real part.)"""
    cleaned = roots.copy()
    parts = np.maximum(np.abs(cleaned.real), np.abs(cleaned.imag))
    tiny = np.isfinite(cleaned) & (np.abs(cleaned.imag) <= 8 * np.finfo(float).eps * parts)
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
        The tolerance of the rank decisions on the system matrix S as given; by default
        (n + p)(n + m) ε ||S||_F of S balanced (scaled by exact powers of two, per state,
        input and output, which leaves the zeros unchanged) so that blocks of very different
        sizes are each judged at their own scale.

    Returns
    -------
    ndarray of complex128
        The finite zeros, sorted by real part, then imaginary part (``numpy.sort_complex``).
        A zero with a part beyond the range of doubles has that part infinite (the other
        part as computed, never NaN), with a NumericalOverflowWarning, and takes its place in
        the same order: a real part of -inf first, +inf last.

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
        with np.errstate(over="ignore"):  # an overflow is warned of below
            parts = np.array([r.real, r.imag])
            coefficients = np.array([1.0, -2.0 * parts[0], float(np.sum(parts * parts))])
        return finite_or_warn(coefficients, "the factor's coefficients")


def _factors(roots: ComplexArray, dt: float) -> list[Factor]:
    """Real roots then pairs, each ordered by increasing |root|."""
    factors: list[Factor] = []
    for r in sorted((r for r in roots if r.imag == 0.0), key=lambda r: (abs(r), r.real)):
        value = float(r.real)
        tau = math.inf if value == 0.0 or dt else 1.0 / abs(value)
        factors.append(Factor((complex(value),), math.nan, abs(value), tau))
    for r in sorted((r for r in roots if r.imag > 0.0), key=lambda r: math.hypot(r.real, r.imag)):
        s = complex(np.log(r)) / dt if dt else complex(r)
        omega = math.hypot(s.real, s.imag)  # inf beyond the doubles (abs raises OverflowError)
        size = max(abs(s.real), abs(s.imag))
        zeta = -(s.real / size) / math.hypot(s.real / size, s.imag / size) if size > 0 else math.nan
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
        # Each zero's factor divided by a pole's, the roots paired by size, so that the
        # partial products stay near the result's size (roots of 1e200: the products of the
        # numerator and of the denominator each overflow, their ratio does not).
        result = np.full(value.shape, complex(self.gain), dtype=np.complex128)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
            zeros = self.zeros[np.argsort(np.abs(self.zeros))]
            poles = self.poles[np.argsort(np.abs(self.poles))]
            for k in range(max(zeros.size, poles.size)):
                if k < zeros.size:
                    result = result * (value - zeros[k])
                if k < poles.size:
                    result = result / (value - poles[k])
        if not np.all(np.isfinite(result)) and np.all(np.isfinite(value)):
            warnings.warn(
                "the result overflowed double precision: G is infinite or NaN (at a pole, or "
                "beyond the doubles)",
                NumericalOverflowWarning,
                stacklevel=2,
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
        with np.errstate(over="ignore"):  # |root| of a root near the overflow threshold
            sizes = np.abs(roots[np.isfinite(roots) & (roots != 0)])
            sizes = sizes[np.isfinite(sizes)]
        # The grid is taken in log10 and kept inside the doubles (a root near 1e308 would
        # otherwise put a candidate at infinity).
        log_centre = float(np.mean(np.log10(sizes))) if sizes.size else 0.0
        exponents = np.clip(log_centre + np.linspace(-1.5, 1.5, 31), -300.0, 307.0)
        candidates = 10.0**exponents
        points = 1j * candidates
    if roots.size == 0:
        best = len(candidates) // 2
    else:
        # Relative distances, computed after a power-of-two scaling by the largest candidate so
        # that a difference of two numbers near 1e308 stays finite; a root so far away that its
        # scaled difference still overflows is infinitely far (inf, never nan, for ranking).
        scale = 2.0 ** -math.frexp(float(np.max(np.abs(points))))[1]
        with np.errstate(over="ignore", invalid="ignore"):
            distance = np.min(
                np.abs(points[:, None] * scale - roots[None, :] * scale)
                / np.maximum(np.abs(points[:, None]) * scale, 1e-300),
                axis=1,
            )
        distance = np.nan_to_num(distance, nan=np.inf)
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


def _scaled_response(channel: StateSpace, omega: float, dt: float) -> tuple[complex, int]:
    """(g, k) with G(jω) = 2^k g (G(e^{jω dt}) for a discrete model): the response of the model
    with C and D divided by the power of two of the largest of them, and B and D by that of
    the largest of B and the scaled D, so that large B and C (1e149) at a point near tiny
    poles (1e-300) do not overflow where G does not in scaled form."""
    A, B, C, D = channel.A, channel.B, channel.C, channel.D
    # The dynamic part C (jωI - A)^-1 B with C and B each scaled to unit size, and D added
    # afterwards at a common power of two: scaling D with C (C of 1e299 beside D of 1e-151)
    # underflowed D to 0 and gave a zero gain for G = D.
    k_out = int(_exponents(np.array([float(np.abs(C).max(initial=0.0))]))[0])
    k_in = int(_exponents(np.array([float(np.abs(B).max(initial=0.0))]))[0])
    with warnings.catch_warnings():
        # An overflow of the scaled response is warned of by _gain, as the gain's.
        warnings.simplefilter("ignore", NumericalOverflowWarning)
        dynamic = _core.frequency_response(
            A,
            np.ldexp(B, -k_in),
            np.ldexp(C, -k_out),
            np.zeros((1, 1)),
            np.array([omega]),
            dt or None,
        )
    r, e = complex(dynamic[0, 0, 0]), k_out + k_in
    d = float(D[0, 0])
    if d == 0.0 or not (math.isfinite(r.real) and math.isfinite(r.imag)):
        return r, e
    size_r = math.frexp(max(abs(r.real), abs(r.imag)))[1] + e if r != 0 else -(10**9)
    common = max(math.frexp(d)[1], size_r)
    g = complex(
        math.ldexp(d, -common) + math.ldexp(r.real, e - common), math.ldexp(r.imag, e - common)
    )
    return g, common


def _gain(
    response: complex, exponent: int, point: complex, zeros: ComplexArray, poles: ComplexArray
) -> float:
    """K = G(point) Π(point - p_j) / Π(point - z_i), with G(point) = 2^exponent response, as
    the exponential of a sum of logarithms:
    the products of many large (or small) factors overflow (or underflow) where K does not
    (1/(s + 1e-151) + 1/(s + 2e-151) + 1/(s + 3e-151) is 3/s: K = 3 from products of sizes
    1e-302 and 1e-453). A K beyond the range of doubles is infinite, with a warning."""
    if response == 0.0:
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        terms = np.concatenate([[np.log(response)], np.log(point - poles), -np.log(point - zeros)])
    if not np.all(np.isfinite(terms)):  # G(point) overflowed even scaled
        gain = math.inf
        finite_or_warn(np.array([gain]), "the gain")
        return gain
    log_size = float(np.sum(terms.real)) + exponent * math.log(2.0)
    phase = float(np.sum(terms.imag))
    with np.errstate(over="ignore"):
        gain = float(np.exp(log_size) * math.cos(phase))
    finite_or_warn(np.array([gain]), "the gain")
    return gain


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
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is warned of below
        denominator = np.real(np.poly(poles)) if poles.size else np.ones(1)
    finite_or_warn(denominator, "the denominator det(sI - A)")
    if reduced.normal_rank == 0:
        zeros = np.zeros(0, np.complex128)
        gain = 0.0
        numerator = np.zeros(1)
    else:
        zeros = reduced.zeros
        omega, point = _evaluation_point(np.concatenate([zeros, poles]), dt)
        response, exponent = _scaled_response(channel, omega, dt)
        gain = _gain(response, exponent, point, zeros, poles)
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is warned of below
            numerator = gain * np.real(np.poly(zeros)) if zeros.size else np.array([gain])
        finite_or_warn(numerator, "the numerator")
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
