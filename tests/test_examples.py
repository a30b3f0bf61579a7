"""The examples folder: every notebook runs from top to bottom in a fresh kernel, and prints
the numbers the course chapter prints. (The gallery's scripts run in the documentation build,
scripts/docs.sh.)"""

from __future__ import annotations

from pathlib import Path

import pytest

nbclient = pytest.importorskip("nbclient")
nbformat = pytest.importorskip("nbformat")

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
NOTEBOOKS = sorted(path.name for path in (EXAMPLES / "notebooks").glob("*.ipynb"))


def _run(name: str, monkeypatch: pytest.MonkeyPatch) -> str:
    """Execute the notebook in a fresh kernel (which inherits this environment, restored
    after the test); the text of its outputs."""
    book = nbformat.read(EXAMPLES / "notebooks" / name, as_version=4)
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    nbclient.NotebookClient(book, timeout=300, kernel_name="python3").execute()
    texts = []
    for cell in book.cells:
        for output in cell.get("outputs", []):
            texts.append(output.get("text", ""))
            texts.append(output.get("data", {}).get("text/plain", ""))
    return "\n".join(texts)


def test_there_is_a_notebook_per_design_study() -> None:
    assert NOTEBOOKS == [
        "dutch-roll-damper.ipynb",
        "lqr-regulator.ipynb",
        "robustness.ipynb",
        "yaw-damper.ipynb",
    ]


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("dutch-roll-damper.ipynb", ["[ 0.1383  0.0943  0.125  -1.1333]", "rudder damper: 1"]),
        ("lqr-regulator.ipynb", ["c = 1: J = 7.088", "critical c = 9.772714"]),
        ("yaw-damper.ipynb", ["washout: k = 1.487, Dutch roll zeta = 0.291"]),
        ("robustness.ipynb", ["closed loop: Dutch roll meets Level 1 with probability 1 "]),
    ],
)
def test_notebook_runs(name: str, expected: list[str], monkeypatch: pytest.MonkeyPatch) -> None:
    text = _run(name, monkeypatch)
    for line in expected:
        assert line in text, (line, text[:2000])
