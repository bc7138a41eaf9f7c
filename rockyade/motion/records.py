"""Readers of recorded accelerograms: a record is read exactly, or refused.

* PEER NGA ``.AT2``: four header lines (database, event/station, quantity and units,
  sampling), then the values in free format. The sampling line comes as
  ``NPTS=  5372, DT=   .0100 SEC,`` with or without the commas and trailing text, or in the
  old layout ``  4000   .0100   NPTS, DT`` (two numbers first). CRLF line ends are
  accepted. The units line names G, CM/S/S (or CM/SEC/SEC, GAL) or M/S/S. The file must
  hold exactly NPTS values: fewer, or a last value cut short (it lacks the digits or the
  exponent every other value has), is refused as truncated; more is refused as a header
  that disagrees with its data.
* PEER velocity (VT2) and displacement (DT2) files, in either header layout
  (:mod:`rockyade.motion.peer`), are refused whatever their extension, format or ``units``:
  rockyade needs accelerations. A PEER acceleration file is read as AT2 whatever its
  extension.
* Two-column text or CSV: time (s) and acceleration, one separator per line (semicolons,
  else commas, else blanks; decimal commas read where unambiguous,
  :mod:`rockyade.motion.text_columns`), ``#`` comments, an optional header line whose
  acceleration column may name its units (``accel_g``, ``a (cm/s2)``, ``accel_m_s2``, ...).
  A line with one number or with three or more is refused, saying what it holds; more
  columns are read only when a header names each of them and the second as an
  acceleration (``t_s,accel_m_s2,vel_m_s,disp_m``, as ``rockyade motion synth`` writes).
* Single-column text: one acceleration per line at a given ``dt_s``; a file given ``dt_s``
  but no format is read as one column when its first data line holds one number.
* ESM's ASCII records (``KEY: value`` header, then one value a line): :mod:`rockyade.motion.esm`.

Numbers are ASCII decimals, with an optional exponent written E or Fortran's D
(``1.0D-02``); ``1_0``, non-ASCII digits, ``inf`` and ``nan`` are refused. A UTF-8 byte
order mark is skipped. Units named by the file win: a different ``units`` argument is
refused as a conflict, and so is a ``dt_s`` that disagrees with the file's own sampling.
Values in g are converted with standard gravity, 9.80665 m/s^2
(:data:`rockyade.constants.STANDARD_GRAVITY`). Every bad file raises
:class:`RecordError` naming the file and the line.
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import numpy as np

from rockyade.constants import STANDARD_GRAVITY
from rockyade.errors import InputError
from rockyade.motion.peer import PeerHeader, peer_header
from rockyade.motion.record_text import (
    DT_RANGE_S,
    MAX_RECORD_SAMPLES,
    NUMBER_PATTERN,
    UNITS,
    Record,
    RecordError,
    accel_si,
    check_dt,
    check_not_cut,
    number_at,
    parse_number,
    read_text,
    resolve_units,
)
from rockyade.motion.text_columns import DECIMAL_COMMA, split_columns, with_point

FORMATS = ("at2", "csv", "single", "esm")
#: How the options that fix a file's reading are spelt in a scene and on the command line.
SINGLE_HINT = 'format = "single" and its sampling interval dt_s (rockyade motion: --format single --dt)'
TWO_COLUMN_HINT = 'format = "csv" (or no format) and no dt_s (rockyade motion: --format csv)'


def _parse_at2_sampling(line: str, path: Path, lineno: int) -> tuple[int, float]:
    """NPTS and DT from the fourth AT2 header line (new or old layout)."""
    upper = line.upper()
    m_n = re.search(r"NPTS\s*=\s*(\S+?)(?:[,\s]|$)", upper)
    m_dt = re.search(r"DT\s*=\s*(\S+?)(?:[,\s]|$)", upper)
    if m_n or m_dt:
        if not m_n:
            raise RecordError(path, lineno, "header has DT= but no NPTS=")
        if not m_dt:
            raise RecordError(path, lineno, "header has NPTS= but no DT=")
        npts_text, dt_text = m_n.group(1), m_dt.group(1)
    else:
        numbers = re.findall(NUMBER_PATTERN, upper, re.ASCII)
        if len(numbers) < 2:
            raise RecordError(path, lineno, f"expected 'NPTS=..., DT=... SEC' or 'NPTS DT', got {line.strip()!r}")
        npts_text, dt_text = numbers[0], numbers[1]
    npts_f, dt = parse_number(npts_text), parse_number(dt_text)
    if npts_f is None or dt is None:
        raise RecordError(path, lineno, f"expected 'NPTS=..., DT=... SEC' or 'NPTS DT', got {line.strip()!r}")
    if not math.isfinite(npts_f) or npts_f != int(npts_f) or npts_f < 2:
        raise RecordError(path, lineno, f"NPTS must be an integer >= 2, got {npts_text}")
    if npts_f > MAX_RECORD_SAMPLES:
        raise RecordError(path, lineno, f"NPTS must be at most {MAX_RECORD_SAMPLES}, got {npts_text}")
    if not dt > 0:
        raise RecordError(path, lineno, f"DT must be > 0 s, got {dt_text}")
    if not DT_RANGE_S[0] <= dt <= DT_RANGE_S[1]:
        raise RecordError(path, lineno, f"DT must be in [{DT_RANGE_S[0]:g}, {DT_RANGE_S[1]:g}] s, got {dt_text}")
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


def _head_lines(path: Path, count: int = 64) -> list[str]:
    """The first ``count`` lines of a file (at most 64 KiB read), for format detection."""
    try:
        with path.open("rb") as fh:
            data = fh.read(1 << 16)
    except OSError:
        return []
    text = data.decode("utf-8-sig", errors="replace").replace("\r\n", "\n").replace("\r", "\n")
    return text.split("\n")[:count]


def _refuse_other_quantities(path: Path, lines: list[str], fmt: str) -> PeerHeader | None:
    """Refuse a PEER velocity or displacement file, and a PEER acceleration file read as text
    columns; return the PEER header of an acceleration file (None when there is none)."""
    header = peer_header(lines)
    if header is None:
        return None
    if header.quantity != "acceleration":
        raise RecordError(path, header.line, header.refusal())
    if fmt != "at2":
        raise RecordError(
            path,
            header.line,
            f"{header.description}, not {'two columns' if fmt == 'csv' else 'one column'}: "
            'read it with format = "at2" (or no format; rockyade motion: --format at2)',
        )
    return header


def read_at2(path: str | Path, units: str | None = None, dt_s: float | None = None) -> Record:
    """Read a PEER NGA AT2 file (see module docstring).

    Parameters
    ----------
    path
        The file.
    units
        Units of the values when the header does not name them (g, m/s2, cm/s2); if the
        header names other units the file is refused as a conflict.
    dt_s
        Optional sampling interval, s: refused unless it equals the header's DT.
    """
    path = Path(path)
    text = read_text(path)
    lines = text.split("\n")
    _refuse_other_quantities(path, lines, "at2")
    if len(lines) < 5:
        raise RecordError(path, len(lines), "an AT2 file needs 4 header lines and data")
    npts, dt = _parse_at2_sampling(lines[3], path, 4)
    file_units = resolve_units(path, 3, _at2_units(lines[2]), units)
    if not file_units:
        raise RecordError(
            path,
            3,
            f"cannot tell the units from {lines[2].strip()!r}: give them with --units g, m/s2 or cm/s2 (a scene: "
            'units = "g" in its [motion])',
        )
    check_dt(path, 4, dt, dt_s, "the header says DT =")
    tokens: list[tuple[str, int]] = []
    values: list[float] = []
    extra = 0  # values after the NPTS-th
    first_extra_line = 0
    for lineno, line in enumerate(lines[4:], start=5):
        parts = line.replace(",", " ").split()
        if len(values) == npts:
            if parts and not extra:
                first_extra_line = lineno
            extra += len(parts)
            continue
        take = parts[: npts - len(values)]
        for token in take:
            values.append(number_at(path, lineno, token))
            tokens.append((token, lineno))
        if len(take) < len(parts):
            first_extra_line = lineno
            extra += len(parts) - len(take)
    if len(values) < npts:
        raise RecordError(
            path, len(lines), f"NPTS = {npts} in the header but the file holds {len(values)} values: truncated?"
        )
    if extra:
        raise RecordError(
            path,
            first_extra_line,
            f"NPTS = {npts} in the header but the file holds {npts + extra} values (value {npts + 1} is on line "
            f"{first_extra_line}): the header and the data disagree; fix NPTS or remove the extra values",
        )
    check_not_cut(path, tokens, True)
    accel = accel_si(path, values, file_units)
    title = lines[1].strip()
    return Record(np.arange(npts) * dt, accel, file_units, str(path), title, {"format": "at2", "dt_file_s": dt})


def _split(line: str) -> list[str]:
    return [t for t in re.split(r"[,;\s]+", line.strip()) if t]


def _header_names(line: str) -> list[str]:
    """Column names of a header: split at commas, semicolons or tabs if it has any, else at
    spaces, where a unit in brackets stays with its name (``time [s]  accel (g)``)."""
    if re.search(r"[,;\t]", line):
        return [p.strip() for p in re.split(r"[,;\t]", line) if p.strip()]
    names: list[str] = []
    for word in line.split():
        if names and word[0] in "([":
            names[-1] += f" {word}"
        else:
            names.append(word)
    return names


def _is_header(tokens: list[str]) -> bool:
    """A header line: words only. A token that starts like a number (``1_0``, ``1.2x``, a
    non-ASCII digit) makes it a data line with a typo, reported as such."""
    return all(parse_number(t) is None and not (t[0].isdigit() or t[0] in "+-.") for t in tokens)


_HEADER_UNITS = (
    (re.compile(r"cm\s*/\s*s(?:ec)?\s*(?:\^?2|²|/\s*s(?:ec)?)|cm_s2|\bgals?\b", re.I), "cm/s2"),
    (re.compile(r"(?<![a-z])m\s*/\s*s(?:ec)?\s*(?:\^?2|²|/\s*s(?:ec)?)|(?<![a-z])m_s2|mps2", re.I), "m/s2"),
    (re.compile(r"(?:^|[_\s(\[])g(?:$|[)\]\s])|\bin\s+g\b", re.I), "g"),
)


def header_units(name: str) -> str | None:
    """Units named by a column header (``accel_g``, ``a (cm/s2)``, ``accel_m_s2``), or None."""
    for pattern, unit in _HEADER_UNITS:
        if pattern.search(name):
            return unit
    return None


#: Column names of a velocity or a displacement (when they name no acceleration unit).
_OTHER_QUANTITY = (
    (
        re.compile(
            r"(?<![a-z])vel(?:ocity)?(?![a-z])|(?<![a-z])c?m\s*/\s*s(?:ec)?(?![a-z0-9^/²])|(?<![a-z])c?m_s(?![a-z0-9])",
            re.I,
        ),
        "a velocity",
    ),
    (re.compile(r"(?<![a-z])disp(?:lacement)?(?![a-z])|\(\s*c?mm?\s*\)|(?<![a-z])c?mm?$", re.I), "a displacement"),
)


def _check_header_quantity(path: Path, line: int, name: str) -> None:
    """Refuse an acceleration column whose header names a velocity or a displacement."""
    if header_units(name) is not None:
        return
    for pattern, what in _OTHER_QUANTITY:
        if pattern.search(name):
            raise RecordError(
                path, line, f"the acceleration column is headed {name!r}, {what}: rockyade needs accelerations"
            )


def _columns(path: Path, lineno: int, body: str) -> list[str]:
    """The columns of a data line; an empty column (two separators in a row) is refused."""
    columns, separator = split_columns(body)
    if len(columns) > 1 and "" in columns:
        raise RecordError(path, lineno, f"an empty column between two {separator}s in {body!r}")
    return columns


def _column_read(
    path: Path,
    count: int,
    column: list[tuple[str, int]],
    header_line: int | None,
    header_unit: str | None,
    units: str | None,
) -> str:
    """The checks a text column makes once read (2 to :data:`MAX_RECORD_SAMPLES` samples, its
    last value not cut off) and its unit: the header's or ``units`` (m/s2 when neither names one)."""
    if count < 2:
        raise RecordError(path, None, "fewer than 2 samples")
    if count > MAX_RECORD_SAMPLES:
        raise RecordError(path, None, f"more than {MAX_RECORD_SAMPLES} samples")
    check_not_cut(path, column, True)
    return resolve_units(path, header_line, header_unit, units) or "m/s2"


def read_two_column(path: str | Path, units: str | None = None, dt_s: float | None = None) -> Record:
    """Read time (s) and acceleration columns (module docstring: separators, decimal commas).

    Parameters
    ----------
    units
        Units of the accelerations when the header does not name them (default m/s2); a
        header naming other units is refused as a conflict.
    dt_s
        Optional sampling interval, s: refused unless the times are spaced by it.
    """
    path = Path(path)
    lines = read_text(path).split("\n")
    _refuse_other_quantities(path, lines, "csv")
    times: list[float] = []
    accel: list[float] = []
    column: list[tuple[str, int]] = []
    header_unit: str | None = None
    header_line: int | None = None
    seen_data = False
    comma_numbers = True  # every data line is one number written with a decimal comma
    width: int | None = None  # values a line holds: two, or as many as a header names (first data line)
    names: list[str] = []
    for lineno, line in enumerate(lines, start=1):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        if not seen_data and header_line is None and _is_header(_split(body)):
            header_line = lineno  # a header: names only, no number at all
            names = _header_names(body)
            if len(names) >= 2:
                header_unit = header_units(names[1])
                _check_header_quantity(path, lineno, names[1])
            continue
        comma_numbers = comma_numbers and bool(DECIMAL_COMMA.match(body))
        columns = _columns(path, lineno, body)
        if len(columns) == 1:
            if seen_data:
                raise RecordError(path, lineno, f"holds one number ({body!r}) where the lines before hold two")
            raise RecordError(
                path,
                lineno,
                f"holds one number ({body!r}), not two columns (time, acceleration): "
                f"a one-column file needs {SINGLE_HINT}",
            )
        if width is None:
            width = 2 if len(columns) == 2 else _named_width(path, lineno, body, columns, names, header_line)
        if len(columns) != width:
            if width == 2:
                raise RecordError(path, lineno, _too_many_columns(body, columns))
            before = f"where the lines before hold {width}"
            raise RecordError(path, lineno, f"holds {len(columns)} values ({body!r}) {before}")
        seen_data = True
        times.append(number_at(path, lineno, columns[0], "time"))
        accel.append(number_at(path, lineno, columns[1]))
        column.append((columns[1], lineno))
    unit = _column_read(path, len(times), column, header_line, header_unit, units)
    t = np.asarray(times)
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if bad.size:
        message = f"time must increase strictly (sample {int(bad[0]) + 2})"
        if comma_numbers:
            message += (
                f"; every line looks like one number written with a decimal comma ({column[0][0]!r} after the "
                f"comma): a one-column file needs {SINGLE_HINT}"
            )
        raise RecordError(path, column[int(bad[0]) + 1][1], message)
    if dt_s is not None:
        steps = np.diff(t)
        worst = int(np.argmax(np.abs(steps - dt_s)))
        check_dt(path, column[worst + 1][1], float(steps[worst]), dt_s, "the time column steps by")
    a = accel_si(path, accel, unit)
    return Record(t - t[0], a, unit, str(path), "", {"format": "csv"})


def _named_width(
    path: Path, line: int, body: str, columns: list[str], names: list[str], header_line: int | None
) -> int:
    """The width of a first data line of three columns or more: accepted only when a header
    names each column and the second as an acceleration (``t_s,accel_m_s2,vel_m_s,disp_m``, as
    ``rockyade motion synth`` writes), so that what is left out is known; refused otherwise."""
    if len(names) != len(columns):
        raise RecordError(path, line, _too_many_columns(body, columns))
    if header_units(names[1]) is None and not re.search(r"(?<![a-z])acc", names[1], re.I):
        raise RecordError(
            path,
            header_line,
            f"the header names {len(names)} columns ({', '.join(names)}) and the second, {names[1]!r}, is not named "
            "as an acceleration (e.g. accel_m_s2): a record's columns are time (s) and acceleration",
        )
    return len(columns)


def _too_many_columns(body: str, columns: list[str]) -> str:
    """The message for a line of three or more columns (a decimal comma among commas said so)."""
    message = (
        f"holds {len(columns)} columns ({body!r}); a two-column record holds time (s) and acceleration only: "
        "remove the other columns"
    )
    if "," in body and ";" not in body and "." not in body and len(columns) % 2 == 0:
        message += (
            "; if its numbers are written with decimal commas, the commas cannot also separate the columns: "
            "separate them with ';' or a tab"
        )
    return message


def read_single_column(path: str | Path, dt_s: float, units: str | None = None) -> Record:
    """Read one acceleration value per line, sampled at ``dt_s``.

    An optional first line without any number is a header (it may name the units). A value
    may be written with a decimal comma (``0,0123``): in a one-column file it can be nothing
    else.
    """
    path = Path(path)
    if not (isinstance(dt_s, (int, float)) and not isinstance(dt_s, bool) and math.isfinite(dt_s) and dt_s > 0):
        raise RecordError(path, None, f"dt must be > 0 s, got {dt_s!r}")
    if not DT_RANGE_S[0] <= dt_s <= DT_RANGE_S[1]:
        raise RecordError(path, None, f"dt must be in [{DT_RANGE_S[0]:g}, {DT_RANGE_S[1]:g}] s, got {dt_s!r}")
    lines = read_text(path).split("\n")
    _refuse_other_quantities(path, lines, "single")
    values: list[float] = []
    column: list[tuple[str, int]] = []
    header_unit: str | None = None
    header_line: int | None = None
    for lineno, line in enumerate(lines, start=1):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        if not values and header_line is None and _is_header(_split(body)):
            header_line, header_unit = lineno, header_units(body)
            _check_header_quantity(path, lineno, body)
            continue
        token = with_point(body)
        if token == body:
            columns = _columns(path, lineno, body)
            if len(columns) > 1:
                raise RecordError(
                    path,
                    lineno,
                    f"holds {len(columns)} numbers ({body!r}); a one-column file holds one acceleration per line: "
                    f"for time and acceleration columns use {TWO_COLUMN_HINT}",
                )
        values.append(number_at(path, lineno, token))
        column.append((token, lineno))
    unit = _column_read(path, len(values), column, header_line, header_unit, units)
    a = accel_si(path, values, unit)
    return Record(np.arange(a.size) * dt_s, a, unit, str(path), "", {"format": "single"})


def count_samples(path: str | Path, fmt: str | None = None) -> int:
    """Samples a record file holds, without reading its values: NPTS of an AT2 header, the
    line count of a text file (an upper bound). For cost estimates."""
    path = Path(path)
    fmt = fmt or detect_format(path)
    try:
        if fmt == "at2":
            with path.open("rb") as fh:
                head = [fh.readline(4096).decode("latin-1") for _ in range(4)]
            return _parse_at2_sampling(head[3], path, 4)[0]
        with path.open("rb") as fh:
            return sum(chunk.count(b"\n") for chunk in iter(lambda: fh.read(1 << 20), b"")) + 1
    except (OSError, IndexError):
        return 0


def detect_format(path: str | Path, dt_s: float | None = None) -> str:
    """The format of a record file from its content, else its extension.

    ``at2`` for a PEER header (whatever the extension) or a ``.AT2`` file; ``esm`` for an ESM
    header; ``single`` when ``dt_s`` is given and the first data line holds one number; ``csv`` otherwise.
    """
    from rockyade.motion.esm import is_esm_header

    path = Path(path)
    head = _head_lines(path)
    if path.suffix.lower() == ".at2" or peer_header(head) is not None:
        return "at2"
    if is_esm_header(head):
        return "esm"
    if dt_s is not None:
        for line in head:
            body = line.split("#", 1)[0].strip()
            if body and not _is_header(_split(body)):
                return "single" if len(split_columns(body)[0]) == 1 else "csv"
    return "csv"


def read_record(
    path: str | Path, fmt: str | None = None, units: str | None = None, dt_s: float | None = None
) -> Record:
    """Read any supported record file.

    Parameters
    ----------
    path
        The file.
    fmt
        "at2", "csv" (two columns), "single" (one column, needs ``dt_s``) or "esm"; default from
        the content (:func:`detect_format`).
    units
        Units of the values when the file does not name them (default m/s2 for text
        files); units the file names win, and a different value here is refused.
    dt_s
        Sampling interval for single-column files, s; with an AT2 or two-column file it must
        agree with the file's own sampling.
    """
    if fmt is not None and fmt not in FORMATS:
        raise InputError("format", f"must be one of {', '.join(FORMATS)}, got {fmt!r}")
    fmt = fmt or detect_format(path, dt_s)
    if fmt in ("at2", "esm"):
        from rockyade.motion.esm import read_esm

        record = (read_at2 if fmt == "at2" else read_esm)(path, units, dt_s)
    elif fmt == "csv":
        record = read_two_column(path, units, dt_s)
    elif dt_s is None:
        raise InputError("dt_s", f"a one-column record needs its sampling interval: {SINGLE_HINT}")
    else:
        record = read_single_column(path, dt_s, units)
    _warn_implausible(record, given=units)
    return record


#: A PGA outside this range, in g, is not that of a record worth a rocking analysis (the strongest
#: recorded reach about 4 g; below 1e-3 g a motion is felt by few and rocks nothing): values in g read as
#: cm/s2 come out 981 times too small (0.5 g as 0.0005 g, below 1e-3 g: a lower bound of 1e-4 g would
#: miss it), values in cm/s2 read as m/s2 or g 100 or 981 times too large (470 cm/s2 as 48 g).
PLAUSIBLE_PGA_G = (1.0e-3, 5.0)
_WARNED: set[str] = set()


def units_warning(record: Record, given: str | None = None) -> str | None:
    """Why ``record``'s units look wrong (its PGA outside :data:`PLAUSIBLE_PGA_G`), or None.

    Parameters
    ----------
    record
        The record read.
    given
        The units given to the reader (None: the file's own, or the default m/s2).
    """
    pga_g = record.pga_m_s2 / STANDARD_GRAVITY
    low, high = PLAUSIBLE_PGA_G
    if low <= pga_g <= high:
        return None
    side = f"above {high:g} g, more than any record" if pga_g > high else f"below {low:g} g, less than any record"
    unit = record.units_in_file
    if given is None:
        how = f"read as {unit} (the file's own units, or the default m/s2)"
    else:
        how = f"read as {unit} (as given)"
    peak = float(np.max(np.abs(record.accel_m_s2))) / UNITS[unit]  # the file's largest value as written
    guesses = [
        f"{name}: PGA {peak * factor / STANDARD_GRAVITY:.3g} g" for name, factor in UNITS.items() if name != unit
    ]
    return (
        f"{record.source}: PGA = {pga_g:.3g} g {how}, {side}: are the units right? the same values in "
        f"{'; in '.join(guesses)}. Give the units with --units (a scene: units in its [motion]); a units line "
        "in the file wins over --units, so fix a wrong one in the file"
    )


def _warn_implausible(record: Record, given: str | None) -> None:
    """Print :func:`units_warning` once per file and process (stderr: the answer on stdout stays clean)."""
    message = units_warning(record, given)
    if message is None or record.source in _WARNED:
        return
    _WARNED.add(record.source)
    print(f"rockyade: warning: {message}", file=sys.stderr, flush=True)
