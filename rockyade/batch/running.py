"""One run of a study, and one job of runs: what a worker does with a task (solve, the collapse
verdict and the metrics the study asks for, the files it keeps) and the row it gives back
(:class:`rockyade.runner.rows.RunRow`).

Every study runs its tasks through here (:func:`rockyade.batch.study_runs.run_study`):
``batch``, ``uncertainty`` and the pattern map ask for the summary metrics (and keep the time
history when the study file says so); ``fragility``, ``assess`` and ``crosscheck`` ask for the
collapse verdict only.

A run of a study with a folder (:class:`Output`) writes its record there as it ends, where it
runs (:mod:`rockyade.runner.journal`: ``runs/<name>.json``, its metadata, row and verdict,
atomically, fsynced and sealed): ``resume`` reads it back. A run whose time history is kept
writes it as ``<name>.csv`` beside it (the JSON, last, marks the pair complete); a solver that
keeps files of its own keeps them in ``runs/<solver>/`` (YADE: its scene data and log). The
folder and the study's lock on it go to the runs once, beside the tasks (:class:`Output`).

Runs that share a structure (no history kept, a solver that runs scenes of one structure
together: :class:`rockyade.solvers.base.GroupSolver`) go to one job (:func:`job_key`), which
the solver answers at once, with the rows of the runs one at a time.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Hashable, Iterable, Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rockyade.batch.study import Study, make_study
from rockyade.constants import G
from rockyade.errors import os_error_message
from rockyade.io.locking import writing_for
from rockyade.result import Result
from rockyade.runner import Task, solve
from rockyade.runner.journal import marked_record, write_run
from rockyade.runner.rows import Cell, RunRow, Verdict
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical
from rockyade.solvers import as_solver
from rockyade.solvers.base import GroupRun, GroupSolver, Solver

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class BatchTask(Task):
    """One run of a study: a task (:class:`rockyade.runner.Task`) and what the study keeps of it.

    Attributes
    ----------
    save_history
        Write the time history as well as the metadata.
    metrics
        The summary metrics (:func:`rockyade.analysis.metrics.summary_metrics`) in its row.
    fallen_blocks
        The collapse verdict in its row, a collapse being this many fallen blocks
        (:func:`rockyade.analysis.collapse_verdict.collapse_verdict`); None: no verdict.
    keep_result
        Its Result comes back in its row (:attr:`rockyade.runner.rows.RunRow.result`): a study
        that reads the whole run.
    """

    save_history: bool = True
    metrics: bool = True
    fallen_blocks: int | None = None
    keep_result: bool = False


@dataclass(frozen=True)
class Output:
    """Where a study's runs keep their files, given to every run once.

    Attributes
    ----------
    out_dir
        The study's folder (absolute: a worker elsewhere, a Dask worker in another folder,
        writes where the study reads).
    lock_token
        The token of the study's lock on ``out_dir`` ("" when the caller holds none): the run
        writes there on the study's behalf (:func:`rockyade.io.locking.writing_for`),
        wherever it runs.
    runs_dir
        The runs' folder in ``out_dir`` (their records, histories and files).
    solver_files
        The solvers keep their own files there (YADE's scene data and log).
    record_meta
        A run's record holds its metadata (the Result's) beside its row; False: its row and
        verdict only (a journal that goes once the study is complete).
    """

    out_dir: str
    lock_token: str = ""
    runs_dir: str = "runs"
    solver_files: bool = True
    record_meta: bool = True

    @property
    def runs(self) -> Path:
        """The runs' folder."""
        return Path(self.out_dir) / self.runs_dir

    def writing(self) -> contextlib.AbstractContextManager[object]:
        """Write under the study's lock (nothing to do without a token)."""
        return writing_for(self.out_dir, self.lock_token) if self.lock_token else contextlib.nullcontext()


def output(out_dir: str | Path, lock_token: str = "", runs_dir: str = "runs", lean: bool = False) -> Output:
    """The :class:`Output` of ``out_dir``, made absolute here, on the client (``lean``: no
    solver's own files, records without the metadata)."""
    return Output(str(Path(out_dir).absolute()), lock_token, runs_dir, not lean, not lean)


def batch_task(
    index: int,
    solver: Solver | str,
    scene: Scene,
    labels: Mapping[str, Cell],
    save_history: bool = True,
    *,
    metrics: bool = True,
    fallen_blocks: int | None = None,
) -> BatchTask:
    """A study's run. Without the history, the solver records only what the row reads
    (:func:`lean_solver`)."""
    solver = as_solver(solver)
    if not save_history:
        solver = lean_solver(solver, scene)
    return BatchTask(index, solver, scene, dict(labels), save_history, metrics, fallen_blocks)


def lean_solver(solver: Solver, scene: Scene) -> Solver:
    """The solver of a run whose history is not kept: without energy terms, and for a column
    without contact states (the row reads neither; an assembly's collapse reads the contacts'
    slipping)."""
    changes = {}
    if getattr(solver, "record_energy", False):
        changes["record_energy"] = False
    if getattr(solver, "record_contacts", False) and not scene.positioned:
        changes["record_contacts"] = False
    return replace(solver, **changes) if changes else solver  # type: ignore[type-var]


def study_tasks(study: Study) -> Iterator[BatchTask]:
    """The tasks of a study file, made as they are asked for: every grid point x solver."""
    index = 0
    for point in study.points():
        for solver in study.solvers:
            yield batch_task(index, solver, point.scene, point.labels, study.save_histories)
            index += 1


def expand(
    bases: list[tuple[str, dict[str, object]]],
    grid: Mapping[str, list[object]],
    solvers: Iterable[Solver | str],
    *,
    save_history: bool = True,
    source: str | None = None,
    allow_large: bool = False,
) -> list[BatchTask]:
    """Tasks for every base scene x grid point x solver (a Solver, or a name), scenes
    validated: :func:`study_tasks` of :func:`rockyade.batch.study.make_study`.

    Raises
    ------
    InputError
        More runs than the limits (before anything is built), a key and its alternative both
        in the grid, a grid point that is not a valid scene (naming the base and the point).
    """
    study = make_study(bases, grid, solvers, save_histories=save_history, source=source, allow_large=allow_large)
    return list(study_tasks(study))


# ---------------------------------------------------------------------- one run


def keeping_files(task: BatchTask, out: Output) -> BatchTask:
    """The task with its solver keeping its own files (if any) in ``runs/<solver>/`` of ``out``."""
    solver = task.solver.keeping_files(out.runs / task.solver.name)
    return task if solver is task.solver else replace(task, solver=solver)


def run_task(task: BatchTask, out: Output | None = None) -> RunRow:
    """Run one task: solve, its verdict and metrics, its files in ``out``; its row. Never
    raises: a failure is a row with status ``failed`` and the reason."""
    with out.writing() if out is not None else contextlib.nullcontext():
        return _run_task(task, out)


def _run_task(task: BatchTask, out: Output | None) -> RunRow:
    start = time.perf_counter()
    if out is not None:
        out.runs.mkdir(parents=True, exist_ok=True)
        if out.solver_files:
            task = keeping_files(task, out)
    result = solve(task)
    row = answered_row(task, result, RunRow.of(task, result.meta))
    row = replace(row, elapsed_s=time.perf_counter() - start, result=result if task.keep_result else None)
    return row if out is None else recorded(row, out, result if task.save_history else None)


def recorded(row: RunRow, out: Output, result: Result | None = None) -> RunRow:
    """``row`` with its record written in ``out``'s runs (with ``result``, when it answered:
    the time history beside it, the record last); a full disk fails the run, saying why (no
    file of it left half-written), and the study goes on."""
    try:
        if result is not None and row.answered:
            result.write(out.runs / f"{row.name}.csv", marked_record(record_of(row)))
        else:
            write_run(out.runs, row.name, record_of(row, out.record_meta))
    except OSError as exc:
        return replace(row.failed(f"cannot write the result: {os_error_message(exc)}"), recorded=True)
    return replace(row, recorded=True)


def answered_row(task: BatchTask, result: Result | GroupRun, row: RunRow) -> RunRow:
    """``row`` with the verdict and the metrics the task asks for, when the run answered (an
    analysis that fails is this run's failure, not the study's)."""
    if not row.answered or not (task.metrics or task.fallen_blocks is not None):
        return row
    from rockyade.analysis.collapse_verdict import collapse_verdict

    scene = task.scene
    try:
        report = _report(task, result)
        verdict = collapse_verdict(scene, result, task.fallen_blocks or 1, report)
        metrics: dict[str, Cell] = {}
        if task.metrics:
            metrics = _metrics(task, result, report, verdict)
    except Exception as exc:
        return row.failed(f"analysis of the run: {type(exc).__name__}: {exc}")
    return replace(row, verdict=verdict if task.fallen_blocks is not None else None, metrics=metrics)


def _report(task: BatchTask, result: Result | GroupRun) -> pd.DataFrame | None:
    """The collapse table of a run of several blocks (shared by its verdict and metrics)."""
    if len(task.scene.blocks) == 1 or isinstance(result, GroupRun):
        return None
    from rockyade.analysis.collapse import collapse_report

    return collapse_report(task.scene, result)


def _metrics(
    task: BatchTask, result: Result | GroupRun, report: pd.DataFrame | None, verdict: Verdict
) -> dict[str, Cell]:
    from rockyade.analysis.metrics import block_summary, summary_metrics

    if not isinstance(result, GroupRun):
        return summary_metrics(task.scene, result, report, verdict)
    spec = task.scene.blocks[0]
    cp = loaded_classical(task.scene, G)[spec.name]  # the body that rocks: each side its own alpha
    t = np.arange(result.theta_rad.size) * result.sample_dt_s
    free = task.scene.motion.type == "free"
    fell = spec.name in verdict.fallen
    return dict(block_summary(result.metrics, t, result.theta_rad, cp.alpha_rad, free, fell, classical=cp))


def record_of(row: RunRow, meta: bool = True) -> dict[str, object]:
    """A run's record in its study's journal (:mod:`rockyade.runner.journal`): its metadata
    (``meta``), status, scene hash, row and verdict."""
    record: dict[str, object] = dict(row.meta.to_dict()) if meta and row.meta is not None else {}
    record.update(status=row.status, scene_hash=row.scene_hash, summary=row.summary())
    if row.verdict is not None:
        record["verdict"] = row.verdict.to_dict()
    return record


# ---------------------------------------------------------------------- runs in groups


def job_key(task: BatchTask) -> Hashable | None:
    """The group of a task (:func:`rockyade.runner.groups.group_jobs`): runs without history
    whose solver runs scenes of one structure together (its ``group_key``: the same block,
    another record or load factor); None: it runs alone."""
    solver = task.solver
    if task.save_history or task.keep_result or not isinstance(solver, GroupSolver):
        return None
    key = solver.group_key(task.scene)
    return None if key is None else (repr(solver), key)


def run_job(job: tuple[BatchTask, ...], out: Output | None = None) -> list[RunRow]:
    """The rows of a job of :func:`job_key`'s group (or of one task). Never raises: should
    the group fail as a whole, its runs are run one by one.

    A group's runs are the solver's own runs stepped together (the same results, bit for bit,
    as one at a time: :meth:`rockyade.solvers.reference.ReferenceSolver.run_group`)."""
    if len(job) == 1:
        return [run_task(job[0], out)]
    with out.writing() if out is not None else contextlib.nullcontext():
        return _run_group(job, out)


def _run_group(job: tuple[BatchTask, ...], out: Output | None) -> list[RunRow]:
    from rockyade.analysis.metrics import uplift_threshold_rad

    start = time.perf_counter()
    solver = job[0].solver
    assert isinstance(solver, GroupSolver)  # job_key groups only these
    alpha = loaded_classical(job[0].scene, G)[job[0].scene.blocks[0].name].alpha_rad
    try:
        runs = solver.run_group([t.scene for t in job], uplift_threshold_rad(alpha))
    except Exception:  # a run of its own says what went wrong
        return [_run_task(task, out) for task in job]
    elapsed = (time.perf_counter() - start) / len(job)
    rows = [answered_row(task, one, RunRow.of(task, one.meta, elapsed)) for task, one in zip(job, runs, strict=True)]
    if out is None:
        return rows
    out.runs.mkdir(parents=True, exist_ok=True)
    return [recorded(row, out) for row in rows]


__all__ = [
    "BatchTask",
    "Output",
    "answered_row",
    "batch_task",
    "expand",
    "job_key",
    "keeping_files",
    "lean_solver",
    "output",
    "record_of",
    "recorded",
    "run_job",
    "run_task",
    "study_tasks",
]
