"""Running many jobs: progress, Ctrl-C, failures, in one place for every executor.

:func:`run_jobs` runs any picklable ``fn`` over jobs; :func:`run_tasks` runs (solver,
scene) tasks after checking their costs; :func:`solve_scenes` is the plain case, one solver
over many scenes, Results back in order.

* **Failures**: a job that raises, or whose worker process dies, gets ``failed(job,
  reason)`` as its value; the others go on.
* **Ctrl-C**: the first stops dispatching (queued jobs never start) and lets the running
  ones finish; the second stops them at once (worker processes killed; threads of this
  process abandoned, KeyboardInterrupt raised for the caller to end the process). The
  :class:`Outcome` says what finished, what did not and whether it started.
* **Progress**: a tqdm bar on stderr, one step per finished job.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from rockyade.result import Result
from rockyade.runner.executor import IN_THIS_THREAD, Executor
from rockyade.runner.stopping import StopRequest
from rockyade.runner.tasks import Task, check_costs, failed_task, solve
from rockyade.runner.threads import Failed, Job, Value
from rockyade.scene import Scene
from rockyade.solvers.base import Solver

#: A kind of task (Task or a subclass carrying more, e.g. a batch row's parameters).
TaskT = TypeVar("TaskT", bound=Task)


@dataclass(frozen=True)
class Outcome(Generic[Value]):
    """What a run of many jobs came to.

    Attributes
    ----------
    values
        Position of each finished job -> its value.
    unfinished
        Positions of the jobs that did not finish (not started, or stopped), in order.
    started
        Positions of the jobs that were started.
    stopped
        A Ctrl-C kept some jobs from finishing.
    hard
        A second Ctrl-C stopped running jobs.
    """

    values: dict[int, Value]
    unfinished: list[int]
    started: frozenset[int]
    stopped: bool
    hard: bool

    def in_order(self) -> list[Value]:
        """The values in the jobs' order (every job finished)."""
        return [self.values[i] for i in range(len(self.values))]


def progress_bar(total: int, enabled: bool, desc: str) -> Any:
    """A tqdm progress bar on stderr, counting runs (``update(n)`` as a job of n runs ends)."""
    from tqdm import tqdm

    return tqdm(total=total, disable=not enabled, desc=desc, unit="run", smoothing=0.05)


def run_jobs(
    jobs: Iterable[Job],
    fn: Callable[[Job], Value],
    *,
    executor: Executor = IN_THIS_THREAD,
    failed: Failed[Job, Value] | None = None,
    on_done: Callable[[int, Value], None] | None = None,
    describe_failure: Callable[[Value], str | None] | None = None,
    progress: bool = False,
    desc: str = "runs",
    skipped: int = 0,
    stop: StopRequest | None = None,
    size: Callable[[Job], int] | None = None,
) -> Outcome[Value]:
    """Run ``fn(job)`` for every job on ``executor`` (module docstring).

    Parameters
    ----------
    fn
        What one job does (top-level function: it travels to worker processes).
    failed
        The value of a job that raised or whose worker died, from the job and the reason
        (None: the error is raised here, and the run of many ends).
    on_done
        Called with (position, value) as each job ends, in this thread.
    describe_failure
        A line to print above the progress bar for a value (None: nothing).
    progress, desc
        Show a progress bar named ``desc``.
    skipped
        Runs done before (a resumed batch): counted on the bar as already finished.
    size
        The runs a job holds, as the bar counts them (None: one each; a study's jobs are groups
        of runs, and its bar counts runs).
    stop
        The stop request (Ctrl-C) of a study of several rounds, entered by the caller (None:
        this call installs its own): a Ctrl-C between two rounds stays requested for the next.
    """
    jobs = list(jobs)
    values: dict[int, Value] = {}
    started: set[int] = set()
    runs = [1 if size is None else size(job) for job in jobs]
    bar = progress_bar(sum(runs) + skipped, progress, desc)
    bar.update(skipped)

    def done(i: int, value: Value) -> None:
        values[i] = value
        bar.update(runs[i])
        if on_done is not None:
            on_done(i, value)
        line = describe_failure(value) if describe_failure is not None else None
        if line:
            bar.write(line)

    stopped_now = False
    with contextlib.ExitStack() as stack:
        if stop is None:
            stop = stack.enter_context(StopRequest(raise_on_second=executor.in_process))
        try:
            executor.run(jobs, fn, done, failed, stop, started)
        except KeyboardInterrupt:
            if not stop.requested:
                raise
            stopped_now = True
        finally:
            bar.close()
    unfinished = [i for i in range(len(jobs)) if i not in values]
    return Outcome(
        values=values,
        unfinished=unfinished,
        started=frozenset(started),
        stopped=stop.requested and bool(unfinished),  # a Ctrl-C after the last job changes nothing here
        hard=stop.now or stopped_now,
    )


def run_tasks(
    tasks: Sequence[TaskT],
    fn: Callable[[TaskT], Any] = solve,
    *,
    allow_large: bool = False,
    failed: Callable[[TaskT, str], Any] = failed_task,
    **options: Any,
) -> Outcome[Any]:
    """Check the tasks' costs (before any run: :func:`~rockyade.runner.tasks.check_costs`),
    then run ``fn(task)`` for each (default :func:`~rockyade.runner.tasks.solve`: its
    Result); ``options`` as :func:`run_jobs` takes them.

    Raises
    ------
    InputError
        A run above the cost limits (``allow_large`` lifts them), bad executor settings.
    """
    check_costs(tasks, allow_large)
    return run_jobs(tasks, fn, failed=failed, **options)


def solve_scenes(
    solver: Solver | str,
    scenes: Iterable[Scene],
    *,
    executor: Executor = IN_THIS_THREAD,
    progress: bool = False,
    desc: str = "runs",
    allow_large: bool = False,
) -> list[Result]:
    """Run every scene with ``solver`` (a Solver, or a name); the Results in the scenes'
    order. A run that fails is a Result with status ``failed`` and the reason.

    Raises
    ------
    InputError
        A run above the cost limits (``allow_large`` lifts them).
    KeyboardInterrupt
        Ctrl-C stopped runs before they all finished.
    """
    from rockyade.solvers import as_solver

    solver = as_solver(solver)
    tasks = [Task(i, solver, scene) for i, scene in enumerate(scenes)]
    outcome = run_tasks(tasks, executor=executor, progress=progress, desc=desc, allow_large=allow_large)
    if outcome.unfinished:
        raise KeyboardInterrupt
    return outcome.in_order()
