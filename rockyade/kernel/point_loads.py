"""Point loads: constant forces without mass at material points of the bodies (a scene's
``[[loads]]``).

A dead load F (fixed direction) at a body point r_b (relative to the centroid, in the body's
frame at angle 0) acts at r = R(theta) r_b when the body's angle is theta. Its torque about
the centroid is

    T = r x F = cos(theta) (r_b x F) - sin(theta) (r_b . F),

so a body's loads reduce to four numbers fixed at build time: the resultant (Fx, Fy) and
the sums M0 = sum r_b x F and Q = sum r_b . F (:func:`rockyade.dem.model_from_scene.load_arrays`).
The loads are weights carried by the body: they follow the apparent gravity, scaled by
(g + a_v) / g (so that they ramp in with gravity when a_v goes from -g to 0), and the
horizontal base acceleration does not act on them (no mass).
"""

from __future__ import annotations

import math

import numba


@numba.njit(cache=True, nogil=True, inline="always")
def apply_point_loads(bodies, kin, g: float, av: float) -> None:
    """Add each moving body's point loads to this step's force and torque.

    Parameters
    ----------
    bodies
        :class:`rockyade.kernel.state.Bodies`: ``load_force`` (nb, 2) resultant, N, and
        ``load_arm`` (nb, 2) (M0, Q), N m (module docstring). Nothing is done when they do
        not have one row per body (a caller that gives no loads).
    kin
        :class:`rockyade.kernel.integration.Motion`: ``ang``, ``force`` and ``torque``.
    g, av
        Gravity and the vertical base acceleration, m/s^2.
    """
    nb = bodies.mass.size
    if bodies.load_force.shape[0] != nb or bodies.load_arm.shape[0] != nb:
        return
    scale = (g + av) / g
    load_force, load_arm, moving = bodies.load_force, bodies.load_arm, bodies.moving
    force, torque, ang = kin.force, kin.torque, kin.ang
    for a in range(nb):
        if not moving[a]:
            continue
        m0 = load_arm[a, 0]
        q = load_arm[a, 1]
        fx = load_force[a, 0]
        fy = load_force[a, 1]
        if m0 == 0.0 and q == 0.0 and fx == 0.0 and fy == 0.0:
            continue
        force[a, 0] += scale * fx
        force[a, 1] += scale * fy
        torque[a] += scale * (math.cos(ang[a]) * m0 - math.sin(ang[a]) * q)
