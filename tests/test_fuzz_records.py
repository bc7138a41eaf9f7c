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
        [b"\xef\xbb\xbf", b"D", b"E", b"d", b"1_0", b"\xd9\xa1", b"\xef\xbc\x91", b"nan", b"inf", b"1e400", b"-",
         b".", b" ", b"\n", b"\r", b",", b"#", b"NPTS=", b"DT=", b"1E400", b"\x00", b"\xff", b"9" * 30, b"0x10"]
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
def test_fuzz_damaged_records_never_crash(case):
    name, data = case
    rec = outcome("records damaged", lambda: _read(name, data))
    if rec is not None:
        assert rec.npts >= 2 and np.all(np.isfinite(rec.accel_m_s2)) and np.all(np.diff(rec.t_s) > 0)


@pytest.fixture(scope="module", autouse=True)
def _print_counts():
    yield
    for suite in ("records truncated", "records damaged"):
        print("\n" + report(suite))
