"""The staging folder of a run, ``.aerocontrol-staging-*`` inside the report folder (so on the
same file system, where a file is moved by a hard link): ``new/`` holds the files the run
rendered, with ``new/figures/`` and the manifest, ready to be linked into place; ``old/``
receives the earlier report's files as backups until the run ends."""

from __future__ import annotations

import contextlib
import stat
from collections.abc import Mapping

from .descriptors import Folder
from .manifest import FIGURES, MANIFEST, digest, manifest_text

__all__ = ["STAGING_PREFIX", "empty_staging", "stage_files"]

STAGING_PREFIX = ".aerocontrol-staging-"
"""The prefix of the staging folder a run builds its files in (removed when it ends)."""


def stage_files(staging: Folder, files: Mapping[str, bytes]) -> None:
    """Write ``files`` (names relative to the report folder, bytes) and their manifest into
    ``new/`` of the staging folder, each as a new file, flushed to disk."""
    new = staging.subfolder("new")
    try:
        new.mkdir(FIGURES)
        figures = new.subfolder(FIGURES)
        try:
            for name, data in files.items():
                if name.startswith(FIGURES + "/"):
                    figures.write_new(name.split("/", 1)[1], data)
                else:
                    new.write_new(name, data)
        finally:
            figures.close()
        listed = {name: digest(data) for name, data in files.items()}
        new.write_new(MANIFEST, manifest_text(listed))
        new.sync()
    finally:
        new.close()


def empty_staging(staging: Folder) -> None:
    """Remove ``new/`` and ``old/`` of the staging folder with what is in them (their files and
    the files of their ``figures/``); what cannot be removed stays."""
    for part in ("new", "old"):
        try:
            folder = staging.subfolder(part)
        except OSError:
            continue
        try:
            for name in folder.names():
                info = folder.lstat(name)
                if info is not None and stat.S_ISDIR(info.st_mode):
                    sub = folder.subfolder(name)
                    for leaf in sub.names():
                        with contextlib.suppress(OSError):
                            sub.unlink(leaf)
                    sub.close()
                    with contextlib.suppress(OSError):
                        folder.rmdir(name)
                else:
                    with contextlib.suppress(OSError):
                        folder.unlink(name)
        finally:
            folder.close()
        with contextlib.suppress(OSError):
            staging.rmdir(part)
