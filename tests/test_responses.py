"""Time responses (chapter §6.2): the chapter's numbers, identities of the responses, and
agreement with scipy.signal.lsim and python-control's forced_response.
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import control
import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
import scipy.signal

import aerocontrol
from aerocontrol import (
    InvalidArgumentError,
    NonFiniteError,
    ShapeError,
    SingularMatrixError,
    responses,
)

A_LON, B_LON = aerocontrol.chapter.boeing747_longitudinal()
A_LAT, B_LAT = aerocontrol.chapter.boeing747_lateral()
ONE_DEGREE = np.pi / 180
LON = aerocontrol.StateSpace(
    A_LON, B_LON, state_names=["u/u0", "alpha", "q", "theta"], input_names=["elevator"]
)


def _random_stable(n: int, m: int, p: int, seed: int) -> aerocontrol.StateSpace:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A -= (np.abs(np.linalg.eigvals(A).real).max() + 0.1) * np.eye(n)
    return aerocontrol.StateSpace(
        A, rng.standard_normal((n, m)), rng.standard_normal((p, n)), rng.standard_normal((p, m))
    )


def _relative(x: np.ndarray, reference: np.ndarray) -> float:
    return float(np.abs(x - reference).max() / np.abs(reference).max())


def test_steady_state_of_a_one_degree_step() -> None:
    # (6.51), printed [0.0459 -0.0186 0.0 -0.0160]; computed [0.045965, -0.018563, 0, -0.015954].
    steady = aerocontrol.steady_state(LON, [ONE_DEGREE])
    np.testing.assert_allclose(steady, [0.045965, -0.018563, 0.0, -0.015954], atol=1e-6)
    np.testing.assert_allclose(steady, [0.0459, -0.0186, 0.0, -0.0160], atol=1e-4)
    np.testing.assert_allclose(
        steady, -np.linalg.solve(A_LON, B_LON[:, 0]) * ONE_DEGREE, rtol=1e-14, atol=1e-18
    )


def test_lift_change_of_the_static_and_dynamic_analyses() -> None:
    # (6.53)-(6.55): ΔCL = CLα α∞ + CLδe δe = -0.100, and the static δe / (Cmα / Δ).
    cl_alpha, cl_de, cm_alpha, cm_de = 5.70, 0.338, -1.26, -1.34
    alpha = aerocontrol.steady_state(LON, [ONE_DEGREE])[1]
    dynamic = cl_alpha * alpha + cl_de * ONE_DEGREE
    delta = -cl_alpha * cm_de + cm_alpha * cl_de
    static = ONE_DEGREE / (cm_alpha / delta)
    assert round(delta, 3) == 7.212
    assert round(dynamic, 3) == -0.100 and round(static, 3) == -0.100
    assert abs(dynamic - static) < 2e-4


def test_step_response_settles_to_the_steady_state() -> None:
    t = np.linspace(0.0, 8000.0, 8001)
    r = aerocontrol.step_response(LON, T=t, eta0=[ONE_DEGREE])
    np.testing.assert_allclose(r.x[-1], aerocontrol.steady_state(LON, [ONE_DEGREE]), atol=1e-7)
    np.testing.assert_array_equal(r.x, r.y)
    assert r.u is not None and np.all(r.u == ONE_DEGREE)
    # A number is the weight of the one input; a multi-input model still needs a vector.
    number = aerocontrol.step_response(LON, T=t, eta0=ONE_DEGREE)
    np.testing.assert_array_equal(number.x, r.x)
    np.testing.assert_array_equal(
        aerocontrol.steady_state(LON, ONE_DEGREE), aerocontrol.steady_state(LON, [ONE_DEGREE])
    )
    lateral = aerocontrol.aircraft.load().lateral()
    with pytest.raises(aerocontrol.ShapeError, match=r"eta0 must have one weight per input \(2\)"):
        aerocontrol.step_response(lateral, T=t, eta0=1.0)


def test_impulse_is_the_free_response_from_b_eta0() -> None:
    # (6.36): x(t) = e^{At} B η0.
    t = np.linspace(0.0, 20.0, 401)
    impulse = aerocontrol.impulse_response(LON, T=t, eta0=[2.0])
    free = aerocontrol.initial_response(LON, 2.0 * B_LON[:, 0], T=t)
    np.testing.assert_array_equal(impulse.x, free.x)
    np.testing.assert_allclose(
        impulse.x[-1], scipy.linalg.expm(20.0 * A_LON) @ B_LON[:, 0] * 2.0, rtol=1e-12
    )


def test_doublet_is_the_free_response_from_a_b_eta0() -> None:
    # (6.38): x(t) = e^{At} A B η0, and it is the derivative of the impulse response.
    t = np.linspace(0.0, 20.0, 2001)
    doublet = aerocontrol.doublet_response(LON, T=t)
    free = aerocontrol.initial_response(LON, A_LON @ B_LON[:, 0], T=t)
    np.testing.assert_array_equal(doublet.x, free.x)
    impulse = aerocontrol.impulse_response(LON, T=t)
    derivative = np.gradient(impulse.x, t, axis=0)
    np.testing.assert_allclose(derivative[5:-5], doublet.x[5:-5], atol=2e-4)


@pytest.mark.parametrize("method", ["zoh", "foh"])
@pytest.mark.parametrize(
    "system",
    [
        aerocontrol.StateSpace(A_LON, B_LON),
        aerocontrol.StateSpace(A_LAT, B_LAT),
        _random_stable(6, 2, 3, 1),
        _random_stable(12, 3, 2, 2),
    ],
    ids=["747-longitudinal", "747-lateral", "random-6", "random-12"],
)
def test_forced_response_against_scipy_and_control(system, method: str) -> None:  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 30.0, 601)
    u = np.cumsum(rng.standard_normal((len(t), system.n_inputs)), axis=0) * 0.01
    x0 = rng.standard_normal(system.n_states) * 0.1
    ours = aerocontrol.forced_response(system, t, u, x0=x0, method=method)
    _, y, x = scipy.signal.lsim(
        (system.A, system.B, system.C, system.D), u, t, X0=x0, interp=(method == "foh")
    )
    assert _relative(ours.x, x) <= 1e-10
    assert _relative(ours.y, y.reshape(ours.y.shape)) <= 1e-10
    if method == "foh":
        peer = control.forced_response(
            control.ss(system.A, system.B, system.C, system.D), t, u.T, X0=x0
        )
        assert _relative(ours.x, peer.states.T) <= 1e-10
        assert _relative(ours.y, peer.outputs.T.reshape(ours.y.shape)) <= 1e-10


def test_step_of_the_singular_example_against_quadrature() -> None:
    # (6.95): A = [[-3, 8], [0, 0]] has a zero eigenvalue, so (6.43) cannot be used; the
    # reference integrates x(t) = ∫_0^t e^{Aτ} dτ B by adaptive quadrature.
    A, B = aerocontrol.chapter.state_feedback_example()
    t = np.linspace(0.0, 3.0, 31)
    r = aerocontrol.step_response((A, B), T=t)
    for k in (1, 10, 30):
        reference, _ = scipy.integrate.quad_vec(
            lambda tau: scipy.linalg.expm(A * tau) @ B[:, 0], 0.0, t[k], epsrel=1e-13
        )
        np.testing.assert_allclose(r.x[k], reference, rtol=1e-12)
    with pytest.raises(SingularMatrixError, match="eigenvalue 0"):
        aerocontrol.steady_state((A, B), [1.0])
    with pytest.raises(SingularMatrixError):
        aerocontrol.dc_gain((A, B))


def _exact_solve(A: np.ndarray, b: np.ndarray) -> list[Fraction]:
    """A^-1 b of a 3 x 3 matrix in exact rational arithmetic (Cramer's rule; every double is a
    rational)."""
    M = [[Fraction(float(v)) for v in row] for row in A]
    rhs = [Fraction(float(v)) for v in b]

    def det(X: list[list[Fraction]]) -> Fraction:
        return (
            X[0][0] * (X[1][1] * X[2][2] - X[1][2] * X[2][1])
            - X[0][1] * (X[1][0] * X[2][2] - X[1][2] * X[2][0])
            + X[0][2] * (X[1][0] * X[2][1] - X[1][1] * X[2][0])
        )

    whole = det(M)
    columns = []
    for j in range(3):
        replaced = [[rhs[i] if k == j else M[i][k] for k in range(3)] for i in range(3)]
        columns.append(det(replaced) / whole)
    return columns


#: A closed loop of loop gain 2^1536 (the shape of feedback's balanced realisation of
#: 2e154/(s + 1) into 1e308 (1/(s + 1) + 1/(s + 2)), closed): couplings of 2^767 and 2^769
#: beside eigenvalues of 1.5 (and ±2^768·√3 j).
_A_BADLY_SCALED = np.array(
    [[-1.0, -(2.0**767), -(2.0**767)], [2.0**769, -1.0, 0.0], [2.0**769, 0.0, -2.0]]
)


@pytest.mark.parametrize("discrete", [False, True])
def test_dc_gain_and_steady_state_of_a_badly_scaled_closed_loop(discrete: bool) -> None:
    """The defect: the core refuses an A with an eigenvalue within 100 n u ||A|| of zero, and
    the eigenvalue -1.5 is within 100·3·u·2^769 = 2e218 of it, so dc_gain reported 'A is
    singular ... (computed as -1.5)' for a closed loop merely badly scaled: its equilibrated
    matrix (rows and columns scaled by powers of two) has condition number 2.6. Oracle: -A^-1 B
    and D - C A^-1 B in exact rational arithmetic, to 2 u (for the discrete model,
    x = (I - A)^-1 B with A - I the same matrix). x0 = -2/(3·2^769)(1 + O(2^-767)), x1 and
    x2 near ±1/3; the gain -1/3 + O(2^-767)."""
    B = np.array([[1.0], [1.0], [0.0]])
    C = np.array([[0.0, 1.0, 2.0]])
    A = _A_BADLY_SCALED + np.eye(3) if discrete else _A_BADLY_SCALED
    model = aerocontrol.StateSpace(A, B, C, [[0.0]], dt=0.1 if discrete else None)
    if discrete:  # the matrix solved is A - I, formed exactly
        assert np.array_equal(model.A - np.eye(3), _A_BADLY_SCALED)
    exact = [-v for v in _exact_solve(_A_BADLY_SCALED, B[:, 0])]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gain = aerocontrol.dc_gain(model)
        if discrete:
            # z = 1 + λ: -0.25 ± 2e231 j outside the unit circle, so the sampled model is
            # unstable and has no steady state; (I - A)^-1 B is still its equilibrium.
            with pytest.raises(InvalidArgumentError, match="sys is unstable"):
                aerocontrol.steady_state(model, [1.0])
            x = responses._steady_state(model.A, model.B, 0.1, np.ones(1))
        else:
            x = aerocontrol.steady_state(model, [1.0])
    np.testing.assert_allclose(x, [float(v) for v in exact], rtol=2 * np.finfo(float).eps)
    expected = float(exact[1] + 2 * exact[2])
    assert expected == pytest.approx(-1.0 / 3.0, rel=1e-15)
    assert abs(gain[0, 0] - expected) <= 2 * np.finfo(float).eps * abs(expected)


@pytest.mark.parametrize("discrete", [False, True])
def test_dc_gain_of_several_inputs_is_each_inputs_steady_state(discrete: bool) -> None:
    """dc_gain solves for every input at once (one factorisation): each column is C x_j + D_j
    with x_j the steady state of input j alone, and D - C A^-1 B (for a discrete model
    D + C (I - A)^-1 B) from numpy; also through the equilibrated retry of a badly scaled A
    (the closed loop above, with a second input)."""
    rng = np.random.default_rng(7)
    n, m, p = 16, 3, 2
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 2.0 * np.eye(n)
    if discrete:
        A = 0.3 * A / np.abs(np.linalg.eigvals(A)).max()
    B, C, D = rng.standard_normal((n, m)), rng.standard_normal((p, n)), rng.standard_normal((p, m))
    model = aerocontrol.StateSpace(A, B, C, D, dt=0.1 if discrete else None)
    gain = aerocontrol.dc_gain(model)
    M = A - np.eye(n) if discrete else A
    expected = D - C @ np.linalg.solve(M, B)
    np.testing.assert_allclose(gain, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    for j in range(m):
        state = aerocontrol.steady_state(model, np.eye(m)[j])
        # The same x_j; C x_j + D_j summed in another order: within n u (|C| |x_j| + |D_j|).
        bound = n * np.finfo(float).eps * (np.abs(C) @ np.abs(state) + np.abs(D[:, j]))
        assert np.all(np.abs(gain[:, j] - (C @ state + D[:, j])) <= bound)
    badly = aerocontrol.StateSpace(
        _A_BADLY_SCALED,
        np.array([[1.0, 2.0], [1.0, 0.0], [0.0, 1.0]]),
        [[0.0, 1.0, 2.0]],
        [[0.0, 0.0]],
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gains = aerocontrol.dc_gain(badly)
        for j in range(2):
            state = aerocontrol.steady_state(badly, np.eye(2)[j])
            assert abs(gains[0, j] - (state[1] + 2 * state[2])) <= 4 * np.finfo(float).eps * abs(
                gains[0, j]
            )
    assert gains[0, 0] == pytest.approx(-1.0 / 3.0, rel=1e-15)


def test_dc_gain_of_feedback_of_a_huge_loop_gain() -> None:
    """The closed loop that feedback forms of that loop (L(0) = 3e462): T(0) = 1 to the
    doubles, and the steady state against exact rational arithmetic (its first entry,
    3.3e-463, below the doubles: 0)."""
    first = aerocontrol.StateSpace([[-1.0]], [[2.0]], [[1e154]], [[0.0]])
    second = aerocontrol.StateSpace(
        [[-1.0, 0.0], [0.0, -2.0]], [[1.0], [1.0]], [[1e308, 1e308]], [[0.0]]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        closed = aerocontrol.feedback(aerocontrol.series(first, second))
        gain = aerocontrol.dc_gain(closed)
        x = aerocontrol.steady_state(closed, [1.0])
    assert gain[0, 0] == 1.0
    exact = [-v for v in _exact_solve(closed.A, closed.B[:, 0])]
    np.testing.assert_allclose(x, [float(v) for v in exact], rtol=2 * np.finfo(float).eps)
    assert x[0] == 0.0 and abs(exact[0]) < Fraction(1, 10**462)


@pytest.mark.parametrize(
    "A",
    [
        np.array([[0.0, 2.0**900], [0.0, -1.0]]),  # an integrator beside a huge coupling
        np.diag([2.0**600, 2.0**-600])
        @ np.array([[1.0, 2.0], [2.0, 4.0]])
        @ np.diag([2.0**-300, 2.0**300]),  # rank one, badly scaled (exactly: powers of two)
    ],
)
def test_singular_a_is_still_refused_after_equilibration(A: np.ndarray) -> None:
    """Equilibration scales rows and columns by powers of two, exactly: a singular A stays
    singular, and the core's error naming the zero eigenvalue stands."""
    assert np.linalg.matrix_rank(np.diag([1.0, 2.0**-600]) @ A @ np.diag([1.0, 2.0**-300])) < 2
    sys_ = (A, np.ones((2, 1)), np.ones((1, 2)), np.zeros((1, 1)))
    with pytest.raises(SingularMatrixError, match="eigenvalue 0"):
        aerocontrol.dc_gain(sys_)
    with pytest.raises(SingularMatrixError, match="eigenvalue 0"):
        aerocontrol.steady_state(sys_, [1.0])


_GOOD = (A_LON, B_LON, np.array([[0.0, 0.0, 0.0, 1.0]]), np.zeros((1, 1)))


def _with(index: int, value: object) -> tuple[object, ...]:
    return tuple(value if k == index else m for k, m in enumerate(_GOOD))


_BAD_MATRICES = [
    _with(0, A_LON[0]),  # A 1-D
    _with(0, A_LON[:, :3]),  # A not square
    _with(0, A_LON + 1j),  # A complex
    _with(0, np.where(np.eye(4) > 0, np.nan, A_LON)),  # A NaN
    _with(1, B_LON[:3]),  # B rows
    _with(1, np.full((4, 1), np.inf)),  # B infinite
    _with(1, [["a"], ["b"], ["c"], ["d"]]),  # B not numbers
]


@pytest.mark.parametrize(
    "bad",
    [
        *_BAD_MATRICES,
        *(bad[:2] for bad in _BAD_MATRICES),
        _with(2, np.ones((1, 3))),  # C columns
        _with(2, np.array([[0.0, np.nan, 0.0, 1.0]])),  # C NaN
        _with(3, np.zeros((1, 2))),  # D columns
        _with(3, np.array([[np.inf]])),  # D infinite
        _GOOD[:3],  # (A, B, C) is no system
    ],
)
def test_a_tuple_is_checked_as_a_state_space_is(bad: tuple[object, ...]) -> None:
    """steady_state and dc_gain read a tuple's matrices without building a StateSpace: each
    bad matrix is refused with the exception and the message StateSpace gives it (those of
    (A, B) by the core's solve, C and D by the core's check_model)."""
    with pytest.raises(Exception) as expected:
        aerocontrol.statespace.as_state_space(bad)  # type: ignore[arg-type]
    with pytest.raises(type(expected.value)) as gain:
        aerocontrol.dc_gain(bad)  # type: ignore[arg-type]
    with pytest.raises(type(expected.value)) as state:
        aerocontrol.steady_state(bad, [1.0])  # type: ignore[arg-type]
    assert str(gain.value) == str(state.value) == str(expected.value)


def test_a_tuple_in_any_layout_gives_the_state_spaces_answer() -> None:
    """Fortran-ordered and strided views give the bits of the StateSpace's C-ordered copies,
    and the caller's arrays are neither modified nor made read-only."""
    model = _random_stable(6, 2, 3, seed=11)
    wide = np.zeros((12, 12))
    wide[::2, ::2] = model.A
    views = (
        wide[::2, ::2],
        np.asfortranarray(model.B),
        np.asfortranarray(model.C),
        np.array(model.D),
    )
    before = [v.copy() for v in views]
    np.testing.assert_array_equal(aerocontrol.dc_gain(views), aerocontrol.dc_gain(model))
    np.testing.assert_array_equal(
        aerocontrol.steady_state(views[:2], [1.0, -0.5]),
        aerocontrol.steady_state(model, [1.0, -0.5]),
    )
    np.testing.assert_array_equal(
        aerocontrol.dc_gain(views[:2]), aerocontrol.dc_gain((model.A, model.B))
    )
    for view, copy in zip(views, before, strict=True):
        np.testing.assert_array_equal(view, copy)
        assert view.flags.writeable


def test_multi_input_gives_one_response_per_input() -> None:
    t = np.linspace(0.0, 10.0, 101)
    lateral = aerocontrol.StateSpace(A_LAT, B_LAT, input_names=["rudder", "aileron"])
    r = aerocontrol.impulse_response(lateral, T=t)
    assert r.x.shape == (2, 101, 4) and r.response_names == ("rudder", "aileron")
    for j in range(2):
        # One input column makes a different augmented matrix: equal to rounding.
        single = aerocontrol.impulse_response((A_LAT, B_LAT[:, [j]]), T=t)
        np.testing.assert_allclose(r.x[j], single.x, rtol=1e-12, atol=1e-15)
    steps = aerocontrol.step_response(lateral, T=t)
    weighted = aerocontrol.step_response(lateral, T=t, eta0=[1.0, 0.0])
    np.testing.assert_allclose(steps.x[0], weighted.x, rtol=1e-14, atol=1e-16)
    assert weighted.x.shape == (101, 4)


def test_several_initial_states_and_inputs_in_one_call() -> None:
    t = np.linspace(0.0, 5.0, 51)
    x0 = np.random.default_rng(4).standard_normal((5, 4))
    batch = aerocontrol.initial_response(LON, x0, T=t)
    assert batch.x.shape == (5, 51, 4)
    for r in range(5):
        np.testing.assert_array_equal(batch.x[r], aerocontrol.initial_response(LON, x0[r], T=t).x)
    u = np.random.default_rng(5).standard_normal((3, 51, 1))
    forced = aerocontrol.forced_response(LON, t, u, method="foh")
    for r in range(3):
        single = aerocontrol.forced_response(LON, t, u[r], method="foh")
        np.testing.assert_array_equal(forced.x[r], single.x)


def test_a_list_of_models_in_one_call() -> None:
    t = np.linspace(0.0, 10.0, 101)
    models = [aerocontrol.StateSpace(A_LON * s, B_LON) for s in (0.5, 1.0, 2.0)]
    batch = aerocontrol.step_response(models, T=t)
    assert batch.x.shape == (3, 101, 4)
    for k, model in enumerate(models):
        np.testing.assert_array_equal(batch.x[k], aerocontrol.step_response(model, T=t).x)
    impulses = aerocontrol.impulse_response(models, T=t)
    np.testing.assert_array_equal(impulses.x[2], aerocontrol.impulse_response(models[2], T=t).x)
    with pytest.raises(ShapeError, match=r"sys\[1\] must have the states"):
        aerocontrol.step_response([models[0], (A_LAT, B_LAT)], T=t)


def test_python_control_models_are_accepted() -> None:
    sysc = control.ss(A_LON, B_LON, np.eye(4), np.zeros((4, 1)))
    t = np.linspace(0.0, 10.0, 101)
    ours = aerocontrol.step_response(sysc, T=t)
    peer = control.step_response(sysc, T=t)
    np.testing.assert_allclose(ours.y, peer.outputs[:, 0, :].T, rtol=1e-10, atol=1e-14)


def test_default_grid_resolves_the_fastest_and_slowest_modes() -> None:
    t = aerocontrol.default_time_grid(LON)
    fastest = np.abs(np.linalg.eigvals(A_LON)).max()
    slowest_decay = np.abs(np.linalg.eigvals(A_LON).real).min()
    assert t[0] == 0.0 and np.allclose(np.diff(t), t[1])
    assert t[1] <= 1.0 / (20 * fastest) * (1 + 1e-12)
    assert t[-1] >= 7.0 / slowest_decay * (1 - 1e-12)
    final_only = aerocontrol.step_response(LON, T=20.0)
    assert final_only.t[-1] == 20.0 and final_only.t[1] <= t[1] * 1.001


@pytest.mark.parametrize(
    ("T", "message"),
    [
        ([0.1, 0.2, 0.3], "T must be a grid that starts at 0"),
        ([0.0, 0.2, 0.1], "strictly increasing"),
        ([0.0, 0.1, 0.3, 0.4], "uniform"),
        ([0.0], "at least 2 times"),
    ],
)
def test_bad_time_grids(T: list[float], message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        aerocontrol.step_response(LON, T=T)


def test_bad_arguments_are_named() -> None:
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ShapeError, match=r"u must have one row of 1 input\(s\) per time"):
        aerocontrol.forced_response(LON, t, np.zeros(10))
    with pytest.raises(ShapeError, match="x0 must be one initial state of 4 values"):
        aerocontrol.initial_response(LON, [1.0, 2.0], T=t)
    with pytest.raises(ShapeError, match=r"eta0 must have one weight per input \(2\)"):
        aerocontrol.step_response((A_LAT, B_LAT), T=t, eta0=[1.0])
    with pytest.raises(NonFiniteError, match=r"u\[3\]"):
        u = np.zeros(11)
        u[3] = np.nan
        aerocontrol.forced_response(LON, t, u)
    with pytest.raises(NonFiniteError, match=r"T\[2\]"):
        aerocontrol.step_response(LON, T=[0.0, 0.1, np.inf])
    with pytest.raises(ShapeError, match=r"C must have as many columns as A \(4\), got 3"):
        aerocontrol.StateSpace(A_LON, B_LON, np.eye(3))
    with pytest.raises(ShapeError, match=r"D must have as many columns as B \(1\), got 2"):
        aerocontrol.StateSpace(A_LON, B_LON, np.eye(4), np.zeros((4, 2)))
    with pytest.raises(ShapeError, match="state_names must have 4 names, got 2"):
        aerocontrol.StateSpace(A_LON, B_LON, state_names=["a", "b"])
    with pytest.raises(TypeError, match="sys must be a StateSpace"):
        aerocontrol.step_response("not a system")  # type: ignore[arg-type]


def test_inputs_are_not_modified() -> None:
    A, B = A_LON.copy(), B_LON.copy()
    u = np.linspace(0.0, 1.0, 11)
    before = (A.copy(), B.copy(), u.copy())
    aerocontrol.forced_response((A, B), np.linspace(0.0, 1.0, 11), u, method="foh")
    aerocontrol.step_response((A, B), T=1.0)
    for now, then in zip((A, B, u), before, strict=True):
        np.testing.assert_array_equal(now, then)


# ----- found by the property suite (tests/properties/test_responses.py) --------------------------


def test_models_without_inputs_have_no_impulse_or_step_responses() -> None:
    # The defect: one response per input, of which there were none, was taken for a single
    # response and indexed (an IndexError).
    free = aerocontrol.StateSpace(-np.eye(2), np.zeros((2, 0)))
    t = np.linspace(0.0, 1.0, 3)
    for response in (
        aerocontrol.impulse_response(free, T=t),
        aerocontrol.doublet_response(free, T=t),
        aerocontrol.step_response(free, T=t),
        aerocontrol.initial_response(free, np.zeros((0, 2)), T=t),
    ):
        assert response.x.shape == (0, 3, 2) and response.y.shape == (0, 3, 2)
        assert response.n_responses == 0 and str(response)
    # A list of models has one response each, to the first input: refused, by name.
    for function in (
        aerocontrol.impulse_response,
        aerocontrol.doublet_response,
        aerocontrol.step_response,
    ):
        with pytest.raises(ShapeError, match=r"one .* response per model"):
            function([free, free], T=t)
    with pytest.raises(ShapeError, match="one initial response per model"):
        aerocontrol.initial_response([free, free], np.zeros((0, 2)), T=t)


def test_input_weights_are_checked_even_where_nothing_uses_them() -> None:
    # The defect: a model without states never read eta0, and a NaN weight was accepted.
    empty = aerocontrol.StateSpace(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[1.0]])
    for function in (aerocontrol.impulse_response, aerocontrol.doublet_response):
        with pytest.raises(NonFiniteError, match=r"eta0\[0\] is NaN") as error:
            function(empty, T=[0.0, 1.0], eta0=np.nan)
        assert error.value.argument == "eta0" and error.value.entry == [0]


def test_results_do_not_share_memory_with_the_arguments() -> None:
    # The defect: forced_response returned the caller's T (and a view of u) as its t and u,
    # so that changing one changed the other.
    t = np.linspace(0.0, 1.0, 11)
    u = np.ones((11, 1))
    response = aerocontrol.forced_response(LON, t, u)
    assert not np.shares_memory(response.t, t) and not np.shares_memory(response.u, u)
    response.t[0] = 5.0
    assert t[0] == 0.0


def test_default_grids_refuse_eigenvalues_beyond_double_precision() -> None:
    # The defect: an eigenvalue that overflowed gave a grid for a model with no modes (0.01 s
    # steps, or 0.01 to 100 rad/s); 1e308 gave 100,002 samples (one over the limit) of a
    # subnormal step with numpy overflow warnings, and a frequency grid of NaN and inf.
    overflowing = aerocontrol.StateSpace(np.full((2, 2), 1e308), np.zeros((2, 1)))
    huge = aerocontrol.StateSpace(np.diag([-1e308, -1.0]), np.zeros((2, 1)))
    for sys in (overflowing, huge):
        with pytest.raises(InvalidArgumentError, match="default time grid"):
            aerocontrol.default_time_grid(sys)
        with pytest.raises(InvalidArgumentError, match="default time grid"):
            aerocontrol.step_response(sys)
    with pytest.raises(InvalidArgumentError, match="default frequency grid"):
        aerocontrol.default_frequency_grid(overflowing)
    omega = aerocontrol.default_frequency_grid(huge)
    # From a tenth of the mode at -1 (resolved from A^-1, 1e-308 of the fastest) to 1e308.
    assert np.all(np.isfinite(omega)) and omega[0] == pytest.approx(0.1) and omega[-1] == 1e308
    # Just below the limit the grid keeps its 100,001 samples at most.
    t = aerocontrol.default_time_grid(aerocontrol.StateSpace(np.diag([-1e300, -1e299]), [[0], [0]]))
    assert len(t) <= aerocontrol.responses.MAX_DEFAULT_SAMPLES
    # Beside a slow mode (7 time constants: 7e11 s) the steps e^(hA) allows (h of 4.5e-285 s)
    # would need more samples than that: refused by name.
    slow = aerocontrol.StateSpace(np.diag([-1e300, -1e-11]), [[0], [0]])
    with pytest.raises(InvalidArgumentError, match="give the grid T"):
        aerocontrol.default_time_grid(slow)


def test_a_number_is_not_a_model() -> None:
    # The defect: a bare TypeError, not one of aerocontrol's (NotRealError is a TypeError).
    with pytest.raises(aerocontrol.NotRealError, match="sys must be a StateSpace"):
        aerocontrol.as_state_space(3.0)
    with pytest.raises(aerocontrol.NotRealError, match="both A and B"):
        aerocontrol.controllability(np.eye(2))


# ----- numerical edges of the time grids (trust fixes) ----------------------------------------


@pytest.mark.parametrize(
    ("sys", "T"),
    [
        # A final time 1e301 over the default step of 5e-302: a ratio of infinity, which
        # int() refused with a bare OverflowError ("cannot convert float infinity").
        ((np.array([[-1e300]]), np.array([[1.0]])), 3e301),
        ((np.array([[-1e300]]), np.array([[1.0]])), 1.7e308),
    ],
)
def test_final_time_beyond_the_samples_is_capped_not_overflowed(sys: tuple, T: float) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", aerocontrol.AerocontrolWarning)
        try:
            response = aerocontrol.step_response(sys, T=T)
        except InvalidArgumentError as error:  # A h overflows: refused, naming T
            assert error.argument == "T" and "T steps by" in str(error)
            return
    assert len(response.t) == aerocontrol.responses.MAX_DEFAULT_SAMPLES
    assert response.t[-1] == T


def test_a_step_too_long_for_the_model_is_refused_naming_T() -> None:
    # The core's refusal named its own argument "dt" and printed 300 digits.
    # T = 3e299 as a final time: 100,000 steps of 3e294 s, A h = -3e594.
    with pytest.raises(InvalidArgumentError, match="T steps by 3e\\+294 s") as caught:
        aerocontrol.step_response((np.array([[-1e300]]), np.array([[1.0]])), T=3e299)
    assert caught.value.argument == "T" and caught.value.value == pytest.approx(3e294)
    with pytest.raises(InvalidArgumentError, match="T steps by") as caught:
        aerocontrol.forced_response(
            (np.array([[-1e300]]), np.array([[1.0]])), np.array([0.0, 1e300]), [1.0, 1.0]
        )
    assert caught.value.argument == "T"


@pytest.mark.parametrize("final", [1e-320, 5e-324, 2e-306])
def test_a_final_time_with_subnormal_steps_is_refused(final: float) -> None:
    # 1e-320 gave a grid of subnormal steps (not uniform: 1e-322 is 20 units of the last
    # place); 5e-324 was refused as "dt must be positive", a name the caller never gave.
    with pytest.raises(InvalidArgumentError, match=r"T as a final time .* too short"):
        aerocontrol.step_response((np.array([[-1.0]]), np.array([[1.0]])), T=final)
    # From 100 tiny normal steps on, the grid is uniform: t = k T / 100 to 1e-9 relatively.
    t = aerocontrol.step_response((np.array([[-1.0]]), np.array([[1.0]])), T=3e-306).t
    assert len(t) == 101 and np.max(np.abs(t - np.arange(101) * 3e-308)) <= 1e-9 * 3e-308


@pytest.mark.parametrize(
    "T", [None, 1e10, np.arange(5) * 1e10], ids=["default grid", "final time", "grid"]
)
def test_discrete_grids_of_too_many_periods_are_refused(T: object) -> None:
    # dt = 1e-300 against 1e10 s: 1e310 periods, an infinite ratio that int() and round()
    # refused with bare OverflowErrors. The default grid (7 / 0.69 s for z = 0.5 would be
    # 1e301 periods) is finite here and kept; a slower mode needs its T.
    model = aerocontrol.StateSpace([[0.5]], [[1.0]], [[1.0]], [[0.0]], dt=1e-300)
    if T is None:
        slow = aerocontrol.StateSpace([[1.0 - 1e-300]], [[1.0]], [[1.0]], [[0.0]], dt=1e-300)
        t = aerocontrol.default_time_grid(model)
        assert len(t) == 101 and t[1] == 1e-300
        # 1 - 1e-300 rounds to 1: no mode, the final time 10 s of 1e301 periods, every
        # q-th of them (q = 1e296 periods), not an overflow.
        t = aerocontrol.default_time_grid(slow)
        assert len(t) <= aerocontrol.responses.MAX_DEFAULT_SAMPLES
        assert t[-1] == pytest.approx(10.0, rel=1e-4)
        return
    for function in (aerocontrol.step_response, aerocontrol.impulse_response):
        with pytest.raises(InvalidArgumentError, match="sampling periods of dt = 1e-300 s"):
            function(model, T=T)


def test_discrete_steps_whose_recurrence_overflows_are_refused_naming_T() -> None:
    # A^q for q = 1e210 periods of an unstable A = 1.5: numpy's RuntimeWarnings, then the
    # core's NonFiniteError blaming A, which is finite.
    unstable = aerocontrol.StateSpace([[1.5]], [[1.0]], [[1.0]], [[0.0]], dt=1e-200)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for call in (
            lambda: aerocontrol.step_response(unstable, T=np.arange(5) * 1e10),
            lambda: aerocontrol.initial_response(unstable, [1.0], T=np.arange(5) * 1e10),
            lambda: aerocontrol.impulse_response(unstable, T=np.arange(5) * 1e10),
        ):
            with pytest.raises(InvalidArgumentError, match="overflows double precision"):
                call()
    # A stable A over as many periods is at rest: A^q = 0, and the step is at its steady
    # state B / (1 - A) = 2 exactly from the first sample of T on.
    stable = aerocontrol.StateSpace([[0.5]], [[1.0]], [[1.0]], [[0.0]], dt=1e-200)
    response = aerocontrol.step_response(stable, T=np.arange(5) * 1e10)
    assert np.array_equal(response.x[:, 0], [0.0, 2.0, 2.0, 2.0, 2.0])


def test_forced_response_on_a_grid_of_1e300_times_smaller_steps() -> None:
    """x' = -x + u, x(0) = 0, u = 1 on t = k 1e-300: x(t) = 1 - e^-t = t (1 - t/2 + ...),
    so x_k = k 1e-300 to the last bit (the correction t^2/2 is below the rounding)."""
    t = 1e-300 * np.arange(6)
    for method in ("zoh", "foh"):
        response = aerocontrol.forced_response(
            (np.array([[-1.0]]), np.array([[1.0]])), t, np.ones(6), method=method
        )
        assert np.allclose(response.x[:, 0], t, rtol=4e-16, atol=0.0)
    # A fast mode, A h = -1: x_k = 1e-300 (1 - e^-k) exactly as the continuous solution.
    response = aerocontrol.forced_response((np.array([[-1e300]]), np.array([[1.0]])), t, np.ones(6))
    expected = 1e-300 * -np.expm1(-np.arange(6.0))
    assert np.allclose(response.x[:, 0], expected, rtol=1e-14, atol=0.0)


@pytest.mark.parametrize("eigenvalue", [1e148, 1e154, 1e200, 1e300, 2e306])
def test_the_default_grid_resolves_modes_up_to_2e306(eigenvalue: float) -> None:
    """The step 1/(20 |λ|) is a normal double up to |λ| = 2.2e306: the grid is made, with the
    documented step, and the response on it is finite. Beyond, refused naming the grid."""
    sys = (np.array([[-eigenvalue]]), np.array([[1.0]]))
    t = aerocontrol.default_time_grid(sys)
    assert t[1] == pytest.approx(1.0 / (20.0 * eigenvalue), rel=1e-15)
    # Final time 7 time constants, at least 100 steps.
    assert len(t) == 141 and t[-1] == pytest.approx(7.0 / eigenvalue, rel=1e-14)
    x = aerocontrol.step_response(sys).x[:, 0]
    assert np.allclose(x, -np.expm1(-eigenvalue * t) / eigenvalue, rtol=1e-13, atol=0.0)
    with pytest.raises(InvalidArgumentError, match="below the normal doubles; give the grid T"):
        aerocontrol.default_time_grid((np.array([[-3e306]]), np.array([[1.0]])))


@pytest.mark.parametrize("layout", ["negative strides", "Fortran", "strided", "zero strides"])
def test_impulse_weights_in_every_layout_give_the_c_ordered_result(layout: str) -> None:
    """eta0 on negative strides gave B eta0 rounded differently from its C-ordered copy (a
    campaign input: two models of one state and three inputs)."""
    B = np.array([[0.1257302210933933, -0.1321048632913019, 0.6404226504432821]])
    sys = [aerocontrol.StateSpace(np.array([[0.1257302210933933]]), B)] * 2
    eta0 = np.array([1.2573022109339329e-09, -1.3210486329130189e-09, 6.4042265044328204e-09])
    if layout == "zero strides":
        eta0 = np.full(3, 1.2573022109339329e-09)
    presented = {
        "negative strides": np.ascontiguousarray(eta0[::-1])[::-1],
        "Fortran": np.asfortranarray(eta0),
        "strided": np.repeat(eta0, 2)[::2],
        "zero strides": np.broadcast_to(eta0[:1], (3,)),
    }[layout]
    for function in (aerocontrol.impulse_response, aerocontrol.doublet_response):
        ours = function(sys, T=np.array([0.0, 0.1]), eta0=presented)
        reference = function(sys, T=np.array([0.0, 0.1]), eta0=eta0.copy())
        assert ours.x.tobytes() == reference.x.tobytes()
        assert ours.y.tobytes() == reference.y.tobytes()


def test_the_default_grid_refuses_an_a_whose_norm_is_far_beyond_its_modes() -> None:
    """A campaign input: a list of a model with modes of size 1 and a nilpotent A of 1e149
    (no mode). The default grid took a step of 0.05 s from the first, on which the core
    refused e^{hA} of the second (h ||A||_1 = 5e148 > 2^53) with an IllConditionedError that
    named neither the grid nor T. Now the step is at most 2^52 / ||A||_1, and where that needs
    more than 100,001 samples the grid is refused by name."""
    nilpotent = aerocontrol.StateSpace(1e149 * np.triu(np.ones((4, 4)), 1), np.zeros((4, 0)))
    modes = aerocontrol.StateSpace(-np.eye(4), np.zeros((4, 0)))
    for sys in ([modes, nilpotent], nilpotent):
        with pytest.raises(InvalidArgumentError, match="default time grid: A has the norm"):
            aerocontrol.default_time_grid(sys)
        with pytest.raises(InvalidArgumentError, match="default time grid: A has the norm"):
            aerocontrol.initial_response(sys, np.ones(4))
    # Where the smaller step fits, it is taken: ||A||_1 = 2^52 / 1e-4 gives h = 1e-4 s
    # instead of 0.01 s (no mode), 100,001 samples to 10 s, and an exact response.
    norm = 2.0**52 / 1e-4
    shear = aerocontrol.StateSpace([[0.0, norm], [0.0, 0.0]], [[0.0], [0.0]])
    t = aerocontrol.default_time_grid(shear)
    assert t[1] == pytest.approx(1e-4, rel=1e-12) and len(t) == 100_001
    x = aerocontrol.initial_response(shear, [0.0, 1.0]).x
    assert np.allclose(x[:, 0], norm * t, rtol=1e-12, atol=0.0) and np.all(x[:, 1] == 1.0)


def test_doublet_initial_state_is_formed_as_a_times_b_eta0() -> None:
    """A campaign input: A = 1.26e-151, B = 1.26e-301, eta0 = 1.26e149. (A B) eta0 underflowed
    A B (1.6e-452) to 0; A (B eta0) = 1.99e-303, a normal double, is x(0) to the rounding."""
    a, b, eta = 1.257302210933933e-151, 1.257302210933933e-301, 1.257302210933933e149
    response = aerocontrol.doublet_response(
        (np.array([[a]]), np.array([[b]])), T=np.array([0.0, 1.0]), eta0=[eta]
    )
    assert response.x[0, 0] == pytest.approx(a * (b * eta), rel=4e-16)
    assert response.x[0, 0] == pytest.approx(1.9875544616903434e-303, rel=1e-15)


@pytest.mark.parametrize(
    ("A", "dt"),
    [
        (np.array([[1.0]]), None),  # x' = x + u: -A^-1 B = -1, never reached
        (np.array([[-2.0, 0.0], [0.0, 1e-6]]), None),  # a slow unstable mode beside a fast one
        (np.array([[0.2, 1.0], [-1.0, 0.2]]), None),  # a growing oscillation
        (np.array([[1.5]]), 0.1),  # z = 1.5
        (np.array([[0.5, 0.0], [0.0, -1.001]]), 0.1),  # z = -1.001, alternating
    ],
)
def test_steady_state_of_an_unstable_model_is_refused(A: np.ndarray, dt: float | None) -> None:
    """Found by a hunt: steady_state returned -A^-1 B η0 of an unstable model silently, a
    state the step grows away from. Refused by name; dc_gain (the output of that equilibrium,
    valid whatever the stability) still gives D - C A^-1 B, against numpy's solve to 1e-14."""
    n = A.shape[0]
    B, C = np.ones((n, 1)), np.ones((1, n))
    model = aerocontrol.StateSpace(A, B, C, np.zeros((1, 1)), dt=dt)
    with pytest.raises(InvalidArgumentError, match="sys is unstable") as caught:
        aerocontrol.steady_state(model, [1.0])
    assert caught.value.argument == "sys"
    M = A - np.eye(n) if dt else A
    np.testing.assert_allclose(aerocontrol.dc_gain(model), -C @ np.linalg.solve(M, B), rtol=1e-14)


@pytest.mark.parametrize(
    ("A", "dt"),
    [
        (np.diag([-1e6, -1e-7]), None),  # stiff: the slow mode settles, if slowly
        (np.array([[0.0, 1.0], [-1.0, 0.0]]), None),  # undamped: Re s is rounding
        (np.array([[-1.0, 0.0], [0.0, -1.0 + 1e-9]]) + np.eye(2), 0.1),  # z = 0 and 1e-9
        (np.array([[0.0, 1.0], [-1.0, 0.0]]), 0.1),  # z = ±j on the unit circle
    ],
)
def test_steady_state_of_a_stable_or_undamped_model(A: np.ndarray, dt: float | None) -> None:
    """Not refused: every mode decays, or lies on the stability boundary to rounding (an
    undamped mode is not called unstable). x∞ = -A^-1 B (discrete: (I - A)^-1 B) against
    numpy's solve, to 1e-14."""
    n = A.shape[0]
    B = np.ones((n, 1))
    model = aerocontrol.StateSpace(A, B, np.eye(n), np.zeros((n, 1)), dt=dt)
    M = A - np.eye(n) if dt else A
    np.testing.assert_allclose(
        aerocontrol.steady_state(model, [1.0]), -np.linalg.solve(M, B[:, 0]), rtol=1e-14
    )


@pytest.mark.parametrize(
    ("A", "slowest"),
    [
        (np.diag([-1e6, -1e-7]), 1e-7),  # the slow mode 1e-13 of the fast one
        (np.array([[-1e6, 1.0], [0.0, -1e-7]]), 1e-7),
        (np.diag([-1.0, -1e-13]), 1e-13),
        (np.array([[-1e3, 0.0, 0.0], [0.0, -1e-10, 2e-10], [0.0, -2e-10, -1e-10]]), 1e-10),
    ],
)
def test_default_grid_reaches_the_slowest_mode_of_a_stiff_model(
    A: np.ndarray, slowest: float
) -> None:
    """Found by a hunt: a decaying mode slower than 1e-12 of the fastest was taken as an
    integrator (the eigenvalues of A resolve it only to u ||A||), so the default grid ended at
    7 time constants of the fast mode and the step response was cut before the slow mode
    moved (x = 7e-6 of 1e7). Now 7 time constants of the slowest decaying mode, 7 / 1e-7 s
    (the step grown to fit 100,001 samples), as the module promises; the response's last
    sample within 1 % of -A^-1 B (e^-7 = 0.09 % of a slow real mode remains, and of the
    oscillating pair about 0.3 %)."""
    n = A.shape[0]
    B = np.ones((n, 1))
    t = aerocontrol.default_time_grid((A, B))
    assert t[-1] == pytest.approx(7.0 / slowest, rel=1e-9)
    assert len(t) == 100_001
    x = aerocontrol.step_response((A, B)).x[-1]
    np.testing.assert_allclose(x, -np.linalg.solve(A, B[:, 0]), rtol=1e-2)


@pytest.mark.parametrize(
    "A",
    [
        np.diag([-1e6, -1e-7, 0.0]),  # an integrator beside the stiff pair
        np.array([[-1e6, 1.0, 0.0, 0.0], [0.0, -1e-7, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], [0.0] * 4]),
        np.array([[-1e6, 1.0, 0.0], [0.0, -1e-7, 1.0], [0.0, 0.0, 0.0]]),  # coupled to it
    ],
)
def test_default_grid_reaches_a_slow_mode_beside_an_integrator(A: np.ndarray) -> None:
    """Found by a hunt: the slow modes are found from the eigenvalues of A^-1, which a
    singular A (an integrator, or a double one) does not have, so the grid ended at 7 time
    constants of the fast mode (7e-6 s) beside a mode of -1e-7. A's null space, an invariant
    subspace, is now deflated first: the grid runs to 7 / 1e-7 s, and the slow state of the
    step response there is within 1 % of its equilibrium (the first two states of -A^-1 B
    restricted to the decaying modes: 1e-6 and 1e7 for the diagonal model)."""
    n = A.shape[0]
    B = np.zeros((n, 1))
    B[:2, 0] = 1.0
    t = aerocontrol.default_time_grid((A, B))
    assert t[-1] == pytest.approx(7.0 / 1e-7, rel=1e-9)
    x = aerocontrol.step_response((A, B)).x[-1]
    decaying = -np.linalg.solve(A[:2, :2], B[:2, 0])
    np.testing.assert_allclose(x[:2], decaying, rtol=1e-2)
    # The same model sampled (z = 1 for the integrator): the grid also reaches the slow mode.
    dt = 1e-7
    Phi = aerocontrol.expm(A * dt)
    samples = aerocontrol.default_time_grid(aerocontrol.StateSpace(Phi, B, dt=dt))
    assert samples[-1] >= 7.0 / 1e-7 * 0.99


@pytest.mark.parametrize("seed", range(6))
def test_regression_default_grid_slow_mode_beside_a_coupled_integrator(seed: int) -> None:
    """Found by a hunt: the null space of a singular A was deflated by an orthogonal basis of
    the singular values above n u σ_max, which took a decaying mode slower than that for null
    space (-1e-10 beside -1e6 and an integrator: a grid of 7e-6 s, 7e10 s without the
    integrator), blurred a slow mode coupled to the integrator by u ||A||, and an exactly
    singular A the LU solve did not find singular gave no slow mode: 65-74 of about 260
    random models per seed ended the grid early. A is now split exactly (by a permutation) into
    its irreducible diagonal blocks, the integrators' [0] dropped, a singular block deflated
    one direction at a time. The oracle: block triangular models (a permutation of an upper
    triangular A, random couplings) whose slowest decaying eigenvalue is exactly -slow: the
    grid ends at 7 / slow to 1e-9."""
    rng = np.random.default_rng(seed)
    for _ in range(20):
        fast, slow = 10.0 ** rng.uniform(4, 7), 10.0 ** rng.uniform(-11, -9.5)
        n = 3 + int(rng.integers(0, 3))
        J = np.diag([-fast, -slow, 0.0, *(-(10.0 ** rng.uniform(-2, 2, n - 3)))])
        J += np.triu(rng.standard_normal((n, n)) * (rng.random((n, n)) < 0.4), 1)
        P = np.eye(n)[rng.permutation(n)]
        A = P @ J @ P.T
        t = aerocontrol.default_time_grid((A, np.ones((n, 1))))
        assert t[-1] == pytest.approx(7.0 / slow, rel=1e-9)
    t = aerocontrol.default_time_grid((np.diag([-1e6, -1e-10, 0.0]), np.ones((3, 1))))
    assert t[-1] == pytest.approx(7e10, rel=1e-9)


def test_steady_state_underflowing_to_a_subnormal_is_correctly_rounded() -> None:
    """x∞ = -A^-1 B of A = [[-1e308]], B = [[1.2573e-4]] is 1.2573e-312, a subnormal: the
    correctly rounded quotient (a property campaign's residual bound once missed that its
    residual, 1.4e-16, is ||A|| times the subnormals' spacing)."""
    x = aerocontrol.steady_state((np.array([[-1e308]]), np.array([[1.2573e-4]])), [1.0])
    assert x.tolist() == [1.2573e-4 / 1e308]
