"""Every public function and class documents itself in numpydoc form: a function its
Parameters, Returns, Raises and an Example; a class its Parameters or Attributes and an
Example. (The examples run in tests/test_docs.py.) The names still missing a section are listed
in KNOWN_GAPS, which may only shrink: a name that gains its sections must leave the list."""

from __future__ import annotations

import importlib
import inspect

import pytest

numpydoc = pytest.importorskip("numpydoc.docscrape")

#: The public modules, as the documentation site's API reference lists them.
MODULES = (
    "aerocontrol",
    "aerocontrol.aircraft",
    "aerocontrol.handling",
    "aerocontrol.design",
    "aerocontrol.batch",
    "aerocontrol.robustness",
    "aerocontrol.schedule",
    "aerocontrol.chapter",
    "aerocontrol.plotting",
    "aerocontrol.report",
)

#: name -> the sections it still lacks.
KNOWN_GAPS: dict[str, set[str]] = {}


def _public() -> dict[str, object]:
    found: dict[str, object] = {}
    seen: set[int] = set()
    for module_name in MODULES:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            value = getattr(module, name)
            if id(value) in seen or not callable(value) or inspect.ismodule(value):
                continue
            if inspect.isclass(value) and issubclass(value, BaseException):
                continue  # the exceptions: one line each, tabulated in aerocontrol.exceptions
            seen.add(id(value))
            found[f"{module_name}.{name}"] = value
    return found


def _missing(value: object) -> set[str]:
    if inspect.isclass(value):
        doc = numpydoc.ClassDoc(value, config={"show_class_members": False})
        missing = {"Examples"} - {s for s in ("Examples",) if doc[s]}
        if not (doc["Parameters"] or doc["Attributes"]):
            missing.add("Parameters or Attributes")
        return missing
    doc = numpydoc.FunctionDoc(value)
    needed = ["Returns", "Raises", "Examples"]
    try:
        if inspect.signature(value).parameters:  # type: ignore[arg-type]
            needed.append("Parameters")
    except (TypeError, ValueError):  # pragma: no cover - a builtin without a signature
        needed.append("Parameters")
    return {section for section in needed if not doc[section]}


def test_every_public_name_documents_its_sections() -> None:
    gaps = {name: missing for name, value in _public().items() if (missing := _missing(value))}
    new = {name: sorted(gaps[name] - KNOWN_GAPS.get(name, set())) for name in gaps}
    assert not {name: missing for name, missing in new.items() if missing}
    closed = {name: sorted(KNOWN_GAPS[name] - gaps.get(name, set())) for name in KNOWN_GAPS}
    assert not {name: done for name, done in closed.items() if done}, "remove from KNOWN_GAPS"


def test_the_public_names_are_many() -> None:
    assert len(_public()) > 150
