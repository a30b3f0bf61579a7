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
(s² + 2ζωs + ω²) factors. :func:`transfer_matrix` gives every channel of a model in one call.

Two paths compute a channel. The core's fast path (``rust/control/transfer.rs``) takes the
same steps in doubles (the equilibration, the reduction by Householder reflections, the gain
confirmed at a point of a second grid) and hands back every channel where its rank decisions
lie near the tolerance, a zero lies far beyond the system's scale, an entry lies beyond
2^±250 or its check fails; the reference path here then computes it, every product held as
a mantissa and a power of two.

References
----------
A. Emami-Naeini and P. Van Dooren, "Computation of zeros of linear multivariable systems",
Automatica 18(4), 415-430, 1982. P. Misra, P. Van Dooren and A. Varga, "Computation of
structural invariants of generalized state-space systems", Automatica 30(12), 1921-1936, 1994
(the rank tolerance).
"""

from __future__ import annotations

import cmath
import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, cast

import numpy as np
from numpy.typing import NDArray

from . import _core
from ._results import Result, Tabular, register
from ._validation import FloatArray, complex_array, finite_or_warn, real_scalar
from .exceptions import (
    ConvergenceError,
    IllConditionedWarning,
    InvalidArgumentError,
    NumericalOverflowWarning,
    NumericalUnderflowWarning,
)
from .linalg import qz
from .statespace import StateSpace, as_state_space, period, signal_indices

if TYPE_CHECKING:
    from ._typing import SignalSelection, System

__all__ = [
    "Factor",
    "TransferFunction",
    "TransferMatrix",
    "transfer_function",
    "transfer_matrix",
    "transmission_zeros",
]

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


def _log2_norm(*vectors: FloatArray) -> float:
    """log2 of the 2-norm of the vectors joined, without overflow or underflow; -inf for zero."""
    largest = max((float(np.max(np.abs(v), initial=0.0)) for v in vectors), default=0.0)
    if largest == 0.0:
        return -math.inf
    total = sum(float(np.sum(np.square(v / largest))) for v in vectors)
    return math.log2(largest) + 0.5 * math.log2(total)


def _log2_sizes(M: FloatArray) -> FloatArray:
    """log2 |M| entry by entry, -inf for a zero entry."""
    with np.errstate(divide="ignore"):
        return np.asarray(np.log2(np.abs(M)), dtype=np.float64)


def _log2_norm_of_logs(*logs: FloatArray) -> float:
    """log2 of the 2-norm of the entries whose log2 sizes are given (-inf for zero
    entries), without forming the entries: log2 sqrt(sum 4^l)."""
    values = np.concatenate([np.ravel(v) for v in logs]) if logs else np.zeros(0)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return -math.inf
    largest = float(np.max(values))
    return largest + 0.5 * math.log2(float(np.sum(np.exp2(2.0 * (values - largest)))))


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
    The scalings are kept as exponents (of the outputs, the inputs, the states and the unit
    of frequency), the norms formed from the logarithms of the entries plus those exponents
    (no overflow, no underflow), and the scalings applied once at the end with ``np.ldexp``,
    exactly: applied step by step, an entry that a later sweep brings back can underflow on
    the way.

    References: D. Ruiz, "A scaling algorithm to equilibrate both rows and columns norms in
    matrices", RAL-TR-2001-034, 2001; E. E. Osborne, J. ACM 7, 338-345, 1960."""
    n, p, m = A.shape[0], C.shape[0], B.shape[1]
    A, B, C, D = (np.asarray(M, dtype=np.float64) for M in (A, B, C, D))
    # The scalings are kept as exponents and applied once at the end: applied step by step,
    # an entry that a later sweep brings back could underflow on the way (B of 1 beside A of
    # 1e300 and C of 1e-300 lost an entry of B to 0, though the product of B and C, which no
    # state scaling changes, matters to the zero near 3e300, which moved to 9e298).
    logs = [_log2_sizes(M) for M in (A, B, C, D)]
    state = np.zeros(n, dtype=np.int64)  # row i of [A B] by 2^t_i, column i of [A; C] by 2^-t_i
    outputs = np.zeros(p, dtype=np.int64)
    inputs = np.zeros(m, dtype=np.int64)
    frequency = 0  # A and B by 2^-frequency

    def exponents() -> tuple[NDArray[np.int64], ...]:
        return (
            state[:, None] - state[None, :] - frequency,
            state[:, None] + inputs[None, :] - frequency,
            outputs[:, None] - state[None, :],
            outputs[:, None] + inputs[None, :],
        )

    for _ in range(40):
        changed = False
        eA, eB, eC, eD = exponents()
        for i in range(p):
            k = _half_exponent(_log2_norm_of_logs(logs[2][i] + eC[i], logs[3][i] + eD[i]))
            if k:
                outputs[i] += k
                eC[i] += k
                eD[i] += k
                changed = True
        for j in range(m):
            k = _half_exponent(
                _log2_norm_of_logs(logs[1][:, j] + eB[:, j], logs[3][:, j] + eD[:, j])
            )
            if k:
                inputs[j] += k
                eB[:, j] += k
                eD[:, j] += k
                changed = True
        # The unit of frequency: A of unit norm (the poles near 1), else the rows of B.
        size = _log2_norm_of_logs(logs[0] + eA)
        if not math.isfinite(size):
            size = _log2_norm_of_logs(logs[1] + eB) if n else -math.inf
        k = _half_exponent(size)
        if k:
            frequency -= k
            changed = True
        eA, eB, eC, eD = exponents()
        for i in range(n):
            others = np.arange(n) != i
            r = _log2_norm_of_logs(logs[0][i, others] + eA[i, others], logs[1][i] + eB[i])
            c = _log2_norm_of_logs(logs[0][others, i] + eA[others, i], logs[2][:, i] + eC[:, i])
            if not (math.isfinite(r) and math.isfinite(c)):
                continue
            k = round((c - r) / 2)
            if k:
                state[i] += k
                eA[i, others] += k
                eA[others, i] -= k
                eB[i] += k
                eC[:, i] -= k
                changed = True
        if not changed:
            break
    eA, eB, eC, eD = exponents()
    np.fill_diagonal(eA, -frequency)
    # Entries far below the others (negligible beside the tolerance) may underflow here; only
    # the diagonal of A can overflow (A of 1e308 beside B of 1e-151 and C of 1e149: the
    # off-diagonal entries move toward their mean size), and is warned of by the zeros.
    with np.errstate(over="ignore", under="ignore"):
        return np.ldexp(A, eA), np.ldexp(B, eB), np.ldexp(C, eC), np.ldexp(D, eD), frequency


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
    given = (A, B, C, D)
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
    near = np.abs(zeros) <= tolerance
    # At the caller's tolerance, a zero within it is the origin (the caller's rank decision).
    if np.any(near) and (tol is not None or _singular_at_origin(*given)):
        zeros[near] = 0.0  # a zero at the origin, to rounding (a washout)
    zeros = _scaled_by_power_of_two(zeros, e)
    finite_or_warn(zeros, "a transmission zero")
    return zeros, rank, limit


#: Multiples of (n + m) u within which the smallest singular value of the equilibrated system
#: matrix at the origin makes it singular (:func:`_singular_at_origin`).
ORIGIN_SINGULARITY = 100.0


def _singular_at_origin(A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray) -> bool:
    """Whether the system matrix at the origin, S0 = [[A, B], [C, D]], loses rank there: for a
    square model, S0 singular to rounding once each row and then each column is scaled by a
    power of two to largest magnitude 1 (as LAPACK's DGEEQU), σ_min <= 100 (n + m) u σ_max. A
    computed zero within the rank tolerance of the origin is the origin only then (a washout's,
    computed as 1e-17); otherwise it is a zero at the scale of small poles beside large ones,
    which the pencil scaled to the large ones puts below its tolerance: 1/(s + 1) +
    1e15/(s + 1e15) has the zero -2, which was returned as 0. The core's fast path
    (``singular_at_origin`` in ``rust/control/transfer.rs``) makes the same decision from the
    pivots of complete-pivoting LU (σ_min <= (n + 1) min |u_ii|), at a fraction of the cost. A
    non-square model (whose zeros are rank drops below the normal rank) keeps the rank
    tolerance alone."""
    if B.shape[1] != C.shape[0]:
        return True
    S0 = np.block([[A, B], [C, D]])
    with np.errstate(over="ignore", under="ignore"):
        _, rows = np.frexp(np.max(np.abs(S0), axis=1, initial=0.0))
        S0 = np.ldexp(S0, -rows[:, None])
        _, columns = np.frexp(np.max(np.abs(S0), axis=0, initial=0.0))
        S0 = np.ldexp(S0, -columns[None, :])
    if not np.all(np.isfinite(S0)):
        return True
    sigma = np.linalg.svd(S0, compute_uv=False)
    size = S0.shape[0]
    return bool(sigma[-1] <= ORIGIN_SINGULARITY * size * np.finfo(float).eps * sigma[0])


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


def _unmatched(taken: ComplexArray, pool: ComplexArray) -> NDArray[np.int64]:
    """The indices (in order) of the values of ``pool`` left when each value of ``taken``, in
    turn, removes the nearest one left (by relative distance; an infinite value is nearest
    an infinite one)."""
    left = list(range(pool.size))
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for value in taken:
            if not left:
                break
            candidates = pool[left]
            if not cmath.isfinite(value):
                distance = np.where(np.isfinite(candidates), np.inf, 0.0)
            else:
                size = np.maximum(np.maximum(np.abs(candidates), abs(value)), 1e-300)
                distance = np.nan_to_num(np.abs(candidates - value) / size, nan=np.inf)
            left.pop(int(np.argmin(distance)))
    return np.array(left, dtype=np.int64)


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


def _modulus_ratio(numerator: complex, denominator: complex) -> float:
    """|numerator / denominator| (inf beyond the doubles, and for a zero denominator; 0 for
    0/0, a singular pair, which sorts among the smallest)."""
    top, bottom = np.float64(abs(numerator)), np.float64(abs(denominator))
    if bottom == 0.0:
        return math.inf if top else 0.0
    with np.errstate(over="ignore", under="ignore"):
        return float(top / bottom)


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
    # By |λ| itself (inf for a zero denominator): a key bounded by 1 (|α| / max(β, |α|))
    # tied every |λ| >= 1 of the forward form, which then kept the QZ's order, and the same
    # eigenvalue could be taken from both forms (zeros -5 and 76 of a balanced pencil came
    # back as -5 twice).
    pairs_forward = sorted(
        zip(forward.alpha, forward.beta, strict=True),
        key=lambda ab: -_modulus_ratio(complex(ab[0]), complex(ab[1])),
    )
    pairs_backward = sorted(
        ((complex(b), complex(a)) for a, b in zip(backward.alpha, backward.beta, strict=True)),
        key=lambda ab: _modulus_ratio(ab[0], ab[1]),
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
    best, best_error, best_rest = n, math.inf, np.zeros(0, dtype=np.int64)
    for count in range(n, -1, -1):
        # The reversed form's eigenvalues other than the count largest: those left when each
        # of the forward form's count largest has taken its nearest (by moduli alone, ties
        # such as ±1.02 were split differently in the two forms, and 1.02 came back twice).
        rest = _unmatched(large[:count], small)
        if not (_paired(large, count) and _paired(small[rest], rest.size)):
            continue
        worst = max(errors_large[:count] + [errors_small[k] for k in rest], default=0.0)
        if worst < best_error:
            best, best_error, best_rest = count, worst, rest
    infinite = np.array([abs(a) * ratio >= b for a, b in pairs_forward], dtype=bool)
    chosen = np.concatenate([large[:best][~infinite[:best]], small[best_rest]])
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

    Raises
    ------
    InvalidArgumentError
        ``tol`` is negative or not finite.
    NotRealError
        ``sys`` is not a model, or a matrix is complex.
    NonFiniteError, ShapeError
        A matrix contains NaN or an infinity, or the matrices disagree in size.

    Warns
    -----
    NumericalOverflowWarning
        A zero has a part beyond the range of doubles.

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
    (s² + 2ζω s + ω²) (in z for a discrete model).

    Attributes
    ----------
    roots : tuple of complex
        One real root, or the pair (Im > 0 first).
    zeta : float
        Damping ratio of a pair (for a discrete model: of s = ln(z)/dt); NaN for a real root.
    omega : float
        ω of a pair (rad/s; for a discrete model of s = ln(z)/dt); abs(root) for a real one.
    time_constant : float
        T of a real root -1/T (s; continuous only): 1/abs(root), inf for a root at 0; NaN for a
        pair.
    coefficients : ndarray (2,) or (3,)
        The monic factor, highest power first.

    Examples
    --------
    The poles of 5/((s + 1)(s² + 2s + 5)): a real root at -1 and a pair of ω = √5, ζ = 1/√5:

    >>> import numpy as np, aerocontrol
    >>> g = aerocontrol.transfer_function(aerocontrol.zpk([], [-1, -1 + 2j, -1 - 2j], 5.0), 0, 0)
    >>> real, pair = g.pole_factors
    >>> real.time_constant, real.coefficients
    (1.0, array([1., 1.]))
    >>> round(pair.zeta, 6), round(pair.omega, 6), np.round(pair.coefficients, 6)
    (0.447214, 2.236068, array([1., 2., 5.]))
    """

    roots: tuple[complex, ...]
    """One real root, or the pair (Im > 0 first)."""
    zeta: float
    """Damping ratio of a pair (for a discrete model: of s = ln(z)/dt); NaN for a real root."""
    omega: float
    """ω of a pair (rad/s; for a discrete model of s = ln(z)/dt); abs(root) for a real one."""
    time_constant: float
    """T of a real root -1/T (s; continuous only): 1/abs(root), inf for a root at 0."""

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
class TransferFunction(Result):
    """One channel G(s) = K Π(s - z_i)/Π(s - p_j) of a model (in z for a discrete model).

    ``print(tf)`` shows the factored "aircraft" form, (s + 1/T) for a real root -1/T and
    (s² + 2(ζ)(ω)s + (ω)²) for a pair, as flight dynamics texts print a numerator N(s) over
    the characteristic polynomial Δ(s).

    Attributes
    ----------
    numerator : ndarray (m + 1,)
        K Π(s - z_i), highest power first.
    denominator : ndarray (n + 1,)
        det(sI - A) = Π(s - p_j), monic, highest power first.
    zeros : ndarray (m,), complex
        The finite zeros of the channel's pencil, sorted.
    poles : ndarray (n,), complex
        The eigenvalues of A (all n), sorted.
    gain : float
        K, the leading coefficient of the numerator (the high-frequency gain over s^(n - m)).
    dt : float
        0.0 for a continuous model, else the sampling period in seconds.
    output_name, input_name : str
        The channel's output and input.
    scaled_gain : tuple of (float, int), or None
        K as (mantissa, exponent), K = mantissa 2^exponent, where K itself lies beyond the
        doubles (``gain`` is then infinite); None when ``gain`` is K.
    variable : str
        "s", or "z" for a discrete model.
    zero_factors, pole_factors : list of Factor
        The numerator's and the denominator's factors: real roots by modulus, then pairs by ω.

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> g = aerocontrol.transfer_function(aerocontrol.zpk([-3.0], [-1.0, -2.0], 2.0), 0, 0)
    >>> np.round(g.numerator, 12), g.denominator                  # 2 (s + 3) / (s² + 3s + 2)
    (array([2., 6.]), array([1., 3., 2.]))
    >>> print(g)
    y0/u0(s) = 2 (s + 3) / (s + 1)(s + 2)
      zero -3 T = 0.3333 s
      pole -1 T = 1 s
      pole -2 T = 0.5 s
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
    scaled_gain: tuple[float, int] | None = field(default=None, repr=False)
    """K as (mantissa, exponent), K = mantissa 2^exponent, where K itself lies beyond the
    doubles (``gain`` is then infinite): calling the function, ``G(s)``, evaluates G from it.
    None when ``gain`` is K."""

    @property
    def variable(self) -> str:
        """ "s", or "z" for a discrete model."""
        return "z" if self.dt else "s"

    @property
    def zero_factors(self) -> list[Factor]:
        """The numerator's factors: real zeros by abs(z), then pairs by ω."""
        return _factors(self.zeros, self.dt)

    @property
    def pole_factors(self) -> list[Factor]:
        """The denominator's factors: real poles by abs(p), then pairs by ω."""
        return _factors(self.poles, self.dt)

    def __call__(self, s: complex | ComplexArray) -> complex | ComplexArray:
        """G at ``s`` (or at z for a discrete model), from the factored form.

        K Π(s - z_i) / Π(s - p_j) is formed as a mantissa and a power of two, renormalised
        after each factor (a zero's, then a pole's, by increasing modulus), and scaled once
        at the end: roots of 1e200 make the products of the numerator and of the denominator
        overflow where their ratio does not, and a K of 1e450 beside poles of 1e150 gives a
        G of 1e300. A G beyond the doubles is infinite, with a NumericalOverflowWarning; one
        below them rounds to 0 (or a subnormal), as a product of doubles does."""
        value = complex_array(s, "s")
        k, e = self.scaled_gain if self.scaled_gain is not None else math.frexp(self.gain)
        result, finite = _core.factored_response(
            [float(k)],
            [int(e)],
            [np.asarray(self.zeros, dtype=np.complex128).reshape(-1)],
            np.asarray(self.poles, dtype=np.complex128).reshape(-1),
            value,
            value.shape,
        )
        if not finite and np.isfinite(value).all():
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

    def _cells(self) -> list[tuple[str, str, str]]:
        """(zero or pole, root, its time constant or ζ and ω) per factor, as text."""
        rows = []
        for what, factors in (("zero", self.zero_factors), ("pole", self.pole_factors)):
            for f in factors:
                if len(f.roots) == 1:
                    tau = f"T = {f.time_constant:.4g} s" if math.isfinite(f.time_constant) else ""
                    rows.append((what, f"{f.roots[0].real:.6g}", tau))
                else:
                    r = f.roots[0]
                    rows.append(
                        (
                            f"{what}s",
                            f"{r.real:.6g} ± {r.imag:.6g}j",
                            f"zeta = {f.zeta:.4g}, omega = {f.omega:.4g} rad/s",
                        )
                    )
        return rows

    def __str__(self) -> str:
        lines = [f"{self.output_name}/{self.input_name}({self.variable}) = {self.aircraft_form()}"]
        for what, root, detail in self._cells():
            separator = ":" if what.endswith("s") else ""
            lines.append(f"  {what} {root}{separator} {detail}".rstrip())
        return "\n".join(lines)

    def _tables(self) -> list[Tabular]:
        title = f"{self.output_name}/{self.input_name}({self.variable}) = {self.aircraft_form()}"
        return [Tabular(title, ("factor", "root", "characteristics"), self._cells())]


def _evaluation_points(
    roots: ComplexArray, dt: float, centre: float | None = None
) -> list[complex]:
    """Points s = jω (z = e^{jω dt}) ranked by their relative distance to the nearest root,
    farthest first: 31 frequencies over three decades around the roots' sizes (around
    10^centre when given), or 19 angles of the unit circle for a discrete model."""
    if dt:
        candidates = np.linspace(0.05, 0.95, 19) * math.pi / dt
        points = np.exp(1j * candidates * dt)
    else:
        if centre is None:
            with np.errstate(over="ignore"):  # |root| of a root near the overflow threshold
                sizes = np.abs(roots[np.isfinite(roots) & (roots != 0)])
                sizes = sizes[np.isfinite(sizes)]
            centre = float(np.mean(np.log10(sizes))) if sizes.size else 0.0
        # The grid is taken in log10 and kept inside the doubles (a root near 1e308 would
        # otherwise put a candidate at infinity).
        exponents = np.clip(centre + np.linspace(-1.5, 1.5, 31), -300.0, 307.0)
        candidates = 10.0**exponents
        points = 1j * candidates
    if roots.size == 0:
        middle = len(candidates) // 2
        return [complex(p) for p in np.roll(points, -middle)]
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
    return [complex(points[k]) for k in np.argsort(-distance, kind="stable")]


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


def _renormalized(values: ComplexArray, exponents: NDArray[np.int64]) -> None:
    """Bring each complex value to a largest part in [1/2, 1) by a power of two, in place,
    adding that power to its exponent (a zero or non-finite value is left as it is)."""
    parts = np.maximum(np.abs(values.real), np.abs(values.imag))
    _, e = np.frexp(parts)
    e = np.where((parts > 0.0) & np.isfinite(parts), e, 0).astype(np.int64)
    values.real, values.imag = np.ldexp(values.real, -e), np.ldexp(values.imag, -e)
    exponents += e


def _scaled_differences(points: ComplexArray, root: complex) -> tuple[ComplexArray, int]:
    """(d, q) with points - root = 2^q d, formed after scaling both by 2^-q, q the exponent
    of the largest part among them: the difference of two numbers near ±1e308 stays finite."""
    largest = max(
        float(np.max(np.abs(points.real), initial=0.0)),
        float(np.max(np.abs(points.imag), initial=0.0)),
        abs(root.real),
        abs(root.imag),
    )
    q = math.frexp(largest)[1] if 0.0 < largest < math.inf else 0
    scaled_points = _scaled_by_power_of_two(points, -q)
    scaled_root = _scaled_by_power_of_two(np.array([root]), -q)[0]
    with np.errstate(invalid="ignore", over="ignore"):  # an infinite root: warned of by callers
        return scaled_points - scaled_root, q


def _scaled_factored(
    mantissa: ComplexArray,
    exponent: NDArray[np.int64],
    points: ComplexArray,
    multiply: ComplexArray,
    divide: ComplexArray,
) -> tuple[ComplexArray, NDArray[np.int64]]:
    """(m, e) with m 2^e = mantissa 2^exponent Π(points - multiply_i) / Π(points - divide_j)
    at each point, the product renormalised after every factor (each factor's difference
    itself formed scaled, :func:`_scaled_differences`), so that nothing overflows or
    underflows where the result, as a mantissa and a power of two, is exact to (2 k + 1) u
    for k factors. The roots are taken by increasing modulus, a zero's factor then a pole's."""
    m = np.array(mantissa, dtype=np.complex128)
    e = np.array(exponent, dtype=np.int64)
    _renormalized(m, e)
    with np.errstate(over="ignore"):
        multiply = multiply[np.argsort(np.abs(multiply))]
        divide = divide[np.argsort(np.abs(divide))]
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        for k in range(max(multiply.size, divide.size)):
            if k < multiply.size:
                d, q = _scaled_differences(points, complex(multiply[k]))
                m = m * d
                e = e + q
                _renormalized(m, e)
            if k < divide.size:
                d, q = _scaled_differences(points, complex(divide[k]))
                m = m / d
                e = e - q
                _renormalized(m, e)
    return m, e


def _scaled_poly(roots: ComplexArray, mantissa: float, exponent: int) -> FloatArray:
    """mantissa 2^exponent Π(s - root), coefficients highest power first, formed with the
    roots scaled by 2^-q (q the exponent of the largest part of a root) and coefficient k
    scaled back by 2^(q k) once: the polynomial of roots near 1e200 (or 1e-200) has
    coefficients beyond (or below) the doubles only where the coefficient itself is, and a
    gain of 1e-300 with zeros of 1e200 has a finite numerator."""
    if roots.size == 0:
        with np.errstate(over="ignore"):
            return np.array([np.ldexp(mantissa, exponent)])
    largest = max(float(np.max(np.abs(roots.real))), float(np.max(np.abs(roots.imag))))
    if not math.isfinite(largest):
        with np.errstate(over="ignore", invalid="ignore"):
            coefficients = np.real(np.poly(roots)) * mantissa
            return np.asarray(np.ldexp(coefficients, exponent), dtype=np.float64)
    q = math.frexp(largest)[1] if largest > 0.0 else 0
    powers = exponent + q * np.arange(roots.size + 1)
    with np.errstate(over="ignore", invalid="ignore"):  # an infinite gain: warned of by callers
        coefficients = np.real(np.poly(_scaled_by_power_of_two(roots, -q))) * mantissa
        return np.asarray(np.ldexp(coefficients, powers), dtype=np.float64)


def _scaled_sum(
    mantissas: ComplexArray, exponents: NDArray[np.int64], axis: int
) -> tuple[ComplexArray, NDArray[np.int64]]:
    """The sums along ``axis`` of the values mantissa 2^exponent, each as a renormalised
    mantissa and a power of two: the terms are brought to the exponent of the largest
    (those far below it lose their low bits, as in floating-point addition) and added."""
    nonzero = mantissas != 0
    common = np.max(np.where(nonzero, exponents, np.iinfo(np.int64).min), axis=axis)
    common = np.where(np.any(nonzero, axis=axis), common, 0)
    shift = np.where(nonzero, exponents - np.expand_dims(common, axis), 0)
    aligned = np.empty(mantissas.shape, dtype=np.complex128)
    with np.errstate(under="ignore"):
        aligned.real, aligned.imag = (
            np.ldexp(mantissas.real, shift),
            np.ldexp(mantissas.imag, shift),
        )
    total = np.asarray(np.sum(aligned, axis=axis), dtype=np.complex128)
    power = np.asarray(common, dtype=np.int64)
    _renormalized(total, power)
    return total, power


def _scaled_solve(
    M: ComplexArray, b: ComplexArray
) -> tuple[ComplexArray, NDArray[np.int64]] | None:
    """The solution of M x = b by Gaussian elimination with partial pivoting, every value
    held as a mantissa (largest part in [1/2, 1)) and a power of two of its own: the
    rounding of each operation is that of double precision (backward stable as LAPACK's
    LU), and nothing overflows or underflows, whatever the spread of the solution's entries
    (a chain of couplings of 1e-200 makes them 1, 1e-200, 1e-400, ...). None if a pivot is
    zero (M singular)."""
    n = M.shape[0]
    m = np.array(M, dtype=np.complex128)
    e = np.zeros(m.shape, dtype=np.int64)
    _renormalized(m, e)
    bm = np.array(b, dtype=np.complex128)
    be = np.zeros(bm.shape, dtype=np.int64)
    _renormalized(bm, be)
    for k in range(n):
        parts = np.maximum(np.abs(m[k:, k].real), np.abs(m[k:, k].imag))
        if not np.any(parts):
            return None
        with np.errstate(divide="ignore"):
            size = np.where(parts > 0.0, e[k:, k] + np.log2(parts), -np.inf)
        pivot = k + int(np.argmax(size))
        for a in (m, e):
            a[[k, pivot]] = a[[pivot, k]]
        for a in (bm, be):
            a[[k, pivot]] = a[[pivot, k]]
        if k == n - 1:
            break
        lm = m[k + 1 :, k] / m[k, k]
        le = e[k + 1 :, k] - e[k, k]
        _renormalized(lm, le)
        # Row i ← row i - l_i row k, on the columns after k and on b.
        product_m = -lm[:, None] * m[k, k + 1 :][None, :]
        product_e = le[:, None] + e[k, k + 1 :][None, :]
        stacked_m = np.stack([m[k + 1 :, k + 1 :], product_m])
        stacked_e = np.stack([e[k + 1 :, k + 1 :], product_e])
        m[k + 1 :, k + 1 :], e[k + 1 :, k + 1 :] = _scaled_sum(stacked_m, stacked_e, 0)
        m[k + 1 :, k], e[k + 1 :, k] = 0.0, 0
        stacked_m = np.stack([bm[k + 1 :], -lm * bm[k]])
        stacked_e = np.stack([be[k + 1 :], le + be[k]])
        bm[k + 1 :], be[k + 1 :] = _scaled_sum(stacked_m, stacked_e, 0)
    xm = np.zeros(n, dtype=np.complex128)
    xe = np.zeros(n, dtype=np.int64)
    for i in range(n - 1, -1, -1):
        terms_m = np.concatenate([[bm[i]], -m[i, i + 1 :] * xm[i + 1 :]])
        terms_e = np.concatenate([[be[i]], e[i, i + 1 :] + xe[i + 1 :]])
        total_m, total_e = _scaled_sum(terms_m, terms_e, 0)
        value = np.array([complex(total_m) / m[i, i]])
        power = np.array([int(total_e) - int(e[i, i])], dtype=np.int64)
        _renormalized(value, power)
        xm[i], xe[i] = value[0], power[0]
    return xm, xe


def _scaled_response(channel: StateSpace, point: complex) -> tuple[complex, int] | None:
    """(g, k) with G(point) = 2^k g, g of largest part in [1/2, 1) (or 0), for a channel
    G(s) = C (sI - A)⁻¹ B + D (s = z for a discrete model): (point I - A) x = B solved with
    every value as a mantissa and a power of two (:func:`_scaled_solve`), C x summed
    likewise, and D added at the common power of two. G is then exact to the rounding of a
    backward stable solve wherever it, as a mantissa and a power of two, is: the dynamic part
    of a chain of integrators with couplings of 1e-200, and B and C of 1e100 and 1e200, is
    1e-100 where its solution in doubles passes through 1e-400 (0); a D of 1e-151 beside a
    C of 1e299 is not lost to the scaling of C. None where point I - A is singular to
    working precision (a zero pivot): G cannot be evaluated there (its value is not D)."""
    A, B, C, D = channel.A, channel.B, channel.C, channel.D
    n = A.shape[0]
    terms_m = np.array([complex(D[0, 0])])
    terms_e = np.zeros(1, dtype=np.int64)
    if n and np.any(B) and np.any(C):
        M = np.asarray(point * np.eye(n) - A, dtype=np.complex128)
        solution = _scaled_solve(M, B[:, 0].astype(np.complex128))
        if solution is None:
            return None
        xm, xe = solution
        cm = C[0].astype(np.complex128)
        ce = np.zeros(n, dtype=np.int64)
        _renormalized(cm, ce)
        terms_m = np.concatenate([terms_m, cm * xm])
        terms_e = np.concatenate([terms_e, ce + xe])
    _renormalized(terms_m, terms_e)
    total_m, total_e = _scaled_sum(terms_m, terms_e, 0)
    return complex(total_m), int(total_e)


def _gain(
    response: complex, exponent: int, point: complex, zeros: ComplexArray, poles: ComplexArray
) -> tuple[float, int]:
    """(k, e) with the gain K = 2^e k = G(point) Π(point - p_j) / Π(point - z_i), G(point) =
    2^exponent response, as a mantissa and a power of two (:func:`_scaled_factored`): the
    products of many large (or small) factors overflow (or underflow) where K does not
    (1/(s + 1e-151) + 1/(s + 2e-151) + 1/(s + 3e-151) is 3/s: K = 3 from products of sizes
    1e-302 and 1e-453), and K itself may lie beyond the doubles where G does not. K is real:
    the imaginary part of the product is rounding. (inf, 0) where a root is beyond the
    doubles."""
    if response == 0.0:
        return 0.0, 0
    m, e = _scaled_factored(
        np.array([response]), np.array([exponent]), np.array([point]), poles, zeros
    )
    mantissa = float(m[0].real)
    if not math.isfinite(mantissa):
        return math.inf, 0
    fraction, shift = math.frexp(mantissa)
    return fraction, int(e[0]) + shift


def _roots_and_gain(channel: StateSpace) -> tuple[ComplexArray, ComplexArray, float, int]:
    """(poles, zeros, k, e) of a single-input, single-output channel G = K Π(s - z)/Π(s - p)
    (in z for a discrete model) with K = k 2^e as a mantissa and a power of two, exact where
    K itself is beyond the doubles; (poles, no zeros, 0, 0) for a zero channel.

    The poles are the eigenvalues of A, the zeros those of the channel's pencil; K = D where
    D is nonzero (G -> D as s -> inf: evaluated at a point, K carried the zeros' rounding,
    1e-10 for zeros at 1 and 1e-149 beside poles at 1e-150), else G at a point away from every
    root times Π(point - p)/Π(point - z), each factor renormalised (:func:`_gain`)."""
    poles = (
        _conjugate_clean(_core.eigenvalues(channel.A))
        if channel.n_states
        else np.zeros(0, np.complex128)
    )
    reduced = _pencil_zeros(channel, None)
    d = float(channel.D[0, 0])
    if d != 0.0 and reduced.zeros.size == channel.n_states:
        mantissa, exponent = math.frexp(d)
        return poles, reduced.zeros, mantissa, exponent
    if reduced.normal_rank == 0:
        return poles, np.zeros(0, np.complex128), 0.0, 0
    mantissa, exponent = _verified_gain(channel, reduced.zeros, poles)
    if mantissa == 0.0:
        return poles, np.zeros(0, np.complex128), 0.0, 0
    return poles, reduced.zeros, mantissa, exponent


def _verified_gain(
    channel: StateSpace, zeros: ComplexArray, poles: ComplexArray
) -> tuple[float, int]:
    """K (as a mantissa and a power of two) of a channel of normal rank 1 (G not identically
    zero) from G at the point of the grid around the roots farthest from them, confirmed by G
    at the first point of another grid (to 1e-6, relative; for a discrete model, whose one
    grid is the unit circle, at its next point): where G at the first point cannot be computed
    accurately, the points of the grids around ||A|| and around 1 are tried. Poles at the
    origin beside a double zero that rounding split to ±1e-9 put every point of the first
    grid near 1e-9, where the terms of C (sI - A)⁻¹ B cancel to the size of G (K came back
    1000 times too small); a nilpotent A, whose eigenvalues rounding puts near 1e-16, puts
    them where sI - A is singular to working precision, or G rounds to exactly 0 (K came back
    0 and the channel as zero). So a point where G cannot be evaluated, or evaluates to 0
    (not a zero of the channel, so a cancellation), gives no gain. If no point is confirmed,
    the best is returned with an IllConditionedWarning; if no point gave a nonzero G, 0 is
    returned, with that warning unless G was exactly 0 at every point tried (a channel that
    is zero to working precision, which the rank decisions judged nonzero)."""
    dt = period(channel) or 0.0
    roots = np.concatenate([zeros, poles])
    size = float(np.max(np.abs(channel.A), initial=0.0))
    grids = [_evaluation_points(roots, dt)]
    if not dt:
        grids += [
            _evaluation_points(roots, dt, math.log10(size) if size > 0.0 else 0.0),
            _evaluation_points(roots, dt, 0.0),
        ]
    best: tuple[float, tuple[float, int]] | None = None
    singular = False
    for index, grid in enumerate(grids):
        point = grid[0]
        response = _scaled_response(channel, point)
        if response is None:
            singular = True
            continue
        mantissa, exponent = _gain(*response, point, zeros, poles)
        if not math.isfinite(mantissa):
            return mantissa, exponent
        if mantissa == 0.0:
            continue
        # Confirmed at a point of another grid: G at the next point of the same grid shares
        # the first's rounding where the terms of C (sI - A)⁻¹ B cancel (a double zero at the
        # origin split to ±2e-8j by rounding, beside poles at 0, -1, -2, centred the grid near
        # 1e-3, where K came back 3.4e-6 too large and the next point agreed with it).
        checks = [g[0] if g[0] != point else g[1] for k, g in enumerate(grids) if k != index]
        error = min(
            _factored_error(channel, mantissa, exponent, c, zeros, poles)
            for c in checks or [grid[1]]
        )
        if error <= 1e-6:
            return mantissa, exponent
        if best is None or error < best[0]:
            best = (error, (mantissa, exponent))
    name = f"{channel.output_names[0]}/{channel.input_names[0]}"
    if best is None:
        if singular:
            warnings.warn(
                f"transfer_function: the gain of {name} could not be computed: G = C (sI - A)⁻¹ "
                "B + D is 0, or sI - A singular, to working precision at every point tried; "
                "the channel is returned as zero",
                IllConditionedWarning,
                stacklevel=5,
            )
        return 0.0, 0
    warnings.warn(
        f"transfer_function: the gain of {name} could not be confirmed: the factored form "
        f"differs from C (sI - A)⁻¹ B + D by {best[0]:.1e} (relative) at a second point "
        "(ill-conditioned zeros or poles)",
        IllConditionedWarning,
        stacklevel=5,
    )
    return best[1]


def _factored_error(
    channel: StateSpace,
    mantissa: float,
    exponent: int,
    point: complex,
    zeros: ComplexArray,
    poles: ComplexArray,
) -> float:
    """|F/G - 1| at ``point``, F = K Π(s - z)/Π(s - p) with K = mantissa 2^exponent and G =
    C (sI - A)⁻¹ B + D from the state space (:func:`_scaled_response`); inf where G cannot be
    evaluated, is 0, or the two differ by more than a factor of 4."""
    checked = _scaled_response(channel, point)
    if checked is None or checked[0] == 0.0:
        return math.inf
    g_m, g_e = checked
    f_m, f_e = _scaled_factored(
        np.array([complex(mantissa)]), np.array([exponent]), np.array([point]), zeros, poles
    )
    # Both renormalised (largest part in [1/2, 1)): near 1 only for exponents within 2.
    shift = int(f_e[0]) - g_e
    if abs(shift) > 2:
        return math.inf
    ratio = complex(f_m[0]) / g_m * 2.0**shift
    return abs(ratio - 1.0) if cmath.isfinite(ratio) else math.inf


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

    Raises
    ------
    InvalidArgumentError
        ``output`` or ``input`` names no signal, is out of range, is of another type, or is
        omitted for a model with several outputs (inputs).
    NotRealError
        ``sys`` is not a model, or a matrix is complex.
    NonFiniteError, ShapeError
        A matrix contains NaN or an infinity, or the matrices disagree in size.

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
    dt = period(model) if model.is_discrete else 0.0
    poles, denominator, channels = _core.transfer_channels(
        model.A, model.B, model.C, model.D, dt, [(i, j)]
    )
    fast = channels.channel(0)
    if fast is not None:
        denominator = _checked_denominator(poles, denominator, 3)
        names = (model.output_names[i], model.input_names[j])
        return _fast_channel(names, dt, poles, denominator, fast)
    return _reference_channel(model, i, j, dt, stacklevel=3)


def _checked_denominator(
    poles: ComplexArray, denominator: FloatArray, stacklevel: int
) -> FloatArray:
    """The core's Π(s - p_j), or (when it overflowed: empty) the same scaled by powers of two
    (:func:`_scaled_poly`), warned of when a coefficient lies beyond the doubles."""
    if denominator.size != poles.size + 1:  # the core's overflowed
        denominator = _scaled_poly(poles, 1.0, 0)
        finite_or_warn(denominator, "the denominator det(sI - A)", stacklevel=stacklevel + 1)
    return denominator


def _fast_channel(
    names: tuple[str, str],
    dt: float,
    poles: ComplexArray,
    denominator: FloatArray,
    fast: tuple[ComplexArray, float, FloatArray],
) -> TransferFunction:
    """The TransferFunction (output and input ``names``) of the core's fast path
    (``rust/control/transfer.rs``), which computes what :func:`_reference_channel` computes and
    leaves it every channel where the two could differ."""
    zeros, gain, numerator = fast
    return TransferFunction(
        numerator=numerator,
        denominator=denominator,
        zeros=zeros,
        poles=poles,
        gain=gain,
        dt=dt,
        output_name=names[0],
        input_name=names[1],
    )


def _reference_channel(
    model: StateSpace, i: int, j: int, dt: float, stacklevel: int
) -> TransferFunction:
    """Channel (i, j) by the reference path: the zeros of the equilibrated pencil
    (:func:`_pencil_zeros`), the gain from G at a point, every product held as a mantissa and
    a power of two (any scaling the doubles can hold)."""
    channel = model[[i], [j]]
    poles, zeros, mantissa, exponent = _roots_and_gain(channel)
    denominator = _scaled_poly(poles, 1.0, 0)
    finite_or_warn(denominator, "the denominator det(sI - A)", stacklevel=stacklevel + 1)
    with np.errstate(over="ignore"):
        gain = float(np.ldexp(mantissa, exponent))
    if mantissa != 0.0 and gain == 0.0:
        # Below the doubles (subnormals included): the channel is returned as zero, numerator,
        # gain and zeros alike, not as a gain of 0 beside the zeros of a nonzero numerator.
        size = (math.log2(abs(mantissa)) + exponent) * math.log10(2.0)
        warnings.warn(
            f"the gain K of {model.output_names[i]}/{model.input_names[j]} is about "
            f"10^{size:.1f}, below the range of doubles: the transfer function is returned "
            "as zero (numerator [0.], no zeros)",
            NumericalUnderflowWarning,
            stacklevel=stacklevel,
        )
        zeros = np.zeros(0, np.complex128)
        gain = 0.0  # not -0.0
    numerator = _scaled_poly(zeros, mantissa, exponent) if gain != 0.0 else np.zeros(1)
    finite_or_warn(numerator, "the numerator", stacklevel=stacklevel + 1)
    return TransferFunction(
        numerator=numerator,
        denominator=denominator,
        zeros=zeros,
        poles=poles,
        gain=gain,
        dt=dt,
        output_name=model.output_names[i],
        input_name=model.input_names[j],
        scaled_gain=(mantissa, exponent) if math.isinf(gain) else None,
    )


class TransferMatrix(Result):
    """Every channel of a model, computed in one call: ``g[output, input]`` is a channel's
    :class:`TransferFunction` (by name or index), ``g(s)`` the values of all channels.

    The channels share the poles and the denominator det(sI - A); each has its own zeros and
    gain, computed as :func:`transfer_function` computes them.

    Attributes
    ----------
    poles : ndarray (n,), complex
        The eigenvalues of A, sorted: the poles every channel shares.
    denominator : ndarray (n + 1,)
        det(sI - A), monic, highest power first.
    dt : float
        0.0 for a continuous model, else the sampling period in seconds.
    output_names, input_names : tuple of str
        The model's outputs and inputs.
    shape : tuple of int
        (outputs, inputs).
    channels : tuple of TransferFunction
        Every channel, output by output (each input's in turn).

    Examples
    --------
    >>> import numpy as np, aerocontrol
    >>> lateral = aerocontrol.aircraft.load("b747-cruise").lateral()
    >>> g = aerocontrol.transfer_matrix(lateral[["p", "r"], :])
    >>> g.shape
    (2, 2)
    >>> g["r", "rudder"].zeros.size
    3
    >>> g(1j * np.array([0.1, 1.0])).shape      # (outputs, inputs, points)
    (2, 2, 2)
    """

    __slots__ = (
        "_channels",
        "_fast",
        "_shape",
        "denominator",
        "dt",
        "input_names",
        "output_names",
        "poles",
    )

    def __init__(
        self,
        poles: ComplexArray,
        denominator: FloatArray,
        dt: float,
        output_names: tuple[str, ...],
        input_names: tuple[str, ...],
        channels: list[TransferFunction | tuple[ComplexArray, float, FloatArray]]
        | _core.FastChannels,
    ) -> None:
        self.poles = poles
        """The eigenvalues of A, sorted."""
        self.denominator = denominator
        """det(sI - A), monic, highest power first."""
        self.dt = dt
        """0.0 for a continuous model, else the sampling period in seconds."""
        self.output_names = output_names
        self.input_names = input_names
        self._shape = (len(output_names), len(input_names))
        # Every channel from the core's fast path: kept there (its arrays made on first use, G(s)
        # evaluated there); else each channel's TransferFunction or the core's (zeros, gain,
        # numerator).
        self._fast: _core.FastChannels | None = None
        self._channels: list[TransferFunction | tuple[ComplexArray, float, FloatArray] | None]
        if isinstance(channels, _core.FastChannels):
            self._fast = channels
            self._channels = [None] * len(channels)
        else:
            self._channels = list(channels)

    @property
    def shape(self) -> tuple[int, int]:
        """(outputs, inputs)."""
        return self._shape

    @property
    def channels(self) -> tuple[TransferFunction, ...]:
        """Every channel's :class:`~aerocontrol.TransferFunction`, output by output (each
        input's in turn); what ``==`` compares besides the poles, the denominator, ``dt`` and
        the names."""
        p, m = self.shape
        return tuple(self._channel(i, j) for i in range(p) for j in range(m))

    def _channel(self, i: int, j: int) -> TransferFunction:
        index = i * len(self.input_names) + j
        channel = self._channels[index]
        if isinstance(channel, TransferFunction):
            return channel
        if channel is None:
            channel = cast("_core.FastChannels", self._fast).channel(index)
            if channel is None:  # pragma: no cover - a FastChannels here holds every channel
                raise AssertionError("a deferred channel among the fast path's")
        names = (self.output_names[i], self.input_names[j])
        made = _fast_channel(names, self.dt, self.poles, self.denominator, channel)
        self._channels[index] = made
        return made

    def __getitem__(self, key: tuple[SignalSelection, SignalSelection]) -> TransferFunction:
        if not (isinstance(key, tuple) and len(key) == 2):
            raise InvalidArgumentError(
                "a TransferMatrix is indexed by [output, input] (a name or an index each)"
            )
        i = _single(key[0], self.output_names, "output")
        j = _single(key[1], self.input_names, "input")
        return self._channel(i, j)

    def __call__(self, s: complex | ComplexArray) -> ComplexArray:
        """G(s) of every channel from its factored form (as :meth:`TransferFunction.__call__`):
        shape (outputs, inputs) + the shape of ``s``."""
        value = complex_array(s, "s")
        shape = self._shape + value.shape
        if self._fast is not None:
            result, finite = self._fast.response(value, shape)
        else:
            # Each channel's gain as a mantissa and a power of two, and its zeros.
            mantissas: list[float] = []
            exponents: list[int] = []
            zeros: list[ComplexArray] = []
            for channel in self._channels:
                if isinstance(channel, TransferFunction):
                    k, e = channel.scaled_gain or math.frexp(channel.gain)
                    zeros.append(channel.zeros)
                else:  # the core's (zeros, gain, numerator)
                    k, e = math.frexp(cast("tuple[ComplexArray, float, FloatArray]", channel)[1])
                    zeros.append(cast("tuple[ComplexArray, float, FloatArray]", channel)[0])
                mantissas.append(k)
                exponents.append(e)
            result, finite = _core.factored_response(
                mantissas, exponents, zeros, self.poles, value, shape
            )
        if not finite and np.isfinite(value).all():
            warnings.warn(
                "the result overflowed double precision: G is infinite or NaN (at a pole, or "
                "beyond the doubles)",
                NumericalOverflowWarning,
                stacklevel=2,
            )
        return result

    def __str__(self) -> str:
        return "\n".join(
            str(self._channel(i, j)) for i in range(self.shape[0]) for j in range(self.shape[1])
        )

    def __repr__(self) -> str:
        return (
            f"TransferMatrix(outputs={list(self.output_names)}, inputs={list(self.input_names)}, "
            f"poles={self.poles!r})"
        )

    def __reduce__(self) -> tuple[type[TransferMatrix], tuple[object, ...]]:
        # By the channels (the core's FastChannels does not pickle), as ``==`` compares.
        return (
            TransferMatrix,
            (
                self.poles,
                self.denominator,
                self.dt,
                self.output_names,
                self.input_names,
                list(self.channels),
            ),
        )


# Equality and the JSON form by the channels (computed on first use, so not the same objects
# in two equal matrices).
register(
    TransferMatrix,
    fields=("poles", "denominator", "dt", "output_names", "input_names", "channels"),
    build=lambda fields: TransferMatrix(
        fields["poles"],
        fields["denominator"],
        fields["dt"],
        fields["output_names"],
        fields["input_names"],
        list(fields["channels"]),
    ),
)


def transfer_matrix(sys: System) -> TransferMatrix:
    """The transfer functions of every channel of a model, in one call.

    Each channel is what :func:`transfer_function` gives for it (the poles, the eigenvalues
    of A, shared; the zeros of the channel's pencil; the gain from G at a point); the core
    computes all of them at once, and a channel it cannot confirm is computed by the
    reference path, as :func:`transfer_function` does.

    Parameters
    ----------
    sys : StateSpace or (A, B, C, D)

    Returns
    -------
    TransferMatrix
        ``g[output, input]`` a :class:`TransferFunction`, ``g(s)`` the values, of shape
        (outputs, inputs) + the shape of ``s``.

    Raises
    ------
    NotRealError
        ``sys`` is not a model, or a matrix is complex.
    NonFiniteError, ShapeError
        A matrix contains NaN or an infinity, or the matrices disagree in size.

    Examples
    --------
    >>> import aerocontrol
    >>> lateral = aerocontrol.aircraft.load("b747-approach").lateral()
    >>> g = aerocontrol.transfer_matrix(lateral[["r"], ["rudder", "aileron"]])
    >>> print(g["r", "rudder"].aircraft_form(3))   # doctest: +NORMALIZE_WHITESPACE
    -0.244 (s + 1.23)(s² + 2(-0.0707)(0.37)s + (0.37)²) /
        (s + 0.0464)(s + 1.23)(s² + 2(0.108)(0.748)s + (0.748)²)
    """
    model = as_state_space(sys)
    dt = period(model)
    poles, denominator, fast = _core.transfer_channels(model.A, model.B, model.C, model.D, dt, None)
    denominator = _checked_denominator(poles, denominator, 2)
    deferred = fast.deferred
    if deferred:  # channels the core leaves to the reference path
        m = model.n_inputs
        channels: list[TransferFunction | tuple[ComplexArray, float, FloatArray]] = [
            _reference_channel(model, k // m, k % m, dt, stacklevel=2)
            if k in deferred
            else cast("tuple[ComplexArray, float, FloatArray]", fast.channel(k))
            for k in range(len(fast))
        ]
        return TransferMatrix(
            poles, denominator, dt, model.output_names, model.input_names, channels
        )
    return TransferMatrix(poles, denominator, dt, model.output_names, model.input_names, fast)
