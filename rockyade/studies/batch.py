"""Batches: a study file expands into scenes; they run on local processes or a Dask cluster.

Study file (TOML)::

    name = "harmonic-sweep"
    solvers = ["reference", "housner"]     # each scene runs with each solver
    save_histories = true                  # the time history of every run (else summary only)
    yade_timeout_s = 600                   # optional: wall-clock limit of each YADE run, s

    [base]                                 # base scenes: one file, or several
    files = ["examples/specimen1_harmonic.toml", "examples/specimen3_free.toml"]

    [grid]                                 # product of the lists; keys are dotted paths
    "motion.frequency_hz" = [2.0, 3.3]     # into the scene ("blocks.0.mu", "motion", ...)
    "motion.amplitude_mm" = [2.0, 6.0]

Each run is named ``<scene hash>_<solver>``; ``runs/<name>.json`` (metadata and metrics) is
written for every run, ``runs/<name>.csv`` with the time history when asked. The summary
(``summary.csv``, and ``summary.parquet`` when pyarrow is installed) has one row per run:
the grid values, status, failure reason, wall time and per-block metrics (see
:func:`rockyade.analysis.run_metrics`, and the rocking pattern for stacks).

A failed run never stops the batch: its row says why. ``resume`` skips runs whose JSON
says they completed (or overturned) for the same scene hash and re-runs failed ones. The
summary is sorted by run order, so the same inputs give the same summary on either
executor (wall times aside).
"""

from __future__ import annotations

import copy
import itertools
import json
import os
import time
import tomllib
from collections.abc import Callable, Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pandas as pd

from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open, write_json
from rockyade.io.fields import TableReader
from rockyade.solvers import solver_names

EXECUTORS = ("local", "dask")
TIMING_COLUMNS = ("wall_time_s", "elapsed_s")


@dataclass(frozen=True)
class Task:
    """One run: a scene (canonical dictionary) and a solver.

    Attributes
    ----------
    index
        Position in the study (the summary's order).
    scene
        The scene as a dictionary (record files as absolute paths).
    solver
        Solver name.
    labels
        Grid values and base-scene name, for the summary.
    out_dir
        Where ``runs/`` is.
    save_history
        Write the time history as well as the metadata.
    """

    index: int
    scene: dict[str, Any]
    solver: str
    labels: dict[str, Any]
    out_dir: str
    save_history: bool = True
    extra: dict[str, Any] = field(default_factory=dict)
    yade_timeout_s: float | None = None


@dataclass(frozen=True)
class Study:
    """A parsed study: its tasks and settings."""

    name: str
    tasks: tuple[Task, ...]
    solvers: tuple[str, ...]


def _set_path(d: dict[str, Any], dotted: str, value: Any, source: str | None) -> None:
    parts = dotted.split(".")
    target: Any = d
    for i, part in enumerate(parts[:-1]):
        key: Any = int(part) if isinstance(target, list) else part
        try:
            target = target[key]
        except (KeyError, IndexError, ValueError, TypeError):
            raise InputError(f"grid.{dotted}", f"no '{'.'.join(parts[: i + 1])}' in the base scene", source) from None
    last: Any = int(parts[-1]) if isinstance(target, list) else parts[-1]
    target[last] = copy.deepcopy(value)


def _scene_dict(path: Path) -> dict[str, Any]:
    from rockyade.scene import load_scene

    return load_scene(path).to_dict()


def load_study(path: str | Path, out_dir: str | Path) -> Study:
    """Read a study file and expand it into tasks (scenes are validated now)."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("study", f"file not found: {path}")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise InputError("study", f"not valid TOML: {exc}", source) from None
    r = TableReader(data, "", source)
    name = r.string("name", path.stem)
    solvers = r.raw("solvers", ["reference"])
    if not isinstance(solvers, list) or not solvers or any(s not in solver_names() for s in solvers):
        raise r.error("solvers", f"must be a list of {', '.join(solver_names())}, got {solvers!r}")
    save = r.boolean("save_histories", True)
    from rockyade.solvers.yade import MAX_TIMEOUT_S

    timeout = r.number("yade_timeout_s", None, lo=0.0, lo_open=True, hi=MAX_TIMEOUT_S, unit="s")
    base = r.sub("base")
    files = base.raw("files", None)
    single = base.raw("file", None)
    if (files is None) == (single is None):
        raise base.error("files", "give exactly one of file and files")
    file_list = [single] if single is not None else files
    if not isinstance(file_list, list) or not all(isinstance(f, str) for f in file_list):
        raise base.error("files", "must be a list of scene file paths")
    base.finish()
    grid_table = r.raw("grid", {})
    if not isinstance(grid_table, dict):
        raise r.error("grid", "must be a table of dotted paths to lists of values")
    for key, values in grid_table.items():
        if not isinstance(values, list) or not values:
            raise InputError(f"grid.{key}", "must be a non-empty list of values", source)
    r.finish()
    bases = [(Path(f).stem, _scene_dict(path.parent / f)) for f in file_list]
    tasks = [replace(t, yade_timeout_s=timeout) for t in expand(bases, grid_table, solvers, out_dir, save, source)]
    return Study(name, tuple(tasks), tuple(solvers))


def expand(
    bases: list[tuple[str, dict[str, Any]]],
    grid: dict[str, list[Any]],
    solvers: Iterable[str],
    out_dir: str | Path,
    save_history: bool = True,
    source: str | None = None,
) -> list[Task]:
    """Tasks for every base scene x grid point x solver (validated scenes)."""
    from rockyade.scene import scene_from_dict

    keys = list(grid)
    tasks = []
    index = 0
    for base_name, base in bases:
        for values in itertools.product(*(grid[k] for k in keys)):
            d = copy.deepcopy(base)
            for key, value in zip(keys, values, strict=True):
                _set_path(d, key, value, source)
            scene = scene_from_dict(d, source=source)
            canonical = scene.to_dict()
            if "file" in canonical["motion"]:
                canonical["motion"]["file"] = str(Path(canonical["motion"]["file"]).resolve())
            labels = {"base": base_name, **{k: _label(v) for k, v in zip(keys, values, strict=True)}}
            for solver in solvers:
                tasks.append(Task(index, canonical, solver, labels, str(out_dir), save_history))
                index += 1
    return tasks


def _label(value: Any) -> Any:
    return value if isinstance(value, (int, float, str, bool)) else json.dumps(value, sort_keys=True)


# ---------------------------------------------------------------------- one run


def run_name(scene_hash: str, solver: str) -> str:
    """File stem of a run."""
    return f"{scene_hash}_{solver}"


def run_task(task: Task) -> dict[str, Any]:
    """Run one task; return its summary row. Never raises: failures become rows."""
    from rockyade.analysis.metrics import run_metrics
    from rockyade.result import failed_result
    from rockyade.scene import scene_from_dict
    from rockyade.solvers import get_solver

    start = time.perf_counter()
    runs = Path(task.out_dir) / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    scene = None
    try:
        scene = scene_from_dict(task.scene)
        name = run_name(scene.scene_hash, task.solver)
        solver = get_solver(task.solver)
        if task.solver == "yade":
            result = solver(scene, workdir=runs / "yade", name=name, timeout_s=task.yade_timeout_s)
        else:
            result = solver(scene)
    except Exception as exc:  # one failed run never stops the batch
        scene_hash = scene.scene_hash if scene is not None else "invalid"
        name = run_name(scene_hash, task.solver)
        result = failed_result(task.solver, scene_hash, f"{type(exc).__name__}: {exc}")
    row: dict[str, Any] = {
        "index": task.index,
        "run": name,
        "scene_hash": result.meta.get("scene_hash"),
        "solver": task.solver,
        **task.labels,
        "status": result.status,
        "failure_reason": result.meta.get("failure_reason") or "",
        "overturn_time_s": result.meta.get("overturn_time_s"),
        "overturned_block": result.meta.get("overturned_block") or "",
        "wall_time_s": result.meta.get("wall_time_s"),
    }
    if result.ok and scene is not None:
        metrics = run_metrics(scene, result)
        single = len(scene.blocks) == 1
        for block, values in metrics.items():
            for key, value in values.items():
                row[key if single else f"{block}_{key}"] = value
        if len(scene.blocks) == 2:
            from rockyade.analysis.patterns import classify_result

            pattern = classify_result(scene, result)
            row["pattern"] = pattern.dominant
            row["pattern_fractions"] = json.dumps(pattern.fractions, sort_keys=True)
    row["elapsed_s"] = time.perf_counter() - start
    meta = dict(result.meta)
    meta["summary"] = row
    if task.save_history and result.ok:
        result.write(runs / f"{name}.csv")  # writes <name>.json last
        _merge_json(runs / f"{name}.json", {"summary": row})
    else:
        write_json(runs / f"{name}.json", meta)
    return row


def _merge_json(path: Path, extra: dict[str, Any]) -> None:
    data = json.loads(path.read_text())
    data.update(extra)
    write_json(path, data)


def _completed_row(task: Task) -> dict[str, Any] | None:
    """The summary row of a run already completed (or overturned) for the same scene."""
    from rockyade.scene import scene_from_dict

    try:
        scene_hash = scene_from_dict(task.scene).scene_hash
    except Exception:
        return None
    path = Path(task.out_dir) / "runs" / f"{run_name(scene_hash, task.solver)}.json"
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    if data.get("status") in ("completed", "overturned") and data.get("scene_hash") == scene_hash and "summary" in data:
        row = dict(data["summary"])
        row["index"] = task.index
        row.update(task.labels)
        return row
    return None


# ---------------------------------------------------------------------- executors


def _progress(total: int, enabled: bool, desc: str):
    from tqdm import tqdm

    return tqdm(total=total, disable=not enabled, desc=desc, unit="run", smoothing=0.05)


def _run_local(tasks: list[Task], workers: int, on_done: Callable[[dict[str, Any]], None]) -> None:
    if workers <= 1:
        for task in tasks:
            on_done(run_task(task))
        return
    import multiprocessing

    ctx = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        futures = [pool.submit(run_task, t) for t in tasks]
        for future in as_completed(futures):
            on_done(future.result())


def _run_dask(
    tasks: list[Task], scheduler: str | None, workers: int, on_done: Callable[[dict[str, Any]], None]
) -> None:
    try:
        from dask.distributed import Client, LocalCluster
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise InputError(
            "executor", "the dask executor needs dask[distributed]: pip install 'rockyade[dask]'"
        ) from None
    cluster = None
    if scheduler:
        client = Client(scheduler)
    else:
        # no scheduler given: an in-process cluster (threads, in-process transport): no port opens
        cluster = LocalCluster(n_workers=1, threads_per_worker=max(1, workers), processes=False, dashboard_address=None)
        client = Client(cluster)
    try:
        futures = client.map(run_task, tasks, pure=False)
        for future in dask_completed(futures):
            on_done(future.result())
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_study_tasks(
    tasks: list[Task],
    out_dir: str | Path,
    *,
    executor: str = "local",
    workers: int = 2,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    desc: str = "runs",
) -> pd.DataFrame:
    """Run tasks and write the summary; return it (sorted by task order).

    Parameters
    ----------
    executor
        "local" (processes) or "dask" (``scheduler`` address, or an in-process cluster).
    resume
        Skip runs already completed for the same scene hash; re-run failed ones.
    """
    if executor not in EXECUTORS:
        raise InputError("executor", f"must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    if workers < 1:
        raise InputError("workers", f"must be >= 1, got {workers}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows: list[dict[str, Any]] = []
    todo = []
    for task in tasks:
        done = _completed_row(task) if resume else None
        if done is not None:
            rows.append(done)
        else:
            todo.append(task)
    bar = _progress(len(tasks), progress, desc)
    bar.update(len(rows))

    def on_done(row: dict[str, Any]) -> None:
        rows.append(row)
        bar.update(1)
        if row["status"] == "failed":
            bar.write(f"failed: {row['run']}: {row['failure_reason']}")

    try:
        if executor == "local":
            _run_local(todo, workers, on_done)
        else:
            _run_dask(todo, scheduler, workers, on_done)
    finally:
        bar.close()
    summary = _ordered(pd.DataFrame(rows).sort_values("index").reset_index(drop=True), tasks)
    write_summary(summary, out)
    return summary


LEADING_COLUMNS = ("index", "run", "scene_hash", "solver")
STATUS_COLUMNS = ("status", "failure_reason", "overturn_time_s", "overturned_block", "wall_time_s", "elapsed_s")


def _ordered(summary: pd.DataFrame, tasks: list[Task]) -> pd.DataFrame:
    """Columns in one canonical order (fresh, resumed or Dask rows alike)."""
    labels = list(tasks[0].labels) if tasks else []
    first = [c for c in (*LEADING_COLUMNS, *labels, *STATUS_COLUMNS) if c in summary.columns]
    rest = sorted(c for c in summary.columns if c not in first)
    return summary[first + rest]


def write_summary(summary: pd.DataFrame, out: Path) -> None:
    """``summary.csv`` (and ``summary.parquet`` when pyarrow is installed), atomically."""
    with atomic_open(out / "summary.csv") as fh:
        summary.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return
    with atomic_open(out / "summary.parquet", "wb") as fh:
        summary.to_parquet(fh, index=False)


def failures(summary: pd.DataFrame) -> pd.DataFrame:
    """Rows of failed runs with their reasons."""
    return summary.loc[summary["status"] == "failed", ["run", "solver", "failure_reason"]]


def comparable(summary: pd.DataFrame) -> pd.DataFrame:
    """The summary without timing columns (equal for equal inputs on any executor)."""
    return summary.drop(columns=[c for c in TIMING_COLUMNS if c in summary.columns])


__all__ = [
    "Study",
    "Task",
    "comparable",
    "expand",
    "failures",
    "load_study",
    "run_study_tasks",
    "run_task",
    "write_summary",
]
