"""Every example in the package's docstrings runs and prints what it shows."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
from pathlib import Path

import numpy as np
import pytest

import aerocontrol

MODULES = sorted(
    name
    for _, name, _ in pkgutil.walk_packages(aerocontrol.__path__, "aerocontrol.")
    if name not in {"aerocontrol._core", "aerocontrol.__main__"}
)


@pytest.mark.parametrize("name", ["aerocontrol", *MODULES])
def test_docstring_examples(name: str) -> None:
    module = importlib.import_module(name)
    # numpy's default print options, whatever another test left.
    defaults = dict(precision=8, floatmode="maxprec", suppress=False, linewidth=75, sign="-")
    with np.printoptions(threshold=1000, edgeitems=3, legacy=False, **defaults):
        failures, _ = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert failures == 0


def test_examples_exist_where_promised() -> None:
    finder = doctest.DocTestFinder()
    for name in ("aerocontrol.linalg", "aerocontrol.chapter"):
        tests = finder.find(importlib.import_module(name))
        assert sum(len(t.examples) for t in tests) >= 3, name


DOCS = Path(__file__).resolve().parents[1] / "docs"
PAGES = sorted(
    str(path.relative_to(DOCS)) for path in DOCS.rglob("*.rst") if "api" not in path.parts
)


def test_the_site_has_pages_with_examples() -> None:
    assert {"aircraft-files.rst", "guide/lqr.rst", "guide/placement.rst"} <= set(PAGES)


@pytest.mark.parametrize("page", PAGES)
def test_page_examples(page: str) -> None:
    """The examples of the documentation site's pages run and print what they show."""
    defaults = dict(precision=8, floatmode="maxprec", suppress=False, linewidth=75, sign="-")
    with np.printoptions(threshold=1000, edgeitems=3, legacy=False, **defaults):
        failures, _ = doctest.testfile(
            str(DOCS / page),
            module_relative=False,
            globs={"np": np, "aerocontrol": aerocontrol},
            optionflags=doctest.NORMALIZE_WHITESPACE,
        )
    assert failures == 0
