"""The cost limits of one run, checked before anything runs.

:func:`check_cost` refuses a run whose estimate (each solver's ``estimate_cost``,
:mod:`rockyade.solvers.cost_estimate`) is above :data:`LIMITS` with an
:class:`~rockyade.errors.InputError` naming what is too large, by how much, and the input
that sets it; ``allow_large=True`` (``--allow-large`` on ``run``, ``compare`` and
``batch``) runs it anyway. The solvers themselves do not check: the command line and the
runner (:func:`rockyade.runner.run_tasks`) do.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rockyade.errors import InputError, at_least, at_most
from rockyade.scene import Scene
from rockyade.solvers.cost_estimate import CostEstimate, duration_text

if TYPE_CHECKING:
    from rockyade.solvers.base import Solver

#: Documented limits of one run (docs/robustness.md); ``allow_large`` lifts them.
LIMITS: dict[str, float] = {
    "integration_steps": 2.0e8,  # body-steps: ~30 s of the reference DEM, hours of YADE
    "output_samples": 2.0e6,  # rows of the result
    "motion_samples": 2.0e7,  # samples of the base motion
    "memory_bytes": 2.0 * 1024**3,  # 2 GiB
    "wall_time_s": 3600.0,  # the solver's estimate, s: binds Siconos (1 ms a body-step), whose steps cost most
}


#: Documented limit of a study's expected wall time (docs/robustness.md), s: the sum of its
#: runs' estimates over its workers (``rockyade crosscheck``, ``rockyade compare``), a night's
#: work; ``allow_large`` lifts it.
MAX_STUDY_S = 8 * 3600.0


def check_study_time(seconds: float, what: str, workers: int = 1, limit_s: float = MAX_STUDY_S) -> None:
    """Refuse a study expected to take more than ``limit_s`` (s) of wall time.

    Parameters
    ----------
    seconds
        The study's expected wall time on ``workers`` workers, s (the solvers' estimates).
    what
        Names the study in the error (e.g. "the cross-check").
    workers
        Its workers (said in the error).

    Raises
    ------
    InputError
        ``allow_large`` (``--allow-large``) named, with the time and the limit.
    """
    if seconds > limit_s:
        raise InputError(
            "allow_large",
            f"{what} is expected to take about {duration_text(seconds)} on {workers} worker(s), above the limit "
            f"of {duration_text(limit_s)}: fewer records, solvers or levels, a coarser time step or resolution, or "
            "pass --allow-large (allow_large=True) to run it anyway",
        )


def estimate_cost(scene: Scene, solver: Solver | str) -> CostEstimate:
    """Estimate the cost of running ``scene`` with ``solver`` (a Solver, or a solver's name)."""
    from rockyade.solvers import as_solver

    return as_solver(solver).estimate_cost(scene)


_WHAT = {
    "integration_steps": ("integration steps", "a larger contact.dt_s or time_step_frac, a shorter duration_s"),
    "output_samples": ("output samples", "a larger sample_dt_s or a shorter duration_s"),
    "motion_samples": ("base-motion samples", "a shorter motion (start_s, cycles, record length)"),
    "memory_bytes": ("bytes of memory", "a larger sample_dt_s, a shorter duration_s or motion"),
    "wall_time_s": ("s of wall time (estimated)", "a larger time step (dt_factor nearer 1), a shorter duration_s"),
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
        f"{where}the {estimate.solver} run needs {at_least(value)} {what}, above the limit {at_most(limit)} "
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


__all__ = ["LIMITS", "MAX_STUDY_S", "check_cost", "check_study_time", "cost_refusal", "estimate_cost"]
