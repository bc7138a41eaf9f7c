"""YADE's machinery: a DEM model run by YADE in batch mode, parsed back.

The DEM model (:mod:`rockyade.dem.model`, the same the reference DEM runs) is written as
JSON data (:mod:`rockyade.yade.payload`) and run by :mod:`rockyade.yade.driver` in Debian's
``/usr/bin/python3.11`` with YADE's modules on the path, in a worker kept warm between runs
(one per thread, YADE reset between scenes). The backend is the worker backend every engine
that runs in another Python fills in (:class:`rockyade.dem.worker_backend.WorkerBackend`:
no listening socket, a timeout per run, a failure of any kind a Result with status
``failed``, the reason, the log path and the samples so far; the run's files kept the one
way of :mod:`rockyade.io.run_files`). What YADE adds:

* the ``yade`` launcher (which opens a Python console on 0.0.0.0:9000+ and an XMLRPC server
  on 21000+) is never used; one OpenMP thread per run (``OMP_NUM_THREADS=1``);
* the folder YADE makes in /tmp at import is removed at once (by the driver);
* its own checks: a rotation between two records too large to follow, and a vertex sphere
  deeper in a block than its radius (:data:`DEEP_OVERLAP`), kept up to the overlap when it
  is part of a collapse (:meth:`Yade.rescue`, docs/yade.md).

The solver, :class:`rockyade.solvers.yade.YadeSolver`, turns a scene into a model
(:func:`yade_model`) and calls :func:`run_model`; :func:`write_script` gives YADE users the
same scene as a script of their own.

Same role as :mod:`rockyade.siconos.backend`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

from __future__ import annotations

import os
from pathlib import Path

from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.model import DemModel
from rockyade.dem.worker_backend import PROBE_ANSWER, Arrays, MetaOf, WorkerBackend, worker_env
from rockyade.dem.worker_backend import TIMEOUT_CAP_S as TIMEOUT_CAP_S  # re-exported: the default timeout's cap
from rockyade.dem.worker_backend import TIMEOUT_STARTUP_S as TIMEOUT_STARTUP_S  # ... and its start-up allowance
from rockyade.dem.worker_output import WorkerOutput
from rockyade.errors import InputError
from rockyade.io import warm_program
from rockyade.io.atomic import write_json, write_text
from rockyade.io.warm_program import QUIT_WAIT_S as QUIT_WAIT_S  # re-exported: a worker's quit allowance
from rockyade.io.warm_program import Program
from rockyade.result import Result
from rockyade.scene import Scene
from rockyade.yade.deep_overlap import DEEP_OVERLAP, collapse_before_overlap, collapsed_meta
from rockyade.yade.payload import scene_payload

#: The script YADE's Python runs, shipped inside the package, and the loop it loads by path.
DRIVER = Path(__file__).resolve().parent / "driver.py"
DRIVER_LOOP = DRIVER.parent.parent / "io" / "driver_loop.py"
PYTHON_VARIABLE = "ROCKYADE_YADE_PYTHON"
YADE_PYTHON = os.environ.get(PYTHON_VARIABLE, "/usr/bin/python3.11")
YADE_PY_DIR = os.environ.get("ROCKYADE_YADE_PY", "/usr/lib/x86_64-linux-gnu/yade-double/py")
#: Default timeout: TIMEOUT_STARTUP_S plus this many seconds per body-step, capped at TIMEOUT_CAP_S.
TIMEOUT_PER_BODY_STEP_S = 50e-6
#: A scene's samples so far are written every so many seconds while it runs, s.
FLUSH_PERIOD_S = 30.0


class Yade(WorkerBackend):
    """YADE in the worker backend (module docstring)."""

    solver = "yade"
    label = "YADE"
    python_variable = PYTHON_VARIABLE
    debian_package = "yade"
    seconds_per_body_step = TIMEOUT_PER_BODY_STEP_S

    def program(self) -> Program:
        env = worker_env(ROCKYADE_YADE_PY=YADE_PY_DIR)
        return Program([YADE_PYTHON, str(DRIVER)], env, self.label, "--yade-timeout", FLUSH_PERIOD_S)

    def needs(self) -> list[Path]:
        return [Path(YADE_PYTHON), Path(YADE_PY_DIR) / "yade" / "__init__.py"]

    def probe(self) -> list[str]:
        code = "import os, sys; sys.path.insert(1, os.environ['ROCKYADE_YADE_PY']); import yade; print({!r})"
        return ["-c", code.format(PROBE_ANSWER)]

    def version(self, meta: WorkerOutput) -> str:
        return f"YADE {meta.version}"

    def unstable_reason(self, meta: WorkerOutput) -> str:
        return (
            f"numerical instability in YADE at t = {meta.stop_time_s} s (non-finite state, runaway speed or "
            "spin, or a rotation between two records too large to follow)"
        )

    def engine_problem(self, model: DemModel, meta: WorkerOutput, arrays: Arrays) -> str | None:
        return DEEP_OVERLAP if meta.max_polyhedra_penetration_over_radius >= 1.0 else None

    def engine_meta(self, model: DemModel, meta: WorkerOutput) -> dict[str, object]:
        return {
            "dt_s": meta.dt_s,
            "dt_source": model.dt_source,
            "n_steps": model.n_steps,
            "calibration": model.calibration,
            "contact": model.joint_summary(),
            "max_polyhedra_penetration_over_radius": meta.max_polyhedra_penetration_over_radius,
            "max_rotation_step_rad": meta.max_rotation_step_rad,
            "rotation_track_period_steps": meta.rotation_track_period_steps,
        }

    def rescue(self, model: DemModel, meta: WorkerOutput, arrays: Arrays, problem: str) -> int | None:
        """An assembly collapsing up to a deep overlap: its samples to there (:mod:`rockyade.yade.deep_overlap`)."""
        return collapse_before_overlap(model, meta, arrays) if problem == DEEP_OVERLAP else None

    def rescued_meta(self, model: DemModel, meta: WorkerOutput, arrays: Arrays, run_meta: MetaOf) -> dict[str, object]:
        return collapsed_meta(model, meta, arrays, run_meta)


YADE = Yade()


def yade_available() -> bool:
    """True when Debian's YADE and its Python are installed."""
    return YADE.missing() is None


def default_timeout(model: DemModel) -> float:
    """Wall-clock limit of a YADE run, s: TIMEOUT_STARTUP_S plus TIMEOUT_PER_BODY_STEP_S per
    body-step (about 5-20x what YADE needs), capped at TIMEOUT_CAP_S (one hour)."""
    return YADE.timeout(None, model.n_steps * len(model.bodies))


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
        default a private temporary folder, removed after a successful run and kept (its log
        path in the Result) after a failed one (:mod:`rockyade.io.run_files`).
    timeout_s
        Wall-clock limit of the run, s (default :func:`default_timeout`).
    warm
        Run in this thread's warm YADE worker; False: in a YADE process of its own (the
        same result, bit for bit, 0.7-1 s slower).
    """
    payload = scene_payload(model)
    plan = payload.get("contact_plan")
    return YADE.run(
        model,
        payload,
        name=name,
        body_steps=model.n_steps * len(model.bodies),
        timeout_s=timeout_s,
        workdir=workdir,
        lowpass=accel_lowpass_hz,
        warm=warm,
        extra={"yade_contacts": plan} if isinstance(plan, dict) else None,
    )


def _parse(
    model: DemModel, out_file: Path, reason: str | None, log_file: Path, total: float, lowpass: float | None
) -> Result:
    """YADE's output file as a Result (:meth:`rockyade.dem.worker_backend.WorkerBackend.parse`)."""
    return YADE.parse(model, out_file, reason, log_file, total, lowpass)


def close_workers() -> None:
    """Close this thread's warm YADE worker, if any (it is closed anyway when the thread ends)."""
    warm_program.close_workers(YADE.label)


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
    """A standalone YADE script for a scene: ``run.py`` (the driver rockyade itself runs, with
    ``driver_loop.py``, the loop it loads, beside it) and ``scene.json`` (its data) in
    ``directory``, for YADE users who go on by hand.

    ``yade -x run.py`` (batch) or ``yade run.py`` (with YADE's GUI and console) builds the
    same scene and writes ``result.npz`` (what rockyade parses) and ``result.csv`` (t,
    centroid and rotation of each block) beside the script; so does
    ``/usr/bin/python3.11 run.py`` (Debian's Python) with YADE's modules on the path. The launcher opens a Python
    console and an XMLRPC server on all interfaces (rockyade never uses it).

    Returns
    -------
    dict
        Paths of ``script``, ``loop`` and ``data``.
    """
    model = yade_model(scene)
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    data, script, loop = out / "scene.json", out / "run.py", out / "driver_loop.py"
    write_json(data, scene_payload(model))
    write_text(loop, DRIVER_LOOP.read_text())
    write_text(script, DRIVER.read_text())
    return {"script": script, "loop": loop, "data": data}
