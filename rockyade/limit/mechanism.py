"""The collapse mechanism from the programme's dual: block velocities, hinges, sliding joints, checks.

The dual variables of the equilibrium equations are a virtual velocity (vx, vy, omega) of
each moving block: vx, vy of its centroid and omega counter-clockwise. They are scaled here
so that the largest horizontal velocity of a centroid is 1 along the load (a displacement
field in units of that largest displacement).

At an interface end p the relative velocity of body a with respect to body b is
dv(p) = v_a(p) - v_b(p), v(p) = (vx - omega (p_y - c_y), vy + omega (p_x - c_x)); its
normal part dv_n (opening, >= 0) and tangential part dv_t. An interface is

* *locked* when dv = 0 at both ends (the two bodies move together: not listed);
* a *hinge* when the bodies turn relative to each other about one end (dv = 0 there, the
  other end opens);
* *sliding* when an end slips on the friction cone (dv_t != 0 and, with the LP's associated
  flow, dv_n = tan(phi) |dv_t|: it dilates);
* *separating* otherwise: both ends leave each other (dv_n > tan(phi) |dv_t|), whether or not
  the bodies also turn or move along the joint.

Checks (:class:`MechanismChecks`): the mechanism is kinematically admissible to first
order (no end closes: dv_n >= tan(phi) |dv_t| with friction, dv_n >= 0 and dv_t = 0
without), and the virtual work of gravity, the loads and lambda m g d vanishes at the
multiplier. Both are computed from the geometry, independently of the solver.

Under the non-associated (Coulomb) rule (:mod:`rockyade.limit.coulomb`) a joint with friction
slides without opening: an end *slides* when dv_t != 0 and dv_n = 0, admissibility asks only
dv_n >= 0 there, and the virtual work of gravity, the loads and lambda m g d equals the work
dissipated by friction, sum c |dv_t| over the ends with c the friction capacity of the last
programme (tan(phi) times the normal force the iteration settled on).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import SolverFailedError
from rockyade.limit.lp import DIRECTIONS, LPSolution
from rockyade.limit.rigid_blocks import Interface, RigidBlockModel

#: Relative velocities below this (in units of the largest centroid velocity, 1) are zero.
VELOCITY_TOL = 1.0e-6


@dataclass(frozen=True)
class Hinge:
    """Two bodies turning relative to each other about one end of their interface.

    Attributes
    ----------
    interface
        Index of the interface in the model.
    a, b
        Body names (``b`` may be ``"base"``); the normal points from b into a.
    point_m
        The hinge (pivot) at rest, base frame, m.
    end
        Which end of the interface it is (0 or 1).
    relative_omega
        omega_a - omega_b, in the mechanism's units (counter-clockwise positive).
    """

    interface: int
    a: str
    b: str
    point_m: tuple[float, float]
    end: int
    relative_omega: float

    def to_dict(self) -> dict:
        """Plain data."""
        return {
            "a": self.a,
            "b": self.b,
            "point_m": list(self.point_m),
            "end": self.end,
            "relative_omega": self.relative_omega,
        }


@dataclass(frozen=True)
class Sliding:
    """A joint whose two bodies slip along each other.

    Attributes
    ----------
    interface
        Index of the interface.
    a, b
        Body names (``b`` may be ``"base"``).
    slip
        Relative tangential velocity of a on b along the interface tangent (the normal
        turned counter-clockwise), mechanism units.
    opening
        Relative normal velocity at the interface's mid-point (the dilatancy of the
        associated flow rule, tan(phi) |slip| where nothing turns), mechanism units.
    midpoint_m
        Middle of the interface at rest, m.
    """

    interface: int
    a: str
    b: str
    slip: float
    opening: float
    midpoint_m: tuple[float, float]

    def to_dict(self) -> dict:
        """Plain data."""
        return {
            "a": self.a,
            "b": self.b,
            "slip": self.slip,
            "opening": self.opening,
            "midpoint_m": list(self.midpoint_m),
        }


@dataclass(frozen=True)
class MechanismChecks:
    """Independent checks of a mechanism.

    Attributes
    ----------
    max_closing
        Largest violation of the kinematic constraints over all interface ends, mechanism
        units (0 when admissible): max(0, tan(phi) |dv_t| - dv_n), or without sliding
        max(0, -dv_n, |dv_t|).
    virtual_work_residual
        |lambda W_load + W_gravity + W_loads - D| / (sum of the absolute works), dimensionless; D the
        work dissipated by friction (0 under the associated rule).
    """

    max_closing: float
    virtual_work_residual: float

    def to_dict(self) -> dict:
        """Plain data."""
        return {"max_closing": self.max_closing, "virtual_work_residual": self.virtual_work_residual}


@dataclass(frozen=True)
class Mechanism:
    """The collapse mechanism (module docstring).

    Attributes
    ----------
    velocities
        (nb, 3) vx, vy (centroid, largest |vx| = 1 along the load) and omega (rad per unit
        of that displacement, counter-clockwise) of every block; zeros for blocks at rest.
    moving
        (nb,) True for the blocks that take part (move).
    hinges, sliding, separating
        Interfaces by kind (separating: indices of interfaces that open without turning).
    checks
        :class:`MechanismChecks`.
    """

    velocities: NDArray[np.float64]
    moving: NDArray[np.bool_]
    hinges: tuple[Hinge, ...]
    sliding: tuple[Sliding, ...]
    separating: tuple[int, ...]
    checks: MechanismChecks
    active_points: tuple[tuple[int, int], ...]

    @property
    def slides(self) -> bool:
        """True when a joint slides."""
        return bool(self.sliding)


def point_velocity(v: NDArray[np.float64], centroid: NDArray[np.float64], p: NDArray[np.float64]):
    """Velocity of point ``p`` of a body moving with ``v`` = (vx, vy, omega) about ``centroid``."""
    r = p - centroid
    return np.array([v[0] - v[2] * r[1], v[1] + v[2] * r[0]])


def relative_velocity(model: RigidBlockModel, velocities: NDArray[np.float64], itf: Interface, p) -> NDArray:
    """dv(p) = v_a(p) - v_b(p) in the interface's (normal, tangent) components."""
    va = point_velocity(velocities[itf.a], model.centroids_m[itf.a], p)
    vb = np.zeros(2) if itf.b < 0 else point_velocity(velocities[itf.b], model.centroids_m[itf.b], p)
    dv = va - vb
    return np.array([dv @ itf.normal, dv @ itf.tangent])


def virtual_work(model: RigidBlockModel, velocities: NDArray[np.float64], lam: float, direction: str):
    """(total, sum of absolute parts) of the virtual work of lambda m g d, gravity and the loads."""
    d = DIRECTIONS[direction]
    mg = model.masses_kg * model.g
    parts = [lam * d * mg * velocities[:, 0], -mg * velocities[:, 1]]
    loads = []
    for load in model.loads:
        i = int(load.block)
        v = point_velocity(velocities[i], model.centroids_m[i], np.asarray(load.point_m))
        loads.append(float(np.dot(load.force_N, v)))
    parts.append(np.array(loads))
    total = float(sum(p.sum() for p in parts))
    scale = float(sum(np.abs(p).sum() for p in parts))
    return total, scale


def mechanism_of(model: RigidBlockModel, solution: LPSolution, friction_rule: str = "associated") -> Mechanism:
    """The normalised, classified and checked mechanism of a collapse solution.

    ``friction_rule``: "associated" (the programme's cone, dilatant sliding) or "coulomb" (a solution
    of :func:`rockyade.limit.coulomb.solve_coulomb`: sliding without opening, module docstring).
    """
    coulomb = friction_rule == "coulomb"
    if coulomb and solution.friction_capacity_N is None:
        raise ValueError("the coulomb rule's mechanism needs the capacities of its programme")
    if solution.velocities is None or solution.load_multiplier is None:
        raise ValueError("only a collapse solution has a mechanism")
    vel = solution.velocities.copy()
    vel[model.fixed] = 0.0
    peak = float(np.max(np.abs(vel[:, 0])))
    if peak <= 0.0:
        raise SolverFailedError("the programme's mechanism does not move horizontally (a degenerate dual)")
    vel /= peak
    size = model.size_m
    speed = np.maximum(np.hypot(vel[:, 0], vel[:, 1]), np.abs(vel[:, 2]) * size)
    scale = max(1.0, float(np.max(np.abs(vel[:, 2]))) * size)
    tol = VELOCITY_TOL * scale
    moving = speed > tol
    vel[~moving] = 0.0
    hinges, sliding, separating, active = [], [], [], []
    worst = 0.0
    dissipated = 0.0
    for k, itf in enumerate(model.interfaces):
        rel = [relative_velocity(model, vel, itf, p) for p in itf.ends_m]
        mu = None if itf.friction_angle_deg is None else math.tan(math.radians(itf.friction_angle_deg))
        # the dilatancy of sliding: tan(phi) under the associated rule, none under Coulomb's
        dilatancy = 0.0 if coulomb else (mu or 0.0)
        for e, (dn, dt) in enumerate(rel):
            worst = max(worst, -dn, abs(dt)) if mu is None else max(worst, dilatancy * abs(dt) - dn)
            if coulomb and mu is not None:
                assert solution.friction_capacity_N is not None  # checked above
                dissipated += float(solution.friction_capacity_N[k, e]) * abs(dt)
        closed = [abs(dn) <= tol and abs(dt) <= tol for dn, dt in rel]
        # an end slides when it slips on the friction cone (dv_n = dilatancy |dv_t|); an end that
        # opens by more than that has left the joint, whatever its tangential motion
        slipping = [mu is not None and abs(dt) > tol and dn <= dilatancy * abs(dt) + tol for dn, dt in rel]
        for e in range(2):
            if closed[e] and (moving[itf.a] or (itf.b >= 0 and moving[itf.b])):
                active.append((k, e))
        if all(closed):
            continue
        omega_b = 0.0 if itf.b < 0 else vel[itf.b, 2]
        d_omega = float(vel[itf.a, 2] - omega_b)
        name_a, name_b = model.body_name(itf.a), model.body_name(itf.b)
        slip = 0.5 * (rel[0][1] + rel[1][1])
        if any(slipping):
            mid = itf.ends_m.mean(axis=0)
            opening = 0.5 * (rel[0][0] + rel[1][0])
            sliding.append(Sliding(k, name_a, name_b, float(slip), float(opening), (float(mid[0]), float(mid[1]))))
        elif abs(d_omega) * itf.length_m > tol and any(closed):
            e = closed.index(True)
            p = itf.ends_m[e]
            hinges.append(Hinge(k, name_a, name_b, (float(p[0]), float(p[1])), e, d_omega))
        else:
            separating.append(k)
    total, scale_w = virtual_work(model, vel, solution.load_multiplier, solution.direction)
    total, scale_w = total - dissipated, scale_w + dissipated
    checks = MechanismChecks(max(worst, 0.0), abs(total) / scale_w if scale_w > 0 else 0.0)
    return Mechanism(vel, moving, tuple(hinges), tuple(sliding), tuple(separating), checks, tuple(active))
