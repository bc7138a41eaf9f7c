"""Numba kernel of the reference DEM: rigid convex polygons with the paper's joint.

Contact law (the same as YADE's ``Law2_ScGeom_ViscElPhys_Basic``, and the paper's UDEC
joint of Section 4), at every contact point:

* normal: F_n = K delta + c_n delta_dot with c_n = beta K, clamped at zero (no tension);
* shear: an incremental spring S += Ks dt v_t (v_t the tangential relative velocity at the
  point), capped at F_n tan(phi) (Coulomb; slip), plus a dashpot c_s v_t, c_s = beta Ks,
  only while sticking;
* the shear memory is reset when the contact point opens.

Contact points (:mod:`rockyade.kernel.contacts`): every vertex below the base (the half-plane
y <= 0); and per pair of touching polygons one manifold of at most two points (reference
face by the separating-axis test with hysteresis, incident edge clipped to its side
planes), each point with the pair's joint K (``JointTable.joint_for``). Candidate pairs come
from a sort-and-sweep broad phase over grown boxes, rebuilt only when a body has moved by
more than its margin (:mod:`rockyade.kernel.broadphase`), so a step costs O(bodies + pairs).

Shear memory of a pair's points: a point inherits the shear spring of last step's point of
the same pair nearest to it (within a quarter of the shortest edge of the two polygons), as
a vector projected on the new tangent (YADE rotates the shear force with the contact
normal). Identifying a point by its place rather than by Box2D's feature ids keeps the
spring when the reference face passes from one block to the other at a flush joint (both
faces tie there) and the incident points change from vertices to clip points.

Integration: the explicit central-difference (leap-frog) scheme of YADE's NewtonIntegrator:
forces at x_n with velocities v_{n-1/2}; v_{n+1/2} = v_{n-1/2} + dt F/m;
x_{n+1} = x_n + dt v_{n+1/2}. Everything is written in the frame of the base, which moves
with the prescribed ground acceleration: each moving body feels m (-a_h, -g - a_v); fixed
bodies move with the base (they never move in this frame).

Recorded every ``steps_per_sample`` steps (at t_n, velocities averaged over the step):
centroid position, rotation, angular velocity, velocity of the output point, the number of
contact points on each body and whether one of them slips, optionally the state of each
vertex (0 open, 1 stick, 2 slip: the worst state of the points at that corner) and the
energy terms.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rockyade.kernel.broadphase import candidate_pairs, moved_beyond_margin, sweep_axis
from rockyade.kernel.contacts import (
    HYSTERESIS_REL,
    NO_FACE,
    clip_manifold,
    incident_edge,
    joint_for,
    separating_axis_test,
)

# energy columns
E_KIN, E_POT, E_EL, E_DASH, E_FRIC, W_BASE = range(6)
N_ENERGY = 6

STATUS_COMPLETED, STATUS_OVERTURNED, STATUS_FAILED = 0, 1, 2

#: Beyond these the state is a numerical blow-up, not rocking (a block overturning under
#: gravity turns at a few rad/s): the run fails instead of being called overturned.
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0

STATE_OPEN, STATE_STICK, STATE_SLIP = 0, 1, 2

#: A contact point counts for a vertex's state within this fraction of the smaller block's width.
CORNER_TOL_REL = 0.01


@numba.njit(cache=True, nogil=True, inline="always")
def _ground(t, mt, mah, mav, j):
    """Base acceleration at t (linear between samples, zero outside); j is a cursor."""
    n = mt.size
    if n < 2 or t < mt[0] or t > mt[n - 1]:
        return 0.0, 0.0, j
    while j + 1 < n - 1 and mt[j + 1] <= t:
        j += 1
    w = (t - mt[j]) / (mt[j + 1] - mt[j])
    if w > 1.0:
        w = 1.0
    return mah[j] + w * (mah[j + 1] - mah[j]), mav[j] + w * (mav[j + 1] - mav[j]), j


@numba.njit(cache=True, nogil=True, inline="always")
def _place(a, pos, ang, verts, normals, nverts, wv, wn, wd, lo, hi):
    """World vertices, edge normals, edge-line offsets and tight box of body a."""
    c = math.cos(ang[a])
    s = math.sin(ang[a])
    lox = math.inf
    loy = math.inf
    hix = -math.inf
    hiy = -math.inf
    for v in range(nverts[a]):
        x = verts[a, v, 0]
        y = verts[a, v, 1]
        px = pos[a, 0] + c * x - s * y
        py = pos[a, 1] + s * x + c * y
        wv[a, v, 0] = px
        wv[a, v, 1] = py
        nx = normals[a, v, 0]
        ny = normals[a, v, 1]
        wn[a, v, 0] = c * nx - s * ny
        wn[a, v, 1] = s * nx + c * ny
        wd[a, v] = wn[a, v, 0] * px + wn[a, v, 1] * py
        lox = min(lox, px)
        hix = max(hix, px)
        loy = min(loy, py)
        hiy = max(hiy, py)
    lo[a, 0] = lox
    lo[a, 1] = loy
    hi[a, 0] = hix
    hi[a, 1] = hiy


@numba.njit(cache=True, nogil=True)
def _carry_pairs(old_keys, old_side, old_face, old_n, old_pt, old_sh, keys):
    """State of the new pair list: the pairs that persist keep theirs (both lists sorted)."""
    n = keys.size
    side = np.full(n, NO_FACE, dtype=np.int64)
    face = np.full(n, NO_FACE, dtype=np.int64)
    npt = np.zeros(n, dtype=np.int64)
    pt = np.zeros((n, 2, 2))
    sh = np.zeros((n, 2, 2))
    i = 0
    for k in range(n):
        while i < old_keys.size and old_keys[i] < keys[k]:
            i += 1
        if i < old_keys.size and old_keys[i] == keys[k]:
            side[k] = old_side[i]
            face[k] = old_face[i]
            npt[k] = old_n[i]
            pt[k] = old_pt[i]
            sh[k] = old_sh[i]
    return side, face, npt, pt, sh


@numba.njit(cache=True, nogil=True, inline="always")
def _mark_corner(vstate, body, v, px, py, wv, tol2, state):
    dx = wv[body, v, 0] - px
    dy = wv[body, v, 1] - py
    if dx * dx + dy * dy <= tol2 and state > vstate[body, v]:
        vstate[body, v] = state


@numba.njit(cache=True, nogil=True)
def simulate(
    mass,
    inertia,
    moving,
    verts,
    normals,
    edge_len,
    nverts,
    radius,
    scale,
    feature_tol,
    margin,
    kn,
    ks,
    cn,
    cs,
    tanphi,
    base_joint,
    own_joint,
    pair_keys,
    pair_joint,
    mass_damping,
    pos0,
    ang0,
    vel0,
    angvel0,
    rest_ang,
    stop_angle,
    stop_on_overturn,
    mt,
    mah,
    mav,
    g,
    dt,
    n_steps,
    steps_per_sample,
    accel_points,
    record_energy,
    record_corners,
    coherent,
):
    """Run the DEM. See the module docstring; arrays are float64 unless stated.

    Parameters
    ----------
    mass, inertia : (nb,)
    moving : (nb,) bool; False for fixed bodies (never integrated)
    verts : (nb, maxv, 2) contact polygon relative to the centroid, body frame, CCW
    normals : (nb, maxv, 2) outward unit normal of edge e (vertex e to e + 1), body frame
    edge_len : (nb, maxv) edge lengths, m
    nverts : (nb,) int64
    radius : (nb,) largest vertex distance from the centroid, m
    scale : (nb,) smallest extent of each polygon, m (tolerances of the reference face)
    feature_tol : (nb,) distance within which a contact point keeps its shear spring, m
    margin : (nb,) broad-phase box growth, m
    kn, ks, cn, cs, tanphi : (nj,) joint parameter sets
    base_joint, own_joint : (nb,) int64 joint indices (-1 for fixed bodies)
    pair_keys, pair_joint : (npairs,) int64 pairs resolved at build, key lo * (nb + 1) + hi,
        sorted; and their joints
    mass_damping : float, mass-proportional viscous damping a (1/s), 0 in the paper
    pos0, vel0 : (nb, 2); ang0, angvel0 : (nb,)
    rest_ang : (nb,) orientation at rest; theta = angle - rest_ang
    stop_angle : (nb,) |theta| at which a body counts as overturned, rad
    stop_on_overturn : bool, end the run when a moving body reaches its stop angle
    mt, mah, mav : base acceleration samples (may be empty)
    g, dt : float; n_steps, steps_per_sample : int
    accel_points : (nb, 2) output point relative to the centroid, body frame
    record_energy, record_corners : bool
    coherent : bool, keep a pair's separating-axis answer while its relative motion stays
        below the test's slack (False: test every pair every step; the results are the same)

    Returns
    -------
    pos_s, ang_s, angvel_s, vpoint_s : sampled states
    state_s : (n_samples or 1, nb, maxv) int8 vertex states (zeros unless record_corners)
    energy_s : (n_samples, 6) energy terms (NaN unless record_energy)
    status, n_filled, t_stop, stop_body : int, int, float, int
    ncont_s : (n_samples, nb) int32 contact points on each body
    slip_s : (n_samples, nb) bool, a point of the body slips
    overturn_t : (nb,) first time |theta| >= stop_angle, NaN if never
    n_builds, max_pairs : broad-phase rebuilds and the largest candidate list
    n_tests : separating-axis tests run (pair-steps)
    """
    nb = mass.shape[0]
    maxv = verts.shape[1]
    n_samples = n_steps // steps_per_sample + 1
    pos_s = np.full((n_samples, nb, 2), np.nan)
    ang_s = np.full((n_samples, nb), np.nan)
    angvel_s = np.full((n_samples, nb), np.nan)
    vpoint_s = np.full((n_samples, nb, 2), np.nan)
    state_s = np.zeros((n_samples if record_corners else 1, nb, maxv), dtype=np.int8)
    ncont_s = np.zeros((n_samples, nb), dtype=np.int32)
    slip_s = np.zeros((n_samples, nb), dtype=np.bool_)
    energy_s = np.full((n_samples, N_ENERGY), np.nan)
    overturn_t = np.full(nb, np.nan)

    pos = pos0.copy()
    ang = ang0.copy()
    vel = vel0.copy()
    angvel = angvel0.copy()
    for a in range(nb):
        if not moving[a]:
            vel[a, 0] = 0.0
            vel[a, 1] = 0.0
            angvel[a] = 0.0
    fixed = ~moving
    wv = np.zeros((nb, maxv, 2))
    wn = np.zeros((nb, maxv, 2))
    wd = np.zeros((nb, maxv))
    lo = np.zeros((nb, 2))
    hi = np.zeros((nb, 2))
    for a in range(nb):
        _place(a, pos, ang, verts, normals, nverts, wv, wn, wd, lo, hi)
    # base contacts: shear memory per vertex
    shear_base = np.zeros((nb, maxv))
    on_base = np.zeros(nb, dtype=np.bool_)
    vstate = np.zeros((nb, maxv), dtype=np.int8)
    ncont = np.zeros(nb, dtype=np.int32)
    slipping = np.zeros(nb, dtype=np.bool_)
    force = np.zeros((nb, 2))
    torque = np.zeros(nb)
    vel_prev = vel.copy()
    angvel_prev = angvel.copy()
    clip = np.zeros((2, 3))

    # broad phase and the pairs' state
    order = np.argsort(lo[:, 0] + hi[:, 0]).astype(np.int64)
    axis = sweep_axis(lo, hi)
    if axis == 1:
        order = np.argsort(lo[:, 1] + hi[:, 1]).astype(np.int64)
    keys, pa, pb = candidate_pairs(lo, hi, margin, fixed, axis, order)
    npairs = keys.size
    pj = np.empty(npairs, dtype=np.int64)
    for k in range(npairs):
        pj[k] = joint_for(pa[k], pb[k], nb, base_joint, own_joint, pair_keys, pair_joint, fixed, kn)
    pside = np.full(npairs, NO_FACE, dtype=np.int64)
    pedge = np.zeros(npairs, dtype=np.int64)
    # temporal coherence: the pair's last test holds while its relative motion < c_slack
    c_slack = np.zeros(npairs)
    c_at = np.zeros((npairs, 4))  # at the test: centroid b - centroid a (x, y), angles of a and b
    pface = np.full(npairs, NO_FACE, dtype=np.int64)
    pn = np.zeros(npairs, dtype=np.int64)
    ppt = np.zeros((npairs, 2, 2))
    psh = np.zeros((npairs, 2, 2))
    ref_pos = pos.copy()
    ref_ang = ang.copy()
    n_builds = 1
    n_tests = 0
    max_pairs = npairs
    multi = nb > 1

    # contacts of the current step, for the dashpot power with step-mean velocities:
    # body a, body b (-1 base); point, normal dashpot force, shear dashpot force, n
    n_base_max = 0
    for a in range(nb):
        if moving[a]:
            n_base_max += nverts[a]
    cap = n_base_max + 2 * npairs + 1 if record_energy else 1
    cbuf_i = np.zeros((cap, 2), dtype=np.int64)
    cbuf = np.zeros((cap, 6))

    e_el = 0.0
    e_dash = 0.0
    e_dash_before = 0.0
    w_base_before = 0.0
    e_fric = 0.0
    w_base = 0.0
    status = STATUS_COMPLETED
    t_stop = -1.0
    stop_body = -1
    jcur = 0
    n_filled = 0

    # one pass of the outer loop per candidate list: the step loop inside it never replaces
    # an array (numba then keeps the arrays' pointers out of the loop: 3x faster)
    step0 = 0
    while True:
        rebuild_now = False
        for step in range(step0, n_steps + 1):
            t = step * dt
            ah, av, jcur = _ground(t, mt, mah, mav, jcur)
            sampling = step % steps_per_sample == 0
            if step > 0:
                for a in range(nb):
                    if moving[a]:
                        _place(a, pos, ang, verts, normals, nverts, wv, wn, wd, lo, hi)
            for a in range(nb):
                force[a, 0] = -mass[a] * ah
                force[a, 1] = -mass[a] * (g + av)
                torque[a] = 0.0
            if sampling:
                ncont[:] = 0
                slipping[:] = False
                if record_corners:
                    vstate[:, :] = 0
            e_el_now = 0.0
            n_contacts = 0
            d_fric = 0.0
            # ---- contacts with the base: every vertex below y = 0
            for a in range(nb):
                if not moving[a] or (lo[a, 1] > 0.0 and not on_base[a]):
                    continue
                touching = False
                joint = base_joint[a]
                for v in range(nverts[a]):
                    px = wv[a, v, 0]
                    py = wv[a, v, 1]
                    delta = -py
                    if delta < 0.0:
                        if shear_base[a, v] != 0.0:
                            # the contact opened: its shear memory (and stored energy) is lost
                            if record_energy and ks[joint] > 0.0:
                                d_fric += 0.5 * shear_base[a, v] ** 2 / ks[joint]
                            shear_base[a, v] = 0.0
                        continue
                    touching = True
                    rax = px - pos[a, 0]
                    ray = py - pos[a, 1]
                    vrx = vel[a, 0] - angvel[a] * ray
                    vry = vel[a, 1] + angvel[a] * rax
                    ddot = -vry
                    fn_spring = kn[joint] * delta
                    fn = fn_spring + cn[joint] * ddot
                    if fn < 0.0:
                        fn = 0.0
                    vt = -vrx
                    s_trial = shear_base[a, v] + ks[joint] * dt * vt
                    smax = fn * tanphi[joint]
                    if abs(s_trial) > smax:
                        s_new = smax if s_trial > 0.0 else -smax
                        visc = 0.0
                        state = STATE_SLIP
                        if record_energy and ks[joint] > 0.0:
                            # the slip of this step, (|s_trial| - smax) / ks, against the force
                            # the bodies feel, smax (as YADE's plastic dissipation)
                            d_fric += smax * (abs(s_trial) - smax) / ks[joint]
                    else:
                        s_new = s_trial
                        visc = cs[joint] * vt
                        state = STATE_STICK
                    shear_base[a, v] = s_new
                    # n = (0, 1), t = (-1, 0)
                    fx = (s_new + visc) * 1.0
                    fy = fn * 1.0
                    force[a, 0] += fx
                    force[a, 1] += fy
                    torque[a] += rax * fy - ray * fx
                    if sampling:
                        ncont[a] += 1
                        if state == STATE_SLIP:
                            slipping[a] = True
                        if record_corners and state > vstate[a, v]:
                            vstate[a, v] = state
                    if record_energy:
                        e_el_now += 0.5 * fn_spring * delta
                        if ks[joint] > 0.0:
                            e_el_now += 0.5 * s_new * s_new / ks[joint]
                        cbuf_i[n_contacts, 0] = a
                        cbuf_i[n_contacts, 1] = -1
                        cbuf[n_contacts, 0] = px
                        cbuf[n_contacts, 1] = py
                        cbuf[n_contacts, 2] = fn - fn_spring
                        cbuf[n_contacts, 3] = visc
                        cbuf[n_contacts, 4] = 0.0
                        cbuf[n_contacts, 5] = 1.0
                        n_contacts += 1
                on_base[a] = touching
            # ---- contacts between bodies: one manifold per candidate pair
            for k in range(npairs):
                a = pa[k]
                b = pb[k]
                n_new = 0
                apart = False  # a separating axis holds (tested or cached)
                side = NO_FACE
                face = NO_FACE
                ref = a
                inc = b
                edge = 0
                if not (lo[a, 0] > hi[b, 0] or lo[b, 0] > hi[a, 0] or lo[a, 1] > hi[b, 1] or lo[b, 1] > hi[a, 1]):
                    # how far a vertex of either body may have moved in the other's frame
                    # since the last test: |d' - d| + |d theta_a| |d| + |d (theta_b - theta_a)| r_b
                    # (d = centroid b - centroid a), and the same from b's side
                    dx = pos[b, 0] - pos[a, 0]
                    dy = pos[b, 1] - pos[a, 1]
                    turn_a = abs(ang[a] - c_at[k, 2])
                    turn_b = abs(ang[b] - c_at[k, 3])
                    turn_rel = abs(ang[b] - ang[a] - (c_at[k, 3] - c_at[k, 2]))
                    r_max = max(radius[a], radius[b])
                    moved = (
                        abs(dx - c_at[k, 0])
                        + abs(dy - c_at[k, 1])
                        + max(turn_a, turn_b) * (abs(c_at[k, 0]) + abs(c_at[k, 1]))
                        + turn_rel * r_max
                    )
                    if coherent and moved < c_slack[k]:
                        side = pside[k]
                        face = pface[k]
                        edge = pedge[k]
                    else:
                        tol = HYSTERESIS_REL * min(scale[a], scale[b])
                        side, face, slack = separating_axis_test(
                            wv, wn, wd, edge_len, nverts, a, b, pside[k], pface[k], tol
                        )
                        if side >= 0:
                            ref = a if side == 0 else b
                            inc = b if side == 0 else a
                            edge, turn_slack = incident_edge(wn, ref, face, inc, nverts[inc])
                            slack = min(slack, turn_slack * r_max)
                        c_slack[k] = slack
                        n_tests += 1
                        c_at[k, 0] = dx
                        c_at[k, 1] = dy
                        c_at[k, 2] = ang[a]
                        c_at[k, 3] = ang[b]
                        pedge[k] = edge
                    apart = side == NO_FACE
                    if side >= 0:
                        ref = a if side == 0 else b
                        inc = b if side == 0 else a
                        n_new = clip_manifold(wv, wn, edge_len, nverts, ref, face, inc, edge, clip)
                joint = pj[k]
                n_old = pn[k]
                if n_new == 0:
                    if n_old > 0:
                        if record_energy and ks[joint] > 0.0:
                            for i in range(n_old):
                                d_fric += 0.5 * (psh[k, i, 0] ** 2 + psh[k, i, 1] ** 2) / ks[joint]
                        pn[k] = 0
                    if not apart:
                        # the boxes parted, or the manifold emptied without a separating
                        # axis: the cached answer no longer holds, test again next time
                        c_slack[k] = 0.0
                    pside[k] = NO_FACE
                    pface[k] = NO_FACE
                    continue
                pside[k] = side
                pface[k] = face
                # normal from b into a (the reference normal points from ref into inc)
                if ref == b:
                    nx = wn[b, face, 0]
                    ny = wn[b, face, 1]
                else:
                    nx = -wn[a, face, 0]
                    ny = -wn[a, face, 1]
                tx = -ny
                ty = nx
                match_tol2 = min(feature_tol[a], feature_tol[b]) ** 2
                used0 = False
                used1 = False
                o0x = ppt[k, 0, 0]
                o0y = ppt[k, 0, 1]
                o1x = ppt[k, 1, 0]
                o1y = ppt[k, 1, 1]
                s0x = psh[k, 0, 0]
                s0y = psh[k, 0, 1]
                s1x = psh[k, 1, 0]
                s1y = psh[k, 1, 1]
                for j in range(n_new):
                    px = clip[j, 0]
                    py = clip[j, 1]
                    delta = clip[j, 2]
                    # the nearest unused point of last step within the feature tolerance
                    s_old = 0.0
                    d0 = math.inf
                    d1 = math.inf
                    if n_old > 0 and not used0:
                        d0 = (px - o0x) ** 2 + (py - o0y) ** 2
                    if n_old > 1 and not used1:
                        d1 = (px - o1x) ** 2 + (py - o1y) ** 2
                    if d0 <= d1 and d0 <= match_tol2:
                        used0 = True
                        s_old = s0x * tx + s0y * ty
                    elif d1 < d0 and d1 <= match_tol2:
                        used1 = True
                        s_old = s1x * tx + s1y * ty
                    rax = px - pos[a, 0]
                    ray = py - pos[a, 1]
                    rbx = px - pos[b, 0]
                    rby = py - pos[b, 1]
                    vrx = vel[a, 0] - angvel[a] * ray - (vel[b, 0] - angvel[b] * rby)
                    vry = vel[a, 1] + angvel[a] * rax - (vel[b, 1] + angvel[b] * rbx)
                    ddot = -(vrx * nx + vry * ny)
                    fn_spring = kn[joint] * delta
                    fn = fn_spring + cn[joint] * ddot
                    if fn < 0.0:
                        fn = 0.0
                    vt = vrx * tx + vry * ty
                    s_trial = s_old + ks[joint] * dt * vt
                    smax = fn * tanphi[joint]
                    if abs(s_trial) > smax:
                        s_new = smax if s_trial > 0.0 else -smax
                        visc = 0.0
                        state = STATE_SLIP
                        if record_energy and ks[joint] > 0.0:
                            d_fric += smax * (abs(s_trial) - smax) / ks[joint]
                    else:
                        s_new = s_trial
                        visc = cs[joint] * vt
                        state = STATE_STICK
                    ppt[k, j, 0] = px
                    ppt[k, j, 1] = py
                    psh[k, j, 0] = s_new * tx
                    psh[k, j, 1] = s_new * ty
                    fx = fn * nx - (s_new + visc) * tx
                    fy = fn * ny - (s_new + visc) * ty
                    force[a, 0] += fx
                    force[a, 1] += fy
                    torque[a] += rax * fy - ray * fx
                    force[b, 0] -= fx
                    force[b, 1] -= fy
                    torque[b] -= rbx * fy - rby * fx
                    if sampling:
                        ncont[a] += 1
                        ncont[b] += 1
                        if state == STATE_SLIP:
                            slipping[a] = True
                            slipping[b] = True
                        if record_corners:
                            # at a corner: within 1 % of the smaller block's width (penetrations
                            # are far smaller, another block's corner is farther)
                            tol2 = (CORNER_TOL_REL * min(scale[a], scale[b])) ** 2
                            nr = nverts[ref]
                            ni = nverts[inc]
                            _mark_corner(vstate, ref, face, px, py, wv, tol2, state)
                            _mark_corner(vstate, ref, face + 1 if face + 1 < nr else 0, px, py, wv, tol2, state)
                            _mark_corner(vstate, inc, edge, px, py, wv, tol2, state)
                            _mark_corner(vstate, inc, edge + 1 if edge + 1 < ni else 0, px, py, wv, tol2, state)
                    if record_energy:
                        e_el_now += 0.5 * fn_spring * delta
                        if ks[joint] > 0.0:
                            e_el_now += 0.5 * s_new * s_new / ks[joint]
                        cbuf_i[n_contacts, 0] = a
                        cbuf_i[n_contacts, 1] = b
                        cbuf[n_contacts, 0] = px
                        cbuf[n_contacts, 1] = py
                        cbuf[n_contacts, 2] = fn - fn_spring
                        cbuf[n_contacts, 3] = visc
                        cbuf[n_contacts, 4] = nx
                        cbuf[n_contacts, 5] = ny
                        n_contacts += 1
                # last step's points that found no successor opened
                if record_energy and ks[joint] > 0.0:
                    if n_old > 0 and not used0:
                        d_fric += 0.5 * (s0x * s0x + s0y * s0y) / ks[joint]
                    if n_old > 1 and not used1:
                        d_fric += 0.5 * (s1x * s1x + s1y * s1y) / ks[joint]
                pn[k] = n_new
            # ---- leap-frog update
            e_dash_before = e_dash
            w_base_before = w_base
            for a in range(nb):
                if not moving[a]:
                    continue
                vel_prev[a, 0] = vel[a, 0]
                vel_prev[a, 1] = vel[a, 1]
                angvel_prev[a] = angvel[a]
                fdx = 0.0
                fdy = 0.0
                tdz = 0.0
                if mass_damping > 0.0:
                    fdx = -mass_damping * mass[a] * vel[a, 0]
                    fdy = -mass_damping * mass[a] * vel[a, 1]
                    tdz = -mass_damping * inertia[a] * angvel[a]
                    force[a, 0] += fdx
                    force[a, 1] += fdy
                    torque[a] += tdz
                vel[a, 0] += dt * force[a, 0] / mass[a]
                vel[a, 1] += dt * force[a, 1] / mass[a]
                angvel[a] += dt * torque[a] / inertia[a]
                if record_energy and mass_damping > 0.0:
                    e_dash -= dt * (
                        fdx * 0.5 * (vel[a, 0] + vel_prev[a, 0])
                        + fdy * 0.5 * (vel[a, 1] + vel_prev[a, 1])
                        + tdz * 0.5 * (angvel[a] + angvel_prev[a])
                    )
            if record_energy:
                # the leap-frog scheme changes the kinetic energy by exactly dt F . v_mean: take
                # every power with the step-mean velocities v_mean = (v_{n-1/2} + v_{n+1/2}) / 2
                for c in range(n_contacts):
                    a = cbuf_i[c, 0]
                    b = cbuf_i[c, 1]
                    px = cbuf[c, 0]
                    py = cbuf[c, 1]
                    w = 0.5 * (angvel[a] + angvel_prev[a])
                    vrx = 0.5 * (vel[a, 0] + vel_prev[a, 0]) - w * (py - pos[a, 1])
                    vry = 0.5 * (vel[a, 1] + vel_prev[a, 1]) + w * (px - pos[a, 0])
                    if b >= 0:
                        w = 0.5 * (angvel[b] + angvel_prev[b])
                        vrx -= 0.5 * (vel[b, 0] + vel_prev[b, 0]) - w * (py - pos[b, 1])
                        vry -= 0.5 * (vel[b, 1] + vel_prev[b, 1]) + w * (px - pos[b, 0])
                    nx = cbuf[c, 4]
                    ny = cbuf[c, 5]
                    ddot = -(vrx * nx + vry * ny)
                    vt = -vrx * ny + vry * nx
                    e_dash += dt * (cbuf[c, 2] * ddot + cbuf[c, 3] * vt)
                e_fric += d_fric
                for a in range(nb):
                    if moving[a]:
                        vx = 0.5 * (vel[a, 0] + vel_prev[a, 0])
                        vy = 0.5 * (vel[a, 1] + vel_prev[a, 1])
                        w_base += -mass[a] * (ah * vx + av * vy) * dt
                e_el = e_el_now
            # ---- record at t_n (positions x_n, velocities averaged over the step)
            if sampling:
                k = step // steps_per_sample
                e_kin = 0.0
                e_pot = 0.0
                for a in range(nb):
                    vx = 0.5 * (vel[a, 0] + vel_prev[a, 0])
                    vy = 0.5 * (vel[a, 1] + vel_prev[a, 1])
                    w = 0.5 * (angvel[a] + angvel_prev[a])
                    pos_s[k, a, 0] = pos[a, 0]
                    pos_s[k, a, 1] = pos[a, 1]
                    ang_s[k, a] = ang[a]
                    angvel_s[k, a] = w
                    c = math.cos(ang[a])
                    s = math.sin(ang[a])
                    qx = c * accel_points[a, 0] - s * accel_points[a, 1]
                    qy = s * accel_points[a, 0] + c * accel_points[a, 1]
                    vpoint_s[k, a, 0] = vx - w * qy
                    vpoint_s[k, a, 1] = vy + w * qx
                    ncont_s[k, a] = ncont[a]
                    slip_s[k, a] = slipping[a]
                    if record_corners:
                        for v in range(nverts[a]):
                            state_s[k, a, v] = vstate[a, v]
                    if moving[a]:
                        # discrete kinetic energy of the leap-frog scheme, (1/2) m v_{n-1/2} . v_{n+1/2}:
                        # with the potential and elastic energies at x_n it is conserved exactly for
                        # gravity and linear springs, so the balance error measures the contacts'
                        # switching and the dissipation alone
                        e_kin += 0.5 * mass[a] * (vel[a, 0] * vel_prev[a, 0] + vel[a, 1] * vel_prev[a, 1])
                        e_kin += 0.5 * inertia[a] * angvel[a] * angvel_prev[a]
                        e_pot += mass[a] * g * pos[a, 1]
                if record_energy:
                    # half of this step's work belongs before t_n and half after it
                    energy_s[k, E_KIN] = e_kin
                    energy_s[k, E_POT] = e_pot
                    energy_s[k, E_EL] = e_el
                    energy_s[k, E_DASH] = 0.5 * (e_dash + e_dash_before)
                    energy_s[k, E_FRIC] = e_fric
                    energy_s[k, W_BASE] = 0.5 * (w_base + w_base_before)
                n_filled = k + 1
            if step == n_steps:
                break
            # ---- positions, overturn and sanity checks
            for a in range(nb):
                if not moving[a]:
                    continue
                pos[a, 0] += dt * vel[a, 0]
                pos[a, 1] += dt * vel[a, 1]
                ang[a] += dt * angvel[a]
                finite = math.isfinite(pos[a, 0]) and math.isfinite(pos[a, 1]) and math.isfinite(ang[a])
                speed2 = vel[a, 0] * vel[a, 0] + vel[a, 1] * vel[a, 1]
                if not finite or speed2 > MAX_SPEED_M_S * MAX_SPEED_M_S or abs(angvel[a]) > MAX_SPIN_RAD_S:
                    status = STATUS_FAILED
                    stop_body = a
                elif abs(ang[a] - rest_ang[a]) >= stop_angle[a] and math.isnan(overturn_t[a]):
                    overturn_t[a] = (step + 1) * dt
                    if stop_on_overturn and status == STATUS_COMPLETED:
                        status = STATUS_OVERTURNED
                        stop_body = a
            if status != STATUS_COMPLETED:
                t_stop = (step + 1) * dt
                break
            # ---- broad phase: rebuild the candidate pairs when a body left its margin
            if multi and moved_beyond_margin(pos, ang, ref_pos, ref_ang, radius, margin, moving):
                rebuild_now = True
                step0 = step + 1
                break
        if not rebuild_now:
            break
        for a in range(nb):
            if moving[a]:
                _place(a, pos, ang, verts, normals, nverts, wv, wn, wd, lo, hi)
        new_keys, pa, pb = candidate_pairs(lo, hi, margin, fixed, axis, order)
        # a pair leaves the list only when its grown boxes are apart: it opened before
        pside, pface, pn, ppt, psh = _carry_pairs(keys, pside, pface, pn, ppt, psh, new_keys)
        pedge = np.zeros(new_keys.size, dtype=np.int64)
        c_slack = np.zeros(new_keys.size)  # every pair is tested again after a rebuild
        c_at = np.zeros((new_keys.size, 4))
        keys = new_keys
        npairs = keys.size
        pj = np.empty(npairs, dtype=np.int64)
        for k in range(npairs):
            pj[k] = joint_for(pa[k], pb[k], nb, base_joint, own_joint, pair_keys, pair_joint, fixed, kn)
        ref_pos[:, :] = pos
        ref_ang[:] = ang
        n_builds += 1
        max_pairs = max(max_pairs, npairs)
        if record_energy and n_base_max + 2 * npairs + 1 > cap:
            cap = n_base_max + 2 * npairs + 1
            cbuf_i = np.zeros((cap, 2), dtype=np.int64)
            cbuf = np.zeros((cap, 6))
    return (
        pos_s,
        ang_s,
        angvel_s,
        vpoint_s,
        state_s,
        energy_s,
        status,
        n_filled,
        t_stop,
        stop_body,
        ncont_s,
        slip_s,
        overturn_t,
        n_builds,
        max_pairs,
        n_tests,
    )
