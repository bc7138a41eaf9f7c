"""A programme solved in a child process: Ctrl-C ends it at once, it dies with its parent, and it
says how far it has got.

HiGHS runs in C++ without returning to Python until it is done, so a Ctrl-C in the process that
calls it waits for the whole solve (minutes on a large wall). :func:`solve_in_child` runs
:func:`rockyade.limit.highs.solve_programme` in a child process instead: the parent waits for it
in short steps, so that

* Ctrl-C (KeyboardInterrupt) in the parent kills the child (SIGKILL), waits for it to be gone and
  raises on: nothing is left running;
* the child dies with its parent however the parent dies (:mod:`rockyade.io.parent_death`, asked
  for by the child itself: no Python runs between fork and exec, where it could deadlock on a
  lock another thread held), and ignores a Ctrl-C of its own (the terminal sends it to both: the
  parent decides);
* ``on_progress`` is called every ``progress_every_s`` seconds with the time so far and HiGHS's
  latest iteration (from its log);
* the time limit is HiGHS's own, with a margin after which the parent kills the child itself.

The programme goes to the child as a ``numpy`` archive (no pickle) in a private temporary
folder, and the answer comes back the same way; the folder is removed afterwards.

Run by the parent as ``python -m rockyade.limit.highs_child FOLDER SOLVER TIME_LIMIT PARENT_PID``.
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from rockyade.errors import SolverFailedError
from rockyade.io.parent_death import die_with_parent
from rockyade.limit.highs import Programme, ProgrammeOutcome, check_solver, solve_programme

#: Seconds between progress calls (the CLI prints a line at each).
PROGRESS_EVERY_S = 10.0
#: Seconds past the time limit after which the parent kills a child that has not stopped by itself.
KILL_MARGIN_S = 30.0
#: Seconds between the parent's looks at the child.
POLL_S = 0.05

_NUMBER = r"[-+]?\d+\.?\d*(?:e[-+]?\d+)?"
#: HiPO's iteration row: iteration, primal and dual objectives, infeasibilities, relative gap, time.
_IPM_ROW = re.compile(rf"^\s*(\d+)\s+{_NUMBER}\s+{_NUMBER}\s+{_NUMBER}\s+{_NUMBER}\s+({_NUMBER})\s+{_NUMBER}\s*$")
_SIMPLEX_ROW = re.compile(r"^\s*(\d+)\s+(\S+)\s+(Ph1|Pr|Du)")


def last_iteration(log: Path) -> str:
    """HiGHS's latest iteration in words, from its log ("" when there is none yet)."""
    try:
        with open(log, "rb") as fh:
            fh.seek(0, os.SEEK_END)
            fh.seek(max(fh.tell() - 4096, 0))
            lines = fh.read().decode("utf-8", "replace").splitlines()
    except OSError:
        return ""
    for line in reversed(lines):
        ipm = _IPM_ROW.match(line)
        if ipm is not None:
            return f"interior point iteration {ipm.group(1)}, relative gap {float(ipm.group(2)):.1e}"
        simplex = _SIMPLEX_ROW.match(line)
        if simplex is not None:
            return f"simplex iteration {simplex.group(1)}"
    return ""


def _read_outcome(path: Path) -> ProgrammeOutcome:
    with np.load(path, allow_pickle=False) as a:
        status = int(a["status"])
        iterations = {str(k): int(v) for k, v in zip(a["iteration_kinds"], a["iteration_counts"], strict=True)}
        x = a["x"] if status == 0 else None
        marginals = a["marginals"] if status == 0 else None
        return ProgrammeOutcome(status, x, marginals, str(a["message"]), float(a["seconds"]), iterations)


def _write_outcome(path: Path, outcome: ProgrammeOutcome) -> None:
    part = path.with_name(path.name + ".part.npz")
    empty = np.zeros(0)
    np.savez(
        part,
        status=outcome.status,
        x=empty if outcome.x is None else outcome.x,
        marginals=empty if outcome.marginals is None else outcome.marginals,
        message=outcome.message,
        seconds=outcome.seconds,
        iteration_kinds=np.array(list(outcome.iterations), dtype=str),
        iteration_counts=np.array(list(outcome.iterations.values()), dtype=np.int64),
    )
    os.replace(part, path)  # whole or absent: the parent never reads half an answer


def _ended(proc: subprocess.Popen) -> bool:
    """Whether the child has ended, left unreaped (``waitid`` with ``WNOWAIT``). A look that takes
    none of ``Popen``'s locks: ``Popen.wait``/``poll`` hold one briefly, and a Ctrl-C raised right
    after they take it leaves it held, so that the kill's ``wait`` then hangs for ever (seen once
    in the suite under load)."""
    return os.waitid(os.P_PID, proc.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None


def _reap(proc: subprocess.Popen) -> None:
    """Wait for the child (ended or killed) and keep its exit code, without ``Popen``'s lock."""
    if proc.returncode is None:
        _, status = os.waitpid(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)


def _stop(proc: subprocess.Popen) -> None:
    """Kill the child and wait until it is gone."""
    if proc.returncode is None:
        with contextlib.suppress(ProcessLookupError):
            os.kill(proc.pid, signal.SIGKILL)  # unreaped until _reap: the pid is still the child's
    with contextlib.suppress(ChildProcessError):  # reaped already, by a _reap that a Ctrl-C cut short
        _reap(proc)


def solve_in_child(
    programme: Programme,
    solver: str,
    time_limit_s: float | None = None,
    on_progress: Callable[[float, str], None] | None = None,
    progress_every_s: float = PROGRESS_EVERY_S,
) -> ProgrammeOutcome:
    """:func:`~rockyade.limit.highs.solve_programme` in a child process (module docstring).

    Parameters
    ----------
    programme, solver, time_limit_s
        As :func:`~rockyade.limit.highs.solve_programme`.
    on_progress
        Called every ``progress_every_s`` seconds with (seconds so far, HiGHS's latest iteration in
        words, or "").
    progress_every_s
        Seconds between progress calls.
    """
    check_solver(solver)
    folder = Path(tempfile.mkdtemp(prefix="rockyade-limit-"))
    try:
        # numpy's stubs type savez's keywords as its allow_pickle flag: the arrays' names are not that
        np.savez(folder / "programme.npz", **programme.arrays())  # type: ignore[arg-type]
        limit = "none" if time_limit_s is None else repr(float(time_limit_s))
        with open(folder / "stderr.txt", "wb") as err, open(folder / "highs.log", "wb") as log:
            proc = subprocess.Popen(
                [sys.executable, "-m", "rockyade.limit.highs_child", str(folder), solver, limit, str(os.getpid())],
                stdin=subprocess.DEVNULL,
                stdout=log,
                stderr=err,
                start_new_session=True,  # a Ctrl-C at the terminal reaches the parent only
            )
        start = time.perf_counter()
        next_progress = start + progress_every_s
        deadline = math.inf if time_limit_s is None else start + time_limit_s + KILL_MARGIN_S
        try:
            while not _ended(proc):
                time.sleep(POLL_S)
                now = time.perf_counter()
                if now > deadline:
                    _stop(proc)
                    return ProgrammeOutcome(1, None, None, "killed past the time limit", now - start)
                if on_progress is not None and now >= next_progress:
                    next_progress = now + progress_every_s
                    on_progress(now - start, last_iteration(folder / "highs.log"))
            _reap(proc)
        except BaseException:
            _stop(proc)  # Ctrl-C, or anything else: the child goes first
            raise
        outcome = folder / "outcome.npz"
        if proc.returncode != 0 or not outcome.is_file():
            tail = (folder / "stderr.txt").read_text(errors="replace").strip().splitlines()[-3:]
            raise SolverFailedError(
                f"the HiGHS process ended with code {proc.returncode} without an answer"
                + (f": {' / '.join(tail)}" if tail else "")
            )
        return _read_outcome(outcome)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _line_buffered_stdout() -> None:
    """C's standard output flushed at every line: HiGHS's log reaches the file as it is written (the
    parent reads its latest iteration from there). Without glibc's ``stdout`` symbol, as it is."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        libc = ctypes.CDLL(None)
        libc.setvbuf(ctypes.c_void_p.in_dll(libc, "stdout"), None, 1, 0)  # 1: _IOLBF


def _child_main(argv: list[str]) -> int:
    """The child: read the programme, solve it, write the outcome."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides on Ctrl-C, and kills this process
    die_with_parent(int(argv[3]))
    _line_buffered_stdout()
    folder, solver, limit = Path(argv[0]), argv[1], argv[2]
    with np.load(folder / "programme.npz", allow_pickle=False) as arrays:
        programme = Programme.from_arrays(arrays)
    time_limit = None if limit == "none" else float(limit)
    outcome = solve_programme(programme, solver, time_limit, log=True)
    _write_outcome(folder / "outcome.npz", outcome)
    return 0


if __name__ == "__main__":
    sys.exit(_child_main(sys.argv[1:]))
