"""What one run of a solver will cost, estimated before it starts.

Each solver answers ``estimate_cost(scene)`` with a :class:`CostEstimate`
(:mod:`rockyade.solvers.base`); the runner refuses a run above its limits
(:mod:`rockyade.runner.cost_limits`). The estimate of a scene run by a solver:

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
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Hashable
from dataclasses import dataclass
from typing import Any

from rockyade.scene import Scene

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
    compile_s
        CPU time compiling the solver's code before the run, s: 0 when numba's cache holds it
        (``make setup`` compiles it, :mod:`rockyade.solvers.compile_cache`), else once per
        process (the first run); not in ``wall_time_s``, which each run of a study costs.
    """

    solver: str
    integration_steps: float
    time_step_s: float
    output_samples: int
    output_columns: int
    motion_samples: int
    memory_bytes: float
    wall_time_s: float
    compile_s: float = 0.0

    def over_limits(self, limits: dict[str, float]) -> list[str]:
        """The limits this run exceeds (names of ``limits``, e.g. :data:`rockyade.runner.cost_limits.LIMITS`)."""
        return [name for name, limit in limits.items() if getattr(self, name) > limit]

    def describe(self) -> str:
        """One line: steps, samples, memory, time."""
        steps = f"{self.integration_steps:.3g} integration steps"
        if not math.isnan(self.time_step_s):
            steps += f" (dt = {self.time_step_s:.3g} s)"
        compiling = ""
        if self.compile_s:
            compiling = f" after ~{duration_text(self.compile_s)} of CPU compiling the solver (first run only)"
        return (
            f"{steps}, {self.output_samples:.3g} output samples, {self.motion_samples:.3g} motion samples, "
            f"~{self.memory_bytes / 1024**3:.2g} GiB, ~{duration_text(self.wall_time_s)}{compiling}"
        )


def duration_text(seconds: float) -> str:
    """A duration for people: seconds below 2 min, minutes below 2 h, else hours (2 or 3
    significant digits), e.g. "45 s", "3.5 min", "2.25 h"."""
    if seconds < 120:
        return f"{seconds:.2g} s"
    if seconds < 7200:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.3g} h"


def dem_time_step(scene: Scene) -> tuple[float, int]:
    """The DEM's time step (s) and its moving bodies, from the model the solvers build.

    The step depends on the joints and masses, not on the motion. The model is the one the
    run builds (:func:`rockyade.calibration.model_stage.calibrated_model` keeps it for the run),
    except for a matched calibration, estimated with the paper's damping (Eq 13), which the
    matching changes little, on the scene with the base at rest (no motion is built).
    """
    from rockyade.calibration.model_stage import calibrated_model
    from rockyade.motion.spec import AtRest

    contact = scene.contact
    if contact.calibration == "matched" and contact.beta_s is None:
        contact = dataclasses.replace(contact, calibration="paper")
        model = calibrated_model(dataclasses.replace(scene, motion=AtRest(), contact=contact))
    else:
        model = calibrated_model(scene)
    moving = sum(1 for b in model.bodies if not b.fixed)
    return float(model.dt_s), moving


_DT_CACHE: dict[Hashable, tuple[float, int]] = {}


def _cached_dem_time_step(scene: Scene) -> tuple[float, int]:
    """:func:`dem_time_step`, remembered per scene without its motion (grids vary the motion)."""
    key: Hashable = (scene.sample_dt_s, scene.blocks, scene.contact, scene.output, scene.joints, scene.loads)
    try:
        hash(key)  # the frozen specs hash their fields (a 1,000-block wall: ~1 ms, its JSON ~1 s)
    except TypeError:
        d = scene.to_dict()
        d.pop("motion", None)
        d["duration_s"] = 0.0
        key = json.dumps(d, sort_keys=True, default=str)
    if key not in _DT_CACHE:
        if len(_DT_CACHE) > 4096:
            _DT_CACHE.clear()
        _DT_CACHE[key] = dem_time_step(scene)
    return _DT_CACHE[key]


def _estimate(scene: Scene, solver: str, steps: float, dt: float, columns: int, run_time_s: float) -> CostEstimate:
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


def dem_cost(scene: Scene, solver: str, seconds_per_body_step: float, dt_factor: float = 1.0) -> CostEstimate:
    """The cost of a DEM run: time steps x moving bodies at the model's time step (times the
    solver's ``dt_factor``), the time history of every block and corner,
    ``seconds_per_body_step`` of the DEM (s)."""
    dt, moving = _cached_dem_time_step(scene)
    steps_per_sample = max(1, math.ceil(scene.sample_dt_s / dt - 1e-9))
    if dt_factor != 1.0:  # as DemModel.with_dt_factor rounds it
        steps_per_sample = math.ceil(steps_per_sample / dt_factor - 1e-9)
        dt = scene.sample_dt_s / steps_per_sample
    steps = float(scene.n_samples - 1) * steps_per_sample * max(1, moving)
    return stepped_cost(scene, solver, steps, dt, steps * seconds_per_body_step)


def stepped_cost(scene: Scene, solver: str, steps: float, dt: float, run_time_s: float) -> CostEstimate:
    """The cost of a run of ``steps`` body-steps at ``dt`` (s) taking ``run_time_s`` (s) that
    records what a DEM run records (a solver with its own time step: Siconos)."""
    corners = sum(len(b.vertices_m or ()) or 4 for b in scene.blocks)
    columns = 2 + 6 * len(scene.blocks) + corners + 7
    return _estimate(scene, solver, steps, dt, columns, run_time_s)


def sample_cost(scene: Scene, solver: str) -> CostEstimate:
    """The cost of a run whose work grows with its output samples (Housner's exact solution):
    one 'step' per sample, the time history of every block."""
    columns = 2 + 6 * len(scene.blocks)
    return _estimate(scene, solver, float(scene.n_samples), math.nan, columns, 0.0)


def estimate_dict(estimate: CostEstimate) -> dict[str, Any]:
    """The estimate as a JSON-ready dictionary."""
    return dataclasses.asdict(estimate)


def numba_cached(*kernels: object) -> bool:
    """Whether running ``kernels`` (compiled functions) compiles nothing: each is loaded in this
    process already, or numba's on-disk cache holds it; else the first run in a process
    compiles it (a minute of CPU). Read from numba's index of each function's cache, empty when
    missing or of another source (stale); should numba's internals move, the cache is taken to
    be there (the smaller estimate). A cache found is remembered for the process."""
    for kernel in kernels:
        if getattr(kernel, "overloads", None) or id(kernel) in _FOUND_CACHED:
            continue
        try:
            cache: Any = getattr(kernel, "_cache", None)
            if not cache._cache_file._load_index():
                return False
        except Exception:
            return True
        _FOUND_CACHED.add(id(kernel))
    return True


#: ``id`` of the compiled functions whose on-disk cache :func:`numba_cached` found (module-level
#: functions: they live as long as the process).
_FOUND_CACHED: set[int] = set()
