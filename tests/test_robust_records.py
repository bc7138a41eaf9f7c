"""Records are read exactly, or refused naming the file and the line."""

from __future__ import annotations

import numpy as np
import pytest

from rockyade.constants import STANDARD_GRAVITY
from rockyade.errors import InputError
from rockyade.motion.records import RecordError, read_at2, read_record, read_single_column, read_two_column

VALUES = [0.0012345, -0.0023456, 0.0345678, -0.0456789, 0.0056789, -0.0067891, 0.0078912]


def _at2(path, values=VALUES, sampling="NPTS=    7, DT=   .0100 SEC,", fmt="{:15.7E}", per_line=5):
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "Test, 1/1/2000, station, 000",
        "ACCELERATION TIME SERIES IN UNITS OF G",
        sampling,
    ]
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


# ---------------------------------------------------------------------- PEER velocity and displacement files

PEER_LAYOUTS = {
    # NGA-West2: "TIME SERIES", NPTS=..., DT=...
    "NGA-West2": (
        "PEER NGA STRONG MOTION DATABASE RECORD",
        "{q} TIME SERIES IN UNITS OF {u}",
        "NPTS=    7, DT=   .0100 SEC,",
    ),
    # the older PEER layout: "TIME HISTORY", the numbers first
    "older PEER": (
        "PACIFIC ENGINEERING AND ANALYSIS STRONG-MOTION DATA",
        "{q} TIME HISTORY IN UNITS OF {u}",
        "    7    0.0100    NPTS, DT",
    ),
}
QUANTITIES = {"VELOCITY": ("CM/SEC", "velocity", "VT2", "cm/s"), "DISPLACEMENT": ("CM", "displacement", "DT2", "cm")}


def _peer(path, layout, quantity, units):
    first, third, fourth = PEER_LAYOUTS[layout]
    lines = [first, "Test, 1/1/2000, station, 000", third.format(q=quantity, u=units), fourth]
    lines += ["".join(f"{v:15.7E}" for v in VALUES[i : i + 5]) for i in range(0, len(VALUES), 5)]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("layout", sorted(PEER_LAYOUTS))
@pytest.mark.parametrize("quantity", sorted(QUANTITIES))
def test_peer_velocity_and_displacement_files_are_refused_whatever_their_name_format_and_units(
    tmp_path, layout, quantity
):
    """A VT2 named .AT2 ran as an acceleration once units = "cm/s2" was given (theta = 0); named
    .VT2 it failed on 'line 2: not a number'. Now each says what the file is."""
    written, word, extension, unit = QUANTITIES[quantity]
    for suffix in (".AT2", f".{extension}", ".txt", ".csv"):
        path = _peer(tmp_path / f"r{suffix}", layout, quantity, written)
        for fmt in (None, "at2", "csv", "single"):
            for units in (None, "cm/s2", "g"):
                with pytest.raises(RecordError) as info:
                    read_record(path, fmt, units, dt_s=0.01)
                message = str(info.value)
                assert info.value.line == 3, message
                assert f"a PEER {word} record ({extension}, {unit}, {layout} layout)" in message, message
                assert "rockyade needs an acceleration record (AT2" in message


@pytest.mark.parametrize("layout", sorted(PEER_LAYOUTS))
def test_a_peer_acceleration_file_is_read_as_at2_whatever_its_extension(tmp_path, layout):
    expected = np.array([float(f"{v:15.7E}") for v in VALUES]) * STANDARD_GRAVITY
    for suffix in (".AT2", ".VT2", ".txt", ".dat"):
        rec = read_record(_peer(tmp_path / f"r{suffix}", layout, "ACCELERATION", "G"))
        np.testing.assert_array_equal(rec.accel_m_s2, expected)
        assert rec.dt_s == pytest.approx(0.01)
    path = _peer(tmp_path / "r.txt", layout, "ACCELERATION", "G")
    with pytest.raises(RecordError, match=r'PEER acceleration record .*format = "at2"'):
        read_record(path, "csv")


def test_a_velocity_record_in_a_scene_is_refused_in_one_line(tmp_path, capsys):
    import json

    from rockyade.cli import main

    from .conftest import free_scene_dict

    _peer(tmp_path / "RSN1_vel.AT2", "NGA-West2", "VELOCITY", "CM/SEC")
    d = free_scene_dict()
    d["motion"] = {"type": "record", "file": "RSN1_vel.AT2", "units": "cm/s2"}
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps(d))
    assert main(["run", str(scene)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "a PEER velocity record (VT2, cm/s, NGA-West2 layout)" in err[0], err


def test_velocity_units_are_named_as_such():
    from rockyade.errors import InputError
    from rockyade.motion.record_text import normalise_units

    for units in ("cm/s", "CM/SEC", "m/s", "cm"):
        with pytest.raises(InputError, match="velocity unit: a record must hold accelerations"):
            normalise_units(units)


@pytest.mark.parametrize(
    "header",
    ["t_s,v_cm_s", "time, velocity (cm/s)", "t;disp (cm)", "t displacement_m"],
)
def test_a_text_file_whose_column_names_a_velocity_or_a_displacement_is_refused(tmp_path, header):
    path = tmp_path / "r.csv"
    path.write_text(f"{header}\n0,0.5\n0.01,0.25\n".replace(",", ";" if ";" in header else ","))
    with pytest.raises(RecordError, match=r"line 1: the acceleration column is headed .*, a (velocity|displacement)"):
        read_record(path)


# ---------------------------------------------------------------------- one column, European CSVs


def test_a_one_column_file_says_which_keys_read_it(tmp_path):
    path = tmp_path / "r.txt"
    path.write_text("0.5\n0.25\n-0.125\n")
    with pytest.raises(RecordError) as info:
        read_record(path)
    assert info.value.line == 1
    assert "holds one number ('0.5')" in str(info.value)
    assert 'a one-column file needs format = "single" and its sampling interval dt_s' in str(info.value)
    rec = read_record(path, dt_s=0.02)  # dt_s alone says it: read as one column
    np.testing.assert_array_equal(rec.accel_m_s2, [0.5, 0.25, -0.125])
    assert rec.dt_s == 0.02 and rec.extra["format"] == "single"
    with pytest.raises(InputError, match='dt_s: a one-column record needs its sampling interval: format = "single"'):
        read_record(path, "single")


def test_a_one_column_scene_record_needs_no_format_when_dt_s_is_given(tmp_path):
    from .conftest import free_scene_dict

    (tmp_path / "r.txt").write_text("accel_g\n0.05\n0.1\n-0.02\n0.0\n")
    d = free_scene_dict()
    d["motion"] = {"type": "record", "file": "r.txt", "dt_s": 0.01}
    from rockyade.scene import scene_from_dict

    scene = scene_from_dict(d, base_dir=tmp_path)
    gm = scene.motion.ground_motion(scene.duration_s)
    np.testing.assert_allclose(gm.ah_m_s2, np.array([0.05, 0.1, -0.02, 0.0]) * STANDARD_GRAVITY)


def test_a_two_column_file_read_as_one_column_says_so(tmp_path):
    path = tmp_path / "r.txt"
    path.write_text("0.0 0.5\n0.01 0.25\n")
    with pytest.raises(RecordError) as info:
        read_record(path, "single", dt_s=0.01)
    assert info.value.line == 1 and "holds 2 numbers ('0.0 0.5')" in str(info.value)
    assert 'format = "csv"' in str(info.value)


@pytest.mark.parametrize(
    "text",
    [
        "t_s;accel_g\n0,00;0,0123\n0,01;-0,0234\n0,02;0,5001\n",  # semicolons and decimal commas (Excel, Europe)
        "t_s;accel_g\n0.00;0.0123\n0.01;-0.0234\n0.02;0.5001\n",  # semicolons and points
        "t_s\taccel_g\n0,00\t0,0123\n0,01\t-0,0234\n0,02\t0,5001\n",  # tabs and decimal commas
        "t_s accel_g\n0 0,0123\n0,01 -2,34E-02\n0,02 0,5001\n",  # blanks, decimal commas, a bare 0
        "t_s,accel_g\n0.00,0.0123\n0.01,-0.0234\n0.02,0.5001\n",  # plain CSV
    ],
)
def test_european_csv_files_are_read_exactly(tmp_path, text):
    """A semicolon or decimal-comma CSV gave a misleading 'time must increase strictly'."""
    path = tmp_path / "r.csv"
    path.write_text(text)
    rec = read_record(path)
    np.testing.assert_array_equal(rec.t_s, [0.0, 0.01, 0.02])
    np.testing.assert_array_equal(rec.accel_m_s2, np.array([0.0123, -0.0234, 0.5001]) * STANDARD_GRAVITY)


def test_decimal_commas_between_comma_separators_are_refused_naming_the_separator(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("0,00,0,0123\n0,01,-0,0234\n")
    with pytest.raises(RecordError) as info:
        read_record(path)
    message = str(info.value)
    assert info.value.line == 1 and "holds 4 columns ('0,00,0,0123')" in message
    assert "decimal commas, the commas cannot also separate the columns: separate them with ';' or a tab" in message


def test_a_one_column_decimal_comma_file_read_as_two_columns_says_what_it_looks_like(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("0,5\n0,25\n-0,125\n")
    with pytest.raises(RecordError) as info:
        read_record(path)
    assert "one number written with a decimal comma" in str(info.value) and 'format = "single"' in str(info.value)
    rec = read_record(path, "single", dt_s=0.01)
    np.testing.assert_array_equal(rec.accel_m_s2, [0.5, 0.25, -0.125])


# ---------------------------------------------------------------------- parts that disagree


def test_at2_with_more_values_than_npts_is_refused_naming_the_line(tmp_path):
    """NPTS = 501 over 1,001 values dropped half the record."""
    values = np.round(np.sin(np.arange(1001) * 0.01), 7) * 0.1
    path = _at2(tmp_path / "r.AT2", values=list(values), sampling="NPTS=  501, DT=   .0100 SEC,")
    with pytest.raises(RecordError) as info:
        read_at2(path)
    message = str(info.value)
    assert "NPTS = 501 in the header but the file holds 1001 values" in message
    assert info.value.line == 4 + 501 // 5 + 1 and f"line {info.value.line}" in message


@pytest.mark.parametrize("header", ["", "t_s,accel_g\n"])
def test_a_third_column_is_refused_naming_the_line(tmp_path, header):
    path = tmp_path / "r.csv"
    path.write_text(f"{header}0.00,0.1\n0.01,0.2,0.9\n0.02,0.3\n")
    with pytest.raises(RecordError) as info:
        read_record(path)
    assert info.value.line == 2 + bool(header) and "holds 3 columns ('0.01,0.2,0.9')" in str(info.value)


def test_columns_a_header_names_are_read_and_rows_must_match_it(tmp_path):
    """``motion synth`` writes t_s, accel_m_s2, vel_m_s, disp_m: named, so the reader knows what
    it leaves out; a row with another count, or a second column not named as an acceleration,
    is refused."""
    path = tmp_path / "record_01.csv"
    path.write_text("t_s,accel_m_s2,vel_m_s,disp_m\n0.00,0.1,0,0\n0.01,0.2,0.001,0\n0.02,0.3,0.003,0.00001\n")
    np.testing.assert_array_equal(read_record(path).accel_m_s2, [0.1, 0.2, 0.3])
    path.write_text("t_s,accel_m_s2,vel_m_s,disp_m\n0.00,0.1,0,0\n0.01,0.2,0.001\n")
    with pytest.raises(RecordError, match=r"line 3: holds 3 values .* where the lines before hold 4"):
        read_record(path)
    path.write_text("t,v,a\n0.00,0.1,0\n0.01,0.2,0.001\n")
    with pytest.raises(RecordError, match=r"line 1: the header names 3 columns \(t, v, a\) and the second, 'v'"):
        read_record(path)
    path.write_text("t_s,accel_m_s2\n0.00,0.1,0\n0.01,0.2,0.001\n")  # a header of two over three columns
    with pytest.raises(RecordError, match=r"line 2: holds 3 columns"):
        read_record(path)
    path.write_text("time [s]   acceleration [g]\n0.00  0.1\n0.01  0.2\n")  # units in brackets stay with names
    np.testing.assert_array_equal(read_record(path).accel_m_s2, np.array([0.1, 0.2]) * STANDARD_GRAVITY)


def test_a_dt_that_disagrees_with_the_file_is_refused(tmp_path):
    at2 = _at2(tmp_path / "r.AT2")
    assert read_record(at2, dt_s=0.01).npts == 7
    with pytest.raises(RecordError, match=r"the header says DT = 0.01 s but dt_s = 0.02 s was given"):
        read_record(at2, dt_s=0.02)
    csv = tmp_path / "r.csv"
    csv.write_text("0.00,0.1\n0.01,0.2\n0.02,0.3\n")
    assert read_record(csv, dt_s=0.01).npts == 3
    with pytest.raises(RecordError, match=r"the time column steps by 0.01 s but dt_s = 0.005 s"):
        read_record(csv, dt_s=0.005)
