"""The examples ship what the README promises: synthetic records that rockyade reads, a
scene that uses one, and a gallery of scripts that run."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rockyade.motion.analytic import Pulse
from rockyade.motion.records import read_record

from .conftest import EXAMPLES, ROOT

RECORDS = EXAMPLES / "records"
GALLERY = sorted((EXAMPLES / "gallery").glob("*.py"))


@pytest.mark.parametrize("name", ["ec8_type2_D_record21", "ricker_pulse_T0.5s"])
def test_example_records_read_alike_in_both_formats(name):
    at2 = read_record(RECORDS / f"{name}.AT2")
    csv = read_record(RECORDS.parent / "records_csv" / f"{name}.csv")
    assert "SYNTHETIC" in at2.title
    assert at2.npts == csv.npts and at2.dt_s == pytest.approx(csv.dt_s)
    # the AT2 holds 8 significant digits in g (standard gravity); the reader's g may differ by 0.04 %
    np.testing.assert_allclose(at2.accel_m_s2, csv.accel_m_s2, rtol=5e-4, atol=1e-6)


def test_the_ricker_record_is_the_pulse_it_says():
    rec = read_record(RECORDS.parent / "records_csv" / "ricker_pulse_T0.5s.csv")
    expected = Pulse("ricker", amplitude_m_s2=3.0, period_s=0.5, start_s=1.0).acceleration(rec.t_s)
    np.testing.assert_allclose(rec.accel_m_s2, expected, atol=1e-7)


def test_motion_info_on_a_shipped_record_from_the_repository(monkeypatch, capsys):
    """As the README prints it: a relative path from the repository root (the command's
    ``main``, in this process: the console script is started by tests/test_docs.py)."""
    from rockyade.cli import main

    monkeypatch.chdir(ROOT)
    assert main(["motion", "info", "examples/records/ec8_type2_D_record21.AT2", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["npts"] == 2001 and info["dt_s"] == pytest.approx(0.01)


@pytest.mark.slow
def test_a_scene_reads_its_record_relative_to_the_scene_file(tmp_path, monkeypatch, capsys):
    """Run from another folder than the scene's (the command's ``main``, in this process)."""
    from rockyade.cli import main

    monkeypatch.chdir(tmp_path)
    code = main(["run", str(EXAMPLES / "specimen1_record.toml"), "--solver", "housner", "--out", "r/x.csv"])
    assert code == 0, capsys.readouterr().err
    assert json.loads((tmp_path / "r/x.json").read_text())["status"] == "completed"


#: The commands of examples/records/README.md and examples/gallery/README.md that run the
#: record generator and each gallery script: tests/test_docs.py runs each once, as printed, and
#: checks what it wrote with the functions below (``AFTER``).
RECORDS_RUN = ".venv/bin/python examples/records/make_example_records.py runs/records"
GALLERY_RUN = ".venv/bin/python examples/gallery/{stem}.py gallery"


def check_generated_records(cwd: Path, printed: str) -> None:
    """The generator (``RECORDS_RUN``, run in ``cwd``) rewrites the shipped records exactly."""
    fresh = read_record(cwd / "runs/records/ricker_pulse_T0.5s.AT2")
    shipped = read_record(RECORDS / "ricker_pulse_T0.5s.AT2")
    np.testing.assert_array_equal(fresh.accel_m_s2, shipped.accel_m_s2)
    assert read_record(cwd / "runs/records/ec8_type2_D_record21.AT2").npts == 2001


def check_gallery_figure(stem: str, cwd: Path, printed: str) -> None:
    """A gallery script (``GALLERY_RUN``, run in ``cwd``) said it wrote its PNG, and did."""
    assert f"wrote {Path('gallery') / f'{stem}.png'}" in printed
    png = cwd / "gallery" / f"{stem}.png"
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000


def test_the_docs_tests_run_the_record_generator_and_each_gallery_script_and_check_them():
    """Each script runs once in the suite: as its README prints it, by tests/test_docs.py, which
    then checks what it wrote (the generator's records, each script's figure)."""
    from .test_docs import AFTER, COMMANDS

    wanted = [RECORDS_RUN, *(GALLERY_RUN.format(stem=script.stem) for script in GALLERY)]
    assert [command for command in wanted if command not in COMMANDS or command not in AFTER] == []


def test_the_gallery_has_scripts():
    assert len(GALLERY) >= 3


@pytest.mark.parametrize("folder", ["records", "records_csv"])
def test_each_shipped_records_folder_is_a_suite(folder):
    """`--records examples/records` (and `examples/records_csv`) reads as a suite of the two
    example records: the AT2 and CSV twins live in separate folders, so neither counts twice."""
    from rockyade.assess.motions import records_in_folder

    suite = records_in_folder(EXAMPLES / folder)
    names = sorted(Path(f).stem for f in suite.files)
    assert names == ["ec8_type2_D_record21", "ricker_pulse_T0.5s"]
