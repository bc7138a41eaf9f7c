"""The single-body path and the batched runs of the reference DEM against its general loop:
the same outputs bit for bit (one block, energy terms off), the same summary rows from a
group as from runs one at a time, and the grouping of tasks into jobs."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from rockyade.batch import comparable, expand
from rockyade.batch.running import job_key, output, run_job, run_task
from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.engine import model_arrays
from rockyade.kernel import simulation as kernel
from rockyade.kernel.single import simulate_single, single_body
from rockyade.kernel.state import pack
from rockyade.runner.groups import group_jobs
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers.reference import ReferenceSolver


def _scene(amplitude_g: float, duration_s: float = 3.0):
    d = load_scene("examples/specimen1_pulse.toml").to_dict()
    d["duration_s"] = duration_s
    d["motion"].pop("amplitude_g", None)
    d["motion"]["amplitude_m_s2"] = 9.81 * amplitude_g
    return scene_from_dict(d)


@pytest.mark.parametrize(("amplitude_g", "corners"), [(0.35, True), (0.35, False), (3.0, False)])
def test_single_body_path_gives_the_general_loops_bits(amplitude_g, corners):
    """Rocking (and, at the larger pulse, overturning) runs: every output field identical."""
    records = pack(
        model_arrays(calibrated_model(_scene(amplitude_g))),
        stop_on_overturn=True,
        record_energy=False,
        record_corners=corners,
        coherent=True,
    )
    assert single_body(records[0], records[1], False)
    general = kernel.simulate(*records)
    single = simulate_single(*records)
    assert general.n_filled > 10
    assert np.nanmax(np.abs(general.ang[: general.n_filled, 0] - general.ang[0, 0])) > 1e-3  # it rocks
    for name in general._fields:
        a, b = getattr(general, name), getattr(single, name)
        if isinstance(a, np.ndarray):
            assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), name
        else:
            assert a == b, name


def test_energy_terms_and_assemblies_keep_the_general_loop():
    records = pack(
        model_arrays(calibrated_model(_scene(0.35))),
        stop_on_overturn=True,
        record_energy=True,
        record_corners=False,
        coherent=True,
    )
    assert not single_body(records[0], records[1], True)
    stack = calibrated_model(load_scene("examples/biblock_free.toml"))
    records = pack(model_arrays(stack), stop_on_overturn=True, record_energy=False, record_corners=False, coherent=True)
    assert not single_body(records[0], records[1], False)


def test_a_group_gives_the_rows_of_runs_one_at_a_time(tmp_path):
    """Pulses of several amplitudes (some overturn): one job, the same summary rows."""
    base = _scene(0.35).to_dict()
    grid = {"motion.amplitude_m_s2": [1.0, 3.4, 6.0, 30.0]}
    a = expand([("s1", base)], grid, ["reference"], save_history=False)
    b = expand([("s1", base)], grid, ["reference"], save_history=False)
    assert not a[0].solver.record_energy  # no history, no energy terms
    assert len({job_key(t) for t in b}) == 1 and job_key(b[0]) is not None
    one = pd.DataFrame([run_task(t, output(tmp_path / "a")).summary() for t in a]).drop(columns="elapsed_s")
    grouped = pd.DataFrame([r.summary() for r in run_job(tuple(b), output(tmp_path / "b"))]).drop(columns="elapsed_s")
    assert set(one.status) == {"completed", "overturned"}
    pd.testing.assert_frame_equal(comparable(one), comparable(grouped))
    assert (tmp_path / "b" / "runs" / f"{b[0].scene_hash}_reference.json").is_file()  # resume reads it


def test_histories_and_other_solvers_run_alone(tmp_path):
    base = _scene(0.35).to_dict()
    kept = expand([("s1", base)], {"motion.amplitude_m_s2": [1.0, 2.0]}, ["reference"], save_history=True)
    assert all(job_key(t) is None for t in kept)
    assert ReferenceSolver(record_energy=True).group_key(_scene(0.35)) is None


def test_group_jobs_keep_order_and_cut_groups():
    tasks = list(range(10))
    jobs = group_jobs(tasks, lambda t: None if t == 3 else t % 2, max_runs=2)
    assert sorted(t for job in jobs for t in job) == tasks
    assert all(len(job) <= 2 for job in jobs)
    assert (3,) in jobs
    assert jobs[0] == (0, 2)
    assert all(len({t % 2 for t in job}) == 1 for job in jobs)
