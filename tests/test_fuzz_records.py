"""Fuzzing the record readers: damaged AT2, two-column and one-column files are read
exactly or refused with a RecordError naming the file; a truncated file is never read as if
whole (data lost), never a traceback, never a hang."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rockyade.constants import STANDARD_GRAVITY
from rockyade.motion.records import read_record

from .fuzzing import COUNTS, fuzz_settings, outcome, report

RNG = np.random.default_rng(11)
VALUES = np.round(RNG.normal(0.0, 0.05, 47), 9)
AT2_TEXT = (
    "PEER NGA STRONG MOTION DATABASE RECORD\nFuzz, 1/1/2000, station, 000\n"
    "ACCELERATION TIME SERIES IN UNITS OF G\n"
    f"NPTS=   {VALUES.size}, DT=   .0100 SEC,\n"
    + "\n".join("".join(f"{v:15.7E}" for v in VALUES[i : i + 5]) for i in range(0, VALUES.size, 5))
    + "\n"
)
CSV_TEXT = "t_s,accel_g\n" + "\n".join(f"{0.01 * i:.2f},{v:.7E}" for i, v in enumerate(VALUES)) + "\n"
SINGLE_TEXT = "accel_g\n" + "\n".join(f"{v:.7E}" for v in VALUES) + "\n"
FILES = {"r.AT2": AT2_TEXT, "r.csv": CSV_TEXT, "r.txt": SINGLE_TEXT}
EXACT_G = np.array([float(f"{v:.7E}") for v in VALUES]) * STANDARD_GRAVITY

PIECES = st.one_of(
    st.binary(max_size=6),
    st.sampled_from(
        [
            b"\xef\xbb\xbf",
            b"D",
            b"E",
            b"d",
            b"1_0",
            b"\xd9\xa1",
            b"\xef\xbc\x91",
            b"nan",
            b"inf",
            b"1e400",
            b"-",
            b".",
            b" ",
            b"\n",
            b"\r",
            b",",
            b"#",
            b"NPTS=",
            b"DT=",
            b"1E400",
            b"\x00",
            b"\xff",
            b"9" * 30,
            b"0x10",
        ]
    ),
)


def _read(name: str, data: bytes):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        path.write_bytes(data)
        return read_record(path, fmt="single" if name.endswith(".txt") else None, dt_s=0.01)


@fuzz_settings(300)
@given(name=st.sampled_from(sorted(FILES)), cut=st.integers(0, 10_000))
def test_fuzz_truncated_records_are_exact_or_refused(name, cut):
    full = FILES[name].encode()
    data = full[: cut % (len(full) + 1)]
    rec = outcome("records truncated", lambda: _read(name, data))
    if rec is None:
        return
    n = rec.npts
    ok = np.array_equal(rec.accel_m_s2, EXACT_G[:n])  # every value read is the value written
    if name == "r.AT2":
        ok = ok and n == VALUES.size  # NPTS says how many: a shorter read would lose data
    if not ok:
        COUNTS["records truncated"]["data lost"] += 1
        raise AssertionError(f"{name} cut at {len(data)} of {len(full)} bytes was read as {n} samples")


@st.composite
def damaged(draw: st.DrawFn) -> tuple[str, bytes]:
    name = draw(st.sampled_from(sorted(FILES)))
    data = bytearray(FILES[name].encode())
    for _ in range(draw(st.integers(1, 4))):
        pos = draw(st.integers(0, len(data)))
        op = draw(st.sampled_from(["insert", "delete", "overwrite"]))
        if op == "insert":
            data[pos:pos] = draw(PIECES)
        elif op == "delete":
            del data[pos : pos + draw(st.integers(1, 16))]
        else:
            piece = draw(PIECES)
            data[pos : pos + len(piece)] = piece
    return name, bytes(data)


@fuzz_settings(500)
@given(damaged())
@pytest.mark.slow
def test_fuzz_damaged_records_never_crash(case):
    name, data = case
    rec = outcome("records damaged", lambda: _read(name, data))
    if rec is not None:
        assert rec.npts >= 2 and np.all(np.isfinite(rec.accel_m_s2)) and np.all(np.diff(rec.t_s) > 0)


@pytest.fixture(scope="module", autouse=True)
def _print_counts():
    yield
    for suite in ("records truncated", "records damaged", "records random bytes", "records numeric text"):
        print("\n" + report(suite))


# ---------------------------------------------------------------------- random bytes and random numeric text


def _read_as(fmt: str | None, suffix: str, data: bytes, dt_s: float | None):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"r{suffix}"
        path.write_bytes(data)
        return read_record(path, fmt=fmt, dt_s=dt_s)


@fuzz_settings(300)
@given(
    data=st.binary(max_size=400),
    fmt=st.sampled_from([None, "at2", "csv", "single"]),
    suffix=st.sampled_from([".AT2", ".VT2", ".csv", ".txt"]),
    dt_s=st.sampled_from([None, 0.01]),
)
def test_fuzz_random_bytes_give_a_record_or_a_clean_error(data, fmt, suffix, dt_s):
    rec = outcome("records random bytes", lambda: _read_as(fmt, suffix, data, dt_s))
    if rec is not None:
        assert rec.npts >= 2 and np.all(np.isfinite(rec.accel_m_s2)) and np.all(np.diff(rec.t_s) > 0)


NUMBER_STYLES = ["{:.6f}", "{:.4E}", "{:g}", "{:.3e}", "{:.0f}"]


@st.composite
def numeric_text(draw: st.DrawFn) -> tuple[str, bytes]:
    """Lines of 1 to 3 random numbers, one separator and one number style per file (a few
    lines mixed), decimal commas or points, an optional header or PEER header."""
    columns = draw(st.integers(1, 3))
    rows = draw(st.integers(0, 12))
    separator = draw(st.sampled_from([",", ";", "\t", " ", ", ", " ; "]))
    comma = draw(st.booleans())
    style = draw(st.sampled_from(NUMBER_STYLES))
    lines = []
    if draw(st.booleans()):
        lines.append(separator.join(["t_s", "accel_g", "x"][:columns]))
    timed = draw(st.booleans())  # a first column of increasing times, as a real file has
    for row in range(rows):
        values = draw(st.lists(st.floats(-10.0, 10.0, allow_nan=False), min_size=columns, max_size=columns))
        if timed and columns > 1:
            values[0] = 0.25 * row
        if draw(st.integers(0, 9)) == 0:
            style = draw(st.sampled_from(NUMBER_STYLES))  # a line written otherwise
        words = [style.format(v) for v in values]
        if comma:
            words = [w.replace(".", ",") for w in words]
        lines.append(separator.join(words))
    name = draw(st.sampled_from(["r.csv", "r.txt", "r.AT2"]))
    return name, ("\n".join(lines) + "\n").encode()


@fuzz_settings(400)
@given(case=numeric_text(), fmt=st.sampled_from([None, "csv", "single"]), dt_s=st.sampled_from([None, 0.01]))
@pytest.mark.slow
def test_fuzz_random_numeric_text_gives_a_record_or_a_clean_error(case, fmt, dt_s):
    name, data = case
    rec = outcome("records numeric text", lambda: _read_as(fmt, Path(name).suffix, data, dt_s))
    if rec is not None:
        assert rec.npts >= 2 and np.all(np.isfinite(rec.accel_m_s2)) and np.all(np.diff(rec.t_s) > 0)


@fuzz_settings(200)
@given(
    values=st.lists(st.floats(-50.0, 50.0, allow_nan=False), min_size=2, max_size=30),
    separator=st.sampled_from([";", "\t", " ; ", "; "]),
)
def test_decimal_comma_files_read_as_their_point_twins(values, separator):
    """Semicolons or tabs with decimal commas (spreadsheets in much of Europe) give exactly the
    record the same numbers give written with points and commas."""
    rows = [(f"{0.01 * i:.2f}", f"{v:.6E}") for i, v in enumerate(values)]
    point = "t_s,accel_m_s2\n" + "\n".join(f"{t},{a}" for t, a in rows) + "\n"
    european = "t_s;accel_m_s2\n" + "\n".join(separator.join(w.replace(".", ",") for w in row) for row in rows) + "\n"
    a = _read_as(None, ".csv", point.encode(), None)
    b = _read_as(None, ".csv", european.encode(), None)
    np.testing.assert_array_equal(a.t_s, b.t_s)
    np.testing.assert_array_equal(a.accel_m_s2, b.accel_m_s2)
