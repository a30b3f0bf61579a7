"""The ``aerocontrol`` command and ``python -m aerocontrol``: each subcommand, and one clear line
with a non-zero exit (never a traceback) for every kind of bad input."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import warnings
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
    assert len(list((report.parent / "figures").glob("*.png"))) == 17
    assert result.stderr == ""
    # README's command, run again into the same folder: the earlier report, untouched, is
    # replaced without any option; a file of the user's beside it stays.
    (tmp_path / "aerocontrol-report" / "notes.txt").write_text("mine")
    again = subprocess.run(
        [sys.executable, "-m", "aerocontrol", "report", "--out", "aerocontrol-report"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert again.returncode == 0, again.stderr
    assert "writing 17 figures and the report (replacing the earlier report)" in again.stdout
    assert (tmp_path / "aerocontrol-report" / "notes.txt").read_text() == "mine"
    assert again.stderr == ""


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
    for argv in ([], ["report"], ["aircraft"], ["modes"], ["lqr"], ["robustness"]):
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
    shipped = aerocontrol.aircraft.reader.resources.files("aerocontrol.aircraft.data")
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


# --- Every error is one line -------------------------------------------------------------------


def _one_line(err: str) -> str:
    """The single line of standard error, without its newline."""
    assert err.endswith("\n") and err.count("\n") == 1, err
    assert "Traceback" not in err
    return err[:-1]


def _hostile(tmp_path: Path, kind: str) -> tuple[Path, str]:
    """A hostile aircraft file and the error message it must give."""
    shipped = aerocontrol.aircraft.reader.resources.files("aerocontrol.aircraft.data")
    text = shipped.joinpath("b747-approach.toml").read_text(encoding="utf-8")
    path = tmp_path / f"{kind}.toml"
    if kind == "digits400":
        path.write_text(text.replace("weight = 564032.0", "weight = 1" + "0" * 399))
        return path, (
            f"{path}: [mass] weight, an integer of about 400 digits, is outside the plausible "
            "range 0.1 to 4.5e+06 lbf"
        )
    if kind == "digits5000":
        path.write_text(text.replace("weight = 564032.0", "weight = " + "7" * 5000))
        line = text.splitlines().index("weight = 564032.0          # lbf") + 1
        return path, (
            f"{path}: line {line}: weight = an integer of 5000 digits is outside the plausible "
            "range of every quantity"
        )
    if kind == "speed":
        path.write_text(text.replace("speed = 279.1", "speed = 1e300"))
        return path, (
            f"{path}: [flight] speed = 1e+300 ft/s is outside the plausible range 1.5 to 11500 ft/s"
        )
    if kind == "Cm_q":
        path.write_text(text.replace("Cm_q = -20.8", "Cm_q = -1e300"))
        return path, (
            f"{path}: [longitudinal] Cm_q = -1e+300 per rad is outside the plausible range "
            "-1000 to 1000 per rad"
        )
    if kind == "latin1":
        path.write_bytes(b'[aircraft]\nname = "Caf\xe9"\n')
        return path, (
            f"{path}: not UTF-8 text: byte 0xe9 at offset 22 (invalid continuation byte); save "
            "the file as UTF-8"
        )
    if kind == "deep":
        path.write_text("a = " + "[" * 3000 + "]" * 3000)
        return path, f"{path}: not valid TOML for an aircraft: arrays or tables nested too deeply"
    if kind == "big":
        path.write_text(text + "#" * 2_000_000)
        return path, (
            f"cannot read the aircraft file {str(path)!r}: it is larger than 1,048,576 bytes, "
            "the limit of an aircraft file"
        )
    if kind == "zero":
        path.symlink_to("/dev/zero")
        return path, (
            f"cannot read the aircraft file {str(path)!r}: it is a device, not a regular file"
        )
    if kind == "folder":
        path.mkdir()
        return path, (
            f"cannot read the aircraft file {str(path)!r}: it is a folder, not a regular file"
        )
    raise AssertionError(kind)  # pragma: no cover


HOSTILE = ["digits400", "digits5000", "speed", "Cm_q", "latin1", "deep", "big", "zero", "folder"]


@pytest.mark.parametrize("kind", HOSTILE)
@pytest.mark.parametrize("command", ["modes", "lqr", "report"])
def test_hostile_aircraft_files_are_one_line_and_status_1(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, kind: str, command: str
) -> None:
    path, message = _hostile(tmp_path, kind)
    out_folder = tmp_path / "report-out"
    extra = ["--out", str(out_folder)] if command == "report" else []
    status, out, err = _run(capsys, command, str(path), *extra)
    assert (status, out) == (1, "")
    assert _one_line(err) == f"aerocontrol: error: {message}"
    assert not out_folder.exists()


def test_a_fifo_does_not_block_the_command(tmp_path: Path) -> None:
    fifo = tmp_path / "x.toml"
    os.mkfifo(fifo)
    result = subprocess.run(
        [sys.executable, "-m", "aerocontrol", "modes", str(fifo)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert (result.returncode, result.stdout) == (1, "")
    assert _one_line(result.stderr) == (
        f"aerocontrol: error: cannot read the aircraft file {str(fifo)!r}: it is a FIFO (named "
        "pipe), not a regular file"
    )


@pytest.mark.parametrize(
    ("value", "message"),
    [
        ("1e300", "--c must lie between 1e-08 and 1e+08 (R = I/c^2 within the range of double "
         "precision of Q = I), got 1e+300"),
        ("1e-300", "--c must lie between 1e-08 and 1e+08 (R = I/c^2 within the range of double "
         "precision of Q = I), got 1e-300"),
        ("inf", "--c must be a positive number, got inf"),
        ("0", "--c must be a positive number, got 0"),
        ("-0", "--c must be a positive number, got -0"),
        ("1e400", "--c must be a positive number, got inf"),
    ],
)  # fmt: skip
def test_lqr_weights_out_of_range_are_usage_errors(
    capsys: pytest.CaptureFixture[str], value: str, message: str
) -> None:
    status, out, err = _run(capsys, "lqr", "--c", value)
    assert (status, out) == (2, "")
    assert _one_line(err) == f"aerocontrol: error: {message} (see aerocontrol --help)"


def test_lqr_weights_at_the_ends_of_the_range_are_solved(
    capsys: pytest.CaptureFixture[str],
) -> None:
    for value in ("1e-8", "1e8"):
        status, out, err = _run(capsys, "lqr", "--c", value)
        assert status == 0 and err == "" and "Riccati relative residual" in out


def test_an_unsolvable_regulator_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """A directionally unstable 747 (Cn_beta < 0) with no lateral controls: no stabilising
    Riccati solution exists, whatever c."""
    shipped = aerocontrol.aircraft.reader.resources.files("aerocontrol.aircraft.data")
    text = shipped.joinpath("b747-approach.toml").read_text(encoding="utf-8")
    text = text.replace("Cn_beta = 0.15", "Cn_beta = -0.15")
    for key in ("Cy_dr = 0.175", "Cl_dr = 0.007", "Cn_dr = -0.109", "Cl_da = 0.0461",
                "Cn_da = 0.0064"):  # fmt: skip
        assert key in text
        text = text.replace(key, key.split(" = ")[0] + " = 0.0")
    path = tmp_path / "uncontrolled.toml"
    path.write_text(text)
    status, out, err = _run(capsys, "lqr", str(path))
    assert (status, out) == (1, "")
    lateral = aerocontrol.aircraft.load(path).lateral()
    with pytest.raises(aerocontrol.AerocontrolLinAlgError) as caught:  # what the core says
        aerocontrol.solve_care(lateral.A, lateral.B, np.eye(4), np.eye(2))
    assert _one_line(err) == f"aerocontrol: error: {caught.value}"


@pytest.mark.parametrize("where", ["before", "after"])
def test_debug_prints_the_traceback_instead(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, where: str
) -> None:
    path, message = _hostile(tmp_path, "speed")
    argv = ["--debug", "modes", str(path)] if where == "before" else ["modes", str(path), "--debug"]
    status, out, err = _run(capsys, *argv)
    assert (status, out) == (1, "")
    assert err.startswith("Traceback (most recent call last):\n")
    assert err.endswith(f"aerocontrol.aircraft.schema.AircraftDataError: {message}\n")
    assert "aerocontrol: error" not in err


@pytest.mark.parametrize(
    ("error", "line"),
    [
        (ZeroDivisionError("division by zero"), "unexpected error (ZeroDivisionError: division "
         "by zero); run 'aerocontrol --debug ...' for the traceback"),
        (RecursionError("maximum recursion depth exceeded"), "unexpected error (RecursionError: "
         "maximum recursion depth exceeded); run 'aerocontrol --debug ...' for the traceback"),
        (MemoryError(), "out of memory (no detail)"),
        (MemoryError("Unable to allocate 149. GiB"), "out of memory (Unable to allocate 149. GiB)"),
        (KeyError("x\ny"), "unexpected error (KeyError: 'x\\ny'); run 'aerocontrol --debug ...' "
         "for the traceback"),
        (aerocontrol.ConvergenceError("no convergence\nafter 30 steps"), "no convergence\\nafter "
         "30 steps"),
        (PermissionError(13, "Permission denied", "x"), "[Errno 13] Permission denied: 'x'"),
    ],
)  # fmt: skip
def test_any_exception_is_one_line_and_status_1(
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    error: BaseException,
    line: str,
) -> None:
    def fail(arguments: object) -> int:
        raise error

    for command in ("aircraft", "modes", "lqr", "report"):
        monkeypatch.setitem(cli._COMMANDS, command, fail)
        status, out, err = _run(capsys, command)
        assert (status, out) == (1, "")
        assert _one_line(err) == f"aerocontrol: error: {line}"
    status, _, err = _run(capsys, "--debug", "aircraft")
    assert status == 1 and err.startswith("Traceback (most recent call last):")


def test_ctrl_c_is_one_line_and_status_130(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def interrupted(arguments: object) -> int:
        raise KeyboardInterrupt

    monkeypatch.setitem(cli._COMMANDS, "modes", interrupted)
    status, out, err = _run(capsys, "modes")
    assert (status, out, err) == (130, "", "aerocontrol: interrupted\n")


def test_warnings_are_one_line(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def warns(arguments: object) -> int:
        warnings.warn(
            "ill-conditioned\nrcond 1e-17", aerocontrol.IllConditionedWarning, stacklevel=1
        )
        return 0

    monkeypatch.setitem(cli._COMMANDS, "modes", warns)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        status, out, err = _run(capsys, "modes")
    assert (status, out) == (0, "")
    assert err == "aerocontrol: warning: ill-conditioned\\nrcond 1e-17\n"


def test_a_refused_report_folder_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "report.md").write_text("my notes")
    status, stdout, err = _run(capsys, "report", "--out", str(out))
    assert (status, stdout) == (1, "")
    assert _one_line(err) == (
        f"aerocontrol: error: cannot write the report into {str(out)!r}: it is not empty and "
        "holds no earlier report (no .aerocontrol-report.json); choose a new or empty folder, or "
        "add --force to write the report beside its files (none of them is replaced)"
    )
    status, stdout, err = _run(capsys, "report", "--out", str(out), "--force")
    assert (status, stdout) == (1, "")
    assert _one_line(err).endswith("report.md is a file the report did not write; it is not "
                                   "replaced: move it away or choose another --out")  # fmt: skip
    assert [p.name for p in out.iterdir()] == ["report.md"]
    assert (out / "report.md").read_text() == "my notes"


def test_the_help_documents_the_folder_rules(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = _run(capsys, "report", "--help")
    assert status == 0
    flat = " ".join(out.split())
    for promise in (
        "never deletes, renames or overwrites a file it did not write",
        "a new or empty DIR is used",
        "running the same command again just works",
        "files the manifest does not list (your notes, your images in figures/) are never touched",
        "a DIR that is not empty and holds no manifest is refused, unless --force",
        "symbolic links inside DIR are never written through",
        "on an error, Ctrl-C or SIGTERM the run is undone",
        "--force also write into a non-empty folder",
    ):
        assert promise in flat, promise


def test_damper_command() -> None:
    """``aerocontrol damper``: the yaw damper's gain, margins and MIL-F-9490D check; a bad
    option value is one line and status 2."""
    result = subprocess.run(
        [sys.executable, "-m", "aerocontrol", "damper", "b747-cruise", "--loop", "yaw"],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    assert "yaw damper, washout 3 s: gain k = 1.4873" in result.stdout
    assert "MIL-F-9490D 3.1.3.6 margins" in result.stdout and "UNVERIFIED" in result.stdout
    pitch = subprocess.run(
        [sys.executable, "-m", "aerocontrol", "damper", "b747-cruise", "--loop", "pitch"],
        capture_output=True,
        text=True,
    )
    assert pitch.returncode == 0 and "pitch damper: gain k =" in pitch.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "aerocontrol", "damper", "--loop", "pitch", "--washout", "2"],
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 2
    assert bad.stderr.splitlines() == [
        "aerocontrol: error: --washout applies to the yaw damper only (see aerocontrol --help)"
    ]


def test_robustness_prints_the_probabilities_of_the_api(
    capsys: pytest.CaptureFixture[str],
) -> None:
    from aerocontrol.aircraft.tables import LATERAL_DERIVATIVES
    from aerocontrol.robustness import Normal, Uncertainty, monte_carlo

    status, out, err = _run(
        capsys, "robustness", "b747-cruise", "--samples", "3000", "--controller", "damper"
    )
    assert status == 0 and err == ""
    plane = aerocontrol.aircraft.load("b747-cruise")
    uncertainty = Uncertainty(
        {name: Normal(0.15) for name in LATERAL_DERIVATIVES if plane.derivatives[name] != 0.0}
    )
    gains = np.vstack([aerocontrol.design.dutch_roll_damper(plane).k, np.zeros(4)])
    result = monte_carlo(plane, uncertainty, 3000, gains, seed=0)
    lines = out.splitlines()
    assert lines[0] == plane.summary()
    assert str(result) in out
    assert lines[-1].startswith("3000 samples in ")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--samples", "0"], "--samples must be a positive number up to 1e+12, got 0"),
        # Beyond MAX_SAMPLES no interval is computed: refused before the run, not after it.
        (["--samples", "10000000000000"], "--samples must be a positive number up to 1e+12"),
        (["--seed", "-1"], "--seed must be >= 0, got -1"),
        (["--sigma", "nan"], "--sigma must be a number >= 0, got nan"),
        (["--c", "0"], "--c must lie between"),
        (["--controller", "damper", "--axis", "longitudinal"], "lateral Dutch roll damper"),
        (["--controller", "pid"], "argument --controller: invalid choice: 'pid'"),
    ],
)
def test_robustness_refuses_bad_options(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    got, out, err = _run(capsys, "robustness", *argv)
    assert got == 2 and message in err and out == ""
    assert err.count("\n") == 1 and "Traceback" not in err


def test_robustness_too_large_for_memory_is_one_line_after_the_first_chunk(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from aerocontrol import robustness

    monkeypatch.setattr(robustness, "_available_memory", lambda: 2.0**20)
    status, _out, err = _run(capsys, "robustness", "b747-cruise", "--samples", "10000000000")
    assert status != 0 and "Traceback" not in err
    assert "out of memory (samples=10,000,000,000 keeps" in err
    assert err.count("\n") == 1


def test_robustness_writes_its_page_under_the_report_folder_rules(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "robust"
    argv = ("robustness", "b747-cruise", "--samples", "2000", "--controller", "lqr")
    status, text, err = _run(capsys, *argv, "--out", str(out))
    assert status == 0 and err == ""
    assert text.splitlines()[-1] == f"report: {out / 'report.html'}"
    names = sorted(p.name for p in (out / "figures").iterdir())
    assert names == ["robustness-convergence-sensitivity.png", "robustness-distributions.png"]
    page = (out / "report.md").read_text(encoding="utf-8")
    # The regulator (Q = I, c = 1) couples roll and spiral in these samples: said, and judged
    # as one oscillation by MIL-F-8785C 3.3.1.4 (its ζ ω_n of about 0.8 rad/s: Level 1).
    assert "roll and spiral coupled: judged as one oscillation (3.3.1.4)" in page
    assert re.search(r"closed loop \| roll Level 1 or better \| (1|0\.9\d+) \(", page), page
    assert "dutch roll Level 1 or better" in page
    # Run again: the earlier page is replaced; a folder of the user's is refused.
    status, text, _ = _run(capsys, *argv, "--out", str(out))
    assert status == 0 and "replacing the earlier report" in text
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    status, text, err = _run(capsys, *argv, "--out", str(mine))
    assert status == 1 and "notes.txt" not in text and err.startswith("aerocontrol")
    assert (mine / "notes.txt").read_text() == "mine" and sorted(mine.iterdir()) == [
        mine / "notes.txt"
    ]
