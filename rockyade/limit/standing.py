"""Whether a scene's loads can be carried at rest: the rule every solver applies before a run.

A scene whose ``[[loads]]`` lift blocks off their supports (a load larger than the weight it
pulls up, a course pulled off the one below: tension no joint carries) does not rock: its blocks
leave their supports for good. Such a run has no meaning whatever the solver
makes of it (Housner's Eq 1 with a load larger than the weight, a DEM's block flying off, a
"numerical instability"), so every solver refuses it before it starts
(:meth:`rockyade.solvers.base.SolverBase` calls :func:`check_loads_stand` on every scene with
loads), and ``rockyade limit`` explains its "unstable" with the same words
(:func:`unbalanced_loads`).

The test is the lower-bound programme of :mod:`rockyade.limit.lp` at rest (no horizontal
acceleration) with the loads scaled by s: maximise s in [0, 1] such that every moving block is in
equilibrium under its weight, s times the loads and contact forces with no tension and
Coulomb's friction (Livesley 1978). If s < 1 the loads cannot be carried; the programme's dual
is the mechanism by which they move the blocks; when the weight and loads of the blocks that
move pull them up together, they fly apart and the run is refused. Loads that overturn or slide
blocks at rest (the moving blocks still pressed down) are a collapse the dynamics show: those
scenes run (Housner overturns a block tipped by a horizontal load). A scene that cannot stand
under its weight alone (s = 0 infeasible: an overhang that topples) is not this rule's either.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from rockyade.errors import InputError
from rockyade.limit.lp import equilibrium_system, highs_method
from rockyade.limit.rigid_blocks import RigidBlockModel, rigid_block_model

#: Loads carried up to this fraction of themselves count as carried (the programme's tolerance).
CARRIED_FRACTION = 1.0 - 1.0e-7
#: Velocities below this fraction of the largest are zero (a block at rest in the mechanism).
VELOCITY_TOL = 1.0e-6


@dataclass(frozen=True)
class UnbalancedLoads:
    """Loads no equilibrium at rest can carry (:func:`unbalanced_loads`).

    Attributes
    ----------
    carried_fraction
        The largest fraction s of the loads that can be carried, in [0, 1).
    moving
        Names of the blocks the loads move (the mechanism's).
    loads
        Indices of the scene's ``[[loads]]`` that do work in the mechanism (they move it).
    lifted
        Names of moving blocks the mechanism lifts (their centroid moves up more than sideways).
    flies_apart
        True when the weight and the loads of the moving blocks together pull them up: they leave
        their supports for good (a load larger than what it lifts, a course pulled off): no solver's
        run of it means anything. False: the loads overturn or slide the blocks at rest, a collapse
        that the dynamics show (they run).
    message
        The whole in words: the loads, their blocks, what happens, the largest fraction carried.
    """

    carried_fraction: float
    moving: tuple[str, ...]
    loads: tuple[int, ...]
    lifted: tuple[str, ...]
    flies_apart: bool
    message: str


def unbalanced_loads(scene, model: RigidBlockModel | None = None) -> UnbalancedLoads | None:
    """The scene's loads that cannot be carried at rest, or None when they can (or it has none).

    Parameters
    ----------
    scene
        A validated :class:`~rockyade.scene.Scene`.
    model
        Its rigid-block model, when already built (default: :func:`rigid_block_model` of ``scene``).
    """
    if not tuple(getattr(scene, "loads", ())):
        return None
    return unbalanced_loads_of_model(rigid_block_model(scene) if model is None else model)


def unbalanced_loads_of_model(model: RigidBlockModel) -> UnbalancedLoads | None:
    """:func:`unbalanced_loads` of a rigid-block model (its loads: the scene's and any added)."""
    if not model.loads:
        return None
    A, b1, lam_col, free, row_of, (_, l_ref) = equilibrium_system(model, "+x")
    b0 = equilibrium_system(replace(model, loads=()), "+x")[1]
    # columns: contact forces, then s; A_c f - s (b1 - b0) = b0; maximise s in [0, 1]
    A_eq = sp.hstack([A[:, :lam_col], sp.csr_matrix((b0 - b1).reshape(-1, 1))], format="csr")
    n_cols = lam_col + 1
    c = np.zeros(n_cols)
    c[-1] = -1.0
    lower = np.append(np.where(free, -np.inf, 0.0), 0.0)
    upper = np.append(np.full(lam_col, np.inf), 1.0)
    res = linprog(c, A_eq=A_eq, b_eq=b0, bounds=np.column_stack([lower, upper]), method=highs_method("highs", n_cols))
    if res.status != 0:
        return None  # it cannot stand under its weight alone: a collapse the dynamics show, not this rule's
    s = float(res.x[-1])
    if s >= CARRIED_FRACTION:
        return None
    y = -np.asarray(res.eqlin.marginals)
    velocities = np.zeros((model.n_blocks, 3))
    r = row_of[model.moving]
    velocities[model.moving] = np.column_stack([y[r], y[r + 1], y[r + 2] / l_ref])
    scale = float(np.max(np.abs(velocities[:, :2]))) + float(np.max(np.abs(velocities[:, 2]))) * l_ref
    moves = np.abs(velocities[:, :2]).max(axis=1) + np.abs(velocities[:, 2]) * l_ref > VELOCITY_TOL * max(scale, 1e-300)
    moving = tuple(model.names[i] for i in np.flatnonzero(moves))
    lifted = tuple(
        model.names[i]
        for i in np.flatnonzero(moves)
        if velocities[i, 1] > 0 and velocities[i, 1] >= abs(velocities[i, 0])
    )
    working = []
    for k, load in enumerate(model.loads):
        i = int(load.block)
        v = velocities[i]
        arm = np.asarray(load.point_m) - model.centroids_m[i]
        point_velocity = np.array([v[0] - v[2] * arm[1], v[1] + v[2] * arm[0]])
        if moves[i] and float(np.dot(point_velocity, load.force_N)) > 0.0:
            working.append(k)
    working = working or [k for k, load in enumerate(model.loads) if moves[int(load.block)]]
    # the moving blocks' weight and loads together: pulled up, they leave their supports for good
    net_up = -float(model.masses_kg[moves].sum() * model.g) + sum(
        float(load.force_N[1]) for load in model.loads if moves[int(load.block)]
    )
    flies = net_up > 0.0
    message = _words(model, s, moving, tuple(working), lifted if flies else ())
    return UnbalancedLoads(s, moving, tuple(working), lifted if flies else (), flies, message)


def _words(model: RigidBlockModel, s: float, moving, working, lifted) -> str:
    said = []
    for k in working[:5]:
        load = model.loads[k]
        name = model.names[int(load.block)]
        fx, fy = load.force_N
        weight = float(model.masses_kg[int(load.block)] * model.g)
        said.append(f"loads[{k}], ({fx:g}, {fy:g}) N on {name} (its weight {weight:.0f} N)")
    loads = ("the load " if len(working) == 1 else "the loads ") + ", ".join(said)
    loads += f" and {len(working) - 5} more" if len(working) > 5 else ""
    verb = "lifts" if len(working) == 1 else "lift"
    if lifted:
        lift = ", ".join(lifted[:8]) + (" ..." if len(lifted) > 8 else "")
        what = (
            f"{verb} {lift} off {'its' if len(lifted) == 1 else 'their'} supports for good (a joint carries no tension)"
        )
        return (
            f"{loads} {what}; at rest at most {100 * s:.3g} % of it can be carried, so the scene cannot stand "
            "(rockyade limit: unstable) and a run of it would mean nothing: reduce the load, or add the mass or "
            "restraint that carries it"
        )
    shown = ", ".join(moving[:8]) + (" ..." if len(moving) > 8 else "")
    return (
        f"{loads} {'overturns or slides' if len(working) == 1 else 'overturn or slide'} {shown} at rest (at most "
        f"{100 * s:.3g} % of it can be carried): the scene cannot stand (rockyade limit: unstable), and a run "
        "shows it collapse"
    )


def check_loads_stand(scene, model: RigidBlockModel | None = None) -> None:
    """Refuse (InputError naming the load) a scene whose loads cannot be carried at rest: the rule
    every solver applies before a run (module docstring)."""
    found = unbalanced_loads(scene, model)
    if found is not None and found.flies_apart:
        field = f"loads[{found.loads[0]}]" if found.loads else "loads"
        raise InputError(field, found.message, getattr(scene, "source", None))
