"""The plausible range of every quantity an aircraft file gives, and the error of a malformed
file: :class:`AircraftDataError` (a ``ValueError``), whose one-line message names the file and,
where there is one, the table and the key. Reading the file is
:mod:`~aerocontrol.aircraft.reader`'s.

Every number of a file is checked against :data:`PLAUSIBLE_RANGES`, generous bounds that admit
any real airplane from a model aircraft to the largest transport and the fastest research
aircraft, and refuse what no airplane has (a negative mass, a weight of 1e300 lbf, a
``Cm_q`` of -1e300): the message names the key, the value and the range, in the file's units.

==========================  ======================  ============================  =============
key                         SI (``units = "si"``)   English (``"english"``)       note
==========================  ======================  ============================  =============
flight.speed                0.5 to 3,500 m/s        1.5 to 11,500 ft/s            u0
flight.mach                 0.001 to 12
flight.altitude             -5,000 to 86,000 m      -16,400 to 282,000 ft         1976 atmosphere
flight.density              1e-6 to 3 kg/m^3        2e-9 to 0.006 slug/ft^3       and 0.5-2 x std
flight.theta0_deg           -89 to 89 deg                                         Θ0
flight.alpha0_deg           -89 to 89 deg                                         α0, body axis
mass.weight                 0.5 to 2e7 N            0.1 to 4.5e6 lbf
mass.mass                   0.05 to 2e6 kg          0.003 to 1.4e5 slug
mass.Ix, Iy, Iz             1e-6 to 1e10 kg m^2     1e-6 to 1e10 slug ft^2
mass.Ixz                    -1e10 to 1e10 kg m^2    -1e10 to 1e10 slug ft^2
geometry.S                  0.001 to 10,000 m^2     0.01 to 100,000 ft^2
geometry.cbar               0.01 to 100 m           0.03 to 300 ft
geometry.b                  0.05 to 500 m           0.15 to 1,600 ft
CL                          -10 to 10
CD                          0 to 10
CL_alpha, CD_alpha,         -100 to 100 per rad                                   α, β
Cm_alpha, Cy_beta,
Cl_beta, Cn_beta
CL_M, CD_M, Cm_M            -100 to 100                                           Mach
CL_alphadot, CL_q,          -1,000 to 1,000 per rad                               rates
Cm_alphadot, Cm_q,
Cy_p, Cy_r, Cl_p, Cl_r,
Cn_p, Cn_r
CL_de, CD_de, Cm_de,        -100 to 100 per rad                                   controls
Cy_dr, Cl_dr, Cn_dr,
Cy_da, Cl_da, Cn_da
published omega_n           1e-5 to 1,000 rad/s
published zeta              -10 to 10 (not 0)
published time_constant,    1e-4 to 1e7 s
time_to_half,
time_to_double
published tolerance         1e-12 to 1                                            relative
==========================  ======================  ============================  =============

The same ranges bound the conditions :meth:`~aerocontrol.aircraft.Aircraft.at` moves an
aircraft to (altitude, Mach and weight), so an envelope sweep records an implausible condition
as a failure.

>>> from aerocontrol.aircraft.schema import PLAUSIBLE_RANGES
>>> PLAUSIBLE_RANGES["weight"].bounds("english")
(0.1, 4500000.0, 'lbf')
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..exceptions import InvalidArgumentError

__all__ = [
    "PLAUSIBLE_RANGES",
    "UNIT_NAMES",
    "AircraftDataError",
    "PlausibleRange",
    "check_range",
    "shown",
]

UNIT_NAMES = {
    "english": {"length": "ft", "speed": "ft/s", "density": "slug/ft^3", "force": "lbf"},
    "si": {"length": "m", "speed": "m/s", "density": "kg/m^3", "force": "N"},
}
"""The unit of a length, a speed, a density and a force in each unit system of a file, for
messages and summaries."""


class AircraftDataError(InvalidArgumentError):
    """An aircraft file or table is malformed: unreadable (not a regular file, too large, not
    UTF-8, not TOML), an unknown or missing key, a value of the wrong type or sign or outside
    its plausible range, or numbers inconsistent with the declared units. The message is one
    line and names the file and the key.

    ``key`` is the dotted key of the problem (``"mass.weight"``, ``"published.roll"``, a
    table's name for a whole table), ``line`` its line in the file (1-based; for a missing
    key, the line of its table) and ``hint`` how to mend it; each is None or ``""`` where the
    reader cannot tell (an unreadable file, a dict without a file).

    Examples
    --------
    >>> error = AircraftDataError("plane.toml: [mass] is missing Ix", "mass.Ix", 12, "add Ix")
    >>> str(error), error.key, error.line, error.hint
    ('plane.toml: [mass] is missing Ix', 'mass.Ix', 12, 'add Ix')
    """

    def __init__(
        self, message: str, key: str | None = None, line: int | None = None, hint: str = ""
    ) -> None:
        super().__init__(message)
        self.key, self.line, self.hint = key, line, hint

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (str(self), self.key, self.line, self.hint))


@dataclass(frozen=True)
class PlausibleRange:
    """The values a quantity may take, ``low <= value <= high``, in each unit system.

    Attributes
    ----------
    low, high : float
        The bounds in SI units (``si_unit``).
    si_unit : str
        The SI unit ("" for a dimensionless quantity).
    english_low, english_high : float or None
        The bounds in English units, or None where they are the SI ones.
    english_unit : str or None
        The English unit, or None where it is the SI one.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> speed = aircraft.PLAUSIBLE_RANGES["speed"]
    >>> speed.bounds("si"), speed.bounds("english")
    ((0.5, 3500.0, 'm/s'), (1.5, 11500.0, 'ft/s'))
    """

    low: float
    high: float
    si_unit: str = ""
    english_low: float | None = None
    english_high: float | None = None
    english_unit: str | None = None

    def bounds(self, units: str) -> tuple[float, float, str]:
        """(low, high, unit) in the unit system ``units`` ("si" or "english")."""
        if units == "english" and self.english_low is not None and self.english_high is not None:
            unit = self.english_unit if self.english_unit is not None else self.si_unit
            return self.english_low, self.english_high, unit
        return self.low, self.high, self.si_unit


def _ranges() -> dict[str, PlausibleRange]:
    ranges = {
        "speed": PlausibleRange(0.5, 3_500.0, "m/s", 1.5, 11_500.0, "ft/s"),
        "mach": PlausibleRange(0.001, 12.0),
        "altitude": PlausibleRange(-5_000.0, 86_000.0, "m", -16_400.0, 282_000.0, "ft"),
        "density": PlausibleRange(1e-6, 3.0, "kg/m^3", 2e-9, 0.006, "slug/ft^3"),
        "theta0_deg": PlausibleRange(-89.0, 89.0, "deg"),
        "alpha0_deg": PlausibleRange(-89.0, 89.0, "deg"),
        "weight": PlausibleRange(0.5, 2e7, "N", 0.1, 4.5e6, "lbf"),
        "mass": PlausibleRange(0.05, 2e6, "kg", 0.003, 1.4e5, "slug"),
        "Ixz": PlausibleRange(-1e10, 1e10, "kg m^2", -1e10, 1e10, "slug ft^2"),
        "S": PlausibleRange(0.001, 10_000.0, "m^2", 0.01, 100_000.0, "ft^2"),
        "cbar": PlausibleRange(0.01, 100.0, "m", 0.03, 300.0, "ft"),
        "b": PlausibleRange(0.05, 500.0, "m", 0.15, 1_600.0, "ft"),
        "CL": PlausibleRange(-10.0, 10.0),
        "CD": PlausibleRange(0.0, 10.0),
        "omega_n": PlausibleRange(1e-5, 1_000.0, "rad/s"),
        "zeta": PlausibleRange(-10.0, 10.0),
        "tolerance": PlausibleRange(1e-12, 1.0),
    }
    for key in ("Ix", "Iy", "Iz"):
        ranges[key] = PlausibleRange(1e-6, 1e10, "kg m^2", 1e-6, 1e10, "slug ft^2")
    for key in ("time_constant", "time_to_half", "time_to_double"):
        ranges[key] = PlausibleRange(1e-4, 1e7, "s")
    per_radian = PlausibleRange(-100.0, 100.0, "per rad")
    for key in ("CL_alpha", "CD_alpha", "Cm_alpha", "Cy_beta", "Cl_beta", "Cn_beta"):
        ranges[key] = per_radian
    for key in ("CL_M", "CD_M", "Cm_M"):
        ranges[key] = PlausibleRange(-100.0, 100.0)
    rates = PlausibleRange(-1_000.0, 1_000.0, "per rad")
    for key in ("CL_alphadot", "CL_q", "Cm_alphadot", "Cm_q"):
        ranges[key] = rates
    for key in ("Cy_p", "Cy_r", "Cl_p", "Cl_r", "Cn_p", "Cn_r"):
        ranges[key] = rates
    for key in ("CL_de", "CD_de", "Cm_de", "Cy_dr", "Cl_dr", "Cn_dr", "Cy_da", "Cl_da", "Cn_da"):
        ranges[key] = per_radian
    return ranges


PLAUSIBLE_RANGES: Mapping[str, PlausibleRange] = _ranges()
"""The plausible range of every number of an aircraft file, by key (the table of the module's
documentation): generous bounds that reject nonsense, not unusual aircraft."""


_REPR = reprlib.Repr()
_REPR.maxstring = 60
_REPR.maxother = 60
_REPR.maxlevel = 3
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = 4


def shown(value: Any) -> str:
    """A short, one-line repr of a value read from a file, for error messages: long strings
    and deep or long containers are abbreviated, huge integers give their size."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
        return f"an integer of about {_digits(value)} digits"
    try:
        return _REPR.repr(value)
    except (RecursionError, ValueError):  # pragma: no cover - defensive: deep or odd values
        return f"a value of type {type(value).__name__}"


def _digits(value: int) -> int:
    return max(1, int(abs(value).bit_length() * math.log10(2.0)) + 1)


def check_range(
    value: Any,
    key: str,
    units: str = "si",
    where: str = "",
    positive: bool = False,
    bounded: bool = True,
) -> float:
    """``value`` as a float if it is a real number within the plausible range of ``key``
    (:data:`PLAUSIBLE_RANGES`) in the unit system ``units``; else AircraftDataError naming
    ``where`` (a prefix such as ``"plane.toml: [mass] "``), the key, the value and the range.
    With ``positive``, zero and negative values are refused first as not positive; with
    ``bounded=False``, only the type, finiteness and sign are checked (for a caller that
    checks the range itself after a more specific test)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise AircraftDataError(f"{where}{key} must be a finite number, got {shown(value)}")
    low, high, unit = PLAUSIBLE_RANGES[key].bounds(units)
    suffix = f" {unit}" if unit else ""
    span = f"the plausible range {low:g} to {high:g}{suffix}"
    try:
        number = float(value)
    except OverflowError:
        raise AircraftDataError(f"{where}{key}, {shown(value)}, is outside {span}") from None
    if not math.isfinite(number):
        raise AircraftDataError(f"{where}{key} must be a finite number, got {value!r}")
    if positive and number <= 0.0:
        raise AircraftDataError(f"{where}{key} must be positive, got {value!r}")
    if bounded and not low <= number <= high:
        raise AircraftDataError(f"{where}{key} = {number:g}{suffix} is outside {span}")
    return number
