"""ESM's ASCII records (the DYNA 1.2 layout Italian engineers download from esm-db.eu): read
exactly, with the integrity checks of the PEER reader, or refused naming the line and the key."""

from __future__ import annotations

import numpy as np
import pytest

from rockyade.assess.motions import records_in_folder
from rockyade.cli import main
from rockyade.motion.esm import DYNA_KEYS, esm_text, is_esm_header, read_esm
from rockyade.motion.records import RecordError, detect_format, read_record

FIELDS = {"EVENT_ID": "EMSC-20161030_0000029", "NETWORK": "IT", "STATION_CODE": "NRC", "STREAM": "HGE"}


def values(n: int = 400, dt: float = 0.01) -> np.ndarray:
    """A decaying 2 Hz wave, cm/s^2 (peak 150 cm/s^2 = 0.153 g)."""
    t = np.arange(n) * dt
    return 150.0 * np.exp(-0.3 * t) * np.sin(2 * np.pi * 2.0 * t)


def write(path, text: str):
    path.write_text(text)
    return path


def test_the_layout_written_has_the_64_keys_of_the_format():
    text = esm_text(values(), 0.01, FIELDS)
    header = text.splitlines()[:64]
    assert len(DYNA_KEYS) == 64 and [line.split(":")[0] for line in header] == list(DYNA_KEYS)
    assert "HEADER_FORMAT: DYNA 1.2" in header and "UNITS: cm/s^2" in header and "NDATA: 400" in header
    assert is_esm_header(text.splitlines())


def test_an_esm_record_reads_in_si_with_its_sampling_and_title(tmp_path):
    a = values()
    path = write(tmp_path / "IT.NRC..HGE.D.20161030.064017.C.ACC.ASC", esm_text(a, 0.01, FIELDS))
    rec = read_record(path)  # the format from the content
    assert detect_format(path) == "esm" and rec.extra["format"] == "esm"
    assert rec.npts == 400 and rec.dt_s == pytest.approx(0.01) and rec.units_in_file == "cm/s2"
    np.testing.assert_allclose(rec.accel_m_s2, a / 100.0, rtol=1e-6)
    assert rec.title == "ESM EMSC-20161030_0000029 IT.NRC HGE"
    # the same file with another extension, and in a folder of records among PEER and CSV files
    copy = write(tmp_path / "nrc.txt", path.read_text())
    assert read_record(copy).npts == 400
    folder = tmp_path / "folder"
    folder.mkdir()
    write(folder / path.name, path.read_text())
    assert records_in_folder(folder).count == 1


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (("DATA_TYPE: ACCELERATION", "DATA_TYPE: VELOCITY"), "not ACCELERATION"),
        (("DATA_TYPE: ACCELERATION", "DATA_TYPE: ACCELERATION RESPONSE SPECTRUM"), "a response spectrum"),
        (("NDATA: 400", "NDATA: 401"), "holds 400 values: truncated"),
        (("NDATA: 400", "NDATA: 399"), "holds more values"),
        (("SAMPLING_INTERVAL_S: 0.010000", "SAMPLING_INTERVAL_S: 0"), "SAMPLING_INTERVAL_S must be"),
        (("SAMPLING_INTERVAL_S: 0.010000", "SAMPLING_INTERVAL_S: 0.02"), "DURATION_S = 4.000"),
        (("UNITS: cm/s^2", "UNITS: cm/s"), "velocity unit"),
        (("UNITS: cm/s^2", "UNITS: m/s^2"), "PGA_CM/S^2"),
        (("UNITS: cm/s^2", "UNITS:"), "UNITS"),
        (("NDATA: 400", "NDATAX: 400"), "lacks NDATA"),
    ],
)
def test_a_header_that_disagrees_with_itself_or_its_data_is_refused(tmp_path, change, words):
    text = esm_text(values(), 0.01, FIELDS).replace(*change)
    path = write(tmp_path / "r.ASC", text)
    with pytest.raises(RecordError) as err:
        read_esm(path)
    assert words in str(err.value) and "r.ASC" in str(err.value)


def test_a_value_that_is_not_a_number_or_a_cut_last_value_is_refused(tmp_path):
    lines = esm_text(values(), 0.01, FIELDS).splitlines()
    bad = list(lines)
    bad[64 + 10] = "nan"
    with pytest.raises(RecordError, match="line 75: not a number: 'nan'"):
        read_esm(write(tmp_path / "nan.ASC", "\n".join(bad) + "\n"))
    cut = list(lines)
    cut[-1] = cut[-1][:5]  # the file ends inside its last value
    with pytest.raises(RecordError, match="truncated inside it"):
        read_esm(write(tmp_path / "cut.ASC", "\n".join(cut)))


def test_units_or_sampling_given_against_the_header_are_refused(tmp_path):
    path = write(tmp_path / "r.ASC", esm_text(values(), 0.01, FIELDS))
    with pytest.raises(RecordError, match="the file says its values are in cm/s2 but units = g"):
        read_record(path, units="g")
    with pytest.raises(RecordError, match=r"SAMPLING_INTERVAL_S says 0\.01 s but dt_s = 0\.02 s"):
        read_record(path, dt_s=0.02)
    assert read_record(path, "esm", "cm/s2", 0.01).npts == 400


def test_the_commands_read_it_and_name_the_key_of_a_bad_one(tmp_path, capsys):
    good = write(tmp_path / "good.ASC", esm_text(values(), 0.01, FIELDS))
    assert main(["motion", "info", str(good)]) == 0
    out = capsys.readouterr().out
    assert "400 samples at dt = 0.01 s" in out and "PGA = 0.1" in out and "units in file: cm/s2" in out
    bad = write(
        tmp_path / "bad.ASC",
        esm_text(values(), 0.01, FIELDS).replace("DATA_TYPE: ACCELERATION", "DATA_TYPE: DISPLACEMENT"),
    )
    assert main(["motion", "info", str(bad), "--format", "esm"]) == 2
    err = capsys.readouterr().err
    assert "DATA_TYPE is 'DISPLACEMENT', not ACCELERATION" in err
