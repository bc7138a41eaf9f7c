"""A scene as the JSON data the Siconos driver (:mod:`rockyade.siconos.driver`) reads.

Scenes are data, never code. The blocks are the DEMs' (:func:`rockyade.calibration.model_stage.calibrated_model`):
contact polygons with the base corners at the equivalent base b_eq (paper Eq 11, so that the
model's alpha is the scene's), masses and centroidal inertias set so that I_O = M g R / p^2
(the scene's p), the ground acceleration samples every solver gets
(:mod:`rockyade.motion.ground`), the loads, the initial state (free-rocking starts
included) and the overturn angles. The DEMs' contact stiffness and damping are not used:
a nonsmooth contact has none. The friction coefficient of each pair of bodies is the DEMs'
(:meth:`rockyade.dem.joints.JointTable.joint_for`).

Same role as :mod:`rockyade.yade.payload`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rockyade.dem.model import DemModel
from rockyade.dem.worker_backend import body_payload

FORMAT = "rockyade-siconos-scene-1"
#: Bullet keeps a contact point while the gap is below this fraction of the smallest block size.
CONTACT_BREAKING_FRACTION = 0.04
#: Moreau-Jean's theta (0.5: the midpoint rule, energy-conserving between impacts).
THETA = 0.5
#: Radius of the vertex disks that carry every contact, as a fraction of the smallest block
#: dimension (the bearing points move this far in from the corners: alpha changes by about
#: this fraction of b / R).
DISK_FRACTION = 1e-3
#: A vertex and another block's edge make a contact pair when, at the start, the vertex is
#: within this fraction of the smaller block's smallest dimension of the edge, its foot on
#: the edge's line within the edge by as much, and the vertex's block lies on the edge's
#: outer side (the vertex-to-edge contacts of the reference DEM).
PAIR_GAP_FRACTION = 0.05
#: ... and a vertex as far as this fraction of the smaller block's largest dimension outside
#: the edge (a corner lifted at the start, as a free-rocking block's, over the seat it lands on).
PAIR_REACH_FRACTION = 0.25
#: A vertex and the ground make a pair when the vertex starts below this fraction of its
#: block's height.
GROUND_PAIR_FRACTION = 0.3
#: Beyond this many contact groups, one friction coefficient (the lowest) for all.
MAX_GROUPS = 64
#: A run fails when a vertex goes deeper below the ground than this fraction of the smallest
#: block dimension: the block went through the ground (the driver opens a pair whose vertex is
#: deeper than that: its DEEP_FRACTION). Moreau-Jean's landing leaves at most about dt x the
#: landing speed (3 mm for a 0.5 m fall at dt 1e-3 s; measured: 0.2 mm at dt 2.6e-4 s).
PENETRATION_FRACTION = 0.25
#: How the one-step problem is built and solved: "numerics" (assembled with numpy, solved by
#: Siconos's numerics: rockyade.siconos.moreau_jean) or "kernel" (Siconos's TimeStepping).
INTEGRATORS = ("numerics", "kernel")


@dataclass(frozen=True)
class Numerics:
    """How the driver steps and solves.

    Attributes
    ----------
    dt_s
        Time step, s (divides the sample interval).
    integrator
        "numerics" (the one-step problem assembled with numpy and solved by Siconos's
        numerics, :mod:`rockyade.siconos.moreau_jean`) or "kernel" (Siconos's TimeStepping;
        ``friction_solver`` and ``fallback_solvers`` apply to it only).
    steps_per_sample
        Steps between two samples.
    restitution
        Newton restitution coefficient at every contact (0: perfectly inelastic impacts,
        so that the block's geometry alone sets its restitution, Housner's Eq 4).
    friction_solver
        The friction-contact solver: "nsn" (Alart-Curnier nonsmooth Newton, the default:
        a few iterations a step on stacked contacts) or "nsgs" (Gauss-Seidel: thousands of
        iterations on a stack, whose two contacts per joint make it hyperstatic).
    fallback_solvers
        Solvers that take again, from the state before it, a step the first one failed
        (Siconos raised, the residual stayed above ``solver_tol``, or the state ran away):
        NSGS by default, unaffected by the redundant contacts of a wall or an arch, on which
        the nonsmooth Newton's LU factorisation is singular.
    solver_tol, solver_max_iter
        Tolerance and iteration cap of the friction-contact solver.
    newton_max_iter, newton_tol
        Newton iterations per step on the nonlinear kinematics, and their tolerance.
    """

    dt_s: float
    steps_per_sample: int
    restitution: float = 0.0
    integrator: str = "numerics"
    friction_solver: str = "nsn"
    fallback_solvers: tuple[str, ...] = ("nsgs", "admm")
    solver_tol: float = 1e-8
    solver_max_iter: int = 1000
    newton_max_iter: int = 1
    newton_tol: float = 1e-10


def _friction(model: DemModel, a: int, b: int) -> float:
    j = model.joints.params[model.joints.joint_for(a, b)]
    return math.tan(math.radians(j.friction_angle_deg))


def contact_laws(model: DemModel) -> tuple[list[tuple[int, int]], list[dict[str, float | int]]]:
    """Each body's contactor groups (its hull, its vertex disks) and the friction laws.

    The ground is group 0. A law acts between a body's vertex disks and another body's
    hull or the ground only (no hull-hull law: Bullet puts a single point in the middle of a
    face-on-face contact, so a stack would stand on pins; measured, a 5-block stack fell).
    One hull group and one disk group for all when every pair has the same friction
    coefficient (or there are more than MAX_GROUPS bodies: then the lowest); else two groups
    per body and a law for every pair.
    """
    nb = len(model.bodies)
    base: dict[int, float] = {}
    pairs: dict[tuple[int, int], float] = {}
    for a in range(nb):
        if not model.bodies[a].fixed:
            base[a] = _friction(model, a, -1)
        for b in range(a + 1, nb):
            if model.bodies[a].fixed and model.bodies[b].fixed:
                continue
            pairs[(a, b)] = _friction(model, a, b)
    values = sorted(set(base.values()) | set(pairs.values()))
    if len(values) <= 1 or 2 * nb + 1 > MAX_GROUPS:
        mu = values[0] if values else 0.6
        return [(1, 2)] * nb, [{"g1": 2, "g2": 0, "mu": mu}, {"g1": 2, "g2": 1, "mu": mu}]
    groups = [(2 * i + 1, 2 * i + 2) for i in range(nb)]
    laws: list[dict[str, float | int]] = [{"g1": groups[a][1], "g2": 0, "mu": mu} for a, mu in base.items()]
    for (a, b), mu in pairs.items():
        laws.append({"g1": groups[a][1], "g2": groups[b][0], "mu": mu})
        laws.append({"g1": groups[b][1], "g2": groups[a][0], "mu": mu})
    return groups, laws


def friction_pairs(model: DemModel) -> list[dict[str, float | int]]:
    """The friction coefficient of every pair of bodies that may touch (b = -1: the ground),
    the DEMs' (tan of the joint's friction angle)."""
    nb = len(model.bodies)
    out: list[dict[str, float | int]] = []
    for a in range(nb):
        if not model.bodies[a].fixed:
            out.append({"a": a, "b": -1, "mu": _friction(model, a, -1)})
        for b in range(a + 1, nb):
            if not (model.bodies[a].fixed and model.bodies[b].fixed):
                out.append({"a": a, "b": b, "mu": _friction(model, a, b)})
    return out


def disk_radius(model: DemModel) -> float:
    """Radius of the vertex disks, m: DISK_FRACTION of the smallest block dimension."""
    return DISK_FRACTION * min(float(np.min(np.ptp(b.contact_vertices_m, axis=0))) for b in model.bodies)


def disk_centres(vertices: np.ndarray, radius: float) -> np.ndarray:
    """(n, 2) centres of the vertex disks: each inside the polygon, tangent to the two edges
    of its vertex (on the bisector, radius / sin(half the interior angle) from the vertex).
    A block at rest then bears on points radius x cot(half angle) from its corners
    (``radius`` for a rectangle)."""
    v = np.asarray(vertices, dtype=float)
    out = np.empty_like(v)
    n = len(v)
    for k in range(n):
        e1 = v[k - 1] - v[k]
        e2 = v[(k + 1) % n] - v[k]
        e1 /= np.hypot(*e1)
        e2 /= np.hypot(*e2)
        u = e1 + e2
        u /= np.hypot(*u)
        half = math.acos(max(-1.0, min(1.0, float(u @ e2))))
        out[k] = v[k] + radius / math.sin(half) * u
    return out


def penetration_bound(model: DemModel) -> float:
    """The depth below the ground beyond which a run fails, m: PENETRATION_FRACTION of the
    smallest block dimension."""
    return PENETRATION_FRACTION * min(float(np.min(np.ptp(b.contact_vertices_m, axis=0))) for b in model.bodies)


def scene_payload(model: DemModel, numerics: Numerics) -> dict[str, object]:
    """The model as the JSON data the Siconos driver reads.

    Parameters
    ----------
    model
        The scene's DEM model (its geometry, inertia, motion, loads and start).
    numerics
        Time step and solver settings.
    """
    groups, laws = contact_laws(model)
    radius = disk_radius(model)
    bodies = []
    for i, b in enumerate(model.bodies):
        load = None
        if model.load_force_N is not None and model.load_arm_Nm is not None and not b.fixed:
            f = [float(v) for v in model.load_force_N[i]]
            arm = [float(v) for v in model.load_arm_Nm[i]]
            if any(f) or any(arm):
                load = {"force_N": f, "arm_Nm": arm}
        bodies.append(
            {
                **body_payload(model, i),
                "disk_centres_m": disk_centres(b.contact_vertices_m, radius).tolist(),
                "hull_group": groups[i][0],
                "disk_group": groups[i][1],
                "load": load,
            }
        )
    motion = model.motion
    n_steps = (model.n_samples - 1) * numerics.steps_per_sample
    return {
        "format": FORMAT,
        "scene_hash": model.scene_hash,
        "dt_s": numerics.dt_s,
        "n_steps": n_steps,
        "steps_per_sample": numerics.steps_per_sample,
        "n_samples": model.n_samples,
        "g": model.g,
        "stop_on_overturn": bool(model.stop_on_overturn),
        "restitution": numerics.restitution,
        "integrator": numerics.integrator,
        "max_penetration_m": penetration_bound(model),
        "theta": THETA,
        "friction_solver": numerics.friction_solver,
        "fallback_solvers": list(numerics.fallback_solvers),
        "solver_tol": numerics.solver_tol,
        "solver_max_iter": numerics.solver_max_iter,
        "newton_max_iter": numerics.newton_max_iter,
        "newton_tol": numerics.newton_tol,
        "contact_breaking_fraction": CONTACT_BREAKING_FRACTION,
        "disk_radius_m": radius,
        "laws": laws,
        "friction_pairs": friction_pairs(model),
        "pair_gap_fraction": PAIR_GAP_FRACTION,
        "pair_reach_fraction": PAIR_REACH_FRACTION,
        "ground_pair_fraction": GROUND_PAIR_FRACTION,
        "bodies": bodies,
        "motion": None
        if motion is None
        else {"t_s": motion.t_s.tolist(), "ah_m_s2": motion.ah_m_s2.tolist(), "av_m_s2": motion.av_m_s2.tolist()},
    }
