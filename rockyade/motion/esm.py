"""The ASCII records of the Engineering Strong-Motion database (ESM, https://esm-db.eu), read
exactly or refused.

ESM (and ITACA, the Italian accelerometric archive it grew from) gives each component of a
record as a text file, ``NETWORK.STATION.LOCATION.STREAM.D.EVENT.C.ACC.ASC`` and the like, in
its "DYNA 1.2" layout (``HEADER_FORMAT: DYNA 1.2``): a header of ``KEY: value`` lines (64 in the
files the database serves: the event, the station, the processing), then the values, one a
line. The keys a record is read by:

* ``SAMPLING_INTERVAL_S``: the sampling interval, s;
* ``NDATA``: the number of values; the file must hold exactly that many (fewer, or a last
  value cut short, is a truncated file; more, a header that disagrees with its data);
* ``UNITS``: ``cm/s^2`` (what ESM serves), ``m/s^2`` or ``g`` (standard gravity);
* ``DATA_TYPE``: ``ACCELERATION``; a velocity, a displacement or a response spectrum
  (``VELOCITY``, ``DISPLACEMENT``, ``... SPECTRUM``; the database serves them in the same
  layout) is refused: rockyade integrates accelerations;
* checked where present: ``DURATION_S`` = NDATA x SAMPLING_INTERVAL_S (within one sample) and
  ``PGA_CM/S^2`` = the data's peak (within 1 %): a header that disagrees with its data is a
  damaged file or the wrong units;
* for the record's title: ``EVENT_ID`` (or ``EVENT_NAME``), ``NETWORK``, ``STATION_CODE``,
  ``STREAM``.

The values pass the checks of every record (:mod:`rockyade.motion.records`): ASCII decimals
(no ``nan``, no ``inf``), within +/- 1000 m/s^2; units given to the reader that differ from
the header's are refused as a conflict, and so is a sampling interval that differs from the
header's. The layout is that of the files the ESM event-data web service returns (ESM
Working Group, Engineering Strong Motion database, https://esm-db.eu; Luzi et al., 2016,
Seismological Research Letters 87(4), 987-997).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from rockyade.errors import InputError
from rockyade.motion.record_text import (
    DT_RANGE_S,
    MAX_RECORD_SAMPLES,
    Record,
    RecordError,
    accel_si,
    check_dt,
    check_not_cut,
    normalise_units,
    number_at,
    parse_number,
    read_text,
    resolve_units,
)

#: A header line: an upper-case key (letters, digits, ``_ / ^ . -``), a colon, its value.
_HEADER_LINE = re.compile(r"^([A-Z][A-Z0-9_/^.\-]*)\s*:(.*)$")
#: The keys a record cannot be read without.
REQUIRED_KEYS = ("SAMPLING_INTERVAL_S", "NDATA", "UNITS", "DATA_TYPE")
#: Relative tolerance of the header's PGA against the data's peak.
PGA_TOLERANCE = 0.01
#: Header lines looked at to tell an ESM file (its header has 64).
DETECT_LINES = 80


def is_esm_header(lines: list[str]) -> bool:
    """True when the first lines of a file are an ESM header: ``KEY: value`` lines from the
    first one on, among them ``SAMPLING_INTERVAL_S`` and ``NDATA``."""
    keys = set()
    for line in lines[:DETECT_LINES]:
        text = line.strip().lstrip("\ufeff")
        if not text:
            continue
        match = _HEADER_LINE.match(text)
        if match is None:
            break
        keys.add(match.group(1))
    return {"SAMPLING_INTERVAL_S", "NDATA"} <= keys


def _header(path: Path, lines: list[str]) -> tuple[dict[str, tuple[str, int]], int]:
    """The header's ``key -> (value, 1-based line)`` and the index of the first data line."""
    header: dict[str, tuple[str, int]] = {}
    index = 0
    for index, line in enumerate(lines):
        text = line.strip()
        if not text:
            continue
        match = _HEADER_LINE.match(text)
        if match is None:
            break
        key = match.group(1)
        if key in header:
            raise RecordError(path, index + 1, f"the header gives {key} twice (line {header[key][1]} and here)")
        header[key] = (match.group(2).strip(), index + 1)
    else:
        index = len(lines)
    missing = [k for k in REQUIRED_KEYS if k not in header]
    if missing:
        raise RecordError(
            path,
            None,
            f"an ESM header needs {', '.join(REQUIRED_KEYS)}; it lacks {', '.join(missing)}",
        )
    return header, index


def _sampling(path: Path, header: dict[str, tuple[str, int]]) -> tuple[int, float]:
    """NDATA and SAMPLING_INTERVAL_S, checked."""
    text, line = header["NDATA"]
    n = parse_number(text)
    if n is None or not math.isfinite(n) or n != int(n) or n < 2:
        raise RecordError(path, line, f"NDATA must be an integer >= 2, got {text!r}")
    if n > MAX_RECORD_SAMPLES:
        raise RecordError(path, line, f"NDATA must be at most {MAX_RECORD_SAMPLES}, got {text}")
    text, line = header["SAMPLING_INTERVAL_S"]
    dt = parse_number(text)
    lo, hi = DT_RANGE_S
    if dt is None or not (math.isfinite(dt) and lo <= dt <= hi):
        raise RecordError(path, line, f"SAMPLING_INTERVAL_S must be a number in [{lo:g}, {hi:g}] s, got {text!r}")
    return int(n), dt


def _units(path: Path, header: dict[str, tuple[str, int]], given: str | None) -> str:
    """The header's UNITS as a unit name (g, m/s2, cm/s2), reconciled with ``given``."""
    text, line = header["UNITS"]
    try:
        unit = normalise_units(text, "UNITS")
    except InputError as exc:
        raise RecordError(path, line, f"UNITS: {exc.message}") from None
    return resolve_units(path, line, unit, given)


def _quantity(path: Path, header: dict[str, tuple[str, int]]) -> None:
    """Refuse anything but an acceleration time series."""
    text, line = header["DATA_TYPE"]
    kind = text.upper()
    if kind != "ACCELERATION":
        what = "a response spectrum" if "SPECTR" in kind else f"{text!r}" if text else "an empty DATA_TYPE"
        raise RecordError(
            path,
            line,
            f"DATA_TYPE is {what}, not ACCELERATION: rockyade needs an acceleration record (ESM serves each "
            "record as ACC, VEL, DIS and spectra files in the same layout; use the ACC one)",
        )


def _check_header_against_data(
    path: Path, header: dict[str, tuple[str, int]], n: int, dt: float, accel_m_s2: np.ndarray
) -> None:
    """DURATION_S and PGA_CM/S^2, where the header gives them, agree with the data."""
    if "DURATION_S" in header:
        text, line = header["DURATION_S"]
        duration = parse_number(text) if text else None
        if duration is not None and math.isfinite(duration) and abs(duration - n * dt) > 1.0001 * dt:
            raise RecordError(
                path,
                line,
                f"DURATION_S = {text} but NDATA x SAMPLING_INTERVAL_S = {n} x {dt:g} = {n * dt:g} s: the header "
                "disagrees with itself",
            )
    if "PGA_CM/S^2" in header:
        text, line = header["PGA_CM/S^2"]
        pga = parse_number(text) if text else None
        peak = float(np.max(np.abs(accel_m_s2))) * 100.0
        if pga is not None and math.isfinite(pga) and abs(abs(pga) - peak) > PGA_TOLERANCE * max(abs(pga), peak):
            raise RecordError(
                path,
                line,
                f"PGA_CM/S^2 = {text} but the data's peak is {peak:.6g} cm/s^2 (read in the header's UNITS): the "
                "header and the data disagree (wrong UNITS, or a damaged file)",
            )


def read_esm(path: str | Path, units: str | None = None, dt_s: float | None = None) -> Record:
    """Read an ESM ASCII record (module docstring).

    Parameters
    ----------
    path
        The file.
    units
        Units of the values: refused unless they are the header's UNITS (which always names them).
    dt_s
        Sampling interval, s: refused unless it is the header's SAMPLING_INTERVAL_S.

    Raises
    ------
    RecordError
        A header key missing or out of range, not an acceleration, a count of values other than
        NDATA, a value that is not a number, or a header that disagrees with the data.
    """
    path = Path(path)
    lines = read_text(path).split("\n")
    header, first = _header(path, lines)
    _quantity(path, header)
    n, dt = _sampling(path, header)
    unit = _units(path, header, units)
    check_dt(path, header["SAMPLING_INTERVAL_S"][1], dt, dt_s, "SAMPLING_INTERVAL_S says")
    values: list[float] = []
    tokens: list[tuple[str, int]] = []
    for lineno, line in enumerate(lines[first:], start=first + 1):
        for token in line.split():
            if len(values) == n:
                raise RecordError(
                    path,
                    lineno,
                    f"NDATA = {n} in the header but the file holds more values (value {n + 1} is on line {lineno}): "
                    "the header and the data disagree",
                )
            values.append(number_at(path, lineno, token))
            tokens.append((token, lineno))
    if len(values) < n:
        raise RecordError(
            path, len(lines), f"NDATA = {n} in the header but the file holds {len(values)} values: truncated?"
        )
    check_not_cut(path, tokens, True)
    accel = accel_si(path, values, unit)
    _check_header_against_data(path, header, n, dt, accel)
    event = header.get("EVENT_ID", header.get("EVENT_NAME", ("", 0)))[0]
    station = ".".join(header.get(k, ("", 0))[0] for k in ("NETWORK", "STATION_CODE"))
    title = f"ESM {event} {station} {header.get('STREAM', ('', 0))[0]}".strip()
    extra = {"format": "esm", "dt_file_s": dt, "header_format": header.get("HEADER_FORMAT", ("", 0))[0]}
    return Record(np.arange(n) * dt, accel, unit, str(path), title, extra)


#: The header keys of ESM's DYNA 1.2 layout, in its order (64 lines).
DYNA_KEYS = (
    "EVENT_NAME", "EVENT_ID", "EVENT_DATE_YYYYMMDD", "EVENT_TIME_HHMMSS", "EVENT_LATITUDE_DEGREE",
    "EVENT_LONGITUDE_DEGREE", "EVENT_DEPTH_KM", "HYPOCENTER_REFERENCE", "MAGNITUDE_W", "MAGNITUDE_W_REFERENCE",
    "MAGNITUDE_L", "MAGNITUDE_L_REFERENCE", "FOCAL_MECHANISM", "NETWORK", "STATION_CODE", "STATION_NAME",
    "STATION_LATITUDE_DEGREE", "STATION_LONGITUDE_DEGREE", "STATION_ELEVATION_M", "LOCATION", "SENSOR_DEPTH_M",
    "VS30_M/S", "SITE_CLASSIFICATION_EC8", "MORPHOLOGIC_CLASSIFICATION", "EPICENTRAL_DISTANCE_KM",
    "EARTHQUAKE_BACKAZIMUTH_DEGREE", "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS", "DATE_TIME_FIRST_SAMPLE_PRECISION",
    "SAMPLING_INTERVAL_S", "NDATA", "DURATION_S", "STREAM", "UNITS", "INSTRUMENT", "INSTRUMENT_ANALOG/DIGITAL",
    "INSTRUMENTAL_FREQUENCY_HZ", "INSTRUMENTAL_DAMPING", "FULL_SCALE_G", "N_BIT_DIGITAL_CONVERTER", "PGA_CM/S^2",
    "TIME_PGA_S", "BASELINE_CORRECTION", "FILTER_TYPE", "FILTER_ORDER", "LOW_CUT_FREQUENCY_HZ",
    "HIGH_CUT_FREQUENCY_HZ", "LATE/NORMAL_TRIGGERED", "DATABASE_VERSION", "HEADER_FORMAT", "DATA_TYPE", "PROCESSING",
    "DATA_TIMESTAMP_YYYYMMDD_HHMMSS", "DATA_LICENSE", "DATA_CITATION", "DATA_CREATOR",
    "ORIGINAL_DATA_MEDIATOR_CITATION", "ORIGINAL_DATA_MEDIATOR", "ORIGINAL_DATA_CREATOR_CITATION",
    "ORIGINAL_DATA_CREATOR", "USER1", "USER2", "USER3", "USER4", "USER5",
)  # fmt: skip


def esm_text(accel_cm_s2: np.ndarray, dt_s: float, fields: dict[str, str] | None = None) -> str:
    """A record in ESM's ASCII layout (module docstring): the 64 header keys (those not in
    ``fields`` empty, but SAMPLING_INTERVAL_S, NDATA, DURATION_S, UNITS = cm/s^2, PGA_CM/S^2,
    TIME_PGA_S, HEADER_FORMAT and DATA_TYPE = ACCELERATION from the data), then one value a line
    in cm/s^2. For synthetic example records and tests: rockyade reads records, it does not
    convert them.

    Parameters
    ----------
    accel_cm_s2
        The acceleration, cm/s^2.
    dt_s
        The sampling interval, s.
    fields
        Header values to set (e.g. EVENT_ID, STATION_CODE, STREAM, PROCESSING).
    """
    a = np.asarray(accel_cm_s2, dtype=float)
    peak = int(np.argmax(np.abs(a)))
    values = {
        "SAMPLING_INTERVAL_S": f"{dt_s:.6f}",
        "NDATA": str(a.size),
        "DURATION_S": f"{a.size * dt_s:.3f}",
        "UNITS": "cm/s^2",
        "PGA_CM/S^2": f"{a[peak]:.6f}",
        "TIME_PGA_S": f"{peak * dt_s:.6f}",
        "HEADER_FORMAT": "DYNA 1.2",
        "DATA_TYPE": "ACCELERATION",
        **(fields or {}),
    }
    header = [f"{key}: {values.get(key, '')}".rstrip() for key in DYNA_KEYS]
    return "\n".join([*header, *(f"{v:.6e}" for v in a)]) + "\n"


__all__ = ["DYNA_KEYS", "esm_text", "is_esm_header", "read_esm"]
