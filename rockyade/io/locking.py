"""One writer per output: an exclusive ``fcntl.flock`` lock, refused at once when taken.

``output_lock(path)`` locks ``.<name>.lock`` beside a file, or ``.rockyade.lock`` inside a
directory, for as long as the ``with`` block runs; the lock file holds the owner's pid
and is removed on release. The kernel drops a flock lock when its process ends, however
it ends, so a killed writer never leaves an output locked. Within one process the lock is
re-entrant (a command that holds its ``--out`` lock may write the file itself).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
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
    key = str(lock.resolve())
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
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
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
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if not same:  # the previous owner removed the file between our open and our lock
            os.close(fd)
            continue
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        return fd
    raise InputError(field, f"could not lock {target}")


def _read_owner(fd: int) -> str:
    try:
        return os.pread(fd, 32, 0).decode("ascii", "replace").strip()
    except OSError:
        return ""


__all__ = ["DIR_LOCK_NAME", "lock_path", "output_lock"]
