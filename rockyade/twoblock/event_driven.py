"""Event-driven integration of the two-block stack, compiled by numba.

Between events the mode's equations (:mod:`rockyade.twoblock.dynamics`) are integrated by
classical 4th-order Runge-Kutta steps no longer than ``h_max`` and aligned with the base
motion's samples, as Housner's integrator (:mod:`rockyade.housner.integrator`) does for one
block. Events are located inside a step by scanning 16 sub-points and bisecting on the
Runge-Kutta sub-step to machine precision:

* an impact: a joint's relative angle (theta_1 on the base, phi on the seat) returns to 0;
  its outcome comes from :func:`rockyade.twoblock.dynamics.impact`;
* an uplift: a closed joint's contact force leaves its contact (a moment margin turns
  negative), and the stack takes the mode :func:`rockyade.twoblock.dynamics.choose_mode`
  finds; at rest the margins are affine in the base acceleration, so the first uplift is
  found exactly on its piecewise-linear samples;
* a flight: an open pivot's normal force turns negative (outside pure rocking: the run fails);
* an overturn: |theta_1|, |theta_2| or |phi| reaches pi/2;
* a peak of either block (recorded only).

After an impact a joint whose relative motion is left with too little energy to lift it by
``REST_FRACTION`` of its alpha is closed (the impacts would otherwise accumulate
geometrically), as Housner's integrator returns a block to rest. Output samples are exact
Runge-Kutta sub-steps from the step's start, so the sampling interval never moves an event.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from rockyade.motion.ground import aligned_step, ground_acceleration
from rockyade.twoblock.dynamics import (
    ADMISSIBLE_TOL,
    ALPHA_BASE,
    ALPHA_SEAT,
    MOMENT_SCALE,
    MU_BASE,
    MU_SEAT,
    P2_BASE,
    P2_SEAT,
    WEIGHT,
    accelerations,
    at_rest_margins,
    choose_mode,
    contact_state,
    held,
    impact,
    post_impact,
)

#: A joint is closed after an impact that leaves it too little energy to lift by REST_FRACTION x alpha.
REST_FRACTION = 1e-6
#: Runge-Kutta steps per radian of p t: the step is at most 1 / (STEPS_PER_RADIAN p).
STEPS_PER_RADIAN = 400.0
#: At most this many impacts, peaks, uplifts and mode changes are kept (all are counted).
MAX_RECORDED_EVENTS = 4000
#: Events at one instant beyond this stop the run as failed (no mode can be found).
MAX_EVENTS_AT_ONE_TIME = 200

# event kinds
_IMPACT_BASE, _IMPACT_SEAT, _OVER_LOWER, _OVER_UPPER = 0, 1, 2, 3
_BASE_L, _BASE_R, _SEAT_L, _SEAT_R, _N_BASE, _N_SEAT = 4, 5, 6, 7, 8, 9
_PEAK_LOWER, _PEAK_UPPER, _TURN_SEAT = 10, 11, 12
_N_KINDS = 13

#: Status codes: 0 completed, 1 overturned, 2 failed. Failure codes (``fail_code``).
FAIL_FLIGHT_BASE, FAIL_FLIGHT_SEAT, FAIL_NO_MODE, FAIL_STUCK = 1, 2, 3, 4


@numba.njit(cache=True)
def _rk4(t, th1, phi, w1, wp, h, sb, ss, prm, mt, mah, mav):
    """One classical Runge-Kutta step of size h in mode (sb, ss); returns the state."""
    ah, av, j = ground_acceleration(t, mt, mah, mav, 0)
    k1a, k1b = accelerations(th1, phi, w1, wp, sb, ss, ah, av, prm)
    ah, av, j = ground_acceleration(t + 0.5 * h, mt, mah, mav, j)
    th1b, phib = th1 + 0.5 * h * w1, phi + 0.5 * h * wp
    w1b, wpb = w1 + 0.5 * h * k1a, wp + 0.5 * h * k1b
    k2a, k2b = accelerations(th1b, phib, w1b, wpb, sb, ss, ah, av, prm)
    th1c, phic = th1 + 0.5 * h * w1b, phi + 0.5 * h * wpb
    w1c, wpc = w1 + 0.5 * h * k2a, wp + 0.5 * h * k2b
    k3a, k3b = accelerations(th1c, phic, w1c, wpc, sb, ss, ah, av, prm)
    ah, av, _ = ground_acceleration(t + h, mt, mah, mav, j)
    th1d, phid = th1 + h * w1c, phi + h * wpc
    w1d, wpd = w1 + h * k3a, wp + h * k3b
    k4a, k4b = accelerations(th1d, phid, w1d, wpd, sb, ss, ah, av, prm)
    return (
        th1 + h / 6.0 * (w1 + 2.0 * w1b + 2.0 * w1c + w1d),
        phi + h / 6.0 * (wp + 2.0 * wpb + 2.0 * wpc + wpd),
        w1 + h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a),
        wp + h / 6.0 * (k1b + 2.0 * k2b + 2.0 * k3b + k4b),
    )


@numba.njit(cache=True)
def _active(kind, sb, ss):
    """Whether event ``kind`` can happen in mode (sb, ss) (rest has its own search)."""
    if kind in (_IMPACT_BASE, _OVER_LOWER, _N_BASE):
        return sb != 0
    if kind in (_IMPACT_SEAT, _N_SEAT):
        return ss != 0
    if kind in (_BASE_L, _BASE_R):
        return sb == 0
    if kind in (_SEAT_L, _SEAT_R):
        return ss == 0
    if kind == _PEAK_LOWER:
        return sb != 0
    if kind == _TURN_SEAT:
        return ss != 0
    return True  # the upper block's overturn and peaks: it moves in every mode but rest


@numba.njit(cache=True)
def _value(kind, t, th1, phi, w1, wp, sb, ss, prm, mt, mah, mav):
    """The event function of ``kind`` (the event happens when it leaves its 'before' side)."""
    if kind == _IMPACT_BASE:
        return sb * th1
    if kind == _IMPACT_SEAT:
        return ss * phi
    if kind == _OVER_LOWER:
        return abs(th1) - 0.5 * math.pi
    if kind == _OVER_UPPER:
        return max(abs(th1 + phi), abs(phi)) - 0.5 * math.pi
    if kind == _PEAK_LOWER:
        return w1
    if kind == _PEAK_UPPER:
        return w1 + wp
    if kind == _TURN_SEAT:
        return wp
    ah, av, _ = ground_acceleration(t, mt, mah, mav, 0)
    loads = contact_state(th1, phi, w1, wp, sb, ss, ah, av, prm)
    if kind == _BASE_L:
        return loads[2] / prm[MOMENT_SCALE]
    if kind == _BASE_R:
        return loads[3] / prm[MOMENT_SCALE]
    if kind == _SEAT_L:
        return loads[6] / prm[MOMENT_SCALE]
    if kind == _SEAT_R:
        return loads[7] / prm[MOMENT_SCALE]
    hb, hs = held(th1, phi, prm)
    if kind == _N_BASE:
        return 1.0 if hb else loads[0] / prm[WEIGHT]
    return 1.0 if hs else loads[4] / prm[WEIGHT]


@numba.njit(cache=True)
def _all_values(t, th1, phi, w1, wp, sb, ss, prm, mt, mah, mav, out):
    """Every event function of :func:`_value` at one state, into ``out`` (one evaluation of the
    contact forces for all); returns those forces (:func:`rockyade.twoblock.dynamics.joint_loads`)."""
    ah, av, _ = ground_acceleration(t, mt, mah, mav, 0)
    loads = contact_state(th1, phi, w1, wp, sb, ss, ah, av, prm)
    hb, hs = held(th1, phi, prm)
    out[_IMPACT_BASE] = sb * th1
    out[_IMPACT_SEAT] = ss * phi
    out[_OVER_LOWER] = abs(th1) - 0.5 * math.pi
    out[_OVER_UPPER] = max(abs(th1 + phi), abs(phi)) - 0.5 * math.pi
    out[_BASE_L] = loads[2] / prm[MOMENT_SCALE]
    out[_BASE_R] = loads[3] / prm[MOMENT_SCALE]
    out[_SEAT_L] = loads[6] / prm[MOMENT_SCALE]
    out[_SEAT_R] = loads[7] / prm[MOMENT_SCALE]
    out[_N_BASE] = 1.0 if hb else loads[0] / prm[WEIGHT]
    out[_N_SEAT] = 1.0 if hs else loads[4] / prm[WEIGHT]
    out[_PEAK_LOWER] = w1
    out[_PEAK_UPPER] = w1 + wp
    out[_TURN_SEAT] = wp
    return loads


@numba.njit(cache=True)
def _before(kind, f, f0):
    """True while the event has not happened: an angle above 0 (impact), below pi/2
    (overturn), a margin or normal force not below -ADMISSIBLE_TOL, or a velocity keeping
    the sign of its start value f0 (peak, turning point)."""
    if kind <= _IMPACT_SEAT:
        return f > 0.0
    if kind <= _OVER_UPPER:
        return f < 0.0
    if kind <= _N_SEAT:
        return f >= -ADMISSIBLE_TOL
    return f * f0 > 0.0


@numba.njit(cache=True)
def _bisect(kind, t, th1, phi, w1, wp, sb, ss, a, b, f0, prm, mt, mah, mav):
    """Refine a bracket [a, b] (event not yet at a, happened at b) to machine precision."""
    for _ in range(200):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        s = _rk4(t, th1, phi, w1, wp, m, sb, ss, prm, mt, mah, mav)
        if _before(kind, _value(kind, t + m, s[0], s[1], s[2], s[3], sb, ss, prm, mt, mah, mav), f0):
            a = m
        else:
            b = m
    return b


@numba.njit(cache=True)
def _first_root(kind, t, th1, phi, w1, wp, h, sb, ss, prm, mt, mah, mav):
    """Smallest tau in (0, h] at which event ``kind`` happens, or -1.

    The step is scanned at 16 sub-points, then the first bracket is bisected. A joint that
    starts on its zero angle (just after an impact or an uplift) and turns back within the
    first sub-interval re-impacts after its turning point: the bracket starts there.
    """
    f0 = _value(kind, t, th1, phi, w1, wp, sb, ss, prm, mt, mah, mav)
    n_scan = 16
    a = 0.0
    for j in range(1, n_scan + 1):
        tau = h * j / n_scan
        s = _rk4(t, th1, phi, w1, wp, tau, sb, ss, prm, mt, mah, mav)
        if _before(kind, _value(kind, t + tau, s[0], s[1], s[2], s[3], sb, ss, prm, mt, mah, mav), f0):
            a = tau
            continue
        if a == 0.0 and not _before(kind, f0, f0):
            if kind > _IMPACT_SEAT:
                return -1.0
            turn = _PEAK_LOWER if kind == _IMPACT_BASE else _TURN_SEAT
            v0 = _value(turn, t, th1, phi, w1, wp, sb, ss, prm, mt, mah, mav)
            if v0 == 0.0:
                return tau
            tp = _bisect(turn, t, th1, phi, w1, wp, sb, ss, 0.0, tau, v0, prm, mt, mah, mav)
            s = _rk4(t, th1, phi, w1, wp, tp, sb, ss, prm, mt, mah, mav)
            if not _before(kind, _value(kind, t + tp, s[0], s[1], s[2], s[3], sb, ss, prm, mt, mah, mav), f0):
                return tp
            a = tp
        return _bisect(kind, t, th1, phi, w1, wp, sb, ss, a, tau, f0, prm, mt, mah, mav)
    return -1.0


@numba.njit(cache=True)
def _uplift(t0, t_end, mt, mah, mav, prm):
    """First t in [t0, t_end) at which a margin of the stack at rest is violated (-1: none).

    The margins are affine in the base acceleration, which is linear between its samples:
    the first sample at which one is violated brackets the crossing, refined by bisection to
    the first representable time at which :func:`rockyade.twoblock.dynamics.at_rest_margins`
    finds it violated (the mode chosen there then sees the same numbers)."""
    n = mt.size
    if n < 2 or t0 >= mt[n - 1]:
        return -1.0
    thr = -ADMISSIBLE_TOL * prm[MOMENT_SCALE]
    ah, av, _ = ground_acceleration(t0, mt, mah, mav, 0)
    fa = at_rest_margins(ah, av, prm)
    if min(fa[0], fa[1], fa[2], fa[3]) < thr:
        return t0
    i = np.searchsorted(mt, t0, side="right")
    ta = t0
    while i < n and ta < t_end:
        tb = mt[i]
        fb = at_rest_margins(mah[i], mav[i], prm)
        if min(fb[0], fb[1], fb[2], fb[3]) < thr:
            a, b = ta, tb
            for _ in range(200):  # bisection on the margins as computed (affine: one root)
                m = 0.5 * (a + b)
                if m <= a or m >= b:
                    break
                ah, av, _j = ground_acceleration(m, mt, mah, mav, 0)
                fc = at_rest_margins(ah, av, prm)
                if min(fc[0], fc[1], fc[2], fc[3]) < thr:
                    b = m
                else:
                    a = m
            tc = b
            return tc if tc < t_end else -1.0
        ta, fa = tb, fb
        i += 1
    return -1.0


@numba.njit(cache=True)
def _lift_too_small(joint, w_rel, prm, rest_fraction):
    """True when a joint's relative angular velocity cannot lift it by rest_fraction x alpha:
    w^2 / (2 p^2) below cos(alpha - eps) - cos(alpha) (Housner's energy in units of W R)."""
    if joint == 0:
        p2, alpha = prm[P2_BASE], prm[ALPHA_BASE]
    else:
        p2, alpha = prm[P2_SEAT], prm[ALPHA_SEAT]
    eps = rest_fraction * alpha
    return 0.5 * w_rel * w_rel / p2 < math.cos(alpha - eps) - math.cos(alpha)


@numba.njit(cache=True)
def _friction(t, loads, prm, fmax, fexceed, tension):
    """Track |T| / N of each joint in contact (``loads``: :func:`rockyade.twoblock.dynamics.joint_loads`):
    the largest, and when it first exceeded the joint's friction coefficient; and when a pivot
    first pulled (N < 0, held as Housner's pivot is: only where the block falls either way,
    :func:`rockyade.twoblock.dynamics.held`)."""
    for k in range(2):
        n = loads[0] if k == 0 else loads[4]
        tt = loads[1] if k == 0 else loads[5]
        if n <= 0.0:
            if n < -ADMISSIBLE_TOL * prm[WEIGHT] and tension[k] < 0.0:
                tension[k] = t
            continue
        r = abs(tt) / n
        if r > fmax[k]:
            fmax[k] = r
        mu = prm[MU_BASE] if k == 0 else prm[MU_SEAT]
        if r > mu and fexceed[k] < 0.0:
            fexceed[k] = t


@numba.njit(cache=True)
def integrate(prm, mt, mah, mav, duration, th1, phi, w1, wp, sb, ss, dt_sample, n_samples, h_max, rest_fraction, cap):
    """Integrate from t = 0 (state and mode given) to ``duration``; see the module docstring.

    Returns the sampled arrays (theta_1, theta_2, omega_1, omega_2, theta_1'', theta_2'',
    base mode, seat mode), the events (impacts, peaks, uplifts, mode changes), their counts,
    the friction record, the status and failure, and the number of samples filled.
    """
    samples = np.zeros((n_samples, 6))
    modes = np.zeros((n_samples, 2), dtype=np.int8)
    impacts = np.zeros((cap, 8))  # t, joint, w1-, w2-, w1+, w2+, sb+, ss+
    peaks = np.zeros((cap, 3))  # t, block (0 lower, 1 upper), theta
    uplifts = np.zeros(cap)
    changes = np.zeros((cap, 3))  # t, sb, ss
    counts = np.zeros(5, dtype=np.int64)  # impacts, peaks, uplifts, mode changes, inadmissible impacts
    fmax = np.zeros(2)
    fexceed = np.full(2, -1.0)
    tension = np.full(2, -1.0)
    imp_ratio = np.zeros(2)
    # a closed joint (0), the joints' indices and the flags of choose_mode as int64 and bool,
    # not literal constants: numba would otherwise compile choose_mode, post_impact and their
    # callees again for each literal
    closed, base_joint, seat_joint = np.int64(0), np.int64(0), np.int64(1)
    yes, no = np.bool_(True), np.bool_(False)
    status = 0
    fail_code = 0
    t_end_run = -1.0
    over_block = -1
    t = 0.0
    k = 0
    eps = 1e-9 * dt_sample
    resting = sb == 0 and ss == 0
    stuck = 0
    t_last = -1.0
    vals0 = np.zeros(_N_KINDS)
    vals1 = np.zeros(_N_KINDS)
    fresh = False  # vals0 holds the event functions at (t, state)
    if not resting:
        ah, av, _ = ground_acceleration(0.0, mt, mah, mav, 0)
        dd1, ddp = accelerations(th1, phi, w1, wp, sb, ss, ah, av, prm)
        samples[0, 0], samples[0, 1] = th1, th1 + phi
        samples[0, 2], samples[0, 3] = w1, w1 + wp
        samples[0, 4], samples[0, 5] = dd1, dd1 + ddp
        modes[0, 0], modes[0, 1] = sb, ss
        k = 1
    while t < duration:
        if t == t_last:
            stuck += 1
            if stuck > MAX_EVENTS_AT_ONE_TIME:
                status, fail_code, t_end_run = 2, FAIL_STUCK, t
                break
        else:
            stuck = 0
            t_last = t
        if resting:
            tu = _uplift(t, duration, mt, mah, mav, prm)
            t_next = duration if tu < 0.0 else tu
            while k < n_samples and k * dt_sample <= t_next + eps:
                k += 1  # samples at rest stay zero
            if tu < 0.0:
                break
            if counts[2] < cap:
                uplifts[counts[2]] = tu
            counts[2] += 1
            t = tu
            th1, phi, w1, wp = 0.0, 0.0, 0.0, 0.0
            ah, av, _ = ground_acceleration(t, mt, mah, mav, 0)
            sb, ss, viol = choose_mode(0.0, 0.0, 0.0, 0.0, closed, closed, ah, av, prm, yes, yes, no, no)
            if viol > ADMISSIBLE_TOL:
                status, fail_code, t_end_run = 2, FAIL_NO_MODE, t
                break
            if counts[3] < cap:
                changes[counts[3], 0], changes[counts[3], 1], changes[counts[3], 2] = t, sb, ss
            counts[3] += 1
            resting = False
        h = aligned_step(t, h_max, duration, mt)  # no longer than h_max, ending on a motion sample
        if h <= 0.0:
            break
        if not fresh:
            _all_values(t, th1, phi, w1, wp, sb, ss, prm, mt, mah, mav, vals0)
            fresh = True
        s1 = _rk4(t, th1, phi, w1, wp, h, sb, ss, prm, mt, mah, mav)
        loads1 = _all_values(t + h, s1[0], s1[1], s1[2], s1[3], sb, ss, prm, mt, mah, mav, vals1)
        tau_end = h
        event = -1
        for kind in range(_PEAK_LOWER):
            if not _active(kind, sb, ss) or _before(kind, vals1[kind], vals0[kind]):
                continue
            tau = _first_root(kind, t, th1, phi, w1, wp, h, sb, ss, prm, mt, mah, mav)
            if tau >= 0.0 and (tau < tau_end or (tau == tau_end and event < 0)):
                tau_end = tau
                event = kind
        for kind in (_PEAK_LOWER, _PEAK_UPPER):
            if not _active(kind, sb, ss):
                continue
            f0, f1 = vals0[kind], vals1[kind]
            if f0 * f1 < 0.0 or (event >= 0 and f0 != 0.0):
                tau = _first_root(kind, t, th1, phi, w1, wp, tau_end, sb, ss, prm, mt, mah, mav)
                if tau > 0.0 and tau < tau_end:
                    sp = _rk4(t, th1, phi, w1, wp, tau, sb, ss, prm, mt, mah, mav)
                    if counts[1] < cap:
                        peaks[counts[1], 0] = t + tau
                        peaks[counts[1], 1] = 0.0 if kind == _PEAK_LOWER else 1.0
                        peaks[counts[1], 2] = sp[0] if kind == _PEAK_LOWER else sp[0] + sp[1]
                    counts[1] += 1
        # samples inside (t, t + tau_end]
        t_stop = t + tau_end
        while k < n_samples and k * dt_sample <= t_stop + eps:
            tk = k * dt_sample
            sk = (th1, phi, w1, wp) if tk <= t else _rk4(t, th1, phi, w1, wp, tk - t, sb, ss, prm, mt, mah, mav)
            ah, av, _ = ground_acceleration(tk, mt, mah, mav, 0)
            dd1, ddp = accelerations(sk[0], sk[1], sk[2], sk[3], sb, ss, ah, av, prm)
            samples[k, 0], samples[k, 1] = sk[0], sk[0] + sk[1]
            samples[k, 2], samples[k, 3] = sk[2], sk[2] + sk[3]
            samples[k, 4], samples[k, 5] = dd1, dd1 + ddp
            modes[k, 0], modes[k, 1] = sb, ss
            k += 1
        if event < 0:
            th1, phi, w1, wp = s1
            t = t + h
            _friction(t, loads1, prm, fmax, fexceed, tension)
            vals0, vals1 = vals1, vals0
            continue
        fresh = False
        th1, phi, w1, wp = _rk4(t, th1, phi, w1, wp, tau_end, sb, ss, prm, mt, mah, mav)
        t = t_stop
        if event in (_OVER_LOWER, _OVER_UPPER):
            status, t_end_run = 1, t
            over_block = 0 if event == _OVER_LOWER else 1
            break
        if event in (_N_BASE, _N_SEAT):
            status, t_end_run = 2, t
            fail_code = FAIL_FLIGHT_BASE if event == _N_BASE else FAIL_FLIGHT_SEAT
            break
        ah, av, _ = ground_acceleration(t, mt, mah, mav, 0)
        if event in (_IMPACT_BASE, _IMPACT_SEAT):
            joint = 0 if event == _IMPACT_BASE else 1
            if joint == 0:
                th1 = 0.0
            else:
                phi = 0.0
            w1m, w2m = w1, w1 + wp
            nsb, nss, nw1, nwp, viol, ratio = impact(th1, phi, w1, wp, sb, ss, joint, prm)
            if viol > ADMISSIBLE_TOL:
                counts[4] += 1
            if ratio > imp_ratio[joint]:
                imp_ratio[joint] = ratio
            # a joint left too little to lift closes: the impact's outcome with it closed
            if nsb != 0 and th1 == 0.0 and _lift_too_small(base_joint, nw1, prm, rest_fraction):
                nsb = closed
                nw1, nwp = post_impact(th1, phi, w1, wp, sb, ss, nsb, nss, prm)
            if nss != 0 and phi == 0.0 and _lift_too_small(seat_joint, nwp, prm, rest_fraction):
                nss = closed
                nw1, nwp = post_impact(th1, phi, w1, wp, sb, ss, nsb, nss, prm)
            sb, ss, w1, wp = nsb, nss, nw1, nwp
            if counts[0] < cap:
                row = impacts[counts[0]]
                row[0], row[1], row[2], row[3] = t, joint, w1m, w2m
                row[4], row[5], row[6], row[7] = w1, w1 + wp, sb, ss
            counts[0] += 1
            if sb == 0 and ss == 0:
                resting = True
                th1, phi, w1, wp = 0.0, 0.0, 0.0, 0.0
            else:
                nsb, nss, viol = choose_mode(th1, phi, w1, wp, sb, ss, ah, av, prm, sb == 0, ss == 0, no, no)
                if viol > ADMISSIBLE_TOL:
                    status, fail_code, t_end_run = 2, FAIL_NO_MODE, t
                    break
                sb, ss = nsb, nss
        else:  # a closed joint's margin: it opens
            free_b, free_s = sb == 0, ss == 0
            nsb, nss, viol = choose_mode(
                th1,
                phi,
                w1,
                wp,
                sb,
                ss,
                ah,
                av,
                prm,
                free_b,
                free_s,
                event in (_BASE_L, _BASE_R),
                event in (_SEAT_L, _SEAT_R),
            )
            if viol > ADMISSIBLE_TOL:
                status, fail_code, t_end_run = 2, FAIL_NO_MODE, t
                break
            sb, ss = nsb, nss
        if counts[3] < cap:
            changes[counts[3], 0], changes[counts[3], 1], changes[counts[3], 2] = t, sb, ss
        counts[3] += 1
    return (
        samples,
        modes,
        impacts,
        peaks,
        uplifts,
        changes,
        counts,
        fmax,
        fexceed,
        imp_ratio,
        tension,
        status,
        fail_code,
        t_end_run,
        over_block,
        k,
    )
