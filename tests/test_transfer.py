"""Transfer functions and transmission zeros against python-control (with slycot), scipy's
generalized eigenvalues of the Rosenbrock pencil, and hand-derived examples."""

from __future__ import annotations

import math
import pickle
import warnings

import control
import numpy as np
import pytest
import scipy.linalg
from scipy.optimize import linear_sum_assignment

import aerocontrol
from aerocontrol import InvalidArgumentError, ShapeError, transfer_function, transmission_zeros


def _matched_error(ours: np.ndarray, theirs: np.ndarray) -> float:
    """The largest relative distance between the two sets of roots, best matched."""
    assert len(ours) == len(theirs)
    if len(ours) == 0:
        return 0.0
    distance = np.abs(ours[:, None] - theirs[None, :])
    rows, columns = linear_sum_assignment(distance)
    return float(np.max(distance[rows, columns] / np.maximum(1.0, np.abs(ours[rows]))))


# ----- hand-derived -----------------------------------------------------------------------------


def test_two_lags_in_parallel() -> None:
    # 1/(s + 1) + 1/(s + 2) = (2s + 3)/((s + 1)(s + 2)): zero -1.5, gain 2 (by hand).
    sys = aerocontrol.StateSpace(np.diag([-1.0, -2.0]), [[1.0], [1.0]], [[1.0, 1.0]], [[0.0]])
    g = transfer_function(sys)
    np.testing.assert_allclose(g.zeros, [-1.5], rtol=1e-14)
    assert g.gain == pytest.approx(2.0, rel=1e-14)
    np.testing.assert_allclose(g.numerator, [2.0, 3.0], rtol=1e-14)
    np.testing.assert_allclose(g.denominator, [1.0, 3.0, 2.0], rtol=1e-14)
    np.testing.assert_allclose(np.sort(g.poles.real), [-2.0, -1.0], rtol=1e-14)


def test_feedthrough_and_zero_channel() -> None:
    # 2 + 1/(s + 1) = (2s + 3)/(s + 1): zero -1.5, gain 2.
    g = transfer_function(([[-1.0]], [[1.0]], [[1.0]], [[2.0]]))
    np.testing.assert_allclose(g.zeros, [-1.5], rtol=1e-14)
    assert g.gain == pytest.approx(2.0, rel=1e-14)
    # An output that the input does not reach: G = 0.
    zero = transfer_function((np.diag([-1.0, -2.0]), [[1.0], [0.0]], [[0.0, 1.0]], [[0.0]]))
    assert zero.gain == 0.0 and zero.zeros.size == 0
    np.testing.assert_array_equal(zero.numerator, [0.0])


def test_aircraft_form_prints_time_constants_and_quadratics() -> None:
    # 5 (s + 2)/(s (s² + 2·0.5·2 s + 4)): zero at -1/T with T = 0.5, pole pair ζ = 0.5, ω = 2.
    g = transfer_function(
        aerocontrol.zpk([-2.0], [0.0, -1 + np.sqrt(3) * 1j, -1 - np.sqrt(3) * 1j], 5.0)
    )
    assert g.aircraft_form() == "5 (s + 2) / s(s² + 2(0.5)(2)s + (2)²)"
    pair = g.pole_factors[-1]
    assert pair.zeta == pytest.approx(0.5, rel=1e-13) and pair.omega == pytest.approx(
        2.0, rel=1e-13
    )
    assert g.zero_factors[0].time_constant == pytest.approx(0.5, rel=1e-13)
    assert "T = 0.5 s" in str(g)


# ----- python-control ---------------------------------------------------------------------------


@pytest.mark.parametrize("identifier", ["b747-approach", "b747-cruise", "navion"])
def test_every_channel_against_ss2tf(identifier: str) -> None:
    plane = aerocontrol.aircraft.load(identifier)
    for sys in (plane.lateral(), plane.longitudinal()):
        theirs_ss = control.ss(sys.A, sys.B, sys.C, sys.D)
        for i, output in enumerate(sys.output_names):
            for j, input_ in enumerate(sys.input_names):
                g = transfer_function(sys, output, input_)
                theirs = control.ss2tf(theirs_ss[i, j])
                num = np.trim_zeros(np.asarray(theirs.num[0][0], float), "f")
                den = np.asarray(theirs.den[0][0], float)
                # Coefficients to 1e-10 of the largest (slycot's TB04AD forms them directly).
                np.testing.assert_allclose(g.denominator, den, atol=1e-10 * np.abs(den).max())
                scale = np.abs(g.numerator).max()
                np.testing.assert_allclose(g.numerator[-len(num) :], num, atol=1e-9 * scale)
                assert _matched_error(g.zeros, control.zeros(theirs_ss[i, j])) < 1e-8


def test_discrete_channel_against_python_control() -> None:
    lateral = aerocontrol.aircraft.load("b747-cruise").lateral()
    d = aerocontrol.c2d(lateral, 0.1)
    g = transfer_function(d, "r", "rudder")
    assert g.variable == "z"
    theirs = control.ss2tf(control.ss(d.A, d.B, d.C, d.D, 0.1)[3, 0])
    np.testing.assert_allclose(g.numerator, theirs.num[0][0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(g.denominator, theirs.den[0][0], rtol=1e-12, atol=1e-14)
    # G(z) from the factored form equals the state-space response at z = e^{jω dt}.
    w = np.array([0.1, 1.0, 10.0])
    response = aerocontrol.frequency_response(d[["r"], ["rudder"]], w).response[:, 0, 0]
    np.testing.assert_allclose(g(np.exp(1j * w * 0.1)), response, rtol=1e-10)


def test_factored_form_reproduces_frequency_response() -> None:
    lateral = aerocontrol.aircraft.load("b747-approach").lateral()
    w = np.logspace(-2, 2, 50)
    for output in lateral.output_names:
        g = transfer_function(lateral, output, "aileron")
        response = aerocontrol.frequency_response(lateral[output, "aileron"], w).response
        np.testing.assert_allclose(g(1j * w), response[:, 0, 0], rtol=1e-10)


# ----- transmission zeros ------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(6))
def test_square_random_systems_against_scipy_pencil(seed: int) -> None:
    """Square systems with a regular pencil: the zeros are scipy's finite generalized
    eigenvalues of [[A, B], [C, D]] - λ diag(I, 0), matched to 1e-8 relative."""
    rng = np.random.default_rng(seed)
    for _ in range(15):
        n, m = int(rng.integers(1, 21)), int(rng.integers(1, 5))
        A, B = rng.standard_normal((n, n)), rng.standard_normal((n, m))
        C = rng.standard_normal((m, n))
        D = rng.standard_normal((m, m)) if rng.random() < 0.5 or m > n else np.zeros((m, m))
        ours = transmission_zeros((A, B, C, D))
        S = np.block([[A, B], [C, D]])
        E = scipy.linalg.block_diag(np.eye(n), np.zeros((m, m)))
        theirs = scipy.linalg.eig(S, E, right=False)
        # LAPACK returns an infinite eigenvalue as a huge finite one now and then.
        theirs = theirs[np.abs(theirs) < 1e8 * np.linalg.norm(S)]
        assert _matched_error(ours, theirs) < 1e-8


@pytest.mark.parametrize("shape", [(6, 3, 2), (6, 2, 3), (8, 1, 3), (12, 4, 2), (5, 2, 4)])
def test_non_square_systems_against_slycot(shape: tuple[int, int, int]) -> None:
    n, m, p = shape
    rng = np.random.default_rng(n * 100 + m * 10 + p)
    A, B, C = rng.standard_normal((n, n)), rng.standard_normal((n, m)), rng.standard_normal((p, n))
    # A structured non-square system with zeros: the same column repeated in B.
    B[:, 1:] = B[:, :1] * np.arange(2, m + 1) if m > 1 else B
    D = np.zeros((p, m))
    ours = transmission_zeros((A, B, C, D))
    theirs = control.zeros(control.ss(A, B, C, D))
    assert _matched_error(ours, theirs) < 1e-8


def test_decoupling_zeros_are_invariant_zeros() -> None:
    # An uncontrollable mode at -3 is an input-decoupling zero (as SLICOT counts them).
    sys = (np.diag([-1.0, -3.0]), [[1.0], [0.0]], [[1.0, 1.0]], [[0.0]])
    np.testing.assert_allclose(transmission_zeros(sys), [-3.0], rtol=1e-14)


def test_bad_arguments_are_named() -> None:
    lateral = aerocontrol.aircraft.load("b747-approach").lateral()
    with pytest.raises(InvalidArgumentError, match="name the output"):
        transfer_function(lateral)
    with pytest.raises(InvalidArgumentError, match="no output is named 'q'"):
        transfer_function(lateral, "q", "rudder")
    with pytest.raises(InvalidArgumentError, match="output must select one output"):
        transfer_function(lateral, ["r", "p"], "rudder")
    with pytest.raises(InvalidArgumentError, match="tol"):
        transmission_zeros(lateral, tol=-1.0)


# ----- badly scaled blocks, tiny and huge poles -------------------------------------------------


def _closed_form_zeros(c: float) -> np.ndarray:
    """The roots of s² + (3 - c) s + 2, the zeros of A = diag(-1, -2), B = [1, 1]ᵀ,
    C = [c, -2c], D = 1 (G = 1 + c/(s + 1) - 2c/(s + 2)), without cancellation: the larger
    from the quadratic formula in the stable form, the other as 2 over it."""
    b = 3.0 - c
    large = -(b + np.sign(b) * np.sqrt(b * b - 8.0)) / 2.0 if b * b >= 8.0 else None
    if large is None:
        return np.sort_complex(np.roots([1.0, b, 2.0]))
    return np.sort_complex(np.array([2.0 / large, large], dtype=complex))


@pytest.mark.parametrize("c", [1e-12, 1e-6, 1e-3, 1e3, 1e6, 1e9, 1e12, -1e9])
def test_zeros_of_a_badly_scaled_output_against_the_closed_form(c: float) -> None:
    # The zeros lie at c and 2/c for a large c: both within a relative 1e3 u c of the closed
    # form (the large one is determined to that by the pencil's normwise backward error).
    zeros = transmission_zeros((np.diag([-1.0, -2.0]), [[1.0], [1.0]], [[c, -2.0 * c]], [[1.0]]))
    expected = _closed_form_zeros(c)
    assert len(zeros) == 2
    tolerance = 1e3 * np.finfo(float).eps * max(1.0, abs(c))
    for z, e in zip(sorted(zeros, key=abs), sorted(expected, key=abs), strict=True):
        assert abs(z - e) <= tolerance * abs(e), (z, e)


@pytest.mark.parametrize("scales", [(1, 1, 1e9, 1), (1, 1e-9, 1, 1), (1e-6, 1, 1, 1e-3)])
def test_zeros_of_scaled_blocks_against_scipy_pencil(scales: tuple[float, ...]) -> None:
    # A random 4-state, 2 x 2 model with blocks scaled apart; the reference is scipy's QZ of
    # the Rosenbrock pencil of the model with the same blocks at unit scale, its zeros moved
    # by the exact relation: scaling B, C, D by b, c, d is an input/output scaling (zeros
    # unchanged) after A, B by a: the zeros of (aA, aB, C, D) are a times those of (A, B, C, D).
    a, b, c, d = scales
    rng = np.random.default_rng(7)
    A, B = rng.standard_normal((4, 4)) - 3 * np.eye(4), rng.standard_normal((4, 2))
    C, D = rng.standard_normal((2, 4)), rng.standard_normal((2, 2))
    # (aA, bB, cC, dD): dividing the input by b/a and the output by c gives (aA, aB, C,
    # (a d / (b c)) D), whose zeros are a times those of (A, B, C, (a d / (b c)) D).
    reference_D = D * (a * d / (b * c))
    M = np.block([[A, B], [C, reference_D]])
    N = np.zeros((6, 6))
    N[:4, :4] = np.eye(4)
    values = scipy.linalg.eigvals(M, N)
    expected = a * values[np.isfinite(values)]
    ours = transmission_zeros((a * A, b * B, c * C, d * D))
    # Zeros at two scales (those of A, and those of C B / D) are determined to a relative
    # u times their ratio, here at most the spread of the blocks.
    spread = max(scales) / min(scales)
    assert _matched_error(ours / a, expected / a) < 1e3 * np.finfo(float).eps * spread


def test_transfer_function_gain_of_tiny_poles() -> None:
    # sum_k 1/(s + k 1e-151), k = 1, 2, 3: poles k 1e-151, zeros 1e-151 (-2 ± 1/√3), gain 3
    # (the products of the gain's evaluation are 1e-302 and 1e-453 in size).
    a = 1e-151
    g = transfer_function((np.diag([-a, -2 * a, -3 * a]), np.ones((3, 1)), np.ones((1, 3)), [[0]]))
    assert g.gain == pytest.approx(3.0, rel=1e-12)
    np.testing.assert_allclose(
        g.zeros.real, a * np.array([-2 - 1 / np.sqrt(3), -2 + 1 / np.sqrt(3)]), rtol=1e-10
    )


def test_transfer_function_of_huge_poles_warns_of_its_denominator() -> None:
    # Poles near 1e103 (n = 3): det(sI - A) has the coefficient 6e309, beyond doubles; the
    # gain (3) is computed, and the overflow is the library's warning, not numpy's.
    A = np.diag([-1.0, -2.0, -3.0]) * 1e103
    with pytest.warns(aerocontrol.NumericalOverflowWarning, match="denominator"):
        g = transfer_function((A, np.ones((3, 1)), np.ones((1, 3)), [[0.0]]))
    assert g.gain == pytest.approx(3.0, rel=1e-12)


def test_transmission_zeros_of_entries_beyond_1e154() -> None:
    # ||S||_F is formed scaled: 1/(s + 1e155) + 1 has its zero at -(1e155 + 1).
    zeros = transmission_zeros(([[-1e155]], [[1.0]], [[1.0]], [[1.0]]))
    np.testing.assert_allclose(zeros, [-1e155], rtol=1e-14)


def test_transfer_function_of_poles_near_the_overflow_threshold() -> None:
    """A of 1e308 and 1.7e308: the evaluation grid about the roots was centre · 10^1.5 (inf,
    numpy's overflow warning); it is now kept inside the doubles, and the gain is exact."""
    for a in (1e308, 1.7e308, -1.7e308):
        model = aerocontrol.StateSpace(np.array([[a]]), np.eye(1), np.eye(1), np.zeros((1, 1)))
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            g = transfer_function(model)
        assert g.poles.tolist() == [complex(a)]
        assert g.zeros.size == 0
        assert g.gain == pytest.approx(1.0, rel=1e-12)
        assert g.denominator.tolist() == [1.0, -a]


def test_factored_form_of_roots_near_1e200() -> None:
    """Poles and zeros near 1e200: G(s) was the product of the numerator's factors (1e400:
    inf) over the denominator's (inf), nan with numpy's warnings; it is now formed zero by
    pole. ζ and ω of a pair beyond 1e154 were Python's abs (OverflowError beyond the doubles);
    a factor's coefficient ω² beyond the doubles is warned of by aerocontrol."""
    A = np.array([[1e200, 1e200], [-1e200, 1e200]])
    B = np.array([[1.0], [1.0]])
    C = np.array([[1.0, 0.0]])
    model = aerocontrol.StateSpace(A, B, C, np.array([[1.0]]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", aerocontrol.NumericalOverflowWarning)  # coefficients
        g = transfer_function(model)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_allclose(g.poles, [1e200 - 1e200j, 1e200 + 1e200j], rtol=1e-14)
        # G(0) = D + C (-A)^-1 B = 1 - 2e200/(2e400) = 1 - 1e-200: the ratio, not nan.
        assert g(0.0) == pytest.approx(1.0, rel=1e-14)
        assert g(1e200 + 0j) == pytest.approx(complex(1.0, 0.0), abs=1e-12)
        (pair,) = g.pole_factors
        assert pair.omega == pytest.approx(math.sqrt(2.0) * 1e200, rel=1e-14)
        assert pair.zeta == pytest.approx(-math.sqrt(0.5), rel=1e-14)
    with pytest.warns(aerocontrol.NumericalOverflowWarning, match="factor's coefficients"):
        coefficients = pair.coefficients
    assert coefficients[1] == -2e200 and coefficients[2] == math.inf


def test_gain_of_a_tiny_feedthrough_beside_a_huge_c() -> None:
    """B = 0, C of 1.26e299, D of 1.26e-151: G = D. The response was evaluated with C and D
    scaled together by 2^-993, which underflowed D to 0 and gave gain 0 (a silent wrong
    answer); D is now added to the scaled dynamic part at a common power of two."""
    d = 1.257302210933933e-151
    a = 0.1257302210933933
    model = (np.array([[a]]), np.zeros((1, 1)), np.array([[1.257e299]]), np.array([[d]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = transfer_function(model)
    assert g.gain == pytest.approx(d, rel=1e-12)
    np.testing.assert_allclose(g.numerator, [d, -d * a], rtol=1e-12)
    assert g(1j) == pytest.approx(complex(d, 0.0), rel=1e-12)


def test_balancing_beside_a_pole_near_1e308() -> None:
    """A of 1e308, B of 1.26e-151, C of 1.26e149: the state balancing scaled A's row by 2^500
    before restoring its diagonal, with numpy's overflow warning; G = D + B C/(s - A) has its
    zero at A - B C/D (1e308 to rounding) and gain D."""
    d = 0.1257302210933933
    model = (
        np.array([[1e308]]),
        np.array([[d * 1e-150]]),
        np.array([[d * 1e150]]),
        np.array([[d]]),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = transfer_function(model)
    assert g.poles.tolist() == [1e308 + 0j]
    np.testing.assert_allclose(g.zeros.real, [1e308], rtol=1e-14)
    assert g.gain == pytest.approx(d, rel=1e-12)


@pytest.mark.parametrize(
    ("A", "expected_real"),
    [
        # Zeros of A - B C/D: [[0, 2h], [-h, 0]], ±j √2 h beyond the doubles, real part 0 to
        # rounding (the pencil's 4e292 is 2e-16 of the imaginary part).
        (np.array([[0.0, 1.7e308], [-1.7e308, 0.0]]), None),
        # [[-h, 2h], [-h, -h]]: -h ± j √2 h.
        (np.array([[-1.7e308, 1.7e308], [-1.7e308, -1.7e308]]), -1.7e308),
    ],
)
def test_zeros_with_an_imaginary_part_beyond_the_doubles(
    A: np.ndarray, expected_real: float | None
) -> None:
    """B = e1, C = [0, -h], D = 1 with h = 1.7e308: the zeros, the eigenvalues of A - B C/D,
    have imaginary parts ±√2 h beyond the doubles. Scaling them back as real + 1j * imag made
    1j * inf = NaN + inf j (numpy's 'invalid value' warning) and NaN zeros; now the imaginary
    parts are ±inf, the real parts kept, one NumericalOverflowWarning, no NaN, sorted."""
    B, C, D = np.array([[1.0], [0.0]]), np.array([[0.0, -1.7e308]]), np.ones((1, 1))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        zeros = transmission_zeros((A, B, C, D))
    assert [type(w.message) for w in caught] == [aerocontrol.NumericalOverflowWarning]
    assert not np.any(np.isnan(zeros))
    assert sorted(zeros.imag.tolist()) == [-math.inf, math.inf]
    if expected_real is None:
        assert np.all(np.abs(zeros.real) <= 1e-15 * 1.7e308 * math.sqrt(2))
    else:
        np.testing.assert_allclose(zeros.real, [expected_real] * 2, rtol=1e-14)
    assert np.all(zeros.real[1:] >= zeros.real[:-1])


def test_zeros_of_modulus_beyond_the_doubles_keep_their_imaginary_parts() -> None:
    """A = [[h, h], [-h, h]] (h = 1.7e308), B = C = 0, D = 1: the zeros (decoupling zeros)
    are h ± j h, whose parts are doubles but whose modulus is not. |z| = inf made every
    imaginary part 'negligible' (|Im| <= 8 ε |z|): the pair came back as the real h twice.
    The zeros are finite, so no warning."""
    h = 1.7e308
    model = (np.array([[h, h], [-h, h]]), np.zeros((2, 1)), np.zeros((1, 2)), np.ones((1, 1)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        zeros = transmission_zeros(model)
    np.testing.assert_allclose(zeros.real, [h, h], rtol=1e-14)
    np.testing.assert_allclose(zeros.imag, [-h, h], rtol=1e-14)


def test_equal_infinite_zeros_are_in_order() -> None:
    """Two blocks [[h, h], [h, -h]] (h = 1.7e308): zeros ±√2 h, each twice, beyond the doubles:
    -inf, -inf, inf, inf, with a NumericalOverflowWarning (np.diff of them is NaN: the order
    is pairwise)."""
    h = 1.7e308
    block = np.array([[h, h], [h, -h]])
    A = np.block([[block, np.zeros((2, 2))], [np.zeros((2, 2)), block]])
    with pytest.warns(aerocontrol.NumericalOverflowWarning):
        zeros = transmission_zeros((A, np.zeros((4, 1)), np.zeros((1, 4)), np.ones((1, 1))))
    assert zeros.tolist() == [-math.inf, -math.inf, math.inf, math.inf]


# ----- gains, responses and zeros of extreme scalings (references: mpmath, closed forms) --------


def _mp_response(A: np.ndarray, B: np.ndarray, C: np.ndarray, s: complex) -> complex:
    """C (sI - A)^-1 B in 400-bit arithmetic (mpmath), rounded to a complex double."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workprec(400):
        M = mpmath.mpc(s.real, s.imag) * mpmath.eye(A.shape[0]) - mpmath.matrix(A.tolist())
        value = (mpmath.matrix(C.tolist()) * mpmath.lu_solve(M, mpmath.matrix(B.tolist())))[0]
        return complex(value)


@pytest.mark.parametrize(
    ("A", "B", "C"),
    [
        # C B = 1.6e-452: the factors are doubles, their product is not.
        (np.array([[-1.0]]), np.array([[1e-226]]), np.array([[1.6e-226]])),
        # Relative degree 3 through couplings of 1e-200: C A² B = 1e-500 (B, C of 1).
        (
            np.diag([-1.0, -2.0, -3.0]) + np.diag([1e-200, 1e-200], 1),
            np.array([[0.0], [0.0], [1e-100]]),
            np.array([[1.0, 0.0, 0.0]]),
        ),
        # Relative degree 1 with a finite zero (-3.2): C B = 1.2e-450.
        (
            np.array([[-1.0, -0.5356693731611109], [0.0, -2.0]]),
            np.array([[0.9470809631292422e-150], [-0.7037352358069926e-150]]),
            np.array([[-1.265421470904605e-300, -0.6232744625373523e-300]]),
        ),
    ],
)
def test_gain_below_the_doubles_gives_a_zero_transfer_function_with_a_warning(
    A: np.ndarray, B: np.ndarray, C: np.ndarray
) -> None:
    """K below the smallest double: it underflowed to 0 beside the zeros of a nonzero
    numerator (the last model came back with gain 0, numerator [-0, -0] and the zero -3.2).
    The channel is now zero throughout, with a NumericalUnderflowWarning that gives K's size."""
    with pytest.warns(aerocontrol.NumericalUnderflowWarning, match=r"10\^-4[5-9]\d|10\^-500"):
        g = transfer_function((A, B, C, np.zeros((1, 1))))
    assert g.gain == 0.0
    assert g.numerator.tolist() == [0.0]
    assert g.zeros.size == 0
    np.testing.assert_allclose(g.poles.real, np.sort(np.diag(A)), rtol=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert g(1j) == 0.0
        assert g.aircraft_form().startswith("0 / ")


def test_gain_of_a_chain_whose_solution_passes_below_and_above_the_doubles() -> None:
    """Chains of integrators whose responses pass through 1e-400 and 1e+360 on the way from
    B to C (the solve of (sI - A) x = B in doubles gave 0 and inf), while K does not:
    K = C A^(n-1) B = 1e100 · 1e-400 · 1e200 = 1e-100, and 1e-100 · 1e360 · 1e-100 = 1e160.
    G = K / Π(s - p), no zeros (closed form)."""
    poles = np.array([-1.0, -2.0, -3.0, -4.0])
    for coupling, b, c, gain in ((1e-200, 1e100, 1e200, 1e-100), (1e120, 1e-100, 1e-100, 1e160)):
        n = 3 if coupling < 1 else 4
        A = np.diag(poles[:n]) + np.diag(np.full(n - 1, coupling), 1)
        B = np.zeros((n, 1))
        B[-1] = b
        C = np.zeros((1, n))
        C[0, 0] = c
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            g = transfer_function((A, B, C, np.zeros((1, 1))))
            assert g.zeros.size == 0
            assert g.gain == pytest.approx(gain, rel=1e-14)
            s = 0.5 + 1.5j
            assert g(s) == pytest.approx(gain / np.prod(s - poles[:n]), rel=1e-14)


def test_gain_beyond_the_doubles_keeps_the_response_exact() -> None:
    """K = C B = 1e450 (B of 1e300, C of 1e150, a pole at -1e150): the gain is infinite with
    a NumericalOverflowWarning, but G = K/(s + 1e150) is a double at s of the pole's size,
    and is evaluated from K held as a mantissa and a power of two (it was -inf + inf j)."""
    A, B, C = np.array([[-1e150]]), np.array([[1e300]]), np.array([[1e150]])
    with pytest.warns(aerocontrol.NumericalOverflowWarning, match="numerator"):
        g = transfer_function((A, B, C, np.zeros((1, 1))))
    assert g.gain == math.inf and g.scaled_gain is not None
    mantissa, exponent = g.scaled_gain
    assert math.ldexp(mantissa, exponent - 1400) == pytest.approx(
        1e300 * 2.0**-700 * (1e150 * 2.0**-700), rel=1e-15
    )
    for s in (1e150j, 3e149 + 1.1e150j):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            got = g(s)
        assert got == pytest.approx(_mp_response(A, B, C, s), rel=1e-14)


def test_zeros_of_an_equilibration_that_passed_below_the_doubles() -> None:
    """A of 1e300, B of 1, C of 1e-300 (upper triangular A): the zero is
    (c1 b1 a22 - c1 a12 b2 + c2 a11 b2) / (c1 b1 + c2 b2) = -3.2050559935e300. The pencil's
    equilibration scaled B step by step and lost its first entry to 0 on the way (its
    product with C's first entry, which no state scaling changes, fixes the zero), and the
    zero came back as 8.8e298; the scalings are now kept as exponents and applied once."""
    unit = np.array([[-1.0, -0.5356693731611109], [0.0, -2.0]])
    B = np.array([[0.9470809631292422], [-0.7037352358069926]])
    C = 1e-300 * np.array([[-1.265421470904605, -0.6232744625373523]])
    (a11, a12), (_, a22) = unit
    (b1,), (b2,) = B
    c1, c2 = C[0] * 1e300
    expected = (c1 * b1 * a22 - c1 * a12 * b2 + c2 * a11 * b2) / (c1 * b1 + c2 * b2)
    # The zeros of (a A, b B, c C, 0) are a times those of (A, B, C, 0).
    for a, b in ((1e300, 1.0), (1e-300, 1e300)):
        zeros = transmission_zeros((a * unit, b * B, C, np.zeros((1, 1))))
        np.testing.assert_allclose(zeros.real, [a * expected], rtol=1e-12)


def test_zeros_are_each_taken_once_from_the_forward_and_reversed_pencils() -> None:
    """A of 1e300, B of 1e300, C of 1e150 (a third-order channel with zeros 1e300 (-13.394...,
    204.560...), from mpmath's roots of C adj(sI - A) B): the eigenvalues of the regular
    pencil were sorted by |α| / max(β, |α|), which ties every |λ| >= 1, and the zero -13.39e300
    was taken twice (from the pencil and its reversal) and 204.56e300 not at all."""
    A = np.array(
        [
            [-1.0, -0.2812874181513504, -0.6680463461089501],
            [0.0, -2.0, 0.48194538850678587],
            [0.0, 0.0, -3.0],
        ]
    )
    B = np.array([[0.02425956507666462], [1.545820851212812], [0.5451055226876446]])
    C = np.array([[-0.505228735614018, -0.1828389745977349, 0.5405251317548021]])
    expected = np.array([-13.394413590475666, 204.56027418012547]) * 1e300
    for b, c in ((1e300, 1e150), (1.0, 1.0), (1e150, 1e150)):
        zeros = transmission_zeros((A * 1e300, B * b, C * c, np.zeros((1, 1))))
        np.testing.assert_allclose(zeros.real, expected, rtol=1e-12)


def test_gain_with_a_feedthrough_is_the_feedthrough() -> None:
    """G(s) -> D as s -> inf, so K = D exactly; evaluated at a point it carried the rounding of
    the zeros (A of 1e-150 beside B, C, D of 1: K = 1 + 1.1e-10)."""
    A = 1e-150 * np.array(
        [
            [-1.0, -0.2812874181513504, -0.6680463461089501],
            [0.0, -2.0, 0.48194538850678587],
            [0.0, 0.0, -3.0],
        ]
    )
    B = np.array([[0.02425956507666462], [1.545820851212812], [0.5451055226876446]])
    C = np.array([[-0.505228735614018, -0.1828389745977349, 0.5405251317548021]])
    for d in (1.0, -0.3, 1e-8):
        g = transfer_function((A, B, C, np.array([[d]])))
        assert g.gain == d
        assert g.numerator[0] == d


# ----- the core's fast path and the transfer matrix ---------------------------------------------


def _random_channels(seed: int) -> list[tuple[aerocontrol.StateSpace, int, int]]:
    """Random models of 1 to 8 states, 1 or 2 inputs and outputs: dense, sparse (structural
    zeros, double zeros at the origin, zero channels), states scaled over 1e±4, discrete."""
    rng = np.random.default_rng(seed)
    channels = []
    for trial in range(120):
        n, p, m = (int(x) for x in (rng.integers(1, 9), rng.integers(1, 3), rng.integers(1, 3)))
        A, B = rng.standard_normal((n, n)), rng.standard_normal((n, m))
        C = rng.standard_normal((p, n))
        D = rng.standard_normal((p, m)) * (rng.random() < 0.3)
        kind = trial % 4
        if kind == 1:
            A *= rng.random((n, n)) < 0.4
            B *= rng.random((n, m)) < 0.5
            C *= rng.random((p, n)) < 0.5
        if kind == 2:
            s = 10.0 ** rng.uniform(-4, 4, n)
            A, B, C = A * s[:, None] / s[None, :], B * s[:, None], C / s[None, :]
        model = aerocontrol.StateSpace(A, B, C, D, dt=0.1 if kind == 3 else None)
        channels += [(model, i, j) for i in range(p) for j in range(m)]
    return channels


def _state_space_value(model: aerocontrol.StateSpace, i: int, j: int, s: complex) -> complex:
    n = model.n_states
    x = np.linalg.solve(s * np.eye(n) - model.A, model.B[:, j]) if n else np.zeros(0)
    return complex(model.C[i] @ x + model.D[i, j])


@pytest.mark.parametrize("seed", [11, 12])
def test_fast_path_agrees_with_the_reference_path(seed: int) -> None:
    # The core's fast path (rust/control/transfer.rs) and the reference path (transfer.py)
    # on the same channels: the same number of zeros, the zeros within 1e-7 (relative; a
    # double zero at the origin that the reference's QZ splits to ±1e-8 is 0 in the fast
    # path), the gains within 1e-7, and both reproduce C (sI - A)⁻¹ B + D to 1e-9 at points
    # away from the roots. The fast path takes at least 95% of the channels.
    from aerocontrol import _core
    from aerocontrol.transfer import _fast_channel, _reference_channel

    taken = 0
    channels = _random_channels(seed)
    for model, i, j in channels:
        dt = model.dt or 0.0
        poles, denominator, channels_of_model = _core.transfer_channels(
            model.A, model.B, model.C, model.D, dt, [(i, j)]
        )
        fast = channels_of_model.channel(0)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reference = _reference_channel(model, i, j, dt, stacklevel=2)
        if fast is None:
            continue
        taken += 1
        names = (model.output_names[i], model.input_names[j])
        ours = _fast_channel(names, dt, poles, denominator, fast)
        assert ours.zeros.size == reference.zeros.size
        assert _matched_error(ours.zeros, reference.zeros) <= 1e-7
        assert ours.gain == pytest.approx(reference.gain, rel=1e-7, abs=0.0)
        np.testing.assert_allclose(ours.denominator, reference.denominator, rtol=1e-12, atol=1e-12)
        points = np.exp(1j * np.array([0.3, 1.1, 2.3])) if dt else 1j * np.array([0.13, 1.1, 7.7])
        expected = np.array([_state_space_value(model, i, j, s) for s in points])
        scale = np.abs(expected) + 1e-300
        if (
            np.all(np.isfinite(ours(points)))
            and np.min(np.abs(points[:, None] - np.concatenate([ours.zeros, ours.poles])[None, :]))
            > 1e-3
        ):
            assert np.max(np.abs(ours(points) - expected) / scale) <= 1e-9
    assert taken >= 0.95 * len(channels)


def test_reference_gain_is_confirmed_at_a_second_point() -> None:
    # Four poles at the origin and a double zero there: G = K/s² with K = -1.3122 (from the
    # state space, c A b = 0 and c A² b... by hand: G(s) = c (sI - A)⁻¹ b, A nilpotent). The
    # reference path's QZ split the double zero to ±1.6e-9, the grid of evaluation points
    # went to 1e-9, where C (sI - A)⁻¹ B cancels to the size of G, and K came back 1000
    # times too small, silently. The gain is now confirmed at a second point, and the grid
    # around ||A|| is tried when it is not.
    from aerocontrol.transfer import _reference_channel

    A = np.array(
        [
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.90735503, 0.0, 0.0, 0.28741138],
            [0.0, 0.41920303, 0.0, 0.0],
        ]
    )
    b = np.array([[1.6018475], [0.0], [0.0], [1.63150833]])
    c = np.array([[0.0, 0.0, -0.6825994, 0.0]])
    model = aerocontrol.StateSpace(A, b, c, np.zeros((1, 1)))
    # c (sI - A)^-1 b = -0.6825994 (0.90735503 1.6018475 + 0.28741138 1.63150833) / s^2.
    k = -0.6825994 * (0.90735503 * 1.6018475 + 0.28741138 * 1.63150833)
    for g in (_reference_channel(model, 0, 0, 0.0, stacklevel=2), transfer_function(model)):
        assert g.gain == pytest.approx(k, rel=1e-7)
        assert g(2.0j) == pytest.approx(k / (2.0j) ** 2, rel=1e-7)


def test_gain_of_a_channel_with_a_nilpotent_state_matrix() -> None:
    # A nilpotent (a double pole at the origin, which rounding puts at ±3e-16j): by hand
    # (sI - A)⁻¹ b = [s + 2, 1]ᵀ / s², so G = (s + 3)/s², K = 1. The grid of evaluation
    # points went to 1e-9, where sI - A is singular to working precision: G was taken as D = 0
    # there and the channel returned as zero (numerator [0.], no zeros), silently.
    from aerocontrol.transfer import _reference_channel

    A = np.array([[2.0, -4.0], [1.0, -2.0]])
    model = aerocontrol.StateSpace(A, [[1.0], [0.0]], [[1.0, 1.0]], [[0.0]])
    peer = control.ss2tf(control.ss(model.A, model.B, model.C, model.D))
    for g in (
        _reference_channel(model, 0, 0, 0.0, stacklevel=2),
        transfer_function(model),
        aerocontrol.transfer_matrix(model)[0, 0],
    ):
        assert g.gain == pytest.approx(1.0, rel=1e-12)
        np.testing.assert_allclose(g.zeros, [-3.0], rtol=1e-12)
        np.testing.assert_allclose(g.numerator, [1.0, 3.0], rtol=1e-12)
        for s in (0.3j, 2.0j, 1.0 + 5.0j):
            assert g(s) == pytest.approx((s + 3.0) / s**2, rel=1e-12)
            assert g(s) == pytest.approx(complex(peer(s)), rel=1e-10)
    # s²/(s (s + 1)(s + 2)) with every eigenvalue exact but the double zero at the origin
    # split to ±2.2e-9: also returned as zero. G(j) = (3 + j)/10 by hand.
    A = np.array([[-2.0, -1.0, -2.0], [1.0, -1.0, 1.0], [0.0, 1.0, 0.0]])
    model = aerocontrol.StateSpace(A, [[1.0], [0.0], [0.0]], [[1.0, -1.0, 1.0]], [[0.0]])
    for g in (transfer_function(model), aerocontrol.transfer_matrix(model)[0, 0]):
        assert g.gain == pytest.approx(1.0, rel=1e-12)
        assert g.zeros.size == 2 and np.max(np.abs(g.zeros)) <= 1e-7
        assert g(1.0j) == pytest.approx(0.3 + 0.1j, rel=1e-12)


def test_gain_is_confirmed_at_a_point_of_another_grid() -> None:
    # s²/(s (s + 1)(s + 2)) in state coordinates scaled by 10^±2: rounding splits the double
    # zero at the origin to ±2e-8j, the first grid of evaluation points centres near
    # 1e-3, where the terms of C (sI - A)⁻¹ B cancel to the size of G, and K came back
    # 1.0000034; the next point of the same grid shared that rounding and confirmed it. K is 1
    # (the realisation's leading Markov parameter c b = 20 0.01 + 0.04 20 = 1, by hand).
    # The double zero is ill-posed: any backward-stable method moves it by about
    # sqrt(u ‖M‖) = 4e-7 for the pencil M (LAPACK's QZ splits it to ±2e-8j or to two real
    # zeros -8e-9 and 1.4e-8, by version), so G from the factored form is within
    # |z1 + z2| / |s| + |z1 z2| / |s|² of the exact G, not within rounding.
    A = np.array(
        [
            [0.6000000000000001, -0.0028000000000000004, 0.12],
            [600.0, -2.8000000000000003, 120.0],
            [-4.0, 0.002, -0.8],
        ]
    )
    b = np.array([[0.01], [20.0], [0.0]])
    c = np.array([[20.0, 0.04000000000000001, 4.0]])
    model = aerocontrol.StateSpace(A, b, c, [[0.0]])
    g = transfer_function(model)
    assert g.gain == pytest.approx(1.0, rel=1e-12)
    small = [z for z in g.zeros if abs(z) < 1e-3]
    assert len(small) == 2 and max(abs(z) for z in small) <= 4e-7
    for s in (0.37j + 0.11, 1.7j - 0.3, 5.3j):
        split = abs(sum(small)) / abs(s) + abs(small[0] * small[1]) / abs(s) ** 2
        bound = 2.0 * split + 1e-10
        assert g(s) == pytest.approx(_state_space_value(model, 0, 0, s), rel=bound)
        assert g(s) == pytest.approx(s / ((s + 1.0) * (s + 2.0)), rel=bound)


def test_transfer_matrix_is_every_transfer_function() -> None:
    lateral = aerocontrol.aircraft.load("b747-cruise").lateral()
    model = lateral[["p", "r", "beta"], :]
    g = aerocontrol.transfer_matrix(model)
    assert g.shape == (3, 2)
    points = 1j * np.array([0.05, 0.3, 1.0, 4.0])
    values = g(points)
    assert values.shape == (3, 2, 4)
    for i, output in enumerate(model.output_names):
        for j, input_name in enumerate(model.input_names):
            single = transfer_function(model, output, input_name)
            channel = g[output, input_name]
            assert channel is g[i, j]  # made once
            np.testing.assert_array_equal(channel.zeros, single.zeros)
            assert channel.gain == single.gain
            np.testing.assert_array_equal(channel.numerator, single.numerator)
            np.testing.assert_array_equal(channel.poles, single.poles)
            np.testing.assert_allclose(values[i, j], single(points), rtol=1e-14)
            expected = [_state_space_value(model, i, j, s) for s in points]
            np.testing.assert_allclose(values[i, j], expected, rtol=1e-11)
    # Against python-control's ss2tf (slycot TB04AD), channel by channel.
    peer = control.ss2tf(control.ss(model.A, model.B, model.C, model.D))
    np.testing.assert_allclose(values, peer(points), rtol=1e-10)
    # A scalar point gives (outputs, inputs).
    assert g(1.0j).shape == (3, 2)
    assert "TransferMatrix" in repr(g) and "r/rudder" in str(g)


def test_transfer_matrix_defers_a_channel_beyond_the_fast_path() -> None:
    # Entries beyond 2^250 leave a channel to the reference path (scaled products); the other
    # channel is the fast path's. Both are right: G = 1e300/(s + 1) and 2/(s + 1).
    model = aerocontrol.StateSpace([[-1.0]], [[1e300, 2.0]], [[1.0]], [[0.0, 0.0]])
    g = aerocontrol.transfer_matrix(model)
    assert g[0, 0].gain == pytest.approx(1e300, rel=1e-14)
    assert g[0, 1].gain == pytest.approx(2.0, rel=1e-14)
    np.testing.assert_allclose(g(0.0), [[1e300, 2.0]], rtol=1e-14)


def test_transfer_matrix_of_a_discrete_model_and_bad_keys() -> None:
    sys = control.ss(
        [[0.9, 0.1], [0.0, 0.8]], [[1.0, 0.0], [0.5, 1.0]], [[1.0, 0.0], [0.0, 1.0]], 0, 0.05
    )
    model = aerocontrol.StateSpace(sys.A, sys.B, sys.C, sys.D, dt=0.05)
    g = aerocontrol.transfer_matrix(model)
    assert g.dt == 0.05 and g["y0", "u1"].variable == "z"
    z = np.exp(1j * np.array([0.2, 1.0]))
    np.testing.assert_allclose(g(z), control.ss2tf(sys)(z), rtol=1e-12)
    with pytest.raises(InvalidArgumentError, match="output"):
        g["nope", 0]
    with pytest.raises(InvalidArgumentError, match=r"\[output, input\]"):
        g[0]  # type: ignore[index]


def test_zeros_of_equal_modulus_are_each_taken_once() -> None:
    # Zeros ±1.0246 (and -0.3237, -0.0293 ± 0.8647j; scipy's generalized eigenvalues of the
    # pencil): their moduli tie, the forward and the reversed QZ forms ordered the tie
    # differently, and the split by count took 1.0246 from both forms: 1.0246 twice and no
    # -1.0246, silently. The reversed form's share is now what is left when each of the
    # forward form's largest has taken its nearest.
    A = np.array(
        [
            [-0.5224016193394476, -0.0, -0.0, -0.0, 0.25018491477761295],
            [-0.0, -0.0, 0.0, -2.2854597440689717, -0.33248557299438186],
            [0.0, 0.0, 0.0, 0.0, 0.5791181163366733],
            [0.027460802271533708, -0.45938269207844, 0.0, 0.0, -2.045483729295253],
            [-0.8635969058500171, -0.0, -0.9964405130152794, -0.0, -0.0],
        ]
    )
    b = np.array([0.9259719948820543, -0.0, 0.5750596771201096, -0.0, 0.678266188103397])[:, None]
    c = np.array([0.19944556062296265, -0.0, -0.0, -0.0, 0.0])[None, :]
    d = np.array([[-1.3185813215677191]])
    ours = transmission_zeros((A, b, c, d))
    n = A.shape[0]
    S = np.block([[A, b], [c, d]])
    E = np.zeros_like(S)
    E[:n, :n] = np.eye(n)
    expected = scipy.linalg.eigvals(S, E)
    expected = expected[np.isfinite(expected)]
    assert ours.size == expected.size == 5
    assert _matched_error(ours, expected) <= 1e-12


def test_transfer_matrix_of_any_memory_layout() -> None:
    # Strided and transposed points, Fortran-ordered matrices: the values of C-ordered copies.
    model = aerocontrol.aircraft.load("b747-cruise").lateral()[["p", "r"], :]
    g = aerocontrol.transfer_matrix(model)
    w = 1j * np.linspace(0.1, 3.0, 12)
    for points in (w[::3], w.reshape(3, 4).T):
        np.testing.assert_array_equal(g(points), g(np.ascontiguousarray(points)))
        np.testing.assert_array_equal(g["p", 0](points), g["p", 0](points.copy()))
    fortran = aerocontrol.StateSpace(
        np.asfortranarray(model.A), np.asfortranarray(model.B), model.C[:, ::1], model.D
    )
    np.testing.assert_array_equal(aerocontrol.transfer_matrix(fortran)(w), g(w))


def test_factored_response_refuses_a_shape_that_does_not_hold_its_values() -> None:
    # The core writes channels x points values into a new array of the shape it is given: a
    # shape of another size is an InvalidArgumentError, never a write past the array.
    # G = K/(s + 1) with K = 0.5 2^2 = 2.
    none = np.zeros(0, np.complex128)
    pole = np.array([-1.0 + 0j])
    points = np.array([1j, 2j])
    values, finite = aerocontrol._core.factored_response([0.5], [2], [none], pole, points, (1, 2))
    assert finite and values.shape == (1, 2)
    np.testing.assert_allclose(values, [2.0 / (points + 1.0)], rtol=4e-16)
    # Negative extents (whose product could be the count) and extents whose product
    # overflows are named too, not a bare OverflowError.
    for shape in ((2, 2), (3,), (), (0, 2), (-1, -2), (-2,), (2**62, 4, 2)):
        with pytest.raises(InvalidArgumentError, match="shape") as error:
            aerocontrol._core.factored_response([0.5], [2], [none], pole, points, shape)
        assert getattr(error.value, "argument", None) == "shape"


def test_matrix_values_from_the_core_equal_each_channels() -> None:
    # transfer_matrix keeps the fast path's channels in the core and evaluates them there from
    # the roots it sorted once; each channel's TransferFunction evaluates its own arrays: the
    # same products in the same order, so the same values, bit for bit, before and after the
    # channels are made and after a pickle round trip (which holds the TransferFunctions).
    rng = np.random.default_rng(25)
    points = 1j * np.array([0.05, 0.3, 1.0, 4.0, 30.0])
    for trial in range(40):
        n, m, p = int(rng.integers(1, 7)), int(rng.integers(1, 4)), int(rng.integers(1, 4))
        model = aerocontrol.StateSpace(
            rng.standard_normal((n, n)) - 0.5 * np.eye(n),
            rng.standard_normal((n, m)),
            rng.standard_normal((p, n)),
            rng.standard_normal((p, m)) * (trial % 2),
        )
        g = aerocontrol.transfer_matrix(model)
        before = g(points)
        each = np.array([[g[i, j](points) for j in range(m)] for i in range(p)])
        np.testing.assert_array_equal(before, each)
        np.testing.assert_array_equal(g(points), before)
        again = pickle.loads(pickle.dumps(g))
        assert again == g
        np.testing.assert_array_equal(again(points), before)
    # The core's object refuses a channel it does not hold and a shape that does not hold the
    # values.
    model = aerocontrol.aircraft.load("b747-cruise").lateral()[["p", "r"], :]
    _, _, fast = aerocontrol._core.transfer_channels(model.A, model.B, model.C, model.D, 0.0, None)
    assert len(fast) == 4 and fast.deferred == []
    with pytest.raises(InvalidArgumentError, match="no channel 4"):
        fast.channel(4)
    for shape in ((2, 2, 4), (-2, -2, len(points)), (2, 2, -len(points))):
        with pytest.raises(InvalidArgumentError, match="shape"):
            fast.response(points, shape)


def _graded_matrix(rng: np.random.Generator, family: int) -> np.ndarray:
    """A seeded graded matrix of order 2 to 8: the companion matrix of a polynomial with roots
    (real, and complex pairs) of moduli spread log-uniformly over 1e0..1e20, with its
    coefficients in the first row (family 0) or the last column (1); or a random matrix graded
    symmetrically (entry (i, j) times g_i g_j, g over ten decades, states permuted) under a
    similarity by random powers of ten (2)."""
    n = int(rng.integers(2, 9))
    if family == 2:
        g = 10.0 ** rng.uniform(0.0, 10.0, n)
        M = rng.standard_normal((n, n)) * np.outer(g, g)
        p = rng.permutation(n)
        D = 10.0 ** rng.integers(-8, 9, n).astype(float)
        return (M[np.ix_(p, p)] / D[:, None]) * D[None, :]
    roots: list[complex] = []
    while len(roots) < n:
        size = 10.0 ** rng.uniform(0.0, 20.0)
        if len(roots) <= n - 2 and rng.random() < 0.3:
            angle = rng.uniform(0.2, 1.4)
            roots += [-size * np.exp(1j * angle), -size * np.exp(-1j * angle)]
        else:
            roots.append(size if rng.random() < 0.2 else -size)
    c = np.real(np.poly(roots))
    A = np.zeros((n, n))
    A[np.arange(1, n), np.arange(n - 1)] = 1.0
    if family == 0:
        A[0, :] = -c[1:]
    else:
        A[:, -1] = -c[1:][::-1]
    return A


def _relative_eigenvalues(A: np.ndarray) -> list[tuple[complex, float]]:
    """Each eigenvalue of A by mpmath (enough digits for the spread of A's entries, 40 beyond
    it) with its componentwise relative condition |y|ᵀ|A||x| / (|λ| |yᴴx|) (its relative
    change per unit relative change of the entries)."""
    import mpmath

    entries = np.abs(A[A != 0])
    with mpmath.workdps(40 + int(np.log10(entries.max() / entries.min()))):
        values, left, right = mpmath.eig(mpmath.matrix(A.tolist()), left=True, right=True)
        size = mpmath.matrix(np.abs(A).tolist())
        n = A.shape[0]
        out = []
        for k in range(n):
            x, y = right[:, k], left[k, :]
            spread = mpmath.fsum(
                abs(y[i]) * size[i, j] * abs(x[j]) for i in range(n) for j in range(n)
            )
            overlap = abs(values[k]) * abs(mpmath.fsum(y[i] * x[i] for i in range(n)))
            out.append((complex(values[k]), float(spread / overlap) if overlap else math.inf))
    return out


@pytest.mark.parametrize("family", [0, 1, 2])
def test_eigenvalues_of_graded_matrices_to_their_own_size(family: int) -> None:
    """The core's eigenvalues (the poles of every model) of 40 seeded graded matrices per
    family (see :func:`_graded_matrix`) against mpmath: each eigenvalue whose componentwise
    relative condition κ has n u κ < 1e-12 to a relative 1e-10 (the states ordered by size
    before the QR iteration and the small eigenvalues refined by the two-sided Rayleigh
    quotient iteration; over 100 such matrices per family of orders 2 to 10 the largest error
    was 4.0e-14, 4.7e-12 and 7.4e-12, where scipy's eigvals missed 35, 81 and 158 eigenvalues
    by more than 1e-10, by up to 4.5e-7, 2.9 and 894 of their size)."""
    rng = np.random.default_rng(20261204 + family)
    for _ in range(40):
        A = _graded_matrix(rng, family)
        found = list(aerocontrol.linalg.eigenvalues(A))
        assert len(found) == A.shape[0]
        for value, condition in _relative_eigenvalues(A):
            nearest = min(found, key=lambda z: abs(z - value))
            found.remove(nearest)
            if A.shape[0] * 2.2e-16 * condition < 1e-12:
                assert abs(nearest - value) <= 1e-10 * abs(value), (A, value, nearest)


@pytest.mark.parametrize("bad", [object(), "1j", None, [[1.0, 2.0], [3.0]]])
def test_evaluation_refuses_what_is_not_numbers_by_name(bad: object) -> None:
    """G(s) of a channel and of the matrix take numbers and arrays of numbers (real ones as
    complex); anything else is an error naming ``s``, not numpy's bare TypeError."""
    G = aerocontrol.transfer_function(aerocontrol.tf([1.0], [1.0, 1.0]))
    M = aerocontrol.transfer_matrix(aerocontrol.tf([1.0], [1.0, 1.0]))
    for evaluate in (G, M):
        with pytest.raises((InvalidArgumentError, ShapeError), match=r"^s must be"):
            evaluate(bad)
    assert G(1j) == pytest.approx(0.5 - 0.5j, rel=1e-15)
    np.testing.assert_allclose(M(np.array([1j, 2.0])), [[[0.5 - 0.5j, 1 / 3]]], rtol=1e-15)
