"""Properties of loop analysis (aerocontrol.loops): margins, sensitivities, root locus.

Oracles: the closed-loop poles as the spectrum of A - B (1 + D)^-1 C formed here (backward
errors relative to ||A|| + ||B|| ||C|| / |1 + D|) and the stability flag against their real
parts wherever an eigenvalue's sensitivity (its condition number times n u ||·||) cannot move
it across the axis; at every reported gain crossover |L(jω)| = 1 and at every phase crossover
Im L(jω) = 0 with Re L < 0, to the accuracy of the evaluation (oracles.response_at) plus the
frequency's own rounding (|ω L'(jω)| u); each gain margin 1/|L| and phase margin 180° + ∠L
at its crossover; the encirclements P - Z from the poles. S = 1/(1 + L) and T = L/(1 + L)
against L evaluated directly, within |1 + L|^-2 times L's error. The root locus: each row the
spectrum of A - k B (1 + k D)^-1 C. The damping designs: their closed-loop poles at the gain
they return, their damping ratio that of their pole, ζ reached within 1e-6 (gain_for_damping,
unless it warns), and no grid gain with a stable, better damped loop (best_damping_gain).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import IllConditionedWarning, NumericalOverflowWarning

from .harness import Arg, Warned, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U,
    assert_response,
    assert_within,
    eigenvalue_backward_error,
    eigenvalue_conditions,
    finite,
    norm,
    response_at,
    silenced,
)
from .strategies import (
    SQUARE_KINDS,
    model_matrices,
    presented,
    presented_system,
    scalar,
    system,
)

COVERED = {
    "stability_margins",
    "sensitivity",
    "complementary_sensitivity",
    "root_locus",
    "best_damping_gain",
    "gain_for_damping",
    "nyquist",
    "nichols",
}

TAME = ("stable", "gaussian", "companion", "integers", "imaginary axis", "diagonal")
POINTS = (0.31j, 1.7j, 11.0j)


@st.composite
def loop(draw: st.DrawFn) -> Arg:
    """A SISO loop: a classic k/(s (s + a)(s + b)) or a lightly damped pair (as a StateSpace
    from zpk), or a drawn plant; now and then one with two inputs (to be refused)."""
    kind = draw(st.sampled_from(("classic", "classic", "drawn", "drawn", "drawn", "wide")))
    if kind == "classic":
        rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
        poles = [0.0, -rng.uniform(0.2, 5.0), -rng.uniform(0.2, 5.0)]
        if draw(st.booleans()):
            pair = complex(-rng.uniform(0.01, 0.3), rng.uniform(0.5, 3.0))
            poles[1:] = [pair, pair.conjugate()]
        if draw(st.booleans()):
            poles[0] = rng.uniform(0.1, 1.0)  # an unstable open loop
        k = float(rng.uniform(0.1, 20.0)) * draw(st.sampled_from((1.0, -1.0)))
        zeros = [-rng.uniform(0.5, 4.0)] if draw(st.booleans()) else []
        model = aerocontrol.zpk(zeros, poles, k)
        matrices = (model.A, model.B, model.C, model.D)
        return draw(presented_system(matrices))
    n = draw(st.sampled_from((0, 1, 2, 3, 4, 5)))
    kinds = draw(st.sampled_from((TAME, TAME, SQUARE_KINDS)))
    return draw(presented_system(draw(system(n, 2 if kind == "wide" else 1, 1, kinds))))


def closed_matrix(A: np.ndarray, B: np.ndarray, C: np.ndarray, d: float, k: float) -> Any:
    """(A - k B (1 + k d)^-1 C, the size of its terms) or None for an algebraic loop."""
    with silenced():
        denominator = 1.0 + k * d
        if denominator == 0:
            return None
        # k/(1 + k d) as 1/(1/k + d) where k d overflows (k = 5, d = 1e308: not 5/inf = 0).
        c = k / denominator if np.isfinite(denominator) else 1.0 / (1.0 / k + d)
        return A - c * (B @ C), norm(A) + abs(c) * norm(B) * norm(C)


def assert_poles(A: np.ndarray, size: float, poles: np.ndarray, what: str) -> None:
    n = A.shape[0]
    assert poles.shape == (n,), f"{what}: {poles.shape} poles of order {n}"
    if n == 0 or not finite(A, poles) or not np.isfinite(size):
        return
    bound = SLACK * n * (U * size + TINY)
    for value in poles:
        error = eigenvalue_backward_error(A, complex(value))
        assert_within(error, bound, f"{what}: backward error of the pole {value}")


def clearly(A: np.ndarray, size: float) -> bool | None:
    """Whether every eigenvalue of A has Re < 0, where no eigenvalue is within its
    sensitivity of the axis; None where that cannot be told."""
    if A.shape[0] == 0:
        return True
    if not finite(A):
        return None
    values, conditions = eigenvalue_conditions(A)
    margin = SLACK * A.shape[0] * U * size * conditions
    if np.any(np.abs(values.real) <= margin) or not np.all(np.isfinite(margin)):
        return None
    return bool(np.all(values.real < 0))


def derivative(A: np.ndarray, B: np.ndarray, C: np.ndarray, s: complex) -> float:
    """|L'(s)| = |C (sI - A)^-2 B|."""
    with silenced():
        M = s * np.eye(A.shape[0]) - A
        X = np.linalg.solve(M, np.linalg.solve(M, B.astype(complex)))
        return float(abs((C @ X)[0, 0])) if A.shape[0] else 0.0


def _margins_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, C, D = model_matrices(args["loop"])
    n, d = A.shape[0], float(D[0, 0])
    formed = closed_matrix(A, B, C, d, 1.0)
    assert formed is not None
    closed, size = formed
    assert_poles(closed, size, result.closed_loop_poles, "the closed-loop poles")
    verdict = clearly(closed, size)
    if verdict is not None:
        assert result.closed_loop_stable == verdict, (
            f"closed_loop_stable = {result.closed_loop_stable}, but the poles of "
            f"A - B (1 + D)^-1 C say {verdict}"
        )
    open_verdict = clearly(A, norm(A))
    if open_verdict is not None and n:
        values = np.linalg.eigvals(A)
        assert result.open_loop_unstable_poles == int(np.sum(values.real > 0))
    # Z counts the closed-loop poles in the right half-plane; one within √u ||A - B C|| of the
    # axis may be counted on it (the side rounding puts it is not a property of the loop).
    real = result.closed_loop_poles.real
    clearly_unstable = int(np.sum(real > SLACK * np.sqrt(U) * size))
    unstable_closed = int(np.sum(real > 0))
    P = result.open_loop_unstable_poles
    assert P - unstable_closed <= result.encirclements <= P - clearly_unstable
    if not result.closed_loop_stable:
        assert result.delay_margin == 0 and result.disk_margin == 0
    for crossovers, margins, kind in (
        (result.gain_crossovers, result.phase_margins, "gain"),
        (result.phase_crossovers, result.gain_margins, "phase"),
    ):
        assert len(crossovers) == len(margins)
        assert np.all(np.diff(crossovers) > 0), f"the {kind} crossovers are not increasing"
        for w, margin in zip(crossovers, margins, strict=True):
            value = response_at(A, B, C, D, 1j * w)
            if value is None:
                continue
            G, evaluation = value
            L = complex(G[0, 0])
            with silenced():
                rounding = 8 * U * w * derivative(A, B, C, 1j * w)
                tolerance = SLACK * max(n, 1) * (U * evaluation + rounding) + TINY
            if not np.isfinite(tolerance) or tolerance > 1e-3:
                continue
            if kind == "gain":
                assert_within(abs(abs(L) - 1), tolerance, f"|L(j{w})| at a gain crossover")
                phase = math.radians(float(margin))
                gap = abs(np.exp(1j * phase) - (-L / abs(L)))
                assert_within(gap, 2 * tolerance, f"the phase margin {margin} at ω = {w}")
            else:
                assert_within(abs(L.imag), tolerance * max(abs(L), 1), f"Im L(j{w})")
                assert L.real < 0, f"L(j{w}) = {L} at a phase crossover is not negative"
                assert_within(
                    abs(margin * abs(L) - 1), 2 * tolerance / abs(L), f"gain margin at ω = {w}"
                )
    if len(result.gain_margins):
        critical = int(np.argmin(np.abs(np.log(result.gain_margins))))
        assert result.gain_margin == result.gain_margins[critical]
    else:
        assert result.gain_margin == math.inf
    if len(result.phase_margins):
        assert result.phase_margin == result.phase_margins[np.argmin(np.abs(result.phase_margins))]
    else:
        assert result.phase_margin == math.inf
    try:
        text = str(result)
    except Exception as error:
        raise AssertionError(f"str(margins) raised {type(error).__name__}: {error}") from error
    assert isinstance(text, str)


#: Fields that are NaN or infinite by definition (no crossover, no margin).
UNBOUNDED = (
    "gain_margin",
    "phase_crossover",
    "phase_margin",
    "gain_crossover",
    "delay_margin",
    "delay_margins",
    "gain_margins",
    "disk_frequency",
    "stability_frequency",
    "disk_margin",
    "stability_margin",
)


@given(st.data())
def test_stability_margins(data: st.DataObject) -> None:
    exercise(
        "stability_margins",
        lambda loop: aerocontrol.stability_margins(loop),
        {"loop": data.draw(loop())},
        _margins_oracle,
        nonfinite_by_definition=UNBOUNDED,
    )


# ----- sensitivities ----------------------------------------------------------------------------


def _sensitivity_oracle(complementary: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        A, B, C, D = model_matrices(args["loop"])
        n, d = A.shape[0], float(D[0, 0])
        assert result.A.shape == (n, n) and (result.n_inputs, result.n_outputs) == (1, 1)
        with silenced():
            kappa0 = (1 + abs(d)) / abs(1 + d)
        for s in POINTS:
            value = response_at(A, B, C, D, s)
            if value is None:
                continue
            G, size = value
            L = np.complex128(G[0, 0])  # numpy's arithmetic: an overflow is inf, not an error
            with silenced():
                expected = L / (1 + L) if complementary else 1 / (1 + L)
                allowed = (
                    SLACK
                    * max(n, 1)
                    * U
                    * (size / abs(1 + L) ** 2)
                    * kappa0
                    * (1 + norm(B) * norm(C) / max(norm(A), TINY))
                )
            if not np.isfinite(allowed) or not np.isfinite(expected):
                continue
            what = "T = L/(1 + L)" if complementary else "S = 1/(1 + L)"
            assert_response(result, np.array([[expected]]), s, allowed, what)

    return oracle


@given(st.data())
def test_sensitivities(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("sensitivity", "complementary_sensitivity")))
    exercise(
        name,
        getattr(aerocontrol, name),
        {"loop": data.draw(loop())},
        _sensitivity_oracle(name == "complementary_sensitivity"),
    )


# ----- root locus -------------------------------------------------------------------------------


def _locus_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, C, D = model_matrices(args["loop"])
    n, d = A.shape[0], float(D[0, 0])
    gains = np.atleast_1d(np.asarray(args["gains"], float))
    assert np.array_equal(result.gains, gains)
    assert result.poles.shape == (gains.size, n) and result.poles.dtype == np.complex128
    for k, row in zip(gains, result.poles, strict=True):
        assert np.array_equal(row, np.sort_complex(row)), "a row of poles is not sorted"
        formed = closed_matrix(A, B, C, d, float(k))
        if formed is not None:
            assert_poles(formed[0], formed[1], row, f"the poles at k = {k}")
    _assert_open_loop_poles(A, result)


def _assert_open_loop_poles(A: np.ndarray, result: Any) -> None:
    """The open-loop poles, read (on first use) with their warnings caught: poles beyond the
    doubles come with aerocontrol's NumericalOverflowWarning, which is part of what is checked
    (under pytest's error filter it was raised inside the oracle, A = 1e308 ones, and failed
    the property). A pole is infinite, with the warning, exactly where the eigenvalue computed
    of A scaled to unit size by a power of two and scaled back is beyond the doubles (to the
    rounding of that scaling); otherwise the poles pass the backward error check."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        poles = result.open_loop_poles
    categories = {w.category for w in caught}
    assert categories <= {NumericalOverflowWarning}, f"warnings {categories} reading the poles"
    overflowed = not finite(poles)
    assert overflowed == (NumericalOverflowWarning in categories), (
        f"open-loop poles {poles} with the warnings {categories}"
    )
    if A.shape[0] and finite(A):
        reference, _ = eigenvalue_conditions(A)
        with np.errstate(over="ignore"):
            largest = float(np.max(np.maximum(np.abs(reference.real), np.abs(reference.imag))))
        if overflowed:
            # Infinite only for an eigenvalue at the edge of the doubles or beyond.
            assert largest >= (1 - 1e-6) * np.finfo(float).max, (
                f"open-loop poles {poles} overflowed where the eigenvalues are {reference}"
            )
        else:
            ours = float(np.max(np.maximum(np.abs(poles.real), np.abs(poles.imag))))
            assert largest < np.inf or ours >= (1 - 1e-6) * np.finfo(float).max, (
                f"finite open-loop poles {poles} where the eigenvalues are {reference}"
            )
    assert_poles(A, norm(A), poles, "the open-loop poles")


GAINS = (
    np.array([0.0, 1.0, 5.0]),
    np.array([0.5]),
    np.logspace(-2, 2, 7),
    np.array([-1.0, 2.0]),
    np.array([1e300, 1.0]),
    np.linspace(-3.0, 3.0, 241),  # runs of the core's continuation, through breakaway points
    np.logspace(-4.0, 4.0, 161),
    np.zeros(0),
    np.array([1.0, np.nan]),
    np.ones((2, 2)),
)


@given(st.data())
def test_root_locus(data: st.DataObject) -> None:
    gains = GAINS[data.draw(st.integers(0, len(GAINS) - 1))]
    outcome = exercise(
        "root_locus",
        lambda loop, gains: aerocontrol.root_locus(loop, gains),
        {"loop": data.draw(loop()), "gains": data.draw(presented(gains))},
        _locus_oracle,
    )
    if gains.ndim != 1 or gains.size == 0:
        assert outcome.error is not None, f"root_locus accepted gains of shape {gains.shape}"


# ----- damping designs --------------------------------------------------------------------------


def least_damping(poles: np.ndarray) -> float:
    oscillatory = poles[poles.imag > 1e-9 * np.abs(poles)]
    if oscillatory.size == 0:
        return 1.0
    return float(np.min(-oscillatory.real / np.abs(oscillatory)))


def _design_oracle(name: str) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        A, B, C, D = model_matrices(args["loop"])
        d = float(D[0, 0])
        assert result.gain >= 0 and np.isfinite(result.gain)
        formed = closed_matrix(A, B, C, d, result.gain)
        assert formed is not None
        assert_poles(formed[0], formed[1], result.closed_loop_poles, "the design's poles")
        pole = result.pole
        if np.isnan(pole.real) or abs(pole.imag) <= 1e-9 * abs(pole):
            assert result.damping_ratio == 1.0, "ζ is 1 where the pole does not oscillate"
        else:
            assert pole.imag >= 0
            assert abs(result.damping_ratio - (-pole.real / abs(pole))) <= 1e-12
        if name == "gain_for_damping":
            if IllConditionedWarning not in warned:
                assert_within(
                    abs(result.damping_ratio - float(args["zeta"])), 1e-6, "ζ at the gain found"
                )
        elif args["mode"] is None and args["gains"] is not None:
            achieved = result.damping_ratio
            for k in np.asarray(args["gains"], float):
                formed = closed_matrix(A, B, C, d, float(k))
                if formed is None or not finite(formed[0]):
                    continue
                poles = np.linalg.eigvals(formed[0])
                if np.all(poles.real < -1e-6 * (1 + np.abs(poles))):
                    assert least_damping(poles) <= achieved + 1e-6, (
                        f"k = {k} damps the loop better ({least_damping(poles)}) than the "
                        f"best gain {result.gain} ({achieved})"
                    )

    return oracle


@given(st.data())
def test_damping_designs(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("best_damping_gain", "gain_for_damping")))
    mode = data.draw(st.sampled_from((None, None, None, -0.1 + 1j, "x", complex(np.nan, 1))))
    gains = data.draw(
        st.sampled_from((None, None, np.linspace(0.0, 10.0, 21), np.array([-1.0, 1.0])))
    )
    arguments = {
        "loop": data.draw(loop()),
        "mode": plain(mode),
        "gains": plain(None) if gains is None else data.draw(presented(gains)),
    }
    if name == "gain_for_damping":
        arguments["zeta"] = data.draw(
            scalar(data.draw(st.sampled_from((0.5, 0.3, 0.7, 1.0, -2.0))))
        )

    def call(**kwargs: Any) -> Any:
        return getattr(aerocontrol, name)(**kwargs)

    outcome = exercise(
        name, call, arguments, _design_oracle(name), nonfinite_by_definition=("pole",)
    )
    if (mode is not None and not isinstance(mode, complex)) or (
        isinstance(mode, complex) and np.isnan(mode.real)
    ):
        assert outcome.error is not None, f"{name} accepted mode = {mode!r}"


# ----- known defects of the core (see known_defects.py) ------------------------------------------


def test_regression_root_locus_gains_alias() -> None:
    model = (np.array([[-1.0]]), np.eye(1), np.eye(1), np.zeros((1, 1)))
    exercise(
        "root_locus",
        lambda loop, gains: aerocontrol.root_locus(loop, gains),
        {"loop": plain(model), "gains": plain(np.array([0.0, 1.0]))},
        _locus_oracle,
    )


def test_regression_margins_table_disk_beyond_two() -> None:
    static = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[0.5]]))
    exercise(
        "stability_margins",
        lambda loop: aerocontrol.stability_margins(loop),
        {"loop": plain(static)},
        _margins_oracle,
        nonfinite_by_definition=UNBOUNDED,
    )


def test_regression_margins_of_a_tiny_loop() -> None:
    """Poles near 1e-300 and C = 0: the transfer function's gain was 0/0 (numpy's
    'invalid value' warning); L is the constant 0.13."""
    A = np.array([[-2.3e-300, -1.3e-301], [6.4e-301, -2.3e-300]])
    model = (A, np.array([[0.13], [-0.13]]), np.zeros((1, 2)), np.array([[0.13]]))
    exercise(
        "stability_margins",
        lambda loop: aerocontrol.stability_margins(loop),
        {"loop": plain(model)},
        _margins_oracle,
        nonfinite_by_definition=UNBOUNDED,
    )
    assert aerocontrol.transfer_function(model).gain == pytest.approx(0.13, rel=1e-12)


def test_regression_closed_loop_overflow() -> None:
    """k B C of 2e308: the pole -1 - 2e308 is beyond doubles, so it is -inf with a
    NumericalOverflowWarning (no numpy warning); at k = 1e-10 it is -2e298."""
    model = (-np.eye(1), np.array([[1e308]]), np.array([[2.0]]), np.zeros((1, 1)))
    outcome = exercise(
        "root_locus",
        lambda loop, gains: aerocontrol.root_locus(loop, gains),
        {"loop": plain(model), "gains": plain([1.0, 1e-10])},
    )
    assert outcome.warned == (NumericalOverflowWarning,)
    assert outcome.result.poles[0, 0] == -np.inf
    assert outcome.result.poles[1, 0] == pytest.approx(-2e298, rel=1e-15)


def test_regression_margins_of_a_loop_of_huge_gain() -> None:
    """L = C B/(s - a) with C B = 1.58e301: the core's squares of B and C overflowed (A was
    blamed). Closed form: no phase crossover, the gain crossover at sqrt((C B)^2 - a^2), phase
    margin 90° + atan(|a|/ω), the closed-loop pole a - C B."""
    a, b, c = -1.8742697789066067, 125.7302210933933, 1.257302210933933e299
    model = (np.array([[a]]), np.array([[b]]), np.array([[c]]), np.zeros((1, 1)))
    outcome = exercise(
        "stability_margins",
        lambda loop: aerocontrol.stability_margins(loop),
        {"loop": plain(model)},
        _margins_oracle,
        nonfinite_by_definition=UNBOUNDED,
    )
    margins = outcome.result
    assert outcome.warned == ()
    assert margins.gain_margin == math.inf and margins.phase_crossovers.size == 0
    assert margins.gain_crossover == pytest.approx(b * c, rel=1e-14)
    assert margins.phase_margin == pytest.approx(90.0, rel=1e-14)
    assert margins.delay_margin == pytest.approx(math.pi / 2 / (b * c), rel=1e-14)
    assert margins.closed_loop_poles == pytest.approx([a - b * c], rel=1e-15)
    assert margins.closed_loop_stable and margins.stability_margin == pytest.approx(1.0)


def test_regression_damping_mode_without_poles() -> None:
    static = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.zeros((1, 1)))
    exercise(
        "best_damping_gain",
        lambda loop, mode: aerocontrol.best_damping_gain(loop, mode),
        {"loop": plain(static), "mode": plain(-0.1 + 1j)},
    )


def test_regression_margins_of_a_zero_loop_with_a_huge_c() -> None:
    """B = 0, C = 1.3e299: L is 0 (the core overflowed on C's square and blamed A); no
    crossover, the closed-loop pole is A's."""
    model = (np.array([[-1.875]]), np.zeros((1, 1)), np.array([[1.257e299]]), np.zeros((1, 1)))
    outcome = exercise(
        "stability_margins",
        lambda loop: aerocontrol.stability_margins(loop),
        {"loop": plain(model)},
        _margins_oracle,
        nonfinite_by_definition=UNBOUNDED,
    )
    margins = outcome.result
    assert margins.gain_crossovers.size == 0 and margins.phase_crossovers.size == 0
    assert np.array_equal(margins.closed_loop_poles, [-1.875 + 0j])


def test_regression_damping_of_a_loop_with_a_huge_c() -> None:
    """A = 0, C B = 1.6e148: the gain grid reaches k C B beyond 2^256 (an exponent of -inf
    for the gain 0 overflowed the int conversion)."""
    model = (np.zeros((1, 1)), np.array([[0.1257]]), np.array([[1.257e149]]), np.zeros((1, 1)))
    exercise(
        "best_damping_gain",
        lambda loop, mode, gains: aerocontrol.best_damping_gain(loop, mode, gains),
        {"loop": plain(model), "mode": plain(None), "gains": plain(None)},
        _design_oracle("best_damping_gain"),
        nonfinite_by_definition=("pole",),
    )


def test_regression_locus_oracle_gain_times_huge_feedthrough() -> None:
    """k = 5 and D = 1e308: the oracle's k/(1 + k D) was 5/inf = 0, the open-loop pole -1.874
    for the true closed-loop pole -1.874 - 0.1257 · 1e308/(5e308) · 5 = -2; it now forms
    1/(1/k + D), as aerocontrol does."""
    a, b = -1.8742697789066067, 0.1257302210933933
    model = (np.array([[a]]), np.array([[b]]), np.array([[1e308]]), np.array([[1e308]]))
    outcome = exercise(
        "root_locus",
        lambda loop, gains: aerocontrol.root_locus(loop, gains),
        {"loop": plain(model), "gains": plain(np.array([0.0, 1.0, 5.0]))},
        _locus_oracle,
    )
    assert outcome.result.poles[:, 0].real == pytest.approx([-1.8742697789066067, -2.0, -2.0])


def test_regression_root_locus_dominant_rank_one() -> None:
    """Formerly the known defect "eigenvalues-dominant-rank-one": A of 4, B of 1e8, C of 2;
    the core's balanced eigenvalues of A - k B C had backward errors of 1e-4 for the small
    ones (6 times the oracle's bound). The root locus now takes the unbalanced QR iteration of
    the loop's controller-Hessenberg form (``_core.root_locus``), backward stable for A - k B C
    itself."""
    A = np.array(
        [
            [-2.8742697789066067, -0.1321048632913019, 0.6404226504432821, 0.10490011715303971],
            [-0.535669373161111, -2.638404945090515, 1.3040000451301372, 0.9470809631292422],
            [-0.7037352358069926, -1.2654214710460525, -3.6232744625373523, 0.0413259793472436],
            [-2.3250307746388343, -0.21879166393254573, -1.2459109472530652, -3.7322673547034517],
        ]
    )
    B = np.array([[3.4558419206478603e07], [8.2161814350115836e07], [3.3043707618338715e07]])
    B = np.vstack([B, [[-1.3031572316043609e08]]])
    model = (A, B, np.array([[0.0, 0.0, 1.0, 2.0]]), np.zeros((1, 1)))
    exercise(
        "root_locus",
        lambda loop, gains: aerocontrol.root_locus(loop, gains),
        {"loop": plain(model), "gains": plain(np.array([0.0, 1.0, 5.0]))},
        _locus_oracle,
    )


def test_regression_sensitivity_beyond_every_scaling() -> None:
    """A campaign input: A of 2.3e300 and B C of 2.5e449 in the closed loop's A - B C, whose
    diagonal no state scaling changes: refused by name. (A scaling that minimises the closed
    loop's largest entry, applied although that least entry is beyond the doubles, overflowed
    the loop's own A: a NonFiniteError naming an A the caller gave finite.)"""
    A = np.array([[-2.2884833412797016e300, -1.321048632913019e299]])
    A = np.vstack([A, [[6.4042265044328213e299, -2.3093134452200553e300]]])
    model = (A, np.array([[1.257302210933933e299], [-1.321048632913019e299]]))
    model += (np.array([[-2e150, 0.0]]), np.zeros((1, 1)))
    outcome = exercise(
        "sensitivity", aerocontrol.sensitivity, {"loop": plain(model)}, _sensitivity_oracle(False)
    )
    assert isinstance(outcome.error, aerocontrol.InvalidArgumentError)
    assert not isinstance(outcome.error, aerocontrol.NonFiniteError)
    assert getattr(outcome.error, "argument", None) == "loop"


def test_regression_locus_oracle_of_open_loop_poles_beyond_the_doubles() -> None:
    """A = 1e308 ones (orders 2 and 3): the eigenvalues n 1e308 are beyond the doubles, and
    reading the open-loop poles issues aerocontrol's NumericalOverflowWarning, which the
    oracle read outside any catch: under pytest's filter (AerocontrolWarning is an error) it
    failed the property with aerocontrol's correct behaviour. The warning is now caught and
    checked against the eigenvalues of A scaled by a power of two: 2e308 and 3e308, beyond
    the doubles, and 0."""
    for n in (2, 3):
        model = (1e308 * np.ones((n, n)), np.ones((n, 1)), np.ones((1, n)), np.zeros((1, 1)))
        outcome = exercise(
            "root_locus",
            lambda loop, gains: aerocontrol.root_locus(loop, gains),
            {"loop": plain(model), "gains": plain(np.array([0.0, 1.0, 5.0]))},
            _locus_oracle,
        )
        poles = outcome.result.open_loop_poles  # read (and warned of) by the oracle
        # The others are 0 to within the backward error n u ||A|| (-4e292 for n = 3).
        others = poles[np.isfinite(poles)]
        assert others.size == n - 1 and np.all(np.abs(others) <= SLACK * n * U * n * 1e308)


# ----- Nyquist and Nichols ----------------------------------------------------------------------

#: Frequencies asked of nyquist and nichols (and some that must be refused).
FREQUENCIES = (
    None,
    np.array([0.0, 0.5, 2.0]),
    np.array([3.0, 0.1]),
    np.array([1.0]),
    np.array([-1.0, 1.0]),
    np.array([1.0, np.nan]),
    np.zeros(0),
    np.ones((2, 2)),
)


def _unstable_count(A: np.ndarray, size: float) -> int | None:
    """The eigenvalues of A right of the band |Re| <= √u ||A||_F that the Nyquist analysis
    takes to be the imaginary axis; None where one is within its sensitivity of the band's
    edge (or of the axis, for a matrix of size 0)."""
    if A.shape[0] == 0:
        return 0
    if not finite(A) or not np.isfinite(size):
        return None
    values, conditions = eigenvalue_conditions(A)
    with silenced():
        margin = SLACK * A.shape[0] * U * size * conditions + TINY
    band = math.sqrt(2 * U) * size
    if np.any(np.abs(np.abs(values.real) - band) <= margin) or not np.all(np.isfinite(margin)):
        return None
    return int(np.sum(values.real > band))


def _check_response(A: Any, B: Any, C: Any, D: Any, s: complex, value: complex, what: str) -> None:
    """L(s) = C (sI - A)^-1 B + D by response_at of B and C divided by powers of two to unit
    size (exact: B of 1e-301 made (sI - A)^-1 B subnormal, 13 digits), within its bound."""
    with silenced():
        if max(abs(s), norm(A)) > 1e150:  # numpy's complex solve squares entries: it overflows
            return
    eb = int(np.frexp(np.max(np.abs(B), initial=0.0))[1])
    ec = int(np.frexp(np.max(np.abs(C), initial=0.0))[1])
    got = response_at(A, np.ldexp(B, -eb), np.ldexp(C, -ec), np.zeros_like(D), s)
    if got is None or not np.isfinite(value):
        return
    G, size = got
    with silenced():
        expected = complex(np.ldexp(G[0, 0].real, eb + ec), np.ldexp(G[0, 0].imag, eb + ec))
        expected += float(D[0, 0])
        bound = SLACK * max(A.shape[0], 1) * (U * (np.ldexp(size, eb + ec) + abs(D[0, 0])) + TINY)
        error = abs(expected - value)
    if np.isfinite(expected) and np.isfinite(bound):
        assert_within(error, bound, f"{what} at s = {s}")


def _nyquist_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, C, D = model_matrices(args["loop"])
    d = float(D[0, 0])
    formed = closed_matrix(A, B, C, d, 1.0)
    assert formed is not None
    closed, size = formed
    assert_poles(closed, size, result.closed_loop_poles, "the closed-loop poles")
    P = _unstable_count(A, norm(A))
    if P is not None:
        assert result.open_loop_unstable_poles == P, f"P = {result.open_loop_unstable_poles}"
    with silenced():
        closed_size = norm(closed)
    Z = _unstable_count(closed, closed_size)
    if Z is not None:
        assert result.closed_loop_unstable_poles == Z, f"Z = {result.closed_loop_unstable_poles}"
    if result.marginal:
        assert result.encirclements is None and not result.closed_loop_stable
    else:
        expected = result.open_loop_unstable_poles - result.closed_loop_unstable_poles
        assert result.encirclements == expected
        turns = np.diff(np.unwrap(np.angle(result.closed_curve + 1.0)))
        assert round(float(np.sum(turns)) / (2 * math.pi)) == expected
    assert result.curve.shape == result.contour.shape == result.indented.shape
    assert np.all(np.diff(result.omega) > 0), "the frequencies are not increasing"
    for w, value in zip(result.omega, result.response, strict=True):
        _check_response(A, B, C, D, 1j * w, complex(value), "L(jω)")
    for i in np.linspace(0, result.contour.size - 2, 12).astype(int):
        _check_response(A, B, C, D, complex(result.contour[i]), complex(result.curve[i]), "L")
    assert "P = " in str(result)


def _nichols_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, C, D = model_matrices(args["loop"])
    assert np.all(np.diff(result.omega) > 0), "the frequencies are not increasing"
    for w, value, gain, phase in zip(
        result.omega, result.response, result.gain_db, result.phase_deg, strict=True
    ):
        _check_response(A, B, C, D, 1j * w, complex(value), "L(jω)")
        if np.isfinite(value) and value != 0:
            expected = 20 * math.log10(abs(value))
            assert_within(abs(gain - expected), 1e-13 * max(1.0, abs(expected)), f"gain of {value}")
            if np.isfinite(phase):
                gap = (float(phase) - math.degrees(np.angle(value)) + 180.0) % 360.0 - 180.0
                assert_within(abs(gap), 1e-9, f"the phase {phase} of L(j{w}) = {value}")
    assert isinstance(str(result), str)


@given(st.data())
def test_nyquist_and_nichols(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("nyquist", "nichols")))
    omega = FREQUENCIES[data.draw(st.integers(0, len(FREQUENCIES) - 1))]
    arguments = {"loop": data.draw(loop())}
    if omega is not None:
        arguments["omega"] = data.draw(presented(omega))
    outcome = exercise(
        name,
        getattr(aerocontrol, name),
        arguments,
        _nyquist_oracle if name == "nyquist" else _nichols_oracle,
        nonfinite_by_definition=("contour", "response", "gain_db", "phase_deg"),
    )
    given_omega = arguments["omega"].canonical if "omega" in arguments else None
    if isinstance(given_omega, np.ndarray) and given_omega.dtype.kind in "biuf":
        if given_omega.ndim != 1 or given_omega.size == 0 or np.any(given_omega < 0):
            assert outcome.error is not None, f"{name} accepted omega {given_omega}"


def test_regression_frequency_point_beyond_the_scaled_range() -> None:
    """A triple integrator perturbed by 1e-308 (A[2, 0]), C of 1e149: the core divided the
    point jω by σ (the power of two of A's largest entry), which overflowed beyond 1e131 rad/s,
    and the Nyquist curve was 0 there. The curve is checked by the suite's oracle, and at
    ω = 1e200, far beyond A's scale, L(jω) = C B / (jω) to 1e-15 (the next term of the
    expansion at infinity, C A B / (jω)^2, is below 1e-400 of it)."""
    A = np.zeros((3, 3))
    A[2, 0] = 1e-308
    B = np.array([[0.1257302210933933], [-0.1321048632913019], [0.6404226504432821]])
    C = np.array([[1.2573022109339329e149, -1.3210486329130188e149, 6.4042265044328201e149]])
    loop = (A, B, C, np.zeros((1, 1)))
    exercise(
        "nyquist",
        aerocontrol.nyquist,
        {"loop": plain(loop)},
        _nyquist_oracle,
        nonfinite_by_definition=("contour", "response"),
    )
    far = aerocontrol.frequency_response(loop, np.array([1e200])).response[0, 0, 0]
    assert far == pytest.approx(float((C @ B)[0, 0]) / 1e200j, rel=1e-15)


def test_regression_closed_loop_poles_of_graded_loops() -> None:
    """L = 1/(s + 2^e) + 1/(s + 1) closes to poles near -2^e and -2 (the closed-loop matrix
    [[-2^e - 1, -1], [-1, -2]] is symmetric: each eigenvalue is well conditioned relative to
    its size), and min |1 + L| = 1 at infinity (Re 1/(jω + 1) >= 0). The core's loop_margins
    took the QR iteration's poles (accurate to u 2^e only): at e = 60 the small pole was +64
    and the loop unstable; at e = 50 it was -1.875, counted on the axis by the normwise
    boundary test, with stability and disk margins 0. Oracle: the closed forms, the poles
    -(2^e + 3)/2 ± sqrt(((2^e - 1)/2)^2 + 1) (the smaller as det / the larger, Vieta), and
    the stability margin min |1 + L| = 1."""
    for e in (40, 50, 60):
        loop = (np.diag([-(2.0**e), -1.0]), np.ones((2, 1)), np.ones((1, 2)), np.zeros((1, 1)))
        margins = aerocontrol.stability_margins(loop)
        large = -(2.0**e + 3.0) / 2.0 - math.sqrt(((2.0**e - 1.0) / 2.0) ** 2 + 1.0)
        small = ((2.0**e + 1.0) * 2.0 - 1.0) / large
        poles = np.sort_complex(margins.closed_loop_poles)
        assert abs(poles[0] - large) <= 1e-12 * abs(large)
        assert abs(poles[1] - small) <= 1e-12 * abs(small)
        assert margins.closed_loop_stable
        assert margins.stability_margin == pytest.approx(1.0, rel=1e-9)


def _order_forty_loop() -> tuple[np.ndarray, ...]:
    """L = 2/(s + 1) as a loop of 40 states: A = diag(-1, -2.5, -3.5, ..., -40.5), B = 1,
    C = 2 e_1 (the other 39 modes unobservable, apart from every closed-loop pole below)."""
    n = 40
    A = np.diag(np.append(-1.0, 0.5 - np.arange(3.0, n + 2.0)))
    C = np.zeros((1, n))
    C[0, 0] = 2.0
    return A, np.ones((n, 1)), C, np.zeros((1, 1))


@pytest.mark.parametrize(
    "function", ["stability_margins", "disk_margins", "root_locus", "nyquist", "gain_for_damping"]
)
def test_regression_loop_of_forty_states(function: str) -> None:
    """Found by a hostile-input hunt: the core's controller-Hessenberg form (the root locus,
    the margins' closed-loop poles) panicked for a SISO loop of 34 states or more (its
    reflector buffer held 32 entries; RuntimeError, not an aerocontrol error).
    Closed forms of L = 2/(s + 1): |L(jω)| = 1 at ω = √3, a phase margin of 180° - 60°;
    the closed loop's poles -3 and -2.5, ..., -40.5; 1 + k L = 0 at s = -1 - 2k. (At 33
    states, the largest order the core reduces, these hold to 1e-13.)"""
    loop = _order_forty_loop()
    rest = 0.5 - np.arange(3.0, 42.0)
    if function == "stability_margins":
        margins = aerocontrol.stability_margins(loop)
        assert margins.gain_crossover == pytest.approx(math.sqrt(3.0), rel=1e-12)
        assert margins.phase_margin == pytest.approx(120.0, rel=1e-12)
        poles = np.sort(margins.closed_loop_poles.real)
        assert np.allclose(poles, np.sort(np.append(rest, -3.0)), rtol=1e-12)
    elif function == "disk_margins":
        # |S - T|/2 = |1 - L|/|1 + L| / 2 = |s - 1|/|s + 3| / 2 peaks at ω = ∞ (1/2): α = 2.
        assert aerocontrol.disk_margins(loop).multiloop.alpha == pytest.approx(2.0, rel=1e-9)
    elif function == "root_locus":
        locus = aerocontrol.root_locus(loop, [0.5, 2.0])
        for k, row in zip([0.5, 2.0], locus.poles, strict=True):
            expected = np.sort(np.append(rest, -1.0 - 2.0 * k))
            assert np.allclose(np.sort(row.real), expected, rtol=1e-12)
            assert np.all(row.imag == 0.0)
    elif function == "nyquist":
        response = aerocontrol.nyquist(loop)
        assert response.encirclements == 0
    else:
        with pytest.raises(aerocontrol.InvalidArgumentError, match="not reached"):
            aerocontrol.gain_for_damping(loop, 0.5)


def test_regression_phase_crossover_of_badly_scaled_states() -> None:
    """Found by an oracle hunt: the core's loop_margins missed this phase crossover (gain
    margin inf, silently), its doubled system's zeros off the axis by more than the axis
    tolerance; the loop's states are now balanced first.

    L = (s - 1)²/((s + 2)(s + 3)(s + 4)) with its states scaled by 10^±6: Im L(jω) = 0 where
    ω⁴ - 45 ω² + 74 = 0 (by hand), L negative at ω² = (45 - √1729)/2 (ω = 1.3074, L =
    -0.0823, a gain margin of 12.145, as python-control's stability_margins gives)."""
    A = np.array(
        [
            [4.0, -270000.0, -200000000.0],
            [-0.0003999999999999999, 26.000000000000004, 20000.0],
            [9.000000000000001e-07, -0.051, -39.0],
        ]
    )
    B = np.array([[10.0], [-0.001], [2e-06]])
    C = np.array([[-0.09999999999999999, -2000.0, 0.0]])
    w = math.sqrt((45.0 - math.sqrt(1729.0)) / 2.0)
    s = 1j * w
    L = (s - 1.0) ** 2 / ((s + 2.0) * (s + 3.0) * (s + 4.0))

    def complete(result: Any, args: dict[str, Any], warned: Warned) -> None:
        _margins_oracle(result, args, warned)
        found = np.abs(result.phase_crossovers - w) <= 1e-9 * w
        assert np.any(found), f"the phase crossover {w} is missing: {result.phase_crossovers}"
        assert result.gain_margins[found][0] == pytest.approx(1.0 / abs(L), rel=1e-9)

    exercise(
        "stability_margins",
        lambda loop: aerocontrol.stability_margins(loop),
        {"loop": plain((A, B, C, np.zeros((1, 1))))},
        complete,
        nonfinite_by_definition=UNBOUNDED,
    )
