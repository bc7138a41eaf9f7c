"""Spectrum-compatible synthetic accelerograms (the paper's Section 3.3 suite and others): the
generator.

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

A suite's :attr:`SuiteSpec.key` hashes all its settings, ``GENERATOR_VERSION`` and the source
code of the modules that make a record (:func:`generator_fingerprint`): records are cached on
disk under it (:mod:`rockyade.motion.suite_cache`, which studies read them through:
:func:`~rockyade.motion.suite_cache.suite_record`), so a change of any of them (the exact
spectra of version 2 changed the matching, hence every record) can never reuse records of
another version. :func:`compatibility_report` compares a suite with its target spectrum
(EC8 3.2.3.1.2).
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.processing import baseline_correct, integrate
from rockyade.motion.record_text import Record
from rockyade.motion.spectra import response_spectrum

GENERATOR_VERSION = 2
#: The modules whose code decides a record's samples (their bytes enter the cache key).
GENERATOR_MODULES = ("synthetic", "spectra", "processing", "ec8")
#: The initial PSD is built for periods up to this, s (longer ones start empty).
PSD_MAX_PERIOD_S = 10.0
ENVELOPES = ("trapezoidal", "jennings")


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


@functools.cache
def generator_fingerprint() -> str:
    """SHA-256 (16 hex digits) of the source of :data:`GENERATOR_MODULES`, read from the
    installed package: records cached by other code are never taken for this code's."""
    digest = hashlib.sha256()
    package = Path(__file__).parent
    for name in GENERATOR_MODULES:
        digest.update((package / f"{name}.py").read_bytes())
    return digest.hexdigest()[:16]


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
