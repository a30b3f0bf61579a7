"""The tables of an aircraft file, read key by key into the quantities of an
:class:`~aerocontrol.aircraft.Aircraft` (:func:`aircraft_fields`).

Every table and key must be known and every required one present; every number is finite and
within its plausible range (:data:`~aerocontrol.aircraft.schema.PLAUSIBLE_RANGES`, in the
file's units); every text is short and free of control characters (so that it prints on one
line). Every failure is an :class:`~aerocontrol.aircraft.schema.AircraftDataError` (a
``ValueError``) whose one-line message names the file, the table and the key.

Inertias given in body axes are rotated into the stability axes by the trim angle of attack α0
of the body x axis (positive nose up): Ix' = Ix cos²α0 + Iz sin²α0 - Ixz sin 2α0,
Iz' = Ix sin²α0 + Iz cos²α0 + Ixz sin 2α0, Ixz' = (Ix - Iz)/2 sin 2α0 + Ixz cos 2α0.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..exceptions import InvalidArgumentError
from .atmosphere import standard_atmosphere
from .schema import UNIT_NAMES, AircraftDataError, check_range, shown

__all__ = [
    "LATERAL_DERIVATIVES",
    "LONGITUDINAL_DERIVATIVES",
    "aircraft_fields",
    "body_to_stability",
]

LONGITUDINAL_DERIVATIVES = (
    "CL",
    "CD",
    "CL_alpha",
    "CL_alphadot",
    "CL_q",
    "CL_M",
    "CD_alpha",
    "CD_M",
    "Cm_alpha",
    "Cm_alphadot",
    "Cm_q",
    "Cm_M",
    "CL_de",
    "CD_de",
    "Cm_de",
)
"""The longitudinal coefficients and derivatives (per radian) an aircraft file must give."""

LATERAL_DERIVATIVES = (
    "Cy_beta",
    "Cy_p",
    "Cy_r",
    "Cl_beta",
    "Cl_p",
    "Cl_r",
    "Cn_beta",
    "Cn_p",
    "Cn_r",
    "Cy_dr",
    "Cl_dr",
    "Cn_dr",
    "Cy_da",
    "Cl_da",
    "Cn_da",
)
"""The lateral-directional derivatives (per radian) an aircraft file must give."""

_GRAVITY = {"english": 32.174, "si": 9.80665}
_CLASSES = ("I", "II-C", "II-L", "III", "IV")
_CATEGORIES = ("A", "B", "C")
_TABLES = (
    "aircraft",
    "flight",
    "mass",
    "geometry",
    "longitudinal",
    "lateral",
    "published",
    "sources",
    "uncertainty",
)
#: The distributions of an [uncertainty] entry and the key of each one's spread.
UNCERTAINTY_SPREADS = {"normal": "sigma", "uniform": "half_width", "lognormal": "sigma"}
#: What besides the derivatives an [uncertainty] table may scatter (as
#: ``Aircraft.model_stack`` can vary it).
UNCERTAIN_FIELDS = ("mass", "Ix", "Iy", "Iz", "Ixz", "speed", "density")
_FLIGHT_KEYS = ("speed", "mach", "altitude", "density", "theta0_deg", "alpha0_deg")
_OSCILLATORY = ("omega_n", "zeta")
_APERIODIC = ("time_constant", "time_to_half", "time_to_double")
_PUBLISHED_MODES = {
    "short_period": _OSCILLATORY,
    "phugoid": _OSCILLATORY,
    "dutch_roll": _OSCILLATORY,
    "roll": _APERIODIC,
    "spiral": _APERIODIC,
}
"""The modes a file's [published] table may give, each with the quantities it may carry
(omega_n in rad/s, zeta; time_constant, time_to_half and time_to_double in s). Any mode may also
carry its own relative ``tolerance``, which then replaces the file-level ``tolerance``."""


def aircraft_fields(data: Mapping[str, Any], origin: str = "<dict>") -> dict[str, Any]:
    """The keyword arguments of :class:`~aerocontrol.aircraft.Aircraft` from the tables of an
    aircraft file, every key checked (:meth:`Aircraft.from_dict
    <aerocontrol.aircraft.Aircraft.from_dict>` builds the aircraft from them); ``origin`` names
    the file in errors."""
    reader = _Reader(data, origin)
    info = reader.table("aircraft", required=("name", "class", "category", "units"))
    units = reader.choice(info, "aircraft", "units", ("english", "si"))
    reader.units = units
    aircraft_class = reader.choice(info, "aircraft", "class", (*_CLASSES, "II"))
    if aircraft_class == "II":
        aircraft_class = "II-L"
    category = reader.choice(info, "aircraft", "category", _CATEGORIES)
    reader.only(info, "aircraft", ("name", "description", "class", "category", "units"))
    name = reader.text(info, "aircraft", "name", _NAME_LIMIT)
    description = reader.text(info, "aircraft", "description", _DESCRIPTION_LIMIT, "")

    flight = reader.table("flight", required=("altitude",))
    reader.only(flight, "flight", _FLIGHT_KEYS)
    altitude = reader.number(flight, "flight", "altitude")
    atmosphere = reader.atmosphere(altitude, units)
    if ("speed" in flight) == ("mach" in flight):
        raise AircraftDataError(f"{origin}: [flight] must give exactly one of speed and mach")
    if "speed" in flight:
        speed = reader.positive(flight, "flight", "speed")
        mach = speed / atmosphere.speed_of_sound
    else:
        mach = reader.positive(flight, "flight", "mach")
        speed = mach * atmosphere.speed_of_sound
    density = atmosphere.density
    if "density" in flight:
        density = reader.number(flight, "flight", "density", positive=True, bounded=False)
        if not 0.5 <= density / atmosphere.density <= 2.0:
            names = UNIT_NAMES[units]
            raise AircraftDataError(
                f"{origin}: [flight] density = {density:g} {names['density']} is not plausible "
                f"at {altitude:g} {names['length']} (the standard atmosphere gives "
                f"{atmosphere.density:.5g} {names['density']}): are the units {units!r}?"
            )
        reader.number(flight, "flight", "density")
    theta0 = math.radians(reader.number(flight, "flight", "theta0_deg", default=0.0))
    gravity = _GRAVITY[units]

    mass_table = reader.table("mass", required=("Ix", "Iy", "Iz", "Ixz", "axes"))
    reader.only(mass_table, "mass", ("weight", "mass", "Ix", "Iy", "Iz", "Ixz", "axes"))
    if ("weight" in mass_table) == ("mass" in mass_table):
        raise AircraftDataError(f"{origin}: [mass] must give exactly one of weight and mass")
    if "weight" in mass_table:
        mass = reader.positive(mass_table, "mass", "weight") / gravity
    else:
        mass = reader.positive(mass_table, "mass", "mass")
    Ix, Iy, Iz = (reader.positive(mass_table, "mass", key) for key in ("Ix", "Iy", "Iz"))
    Ixz = reader.number(mass_table, "mass", "Ixz")
    axes = reader.choice(mass_table, "mass", "axes", ("stability", "body"))
    if axes == "body":
        if "alpha0_deg" not in flight:
            raise AircraftDataError(
                f"{origin}: [mass] axes = 'body' needs [flight] alpha0_deg, the trim angle "
                "of attack of the body x axis, to rotate the inertias into stability axes"
            )
        Ix, Iz, Ixz = body_to_stability(
            Ix, Iz, Ixz, math.radians(reader.number(flight, "flight", "alpha0_deg"))
        )
    if Ix * Iz <= Ixz**2:
        raise AircraftDataError(
            f"{origin}: [mass] the inertia tensor must be positive definite, but "
            f"Ix Iz = {Ix * Iz:.4g} <= Ixz^2 = {Ixz**2:.4g}"
        )

    geometry = reader.table("geometry", required=("S", "cbar", "b"))
    reader.only(geometry, "geometry", ("S", "cbar", "b"))
    S, cbar, b = (reader.positive(geometry, "geometry", key) for key in ("S", "cbar", "b"))

    derivatives: dict[str, float] = {}
    for table_name, keys in (
        ("longitudinal", LONGITUDINAL_DERIVATIVES),
        ("lateral", LATERAL_DERIVATIVES),
    ):
        table = reader.table(table_name, required=keys)
        reader.only(table, table_name, keys)
        derivatives.update({key: reader.number(table, table_name, key) for key in keys})

    published = reader.published()
    sources: dict[str, str] = {}
    if "sources" in data:
        table = reader.table("sources", required=("default",))
        sources = {
            str(key): reader.text(table, "sources", str(key), _SOURCE_LIMIT) for key in table
        }
    uncertainty = reader.uncertainty(tuple(derivatives)) if "uncertainty" in data else {}
    reader.only_tables(_TABLES)
    return dict(
        name=name,
        identifier=Path(origin).stem,
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


def body_to_stability(
    Ix: float, Iz: float, Ixz: float, alpha0: float
) -> tuple[float, float, float]:
    """(Ix, Iz, Ixz) rotated from body axes into stability axes, α0 the angle of attack of the
    body x axis (rad, positive nose up)."""
    c2, s2 = math.cos(alpha0) ** 2, math.sin(alpha0) ** 2
    sin2, cos2 = math.sin(2 * alpha0), math.cos(2 * alpha0)
    return (
        Ix * c2 + Iz * s2 - Ixz * sin2,
        Ix * s2 + Iz * c2 + Ixz * sin2,
        0.5 * (Ix - Iz) * sin2 + Ixz * cos2,
    )


_NAME_LIMIT = 200
_DESCRIPTION_LIMIT = 2_000
_SOURCE_LIMIT = 20_000
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u200e\u200f\u2028-\u202e\u2066-\u2069]")
_PLAIN_KEY = re.compile(r"[A-Za-z0-9_\-]{1,40}")


def _keys(keys: list[str]) -> str:
    """Keys read from a file, for a message: plain ones as they are, others quoted and
    shortened, at most five of them."""
    named = [key if _PLAIN_KEY.fullmatch(key) else shown(key) for key in keys[:5]]
    more = f" and {len(keys) - 5} more" if len(keys) > 5 else ""
    return ", ".join(named) + more


class _Reader:
    """Typed access to the tables of an aircraft file, raising AircraftDataError by name.

    Every number is checked against its plausible range
    (:data:`~aerocontrol.aircraft.schema.PLAUSIBLE_RANGES`) in the file's units, which
    :func:`aircraft_fields` sets in ``units`` once it has read them.
    """

    def __init__(self, data: Mapping[str, Any], origin: str) -> None:
        if not isinstance(data, Mapping):
            raise AircraftDataError(f"{origin}: an aircraft must be a table of tables")
        self.data, self.origin = data, origin
        self.units = "si"

    def table(self, name: str, required: tuple[str, ...]) -> Mapping[str, Any]:
        table = self.data.get(name)
        if not isinstance(table, Mapping):
            raise AircraftDataError(f"{self.origin}: the table [{name}] is missing")
        missing = [key for key in required if key not in table]
        if missing:
            hint = ""
            if name in ("longitudinal", "lateral"):
                hint = " (write 0.0 for a derivative the source does not give)"
            raise AircraftDataError(
                f"{self.origin}: [{name}] is missing {', '.join(missing)}{hint}"
            )
        return table

    def only(self, table: Mapping[str, Any], name: str, allowed: tuple[str, ...]) -> None:
        unknown = [key for key in table if key not in allowed]
        if unknown:
            raise AircraftDataError(
                f"{self.origin}: [{name}] has unknown key(s) {_keys(unknown)}; "
                f"the keys are {', '.join(allowed)}"
            )

    def only_tables(self, allowed: tuple[str, ...]) -> None:
        unknown = [key for key in self.data if key not in allowed]
        if unknown:
            raise AircraftDataError(
                f"{self.origin}: unknown table(s) {_keys(unknown)}; the tables are "
                f"{', '.join(allowed)}"
            )

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
        finite, and positive if asked, with ``bounded=False``)."""
        if key not in table and default is not None:
            return default
        where = f"{self.origin}: [{name}] "
        return check_range(table[key], key, self.units, where, positive, bounded)

    def positive(self, table: Mapping[str, Any], name: str, key: str) -> float:
        return self.number(table, name, key, positive=True)

    def text(
        self, table: Mapping[str, Any], name: str, key: str, limit: int, default: str | None = None
    ) -> str:
        """The string ``table[key]``: at most ``limit`` characters, none of them a control
        character (so that it prints on one line)."""
        if key not in table and default is not None:
            return default
        value = table[key]
        if not isinstance(value, str):
            raise AircraftDataError(
                f"{self.origin}: [{name}] {key} must be a string, got {shown(value)}"
            )
        if len(value) > limit:
            raise AircraftDataError(
                f"{self.origin}: [{name}] {key} has {len(value):,} characters, more than the "
                f"{limit:,} allowed"
            )
        control = _CONTROL.search(value)
        if control:
            raise AircraftDataError(
                f"{self.origin}: [{name}] {key} contains the control character "
                f"{control.group()!r} at position {control.start()}"
            )
        return value

    def choice(
        self, table: Mapping[str, Any], name: str, key: str, choices: tuple[str, ...]
    ) -> str:
        value = table.get(key)
        if not isinstance(value, str) or value not in choices:
            listed = ", ".join(repr(c) for c in choices)
            raise AircraftDataError(
                f"{self.origin}: [{name}] {key} must be one of {listed}, got {shown(value)}"
            )
        return str(value)

    def uncertainty(self, derivatives: tuple[str, ...]) -> dict[str, Any]:
        """The [uncertainty] table: per uncertain parameter (a derivative, or one of
        :data:`UNCERTAIN_FIELDS`) an inline table ``{distribution = "normal", sigma = 0.2}``
        ("uniform": ``half_width``; ``relative = false`` for a spread in the parameter's
        units), and an optional ``correlations = [["Cn_beta", "Cn_r", 0.5], ...]``. Returns
        ``{"parameters": {name: {"distribution", "spread", "relative"}}, "correlations":
        [(a, b, rho), ...]}``."""
        table = self.table("uncertainty", required=())
        where = f"{self.origin}: [uncertainty]"
        allowed = (*derivatives, *UNCERTAIN_FIELDS)
        parameters: dict[str, dict[str, Any]] = {}
        for key, entry in table.items():
            if key == "correlations":
                continue
            if key not in allowed:
                raise AircraftDataError(
                    f"{where} {_keys([str(key)])} is neither a derivative nor one of "
                    f"{', '.join(UNCERTAIN_FIELDS)}"
                )
            if not isinstance(entry, Mapping):
                raise AircraftDataError(
                    f'{where} {key} must be an inline table such as {{distribution = "normal", '
                    f"sigma = 0.1}}, got {shown(entry)}"
                )
            distribution = self.choice(
                entry, f"uncertainty.{key}", "distribution", tuple(UNCERTAINTY_SPREADS)
            )
            spread_key = UNCERTAINTY_SPREADS[distribution]
            self.only(entry, f"uncertainty.{key}", ("distribution", spread_key, "relative"))
            spread = entry.get(spread_key)
            if (
                isinstance(spread, bool)
                or not isinstance(spread, (int, float))
                or not (math.isfinite(spread) and spread >= 0)
            ):
                raise AircraftDataError(
                    f"{where} {key}: {spread_key} must be a finite number >= 0, got {shown(spread)}"
                )
            relative = entry.get("relative", True)
            if not isinstance(relative, bool):
                raise AircraftDataError(
                    f"{where} {key}: relative must be true or false, got {shown(relative)}"
                )
            if distribution == "lognormal" and not relative:
                raise AircraftDataError(f"{where} {key}: a lognormal scatter is relative")
            parameters[str(key)] = {
                "distribution": distribution,
                "spread": float(spread),
                "relative": relative,
            }
        correlations: list[tuple[str, str, float]] = []
        listed = table.get("correlations", [])
        if not isinstance(listed, list):
            raise AircraftDataError(
                f'{where} correlations must be a list of ["A", "B", rho] entries, got '
                f"{shown(listed)}"
            )
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
                raise AircraftDataError(
                    f'{where} correlations: each entry is ["A", "B", rho], A and B two of the '
                    f"uncertain parameters and -1 < rho < 1; got {shown(item)}"
                )
            if frozenset(item[:2]) in pairs:  # given twice, in either order: which one holds?
                raise AircraftDataError(
                    f"{where} correlations: the pair {item[0]}, {item[1]} is given twice"
                )
            pairs.add(frozenset(item[:2]))
            correlations.append((item[0], item[1], float(item[2])))
        return {"parameters": parameters, "correlations": correlations}

    def published(self) -> dict[str, Any]:
        """[published]: an optional relative ``tolerance`` and, per mode, its quantities and an
        optional ``tolerance`` of its own; every value a positive finite number (zeta may be
        negative, an unstable oscillation, but not zero)."""
        table = self.data.get("published", {})
        if not isinstance(table, Mapping):
            raise AircraftDataError(
                f"{self.origin}: [published] must be a table, got {shown(table)}"
            )
        published: dict[str, Any] = {}
        for mode, entry in table.items():
            if mode == "tolerance":
                published[mode] = self.positive(table, "published", mode)
                continue
            if mode not in _PUBLISHED_MODES:
                raise AircraftDataError(
                    f"{self.origin}: [published] has unknown mode {shown(mode)}; the modes are "
                    f"{', '.join(_PUBLISHED_MODES)} (and the file-level tolerance)"
                )
            name = f"published.{mode}"
            if not isinstance(entry, Mapping):
                raise AircraftDataError(
                    f"{self.origin}: [{name}] must be a table of quantities such as "
                    f"{{ {_PUBLISHED_MODES[mode][0]} = ... }}, got {shown(entry)}"
                )
            allowed = (*_PUBLISHED_MODES[mode], "tolerance")
            unknown = [key for key in entry if key not in allowed]
            if unknown:
                raise AircraftDataError(
                    f"{self.origin}: [{name}] has unknown quantity {_keys(unknown)}; "
                    f"the quantities of the {mode} are {', '.join(allowed)}"
                )
            if not any(key != "tolerance" for key in entry):
                raise AircraftDataError(
                    f"{self.origin}: [{name}] gives no quantity; give one of "
                    f"{', '.join(_PUBLISHED_MODES[mode])}"
                )
            values: dict[str, float] = {}
            for key in entry:
                if key == "zeta":
                    values[key] = self.number(entry, name, key)
                    if values[key] == 0.0:
                        raise AircraftDataError(
                            f"{self.origin}: [{name}] zeta must not be zero (a relative "
                            "tolerance cannot check it)"
                        )
                else:
                    values[key] = self.positive(entry, name, key)
            published[mode] = values
        return published

    def atmosphere(self, altitude: float, units: str) -> Any:
        try:
            return standard_atmosphere(altitude, units)
        except InvalidArgumentError as error:
            raise AircraftDataError(f"{self.origin}: [flight] {error}") from None
