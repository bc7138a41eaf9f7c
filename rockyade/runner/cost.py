"""What a run will cost, estimated before it starts, and a refusal above documented limits.

Each solver answers for its own runs (``solver.estimate_cost(scene)``) with the models
here:

* **integration steps**: for the DEMs (:func:`dem_cost`, reference and YADE), the explicit
  time steps times the moving bodies, with the time step the model will use (paper Eq 7,
  kept below the stability limit, or ``contact.dt_s``); for Housner (:func:`sample_cost`),
  the output samples;
* **output samples** and **base-motion samples** (the motion as it is built: a harmonic
  motion at 400 points per cycle, a pulse at T/400, a record's samples);
* **memory**, bytes: about 45 bytes per output value (the frame, its CSV text and the
  digest: measured on 1e6-sample runs of the Housner and reference solvers), 80 bytes per
  motion sample, and 250 MB for the interpreter, numpy, scipy, pandas and numba;
* **wall time**, s: a solver's seconds per body-step (150 ns for the reference DEM, 5 us
  for YADE: each solver's ``SECONDS_PER_BODY_STEP``) and 1.5 us per output value written
  (measured on this project's benchmarks; an order of magnitude).

:func:`check_cost` refuses a run above :data:`LIMITS` with an
:class:`~rockyade.errors.InputError` naming what is too large, by how much, and the input
that sets it; ``allow_large=True`` (``--allow-large`` on ``run``, ``compare`` and
``batch``) runs it anyway. The solvers themselves do not check: the command line and the
runner (:func:`rockyade.runner.run_tasks`, before any run starts) do.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rockyade.errors import InputError
from rockyade.scene import Scene

if TYPE_CHECKING:
    from rockyade.solvers.base import Solver

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
SECONDS_PER_OUTPUT_VALUE = 1.5e-6


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


def _estimate(
    scene: Scene, solver: str, steps: float, dt: float, columns: int, run_time_s: float
) -> CostEstimate:
    values = float(scene.n_samples) * columns
    motion_samples = scene.motion.sample_count(scene.duration_s)
    memory = BASE_MEMORY_BYTES + BYTES_PER_OUTPUT_VALUE * values + BYTES_PER_MOTION_SAMPLE * motion_samples
    return CostEstimate(
        solver=solver,
        integration_steps=steps,
        time_step_s=dt,
        output_samples=scene.n_samples,
        output_columns=columns,
        motion_samples=motion_samples,
        memory_bytes=memory,
        wall_time_s=run_time_s + SECONDS_PER_OUTPUT_VALUE * values,
    )


def dem_cost(scene: Scene, solver: str, seconds_per_body_step: float) -> CostEstimate:
    """The cost of a DEM run: time steps x moving bodies at the model's time step, the
    time history of every block and corner, ``seconds_per_body_step`` of the DEM (s)."""
    dt, moving = _cached_dem_time_step(scene)
    steps_per_sample = max(1, math.ceil(scene.sample_dt_s / dt - 1e-9))
    steps = float(scene.n_samples - 1) * steps_per_sample * max(1, moving)
    corners = sum(len(b.vertices_m or ()) or 4 for b in scene.blocks)
    columns = 2 + 6 * len(scene.blocks) + corners + 7
    return _estimate(scene, solver, steps, dt, columns, steps * seconds_per_body_step)


def sample_cost(scene: Scene, solver: str) -> CostEstimate:
    """The cost of a run whose work grows with its output samples (Housner's exact solution):
    one 'step' per sample, the time history of every block."""
    columns = 2 + 6 * len(scene.blocks)
    return _estimate(scene, solver, float(scene.n_samples), math.nan, columns, 0.0)


def estimate_cost(scene: Scene, solver: Solver | str) -> CostEstimate:
    """Estimate the cost of running ``scene`` with ``solver`` (a Solver, or a solver's name)."""
    from rockyade.solvers import as_solver

    return as_solver(solver).estimate_cost(scene)


_WHAT = {
    "integration_steps": ("integration steps", "a larger contact.dt_s or time_step_frac, a shorter duration_s"),
    "output_samples": ("output samples", "a larger sample_dt_s or a shorter duration_s"),
    "motion_samples": ("base-motion samples", "a shorter motion (start_s, cycles, record length)"),
    "memory_bytes": ("bytes of memory", "a larger sample_dt_s, a shorter duration_s or motion"),
}


def cost_refusal(
    estimate: CostEstimate, source: str | None = None, label: str = "", limits: dict[str, float] | None = None
) -> InputError | None:
    """The error refusing a run whose ``estimate`` is above the limits, or None when it is within."""
    limits = LIMITS if limits is None else limits
    over = estimate.over_limits(limits)
    if not over:
        return None
    name = over[0]
    what, remedy = _WHAT[name]
    value, limit = getattr(estimate, name), limits[name]
    where = f"{label}: " if label else ""
    return InputError(
        "allow_large",
        f"{where}the {estimate.solver} run needs {value:.3g} {what}, above the limit {limit:.3g} "
        f"({estimate.describe()}); use {remedy}, or pass --allow-large (allow_large=True) to run it anyway",
        source,
    )


def check_cost(
    scene: Scene,
    solver: Solver | str,
    allow_large: bool = False,
    label: str = "",
    limits: dict[str, float] | None = None,
) -> CostEstimate:
    """The cost estimate; raise InputError if it exceeds the limits and ``allow_large`` is False.

    Parameters
    ----------
    solver
        A Solver, or a solver's name.
    label
        Names the run in the error (e.g. a batch's run index and grid values).
    """
    estimate = estimate_cost(scene, solver)
    refusal = None if allow_large else cost_refusal(estimate, scene.source, label, limits)
    if refusal is not None:
        raise refusal
    return estimate


def estimate_dict(estimate: CostEstimate) -> dict[str, Any]:
    """The estimate as a JSON-ready dictionary."""
    return dataclasses.asdict(estimate)


__all__ = [
    "LIMITS",
    "CostEstimate",
    "check_cost",
    "cost_refusal",
    "dem_cost",
    "dem_time_step",
    "estimate_cost",
    "estimate_dict",
    "sample_cost",
]
