"""Integration: the explicit central-difference (leap-frog) scheme of YADE's NewtonIntegrator.

Forces at x_n with velocities v_{n-1/2}; then

    v_{n+1/2} = v_{n-1/2} + dt F / m,    w_{n+1/2} = w_{n-1/2} + dt T / I,
    x_{n+1}   = x_n + dt v_{n+1/2},      theta_{n+1} = theta_n + dt w_{n+1/2}.

Everything is written in the frame of the base, which moves with the prescribed ground
acceleration: each moving body feels m (-a_h, -g - a_v); fixed bodies move with the base
(they never move in this frame). An optional mass-proportional damping adds
-a (m v, m v, I w) with v the velocity v_{n-1/2}.

After the positions move, a body that reaches |theta| >= its stop angle has overturned
(its first time is kept), and a state beyond ``MAX_SPEED_M_S`` / ``MAX_SPIN_RAD_S`` or not
finite is a numerical blow-up: the run fails.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.step import (
    MAX_SPEED_M_S,
    MAX_SPIN_RAD_S,
    beyond_stop_angle,
    damping,
    drifted,
    kicked,
)

__all__ = ["MAX_SPEED_M_S", "MAX_SPIN_RAD_S", "STATUS_COMPLETED", "STATUS_FAILED", "STATUS_OVERTURNED"]

STATUS_COMPLETED, STATUS_OVERTURNED, STATUS_FAILED = 0, 1, 2


class Motion(NamedTuple):
    """The bodies' state and this step's loads (arrays updated in place)."""

    pos: NDArray[np.float64]  #: (nb, 2) centroids x_n, m
    ang: NDArray[np.float64]  #: (nb,) angles theta_n, rad
    vel: NDArray[np.float64]  #: (nb, 2) v_{n-1/2}, then v_{n+1/2} after the kick, m/s
    angvel: NDArray[np.float64]  #: (nb,) w_{n-1/2}, then w_{n+1/2}, rad/s
    vel_prev: NDArray[np.float64]  #: (nb, 2) v_{n-1/2} after the kick, m/s
    angvel_prev: NDArray[np.float64]  #: (nb,) w_{n-1/2} after the kick, rad/s
    force: NDArray[np.float64]  #: (nb, 2) N
    torque: NDArray[np.float64]  #: (nb,) N m


@numba.njit(cache=True, nogil=True, inline="always")
def initial_motion(bodies, initial) -> Motion:
    """The state at t = 0 from :class:`rockyade.kernel.state.Initial` (copied; fixed bodies
    at rest)."""
    pos = initial.pos.copy()
    vel = initial.vel.copy()
    angvel = initial.angvel.copy()
    for a in range(bodies.mass.shape[0]):
        if not bodies.moving[a]:
            vel[a, 0] = 0.0
            vel[a, 1] = 0.0
            angvel[a] = 0.0
    nb = pos.shape[0]
    return Motion(pos, initial.ang.copy(), vel, angvel, vel.copy(), angvel.copy(), np.zeros((nb, 2)), np.zeros(nb))


@numba.njit(cache=True, nogil=True, inline="always")
def apply_body_loads(bodies, kin, g: float, ah: float, av: float) -> None:
    """Start this step's forces from gravity and the base frame's inertia, m (-a_h, -g - a_v).

    Parameters
    ----------
    g, ah, av
        Gravity and the horizontal and vertical base acceleration, m/s^2.
    """
    mass, force, torque = bodies.mass, kin.force, kin.torque
    for a in range(mass.size):
        force[a, 0] = -mass[a] * ah
        force[a, 1] = -mass[a] * (g + av)
        torque[a] = 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def kick(bodies, kin, dt: float, mass_damping: float, record_energy: bool, e_dash: float) -> float:
    """Velocities v_{n-1/2} -> v_{n+1/2} of the moving bodies (kept in ``vel_prev``) under
    the forces and the mass-proportional damping.

    Parameters
    ----------
    dt
        Time step, s.
    mass_damping
        Mass-proportional damping a, 1/s.
    e_dash
        Dashpot work so far, J.

    Returns
    -------
    float
        ``e_dash`` plus the damping's dissipation with the step-mean velocities (with
        ``record_energy``), J.
    """
    mass, inertia, moving = bodies.mass, bodies.inertia, bodies.moving
    vel, angvel, vel_prev, angvel_prev = kin.vel, kin.angvel, kin.vel_prev, kin.angvel_prev
    force, torque = kin.force, kin.torque
    for a in range(mass.size):
        if not moving[a]:
            continue
        vel_prev[a, 0] = vel[a, 0]
        vel_prev[a, 1] = vel[a, 1]
        angvel_prev[a] = angvel[a]
        fdx = 0.0
        fdy = 0.0
        tdz = 0.0
        if mass_damping > 0.0:
            fdx, fdy, tdz = damping(mass[a], inertia[a], mass_damping, vel[a, 0], vel[a, 1], angvel[a])
            force[a, 0] += fdx
            force[a, 1] += fdy
            torque[a] += tdz
        vel[a, 0] = kicked(vel[a, 0], force[a, 0], mass[a], dt)
        vel[a, 1] = kicked(vel[a, 1], force[a, 1], mass[a], dt)
        angvel[a] = kicked(angvel[a], torque[a], inertia[a], dt)
        if record_energy and mass_damping > 0.0:
            e_dash -= dt * (
                fdx * 0.5 * (vel[a, 0] + vel_prev[a, 0])
                + fdy * 0.5 * (vel[a, 1] + vel_prev[a, 1])
                + tdz * 0.5 * (angvel[a] + angvel_prev[a])
            )
    return e_dash


@numba.njit(cache=True, nogil=True, inline="always")
def drift(bodies, kin, samples, step: int, dt: float, stop_on_overturn: bool, status: int) -> tuple[int, int]:
    """Positions x_n -> x_{n+1} of the moving bodies, then the overturn and sanity checks.

    Parameters
    ----------
    samples
        :class:`rockyade.kernel.recording.Samples`: ``overturn_time``, the first time each
        body reached its stop angle, s (NaN: never), is updated.
    step, dt
        The step just integrated (t_n = step dt) and the time step, s.
    status
        The run's status so far (``STATUS_COMPLETED``).

    Returns
    -------
    status, stop_body
        ``STATUS_FAILED`` (a blow-up), ``STATUS_OVERTURNED`` (with ``stop_on_overturn``) or
        ``status`` unchanged, and the body that ended the run (-1: none).
    """
    pos, ang, vel, angvel = kin.pos, kin.ang, kin.vel, kin.angvel
    moving, rest_ang, stop_angle = bodies.moving, bodies.rest_ang, bodies.stop_angle
    overturn_t = samples.overturn_time
    stop_body = -1
    for a in range(moving.size):
        if not moving[a]:
            continue
        pos[a, 0] = drifted(pos[a, 0], vel[a, 0], dt)
        pos[a, 1] = drifted(pos[a, 1], vel[a, 1], dt)
        ang[a] = drifted(ang[a], angvel[a], dt)
        finite = math.isfinite(pos[a, 0]) and math.isfinite(pos[a, 1]) and math.isfinite(ang[a])
        # the blow-up test of :func:`.step.blown_up` with the positions' finiteness (then the
        # velocities are finite, and the two forms decide the same); written with > here, which
        # keeps this loop's compiled code as it was (measured: the other form costs ~3 %)
        speed2 = vel[a, 0] * vel[a, 0] + vel[a, 1] * vel[a, 1]
        if not finite or speed2 > MAX_SPEED_M_S * MAX_SPEED_M_S or abs(angvel[a]) > MAX_SPIN_RAD_S:
            status = STATUS_FAILED
            stop_body = a
        elif beyond_stop_angle(ang[a], rest_ang[a], stop_angle[a]) and math.isnan(overturn_t[a]):
            overturn_t[a] = (step + 1) * dt
            if stop_on_overturn and status == STATUS_COMPLETED:
                status = STATUS_OVERTURNED
                stop_body = a
    return status, stop_body
