"""``aerocontrol check`` and ``aerocontrol schema``: every problem of an aircraft file with its
key, line and hint; the modes and Levels of a valid one; and the JSON Schema of the format,
generated from the reader's own definitions."""

from __future__ import annotations

import json
import math
import pickle
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from aerocontrol import aircraft, cli, handling
from aerocontrol.aircraft import keys
from aerocontrol.aircraft.naming import classify_modes
from aerocontrol.aircraft.reader import key_lines, parse_toml, read_source, resources
from aerocontrol.aircraft.schema import PLAUSIBLE_RANGES, AircraftDataError
from aerocontrol.aircraft.tables import table_problems

ROOT = Path(__file__).resolve().parent.parent


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        status = cli.main(list(argv))
    except SystemExit as exit_:
        status = int(exit_.code or 0)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def _shipped(identifier: str) -> str:
    data = resources.files("aerocontrol.aircraft.data")
    return data.joinpath(f"{identifier}.toml").read_text(encoding="utf-8")


def _broken(tmp_path: Path, identifier: str, *edits: tuple[str, str]) -> tuple[Path, list[str]]:
    """A copy of a shipped file with each (old, new) line replaced once; the file and its lines."""
    text = _shipped(identifier)
    for old, new in edits:
        assert text.count(old) >= 1, old
        text = text.replace(old, new, 1)
    path = tmp_path / f"{identifier}-broken.toml"
    path.write_text(text, encoding="utf-8")
    return path, text.splitlines()


def _line_of(lines: list[str], start: str) -> int:
    """The 1-based line that starts with ``start`` (the oracle for the reported lines)."""
    matches = [n for n, line in enumerate(lines, start=1) if line.startswith(start)]
    assert len(matches) == 1, (start, matches)
    return matches[0]


# ---------------------------------------------------------------------------------------------
# check: every problem at once
# ---------------------------------------------------------------------------------------------

EDITS = (
    ('class = "III"', 'class = "3"'),  # not one of the classes
    ("density = 0.002377", "density = 1.225"),  # kg/m^3 in an English file
    ("Ix = 14.3e6", 'Ix = "14.3e6"'),  # a string
    ("Cm_q = -20.8", "Cm_qq = -20.8"),  # a typo: unknown Cm_qq, missing Cm_q
    ("b = 195.7", "b = 19570.0"),  # beyond the plausible 1,600 ft
    ("roll = { time_to_half = 0.56 }", "roll = { time_to_halve = 0.56 }"),
    ("\n[sources]\n", "\n[sauces]\n"),  # an unknown table
)


def test_every_problem_is_reported_with_its_key_line_and_hint(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path, lines = _broken(tmp_path, "b747-approach", *EDITS)
    expected = [
        (_line_of(lines, 'class = "3"'), "aircraft.class", "got '3'", "write one of 'I', "),
        (
            _line_of(lines, "density = 1.225"),
            "flight.density",
            "density = 1.225 slug/ft^3 is not plausible at 0 ft",
            "give the density in slug/ft^3 (not kg/m^3)",
        ),
        (
            _line_of(lines, 'Ix = "14.3e6"'),
            "mass.Ix",
            "Ix must be a finite number, got '14.3e6'",
            "write a number without quotes, such as Ix = 14.3e6",
        ),
        (
            _line_of(lines, "b = 19570.0"),
            "geometry.b",
            "b = 19570 ft is outside the plausible range 0.15 to 1600 ft",
            "the file's units are 'english'",
        ),
        (
            _line_of(lines, "[longitudinal]"),
            "longitudinal.Cm_q",
            "[longitudinal] is missing Cm_q",
            "is Cm_qq meant to be Cm_q?",
        ),
        (
            _line_of(lines, "Cm_qq = -20.8"),
            "longitudinal.Cm_qq",
            "[longitudinal] has unknown key Cm_qq",
            "did you mean Cm_q?",
        ),
        (
            _line_of(lines, "roll = { time_to_halve"),
            "published.roll",
            "unknown quantity time_to_halve",
            "did you mean time_to_half?",
        ),
        (_line_of(lines, "[sauces]"), "sauces", "unknown table sauces", "did you mean [sources]?"),
    ]
    found = aircraft.problems(path)
    assert [(p.line, p.key) for p in found] == [(line, key) for line, key, _, _ in expected]
    for problem, (_, _, message, hint) in zip(found, expected, strict=True):
        assert message in str(problem) and hint in problem.hint, (str(problem), problem.hint)
        assert str(problem).startswith(f"{path}: ")

    status, out, err = _run(capsys, "check", str(path))
    assert status == 1 and err == ""
    printed = out.splitlines()
    assert printed[-1] == f"{len(expected)} problems"
    assert len(printed) == len(expected) + 1
    for text, (line, key, message, hint) in zip(printed[:-1], expected, strict=True):
        assert text.startswith(f"{path}:{line}: {key}: ")
        assert message in text and f"(hint: {hint}" in text


def test_load_still_raises_the_first_problem_with_its_message(tmp_path: Path) -> None:
    """The reader goes on past a problem, but load stops as before: the first problem in the
    order of the checks, with the message a reader that stops there gives."""
    path, _ = _broken(tmp_path, "b747-approach", *EDITS)
    with pytest.raises(AircraftDataError) as raised:
        aircraft.load(path)
    assert str(raised.value) == (
        f"{path}: [aircraft] class must be one of 'I', 'II-C', 'II-L', 'III', 'IV', 'II', got '3'"
    )
    assert raised.value.key == "aircraft.class" and raised.value.line == 10
    # Several unknown keys of a table: one message for load, one problem per key for check.
    path, lines = _broken(tmp_path, "navion", ("Cn_r = -0.125", "Cn_r = -0.125\ncn_r = 1\nXyz = 2"))
    with pytest.raises(AircraftDataError, match=r"\[lateral\] has unknown key\(s\) cn_r, Xyz;"):
        aircraft.load(path)
    found = aircraft.problems(path)
    assert [(p.line, p.key, p.hint) for p in found] == [
        (_line_of(lines, "cn_r = 1"), "lateral.cn_r", "did you mean Cn_r?"),
        (
            _line_of(lines, "Xyz = 2"),
            "lateral.Xyz",
            f"the keys are {', '.join(aircraft.LATERAL_DERIVATIVES)}",
        ),
    ]


def test_problems_that_follow_from_another_are_not_reported(tmp_path: Path) -> None:
    """Bad units: the dimensional ranges are not judged (no second problem per number), but a
    wrong type still is; a missing table is one problem, not one per key."""
    path, lines = _broken(
        tmp_path,
        "navion",
        ('units = "english"', 'units = "imperial"'),
        ("weight = 2750.0", "weight = 2750.0e9"),  # outside both ranges, not judged
        ("Iy = 3000.0", "Iy = -3000.0"),  # the sign is judged whatever the units
        ("[geometry]\nS = 184.0 ", "[geometry_data]\nS = 184.0 "),
    )
    found = aircraft.problems(path)
    assert [(p.key, p.line) for p in found] == [
        ("aircraft.units", _line_of(lines, 'units = "imperial"')),
        ("mass.Iy", _line_of(lines, "Iy = -3000.0")),
        ("geometry_data", _line_of(lines, "[geometry_data]")),
        ("geometry", None),
    ]
    assert found[0].hint == "write one of 'english', 'si'"
    assert found[3].hint.startswith("is [geometry_data] meant to be [geometry]?")


def test_a_file_that_is_not_toml_is_one_problem_at_the_parsers_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path, lines = _broken(tmp_path, "navion", ("Cm_q = -9.96", "Cm_q = "))
    found = aircraft.problems(path)
    assert len(found) == 1 and found[0].line == _line_of(lines, "Cm_q = ")
    assert "not valid TOML" in str(found[0])
    status, out, _ = _run(capsys, "check", str(path))
    assert status == 1 and out.startswith(f"{path}:{found[0].line}: not valid TOML")
    status, out, _ = _run(capsys, "check", str(tmp_path / "none.toml"))
    assert status == 1 and "cannot read the aircraft file" in out and out.endswith("1 problem\n")


def test_key_lines_follow_tables_inline_tables_and_multiline_strings() -> None:
    text = (
        "[a]\nx = 1\ns = '''\n[b]\ny = 2\n'''\n"  # a multi-line string that looks like TOML
        '"q k" = 3\n[c.d]\nz = { p = 1, "r" = 2 }\n'
    )
    lines = key_lines(text)
    assert lines == {
        "a": 1,
        "a.x": 2,
        "a.s": 3,
        "a.q k": 7,
        "c.d": 8,
        "c.d.z": 9,
        "c.d.z.p": 9,
        "c.d.z.r": 9,
    }
    # The oracle for a shipped file: every table and key tomllib reads has a line whose text
    # starts with that key (or, for a table, its header).
    text, origin = read_source("b747-approach")
    data = parse_toml(text, origin)
    lines = key_lines(text)
    rows = text.splitlines()
    for table, entries in data.items():
        assert rows[lines[table] - 1] == f"[{table}]"
        for key in entries:
            assert rows[lines[f"{table}.{key}"] - 1].startswith(f"{key} = ")


def test_every_shipped_aircraft_checks_clean() -> None:
    for identifier in aircraft.available():
        text, origin = read_source(identifier)
        assert table_problems(parse_toml(text, origin), origin, text) == []
        assert aircraft.problems(identifier) == []


def test_the_error_keeps_key_line_and_hint_through_pickle() -> None:
    error = AircraftDataError("f.toml: [mass] is missing Ix", "mass.Ix", 3, "add Ix")
    copy = pickle.loads(pickle.dumps(error))
    assert (str(copy), copy.key, copy.line, copy.hint) == (str(error), "mass.Ix", 3, "add Ix")
    assert isinstance(copy, ValueError)


_EIGENVALUE = re.compile(r"(-?\d+\.\d+(?:e[+-]\d+)?)(?: ± (\d+\.\d+)j)?")


def test_a_valid_file_prints_modes_and_levels_as_assess_finds_them(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The modes (eigenvalues from numpy, to the 5 printed digits) and every requirement's
    Level of handling.assess on the same aircraft."""
    path, _ = _broken(tmp_path, "f4c-approach", ("# ", "#  "))  # a copy, unchanged
    status, out, err = _run(capsys, "check", str(path))
    assert status == 0 and err == ""
    plane = aircraft.load(path)
    assert out.splitlines()[0] == plane.summary()
    named: dict[str, Any] = {}
    for axis, system in (("longitudinal", plane.longitudinal()), ("lateral", plane.lateral())):
        eigenvalues = np.linalg.eigvals(system.A)
        named.update(classify_modes(eigenvalues, axis))
        section = out.split(f"{axis} modes\n", 1)[1].split("\n\n", 1)[0].splitlines()[2:]
        printed = []
        for row in section:
            match = _EIGENVALUE.search(row[20:])
            assert match is not None, row
            printed.append(complex(float(match.group(1)), float(match.group(2) or 0.0)))
        assert len(printed) == len({complex(v.real, abs(v.imag)) for v in eigenvalues})
        for value in printed:
            nearest = min(eigenvalues, key=lambda v: abs(complex(v.real, abs(v.imag)) - value))
            assert abs(complex(nearest.real, abs(nearest.imag)) - value) <= 1e-4 * abs(value)
    quality = handling.assess(named, plane.aircraft_class, plane.category)
    table = out.split("MIL-F-8785C handling qualities", 1)[1].splitlines()[3:]
    rows = [re.split(r"\s{2,}", row.strip()) for row in table if row.strip()]
    assert [(row[0], row[1], int(row[3])) for row in rows] == [
        (r.mode, r.quantity, r.level) for r in quality.requirements
    ]


def test_check_takes_a_shipped_identifier_and_help(capsys: pytest.CaptureFixture[str]) -> None:
    status, out, _ = _run(capsys, "check", "b747-approach")
    assert status == 0 and "dutch roll    zeta*omega_n    0.08066 rad/s  2" in out
    for command in ("check", "schema"):
        status, out, _ = _run(capsys, command, "--help")
        assert status == 0 and out.startswith(f"usage: aerocontrol {command}")


# ---------------------------------------------------------------------------------------------
# The JSON Schema
# ---------------------------------------------------------------------------------------------


def _numbers(schema: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Every number of the schema by dotted key (tables and [published] modes)."""
    found: dict[str, dict[str, Any]] = {}
    for table, spec in schema["properties"].items():
        for key, entry in spec.get("properties", {}).items():
            if entry.get("type") == "number":
                found[f"{table}.{key}"] = entry
            for inner, quantity in entry.get("properties", {}).items():
                if quantity.get("type") == "number":
                    found[f"{table}.{key}.{inner}"] = quantity
    return found


def _bounds(schema: dict[str, Any], dotted: str, units: str) -> tuple[float, float]:
    """The minimum and maximum of a number for a file in ``units``: its own or, for a
    dimensional number, those of the if/then branch of those units."""
    table, key = dotted.split(".")[0], dotted.split(".")[-1]
    entry = _numbers(schema)[dotted]
    if "minimum" in entry:
        return entry["minimum"], entry["maximum"]
    (branch,) = [
        b
        for b in schema["allOf"]
        if b["if"]["properties"]["aircraft"]["properties"]["units"]["const"] == units
    ]
    bounds = branch["then"]["properties"][table]["properties"][key]
    return bounds["minimum"], bounds["maximum"]


def test_the_schema_has_the_shape_of_draft_2020_12() -> None:
    schema = aircraft.json_schema()
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["type"] == "object" and schema["additionalProperties"] is False
    assert schema["required"] == [
        "aircraft",
        "flight",
        "mass",
        "geometry",
        "longitudinal",
        "lateral",
    ]
    for table, spec in schema["properties"].items():
        assert spec["type"] == "object" and spec["description"], table
        assert set(spec.get("required", [])) <= set(spec["properties"]), table
    assert schema["properties"]["flight"]["allOf"] == [
        {"oneOf": [{"required": ["speed"]}, {"required": ["mach"]}]}
    ]
    # Every $ref resolves inside the document.
    for ref in re.findall(r'"\$ref": "#/([^"]+)"', json.dumps(schema)):
        node: Any = schema
        for part in ref.split("/"):
            node = node[part]
        assert node["type"] == "object"
    # Every value is JSON (the round trip changes nothing).
    assert json.loads(json.dumps(schema)) == schema


def test_the_schema_names_the_keys_the_reader_accepts_and_no_other() -> None:
    """The reader is the oracle: a key of the schema added to a valid file is not reported
    unknown; a key outside it is."""
    schema = aircraft.json_schema()
    text, origin = read_source("b747-approach")
    for table in ("aircraft", "flight", "mass", "geometry", "longitudinal", "lateral"):
        spec = schema["properties"][table]
        for key in spec["properties"]:
            data = parse_toml(text, origin)
            data[table].setdefault(key, 1.0)
            messages = [str(p) for p in table_problems(data, origin)]
            assert not any("unknown" in m for m in messages), (table, key, messages)
        data = parse_toml(text, origin)
        data[table]["Cm_x"] = 1.0
        assert [p.key for p in table_problems(data, origin)] == [f"{table}.Cm_x"]
        # Required keys: removing one is a problem exactly when the schema requires it.
        for key in list(parse_toml(text, origin)[table]):
            data = parse_toml(text, origin)
            del data[table][key]
            missing = any("missing" in str(p) for p in table_problems(data, origin))
            assert missing == (key in spec["required"]), (table, key)
        for key, entry in spec["properties"].items():
            if "enum" in entry:
                for value in [*entry["enum"], "other"]:
                    data = parse_toml(text, origin)
                    data[table][key] = value
                    if key == "axes" and value == "body":
                        data["flight"]["alpha0_deg"] = 0.0
                    if key == "units":  # the file's density is in slug/ft^3
                        del data["flight"]["density"]
                    assert (table_problems(data, origin) == []) == (value in entry["enum"])
    for mode, spec in schema["properties"]["published"]["properties"].items():
        if mode == "tolerance":
            continue
        for quantity in spec["properties"]:
            data = parse_toml(text, origin)
            data["published"][mode] = {quantity: 0.5}
            if quantity == "tolerance":  # a mode's tolerance goes with a quantity
                data["published"][mode][spec["anyOf"][0]["required"][0]] = 1.0
            assert table_problems(data, origin) == [], (mode, quantity)
    assert set(schema["properties"]) == set(keys.TABLES)
    data = parse_toml(text, origin)
    data["tables"] = {}
    assert [p.key for p in table_problems(data, origin)] == ["tables"]
    uncertain = schema["properties"]["uncertainty"]["properties"]
    assert set(uncertain) == {
        *aircraft.LONGITUDINAL_DERIVATIVES,
        *aircraft.LATERAL_DERIVATIVES,
        *keys.UNCERTAIN_FIELDS,
        "correlations",
    }
    for name in uncertain:
        data = parse_toml(text, origin)
        data["uncertainty"] = {name: {"distribution": "uniform", "half_width": 0.1}}
        if name == "correlations":
            data["uncertainty"] = {"correlations": []}
        assert table_problems(data, origin) == [], name


def test_the_schemas_ranges_are_the_plausible_ranges() -> None:
    schema = aircraft.json_schema()
    numbers = _numbers(schema)
    assert {dotted.split(".")[-1] for dotted in numbers} == set(PLAUSIBLE_RANGES)
    for dotted, entry in numbers.items():
        plausible = PLAUSIBLE_RANGES[dotted.split(".")[-1]]
        for units in ("si", "english"):
            low, high, unit = plausible.bounds(units)
            assert _bounds(schema, dotted, units) == (low, high), (dotted, units)
            if unit:
                assert unit in entry["description"], dotted
        if plausible.english_low is not None:
            assert entry["x-units"] == {"si": plausible.si_unit, "english": plausible.english_unit}


def _check_value(entry: dict[str, Any], value: Any, where: str) -> None:
    if entry.get("type") == "number":
        assert isinstance(value, (int, float)) and not isinstance(value, bool), where
        if "exclusiveMinimum" in entry:
            assert value > entry["exclusiveMinimum"], where
    elif entry.get("type") == "string":
        assert isinstance(value, str) and len(value) <= entry.get("maxLength", math.inf), where
        assert "enum" not in entry or value in entry["enum"], where


def test_every_shipped_file_fits_the_schema() -> None:
    schema = aircraft.json_schema()
    for identifier in aircraft.available():
        text, origin = read_source(identifier)
        data = parse_toml(text, origin)
        units = data["aircraft"]["units"]
        assert set(schema["required"]) <= set(data) <= set(schema["properties"])
        for table, entries in data.items():
            spec = schema["properties"][table]
            assert set(spec.get("required", [])) <= set(entries), (identifier, table)
            for key, value in entries.items():
                where = f"{identifier}: {table}.{key}"
                if key not in spec["properties"]:
                    assert spec["additionalProperties"] == {"type": "string", "maxLength": 20000}
                    _check_value(spec["additionalProperties"], value, where)
                    continue
                entry = spec["properties"][key]
                if isinstance(value, dict):  # a [published] mode
                    assert set(value) <= set(entry["properties"]), where
                    for inner, number in value.items():
                        _check_value(entry["properties"][inner], number, where)
                        low, high = _bounds(schema, f"{table}.{key}.{inner}", units)
                        assert low <= number <= high, where
                    continue
                _check_value(entry, value, where)
                if entry.get("type") == "number":
                    low, high = _bounds(schema, f"{table}.{key}", units)
                    assert low <= value <= high, where


def test_the_shipped_schema_file_is_the_generated_one(capsys: pytest.CaptureFixture[str]) -> None:
    shipped = ROOT / "python" / "aerocontrol" / "aircraft" / "aircraft.schema.json"
    assert shipped.read_text(encoding="utf-8") == keys.schema_text(), (
        "run: PYTHONPATH=python python scripts/aircraft_schema.py"
    )
    assert keys.shipped_json_schema() == aircraft.json_schema()
    status, out, err = _run(capsys, "schema")
    assert status == 0 and err == ""
    assert json.loads(out) == aircraft.json_schema()
    # A new dict every call: a caller's edit does not leak into the next.
    first = aircraft.json_schema()
    first["properties"].clear()
    assert aircraft.json_schema()["properties"]


def test_uncertainty_and_published_problems_are_each_reported(tmp_path: Path) -> None:
    uncertainty = (
        "\n[uncertainty]\n"
        'Cn_bta = { distribution = "normal", sigma = 0.1 }\n'
        'Cl_p = { distribution = "normal", sigma = -0.1 }\n'
        'Cn_r = { distribution = "lognormal", sigma = 0.1, relative = false }\n'
        'Cl_r = { distribution = "gaussian", sigma = 0.1 }\n'
    )
    path, lines = _broken(
        tmp_path,
        "navion",
        ("spiral = { time_constant = 114.16 }", "spiral = { time_constant = -114.16 }"),
        (
            "phugoid = { omega_n = 0.2137, zeta = 0.0801 }",
            "phugoid = { omega_n = 0.2137, zeta = 0 }",
        ),
        (
            "alpha0_deg = 0.6 ",
            "alpha0_deg = 95.0 ",
        ),  # checked though the inertias are stability-axis
        ("\n[sources]\n", f"{uncertainty}\n[sources]\n"),
    )
    found = aircraft.problems(path)
    assert [(p.line, p.key) for p in found] == [
        (_line_of(lines, "alpha0_deg = 95.0"), "flight.alpha0_deg"),
        (_line_of(lines, "phugoid = "), "published.phugoid.zeta"),
        (_line_of(lines, "spiral = "), "published.spiral.time_constant"),
        (_line_of(lines, "Cn_bta = "), "uncertainty.Cn_bta"),
        (_line_of(lines, "Cl_p = { d"), "uncertainty.Cl_p.sigma"),
        (_line_of(lines, "Cn_r = { d"), "uncertainty.Cn_r.relative"),
        (_line_of(lines, "Cl_r = { d"), "uncertainty.Cl_r.distribution"),
    ]
    assert found[0].hint == "is the value mistyped?"
    assert "outside the plausible range -89 to 89 deg" in str(found[0])
    assert found[3].hint == "did you mean Cn_beta?"
    assert found[6].hint == "write one of 'normal', 'uniform', 'lognormal'"
