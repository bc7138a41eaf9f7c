"""The one way a study runs its runs: :func:`run_study`.

Every study goes through it (``batch``, ``uncertainty``, the pattern map, ``fragility``,
``assess``, the paper's fragility, each round of ``crosscheck``) with its tasks
(:class:`rockyade.batch.running.BatchTask`) and, when it resumes and keeps its runs, the
journal of its output folder (:class:`rockyade.runner.study_folder.StudyFolder`):

1. tasks that repeat a run (the same scene hash and solver: the same name) run once, the
   others reading its row (``duplicate_of``);
2. a run the journal holds (finished earlier, sealed, answered for the same scene) is read
   back, not run again; a record that is not as it was written is said and run again;
3. the costs of the runs to make are checked before any runs
   (:func:`rockyade.runner.tasks.check_costs`);
4. runs that share a structure go to one job (:func:`rockyade.batch.running.job_key`), the
   jobs to the executor (:func:`rockyade.runner.dispatch.run_jobs`: local processes, threads or
   Dask; progress; a failed run never stopping the others; Ctrl-C);
5. each run writes its record in the study's folder as it ends, where it runs
   (:func:`rockyade.batch.running.recorded`);
6. Ctrl-C: the rows so far, the others ``unfinished``, in :class:`StudyInterruptedError`. A study
   of several rounds passes one stop request (:class:`rockyade.runner.stopping.StopRequest`)
   to every round and stops between rounds when it was asked to: a Ctrl-C is never lost.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Hashable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from rockyade.batch.running import BatchTask, Output, job_key, run_job
from rockyade.errors import BatchInterruptedError
from rockyade.runner import Executor, check_costs, run_jobs
from rockyade.runner.executor import IN_THIS_THREAD
from rockyade.runner.groups import group_jobs
from rockyade.runner.rows import UNFINISHED, RunRow
from rockyade.runner.stopping import say as say_on_stderr

if TYPE_CHECKING:
    from rockyade.result import Result
    from rockyade.runner.journal import Journal
    from rockyade.runner.stopping import StopRequest
    from rockyade.scene import Scene
    from rockyade.solvers.base import Solver

#: Most runs of one group in one job (groups are cut so that every worker gets jobs).
MAX_RUNS_PER_JOB = 64


@dataclass(frozen=True)
class StudyRuns:
    """What :func:`run_study` came to.

    Attributes
    ----------
    rows
        A row per task, in the tasks' order (index).
    made
        Runs made now.
    reused
        Runs read back from the journal.
    unfinished
        Runs a Ctrl-C stopped or kept from starting (their rows ``unfinished``).
    hard
        A second Ctrl-C stopped running runs.
    """

    rows: list[RunRow]
    made: int
    reused: int
    unfinished: int = 0
    hard: bool = False

    @property
    def finished(self) -> int:
        """Runs that finished (answered or failed)."""
        return len(self.rows) - self.unfinished


class StudyInterruptedError(BatchInterruptedError):
    """Ctrl-C stopped a study's runs: its :class:`StudyRuns` so far (unfinished rows included)."""

    def __init__(self, runs: StudyRuns, resume_option: str | None = "--resume") -> None:
        self.runs = runs
        super().__init__(runs.finished, runs.unfinished, None, runs.hard, resume_option)


def distinct(tasks: Sequence[BatchTask]) -> tuple[list[BatchTask], list[tuple[BatchTask, BatchTask]]]:
    """The tasks run (the first of each run name: the same scene hash and solver) and the
    duplicates, each with the task it repeats (run once: two tasks would write one record)."""
    first: dict[str, BatchTask] = {}
    duplicates = []
    for task in tasks:
        if task.name in first:
            duplicates.append((task, first[task.name]))
        else:
            first[task.name] = task
    return list(first.values()), duplicates


def run_study(
    tasks: Iterable[BatchTask],
    *,
    executor: Executor = IN_THIS_THREAD,
    journal: Journal | None = None,
    reuse: bool = True,
    files: Output | None = None,
    allow_large: bool = False,
    progress: bool = True,
    desc: str = "runs",
    group_runs: bool = True,
    stop: StopRequest | None = None,
    tell_failures: bool = True,
    say: Callable[[str], None] = say_on_stderr,
) -> StudyRuns:
    """Run a study's tasks (module docstring); their rows in the tasks' order.

    Parameters
    ----------
    tasks
        The runs, each with its index in the study.
    executor
        Where the runs run.
    journal
        The journal of the study's finished runs (None: none).
    reuse
        Read back the runs the journal holds rather than run them again (a resume).
    files
        Where the runs write their records as they end, and keep their files (a kept time
        history, a solver's own); None: nowhere (the journal's folder, when given, is the runs').
    allow_large
        Run even if a run's cost estimate is above the limits of :mod:`rockyade.runner.cost_limits`.
    progress, desc
        A progress bar named ``desc``.
    group_runs
        Run the runs that share a structure together (the same rows); False: one run per job.
    stop
        The stop request of a study of several rounds (None: this call's own).
    tell_failures
        Say each failed run above the progress bar.
    say
        Where notes go (records not as written).

    Raises
    ------
    InputError
        A run above the cost limits, bad executor settings.
    StudyInterruptedError
        Ctrl-C stopped runs before they all finished (the rows so far in it).
    """
    tasks = list(tasks)
    first, duplicates = distinct(tasks)
    rows: dict[int, RunRow] = {}
    todo = []
    damaged = len(journal.damaged) if journal is not None else 0
    for task in first:
        found = journal.found(task.name, task.scene_hash) if journal is not None and reuse else None
        if found is None:
            todo.append(task)
        else:
            rows[task.index] = replace(RunRow.from_record(task, found.summary, found.verdict), recorded=True)
    if journal is not None and len(journal.damaged) > damaged:
        names = journal.damaged[damaged:]
        say(
            f"{len(names)} run record(s) in {journal.folder} are not as they were written (edited or damaged: their "
            f"SHA-256 does not match): run again ({', '.join(names[:3])}{', ...' if len(names) > 3 else ''})"
        )
    check_costs(todo, allow_large)
    key: Callable[[BatchTask], Hashable | None] = job_key if group_runs else (lambda _task: None)
    n_grouped = sum(key(t) is not None for t in todo)
    jobs = group_jobs(todo, key, min(MAX_RUNS_PER_JOB, max(1, -(-n_grouped // (4 * executor.workers)))))
    reused = len(rows)

    def done(_i: int, job_rows: list[RunRow]) -> None:
        for row in job_rows:
            rows[row.index] = row

    outcome = run_jobs(
        jobs,
        functools.partial(run_job, out=files),
        executor=executor,
        failed=lambda job, reason: [RunRow.placeholder(task, "failed", reason) for task in job],
        on_done=done,
        describe_failure=_failure_lines if tell_failures else None,
        progress=progress,
        desc=desc,
        skipped=reused,
        stop=stop,
        size=len,
    )
    for i in outcome.unfinished:
        reason = "stopped by Ctrl-C" if i in outcome.started else "not started: Ctrl-C"
        for task in jobs[i]:
            rows[task.index] = RunRow.placeholder(task, UNFINISHED, reason)
    for task, original in duplicates:
        rows[task.index] = rows[original.index].duplicate(task)
    ordered = [rows[index] for index in sorted(rows)]
    unfinished = sum(row.status == UNFINISHED for row in ordered)
    runs = StudyRuns(
        ordered, len(todo) - sum(len(jobs[i]) for i in outcome.unfinished), reused, unfinished, outcome.hard
    )
    if outcome.stopped:
        raise StudyInterruptedError(runs)
    return runs


def _failure_lines(job_rows: list[RunRow]) -> str | None:
    """``failed: <run>: <reason>`` for each failed run of a job; None when none failed."""
    lines = [f"failed: {row.name}: {row.failure_reason}" for row in job_rows if row.status == "failed"]
    return "\n".join(lines) or None


def run_scenes(
    solver: Solver | str, scenes: Iterable[Scene], executor: Executor = IN_THIS_THREAD, desc: str = "runs"
) -> list[Result]:
    """The Results of ``solver`` (a Solver, or a name) on ``scenes``, in their order, for a study
    that reads each run whole: :func:`run_study` keeping the Results, a progress bar named
    ``desc``; a run that failed is a failed Result with its reason (as
    :func:`rockyade.runner.solve_scenes` gives them to a script).

    Raises
    ------
    KeyboardInterrupt
        Ctrl-C stopped runs before they all finished.
    """
    from rockyade.result import failed_result
    from rockyade.solvers import as_solver

    one = as_solver(solver)
    tasks = [
        BatchTask(i, one, s, {}, save_history=False, metrics=False, keep_result=True) for i, s in enumerate(scenes)
    ]
    try:
        rows = run_study(tasks, executor=executor, desc=desc, tell_failures=False).rows
    except StudyInterruptedError:
        raise KeyboardInterrupt from None
    return [r.result if r.result is not None else failed_result(r.solver, r.scene_hash, r.failure_reason) for r in rows]


__all__ = ["MAX_RUNS_PER_JOB", "StudyInterruptedError", "StudyRuns", "distinct", "run_scenes", "run_study"]
