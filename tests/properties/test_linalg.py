"""Properties of the matrix exponential, the transition matrices, exact discretisation and the
real Schur form (aerocontrol.linalg).

Oracles: the exponential in extended precision (within its estimated condition number), Van Loan's
block exponential likewise for the discretisation, and for the Schur form the
reconstruction Q T Q^T = A, orthogonality, the block structure, eigenvalue backward errors and
the selection.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import aerocontrol
from aerocontrol.exceptions import IllConditionedError, IllConditionedWarning

from .harness import CALLBACK, Arg, CallerError, Warned, exercise, plain
from .oracles import (
    SLACK,
    TINY,
    U,
    assert_exponential,
    assert_spectrum,
    assert_within,
    exponential_tolerance,
    finite,
    norm,
    quietly,
    van_loan,
)
from .strategies import (
    SCALAR_PRESENTATIONS,
    canonical,
    orders,
    presented,
    rectangular,
    scalar,
    square,
)

COVERED = {"expm", "transition_matrix", "discretize", "schur"}


def _expm_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A = args["A"]
    assert result.shape == A.shape and result.dtype == np.float64
    if A.ndim == 3:
        # A stack is exponentiated matrix by matrix, exactly as each alone.
        for k in range(A.shape[0]):
            alone = quietly(aerocontrol.expm, A[k])
            assert np.array_equal(result[k], alone, equal_nan=True), f"stack member {k}"
        return
    assert_exponential(result, A, "expm", warned)


@given(st.data())
def test_expm(data: st.DataObject) -> None:
    n = data.draw(orders())
    members = data.draw(st.sampled_from((None, None, None, 0, 1, 3)))
    if members is None:
        A = data.draw(square(n))
    else:
        A = np.stack([data.draw(square(n)) for _ in range(members)] or [np.zeros((n, n))])
        A = A[:members]
    exercise("expm", aerocontrol.expm, {"A": data.draw(presented(A))}, _expm_oracle)


TIMES = st.sampled_from((0.0, 1.0, -1.0, 0.1, 2.5, -3.0, 1e-300, 5e-324, 1e3, 1e300, np.nan))


def _transition_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, t = args["A"], np.asarray(args["t"])
    n = A.shape[0]
    times = t.reshape(-1)
    Phi = result.reshape(len(times), n, n)
    assert result.shape == ((n, n) if t.ndim == 0 else (len(times), n, n))
    for k, time in enumerate(times):
        if time == 0.0:
            assert np.array_equal(Phi[k], np.eye(n)), "Phi(0) = I exactly (6.24)"
        else:
            assert_exponential(Phi[k], quietly(np.multiply, A, time), f"Phi({time})", warned)


@given(st.data())
def test_transition_matrix(data: st.DataObject) -> None:
    n = data.draw(orders())
    A = data.draw(square(n))
    shape = data.draw(st.sampled_from(("scalar", "vector", "vector", "empty", "matrix")))
    if shape == "scalar":
        t = data.draw(scalar(data.draw(TIMES), kinds=SCALAR_PRESENTATIONS[:-1]))
    else:
        count = {"vector": data.draw(st.integers(1, 4)), "empty": 0, "matrix": 4}[shape]
        times = np.array([data.draw(TIMES) for _ in range(count)])
        t = data.draw(presented(times.reshape(2, 2) if shape == "matrix" else times))
    exercise(
        "transition_matrix",
        aerocontrol.transition_matrix,
        {"A": data.draw(presented(A)), "t": t},
        _transition_oracle,
    )


def _discretize_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    """Van Loan (1978) in extended precision (oracles.van_loan), with the blocks scaled by
    dt so that their accuracy is relative to Γ/dt, not to Φ: for
    N = [[A dt, B, 0], [0, 0, I], [0, 0, 0]], G = e^N gives Φ = G11, Γ0 = dt G12,
    Γ1 = dt G13 (exp(M dt) = D^-1 e^N D with D = diag(I, dt I, dt² I))."""
    A, dt, method = args["A"], float(args["dt"]), args["method"]
    B = np.asarray(args["B"], dtype=float)
    B = B.reshape(-1, 1) if B.ndim == 1 else B
    n, m = B.shape
    assert result.Phi.shape == (n, n) and result.Gamma0.shape == (n, m)
    assert result.dt == dt and result.method == method
    assert (result.Gamma1 is None) == (method == "zoh")
    if not finite(A) or not np.isfinite(dt):
        return
    N, G, Phi, Gamma0, Gamma1, beta = (
        quietly(np.asarray, x, dtype=np.float64) for x in van_loan(A, B, dt)
    )
    if not finite(G) or np.max(np.abs(G), initial=0.0) * max(dt, 1.0) * beta >= 1e300:
        return
    blocks = [result.Phi, result.Gamma0] + [result.Gamma1] * (result.Gamma1 is not None)
    if np.sum(np.abs(N[:n, :n]), axis=0).max(initial=0.0) >= 2.0**53 and finite(*blocks):
        # Φ = e^{A dt}: as for the exponential, whose rounding alone then changes every digit,
        # a finite result must say so (an overflowed one says so with its own warning).
        assert IllConditionedWarning in warned, "||A dt||_1 >= 2^53 without a warning"
    # Φ, Γ0 and Γ1 are representable: no NaN, and no infinity unless ill-conditioned.
    assert not any(np.any(np.isnan(b)) for b in blocks), "NaN in a finite discretisation"
    if IllConditionedWarning in warned:
        return
    assert finite(*blocks), "an infinity in a finite discretisation"
    # Relative to ||e^N||, times β dt for the Γ blocks, and at least TINY where they underflow.
    bound = exponential_tolerance(N, G)
    floor = SLACK * (n + 2 * m) * TINY
    assert_within(norm(result.Phi - Phi), bound, "Phi against Van Loan")
    assert_within(norm(result.Gamma0 - Gamma0), bound * beta * dt + floor, "Gamma0")
    if result.Gamma1 is not None:
        assert_within(norm(result.Gamma1 - Gamma1), bound * beta * dt + floor, "Gamma1")


STEPS = st.sampled_from((0.1, 1.0, 0.01, 5e-324, 1e-300, 1e3, 1e300, 0.0, -0.1, np.inf, np.nan))
METHODS = st.sampled_from(("zoh", "foh", "zoh", "foh", "ZOH", "", "euler", 3))


@given(st.data())
def test_discretize(data: st.DataObject) -> None:
    n, m = data.draw(orders()), data.draw(st.integers(0, 3))
    A = data.draw(square(n))
    B = data.draw(rectangular(n, m))
    if m == 1 and data.draw(st.booleans()):
        B = B[:, 0]  # one input as a vector
    exercise(
        "discretize",
        aerocontrol.discretize,
        {
            "A": data.draw(presented(A)),
            "B": data.draw(presented(B)),
            "dt": data.draw(scalar(data.draw(STEPS))),
            "method": plain(data.draw(METHODS)),
        },
        _discretize_oracle,
    )


# ----- the real Schur form ----------------------------------------------------------------------


def _selector(kind: str) -> Any:
    if kind == "raises":

        def select(z: complex) -> bool:
            raise CallerError("raised by the caller's select")

        return select
    if kind == "numpy bool":
        return lambda z: np.bool_(z.imag != 0)
    if kind == "stable and slow":
        return lambda z: z.real < 0 and abs(z) < 2
    if kind == "not callable":
        return 42
    return {"none": None, "lhp": "lhp", "rhp": "rhp", "iuc": "iuc", "ouc": "ouc", "bad": "left"}[
        kind
    ]


SELECTORS = ("none", "lhp", "rhp", "iuc", "ouc", "numpy bool", "stable and slow", "raises")
SELECTORS_REFUSED = ("bad", "not callable")


def _selected(select: Any, z: complex) -> bool:
    if select is None:
        return True
    from aerocontrol.linalg import SELECTIONS

    function = SELECTIONS[select] if isinstance(select, str) else select
    return bool(function(complex(z.real, abs(z.imag))))


def _schur_oracle(result: Any, args: dict[str, Any], warned: Warned) -> None:
    A, select = args["A"], args["select"]
    T, Q, eigenvalues = result
    n = A.shape[0]
    assert T.shape == Q.shape == (n, n) and eigenvalues.shape == (n,)
    if not finite(A):
        return
    # T and Q are bounded (||T||_F = ||A||_F, Q orthogonal): nothing can overflow.
    if norm(A) < 1e300:
        assert finite(T, Q, eigenvalues), f"NaN or Inf in the Schur form of a finite A ({warned})"
    scale = SLACK * n * U
    assert_within(norm(Q.T @ Q - np.eye(n)), scale, "Q^T Q = I")
    assert_within(norm(Q @ T @ Q.T - A), scale * norm(A) + SLACK * n * TINY, "Q T Q^T = A")
    # Quasi-triangular: exact zeros below the subdiagonal, and no two adjacent subdiagonal
    # entries nonzero; a 2 x 2 block holds a complex pair (standard form: equal diagonal).
    assert not np.any(np.tril(T, -2)), "T has entries below its subdiagonal"
    sub = np.diag(T, -1)
    assert not np.any((sub[:-1] != 0) & (sub[1:] != 0)), "T has a 3 x 3 block"
    for k in np.flatnonzero(sub):
        assert T[k, k] == T[k + 1, k + 1], f"2 x 2 block {k} not in standard form"
        assert np.sign(T[k, k + 1]) * np.sign(T[k + 1, k]) < 0, f"2 x 2 block {k} is real"
        assert eigenvalues[k].imag > 0 and eigenvalues[k + 1] == np.conj(eigenvalues[k])
    assert_spectrum(A, eigenvalues, "schur eigenvalues")
    if select is not None:
        # The selected eigenvalues come first. An eigenvalue within its backward error of the
        # boundary of the selection may count as either.
        radius = scale * (norm(A) + TINY)
        sides = [_side(select, complex(z), radius) for z in eigenvalues]
        if "in" in sides and "out" in sides:
            last_in = len(sides) - 1 - sides[::-1].index("in")
            assert last_in < sides.index("out"), (
                f"a selected eigenvalue after a rejected one: {eigenvalues}, {sides}"
            )


def _side(select: Any, z: complex, radius: float) -> str:
    """ "in" or "out" of the selection, or "edge" if a perturbation by ``radius`` changes it."""
    verdicts = {_selected(select, z + d) for d in (0, radius, -radius, 1j * radius, -1j * radius)}
    return "edge" if len(verdicts) == 2 else "in" if verdicts == {True} else "out"


@given(st.data())
def test_schur(data: st.DataObject) -> None:
    n = data.draw(orders())
    A = data.draw(square(n))
    kind = data.draw(st.sampled_from(SELECTORS + SELECTORS_REFUSED))
    select = _selector(kind)
    outcome = exercise(
        "schur",
        aerocontrol.schur,
        {
            "A": data.draw(presented(A)),
            "select": Arg(select, select, kind, CALLBACK if kind == "raises" else "same"),
        },
        _schur_oracle,
    )
    if kind in SELECTORS_REFUSED:
        assert outcome.error is not None, f"select={kind} was accepted"
    if kind == "raises" and n and finite(A) and outcome.error is None:
        raise AssertionError("the select callable raised, and schur returned")


# ----- known defects of the core (see known_defects.py) ------------------------------------------


SCHUR_EXTREME_EXAMPLES = {
    "huge entry": np.array([[1e300, -0.13, 0.64], [0.10, -0.54, 0.36], [1.30, 0.95, -0.70]]),
    "tiny entry": np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1e-300, 0.0, -1.0]]),
    "subnormal": np.array([[1e-310]]),
}


@pytest.mark.parametrize("example", SCHUR_EXTREME_EXAMPLES)
def test_schur_extreme_entries(example: str) -> None:
    """Entries whose squares leave the normal range (once returned unreduced or NaN)."""
    A = SCHUR_EXTREME_EXAMPLES[example]
    exercise("schur", aerocontrol.schur, {"A": canonical(A), "select": plain(None)}, _schur_oracle)


def test_schur_reordering_of_tiny_entries() -> None:
    """The reordering of a Schur form of entries near 1e-300 (its swaps compared with absolute
    thresholds: residual 6.5e-301 for a matrix of norm 2e-300)."""
    A = 1e-301 * np.array(
        [[4.0313, 8.5368, -10.546], [11.535, -9.0528, -0.13459], [5.5115, 1.1740, 3.6542]]
    )
    select = _selector("rhp")
    exercise(
        "schur",
        aerocontrol.schur,
        {"A": canonical(A), "select": Arg(select, select, "rhp", "same")},
        _schur_oracle,
    )


def test_discretize_warns_beyond_2_to_53() -> None:
    """||A dt|| = 1.4e149 (n = 1, m = 0): the IllConditionedWarning of expm, once missing."""
    outcome = exercise(
        "discretize",
        aerocontrol.discretize,
        {
            "A": canonical(np.array([[-1.4308730228590872e150]])),
            "B": canonical(np.zeros((1, 0))),
            "dt": plain(0.1),
            "method": plain("zoh"),
        },
        _discretize_oracle,
    )
    assert IllConditionedWarning in outcome.warned


def test_transition_huge_times() -> None:
    """Φ(1e155) of A = 0 is I (the powers of A and of t, formed apart, once gave 0 · inf)."""
    exercise(
        "transition_matrix",
        aerocontrol.transition_matrix,
        {"A": canonical(np.zeros((3, 3))), "t": plain(1e155)},
        _transition_oracle,
    )


def test_exponential_huge_norm() -> None:
    """e^A of a rotation by 1e50 rad: refused as ill-conditioned (was all NaN)."""
    rotation = np.array([[0.0, 1e50], [-1e50, 0.0]])
    outcome = exercise("expm", aerocontrol.expm, {"A": canonical(rotation)}, _expm_oracle)
    assert isinstance(outcome.error, IllConditionedError), outcome


def test_discretize_huge_rotation() -> None:
    """A rotation by 2e299 rad per step (Phi was once 0), with the IllConditionedWarning."""
    rotation = np.array([[0.0, 2e300], [-2e300, 0.0]])
    exercise(
        "discretize",
        aerocontrol.discretize,
        {
            "A": canonical(rotation),
            "B": canonical(np.zeros((2, 1))),
            "dt": plain(0.1),
            "method": plain("zoh"),
        },
        _discretize_oracle,
    )
