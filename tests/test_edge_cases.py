"""Inputs at the edges: the range of doubles, memory, alignment and odd argument types.

Each case here once misbehaved (found by review): it returned a wrong value silently, raised
the wrong exception, or crashed the interpreter. Each now has the right answer or a clear
exception.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import aerocontrol
from aerocontrol import (
    IllConditionedWarning,
    InvalidArgumentError,
    NumericalOverflowWarning,
    ShapeError,
)


def test_column_sums_that_overflow_are_handled() -> None:
    # ||A||_1 = 2e308 overflows. For exact data, e^A of -1e308 [[1, 1], [1, 1]] is the
    # projector onto the kernel; but one rounding unit in A moves the zero eigenvalue by about
    # 1e292, so e^A is anything from 0 to inf: the problem is ill-posed in double precision and
    # says so. (This once returned the identity, silently.)
    with pytest.warns(IllConditionedWarning):
        result = aerocontrol.expm(np.full((2, 2), -1e308))
    assert not np.isnan(result).any()
    assert not np.allclose(result, np.eye(2))
    # Well-posed matrices of huge entries keep their answers: a diagonal one exactly.
    with pytest.warns(IllConditionedWarning):
        result = aerocontrol.expm(np.diag([-1e308, -1e300, 0.0]))
    np.testing.assert_array_equal(result, np.diag([0.0, 0.0, 1.0]))
    with pytest.warns(NumericalOverflowWarning), pytest.warns(IllConditionedWarning):
        result = aerocontrol.expm(np.full((2, 2), 1e308))
    assert np.isinf(result).all()


def test_overflowing_diagonal_keeps_zero_off_diagonals() -> None:
    with pytest.warns(NumericalOverflowWarning):
        result = aerocontrol.expm(np.diag([800.0, 800.0]))
    np.testing.assert_array_equal(result, [[np.inf, 0.0], [0.0, np.inf]])
    with pytest.warns(NumericalOverflowWarning):
        phi = aerocontrol.transition_matrix([[1.0, 0.0], [0.0, 2.0]], 1000.0)
    assert not np.isnan(phi).any()
    # The divided difference of two overflowing exponentials is infinite, not NaN.
    with pytest.warns(NumericalOverflowWarning):
        result = aerocontrol.expm([[800.0, 1.0], [0.0, 801.0]])
    assert result[0, 1] == np.inf and result[1, 0] == 0.0


def test_meaningless_exponentials_are_flagged() -> None:
    # A rotation by 1e100 rad: no digit of the phase survives the rounding of the input.
    rotation = np.array([[0.0, 1.0], [-1.0, 0.0]])
    with pytest.warns(IllConditionedWarning, match=r"2\^53"):
        aerocontrol.transition_matrix(rotation, 1e100)
    with pytest.warns(IllConditionedWarning):
        aerocontrol.expm(np.stack([rotation, rotation * 1e20]))


@pytest.mark.parametrize(
    "call",
    [
        lambda: aerocontrol.expm(np.broadcast_to(0.0, (100_000, 100_000))),
        lambda: aerocontrol.transition_matrix(np.eye(2), np.broadcast_to(0.0, (10**11,))),
        lambda: aerocontrol.expm(np.broadcast_to(0.0, (10**7, 30, 30))),
        lambda: aerocontrol.discretize(np.eye(2), np.broadcast_to(0.0, (2, 10**10)), 0.1),
    ],
    ids=["expm", "transition-times", "stack", "discretize-inputs"],
)
def test_impossible_sizes_raise_memory_error(call) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(MemoryError):
        call()


def test_misaligned_arrays_are_read_correctly() -> None:
    buffer = np.zeros(4 * 8 + 1, dtype=np.uint8)
    A = np.frombuffer(buffer.data, dtype=np.float64, count=4, offset=1).reshape(2, 2)
    assert not A.flags.aligned
    np.testing.assert_array_equal(aerocontrol.expm(A), np.eye(2))


def test_discretize_at_the_edges_of_the_range() -> None:
    A = np.array([[-1.0]])
    for b, dt in [(1e-300, 1e-10), (1e300, 1e-10), (1.0, 5e-324), (1e300, 1.0)]:
        d = aerocontrol.discretize(A, [[b]], dt)
        np.testing.assert_allclose(d.Gamma0, [[b * -np.expm1(-dt)]], rtol=1e-14)
    with pytest.raises(InvalidArgumentError, match="dt must be small enough that A dt is finite"):
        aerocontrol.discretize([[1e300]], [[1.0]], 1e10)


def test_method_must_be_one_of_the_names() -> None:
    A, B = aerocontrol.chapter.boeing747_longitudinal()
    with pytest.raises(InvalidArgumentError, match="method must be one of"):
        aerocontrol.discretize(A, B, 0.1, method=np.array(["zoh", "foh"]))  # type: ignore[arg-type]
    d = aerocontrol.discretize(A, B, 0.1, method=np.str_("foh"))  # type: ignore[arg-type]
    assert d.method == "foh" and type(d.method) is str


@pytest.mark.parametrize(
    "call",
    [
        lambda names: aerocontrol.summing_junction(names, "e"),
        lambda names: aerocontrol.modes(np.diag([-1.0, -2.0]), mode_names=names),
        lambda names: aerocontrol.StateSpace(np.eye(2), np.ones((2, 1)), state_names=names),
    ],
    ids=["summing_junction", "modes", "StateSpace"],
)
def test_names_are_strings_or_sequences_of_strings(call: Any) -> None:
    for bad in (3, [1, 2], 2.5, [b"a", b"b"]):
        with pytest.raises(InvalidArgumentError, match="must be a string or a sequence of strings"):
            call(bad)


def test_one_string_is_one_name() -> None:
    with pytest.raises(ShapeError, match="mode_names must name 2 modes, got 1"):
        aerocontrol.modes(np.diag([-1.0, -2.0]), mode_names="ab")
    assert aerocontrol.summing_junction("-r", "e").input_names == ("r",)


def test_a_bool_is_no_scalar_argument() -> None:
    """True given for a tolerance, a weight or a frequency is refused by name, as dt=True and
    a thread count of True are (numpy reads it as 1: tol=True gave the verdict for the
    tolerance 1, alpha=True the backward difference); the numbers 1 and 1.0 still work, and
    give what True gave."""
    A, b = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]])
    model = (A, b, [[1.0, 0.0]], [[0.0]])
    calls = {
        "tol": lambda value: aerocontrol.is_controllable(A, b, tol=value),
        "alpha": lambda value: aerocontrol.c2d(model, 0.1, "gbt", alpha=value),
        "prewarp": lambda value: aerocontrol.c2d(model, 0.1, "tustin", prewarp=value),
        "omega_n": lambda value: aerocontrol.augment_mode(A, 0, omega_n=value),
    }
    for name, call in calls.items():
        for flag in (True, np.bool_(True)):
            with pytest.raises(aerocontrol.InvalidArgumentError, match=f"{name} must be a number"):
                call(flag)
    assert aerocontrol.is_controllable(A, b, tol=1.0) is False  # sigma_min of the pair < 1
    backward = aerocontrol.c2d(model, 0.1, "backward_diff")
    np.testing.assert_array_equal(aerocontrol.c2d(model, 0.1, "gbt", alpha=1).A, backward.A)
