"""Reading aircraft files safely, and the plausible range of every quantity they give.

An aircraft file is read only if it is a regular file (a symbolic link is followed only to a
regular file; a FIFO, a device, a socket or a folder is refused without being read) of at most
:data:`AIRCRAFT_FILE_LIMIT` bytes (1 MiB; the shipped files are under 15 kB), in UTF-8, and valid
TOML. Every failure is an :class:`AircraftDataError` (a ``ValueError``) whose one-line message
names the file and, where there is one, the table and the key.

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

The same ranges bound the conditions :meth:`Aircraft.at` moves an aircraft to (altitude, Mach
and weight), so an envelope sweep records an implausible condition as a failure.

>>> from aerocontrol.aircraft.schema import PLAUSIBLE_RANGES
>>> PLAUSIBLE_RANGES["weight"].bounds("english")
(0.1, 4500000.0, 'lbf')
"""

from __future__ import annotations

import math
import os
import re
import reprlib
import stat
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..exceptions import InvalidArgumentError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "AIRCRAFT_FILE_LIMIT",
    "PLAUSIBLE_RANGES",
    "AircraftDataError",
    "PlausibleRange",
    "check_range",
    "decode_text",
    "parse_toml",
    "read_aircraft_file",
    "read_toml",
    "shown",
]

AIRCRAFT_FILE_LIMIT = 1 << 20
"""The largest aircraft file read, in bytes (1 MiB)."""


class AircraftDataError(InvalidArgumentError):
    """An aircraft file or table is malformed: unreadable (not a regular file, too large, not
    UTF-8, not TOML), an unknown or missing key, a value of the wrong type or sign or outside
    its plausible range, or numbers inconsistent with the declared units. The message is one
    line and names the file and the key."""


@dataclass(frozen=True)
class PlausibleRange:
    """The values a quantity may take, ``low <= value <= high``, in each unit system."""

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


# --- Reading the file ---------------------------------------------------------------------------


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def read_aircraft_file(path: str | os.PathLike[str]) -> str:
    """The text of the aircraft file at ``path``: a regular file (a symbolic link is followed
    only to a regular file) of at most :data:`AIRCRAFT_FILE_LIMIT` bytes, decoded as UTF-8.

    A FIFO, a device, a socket or a folder is refused without being read (the file is opened
    non-blocking and checked again after opening, so a FIFO cannot block and a file swapped
    after the first check is still refused). Raises AircraftDataError naming the file.
    """
    name = str(path)
    where = f"cannot read the aircraft file {name!r}"
    try:
        before = os.stat(path)
    except (OSError, ValueError) as error:  # ValueError: a NUL byte in the path
        raise AircraftDataError(f"{where}: {_reason(error)}") from None
    if not stat.S_ISREG(before.st_mode):
        raise AircraftDataError(f"{where}: it is {_kind(before.st_mode)}, not a regular file")
    flags = os.O_RDONLY
    for flag in ("O_NONBLOCK", "O_NOCTTY", "O_CLOEXEC", "O_BINARY"):
        flags |= getattr(os, flag, 0)
    try:
        descriptor = os.open(path, flags)
    except OSError as error:
        raise AircraftDataError(f"{where}: {_reason(error)}") from None
    try:
        after = os.fstat(descriptor)
        if not stat.S_ISREG(after.st_mode):
            raise AircraftDataError(f"{where}: it is {_kind(after.st_mode)}, not a regular file")
        limit = f"it is larger than {AIRCRAFT_FILE_LIMIT:,} bytes, the limit of an aircraft file"
        if after.st_size > AIRCRAFT_FILE_LIMIT:
            raise AircraftDataError(f"{where}: {limit}")
        chunks, size = [], 0
        while size <= AIRCRAFT_FILE_LIMIT:
            chunk = os.read(descriptor, AIRCRAFT_FILE_LIMIT + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        if size > AIRCRAFT_FILE_LIMIT:  # grew while being read
            raise AircraftDataError(f"{where}: {limit}")
    except OSError as error:
        raise AircraftDataError(f"{where}: {_reason(error)}") from None
    finally:
        os.close(descriptor)
    return decode_text(b"".join(chunks), name)


def _reason(error: BaseException) -> str:
    if isinstance(error, OSError) and error.strerror:
        return error.strerror
    return str(error) or type(error).__name__


def decode_text(data: bytes, origin: str) -> str:
    """``data`` decoded as UTF-8, or AircraftDataError naming the first bad byte's offset."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise AircraftDataError(
            f"{origin}: not UTF-8 text: byte 0x{data[error.start]:02x} at offset {error.start} "
            f"({error.reason}); save the file as UTF-8"
        ) from None


_INTEGER = re.compile(r"[0-9][0-9_]*")
_KEY_BEFORE = re.compile(r"([A-Za-z0-9_\-]+)\s*=\s*[+-]?$")


def parse_toml(text: str, origin: str) -> dict[str, Any]:
    """The tables of a TOML document, or AircraftDataError with one line saying why not
    (the parser's message and position, nesting too deep for the parser, a number with more
    digits than Python converts)."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        message = " ".join(str(error).split())
        raise AircraftDataError(f"{origin}: not valid TOML: {message}") from None
    except RecursionError:
        raise AircraftDataError(
            f"{origin}: not valid TOML for an aircraft: arrays or tables nested too deeply"
        ) from None
    except ValueError:
        # The parser's int() refused an integer of more digits than Python converts
        # (sys.get_int_max_str_digits(), 4300 by default).
        raise AircraftDataError(f"{origin}: {_longest_integer(text)}") from None


def _longest_integer(text: str) -> str:
    """Where the longest run of digits is, for the message about an integer too long."""
    longest = max(_INTEGER.finditer(text), key=lambda m: len(m.group()), default=None)
    if longest is None:  # pragma: no cover - the parser fails only on a long integer
        return "not valid TOML: a number Python cannot read"
    start = longest.start()
    line_start = text.rfind("\n", 0, start) + 1
    line = text.count("\n", 0, start) + 1
    key = _KEY_BEFORE.search(text[line_start:start])
    digits = len(longest.group().replace("_", ""))
    named = f"{key.group(1)} = " if key else ""
    return (
        f"line {line}: {named}an integer of {digits} digits is outside the plausible range "
        "of every quantity"
    )


def read_toml(path: str | os.PathLike[str] | Path) -> dict[str, Any]:
    """:func:`read_aircraft_file` then :func:`parse_toml`: the tables of a TOML file."""
    return parse_toml(read_aircraft_file(path), str(path))
