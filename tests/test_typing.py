"""The type information shipped with the package cannot drift from the code.

* ``mypy.stubtest`` compares ``_core.pyi`` with the compiled module: every function, argument
  kind and constant in one must be in the other.
* ``mypy --strict`` type-checks the package against those stubs.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import aerocontrol

PACKAGE = Path(aerocontrol.__file__).parent


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", *args], capture_output=True, text=True, check=False
    )


def test_stubs_match_the_native_module() -> None:
    result = _run("mypy.stubtest", "aerocontrol._core", "--concise")
    assert result.returncode == 0, result.stdout + result.stderr


def test_package_is_strictly_typed() -> None:
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_core.pyi").is_file()
    result = _run("mypy", "--strict", "--no-incremental", "-p", "aerocontrol")
    assert result.returncode == 0, result.stdout + result.stderr
