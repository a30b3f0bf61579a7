"""The report of the chapter's analyses: its content on the embedded 747 (the chapter's numbers
through the public API), every shipped aircraft, and the folder it writes (self-contained HTML,
Markdown, PNG figures; nothing half-written)."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

import aerocontrol
from aerocontrol.report import Report, build_report, write_report
from aerocontrol.report import build as report_module
from aerocontrol.report import damper as report_damper
from aerocontrol.report import regulator as report_regulator
from aerocontrol.report import responses as report_responses

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
FIGURES = {
    "modes.png",
    "elevator-impulse.png",
    "elevator-step.png",
    "lateral-steps.png",
    "bode.png",
    "damper-rudder.png",
    "damper-aileron.png",
    "lqr-small-c.png",
    "lqr-responses.png",
    "lqr-penalty.png",
    "root-locus.png",
    "envelope.png",
}
#: The chapter's two small examples, in the embedded 747's report only.
EXAMPLES = {"feedback-example.png", "pendulum-root-locus.png"}


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[str]]:
    """The default report, written once for the module; with its progress lines."""
    lines: list[str] = []
    path = write_report(out=tmp_path_factory.mktemp("report") / "out", progress=lines.append)
    return path, lines


def _table_row(markdown: str, first_cell: str, last: bool = False) -> list[str]:
    """The cells of the first (or last) table row that starts with ``first_cell``."""
    lines = markdown.splitlines()
    for line in reversed(lines) if last else lines:
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if cells and cells[0] == first_cell:
            return cells
    raise AssertionError(f"no table row starting with {first_cell!r}")


def test_the_folder_has_the_report_and_every_figure(written: tuple[Path, list[str]]) -> None:
    path, _ = written
    folder = path.parent
    assert path.name == "report.html"
    assert sorted(p.name for p in folder.iterdir()) == [
        ".aerocontrol-report.json",
        "figures",
        "report.html",
        "report.md",
    ]
    assert {p.name for p in (folder / "figures").iterdir()} == FIGURES | EXAMPLES
    for figure in (folder / "figures").iterdir():
        assert figure.read_bytes().startswith(PNG_SIGNATURE)
    page = path.read_text(encoding="utf-8")
    # Self-contained: every image embedded, nothing fetched from elsewhere.
    assert page.count('src="data:image/png;base64,') == len(FIGURES | EXAMPLES)
    assert not re.search(r'(src|href)="(?!data:)', page)
    markdown = (folder / "report.md").read_text(encoding="utf-8")
    for name in FIGURES | EXAMPLES:
        assert f"(figures/{name})" in markdown


def test_progress_is_one_line_per_step(written: tuple[Path, list[str]]) -> None:
    _, lines = written
    starts = [line.split(":")[0].split(" (")[0] for line in lines]
    assert starts == [
        "models",
        "modes",
        "handling qualities",
        "responses",
        "Dutch-roll damper",
        "LQR",
        "root locus",
        "levels after augmentation",
        "envelope",
        "chapter check",
        "writing 14 figures and the report",
    ]
    assert "critically damped at c = 9.772714" in lines[6]
    assert "dutch roll 2 -> damper (rudder) 1, damper (aileron) 1" in lines[7]


def test_the_report_has_the_chapters_results(written: tuple[Path, list[str]]) -> None:
    """The tables carry the chapter's numbers, computed from the coefficients."""
    markdown = (written[0].parent / "report.md").read_text(encoding="utf-8")
    # Modes (6.152)-(6.154).
    dutch = _table_row(markdown, "Dutch roll")
    assert dutch[1] == "-0.080661 ± 0.74331j" and dutch[2] == "0.1079" and dutch[3] == "0.7477"
    assert _table_row(markdown, "roll")[5] == "0.5632"
    assert _table_row(markdown, "spiral")[5] == "14.93"
    # Dampers: from the coefficients, both come out as printed in (6.159) and (6.164).
    assert _table_row(markdown, "rudder")[1:5] == ["0.1383", "0.0943", "0.1250", "-1.1333"]
    assert _table_row(markdown, "aileron")[1:5] == ["-3.5417", "0.8715", "0.6746", "-4.0504"]
    # The regulator at c = 1 against scipy (see test_chapter.py for the tolerances).
    row = _table_row(markdown, "1")
    assert row[1] == "[1.379, -0.4307, -0.3976, -2.816]"
    assert float(row[4]) == pytest.approx(7.088, abs=1e-3)
    assert float(row[5]) < 1e-13
    assert "critically damped at c = 9.772714" in markdown
    # Levels: the Dutch roll is Level 2 open loop, Level 1 with either damper.
    levels = _table_row(markdown, "dutch roll", last=True)
    header = next(line for line in markdown.splitlines() if "| open loop |" in line)
    assert [cell.strip() for cell in header.strip("|").split("|")][:4] == [
        "mode",
        "open loop",
        "damper (rudder)",
        "damper (aileron)",
    ]
    assert levels[1:4] == ["2", "1", "1"]
    # The damper's polynomials (6.155)-(6.157) and closed loops (6.162), (6.165), as printed.
    assert _table_row(markdown, "a (open loop)")[1:] == ["1.4385", "0.8222", "0.7232", "0.0319"]
    assert _table_row(markdown, "ā (target)")[1:] == ["1.7258", "1.1891", "0.7396", "0.0319"]
    assert _table_row(markdown, "k̄ = ā - a")[1:] == ["0.2873", "0.3669", "0.0164", "0.0000"]
    after = markdown.split("The closed loop A - b k^T with the rudder (6.162):")[1]
    assert _table_row(after, "p")[1:5] == ["-1.6158", "-1.1014", "-0.0109", "0.3834"]
    assert _table_row(after, "r")[1:5] == ["0.4427", "-0.0165", "0.0305", "-0.5220"]
    assert _table_row(markdown, "aileron closed loop (6.165)")[2] == "largest difference 2.6e-05"
    # The small examples and the static check, each as printed.
    for name, printed in (
        ("static check (6.52)-(6.55)", "Δ = 7.212, ΔCL = -0.100"),
        ("controllability (6.81), B = [0, 1]", "det V = -1"),
        ("controllability matrix (6.98)", "det V = -128"),
    ):
        assert _table_row(markdown, name)[1:] == [printed, printed]
    lost = _table_row(markdown, "controllability (6.84)-(6.88), B = [-1, 1]")
    assert lost[2] == "det V = 0; not controllable: -2"
    # (6.49) against the model at the printed chord and at the unrounded one.
    assert _table_row(markdown, "longitudinal A, B (6.49)")[2] == (
        "largest difference 3.6e-04 (c̄ = 27.3 ft), 1.1e-04 (c̄ = 27.31 ft)"
    )
    # The small examples: Figure 6.4's gains (6.95), the pendulum's closed form (6.218).
    assert _table_row(markdown, "feedback gains (6.95)-(6.102)")[2] == "[16.49844, 8.0875]"
    pendulum = _table_row(markdown, "pendulum gain (6.218), γ = c = 1")
    assert pendulum[1] == pendulum[2] == "[2.414213562, 2.197368227]"
    steady = _table_row(markdown, "steady state (6.51)")[2].strip("[]").split(", ")
    assert [round(float(v), 4) for v in steady] == [0.0459, -0.0186, 0.0, -0.0160]  # as printed


def test_the_loci_name_their_modes_and_mark_the_critical_weight() -> None:
    """Figure 6.12 names the lateral modes where their branches start and marks the Dutch
    roll's double root at the critical c; Figure 6.8 adds a panel near the origin."""
    built = dict(build_report().figures)
    (locus,) = built["root-locus.png"].axes
    texts = {text.get_text(): text for text in locus.texts}
    assert {"Dutch roll", "roll", "spiral", "critical c = 9.7727"} <= set(texts)
    # The mark is on the real axis, where the closed loop at the critical c has its double root.
    lateral = aerocontrol.aircraft.load().lateral()
    critical = aerocontrol.design.critical_weight(lateral, "dutch roll", bounds=(1e-3, 1e3))
    roots = aerocontrol.design.lqr_root_locus(lateral, [critical])[0]
    x, y = texts["critical c = 9.7727"].xy
    assert y == 0.0
    assert np.min(np.abs(roots - x)) < 1e-4
    pendulum = built["pendulum-root-locus.png"].axes
    titles = [ax.get_title() for ax in pendulum]
    assert titles == ["(a) c/γ from 0.001 to 1000", "(b) near the origin"]
    assert pendulum[1].get_xlim()[0] == -3.0
    for figure in built.values():
        figure.clear()


@pytest.mark.parametrize("identifier", aerocontrol.aircraft.available())
def test_every_shipped_aircraft_reports(identifier: str) -> None:
    lines: list[str] = []
    built = build_report(identifier, progress=lines.append)
    chapter = identifier == "b747-approach"
    assert len(built.figures) == len(FIGURES) + (len(EXAMPLES) if chapter else 0)
    assert built.title.endswith(aerocontrol.aircraft.load(identifier).name)
    assert lines[0].startswith("models: ")
    assert ("chapter check" in lines[-1]) == chapter
    for _, figure in built.figures:
        figure.clear()


def test_a_design_that_does_not_apply_is_reported_and_the_rest_goes_on(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise aerocontrol.UncontrollableError("the Dutch roll is not controllable from here")

    monkeypatch.setattr(report_damper, "dutch_roll_damper", refuse)
    lines: list[str] = []
    built = build_report(progress=lines.append)
    markdown = built.markdown()
    assert "The damper with the rudder alone is not available: the Dutch roll" in markdown
    assert "rudder: not available (the Dutch roll is not controllable from here)" in lines[4]
    assert "Optimal regulator" in markdown
    assert len(built.figures) == len(FIGURES | EXAMPLES) - 2


def _tiny(*args: object, **kwargs: object) -> Report:
    from matplotlib.figure import Figure

    tiny = Report("tiny")
    tiny.heading("a <heading> & more")
    tiny.paragraph("text | with a bar")
    tiny.table(("a", "b"), [("1", "x|y")])
    tiny.figure("one", "a figure", Figure(figsize=(1, 1)))
    return tiny


def test_rendering_escapes_html_and_markdown(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(report_module, "build_report", _tiny)
    path = write_report(out=tmp_path / "tiny")
    page = path.read_text(encoding="utf-8")
    assert "<h2>a &lt;heading&gt; &amp; more</h2>" in page
    assert "| 1 | x\\|y |" in (tmp_path / "tiny" / "report.md").read_text(encoding="utf-8")


def test_rewriting_a_folder_keeps_the_users_files(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Files the report did not write are never removed (see test_report_folder.py for the
    rules): with --force into a folder of the user's, then again into it as an earlier report."""
    monkeypatch.setattr(report_module, "build_report", _tiny)
    out = tmp_path / "out"
    (out / "figures").mkdir(parents=True)
    (out / "figures" / "stale.png").write_bytes(b"old")
    (out / "notes.txt").write_text("mine")
    with pytest.raises(aerocontrol.OutputFolderError, match="it is not empty and holds no"):
        write_report(out=out)
    write_report(out=out, force=True)
    write_report(out=out)
    assert sorted(p.name for p in out.iterdir()) == [
        ".aerocontrol-report.json",
        "figures",
        "notes.txt",
        "report.html",
        "report.md",
    ]
    assert sorted(p.name for p in (out / "figures").iterdir()) == ["one.png", "stale.png"]
    assert (out / "figures" / "stale.png").read_bytes() == b"old"


@pytest.mark.parametrize("existing", [False, True])
def test_a_failure_leaves_nothing_half_written(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, existing: bool
) -> None:
    def fail(ctx: object) -> str:
        raise aerocontrol.ConvergenceError("the regulator failed")

    monkeypatch.setattr(report_regulator, "section", fail)
    out = tmp_path / "out"
    if existing:
        out.mkdir()
        (out / "notes.txt").write_text("mine")
    with pytest.raises(aerocontrol.ConvergenceError, match="the regulator failed"):
        write_report(out=out, force=True)
    if existing:
        assert [p.name for p in out.iterdir()] == ["notes.txt"]
    else:
        assert not out.exists()


def test_an_unwritable_folder_is_one_clear_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(OSError, match=r"cannot write the report into '.*file/out'"):
        write_report(out=blocker / "out")


def test_a_figure_that_cannot_be_drawn_is_replaced_and_the_report_goes_on(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """matplotlib refuses data no axis can hold (the responses of an aircraft whose numbers
    are each plausible but together absurd): that figure says so, the rest is written."""
    from matplotlib.figure import Figure

    class Undrawable(Figure):  # type: ignore[misc]
        def savefig(self, *args: object, **kwargs: object) -> None:
            raise ValueError("arange: cannot compute length")

    def build(*args: object, **kwargs: object) -> Report:
        built = _tiny()
        built.figure("broken", "a figure that cannot be drawn", Undrawable(figsize=(1, 1)))
        return built

    monkeypatch.setattr(report_module, "build_report", build)
    lines: list[str] = []
    path = write_report(out=tmp_path / "out", progress=lines.append)
    assert lines == [
        "writing 2 figures and the report",
        "figure broken.png could not be drawn (ValueError: arange: cannot compute length)",
    ]
    broken = (tmp_path / "out" / "figures" / "broken.png").read_bytes()
    assert broken.startswith(PNG_SIGNATURE)
    assert path.read_text(encoding="utf-8").count('src="data:image/png;base64,') == 2


def test_the_response_grid_is_bounded_for_an_extreme_aircraft(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """A 747 file weighing 0.1 lbf (every number in range) has a short time scale of 0.1 ms over
    a 5,000 s phugoid scale: 400 samples per short scale would be 2e10 samples (a MemoryError
    once); the grid is capped at 200,001."""
    text = (Path(aerocontrol.aircraft.__file__).parent / "data" / "b747-approach.toml").read_text()
    path = tmp_path / "feather.toml"
    path.write_text(text.replace("weight = 564032.0", "weight = 0.1"))
    sizes: list[int] = []
    real = report_responses.impulse_response

    def recording(sys: object, T: np.ndarray, **kwargs: object) -> object:
        sizes.append(len(T))
        return real(sys, T=T, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(report_responses, "impulse_response", recording)
    lines: list[str] = []
    built = build_report(str(path), progress=lines.append)
    assert sizes == [200_001]
    assert lines[3].startswith("responses: elevator impulse and step over 0.0001 s and 5000 s")
    for _, figure in built.figures:
        figure.clear()
