"""Arguments as python-control reads them, and models to and from python-control and scipy.

The oracle for every argument form is the explicit 2-D form of the same argument: a 1-D B
(or G) is the column B.reshape(-1, 1), a 1-D C the row C.reshape(1, -1), a scalar the 1 x 1
matrix, a numpy.matrix its plain array, poles of one row or column their flat list. The
conversion happens before the computation, so the results must be bitwise equal. Forms with
no single reading are refused with a ShapeError naming the argument.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import aerocontrol
from aerocontrol import ShapeError

control = pytest.importorskip("control")
signal = pytest.importorskip("scipy.signal")

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")  # numpy.matrix

Array = np.ndarray[Any, Any]
A, B2 = aerocontrol.chapter.boeing747_longitudinal()  # 4 states, elevator
b = B2[:, 0].copy()  # 1-D: one input
c = np.array([0.0, 1.0, 0.0, 1.0])  # 1-D: one output
C2 = c.reshape(1, -1)
POLES = [-1.0 + 1.0j, -1.0 - 1.0j, -0.2, -0.3]
Ad = aerocontrol.c2d((A, B2), 0.5).A


def equal(first: Any, second: Any) -> bool:
    """Bitwise equality of results: arrays, tuples of arrays, or objects with array fields."""
    if isinstance(first, tuple):
        return all(equal(x, y) for x, y in zip(first, second, strict=True))
    if isinstance(first, np.ndarray):
        return first.shape == second.shape and bool(np.array_equal(first, second))
    if hasattr(first, "__dataclass_fields__"):
        return all(equal(getattr(first, f), getattr(second, f)) for f in first.__dataclass_fields__)
    if hasattr(first, "K") and hasattr(first, "achieved_poles"):  # Placement
        return equal((first.K, first.achieved_poles), (second.K, second.achieved_poles))
    return bool(first == second)


# (what, the call with python-control's argument form, the call with the explicit 2-D form)
CASES: list[tuple[str, Callable[[], Any], Callable[[], Any]]] = [
    (
        "lqr 1-D B",
        lambda: aerocontrol.lqr(A, b, np.eye(4), 1),
        lambda: aerocontrol.lqr(A, B2, np.eye(4), [[1.0]]),
    ),
    (
        "lqr list B",
        lambda: aerocontrol.lqr(A, list(b), np.eye(4), 1.0),
        lambda: aerocontrol.lqr(A, B2, np.eye(4), 1.0),
    ),
    (
        "lqr scalars",
        lambda: aerocontrol.lqr(-1, 2, 3, 4),
        lambda: aerocontrol.lqr([[-1]], [[2]], [[3]], [[4]]),
    ),
    (
        "lqr matrix",
        lambda: aerocontrol.lqr(np.asmatrix(A), np.asmatrix(B2), np.asmatrix(np.eye(4)), 1),
        lambda: aerocontrol.lqr(A, B2, np.eye(4), 1),
    ),
    (
        "dlqr 1-D B",
        lambda: aerocontrol.dlqr(Ad, b, np.eye(4), 1),
        lambda: aerocontrol.dlqr(Ad, B2, np.eye(4), 1),
    ),
    (
        "solve_care 1-D B",
        lambda: aerocontrol.solve_care(A, b, np.eye(4), 1),
        lambda: aerocontrol.solve_care(A, B2, np.eye(4), 1),
    ),
    (
        "solve_care scalars",
        lambda: aerocontrol.solve_care(-1.0, 1.0, 1.0, 1.0),
        lambda: aerocontrol.solve_care([[-1.0]], [[1.0]], [[1.0]], [[1.0]]),
    ),
    (
        "solve_dare 1-D B",
        lambda: aerocontrol.solve_dare(Ad, b, np.eye(4), 1),
        lambda: aerocontrol.solve_dare(Ad, B2, np.eye(4), 1),
    ),
    (
        "solve_lyapunov scalars",
        lambda: aerocontrol.solve_lyapunov(-2.0, 1.0),
        lambda: aerocontrol.solve_lyapunov([[-2.0]], [[1.0]]),
    ),
    (
        "solve_lyapunov matrix",
        lambda: aerocontrol.solve_lyapunov(np.asmatrix(A), np.asmatrix(np.eye(4))),
        lambda: aerocontrol.solve_lyapunov(A, np.eye(4)),
    ),
    (
        "riccati_ode 1-D B",
        lambda: aerocontrol.riccati_ode(A, b, np.eye(4), 1, [0.0, 1.0]),
        lambda: aerocontrol.riccati_ode(A, B2, np.eye(4), 1, [0.0, 1.0]),
    ),
    (
        "riccati_difference 1-D B",
        lambda: aerocontrol.riccati_difference(Ad, b, np.eye(4), 1, 3),
        lambda: aerocontrol.riccati_difference(Ad, B2, np.eye(4), 1, 3),
    ),
    (
        "place 1-D B",
        lambda: aerocontrol.place(A, b, POLES),
        lambda: aerocontrol.place(A, B2, POLES),
    ),
    (
        "place poles row",
        lambda: aerocontrol.place(A, B2, np.array([POLES])),
        lambda: aerocontrol.place(A, B2, POLES),
    ),
    (
        "place poles column",
        lambda: aerocontrol.place(A, B2, np.array([POLES]).T),
        lambda: aerocontrol.place(A, B2, POLES),
    ),
    (
        "place poles matrix",
        lambda: aerocontrol.place(np.asmatrix(A), np.asmatrix(B2), np.asmatrix(POLES)),
        lambda: aerocontrol.place(A, B2, POLES),
    ),
    (
        "place scalars",
        lambda: aerocontrol.place(1.0, 1.0, -2.0),
        lambda: aerocontrol.place([[1.0]], [[1.0]], [-2.0]),
    ),
    (
        "bass_gura poles row",
        lambda: aerocontrol.place_bass_gura(A, b, np.array([POLES])),
        lambda: aerocontrol.place_bass_gura(A, B2, POLES),
    ),
    (
        "ackermann poles matrix",
        lambda: aerocontrol.place_ackermann(A, list(b), np.asmatrix(POLES).T),
        lambda: aerocontrol.place_ackermann(A, B2, POLES),
    ),
    (
        "place_observer 1-D C",
        lambda: aerocontrol.place_observer(A, c, np.array([POLES])),
        lambda: aerocontrol.place_observer(A, C2, POLES),
    ),
    (
        "companion_form matrix",
        lambda: aerocontrol.companion_form(np.asmatrix(A), b),
        lambda: aerocontrol.companion_form(A, B2),
    ),
    ("ctrb 1-D B", lambda: aerocontrol.ctrb(A, b), lambda: aerocontrol.ctrb(A, B2)),
    ("ctrb scalars", lambda: aerocontrol.ctrb(2, 3), lambda: aerocontrol.ctrb([[2.0]], [[3.0]])),
    ("obsv 1-D C", lambda: aerocontrol.obsv(A, c), lambda: aerocontrol.obsv(A, C2)),
    (
        "controllability 1-D B",
        lambda: aerocontrol.controllability(A, b),
        lambda: aerocontrol.controllability(A, B2),
    ),
    (
        "observability 1-D C",
        lambda: aerocontrol.observability(A, list(c)),
        lambda: aerocontrol.observability(A, C2),
    ),
    (
        "is_controllable matrix",
        lambda: aerocontrol.is_controllable(np.asmatrix(A), b),
        lambda: aerocontrol.is_controllable(A, B2),
    ),
    (
        "is_observable 1-D C",
        lambda: aerocontrol.is_observable(A, c),
        lambda: aerocontrol.is_observable(A, C2),
    ),
    (
        "lqe 1-D G and C",
        lambda: aerocontrol.lqe(A, b, c, 1, 0.1),
        lambda: aerocontrol.lqe(A, B2, C2, [[1.0]], [[0.1]]),
    ),
    (
        "dlqe 1-D G and C",
        lambda: aerocontrol.dlqe(Ad, b, c, 1, 0.1),
        lambda: aerocontrol.dlqe(Ad, B2, C2, [[1.0]], [[0.1]]),
    ),
    (
        "step of an (A, b, c, d) tuple",
        lambda: aerocontrol.step_response((A, b, c, 0.0), T=[0.0, 1.0, 2.0]).y,
        lambda: aerocontrol.step_response((A, B2, C2, [[0.0]]), T=[0.0, 1.0, 2.0]).y,
    ),
    (
        "transfer function of a tuple",
        lambda: aerocontrol.transfer_function((A, b, c, 0)).numerator,
        lambda: aerocontrol.transfer_function((A, B2, C2, np.zeros((1, 1)))).numerator,
    ),
]


@pytest.mark.parametrize(("what", "given", "explicit"), CASES, ids=[c[0] for c in CASES])
def test_python_control_argument_forms_give_the_explicit_answer(
    what: str, given: Callable[[], Any], explicit: Callable[[], Any]
) -> None:
    assert equal(given(), explicit()), what


def test_state_space_reads_scalars_vectors_and_matrices() -> None:
    first = aerocontrol.StateSpace(-1, 2, 3, 0)
    assert (first.A, first.B, first.C, first.D) == ([[-1.0]], [[2.0]], [[3.0]], [[0.0]])
    model = aerocontrol.StateSpace(np.asmatrix(A), b, c, 0.5)
    reference = aerocontrol.StateSpace(A, B2, C2, [[0.5]])
    for ours, theirs in zip("ABCD", "ABCD", strict=True):
        assert type(getattr(model, ours)) is np.ndarray
        assert np.array_equal(getattr(model, ours), getattr(reference, theirs))
    # a 1-D D: the row of a single-output model, the column of a single-input one
    two_in = aerocontrol.StateSpace(A, np.ones((4, 2)), c, [1.0, 2.0])
    assert np.array_equal(two_in.D, [[1.0, 2.0]])
    two_out = aerocontrol.StateSpace(A, b, np.ones((2, 4)), [1.0, 2.0])
    assert np.array_equal(two_out.D, [[1.0], [2.0]])
    # D = 0 for several inputs and outputs is the zero matrix
    assert np.array_equal(
        aerocontrol.StateSpace(A, np.ones((4, 2)), np.eye(4), 0).D, np.zeros((4, 2))
    )


@pytest.mark.parametrize(
    ("call", "argument", "message"),
    [
        (lambda: aerocontrol.StateSpace(A[0], b), "A", "A must be a 2-D matrix.*ambiguous"),
        (
            lambda: aerocontrol.StateSpace(A, np.ones((4, 2)), np.ones((3, 4)), np.ones(2)),
            "D",
            "D must be a 2-D matrix.*ambiguous",
        ),
        (lambda: aerocontrol.lqr(A, B2[None], np.eye(4), 1), "B", "B must be a 2-D matrix"),
        (
            lambda: aerocontrol.solve_lyapunov(A, np.ones(4)),
            "Q",
            "Q must be a 2-D matrix.*ambiguous",
        ),
        (lambda: aerocontrol.ctrb(A, np.ones(3)), None, "B must have as many rows as A"),
        (lambda: aerocontrol.obsv(A, np.ones(3)), None, "C must have one column per row of A"),
        (
            lambda: aerocontrol.place(A, B2, np.reshape(POLES, (2, 2))),
            None,
            "poles must be a 1-D sequence",
        ),
    ],
)
def test_ambiguous_or_wrong_forms_are_refused_by_name(
    call: Callable[[], Any], argument: str | None, message: str
) -> None:
    with pytest.raises(ShapeError, match=message) as caught:
        call()
    if argument is not None:
        assert caught.value.argument == argument


# --- scipy.signal systems are systems ------------------------------------------------------------


def test_scipy_state_space_is_accepted_wherever_a_system_is() -> None:
    D = np.zeros((4, 1))
    continuous = signal.StateSpace(A, B2, np.eye(4), D)
    model = aerocontrol.as_state_space(continuous)
    assert model.dt is None and not model.is_discrete
    assert np.array_equal(model.A, A) and np.array_equal(model.B, B2)
    ours = aerocontrol.StateSpace(A, B2)
    assert equal(aerocontrol.lqr(continuous, np.eye(4), 1), aerocontrol.lqr(ours, np.eye(4), 1))
    assert equal(aerocontrol.place(continuous, POLES), aerocontrol.place(ours, POLES))
    assert aerocontrol.is_controllable(continuous)
    t = [0.0, 1.0, 2.0]
    assert equal(
        aerocontrol.step_response(continuous, T=t).y, aerocontrol.step_response(ours, T=t).y
    )
    discrete = signal.StateSpace(Ad, B2, np.eye(4), D, dt=0.5)
    sampled = aerocontrol.as_state_space(discrete)
    assert sampled.dt == 0.5 and sampled.is_discrete
    reference = aerocontrol.StateSpace(Ad, B2, dt=0.5)
    assert equal(
        aerocontrol.dlqr(discrete, np.eye(4), 1), aerocontrol.dlqr(reference, np.eye(4), 1)
    )
    with pytest.raises(aerocontrol.InvalidArgumentError, match="lqr designs in continuous time"):
        aerocontrol.lqr(discrete, np.eye(4), 1)
    assert equal(
        aerocontrol.step_response(discrete, T=[0.0, 0.5, 1.0]).y,
        aerocontrol.step_response(reference, T=[0.0, 0.5, 1.0]).y,
    )


# --- to and from python-control and scipy -----------------------------------------------------

NAMED = aerocontrol.aircraft.load("b747-approach").lateral()


@pytest.mark.parametrize("dt", [None, 0.0, 0.25])
def test_round_trip_through_python_control(dt: float | None) -> None:
    model = aerocontrol.StateSpace(
        NAMED.A,
        NAMED.B,
        NAMED.C,
        NAMED.D,
        NAMED.state_names,
        NAMED.input_names,
        NAMED.output_names,
        dt=dt,
    )
    theirs = model.to_control()
    assert isinstance(theirs, control.StateSpace)
    assert theirs.dt == dt
    assert theirs.state_labels == list(model.state_names)
    assert theirs.input_labels == ["rudder", "aileron"] and theirs.output_labels == list(
        model.output_names
    )
    for name in "ABCD":
        assert np.array_equal(getattr(theirs, name), getattr(model, name))
        assert not np.shares_memory(getattr(theirs, name), getattr(model, name))
    back = aerocontrol.StateSpace.from_control(theirs)
    assert back.dt == dt
    assert (back.state_names, back.input_names, back.output_names) == (
        model.state_names,
        model.input_names,
        model.output_names,
    )
    assert all(np.array_equal(getattr(back, n), getattr(model, n)) for n in "ABCD")


def test_round_trip_from_python_control() -> None:
    theirs = control.ss(Ad, B2, C2, 0, dt=0.5, states=list("abcd"), inputs=["e"], outputs=["y"])
    ours = aerocontrol.StateSpace.from_control(theirs)
    assert ours.dt == 0.5 and ours.state_names == tuple("abcd") and ours.output_names == ("y",)
    again = ours.to_control()
    assert again.dt == 0.5 and again.state_labels == list("abcd") and again.input_labels == ["e"]
    assert all(np.array_equal(getattr(again, n), getattr(theirs, n)) for n in "ABCD")
    # a transfer function is realised by control.ss
    tf = control.tf([1.0, 2.0], [1.0, 3.0, 5.0])
    realised = aerocontrol.StateSpace.from_control(tf)
    expected = control.ss(tf)
    assert all(np.array_equal(getattr(realised, n), getattr(expected, n)) for n in "ABCD")
    with pytest.raises(aerocontrol.NotRealError, match=r"python-control system"):
        aerocontrol.StateSpace.from_control((A, B2))


@pytest.mark.parametrize("dt", [None, 0.25])
def test_round_trip_through_scipy(dt: float | None) -> None:
    model = aerocontrol.StateSpace(A, B2, C2, [[0.5]], dt=dt)
    theirs = model.to_scipy()
    assert isinstance(theirs, signal.StateSpace)
    assert theirs.dt == dt
    for name in "ABCD":
        assert np.array_equal(getattr(theirs, name), getattr(model, name))
    back = aerocontrol.StateSpace.from_scipy(theirs)
    assert back.dt == dt and all(
        np.array_equal(getattr(back, n), getattr(model, n)) for n in "ABCD"
    )
    # and from scipy's side
    source = signal.StateSpace(Ad, B2, C2, [[0.0]], dt=0.5)
    again = aerocontrol.StateSpace.from_scipy(source).to_scipy()
    assert again.dt == 0.5 and all(
        np.array_equal(getattr(again, n), getattr(source, n)) for n in "ABCD"
    )
    tf = signal.TransferFunction([1.0], [1.0, 2.0, 2.0])
    realised = aerocontrol.StateSpace.from_scipy(tf)
    assert all(np.array_equal(getattr(realised, n), getattr(tf.to_ss(), n)) for n in "ABCD")
    with pytest.raises(aerocontrol.NotRealError, match=r"scipy\.signal system"):
        aerocontrol.StateSpace.from_scipy(control.ss(A, B2, C2, 0))


@pytest.mark.parametrize(
    ("module", "call", "package"),
    [
        ("control", lambda: NAMED.to_control(), "python-control"),
        ("control", lambda: aerocontrol.StateSpace.from_control(None), "python-control"),
        ("scipy.signal", lambda: NAMED.to_scipy(), "scipy"),
        ("scipy.signal", lambda: aerocontrol.StateSpace.from_scipy(None), "scipy"),
    ],
)
def test_a_missing_package_is_a_clear_import_error(
    monkeypatch: pytest.MonkeyPatch, module: str, call: Callable[[], Any], package: str
) -> None:
    monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(ImportError, match=f"needs {package}, which is not installed"):
        call()
