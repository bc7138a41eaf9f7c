"""Solvers as objects and the runner: options checked by name, tasks and solvers that pickle
small and run the same anywhere, every executor giving the same results, a dead worker
failing its job alone, and callers that never branch on a solver's name."""

from __future__ import annotations

import os
import pickle
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd
import pytest

from rockyade.batch import comparable, expand, load_study, run_study_tasks, study_tasks
from rockyade.batch.running import keeping_files, output
from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.runner import IN_THIS_THREAD, Executor, Task, run_jobs, run_tasks, solve, solve_scenes
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers import make_solver, make_solvers, run, solver_names
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.solvers.yade import YadeSolver

from .conftest import EXAMPLES

# ------------------------------------------------------------------ solvers as objects


def test_the_registry_hands_back_solver_objects_that_pickle():
    for name in solver_names():
        solver = make_solver(name)
        assert solver.name == name
        assert pickle.loads(pickle.dumps(solver)) == solver
    yade = make_solver("yade", timeout_s=90, workdir="runs/yade")
    assert yade == YadeSolver(timeout_s=90.0, workdir="runs/yade")
    assert pickle.loads(pickle.dumps(yade)).timeout_s == 90.0
    assert make_solver("reference", record_energy=False) == ReferenceSolver(record_energy=False)


def test_options_that_do_not_apply_are_refused_naming_the_option():
    with pytest.raises(InputError) as info:
        make_solver("reference", timeout_s=5)
    assert info.value.field == "timeout_s" and "reference" in str(info.value)
    with pytest.raises(InputError) as info:
        make_solvers(["housner", "reference"], {"timeout_s": 5}, {"timeout_s": "--yade-timeout"})
    assert info.value.field == "--yade-timeout" and "applies to the yade and siconos solvers only" in str(info.value)
    with pytest.raises(InputError) as info:
        make_solver("yade", timeout_s=-1, fields={"timeout_s": "--yade-timeout"})
    assert info.value.field == "--yade-timeout"
    with pytest.raises(InputError) as info:
        make_solver("reference", record_energy="yes")
    assert info.value.field == "record_energy"
    # an option goes to the solvers that take it
    housner, yade = make_solvers(["housner", "yade"], {"timeout_s": 30})
    assert housner == HousnerSolver() and yade.timeout_s == 30.0


@pytest.mark.parametrize("kind", ["local", "threads", "dask"])
def test_more_workers_than_cores_is_said_once_and_accepted(kind, monkeypatch):
    """A note (not an error) when this machine's workers outnumber its cores: 1000 workers on
    2 cores gave a batch's first result after 31 s against 6 s for the whole study with one."""
    import warnings

    from rockyade.errors import InputNote
    from rockyade.runner import executor

    monkeypatch.setattr(executor, "usable_cores", lambda: 4)
    with pytest.warns(InputNote, match=r"^workers: 5 parallel workers on this machine's 4 cores"):
        assert Executor(kind, 5).workers == 5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Executor(kind, 4)  # as many as the cores: nothing to say
        monkeypatch.setattr(executor, "usable_cores", lambda: 1)
        Executor(kind, 2)  # the default, even on one core
        if kind == "dask":
            Executor(kind, 64, scheduler="tcp://127.0.0.1:8786")  # a cluster's workers are its own


def test_the_progress_bar_counts_runs_when_a_job_holds_several(capsys):
    """A study's jobs are groups of runs: its bar counts the runs (a cross-check's said 21/27 while
    57 runs had finished), and runs done before a resume are counted as done."""
    jobs = [("a", "b", "c"), ("d",), ("e", "f")]
    run_jobs(jobs, len, progress=True, desc="groups", skipped=4, size=len)
    err = capsys.readouterr().err
    assert "10/10" in err and "run/s" in err
    run_jobs(jobs, len, progress=True, desc="plain")
    assert "3/3" in capsys.readouterr().err  # one a job without size


def test_the_command_line_refuses_yade_options_without_yade(tmp_path, capsys):
    scene = str(EXAMPLES / "specimen1_free.toml")
    assert main(["run", scene, "--solver", "reference", "--yade-timeout", "5"]) == 2
    assert "error: --yade-timeout: applies to the yade and siconos solvers only" in capsys.readouterr().err
    argv = ["compare", scene, "--solvers", "housner,reference", "--yade-timeout", "5", "--out", str(tmp_path / "c")]
    assert main(argv) == 2
    assert "--yade-timeout" in capsys.readouterr().err and not (tmp_path / "c").exists()


def test_a_study_file_refuses_a_yade_timeout_without_yade(tmp_path):
    study = tmp_path / "study.toml"
    body = f'yade_timeout_s = 60\n[base]\nfile = "{EXAMPLES / "specimen1_free.toml"}"\n'
    study.write_text('solvers = ["reference"]\n' + body)
    with pytest.raises(InputError) as info:
        load_study(study)
    assert info.value.field == "yade_timeout_s" and info.value.source == str(study)
    # the command line's value replaces the file's, and is named as the command line names it
    study.write_text('solvers = ["yade"]\n' + body)
    loaded = load_study(study, {"timeout_s": 7.0}, {"timeout_s": "--yade-timeout"})
    assert {t.solver.timeout_s for t in study_tasks(loaded)} == {7.0}
    with pytest.raises(InputError) as info:
        load_study(study, {"timeout_s": 0.0}, {"timeout_s": "--yade-timeout"})
    assert info.value.field == "--yade-timeout"


def test_yade_files_are_named_by_the_solver_s_options_and_the_scene_hash(tmp_path):
    """A batch places YADE's files under runs/yade/, named by scene hash; a run of its own
    names them after its result."""
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    tasks = expand([("s", base)], {"motion.theta0_rad": [0.03]}, ["yade", "housner"])
    yade, housner = (keeping_files(t, output(tmp_path / "out")).solver for t in tasks)
    assert yade.workdir == str(tmp_path / "out" / "runs" / "yade") and yade.stem is None
    assert housner == HousnerSolver()  # keeps no files
    assert YadeSolver().keeping_files(tmp_path, "r") == YadeSolver(workdir=str(tmp_path), stem="r")


@dataclass(frozen=True)
class SlowerHousner(HousnerSolver):
    """A solver the registry does not know, to show that nothing branches on names: Housner's
    exact solution under another name, with a cost model of its own."""

    name: ClassVar[str] = "housner_renamed"

    def estimate_cost(self, scene):
        from dataclasses import replace

        return replace(super().estimate_cost(scene), integration_steps=3e8)  # above the limit


def test_a_solver_the_registry_does_not_know_runs_through_batches(tmp_path):
    base = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    base["duration_s"] = 1.0
    tasks = expand([("s", base)], {"motion.theta0_rad": [0.05, 0.1]}, [SlowerHousner()])
    with pytest.raises(InputError) as info:  # its own cost model answers
        run_study_tasks(tasks, tmp_path, workers=1, progress=False)
    assert info.value.field == "allow_large"
    assert "the housner_renamed run needs 3e+08 integration steps" in str(info.value)
    summary = run_study_tasks(tasks, tmp_path, workers=2, progress=False, allow_large=True)
    assert list(summary.solver) == ["housner_renamed"] * 2 and (summary.status == "completed").all()
    exact = run(scene_from_dict({**base, "motion": {"type": "free", "theta0_rad": 0.1}}), "housner")
    assert summary.max_abs_theta_rad.iloc[1] == pytest.approx(np.max(np.abs(exact.series("theta_rad"))), rel=1e-12)
    assert all(run.endswith("_housner_renamed") for run in summary.run)


# ------------------------------------------------------------------ tasks travel light


def test_tasks_pickle_small_and_run_the_same_after_the_trip():
    """A record is named by its file, not carried: a task weighs a few kB where the record's
    samples alone weigh more, and the scene, its hash and its result survive the trip."""
    scene = load_scene(EXAMPLES / "specimen1_record.toml")
    task = Task(0, HousnerSolver(), scene)
    data = pickle.dumps(task)
    motion = scene.motion.ground_motion(scene.duration_s)
    assert len(data) < 4000 < len(pickle.dumps((motion.t_s, motion.ah_m_s2)))
    back = pickle.loads(data)
    assert back.scene == scene and back.scene_hash == scene.scene_hash == back.scene.scene_hash
    pd.testing.assert_frame_equal(solve(back).frame, solve(task).frame)
    synthetic = Task(1, ReferenceSolver(), load_scene(EXAMPLES / "specimen2_record21.toml"))
    assert len(pickle.dumps(synthetic)) < 4000


# ------------------------------------------------------------------ executors


def _free_scenes():
    base = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    base["duration_s"] = 1.5
    good = [scene_from_dict({**base, "motion": {"type": "free", "theta0_rad": th}}) for th in (0.05, 0.1, 0.12)]
    bad = scene_from_dict(
        {**base, "contact": {"calibration": "matched"}, "blocks": [{**base["blocks"][0], "mu": 0.999}]}
    )
    return [good[0], bad, *good[1:]]


@pytest.mark.parametrize("executor", [Executor("threads", 2), Executor("local", 2), Executor("dask", 2)])
def test_every_executor_gives_the_results_of_one_thread(executor):
    if executor.kind == "dask":
        pytest.importorskip("dask")
    scenes = _free_scenes()
    solver = ReferenceSolver(record_energy=False, record_contacts=False)
    serial = solve_scenes(solver, scenes, executor=IN_THIS_THREAD)
    parallel = solve_scenes(solver, scenes, executor=executor)
    assert [r.status for r in parallel] == ["completed", "failed", "completed", "completed"]
    assert "CalibrationError" in parallel[1].meta.failure_reason
    for a, b in zip(parallel, serial, strict=True):
        pd.testing.assert_frame_equal(a.frame, b.frame)


def _exit_on_two(job: int) -> int:
    if job == 2:
        os._exit(7)  # the worker process dies: no exception, no result
    return job * job


def test_a_dead_worker_fails_its_job_and_the_others_finish():
    """The pool breaks with its worker: the job that ran beside it (if any) fails with the
    same reason, a fresh pool runs the rest."""
    outcome = run_jobs(
        range(8), _exit_on_two, executor=Executor("local", 2), failed=lambda job, reason: f"failed {job}: {reason}"
    )
    values = outcome.in_order()
    assert values[2] == "failed 2: the worker process died (killed, or out of memory)"
    failed = [i for i, v in enumerate(values) if isinstance(v, str)]
    assert 2 in failed and len(failed) <= 2
    assert all(v == i * i for i, v in enumerate(values) if i not in failed)
    assert not outcome.stopped and not outcome.unfinished


def test_costs_are_checked_before_any_run():
    small = load_scene(EXAMPLES / "specimen1_free.toml")
    large = scene_from_dict({**small.to_dict(), "duration_s": 100.0, "sample_dt_s": 1e-5})
    ran = []
    tasks = [Task(0, HousnerSolver(), small, {"case": "small"}), Task(1, HousnerSolver(), large, {"case": "large"})]
    with pytest.raises(InputError) as info:
        run_tasks(tasks, lambda task: ran.append(task.index))
    assert info.value.field == "allow_large" and "run 1 (case = large)" in str(info.value) and ran == []


def test_a_batch_on_threads_equals_local_processes(tmp_path):
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    base["duration_s"] = 1.0
    grid = {"motion.theta0_rad": [0.03, 0.06]}

    def batch(out, **executor):
        tasks = expand([("s", base)], grid, ["reference", "housner"])
        return run_study_tasks(tasks, out, progress=False, **executor)

    local = batch(tmp_path / "a", executor=Executor("local", 2))
    threads = batch(tmp_path / "b", executor="threads", workers=2)
    pd.testing.assert_frame_equal(comparable(local), comparable(threads))
