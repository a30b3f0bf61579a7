"""Properties of the batch solvers (aerocontrol.batch): solve_care_batch, solve_dare_batch,
place_batch, lqr_sweep and dlqr_sweep.

Oracles: each problem of a batch against the single-problem call on the same numbers
(solve_care, solve_dare, place, place_bass_gura, place_ackermann), bitwise, as the module
promises ("each solved exactly as solve_care solves it alone"); the warning issued when and
only when a single call would warn; a failure reported as the lowest failing problem's own
exception class with its index (``batch_index`` and "problem i of the batch" in the message),
and a batch that fails only where some single call fails; a stack of the wrong shape or count
refused as ShapeError naming the argument; the sweeps as the single solves of R / c².
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol import batch
from aerocontrol.exceptions import AerocontrolError, IllConditionedWarning, ShapeError

from .harness import SAME, TALLY, Arg, Outcome, Warned, _known_defect, exercise, plain
from .oracles import finite, silenced
from .strategies import (
    canonical,
    model_matrices,
    orders,
    presented,
    presented_system,
    riccati_problem,
    square,
)

COVERED = {
    "batch.solve_care_batch",
    "batch.solve_dare_batch",
    "batch.place_batch",
    "batch.lqr_sweep",
    "batch.dlqr_sweep",
}

#: How a stacked argument is given: one matrix shared by every problem, a stack of k, or a
#: wrong one (to be refused as a ShapeError naming it).
SHARING = ("shared", "stack", "stack", "stack")
WRONG = ("count", "order", "4-D", "vector")


# ----- calling the single-problem functions -----------------------------------------------------


def member(stack: np.ndarray, i: int, name: str) -> np.ndarray:
    """Problem i's matrix of a canonical stacked argument (one matrix shared, or k of them; a
    1-D B is one input)."""
    array = np.asarray(stack, dtype=np.float64)
    if name == "B" and array.ndim == 1:
        return array.reshape(-1, 1)
    return array if array.ndim == 2 else array[i if array.shape[0] > 1 else 0]


def batch_count(args: dict[str, Any], names: tuple[str, ...], rows: int = 1) -> int:
    """The number of problems: the count of the stacks that are not of one (shared)."""
    counts = [np.asarray(args[x]).shape[0] for x in names if np.asarray(args[x]).ndim == 3]
    counts = [count for count in [*counts, rows] if count != 1]
    return counts[0] if counts else 1


def single_outcome(function: Any, *args: Any, **kwargs: Any) -> Outcome:
    """The outcome of one single-problem call, its aerocontrol warnings recorded."""
    import warnings

    with warnings.catch_warnings(record=True) as caught, silenced():
        warnings.simplefilter("always")
        try:
            result = function(*args, **kwargs)
            error = None
        except AerocontrolError as raised:
            result, error = None, raised
    warned = tuple(dict.fromkeys(w.category for w in caught if w.category is IllConditionedWarning))
    return Outcome(result, error, warned)


def _riccati_singles(args: dict[str, Any], discrete: bool) -> list[Outcome]:
    solver = aerocontrol.solve_dare if discrete else aerocontrol.solve_care
    k = batch_count(args, ("A", "B", "Q", "R"))
    extra = {} if discrete else {"refine": args.get("refine", True)}
    return [
        single_outcome(solver, *(member(args[x], i, x) for x in "ABQR"), **extra) for i in range(k)
    ]


def assert_batch_failure(name: str, outcome: Outcome, singles: list[Outcome]) -> None:
    """A batch fails as its lowest failing problem does, naming its index; it fails only if
    some problem does."""
    error = outcome.error
    assert error is not None
    failing = [i for i, single in enumerate(singles) if single.error is not None]
    if error.batch_index is None:
        # Refused before any problem was solved: the stacks' shapes or counts.
        assert (
            not isinstance(error, AerocontrolError)
            or isinstance(error, (ShapeError, aerocontrol.NonFiniteError, aerocontrol.NotRealError))
            or failing
        ), f"{name} refused the batch although every problem is solved: {error!r}"
        return
    assert failing, f"{name} failed at problem {error.batch_index}, which solves alone: {error}"
    first = failing[0]
    assert error.batch_index == first, (
        f"{name} names problem {error.batch_index}, the lowest failing one is {first}"
    )
    assert str(error).startswith(f"problem {first} of the batch"), f"message: {error}"
    expected = singles[first].error
    assert type(error) is type(expected), (
        f"{name}: problem {first} raises {type(error).__name__} in the batch but "
        f"{type(expected).__name__} alone ({expected})"
    )


def _assert_warning(name: str, warned: Warned, singles: list[Outcome]) -> None:
    alone = any(IllConditionedWarning in single.warned for single in singles)
    assert (IllConditionedWarning in warned) == alone, (
        f"{name} warned {warned}, the single calls {'did' if alone else 'did not'}"
    )


# ----- solve_care_batch and solve_dare_batch -----------------------------------------------------


def _riccati_batch_oracle(discrete: bool) -> Any:
    name = "solve_dare_batch" if discrete else "solve_care_batch"

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        singles = _riccati_singles(args, discrete)
        assert len(result) == len(singles), f"{len(result)} solutions of {len(singles)}"
        for i, single in enumerate(singles):
            assert single.error is None, f"problem {i} fails alone ({single.error!r})"
            alone = single.result
            for field in ("X", "K", "closed_loop_poles"):
                assert np.array_equal(
                    getattr(result, field)[i], getattr(alone, field), equal_nan=True
                ), f"{name}: {field} of problem {i} differs from the single call's"
            assert np.array_equal(result.residual[i], alone.residual, equal_nan=True), (
                f"{name}: the residual of problem {i} differs from the single call's"
            )
            assert np.array_equal(result.rcond[i], alone.rcond, equal_nan=True), (
                f"{name}: rcond of problem {i} is {result.rcond[i]}, alone {alone.rcond}"
            )
        _assert_warning(name, warned, singles)

    return oracle


def stacked(members: list[np.ndarray], how: str) -> np.ndarray:
    """The members as one shared matrix (the first) or a stack."""
    if how == "shared":
        return members[0]
    return np.stack(members) if members else np.zeros((0, 0, 0))


def _wrong(a: np.ndarray, how: str, name: str, others: list[Any]) -> np.ndarray:
    """``a`` (a stack of k, or one matrix) made of the wrong count or shape; ``others`` are
    the other stacked arguments, whose counts the wrong count must contradict."""
    stack = a if a.ndim == 3 else a[np.newaxis]
    counts = {np.asarray(o).shape[0] for o in others if np.asarray(o).ndim == 3} - {1}
    if how == "count" and counts:
        # Neither one (shared) nor the other stacks' count.
        wrong = max(max(counts) + 1, 2)
        return np.concatenate([stack[:1]] * wrong) if stack.shape[0] else np.zeros((wrong, 1, 1))
    if how in ("count", "order"):
        return np.pad(stack, ((0, 0), (0, 1), (0, 1)))
    if how == "4-D":
        return stack[np.newaxis]
    return np.zeros(3) if name != "B" else np.zeros((2, 2, 2, 2))


@st.composite
def riccati_batch(draw: st.DrawFn) -> tuple[dict[str, Arg], str | None]:
    """The arguments of a Riccati batch, and the argument made wrong (None: none is)."""
    n = draw(orders())
    m = draw(st.integers(1, 3))
    k = draw(st.sampled_from((0, 1, 2, 3, 3)))
    kinds = ("regulator", "regulator", "drawn", "imaginary axis") + ("planted",) * (n > 0)
    problems = [
        draw(riccati_problem(cross=False, descriptor_matrix=False, n=n, m=m, kinds=kinds))
        for _ in range(max(k, 1))
    ]
    problems = [p for p in problems if p["A"] is not None and p["A"].shape == (n, n)]
    arrays: dict[str, np.ndarray] = {}
    for name in "ABQR":
        how = draw(st.sampled_from(SHARING))
        members = [p[name] for p in problems][: k if how == "stack" else 1]
        if how == "stack" and len(members) < k:
            how = "shared"
        empty = np.zeros((0, *problems[0][name].shape))
        arrays[name] = stacked(members, how) if members else empty
    if k == 0:
        arrays["A"] = np.zeros((0, n, n))
    wrong = None
    if draw(st.sampled_from((False,) * 6 + (True,))):
        wrong = draw(st.sampled_from(("B", "Q", "R")))
        others = [a for name, a in arrays.items() if name != wrong]
        arrays[wrong] = _wrong(arrays[wrong], draw(st.sampled_from(WRONG)), wrong, others)
    if m == 1 and arrays["B"].ndim == 2 and draw(st.booleans()):
        arrays["B"] = arrays["B"][:, 0]  # one input as a vector, shared
    return {name: draw(presented(a)) for name, a in arrays.items()}, wrong


def _assert_shape_refusal(
    name: str, outcome: Outcome, arguments: dict[str, Arg], wrong: str
) -> None:
    """A stack made of the wrong shape is refused as a ShapeError that names it (unless
    another argument is refused first)."""
    if any(arg.expect != SAME for arg in arguments.values()):
        return
    error = outcome.error
    if error is None:
        failure = f"{name} accepted a wrong {wrong}"
        defect = _known_defect(f"batch.{name}", arguments, failure)
        if defect is None:
            _recount(f"batch.{name}", outcome.label, "FAILED")
            raise AssertionError(failure)
        _recount(f"batch.{name}", outcome.label, f"known defect: {defect.key}")
        return
    if isinstance(error, aerocontrol.InvalidArgumentError) and not isinstance(error, ShapeError):
        return  # another argument refused first (a NaN, a Q that is not symmetric)
    assert isinstance(error, ShapeError), f"{name}: a wrong {wrong} raised {error!r}"
    named = error.argument == wrong or re.search(rf"\b{wrong}\b", str(error))
    assert named, f"{name}: the ShapeError does not name {wrong}: {error}"


def _run_riccati_batch(data: st.DataObject, discrete: bool) -> None:
    name = "solve_dare_batch" if discrete else "solve_care_batch"
    arguments, wrong = data.draw(riccati_batch())
    if not discrete and data.draw(st.sampled_from((False, False, True))):
        arguments["refine"] = plain(False)
    function = batch.solve_dare_batch if discrete else batch.solve_care_batch
    outcome = exercise(f"batch.{name}", function, arguments, _riccati_batch_oracle(discrete))
    if wrong is not None:
        _assert_shape_refusal(name, outcome, arguments, wrong)
        return
    if outcome.error is None or any(arg.expect != SAME for arg in arguments.values()):
        return
    values = {key: arg.canonical for key, arg in arguments.items()}
    if _finite_stacks(values):
        failure_check(f"batch.{name}", outcome, values, _riccati_singles(values, discrete))


def _finite_stacks(values: dict[str, Any]) -> bool:
    return all(finite(value) for value in values.values() if isinstance(value, np.ndarray))


def failure_check(
    name: str, outcome: Outcome, values: dict[str, Any], singles: list[Outcome]
) -> None:
    """assert_batch_failure, a failed check on a known defect's inputs counted as such."""
    try:
        assert_batch_failure(name, outcome, singles)
    except AssertionError as failure:
        arguments = {key: Arg(value, value, "canonical", SAME) for key, value in values.items()}
        defect = _known_defect(name, arguments, str(failure))
        if defect is not None:
            # Counted as the defect, not as the exception the call raised.
            _recount(name, outcome.label, f"known defect: {defect.key}")
            return
        _recount(name, outcome.label, "FAILED")
        raise


def _recount(name: str, counted: str, instead: str) -> None:
    """Move one call of the tally from the outcome it was counted as to ``instead``."""
    TALLY[name][counted] -= 1
    if not TALLY[name][counted]:
        del TALLY[name][counted]
    TALLY[name][instead] += 1


@given(st.data())
def test_solve_care_batch(data: st.DataObject) -> None:
    _run_riccati_batch(data, False)


@given(st.data())
def test_solve_dare_batch(data: st.DataObject) -> None:
    _run_riccati_batch(data, True)


# ----- place_batch ------------------------------------------------------------------------------

PLACE_METHODS = {
    "knv": aerocontrol.place,
    "bass-gura": aerocontrol.place_bass_gura,
    "ackermann": aerocontrol.place_ackermann,
}


def _place_singles(args: dict[str, Any]) -> list[Outcome]:
    method = args["method"]
    poles = np.atleast_2d(np.asarray(args["poles"], dtype=np.complex128))
    k = batch_count(args, ("A", "B"), poles.shape[0])
    function = PLACE_METHODS[method]
    outcomes = []
    for i in range(k):
        A, B = member(args["A"], i, "A"), member(args["B"], i, "B")
        row = poles[0] if poles.shape[0] == 1 else poles[i]
        outcomes.append(single_outcome(function, A, B, row))
    return outcomes


def _place_batch_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    singles = _place_singles(args)
    method = args["method"]
    assert len(result) == len(singles)
    for i, single in enumerate(singles):
        assert single.error is None, f"problem {i} fails alone ({single.error!r})"
        alone = single.result
        assert np.array_equal(result.K[i], alone.K, equal_nan=True), f"K of problem {i}"
        assert np.array_equal(result.achieved_poles[i], alone.achieved_poles, equal_nan=True)
        assert np.array_equal(result.max_relative_error[i], alone.max_relative_error)
        measure = (
            alone.eigenvector_condition if method == "knv" else alone.controllability_condition
        )
        assert np.array_equal(result.condition[i], measure, equal_nan=True), f"condition {i}"
    _assert_warning("place_batch", warned, singles)


@given(st.data())
def test_place_batch(data: st.DataObject) -> None:
    n = data.draw(st.sampled_from((1, 2, 3, 4, 6)))
    method = data.draw(st.sampled_from(("knv", "knv", "bass-gura", "ackermann", "robust")))
    m = 1 if method in ("bass-gura", "ackermann") else data.draw(st.integers(1, 3))
    k = data.draw(st.sampled_from((0, 1, 2, 3)))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    plants = [data.draw(square(n)) for _ in range(max(k, 1))]
    inputs = [rng.standard_normal((n, m)) for _ in range(max(k, 1))]
    rows = []
    for _ in range(max(k, 1)):
        poles = -rng.uniform(0.5, 4.0, n).astype(complex)
        if n >= 2 and data.draw(st.booleans()):
            poles[0], poles[1] = complex(-1.0, 2.0), complex(-1.0, -2.0)
        rows.append(poles)
    A = plants[0] if data.draw(st.sampled_from(SHARING)) == "shared" else np.stack(plants)[:k]
    B = inputs[0] if data.draw(st.sampled_from(SHARING)) == "shared" else np.stack(inputs)[:k]
    P = rows[0] if data.draw(st.sampled_from(SHARING)) == "shared" else np.stack(rows)[:k]
    if k == 0:
        A = np.zeros((0, n, n))
    wrong = None
    if data.draw(st.sampled_from((False,) * 6 + (True,))):
        wrong = data.draw(st.sampled_from(("B", "poles")))
        if wrong == "B":
            B = _wrong(B, data.draw(st.sampled_from(WRONG)), "B", [A, np.atleast_2d(P)[:, None, :]])
        else:
            P = np.pad(np.atleast_2d(P), ((0, 0), (0, 1)), constant_values=-1.0)
    if m == 1 and B.ndim == 2 and data.draw(st.booleans()):
        B = B[:, 0]
    how = data.draw(st.sampled_from(("complex array", "list", "complex array")))
    if how == "list" and P.size == 0:
        how = "complex array"  # a list cannot hold the shape of an empty array
    pole_arg = Arg(P.tolist() if how == "list" else P, np.array(P, dtype=complex), how, SAME)
    arguments = {
        "A": data.draw(presented(A)),
        "B": data.draw(presented(B)),
        "poles": pole_arg,
        "method": plain(method),
    }
    outcome = exercise("batch.place_batch", batch.place_batch, arguments, _place_batch_oracle)
    if method == "robust":
        assert outcome.error is not None, "an unknown method was accepted"
        return
    if wrong is not None:
        _assert_shape_refusal("place_batch", outcome, arguments, wrong)
        return
    if outcome.error is None or any(arg.expect != SAME for arg in arguments.values()):
        return
    values = {key: arg.canonical for key, arg in arguments.items()}
    if _finite_stacks(values):
        failure_check("batch.place_batch", outcome, values, _place_singles(values))


# ----- lqr_sweep and dlqr_sweep -----------------------------------------------------------------


def _sweep_problem(args: dict[str, Any]) -> tuple[np.ndarray, ...]:
    if "sys" in args:
        A, B, _, _ = model_matrices(args["sys"])
    else:
        A = np.asarray(args["sys_or_A"], float)
        B = np.asarray(args["B"], float)
        B = B.reshape(-1, 1) if B.ndim == 1 else B
    n, m = A.shape[0], B.shape[1]
    Q = np.eye(n) if args["Q"] is None else np.asarray(args["Q"], float)
    R = np.eye(m) if args["R"] is None else np.atleast_2d(np.asarray(args["R"], float))
    c = np.atleast_1d(np.asarray(args["weights"], float))
    return A, B, Q, R, c


def _sweep_singles(args: dict[str, Any], discrete: bool) -> list[Outcome]:
    A, B, Q, R, c = _sweep_problem(args)
    solver = aerocontrol.solve_dare if discrete else aerocontrol.solve_care
    return [single_outcome(solver, A, B, Q, R / (w * w)) for w in c]


def _sweep_oracle(discrete: bool) -> Any:
    name = "dlqr_sweep" if discrete else "lqr_sweep"

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        _, _, _, _, c = _sweep_problem(args)
        assert np.array_equal(result.weights, c), "weights not returned as given"
        singles = _sweep_singles(args, discrete)
        assert len(result) == len(singles)
        for i, single in enumerate(singles):
            assert single.error is None, f"weight {c[i]} fails alone ({single.error!r})"
            alone = single.result
            assert np.array_equal(result.K[i], alone.K), f"{name}: K at c = {c[i]}"
            assert np.array_equal(result.X[i], alone.X), f"{name}: X at c = {c[i]}"
            assert np.array_equal(result.poles[i], alone.closed_loop_poles), f"poles {c[i]}"
            assert result.residual[i] == alone.residual, f"{name}: residual at c = {c[i]}"
            assert result.rcond[i] == alone.rcond, (
                f"{name}: rcond at c = {c[i]} is {result.rcond[i]}, alone {alone.rcond}"
            )
        _assert_warning(name, warned, singles)

    return oracle


WEIGHTS = (
    np.geomspace(1e-2, 10.0, 4),
    np.array([1.0]),
    np.array([]),
    np.array([1e-150, 1e150]),
    np.array([1.0, -1.0]),
    np.array([0.0]),
    np.array([1.0, np.inf]),
    np.ones((2, 2)),
)


@given(st.data())
def test_sweeps(data: st.DataObject) -> None:
    discrete = data.draw(st.booleans())
    name = "dlqr_sweep" if discrete else "lqr_sweep"
    function = batch.dlqr_sweep if discrete else batch.lqr_sweep
    problem = data.draw(riccati_problem(cross=False, descriptor_matrix=False))
    A, B, Q, R = (problem[k] for k in "ABQR")
    n, m = B.shape
    arguments: dict[str, Arg] = {}
    form = data.draw(st.sampled_from(("matrices", "system")))
    if form == "system":
        arguments["sys"] = data.draw(
            presented_system((A, B, np.eye(n), np.zeros((n, m))), container="attributes")
        )

        def call(sys: Any, Q: Any, R: Any, weights: Any) -> Any:
            return function(sys, Q=Q, R=R, weights=weights)

    else:
        arguments["sys_or_A"], arguments["B"] = data.draw(presented(A)), data.draw(presented(B))
        call = function  # type: ignore[assignment]
    arguments["Q"] = plain(None) if data.draw(st.booleans()) else data.draw(presented(Q))
    arguments["R"] = plain(None) if data.draw(st.booleans()) else data.draw(presented(R))
    arguments["weights"] = data.draw(presented(data.draw(st.sampled_from(WEIGHTS))))
    oracle = _sweep_oracle(discrete)
    outcome = exercise(f"batch.{name}", call, arguments, oracle)
    values = {key: arg.canonical for key, arg in arguments.items()}
    result = outcome.result
    if result is not None and np.shares_memory(result.weights, arguments["weights"].value):
        # Counted as the known defect sweep-weights-alias, which stops the harness before
        # the oracle: the oracle still checks the result.
        try:
            oracle(result, values, outcome.warned)
        except AssertionError as failure:
            if _known_defect(f"batch.{name}", arguments, str(failure)) is None:
                raise
    if outcome.error is None or any(arg.expect != SAME for arg in arguments.values()):
        return
    c = np.atleast_1d(np.asarray(values["weights"], float))
    if _finite_stacks(values) and c.ndim == 1 and np.all(c > 0) and finite(c):
        try:
            singles = _sweep_singles(values, discrete)
        except (ValueError, IndexError):
            return  # shapes the sweep refuses before solving
        failure_check(f"batch.{name}", outcome, values, singles)


# ----- known defects of the core (see known_defects.py) ------------------------------------------


def test_regression_batch_refuses_indefinite_r() -> None:
    A, B, Q, R = np.array([[-5.0]]), np.array([[1.0]]), np.array([[1.0]]), np.array([[-1.0]])
    values = {"A": A, "B": B, "Q": Q, "R": R}
    outcome = exercise(
        "batch.solve_care_batch",
        batch.solve_care_batch,
        {key: canonical(value) for key, value in values.items()},
        _riccati_batch_oracle(False),
    )
    if outcome.error is not None:
        failure_check("batch.solve_care_batch", outcome, values, _riccati_singles(values, False))


def test_regression_batch_empty_rcond() -> None:
    exercise(
        "batch.solve_care_batch",
        batch.solve_care_batch,
        {
            "A": canonical(np.zeros((0, 0))),
            "B": canonical(np.zeros((0, 2))),
            "Q": canonical(np.zeros((0, 0))),
            "R": canonical(np.eye(2)),
        },
        _riccati_batch_oracle(False),
    )


def test_regression_sweep_weights_alias() -> None:
    A, B = aerocontrol.chapter.boeing747_lateral()
    exercise(
        "batch.lqr_sweep",
        batch.lqr_sweep,
        {
            "sys_or_A": canonical(A),
            "B": canonical(B),
            "Q": plain(None),
            "R": plain(None),
            "weights": canonical(np.array([1.0, 2.0])),
        },
        _sweep_oracle(False),
    )


def test_regression_sweep_weight_overflow() -> None:
    exercise(
        "batch.lqr_sweep",
        batch.lqr_sweep,
        {
            "sys_or_A": canonical(np.array([[-1.0]])),
            "B": canonical(np.eye(1)),
            "Q": plain(None),
            "R": canonical(np.array([[1e10]])),
            "weights": plain([1e-150]),
        },
        _sweep_oracle(False),
    )
