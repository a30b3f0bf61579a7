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


_MODES_FIELDS = (
    "eigenvalues",
    "eigenvalue",
    "oscillatory",
    "natural_frequency",
    "damping_ratio",
    "damped_frequency",
    "period",
    "time_to_half",
    "time_to_double",
    "cycles_to_half",
    "time_constant",
    "modal_matrix",
    "modal_matrix_condition",
    "modal_input",
    "characteristic_polynomial",
    "mode_names",
)


def test_the_deferred_modal_matrix_is_that_of_one_analysis_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Above EAGER_VECTORS_MAX_ORDER the modes come from the Schur form without Z and the
    modal matrix, its condition number and P^-1 B on first access: every field equals, bit for
    bit, that of one analysis with the eigenvectors (the order raised past n), over 60 seeded
    systems of orders 17 to 120 (both QR iterations), continuous and discrete, graded states
    among them; and A P = P Λ for the deferred P."""
    rng = np.random.default_rng(2026)
    import aerocontrol.modal as modal

    cases = 0
    for n in (17, 20, 33, 64, 80, 120):
        for variant in range(10):
            A = rng.standard_normal((n, n)) / np.sqrt(n)
            if variant % 3 == 1:
                grade = 10.0 ** np.linspace(-3, 3, n)
                A = A * grade[:, None] / grade[None, :]
            B = rng.standard_normal((n, 2))
            dt = 0.05 if variant % 2 else 0.0
            system = aerocontrol.StateSpace(A, B, np.eye(n)[:1], np.zeros((1, 2)), dt=dt)
            deferred = aerocontrol.modes(system)
            assert "_plant" in vars(deferred)
            P = deferred.modal_matrix
            assert "_plant" not in vars(deferred)
            with monkeypatch.context() as patch:
                patch.setattr(modal, "EAGER_VECTORS_MAX_ORDER", 10**6)
                eager = aerocontrol.modes(system)
            assert "_plant" not in vars(eager)
            for name in _MODES_FIELDS:
                got, expected = getattr(deferred, name), getattr(eager, name)
                if isinstance(expected, np.ndarray):
                    np.testing.assert_array_equal(got, expected, err_msg=f"n = {n}: {name}")
                else:
                    assert got == expected, f"n = {n}: {name}"
            assert P is not None
            if dt == 0.0 and variant % 3 != 1:
                residual = np.linalg.norm(A @ P - P * deferred.eigenvalues[None, :])
                assert residual <= 1e-12 * np.linalg.norm(A) * np.linalg.norm(P)
            cases += 1
    assert cases == 60


def test_a_deferred_singular_modal_matrix_warns_at_the_first_access() -> None:
    """Ten defective 2 x 2 Jordan blocks (λ = -1, ..., -10, each with one eigenvector): above
    16 states ``modes`` does not warn; the first access to the modal matrix does, once, and
    gives None, P^-1 B None and κ₂ above 1e8, as the analysis at the call gives them for a
    small model."""
    n = 20
    A = np.zeros((n, n))
    for k in range(n // 2):
        A[2 * k, 2 * k] = A[2 * k + 1, 2 * k + 1] = -(k + 1.0)
        A[2 * k, 2 * k + 1] = 1.0
    B = np.ones((n, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        m = aerocontrol.modes((A, B))
    np.testing.assert_array_equal(
        np.sort(m.eigenvalues.real), np.repeat(-np.arange(10.0, 0, -1), 2)
    )
    with pytest.warns(IllConditionedWarning, match="modal matrix P is singular"):
        assert m.modal_matrix is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert m.modal_input is None
        assert m.modal_matrix_condition > 1e8


@pytest.mark.parametrize("given", ["matrix", "pair"])
def test_the_deferred_modal_matrix_is_of_the_arrays_as_given_at_the_call(given: str) -> None:
    """The deferred analysis works on copies: a caller who changes its A and B in place
    between ``modes`` and the first access still gets the modal matrix and P^-1 B of the
    matrices it passed (A P = P Λ and P (P^-1 B) = B for them), not an error or another
    plant's. (It held the caller's arrays, and the second analysis read them as changed.)"""
    rng = np.random.default_rng(7)
    n = 24
    A = rng.standard_normal((n, n)) / np.sqrt(n)
    B = rng.standard_normal((n, 2))
    A_given, B_given = A.copy(), B.copy()
    m = aerocontrol.modes(A if given == "matrix" else (A, B))
    A *= 3.0
    A[0, 1] += 1.0
    B[:] = 0.0
    P = m.modal_matrix
    assert P is not None
    residual = np.linalg.norm(A_given @ P - P * m.eigenvalues[None, :])
    assert residual <= 1e-12 * np.linalg.norm(A_given) * np.linalg.norm(P)
    if given == "pair":
        assert m.modal_input is not None
        np.testing.assert_allclose(P @ m.modal_input, B_given, atol=1e-12 * np.abs(B_given).max())
