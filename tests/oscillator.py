"""An independent reference for response spectra: the damped oscillator's exact response to a
record taken linear between its samples, on a grid much finer than the record's."""

from __future__ import annotations

import numpy as np
from scipy import signal

#: Reference points per sample of the record.
FINE = 100


def fine_grid_psa(accel: np.ndarray, dt: float, period: float, damping: float, free_s: float | None = None) -> float:
    """Pseudo-spectral acceleration w^2 max|u| (units of ``accel``) of the oscillator of
    ``period`` (s) and ``damping`` (ratio) under ``accel`` sampled every ``dt`` (s), followed
    by ``free_s`` of free vibration (default two periods), the peak taken on a grid of dt / FINE.

    scipy's exact discretisation (``cont2discrete``, first-order hold: the input linear between
    points) run as a recurrence by ``lfilter``: it agrees with ``signal.lsim(..., interp=True)``
    on the same grid within 2e-8 (relative), at a fortieth of its cost."""
    w = 2 * np.pi / period
    free = 2 * period if free_s is None else free_s
    padded = np.concatenate([accel, np.zeros(int(np.ceil(free / dt)))])
    t = np.arange(padded.size) * dt
    fine_t = np.arange(0.0, t[-1], dt / FINE)
    a = np.array([[0.0, 1.0], [-w * w, -2 * damping * w]])
    b, c, d = np.array([[0.0], [-1.0]]), np.array([[1.0, 0.0]]), np.array([[0.0]])
    ad, bd, cd, dd, _ = signal.cont2discrete((a, b, c, d), dt / FINE, method="foh")
    num, den = signal.ss2tf(ad, bd, cd, dd)
    u = signal.lfilter(num[0], den, np.interp(fine_t, t, padded))
    return float(w * w * np.max(np.abs(u)))
