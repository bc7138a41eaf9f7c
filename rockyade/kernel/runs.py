"""Many runs of one body in one call: the runs of a study that share a structure (the same
block, joint, time step and length) and differ in their base motion.

:func:`simulate_runs` steps them together: chunks of up to :data:`CHUNK_RUNS` runs, in
parallel over numba's threads (``prange``), each chunk advanced step by step with the inner
loop over its runs (:func:`step_runs`: the runs' state held by field), and a run that ends
drops out of its chunk. Each run's arithmetic is that of
the single-body loop (:func:`rockyade.kernel.single.run_body`), both from :mod:`.step`, so
the results are the same bits as one run at a time (each by the single-body kernel,
:func:`rockyade.kernel.single.simulate_single`; ``tests/test_runs_batched.py``). The summary's metrics are computed
in the kernel from each run's samples:

* peak |theta| over the samples and the time of its first sample, rad and s;
* the residual theta, the last sample's, rad;
* the uplift time, the first sample with |theta| above a threshold, s (NaN: never);
* how the run ended, when, and the first time |theta| reached the stop angle.

Only the sampled position, angle and angular velocity are kept (what the outcome and the
summary need); a run that ends early stops there (its remaining samples stay NaN).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.contact_law import JointLaw, joint_law
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


class RunsOutput(NamedTuple):
    """What :func:`simulate_runs` returns, one row per run."""

    status: NDArray[np.int64]  #: (R,) STATUS_COMPLETED, STATUS_OVERTURNED or STATUS_FAILED
    t_stop: NDArray[np.float64]  #: (R,) time the run ended early, s (-1: it ran to the end)
    n_filled: NDArray[np.int64]  #: (R,) samples written
    overturn_time: NDArray[np.float64]  #: (R,) first time |theta| >= the stop angle, s (NaN: never)
    pos: NDArray[np.float64]  #: (R, n_samples, 2) centroids, m (NaN after the run ended)
    ang: NDArray[np.float64]  #: (R, n_samples) angles, rad
    angvel: NDArray[np.float64]  #: (R, n_samples) step-mean angular velocities, rad/s
    max_abs_theta: NDArray[np.float64]  #: (R,) peak |theta| over the samples, rad
    max_abs_theta_time: NDArray[np.float64]  #: (R,) its (first) sample time, s
    residual_theta: NDArray[np.float64]  #: (R,) theta of the last sample, rad
    uplift_time: NDArray[np.float64]  #: (R,) first sample time with |theta| > the threshold, s


@numba.njit(cache=True, nogil=True, inline="always")
def _sample_arrays(n_runs: int, n_samples: int):
    """The runs' samples, NaN until written: positions (R, n_samples, 2), angles and angular
    velocities (R, n_samples)."""
    return (
        np.full((n_runs, n_samples, 2), np.nan),
        np.full((n_runs, n_samples), np.nan),
        np.full((n_runs, n_samples), np.nan),
    )


@numba.njit(cache=True, nogil=True, parallel=True)
def _summaries(ang, n_filled, rest: float, uplift_rad: float, sample_dt: float):
    """The summary's metrics of every run from its samples (module docstring; theta = angle -
    ``rest``): peak |theta| (rad), its first sample time (s), the residual theta (rad) and the
    uplift time (s), each (R,) and NaN for a run without samples (the uplift: NaN when never)."""
    n_runs = n_filled.size
    peak = np.full(n_runs, np.nan)
    peak_t = np.full(n_runs, np.nan)
    residual = np.full(n_runs, np.nan)
    uplift = np.full(n_runs, np.nan)
    for r in numba.prange(n_runs):
        nf = n_filled[r]
        best = -1.0
        for k in range(nf):
            th = ang[r, k] - rest
            if abs(th) > best:
                best = abs(th)
                peak_t[r] = k * sample_dt
            if abs(th) > uplift_rad and np.isnan(uplift[r]):
                uplift[r] = k * sample_dt
        if nf > 0:
            peak[r] = best
            residual[r] = ang[r, nf - 1] - rest
    return peak, peak_t, residual, uplift


@numba.njit(cache=True, nogil=True, inline="always")
def _segment(seg, i: int, h: int, mt, mah, mav) -> None:
    """Slot ``i`` of ``seg`` takes the motion's interval from sample ``h`` to ``h`` + 1."""
    seg[0, i] = mt[h]
    seg[1, i] = mt[h + 1]
    seg[2, i] = mah[h]
    seg[3, i] = mah[h + 1]
    seg[4, i] = mav[h]
    seg[5, i] = mav[h + 1]


@numba.njit(cache=True, nogil=True)
def step_runs(
    lo: int,
    hi: int,
    verts,
    nv: int,
    mass: float,
    inertia: float,
    law: JointLaw,
    rest_ang: float,
    stop_angle: float,
    g: float,
    dt: float,
    n_steps: int,
    sps: int,
    mass_damping: float,
    stop_on_overturn: bool,
    mt,
    mah,
    mav,
    starts,
    x0: float,
    y0: float,
    ang0: float,
    vx0: float,
    vy0: float,
    w0: float,
    status,
    t_stop,
    n_filled,
    overturn_t,
    pos,
    ang_s,
    angvel_s,
) -> None:
    """Step runs ``lo`` to ``hi`` - 1 together (module docstring): each step, the inner loop goes
    over the runs still going (their state held by field, one array each, by slot), each run's
    arithmetic that of :func:`rockyade.kernel.single.run_body` (operation for operation, so the
    same doubles; the samples' extras that the runs do not keep left out); a run that ends drops
    out of the active set, which is compacted at once.

    Parameters
    ----------
    lo, hi
        The runs stepped by this call.
    verts, nv, mass, inertia, law, rest_ang, stop_angle, g, dt, n_steps, sps, mass_damping,
    stop_on_overturn
        As :func:`rockyade.kernel.single.run_body` (SI units).
    mt, mah, mav, starts
        The runs' base motions one after the other (s, m/s^2, m/s^2) and where each starts.
    x0, y0, ang0, vx0, vy0, w0
        The shared initial state (m, rad, m/s, rad/s).
    status, t_stop, n_filled, overturn_t, pos, ang_s, angvel_s
        :class:`RunsOutput`'s arrays, rows ``lo`` to ``hi`` - 1 written.
    """
    n = hi - lo
    # the state of the runs still going, by slot (slot i holds run run_of[i])
    run_of = np.arange(lo, hi)
    x = np.full(n, x0)
    y = np.full(n, y0)
    ang = np.full(n, ang0)
    vx = np.full(n, vx0)
    vy = np.full(n, vy0)
    w = np.full(n, w0)
    shear = np.zeros((n, nv))
    hint = np.zeros(n, dtype=np.int64)
    first = np.empty(n, dtype=np.int64)
    t_last = np.empty(n)
    ot = np.full(n, math.nan)
    # each run's motion: its first and last sample, and the interval the time is in
    t_first = np.zeros(n)
    a_last = np.zeros((2, n))
    seg = np.zeros((6, n))  # t, t', a_h, a_h', a_v, a_v' at the interval's ends
    for i in range(n):
        a, b = starts[lo + i], starts[lo + i + 1]
        first[i] = a
        t_last[i] = mt[b - 1] if b - a >= 2 else -math.inf
        if b - a >= 2:
            t_first[i] = mt[a]
            a_last[0, i] = mah[b - 1]
            a_last[1, i] = mav[b - 1]
            _segment(seg, i, a, mt, mah, mav)
    done = np.zeros(n, dtype=np.bool_)
    n_act = n
    for step in range(n_steps + 1):
        if n_act == 0:
            break
        t = step * dt
        sampling = step % sps == 0
        k = step // sps
        n_done = 0
        for i in range(n_act):
            # the base acceleration (run_body's lookup, this run's motion)
            ah = 0.0
            av = 0.0
            if t < t_last[i] and t >= t_first[i]:
                if t >= seg[1, i]:  # the next interval (rare: a record's samples are many steps apart)
                    a = first[i]
                    h = hint[i]
                    while t >= mt[a + h + 1]:
                        h += 1
                    hint[i] = h
                    _segment(seg, i, a + h, mt, mah, mav)
                u = fraction(t, seg[0, i], seg[1, i] - seg[0, i])
                ah = lerp(u, seg[2, i], seg[3, i] - seg[2, i])
                av = lerp(u, seg[4, i], seg[5, i] - seg[4, i])
            elif t == t_last[i]:
                ah = a_last[0, i]
                av = a_last[1, i]
            xi, yi, angi, vxi, vyi, wi = x[i], y[i], ang[i], vx[i], vy[i], w[i]
            c = math.cos(angi)
            s = math.sin(angi)
            fx = -mass * ah
            fy = -mass * (g + av)
            tz = 0.0
            for v in range(nv):
                py = world_y(yi, c, s, verts[v, 0], verts[v, 1])
                if -py < 0.0:
                    if shear[i, v] != 0.0:
                        shear[i, v] = 0.0
                    continue
                px = world_x(xi, c, s, verts[v, 0], verts[v, 1])
                cfx, cfy, ctz, _fn, _spring, s_new, _visc, _state, _slip = base_point(
                    px, py, xi, yi, vxi, vyi, wi, shear[i, v], law, dt
                )
                shear[i, v] = s_new
                fx += cfx
                fy += cfy
                tz += ctz
            # kick
            w_prev = wi
            if mass_damping > 0.0:
                fdx, fdy, tdz = damping(mass, inertia, mass_damping, vxi, vyi, wi)
                fx += fdx
                fy += fdy
                tz += tdz
            vxi = kicked(vxi, fx, mass, dt)
            vyi = kicked(vyi, fy, mass, dt)
            wi = kicked(wi, tz, inertia, dt)
            if sampling:
                r = run_of[i]
                pos[r, k, 0] = xi
                pos[r, k, 1] = yi
                ang_s[r, k] = angi
                angvel_s[r, k] = 0.5 * (wi + w_prev)
                n_filled[r] = k + 1
            if step == n_steps:
                done[i] = True
                n_done += 1
                continue
            # drift, then the blow-up and overturn checks
            xi = drifted(xi, vxi, dt)
            yi = drifted(yi, vyi, dt)
            angi = drifted(angi, wi, dt)
            x[i], y[i], ang[i], vx[i], vy[i], w[i] = xi, yi, angi, vxi, vyi, wi
            st = STATUS_COMPLETED
            if blown_up(vxi, vyi, wi):
                st = STATUS_FAILED
            elif beyond_stop_angle(angi, rest_ang, stop_angle) and math.isnan(ot[i]):
                ot[i] = (step + 1) * dt
                if stop_on_overturn:
                    st = STATUS_OVERTURNED
            if st != STATUS_COMPLETED:
                r = run_of[i]
                status[r] = st
                t_stop[r] = (step + 1) * dt
                done[i] = True
                n_done += 1
        if n_done:
            # the runs that ended drop out: their last values out, the others moved down
            keep = 0
            for i in range(n_act):
                if done[i]:
                    overturn_t[run_of[i]] = ot[i]
                    continue
                if keep != i:
                    run_of[keep], x[keep], y[keep], ang[keep] = run_of[i], x[i], y[i], ang[i]
                    vx[keep], vy[keep], w[keep], hint[keep] = vx[i], vy[i], w[i], hint[i]
                    first[keep], t_first[keep], t_last[keep], ot[keep] = first[i], t_first[i], t_last[i], ot[i]
                    a_last[0, keep], a_last[1, keep] = a_last[0, i], a_last[1, i]
                    for f in range(6):
                        seg[f, keep] = seg[f, i]
                    for v in range(nv):
                        shear[keep, v] = shear[i, v]
                done[keep] = False
                keep += 1
            n_act = keep


#: Runs stepped together by one call of :func:`step_runs` at most (a chunk: their state stays
#: in the core's caches, and the chunks are shared out among numba's threads).
CHUNK_RUNS = 16


@numba.njit(cache=True, nogil=True, parallel=True)
def simulate_runs(bodies, joints, settings, initial, mt, mah, mav, starts, uplift_rad: float, sample_dt: float):
    """Run R motions on one body, stepped together (module docstring): the runs are cut into
    chunks of at most :data:`CHUNK_RUNS` runs, in parallel over numba's threads, and each chunk is stepped by
    :func:`step_runs`; the same results, bit for bit, as one run at a time by
    :func:`rockyade.kernel.single.simulate_single`.

    Parameters
    ----------
    bodies, joints, settings, initial
        The records of :func:`rockyade.kernel.state.pack` for the shared structure (one
        moving body, ``record_energy`` and ``record_corners`` off).
    mt, mah, mav
        The runs' base motions one after the other: s, m/s^2, m/s^2.
    starts
        (R + 1,) where each run's motion starts in them (the last: their length).
    uplift_rad
        |theta| above which the block has lifted off, rad.
    sample_dt
        Time between samples, s.

    Returns
    -------
    RunsOutput
    """
    n_runs = starts.size - 1
    nv = bodies.nverts[0]
    n_samples = settings.n_steps // settings.steps_per_sample + 1
    j = joints.base_joint[0]
    rest = bodies.rest_ang[0]
    status = np.full(n_runs, STATUS_COMPLETED, dtype=np.int64)
    t_stop = np.full(n_runs, -1.0)
    n_filled = np.zeros(n_runs, dtype=np.int64)
    overturn_t = np.full(n_runs, np.nan)
    pos, ang, angvel = _sample_arrays(n_runs, n_samples)
    n_chunks = (n_runs + CHUNK_RUNS - 1) // CHUNK_RUNS
    verts = np.ascontiguousarray(bodies.verts[0, :nv])
    for c in numba.prange(n_chunks):
        lo = c * n_runs // n_chunks
        hi = (c + 1) * n_runs // n_chunks
        if hi > lo:
            step_runs(
                lo,
                hi,
                verts,
                nv,
                bodies.mass[0],
                bodies.inertia[0],
                joint_law(joints, j),
                rest,
                bodies.stop_angle[0],
                settings.g,
                settings.dt,
                settings.n_steps,
                settings.steps_per_sample,
                settings.mass_damping,
                settings.stop_on_overturn,
                mt,
                mah,
                mav,
                starts,
                initial.pos[0, 0],
                initial.pos[0, 1],
                initial.ang[0],
                initial.vel[0, 0],
                initial.vel[0, 1],
                initial.angvel[0],
                status,
                t_stop,
                n_filled,
                overturn_t,
                pos,
                ang,
                angvel,
            )
    peak, peak_t, residual, uplift = _summaries(ang, n_filled, rest, uplift_rad, sample_dt)
    return RunsOutput(status, t_stop, n_filled, overturn_t, pos, ang, angvel, peak, peak_t, residual, uplift)
