"""The two-block stack's mechanics, compiled by numba: kinematics, equations of motion of
every mode, contact forces and impulses, and the choice of the mode after an event.

Coordinates and modes (docs/twoblock.md has the derivation). The lower block turns by
theta_1 about a base corner O (``sb``: +1 left corner, theta_1 >= 0; -1 right corner; 0 the
base joint closed, theta_1 = 0); the upper block turns by phi relative to the lower one about
a corner S of its seat (``ss``: +1 left, -1 right, 0 closed), so its absolute rotation is
theta_2 = theta_1 + phi. With r_1 = G_1 - O, s = S - O and r_2 = G_2 - S at rest, and
a = R(theta_1) r_1, c = R(theta_1) s, d = R(theta_2) r_2 (R the rotation):

    G_1 = O + a,    G_2 = O + c + d.

Lagrange's equations of the chain (the two-block equations of Psycharis 1990, in this notation):

    M11 theta_1'' + M12 theta_2'' = Q1 + m_2 (c x d) theta_2'^2
    M12 theta_1'' + M22 theta_2'' = Q2 - m_2 (c x d) theta_1'^2

with M11 = I_1 + m_1 |r_1|^2 + m_2 |s|^2, M12 = m_2 c . d, M22 = I_2 + m_2 |r_2|^2 and
the generalised forces of the weights and of the base's inertia in the base frame (a_h the
horizontal base acceleration, g_v = g + a_v the apparent gravity)

    Q1 = m_1 (a_h a_y - g_v a_x) + m_2 (a_h c_y - g_v c_x),    Q2 = m_2 (a_h d_y - g_v d_x).

Both joints open (``sb``, ``ss`` != 0): the 2 x 2 system. The base joint open and the seat
closed (phi = 0): one body, theta_1'' = (f_1 + f_2) / (M11 + 2 M12 + M22). The base closed and
the seat open (theta_1 = 0): theta_2'' = f_2 / M22. Both closed: rest.

Contact forces follow from Newton-Euler on the part above each joint: the seat carries
F_s = m_2 a_G2 - F_2 (F_i = (-m_i a_h, -m_i g_v)) with the moment M_s(P) = I_2 theta_2'' +
(G_2 - P) x F_s about a point P; the base carries F_b = m_1 a_G1 - F_1 + F_s with
M_b(P) = I_1 theta_1'' + (G_1 - P) x (m_1 a_G1 - F_1) + M_s(P). A closed joint stands while
the resultant lies on its contact: M(left corner) >= 0 and M(right corner) <= 0; an open joint
needs N >= 0 at its pivot. Impulses take the same formulas with the accelerations replaced by
the jumps of velocity and no external force (the weights and the base's inertia are finite).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rockyade.motion.ground import ground_acceleration

# the parameter vector (rockyade.twoblock.stack.TwoBlockModel.params)
(
    M1,
    I1,
    M2,
    I2,
    BLX,
    BRX,
    SLX,
    SRX,
    HS,
    G1X,
    G1Y,
    G2X,
    G2Y,
    GRAV,
    MOMENT_SCALE,
    WEIGHT,
    MU_BASE,
    MU_SEAT,
    P2_BASE,
    ALPHA_BASE,
    P2_SEAT,
    ALPHA_SEAT,
    N_PARAMS,
) = range(23)

#: A candidate mode or impact outcome is admissible when its worst normalised violation is below this.
ADMISSIBLE_TOL = 1e-9


@numba.njit(cache=True)
def kinematics(th1, phi, sb, ss, prm):
    """Pivot O (x; y = 0) and the vectors a, c, d of the module docstring (base frame, m)."""
    ox = prm[BLX] if sb >= 0 else prm[BRX]
    sx = prm[SLX] if ss >= 0 else prm[SRX]
    c1, s1 = math.cos(th1), math.sin(th1)
    th2 = th1 + phi
    c2, s2 = math.cos(th2), math.sin(th2)
    r1x, r1y = prm[G1X] - ox, prm[G1Y]
    sxr, syr = sx - ox, prm[HS]
    r2x, r2y = prm[G2X] - sx, prm[G2Y] - prm[HS]
    ax, ay = c1 * r1x - s1 * r1y, s1 * r1x + c1 * r1y
    cx, cy = c1 * sxr - s1 * syr, s1 * sxr + c1 * syr
    dx, dy = c2 * r2x - s2 * r2y, s2 * r2x + c2 * r2y
    return ox, ax, ay, cx, cy, dx, dy


@numba.njit(cache=True)
def accelerations(th1, phi, w1, wphi, sb, ss, ah, av, prm):
    """(theta_1'', phi'') of the mode (sb, ss), rad/s^2 (module docstring)."""
    if sb == 0 and ss == 0:
        return 0.0, 0.0
    _ox, ax, ay, cx, cy, dx, dy = kinematics(th1, phi, sb, ss, prm)
    m1, m2 = prm[M1], prm[M2]
    gv = prm[GRAV] + av
    w2 = w1 + wphi
    x = cx * dy - cy * dx
    q1 = m1 * (ah * ay - gv * ax) + m2 * (ah * cy - gv * cx)
    q2 = m2 * (ah * dy - gv * dx)
    f1 = q1 + m2 * x * w2 * w2
    f2 = q2 - m2 * x * w1 * w1
    m11 = prm[I1] + m1 * (ax * ax + ay * ay) + m2 * (cx * cx + cy * cy)
    m22 = prm[I2] + m2 * (dx * dx + dy * dy)
    m12 = m2 * (cx * dx + cy * dy)
    if ss == 0:  # one body about O
        dd = (f1 + f2) / (m11 + 2.0 * m12 + m22)
        return dd, 0.0
    if sb == 0:  # the upper block alone about S
        return 0.0, f2 / m22
    det = m11 * m22 - m12 * m12
    dd1 = (f1 * m22 - f2 * m12) / det
    dd2 = (m11 * f2 - m12 * f1) / det
    return dd1, dd2 - dd1


@numba.njit(cache=True)
def joint_loads(th1, phi, sb, ss, dd1, dd2, a1x, a1y, a2x, a2y, f1x, f1y, f2x, f2y, prm):
    """What the joints carry, from the blocks' motion (module docstring).

    Parameters: the blocks' angular accelerations dd1, dd2 (absolute), their centroids'
    accelerations a1, a2 and the external forces F1, F2 (or, for an impact, the jumps of
    angular and centroid velocity and zero forces).

    Returns (N_b, T_b, M_b(left corner), -M_b(right corner), N_s, T_s, M_s(left seat corner),
    -M_s(right seat corner)): normal and tangential components in each joint's frame (the
    seat's turns with the lower block) and the two moment margins of each joint.
    """
    ox, ax, ay, cx, cy, dx, dy = kinematics(th1, phi, sb, ss, prm)
    m1, m2 = prm[M1], prm[M2]
    g1x, g1y = ox + ax, ay
    g2x, g2y = ox + cx + dx, cy + dy
    fsx, fsy = m2 * a2x - f2x, m2 * a2y - f2y
    fbx, fby = m1 * a1x - f1x + fsx, m1 * a1y - f1y + fsy
    c1, s1 = math.cos(th1), math.sin(th1)
    # the seat's corners where the lower block has carried them
    hs = prm[HS]
    sl_x = ox + c1 * (prm[SLX] - ox) - s1 * hs
    sl_y = s1 * (prm[SLX] - ox) + c1 * hs
    sr_x = ox + c1 * (prm[SRX] - ox) - s1 * hs
    sr_y = s1 * (prm[SRX] - ox) + c1 * hs
    ms_l = prm[I2] * dd2 + (g2x - sl_x) * fsy - (g2y - sl_y) * fsx
    ms_r = prm[I2] * dd2 + (g2x - sr_x) * fsy - (g2y - sr_y) * fsx
    n_s = -s1 * fsx + c1 * fsy
    t_s = c1 * fsx + s1 * fsy
    lx = m1 * a1x - f1x
    ly = m1 * a1y - f1y
    mb_l = prm[I1] * dd1 + (g1x - prm[BLX]) * ly - g1y * lx + prm[I2] * dd2 + (g2x - prm[BLX]) * fsy - g2y * fsx
    mb_r = prm[I1] * dd1 + (g1x - prm[BRX]) * ly - g1y * lx + prm[I2] * dd2 + (g2x - prm[BRX]) * fsy - g2y * fsx
    return fby, fbx, mb_l, -mb_r, n_s, t_s, ms_l, -ms_r


@numba.njit(cache=True)
def centroid_accelerations(th1, phi, w1, wphi, dd1, ddphi, sb, ss, prm):
    """Accelerations of the two centroids relative to the base, m/s^2: (a1x, a1y, a2x, a2y)."""
    _ox, ax, ay, cx, cy, dx, dy = kinematics(th1, phi, sb, ss, prm)
    w2 = w1 + wphi
    dd2 = dd1 + ddphi
    a1x = -dd1 * ay - w1 * w1 * ax
    a1y = dd1 * ax - w1 * w1 * ay
    a2x = -dd1 * cy - w1 * w1 * cx - dd2 * dy - w2 * w2 * dx
    a2y = dd1 * cx - w1 * w1 * cy + dd2 * dx - w2 * w2 * dy
    return a1x, a1y, a2x, a2y


@numba.njit(cache=True)
def contact_state(th1, phi, w1, wphi, sb, ss, ah, av, prm):
    """:func:`joint_loads` of the motion in mode (sb, ss) at a state and base acceleration."""
    dd1, ddphi = accelerations(th1, phi, w1, wphi, sb, ss, ah, av, prm)
    a1x, a1y, a2x, a2y = centroid_accelerations(th1, phi, w1, wphi, dd1, ddphi, sb, ss, prm)
    gv = prm[GRAV] + av
    m1, m2 = prm[M1], prm[M2]
    return joint_loads(
        th1, phi, sb, ss, dd1, dd1 + ddphi, a1x, a1y, a2x, a2y, -m1 * ah, -m1 * gv, -m2 * ah, -m2 * gv, prm
    )


@numba.njit(cache=True)
def _violation(sb, ss, loads, open_b, open_s, rate_b, rate_s, force_scale, moment_scale, rate_scale, held_b, held_s):
    """Worst normalised violation of the conditions of mode (sb, ss): closed joints keep their
    resultant on the contact, open pivots press (N >= 0; not asked of a pivot ``held`` past its
    alpha, where the block falls either way and the pivot is held as Housner's is), and a joint
    that opens now turns the way it opens (``rate``: its relative acceleration, or velocity
    after an impact)."""
    nb, _tb, mbl, mbr, ns, _ts, msl, msr = loads
    worst = 0.0
    if sb == 0:
        worst = max(worst, -mbl / moment_scale, -mbr / moment_scale)
    else:
        if not held_b:
            worst = max(worst, -nb / force_scale)
        if open_b:
            worst = max(worst, -sb * rate_b / rate_scale)
    if ss == 0:
        worst = max(worst, -msl / moment_scale, -msr / moment_scale)
    else:
        if not held_s:
            worst = max(worst, -ns / force_scale)
        if open_s:
            worst = max(worst, -ss * rate_s / rate_scale)
    return worst


@numba.njit(cache=True)
def held(th1, phi, prm):
    """Whether each joint's pivot is held when it pulls (the integrator's flight test and
    :func:`choose_mode` skip it): past the joint's alpha (base: |theta_1|, seat: |phi|), or,
    for the seat, while the lower block is past its own (the stack is falling; the upper block
    goes with it). There the block falls either way, and its pivot is held as Housner's is."""
    base = abs(th1) > prm[ALPHA_BASE]
    return base, base or abs(phi) > prm[ALPHA_SEAT]


@numba.njit(cache=True)
def choose_mode(th1, phi, w1, wphi, sb, ss, ah, av, prm, free_b, free_s, exclude_b, exclude_s):
    """The mode the stack moves in from this state: every joint marked free (closed, at rest
    relative to its support) may stay closed or open about either corner; the admissible
    candidate with the fewest opened joints wins (module docstring's conditions).

    ``exclude_b``/``exclude_s``: that free joint may not stay closed (its closed condition has
    just been found violated). Returns (sb, ss, violation): the violation (normalised) of the
    candidate chosen, > ADMISSIBLE_TOL when none is admissible (the least violated is returned).
    """
    best_v = math.inf
    best_n = 3
    best_b = sb
    best_s = ss
    g = prm[GRAV]
    force_scale = prm[WEIGHT]
    moment_scale = prm[MOMENT_SCALE]
    rate_scale = g * prm[WEIGHT] / prm[MOMENT_SCALE]  # g / height
    hb, hs = held(th1, phi, prm)
    for cb in range(-1, 2):
        if not free_b and cb != sb:
            continue
        if free_b and exclude_b and cb == 0:
            continue
        for cs in range(-1, 2):
            if not free_s and cs != ss:
                continue
            if free_s and exclude_s and cs == 0:
                continue
            dd1, ddphi = accelerations(th1, phi, w1, wphi, cb, cs, ah, av, prm)
            a1x, a1y, a2x, a2y = centroid_accelerations(th1, phi, w1, wphi, dd1, ddphi, cb, cs, prm)
            gv = g + av
            m1, m2 = prm[M1], prm[M2]
            loads = joint_loads(
                th1, phi, cb, cs, dd1, dd1 + ddphi, a1x, a1y, a2x, a2y, -m1 * ah, -m1 * gv, -m2 * ah, -m2 * gv, prm
            )
            v = _violation(
                cb,
                cs,
                loads,
                free_b and cb != 0,
                free_s and cs != 0,
                dd1,
                ddphi,
                force_scale,
                moment_scale,
                rate_scale,
                hb,
                hs,
            )
            n_open = (1 if (free_b and cb != 0) else 0) + (1 if (free_s and cs != 0) else 0)
            ok = v <= ADMISSIBLE_TOL
            best_ok = best_v <= ADMISSIBLE_TOL
            if (ok and (not best_ok or n_open < best_n)) or (not ok and not best_ok and v < best_v):
                best_v, best_n, best_b, best_s = v, n_open, cb, cs
    return best_b, best_s, best_v


@numba.njit(cache=True)
def _momenta(th1, phi, w1, wphi, sb, ss, px, py, qx, qy, prm):
    """Angular momenta, kg m^2/s: of the upper block about the point (px, py), and of both
    blocks about (qx, qy), the velocities taken in the chain of pivots (sb, ss)."""
    ox, ax, ay, cx, cy, dx, dy = kinematics(th1, phi, sb, ss, prm)
    w2 = w1 + wphi
    m1, m2 = prm[M1], prm[M2]
    v1x, v1y = -w1 * ay, w1 * ax
    v2x, v2y = -w1 * cy - w2 * dy, w1 * cx + w2 * dx
    g1x, g1y = ox + ax, ay
    g2x, g2y = ox + cx + dx, cy + dy
    h_up_p = prm[I2] * w2 + m2 * ((g2x - px) * v2y - (g2y - py) * v2x)
    h_up_q = prm[I2] * w2 + m2 * ((g2x - qx) * v2y - (g2y - qy) * v2x)
    h_all = prm[I1] * w1 + m1 * ((g1x - qx) * v1y - (g1y - qy) * v1x) + h_up_q
    return h_up_p, h_all


@numba.njit(cache=True)
def _centroid_velocities(th1, phi, w1, wphi, sb, ss, prm):
    """Velocities of the two centroids relative to the base, m/s: (v1x, v1y, v2x, v2y)."""
    _ox, ax, ay, cx, cy, dx, dy = kinematics(th1, phi, sb, ss, prm)
    w2 = w1 + wphi
    return -w1 * ay, w1 * ax, -w1 * cy - w2 * dy, w1 * cx + w2 * dx


@numba.njit(cache=True)
def post_impact(th1, phi, w1, wphi, sb, ss, nb_, ns_, prm):
    """Velocities (theta_1', phi') just after an impact, in the mode (nb_, ns_) after it:
    the angular momentum of the upper block about its seat pivot (when the seat is open after
    the impact) and of the stack about its base pivot (when the base is open) are conserved
    (the impulses act at those points only); a closed joint's relative velocity is zero."""
    ox_new = prm[BLX] if nb_ >= 0 else prm[BRX]
    c1, s1 = math.cos(th1), math.sin(th1)
    sx0 = prm[SLX] if ns_ >= 0 else prm[SRX]
    # the new seat pivot, carried by the lower block (about the old base pivot: same point)
    ox_old = prm[BLX] if sb >= 0 else prm[BRX]
    spx = ox_old + c1 * (sx0 - ox_old) - s1 * prm[HS]
    spy = s1 * (sx0 - ox_old) + c1 * prm[HS]
    h_up, h_all = _momenta(th1, phi, w1, wphi, sb, ss, spx, spy, ox_new, 0.0, prm)
    if nb_ == 0 and ns_ == 0:
        return 0.0, 0.0
    if nb_ == 0:  # theta_1' = 0: the upper block's momentum about S fixes phi'
        u1, _ = _momenta(th1, phi, 0.0, 1.0, nb_, ns_, spx, spy, ox_new, 0.0, prm)
        return 0.0, h_up / u1
    if ns_ == 0:  # one body: phi' = 0
        _, a1 = _momenta(th1, phi, 1.0, 0.0, nb_, ns_, spx, spy, ox_new, 0.0, prm)
        return h_all / a1, 0.0
    ub, ab = _momenta(th1, phi, 1.0, 0.0, nb_, ns_, spx, spy, ox_new, 0.0, prm)
    us, as_ = _momenta(th1, phi, 0.0, 1.0, nb_, ns_, spx, spy, ox_new, 0.0, prm)
    det = ub * as_ - us * ab
    return (h_up * as_ - us * h_all) / det, (ub * h_all - ab * h_up) / det


@numba.njit(cache=True)
def impact(th1, phi, w1, wphi, sb, ss, joint, prm):
    """The outcome of an impact at ``joint`` (0 base, 1 seat), which lands on the corner
    opposite its pivot: the impacting joint either rocks on about the landing corner or stays
    closed; the other joint, if open, keeps its pivot; if closed, it stays closed or is thrown
    open about either corner. The admissible outcome with the fewest opened joints is chosen
    (impulses pressing, a closed joint's impulse on its contact, an opened joint opening).

    Returns (sb, ss, theta_1', phi', violation, tangential / normal impulse at the landing
    corner (friction needed)).
    """
    land_b = -sb if joint == 0 else sb
    land_s = -ss if joint == 1 else ss
    v1x0, v1y0, v2x0, v2y0 = _centroid_velocities(th1, phi, w1, wphi, sb, ss, prm)
    w2_0 = w1 + wphi
    scale_w = abs(w1) + abs(w2_0) + 1e-300
    height = prm[MOMENT_SCALE] / prm[WEIGHT]
    force_scale = (prm[M1] + prm[M2]) * height * scale_w
    moment_scale = force_scale * height
    best_v = math.inf
    best_n = 3
    hb, hs = held(th1, phi, prm)
    out_b, out_s, out_w1, out_wphi, ratio = sb, ss, w1, wphi, 0.0
    for cb in range(-1, 2):
        if joint == 0:
            if cb != 0 and cb != land_b:
                continue
        elif sb != 0 and cb != sb:
            continue
        for cs in range(-1, 2):
            if joint == 1:
                if cs != 0 and cs != land_s:
                    continue
            elif ss != 0 and cs != ss:
                continue
            nw1, nwphi = post_impact(th1, phi, w1, wphi, sb, ss, cb, cs, prm)
            v1x, v1y, v2x, v2y = _centroid_velocities(th1, phi, nw1, nwphi, cb, cs, prm)
            loads = joint_loads(
                th1,
                phi,
                cb,
                cs,
                nw1 - w1,
                nw1 + nwphi - w2_0,
                v1x - v1x0,
                v1y - v1y0,
                v2x - v2x0,
                v2y - v2y0,
                0.0,
                0.0,
                0.0,
                0.0,
                prm,
            )
            opens_b = cb != 0 and (joint == 0 or sb == 0)
            opens_s = cs != 0 and (joint == 1 or ss == 0)
            v = _violation(cb, cs, loads, opens_b, opens_s, nw1, nwphi, force_scale, moment_scale, scale_w, hb, hs)
            n_open = (1 if opens_b else 0) + (1 if opens_s else 0)
            ok = v <= ADMISSIBLE_TOL
            best_ok = best_v <= ADMISSIBLE_TOL
            if (ok and (not best_ok or n_open < best_n)) or (not ok and not best_ok and v < best_v):
                best_v, best_n = v, n_open
                out_b, out_s, out_w1, out_wphi = cb, cs, nw1, nwphi
                nbi, tbi, _a, _b, nsi, tsi, _c, _d = loads
                n_imp, t_imp = (nbi, tbi) if joint == 0 else (nsi, tsi)
                ratio = abs(t_imp) / n_imp if n_imp > 0.0 else math.inf
    return out_b, out_s, out_w1, out_wphi, best_v, ratio


@numba.njit(cache=True)
def energy(th1, phi, w1, wphi, sb, ss, prm):
    """Kinetic energy plus the weights' potential above rest, J (base at rest)."""
    _ox, ax, ay, cx, cy, dx, dy = kinematics(th1, phi, sb, ss, prm)
    m1, m2 = prm[M1], prm[M2]
    w2 = w1 + wphi
    m11 = prm[I1] + m1 * (ax * ax + ay * ay) + m2 * (cx * cx + cy * cy)
    m22 = prm[I2] + m2 * (dx * dx + dy * dy)
    m12 = m2 * (cx * dx + cy * dy)
    kinetic = 0.5 * (m11 * w1 * w1 + 2.0 * m12 * w1 * w2 + m22 * w2 * w2)
    g = prm[GRAV]
    potential = m1 * g * (ay - prm[G1Y]) + m2 * g * (cy + dy - prm[G2Y])
    return kinetic + potential


@numba.njit(cache=True)
def at_rest_margins(ah, av, prm):
    """The four moment margins of the stack at rest under the base acceleration (a_h, a_v):
    (base left, base right, seat left, seat right), N m; affine in (a_h, a_v)."""
    closed = np.int64(0)  # not the literal 0: numba would compile contact_state's callees again for it
    out = contact_state(0.0, 0.0, 0.0, 0.0, closed, closed, ah, av, prm)
    return out[2], out[3], out[6], out[7]


@numba.njit(cache=True)
def ground(t, mt, mah, mav):
    """Base acceleration (a_h, a_v) at t, m/s^2 (:func:`rockyade.motion.ground.ground_acceleration`)."""
    ah, av, _ = ground_acceleration(t, mt, mah, mav, 0)
    return ah, av


def parameter_count() -> int:
    """Length of the parameter vector."""
    return N_PARAMS


__all__ = [
    "ADMISSIBLE_TOL",
    "accelerations",
    "at_rest_margins",
    "choose_mode",
    "contact_state",
    "energy",
    "impact",
    "joint_loads",
    "kinematics",
    "parameter_count",
    "post_impact",
]
