"""The manifest of a report folder, :data:`MANIFEST`: a JSON file listing every file the report
wrote with its size and SHA-256, so that the next run replaces only those files, and only while
they are unchanged.

It is read as untrusted input: the caller reads at most :data:`MANIFEST_LIMIT` bytes of a
regular file, and :func:`parse_manifest` accepts only this program's format and version with
entries that are the report's own file names (:data:`REPORT_FILE`); anything else (``..``,
absolute paths, other folders) is refused with the reason."""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Mapping
from dataclasses import dataclass

__all__ = [
    "FIGURES",
    "MANIFEST",
    "MANIFEST_LIMIT",
    "REPORT_FILE",
    "Listed",
    "digest",
    "manifest_text",
    "parse_manifest",
]

MANIFEST = ".aerocontrol-report.json"
"""The manifest of a report folder: every file the report wrote, with size and SHA-256."""
MANIFEST_LIMIT = 1 << 20
"""The largest manifest read, in bytes (1 MiB)."""
FIGURES = "figures"
"""The folder of the figures, inside the report folder."""
REPORT_FILE = re.compile(r"report\.html|report\.md|figures/[A-Za-z0-9][A-Za-z0-9_-]{0,100}\.png")
"""The names of a report's files, relative to the report folder: all a manifest may list."""
_FORMAT = "aerocontrol-report"
_VERSION = 1
_SHA256 = re.compile(r"[0-9a-f]{64}")


@dataclass(frozen=True)
class Listed:
    """A file as a manifest lists it: its size in bytes and its SHA-256 (hexadecimal)."""

    size: int
    sha256: str


def digest(data: bytes) -> Listed:
    """The manifest entry of a file with the bytes ``data``."""
    return Listed(len(data), hashlib.sha256(data).hexdigest())


def manifest_text(files: Mapping[str, Listed]) -> bytes:
    """The manifest listing ``files``, as UTF-8 JSON (keys sorted, so equal lists give equal
    bytes)."""
    document = {
        "format": _FORMAT,
        "version": _VERSION,
        "note": "Written by 'aerocontrol report': the files of the report, replaced by the next "
        "report into this folder while they are unchanged; other files are never touched.",
        "files": {
            name: {"size": entry.size, "sha256": entry.sha256} for name, entry in files.items()
        },
    }
    return (json.dumps(document, indent=1, sort_keys=True) + "\n").encode("utf-8")


def parse_manifest(data: bytes) -> dict[str, Listed] | str:
    """The files a manifest lists, or why it is not a manifest of this program."""
    try:
        document = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError):
        return "not JSON"
    if not isinstance(document, dict):
        return "not a JSON object"
    if document.get("format") != _FORMAT or document.get("version") != _VERSION:
        return f"not format {_FORMAT!r} version {_VERSION}"
    listed = document.get("files")
    if not isinstance(listed, dict):
        return "no table of files"
    files: dict[str, Listed] = {}
    for name, entry in listed.items():
        if not isinstance(name, str) or not REPORT_FILE.fullmatch(name):
            shown = repr(name)[:80] if isinstance(name, str) else type(name).__name__
            return f"the entry {shown} is not a file of a report"
        if not isinstance(entry, dict):
            return f"the entry {name!r} has no size and hash"
        size, sha256 = entry.get("size"), entry.get("sha256")
        if isinstance(size, bool) or not isinstance(size, int) or not 0 <= size <= 1 << 40:
            return f"the entry {name!r} has no valid size"
        if not isinstance(sha256, str) or not _SHA256.fullmatch(sha256):
            return f"the entry {name!r} has no valid SHA-256"
        files[name] = Listed(size, sha256)
    return files
