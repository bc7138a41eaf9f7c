"""Runs of one structure stepped together (rockyade.kernel.runs.simulate_runs) give the same
bits as one run at a time: against the per-run kernel (simulate_runs_each) and against the
reference DEM's own run of each scene (ReferenceSolver.run), over the paper's four specimens,
several synthetic records and load factors that overturn some of them."""

from __future__ import annotations

from dataclasses import replace

import numba
import numpy as np
import pytest

from rockyade.analysis.metrics import uplift_threshold_rad
from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.engine import model_arrays
from rockyade.kernel.runs import CHUNK_RUNS, simulate_runs, simulate_runs_each
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


def _kernel_inputs(tasks, repeat: int = 1):
    """The packed structure and the runs' motions (each task ``repeat`` times) of one group."""
    base = calibrated_model(tasks[0].scene)
    models = [replace(base, motion=t.scene.motion.ground_motion(t.scene.duration_s)) for t in tasks] * repeat
    b, j, _, st, i = pack(
        model_arrays(base), stop_on_overturn=True, record_energy=False, record_corners=False, coherent=True
    )
    motions = [model_arrays_motion(m) for m in models]
    starts = np.cumsum([0] + [m[0].size for m in motions])
    mt, mah, mav = (np.concatenate([m[k] for m in motions]) for k in range(3))
    alpha = tasks[0].scene.blocks[0].classical().alpha_rad
    return (b, j, st, i, mt, mah, mav, starts, uplift_threshold_rad(alpha), base.sample_dt_s)


@pytest.mark.parametrize("specimen", SINGLE_SPECIMENS)
@pytest.mark.slow
def test_runs_stepped_together_are_bit_identical_to_one_at_a_time(tmp_path, specimen):
    # more runs than a chunk (so that chunks and drop-outs mix), on one thread and on two
    args = _kernel_inputs(_tasks(tmp_path, specimen), repeat=CHUNK_RUNS // len(RECORDS) // len(LOAD_FACTORS) + 1)
    assert args[7].size - 1 > CHUNK_RUNS
    each = simulate_runs_each(*args)
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
