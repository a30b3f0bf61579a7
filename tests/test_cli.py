"""The ``aerocontrol`` command and ``python -m aerocontrol``: each subcommand, and one clear line
with a non-zero exit (never a traceback) for every kind of bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import aerocontrol
from aerocontrol import cli


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        status = cli.main(list(argv))
    except SystemExit as exit_:  # argparse's --help, --version and usage errors
        status = int(exit_.code or 0)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_default_run_writes_the_report_of_the_747(tmp_path: Path) -> None:
    """``python -m aerocontrol`` with no arguments: the main job, one line per step, the path
    of the report at the end."""
    result = subprocess.run(
        [sys.executable, "-m", "aerocontrol"], capture_output=True, text=True, cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("models: Boeing 747, powered approach")
    assert any("critically damped at c = 9.772714" in line for line in lines)
    report = tmp_path / "aerocontrol-report" / "report.html"
    assert lines[-1] == f"report: {Path('aerocontrol-report') / 'report.html'}"
    assert report.is_file() and (report.parent / "report.md").is_file()
    assert len(list((report.parent / "figures").glob("*.png"))) == 14
    assert result.stderr == ""


def test_aircraft_lists_the_shipped_aircraft(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = _run(capsys, "aircraft")
    assert status == 0
    listed = [line.split()[0] for line in out.splitlines() if not line.startswith(" ")]
    assert listed == list(aerocontrol.aircraft.available())
    assert "Boeing 747, powered approach (default)" in out


def test_modes_prints_the_modes_and_levels(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = _run(capsys, "modes", "b747-approach")
    assert status == 0
    assert "-0.080661 ± 0.74331j    0.1079        0.7477" in out  # (6.152), (6.153)
    assert "Class III, Flight Phase Category C" in out
    assert "dutch roll    zeta*omega_n    0.08066 rad/s  2" in out


def test_lqr_prints_the_gain_of_the_chapters_regulator(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """(6.224)-(6.227) at c = 0.5: the printed gain is scipy's to the printed digits."""
    status, out, _ = _run(capsys, "lqr", "b747-approach", "--c", "0.5")
    assert status == 0
    sys_ = aerocontrol.aircraft.load().lateral()
    R = np.eye(2) / 0.5**2
    X = scipy.linalg.solve_continuous_are(sys_.A, sys_.B, np.eye(4), R)
    K = np.linalg.solve(R, sys_.B.T @ X)
    for name, row in zip(("rudder", "aileron"), K, strict=True):
        assert f"  {name:<9}" + "".join(f"{value:+12.5f}" for value in row) in out
    assert "closed-loop modes" in out and "Riccati relative residual" in out
    status, out, _ = _run(capsys, "lqr", "--axis", "longitudinal", "--c", "2")
    assert status == 0 and "inputs elevator" in out


def test_help_everywhere(capsys: pytest.CaptureFixture[str]) -> None:
    for argv in ([], ["report"], ["aircraft"], ["modes"], ["lqr"]):
        status, out, _ = _run(capsys, *argv, "--help")
        assert status == 0 and out.startswith("usage: aerocontrol")
    status, out, _ = _run(capsys, "--version")
    assert status == 0 and aerocontrol.__version__ in out


@pytest.mark.parametrize(
    ("argv", "status", "message"),
    [
        (["modes", "concorde"], 1, "unknown aircraft 'concorde'"),
        (["lqr", "--c", "-1"], 2, "--c must be a positive number, got -1"),
        (["lqr", "--c", "nan"], 2, "--c must be a positive number, got nan"),
        (["lqr", "--c", "one"], 2, "argument --c: invalid float value: 'one'"),
        (["lqr", "--axis", "vertical"], 2, "argument --axis: invalid choice: 'vertical'"),
        (["report", "--colour"], 2, "unrecognized arguments: --colour"),
        (["fly"], 2, "invalid choice: 'fly'"),
        (["modes", "missing.toml"], 1, "cannot read the aircraft file 'missing.toml'"),
    ],
)
def test_bad_input_is_one_line_and_a_nonzero_exit(
    capsys: pytest.CaptureFixture[str], argv: list[str], status: int, message: str
) -> None:
    got, out, err = _run(capsys, *argv)
    assert got == status
    assert err.count("\n") == 1 and message in err and err.startswith("aerocontrol")
    assert "Traceback" not in err and out == ""


def _aircraft_file(tmp_path: Path, replace: tuple[str, str]) -> Path:
    shipped = aerocontrol.aircraft.model.resources.files("aerocontrol.aircraft.data")
    text = shipped.joinpath("b747-approach.toml").read_text(encoding="utf-8")
    assert replace[0] in text
    path = tmp_path / "plane.toml"
    path.write_text(text.replace(replace[0], replace[1], 1), encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("replace", "message"),
    [
        (("Cm_q = -20.8\n", ""), "[longitudinal] is missing Cm_q"),
        (("Cm_q = -20.8", "Cm_q = "), "not valid TOML"),
        (("weight = 564032.0", "weight = -564032.0"), "weight"),
    ],
)
def test_a_bad_aircraft_file_stops_the_report_before_anything_is_written(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, replace: tuple[str, str], message: str
) -> None:
    path = _aircraft_file(tmp_path, replace)
    out = tmp_path / "out"
    status, _, err = _run(capsys, "report", str(path), "--out", str(out))
    assert status == 1 and err.count("\n") == 1
    assert message in err and "plane.toml" in err
    assert not out.exists()


def test_an_unwritable_output_folder_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    status, out, err = _run(capsys, "report", "--out", str(blocker / "out"))
    assert status == 1 and out == ""
    assert (
        err.startswith("aerocontrol: error: cannot write the report into") and err.count("\n") == 1
    )


def test_report_on_an_aircraft_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """Any aircraft described in a file: here the 747 with a 20 % larger fin (Cn_beta)."""
    path = _aircraft_file(tmp_path, ("Cn_beta = 0.15", "Cn_beta = 0.18"))
    status, out, _ = _run(capsys, "report", str(path), "--out", str(tmp_path / "fin"))
    assert status == 0
    assert out.splitlines()[-1] == f"report: {tmp_path / 'fin' / 'report.html'}"
    assert "chapter check" not in out  # the chapter's numbers are for the embedded 747 only
