"""One body's time step on the moving base, its state in scalars: the step function that the
single-body path (:func:`rockyade.kernel.single.run_body`) and the runs stepped together
(:func:`rockyade.kernel.runs.step_runs`) both call, so that the two are one loop body.

A step t_n = n dt, in the order of the general loop (:mod:`.simulation`):

1. :func:`step_body`: the base acceleration a_h, a_v at t_n, linear between two motion samples
   (the arithmetic of :func:`rockyade.motion.ground.ground_acceleration`, the interval held
   between steps as a :data:`Interval` and walked forward, the times only increasing); the
   vertices p = x + R(theta) v; F = m (-a_h, -g - a_v), T = 0; every vertex below y = 0 through
   the one contact law (:func:`rockyade.kernel.step.base_point`); the kick
   v_{n+1/2} = v_{n-1/2} + dt F / m, with the optional mass-proportional damping;
2. the caller's sample at t_n, if any;
3. :func:`end_step`: the drift x_{n+1} = x_n + dt v_{n+1/2}, then the blow-up and overturn tests.

Each function is ``inline="always"``: numba pastes it into both loops, which thus compute the
same operations on the same operands in the same order as when each wrote them out (the same
doubles: ``tests/test_single_body.py``, ``tests/test_runs_batched.py``).

numba's on-disk cache keys a compiled function by its own file: after editing this module,
delete ``rockyade/kernel/__pycache__`` so that the loops are compiled again with the change.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.contact_law import STATE_SLIP
from rockyade.kernel.integration import STATUS_COMPLETED, STATUS_FAILED, STATUS_OVERTURNED
from rockyade.kernel.step import (
    base_point,
    beyond_stop_angle,
    blown_up,
    damping,
    drifted,
    fraction,
    kicked,
    lerp,
    world_x,
    world_y,
)


class OneBody(NamedTuple):
    """The body that is stepped and its base joint (a record numba passes as one argument)."""

    verts: NDArray[np.float64]  #: (maxv, 2) polygon relative to the centroid, body frame, m
    nv: int  #: vertices used
    mass: float  #: kg
    inertia: float  #: about the centroid, kg m^2
    kn: float  #: base joint: normal stiffness, N/m
    ks: float  #: shear stiffness, N/m
    cn: float  #: normal dashpot, N s/m
    cs: float  #: shear dashpot, N s/m
    tanphi: float  #: friction coefficient
    rest_ang: float  #: orientation at rest, rad
    stop_angle: float  #: |theta| at which the body has overturned, rad
    apx: float  #: output point relative to the centroid, body frame, m
    apy: float  #: (its y), m


#: The fields of a motion interval (a tuple of 7 floats): its start and end times (s), length
#: (s), and the horizontal and vertical accelerations at its start and their rise over it (m/s^2).
Interval = ("t_lo", "t_hi", "t_span", "ah_lo", "ah_span", "av_lo", "av_span")


@numba.njit(cache=True, nogil=True, inline="always")
def motion_interval(mt, mah, mav, h: int) -> tuple[float, float, float, float, float, float, float]:
    """The :data:`Interval` from motion sample ``h`` to ``h`` + 1 (s, m/s^2)."""
    t_lo = mt[h]
    t_hi = mt[h + 1]
    ah_lo = mah[h]
    av_lo = mav[h]
    return t_lo, t_hi, t_hi - t_lo, ah_lo, mah[h + 1] - ah_lo, av_lo, mav[h + 1] - av_lo


@numba.njit(cache=True, nogil=True, inline="always")
def step_body(
    t: float,
    mt,
    mah,
    mav,
    first: int,
    t_first: float,
    t_last: float,
    ah_end: float,
    av_end: float,
    hint: int,
    interval,
    one: OneBody,
    g: float,
    dt: float,
    mass_damping: float,
    x: float,
    y: float,
    ang: float,
    vx: float,
    vy: float,
    w: float,
    shear,
    row: int,
    count: bool,
    vstate,
    corners: bool,
):
    """The first part of a step of one body (module docstring): the base acceleration at ``t``,
    the forces and the kick.

    Parameters
    ----------
    t
        The time t_n, s.
    mt, mah, mav, first
        The motion's samples (s, m/s^2, m/s^2), this run's from index ``first``.
    t_first, t_last, ah_end, av_end
        Its first and last sample times (s; ``t_last`` -inf for fewer than two samples) and
        the accelerations of the last, m/s^2 (zero outside the samples).
    hint, interval
        The interval that held the time of the last step: its first sample (from ``first``)
        and its :data:`Interval`.
    one
        The body and its base joint.
    g, dt, mass_damping
        Gravity (m/s^2), the time step (s) and the mass damping (1/s).
    x, y, ang, vx, vy, w
        The state: centroid (m) and angle (rad) at t_n, velocities v_{n-1/2} (m/s, rad/s).
    shear, row
        The vertices' shear springs, N: row ``row`` of ``shear``, updated.
    count, vstate, corners
        Count the vertices on the base and whether one slips (a sampled step); with
        ``corners`` also raise ``vstate`` (each vertex's worst contact state) to this step's.

    Returns
    -------
    c, s, vx, vy, w, n_contacts, slipping, hint, interval, moved
        cos and sin of the angle at t_n, the velocities v_{n+1/2}, the vertices on the base and
        whether one slips (when counted), the interval of ``t`` and whether it changed.
    """
    verts, nv, mass, inertia = one.verts, one.nv, one.mass, one.inertia
    kn, ks, cn, cs, tanphi = one.kn, one.ks, one.cn, one.cs, one.tanphi
    # the base acceleration: ground_acceleration's arithmetic
    ah = 0.0
    av = 0.0
    moved = False
    if t < t_last and t >= t_first:
        if t >= interval[1]:  # the next interval (rare: a record's samples are many steps apart)
            while t >= mt[first + hint + 1]:
                hint += 1
            interval = motion_interval(mt, mah, mav, first + hint)
            moved = True
        u = fraction(t, interval[0], interval[2])
        ah = lerp(u, interval[3], interval[4])
        av = lerp(u, interval[5], interval[6])
    elif t == t_last:
        ah = ah_end
        av = av_end
    c = math.cos(ang)
    s = math.sin(ang)
    fx = -mass * ah
    fy = -mass * (g + av)
    tz = 0.0
    n_contacts = 0
    slipping = False
    # every vertex (the general loop skips a body above the base that touched nothing last
    # step: then no vertex is below the base and every shear spring is already 0, so visiting
    # them changes nothing)
    for v in range(nv):
        py = world_y(y, c, s, verts[v, 0], verts[v, 1])
        if -py < 0.0:
            if shear[row, v] != 0.0:
                shear[row, v] = 0.0
            continue
        px = world_x(x, c, s, verts[v, 0], verts[v, 1])
        cfx, cfy, ctz, _fn, _spring, s_new, _visc, state, _slip = base_point(
            px, py, x, y, vx, vy, w, shear[row, v], kn, ks, cn, cs, tanphi, dt
        )
        shear[row, v] = s_new
        fx += cfx
        fy += cfy
        tz += ctz
        if count:
            n_contacts += 1
            if state == STATE_SLIP:
                slipping = True
            if corners and state > vstate[v]:
                vstate[v] = state
    # kick
    if mass_damping > 0.0:
        fdx, fdy, tdz = damping(mass, inertia, mass_damping, vx, vy, w)
        fx += fdx
        fy += fdy
        tz += tdz
    vx = kicked(vx, fx, mass, dt)
    vy = kicked(vy, fy, mass, dt)
    w = kicked(w, tz, inertia, dt)
    return c, s, vx, vy, w, n_contacts, slipping, hint, interval, moved


@numba.njit(cache=True, nogil=True, inline="always")
def end_step(
    step: int,
    x: float,
    y: float,
    ang: float,
    vx: float,
    vy: float,
    w: float,
    dt: float,
    one: OneBody,
    stop_on_overturn: bool,
    overturn_t: float,
) -> tuple[float, float, float, int, float]:
    """The last part of step ``step`` of one body: the drift and the blow-up and overturn tests.

    Parameters
    ----------
    x, y, ang, vx, vy, w
        Centroid (m) and angle (rad) at t_n, velocities v_{n+1/2} (m/s, rad/s).
    dt, one, stop_on_overturn
        The time step (s), the body (its angle at rest and the |theta| at which it has
        overturned, rad), and whether an overturn ends the run.
    overturn_t
        The first time |theta| reached the stop angle, s (NaN: not yet).

    Returns
    -------
    x, y, ang, status, overturn_t
        The state at t_{n+1}, STATUS_COMPLETED (the run goes on), STATUS_FAILED or
        STATUS_OVERTURNED, and the first overturn time.
    """
    x = drifted(x, vx, dt)
    y = drifted(y, vy, dt)
    ang = drifted(ang, w, dt)
    # the general loop's blow-up test: x, y, theta stay finite while the velocities are finite
    # and bounded (tested every step), so testing the velocities alone (NaN fails both
    # comparisons) decides the same
    status = STATUS_COMPLETED
    if blown_up(vx, vy, w):
        status = STATUS_FAILED
    elif beyond_stop_angle(ang, one.rest_ang, one.stop_angle) and math.isnan(overturn_t):
        overturn_t = (step + 1) * dt
        if stop_on_overturn:
            status = STATUS_OVERTURNED
    return x, y, ang, status, overturn_t
