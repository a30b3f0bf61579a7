"""Properties of the Riccati and Lyapunov solvers (aerocontrol.riccati).

Oracles (oracles.py, "Riccati and Lyapunov equations"):

* the residual of the equation, evaluated in long double from the returned X and K, relative
  to the size of its terms as the solvers define it, is within SLACK (n + m) u of the residual
  the solver reports (which is honest), and below the documented 1e-8 unless an
  IllConditionedWarning said otherwise (the warning's contract: rcond >= 1e-8 too);
* X is symmetric to SLACK n u ||X||_F; the gain K solves its own linear system
  (R K = B^T X E + S^T, or (R + B^T X B) K = B^T X A + S^T) with a residual of SLACK (n + m) u
  times the size of its terms (times κ(E) with a descriptor E);
* the closed loop is stable: every eigenvalue of (A - B K, E) by scipy has Re < 0 (|z| < 1),
  up to its own sensitivity to the rounding of A - B K; the reported poles are strictly
  inside and are eigenvalues of (A - B K, E) by their backward error;
* against scipy's solve_continuous_are / solve_discrete_are where scipy returns a
  stabilising solution: within the first-order forward bound (||Res(X)|| + ||Res(X_s)||) / sep,
  asked only where it is below 1e-6 ||X||;
* a refusal (any aerocontrol error) of a problem that is clearly well posed fails: finite
  data of moderate size, R definite (κ <= 1e6), E well conditioned, Q - S R^-1 S^T definite,
  (A, B) stabilisable by the PBH test with a margin of 1e-4, the extended pencil's
  eigenvalues at least 1e-6 (relatively) away from the imaginary axis or the unit circle,
  and scipy's solution stabilising with ||X B R^-1 B^T|| <= 1e6 (times ||A|| in continuous
  time): a well-conditioned graph. (A DARE with A's eigenvalues near -3000 and a single input
  is stabilisable by a margin of 1e-5, yet X is near 1e20: no solver should be asked for it.)
* lqr and dlqr equal solve_care and solve_dare bitwise; lqr_finite equals riccati_ode's K;
  riccati_ode against the Hamiltonian transition matrix e^{-H (t_f - t)} in long double;
* riccati_difference step by step in long double: each K_k solves its system
  (R + B^T S_{k+1} B) K_k = B^T S_{k+1} A + N^T, and each S_k is the step
  A^T S A - M^T W^-1 M + Q from S_{k+1} within SLACK (n + m)^2 u of the size of its terms over
  rcond(W) (unless warned); S_N = Sf; the reported rcond, error estimate and the warning
  agree; a short horizon with R definite and [[Q, N], [N^T, R]], Sf semidefinite is never
  refused (R + B^T S B is then definite); dlqr_finite equals its K;
  solve_lyapunov by its residual and against scipy within the bound of its separation.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import scipy.linalg as sl
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import AerocontrolError, IllConditionedWarning
from aerocontrol.riccati import RCOND_WARNING, RESIDUAL_WARNING

from .harness import SAME, Arg, Outcome, Warned, _known_defect, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U_LONG,
    U,
    care_residual,
    closed_loop_separation,
    condition,
    dare_residual,
    expm_long,
    finite,
    longdouble,
    norm,
    pencil_eigenvalues,
    quietly,
    riccati_defect,
    riccati_gain,
    silenced,
    stabilizability_margin,
    symmetric_part,
)
from .strategies import (
    LAYOUTS,
    canonical,
    model_matrices,
    orders,
    presented,
    presented_system,
    rectangular,
    riccati_problem,
    scalar,
    square,
    symmetric_weight,
)

COVERED = {
    "solve_care",
    "lqr",
    "solve_lyapunov",
    "riccati_ode",
    "lqr_finite",
    "solve_dare",
    "dlqr",
    "riccati_difference",
    "dlqr_finite",
}

#: The errors by which a solver refuses a problem (besides refusing an argument).
Problem = dict[str, Any]


def optional(draw: st.DrawFn, value: np.ndarray | None) -> Arg:
    """An optional matrix argument: None as it is, else presented in any way."""
    return plain(None) if value is None else draw(presented(value))


def _matrices(args: Problem) -> Problem:
    """The canonical arguments as float64 arrays (B as a matrix), None kept."""
    out: Problem = {}
    for key, value in args.items():
        out[key] = None if value is None else np.asarray(value, dtype=np.float64)
    if out.get("B") is not None and out["B"].ndim == 1:
        out["B"] = out["B"].reshape(-1, 1)
    return out


# ----- the oracle of a Riccati solution ---------------------------------------------------------


def assert_riccati_solution(
    problem: Problem,
    X: np.ndarray,
    K: np.ndarray,
    poles: np.ndarray,
    warned: Warned,
    discrete: bool,
    reported: tuple[float, float] | None = None,
) -> None:
    """The checks of the module docstring on one solution (X, K, poles) of the problem
    (A, B, Q, R, S, E); ``reported`` is (residual, rcond) where the function reports them."""
    A, B, Q, R = (problem[k] for k in "ABQR")
    S, E = problem.get("S"), problem.get("E")
    n, m = B.shape
    assert X.shape == (n, n) and K.shape == (m, n), f"shapes {X.shape}, {K.shape}"
    assert poles.shape == (n,) and poles.dtype == np.complex128, f"poles {poles.shape}"
    if not finite(A, B, Q, R, X, K, poles) or (S is not None and not finite(S)):
        return
    if E is not None and not finite(E):
        return
    ill = IllConditionedWarning in warned
    if reported is not None and not ill:
        residual, rcond = reported
        assert residual <= RESIDUAL_WARNING and rcond >= RCOND_WARNING, (
            f"residual {residual:.2e}, rcond {rcond:.2e} without an IllConditionedWarning"
        )
    assert_within_(norm(X - X.T), SLACK * n * U * norm(X) + TINY, "X is symmetric")
    _assert_gain(problem, X, K, discrete)
    size, scale = (dare_residual if discrete else care_residual)(A, B, Q, S, E, X, K)
    relative = size / scale if scale else 0.0 if size == 0 else np.inf
    if reported is not None and np.isfinite(scale) and scale > 1e-280:
        # The solver evaluates the residual in double precision: its own rounding is u times
        # the norms of the products it forms, which cancel when X is large and B^T X is not.
        with silenced():
            e_size = np.sqrt(n) if E is None else norm(E)
            s_size = 0.0 if S is None else norm(S)
            if discrete:
                products = (norm(A) ** 2 + e_size**2 + norm(B) * norm(A) * norm(K)) * norm(X)
            else:
                products = (2 * norm(A) + norm(B) * norm(K)) * e_size * norm(X)
            products += norm(Q) + s_size * norm(K)
        assert_within_(
            relative,
            reported[0] + SLACK * (n + m) * U * products / scale,
            "the relative residual in long double against the reported one",
        )
    if not ill and np.isfinite(scale) and scale > 1e-280:
        assert_within_(relative, RESIDUAL_WARNING, "the relative residual (no warning)")
    _assert_closed_loop(problem, K, poles, discrete)
    if not ill:
        _compare_with_scipy(problem, X, K, discrete)


def assert_within_(error: float, bound: float, what: str) -> None:
    assert error <= bound, f"{what}: {error:.3e} exceeds the tolerance {bound:.3e}"


def _assert_gain(problem: Problem, X: np.ndarray, K: np.ndarray, discrete: bool) -> None:
    """K solves (R [+ B^T X B]) K = B^T X (E or A) + S^T, by its residual in long double."""
    A, B, R = problem["A"], problem["B"], problem["R"]
    S, E = problem.get("S"), problem.get("E")
    n, m = B.shape
    with silenced():
        b, x, k = longdouble(B), longdouble(X), longdouble(K)
        right = longdouble(A) if discrete else (longdouble(E) if E is not None else None)
        lhs = longdouble(symmetric_part(R)) + (b.T @ x @ b if discrete else 0)
        rhs = b.T @ x @ (right if right is not None else np.eye(n, dtype=np.longdouble))
        if S is not None:
            rhs = rhs + longdouble(S).T
        error = norm(np.asarray(lhs @ k - rhs, dtype=np.float64))
        sizes = norm(np.asarray(lhs, np.float64)) * norm(K) + norm(B) * norm(X) * (
            norm(A) if discrete else (norm(E) if E is not None else np.sqrt(n))
        )
        sizes += norm(S) if S is not None else 0.0
    kappa = 1.0 if E is None else condition(E)
    if np.isfinite(sizes) and np.isfinite(kappa):
        # K may underflow (R = 1e150, B^T X A = 1e-304: K = 1e-454): an absolute error of
        # TINY in K, ||R|| TINY in the equation.
        floor = SLACK * (norm(np.asarray(lhs, np.float64)) + 1) * TINY
        assert_within_(error, SLACK * (n + m) * U * kappa * sizes + floor, "the gain's equation")


def _assert_closed_loop(problem: Problem, K: np.ndarray, poles: np.ndarray, discrete: bool) -> None:
    A, B, E = problem["A"], problem["B"], problem.get("E")
    n = A.shape[0]
    if n == 0:
        return
    inside = np.abs(poles) < 1 if discrete else poles.real < 0
    assert np.all(inside), f"a reported closed-loop pole is not stable: {poles}"
    e = np.eye(n) if E is None else E
    with silenced():
        closed = A - B @ K
        spread = norm(A) + norm(B) * norm(K)
        values, left, right = sl.eig(closed, e, left=True, right=True)
        sensitivity = 1.0 / np.abs(np.sum(left.conj() * (e @ right), axis=0))
    if not finite(closed, values) or not np.isfinite(spread):
        return
    margin = SLACK * n * U * spread * sensitivity
    distance = np.abs(values) - 1 if discrete else values.real
    worst = int(np.argmax(distance - margin))
    assert distance[worst] < margin[worst] or distance[worst] < 0, (
        f"the closed loop (A - B K, E) has the eigenvalue {values[worst]}, not stable "
        f"(sensitivity margin {margin[worst]:.2e})"
    )
    # The reported poles are eigenvalues of (A - B K, E) to their backward error, which grows
    # by the closed loop's own forward error (the gain is accurate to cond u, not u).
    for pole in poles:
        pencil = closed.astype(complex) - pole * e
        backward = float(np.linalg.svd(pencil, compute_uv=False)[-1])
        bound = SLACK * n * (U * (spread + abs(pole) * norm(e)) + TINY)
        assert_within_(backward / max(1.0, float(np.max(sensitivity))), bound, f"pole {pole}")


def _compare_with_scipy(problem: Problem, X: np.ndarray, K: np.ndarray, discrete: bool) -> None:
    """Against scipy's solution within the first-order forward error bound."""
    A, B, Q, R = (problem[k] for k in "ABQR")
    S, E = problem.get("S"), problem.get("E")
    n = A.shape[0]
    if n == 0:
        return
    solver = sl.solve_discrete_are if discrete else sl.solve_continuous_are
    try:
        theirs = quietly(solver, A, B, Q, R, e=E, s=S)
    except (ValueError, np.linalg.LinAlgError):
        return
    if not finite(theirs):
        return
    theirs = symmetric_part(theirs)
    their_gain = riccati_gain(A, B, R, S, E, theirs, discrete)
    if not finite(their_gain):
        return
    e = np.eye(n) if E is None else E
    with silenced():
        their_closed_loop = A - B @ their_gain
    if not finite(their_closed_loop):
        return  # B K overflows: no loop to compare
    with silenced():
        their_loop = quietly(sl.eigvals, their_closed_loop, e)
    stable = np.abs(their_loop) < 1 - 1e-6 if discrete else their_loop.real < -1e-6 * norm(A)
    if not np.all(stable):
        return  # scipy's X is not the stabilising solution
    size = riccati_defect(A, B, Q, R, S, E, X, riccati_gain(A, B, R, S, E, X, discrete), discrete)
    their_size = riccati_defect(A, B, Q, R, S, E, theirs, their_gain, discrete)
    separation = closed_loop_separation(A - B @ K, E, discrete)
    if not separation > 0:
        return
    bound = 2 * (size + their_size) / separation
    with silenced():
        lhs = symmetric_part(R) + (B.T @ X @ B if discrete else 0)
        gain_size = norm(B) ** 2 / float(np.linalg.svd(lhs, compute_uv=False)[-1])
        second = gain_size * max(1.0, norm(A) ** 2 if discrete else norm(e) ** 2) * bound
    if not (bound <= 1e-6 * norm(X) and second <= 1e-2 * separation):
        return
    assert_within_(
        norm(X - theirs),
        bound + SLACK * n * U * norm(X) + TINY,
        f"X against scipy's {solver.__name__} (sep {separation:.2e})",
    )


def well_posed(problem: Problem, discrete: bool) -> bool:
    """Whether the problem clearly has a stabilising solution that a solver must find (see
    the module docstring)."""
    A, B, Q, R = (problem[k] for k in "ABQR")
    S, E = problem.get("S"), problem.get("E")
    n = B.shape[0]
    matrices = [M for M in (A, B, Q, R, S, E) if M is not None]
    if n == 0 or not finite(*matrices):
        return False
    if any(not 1e-20 <= norm(M) <= 1e20 for M in (A, B, Q, R)):
        return False
    try:
        return _clearly_solvable(A, B, Q, R, S, E, discrete)
    except (ValueError, np.linalg.LinAlgError):
        return False  # numpy cannot tell: not clearly well posed


def _clearly_solvable(
    A: np.ndarray,
    B: np.ndarray,
    Q: np.ndarray,
    R: np.ndarray,
    S: np.ndarray | None,
    E: np.ndarray | None,
    discrete: bool,
) -> bool:
    n = A.shape[0]
    with silenced():
        if max(np.max(np.abs(Q - Q.T)), np.max(np.abs(R - R.T))) > 0:
            return False
        r = np.linalg.eigvalsh(R)
        if not r[0] >= 1e-6 * r[-1] > 0:
            return False
        if E is not None and condition(E) > 1e6:
            return False
        effective = Q if S is None else Q - S @ np.linalg.solve(R, S.T)
        q = np.linalg.eigvalsh(symmetric_part(effective))
        if not q[0] >= 1e-6 * max(q[-1], norm(Q)) > 0:
            return False
    if not stabilizability_margin(A, B, E, discrete) >= 1e-4:
        return False
    eigenvalues = pencil_eigenvalues(A, B, Q, R, S, E, discrete)
    if eigenvalues.size != 2 * n or not finite(eigenvalues):
        return False
    if discrete:
        if not np.min(np.abs(np.abs(eigenvalues) - 1)) >= 1e-6:
            return False
    elif not np.min(np.abs(eigenvalues.real)) >= 1e-6 * np.max(np.abs(eigenvalues)):
        return False
    # Well conditioned: scipy finds the stabilising solution, and the graph [I; X] of the
    # stable subspace is well conditioned, ||X G|| <= 1e6 (||A|| in continuous time), with
    # G = B R^-1 B^T (X G is dimensionless in discrete time, has A's units in continuous).
    solver = sl.solve_discrete_are if discrete else sl.solve_continuous_are
    try:
        X = quietly(solver, A, B, Q, R, e=E, s=S)
    except (ValueError, np.linalg.LinAlgError):
        return False
    with silenced():
        K = riccati_gain(A, B, R, S, E, symmetric_part(X), discrete)
        loop = sl.eigvals(A - B @ K, np.eye(n) if E is None else E)
        G = B @ np.linalg.solve(R, B.T)
        size = norm(X @ G) / (1.0 if discrete else max(norm(A), TINY))
    stable = np.abs(loop) < 1 - 1e-6 if discrete else loop.real < 0
    return bool(finite(X, loop) and np.all(stable) and size <= 1e6)


def assert_refusal_justified(
    name: str, outcome: Outcome, arguments: dict[str, Arg], problem: Problem, discrete: bool
) -> None:
    """A solver may refuse a problem only if it is not clearly well posed."""
    if outcome.error is None or not isinstance(outcome.error, AerocontrolError):
        return
    if any(arg.expect != SAME for arg in arguments.values()):
        return
    assert not well_posed(problem, discrete), (
        f"{name} refused a well-posed problem: {type(outcome.error).__name__}: {outcome.error}"
    )


# ----- solve_care and solve_dare ----------------------------------------------------------------


def _solution_oracle(discrete: bool) -> Any:
    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        problem = _matrices({k: args.get(k) for k in ("A", "B", "Q", "R", "S", "E")})
        assert isinstance(result.refinement_steps, int) and result.refinement_steps >= 0
        assert_riccati_solution(
            problem,
            result.X,
            result.K,
            result.closed_loop_poles,
            warned,
            discrete,
            (result.residual, result.rcond),
        )

    return oracle


def riccati_arguments(draw: st.DrawFn, problem: Problem) -> dict[str, Arg]:
    return {
        "A": draw(presented(problem["A"])),
        "B": draw(presented(problem["B"])),
        "Q": draw(presented(problem["Q"])),
        "R": draw(presented(problem["R"])),
        "S": optional(draw, problem["S"]),
        "E": optional(draw, problem["E"]),
    }


def _canonical_problem(arguments: dict[str, Arg]) -> Problem | None:
    if any(arg.expect != SAME for arg in arguments.values()):
        return None
    return _matrices({key: arg.canonical for key, arg in arguments.items()})


@given(st.data())
def test_solve_care(data: st.DataObject) -> None:
    problem = data.draw(riccati_problem())
    arguments = riccati_arguments(data.draw, problem)
    refine = data.draw(st.sampled_from((True, True, False)))
    if not refine:
        arguments["refine"] = plain(False)
    outcome = exercise("solve_care", aerocontrol.solve_care, arguments, _solution_oracle(False))
    canonical_problem = _canonical_problem(arguments)
    if canonical_problem is not None:
        assert_refusal_justified("solve_care", outcome, arguments, canonical_problem, False)


@given(st.data())
def test_solve_dare(data: st.DataObject) -> None:
    problem = data.draw(riccati_problem())
    arguments = riccati_arguments(data.draw, problem)
    outcome = exercise("solve_dare", aerocontrol.solve_dare, arguments, _solution_oracle(True))
    canonical_problem = _canonical_problem(arguments)
    if canonical_problem is not None:
        assert_refusal_justified("solve_dare", outcome, arguments, canonical_problem, True)


# ----- lqr and dlqr -----------------------------------------------------------------------------

FORMS = ("A, B, Q, R", "A, B, Q, R, N", "N keyword", "sys, Q, R", "sys, Q, R, N")


def _regulator_call(name: str, form: str) -> Any:
    function = getattr(aerocontrol, name)
    if form == "A, B, Q, R":
        return lambda A, B, Q, R: function(A, B, Q, R)
    if form == "A, B, Q, R, N":
        return lambda A, B, Q, R, N: function(A, B, Q, R, N)
    if form == "N keyword":
        return lambda A, B, Q, R, N: function(A, B, Q, R, N=N)
    if form == "sys, Q, R":
        return lambda sys, Q, R: function(sys, Q, R)
    return lambda sys, Q, R, N: function(sys, Q, R, N)


def _regulator_problem(args: dict[str, Any]) -> Problem:
    if "sys" in args:
        A, B, _, _ = model_matrices(args["sys"])
    else:
        A, B = args["A"], args["B"]
    return _matrices({"A": A, "B": B, "Q": args["Q"], "R": args["R"], "S": args.get("N")})


def _regulator_oracle(name: str) -> Any:
    discrete = name == "dlqr"
    solver = aerocontrol.solve_dare if discrete else aerocontrol.solve_care

    def oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
        K, X, poles = result
        problem = _regulator_problem(args)
        # The regulator is the solver's solution, bitwise.
        alone = quietly(
            solver, problem["A"], problem["B"], problem["Q"], problem["R"], problem["S"]
        )
        assert np.array_equal(K, alone.K) and np.array_equal(X, alone.X), f"{name} != solver"
        assert np.array_equal(poles, alone.closed_loop_poles), f"{name}'s poles != the solver's"
        assert_riccati_solution(problem, X, K, poles, warned, discrete)

    return oracle


@given(st.data())
def test_regulators(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("lqr", "dlqr")))
    form = data.draw(st.sampled_from(FORMS))
    problem = data.draw(riccati_problem(descriptor_matrix=False))
    A, B, Q, R, N = (problem[k] for k in "ABQRS")
    if "N" in form and N is None:
        N = np.zeros(B.shape)
    arguments: dict[str, Arg] = {}
    if form.startswith("sys"):
        n, m = B.shape
        arguments["sys"] = data.draw(
            presented_system((A, B, np.eye(n), np.zeros((n, m))), container="attributes")
        )
    else:
        arguments["A"], arguments["B"] = data.draw(presented(A)), data.draw(presented(B))
    arguments["Q"], arguments["R"] = data.draw(presented(Q)), data.draw(presented(R))
    if "N" in form:
        arguments["N"] = data.draw(presented(N))
    outcome = exercise(name, _regulator_call(name, form), arguments, _regulator_oracle(name))
    if all(arg.expect == SAME for arg in arguments.values()):
        canonical_values = {key: arg.canonical for key, arg in arguments.items()}
        problem = _regulator_problem(canonical_values)
        assert_refusal_justified(name, outcome, arguments, problem, name == "dlqr")


# ----- solve_lyapunov ---------------------------------------------------------------------------


def _lyapunov_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, Q = np.asarray(args["A"], float), np.asarray(args["Q"], float)
    n = A.shape[0]
    assert result.shape == (n, n) and result.dtype == np.float64
    if not finite(A, Q, result):
        return
    X = result
    with silenced():
        a, x = longdouble(A), longdouble(X)
        residual = norm(np.asarray(a @ x + x @ a.T + longdouble(Q), dtype=np.float64))
        scale = 2 * norm(A) * norm(X) + norm(Q)
    if not np.isfinite(scale):
        return
    # Bartels-Stewart with orthogonal transformations: a residual of a few n u the terms; X
    # may underflow (A = 1e299, Q = 1e-151: X = -5e-451 rounds to 0), by TINY, which A maps
    # to 2 ||A|| TINY.
    floor = SLACK * (2 * norm(A) + 1) * TINY
    assert_within_(residual, SLACK * n * U * scale + floor, "A X + X A^T + Q")
    if np.array_equal(Q, Q.T):
        assert_within_(norm(X - X.T), SLACK * n * U * norm(X) + TINY, "X is symmetric")
    theirs = quietly(sl.solve_continuous_lyapunov, A, -Q)
    if not finite(theirs):
        return
    with silenced():
        t = longdouble(theirs)
        their_residual = norm(np.asarray(a @ t + t @ a.T + longdouble(Q), dtype=np.float64))
    separation = _lyapunov_separation(A)
    if separation > 0 and np.isfinite(their_residual):
        bound = (residual + their_residual) / separation
        assert_within_(
            norm(X - theirs),
            bound + SLACK * n * U * norm(X) + SLACK * TINY,
            f"X against scipy's solve_continuous_lyapunov (sep {separation:.2e})",
        )


def _lyapunov_separation(A: np.ndarray) -> float:
    """sigma_min of X -> A X + X A^T (its Kronecker matrix I ⊗ A + A ⊗ I)."""
    n = A.shape[0]
    if n == 0:
        return np.inf
    with silenced():
        operator = np.kron(np.eye(n), A) + np.kron(A, np.eye(n))
        try:
            return float(np.linalg.svd(operator, compute_uv=False)[-1])
        except np.linalg.LinAlgError:
            return 0.0


@given(st.data())
def test_solve_lyapunov(data: st.DataObject) -> None:
    n = data.draw(orders())
    A = data.draw(square(n))
    if data.draw(st.booleans()):
        Q = data.draw(symmetric_weight(n))
    else:
        Q = data.draw(rectangular(n, n))
    arguments = {"A": data.draw(presented(A)), "Q": data.draw(presented(Q))}
    outcome = exercise("solve_lyapunov", aerocontrol.solve_lyapunov, arguments, _lyapunov_oracle)
    if outcome.error is not None and all(arg.expect == SAME for arg in arguments.values()):
        A = np.asarray(arguments["A"].canonical, float)
        Q = np.asarray(arguments["Q"].canonical, float)
        if A.ndim == 2 and A.shape[0] == A.shape[1] and Q.shape == A.shape and finite(A, Q):
            # A unique solution of representable size, separated from singularity (relative
            # to ||A||, at any scale): a refusal is wrong.
            separation = _lyapunov_separation(A)
            if norm(A) > 0 and separation >= 1e-6 * norm(A) and norm(Q) / separation < 1e300:
                failure = f"solve_lyapunov refused A with sep {separation:.2e}: {outcome.error!r}"
                if _known_defect("solve_lyapunov", arguments, failure) is None:
                    raise AssertionError(failure)


# ----- riccati_ode and lqr_finite ---------------------------------------------------------------

HORIZONS = (0.1, 1.0, 3.0, 20.0, 1e-300, 1e3)
#: The most substeps a call of riccati_ode may take.
MAX_SUBSTEPS = 10**5


@st.composite
def time_grid(draw: st.DrawFn) -> Arg:
    """t: increasing (linspace or not uniform, from any start), one time, or refused:
    decreasing, repeated, empty, NaN, 2-D."""
    kind = draw(
        st.sampled_from(
            ("linspace",) * 4
            + ("uneven", "single", "negative start")
            + ("decreasing", "repeated", "empty", "nan", "2-D")
        )
    )
    k = draw(st.integers(2, 6))
    horizon = draw(st.sampled_from(HORIZONS))
    if kind == "single":
        return draw(scalar(horizon, kinds=("float", "np.float64", "0-d array")))
    with np.errstate(all="ignore"):
        grid = {
            "linspace": np.linspace(0.0, horizon, k),
            "uneven": horizon * np.sort(np.unique(np.r_[0.0, 1.0, np.arange(1, k) ** 2 / k**2])),
            "negative start": np.linspace(-horizon, horizon, k),
            "decreasing": np.linspace(horizon, 0.0, k),
            "repeated": np.array([0.0, horizon, horizon]),
            "empty": np.zeros(0),
            "nan": np.array([0.0, np.nan, horizon]),
            "2-D": np.linspace(0.0, horizon, 4).reshape(2, 2),
        }[kind]
    return draw(presented(grid))


def _ode_reference(problem: Problem, Sf: np.ndarray, tau: float) -> tuple[np.ndarray, float]:
    """(S, tolerance): S(t_f - tau) from [X; Y] = e^{-H tau} [I; Sf], S = Y X^-1, in long
    double; the tolerance allows SLACK 2n (u + u_long kappa) ||e^{-H tau}|| (1 + ||Sf||) in X
    and Y, amplified by ||X^-1|| (1 + ||S||). inf where no reference can be trusted."""
    A, B, Q, R = (problem[k] for k in "ABQR")
    n = A.shape[0]
    with silenced():
        G = B @ np.linalg.solve(symmetric_part(R), B.T)
        H = np.block([[A, -G], [-symmetric_part(Q), -A.T]])
        if not finite(H) or norm(H) * tau > 30:
            return np.zeros((n, n)), np.inf
        Phi = expm_long(-H * tau)
        top = Phi @ np.vstack([np.eye(n), Sf]).astype(np.longdouble)
        X, Y = np.asarray(top[:n], np.float64), top[n:]
        if condition(X) > 1e8:
            return np.zeros((n, n)), np.inf
        Xinv = np.linalg.inv(X)
        # One step of refinement of the solve, with the residual in long double.
        Xinv = Xinv + Xinv @ np.asarray(np.eye(n) - top[:n] @ longdouble(Xinv), np.float64)
        S = np.asarray(Y @ longdouble(Xinv), dtype=np.float64)
        scale = norm(np.asarray(Phi, np.float64)) * (1 + norm(Sf))
        tolerance = (
            SLACK * 2 * n * (U + U_LONG) * (1 + norm(H) * tau) * scale * norm(Xinv) * (1 + norm(S))
        )
    return symmetric_part(S), tolerance if np.isfinite(tolerance) else np.inf


def _ode_problem(args: dict[str, Any]) -> tuple[Problem, np.ndarray, np.ndarray]:
    if "sys" in args:
        A, B, _, _ = model_matrices(args["sys"])
    else:
        A, B = args["A_or_sys"], args["B"]
    problem = _matrices({"A": A, "B": B, "Q": args["Q"], "R": args["R"]})
    t = np.atleast_1d(np.asarray(args["t"], dtype=np.float64))
    n = problem["A"].shape[0]
    Sf = np.zeros((n, n)) if args["Sf"] is None else np.asarray(args["Sf"], np.float64)
    return problem, t, Sf


def _ode_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    problem, t, Sf = _ode_problem(args)
    A, B, R = problem["A"], problem["B"], problem["R"]
    n, m = B.shape
    k = t.size
    assert result.S.shape == (k, n, n) and result.K.shape == (k, m, n)
    assert np.array_equal(result.t, t), "t is not returned as given"
    assert isinstance(result.substeps, int) and result.substeps >= 0
    # The work is bounded: S(t) converges to the algebraic solution within a few time
    # constants, so that no horizon needs more than a bounded number of steps.
    assert result.substeps <= MAX_SUBSTEPS, f"{result.substeps} substeps"
    if not finite(result.S, result.K, A, B, R, Sf):
        return
    assert_within_(norm(result.S[-1] - Sf), 4 * U * norm(Sf), "S(t_f) = Sf")
    for j in range(k):
        S, K = result.S[j], result.K[j]
        assert_within_(norm(S - S.T), SLACK * n * U * norm(S) + TINY, f"S({t[j]}) is symmetric")
        with silenced():
            error = norm(
                np.asarray(
                    longdouble(R) @ longdouble(K) - longdouble(B).T @ longdouble(S), np.float64
                )
            )
            size = norm(R) * norm(K) + norm(B) * norm(S)
        if np.isfinite(size):
            assert_within_(error, SLACK * (n + m) * U * size + TINY, f"R K({t[j]}) = B^T S")
    # Against the transition matrix in long double, at up to 6 times.
    for j in np.unique(np.linspace(0, k - 1, min(k, 6)).astype(int)):
        tau = float(t[-1] - t[j])
        reference, tolerance = _ode_reference(problem, Sf, tau)
        if np.isfinite(tolerance):
            assert_within_(
                norm(result.S[j] - reference),
                tolerance + SLACK * n * TINY,
                f"S(t_f - {tau:g}) against e^(-H tau) in long double",
            )


#: The largest ||H||_1 (t_f - t_0) for which riccati_ode is called: its substeps grow with it
#: (known defect riccati-ode-unbounded-substeps), 1.4e5 of them take 0.05 s.
MAX_WORK = 2e5


def hamiltonian_work(A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray, t: Any) -> float:
    """||H||_1 (t_f - t_0) for H = [[A, -B R^-1 B^T], [-Q, -A^T]] (an upper bound of the
    growth rate of its modes times the horizon), 0 when it cannot be formed."""
    with silenced():
        try:
            times = np.atleast_1d(np.asarray(t, dtype=np.float64))
            G = B @ np.linalg.solve(R, B.T)
            H = np.block([[A, -G], [-Q, -A.T]])
            size = float(np.max(np.sum(np.abs(H), axis=0), initial=0.0))
            span = float(times[-1] - times[0]) if times.ndim == 1 and times.size else 0.0
        except (ValueError, TypeError, IndexError, np.linalg.LinAlgError):
            return 0.0
    work = size * abs(span)
    return work if not np.isnan(work) else 0.0


def _ode_call(name: str, form: str) -> Any:
    function = getattr(aerocontrol, name)
    if form == "sys":
        return lambda sys, Q, R, t, Sf: function(sys, Q, R, t, Sf)
    return lambda A_or_sys, B, Q, R, t, Sf: function(A_or_sys, B, Q, R, t, Sf)


def _lqr_finite_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    call = _ode_call("riccati_ode", "sys" if "sys" in args else "matrices")
    alone = quietly(call, **args)
    assert np.array_equal(result, alone.K), "lqr_finite is not riccati_ode's K"


def plant_and_weights(
    data: st.DataObject, A: np.ndarray, B: np.ndarray, Q: np.ndarray, R: np.ndarray
) -> tuple[str, dict[str, Arg]]:
    """The form of a finite-horizon call ("matrices": A_or_sys and B; "sys": a system) and
    its plant and weight arguments, presented."""
    form = data.draw(st.sampled_from(("matrices", "matrices", "sys")))
    arguments: dict[str, Arg] = {}
    if form == "sys":
        n, m = B.shape
        arguments["sys"] = data.draw(
            presented_system((A, B, np.eye(n), np.zeros((n, m))), container="attributes")
        )
    else:
        arguments["A_or_sys"], arguments["B"] = data.draw(presented(A)), data.draw(presented(B))
    arguments["Q"], arguments["R"] = data.draw(presented(Q)), data.draw(presented(R))
    return form, arguments


def terminal_weight(data: st.DataObject, n: int) -> tuple[str, Arg]:
    """Sf of a finite-horizon problem and how it was drawn: none, zero, a symmetric weight, or
    of the wrong shape (refused)."""
    kind = data.draw(st.sampled_from(("none", "none", "zero", "weight", "wrong shape")))
    if kind == "zero":
        return kind, data.draw(presented(np.zeros((n, n))))
    if kind == "weight":
        return kind, data.draw(presented(data.draw(symmetric_weight(n))))
    if kind == "wrong shape":
        return kind, data.draw(presented(np.eye(n + 1)))
    return kind, plain(None)


@given(st.data())
def test_riccati_ode(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("riccati_ode", "riccati_ode", "lqr_finite")))
    n = data.draw(st.sampled_from((0, 1, 2, 3, 4, 6)))
    problem = data.draw(riccati_problem(cross=False, descriptor_matrix=False, n=n))
    A, B, Q, R = (problem[k] for k in "ABQR")
    _, Sf = terminal_weight(data, n)
    form, arguments = plant_and_weights(data, A, B, Q, R)
    arguments["t"], arguments["Sf"] = data.draw(time_grid()), Sf
    if hamiltonian_work(A, B, Q, R, arguments["t"].canonical) > MAX_WORK:
        # The call would run for hours (known defect riccati-ode-unbounded-substeps): the
        # horizon is cut to ||H||_1 (t_f - t_0) = MAX_WORK.
        t = np.atleast_1d(np.asarray(arguments["t"].canonical, dtype=np.float64))
        span = hamiltonian_work(A, B, Q, R, t)
        arguments["t"] = data.draw(presented(t * (MAX_WORK / span), LAYOUTS))
    oracle = _ode_oracle if name == "riccati_ode" else _lqr_finite_oracle
    exercise(name, _ode_call(name, form), arguments, oracle)


# ----- riccati_difference and dlqr_finite -------------------------------------------------------


def _difference_problem(args: dict[str, Any]) -> tuple[Problem, np.ndarray, np.ndarray, int]:
    if "sys" in args:
        A, B, _, _ = model_matrices(args["sys"])
    else:
        A, B = args["A_or_sys"], args["B"]
    problem = _matrices({"A": A, "B": B, "Q": args["Q"], "R": args["R"]})
    n, m = problem["B"].shape
    Sf = np.zeros((n, n)) if args["Sf"] is None else np.asarray(args["Sf"], np.float64)
    N = np.zeros((n, m)) if args["N"] is None else np.asarray(args["N"], np.float64)
    return problem, Sf, N, int(args["steps"])


#: The smallest normal double.
TINY_NORMAL = float(np.finfo(np.float64).tiny)


def _difference_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    problem, Sf, N, steps = _difference_problem(args)
    A, B, Q, R = (problem[k] for k in "ABQR")
    with silenced():
        Sf, Q, R = symmetric_part(Sf), symmetric_part(Q), symmetric_part(R)
    n, m = B.shape
    assert result.S.shape == (steps + 1, n, n) and result.K.shape == (steps, m, n)
    assert 0.0 <= result.rcond <= 1.0
    assert result.error_estimate >= 0.0
    assert (IllConditionedWarning in warned) == (
        result.rcond < RCOND_WARNING or result.error_estimate > RESIDUAL_WARNING
    )
    assert_within_(norm(result.S[-1] - Sf), 4 * U * norm(Sf), "S_N = Sf")
    for k in range(steps):
        S_next, S, K = result.S[k + 1], result.S[k], result.K[k]
        assert np.array_equal(S, S.T), f"S_{k} is not symmetric"
        with silenced():
            s, g = longdouble(S_next), longdouble(K)
            weight = longdouble(R) + longdouble(B).T @ s @ longdouble(B)
            mixed = longdouble(B).T @ s @ longdouble(A) + longdouble(N).T
            error = norm(np.asarray(weight @ g - mixed, np.float64))
            # The terms of forming W and M in double, and of the solve.
            size = (
                norm(np.asarray(weight, np.float64)) * norm(K)
                + norm(B) * norm(S_next) * (norm(A) + norm(B) * norm(K))
                + norm(R) * norm(K)
                + norm(N)
            )
            # The step (1) from the returned S_{k+1}, with the gain solved again in double and
            # refined once in long double: S = A^T S A - M^T W^-1 M + Q. Its terms bound the
            # error of any evaluation in double (the solver's subtraction-free form is more
            # accurate where they cancel).
            exact = np.linalg.solve(np.asarray(weight, np.float64), np.asarray(mixed, np.float64))
            exact = longdouble(exact) + longdouble(
                np.linalg.solve(
                    np.asarray(weight, np.float64),
                    np.asarray(mixed - weight @ longdouble(exact), np.float64),
                )
            )
            axa = longdouble(A).T @ s @ longdouble(A)
            quadratic = mixed.T @ exact
            step = axa - quadratic + longdouble(Q)
            step_error = norm(S - np.asarray(step, np.float64))
            step_size = (
                norm(np.asarray(axa, np.float64))
                + norm(np.asarray(quadratic, np.float64))
                + norm(Q)
            )
        # A gain below the normal range (M tiny beside W) rounds to subnormals or zero.
        weight_norm, mixed_norm = (
            norm(np.asarray(weight, np.float64)),
            norm(np.asarray(mixed, np.float64)),
        )
        underflow = mixed_norm if mixed_norm <= TINY_NORMAL * weight_norm / U else 0.0
        if np.isfinite(size):
            assert_within_(
                error,
                SLACK * (n + m) * U * size / max(result.rcond, U) + TINY + underflow,
                f"K_{k} solves",
            )
        if np.isfinite(step_size) and IllConditionedWarning not in warned:
            assert_within_(
                step_error,
                SLACK * (n + m) ** 2 * U * step_size / result.rcond + TINY,
                f"S_{k} is the step",
            )


def _dlqr_finite_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    call = _difference_call("riccati_difference", "sys" if "sys" in args else "matrices")
    alone = quietly(call, **args)
    assert np.array_equal(result, alone.K), "dlqr_finite is not riccati_difference's K"


def _difference_call(name: str, form: str) -> Any:
    function = getattr(aerocontrol, name)
    if form == "sys":
        return lambda sys, Q, R, steps, Sf, N: function(sys, Q, R, steps, Sf=Sf, N=N)
    return lambda A_or_sys, B, Q, R, steps, Sf, N: function(A_or_sys, B, Q, R, steps, Sf, N)


def _never_refused(problem: Problem, Sf: np.ndarray, N: np.ndarray, steps: int) -> bool:
    """R definite (κ <= 1e6), the joint weight [[Q, N], [N^T, R]] and Sf semidefinite, moderate
    finite data and a short horizon: every S_k is then semidefinite, every R + B^T S B definite
    and S stays in range, so a refusal is a defect."""
    A, B, Q, R = (problem[k] for k in "ABQR")
    if not finite(A, B, Q, R, Sf, N) or steps > 8:
        return False
    if any(norm(M) > 1e3 for M in (A, B, Q, R, Sf, N)) or norm(R) < 1e-3:
        return False
    if any(np.abs(M - M.T).max(initial=0.0) > 0.0 for M in (Q, R, Sf)):
        return False  # asymmetric weights are refused beyond 1e-12 of their size
    with silenced():
        joint = symmetric_part(np.block([[Q, N], [N.T, R]]))
        w = np.linalg.eigvalsh(joint)
        r = np.linalg.eigvalsh(symmetric_part(R))
        f = np.linalg.eigvalsh(Sf) if Sf.size else np.zeros(1)
    return bool(
        r.min() > 1e-6 * r.max()
        and w.min() >= -1e-12 * max(1.0, abs(w).max())
        and f.min() >= -1e-12 * max(1.0, abs(f).max())
    )


@given(st.data())
def test_riccati_difference(data: st.DataObject) -> None:
    name = data.draw(st.sampled_from(("riccati_difference", "riccati_difference", "dlqr_finite")))
    n = data.draw(st.sampled_from((0, 1, 2, 3, 4, 6)))
    problem = data.draw(riccati_problem(cross=True, descriptor_matrix=False, n=n))
    A, B, Q, R, N = (problem[k] for k in "ABQRS")
    n = A.shape[0]  # a planted problem may change the order
    steps = data.draw(st.sampled_from((0, 1, 2, 5, 8, 40)))
    kind, Sf = terminal_weight(data, n)
    form, arguments = plant_and_weights(data, A, B, Q, R)
    arguments["steps"] = plain(data.draw(st.sampled_from((steps, np.int64(steps)))))
    arguments["Sf"], arguments["N"] = Sf, optional(data.draw, N)
    oracle = _difference_oracle if name == "riccati_difference" else _dlqr_finite_oracle
    outcome = exercise(name, _difference_call(name, form), arguments, oracle)
    if outcome.error is None or kind == "wrong shape":
        return
    canonical = {key: arg.canonical for key, arg in arguments.items()}
    if any(arg.expect != SAME for arg in arguments.values()):
        return
    problem_canonical, Sf_canonical, N_canonical, _ = _difference_problem(canonical)
    assert not _never_refused(problem_canonical, Sf_canonical, N_canonical, steps), (
        f"{name} refused a problem with R definite and Q, Sf semidefinite: "
        f"{type(outcome.error).__name__}: {outcome.error}"
    )


# ----- known defects of the core (see known_defects.py) ------------------------------------------


def test_regression_dare_badly_scaled_states() -> None:
    """Found by an oracle hunt (the core refused it: 2 of the 6 pencil eigenvalues inside the
    unit circle, not 3), fixed by the exact scaling of the equation before the core's solve:
    the regulator of a well-conditioned 3-state model in states T = diag(1e-5, 1e6, 1e-4),
    which is that of the unscaled model (X = T^-T X0 T^-1, K = K0 T^-1, the same closed
    loop)."""
    A = np.array(
        [
            [0.9153299667155719, -4.225366333414862e-12, 0.08260637158803313],
            [110381521018.32742, 0.2226317431058629, -4042243188.6160803],
            [9.829712051107036, 7.585139064630774e-11, 0.6870135440031627],
        ]
    )
    B = np.array([[-1.68095734956127e-05], [437652.243575086], [0.00020643404268335362]])
    Q, R = np.diag([1e10, 1e-12, 1e8]), np.eye(1)
    t = np.array([1e-5, 1e6, 1e-4])
    _, _, unscaled = aerocontrol.dlqr(A * (t[None, :] / t[:, None]), B / t[:, None], np.eye(3), R)
    X = sl.solve_discrete_are(A, B, Q, R)
    K = np.linalg.solve(B.T @ X @ B + R, B.T @ X @ A)
    theirs = np.sort(np.abs(np.linalg.eigvals(A - B @ K)))
    np.testing.assert_allclose(np.sort(np.abs(unscaled)), theirs, rtol=1e-8)
    K_ours, X_ours, poles = aerocontrol.dlqr(A, B, Q, R)
    np.testing.assert_allclose(np.sort(np.abs(poles)), theirs, rtol=1e-10)
    np.testing.assert_allclose(K_ours, K, rtol=1e-8)
    # X in the scaled states: entry (i, j) relative to sqrt(X_ii X_jj).
    size = np.sqrt(np.outer(np.diag(X), np.diag(X)))
    assert np.max(np.abs(X_ours - X) / size) < 1e-9


def test_regression_care_empty_indefinite_rcond() -> None:
    exercise(
        "solve_care",
        aerocontrol.solve_care,
        {
            "A": canonical(np.zeros((0, 0))),
            "B": canonical(np.zeros((0, 2))),
            "Q": canonical(np.zeros((0, 0))),
            "R": canonical(np.diag([1.0, -1.0])),
        },
        _solution_oracle(False),
    )


def test_regression_riccati_ode_unbounded_substeps() -> None:
    exercise(
        "riccati_ode",
        _ode_call("riccati_ode", "matrices"),
        {
            "A_or_sys": canonical(np.array([[1e6]])),
            "B": canonical(np.eye(1)),
            "Q": canonical(np.eye(1)),
            "R": canonical(np.eye(1)),
            "t": canonical(np.array([0.0, 1.0])),
            "Sf": plain(None),
        },
        _ode_oracle,
    )


def test_regression_riccati_overflow_blames_a() -> None:
    exercise(
        "solve_care",
        aerocontrol.solve_care,
        {
            "A": canonical(np.zeros((1, 1))),
            "B": canonical(np.array([[1e200]])),
            "Q": canonical(np.eye(1)),
            "R": canonical(np.eye(1)),
        },
        _solution_oracle(False),
    )


def test_regression_lyapunov_tiny_refused() -> None:
    A, Q = np.array([[-1e-295]]), np.array([[1e-295]])
    arguments = {"A": canonical(A), "Q": canonical(Q)}
    outcome = exercise("solve_lyapunov", aerocontrol.solve_lyapunov, arguments, _lyapunov_oracle)
    assert outcome.error is None, f"X = 0.5 exactly, but: {outcome.error!r}"


def test_regression_dare_pencil_overflow_not_blamed_on_a() -> None:
    # A = 1e308: the compressed pencil overflowed and its QZ refused "A must be finite, A is
    # NaN" (NonFiniteError for finite data); now a named IllConditionedError.
    exercise(
        "solve_dare",
        aerocontrol.solve_dare,
        {
            "A": canonical(np.array([[1e308]])),
            "B": canonical(np.array([[0.345584192064786]])),
            "Q": canonical(np.eye(1)),
            "R": canonical(np.array([[0.11580808849619356]])),
        },
        _solution_oracle(True),
    )
    with pytest.raises(aerocontrol.exceptions.IllConditionedError, match="range of doubles"):
        aerocontrol.solve_dare([[1e308]], [[0.345584192064786]], [[1.0]], [[0.1158]])
