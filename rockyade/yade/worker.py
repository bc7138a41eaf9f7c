"""YADE kept warm: one YADE process runs many scenes, one after the other.

Starting YADE (Debian's Python, YADE's modules, numpy) costs 0.7-1.0 s, as much as the
simulation of a short single-block scene. A :class:`YadeWorker` is the driver
(:mod:`rockyade.yade.driver`) started once with ``--serve``: it takes a scene, runs it,
resets YADE (``O.reset()``: bodies, engines, materials, time step, periodic cell; and its
own recorder) and waits for the next. Results are the same, bit for bit, as one process
per scene (``tests/test_yade_worker.py``).

* **No port.** The worker talks over a socket pair (AF_UNIX, SOCK_SEQPACKET: no address,
  nothing listens); each job's log file goes to it as a descriptor (SCM_RIGHTS), opened
  here as :mod:`rockyade.io.atomic` opens files (a new file under a random name, never
  through a link), and renamed onto ``<name>.yade.log`` when the job ends.
* **Dies with its parent.** Its own session (a timeout kills its group) and
  ``PR_SET_PDEATHSIG`` (:mod:`rockyade.io.lifetime`): the kernel kills it when the thread
  that started it ends, however the process ends. Each thread therefore keeps its own
  worker (:func:`run_scene`); a thread that ends closes it; a forked child forgets its
  parent's.
* **Timeout per scene.** Each scene has its own wall-clock limit (counting a worker's
  start when one is needed). The driver stops the scene at that deadline itself and writes
  the samples it has (the worker goes on to the next scene); a worker that has not answered
  STOP_GRACE_S later is killed and the next scene starts a fresh one. While a scene runs its
  samples so far are written every FLUSH_PERIOD_S seconds, so a killed scene keeps them too:
  the Result is ``failed`` with ``partial: true`` (:mod:`rockyade.yade.backend`).
* **A crash costs one scene.** A worker that dies (a YADE crash, a signal) or whose scene
  raised fails that scene only; the next starts a fresh worker.
* **Nothing left behind.** The worker's start-up output goes to an anonymous file; the
  folder YADE makes in /tmp at import is removed by the driver at once.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import tempfile
import threading
import time
import weakref
from pathlib import Path
from typing import IO, Any

from rockyade.errors import os_error_message
from rockyade.io.atomic import create_temporary, file_mode
from rockyade.io.lifetime import child_dies_with_parent

#: Seconds a worker has to stop after ``quit`` before it is killed.
QUIT_WAIT_S = 5.0
#: Largest message either side sends, bytes.
MESSAGE_BYTES = 1 << 16
#: A scene's samples so far are written every so many seconds while it runs (kept when the
#: worker is killed), s.
FLUSH_PERIOD_S = 30.0
#: Seconds after a scene's deadline before its worker is killed: the driver stops the scene at
#: the deadline itself (at its next sample) and writes what it recorded in this time.
STOP_GRACE_S = 10.0


class WorkerLostError(Exception):
    """The worker ended (crashed, killed, or timed out): the reason, as a run failure.

    Attributes
    ----------
    output
        What the worker wrote outside a job (its start-up, a crash's last words).
    """

    def __init__(self, reason: str, output: str = "") -> None:
        super().__init__(reason)
        self.output = output


def _timeout_reason(timeout: float) -> str:
    return f"timeout: YADE did not finish within {timeout:.6g} s and was stopped (raise it with --yade-timeout)"


def _last_error_line(text: str) -> str:
    """The last line that names an error ("" when there is none: a banner is not a reason)."""
    for line in reversed([ln.strip() for ln in text.splitlines() if ln.strip()]):
        if "Error" in line or "Exception" in line:
            return line
    return ""


class YadeWorker:
    """One YADE process that runs scenes on request (module docstring).

    Parameters
    ----------
    command
        The driver's command line without ``--serve FD`` (YADE's Python and the driver).
    env
        Its environment.
    deadline
        ``time.monotonic()`` by which it must be ready.

    Raises
    ------
    WorkerLostError
        It did not start (the reason names YADE's last error line) or not in time.
    """

    def __init__(self, command: list[str], env: dict[str, str], deadline: float, timeout: float) -> None:
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        # its output outside jobs: a file unlinked at once, nothing to leave behind
        self.startup: IO[bytes] = tempfile.TemporaryFile()  # noqa: SIM115 - lives as long as the worker
        self.owner = os.getpid()
        self.sock = ours
        self.closed = False
        try:
            self.proc = subprocess.Popen(
                [*command, "--serve", str(theirs.fileno())],
                stdin=subprocess.DEVNULL,
                stdout=self.startup,
                stderr=subprocess.STDOUT,
                env=env,
                pass_fds=(theirs.fileno(),),
                start_new_session=True,  # a group of its own: a timeout kills YADE and its children
                preexec_fn=child_dies_with_parent(),  # ... and it dies with this thread, even by SIGKILL
            )
        except BaseException:
            ours.close()
            self.startup.close()
            raise
        finally:
            theirs.close()
        _WORKERS.add(self)
        try:
            hello = self._receive(deadline, timeout)
        except WorkerLostError:
            raise
        except BaseException:
            self.kill()
            self.forget()
            raise
        if not hello.get("ready"):
            raise self._lost(f"YADE did not start: unexpected first message {hello!r}")
        self.pid = int(hello["pid"])

    # ------------------------------------------------------------------ messages

    def _receive(self, deadline: float, timeout: float) -> dict[str, Any]:
        """The next message; WorkerLostError when the worker ends or the deadline passes."""
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise self._lost(_timeout_reason(timeout))
        self.sock.settimeout(remaining)
        try:
            data = self.sock.recv(MESSAGE_BYTES)
        except TimeoutError:
            raise self._lost(_timeout_reason(timeout)) from None
        except OSError as exc:
            data = b""
            note = f" ({exc})"
        else:
            note = ""
        if not data:
            raise self._lost(f"YADE exited with code {{code}}{note}")
        return json.loads(data)

    def _lost(self, reason: str) -> WorkerLostError:
        """Kill and reap the worker (at once if it ended already); the error saying why it is
        lost (``{code}`` in ``reason``: its exit code), with its last error line."""
        code = self.kill()
        output = self.startup_text()
        self.forget()
        detail = _last_error_line(output)
        reason = reason.replace("{code}", str(code))
        if detail and not reason.startswith("timeout"):
            reason += f": {detail}"
        return WorkerLostError(reason, output)

    def startup_text(self) -> str:
        """What the worker wrote outside a job (its start-up, a crash's last words)."""
        try:
            self.startup.seek(0)
            return self.startup.read().decode(errors="replace")
        except (OSError, ValueError):
            return ""

    # ------------------------------------------------------------------ a job

    def run(self, scene_file: Path, out_file: Path, log_fd: int, deadline: float, timeout: float) -> str | None:
        """Run one scene; the reason it failed, or None. Its stdout and stderr go to ``log_fd``.

        Raises
        ------
        WorkerLostError
            The worker ended (the reason is the scene's failure); it is not used again.
        """
        # the deadline as time.monotonic() gives it: CLOCK_MONOTONIC, one clock for every process
        job = {"scene": str(scene_file), "out": str(out_file), "deadline": deadline, "flush_s": FLUSH_PERIOD_S}
        message = json.dumps(job).encode()
        try:
            socket.send_fds(self.sock, [message], [log_fd])
        except OSError:  # it died since the last job: the caller starts a fresh one
            self.kill()
            self.forget()
            raise
        try:
            reply = self._receive(deadline + STOP_GRACE_S, timeout)
        except WorkerLostError:
            raise
        except BaseException:  # Ctrl-C or any other interruption: never leave YADE running
            self.kill()
            self.forget()
            raise
        if reply.get("ok"):  # done, or stopped at its deadline with its samples written
            return _timeout_reason(timeout) if reply.get("timeout") else None
        if "errno" in reply:  # YADE could not write its output (its partial file removed)
            error = OSError(reply["errno"], reply.get("strerror") or "", reply.get("path"))
            return f"YADE could not write its output: {os_error_message(error)}"
        code = self.wait_exit(deadline)  # a scene that raised: the worker ends
        return f"YADE exited with code {code}"

    # ------------------------------------------------------------------ the end

    def alive(self) -> bool:
        """True while the worker process runs and belongs to this process (not closed, not
        inherited through a fork)."""
        return not self.closed and self.owner == os.getpid() and self.proc.poll() is None

    def wait_exit(self, deadline: float) -> int | None:
        """Wait for the worker to end (killed at the deadline); its exit code."""
        try:
            return self.proc.wait(timeout=max(deadline - time.monotonic(), 0.1))
        except subprocess.TimeoutExpired:
            return self.kill()
        finally:
            self.forget()

    def kill(self) -> int | None:
        """Kill the worker's process group and reap it; its exit code. Its start-up output
        stays readable until :meth:`forget`."""
        if self.owner != os.getpid():
            self.forget()
            return None
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            with contextlib.suppress(OSError):
                self.proc.kill()
        code = self.proc.wait()
        self.closed = True
        _WORKERS.discard(self)
        return code

    def close(self) -> None:
        """Ask the worker to stop, and kill it if it does not within QUIT_WAIT_S."""
        if self.closed:
            return
        if self.owner != os.getpid():
            self.forget()
            return
        with contextlib.suppress(OSError):
            self.sock.send(json.dumps({"quit": True}).encode())
        try:
            self.proc.wait(timeout=QUIT_WAIT_S)
        except subprocess.TimeoutExpired:
            self.kill()
        self.forget()

    def forget(self) -> None:
        """Drop this side's descriptors (a forked child's copies, or once the worker ended)."""
        self.closed = True
        with contextlib.suppress(OSError):
            self.sock.close()
        with contextlib.suppress(OSError, ValueError):
            self.startup.close()
        _WORKERS.discard(self)


# ---------------------------------------------------------------------- one per thread

_WORKERS: weakref.WeakSet[YadeWorker] = weakref.WeakSet()
_LOCAL = threading.local()


class _Slot:
    """A thread's place for its worker; when the thread ends it is collected and its
    finalizer closes the worker (also at the interpreter's exit)."""

    def __init__(self) -> None:
        self.box: list[YadeWorker] = []
        weakref.finalize(self, _close_box, self.box)


def _close_box(box: list[YadeWorker]) -> None:
    while box:
        box.pop().close()


def _slot() -> _Slot:
    slot = getattr(_LOCAL, "slot", None)
    if slot is None:
        slot = _LOCAL.slot = _Slot()
    return slot


def _forget_after_fork() -> None:
    """In a forked child: the parent's workers are not ours (their sockets are copies)."""
    for worker in list(_WORKERS):
        worker.forget()
    slot = getattr(_LOCAL, "slot", None)
    if slot is not None:
        slot.box.clear()


os.register_at_fork(after_in_child=_forget_after_fork)


def close_workers() -> None:
    """Close this thread's warm worker, if any (it is closed anyway when the thread ends)."""
    _close_box(_slot().box)


def run_scene(
    command: list[str],
    env: dict[str, str],
    scene_file: Path,
    out_file: Path,
    log_file: Path,
    timeout: float,
    warm: bool = True,
) -> str | None:
    """Run one scene in YADE; the reason it failed, or None.

    Parameters
    ----------
    command, env
        How to start the driver (:class:`YadeWorker`).
    log_file
        Where YADE's output for this scene goes (written as :mod:`rockyade.io.atomic` writes
        files: never through a link; replaced when the scene ends, however it ends).
    timeout
        Wall-clock limit of this scene, s (counting a worker's start when one is needed).
    warm
        Use this thread's warm worker (started if there is none); False: a worker of its
        own, closed after the scene (one process per scene).

    Raises
    ------
    OSError
        The log file could not be created (naming it).
    """
    deadline = time.monotonic() + timeout
    fd, tmp = create_temporary(log_file)
    try:
        os.fchmod(fd, file_mode())
        return _run_logged(command, env, scene_file, out_file, fd, deadline, timeout, warm)
    finally:
        os.close(fd)
        try:
            os.replace(tmp, log_file)
        except OSError:
            with contextlib.suppress(OSError):
                tmp.unlink()


def _run_logged(
    command: list[str],
    env: dict[str, str],
    scene_file: Path,
    out_file: Path,
    log_fd: int,
    deadline: float,
    timeout: float,
    warm: bool,
) -> str | None:
    box = _slot().box if warm else []
    try:
        for attempt in range(2):
            if box and not box[-1].alive():
                box.pop().forget()
            try:
                if not box:
                    box.append(YadeWorker(command, env, deadline, timeout))
                return box[-1].run(scene_file, out_file, log_fd, deadline, timeout)
            except WorkerLostError as exc:
                box.clear()
                _copy(exc.output, log_fd)
                return str(exc)
            except OSError:  # the warm worker had died since its last scene: a fresh one, once
                box.clear()
                if attempt:
                    raise
        raise AssertionError("unreachable")
    finally:
        if not warm:
            _close_box(box)
        elif box and not box[-1].alive():
            box.pop().forget()


def _copy(text: str, fd: int) -> None:
    """Append ``text`` (a dead worker's last words) to the job's log."""
    if text:
        with contextlib.suppress(OSError):
            os.write(fd, text.encode())


__all__ = ["WorkerLostError", "YadeWorker", "close_workers", "run_scene"]
