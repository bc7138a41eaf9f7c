"""The on-disk cache of synthetic records: record i of a suite from its file, or generated
(:func:`rockyade.motion.synthetic.generate_record`) and written there.

Records are cached (``$ROCKYADE_CACHE``, default ``~/.cache/rockyade``) under their suite's
key (:attr:`rockyade.motion.synthetic.SuiteSpec.key`: every setting, the generator's version
and its code), so that records of other settings or another generator are never reused.

A cache file is trusted only as far as it checks out (:func:`load_cached_record`): a plain
file (never through a link) of at most :data:`MAX_CACHE_BYTES`, an ``.npz`` of exactly the
arrays written, float64 samples of the suite's length and sampling, the SHA-256 of its
content as written, the suite's key and the record's index in its metadata, and the bounds
every read record passes (:func:`rockyade.motion.record_text.record_problem`). Anything else (a
truncated, emptied, rescaled or replaced file) is regenerated and rewritten atomically (two
processes doing so at once each rename a complete file into place); a cache that cannot be
written (a folder that is a file, a read-only disk) gives the generated record with one
warning on stderr.
"""

from __future__ import annotations

import collections
import errno
import hashlib
import io
import json
import os
import stat
import sys
from pathlib import Path

import numpy as np

from rockyade.io.atomic import atomic_open
from rockyade.motion.record_text import Record, RecordError, record_problem
from rockyade.motion.synthetic import SuiteSpec, generate_record

#: Largest synthetic-record cache file read, bytes (a 20 s record at 0.01 s takes 33 kB).
MAX_CACHE_BYTES = 64 * 1024 * 1024
#: The arrays of a cache file, no more, no fewer.
CACHE_ARRAYS = frozenset({"t_s", "accel_m_s2", "meta", "sha256"})


def cache_dir() -> Path:
    """Where generated records are cached."""
    return Path(os.environ.get("ROCKYADE_CACHE", Path.home() / ".cache" / "rockyade"))


def cache_path(spec: SuiteSpec, index: int) -> Path:
    """The cache file of record ``index`` of a suite."""
    return cache_dir() / "suites" / spec.key / f"record_{index:02d}.npz"


def suite_record(spec: SuiteSpec, index: int) -> Record:
    """Record ``index`` of a suite, from the cache or generated (then cached).

    A damaged cache file is regenerated with a note on stderr; a cache that cannot be
    written gives the generated record with a warning (module docstring).
    """
    path = cache_path(spec, index)
    try:
        return _held_record(path, spec, index)
    except FileNotFoundError:
        pass
    except CacheDamagedError as exc:
        _note_once(path, f"{path}: {exc}: regenerated")
    record = generate_record(spec, index)
    trouble = record_problem(record.t_s, record.accel_m_s2)
    if trouble:
        raise RecordError(record.source, None, f"the generated record is out of bounds: {trouble}")
    try:
        _write_cached_record(path, spec, index, record)
    except OSError as exc:
        _warn_once(
            cache_dir(),
            f"cannot write the synthetic-record cache in {path.parent} ({exc.strerror or exc}): records are "
            "generated each time (set ROCKYADE_CACHE to a writable folder)",
        )
    return record


#: Cache files read in this process and held in memory (the most recently used), at most.
HELD_RECORDS = 256
_HELD: collections.OrderedDict[tuple[str, str, int, int, int, int, int], Record] = collections.OrderedDict()


def _held_record(path: Path, spec: SuiteSpec, index: int) -> Record:
    """:func:`load_cached_record`, read once per process: a record read (and checked) before
    is given again while its file is the same one (path, inode, size, modification and change
    times, read without following a link); the :data:`HELD_RECORDS` most recently used are
    held. The held arrays are read-only (a batch reads each record once per run)."""
    try:
        info = os.stat(path, follow_symlinks=False)
    except FileNotFoundError:
        raise
    except OSError:  # load_cached_record says what is wrong
        return load_cached_record(path, spec, index)
    key = (str(path), spec.key, index, info.st_ino, info.st_size, info.st_mtime_ns, info.st_ctime_ns)
    held = _HELD.get(key)
    if held is not None and stat.S_ISREG(info.st_mode):
        _HELD.move_to_end(key)
        return held
    record = load_cached_record(path, spec, index)
    record.t_s.flags.writeable = False
    record.accel_m_s2.flags.writeable = False
    _HELD[key] = record
    while len(_HELD) > HELD_RECORDS:
        _HELD.popitem(last=False)
    return record


class CacheDamagedError(Exception):
    """A cache file that does not check out (the message says how)."""


def _digest(t_s: np.ndarray, accel_m_s2: np.ndarray, meta: str) -> str:
    """SHA-256 of a cache file's content: both arrays (little-endian float64) and the metadata."""
    digest = hashlib.sha256(b"rockyade synthetic record\0")
    digest.update(np.ascontiguousarray(t_s, dtype="<f8").tobytes())
    digest.update(np.ascontiguousarray(accel_m_s2, dtype="<f8").tobytes())
    digest.update(meta.encode())
    return digest.hexdigest()


def _write_cached_record(path: Path, spec: SuiteSpec, index: int, record: Record) -> None:
    meta = json.dumps(
        {"key": spec.key, "index": index, "source": record.source, "title": record.title, "extra": record.extra},
        sort_keys=True,
    )
    sha = _digest(record.t_s, record.accel_m_s2, meta)
    with atomic_open(path, "wb") as fh:
        np.savez(fh, t_s=record.t_s, accel_m_s2=record.accel_m_s2, meta=np.array(meta), sha256=np.array(sha))


def _read_plain_file(path: Path) -> bytes:
    """The bytes of a plain file, opened without following a link; CacheDamagedError otherwise."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0) | os.O_NONBLOCK)
    except FileNotFoundError:
        raise
    except OSError as exc:
        if os.path.islink(path):
            raise CacheDamagedError("a symbolic link, not a cache file") from None
        if exc.errno == errno.ENOTDIR:
            raise CacheDamagedError("a folder on its path is a file") from None
        raise CacheDamagedError(f"cannot be read ({exc.strerror or exc})") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):  # checked on the descriptor: a folder does not even open as a file
        os.close(fd)
        raise CacheDamagedError("a folder, not a cache file" if stat.S_ISDIR(info.st_mode) else "not a plain file")
    with os.fdopen(fd, "rb") as fh:
        if info.st_size > MAX_CACHE_BYTES:
            raise CacheDamagedError(f"{info.st_size} bytes, more than the {MAX_CACHE_BYTES} a cache file may have")
        return fh.read(MAX_CACHE_BYTES + 1)


def load_cached_record(path: Path, spec: SuiteSpec, index: int) -> Record:
    """Record ``index`` of ``spec`` from its cache file, checked (module docstring).

    Raises
    ------
    FileNotFoundError
        No cache file.
    CacheDamagedError
        The file does not check out; the message says how.
    """
    data = _read_plain_file(path)
    try:
        # the bytes are untrusted: any failure to decode them (BadZipFile, EOFError, a
        # ValueError of np.load, a TypeError of a pickled or odd array) means a damaged file
        with np.load(io.BytesIO(data), allow_pickle=False) as archive:
            names = set(archive.files)
            if names != CACHE_ARRAYS:
                raise CacheDamagedError(f"holds the arrays {sorted(names)}, not {sorted(CACHE_ARRAYS)}")
            t, accel = archive["t_s"], archive["accel_m_s2"]
            meta_array, sha_array = archive["meta"], archive["sha256"]
    except CacheDamagedError:
        raise
    except Exception as exc:
        raise CacheDamagedError(f"not a readable .npz ({type(exc).__name__}: {exc})") from None
    if meta_array.shape != () or sha_array.shape != () or meta_array.dtype.kind != "U" or sha_array.dtype.kind != "U":
        raise CacheDamagedError("its metadata or checksum is not a string")
    meta_text, sha = str(meta_array[()]), str(sha_array[()])
    n = round(spec.envelope.duration_s / spec.dt_s) + 1
    for name, array in (("t_s", t), ("accel_m_s2", accel)):
        if array.dtype != np.float64 or array.shape != (n,):
            raise CacheDamagedError(f"{name} is {array.dtype} of shape {array.shape}, not float64 of shape ({n},)")
    if sha != _digest(t, accel, meta_text):
        raise CacheDamagedError("its content does not match its SHA-256 checksum (changed after it was written)")
    try:
        meta = json.loads(meta_text)
        source, title, extra = meta["source"], meta["title"], meta["extra"]
        key, cached_index = meta["key"], meta["index"]
    except (ValueError, KeyError, TypeError) as exc:
        raise CacheDamagedError(f"its metadata is not as written ({type(exc).__name__})") from None
    if (key, cached_index) != (spec.key, index):
        raise CacheDamagedError(
            f"it holds record {cached_index} of suite {key}, not record {index} of suite {spec.key}"
        )
    if not (isinstance(source, str) and isinstance(title, str) and isinstance(extra, dict)):
        raise CacheDamagedError("its metadata is not as written")
    if not np.array_equal(t, np.arange(n) * spec.dt_s):
        raise CacheDamagedError(f"its times are not the suite's sampling (dt = {spec.dt_s:g} s from 0)")
    problem = record_problem(t, accel)
    if problem:
        raise CacheDamagedError(problem)
    return Record(t, accel, "m/s2", source, title, extra)


_WARNED: set[str] = set()


def _warn_once(where: Path, message: str) -> None:
    """One warning line on stderr per cache folder and process."""
    if str(where) not in _WARNED:
        _WARNED.add(str(where))
        print(f"rockyade: warning: {message}", file=sys.stderr)


def _note(message: str) -> None:
    print(f"rockyade: note: {message}", file=sys.stderr)


_NOTED: set[str] = set()


def _note_once(where: Path, message: str) -> None:
    """One note per cache file and process (a cache that cannot be rewritten finds the same
    damaged file at every read)."""
    if str(where) not in _NOTED:
        _NOTED.add(str(where))
        _note(message)


def generate_suite(spec: SuiteSpec) -> list[Record]:
    """All records of a suite (cached)."""
    return [suite_record(spec, i) for i in range(1, spec.count + 1)]
