"""Jobs on a pool of local worker processes (:mod:`rockyade.runner.workers`).

At most ``workers`` jobs are handed to the pool at a time, so a first Ctrl-C leaves the
others unstarted; a second kills the workers (and what they started). A worker that dies
(killed, out of memory) fails its job with that reason; the pool is replaced and the other
jobs go on.
"""

from __future__ import annotations

import collections
from concurrent.futures import FIRST_COMPLETED, Future, wait
from concurrent.futures.process import BrokenProcessPool

from rockyade.runner.threads import Batch, Job, Value, failure_reason
from rockyade.runner.workers import kill_workers, new_pool, replace_pool

WORKER_DIED = "the worker process died (killed, or out of memory)"


def run_local(batch: Batch[Job, Value], workers: int) -> None:
    """Run ``fn(job)`` for every job on ``workers`` processes; ``done(i, value)`` as each ends.

    ``fn`` and the jobs must pickle. Returns when every job ended, or when a stop request
    left the others unstarted (or, after a second Ctrl-C, stopped).
    """
    pending = collections.deque(range(len(batch.jobs)))
    running: dict[Future[Value], int] = {}
    pool = new_pool(workers)
    killed = False
    try:
        while pending or running:
            while pending and len(running) < workers and not batch.stop.requested:
                i = pending.popleft()
                try:
                    running[pool.submit(batch.fn, batch.jobs[i])] = i
                    batch.started.add(i)
                except BrokenProcessPool:
                    pending.appendleft(i)
                    pool = replace_pool(pool, workers)
            if not running:
                break
            finished, _ = wait(running, timeout=0.2, return_when=FIRST_COMPLETED)
            broken = False
            for future in finished:
                i = running.pop(future)
                try:
                    value = future.result()
                except Exception as exc:  # a dead worker, a value that does not pickle: this job fails
                    if batch.failed is None:
                        raise
                    broken = broken or isinstance(exc, BrokenProcessPool)
                    value = batch.failed(
                        batch.jobs[i], WORKER_DIED if isinstance(exc, BrokenProcessPool) else failure_reason(exc)
                    )
                batch.done(i, value)
            if batch.stop.now:
                kill_workers(pool)
                killed = True
                break
            if broken and batch.failed is not None:  # the pool broke: its other running jobs are lost too
                for future, i in list(running.items()):
                    running.pop(future)
                    batch.done(i, batch.failed(batch.jobs[i], WORKER_DIED))
                pool = replace_pool(pool, workers)
    except BaseException:
        kill_workers(pool)
        killed = True
        raise
    finally:
        pool.shutdown(wait=not killed, cancel_futures=True)
