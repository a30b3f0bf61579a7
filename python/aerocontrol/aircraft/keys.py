"""The keys of an aircraft file, in one place: their tables, whether each is required, its kind
and its description. The reader (:mod:`~aerocontrol.aircraft.tables`) takes the keys it
accepts and requires from here, and :func:`json_schema` generates the JSON Schema of the
format from the same definitions, with the units of :data:`~aerocontrol.aircraft.schema.
UNIT_NAMES` and the bounds of :data:`~aerocontrol.aircraft.PLAUSIBLE_RANGES`, so that
neither can drift from what the reader does.

Derivatives are per radian in stability axes, the rate derivatives with respect to the
nondimensional rates q c̄/(2 u0), α̇ c̄/(2 u0), p b/(2 u0) and r b/(2 u0), as in the chapter's
(6.48) and (6.148).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from typing import Any

from .schema import PLAUSIBLE_RANGES, UNIT_NAMES

__all__ = [
    "FILE_KEYS",
    "LATERAL_DERIVATIVES",
    "LONGITUDINAL_DERIVATIVES",
    "PUBLISHED_MODES",
    "REQUIRED_TABLES",
    "TABLES",
    "UNCERTAINTY_SPREADS",
    "UNCERTAIN_FIELDS",
    "Key",
    "json_schema",
    "schema_text",
    "shipped_json_schema",
]


@dataclass(frozen=True)
class Key:
    """One key of a table of an aircraft file.

    ``kind`` is ``"number"`` (its plausible range in :data:`PLAUSIBLE_RANGES` under the key's
    name), ``"string"`` (at most ``limit`` characters) or ``"choice"`` (one of ``choices``);
    ``required`` is True, False, or the name of a group of keys of which exactly one is given
    (``"speed|mach"``).

    Examples
    --------
    >>> speed = FILE_KEYS["flight"]["speed"]
    >>> speed.kind, speed.required, speed.positive
    ('number', 'speed|mach', True)
    >>> [key for key, spec in FILE_KEYS["mass"].items() if spec.required is True]
    ['Ix', 'Iy', 'Iz', 'Ixz', 'axes']
    """

    description: str
    kind: str = "number"
    required: bool | str = True
    choices: tuple[str, ...] = ()
    limit: int = 0
    positive: bool = False


_NAME_LIMIT = 200
_DESCRIPTION_LIMIT = 2_000
_SOURCE_LIMIT = 20_000
_CLASSES = ("I", "II-C", "II-L", "III", "IV", "II")
_CATEGORIES = ("A", "B", "C")

_LONGITUDINAL = {
    "CL": "trim lift coefficient",
    "CD": "trim drag coefficient",
    "CL_alpha": "lift-curve slope dCL/dα",
    "CL_alphadot": "dCL/d(α̇ c̄/2u0); positive when a rising α raises the lift",
    "CL_q": "dCL/d(q c̄/2u0)",
    "CL_M": "dCL/dM, the lift's change with Mach number (0 if the source does not give it)",
    "CD_alpha": "dCD/dα",
    "CD_M": "dCD/dM (0 if the source does not give it)",
    "Cm_alpha": "pitch stiffness dCm/dα; negative for a statically stable airplane",
    "Cm_alphadot": "dCm/d(α̇ c̄/2u0)",
    "Cm_q": "pitch damping dCm/d(q c̄/2u0); negative",
    "Cm_M": "dCm/dM (0 if the source does not give it)",
    "CL_de": "dCL/dδe, δe positive trailing edge down",
    "CD_de": "dCD/dδe",
    "Cm_de": "elevator power dCm/dδe, δe positive trailing edge down; negative",
}
_LATERAL = {
    "Cy_beta": "side force dCy/dβ",
    "Cy_p": "dCy/d(p b/2u0)",
    "Cy_r": "dCy/d(r b/2u0)",
    "Cl_beta": "dihedral effect dCl/dβ; negative for a stable airplane",
    "Cl_p": "roll damping dCl/d(p b/2u0); negative",
    "Cl_r": "dCl/d(r b/2u0)",
    "Cn_beta": "weathercock stability dCn/dβ; positive for a stable airplane",
    "Cn_p": "dCn/d(p b/2u0)",
    "Cn_r": "yaw damping dCn/d(r b/2u0); negative",
    "Cy_dr": "dCy/dδr",
    "Cl_dr": "dCl/dδr",
    "Cn_dr": "rudder power dCn/dδr",
    "Cy_da": "dCy/dδa",
    "Cl_da": "aileron power dCl/dδa; positive when a positive δa rolls the right "
    "wing down, as in the shipped files",
    "Cn_da": "adverse or proverse yaw dCn/dδa",
}
LONGITUDINAL_DERIVATIVES = tuple(_LONGITUDINAL)
"""The longitudinal coefficients and derivatives (per radian) an aircraft file must give."""
LATERAL_DERIVATIVES = tuple(_LATERAL)
"""The lateral-directional derivatives (per radian) an aircraft file must give."""

#: The distributions of an [uncertainty] entry and the key of each one's spread.
UNCERTAINTY_SPREADS = {"normal": "sigma", "uniform": "half_width", "lognormal": "sigma"}
#: What besides the derivatives an [uncertainty] table may scatter (as
#: ``Aircraft.model_stack`` can vary it).
UNCERTAIN_FIELDS = ("mass", "Ix", "Iy", "Iz", "Ixz", "speed", "density")

_OSCILLATORY = ("omega_n", "zeta")
_APERIODIC = ("time_constant", "time_to_half", "time_to_double")
PUBLISHED_MODES = {
    "short_period": _OSCILLATORY,
    "phugoid": _OSCILLATORY,
    "dutch_roll": _OSCILLATORY,
    "roll": _APERIODIC,
    "spiral": _APERIODIC,
}
"""The modes a file's [published] table may give, each with the quantities it may carry
(omega_n in rad/s, zeta; time_constant, time_to_half and time_to_double in s). Any mode may
also carry its own relative ``tolerance``, which then replaces the file-level ``tolerance``."""

_PUBLISHED_QUANTITIES = {
    "omega_n": "undamped natural frequency",
    "zeta": "damping ratio (negative for an unstable oscillation, never 0)",
    "time_constant": "time constant -1/λ of the real root",
    "time_to_half": "time to half amplitude ln 2 / -λ of a stable root",
    "time_to_double": "time to double amplitude ln 2 / λ of an unstable root",
    "tolerance": "relative tolerance of this mode's checks, replacing the file-level one",
}

FILE_KEYS: Mapping[str, Mapping[str, Key]] = {
    "aircraft": {
        "name": Key("the aircraft and its condition, one line", "string", limit=_NAME_LIMIT),
        "description": Key(
            "a longer description, one line", "string", False, limit=_DESCRIPTION_LIMIT
        ),
        "class": Key(
            'MIL-F-8785C 1.3 airplane class ("II" reads as "II-L", land-based)',
            "choice",
            choices=_CLASSES,
        ),
        "category": Key(
            "MIL-F-8785C 1.5 flight-phase category of this condition (A nonterminal precise, "
            "B nonterminal gradual, C terminal)",
            "choice",
            choices=_CATEGORIES,
        ),
        "units": Key(
            'the unit system of every dimensional number: "english" (ft, slug, lbf, s) or '
            '"si" (m, kg, N, s)',
            "choice",
            choices=("english", "si"),
        ),
    },
    "flight": {
        "speed": Key("flight speed u0", required="speed|mach", positive=True),
        "mach": Key("flight Mach number", required="speed|mach", positive=True),
        "altitude": Key("geopotential altitude, for the 1976 standard atmosphere"),
        "density": Key(
            "air density (default: the standard atmosphere's at the altitude; within 0.5 to 2 "
            "times it)",
            required=False,
            positive=True,
        ),
        "theta0_deg": Key(
            "equilibrium flight-path angle Θ0 in degrees, positive climbing (default 0)",
            required=False,
        ),
        "alpha0_deg": Key(
            "trim angle of attack of the body x axis in degrees, positive nose up; needed "
            'when [mass] axes = "body"',
            required=False,
        ),
    },
    "mass": {
        "weight": Key("weight W = m g", required="weight|mass", positive=True),
        "mass": Key("mass m", required="weight|mass", positive=True),
        "Ix": Key("rolling moment of inertia, in the axes of [mass] axes", positive=True),
        "Iy": Key("pitching moment of inertia", positive=True),
        "Iz": Key("yawing moment of inertia, in the axes of [mass] axes", positive=True),
        "Ixz": Key(
            "product of inertia ∫ x z dm, in the axes of [mass] axes (Ix Iz > Ixz²)",
        ),
        "axes": Key(
            'the axes of Ix, Iz and Ixz: "stability", or "body" (rotated into stability axes '
            "by [flight] alpha0_deg)",
            "choice",
            choices=("stability", "body"),
        ),
    },
    "geometry": {
        "S": Key("wing reference area", positive=True),
        "cbar": Key("mean aerodynamic chord c̄", positive=True),
        "b": Key("wing span", positive=True),
    },
    "longitudinal": {key: Key(text) for key, text in _LONGITUDINAL.items()},
    "lateral": {key: Key(text) for key, text in _LATERAL.items()},
}
"""The keys of the tables of plain keys, by table (the tables [published], [sources] and
[uncertainty] have keys of their own making: :data:`TABLES`)."""

TABLES = {
    "aircraft": "what the aircraft is, its MIL-F-8785C class and category, and the units",
    "flight": "the flight condition",
    "mass": "mass and inertias",
    "geometry": "reference geometry",
    "longitudinal": "longitudinal coefficients and derivatives, per radian, stability axes",
    "lateral": "lateral-directional derivatives, per radian, stability axes",
    "published": "the source's own mode characteristics, checked against the model's modes",
    "sources": "a citation for the numbers: default, and one per table",
    "uncertainty": "the scatter of uncertain parameters, for aerocontrol robustness",
}
"""Every table of an aircraft file, in the order of a file, with what it holds."""
REQUIRED_TABLES = tuple(FILE_KEYS)
"""The tables every aircraft file gives."""


def _number(key: str, spec: Key | None, description: str) -> dict[str, Any]:
    """The schema of a number: its range (unitless) or its units, bounds set by units."""
    plausible = PLAUSIBLE_RANGES[key]
    out: dict[str, Any] = {"type": "number"}
    if plausible.english_low is None:
        unit = f" [{plausible.si_unit}]" if plausible.si_unit else ""
        out["description"] = description + unit
        out["minimum"], out["maximum"] = plausible.low, plausible.high
    else:
        si, english = plausible.bounds("si")[2], plausible.bounds("english")[2]
        out["description"] = f"{description} [{si} or {english}, by [aircraft] units]"
        out["x-units"] = {"si": si, "english": english}
    if spec is not None and spec.positive:
        out["exclusiveMinimum"] = 0
    return out


def _key_schema(key: str, spec: Key) -> dict[str, Any]:
    if spec.kind == "number":
        return _number(key, spec, spec.description)
    if spec.kind == "string":
        return {"type": "string", "maxLength": spec.limit, "description": spec.description}
    return {"type": "string", "enum": list(spec.choices), "description": spec.description}


def _table_schema(table: str, keys: Mapping[str, Key]) -> dict[str, Any]:
    required = [key for key, spec in keys.items() if spec.required is True]
    groups = sorted({spec.required for spec in keys.values() if isinstance(spec.required, str)})
    out: dict[str, Any] = {
        "type": "object",
        "description": TABLES[table],
        "properties": {key: _key_schema(key, spec) for key, spec in keys.items()},
        "required": required,
        "additionalProperties": False,
    }
    if groups:
        out["allOf"] = [
            {"oneOf": [{"required": [member]} for member in group.split("|")]} for group in groups
        ]
    return out


def _published_schema() -> dict[str, Any]:
    modes: dict[str, Any] = {}
    for mode, quantities in PUBLISHED_MODES.items():
        properties = {
            name: _number(name, None, _PUBLISHED_QUANTITIES[name])
            for name in (*quantities, "tolerance")
        }
        for name, quantity in properties.items():
            if name == "zeta":
                quantity["not"] = {"const": 0}
            else:
                quantity["exclusiveMinimum"] = 0
        modes[mode] = {
            "type": "object",
            "description": f"the {mode.replace('_', ' ')} as the source gives it",
            "properties": properties,
            "additionalProperties": False,
            "anyOf": [{"required": [name]} for name in quantities],
        }
    tolerance = _number("tolerance", None, "relative tolerance of the checks of every mode")
    tolerance["exclusiveMinimum"] = 0
    return {
        "type": "object",
        "description": TABLES["published"],
        "properties": {"tolerance": tolerance, **modes},
        "additionalProperties": False,
    }


def _scatter_schema() -> dict[str, Any]:
    """The schema of one entry of [uncertainty] (``$defs/scatter``)."""
    branches = []
    for distribution, spread in UNCERTAINTY_SPREADS.items():
        branch: dict[str, Any] = {
            "properties": {
                "distribution": {"const": distribution},
                spread: {"type": "number", "minimum": 0},
                "relative": {"type": "boolean"},
            },
            "required": ["distribution", spread],
            "additionalProperties": False,
        }
        if distribution == "lognormal":
            branch["properties"]["relative"] = {"const": True}
        branches.append(branch)
    return {
        "type": "object",
        "description": "the parameter's distribution and spread (relative to its value "
        "unless relative = false)",
        "oneOf": branches,
    }


def _uncertainty_schema() -> dict[str, Any]:
    parameters = (*LONGITUDINAL_DERIVATIVES, *LATERAL_DERIVATIVES, *UNCERTAIN_FIELDS)
    correlation = {
        "type": "array",
        "prefixItems": [
            {"type": "string", "enum": list(parameters)},
            {"type": "string", "enum": list(parameters)},
            {"type": "number", "exclusiveMinimum": -1, "exclusiveMaximum": 1},
        ],
        "items": False,
        "minItems": 3,
    }
    return {
        "type": "object",
        "description": TABLES["uncertainty"],
        "properties": {
            **{name: {"$ref": "#/$defs/scatter"} for name in parameters},
            "correlations": {
                "type": "array",
                "description": 'correlation coefficients, ["A", "B", rho] with -1 < rho < 1',
                "items": correlation,
            },
        },
        "additionalProperties": False,
    }


def _bounds(units: str) -> dict[str, Any]:
    """The bounds of the dimensional numbers in the unit system ``units``."""
    tables: dict[str, Any] = {}
    for table, keys in FILE_KEYS.items():
        for key, spec in keys.items():
            if spec.kind == "number" and PLAUSIBLE_RANGES[key].english_low is not None:
                low, high, _ = PLAUSIBLE_RANGES[key].bounds(units)
                properties = tables.setdefault(table, {"properties": {}})["properties"]
                properties[key] = {"minimum": low, "maximum": high}
    return {
        "if": {
            "properties": {"aircraft": {"properties": {"units": {"const": units}}}},
            "required": ["aircraft"],
        },
        "then": {"properties": tables},
    }


def json_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of an aircraft file, generated from the reader's own
    definitions.

    Every key the reader accepts, its type, its description with its unit and sign
    convention, which keys are required (and the pairs of which exactly one is given), and
    the bounds of :data:`~aerocontrol.aircraft.PLAUSIBLE_RANGES`: unitless bounds on
    the key, and the bounds of a dimensional number (a speed, a weight, an inertia) under
    ``allOf`` in one ``if``/``then`` per unit system of ``[aircraft] units``, the units named
    in ``x-units``. Checks that need arithmetic (the density within 0.5 to 2 times the
    standard atmosphere's, Ix Iz > Ixz²) are the reader's alone: ``aerocontrol check``.

    Returns
    -------
    dict
        The schema, ready for :func:`json.dumps`; a new dict on every call.

    Raises
    ------
    None

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> schema = aircraft.json_schema()
    >>> schema["$schema"]
    'https://json-schema.org/draft/2020-12/schema'
    >>> speed = schema["properties"]["flight"]["properties"]["speed"]
    >>> speed["x-units"]
    {'si': 'm/s', 'english': 'ft/s'}
    """
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "urn:aerocontrol:aircraft-file",
        "title": "aerocontrol aircraft file",
        "description": "One aircraft at one flight condition (a TOML file read by "
        "aerocontrol.aircraft.load): nondimensional derivatives per radian in stability axes, "
        "dimensional numbers in the units of [aircraft] units ("
        + "; ".join(
            f"{system}: " + ", ".join(f"{kind} {unit}" for kind, unit in names.items())
            for system, names in UNIT_NAMES.items()
        )
        + ").",
        "type": "object",
        "properties": {
            **{table: _table_schema(table, keys) for table, keys in FILE_KEYS.items()},
            "published": _published_schema(),
            "sources": {
                "type": "object",
                "description": TABLES["sources"],
                "properties": {
                    "default": {
                        "type": "string",
                        "maxLength": _SOURCE_LIMIT,
                        "description": "the citation of every number not cited by its table",
                    }
                },
                "required": ["default"],
                "additionalProperties": {"type": "string", "maxLength": _SOURCE_LIMIT},
            },
            "uncertainty": _uncertainty_schema(),
        },
        "required": list(REQUIRED_TABLES),
        "additionalProperties": False,
        "allOf": [_bounds(units) for units in UNIT_NAMES],
        "$defs": {"scatter": _scatter_schema()},
    }


SCHEMA_FILE = "aircraft.schema.json"
"""The name of the schema shipped beside this module, for editors."""


def shipped_json_schema() -> dict[str, Any]:
    """The JSON Schema shipped in the package (``aerocontrol/aircraft/aircraft.schema.json``),
    read from the file: :func:`json_schema` at the time of the release.

    Returns
    -------
    dict
        The schema as the file holds it.

    Raises
    ------
    OSError
        If the file is missing from the installation.

    Examples
    --------
    >>> from aerocontrol.aircraft.keys import json_schema, shipped_json_schema
    >>> shipped_json_schema() == json_schema()
    True
    """
    text = resources.files(__package__).joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    loaded: dict[str, Any] = json.loads(text)
    return loaded


def schema_text() -> str:
    """:func:`json_schema` as the text of the shipped file (indented, non-ASCII kept, one
    newline at the end): what ``aerocontrol schema`` prints.

    Returns
    -------
    str
        The JSON text.

    Raises
    ------
    None

    Examples
    --------
    >>> import json
    >>> json.loads(schema_text()) == json_schema()
    True
    """
    return json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"
