"""YADE as a solver: a scene's DEM model run by YADE in batch mode (:mod:`rockyade.yade.backend`).

The model is the reference DEM's (:mod:`rockyade.dem.model`, matched calibration
included), written as data and run by YADE's own Python in a process of its own, kept warm
for the next run (:class:`rockyade.dem.worker_backend.WorkerBackend`): no listening socket,
one OpenMP thread, a timeout per run, its log kept beside its output. A failure of any kind
(exit code, timeout, exception inside YADE, non-finite state, partial output) is a Result
with status ``failed``, the reason and the log path.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar

from rockyade.errors import InputError
from rockyade.result import Result
from rockyade.scene import Scene
from rockyade.solvers.base import WORKER_OPTIONS, SolverBase
from rockyade.solvers.cost_estimate import CostEstimate, dem_cost
from rockyade.yade.backend import run_model, yade_model


def _check_stem(value: Any, field: str) -> str | None:
    if value is not None and (not isinstance(value, str) or not value or "/" in value or value.startswith(".")):
        raise InputError(field, f"must be a file name without folder, got {value!r}")
    return value


@dataclass(frozen=True)
class YadeSolver(SolverBase):
    """YADE as a solver.

    Attributes
    ----------
    timeout_s
        Wall-clock limit of each YADE process, s (default: 60 s plus 50 us per
        body-step, at most one hour; :func:`rockyade.yade.backend.default_timeout`).
    workdir
        Where YADE's files are kept: ``<stem>.yade.json`` (the scene data),
        ``<stem>.yade.npz`` (its output) and ``<stem>.yade.log``. Default: a private
        temporary folder, removed after a successful run and kept (its log path in the
        Result) after a failed one (:mod:`rockyade.io.run_files`).
    stem
        File stem of those files (default: ``<scene hash>_yade``).
    warm
        Run in a YADE process kept warm between runs (one per thread; the default), or in
        a process of its own (False): the same result, bit for bit; a warm run saves YADE's
        start-up, 0.7-1.0 s.
    dt_factor
        Factor in [0.001, 1] on the model's time step (as the reference DEM's), recorded in the
        Result's ``dt_factor`` beside the ``dt_s`` used.
    """

    name: ClassVar[str] = "yade"
    OPTIONS: ClassVar = {**WORKER_OPTIONS, "stem": _check_stem}
    #: YADE's time per body-step, s (cost estimate; this project's benchmarks).
    SECONDS_PER_BODY_STEP: ClassVar[float] = 5e-6

    timeout_s: float | None = None
    workdir: str | None = None
    stem: str | None = None
    warm: bool = True
    dt_factor: float = 1.0

    def run(self, scene: Scene) -> Result:
        """Run a scene in YADE (:func:`rockyade.yade.backend.run_model`)."""
        model = yade_model(scene).with_dt_factor(self.dt_factor)
        result = run_model(
            model,
            workdir=self.workdir,
            name=self.stem or f"{scene.scene_hash}_{self.name}",
            timeout_s=self.timeout_s,
            accel_lowpass_hz=scene.output.accel_lowpass_hz,
            warm=self.warm,
        )
        result.meta = replace(result.meta, dt_factor=self.dt_factor)
        return result

    def estimate_cost(self, scene: Scene) -> CostEstimate:
        """Body-steps of the model's time step (:func:`rockyade.solvers.cost_estimate.dem_cost`)."""
        return dem_cost(scene, self.name, self.SECONDS_PER_BODY_STEP, self.dt_factor)

    def keeping_files(self, folder: str | Path, stem: str | None = None) -> YadeSolver:
        """This solver keeping YADE's files in ``folder``, named ``stem`` (default: by scene hash)."""
        return replace(self, workdir=str(folder), stem=stem)
