"""Regenerate python/aerocontrol/aircraft/aircraft.schema.json, the JSON Schema of the aircraft
file shipped for editors, from the reader's own definitions (aerocontrol.aircraft.json_schema).

    PYTHONPATH=python python scripts/aircraft_schema.py          # write the file
    PYTHONPATH=python python scripts/aircraft_schema.py --check  # exit 1 if it is out of date

tests/test_check.py fails while the shipped file differs from the generated schema.
"""

from __future__ import annotations

import sys
from pathlib import Path

from aerocontrol.aircraft.keys import SCHEMA_FILE, schema_text

TARGET = (
    Path(__file__).resolve().parent.parent / "python" / "aerocontrol" / "aircraft" / SCHEMA_FILE
)


def main(argv: list[str]) -> int:
    text = schema_text()
    if "--check" in argv:
        current = TARGET.read_text(encoding="utf-8") if TARGET.is_file() else ""
        if current != text:
            print(f"{TARGET} is out of date: run scripts/aircraft_schema.py", file=sys.stderr)
            return 1
        return 0
    TARGET.write_text(text, encoding="utf-8")
    print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
