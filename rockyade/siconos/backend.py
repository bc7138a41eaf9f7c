"""Siconos's machinery: a scene run by Siconos (nonsmooth contact dynamics), parsed back.

The scene's DEM model (its blocks, their contact polygons at b_eq and inertias from p, the
ground motion, the loads, the start) is written as JSON data (:mod:`rockyade.siconos.payload`)
and run by :mod:`rockyade.siconos.driver` in Debian's ``/usr/bin/python3``
(``python3-siconos``), in a worker kept warm between runs. The backend is the worker backend
every engine that runs in another Python fills in
(:class:`rockyade.dem.worker_backend.WorkerBackend`: no listening socket, a timeout per
run, a failure of any kind a Result with status ``failed``, the reason, the log path and the
samples so far; the run's files kept the one way of :mod:`rockyade.io.run_files`). What
Siconos adds: its own check, a friction-contact problem the solvers did not converge on
(:meth:`Siconos.engine_problem`), its diagnostics in the Result, and its version as the
Debian package names it (:func:`version_label`).

Same role as :mod:`rockyade.yade.backend`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

from __future__ import annotations

import functools
import os
import subprocess
from pathlib import Path

from rockyade.dem.model import DemModel
from rockyade.dem.worker_backend import PROBE_ANSWER, Arrays, WorkerBackend, worker_env
from rockyade.dem.worker_output import WorkerOutput
from rockyade.io.warm_program import Program
from rockyade.result import Result
from rockyade.siconos.calibration import model_restitution
from rockyade.siconos.payload import Numerics, scene_payload

DRIVER = Path(__file__).resolve().parent / "driver.py"
PYTHON_VARIABLE = "ROCKYADE_SICONOS_PYTHON"
SICONOS_PYTHON = os.environ.get(PYTHON_VARIABLE, "/usr/bin/python3")
#: A file of Debian's python3-siconos the driver needs (the 2-D Bullet collision manager).
SICONOS_MODULE = Path(
    os.environ.get("ROCKYADE_SICONOS_MODULE", "/usr/lib/python3/dist-packages/siconos/mechanics/collision/bullet.py")
)
#: How a user raises a run's timeout: the command line's --yade-timeout bounds every solver with a
#: ``timeout_s`` (rockyade.cli.common.SOLVER_OPTION_FLAGS); in Python, SiconosSolver(timeout_s=...).
TIMEOUT_OPTION = "--yade-timeout (timeout_s in Python)"
#: Samples so far are written every so many seconds while a scene runs, s.
FLUSH_PERIOD_S = 30.0
#: Default timeout: TIMEOUT_STARTUP_S plus this many seconds per body-step (measured on a
#: loaded 2-core machine: 0.25-0.9 ms per body-step for a single block, 3-4 ms for a 33-block
#: wall at rest, about 40 ms under a pulse: give such a run its own timeout_s), capped.
TIMEOUT_PER_BODY_STEP_S = 10e-3

#: A run fails when a step's friction-contact residual exceeds this (the solver stopped far
#: from a solution) ...
FAIL_RESIDUAL = 1e-4
#: ... or when more than this fraction of the solver's calls (and at least FAIL_UNCONVERGED_MIN
#: of them) end above its tolerance.
FAIL_UNCONVERGED_FRACTION = 0.01
FAIL_UNCONVERGED_MIN = 10
#: The driver's diagnostics the Result records under their own names.
SAME_NAMES = (
    "solver_calls",
    "solver_iterations",
    "unconverged_steps",
    "retried_steps",
    "retried_steps_converged",
    "fallback_steps",
    "loose_steps",
    "max_penetration_m",
    "max_bullet_overlap_m",
    "process_cpu_s",
)
#: What a Result says of the model's calibration.
CALIBRATION = "siconos (nonsmooth: Newton restitution e, Coulomb friction; geometry and inertia as the DEMs)"
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


class Siconos(WorkerBackend):
    """Siconos in the worker backend (module docstring)."""

    solver = "siconos"
    label = "Siconos"
    python_variable = PYTHON_VARIABLE
    debian_package = SICONOS_PACKAGE
    seconds_per_body_step = TIMEOUT_PER_BODY_STEP_S

    def program(self) -> Program:
        env = worker_env(PYTHONPATH=None)  # Debian's Python with its own modules only
        return Program([SICONOS_PYTHON, str(DRIVER)], env, self.label, TIMEOUT_OPTION, FLUSH_PERIOD_S)

    def needs(self) -> list[Path]:
        return [Path(SICONOS_PYTHON), SICONOS_MODULE]

    def probe(self) -> list[str]:
        return ["-c", f"import siconos.kernel, siconos.numerics; print({PROBE_ANSWER!r})"]

    def version(self, meta: WorkerOutput) -> str:
        return version_label(meta.version)

    def engine_problem(self, model: DemModel, meta: WorkerOutput, arrays: Arrays) -> str | None:
        """A friction-contact problem the solvers did not converge on (FAIL_RESIDUAL, FAIL_UNCONVERGED_*)."""
        calls, bad = meta.solver_calls, meta.unconverged_steps
        if meta.max_residual > FAIL_RESIDUAL or (
            bad >= FAIL_UNCONVERGED_MIN and bad > FAIL_UNCONVERGED_FRACTION * calls
        ):
            return (
                f"Siconos did not converge: {bad} of {calls} friction-contact solves ended above the tolerance "
                f"(largest residual {meta.max_residual:.3g}, first at t = {meta.first_unconverged_s} s); "
                "try a smaller dt_factor or more solver iterations"
            )
        return None

    def engine_meta(self, model: DemModel, meta: WorkerOutput) -> dict[str, object]:
        calls = meta.solver_calls
        return {
            **{key: getattr(meta, key) for key in SAME_NAMES},
            "n_steps": meta.steps,
            "solver_iterations_mean": (meta.solver_iterations / calls) if calls else 0.0,
            "friction_solvers": list(meta.friction_solvers),
            "max_solver_residual": meta.max_residual,
            "calibration": CALIBRATION,
            "mu_model": {b.name: model_restitution(b) for b in model.bodies if not b.fixed},
        }


SICONOS = Siconos()


def siconos_available() -> bool:
    """True when Debian's python3-siconos and the Python that runs it are installed."""
    return SICONOS.missing() is None


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
        Wall-clock limit, s (default TIMEOUT_STARTUP_S plus TIMEOUT_PER_BODY_STEP_S per body-step).
    warm
        Run in this thread's warm worker; False: in a process of its own.
    workdir, failed_dir
        Where ``<name>.siconos.json``, ``.npz`` and ``.log`` are kept after every run, after a
        failed run only (``run --out``'s folder); default: none, the run works in a private
        temporary folder (:mod:`rockyade.io.run_files`).
    name
        The files' stem (the solver's: the scene hash or the caller's stem, and dt_factor).
    extra_meta
        More metadata for the Result (calibration, time-step choice).
    """
    payload = scene_payload(model, numerics)
    extra: dict[str, object] = {
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
    n_steps = (model.n_samples - 1) * numerics.steps_per_sample
    return SICONOS.run(
        model,
        payload,
        name=name,
        body_steps=n_steps * len(model.bodies),
        timeout_s=timeout_s,
        workdir=workdir,
        failed_dir=failed_dir,
        lowpass=accel_lowpass_hz,
        warm=warm,
        extra=extra,
    )
