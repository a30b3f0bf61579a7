"""The tables of an aircraft file, read key by key into the quantities of an
:class:`~aerocontrol.aircraft.Aircraft` (:func:`aircraft_fields`), or into the list of
everything wrong with them (:func:`table_problems`).

Every table and key must be known and every required one present (the keys are
:data:`~aerocontrol.aircraft.keys.FILE_KEYS`); every number is finite and within its
plausible range (:data:`~aerocontrol.aircraft.schema.PLAUSIBLE_RANGES`, in the file's units);
every text is short and free of control characters (so that it prints on one line). Every
failure is an :class:`~aerocontrol.aircraft.schema.AircraftDataError` (a ``ValueError``)
whose one-line message names the file, the table and the key, and which carries the dotted
key, its line in the file and a hint. The reader goes on past a problem, so that one pass
finds them all: :func:`aircraft_fields` raises the first (the one a reader that stops at the
first problem would raise), :func:`table_problems` returns every one, one per key.

Inertias given in body axes are rotated into the stability axes by the trim angle of attack α0
of the body x axis (positive nose up): Ix' = Ix cos²α0 + Iz sin²α0 - Ixz sin 2α0,
Iz' = Ix sin²α0 + Iz cos²α0 + Ixz sin 2α0, Ixz' = (Ix - Iz)/2 sin 2α0 + Ixz cos 2α0.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..exceptions import InvalidArgumentError
from .atmosphere import standard_atmosphere
from .keys import (
    _DESCRIPTION_LIMIT,
    _NAME_LIMIT,
    _SOURCE_LIMIT,
    FILE_KEYS,
    LATERAL_DERIVATIVES,
    LONGITUDINAL_DERIVATIVES,
    PUBLISHED_MODES,
    TABLES,
    UNCERTAIN_FIELDS,
    UNCERTAINTY_SPREADS,
)
from .reader import key_lines
from .schema import PLAUSIBLE_RANGES, UNIT_NAMES, AircraftDataError, check_range, shown

__all__ = [
    "LATERAL_DERIVATIVES",
    "LONGITUDINAL_DERIVATIVES",
    "UNCERTAINTY_SPREADS",
    "UNCERTAIN_FIELDS",
    "aircraft_fields",
    "body_to_stability",
    "table_problems",
]

_GRAVITY = {"english": 32.174, "si": 9.80665}
_NAN = math.nan


def aircraft_fields(
    data: Mapping[str, Any], origin: str = "<dict>", text: str = ""
) -> dict[str, Any]:
    """The keyword arguments of :class:`~aerocontrol.aircraft.Aircraft` from the tables of an
    aircraft file, every key checked (:meth:`Aircraft.from_dict
    <aerocontrol.aircraft.Aircraft.from_dict>` builds the aircraft from them).

    Parameters
    ----------
    data : mapping
        The tables of the file, as :func:`~aerocontrol.aircraft.reader.parse_toml` reads them.
    origin : str
        The name of the file in errors.
    text : str
        The text of the file, for the line of the error (without it, the line is None).

    Returns
    -------
    dict
        The fields of an Aircraft.

    Raises
    ------
    AircraftDataError
        The first problem of the tables (:func:`table_problems` lists them all).

    Examples
    --------
    >>> from aerocontrol.aircraft.reader import parse_toml, read_source
    >>> fields = aircraft_fields(parse_toml(*read_source("navion")), "navion.toml")
    >>> fields["name"], fields["S"]
    ('Navion, level flight', 184.0)
    """
    reader = _Reader(data, origin, key_lines(text) if text else {})
    fields = reader.read()
    if reader.first is not None:
        raise reader.first
    return fields


def table_problems(
    data: Mapping[str, Any], origin: str = "<dict>", text: str = ""
) -> list[AircraftDataError]:
    """Every problem of the tables of an aircraft file, one per key, in the order of the file.

    Each is an :class:`~aerocontrol.aircraft.schema.AircraftDataError` with its dotted
    ``key``, its ``line`` in ``text`` (for a missing key, the line of its table; None for a
    missing table) and a ``hint``: an unknown key, with the known key it most resembles
    (:func:`difflib.get_close_matches`); a missing key or table; a value of the wrong type,
    sign or range (:data:`~aerocontrol.aircraft.schema.PLAUSIBLE_RANGES`, in the file's
    units); numbers inconsistent with each other or with the units. A problem that follows
    from another (the range of a speed whose units are not known) is not reported.

    Parameters
    ----------
    data : mapping
        The tables of the file.
    origin : str
        The name of the file in messages.
    text : str
        The text of the file, for the lines (without it, every line is None).

    Returns
    -------
    list of AircraftDataError
        Empty if the tables are valid.

    Raises
    ------
    AircraftDataError
        If ``data`` is not a mapping.

    Examples
    --------
    >>> from aerocontrol.aircraft.reader import parse_toml, read_source
    >>> text, origin = read_source("navion")
    >>> table_problems(parse_toml(text, origin), origin, text)
    []
    >>> text = text.replace("Cm_q = -9.96", "Cm_qq = -9.96").replace("S = 184.0", "S = -1")
    >>> found = table_problems(parse_toml(text, origin), origin, text)
    >>> for problem in found:
    ...     print(problem.line, problem.key)
    62 geometry.S
    66 longitudinal.Cm_q
    77 longitudinal.Cm_qq
    >>> found[2].hint
    'did you mean Cm_q?'
    """
    reader = _Reader(data, origin, key_lines(text) if text else {})
    reader.read()
    return sorted(reader.problems, key=lambda error: (error.line is None, error.line or 0))


def body_to_stability(
    Ix: float, Iz: float, Ixz: float, alpha0: float
) -> tuple[float, float, float]:
    """(Ix, Iz, Ixz) rotated from body axes into stability axes, α0 the angle of attack of the
    body x axis (rad, positive nose up).

    Ix' = Ix cos²α0 + Iz sin²α0 - Ixz sin 2α0, Iz' = Ix sin²α0 + Iz cos²α0 + Ixz sin 2α0,
    Ixz' = (Ix - Iz)/2 sin 2α0 + Ixz cos 2α0 (the rotation of the inertia tensor about y).

    Parameters
    ----------
    Ix, Iz, Ixz : float
        The moments and product of inertia in body axes (any consistent unit).
    alpha0 : float
        The trim angle of attack of the body x axis, rad.

    Returns
    -------
    tuple of float
        (Ix, Iz, Ixz) in stability axes; Iy is the same in both.

    Raises
    ------
    None
        The arguments are taken as floats (the reader checks them first).

    Examples
    --------
    >>> import math
    >>> from aerocontrol.aircraft import body_to_stability
    >>> [round(v, 1) for v in body_to_stability(1000.0, 2000.0, 0.0, math.radians(10.0))]
    [1030.2, 1969.8, -171.0]"""
    c2, s2 = math.cos(alpha0) ** 2, math.sin(alpha0) ** 2
    sin2, cos2 = math.sin(2 * alpha0), math.cos(2 * alpha0)
    return (
        Ix * c2 + Iz * s2 - Ixz * sin2,
        Ix * s2 + Iz * c2 + Ixz * sin2,
        0.5 * (Ix - Iz) * sin2 + Ixz * cos2,
    )


_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u200e\u200f\u2028-\u202e\u2066-\u2069]")
_NUMBER = re.compile(r"[+-]?[0-9][0-9_]{0,30}(\.[0-9_]{0,30})?([eE][+-]?[0-9]{1,3})?")
_PLAIN_KEY = re.compile(r"[A-Za-z0-9_\-]{1,40}")


def _keys(keys: list[str]) -> str:
    """Keys read from a file, for a message: plain ones as they are, others quoted and
    shortened, at most five of them."""
    named = [key if _PLAIN_KEY.fullmatch(key) else shown(key) for key in keys[:5]]
    more = f" and {len(keys) - 5} more" if len(keys) > 5 else ""
    return ", ".join(named) + more


def _similar(key: Any, known: tuple[str, ...]) -> str:
    """The known key most like ``key`` (a typo's correction), or ""."""
    if not isinstance(key, str):
        return ""
    close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    if not close:  # a difference of case only, such as cm_q for Cm_q
        close = [name for name in known if name.lower() == key.lower()]
    return close[0] if close else ""


def _finite(*values: float) -> bool:
    return all(math.isfinite(value) for value in values)


class _Reader:
    """Typed access to the tables of an aircraft file that records every problem as an
    AircraftDataError with its key, line and hint and goes on (a number found bad reads as
    NaN, so that what depends on it is skipped).

    ``first`` is the problem a reader that stops at the first would raise (its message as
    such a reader words it: one message for all the unknown keys of a table); ``problems``
    has one entry per key. Every number is checked against its plausible range
    (:data:`~aerocontrol.aircraft.schema.PLAUSIBLE_RANGES`) in the file's units, which
    :meth:`read` sets in ``units`` once it has read them (None until then or if they are bad:
    dimensional numbers are then checked for type and sign only).
    """

    def __init__(self, data: Mapping[str, Any], origin: str, lines: Mapping[str, int]) -> None:
        if not isinstance(data, Mapping):
            raise AircraftDataError(f"{origin}: an aircraft must be a table of tables")
        self.data, self.origin, self.lines = data, origin, lines
        self.units: str | None = None
        self.first: AircraftDataError | None = None
        self.problems: list[AircraftDataError] = []
        self.missing: set[str] = set()

    # -- recording ------------------------------------------------------------------------

    def line(self, key: str) -> int | None:
        """The line of ``key`` or, if it is not in the file, of the nearest enclosing table."""
        while key:
            if key in self.lines:
                return self.lines[key]
            key = key.rpartition(".")[0]
        return None

    def problem(
        self, message: str, key: str, hint: str = "", parts: list[AircraftDataError] | None = None
    ) -> None:
        """Record the problem ``message`` (the origin is prefixed) of ``key``; ``parts``, if
        given, are its entries one per key in place of the problem itself."""
        error = AircraftDataError(f"{self.origin}: {message}", key, self.line(key), hint)
        if self.first is None:
            self.first = error
        self.problems.extend(parts if parts is not None else [error])

    def part(self, message: str, key: str, hint: str) -> AircraftDataError:
        return AircraftDataError(f"{self.origin}: {message}", key, self.line(key), hint)

    # -- the file -------------------------------------------------------------------------

    def read(self) -> dict[str, Any]:
        """Every table, in the order of the checks of a reader that stops at the first
        problem; the fields of an Aircraft (with NaN for bad numbers)."""
        info = self.table("aircraft")
        units = self.choice(info, "aircraft", "units")
        self.units = units or None
        aircraft_class = self.choice(info, "aircraft", "class")
        if aircraft_class == "II":
            aircraft_class = "II-L"
        category = self.choice(info, "aircraft", "category")
        self.only(info, "aircraft")
        name = self.text(info, "aircraft", "name", _NAME_LIMIT)
        description = self.text(info, "aircraft", "description", _DESCRIPTION_LIMIT, "")

        flight = self.table("flight")
        self.only(flight, "flight")
        altitude = self.number(flight, "flight", "altitude")
        atmosphere = self.atmosphere(altitude)
        sound = atmosphere.speed_of_sound if atmosphere is not None else _NAN
        given = self.one_of(flight, "flight", ("speed", "mach"))
        speed = mach = _NAN
        if given == "speed":
            speed = self.positive(flight, "flight", "speed")
            mach = speed / sound
        elif given == "mach":
            mach = self.positive(flight, "flight", "mach")
            speed = mach * sound
        density = atmosphere.density if atmosphere is not None else _NAN
        if "density" in flight:
            density = self.density(flight, altitude, density)
        theta0 = math.radians(self.number(flight, "flight", "theta0_deg", default=0.0))
        gravity = _GRAVITY.get(units, _NAN)

        mass_table = self.table("mass")
        self.only(mass_table, "mass")
        given = self.one_of(mass_table, "mass", ("weight", "mass"))
        mass = _NAN
        if given == "weight":
            mass = self.positive(mass_table, "mass", "weight") / gravity
        elif given == "mass":
            mass = self.positive(mass_table, "mass", "mass")
        Ix, Iy, Iz = (self.positive(mass_table, "mass", key) for key in ("Ix", "Iy", "Iz"))
        Ixz = self.number(mass_table, "mass", "Ixz")
        axes = self.choice(mass_table, "mass", "axes")
        if axes == "body":
            if "alpha0_deg" not in flight:
                self.problem(
                    "[mass] axes = 'body' needs [flight] alpha0_deg, the trim angle of attack "
                    "of the body x axis, to rotate the inertias into stability axes",
                    "mass.axes",
                    "add alpha0_deg = ... (degrees, positive nose up) to [flight], or give "
                    'the inertias in stability axes with axes = "stability"',
                )
                Ix = Iz = Ixz = _NAN
            else:
                alpha0 = self.number(flight, "flight", "alpha0_deg")
                Ix, Iz, Ixz = body_to_stability(Ix, Iz, Ixz, math.radians(alpha0))
        elif "alpha0_deg" in flight:  # not used, but a number of the file all the same
            self.number(flight, "flight", "alpha0_deg")
        if _finite(Ix, Iz, Ixz) and Ix * Iz <= Ixz**2:
            self.problem(
                f"[mass] the inertia tensor must be positive definite, but "
                f"Ix Iz = {Ix * Iz:.4g} <= Ixz^2 = {Ixz**2:.4g}",
                "mass.Ixz",
                "check the sign and the magnitude of Ixz against Ix and Iz, and their axes",
            )

        geometry = self.table("geometry")
        self.only(geometry, "geometry")
        S, cbar, b = (self.positive(geometry, "geometry", key) for key in ("S", "cbar", "b"))

        derivatives: dict[str, float] = {}
        for table_name, keys in (
            ("longitudinal", LONGITUDINAL_DERIVATIVES),
            ("lateral", LATERAL_DERIVATIVES),
        ):
            table = self.table(table_name)
            self.only(table, table_name)
            derivatives.update({key: self.number(table, table_name, key) for key in keys})

        published = self.published()
        sources: dict[str, str] = {}
        if "sources" in self.data:
            table = self.table("sources", required=("default",))
            sources = {
                str(key): self.text(table, "sources", str(key), _SOURCE_LIMIT) for key in table
            }
        uncertainty = self.uncertainty(tuple(derivatives)) if "uncertainty" in self.data else {}
        self.only_tables()
        return dict(
            name=name,
            identifier=Path(self.origin).stem,
            description=description,
            aircraft_class=aircraft_class,
            category=category,
            units=units,
            speed=speed,
            altitude=altitude,
            density=density,
            mach=mach,
            theta0=theta0,
            mass=mass,
            gravity=gravity,
            Ix=Ix,
            Iy=Iy,
            Iz=Iz,
            Ixz=Ixz,
            S=S,
            cbar=cbar,
            b=b,
            derivatives=derivatives,
            published=published,
            sources=sources,
            uncertainty=uncertainty,
        )

    # -- tables and keys ------------------------------------------------------------------

    def table(self, name: str, required: tuple[str, ...] | None = None) -> Mapping[str, Any]:
        """The table ``name`` (empty if it is missing) and a problem for each missing
        required key (by default, the keys :data:`FILE_KEYS` requires)."""
        if required is None:
            keys = FILE_KEYS.get(name, {})
            required = tuple(key for key, spec in keys.items() if spec.required is True)
        table = self.data.get(name)
        if not isinstance(table, Mapping):
            self.missing.add(name)
            unknown = [key for key in self.data if key not in TABLES]
            like = [key for key in unknown if _similar(key, (name,))]
            hint = f"add the table [{name}] ({TABLES[name]})"
            if like:
                hint = f"is [{like[0]}] meant to be [{name}]? " + hint
            self.problem(f"the table [{name}] is missing", name, hint)
            return {}
        missing = [key for key in required if key not in table]
        if missing:
            note = ""
            if name in ("longitudinal", "lateral"):
                note = " (write 0.0 for a derivative the source does not give)"
            parts = []
            known = FILE_KEYS.get(name, {})
            for key in missing:
                spec = known.get(key)
                what = f": {spec.description}" if spec is not None else ""
                hint = f"add {key} = ... to [{name}]{what}{note}"
                typo = _similar(key, tuple(str(k) for k in table if k not in known))
                if typo:
                    hint = f"is {typo} meant to be {key}? else {hint}"
                parts.append(self.part(f"[{name}] is missing {key}", f"{name}.{key}", hint))
            self.problem(
                f"[{name}] is missing {', '.join(missing)}{note}", f"{name}.{missing[0]}", "", parts
            )
        return table

    def only(self, table: Mapping[str, Any], name: str, allowed: tuple[str, ...] = ()) -> None:
        """A problem for the keys of ``table`` other than ``allowed`` (by default, the keys of
        :data:`FILE_KEYS`), one per key, each with the known key it most resembles."""
        allowed = allowed or tuple(FILE_KEYS[name])
        unknown = [key for key in table if key not in allowed]
        if not unknown:
            return
        parts = []
        for key in unknown:
            similar = _similar(key, allowed)
            hint = f"did you mean {similar}?" if similar else f"the keys are {', '.join(allowed)}"
            where = f"{name}.{key}" if isinstance(key, str) else name
            parts.append(self.part(f"[{name}] has unknown key {_keys([key])}", where, hint))
        self.problem(
            f"[{name}] has unknown key(s) {_keys(unknown)}; the keys are {', '.join(allowed)}",
            parts[0].key or name,
            parts[0].hint,
            parts,
        )

    def only_tables(self) -> None:
        allowed = tuple(TABLES)
        unknown = [key for key in self.data if key not in allowed]
        if not unknown:
            return
        parts = []
        for key in unknown:
            similar = _similar(key, allowed)
            hint = (
                f"did you mean [{similar}]?" if similar else f"the tables are {', '.join(allowed)}"
            )
            parts.append(self.part(f"unknown table {_keys([key])}", str(key), hint))
        self.problem(
            f"unknown table(s) {_keys(unknown)}; the tables are {', '.join(allowed)}",
            str(unknown[0]),
            parts[0].hint,
            parts,
        )

    def one_of(self, table: Mapping[str, Any], name: str, pair: tuple[str, str]) -> str:
        """Which of the two keys ``pair`` the table gives, or "" (a problem unless the table
        itself is missing) if it gives neither or both."""
        given = [key for key in pair if key in table]
        if len(given) == 1:
            return given[0]
        if name not in self.missing:
            first, second = pair
            hint = (
                f"remove one of {first} and {second}"
                if given
                else f"add {first} = ... or {second} = ..."
            )
            key = f"{name}.{given[1]}" if given else name
            self.problem(f"[{name}] must give exactly one of {first} and {second}", key, hint)
        return ""

    def number(
        self,
        table: Mapping[str, Any],
        name: str,
        key: str,
        default: float | None = None,
        positive: bool = False,
        bounded: bool = True,
    ) -> float:
        """The number ``table[key]``, a finite real within the key's plausible range (only
        finite, and positive if asked, with ``bounded=False`` or units not known); NaN if it
        is missing (reported by :meth:`table`) or bad (reported here)."""
        if key not in table:
            return default if default is not None else _NAN
        dimensional = PLAUSIBLE_RANGES[key].english_low is not None
        if self.units is None and dimensional:
            bounded = False
        where = f"{self.origin}: [{name}] "
        value = table[key]
        try:
            return check_range(value, key, self.units or "si", where, positive, bounded)
        except AircraftDataError as error:
            if self.first is None:
                self.first = error
            hint = self.number_hint(value, key, positive)
            self.problems.append(
                AircraftDataError(str(error), f"{name}.{key}", self.line(f"{name}.{key}"), hint)
            )
            return _NAN

    def number_hint(self, value: Any, key: str, positive: bool) -> str:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            example = "0.5"
            if isinstance(value, str) and _NUMBER.fullmatch(value.strip()):
                example = value.strip()
            return f"write a number without quotes, such as {key} = {example}"
        if isinstance(value, float) and not math.isfinite(value):
            return "write a finite number"
        if positive and value <= 0:
            return f"{key} is a magnitude: give it as a positive number"
        if PLAUSIBLE_RANGES[key].english_low is not None and self.units is not None:
            names = ", ".join(UNIT_NAMES[self.units].values())
            return (
                f"the file's units are {self.units!r} ({names}): is the value in the other "
                "unit system, or mistyped?"
            )
        if PLAUSIBLE_RANGES[key].si_unit == "per rad":
            return "derivatives are per radian: is the value mistyped?"
        return "is the value mistyped?"

    def positive(self, table: Mapping[str, Any], name: str, key: str) -> float:
        return self.number(table, name, key, positive=True)

    def density(self, flight: Mapping[str, Any], altitude: float, standard: float) -> float:
        """[flight] density: positive, within 0.5 to 2 times the standard atmosphere's at
        the altitude (if known), then within its plausible range."""
        density = self.number(flight, "flight", "density", positive=True, bounded=False)
        if not _finite(density, standard) or self.units is None:
            return density
        if not 0.5 <= density / standard <= 2.0:
            names = UNIT_NAMES[self.units]
            other = "si" if self.units == "english" else "english"
            self.problem(
                f"[flight] density = {density:g} {names['density']} is not plausible "
                f"at {altitude:g} {names['length']} (the standard atmosphere gives "
                f"{standard:.5g} {names['density']}): are the units {self.units!r}?",
                "flight.density",
                f"give the density in {names['density']} (not {UNIT_NAMES[other]['density']}) "
                "or leave it out to use the standard atmosphere's",
            )
            return _NAN
        return self.number(flight, "flight", "density")

    def text(
        self, table: Mapping[str, Any], name: str, key: str, limit: int, default: str | None = None
    ) -> str:
        """The string ``table[key]``: at most ``limit`` characters, none of them a control
        character (so that it prints on one line); "" if missing or bad."""
        if key not in table:
            return default if default is not None else ""
        value = table[key]
        where = f"{name}.{key}"
        if not isinstance(value, str):
            self.problem(
                f"[{name}] {key} must be a string, got {shown(value)}",
                where,
                f'put the text in quotes: {key} = "..."',
            )
            return ""
        if len(value) > limit:
            self.problem(
                f"[{name}] {key} has {len(value):,} characters, more than the {limit:,} allowed",
                where,
                "shorten it; a long citation can be split over the tables of [sources]",
            )
            return ""
        control = _CONTROL.search(value)
        if control:
            self.problem(
                f"[{name}] {key} contains the control character {control.group()!r} at "
                f"position {control.start()}",
                where,
                "keep it on one line, without tabs or control characters",
            )
            return ""
        return value

    def choice(
        self,
        table: Mapping[str, Any],
        name: str,
        key: str,
        choices: tuple[str, ...] | None = None,
    ) -> str:
        """The string ``table[key]`` if it is one of ``choices`` (by default, those of
        :data:`FILE_KEYS`); "" if missing (reported by :meth:`table`) or not one of them."""
        if choices is None:
            choices = FILE_KEYS[name][key].choices
        if key not in table and name in FILE_KEYS:
            return ""
        value = table.get(key)
        if not isinstance(value, str) or value not in choices:
            listed = ", ".join(repr(c) for c in choices)
            similar = _similar(value, choices)
            hint = f"did you mean {similar!r}?" if similar else f"write one of {listed}"
            self.problem(
                f"[{name}] {key} must be one of {listed}, got {shown(value)}",
                f"{name}.{key}",
                hint,
            )
            return ""
        return str(value)

    def atmosphere(self, altitude: float) -> Any:
        """The standard atmosphere at ``altitude`` in the file's units, or None if either is
        not known."""
        if self.units is None or not math.isfinite(altitude):
            return None
        try:
            return standard_atmosphere(altitude, self.units)
        except InvalidArgumentError as error:
            self.problem(f"[flight] {error}", "flight.altitude", "is the altitude mistyped?")
            return None

    def uncertainty(self, derivatives: tuple[str, ...]) -> dict[str, Any]:
        """The [uncertainty] table: per uncertain parameter (a derivative, or one of
        :data:`UNCERTAIN_FIELDS`) an inline table ``{distribution = "normal", sigma = 0.2}``
        ("uniform": ``half_width``; ``relative = false`` for a spread in the parameter's
        units), and an optional ``correlations = [["Cn_beta", "Cn_r", 0.5], ...]``. Returns
        ``{"parameters": {name: {"distribution", "spread", "relative"}}, "correlations":
        [(a, b, rho), ...]}``."""
        table = self.table("uncertainty", required=())
        where = "[uncertainty]"
        allowed = (*derivatives, *UNCERTAIN_FIELDS)
        parameters: dict[str, dict[str, Any]] = {}
        for key, entry in table.items():
            if key == "correlations":
                continue
            at = f"uncertainty.{key}"
            if key not in allowed:
                similar = _similar(key, allowed)
                self.problem(
                    f"{where} {_keys([str(key)])} is neither a derivative nor one of "
                    f"{', '.join(UNCERTAIN_FIELDS)}",
                    at,
                    f"did you mean {similar}?" if similar else "name a derivative",
                )
                continue
            if not isinstance(entry, Mapping):
                self.problem(
                    f'{where} {key} must be an inline table such as {{distribution = "normal", '
                    f"sigma = 0.1}}, got {shown(entry)}",
                    at,
                    f'write {key} = {{ distribution = "normal", sigma = 0.1 }}',
                )
                continue
            distribution = self.choice(entry, at, "distribution", tuple(UNCERTAINTY_SPREADS))
            if not distribution:
                continue
            spread_key = UNCERTAINTY_SPREADS[distribution]
            before = len(self.problems)
            self.only(entry, at, ("distribution", spread_key, "relative"))
            spread = entry.get(spread_key)
            if (
                isinstance(spread, bool)
                or not isinstance(spread, (int, float))
                or not (math.isfinite(spread) and spread >= 0)
            ):
                self.problem(
                    f"{where} {key}: {spread_key} must be a finite number >= 0, got "
                    f"{shown(spread)}",
                    f"{at}.{spread_key}",
                    f"a {distribution} scatter is given by {spread_key} = ... (>= 0)",
                )
            relative = entry.get("relative", True)
            if not isinstance(relative, bool):
                self.problem(
                    f"{where} {key}: relative must be true or false, got {shown(relative)}",
                    f"{at}.relative",
                    "write relative = true or relative = false, without quotes",
                )
            elif distribution == "lognormal" and not relative:
                self.problem(
                    f"{where} {key}: a lognormal scatter is relative",
                    f"{at}.relative",
                    "remove relative = false, or choose a normal or uniform distribution",
                )
            if len(self.problems) == before and isinstance(spread, (int, float)):
                parameters[str(key)] = {
                    "distribution": distribution,
                    "spread": float(spread),
                    "relative": relative,
                }
        correlations: list[tuple[str, str, float]] = []
        listed = table.get("correlations", [])
        at = "uncertainty.correlations"
        if not isinstance(listed, list):
            self.problem(
                f'{where} correlations must be a list of ["A", "B", rho] entries, got '
                f"{shown(listed)}",
                at,
                'write correlations = [["Cn_beta", "Cn_r", 0.5]]',
            )
            listed = []
        pairs: set[frozenset[str]] = set()
        for item in listed:
            if not (
                isinstance(item, list)
                and len(item) == 3
                and all(isinstance(name, str) for name in item[:2])
                and item[0] in parameters
                and item[1] in parameters
                and item[0] != item[1]
                and isinstance(item[2], (int, float))
                and not isinstance(item[2], bool)
                and -1.0 < item[2] < 1.0
            ):
                self.problem(
                    f'{where} correlations: each entry is ["A", "B", rho], A and B two of the '
                    f"uncertain parameters and -1 < rho < 1; got {shown(item)}",
                    at,
                    "name two parameters this table scatters, and a coefficient between -1 and 1",
                )
                continue
            if frozenset(item[:2]) in pairs:  # given twice, in either order: which one holds?
                self.problem(
                    f"{where} correlations: the pair {item[0]}, {item[1]} is given twice",
                    at,
                    "keep one of the two entries",
                )
                continue
            pairs.add(frozenset(item[:2]))
            correlations.append((item[0], item[1], float(item[2])))
        return {"parameters": parameters, "correlations": correlations}

    def published(self) -> dict[str, Any]:
        """[published]: an optional relative ``tolerance`` and, per mode, its quantities and an
        optional ``tolerance`` of its own; every value a positive finite number (zeta may be
        negative, an unstable oscillation, but not zero)."""
        table = self.data.get("published", {})
        if not isinstance(table, Mapping):
            self.problem(
                f"[published] must be a table, got {shown(table)}",
                "published",
                "write [published] as a table header, with one mode per line under it",
            )
            return {}
        published: dict[str, Any] = {}
        modes = tuple(PUBLISHED_MODES)
        for mode, entry in table.items():
            if mode == "tolerance":
                published[mode] = self.positive(table, "published", mode)
                continue
            name = f"published.{mode}"
            if mode not in PUBLISHED_MODES:
                similar = _similar(mode, modes)
                self.problem(
                    f"[published] has unknown mode {shown(mode)}; the modes are "
                    f"{', '.join(modes)} (and the file-level tolerance)",
                    name if isinstance(mode, str) else "published",
                    f"did you mean {similar}?" if similar else f"the modes are {', '.join(modes)}",
                )
                continue
            quantities = PUBLISHED_MODES[mode]
            if not isinstance(entry, Mapping):
                self.problem(
                    f"[{name}] must be a table of quantities such as "
                    f"{{ {quantities[0]} = ... }}, got {shown(entry)}",
                    name,
                    f"write {mode} = {{ {quantities[0]} = ... }}",
                )
                continue
            allowed = (*quantities, "tolerance")
            unknown = [key for key in entry if key not in allowed]
            if unknown:
                parts = []
                for key in unknown:
                    similar = _similar(key, allowed)
                    hint = (
                        f"did you mean {similar}?"
                        if similar
                        else f"the quantities of the {mode} are {', '.join(allowed)}"
                    )
                    parts.append(
                        self.part(f"[{name}] has unknown quantity {_keys([key])}", name, hint)
                    )
                self.problem(
                    f"[{name}] has unknown quantity {_keys(unknown)}; "
                    f"the quantities of the {mode} are {', '.join(allowed)}",
                    name,
                    parts[0].hint,
                    parts,
                )
                continue
            if not any(key != "tolerance" for key in entry):
                self.problem(
                    f"[{name}] gives no quantity; give one of {', '.join(quantities)}",
                    name,
                    f"add {quantities[0]} = ... to the {mode}",
                )
                continue
            values: dict[str, float] = {}
            for key in entry:
                if key == "zeta":
                    values[key] = self.number(entry, name, key)
                    if values[key] == 0.0:
                        self.problem(
                            f"[{name}] zeta must not be zero (a relative tolerance cannot "
                            "check it)",
                            f"{name}.zeta",
                            "leave zeta out, or give the source's nonzero value",
                        )
                else:
                    values[key] = self.positive(entry, name, key)
            published[mode] = values
        return published
