"""Properties of transfer functions and transmission zeros (aerocontrol.transfer).

Oracles: the transmission zeros by their backward error (the smallest singular value of the
system matrix [[A - zI, B], [C, D]] at each zero, relative to its size), and, for square
systems in general position, against scipy's finite generalized eigenvalues of the Rosenbrock
pencil ([[A, B], [C, D]], [[I, 0], [0, 0]]) within each eigenvalue's condition number times
n u ||S|| (from scipy's left and right vectors); the zeros are invariant under an orthogonal
change of state coordinates, to the same tolerance. A transfer function's denominator is the
characteristic polynomial of A (oracles.characteristic_tolerance), its poles the spectrum of A
(oracles.assert_spectrum), its zeros the channel's transmission zeros (bitwise), and
numerator(s) / denominator(s) is G(s) = C (sI - A)^-1 B + D evaluated directly, within the
sensitivity of the factored form to the errors of its roots (sum_r δr / |s - r|, δr the root's
condition times n u ||·||) and of the polynomials' evaluation.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import NumericalUnderflowWarning

from .harness import Warned, exercise, plain
from .known_defects import ZEROS_DROPPED, ZEROS_OF_GRADED_MODELS
from .oracles import (
    SLACK,
    TINY,
    U,
    assert_coefficients,
    assert_spectrum,
    assert_within,
    characteristic_tolerance,
    condition,
    eigenvalue_conditions,
    finite,
    norm,
    quietly,
    response_at,
    silenced,
)
from .strategies import (
    SQUARE_KINDS,
    model_matrices,
    orders,
    presented_system,
    rectangular,
    square,
    system,
)

COVERED = {"transmission_zeros", "transfer_function"}

GENERAL = ("gaussian", "stable")
POINTS = (0.23j, 1.3j, 7.0j, 0.5 + 2.0j)


def rosenbrock(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray) -> tuple[Any, ...]:
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    M = np.block([[A, B], [C, D]])
    N = np.zeros((n + p, n + m))
    N[:n, :n] = np.eye(n)
    return M, N


def pencil_zeros(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray) -> Any:
    """(finite eigenvalues, their tolerances) of the Rosenbrock pencil of a square system, by
    scipy's QZ; None where scipy fails or the pencil is singular (det(M - λN) ≡ 0)."""
    M, N = rosenbrock(A, B, C, D)
    size = norm(M)
    with silenced():
        try:
            values, left, right = sl.eig(M, N, left=True, right=True, homogeneous_eigvals=True)
        except (ValueError, np.linalg.LinAlgError):
            return None
        alpha, beta = values
        if np.any((np.abs(alpha) < 1e3 * U * size) & (np.abs(beta) < 1e3 * U)):
            return None  # a singular pencil: no comparison
        finite_ones = np.abs(beta) * (size + 1) > 1e-8 * np.abs(alpha)
        lam = alpha[finite_ones] / beta[finite_ones]
        x, y = right[:, finite_ones], left[:, finite_ones]
        denominators = np.abs(np.sum(y.conj() * (N @ x), axis=0))
        conditions = np.linalg.norm(x, axis=0) * np.linalg.norm(y, axis=0) / denominators
        n = M.shape[0]
        tolerance = SLACK * n * U * (size + np.abs(lam)) * conditions
    return lam, tolerance


def match(got: np.ndarray, expected: np.ndarray, tolerance: np.ndarray, what: str) -> None:
    """The same multiset of values: each expected value has its own got value within its
    tolerance (greedily, tightest first)."""
    assert len(got) == len(expected), f"{what}: {len(got)} zeros, scipy finds {len(expected)}"
    remaining = list(got)
    for k in np.argsort(tolerance):
        distances = [abs(z - expected[k]) for z in remaining]
        nearest = int(np.argmin(distances))
        assert_within(distances[nearest], tolerance[k], f"{what}: zero {expected[k]}")
        remaining.pop(nearest)


def contained(got: np.ndarray, expected: np.ndarray, tolerance: np.ndarray, what: str) -> None:
    """Each got value has its own expected value within that value's tolerance (the expected
    values may have extras: QZ's spurious finite eigenvalues of a pencil whose infinite ones
    it resolves badly)."""
    remaining = list(range(len(expected)))
    for z in sorted(got, key=abs):
        assert remaining, f"{what}: the zero {z} has no scipy value left"
        ratios = [abs(z - expected[k]) / max(tolerance[k], TINY) for k in remaining]
        best = int(np.argmin(ratios))
        k = remaining.pop(best)
        assert_within(abs(z - expected[k]), tolerance[k], f"{what}: zero {z}")


def finite_zero_count(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray) -> int | None:
    """n - m for a square system with D = 0 and C B invertible (well conditioned: cond(C B) <
    1/(1e3 u)), the exact number of its finite zeros (the pencil has m Jordan chains of
    length 2 at infinity); None otherwise."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    if m != p or n < m or np.any(D != 0):
        return None
    CB = C @ B
    with silenced():
        well = bool(np.isfinite(condition(CB)) and condition(CB) < 1.0 / (1e3 * U))
    return n - m if well else None


def match_zeros(
    A: np.ndarray,
    B: np.ndarray,
    C: np.ndarray,
    D: np.ndarray,
    got: np.ndarray,
    reference: tuple[np.ndarray, np.ndarray],
    what: str,
) -> None:
    """``got`` against scipy's zeros; where the number of finite zeros is known exactly
    (:func:`finite_zero_count`) and scipy finds more, aerocontrol's must be that many, each
    within tolerance of its own scipy value (scipy's extras are spurious)."""
    expected, tolerance = reference
    count = finite_zero_count(A, B, C, D)
    if count is not None and len(expected) > count:
        assert len(got) == count, f"{what}: {len(got)} zeros, but D = 0 and C B invertible: {count}"
        contained(got, expected, tolerance, what)
        return
    match(got, expected, tolerance, what)


def backward_errors(
    A: Any, B: Any, C: Any, D: Any, zeros: np.ndarray, what: str, tol: float = 0.0
) -> None:
    """sigma_min of the system matrix at each zero, within SLACK times its rounding errors
    and the caller's rank tolerance ``tol`` (rank decisions at tol perturb S by about tol: with
    tol = 1e-10 on a model of 1e-150 every entry is negligible)."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    M, _ = rosenbrock(A, B, C, D)
    for z in zeros:
        shifted = M.astype(complex)
        shifted[:n, :n] -= z * np.eye(n)
        if min(shifted.shape) == 0:
            continue
        smallest = np.linalg.svd(shifted, compute_uv=False)[min(n + m, n + p) - 1]
        bound = SLACK * (n + max(m, p)) * (U * (norm(M) + abs(z) * np.sqrt(n)) + tol + TINY)
        assert_within(smallest, bound, f"{what}: backward error of the zero {z}")


def _zeros_oracle(general: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        A, B, C, D = model_matrices(args["sys"])
        assert result.dtype == np.complex128 and result.ndim == 1
        # Pairwise, not np.diff: two zeros at +inf (beyond the doubles) are in order, and
        # inf - inf is NaN.
        assert not np.any(np.isnan(result)), "a zero is NaN"
        assert np.all(result.real[1:] >= result.real[:-1]), "the zeros are not sorted by real part"
        ties = result.real[1:] == result.real[:-1]
        assert np.all(result.imag[1:][ties] >= result.imag[:-1][ties]), "ties not by imaginary part"
        if not finite(A, B, C, D, result) or norm(np.block([[A, B], [C, D]])) > 1e150:
            return
        tol = args.get("tol")
        given = float(tol) if isinstance(tol, float) and math.isfinite(tol) and tol > 0 else 0.0
        backward_errors(A, B, C, D, result, "transmission_zeros", given)
        if not general or B.shape[1] != C.shape[0]:
            return
        reference = pencil_zeros(A, B, C, D)
        if reference is None or not np.all(np.isfinite(reference[1])):
            return
        match_zeros(
            A, B, C, D, result, reference, "transmission_zeros against scipy's Rosenbrock pencil"
        )
        # Invariant under an orthogonal change of state coordinates.
        rng = np.random.default_rng(len(result))
        Q, _ = np.linalg.qr(rng.standard_normal((A.shape[0], A.shape[0])))
        moved = quietly(aerocontrol.transmission_zeros, (Q @ A @ Q.T, Q @ B, C @ Q.T, D))
        match_zeros(
            A,
            B,
            C,
            D,
            moved,
            (reference[0], 2 * reference[1]),
            "transmission_zeros of T A T^-1, ...",
        )

    return oracle


@given(st.data())
def test_transmission_zeros(data: st.DataObject) -> None:
    general = data.draw(st.sampled_from((True, True, False)))
    n = data.draw(st.sampled_from((0, 1, 2, 3, 4, 5, 6))) if general else data.draw(orders())
    m = data.draw(st.integers(1, 3))
    p = m if general or data.draw(st.booleans()) else data.draw(st.integers(0, 3))
    if general:
        A = data.draw(square(n, GENERAL))
        B = data.draw(rectangular(n, m, ("gaussian",)))
        C = data.draw(rectangular(p, n, ("gaussian",)))
        D = data.draw(rectangular(p, m, ("zero", "gaussian")))
        matrices = (A, B, C, D)
    else:
        matrices = data.draw(system(n, m, p, SQUARE_KINDS))
    tol = data.draw(st.sampled_from((None, None, None, 1e-10, 0.0, -1.0, np.nan)))
    exercise(
        "transmission_zeros",
        lambda sys, tol: aerocontrol.transmission_zeros(sys, tol),
        {"sys": data.draw(presented_system(matrices)), "tol": plain(tol)},
        _zeros_oracle(general and tol is None),
    )


# ----- transfer_function ------------------------------------------------------------------------


def _index(key: Any, count: int, prefix: str) -> int:
    if key is None:
        return 0
    if isinstance(key, str):
        return int(key[len(prefix) :])
    if isinstance(key, list):
        return int(key[0]) % count
    return int(key) % count


def _transfer_oracle(general: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        A, B, C, D = model_matrices(args["sys"])
        i = _index(args["output"], C.shape[0], "y")
        j = _index(args["input"], B.shape[1], "u")
        b, c, d = B[:, [j]], C[[i], :], D[[i]][:, [j]]
        n = A.shape[0]
        assert result.denominator.shape == (n + 1,) and result.denominator[0] == 1.0
        assert result.dt == 0.0 and result.variable == "s"
        assert result.output_name == f"y{i}" and result.input_name == f"u{j}"
        zeros = quietly(aerocontrol.transmission_zeros, (A, b, c, d))
        if result.gain != 0:
            assert np.array_equal(result.zeros, zeros), "the zeros are not the channel's"
            assert result.numerator[0] == result.gain
        else:
            # A zero channel, or one whose gain is below the doubles (warned of): zero
            # throughout, never a gain of 0 beside the zeros of a nonzero numerator.
            assert np.array_equal(result.numerator, [0.0]), f"gain 0, numerator {result.numerator}"
            assert result.zeros.size == 0, f"gain 0 beside the zeros {result.zeros}"
            assert math.copysign(1.0, result.gain) == 1.0, "gain -0.0"
            if NumericalUnderflowWarning not in warned:
                value = response_at(A, b, c, d, POINTS[1])
                if value is not None:
                    G, size = value
                    assert_within(
                        abs(G[0, 0]), SLACK * max(n, 1) * (U * size + TINY), "a gain of 0"
                    )
        if NumericalUnderflowWarning in warned:
            assert result.gain == 0.0, "an underflow warning beside a nonzero gain"
        if not finite(A, b, c, d, result.poles, result.numerator, result.denominator):
            return
        assert_spectrum(A, result.poles, "the poles")
        assert_coefficients(
            result.denominator,
            np.real(quietly(np.poly, A)) if n else np.ones(1),
            characteristic_tolerance(A),
            "the denominator against det(sI - A)",
        )
        if not general or result.gain == 0:
            return
        reference = pencil_zeros(A, b, c, d)
        if reference is None or len(reference[0]) != len(result.zeros):
            return
        zero_tolerance = reference[1]
        _, pole_conditions = eigenvalue_conditions(A) if n else (None, np.zeros(0))
        pole_tolerance = SLACK * n * U * norm(A) * np.sort(pole_conditions)
        roots = np.concatenate([result.zeros, result.poles])
        errors = np.concatenate([np.sort(zero_tolerance)[::-1], pole_tolerance[::-1]])
        for s in POINTS:
            value = response_at(A, b, c, d, s)
            if value is None:
                continue
            G, size = value
            with silenced():
                got = np.polyval(result.numerator, s) / np.polyval(result.denominator, s)
                relative = 2 * np.max(errors, initial=0.0) * np.sum(1 / np.abs(s - roots))
                evaluation = sum(
                    np.dot(np.abs(p), np.abs(s) ** np.arange(len(p))[::-1]) / abs(np.polyval(p, s))
                    for p in (result.numerator, result.denominator)
                )
                bound = abs(G[0, 0]) * (relative + SLACK * (n + 1) * U * evaluation) + (
                    SLACK * max(n, 1) * U * size
                )
            if not np.isfinite(bound) or relative > 1e-3:
                continue
            assert_within(abs(got - G[0, 0]), 2 * bound + TINY, f"N(s)/D(s) against G(s = {s})")

    return oracle


CHANNELS = (None, None, 0, -1, 1, "y0", "u0", "y1", 9, 1.5, [0])


@given(st.data())
def test_transfer_function(data: st.DataObject) -> None:
    general = data.draw(st.booleans())
    n = data.draw(st.sampled_from((0, 1, 2, 3, 4, 5, 6))) if general else data.draw(orders())
    m, p = data.draw(st.integers(1, 2)), data.draw(st.integers(1, 2))
    if general:
        A = data.draw(square(n, GENERAL))
        B = data.draw(rectangular(n, m, ("gaussian",)))
        C = data.draw(rectangular(p, n, ("gaussian",)))
        D = data.draw(rectangular(p, m, ("zero", "gaussian")))
        matrices = (A, B, C, D)
    else:
        matrices = data.draw(system(n, m, p))
    output, input_ = data.draw(st.sampled_from(CHANNELS)), data.draw(st.sampled_from(CHANNELS))
    if isinstance(output, str) and output.startswith("u"):
        output = "y0"
    if isinstance(input_, str) and input_.startswith("y"):
        input_ = "u0"
    outcome = exercise(
        "transfer_function",
        lambda sys, output, input: aerocontrol.transfer_function(sys, output, input),
        {
            "sys": data.draw(presented_system(matrices)),
            "output": plain(output),
            "input": plain(input_),
        },
        _transfer_oracle(general),
    )
    if outcome.error is None and outcome.result is not None:
        assert isinstance(str(outcome.result), str)
        assert isinstance(outcome.result.aircraft_form(3), str)


# ----- known defects of the core (see known_defects.py) ------------------------------------------


def _diagonal_channel(scale: float) -> tuple[np.ndarray, ...]:
    """sum_k 1/(s + k scale), k = 1, 2, 3: poles -scale, -2 scale, -3 scale, gain 3."""
    return (np.diag([-1.0, -2.0, -3.0]) * scale, np.ones((3, 1)), np.ones((1, 3)), np.zeros((1, 1)))


def test_regression_pencil_tolerance_overflow() -> None:
    """||S||_F of entries beyond 1e154 was formed from their squares, which overflowed."""
    model = (np.array([[-1e155]]), np.eye(1), np.eye(1), np.zeros((1, 1)))
    outcome = exercise(
        "transmission_zeros",
        lambda sys: aerocontrol.transmission_zeros(sys),
        {"sys": plain(model)},
        _zeros_oracle(False),
    )
    assert outcome.result.shape == (0,)  # 1/(s + 1e155): no finite zero


def test_regression_transfer_scale_overflow() -> None:
    """Poles near 1e103 (n = 3): det(sI - A) has a coefficient of 6e309, infinite, which came
    back without a warning; the gain was formed from products that overflowed."""
    outcome = exercise(
        "transfer_function",
        lambda sys, output, input: aerocontrol.transfer_function(sys, output, input),
        {"sys": plain(_diagonal_channel(1e103)), "output": plain(None), "input": plain(None)},
        _transfer_oracle(False),
    )
    assert aerocontrol.NumericalOverflowWarning in outcome.warned
    assert outcome.result.gain == pytest.approx(3.0, rel=1e-12)  # sum of 1/(s + k 1e103)


def test_regression_transfer_gain_underflow() -> None:
    """Poles near 1e-151 (n = 3): Π(point - p) underflowed, and the gain of 3/s came out
    -0.0. The zeros are 1e-151 (-2 ± 1/√3) (3 s² + 12 a s + 11 a², a = 1e-151)."""
    outcome = exercise(
        "transfer_function",
        lambda sys, output, input: aerocontrol.transfer_function(sys, output, input),
        {"sys": plain(_diagonal_channel(1e-151)), "output": plain(None), "input": plain(None)},
        _transfer_oracle(False),
    )
    assert outcome.result.gain == pytest.approx(3.0, rel=1e-12)
    expected = 1e-151 * np.array([-2.0 - 1.0 / np.sqrt(3.0), -2.0 + 1.0 / np.sqrt(3.0)])
    np.testing.assert_allclose(outcome.result.zeros.real, expected, rtol=1e-10)


def test_regression_zeros_of_badly_scaled_blocks() -> None:
    """C of 1e9 beside A, B and D of 1: the zeros 1e9 - 3 and 2e-9 (s^2 + (3 - 1e9) s + 2)
    were returned as [0]."""
    model = (np.diag([-1.0, -2.0]), np.ones((2, 1)), np.array([[1e9, -2e9]]), np.eye(1))
    with ZEROS_DROPPED.reproducing():  # the oracle in full, though the class is registered
        outcome = exercise(
            "transmission_zeros",
            lambda sys: aerocontrol.transmission_zeros(sys),
            {"sys": plain(model)},
            _zeros_oracle(True),
        )
    small = 2.0 / (1e9 - 3.0)  # the product of the roots is 2
    np.testing.assert_allclose(outcome.result.real, [small, 2.0 / small], rtol=1e-6)


@pytest.mark.xfail(strict=True, reason="zeros-dropped-badly-scaled: zeros at two scales")
def test_known_defect_zeros_at_two_scales() -> None:
    rng = np.random.default_rng(6)
    A = rng.standard_normal((3, 3)) * 1e-8
    B, C, D = (
        np.array([[0.1257302210933933], [-0.1321048632913019], [0.6404226504432821]]),
        (np.array([[125.7302210933933, -132.10486329130188, 640.422650443282]])),
        np.array([[0.1257302210933933]]),
    )
    with ZEROS_DROPPED.reproducing():
        exercise(
            "transmission_zeros",
            lambda sys: aerocontrol.transmission_zeros(sys),
            {"sys": plain((A, B, C, D))},
            _zeros_oracle(True),
        )


def _small_zero_beside_a_large_pole(large: float) -> None:
    """1/(s + 1) + L/(s + L) = ((1 + L) s + 2 L) / ((s + 1)(s + L)): the zero -2 L/(L + 1)
    (closed form; scipy's QZ of the Rosenbrock pencil gives it too), from transmission_zeros,
    transfer_function and transfer_matrix, and G from their factored forms."""
    model = (np.diag([-1.0, -large]), np.array([[1.0], [large]]), np.ones((1, 2)), np.zeros((1, 1)))
    zero = -2.0 * large / (large + 1.0)
    np.testing.assert_allclose(aerocontrol.transmission_zeros(model), [zero], rtol=1e-10)
    channel = aerocontrol.transfer_function(model)
    np.testing.assert_allclose(channel.zeros, [zero], rtol=1e-10)
    matrix = aerocontrol.transfer_matrix(model)
    np.testing.assert_allclose(matrix[0, 0].zeros, [zero], rtol=1e-10)
    for s in (1j, 0.3 + 0.7j, 1j * large):
        expected = 1.0 / (s + 1.0) + large / (s + large)
        assert abs(channel(s) - expected) <= 1e-10 * abs(expected)
        assert abs(matrix(s)[0, 0] - expected) <= 1e-10 * abs(expected)


@pytest.mark.parametrize("large", [1e5, 1e10, 1e15])
def test_regression_a_small_zero_beside_a_large_pole_is_not_the_origin(large: float) -> None:
    """Both paths set to 0 every zero below the rank tolerance of the pencil scaled to its
    largest pole, so that transmission_zeros and transfer_function returned 0 for
    :func:`_small_zero_beside_a_large_pole` at L = 1e15, and G(j) was off by 1.41 beside
    |G| = 1.58, silently. A zero near the origin is now 0 only where the equilibrated system
    matrix at the origin is singular."""
    _small_zero_beside_a_large_pole(large)


@pytest.mark.xfail(strict=True, reason="zeros-of-graded-models: a small zero beside a large pole")
@pytest.mark.parametrize("large", [1e20, 1e50, 1e100])
def test_known_defect_zeros_of_graded_models(large: float) -> None:
    """:func:`_small_zero_beside_a_large_pole` at L of 1e20 and beyond (see
    known_defects.ZEROS_OF_GRADED_MODELS)."""
    with ZEROS_OF_GRADED_MODELS.reproducing():
        _small_zero_beside_a_large_pole(large)


@pytest.mark.parametrize("large", [1.0, 1e15])
def test_a_washout_zero_is_the_origin_exactly(large: float) -> None:
    """s/(s + 1) in series with 1/(s + L): the zero at the origin, computed as about 1e-17, is
    0 exactly (the system matrix at the origin is singular) for both paths, beside a pole at
    any scale."""
    washout = aerocontrol.washout(1.0)
    model = aerocontrol.series(washout, aerocontrol.zpk([], [-large], large))
    for zeros in (
        aerocontrol.transmission_zeros(model),
        aerocontrol.transfer_function(model).zeros,
        aerocontrol.transfer_matrix(model)[0, 0].zeros,
    ):
        assert zeros.tolist() == [0.0]


def test_regression_poles_of_a_graded_companion_form() -> None:
    """1/(1e-20 s^2 + s + 1): tf's companion form [[0, -2^33.4], [2^33, -1e20]] had the poles
    -1e20 and 0 (the QR iteration on the small state first, as LAPACK's dhseqr: accurate to
    u ||A|| = 1e4 only), so that G(0.3 + 0.7j) was off by 131 % and G(0) infinite. The core
    now orders the balanced states by decreasing size before the Hessenberg reduction.
    Oracle: the closed-form roots -1e20 and -1 (to 1e-20; mpmath's polyroots agrees), and G
    from its closed form."""
    model = aerocontrol.tf([1.0], [1e-20, 1.0, 1.0])
    channel = aerocontrol.transfer_function(model)
    np.testing.assert_allclose(np.sort(channel.poles.real), [-1e20, -1.0], rtol=1e-12)
    for s in (0.3 + 0.7j, 0.0):
        expected = 1.0 / (1e-20 * s * s + s + 1.0)
        assert abs(channel(s) - expected) <= 1e-12 * abs(expected)


def test_regression_zeros_oracle_spurious_qz_zero() -> None:
    """A, C of 1e-9, B of 1e-4, D = 0, square with C B invertible: 4 - 2 = 2 finite zeros,
    which aerocontrol finds; scipy's QZ of the pencil reports a third, 7.4e4 (tolerance 4e16),
    from its infinite eigenvalues. The oracle now requires the count n - m and each zero
    matched to one of scipy's, allowing its extra; a missing zero still fails."""
    A = np.array(
        [
            [
                -1.3210486329130190e-10,
                6.4042265044328212e-10,
                1.0490011715303971e-10,
                -5.3566937316111099e-10,
            ],
            [
                3.6159505490948475e-10,
                1.3040000451301374e-09,
                9.4708096312924218e-10,
                -7.0373523580699261e-10,
            ],
            [
                -1.2654214710460525e-09,
                -6.2327446253735220e-10,
                4.1325979347243603e-11,
                -2.3250307746388344e-09,
            ],
            [
                -2.1879166393254575e-10,
                -1.2459109472530653e-09,
                -7.3226735470345161e-10,
                -5.4425898285730987e-10,
            ],
        ]
    )
    B = np.array(
        [
            [-3.1630015636915455e-05, 4.1163053637413283e-05],
            [1.0425133694426776e-04, -1.2853466294403426e-05],
            [1.3664634705496859e-04, -6.6519467348661362e-05],
            [3.5151007009301975e-05, 9.0347018165180861e-05],
        ]
    )
    C = np.array(
        [
            [
                9.4012297760874572e-11,
                -7.4349924935380840e-10,
                -9.2172537625841949e-10,
                -4.5772582566733917e-10,
            ],
            [
                2.2019512347004942e-10,
                -1.0096181835387360e-09,
                -2.0917557487171308e-10,
                -1.5922500991447772e-10,
            ],
        ]
    )
    D = np.zeros((2, 2))
    reference = pencil_zeros(A, B, C, D)
    assert reference is not None and len(reference[0]) == 3  # scipy's spurious third zero
    assert finite_zero_count(A, B, C, D) == 2
    with ZEROS_DROPPED.reproducing():  # the oracle in full
        outcome = exercise(
            "transmission_zeros",
            lambda sys: aerocontrol.transmission_zeros(sys),
            {"sys": plain((A, B, C, D))},
            _zeros_oracle(True),
        )
    np.testing.assert_allclose(
        outcome.result.real, [-1.8496236075240483e-07, 1.4260241541636993e-09], rtol=1e-9
    )
    # A genuine miss still fails: one of the two zeros dropped.
    with pytest.raises(AssertionError, match="1 zeros, but D = 0 and C B invertible: 2"):
        match_zeros(A, B, C, D, outcome.result[:1], reference, "dropped")
    with pytest.raises(AssertionError, match="zero"):
        contained(outcome.result + 1e-9, *reference, "moved")


def test_regression_zeros_backward_error_with_a_given_tol() -> None:
    """A model of 1e-151 with tol = 1e-10: every entry is below the caller's rank tolerance,
    and the zero 0 has the backward error 6e-153 <= tol; the oracle's bound counted only the
    rounding errors of the model's norm (5e-164), not the tolerance the caller gave."""
    A = np.array(
        [
            [3.45584192064786e-151, 8.216181435011584e-151],
            [3.3043707618338715e-151, -1.303157231604361e-150],
        ]
    )
    B = np.array([[1.257302210933933e-151], [-1.3210486329130188e-151]])
    model = (A, B, B.T.copy(), np.zeros((1, 1)))
    outcome = exercise(
        "transmission_zeros",
        lambda sys, tol: aerocontrol.transmission_zeros(sys, tol),
        {"sys": plain(model), "tol": plain(1e-10)},
        _zeros_oracle(False),
    )
    # B, C and A are all negligible at tol: both modes are zeros of the pencil, at 0.
    assert outcome.result.tolist() == [0j, 0j]
    # Without tol the zero is resolved at the model's own scale.
    zeros = aerocontrol.transmission_zeros(model)
    np.testing.assert_allclose(zeros.real, [1.3727543e-151], rtol=1e-7)


def test_regression_transfer_gain_below_the_doubles() -> None:
    """The fuzz input: A of 1e149, B of 1e-151, C of 1e-301, D = 0: K = C B = 1.5e-452, which
    came back as gain 0 beside the numerator [0, -0] (and, where the channel has a finite
    zero, beside that zero), with no warning. The channel is now zero throughout, with a
    NumericalUnderflowWarning."""
    model = (
        np.array(
            [
                [1.2573022109339329e149, -1.3210486329130188e149],
                [6.4042265044328201e149, 1.0490011715303971e149],
            ]
        ),
        np.array([[1.2573022109339330e-151], [-1.3210486329130188e-151]]),
        np.array([[1.257302210933933e-301, -1.321048632913019e-301]]),
        np.zeros((1, 1)),
    )
    outcome = exercise(
        "transfer_function",
        lambda sys, output, input: aerocontrol.transfer_function(sys, output, input),
        {"sys": plain(model), "output": plain(None), "input": plain(None)},
        _transfer_oracle(False),
    )
    assert outcome.warned == (NumericalUnderflowWarning,)
    assert outcome.result.numerator.tolist() == [0.0] and outcome.result.zeros.size == 0
