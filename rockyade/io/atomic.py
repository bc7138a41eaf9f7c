"""Atomic file writing: a failed or killed run never leaves a half-written file that looks
complete, and never leaves its temporary files behind when it fails.

Every writer goes to a temporary file ``.<name>.<random>.tmp`` in the destination
directory, flushes and fsyncs it, gives it the permissions the umask allows (as ``open``
would: ``0o666 & ~umask``), then renames it over the destination (``os.replace`` is atomic
on POSIX filesystems, and replaces a link at the destination rather than writing where it
points) and fsyncs the directory. The temporary file is created with
``O_CREAT | O_EXCL | O_NOFOLLOW`` under a random name: a name that exists already (a file,
or a link an attacker planted) is never opened, and another random name is tried. On
any failure (a full disk, Ctrl-C) the temporary file is removed. A process killed with
SIGKILL may leave one behind: :func:`remove_stale_temporaries` clears a directory that
the caller holds the lock of (:mod:`rockyade.io.locking`).

A writer that opens the file itself and picks its format by the file's suffix (matplotlib's
movie writers) gets a temporary path that ends in the destination's suffix,
``.<name>.<random>.tmp<suffix>`` (:func:`atomic_path`), renamed in the same way.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from rockyade.io.strict_json import json_text

#: Suffix of every temporary file written here.
TEMP_SUFFIX = ".tmp"
#: Random names tried for a temporary file before giving up (each taken one is skipped).
TEMP_ATTEMPTS = 100
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def _random_part() -> str:
    """The random part of a temporary file's name (16 hex digits)."""
    return secrets.token_hex(8)


def create_temporary(dest: Path, suffix: str = "") -> tuple[int, Path]:
    """Create ``.<name>.<random>.tmp<suffix>`` beside ``dest`` exclusively, never through a link.

    Returns the open descriptor (read-write, mode 0600 until the writer sets its own) and
    the path. A name that exists, whatever it is, is skipped for another random one.
    """
    flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC
    for _ in range(TEMP_ATTEMPTS):
        tmp = dest.parent / f".{dest.name}.{_random_part()}{TEMP_SUFFIX}{suffix}"
        try:
            return os.open(tmp, flags, 0o600), tmp
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, f"no free temporary name after {TEMP_ATTEMPTS} tries", str(dest.parent))


def current_umask() -> int:
    """The process umask, read without changing it (Linux ``/proc``), else by set-and-restore."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def file_mode() -> int:
    """Permissions of a new file under the current umask (``0o666 & ~umask``)."""
    return 0o666 & ~current_umask()


@contextlib.contextmanager
def staged_file(path: str | os.PathLike[str], mode: str = "w", durable: bool = True) -> Iterator[tuple[IO[Any], Path]]:
    """A complete, fsynced temporary file beside ``path`` that the caller renames itself
    (``durable=False``: not fsynced).

    Yields ``(file, temporary_path)``; on success the file is closed with the umask's
    permissions and left in place for the caller to ``os.replace``; on failure it is removed.
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb', not {mode!r}")
    dest = Path(path)
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = create_temporary(dest)
    try:
        binary = "b" in mode
        with os.fdopen(fd, mode, encoding=None if binary else "utf-8", newline=None if binary else "") as fh:
            yield fh, tmp
            fh.flush()
            os.fchmod(fh.fileno(), file_mode())
            if durable:
                os.fsync(fh.fileno())
    except OSError as exc:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        if exc.filename is None:  # a write on a full disk names no file: the message names it
            exc.filename = str(dest)
        raise
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w", durable: bool = True) -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path``; rename it onto ``path`` only on success.

    Parameters
    ----------
    path
        Destination file.
    mode
        ``"w"`` (text, UTF-8) or ``"wb"`` (binary).
    durable
        Fsync the file and its folder (False: still atomic for readers and for a killed
        process, but a power cut may leave the old file or an empty one).
    """
    dest = Path(path)
    with staged_file(dest, mode, durable) as (fh, tmp):
        yield fh
    _rename_into_place(tmp, dest, durable)


def _rename_into_place(tmp: Path, dest: Path, durable: bool) -> None:
    """Rename the complete temporary ``tmp`` onto ``dest`` (and make it durable); on failure
    remove ``tmp``."""
    try:
        os.replace(tmp, dest)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    if durable:
        fsync_dir(dest.parent)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], durable: bool = True) -> Iterator[Path]:
    """A temporary path beside ``path``, ending in its suffix, for a writer that opens the file
    itself and picks the format by the suffix; renamed onto ``path`` when the block ends
    without an error, removed otherwise (``durable``: see :func:`atomic_open`).

    The file is created empty (exclusively, never through a link) before the writer opens it.
    """
    dest = Path(path)
    dest.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = create_temporary(dest, dest.suffix)
    os.close(fd)
    try:
        yield tmp
        fd = os.open(tmp, os.O_RDONLY | _NOFOLLOW | _CLOEXEC)
        try:
            os.fchmod(fd, file_mode())
            if durable:
                os.fsync(fd)
        finally:
            os.close(fd)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    _rename_into_place(tmp, dest, durable)


def fsync_dir(directory: str | os.PathLike[str]) -> None:
    """Make renames in ``directory`` durable (best effort: some filesystems refuse)."""
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def remove_stale_temporaries(directory: str | os.PathLike[str]) -> list[Path]:
    """Remove the temporary files a killed writer left in ``directory``; return them.

    Only call this while holding the directory's lock (no other writer is active there).
    """
    removed = []
    folder = Path(directory)
    for path in sorted({*folder.glob(f".*{TEMP_SUFFIX}"), *folder.glob(f".*{TEMP_SUFFIX}.*")}):
        with contextlib.suppress(OSError):  # gone already, or a folder: left alone
            if path.is_symlink() or path.is_file():
                path.unlink()  # a link is removed itself, never what it points to
                removed.append(path)
    return removed


def write_text(path: str | os.PathLike[str], text: str, durable: bool = True) -> None:
    """Write ``text`` to ``path`` atomically (``durable``: see :func:`atomic_open`)."""
    with atomic_open(path, "w", durable) as fh:
        fh.write(text)


def write_json(path: str | os.PathLike[str], data: Any, durable: bool = True) -> None:
    """Write ``data`` as indented strict JSON (:func:`rockyade.io.strict_json.json_text`: NaN and
    infinity as null) to ``path`` atomically (``durable``: see :func:`atomic_open`)."""
    write_text(path, json_text(data) + "\n", durable)
