"""Folders opened once and worked on by descriptor (``openat``, ``linkat``, ``unlinkat``...),
so that a symbolic link swapped in for a folder later cannot redirect what the report writes
or removes; and the one way a file is put in place, never replacing another."""

from __future__ import annotations

import contextlib
import errno
import os
import stat

__all__ = ["Folder", "link_new", "same_file"]

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)
_BINARY = getattr(os, "O_BINARY", 0)
_AT = os.open in os.supports_dir_fd and os.link in os.supports_dir_fd


class Folder:
    """A folder opened once: every operation is relative to its descriptor (``openat``,
    ``linkat``, ``renameat``...), so a symbolic link swapped in for the folder or one of its
    sub-folders later cannot redirect anything. Without ``dir_fd`` support (not POSIX) the
    operations fall back to paths."""

    def __init__(self, path: str, fd: int | None) -> None:
        self.path, self.fd = path, fd

    @classmethod
    def open(cls, path: str, dir_fd: int | None = None, follow: bool = False) -> Folder:
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

    def subfolder(self, name: str) -> Folder:
        if self.fd is None:  # pragma: no cover - not POSIX
            return Folder.open(self.child(name))
        return Folder.open(self.child(name), dir_fd=self.fd)

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


def link_new(source: Folder, name: str, target: Folder, new_name: str) -> None:
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


def same_file(info: os.stat_result | None, other: os.stat_result | None) -> bool:
    """Whether two ``lstat`` results (None: nothing there) are of the same file: the same
    device and inode."""
    return (
        info is not None
        and other is not None
        and (info.st_dev, info.st_ino) == (other.st_dev, other.st_ino)
    )
