"""Batches: a study file expands into tasks; the runner runs them; one summary row per run.

Study file (TOML)::

    name = "harmonic-sweep"
    solvers = ["reference", "housner"]     # each scene runs with each solver
    save_histories = true                  # the time history of every run (else summary only)
    yade_timeout_s = 600                   # optional: YADE's timeout_s, the wall-clock limit of each run, s

    [base]                                 # base scenes: one file, or several
    files = ["examples/specimen1_harmonic.toml", "examples/specimen3_free.toml"]

    [grid]                                 # product of the lists; keys are dotted paths
    "motion.frequency_hz" = [2.0, 3.3]     # into the scene ("blocks.0.mu", "motion", ...)
    "motion.amplitude_mm" = [2.0, 6.0]

Each run is named ``<scene hash>_<solver>``; ``runs/<name>.json`` (metadata and metrics) is
written for every run, ``runs/<name>.csv`` with the time history when asked; a solver that
keeps files of its own keeps them in ``runs/<solver>/`` (YADE: its scene data and log). The
summary (``summary.csv``, and ``summary.parquet`` when pyarrow is installed) has one row per
run: the grid values, status, failure reason, wall time and per-block metrics (see
:func:`rockyade.analysis.run_metrics`, and the rocking pattern for stacks).

A run's JSON is its record in the journal of finished runs that every study command shares
(:mod:`rockyade.runner.journal`): written atomically and fsynced, file and folder, as the run
ends (a killed batch, or a power cut, leaves whole records or none).

A failed run never stops the batch: its row says why (a full disk too: the run fails with
that reason and the batch goes on). ``resume`` skips runs whose JSON says they completed
(or overturned) for the same scene hash and re-runs failed ones
(:func:`rockyade.runner.journal.read_run`). The summary is sorted by
run order, so the same inputs give the same summary on any executor (wall times aside).

The runs go through :mod:`rockyade.runner`: costs checked before any run (``allow_large``
lifts the limits), local processes or Dask, Ctrl-C, worker lifetime. One batch at a time
may write an output directory (a lock); what a killed batch left (temporary files, a result
between its two renames) is settled when the next one starts. After Ctrl-C ``summary.csv``
is written with what finished, the unfinished runs listed with status ``unfinished``, and
:class:`~rockyade.errors.BatchInterruptedError` is raised.
"""

from __future__ import annotations

import contextlib
import copy
import itertools
import json
import time
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.errors import BatchInterruptedError, InputError, os_error_message
from rockyade.io.atomic import atomic_open, remove_stale_temporaries
from rockyade.io.fields import TableReader
from rockyade.io.folders import output_folder
from rockyade.io.locking import lock_token, output_lock, writing_for
from rockyade.motion.types import RecordMotion
from rockyade.result import Result
from rockyade.run_meta import RunMeta
from rockyade.runner import Executor, Task, check_costs, run_jobs, solve
from rockyade.runner.executor import SCHEDULER_TIMEOUT_S
from rockyade.runner.groups import group_jobs
from rockyade.runner.journal import claim, marked_record, read_run, write_run
from rockyade.scene import Scene
from rockyade.solvers import as_solver, make_solvers, solver_names
from rockyade.solvers.base import GroupSolver, Solver

TIMING_COLUMNS = ("wall_time_s", "elapsed_s")
#: Status of a run that a Ctrl-C stopped or kept from starting (summary only).
UNFINISHED = "unfinished"
#: Study-file keys that set a solver's option: key -> option.
SOLVER_OPTION_KEYS = {"yade_timeout_s": "timeout_s"}
#: Runs a study may expand into (base scenes x grid points x solvers); ``allow_large``
#: (``--allow-large``) lifts it up to MAX_RUNS_ALLOWED, a ceiling nothing lifts (every run is
#: a validated scene held in memory, about 2 kB, and is validated in about 5 ms).
MAX_RUNS = 100_000
MAX_RUNS_ALLOWED = 1_000_000
#: Largest study file, bytes: a grid is lists of values (1 MiB holds some 200,000 numbers;
#: Python's TOML reader takes about 0.6 s for it); the count check above then refuses more.
MAX_STUDY_BYTES = 1024 * 1024
#: Keys of the scene format that a table takes only alone (its readers refuse both, saying
#: "give exactly one of ..." or "give either ... or ..."): a grid key replaces its
#: alternatives in the table it sets. The base scene is read into its canonical form, which
#: may hold the other key (a pulse given in g holds amplitude_m_s2).
ALTERNATIVES: dict[str, tuple[str, ...]] = {
    # a pulse (motion)
    "amplitude_g": ("amplitude_m_s2",),
    "amplitude_m_s2": ("amplitude_g",),
    # a harmonic motion (motion)
    "cycles": ("duration_s",),
    "duration_s": ("cycles",),
    # a sampled motion (motion)
    "dt_s": ("t_s",),
    "t_s": ("dt_s",),
    # a block (blocks.<i>)
    "mass_kg": ("density_kg_m3",),
    "density_kg_m3": ("mass_kg",),
    "inertia_kgm2": ("p_rad_s",),
    "p_rad_s": ("inertia_kgm2",),
    "vertices_m": ("width_m", "height_m"),
    "width_m": ("vertices_m",),
    "height_m": ("vertices_m",),
}


@dataclass(frozen=True)
class BatchTask(Task):
    """One run of a batch: a task (:class:`rockyade.runner.Task`) and where its result goes.

    Attributes
    ----------
    out_dir
        Where ``runs/`` is.
    save_history
        Write the time history as well as the metadata.
    lock_token
        The token of the batch's lock on ``out_dir`` (set when the batch runs): the run writes
        there on the batch's behalf (:func:`rockyade.io.locking.writing_for`), wherever it runs.
    """

    out_dir: str = "."
    save_history: bool = True
    lock_token: str = ""


@dataclass(frozen=True)
class Study:
    """A parsed study: its tasks and the names of its solvers."""

    name: str
    tasks: tuple[BatchTask, ...]
    solvers: tuple[str, ...]


def batch_task(
    index: int,
    solver: Solver | str,
    scene: Scene,
    labels: Mapping[str, Any],
    out_dir: str | Path,
    save_history: bool = True,
) -> BatchTask:
    """A batch run; the solver keeps its own files (if any) in ``<out_dir>/runs/<solver>/``.
    Without the history, the solver records only what the summary reads (:func:`lean_solver`).

    ``out_dir`` is made absolute here, on the client: a worker elsewhere (a Dask worker in
    another folder) writes where the batch reads."""
    solver = as_solver(solver)
    if not save_history:
        solver = lean_solver(solver, scene)
    out = Path(out_dir).absolute()
    kept = solver.keeping_files(out / "runs" / solver.name)
    return BatchTask(index, kept, scene, dict(labels), str(out), save_history)


def lean_solver(solver: Solver, scene: Scene) -> Solver:
    """The solver of a run whose history is not kept: without energy terms, and for a column
    without contact states (the summary reads neither; an assembly's collapse metrics read
    the contacts' slipping)."""
    changes = {}
    if getattr(solver, "record_energy", False):
        changes["record_energy"] = False
    if getattr(solver, "record_contacts", False) and not scene.positioned:
        changes["record_contacts"] = False
    return replace(solver, **changes) if changes else solver  # type: ignore[type-var]


# ---------------------------------------------------------------------- the study file


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
    if isinstance(target, dict):
        for other in ALTERNATIVES.get(last, ()):
            target.pop(other, None)
    target[last] = copy.deepcopy(value)


def _check_alternatives(keys: Iterable[str], source: str | None) -> None:
    """Refuse a grid that sets a key and its alternative in the same table."""
    seen: dict[tuple[str, str], str] = {}
    for key in keys:
        table, _, leaf = key.rpartition(".")
        for other in ALTERNATIVES.get(leaf, ()):
            if (table, other) in seen:
                raise InputError(
                    f"grid.{key}",
                    f"sets what grid.{seen[(table, other)]} sets (the scene takes one of {leaf} and {other}): "
                    "keep one of the two",
                    source,
                )
        seen[(table, leaf)] = key


def grid_size(n_bases: int, grid: Mapping[str, list[Any]], n_solvers: int) -> int:
    """Runs a study expands into: base scenes x the product of the grid's list lengths x solvers."""
    count = n_bases * n_solvers
    for values in grid.values():
        count *= len(values)
    return count


def check_run_count(count: int, allow_large: bool = False, source: str | None = None) -> None:
    """Refuse a study of more than :data:`MAX_RUNS` runs (``allow_large``: of more than
    :data:`MAX_RUNS_ALLOWED`), from the grid's sizes, before anything is built.

    Raises
    ------
    InputError
        Field ``grid``, with the count and the limit.
    """
    if count > MAX_RUNS_ALLOWED:
        raise InputError(
            "grid",
            f"the study expands into {count:,} runs, more than the limit of {MAX_RUNS:,} and than the "
            f"{MAX_RUNS_ALLOWED:,} a batch can hold even with --allow-large: split it into several studies",
            source,
        )
    if count > MAX_RUNS and not allow_large:
        raise InputError(
            "grid",
            f"the study expands into {count:,} runs, more than the limit of {MAX_RUNS:,} (each run is a "
            f"validated scene, a row and a file); use a smaller grid, or pass --allow-large (allow_large=True) "
            f"to go up to {MAX_RUNS_ALLOWED:,}",
            source,
        )


def _scene_dict(path: Path) -> dict[str, Any]:
    from rockyade.scene import load_scene

    return load_scene(path).to_dict()


def load_study(
    path: str | Path,
    out_dir: str | Path,
    options: Mapping[str, Any] | None = None,
    fields: Mapping[str, str] | None = None,
    allow_large: bool = False,
) -> Study:
    """Read a study file and expand it into tasks (scenes are validated now).

    Record files the grid names (``"motion.file" = [...]``, or a file in a grid's motion
    table) are found from the study file's folder, as a scene's from the scene's.

    Parameters
    ----------
    options
        Solver options that replace the file's (e.g. ``{"timeout_s": 90}`` from the command
        line); each goes to the solvers that take it, and one none of them takes is refused.
    fields
        How ``options`` are named in errors (e.g. ``{"timeout_s": "--yade-timeout"}``).
    allow_large
        Expand up to :data:`MAX_RUNS_ALLOWED` runs rather than :data:`MAX_RUNS`.

    Raises
    ------
    InputError
        A bad study file (naming the key), a file above :data:`MAX_STUDY_BYTES`, a grid of
        more runs than the limit (from its sizes, before any scene is built), a bad scene.
    """
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("study", f"file not found: {path}")
    size = path.stat().st_size
    if size > MAX_STUDY_BYTES:
        raise InputError(
            "study",
            f"the file has {size:,} bytes, more than the {MAX_STUDY_BYTES:,} (1 MiB) a study file may have: "
            "a grid of that size expands into more runs than a batch takes; split the study",
            source,
        )
    from rockyade.io.fields import plain_data
    from rockyade.scene.loading import parse_text_file

    data = plain_data(parse_text_file(path, "study"), "study", source)
    r = TableReader(data, "", source)
    name = r.string("name", path.stem)
    names = r.raw("solvers", ["reference"])
    if not isinstance(names, list) or not names or any(s not in solver_names() for s in names):
        raise r.error("solvers", f"must be a list of {', '.join(solver_names())}, got {names!r}")
    save = r.boolean("save_histories", True)
    file_options = {opt: r.raw(key) for key, opt in SOLVER_OPTION_KEYS.items() if r.has(key)}
    file_fields = {opt: key for key, opt in SOLVER_OPTION_KEYS.items()}
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
    check_run_count(grid_size(len(file_list), grid_table, len(names)), allow_large, source)
    try:
        solvers = make_solvers(names, {**file_options, **(options or {})}, {**file_fields, **(fields or {})})
    except InputError as exc:  # a key of this file is named with the file
        raise InputError(exc.field, exc.message, source if exc.field in SOLVER_OPTION_KEYS else exc.source) from None
    bases = [(Path(f).stem, _scene_dict(path.parent / f)) for f in file_list]
    tasks = expand(bases, grid_table, solvers, out_dir, save, source, allow_large=allow_large)
    return Study(name, tuple(tasks), tuple(names))


def expand(
    bases: list[tuple[str, dict[str, Any]]],
    grid: dict[str, list[Any]],
    solvers: Iterable[Solver | str],
    out_dir: str | Path,
    save_history: bool = True,
    source: str | None = None,
    *,
    allow_large: bool = False,
) -> list[BatchTask]:
    """Tasks for every base scene x grid point x solver (a Solver, or a name), scenes validated.

    A grid key replaces its alternatives (:data:`ALTERNATIVES`) in the table it sets. With a
    ``source`` (the study file), record files named by the grid are found from its folder.

    Raises
    ------
    InputError
        More runs than the limits (:func:`check_run_count`, before anything is built), a
        key and its alternative both in the grid, a grid point that is not a valid scene
        (naming the base and the grid point).
    """
    solver_list = [as_solver(s) for s in solvers]
    check_run_count(grid_size(len(bases), grid, len(solver_list)), allow_large, source)
    keys = list(grid)
    _check_alternatives(keys, source)
    base_dir = Path(source).resolve().parent if source else None
    motion_only = bool(keys) and all(k == "motion" or k.startswith("motion.") for k in keys)
    tasks: list[BatchTask] = []
    for base_name, base in bases:
        base_scene = _valid_scene(base, source, base_dir) if motion_only else None
        for values in itertools.product(*(grid[k] for k in keys)):
            # a grid over the motion changes only the motion's table: the rest is shared, read-only
            d = {**base, "motion": copy.deepcopy(base["motion"])} if base_scene is not None else copy.deepcopy(base)
            for key, value in zip(keys, values, strict=True):
                _set_path(d, key, value, source)
            labels = {"base": base_name, **{k: _label(v) for k, v in zip(keys, values, strict=True)}}
            try:
                scene = _absolute_files(_grid_scene(d, base_scene, source, base_dir))
            except InputError as exc:
                point = ", ".join(f"{k} = {v}" for k, v in labels.items())
                raise InputError(exc.field, f"{exc.message} (grid point: {point})", exc.source) from None
            for solver in solver_list:
                tasks.append(batch_task(len(tasks), solver, scene, labels, out_dir, save_history))
    return tasks


def _valid_scene(d: dict[str, Any], source: str | None, base_dir: Path | None) -> Scene | None:
    """The scene of ``d``, or None if it is not valid as it is (a grid point may complete it)."""
    from rockyade.scene import scene_from_dict

    try:
        return scene_from_dict(d, source=source, base_dir=base_dir)
    except InputError:
        return None


def _grid_scene(d: dict[str, Any], base_scene: Scene | None, source: str | None, base_dir: Path | None) -> Scene:
    """The scene of a grid point ``d``: ``scene_from_dict(d)``. With ``base_scene`` (the valid
    base scene of a grid over the motion only) the same Scene, read at a third of the cost:
    only the motion is read, and checked with the rest (:meth:`rockyade.scene.Scene.with_changes`);
    a motion that does not read is read again with the whole scene, which says what is wrong."""
    from rockyade.io.fields import plain_data
    from rockyade.motion.spec import parse_motion
    from rockyade.scene import scene_from_dict

    if base_scene is not None:
        try:
            motion = parse_motion(plain_data(d["motion"], "motion", source), source, base_dir)
            return base_scene.with_changes(motion=motion)
        except InputError:
            pass
    return scene_from_dict(d, source=source, base_dir=base_dir)


def _absolute_files(scene: Scene) -> Scene:
    """The scene with its record file named by an absolute path (a worker elsewhere reads it)."""
    motion = scene.motion
    if not isinstance(motion, RecordMotion) or Path(motion.file).is_absolute():
        return scene
    return replace(scene, motion=replace(motion, file=str(Path(motion.file).resolve())))


def _label(value: Any) -> Any:
    return value if isinstance(value, (int, float, str, bool)) else json.dumps(value, sort_keys=True)


# ---------------------------------------------------------------------- one run


def run_name(scene_hash: str, solver: str) -> str:
    """File stem of a run."""
    return f"{scene_hash}_{solver}"


def run_task(task: BatchTask) -> dict[str, Any]:
    """Run one task: solve, metrics, write its files; return its summary row. Never raises:
    failures become rows."""
    with writing_for(task.out_dir, task.lock_token) if task.lock_token else contextlib.nullcontext():
        return _run_task(task)


def _run_task(task: BatchTask) -> dict[str, Any]:
    start = time.perf_counter()
    runs = Path(task.out_dir) / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    name = run_name(task.scene_hash, task.solver.name)
    result = solve(task)
    row = _status_row(task, result.meta)
    if result.ok:
        row.update(_metrics(task.scene, result))
    row["elapsed_s"] = time.perf_counter() - start
    try:
        if task.save_history and result.ok:
            result.write(runs / f"{name}.csv", marked_record({"summary": row}))  # the JSON, last, marks it complete
        else:
            write_run(runs, name, {**result.meta.to_dict(), "summary": row})
    except OSError as exc:  # a full disk: this run fails with the reason, the batch goes on
        row = _write_failure(task, row, exc)
    return row


def coverage_columns(coverage: Mapping[str, Any] | None) -> dict[str, Any]:
    """The summary's columns of how much of the base motion a run leaves out
    (``meta.motion_coverage``, :func:`rockyade.motion.coverage.record_coverage`): the time
    after the scene's end, s, and the fraction of the motion's PGA the run never sees (0 when
    the run covers the motion; no columns without a base motion)."""
    if not coverage or "pga_left_out_fraction" not in coverage:
        return {}
    return {
        "motion_time_left_out_s": coverage["time_left_out_s"],
        "motion_pga_left_out_fraction": coverage["pga_left_out_fraction"],
    }


def _status_row(task: BatchTask, meta: RunMeta) -> dict[str, Any]:
    """The summary row's leading and status columns of a run from its Result's metadata."""
    return {
        "index": task.index,
        "run": run_name(task.scene_hash, task.solver.name),
        "scene_hash": meta.scene_hash,
        "solver": task.solver.name,
        **task.labels,
        "status": meta.status,
        "failure_reason": meta.failure_reason or "",
        "overturn_time_s": meta.overturn_time_s,
        "overturned_block": meta.overturned_block or "",
        "wall_time_s": meta.wall_time_s,
        **coverage_columns(meta.motion_coverage),
    }


# ---------------------------------------------------------------------- runs in groups


def job_key(task: BatchTask) -> Any:
    """The group of a task (:func:`rockyade.runner.groups.group_jobs`): runs without history
    whose solver runs scenes of one structure together (``group_key``); None: it runs alone."""
    if task.save_history or not isinstance(task.solver, GroupSolver):
        return None
    k = task.solver.group_key(task.scene)
    return None if k is None else (task.out_dir, repr(task.solver), k)


def run_job(job: tuple[BatchTask, ...]) -> list[dict[str, Any]]:
    """Run a job of :func:`job_key`'s group (or one task); its summary rows. Never raises:
    should the group fail as a whole, its runs are run one by one."""
    if len(job) == 1:
        return [run_task(job[0])]
    first = job[0]
    with writing_for(first.out_dir, first.lock_token) if first.lock_token else contextlib.nullcontext():
        return _run_group(job)


def _run_group(job: tuple[BatchTask, ...]) -> list[dict[str, Any]]:
    from rockyade.analysis.metrics import block_overturned, block_summary, uplift_threshold_rad

    start = time.perf_counter()
    first = job[0]
    spec = first.scene.blocks[0]
    alpha = spec.classical().alpha_rad
    solver = first.solver
    assert isinstance(solver, GroupSolver)  # job_key groups only these
    try:
        runs = solver.run_group([t.scene for t in job], uplift_threshold_rad(alpha))
    except Exception:  # a run of its own says what went wrong
        return [_run_task(task) for task in job]
    elapsed = (time.perf_counter() - start) / len(job)
    folder = Path(first.out_dir) / "runs"
    folder.mkdir(parents=True, exist_ok=True)
    free = first.scene.motion.type == "free"
    rows = []
    for task, one in zip(job, runs, strict=True):
        row = _status_row(task, one.meta)
        if one.status != "failed":
            t = np.arange(one.theta_rad.size) * one.sample_dt_s
            overturned = block_overturned(one.meta, spec.name)
            row.update(block_summary(one.metrics, t, one.theta_rad, alpha, free, overturned))
        row["elapsed_s"] = elapsed
        try:
            write_run(folder, row["run"], {**one.meta.to_dict(), "summary": row})
        except OSError as exc:
            row = _write_failure(task, row, exc)
        rows.append(row)
    return rows


def _metrics(scene: Scene, result: Result) -> dict[str, Any]:
    """The summary's metrics of a run: per block (prefixed with its name in a stack), of the
    assembly, and the rocking pattern of a two-block stack."""
    from rockyade.analysis.metrics import PER_BLOCK_LIMIT, assembly_metrics, run_metrics

    row: dict[str, Any] = {}
    if scene.positioned:
        row.update(assembly_metrics(scene, result))
    if not scene.positioned or len(scene.blocks) <= PER_BLOCK_LIMIT:
        single = len(scene.blocks) == 1
        for block, values in run_metrics(scene, result).items():
            for key, value in values.items():
                row[key if single else f"{block}_{key}"] = value
    if len(scene.blocks) == 2:
        from rockyade.analysis.patterns import classify_result

        pattern = classify_result(scene, result)
        row["pattern"] = pattern.dominant
        row["pattern_fractions"] = json.dumps(pattern.fractions, sort_keys=True)
    return row


def _write_failure(task: BatchTask, row: dict[str, Any], exc: OSError) -> dict[str, Any]:
    """The row of a run whose result could not be written (no file of it is left half-written)."""
    keep = (
        *LEADING_COLUMNS,
        *task.labels,
        "wall_time_s",
        "elapsed_s",
        "motion_time_left_out_s",
        "motion_pga_left_out_fraction",
    )
    return {
        **{k: v for k, v in row.items() if k in keep},
        "status": "failed",
        "failure_reason": f"cannot write the result: {os_error_message(exc)}",
        "overturn_time_s": None,
        "overturned_block": "",
    }


def _completed_row(task: BatchTask) -> dict[str, Any] | None:
    """The summary row of a run already completed (or overturned) for the same scene
    (:func:`rockyade.runner.journal.read_run`)."""
    row = read_run(Path(task.out_dir) / "runs", run_name(task.scene_hash, task.solver.name), task.scene_hash)
    if row is None:
        return None
    row["index"] = task.index
    row.update(task.labels)
    return row


def _placeholder_row(task: BatchTask, status: str, reason: str) -> dict[str, Any]:
    """A summary row for a run that produced no result (unfinished, or its worker died)."""
    return {
        "index": task.index,
        "run": run_name(task.scene_hash, task.solver.name),
        "scene_hash": task.scene_hash,
        "solver": task.solver.name,
        **task.labels,
        "status": status,
        "failure_reason": reason,
        "overturn_time_s": None,
        "overturned_block": "",
        "wall_time_s": None,
    }


def _crashed_row(task: BatchTask, reason: str) -> dict[str, Any]:
    return _placeholder_row(task, "failed", reason)


def _failure_line(row: dict[str, Any]) -> str | None:
    return f"failed: {row['run']}: {row['failure_reason']}" if row["status"] == "failed" else None


# ---------------------------------------------------------------------- the batch


def run_study_tasks(
    tasks: list[BatchTask],
    out_dir: str | Path,
    *,
    executor: str | Executor = "local",
    workers: int = 2,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    desc: str = "runs",
    allow_large: bool = False,
    scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S,
    group_runs: bool = True,
    identity: Mapping[str, Any] | None = None,
    resume_option: str | None = "--resume",
) -> pd.DataFrame:
    """Run tasks and write the summary; return it (sorted by task order).

    Parameters
    ----------
    executor
        "local" (worker processes), "dask" (``scheduler`` address, or Dask's threaded
        scheduler in this process) or "threads" (this process), with ``workers``,
        ``scheduler`` and ``scheduler_timeout_s``; or a :class:`rockyade.runner.Executor`
        holding them all.
    resume
        Skip runs already completed for the same scene hash; re-run failed ones.
    allow_large
        Run even if a run's cost estimate is above the limits of :mod:`rockyade.runner.cost`.
    resume_option
        The caller's option that resumes, named after Ctrl-C (None: it cannot resume).
    identity
        What study this is (:func:`rockyade.runner.journal.claim`: ``study.json`` in ``out_dir``);
        ``resume`` over the runs of another is refused. None: not checked.
    group_runs
        Run the runs that share a structure together (:func:`job_key`, :func:`run_job`; the
        same rows); False: one run per job (benchmarks compare the two).

    Raises
    ------
    InputError
        Bad settings, a run above the cost limits, an output another batch is writing,
        ``resume`` over the runs of another study (``identity``).
    BatchInterruptedError
        After Ctrl-C, once the summary of what finished is written.
    """
    how = executor if isinstance(executor, Executor) else Executor(executor, workers, scheduler, scheduler_timeout_s)
    out = Path(out_dir)
    with output_folder(out), output_lock(out, "out"):  # an error before any run leaves no empty folder
        token = lock_token(out)
        _settle(out)
        if identity is not None:
            claim(out, identity, resume)
        return _run_locked(
            [replace(t, lock_token=token) for t in tasks],
            out,
            how,
            resume,
            progress,
            desc,
            allow_large,
            group_runs,
            resume_option,
        )


def _settle(out: Path) -> None:
    """What a killed batch left: finish or drop half-replaced results, remove temporary files."""
    from rockyade.result import settle_results

    remove_stale_temporaries(out)
    if (out / "runs").is_dir():
        settle_results(out / "runs")


def _run_locked(
    tasks: list[BatchTask],
    out: Path,
    how: Executor,
    resume: bool,
    progress: bool,
    desc: str,
    allow_large: bool,
    group_runs: bool = True,
    resume_option: str | None = "--resume",
) -> pd.DataFrame:
    first, duplicates = _distinct(tasks)
    rows: list[dict[str, Any]] = []
    todo = []
    for task in first:
        done = _completed_row(task) if resume else None
        if done is not None:
            rows.append(done)
        else:
            todo.append(task)
    check_costs(todo, allow_large)
    key = job_key if group_runs else (lambda _task: None)
    n_grouped = sum(key(t) is not None for t in todo)
    jobs = group_jobs(todo, key, min(MAX_RUNS_PER_JOB, max(1, -(-n_grouped // (4 * how.workers)))))
    outcome = run_jobs(
        jobs,
        run_job,
        executor=how,
        failed=lambda job, reason: [_crashed_row(task, reason) for task in job],
        on_done=lambda _i, job_rows: rows.extend(job_rows),
        describe_failure=lambda job_rows: "\n".join(filter(None, map(_failure_line, job_rows))) or None,
        progress=progress,
        desc=desc,
        skipped=len(rows),
    )
    for i in outcome.unfinished:
        reason = "stopped by Ctrl-C" if i in outcome.started else "not started: Ctrl-C"
        rows.extend(_placeholder_row(task, UNFINISHED, reason) for task in jobs[i])
    by_index = {row["index"]: row for row in rows}
    for task, original in duplicates:
        rows.append(_duplicate_row(task, by_index[original.index]))
    for row in rows:
        row.setdefault("duplicate_of", -1)
    summary = _ordered(pd.DataFrame(rows).sort_values("index").reset_index(drop=True), tasks)
    write_summary(summary, out)
    if outcome.stopped:
        if outcome.hard:
            _settle(out)
        stopped = {task.index for i in outcome.unfinished for task in jobs[i]}
        unfinished = len(stopped) + sum(1 for _task, original in duplicates if original.index in stopped)
        raise BatchInterruptedError(
            len(tasks) - unfinished, unfinished, str(out / "summary.csv"), outcome.hard, resume_option
        )
    return summary


#: Most runs of one group in one job (groups are cut so that every worker gets jobs).
MAX_RUNS_PER_JOB = 64


def _distinct(tasks: list[BatchTask]) -> tuple[list[BatchTask], list[tuple[BatchTask, BatchTask]]]:
    """The tasks run (the first of each run name: the same scene hash and solver) and the
    duplicates, each with the task it repeats (run once: two tasks would write one file)."""
    first: dict[str, BatchTask] = {}
    duplicates = []
    for task in tasks:
        name = run_name(task.scene_hash, task.solver.name)
        if name in first:
            duplicates.append((task, first[name]))
        else:
            first[name] = task
    return list(first.values()), duplicates


def _duplicate_row(task: BatchTask, original: dict[str, Any]) -> dict[str, Any]:
    """The row of a grid point that repeats an earlier one: its result, its own grid values,
    and ``duplicate_of`` the index of the row it repeats."""
    return {**original, "index": task.index, **task.labels, "duplicate_of": original["index"]}


LEADING_COLUMNS = ("index", "run", "scene_hash", "solver")
STATUS_COLUMNS = (
    "status",
    "duplicate_of",
    "failure_reason",
    "overturn_time_s",
    "overturned_block",
    "wall_time_s",
    "elapsed_s",
    "motion_time_left_out_s",
    "motion_pga_left_out_fraction",
)


def _ordered(summary: pd.DataFrame, tasks: list[BatchTask]) -> pd.DataFrame:
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
    "BatchTask",
    "Study",
    "batch_task",
    "comparable",
    "expand",
    "failures",
    "job_key",
    "load_study",
    "run_job",
    "run_study_tasks",
    "run_task",
    "write_summary",
]
