"""A program kept warm: one process of another Python runs many scenes, one after the other.

The backends that run inside another program's Python (YADE's driver,
:mod:`rockyade.yade.driver`; Siconos's, :mod:`rockyade.siconos.driver`) start once with
``--serve FD`` and take one scene after another; starting that Python and its modules costs
up to a second, as much as a short single-block scene. Each backend names its program
(``label``: "YADE", "Siconos") and how a user raises its timeout (``timeout_option``); this
module knows no program.

* **No port.** The worker talks over a socket pair (AF_UNIX, SOCK_SEQPACKET: no address,
  nothing listens); each job's log file goes to it as a descriptor (SCM_RIGHTS), opened
  here as :mod:`rockyade.io.atomic` opens files (a new file under a random name, never
  through a link), and renamed onto the job's log when the job ends.
* **Dies with its parent.** Its own session (a timeout kills its group) and
  ``PR_SET_PDEATHSIG``, which the driver asks for itself
  (:func:`rockyade.io.driver_loop.die_with_parent`): the kernel kills it when the thread
  that started it ends, however the process ends. No Python runs between fork and exec
  (no ``preexec_fn``): there it could deadlock on a lock another thread held at the fork.
  Each thread therefore keeps its own worker per program (:func:`run_scene`); a thread
  that ends closes them; a forked child forgets its parent's.
* **Timeout per scene.** Each scene has its own wall-clock limit (counting a worker's
  start when one is needed). The driver stops the scene at that deadline itself and writes
  the samples it has (the worker goes on to the next scene); a worker that has not answered
  STOP_GRACE_S later is killed and the next scene starts a fresh one. While a scene runs its
  samples so far are written every ``flush_s`` seconds, so a killed scene keeps them too.
* **A crash costs one scene.** A worker that dies (a crash, a signal) or whose scene
  raised fails that scene only; the next starts a fresh worker.
* **Nothing left behind.** The worker's start-up output goes to an anonymous file.

The protocol the driver speaks is its loop's, :mod:`rockyade.io.driver_loop` (one module for
every driver): it says ``{"ready": true, "pid": ...}``, then takes jobs ``{"scene", "out",
"deadline", "flush_s"}`` with the log's descriptor, and answers ``{"ok": true}``
(``"timeout": true`` when stopped at the deadline), ``{"ok": false, "errno", "strerror",
"path"}`` (its output could not be written) or ``{"ok": false}`` and exits (its scene
raised); it stops on ``{"quit": true}``.
"""

from __future__ import annotations

import collections
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
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from rockyade.errors import InputError, os_error_message
from rockyade.io.atomic import create_temporary, file_mode
from rockyade.io.driver_loop import MESSAGE_BYTES, PARENT_VARIABLE

#: Seconds a worker has to stop after ``quit`` before it is killed.
QUIT_WAIT_S = 5.0
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


@contextlib.contextmanager
def sigint_held_back() -> Iterator[None]:
    """Hold SIGINT back from this thread while it forks a worker. The worker inherits the
    blocked signal through exec: in a session of its own, it never takes Ctrl-C (its parent
    decides). In this process a Ctrl-C meanwhile goes to another thread, or waits for this one
    to unblock it. (Before, the child ran Python between fork and exec, a ``preexec_fn``,
    where a Ctrl-C ran this process's handler in the child: "Exception ignored in: <bound
    method Random.seed ...>". No Python runs there now.)"""
    try:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    except (AttributeError, OSError, ValueError):  # no per-thread masks here
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _timeout_reason(timeout: float, label: str, option: str) -> str:
    return f"timeout: {label} did not finish within {timeout:.6g} s and was stopped (raise it with {option})"


def error_line(text: str) -> str:
    """The last line that names an error ("" when there is none: a banner is not a reason)."""
    for line in reversed([ln.strip() for ln in text.splitlines() if ln.strip()]):
        if "Error" in line or "Exception" in line:
            return line
    return ""


class Worker:
    """One process that runs scenes on request (module docstring).

    Parameters
    ----------
    command
        The driver's command line without ``--serve FD`` (the program's Python and the driver).
    env
        Its environment.
    deadline
        ``time.monotonic()`` by which it must be ready.
    timeout
        The scene's timeout, s (for the reason when it passes).
    label, timeout_option
        The program's name and the option that raises its timeout, for the reasons given.

    Raises
    ------
    WorkerLostError
        It did not start (the reason names its last error line) or not in time.
    """

    def __init__(
        self,
        command: list[str],
        env: dict[str, str],
        deadline: float,
        timeout: float,
        label: str,
        timeout_option: str,
    ) -> None:
        self.label, self.timeout_option = label, timeout_option
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        # its output outside jobs: a file unlinked at once, nothing to leave behind
        self.startup: IO[bytes] = tempfile.TemporaryFile()  # noqa: SIM115 - lives as long as the worker
        self.owner = os.getpid()
        self.sock = ours
        self.closed = False
        try:
            with sigint_held_back():
                self.proc = subprocess.Popen(
                    [*command, "--serve", str(theirs.fileno())],
                    stdin=subprocess.DEVNULL,
                    stdout=self.startup,
                    stderr=subprocess.STDOUT,
                    env={**env, PARENT_VARIABLE: str(os.getpid())},
                    pass_fds=(theirs.fileno(),),
                    start_new_session=True,  # a group of its own: a timeout kills it and its children
                )
        except BaseException:
            ours.close()
            self.startup.close()
            raise
        finally:
            theirs.close()
        _WORKERS.add(self)
        STARTED[label] += 1
        try:
            hello = self._receive(deadline, timeout)
        except WorkerLostError:
            raise
        except BaseException:
            self.kill()
            self.forget()
            raise
        if not hello.get("ready"):
            raise self._lost(f"{self.label} did not start: unexpected first message {hello!r}")
        self.pid = int(hello["pid"])

    # ------------------------------------------------------------------ messages

    def _receive(self, deadline: float, timeout: float) -> dict[str, Any]:
        """The next message; WorkerLostError when the worker ends or the deadline passes."""
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise self._lost(_timeout_reason(timeout, self.label, self.timeout_option))
        self.sock.settimeout(remaining)
        try:
            data = self.sock.recv(MESSAGE_BYTES)
        except TimeoutError:
            raise self._lost(_timeout_reason(timeout, self.label, self.timeout_option)) from None
        except OSError as exc:
            data = b""
            note = f" ({exc})"
        else:
            note = ""
        if not data:
            raise self._lost(f"{self.label} exited with code {{code}}{note}")
        return json.loads(data)

    def _lost(self, reason: str) -> WorkerLostError:
        """Kill and reap the worker (at once if it ended already); the error saying why it is
        lost (``{code}`` in ``reason``: its exit code), with its last error line."""
        code = self.kill()
        output = self.startup_text()
        self.forget()
        detail = error_line(output)
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

    def run(
        self, scene_file: Path, out_file: Path, log_fd: int, deadline: float, timeout: float, flush_s: float = 30.0
    ) -> str | None:
        """Run one scene; the reason it failed, or None. Its stdout and stderr go to ``log_fd``.

        Raises
        ------
        WorkerLostError
            The worker ended (the reason is the scene's failure); it is not used again.
        """
        # the deadline as time.monotonic() gives it: CLOCK_MONOTONIC, one clock for every process
        job = {"scene": str(scene_file), "out": str(out_file), "deadline": deadline, "flush_s": flush_s}
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
        except BaseException:  # Ctrl-C or any other interruption: never leave the worker running
            self.kill()
            self.forget()
            raise
        if reply.get("ok"):  # done, or stopped at its deadline with its samples written
            return _timeout_reason(timeout, self.label, self.timeout_option) if reply.get("timeout") else None
        if "errno" in reply:  # it could not write its output (its partial file removed)
            error = OSError(reply["errno"], reply.get("strerror") or "", reply.get("path"))
            return f"{self.label} could not write its output: {os_error_message(error)}"
        code = self.wait_exit(deadline)  # a scene that raised: the worker ends
        return f"{self.label} exited with code {code}"

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

_WORKERS: weakref.WeakSet[Worker] = weakref.WeakSet()
_LOCAL = threading.local()
#: Workers this process started, by program (what ran here: the test suite's gate reads it).
STARTED: collections.Counter[str] = collections.Counter()


class _Slot:
    """A thread's place for its worker of one program; when the thread ends it is collected
    and its finalizer closes the worker (also at the interpreter's exit)."""

    def __init__(self) -> None:
        self.box: list[Worker] = []
        weakref.finalize(self, _close_box, self.box)


def _close_box(box: list[Worker]) -> None:
    while box:
        box.pop().close()


def slot(label: str) -> _Slot:
    """This thread's place for its worker of program ``label``."""
    slots = getattr(_LOCAL, "slots", None)
    if slots is None:
        slots = _LOCAL.slots = {}
    if label not in slots:
        slots[label] = _Slot()
    return slots[label]


def _forget_after_fork() -> None:
    """In a forked child: the parent's workers are not ours (their sockets are copies)."""
    for worker in list(_WORKERS):
        worker.forget()
    for one in getattr(_LOCAL, "slots", {}).values():
        one.box.clear()


os.register_at_fork(after_in_child=_forget_after_fork)


def close_workers(label: str) -> None:
    """Close this thread's warm worker of program ``label``, if any (it is closed anyway
    when the thread ends)."""
    _close_box(slot(label).box)


@dataclass(frozen=True)
class Program:
    """How to start one program's driver and name it in reasons.

    Attributes
    ----------
    command, env
        The driver's command line (without ``--serve FD``) and environment.
    label
        Its name in reasons ("YADE", "Siconos"); also the key of the per-thread workers.
    timeout_option
        The option that raises its timeout, named in a timeout's reason.
    flush_s
        Its samples so far are written every so many seconds of a scene, s.
    """

    command: list[str]
    env: dict[str, str]
    label: str
    timeout_option: str
    flush_s: float = 30.0


def run_scene(
    program: Program,
    scene_file: Path,
    out_file: Path,
    log_file: Path,
    timeout: float,
    warm: bool = True,
) -> str | None:
    """Run one scene in ``program``; the reason it failed, or None.

    Parameters
    ----------
    program
        How to start the driver (:class:`Worker`).
    log_file
        Where the program's output for this scene goes (written as :mod:`rockyade.io.atomic`
        writes files: never through a link; replaced when the scene ends, however it ends).
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
        return _run_logged(program, scene_file, out_file, fd, deadline, timeout, warm)
    finally:
        os.close(fd)
        try:
            os.replace(tmp, log_file)
        except OSError:
            with contextlib.suppress(OSError):
                tmp.unlink()


def _run_logged(
    program: Program,
    scene_file: Path,
    out_file: Path,
    log_fd: int,
    deadline: float,
    timeout: float,
    warm: bool,
) -> str | None:
    box = slot(program.label).box if warm else []
    try:
        for attempt in range(2):
            if box and not box[-1].alive():
                box.pop().forget()
            try:
                if not box:
                    box.append(
                        Worker(program.command, program.env, deadline, timeout, program.label, program.timeout_option)
                    )
                return box[-1].run(scene_file, out_file, log_fd, deadline, timeout, program.flush_s)
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


#: The longest timeout a user may give a run, s (30 days).
MAX_TIMEOUT_S = 30 * 86400.0


def check_timeout(timeout_s: float | None, field: str = "timeout_s") -> float | None:
    """A user timeout of a run in a worker (YADE, Siconos): None (the program's default) or a
    number of seconds in (0, MAX_TIMEOUT_S].

    Raises
    ------
    InputError
        Not a positive finite number of seconds within the limit, naming ``field``.
    """
    if timeout_s is None:
        return None
    try:
        value = float(timeout_s)
    except (TypeError, ValueError):
        raise InputError(field, f"must be a number of seconds, got {timeout_s!r}") from None
    if not (0.0 < value <= MAX_TIMEOUT_S):
        raise InputError(field, f"must be in (0, {MAX_TIMEOUT_S:g}] s, got {timeout_s!r}")
    return value


__all__ = [
    "MAX_TIMEOUT_S",
    "STARTED",
    "Program",
    "Worker",
    "WorkerLostError",
    "check_timeout",
    "close_workers",
    "error_line",
    "run_scene",
    "slot",
]
