"""The lowest admissible mechanism where corners meet: branch and bound over the ways a corner holds.

Where a corner of a moving block meets a corner of a fixed block (or the base), the block may
pass the other on either side (:mod:`rockyade.limit.point_contacts`): the admissible motions there are
a union of two half-planes, which one linear programme cannot hold. The collapse multiplier is the
lowest over the admissible mechanisms (the kinematic theorem), so:

* the programme without such a contact is a relaxation: its multiplier is a lower bound for every
  way of holding the contact (fewer contact forces carry less);
* when the relaxation's mechanism passes every such corner in one of its ways, it is admissible
  and its multiplier is the answer of that branch;
* else the corner it passes through is tried each way in turn (a branch each), lowest bound first.

The search ends when no open branch can go lower than the best admissible mechanism found, which
is then the exact multiplier of the rigid-block model (for associated friction), as for a model
without such corners.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from rockyade.errors import SolverFailedError
from rockyade.limit.lp import LPSolution, solve_equilibrium
from rockyade.limit.mechanism import VELOCITY_TOL, relative_velocity
from rockyade.limit.rigid_blocks import Corner, Interface, RigidBlockModel

#: Programmes solved at most in one search (each branch point doubles the open branches).
MAX_PROGRAMMES = 64


def _held(model: RigidBlockModel, vel, way: tuple[Interface, ...], tol: float) -> float:
    """How far the motion ``vel`` breaks ``way`` (0: it holds), mechanism units."""
    worst = 0.0
    for itf in way:
        dn, dt = relative_velocity(model, vel, itf, itf.ends_m[0])
        mu = None if itf.friction_angle_deg is None else math.tan(math.radians(itf.friction_angle_deg))
        worst = max(worst, -dn, abs(dt)) if mu is None else max(worst, mu * abs(dt) - dn)
    return max(0.0, worst - tol)


def _violation(model: RigidBlockModel, sol: LPSolution, corner: Corner) -> tuple[float, int]:
    """(how far the mechanism passes through ``corner`` in its least broken way, that way)."""
    assert sol.velocities is not None
    vel = sol.velocities / max(float(np.max(np.abs(sol.velocities[:, :2]))), 1e-300)
    scale = max(1.0, float(np.max(np.abs(vel[:, 2]))) * model.size_m)
    broken = [_held(model, vel, way, VELOCITY_TOL * scale) for way in corner.ways]
    k = int(np.argmin(broken))
    return broken[k], k


def _with(model: RigidBlockModel, choice: dict[int, int]) -> RigidBlockModel:
    extra = tuple(itf for c, w in sorted(choice.items()) for itf in model.corners[c].ways[w])
    return replace(model, interfaces=model.interfaces + extra, corners=())


def _way_words(model: RigidBlockModel, corner: Corner, way: int) -> str:
    normals = ", ".join(f"({itf.normal[0]:.3g}, {itf.normal[1]:.3g})" for itf in corner.ways[way])
    x, y = corner.point_m
    return (
        f"{model.body_name(corner.a)}'s corner on {model.body_name(corner.b)} at ({x:.4g}, {y:.4g}) m "
        f"held by contact normal {normals} (way {way + 1} of {len(corner.ways)})"
    )


def solve_admissible(
    model: RigidBlockModel,
    direction: str = "+x",
    method: str = "highs",
    time_limit_s: float | None = None,
    on_progress: Callable[[float, str], None] | None = None,
) -> tuple[LPSolution, RigidBlockModel]:
    """The programme's solution with every corner of ``model.corners`` held in one of its ways, the
    lowest (module docstring), and the model solved (those contacts among its interfaces, the
    choice said in its notes). Without such corners: :func:`~rockyade.limit.lp.solve_equilibrium`.
    ``time_limit_s`` bounds the programmes' time together, s (None: no limit; past it
    :class:`~rockyade.limit.lp.TimeLimitError`); ``on_progress`` as
    :func:`~rockyade.limit.lp.solve_equilibrium`'s.
    """
    if not model.corners:
        return solve_equilibrium(model, direction, method, time_limit_s=time_limit_s, on_progress=on_progress), model
    count = 0
    order = 0
    heap: list[tuple[float, int, dict[int, int]]] = [(-math.inf, order, {})]
    best: tuple[LPSolution, dict[int, int]] | None = None
    fallback: tuple[LPSolution, dict[int, int]] | None = None
    spent = 0.0
    while heap:
        bound, _, choice = heapq.heappop(heap)
        if best is not None and best[0].load_multiplier is not None and bound >= best[0].load_multiplier:
            break
        if count >= MAX_PROGRAMMES:
            raise SolverFailedError(
                f"the search over {len(model.corners)} corner contacts needed more than {MAX_PROGRAMMES} programmes"
            )
        left = None if time_limit_s is None else time_limit_s - spent  # the programmes' time so far
        sol = solve_equilibrium(_with(model, choice), direction, method, time_limit_s=left, on_progress=on_progress)
        count += 1
        spent += sol.solve_time_s
        open_corners = [c for c in range(len(model.corners)) if c not in choice]
        if sol.status == "no_mechanism":
            fallback = fallback or (sol, choice)
            continue
        if sol.status == "unstable":
            if not open_corners:
                best = (sol, choice)  # it falls under gravity with this way held: nothing is lower
                break
            for w in range(len(model.corners[open_corners[0]].ways)):
                order += 1
                heapq.heappush(heap, (bound, order, {**choice, open_corners[0]: w}))
            continue
        assert sol.load_multiplier is not None
        worst, worst_corner, held = 0.0, -1, dict(choice)
        for c in open_corners:
            broken, way = _violation(model, sol, model.corners[c])
            held[c] = way
            if broken > worst:
                worst, worst_corner = broken, c
        if worst_corner < 0:
            if best is None or best[0].load_multiplier is None or sol.load_multiplier < best[0].load_multiplier:
                best = (sol, held)
            continue
        for w in range(len(model.corners[worst_corner].ways)):
            order += 1
            heapq.heappush(heap, (sol.load_multiplier, order, {**choice, worst_corner: w}))
    if best is None:
        if fallback is None:
            raise SolverFailedError("no way of holding the corner contacts gave an answer")
        best = fallback
    sol, choice = best
    solved = _with(model, choice)
    if sol.status == "collapse":
        sol = solve_equilibrium(solved, direction, method, on_progress=on_progress)  # forces for every contact
        spent += sol.solve_time_s
        count += 1
    words = "; ".join(_way_words(model, model.corners[c], w) for c, w in sorted(choice.items()))
    note = (
        f"corner contacts where a corner meets a fixed block's corner can hold two ways; the lowest admissible "
        f"mechanism of {count} programmes has: {words}"
    )
    solved = replace(solved, notes=(*model.notes, note))
    return replace(sol, solve_time_s=spent), solved
