"""Pole placement: the chapter's designs (6.95)-(6.102) and (6.146)-(6.165), the companion form,
agreement with scipy.signal.place_poles and python-control, the Kautsky-Nichols-Van Dooren
examples of scipy's own tests, a property test, and bad requests."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import aerocontrol
from aerocontrol import (
    IllConditionedWarning,
    InvalidArgumentError,
    NonFiniteError,
    ShapeError,
    UncontrollableError,
)

A_LAT, B_LAT = aerocontrol.chapter.boeing747_lateral()
RUDDER, AILERON = B_LAT[:, 0], B_LAT[:, 1]
SINGLE_INPUT = [aerocontrol.place_bass_gura, aerocontrol.place_ackermann]


def _dutch_roll_request() -> np.ndarray:
    return aerocontrol.augment_mode(A_LAT, 1, zeta=0.30)  # (6.156)


def _matched_error(achieved: np.ndarray, requested: np.ndarray) -> float:
    """Largest relative distance after matching each requested pole to the nearest one."""
    remaining = list(achieved)
    worst = 0.0
    for pole in requested:
        k = int(np.argmin([abs(a - pole) for a in remaining]))
        worst = max(worst, abs(remaining.pop(k) - pole) / max(abs(pole), 1e-300))
    return worst


@pytest.mark.parametrize("placer", [*SINGLE_INPUT, aerocontrol.place])
def test_state_feedback_example(placer) -> None:
    # (6.95)-(6.102): ω_n = 25, ζ = 0.707 gives k = [16.49844, 8.0875].
    A, b = aerocontrol.chapter.state_feedback_example()
    s = complex(-0.707 * 25, 25 * np.sqrt(1 - 0.707**2))
    design = placer(A, b, [s, s.conjugate()])
    np.testing.assert_allclose(design.K, [[16.4984375, 8.0875]], rtol=1e-13)
    np.testing.assert_allclose(np.round(design.k, 5), [16.49844, 8.0875])
    assert design.K.shape == (1, 2) and design.max_relative_error < 1e-14
    np.testing.assert_allclose(design.closed_loop, A - b @ design.K, rtol=0, atol=0)


def test_dutch_roll_request_and_companion_gains() -> None:
    # (6.155)-(6.157): kbar = ā - a = [0.2873, 0.3669, 0.0164, 0.0000].
    desired = np.poly(_dutch_roll_request()).real
    np.testing.assert_allclose(desired, [1, 1.7258, 1.1891, 0.7396, 0.0319], atol=6e-5)
    form = aerocontrol.companion_form(A_LAT, RUDDER)
    kbar = desired[1:] - form.coefficients[1:]
    # Printed as differences of the 4-decimal coefficients: half a unit of each, 1e-4.
    np.testing.assert_allclose(kbar, [0.2873, 0.3669, 0.0164, 0.0], atol=1e-4)
    # T A T^-1 is the first companion form (6.116) and T b = e_1 (6.109).
    np.testing.assert_allclose(form.T @ A_LAT, form.companion @ form.T, atol=1e-12)
    np.testing.assert_allclose(form.T @ RUDDER, [1, 0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(form.T, np.linalg.inv(form.V @ form.W), rtol=1e-10)
    # Bass-Gura in companion coordinates: k = T^T kbar (6.143).
    design = aerocontrol.place_bass_gura(A_LAT, RUDDER, _dutch_roll_request())
    np.testing.assert_allclose(design.k, form.T.T @ kbar, rtol=1e-10)


@pytest.mark.parametrize("placer", SINGLE_INPUT)
def test_boeing_747_rudder_damper(placer) -> None:
    # (6.159): computed [0.13836, 0.09439, 0.12508, -1.13364]; closed loop (6.162).
    design = placer(A_LAT, RUDDER, _dutch_roll_request())
    np.testing.assert_allclose(design.k, [0.13836, 0.09439, 0.12508, -1.13364], atol=5e-6)
    printed = [
        [-0.1024, -0.0017, 0.1130, -0.9794],
        [-1.6158, -1.1014, -0.0109, 0.3834],
        [0, 1, 0, 0],
        [0.4427, -0.0165, 0.0305, -0.5220],
    ]
    np.testing.assert_allclose(design.closed_loop, printed, atol=6e-5)
    assert design.max_relative_error < 1e-12


@pytest.mark.parametrize("placer", SINGLE_INPUT)
def test_boeing_747_aileron_damper(placer) -> None:
    # Computed from the printed A and B: [-3.54833, 0.87228, 0.67487, -4.04805]; (6.165).
    design = placer(A_LAT, AILERON, _dutch_roll_request())
    np.testing.assert_allclose(design.k, [-3.54833, 0.87228, 0.67487, -4.04805], atol=5e-6)
    printed = [
        [-0.0999, 0, 0.1153, -1],
        [-0.4651, -1.3734, -0.2169, 1.5873],
        [0, 1, 0, 0],
        [0.4027, -0.0380, 0.0012, -0.2525],
    ]
    # (6.165) is A - b k with the printed gains (6.164), both from unrounded matrices: with the
    # printed, rounded A and b it holds to 2.2e-4, and to 2.1e-3 for our gains (the (2, 1)
    # entry moves by b_2 δk_1 = 0.3215 x 0.0066).
    printed_gains = np.array([-3.5417, 0.8715, 0.6746, -4.0504])
    np.testing.assert_allclose(A_LAT - np.outer(AILERON, printed_gains), printed, atol=2.2e-4)
    np.testing.assert_allclose(design.closed_loop, printed, atol=2.1e-3)
    np.testing.assert_allclose(design.achieved_poles, design.poles, rtol=1e-12)


def _random_controllable(n: int, m: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    B = rng.standard_normal((n, m))
    real = rng.uniform(-3, -0.2, size=n)
    poles = real.astype(complex)
    for k in range(0, n - 1, 4):  # a few complex pairs
        poles[k] = complex(real[k], rng.uniform(0.3, 2))
        poles[k + 1] = poles[k].conjugate()
    return A, B, poles


@pytest.mark.parametrize("n", range(2, 11))
@pytest.mark.parametrize("seed", range(3))
def test_robust_placement_against_scipy(n: int, seed: int) -> None:
    signal = pytest.importorskip("scipy.signal")
    for m in sorted({1, 2, min(3, n)}):
        A, B, poles = _random_controllable(n, m, 100 * n + 10 * seed + m)
        with warnings.catch_warnings():
            # One input leaves no freedom: some of these are ill conditioned for every method.
            warnings.simplefilter("ignore", IllConditionedWarning)
            ours = aerocontrol.place(A, B, poles)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # scipy's YT non-convergence notes
            theirs = signal.place_poles(A, B, poles)
        their_error = _matched_error(np.linalg.eigvals(A - B @ theirs.gain_matrix), poles)
        our_error = _matched_error(np.linalg.eigvals(A - B @ ours.K), poles)
        if m == 1:
            # One input: the gain is unique, both methods compute it up to rounding, and which
            # one's rounding places the poles better is luck (scipy's BLAS kernels differ by
            # CPU). The bound is first-order perturbation theory: |δλ| <= κ(X) ||δ(A - B K)||,
            # with ||δ(A - B K)|| a few u (||A|| + ||B|| ||K||); here up to 6e-11 at κ = 1e5.
            scale = np.linalg.norm(A, 2) + np.linalg.norm(B, 2) * np.linalg.norm(ours.K, 2)
            bound = ours.eigenvector_condition * np.finfo(float).eps * scale
            assert our_error <= 10 * bound / np.abs(poles).min(), (n, our_error, bound)
            assert np.abs(ours.K - theirs.gain_matrix).max() <= 1e-6 * np.abs(ours.K).max()
        else:
            assert our_error <= 10 * their_error + 1e-13, (n, m, our_error, their_error)
        if ours.eigenvector_condition < 1e6:  # well conditioned: the 1e-8
            assert ours.max_relative_error <= 1e-8
        assert ours.K.shape == (m, n)


@pytest.mark.parametrize("n", range(2, 11))
def test_single_input_formulas_against_python_control(n: int) -> None:
    control = pytest.importorskip("control")
    A, b, poles = _random_controllable(n, 1, 7 * n)
    reference = np.asarray(control.acker(A, b, poles)).ravel()
    reference_error = _matched_error(np.linalg.eigvals(A - np.outer(b, reference)), poles)
    for placer in SINGLE_INPUT:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", IllConditionedWarning)
            design = placer(A, b, poles)
        closed = A - b @ design.K
        values, vectors = np.linalg.eig(closed)
        error = _matched_error(values, poles)
        # Both formulas are exact for a problem perturbed by about u κ(V); the poles then move
        # by that times their sensitivity, at most about κ(X) of the closed-loop eigenvectors.
        # (Bass-Gura also inherits the rounding of the open-loop coefficients: at n = 9 here it
        # is 18x less accurate than Ackermann's formula, and still inside this bound.)
        conditioning = np.finfo(float).eps * design.controllability_condition
        conditioning *= np.linalg.cond(vectors)
        assert error <= max(10 * reference_error, 10 * conditioning) + 1e-13, (
            placer.__name__,
            error,
            reference_error,
        )
        # Where the problem is well conditioned, the formulas agree with python-control's gains.
        if conditioning < 1e-10:
            tolerance = 1e-8 * design.controllability_condition
            np.testing.assert_allclose(design.k, reference, rtol=tolerance)
            assert design.max_relative_error <= 1e-8


# The examples of scipy's place_poles tests (scipy/signal/tests/test_ltisys.py,
# TestPlacePoles): example 1 of Kautsky, Nichols & Van Dooren (1985, section 4), the linearised
# car of Jaulin's "Automatique pour la robotique" (pp. 184-185), and the Monte Carlo 6 x 6 case.
KNV_A = np.array(
    [1.380, -0.2077, 6.715, -5.676, -0.5814, -4.290, 0, 0.6750,
     1.067, 4.273, -6.654, 5.893, 0.0480, 4.273, 1.343, -2.104]
).reshape(4, 4)  # fmt: skip
KNV_B = np.array([0, 5.679, 1.136, 1.136, 0, 0, -3.146, 0]).reshape(4, 2)
CAR_A = np.array([[0, 7, 0, 0], [0, 0, 0, 7 / 3.0], [0, 0, 0, 0], [0, 0, 0, 0]])
CAR_B = np.array([[0, 0], [0, 0], [1, 0], [0, 1]])
MONTE_CARLO_A = np.array(
    [-2148, -2902, -2267, -598, -1722, -1829, -165, -283, -2546, -167, -754, -2285,
     -543, -1700, -584, -2978, -925, -1300, -1583, -984, -386, -2650, -764, -897,
     -517, -1598, 2, -1709, -291, -338, -153, -1804, -1106, -1168, -867, -2297]
).reshape(6, 6).astype(float)  # fmt: skip
MONTE_CARLO_B = np.array(
    [-108, -374, -524, -1285, -1232, -161, -1204, -672, -637, -15, -483, -23, -931, -780,
     -1245, -1129, -1290, -1502, -952, -1374, -62, -964, -930, -939, -792, -756, -1437,
     -491, -1543, -686]
).reshape(6, 5).astype(float)  # fmt: skip


@pytest.mark.parametrize(
    ("A", "B", "poles"),
    [
        (KNV_A, KNV_B, [-0.2, -0.5, -5.0566, -8.6659]),
        (KNV_A, KNV_B, [2, 2, 3, 3]),
        (CAR_A, CAR_B, [-3, -1, -2 - 1j, -2 + 1j]),
        (CAR_A, CAR_B, [0 - 1e-6j, 0 + 1e-6j, -10, 10]),
        (
            MONTE_CARLO_A,
            MONTE_CARLO_B,
            [-25 - 29j, -25 + 29j, 31 - 42j, 31 + 42j, 33 - 41j, 33 + 41j],
        ),
        (
            KNV_A,
            np.column_stack([KNV_B, [1, 2, 3, 4], [5, 6, 7, 8]]),
            [-0.2, -0.5, -5.0566, -8.6659],
        ),
        (KNV_A, KNV_B[:, :1], [-2 + 1j, -2 - 1j, -3, -2]),
    ],
    ids=[
        "knv-example-1",
        "knv-repeated",
        "car",
        "car-near-zero",
        "monte-carlo",
        "square-B",
        "one-column",
    ],
)
def test_kautsky_nichols_van_dooren_examples(A, B, poles) -> None:
    signal = pytest.importorskip("scipy.signal")
    design = aerocontrol.place(A, B, poles)
    their = signal.place_poles(A, B, poles)
    their_error = _matched_error(np.linalg.eigvals(A - B @ their.gain_matrix), np.asarray(poles))
    assert design.max_relative_error <= max(1e-8, 10 * their_error)
    np.testing.assert_allclose(A - B @ design.K, design.closed_loop, atol=1e-12 * np.abs(A).max())


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(2, 6),
    seed=st.integers(0, 2**32 - 1),
)
def test_property_poles_are_placed(n: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    A = rng.uniform(-2, 2, (n, n))
    b = rng.uniform(-1, 1, n)
    poles = -rng.uniform(0.1, 3, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IllConditionedWarning)
        for placer in SINGLE_INPUT:
            design = placer(A, b, poles)
            # Gains exact for a problem perturbed by about u κ(V): the poles move by that much
            # times their sensitivity, bounded here through the closed-loop eigenvector matrix.
            closed = A - np.outer(b, design.k)
            values, vectors = np.linalg.eig(closed)
            sensitivity = np.linalg.cond(vectors)
            scale = np.linalg.norm(closed) + np.linalg.norm(A)
            tolerance = 1e3 * np.finfo(float).eps * design.controllability_condition
            tolerance *= sensitivity * scale + 1.0
            assert _matched_error(values, poles) * np.abs(poles).max() <= tolerance


def test_multi_input_repeated_poles() -> None:
    design = aerocontrol.place(A_LAT, B_LAT, [-1, -1, -2, -3])
    assert design.max_relative_error < 1e-6
    with pytest.raises(InvalidArgumentError, match=r"poles\[0\] = -1 is repeated 3 times.*rank 2"):
        aerocontrol.place(A_LAT, B_LAT, [-1, -1, -1, -3])
    # The single-input formulas accept any multiplicity; a 4-fold pole moves by about u^(1/4).
    with pytest.warns(IllConditionedWarning, match="repeated or close together"):
        design = aerocontrol.place_bass_gura(A_LAT, RUDDER, [-1, -1, -1, -1])
    assert 1e-6 < design.max_relative_error < 1e-3
    np.testing.assert_allclose(np.poly(design.closed_loop), np.poly([-1, -1, -1, -1]), atol=1e-10)


def test_bad_requests_name_the_argument() -> None:
    with pytest.raises(ShapeError, match="poles must have one entry per state of A \\(4\\), got 3"):
        aerocontrol.place(A_LAT, B_LAT, [-1, -2, -3])
    with pytest.raises(InvalidArgumentError, match=r"poles\[1\] = -1\+2j has no complex conjugate"):
        aerocontrol.place_bass_gura(A_LAT, RUDDER, [-3, -1 + 2j, -1 + 2j, -2])
    with pytest.raises(NonFiniteError, match="poles"):
        aerocontrol.place_ackermann(A_LAT, RUDDER, [-1, np.inf, -2, -3])
    with pytest.raises(ShapeError, match="poles must be a 1-D"):
        aerocontrol.place(A_LAT, B_LAT, [[-1, -2], [-3, -4]])
    with pytest.raises(InvalidArgumentError, match="use place\\(\\) for several inputs"):
        aerocontrol.place_bass_gura(A_LAT, B_LAT, [-1, -2, -3, -4])
    with pytest.raises(InvalidArgumentError, match="column 1 of B is zero"):
        aerocontrol.place(A_LAT, np.column_stack([RUDDER, np.zeros(4)]), [-1, -2, -3, -4])
    with pytest.raises(InvalidArgumentError, match="rank 1"):
        aerocontrol.place(A_LAT, np.column_stack([RUDDER, 2 * RUDDER]), [-1, -2, -3, -4])
    with pytest.raises(NonFiniteError, match=r"B\[2, 0\]"):
        aerocontrol.place(A_LAT, [[0], [1], [np.nan], [0]], [-1, -2, -3, -4])
    with pytest.raises(InvalidArgumentError, match="poles must be numbers"):
        aerocontrol.place(A_LAT, B_LAT, ["a", "b", "c", "d"])


@pytest.mark.parametrize("placer", [*SINGLE_INPUT, aerocontrol.place])
def test_uncontrollable_pairs_name_the_eigenvalue(placer) -> None:
    # (6.84): B = [-1, 1]^T cannot move the eigenvalue -2.
    with pytest.raises(UncontrollableError, match="no state feedback can move the eigenvalue -2"):
        placer([[0, 1], [-2, -3]], [[-1], [1]], [-3, -4])


def test_ill_conditioned_controllability_warns() -> None:
    # A chain of widely spaced integrators: κ(V) far above 1e8.
    n = 8
    A = np.diag(10.0 ** np.arange(n))
    b = np.ones(n)
    with pytest.warns(
        IllConditionedWarning, match="controllability matrix condition number"
    ) as record:
        design = aerocontrol.place_ackermann(A, b, -np.arange(1.0, n + 1))
    assert design.controllability_condition > 1e8
    # The warning points at the caller, not into the package.
    assert record[0].filename == __file__


def test_inputs_are_not_modified_and_results_are_fresh() -> None:
    A, B, poles = A_LAT.copy(), B_LAT.copy(), _dutch_roll_request().copy()
    for call in (
        lambda: aerocontrol.place(A, B, poles),
        lambda: aerocontrol.place_bass_gura(A, B[:, 0], poles),
        lambda: aerocontrol.companion_form(A, B[:, :1]),
    ):
        call()
        np.testing.assert_array_equal(A, A_LAT)
        np.testing.assert_array_equal(B, B_LAT)
        np.testing.assert_array_equal(poles, _dutch_roll_request())


def test_systems_are_accepted() -> None:
    sys = aerocontrol.StateSpace(A_LAT, B_LAT[:, :1])
    poles = _dutch_roll_request()
    np.testing.assert_allclose(
        aerocontrol.place_bass_gura(sys, poles).K,
        aerocontrol.place_bass_gura(A_LAT, RUDDER, poles).K,
    )
    assert aerocontrol.place((A_LAT, B_LAT), poles).K.shape == (2, 4)
    text = str(aerocontrol.place(A_LAT, B_LAT, poles))
    assert "Kautsky-Nichols-Van Dooren" in text and "largest relative pole error" in text
    with pytest.raises(ShapeError, match="k is defined for one input"):
        _ = aerocontrol.place(A_LAT, B_LAT, poles).k


def test_the_result_is_frozen_and_pickles() -> None:
    design = aerocontrol.place_ackermann([[0, 1], [-2, -3]], [0, 1], [-5, -6])
    assert isinstance(design, aerocontrol.Placement)
    with pytest.raises(AttributeError):
        design.K = np.zeros((1, 2))  # type: ignore[misc]
    copy = pickle.loads(pickle.dumps(design))
    np.testing.assert_array_equal(copy.K, [[28.0, 8.0]])
    np.testing.assert_array_equal(copy.closed_loop, [[0.0, 1.0], [-30.0, -11.0]])
    np.testing.assert_array_equal(copy.achieved_poles, design.achieved_poles)
    assert (copy.method, copy.iterations, copy.converged) == ("Ackermann", 0, True)
    assert copy.controllability_condition == design.controllability_condition == 16.0
    assert np.isnan(copy.eigenvector_condition)
    text = repr(design)
    assert text.startswith("Placement(K=array([[28.,  8.]]), closed_loop=array(")
    assert "method='Ackermann'" in text and "eigenvector_condition=nan)" in text
    assert "controllability_condition=16.0" in text and "converged=True" in text


def test_strided_and_reversed_views_are_read_as_given() -> None:
    # The core reads numpy's shape and strides directly: transposed, reversed and sliced
    # views must give what their copies give.
    poles = _dutch_roll_request()
    reference = aerocontrol.place(A_LAT, B_LAT, poles)
    wide = np.zeros((4, 8))
    wide[:, ::2] = A_LAT
    for A, B, P in (
        (np.asfortranarray(A_LAT), np.asfortranarray(B_LAT), poles),
        (wide[:, ::2], B_LAT[::-1][::-1], np.repeat(poles, 2)[::2]),
        (A_LAT.T.copy().T, np.ascontiguousarray(B_LAT[:, ::-1])[:, ::-1], poles[::-1][::-1]),
    ):
        design = aerocontrol.place(A, B, P)
        np.testing.assert_array_equal(design.K, reference.K)
        np.testing.assert_array_equal(design.poles, reference.poles)


def test_odd_strides_and_misaligned_data_are_read_as_given() -> None:
    # numpy allows byte strides that are not multiples of the item size (a field of a packed
    # structured array) and data at odd addresses: both must be read as their copies are,
    # never reinterpreted at rounded-down strides.
    poles = _dutch_roll_request()
    reference = aerocontrol.place(A_LAT, B_LAT, poles)
    packed = np.zeros((4, 4), dtype=[("x", "<f8"), ("pad", "V1")])
    packed["x"] = A_LAT
    assert packed["x"].strides == (36, 9) and not packed["x"].flags.aligned
    np.testing.assert_array_equal(aerocontrol.place(packed["x"], B_LAT, poles).K, reference.K)
    np.testing.assert_array_equal(aerocontrol.expm(packed["x"]), aerocontrol.expm(A_LAT))
    shifted = np.frombuffer(b"\0" + poles.astype(complex).tobytes(), dtype=complex, offset=1)
    packed_poles = np.zeros(4, dtype=[("z", "<c16"), ("pad", "V1")])
    packed_poles["z"] = poles
    for P in (shifted, packed_poles["z"]):
        assert not P.flags.aligned
        np.testing.assert_array_equal(aerocontrol.place(A_LAT, B_LAT, P).K, reference.K)
    # Complex poles read 8 bytes apart: the values numpy shows, -1 and -2j, whose missing
    # conjugate is named (a rounded-down stride would have read -1 four times and placed them).
    halves = np.lib.stride_tricks.as_strided(np.array([-1, -2, -3, -4], complex), (2,), (8,))
    with pytest.raises(aerocontrol.InvalidArgumentError, match=r"poles\[1\] = 0-2j"):
        aerocontrol.place_bass_gura([[0, 1], [-2, -3]], [0, 1], halves)


def test_a_placement_built_by_hand_checks_its_shapes() -> None:
    design = aerocontrol.place_ackermann([[0, 1], [-2, -3]], [0, 1], [-5, -6])
    fields = (design.K, design.closed_loop, design.poles, design.achieved_poles)
    scalars = (0.0, 0, True, "hand", 1.0, 1.0)
    assert aerocontrol.Placement(*fields, *scalars).k.tolist() == [28.0, 8.0]
    for broken in (
        (np.array(1.0), *fields[1:]),
        (design.K.ravel(), *fields[1:]),
        (*fields[:3], design.achieved_poles[:1]),
        (design.K, np.zeros((2, 3)), *fields[2:]),
    ):
        with pytest.raises(aerocontrol.ShapeError, match="Placement needs K"):
            aerocontrol.Placement(*broken, *scalars)


def test_augment_mode_selects_and_changes_one_mode() -> None:
    modes = aerocontrol.modes(A_LAT, mode_names=["spiral", "Dutch roll", "roll"])
    by_name = aerocontrol.augment_mode(modes, "dutch roll", zeta=0.30)
    by_value = aerocontrol.augment_mode(A_LAT, -0.08 + 0.74j, zeta=0.30)
    np.testing.assert_allclose(np.sort_complex(by_name), np.sort_complex(by_value))
    np.testing.assert_allclose(np.sort_complex(by_name), np.sort_complex(_dutch_roll_request()))
    # Same ω_n, new ζ; other poles untouched.
    pair = by_name[np.abs(by_name.imag) > 0]
    np.testing.assert_allclose(np.abs(pair), modes.natural_frequency[1], rtol=1e-14)
    np.testing.assert_allclose(-pair.real / np.abs(pair), 0.30, rtol=1e-14)
    # ζ >= 1 splits the pair; a real mode takes omega_n only.
    split = aerocontrol.augment_mode(A_LAT, 1, zeta=2.0, omega_n=1.0)
    assert np.all(split.imag == 0)
    faster_spiral = aerocontrol.augment_mode(A_LAT, "spiral" if False else 0, omega_n=0.5)
    assert np.isclose(faster_spiral, -0.5).sum() == 1
    with pytest.raises(InvalidArgumentError, match="is real"):
        aerocontrol.augment_mode(A_LAT, 0, zeta=0.5)
    with pytest.raises(InvalidArgumentError, match="not one of the modes"):
        aerocontrol.augment_mode(modes, "phugoid", zeta=0.5)
    with pytest.raises(InvalidArgumentError, match="out of range"):
        aerocontrol.augment_mode(A_LAT, 7, zeta=0.5)


@pytest.mark.parametrize("placer", [*SINGLE_INPUT, aerocontrol.place])
def test_an_empty_system_has_nothing_to_place(placer) -> None:
    design = placer(np.zeros((0, 0)), np.zeros((0, 1)), [])
    assert design.K.shape == (1, 0) and design.max_relative_error == 0.0


def test_a_system_given_with_its_second_matrix_is_refused_by_name() -> None:
    """place(sys, B, poles) and the controllability functions with a system and a matrix:
    the system has its own B (or C), and the call is refused by an InvalidArgumentError
    naming it (it was a NotRealError saying that A has dtype object); the system alone
    gives the gain of the matrices, k = (4, 2) for the poles -2, -3 of (6.81)'s pair."""
    A, b = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]])
    sys = aerocontrol.StateSpace(A, b)
    calls = [
        lambda: aerocontrol.place(sys, b, [-2.0, -3.0]),
        lambda: aerocontrol.place_bass_gura(sys, b, [-2.0, -3.0]),
        lambda: aerocontrol.place_ackermann(sys, b, [-2.0, -3.0]),
        lambda: aerocontrol.companion_form(sys, b),
        lambda: aerocontrol.controllability(sys, b),
        lambda: aerocontrol.is_controllable(sys, b),
    ]
    for call in calls:
        with pytest.raises(aerocontrol.InvalidArgumentError, match="has its own B") as info:
            call()
        assert info.value.argument == "B"
    for call in (
        lambda: aerocontrol.observability(sys, [[1.0, 0.0]]),
        lambda: aerocontrol.is_observable(sys, [[1.0, 0.0]]),
    ):
        with pytest.raises(aerocontrol.InvalidArgumentError, match="has its own C"):
            call()
    for place in (aerocontrol.place, aerocontrol.place_bass_gura, aerocontrol.place_ackermann):
        np.testing.assert_allclose(place(sys, [-2.0, -3.0]).K, [[4.0, 2.0]], rtol=1e-12)


@pytest.mark.parametrize("scale", [1e4, 1e6, 1e8])
def test_placement_of_states_scaled_far_apart(scale: float) -> None:
    """A controllable pair with its states scaled by 1/scale, 1, scale, 1 (A = T A0 T^-1,
    B = T B0): every method places the poles -1 .. -4 to 1e-9 (the eigenvalues of A - B K
    by numpy), K = K0 T^-1 for the gain K0 of the unscaled pair to 1e-9 relatively (the
    single-input gain is unique), and A - B K is the closed loop reported; unbalanced, KNV
    missed the poles by 147 % at 1e6 and every method refused the pair as uncontrollable at
    1e8. place_batch places each problem exactly as the single functions."""
    rng = np.random.default_rng(11)
    A0, B0 = rng.standard_normal((4, 4)), rng.standard_normal((4, 2))
    T = np.diag([1.0 / scale, 1.0, scale, 1.0])
    A, B = T @ A0 @ np.linalg.inv(T), T @ B0
    poles = [-1.0, -2.0, -3.0, -4.0]
    for place, inputs in (
        (aerocontrol.place, B),
        (aerocontrol.place_bass_gura, B[:, :1]),
        (aerocontrol.place_ackermann, B[:, :1]),
    ):
        design = place(A, inputs, poles)
        closed = A - inputs @ design.K
        achieved = np.sort(np.linalg.eigvals(closed).real)
        np.testing.assert_allclose(achieved, [-4.0, -3.0, -2.0, -1.0], rtol=1e-9)
        np.testing.assert_allclose(design.closed_loop, closed, rtol=0, atol=1e-12 * scale**2)
        if inputs.shape[1] == 1:
            K0 = place(A0, B0[:, :1], poles).K
            np.testing.assert_allclose(design.K, K0 @ np.linalg.inv(T), rtol=1e-9)
    for method, single, inputs in (
        ("knv", aerocontrol.place, B),
        ("bass-gura", aerocontrol.place_bass_gura, B[:, :1]),
    ):
        stack = np.stack([A, A0])
        batch = aerocontrol.batch.place_batch(stack, np.stack([inputs, inputs]), poles, method)
        for i, plant in enumerate(stack):
            np.testing.assert_array_equal(batch.K[i], single(plant, inputs, poles).K)
        shared = aerocontrol.batch.place_batch(A, inputs, [poles, poles], method)
        np.testing.assert_array_equal(shared.K[1], single(A, inputs, poles).K)
