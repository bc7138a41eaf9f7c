"""The backend of an engine that runs in another Python, written once: YADE's
(:mod:`rockyade.yade.backend`) and Siconos's (:mod:`rockyade.siconos.backend`) fill it in.

Such an engine has a driver, run by the engine's Python in a worker process kept warm between
runs (:mod:`rockyade.io.warm_program`: no port, a deadline per run, a crash costs one scene;
the driver's side is :mod:`rockyade.io.driver_loop`). Its backend, a :class:`WorkerBackend`:

1. refuses before any run a Python named by its variable (``ROCKYADE_<ENGINE>_PYTHON``) that
   is not an executable file or cannot import the engine (InputError naming the variable),
   and an engine that is not installed (SolverUnavailableError);
2. writes the scene's data (JSON) and runs it under a timeout (:meth:`WorkerBackend.run`), its
   files where :mod:`rockyade.io.run_files` puts them (one way for every engine);
3. reads the output back (:meth:`WorkerBackend.parse`, with :mod:`rockyade.dem.worker_result`
   and :class:`rockyade.dem.worker_output.WorkerOutput`): a crash, a timeout, an exception
   inside the engine, an output it could not write, a missing, partial, unstable or
   energy-creating output, or a problem of the engine's own give a Result with status
   ``failed``, the reason, the log path and the samples recorded up to there (``partial:
   true``), never one that looks complete.

An engine fills in its names (``solver``, ``label``, ``python_variable``,
``debian_package``, ``seconds_per_body_step`` of its default timeout) and the hooks
:meth:`~WorkerBackend.program`, :meth:`~WorkerBackend.needs`, :meth:`~WorkerBackend.probe`,
:meth:`~WorkerBackend.version`, and, where it has them, :meth:`~WorkerBackend.unstable_reason`,
:meth:`~WorkerBackend.engine_problem`, :meth:`~WorkerBackend.engine_meta` and
:meth:`~WorkerBackend.rescue` with :meth:`~WorkerBackend.rescued_meta` (docs/architecture.md, "How
to add a solver").
"""

from __future__ import annotations

import abc
import contextlib
import dataclasses
import functools
import json
import math
import os
import subprocess
import time
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import ClassVar

import numpy as np

from rockyade import __version__
from rockyade.dem import worker_result
from rockyade.dem.model import DemModel
from rockyade.dem.result_frames import worker_frame
from rockyade.dem.worker_output import WorkerOutput
from rockyade.errors import InputError, SolverUnavailableError, os_error_message
from rockyade.io import run_files
from rockyade.io.atomic import write_text
from rockyade.io.warm_program import Program, check_timeout, error_line, run_scene
from rockyade.result import Result, failed_result
from rockyade.run_meta import RunMeta

#: Default timeout of a run: this start-up allowance plus the engine's seconds per body-step ...
TIMEOUT_STARTUP_S = 60.0
#: ... capped here unless a larger one is asked for (``--yade-timeout``, ``timeout_s``).
TIMEOUT_CAP_S = 3600.0
#: What a worker's output file cannot be read for.
UNREADABLE = (OSError, ValueError, KeyError, zipfile.BadZipFile)
#: Seconds a Python named by a variable has to show that it imports its engine ...
PROBE_TIMEOUT_S = 120.0
#: ... by printing this.
PROBE_ANSWER = "rockyade-engine-ok"

Arrays = dict[str, np.ndarray]
#: A run's metadata from what its driver said (:meth:`WorkerBackend.run_meta` with the rest bound).
MetaOf = Callable[[WorkerOutput], dict[str, object]]


class WorkerBackend(abc.ABC):
    """An engine run by its driver in a warm worker (module docstring); an engine subclasses it.

    Attributes
    ----------
    solver
        The solver's name in Results ("yade"); the files' tag is ``.<solver>``.
    label
        The engine's name in reasons ("YADE").
    python_variable
        The environment variable that names another Python for the engine.
    debian_package
        What to install for it.
    seconds_per_body_step
        The default timeout's seconds per body-step (:meth:`timeout`).
    """

    solver: ClassVar[str]
    label: ClassVar[str]
    python_variable: ClassVar[str]
    debian_package: ClassVar[str]
    seconds_per_body_step: ClassVar[float]

    # ------------------------------------------------------------------ the hooks

    @abc.abstractmethod
    def program(self) -> Program:
        """How to start the driver: its command, environment and names in reasons."""

    @abc.abstractmethod
    def needs(self) -> list[Path]:
        """The engine's Python and the files of the engine it needs."""

    @abc.abstractmethod
    def probe(self) -> list[str]:
        """A command of the engine's Python that imports the engine (run once for a Python named
        by ``python_variable``), printing PROBE_ANSWER."""

    @abc.abstractmethod
    def version(self, meta: WorkerOutput) -> str:
        """The engine's version as a Result records it."""

    def missing(self) -> str | None:
        """Why the engine cannot run here (what to install), or None."""
        needs = self.needs()
        if all(path.is_file() for path in needs):
            return None
        return (
            f"{self.label} is not installed (looked for {' and '.join(map(str, needs))}): apt-get install -y "
            f"--no-install-recommends {self.debian_package}, or set {self.python_variable} to the Python that runs it"
        )

    def unstable_reason(self, meta: WorkerOutput) -> str:
        """What a run the driver ended ``failed`` (or whose state is not finite) says."""
        why = meta.failure_reason or "non-finite state or runaway speed"
        return f"numerical instability in {self.label} at t = {meta.stop_time_s} s ({why})"

    def engine_problem(self, model: DemModel, meta: WorkerOutput, arrays: Arrays) -> str | None:
        """Why a complete, stable output is not a result by the engine's own checks, or None."""
        return None

    def engine_meta(self, model: DemModel, meta: WorkerOutput) -> dict[str, object]:
        """The engine's own fields of the Result's metadata."""
        return {}

    def rescue(self, model: DemModel, meta: WorkerOutput, arrays: Arrays, problem: str) -> int | None:
        """How many samples to keep as a result instead of failing for ``problem`` (YADE: an
        assembly collapsing up to a deep overlap), or None; :meth:`rescued_meta` then says how
        the run ended."""
        return None

    def rescued_meta(self, model: DemModel, meta: WorkerOutput, arrays: Arrays, run_meta: MetaOf) -> dict[str, object]:
        """The metadata of a rescued run, ``arrays`` cut to the samples kept (``run_meta(m)``:
        :meth:`run_meta` of a run whose driver said ``m``)."""
        return run_meta(meta)

    # ------------------------------------------------------------------ running

    def timeout(self, timeout_s: float | None, body_steps: float) -> float:
        """A run's wall-clock limit, s: ``timeout_s`` checked (in (0, MAX_TIMEOUT_S]), or
        TIMEOUT_STARTUP_S plus ``seconds_per_body_step`` per body-step, capped at TIMEOUT_CAP_S."""
        checked = check_timeout(timeout_s, "timeout_s")
        if checked is not None:
            return checked
        return min(TIMEOUT_STARTUP_S + self.seconds_per_body_step * body_steps, TIMEOUT_CAP_S)

    def check_variable(self) -> None:
        """Refuse a Python named by ``python_variable`` that is not an executable file or cannot
        import the engine (:func:`check_python`; nothing to check when the variable is unset).

        Raises
        ------
        InputError
            Naming the variable.
        """
        if os.environ.get(self.python_variable):
            program = self.program()
            check_python(
                self.python_variable, program.command[0], tuple(self.probe()), tuple(sorted(program.env.items()))
            )

    def check_installed(self) -> None:
        """Refuse a bad Python named by ``python_variable`` and a missing engine (module docstring).

        Raises
        ------
        InputError
            The variable names no executable file, or a Python that cannot import the engine.
        SolverUnavailableError
            The engine is not installed.
        """
        self.check_variable()
        why = self.missing()
        if why is not None:
            raise SolverUnavailableError(why)

    def run(
        self,
        model: DemModel,
        payload: dict[str, object],
        *,
        name: str,
        body_steps: float,
        timeout_s: float | None = None,
        workdir: str | Path | None = None,
        failed_dir: str | Path | None = None,
        lowpass: float | None = None,
        warm: bool = True,
        extra: dict[str, object] | None = None,
    ) -> Result:
        """Run ``payload`` (the model as the driver's JSON data) and return a Result (status
        ``failed`` on any failure).

        Parameters
        ----------
        name
            The files' stem (:mod:`rockyade.io.run_files`).
        body_steps
            The run's time steps times its bodies (the default timeout).
        timeout_s
            Wall-clock limit, s (default :meth:`timeout`).
        workdir, failed_dir
            Where the run's files are kept after every run, after a failed run only.
        lowpass
            Optional zero-phase low-pass of the output accelerations, Hz.
        warm
            Run in this thread's warm worker; False: in a process of its own.
        extra
            More metadata for the Result.
        """
        self.check_installed()
        timeout = self.timeout(timeout_s, body_steps)
        files = run_files.start(self.solver, name, f".{self.solver}", workdir)
        scene_file, out_file, log_file = (files.working(s) for s in run_files.SUFFIXES)
        start = time.perf_counter()
        try:
            # compact and not synced: the driver reads it at once, and a run that did not end is run again
            write_text(scene_file, json.dumps(payload, sort_keys=True) + "\n", durable=False)
            reason = run_scene(self.program(), scene_file, out_file, log_file, timeout, warm)
        except OSError as exc:  # a full disk: the run fails naming the file
            error = exc if exc.filename else OSError(exc.errno, exc.strerror, str(scene_file))
            reason = f"cannot write {os_error_message(error)}"
        except BaseException:  # Ctrl-C: an interrupted run leaves none of its files
            files.discard()
            raise
        total = time.perf_counter() - start
        if reason is not None:
            files.working(".npz.part").unlink(missing_ok=True)  # a worker killed while writing
        result = self.parse(model, out_file, reason, log_file, total, lowpass, {"timeout_s": timeout, **(extra or {})})
        log = files.keep(result.ok, workdir, failed_dir)
        result.meta = dataclasses.replace(result.meta, log_path=None if log is None else str(log))
        return result

    # ------------------------------------------------------------------ reading

    def parse(
        self,
        model: DemModel,
        out_file: Path,
        reason: str | None,
        log_file: Path,
        total: float,
        lowpass: float | None,
        extra: dict[str, object] | None = None,
    ) -> Result:
        """The driver's output file as a Result, or a failed Result saying why there is none
        (with the samples it wrote, when it wrote some).

        Parameters
        ----------
        reason
            Why the worker failed (None: the scene ran to its end).
        total
            Wall time of the whole worker call, s.
        lowpass
            Optional zero-phase low-pass of the output accelerations, Hz.
        extra
            More metadata for the Result.
        """
        extra = {"log_path": str(log_file), "total_time_s": total, **(extra or {})}
        if reason is None and not out_file.is_file():
            reason = f"{self.label} wrote no output file"
        if reason is not None:
            detail = worker_result.last_error_line(log_file)
            reason = f"{reason}: {detail}" if detail and detail not in reason else reason
            kept = None
            with contextlib.suppress(*UNREADABLE):
                kept = worker_result.read_output(out_file)
            if kept is not None:  # a timeout or a lost worker after a flush: the samples it wrote
                return self._partial_failure(model, *kept, reason, total, extra)
            return failed_result(self.solver, model.scene_hash, reason, wall_time_s=total, partial=False, **extra)
        try:
            meta, arrays = worker_result.read_output(out_file)
        except UNREADABLE as exc:
            return failed_result(
                self.solver, model.scene_hash, f"unreadable {self.label} output {out_file.name}: {exc}", **extra
            )
        problem = self.problem(model, meta, arrays)
        keep = None if problem is None else self.rescue(model, meta, arrays, problem)
        if problem is not None and keep is None:
            return self._partial_failure(model, meta, arrays, problem, total, extra)
        if keep is not None:
            arrays = {k: v[:keep] for k, v in arrays.items()}
            out = self.rescued_meta(model, meta, arrays, lambda m: self.run_meta(model, m, total, extra, arrays))
            return Result(worker_frame(model, arrays, lowpass), RunMeta.from_dict(out))
        return Result(
            worker_frame(model, arrays, lowpass), RunMeta.from_dict(self.run_meta(model, meta, total, extra, arrays))
        )

    def problem(self, model: DemModel, meta: WorkerOutput, arrays: Arrays) -> str | None:
        """Why a complete-looking output is not a result: partial or short, unstable, created
        energy, then the engine's own checks (:meth:`engine_problem`); None when it is one."""
        incomplete = worker_result.incomplete_output(model, meta, arrays, self.label)
        if incomplete is not None:
            return incomplete
        if worker_result.unstable(meta, arrays):
            return self.unstable_reason(meta)
        blowup = worker_result.energy_problem(model, arrays, self.label)
        return blowup if blowup is not None else self.engine_problem(model, meta, arrays)

    def run_meta(
        self, model: DemModel, meta: WorkerOutput, total: float, extra: dict[str, object], arrays: Arrays
    ) -> dict[str, object]:
        """The Result's metadata: how the run ended, what ran, the engine's diagnostics."""
        return {
            "solver": self.solver,
            "version": f"{self.version(meta)}, rockyade {__version__} driver",
            **worker_result.shared_run_meta(model, meta, total, arrays),
            **self.engine_meta(model, meta),
            **extra,
        }

    def _partial_failure(
        self,
        model: DemModel,
        meta: WorkerOutput,
        arrays: Arrays,
        reason: str,
        total: float,
        extra: dict[str, object],
    ) -> Result:
        """A failed run that keeps what it recorded: status ``failed``, ``partial: true``, the
        samples it has (never read as complete: its status is ``failed``)."""
        n = min(meta.n_filled, arrays["pos"].shape[0])
        arrays = {k: v[:n] for k, v in arrays.items()}
        frame = None
        if n > 0 and meta.wall_time_s is not None:  # (an older driver's flush had no wall time)
            with contextlib.suppress(ValueError, FloatingPointError):  # samples too broken to derive accelerations
                frame = worker_frame(model, arrays, None)
        if frame is None:
            return failed_result(self.solver, model.scene_hash, reason, partial=True, wall_time_s=total, **extra)
        out = self.run_meta(model, dataclasses.replace(meta, status="failed"), total, extra, arrays)
        return Result(frame, RunMeta.from_dict(worker_result.failed_partially(out, reason, n)))


def body_payload(model: DemModel, i: int) -> dict[str, object]:
    """What every driver reads of body ``i`` (its payload adds the engine's own keys): its name,
    whether it is fixed, mass (kg) and centroidal inertia (kg m^2), contact polygon about its
    centroid (m), start (centroid m, angle rad, velocity m/s, angular velocity rad/s), rest and
    stop angles (rad; None: it never stops the run) and the point whose acceleration is
    recorded (m, from the centroid)."""
    b = model.bodies[i]
    stop = float(model.stop_angle_rad[i]) if model.stop_angle_rad is not None else 0.5 * math.pi
    return {
        "name": b.name,
        "fixed": bool(b.fixed),
        "mass_kg": b.mass_kg,
        "inertia_kgm2": b.inertia_kgm2,
        "vertices_m": b.contact_vertices_m.tolist(),
        "centroid0_m": model.pos0_m[i].tolist(),
        "angle0_rad": float(model.ang0_rad[i]),
        "rest_angle_rad": b.rest_angle_rad,
        "stop_angle_rad": stop if math.isfinite(stop) else None,
        "vel0_m_s": model.vel0_m_s[i].tolist(),
        "angvel0_rad_s": float(model.angvel0_rad_s[i]),
        "accel_point_m": list(b.accel_point_m),
    }


def worker_env(**changes: str | None) -> dict[str, str]:
    """A driver's environment: this one, with one OpenMP thread, no display (no GUI), no user
    site-packages, and ``changes`` (None: the variable removed)."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "PYTHONNOUSERSITE": "1"}
    env.pop("DISPLAY", None)
    for key, value in changes.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env


@functools.cache
def check_python(variable: str, python: str, probe: tuple[str, ...], env: tuple[tuple[str, str], ...]) -> None:
    """Refuse a Python named by ``variable`` that is not an executable file or whose ``probe``
    (its engine's import) fails; checked once per process.

    Raises
    ------
    InputError
        Naming ``variable``.
    """
    path = Path(python)
    if not path.is_file():
        raise InputError(variable, f"must name the Python that runs the engine, got {python!r}: no such file")
    if not os.access(path, os.X_OK):
        raise InputError(variable, f"must name the Python that runs the engine, got {python!r}: not executable")
    try:
        done = subprocess.run(
            [python, *probe], capture_output=True, text=True, env=dict(env), timeout=PROBE_TIMEOUT_S, check=False
        )
    except (OSError, subprocess.SubprocessError) as exc:
        raise InputError(variable, f"must name the Python that runs the engine, got {python!r}: {exc}") from None
    if done.returncode != 0 or PROBE_ANSWER not in done.stdout:
        said = error_line(done.stderr) or f"exit code {done.returncode}, no answer"
        raise InputError(variable, f"must name a Python that imports the engine, got {python!r}: {said}")


__all__ = [
    "PROBE_ANSWER",
    "TIMEOUT_CAP_S",
    "TIMEOUT_STARTUP_S",
    "WorkerBackend",
    "body_payload",
    "check_python",
    "worker_env",
]
