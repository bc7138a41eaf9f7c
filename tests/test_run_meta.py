"""RunMeta, the typed metadata of a Result: it survives its files, older results load, and
every JSON the toolkit writes is strict (NaN and infinity as null, never a bare NaN token)."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import pickle
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rockyade.cli import main
from rockyade.io.atomic import write_json
from rockyade.io.strict_json import json_text, null_to_nan
from rockyade.result import Result, failed_result
from rockyade.run_meta import RunMeta
from rockyade.runner.journal import read_run, write_run
from rockyade.scene.generators import rest_motion, stack, write_scene

from .conftest import EXAMPLES


def _frame() -> pd.DataFrame:
    return pd.DataFrame({"t_s": np.arange(4) * 0.01, "theta_rad": [0.0, 1e-3, 2e-3, 1e-3]})


def _full_meta() -> RunMeta:
    """Every field set (finite values: NaN is not equal to itself)."""
    return RunMeta(
        status="overturned",
        solver="reference",
        version="rockyade test",
        scene_hash="abc123",
        failure_reason=None,
        partial=False,
        partial_samples=3,
        overturn_time_s=0.025,
        overturned_block="b",
        overturn_times_s={"b": 0.025},
        blocks=("b",),
        sample_dt_s=0.01,
        duration_s=0.03,
        dt_s=1e-5,
        dt_factor=0.5,
        wall_time_s=1.25,
        process_cpu_s=1.5,
        startup_time_s=0.1,
        setup_time_s=0.2,
        total_time_s=1.4,
        timeout_s=60.0,
        log_path="/tmp/x.log",
        motion_coverage={"status": "covered", "time_left_out_s": 0.0},
        bodies={"b": {"mass_kg": 2.0}},
        classical={"b": {"mu": 0.9}},
        n_steps=3000,
        iterations=2500,
        unconverged_steps=0,
        extra={"contact": {"b": {"kn": 1e8}}, "broad_phase": {"rebuilds": 1}},
    )


def test_a_result_written_and_read_has_the_same_metadata(tmp_path):
    meta = _full_meta()
    Result(_frame(), meta).write(tmp_path / "r.csv")
    back = Result.read(tmp_path / "r.csv")
    assert back.meta == meta
    assert back.meta.blocks == ("b",) and back.meta.extra["broad_phase"] == {"rebuilds": 1}
    assert pickle.loads(pickle.dumps(meta)) == meta  # results come back from worker processes


def test_a_run_meta_is_read_only_and_updated_by_replace():
    meta = _full_meta()
    with pytest.raises(dataclasses.FrozenInstanceError):
        meta.dt_factor = 1.0  # type: ignore[misc]
    with pytest.raises(TypeError):
        meta.extra["contact"] = None  # type: ignore[index]
    with pytest.raises(TypeError):
        meta.bodies["c"] = {}  # type: ignore[index]
    half = dataclasses.replace(meta, dt_factor=0.25)
    assert half.dt_factor == 0.25 and meta.dt_factor == 0.5 and half.bodies == meta.bodies
    more = meta.with_extra(note="x")
    assert more.extra["note"] == "x" and "note" not in meta.extra and more.extra["contact"] == meta.extra["contact"]


def test_a_status_out_of_its_set_is_refused():
    with pytest.raises(ValueError, match="status"):
        RunMeta.from_dict({"status": "finished"})
    with pytest.raises(ValueError, match="status"):
        RunMeta.from_dict({"solver": "housner"})  # no status at all


def _write_old_pair(folder: Path, meta_text: str) -> Path:
    """A result pair as the previous version wrote it: the CSV, and its JSON with the CSV's SHA-256."""
    csv = folder / "old.csv"
    text = "t_s,theta_rad\n0,0\n0.01,0.001\n"
    csv.write_text(text)
    digest = hashlib.sha256(text.encode()).hexdigest()
    meta_text = meta_text.replace("@SHA@", digest)
    (folder / "old.json").write_text(meta_text)
    return csv


def test_an_older_result_loads_unknown_keys_to_extra_and_missing_ones_by_default(tmp_path):
    """The previous version's JSON: Python's NaN token, keys RunMeta does not know, no
    ``rockyade_version``, ``dt_factor`` or ``motion_coverage``."""
    csv = _write_old_pair(
        tmp_path,
        """{
  "alpha_exceeded_time_s": NaN,
  "blocks": ["specimen1"],
  "classical": {"specimen1": {"mu": 0.936}},
  "columns": ["t_s", "theta_rad"],
  "csv_file": "old.csv",
  "csv_sha256": "@SHA@",
  "impacts": [0.5, 1.0],
  "old_only_key": {"a": 1},
  "overturn_time_s": null,
  "overturned_block": null,
  "sample_dt_s": 0.01,
  "scene_hash": "h",
  "solver": "housner",
  "status": "completed",
  "wall_time_s": 0.02
}
""",
    )
    back = Result.read(csv)
    meta = back.meta
    assert meta.status == "completed" and meta.solver == "housner" and meta.blocks == ("specimen1",)
    assert meta.wall_time_s == 0.02 and meta.sample_dt_s == 0.01 and meta.overturn_time_s is None
    assert meta.classical == {"specimen1": {"mu": 0.936}}
    assert meta.dt_factor is None and meta.motion_coverage is None and meta.overturn_times_s is None
    assert meta.extra["old_only_key"] == {"a": 1} and meta.extra["impacts"] == [0.5, 1.0]
    assert math.isnan(meta.extra["alpha_exceeded_time_s"])
    assert not {"columns", "csv_file", "csv_sha256"} & set(meta.extra)
    assert back.series("theta_rad").tolist() == [0.0, 0.001]


def test_an_older_failed_result_with_few_keys_loads(tmp_path):
    csv = _write_old_pair(
        tmp_path,
        '{"csv_sha256": "@SHA@", "status": "failed", "failure_reason": "YADE exited with 1", "solver": "yade"}',
    )
    meta = Result.read(csv).meta
    assert not meta.ok and meta.failure_reason == "YADE exited with 1" and meta.blocks == () and meta.version == ""


def test_not_finite_numbers_are_written_as_null_and_read_back_as_nan(tmp_path):
    failed = failed_result("yade", "h", "why", wall_time_s=math.nan, max_residual=math.inf, log_path=Path("/x"))
    failed.write(tmp_path / "f.csv")
    data = _strict_load(tmp_path / "f.json")
    assert data["wall_time_s"] is None and data["max_residual"] is None and data["log_path"] == "/x"
    back = Result.read(tmp_path / "f.csv").meta
    assert back.wall_time_s is None and back.extra["max_residual"] is None
    assert math.isnan(null_to_nan(back.extra["max_residual"])) and null_to_nan(2) == 2.0
    assert (
        json_text({"a": np.float64("nan"), "b": [np.int64(2), -math.inf]}, indent=None) == '{"a": null, "b": [2, null]}'
    )
    write_json(tmp_path / "x.json", {"v": np.array([1.0, math.nan])})
    assert _strict_load(tmp_path / "x.json") == {"v": [1.0, None]}


def test_a_journal_record_is_strict_and_its_row_reads_back_as_written(tmp_path):
    """NaN, infinity and None of a run's row are all null on disk; the row reads back with each
    as it was (a resumed study's table equals the one run at once)."""
    meta = dataclasses.replace(_full_meta(), status="completed", wall_time_s=math.nan)
    row = {"run": "run1", "uplift_time_s": np.float64("nan"), "ratio": -math.inf, "overturn_time_s": None, "n": 2}
    write_run(tmp_path, "run1", {**meta.to_dict(), "summary": row})
    data = _strict_load(tmp_path / "run1.json")
    assert data["wall_time_s"] is None and data["summary"]["uplift_time_s"] is None
    back = read_run(tmp_path, "run1", "abc123")
    assert back is not None and back["run"] == "run1" and back["n"] == 2 and back["overturn_time_s"] is None
    assert math.isnan(back["uplift_time_s"]) and back["ratio"] == -math.inf


def _refuse(token: str) -> float:
    raise AssertionError(f"not strict JSON: {token}")


def _strict_load(path: Path) -> object:
    """The JSON at ``path`` parsed by a strict reader: NaN, Infinity and -Infinity are refused."""
    return json.loads(path.read_text(), parse_constant=_refuse)


@pytest.mark.slow
def test_every_json_a_small_run_batch_and_assess_write_is_strict(tmp_path, capsys):
    """A Housner run (free rocking: its metadata holds NaN, a time never reached), a batch of
    two runs (their journal records) and an assessment (code checks, a fragility of a few runs)
    write JSON files; a strict parser reads every one of them."""
    code = main(["run", str(EXAMPLES / "specimen1_free.toml"), "--solver", "housner", "--out", str(tmp_path / "r.csv")])
    assert code == 0
    meta = Result.read(tmp_path / "r.csv").meta
    assert meta.solver == "housner" and meta.dt_factor == 1.0 and meta.motion_coverage is not None

    study = tmp_path / "study.toml"
    study.write_text(f"""
name = "tiny"
solvers = ["housner"]
[base]
file = "{EXAMPLES / "specimen1_pulse.toml"}"
[grid]
"motion.amplitude_m_s2" = [1.962, 4.905]
""")
    assert main(["batch", str(study), "--out", str(tmp_path / "batch"), "--workers", "1", "--quiet"]) == 0

    records = tmp_path / "records"
    records.mkdir()
    shutil.copy(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2", records)
    wall = tmp_path / "wall.toml"
    write_scene(wall, stack(widths_m=[0.25], heights_m=1.0, thickness_m=1.0, layout="column", motion=rest_motion()))
    argv = ["assess", str(wall), "--knowledge-level", "LC1", "--spectrum-type", "1", "--ground", "B", "--ag", "0.25g",
            "--records", str(records), "--load-factors", "0.5,8", "--no-extend", "--solver", "housner",
            "--workers", "1", "--out", str(tmp_path / "assess"), "--quiet"]  # fmt: skip
    assert main(argv) == 0
    capsys.readouterr()

    files = sorted(tmp_path.rglob("*.json"))
    names = {str(f.relative_to(tmp_path)) for f in files}
    assert {"r.json", "assess/assess.json", "batch/study.json"} <= names, names
    nulls = 0
    for path in files:
        text = path.read_text()
        _strict_load(path)
        nulls += text.count("null")
    assert nulls > 0  # some number was not finite, and it was written as null


def test_mypy_sees_a_misspelt_metadata_attribute(tmp_path):
    """The point of typed metadata: ``meta.wall_time`` (for ``wall_time_s``) is an error before
    any run, where ``meta["wall_time"]`` was a KeyError (or a silent None) after one."""
    api = pytest.importorskip("mypy.api")
    snippet = tmp_path / "snippet.py"
    snippet.write_text(
        "from rockyade.run_meta import RunMeta\n\n\n"
        "def wall(meta: RunMeta) -> float | None:\n"
        "    return meta.wall_time\n\n\n"
        "def fine(meta: RunMeta) -> float | None:\n"
        "    return meta.wall_time_s\n"
    )
    out, _err, status = api.run(
        [str(snippet), "--follow-imports=silent", "--no-incremental", "--cache-dir", str(tmp_path / "cache")]
    )
    assert status == 1 and '"RunMeta" has no attribute "wall_time"' in out and out.count("error:") == 1, out


def test_a_workers_metadata_is_read_into_its_typed_form():
    """The drivers' JSON (YADE's names, Siconos's; an older driver without the newer keys)."""
    from rockyade.dem.worker_output import WorkerOutput

    yade = WorkerOutput.from_json(
        '{"status": "overturned", "stop_time_s": 1.5, "overturn_times_s": {"0": 1.5}, "stop_body": 0, "n_filled": 151,'
        ' "iterations": 30000, "wall_time_s": 2.0, "yade_version": "2023.02a", "dt_s": 5e-05, "complete": true,'
        ' "max_polyhedra_penetration_over_radius": 0.2, "deep_overlap_time_s": null, "flushes": 3}'
    )
    assert yade.status == "overturned" and yade.steps == 30000 and yade.version == "2023.02a" and yade.complete
    assert yade.overturn_times_s == {"0": 1.5} and yade.stop_body == 0 and yade.deep_overlap_time_s is None
    assert yade.max_residual == 0.0 and yade.solver_calls == 0  # Siconos's keys: their defaults
    older = {"status": "running", "n_filled": 3, "steps": 12, "siconos_version": "4.4", "solver_calls": 12}
    siconos = WorkerOutput.from_dict({**older, "max_residual": 1e-9, "first_unconverged_s": None})
    assert siconos.steps == 12 and siconos.version == "4.4" and not siconos.complete and siconos.wall_time_s is None
    with pytest.raises(KeyError):
        WorkerOutput.from_dict({"n_filled": 3})
    with pytest.raises(ValueError):
        WorkerOutput.from_json("[1, 2]")
