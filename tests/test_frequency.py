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
