"""What a worker's driver (YADE's, :mod:`rockyade.yade.driver`; Siconos's,
:mod:`rockyade.siconos.driver`) writes beside its samples, typed: :class:`WorkerOutput`.

The drivers run in another Python (YADE's, Debian's) and write their metadata as one JSON
object in the output ``.npz`` (key ``meta``), in the one dialect of
:func:`rockyade.io.driver_loop.output_meta` plus each engine's own diagnostics; the backends
read it once, here, and decide from its attributes whether the samples are a result
(complete, stable, converged) and what the Result's :class:`rockyade.run_meta.RunMeta` says.
A key a driver does not write (the other engine's) takes its default; the names an older
driver wrote (OLDER_NAMES: a ``rockyade yade-script`` folder made before the one dialect) are
read as today's.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from rockyade.run_meta import FrozenMapping


@dataclass(frozen=True)
class WorkerOutput:
    """A driver's metadata (module docstring). Times in s, lengths in m.

    Attributes
    ----------
    status
        completed | overturned | failed | timeout (stopped at its deadline) | running (a flush).
    n_filled
        Samples written.
    complete
        The run ended (False: a flush while running, or a run stopped at its deadline).
    stop_time_s
        When the run stopped (an overturn, an instability), s.
    stop_body
        The body whose overturn stopped the run (its index).
    overturn_times_s
        Per body that fell (its index, as text), when it did, s.
    wall_time_s
        The driver's wall time, s (None: an older driver's partial output).
    process_cpu_s
        The worker process's CPU time, s.
    dt_s
        The time step, s.
    steps
        Time steps taken.
    version
        The engine's version.
    max_polyhedra_penetration_over_radius
        YADE: the deepest vertex sphere in a non-rectangular block over its radius.
    deep_overlap_time_s
        YADE: when that depth first reached the radius, s.
    max_rotation_step_rad
        YADE: the largest rotation between two records, rad.
    rotation_track_period_steps
        YADE: steps between two rotation records.
    solver_calls
        Siconos: friction-contact solves.
    solver_iterations
        Siconos: their iterations, all together.
    unconverged_steps
        Siconos: solves that ended above the tolerance.
    first_unconverged_s
        Siconos: when the first did, s.
    max_residual
        Siconos: the largest residual of a solve.
    max_penetration_m
        Siconos: the deepest penetration, m.
    max_bullet_overlap_m
        Siconos: Bullet's largest overlap, m.
    failure_reason
        Siconos: why the driver stopped a failed run (the step no solver could take).
    retried_steps, retried_steps_converged
        Siconos: steps taken again after the nonsmooth Newton failed, and how many of them a
        fallback solver then took.
    fallback_steps
        Siconos: steps solved by a fallback friction-contact solver.
    loose_steps
        Siconos: steps accepted with a residual between the tolerance and 100 times it.
    friction_solvers
        Siconos: the friction-contact solvers tried, in order.
    """

    status: str
    n_filled: int = 0
    complete: bool = False
    stop_time_s: float | None = None
    stop_body: int | None = None
    overturn_times_s: Mapping[str, float] = field(default_factory=lambda: FrozenMapping())
    wall_time_s: float | None = None
    process_cpu_s: float | None = None
    dt_s: float | None = None
    steps: int = 0
    version: str | None = None
    max_polyhedra_penetration_over_radius: float = 0.0
    deep_overlap_time_s: float | None = None
    max_rotation_step_rad: float | None = None
    rotation_track_period_steps: int | None = None
    solver_calls: int = 0
    solver_iterations: int = 0
    unconverged_steps: int = 0
    first_unconverged_s: float | None = None
    max_residual: float = 0.0
    max_penetration_m: float = 0.0
    max_bullet_overlap_m: float = 0.0
    failure_reason: str | None = None
    retried_steps: int = 0
    retried_steps_converged: int = 0
    fallback_steps: int = 0
    loose_steps: int = 0
    friction_solvers: tuple[str, ...] = ()

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> WorkerOutput:
        """The metadata a driver wrote (module docstring); other keys are left out.

        Raises
        ------
        KeyError
            No ``status``.
        ValueError, TypeError
            A value of the wrong kind.
        """
        named = {OLDER_NAMES.get(k, k): v for k, v in data.items()}
        values: dict[str, Any] = {k: v for k, v in named.items() if k in _FIELDS and v is not None}
        values["status"] = str(data["status"])
        if "version" in values:
            values["version"] = str(values["version"])
        for key in _INTEGERS & values.keys():
            values[key] = int(values[key])
        for key in _FLOATS & values.keys():
            values[key] = float(values[key])
        values["complete"] = bool(values.get("complete", False))
        if "failure_reason" in values:
            values["failure_reason"] = str(values["failure_reason"])
        values["friction_solvers"] = tuple(str(n) for n in values.get("friction_solvers", ()))
        values["overturn_times_s"] = FrozenMapping(
            {str(i): float(t) for i, t in dict(values.get("overturn_times_s", {})).items()}
        )
        return cls(**values)

    @classmethod
    def from_json(cls, text: str) -> WorkerOutput:
        """:meth:`from_dict` of the JSON text a driver wrote."""
        data = json.loads(text)
        if not isinstance(data, dict):
            raise ValueError("the worker's metadata is not a JSON object")
        return cls.from_dict(data)


#: Keys of the drivers before the one dialect -> today's.
OLDER_NAMES = {"iterations": "steps", "yade_version": "version", "siconos_version": "version"}
_FIELDS = frozenset(f.name for f in fields(WorkerOutput))
#: The fields read as integers and as floats (by their annotations).
_INTEGERS = frozenset(f.name for f in fields(WorkerOutput) if f.type in ("int", "int | None"))
_FLOATS = frozenset(f.name for f in fields(WorkerOutput) if f.type in ("float", "float | None"))
