"""Properties of state estimation (aerocontrol.estimation): lqe, dlqe, kalman, place_observer
and lqg.

Oracles: duality, bitwise: the filter of (A, G, C, QN, RN, NN) is the regulator of
(A^T, C^T) with the weights G QN G^T (symmetrised as the documentation says) and RN and the
cross weight G NN, L = K^T (lqr, dlqr); the observer is place's gain for (A^T, C^T),
transposed. Independently, the filter's Riccati solution passes the oracle of a Riccati
solution (test_riccati.assert_riccati_solution: residual in long double, symmetric P, the
gain's equation, the estimator A - L C stable by its sensitivity, scipy within the forward
error bound); the discrete filter's two gains by their equations (M (C P C^T + RN) = P C^T,
L = A M without NN, within κ(C P C^T + RN) u); the estimator's matrices by their definition;
the observer's poles by the warning's contract; the LQG closed loop's matrix by its block
definition and every eigenvalue stable by its sensitivity, its parts the lqr and lqe designs
bitwise.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import IllConditionedWarning
from aerocontrol.placement import POLE_ERROR_WARNING

from .harness import SAME, Arg, Warned, exercise, plain
from .oracles import SLACK, TINY, U, assert_stable, condition, finite, norm, quietly, silenced
from .strategies import (
    canonical,
    model_matrices,
    presented,
    presented_system,
    rectangular,
    riccati_problem,
    symmetric_weight,
)
from .test_riccati import assert_riccati_solution

COVERED = {"lqe", "dlqe", "kalman", "place_observer", "lqg"}

Problem = dict[str, Any]


@st.composite
def noise_problem(draw: st.DrawFn) -> Problem:
    """(A, B, G, C, D, QN, RN, NN): the dual of a Riccati problem (A = A_r^T, C = B_r^T,
    RN = R_r, and G = I with QN = Q_r and NN = S_r, or a drawn G with its own QN and NN)."""
    dual = draw(riccati_problem(descriptor_matrix=False))
    A = dual["A"].T.copy()
    C = dual["B"].T.copy()
    n, p = A.shape[0], C.shape[0]
    if draw(st.booleans()):
        G, QN, NN = np.eye(n), dual["Q"], dual["S"]
    else:
        g = draw(st.integers(1, 3))
        G = draw(rectangular(n, g))
        QN = draw(symmetric_weight(g))
        NN = None
        if draw(st.sampled_from((False, False, True))):
            NN = 0.1 * draw(rectangular(g, p, ("gaussian", "zero")))
    m = draw(st.integers(1, 2))
    B = draw(rectangular(n, m, ("gaussian", "integers", "zero")))
    D = draw(rectangular(p, m, ("zero", "zero", "gaussian")))
    return {"A": A, "B": B, "G": G, "C": C, "D": D, "QN": QN, "RN": dual["R"], "NN": NN}


def process_weights(problem: Problem) -> tuple[np.ndarray, np.ndarray | None]:
    """(G QN G^T symmetrised, G NN): the dual regulator's Q and cross weight, formed as the
    estimation module forms them."""
    G, QN, NN = problem["G"], problem["QN"], problem["NN"]
    with np.errstate(over="ignore"):  # an overflow is the estimation module's to refuse
        process = G @ QN @ G.T
        process = 0.5 * process + 0.5 * process.T
        return process, None if NN is None else G @ NN


def _dual_problem(problem: Problem) -> Problem:
    process, cross = process_weights(problem)
    A, C = problem["A"], problem["C"]
    return {"A": A.T, "B": C.T, "Q": process, "R": problem["RN"], "S": cross, "E": None}


def _floats(args: dict[str, Any]) -> Problem:
    return {k: None if v is None else np.asarray(v, dtype=np.float64) for k, v in args.items()}


def _assert_filter(
    problem: Problem, L: np.ndarray, P: np.ndarray, E: np.ndarray, warned: Warned, discrete: bool
) -> None:
    """The filter is the dual regulator, bitwise, and a Riccati solution of the dual."""
    dual = _dual_problem(problem)
    regulator = aerocontrol.dlqr if discrete else aerocontrol.lqr
    K, S, poles = quietly(regulator, dual["A"], dual["B"], dual["Q"], dual["R"], N=dual["S"])
    assert np.array_equal(L, K.T), "L is not the dual regulator's K^T"
    assert np.array_equal(P, S), "P is not the dual regulator's S"
    assert np.array_equal(E, poles), "the estimator's poles are not the dual regulator's"
    assert_riccati_solution(dual, P, L.T, E, warned, discrete)


# ----- lqe and dlqe -----------------------------------------------------------------------------

FORMS = ("A, G, C, QN, RN", "A, G, C, QN, RN, NN", "NN keyword", "sys, QN, RN", "sys, QN, RN, NN")


def _filter_call(name: str, form: str) -> Any:
    function = getattr(aerocontrol, name)
    if form == "A, G, C, QN, RN":
        return lambda A, G, C, QN, RN: function(A, G, C, QN, RN)
    if form == "A, G, C, QN, RN, NN":
        return lambda A, G, C, QN, RN, NN: function(A, G, C, QN, RN, NN)
    if form == "NN keyword":
        return lambda A, G, C, QN, RN, NN: function(A, G, C, QN, RN, NN=NN)
    if form == "sys, QN, RN":
        return lambda sys, QN, RN: function(sys, QN, RN)
    return lambda sys, QN, RN, NN: function(sys, QN, RN, NN)


def _filter_problem(args: dict[str, Any]) -> Problem:
    if "sys" in args:
        A, G, C, _ = model_matrices(args["sys"])
    else:
        A, G, C = args["A"], args["G"], args["C"]
    return _floats(
        {"A": A, "G": G, "C": C, "QN": args["QN"], "RN": args["RN"], "NN": args.get("NN")}
    )


def _filter_oracle(discrete: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        L, P, E = result
        problem = _filter_problem(args)
        for key in ("QN", "RN", "NN"):
            if problem[key] is not None and problem[key].ndim < 2:
                problem[key] = problem[key].reshape(1, 1)
        _assert_filter(problem, L, P, E, warned, discrete)

    return oracle


@given(st.data())
def test_lqe(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("lqe", "dlqe")))
    form = data.draw(st.sampled_from(FORMS))
    problem = data.draw(noise_problem())
    if "NN" in form and problem["NN"] is None:
        problem["NN"] = np.zeros((problem["G"].shape[1], problem["C"].shape[0]))
    arguments: dict[str, Arg] = {}
    if form.startswith("sys"):
        model = (problem["A"], problem["G"], problem["C"], problem["D"])
        arguments["sys"] = data.draw(presented_system(model, container="attributes"))
        if name == "dlqe" and data.draw(st.booleans()) and arguments["sys"].expect == SAME:
            # A python-control model with its period: lqe passes it on to dlqe.
            sys = arguments["sys"]
            arguments["sys"] = Arg(
                _with_dt(sys.value), _with_dt(sys.canonical), sys.label + " with dt", SAME
            )
            name = data.draw(st.sampled_from(("lqe", "dlqe")))
            discrete = True
        else:
            discrete = name == "dlqe"
    else:
        for key in ("A", "G", "C"):
            arguments[key] = data.draw(presented(problem[key]))
        discrete = name == "dlqe"
    for key in ("QN", "RN"):
        arguments[key] = data.draw(presented(problem[key]))
    if "NN" in form:
        arguments["NN"] = data.draw(presented(problem["NN"]))
    exercise(name, _filter_call(name, form), arguments, _filter_oracle(discrete))


def _with_dt(sys: Any) -> Any:
    return SimpleNamespace(A=sys.A, B=sys.B, C=sys.C, D=sys.D, dt=0.1)


# ----- kalman -----------------------------------------------------------------------------------


def _kalman_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    given_ = args["sys_or_matrices"]
    model = given_ if isinstance(given_, SimpleNamespace) else tuple(given_)
    if isinstance(model, tuple) and len(model) == 3:
        A, B, C = (np.asarray(m, float) for m in model)
        D = np.zeros((C.shape[0], B.shape[1]))
    else:
        A, B, C, D = model_matrices(model)
    G = B if args["G"] is None else np.asarray(args["G"], float)
    problem = _floats(
        {"A": A, "G": G, "C": C, "QN": args["QN"], "RN": args["RN"], "NN": args["NN"]}
    )
    for key in ("QN", "RN", "NN"):
        if problem[key] is not None and problem[key].ndim < 2:
            problem[key] = problem[key].reshape(1, 1)
    discrete = args["dt"] is not None
    assert result.discrete == discrete
    L = result.predictor_gain if discrete else result.gain
    _assert_filter(problem, L, result.P, result.closed_loop_poles, warned, discrete)
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    assert np.array_equal(result.estimator_A, A - L @ C), "estimator_A is not A - L C"
    assert np.array_equal(result.estimator_B, np.hstack([B - L @ D, L])), "estimator_B"
    assert np.array_equal(result.estimator_C, np.eye(n))
    assert np.array_equal(result.estimator_D, np.zeros((n, m + p)))
    if not discrete or not finite(result.P, L):
        return
    M, P, RN = result.filter_gain, result.P, problem["RN"]
    with silenced():
        innovation = C @ P @ C.T + RN
        kappa = condition(innovation)
        error = norm(M @ innovation - P @ C.T)
        size = norm(M) * norm(innovation) + norm(P) * norm(C)
    if np.isfinite(kappa) and np.isfinite(size):
        assert error <= SLACK * (n + p) * U * size + TINY, "M (C P C^T + RN) != P C^T"
        if problem["NN"] is None:
            gap = norm(L - A @ M)
            bound = SLACK * (n + p) * U * kappa * (norm(A) * norm(M) + norm(L)) + TINY
            assert gap <= bound, f"L != A M: {gap:.3e} > {bound:.3e}"
        posterior = result.posterior_covariance
        assert np.array_equal(posterior, posterior.T), "the posterior covariance is symmetric"


@given(st.data())
def test_kalman(data: st.DataObject) -> None:
    problem = data.draw(noise_problem())
    A, B, C, D = (problem[k] for k in "ABCD")
    container = data.draw(st.sampled_from(("(A, B, C)", "(A, B, C, D)", "attributes")))
    own_G = data.draw(st.booleans())
    if not own_G:
        B = problem["G"]  # the noise enters with the inputs
        D = np.zeros((C.shape[0], B.shape[1]))
    if container == "(A, B, C)":
        parts = [data.draw(presented(M)) for M in (A, B, C)]
        sys = Arg(
            tuple(part.value for part in parts),
            tuple(part.canonical for part in parts),
            "(" + ", ".join(part.label for part in parts) + ")",
            next((part.expect for part in parts if part.expect != SAME), SAME),
        )
    else:
        sys = data.draw(
            presented_system(
                (A, B, C, D), container="tuple" if container == "(A, B, C, D)" else "attributes"
            )
        )
    dt = data.draw(st.sampled_from((None, None, 0.02, 1.0, -1.0, 0.0)))
    arguments = {
        "sys_or_matrices": sys,
        "QN": data.draw(presented(problem["QN"])),
        "RN": data.draw(presented(problem["RN"])),
        "NN": plain(None) if problem["NN"] is None else data.draw(presented(problem["NN"])),
        "dt": plain(dt),
        "G": data.draw(presented(problem["G"])) if own_G else plain(None),
    }

    def call(sys_or_matrices: Any, QN: Any, RN: Any, NN: Any, dt: Any, G: Any) -> Any:
        return aerocontrol.kalman(sys_or_matrices, QN, RN, NN, dt, G=G)

    outcome = exercise("kalman", call, arguments, _kalman_oracle)
    if dt is not None and dt <= 0:
        assert outcome.error is not None, f"kalman accepted dt = {dt}"


# ----- place_observer ---------------------------------------------------------------------------


def _observer_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    if args["poles"] is None:
        A, _, C, _ = model_matrices(args["A_or_sys"])
        poles = np.asarray(args["C"], dtype=complex)
    else:
        A, C = np.asarray(args["A_or_sys"], float), np.asarray(args["C"], float)
        poles = np.asarray(args["poles"], dtype=complex)
    design = quietly(aerocontrol.place, A.T, C.T, poles)
    assert np.array_equal(result, design.K.T), "L is not place's gain for (A^T, C^T), transposed"
    if not finite(A, C, result) or IllConditionedWarning in warned:
        return
    with silenced():
        achieved = np.linalg.eigvals(A - result @ C)
    remaining = list(achieved)
    scale = norm(A - result @ C) or 1.0
    for pole in poles:
        nearest = int(np.argmin([abs(z - pole) for z in remaining]))
        miss = abs(remaining.pop(nearest) - pole) / (abs(pole) or scale)
        assert miss <= POLE_ERROR_WARNING, f"pole {pole} missed by {miss:.2e} without a warning"


@given(st.data())
def test_place_observer(data: st.DataObject) -> None:
    problem = data.draw(noise_problem())
    A, C = problem["A"], problem["C"]
    n = A.shape[0]
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    poles = -rng.uniform(0.5, 5.0, n).astype(complex)
    if n >= 2 and data.draw(st.booleans()):
        poles[0], poles[1] = complex(-1.0, 1.0), complex(-1.0, -1.0)
    if data.draw(st.sampled_from((False,) * 5 + (True,))):
        poles = np.append(poles, -7.0)  # one too many
    pole_arg = Arg(poles, poles, "complex array", SAME)
    if data.draw(st.sampled_from((False, False, True))):
        m = problem["B"].shape[1]
        model = (A, problem["B"], C, np.zeros((C.shape[0], m)))
        arguments = {
            "A_or_sys": data.draw(presented_system(model, container="tuple")),
            "C": pole_arg,
            "poles": plain(None),
        }
    else:
        arguments = {
            "A_or_sys": data.draw(presented(A)),
            "C": data.draw(presented(C)),
            "poles": pole_arg,
        }
    exercise("place_observer", aerocontrol.place_observer, arguments, _observer_oracle)


# ----- lqg --------------------------------------------------------------------------------------


def _lqg_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, B, C, D = model_matrices(args["sys"])
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    Q, R = np.asarray(args["Q"], float), np.asarray(args["R"], float)
    N = None if args["N"] is None else np.asarray(args["N"], float)
    regulator = quietly(aerocontrol.solve_care, A, B, Q, R, N)
    assert np.array_equal(result.K, regulator.K) and np.array_equal(result.S, regulator.X)
    assert np.array_equal(result.regulator_poles, regulator.closed_loop_poles)
    G = B if args["G"] is None else args["G"]
    L, P, E = quietly(aerocontrol.lqe, A, G, C, args["QN"], args["RN"], NN=args["NN"])
    assert np.array_equal(result.L, L) and np.array_equal(result.P, P), "the filter is lqe's"
    assert np.array_equal(result.estimator_poles, E)
    assert np.array_equal(
        result.closed_loop_poles, np.concatenate([regulator.closed_loop_poles, E])
    )
    K = result.K
    compensator, loop = result.compensator, result.closed_loop
    assert np.array_equal(compensator.A, A - B @ K - L @ C + L @ D @ K)
    assert np.array_equal(compensator.B, L) and np.array_equal(compensator.C, -K)
    assert np.array_equal(compensator.D, np.zeros((m, p)))
    expected = np.block([[A, -B @ K], [L @ C, A - B @ K - L @ C]])
    assert np.array_equal(loop.A, expected), "the closed loop is not [[A, -BK], [LC, A-BK-LC]]"
    assert np.array_equal(loop.B, np.vstack([B, L @ D]))
    assert np.array_equal(loop.C, np.block([[C, -D @ K], [np.zeros((m, n)), -K]]))
    assert np.array_equal(loop.D, np.vstack([D, np.eye(m)]))
    if finite(loop.A):
        assert_stable(loop.A, "the LQG closed loop")


@given(st.data())
def test_lqg(data: st.DataObject) -> None:
    problem = data.draw(noise_problem())
    A, B, C, D = (problem[k] for k in "ABCD")
    n, m = B.shape
    regulator = data.draw(riccati_problem(descriptor_matrix=False, n=n, m=m, kinds=("regulator",)))
    if regulator["A"].shape != A.shape:
        regulator = {"Q": np.eye(n), "R": np.eye(m), "S": None}
    own_G = data.draw(st.booleans())
    if not own_G:
        problem["G"] = B
        problem["QN"] = np.eye(m)
        problem["NN"] = None
    model = (A, B, C, D)
    container = data.draw(st.sampled_from(("tuple", "attributes")))
    arguments = {
        "sys": data.draw(presented_system(model, container=container)),
        "Q": data.draw(presented(regulator["Q"])),
        "R": data.draw(presented(regulator["R"])),
        "QN": data.draw(presented(problem["QN"])),
        "RN": data.draw(presented(problem["RN"])),
        "N": plain(None) if regulator["S"] is None else data.draw(presented(regulator["S"])),
        "G": data.draw(presented(problem["G"])) if own_G else plain(None),
        "NN": plain(None) if problem["NN"] is None else data.draw(presented(problem["NN"])),
    }

    def call(sys: Any, Q: Any, R: Any, QN: Any, RN: Any, N: Any, G: Any, NN: Any) -> Any:
        return aerocontrol.lqg(sys, Q, R, QN, RN, N=N, G=G, NN=NN)

    exercise("lqg", call, arguments, _lqg_oracle)


# ----- known defects of the core (see known_defects.py) ------------------------------------------


@pytest.mark.parametrize("covariance", [1.0, 1e308])
def test_regression_estimation_overflow(covariance: float) -> None:
    G = 1e200 if covariance == 1.0 else 1.0
    exercise(
        "lqe",
        _filter_call("lqe", "A, G, C, QN, RN"),
        {
            "A": canonical(np.array([[-1.0]])),
            "G": canonical(np.array([[G]])),
            "C": canonical(np.eye(1)),
            "QN": canonical(np.array([[covariance]])),
            "RN": canonical(np.eye(1)),
        },
        _filter_oracle(False),
    )
