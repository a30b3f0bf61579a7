"""Sphinx extension: the API reference pages, written from the package's ``__all__`` lists.

Every public name of :mod:`aerocontrol` and of its public submodules gets an entry (a row of
the module page's summary table, and its documentation below), grouped by the module that
defines it, so that a name added to ``__all__`` is documented without editing the site, and
the build fails (``-W``) when one has no docstring to show.
"""

from __future__ import annotations

import importlib
import inspect
from pathlib import Path
from typing import Any

#: The public modules whose ``__all__`` is documented, with the page's title.
MODULES = {
    "aerocontrol": "aerocontrol",
    "aerocontrol.aircraft": "aerocontrol.aircraft: aircraft files and models",
    "aerocontrol.handling": "aerocontrol.handling: MIL-F-8785C Levels and MIL-F-9490D margins",
    "aerocontrol.design": "aerocontrol.design: the design studies",
    "aerocontrol.batch": "aerocontrol.batch: batches and sweeps",
    "aerocontrol.robustness": "aerocontrol.robustness: stochastic robustness",
    "aerocontrol.schedule": "aerocontrol.schedule: gain schedules over the envelope",
    "aerocontrol.chapter": "aerocontrol.chapter: the chapter's matrices",
    "aerocontrol.plotting": "aerocontrol.plotting: figures",
    "aerocontrol.report": "aerocontrol.report: the report",
    "aerocontrol.exceptions": "aerocontrol.exceptions: errors and warnings",
    "aerocontrol.accelerate": "aerocontrol.accelerate: python-control on aerocontrol's kernels",
}


def _summary(module: Any) -> str:
    doc = inspect.getdoc(module) or ""
    return doc.split("\n\n", 1)[0].replace("\n", " ")


def _groups(name: str) -> dict[str, list[str]]:
    """The names of ``name.__all__`` by the module that defines them (top level only)."""
    module = importlib.import_module(name)
    groups: dict[str, list[str]] = {}
    for public in module.__all__:
        value = getattr(module, public)
        if inspect.ismodule(value):  # a submodule: its own page
            continue
        home = getattr(value, "__module__", None) if name == "aerocontrol" else None
        if not isinstance(home, str) or not home.startswith("aerocontrol"):
            home = name
        groups.setdefault(home, []).append(public)
    return groups


def _directive(module: str, public: str) -> list[str]:
    """The autodoc entry of one name: its whole documentation on the module's page."""
    value = getattr(importlib.import_module(module), public)
    if inspect.isclass(value) and issubclass(value, BaseException):
        return [f".. autoexception:: {public}", "   :show-inheritance:", ""]
    if inspect.isclass(value):
        entry = [f".. autoclass:: {public}", "   :members:", "   :undoc-members:"]
        # Methods a public class takes from a private base of aerocontrol's (the probabilities
        # the two Monte Carlo results share) are documented as the class's own.
        if any(base.__name__.startswith("_") for base in value.__mro__[1:-1]):
            entry.append("   :inherited-members: Result")
        return [*entry, ""]
    if callable(value):
        return [f".. autofunction:: {public}", ""]
    return [f".. autodata:: {public}", "   :no-value:", ""]


def _page(name: str, title: str) -> str:
    """One page per module: a summary table of its names, then each name's documentation
    (one page per module, not per name, keeps the site's navigation small)."""
    lines = [title, "=" * len(title), "", f".. automodule:: {name}", "   :no-members:", ""]
    for home, names in sorted(_groups(name).items()):
        ordered = sorted(names, key=str.lower)
        if name == "aerocontrol":
            heading = f"From ``{home}``"
            lines += [heading, "-" * len(heading), "", _summary(importlib.import_module(home)), ""]
        lines += [f".. currentmodule:: {name}", "", ".. autosummary::", ""]
        lines += [f"   {public}" for public in ordered]
        lines.append("")
        for public in ordered:
            lines += _directive(name, public)
    return "\n".join(lines)


def write_pages(app: Any) -> None:
    """Write ``docs/api/<module>.rst`` for every module of :data:`MODULES` (unchanged files
    are left alone, so that Sphinx does not rebuild them)."""
    folder = Path(app.srcdir) / "api"
    folder.mkdir(exist_ok=True)
    for name, title in MODULES.items():
        path = folder / f"{name}.rst"
        text = _page(name, title)
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", write_pages, priority=100)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
