"""The chapter's numbered results reproduced through the public API, starting from the
coefficients of the embedded Boeing 747 (../shared/reference/seed-values.md).

The models themselves, (6.47) -> (6.48) -> (6.49) and (6.147) -> (6.148) -> (6.150), and the
modes (6.152)-(6.154) are checked in test_aircraft.py; here the analyses and designs that follow
from them. Printed values carry four decimals: 2e-3 relative and half a unit in the last printed
place. The chapter's abstract examples, which have no coefficients, are reproduced beside their
algorithms: the controllability example (6.75)-(6.88) in test_controllability.py, the
state-feedback example (6.94)-(6.102) in test_placement.py, the inverted pendulum (6.202)-(6.223)
in test_riccati.py; the report (test_report.py) prints them beside the chapter's values.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl

import aerocontrol
from aerocontrol import aircraft, design

PRINTED = {"rtol": 2e-3, "atol": 5e-5}


@pytest.fixture(scope="module")
def b747() -> aircraft.Aircraft:
    return aircraft.load("b747-approach")


def test_step_response_steady_state(b747: aircraft.Aircraft) -> None:
    # (6.45), (6.51): one degree of elevator.
    steady = aerocontrol.steady_state(b747.longitudinal(), [np.pi / 180])
    np.testing.assert_allclose(steady, [0.0459, -0.0186, 0.0, -0.0160], rtol=5e-3, atol=5e-5)
    # (6.53)-(6.55): the lift-coefficient change is -0.100 from the steady state.
    c = b747.derivatives
    delta_cl = c["CL_alpha"] * steady[1] + c["CL_de"] * np.pi / 180
    assert delta_cl == pytest.approx(-0.100, abs=5e-4)
    assert -c["CL_alpha"] * c["Cm_de"] + c["Cm_alpha"] * c["CL_de"] == pytest.approx(
        7.212, abs=5e-4
    )


def test_damper_target_polynomial_and_companion_gains(b747: aircraft.Aircraft) -> None:
    sys = b747.lateral()
    lateral_modes = b747.modes("lateral")
    poles = aerocontrol.augment_mode(lateral_modes, "Dutch roll", zeta=0.30)
    target = np.poly(poles).real
    np.testing.assert_allclose(target, [1.0, 1.7258, 1.1891, 0.7396, 0.0319], **PRINTED)  # (6.156)
    open_loop = aerocontrol.charpoly(sys.A)
    np.testing.assert_allclose(open_loop, [1.0, 1.4385, 0.8222, 0.7232, 0.0319], **PRINTED)
    kbar = (target - open_loop)[1:]  # (6.157): ā - a
    np.testing.assert_allclose(kbar, [0.2873, 0.3669, 0.0164, 0.0], **PRINTED)


@pytest.mark.parametrize(
    ("surface", "gains", "closed_loop"),
    [
        (
            "rudder",
            [0.1383, 0.0943, 0.1250, -1.1333],  # (6.159)
            [  # (6.162)
                [-0.1024, -0.0017, 0.1130, -0.9794],
                [-1.6158, -1.1014, -0.0109, 0.3834],
                [0.0, 1.0, 0.0, 0.0],
                [0.4427, -0.0165, 0.0305, -0.5220],
            ],
        ),
        (
            "aileron",
            [-3.5417, 0.8715, 0.6746, -4.0504],  # (6.164)
            [  # (6.165)
                [-0.0999, 0.0, 0.1153, -1.0],
                [-0.4651, -1.3734, -0.2169, 1.5873],
                [0.0, 1.0, 0.0, 0.0],
                [0.4027, -0.0380, 0.0012, -0.2525],
            ],
        ),
    ],
)
def test_dutch_roll_dampers(
    b747: aircraft.Aircraft, surface: str, gains: list[float], closed_loop: list[list[float]]
) -> None:
    # The printed aileron gains came from unrounded matrices: the model built from the
    # coefficients reproduces them to the last printed digit, as it does the rudder gains.
    damper = design.dutch_roll_damper(b747, zeta=0.30, surface=surface)
    np.testing.assert_allclose(damper.k, gains, rtol=0, atol=5.01e-5)
    np.testing.assert_allclose(damper.closed_loop, closed_loop, rtol=0, atol=5.01e-5)
    assert damper.max_relative_error < 1e-12
    named = aircraft.classify_modes(aerocontrol.modes(damper.closed_loop), "lateral")
    l1 = named["dutch roll"][0]
    omega_n = abs(l1)
    assert -l1.real / omega_n == pytest.approx(0.30, rel=1e-10)
    assert omega_n == pytest.approx(0.7477, rel=2e-4)
    np.testing.assert_allclose(named["roll"][0], -1.2308, rtol=1e-4)
    np.testing.assert_allclose(named["spiral"][0], -0.04641, rtol=2e-4)


def test_lqr_root_locus_matches_scipy(b747: aircraft.Aircraft) -> None:
    sys = b747.lateral()
    weights = [0.001, 0.5, 1.0, 2.0, 5.0, 8.0, 9.0, 9.7, 9.76, 10.0]  # Figure 6.12
    locus = design.lqr_root_locus(sys, weights)
    assert locus.shape == (len(weights), 4)
    for c, row in zip(weights, locus, strict=True):
        X = sl.solve_continuous_are(sys.A, sys.B, np.eye(4), np.eye(2) / c**2)
        K = c**2 * sys.B.T @ X
        expected = np.linalg.eigvals(sys.A - sys.B @ K)
        np.testing.assert_allclose(np.sort_complex(row), np.sort_complex(expected), rtol=1e-9)
    # c = 0.001: the closed loop is nearly the open loop (Figure 6.9); the spiral root, the
    # slowest, moves most (by 7.5e-5 of itself).
    np.testing.assert_allclose(
        np.sort_complex(locus[0]), np.sort_complex(np.linalg.eigvals(sys.A)), rtol=1e-4
    )


@pytest.mark.parametrize("c", [0.001, 0.5, 1.0, 2.0])
def test_lateral_regulator_against_scipy_and_control(b747: aircraft.Aircraft, c: float) -> None:
    """(6.224)-(6.227): Q = I, R = I / c² on the model built from the coefficients, against
    scipy and python-control (slycot) within 1e-10."""
    import control

    sys = b747.lateral()
    K, X, poles = aerocontrol.lqr(sys, np.eye(4), np.eye(2) / c**2)
    X_scipy = sl.solve_continuous_are(sys.A, sys.B, np.eye(4), np.eye(2) / c**2)
    K_control, X_control, _ = control.lqr(sys.A, sys.B, np.eye(4), np.eye(2) / c**2)
    for reference in (X_scipy, X_control):
        assert np.linalg.norm(X - reference) <= 1e-10 * np.linalg.norm(reference)
    assert np.linalg.norm(K - K_control) <= 1e-10 * np.linalg.norm(K_control)
    np.testing.assert_allclose(
        np.sort_complex(poles), np.sort_complex(np.linalg.eigvals(sys.A - sys.B @ K)), rtol=1e-12
    )


def test_performance_index_is_the_area_between_the_penalties(b747: aircraft.Aircraft) -> None:
    """Figure 6.11: for a unit sideslip, J = x0^T X x0 equals the integral of x^T Q x + η^T R η
    along the closed-loop response (Simpson's rule on 0.005 s over 120 s, within 1e-6)."""
    sys = b747.lateral()
    for c in (0.5, 1.0, 2.0):
        R = np.eye(2) / c**2
        K, X, _ = aerocontrol.lqr(sys, np.eye(4), R)
        closed = aerocontrol.StateSpace(sys.A - sys.B @ K, sys.B)
        t = np.linspace(0.0, 120.0, 24001)
        response = aerocontrol.initial_response(closed, [1.0, 0.0, 0.0, 0.0], T=t)
        state, control = aerocontrol.plotting.penalty_terms(response, K, np.eye(4), R)
        f = state + control
        integral = (t[1] - t[0]) / 3 * (f[0] + f[-1] + 4 * f[1:-1:2].sum() + 2 * f[2:-1:2].sum())
        assert integral == pytest.approx(X[0, 0], rel=1e-6)


def test_critical_weight_of_the_dutch_roll(b747: aircraft.Aircraft) -> None:
    # The caption of Figure 6.12 says 9.7227 < c < 9.7228 and the text "approximately
    # c = 9.973"; the figure's symbols sit at 9.7727 and 9.7728. The model from the
    # coefficients puts the critical c between the symbols.
    c = design.critical_weight(b747.lateral())
    assert 9.7727 < c < 9.7728
    assert c == pytest.approx(9.772714283, rel=1e-8)
    # Just below it the Dutch roll is an oscillation; just above, two real roots.
    below, above = design.lqr_root_locus(b747.lateral(), [c * (1 - 1e-6), c * (1 + 1e-6)])
    assert np.count_nonzero(below.imag > 0) == 1
    assert np.count_nonzero(above.imag != 0) == 0
    # From the printed (rounded) matrices instead it moves in the third decimal.
    A, B = aerocontrol.chapter.boeing747_lateral()
    assert design.critical_weight(aerocontrol.StateSpace(A, B)) == pytest.approx(9.7749, abs=1e-4)


def test_design_helpers_reject_bad_arguments(b747: aircraft.Aircraft) -> None:
    with pytest.raises(aerocontrol.InvalidArgumentError, match="surface must be one of"):
        design.dutch_roll_damper(b747, surface="elevator")
    with pytest.raises(aerocontrol.InvalidArgumentError, match="weights must be"):
        design.lqr_root_locus(b747.lateral(), [1.0, -2.0])
    with pytest.raises(aerocontrol.InvalidArgumentError, match="does not become critically"):
        design.critical_weight(b747.lateral(), bounds=(0.1, 1.0))
    with pytest.raises(aerocontrol.InvalidArgumentError, match="expected an Aircraft"):
        design.dutch_roll_damper(np.eye(4))  # type: ignore[arg-type]
