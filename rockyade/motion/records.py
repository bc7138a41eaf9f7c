"""Readers of recorded accelerograms.

* PEER NGA ``.AT2``: four header lines (database, event/station, units, sampling), then
  the values in free format. The sampling line comes as ``NPTS=  5372, DT=   .0100 SEC,``
  with or without the commas and trailing text, or in the old layout
  ``  4000   .0100   NPTS, DT`` (two numbers first). Values beyond NPTS are ignored; CRLF
  line ends are accepted. The units line names G, CM/S/S (or CM/SEC/SEC, GAL) or M/S/S.
* Two-column text or CSV: time (s) and acceleration, comma / semicolon / whitespace
  separated, an optional header line, ``#`` comments.
* Single-column text: one acceleration per line at a given dt.

Every bad file raises :class:`RecordError` naming the file and the line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rockyade.constants import G
from rockyade.errors import InputError

#: factor to m/s^2 per unit name
UNITS = {"g": G, "m/s2": 1.0, "cm/s2": 0.01}
UNIT_ALIASES = {
    "g": "g",
    "m/s2": "m/s2",
    "m/s^2": "m/s2",
    "m/s/s": "m/s2",
    "mps2": "m/s2",
    "cm/s2": "cm/s2",
    "cm/s^2": "cm/s2",
    "cm/s/s": "cm/s2",
    "cm/sec/sec": "cm/s2",
    "gal": "cm/s2",
}
FORMATS = ("at2", "csv", "single")


class RecordError(InputError):
    """A record file that cannot be read: names the file and the line."""

    def __init__(self, path: str | Path, line: int | None, message: str) -> None:
        where = f"line {line}" if line is not None else "record"
        super().__init__(where, message, str(path))
        self.path = str(path)
        self.line = line


def normalise_units(units: str, source: str = "units") -> str:
    """Canonical unit name (g, m/s2, cm/s2) or InputError."""
    key = units.strip().lower().replace(" ", "")
    if key not in UNIT_ALIASES:
        raise InputError(
            source, f"must be one of g, m/s2, cm/s2 (aliases: {', '.join(sorted(UNIT_ALIASES))}), got {units!r}"
        )
    return UNIT_ALIASES[key]


@dataclass(frozen=True)
class Record:
    """An accelerogram in SI units.

    Attributes
    ----------
    t_s
        Sample times, s, from 0 (uniform for AT2 and single-column files).
    accel_m_s2
        Acceleration, m/s^2.
    units_in_file
        Units the file used (g, m/s2, cm/s2).
    source
        File path or description.
    title
        Header text (event, station) when the file has one.
    """

    t_s: np.ndarray
    accel_m_s2: np.ndarray
    units_in_file: str
    source: str
    title: str = ""
    extra: dict[str, object] = field(default_factory=dict)

    @property
    def npts(self) -> int:
        """Number of samples."""
        return int(self.accel_m_s2.size)

    @property
    def dt_s(self) -> float:
        """Sampling interval, s (the mean one for non-uniform files)."""
        return float((self.t_s[-1] - self.t_s[0]) / (self.npts - 1))

    @property
    def uniform(self) -> bool:
        """True when the samples are equally spaced."""
        d = np.diff(self.t_s)
        return bool(np.allclose(d, d[0], rtol=1e-6, atol=0))

    @property
    def duration_s(self) -> float:
        """Time of the last sample, s."""
        return float(self.t_s[-1])

    @property
    def pga_m_s2(self) -> float:
        """Peak absolute acceleration, m/s^2."""
        return float(np.max(np.abs(self.accel_m_s2)))

    @property
    def pga_time_s(self) -> float:
        """Time of the peak absolute acceleration, s."""
        return float(self.t_s[int(np.argmax(np.abs(self.accel_m_s2)))])

    def with_accel(self, accel: np.ndarray, note: str) -> Record:
        """A copy with other acceleration samples (processing history in ``extra``)."""
        history = [*list(self.extra.get("processing", [])), note]  # type: ignore[arg-type]
        return Record(
            self.t_s,
            np.asarray(accel, dtype=float),
            self.units_in_file,
            self.source,
            self.title,
            {**self.extra, "processing": history},
        )


_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?"


def _parse_at2_sampling(line: str, path: Path, lineno: int) -> tuple[int, float]:
    """NPTS and DT from the fourth AT2 header line (new or old layout)."""
    upper = line.upper()
    m_n = re.search(r"NPTS\s*=\s*(" + _NUMBER + ")", upper)
    m_dt = re.search(r"DT\s*=\s*(" + _NUMBER + ")", upper)
    if m_n or m_dt:
        if not m_n:
            raise RecordError(path, lineno, "header has DT= but no NPTS=")
        if not m_dt:
            raise RecordError(path, lineno, "header has NPTS= but no DT=")
        npts_text, dt_text = m_n.group(1), m_dt.group(1)
    else:
        numbers = re.findall(_NUMBER, upper)
        if len(numbers) < 2:
            raise RecordError(path, lineno, f"expected 'NPTS=..., DT=... SEC' or 'NPTS DT', got {line.strip()!r}")
        npts_text, dt_text = numbers[0], numbers[1]
    try:
        npts_f = float(npts_text.replace("D", "E").replace("d", "e"))
        dt = float(dt_text.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise RecordError(path, lineno, f"cannot read NPTS and DT from {line.strip()!r}") from None
    if npts_f != int(npts_f) or npts_f < 2:
        raise RecordError(path, lineno, f"NPTS must be an integer >= 2, got {npts_text}")
    if not dt > 0:
        raise RecordError(path, lineno, f"DT must be > 0 s, got {dt_text}")
    return int(npts_f), dt


def _at2_units(line: str) -> str | None:
    upper = line.upper()
    if re.search(r"\bCM\s*/\s*S(EC)?\s*/\s*S(EC)?\b|\bCM/S\^?2\b|\bGALS?\b", upper):
        return "cm/s2"
    if re.search(r"\bM\s*/\s*S(EC)?\s*/\s*S(EC)?\b|\bM/S\^?2\b", upper):
        return "m/s2"
    if re.search(r"\bUNITS\s+OF\s+G\b|\bIN\s+G\b|\(G\)|\bG\s*$", upper):
        return "g"
    return None


def _read_lines(path: Path) -> list[str]:
    if not path.is_file():
        raise RecordError(path, None, "file not found")
    try:
        text = path.read_bytes().decode("utf-8", errors="strict")
    except UnicodeDecodeError:
        text = path.read_bytes().decode("latin-1")
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


def read_at2(path: str | Path, units: str | None = None) -> Record:
    """Read a PEER NGA AT2 file (see module docstring).

    Parameters
    ----------
    path
        The file.
    units
        Override the units named in the header (g, m/s2, cm/s2).
    """
    path = Path(path)
    lines = _read_lines(path)
    if len(lines) < 5:
        raise RecordError(path, len(lines), "an AT2 file needs 4 header lines and data")
    npts, dt = _parse_at2_sampling(lines[3], path, 4)
    file_units = normalise_units(units) if units else _at2_units(lines[2])
    if file_units is None:
        raise RecordError(path, 3, f"cannot tell the units from {lines[2].strip()!r}; give units explicitly")
    values: list[float] = []
    for lineno, line in enumerate(lines[4:], start=5):
        for token in line.replace(",", " ").split():
            try:
                values.append(float(token.replace("D", "E").replace("d", "e")))
            except ValueError:
                raise RecordError(path, lineno, f"not a number: {token!r}") from None
            if len(values) == npts:
                break
        if len(values) == npts:
            break
    if len(values) < npts:
        raise RecordError(path, len(lines), f"NPTS = {npts} in the header but the file holds {len(values)} values")
    accel = np.asarray(values) * UNITS[file_units]
    if not np.all(np.isfinite(accel)):
        raise RecordError(path, None, "contains NaN or infinite values")
    title = lines[1].strip()
    return Record(np.arange(npts) * dt, accel, file_units, str(path), title, {"format": "at2", "dt_file_s": dt})


def _split(line: str) -> list[str]:
    return [t for t in re.split(r"[,;\s]+", line.strip()) if t]


def read_two_column(path: str | Path, units: str = "m/s2") -> Record:
    """Read time (s) and acceleration columns (comma, semicolon or whitespace separated)."""
    path = Path(path)
    unit = normalise_units(units)
    times: list[float] = []
    accel: list[float] = []
    for lineno, line in enumerate(_read_lines(path), start=1):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        tokens = _split(body)
        try:
            numbers = [float(t) for t in tokens]
        except ValueError:
            if not times:  # a header line
                continue
            raise RecordError(path, lineno, f"not numeric: {body!r}") from None
        if len(numbers) < 2:
            raise RecordError(path, lineno, f"expected two columns (time, acceleration), got {body!r}")
        times.append(numbers[0])
        accel.append(numbers[1])
    if len(times) < 2:
        raise RecordError(path, None, "fewer than 2 samples")
    t = np.asarray(times)
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if bad.size:
        raise RecordError(path, None, f"time must increase strictly (sample {int(bad[0]) + 2})")
    a = np.asarray(accel) * UNITS[unit]
    if not np.all(np.isfinite(a)) or not np.all(np.isfinite(t)):
        raise RecordError(path, None, "contains NaN or infinite values")
    return Record(t - t[0], a, unit, str(path), "", {"format": "csv"})


def read_single_column(path: str | Path, dt_s: float, units: str = "m/s2") -> Record:
    """Read one acceleration value per line, sampled at ``dt_s``."""
    path = Path(path)
    if not (isinstance(dt_s, (int, float)) and dt_s > 0):
        raise RecordError(path, None, f"dt must be > 0 s, got {dt_s!r}")
    unit = normalise_units(units)
    values: list[float] = []
    for lineno, line in enumerate(_read_lines(path), start=1):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        try:
            values.append(float(body))
        except ValueError:
            if not values:
                continue
            raise RecordError(path, lineno, f"not a number: {body!r}") from None
    if len(values) < 2:
        raise RecordError(path, None, "fewer than 2 samples")
    a = np.asarray(values) * UNITS[unit]
    if not np.all(np.isfinite(a)):
        raise RecordError(path, None, "contains NaN or infinite values")
    return Record(np.arange(a.size) * dt_s, a, unit, str(path), "", {"format": "single"})


def detect_format(path: str | Path) -> str:
    """``at2`` for .AT2 files, ``csv`` otherwise (two columns)."""
    return "at2" if Path(path).suffix.lower() == ".at2" else "csv"


def read_record(
    path: str | Path, fmt: str | None = None, units: str | None = None, dt_s: float | None = None
) -> Record:
    """Read any supported record file.

    Parameters
    ----------
    path
        The file.
    fmt
        "at2", "csv" (two columns) or "single" (one column, needs ``dt_s``); default by
        extension.
    units
        Units of the values (default: from the AT2 header; m/s2 for text files).
    dt_s
        Sampling interval for single-column files, s.
    """
    fmt = fmt or detect_format(path)
    if fmt not in FORMATS:
        raise InputError("format", f"must be one of {', '.join(FORMATS)}, got {fmt!r}")
    if fmt == "at2":
        return read_at2(path, units)
    if fmt == "csv":
        return read_two_column(path, units or "m/s2")
    if dt_s is None:
        raise InputError("dt_s", "a single-column record needs its sampling interval dt_s")
    return read_single_column(path, dt_s, units or "m/s2")
