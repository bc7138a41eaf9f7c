"""A warm starter for the documented commands: a Python that has imported rockyade and its
libraries once, and runs each command in a fresh process forked from itself.

The docs' tests run ~100 commands as printed. Started one by one, each process spends about
two seconds importing numpy, scipy, pandas, matplotlib, numba and rockyade before it does
anything; forked from this process, a command starts with those imports done and otherwise runs
as it would from a shell: its own process (its own signal handlers, environment, working folder
and exit code), ``rockyade.cli.main`` as the console script calls it, stdout and stderr
to files, Python's normal exit (threads joined, ``atexit`` run). The starter loads the single-threaded
kernels (a tiny run of each) and starts no thread of its own before it forks (its libraries start
idle ones on import: BLAS pools, one more under ``make test``'s one-thread settings).

Protocol (one JSON object a line): the test writes a request on stdin ``{"kind": "rockyade" |
"script" | "code", "argv": [...], "code": str, "cwd": str, "env": {...} | null, "stdout": path,
"stderr": path}`` and reads ``{"pid": n}`` when the command starts, then ``{"returncode": n,
"cpu_s": x}`` when it ends (the CPU seconds of the command and of the processes it waited for).
Run as a script: ``python tests/command_server.py``."""

from __future__ import annotations

import atexit
import gc
import importlib
import json
import os
import runpy
import signal
import sys
import threading
import time
import traceback
from typing import TextIO

import numpy as np

#: What a rockyade command imports before its first line of work (measured with
#: ``python -X importtime``): loaded here once, shared by every forked command.
PRELOAD = (
    "numpy",
    "scipy.optimize",
    "scipy.interpolate",
    "scipy.sparse",
    "scipy.stats",
    "pandas",
    "matplotlib",
    "matplotlib.pyplot",
    "numba",
    "rockyade.cli",
    "rockyade.solvers.reference",
    "rockyade.solvers.housner",
    "rockyade.motion",
    "rockyade.scene",
    "rockyade.calibration.model_stage",
    "rockyade.dem.model_from_scene",
    "rockyade.runner",
    "rockyade.result",
)


#: The folder of the console scripts: first on ``sys.path`` as in ``.venv/bin/rockyade``.
BIN = os.path.dirname(sys.executable)


def _preload() -> None:
    for name in PRELOAD:
        importlib.import_module(name)
    import rockyade.cli

    rockyade.cli.build_parser()  # imports every command's module (each registers its options)
    _load_kernels()


def _load_kernels() -> None:
    """Load the solvers' single-threaded numba code from numba's cache (``make test`` compiled
    it): numba's first use in a process sets up its typing and code-generation registries (and
    imports scipy's BLAS), ~0.3 CPU-s, then each kernel's loading; done here once, a forked
    command finds them loaded. The runs stepped together (:mod:`rockyade.kernel.runs`) are left
    out: they run on numba's threads, and this process starts none before it forks."""
    from rockyade.dem.engine import warm_up
    from rockyade.housner.integrator import warm_up as warm_housner
    from rockyade.motion.spectra import response_spectrum
    from rockyade.twoblock import warm_up as warm_twoblock

    threads = len(os.listdir("/proc/self/task"))  # the BLAS libraries' own, where not set to one
    warm_up()  # the general loop
    warm_up(single=True)
    warm_housner()
    warm_twoblock()
    response_spectrum(np.array([0.0, 1.0, 0.0]), 0.025, np.array([0.5]))
    started = len(os.listdir("/proc/self/task")) - threads
    if started:  # a thread would not survive the fork, and whatever it holds would stay held
        raise RuntimeError(
            f"loading the kernels started {started} thread(s) in the command starter; it must start none"
        )


def _run(request: dict) -> int:
    """The forked command's body; returns its exit code (never raises)."""
    try:
        os.chdir(request["cwd"])
        if request.get("env") is not None:
            os.environ.clear()
            os.environ.update(request["env"])
        kind = request["kind"]
        if kind == "rockyade":
            import rockyade.cli

            rockyade.cli._T0 = time.perf_counter()  # the process's start, as the console script's
            sys.argv = [os.path.join(BIN, "rockyade"), *request["argv"]]
            return int(rockyade.cli.main(request["argv"]) or 0)
        if kind == "script":
            sys.argv = list(request["argv"])
            sys.path[0] = os.path.dirname(os.path.abspath(sys.argv[0]))
            runpy.run_path(sys.argv[0], run_name="__main__")
            return 0
        sys.argv = ["-c"]
        sys.path[0] = ""
        exec(compile(request["code"], "<string>", "exec"), {"__name__": "__main__"})
        return 0
    except SystemExit as exc:
        code = exc.code
        if code is None or isinstance(code, int):
            return int(code or 0)
        print(code, file=sys.stderr)
        return 1
    except BaseException:
        traceback.print_exc()
        return 1


def _child(request: dict, pipes: tuple[TextIO, TextIO]) -> None:
    """In the forked process: stdio to the request's files, the starter's pipes closed, the
    command run, then Python's own exit."""
    for pipe in pipes:
        pipe.close()
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.close(devnull)
    for fd, key in ((1, "stdout"), (2, "stderr")):
        out = os.open(request[key], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(out, fd)
        os.close(out)
    code = _run(request)
    # Python's exit, less the freeing of every object (which would copy each page shared with
    # the starter): threads joined, atexit handlers run, streams flushed
    threading._shutdown()  # type: ignore[attr-defined]
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            code = code or 120  # as Python's own exit when its streams cannot be flushed
    os._exit(code)


def main() -> None:
    # the protocol on their own descriptors: nothing a command prints can reach them
    sys.path[0] = BIN  # not this file's folder (tests/): as the console script's
    requests, replies = os.dup(0), os.dup(1)
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.dup2(2, 1)
    _preload()
    gc.freeze()  # what the imports made stays out of the collector: no forked command copies it
    reader = os.fdopen(requests, "r")
    writer = os.fdopen(replies, "w")
    writer.write(json.dumps({"ready": True}) + "\n")
    writer.flush()
    for line in reader:
        request = json.loads(line)
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            _child(request, (reader, writer))
        writer.write(json.dumps({"pid": pid}) + "\n")
        writer.flush()
        _, status, usage = os.wait4(pid, 0)
        cpu_s = usage.ru_utime + usage.ru_stime  # the command's and its children's
        writer.write(json.dumps({"returncode": os.waitstatus_to_exitcode(status), "cpu_s": cpu_s}) + "\n")
        writer.flush()


if __name__ == "__main__":
    main()
