"""YADE's machinery: a DEM model run by YADE in batch mode, parsed back.

The DEM model (:mod:`rockyade.dem.model`, the same the reference DEM runs) is written as
JSON data (:mod:`rockyade.yade.payload`) and run by :mod:`rockyade.yade.driver`
in Debian's ``/usr/bin/python3.11`` with YADE's modules on the path, as a subprocess kept
warm between runs (:mod:`rockyade.yade.warm_worker`: one per thread, reset between scenes):

* no listening socket: the ``yade`` launcher (which opens a Python console on
  0.0.0.0:9000+ and an XMLRPC server on 21000+) is never used, and the worker talks over
  a socket pair;
* one OpenMP thread per run (``OMP_NUM_THREADS=1``), a timeout per run, stdout and stderr
  in a log file next to the result (never written through a link);
* a crash, a timeout, a Python exception inside YADE, an output it cannot write (its
  partial file removed, the path named), a non-finite state, or a missing or partial
  output file give a Result with status ``failed``, the reason and the log path, never a
  Result that looks complete;
* nothing is left in the temporary folder: the folder YADE makes in /tmp at import is
  removed at once, rockyade's own (a run without ``workdir``) honours ``TMPDIR`` and is
  removed after a successful run.

Runs are independent (own files; a worker runs one scene at a time), so several can go in
parallel (the runner, :mod:`rockyade.runner`). The solver, :class:`rockyade.solvers.yade.YadeSolver`,
turns a scene into a model (:func:`yade_model`) and calls :func:`run_model`;
:func:`write_script` gives YADE users the same scene as a script of their own.

Same role as :mod:`rockyade.siconos.backend`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import os
import shutil
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from rockyade import __version__
from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem import worker_result
from rockyade.dem.model import DemModel
from rockyade.dem.result_frames import energy_gain, worker_frame
from rockyade.dem.worker_output import WorkerOutput
from rockyade.errors import InputError, SolverUnavailableError, os_error_message
from rockyade.io.atomic import write_json, write_text
from rockyade.io.warm_program import check_timeout as checked_timeout
from rockyade.io.warm_program import keep_run_files
from rockyade.result import Result, failed_result
from rockyade.run_meta import RunMeta
from rockyade.scene import Scene
from rockyade.yade.payload import scene_payload
from rockyade.yade.warm_worker import run_scene

#: The script YADE's Python runs, shipped inside the package.
DRIVER = Path(__file__).resolve().parent / "driver.py"
YADE_PYTHON = os.environ.get("ROCKYADE_YADE_PYTHON", "/usr/bin/python3.11")
YADE_PY_DIR = os.environ.get("ROCKYADE_YADE_PY", "/usr/lib/x86_64-linux-gnu/yade-double/py")


def yade_available() -> bool:
    """True when Debian's YADE and its Python are installed."""
    return Path(YADE_PYTHON).is_file() and (Path(YADE_PY_DIR) / "yade" / "__init__.py").is_file()


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["OMP_NUM_THREADS"] = "1"
    env.pop("DISPLAY", None)  # no GUI
    env["ROCKYADE_YADE_PY"] = YADE_PY_DIR
    env["PYTHONNOUSERSITE"] = "1"
    return env


# ---------------------------------------------------------------------- running

#: Default timeout: start-up allowance plus this many seconds per body-step ...
TIMEOUT_STARTUP_S = 60.0
TIMEOUT_PER_BODY_STEP_S = 50e-6
#: ... capped here unless a larger one is asked for (``--yade-timeout``, ``timeout_s``).
TIMEOUT_CAP_S = 3600.0
#: Largest timeout accepted, s (30 days).


def default_timeout(model: DemModel) -> float:
    """Wall-clock limit of a YADE run, s: TIMEOUT_STARTUP_S plus TIMEOUT_PER_BODY_STEP_S per
    body-step (about 5-20x what YADE needs), capped at TIMEOUT_CAP_S (one hour)."""
    work = TIMEOUT_STARTUP_S + TIMEOUT_PER_BODY_STEP_S * model.n_steps * len(model.bodies)
    return min(work, TIMEOUT_CAP_S)


def check_timeout(timeout_s: float | None, field: str = "yade_timeout_s") -> float | None:
    """A user timeout checked (:func:`rockyade.io.warm_program.check_timeout`, in (0, MAX_TIMEOUT_S] s)."""
    return checked_timeout(timeout_s, field)


def run_model(
    model: DemModel,
    *,
    workdir: str | Path | None = None,
    name: str = "yade",
    timeout_s: float | None = None,
    accel_lowpass_hz: float | None = None,
    warm: bool = True,
) -> Result:
    """Run a DEM model in YADE and return a Result (status ``failed`` on any failure).

    Parameters
    ----------
    model
        The DEM model.
    workdir
        Where ``<name>.yade.json`` (the scene data), ``<name>.yade.npz`` (YADE's output)
        and ``<name>.yade.log`` are kept (relative to the current folder, or absolute);
        default a temporary directory, removed after a successful run and kept (its log
        path in the Result) after a failed one.
    timeout_s
        Wall-clock limit of the run, s (default :func:`default_timeout`).
    warm
        Run in this thread's warm YADE worker (:mod:`rockyade.yade.warm_worker`); False: in a
        YADE process of its own (the same result, bit for bit, 0.7-1 s slower).
    """
    if not yade_available():
        raise SolverUnavailableError(
            f"YADE is not installed (looked for {YADE_PYTHON} and {YADE_PY_DIR}/yade): "
            "apt-get install -y --no-install-recommends yade, or set ROCKYADE_YADE_PYTHON to the Python "
            "that runs YADE's modules"
        )
    timeout = check_timeout(timeout_s)
    timeout = timeout if timeout is not None else default_timeout(model)
    keep = workdir is not None
    # absolute paths: the process runs in ``directory``, where a relative path would be
    # taken relative to it a second time
    directory = (Path(workdir) if workdir is not None else Path(tempfile.mkdtemp(prefix="rockyade-yade-"))).resolve()
    directory.mkdir(parents=True, exist_ok=True)
    # the run writes under a name of its own; its files take the run's name once it ended
    # (:func:`_keep_files`): an earlier run's files are never touched by a run that fails
    work = f"{name}.running"
    scene_file = directory / f"{work}.yade.json"
    out_file = directory / f"{work}.yade.npz"
    log_file = directory / f"{work}.yade.log"
    partial = directory / f"{work}.yade.npz.part"
    for stale in (out_file, partial, log_file):  # a killed run's
        stale.unlink(missing_ok=True)
    payload = scene_payload(model)
    start = time.perf_counter()
    try:
        # compact (json's C encoder: half the time of the indented form) and not synced: YADE
        # reads it at once, and a run that did not end is run again
        write_text(scene_file, json.dumps(payload, sort_keys=True) + "\n", durable=False)
        reason = run_scene(_command(), _env(), scene_file, out_file, log_file, timeout, warm)
    except OSError as exc:  # a full disk: the run fails naming the file; its temporary files are gone
        error = exc if exc.filename else OSError(exc.errno, exc.strerror, str(scene_file))
        reason = f"cannot write {os_error_message(error)}"
    except BaseException:  # Ctrl-C: an interrupted run leaves none of its files
        if keep:
            for path in (scene_file, out_file, log_file, partial):
                path.unlink(missing_ok=True)
        else:
            shutil.rmtree(directory, ignore_errors=True)
        raise
    total = time.perf_counter() - start
    if reason is not None:
        partial.unlink(missing_ok=True)  # a worker killed while writing
    plan = payload.get("contact_plan")
    plan = plan if isinstance(plan, dict) else None
    result = _parse(model, out_file, reason, log_file, total, accel_lowpass_hz, plan)
    result.meta = dataclasses.replace(result.meta, timeout_s=timeout)
    if result.ok and not keep:
        shutil.rmtree(directory, ignore_errors=True)
    else:
        _keep_files(directory, work, name, result)
    return result


def _keep_files(directory: Path, work: str, name: str, result: Result) -> None:
    """Give a run's files (``<work>.yade.*``) their names (:func:`rockyade.io.warm_program.keep_run_files`:
    ``<name>.yade.*``, or ``<name>_failed.yade.*`` beside an earlier run's output when this one
    failed). ``log_path`` says where the log went."""
    log = keep_run_files(directory, work, name, ".yade", result.ok)
    if result.meta.log_path is not None:
        result.meta = dataclasses.replace(result.meta, log_path=str(log))


def _command() -> list[str]:
    """YADE's Python running the driver."""
    return [YADE_PYTHON, str(DRIVER)]


def _parse(
    model: DemModel,
    out_file: Path,
    reason: str | None,
    log_file: Path,
    total: float,
    lowpass: float | None,
    contact_plan: dict | None = None,
) -> Result:
    """YADE's output file as a Result, or a failed Result saying why there is none.

    Parameters
    ----------
    reason
        Why the process failed (None: it exited normally).
    total
        Wall time of the whole process, s.
    lowpass
        Optional zero-phase low-pass of the output accelerations, Hz.
    """
    extra: dict[str, object] = {"log_path": str(log_file), "total_time_s": total}
    if contact_plan is not None:
        extra["yade_contacts"] = contact_plan
    if reason is None and not out_file.is_file():
        reason = "YADE wrote no output file"
    if reason is not None:
        detail = worker_result.last_error_line(log_file)
        reason = f"{reason}: {detail}" if detail else reason
        kept = None
        with contextlib.suppress(OSError, ValueError, KeyError, zipfile.BadZipFile):
            kept = worker_result.read_output(out_file)
        if kept is not None:  # a timeout or a lost worker after a flush: the samples it wrote
            return _partial_failure(model, kept[0], kept[1], reason, total, extra)
        extra["wall_time_s"] = total
        return failed_result("yade", model.scene_hash, reason, **extra)
    try:
        meta, arrays = worker_result.read_output(out_file)
    except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:
        return failed_result("yade", model.scene_hash, f"unreadable YADE output {out_file.name}: {exc}", **extra)
    extra["max_polyhedra_penetration_over_radius"] = meta.max_polyhedra_penetration_over_radius
    extra["max_rotation_step_rad"] = meta.max_rotation_step_rad
    extra["rotation_track_period_steps"] = meta.rotation_track_period_steps
    problem = _output_problem(model, meta, arrays)
    if problem == DEEP_OVERLAP:
        cut = _collapse_before_overlap(model, meta, arrays)
        if cut is not None:  # a collapse: kept up to the overlap, ended overturned
            return _collapsed(model, meta, arrays, cut, total, extra, lowpass)
    if problem is not None:
        return _partial_failure(model, meta, arrays, problem, total, extra)
    return Result(worker_frame(model, arrays, lowpass), RunMeta.from_dict(_run_meta(model, meta, total, extra, arrays)))


#: Why a run with a deep sphere-polyhedron overlap fails (when it is not part of a collapse).
DEEP_OVERLAP = (
    "a vertex sphere went deeper into a non-rectangular block than its own radius (YADE's sphere-polyhedron "
    "contact then loses its normal): the impact is too hard for these contact spheres"
)
#: A block has fallen off when its centroid dropped by more than this fraction of its height
#: (the collapse table's rule, rockyade.analysis.collapse.DROP_FRACTION).
DROP_FRACTION = 0.5


def _collapse_before_overlap(model: DemModel, meta: WorkerOutput, arrays: dict[str, np.ndarray]) -> int | None:
    """The samples to keep when a deep overlap is part of a collapse, or None (a blow-up).

    The rule (docs/yade.md): at the last sample before the overlap (``deep_overlap_time_s``
    of the driver; the end of the output when an older driver does not say), some moving block
    has reached its landing angle, dropped by more than DROP_FRACTION of its height, or passed
    its tipping angle alpha, and the energy has not grown up to then (no blow-up by
    :func:`rockyade.dem.result_frames.energy_gain`).
    """
    n = meta.n_filled
    when = meta.deep_overlap_time_s
    # the depth is measured at the samples: keep those before the one that saw it
    keep = n if when is None else min(n, math.floor(float(when) / model.sample_dt_s + 1e-9))
    if keep < 3:
        return None
    pos, ang, angvel = arrays["pos"][:keep], arrays["ang"][:keep], arrays["angvel"][:keep]
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(ang))):
        return None
    _, t_blowup = energy_gain(model, pos, ang, angvel)
    if t_blowup is not None:
        return None
    stop = model.stop_angle_rad if model.stop_angle_rad is not None else np.full(len(model.bodies), 0.5 * math.pi)
    for i, body in enumerate(model.bodies):
        if body.fixed:
            continue
        theta = np.abs(ang[:, i] - body.rest_angle_rad)
        height = float(np.ptp(body.contact_vertices_m[:, 1]))
        dropped = body.rest_centroid_m[1] - pos[:, i, 1] > DROP_FRACTION * height
        alpha = body.alpha_rad if math.isfinite(body.alpha_rad) else stop[i]
        if np.any(theta >= stop[i]) or np.any(dropped) or np.any(theta > alpha):
            return keep
    return None


def _cut(arrays: dict[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
    return {k: v[:n] for k, v in arrays.items()}


def _collapsed(
    model: DemModel,
    meta: WorkerOutput,
    arrays: dict[str, np.ndarray],
    keep: int,
    total: float,
    extra: dict[str, object],
    lowpass: float | None,
) -> Result:
    """An assembly collapsing up to a deep overlap: its history to the overlap, status
    ``overturned`` (the first block that landed, else the first past its tipping angle)."""
    names = model.names
    t_cut = (keep - 1) * model.sample_dt_s
    meta = dataclasses.replace(
        meta,
        overturn_times_s={i: t for i, t in meta.overturn_times_s.items() if t <= t_cut + 1e-12},
        status="completed",  # re-decided below from the blocks' falls up to the cut
    )
    arrays = _cut(arrays, keep)
    out = _run_meta(model, meta, total, extra, arrays)
    if out["status"] != "overturned":
        ang = arrays["ang"]
        first, block = math.inf, None
        for i, body in enumerate(model.bodies):
            if body.fixed:
                continue
            over = np.flatnonzero(np.abs(ang[:, i] - body.rest_angle_rad) > body.alpha_rad)
            if over.size and over[0] * model.sample_dt_s < first:
                first, block = over[0] * model.sample_dt_s, names[i]
        out.update(status="overturned", overturn_time_s=first if block else t_cut, overturned_block=block)
    out["stopped_at_deep_overlap_s"] = t_cut
    out["deep_overlap_note"] = (
        "the run stopped at a deep sphere-polyhedron overlap after the assembly had started to collapse "
        "(docs/yade.md): its history up to there is kept"
    )
    return Result(worker_frame(model, arrays, lowpass), RunMeta.from_dict(out))


def _partial_failure(
    model: DemModel,
    meta: WorkerOutput,
    arrays: dict[str, np.ndarray],
    reason: str,
    total: float,
    extra: dict[str, object],
) -> Result:
    """A failed run that keeps what it recorded: status ``failed``, ``partial: true``, the
    samples it has (never read as complete: its status is ``failed``)."""
    n = min(meta.n_filled, arrays["pos"].shape[0])
    if n == 0 or meta.wall_time_s is None:
        return failed_result("yade", model.scene_hash, reason, partial=True, **extra)
    arrays = _cut(arrays, n)
    try:
        frame = worker_frame(model, arrays, None)
    except (ValueError, FloatingPointError):  # samples too broken to derive accelerations
        return failed_result("yade", model.scene_hash, reason, partial=True, **extra)
    out = _run_meta(model, dataclasses.replace(meta, status="failed"), total, extra, arrays)
    return Result(frame, RunMeta.from_dict(worker_result.failed_partially(out, reason, n)))


def _output_problem(model: DemModel, meta: WorkerOutput, arrays: dict[str, np.ndarray]) -> str | None:
    """Why a complete-looking output is not a result (partial, short, unstable, a lost
    contact normal), or None when it is one."""
    incomplete = worker_result.incomplete_output(model, meta, arrays, "YADE")
    if incomplete is not None:
        return incomplete
    if worker_result.unstable(meta, arrays):
        return (
            f"numerical instability in YADE at t = {meta.stop_time_s} s (non-finite state, runaway speed or "
            "spin, or a rotation between two records too large to follow)"
        )
    blowup = worker_result.energy_problem(model, arrays, "YADE")
    if blowup is not None:
        return blowup
    if meta.max_polyhedra_penetration_over_radius >= 1.0:
        return DEEP_OVERLAP
    return None


def _run_meta(
    model: DemModel, meta: WorkerOutput, total: float, extra: dict[str, object], arrays: dict[str, np.ndarray]
) -> dict[str, object]:
    """The Result's metadata: how the run ended (overturns per block) and what ran."""
    return {
        "solver": "yade",
        "version": f"YADE {meta.version} (rockyade {__version__} driver)",
        **worker_result.shared_run_meta(model, meta, total, arrays),
        "dt_s": meta.dt_s,
        "dt_source": model.dt_source,
        "n_steps": model.n_steps,
        "calibration": model.calibration,
        "contact": model.joint_summary(),
        **extra,
    }


def yade_model(scene: Scene) -> DemModel:
    """The DEM model YADE runs for ``scene`` (the reference DEM's, matched calibration included).

    Raises
    ------
    InputError
        A scene YADE cannot run (mass-proportional damping).
    """
    if scene.contact.mass_damping_1_s:
        raise InputError("contact.mass_damping_1_s", "mass-proportional damping is available in the reference DEM only")
    return calibrated_model(scene)


def write_script(scene: Scene, directory: str | Path) -> dict[str, Path]:
    """A standalone YADE script for a scene: ``run.py`` (the driver rockyade itself runs) and
    ``scene.json`` (its data) in ``directory``, for YADE users who go on by hand.

    ``yade -x run.py`` (batch) or ``yade run.py`` (with YADE's GUI and console) builds the
    same scene and writes ``result.npz`` (what rockyade parses) and ``result.csv`` (t,
    centroid and rotation of each block) beside the script; so does
    ``/usr/bin/python3.11 run.py`` (Debian's Python) with YADE's modules on the path. The launcher opens a Python
    console and an XMLRPC server on all interfaces (rockyade never uses it).

    Returns
    -------
    dict
        Paths of ``script`` and ``data``.
    """
    model = yade_model(scene)
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    data, script = out / "scene.json", out / "run.py"
    write_json(data, scene_payload(model))
    write_text(script, DRIVER.read_text())
    return {"script": script, "data": data}
