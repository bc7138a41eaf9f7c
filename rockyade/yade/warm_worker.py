"""YADE kept warm: one YADE process runs many scenes, one after the other.

Starting YADE (Debian's Python, YADE's modules, numpy) costs 0.7-1.0 s, as much as the
simulation of a short single-block scene. A YADE worker is the driver
(:mod:`rockyade.yade.driver`) started once with ``--serve``: it takes a scene, runs it,
resets YADE (``O.reset()``: bodies, engines, materials, time step, periodic cell; and its
own recorder) and waits for the next. Results are the same, bit for bit, as one process
per scene (``tests/test_yade_worker.py``). The machinery (no port, dies with its parent,
timeout per scene, a crash costs one scene, samples flushed every FLUSH_PERIOD_S) is
:mod:`rockyade.io.warm_program`'s, shared with the Siconos backend; this module names YADE.
"""

from __future__ import annotations

from pathlib import Path

from rockyade.io import warm_program as _generic
from rockyade.io.warm_program import QUIT_WAIT_S, STOP_GRACE_S, Program, WorkerLostError
from rockyade.io.warm_program import Worker as YadeWorker

#: The program's name in reasons, and the key of its per-thread workers.
LABEL = "YADE"
#: A scene's samples so far are written every so many seconds while it runs (kept when the
#: worker is killed), s.
FLUSH_PERIOD_S = 30.0


def _slot() -> _generic._Slot:
    """This thread's place for its YADE worker."""
    return _generic.slot(LABEL)


def close_workers() -> None:
    """Close this thread's warm YADE worker, if any (it is closed anyway when the thread ends)."""
    _generic.close_workers(LABEL)


def run_scene(
    command: list[str],
    env: dict[str, str],
    scene_file: Path,
    out_file: Path,
    log_file: Path,
    timeout: float,
    warm: bool = True,
) -> str | None:
    """Run one scene in YADE; the reason it failed, or None (:func:`rockyade.io.warm_program.run_scene`)."""
    program = Program(command, env, LABEL, "--yade-timeout", FLUSH_PERIOD_S)
    return _generic.run_scene(program, scene_file, out_file, log_file, timeout, warm)


__all__ = [
    "FLUSH_PERIOD_S",
    "QUIT_WAIT_S",
    "STOP_GRACE_S",
    "WorkerLostError",
    "YadeWorker",
    "close_workers",
    "run_scene",
]
