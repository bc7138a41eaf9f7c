"""Records are read exactly, or refused naming the file and the line."""

from __future__ import annotations

import numpy as np
import pytest

from rockyade.constants import STANDARD_GRAVITY
from rockyade.motion.records import RecordError, read_at2, read_record, read_single_column, read_two_column

VALUES = [0.0012345, -0.0023456, 0.0345678, -0.0456789, 0.0056789, -0.0067891, 0.0078912]


def _at2(path, values=VALUES, sampling="NPTS=    7, DT=   .0100 SEC,", fmt="{:15.7E}", per_line=5):
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "Test, 1/1/2000, station, 000",
             "ACCELERATION TIME SERIES IN UNITS OF G", sampling]
    for i in range(0, len(values), per_line):
        lines.append("".join(fmt.format(v) for v in values[i : i + per_line]))
    path.write_text("\n".join(lines) + "\n")
    return path


def test_at2_values_are_exact_in_standard_gravity(tmp_path):
    rec = read_at2(_at2(tmp_path / "r.AT2"))
    expected = np.array([float(f"{v:15.7E}") for v in VALUES]) * STANDARD_GRAVITY
    np.testing.assert_array_equal(rec.accel_m_s2, expected)


@pytest.mark.parametrize("cut", [1, 2, 4, 6, 9])
def test_at2_cut_inside_its_last_value_is_refused(tmp_path, cut):
    path = _at2(tmp_path / "r.AT2")
    text = path.read_text().rstrip("\n")
    path.write_text(text[:-cut])
    with pytest.raises(RecordError, match=r"truncated|not a number|holds 6 values") as info:
        read_at2(path)
    assert str(path) in str(info.value)


def test_at2_with_fewer_values_than_npts(tmp_path):
    path = _at2(tmp_path / "r.AT2", sampling="NPTS=    9, DT=   .0100 SEC,")
    with pytest.raises(RecordError, match="NPTS = 9 in the header but the file holds 7 values: truncated"):
        read_at2(path)


@pytest.mark.parametrize(
    ("sampling", "match"),
    [
        ("NPTS= 7, DT= 1E400 SEC", "DT must be in"),
        ("NPTS= 1E400, DT= .01 SEC", "NPTS must be an integer"),
        ("NPTS= 1_0, DT= .01 SEC", "expected 'NPTS="),
        ("NPTS= \u0667, DT= .01 SEC", "expected 'NPTS="),
        ("NPTS= 7, DT= 0 SEC", "DT must be > 0"),
        ("NPTS= 99999999999, DT= .01 SEC", "at most"),
    ],
)
def test_at2_header_numbers_are_exact_or_refused(tmp_path, sampling, match):
    with pytest.raises(RecordError, match=match) as info:
        read_at2(_at2(tmp_path / "r.AT2", sampling=sampling))
    assert info.value.line == 4


@pytest.mark.parametrize("bad", ["1_0", "\u0661.5", "\uff11.0", "inf", "nan", "1.0x", "0x10", "1e400"])
def test_odd_numbers_in_the_data_are_refused(tmp_path, bad):
    path = _at2(tmp_path / "r.AT2")
    lines = path.read_text().split("\n")
    lines[5] = lines[5].replace(f"{VALUES[5]:15.7E}".strip(), bad)
    path.write_text("\n".join(lines), encoding="utf-8")
    with pytest.raises(RecordError) as info:
        read_at2(path)
    assert info.value.line == 6 and bad in str(info.value)


def test_fortran_d_exponent_is_read(tmp_path):
    path = _at2(tmp_path / "r.AT2", fmt="{:15.7E}")
    path.write_text(path.read_text().replace("E-", "D-"))
    np.testing.assert_array_equal(read_at2(path).accel_m_s2, read_at2(_at2(tmp_path / "e.AT2")).accel_m_s2)
    two = tmp_path / "two.txt"
    two.write_text("0.0 1.0D-02\n0.01 2.0d-02\n0.02 -3.0D-02\n")
    np.testing.assert_array_equal(read_two_column(two).accel_m_s2, [0.01, 0.02, -0.03])


@pytest.mark.parametrize("reader", ["two", "single"])
def test_first_line_is_never_dropped(tmp_path, reader):
    path = tmp_path / "r.txt"
    rows = ["0.0 0.5", "0.01 0.25", "0.02 -0.125"] if reader == "two" else ["0.5", "0.25", "-0.125"]

    def read(text: str):
        path.write_bytes(text.encode("utf-8"))
        return read_two_column(path) if reader == "two" else read_single_column(path, 0.01)

    expected = [0.5, 0.25, -0.125]
    np.testing.assert_array_equal(read("\n".join(rows)).accel_m_s2, expected)
    np.testing.assert_array_equal(read("\ufeff" + "\n".join(rows)).accel_m_s2, expected)  # a UTF-8 BOM
    np.testing.assert_array_equal(read("\n".join(rows).replace("0.5", "5.0D-01")).accel_m_s2, expected)
    typo = rows[0].replace("0.5", "0.5x")
    with pytest.raises(RecordError) as info:
        read("\n".join([typo, *rows[1:]]))
    assert info.value.line == 1 and str(path) in str(info.value) and "0.5x" in str(info.value)
    with pytest.raises(RecordError, match="line 1"):
        read("\n".join([rows[0].replace("0.5", "1_0"), *rows[1:]]))


def test_two_column_cut_inside_its_last_value(tmp_path):
    path = tmp_path / "r.csv"
    rows = [f"{0.01 * i:.2f},{v:.7E}" for i, v in enumerate(VALUES)]
    path.write_text("\n".join(rows)[:-4])  # 7.8912000E-03 -> 7.8912000
    with pytest.raises(RecordError, match="truncated") as info:
        read_two_column(path)
    assert info.value.line == 7


def test_accelerations_beyond_a_hundred_g_are_refused(tmp_path):
    path = tmp_path / "r.txt"
    path.write_text("0 1\n0.01 2000\n0.02 3\n")
    with pytest.raises(RecordError, match="wrong units"):
        read_record(path)


def test_units_in_the_header_of_a_text_file(tmp_path):
    for header, factor in (("t_s,accel_g", STANDARD_GRAVITY), ("t (s), a (cm/s2)", 0.01), ("time accel_m_s2", 1.0)):
        path = tmp_path / "r.csv"
        path.write_text(f"{header}\n0,0.5\n0.01,0.25\n")
        np.testing.assert_array_equal(read_record(path).accel_m_s2, np.array([0.5, 0.25]) * factor)
