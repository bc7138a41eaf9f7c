"""Jobs on Dask: its threaded scheduler in this process, or a ``distributed`` cluster.

Without a scheduler address the jobs run on Dask's threaded scheduler inside this process:
no cluster starts and no socket opens (a ``distributed.LocalCluster`` would start HTTP
servers). With an address (``tcp://``, ``tls://``, ...) they run on that cluster; Ctrl-C
cancels what has not finished. Dask is optional: ``pip install 'rockyade[dask]'``.
"""

from __future__ import annotations

import queue
import re
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from rockyade.errors import InputError
from rockyade.runner.threads import Batch, Job, Value, call, failure_reason

SCHEDULER_ADDRESS = re.compile(r"^(tcp|tls|ucx|inproc)://\S+$")


def check_scheduler(address: str) -> str:
    """A scheduler address as ``tcp://host:port`` (or tls, ucx, inproc).

    Raises
    ------
    InputError
        Anything else.
    """
    if not isinstance(address, str) or not SCHEDULER_ADDRESS.match(address):
        raise InputError("scheduler", f"must be an address like tcp://host:8786 or tls://host:8786, got {address!r}")
    return address


def run_dask_in_process(batch: Batch[Job, Value], workers: int) -> None:
    """Dask's threaded scheduler on ``workers`` threads of this process; a stop request makes
    the unstarted jobs return at once, unfinished."""
    try:
        import dask.threaded
        from dask.callbacks import Callback
    except ImportError:
        raise InputError("executor", "the dask executor needs dask: pip install 'rockyade[dask]'") from None

    unfinished = object()

    def guarded(i: int) -> Any:
        if batch.stop.requested:
            return unfinished
        batch.started.add(i)
        return i, call(batch.fn, batch.jobs[i], batch.failed)

    finished: queue.Queue[Any] = queue.Queue()
    end = object()
    errors: list[BaseException] = []

    def posttask(key: Any, value: Any, dsk: Any, state: Any, worker_id: Any) -> None:
        if value is not unfinished:
            finished.put(value)

    def drive() -> None:
        try:
            with Callback(posttask=posttask):
                dask.threaded.get(graph, list(graph), pool=pool)
        except BaseException as exc:  # handed to the calling thread
            errors.append(exc)
        finally:
            finished.put(end)

    # the graph's arguments are positions: Dask never looks inside a job
    graph = {f"run-{i}": (guarded, i) for i in range(len(batch.jobs))}
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="rockyade-dask")
    clean = False
    try:
        # Dask's scheduler waits in a thread of its own; this thread takes each finished job
        # (``done`` runs here) and, after a second Ctrl-C, stops at its next wait (a safe point:
        # the signal handler never raises)
        # not a daemon: neither are the pool's threads it starts, which the command line then
        # sees as busy after a second Ctrl-C and ends the process without waiting for them
        threading.Thread(target=drive, name="rockyade-dask-get", daemon=False).start()
        while True:
            try:
                item = finished.get(timeout=0.1)
            except queue.Empty:
                if batch.stop.now:
                    raise KeyboardInterrupt from None
                continue
            if item is end:
                break
            batch.done(*item)
        if errors:
            raise errors[0]
        clean = True
    finally:
        # after a second Ctrl-C the running jobs are threads that cannot be killed: the
        # command line ends the process
        pool.shutdown(wait=clean, cancel_futures=True)


def run_dask_remote(batch: Batch[Job, Value], scheduler: str, timeout_s: float) -> None:
    """A ``distributed`` cluster at ``scheduler``; Ctrl-C cancels what has not finished.

    Raises
    ------
    InputError
        No dask[distributed], a malformed address, or no scheduler answering within ``timeout_s``.
    """
    try:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise InputError(
            "executor", "the dask executor needs dask[distributed]: pip install 'rockyade[dask]'"
        ) from None
    check_scheduler(scheduler)
    try:
        client = Client(scheduler, timeout=timeout_s)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            "scheduler", f"no Dask scheduler answered at {scheduler} within {timeout_s:g} s ({exc})"
        ) from None
    try:
        futures = client.map(batch.fn, list(batch.jobs), pure=False)
        position = {future.key: i for i, future in enumerate(futures)}
        batch.started.update(range(len(batch.jobs)))  # the cluster decides when: cancelled ones count as stopped
        pending = dask_completed(futures)
        while not pending.is_empty():
            ready = pending.next_batch(block=False)
            for future in ready:
                i = position[future.key]
                try:
                    value = future.result()
                except Exception as exc:  # a worker lost, a value that does not pickle: this job fails
                    if batch.failed is None:
                        raise
                    value = batch.failed(batch.jobs[i], failure_reason(exc))
                batch.done(i, value)
            if batch.stop.requested:
                client.cancel([f for f in futures if not f.done()])
                break
            if not ready:
                time.sleep(0.1)
    finally:
        client.close()
