"""Worker processes that never outlive the process that started them.

A pool worker ignores Ctrl-C (the parent decides), leads its own process group (so that
killing the group ends the worker and whatever it started, e.g. a YADE process) and is
killed by the kernel when its parent dies, however it dies (``prctl(PR_SET_PDEATHSIG)``,
:mod:`rockyade.io.parent_death`; where that is missing, a watchdog thread polls the parent).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

from rockyade.io.parent_death import die_with_parent


def worker_init(parent_pid: int) -> None:
    """Pool worker set-up: ignore Ctrl-C (the parent decides), own process group, killed with
    the parent (and a YADE process it started with it)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(OSError):
        os.setpgid(0, 0)
    die_with_parent(parent_pid)
    if threading.current_thread() is threading.main_thread():
        threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="watch-parent").start()


def _watch_parent(parent_pid: int) -> None:
    """Where prctl is missing: poll the parent and end this worker's group when it is gone."""
    while True:
        time.sleep(0.5)
        if os.getppid() != parent_pid:
            with contextlib.suppress(OSError):
                os.killpg(os.getpgrp(), signal.SIGKILL)
            os._exit(1)


def new_pool(workers: int) -> ProcessPoolExecutor:
    """A pool of ``workers`` processes set up by :func:`worker_init` (forked where the system can)."""
    import multiprocessing

    ctx = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=worker_init, initargs=(os.getpid(),))


def kill_workers(pool: ProcessPoolExecutor) -> None:
    """SIGKILL every worker of the pool and the processes they started."""
    processes: dict[int, Any] = dict(getattr(pool, "_processes", None) or {})
    for pid in processes:
        try:
            os.killpg(pid, signal.SIGKILL)
        except OSError:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)


def replace_pool(pool: ProcessPoolExecutor, workers: int) -> ProcessPoolExecutor:
    """A fresh pool in place of a broken one (whose workers are killed first)."""
    kill_workers(pool)
    pool.shutdown(wait=False, cancel_futures=True)
    return new_pool(workers)
