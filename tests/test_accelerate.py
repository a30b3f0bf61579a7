"""aerocontrol.accelerate_control: aerocontrol's kernels inside python-control.

The oracles are python-control's own functions, captured before patching (with slycot
installed, python-control's default method): the patched functions must return the same
values (to 1e-9 relative), raise the same exception classes with the same messages, keep the
signatures, and really call aerocontrol (counted by :func:`aerocontrol.accelerate.kernel_calls`).
The acceptance test runs python-control's own test files for these functions, unchanged, with
the patch applied by the pytest plugin ``aerocontrol._pytest_accelerate``.
"""

from __future__ import annotations

import importlib
import inspect
import json
import os
import re
import subprocess
import sys
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pytest

import aerocontrol
from aerocontrol import accelerate

control = pytest.importorskip("control")
importlib.import_module("control.matlab")  # the names are bound there too

Array = np.ndarray[Any, Any]
NAMES = (
    "lqr",
    "dlqr",
    "care",
    "dare",
    "lyap",
    "place",
    "acker",
    "place_acker",
    "ctrb",
    "obsv",
    "lqe",
    "dlqe",
)
ORIGINAL: dict[str, Callable[..., Any]] = {name: getattr(control, name) for name in NAMES}
TOLERANCE = 1e-9


def control_namespaces() -> dict[str, dict[str, int]]:
    """id() of every attribute of every imported python-control module."""
    return {
        name: {key: id(value) for key, value in vars(module).items()}
        for name, module in list(sys.modules.items())
        if isinstance(module, ModuleType) and (name == "control" or name.startswith("control."))
    }


@pytest.fixture
def patched() -> Iterator[None]:
    """python-control accelerated for one test, restored after it whatever happens."""
    assert not accelerate.is_accelerated()
    aerocontrol.accelerate_control()
    try:
        yield
    finally:
        aerocontrol.restore_control()


def counts(name: str) -> tuple[int, int]:
    calls = accelerate.kernel_calls()[name]
    return calls["aerocontrol"], calls["fallback"]


def relative(ours: Array, theirs: Array) -> float:
    return float(np.linalg.norm(np.asarray(ours) - theirs) / max(np.linalg.norm(theirs), 1e-300))


def same_eigenvalues(ours: Array, theirs: Array) -> float:
    return relative(np.sort_complex(np.asarray(ours)), np.sort_complex(np.asarray(theirs)))


def random_problem(seed: int, n: int, m: int) -> tuple[Array, Array, Array, Array]:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    B = rng.standard_normal((n, m))
    F = rng.standard_normal((n, n))
    Q = F @ F.T + np.eye(n)
    G = rng.standard_normal((m, m))
    R = G @ G.T + np.eye(m)
    return A, B, Q, R


# --- patching ----------------------------------------------------------------------------------


def test_patch_replaces_every_namespace_and_restore_is_exact() -> None:
    before = control_namespaces()
    originals = {id(f) for f in ORIGINAL.values()}
    holders = {
        (module, key)
        for module, names in before.items()
        for key, ident in names.items()
        if ident in originals
    }
    # the names live in several modules: control, statefbk, mateqn, stochsys, canonical, matlab
    assert {module for module, _ in holders} >= {
        "control",
        "control.statefbk",
        "control.mateqn",
        "control.stochsys",
        "control.canonical",
        "control.matlab",
    }
    aerocontrol.accelerate_control()
    try:
        first = control_namespaces()
        aerocontrol.accelerate_control()  # twice: harmless, the same replacements
        assert control_namespaces() == first
        for module, key in holders:
            value = getattr(sys.modules[module], key)
            assert id(value) not in originals, (module, key)
            assert value.__wrapped__ is ORIGINAL.get(key, ORIGINAL["place_acker"])
        assert control.acker is control.place_acker is control.statefbk.acker
        assert control.statefbk.care is control.mateqn.care is control.stochsys.care
        # nothing else changed
        changed = {
            (module, key)
            for module, names in first.items()
            for key, ident in names.items()
            if before.get(module, {}).get(key) != ident
        }
        assert changed == holders
    finally:
        aerocontrol.restore_control()
    assert control_namespaces() == before
    aerocontrol.restore_control()  # restoring twice is harmless
    assert control_namespaces() == before


def test_modules_imported_after_patching_are_restored(patched: None) -> None:
    fake = ModuleType("control._imported_later")
    fake.lqr = control.lqr  # type: ignore[attr-defined]   # as `from control import lqr`
    sys.modules["control._imported_later"] = fake
    try:
        aerocontrol.restore_control()
        assert fake.lqr is ORIGINAL["lqr"]  # type: ignore[attr-defined]
        aerocontrol.accelerate_control()
    finally:
        del sys.modules["control._imported_later"]


def test_context_manager_restores_and_nests() -> None:
    with aerocontrol.accelerated_control():
        assert control.lqr is not ORIGINAL["lqr"]
        with aerocontrol.accelerated_control():
            assert accelerate.is_accelerated()
        assert accelerate.is_accelerated()  # the inner block found it patched: left so
    assert control.lqr is ORIGINAL["lqr"]
    with pytest.raises(RuntimeError), aerocontrol.accelerated_control():
        raise RuntimeError("inside")
    assert control.lqr is ORIGINAL["lqr"]


def test_signatures_and_documentation_are_python_control_s(patched: None) -> None:
    for name in NAMES:
        ours = getattr(control, name)
        assert inspect.signature(ours) == inspect.signature(ORIGINAL[name]), name
        assert ours.__doc__ == ORIGINAL[name].__doc__
        assert ours.__name__ == ORIGINAL[name].__name__


def test_missing_python_control_is_a_clear_import_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "control", None)
    with pytest.raises(ImportError, match="accelerate_control needs python-control"):
        aerocontrol.accelerate_control()


# --- values against the originals --------------------------------------------------------------


@pytest.mark.parametrize(("seed", "n", "m"), [(1, 4, 1), (2, 6, 2), (3, 1, 1), (4, 9, 3)])
def test_riccati_and_regulators_agree_with_the_originals(
    patched: None, seed: int, n: int, m: int
) -> None:
    A, B, Q, R = random_problem(seed, n, m)
    N = 0.1 * np.random.default_rng(seed + 100).standard_normal((n, m))
    Ad = A / (1.5 * max(abs(np.linalg.eigvals(A))))
    cont = control.ss(A, B, np.eye(n), 0)
    disc = control.ss(Ad, B, np.eye(n), 0, 0.1)
    # (name, arguments, plant matrix A); each returns K, S and the closed-loop poles
    cases: list[tuple[str, tuple[Any, ...], Array]] = [
        ("lqr", (A, B, Q, R), A),
        ("lqr", (A, B, Q, R, N), A),
        ("lqr", (cont, Q, R), A),
        ("care", (A, B, Q, R), A),
        ("care", (A, B, Q), A),
        ("care", (A, B, Q, R, N), A),
        ("dlqr", (Ad, B, Q, R), Ad),
        ("dlqr", (Ad, B, Q, R, N), Ad),
        ("dlqr", (disc, Q, R), Ad),
        ("lqr", (disc, Q, R), Ad),  # python-control's lqr of a discrete system is dlqr
        ("dare", (Ad, B, Q, R), Ad),
        ("dare", (Ad, B, Q, R, N), Ad),
    ]
    for name, args, plant in cases:
        counted = "dlqr" if args[0] is disc else name
        before = counts(counted)[0]
        ours = getattr(control, name)(*args)
        assert counts(counted)[0] == before + 1, name
        theirs = ORIGINAL[name](*args)
        if name in ("care", "dare"):  # (X, L, G) -> (G, X, L)
            ours, theirs = (ours[2], ours[0], ours[1]), (theirs[2], theirs[0], theirs[1])
        for mine, reference in zip(ours[:2], theirs[:2], strict=True):
            assert type(mine) is np.ndarray
            assert relative(mine, reference) < TOLERANCE, name
        # slycot returns the poles in single precision: compare with eig(A - B K) of its K
        exact = np.linalg.eigvals(plant - B @ theirs[0])
        assert same_eigenvalues(ours[2], exact) < TOLERANCE, name
        assert same_eigenvalues(theirs[2], exact) < 1e-6, name


@pytest.mark.parametrize(("seed", "n", "p"), [(5, 4, 2), (6, 3, 1)])
def test_estimators_and_lyapunov_agree_with_the_originals(
    patched: None, seed: int, n: int, p: int
) -> None:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n)) - 3 * np.eye(n)
    G = np.eye(n)
    C = rng.standard_normal((p, n))
    F = rng.standard_normal((n, n))
    QN = F @ F.T + np.eye(n)
    RN = np.eye(p)
    Ad = A / (1.5 * max(abs(np.linalg.eigvals(A))))
    for name, args, plant in [
        ("lqe", (A, G, C, QN, RN), A),
        ("lqe", (control.ss(A, G, C, 0), QN, RN), A),
        ("dlqe", (Ad, G, C, QN, RN), Ad),
        ("dlqe", (control.ss(Ad, G, C, 0, 1.0), QN, RN), Ad),
    ]:
        before = counts(name)
        L, P, E = getattr(control, name)(*args)
        assert counts(name)[0] == before[0] + 1
        L0, P0, E0 = ORIGINAL[name](*args)
        assert relative(L, L0) < TOLERANCE and relative(P, P0) < TOLERANCE, name
        # slycot returns the poles in single precision: compare with eig(A - L C) of its L
        assert same_eigenvalues(E, np.linalg.eigvals(plant - L0 @ C)) < TOLERANCE, name
        assert same_eigenvalues(E0, np.linalg.eigvals(plant - L0 @ C)) < 1e-6, name
    before = counts("lyap")
    X = control.lyap(A, QN)
    assert counts("lyap")[0] == before[0] + 1
    assert relative(X, ORIGINAL["lyap"](A, QN)) < TOLERANCE
    assert np.linalg.norm(A @ X + X @ A.T + QN) < 1e-13 * np.linalg.norm(QN)


@pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")  # np.asmatrix
def test_placement_and_krylov_matrices_agree_with_the_originals(patched: None) -> None:
    A, b = aerocontrol.chapter.boeing747_longitudinal()
    poles = [-1.0 + 1j, -1.0 - 1j, -0.2 + 0.1j, -0.2 - 0.1j]
    for name, args in [
        ("place", (A, b, poles)),
        ("place", (A, b[:, 0], np.array([poles]))),  # 1-D B, poles as one row
        ("acker", (A, b, poles)),
        ("ctrb", (A, b)),
        ("ctrb", (A, b[:, 0])),
        ("obsv", (A, b.T)),
        ("obsv", (A, b[:, 0])),
        ("ctrb", (np.asmatrix(A), np.asmatrix(b), 9)),
    ]:
        key = "place_acker" if name == "acker" else name
        before = counts(key)
        ours = getattr(control, name)(*args)
        assert counts(key)[0] == before[0] + 1, name
        theirs = ORIGINAL[name](*args)
        assert type(ours) is np.ndarray and ours.shape == np.shape(theirs), name
        assert relative(ours, theirs) < 1e-8, name
    # several inputs: the gain is not unique; the same poles are placed
    A, B = aerocontrol.chapter.boeing747_lateral()
    wanted = [-0.5 + 0.8j, -0.5 - 0.8j, -1.2, -0.1]
    K = control.place(A, B, wanted)
    assert same_eigenvalues(np.linalg.eigvals(A - B @ K), np.array(wanted)) < 1e-10


# --- errors and fallbacks ----------------------------------------------------------------------


def raised(function: Callable[..., Any], *args: Any, **kwargs: Any) -> BaseException:
    with pytest.raises(Exception) as info:
        function(*args, **kwargs)
    return info.value


@pytest.mark.parametrize(
    ("name", "args", "kwargs"),
    [
        ("lqr", (np.eye(2), np.ones((3, 1)), np.eye(2), 1), {}),  # B rows: ControlDimension
        ("lqr", (np.eye(2), np.ones((2, 1)), [[1, 2], [0, 1]], 1), {}),  # Q: ControlArgument
        ("lqr", (np.eye(2), np.ones((2, 1))), {}),  # too few arguments: ControlArgument
        ("care", (np.eye(2), np.ones((2, 1)), np.eye(3)), {}),
        ("lyap", (np.eye(2), [[1.0, 2.0], [0.0, 1.0]]), {}),  # non-symmetric Q
        ("lyap", (np.ones((2, 3)), np.eye(2)), {}),
        ("dare", (np.eye(2), np.ones((2, 1)), np.eye(2), np.eye(2)), {}),
        ("place", (np.eye(2), np.ones((3, 1)), [-1, -2]), {}),
        ("place", (np.eye(2), np.ones((2, 1)), [-1, -1]), {}),  # repeated beyond rank B
        ("acker", ([[1.0, 0.0], [0.0, 1.0]], [[1.0], [1.0]], [-1, -2]), {}),  # not reachable
        ("ctrb", (np.ones((2, 3)), np.ones((2, 1))), {}),
        ("obsv", (np.eye(2), np.ones((1, 3))), {}),
        ("lqe", (np.eye(2), np.eye(2), np.ones((1, 2)), np.eye(3), 1), {}),
        ("lqr", (control.tf([1], [1, 1]), 1, 1), {}),  # not in state-space form
        ("dlqr", (control.ss(-1, 1, 1, 0), 1, 1), {}),  # continuous system
        ("lqr", (np.eye(2), np.ones((2, 1)), np.eye(2), 1), {"bad": 1}),  # unknown keyword
    ],
)
def test_errors_are_python_control_s(
    patched: None, name: str, args: tuple[Any, ...], kwargs: dict[str, Any]
) -> None:
    ours = raised(getattr(control, name), *args, **kwargs)
    theirs = raised(ORIGINAL[name], *args, **kwargs)
    assert type(ours) is type(theirs), (ours, theirs)
    assert str(ours) == str(theirs)
    assert not isinstance(ours, aerocontrol.AerocontrolError)


def test_uncovered_options_fall_back_to_the_original(patched: None) -> None:
    A, B, Q, R = random_problem(7, 3, 1)
    E = np.eye(3) + 0.1 * np.triu(np.ones((3, 3)), 1)
    for name, args, kwargs in [
        ("care", (A, B, Q, R), {"method": "scipy"}),
        ("care", (A, B, Q, R, None, E), {}),
        ("care", (A, B, Q, R), {"stabilizing": False}),
        ("lyap", (A - 5 * np.eye(3), Q, np.ones((3, 3))), {}),  # Sylvester
        ("lqr", (A, B, Q, R), {"method": "slycot"}),
        ("ctrb", (A, B, 2), {}),
    ]:
        before = counts(name)
        ours = getattr(control, name)(*args, **kwargs)
        assert counts(name)[1] == before[1] + 1, name
        theirs = ORIGINAL[name](*args, **kwargs)
        for mine, reference in zip(
            ours if isinstance(ours, tuple) else (ours,),
            theirs if isinstance(theirs, tuple) else (theirs,),
            strict=True,
        ):
            np.testing.assert_allclose(mine, reference, rtol=1e-12)
    # integral action: lqr falls back, and python-control's lqr then calls the patched care
    before_care = counts("care")[0]
    C = np.array([[1.0, 0.0, 0.0]])
    K, S, _ = control.lqr(A, B, np.eye(4), R, integral_action=C)
    assert counts("care")[0] == before_care + 1
    K0, S0, _ = ORIGINAL["lqr"](A, B, np.eye(4), R, integral_action=C)
    assert relative(K, K0) < TOLERANCE and relative(S, S0) < TOLERANCE


def test_a_problem_aerocontrol_refuses_is_answered_by_the_original(patched: None) -> None:
    # An undamped mode neither controllable nor penalised: no stabilising solution.
    A, B, Q = np.diag([0.0, -1.0]), np.array([[0.0], [1.0]]), np.diag([0.0, 1.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = raised(control.care, A, B, Q)
        theirs = raised(ORIGINAL["care"], A, B, Q)
    assert type(ours) is type(theirs) and str(ours) == str(theirs)


# --- python-control's own tests, unchanged, on aerocontrol's kernels ---------------------------

CONTROL_TESTS = ["statefbk_test", "mateqn_test", "stochsys_test", "canonical_test", "matlab_test"]


@pytest.fixture(scope="session")
def control_test_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, dict[str, Any]]:
    """python-control's test files for these functions, run once with the plugin: (the
    report's summary line, the call counts)."""
    folder = tmp_path_factory.mktemp("control_tests")
    calls = folder / "calls.json"
    source = Path(aerocontrol.__file__).parent.parent
    environment = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(source), os.environ.get("PYTHONPATH")])),
        "AEROCONTROL_ACCELERATE_CALLS": str(calls),
    }
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "-p",
            "no:randomly",
            "-p",
            "aerocontrol._pytest_accelerate",
            "--pyargs",
            *(f"control.tests.{name}" for name in CONTROL_TESTS),
        ],
        cwd=folder,
        env=environment,
        capture_output=True,
        text=True,
        timeout=600,
    )
    summary = result.stdout.strip().splitlines()[-1] if result.stdout.strip() else ""
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    return summary, json.loads(calls.read_text())


def test_python_control_s_own_tests_pass_accelerated(
    control_test_run: tuple[str, dict[str, Any]],
) -> None:
    summary, calls = control_test_run
    # 204 tests pass and 2 are expected failures on python-control 0.10.2 without the patch
    outcomes = {word: int(count) for count, word in re.findall(r"(\d+) (\w+)", summary)}
    assert set(outcomes) <= {"passed", "xfailed", "skipped", "warnings"}, summary
    assert outcomes["passed"] >= 200, summary
    answered = {name: count["aerocontrol"] for name, count in calls.items()}
    assert sum(answered.values()) >= 200, answered
    assert answered["lqr"] >= 100, answered
    assert all(answered[name] >= 1 for name in answered), answered
