"""Energy terms of the reference DEM, taken so that the balance closes to rounding.

The leap-frog scheme changes the kinetic energy by exactly dt F . v_mean in a step, with
v_mean = (v_{n-1/2} + v_{n+1/2}) / 2; every power is therefore taken with the step-mean
velocities:

* kinetic: (1/2) m v_{n-1/2} . v_{n+1/2} + (1/2) I w_{n-1/2} w_{n+1/2} (the scheme's discrete
  kinetic energy: with the potential and elastic energies at x_n it is conserved exactly for
  gravity and linear springs, so the balance error measures the contacts' switching and the
  dissipation alone);
* potential: m g y_n;
* elastic: K delta^2 / 2 + S^2 / (2 K_s) over the contact points (:mod:`.contact_law`);
* dashpots: the sum over steps of dt (F_n^dash delta_dot + F_s^dash v_t) at each point,
  with delta_dot and v_t from the step-mean velocities, plus the mass-proportional damping's
  work;
* friction: the slip work and the shear energy lost when points open (:mod:`.contact_law`);
* base work: the sum over steps of -m (a_h vx + a_v vy) dt with step-mean velocities (the
  inertial force of the moving base frame).

The dashpot forces of a step are kept in :class:`Dashpots` until the new velocities are
known. Recorded at t_n, the dashpot and base work are the mean of their values before and
after the step (half of the step's work belongs before t_n and half after it).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

# energy columns
E_KIN, E_POT, E_EL, E_DASH, E_FRIC, W_BASE = range(6)
N_ENERGY = 6

#: The running totals carried from step to step (:func:`new_totals`): the elastic energy of
#: the last step's points, the dashpot, friction and base work so far, J.
T_EL, T_DASH, T_FRIC, T_BASE = range(4)


class Dashpots(NamedTuple):
    """The contact points of the current step, for the dashpot power."""

    bodies: NDArray[np.int64]  #: (cap, 2) body a, body b (-1: the base)
    data: NDArray[np.float64]  #: (cap, 6) point x, y (m), normal and shear dashpot forces (N), normal x, y


@numba.njit(cache=True, nogil=True, inline="always")
def new_totals():
    """Running energy totals at t = 0 (indices ``T_*``)."""
    return np.zeros(4)


@numba.njit(cache=True, nogil=True, inline="always")
def new_dashpots(cap: int) -> Dashpots:
    """Room for ``cap`` contact points."""
    return Dashpots(np.zeros((cap, 2), dtype=np.int64), np.zeros((cap, 6)))


@numba.njit(cache=True, nogil=True, inline="always")
def dashpot_room(record_energy: bool, n_base: int, n_pairs: int, old: Dashpots) -> Dashpots:
    """``old``, or a larger buffer when ``n_base`` base points and two points per pair no
    longer fit (one entry without energy terms)."""
    cap = n_base + 2 * n_pairs + 1 if record_energy else 1
    if cap > old.bodies.shape[0]:
        return new_dashpots(cap)
    return old


@numba.njit(cache=True, nogil=True, inline="always")
def push_dashpot(
    dash, n: int, a: int, b: int, px: float, py: float, f_normal: float, f_shear: float, nx: float, ny: float
) -> int:
    """Keep contact point ``n`` (between a and b, -1 the base); returns n + 1."""
    ab, data = dash.bodies, dash.data
    ab[n, 0] = a
    ab[n, 1] = b
    data[n, 0] = px
    data[n, 1] = py
    data[n, 2] = f_normal
    data[n, 3] = f_shear
    data[n, 4] = nx
    data[n, 5] = ny
    return n + 1


@numba.njit(cache=True, nogil=True, inline="always")
def add_dashpot_work(e_dash: float, dash, n_contacts: int, kin, dt: float) -> float:
    """``e_dash`` plus this step's dashpot work at the kept points, with the step-mean
    velocities (``kin``: :class:`rockyade.kernel.integration.Motion` after the kick), J;
    ``dt`` the time step, s."""
    pos, vel, vel_prev, angvel, angvel_prev = kin.pos, kin.vel, kin.vel_prev, kin.angvel, kin.angvel_prev
    ab, data = dash.bodies, dash.data
    for c in range(n_contacts):
        a = ab[c, 0]
        b = ab[c, 1]
        px = data[c, 0]
        py = data[c, 1]
        w = 0.5 * (angvel[a] + angvel_prev[a])
        vrx = 0.5 * (vel[a, 0] + vel_prev[a, 0]) - w * (py - pos[a, 1])
        vry = 0.5 * (vel[a, 1] + vel_prev[a, 1]) + w * (px - pos[a, 0])
        if b >= 0:
            w = 0.5 * (angvel[b] + angvel_prev[b])
            vrx -= 0.5 * (vel[b, 0] + vel_prev[b, 0]) - w * (py - pos[b, 1])
            vry -= 0.5 * (vel[b, 1] + vel_prev[b, 1]) + w * (px - pos[b, 0])
        nx = data[c, 4]
        ny = data[c, 5]
        ddot = -(vrx * nx + vry * ny)
        vt = -vrx * ny + vry * nx
        e_dash += dt * (data[c, 2] * ddot + data[c, 3] * vt)
    return e_dash


@numba.njit(cache=True, nogil=True, inline="always")
def add_base_work(w_base: float, bodies, kin, ah: float, av: float, dt: float) -> float:
    """``w_base`` plus this step's work of the base frame's inertial force, J (``ah``, ``av``
    the base acceleration, m/s^2; ``dt`` the time step, s)."""
    mass, moving, vel, vel_prev = bodies.mass, bodies.moving, kin.vel, kin.vel_prev
    for a in range(mass.size):
        if moving[a]:
            vx = 0.5 * (vel[a, 0] + vel_prev[a, 0])
            vy = 0.5 * (vel[a, 1] + vel_prev[a, 1])
            w_base += -mass[a] * (ah * vx + av * vy) * dt
    return w_base


@numba.njit(cache=True, nogil=True, inline="always")
def mechanical_energy(bodies, kin, g: float) -> tuple[float, float]:
    """Discrete kinetic energy of the leap-frog scheme and potential energy of the moving
    bodies at t_n, J (module docstring; ``g`` gravity, m/s^2)."""
    mass, inertia, moving = bodies.mass, bodies.inertia, bodies.moving
    pos, vel, vel_prev, angvel, angvel_prev = kin.pos, kin.vel, kin.vel_prev, kin.angvel, kin.angvel_prev
    e_kin = 0.0
    e_pot = 0.0
    for a in range(mass.size):
        if moving[a]:
            e_kin += 0.5 * mass[a] * (vel[a, 0] * vel_prev[a, 0] + vel[a, 1] * vel_prev[a, 1])
            e_kin += 0.5 * inertia[a] * angvel[a] * angvel_prev[a]
            e_pot += mass[a] * g * pos[a, 1]
    return e_kin, e_pot
