"""A batch's summary: one row per run (:meth:`rockyade.runner.rows.RunRow.summary`), and
``summary.csv`` (with ``summary.parquet`` when pyarrow is installed) written as one set; the
batch itself (:func:`run_study_tasks`: its folder, its runs, its summary).

A row holds the run's name, the grid values (the task's labels), its status, failure
reason, wall time and metrics (:func:`rockyade.analysis.metrics.summary_metrics`). A run's
row is also in its record (``runs/<name>.json``, :mod:`rockyade.runner.journal`), which is
what ``resume`` reads back. The summary is sorted by run order, its columns in one order,
so that the same inputs give the same summary on any executor (wall times aside).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import pandas as pd

from rockyade.batch.running import BatchTask, output
from rockyade.batch.study_runs import StudyInterruptedError, StudyRuns, run_study
from rockyade.errors import BatchInterruptedError
from rockyade.io.resultset import replacing_set
from rockyade.runner import Executor, Task
from rockyade.runner.executor import SCHEDULER_TIMEOUT_S
from rockyade.runner.journal import read_run
from rockyade.runner.rows import LEADING_COLUMNS, STATUS_COLUMNS, UNFINISHED, Cell, Cells, RunRow
from rockyade.runner.study_folder import BATCH, StudyFolder, StudySet
from rockyade.runner.tasks import run_name

#: Columns that differ between equal runs (wall-clock times).
TIMING_COLUMNS = ("wall_time_s", "elapsed_s")
#: The summary's files: written together (:func:`rockyade.io.resultset.replacing_set`), the CSV last.
SUMMARY_FILES = BATCH.names


def task_run_name(task: Task) -> str:
    """File stem of a task's run (:func:`rockyade.runner.tasks.run_name`)."""
    return task.name


def completed_row(task: Task, runs: Path) -> Cells | None:
    """The row of a run already completed (or overturned) for the same scene, from its
    sealed record in ``runs`` (:func:`rockyade.runner.journal.read_run`), with this task's index
    and labels; None: it is to be run."""
    row = read_run(runs, task.name, task.scene_hash)
    if row is None:
        return None
    row["index"] = task.index
    row.update(task.labels)
    return row


def summary_frame(rows: Sequence[RunRow | Mapping[str, Cell]], labels: Iterable[str]) -> pd.DataFrame:
    """The summary of ``rows``: sorted by run order, columns in one canonical order (fresh,
    resumed or Dask rows alike): leading, the grid's ``labels``, status, then the rest sorted."""
    cells = [dict(row.summary() if isinstance(row, RunRow) else row) for row in rows]
    for row in cells:
        row.setdefault("duplicate_of", -1)
    summary = pd.DataFrame(cells).sort_values("index").reset_index(drop=True)
    first = [c for c in (*LEADING_COLUMNS, *labels, *STATUS_COLUMNS) if c in summary.columns]
    rest = sorted(c for c in summary.columns if c not in first)
    return summary[first + rest]


def write_summary(summary: pd.DataFrame, out: Path) -> None:
    """``summary.csv`` (and ``summary.parquet`` when pyarrow is installed) in ``out``, replaced
    as one set, fsynced (:func:`rockyade.io.resultset.replacing_set`: the previous pair or the
    new one, never one of each). The caller holds ``out``'s lock."""
    with replacing_set(out, SUMMARY_FILES, last="summary.csv") as stage:
        with open(stage / "summary.csv", "w", newline="") as fh:
            summary.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
        if _has_pyarrow():
            summary.to_parquet(stage / "summary.parquet", index=False)


def _has_pyarrow() -> bool:
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def failures(summary: pd.DataFrame) -> pd.DataFrame:
    """Rows of failed runs with their reasons."""
    return summary.loc[summary["status"] == "failed", ["run", "solver", "failure_reason"]]


def comparable(summary: pd.DataFrame) -> pd.DataFrame:
    """The summary without timing columns (equal for equal inputs on any executor)."""
    return summary.drop(columns=[c for c in TIMING_COLUMNS if c in summary.columns])


def summarised_runs(
    folder: StudyFolder,
    tasks: Sequence[BatchTask],
    executor: Executor,
    *,
    resume: bool,
    progress: bool = True,
    desc: str = "runs",
    allow_large: bool = False,
    group_runs: bool = True,
) -> tuple[pd.DataFrame, StudyRuns]:
    """A batch-shaped study's runs (:func:`rockyade.batch.study_runs.run_study`, its journal the
    folder's ``runs/``) and their summary, written as ``summary.csv`` in ``folder``.

    Raises
    ------
    BatchInterruptedError
        After Ctrl-C, once the summary of what finished is written (the others ``unfinished``).
    """
    labels = list(tasks[0].labels) if tasks else []
    try:
        runs = run_study(
            tasks,
            executor=executor,
            journal=folder.journal,
            reuse=resume,
            files=output(folder.out, folder.writing_token()),
            allow_large=allow_large,
            progress=progress,
            desc=desc,
            group_runs=group_runs,
        )
    except StudyInterruptedError as exc:
        write_summary(summary_frame(exc.runs.rows, labels), folder.out)
        if exc.runs.hard:
            from rockyade.result import settle_results

            settle_results(folder.journal_dir)  # what the stopped runs left half-written
        raise BatchInterruptedError(
            exc.runs.finished,
            exc.runs.unfinished,
            str(folder.out / "summary.csv"),
            exc.runs.hard,
            folder.resume_field,
        ) from None
    summary = summary_frame(runs.rows, labels)
    write_summary(summary, folder.out)
    return summary, runs


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
    identity: Mapping[str, object] | None = None,
    resume_option: str | None = "--resume",
    kind: StudySet = BATCH,
) -> pd.DataFrame:
    """Run a batch's tasks and write the summary in ``out_dir``; return it (sorted by task order).

    Parameters
    ----------
    tasks
        The runs (:func:`rockyade.batch.running.study_tasks`, :func:`rockyade.batch.running.expand`).
    out_dir
        The batch's folder (made if missing; locked while the batch runs;
        :class:`rockyade.runner.study_folder.StudyFolder`).
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
        What study this is (``study.json`` in ``out_dir``); ``resume`` over the runs of another
        is refused. None: not checked.
    group_runs
        Run the runs that share a structure together (the same rows); False: one run per job
        (benchmarks compare the two).
    kind
        The command whose folder this is (an ``--out`` holding another command's results is
        refused).

    Raises
    ------
    InputError
        Bad settings, a run above the cost limits, an output another process is writing or that
        holds another command's results, ``resume`` over the runs of another study (``identity``).
    BatchInterruptedError
        After Ctrl-C, once the summary of what finished is written.
    """
    how = executor if isinstance(executor, Executor) else Executor(executor, workers, scheduler, scheduler_timeout_s)
    task_list = list(tasks)  # scenes built (a bad grid point refused) before the folder is touched
    with StudyFolder(out_dir, kind, identity, resume, field="out", resume_field=resume_option) as folder:
        summary, _runs = summarised_runs(
            folder,
            task_list,
            how,
            resume=resume,
            progress=progress,
            desc=desc,
            allow_large=allow_large,
            group_runs=group_runs,
        )
    return summary


__all__ = [
    "SUMMARY_FILES",
    "TIMING_COLUMNS",
    "UNFINISHED",
    "comparable",
    "completed_row",
    "failures",
    "run_name",
    "run_study_tasks",
    "summarised_runs",
    "summary_frame",
    "write_summary",
]
