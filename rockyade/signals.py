"""Signal processing helpers shared by solvers and analysis (scipy.signal underneath)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import signal

from rockyade.errors import InputError


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
    if not 0 < cutoff_hz < nyquist:
        raise InputError("output.accel_lowpass_hz", f"must be in (0, {nyquist:g}) Hz (Nyquist), got {cutoff_hz!r}")
    sos = signal.butter(order, cutoff_hz, btype="low", fs=1.0 / dt_s, output="sos")
    if x.size <= 3 * (2 * len(sos) + 1):
        return x.copy()
    return signal.sosfiltfilt(sos, x)
