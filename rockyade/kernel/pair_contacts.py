"""Contacts between bodies: one manifold per candidate pair, the contact law at its points.

Manifold (:mod:`rockyade.kernel.narrowphase`): the separating-axis test picks the reference
face (or finds a separating axis), the incident edge is clipped to the face's side planes,
and the clipped points below the face are the contact points (at most two), each with the
pair's joint K (``JointTable.joint_for``).

Temporal coherence: a pair's last test holds while no vertex of either body can have moved
by more than the test's slack in the other body's frame since the test. The bound used is

    |d' - d| + max(|d theta_a|, |d theta_b|) |d| + |d (theta_b - theta_a)| r_max

(d = centroid b - centroid a at the test, d' now; r_max the larger radius); with
``coherent = False`` every pair is tested every step (the results are the same).

At a point p the normal n points from b into a (the reference normal points from the
reference body into the incident one), t = (-n_y, n_x); the relative velocity is
v_a + w_a x (p - x_a) - v_b - w_b x (p - x_b), delta_dot = -v_rel . n, v_t = v_rel . t.
The force F_n n - (S + c_s v_t) t acts on a at p, its opposite on b.

Shear memory: a point inherits the shear spring of last step's point of the same pair
nearest to it (within the smaller ``feature_tol`` of the two bodies, a quarter of the
shortest edge), as a vector projected on the new tangent (YADE rotates the shear force with
the contact normal). Identifying a point by its place rather than by Box2D's feature ids
keeps the spring when the reference face passes from one block to the other at a flush
joint (both faces tie there) and the incident points change from vertices to clip points.
Last step's points that find no successor opened: their spring energy is lost.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numba

from rockyade.kernel.contact_law import add_released_energy, add_stored_energy, contact_law, joint_law
from rockyade.kernel.energy import push_dashpot
from rockyade.kernel.narrowphase import HYSTERESIS_REL, NO_FACE, clip_manifold, incident_edge, separating_axis_test
from rockyade.kernel.recording import count_point, mark_pair_corners

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

    from rockyade.kernel.energy import Dashpots
    from rockyade.kernel.integration import Motion
    from rockyade.kernel.pairs import PairState
    from rockyade.kernel.recording import Tally
    from rockyade.kernel.state import Bodies, Joints, Settings
    from rockyade.kernel.world import World


@numba.njit(cache=True, nogil=True, inline="always")
def pair_manifold(
    k: int, bodies: Bodies, kin: Motion, world: World, pairs: PairState, coherent: bool, clip: NDArray[np.float64]
) -> tuple[int, bool, int, int, int, int, int, int]:
    """Contact points of pair k written to ``clip``.

    Returns
    -------
    n_new, apart, side, face, ref, inc, edge, tested
        Points (0-2); whether a separating axis holds (tested or cached; False when the
        boxes are apart); the reference side (0: a, 1: b, ``NO_FACE``: none), face,
        reference and incident bodies and incident edge; 1 when a separating-axis test ran
        (0: the boxes are apart, or the last test holds).
    """
    wv, wn, wd, lo, hi = world.wv, world.wn, world.wd, world.lo, world.hi
    pos, ang = kin.pos, kin.ang
    edge_len, nverts, radius, scale = bodies.edge_len, bodies.nverts, bodies.radius, bodies.scale
    p_side, p_face, p_edge, p_slack, at = pairs.side, pairs.face, pairs.edge, pairs.slack, pairs.at
    a = pairs.a[k]
    b = pairs.b[k]
    side = NO_FACE
    face = NO_FACE
    edge = 0
    tested = 0
    if lo[a, 0] > hi[b, 0] or lo[b, 0] > hi[a, 0] or lo[a, 1] > hi[b, 1] or lo[b, 1] > hi[a, 1]:
        return 0, False, NO_FACE, NO_FACE, a, b, 0, 0
    dx = pos[b, 0] - pos[a, 0]
    dy = pos[b, 1] - pos[a, 1]
    turn_a = abs(ang[a] - at[k, 2])
    turn_b = abs(ang[b] - at[k, 3])
    turn_rel = abs(ang[b] - ang[a] - (at[k, 3] - at[k, 2]))
    r_max = max(radius[a], radius[b])
    moved = (
        abs(dx - at[k, 0])
        + abs(dy - at[k, 1])
        + max(turn_a, turn_b) * (abs(at[k, 0]) + abs(at[k, 1]))
        + turn_rel * r_max
    )
    if coherent and moved < p_slack[k]:
        side = p_side[k]
        face = p_face[k]
        edge = p_edge[k]
    else:
        tol = HYSTERESIS_REL * min(scale[a], scale[b])
        side, face, slack = separating_axis_test(wv, wn, wd, edge_len, nverts, a, b, p_side[k], p_face[k], tol)
        if side >= 0:
            ref = a if side == 0 else b
            inc = b if side == 0 else a
            edge, turn_slack = incident_edge(wn, ref, face, inc, nverts[inc])
            slack = min(slack, turn_slack * r_max)
        p_slack[k] = slack
        tested = 1
        at[k, 0] = dx
        at[k, 1] = dy
        at[k, 2] = ang[a]
        at[k, 3] = ang[b]
        p_edge[k] = edge
    if side < 0:
        return 0, True, side, face, a, b, edge, tested
    ref = a if side == 0 else b
    inc = b if side == 0 else a
    n_new = clip_manifold(wv, wn, edge_len, nverts, ref, face, inc, edge, clip)
    return n_new, False, side, face, ref, inc, edge, tested


@numba.njit(cache=True, nogil=True, inline="always")
def pair_opened(k: int, pairs: PairState, joints: Joints, apart: bool, record_energy: bool, d_fric: float) -> float:
    """Pair k has no contact point this step: last step's points opened (their spring energy
    added to ``d_fric``, returned). Unless a separating axis holds, the cached test no longer
    does (the boxes parted, or the manifold emptied without one): test again next time."""
    p_n, shear, ks_all, p_joint = pairs.n, pairs.shear, joints.ks, pairs.joint
    n_old = p_n[k]
    if n_old > 0:
        if record_energy:
            ks = ks_all[p_joint[k]]
            for i in range(n_old):
                d_fric = add_released_energy(d_fric, shear[k, i, 0] ** 2 + shear[k, i, 1] ** 2, ks)
        p_n[k] = 0
    if not apart:
        pairs.slack[k] = 0.0
    pairs.side[k] = NO_FACE
    pairs.face[k] = NO_FACE
    return d_fric


@numba.njit(cache=True, nogil=True, inline="always")
def nearest_old_point(
    px: float,
    py: float,
    n_old: int,
    used0: bool,
    used1: bool,
    o0x: float,
    o0y: float,
    o1x: float,
    o1y: float,
    tol2: float,
) -> int:
    """Last step's unused point (0 or 1) nearest to (px, py) within sqrt(tol2), or -1."""
    d0 = math.inf
    d1 = math.inf
    if n_old > 0 and not used0:
        d0 = (px - o0x) ** 2 + (py - o0y) ** 2
    if n_old > 1 and not used1:
        d1 = (px - o1x) ** 2 + (py - o1y) ** 2
    if d0 <= d1 and d0 <= tol2:
        return 0
    if d1 < d0 and d1 <= tol2:
        return 1
    return -1


@numba.njit(cache=True, nogil=True, inline="always")
def pair_points(
    k: int,
    n_new: int,
    ref: int,
    inc: int,
    face: int,
    edge: int,
    bodies: Bodies,
    joints: Joints,
    settings: Settings,
    kin: Motion,
    world: World,
    pairs: PairState,
    tally: Tally,
    dash: Dashpots,
    clip: NDArray[np.float64],
    sampling: bool,
    e_el: float,
    n_dash: int,
    d_fric: float,
) -> tuple[float, int, float]:
    """The contact law at pair k's ``n_new`` points in ``clip``; their forces, tally and
    energy terms (see :func:`pair_contacts`)."""
    pos, vel, angvel, force, torque = kin.pos, kin.vel, kin.angvel, kin.force, kin.torque
    wn, feature_tol = world.wn, bodies.feature_tol
    pt, sh = pairs.pt, pairs.shear
    record_energy, record_corners, dt = settings.record_energy, settings.record_corners, settings.dt
    a = pairs.a[k]
    b = pairs.b[k]
    law = joint_law(joints, pairs.joint[k])
    # normal from b into a (the reference normal points from ref into inc)
    sgn = 1.0 if ref == b else -1.0
    nx = sgn * wn[ref, face, 0]
    ny = sgn * wn[ref, face, 1]
    tx = -ny
    ty = nx
    tol2 = min(feature_tol[a], feature_tol[b]) ** 2
    n_old = pairs.n[k]
    # last step's points (overwritten below)
    o0x, o0y, o1x, o1y = pt[k, 0, 0], pt[k, 0, 1], pt[k, 1, 0], pt[k, 1, 1]
    s0x, s0y, s1x, s1y = sh[k, 0, 0], sh[k, 0, 1], sh[k, 1, 0], sh[k, 1, 1]
    used0 = False
    used1 = False
    for i in range(n_new):
        px = clip[i, 0]
        py = clip[i, 1]
        delta = clip[i, 2]
        s_old = 0.0
        old = nearest_old_point(px, py, n_old, used0, used1, o0x, o0y, o1x, o1y, tol2)
        if old == 0:
            used0 = True
            s_old = s0x * tx + s0y * ty
        elif old == 1:
            used1 = True
            s_old = s1x * tx + s1y * ty
        rax = px - pos[a, 0]
        ray = py - pos[a, 1]
        rbx = px - pos[b, 0]
        rby = py - pos[b, 1]
        vrx = vel[a, 0] - angvel[a] * ray - (vel[b, 0] - angvel[b] * rby)
        vry = vel[a, 1] + angvel[a] * rax - (vel[b, 1] + angvel[b] * rbx)
        fn, fn_spring, s_new, visc, state, slip_work = contact_law(
            delta, -(vrx * nx + vry * ny), vrx * tx + vry * ty, s_old, law, dt
        )
        pt[k, i, 0] = px
        pt[k, i, 1] = py
        sh[k, i, 0] = s_new * tx
        sh[k, i, 1] = s_new * ty
        fx = fn * nx - (s_new + visc) * tx
        fy = fn * ny - (s_new + visc) * ty
        force[a, 0] += fx
        force[a, 1] += fy
        torque[a] += rax * fy - ray * fx
        force[b, 0] -= fx
        force[b, 1] -= fy
        torque[b] -= rbx * fy - rby * fx
        if sampling:
            count_point(tally, a, state)
            count_point(tally, b, state)
            if record_corners:
                mark_pair_corners(tally, world, bodies, a, b, ref, face, inc, edge, px, py, state)
        if record_energy:
            d_fric += slip_work
            e_el = add_stored_energy(e_el, fn_spring, delta, s_new, law.ks)
            n_dash = push_dashpot(dash, n_dash, a, b, px, py, fn - fn_spring, visc, nx, ny)
    # last step's points that found no successor opened
    if record_energy:
        if n_old > 0 and not used0:
            d_fric = add_released_energy(d_fric, s0x * s0x + s0y * s0y, law.ks)
        if n_old > 1 and not used1:
            d_fric = add_released_energy(d_fric, s1x * s1x + s1y * s1y, law.ks)
    pairs.n[k] = n_new
    return e_el, n_dash, d_fric
