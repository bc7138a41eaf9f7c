"""Numba kernel of the reference DEM: rigid convex polygons with the paper's joint.

Contact law (the same as YADE's ``Law2_ScGeom_ViscElPhys_Basic``, and the paper's UDEC
joint of Section 4), at every vertex that penetrates another body or the base:

* normal: F_n = K delta + c_n delta_dot with c_n = beta K, clamped at zero (no tension);
* shear: an incremental spring S += Ks dt v_t (v_t the tangential relative velocity at the
  vertex), capped at F_n tan(phi) (Coulomb; slip), plus a dashpot c_s v_t, c_s = beta Ks,
  only while sticking;
* the shear memory is reset when the contact opens.

Integration: the explicit central-difference (leap-frog) scheme of YADE's NewtonIntegrator:
forces at x_n with velocities v_{n-1/2}; v_{n+1/2} = v_{n-1/2} + dt F/m;
x_{n+1} = x_n + dt v_{n+1/2}. Everything is written in the frame of the base, which moves
with the prescribed ground acceleration: each body feels m (-a_h, -g - a_v).

Recorded every ``steps_per_sample`` steps (at t_n, velocities averaged over the step):
centroid position, rotation, angular velocity, velocity of the output point, the state of
each vertex (0 open, 1 stick, 2 slip) and, optionally, the energy terms.
"""

from __future__ import annotations

import math

import numba
import numpy as np

# energy columns
E_KIN, E_POT, E_EL, E_DASH, E_FRIC, W_BASE = range(6)
N_ENERGY = 6

STATUS_COMPLETED, STATUS_OVERTURNED, STATUS_FAILED = 0, 1, 2

#: Beyond these the state is a numerical blow-up, not rocking (a block overturning under
#: gravity turns at a few rad/s): the run fails instead of being called overturned.
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0


@numba.njit(cache=True, nogil=True)
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


@numba.njit(cache=True, nogil=True)
def simulate(
    mass,
    inertia,
    verts,
    nverts,
    radius,
    kn,
    ks,
    cn,
    cs,
    tanphi,
    mass_damping,
    pos0,
    ang0,
    vel0,
    angvel0,
    mt,
    mah,
    mav,
    g,
    dt,
    n_steps,
    steps_per_sample,
    accel_points,
    record_energy,
):
    """Run the DEM. See the module docstring; arrays are float64 unless stated.

    Parameters
    ----------
    mass, inertia : (nb,)
    verts : (nb, maxv, 2) contact polygon relative to the centroid, body frame, CCW
    nverts : (nb,) int64
    radius : (nb,) bounding radius of each polygon about its centroid
    kn, ks, cn, cs, tanphi : (nb,) joint beneath each body (a contact uses the upper body's)
    mass_damping : float, mass-proportional viscous damping a (1/s), 0 in the paper
    pos0, vel0 : (nb, 2); ang0, angvel0 : (nb,)
    mt, mah, mav : base acceleration samples (may be empty)
    g, dt : float; n_steps, steps_per_sample : int
    accel_points : (nb, 2) output point relative to the centroid, body frame
    record_energy : bool

    Returns
    -------
    pos_s, ang_s, angvel_s, vpoint_s, state_s, energy_s, status, n_filled, t_stop, stop_body
    """
    nb = mass.shape[0]
    maxv = verts.shape[1]
    n_samples = n_steps // steps_per_sample + 1
    pos_s = np.full((n_samples, nb, 2), np.nan)
    ang_s = np.full((n_samples, nb), np.nan)
    angvel_s = np.full((n_samples, nb), np.nan)
    vpoint_s = np.full((n_samples, nb, 2), np.nan)
    state_s = np.zeros((n_samples, nb, maxv), dtype=np.int8)
    energy_s = np.full((n_samples, N_ENERGY), np.nan)

    pos = pos0.copy()
    ang = ang0.copy()
    vel = vel0.copy()
    angvel = angvel0.copy()
    # shear spring memory: (owner body, vertex, target) ; target nb = base
    shear = np.zeros((nb, maxv, nb + 1))
    touched = np.zeros((nb, maxv, nb + 1), dtype=np.bool_)
    vstate = np.zeros((nb, maxv), dtype=np.int8)
    wv = np.zeros((nb, maxv, 2))
    force = np.zeros((nb, 2))
    torque = np.zeros(nb)
    vel_prev = vel0.copy()
    angvel_prev = angvel0.copy()
    # contacts of the current step, for the dashpot power with step-mean velocities:
    # body a, body b (-1 base), point, normal dashpot force, shear dashpot force, n, t
    max_contacts = nb * maxv * (nb + 1)
    cbuf_i = np.zeros((max_contacts, 2), dtype=np.int64)
    cbuf = np.zeros((max_contacts, 8))

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
    half_pi = 0.5 * math.pi

    for step in range(n_steps + 1):
        t = step * dt
        ah, av, jcur = _ground(t, mt, mah, mav, jcur)
        # world positions of the contact vertices
        for a in range(nb):
            c = math.cos(ang[a])
            s = math.sin(ang[a])
            for v in range(nverts[a]):
                x = verts[a, v, 0]
                y = verts[a, v, 1]
                wv[a, v, 0] = pos[a, 0] + c * x - s * y
                wv[a, v, 1] = pos[a, 1] + s * x + c * y
        for a in range(nb):
            force[a, 0] = -mass[a] * ah
            force[a, 1] = -mass[a] * (g + av)
            torque[a] = 0.0
        touched[:, :, :] = False
        vstate[:, :] = 0
        e_el_now = 0.0
        n_contacts = 0
        d_fric = 0.0
        # ---- contacts: each vertex of a against the base and against other bodies b
        for a in range(nb):
            for v in range(nverts[a]):
                px = wv[a, v, 0]
                py = wv[a, v, 1]
                for b in range(-1, nb):
                    if b == a:
                        continue
                    if b < 0:
                        delta = -py
                        if delta < 0.0:
                            continue
                        nx = 0.0
                        ny = 1.0
                        target = nb
                        joint = a
                    else:
                        dx = px - pos[b, 0]
                        dy = py - pos[b, 1]
                        if dx * dx + dy * dy > radius[b] * radius[b]:
                            continue
                        # inside test against the convex polygon b: least penetrated edge
                        best = -1e300
                        bnx = 0.0
                        bny = 0.0
                        inside = True
                        nvb = nverts[b]
                        for e in range(nvb):
                            e2 = e + 1 if e + 1 < nvb else 0
                            ex = wv[b, e2, 0] - wv[b, e, 0]
                            ey = wv[b, e2, 1] - wv[b, e, 1]
                            le = math.sqrt(ex * ex + ey * ey)
                            onx = ey / le
                            ony = -ex / le
                            d = (px - wv[b, e, 0]) * onx + (py - wv[b, e, 1]) * ony
                            if d > 0.0:
                                inside = False
                                break
                            if d > best:
                                best = d
                                bnx = onx
                                bny = ony
                        if not inside:
                            continue
                        delta = -best
                        nx = bnx
                        ny = bny
                        target = b
                        joint = a if a > b else b
                    # relative velocity at the vertex
                    rax = px - pos[a, 0]
                    ray = py - pos[a, 1]
                    vrx = vel[a, 0] - angvel[a] * ray
                    vry = vel[a, 1] + angvel[a] * rax
                    if b >= 0:
                        rbx = px - pos[b, 0]
                        rby = py - pos[b, 1]
                        vrx -= vel[b, 0] - angvel[b] * rby
                        vry -= vel[b, 1] + angvel[b] * rbx
                    ddot = -(vrx * nx + vry * ny)
                    fn_spring = kn[joint] * delta
                    fn = fn_spring + cn[joint] * ddot
                    if fn < 0.0:
                        fn = 0.0
                    tx = -ny
                    ty = nx
                    vt = vrx * tx + vry * ty
                    s_old = shear[a, v, target]
                    s_trial = s_old + ks[joint] * dt * vt
                    smax = fn * tanphi[joint]
                    if abs(s_trial) > smax:
                        s_new = smax if s_trial > 0.0 else -smax
                        visc = 0.0
                        state = 2
                        if record_energy and ks[joint] > 0.0:
                            # the return to the Coulomb limit releases stored spring energy
                            d_fric += 0.5 * (s_trial * s_trial - smax * smax) / ks[joint]
                    else:
                        s_new = s_trial
                        visc = cs[joint] * vt
                        state = 1
                    shear[a, v, target] = s_new
                    touched[a, v, target] = True
                    if state > vstate[a, v]:
                        vstate[a, v] = state
                    fx = fn * nx - (s_new + visc) * tx
                    fy = fn * ny - (s_new + visc) * ty
                    force[a, 0] += fx
                    force[a, 1] += fy
                    torque[a] += rax * fy - ray * fx
                    if b >= 0:
                        force[b, 0] -= fx
                        force[b, 1] -= fy
                        torque[b] -= rbx * fy - rby * fx
                    if record_energy:
                        e_el_now += 0.5 * fn_spring * delta
                        if ks[joint] > 0.0:
                            e_el_now += 0.5 * s_new * s_new / ks[joint]
                        # dashpot forces (normal: beyond the spring, including the clamp)
                        cbuf_i[n_contacts, 0] = a
                        cbuf_i[n_contacts, 1] = b
                        cbuf[n_contacts, 0] = px
                        cbuf[n_contacts, 1] = py
                        cbuf[n_contacts, 2] = fn - fn_spring
                        cbuf[n_contacts, 3] = visc
                        cbuf[n_contacts, 4] = nx
                        cbuf[n_contacts, 5] = ny
                        n_contacts += 1
        # contacts that opened lose their shear memory (and its stored energy)
        for a in range(nb):
            for v in range(nverts[a]):
                for target in range(nb + 1):
                    if not touched[a, v, target] and shear[a, v, target] != 0.0:
                        if record_energy:
                            joint = a if target == nb or a > target else target
                            if ks[joint] > 0.0:
                                d_fric += 0.5 * shear[a, v, target] ** 2 / ks[joint]
                        shear[a, v, target] = 0.0
        # ---- leap-frog update
        e_dash_before = e_dash
        w_base_before = w_base
        for a in range(nb):
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
                vx = 0.5 * (vel[a, 0] + vel_prev[a, 0])
                vy = 0.5 * (vel[a, 1] + vel_prev[a, 1])
                w_base += -mass[a] * (ah * vx + av * vy) * dt
            e_el = e_el_now
        # ---- record at t_n (positions x_n, velocities averaged over the step)
        if step % steps_per_sample == 0:
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
                for v in range(nverts[a]):
                    state_s[k, a, v] = vstate[a, v]
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
            pos[a, 0] += dt * vel[a, 0]
            pos[a, 1] += dt * vel[a, 1]
            ang[a] += dt * angvel[a]
            finite = math.isfinite(pos[a, 0]) and math.isfinite(pos[a, 1]) and math.isfinite(ang[a])
            speed2 = vel[a, 0] * vel[a, 0] + vel[a, 1] * vel[a, 1]
            if not finite or speed2 > MAX_SPEED_M_S * MAX_SPEED_M_S or abs(angvel[a]) > MAX_SPIN_RAD_S:
                status = STATUS_FAILED
                stop_body = a
            elif abs(ang[a]) >= half_pi and status == STATUS_COMPLETED:
                status = STATUS_OVERTURNED
                stop_body = a
        if status != STATUS_COMPLETED:
            t_stop = (step + 1) * dt
            break
    return pos_s, ang_s, angvel_s, vpoint_s, state_s, energy_s, status, n_filled, t_stop, stop_body
