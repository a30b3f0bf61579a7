"""The peer bench (benches/compare_peers.py and benches/peers/) runs: its harness times a tiny
case with a 0.01 s budget and writes the performance record with the expected columns, its
groups are named after the case files, and the command line lists and selects them. The
growth bench (benches/growth.py) computes its slopes and crossings, stops a size at its time
limit, and runs its --quick mode end to end. Speed itself is not checked here (that is the
benches' job)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

BENCHES = Path(__file__).resolve().parents[1] / "benches"
if not (BENCHES / "peers" / "harness.py").is_file():  # pragma: no cover - sdist without benches
    pytest.skip("benches/peers not found beside the tests", allow_module_level=True)
pytest.importorskip("scipy")
pytest.importorskip("control")
pytest.importorskip("slycot")
sys.path.insert(0, str(BENCHES))

import compare_peers  # noqa: E402
import growth  # noqa: E402
import peers  # noqa: E402
import scipy.linalg  # noqa: E402
from peers import harness  # noqa: E402

import aerocontrol  # noqa: E402

MACHINE_ROWS = ("CPU", "cores", "OS", "Python", "numpy", "scipy", "python-control")


def _tiny_cases() -> list[harness.Case]:
    """e^A of a 4x4 matrix against scipy, with a target it meets easily."""
    return [
        harness.Case(
            op="expm",
            size="n=4",
            seed=4,
            setup=lambda rng: (rng.standard_normal((4, 4)) / 4,),
            ours=aerocontrol.expm,
            peers=[
                harness.Peer(
                    "scipy.linalg.expm",
                    scipy.linalg.expm,
                    target=harness.Target("n=4: ours <= 1 s", max_ours=1.0),
                )
            ],
        )
    ]


TINY = harness.Group("linalg.tiny", _tiny_cases)


@pytest.fixture(scope="module")
def tiny_run() -> dict[str, Any]:
    return harness.run([TINY], repeat=2, min_time=0.01, warn=pytest.fail)


def _header(markdown: str) -> list[str]:
    """The cells of the first results table's header row."""
    row = next(line for line in markdown.splitlines() if line.startswith("| operation |"))
    return [cell.strip() for cell in row.strip("|").split("|")]


def test_run_times_and_checks_the_case(tiny_run: dict[str, Any]) -> None:
    (record,) = tiny_run["records"]
    assert record["group"] == "linalg.tiny"
    assert record["case"] == "expm n=4"
    assert record["agree"]
    assert record["repeats"] == 2
    assert record["ours_s"] > 0 and record["peer_s"] > 0
    assert record["ratio"] == pytest.approx(record["peer_s"] / record["ours_s"])
    assert record["target_met"] is True
    # A call of about a microsecond is looped to fill the 0.01 s of a repeat.
    assert record["ours_number"] >= 10
    assert tiny_run["threads"] in ("one", "default", "inherited")


def test_markdown_record_of_one_run(tiny_run: dict[str, Any]) -> None:
    text = harness.format_markdown([tiny_run], [TINY], harness.machine(), "bench --markdown")
    assert text.startswith("# Performance record\n")
    assert "    bench --markdown" in text
    for row in MACHINE_ROWS:
        assert f"| {row} |" in text
    assert "| aerocontrol commit |" in text
    assert _header(text) == ["operation", "size", "peer", "ours", "peer", "peer / ours", "target"]
    assert "| expm | n=4 | scipy.linalg.expm |" in text
    assert "#### linalg.tiny" in text
    assert "## Targets" in text


def test_markdown_record_of_two_thread_settings(tiny_run: dict[str, Any]) -> None:
    runs = [{**tiny_run, "threads": "one"}, {**tiny_run, "threads": "default"}]
    text = harness.format_markdown(runs, [TINY], harness.machine(), "bench")
    assert _header(text) == [
        "operation",
        "size",
        "peer",
        "ours, 1 thread",
        "peer, 1 thread",
        "peer / ours, 1 thread",
        "ours, default",
        "peer, default",
        "peer / ours, default",
        "target",
    ]
    assert "**1 thread**" in text and "**default threads**" in text
    assert "| target | case | peer | 1 thread | default threads |" in text
    row = next(line for line in text.splitlines() if line.startswith("| expm | n=4 |"))
    assert row.rstrip().endswith("| PASS / PASS |")


def test_thread_environment() -> None:
    base = {"PATH": "/bin", "OPENBLAS_NUM_THREADS": "4"}
    one = harness.thread_environment("one", base)
    assert all(one[name] == "1" for name in harness.THREAD_ENV_VARS)
    assert one["PATH"] == "/bin"
    default = harness.thread_environment("default", base)
    assert not set(harness.THREAD_ENV_VARS) & set(default)
    with pytest.raises(ValueError, match="thread setting"):
        harness.thread_environment("two", base)


def test_groups_are_named_after_their_case_files() -> None:
    groups = peers.all_groups()
    names = [group.name for group in groups]
    assert len(names) == len(set(names))
    assert {group.module for group in groups} == set(peers.MODULES)
    for group in groups:
        cases = group.cases()
        assert cases, group.name
        assert group.description, group.name
        assert len({(c.name, tuple(p.name for p in c.peers)) for c in cases}) == len(cases)
    assert [g.name for g in peers.select(["riccati.lqr", "batch"])] == [
        "riccati.lqr",
        "batch.riccati",
    ]
    with pytest.raises(ValueError, match="unknown group"):
        peers.select(["nonesuch"])


def test_command_line_lists_and_runs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert compare_peers.main(["--list", "--only", "modal"]) == 0
    listing = capsys.readouterr().out
    assert listing.startswith("modal.modes (8 cases):")
    assert "    charpoly n=4 747 lateral  [numpy.poly]" in listing

    record = tmp_path / "performance.md"
    argv = ["--only", "modal", "-k", "charpoly n=4", "--repeat", "1", "--min-time", "0.01"]
    assert compare_peers.main([*argv, "--markdown", str(record)]) == 0
    assert "charpoly" in capsys.readouterr().out  # the text table still goes to stdout
    text = record.read_text(encoding="utf-8")
    row = next(line for line in text.splitlines() if line.startswith("| charpoly |"))
    cells = [cell.strip() for cell in row.strip("|").split("|")]
    assert cells[:3] == ["charpoly", "n=4 747 lateral", "numpy.poly"]
    assert cells[5].endswith("x") and float(cells[5][:-1]) > 0


# ---------------------------------------------------------------------------------------------
# benches/growth.py: cost against n and against the batch size
# ---------------------------------------------------------------------------------------------


def test_growth_slopes_and_crossings() -> None:
    """The log-log slopes of an exact power law, and where a ratio n / 16 crosses 1."""
    pts = [(float(n), 2e-9 * n**3) for n in (4, 8, 16, 64)]
    assert growth.fitted_slope(pts) == pytest.approx(3.0, abs=1e-12)
    assert growth.slope(pts[0], pts[-1]) == pytest.approx(3.0, abs=1e-12)
    cells = [
        {"size": n, "ours_s": 1e-3 * n / 16, "peer_s": 1e-3, "agree": True} for n in (4, 8, 32)
    ]
    cells.insert(1, {"size": 6, "ours_s": None, "peer_s": 1e-3, "agree": None})
    assert growth.successive_slopes(cells, "ours_s") == [None, None, None, pytest.approx(1.0)]
    (crossing,) = growth.crossings(cells)
    assert (crossing["from"], crossing["to"], crossing["beyond"]) == (8, 32, "peer")
    assert crossing["at"] == pytest.approx(16.0)


def test_growth_sweep_stops_at_the_limit() -> None:
    """A peer predicted over its limit is not run, and no later size of it either."""
    op = growth.Operation(
        "double",
        "Double",
        "x2",
        "ours",
        "peer",
        lambda x: 2 * x,
        lambda x: x + x,
        lambda d: (d,),
        harness.same,
    )
    cells = growth.sweep(op, (1, 10, 100), lambda k: (np.ones(k),), 1, 0.0, 0.001, 1)
    assert [c["ours_s"] is not None for c in cells] == [True, True, True]
    assert [c["peer_s"] is not None for c in cells] == [True, False, False]
    assert cells[0]["agree"] is True
    assert cells[1]["peer_predicted_s"] == pytest.approx(10 * cells[0]["peer_s"])
    table = "\n".join(growth.cell_table(cells, "batch"))
    assert table.count("not run") == 2


def test_growth_quick_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--quick`` in one fresh one-thread process: every cell agrees with its peer, and the
    record and both plots are written."""
    paths = {name: tmp_path / name for name in ("growth.md", "size.png", "batch.png")}
    argv = ["--quick", "--threads", "one", "--json", "--markdown", str(paths["growth.md"])]
    argv += ["--size-plot", str(paths["size.png"]), "--batch-plot", str(paths["batch.png"])]
    assert growth.main(argv) == 0
    (run,) = json.loads(capsys.readouterr().out)["runs"]
    assert run["threads"] == "one"
    for kind, sizes in (("size", [4, 8]), ("batch", [1, 10])):
        for cells in run[kind].values():
            assert [c["size"] for c in cells] == sizes
            assert all(c["agree"] and c["ours_s"] > 0 and c["peer_s"] > 0 for c in cells)
    for name in ("size.png", "batch.png"):
        assert paths[name].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = paths["growth.md"].read_text(encoding="utf-8")
    assert text.startswith("# How cost grows with size\n")
    assert "![time against n, log-log](size.png)" in text
    assert "| care | 1 thread |" in text
    assert "| 1,000,000 |" not in text and "| 10 | " in text
