"""Running a batch: a study's tasks, what one run does (solve, metrics, write its files),
and handing them to the runner (:mod:`rockyade.runner`).

Each run is named ``<scene hash>_<solver>``; ``runs/<name>.json`` (metadata and the summary
row) is written for every run, ``runs/<name>.csv`` with the time history when asked; a solver
that keeps files of its own keeps them in ``runs/<solver>/`` (YADE: its scene data and log).
A run's JSON is its record in the journal of finished runs that every study command shares
(:mod:`rockyade.runner.journal`): written atomically and fsynced, file and folder, as the run
ends (a killed batch, or a power cut, leaves whole records or none).

A failed run never stops the batch: its row says why (a full disk too: the run fails with
that reason and the batch goes on). ``resume`` skips runs whose JSON says they completed
(or overturned) for the same scene hash and re-runs failed ones.

The runs go through :mod:`rockyade.runner`: costs checked before any run (``allow_large``
lifts the limits), local processes or Dask, Ctrl-C, worker lifetime. One batch at a time
may write an output directory (a lock); what a killed batch left (temporary files, a result
between its two renames) is settled when the next one starts. After Ctrl-C ``summary.csv``
is written with what finished, the unfinished runs listed with status ``unfinished``, and
:class:`~rockyade.errors.BatchInterruptedError` is raised.

The output folder and the batch's lock on it go to the runs once, beside the tasks
(:class:`Output`), not in every task.
"""

from __future__ import annotations

import contextlib
import functools
import time
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.batch.study import Study, make_study
from rockyade.batch.summary import (
    UNFINISHED,
    completed_row,
    duplicate_row,
    failure_line,
    placeholder_row,
    status_row,
    summary_frame,
    task_run_name,
    write_failure_row,
    write_summary,
)
from rockyade.errors import BatchInterruptedError
from rockyade.io.atomic import remove_stale_temporaries
from rockyade.io.folders import output_folder
from rockyade.io.locking import lock_token, output_lock, writing_for
from rockyade.runner import Executor, Task, check_costs, run_jobs, solve
from rockyade.runner.executor import SCHEDULER_TIMEOUT_S
from rockyade.runner.groups import group_jobs
from rockyade.runner.journal import claim, marked_record, write_run
from rockyade.scene import Scene
from rockyade.solvers import as_solver
from rockyade.solvers.base import GroupSolver, Solver

#: Most runs of one group in one job (groups are cut so that every worker gets jobs).
MAX_RUNS_PER_JOB = 64


@dataclass(frozen=True)
class BatchTask(Task):
    """One run of a batch: a task (:class:`rockyade.runner.Task`) and whether its time
    history is kept.

    Attributes
    ----------
    save_history
        Write the time history as well as the metadata.
    """

    save_history: bool = True


@dataclass(frozen=True)
class Output:
    """Where a batch's runs write, given to every run once.

    Attributes
    ----------
    out_dir
        The batch's folder (absolute: a worker elsewhere, a Dask worker in another folder,
        writes where the batch reads); the runs go in ``runs/``.
    lock_token
        The token of the batch's lock on ``out_dir`` ("" when the caller holds none): the run
        writes there on the batch's behalf (:func:`rockyade.io.locking.writing_for`),
        wherever it runs.
    """

    out_dir: str
    lock_token: str = ""

    @property
    def runs(self) -> Path:
        """The runs' folder."""
        return Path(self.out_dir) / "runs"

    def writing(self) -> contextlib.AbstractContextManager[Any]:
        """Write under the batch's lock (nothing to do without a token)."""
        return writing_for(self.out_dir, self.lock_token) if self.lock_token else contextlib.nullcontext()


def output(out_dir: str | Path, lock_token: str = "") -> Output:
    """The :class:`Output` of ``out_dir``, made absolute here, on the client."""
    return Output(str(Path(out_dir).absolute()), lock_token)


def batch_task(
    index: int, solver: Solver | str, scene: Scene, labels: Mapping[str, Any], save_history: bool = True
) -> BatchTask:
    """A batch run. Without the history, the solver records only what the summary reads
    (:func:`lean_solver`)."""
    solver = as_solver(solver)
    if not save_history:
        solver = lean_solver(solver, scene)
    return BatchTask(index, solver, scene, dict(labels), save_history)


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


def study_tasks(study: Study) -> Iterator[BatchTask]:
    """The tasks of a study, made as they are asked for: every grid point x solver."""
    index = 0
    for point in study.points():
        for solver in study.solvers:
            yield batch_task(index, solver, point.scene, point.labels, study.save_histories)
            index += 1


def expand(
    bases: list[tuple[str, dict[str, Any]]],
    grid: Mapping[str, list[Any]],
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


def run_task(task: BatchTask, out: Output) -> dict[str, Any]:
    """Run one task: solve, metrics, write its files in ``out``; its summary row. Never
    raises: failures become rows."""
    with out.writing():
        return _run_task(task, out)


def keeping_files(task: BatchTask, out: Output) -> BatchTask:
    """The task with its solver keeping its own files (if any) in ``runs/<solver>/`` of ``out``."""
    solver = task.solver.keeping_files(out.runs / task.solver.name)
    return task if solver is task.solver else replace(task, solver=solver)


def _run_task(task: BatchTask, out: Output) -> dict[str, Any]:
    from rockyade.analysis.metrics import summary_metrics

    start = time.perf_counter()
    runs = out.runs
    runs.mkdir(parents=True, exist_ok=True)
    name = task_run_name(task)
    result = solve(keeping_files(task, out))
    row = status_row(task, result.meta)
    if result.ok:
        row.update(summary_metrics(task.scene, result))
    row["elapsed_s"] = time.perf_counter() - start
    try:
        if task.save_history and result.ok:
            result.write(runs / f"{name}.csv", marked_record({"summary": row}))  # the JSON, last, marks it complete
        else:
            write_run(runs, name, {**result.meta.to_dict(), "summary": row})
    except OSError as exc:  # a full disk: this run fails with the reason, the batch goes on
        row = write_failure_row(task, row, exc)
    return row


# ---------------------------------------------------------------------- runs in groups


def job_key(task: BatchTask) -> Any:
    """The group of a task (:func:`rockyade.runner.groups.group_jobs`): runs without history
    whose solver runs scenes of one structure together (``group_key``); None: it runs alone."""
    if task.save_history or not isinstance(task.solver, GroupSolver):
        return None
    k = task.solver.group_key(task.scene)
    return None if k is None else (repr(task.solver), k)


def run_job(job: tuple[BatchTask, ...], out: Output) -> list[dict[str, Any]]:
    """Run a job of :func:`job_key`'s group (or one task); its summary rows. Never raises:
    should the group fail as a whole, its runs are run one by one."""
    if len(job) == 1:
        return [run_task(job[0], out)]
    with out.writing():
        return _run_group(job, out)


def _run_group(job: tuple[BatchTask, ...], out: Output) -> list[dict[str, Any]]:
    from rockyade.analysis.metrics import block_overturned, block_summary, uplift_threshold_rad
    from rockyade.constants import G
    from rockyade.scene.carried import loaded_classical

    start = time.perf_counter()
    first = job[0]
    spec = first.scene.blocks[0]
    cp = loaded_classical(first.scene, G)[spec.name]  # the body that rocks: each side its own alpha
    alpha = cp.alpha_rad
    solver = first.solver
    assert isinstance(solver, GroupSolver)  # job_key groups only these
    try:
        runs = solver.run_group([t.scene for t in job], uplift_threshold_rad(alpha))
    except Exception:  # a run of its own says what went wrong
        return [_run_task(task, out) for task in job]
    elapsed = (time.perf_counter() - start) / len(job)
    folder = out.runs
    folder.mkdir(parents=True, exist_ok=True)
    free = first.scene.motion.type == "free"
    rows = []
    for task, one in zip(job, runs, strict=True):
        row = status_row(task, one.meta)
        if one.status != "failed":
            t = np.arange(one.theta_rad.size) * one.sample_dt_s
            overturned = block_overturned(one.meta, spec.name)
            row.update(block_summary(one.metrics, t, one.theta_rad, alpha, free, overturned, classical=cp))
        row["elapsed_s"] = elapsed
        try:
            write_run(folder, row["run"], {**one.meta.to_dict(), "summary": row})
        except OSError as exc:
            row = write_failure_row(task, row, exc)
        rows.append(row)
    return rows


# ---------------------------------------------------------------------- the batch


def run_study_tasks(
    tasks: Iterable[BatchTask],
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
    """Run tasks and write the summary in ``out_dir``; return it (sorted by task order).

    Parameters
    ----------
    tasks
        The runs (:func:`study_tasks`, :func:`expand`, :func:`batch_task`).
    out_dir
        The batch's folder (made if missing; locked while the batch runs).
    executor
        "local" (worker processes), "dask" (``scheduler`` address, or Dask's threaded
        scheduler in this process) or "threads" (this process), with ``workers``,
        ``scheduler`` and ``scheduler_timeout_s``; or a :class:`rockyade.runner.Executor`
        holding them all.
    resume
        Skip runs already completed for the same scene hash; re-run failed ones.
    allow_large
        Run even if a run's cost estimate is above the limits of :mod:`rockyade.runner.cost_limits`.
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
    task_list = list(tasks)  # scenes built (a bad grid point refused) before the folder is touched
    folder = Path(out_dir)
    with output_folder(folder), output_lock(folder, "out"):  # an error before any run leaves no empty folder
        out = output(folder, lock_token(folder))
        _settle(out.runs)
        if identity is not None:
            claim(folder, identity, resume)
        return _run_locked(task_list, out, how, resume, progress, desc, allow_large, group_runs, resume_option)


def _settle(runs: Path) -> None:
    """What a killed batch left: finish or drop half-replaced results, remove temporary files."""
    from rockyade.result import settle_results

    remove_stale_temporaries(runs.parent)
    if runs.is_dir():
        settle_results(runs)


def _run_locked(
    tasks: list[BatchTask],
    out: Output,
    how: Executor,
    resume: bool,
    progress: bool,
    desc: str,
    allow_large: bool,
    group_runs: bool,
    resume_option: str | None,
) -> pd.DataFrame:
    first, duplicates = _distinct(tasks)
    rows: list[dict[str, Any]] = []
    todo = []
    for task in first:
        done = completed_row(task, out.runs) if resume else None
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
        functools.partial(run_job, out=out),
        executor=how,
        failed=lambda job, reason: [placeholder_row(task, "failed", reason) for task in job],
        on_done=lambda _i, job_rows: rows.extend(job_rows),
        describe_failure=lambda job_rows: "\n".join(filter(None, map(failure_line, job_rows))) or None,
        progress=progress,
        desc=desc,
        skipped=len(rows),
    )
    for i in outcome.unfinished:
        reason = "stopped by Ctrl-C" if i in outcome.started else "not started: Ctrl-C"
        rows.extend(placeholder_row(task, UNFINISHED, reason) for task in jobs[i])
    by_index = {row["index"]: row for row in rows}
    for task, original in duplicates:
        rows.append(duplicate_row(task, by_index[original.index]))
    summary = summary_frame(rows, list(tasks[0].labels) if tasks else [])
    folder = Path(out.out_dir)
    write_summary(summary, folder)
    if outcome.stopped:
        if outcome.hard:
            _settle(out.runs)
        stopped = {task.index for i in outcome.unfinished for task in jobs[i]}
        unfinished = len(stopped) + sum(1 for _task, original in duplicates if original.index in stopped)
        raise BatchInterruptedError(
            len(tasks) - unfinished, unfinished, str(folder / "summary.csv"), outcome.hard, resume_option
        )
    return summary


def _distinct(tasks: list[BatchTask]) -> tuple[list[BatchTask], list[tuple[BatchTask, BatchTask]]]:
    """The tasks run (the first of each run name: the same scene hash and solver) and the
    duplicates, each with the task it repeats (run once: two tasks would write one file)."""
    first: dict[str, BatchTask] = {}
    duplicates = []
    for task in tasks:
        name = task_run_name(task)
        if name in first:
            duplicates.append((task, first[name]))
        else:
            first[name] = task
    return list(first.values()), duplicates


__all__ = [
    "MAX_RUNS_PER_JOB",
    "BatchTask",
    "Output",
    "batch_task",
    "expand",
    "job_key",
    "keeping_files",
    "lean_solver",
    "output",
    "run_job",
    "run_study_tasks",
    "run_task",
    "study_tasks",
]
