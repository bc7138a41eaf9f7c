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
from typing import TypeVar

from rockyade.runner.stopping import StopRequest

#: A job, and the value its function gives (a Result, a row, ...): open to the caller.
Job = TypeVar("Job")
Value = TypeVar("Value")
#: The value of a job that raised or whose worker died, from the job and the reason.
Failed = Callable[[Job, str], Value]


def call(fn: Callable[[Job], Value], job: Job, failed: Failed[Job, Value] | None) -> Value:
    """``fn(job)``, or the failed value of the job if it raises (``failed`` None: it raises)."""
    try:
        return fn(job)
    except Exception as exc:  # one failed job never stops the others
        if failed is None:
            raise
        return failed(job, f"{type(exc).__name__}: {exc}")


def run_threads(
    jobs: Sequence[Job],
    fn: Callable[[Job], Value],
    workers: int,
    done: Callable[[int, Value], None],
    failed: Failed[Job, Value] | None,
    stop: StopRequest,
    started: set[int],
) -> None:
    """Run ``fn(job)`` for every job on ``workers`` threads (1: in this thread, in order)."""
    if workers == 1:
        for i, job in enumerate(jobs):
            if stop.requested:
                return
            started.add(i)
            done(i, call(fn, job, failed))
        return
    pending = collections.deque(range(len(jobs)))
    running: dict[Future[Value], int] = {}
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="rockyade-run")
    clean = False
    try:
        while pending or running:
            while pending and len(running) < workers and not stop.requested:
                i = pending.popleft()
                started.add(i)
                running[pool.submit(call, fn, jobs[i], failed)] = i
            if not running:
                break
            finished, _ = wait(running, timeout=0.2, return_when=FIRST_COMPLETED)
            for future in finished:
                done(running.pop(future), future.result())
            if stop.now and running:  # a safe point: the running threads are abandoned
                raise KeyboardInterrupt
        clean = True
    finally:
        pool.shutdown(wait=clean, cancel_futures=True)
