"""Response spectra by the exact piecewise-linear recurrence (Nigam & Jennings, 1969).

For an SDOF oscillator u'' + 2 xi w u' + w^2 u = -a(t) with a(t) linear between samples,
the state x = (u, u') advances exactly over a step h as

    x_{i+1} = Phi x_i + Gamma0 a_i + Gamma1 (a_{i+1} - a_i),

Phi = exp(M h), Gamma0 = integral_0^h exp(M s) ds b and Gamma1 = integral_0^h
exp(M (h - s)) s / h ds b (M = [[0, 1], [-w^2, -2 xi w]], b = (0, -1)). The three are
taken from one matrix exponential of an augmented 4x4 matrix (Van Loan), so there are no
hand-expanded coefficients to get wrong. Periods shorter than 10 dt are sub-stepped (the
input interpolated linearly, still exact) so that the peak response between samples is
not missed. The recurrence over time runs in numba for all periods of one call.

The pseudo-spectral acceleration is PSA = w^2 max |u|.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import NDArray
from scipy.linalg import expm

from rockyade.errors import InputError

#: Sub-step when the period is shorter than this many samples.
MIN_STEPS_PER_PERIOD = 10


def default_periods(t_min: float = 0.02, t_max: float = 4.0, n: int = 100) -> NDArray[np.float64]:
    """Log-spaced periods, s."""
    return np.geomspace(t_min, t_max, n)


def _recurrence(omega: float, damping: float, h: float) -> NDArray[np.float64]:
    """(Phi, Gamma0, Gamma1) flattened: 4 + 2 + 2 numbers."""
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
    return np.concatenate([phi.ravel(), gamma0, gamma1])


@numba.njit(cache=True)
def _peak_response(accel, coeffs, substeps):
    n_per = coeffs.shape[0]
    out = np.zeros(n_per)
    n = accel.size
    for j in range(n_per):
        c = coeffs[j]
        m = substeps[j]
        u = 0.0
        v = 0.0
        peak = 0.0
        for i in range(n - 1):
            a0 = accel[i]
            da = (accel[i + 1] - a0) / m
            for k in range(m):
                aa = a0 + k * da
                u_new = c[0] * u + c[1] * v + c[4] * aa + c[6] * da
                v = c[2] * u + c[3] * v + c[5] * aa + c[7] * da
                u = u_new
                if abs(u) > peak:
                    peak = abs(u)
        out[j] = peak
    return out


def response_spectrum(
    accel_m_s2: NDArray[np.float64], dt_s: float, periods_s: NDArray[np.float64] | None = None, damping: float = 0.05
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Pseudo-acceleration response spectrum of a uniformly sampled record.

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
    coeffs = np.array([_recurrence(2 * np.pi / T, damping, dt_s / m) for T, m in zip(periods, substeps, strict=True)])
    peaks = _peak_response(accel, coeffs, substeps)
    omega = 2 * np.pi / periods
    return periods, omega * omega * peaks
