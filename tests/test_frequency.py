"""Frequency response (chapter §6.3) against a direct complex solve at every frequency, and
against python-control."""

from __future__ import annotations

import control
import numpy as np
import pytest

import aerocontrol
from aerocontrol import NonFiniteError, ShapeError

A_LON, B_LON = aerocontrol.chapter.boeing747_longitudinal()


def _direct(sys: aerocontrol.StateSpace, omega: np.ndarray) -> np.ndarray:
    n = sys.n_states
    return np.stack(
        [sys.C @ np.linalg.solve(1j * w * np.eye(n) - sys.A, sys.B) + sys.D for w in omega]
    )


def _random(n: int, m: int, p: int, seed: int) -> aerocontrol.StateSpace:
    rng = np.random.default_rng(seed)
    return aerocontrol.StateSpace(
        rng.standard_normal((n, n)),
        rng.standard_normal((n, m)),
        rng.standard_normal((p, n)),
        rng.standard_normal((p, m)),
    )


@pytest.mark.parametrize(
    "sys",
    [
        aerocontrol.StateSpace(A_LON, B_LON),
        aerocontrol.StateSpace(*aerocontrol.chapter.boeing747_lateral()),
        _random(7, 2, 3, 1),
        _random(64, 2, 2, 2),
    ],
    ids=["747-longitudinal", "747-lateral", "random-7", "random-64"],
)
def test_against_a_direct_complex_solve(sys: aerocontrol.StateSpace) -> None:
    omega = np.concatenate([[0.0], np.logspace(-3, 3, 300), [-1.5]])
    ours = aerocontrol.frequency_response(sys, omega).response
    reference = _direct(sys, omega)
    relative = np.abs(ours - reference).max(axis=(1, 2)) / np.abs(reference).max(axis=(1, 2))
    assert relative.max() <= 1e-12, relative.max()


def test_against_python_control() -> None:
    sys = aerocontrol.StateSpace(*aerocontrol.chapter.boeing747_lateral())
    omega = np.logspace(-2, 1, 200)
    ours = aerocontrol.frequency_response(sys, omega)
    peer = control.frequency_response(control.ss(sys.A, sys.B, sys.C, sys.D), omega)
    np.testing.assert_allclose(ours.magnitude, peer.magnitude.transpose(2, 0, 1), rtol=1e-10)


def test_bode_magnitude_and_unwrapped_phase() -> None:
    # A double pole lag 1/(s + 1)^2: magnitude -20 log10(1 + ω^2), phase -2 arctan ω, which
    # passes -180 degrees only at infinity; a triple lag must unwrap past -180.
    triple = aerocontrol.StateSpace(
        [[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [0.0, 0.0, -1.0]],
        [[0.0], [0.0], [1.0]],
        [[1.0, 0.0, 0.0]],
    )
    omega = np.logspace(-2, 3, 500)
    b = aerocontrol.bode(triple, omega)
    np.testing.assert_allclose(b.magnitude_db[:, 0, 0], -30 * np.log10(1 + omega**2), atol=1e-10)
    np.testing.assert_allclose(b.phase_deg[:, 0, 0], -3 * np.degrees(np.arctan(omega)), atol=1e-9)
    assert b.phase_deg[-1, 0, 0] < -260


def test_default_grid_spans_the_modes() -> None:
    b = aerocontrol.bode((A_LON, B_LON))
    magnitudes = np.abs(np.linalg.eigvals(A_LON))
    assert len(b.omega) == 1000
    assert b.omega[0] == pytest.approx(magnitudes.min() / 10)
    assert b.omega[-1] == pytest.approx(magnitudes.max() * 10)
    assert "peak" in str(b)


def test_bad_arguments() -> None:
    with pytest.raises(NonFiniteError, match=r"omega\[1\]"):
        aerocontrol.frequency_response((A_LON, B_LON), [1.0, np.nan])
    with pytest.raises(ShapeError, match="omega must be a 1-D array"):
        aerocontrol.frequency_response((A_LON, B_LON), np.ones((2, 2)))


def test_the_count_of_the_default_grid_is_checked() -> None:
    # Found by the property suite: a negative count was numpy's bare ValueError.
    for count in (0, -1, 2.5, True, "10"):
        with pytest.raises(aerocontrol.InvalidArgumentError, match="count must be a positive"):
            aerocontrol.default_frequency_grid((A_LON, B_LON), count)  # type: ignore[arg-type]
    assert len(aerocontrol.default_frequency_grid((A_LON, B_LON), np.int64(3))) == 3


def test_frequency_response_of_badly_scaled_states_is_that_of_the_model() -> None:
    """A well-conditioned 4-state 2 x 2 model (cond(A) = 8) in states scaled by
    10^(-4, -3, 4, 6): the core's Hessenberg solve has errors relative to the size of the
    matrix it is given, and the response was wrong by 1.6e-3 of its size; the states are now
    balanced first (exact powers of two). Oracle: numpy's solve of the unscaled model, and
    python-control's frequency_response of it; also 50 random scaled models (2 to 6 states)."""
    A = np.array(
        [
            [-1.5578037015944788, -1.4641393051201623, 0.26913287834979754, 0.5642681004713006],
            [1.467471704389781, -1.703154654560851, 0.24120445283023215, 0.08867354909967969],
            [-0.05003194727880665, 1.1474753245159799, -3.2809249028907703, 0.5302385977171965],
            [-0.08412698087139053, 0.2503985407752395, -0.25238638051859014, -0.48775170060637674],
        ]
    )
    B = np.array(
        [
            [-0.6467331644864861, 0.26380847414351544],
            [0.28688782084437325, 0.6192367647758478],
            [0.4617531850459596, 0.4360343563754495],
            [0.9934980811484962, -1.4932654754390196],
        ]
    )
    C = np.array(
        [
            [0.021734239849973837, -1.221681561296693, 0.24459577811774602, -1.1706072134118364],
            [-0.9478177259625263, -0.04824624693552761, 1.4088457450675202, 0.5899841756446085],
        ]
    )
    D = np.array(
        [[0.09279650732959999, 0.42484393366617484], [-0.27967821908561374, -0.6237068580187078]]
    )
    omega = np.array([1e-3, 0.1, 3.0, 40.0])
    theirs = control.ss(A, B, C, D)(1j * omega)  # (outputs, inputs, frequencies)
    cases = [(A, B, C, D, [-4, -3, 4, 6])]
    rng = np.random.default_rng(5)
    for _ in range(50):
        n = int(rng.integers(2, 7))
        M = rng.standard_normal((n, n))
        M -= (np.max(np.linalg.eigvals(M).real) + 0.5) * np.eye(n)
        cases.append(
            (
                M,
                rng.standard_normal((n, 2)),
                rng.standard_normal((1, n)),
                np.zeros((1, 2)),
                list(rng.integers(-6, 7, n)),
            )
        )
    for M, b, c, d, exponents in cases:
        scaled = aerocontrol.StateSpace(*_scaled(M, b, c, exponents), d)
        ours = aerocontrol.frequency_response(scaled, omega).response
        n = M.shape[0]
        exact = np.array([c @ np.linalg.solve(1j * w * np.eye(n) - M, b) + d for w in omega])
        assert np.max(np.abs(ours - exact)) <= 1e-12 * np.max(np.abs(exact))
    ours = aerocontrol.frequency_response(
        aerocontrol.StateSpace(*_scaled(A, B, C, [-4, -3, 4, 6]), D), omega
    ).response
    np.testing.assert_allclose(ours, np.moveaxis(theirs, -1, 0), rtol=1e-12, atol=0)


def _scaled(
    A: np.ndarray, B: np.ndarray, C: np.ndarray, exponents: list[int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """T A T⁻¹, T B, C T⁻¹ with T = diag(10^e): the same model in badly scaled states."""
    t = 10.0 ** np.array(exponents, dtype=float)
    return A * (t[:, None] / t[None, :]), B * t[:, None], C / t[None, :]


@pytest.mark.parametrize(
    ("A", "dt", "slowest", "fastest"),
    [
        (np.diag([-1e6, -1e-7]), None, 1e-7, 1e6),
        (np.array([[-1e6, 1.0], [0.0, -1e-7]]), None, 1e-7, 1e6),
        (np.diag([-1.0, -1e-13]), None, 1e-13, 1.0),
        # z = 1 - 1e-14: s = ln(z)/dt = -1.0000000000000049e-13 rad/s
        (np.diag([0.5, 1.0 - 1e-14]), 0.1, -np.log1p(-1e-14) / 0.1, np.pi / 0.1),
    ],
)
def test_default_frequency_grid_reaches_the_slowest_mode_of_a_stiff_model(
    A: np.ndarray, dt: float | None, slowest: float, fastest: float
) -> None:
    """Found by a hunt: a mode slower than 1e-12 of the fastest (or of the Nyquist frequency)
    was taken as zero, so the grid started at a tenth of the fast mode (1e5 rad/s for modes
    of 1e-7 and 1e6) and missed the slow corner, where the gain is 1e7. Now from a tenth of
    the slowest natural frequency, as promised (the closed forms above, to 1e-6: the grid's
    ends are 10^(log10 ω ∓ 1))."""
    n = A.shape[0]
    model = aerocontrol.StateSpace(A, np.ones((n, 1)), np.ones((1, n)), np.zeros((1, 1)), dt=dt)
    omega = aerocontrol.default_frequency_grid(model)
    assert omega[0] == pytest.approx(slowest / 10.0, rel=1e-6)
    upper = fastest if dt else fastest * 10.0
    assert omega[-1] == pytest.approx(upper, rel=1e-6)


@pytest.mark.parametrize("dt", [1e-4, 1e-8, 1e-10])
def test_discrete_response_of_a_model_sampled_fast(dt: float) -> None:
    """Found by a hunt: a model sampled fast against its modes (A = e^{A_c dt}, eigenvalues
    clustered at z = 1) lost a relative u / (ω dt²) of G at low frequencies, silently: 1.7e-4
    at dt = 1e-10, ω = 1e-3 rad/s (Hessenberg errors of u ||A|| beside A - I of size dt).
    Now evaluated about z = 1, C ((z - 1) I - (A - I))^-1 B: against the resolvent in 50-digit
    arithmetic (mpmath, A and B, C as given, z = e^{jω dt} exact), to 1e-12."""
    import mpmath
    import scipy.linalg

    rng = np.random.default_rng(1)
    n = 6
    A_c = rng.standard_normal((n, n)) / np.sqrt(n) - 0.5 * np.eye(n)
    B, C = rng.standard_normal((n, 1)), rng.standard_normal((1, n))
    A = scipy.linalg.expm(A_c * dt)
    omega = np.array([1e-3, 1e-1, 10.0, 1e3])
    response = aerocontrol.frequency_response(
        aerocontrol.StateSpace(A, B, C, np.zeros((1, 1)), dt=dt), omega
    ).response[:, 0, 0]
    with mpmath.workdps(50):
        for k, w in enumerate(omega):
            z = mpmath.exp(mpmath.mpc(0, 1) * mpmath.mpf(float(w)) * mpmath.mpf(dt))
            M = mpmath.matrix(n, n)
            for i in range(n):
                for j in range(n):
                    M[i, j] = (z if i == j else 0) - mpmath.mpf(float(A[i, j]))
            x = mpmath.lu_solve(M, mpmath.matrix([mpmath.mpf(float(b)) for b in B[:, 0]]))
            exact = complex(sum(mpmath.mpf(float(C[0, i])) * x[i] for i in range(n)))
            assert abs(response[k] - exact) <= 1e-12 * abs(exact)


def _lightly_damped(n: int, seed: int) -> aerocontrol.StateSpace:
    """n/2 modes (n even) of natural frequencies 0.3-30 rad/s and damping ratios 0.002-0.05 in
    coordinates rotated by a random orthogonal matrix, 2 inputs, 2 outputs."""
    rng = np.random.default_rng(seed)
    A = np.zeros((n, n))
    for k in range(0, n - 1, 2):
        w, z = 10 ** rng.uniform(-0.5, 1.5), 10 ** rng.uniform(-2.7, -1.3)
        wd = w * np.sqrt(1 - z * z)
        A[k : k + 2, k : k + 2] = [[-z * w, wd], [-wd, -z * w]]
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    return aerocontrol.StateSpace(
        Q @ A @ Q.T,
        rng.standard_normal((n, 2)),
        rng.standard_normal((2, n)),
        np.zeros((2, 2)),
    )


def _one_at_a_time(sys: aerocontrol.StateSpace, omega: np.ndarray) -> np.ndarray:
    """The response one frequency per call: always the Hessenberg solve (the partial-fraction
    form is set up only for at least twice as many frequencies as states)."""
    return np.concatenate(
        [aerocontrol.frequency_response(sys, omega[k : k + 1]).response for k in range(len(omega))]
    )


@pytest.mark.parametrize("dt", [None, 0.02])
def test_partial_fraction_form_against_the_resolvent_in_50_digits(dt: float | None) -> None:
    """A 14-state model at 400 frequencies (its partial-fraction form: the sum over the modes
    of A) with lightly damped modes (ζ down to 0.002), continuous and sampled, at the
    frequencies of its resonant peaks and between them: every entry of G against the
    resolvent in 50-digit arithmetic (mpmath) to 30 n u κ(sI - A) of |G| (a backward-stable
    solve's error; at the sampled model's sharpest peak, κ = 6.5e3, the form's error is
    1.6e-11 and the Hessenberg solve's 1.1e-11), and the form was used (the values are not
    the Hessenberg solve's bit for bit)."""
    import mpmath
    import scipy.linalg

    sys = _lightly_damped(14, 3)
    A = sys.A
    if dt is not None:
        A = scipy.linalg.expm(sys.A * dt)
        sys = aerocontrol.StateSpace(A, sys.B, sys.C, sys.D, dt=dt)
    peaks = np.abs(np.linalg.eigvals(sys.A if dt is None else scipy.linalg.logm(A).real / dt))
    omega = np.sort(np.concatenate([np.logspace(-2, 2, 400 - 7), np.unique(peaks)[:7]]))
    response = aerocontrol.frequency_response(sys, omega).response
    assert np.mean(response != _one_at_a_time(sys, omega)) > 0.5
    n = A.shape[0]
    picked = [int(np.argmin(np.abs(omega - p))) for p in np.unique(peaks)[:7]]
    picked += list(range(0, 400, 37))
    with mpmath.workdps(50):
        for k in picked:
            w = mpmath.mpf(float(omega[k]))
            s = mpmath.mpc(0, w) if dt is None else mpmath.exp(mpmath.mpc(0, 1) * w * dt)
            M = mpmath.matrix(n, n)
            for i in range(n):
                for j in range(n):
                    M[i, j] = (s if i == j else 0) - mpmath.mpf(float(A[i, j]))
            point = complex(s)
            tolerance = 30 * n * 2.0**-53 * np.linalg.cond(point * np.eye(n) - A)
            for j in range(2):
                x = mpmath.lu_solve(M, mpmath.matrix([mpmath.mpf(float(b)) for b in sys.B[:, j]]))
                for i in range(2):
                    exact = complex(sum(mpmath.mpf(float(sys.C[i, r])) * x[r] for r in range(n)))
                    assert abs(response[k, i, j] - exact) <= tolerance * abs(exact), (k, i, j)


def test_nearly_defective_models_take_the_hessenberg_solve() -> None:
    """A chain of 16 lags whose poles are split by 1e-7 (eigenvectors nearly parallel: the
    partial-fraction form would lose digits in cancelling residues of 1e100) is refused its
    form: at 500 frequencies G is the Hessenberg solve's, bit for bit."""
    n = 16
    A = np.diag(-1.0 - 1e-7 * np.arange(n)) + np.diag(np.ones(n - 1), 1)
    rng = np.random.default_rng(4)
    sys = aerocontrol.StateSpace(A, rng.standard_normal((n, 1)), rng.standard_normal((1, n)))
    omega = np.logspace(-2, 2, 500)
    response = aerocontrol.frequency_response(sys, omega).response
    np.testing.assert_array_equal(response, _one_at_a_time(sys, omega))


def test_frequencies_at_an_imaginary_axis_pole_with_the_partial_fraction_form() -> None:
    """A 21-state model with poles at 0 and ±2j (an exact 3 x 3 block on the diagonal of a
    block-triangular A, coupled to 18 lightly damped states) at 100 frequencies that include
    0 and 2 rad/s: there, as with the Hessenberg solve, G is infinite, NaN or beyond 1e12 (a
    pole, with the overflow warning; the form refuses points nearer an eigenvalue than its
    error bound); at the other
    frequencies the form's G agrees with a direct complex solve to 1e-12."""
    rng = np.random.default_rng(6)
    n = 21
    A = np.zeros((n, n))
    A[1:3, 1:3] = [[0.0, 2.0], [-2.0, 0.0]]
    A[3:, 3:] = _lightly_damped(18, 5).A
    A[:3, 3:] = rng.standard_normal((3, 18))
    sys = aerocontrol.StateSpace(A, rng.standard_normal((n, 2)), rng.standard_normal((2, n)))
    omega = np.concatenate([[0.0, 2.0], np.logspace(-1, 1.5, 98)])
    with pytest.warns(aerocontrol.NumericalOverflowWarning):
        response = aerocontrol.frequency_response(sys, omega).response
    assert np.mean(response[2:] != _one_at_a_time(sys, omega[2:])) > 0.5
    with pytest.warns(aerocontrol.NumericalOverflowWarning):
        alone = _one_at_a_time(sys, omega[:2])
    for values in (response[:2], alone):
        with np.errstate(invalid="ignore"):
            assert np.all(~np.isfinite(values) | (np.abs(values) > 1e12)), values
    reference = _direct(sys, omega[2:])
    relative = np.abs(response[2:] - reference).max(axis=(1, 2)) / np.abs(reference).max(
        axis=(1, 2)
    )
    assert relative.max() <= 1e-12, relative.max()
