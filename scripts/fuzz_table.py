"""The tally of a property campaign (the JSON that tests/properties/conftest.py writes) as a
Markdown table: per public function, the cases run and their outcomes by class.

    python scripts/fuzz_table.py tally.json
"""

from __future__ import annotations

import json
import sys
from collections import Counter


def table(report: dict[str, object]) -> str:
    functions = report["functions"]
    assert isinstance(functions, dict)
    lines = [
        f"{report['max_examples']} examples per property ({report['profile']} profile), "
        f"exit status {report['exit_status']}.",
        "",
        "| function | cases | outcomes |",
        "| --- | ---: | --- |",
    ]
    totals: Counter[str] = Counter()
    for name, outcomes in functions.items():
        counts = Counter({str(k): int(v) for k, v in outcomes.items()})
        totals.update(counts)
        shown = ", ".join(f"{k} {v}" for k, v in counts.most_common())
        lines.append(f"| `{name}` | {sum(counts.values())} | {shown or 'none'} |")
    shown = ", ".join(f"{k} {v}" for k, v in totals.most_common())
    lines.append(f"| all | {sum(totals.values())} | {shown} |")
    return "\n".join(lines)


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as source:
        print(table(json.load(source)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
