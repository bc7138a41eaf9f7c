"""The examples ship what the README promises: synthetic records that rockyade reads, a
scene that uses one, and a gallery of scripts that run."""

from __future__ import annotations

import json
import runpy
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rockyade.motion.analytic import Pulse
from rockyade.motion.records import read_record

from .conftest import EXAMPLES, ROOT

ROCKYADE = Path(sys.executable).parent / "rockyade"
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


def test_motion_info_on_a_shipped_record_from_the_repository():
    """As the README prints it: a relative path from the repository root."""
    proc = subprocess.run(
        [str(ROCKYADE), "motion", "info", "examples/records/ec8_type2_D_record21.AT2", "--json"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    info = json.loads(proc.stdout)
    assert info["npts"] == 2001 and info["dt_s"] == pytest.approx(0.01)


@pytest.mark.slow
def test_a_scene_reads_its_record_relative_to_the_scene_file(tmp_path, monkeypatch, capsys):
    """Run from another folder than the scene's (the command's ``main``, in this process)."""
    from rockyade.cli import main

    monkeypatch.chdir(tmp_path)
    code = main(["run", str(EXAMPLES / "specimen1_record.toml"), "--solver", "housner", "--out", "r/x.csv"])
    assert code == 0, capsys.readouterr().err
    assert json.loads((tmp_path / "r/x.json").read_text())["status"] == "completed"


@pytest.mark.slow
def test_the_record_generator_runs(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(RECORDS / "make_example_records.py"), "out"], cwd=tmp_path, capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr
    fresh = read_record(tmp_path / "out/ricker_pulse_T0.5s.AT2")
    shipped = read_record(RECORDS / "ricker_pulse_T0.5s.AT2")
    np.testing.assert_array_equal(fresh.accel_m_s2, shipped.accel_m_s2)
    assert read_record(tmp_path / "out/ec8_type2_D_record21.AT2").npts == 2001


@pytest.mark.parametrize("script", GALLERY, ids=[p.stem for p in GALLERY])
@pytest.mark.slow
def test_gallery_script_runs_and_writes_its_figure(script, tmp_path, monkeypatch, capsys):
    """Each script, run as ``python SCRIPT gallery`` would run it (as ``__main__``, with that
    argument, in a fresh folder), but in this process: the test is about the script, not about
    starting Python (examples/gallery/README.md's commands start it, tests/test_docs.py)."""
    import matplotlib.pyplot as plt

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script), "gallery"])
    before = set(plt.get_fignums())
    try:
        runpy.run_path(str(script), run_name="__main__")
    finally:
        for number in set(plt.get_fignums()) - before:
            plt.close(number)
    assert f"wrote {Path('gallery') / f'{script.stem}.png'}" in capsys.readouterr().out
    png = tmp_path / "gallery" / f"{script.stem}.png"
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000


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
