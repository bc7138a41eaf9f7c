"""Siconos's machinery: a scene run by Siconos (nonsmooth contact dynamics), parsed back.

The scene's DEM model (:func:`rockyade.calibration.model_stage.calibrated_model`: the blocks,
their contact polygons at b_eq and inertias from p, the ground motion, the loads, the
start) is written as JSON data (:mod:`rockyade.siconos.payload`) and run by
:mod:`rockyade.siconos.driver` in Debian's ``/usr/bin/python3`` (``python3-siconos``), as
a subprocess kept warm between runs (:mod:`rockyade.io.warm_program`, the machinery YADE's
backend uses: no listening socket, a timeout per run, a crash costs one scene, the log
kept beside the output). A failure of any kind (a crash, a timeout, an exception inside
Siconos, a non-finite state, a step the friction-contact solver could not converge, a
partial output) gives a Result with status ``failed``, the reason and the log path, and
the samples recorded up to there (``partial: true``): never one that looks complete.

Same role as :mod:`rockyade.yade.backend`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import json
import os
import shutil
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from rockyade import __version__
from rockyade.dem import worker_result
from rockyade.dem.model import DemModel
from rockyade.dem.result_frames import worker_frame
from rockyade.dem.worker_output import WorkerOutput
from rockyade.errors import SolverUnavailableError, os_error_message
from rockyade.io.atomic import write_text
from rockyade.io.warm_program import Program, keep_run_files, run_scene
from rockyade.io.warm_program import check_timeout as checked_timeout
from rockyade.result import Result, failed_result
from rockyade.run_meta import RunMeta
from rockyade.siconos.calibration import model_restitution
from rockyade.siconos.payload import Numerics, scene_payload

DRIVER = Path(__file__).resolve().parent / "driver.py"
SICONOS_PYTHON = os.environ.get("ROCKYADE_SICONOS_PYTHON", "/usr/bin/python3")
#: A file of Debian's python3-siconos the driver needs (the 2-D Bullet collision manager).
SICONOS_MODULE = Path(
    os.environ.get("ROCKYADE_SICONOS_MODULE", "/usr/lib/python3/dist-packages/siconos/mechanics/collision/bullet.py")
)
LABEL = "Siconos"
#: How a user raises a run's timeout: the command line's --yade-timeout bounds every solver with a
#: ``timeout_s`` (rockyade.cli.common.SOLVER_OPTION_FLAGS); in Python, SiconosSolver(timeout_s=...).
TIMEOUT_OPTION = "--yade-timeout (timeout_s in Python)"
#: Samples so far are written every so many seconds while a scene runs, s.
FLUSH_PERIOD_S = 30.0

#: Default timeout: start-up allowance plus this many seconds per body-step, capped.
TIMEOUT_STARTUP_S = 60.0
TIMEOUT_PER_BODY_STEP_S = 10e-3
TIMEOUT_CAP_S = 3600.0

#: A run fails when a step's friction-contact residual exceeds this (the solver stopped far
#: from a solution) ...
FAIL_RESIDUAL = 1e-4
#: ... or when more than this fraction of the solver's calls (and at least FAIL_UNCONVERGED_MIN
#: of them) end above its tolerance.
FAIL_UNCONVERGED_FRACTION = 0.01
FAIL_UNCONVERGED_MIN = 10


def siconos_available() -> bool:
    """True when Debian's python3-siconos and the Python that runs it are installed."""
    return Path(SICONOS_PYTHON).is_file() and SICONOS_MODULE.is_file()


#: The Debian package whose Siconos runs (its version is the one to cite: the module it ships
#: calls itself 4.5.0, in ``siconos.version`` and its egg-info, while the package is 4.4.0).
SICONOS_PACKAGE = "python3-siconos"


@functools.cache
def package_version() -> str | None:
    """The installed Debian package's version (``dpkg-query``), e.g. "4.4.0+dfsg-2"; None
    where dpkg does not know it (another installation, ``ROCKYADE_SICONOS_PYTHON``)."""
    try:
        done = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", SICONOS_PACKAGE], capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return (done.stdout.strip() or None) if done.returncode == 0 else None


def version_label(module_version: object) -> str:
    """What a Result records as Siconos's version: the Debian package's, and the module's own
    label when it says otherwise (``module_version``, as the driver reports it)."""
    package = package_version()
    module = str(module_version) if module_version not in (None, "") else "unknown"
    if package is None:
        return f"Siconos {module}"
    if package.split("+")[0] == module:
        return f"Siconos {package} (Debian {SICONOS_PACKAGE})"
    return f"Siconos {package} (Debian {SICONOS_PACKAGE}; its module calls itself {module})"


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["OMP_NUM_THREADS"] = "1"
    env.pop("DISPLAY", None)
    env["PYTHONNOUSERSITE"] = "1"
    env.pop("PYTHONPATH", None)  # Debian's Python with its own modules only
    return env


def default_timeout(n_steps: int, n_bodies: int) -> float:
    """Wall-clock limit of a run, s: TIMEOUT_STARTUP_S plus TIMEOUT_PER_BODY_STEP_S per
    body-step (measured on a loaded 2-core machine: 0.25-0.9 ms per body-step for a single
    block, 3-4 ms for a 33-block wall at rest, about 40 ms under a pulse: give such a run its
    own timeout_s), capped at TIMEOUT_CAP_S."""
    return min(TIMEOUT_STARTUP_S + TIMEOUT_PER_BODY_STEP_S * n_steps * n_bodies, TIMEOUT_CAP_S)


def check_timeout(timeout_s: float | None, field: str = "timeout_s") -> float | None:
    """A user timeout checked (:func:`rockyade.io.warm_program.check_timeout`, in (0, MAX_TIMEOUT_S] s)."""
    return checked_timeout(timeout_s, field)


def run_model(
    model: DemModel,
    numerics: Numerics,
    *,
    timeout_s: float | None = None,
    accel_lowpass_hz: float | None = None,
    warm: bool = True,
    workdir: str | Path | None = None,
    failed_dir: str | Path | None = None,
    name: str = "siconos",
    extra_meta: dict[str, object] | None = None,
) -> Result:
    """Run a model in Siconos and return a Result (status ``failed`` on any failure).

    Parameters
    ----------
    model
        The scene's DEM model (geometry, inertia, motion, loads, start).
    numerics
        Time step and solver settings.
    timeout_s
        Wall-clock limit, s (default :func:`default_timeout`).
    warm
        Run in this thread's warm worker; False: in a process of its own.
    workdir
        Where ``<name>.siconos.json``, ``.npz`` and ``.log`` are kept after every run.
    failed_dir
        Where they are kept after a failed run only (``run --out``'s folder; ignored with
        ``workdir``). The run itself works in a private temporary folder, removed after a
        successful run (unless ``workdir``) and when the run is interrupted (Ctrl-C); a failed
        run's files are moved to ``workdir`` or ``failed_dir``, or stay in that folder
        (``log_path`` says where).
    name
        The files' stem (the solver's: the scene hash or the caller's stem, and dt_factor).
    extra_meta
        More metadata for the Result (calibration, time-step choice).
    """
    if not siconos_available():
        raise SolverUnavailableError(
            f"Siconos is not installed (looked for {SICONOS_PYTHON} and {SICONOS_MODULE}): "
            "apt-get install -y --no-install-recommends python3-siconos, or set ROCKYADE_SICONOS_PYTHON"
        )
    n_steps = (model.n_samples - 1) * numerics.steps_per_sample
    timeout = check_timeout(timeout_s)
    timeout = timeout if timeout is not None else default_timeout(n_steps, len(model.bodies))
    destination = workdir if workdir is not None else failed_dir
    directory = Path(tempfile.mkdtemp(prefix="rockyade-siconos-")).resolve()
    scene_file = directory / f"{name}.siconos.json"
    out_file = directory / f"{name}.siconos.npz"
    log_file = directory / f"{name}.siconos.log"
    partial = directory / f"{name}.siconos.npz.part"
    payload = scene_payload(model, numerics)
    program = Program([SICONOS_PYTHON, str(DRIVER)], _env(), LABEL, TIMEOUT_OPTION, FLUSH_PERIOD_S)
    start = time.perf_counter()
    try:
        write_text(scene_file, json.dumps(payload, sort_keys=True) + "\n", durable=False)
        reason = run_scene(program, scene_file, out_file, log_file, timeout, warm)
    except OSError as exc:
        error = exc if exc.filename else OSError(exc.errno, exc.strerror, str(scene_file))
        reason = f"cannot write {os_error_message(error)}"
    except BaseException:  # Ctrl-C: an interrupted run leaves none of its files
        shutil.rmtree(directory, ignore_errors=True)
        raise
    total = time.perf_counter() - start
    if reason is not None:
        partial.unlink(missing_ok=True)
    extra: dict[str, object] = {
        "log_path": str(log_file),
        "total_time_s": total,
        "timeout_s": timeout,
        "restitution_e": numerics.restitution,
        "solver_tol": numerics.solver_tol,
        "solver_max_iter": numerics.solver_max_iter,
        "newton_max_iter": numerics.newton_max_iter,
        "friction_laws": payload["laws"],
        "friction_solver": numerics.friction_solver,
        "vertex_disk_radius_m": payload["disk_radius_m"],
        "dt_s": numerics.dt_s,
        **(extra_meta or {}),
    }
    result = _parse(model, numerics, out_file, reason, log_file, total, accel_lowpass_hz, extra)
    if result.ok and workdir is None:
        shutil.rmtree(directory, ignore_errors=True)
    elif destination is not None:
        into = Path(destination).resolve()
        try:
            into.mkdir(parents=True, exist_ok=True)
            log = keep_run_files(directory, name, name, ".siconos", result.ok, into)
            result.meta = dataclasses.replace(result.meta, log_path=str(log))
        except OSError:  # the folder cannot take them: they stay where they are (log_path says so)
            pass
        else:
            shutil.rmtree(directory, ignore_errors=True)
    return result


def _parse(
    model: DemModel,
    numerics: Numerics,
    out_file: Path,
    reason: str | None,
    log_file: Path,
    total: float,
    lowpass: float | None,
    extra: dict[str, object],
) -> Result:
    """The driver's output as a Result, or a failed Result saying why (with its samples)."""
    if reason is None and not out_file.is_file():
        reason = "Siconos wrote no output file"
    if reason is not None:
        detail = worker_result.last_error_line(log_file)
        reason = f"{reason}: {detail}" if detail and detail not in reason else reason
        kept = None
        with contextlib.suppress(OSError, ValueError, KeyError, zipfile.BadZipFile):
            kept = worker_result.read_output(out_file)
        if kept is not None:
            return _partial_failure(model, numerics, kept[0], kept[1], reason, total, extra)
        return failed_result("siconos", model.scene_hash, reason, wall_time_s=total, partial=False, **extra)
    try:
        meta, arrays = worker_result.read_output(out_file)
    except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:
        return failed_result("siconos", model.scene_hash, f"unreadable Siconos output {out_file.name}: {exc}", **extra)
    problem = _output_problem(model, meta, arrays)
    if problem is not None:
        return _partial_failure(model, numerics, meta, arrays, problem, total, extra)
    return Result(
        worker_frame(model, arrays, lowpass), RunMeta.from_dict(_run_meta(model, numerics, meta, total, extra, arrays))
    )


def _output_problem(model: DemModel, meta: WorkerOutput, arrays: dict[str, np.ndarray]) -> str | None:
    """Why a complete-looking output is not a result, or None."""
    incomplete = worker_result.incomplete_output(model, meta, arrays, "Siconos")
    if incomplete is not None:
        return incomplete
    if worker_result.unstable(meta, arrays):
        why = meta.failure_reason or "non-finite state or runaway speed"
        return f"numerical instability in Siconos at t = {meta.stop_time_s} s ({why})"
    calls = meta.solver_calls
    bad = meta.unconverged_steps
    if meta.max_residual > FAIL_RESIDUAL or (bad >= FAIL_UNCONVERGED_MIN and bad > FAIL_UNCONVERGED_FRACTION * calls):
        return (
            f"Siconos did not converge: {bad} of {calls} friction-contact solves ended above the tolerance "
            f"(largest residual {meta.max_residual:.3g}, "
            f"first at t = {meta.first_unconverged_s} s); "
            "try a smaller dt_factor or more solver iterations"
        )
    return worker_result.energy_problem(model, arrays, "Siconos")


def _partial_failure(
    model: DemModel,
    numerics: Numerics,
    meta: WorkerOutput,
    arrays: dict[str, np.ndarray],
    reason: str,
    total: float,
    extra: dict[str, object],
) -> Result:
    """A failed run that keeps what it recorded: status ``failed``, ``partial: true``."""
    n = min(meta.n_filled, arrays["pos"].shape[0])
    if n == 0:
        return failed_result("siconos", model.scene_hash, reason, partial=True, wall_time_s=total, **extra)
    arrays = {k: v[:n] for k, v in arrays.items()}
    frame = worker_frame(model, arrays, None)
    out = _run_meta(model, numerics, dataclasses.replace(meta, status="failed"), total, extra, arrays)
    return Result(frame, RunMeta.from_dict(worker_result.failed_partially(out, reason, n)))


def _run_meta(
    model: DemModel,
    numerics: Numerics,
    meta: WorkerOutput,
    total: float,
    extra: dict[str, object],
    arrays: dict[str, np.ndarray],
) -> dict[str, object]:
    """The Result's metadata: how the run ended, what ran, and Siconos's own diagnostics."""
    calls = meta.solver_calls
    return {
        "solver": "siconos",
        "version": f"{version_label(meta.version)}, rockyade {__version__} driver",
        **worker_result.shared_run_meta(model, meta, total, arrays),
        "n_steps": meta.steps,
        "solver_calls": calls,
        "solver_iterations": meta.solver_iterations,
        "solver_iterations_mean": (meta.solver_iterations / calls) if calls else 0.0,
        "unconverged_steps": meta.unconverged_steps,
        "retried_steps": meta.retried_steps,
        "retried_steps_converged": meta.retried_steps_converged,
        "fallback_steps": meta.fallback_steps,
        "loose_steps": meta.loose_steps,
        "friction_solvers": list(meta.friction_solvers),
        "max_solver_residual": meta.max_residual,
        "max_penetration_m": meta.max_penetration_m,
        "max_bullet_overlap_m": meta.max_bullet_overlap_m,
        "calibration": "siconos (nonsmooth: Newton restitution e, Coulomb friction; geometry and inertia as the DEMs)",
        "mu_model": {b.name: model_restitution(b) for b in model.bodies if not b.fixed},
        "process_cpu_s": meta.process_cpu_s,
        **extra,
    }
