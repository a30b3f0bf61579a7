"""Properties of pole placement and the companion form (aerocontrol.placement).

Oracles: the closed loop A - BK against numpy's product; the achieved poles as the eigenvalues
of that closed loop (backward errors and multiplicities, oracles.assert_spectrum); their
reported error against the requested poles, and below the warning threshold unless a warning
was issued (the conditioning-aware contract: a placement that misses by more than 1e-6
relatively, or whose controllability matrix has κ >= 1e8, must say so); Bass-Gura against
Ackermann within κ(V); the companion form by its structure and T A = C T; augment_mode by the
poles it keeps and the damping and frequency of those it sets.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import IllConditionedWarning
from aerocontrol.placement import ILL_CONDITIONED_CONTROLLABILITY, POLE_ERROR_WARNING

from .harness import REFUSE, SAME, Arg, Warned, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U,
    assert_coefficients,
    assert_spectrum,
    characteristic_tolerance,
    finite,
    norm,
    quietly,
    silenced,
)
from .oracles import (
    condition as condition_number,
)
from .strategies import (
    canonical,
    model_matrices,
    orders,
    planted_uncontrollable,
    presented,
    presented_system,
    rectangular,
    scalar,
    square,
)

COVERED = {"place", "place_bass_gura", "place_ackermann", "companion_form", "augment_mode"}

#: Fields of a Placement that are NaN where the measure does not apply (κ(V) for the robust
#: method, κ(X) for the single-input formulas).
NOT_APPLICABLE = ("controllability_condition", "eigenvector_condition")


@st.composite
def requested_poles(draw: st.DrawFn, n: int) -> np.ndarray:
    """n poles: real or in conjugate pairs, distinct or repeated, stable or not; sometimes
    one too many or one without its conjugate (to be refused)."""
    kind = draw(
        st.sampled_from(
            ("real", "pairs", "repeated", "mixed", "scaled", "wrong count", "unpaired", "nan")
        )
    )
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    if kind == "wrong count":
        return -np.arange(1.0, n + 2)
    poles = -rng.uniform(0.5, 5.0, n).astype(complex)
    if kind in ("pairs", "mixed", "scaled", "unpaired") and n >= 2:
        pairs = n // 2 if kind != "mixed" else max(1, n // 4)
        for k in range(pairs):
            value = complex(-rng.uniform(0.1, 3.0), rng.uniform(0.1, 3.0))
            poles[2 * k], poles[2 * k + 1] = value, value.conjugate()
    if kind == "repeated" and n:
        poles[:] = poles[0]
    if kind == "scaled":
        poles *= draw(st.sampled_from((1e-8, 1e8, 1e-300, 1e300)))
    if kind == "unpaired" and n >= 2:
        poles[0] += 0.5j
    if kind == "nan" and n:
        poles[-1] = np.nan
    return poles


def pole_arg(draw: st.DrawFn, poles: np.ndarray) -> Arg:
    """The poles as a complex array in some layout, a list, a real array when they are real."""
    how = draw(st.sampled_from(("complex array", "list", "real", "reversed view", "text")))
    value: Any = np.array(poles, dtype=complex)
    if how == "list":
        value = poles.tolist()
    elif how == "real" and np.all(poles.imag == 0):
        value = poles.real.copy()
    elif how == "reversed view":
        value = np.ascontiguousarray(poles[::-1])[::-1]
    elif how == "text" and len(poles):
        return Arg(np.array(["pole"] * len(poles)), None, how, REFUSE)
    else:
        how = "complex array"
    return Arg(value, np.array(value, dtype=complex), how, SAME)


def _placement_oracle(single_input: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        second = args["b" if single_input else "B"]
        if args.get("poles") is None:  # place(sys, poles)
            A, B, _, _ = model_matrices(args["A_or_sys"])
            requested = np.asarray(second, dtype=complex)
        else:
            A, B = np.asarray(args["A_or_sys"], float), np.asarray(second, float)
            requested = np.asarray(args["poles"], dtype=complex)
        B = B.reshape(-1, 1) if B.ndim == 1 else B
        n, m = B.shape
        K, closed = result.K, result.closed_loop
        assert K.shape == (m, n) and closed.shape == (n, n)
        assert np.array_equal(np.sort_complex(result.poles), np.sort_complex(requested))
        if single_input:
            assert np.array_equal(result.k, K[0])
        if not finite(A, B, K, closed):
            return
        with silenced():
            expected = A - B @ K
            scale = norm(A) + norm(B) * norm(K)
        assert norm(closed - expected) <= SLACK * n * (U * scale + TINY), "closed_loop != A - BK"
        assert_spectrum(closed, result.achieved_poles, "the achieved poles")
        # The reported error is the error of the achieved poles matched to the requested ones.
        # Relative to each pole, or to ||A - B K||_F for a pole below u times it (zero included).
        with silenced():
            largest = float(np.max(np.abs(closed), initial=0.0))
            # Scaled, as the core's: numpy's sum of squares underflows for entries near 1e-160.
            closed_norm = largest * float(np.linalg.norm(closed / largest)) if largest else 0.0
            small = np.abs(result.poles) <= np.finfo(float).eps * closed_norm
            reference = np.where(
                small, closed_norm if closed_norm > 0 else 1.0, np.abs(result.poles)
            )
            errors = np.abs(result.achieved_poles - result.poles) / reference
        assert np.all(errors <= result.max_relative_error * (1 + 8 * U) + TINY), (
            f"errors {errors} above the reported {result.max_relative_error}"
        )
        if IllConditionedWarning not in warned:
            assert result.max_relative_error <= POLE_ERROR_WARNING, (
                f"poles missed by {result.max_relative_error:.2e} relatively, without a warning"
            )
            if single_input:
                assert result.controllability_condition < ILL_CONDITIONED_CONTROLLABILITY
        assert isinstance(str(result), str)

    return oracle


@st.composite
def placement_problem(draw: st.DrawFn, m: int | None) -> tuple[dict[str, Arg], int]:
    """The arguments of a placement: (A, B, poles) or (sys, poles); m = None draws it."""
    n = draw(orders())
    inputs = draw(st.integers(1, 3)) if m is None else m
    if draw(st.sampled_from((False, False, False, True))):
        A, B, _ = draw(planted_uncontrollable(n, inputs))
        n = A.shape[0]
    else:
        A = draw(square(n))
        B = draw(rectangular(n, inputs))
    if m == 1 and draw(st.booleans()):
        B = B[:, 0]
    poles = pole_arg(draw, draw(requested_poles(n)))
    key = "B" if m is None else "b"  # place(A, B, poles), place_bass_gura(A, b, poles)
    if draw(st.sampled_from((False, False, True))):
        sys = draw(presented_system((A, B if B.ndim == 2 else B[:, np.newaxis])))
        return {"A_or_sys": sys, key: poles, "poles": plain(None)}, n
    return {"A_or_sys": draw(presented(A)), key: draw(presented(B)), "poles": poles}, n


@given(st.data())
def test_place(data: st.DataObject) -> None:
    arguments, _ = data.draw(placement_problem(None))
    exercise(
        "place",
        aerocontrol.place,
        arguments,
        _placement_oracle(False),
        nonfinite_by_definition=NOT_APPLICABLE,
    )


@given(st.data())
def test_single_input_placement(data: st.DataObject) -> None:
    arguments, _ = data.draw(placement_problem(1))
    name = data.draw(st.sampled_from(("place_bass_gura", "place_ackermann")))
    outcome = exercise(
        name,
        getattr(aerocontrol, name),
        arguments,
        _placement_oracle(True),
        nonfinite_by_definition=NOT_APPLICABLE,
    )
    design = outcome.result
    if design is None or IllConditionedWarning in outcome.warned or not finite(design.K):
        return
    # The other formula gives the same gain, to the conditioning of the controllability matrix.
    other = "place_ackermann" if name == "place_bass_gura" else "place_bass_gura"
    values = {key: arg.canonical for key, arg in arguments.items()}
    try:
        twin = quietly(getattr(aerocontrol, other), **values)
    except aerocontrol.AerocontrolError:
        return
    n = design.K.shape[1]
    bound = SLACK * n * U * design.controllability_condition * norm(design.K) + SLACK * TINY
    assert norm(twin.K - design.K) <= bound, f"{name} and {other} disagree beyond κ(V) u"


def _companion_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    if args["b"] is None:
        A, b, _, _ = model_matrices(args["A_or_sys"])
    else:
        A, b = np.asarray(args["A_or_sys"], float), np.asarray(args["b"], float)
    b = b.reshape(-1, 1)
    n = A.shape[0]
    a = result.coefficients
    assert a.shape == (n + 1,) and a[0] == 1.0
    with silenced():
        assert_coefficients(
            a, np.real(np.poly(A)) if n else np.ones(1), characteristic_tolerance(A), "a"
        )
    V = quietly(aerocontrol.ctrb, A, b)
    assert np.array_equal(result.V, V, equal_nan=True), "V is not ctrb(A, b)"
    W = np.eye(n)
    for k in range(1, n):
        W += np.diag(np.full(n - k, a[k]), k)
    assert np.array_equal(result.W, W, equal_nan=True), "W is not the Toeplitz matrix (6.131)"
    C = np.zeros((n, n))
    if n:
        C[0] = -a[1:]
        C[1:, :-1] += np.eye(n - 1)
    assert np.array_equal(result.companion, C, equal_nan=True), "not the companion form (6.116)"
    T = result.T
    with silenced():
        # (VW)^-1 is as accurate as κ(VW) allows; evaluating T V W adds u ||T|| ||V|| ||W||.
        condition = condition_number(result.V @ W)
        evaluation = norm(T) * norm(result.V) * norm(W)
        residual = norm(T @ result.V @ W - np.eye(n))
        similarity = norm(T @ A - C @ T)
        bound = SLACK * n * U * condition * norm(T) * (norm(A) + norm(C)) + SLACK * n * TINY
    if finite(T) and np.isfinite(condition) and condition * U < 1e-2:
        assert residual <= SLACK * n * U * (condition + evaluation), "T is not (VW)^-1"
        assert similarity <= bound, "T A T^-1 is not the companion form"


@given(st.data())
def test_companion_form(data: st.DataObject) -> None:
    n = data.draw(orders())
    if data.draw(st.sampled_from((False, False, True))):
        A, B, _ = data.draw(planted_uncontrollable(n, 1))
    else:
        A, B = data.draw(square(n)), data.draw(rectangular(n, 1))
    if data.draw(st.sampled_from((False, False, True))):
        arguments = {"A_or_sys": data.draw(presented_system((A, B))), "b": plain(None)}
    else:
        arguments = {"A_or_sys": data.draw(presented(A)), "b": data.draw(presented(B[:, 0]))}
    exercise("companion_form", aerocontrol.companion_form, arguments, _companion_oracle)


def _augment_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    """Every pole of the other modes kept, bitwise; the chosen mode's pole (pair) replaced by
    one with the requested natural frequency and damping (defaults: the mode's own)."""
    A = np.asarray(args["sys_or_A"], float)
    analysis = quietly(aerocontrol.modes, A)
    mode, zeta, omega_n = args["mode"], args["zeta"], args["omega_n"]
    eigenvalues = analysis.eigenvalues
    assert result.shape == eigenvalues.shape and result.dtype == np.complex128
    if isinstance(mode, str):
        index = [name.lower() for name in analysis.mode_names].index(mode.lower())
    elif isinstance(mode, (float, complex)):
        target = complex(mode)
        index = int(np.argmin(np.abs(analysis.eigenvalue - complex(target.real, abs(target.imag)))))
    else:
        index = int(mode) % len(analysis)
    old = complex(analysis.eigenvalue[index])
    oscillatory = bool(analysis.oscillatory[index])
    olds = [old, old.conjugate()] if oscillatory else [old]
    positions = [int(np.argmin(np.abs(eigenvalues - value))) for value in olds]
    others = np.ones(len(eigenvalues), dtype=bool)
    others[positions] = False
    assert np.array_equal(result[others], eigenvalues[others]), "another mode's poles changed"
    new = result[positions]
    wn = analysis.natural_frequency[index] if omega_n is None else float(omega_n)
    if not oscillatory:
        assert new[0] == complex(-wn), f"the real mode's new pole {new[0]} is not -ω_n"
        return
    z = analysis.damping_ratio[index] if zeta is None else float(zeta)
    if z < 1:
        assert new[1] == np.conj(new[0]), "the new pair is not conjugate"
        assert abs(abs(new[0]) / wn - 1) <= 8 * U, f"|λ| = {abs(new[0])}, not ω_n = {wn}"
        assert abs(-new[0].real / abs(new[0]) - z) <= 8 * U, "the damping ratio is not ζ"
    else:
        spread = wn * np.sqrt(z * z - 1)
        expected = np.sort([-z * wn - spread, -z * wn + spread])
        assert np.all(new.imag == 0), "ζ >= 1 gives two real poles"
        assert np.allclose(np.sort(new.real), expected, rtol=8 * U, atol=8 * U * z * wn)


@given(st.data())
def test_augment_mode(data: st.DataObject) -> None:
    A = data.draw(square(data.draw(st.sampled_from((1, 2, 3, 4, 6)))))
    mode = data.draw(st.sampled_from((0, 1, -1, 2, 7, "mode 1", "Dutch roll", True, 1.5, "x")))
    zeta = data.draw(st.sampled_from((None, 0.3, 0.0, 1.5, 1.0, -0.2, np.nan)))
    omega_n = data.draw(st.sampled_from((None, 2.0, 1e-3, 0.0, -1.0, np.inf)))
    exercise(
        "augment_mode",
        aerocontrol.augment_mode,
        {
            "sys_or_A": data.draw(presented(A)),
            "mode": plain(mode),
            "zeta": plain(zeta) if zeta is None else data.draw(scalar(zeta)),
            "omega_n": plain(omega_n) if omega_n is None else data.draw(scalar(omega_n)),
        },
        _augment_oracle,
    )


# ----- inputs a campaign found (regressions) -----------------------------------------------------


@pytest.mark.parametrize("function", ["place_ackermann", "place_bass_gura"])
def test_placement_overflow_names_the_poles(function: str) -> None:
    """Poles whose characteristic polynomial overflows: the error names the poles (it blamed
    A, which is finite, or the controllability matrix)."""
    A = np.array([[0.1257, -0.132], [0.64, 0.105]])
    b = np.array([0.1257, -0.132])
    outcome = exercise(
        function,
        getattr(aerocontrol, function),
        {"A_or_sys": canonical(A), "b": canonical(b), "poles": plain([-1e160, -2e160])},
        _placement_oracle(True),
        nonfinite_by_definition=NOT_APPLICABLE,
    )
    assert "poles" in str(outcome.error), f"the error blames another argument: {outcome.error}"


@pytest.mark.parametrize("factor", [1e-200, 1e150, 1e200])
def test_placement_of_plants_at_extreme_scales(factor: float) -> None:
    """(A, B) and the poles scaled together: the gain is the same, computed from the scaled
    plant (entries near 1e150 overflowed inside the methods)."""
    A = np.array([[0.1257, -0.132], [0.64, 0.105]])
    b = np.array([[0.1257], [-0.132]])
    poles = [-1.0, -2.0]
    reference = aerocontrol.place(A, b, poles).K
    for function in ("place", "place_ackermann", "place_bass_gura"):
        design = getattr(aerocontrol, function)(A * factor, b * factor, [p * factor for p in poles])
        assert np.allclose(design.K, reference, rtol=1e-12, atol=0), function
        assert np.allclose(np.sort(design.achieved_poles.real), [-2 * factor, -factor], rtol=1e-12)


def test_placement_of_poles_below_rounding() -> None:
    """Poles of 1e-301 for a plant of 1e149: the relative pole error is judged against
    ||A - B K|| below u ||A - B K|| (it overflowed to inf without a NumericalOverflowWarning)."""
    A = np.array([[1.2573e149, -1.3210e149], [6.404e148, 1.049e149]])
    b = np.array([[0.1257], [-0.1321]])
    poles = [-2.19e-301 + 1.48e-301j, -2.19e-301 - 1.48e-301j]
    for function in ("place_bass_gura", "place_ackermann"):
        design = getattr(aerocontrol, function)(A, b, poles)
        assert np.isfinite(design.max_relative_error), function
