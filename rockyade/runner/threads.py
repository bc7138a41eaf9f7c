"""Jobs in this process: in the calling thread (one worker) or on a pool of threads.

The numba kernels release the GIL and a YADE run is a process of its own, so threads run
solvers in parallel without the cost of worker processes (and ``fn`` need not pickle).
Threads cannot be killed: after a second Ctrl-C the loop raises KeyboardInterrupt at its
next wait and the caller ends the process (:class:`~rockyade.runner.stopping.StopRequest`
only counts; it never raises from the signal handler).
"""

from __future__ import annotations

import collections
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from typing import Generic, TypeVar

from rockyade.runner.stopping import StopRequest

#: A job, and the value its function gives (a Result, a row, ...): open to the caller.
Job = TypeVar("Job")
Value = TypeVar("Value")
#: The value of a job that raised or whose worker died, from the job and the reason.
Failed = Callable[[Job, str], Value]


@dataclass(frozen=True)
class Batch(Generic[Job, Value]):
    """The jobs one executor runs and what it tells as they go (every runner of this package
    takes one, with its own settings: workers, a scheduler).

    Attributes
    ----------
    jobs
        The jobs, by position.
    fn
        A job's value: ``fn(job)``.
    done
        Takes each value as its job ends: ``done(position, value)``, in the calling thread.
    failed
        The value of a job that raised or whose worker died: ``failed(job, reason)`` (None:
        the error is raised).
    stop
        The stop request (Ctrl-C) the runner honours.
    started
        Where the runner adds the position of each job it started.
    """

    jobs: Sequence[Job]
    fn: Callable[[Job], Value]
    done: Callable[[int, Value], None]
    failed: Failed[Job, Value] | None
    stop: StopRequest
    started: set[int]


def failure_reason(exc: BaseException) -> str:
    """What a failed job's value says of the error that ended it."""
    return f"{type(exc).__name__}: {exc}"


def call(fn: Callable[[Job], Value], job: Job, failed: Failed[Job, Value] | None) -> Value:
    """``fn(job)``, or the failed value of the job if it raises (``failed`` None: it raises)."""
    try:
        return fn(job)
    except Exception as exc:  # one failed job never stops the others
        if failed is None:
            raise
        return failed(job, failure_reason(exc))


def run_threads(batch: Batch[Job, Value], workers: int) -> None:
    """Run ``fn(job)`` for every job on ``workers`` threads (1: in this thread, in order)."""
    if workers == 1:
        for i, job in enumerate(batch.jobs):
            if batch.stop.requested:
                return
            batch.started.add(i)
            batch.done(i, call(batch.fn, job, batch.failed))
        return
    pending = collections.deque(range(len(batch.jobs)))
    running: dict[Future[Value], int] = {}
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="rockyade-run")
    clean = False
    try:
        while pending or running:
            while pending and len(running) < workers and not batch.stop.requested:
                i = pending.popleft()
                batch.started.add(i)
                running[pool.submit(call, batch.fn, batch.jobs[i], batch.failed)] = i
            if not running:
                break
            finished, _ = wait(running, timeout=0.2, return_when=FIRST_COMPLETED)
            for future in finished:
                batch.done(running.pop(future), future.result())
            if batch.stop.now and running:  # a safe point: the running threads are abandoned
                raise KeyboardInterrupt
        clean = True
    finally:
        pool.shutdown(wait=clean, cancel_futures=True)
