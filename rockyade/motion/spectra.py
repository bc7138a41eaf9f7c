"""Response spectra by the exact piecewise-linear recurrence (Nigam & Jennings, 1969).

For an SDOF oscillator u'' + 2 xi w u' + w^2 u = -a(t) with a(t) linear between samples,
the state x = (u, u') advances exactly over a step h as

    x_{i+1} = Phi x_i + Gamma0 a_i + Gamma1 (a_{i+1} - a_i),

Phi = exp(M h), Gamma0 = integral_0^h exp(M s) ds b and Gamma1 = integral_0^h
exp(M (h - s)) s / h ds b (M = [[0, 1], [-w^2, -2 xi w]], b = (0, -1)). The three are
taken from one matrix exponential of an augmented 4x4 matrix (Van Loan), so there are no
hand-expanded coefficients to get wrong. Periods shorter than 10 dt are sub-stepped (the
input interpolated linearly, still exact) so that a step holds at most one extremum of u.

The peak is exact, not the largest sample: where the velocity changes sign inside a step,
the extremum of the exact solution in that step is located. Within a step the solution
is the particular part of the linear load plus a damped free vibration (Chopra, *Dynamics
of Structures*, Section 5.2):

    u(s) = c0 + c1 s + exp(-xi w s) (A cos(w_d s) + B sin(w_d s)),
    c1 = -k / w^2, c0 = -(a_i + 2 xi w c1) / w^2, k = (a_{i+1} - a_i) / h,
    A = u_i - c0, B = (v_i - c1 + xi w A) / w_d, w_d = w sqrt(1 - xi^2),

and the zero of u'(s) is found by safeguarded Newton steps on this closed form. The
recurrence over time runs in numba for all periods of one call.

The pseudo-spectral acceleration is PSA = w^2 max |u|.
"""

from __future__ import annotations

import functools
import math

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError

#: Sub-step when the period is shorter than this many samples.
MIN_STEPS_PER_PERIOD = 10

#: Newton iterations (bisection-safeguarded) locating an extremum inside a step.
PEAK_ITERATIONS = 30


def default_periods(t_min: float = 0.02, t_max: float = 4.0, n: int = 100) -> NDArray[np.float64]:
    """Log-spaced periods, s."""
    return np.geomspace(t_min, t_max, n)


@functools.lru_cache(maxsize=4096)
def _recurrence(omega: float, damping: float, h: float) -> NDArray[np.float64]:
    """(Phi, Gamma0, Gamma1) flattened: 4 + 2 + 2 numbers (read-only; kept for the next record
    of the same sampling: a folder's records share their periods and step)."""
    from scipy.linalg import expm

    m = np.zeros((4, 4))
    m[0, 1] = 1.0
    m[1, 0] = -omega * omega
    m[1, 1] = -2.0 * damping * omega
    m[1, 2] = -1.0  # b = (0, -1): the ground acceleration drives -a
    m[2, 3] = 1.0 / h  # a(s) = a_i + (a_{i+1} - a_i) s / h
    e = expm(m * h)
    phi = e[:2, :2]
    gamma0 = e[:2, 2]
    gamma1 = e[:2, 3]
    out = np.concatenate([phi.ravel(), gamma0, gamma1])
    out.setflags(write=False)
    return out


@numba.njit(cache=True)
def _state_in_step(s, c0, c1, amp_a, amp_b, omega, damping, omega_d):
    """(u, v) at time s into a step, from the closed form of the module docstring."""
    decay = math.exp(-damping * omega * s)
    cos_s = math.cos(omega_d * s)
    sin_s = math.sin(omega_d * s)
    free = decay * (amp_a * cos_s + amp_b * sin_s)
    rate_cos = amp_b * omega_d - damping * omega * amp_a
    rate_sin = amp_a * omega_d + damping * omega * amp_b
    free_rate = decay * (rate_cos * cos_s - rate_sin * sin_s)
    return c0 + c1 * s + free, c1 + free_rate


@numba.njit(cache=True)
def _extremum_in_step(u0, v0, v1, a0, slope, h, omega, damping):
    """|u| at the zero of the velocity inside a step where v changes sign (v0 v1 < 0)."""
    omega_d = omega * math.sqrt(1.0 - damping * damping)
    c1 = -slope / (omega * omega)
    c0 = -(a0 + 2.0 * damping * omega * c1) / (omega * omega)
    amp_a = u0 - c0
    amp_b = (v0 - c1 + damping * omega * amp_a) / omega_d
    lo, hi = 0.0, h
    v_lo = v0
    s = h * v0 / (v0 - v1)  # secant start
    for _ in range(PEAK_ITERATIONS):
        u, v = _state_in_step(s, c0, c1, amp_a, amp_b, omega, damping, omega_d)
        if v == 0.0:
            break
        if (v > 0.0) == (v_lo > 0.0):
            lo, v_lo = s, v
        else:
            hi = s
        accel = -(a0 + slope * s) - 2.0 * damping * omega * v - omega * omega * u  # u''(s)
        s_new = s - v / accel if accel != 0.0 else 0.5 * (lo + hi)
        if not lo < s_new < hi:
            s_new = 0.5 * (lo + hi)
        if abs(s_new - s) <= 1e-14 * h:
            s = s_new
            break
        s = s_new
    u, _v = _state_in_step(s, c0, c1, amp_a, amp_b, omega, damping, omega_d)
    return abs(u)


@numba.njit(cache=True)
def _peak_response(accel, coeffs, substeps, omegas, damping, dt):
    n_per = coeffs.shape[0]
    out = np.zeros(n_per)
    n = accel.size
    for j in range(n_per):
        c = coeffs[j]
        m = substeps[j]
        h = dt / m
        omega = omegas[j]
        u = 0.0
        v = 0.0
        peak = 0.0
        for i in range(n - 1):
            a0 = accel[i]
            da = (accel[i + 1] - a0) / m
            for k in range(m):
                aa = a0 + k * da
                u_new = c[0] * u + c[1] * v + c[4] * aa + c[6] * da
                v_new = c[2] * u + c[3] * v + c[5] * aa + c[7] * da
                if v * v_new < 0.0 and max(abs(u), abs(u_new)) > 0.5 * peak:
                    inside = _extremum_in_step(u, v, v_new, aa, da / h, h, omega, damping)
                    if inside > peak:
                        peak = inside
                u = u_new
                v = v_new
                if abs(u) > peak:
                    peak = abs(u)
        out[j] = peak
    return out


def response_spectrum(
    accel_m_s2: NDArray[np.float64], dt_s: float, periods_s: NDArray[np.float64] | None = None, damping: float = 0.05
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Pseudo-acceleration response spectrum of a uniformly sampled record.

    The peak of each oscillator is that of the exact response to the piecewise-linear
    input, between samples included (see the module docstring).

    Parameters
    ----------
    accel_m_s2
        Ground acceleration samples, m/s^2.
    dt_s
        Sampling interval, s.
    periods_s
        Periods, s (default: 100 log-spaced from 0.02 to 4 s).
    damping
        Damping ratio (0.05 = 5 %), in [0, 1).

    Returns
    -------
    periods_s, psa_m_s2
    """
    if not 0.0 <= damping < 1.0:
        raise InputError("damping", f"must be in [0, 1), got {damping!r}")
    if not dt_s > 0:
        raise InputError("dt_s", f"must be > 0, got {dt_s!r}")
    periods = default_periods() if periods_s is None else np.asarray(periods_s, dtype=float)
    if np.any(periods <= 0) or not np.all(np.isfinite(periods)):
        raise InputError("periods_s", "must be finite and > 0")
    accel = np.ascontiguousarray(accel_m_s2, dtype=float)
    # pad with the free vibration after the record (two periods of the longest oscillator)
    pad = int(np.ceil(2.0 * periods.max() / dt_s))
    accel = np.concatenate([accel, np.zeros(pad)])
    substeps = np.maximum(1, np.ceil(MIN_STEPS_PER_PERIOD * dt_s / periods)).astype(np.int64)
    omega = 2 * np.pi / periods
    coeffs = np.array(
        [_recurrence(float(w), float(damping), float(dt_s / m)) for w, m in zip(omega, substeps, strict=True)]
    )
    peaks = _peak_response(accel, coeffs, substeps, omega, float(damping), float(dt_s))
    return periods, omega * omega * peaks
