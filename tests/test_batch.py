"""Batches of Riccati equations: equal to the one-at-a-time results bitwise (a sweep over R
bitwise at the first weight of each group, within 1e-13 elsewhere), to scipy within 1e-10,
and an error names the failing problem's index."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import scipy.linalg as sl

import aerocontrol
from aerocontrol import batch
from aerocontrol.batch import lqr_sweep, solve_care_batch

LATERAL = aerocontrol.aircraft.load().lateral()
WEIGHTS = np.geomspace(1e-3, 10.0, 200)


#: Consecutive weights per task of a sweep (rust/control/batch.rs SWEEP_GROUP): the first of
#: each is solved by the Schur method, the others by Newton's method from the ones before.
SWEEP_GROUP = 32


def _sorted_poles(poles: np.ndarray) -> np.ndarray:
    return np.array(sorted(poles, key=lambda z: (round(z.real, 9), z.imag)))


@pytest.mark.parametrize("order", ["increasing", "reversed", "shuffled"])
def test_sweep_equals_one_lqr_at_a_time(order: str) -> None:
    """Bitwise at each group's first weight (the Schur method, as lqr solves it); elsewhere
    Newton's method from the weights before agrees with lqr to 1e-13 relative in X and K
    (measured 6e-15 over 1000 weights) and to 1e-12 in the poles, with residuals of at most
    a few units of rounding, whichever order the weights come in."""
    weights = {
        "increasing": WEIGHTS,
        "reversed": WEIGHTS[::-1],
        "shuffled": np.random.default_rng(3).permutation(WEIGHTS),
    }[order]
    sweep = lqr_sweep(LATERAL, weights=weights)
    assert sweep.K.shape == (200, 2, 4) and sweep.poles.shape == (200, 4) and len(sweep) == 200
    for k, c in enumerate(weights):
        K, S, E = aerocontrol.lqr(LATERAL.A, LATERAL.B, np.eye(4), np.eye(2) / c**2)
        if k % SWEEP_GROUP == 0:
            assert np.array_equal(sweep.K[k], K)
            assert np.array_equal(sweep.X[k], S)
            assert np.array_equal(sweep.poles[k], E)
        assert np.linalg.norm(sweep.X[k] - S) <= 1e-13 * np.linalg.norm(S)
        assert np.linalg.norm(sweep.K[k] - K) <= 1e-13 * np.linalg.norm(K)
        np.testing.assert_allclose(_sorted_poles(sweep.poles[k]), _sorted_poles(E), rtol=1e-12)
    np.testing.assert_array_equal(sweep.weights, weights)
    assert sweep.residual.max() < 1e-14


def test_sweep_refuses_what_the_single_solver_refuses_near_the_axis() -> None:
    """A weakly controllable undamped mode seen by a tiny weight, swept from large to small c:
    the Schur method fails from some weight on, in the middle of a group, where Newton's
    method from the weights before could still converge; the sweep leaves such weights (a
    closed-loop eigenvalue within sqrt(u) of the axis) to the Schur method, and so fails at
    the same weight with the same error."""
    A, B, Q = np.array([[0.0, 2.0], [-2.0, 0.0]]), np.array([[0.0], [1e-3]]), np.diag([1e-6, 0])
    weights = np.geomspace(10.0, 1e-6, 200)
    first = None
    for k, c in enumerate(weights):
        try:
            aerocontrol.solve_care(A, B, Q, np.eye(1) / c**2)
        except aerocontrol.AerocontrolError as error:
            first = (k, type(error))
            break
    assert first is not None and first[0] % SWEEP_GROUP != 0
    with pytest.raises(first[1], match=rf"^problem {first[0]} of the batch"):
        lqr_sweep(A, B, Q, np.eye(1), weights=weights)


def test_sweep_does_not_depend_on_the_threads() -> None:
    """The groups are fixed, so one thread and every thread give the same bits."""
    sweep = lqr_sweep(LATERAL, weights=WEIGHTS)
    with aerocontrol.limit_threads(1):
        single_thread = lqr_sweep(LATERAL, weights=WEIGHTS)
    for name in ("K", "X", "poles", "residual", "rcond"):
        np.testing.assert_array_equal(getattr(single_thread, name), getattr(sweep, name))


def test_sweep_against_scipy() -> None:
    """Within 1e-10 relative of scipy's solution on every weight where scipy is accurate
    (its own residual below 1e-10)."""
    sweep = lqr_sweep(LATERAL.A, LATERAL.B, np.eye(4), np.eye(2), weights=WEIGHTS[::10])
    for k, c in enumerate(WEIGHTS[::10]):
        X = scipy.linalg.solve_continuous_are(LATERAL.A, LATERAL.B, np.eye(4), np.eye(2) / c**2)
        assert np.linalg.norm(sweep.X[k] - X) <= 1e-10 * np.linalg.norm(X)


def test_root_locus_and_critical_weight_use_the_sweep() -> None:
    poles = aerocontrol.design.lqr_root_locus(LATERAL, WEIGHTS)
    np.testing.assert_array_equal(poles, lqr_sweep(LATERAL, weights=WEIGHTS).poles)


def test_critical_weight_bounds_beyond_the_doubles_are_named() -> None:
    """Found by a hunt: bounds (1e-300, 1e300) were refused as "weights[0] = 1e-300 is out
    of range", naming an argument critical_weight does not have. Now named bounds; the
    default bounds still give the chapter's c = 9.7727 (to 1e-4)."""
    with pytest.raises(aerocontrol.InvalidArgumentError, match="bounds") as caught:
        aerocontrol.design.critical_weight(LATERAL, bounds=(1e-300, 1e300))
    assert caught.value.argument == "bounds"
    assert aerocontrol.design.critical_weight(LATERAL) == pytest.approx(9.7727, abs=1e-4)


def test_monte_carlo_stack_with_shared_weights() -> None:
    """A stack of plants, one B, Q and R shared by all: each equals its single solve."""
    rng = np.random.default_rng(7)
    A = np.repeat(LATERAL.A[np.newaxis], 50, axis=0)
    A[:, 3, 0] *= 1 + 0.2 * rng.standard_normal(50)
    original = A.copy()
    batch = solve_care_batch(A, LATERAL.B, np.eye(4), np.eye(2))
    np.testing.assert_array_equal(A, original)  # the inputs are not modified
    for k in (0, 17, 49):
        single = aerocontrol.solve_care(A[k], LATERAL.B, np.eye(4), np.eye(2))
        assert np.array_equal(batch.X[k], single.X)
        assert np.array_equal(batch.closed_loop_poles[k], single.closed_loop_poles)
        assert batch.residual[k] == single.residual and batch.rcond[k] == single.rcond
    assert len(batch) == 50


def test_single_input_and_empty_sweeps() -> None:
    rudder = lqr_sweep(LATERAL.A, LATERAL.B[:, 0], weights=[1.0, 2.0])
    assert rudder.K.shape == (2, 1, 4)
    K, _, _ = aerocontrol.lqr(LATERAL.A, LATERAL.B[:, :1], np.eye(4), np.eye(1))
    assert np.array_equal(rudder.K[0], K)
    empty = lqr_sweep(LATERAL, weights=np.array([]))
    assert empty.K.shape == (0, 2, 4) and empty.poles.shape == (0, 4)


def test_an_error_names_the_lowest_failing_index() -> None:
    # A singular R (problem 2) is refused as solve_care refuses it; an indefinite one
    # (problem 4) is solved by the extended pencil, as solve_care solves it.
    R = np.repeat(np.eye(2)[np.newaxis], 6, axis=0)
    R[4, 0, 0] = -1.0
    R[2, 1, 1] = 0.0
    with pytest.raises(
        aerocontrol.InvalidArgumentError, match=r"^problem 2 of the batch: R must be"
    ):
        solve_care_batch(LATERAL.A, LATERAL.B, np.eye(4), R)
    with pytest.raises(aerocontrol.InvalidArgumentError, match=r"^R must be nonsingular"):
        aerocontrol.solve_care(LATERAL.A, LATERAL.B, np.eye(4), R[2])
    # No stabilising solution in problem 1 only (the chapter's undamped example, (6.5)).
    A = np.array([[[-1.0, 0.0], [0.0, -2.0]], [[0.0, 1.0], [-1.0, 0.0]]])
    with pytest.raises(aerocontrol.NoStabilizingSolutionError, match=r"^problem 1 of the batch"):
        solve_care_batch(A, [[0.0], [1.0]], np.zeros((2, 2)), [[1.0]])
    A_bad = np.repeat(LATERAL.A[np.newaxis], 3, axis=0)
    A_bad[1, 2, 2] = np.nan
    with pytest.raises(aerocontrol.NonFiniteError, match=r"^problem 1 of the batch: A must be"):
        solve_care_batch(A_bad, LATERAL.B, np.eye(4), np.eye(2))


@pytest.mark.parametrize(
    ("arguments", "error", "message"),
    [
        ({"weights": [1.0, 0.0]}, aerocontrol.InvalidArgumentError, r"weights\[1\] = 0.0"),
        ({"weights": [1.0, np.inf]}, aerocontrol.InvalidArgumentError, r"weights\[1\] = inf"),
        ({"weights": [[1.0]]}, aerocontrol.ShapeError, "weights must be a 1-D array"),
        ({}, aerocontrol.InvalidArgumentError, "weights must be given"),
        ({"weights": [1.0], "R": np.ones((2, 2, 2))}, aerocontrol.ShapeError, "R must be one"),
    ],
)
def test_bad_sweep_arguments(arguments: dict[str, object], error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        lqr_sweep(LATERAL, **arguments)  # type: ignore[arg-type]


def test_stacks_must_agree() -> None:
    A = np.repeat(LATERAL.A[np.newaxis], 3, axis=0)
    R = np.repeat(np.eye(2)[np.newaxis], 2, axis=0)
    with pytest.raises(
        aerocontrol.ShapeError,
        match=r"R must have 1 \(shared by every problem\) or as many problems as A \(3\), got 2",
    ):
        solve_care_batch(A, LATERAL.B, np.eye(4), R)
    with pytest.raises(aerocontrol.ShapeError, match=r"A must be a matrix .* or a 3-D stack"):
        solve_care_batch(np.zeros((1, 1, 4, 4)), LATERAL.B, np.eye(4), np.eye(2))


def _damper_poles(zetas: np.ndarray) -> np.ndarray:
    """The chapter's damper request (6.156) for each damping ratio: the Dutch roll moved to
    ζ at its ω_n, the roll and spiral roots kept."""
    open_loop = aerocontrol.modes(LATERAL.A)
    rows = [aerocontrol.augment_mode(open_loop, 1, zeta=float(z)) for z in zetas]
    return np.array(rows)


@pytest.mark.parametrize(
    ("method", "single", "inputs"),
    [
        ("bass-gura", aerocontrol.place_bass_gura, [0]),
        ("ackermann", aerocontrol.place_ackermann, [1]),
        ("knv", aerocontrol.place, [0, 1]),
    ],
)
def test_place_batch_equals_one_at_a_time(method: str, single: object, inputs: list[int]) -> None:
    poles = _damper_poles(np.linspace(0.15, 0.6, 12))
    B = LATERAL.B[:, inputs]
    batch = aerocontrol.batch.place_batch(LATERAL.A, B, poles, method)
    assert batch.K.shape == (12, len(inputs), 4) and len(batch) == 12
    for k in (0, 5, 11):
        design = single(LATERAL.A, B, poles[k])  # type: ignore[operator]
        assert np.array_equal(batch.K[k], design.K)
        assert np.array_equal(batch.achieved_poles[k], design.achieved_poles)
        assert batch.max_relative_error[k] == design.max_relative_error
    assert batch.max_relative_error.max() < 1e-10


def test_place_batch_over_plants_with_shared_poles() -> None:
    rng = np.random.default_rng(3)
    A = np.repeat(LATERAL.A[np.newaxis], 20, axis=0)
    A[:, 1, 0] *= 1 + 0.1 * rng.standard_normal(20)  # L'_beta, the dihedral effect, ±10 %
    poles = _damper_poles(np.array([0.3]))[0]
    batch = aerocontrol.batch.place_batch(A, LATERAL.B[:, 0], poles, "bass-gura")
    for k in range(20):
        closed = A[k] - np.outer(LATERAL.B[:, 0], batch.K[k, 0])
        np.testing.assert_allclose(
            np.sort_complex(np.linalg.eigvals(closed)), np.sort_complex(poles), rtol=1e-10
        )


def test_place_batch_errors_name_the_problem() -> None:
    poles = _damper_poles(np.array([0.2, 0.3, 0.4]))
    poles[2, 0] = -0.2 + 0.5j  # its conjugate is missing
    with pytest.raises(aerocontrol.InvalidArgumentError, match=r"^problem 2 of the batch"):
        aerocontrol.batch.place_batch(LATERAL.A, LATERAL.B[:, 0], poles, "bass-gura")
    B = np.repeat(LATERAL.B[np.newaxis, :, :1], 3, axis=0)
    B[1] = [[-1.0], [1.0], [0.0], [0.0]]
    A = np.repeat(
        np.array([[[0.0, 1.0, 0, 0], [-2, -3, 0, 0], [0, 0, -1, 0], [0, 0, 0, -4]]]), 3, 0
    )
    A[[0, 2]] = LATERAL.A
    with pytest.raises(aerocontrol.UncontrollableError, match=r"^problem 1 of the batch"):
        aerocontrol.batch.place_batch(A, B, [-1, -2, -3, -5], "knv")
    with pytest.raises(aerocontrol.InvalidArgumentError, match="method must be one of"):
        aerocontrol.batch.place_batch(LATERAL.A, LATERAL.B, poles[0], "lqr")
    with pytest.raises(aerocontrol.ShapeError, match=r"poles must be \(n,\) or \(k, n\)"):
        aerocontrol.batch.place_batch(LATERAL.A, LATERAL.B, np.ones((1, 1, 4)))
    with pytest.raises(
        aerocontrol.ShapeError,
        match=r"poles must have 1 \(shared by every problem\) or as many problems as A \(3\)",
    ):
        aerocontrol.batch.place_batch(A, B, poles[:2])


def test_batches_warn_naming_the_doubtful_problems() -> None:
    """As the single functions do: here problem 1's fourth state is barely reachable
    (κ(V) >= 1e8), problem 0 is well conditioned."""
    A = np.diag([-1.0, -2.0, -3.0, -4.0])
    b = np.array([[[1.0], [1.0], [1.0], [1.0]], [[1.0], [1.0], [1.0], [1e-9]]])
    with pytest.warns(aerocontrol.IllConditionedWarning, match=r"^1 of the 2 placements .* 1$"):
        aerocontrol.batch.place_batch(A, b, [-5.0, -6.0, -7.0, -8.0], "bass-gura")
    with pytest.warns(aerocontrol.IllConditionedWarning) as single:
        aerocontrol.place_bass_gura(A, b[1], [-5.0, -6.0, -7.0, -8.0])
    assert len(single) == 1


def test_place_batch_checks_shapes_of_an_empty_batch() -> None:
    """No problem to solve, but B must still have A's rows (an empty stack of A accepted any
    B)."""
    with pytest.raises(aerocontrol.ShapeError, match="B must have as many rows as A"):
        aerocontrol.batch.place_batch(np.zeros((0, 1, 1)), np.zeros((1, 2, 2)), [[-1.0]])


def test_batches_on_a_dask_cluster_are_bitwise_the_local_ones(
    dask_client: object, monkeypatch: pytest.MonkeyPatch
) -> None:
    from aerocontrol import batch as batch_module

    monkeypatch.setattr(batch_module, "DISTRIBUTED_CHUNK", 64)  # 300 problems in 5 chunks
    sys = aerocontrol.aircraft.load().lateral()
    rng = np.random.default_rng(4)
    A = np.repeat(sys.A[np.newaxis], 300, axis=0)
    A[:, 3, 0] *= 1 + 0.1 * rng.standard_normal(300)
    local = aerocontrol.batch.solve_care_batch(A, sys.B, np.eye(4), np.eye(2))
    remote = aerocontrol.batch.solve_care_batch(A, sys.B, np.eye(4), np.eye(2), client=dask_client)
    for name in ("X", "K", "closed_loop_poles", "residual", "rcond"):
        np.testing.assert_array_equal(getattr(remote, name), getattr(local, name))
    weights = np.geomspace(1e-2, 10, 200)
    sweep = aerocontrol.batch.lqr_sweep(sys, weights=weights)
    remote_sweep = aerocontrol.batch.lqr_sweep(sys, weights=weights, client=dask_client)
    np.testing.assert_array_equal(remote_sweep.K, sweep.K)
    np.testing.assert_array_equal(remote_sweep.poles, sweep.poles)
    sampled = aerocontrol.c2d(sys, 0.1)
    np.testing.assert_array_equal(
        aerocontrol.batch.dlqr_sweep(sampled, weights=weights, client=dask_client).K,
        aerocontrol.batch.dlqr_sweep(sampled, weights=weights).K,
    )
    # The first failing problem is named by its index in the whole batch (chunk 3, row 5).
    R = np.repeat(np.eye(2)[np.newaxis], 300, axis=0)
    R[197] = 0.0
    with pytest.raises(
        aerocontrol.exceptions.AerocontrolError, match="problem 197 of the batch"
    ) as info:
        aerocontrol.batch.solve_care_batch(A, sys.B, np.eye(4), R, client=dask_client)
    assert info.value.batch_index == 197  # type: ignore[attr-defined]
    with pytest.raises(aerocontrol.exceptions.AerocontrolError, match="problem 197 of the batch"):
        aerocontrol.batch.solve_care_batch(A, sys.B, np.eye(4), R)
    # Each chunk on a pool of two threads of its worker (the pool robustness's test counts):
    # the same numbers, for every entry point.
    threaded = aerocontrol.batch.solve_care_batch(
        A, sys.B, np.eye(4), np.eye(2), client=dask_client, worker_threads=2
    )
    np.testing.assert_array_equal(threaded.X, local.X)
    np.testing.assert_array_equal(
        aerocontrol.batch.lqr_sweep(sys, weights=weights, client=dask_client, worker_threads=2).K,
        sweep.K,
    )
    np.testing.assert_array_equal(
        aerocontrol.batch.dlqr_sweep(
            sampled, weights=weights, client=dask_client, worker_threads=2
        ).K,
        aerocontrol.batch.dlqr_sweep(sampled, weights=weights).K,
    )
    np.testing.assert_array_equal(
        aerocontrol.batch.solve_dare_batch(
            sampled.A, sampled.B, np.eye(4), np.eye(2), client=dask_client, worker_threads=2
        ).X,
        aerocontrol.batch.solve_dare_batch(sampled.A, sampled.B, np.eye(4), np.eye(2)).X,
    )


@pytest.mark.parametrize("threads", [0, -1, 1.5, True, "2"])
def test_worker_threads_is_a_positive_int(threads: object) -> None:
    sys = aerocontrol.aircraft.load().lateral()
    with pytest.raises(aerocontrol.InvalidArgumentError, match="worker_threads must be a positive"):
        aerocontrol.batch.lqr_sweep(
            sys,
            weights=[1.0],
            client=_UnusedClient(),
            worker_threads=threads,  # type: ignore[arg-type]
        )


def test_worker_threads_needs_a_client() -> None:
    with pytest.raises(aerocontrol.InvalidArgumentError, match="give it with a client"):
        aerocontrol.batch.solve_care_batch(
            -np.eye(2), np.eye(2), np.eye(2), np.eye(2), worker_threads=2
        )


class _UnusedClient:
    """A Dask client stand-in that fails if any work is sent to it."""

    def map(self, *args: object, **kwargs: object) -> None:
        raise AssertionError("an empty batch sent work to the cluster")


def test_an_empty_batch_with_a_client_is_the_local_empty_batch() -> None:
    sys = aerocontrol.aircraft.load().lateral()
    empty = np.zeros((0, 4, 4))
    local = aerocontrol.batch.solve_care_batch(empty, np.zeros((0, 4, 2)), np.eye(4), np.eye(2))
    remote = aerocontrol.batch.solve_care_batch(
        empty, np.zeros((0, 4, 2)), np.eye(4), np.eye(2), client=_UnusedClient()
    )
    assert remote.K.shape == local.K.shape == (0, 2, 4)
    sweep = aerocontrol.batch.lqr_sweep(sys, weights=[], client=_UnusedClient())
    assert sweep.K.shape == aerocontrol.batch.lqr_sweep(sys, weights=[]).K.shape


def test_sweep_weight_whose_square_is_subnormal_or_overflows() -> None:
    """R / c² is formed without squaring c where c² leaves the normal doubles: for c = 3e-162
    (c² subnormal, 2 digits) and R = 1e-20 the control weight is 1.11e303, and the gain of
    the regulator of two stable lags with that weight is B^T X / R to 1e-12 of
    lqr(A, B, Q, R / c / c); for c = 1e150 (c² = inf) and R = 1e290, R / c² = 1e-10 is
    solved, not refused as out of range."""
    A, B = np.diag([-1.0, -2.0]), np.ones((2, 1))
    for c, R in ((3e-162, 1e-20), (1e-160, 1e-30), (1e150, 1e290)):
        sweep = lqr_sweep(A, B, np.eye(2), [[R]], weights=[c])
        K, X, _ = aerocontrol.lqr(A, B, np.eye(2), [[R / c / c]])
        np.testing.assert_allclose(sweep.K[0], K, rtol=1e-12, atol=0)
        np.testing.assert_allclose(sweep.X[0], X, rtol=1e-12, atol=0)
    # the oracle: scipy's Riccati solution for R / c² = 1e-10, of normal size
    reference = scipy.linalg.solve_continuous_are(A, B, np.eye(2), [[1e-10]])
    sweep = lqr_sweep(A, B, np.eye(2), [[1e290]], weights=[1e150])
    np.testing.assert_allclose(sweep.X[0], reference, rtol=1e-9)


def test_batches_of_states_scaled_apart_are_solved_as_alone() -> None:
    """Found by a hunt: the batch solvers refused (NoStabilizingSolutionError, "problem 0 of
    the batch") the regulators of models in states scaled by 1e±6 that the single solves, with
    their exact scaling, solve. Each problem is now scaled as alone: the batch's X, K and
    poles equal the single solves' bitwise, and K that of the unscaled model transformed
    (K0 T, scipy's solve_*_are on the unscaled model) to 1e-9, mixed with a well-scaled
    problem that is left as it was."""
    rng = np.random.default_rng(11)
    A0, B0 = rng.standard_normal((4, 4)), rng.standard_normal((4, 1))
    t = np.array([1e-6, 1e6, 1e-3, 1e3])
    A = A0 * (t[np.newaxis, :] / t[:, np.newaxis])
    B, Q, R = B0 / t[:, np.newaxis], np.diag(t**2), np.eye(1)
    sampled = aerocontrol.discretize(A0, B0, dt=0.1)
    Ad = sampled.Phi * (t[np.newaxis, :] / t[:, np.newaxis])
    Bd = sampled.Gamma0 / t[:, np.newaxis]
    for solve, single, plant, gain, oracle in (
        (batch.solve_care_batch, aerocontrol.solve_care, (A, B), B0, sl.solve_continuous_are),
        (batch.solve_dare_batch, aerocontrol.solve_dare, (Ad, Bd), None, sl.solve_discrete_are),
    ):
        a, b = plant
        stack_A = np.stack([a, A0 if gain is not None else sampled.Phi])
        stack_B = np.stack([b, B0 if gain is not None else sampled.Gamma0])
        stack_Q = np.stack([Q, np.eye(4)])
        result = solve(stack_A, stack_B, stack_Q, R)
        for i in range(2):
            alone = single(stack_A[i], stack_B[i], stack_Q[i], R)
            np.testing.assert_array_equal(result.X[i], alone.X)
            np.testing.assert_array_equal(result.K[i], alone.K)
            np.testing.assert_array_equal(result.closed_loop_poles[i], alone.closed_loop_poles)
        if gain is not None:
            X0 = oracle(A0, B0, np.eye(4), R)
            K0 = B0.T @ X0
        else:
            X0 = oracle(sampled.Phi, sampled.Gamma0, np.eye(4), R)
            Bs = sampled.Gamma0
            K0 = np.linalg.solve(R + Bs.T @ X0 @ Bs, Bs.T @ X0 @ sampled.Phi)
        np.testing.assert_allclose(result.K[0], K0 * t[np.newaxis, :], rtol=1e-9)
        np.testing.assert_allclose(result.K[1], K0, rtol=1e-9)
        assert np.all(result.residual < 1e-12)
    sweep = batch.dlqr_sweep(Ad, Bd, Q, R, weights=[1.0, 2.0])
    K, X, poles = aerocontrol.dlqr(Ad, Bd, Q, R / 4.0)
    np.testing.assert_array_equal(sweep.X[1], X)
    np.testing.assert_array_equal(sweep.K[1], K)
    np.testing.assert_array_equal(sweep.poles[1], poles)
