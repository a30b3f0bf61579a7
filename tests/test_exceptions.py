"""The exceptions of aerocontrol: every class the native core raises exists, with the right base,
and errors carry their data as attributes."""

from __future__ import annotations

import numpy as np
import pytest

import aerocontrol
from aerocontrol import _core, exceptions


def test_every_class_the_core_raises_exists_with_its_base() -> None:
    names = _core.exception_classes()
    assert len(names) == len(set(names)) == 11
    for name in names:
        cls = getattr(exceptions, name)
        assert name in exceptions.__all__
        if name.endswith("Warning"):
            assert issubclass(cls, exceptions.AerocontrolWarning)
        else:
            assert issubclass(cls, exceptions.AerocontrolError)
    assert issubclass(exceptions.ShapeError, ValueError)
    assert issubclass(exceptions.NoStabilizingSolutionError, np.linalg.LinAlgError)


def test_errors_name_their_argument_and_value() -> None:
    with pytest.raises(exceptions.ShapeError) as shape:
        aerocontrol.expm(np.ones((2, 3)))
    assert shape.value.argument == "A" and shape.value.batch_index is None
    A = np.eye(2)
    A[1, 0] = np.nan
    with pytest.raises(exceptions.NonFiniteError) as nonfinite:
        aerocontrol.expm(A)
    assert nonfinite.value.argument == "A"
    assert nonfinite.value.entry == [1, 0] and np.isnan(nonfinite.value.value)
    with pytest.raises(exceptions.InvalidArgumentError) as invalid:
        aerocontrol.discretize(np.eye(2), np.ones((2, 1)), -0.5)
    assert invalid.value.argument == "dt" and invalid.value.value == -0.5


def test_uncontrollable_errors_carry_the_eigenvalues() -> None:
    A = np.diag([-1.0, -2.0])
    with pytest.raises(exceptions.UncontrollableError) as error:
        aerocontrol.place_bass_gura(A, [1.0, 0.0], [-3.0, -4.0])
    assert error.value.eigenvalues is not None
    assert np.allclose(error.value.eigenvalues, [-2.0])


def test_batch_errors_carry_the_index_of_the_problem() -> None:
    A = np.stack([np.diag([-1.0, -2.0])] * 3)
    A[2, 1, 1] = np.inf
    with pytest.raises(exceptions.NonFiniteError, match="problem 2 of the batch") as error:
        aerocontrol.expm(A)
    assert error.value.batch_index == 2
    assert error.value.argument == "A" and error.value.entry == [1, 1]
    R = np.stack([np.eye(1), np.zeros((1, 1)), np.eye(1)])  # a singular R in problem 1
    with pytest.raises(exceptions.InvalidArgumentError) as weight:
        aerocontrol.batch.solve_care_batch(-np.eye(2), np.ones((2, 1)), np.eye(2), R)
    assert weight.value.batch_index == 1 and weight.value.argument == "R"


def test_errors_raised_in_python_have_the_attributes_too() -> None:
    with pytest.raises(exceptions.AerocontrolError) as error:
        aerocontrol.lqr(np.eye(2))
    assert error.value.batch_index is None
