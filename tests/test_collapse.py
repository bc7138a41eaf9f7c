"""Overturn criterion of the DEMs and the collapse analysis of assemblies."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from rockyade.analysis.collapse import (
    FALLEN,
    FALLING,
    REST,
    ROCKING,
    SLIDING,
    block_states,
    collapse_report,
)
from rockyade.analysis.metrics import (
    NO_WHOLE_ROTATION,
    assembly_metrics,
    run_metrics,
    stack_order,
    structure_rotation,
)
from rockyade.blocks.geometry import chamfered_rectangle_vertices, rectangle_vertices
from rockyade.cli import main
from rockyade.dem.model_from_scene import contact_polygon
from rockyade.dem.overturn import (
    LANDING_TOL_RAD,
    block_fall,
    first_overturn,
    landing_angles,
    overturn_thresholds,
    run_outcome,
)
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import write_scene
from rockyade.solvers import run

from .conftest import EXAMPLES


def test_landing_angles_rectangle_beq_and_chamfer():
    assert landing_angles(rectangle_vertices(0.25, 1.0)) == pytest.approx((math.pi / 2, math.pi / 2))
    spec = load_scene(EXAMPLES / "specimen1_free.toml").blocks[0]
    poly = contact_polygon(spec.block(), spec.alpha_rad)  # base corners at +/- b_eq (Eq 11)
    b_eq = 0.5 * math.tan(0.235)
    lean = math.atan2(0.125 - b_eq, 1.0)  # the side face leans in by this angle
    assert landing_angles(poly) == pytest.approx((math.pi / 2 - lean, math.pi / 2 - lean), rel=1e-12)
    chamfered = chamfered_rectangle_vertices(0.16, 0.457, 0.04)
    assert landing_angles(chamfered) == pytest.approx((math.pi / 4, math.pi / 4))


def test_first_overturn_picks_the_body_and_sample():
    thresholds = overturn_thresholds([rectangle_vertices(0.2, 1.0), rectangle_vertices(0.2, 1.0)])
    theta = np.zeros((5, 2))
    theta[3, 1] = -(math.pi / 2 - LANDING_TOL_RAD)  # lands on the right (clockwise)
    theta[4, 0] = math.pi / 2
    assert first_overturn(theta, thresholds) == (3, 1)
    assert first_overturn(np.zeros((5, 2)), thresholds) == (-1, -1)


def _pulse_scene(amplitude_g: float, duration: float = 6.0) -> dict:
    d = load_scene(EXAMPLES / "specimen1_pulse.toml").to_dict()
    d["motion"]["amplitude_m_s2"] = amplitude_g * 9.81
    d["contact"]["calibration"] = "paper"
    d["duration_s"] = duration
    d["sample_dt_s"] = 0.002
    return d


def test_dem_fall_time_agrees_with_housner_overturn():
    """One-sine pulses that overturn specimen 1: the DEM lies on its side (it lands at its
    landing angle, never at pi/2) when Housner's block reaches pi/2 (measured: 0.02-0.03 s
    apart at 0.4-0.7 g)."""
    scene = scene_from_dict(_pulse_scene(0.6))
    exact = run(scene, "housner")
    dem = run(scene, "reference")
    assert exact.status == "overturned"
    report = collapse_report(scene, dem).iloc[0]
    assert report["fell"] and report["final_state"] == "fallen"
    assert report["fall_time_s"] == pytest.approx(exact.meta.overturn_time_s, abs=0.05)
    assert report["tipped_time_s"] < report["fall_time_s"]
    assert abs(report["residual_theta_rad"]) > math.pi / 2 - 0.05


def test_rocking_without_falling():
    scene = scene_from_dict(_pulse_scene(0.3))  # rocks to ~0.055 rad; Housner does not overturn either
    assert run(scene, "housner").status == "completed"
    dem = run(scene, "reference")
    report = collapse_report(scene, dem).iloc[0]
    assert not report["fell"] and math.isnan(report["fall_time_s"])
    assert report["rocking_time_s"] > 0.5 and report["final_state"] in ("rest", "rocking")
    assert 0.01 < report["max_abs_theta_rad"] < 0.235


def test_sliding_slab_is_sliding_and_a_wall_at_rest_rests():
    slab = scene_from_dict(
        {
            "duration_s": 1.0,
            "sample_dt_s": 0.001,
            "blocks": [{"name": "slab", "width_m": 1.0, "height_m": 0.2, "thickness_m": 0.5, "mass_kg": 250}],
            "contact": {"calibration": "paper", "friction_angle_deg": 10.0},
            "motion": {"type": "sampled", "t_s": [0.0, 0.05, 2.0], "accel_m_s2": [0.0, 3.0, 3.0]},
        }
    )
    states, _ = block_states(slab, run(slab, "reference"))
    assert (states[300:, 0] == SLIDING).all() and (states[:20, 0] == REST).all()
    stack = scene_from_dict(
        {
            "duration_s": 0.3,
            "sample_dt_s": 0.001,
            "blocks": [
                {"name": "low", "width_m": 0.3, "height_m": 0.6, "thickness_m": 0.3, "density_kg_m3": 2500},
                {"name": "up", "width_m": 0.2, "height_m": 0.6, "thickness_m": 0.3, "density_kg_m3": 2500},
            ],
            "contact": {"calibration": "paper", "beta_s": 1e-4},
            "motion": {"type": "rest"},
        }
    )
    states, _ = block_states(stack, run(stack, "reference"))
    assert (states == REST).all()
    assert FALLEN not in states


def test_drums_carried_by_a_rocking_column_rock_and_do_not_slide():
    """An 8-drum column rocking as one body: the upper drums move fast with it, but no joint
    slips, so they are rocking (the kinematic rule alone called them sliding for seconds)."""
    data = load_scene(EXAMPLES / "assemblies/column_8_drums.toml").to_dict()
    data.update(duration_s=2.0, motion={"type": "pulse", "shape": "sine", "amplitude_g": 0.25, "period_s": 1.0})
    scene = scene_from_dict(data)
    dem = run(scene, "reference")
    states, geometry = block_states(scene, dem)
    top = [g.name for g in geometry].index("d08")
    rocking = np.abs(dem.series("theta_rad", "d08")) > 0.05
    assert rocking.sum() > 100  # the column rocks well beyond its elastic tilt
    assert (states[rocking, top] == ROCKING).mean() > 0.95
    assert (states[:, top] == SLIDING).mean() < 0.05
    # issue "What users hit" 4: against its own alpha each drum looks safe; the column as one
    # body (its centroid about its base corner, against the column's alpha) is near its limit
    whole = structure_rotation(scene, dem)
    drums = run_metrics(scene, dem)
    assert whole["structure"] == "stack of 8"
    assert whole["structure_alpha_rad"] == pytest.approx(math.atan(0.15 / 2.0), rel=1e-3)
    assert whole["structure_max_theta_over_alpha"] > 0.9
    assert max(m["max_theta_over_alpha"] for m in drums.values()) < 0.2


def test_a_falling_column_lands_from_the_bottom_up_after_tipping_as_one_body():
    """8 drums, 0.25 g one-sine pulse of 1 s: the column tips as one body (every drum passes
    alpha at the same sample) and lands bottom first; the old centroid-drop rule called the
    top drums fallen while the column was still in the air, before they had tipped."""
    data = load_scene(EXAMPLES / "assemblies/column_8_drums.toml").to_dict()
    data.update(duration_s=6.0, motion={"type": "pulse", "shape": "sine", "amplitude_g": 0.25, "period_s": 1.0})
    scene = scene_from_dict(data)
    report = collapse_report(scene, run(scene, "reference")).set_index("block")
    drums = [f"d0{k}" for k in range(1, 9)]
    assert report.loc[drums, "fell"].all()
    tipped = report.loc[drums, "tipped_time_s"].to_numpy()
    falls = report.loc[drums, "fall_time_s"].to_numpy()
    assert np.ptp(tipped) == 0.0 and (falls > tipped + 0.3).all()
    assert (np.diff(falls) > 0).all(), falls  # bottom first
    assert (report.loc[drums, "final_state"] == "fallen").all()


def _falling_column(duration_s: float) -> dict:
    data = load_scene(EXAMPLES / "assemblies/column_8_drums.toml").to_dict()
    data.update(duration_s=duration_s, motion={"type": "pulse", "shape": "sine", "amplitude_g": 0.25, "period_s": 1.0})
    return data


@pytest.mark.slow
def test_a_run_that_ends_while_blocks_fall_says_falling_and_its_status_follows_the_table(tmp_path, capsys):
    """Issue "What users hit" 3: a run that ended while the drums were in the air marked them
    fallen at the last sample while its status said completed ("8 fell", completed); a run
    ended just after the first drum landed said overturned. One rule now: a block still
    falling at the end is falling (not fallen), and the status is overturned exactly when
    the table holds a fallen block, in the solver's metadata, the table, the batch metrics
    and the printed line alike."""
    long_run = scene_from_dict(_falling_column(6.0))
    full = collapse_report(long_run, run(long_run, "reference"))
    tip, first, last = full["tipped_time_s"].max(), full["fall_time_s"].min(), full["fall_time_s"].max()
    assert full["fell"].all() and tip < first < last
    # ended in mid-air: every drum beyond alpha and still turning
    in_air = scene_from_dict(_falling_column(round(0.5 * (tip + first), 3)))
    result = run(in_air, "reference")
    report = collapse_report(in_air, result)
    assert result.status == "completed" and result.meta.overturned_block is None
    assert not report["fell"].any() and report["falling_at_end"].all()
    assert (report["final_state"] == "falling").all() and report["tipped_time_s"].notna().all()
    states, _ = block_states(in_air, result)
    assert FALLEN not in states and (states[-1] == FALLING).all()
    metrics = assembly_metrics(in_air, result)
    assert metrics["n_fallen"] == 0 and metrics["n_falling_at_end"] == 8
    # ended after some drums landed: those fell, the run overturned at the first of them
    landing = scene_from_dict(_falling_column(round(0.5 * (first + last), 3)))
    result = run(landing, "reference")
    report = collapse_report(landing, result).set_index("block")
    fell = report.index[report["fell"]]
    assert 0 < len(fell) < 8 and report.loc[~report["fell"], "falling_at_end"].all()
    assert result.status == "overturned" and result.meta.overturned_block == report["fall_time_s"].idxmin()
    assert result.meta.overturn_time_s == pytest.approx(report["fall_time_s"].min(), abs=landing.sample_dt_s)
    # the printed line says the same as the table and the status
    scene_file = tmp_path / "column.toml"
    write_scene(scene_file, _falling_column(in_air.duration_s))
    assert main(["run", str(scene_file), "--solver", "reference"]) == 0
    out = capsys.readouterr().out
    assert "status completed" in out and "0 fell, 8 still falling when the run ended" in out


def test_the_fall_rule_on_histories_it_decides_alone():
    """block_fall on made histories: a block dropped by more than half its height is falling
    while it descends and fallen once it stops; leaning beyond alpha, fallen once it stops
    turning; the run's status follows (a drop counts, with no face on the ground)."""
    t = np.arange(0.0, 2.0, 0.01)
    theta = np.zeros_like(t)
    y = np.where(t < 1.0, 0.0, -2.0 * (t - 1.0) ** 2)  # free fall from t = 1 s, never stopped
    landing, height = (math.pi / 2, math.pi / 2), 1.0
    still = block_fall(t, theta, y, 0.2, landing, height)
    assert not still.fell and still.falling_at_end and t[still.falling] == pytest.approx(1.51, abs=0.011)
    y_landed = np.maximum(y, -0.8)  # it hits something at 0.8 m down
    landed = block_fall(t, theta, y_landed, 0.2, landing, height)
    assert landed.fell and t[landed.fall] > 1.6 and landed.tip == -1
    lean = np.where(t < 1.0, 0.3 * t, 0.3)  # passes alpha = 0.2 at 0.67 s, stops at 0.3 rad
    leaning = block_fall(t, lean, np.zeros_like(t), 0.2, landing, height)
    assert leaning.fell and t[leaning.tip] == pytest.approx(0.67, abs=0.011) and t[leaning.fall] >= 1.0
    falls = {"a": still, "b": landed}
    assert run_outcome({}, ["a", "b"], falls, t) == ("overturned", float(t[landed.fall]), "b")
    assert run_outcome({}, ["a", "b"], {"a": still}, t) == ("completed", None, None)


def test_a_beam_on_rocking_columns_is_carried_and_a_block_that_never_tipped_has_no_tip_time(capsys):
    scene = load_scene(EXAMPLES / "assemblies/frame.toml")
    result = run(scene, "reference")
    report = collapse_report(scene, result).set_index("block")
    # a frame is no stack: no whole-body alpha, and the summary says why and what to compare instead
    assert stack_order(scene) is None and stack_order(load_scene(EXAMPLES / "assemblies/wall_5_courses.toml")) is None
    whole = assembly_metrics(scene, result)
    assert whole["structure"] == "none" and math.isnan(whole["structure_max_theta_over_alpha"])
    assert whole["structure_note"] == NO_WHOLE_ROTATION
    assert main(["run", str(EXAMPLES / "assemblies/frame.toml"), "--solver", "reference"]) == 0
    out = capsys.readouterr().out
    assert "as one body: not a single stack" in out and "against the collapse acceleration of 'rockyade limit" in out
    assert report.loc["beam", "final_state"] == "carried"  # it swings with the columns: not at rest
    assert report.loc["column_left", "final_state"] == "rocking"
    assert not report["fell"].any() and report["tipped_time_s"].isna().all()


def _record_cases():
    """Specimen 2 (paper calibration) under records 1-10 of the paper's synthetic suite at two levels."""
    base = load_scene(EXAMPLES / "specimen2_record21.toml").to_dict()
    for record in range(1, 11):
        for load_factor in (0.6, 1.0):
            d = {**base, "duration_s": 20.0, "sample_dt_s": 0.005}
            d["motion"] = {**base["motion"], "record": record, "load_factor": load_factor}
            d["contact"] = {**base["contact"], "calibration": "paper"}
            yield scene_from_dict(d)


def _agreement(scenes) -> tuple[int, int, list[float]]:
    agree, total, dt = 0, 0, []
    for scene in scenes:
        exact, dem = run(scene, "housner"), run(scene, "reference")
        total += 1
        agree += exact.status == dem.status
        if dem.status == "completed":  # never a block lying on its side called completed
            alpha = scene.blocks[0].classical().alpha_rad
            assert abs(dem.series("theta_rad")[-1]) < alpha
        if exact.status == dem.status == "overturned":
            dt.append(dem.meta.overturn_time_s - exact.meta.overturn_time_s)
    return agree, total, dt


@pytest.mark.slow
def test_dem_overturns_with_housner_on_a_record_suite():
    """Rocking under records is chaotic run by run (the paper: 'very sensitive'), so the
    criterion is checked over a suite: measured 17 of 20 outcomes equal, and no DEM run ends
    'completed' with its block on its side (the bug this criterion fixes)."""
    agree, total, dt = _agreement(_record_cases())
    assert agree >= 0.75 * total
    assert dt and np.median(np.abs(dt)) < 1.0


@pytest.mark.skipif(
    not os.environ.get("ROCKYADE_RECORDS_DIR"),
    reason="external records: set ROCKYADE_RECORDS_DIR to a folder of PEER NGA .AT2 files",
)
def test_dem_overturns_with_housner_on_real_records():
    """The same on real accelerograms (ROCKYADE_RECORDS_DIR, PEER AT2): specimen 1, load
    factors 1, 1.5, 2 (measured on three records: 8 of 9 outcomes equal)."""
    files = sorted(Path(os.environ["ROCKYADE_RECORDS_DIR"]).expanduser().glob("*.AT2"))
    assert files, "ROCKYADE_RECORDS_DIR holds no .AT2 file"
    scenes = []
    for path in files:
        for load_factor in (1.0, 1.5, 2.0):
            d = load_scene(EXAMPLES / "specimen1_pulse.toml").to_dict()
            d.update(duration_s=25.0, sample_dt_s=0.005)
            d["motion"] = {"type": "record", "file": str(path), "load_factor": load_factor}
            scenes.append(scene_from_dict(d))
    agree, total, _ = _agreement(scenes)
    assert agree >= 0.75 * total
