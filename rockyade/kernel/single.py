"""The single-body path: one moving polygon on the moving base, without energy terms.

The same physics as the general loop (:mod:`.simulation`), step for step, for the case that most
studies run: one block on the base (fragility, overturning spectra, uncertainty and sensitivity
samples). Its state is held in scalars instead of per-body arrays, there are no candidate pairs,
no dashpot bookkeeping and no energy terms; the results are the same bits as the general loop's
with ``record_energy`` off (the ``n_builds``, ``max_pairs`` and ``n_tests`` of the output are those
of a lone body: 1, 0, 0).

Each step t_n = n dt (the order of :mod:`.simulation`) is the one step of a body of
:mod:`.body_step`, which the runs stepped together (:mod:`.runs`) call too:

1. :func:`~rockyade.kernel.body_step.step_body`: the base acceleration a_h, a_v at t_n, the
   vertices below y = 0 through the one contact law, gravity and the base's inertia, the kick;
2. every ``steps_per_sample`` steps a sample at t_n (:mod:`.recording`);
3. :func:`~rockyade.kernel.body_step.end_step`: the drift, then the blow-up and overturn checks.

:func:`run_body` is the loop itself; :func:`simulate_single` returns the general
kernel's :class:`~rockyade.kernel.recording.Output`, and :func:`rockyade.kernel.runs.simulate_runs_each`
runs many motions of one body with it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rockyade.kernel.body_step import OneBody, end_step, motion_interval, step_body
from rockyade.kernel.integration import STATUS_COMPLETED
from rockyade.kernel.recording import Output, new_samples, output_of


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


@numba.njit(cache=True, nogil=True, inline="always")
def lone_body(bodies, joints, verts) -> OneBody:
    """The one moving body of the records (:func:`single_body`) and its base joint, with the
    polygon ``verts`` (its vertices, ``bodies.verts[0]`` or a contiguous copy), m."""
    j = joints.base_joint[0]
    return OneBody(
        verts,
        bodies.nverts[0],
        bodies.mass[0],
        bodies.inertia[0],
        joints.kn[j],
        joints.ks[j],
        joints.cn[j],
        joints.cs[j],
        joints.tanphi[j],
        bodies.rest_ang[0],
        bodies.stop_angle[0],
        bodies.accel_points[0, 0],
        bodies.accel_points[0, 1],
    )


@numba.njit(cache=True, nogil=True, inline="always")
def start_of(initial) -> tuple[float, float, float, float, float, float]:
    """(x, y, angle, vx, vy, w) of the one body at the start: m, rad, and the velocities at
    t = -dt/2 (m/s, rad/s)."""
    return initial.pos[0, 0], initial.pos[0, 1], initial.ang[0], initial.vel[0, 0], initial.vel[0, 1], initial.angvel[0]


@numba.njit(cache=True, nogil=True)
def run_body(
    one, settings, mt, mah, mav, start, shear, vstate, s_pos, s_ang, s_angvel, s_vpoint, s_ncont, s_slip, s_state
) -> tuple[int, float, int, float]:
    """Run one body from its initial state to the end or an early stop (module docstring).

    Parameters
    ----------
    one
        The body, its base joint, angles and output point (:func:`lone_body`).
    settings
        :class:`rockyade.kernel.state.Settings`: gravity (m/s^2), time step (s), steps, steps
        per sample, mass damping (1/s), whether an overturn ends the run and whether the
        vertices' states are recorded.
    mt, mah, mav
        Base motion samples: s, m/s^2, m/s^2.
    start
        Initial centroid (m), angle (rad) and velocities at t = -dt/2 (m/s, rad/s): :func:`start_of`.
    shear, vstate
        (1, maxv) scratch: shear springs (N, zeroed); (maxv,) vertex states.
    s_pos, s_ang, s_angvel, s_vpoint, s_ncont, s_slip, s_state
        Sample arrays of this body, (n_samples, 2), (n_samples,), ... (NaN-filled), written.

    Returns
    -------
    status, t_stop, n_filled, overturn_time
        How the run ended, when it stopped early (-1: it did not), samples written, and the
        first time |theta| reached the stop angle (NaN: never), s.
    """
    x, y, ang, vx, vy, w = start
    nv = one.nv
    g, dt, n_steps, sps = settings.g, settings.dt, settings.n_steps, settings.steps_per_sample
    record_corners = settings.record_corners
    status = STATUS_COMPLETED
    t_stop = -1.0
    overturn_t = math.nan
    n_filled = 0
    for v in range(nv):
        shear[0, v] = 0.0
        vstate[v] = 0
    # the motion's interval that holds t, kept while t stays in it (walked forward: the times
    # only increase)
    n_motion = mt.size
    t_first = math.inf
    t_last = -math.inf
    ah_end = av_end = 0.0
    hint = 0
    interval = (0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0)
    if n_motion >= 2:
        t_first, t_last = mt[0], mt[n_motion - 1]
        ah_end, av_end = mah[n_motion - 1], mav[n_motion - 1]
        interval = motion_interval(mt, mah, mav, 0)
    next_sample = 0
    for step in range(n_steps + 1):
        t = step * dt
        sampling = step == next_sample
        if sampling:
            next_sample += sps
            if record_corners:
                for v in range(nv):
                    vstate[v] = 0
        c, s, vx_new, vy_new, w_new, ncont, slipping, hint, interval, _ = step_body(
            t,
            mt,
            mah,
            mav,
            0,
            t_first,
            t_last,
            ah_end,
            av_end,
            hint,
            interval,
            one,
            g,
            dt,
            settings.mass_damping,
            x,
            y,
            ang,
            vx,
            vy,
            w,
            shear,
            0,
            sampling,
            vstate,
            record_corners,
        )
        if sampling:
            k = step // sps
            wm = 0.5 * (w_new + w)
            s_pos[k, 0] = x
            s_pos[k, 1] = y
            s_ang[k] = ang
            s_angvel[k] = wm
            qx = c * one.apx - s * one.apy
            qy = s * one.apx + c * one.apy
            s_vpoint[k, 0] = 0.5 * (vx_new + vx) - wm * qy
            s_vpoint[k, 1] = 0.5 * (vy_new + vy) + wm * qx
            s_ncont[k] = ncont
            s_slip[k] = slipping
            if record_corners:
                for v in range(nv):
                    s_state[k, v] = vstate[v]
            n_filled = k + 1
        vx, vy, w = vx_new, vy_new, w_new
        if step == n_steps:
            break
        x, y, ang, status, overturn_t = end_step(
            step, x, y, ang, vx, vy, w, dt, one, settings.stop_on_overturn, overturn_t
        )
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
    status, t_stop, n_filled, overturn_t = run_body(
        lone_body(bodies, joints, bodies.verts[0]),
        settings,
        motion.t_s,
        motion.ah,
        motion.av,
        start_of(initial),
        np.zeros((1, maxv)),
        np.zeros(maxv, dtype=np.int8),
        samples.pos[:, 0, :],
        samples.ang[:, 0],
        samples.angvel[:, 0],
        samples.vpoint[:, 0, :],
        samples.n_contacts[:, 0],
        samples.slipping[:, 0],
        samples.corner_states[:, 0, :],
    )
    samples.overturn_time[0] = overturn_t
    stop_body = 0 if status != STATUS_COMPLETED else -1
    return output_of(samples, status, n_filled, t_stop, stop_body, 1, 0, 0)
