"""Housner's runs in groups: one model per group, each run integrated as a run of its own.
The same theta (bit for bit), metadata and summary rows as :meth:`HousnerSolver.run` per scene."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from rockyade.analysis.metrics import theta_metrics, uplift_threshold_rad
from rockyade.batch import comparable, expand
from rockyade.batch.running import job_key, output, run_job, run_task
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers.housner import HousnerSolver

#: Keys of a run's metadata that are timings (or say the run was batched).
TIMINGS = {"wall_time_s", "batched"}


def _pulses(amplitudes_m_s2, loads: bool = False):
    d = load_scene("examples/specimen1_pulse.toml").to_dict()
    d["duration_s"] = 3.0
    d["motion"].pop("amplitude_g", None)
    if loads:
        d["loads"] = [{"block": d["blocks"][0]["name"], "point_m": [0.1, 1.0], "force_N": [0.0, -800.0]}]
    scenes = []
    for a in amplitudes_m_s2:
        d["motion"]["amplitude_m_s2"] = a
        scenes.append(scene_from_dict(d))
    return scenes


def _records(load_factors):
    d = load_scene("examples/specimen1_record.toml").to_dict()
    d["duration_s"] = 4.0
    scenes = []
    for lf in load_factors:
        d["motion"]["load_factor"] = lf
        scenes.append(scene_from_dict(d))
    return scenes


def _free(tilts):
    d = load_scene("examples/specimen1_free.toml").to_dict()
    d["duration_s"] = 2.0
    return [scene_from_dict({**d, "motion": {**d["motion"], "theta0_rad": tilt}}) for tilt in tilts]


@pytest.mark.parametrize(
    "scenes",
    [
        pytest.param(_pulses([1.0, 3.4, 6.0, 30.0]), id="pulses"),
        pytest.param(_pulses([2.0, 4.0, 40.0], loads=True), id="loaded"),
        pytest.param(_records([0.5, 1.0, 2.5]), id="record"),
        pytest.param(_free([0.05, 0.1, 0.2]), id="free"),
    ],
)
def test_a_group_gives_each_runs_own_results(scenes):
    solver = HousnerSolver()
    assert len({solver.group_key(s) for s in scenes}) == 1
    alpha = scenes[0].blocks[0].classical().alpha_rad
    grouped = solver.run_group(scenes, uplift_threshold_rad(alpha))
    statuses = set()
    for scene, one in zip(scenes, grouped, strict=True):
        result = solver.run(scene)
        statuses.add(result.status)
        theta = result.series("theta_rad")
        assert one.theta_rad.shape == theta.shape and np.array_equal(one.theta_rad, theta)
        assert one.sample_dt_s == scene.sample_dt_s
        assert {k: v for k, v in one.meta.to_dict().items() if k not in TIMINGS} == {
            k: v for k, v in result.meta.to_dict().items() if k not in TIMINGS
        }
        expected = theta_metrics(result.t, theta, alpha)
        for key, value in one.metrics.items():
            assert value == expected[key] or (np.isnan(value) and np.isnan(expected[key])), key
    assert max(np.max(np.abs(one.theta_rad)) for one in grouped) > 1e-3  # they rock
    if scenes[0].motion.type == "pulse":
        assert statuses == {"completed", "overturned"}


def test_a_housner_batch_gives_the_rows_of_runs_one_at_a_time(tmp_path):
    """The batch's rows (status, peaks, metrics, coverage) from a group and from runs alone."""
    base = _pulses([1.0])[0].to_dict()
    grid = {"motion.amplitude_m_s2": [1.0, 3.4, 6.0, 30.0]}
    a = expand([("s1", base)], grid, ["housner"], save_history=False)
    b = expand([("s1", base)], grid, ["housner"], save_history=False)
    assert len({job_key(t) for t in b}) == 1 and job_key(b[0]) is not None
    one = pd.DataFrame([run_task(t, output(tmp_path / "a")).summary() for t in a]).drop(columns="elapsed_s")
    grouped = pd.DataFrame([r.summary() for r in run_job(tuple(b), output(tmp_path / "b"))]).drop(columns="elapsed_s")
    assert set(one.status) == {"completed", "overturned"}
    pd.testing.assert_frame_equal(comparable(one), comparable(grouped))
    assert (tmp_path / "b" / "runs" / f"{b[0].scene_hash}_housner.json").is_file()  # resume reads it


def test_housner_runs_with_histories_or_of_stacks_go_alone(tmp_path):
    base = _pulses([1.0])[0].to_dict()
    kept = expand([("s1", base)], {"motion.amplitude_m_s2": [1.0, 2.0]}, ["housner"], save_history=True)
    assert all(job_key(t) is None for t in kept)
    assert HousnerSolver().group_key(load_scene("examples/biblock_free.toml")) is None
    one = _pulses([1.0])[0]
    other = scene_from_dict({**one.to_dict(), "blocks": [{**one.to_dict()["blocks"][0], "mu": 0.9}]})
    assert HousnerSolver().group_key(one) != HousnerSolver().group_key(other)  # another model
    released = scene_from_dict({**one.to_dict(), "motion": {"type": "free", "theta0_rad": 0.1}})
    assert HousnerSolver().group_key(one) != HousnerSolver().group_key(released)  # free rocking's metrics differ


def test_group_solvers_are_declared():
    """The grouped runs are a declared protocol (GroupSolver), not attributes found by name:
    Housner and the reference DEM run groups, YADE does not."""
    from rockyade.solvers.base import GroupSolver, Solver
    from rockyade.solvers.reference import ReferenceSolver
    from rockyade.solvers.yade import YadeSolver

    assert isinstance(HousnerSolver(), GroupSolver)
    assert isinstance(ReferenceSolver(record_energy=False), GroupSolver)
    assert isinstance(YadeSolver(), Solver)
    assert not isinstance(YadeSolver(), GroupSolver)
