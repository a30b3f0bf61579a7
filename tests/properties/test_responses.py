"""Properties of state-space models and time responses (aerocontrol.statespace, .responses).

Oracles: the exact response at the given times, computed in long double by an independent
recurrence on Van Loan's exact discretisation (oracles.exact_response, with its error bound);
y = C x + D u from the returned states; the grid's definition; steady states and DC gains by
their residual and numpy's solve; the model's matrices kept bitwise.
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.responses import MAX_DEFAULT_SAMPLES

from .harness import Arg, Warned, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U,
    exact_response,
    expm_long,
    finite,
    norm,
    quietly,
    row_norms,
    silenced,
)
from .oracles import condition as condition_number
from .strategies import (
    ALL_PRESENTATIONS,
    LAYOUTS,
    model_matrices,
    orders,
    presented,
    presented_system,
    rectangular,
    scalar,
    square,
    system,
)

COVERED = {
    "StateSpace",
    "as_state_space",
    "impulse_response",
    "doublet_response",
    "step_response",
    "initial_response",
    "forced_response",
    "steady_state",
    "dc_gain",
    "default_time_grid",
}

#: Samples of a response compared with the exact one (the grid may have 100,001).
COMPARED_SAMPLES = 25

STEPS = (0.1, 0.05, 1.0, 0.01, 3.7, 1e-3, 1e-300, 1e3, 1e300)


@st.composite
def time_grids(draw: st.DrawFn) -> Arg:
    """T: a uniform grid (arange or linspace), a final time, None for the default grid, or
    one that must be refused (one sample, not from 0, not uniform, decreasing, NaN, 2-D)."""
    kind = draw(
        st.sampled_from(
            (
                *("arange", "linspace", "arange", "final time", "default") * 3,
                *("one sample", "not from 0", "not uniform", "decreasing", "nan", "2-D"),
            )
        )
    )
    k = draw(st.integers(2, 30))
    h = draw(st.sampled_from(STEPS))
    if kind == "default":
        return plain(None)
    if kind == "final time":
        return draw(scalar(h * k, kinds=("float", "np.float64", "0-d array", "int")))
    with np.errstate(all="ignore"):
        grid = {
            "arange": h * np.arange(k),
            "linspace": np.linspace(0.0, h * (k - 1), k),
            "one sample": np.zeros(1),
            "not from 0": h * np.arange(1, k + 1),
            "not uniform": h * np.arange(k) ** 1.5,
            "decreasing": -h * np.arange(k),
            "nan": np.where(np.arange(k) == k - 1, np.nan, h * np.arange(k)),
            "2-D": h * np.arange(2 * k).reshape(2, k),
        }[kind]
    return draw(presented(grid, LAYOUTS))


def _check_grid(t: np.ndarray) -> None:
    """A grid the responses may return: from 0, increasing, uniform, at most 100,001 times."""
    assert t.ndim == 1 and 2 <= len(t) <= MAX_DEFAULT_SAMPLES, f"{len(t)} samples"
    assert t[0] == 0.0 and finite(t) and np.all(np.diff(t) > 0), "t is not an increasing grid"
    h = t[-1] / (len(t) - 1)
    assert np.max(np.abs(t - h * np.arange(len(t)))) <= 1e-9 * h, "t is not uniform"


def _models(sys: Any) -> list[tuple[np.ndarray, ...]]:
    """(A, B, C, D) of each canonical model: one, or a list."""
    return [model_matrices(model) for model in (sys if isinstance(sys, list) else [sys])]


def _responses(array: np.ndarray | None, several: bool) -> list[np.ndarray | None]:
    if array is None:
        return [None]
    return list(array) if several else [array]


def _check_trajectories(
    result: Any,
    models: list[tuple[np.ndarray, ...]],
    starts: list[np.ndarray],
    inputs: list[np.ndarray],
    hold: str,
    warned: Warned,
    initial_errors: list[float],
) -> None:
    """Each response r of ``result`` against the exact one from ``starts[r]`` under
    ``inputs[r]`` (samples, m), with ``models[r]``; and y = C x + D u."""
    several = result.x.ndim == 3
    xs = _responses(result.x, several)
    ys = _responses(result.y, several)
    assert len(xs) == len(starts), f"{len(xs)} responses, expected {len(starts)}"
    t = result.t
    compared = min(len(t), COMPARED_SAMPLES)
    for r, (x, y) in enumerate(zip(xs, ys, strict=True)):
        A, B, C, D = models[r]
        u = inputs[r]
        assert x is not None and y is not None
        assert x.shape == (len(t), A.shape[0]) and y.shape == (len(t), C.shape[0])
        # y = C x + D u from the returned x (D u only where an input is applied).
        applied = u if result.u is not None else np.zeros_like(u)
        with silenced():
            expected_y = x @ C.T + applied @ D.T
            scale = norm(C) * row_norms(x) + norm(D) * row_norms(applied)
        if finite(x, expected_y):
            error = row_norms(y - expected_y)
            bound = SLACK * max(A.shape[0], 1) * (U * scale + TINY)
            assert np.all(error <= bound), "y = C x + D u"
        reference, tolerance = exact_response(
            A, B, t[:compared], starts[r], u[:compared], hold, initial_errors[r]
        )
        exact = finite(reference) and np.max(np.abs(reference), initial=0.0) < 1e300
        if not exact or not np.all(np.isfinite(tolerance)):
            continue
        assert not np.any(np.isnan(x[:compared])), "NaN in a response whose exact value is finite"
        if not finite(x[:compared]):
            continue  # an infinity comes with its warning (checked by the harness)
        error = row_norms(x[:compared] - reference)
        worst = int(np.argmax(error - tolerance))
        assert error[worst] <= tolerance[worst], (
            f"response {r} at t = {t[worst]}: error {error[worst]:.3e} exceeds the "
            f"tolerance {tolerance[worst]:.3e}"
        )
    assert isinstance(str(result), str)


# ----- free responses and steps -----------------------------------------------------------------


def _free_oracle(kind: str) -> Any:
    """The oracle of the free responses: from x0 (initial), B η0 (impulse) or A B η0
    (doublet), one response per initial state or input weight, or per model of a list (each
    from the first)."""

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        _check_grid(result.t)
        if args["T"] is not None and np.ndim(args["T"]) == 1:
            assert np.array_equal(result.t, np.asarray(args["T"], float)), "t is not T"
        models = _models(args["sys"])
        several = isinstance(args["sys"], list)
        m = models[0][1].shape[1]
        if kind == "initial":
            rows = list(np.atleast_2d(np.asarray(args["x0"], float)))
        else:
            eta0 = args["eta0"]
            rows = list(np.eye(m) if eta0 is None else np.atleast_1d(eta0)[None, :])
        cases = (
            [(model, rows[0]) for model in models]
            if several
            else [(models[0], row) for row in rows]
        )
        starts, errors = [], []
        for (A, B, _, _), row in cases:
            if kind == "initial":
                starts.append(row)
                errors.append(0.0)
                continue
            column = B.astype(np.longdouble) @ row
            rounding = norm(B) * norm(row)
            if kind == "doublet":
                column = A.astype(np.longdouble) @ column
                rounding *= norm(A)
            with silenced():
                starts.append(column.astype(np.float64))
            errors.append(SLACK * max(A.shape[0], 1) * U * rounding)
        per_response = [model for model, _ in cases]
        inputs = [np.zeros((len(result.t), model[1].shape[1])) for model in per_response]
        _check_trajectories(result, per_response, starts, inputs, "zoh", warned, errors)
        assert result.u is None

    return oracle


def _step_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    _check_grid(result.t)
    models = _models(args["sys"])
    several_models = isinstance(args["sys"], list)
    m = models[0][1].shape[1]
    eta0 = args["eta0"]
    weights = np.eye(m) if eta0 is None else np.atleast_1d(np.asarray(eta0, float))[None, :]
    if several_models:
        per_response, inputs_of = models, [weights[0]] * len(models)
    else:
        per_response, inputs_of = [models[0]] * len(weights), list(weights)
    k = len(result.t)
    inputs = [np.repeat(w[None, :], k, axis=0) for w in inputs_of]
    starts = [np.zeros(model[0].shape[0]) for model in per_response]
    _check_trajectories(result, per_response, starts, inputs, "zoh", warned, [0.0] * len(starts))
    applied = result.u if result.u.ndim == 3 else result.u[None]
    expected = np.array(inputs).reshape(len(inputs), k, m)
    assert np.array_equal(applied, expected), "u is not the step's input"


@st.composite
def models(draw: st.DrawFn, several: bool = True) -> tuple[Arg, int, int]:
    """(sys, n, m): one model as a tuple or an object with A, B, C, D, or a list of two
    models of one size."""
    n, m, p = draw(orders()), draw(st.integers(0, 3)), draw(st.integers(0, 3))
    matrices = draw(system(n, m, p))
    if several and draw(st.sampled_from((False, False, False, True))):
        other = draw(system(n, m, p))
        first, second = (
            draw(presented_system(x, LAYOUTS, "attributes")) for x in (matrices, other)
        )
        value = [first.value, second.value]
        return Arg(value, [first.canonical, second.canonical], "list of two models"), n, m
    pair = draw(st.sampled_from((False, False, True)))
    return draw(presented_system(matrices[:2] if pair else matrices, ALL_PRESENTATIONS)), n, m


def _weights(draw: st.DrawFn, m: int) -> Arg:
    """eta0: None (a response per input), a weight per input, or a number for one input."""
    kind = draw(st.sampled_from(("none", "vector", "vector", "number", "wrong length")))
    if kind == "none":
        return plain(None)
    if kind == "number" and m == 1:
        value = draw(st.sampled_from((1.0, -2.0, 1e300, 0.0, np.nan)))
        return draw(scalar(value, kinds=("float", "np.float64", "0-d array", "int", "complex")))
    size = m + 1 if kind == "wrong length" else m
    return draw(presented(draw(rectangular(1, size))[0]))


@given(st.data())
def test_impulse_and_doublet_responses(data: st.DataObject) -> None:
    sys, _, m = data.draw(models())
    kind = data.draw(st.sampled_from(("impulse", "doublet")))
    function = {
        "impulse": aerocontrol.impulse_response,
        "doublet": aerocontrol.doublet_response,
    }[kind]
    exercise(
        f"{kind}_response",
        function,
        {"sys": sys, "T": data.draw(time_grids()), "eta0": _weights(data.draw, m)},
        _free_oracle(kind),
    )


@given(st.data())
def test_initial_response(data: st.DataObject) -> None:
    sys, n, _ = data.draw(models())
    shape = data.draw(st.sampled_from(((n,), (1, n), (3, n), (n + 1,))))
    x0 = data.draw(rectangular(1, int(np.prod(shape)))).reshape(shape)
    exercise(
        "initial_response",
        aerocontrol.initial_response,
        {"sys": sys, "x0": data.draw(presented(x0)), "T": data.draw(time_grids())},
        _free_oracle("initial"),
    )


@given(st.data())
def test_step_response(data: st.DataObject) -> None:
    sys, _, m = data.draw(models())
    exercise(
        "step_response",
        aerocontrol.step_response,
        {"sys": sys, "T": data.draw(time_grids()), "eta0": _weights(data.draw, m)},
        _step_oracle,
    )


def _forced_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    (A, B, C, D) = _models(args["sys"])[0]
    n, m = B.shape
    t = np.asarray(args["T"], float)
    assert np.array_equal(result.t, t)
    _check_grid(t)
    u = np.asarray(args["u"], float)
    histories = u.reshape(u.shape[0] if u.ndim == 3 else 1, len(t), m)
    x0 = np.zeros(n) if args["x0"] is None else np.asarray(args["x0"], float)
    starts = np.atleast_2d(x0)
    count = max(len(histories), len(starts))
    histories = np.broadcast_to(histories, (count, len(t), m))
    starts = np.broadcast_to(starts, (count, n))
    _check_trajectories(
        result,
        [(A, B, C, D)] * count,
        list(starts),
        list(histories),
        args["method"],
        warned,
        [0.0] * count,
    )
    assert np.array_equal(result.u.reshape(count, len(t), m), histories), "u is not the input"


@given(st.data())
def test_forced_response(data: st.DataObject) -> None:
    sys, n, m = data.draw(models(several=False))
    T = data.draw(time_grids())
    k = len(T.canonical) if isinstance(T.canonical, np.ndarray) and T.canonical.ndim == 1 else 5
    shape = data.draw(st.sampled_from(((k, m), (k, m), (2, k, m), (k,), (k + 1, m))))
    u = data.draw(rectangular(1, int(np.prod(shape)))).reshape(shape)
    x0 = data.draw(st.sampled_from((None, (n,), (1, n), (2, n), (3, n))))
    exercise(
        "forced_response",
        aerocontrol.forced_response,
        {
            "sys": sys,
            "T": T,
            "u": data.draw(presented(u)),
            "x0": plain(None)
            if x0 is None
            else data.draw(presented(data.draw(rectangular(1, int(np.prod(x0)))).reshape(x0))),
            "method": plain(data.draw(st.sampled_from(("zoh", "foh", "zoh", "linear")))),
        },
        _forced_oracle,
    )


# ----- steady state, DC gain, the default grid --------------------------------------------------


def _steady_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, _, _ = _models(args["sys"])[0]
    eta0 = np.atleast_1d(np.asarray(args["eta0"], float))
    assert result.shape == (A.shape[0],)
    if not finite(result):
        return
    # A backward-stable solve of A x = -B η0: its residual is small relative to ||A|| ||x||,
    # plus ||A|| times the spacing of the subnormals where x underflows (A = [[-1e308]],
    # B = [[1.26e-4]]: x = 1.26e-312, correctly rounded, has a residual of 1e-16).
    with silenced():
        forcing = B @ eta0
        residual = A @ result + forcing
        scale = norm(A) * norm(result) + norm(forcing)
        underflow = norm(A) * np.finfo(float).smallest_subnormal
    if finite(residual, scale, underflow):
        n = A.shape[0]
        bound = SLACK * n * (U * scale + underflow + TINY)
        assert norm(residual) <= bound, "A x + B η0 != 0"


@given(st.data())
def test_steady_state(data: st.DataObject) -> None:
    sys, _, m = data.draw(models(several=False))
    eta0 = _weights(data.draw, m)
    if eta0.value is None:
        eta0 = data.draw(presented(np.ones(m)))
    exercise("steady_state", aerocontrol.steady_state, {"sys": sys, "eta0": eta0}, _steady_oracle)


def _dc_gain_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, C, D = _models(args["sys"])[0]
    n = A.shape[0]
    assert result.shape == D.shape
    if not finite(result) or n == 0:
        if n == 0:
            assert np.array_equal(result, D), "no states: the gain is D"
        return
    # D - C A^-1 B against numpy: the solve's forward error is cond(A) u ||A^-1 B||.
    X = quietly(np.linalg.solve, A, B) if np.linalg.matrix_rank(A) == n else None
    if X is None or not finite(X):
        return
    with silenced():
        reference = D - C @ X
    condition = condition_number(A)
    bound = SLACK * n * (U * condition * norm(C) * norm(X) + U * norm(D) + TINY)
    if finite(reference, bound):
        assert norm(result - reference) <= bound, "DC gain against numpy"


@given(st.data())
def test_dc_gain(data: st.DataObject) -> None:
    sys, _, _ = data.draw(models(several=False))
    exercise("dc_gain", aerocontrol.dc_gain, {"sys": sys}, _dc_gain_oracle)


def _default_grid_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    _check_grid(result)
    n = _models(args["sys"])[0][0].shape[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", aerocontrol.AerocontrolWarning)
        free = aerocontrol.initial_response(args["sys"], np.zeros(n))
    assert np.array_equal(free.t, result), "the responses' default grid differs"


@given(st.data())
def test_default_time_grid(data: st.DataObject) -> None:
    sys, _, _ = data.draw(models())
    exercise("default_time_grid", aerocontrol.default_time_grid, {"sys": sys}, _default_grid_oracle)


# ----- models -----------------------------------------------------------------------------------


def _state_space_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A = np.asarray(args["A"], float)
    B = np.asarray(args["B"], float)
    B = B.reshape(-1, 1) if B.ndim == 1 else B
    n, m = B.shape
    C = np.eye(n) if args["C"] is None else np.asarray(args["C"], float)
    D = np.zeros((C.shape[0], m)) if args["D"] is None else np.asarray(args["D"], float)
    for name, given_, kept in (("A", A, result.A), ("B", B, result.B), ("C", C, result.C)):
        assert kept.dtype == np.float64 and kept.flags.c_contiguous, name
        assert not kept.flags.writeable, f"{name} is writeable"
        assert np.array_equal(kept, given_) and kept.tobytes() == given_.tobytes(), name
    assert np.array_equal(result.D, D)
    assert (result.n_states, result.n_inputs, result.n_outputs) == (n, m, C.shape[0])
    names = args["state_names"]
    assert result.state_names == (
        tuple(f"x{i}" for i in range(n)) if names is None else tuple(map(str, names))
    )
    assert isinstance(repr(result), str)


NAMES = st.sampled_from(("none", "right", "one too many", "numbers"))


@given(st.data())
def test_state_space(data: st.DataObject) -> None:
    n, m, p = data.draw(orders()), data.draw(st.integers(0, 3)), data.draw(st.integers(0, 3))
    A, B, C, D = data.draw(system(n, m, p))
    if m == 1 and data.draw(st.booleans()):
        B = B[:, 0]
    names = data.draw(NAMES)
    state_names = {
        "none": None,
        "right": [f"s{i}" for i in range(n)],
        "one too many": [f"s{i}" for i in range(n + 1)],
        "numbers": list(range(n)),
    }[names]
    optional = data.draw(st.sampled_from(("both", "no C", "no D", "neither")))
    exercise(
        "StateSpace",
        aerocontrol.StateSpace,
        {
            "A": data.draw(presented(A)),
            "B": data.draw(presented(B)),
            "C": plain(None) if optional in ("no C", "neither") else data.draw(presented(C)),
            "D": plain(None) if optional in ("no D", "neither") else data.draw(presented(D)),
            "state_names": plain(state_names),
        },
        _state_space_oracle,
    )


def _as_state_space_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    model = args["model"]
    assert isinstance(model, (tuple, SimpleNamespace)), "only models are state spaces"
    A, B, C, D = _models(model)[0]
    for got, expected in ((result.A, A), (result.B, B), (result.C, C), (result.D, D)):
        assert np.array_equal(got, expected) and got.tobytes() == expected.tobytes()


@given(st.data())
def test_as_state_space(data: st.DataObject) -> None:
    kind = data.draw(st.sampled_from(("model", "model", "three matrices", "number", "matrix")))
    n = data.draw(orders())
    if kind == "model":
        model = data.draw(models(several=False))[0]
    elif kind == "three matrices":
        matrices = data.draw(system(n, 1, 1))[:3]
        model = data.draw(presented_system(matrices, LAYOUTS))
    elif kind == "number":
        model = plain(3.0)
    else:  # a matrix is no model (as a list it is a sequence of matrices: also refused)
        model = data.draw(presented(data.draw(square(n)), LAYOUTS[:-3] + LAYOUTS[-2:]))
    outcome = exercise(
        "as_state_space", aerocontrol.as_state_space, {"model": model}, _as_state_space_oracle
    )
    if kind in ("three matrices", "number", "matrix"):
        assert outcome.error is not None, f"{kind} was taken for a model"


# ----- inputs a campaign found ------------------------------------------------------------------


def test_regression_initial_response_oracle_of_a_huge_off_diagonal() -> None:
    """A = [[0, 0], [9e15, 2]] from x0 = (0.126, -0.132) over one second: the long double
    reference squared I + F 55 times and rounded the diagonal 1 + 2^-54 of e^(A / 2^55) to a
    relative 1e-3, so the reference was 1.1e6 off in 3.6e15 and blamed aerocontrol's answer
    (0.006 ulp from mpmath's). The reference now squares F = e^Y - I, and both it and the
    response are checked against the closed form e^(At) = [[1, 0], [c (e^(2t) - 1)/2,
    e^(2t)]], evaluated in 50 digits (mpmath)."""
    mpmath = pytest.importorskip("mpmath")
    c = 9.007199254740994e15
    A = np.array([[0.0, 0.0], [c, 2.0]])
    B = np.array([[0.1257302210933933], [-0.1321048632913019]])
    x0 = np.array([0.1257302210933933, -0.1321048632913019])
    with mpmath.workdps(50):
        e2 = mpmath.exp(2)
        exact = [x0[0], mpmath.mpf(c) * (e2 - 1) / 2 * x0[0] + e2 * mpmath.mpf(x0[1])]
        exact = np.array([float(v) for v in exact])
    reference = (expm_long(A) @ x0.astype(np.longdouble)).astype(np.float64)
    assert np.max(np.abs(reference - exact)) <= 4 * U * np.max(np.abs(exact))
    outcome = exercise(
        "initial_response",
        aerocontrol.initial_response,
        {"sys": plain((A, B)), "x0": plain(x0), "T": plain(np.array([0.0, 1.0]))},
        _free_oracle("initial"),
    )
    assert np.max(np.abs(outcome.result.x[-1] - exact)) <= 4 * U * np.max(np.abs(exact))
