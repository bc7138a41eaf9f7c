"""A scene that ends before its record: generators default to the record's length plus a tail,
and ``rockyade run`` says how much of the record, its PGA and its Arias intensity it leaves out."""

from __future__ import annotations

import itertools
import json
import math
import shutil

import numpy as np
import pytest
from scipy.integrate import quad

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.motion.coverage import RECORD_TAIL_S, record_coverage
from rockyade.motion.ground import GroundMotion
from rockyade.motion.records import read_record
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import drum_column, record_motion, wall

from .conftest import EXAMPLES, external_records_dir, free_scene_dict, needs_records

EC8 = EXAMPLES / "records/ec8_type2_D_record21.AT2"  # 20 s, PGA 3.642 m/s^2 at 2.35 s


def _record_scene(duration_s: float, file=EC8) -> dict:
    d = free_scene_dict(duration=duration_s)
    d["motion"] = {"type": "record", "file": str(file), "load_factor": 0.5}
    return d


# ---------------------------------------------------------------------- record_coverage


def test_coverage_of_a_cut_record_against_direct_integration():
    scene = scene_from_dict(_record_scene(2.0))
    c = record_coverage(scene.motion, 2.0)
    rec = read_record(EC8)
    a = 0.5 * rec.accel_m_s2  # the load factor applies: what the solvers see
    assert c["status"] == "cut" and c["motion_end_s"] == pytest.approx(20.0)
    assert c["time_left_out_s"] == pytest.approx(18.0) and c["time_left_out_fraction"] == pytest.approx(0.9)
    assert c["pga_m_s2"] == pytest.approx(np.max(np.abs(a))) and c["pga_time_s"] == pytest.approx(2.35)
    inside = np.abs(a[rec.t_s <= 2.0])
    assert c["pga_in_run_m_s2"] == pytest.approx(max(inside.max(), abs(np.interp(2.0, rec.t_s, a))))
    assert c["pga_left_out_fraction"] == pytest.approx(1 - c["pga_in_run_m_s2"] / c["pga_m_s2"])
    assert c["pga_left_out_fraction"] > 0

    def square(t: float) -> float:
        return float(np.interp(t, rec.t_s, a)) ** 2

    breaks = list(rec.t_s)
    assert breaks[200] == pytest.approx(2.0)  # the scene's end, a sample of the record
    after = sum(quad(square, t0, t1)[0] for t0, t1 in itertools.pairwise(breaks[200:]))
    total = after + sum(quad(square, t0, t1)[0] for t0, t1 in itertools.pairwise(breaks[:201]))
    assert c["arias_left_out_fraction"] == pytest.approx(after / total, rel=1e-9)
    assert c["suggested_duration_s"] == pytest.approx(20.0 + RECORD_TAIL_S)
    for word in ("ends at 2 s", "lasts 20 s", "18 s (90 %)", "its peak", "Arias intensity", "duration_s = 25"):
        assert word in c["message"], c["message"]
    json.dumps(c)  # plain data for a result's metadata
    assert all(isinstance(v, (float, str)) for v in c.values())


def test_coverage_of_a_whole_record_and_of_no_motion():
    c = record_coverage(scene_from_dict(_record_scene(25.0)).motion, 25.0)
    assert c["status"] == "complete" and c["message"] == "" and c["time_left_out_s"] == 0.0
    assert c["pga_left_out_fraction"] == 0.0 and c["arias_left_out_fraction"] == 0.0
    # a scene that ends with the record's last sample leaves nothing out
    assert record_coverage(scene_from_dict(_record_scene(20.0)).motion, 20.0)["status"] == "complete"
    free = scene_from_dict(free_scene_dict())
    assert record_coverage(free.motion, 4.0)["status"] == "no base motion"


def test_coverage_of_a_ground_motion_keeps_its_peak_when_it_falls_inside():
    t = np.linspace(0.0, 10.0, 1001)
    a = np.where(t < 1.0, 3.0 * np.sin(math.pi * t), 0.01 * np.sin(7 * t))
    c = record_coverage(GroundMotion(t, a, label="test"), 2.0)
    assert c["status"] == "cut" and c["pga_left_out_fraction"] == 0.0 and c["pga_time_s"] == pytest.approx(0.5)
    assert "not its peak" in c["message"] and c["arias_left_out_fraction"] < 0.01


def test_rockyade_run_warns_on_stderr_when_the_scene_ends_before_its_record(tmp_path, capsys):
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps(_record_scene(3.0)))
    assert main(["run", str(scene)]) == 0
    err = capsys.readouterr().err
    assert err.count("rockyade: warning:") == 1 and f"{scene}: the scene ends at 3 s" in err
    scene.write_text(json.dumps(_record_scene(25.0)))
    assert main(["run", str(scene)]) == 0
    assert "warning" not in capsys.readouterr().err


def test_rockyade_run_works_out_the_coverage_once_and_its_result_carries_it(tmp_path, monkeypatch):
    """The warning before the run and the Result's meta["motion_coverage"] are one computation
    (the record is read and integrated once per run), and the Result's is the warned one."""
    import rockyade.motion.coverage as coverage

    calls = []

    def counted(motion, duration_s):
        calls.append(duration_s)
        return record_coverage(motion, duration_s)

    monkeypatch.setattr(coverage, "record_coverage", counted)
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps(_record_scene(2.5)))
    out = tmp_path / "r.csv"
    assert main(["run", str(scene), "--solver", "housner", "--out", str(out)]) == 0
    assert calls == [2.5]
    meta = json.loads(out.with_suffix(".json").read_text())
    assert meta["motion_coverage"]["status"] == "cut"
    assert meta["motion_coverage"]["message"].startswith("the scene ends at 2.5 s")


# ---------------------------------------------------------------------- generators' duration


def test_a_generator_given_a_record_lasts_the_record_plus_the_tail(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    shutil.copy(EC8, tmp_path / "r.AT2")
    d = drum_column(drums=2, motion=record_motion("r.AT2"))
    assert d["duration_s"] == pytest.approx(20.0 + RECORD_TAIL_S)
    assert drum_column(drums=2, motion=record_motion("r.AT2"), duration_s=7.0)["duration_s"] == 7.0  # given: kept
    assert drum_column(drums=2)["duration_s"] == 3.0  # the default pulse: as before
    synthetic = {"type": "synthetic", "suite": "paper", "record": 3}
    assert wall(courses=2, units_per_course=2, motion=synthetic)["duration_s"] == pytest.approx(25.0)
    scene = scene_from_dict(d, base_dir=tmp_path)
    assert record_coverage(scene.motion, scene.duration_s)["status"] == "complete"


def test_a_generator_whose_record_is_not_found_says_what_to_give(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as info:
        drum_column(motion=record_motion("elsewhere/r.AT2"))
    assert info.value.field == "motion.file" and "give duration_s" in info.value.message


def test_build_with_a_record_writes_its_length_plus_the_tail(tmp_path, capsys):
    record = tmp_path / "records" / "r.AT2"
    record.parent.mkdir()
    shutil.copy(EC8, record)
    out = tmp_path / "scenes" / "column.toml"
    argv = ["build", "column", "--drums", "2", "--motion", "record", "--record", str(record), "--out", str(out)]
    assert main(argv) == 0
    assert "duration_s = 25 s: the record's length plus 5 s of free rocking" in capsys.readouterr().out
    scene = load_scene(out)
    assert scene.duration_s == pytest.approx(25.0)
    assert record_coverage(scene.motion, scene.duration_s)["status"] == "complete"
    assert main([*argv, "--duration-s", "4"]) == 0 and load_scene(out).duration_s == 4.0  # an explicit value wins
    assert main(["build", "column", "--out", str(out)]) == 0 and load_scene(out).duration_s == 3.0


@needs_records("RSN77_SFERN_PUL164-hor1.AT2")
def test_the_issues_column_under_pacoima_dam_covers_the_record(tmp_path, capsys):
    """The issue's command wrote duration_s = 3.0 for a record of 41.7 s peaking at 7.75 s."""
    record = external_records_dir() / "RSN77_SFERN_PUL164-hor1.AT2"
    out = tmp_path / "column.toml"
    argv = ["build", "column", "--drums", "6", "--diameter-m", "0.8", "--drum-height-m", "1.0"]
    argv += ["--density-kg-m3", "2700", "--motion", "record", "--record", str(record), "--out", str(out)]
    assert main(argv) == 0
    scene = load_scene(out)
    assert scene.duration_s == pytest.approx(41.71 + RECORD_TAIL_S)
    c = record_coverage(scene.motion, 3.0)
    assert c["status"] == "cut" and c["pga_time_s"] == pytest.approx(7.75) and c["pga_left_out_fraction"] > 0.5
