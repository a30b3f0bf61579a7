"""Systems as building blocks (issue 25): signal selection, series, parallel, feedback, append,
connect by name, and the element constructors.

Oracles: python-control (``series``, ``parallel``, ``feedback``, ``append``, ``interconnect``,
``tf``, ``zpk``, ``tf2ss``, ``pade``; with slycot) on the same block diagrams, compared by their
frequency responses at many frequencies and by their poles, never by their realisations (which
may differ by any similarity); and closed forms (a washout's gains at rest and at high
frequency, the pole -(a + k) of k/(s + a) in a negative unity loop, a Padé approximant's unit
magnitude).
"""

from __future__ import annotations

import math
import warnings

import control
import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import aerocontrol
from aerocontrol import (
    IllConditionedWarning,
    InvalidArgumentError,
    NonFiniteError,
    NotRealError,
    ShapeError,
    SingularMatrixError,
    StateSpace,
)

#: The frequency responses must agree to this relative error, normwise at each frequency.
RTOL = 1e-10
FREQUENCIES = np.logspace(-3, 3, 400)
LATERAL = aerocontrol.aircraft.load("b747-approach").lateral()  # beta, p, phi, r; rudder, aileron


def _random(n: int, m: int, p: int, seed: int, dt: float | None = None) -> StateSpace:
    """A seeded random model with distinct, stable poles (inside the unit circle if discrete)."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    if n and dt is None:
        A -= (np.abs(np.linalg.eigvals(A).real).max() + 0.5) * np.eye(n)
    elif n:
        A *= 0.9 / np.abs(np.linalg.eigvals(A)).max()
    return StateSpace(
        A,
        rng.standard_normal((n, m)),
        rng.standard_normal((p, n)),
        rng.standard_normal((p, m)),
        input_names=[f"in{k}" for k in range(m)],
        output_names=[f"out{k}" for k in range(p)],
        dt=dt,
    )


def _pc(sys: StateSpace) -> control.StateSpace:
    """The same model in python-control, with the same signal names."""
    return control.ss(
        sys.A,
        sys.B,
        sys.C,
        sys.D,
        sys.dt or 0,
        inputs=list(sys.input_names),
        outputs=list(sys.output_names),
    )


def _reference_response(sys: control.LTI, omega: np.ndarray) -> np.ndarray:
    """python-control's G(jω) (G(e^{jω dt}) if discrete), shape (len(omega), p, m)."""
    points = np.exp(1j * omega * sys.dt) if sys.dt else 1j * omega
    values = [np.asarray(sys(point), dtype=complex) for point in points]
    return np.stack(values).reshape(len(omega), sys.noutputs, sys.ninputs)


def _worst_relative_error(
    ours: StateSpace, reference: control.LTI, omega: np.ndarray = FREQUENCIES
) -> float:
    """max over ω of ||G(jω) - G_ref(jω)||_F / ||G_ref(jω)||_F, G by aerocontrol's own
    frequency_response."""
    G = aerocontrol.frequency_response(ours, omega).response
    R = _reference_response(reference, omega)
    assert G.shape == R.shape
    difference = np.linalg.norm((G - R).reshape(len(omega), -1), axis=1)
    size = np.linalg.norm(R.reshape(len(omega), -1), axis=1)
    return float(np.max(difference / size))


def _assert_same_response(ours: StateSpace, reference: control.LTI, rtol: float = RTOL) -> None:
    error = _worst_relative_error(ours, reference)
    assert error <= rtol, f"relative error {error:.3g} > {rtol:g}"


def _assert_same_poles(ours: StateSpace, reference: control.LTI, rtol: float = 1e-9) -> None:
    mine = list(np.linalg.eigvals(ours.A)) if ours.n_states else []
    theirs = list(np.asarray(reference.poles(), dtype=complex))
    assert len(mine) == len(theirs)
    for pole in theirs:  # greedy matching: the poles here are distinct
        k = int(np.argmin([abs(pole - q) for q in mine]))
        assert abs(pole - mine[k]) <= rtol * max(1.0, abs(pole)), (pole, mine)
        mine.pop(k)


# ----- sys[outputs, inputs] ---------------------------------------------------------------------


def test_selection_by_name_keeps_names_states_and_dt() -> None:
    yaw = LATERAL["r", "rudder"]
    assert yaw.output_names == ("r",) and yaw.input_names == ("rudder",)
    assert yaw.state_names == LATERAL.state_names
    np.testing.assert_array_equal(yaw.A, LATERAL.A)
    np.testing.assert_array_equal(yaw.B, LATERAL.B[:, [0]])
    np.testing.assert_array_equal(yaw.C, LATERAL.C[[3], :])
    np.testing.assert_array_equal(yaw.D, LATERAL.D[[3]][:, [0]])
    sampled = StateSpace(LATERAL.A, LATERAL.B, input_names=LATERAL.input_names, dt=0.05)
    assert sampled["x3", "aileron"].dt == 0.05
    assert sampled["x3", "aileron"].input_names == ("aileron",)


@pytest.mark.parametrize(
    ("outputs", "inputs", "rows", "columns"),
    [
        (3, 0, [3], [0]),
        (-1, -2, [3], [0]),
        (slice(1, 3), slice(None), [1, 2], [0, 1]),
        (["p", 3, "beta"], ["aileron"], [1, 3, 0], [1]),
        ((0, "phi"), np.int64(1), [0, 2], [1]),
        ([], "rudder", [], [0]),
    ],
)
def test_selection_by_index_slice_and_list(
    outputs: object, inputs: object, rows: list[int], columns: list[int]
) -> None:
    selected = LATERAL[outputs, inputs]  # type: ignore[index]
    np.testing.assert_array_equal(selected.C, LATERAL.C[rows, :])
    np.testing.assert_array_equal(selected.B, LATERAL.B[:, columns])
    assert selected.output_names == tuple(LATERAL.output_names[i] for i in rows)
    assert selected.input_names == tuple(LATERAL.input_names[j] for j in columns)


def test_selection_matches_python_control_indexing() -> None:
    sys = _random(4, 3, 3, seed=1)
    ours = sys[["out2", "out0"], 1:]
    theirs = _pc(sys)[[2, 0], 1:]
    _assert_same_response(ours, theirs)


@pytest.mark.parametrize(
    ("key", "message"),
    [
        (("yaw rate", "rudder"), "no output is named 'yaw rate'; the outputs are 'beta'"),
        (("r", "elevator"), "no input is named 'elevator'"),
        (("r", 2), "input index 2 is out of range for a model with 2 inputs"),
        ((-5, 0), "output index -5 is out of range"),
        (("r", True), "an input must be selected by name or by integer index"),
        (("r", 1.0), "an input selection must be a name, an index, a slice or a list"),
        ("r", r"select signals as sys\[outputs, inputs\]"),
        (("r", "rudder", 0), r"select signals as sys\[outputs, inputs\]"),
        # Slices as Python slices lists, but refused by name: a bare TypeError for name or
        # float bounds, ValueError for a zero step, and a bool bound taken as 0 or 1.
        ((slice("beta", "phi"), 0), "an output slice must have integer bounds"),
        ((slice(0.0, 2), 0), "an output slice must have integer bounds"),
        ((slice(True, 3), 0), "an output slice must have integer bounds"),
        (("r", slice(None, None, 0)), "an input slice must have a nonzero step"),
    ],
)
def test_selection_refuses_what_it_cannot_find(key: object, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        LATERAL[key]  # type: ignore[index]


def test_selection_refuses_an_ambiguous_name() -> None:
    sys = StateSpace(-np.eye(2), np.ones((2, 1)), output_names=["y", "y"])
    with pytest.raises(
        InvalidArgumentError, match=r"2 outputs are named 'y' \(positions \[0, 1\]\)"
    ):
        sys["y", 0]
    assert sys[1, 0].output_names == ("y",)


# ----- series, parallel, feedback, append -------------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("dt", [None, 0.1])
def test_series_parallel_append_feedback_match_python_control(seed: int, dt: float | None) -> None:
    a = _random(3, 2, 2, seed=seed, dt=dt)
    b = _random(4, 2, 2, seed=100 + seed, dt=dt)
    c = _random(2, 2, 2, seed=200 + seed, dt=dt)
    pa, pb, pc = _pc(a), _pc(b), _pc(c)
    cases = [
        (aerocontrol.series(a, b), control.series(pa, pb)),
        (aerocontrol.series(a, b, c), control.series(pa, pb, pc)),
        (aerocontrol.parallel(a, b), control.parallel(pa, pb)),
        (aerocontrol.parallel(a, b, c), control.parallel(pa, pb, pc)),
        (aerocontrol.append(a, b, c), control.append(pa, pb, pc)),
        (aerocontrol.feedback(a, b), control.feedback(pa, pb)),
        (aerocontrol.feedback(a, b, sign=+1), control.feedback(pa, pb, sign=1)),
        (aerocontrol.feedback(a), control.feedback(pa, np.eye(2))),
        (aerocontrol.feedback(a, c, -1), control.feedback(pa, pc, -1)),
    ]
    for ours, theirs in cases:
        assert ours.dt == dt
        _assert_same_response(ours, theirs)
        _assert_same_poles(ours, theirs)


def test_series_of_non_square_models_matches_python_control() -> None:
    a, b = _random(3, 1, 2, seed=7), _random(2, 2, 3, seed=8)
    _assert_same_response(aerocontrol.series(a, b), control.series(_pc(a), _pc(b)))
    forward, back = _random(3, 2, 3, seed=9), _random(1, 3, 2, seed=10)
    _assert_same_response(
        aerocontrol.feedback(forward, back), control.feedback(_pc(forward), _pc(back))
    )


@pytest.mark.parametrize(("a", "k"), [(2.0, 3.0), (0.5, 10.0), (-1.0, 4.0), (1e-3, 1e3)])
def test_feedback_of_a_first_order_loop_has_the_pole_minus_a_plus_k(a: float, k: float) -> None:
    # k/(s + a) in a negative unity loop: k/(s + a + k); in a positive one: k/(s + a - k).
    loop = aerocontrol.tf([k], [1.0, a])
    negative = aerocontrol.feedback(loop)
    np.testing.assert_allclose(np.linalg.eigvals(negative.A), [-(a + k)], rtol=1e-14)
    np.testing.assert_allclose(aerocontrol.dc_gain(negative), [[k / (a + k)]], rtol=1e-14)
    positive = aerocontrol.feedback(loop, aerocontrol.gain(1.0), sign=+1)
    np.testing.assert_allclose(np.linalg.eigvals(positive.A), [k - a], rtol=1e-13)


def test_feedback_through_direct_feedthrough_matches_python_control() -> None:
    # Both parts biproper: the loop is solved through F = I - sign D2 D1.
    forward = aerocontrol.tf([2.0, 1.0], [1.0, 3.0])
    back = aerocontrol.tf([0.5, 2.0], [1.0, 1.0])
    theirs = control.feedback(
        control.tf([2.0, 1.0], [1.0, 3.0]), control.tf([0.5, 2.0], [1.0, 1.0])
    )
    _assert_same_response(aerocontrol.feedback(forward, back), theirs)
    _assert_same_poles(aerocontrol.feedback(forward, back), theirs)


def test_feedback_refuses_an_algebraic_loop_by_name() -> None:
    with pytest.raises(SingularMatrixError, match=r"algebraic loop: I - sign·D2·D1 is singular"):
        aerocontrol.feedback(aerocontrol.gain(1.0), sign=+1)
    with pytest.raises(SingularMatrixError, match="algebraic loop"):
        aerocontrol.feedback(aerocontrol.tf([1.0, 0.0], [1.0, 1.0]), aerocontrol.gain(-1.0))
    singular = np.array([[1.0, 0.0], [0.0, 0.0]])
    plant = StateSpace(-np.eye(2), np.eye(2), np.eye(2), np.eye(2))
    with pytest.raises(SingularMatrixError, match="algebraic loop"):
        aerocontrol.feedback(plant, aerocontrol.gain(singular), sign=+1)


def test_feedback_warns_of_a_nearly_singular_algebraic_loop() -> None:
    with pytest.warns(IllConditionedWarning, match="condition number"):
        aerocontrol.feedback(aerocontrol.gain(1.0 - 1e-10), sign=+1)


def test_positional_interconnections_check_their_arguments() -> None:
    a, b = _random(2, 2, 2, seed=1), _random(2, 1, 1, seed=2)
    with pytest.raises(ShapeError, match="series: sys2 has 1 inputs but the model before it has 2"):
        aerocontrol.series(a, b)
    with pytest.raises(ShapeError, match="parallel: sys2 has 1 outputs and 1 inputs"):
        aerocontrol.parallel(a, b)
    with pytest.raises(ShapeError, match="feedback: sys2 must have as many inputs"):
        aerocontrol.feedback(a, b)
    with pytest.raises(ShapeError, match="unity feedback needs as many outputs as inputs"):
        aerocontrol.feedback(_random(2, 1, 2, seed=3))
    for sign in (0, 2, -0.5, True, "-"):
        with pytest.raises((InvalidArgumentError, NotRealError), match="sign"):
            aerocontrol.feedback(a, sign=sign)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="append needs at least one model"):
        aerocontrol.append()
    with pytest.raises(NotRealError, match="series: sys2 must be a StateSpace"):
        aerocontrol.series(a, 3.0)  # type: ignore[arg-type]


def test_time_bases_must_agree() -> None:
    continuous = _random(2, 1, 1, seed=1)
    sampled = _random(2, 1, 1, seed=2, dt=0.1)
    other = _random(2, 1, 1, seed=3, dt=0.2)
    with pytest.raises(
        InvalidArgumentError,
        match=r"series: sys1 is continuous but sys2 is discrete \(dt = 0.1 s\)",
    ):
        aerocontrol.series(continuous, sampled)
    with pytest.raises(InvalidArgumentError, match=r"dt = 0.1 s\) but sys2 is discrete \(dt = 0.2"):
        aerocontrol.feedback(sampled, other)
    # Periods that differ in the 17th digit are told apart (:g printed 0.1 for both).
    nearly = _random(2, 1, 1, seed=3, dt=0.1 * (1 + 1e-15))
    with pytest.raises(
        InvalidArgumentError, match=r"\(dt = 0.1 s\) .*\(dt = 0.10000000000000012 s\)"
    ):
        aerocontrol.series(sampled, nearly)
    with pytest.raises(InvalidArgumentError, match=r"systems\[0\] is discrete"):
        aerocontrol.connect([sampled, continuous])
    # A static model fits either time base, and the result takes the dynamic one's.
    assert aerocontrol.series(sampled, aerocontrol.gain(2.0)).dt == 0.1
    assert aerocontrol.feedback(sampled, aerocontrol.gain(2.0, dt=0.5)).dt == 0.1
    assert aerocontrol.parallel(continuous, aerocontrol.gain(2.0)).dt is None
    marked = StateSpace(continuous.A, continuous.B, continuous.C, continuous.D, dt=0)
    assert aerocontrol.parallel(continuous, marked).dt == 0.0


def test_positional_interconnections_keep_the_names() -> None:
    servo = aerocontrol.actuator(20.0, input_names="rudder command", output_names="rudder")
    plant = LATERAL[["r", "beta"], "rudder"]
    chain = aerocontrol.series(servo, plant)
    assert chain.input_names == ("rudder command",)
    assert chain.output_names == ("r", "beta")
    assert chain.state_names == ("rudder", "beta", "p", "phi", "r")
    loop = aerocontrol.feedback(LATERAL["r", "rudder"], aerocontrol.washout(2.0))
    assert loop.input_names == ("rudder",) and loop.output_names == ("r",)
    assert loop.state_names == ("beta", "p", "phi", "r", "u0 lagged")
    both = aerocontrol.append(plant, servo)
    assert both.input_names == ("rudder", "rudder command")
    assert both.output_names == ("r", "beta", "rudder")
    total = aerocontrol.parallel(servo, aerocontrol.gain(1.0, input_names="x", output_names="y"))
    assert total.input_names == ("rudder command",) and total.output_names == ("rudder",)


# ----- connect ----------------------------------------------------------------------------------


def _yaw_damper_blocks(k: float = 1.5) -> list[StateSpace]:
    return [
        LATERAL[["r", "beta"], "rudder"],
        aerocontrol.washout(2.0, input_names="r", output_names="r washed"),
        aerocontrol.gain(k, input_names="r washed", output_names="u"),
        aerocontrol.summing_junction(["rudder command", "u"], "servo input"),
        aerocontrol.actuator(20.0, input_names="servo input", output_names="rudder"),
    ]


def test_connect_by_names_matches_python_control_interconnect() -> None:
    blocks = _yaw_damper_blocks()
    ours = aerocontrol.connect(blocks, inputs="rudder command", outputs=["r", "beta", "rudder"])
    theirs = control.interconnect(
        [_pc(b) for b in blocks], inputs="rudder command", outputs=["r", "beta", "rudder"]
    )
    assert ours.input_names == ("rudder command",)
    assert ours.output_names == ("r", "beta", "rudder")
    assert ours.state_names == ("beta", "p", "phi", "r", "r lagged", "rudder")
    _assert_same_response(ours, theirs)
    _assert_same_poles(ours, theirs)


def test_connect_with_explicit_connections_and_gains() -> None:
    implicit = aerocontrol.connect(_yaw_damper_blocks(), inputs="rudder command", outputs="r")
    plant, filt, _, _, servo = _yaw_damper_blocks()
    explicit = aerocontrol.connect(
        [plant, filt, servo],
        [
            ["r", "r"],
            ["servo input", "rudder command", ("r washed", 1.5)],
            ["rudder", "rudder"],
        ],
        inputs="rudder command",
        outputs="r",
    )
    assert _worst_relative_error(explicit, _pc(implicit)) <= RTOL
    # "-name" subtracts: the same loop with the gain's sign moved into the connection.
    negative = aerocontrol.connect(
        [plant, filt, aerocontrol.gain(-1.5, input_names="r washed", output_names="v"), servo],
        [
            ["r", "r"],
            ["r washed", "r washed"],
            ["servo input", "rudder command", "-v"],
            ["rudder", "rudder"],
        ],
        inputs="rudder command",
        outputs="r",
    )
    assert _worst_relative_error(negative, _pc(implicit)) <= RTOL


@pytest.mark.parametrize("seed", range(4))
def test_connect_reproduces_feedback_and_series(seed: int) -> None:
    plant = _random(3, 2, 2, seed=seed)
    controller = _random(2, 2, 2, seed=50 + seed)
    named_plant = StateSpace(
        plant.A, plant.B, plant.C, plant.D, input_names=["u0", "u1"], output_names=["y0", "y1"]
    )
    named_controller = StateSpace(
        controller.A,
        controller.B,
        controller.C,
        controller.D,
        input_names=["e0", "e1"],
        output_names=["u0", "u1"],
    )
    junctions = [aerocontrol.summing_junction([f"r{k}", f"-y{k}"], f"e{k}") for k in range(2)]
    closed = aerocontrol.connect(
        [named_plant, named_controller, *junctions], inputs=["r0", "r1"], outputs=["y0", "y1"]
    )
    reference = control.feedback(control.series(_pc(controller), _pc(plant)), np.eye(2))
    _assert_same_response(closed, reference)
    _assert_same_poles(closed, reference)
    ours_feedback = aerocontrol.feedback(aerocontrol.series(controller, plant))
    assert _worst_relative_error(closed, _pc(ours_feedback)) <= RTOL


def test_connect_sums_outputs_of_one_name_and_feeds_inputs_of_one_name() -> None:
    # Two blocks output "y" (summed, as python-control does); two blocks read "u" (fan-out).
    a = _random(2, 1, 1, seed=1)
    b = _random(3, 1, 1, seed=2)
    a_named = StateSpace(a.A, a.B, a.C, a.D, input_names=["u"], output_names=["y"])
    b_named = StateSpace(b.A, b.B, b.C, b.D, input_names=["u"], output_names=["y"])
    ours = aerocontrol.connect([a_named, b_named], inputs="u", outputs="y")
    _assert_same_response(ours, control.parallel(_pc(a), _pc(b)))
    theirs = control.interconnect([_pc(a_named), _pc(b_named)], inputs="u", outputs="y")
    _assert_same_response(ours, theirs)


def test_connect_defaults_and_outputs_that_are_inputs() -> None:
    blocks = _yaw_damper_blocks()
    everything = aerocontrol.connect(blocks)
    # Unfed inputs become the external inputs; every output name is an output.
    assert everything.input_names == ("rudder command",)
    assert everything.output_names == ("r", "beta", "r washed", "u", "servo input", "rudder")
    # An output may name a signal entering a block, or an external input; "-name" negates.
    probe = aerocontrol.connect(
        blocks, inputs="rudder command", outputs=["servo input", "-rudder command"]
    )
    G = aerocontrol.frequency_response(probe, [0.0, 1.0]).response
    np.testing.assert_allclose(G[:, 1, 0], -1.0, rtol=0, atol=0)
    reference = aerocontrol.connect(blocks, inputs="rudder command", outputs="servo input")
    np.testing.assert_allclose(
        G[:, :1], aerocontrol.frequency_response(reference, [0.0, 1.0]).response
    )


def test_connect_is_discrete_for_discrete_blocks() -> None:
    plant = _random(3, 1, 1, seed=4, dt=0.05)
    named = StateSpace(
        plant.A, plant.B, plant.C, plant.D, input_names=["u"], output_names=["y"], dt=0.05
    )
    controller = aerocontrol.tf(
        [0.4, -0.3], [1.0, -0.5], dt=0.05, input_names="e", output_names="u"
    )
    junction = aerocontrol.summing_junction(["r", "-y"], "e")
    ours = aerocontrol.connect([named, controller, junction], inputs="r", outputs="y")
    assert ours.dt == 0.05
    reference = control.feedback(
        control.series(control.tf([0.4, -0.3], [1.0, -0.5], 0.05), _pc(plant)), 1
    )
    _assert_same_response(ours, reference)
    _assert_same_poles(ours, reference)


def test_connect_refuses_an_algebraic_loop() -> None:
    blocks = [
        aerocontrol.gain(2.0, input_names="a", output_names="b"),
        aerocontrol.gain(0.5, input_names="b", output_names="a"),
        aerocontrol.first_order_lag(1.0, input_names="r", output_names="y"),
    ]
    with pytest.raises(SingularMatrixError, match=r"connect: algebraic loop: I - K·D is singular"):
        aerocontrol.connect(blocks, inputs="r", outputs="y")


@pytest.mark.parametrize(
    ("connections", "inputs", "outputs", "message"),
    [
        (None, ["rudder command", "gust"], "r", "external input 'gust' feeds nothing"),
        (None, [], "r", r"nothing feeds the block input\(s\) 'rudder command'"),
        (None, "rudder command", "yaw", "the output 'yaw' names no block output"),
        (None, ["rudder command", "rudder command"], "r", "names 'rudder command' more than once"),
        ([["nowhere", "r"]], None, "r", r"connections\[0\]: no block has an input named 'nowhere'"),
        ([["r", "yaw"]], None, "r", "no block output and no external input is named 'yaw'"),
        ([["r", "r"], ["r", "beta"]], None, "r", "the input 'r' is fed by an earlier connection"),
        ([["r"]], None, "r", r"connections\[0\] must be \[input, source, ...\]"),
        (["r"], None, "r", r"connections\[0\] must be a list"),
        ([["r", ("r", "big")]], None, "r", "gain of 'r'"),
        ([["r", ("r", 1.0, 2.0)]], None, "r", "a signal must be 'name', '-name' or"),
        (
            [["r", "r"], ["servo input", "rudder"]],
            ["rudder"],
            "r",
            "'rudder' is both a block output and an external input",
        ),
    ],
)
def test_connect_refuses_what_does_not_connect(
    connections: object, inputs: object, outputs: object, message: str
) -> None:
    with pytest.raises((InvalidArgumentError, NotRealError), match=message):
        aerocontrol.connect(
            _yaw_damper_blocks(),
            connections,  # type: ignore[arg-type]
            inputs,  # type: ignore[arg-type]
            outputs,  # type: ignore[arg-type]
        )


def test_connect_refuses_no_systems() -> None:
    for systems in ([], "plant", None):
        with pytest.raises(InvalidArgumentError, match="non-empty list of models"):
            aerocontrol.connect(systems)  # type: ignore[arg-type]


def test_summing_junction() -> None:
    junction = aerocontrol.summing_junction(["r", "-y", "d"], "e")
    assert junction.input_names == ("r", "y", "d") and junction.output_names == ("e",)
    np.testing.assert_array_equal(junction.D, [[1.0, -1.0, 1.0]])
    theirs = control.summing_junction(inputs=["r", "-y", "d"], output="e")
    np.testing.assert_array_equal(junction.D, theirs.D)
    assert aerocontrol.summing_junction("r", "e").D.shape == (1, 1)
    for bad in ([], ["-"], [""], [3]):
        with pytest.raises(InvalidArgumentError):
            aerocontrol.summing_junction(bad, "e")  # type: ignore[arg-type]


# ----- elements ---------------------------------------------------------------------------------


@pytest.mark.parametrize("tau", [1e-3, 0.5, 2.0, 1e3])
def test_washout_blocks_a_steady_signal_and_passes_changes(tau: float) -> None:
    filt = aerocontrol.washout(tau)
    assert aerocontrol.dc_gain(filt)[0, 0] == 0.0
    high = aerocontrol.frequency_response(filt, [1e8 / tau]).response[0, 0, 0]
    assert abs(high - 1.0) <= 1e-8
    corner = aerocontrol.frequency_response(filt, [1.0 / tau]).response[0, 0, 0]
    np.testing.assert_allclose(corner, 0.5 + 0.5j, rtol=1e-15)
    _assert_same_response(filt, control.tf([tau, 0.0], [tau, 1.0]))
    np.testing.assert_allclose(np.linalg.eigvals(filt.A), [-1.0 / tau], rtol=1e-15)


@pytest.mark.parametrize("tau", [1e-3, 0.25, 4.0])
def test_first_order_lag_and_actuator(tau: float) -> None:
    lag = aerocontrol.first_order_lag(tau, gain=2.5)
    _assert_same_response(lag, control.tf([2.5], [tau, 1.0]))
    assert aerocontrol.dc_gain(lag)[0, 0] == pytest.approx(2.5, rel=1e-15)
    bandwidth = 1.0 / tau
    servo = aerocontrol.actuator(bandwidth, input_names="command", output_names="rudder")
    _assert_same_response(servo, control.tf([bandwidth], [1.0, bandwidth]))
    assert servo.state_names == ("rudder",)
    # At the bandwidth: -3 dB and -45 degrees.
    g = aerocontrol.frequency_response(servo, [bandwidth]).response[0, 0, 0]
    np.testing.assert_allclose([abs(g), np.angle(g, deg=True)], [np.sqrt(0.5), -45.0], rtol=1e-14)


@pytest.mark.parametrize(("omega_n", "zeta"), [(30.0, 0.7), (1.0, 0.0), (200.0, 1.0), (5.0, 3.0)])
def test_second_order(omega_n: float, zeta: float) -> None:
    element = aerocontrol.second_order(omega_n, zeta, output_names="delta")
    _assert_same_response(element, control.tf([omega_n**2], [1.0, 2 * zeta * omega_n, omega_n**2]))
    assert element.state_names == ("delta", "delta rate/omega_n")
    poles = np.linalg.eigvals(element.A)
    np.testing.assert_allclose(np.prod(poles).real, omega_n**2, rtol=1e-14)
    np.testing.assert_allclose(-np.sum(poles).real, 2 * zeta * omega_n, rtol=1e-14, atol=1e-14)
    assert aerocontrol.dc_gain(element)[0, 0] == pytest.approx(1.0, rel=1e-15)


@pytest.mark.parametrize("order", range(1, 11))
@pytest.mark.parametrize("T", [0.01, 0.3, 2.0])
def test_pade_delay_matches_python_control(order: int, T: float) -> None:
    delay = aerocontrol.pade_delay(T, order)
    num, den = control.pade(T, order)
    reference = control.tf(num, den)
    _assert_same_response(delay, reference)
    _assert_same_poles(delay, control.tf2ss(num, den), rtol=1e-8)
    # An all-pass: |G| = 1 at every frequency; e^{-jωT} well below the approximant's reach.
    g = aerocontrol.frequency_response(delay, FREQUENCIES).response[:, 0, 0]
    np.testing.assert_allclose(np.abs(g), 1.0, rtol=1e-12)
    slow = FREQUENCIES[FREQUENCIES * T < 0.1]
    np.testing.assert_allclose(
        aerocontrol.frequency_response(delay, slow).response[:, 0, 0],
        np.exp(-1j * slow * T),
        rtol=0,
        atol=0.1 ** (2 * order + 1) + 1e-13,
    )


@pytest.mark.parametrize(
    ("num", "den"),
    [
        ([1.0], [1.0, 2.0]),
        ([1.0, 2.0, 3.0], [2.0, 1.0, 4.0, 5.0]),
        ([3.0, 1.0], [1.0, 0.5]),  # biproper
        ([0.0, 0.0, 1.0, 2.0], [1.0, 6.0, 11.0, 6.0]),  # leading zeros
        ([1e4], [1.0, 1.4e2, 1e4]),  # a fast second-order filter: coefficients over 4 decades
        ([1.0, 0.0, 0.25], [1.0, 0.4, 4.0, 1.2, 3.0]),  # a notch-like numerator
        ([4.0], [2.0]),  # static
    ],
)
def test_tf_matches_python_control(num: list[float], den: list[float]) -> None:
    ours = aerocontrol.tf(num, den, input_names="e", output_names="u")
    assert ours.input_names == ("e",) and ours.output_names == ("u",)
    _assert_same_response(ours, control.tf(num, den))
    _assert_same_response(ours, control.tf2ss(num, den))
    _assert_same_poles(ours, control.tf(num, den))


def test_tf_discrete() -> None:
    ours = aerocontrol.tf([0.2, 0.1], [1.0, -1.2, 0.5], dt=0.1)
    assert ours.dt == 0.1
    _assert_same_response(ours, control.tf([0.2, 0.1], [1.0, -1.2, 0.5], 0.1))


@pytest.mark.parametrize(
    ("zeros", "poles", "k"),
    [
        ([], [-1.0], 2.0),
        ([0.0], [-0.5, -10.0], 10.0),
        ([-1 + 2j, -1 - 2j, 0.5], [-0.1 + 3j, -0.1 - 3j, -2.0, -3.0, -4.0], 2.5),
        (
            [-3.0, -4.0, -5.0],
            [-1 + 1j, -1 - 1j, -2 + 5j, -2 - 5j],
            -0.3,
        ),  # real zeros, no real pole
        ([2.0], [-1.0, -2.0, -3.0], 1.0),  # right-half-plane zero
        ([-1.0 + 1j, -1.0 - 1j], [-1.5 + 1j, -1.5 - 1j], 1.0),  # biproper
        ([], [-0.05, -0.8 + 0.7j, -0.8 - 0.7j, -1.3, -20.0], 7.0),
    ],
)
def test_zpk_matches_python_control(zeros: list[complex], poles: list[complex], k: float) -> None:
    ours = aerocontrol.zpk(zeros, poles, k)
    reference = control.zpk(zeros, poles, k)
    _assert_same_response(ours, reference)
    _assert_same_poles(ours, reference)
    assert ours.n_states == len(poles)


def test_zpk_discrete_and_zero_gain() -> None:
    ours = aerocontrol.zpk([0.5], [0.9, 0.2 + 0.3j, 0.2 - 0.3j], 0.7, dt=0.02)
    _assert_same_response(ours, control.zpk([0.5], [0.9, 0.2 + 0.3j, 0.2 - 0.3j], 0.7, dt=0.02))
    zero = aerocontrol.zpk([], [-1.0, -2.0], 0.0)
    assert np.all(aerocontrol.frequency_response(zero, FREQUENCIES).response == 0.0)


def test_gain() -> None:
    scalar = aerocontrol.gain(2.5, input_names="r", output_names="rudder")
    assert scalar.n_states == 0 and scalar.D.tolist() == [[2.5]]
    matrix = aerocontrol.gain([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]], output_names=["a", "b", "c"])
    assert matrix.input_names == ("u0", "u1") and matrix.output_names == ("a", "b", "c")
    g = aerocontrol.frequency_response(matrix, [0.0, 1e3]).response
    np.testing.assert_array_equal(g, np.broadcast_to(matrix.D, (2, 3, 2)))


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda: aerocontrol.washout(0.0), InvalidArgumentError, "tau must be positive, got 0.0"),
        (lambda: aerocontrol.washout(-2.0), InvalidArgumentError, "tau must be positive"),
        (lambda: aerocontrol.washout(np.nan), NonFiniteError, "tau must be finite"),
        (lambda: aerocontrol.washout(np.inf), NonFiniteError, "tau must be finite"),
        (lambda: aerocontrol.washout("2"), NotRealError, "tau must be an array of real numbers"),
        (lambda: aerocontrol.washout([1.0, 2.0]), ShapeError, "tau must be a scalar"),
        (lambda: aerocontrol.first_order_lag(0.0), InvalidArgumentError, "tau must be positive"),
        (lambda: aerocontrol.first_order_lag(1.0, gain=np.inf), NonFiniteError, "gain"),
        (lambda: aerocontrol.actuator(-20.0), InvalidArgumentError, "bandwidth must be positive"),
        (lambda: aerocontrol.actuator(1j), NotRealError, "bandwidth must be real"),
        (lambda: aerocontrol.second_order(0.0, 0.7), InvalidArgumentError, "omega_n must be"),
        (lambda: aerocontrol.second_order(1.0, -0.1), InvalidArgumentError, "zeta must be non-ne"),
        (lambda: aerocontrol.second_order(1.0, np.nan), NonFiniteError, "zeta must be finite"),
        (lambda: aerocontrol.pade_delay(0.0, 2), InvalidArgumentError, "T must be positive"),
        (lambda: aerocontrol.pade_delay(0.1, 0), InvalidArgumentError, "order must be a positive"),
        (
            lambda: aerocontrol.pade_delay(0.1, 2.0),
            InvalidArgumentError,
            "order must be a positive",
        ),
        (lambda: aerocontrol.pade_delay(0.1, True), InvalidArgumentError, "order must be a posit"),
        (lambda: aerocontrol.pade_delay(0.1, 21), InvalidArgumentError, "order must be at most 20"),
        (lambda: aerocontrol.gain(np.ones((2, 2, 2))), ShapeError, "K must be a scalar or a 2-D"),
        (lambda: aerocontrol.gain([[np.nan]]), NonFiniteError, r"K\[0, 0\] is NaN"),
        (lambda: aerocontrol.tf([1, 0, 0], [1, 1]), InvalidArgumentError, "improper"),
        (lambda: aerocontrol.tf([1], [0, 0]), InvalidArgumentError, "den must have a nonzero"),
        (lambda: aerocontrol.tf([1], [[1, 2]]), ShapeError, "den must be a 1-D array"),
        (lambda: aerocontrol.tf([1], [1, np.inf]), NonFiniteError, r"den\[1\] is inf"),
        (lambda: aerocontrol.tf([1j], [1, 2]), NotRealError, "num must be real"),
        (lambda: aerocontrol.zpk([-1, -2], [-3], 1.0), InvalidArgumentError, "improper"),
        (lambda: aerocontrol.zpk([], [-1 + 1j], 1.0), InvalidArgumentError, "without its conj"),
        (lambda: aerocontrol.zpk([], [-1 + 1j, -1 - 2j], 1.0), InvalidArgumentError, "conjugate"),
        (lambda: aerocontrol.zpk([], [np.nan], 1.0), NonFiniteError, "p must be finite"),
        (lambda: aerocontrol.zpk([], [-1.0], np.inf), NonFiniteError, "k must be finite"),
        (lambda: aerocontrol.zpk([], ["a"], 1.0), NotRealError, "p must be an array of numbers"),
        (lambda: aerocontrol.washout(1.0, input_names=["a", "b"]), ShapeError, "input_names must"),
        (lambda: aerocontrol.washout(1.0, output_names=[3]), InvalidArgumentError, "output_name"),
    ],
)
def test_elements_check_their_arguments_by_name(make: object, error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        make()  # type: ignore[operator]


def test_elements_name_their_signals_and_states() -> None:
    filt = aerocontrol.washout(2.0, input_names="r", output_names="r washed")
    assert (filt.input_names, filt.output_names, filt.state_names) == (
        ("r",),
        ("r washed",),
        ("r lagged",),
    )
    delay = aerocontrol.pade_delay(0.1, 2, input_names="command")
    assert delay.state_names == ("command delay x0", "command delay x1")
    assert aerocontrol.tf([1.0], [1.0, 1.0, 1.0], output_names="y").state_names == ("y x0", "y x1")
    named = aerocontrol.zpk([], [-1.0, -2.0], 1.0, state_names=["slow", "fast"])
    assert named.state_names == ("slow", "fast")


def test_yaw_damper_improves_the_dutch_roll() -> None:
    """The assembled damper (washout, gain 1.5, actuator) raises the damping of the 747's
    Dutch roll by more than half (0.108 to 0.188); python-control's interconnect of the same
    blocks has the same poles."""

    def dutch_roll_damping(sys: StateSpace) -> float:
        found = aerocontrol.modes(sys)
        return float(np.min(found.damping_ratio[np.asarray(found.oscillatory, dtype=bool)]))

    closed = aerocontrol.connect(_yaw_damper_blocks(1.5), inputs="rudder command", outputs="r")
    assert dutch_roll_damping(closed) > 1.5 * dutch_roll_damping(LATERAL)
    reference = control.interconnect(
        [_pc(b) for b in _yaw_damper_blocks(1.5)],
        inputs="rudder command",
        outputs="r",
        check_unused=False,  # beta is measured but not an output here
    )
    _assert_same_poles(closed, reference)


def test_no_warnings_for_ordinary_use() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        aerocontrol.connect(_yaw_damper_blocks(), inputs="rudder command", outputs="r")
        aerocontrol.pade_delay(0.2, 6)
        aerocontrol.feedback(aerocontrol.tf([1.0], [1.0, 1.0]))


# ----- identities and high-precision references --------------------------------------------------


@settings(max_examples=40, deadline=None, derandomize=True, database=None)
@given(
    n1=st.integers(0, 5),
    n2=st.integers(0, 5),
    m=st.integers(1, 3),
    p=st.integers(1, 3),
    seed=st.integers(0, 2**32 - 1),
    discrete=st.booleans(),
    sign=st.sampled_from([-1, 1]),
)
def test_interconnections_multiply_add_and_invert_frequency_responses(
    n1: int, n2: int, m: int, p: int, seed: int, discrete: bool, sign: int
) -> None:
    """G_series = G2 G1, G_parallel = G1 + G3 and G_feedback = (I - sign G1 G2)^-1 G1 at every
    frequency, from the parts' own responses (an oracle independent of the realisation)."""
    dt = 0.1 if discrete else None
    g1 = _random(n1, m, p, seed=seed % 1000, dt=dt)
    g2 = _random(n2, p, m, seed=seed % 997 + 1, dt=dt)
    g3 = _random(n2, m, p, seed=seed % 991 + 2, dt=dt)
    omega = np.logspace(-2, np.log10(np.pi / 0.1) if discrete else 2, 30)

    def response(sys: StateSpace) -> np.ndarray:
        return aerocontrol.frequency_response(sys, omega).response

    G1, G2, G3 = response(g1), response(g2), response(g3)
    loop = np.eye(p) - sign * G1 @ G2
    if np.min(np.linalg.svd(loop, compute_uv=False)) < 1e-6:
        return  # a closed-loop pole within 1e-6 of the grid: the comparison loses its digits
    expected = [G2 @ G1, G1 + G3, np.linalg.solve(loop, G1)]
    try:
        closed = aerocontrol.feedback(g1, g2, sign=sign)
    except SingularMatrixError:
        return  # I - sign D2 D1 singular: refused, as it must be
    actual = [response(aerocontrol.series(g1, g2)), response(aerocontrol.parallel(g1, g3))]
    actual.append(response(closed))
    for got, want in zip(actual, expected, strict=True):
        error = np.linalg.norm(got - want, axis=(1, 2)) / np.linalg.norm(want, axis=(1, 2))
        assert np.max(error) <= 1e-9


@pytest.mark.parametrize(
    ("order", "bound"), [(2, 1e-14), (6, 1e-14), (10, 5e-14), (14, 2e-13), (20, 5e-12)]
)
def test_pade_delay_against_the_approximant_in_high_precision(order: int, bound: float) -> None:
    # P(-x)/P(x), P(x) = sum c_k x^k, c_k = (2n - k)! n! / ((2n)! k! (n - k)!), at 50 digits.
    # Measured: 5.7e-16 (order 3), 1.3e-15 (6), 7.6e-15 (10), 4.2e-14 (14), 1.2e-12 (20).
    T = 0.3
    n = order
    c = [
        mpmath.factorial(2 * n - k)
        * mpmath.factorial(n)
        / (mpmath.factorial(2 * n) * mpmath.factorial(k) * mpmath.factorial(n - k))
        for k in range(n + 1)
    ]
    with mpmath.workdps(50):
        exact = []
        for w in FREQUENCIES:
            x = mpmath.mpc(0, w) * mpmath.mpf(T)
            exact.append(
                complex(
                    sum(ck * (-x) ** k for k, ck in enumerate(c))
                    / sum(ck * x**k for k, ck in enumerate(c))
                )
            )
    ours = aerocontrol.frequency_response(aerocontrol.pade_delay(T, order), FREQUENCIES).response
    error = np.abs(ours[:, 0, 0] - np.array(exact))  # |G| = 1
    assert np.max(error) <= bound, np.max(error)


# ----- products beyond the range of doubles -----------------------------------------------------

#: 1/(s + 1) and 1/(s + 2) realised with B and C of 1e±200: B2 C1 = 1e400 overflows.
_LAG_1 = (np.array([[-1.0]]), np.array([[1e-200]]), np.array([[1e200]]), np.zeros((1, 1)))
_LAG_2 = (np.array([[-2.0]]), np.array([[1e200]]), np.array([[1e-200]]), np.zeros((1, 1)))


def _response(sys: aerocontrol.StateSpace, s: complex) -> complex:
    """C (sI - A)^-1 B + D by numpy, independently of the core."""
    n = sys.n_states
    return complex((sys.C @ np.linalg.solve(s * np.eye(n) - sys.A, sys.B) + sys.D)[0, 0])


_POINTS = (0.0, 0.3j, 1.0 + 2.0j, 40.0j)


def test_interconnections_whose_products_overflow_are_formed_in_scaled_states() -> None:
    """The states are rescaled by powers of two, so the models are those of the transfer
    functions: G2 G1 = 1/((s + 1)(s + 2)), G1/(1 + G2 G1) = (s + 2)/(s^2 + 3 s + 3), the
    same by name, and S of the series loop (s + 1)(s + 2)/(s^2 + 3 s + 3); to 1e-14."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = aerocontrol.series(_LAG_1, _LAG_2)
        loop = aerocontrol.feedback(_LAG_1, _LAG_2)
        named = aerocontrol.connect(
            [
                aerocontrol.summing_junction(["r", "-z"], "e"),
                aerocontrol.StateSpace(*_LAG_1, input_names="e", output_names="y"),
                aerocontrol.StateSpace(*_LAG_2, input_names="y", output_names="z"),
            ],
            inputs="r",
            outputs="y",
        )
        S = aerocontrol.sensitivity(chain)
    for s in _POINTS:
        expected = {
            "series": 1 / ((s + 1) * (s + 2)),
            "feedback": (s + 2) / (s * s + 3 * s + 3),
            "connect": (s + 2) / (s * s + 3 * s + 3),
            "sensitivity": (s + 1) * (s + 2) / (s * s + 3 * s + 3),
        }
        for name, model in (("series", chain), ("feedback", loop), ("connect", named)):
            assert _response(model, s) == pytest.approx(expected[name], rel=1e-14), name
        assert _response(S, s) == pytest.approx(expected["sensitivity"], rel=1e-14)
    assert np.sort_complex(np.linalg.eigvals(loop.A)) == pytest.approx(
        [(-3 - 3**0.5 * 1j) / 2, (-3 + 3**0.5 * 1j) / 2], rel=1e-14
    )
    assert np.all(np.abs(chain.A) < 1e200) and np.all(np.abs(loop.A) < 1e200)


def test_interconnections_beyond_the_range_of_doubles_are_refused_by_name() -> None:
    """D2 D1 = 1e400, and the pole -1 - 1e400 of a loop: no state scaling brings them into
    range, so InvalidArgumentError names the arguments (not NonFiniteError on A)."""
    big = (np.array([[-1.0]]), np.array([[1e200]]), np.array([[1e200]]), np.zeros((1, 1)))
    static = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[1e200]]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(aerocontrol.InvalidArgumentError, match="D overflows") as error:
            aerocontrol.series(static, static)
        assert not isinstance(error.value, aerocontrol.NonFiniteError)
        assert error.value.argument == "sys1"
        with pytest.raises(aerocontrol.InvalidArgumentError, match="sys1, sys2") as error:
            aerocontrol.feedback(big)
        assert not isinstance(error.value, aerocontrol.NonFiniteError)
        with pytest.raises(aerocontrol.InvalidArgumentError, match="loop") as error:
            aerocontrol.complementary_sensitivity(big)
        assert error.value.argument == "loop"


def test_parallel_of_feedthroughs_whose_sum_overflows() -> None:
    """D1 + D2 = 2e308: numpy's overflow warning in the sum, then a NonFiniteError blaming a D
    the caller gave finite; now an InvalidArgumentError naming the models. A sum that cancels
    is exact."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(aerocontrol.InvalidArgumentError, match=r"parallel: .*D overflows") as e:
            aerocontrol.parallel(aerocontrol.gain(1e308), aerocontrol.gain(1e308))
        assert getattr(e.value, "argument", None) == "sys1"
        assert aerocontrol.parallel(aerocontrol.gain(1e308), aerocontrol.gain(-1e308)).D == 0.0


@pytest.mark.parametrize(
    ("make", "argument", "message"),
    [
        (lambda: aerocontrol.zpk([], [1.5e308 + 1j, 1.5e308 - 1j], 1.0), "p", "about 6e307"),
        (lambda: aerocontrol.zpk([1.5e308, 1.5e308], [-1.0, -2.0], 1.0), "z", "about 6e307"),
        (
            lambda: aerocontrol.zpk(
                [1e300 + 1e300j, 1e300 - 1e300j], [1e-300 + 1e-300j, 1e-300 - 1e-300j], 1.0
            ),
            "z",
            "too far apart in size",
        ),
        (lambda: aerocontrol.first_order_lag(1e-310), "tau", r"tau = 1e-310 is too small"),
        (lambda: aerocontrol.washout(1e-310), "tau", "1/tau overflows"),
        (lambda: aerocontrol.tf([1e300, 1.0], [1e-300, 1.0]), "num", "leading coefficient 1e-300"),
        (lambda: aerocontrol.tf([1.0], [1e-300, 1.0, 1e300]), "den", "realisation's A overflows"),
        (lambda: aerocontrol.second_order(1e308, 10.0), "zeta", "2 zeta omega_n"),
        (lambda: aerocontrol.pade_delay(1e-310, 3), "T", "T = 1e-310 is too small"),
    ],
)
def test_realisations_beyond_the_doubles_are_refused_by_name(
    make: object, argument: str, message: str
) -> None:
    """Finite arguments whose realisation overflows: numpy's overflow warnings, an
    OverflowError from the balancing (int(inf)) or a NonFiniteError blaming an A the caller
    never gave; now an InvalidArgumentError naming the argument, and no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(aerocontrol.InvalidArgumentError, match=message) as raised:
            make()  # type: ignore[operator]
    assert getattr(raised.value, "argument", None) == argument


def test_realisations_near_the_limits_that_fit() -> None:
    """Just inside the doubles the realisations are exact."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lag = aerocontrol.first_order_lag(2.0**-1000)
        assert lag.A[0, 0] == -(2.0**1000) and lag.B[0, 0] == 2.0**1000
        g = aerocontrol.zpk([], [1e150 + 1e150j, 1e150 - 1e150j], 1.0)
        poles = np.sort_complex(np.linalg.eigvals(g.A))
        np.testing.assert_allclose(poles, [1e150 - 1e150j, 1e150 + 1e150j], rtol=1e-12)
        assert aerocontrol.second_order(5e306, 10.0).A[1, 1] == -1e308
        # Real poles are first-order sections unless a zero needs them in a quadratic: no
        # coefficient r1 r2 of 2.25e616 (refused before, as "beyond about 6e307").
        poles = np.linalg.eigvals(aerocontrol.zpk([], [1.5e308, 1.5e308], 1.0).A)
        np.testing.assert_array_equal(poles, [1.5e308, 1.5e308])


def test_feedback_of_a_series_whose_states_differ_in_size() -> None:
    """feedback(series(plant with B of 1e308, lag with C of 2.04)): B C of 2e308 under every
    scaling of the series as one part ('no scaling of the states brings it within range', which
    was false); the states are now scaled one by one, on the closed loop's entries (see
    test_feedback_balances_the_closed_loop_not_the_parts). The closed loop's poles are
    a ± j √(b1 c1 b2 c2), exactly as the characteristic polynomial (s - a)² + b1 c1 b2 c2."""
    a, b, c = -1.8742697789066067, 0.1257302210933933, 2.0409191213851825
    plant = aerocontrol.StateSpace([[a]], [[1e308]], [[b]], [[0.0]])
    lag = aerocontrol.StateSpace([[a]], [[b]], [[c]], [[0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        closed = aerocontrol.feedback(aerocontrol.series(plant, lag))
    poles = np.sort_complex(np.linalg.eigvals(closed.A))
    omega = math.sqrt(1e308 * b * b * c)
    np.testing.assert_allclose(poles.imag, [-omega, omega], rtol=1e-14)
    np.testing.assert_allclose(poles.real, [a, a], rtol=1e-6)


# ----- products beyond the range of doubles that a scaling of the states keeps ---------------


def _series_then_loop() -> tuple[StateSpace, StateSpace]:
    """2e154/(s + 1) into 1e308 (1/(s + 1) + 1/(s + 2)): the open loop of the loop gain
    L(s) = 2e462 (2s + 3)/((s + 1)^2 (s + 2))."""
    first = StateSpace([[-1.0]], [[2.0]], [[1e154]], [[0.0]])
    second = StateSpace([[-1.0, 0.0], [0.0, -2.0]], [[1.0], [1.0]], [[1e308, 1e308]], [[0.0]])
    return first, second


def _closed_loop_reference(s: complex) -> complex:
    """T = L/(1 + L) = 1/(1 + 1/L) of that loop, at 50 digits."""
    with mpmath.workdps(50):
        x = mpmath.mpc(s)
        inverse = (x + 1) ** 2 * (x + 2) / (mpmath.mpf(2) * 10**462 * (2 * x + 3))
        return complex(1 / (1 + inverse))


def test_feedback_balances_the_closed_loop_not_the_parts() -> None:
    """The defect: the closed loop A - B C has couplings B C of 2e308 that no scaling of the
    parts' states, each part balanced on its own, brings within range, and feedback refused
    it ('no scaling of the states brings it within range'), though one exists: the states are
    now scaled on the entries of the closed loop itself. Oracles: its poles, the roots of
    (s + 1)^2 (s + 2) + 2e462 (2s + 3) by mpmath (-1.5 and -1.25 ± 2.0000000000000000479e231
    j), to 1e-15; its response T = 1/(1 + 1/L) at 50 digits, to 1e-14 (measured 1.3e-17)
    away from the resonance at 2e231, where 1e-16 of ω moves T by its own size; the same
    loop closed by connect, by complementary_sensitivity, and the sensitivity 1 - T (at low
    frequency 1e-462, that is 0 to the rounding of its terms of 1)."""
    first, second = _series_then_loop()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        loop = aerocontrol.series(first, second)
        closed = aerocontrol.feedback(loop)
        named = aerocontrol.connect(
            [
                aerocontrol.summing_junction(["r", "-y"], "e"),
                StateSpace(first.A, first.B, first.C, first.D, input_names="e", output_names="v"),
                StateSpace(
                    second.A, second.B, second.C, second.D, input_names="v", output_names="y"
                ),
            ],
            inputs="r",
            outputs="y",
        )
        T = aerocontrol.complementary_sensitivity(loop)
        S = aerocontrol.sensitivity(loop)
    with mpmath.workdps(60):
        g = mpmath.mpf(2) * 10**462
        roots = mpmath.polyroots(
            [2 + 3 * g, 5 + 2 * g, 4, 1], asc=True, maxsteps=200, extraprec=3000
        )
    expected = np.sort_complex(np.array([complex(r) for r in roots]))
    assert expected[1].imag == pytest.approx(-2.0000000000000000479e231, rel=1e-16)
    omegas = [0.0, 1.0, 1e231, 1e232]
    for model in (closed, named, T, S):
        assert np.all(np.isfinite(model.A)) and np.abs(model.A).max() < 1e240
        poles = np.sort_complex(np.linalg.eigvals(model.A))
        np.testing.assert_allclose(poles, expected, rtol=1e-15)
        response = aerocontrol.frequency_response(model, omegas).response[:, 0, 0]
        for w, value in zip(omegas, response, strict=True):
            reference = _closed_loop_reference(1j * w)
            if model is S:
                reference = 1.0 - reference
                if w < 1e231:  # S = 1/(1 + L) of 1e-462 is 1 - T: 0 to the rounding of 1
                    assert abs(value) <= 1e-15
                    continue
            assert abs(value - reference) <= 1e-14 * abs(reference), (w, value, reference)


def test_connect_scales_each_state_of_a_block() -> None:
    """A loop found by the property suite: a plant of pole 1e308 and B of 1.7e300 into a
    sixth-order block with C of 1e8 (B C beyond the doubles in the closed loop). feedback
    refused it (a NonFiniteError from the balancing of the series: A_ii times then divided by
    2^k overflowed); connect, which scaled each block as one, then formed the block's A
    unscaled beside its B and C scaled state by state, a different system (T off by 20 %).
    Oracle: T = L/(1 + L) with L = P O, the plant P(s) = c b/(s - a) and the block
    O(s) = C (sI - A)^-1 B each evaluated by numpy, to 1e-12 (measured 2e-16)."""
    rng = np.random.default_rng(11)
    A6 = -3.0 * np.eye(6) + 0.5 * rng.standard_normal((6, 6))
    B6 = 0.5 * rng.standard_normal((6, 1))
    C6 = 1e8 * rng.standard_normal((1, 6))
    a, b, c = 1e308, 1.728162865989976e300, 0.1257302210933933
    plant = StateSpace([[a]], [[b]], [[c]], [[0.0]], input_names="e", output_names="v")
    block = StateSpace(A6, B6, C6, [[0.0]], input_names="v", output_names="z")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        closed = aerocontrol.feedback(aerocontrol.series(plant, block))
        named = aerocontrol.connect(
            [aerocontrol.summing_junction(["r", "-z"], "e"), plant, block],
            inputs="r",
            outputs="z",
        )
    omegas = [0.31, 1.7, 11.0]
    for model in (closed, named):
        response = aerocontrol.frequency_response(model, omegas).response[:, 0, 0]
        for w, value in zip(omegas, response, strict=True):
            s = 1j * w
            L = c * b / (s - a) * (C6 @ np.linalg.solve(s * np.eye(6) - A6, B6))[0, 0]
            assert abs(value - L / (1 + L)) <= 1e-12 * abs(L / (1 + L)), (w, value)


def test_series_keeps_a_product_that_underflows() -> None:
    """A property-suite input: a lag with B of 1.26e149 into a gain of 5e-324 (the smallest
    double). D2 C1 = 5e-324 x 0.126 is 0 in doubles and the series was the zero model,
    silently; its G2 G1 = 5e-324 c b/(s - a) is 4e-176. The states are now scaled where a
    product underflows as where one overflows. Oracle: the closed form, to 1e-15."""
    a, b, c = -1.8742697789066067, 1.257302210933933e149, 0.1257302210933933
    lag = StateSpace([[a]], [[b]], [[c]], [[0.0]])
    tiny = aerocontrol.gain(5e-324)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = aerocontrol.series(lag, tiny)
    for w in (0.0, 0.31, 11.0):
        value = aerocontrol.frequency_response(chain, [w]).response[0, 0, 0]
        expected = c * b / (1j * w - a) * 5e-324
        assert abs(value - expected) <= 1e-15 * abs(expected), (w, value, expected)


def _zpk_reference(zeros: list[complex], poles: list[complex], k: float, s: complex) -> complex:
    with mpmath.workdps(40):
        value = mpmath.mpf(k)
        for r in zeros:
            value *= mpmath.mpc(s) - mpmath.mpc(r)
        for r in poles:
            value /= mpmath.mpc(s) - mpmath.mpc(r)
        return complex(value)


@pytest.mark.parametrize(
    ("zeros", "poles", "k", "omegas"),
    [
        ([], [1e200 + 1e200j, 1e200 - 1e200j], 1e300, [1e200, 3e200]),
        (
            [3e200 + 4e200j, 3e200 - 4e200j],
            [1e200 + 1e200j, 1e200 - 1e200j, -2.0],
            1.0,
            [1.0, 1e200, 5e200],
        ),
        ([1e200, 2e200], [-1.0, -2.0], 1e-300, [0.0, 1.0]),
        ([], [-1e200, -3e200], 1e300, [0.0, 1e200]),
        ([], [1e-200, 1e-200], 1e-300, [0.0, 1e-200]),
        ([], [-1e-200 + 1e-200j, -1e-200 - 1e-200j], 1e-300, [0.0, 1e-200]),
    ],
)
def test_zpk_of_roots_whose_products_leave_the_doubles(
    zeros: list[complex], poles: list[complex], k: float, omegas: list[float]
) -> None:
    """The defect: zpk formed |p|^2 (and r1 r2) of a pair as a coefficient, refused roots
    beyond 1e154 ('the second-order section overflows'), and turned a product of roots of
    1e-200 into 0, a pole at 0 for a pole at 1e-200, silently. The sections now hold the
    product as a mantissa and a power of two, and their realisation the scaled entries a0/t
    and t. Oracles: the poles (eigenvalues of A, to 1e-14; measured 1.7e-16) and the response
    k Π(s - z)/Π(s - p) at 40 digits (to 1e-14; measured 3.6e-16)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = aerocontrol.zpk(zeros, poles, k)
    ours = np.sort_complex(np.linalg.eigvals(g.A))
    np.testing.assert_allclose(ours, np.sort_complex(np.array(poles, complex)), rtol=1e-14)
    response = aerocontrol.frequency_response(g, omegas).response[:, 0, 0]
    for w, value in zip(omegas, response, strict=True):
        expected = _zpk_reference(zeros, poles, k, 1j * w)
        assert abs(value - expected) <= 1e-14 * abs(expected), (w, value, expected)


@pytest.mark.parametrize(
    ("zeros", "poles", "k"),
    [
        ([], [-1.0, -1e20], 1e20),
        ([], [-1.0, -1e300], 1e300),
        ([], [-1.0, -2.0, -3e15, -1e20], 1e35),
        ([-2e20], [-1.0, -2.0, -1e20, -5.0 + 1j, -5.0 - 1j], 1.0),
        ([-5.0], [-1.0, -1e20], 1e20),
        ([-3e20], [-1.0, -1e20], 1.0),
    ],
)
def test_zpk_real_poles_far_apart_keep_their_sizes(
    zeros: list[complex], poles: list[complex], k: float
) -> None:
    """The defect: zpk joined every two real poles in one quadratic section, whose
    A = [[0, -a0/t], [t, -a1]] keeps the smaller pole only to the larger's rounding in its
    eigenvalues (their backward error is u ||A||): zpk([], [-1, -1e20], 1e20) had the poles 0
    and -1e20 (numpy's eigvals and transfer_function alike), so that transfer_function's
    G(0.3 + 0.7j) was off by 131 % and its G(0) infinite, silently. A pair of real poles that
    holds no zero is now two first-order sections (A triangular), and so is a pair far apart
    holding a zero no smaller than the smaller pole ((s + 5)/(s + 1) and 1/(s + 1e20)).
    Oracles: the poles given
    (the eigenvalues of A, and transfer_function's, to 1e-14; measured 3e-16) and
    k Π(s - z)/Π(s - p) at 40 digits (transfer_function's G and frequency_response, to
    1e-13; measured 6e-16)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        g = aerocontrol.zpk(zeros, poles, k)
    expected_poles = np.sort_complex(np.array(poles, complex))
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(g.A)), expected_poles, rtol=1e-14)
    channel = aerocontrol.transfer_function(g)
    np.testing.assert_allclose(np.sort_complex(channel.poles), expected_poles, rtol=1e-14)
    expected_zeros = np.sort_complex(np.array(zeros, complex))
    np.testing.assert_allclose(np.sort_complex(channel.zeros), expected_zeros, rtol=1e-13)
    omegas = [0.0, 0.7, 2.0]
    response = aerocontrol.frequency_response(g, omegas).response[:, 0, 0]
    for s, value in zip([0.3 + 0.7j, *(1j * w for w in omegas)], [None, *response], strict=True):
        expected = _zpk_reference(zeros, poles, k, s)
        for got in (channel(s), value):
            if got is not None:
                assert abs(got - expected) <= 1e-13 * abs(expected), (s, got, expected)
