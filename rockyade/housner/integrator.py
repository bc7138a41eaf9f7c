"""Exact solution of Housner's rocking equation (paper Eq 1, nonlinear).

For theta > 0 the block pivots on its left base corner, for theta < 0 on its right one:

    theta'' = (p_L^2 / g) [ -(g + a_v) sin(alpha_L - theta) + a_h cos(alpha_L - theta) ]
    theta'' = (p_R^2 / g) [ +(g + a_v) sin(alpha_R + theta) + a_h cos(alpha_R + theta) ]

with a_h the horizontal base acceleration (> 0 towards +x makes theta'' > 0: the paper's
Eq 1 with a(t) the base acceleration) and a_v the vertical one (> 0 upwards; 0 in the
paper). Phases:

* rest: the block stays at theta = 0 until a_h exceeds the uplift threshold
  (g + a_v) tan(alpha); the crossing is found exactly on the piecewise-linear base
  acceleration;
* rocking: classical 4th-order Runge-Kutta steps no longer than 1 / (``STEPS_PER_RADIAN``
  p) and aligned with the base-motion samples (the forcing is smooth within a step);
  impacts theta = 0 are located by root finding (Brent-type bracketing on the Runge-Kutta
  sub-step theta(tau), to machine precision), and omega is multiplied by mu (the pivot
  changes);
* return to rest: after an impact that leaves the block too little energy to lift it by
  more than ``REST_FRACTION`` * alpha (the impacts would otherwise accumulate
  geometrically);
* overturning: |theta| reaching pi/2 (the block lies on its side), located by root
  finding. The last time |theta| crossed alpha outwards (beyond which, without base motion,
  there is no way back) is reported beside it.

Output samples are computed by exact Runge-Kutta sub-steps to each sample time, not by
interpolation. The kernel is compiled by numba.

Point loads (a scene's ``[[loads]]``; Eq 1 modified). A dead load F = (F_x, F_y) without mass
at a material point of the block, at r_0 = (r_x, r_y) from the active pivot at rest, acts at
r(theta) = R(theta) r_0 (R the rotation by theta, counter-clockwise). Its moment about the
pivot is

    M_F = r(theta) x F = cos(theta) (r_0 x F) - sin(theta) (r_0 . F) = A cos(theta) - B sin(theta),

A = r_x F_y - r_y F_x and B = r_x F_x + r_y F_y (summed over the loads, each side with its own
pivot). The load is a weight carried by the block: it follows the apparent gravity (scaled by
(g + a_v) / g) and the horizontal base acceleration does not act on it (no mass). The
block's inertia I_O is unchanged, so I_O theta'' = M_weight + M_inertia + s M_F with
s = (g + a_v) / g; dividing by I_O = M g R / p^2 (Eq 3, which is also how an overridden p
acts):

    theta'' = (p_L^2 / g) [ -(g + a_v) sin(alpha_L - theta) + a_h cos(alpha_L - theta)
                            + s (a_L cos(theta) - b_L sin(theta)) ]           (left pivot)
    theta'' = (p_R^2 / g) [ +(g + a_v) sin(alpha_R + theta) + a_h cos(alpha_R + theta)
                            + s (a_R cos(theta) - b_R sin(theta)) ]           (right pivot)

with a = A / (M R) and b = B / (M R) (m/s^2, R the pivot-to-centroid distance of that side).
At theta = 0 the block lifts about its left pivot when a_h > (g + a_v) (tan(alpha_L) -
a_L / (g cos(alpha_L))), about its right one when -a_h > (g + a_v) (tan(alpha_R) + a_R /
(g cos(alpha_R))): for a vertical load N at horizontal distance d inside the pivot
(A = -N d on the left, so -a_L / (g cos(alpha_L)) = N d / (W h_c)) the multiplier is
lambda = (W b + N d) / (W h_c), the statics of the block (W its weight, b and h_c the
centroid's distances from the pivot). Between impacts the energy in units of M g R is
omega^2 / (2 p^2) + cos(alpha - |theta|) - cos(alpha) - (a / g) sin(theta) + (b / g)
(1 - cos(theta)); the return to rest compares the energy after an impact with that
potential at REST_FRACTION alpha.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numba
import numpy as np

from rockyade.housner.equation import (
    I_AL,
    I_AR,
    I_G,
    I_LAL,
    I_LAR,
    I_LBL,
    I_LBR,
    I_LOADED,
    I_MULR,
    I_MURL,
    I_PL,
    I_PR,
    theta_dd,
)
from rockyade.housner.sdof import HousnerModel
from rockyade.motion.ground import GroundMotion, aligned_step, ground_acceleration

#: A block is declared at rest when an impact leaves it an energy that would lift it by
#: less than REST_FRACTION * alpha.
REST_FRACTION = 1e-6
#: Runge-Kutta steps per radian of p t: the step is at most 1 / (STEPS_PER_RADIAN * p).
STEPS_PER_RADIAN = 400.0
#: At most this many impacts, peaks and uplifts are kept (all are counted).
MAX_RECORDED_EVENTS = 4000

_STATUS_NAMES = ("completed", "overturned")

# ------------------------------------------------------------------ numba kernel


@numba.njit(cache=True)
def _rk4(t, th, om, h, side, prm, mt, mah, mav):
    """One classical Runge-Kutta step of size h; returns (theta, omega)."""
    ah, av, j = ground_acceleration(t, mt, mah, mav, 0)
    k1t = om
    k1w = theta_dd(side, th, ah, av, prm)
    ah, av, j = ground_acceleration(t + 0.5 * h, mt, mah, mav, j)
    k2t = om + 0.5 * h * k1w
    k2w = theta_dd(side, th + 0.5 * h * k1t, ah, av, prm)
    k3t = om + 0.5 * h * k2w
    k3w = theta_dd(side, th + 0.5 * h * k2t, ah, av, prm)
    ah, av, _ = ground_acceleration(t + h, mt, mah, mav, j)
    k4t = om + h * k3w
    k4w = theta_dd(side, th + h * k3t, ah, av, prm)
    return (
        th + h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t),
        om + h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w),
    )


@numba.njit(cache=True)
def _event_value(kind, th, om, side, level):
    """Event functions. 0: side*theta (impact when it falls to 0); 1: side*theta - level
    (overturn when it rises to 0); 2: omega (peak when it changes sign)."""
    if kind == 0:
        return side * th
    if kind == 1:
        return side * th - level
    return om


@numba.njit(cache=True)
def _before(kind, f, f0):
    """True while the event has not happened: f > 0 (impact), f < 0 (overturn), or f
    keeps the sign of the starting value f0 (peak)."""
    if kind == 0:
        return f > 0.0
    if kind == 1:
        return f < 0.0
    return f * f0 > 0.0


@numba.njit(cache=True)
def _bisect(kind, t, th, om, side, level, a, b, f0, prm, mt, mah, mav):
    """Refine a bracket [a, b] (event not yet at a, happened at b) to machine precision
    on the Runge-Kutta sub-step."""
    for _ in range(200):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        th1, om1 = _rk4(t, th, om, m, side, prm, mt, mah, mav)
        if _before(kind, _event_value(kind, th1, om1, side, level), f0):
            a = m
        else:
            b = m
    return b


@numba.njit(cache=True)
def _first_root(kind, t, th, om, h, side, level, prm, mt, mah, mav):
    """Smallest tau in (0, h] at which the event happens, or -1.

    The step is scanned at 16 sub-points for the first change, then refined by bisection.
    A block that starts on theta = 0 (just after an impact) and turns back within the
    first sub-interval re-impacts after its turning point: the bracket starts there.
    """
    f0 = _event_value(kind, th, om, side, level)
    n_scan = 16
    a = 0.0
    for j in range(1, n_scan + 1):
        tau = h * j / n_scan
        th1, om1 = _rk4(t, th, om, tau, side, prm, mt, mah, mav)
        if _before(kind, _event_value(kind, th1, om1, side, level), f0):
            a = tau
            continue
        if a == 0.0 and not _before(kind, f0, f0):
            if kind != 0 or om == 0.0:
                return tau if kind == 0 else -1.0
            # turning point (omega = 0) inside (0, tau), then the fall back to theta = 0
            tp = _bisect(np.int64(2), t, th, om, side, level, 0.0, tau, om, prm, mt, mah, mav)
            thp, omp = _rk4(t, th, om, tp, side, prm, mt, mah, mav)
            if not _before(kind, _event_value(kind, thp, omp, side, level), f0):
                return tp
            a = tp
        return _bisect(kind, t, th, om, side, level, a, tau, f0, prm, mt, mah, mav)
    return -1.0


@numba.njit(cache=True)
def _uplift(t0, t_end, mt, mah, mav, prm):
    """First t in [t0, t_end) where the base lifts the block, and the side (0: none)."""
    n = mt.size
    if n < 2 or t0 >= mt[n - 1]:
        return -1.0, 0
    g = prm[I_G]
    # uplift multipliers (module docstring): tan(alpha) without loads
    tan_l = math.tan(prm[I_AL]) - prm[I_LAL] / (g * math.cos(prm[I_AL]))
    tan_r = math.tan(prm[I_AR]) + prm[I_LAR] / (g * math.cos(prm[I_AR]))
    ah, av, _ = ground_acceleration(t0, mt, mah, mav, 0)
    fp = ah - (g + av) * tan_l
    fm = -ah - (g + av) * tan_r
    if fp > 0.0:
        return t0, 1
    if fm > 0.0:
        return t0, -1
    i = np.searchsorted(mt, t0, side="right")
    ta = t0
    while i < n and ta < t_end:
        tb = mt[i]
        ah_b = mah[i]
        av_b = mav[i]
        fpb = ah_b - (g + av_b) * tan_l
        fmb = -ah_b - (g + av_b) * tan_r
        if fpb > 0.0 or fmb > 0.0:
            best = math.inf
            side = 0
            if fpb > 0.0:
                tc = ta + (tb - ta) * (-fp) / (fpb - fp)
                best, side = tc, 1
            if fmb > 0.0:
                tc = ta + (tb - ta) * (-fm) / (fmb - fm)
                if tc < best:
                    best, side = tc, -1
            best = min(np.nextafter(best, math.inf), tb)
            if best >= t_end:
                return -1.0, 0
            return best, side
        ta, fp, fm = tb, fpb, fmb
        i += 1
    return -1.0, 0


@numba.njit(cache=True)
def _integrate(prm, mt, mah, mav, duration, theta0, omega0, dt_sample, n_samples, h_max, rest_lift, max_events):
    theta_s = np.zeros(n_samples)
    omega_s = np.zeros(n_samples)
    acc_s = np.zeros(n_samples)
    impacts = np.zeros((max_events, 3))
    peaks = np.zeros((max_events, 2))
    uplifts = np.zeros(max_events)
    counts = np.zeros(3, dtype=np.int64)  # impacts, peaks, uplifts
    # the event kinds of _event_value, as int64 rather than literal constants: numba would
    # otherwise compile _first_root, _bisect and their callees once per kind (three copies)
    impact, overturn, peak = np.int64(0), np.int64(1), np.int64(2)
    status = 0
    t_over = -1.0
    t_alpha = -1.0
    alpha_min = min(prm[I_AL], prm[I_AR])
    t = 0.0
    th = theta0
    om = omega0
    k = 0  # next sample index
    eps = 1e-9 * dt_sample
    side = 1
    resting = th == 0.0 and om == 0.0
    if not resting:
        theta_s[0] = th
        omega_s[0] = om
        side0 = 1 if (th > 0.0 or (th == 0.0 and om > 0.0)) else -1
        ah, av, _ = ground_acceleration(0.0, mt, mah, mav, 0)
        acc_s[0] = theta_dd(side0, th, ah, av, prm)
        k = 1
    while t < duration:
        if resting:
            tu, side_up = _uplift(t, duration, mt, mah, mav, prm)
            t_next = duration if tu < 0.0 else tu
            while k < n_samples and k * dt_sample <= t_next + eps:
                k += 1  # samples at rest stay zero
            if tu < 0.0:
                break
            if counts[2] < max_events:
                uplifts[counts[2]] = tu
            counts[2] += 1
            t = tu
            th = 0.0
            om = 0.0
            resting = False
            side = side_up
        elif th != 0.0 or om != 0.0:
            side = 1 if (th > 0.0 or (th == 0.0 and om > 0.0)) else -1
        alpha_side = prm[I_AL] if side > 0 else prm[I_AR]
        h = aligned_step(t, h_max, duration, mt)  # no longer than h_max, ending on a motion sample
        if h <= 0.0:
            break
        th1, om1 = _rk4(t, th, om, h, side, prm, mt, mah, mav)
        # events inside the step: impact, overturn (terminal), peak (recorded)
        tau_end = h
        event = 0  # 0 none, 1 impact, 2 overturn
        if side * th1 >= 0.5 * math.pi:
            tau = _first_root(overturn, t, th, om, h, side, 0.5 * math.pi, prm, mt, mah, mav)
            if tau >= 0.0:
                tau_end = tau
                event = 2
        if side * th1 <= 0.0:
            tau = _first_root(impact, t, th, om, h, side, 0.0, prm, mt, mah, mav)
            if tau >= 0.0 and tau <= tau_end:
                tau_end = tau
                event = 1
        if om * om1 < 0.0 or (event != 0 and om != 0.0):
            tau = _first_root(peak, t, th, om, tau_end, side, 0.0, prm, mt, mah, mav)
            if tau > 0.0 and tau < tau_end:
                thp, _omp = _rk4(t, th, om, tau, side, prm, mt, mah, mav)
                if counts[1] < max_events:
                    peaks[counts[1], 0] = t + tau
                    peaks[counts[1], 1] = thp
                counts[1] += 1
        if side * th < alpha_side <= side * th1:
            t_alpha = t + h * (alpha_side - side * th) / (side * (th1 - th))
        # samples inside (t, t + tau_end]
        t_end = t + tau_end
        while k < n_samples and k * dt_sample <= t_end + eps:
            tk = k * dt_sample
            if tk <= t:
                thk, omk = th, om
            else:
                thk, omk = _rk4(t, th, om, tk - t, side, prm, mt, mah, mav)
            theta_s[k] = thk
            omega_s[k] = omk
            ah, av, _ = ground_acceleration(tk, mt, mah, mav, 0)
            acc_s[k] = theta_dd(side, thk, ah, av, prm)
            k += 1
        if event == 0:
            t, th, om = t + h, th1, om1
            continue
        _th_e, om_e = _rk4(t, th, om, tau_end, side, prm, mt, mah, mav)
        t = t_end
        if event == 2:
            status = 1
            t_over = t
            break
        mu = prm[I_MULR] if side > 0 else prm[I_MURL]
        om_after = mu * om_e
        if counts[0] < max_events:
            impacts[counts[0], 0] = t
            impacts[counts[0], 1] = om_e
            impacts[counts[0], 2] = om_after
        counts[0] += 1
        th = 0.0
        om = om_after
        new_side = -side
        p_new = prm[I_PL] if new_side > 0 else prm[I_PR]
        a_new = prm[I_AL] if new_side > 0 else prm[I_AR]
        lift = 0.5 * om_after * om_after / (p_new * p_new)
        eps_rest = rest_lift * alpha_min
        barrier = math.cos(a_new - eps_rest) - math.cos(a_new)
        if prm[I_LOADED] != 0.0:
            la = prm[I_LAL] if new_side > 0 else prm[I_LAR]
            lb = prm[I_LBL] if new_side > 0 else prm[I_LBR]
            barrier += (-new_side * la * math.sin(eps_rest) + lb * (1.0 - math.cos(eps_rest))) / prm[I_G]
        if lift < barrier:
            om = 0.0
            resting = True
    return theta_s, omega_s, acc_s, impacts, peaks, uplifts, counts, status, t_over, t_alpha, k


#: The compiled functions of a run (numba's cache holds them once a run compiled them:
#: :meth:`rockyade.solvers.housner.HousnerSolver.compiled_cached`).
KERNELS = (_integrate,)

# ------------------------------------------------------------------ Python API


@dataclass
class Trajectory:
    """What the solver found.

    Attributes
    ----------
    t_s, theta_rad, omega_rad_s, theta_dd_rad_s2
        Samples (for an overturned run, up to the overturn time).
    impacts
        (n, 3): time, omega before, omega after.
    peaks
        (n, 2): time, theta where omega = 0 during rocking.
    uplift_times_s
        Times the block left rest.
    n_impacts
        All impacts (``impacts`` keeps the first MAX_RECORDED_EVENTS).
    status
        "completed" or "overturned".
    overturn_time_s, alpha_exceeded_time_s
        When |theta| reached pi/2, and last crossed alpha outwards.
    step_s
        Largest Runge-Kutta step used, s.
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    omega_rad_s: np.ndarray
    theta_dd_rad_s2: np.ndarray
    impacts: np.ndarray
    peaks: np.ndarray
    uplift_times_s: np.ndarray
    n_impacts: int
    status: str
    overturn_time_s: float | None
    alpha_exceeded_time_s: float | None
    step_s: float


def solve(
    model: HousnerModel,
    motion: GroundMotion | None,
    duration_s: float,
    theta0: float = 0.0,
    omega0: float = 0.0,
    sample_dt_s: float = 0.001,
    step_s: float | None = None,
) -> Trajectory:
    """Integrate the rocking equation from t = 0 to ``duration_s``.

    Parameters
    ----------
    model
        Classical parameters of both pivots.
    motion
        Base acceleration (None: the base is at rest).
    duration_s
        End time, s.
    theta0, omega0
        Initial tilt (rad) and angular velocity (rad/s).
    sample_dt_s
        Output sampling interval, s.
    step_s
        Largest Runge-Kutta step, s (default 1 / (400 p)).
    """
    prm = model.params()
    if step_s is None:
        step_s = 1.0 / (STEPS_PER_RADIAN * max(model.p_left, model.p_right))
    if motion is None and model.loaded:
        # a base at rest, given as samples: the uplift test then sees a load that tips the block
        mt = np.array([0.0, float(duration_s)])
        mah = np.zeros(2)
        mav = np.zeros(2)
    elif motion is None:
        mt = np.zeros(0)
        mah = np.zeros(0)
        mav = np.zeros(0)
    else:
        mt, mah, mav = motion.t_s, motion.ah_m_s2, motion.av_m_s2
    n_samples = math.floor(duration_s / sample_dt_s + 1e-9) + 1
    out = _integrate(
        prm,
        mt,
        mah,
        mav,
        float(duration_s),
        float(theta0),
        float(omega0),
        float(sample_dt_s),
        n_samples,
        float(step_s),
        REST_FRACTION,
        MAX_RECORDED_EVENTS,
    )
    theta, omega, acc, impacts, peaks, uplifts, counts, status, t_over, t_alpha, n_filled = out
    n_imp, n_peak, n_up = (int(c) for c in counts)
    n_keep = int(n_filled) if status == 1 else n_samples
    overturned = status == 1
    return Trajectory(
        t_s=np.arange(n_keep) * sample_dt_s,
        theta_rad=theta[:n_keep],
        omega_rad_s=omega[:n_keep],
        theta_dd_rad_s2=acc[:n_keep],
        impacts=impacts[: min(n_imp, MAX_RECORDED_EVENTS)],
        peaks=peaks[: min(n_peak, MAX_RECORDED_EVENTS)],
        uplift_times_s=uplifts[: min(n_up, MAX_RECORDED_EVENTS)],
        n_impacts=n_imp,
        status=_STATUS_NAMES[status],
        overturn_time_s=float(t_over) if overturned else None,
        alpha_exceeded_time_s=float(t_alpha) if overturned and t_alpha >= 0 else None,
        step_s=float(step_s),
    )


@functools.cache
def warm_up() -> None:
    """Load the compiled kernel once per process, so that wall times measure the solve."""
    solve(HousnerModel.symmetric(0.2, 3.0, 0.9), GroundMotion(np.array([0.0, 0.1]), np.zeros(2)), 0.01, 0.01)
