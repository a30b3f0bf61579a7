"""Independent computations and the tolerances to compare with them.

Every tolerance is a modest constant times n u (u = 2^-53, the unit roundoff) times a scale
that the data justify:

* a backward-stable result is exact for data perturbed by about n u ||data|| (Higham,
  *Accuracy and Stability of Numerical Algorithms*, 2002): eigenvalues are checked by their
  backward error sigma_min(A - lambda I), equations by their residual relative to the size of
  their terms; neither depends on the conditioning of the problem;
* where a forward result is compared with a reference, the difference may be as large as the
  problem's condition number times u: the exponential's relative condition number is
  estimated (a few power steps on its Fréchet derivative, scipy's ``expm_frechet``), the
  linear systems' by ``numpy.linalg.cond``. The exponential's reference is computed in
  extended precision (x87 long double, u = 2^-64, scaling and squaring with a Taylor
  polynomial), because scipy's ``expm`` is itself off by up to a few thousand u on matrices
  as plain as ``ones((4, 4))`` (5e-13 relatively, where aerocontrol's is within 1.3e-16).

``SLACK`` is the modest constant: rounding error bounds carry low-degree polynomials in n
which are pessimistic by orders of magnitude in practice, so 100 n u is generous for the
backward errors and still fails on any error of a percent, a sign or a lost term.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from math import comb
from typing import Any

import numpy as np
import scipy.linalg as sl

from aerocontrol.exceptions import IllConditionedWarning

U = np.finfo(float).eps / 2
SLACK = 100.0
#: The unit roundoff of the x87 long double in which the references are computed.
U_LONG = float(np.finfo(np.longdouble).eps) / 2
#: The smallest normal double: the absolute accuracy of results that underflow.
TINY = np.finfo(float).tiny


def norm(a: Any) -> float:
    """Frobenius norm without overflow in the squares; 0 for an empty array, NaN or inf as
    the entries are."""
    return float(row_norms(np.asarray(a).reshape(1, -1))[0])


def row_norms(a: Any) -> np.ndarray:
    """The 2-norm of each row of a 2-D array, scaled so that squaring cannot overflow."""
    a = np.abs(np.asarray(a, dtype=complex if np.iscomplexobj(a) else float))
    if a.shape[1] == 0:
        return np.zeros(a.shape[0])
    with np.errstate(all="ignore"):
        largest = np.max(a, axis=1)
        scale = np.where((largest > 0) & np.isfinite(largest), largest, 1.0)
        return np.where(
            np.isfinite(largest),
            scale * np.sqrt(np.sum((a / scale[:, None]) ** 2, axis=1)),
            largest,
        )


def finite(*arrays: Any) -> bool:
    with np.errstate(all="ignore"):
        return all(bool(np.all(np.isfinite(np.asarray(a)))) for a in arrays)


@contextmanager
def silenced() -> Iterator[None]:
    """numpy's and scipy's warnings silenced: the reference computations may overflow, and
    then the comparison is skipped."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def quietly(function: Any, *args: Any, **kwargs: Any) -> Any:
    """``function(*args, **kwargs)``, :func:`silenced`."""
    with silenced():
        return function(*args, **kwargs)


def assert_within(error: float, bound: float, what: str) -> None:
    """``error <= bound``, or a message with both (a NaN error fails)."""
    assert error <= bound, f"{what}: error {error:.3e} exceeds the tolerance {bound:.3e}"


# ----- the exponential --------------------------------------------------------------------------


def expm_condition(X: np.ndarray) -> float:
    """An estimate of the relative condition number of e^X in the Frobenius norm,
    ||L(X)|| ||X||_F / ||e^X||_F, L the Fréchet derivative: the largest of three power
    iterations on L^* L (L^* = L(X^T) for real X) of three steps each, from fixed random
    starts, times ``CONDITION_SAFETY`` (a power iteration approaches ||L|| from below). At
    least 1; inf where scipy's derivative overflows."""
    n = X.shape[0]
    if n == 0:
        return 1.0
    with silenced():
        try:
            E = sl.expm(X)
            if not finite(E) or norm(E) == 0:
                return np.inf if norm(E) else 1.0  # e^X underflows: only TINY is asked for
            largest = 0.0
            rng = np.random.default_rng(0)
            for _ in range(3):
                Z = rng.standard_normal(X.shape)
                for _ in range(3):
                    Z = Z / norm(Z)
                    L = sl.expm_frechet(X, Z, compute_expm=False)
                    largest = max(largest, norm(L))
                    if not finite(L) or norm(L) == 0:
                        break
                    Z = sl.expm_frechet(X.T, L / norm(L), compute_expm=False)
                    if not finite(Z) or norm(Z) == 0:
                        break
        except (ValueError, np.linalg.LinAlgError):
            return np.inf
        kappa = CONDITION_SAFETY * largest * norm(X) / norm(E)
    return max(1.0, kappa) if np.isfinite(kappa) else np.inf


#: The factor by which :func:`expm_condition` may underestimate: against scipy's exact
#: ``expm_cond`` on 1,190 random, graded, scaled and non-normal matrices of orders 2 to 6,
#: the unscaled estimate was never below a sixth of it (and the worst cases had kappa > 1e20).
CONDITION_SAFETY = 10.0


def expm_long(X: np.ndarray) -> np.ndarray:
    """e^X in long double arithmetic: X / 2^s with ||X / 2^s||_1 <= 1/4, the Taylor
    polynomial of degree 20 of F = e^Y - I (truncation below 1e-30 relatively), then s
    squarings: of F, as F (2I + F) (I + F squared, less I), while every diagonal entry of F is
    below 1/2 in size, and of E = I + F after that. Independent of aerocontrol's and scipy's
    Padé approximants.

    Squaring I + F from the start rounds a diagonal of I + F near 1 to the unit roundoff of 1,
    and each squaring doubles that relative error: for X = [[0, 0], [9e15, 2]] (55 squarings)
    the diagonal 1 + 2^-54 of e^Y was held to a relative 1e-3 in its distance from 1, and e^X
    came out 1.1e6 off in 3.6e15. Held as F, each diagonal entry keeps the relative accuracy of
    its distance from 1, and the error of e^(X_ii) stays |X_ii| u (the device of expm1; Higham,
    "The scaling and squaring method for the matrix exponential revisited", SIAM J. Matrix
    Anal. Appl. 26, 2005). Kept as F while I + F is near 0, its diagonal would lose the
    relative accuracy of a decaying e^(X_ii) (-1 + ε formed as F² + 2F): once a diagonal entry
    of F reaches 1/2 in size, the squarings left are about log2(|X_ii| / 0.7), and squaring E
    costs |X_ii| u relatively again."""
    n = X.shape[0]
    Y = X.astype(np.longdouble)
    with np.errstate(all="ignore"):
        size = float(np.max(np.sum(np.abs(Y), axis=0))) if n else 0.0
    if not np.isfinite(size):
        return np.full((n, n), np.nan, dtype=np.longdouble)  # no reference: skipped
    squarings = max(0, int(np.ceil(np.log2(size) + 2))) if size > 0.25 else 0
    Y = Y / np.longdouble(2.0) ** squarings
    identity = np.eye(n, dtype=np.longdouble)
    F, term = np.zeros((n, n), dtype=np.longdouble), identity.copy()
    with np.errstate(all="ignore"):
        for k in range(1, 21):
            term = term @ Y / k
            F = F + term
        E = None
        for _ in range(squarings):
            if E is None and n and np.max(np.abs(np.diag(F))) >= 0.5:
                E = identity + F
            if E is None:
                F = F @ F + 2 * F
            else:
                E = E @ E
    return identity + F if E is None else E


def expm_extended(X: np.ndarray) -> np.ndarray:
    """e^X computed in long double (:func:`expm_long`), rounded to float64."""
    with np.errstate(all="ignore"):
        return expm_long(X).astype(np.float64)


def assert_exponential(
    result: np.ndarray, X: np.ndarray, what: str, warned: tuple[type[Warning], ...]
) -> None:
    """``result`` is e^X to the accuracy its conditioning allows: compared with
    :func:`expm_extended`, ||result - e^X||_F <= SLACK n (u kappa(X) ||e^X||_F + TINY), unless
    an IllConditionedWarning said that no digit can be trusted.

    Whatever the warnings, a result whose exact value is representable (every entry of the
    reference below 1e300 in magnitude) has no NaN, and no infinity without an
    IllConditionedWarning: a NumericalOverflowWarning then is no excuse, nothing overflowed."""
    if not finite(X):
        return
    reference = expm_extended(X)
    if not finite(reference) or np.max(np.abs(reference), initial=0.0) >= 1e300:
        return
    assert not np.any(np.isnan(result)), f"{what}: NaN in a result whose exact value is finite"
    if IllConditionedWarning in warned:
        return
    assert finite(result), f"{what}: an infinity in a result whose exact value is finite"
    assert_within(
        norm(result - reference),
        exponential_tolerance(X, reference),
        f"{what} against the extended-precision e^X",
    )


def exponential_tolerance(X: np.ndarray, reference: np.ndarray) -> float:
    """SLACK n ((u + u_long) kappa(X) ||e^X||_F + TINY): the error of a result as accurate as
    the exponential's conditioning allows, plus that of the long double reference (inf where
    the condition cannot be estimated)."""
    kappa = expm_condition(X)
    if not np.isfinite(kappa):
        return np.inf
    return SLACK * max(X.shape[0], 1) * ((U + U_LONG) * kappa * norm(reference) + TINY)


# ----- eigenvalues ------------------------------------------------------------------------------


def eigenvalue_backward_error(A: np.ndarray, eigenvalue: complex) -> float:
    """sigma_min(A - lambda I): the norm of the smallest perturbation of A that has lambda
    as an eigenvalue."""
    shifted = A.astype(complex) - eigenvalue * np.eye(A.shape[0])
    return float(np.linalg.svd(shifted, compute_uv=False)[-1])


def characteristic_tolerance(A: np.ndarray) -> np.ndarray:
    """Per coefficient a_k of det(lambda I - A): SLACK n u C(n, k) k ||A||_F^k. a_k is the sum
    of the C(n, k) principal minors of order k, and a perturbation E of A changes a minor of
    order k by at most k ||A||^(k-1) ||E||; the eigenvalue solvers' E is about n u ||A||."""
    n = A.shape[0]
    size = np.float64(norm(A))  # the Frobenius norm bounds the 2-norm
    with np.errstate(over="ignore"):
        return np.array([SLACK * n * U * comb(n, k) * max(k, 1) * size**k for k in range(n + 1)])


def assert_spectrum(A: np.ndarray, eigenvalues: np.ndarray, what: str) -> None:
    """``eigenvalues`` are the n eigenvalues of A, with their multiplicities: each has a
    backward error sigma_min(A - lambda I) <= SLACK n (u ||A||_F + TINY), the set is closed under
    conjugation, and the polynomial with these roots has the coefficients of det(lambda I - A)
    (numpy.poly of numpy's eigenvalues) within :func:`characteristic_tolerance`: that catches a
    right eigenvalue with the wrong multiplicity."""
    n = A.shape[0]
    eigenvalues = np.asarray(eigenvalues)
    assert eigenvalues.shape == (n,), f"{what}: {eigenvalues.shape} eigenvalues of order {n}"
    if n == 0 or not finite(A, eigenvalues):
        return
    bound = SLACK * n * (U * norm(A) + TINY)
    for value in eigenvalues:
        error = eigenvalue_backward_error(A, complex(value))
        assert_within(error, bound, f"{what}: backward error of the eigenvalue {value}")
    spread = np.sort_complex(eigenvalues) - np.sort_complex(np.conj(eigenvalues))
    assert_within(norm(spread), bound, f"{what}: the eigenvalues are closed under conjugation")
    assert_coefficients(
        np.real(quietly(np.poly, eigenvalues)),
        np.real(quietly(np.poly, A)),
        characteristic_tolerance(A),
        f"{what}: the polynomial of the eigenvalues against det(lambda I - A)",
    )


def assert_coefficients(
    got: np.ndarray, expected: np.ndarray, tolerance: np.ndarray, what: str
) -> None:
    if not (finite(got, expected) and finite(tolerance)):
        return
    errors = np.abs(np.asarray(got) - np.asarray(expected))
    worst = int(np.argmax(errors / np.maximum(tolerance, np.finfo(float).tiny)))
    assert_within(errors[worst], tolerance[worst], f"{what} (coefficient {worst})")


def eigenvalue_conditions(A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(eigenvalues, condition numbers 1/|y^H x|) of A, scipy's left and right vectors.

    Of A divided by the power of two nearest its largest entry (exact; the eigenvalues are
    multiplied back, the condition numbers are those of A): LAPACK's dgeev with vectors gave
    eigenvalues 1.9e-155 and -1.1e-139 for a rank-one A of 1e-152 whose eigenvalues are 0
    and -1.07e-152 (and so a wrong verdict on the stability of a closed loop)."""
    largest = float(np.max(np.abs(A), initial=0.0))
    exponent = int(np.frexp(largest)[1]) if 0.0 < largest < np.inf else 0
    values, left, right = quietly(sl.eig, np.ldexp(A, -exponent), left=True, right=True)
    with np.errstate(divide="ignore"):
        condition = 1.0 / np.abs(np.sum(left.conj() * right, axis=0))
    scaled = np.empty(values.shape, dtype=np.complex128)
    with np.errstate(over="ignore"):
        scaled.real, scaled.imag = np.ldexp(values.real, exponent), np.ldexp(values.imag, exponent)
    return scaled, condition


def assert_stable(A: np.ndarray, what: str) -> None:
    """Every eigenvalue of A has Re < 0, to within its own sensitivity: numpy's eigenvalue is
    exact for A + E, ||E|| <= n u ||A||, which moves it by up to its condition number times
    that; an eigenvalue that far from the axis and on the wrong side fails."""
    n = A.shape[0]
    if n == 0 or not finite(A):
        return
    values, condition = eigenvalue_conditions(A)
    margin = SLACK * n * U * norm(A) * condition
    worst = int(np.argmax(values.real - margin))
    assert values.real[worst] < margin[worst] or values.real[worst] < 0, (
        f"{what}: eigenvalue {values[worst]} is not in the left half plane "
        f"(sensitivity margin {margin[worst]:.2e})"
    )


def condition(M: np.ndarray) -> float:
    """The 2-norm condition number of M (numpy's), inf where it cannot be computed."""
    if M.shape[0] == 0:
        return 1.0
    with silenced():
        try:
            value = float(np.linalg.cond(M))
        except np.linalg.LinAlgError:
            return np.inf
    return value if np.isfinite(value) else np.inf


def relative_residual(residual: np.ndarray, *terms: Any) -> float:
    """||residual||_F / sum ||term||_F, 0 when every term vanishes."""
    scale = sum(norm(term) for term in terms)
    size = norm(residual)
    return 0.0 if size == 0 else size / scale if scale else np.inf


# ----- time responses ---------------------------------------------------------------------------


def van_loan(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, ...]:
    """(N, G, Φ, Γ0, Γ1, β) of a step h in long double: G = e^N with
    N = [[A h, B / β, 0], [0, 0, I], [0, 0, 0]], Φ = G11, Γ0 = β h G12, Γ1 = β h G13 (Van Loan
    1978). The blocks are scaled by h so that Γ keeps its relative accuracy for tiny h, and B
    by β, a power of two near its largest entry, so that the squarings do not drown A."""
    n, m = B.shape
    largest = float(np.max(np.abs(B), initial=0.0))
    beta = 2.0 ** np.round(np.log2(largest)) if 0 < largest < np.inf else 1.0
    N = np.zeros((n + 2 * m, n + 2 * m), dtype=np.longdouble)
    with np.errstate(all="ignore"):
        N[:n, :n] = A.astype(np.longdouble) * np.longdouble(h)
    N[:n, n : n + m] = B / beta
    N[n : n + m, n + m :] = np.eye(m)
    G = expm_long(N)
    scale = np.longdouble(h) * np.longdouble(beta)
    with np.errstate(all="ignore"):
        return N, G, G[:n, :n], scale * G[:n, n : n + m], scale * G[:n, n + m :], beta


def exact_response(
    A: np.ndarray,
    B: np.ndarray,
    times: np.ndarray,
    x0: np.ndarray,
    inputs: np.ndarray,
    hold: str,
    initial_error: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(x, tolerance): the states of x' = A x + B u from x0 at ``times`` (a uniform grid from
    0), the input held between samples (``"zoh"``) or linear between them (``"foh"``),
    computed in long double; and the error allowed at each sample.

    The grid's step is h = t[-1] / (k - 1) (as aerocontrol takes it), and x is propagated by
    the exact recurrence x[j+1] = Φ x[j] + Γ0 u[j] (+ Γ1 (u[j+1] - u[j]) with FOH). A double
    precision recurrence with Φ, Γ carrying relative errors of u (1 + kappa) (kappa the
    condition of e^N) makes local errors e_j <= n u (1 + kappa) (||Φ|| ||x_j|| + ||Γ0|| ||u_j||
    + ||Γ1|| ||u_j+1||), which reach sample k through Φ^(k-1-j). Hence the tolerance

        SLACK n [(u + u_long) (1 + kappa) sum_j ||Φ^(k-1-j)|| e_j + ||Φ^k|| initial_error + TINY]
            + ||A x_k + B u_k|| |t_k - k h|

    the last term for the grid's deviation from uniform (aerocontrol accepts 1e-9 h).
    ``initial_error`` is the rounding in x0 as the caller forms it (B η0 for an impulse)."""
    k, n = len(times), A.shape[0]
    h = float(times[-1]) / (k - 1)
    N, _, Phi, Gamma0, Gamma1, _ = van_loan(A, B, h)
    if hold == "zoh":
        Gamma1 = np.zeros_like(Gamma1)
    u = inputs.astype(np.longdouble)
    x = np.zeros((k, n), dtype=np.longdouble)
    x[0] = x0
    with silenced():
        for j in range(k - 1):
            x[j + 1] = Phi @ x[j] + Gamma0 @ u[j] + Gamma1 @ (u[j + 1] - u[j])
        x64 = x.astype(np.float64)
        Phi64 = Phi.astype(np.float64)
        kappa = expm_condition(N.astype(np.float64))
        local = (
            norm(Phi64) * row_norms(x64)
            + norm(Gamma0.astype(np.float64)) * row_norms(inputs)
            + norm(Gamma1.astype(np.float64)) * row_norms(np.vstack([inputs[1:], inputs[-1:]]))
        )
        powers = np.empty(k)
        power = np.eye(n)
        for i in range(k):
            powers[i] = norm(power) if n else 0.0
            power = power @ Phi64
        propagated = np.array([np.dot(powers[:j][::-1], local[:j]) for j in range(k)])
        deviation = np.abs(times - np.arange(k) * h)
        rate = row_norms(x64 @ A.T + inputs @ B.T)
        tolerance = (
            SLACK
            * max(n, 1)
            * ((U + U_LONG) * (1 + kappa) * propagated + powers * initial_error + TINY)
            + rate * deviation
        )
    return x64, tolerance


# ----- Riccati and Lyapunov equations -----------------------------------------------------------
#
# A returned solution is checked by its residual, evaluated in long double from the returned X
# and K (so that the evaluation adds nothing of its own), relative to the size of the
# equation's terms as the solvers report it; by the residual of its gain; by the stability of
# its closed loop; and, where scipy solves the same equation, against scipy's solution within
# the first-order forward error bound ||X - X_s||_F <= (||Res(X)||_F + ||Res(X_s)||_F) / sep,
# sep = sigma_min of the Lyapunov (continuous) or Stein (discrete) operator of the closed loop:
# Res(X* + D) = Omega(D) + O(||D||^2), so each solution is within ||Res|| / sep of X*. The
# comparison is made only where that bound is below 1e-6 ||X|| and the second-order term is
# negligible, so that it holds whatever the problem's conditioning.


def symmetric_part(M: np.ndarray) -> np.ndarray:
    return 0.5 * (M + M.T)


def longdouble(M: Any) -> np.ndarray:
    return np.asarray(M, dtype=np.float64).astype(np.longdouble)


def care_residual(
    A: np.ndarray,
    B: np.ndarray,
    Q: np.ndarray,
    S: np.ndarray | None,
    E: np.ndarray | None,
    X: np.ndarray,
    K: np.ndarray,
) -> tuple[float, float]:
    """(||Res||_F, ||Q||_F + 2 ||A^T X E||_F + ||M^T K||_F) of
    Res = A^T X E + E^T X A - M^T K + Q, M = B^T X E + S^T, in long double (the solvers'
    reported residual is the first divided by the second)."""
    n, m = B.shape
    a, b, q, x, k = (longdouble(M) for M in (A, B, symmetric_part(Q), X, K))
    e = np.eye(n, dtype=np.longdouble) if E is None else longdouble(E)
    s = np.zeros((n, m), dtype=np.longdouble) if S is None else longdouble(S)
    with silenced():
        axe = a.T @ x @ e
        M = b.T @ x @ e + s.T
        quadratic = M.T @ k
        residual = axe + axe.T - quadratic + q
        sizes = [norm(np.asarray(t, dtype=np.float64)) for t in (residual, q, axe, quadratic)]
    return sizes[0], sizes[1] + 2 * sizes[2] + sizes[3]


def dare_residual(
    A: np.ndarray,
    B: np.ndarray,
    Q: np.ndarray,
    S: np.ndarray | None,
    E: np.ndarray | None,
    X: np.ndarray,
    K: np.ndarray,
) -> tuple[float, float]:
    """(||Res||_F, ||Q||_F + ||A^T X A||_F + ||E^T X E||_F + ||M^T K||_F) of
    Res = A^T X A - E^T X E - M^T K + Q, M = B^T X A + S^T, in long double."""
    n, m = B.shape
    a, b, q, x, k = (longdouble(M) for M in (A, B, symmetric_part(Q), X, K))
    e = np.eye(n, dtype=np.longdouble) if E is None else longdouble(E)
    s = np.zeros((n, m), dtype=np.longdouble) if S is None else longdouble(S)
    with silenced():
        axa = a.T @ x @ a
        exe = e.T @ x @ e
        M = b.T @ x @ a + s.T
        quadratic = M.T @ k
        residual = axa - exe - quadratic + q
        sizes = [norm(np.asarray(t, dtype=np.float64)) for t in (residual, q, axa, exe, quadratic)]
    return sizes[0], sizes[1] + sizes[2] + sizes[3] + sizes[4]


def riccati_gain(
    A: np.ndarray,
    B: np.ndarray,
    R: np.ndarray,
    S: np.ndarray | None,
    E: np.ndarray | None,
    X: np.ndarray,
    discrete: bool,
) -> np.ndarray:
    """The gain of a solution X: R^-1 (B^T X E + S^T) (continuous) or
    (R + B^T X B)^-1 (B^T X A + S^T) (discrete), by numpy's solve and one step of refinement
    with the residual in long double."""
    n, m = B.shape
    e = np.eye(n) if E is None else E
    s = np.zeros((n, m)) if S is None else S
    with silenced():
        if discrete:
            lhs = longdouble(symmetric_part(R)) + longdouble(B).T @ longdouble(X) @ longdouble(B)
            rhs = longdouble(B).T @ longdouble(X) @ longdouble(A) + longdouble(s).T
        else:
            lhs = longdouble(symmetric_part(R))
            rhs = longdouble(B).T @ longdouble(X) @ longdouble(e) + longdouble(s).T
        lhs64 = np.asarray(lhs, dtype=np.float64)
        K = np.linalg.solve(lhs64, np.asarray(rhs, dtype=np.float64))
        correction = np.asarray(rhs - lhs @ longdouble(K), dtype=np.float64)
        return np.asarray(K + np.linalg.solve(lhs64, correction), dtype=np.float64)


def closed_loop_separation(Acl: np.ndarray, E: np.ndarray | None, discrete: bool) -> float:
    """sigma_min of the operator D -> Acl^T D E + E^T D Acl (continuous) or
    Acl^T D Acl - E^T D E (discrete), by its Kronecker matrix: 1 / ||Omega^-1||_2 (n <= 12)."""
    n = Acl.shape[0]
    if n == 0:
        return np.inf
    e = np.eye(n) if E is None else E
    with silenced():
        if discrete:
            operator = np.kron(Acl.T, Acl.T) - np.kron(e.T, e.T)
        else:
            operator = np.kron(e.T, Acl.T) + np.kron(Acl.T, e.T)
        try:
            return float(np.linalg.svd(operator, compute_uv=False)[-1])
        except np.linalg.LinAlgError:
            return 0.0


def pencil_eigenvalues(
    A: np.ndarray,
    B: np.ndarray,
    Q: np.ndarray,
    R: np.ndarray,
    S: np.ndarray | None,
    E: np.ndarray | None,
    discrete: bool,
) -> np.ndarray:
    """The finite eigenvalues of the extended Hamiltonian (continuous) or symplectic
    (discrete) pencil of order 2n + m (scipy's construction), by scipy's QZ: n of them are the
    closed-loop poles of the stabilising solution when it exists."""
    n, m = B.shape
    e = np.eye(n) if E is None else E
    s = np.zeros((n, m)) if S is None else S
    q, r = symmetric_part(Q), symmetric_part(R)
    zero = np.zeros((n, n))
    if discrete:
        M = np.block([[A, zero, B], [-q, e.T, -s], [s.T, np.zeros((m, n)), r]])
        N = np.block(
            [
                [e, zero, np.zeros((n, m))],
                [zero, A.T, np.zeros((n, m))],
                [np.zeros((m, n)), -B.T, np.zeros((m, m))],
            ]
        )
    else:
        M = np.block([[A, zero, B], [-q, -A.T, -s], [s.T, B.T, r]])
        N = np.zeros((2 * n + m, 2 * n + m))
        N[:n, :n], N[n : 2 * n, n : 2 * n] = e, e.T
    with silenced():
        try:
            alpha, beta = sl.eig(M, N, right=False, homogeneous_eigvals=True)
        except (ValueError, np.linalg.LinAlgError):
            return np.full(2 * n, np.nan + 0j)
    size = np.abs(alpha) + np.abs(beta)
    finite_ones = np.abs(beta) > 1e3 * U * size
    with silenced():
        return np.asarray(alpha[finite_ones] / beta[finite_ones])


def stabilizability_margin(
    A: np.ndarray, B: np.ndarray, E: np.ndarray | None, discrete: bool
) -> float:
    """min over the eigenvalues lambda of (A, E) that are not stable of
    sigma_min([A - lambda E, B]) / (||A||_F + ||B||_F + |lambda| ||E||_F) (the PBH test, by
    distance): 0 when (A, B) is not stabilisable, inf when A is stable; NaN where it cannot
    be computed."""
    n = A.shape[0]
    if n == 0:
        return np.inf
    e = np.eye(n) if E is None else E
    with silenced():
        try:
            eigenvalues = sl.eigvals(A, e)
        except (ValueError, np.linalg.LinAlgError):
            return np.nan
        worst = np.inf
        for value in eigenvalues:
            if not np.isfinite(value):
                continue
            unstable = abs(value) >= 1 - 1e-8 if discrete else value.real >= -1e-8 * abs(value)
            if not unstable:
                continue
            pencil = np.hstack([A.astype(complex) - value * e, B.astype(complex)])
            smallest = np.linalg.svd(pencil, compute_uv=False)[-1] if n else np.inf
            worst = min(worst, smallest / (norm(A) + norm(B) + abs(value) * norm(e)))
    return float(worst)


def riccati_defect(
    A: np.ndarray,
    B: np.ndarray,
    Q: np.ndarray,
    R: np.ndarray,
    S: np.ndarray | None,
    E: np.ndarray | None,
    X: np.ndarray,
    K: np.ndarray,
    discrete: bool,
) -> float:
    """||Res(X)||_F in the form that is stationary in the gain, in long double:
    (A - B K)^T X E + E^T X (A - B K) (continuous) or (A - B K)^T X (A - B K) - E^T X E
    (discrete), plus Q - S K - K^T S^T + K^T R K. At the optimal gain of X it is the Riccati
    residual; an error dK in K changes it by O(||dK||^2) only, so that it measures X."""
    n, m = B.shape
    a, b, q, r, x, k = (longdouble(M) for M in (A, B, symmetric_part(Q), symmetric_part(R), X, K))
    e = np.eye(n, dtype=np.longdouble) if E is None else longdouble(E)
    s = np.zeros((n, m), dtype=np.longdouble) if S is None else longdouble(S)
    with silenced():
        closed = a - b @ k
        if discrete:
            loop = closed.T @ x @ closed - e.T @ x @ e
        else:
            half = closed.T @ x @ e
            loop = half + half.T
        cross = s @ k
        residual = loop + q - cross - cross.T + k.T @ r @ k
        return norm(np.asarray(residual, dtype=np.float64))


# ----- transfer functions -----------------------------------------------------------------------


def response_at(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, s: complex
) -> tuple[np.ndarray, float] | None:
    """(G(s), size): G(s) = C (sI - A)^-1 B + D by a complex solve, and the size of its terms
    ||C R|| ||R B|| ||A|| + ||C R|| ||B|| + ||C|| ||R B|| + ||D|| (R = (sI - A)^-1, Frobenius
    norms): the change of G under perturbations of every matrix by u times its norm is at most
    u times that size. None where sI - A is too close to singular (κ u > 1e-6) or where the
    numbers overflow: there is nothing to compare."""
    n = A.shape[0]
    with silenced():
        if not finite(A, B, C, D):
            return None
        M = s * np.eye(n) - A
        if n and condition(M) * U > 1e-6:
            return None
        try:
            RB = np.linalg.solve(M, B.astype(complex)) if n else np.zeros((0, B.shape[1]))
            CR = np.linalg.solve(M.T, C.T.astype(complex)).T if n else np.zeros((C.shape[0], 0))
        except np.linalg.LinAlgError:
            return None
        G = C @ RB + D
        size = norm(CR) * norm(RB) * norm(A) + norm(CR) * norm(B) + norm(C) * norm(RB) + norm(D)
    if not (finite(G) and np.isfinite(size)) or size > 1e250:
        return None
    return G, size


def assert_response(
    model: Any, expected: np.ndarray, s: complex, allowed: float, what: str
) -> None:
    """The model's G(s) is ``expected`` within SLACK n u (its own size) + ``allowed``."""
    got = response_at(model.A, model.B, model.C, model.D, s)
    if got is None or not np.isfinite(allowed) or not finite(expected):
        return
    G, size = got
    n = max(model.A.shape[0], 1)
    bound = SLACK * n * (U * size + TINY) + allowed
    assert G.shape == expected.shape, f"{what}: G has shape {G.shape}, expected {expected.shape}"
    assert_within(norm(G - expected), bound, f"{what} at s = {s}")
