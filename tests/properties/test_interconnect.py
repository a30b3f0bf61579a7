"""Properties of the interconnections and elements (aerocontrol.interconnect, and the signal
selection ``StateSpace.__getitem__``).

Oracles: every interconnection against the products of its parts' own frequency responses,
at a few points s = jω where no resolvent is near singular (oracles.response_at): series
G2 G1, parallel G1 + G2, append diag(G1, G2), feedback G1 (I - sign G2 G1)^-1, connect by name
against the same diagrams formed by position. The tolerance is SLACK n u times the size of the
terms (||C R|| ||R B|| ||A|| + ... for each model, R the resolvent) and, for a loop, times the
condition numbers of the loop matrices I - sign D2 D1 (the realisation) and I - sign G2 G1(s)
(the reference). The elements against their closed forms (washout, lag, actuator, second
order), pade_delay against python-control's ``pade`` coefficients, tf and zpk against
python-control's ``tf`` and ``zpk`` evaluated at s, with the conditioning of the polynomials
(sum |c_k| |s|^k / |p(s)|) or of the factors in the tolerance.
"""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import control
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol

from .harness import SAME, Arg, Warned, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U,
    assert_response,
    condition,
    norm,
    quietly,
    response_at,
    silenced,
)
from .strategies import (
    SQUARE_KINDS,
    model_matrices,
    orders,
    present,
    presented,
    presented_system,
    scalar,
    system,
)

COVERED = {
    "series",
    "parallel",
    "feedback",
    "append",
    "connect",
    "summing_junction",
    "washout",
    "first_order_lag",
    "actuator",
    "second_order",
    "pade_delay",
    "gain",
    "tf",
    "zpk",
    "StateSpace",
}

#: Plants whose frequency responses are mostly comparable; the others now and then.
TAME = ("stable", "gaussian", "integers", "companion", "diagonal", "imaginary axis")
#: The points s = jω of the comparisons.
POINTS = (0.31j, 1.7j, 11.0j)


@st.composite
def model(draw: st.DrawFn, m: int, p: int, n: int | None = None) -> Arg:
    """A model (tuple or attributes) with m inputs and p outputs, its matrices presented."""
    n = draw(st.sampled_from((0, 1, 2, 3, 4, 2, 3, 6))) if n is None else n
    kinds = draw(st.sampled_from((TAME, TAME, TAME, SQUARE_KINDS)))
    return draw(presented_system(draw(system(n, m, p, kinds))))


def parts(args: dict[str, Any], *keys: str) -> list[tuple[np.ndarray, ...]]:
    return [model_matrices(args[key]) for key in keys]


def sizes(*matrices: np.ndarray) -> float:
    return sum(norm(M) for M in matrices)


def _check_points(result: Any, expected: Any, allowed: Any, what: str) -> None:
    """At each point of POINTS where every part's response exists: the result's response
    against expected(s) within allowed(s)."""
    for s in POINTS:
        value = expected(s)
        if value is None:
            continue
        reference, tolerance = value
        assert_response(result, reference, s, tolerance(), what)


# ----- series, parallel, append ---------------------------------------------------------------


def _series_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    (A1, B1, C1, D1), (A2, B2, C2, D2) = parts(args, "sys1", "sys2")
    n1, n2 = A1.shape[0], A2.shape[0]
    assert result.A.shape == (n1 + n2, n1 + n2)
    assert (result.n_inputs, result.n_outputs) == (B1.shape[1], C2.shape[0])
    first = aerocontrol.as_state_space(args["sys1"])
    second = aerocontrol.as_state_space(args["sys2"])
    assert result.input_names == first.input_names
    assert result.output_names == second.output_names
    assert result.state_names == first.state_names + second.state_names
    with silenced():
        products = norm(B2) * norm(C1) + norm(B2) * norm(D1) + norm(D2) * norm(C1)
        ratio = max(1.0, (products + norm(D2) * norm(D1)) / (sizes(*result_matrices(result)) or 1))

    def expected(s: complex) -> Any:
        g1, g2 = response_at(A1, B1, C1, D1, s), response_at(A2, B2, C2, D2, s)
        own = response_at(*result_matrices(result), s)
        if g1 is None or g2 is None or own is None:
            return None
        (G1, e1), (G2, e2) = g1, g2
        n = max(n1 + n2, 1)

        def tolerance() -> float:
            return SLACK * n * U * (e2 * norm(G1) + norm(G2) * e1 + own[1] * ratio) + TINY

        return G2 @ G1, tolerance

    _check_points(result, expected, None, "series: G2 G1")


def result_matrices(result: Any) -> tuple[np.ndarray, ...]:
    return result.A, result.B, result.C, result.D


def _shapes(data: st.DataObject) -> tuple[int, int, int]:
    return data.draw(st.integers(0, 2)), data.draw(st.integers(1, 2)), data.draw(st.integers(0, 2))


@given(st.data())
def test_series(data: st.DataObject) -> None:
    m, p1, p2 = _shapes(data)
    inputs2 = p1 if data.draw(st.sampled_from((True,) * 7 + (False,))) else p1 + 1
    arguments = {"sys1": data.draw(model(m, p1)), "sys2": data.draw(model(inputs2, p2))}
    exercise(
        "series",
        lambda sys1, sys2: aerocontrol.series(sys1, sys2),
        arguments,
        _series_oracle,
    )


def _parallel_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    (A1, B1, C1, D1), (A2, B2, C2, D2) = parts(args, "sys1", "sys2")
    assert result.A.shape[0] == A1.shape[0] + A2.shape[0]
    assert result.input_names == aerocontrol.as_state_space(args["sys1"]).input_names

    def expected(s: complex) -> Any:
        g1, g2 = response_at(A1, B1, C1, D1, s), response_at(A2, B2, C2, D2, s)
        if g1 is None or g2 is None:
            return None
        n = max(result.A.shape[0], 1)
        return g1[0] + g2[0], lambda: SLACK * n * U * (g1[1] + g2[1]) + TINY

    _check_points(result, expected, None, "parallel: G1 + G2")


@given(st.data())
def test_parallel(data: st.DataObject) -> None:
    m, p, _ = _shapes(data)
    other = (m, p) if data.draw(st.sampled_from((True,) * 7 + (False,))) else (m + 1, p)
    arguments = {"sys1": data.draw(model(m, p)), "sys2": data.draw(model(*other))}
    exercise(
        "parallel",
        lambda sys1, sys2: aerocontrol.parallel(sys1, sys2),
        arguments,
        _parallel_oracle,
    )


def _append_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    models = [model_matrices(args[key]) for key in sorted(args)]
    m = sum(M[1].shape[1] for M in models)
    p = sum(M[2].shape[0] for M in models)
    assert (result.n_inputs, result.n_outputs) == (m, p)

    def expected(s: complex) -> Any:
        responses = [response_at(*M, s) for M in models]
        if any(r is None for r in responses):
            return None
        G = np.zeros((p, m), dtype=complex)
        i = j = 0
        for Gk, _ in responses:  # type: ignore[misc]
            G[i : i + Gk.shape[0], j : j + Gk.shape[1]] = Gk
            i, j = i + Gk.shape[0], j + Gk.shape[1]
        n = max(result.A.shape[0], 1)
        return G, lambda: SLACK * n * U * sum(r[1] for r in responses) + TINY  # type: ignore[index]

    _check_points(result, expected, None, "append: diag(G1, G2, ...)")


@given(st.data())
def test_append(data: st.DataObject) -> None:
    count = data.draw(st.integers(1, 3))
    arguments = {
        f"sys{k}": data.draw(model(data.draw(st.integers(0, 2)), data.draw(st.integers(0, 2))))
        for k in range(count)
    }
    exercise(
        "append", lambda **systems: aerocontrol.append(*systems.values()), arguments, _append_oracle
    )


# ----- feedback -------------------------------------------------------------------------------


def _feedback_reference(
    A1: np.ndarray,
    B1: np.ndarray,
    C1: np.ndarray,
    D1: np.ndarray,
    back: tuple[np.ndarray, ...],
    sign: float,
    result: Any,
    ratio: float,
) -> Any:
    A2, B2, C2, D2 = back

    def expected(s: complex) -> Any:
        g1, g2 = response_at(A1, B1, C1, D1, s), response_at(A2, B2, C2, D2, s)
        own = response_at(*result_matrices(result), s)
        if g1 is None or g2 is None or own is None:
            return None
        (G1, e1), (G2, e2) = g1, g2
        with silenced():
            F = np.eye(G1.shape[1]) - sign * G2 @ G1
            kappa = condition(F)
            if not np.isfinite(kappa) or kappa * U > 1e-6:
                return None
            Y = G1 @ np.linalg.inv(F)
            loop = e2 * norm(G1) + norm(G2) * e1
            n = max(result.A.shape[0], 1)
            bound = (
                SLACK
                * n
                * U
                * (
                    kappa * (e1 + norm(Y) * loop) * max(1.0, norm(np.linalg.inv(F)))
                    + own[1] * ratio
                )
            )
        return Y, lambda: bound + TINY

    return expected


def _feedback_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    sign = float(args["sign"])
    A1, B1, C1, D1 = model_matrices(args["sys1"])
    m1 = B1.shape[1]
    if args["sys2"] is None:
        back = (np.zeros((0, 0)), np.zeros((0, m1)), np.zeros((m1, 0)), np.eye(m1))
    else:
        back = model_matrices(args["sys2"])
    forward = aerocontrol.as_state_space(args["sys1"])
    assert result.input_names == forward.input_names
    assert result.output_names == forward.output_names
    assert result.A.shape[0] == A1.shape[0] + back[0].shape[0]
    D2 = back[3]
    with silenced():
        loop = sign * D2 @ D1
        kappa0 = (1 + norm(loop)) * norm(np.linalg.inv(np.eye(m1) - loop)) if m1 else 1.0
        terms = sizes(A1, B1, C1, D1) + sizes(*back)
        ratio = max(1.0, kappa0) * max(
            1.0, np.float64(terms) ** 2 / (sizes(*result_matrices(result)) or 1)
        )
    reference = _feedback_reference(A1, B1, C1, D1, back, sign, result, ratio)
    _check_points(result, reference, None, "feedback: G1 (I - sign G2 G1)^-1")


SIGNS = (-1, -1, -1.0, 1, 1.0, np.float32(-1.0), 0.5, 0, True, "-1", np.nan, 1j)


@given(st.data())
def test_feedback(data: st.DataObject) -> None:
    m, p = data.draw(st.integers(1, 2)), data.draw(st.integers(1, 2))
    unity = data.draw(st.sampled_from((False, False, True)))
    if unity:
        p = m if data.draw(st.sampled_from((True,) * 7 + (False,))) else m + 1
    sign = data.draw(st.sampled_from(SIGNS))
    arguments = {
        "sys1": data.draw(model(m, p)),
        "sys2": plain(None) if unity else data.draw(model(p, m)),
        "sign": plain(sign),
    }
    outcome = exercise(
        "feedback",
        lambda sys1, sys2, sign: aerocontrol.feedback(sys1, sys2, sign),
        arguments,
        _feedback_oracle if sign in (-1, 1) and not isinstance(sign, bool) else None,
    )
    if isinstance(sign, bool) or sign not in (-1, 1):
        assert outcome.error is not None, f"feedback accepted sign = {sign!r}"


# ----- connect and summing_junction -----------------------------------------------------------


def _named(arg: Arg, inputs: list[str], outputs: list[str]) -> Arg:
    """The model as a python-control-like object with signal labels."""

    def label(value: Any) -> Any:
        if value is None:
            return None
        A, B, C, D = value if isinstance(value, tuple) else (value.A, value.B, value.C, value.D)
        return SimpleNamespace(A=A, B=B, C=C, D=D, input_labels=inputs, output_labels=outputs)

    return Arg(label(arg.value), label(arg.canonical), arg.label + " labelled", arg.expect)


def _connect_oracle(form: str) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        plant = model_matrices(args["plant"])
        other = model_matrices(args["other"])
        if form == "series":
            assert result.input_names == ("r",) and result.output_names == ("y",)
            expected = quietly(aerocontrol.series, args["plant"], args["other"])
            sizes_of_parts = sizes(*plant) + sizes(*other)
        else:  # unity negative feedback around plant -> other
            assert result.input_names == ("r",) and result.output_names == ("z",)
            expected = quietly(aerocontrol.feedback, aerocontrol.series(plant, other))
            sizes_of_parts = sizes(*plant) + sizes(*other)
        with silenced():
            ratio = max(
                1.0, np.float64(sizes_of_parts) ** 2 / (sizes(*result_matrices(result)) or 1)
            )
            D = quietly(aerocontrol.series, args["plant"], args["other"]).D
            kappa0 = (1 + norm(D)) * norm(np.linalg.inv(np.eye(D.shape[0]) + D))
            ratio *= max(1.0, kappa0) if form != "series" else 1.0
        for s in POINTS:
            reference = response_at(*result_matrices(expected), s)
            if reference is None:
                continue
            n = max(result.A.shape[0], 1)
            with silenced():
                allowed = SLACK * n * U * reference[1] * ratio + TINY
            assert_response(
                result,
                reference[0],
                s,
                allowed,
                f"connect ({form}) against the same diagram by position",
            )

    return oracle


@given(st.data())
def test_connect(data: st.DataObject) -> None:
    """Two diagrams by name: r -> plant -> e -> other -> y (a series), and the loop
    e = r - z, z = other(plant(e)) closed through a summing junction."""
    form = data.draw(st.sampled_from(("series", "loop")))
    plant = _named(data.draw(model(1, 1)), ["e" if form == "loop" else "r"], ["v"])
    other = _named(data.draw(model(1, 1)), ["v"], ["y" if form == "series" else "z"])
    arguments = {"plant": plant, "other": other}
    if form == "series":

        def call(plant: Any, other: Any) -> Any:
            return aerocontrol.connect([plant, other], inputs="r", outputs="y")
    else:

        def call(plant: Any, other: Any) -> Any:
            junction = aerocontrol.summing_junction(["r", "-z"], "e")
            return aerocontrol.connect([junction, plant, other], inputs="r", outputs="z")

    exercise("connect", call, arguments, _connect_oracle(form))


NAME_SETS = (
    ["a", "-b"],
    "a",
    ["-a", "-b", "c"],
    [],
    ["a", ""],
    ["-"],
    ["a", 3],
    ("x", "-y"),
)


@given(st.data())
def test_summing_junction(data: st.DataObject) -> None:
    inputs = data.draw(st.sampled_from(NAME_SETS))
    output = data.draw(st.sampled_from(("e", "e", 7, None)))
    dt = data.draw(st.sampled_from((None, None, 0.1, -1.0)))

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        specs = [inputs] if isinstance(inputs, str) else list(inputs)
        assert result.input_names == tuple(s.lstrip("-") for s in specs)
        assert result.output_names == (output,)
        expected = [[-1.0 if s.startswith("-") else 1.0 for s in specs]]
        assert np.array_equal(result.D, np.array(expected)) and result.n_states == 0

    exercise(
        "summing_junction",
        lambda inputs, output, dt: aerocontrol.summing_junction(inputs, output, dt=dt),
        {"inputs": plain(inputs), "output": plain(output), "dt": plain(dt)},
        oracle,
    )


# ----- StateSpace.__getitem__ -----------------------------------------------------------------

KEYS = (0, -1, 1, 5, slice(None), slice(None, None, -1), [0], [0, 0], "y0", "u0", "nope", 1.0, None)


@given(st.data())
def test_signal_selection(data: st.DataObject) -> None:
    n = data.draw(orders())
    m, p = data.draw(st.integers(1, 3)), data.draw(st.integers(1, 3))
    A, B, C, D = data.draw(system(n, m, p))
    rows, columns = data.draw(st.sampled_from(KEYS)), data.draw(st.sampled_from(KEYS))

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        def indices(key: Any, count: int, prefix: str) -> list[int]:
            names = [f"{prefix}{k}" for k in range(count)]
            if isinstance(key, str):
                return [names.index(key)]
            if isinstance(key, slice):
                return list(range(count))[key]
            if isinstance(key, list):
                return [k % count for k in key]
            return [int(key) % count]

        i, j = indices(rows, p, "y"), indices(columns, m, "u")
        A0, B0, C0, D0 = (np.asarray(args[k], float) for k in "ABCD")
        assert np.array_equal(result.A, A0)
        assert np.array_equal(result.B, B0[:, j]) and np.array_equal(result.C, C0[i, :])
        assert np.array_equal(result.D, D0[np.ix_(i, j)])
        assert result.input_names == tuple(f"u{k}" for k in j)
        assert result.output_names == tuple(f"y{k}" for k in i)

    def call(A: Any, B: Any, C: Any, D: Any) -> Any:
        return aerocontrol.StateSpace(A, B, C, D)[rows, columns]

    arguments = {key: data.draw(presented(M)) for key, M in zip("ABCD", (A, B, C, D), strict=True)}
    outcome = exercise("StateSpace", call, arguments, oracle)
    if isinstance(rows, float) or rows is None or rows == "nope" or (rows == 5 and p <= 5):
        assert outcome.error is not None, f"sys[{rows!r}, ...] was accepted"


# ----- elements -------------------------------------------------------------------------------

VALUES = (0.5, 2.0, 0.05, 30.0, 1.0, 1e-3, 1e3, 0.0, -1.0, 1e-300, 1e300, np.nan, np.inf)


def _closed_form(name: str, values: dict[str, float], s: complex) -> tuple[complex, float]:
    """(G(s), the size of its terms) of an element, from its definition."""
    if name == "washout":
        tau = values["tau"]
        return tau * s / (tau * s + 1), abs(tau * s) * (abs(tau * s) + 1) / abs(tau * s + 1) ** 2
    if name == "first_order_lag":
        tau, k = values["tau"], values["gain"]
        return k / (tau * s + 1), abs(k) * (abs(tau * s) + 1) / abs(tau * s + 1) ** 2
    if name == "actuator":
        w = values["bandwidth"]
        return w / (s + w), w * (abs(s) + w) / abs(s + w) ** 2
    w, z = values["omega_n"], values["zeta"]
    den = s * s + 2 * z * w * s + w * w
    return w * w / den, w * w * (abs(s) ** 2 + 2 * abs(z) * w * abs(s) + w * w) / abs(den) ** 2


ELEMENTS = {
    "washout": ("tau",),
    "first_order_lag": ("tau", "gain"),
    "actuator": ("bandwidth",),
    "second_order": ("omega_n", "zeta"),
}


def _element_oracle(name: str) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        values = {key: float(value) for key, value in args.items() if key in ELEMENTS[name]}
        assert (result.n_inputs, result.n_outputs) == (1, 1)
        assert result.input_names == (args.get("input_names") or "u0",) or isinstance(
            args.get("input_names"), list
        )
        scale = max(values[ELEMENTS[name][0]], 1.0 / values[ELEMENTS[name][0]])
        for s in (*POINTS, 0.0, 1j * scale):
            try:
                with silenced():
                    G, size = _closed_form(name, values, s)
            except (OverflowError, ZeroDivisionError):
                continue  # the closed form itself leaves the range of doubles
            if not (np.isfinite(G) and np.isfinite(size)):
                continue
            assert_response(
                result,
                np.array([[G]]),
                s,
                SLACK * 4 * U * size + TINY,
                f"{name} against its closed form",
            )

    return oracle


@given(st.data())
def test_elements(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(sorted(ELEMENTS)))
    arguments: dict[str, Arg] = {}
    for key in ELEMENTS[name]:
        value = data.draw(st.sampled_from(VALUES if key != "zeta" else (0.7, 0.0, 0.1, 2.0, -0.1)))
        arguments[key] = data.draw(scalar(value))
    names = data.draw(st.sampled_from((None, "in", ["in"], ["in", "extra"], 3)))
    arguments["input_names"] = plain(names)
    function = getattr(aerocontrol, name)
    keys = ELEMENTS[name]

    def call(**kwargs: Any) -> Any:
        first = kwargs.pop(keys[0])
        if name == "second_order":
            return function(first, kwargs.pop("zeta"), **kwargs)
        return function(first, **kwargs)

    outcome = exercise(name, call, arguments, _element_oracle(name))
    first = arguments[keys[0]].canonical
    if first is not None and not first > 0:
        assert outcome.error is not None, f"{name} accepted {keys[0]} = {first}"


def _pade_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    T, order = float(args["T"]), int(args["order"])
    num, den = control.pade(T, order)
    assert result.n_states == order
    for s in (*POINTS, 1j / T, 3j / T):
        with silenced():
            N, Dn = np.polyval(num, s), np.polyval(den, s)
            powers = np.abs(s) ** np.arange(len(den))[::-1]
            size = abs(N / Dn) * (
                np.dot(np.abs(num), powers) / abs(N) + np.dot(np.abs(den), powers) / abs(Dn)
            )
        if not (np.isfinite(size) and size < 1e12):
            continue
        assert_response(
            result,
            np.array([[N / Dn]]),
            s,
            SLACK * order * U * size + TINY,
            "pade against control.pade",
        )


@given(st.data())
def test_pade_delay(data: st.DataObject) -> None:
    T = data.draw(st.sampled_from((0.1, 0.3, 1.0, 2.5, 1e-3, 0.0, -0.2, np.inf)))
    order = data.draw(st.sampled_from((1, 2, 3, 5, 8, 0, 21, 2.0, True, np.int32(4))))
    outcome = exercise(
        "pade_delay",
        lambda T, order: aerocontrol.pade_delay(T, order),
        {"T": data.draw(scalar(T)), "order": plain(order)},
        _pade_oracle
        if isinstance(order, (int, np.integer)) and not isinstance(order, bool)
        else None,
    )
    if isinstance(order, (bool, float)) or not 1 <= order <= 20:
        assert outcome.error is not None, f"pade_delay accepted order {order!r}"


@given(st.data())
def test_gain(data: st.DataObject) -> None:
    shape = data.draw(st.sampled_from(((), (1, 1), (2, 3), (0, 2), (3,))))
    K = data.draw(st.sampled_from((-1.5, 0.0, 2.0, np.nan))) * np.ones(shape)
    if len(shape) == 2 and K.size:
        K = K + np.arange(K.size).reshape(shape)
    argument = data.draw(presented(K)) if shape else data.draw(scalar(float(K)))

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        expected = np.asarray(args["K"], float)
        expected = expected.reshape(1, 1) if expected.ndim == 0 else expected
        assert np.array_equal(result.D, expected) and result.n_states == 0

    outcome = exercise("gain", lambda K: aerocontrol.gain(K), {"K": argument}, oracle)
    if shape == (3,):
        assert outcome.error is not None, "gain accepted a 1-D K"


# ----- tf and zpk -----------------------------------------------------------------------------


def _polynomial_size(c: np.ndarray, s: complex) -> float:
    return float(np.dot(np.abs(c), np.abs(s) ** np.arange(len(c))[::-1])) if len(c) else 0.0


def _tf_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    num = np.trim_zeros(np.atleast_1d(np.asarray(args["num"], float)), "f")
    den = np.trim_zeros(np.atleast_1d(np.asarray(args["den"], float)), "f")
    assert result.n_states == len(den) - 1
    reference = control.tf(num if len(num) else [0.0], den)
    for s in POINTS:
        with silenced():
            G = complex(reference(s))
            Dn = np.polyval(den, s)
            size = _polynomial_size(num, s) / abs(Dn) + abs(G) * _polynomial_size(den, s) / abs(Dn)
        if not (np.isfinite(size) and np.isfinite(G)) or size * U > 1e-6:
            continue
        n = max(len(den), 1)
        assert_response(result, np.array([[G]]), s, SLACK * n * U * size + TINY, "tf")


@st.composite
def roots(draw: st.DrawFn, count: int) -> np.ndarray:
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    values = (-rng.uniform(0.1, 5.0, count)).astype(complex)
    for k in range(0, count - 1, 2):
        if draw(st.booleans()):
            values[k] = complex(values[k].real, rng.uniform(0.1, 4.0))
            values[k + 1] = values[k].conjugate()
    kind = draw(st.sampled_from(("plain", "plain", "repeated", "origin", "unpaired", "nan")))
    if kind == "repeated" and count:
        values[:] = values[0].real
    elif kind == "origin" and count:
        values[0] = 0.0
    elif kind == "unpaired" and count:
        values[0] = complex(values[0].real, 1.0)
    elif kind == "nan" and count:
        values[-1] = np.nan
    return values


def _zpk_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    z, p, k = np.asarray(args["z"], complex), np.asarray(args["p"], complex), float(args["k"])
    assert result.n_states == p.size
    reference = control.zpk(z, p, k)
    for s in POINTS:
        with silenced():
            G = complex(reference(s))
            # each factor (s - r) evaluated to u (|s| + |r|), a pair's quadratic to
            # u (|s|^2 + 2 |Re r| |s| + |r|^2)
            relative = sum((abs(s) + abs(r)) / abs(s - r) for r in np.concatenate([z, p]))
        if not (np.isfinite(G) and np.isfinite(relative)) or relative * U > 1e-6:
            continue
        n = max(p.size, 1)
        assert_response(
            result, np.array([[G]]), s, SLACK * n * U * abs(G) * (1 + relative) + TINY, "zpk"
        )


@given(st.data())
def test_tf_and_zpk(data: st.DataObject) -> None:
    degree = data.draw(st.sampled_from((0, 1, 2, 3, 4, 6)))
    zeros = data.draw(st.integers(0, degree + data.draw(st.sampled_from((0,) * 7 + (1,)))))
    if data.draw(st.booleans()):
        den = np.atleast_1d(np.real(np.poly(data.draw(roots(degree))))) * data.draw(
            st.sampled_from((1.0, 3.0, -0.5))
        )
        num = np.real(np.poly(data.draw(roots(zeros)))) * 2.0 if zeros else np.array([2.0])
        if data.draw(st.sampled_from((False,) * 5 + (True,))):
            num = np.concatenate([[0.0], num])  # a leading zero, dropped
        if data.draw(st.sampled_from((False,) * 7 + (True,))):
            den = np.zeros(degree + 1)
        exercise(
            "tf",
            lambda num, den: aerocontrol.tf(num, den),
            {"num": data.draw(presented(num)), "den": data.draw(presented(den))},
            _tf_oracle,
        )
        return
    z, p = data.draw(roots(zeros)), data.draw(roots(degree))
    k = data.draw(st.sampled_from((1.0, -2.5, 0.0, 1e3, np.nan)))

    def as_arg(r: np.ndarray) -> Arg:
        how = data.draw(st.sampled_from(("array", "list", "real")))
        if how == "list":
            return Arg(r.tolist(), r.copy(), how, SAME)
        if how == "real" and np.all(r.imag == 0):
            return Arg(r.real.copy(), r.real.copy(), how, SAME)
        return Arg(r.copy(), r.copy(), "array", SAME)

    exercise(
        "zpk",
        lambda z, p, k: aerocontrol.zpk(z, p, k),
        {"z": as_arg(z), "p": as_arg(p), "k": data.draw(scalar(k))},
        _zpk_oracle,
    )


def test_feedback_of_a_unit_gain_is_an_algebraic_loop() -> None:
    outcome = exercise(
        "feedback",
        lambda sys1, sign: aerocontrol.feedback(sys1, sign=sign),
        {
            "sys1": plain((np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.eye(1))),
            "sign": plain(1),
        },
    )
    assert isinstance(outcome.error, aerocontrol.SingularMatrixError)


# ----- known defects of the core (see known_defects.py) ------------------------------------------


@pytest.mark.parametrize("function", ["series", "feedback"])
def test_regression_interconnect_overflow(function: str) -> None:
    """B2 C1 = 1e400 overflows, but the interconnection exists in doubles once the states are
    scaled: series 1e400/(s + 1)^2, feedback poles -1 ± 1e200 j."""
    first = (np.array([[-1.0]]), np.array([[1.0]]), np.array([[1e200]]), np.zeros((1, 1)))
    second = (np.array([[-1.0]]), np.array([[1e200]]), np.array([[1.0]]), np.zeros((1, 1)))
    outcome = exercise(
        function,
        lambda sys1, sys2: getattr(aerocontrol, function)(sys1, sys2),
        {"sys1": plain(first), "sys2": plain(second)},
    )
    result = outcome.result
    assert outcome.error is None and outcome.warned == ()
    poles = np.sort_complex(np.linalg.eigvals(result.A))
    if function == "series":
        assert np.array_equal(poles, [-1.0, -1.0])
        # the second Markov parameter C A B = 1e400 as a product of doubles of 1e133
        markov = [result.C[0, 1], (result.A[1, 0]), result.B[0, 0]]
        assert math.fsum(math.log10(abs(x)) for x in markov) == pytest.approx(400.0, abs=1e-12)
    else:
        assert np.allclose(poles, [-1.0 - 1e200j, -1.0 + 1e200j], rtol=1e-15)


def test_regression_names_not_iterable() -> None:
    exercise(
        "actuator",
        lambda bandwidth, input_names: aerocontrol.actuator(bandwidth, input_names=input_names),
        {"bandwidth": plain(1.0), "input_names": plain(3)},
    )


def test_regression_connect_loop_near_the_range() -> None:
    """b c = 1.3e307 in series, then unity feedback: representable as given, so formed as
    given (a rescaled series was left unbalanced for the feedback after it)."""
    part = (np.array([[-1.875]]), np.array([[0.1257]]), np.array([[1e308]]), np.zeros((1, 1)))
    plant = _named(plain(part), ["e"], ["v"])
    other = _named(plain(part), ["v"], ["z"])

    def call(plant: Any, other: Any) -> Any:
        junction = aerocontrol.summing_junction(["r", "-z"], "e")
        return aerocontrol.connect([junction, plant, other], inputs="r", outputs="z")

    exercise("connect", call, {"plant": plant, "other": other}, _connect_oracle("loop"))


#: The sixth-order blocks of two campaign inputs (Gaussian draws of the strategies).
_BLOCK_A = np.array(
    [
        [-3.3237595216897846, -0.1321048632913019, 0.6404226504432821, 0.10490011715303971,
         -0.535669373161111, 0.36159505490948474],
        [1.3040000451301372, -2.5024087796539356, -0.7037352358069926, -1.2654214710460525,
         -0.6232744625373522, 0.0413259793472436],
        [-2.3250307746388343, -0.21879166393254573, -4.695400690036243, -0.7322673547034516,
         -0.5442589828573099, -0.31630015636915454],
        [0.4116305363741328, 1.0425133694426776, -0.12853466294403426, -2.083026272233492,
         -0.6651946734866135, 0.3515100700930197],
        [0.9034701816518086, 0.09401229776087457, -0.7434992493538084, -0.9217253762584194,
         -3.907215568450517, 0.2201951234700494],
        [-1.009618183538736, -0.20917557487171307, -0.15922500991447772, 0.5408455846858077,
         0.2146591225063409, -3.0941170337432564],
    ]
)  # fmt: skip
_BLOCK_B = np.array(
    [[0.1257302210933933], [-0.1321048632913019], [0.6404226504432821], [0.10490011715303971],
     [-0.535669373161111], [0.36159505490948474]]
)  # fmt: skip
_BLOCK_C = np.array(
    [[3.4558419206478603e07, 8.2161814350115836e07, 3.3043707618338715e07,
      -1.3031572316043609e08, 9.0535586667311773e07, 4.4637457236401126e07]]
)  # fmt: skip
_BIG_BLOCK_A = np.array(
    [
        [-3.3237595216897845e08, -1.3210486329130189e07, 6.4042265044328205e07,
         1.0490011715303971e07, -5.3566937316111095e07, 3.6159505490948476e07],
        [1.3040000451301372e08, -2.5024087796539357e08, -7.0373523580699265e07,
         -1.2654214710460526e08, -6.2327446253735222e07, 4.1325979347243602e06],
        [-2.3250307746388343e08, -2.1879166393254574e07, -4.6954006900362426e08,
         -7.3226735470345154e07, -5.4425898285730988e07, -3.1630015636915453e07],
        [4.1163053637413286e07, 1.0425133694426776e08, -1.2853466294403426e07,
         -2.0830262722334921e08, -6.6519467348661356e07, 3.5151007009301968e07],
        [9.0347018165180862e07, 9.4012297760874573e06, -7.4349924935380846e07,
         -9.2172537625841945e07, -3.9072155684505171e08, 2.2019512347004943e07],
        [-1.0096181835387360e08, -2.0917557487171307e07, -1.5922500991447771e07,
         5.4084558468580768e07, 2.1465912250634089e07, -3.0941170337432563e08],
    ]
)  # fmt: skip
_BIG_BLOCK_C = np.array(
    [[3.9836996726397239e07, -5.6282333741752498e07, 5.8883494374844514e07,
      4.2118102942453157e06, -1.5709005193070567e08, 1.0016547499330197e08]]
)  # fmt: skip


@pytest.mark.parametrize("case", ["pole of 1e308", "block without input"])
def test_regression_connect_loop_balanced_state_by_state(case: str) -> None:
    """Two campaign inputs of the loop by name, whose oracle (feedback of the series) failed:
    a plant with A of 1e308 and B of 1.7e300 (the balancing of the series, each part on its
    own, overflowed its A_ii: a NonFiniteError), and one with B of -1.2e300 into a block
    with B = 0 and A, C of 1e8 (the closed loop's B C of 1.9e308, refused, though the block's
    states, which the plant does not reach, scale freely)."""
    c = np.array([[0.1257302210933933]])
    if case == "pole of 1e308":
        plant = (np.array([[1e308]]), np.array([[1.728162865989976e300]]), c)
        block = (_BLOCK_A, _BLOCK_B, _BLOCK_C)
    else:
        plant = (np.array([[-1.8742697789066067]]), np.array([[-1.2316649689147774e300]]), c)
        block = (_BIG_BLOCK_A, np.zeros((6, 1)), _BIG_BLOCK_C)
    zero = np.zeros((1, 1))
    arguments = {
        "plant": _named(plain((*plant, zero)), ["e"], ["v"]),
        "other": _named(plain((*block, zero)), ["v"], ["z"]),
    }

    def call(plant: Any, other: Any) -> Any:
        junction = aerocontrol.summing_junction(["r", "-z"], "e")
        return aerocontrol.connect([junction, plant, other], inputs="r", outputs="z")

    outcome = exercise("connect", call, arguments, _connect_oracle("loop"))
    assert outcome.error is None and outcome.warned == ()


def test_regression_series_product_that_underflows() -> None:
    """A campaign input: D2 C1 = 5e-324 x 0.126 underflowed to 0, and the series was the zero
    model where G2 G1 is 4e-176."""
    lag = (np.array([[-1.8742697789066067]]), np.array([[1.257302210933933e149]]))
    lag += (np.array([[0.1257302210933933]]), np.zeros((1, 1)))
    tiny = (np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[5e-324]]))
    outcome = exercise(
        "series",
        lambda sys1, sys2: aerocontrol.series(sys1, sys2),
        {"sys1": plain(lag), "sys2": plain(tiny)},
        _series_oracle,
    )
    assert outcome.error is None and outcome.warned == ()


def test_regression_zero_strides_keep_the_sign_of_zero() -> None:
    """The "zero strides" presentation took a matrix whose rows differ only in the sign of a
    zero (np.array_equal: -0.0 == 0.0) for a broadcast of its first row, so the presented
    matrix held +0.0 where the canonical one held -0.0, and append and parallel, which keep
    the entries bitwise, failed their comparison with the canonical call."""
    signed = np.array([[0.0, 1.0], [-0.0, 1.0]])
    arg = present(signed, "zero strides")
    assert np.array(arg.value).tobytes() == arg.canonical.tobytes()
    # Rows that are bitwise equal are still presented as a view with stride 0.
    same = present(np.array([[-0.0, 1.0], [-0.0, 1.0]]), "zero strides")
    assert same.value.strides[0] == 0
    assert np.array(same.value).tobytes() == same.canonical.tobytes()
    # The campaign's failure: B = [[0], [-0]] of a model appended and added in parallel.
    A, C, D = np.diag([-1.0, -2.0]), np.array([[1.0, 1.0]]), np.zeros((1, 1))
    B = present(np.array([[0.0], [-0.0]]), "zero strides")
    model = Arg((A, B.value, C, D), (A, B.canonical, C, D), "tuple of (C, zero strides, C, C)")
    exercise("append", lambda **systems: aerocontrol.append(*systems.values()), {"sys0": model})
    exercise(
        "parallel",
        lambda sys1, sys2: aerocontrol.parallel(sys1, sys2),
        {"sys1": model, "sys2": model},
    )
