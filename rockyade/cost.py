"""What a run will cost, estimated before it starts, and a refusal above documented limits.

The estimate of a scene run by a solver (:func:`estimate_cost`):

* **integration steps**: for the DEMs (reference and YADE), the explicit time steps times
  the moving bodies, with the time step the model will use (paper Eq 7, kept below the
  stability limit, or ``contact.dt_s``); for Housner, the output samples;
* **output samples** and **base-motion samples** (the motion as it is built: a harmonic
  motion at 400 points per cycle, a pulse at T/400, a record's samples);
* **memory**, bytes: about 45 bytes per output value (the frame, its CSV text and the
  digest: measured on 1e6-sample runs of the Housner and reference solvers), 80 bytes per
  motion sample, and 250 MB for the interpreter, numpy, scipy, pandas and numba;
* **wall time**, s: 150 ns per body-step for the reference DEM, 5 us for YADE, 1.5 us per
  output value written (measured on this project's benchmarks; an order of magnitude).

:func:`check_cost` refuses a run above :data:`LIMITS` with an
:class:`~rockyade.errors.InputError` naming what is too large, by how much, and the input
that sets it; ``allow_large=True`` (``--allow-large`` on ``run``, ``compare`` and
``batch``) runs it anyway. The solver functions themselves do not check: the command line
and :func:`rockyade.studies.batch.run_study_tasks` do.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from typing import Any

from rockyade.errors import InputError
from rockyade.scene import Scene

#: Documented limits of one run (docs/reliability.md); ``allow_large`` lifts them.
LIMITS: dict[str, float] = {
    "integration_steps": 2.0e8,  # body-steps: ~30 s of the reference DEM, hours of YADE
    "output_samples": 2.0e6,  # rows of the result
    "motion_samples": 2.0e7,  # samples of the base motion
    "memory_bytes": 2.0 * 1024**3,  # 2 GiB
}

BYTES_PER_OUTPUT_VALUE = 45.0
BYTES_PER_MOTION_SAMPLE = 80.0
BASE_MEMORY_BYTES = 250.0e6
SECONDS_PER_BODY_STEP = {"reference": 150e-9, "yade": 5e-6}
SECONDS_PER_OUTPUT_VALUE = 1.5e-6
DEM_SOLVERS = ("reference", "yade")


@dataclass(frozen=True)
class CostEstimate:
    """What one run will cost (see the module docstring).

    Attributes
    ----------
    solver
        Solver name.
    integration_steps
        Body-steps of the DEMs (time steps x moving bodies); output samples for Housner.
    time_step_s
        The DEM's time step, s (NaN for Housner).
    output_samples, output_columns
        Rows and (about) columns of the result.
    motion_samples
        Samples of the base motion as built.
    memory_bytes
        Peak memory, bytes (estimate).
    wall_time_s
        Run time, s (order of magnitude).
    """

    solver: str
    integration_steps: float
    time_step_s: float
    output_samples: int
    output_columns: int
    motion_samples: int
    memory_bytes: float
    wall_time_s: float

    def over_limits(self, limits: dict[str, float] | None = None) -> list[str]:
        """The limits this run exceeds (names of :data:`LIMITS`)."""
        limits = LIMITS if limits is None else limits
        return [name for name, limit in limits.items() if getattr(self, name) > limit]

    def describe(self) -> str:
        """One line: steps, samples, memory, time."""
        steps = f"{self.integration_steps:.3g} integration steps"
        if not math.isnan(self.time_step_s):
            steps += f" (dt = {self.time_step_s:.3g} s)"
        return (
            f"{steps}, {self.output_samples:.3g} output samples, {self.motion_samples:.3g} motion samples, "
            f"~{self.memory_bytes / 1024**3:.2g} GiB, ~{_duration(self.wall_time_s)}"
        )


def _duration(seconds: float) -> str:
    if seconds < 120:
        return f"{seconds:.2g} s"
    if seconds < 7200:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.3g} h"


def dem_time_step(scene: Scene) -> tuple[float, int]:
    """The DEM's time step (s) and its moving bodies, from the model the solvers build.

    The model is built on the scene with the base at rest (the step depends on the joints
    and masses, not on the motion, so no motion is built); a matched calibration is
    estimated with the paper's damping (Eq 13), which the matching changes little.
    """
    from rockyade.calibration.model import calibrated_model
    from rockyade.motion.spec import AtRest

    contact = scene.contact
    if contact.calibration == "matched" and contact.beta_s is None:
        contact = dataclasses.replace(contact, calibration="paper")
    at_rest = dataclasses.replace(scene, motion=AtRest(), contact=contact)
    model = calibrated_model(at_rest)
    moving = sum(1 for b in model.bodies if not b.fixed)
    return float(model.dt_s), moving


_DT_CACHE: dict[str, tuple[float, int]] = {}


def _cached_dem_time_step(scene: Scene) -> tuple[float, int]:
    """:func:`dem_time_step`, remembered per scene without its motion (grids vary the motion)."""
    d = scene.to_dict()
    d.pop("motion", None)
    d["duration_s"] = 0.0
    key = json.dumps(d, sort_keys=True, default=str)
    if key not in _DT_CACHE:
        if len(_DT_CACHE) > 4096:
            _DT_CACHE.clear()
        _DT_CACHE[key] = dem_time_step(scene)
    return _DT_CACHE[key]


def estimate_cost(scene: Scene, solver: str) -> CostEstimate:
    """Estimate the cost of running ``scene`` with ``solver`` (module docstring)."""
    n_out = scene.n_samples
    n_blocks = len(scene.blocks)
    motion_samples = scene.motion.sample_count(scene.duration_s)
    if solver in DEM_SOLVERS:
        dt, moving = _cached_dem_time_step(scene)
        steps_per_sample = max(1, math.ceil(scene.sample_dt_s / dt - 1e-9))
        steps = float(n_out - 1) * steps_per_sample * max(1, moving)
        corners = sum(len(b.vertices_m or ()) or 4 for b in scene.blocks)
        columns = 2 + 6 * n_blocks + corners + 7
        run_time = steps * SECONDS_PER_BODY_STEP[solver]
    else:
        dt = math.nan
        steps = float(n_out)
        columns = 2 + 6 * n_blocks
        run_time = 0.0
    values = float(n_out) * columns
    memory = BASE_MEMORY_BYTES + BYTES_PER_OUTPUT_VALUE * values + BYTES_PER_MOTION_SAMPLE * motion_samples
    return CostEstimate(
        solver=solver,
        integration_steps=steps,
        time_step_s=dt,
        output_samples=n_out,
        output_columns=columns,
        motion_samples=motion_samples,
        memory_bytes=memory,
        wall_time_s=run_time + SECONDS_PER_OUTPUT_VALUE * values,
    )


_WHAT = {
    "integration_steps": ("integration steps", "a larger contact.dt_s or time_step_frac, a shorter duration_s"),
    "output_samples": ("output samples", "a larger sample_dt_s or a shorter duration_s"),
    "motion_samples": ("base-motion samples", "a shorter motion (start_s, cycles, record length)"),
    "memory_bytes": ("bytes of memory", "a larger sample_dt_s, a shorter duration_s or motion"),
}


def check_cost(
    scene: Scene, solver: str, allow_large: bool = False, label: str = "", limits: dict[str, float] | None = None
) -> CostEstimate:
    """The cost estimate; raise InputError if it exceeds the limits and ``allow_large`` is False.

    Parameters
    ----------
    label
        Names the run in the error (e.g. a batch's run index and grid values).
    """
    estimate = estimate_cost(scene, solver)
    over = estimate.over_limits(limits)
    if over and not allow_large:
        limits = LIMITS if limits is None else limits
        name = over[0]
        what, remedy = _WHAT[name]
        value, limit = getattr(estimate, name), limits[name]
        where = f"{label}: " if label else ""
        raise InputError(
            "allow_large",
            f"{where}the {solver} run needs {value:.3g} {what}, above the limit {limit:.3g} "
            f"({estimate.describe()}); use {remedy}, or pass --allow-large (allow_large=True) to run it anyway",
            scene.source,
        )
    return estimate


def estimate_dict(estimate: CostEstimate) -> dict[str, Any]:
    """The estimate as a JSON-ready dictionary."""
    return dataclasses.asdict(estimate)


__all__ = ["LIMITS", "CostEstimate", "check_cost", "dem_time_step", "estimate_cost", "estimate_dict"]
