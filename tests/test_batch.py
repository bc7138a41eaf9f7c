"""Batch engine, rocking patterns of the bi-block, fragility fits."""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pandas as pd
import pytest

from rockyade.analysis.patterns import classify, classify_samples
from rockyade.batch import comparable, expand, failures, load_study, run_study_tasks, study_tasks
from rockyade.errors import InputError
from rockyade.scene import load_scene

from .conftest import EXAMPLES


def _tasks(out, extra_bad: bool = False):
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    base["duration_s"] = 1.0
    bases = [("specimen3", base)]
    if extra_bad:
        bad = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
        bad["duration_s"] = 1.0
        bad["blocks"][0]["mu"] = 0.999  # above what the DEM reaches: matched calibration fails
        bad["contact"]["calibration"] = "matched"
        bases.append(("unreachable", bad))
    grid = {"motion.theta0_rad": [0.03, 0.06], "blocks.0.p_rad_s": [3.5, 3.61]}
    return expand(bases, grid, ["reference", "housner"], save_history=True)


def test_expand_grid_and_labels(tmp_path):
    tasks = _tasks(tmp_path)
    assert len(tasks) == 2 * 2 * 2
    assert [t.index for t in tasks] == list(range(8))
    assert tasks[0].labels == {"base": "specimen3", "motion.theta0_rad": 0.03, "blocks.0.p_rad_s": 3.5}
    assert {t.solver.name for t in tasks} == {"reference", "housner"}
    assert tasks[0].scene.blocks[0].p_rad_s == 3.5


def test_batch_runs_isolates_failures_and_resumes(tmp_path):
    tasks = _tasks(tmp_path, extra_bad=True)
    summary = run_study_tasks(tasks, tmp_path, workers=2, progress=False)
    assert len(summary) == len(tasks) and list(summary["index"]) == list(range(len(tasks)))
    failed = failures(summary)
    assert len(failed) == 4 and (summary[summary.base == "specimen3"].status == "completed").all()
    assert failed["failure_reason"].str.contains("CalibrationError").all()
    assert failed["failure_reason"].str.contains("reachable range").all()
    for row in summary[summary.status == "completed"].itertuples():
        assert (tmp_path / "runs" / f"{row.run}.csv").is_file()
        data = json.loads((tmp_path / "runs" / f"{row.run}.json").read_text())
        assert data["summary"]["status"] == "completed" and data["scene_hash"] == row.scene_hash
    assert (tmp_path / "summary.csv").is_file() and (tmp_path / "summary.parquet").is_file()
    back = pd.read_csv(tmp_path / "summary.csv")
    assert len(back) == len(tasks) and "max_abs_theta_rad" in back.columns

    # resume: completed runs are not run again, failed ones are
    stamps = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "runs").glob("*.json")}
    again = run_study_tasks(tasks, tmp_path, workers=2, resume=True, progress=False)
    for row in again.itertuples():
        stamp = (tmp_path / "runs" / f"{row.run}.json").stat().st_mtime_ns
        if row.status == "completed":
            assert stamp == stamps[f"{row.run}.json"]
        else:
            assert stamp != stamps[f"{row.run}.json"]
    pd.testing.assert_frame_equal(
        comparable(again).drop(columns=["failure_reason"]),
        comparable(summary).drop(columns=["failure_reason"]),
        check_dtype=False,
    )


@pytest.mark.slow
def test_dask_executor_equals_local(tmp_path):
    distributed = pytest.importorskip("distributed")
    tasks_local = _tasks(tmp_path / "local")
    tasks_dask = _tasks(tmp_path / "dask")
    local = run_study_tasks(tasks_local, tmp_path / "local", workers=2, progress=False)
    # one worker, a thread of this process, the scheduler's comms on TCP (every job and result
    # serialised through the loopback, as to a remote worker): the test is about a scheduler's
    # results equal to local ones, not about its processes (a worker process only added its
    # start-up, a Python importing dask and rockyade; test_dask_deployment runs Dask's own
    # scheduler and worker processes)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1", dashboard_address=None
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")  # loopback only
        dask = run_study_tasks(
            tasks_dask, tmp_path / "dask", executor="dask", scheduler=cluster.scheduler_address, progress=False
        )
    pd.testing.assert_frame_equal(comparable(local), comparable(dask))


def test_dask_without_scheduler_runs_in_process(tmp_path):
    pytest.importorskip("distributed")
    tasks = _tasks(tmp_path)[:2]
    summary = run_study_tasks(tasks, tmp_path, executor="dask", workers=2, progress=False)
    assert (summary.status == "completed").all()


def test_study_file_and_cli(tmp_path, capsys):
    from rockyade.cli import main

    study = tmp_path / "study.toml"
    study.write_text(f"""
name = "tiny"
solvers = ["housner", "reference"]
[base]
file = "{EXAMPLES / "specimen1_pulse.toml"}"
[grid]
"motion.amplitude_m_s2" = [1.962, 4.905]
""")
    loaded = load_study(study)
    assert loaded.name == "tiny" and loaded.run_count == len(list(study_tasks(loaded))) == 4
    code = main(["batch", str(study), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet"])
    out = capsys.readouterr().out
    summary = pd.read_csv(tmp_path / "out" / "summary.csv")
    assert code == 0 and "4 runs" in out
    by_amp = summary.groupby("motion.amplitude_m_s2")["status"].agg(set)
    assert by_amp[1.962] == {"completed"} and by_amp[4.905] == {"overturned"}


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ('solvers = ["nope"]\n[base]\nfile = "x.toml"\n', "solvers"),
        ("[base]\n", "base.files"),
        (
            f'[base]\nfile = "{EXAMPLES / "specimen1_free.toml"}"\n[grid]\n"motion.theta0_rad" = []\n',
            "grid.motion.theta0_rad",
        ),
        (f'[base]\nfile = "{EXAMPLES / "specimen1_free.toml"}"\n[grid]\n"blocks.3.mu" = [0.9]\n', "grid.blocks.3.mu"),
        (f'[base]\nfile = "{EXAMPLES / "specimen1_free.toml"}"\n[grid]\n"blocks.0.mu" = [2.0]\n', "blocks[0].mu"),
    ],
)
def test_bad_study_files(tmp_path, text, field):
    study = tmp_path / "s.toml"
    study.write_text(text)
    with pytest.raises(InputError) as info:  # the file when read, a grid point when it is made
        list(study_tasks(load_study(study)))
    assert info.value.field == field


def test_the_example_study_loads():
    study = load_study(EXAMPLES / "studies" / "harmonic_sweep.toml")
    assert len(list(study_tasks(study))) == study.run_count == 2 * 3 * 2 * 2


# ------------------------------------------------------------------ patterns

T = np.linspace(0, 10, 5001)
WAVE = np.sin(2 * math.pi * 2 * T)
AL, AU = 0.366, 0.229


@pytest.mark.parametrize(
    ("lower", "upper", "expected"),
    [
        (1e-7 * WAVE, 1e-7 * WAVE, "rest"),
        (0.02 * WAVE, 0.02 * WAVE, "3"),  # the stack rocks as one body
        (1e-7 * WAVE, 0.05 * WAVE, "4"),  # only the upper block
        (0.02 * WAVE, 0.06 * WAVE, "1"),  # same way
        (0.02 * WAVE, -0.04 * WAVE, "2"),  # opposite ways
    ],
)
def test_pattern_of_synthetic_histories(lower, upper, expected):
    report = classify(T, lower, upper, AL, AU)
    assert report.dominant == expected
    if expected != "rest":
        assert report.fractions[expected] > 0.8  # the samples near zero crossings are "rest"


def test_pattern_windows_thresholds_and_overturn():
    lower = np.where(T < 5, 0.0, 0.02 * WAVE)
    upper = np.where(T < 5, 0.0, -0.04 * WAVE)
    report = classify(T, lower, upper, AL, AU)
    assert [w[2] for w in report.windows[:5]] == ["rest"] * 5 and all(w[2] == "2" for w in report.windows[5:])
    assert report.dominant == "2"
    # the threshold: 1 % of alpha
    assert classify_samples(np.array([0.009 * AL]), np.array([0.009 * AL]), AL, AU)[0] == "rest"
    assert classify_samples(np.array([0.011 * AL]), np.array([0.011 * AL]), AL, AU)[0] == "3"
    assert classify(T, lower, upper, AL, AU, overturned="upper").dominant == "overturn-upper"


def test_pattern_of_a_real_stack_run():
    from rockyade.analysis.patterns import classify_result
    from rockyade.scene import scene_from_dict
    from rockyade.solvers.reference import ReferenceSolver

    d = load_scene(EXAMPLES / "biblock_free.toml").to_dict()
    d["motion"] = {"type": "harmonic", "amplitude_mm": 2.0, "frequency_hz": 6.0, "cycles": 8}
    d["duration_s"] = 3.0
    scene = scene_from_dict(d)
    report = classify_result(scene, ReferenceSolver().run(scene))
    assert report.dominant == "4"  # 6 Hz / 2 mm: 2.8 m/s^2 lifts the upper block only


def test_no_network_listening_in_local_batches(tmp_path):
    """The local executor uses process pools: no socket is opened by the batch itself."""
    before = set(os.listdir("/proc/self/fd"))
    run_study_tasks(_tasks(tmp_path)[:2], tmp_path, workers=1, progress=False)
    after = set(os.listdir("/proc/self/fd"))
    sockets = [f for f in after - before if os.readlink(f"/proc/self/fd/{f}").startswith("socket:")]
    assert not sockets


@pytest.mark.slow
def test_paper_command_writes_index(tmp_path, capsys):
    from rockyade.cli import main

    code = main(["paper", "--out", str(tmp_path), "--only", "tables,sensitivity", "--no-yade"])
    assert code == 0
    index = (tmp_path / "index.md").read_text()
    assert "Tables 1-6 reproduced" in index and "Sensitivity" in index
    for name in ("table5_reproduced.csv", "sensitivity.csv", "sensitivity.png"):
        assert (tmp_path / name).is_file() and name in index
    table5 = pd.read_csv(tmp_path / "table5_reproduced.csv")
    assert {"paper", "ours", "diff_pct", "consistent"} <= set(table5.columns)
    with pytest.raises(SystemExit):
        main(["paper", "--bogus"])
    assert main(["paper", "--out", str(tmp_path), "--only", "nope"]) == 2
