"""Processing of accelerograms: integration, baseline correction, band-pass, scaling.

Baseline correction (zero final velocity and displacement) in two steps:

1. (records, ``detrend=True``) a least-squares quadratic fitted to the velocity is removed
   (its derivative from the acceleration), which takes out the usual linear drift of
   velocity; synthetic records skip it, since a ramp in the acceleration has a broad
   low-frequency spectrum that would undo the spectral matching at long periods;
2. an exact end correction c1 sin(pi t / T) + c2 sin(2 pi t / T) is removed from the
   acceleration, with c1, c2 solving final velocity = 0 and final displacement = 0 for the
   integration actually used. Both windows vanish at both ends (the base starts and ends
   at rest without a jump) and have periods T and 2 T, longer than any structural period
   of interest, so the response spectrum is barely touched.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError

#: Lowest corner of a Butterworth filter, as a fraction of the Nyquist frequency: below
#: it the digital filter's poles sit within rounding of 1 and the filter is meaningless.
MIN_CORNER_FRACTION = 1.0e-5


def integrate(t: NDArray[np.float64], accel: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Velocity and displacement from rest, exact for piecewise-linear acceleration."""
    dt = np.diff(t)
    from scipy.integrate import cumulative_trapezoid

    v = cumulative_trapezoid(accel, t, initial=0.0)
    dd = v[:-1] * dt + dt * dt * (accel[:-1] / 3.0 + accel[1:] / 6.0)
    return v, np.concatenate([[0.0], np.cumsum(dd)])


def baseline_correct(t: NDArray[np.float64], accel: NDArray[np.float64], detrend: bool = True) -> NDArray[np.float64]:
    """Acceleration corrected so that the final velocity and displacement are zero.

    See the module docstring for the method.
    """
    t = np.asarray(t, dtype=float)
    a = np.asarray(accel, dtype=float)
    if detrend:
        v, _ = integrate(t, a)
        coeffs = np.polynomial.polynomial.polyfit(t, v, 2)
        a = a - (coeffs[1] + 2.0 * coeffs[2] * t)
    span = t[-1] - t[0]
    tau = (t - t[0]) / span
    basis = [np.sin(np.pi * tau), np.sin(2.0 * np.pi * tau)]
    v_end, d_end = (x[-1] for x in integrate(t, a))
    m = np.array([[integrate(t, b)[k][-1] for b in basis] for k in (0, 1)])
    c = np.linalg.solve(m, [v_end, d_end])
    return a - c[0] * basis[0] - c[1] * basis[1]


def bandpass(
    accel: NDArray[np.float64], dt_s: float, low_hz: float | None, high_hz: float | None, order: int = 4
) -> NDArray[np.float64]:
    """Zero-phase Butterworth band-pass (or low/high-pass when one corner is None)."""
    fs = 1.0 / dt_s
    nyq = 0.5 * fs
    lowest = MIN_CORNER_FRACTION * nyq
    if low_hz is not None and not lowest <= low_hz < nyq:
        raise InputError("bandpass_hz", f"low corner must be in [{lowest:g}, {nyq:g}) Hz, got {low_hz!r}")
    if high_hz is not None and not lowest <= high_hz < nyq:
        raise InputError("bandpass_hz", f"high corner must be in [{lowest:g}, {nyq:g}) Hz (Nyquist), got {high_hz!r}")
    if low_hz is not None and high_hz is not None and low_hz >= high_hz:
        raise InputError("bandpass_hz", f"low corner {low_hz} Hz must be below the high corner {high_hz} Hz")
    if low_hz is None and high_hz is None:
        return np.asarray(accel, dtype=float).copy()
    from scipy import signal

    if low_hz is not None and high_hz is not None:
        sos = signal.butter(order, [low_hz, high_hz], btype="bandpass", fs=fs, output="sos")
    elif low_hz is not None:
        sos = signal.butter(order, low_hz, btype="highpass", fs=fs, output="sos")
    else:
        sos = signal.butter(order, high_hz, btype="lowpass", fs=fs, output="sos")
    return signal.sosfiltfilt(sos, np.asarray(accel, dtype=float))


def scale_to_pga(accel: NDArray[np.float64], target_pga_m_s2: float) -> tuple[NDArray[np.float64], float]:
    """The record scaled to a target peak ground acceleration, and the factor used."""
    pga = float(np.max(np.abs(accel)))
    if pga == 0:
        raise InputError("target_pga_m_s2", "cannot scale a record of zero acceleration")
    factor = target_pga_m_s2 / pga
    return np.asarray(accel) * factor, factor


def lowpass_zero_phase(x: NDArray[np.float64], dt_s: float, cutoff_hz: float, order: int = 4) -> NDArray[np.float64]:
    """Zero-phase Butterworth low-pass (forward-backward, ``sosfiltfilt``).

    The paper (Section 6.1) notes that the DEM's impact spikes in the top accelerations are
    numerical and may be filtered without losing accuracy; a zero-phase filter does so
    without shifting the signal in time.

    Parameters
    ----------
    x
        Samples.
    dt_s
        Sampling interval, s.
    cutoff_hz
        -3 dB cut-off, Hz; must be below the Nyquist frequency 1 / (2 dt).
    order
        Filter order (applied twice).
    """
    nyquist = 0.5 / dt_s
    lowest = MIN_CORNER_FRACTION * nyquist
    if not lowest <= cutoff_hz < nyquist:
        raise InputError(
            "output.accel_lowpass_hz", f"must be in [{lowest:g}, {nyquist:g}) Hz (Nyquist), got {cutoff_hz!r}"
        )
    from scipy import signal

    sos = signal.butter(order, cutoff_hz, btype="low", fs=1.0 / dt_s, output="sos")
    if x.size <= 3 * (2 * len(sos) + 1):
        return x.copy()
    return signal.sosfiltfilt(sos, x)
