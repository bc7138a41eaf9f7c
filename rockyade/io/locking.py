"""One writer per output: an exclusive ``fcntl.flock`` lock, refused at once when taken.

``output_lock(path)`` locks ``.<name>.lock`` beside a file, or ``.rockyade.lock`` inside a
directory, for as long as the ``with`` block runs; the lock file holds the owner's pid
and is removed on release. The kernel drops a flock lock when its process ends, however
it ends, so a killed writer never leaves an output locked. Within one process the lock is
re-entrant (a command that holds its ``--out`` lock may write the file itself).

The lock file never follows a link: it is created with ``O_CREAT | O_EXCL | O_NOFOLLOW``;
one that exists already (left by a process that was killed, whose lock the kernel has
released) is opened with ``O_NOFOLLOW`` and reused only if it is a plain file with one
name. A symbolic link, a hard link to another file, a folder or a device in its place is
refused with a message naming it, and nothing is written to it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import stat
from collections.abc import Iterator
from pathlib import Path

from rockyade.errors import InputError

#: Name of the lock file of a locked directory.
DIR_LOCK_NAME = ".rockyade.lock"

_held: dict[str, tuple[int, int]] = {}  # lock file -> (fd, depth) held by this process


def lock_path(path: str | os.PathLike[str]) -> Path:
    """The lock file of ``path`` (a directory's is inside it)."""
    p = Path(path)
    if p.is_dir():
        return p / DIR_LOCK_NAME
    return p.parent / f".{p.name}.lock"


@contextlib.contextmanager
def output_lock(path: str | os.PathLike[str], field: str = "out") -> Iterator[Path]:
    """Hold the exclusive lock of an output file or directory.

    Parameters
    ----------
    path
        The output (file or existing directory).
    field
        Option or field named in the error when another process holds the lock.

    Raises
    ------
    InputError
        Another process is writing the same output.
    """
    lock = lock_path(path)
    key = str(lock.parent.resolve() / lock.name)  # the lock file itself, never where a link points
    if key in _held:
        fd, depth = _held[key]
        _held[key] = (fd, depth + 1)
        try:
            yield lock
        finally:
            fd, depth = _held[key]
            _held[key] = (fd, depth - 1)
        return
    fd = _acquire(lock, field, path)
    _held[key] = (fd, 1)
    try:
        yield lock
    finally:
        _held.pop(key, None)
        with contextlib.suppress(OSError):
            os.unlink(lock)
        os.close(fd)


def _acquire(lock: Path, field: str, target: str | os.PathLike[str]) -> int:
    lock.parent.mkdir(parents=True, exist_ok=True)
    for _ in range(100):
        fd = _open_lock_file(lock, field)
        if fd is None:
            continue  # the file went away between our two opens: try again
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            owner = _read_owner(fd)
            os.close(fd)
            if exc.errno in (errno.EAGAIN, errno.EACCES):
                who = f" (pid {owner})" if owner else ""
                raise InputError(
                    field,
                    f"{target} is being written by another rockyade process{who}; "
                    "wait for it to finish or choose another output",
                ) from None
            raise
        try:
            same = os.fstat(fd).st_ino == os.lstat(lock).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # the previous owner removed the file between our open and our lock
            os.close(fd)
            continue
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        return fd
    raise InputError(field, f"could not lock {target}")


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def _open_lock_file(lock: Path, field: str) -> int | None:
    """A descriptor of the lock file, created exclusively or, when it exists, opened without
    following a link and checked to be a plain file with one name; None if it vanished
    between the two opens. InputError for anything else in its place."""
    try:
        return os.open(lock, os.O_RDWR | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o644)
    except FileExistsError:
        pass
    try:
        # O_NONBLOCK: a FIFO put in its place must not hang the open
        fd = os.open(lock, os.O_RDWR | _NOFOLLOW | _CLOEXEC | os.O_NONBLOCK)
    except FileNotFoundError:
        return None
    except OSError as exc:
        if exc.errno == errno.ELOOP or os.path.islink(lock):
            raise InputError(field, _not_a_lock(lock, "a symbolic link")) from None
        if exc.errno == errno.EISDIR:
            raise InputError(field, _not_a_lock(lock, "a folder")) from None
        raise
    info = os.fstat(fd)
    what = None
    if not stat.S_ISREG(info.st_mode):
        what = "not a plain file"
    elif info.st_nlink != 1:
        what = f"a file with {info.st_nlink} names (a hard link)"
    if what is not None:
        os.close(fd)
        raise InputError(field, _not_a_lock(lock, what))
    os.set_blocking(fd, True)
    return fd


def _not_a_lock(lock: Path, what: str) -> str:
    return (
        f"the lock file {lock} is {what}: rockyade writes only a lock file it created, never through a link; "
        "remove it (nothing was written)"
    )


def _read_owner(fd: int) -> str:
    try:
        return os.pread(fd, 32, 0).decode("ascii", "replace").strip()
    except OSError:
        return ""


__all__ = ["DIR_LOCK_NAME", "lock_path", "output_lock"]
