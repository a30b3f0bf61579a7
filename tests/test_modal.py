"""Modal analysis: the chapter's lateral modes (6.152)-(6.155), the modal test of
controllability (6.61), defective matrices, and mode characteristics in closed form."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import aerocontrol
from aerocontrol import IllConditionedWarning

A_LAT, B_LAT = aerocontrol.chapter.boeing747_lateral()


def test_lateral_modes_of_the_chapter() -> None:
    # (6.152)-(6.154), printed from the unrounded matrices (about 4 digits): spiral -0.04641,
    # Dutch roll -0.08066 ± 0.7433i (ω_n 0.7477, ζ 0.1079), roll -1.2308; t½ 14.93 s, 0.56 s.
    m = aerocontrol.modes(A_LAT, mode_names=["spiral", "Dutch roll", "roll"])
    spiral, dutch, roll = 0, 1, 2
    assert m.oscillatory.tolist() == [False, True, False]
    assert m.eigenvalue[spiral].real == pytest.approx(-0.04641, rel=2e-3)
    assert m.eigenvalue[dutch].real == pytest.approx(-0.08066, rel=2e-3)
    assert m.eigenvalue[dutch].imag == pytest.approx(0.7433, rel=2e-3)
    assert m.eigenvalue[roll].real == pytest.approx(-1.2308, rel=2e-3)
    assert m.natural_frequency[dutch] == pytest.approx(0.7477, rel=2e-3)
    assert m.damping_ratio[dutch] == pytest.approx(0.1079, rel=2e-3)
    assert m.time_to_half[roll] == pytest.approx(0.56, rel=1e-2)
    assert m.time_to_half[spiral] == pytest.approx(14.93, rel=2e-3)
    # (6.155): λ^4 + 1.4385 λ^3 + 0.8222 λ^2 + 0.7232 λ + 0.0319.
    np.testing.assert_allclose(
        m.characteristic_polynomial, [1, 1.4385, 0.8222, 0.7232, 0.0319], atol=2e-4
    )
    np.testing.assert_allclose(
        m.characteristic_polynomial, np.poly(np.linalg.eigvals(A_LAT)).real, rtol=1e-12
    )
    table = str(m)
    assert "Dutch roll" in table and "0.1079" in table and "14.93" in table


def test_modal_matrix_diagonalises_and_modal_input() -> None:
    m = aerocontrol.modes((A_LAT, B_LAT))
    P = m.modal_matrix
    assert P is not None and m.modal_input is not None
    np.testing.assert_allclose(np.linalg.solve(P, A_LAT @ P), np.diag(m.eigenvalues), atol=1e-12)
    np.testing.assert_allclose(m.modal_input, np.linalg.solve(P, B_LAT), atol=1e-12)


def test_uncontrollable_mode_has_a_zero_row() -> None:
    # (6.75)-(6.88): with B = [-1, 1]^T the mode λ = -2 is not reached.
    A, _ = aerocontrol.chapter.controllability_example()
    m = aerocontrol.modes((A, np.array([[-1.0], [1.0]])))
    assert m.modal_input is not None
    reached = np.abs(m.modal_input[:, 0]) > 1e-12
    assert dict(zip(np.round(m.eigenvalues.real, 12), reached, strict=True)) == {
        -1.0: True,
        -2.0: False,
    }


def test_defective_matrix_reports_a_singular_modal_matrix() -> None:
    double_integrator = np.array([[0.0, 1.0], [0.0, 0.0]])
    with pytest.warns(IllConditionedWarning, match="modal matrix P is singular"):
        m = aerocontrol.modes((double_integrator, [[0.0], [1.0]]))
    assert m.modal_matrix is None and m.modal_input is None
    assert m.modal_matrix_condition > 1e8
    assert np.isnan(m.damping_ratio).all()
    np.testing.assert_array_equal(m.characteristic_polynomial, [1.0, 0.0, 0.0])


def test_mode_characteristics_in_closed_form() -> None:
    # λ = -1 ± 2i and 0.5 (unstable).
    A = np.array([[-1.0, 2.0, 0.0], [-2.0, -1.0, 0.0], [0.0, 0.0, 0.5]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = aerocontrol.modes(A)
    oscillation = int(np.argmax(m.oscillatory))
    real = 1 - oscillation
    assert m.natural_frequency[oscillation] == pytest.approx(np.sqrt(5))
    assert m.damping_ratio[oscillation] == pytest.approx(1 / np.sqrt(5))
    assert m.period[oscillation] == pytest.approx(np.pi)
    assert m.cycles_to_half[oscillation] == pytest.approx(np.log(2) / np.pi)
    assert m.time_to_double[real] == pytest.approx(2 * np.log(2))
    assert np.isnan(m.time_to_half[real]) and m.time_constant[real] == pytest.approx(2.0)


def test_charpoly_of_the_state_feedback_example() -> None:
    A, _ = aerocontrol.chapter.state_feedback_example()
    np.testing.assert_array_equal(aerocontrol.charpoly(A), [1.0, 3.0, 0.0])


def test_mode_names_of_the_wrong_count_are_a_shape_error() -> None:
    # Found by the property suite: a bare ValueError, not one of aerocontrol's.
    with pytest.raises(aerocontrol.ShapeError, match="mode_names must name 3 modes, got 1"):
        aerocontrol.modes(A_LAT, mode_names=["spiral"])


def test_a_tuple_in_any_layout_gives_the_state_spaces_modes() -> None:
    """modes reads a tuple's matrices without building a StateSpace: a Fortran-ordered A and
    a strided B give the bits of the StateSpace's C-ordered copies, unmodified, and a bad B is
    refused by name as StateSpace refuses it."""
    wide = np.zeros((4, 4))
    wide[:, ::2] = B_LAT
    A, B = np.asfortranarray(A_LAT), wide[:, ::2]
    ours = aerocontrol.modes((A, B))
    reference = aerocontrol.modes(aerocontrol.StateSpace(A_LAT, B_LAT))
    np.testing.assert_array_equal(ours.eigenvalues, reference.eigenvalues)
    np.testing.assert_array_equal(ours.modal_input, reference.modal_input)
    np.testing.assert_array_equal(ours.damping_ratio, reference.damping_ratio)
    assert ours.mode_names == ("mode 1", "mode 2", "mode 3")
    np.testing.assert_array_equal(A, A_LAT)
    assert A.flags.writeable and B.flags.writeable
    bad = np.full((4, 2), np.nan)
    with pytest.raises(aerocontrol.NonFiniteError, match=r"^B must be finite, but B\[0, 0\]"):
        aerocontrol.modes((A_LAT, bad))
    with pytest.raises(aerocontrol.ShapeError, match="B must have as many rows as A"):
        aerocontrol.modes((A_LAT, B_LAT[:3]))
