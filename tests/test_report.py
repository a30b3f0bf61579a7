"""The report of the chapter's analyses: its content on the embedded 747 (the chapter's numbers
through the public API), every shipped aircraft, and the folder it writes (self-contained HTML,
Markdown, PNG figures; nothing half-written)."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import control
import numpy as np
import pytest
import scipy.integrate
import scipy.linalg
import scipy.signal

import aerocontrol
from aerocontrol.report import Report, build_report, write_report
from aerocontrol.report import build as report_module
from aerocontrol.report import damper as report_damper
from aerocontrol.report import digital as report_digital
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
    "digital-regulator.png",
    "digital-lqg.png",
    "yaw-damper.png",
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
        "digital regulator",
        "digital damper",
        "LQG",
        "output-feedback dampers",
        "levels after augmentation",
        "envelope",
        "chapter check",
        "writing 17 figures and the report",
    ]
    assert "critically damped at c = 9.772714" in lines[6]
    assert "dutch roll 2 -> damper (rudder) 1, damper (aileron) 1" in lines[11]


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


# ----- the digital section -------------------------------------------------------------------
#
# Oracles, independent of aerocontrol: the zero-order-hold plant by scipy.signal.cont2discrete,
# the sampled weights by adaptive quadrature (scipy.integrate.quad_vec of
# e^{F^T t} diag(Q, R) e^{F t} with scipy.linalg.expm), the regulators by python-control's lqr
# and dlqr, the damper by scipy.signal.place_poles, the Kalman filter by python-control's dlqe,
# the costs by scipy.linalg.solve_discrete_lyapunov, the roots by numpy's eigvals. The report
# prints ζ and ω_n to 5 decimals, gains to 5 (M to 6), J to 6 significant digits and the gain
# differences to 4: each is compared with the oracle to half a unit of its last printed digit
# plus 1e-9 (the oracles' own error, far smaller).

LATERAL_747 = aerocontrol.aircraft.load().lateral()


def _section(markdown: str, start: str, end: str | None = None) -> str:
    after = markdown.split(start, 1)[1]
    return after.split(end, 1)[0] if end else after


def _zoh(period: float) -> tuple[np.ndarray, np.ndarray]:
    sys = LATERAL_747
    Phi, Gamma, *_ = scipy.signal.cont2discrete((sys.A, sys.B, np.eye(4), np.zeros((4, 2))), period)
    return Phi, Gamma


def _oracle_weights(period: float) -> np.ndarray:
    """W = ∫_0^T e^{F^T t} diag(Q, R) e^{F t} dt by adaptive quadrature, Q = I, R = I."""
    F = np.zeros((6, 6))
    F[:4, :4], F[:4, 4:] = LATERAL_747.A, LATERAL_747.B

    def integrand(t: float) -> np.ndarray:
        E = scipy.linalg.expm(F * t)
        return E.T @ E

    W, _ = scipy.integrate.quad_vec(integrand, 0.0, period, epsabs=1e-15, epsrel=1e-13)
    return 0.5 * (W + W.T)


def _oracle_regulator(period: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(K, S, W) of python-control's dlqr with the quadrature's sampled weights."""
    Phi, Gamma = _zoh(period)
    W = _oracle_weights(period)
    K, S, _ = control.dlqr(Phi, Gamma, W[:4, :4], W[4:, 4:], W[:4, 4:])
    return np.asarray(K), np.asarray(S), W


def _oracle_cost(closed: np.ndarray, stage: np.ndarray, x0: np.ndarray) -> float:
    P = scipy.linalg.solve_discrete_lyapunov(closed.T, stage)
    return float(x0 @ P @ x0)


def _dutch_roll_of(closed: np.ndarray, period: float | None) -> complex:
    """The one complex root (Im > 0) of a 747 lateral loop, mapped by ln(z)/T if sampled."""
    values = np.linalg.eigvals(closed)
    (root,) = [v for v in values if v.imag > 1e-12]
    return complex(np.log(root) / period) if period else complex(root)


def _printed(
    cell: str, value: float, decimals: int | None = None, digits: int | None = None
) -> None:
    """The printed ``cell`` equals ``value`` to half a unit of its last printed place."""
    if decimals is not None:
        tolerance = 0.5 * 10.0**-decimals
    else:
        assert digits is not None
        tolerance = 0.5 * 10.0 ** (np.floor(np.log10(abs(value))) - digits + 1)
    assert abs(float(cell) - value) <= tolerance + 1e-9, (cell, value)


def test_the_digital_section_is_in_the_report(written: tuple[Path, list[str]]) -> None:
    markdown = (written[0].parent / "report.md").read_text(encoding="utf-8")
    for heading in (
        "## Digital flight control",
        "### The lateral regulator at a flight computer's rate",
        "### The Dutch-roll damper at a flight computer's rate",
        "### LQG at 50 Hz with sideslip not measured",
    ):
        assert heading in markdown
    # Between the regulator and the Levels, in the order of the report.
    assert markdown.index("## Optimal regulator") < markdown.index("## Digital flight control")
    assert markdown.index("## Digital flight control") < markdown.index("(figures/envelope.png)")
    lines = written[1]
    assert lines[7].startswith("digital regulator (c = 1): 50 Hz: ‖K - K_c‖/‖K_c‖ = 6.377e-03")
    assert lines[9].startswith("LQG (50 Hz, p, r, phi measured): filter poles")


def test_the_digital_regulator_matches_python_control_and_quadrature(
    written: tuple[Path, list[str]],
) -> None:
    markdown = (written[0].parent / "report.md").read_text(encoding="utf-8")
    sys = LATERAL_747
    x0 = np.array([1.0, 0.0, 0.0, 0.0])
    Kc, Sc, _ = control.lqr(sys.A, sys.B, np.eye(4), np.eye(2))
    Kc, Sc = np.asarray(Kc), np.asarray(Sc)
    row = _table_row(markdown, "LQR continuous")
    dutch = _dutch_roll_of(sys.A - sys.B @ Kc, None)
    _printed(row[2], -dutch.real / abs(dutch), decimals=5)
    _printed(row[3], abs(dutch), decimals=5)
    assert row[4] == "0"
    _printed(row[5], float(x0 @ Sc @ x0), digits=6)
    gains = _section(markdown, "The gains, K (rows")
    costs = {}
    for rate in report_digital.DIGITAL_RATES:
        period = 1.0 / rate
        Phi, Gamma = _zoh(period)
        K, S, W = _oracle_regulator(period)
        for name, gain in ((f"LQR dlqr {rate:g} Hz", K), (f"LQR held {rate:g} Hz", Kc)):
            closed = Phi - Gamma @ gain
            assert np.all(np.abs(np.linalg.eigvals(closed)) < 1), name  # stable
            row = _table_row(markdown, name)
            dutch = _dutch_roll_of(closed, period)
            _printed(row[2], -dutch.real / abs(dutch), decimals=5)
            _printed(row[3], abs(dutch), decimals=5)
            difference = np.linalg.norm(gain - Kc) / np.linalg.norm(Kc)
            if gain is Kc:
                assert row[4] == "0"
            else:
                _printed(row[4], difference, digits=4)
            stage = np.vstack([np.eye(4), -gain])
            costs[name] = _oracle_cost(closed, stage.T @ W @ stage, x0)
            _printed(row[5], costs[name], digits=6)
            printed_gain = [float(v) for v in _table_row(gains, name)[1:]]
            assert np.max(np.abs(np.array(printed_gain) - gain.ravel())) <= 0.5e-5 + 1e-9
        # The dlqr cost is x0^T S x0, and no held gain does better; the continuous design,
        # free to change its command between samples, does better still.
        assert costs[f"LQR dlqr {rate:g} Hz"] == pytest.approx(float(x0 @ S @ x0), rel=1e-10)
        assert float(x0 @ Sc @ x0) < costs[f"LQR dlqr {rate:g} Hz"] < costs[f"LQR held {rate:g} Hz"]
    # Measured: at 50 Hz the dlqr design is the continuous one to 0.64 %, at 10 Hz to 3.2 %.
    assert _table_row(markdown, "LQR dlqr 50 Hz")[4] == "6.377e-03"
    assert _table_row(markdown, "LQR dlqr 10 Hz")[4] == "3.164e-02"


def test_the_digital_damper_matches_scipys_placement(written: tuple[Path, list[str]]) -> None:
    markdown = (written[0].parent / "report.md").read_text(encoding="utf-8")
    sys = LATERAL_747
    # The continuous target (6.156) from numpy's eigenvalues: the Dutch roll at ζ = 0.3 and the
    # same ω_n, the roll and spiral kept.
    values = np.linalg.eigvals(sys.A)
    (dutch,) = [v for v in values if v.imag > 0]
    omega = abs(dutch)
    target = [v for v in values if v.imag == 0] + [
        complex(-0.3 * omega, s * omega * np.sqrt(1 - 0.09)) for s in (1, -1)
    ]
    k_continuous = scipy.signal.place_poles(sys.A, sys.B[:, :1], target).gain_matrix.ravel()
    row = _table_row(markdown, "damper continuous")
    assert np.max(np.abs([float(v) for v in row[1:5]] - k_continuous)) <= 0.5e-5 + 1e-9
    _printed(row[6], 0.3, decimals=5)
    _printed(row[7], omega, decimals=5)
    for rate in report_digital.DIGITAL_RATES:
        period = 1.0 / rate
        Phi, Gamma = _zoh(period)
        mapped = np.exp(np.array(target) * period)
        k = scipy.signal.place_poles(Phi, Gamma[:, :1], mapped).gain_matrix.ravel()
        row = _table_row(markdown, f"damper placed {rate:g} Hz")
        assert np.max(np.abs([float(v) for v in row[1:5]] - k)) <= 0.5e-5 + 1e-9
        _printed(row[6], 0.3, decimals=5)  # the mapped roots are the continuous ones
        _printed(row[7], omega, decimals=5)
        _printed(row[8], np.linalg.norm(k - k_continuous) / np.linalg.norm(k_continuous), digits=4)
        held = _table_row(markdown, f"damper held {rate:g} Hz")
        closed = Phi - np.outer(Gamma[:, 0], k_continuous)
        assert np.all(np.abs(np.linalg.eigvals(closed)) < 1)
        root = _dutch_roll_of(closed, period)
        _printed(held[6], -root.real / abs(root), decimals=5)
        _printed(held[7], abs(root), decimals=5)
    # Measured: holding the continuous damper's gain at 10 Hz gives ζ = 0.30202, not 0.30.
    assert _table_row(markdown, "damper held 10 Hz")[6] == "0.30202"


def test_the_lqg_regulator_matches_python_control_and_its_loop_is_stable(
    written: tuple[Path, list[str]],
) -> None:
    markdown = (written[0].parent / "report.md").read_text(encoding="utf-8")
    lqg = _section(markdown, "### LQG at 50 Hz with sideslip not measured")
    period = 1.0 / report_digital.LQG_RATE
    Phi, Gamma = _zoh(period)
    K, S, W = _oracle_regulator(period)
    C = np.eye(4)[[1, 3, 2]]  # p, r, φ of (β, p, φ, r)
    QN = np.radians(1.0) ** 2 * np.eye(2)
    RN = np.diag(np.radians([0.1, 0.1, 0.2]) ** 2)
    L, P, E = control.dlqe(Phi, Gamma, C, QN, RN)
    L, P = np.asarray(L), np.asarray(P)
    M = P @ C.T @ np.linalg.inv(C @ P @ C.T + RN)
    assert np.allclose(L, Phi @ M, rtol=1e-9)  # L = Φ M (no cross covariance)
    for state, gains in zip(("beta", "p", "phi", "r"), M, strict=True):
        printed = [float(v) for v in _table_row(lqg, state)[1:]]
        assert np.max(np.abs(np.array(printed) - gains)) <= 0.5e-6 + 1e-9
    # The poles: the table's |z| and ω_n of the filter against dlqe's E.
    rows = [line for line in lqg.splitlines() if line.startswith("| Kalman filter")]
    expected = sorted((v for v in np.asarray(E) if v.imag >= 0), key=lambda v: abs(np.log(v)))
    assert len(rows) == len(expected)
    for line, z in zip(rows, expected, strict=True):
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        _printed(cells[3], abs(z), decimals=6)
        _printed(cells[5], abs(np.log(z) / period), decimals=5)
    # The closed loop, built here from the current-estimate compensator: x̂ = x̄ + M C (x - x̄),
    # η = -K x̂, x̄⁺ = Φ x̂ + Γ η. Stable, and its poles are the regulator's and the filter's.
    estimate = np.hstack([M @ C, np.eye(4) - M @ C])
    command = -K @ estimate
    closed = np.vstack(
        [np.hstack([Phi, np.zeros((4, 4))]) + Gamma @ command, Phi @ estimate + Gamma @ command]
    )
    computed = np.linalg.eigvals(closed)
    assert np.all(np.abs(computed) < 1)
    union = np.concatenate([np.linalg.eigvals(Phi - Gamma @ K), np.asarray(E)])
    assert max(np.min(np.abs(union - value)) for value in computed) < 1e-9
    # The costs from a unit sideslip, the estimate starting at zero.
    x0 = np.r_[1.0, np.zeros(7)]
    stage = np.vstack([np.hstack([np.eye(4), np.zeros((4, 4))]), command])
    lqg_cost = _oracle_cost(closed, stage.T @ W @ stage, x0)
    found = re.search(r"J = ([0-9.]+) \(full-state feedback: J = ([0-9.]+), \+([0-9.]+) %\)", lqg)
    assert found is not None
    _printed(found.group(1), lqg_cost, digits=6)
    _printed(found.group(2), float(S[0, 0]), digits=6)
    assert "The closed loop (order 8) is stable" in lqg
    # Measured: not measuring the sideslip costs 40 % more from this start.
    assert found.group(3) == "39.7"


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
    with warnings.catch_warnings():
        # numpy's 'invalid value in subtract' leaked from the root locus's marked gain.
        warnings.simplefilter("error", RuntimeWarning)
        built = build_report(str(path), progress=lines.append)
    assert sizes == [200_001]
    assert lines[3].startswith("responses: elevator impulse and step over 0.0001 s and 5000 s")
    for _, figure in built.figures:
        figure.clear()
