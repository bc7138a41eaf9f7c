"""Ctrl-C during a run of many: the first stops dispatching, the second stops the running runs.

The handler only counts and says so: it raises nothing, sets no event and takes no lock (a
``threading.Event`` set from a handler deadlocks when the main thread was inside that event's
lock), and its message never raises either (a write to stderr interrupted by the signal is a
reentrant call: the line then goes to the descriptor directly). The run loops read the count
at their own safe points. A worker process forked while Ctrl-C is pressed never runs this
handler: the thread that forks it holds SIGINT back (:mod:`rockyade.io.warm_program`).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from typing import Any


class StopRequest:
    """Counts Ctrl-C (SIGINT) while work runs: the first asks to stop dispatching, the second
    to stop at once. Installed only in the main thread (elsewhere Python delivers no signal).

    Parameters
    ----------
    raise_on_second
        The runs are threads of this process (they cannot be killed): after the second
        Ctrl-C the run loops raise KeyboardInterrupt at their next safe point (between two
        waits; a run in the calling thread first finishes) for the caller to end the
        process, and a third Ctrl-C is Python's own. The handler itself never raises.
    """

    def __init__(self, raise_on_second: bool = False) -> None:
        self.count = 0
        self.raise_on_second = raise_on_second
        self._previous: Any = None
        self._installed = False

    @property
    def requested(self) -> bool:
        """A first Ctrl-C came: start no new run."""
        return self.count >= 1

    @property
    def now(self) -> bool:
        """A second Ctrl-C came: stop the running runs."""
        return self.count >= 2

    def _handler(self, signum: int, frame: Any) -> None:
        # never raises (module docstring): an exception raised here would surface at an arbitrary
        # point of the main thread (inside a C call it reads as "SystemError: ... returned a
        # result with an exception set"); the run loops read the count at their own safe points
        self.count += 1
        if self.count == 1:
            say("Ctrl-C: no new run starts; waiting for the running runs to finish (Ctrl-C again stops them now)")
        elif self.count == 2:
            if self.raise_on_second:
                say(
                    "Ctrl-C again: stopping the running runs now (a run in this thread cannot be stopped safely "
                    "and finishes first; Ctrl-C a third time interrupts it at once)"
                )
                if self._installed:  # the next Ctrl-C is Python's own KeyboardInterrupt
                    signal.signal(signal.SIGINT, self._previous)
                    self._installed = False
            else:
                say("Ctrl-C again: stopping the running runs now")

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handler)
            self._installed = True
        return self

    def __exit__(self, *exc: object) -> None:
        if self._installed:
            signal.signal(signal.SIGINT, self._previous)
            self._installed = False


def say(message: str) -> None:
    """A line on stderr, on a line of its own (below a progress bar); never raises: where
    ``sys.stderr`` cannot take it (closed, or busy in the very write a signal interrupted),
    it goes to descriptor 2 as it is."""
    line = f"\n{message}\n"
    try:
        sys.stderr.write(line)
        sys.stderr.flush()
    except (OSError, ValueError, RuntimeError):  # RuntimeError: a reentrant call inside the writer
        with contextlib.suppress(OSError):
            os.write(2, line.encode(errors="replace"))
