"""Runs of one structure stepped together (rockyade.kernel.runs.simulate_runs) give the same
bits as one run at a time: against the single-body kernel run once per motion
(rockyade.kernel.single.simulate_single, the path of one run) and against the reference DEM's
own run of each scene (ReferenceSolver.run), over the paper's four specimens, several
synthetic records and load factors that overturn some of them."""

from __future__ import annotations

from dataclasses import replace

import numba
import numpy as np
import pytest

from rockyade.analysis.metrics import uplift_threshold_rad
from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.engine import model_arrays
from rockyade.kernel.runs import CHUNK_RUNS, RunsOutput, _summaries, simulate_runs
from rockyade.kernel.single import simulate_single
from rockyade.kernel.state import pack
from rockyade.paper.specimens import SINGLE_SPECIMENS
from rockyade.solvers.reference import model_arrays_motion
from rockyade.studies import fragility_study

RECORDS = (1, 2, 3)
#: A gentle and a strong load factor: the strong one overturns some runs (checked below).
LOAD_FACTORS = (0.3, 1.2)


def _tasks(tmp_path, specimen: str):
    return fragility_study.tasks(
        specimens=(specimen,), records=RECORDS, load_factors=LOAD_FACTORS, solvers=("reference",)
    )


def _runs(tasks, repeat: int = 1):
    """The models of one group's runs (each task ``repeat`` times): the calibrated structure of
    the first with each task's motion."""
    base = calibrated_model(tasks[0].scene)
    return [replace(base, motion=t.scene.motion.ground_motion(t.scene.duration_s)) for t in tasks] * repeat


def _packed(model):
    """The kernel's records of one model, as the group's kernel gets them."""
    return pack(model_arrays(model), stop_on_overturn=True, record_energy=False, record_corners=False, coherent=True)


def _kernel_inputs(tasks, repeat: int = 1):
    """The packed structure and the runs' motions (each task ``repeat`` times) of one group."""
    models = _runs(tasks, repeat)
    b, j, _, st, i = _packed(models[0])
    motions = [model_arrays_motion(m) for m in models]
    starts = np.cumsum([0] + [m[0].size for m in motions])
    mt, mah, mav = (np.concatenate([m[k] for m in motions]) for k in range(3))
    alpha = tasks[0].scene.blocks[0].classical().alpha_rad
    return (b, j, st, i, mt, mah, mav, starts, uplift_threshold_rad(alpha), models[0].sample_dt_s)


def _one_at_a_time(tasks, repeat: int, uplift_rad: float, sample_dt: float) -> RunsOutput:
    """What :func:`simulate_runs` returns, from the single-body kernel run once per motion
    (the summaries by the same function from those samples). A repeated task's run is its
    first run's: the single-body kernel is a function of its inputs alone (the group repeats
    tasks only to hold more runs than a chunk)."""
    models = _runs(tasks)
    outs = [simulate_single(*_packed(m)) for m in models] * repeat
    ang = np.stack([o.ang[:, 0] for o in outs])
    n_filled = np.array([o.n_filled for o in outs], dtype=np.int64)
    rest = _packed(models[0])[0].rest_ang[0]
    return RunsOutput(
        np.array([o.status for o in outs], dtype=np.int64),
        np.array([o.t_stop for o in outs]),
        n_filled,
        np.array([o.overturn_time[0] for o in outs]),
        np.stack([o.pos[:, 0, :] for o in outs]),
        ang,
        np.stack([o.angvel[:, 0] for o in outs]),
        *_summaries(ang, n_filled, rest, uplift_rad, sample_dt),
    )


@pytest.mark.parametrize("specimen", SINGLE_SPECIMENS)
@pytest.mark.slow
def test_runs_stepped_together_are_bit_identical_to_one_at_a_time(tmp_path, specimen):
    # more runs than a chunk (so that chunks and drop-outs mix), on one thread and on two
    tasks, repeat = _tasks(tmp_path, specimen), CHUNK_RUNS // len(RECORDS) // len(LOAD_FACTORS) + 1
    args = _kernel_inputs(tasks, repeat)
    assert args[7].size - 1 > CHUNK_RUNS
    each = _one_at_a_time(tasks, repeat, args[8], args[9])
    before = numba.get_num_threads()
    try:
        for threads in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):  # type: ignore[attr-defined]
            numba.set_num_threads(threads)
            together = simulate_runs(*args)
            for name, a, b in zip(each._fields, each, together, strict=True):
                assert a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True), (specimen, threads, name)
    finally:
        numba.set_num_threads(before)
    assert np.all(each.n_filled > 0)


def test_a_group_gives_the_reference_solvers_runs(tmp_path):
    overturned = completed = 0
    for specimen in SINGLE_SPECIMENS:
        tasks = _tasks(tmp_path, specimen)
        solver = tasks[0].solver
        assert len({solver.group_key(t.scene) for t in tasks}) == 1
        alpha = tasks[0].scene.blocks[0].classical().alpha_rad
        group = solver.run_group([t.scene for t in tasks], uplift_threshold_rad(alpha))
        for task, one in zip(tasks, group, strict=True):
            alone = solver.run(task.scene)
            name = task.scene.blocks[0].name
            theta = (
                alone.frame[f"{name}_theta_rad"].to_numpy()
                if f"{name}_theta_rad" in alone.frame
                else alone.frame["theta_rad"].to_numpy()
            )
            # the same verdict, at the same time, and the same rotations bit for bit
            assert one.status == alone.meta.status, task.labels
            assert one.meta.overturn_time_s == alone.meta.overturn_time_s
            assert one.meta.overturn_times_s == alone.meta.overturn_times_s
            assert np.array_equal(one.theta_rad, theta), task.labels
            assert one.metrics["max_abs_theta_rad"] == np.max(np.abs(theta))
            assert one.metrics["residual_theta_rad"] == theta[-1]
            overturned += one.status == "overturned"
            completed += one.status == "completed"
    assert overturned > 0 and completed > 0
