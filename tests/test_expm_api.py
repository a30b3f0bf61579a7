"""The Python API of expm and transition_matrix: accepted inputs, shapes, and every bad input.

Oracle: scipy.linalg.expm for values; the issue's list of bad inputs for the errors.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.linalg

import aerocontrol
from aerocontrol import NonFiniteError, NotRealError, NumericalOverflowWarning, ShapeError

A747, B747 = aerocontrol.chapter.boeing747_longitudinal()


def test_chapter_matrix_against_scipy() -> None:
    np.testing.assert_allclose(aerocontrol.expm(A747), scipy.linalg.expm(A747), rtol=1e-14)


@pytest.mark.parametrize(
    "convert",
    [
        lambda a: a.tolist(),
        lambda a: a.astype(np.float32),
        lambda a: np.asfortranarray(a),
        lambda a: np.ascontiguousarray(a[::-1, ::-1])[::-1, ::-1],  # negative strides
        lambda a: np.repeat(np.repeat(a, 2, axis=0), 2, axis=1)[::2, ::2],  # strided view
        lambda a: a.astype(">f8"),  # big-endian
    ],
    ids=["list", "float32", "fortran", "negative-strides", "strided-view", "big-endian"],
)
def test_accepts_any_real_array_like(convert) -> None:  # type: ignore[no-untyped-def]
    given = convert(A747)
    expected = scipy.linalg.expm(np.asarray(given, dtype=np.float64))
    result = aerocontrol.expm(given)
    assert result.dtype == np.float64 and result.flags.c_contiguous
    np.testing.assert_allclose(result, expected, rtol=1e-13)


def test_integer_and_boolean_input() -> None:
    Q = np.array([[-3, 1, 1, 1], [1, -3, 1, 1], [1, 1, -3, 1], [1, 1, 1, -3]])
    np.testing.assert_allclose(aerocontrol.expm(Q), scipy.linalg.expm(1.0 * Q), rtol=1e-14)
    np.testing.assert_allclose(
        aerocontrol.expm(np.eye(2, dtype=bool)), np.e * np.eye(2), rtol=1e-15
    )


def test_inputs_are_not_modified() -> None:
    A = np.asfortranarray(A747.copy())
    before = A.copy()
    aerocontrol.expm(A)
    aerocontrol.transition_matrix(A, [0.5, 1.0])
    aerocontrol.discretize(A, B747, 0.1, method="foh")
    np.testing.assert_array_equal(A, before)
    stack = np.stack([A747, 2 * A747])
    stack_before = stack.copy()
    aerocontrol.expm(stack)
    np.testing.assert_array_equal(stack, stack_before)


def test_empty_and_scalar_matrices() -> None:
    assert aerocontrol.expm(np.zeros((0, 0))).shape == (0, 0)
    np.testing.assert_array_equal(aerocontrol.expm([[2.0]]), [[np.exp(2.0)]])
    assert aerocontrol.expm(np.zeros((3, 0, 0))).shape == (3, 0, 0)


def test_stack_equals_one_at_a_time_exactly() -> None:
    rng = np.random.default_rng(4)
    for n in (2, 4, 7, 12):
        stack = rng.standard_normal((40, n, n))
        batch = aerocontrol.expm(stack)
        singles = np.stack([aerocontrol.expm(a) for a in stack])
        np.testing.assert_array_equal(batch, singles)
        np.testing.assert_allclose(batch, scipy.linalg.expm(stack), rtol=1e-10, atol=1e-12)


def test_transition_matrix_shapes_and_values() -> None:
    single = aerocontrol.transition_matrix(A747, 2.0)
    assert single.shape == (4, 4)
    np.testing.assert_allclose(single, scipy.linalg.expm(2.0 * A747), rtol=1e-14)
    times = np.linspace(-5.0, 500.0, 37)
    many = aerocontrol.transition_matrix(A747, times)
    assert many.shape == (37, 4, 4)
    for t, phi in zip(times, many, strict=True):
        np.testing.assert_allclose(phi, scipy.linalg.expm(t * A747), rtol=1e-12, atol=1e-15)
    assert aerocontrol.transition_matrix(A747, []).shape == (0, 4, 4)


def test_transition_matrix_of_a_large_matrix_matches_scipy() -> None:
    rng = np.random.default_rng(7)
    A = rng.standard_normal((20, 20)) / 5
    times = [0.0, 0.3, 2.0]
    many = aerocontrol.transition_matrix(A, times)
    for t, phi in zip(times, many, strict=True):
        np.testing.assert_allclose(phi, scipy.linalg.expm(t * A), rtol=1e-12, atol=1e-14)


# Bad input: a clear exception that names the argument.


@pytest.mark.parametrize(
    ("A", "message"),
    [
        (np.zeros((3, 4)), r"A must be square, got shape \(3, 4\)"),
        (np.zeros(3), r"A must be a 2-D square matrix or a 3-D stack.*shape \(3,\)"),
        (np.zeros((2, 2, 2, 2)), r"A must be a 2-D square matrix or a 3-D stack"),
        (np.float64(1.0), r"A must be a 2-D square matrix"),
        (np.zeros((5, 2, 3)), r"A must be square, got shape \(2, 3\)"),
        ([[1.0, 2.0], [3.0]], r"A must be a rectangular array of numbers"),
    ],
)
def test_bad_shapes(A, message: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ShapeError, match=message):
        aerocontrol.expm(A)
    # ShapeError is a ValueError, so generic handlers still work.
    with pytest.raises(ValueError):
        aerocontrol.expm(A)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_entries_are_named(bad: float) -> None:
    A = np.eye(3)
    A[1, 2] = bad
    with pytest.raises(NonFiniteError, match=r"A must be finite, but A\[1, 2\] is"):
        aerocontrol.expm(A)
    with pytest.raises(NonFiniteError, match=r"A\[1, 2\]"):
        aerocontrol.transition_matrix(A, 1.0)


def test_non_finite_entry_in_a_stack_names_the_matrix() -> None:
    stack = np.zeros((6, 3, 3))
    stack[4, 0, 1] = np.nan
    with pytest.raises(
        NonFiniteError, match=r"problem 4 of the batch: A must be finite.*A\[0, 1\]"
    ):
        aerocontrol.expm(stack)


@pytest.mark.parametrize(
    "A", [np.eye(2, dtype=complex), [[1j, 0], [0, 1]], np.array([["a", "b"], ["c", "d"]])]
)
def test_complex_and_non_numeric_are_type_errors(A) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(NotRealError, match="A must be"):
        aerocontrol.expm(A)
    with pytest.raises(TypeError):
        aerocontrol.expm(A)


def test_non_finite_or_badly_shaped_times() -> None:
    with pytest.raises(NonFiniteError, match=r"t must be finite, but t\[1\] is NaN"):
        aerocontrol.transition_matrix(A747, [0.0, np.nan])
    with pytest.raises(ShapeError, match=r"t must be a scalar or a 1-D array"):
        aerocontrol.transition_matrix(A747, np.zeros((2, 2)))
    with pytest.raises(NotRealError, match="t must be real"):
        aerocontrol.transition_matrix(A747, 1j)


def test_overflow_returns_inf_with_a_warning() -> None:
    with pytest.warns(NumericalOverflowWarning, match="overflowed"):
        result = aerocontrol.expm([[1000.0]])
    assert result[0, 0] == np.inf
    with pytest.warns(NumericalOverflowWarning, match=r"matrices \[1\] of the stack"):
        aerocontrol.expm(np.array([[[1.0]], [[1000.0]]]))
    with pytest.warns(NumericalOverflowWarning):
        aerocontrol.transition_matrix([[1.0, 0.0], [0.0, 2.0]], 1000.0)


def test_warning_points_at_the_caller() -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        aerocontrol.expm([[1000.0]])
    assert caught and caught[0].filename == __file__


def test_approximant_choice_diagnostic() -> None:
    from aerocontrol import _core

    assert _core.expm_approximant_choice(np.zeros((3, 3))) == (3, 0)
    degree, squarings = _core.expm_approximant_choice(100.0 * A747)
    assert degree == 13 and squarings > 0
    # Above order 8, a matrix needing at most 2 squarings takes the Taylor approximant 15+,
    # reported as degree 15; a larger norm goes back to Padé 13.
    rng = np.random.default_rng(0)
    a = rng.standard_normal((12, 12))
    assert _core.expm_approximant_choice(0.1 * a) == (15, 0)
    degree, squarings = _core.expm_approximant_choice(100.0 * a)
    assert degree == 13 and squarings > 2
