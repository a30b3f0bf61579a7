"""The README's usage example runs as written."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_example_runs() -> None:
    if not README.is_file():  # pragma: no cover - tests run from an sdist without README
        pytest.skip("README.md not found beside the tests")
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.DOTALL)
    assert blocks, "README.md has no python example"
    namespace: dict[str, object] = {}
    exec(compile(blocks[0], str(README), "exec"), namespace)
    assert namespace["Phi"].shape == (3, 4, 4)  # type: ignore[attr-defined]
    assert namespace["E"].shape == (10_000, 4, 4)  # type: ignore[attr-defined]
