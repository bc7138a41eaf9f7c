"""Contacts with the base: every vertex of a moving body below the half-plane y <= 0.

At a vertex p of body a (centroid x_a) the base normal is n = (0, 1) and the tangent
t = (-1, 0); the penetration is delta = -p_y, and with r = p - x_a the relative velocity is
v_a + w_a x r, so delta_dot = -v_y and v_t = -v_x. The law (:mod:`.contact_law`) gives
F_n, S and the shear dashpot; the force F_n n - (S + c_s v_t) t = (S + c_s v_t, F_n) acts
at p. Each vertex keeps its own shear spring (the base has no side planes to clip to);
it is reset when the vertex leaves the base.

A body is skipped while its box is above the base and it touched nothing last step.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.contact_law import add_released_energy, add_stored_energy, joint_law
from rockyade.kernel.energy import push_dashpot
from rockyade.kernel.recording import count_point
from rockyade.kernel.step import base_point


class BaseState(NamedTuple):
    """What base contacts keep between steps."""

    shear: NDArray[np.float64]  #: (nb, maxv) shear spring of each vertex on the base, N
    on_base: NDArray[np.bool_]  #: (nb,) a vertex of the body touched the base last step


@numba.njit(cache=True, nogil=True, inline="always")
def new_base_state(nb: int, maxv: int) -> BaseState:
    """No vertex on the base."""
    return BaseState(np.zeros((nb, maxv)), np.zeros(nb, dtype=np.bool_))


@numba.njit(cache=True, nogil=True, inline="always")
def base_contacts(
    bodies, joints, settings, kin, world, base, tally, dash, sampling: bool, e_el: float, n_dash: int, d_fric: float
) -> tuple[float, int, float]:
    """Add the base contacts' forces to every moving body.

    Parameters
    ----------
    tally
        :class:`rockyade.kernel.recording.Tally`, counted when ``sampling``.
    dash
        :class:`rockyade.kernel.energy.Dashpots`, filled from ``n_dash`` with energy terms.
    e_el, d_fric
        Elastic energy of this step's points and friction dissipation of this step so far, J.

    Returns
    -------
    e_el, n_dash, d_fric
        Updated with the base contacts (only with ``settings.record_energy``).
    """
    moving, lo, on_base = bodies.moving, world.lo, base.on_base
    for a in range(moving.size):
        if not moving[a] or (lo[a, 1] > 0.0 and not on_base[a]):
            continue
        e_el, n_dash, d_fric = body_on_base(
            a, bodies, joints, settings, kin, world, base, tally, dash, sampling, e_el, n_dash, d_fric
        )
    return e_el, n_dash, d_fric


@numba.njit(cache=True, nogil=True, inline="always")
def body_on_base(
    a: int,
    bodies,
    joints,
    settings,
    kin,
    world,
    base,
    tally,
    dash,
    sampling: bool,
    e_el: float,
    n_dash: int,
    d_fric: float,
) -> tuple[float, int, float]:
    """The base contacts of body ``a`` (see :func:`base_contacts`)."""
    wv, shear, vstate = world.wv, base.shear, tally.vstate
    pos, vel, angvel, force, torque = kin.pos, kin.vel, kin.angvel, kin.force, kin.torque
    record_energy, record_corners, dt = settings.record_energy, settings.record_corners, settings.dt
    law = joint_law(joints, joints.base_joint[a])
    touching = False
    for v in range(bodies.nverts[a]):
        px = wv[a, v, 0]
        py = wv[a, v, 1]
        delta = -py
        if delta < 0.0:
            if shear[a, v] != 0.0:
                # the contact opened: its shear memory (and stored energy) is lost
                if record_energy:
                    d_fric = add_released_energy(d_fric, shear[a, v] ** 2, law.ks)
                shear[a, v] = 0.0
            continue
        touching = True
        fx, fy, tz, fn, fn_spring, s_new, visc, state, slip_work = base_point(
            px, py, pos[a, 0], pos[a, 1], vel[a, 0], vel[a, 1], angvel[a], shear[a, v], law, dt
        )
        shear[a, v] = s_new
        force[a, 0] += fx
        force[a, 1] += fy
        torque[a] += tz
        if sampling:
            count_point(tally, a, state)
            if record_corners and state > vstate[a, v]:
                vstate[a, v] = state
        if record_energy:
            d_fric += slip_work
            e_el = add_stored_energy(e_el, fn_spring, delta, s_new, law.ks)
            n_dash = push_dashpot(dash, n_dash, a, -1, px, py, fn - fn_spring, visc, 0.0, 1.0)
    base.on_base[a] = touching
    return e_el, n_dash, d_fric
