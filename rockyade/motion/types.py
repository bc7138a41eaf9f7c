"""Scene motion types: harmonic, pulse, record and synthetic (registered in MOTION_TYPES).

The quasi-static types ``gravity-ramp`` and ``pushover`` are in :mod:`rockyade.motion.quasistatic`.

Scene tables (all take ``load_factor``, default 1)::

    [motion]                    # shake-table sine (paper Sections 3.3, 7)
    type = "harmonic"
    amplitude_mm = 6.0
    frequency_hz = 3.3
    cycles = 20                 # stationary cycles (or duration_s: rounded to whole cycles)
    ramp_cycles = 2             # half-cosine ramps up and down
    start_s = 0.0

    [motion]                    # overturning pulses
    type = "pulse"
    shape = "sine"              # sine | cosine | ricker | symmetric | antisymmetric
    amplitude_m_s2 = 3.0        # or amplitude_g
    period_s = 0.5
    cycles = 1
    start_s = 0.0

    [motion]                    # recorded accelerogram
    type = "record"
    file = "records/RSN6.AT2"   # relative to the scene file
    format = "at2"              # at2 | csv | single | esm (default by content)
    units = "g"                 # default: the AT2 header; m/s2 for text files
    dt_s = 0.01                 # one-column files (read as such without format); else must match the file
    baseline = false            # zero final velocity and displacement
    bandpass_hz = [0.1, 25.0]   # optional zero-phase band-pass
    target_pga_m_s2 = 3.0       # optional: scale to this PGA (before load_factor)

    [motion]                    # synthetic, spectrum-compatible (Section 3.3)
    type = "synthetic"
    suite = "paper"             # the paper's EC8 Type 2, ground D suite; or give
    record = 21                 # spectrum_type, ground, ag_s_m_s2 (or ag_m_s2), seed, count
    load_factor = 0.6
"""

from __future__ import annotations

import hashlib
from abc import abstractmethod
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.io.fields import TableReader
from rockyade.motion.analytic import PULSE_SHAPES, Harmonic, Pulse
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.ground import GroundMotion
from rockyade.motion.processing import bandpass, baseline_correct, scale_to_pga
from rockyade.motion.quasistatic import GravityRamp, Pushover
from rockyade.motion.record_text import DT_RANGE_S, MAX_ABS_ACCEL_M_S2, Record, normalise_units
from rockyade.motion.records import FORMATS, count_samples, read_record
from rockyade.motion.spec import MAX_START_S, MOTION_TYPES, MotionSpec
from rockyade.motion.suite_cache import suite_record
from rockyade.motion.synthetic import SuiteSpec, paper_suite


def _load_factor(r: TableReader) -> float:
    return r.number("load_factor", 1.0, lo=0.0, hi=100.0)


class _AnalyticMotion(MotionSpec):
    """A motion of :mod:`rockyade.motion.analytic`, times the spec's ``load_factor``."""

    load_factor: float

    @property
    @abstractmethod
    def analytic(self) -> Harmonic | Pulse:
        """The analytic motion."""

    def ground_motion(self, duration_s: float) -> GroundMotion:
        """The analytic motion's acceleration times ``load_factor``, sampled as it samples itself; m/s^2."""
        return self.analytic.ground_motion(self.load_factor)

    def sample_count(self, duration_s: float) -> int:
        """The analytic motion's samples (:attr:`~rockyade.motion.analytic.Harmonic.sample_count`)."""
        return self.analytic.sample_count


@dataclass(frozen=True)
class HarmonicMotion(_AnalyticMotion):
    """``type = "harmonic"``: see :class:`rockyade.motion.analytic.Harmonic`."""

    type: ClassVar[str] = "harmonic"
    amplitude_mm: float
    frequency_hz: float
    cycles: int
    ramp_cycles: int = 2
    start_s: float = 0.0
    load_factor: float = 1.0

    @property
    def harmonic(self) -> Harmonic:
        """The analytic motion (400 samples per cycle)."""
        return Harmonic(self.amplitude_mm, self.frequency_hz, self.cycles, self.ramp_cycles, self.start_s)

    @property
    def analytic(self) -> Harmonic:
        """:attr:`harmonic`, the motion :class:`_AnalyticMotion` samples."""
        return self.harmonic

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> HarmonicMotion:
        """The motion from its ``[motion]`` table: ``amplitude_mm`` (mm), ``frequency_hz`` (Hz),
        ``cycles`` or ``duration_s``, ``ramp_cycles``, ``start_s``."""
        amplitude = r.number("amplitude_mm", lo=0.0, hi=1000.0, lo_open=True, unit="mm")
        frequency = r.number("frequency_hz", lo=0.0, hi=100.0, lo_open=True, unit="Hz")
        cycles = r.integer("cycles", None, lo=1, hi=100_000)
        duration = r.positive("duration_s", None, unit="s")
        if (cycles is None) == (duration is None):
            raise r.error("cycles", "give exactly one of cycles (stationary cycles) and duration_s")
        if cycles is None:
            cycles = max(1, round(duration * frequency))
        ramp = r.integer("ramp_cycles", 2, lo=1, hi=1000)
        start = r.number("start_s", 0.0, lo=0.0, hi=MAX_START_S, unit="s")
        return cls(amplitude, frequency, int(cycles), ramp, start, _load_factor(r))


@dataclass(frozen=True)
class PulseMotion(_AnalyticMotion):
    """``type = "pulse"``: see :class:`rockyade.motion.analytic.Pulse`."""

    type: ClassVar[str] = "pulse"
    shape: str
    amplitude_m_s2: float
    period_s: float
    cycles: int = 1
    start_s: float = 0.0
    load_factor: float = 1.0

    @property
    def analytic(self) -> Pulse:
        """The analytic pulse (sampled at T/400, at most 1 ms)."""
        return Pulse(self.shape, self.amplitude_m_s2, self.period_s, self.cycles, self.start_s)

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> PulseMotion:
        """The motion from its ``[motion]`` table: ``shape``, ``amplitude_m_s2`` or ``amplitude_g``,
        ``period_s``, ``cycles``, ``start_s``."""
        shape = r.string("shape", choices=PULSE_SHAPES)
        amp = r.number("amplitude_m_s2", None, lo=0.0, hi=1000.0, lo_open=True, unit="m/s^2")
        amp_g = r.number("amplitude_g", None, lo=0.0, hi=100.0, lo_open=True, unit="g")
        if (amp is None) == (amp_g is None):
            raise r.error("amplitude_m_s2", "give exactly one of amplitude_m_s2 and amplitude_g")
        period = r.number("period_s", lo=0.0, hi=100.0, lo_open=True, unit="s")
        cycles = r.integer("cycles", 1, lo=1, hi=1000)
        start = r.number("start_s", 0.0, lo=0.0, hi=MAX_START_S, unit="s")
        return cls(shape, amp if amp is not None else amp_g * G, period, cycles, start, _load_factor(r))


@dataclass(frozen=True)
class RecordMotion(MotionSpec):
    """``type = "record"``: a recorded accelerogram file (module docstring)."""

    type: ClassVar[str] = "record"
    file: str
    format: str | None = None
    units: str | None = None
    dt_s: float | None = None
    baseline: bool = False
    bandpass_hz: tuple[float | None, float | None] | None = None
    target_pga_m_s2: float | None = None
    load_factor: float = 1.0

    def record(self) -> Record:
        """The processed record (before the load factor)."""
        rec = read_record(self.file, self.format, self.units, self.dt_s)
        accel = rec.accel_m_s2
        if self.bandpass_hz is not None:
            if not rec.uniform:
                raise InputError("motion.bandpass_hz", "needs a uniformly sampled record")
            accel = bandpass(accel, rec.dt_s, *self.bandpass_hz)
            rec = rec.with_accel(accel, f"band-pass {self.bandpass_hz} Hz")
        if self.baseline:
            rec = rec.with_accel(baseline_correct(rec.t_s, rec.accel_m_s2), "baseline corrected")
        if self.target_pga_m_s2 is not None:
            scaled, factor = scale_to_pga(rec.accel_m_s2, self.target_pga_m_s2)
            rec = rec.with_accel(scaled, f"scaled x{factor:.4g} to PGA {self.target_pga_m_s2:g} m/s^2")
        return rec

    def ground_motion(self, duration_s: float) -> GroundMotion:
        """The record's samples times ``load_factor``; m/s^2."""
        rec = self.record()
        label = f"record {Path(self.file).name}" + (f" x{self.load_factor:g}" if self.load_factor != 1 else "")
        return GroundMotion(rec.t_s, rec.accel_m_s2 * self.load_factor, None, label)

    def hash_material(self) -> dict[str, Any]:
        """The table with the file named by the SHA-256 of its bytes (a moved file keeps its hash)."""
        d = self.to_dict()
        d["file"] = hashlib.sha256(Path(self.file).read_bytes()).hexdigest()
        return d

    def sample_count(self, duration_s: float) -> int:
        """The record's samples, counted without reading them all."""
        return count_samples(self.file, self.format)

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> RecordMotion:
        """The motion from its ``[motion]`` table: ``file`` (relative to ``base_dir``), ``format``,
        ``units``, ``dt_s``, ``baseline``, ``bandpass_hz``."""
        name = r.string("file")
        path = Path(name)
        if not path.is_absolute() and base_dir is not None:
            path = base_dir / path
        if not path.is_file():
            raise r.error("file", f"record file not found: {path}")
        fmt = r.string("format", None, choices=FORMATS)
        units = r.string("units", None)
        if units is not None:
            units = normalise_units(units, r.field("units"))
        dt = r.number("dt_s", None, lo=DT_RANGE_S[0], hi=DT_RANGE_S[1], unit="s")
        baseline = r.boolean("baseline", False)
        bp = r.raw("bandpass_hz", None)
        band: tuple[float | None, float | None] | None = None
        if bp is not None:
            if not (isinstance(bp, list) and len(bp) == 2):
                raise r.error("bandpass_hz", "must be [low, high] in Hz (either may be omitted as a bare low/high)")
            corners = TableReader({"low": bp[0], "high": bp[1]}, r.field("bandpass_hz"), r.source)
            low = corners.number("low", None, lo=1e-3, hi=1e4, unit="Hz")
            high = corners.number("high", None, lo=1e-3, hi=1e4, unit="Hz")
            if low is None and high is None:
                raise r.error("bandpass_hz", "give at least one corner, in Hz")
            band = (low, high)
        pga = r.number("target_pga_m_s2", None, lo=1e-3, hi=MAX_ABS_ACCEL_M_S2, unit="m/s^2")
        spec = cls(str(path.resolve()), fmt, units, dt, baseline, band, pga, _load_factor(r))
        spec.record()  # read now so that a bad file is reported with the scene
        return spec


@dataclass(frozen=True)
class SyntheticMotion(MotionSpec):
    """``type = "synthetic"``: record i of a spectrum-compatible suite (module docstring)."""

    type: ClassVar[str] = "synthetic"
    record: int
    suite: str = "paper"
    spectrum_type: int | None = None
    ground: str | None = None
    ag_s_m_s2: float | None = None
    seed: int | None = None
    count: int | None = None
    load_factor: float = 1.0

    def suite_spec(self) -> SuiteSpec:
        """The suite's settings."""
        if self.suite == "paper":
            return paper_suite()
        target = ElasticSpectrum.ec8(self.spectrum_type, self.ground, ag_s_m_s2=self.ag_s_m_s2)  # type: ignore[arg-type]
        return SuiteSpec(target, count=self.count or 30, seed=self.seed or 0, name=self.suite)

    def sample_count(self, duration_s: float) -> int:
        """Samples of the suite's records (envelope duration over dt)."""
        spec = self.suite_spec()
        return round(spec.envelope.duration_s / spec.dt_s) + 1

    def ground_motion(self, duration_s: float) -> GroundMotion:
        """The suite's record number ``record`` (generated once, cached) times ``load_factor``; m/s^2."""
        rec = suite_record(self.suite_spec(), self.record)
        label = f"synthetic {self.suite} record {self.record}" + (
            f" x{self.load_factor:g}" if self.load_factor != 1 else ""
        )
        return GroundMotion(rec.t_s, rec.accel_m_s2 * self.load_factor, None, label)

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> SyntheticMotion:
        """The motion from its ``[motion]`` table: ``suite``, the EC8 spectrum and site (a custom
        suite), ``seed``, ``count``, ``record``."""
        suite = r.string("suite", "paper")
        st = r.integer("spectrum_type", None, lo=1, hi=2)
        ground = r.string("ground", None, choices=["A", "B", "C", "D", "E"])
        ags = r.number("ag_s_m_s2", None, lo=1e-3, hi=100.0, unit="m/s^2")
        seed = r.integer("seed", None, lo=0)
        count = r.integer("count", None, lo=1, hi=10_000)
        if suite != "paper" and None in (st, ground, ags, seed, count):
            raise r.error("suite", "a suite other than 'paper' needs spectrum_type, ground, ag_s_m_s2, seed and count")
        n = 30 if suite == "paper" else count
        record = r.integer("record", lo=1, hi=n)
        return cls(record, suite, st, ground, ags, seed, count, _load_factor(r))


MOTION_TYPES.update(
    {
        HarmonicMotion.type: HarmonicMotion.parse,
        PulseMotion.type: PulseMotion.parse,
        RecordMotion.type: RecordMotion.parse,
        SyntheticMotion.type: SyntheticMotion.parse,
        GravityRamp.type: GravityRamp.parse,
        Pushover.type: Pushover.parse,
    }
)

__all__ = ["GravityRamp", "HarmonicMotion", "PulseMotion", "Pushover", "RecordMotion", "SyntheticMotion"]
