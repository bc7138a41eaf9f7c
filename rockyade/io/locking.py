"""One writer per output: an exclusive ``fcntl.flock`` lock, refused at once when taken.

``output_lock(path)`` locks ``.<name>.lock`` beside a file, or ``.rockyade.lock`` inside a
directory, for as long as the ``with`` block runs; the lock file holds the owner's pid
and is removed on release. The kernel drops a flock lock when its process ends, however
it ends, so a killed writer never leaves an output locked. Within one process the lock is
re-entrant (a command that holds its ``--out`` lock may write the file itself).

A lock covers the folder it is in: ``output_lock`` on a file or folder inside a locked
folder is refused while another process holds that folder's lock (``rockyade run --out``
inside a running batch's output), and otherwise holds a shared lock on every
``.rockyade.lock`` above it for as long as it writes, so that a batch cannot start over it.
A process that writes inside a folder on behalf of the process holding its lock (a batch's
worker, on this machine or on a Dask worker) says so with :func:`writing_for` and the
lock's token (:func:`lock_token`).

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
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

from rockyade.errors import InputError

#: Name of the lock file of a locked directory.
DIR_LOCK_NAME = ".rockyade.lock"

_held: dict[str, tuple[int, int]] = {}  # lock file -> (fd, depth) held by this process
_tokens: dict[str, str] = {}  # lock file held by this process -> its token
_granted: dict[str, str] = {}  # folder lock file -> token of the holder this process writes for


def lock_path(path: str | os.PathLike[str]) -> Path:
    """The lock file of ``path`` (a directory's is inside it)."""
    p = Path(path)
    if p.is_dir():
        return p / DIR_LOCK_NAME
    return p.parent / f".{p.name}.lock"


def _key(lock: Path) -> str:
    """The lock file's name as held (its folder resolved, never where a link points)."""
    return str(lock.parent.resolve() / lock.name)


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
        Another process is writing the same output, or holds the lock of a folder above it.
    """
    lock = lock_path(path)
    key = _key(lock)
    if key in _held:
        fd, depth = _held[key]
        _held[key] = (fd, depth + 1)
        try:
            yield lock
        finally:
            fd, depth = _held[key]
            _held[key] = (fd, depth - 1)
        return
    lock.parent.mkdir(parents=True, exist_ok=True)
    above = _lock_above(lock, field, path)
    try:
        fd, token = _acquire(lock, field, path)
    except BaseException:
        _release_all(above)
        raise
    _held[key] = (fd, 1)
    _tokens[key] = token
    try:
        yield lock
    finally:
        _held.pop(key, None)
        _tokens.pop(key, None)
        with contextlib.suppress(OSError):
            os.unlink(lock)
        os.close(fd)
        _release_all(above)


def lock_token(path: str | os.PathLike[str]) -> str:
    """The token of the lock this process holds on ``path`` (for :func:`writing_for`).

    Raises
    ------
    KeyError
        This process does not hold that lock.
    """
    return _tokens[_key(lock_path(path))]


@contextlib.contextmanager
def writing_for(folder: str | os.PathLike[str], token: str) -> Iterator[None]:
    """Write inside ``folder`` on behalf of the process holding its lock with ``token``
    (a batch's worker): the folder's lock then does not refuse this process's outputs."""
    key = _key(Path(folder) / DIR_LOCK_NAME)
    previous = _granted.get(key)
    _granted[key] = token
    try:
        yield
    finally:
        if previous is None:
            _granted.pop(key, None)
        else:
            _granted[key] = previous


def _lock_above(lock: Path, field: str, target: str | os.PathLike[str]) -> list[int]:
    """Shared locks on the folder locks (``.rockyade.lock``) above ``lock``, held while it is;
    InputError naming the folder when another process writes it. A folder lock this process
    holds, or writes for (:func:`writing_for`), is passed over."""
    folder = lock.parent.resolve()
    if lock.name == DIR_LOCK_NAME:
        folder = folder.parent
    fds: list[int] = []
    try:
        for directory in (folder, *folder.parents):
            candidate = directory / DIR_LOCK_NAME
            key = str(candidate)
            if key in _held:
                continue
            fd = _open_folder_lock(candidate)
            if fd is None:
                continue
            try:
                fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
            except OSError as exc:
                owner = _read_owner(fd)
                os.close(fd)
                if exc.errno not in (errno.EAGAIN, errno.EACCES):
                    raise
                pid, _, token = owner.partition(" ")
                if token and _granted.get(key) == token:
                    continue
                who = f" (pid {pid})" if pid else ""
                raise InputError(
                    field,
                    f"{target} is inside {directory}, which another rockyade process{who} is writing (a batch's "
                    "output folder); wait for it to finish or choose an output outside it",
                ) from None
            fds.append(fd)
    except BaseException:
        _release_all(fds)
        raise
    return fds


def _open_folder_lock(candidate: Path) -> int | None:
    """A read-only descriptor of a folder's lock file, if it is there and a plain file
    (anything else, a link included, is not a rockyade lock: passed over, never opened)."""
    try:
        fd = os.open(candidate, os.O_RDONLY | _NOFOLLOW | _CLOEXEC | os.O_NONBLOCK)
    except OSError:
        return None
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        return None
    return fd


def _release_all(fds: list[int]) -> None:
    for fd in fds:
        with contextlib.suppress(OSError):
            os.close(fd)


def _acquire(lock: Path, field: str, target: str | os.PathLike[str]) -> tuple[int, str]:
    """The descriptor of the lock file, locked, holding ``<pid> <token>``; and the token."""
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
                pid = owner.partition(" ")[0]
                who = f" (pid {pid})" if pid else ""
                raise InputError(
                    field,
                    f"{target} is being written by another rockyade process{who}, or something inside it is; "
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
        token = secrets.token_hex(8)
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()} {token}\n".encode())
        return fd, token
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


__all__ = ["DIR_LOCK_NAME", "lock_path", "lock_token", "output_lock", "writing_for"]
