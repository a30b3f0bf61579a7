"""The folder a report is written into, changed only where the report's own files are.

The rules (the README's "The report" and ``aerocontrol report --help`` say the same):

* A new or empty folder is used (missing parent folders are created).
* The report writes ``report.html``, ``report.md``, ``figures/*.png`` and a manifest,
  :data:`MANIFEST`, listing each of these files with its size and SHA-256.
* A folder with a manifest holds an earlier report. It is replaced, file by file, if every file
  the manifest lists is unchanged (or deleted): the earlier report's files are replaced or,
  if the new report does not write them, removed. Any file the manifest does not list (your
  notes, your images in ``figures/``) is never read, moved or deleted. If a listed file was
  changed since, the run stops and names it: a changed file is yours now.
* A folder that is not empty and holds no manifest is refused; with ``force`` the report is
  written beside the files there, still never replacing one: a file in the way (say your own
  ``report.md``) stops the run and is named.
* The manifest is read as untrusted input: a regular file of at most 1 MiB of JSON whose
  entries are only the report's own names (``report.html``, ``report.md``,
  ``figures/NAME.png``); anything else (``..``, absolute paths, other folders) refuses the run.
* Nothing is written through a symbolic link inside the folder (``report.md`` or ``figures``
  being one is a file in the way). The folder itself may be a link to a folder; it is
  resolved once, and every later step works on that folder (``openat`` and friends).
* The files are rendered into a staging folder inside the folder (``.aerocontrol-staging-*``,
  so on the same file system), then moved in: the earlier files into the staging folder as
  backups, the new ones linked into place without ever replacing a file (``link`` fails on
  an existing name). On any failure, and on SIGINT or SIGTERM, exactly what the run did is
  undone: its files are removed, the backups put back, the staging folder, the ``figures``
  folder and the parent folders it created removed if empty. The final moves run with
  SIGINT, SIGTERM and SIGHUP held back (their handlers run once the moves are done), so that
  a signal lands before them (nothing changed) or after them (the whole new report in
  place). Only a SIGKILL or a crash of the
  machine during those milliseconds can leave a mix, with the earlier files in the staging
  folder.
* One run at a time: a run holds an advisory lock (``flock``) on the folder; a second run
  into the same folder stops at once with one line.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ..exceptions import OutputFolderError
from .descriptors import Folder, link_new, same_file
from .manifest import FIGURES, MANIFEST, MANIFEST_LIMIT, REPORT_FILE, Listed, digest, parse_manifest
from .signals import signals_deferred
from .staging import STAGING_PREFIX, empty_staging, stage_files

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None  # type: ignore[assignment]

__all__ = ["ReportFolder"]


def _quoted(path: str) -> str:
    return repr(path)


@dataclass
class ReportFolder:
    """Writes a report's files into ``out`` by the rules of the module's documentation.

    Use :meth:`prepare` (creates and checks the folder, takes the lock, refuses at once what
    it must refuse), then :meth:`write` with the files (names relative to the folder, bytes),
    and :meth:`rollback` on any failure; :meth:`release` at the end in any case.
    """

    out: Path
    force: bool = False
    _created: list[str] = field(default_factory=list)
    _root: Folder | None = None
    _figures: Folder | None = None
    _figures_created: bool = False
    _staging: Folder | None = None
    _staging_name: str = ""
    _locked: bool = False
    _earlier: dict[str, Listed] = field(default_factory=dict)
    _manifest_present: bool = False
    _placed: list[tuple[Folder, str, os.stat_result]] = field(default_factory=list)
    _backups: list[tuple[Folder, str, str]] = field(default_factory=list)
    replacing: bool = False
    """Whether the folder holds an earlier report that this run replaces."""

    # -- Preparing ---------------------------------------------------------------------------

    def prepare(self) -> None:
        """Create the folder (and missing parents) if needed, lock it and check that the
        report may be written into it. Raises OutputFolderError (or OSError) with one line;
        then nothing is left of what it did."""
        try:
            self._create()
            try:
                self._root = Folder.open(str(self.out), follow=True)
            except OSError as error:
                raise self._fail(error.strerror or str(error)) from None
            self._lock()
            self._survey()
            self._staging_name = STAGING_PREFIX + secrets.token_hex(6)
            try:
                self._root.mkdir(self._staging_name, 0o700)
            except OSError as error:
                raise self._fail(error.strerror or str(error)) from None
            self._staging = self._root.subfolder(self._staging_name)
            self._staging.mkdir("new")
            self._staging.mkdir("old")
        except BaseException:
            self.rollback()
            raise

    def _fail(self, message: str) -> OutputFolderError:
        return OutputFolderError(
            f"cannot write the report into {_quoted(str(self.out))}: {message}"
        )

    def _create(self) -> None:
        out = str(self.out)
        if "\0" in out:
            raise self._fail("a folder name cannot contain a NUL character")
        if os.path.lexists(out):
            if os.path.isdir(out):
                return
            if os.path.islink(out) and not os.path.exists(out):
                raise self._fail("it is a symbolic link to nothing (a broken link)")
            raise self._fail("it exists and is not a folder")
        missing: list[str] = []
        path = os.path.abspath(out)
        while not os.path.lexists(path):
            missing.append(path)
            parent = os.path.dirname(path)
            if parent == path:  # pragma: no cover - the root always exists
                break
            path = parent
        if not os.path.isdir(path):
            raise self._fail(f"{_quoted(path)} is not a folder")
        for folder in reversed(missing):
            try:
                os.mkdir(folder)
            except FileExistsError:  # made meanwhile by someone else: not ours to remove
                continue
            except OSError as error:
                raise self._fail(error.strerror or str(error)) from None
            self._created.append(folder)

    def _lock(self) -> None:
        if fcntl is None or self._root is None or self._root.fd is None:  # pragma: no cover
            self._locked = True
            return
        try:
            fcntl.flock(self._root.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise self._fail(
                "another 'aerocontrol report' is writing into it; try again when it has finished"
            ) from None
        except OSError:  # pragma: no cover - a file system without locks: go on unlocked
            pass
        self._locked = True

    def _survey(self) -> None:
        root = self._root
        assert root is not None
        names = root.names()
        info = root.lstat(FIGURES)
        if info is not None and not stat.S_ISDIR(info.st_mode):
            raise self._in_the_way(FIGURES, info)
        manifest = root.lstat(MANIFEST)
        if manifest is not None:
            self._manifest_present = True
            data = root.read_regular(MANIFEST, MANIFEST_LIMIT)
            parsed: dict[str, Listed] | str
            if data is None:
                parsed = "not a regular file of at most 1 MiB"
            else:
                parsed = parse_manifest(data)
            if isinstance(parsed, str):
                raise self._fail(
                    f"{MANIFEST} is not a manifest written by aerocontrol ({parsed}); nothing "
                    "was changed: move it away or choose another --out"
                )
            self._earlier = parsed
            self.replacing = True
            for name, entry in parsed.items():
                if self._changed(name, entry):
                    raise self._changed_error(name)
        elif names and not self.force:
            leftover = [name for name in names if name.startswith(STAGING_PREFIX)]
            hint = (
                f" (it holds {leftover[0]}, left by a run that was killed: look into it, then "
                "remove it)"
                if leftover
                else ""
            )
            raise self._fail(
                f"it is not empty and holds no earlier report (no {MANIFEST}){hint}; choose a "
                "new or empty folder, or add --force to write the report beside its files "
                "(none of them is replaced)"
            )
        for name in ("report.html", "report.md"):
            self._check_free(name)

    def _in_the_way(self, name: str, info: os.stat_result) -> OutputFolderError:
        if stat.S_ISLNK(info.st_mode):
            what = "a symbolic link (the report never writes through one)"
        elif stat.S_ISDIR(info.st_mode):
            what = "a folder"
        elif stat.S_ISREG(info.st_mode) and name == FIGURES:
            what = "a file, where the report puts its figures folder"
        else:
            what = "a file the report did not write"
        return self._fail(
            f"{name} is {what}; it is not replaced: move it away or choose another --out"
        )

    def _changed_error(self, name: str) -> OutputFolderError:
        return self._fail(
            f"{name} was changed after aerocontrol wrote it, so it is yours now and is not "
            "replaced: move it away (or choose another --out) and run again"
        )

    def _check_free(self, name: str) -> None:
        """``name`` may be written: absent, or a file of the earlier report (checked unchanged
        by the survey)."""
        assert self._root is not None
        folder, leaf = self._root, name
        if "/" in name:
            sub, leaf = name.split("/", 1)
            info = self._root.lstat(sub)
            if info is None:
                return
            if not stat.S_ISDIR(info.st_mode):
                raise self._in_the_way(sub, info)
            folder = self._figures if self._figures is not None else self._root.subfolder(sub)
            try:
                info = folder.lstat(leaf)
            finally:
                if folder is not self._figures:
                    folder.close()
        else:
            info = folder.lstat(leaf)
        if info is None or name in self._earlier:
            return
        raise self._in_the_way(name, info)

    def _changed(self, name: str, entry: Listed) -> bool:
        """Whether the earlier report's ``name`` exists and differs from its manifest entry
        (a deleted file is not a change: there is nothing to lose)."""
        assert self._root is not None
        folder, leaf = self._root, name
        if "/" in name:
            sub, leaf = name.split("/", 1)
            info = self._root.lstat(sub)
            if info is None:
                return False
            if not stat.S_ISDIR(info.st_mode):
                return True
            folder = self._root.subfolder(sub)
        try:
            info = folder.lstat(leaf)
            if info is None:
                return False
            if not stat.S_ISREG(info.st_mode) or info.st_size != entry.size:
                return True
            data = folder.read_regular(leaf, entry.size)
            return data is None or digest(data) != entry
        finally:
            if folder is not self._root:
                folder.close()

    # -- Writing ------------------------------------------------------------------------------

    def write(self, files: Mapping[str, bytes]) -> None:
        """Stage ``files`` and move them into the folder, with the manifest; the earlier
        report's files are replaced or removed. Raises OutputFolderError naming a file in the
        way or changed meanwhile, or the reason the file system gave; call :meth:`rollback` on
        any exception."""
        for name in files:
            if not REPORT_FILE.fullmatch(name):  # pragma: no cover - the report's own names
                raise ValueError(f"not a file of a report: {name!r}")
        try:
            assert self._staging is not None
            stage_files(self._staging, files)
            with signals_deferred():
                self._commit(files)
                self._finish()
        except OutputFolderError:
            raise
        except OSError as error:
            reason = error.strerror or str(error)
            raise self._fail(reason) from error

    def _commit(self, files: Mapping[str, bytes]) -> None:
        root, staging = self._root, self._staging
        assert root is not None and staging is not None
        # Everything is checked again: files may have changed while the report was built.
        for name, entry in self._earlier.items():
            if self._changed(name, entry):
                raise self._changed_error(name)
        for name in files:
            self._check_free(name)
        info = root.lstat(FIGURES)
        if info is None:
            root.mkdir(FIGURES)
            self._figures_created = True
        elif not stat.S_ISDIR(info.st_mode):
            raise self._in_the_way(FIGURES, info)
        self._figures = root.subfolder(FIGURES)
        old = staging.subfolder("old")
        new = staging.subfolder("new")
        new_figures = new.subfolder(FIGURES)
        old.mkdir(FIGURES)
        old_figures = old.subfolder(FIGURES)
        try:
            # The earlier report's files (and manifest) out of the way, into the staging folder.
            earlier = [*self._earlier, MANIFEST] if self._manifest_present else []
            for name in earlier:
                folder, leaf, backup = self._place_of(name, old, old_figures)
                if folder.lstat(leaf) is None:
                    continue
                link_new(folder, leaf, backup, leaf)
                self._backups.append((folder, leaf, name))
                if name != MANIFEST and self._changed_backup(backup, leaf, self._earlier[name]):
                    raise self._changed_error(name)
            # The new files into place, never over an existing name.
            for name in [*files, MANIFEST]:
                folder, leaf, source = self._place_of(name, new, new_figures)
                try:
                    link_new(source, leaf, folder, leaf)
                except FileExistsError:
                    info = folder.lstat(leaf)
                    raise (
                        self._in_the_way(name, info)
                        if info
                        else self._fail(f"{name} appeared while the report was written")
                    ) from None
                placed = folder.lstat(leaf)
                assert placed is not None
                self._placed.append((folder, leaf, placed))
            self._figures.sync()
            root.sync()
        finally:
            for handle in (old_figures, old, new_figures, new):
                handle.close()

    def _place_of(
        self, name: str, staged: Folder, staged_figures: Folder
    ) -> tuple[Folder, str, Folder]:
        assert self._root is not None and self._figures is not None
        if name.startswith(FIGURES + "/"):
            return self._figures, name.split("/", 1)[1], staged_figures
        return self._root, name, staged

    def _changed_backup(self, backup: Folder, leaf: str, entry: Listed) -> bool:
        data = backup.read_regular(leaf, entry.size)
        return data is None or digest(data) != entry

    def _finish(self) -> None:
        """The run succeeded: drop the backups and the staging folder."""
        self._backups.clear()
        self._placed.clear()
        self._remove_staging()

    # -- Undoing ------------------------------------------------------------------------------

    def rollback(self) -> list[str]:
        """Undo what this run did, with signals held back: remove the files it placed (if
        they are still its own), put the earlier files back, remove the staging folder and
        the folders it created if they are empty. Returns what could not be undone."""
        problems: list[str] = []
        with signals_deferred():
            for folder, leaf, placed in reversed(self._placed):
                with contextlib.suppress(OSError):
                    if same_file(folder.lstat(leaf), placed):
                        folder.unlink(leaf)
            self._placed.clear()
            kept = False
            if self._backups and self._staging is not None:
                old = self._staging.subfolder("old")
                old_figures = old.subfolder(FIGURES)
                for folder, leaf, name in reversed(self._backups):
                    backup = old_figures if name.startswith(FIGURES + "/") else old
                    try:
                        link_new(backup, leaf, folder, leaf)
                    except OSError as error:
                        kept = True
                        problems.append(
                            f"the earlier {name} could not be put back ({error.strerror or error})"
                            f"; it is in {self._staging_name}/old"
                        )
                old_figures.close()
                old.close()
            self._backups.clear()
            if not kept:
                self._remove_staging()
            if self._figures_created and self._root is not None:
                if self._figures is not None:
                    self._figures.close()
                    self._figures = None
                with contextlib.suppress(OSError):
                    self._root.rmdir(FIGURES)
                self._figures_created = False
            # The folders this run created, deepest first, if empty; not if another run holds
            # the lock on the folder (it made the folder its own), and while holding it.
            if self._locked or self._root is None:
                for created in reversed(self._created):
                    with contextlib.suppress(OSError):
                        os.rmdir(created)
            self._created.clear()
            self.release()
        return problems

    def _remove_staging(self) -> None:
        if self._staging is None or self._root is None:
            return
        staging = self._staging
        empty_staging(staging)
        staging.close()
        self._staging = None
        with contextlib.suppress(OSError):
            self._root.rmdir(self._staging_name)

    def release(self) -> None:
        """Close the folder (which releases the lock)."""
        if self._figures is not None:
            self._figures.close()
            self._figures = None
        if self._root is not None:
            self._root.close()
