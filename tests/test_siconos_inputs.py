"""What Siconos takes and what it leaves (issue 34, the hostile review's Siconos findings): it
is not refused by the DEMs' calibration checks (Eq 13's range, the penalty springs'
settlement), a block's mass bound holds however the mass is given, a bad
ROCKYADE_SICONOS_PYTHON is refused naming the variable (exit 2), a killed process's private
folder is removed by the next run, and a failed run's files go when its rerun succeeds. The
tests that run the real Siconos use the fixture ``siconos_present`` (marked ``siconos``)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from rockyade.calibration.model_stage import calibrated_model
from rockyade.errors import CalibrationError, InputError
from rockyade.io import run_files
from rockyade.io.warm_program import STARTED
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, stack
from rockyade.siconos import backend as siconos_backend
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.siconos import SiconosSolver

ROOT = Path(__file__).resolve().parent.parent


def _block(width: float, height: float, thickness: float, motion: dict | None = None, **block) -> dict:
    return {
        "duration_s": 0.2,
        "sample_dt_s": 0.001,
        "blocks": [{"name": "b", "width_m": width, "height_m": height, "thickness_m": thickness, **block}],
        "motion": motion or {"type": "free", "theta0_rad": 0.1},
    }


#: A 10 x 40 mm block (Eq 13 has no value: Gamma / mu^2 = 0.08, far below its range) and a
#: 1000 m x 1 mm plate (the paper's stiffness lets it sink 6700 times the allowed settlement).
TINY = _block(0.01, 0.04, 0.01, density_kg_m3=2400)
PLATE = _block(1000.0, 0.001, 1.0, {"type": "rest"}, density_kg_m3=2400)


def test_the_dems_calibration_checks_do_not_refuse_siconos():
    tiny, plate = scene_from_dict(TINY), scene_from_dict(PLATE)
    with pytest.raises(CalibrationError, match="Eq 13 gives sqrt"):
        calibrated_model(tiny)
    with pytest.raises(InputError, match="sinks into its base"):
        calibrated_model(plate)
    for scene in (tiny, plate):
        SiconosSolver().check_scene(scene)
        model = SiconosSolver().model(scene)
        assert model.scene_hash == scene.scene_hash  # the scene's own, as every solver's Result
    # the blocks Siconos runs are the DEMs' (geometry, mass, inertia from p); only the joints differ
    given = scene_from_dict({**TINY, "contact": {"beta_s": 0.001}})  # the DEMs with a damping given
    for ours, dems in zip(SiconosSolver().model(tiny).bodies, calibrated_model(given).bodies, strict=True):
        np.testing.assert_array_equal(ours.contact_vertices_m, dems.contact_vertices_m)
        assert (ours.mass_kg, ours.inertia_kgm2, ours.p_rad_s) == (dems.mass_kg, dems.inertia_kgm2, dems.p_rad_s)


def test_a_tiny_block_and_a_thin_plate_run_in_siconos(siconos_present):
    """The tiny block rocks as Housner's does (its first impact within 1 %); the plate stays put."""
    tiny = scene_from_dict(TINY)
    rocking = SiconosSolver().run(tiny)
    assert rocking.ok, rocking.meta.failure_reason
    housner = HousnerSolver().run(tiny)
    first = [float(r.t[np.argmax(r.series("theta_rad") <= 0)]) for r in (rocking, housner)]
    assert 0 < first[1] < tiny.duration_s and abs(first[0] - first[1]) <= 0.01 * first[1], first
    plate = SiconosSolver().run(scene_from_dict(PLATE))
    assert plate.ok, plate.meta.failure_reason
    assert np.max(np.abs(plate.series("theta_rad"))) < 1e-9


def test_a_mass_outside_its_range_is_refused_however_it_is_given(tmp_path, capsys):
    from rockyade.cli import main

    cube = _block(1000.0, 1000.0, 1000.0, density_kg_m3=1e5)  # 1e14 kg
    with pytest.raises(InputError, match=r"mass of 1e\+14 kg .*\[0.001, 1e\+09\] kg") as refused:
        scene_from_dict(cube)
    assert refused.value.field == "blocks[0].density_kg_m3"
    with pytest.raises(InputError, match=r"mass_kg"):
        scene_from_dict(_block(1000.0, 1000.0, 1000.0, mass_kg=1e14))
    with pytest.raises(InputError) as light:  # 1 mm cubed of a light material: 1e-9 kg
        scene_from_dict(_block(0.001, 0.001, 0.001, density_kg_m3=1.0))
    assert light.value.field == "blocks[0].density_kg_m3"
    (tmp_path / "cube.json").write_text(json.dumps(cube))
    assert main(["run", str(tmp_path / "cube.json"), "--solver", "siconos"]) == 2
    assert "blocks[0].density_kg_m3" in capsys.readouterr().err


def _wall(top_gap_m: float) -> dict:
    """Three 0.25 x 0.5 m courses; the top one ``top_gap_m`` above the second."""
    ys = (0.0, 0.5, 1.0 + top_gap_m)
    return {
        "duration_s": 0.2,
        "sample_dt_s": 0.002,
        "contact": {"calibration": "paper"},
        "motion": {"type": "rest"},
        "blocks": [
            {
                "name": f"b{k}",
                "width_m": 0.25,
                "height_m": 0.5,
                "thickness_m": 1.0,
                "density_kg_m3": 1800.0,
                "position_m": [0.0, y],
            }
            for k, y in enumerate(ys)
        ],
    }


def test_a_block_beyond_the_pairs_reach_above_its_support_is_refused(tmp_path, capsys):
    """Siconos's pairs are found once, from the start, within PAIR_REACH_FRACTION (0.25) of the
    smaller block's largest dimension: a top course 0.2 m above the second (0.125 m of reach) fell
    through it and the run said ``overturned`` where both DEMs land it. Refused naming the field,
    the gap and the reach, exit 2, before Siconos starts; within the reach, and touching, it runs."""
    from rockyade.cli import main
    from rockyade.siconos.reach import check_landing_reach

    with pytest.raises(InputError, match=r"b2 starts 0.2 m above block b1, beyond the 0.125 m") as refused:
        check_landing_reach(scene_from_dict(_wall(0.2)))
    assert refused.value.field == "blocks[2].position_m"
    check_landing_reach(scene_from_dict(_wall(0.1)))  # within the reach: paired, it lands
    check_landing_reach(scene_from_dict(_wall(0.0)))
    (tmp_path / "gap.json").write_text(json.dumps(_wall(0.2)))
    assert main(["run", str(tmp_path / "gap.json"), "--solver", "siconos"]) == 2
    err = capsys.readouterr().err
    assert "blocks[2].position_m" in err and "Traceback" not in err


@pytest.mark.parametrize("kind", ["missing", "not executable", "without siconos", "not a python"])
def test_a_bad_siconos_python_is_refused_naming_the_variable(kind, tmp_path, monkeypatch, capsys):
    from rockyade.cli import main

    plain = tmp_path / "python3"
    plain.write_text("#!/bin/sh\nexit 0\n")  # exits 0 at once: "exited with code 0" before
    paths = {
        "missing": tmp_path / "nothing-here",
        "not executable": plain,
        "without siconos": Path(sys.executable),  # this virtual environment's: no system packages
        "not a python": plain,
    }
    if kind == "not a python":
        plain.chmod(0o755)
    monkeypatch.setenv("ROCKYADE_SICONOS_PYTHON", str(paths[kind]))
    monkeypatch.setattr(siconos_backend, "SICONOS_PYTHON", str(paths[kind]))
    before = STARTED["Siconos"]
    code = main(["run", str(ROOT / "examples/specimen1_free.toml"), "--solver", "siconos"])
    err = capsys.readouterr().err
    assert code == 2 and "ROCKYADE_SICONOS_PYTHON" in err and "Traceback" not in err, err
    assert STARTED["Siconos"] == before  # refused before any worker started
    with pytest.raises(InputError) as refused:  # and by the studies' check before their runs
        SiconosSolver().check_scene(scene_from_dict(TINY))
    assert refused.value.field == "ROCKYADE_SICONOS_PYTHON"


LONG_RUN = """
import sys
from rockyade.scene import scene_from_dict
from rockyade.solvers.siconos import SiconosSolver
scene = {"duration_s": 10000.0, "sample_dt_s": 0.01, "motion": {"type": "free", "theta0_rad": 0.1},
         "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.5, "mass_kg": 300}]}
SiconosSolver().run(scene_from_dict(scene))
"""


def test_a_killed_processs_private_folder_goes_at_the_next_run(tmp_path, monkeypatch, siconos_present):
    """kill -9 of a process in the middle of a Siconos run (no clean-up of its own runs) leaves
    its private folder; the next process's first run removes it (its owner is dead)."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    env = {**os.environ, "TMPDIR": str(scratch), "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", LONG_RUN], env=env, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not list(scratch.glob("rockyade-siconos-*/*.running.siconos.json")):
            time.sleep(0.05)
        (left,) = scratch.glob(f"rockyade-siconos-{proc.pid}-*")
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    assert left.is_dir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    monkeypatch.setattr(run_files, "_SWEPT", set())  # as a fresh process
    assert SiconosSolver().run(scene_from_dict(_block(0.25, 1.0, 0.5, mass_kg=300))).ok
    assert not list(scratch.iterdir())


def test_a_failed_runs_files_go_when_its_rerun_succeeds(tmp_path, monkeypatch, siconos_present):
    """A failed run keeps its files beside the result (``run --out``'s folder); the same run
    succeeding later replaces the result and removes them (they stayed beside it)."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    out = tmp_path / "out"
    scene = scene_from_dict(
        stack(widths_m=[0.4, 0.35], heights_m=0.5, motion=rest_motion(), duration_s=0.3, sample_dt_s=0.01)
    )
    failed = SiconosSolver(solver_max_iter=1).keeping_files(out, "x").run(scene)
    assert not failed.ok and Path(failed.meta.log_path or "").name == "x_dt1.siconos.log"
    assert sorted(p.name for p in out.iterdir()) == ["x_dt1.siconos.json", "x_dt1.siconos.log", "x_dt1.siconos.npz"]
    rerun = SiconosSolver().keeping_files(out, "x").run(scene)
    assert rerun.ok and rerun.meta.log_path is None
    assert not list(out.iterdir()) and not list((tmp_path / "tmp").iterdir())
