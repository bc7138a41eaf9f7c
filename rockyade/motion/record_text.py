"""What every reader of recorded accelerograms shares (:mod:`rockyade.motion.records` for PEER
AT2 and text columns, :mod:`rockyade.motion.esm` for ESM's ASCII): the :class:`Record` in SI
units, :class:`RecordError` naming the file and the line, the units a record may be in, numbers
read as ASCII decimals, and the integrity checks every reader makes (a value cut short, the
sampling against the one given, a file too large, values that are not finite or not plausible).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import cast

import numpy as np

from rockyade.constants import STANDARD_GRAVITY
from rockyade.errors import InputError

#: factor to m/s^2 per unit name (a record "in g" means standard gravity)
UNITS = {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}


#: Most samples a record may hold (a day at 100 Hz is 8.6 million).
MAX_RECORD_SAMPLES = 10_000_000


#: Largest record file read, bytes.
MAX_RECORD_BYTES = 512 * 1024 * 1024


#: Sampling interval range of a record, s.
DT_RANGE_S = (1.0e-5, 1.0)


#: Largest |acceleration| accepted, m/s^2 (about 100 g; the strongest records reach 4 g).
MAX_ABS_ACCEL_M_S2 = 1000.0


UNIT_ALIASES = {
    "g": "g",
    **dict.fromkeys(("m/s2", "m/s^2", "m/s/s", "mps2"), "m/s2"),
    **dict.fromkeys(("cm/s2", "cm/s^2", "cm/s/s", "cm/sec/sec", "gal"), "cm/s2"),
}


#: Unit names of velocities and displacements (refused with a message saying so).
VELOCITY_UNITS = ("cm/s", "cm/sec", "m/s", "m/sec", "mm/s", "in/s", "cm", "m", "mm")


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
    if key in VELOCITY_UNITS:
        raise InputError(source, f"{units!r} is a velocity unit: a record must hold accelerations, in g, m/s2 or cm/s2")
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
        done = cast("list[str]", self.extra.get("processing", []))  # only this method writes it: a list
        history = [*done, note]
        return Record(
            self.t_s,
            np.asarray(accel, dtype=float),
            self.units_in_file,
            self.source,
            self.title,
            {**self.extra, "processing": history},
        )


#: An ASCII decimal number, its exponent written E or Fortran's D (module docstring of
#: :mod:`rockyade.motion.records`).
NUMBER_PATTERN = r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eEdD][-+]?[0-9]+)?"


_NUMBER_RE = re.compile(rf"^{NUMBER_PATTERN}$", re.ASCII)


def parse_number(token: str) -> float | None:
    """A decimal number as written in records (exponent E or D), or None if not one.

    Only ASCII digits; no ``_``, no ``inf``/``nan``. A value beyond the float range gives
    ``inf`` (the callers refuse it).
    """
    if not _NUMBER_RE.match(token):
        return None
    return float(token.replace("D", "E").replace("d", "e"))


def _signature(token: str) -> tuple[bool, int, int]:
    """How a number is written: (has an exponent, digits after the point, exponent digits)."""
    mantissa, mark, exponent = token.upper().replace("D", "E").partition("E")
    return (bool(mark), len(mantissa.partition(".")[2]), len(exponent.lstrip("+-")))


def check_not_cut(path: Path, tokens: list[tuple[str, int]], last_in_file: bool) -> None:
    """Refuse a last value that is cut short: every other value is written one way, it another.

    ``tokens`` are the (text, line) of the values of one column, in order;
    ``last_in_file``: no value follows the last of them. Only a column written in a fixed
    format (every other value with an exponent, or with 3 decimals or more, alike) says how
    the last value should look; a free-format column is left alone.
    """
    if not last_in_file or len(tokens) < 2:
        return
    last, line = tokens[-1]
    others = [_signature(t) for t, _ in tokens[:-1]]
    if len({(exp, frac) for exp, frac, _ in others}) != 1:
        return  # free format: the values vary anyway
    has_exp, frac, _ = others[0]
    fixed = has_exp if len(others) == 1 else (has_exp or frac >= 3)
    if not fixed:
        return
    min_exp_digits = min(2, *(d for _, _, d in others))  # exponents are written with 2 digits or more
    mine = _signature(last)
    if mine[0] != has_exp or mine[1] != frac or mine[2] < min_exp_digits:
        raise RecordError(
            path,
            line,
            f"the last value {last!r} is written differently from every other value (e.g. "
            f"{tokens[0][0]!r}): the file looks truncated inside it",
        )


def number_at(path: Path, lineno: int, token: str, what: str = "value") -> float:
    value = parse_number(token)
    if value is None:
        raise RecordError(path, lineno, f"not a number: {token!r}")
    if not math.isfinite(value):
        raise RecordError(path, lineno, f"{what} {token!r} is beyond the floating-point range")
    return value


def read_text(path: Path) -> str:
    if not path.is_file():
        raise RecordError(path, None, "file not found")
    size = path.stat().st_size
    if size > MAX_RECORD_BYTES:
        raise RecordError(path, None, f"the file has {size} bytes, more than the {MAX_RECORD_BYTES} a record may have")
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return text.replace("\r\n", "\n").replace("\r", "\n")


def resolve_units(path: Path, line: int | None, in_file: str | None, given: str | None) -> str:
    """The units to use: the file's; ``given`` must agree with them (or stand in for none)."""
    wanted = normalise_units(given) if given else None
    if in_file is not None and wanted is not None and wanted != in_file:
        raise RecordError(
            path,
            line,
            f"the file says its values are in {in_file} but units = {wanted} was given: "
            "drop the units option (the file's units are used) or fix the file",
        )
    return in_file or wanted or ""


def check_dt(path: Path, line: int | None, dt_file: float, dt_given: float | None, where: str) -> None:
    """Refuse a ``dt_s`` that disagrees with the file's own sampling (relative 1e-6)."""
    if dt_given is not None and not math.isclose(dt_given, dt_file, rel_tol=1e-6):
        raise RecordError(
            path,
            line,
            f"{where} {dt_file:g} s but dt_s = {dt_given:g} s was given: drop dt_s (the file's sampling is "
            "used) or fix the file",
        )


def accel_si(path: Path, values: list[float], unit: str) -> np.ndarray:
    a = np.asarray(values, dtype=float) * UNITS[unit]
    if not np.all(np.isfinite(a)):
        raise RecordError(path, None, "contains NaN or infinite values")
    worst = int(np.argmax(np.abs(a)))
    if abs(a[worst]) > MAX_ABS_ACCEL_M_S2:
        raise RecordError(
            path,
            None,
            f"sample {worst + 1} is {a[worst]:.4g} m/s^2, beyond +/-{MAX_ABS_ACCEL_M_S2:g} m/s^2: "
            f"wrong units ({unit})?",
        )
    return a


def record_problem(t_s: np.ndarray, accel_m_s2: np.ndarray) -> str | None:
    """What keeps samples from being a record, or None: the bounds every record passes,
    whether read from a file or taken from the synthetic-record cache.

    1-D float arrays of the same length, 2 to :data:`MAX_RECORD_SAMPLES` samples, times from 0
    strictly increasing, finite accelerations within +/- :data:`MAX_ABS_ACCEL_M_S2` m/s^2.
    """
    if not all(isinstance(x, np.ndarray) and x.dtype == np.float64 and x.ndim == 1 for x in (t_s, accel_m_s2)):
        return "times and accelerations must be 1-D float64 arrays"
    if t_s.shape != accel_m_s2.shape:
        return f"{t_s.size} times but {accel_m_s2.size} accelerations"
    if not 2 <= t_s.size <= MAX_RECORD_SAMPLES:
        return f"{t_s.size} samples, not in [2, {MAX_RECORD_SAMPLES}]"
    if not (np.all(np.isfinite(t_s)) and t_s[0] == 0.0 and np.all(np.diff(t_s) > 0)):
        return "times must start at 0 and increase strictly"
    if not np.all(np.isfinite(accel_m_s2)):
        return "contains NaN or infinite values"
    worst = int(np.argmax(np.abs(accel_m_s2)))
    if abs(accel_m_s2[worst]) > MAX_ABS_ACCEL_M_S2:
        return f"sample {worst + 1} is {accel_m_s2[worst]:.4g} m/s^2, beyond +/-{MAX_ABS_ACCEL_M_S2:g} m/s^2"
    return None
