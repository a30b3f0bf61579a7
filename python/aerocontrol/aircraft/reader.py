"""Reading aircraft files: the file itself and its TOML, for a shipped aircraft or a path.

An aircraft file is read only if it is a regular file (a symbolic link is followed only to a
regular file; a FIFO, a device, a socket or a folder is refused without being read) of at most
:data:`AIRCRAFT_FILE_LIMIT` bytes (1 MiB; the shipped files are under 15 kB), in UTF-8, and valid
TOML. Every failure is an :class:`~aerocontrol.aircraft.schema.AircraftDataError` (a
``ValueError``) whose one-line message names the file. Its tables are then read by
:mod:`~aerocontrol.aircraft.tables`.
"""

from __future__ import annotations

import os
import re
import stat
import sys
from importlib import resources
from pathlib import Path
from typing import Any

from .schema import AircraftDataError, shown

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = [
    "AIRCRAFT_FILE_LIMIT",
    "available",
    "decode_text",
    "key_lines",
    "parse_toml",
    "read_aircraft_file",
    "read_source",
    "read_toml",
]

AIRCRAFT_FILE_LIMIT = 1 << 20
"""The largest aircraft file read, in bytes (1 MiB)."""
_DATA = "aerocontrol.aircraft.data"


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
_AT_LINE = re.compile(r"\bline (\d+)")


def parse_toml(text: str, origin: str) -> dict[str, Any]:
    """The tables of a TOML document, or AircraftDataError with one line saying why not
    (the parser's message and position, nesting too deep for the parser, a number with more
    digits than Python converts)."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        message = " ".join(str(error).split())
        at = _AT_LINE.search(message)
        raise AircraftDataError(
            f"{origin}: not valid TOML: {message}",
            line=int(at.group(1)) if at else None,
            hint="mend the TOML syntax at that line (a value after every '=', quotes around "
            "text, each key once per table); the parser stops at its first error",
        ) from None
    except RecursionError:
        raise AircraftDataError(
            f"{origin}: not valid TOML for an aircraft: arrays or tables nested too deeply"
        ) from None
    except ValueError:
        # The parser's int() refused an integer of more digits than Python converts
        # (sys.get_int_max_str_digits(), 4300 by default).
        message = _longest_integer(text)
        at = _AT_LINE.search(message)
        raise AircraftDataError(
            f"{origin}: {message}", line=int(at.group(1)) if at else None
        ) from None


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


_HEADER = re.compile(r"\s*\[\s*([^\[\]#=,]+?)\s*\]\s*(?:#.*)?$")
_ASSIGNED = re.compile(
    r"\s*((?:[A-Za-z0-9_\-]+|\"[^\"]*\"|'[^']*')(?:\s*\.\s*(?:[A-Za-z0-9_\-]+|\"[^\"]*\"|'[^']*'))*)\s*="
)
_INLINE_KEY = re.compile(r"[{,]\s*([A-Za-z0-9_\-]+|\"[^\"]*\"|'[^']*')\s*=")


def _dotted(key: str) -> str:
    """A TOML key as a dotted path: whitespace around dots and the quotes of parts dropped."""
    parts = re.findall(r"\"([^\"]*)\"|'([^']*)'|([^.\s]+)", key)
    return ".".join(next(part for part in groups if part) for groups in parts)


def key_lines(text: str) -> dict[str, int]:
    """The line (1-based) of every table and key of a TOML document, by dotted path.

    ``[published]`` maps ``"published"``, ``Cm_q = -20.8`` under ``[longitudinal]`` maps
    ``"longitudinal.Cm_q"``, and the keys of an inline table such as ``roll = {
    time_constant = 0.8 }`` map ``"published.roll"`` and ``"published.roll.time_constant"``
    to the line of the inline table. Lines inside multi-line strings are skipped; a key given
    twice (invalid TOML, which the parser refuses) keeps its first line.

    Parameters
    ----------
    text : str
        The TOML document.

    Returns
    -------
    dict of str to int
        The line of each dotted path.

    Raises
    ------
    None

    Examples
    --------
    >>> lines = key_lines("[mass]\\nIx = 1.0  # slug ft^2\\n[published]\\nroll = { zeta = 1 }")
    >>> lines["mass.Ix"], lines["published"], lines["published.roll.zeta"]
    (2, 3, 4)
    """
    lines: dict[str, int] = {}
    table = ""
    quote: str | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        if quote is not None:  # inside a multi-line string
            if line.count(quote) % 2 == 1:
                quote = None
            continue
        header = _HEADER.match(line)
        if header:
            table = _dotted(header.group(1))
            lines.setdefault(table, number)
            continue
        assigned = _ASSIGNED.match(line)
        if not assigned:
            continue
        path = f"{table}.{_dotted(assigned.group(1))}" if table else _dotted(assigned.group(1))
        lines.setdefault(path, number)
        rest = line[assigned.end() :]
        for marker in ('"""', "'''"):
            if rest.count(marker) % 2 == 1:
                quote = marker
        if rest.lstrip().startswith("{"):
            for inner in _INLINE_KEY.finditer(rest):
                lines.setdefault(f"{path}.{_dotted(inner.group(1))}", number)
    return lines


def read_toml(path: str | os.PathLike[str] | Path) -> dict[str, Any]:
    """:func:`read_aircraft_file` then :func:`parse_toml`: the tables of a TOML file."""
    return parse_toml(read_aircraft_file(path), str(path))


def available() -> tuple[str, ...]:
    """The identifiers of the shipped aircraft, sorted (``load`` takes any of them).

    Returns
    -------
    tuple of str
        The identifiers, the names of the shipped files without ``.toml``.

    Raises
    ------
    None
        The shipped files are listed from the installed package.

    Examples
    --------
    >>> from aerocontrol import aircraft
    >>> aircraft.available()[:3]
    ('b747-20kft', 'b747-approach', 'b747-cruise')
    """
    return tuple(
        sorted(
            entry.name.removesuffix(".toml")
            for entry in resources.files(_DATA).iterdir()
            if entry.name.endswith(".toml")
        )
    )


def read_source(name_or_path: str | Path) -> tuple[str, str]:
    """The text of a shipped aircraft (by identifier) or of an aircraft file (by path), and its
    origin, the name its errors give; AircraftDataError for anything else."""
    if isinstance(name_or_path, str) and name_or_path in available():
        resource = resources.files(_DATA).joinpath(f"{name_or_path}.toml")
        origin = f"{name_or_path}.toml"
        return decode_text(resource.read_bytes(), origin), origin
    if not isinstance(name_or_path, (str, Path)):
        raise AircraftDataError(
            f"an aircraft is a shipped identifier or the path of a .toml file, got "
            f"{shown(name_or_path)}"
        )
    path = Path(name_or_path)
    if path.suffix != ".toml":
        raise AircraftDataError(
            f"unknown aircraft {shown(str(name_or_path))}: give a file ending in .toml or one of "
            f"{', '.join(available())}"
        )
    return read_aircraft_file(path), str(path)
