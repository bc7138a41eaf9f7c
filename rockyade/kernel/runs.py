"""Many runs of one body in one call: the runs of a study that share a structure (the same
block, joint, time step and length) and differ in their base motion.

:func:`simulate_runs` steps them together: chunks of up to :data:`CHUNK_RUNS` runs, in
parallel over numba's threads (``prange``), each chunk advanced step by step with the inner
loop over its runs (:func:`step_runs`: the runs' state held by field), and a run that ends
drops out of its chunk. Each run's step is that of the single-body loop
(:func:`rockyade.kernel.single.run_body`): both call the one step of a body of :mod:`.body_step`,
so the results are the same bits as one run at a time (:func:`simulate_runs_each`, which runs
each by ``run_body``; ``tests/test_runs_batched.py``). The summary's metrics are computed
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

from rockyade.kernel.body_step import end_step, motion_interval, step_body
from rockyade.kernel.integration import STATUS_COMPLETED
from rockyade.kernel.single import lone_body, run_body, start_of


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
def new_runs_output(n_runs: int, n_samples: int) -> RunsOutput:
    """A :class:`RunsOutput` of ``n_runs`` runs that have not started: completed, not stopped, no
    sample written, never overturned, NaN samples and metrics."""
    return RunsOutput(
        np.full(n_runs, STATUS_COMPLETED, dtype=np.int64),
        np.full(n_runs, -1.0),
        np.zeros(n_runs, dtype=np.int64),
        np.full(n_runs, np.nan),
        np.full((n_runs, n_samples, 2), np.nan),
        np.full((n_runs, n_samples), np.nan),
        np.full((n_runs, n_samples), np.nan),
        np.full(n_runs, np.nan),
        np.full(n_runs, np.nan),
        np.full(n_runs, np.nan),
        np.full(n_runs, np.nan),
    )


@numba.njit(cache=True, nogil=True)
def summarise(
    n_filled, ang, peak, peak_t, residual, uplift, r: int, rest: float, uplift_rad: float, sample_dt: float
) -> None:
    """The summary's metrics of run ``r`` from its samples (module docstring; theta = angle -
    ``rest``, rad; ``uplift_rad`` the lift-off threshold, rad; ``sample_dt`` s): row ``r`` of
    :class:`RunsOutput`'s ``max_abs_theta``, ``max_abs_theta_time``, ``residual_theta`` and
    ``uplift_time`` (``peak``, ``peak_t``, ``residual``, ``uplift``) written.

    Compiled on its own (not inlined) and given the arrays, not the :class:`RunsOutput`: numba
    (0.68) dropped stores in a ``prange`` loop made through the tuple's fields
    (``out.n_filled[r] = ...``) or by this function inlined there (the metrics stayed NaN)."""
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


@numba.njit(cache=True, nogil=True, parallel=True)
def simulate_runs_each(bodies, joints, settings, initial, mt, mah, mav, starts, uplift_rad: float, sample_dt: float):
    """Run R motions on one body, each by :func:`rockyade.kernel.single.run_body` (the per-run
    path that :func:`simulate_runs` is checked against; the same arguments and results).

    Parameters
    ----------
    bodies, joints, settings, initial
        The records of :func:`rockyade.kernel.state.pack` for the shared structure (one
        moving body, ``record_energy`` off: :func:`rockyade.kernel.single.single_body`).
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
    maxv = bodies.verts.shape[1]
    n_samples = settings.n_steps // settings.steps_per_sample + 1
    out = new_runs_output(n_runs, n_samples)
    status, t_stop, n_filled, overturn_t = out.status, out.t_stop, out.n_filled, out.overturn_time
    pos, ang, angvel = out.pos, out.ang, out.angvel
    peak, peak_t, residual, uplift = out.max_abs_theta, out.max_abs_theta_time, out.residual_theta, out.uplift_time
    for r in numba.prange(n_runs):
        a, b = starts[r], starts[r + 1]
        st, ts, nf, ot = run_body(
            lone_body(bodies, joints, bodies.verts[0]),
            settings,
            mt[a:b],
            mah[a:b],
            mav[a:b],
            start_of(initial),
            np.zeros((1, maxv)),
            np.zeros(maxv, dtype=np.int8),
            pos[r],
            ang[r],
            angvel[r],
            np.empty((n_samples, 2)),
            np.empty(n_samples, dtype=np.int32),
            np.empty(n_samples, dtype=np.bool_),
            np.zeros((n_samples if settings.record_corners else 1, maxv), dtype=np.int8),
        )
        status[r], t_stop[r], n_filled[r], overturn_t[r] = st, ts, nf, ot
        summarise(n_filled, ang, peak, peak_t, residual, uplift, r, bodies.rest_ang[0], uplift_rad, sample_dt)
    return out


@numba.njit(cache=True, nogil=True)
def step_runs(lo: int, hi: int, one, settings, mt, mah, mav, starts, start, out: RunsOutput) -> None:
    """Step runs ``lo`` to ``hi`` - 1 together (module docstring): each step, the inner loop goes
    over the runs still going (their state held by field, one array each, by slot), each run's
    step that of :func:`rockyade.kernel.single.run_body` (the one step of
    :func:`rockyade.kernel.body_step.step_body` and :func:`~rockyade.kernel.body_step.end_step`, so
    the same doubles; the samples' extras that the runs do not keep left out); a run that ends
    drops out of the active set, which is compacted at once.

    Parameters
    ----------
    lo, hi
        The runs stepped by this call.
    one, settings
        The body and its base joint (:class:`rockyade.kernel.body_step.OneBody`) and the
        :class:`rockyade.kernel.state.Settings` (SI units).
    mt, mah, mav, starts
        The runs' base motions one after the other (s, m/s^2, m/s^2) and where each starts.
    start
        The shared initial state (m, rad, m/s, rad/s): :func:`rockyade.kernel.single.start_of`.
    out
        :class:`RunsOutput`, rows ``lo`` to ``hi`` - 1 written.
    """
    nv = one.nv
    dt, n_steps, sps = settings.dt, settings.n_steps, settings.steps_per_sample
    x0, y0, ang0, vx0, vy0, w0 = start
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
    no_states = np.zeros(1, dtype=np.int8)
    hint = np.zeros(n, dtype=np.int64)
    first = np.empty(n, dtype=np.int64)
    t_last = np.empty(n)
    ot = np.full(n, math.nan)
    # each run's motion: its first and last sample, and the interval the time is in
    t_first = np.zeros(n)
    a_last = np.zeros((2, n))
    seg = np.zeros((7, n))  # the interval (body_step.Interval), by field
    for i in range(n):
        a, b = starts[lo + i], starts[lo + i + 1]
        first[i] = a
        t_last[i] = mt[b - 1] if b - a >= 2 else -math.inf
        if b - a >= 2:
            t_first[i] = mt[a]
            a_last[0, i] = mah[b - 1]
            a_last[1, i] = mav[b - 1]
            _store(seg, i, motion_interval(mt, mah, mav, a))
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
            xi, yi, angi, vxi, vyi, wi = x[i], y[i], ang[i], vx[i], vy[i], w[i]
            interval = (seg[0, i], seg[1, i], seg[2, i], seg[3, i], seg[4, i], seg[5, i], seg[6, i])
            _, _, vx_new, vy_new, w_new, _, _, h, interval, moved = step_body(
                t,
                mt,
                mah,
                mav,
                first[i],
                t_first[i],
                t_last[i],
                a_last[0, i],
                a_last[1, i],
                hint[i],
                interval,
                one,
                settings.g,
                dt,
                settings.mass_damping,
                xi,
                yi,
                angi,
                vxi,
                vyi,
                wi,
                shear,
                i,
                False,
                no_states,
                False,
            )
            if moved:
                hint[i] = h
                _store(seg, i, interval)
            if sampling:
                r = run_of[i]
                out.pos[r, k, 0] = xi
                out.pos[r, k, 1] = yi
                out.ang[r, k] = angi
                out.angvel[r, k] = 0.5 * (w_new + wi)
                out.n_filled[r] = k + 1
            if step == n_steps:
                done[i] = True
                n_done += 1
                continue
            xi, yi, angi, st, ot_i = end_step(
                step, xi, yi, angi, vx_new, vy_new, w_new, dt, one, settings.stop_on_overturn, ot[i]
            )
            x[i], y[i], ang[i], vx[i], vy[i], w[i], ot[i] = xi, yi, angi, vx_new, vy_new, w_new, ot_i
            if st != STATUS_COMPLETED:
                r = run_of[i]
                out.status[r] = st
                out.t_stop[r] = (step + 1) * dt
                done[i] = True
                n_done += 1
        if n_done:
            # the runs that ended drop out: their last values out, the others moved down
            keep = 0
            for i in range(n_act):
                if done[i]:
                    out.overturn_time[run_of[i]] = ot[i]
                    continue
                if keep != i:
                    run_of[keep], x[keep], y[keep], ang[keep] = run_of[i], x[i], y[i], ang[i]
                    vx[keep], vy[keep], w[keep], hint[keep] = vx[i], vy[i], w[i], hint[i]
                    first[keep], t_first[keep], t_last[keep], ot[keep] = first[i], t_first[i], t_last[i], ot[i]
                    a_last[0, keep], a_last[1, keep] = a_last[0, i], a_last[1, i]
                    for f in range(7):
                        seg[f, keep] = seg[f, i]
                    for v in range(nv):
                        shear[keep, v] = shear[i, v]
                done[keep] = False
                keep += 1
            n_act = keep


@numba.njit(cache=True, nogil=True, inline="always")
def _store(seg, i: int, interval) -> None:
    """Slot ``i`` of ``seg`` takes an interval (:data:`rockyade.kernel.body_step.Interval`)."""
    for f in range(7):
        seg[f, i] = interval[f]


#: Runs stepped together by one call of :func:`step_runs` at most (a chunk: their state stays
#: in the core's caches, and the chunks are shared out among numba's threads).
CHUNK_RUNS = 16


@numba.njit(cache=True, nogil=True, parallel=True)
def simulate_runs(bodies, joints, settings, initial, mt, mah, mav, starts, uplift_rad: float, sample_dt: float):
    """Run R motions on one body, stepped together (module docstring): the runs are cut into
    chunks of at most :data:`CHUNK_RUNS` runs, in parallel over numba's threads, and each chunk is stepped by
    :func:`step_runs`; the same results, bit for bit, as :func:`simulate_runs_each`, which
    takes the same arguments (``record_corners`` off here) and returns the same
    :class:`RunsOutput`."""
    n_runs = starts.size - 1
    nv = bodies.nverts[0]
    n_samples = settings.n_steps // settings.steps_per_sample + 1
    out = new_runs_output(n_runs, n_samples)
    # the polygon's vertices, contiguous: stepped by every run of a chunk
    verts = np.ascontiguousarray(bodies.verts[0, :nv])
    n_chunks = (n_runs + CHUNK_RUNS - 1) // CHUNK_RUNS
    for c in numba.prange(n_chunks):
        lo = c * n_runs // n_chunks
        hi = (c + 1) * n_runs // n_chunks
        if hi > lo:
            step_runs(lo, hi, lone_body(bodies, joints, verts), settings, mt, mah, mav, starts, start_of(initial), out)
    n_filled, ang = out.n_filled, out.ang
    peak, peak_t, residual, uplift = out.max_abs_theta, out.max_abs_theta_time, out.residual_theta, out.uplift_time
    for r in numba.prange(n_runs):
        summarise(n_filled, ang, peak, peak_t, residual, uplift, r, bodies.rest_ang[0], uplift_rad, sample_dt)
    return out
