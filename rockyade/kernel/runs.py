"""Many runs of one body in one call: the runs of a study that share a structure (the same
block, joint, time step and length) and differ in their base motion, advanced in parallel
over runs (numba ``prange``), each by the single-body loop (:func:`rockyade.kernel.single.run_body`,
the same results bit for bit as one run at a time), with the summary's metrics computed as
each run ends:

* peak |theta| over the samples and the time of its first sample, rad and s;
* the residual theta, the last sample's, rad;
* the uplift time, the first sample with |theta| above a threshold, s (NaN: never);
* how the run ended, when, and the first time |theta| reached the stop angle.

Only the sampled position, angle and angular velocity are kept (what the outcome and the
summary need); a run that ends early stops there (its remaining samples stay NaN) and its
thread takes the next run.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.single import run_body


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


@numba.njit(cache=True, nogil=True, parallel=True)
def simulate_runs(bodies, joints, settings, initial, mt, mah, mav, starts, uplift_rad: float, sample_dt: float):
    """Run R motions on one body (module docstring).

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
    nv = bodies.nverts[0]
    n_samples = settings.n_steps // settings.steps_per_sample + 1
    j = joints.base_joint[0]
    rest = bodies.rest_ang[0]
    status = np.zeros(n_runs, dtype=np.int64)
    t_stop = np.zeros(n_runs)
    n_filled = np.zeros(n_runs, dtype=np.int64)
    overturn_t = np.zeros(n_runs)
    pos = np.full((n_runs, n_samples, 2), np.nan)
    ang = np.full((n_runs, n_samples), np.nan)
    angvel = np.full((n_runs, n_samples), np.nan)
    peak = np.full(n_runs, np.nan)
    peak_t = np.full(n_runs, np.nan)
    residual = np.full(n_runs, np.nan)
    uplift = np.full(n_runs, np.nan)
    for r in numba.prange(n_runs):
        a, b = starts[r], starts[r + 1]
        vpoint = np.empty((n_samples, 2))
        ncont = np.empty(n_samples, dtype=np.int32)
        slip = np.empty(n_samples, dtype=np.bool_)
        states = np.zeros((n_samples if settings.record_corners else 1, maxv), dtype=np.int8)
        st, ts, nf, ot = run_body(
            bodies.verts[0], nv, bodies.mass[0], bodies.inertia[0],
            joints.kn[j], joints.ks[j], joints.cn[j], joints.cs[j], joints.tanphi[j],
            rest, bodies.stop_angle[0], bodies.accel_points[0, 0], bodies.accel_points[0, 1],
            settings.g, settings.dt, settings.n_steps, settings.steps_per_sample, settings.mass_damping,
            settings.stop_on_overturn, settings.record_corners, mt[a:b], mah[a:b], mav[a:b],
            initial.pos[0, 0], initial.pos[0, 1], initial.ang[0], initial.vel[0, 0], initial.vel[0, 1],
            initial.angvel[0], np.zeros(maxv), np.zeros(maxv, dtype=np.int8),
            pos[r], ang[r], angvel[r], vpoint, ncont, slip, states,
        )
        status[r], t_stop[r], n_filled[r], overturn_t[r] = st, ts, nf, ot
        # the summary's metrics from this run's samples (theta = angle - rest angle)
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
    return RunsOutput(status, t_stop, n_filled, overturn_t, pos, ang, angvel, peak, peak_t, residual, uplift)
