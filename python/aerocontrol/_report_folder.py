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
import errno
import hashlib
import json
import os
import re
import secrets
import signal
import stat
import threading
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .exceptions import OutputFolderError

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None  # type: ignore[assignment]

__all__ = ["MANIFEST", "STAGING_PREFIX", "ReportFolder", "signals_deferred", "termination_exits"]

MANIFEST = ".aerocontrol-report.json"
"""The manifest of a report folder: every file the report wrote, with size and SHA-256."""
STAGING_PREFIX = ".aerocontrol-staging-"
"""The prefix of the staging folder a run builds its files in (removed when it ends)."""
MANIFEST_LIMIT = 1 << 20
_FORMAT = "aerocontrol-report"
_VERSION = 1
_FIGURES = "figures"
_NAME = re.compile(r"report\.html|report\.md|figures/[A-Za-z0-9][A-Za-z0-9_-]{0,100}\.png")
_SHA256 = re.compile(r"[0-9a-f]{64}")

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_BINARY = getattr(os, "O_BINARY", 0)
_AT = os.open in os.supports_dir_fd and os.link in os.supports_dir_fd
_DEFERRED = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)


# --- Signals ------------------------------------------------------------------------------------


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """Hold back SIGINT, SIGTERM and SIGHUP for the duration: a signal that arrives meanwhile
    is recorded, and its handler runs (or its default action is taken) when the block ends.

    The Python-level handlers are swapped, not the thread's signal mask: in a process with
    other threads (the core's thread pool) the kernel delivers a signal to any thread that
    does not block it, and Python then runs the handler in the main thread regardless. Only
    in the main thread (where handlers can be set); elsewhere the block is not protected.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []

    def hold(signum: int, frame: object) -> None:
        received.append(signum)

    previous: dict[int, Any] = {}
    for number in _DEFERRED:
        handler = signal.getsignal(number)
        if handler is None or handler == signal.SIG_IGN:  # set outside Python, or ignored
            continue
        previous[number] = signal.signal(number, hold)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        for number in dict.fromkeys(received):  # each signal once, in order of arrival
            handler = previous[number]
            if callable(handler):
                handler(number, None)
            else:  # SIG_DFL: the default action, now that the handler is back
                os.kill(os.getpid(), number)


def _exit_on_signal(signum: int, frame: object) -> None:
    raise SystemExit(128 + signum)


@contextlib.contextmanager
def termination_exits() -> Iterator[None]:
    """While it lasts, SIGTERM and SIGHUP, where they would kill the process outright (their
    default action), raise SystemExit(128 + signal) instead, so that a run is undone before
    the process ends. Only in the main thread, and only for signals left at their default."""
    installed: dict[int, Any] = {}
    if threading.current_thread() is threading.main_thread():
        for name in ("SIGTERM", "SIGHUP"):
            number = getattr(signal, name, None)
            if number is not None and signal.getsignal(number) == signal.SIG_DFL:
                installed[number] = signal.signal(number, _exit_on_signal)
    try:
        yield
    finally:
        for number, previous in installed.items():
            signal.signal(number, previous)


# --- Folders by descriptor ----------------------------------------------------------------------


class _Folder:
    """A folder opened once: every operation is relative to its descriptor (``openat``,
    ``linkat``, ``renameat``...), so a symbolic link swapped in for the folder or one of its
    sub-folders later cannot redirect anything. Without ``dir_fd`` support (not POSIX) the
    operations fall back to paths."""

    def __init__(self, path: str, fd: int | None) -> None:
        self.path, self.fd = path, fd

    @classmethod
    def open(cls, path: str, dir_fd: int | None = None, follow: bool = False) -> _Folder:
        flags = os.O_RDONLY | _DIRECTORY | _CLOEXEC | (0 if follow else _NOFOLLOW)
        if not _AT:  # pragma: no cover - not POSIX
            if not os.path.isdir(path):
                raise NotADirectoryError(errno.ENOTDIR, "Not a directory", path)
            return cls(path, None)
        name = path if dir_fd is None else os.path.basename(path)
        return cls(path, os.open(name, flags, dir_fd=dir_fd))

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def child(self, name: str) -> str:
        return os.path.join(self.path, name)

    def _at(self, name: str) -> tuple[str, int | None]:
        return (name, self.fd) if self.fd is not None else (self.child(name), None)

    def subfolder(self, name: str) -> _Folder:
        if self.fd is None:  # pragma: no cover - not POSIX
            return _Folder.open(self.child(name))
        return _Folder.open(self.child(name), dir_fd=self.fd)

    def names(self) -> list[str]:
        return sorted(os.listdir(self.fd if self.fd is not None else self.path))

    def lstat(self, name: str) -> os.stat_result | None:
        where, fd = self._at(name)
        try:
            return os.stat(where, dir_fd=fd, follow_symlinks=False)
        except FileNotFoundError:
            return None

    def mkdir(self, name: str, mode: int = 0o777) -> None:
        where, fd = self._at(name)
        os.mkdir(where, mode, dir_fd=fd)

    def rmdir(self, name: str) -> None:
        where, fd = self._at(name)
        os.rmdir(where, dir_fd=fd)

    def unlink(self, name: str) -> None:
        where, fd = self._at(name)
        os.unlink(where, dir_fd=fd)

    def open_file(self, name: str, flags: int, mode: int = 0o666) -> int:
        where, fd = self._at(name)
        return os.open(where, flags | _CLOEXEC | _NOFOLLOW | _BINARY, mode, dir_fd=fd)

    def read_regular(self, name: str, limit: int) -> bytes | None:
        """The bytes of the regular file ``name`` (not a link, FIFO or device), or None if it
        is not one or is larger than ``limit``."""
        try:
            descriptor = self.open_file(name, os.O_RDONLY | _NONBLOCK)
        except OSError:
            return None
        try:
            info = os.fstat(descriptor)
            if not stat.S_ISREG(info.st_mode) or info.st_size > limit:
                return None
            chunks, size = [], 0
            while size <= limit:
                chunk = os.read(descriptor, min(1 << 20, limit + 1 - size))
                if not chunk:
                    break
                chunks.append(chunk)
                size += len(chunk)
            return None if size > limit else b"".join(chunks)
        finally:
            os.close(descriptor)

    def write_new(self, name: str, data: bytes) -> os.stat_result:
        """Create the file ``name`` (it must not exist) with ``data``, flushed to disk."""
        descriptor = self.open_file(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(descriptor, view) :]
            os.fsync(descriptor)
            return os.fstat(descriptor)
        finally:
            os.close(descriptor)

    def sync(self) -> None:
        if self.fd is not None:
            with contextlib.suppress(OSError):
                os.fsync(self.fd)


def _link_new(source: _Folder, name: str, target: _Folder, new_name: str) -> None:
    """Put ``source/name`` at ``target/new_name`` without replacing anything there: a hard
    link, which fails with FileExistsError on an existing name (a symbolic link included);
    where the file system has no hard links, a rename after checking that the name is free."""
    src, src_fd = source._at(name)
    dst, dst_fd = target._at(new_name)
    try:
        os.link(src, dst, src_dir_fd=src_fd, dst_dir_fd=dst_fd, follow_symlinks=False)
    except FileExistsError:
        raise
    except OSError as error:
        if error.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EMLINK):
            raise
        if target.lstat(new_name) is not None:  # pragma: no cover - file systems without links
            raise FileExistsError(errno.EEXIST, "File exists", target.child(new_name)) from None
        os.rename(src, dst, src_dir_fd=src_fd, dst_dir_fd=dst_fd)  # pragma: no cover
        return  # pragma: no cover
    os.unlink(src, dir_fd=src_fd)


def _same_file(info: os.stat_result | None, other: os.stat_result | None) -> bool:
    return (
        info is not None
        and other is not None
        and (info.st_dev, info.st_ino) == (other.st_dev, other.st_ino)
    )


# --- The manifest -------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Listed:
    size: int
    sha256: str


def _digest(data: bytes) -> _Listed:
    return _Listed(len(data), hashlib.sha256(data).hexdigest())


def _manifest_text(files: Mapping[str, _Listed]) -> bytes:
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


def _parse_manifest(data: bytes) -> dict[str, _Listed] | str:
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
    files: dict[str, _Listed] = {}
    for name, entry in listed.items():
        if not isinstance(name, str) or not _NAME.fullmatch(name):
            shown = repr(name)[:80] if isinstance(name, str) else type(name).__name__
            return f"the entry {shown} is not a file of a report"
        if not isinstance(entry, dict):
            return f"the entry {name!r} has no size and hash"
        size, digest = entry.get("size"), entry.get("sha256")
        if isinstance(size, bool) or not isinstance(size, int) or not 0 <= size <= 1 << 40:
            return f"the entry {name!r} has no valid size"
        if not isinstance(digest, str) or not _SHA256.fullmatch(digest):
            return f"the entry {name!r} has no valid SHA-256"
        files[name] = _Listed(size, digest)
    return files


# --- The folder ---------------------------------------------------------------------------------


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
    _root: _Folder | None = None
    _figures: _Folder | None = None
    _figures_created: bool = False
    _staging: _Folder | None = None
    _staging_name: str = ""
    _locked: bool = False
    _earlier: dict[str, _Listed] = field(default_factory=dict)
    _manifest_present: bool = False
    _placed: list[tuple[_Folder, str, os.stat_result]] = field(default_factory=list)
    _backups: list[tuple[_Folder, str, str]] = field(default_factory=list)
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
                self._root = _Folder.open(str(self.out), follow=True)
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
        info = root.lstat(_FIGURES)
        if info is not None and not stat.S_ISDIR(info.st_mode):
            raise self._in_the_way(_FIGURES, info)
        manifest = root.lstat(MANIFEST)
        if manifest is not None:
            self._manifest_present = True
            data = root.read_regular(MANIFEST, MANIFEST_LIMIT)
            parsed: dict[str, _Listed] | str
            if data is None:
                parsed = "not a regular file of at most 1 MiB"
            else:
                parsed = _parse_manifest(data)
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
        elif stat.S_ISREG(info.st_mode) and name == _FIGURES:
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

    def _changed(self, name: str, entry: _Listed) -> bool:
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
            return data is None or _digest(data) != entry
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
            if not _NAME.fullmatch(name):  # pragma: no cover - the report's own names
                raise ValueError(f"not a file of a report: {name!r}")
        try:
            self._stage(files)
            with signals_deferred():
                self._commit(files)
                self._finish()
        except OutputFolderError:
            raise
        except OSError as error:
            reason = error.strerror or str(error)
            raise self._fail(reason) from error

    def _stage(self, files: Mapping[str, bytes]) -> None:
        assert self._staging is not None
        new = self._staging.subfolder("new")
        try:
            new.mkdir(_FIGURES)
            figures = new.subfolder(_FIGURES)
            try:
                for name, data in files.items():
                    if name.startswith(_FIGURES + "/"):
                        figures.write_new(name.split("/", 1)[1], data)
                    else:
                        new.write_new(name, data)
            finally:
                figures.close()
            listed = {name: _digest(data) for name, data in files.items()}
            new.write_new(MANIFEST, _manifest_text(listed))
            new.sync()
        finally:
            new.close()

    def _commit(self, files: Mapping[str, bytes]) -> None:
        root, staging = self._root, self._staging
        assert root is not None and staging is not None
        # Everything is checked again: files may have changed while the report was built.
        for name, entry in self._earlier.items():
            if self._changed(name, entry):
                raise self._changed_error(name)
        for name in files:
            self._check_free(name)
        info = root.lstat(_FIGURES)
        if info is None:
            root.mkdir(_FIGURES)
            self._figures_created = True
        elif not stat.S_ISDIR(info.st_mode):
            raise self._in_the_way(_FIGURES, info)
        self._figures = root.subfolder(_FIGURES)
        old = staging.subfolder("old")
        new = staging.subfolder("new")
        new_figures = new.subfolder(_FIGURES)
        old.mkdir(_FIGURES)
        old_figures = old.subfolder(_FIGURES)
        try:
            # The earlier report's files (and manifest) out of the way, into the staging folder.
            earlier = [*self._earlier, MANIFEST] if self._manifest_present else []
            for name in earlier:
                folder, leaf, backup = self._place_of(name, old, old_figures)
                if folder.lstat(leaf) is None:
                    continue
                _link_new(folder, leaf, backup, leaf)
                self._backups.append((folder, leaf, name))
                if name != MANIFEST and self._changed_backup(backup, leaf, self._earlier[name]):
                    raise self._changed_error(name)
            # The new files into place, never over an existing name.
            for name in [*files, MANIFEST]:
                folder, leaf, source = self._place_of(name, new, new_figures)
                try:
                    _link_new(source, leaf, folder, leaf)
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
        self, name: str, staged: _Folder, staged_figures: _Folder
    ) -> tuple[_Folder, str, _Folder]:
        assert self._root is not None and self._figures is not None
        if name.startswith(_FIGURES + "/"):
            return self._figures, name.split("/", 1)[1], staged_figures
        return self._root, name, staged

    def _changed_backup(self, backup: _Folder, leaf: str, entry: _Listed) -> bool:
        data = backup.read_regular(leaf, entry.size)
        return data is None or _digest(data) != entry

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
                    if _same_file(folder.lstat(leaf), placed):
                        folder.unlink(leaf)
            self._placed.clear()
            kept = False
            if self._backups and self._staging is not None:
                old = self._staging.subfolder("old")
                old_figures = old.subfolder(_FIGURES)
                for folder, leaf, name in reversed(self._backups):
                    backup = old_figures if name.startswith(_FIGURES + "/") else old
                    try:
                        _link_new(backup, leaf, folder, leaf)
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
                    self._root.rmdir(_FIGURES)
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
