"""The type information shipped with the package cannot drift from the code.

* ``mypy.stubtest`` compares ``_core.pyi`` with the compiled module: every function, argument
  kind and constant in one must be in the other.
* ``mypy --strict`` type-checks the package against those stubs.
* ``mypy --strict`` type-checks ``tests/typing/usage.py``, the public API called as the README
  and the docstrings call it (lists, tuples, numpy arrays, StateSpace, foreign models, axes),
  with ``assert_type`` on the results and calls that must be refused: an annotation too narrow,
  too wide or wrong fails it. The script also runs, so its calls are ones the package accepts.
"""

from __future__ import annotations

import runpy
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

import aerocontrol

PACKAGE = Path(aerocontrol.__file__).parent
ROOT = Path(__file__).resolve().parents[1]
USAGE = ROOT / "tests" / "typing" / "usage.py"


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    # From the repository root, so that mypy reads the [tool.mypy] table of pyproject.toml.
    return subprocess.run(
        [sys.executable, "-m", *args], capture_output=True, text=True, check=False, cwd=ROOT
    )


def test_stubs_match_the_native_module() -> None:
    result = _run("mypy.stubtest", "aerocontrol._core", "--concise")
    assert result.returncode == 0, result.stdout + result.stderr


def test_package_is_strictly_typed() -> None:
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_core.pyi").is_file()
    result = _run("mypy", "--strict", "--no-incremental", "-p", "aerocontrol")
    assert result.returncode == 0, result.stdout + result.stderr


def test_users_calls_type_check() -> None:
    result = _run("mypy", "--strict", "--no-incremental", str(USAGE))
    assert result.returncode == 0, result.stdout + result.stderr


def test_users_calls_run() -> None:
    try:
        runpy.run_path(str(USAGE), run_name="usage")
    finally:
        plt.close("all")
