"""The ``aerocontrol`` command and ``python -m aerocontrol``."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import scipy.linalg

import aerocontrol
from aerocontrol import cli


def test_demo_prints_the_transition_matrix_of_the_747() -> None:
    text = cli.transition_demo(times=(0.0, 5.0))
    A, _ = aerocontrol.chapter.boeing747_longitudinal()
    phi5 = scipy.linalg.expm(5.0 * A)
    assert "Phi(5 s) =" in text
    assert f"{phi5[0, 0]:+.6f}" in text and f"{phi5[3, 1]:+.6f}" in text
    assert "check (6.25)" in text


def test_module_entry_point_runs() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "aerocontrol"], capture_output=True, text=True, check=True
    )
    assert "Boeing 747" in result.stdout
    assert "(6.51)" in result.stdout
    # The steady state of the one-degree step, printed to four decimals, is the chapter's.
    assert "0.046" in result.stdout and "-0.0186" in result.stdout


def test_version_flag(capsys) -> None:  # type: ignore[no-untyped-def]
    try:
        cli.main(["--version"])
    except SystemExit as exit_:
        assert exit_.code == 0
    assert aerocontrol.__version__ in capsys.readouterr().out
    assert np.__name__ == "numpy"
