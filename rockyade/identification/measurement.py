"""Measured free-rocking histories: rotation from a CSV file, in radians or degrees, or
derived from two vertical displacements of targets (LEDs) a known distance apart.

Format (docs/identification.md): a CSV file with a header row, one row per sample, equally
spaced in time (any rate from :data:`MIN_RATE_HZ` up). Columns:

* ``t_s``: time, s (other name: ``time_column``);
* ``theta_rad`` (or ``theta_deg``, read in degrees): rotation, counter-clockwise positive
  (other name: ``theta_column``; ``degrees=True`` for a column in degrees);
* or two vertical displacements ``led1_y_m`` and ``led2_y_m`` of targets fixed on the
  block on a horizontal line, LED 2 a distance ``led_distance_m`` to the right of LED 1.
  A rigid rotation theta moves LED 2 up relative to LED 1 by d sin(theta) whatever the
  pivot, so theta = asin((y2 - y1) / d - u_rest) with u_rest = (y2 - y1) / d when the
  block stands upright at rest (``led_zero = "end"``: the last samples, where a
  free-rocking test ends at rest; ``"none"``: the displacements are already zero upright).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError

#: Slowest sampling accepted, Hz.
MIN_RATE_HZ = 50.0
#: Largest deviation of a sample time from the uniform grid, as a fraction of the interval
#: (1 % of a 100 Hz interval moves theta by ~1e-4 rad at the fastest rocking: below the noise).
MAX_JITTER = 0.01
#: Fraction of the record (at its end) taken as the upright rest for LED data.
REST_TAIL_FRACTION = 0.05
LED_ZERO_CHOICES = ("end", "none")


@dataclass(frozen=True)
class MeasuredHistory:
    """A measured rotation history, equally spaced.

    Attributes
    ----------
    t_s
        Sample times, s.
    theta_rad
        Rotation, rad (counter-clockwise positive).
    dt_s
        Sampling interval, s.
    source
        Where it came from (file name or description).
    notes
        How the rotation was obtained (units, LED conversion, rest reference).
    """

    t_s: NDArray[np.float64]
    theta_rad: NDArray[np.float64]
    dt_s: float
    source: str = ""
    notes: tuple[str, ...] = field(default=())

    @property
    def rate_hz(self) -> float:
        """Sampling rate, Hz."""
        return 1.0 / self.dt_s

    @property
    def duration_s(self) -> float:
        """Time span of the record, s."""
        return float(self.t_s[-1] - self.t_s[0])


def measured_history(
    t_s: NDArray[np.float64], theta_rad: NDArray[np.float64], source: str = "", notes: tuple[str, ...] = ()
) -> MeasuredHistory:
    """Validate samples and wrap them: finite, |theta| < pi/2, at least 20, equally spaced, >= 50 Hz.

    Parameters
    ----------
    t_s
        Sample times, s.
    theta_rad
        Measured rotation, rad (counter-clockwise positive).
    source
        Where the samples come from (a file name), for messages.
    notes
        How the rotation was derived (e.g. from LED displacements).

    Raises
    ------
    InputError
        Naming ``t_s`` or ``theta_rad`` and the rule broken.
    """
    t = np.asarray(t_s, dtype=float)
    theta = np.asarray(theta_rad, dtype=float)
    if t.ndim != 1 or theta.shape != t.shape:
        raise InputError("theta_rad", "time and rotation must be 1-D columns of equal length", source or None)
    if t.size < 20:
        raise InputError("t_s", f"needs at least 20 samples, got {t.size}", source or None)
    if not np.all(np.isfinite(t)):
        raise InputError("t_s", "contains empty, NaN or infinite values", source or None)
    bad = np.nonzero(~np.isfinite(theta))[0]
    if bad.size:
        raise InputError(
            "theta_rad", f"contains empty, NaN or infinite values (first at row {bad[0] + 1})", source or None
        )
    peak = float(np.max(np.abs(theta)))
    if peak >= 0.5 * math.pi:
        # a rocking block turns by less than its slenderness alpha < pi/2: a larger value is
        # not a rotation in radians (most often degrees read as radians)
        raise InputError(
            "theta_rad",
            f"|rotation| reaches {peak:.4g} rad, must stay below pi/2 = 1.5708 rad "
            "(in degrees? name the column theta_deg or give --degrees)",
            source or None,
        )
    steps = np.diff(t)
    if np.any(steps <= 0):
        raise InputError("t_s", "must be strictly increasing", source or None)
    index = np.arange(t.size)
    dt, t0 = np.polyfit(index, t, 1)
    jitter = float(np.max(np.abs(t - (t0 + dt * index))))
    if jitter > MAX_JITTER * dt:
        raise InputError(
            "t_s",
            f"samples must be equally spaced (a time deviates by {jitter:.3g} s from a uniform grid of "
            f"{dt:.6g} s); resample the record to a constant interval",
            source or None,
        )
    if 1.0 / dt < MIN_RATE_HZ * (1 - 1e-6):
        raise InputError(
            "t_s", f"sampling rate {1.0 / dt:.4g} Hz is below the {MIN_RATE_HZ:g} Hz needed", source or None
        )
    uniform = t0 + dt * index
    return MeasuredHistory(uniform, theta, float(dt), source, tuple(notes))


def rotation_from_leds(
    y1_m: NDArray[np.float64], y2_m: NDArray[np.float64], distance_m: float, zero: str = "end"
) -> tuple[NDArray[np.float64], str]:
    """Rotation from two vertical target displacements, rad, and a note on how.

    theta = asin((y2 - y1) / d - u_rest): a rigid rotation theta raises a point a distance
    d to the right of another by d sin(theta), whatever the pivot.

    Parameters
    ----------
    y1_m, y2_m
        Vertical displacements of LED 1 and LED 2 (LED 2 to the right), m.
    distance_m
        Horizontal distance between the LEDs when the block stands upright, m.
    zero
        ``"end"``: the upright rest is the mean of the last 5 % of the record;
        ``"none"``: the displacements are zero when the block stands upright.
    """
    if not (isinstance(distance_m, (int, float)) and math.isfinite(distance_m) and distance_m > 0):
        raise InputError("led_distance_m", f"must be a number > 0 m, got {distance_m!r}")
    if zero not in LED_ZERO_CHOICES:
        raise InputError("led_zero", f"must be one of {', '.join(LED_ZERO_CHOICES)}, got {zero!r}")
    u = (np.asarray(y2_m, dtype=float) - np.asarray(y1_m, dtype=float)) / distance_m
    note = f"theta = asin((y2 - y1) / {distance_m:g} m"
    if zero == "end":
        tail = u[-max(5, int(REST_TAIL_FRACTION * u.size)) :]
        u_rest = float(np.mean(tail))
        swing = float(np.max(u) - np.min(u))
        if float(np.std(tail)) > 0.05 * swing:
            raise InputError(
                "led_zero",
                "the record does not end at rest (the last 5 % of (y2 - y1) / d varies by "
                f"{np.std(tail):.3g}, over 5 % of its range): give led_zero = 'none' with displacements "
                "zero when the block stands upright",
            )
        u = u - u_rest
        note += f" - {u_rest:.6g}) (upright rest from the last 5 % of the record)"
    else:
        note += ") (displacements zero when upright)"
    if np.any(np.abs(u) >= 1.0):
        raise InputError("led_distance_m", f"(y2 - y1) / d reaches {np.max(np.abs(u)):.3g} >= 1: check d and the units")
    return np.arcsin(u), note


def read_measurement(
    path: str | Path,
    *,
    time_column: str = "t_s",
    theta_column: str | None = None,
    degrees: bool | None = None,
    led_columns: tuple[str, str] | None = None,
    led_distance_m: float | None = None,
    led_zero: str = "end",
) -> MeasuredHistory:
    """Read a measured free-rocking history from a CSV file (format in the module docstring).

    Parameters
    ----------
    path
        CSV file with a header row.
    time_column
        Time column, s.
    theta_column
        Rotation column (default ``theta_rad``, else ``theta_deg``).
    degrees
        The rotation column is in degrees (default: when its name ends in ``_deg``).
    led_columns, led_distance_m, led_zero
        Two vertical displacement columns (m), their distance (m) and the rest reference:
        the rotation is derived from them (see :func:`rotation_from_leds`).
    """
    import pandas as pd

    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("measurement", f"file not found: {path}")
    try:
        frame = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise InputError("measurement", f"not a readable CSV file: {exc}", source) from None
    frame.columns = [str(c).strip() for c in frame.columns]

    def column(name: str, what: str) -> NDArray[np.float64]:
        if name not in frame.columns:
            raise InputError(what, f"no column {name!r} (columns: {', '.join(frame.columns)})", source)
        values = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)
        bad = np.nonzero(~np.isfinite(values))[0]
        if bad.size:
            raise InputError(what, f"column {name!r} has a non-numeric or empty value at data row {bad[0] + 1}", source)
        return values

    t = column(time_column, "time_column")
    notes = [f"time from column {time_column!r} (s)"]
    if led_columns is not None:
        if theta_column is not None:
            raise InputError("led_columns", "give either a rotation column or two LED columns, not both", source)
        if led_distance_m is None:
            raise InputError("led_distance_m", "is required with LED columns (m between the two targets)", source)
        y1 = column(led_columns[0], "led_columns")
        y2 = column(led_columns[1], "led_columns")
        theta, note = rotation_from_leds(y1, y2, led_distance_m, led_zero)
        notes.append(f"rotation from LED columns {led_columns[0]!r}, {led_columns[1]!r}: {note}")
    else:
        if theta_column is None:
            theta_column = (
                "theta_rad" if "theta_rad" in frame.columns or "theta_deg" not in frame.columns else "theta_deg"
            )
        if degrees and theta_column.endswith("_rad"):
            # the name says radians: read as degrees, a 0.1 rad swing became 0.0017 rad, and the
            # fit returned a block 57 times less slender without a word
            raise InputError(
                "degrees",
                f"column {theta_column!r} is in radians by its name; --degrees is for a column in degrees "
                "(one named theta_deg is read as degrees without it)",
                source,
            )
        in_degrees = theta_column.endswith("_deg") if degrees is None else degrees
        theta = column(theta_column, "theta_column")
        if in_degrees:
            theta = np.radians(theta)
        notes.append(f"rotation from column {theta_column!r} ({'degrees' if in_degrees else 'rad'})")
    return measured_history(t, theta, source, tuple(notes))
