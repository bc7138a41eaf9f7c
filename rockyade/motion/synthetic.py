"""Spectrum-compatible synthetic accelerograms (the paper's Section 3.3 suite and others).

Each record is generated on its own, so record i of a suite is reproducible alone:

1. random phases from ``numpy.random.SeedSequence(seed, spawn_key=(i,))``;
2. a stationary Gaussian process whose one-sided power spectral density G(w) follows the
   target spectrum through Vanmarcke's relation (as in SIMQKE, Gasparini & Vanmarcke
   1976): G(w_i) = 4 xi / (pi w_i - 4 xi w_{i-1}) (Sa(w_i)^2 / r_i^2 - sum_{k<i} G(w_k) dw),
   with the peak factor r of Vanmarcke (1976) for a response of duration T_s (median,
   p = 0.5) and the time-dependent damping xi / (1 - exp(-2 xi w T_s));
3. modulated by an envelope (trapezoidal, or Jennings et al.: (t/t1)^2, 1, exp(-c t));
4. corrected iteratively in the frequency domain: the Fourier amplitudes are multiplied by
   the ratio target / computed 5 % spectrum (interpolated in log frequency) until every
   period of the matching range is within ``tolerance`` (or ``max_iterations``);
5. baseline-corrected (zero final velocity and displacement) at each iteration and at the
   end.

Records are cached on disk (``$ROCKYADE_CACHE``, default ``~/.cache/rockyade``) under a hash
of all settings, ``GENERATOR_VERSION`` and the source code of the modules that make a record
(:func:`generator_fingerprint`): a change of any of them (the exact spectra of version 2
changed the matching, hence every record) can never reuse records of another version.

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
import functools
import hashlib
import io
import json
import math
import os
import stat
import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.processing import baseline_correct, integrate
from rockyade.motion.record_text import Record, RecordError, record_problem
from rockyade.motion.spectra import response_spectrum

GENERATOR_VERSION = 2
#: The modules whose code decides a record's samples (their bytes enter the cache key).
GENERATOR_MODULES = ("synthetic", "spectra", "processing", "ec8")
#: The initial PSD is built for periods up to this, s (longer ones start empty).
PSD_MAX_PERIOD_S = 10.0
ENVELOPES = ("trapezoidal", "jennings")
#: Largest synthetic-record cache file read, bytes (a 20 s record at 0.01 s takes 33 kB).
MAX_CACHE_BYTES = 64 * 1024 * 1024
#: The arrays of a cache file, no more, no fewer.
CACHE_ARRAYS = frozenset({"t_s", "accel_m_s2", "meta", "sha256"})


@dataclass(frozen=True)
class Envelope:
    """Time modulation: rise, strong-motion (stationary) and decay durations, s."""

    kind: str = "jennings"
    rise_s: float = 2.0
    strong_s: float = 10.0
    decay_s: float = 8.0

    def __post_init__(self) -> None:
        if self.kind not in ENVELOPES:
            raise InputError("envelope", f"must be one of {', '.join(ENVELOPES)}, got {self.kind!r}")
        for name in ("rise_s", "strong_s", "decay_s"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value > 0 and math.isfinite(value)):
                raise InputError(f"envelope.{name}", f"must be a number > 0 s, got {value!r}")

    @property
    def duration_s(self) -> float:
        """Total duration, s."""
        return self.rise_s + self.strong_s + self.decay_s

    def __call__(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        t1 = self.rise_s
        t2 = t1 + self.strong_s
        w = np.ones_like(t)
        if self.kind == "trapezoidal":
            w = np.where(t < t1, t / t1, w)
            w = np.where(t > t2, np.clip(1.0 - (t - t2) / self.decay_s, 0.0, 1.0), w)
        else:
            w = np.where(t < t1, (t / t1) ** 2, w)
            c = -math.log(0.05) / self.decay_s  # down to 5 % at the end
            w = np.where(t > t2, np.exp(-c * (t - t2)), w)
        return w


@dataclass(frozen=True)
class SuiteSpec:
    """Settings of a synthetic suite.

    Attributes
    ----------
    target
        Target elastic spectrum (5 % damped).
    count
        Number of records.
    seed
        Seed of the suite; record i uses SeedSequence(seed, spawn_key=(i,)).
    envelope
        Time modulation.
    dt_s
        Sampling interval, s.
    match_periods_s
        (min, max) periods over which the spectrum is matched, s.
    tolerance
        Accepted relative misfit at every matched period.
    max_iterations
        Frequency-domain corrections at most.
    name
        Name of the suite.
    """

    target: ElasticSpectrum
    count: int = 30
    seed: int = 2007
    envelope: Envelope = field(default_factory=Envelope)
    dt_s: float = 0.01
    match_periods_s: tuple[float, float] = (0.05, 3.0)
    tolerance: float = 0.05
    max_iterations: int = 25
    name: str = "suite"

    def __post_init__(self) -> None:
        if not (isinstance(self.count, int) and 1 <= self.count <= 10_000):
            raise InputError("count", f"must be an integer in [1, 10000], got {self.count!r}")
        if not (isinstance(self.seed, int) and self.seed >= 0):
            raise InputError("seed", f"must be an integer >= 0, got {self.seed!r}")
        if not 0 < self.dt_s <= 0.05:
            raise InputError("dt_s", f"must be in (0, 0.05] s, got {self.dt_s!r}")

    def as_dict(self) -> dict[str, object]:
        """JSON-ready settings (written as ``suite.json``)."""
        d = asdict(self)
        d["target"] = self.target.as_dict()
        d["generator_version"] = GENERATOR_VERSION
        d["generator_code"] = generator_fingerprint()
        return d

    @property
    def key(self) -> str:
        """Hash of everything that determines the records (computed once per suite and
        generator code)."""
        return _suite_key(self, GENERATOR_VERSION, generator_fingerprint())

    @property
    def periods_s(self) -> NDArray[np.float64]:
        """Matching periods, s."""
        lo, hi = self.match_periods_s
        return np.geomspace(lo, hi, 70)


@functools.lru_cache(maxsize=64)
def _suite_key(spec: SuiteSpec, version: int, fingerprint: str) -> str:
    """:attr:`SuiteSpec.key` of a suite for this generator version and code."""
    text = json.dumps(spec.as_dict(), sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@functools.cache
def paper_suite() -> SuiteSpec:
    """The paper's 30 records: EC8 Type 2, ground D, ag S = 2.8 m/s^2 (Section 3.3); one
    (frozen) object per process.

    Not in the paper and chosen here: 20 s records (2 s rise, 10 s stationary as EC8
    3.2.3.1.2 asks, 8 s decay, Jennings envelope), dt = 0.01 s, seed 2007.
    """
    return SuiteSpec(ElasticSpectrum.ec8(2, "D", ag_s_m_s2=2.8), count=30, seed=2007, name="paper")


# ---------------------------------------------------------------------- generation


def peak_factor(omega: np.ndarray, damping: float, duration_s: float, p: float = 0.5) -> np.ndarray:
    """Vanmarcke's peak factor of an SDOF response of duration ``duration_s`` (median)."""
    xi_s = damping / (1.0 - np.exp(-2.0 * damping * omega * duration_s))
    delta = np.sqrt(np.clip(4.0 * xi_s / np.pi, 1e-6, 1.0))
    n = omega * duration_s / (2.0 * np.pi) / (-math.log(p))
    n = np.maximum(n, 1.01)
    inner = 2.0 * n * (1.0 - np.exp(-(delta**1.2) * np.sqrt(np.pi * np.log(2.0 * n))))
    # the asymptotic formula fails for oscillators slower than the motion lasts; a peak is
    # never below the rms (r >= 1)
    return np.maximum(np.sqrt(2.0 * np.log(np.maximum(inner, 1.0 + 1e-9))), 1.0)


def vanmarcke_psd(spec: SuiteSpec, omega: np.ndarray) -> np.ndarray:
    """One-sided PSD of ground acceleration from the target spectrum, (m/s^2)^2 / (rad/s)."""
    xi = spec.target.damping
    with np.errstate(divide="ignore"):
        periods = np.where(omega > 0, 2.0 * np.pi / np.maximum(omega, 1e-12), np.inf)
    sa = spec.target.psa(np.minimum(periods, 1e6))
    r = peak_factor(np.maximum(omega, 1e-6), xi, spec.envelope.strong_s)
    G = np.zeros_like(omega)
    d_omega = omega[1] - omega[0]
    cumulative = 0.0
    first = max(1, int(np.searchsorted(omega, 2.0 * np.pi / PSD_MAX_PERIOD_S)))
    for i in range(first, omega.size):
        denom = omega[i] * np.pi - 4.0 * xi * omega[i - 1]
        value = 4.0 * xi / denom * (sa[i] ** 2 / r[i] ** 2 - cumulative) if denom > 0 else 0.0
        G[i] = max(value, 0.0)
        cumulative += G[i] * d_omega
    return G


def generate_record(spec: SuiteSpec, index: int) -> Record:
    """Record ``index`` (1-based) of the suite, reproducible alone."""
    if not (isinstance(index, int) and 1 <= index <= spec.count):
        raise InputError("record", f"must be an integer in [1, {spec.count}], got {index!r}")
    rng = np.random.default_rng(np.random.SeedSequence(spec.seed, spawn_key=(index,)))
    n = round(spec.envelope.duration_s / spec.dt_s) + 1
    nfft = 1 << math.ceil(math.log2(2 * n))  # zero padding: no wrap-around
    t = np.arange(n, dtype=float) * spec.dt_s
    freq_hz = np.fft.rfftfreq(nfft, spec.dt_s)
    omega = 2.0 * np.pi * freq_hz
    G = vanmarcke_psd(spec, omega)
    d_omega = omega[1] - omega[0]
    phases = rng.uniform(0.0, 2.0 * np.pi, omega.size)
    coeffs = 0.5 * nfft * np.sqrt(2.0 * G * d_omega) * np.exp(1j * phases)
    coeffs[0] = 0.0
    stationary = np.fft.irfft(coeffs, nfft)[:n]
    accel = stationary * spec.envelope(t)
    periods = spec.periods_s
    target = spec.target.psa(periods)
    freqs_match = 1.0 / periods[::-1]
    iterations = 0
    misfit = math.inf
    while iterations < spec.max_iterations:
        iterations += 1
        accel = baseline_correct(t, accel, detrend=False)
        _, psa = response_spectrum(accel, spec.dt_s, periods, spec.target.damping)
        ratio = target / psa
        misfit = float(np.max(np.abs(ratio - 1.0)))
        if misfit <= spec.tolerance:
            break
        # multiply the Fourier amplitudes by the ratio, interpolated in log frequency;
        # outside the matching range the edge ratios are held
        log_ratio = np.interp(
            np.log(np.maximum(freq_hz, 1e-9)),
            np.log(freqs_match),
            np.log(ratio[::-1]),
            left=np.log(ratio[-1]),
            right=np.log(ratio[0]),
        )
        spectrum = np.fft.rfft(accel, nfft) * np.exp(log_ratio)
        accel = np.fft.irfft(spectrum, nfft)[:n]
    accel = baseline_correct(t, accel, detrend=False)
    v, d = integrate(t, accel)
    _, psa = response_spectrum(accel, spec.dt_s, periods, spec.target.damping)
    return Record(
        t,
        accel,
        "m/s2",
        f"{spec.name} record {index:02d}",
        f"synthetic {spec.target.label}, record {index} of {spec.count}, seed {spec.seed}",
        {
            "format": "synthetic",
            "index": index,
            "iterations": iterations,
            "misfit": float(np.max(np.abs(target / psa - 1.0))),
            "final_velocity_m_s": float(v[-1]),
            "final_displacement_m": float(d[-1]),
        },
    )


# ---------------------------------------------------------------------- cache


@functools.cache
def generator_fingerprint() -> str:
    """SHA-256 (16 hex digits) of the source of :data:`GENERATOR_MODULES`, read from the
    installed package: records cached by other code are never taken for this code's."""
    digest = hashlib.sha256()
    package = Path(__file__).parent
    for name in GENERATOR_MODULES:
        digest.update((package / f"{name}.py").read_bytes())
    return digest.hexdigest()[:16]


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


# ---------------------------------------------------------------------- report


def compatibility_report(
    records: list[Record], target: ElasticSpectrum, period_range_s: tuple[float, float] = (0.05, 2.0)
) -> dict[str, object]:
    """Mean 5 % spectrum against the target, PGAs and durations of a suite.

    Returns a dictionary with ``periods_s``, ``target_m_s2``, ``mean_psa_m_s2``,
    ``ratio`` (mean / target), ``ratio_min``, ``ratio_max`` (over the period range),
    ``mean_pga_m_s2``, ``ag_s_m_s2``, ``pga_ratio``, ``records`` (name, PGA, duration,
    final velocity and displacement, own misfit) and ``compatible`` (EC8 3.2.3.1.2: mean
    >= 0.9 target over the range, mean PGA >= ag S).
    """
    lo, hi = period_range_s
    periods = np.geomspace(lo, hi, 60)
    spectra = []
    rows = []
    for rec in records:
        _, psa = response_spectrum(rec.accel_m_s2, rec.dt_s, periods, target.damping)
        spectra.append(psa)
        v, d = integrate(rec.t_s, rec.accel_m_s2)
        rows.append(
            {
                "record": rec.source,
                "pga_m_s2": rec.pga_m_s2,
                "duration_s": rec.duration_s,
                "final_velocity_m_s": float(v[-1]),
                "final_displacement_m": float(d[-1]),
                "ratio_min": float(np.min(psa / target.psa(periods))),
                "ratio_max": float(np.max(psa / target.psa(periods))),
            }
        )
    mean = np.mean(spectra, axis=0)
    ratio = mean / target.psa(periods)
    mean_pga = float(np.mean([r["pga_m_s2"] for r in rows]))
    return {
        "periods_s": periods.tolist(),
        "target_m_s2": target.psa(periods).tolist(),
        "mean_psa_m_s2": mean.tolist(),
        "ratio": ratio.tolist(),
        "ratio_min": float(ratio.min()),
        "ratio_max": float(ratio.max()),
        "period_range_s": [lo, hi],
        "mean_pga_m_s2": mean_pga,
        "ag_s_m_s2": target.ag_s_m_s2,
        "pga_ratio": mean_pga / target.ag_s_m_s2,
        "records": rows,
        "compatible": bool(ratio.min() >= 0.9 and mean_pga >= target.ag_s_m_s2),
    }
