"""Where jobs run: in this process (threads), on local processes, or on Dask.

* ``threads``: in this process, on ``workers`` threads (1: in the calling thread, in
  order); what a notebook or a study uses for solver runs;
* ``local``: ``workers`` processes of this machine (:mod:`rockyade.runner.local`), tied to
  this process; the batch default;
* ``dask``: Dask's threaded scheduler in this process (no ``scheduler``: no cluster, no
  port), or a ``distributed`` cluster at the ``scheduler`` address
  (:mod:`rockyade.runner.dask_executor`).
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from rockyade.errors import InputError, InputNote
from rockyade.runner.stopping import StopRequest
from rockyade.runner.threads import Batch, Failed, Job, Value

EXECUTORS = ("threads", "local", "dask")
MAX_WORKERS = 1024
#: Seconds to wait for a Dask scheduler to answer (default), and the range allowed.
SCHEDULER_TIMEOUT_S = 10.0
SCHEDULER_TIMEOUT_RANGE_S = (0.1, 3600.0)


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system says, else the
    machine's count)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


@dataclass(frozen=True)
class Executor:
    """How to run many jobs (module docstring).

    Attributes
    ----------
    kind
        ``threads``, ``local`` or ``dask``.
    workers
        Parallel jobs, 1 to 1024 (Dask with a scheduler: the cluster's own).
    scheduler
        A Dask scheduler's address (``kind = "dask"`` only).
    scheduler_timeout_s
        Seconds to wait for that scheduler to answer, 0.1 to 3600.
    """

    kind: str = "local"
    workers: int = 2
    scheduler: str | None = None
    scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S

    def __post_init__(self) -> None:
        if self.kind not in EXECUTORS:
            raise InputError("executor", f"must be one of {', '.join(EXECUTORS)}, got {self.kind!r}")
        if isinstance(self.workers, bool) or not isinstance(self.workers, int) or not 1 <= self.workers <= MAX_WORKERS:
            raise InputError("workers", f"must be an integer in [1, {MAX_WORKERS}], got {self.workers!r}")
        if self.scheduler is not None and self.kind != "dask":
            raise InputError("scheduler", "needs --executor dask")
        lo, hi = SCHEDULER_TIMEOUT_RANGE_S
        timeout = self.scheduler_timeout_s
        if not (isinstance(timeout, (int, float)) and math.isfinite(timeout) and lo <= timeout <= hi):
            raise InputError("scheduler_timeout_s", f"must be in [{lo:g}, {hi:g}] s, got {timeout!r}")
        cores = usable_cores()
        if self.scheduler is None and self.workers > max(2, cores):
            warnings.warn(
                InputNote(
                    "workers",
                    f"{self.workers} parallel workers on this machine's {cores} cores: they share the cores and "
                    f"each pays its start-up before its first run, so {cores} or fewer usually finish sooner; "
                    "accepted as given",
                ),
                stacklevel=2,
            )

    @property
    def in_process(self) -> bool:
        """The jobs are threads of this process (they cannot be killed, only abandoned)."""
        return self.kind == "threads" or (self.kind == "dask" and not self.scheduler)

    def run(
        self,
        jobs: Sequence[Job],
        fn: Callable[[Job], Value],
        done: Callable[[int, Value], None],
        failed: Failed[Job, Value] | None,
        stop: StopRequest,
        started: set[int],
    ) -> None:
        """Run ``fn(job)`` for each job; ``done(position, value)`` as each ends (in this
        thread). A job that raises, or whose worker dies, gets ``failed(job, reason)`` (None:
        the error is raised here)."""
        batch = Batch(jobs, fn, done, failed, stop, started)
        if self.kind == "threads":
            from rockyade.runner.threads import run_threads

            run_threads(batch, self.workers)
        elif self.kind == "local":
            from rockyade.runner.local import run_local

            run_local(batch, self.workers)
        elif self.scheduler:
            from rockyade.runner.dask_executor import run_dask_remote

            run_dask_remote(batch, self.scheduler, self.scheduler_timeout_s)
        else:
            from rockyade.runner.dask_executor import run_dask_in_process

            run_dask_in_process(batch, self.workers)


#: One job after the other in the calling thread.
IN_THIS_THREAD = Executor("threads", 1)
