"""The loop of every worker driver, and the one dialect of their output (standard library only).

A driver (YADE's, :mod:`rockyade.yade.driver`; Siconos's, :mod:`rockyade.siconos.driver`) runs
in its engine's Python, where rockyade is not importable: it loads this file by its path
inside the installed package (``rockyade/io/driver_loop.py``, found from the driver's own
folder; beside ``run.py`` in a ``rockyade yade-script`` folder), so it imports nothing but
the standard library. The other side of the protocol is :mod:`rockyade.io.warm_program`.

**Dies with its parent** (:func:`die_with_parent`): first thing in :func:`serve`, the worker asks
the kernel to SIGKILL it when the thread that started it ends (Linux ``prctl(PR_SET_PDEATHSIG)``),
and leaves at once if that process (``ROCKYADE_WORKER_PARENT``) is already gone. It is done here,
after exec, not in a ``preexec_fn``: Python code between fork and exec in a process with
threads can deadlock the child before exec (a lock another thread held at the fork), and the
thread that started it then waits for it forever.

**The loop** (:func:`serve`, ``--serve FD``): FD is the worker's end of a socket pair
(AF_UNIX, SOCK_SEQPACKET: no address, no port). It says ``{"ready": true, "pid": ...}``, then
takes jobs ``{"scene": path, "out": path, "deadline": t, "flush_s": s}``, each with the
descriptor of the job's log file (SCM_RIGHTS) onto which its stdout and stderr go while the
job runs, and answers each with ``{"ok": true}`` (``"timeout": true`` when the scene was
stopped at its deadline, a ``time.monotonic()`` value, with its samples written),
``{"ok": false, "path", "errno", "strerror"}`` (its output could not be written: its
partial file removed) or ``{"ok": false, "error"}`` after a scene that raised, and then exits
(code 1): a fresh worker takes the next scene. It stops on ``{"quit": true}`` or when its end
of the socket closes.

**The output** (:func:`output_meta`, :func:`write_output`): a ``.npz`` of the engine's
arrays and ``meta``, one JSON object whose keys are the same for every engine: ``status``
(``running`` for a flush while the scene runs), ``stop_time_s``, ``overturn_times_s`` (body
index as text -> s), ``stop_body``, ``n_filled``, ``steps``, ``version`` (the engine's),
``dt_s``, ``wall_time_s``, ``complete``, ``flushes``, ``process_cpu_s``, then the engine's
own diagnostics (:class:`rockyade.dem.worker_output.WorkerOutput` reads them). Every file is
written to ``<path>.part`` and renamed onto ``path``: a kill leaves the previous file whole.
"""

import contextlib
import ctypes
import json
import os
import signal
import socket
import sys
import time
import traceback
from collections.abc import Callable
from typing import IO, Any, NoReturn

#: Largest message either side sends, bytes.
MESSAGE_BYTES = 1 << 16

#: The environment variable naming the process that started this worker (its pid).
PARENT_VARIABLE = "ROCKYADE_WORKER_PARENT"

#: ``prctl``'s option that names the signal sent when the parent thread ends (linux/prctl.h).
PR_SET_PDEATHSIG = 1


class OutputError(Exception):
    """The output could not be written (its partial file is removed)."""

    def __init__(self, path: str, exc: OSError) -> None:
        super().__init__(f"cannot write {path}: {exc.strerror or exc}")
        self.path = path
        self.errno = exc.errno
        self.strerror = exc.strerror or str(exc)


def write_replacing(path: str, fill: Callable[[IO[bytes]], object]) -> None:
    """``fill(fh)`` into ``path + ".part"`` (an open binary file, flushed and synced), then
    renamed onto ``path``; on failure the partial file is removed and OutputError names ``path``."""
    tmp = path + ".part"
    try:
        with open(tmp, "wb") as fh:
            fill(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise OutputError(path, exc) from None


def output_meta(
    recorder: Any, complete: bool, steps: int, version: str, dt_s: float, **engine: object
) -> dict[str, Any]:
    """The output's metadata (module docstring) from a driver's recorder, whose attributes
    ``status``, ``stop_time``, ``stop_body``, ``overturn_times`` (index -> s), ``k`` (samples
    taken), ``start`` (``time.perf_counter()`` at its start) and ``flushes`` are the same in
    every driver; ``complete`` False: a flush while running, or a run stopped at its deadline;
    ``engine``: the engine's own diagnostics."""
    status = recorder.status
    return {
        "status": status if complete or status == "timeout" else "running",
        "stop_time_s": recorder.stop_time,
        "overturn_times_s": {str(i): t for i, t in recorder.overturn_times.items()},
        "stop_body": recorder.stop_body,
        "n_filled": recorder.k,
        "steps": steps,
        "version": version,
        "dt_s": dt_s,
        "wall_time_s": time.perf_counter() - recorder.start,
        "complete": complete,
        "flushes": recorder.flushes,
        "process_cpu_s": time.process_time(),
        **engine,
    }


def write_output(path: str, savez: Callable[..., None], arrays: dict[str, Any], meta: dict[str, Any]) -> None:
    """The samples and their metadata to ``path`` (``savez``: numpy's, from the driver)."""
    write_replacing(path, lambda fh: savez(fh, **arrays, meta=json.dumps(meta)))


def die_with_parent() -> None:
    """Ask the kernel to SIGKILL this process when the thread that started it ends, however it
    ends; leave at once (exit 1) if the process named by ``ROCKYADE_WORKER_PARENT`` is no longer
    our parent (it died before the request took effect). Where ``prctl`` is missing (not
    Linux) only the check remains; the parent's own clean-up (it kills the worker's process
    group) does the rest."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    parent = os.environ.get(PARENT_VARIABLE, "")
    if parent.isdigit() and os.getppid() != int(parent):
        os._exit(1)


def _send(sock: socket.socket, message: dict[str, Any]) -> None:
    sock.send(json.dumps(message).encode())


def serve(
    fd: int,
    run: Callable[[str, str, float | None, float | None], str | None],
    hello: dict[str, Any] | None = None,
    after_job: Callable[[], None] | None = None,
) -> int:
    """Run scenes as they come on socket ``fd`` (module docstring); return the exit code.

    Parameters
    ----------
    run
        ``run(scene_path, out_path, deadline, flush_s)``: one scene; its status.
    hello
        More keys of the first message.
    after_job
        Called after each job the worker survives, before it answers (YADE's reset).
    """
    die_with_parent()
    sock = socket.socket(fileno=fd)
    keep_out, keep_err = os.dup(1), os.dup(2)
    _send(sock, {"ready": True, "pid": os.getpid(), **(hello or {})})
    while True:
        try:
            data, fds, _flags, _addr = socket.recv_fds(sock, MESSAGE_BYTES, 1)
        except OSError:
            return 0
        if not data:  # the other end closed: rockyade is gone or done
            for extra in fds:
                os.close(extra)
            return 0
        job = json.loads(data)
        if job.get("quit"):
            return 0
        sys.stdout.flush()
        sys.stderr.flush()
        for log in fds:
            os.dup2(log, 1)
            os.dup2(log, 2)
            os.close(log)
        reply: dict[str, Any] = {"ok": True}
        try:
            if run(job["scene"], job["out"], job.get("deadline"), job.get("flush_s")) == "timeout":
                reply["timeout"] = True  # stopped at its deadline, its samples written
        except OutputError as exc:
            reply = {"ok": False, "path": exc.path, "errno": exc.errno, "strerror": exc.strerror}
        except Exception as exc:  # reported, then this worker ends
            traceback.print_exc()
            reply = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(keep_out, 1)
        os.dup2(keep_err, 2)
        if not reply["ok"] and "errno" not in reply:
            _send(sock, reply)
            return 1  # a scene that raised: a fresh worker takes the next
        if after_job is not None:
            after_job()
        _send(sock, reply)


def exit_now(code: int) -> NoReturn:
    """Leave at once, output flushed: an engine's threads, cancelled by the interpreter's
    normal exit, may abort the process after the output is written (YADE's does)."""
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
