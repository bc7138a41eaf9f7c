"""Child processes that never outlive their parent (Linux ``prctl(PR_SET_PDEATHSIG)``).

A forked batch worker (:mod:`rockyade.runner.workers`) asks the kernel to SIGKILL it when the
process that started it dies, however it dies (SIGKILL included, where no clean-up code runs).
Where ``prctl`` is missing (not Linux) :func:`die_with_parent` does nothing and the callers'
own clean-up (killing process groups, timeouts) is what remains. The workers of another
program (YADE, Siconos) ask for the same in their own driver,
:func:`rockyade.io.driver_loop.die_with_parent`.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import signal
from collections.abc import Callable

PR_SET_PDEATHSIG = 1


def _load_prctl() -> Callable[..., int] | None:
    libc_name = ctypes.util.find_library("c")
    if not libc_name:
        return None
    try:
        return ctypes.CDLL(libc_name, use_errno=True).prctl
    except (OSError, AttributeError):
        return None


#: Loaded once, in the parent, before any worker is forked.
_PRCTL = _load_prctl()


def die_with_parent(parent_pid: int) -> None:
    """Ask the kernel to SIGKILL this process when its parent dies; leave at once if the
    parent (``parent_pid``) is already gone (it died before the request took effect)."""
    if _PRCTL is not None:
        with contextlib.suppress(OSError):
            _PRCTL(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:
        os._exit(1)
