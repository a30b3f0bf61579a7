"""The guarantees of "What aerocontrol promises" (docs/promises.md) that concern computations:
memory layouts, Ctrl-C, the GIL, memory limits, zero-size work and overflow.

Interrupts and memory limits are tested in child processes, so that a failure (an abort, a hang)
cannot take the test session with it.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import threading
import time
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import aerocontrol
from aerocontrol.exceptions import NumericalOverflowWarning


def _child(code: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )


# ----- layouts ----------------------------------------------------------------------------------


def _layouts(a: np.ndarray) -> dict[str, np.ndarray]:
    """Arrays equal to ``a`` (C-ordered float64) in other memory layouts."""
    big = np.zeros(tuple(2 * d for d in a.shape))
    strided = big[(slice(None, None, 2),) * a.ndim]
    strided[...] = a
    buffer = bytearray(a.nbytes + 1)
    misaligned = np.frombuffer(buffer, dtype=np.float64, count=a.size, offset=1).reshape(a.shape)
    misaligned[...] = a
    reversed_view = np.ascontiguousarray(a[(slice(None, None, -1),) * a.ndim])[
        (slice(None, None, -1),) * a.ndim
    ]
    return {
        "fortran": np.asfortranarray(a),
        "transposed": np.ascontiguousarray(a.T).T,
        "strided": strided,
        "negative strides": reversed_view,
        "misaligned": misaligned,
        "big-endian": a.astype(">f8"),
        "read-only": np.frombuffer(a.tobytes(), dtype=np.float64).reshape(a.shape),
    }


def test_stacks_of_every_layout_give_the_c_ordered_result() -> None:
    # The defect: a (2, 3, 3) stack in Fortran order was read as C-ordered (wrong by O(1)).
    a = np.random.default_rng(1).standard_normal((2, 3, 3))
    expected = aerocontrol.expm(a)
    for name, array in _layouts(a).items():
        assert np.array_equal(aerocontrol.expm(array), expected), name


def test_every_argument_of_every_layout_gives_the_c_ordered_result() -> None:
    rng = np.random.default_rng(2)
    A = rng.standard_normal((4, 4)) - 3 * np.eye(4)
    B = rng.standard_normal((4, 2))
    C = rng.standard_normal((3, 4))
    D = rng.standard_normal((3, 2))
    calls: dict[str, Callable[[np.ndarray], Any]] = {
        "expm": lambda a: aerocontrol.expm(a),
        "transition_matrix": lambda a: aerocontrol.transition_matrix(a, [0.5, 1.0]),
        "discretize": lambda b: aerocontrol.discretize(A, b, 0.1, "foh").Gamma1,
        "schur": lambda a: aerocontrol.schur(a)[0],
        "solve_lyapunov": lambda a: aerocontrol.solve_lyapunov(a, np.eye(4)),
        "solve_care": lambda b: aerocontrol.solve_care(A, b, np.eye(4), np.eye(2)).X,
        "place": lambda b: aerocontrol.place(A, b, [-1, -2, -3, -4]).K,
        "ctrb": lambda b: aerocontrol.ctrb(A, b),
        "modes": lambda a: aerocontrol.modes(a).eigenvalues,
        "step_response": lambda c: (
            aerocontrol.step_response(aerocontrol.StateSpace(A, B, c, D), T=np.linspace(0, 1, 11)).y
        ),
        "frequency_response": lambda d: (
            aerocontrol.frequency_response(aerocontrol.StateSpace(A, B, C, d), [0.1, 1.0]).response
        ),
    }
    arguments = {"b": B, "c": C, "d": D}
    for name, call in calls.items():
        parameter = call.__code__.co_varnames[0]
        value = arguments.get(parameter, A)
        expected = call(value)
        for layout, array in _layouts(value).items():
            assert np.array_equal(call(array), expected), (name, layout)


def test_inputs_are_not_modified() -> None:
    A = np.asfortranarray(np.random.default_rng(3).standard_normal((5, 5)) - 4 * np.eye(5))
    B = np.arange(10.0).reshape(5, 2) ** 2
    before = (A.copy(order="K"), B.copy())
    aerocontrol.solve_care(A, B, np.eye(5), np.eye(2))
    aerocontrol.expm(A)
    aerocontrol.place(A, B, [-1, -2, -3, -4, -5])
    assert np.array_equal(A, before[0]) and A.flags.f_contiguous
    assert np.array_equal(B, before[1])


def test_poles_whose_conversion_changes_another_argument_are_safe() -> None:
    # A `poles` whose __array__ resizes A while the arguments are converted: A was read through a
    # raw view taken before, and the freed buffer was read (a crash). Every argument is now
    # converted, and copied, before anything is computed.
    A = np.diag([-1.0, -2.0, -3.0])
    B = np.array([[1.0], [1.0], [1.0]])

    class Resizing:
        def __array__(self, dtype: Any = None, copy: Any = None) -> np.ndarray:
            A.resize((1000, 1000), refcheck=False)
            return np.array([-4.0, -5.0, -6.0])

    design = aerocontrol.place_bass_gura(A, B, Resizing())
    assert A.shape == (1000, 1000)  # resized while `poles` was converted
    assert np.allclose(np.sort(design.achieved_poles.real), [-6, -5, -4])
    assert np.allclose(design.closed_loop, np.diag([-1.0, -2.0, -3.0]) - B @ design.K)


# ----- zero-size work and results with no outputs -----------------------------------------------


def test_zero_size_work_returns_at_once() -> None:
    start = time.perf_counter()
    result = aerocontrol.expm(np.empty((10**18, 0, 0)))
    assert result.shape == (10**18, 0, 0)
    # 10^18 samples of a model with neither states nor outputs.
    empty = np.empty((0, 0))
    x, y = aerocontrol._core.simulate(
        empty,
        np.empty((0, 1)),
        np.empty((0, 0)),
        np.empty((0, 1)),
        np.empty((1, 0)),
        None,
        np.ones(1),
        0.1,
        10**18,
        "zoh",
    )
    assert x.shape == (1, 10**18, 0) and y.shape == (1, 10**18, 0)
    assert time.perf_counter() - start < 1.0


def test_models_without_outputs_or_inputs_or_states_are_simulated() -> None:
    # The defect: with C of shape (0, n) every state trajectory came back as zeros.
    A, B = -np.diag([1.0, 2.0]), np.array([[1.0], [1.0]])
    t = np.linspace(0, 1, 6)
    exact_step = np.stack([1 - np.exp(-t), (1 - np.exp(-2 * t)) / 2], axis=1)
    blind = aerocontrol.StateSpace(A, B, np.zeros((0, 2)), np.zeros((0, 1)))
    for several in (False, True):
        sys_ = [blind, blind] if several else blind
        step = aerocontrol.step_response(sys_, T=t)
        x = step.x[1] if several else step.x
        assert np.allclose(x, exact_step, rtol=1e-13, atol=1e-15)
        assert step.y.shape[-1] == 0
        impulse = aerocontrol.impulse_response(sys_, T=t)
        x = impulse.x[1] if several else impulse.x
        assert np.allclose(x, np.stack([np.exp(-t), np.exp(-2 * t)], 1), rtol=1e-13)
        doublet = aerocontrol.doublet_response(sys_, T=t)
        x = doublet.x[1] if several else doublet.x
        assert np.allclose(x, np.stack([-np.exp(-t), -2 * np.exp(-2 * t)], 1), rtol=1e-13)
    initial = aerocontrol.initial_response(blind, [1.0, 1.0], T=t)
    assert np.allclose(initial.x[:, 0], np.exp(-t), rtol=1e-13)
    # No inputs: the free response still runs.
    free = aerocontrol.StateSpace(A, np.zeros((2, 0)), np.eye(2), np.zeros((2, 0)))
    assert np.allclose(aerocontrol.initial_response(free, [1.0, 0.0], T=t).y[:, 0], np.exp(-t))
    # No states: y = D η.
    gain = aerocontrol.StateSpace(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[2.5]])
    assert np.array_equal(aerocontrol.step_response(gain, T=t).y[:, 0], np.full(6, 2.5))


# ----- overflow ---------------------------------------------------------------------------------


def test_results_that_overflow_come_with_a_warning() -> None:
    # The defect: B η0 overflowing gave infinite states without a word.
    sys_ = aerocontrol.StateSpace(-np.eye(2), [[1e300], [1.0]], np.eye(2), np.zeros((2, 1)))
    with pytest.warns(NumericalOverflowWarning, match="states x"):
        response = aerocontrol.step_response(sys_, T=np.linspace(0, 1, 5), eta0=[1e10])
    assert not np.all(np.isfinite(response.x))
    with pytest.warns(NumericalOverflowWarning, match="steady state"):
        aerocontrol.steady_state(sys_, [1e10])
    with pytest.warns(NumericalOverflowWarning):
        aerocontrol.ctrb(np.diag([1e200, 1.0]), [[1e200], [1.0]])
    huge = aerocontrol.StateSpace(-1e-300 * np.eye(2), [[1e300], [1.0]], [[1e300, 0]], [[0.0]])
    with pytest.warns(NumericalOverflowWarning, match="DC gain"):
        assert np.isinf(aerocontrol.dc_gain(huge)[0, 0])
    # The doublet starts from A B η0: refused when that overflows, before anything runs.
    stiff = aerocontrol.StateSpace(-1e300 * np.eye(2), [[1e300], [1.0]], np.eye(2), [[0], [0]])
    with pytest.raises(aerocontrol.InvalidArgumentError, match="A B eta0"):
        aerocontrol.doublet_response(stiff, T=np.linspace(0, 1, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        aerocontrol.modes(np.diag([-1.0, 0.0]))  # infinite time constant: by definition


# ----- the GIL ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call",
    [
        lambda A, B: aerocontrol.modes(A),
        lambda A, B: aerocontrol.schur(A),
        lambda A, B: aerocontrol.controllability(A, B),
        lambda A, B: aerocontrol.solve_care(A, B, np.eye(len(A)), np.eye(B.shape[1])),
        lambda A, B: aerocontrol.place(A, B, -np.arange(1.0, len(A) + 1)),
    ],
    ids=["modes", "schur", "controllability", "solve_care", "place"],
)
def test_long_calls_release_the_gil(call: Callable[[np.ndarray, np.ndarray], Any]) -> None:
    rng = np.random.default_rng(4)
    n = 150
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 2 * np.eye(n)
    B = rng.standard_normal((n, 2))
    ticks = 0
    done = False

    def count() -> None:
        nonlocal ticks
        while not done:
            ticks += 1

    counter = threading.Thread(target=count)
    counter.start()
    try:
        time.sleep(0.05)
        before = ticks
        start = time.perf_counter()
        try:
            with warnings.catch_warnings():
                # 150 poles by 2 inputs are sensitive: the warning is not what is tested here.
                warnings.simplefilter("ignore", aerocontrol.AerocontrolWarning)
                call(A, B)
        except aerocontrol.AerocontrolError:
            pass  # a refusal after the work is as good a witness as a result
        elapsed = time.perf_counter() - start
        during = ticks - before
    finally:
        done = True
        counter.join()
    # With the GIL held for the whole call the counter could not advance; released, it runs
    # freely (millions of ticks per second), apart from the call's own Python steps.
    assert elapsed > 0.002
    assert during > 2000 * elapsed * 1000 * 0.1, (during, elapsed)


def test_threads_give_bitwise_the_results_of_one_thread() -> None:
    rng = np.random.default_rng(5)
    problems = [
        (rng.standard_normal((n, n)) / np.sqrt(n) - 2 * np.eye(n), rng.standard_normal((n, 2)))
        for n in (4, 12, 40, 90)
    ]

    def solve(A: np.ndarray, B: np.ndarray) -> list[np.ndarray]:
        n = len(A)
        return [
            aerocontrol.expm(A),
            aerocontrol.solve_care(A, B, np.eye(n), np.eye(2)).X,
            aerocontrol.modes(A).eigenvalues,
            aerocontrol.step_response((A, B), T=np.linspace(0, 2, 21)).x,
            aerocontrol.batch.lqr_sweep(A, B, weights=[0.5, 1.0, 2.0]).K,
        ]

    expected = [solve(A, B) for A, B in problems]
    results: dict[int, list[list[np.ndarray]]] = {}

    def work(thread: int) -> None:
        results[thread] = [solve(A, B) for A, B in problems]

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(results) == list(range(8))
    for got in results.values():
        for mine, theirs in zip(got, expected, strict=True):
            for a, b in zip(mine, theirs, strict=True):
                assert np.array_equal(a, b)


def test_results_do_not_depend_on_the_number_of_threads() -> None:
    # Large orders run faer's parallel kernels (products and LU of the exponential); the
    # reductions whose rounding would depend on the number of threads run sequentially.
    code = """
        import hashlib, numpy as np, aerocontrol
        rng = np.random.default_rng(1)
        M = rng.standard_normal((450, 450)) / np.sqrt(450) - 0.5 * np.eye(450)
        B = rng.standard_normal((450, 2))
        results = [*aerocontrol.schur(M)[:2], aerocontrol.expm(M),
                   aerocontrol.solve_lyapunov(M, np.eye(450)),
                   aerocontrol.solve_care(M[:200, :200], B[:200], np.eye(200), np.eye(2)).X]
        print([hashlib.sha256(r.tobytes()).hexdigest() for r in results])
        """
    one = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "RAYON_NUM_THREADS": "1"},
    )
    default = _child(code, timeout=300)
    assert one.returncode == 0 and default.returncode == 0, one.stderr + default.stderr
    assert one.stdout == default.stdout


# ----- Ctrl-C -----------------------------------------------------------------------------------

_INTERRUPT = """
import json, os, signal, threading, time
import numpy as np, aerocontrol
rng = np.random.default_rng(0)
work = {work}
data = work[0]()
def interrupt():
    global sent
    sent = time.perf_counter()
    os.kill(os.getpid(), signal.SIGINT)
sent = None
threading.Timer(0.4, interrupt).start()
start = time.perf_counter()
try:
    work[1](data)
    outcome = "finished"
except KeyboardInterrupt:
    outcome = "interrupted"
stopped = time.perf_counter()
cpu = time.process_time()
time.sleep(0.5)
print(json.dumps({{"outcome": outcome, "latency": stopped - (sent or stopped),
    "elapsed": stopped - start, "cpu_after": time.process_time() - cpu,
    "threads": threading.active_count()}}))
"""


@pytest.mark.parametrize(
    "work",
    # (setup, work on what setup made): the timer starts after the setup. Order 1200 keeps the
    # Schur form and the Lyapunov solve long enough (about 2 s) that the interrupt lands
    # mid-work. At n = 2500 the interrupt lands in the Hessenberg reduction of the eigenvalues
    # (about 4 s here), which stops between panels of 24 columns; it was one uninterruptible
    # call of faer's, whose latency grew as n^3 (1.1 s at n = 1500).
    # The DC gain at n = 3500 is one LU factorisation (1.7 s of latency when it was one call of
    # faer's), and Tustin's transformation at n = 3000 an LU factorisation, solves with n
    # right-hand sides and products (7.5 s): both now stop between column panels. The
    # exponential at n = 2000 (9.6 s of latency when its products and Padé solve were single
    # calls of faer's) stops between panels, and with ||A|| = 1e4 between its squarings (2.2 s
    # at n = 1000 when they were single calls; that whole call now takes 0.4 s, as long as the
    # timer, hence n = 1500).
    # Pole placement at n = 300 forms a subspace per pole (a product and a QR each) with no
    # check between poles (2.0 s of latency), then complex LU solves; the QZ form at n = 3500
    # starts with the QR of B and two applications of its Q (1.4 s of latency): they now stop
    # between poles, and between blocks of columns.
    [
        "(lambda: rng.standard_normal((1200, 1200)), aerocontrol.schur)",
        "(lambda: np.geomspace(1e-3, 10, 2_000_000), lambda c: aerocontrol.batch.lqr_sweep("
        "aerocontrol.aircraft.load().lateral(), weights=c))",
        "(lambda: rng.standard_normal((1_000_000, 6, 6)), aerocontrol.expm)",
        "(lambda: rng.standard_normal((1200, 1200)) - 40 * np.eye(1200), "
        "lambda a: aerocontrol.solve_lyapunov(a, np.eye(1200)))",
        "(lambda: rng.standard_normal((2500, 2500)), aerocontrol.linalg.eigenvalues)",
        "(lambda: (rng.standard_normal((3500, 3500)) - 60 * np.eye(3500), "
        "rng.standard_normal((3500, 2)), rng.standard_normal((2, 3500)), np.zeros((2, 2))), "
        "aerocontrol.dc_gain)",
        "(lambda: aerocontrol.StateSpace(rng.standard_normal((3000, 3000)) - 60 * np.eye(3000), "
        "rng.standard_normal((3000, 2)), rng.standard_normal((2, 3000)), np.zeros((2, 2))), "
        "lambda sys: aerocontrol.c2d(sys, 0.01, 'tustin'))",
        "(lambda: 3 / np.sqrt(2000) * rng.standard_normal((2000, 2000)), aerocontrol.expm)",
        "(lambda: 1e4 / np.sqrt(1500) * rng.standard_normal((1500, 1500)), aerocontrol.expm)",
        "(lambda: (rng.standard_normal((300, 300)), rng.standard_normal((300, 2)), "
        "-1 - np.arange(300) / 30), lambda d: aerocontrol.place(*d))",
        "(lambda: (rng.standard_normal((3500, 3500)), rng.standard_normal((3500, 3500))), "
        "lambda d: aerocontrol.linalg.qz(*d))",
    ],
    ids=[
        "schur n=1200",
        "lqr_sweep 2e6",
        "expm stack 1e6",
        "lyapunov n=1200",
        "eigenvalues n=2500",
        "dc_gain n=3500",
        "c2d tustin n=3000",
        "expm n=2000",
        "expm n=1500 squarings",
        "place n=300",
        "qz n=3500",
    ],
)
def test_ctrl_c_stops_a_long_computation_within_a_second(work: str) -> None:
    result = _child(_INTERRUPT.format(work=work))
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["outcome"] == "interrupted", report
    assert report["latency"] < 1.0, report
    # Nothing goes on computing after the call returned.
    assert report["cpu_after"] < 0.05, report
    assert report["threads"] == 1, report


# ----- memory -----------------------------------------------------------------------------------

_LIMITED = """
import resource
limit = {limit}
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
import json
import numpy as np, aerocontrol
import_size = int(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1])
outcomes = {{}}
rng = np.random.default_rng(0)
for n in (4, 30, 100, 300):
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 2 * np.eye(n)
    B = rng.standard_normal((n, 2))
    calls = {{
        "expm": lambda: aerocontrol.expm(A),
        "modes": lambda: aerocontrol.modes(A),
        "schur": lambda: aerocontrol.schur(A),
        "solve_lyapunov": lambda: aerocontrol.solve_lyapunov(A, np.eye(n)),
        "solve_care": lambda: aerocontrol.solve_care(A, B, np.eye(n), np.eye(2)),
        "controllability": lambda: aerocontrol.controllability(A, B),
        "bode": lambda: aerocontrol.bode((A, B)),
    }}
    for name, call in calls.items():
        try:
            call()
            outcomes[f"{{name}} {{n}}"] = "ok"
        except MemoryError:
            outcomes[f"{{name}} {{n}}"] = "MemoryError"
try:
    aerocontrol.expm(np.broadcast_to(np.eye(3), (10**9, 3, 3)))
    outcomes["huge"] = "ok"
except MemoryError:
    outcomes["huge"] = "MemoryError"
print(json.dumps({{"import_kib": import_size, "outcomes": outcomes}}))
"""


@pytest.mark.parametrize("limit_mb", [600, 1450])
def test_an_address_space_limit_gives_memory_errors_never_an_abort(limit_mb: int) -> None:
    result = _child(_LIMITED.format(limit=limit_mb * 10**6), timeout=300)
    # An abort (SIGABRT) would be a negative return code and no report.
    assert result.returncode == 0, result.stderr[-2000:]
    report = json.loads(result.stdout)
    outcomes = report["outcomes"]
    assert set(outcomes.values()) <= {"ok", "MemoryError"}
    assert outcomes["huge"] == "MemoryError"
    # Small models never multiply through faer's large-product kernel, so they need no
    # workspace and work under any limit that lets the package import.
    assert all(outcomes[f"{name} 4"] == "ok" for name in ("expm", "modes", "solve_care"))
    if limit_mb >= 1450:
        # The limit: everything up to n = 300 succeeds (one product workspace is
        # twice the L3 cache, 520 MiB on machines that report a server's 260 MiB).
        assert all(value == "ok" for key, value in outcomes.items() if key != "huge"), outcomes


def test_importing_takes_little_address_space() -> None:
    result = _child(
        """
        import aerocontrol
        print(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1])
        """
    )
    assert result.returncode == 0, result.stderr
    # numpy alone takes about 140 MB (OpenBLAS's buffers); mimalloc once reserved 1 GiB.
    assert int(result.stdout) < 400_000
