"""The single-body path: one moving polygon on the moving base, without energy terms.

The same physics as the general loop (:mod:`.simulation`), step for step: both take a body's
arithmetic from :mod:`.step` (inlined), for the case that most studies run: one block on the
base (fragility, overturning spectra, uncertainty and sensitivity samples). Its state is held
in scalars instead of per-body arrays, there are no candidate pairs, no dashpot bookkeeping and no energy terms; the
results are the same bits as the general loop's with ``record_energy`` off (the
``n_builds``, ``max_pairs`` and ``n_tests`` of the output are those of a lone body: 1, 0, 0).

Each step t_n = n dt (the order of :mod:`.simulation`):

1. the base acceleration a_h, a_v at t_n (the arithmetic of
   :func:`rockyade.motion.ground.ground_acceleration`, stepping forward through the samples);
2. the vertices p_v = x + R(theta) v_v (:mod:`.placement`);
3. F = m (-a_h, -g - a_v), T = 0;
4. every vertex below y = 0 through the one contact law (:mod:`.contact_law`, as in
   :mod:`.base_contacts`);
5. the kick v_{n+1/2} = v_{n-1/2} + dt F / m (with the optional mass-proportional damping);
6. every ``steps_per_sample`` steps a sample at t_n (:mod:`.recording`);
7. the drift x_{n+1} = x_n + dt v_{n+1/2}, then the blow-up and overturn checks (:mod:`.integration`).

:func:`run_body` is the loop itself; :func:`simulate_single` returns the general
kernel's :class:`~rockyade.kernel.recording.Output`, and :mod:`.runs` steps many runs of one
body with it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rockyade.kernel.contact_law import STATE_SLIP, JointLaw, joint_law
from rockyade.kernel.integration import STATUS_COMPLETED, STATUS_FAILED, STATUS_OVERTURNED
from rockyade.kernel.recording import Output, new_samples, output_of
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


def single_body(bodies, joints, record_energy: bool) -> bool:
    """Whether a run can take the single-body path: one moving body, no pairs, no energy terms,
    no loads (:mod:`rockyade.kernel.point_loads` acts in the general loop only).

    Parameters
    ----------
    bodies, joints
        :class:`rockyade.kernel.state.Bodies` and ``Joints``.
    record_energy
        The run records energy terms (only the general loop does).
    """
    return (
        not record_energy
        and bodies.mass.size == 1
        and bool(bodies.moving[0])
        and joints.pair_keys.size == 0
        and int(joints.base_joint[0]) >= 0
        and not np.any(bodies.load_force)
        and not np.any(bodies.load_arm)
    )


@numba.njit(cache=True, nogil=True)
def run_body(
    verts,
    nv: int,
    mass: float,
    inertia: float,
    law: JointLaw,
    rest_ang: float,
    stop_angle: float,
    apx: float,
    apy: float,
    g: float,
    dt: float,
    n_steps: int,
    sps: int,
    mass_damping: float,
    stop_on_overturn: bool,
    record_corners: bool,
    mt,
    mah,
    mav,
    x: float,
    y: float,
    ang: float,
    vx: float,
    vy: float,
    w: float,
    shear,
    vstate,
    s_pos,
    s_ang,
    s_angvel,
    s_vpoint,
    s_ncont,
    s_slip,
    s_state,
) -> tuple[int, float, int, float]:
    """Run one body from its initial state to the end or an early stop (module docstring).

    Parameters
    ----------
    verts
        (maxv, 2) polygon relative to the centroid, body frame, m; ``nv`` vertices used.
    mass, inertia
        kg and kg m^2.
    law
        The base joint's law: stiffnesses (N/m), dashpots (N s/m), friction coefficient.
    rest_ang, stop_angle
        Orientation at rest and |theta| at which the body has overturned, rad.
    apx, apy
        Output point relative to the centroid, body frame, m.
    g, dt, n_steps, sps, mass_damping
        Gravity (m/s^2), time step (s), steps, steps per sample, mass damping (1/s).
    mt, mah, mav
        Base motion samples: s, m/s^2, m/s^2.
    x, y, ang, vx, vy, w
        Initial centroid (m), angle (rad) and velocities at t = -dt/2 (m/s, rad/s).
    shear, vstate
        (maxv,) scratch: shear springs (N, zeroed) and vertex states.
    s_pos, s_ang, s_angvel, s_vpoint, s_ncont, s_slip, s_state
        Sample arrays of this body, (n_samples, 2), (n_samples,), ... (NaN-filled), written.

    Returns
    -------
    status, t_stop, n_filled, overturn_time
        How the run ended, when it stopped early (-1: it did not), samples written, and the
        first time |theta| reached the stop angle (NaN: never), s.
    """
    status = STATUS_COMPLETED
    t_stop = -1.0
    overturn_t = math.nan
    n_filled = 0
    hint = 0
    for v in range(nv):
        shear[v] = 0.0
        vstate[v] = 0
    n_motion = mt.size
    t_last = mt[n_motion - 1] if n_motion >= 2 else -math.inf
    next_sample = 0
    # the interval [m_lo, m_hi) of the motion samples that holds t, and its spans, kept in
    # scalars while t stays in it (the same operands as indexing the samples every step)
    m_lo = mt[0] if n_motion >= 1 else math.inf
    m_hi = m_lo
    m_span = 1.0
    ah_lo = ah_span = av_lo = av_span = 0.0
    for step in range(n_steps + 1):
        t = step * dt
        # the base acceleration: ground_acceleration's arithmetic, its interval found by
        # walking forward (the times only increase)
        ah = 0.0
        av = 0.0
        if t < t_last and t >= m_lo:
            if t >= m_hi:
                while t >= mt[hint + 1]:
                    hint += 1
                m_lo = mt[hint]
                m_hi = mt[hint + 1]
                m_span = m_hi - m_lo
                ah_lo = mah[hint]
                ah_span = mah[hint + 1] - ah_lo
                av_lo = mav[hint]
                av_span = mav[hint + 1] - av_lo
            u = fraction(t, m_lo, m_span)
            ah = lerp(u, ah_lo, ah_span)
            av = lerp(u, av_lo, av_span)
        elif t == t_last:
            ah = mah[n_motion - 1]
            av = mav[n_motion - 1]
        sampling = step == next_sample
        if sampling:
            next_sample += sps
        c = math.cos(ang)
        s = math.sin(ang)
        fx = -mass * ah
        fy = -mass * (g + av)
        tz = 0.0
        ncont = 0
        slipping = False
        if sampling and record_corners:
            for v in range(nv):
                vstate[v] = 0
        # every vertex (the general loop skips a body above the base that touched nothing
        # last step: then no vertex is below the base and every shear spring is already 0,
        # so visiting them changes nothing)
        for v in range(nv):
            py = world_y(y, c, s, verts[v, 0], verts[v, 1])
            if -py < 0.0:
                if shear[v] != 0.0:
                    shear[v] = 0.0
                continue
            px = world_x(x, c, s, verts[v, 0], verts[v, 1])
            cfx, cfy, ctz, _fn, _spring, s_new, _visc, state, _slip = base_point(
                px, py, x, y, vx, vy, w, shear[v], law, dt
            )
            shear[v] = s_new
            fx += cfx
            fy += cfy
            tz += ctz
            if sampling:
                ncont += 1
                if state == STATE_SLIP:
                    slipping = True
                if record_corners and state > vstate[v]:
                    vstate[v] = state
        # kick
        vx_prev, vy_prev, w_prev = vx, vy, w
        if mass_damping > 0.0:
            fdx, fdy, tdz = damping(mass, inertia, mass_damping, vx, vy, w)
            fx += fdx
            fy += fdy
            tz += tdz
        vx = kicked(vx, fx, mass, dt)
        vy = kicked(vy, fy, mass, dt)
        w = kicked(w, tz, inertia, dt)
        if sampling:
            k = step // sps
            wm = 0.5 * (w + w_prev)
            s_pos[k, 0] = x
            s_pos[k, 1] = y
            s_ang[k] = ang
            s_angvel[k] = wm
            qx = c * apx - s * apy
            qy = s * apx + c * apy
            s_vpoint[k, 0] = 0.5 * (vx + vx_prev) - wm * qy
            s_vpoint[k, 1] = 0.5 * (vy + vy_prev) + wm * qx
            s_ncont[k] = ncont
            s_slip[k] = slipping
            if record_corners:
                for v in range(nv):
                    s_state[k, v] = vstate[v]
            n_filled = k + 1
        if step == n_steps:
            break
        # drift
        x = drifted(x, vx, dt)
        y = drifted(y, vy, dt)
        ang = drifted(ang, w, dt)
        # the general loop's blow-up test: x, y, theta stay finite while the velocities are
        # finite and bounded (tested every step), so testing the velocities alone (NaN fails
        # both comparisons) decides the same
        if blown_up(vx, vy, w):
            status = STATUS_FAILED
        elif beyond_stop_angle(ang, rest_ang, stop_angle) and math.isnan(overturn_t):
            overturn_t = (step + 1) * dt
            if stop_on_overturn:
                status = STATUS_OVERTURNED
        if status != STATUS_COMPLETED:
            t_stop = (step + 1) * dt
            break
    return status, t_stop, n_filled, overturn_t


@numba.njit(cache=True, nogil=True)
def simulate_single(bodies, joints, motion, settings, initial) -> Output:
    """:func:`rockyade.kernel.simulation.simulate` for one moving body without energy terms
    (:func:`single_body`); the same outputs, bit for bit."""
    maxv = bodies.verts.shape[1]
    n_samples = settings.n_steps // settings.steps_per_sample + 1
    samples = new_samples(1, maxv, n_samples, settings.record_corners)
    j = joints.base_joint[0]
    states = samples.corner_states[:, 0, :]
    status, t_stop, n_filled, overturn_t = run_body(
        bodies.verts[0],
        bodies.nverts[0],
        bodies.mass[0],
        bodies.inertia[0],
        joint_law(joints, j),
        bodies.rest_ang[0],
        bodies.stop_angle[0],
        bodies.accel_points[0, 0],
        bodies.accel_points[0, 1],
        settings.g,
        settings.dt,
        settings.n_steps,
        settings.steps_per_sample,
        settings.mass_damping,
        settings.stop_on_overturn,
        settings.record_corners,
        motion.t_s,
        motion.ah,
        motion.av,
        initial.pos[0, 0],
        initial.pos[0, 1],
        initial.ang[0],
        initial.vel[0, 0],
        initial.vel[0, 1],
        initial.angvel[0],
        np.zeros(maxv),
        np.zeros(maxv, dtype=np.int8),
        samples.pos[:, 0, :],
        samples.ang[:, 0],
        samples.angvel[:, 0],
        samples.vpoint[:, 0, :],
        samples.n_contacts[:, 0],
        samples.slipping[:, 0],
        states,
    )
    samples.overturn_time[0] = overturn_t
    stop_body = 0 if status != STATUS_COMPLETED else -1
    return output_of(samples, status, n_filled, t_stop, stop_body, 1, 0, 0)
