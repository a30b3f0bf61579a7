"""Sphinx extension: the ``aircraft-keys`` directive, the reference table of every key of an
aircraft file, written from the definitions the reader itself uses
(:data:`aerocontrol.aircraft.keys.FILE_KEYS`, :data:`~aerocontrol.aircraft.keys.TABLES`,
:data:`~aerocontrol.aircraft.PLAUSIBLE_RANGES`), so the page cannot drift from the reader."""

from __future__ import annotations

from typing import Any

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.util.docutils import SphinxDirective

from aerocontrol.aircraft import PLAUSIBLE_RANGES
from aerocontrol.aircraft.keys import FILE_KEYS, TABLES, Key


def _required(spec: Key) -> str:
    if spec.required is True:
        return "yes"
    if spec.required is False:
        return "no"
    return "one of " + ", ".join(f"``{name}``" for name in str(spec.required).split("|"))


def _values(key: str, spec: Key) -> str:
    if spec.kind == "choice":
        return ", ".join(f'``"{choice}"``' for choice in spec.choices)
    if spec.kind == "string":
        return f"text, at most {spec.limit:,} characters"
    span = PLAUSIBLE_RANGES[key]
    ranges = []
    for units in ("english", "si"):
        low, high, unit = span.bounds(units)
        text = f"{low:g} to {high:g}" + (f" {unit}" if unit else "")
        if text not in ranges:
            ranges.append(text)
    return " (English); ".join(ranges) + (" (SI)" if len(ranges) == 2 else "")


def _table_rows() -> list[str]:
    lines: list[str] = []
    for table, keys in FILE_KEYS.items():
        lines += [
            f".. list-table:: ``[{table}]``: {TABLES[table]}",
            "   :header-rows: 1",
            "   :widths: 14 12 30 44",
            "",
            "   * - key",
            "     - required",
            "     - values",
            "     - meaning",
        ]
        for key, spec in keys.items():
            lines += [
                f"   * - ``{key}``",
                f"     - {_required(spec)}",
                f"     - {_values(key, spec)}",
                f"     - {spec.description}",
            ]
        lines.append("")
    return lines


class AircraftKeys(SphinxDirective):
    """``.. aircraft-keys::``: one table per table of plain keys of an aircraft file."""

    has_content = False

    def run(self) -> list[nodes.Node]:
        container = nodes.container()
        self.state.nested_parse(StringList(_table_rows(), source="aircraft-keys"), 0, container)
        return [container]


def setup(app: Any) -> dict[str, Any]:
    app.add_directive("aircraft-keys", AircraftKeys)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
