"""Rocking peaks and the effective restitution measured on a history theta(t).

Classical theory applied to any solver's output (and to measurements). Effective
restitution: with V(theta) = M g R (cos(alpha - |theta|) - cos alpha)
the potential energy at a peak, mu_eff = sqrt(V(theta_peak,n+1) / V(theta_peak,n)) for
successive peaks of a free-rocking history (one impact between them). M g R cancels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class Peaks:
    """Peaks of |theta|, one per excursion between zero crossings.

    Attributes
    ----------
    t_s
        Peak times, s (parabolic refinement between samples).
    theta_rad
        Signed peak values, rad.
    """

    t_s: NDArray[np.float64]
    theta_rad: NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.t_s.size)

    @property
    def amplitude_rad(self) -> NDArray[np.float64]:
        """|theta| at the peaks."""
        return np.abs(self.theta_rad)


def find_peaks(t: NDArray[np.float64], theta: NDArray[np.float64], min_peak_rad: float = 1e-5) -> Peaks:
    """Rocking peaks: the extreme of theta in each excursion between sign changes.

    Each peak is refined by the vertex of the parabola through the extreme sample and its
    neighbours. Excursions whose |theta| stays below ``min_peak_rad`` (contact settlement
    noise in the DEMs) are ignored, as are excursions cut by the ends of the record.

    Parameters
    ----------
    t, theta
        Samples (s, rad), equally spaced.
    min_peak_rad
        Smallest peak kept, rad.
    """
    theta = np.asarray(theta, dtype=float)
    t = np.asarray(t, dtype=float)
    valid = np.isfinite(theta)
    amp = np.abs(theta)
    sign = np.where(amp < 0.1 * min_peak_rad, 0, np.sign(theta))
    sign[~valid] = 0
    times, values = [], []
    n = theta.size
    if n:
        # the excursions: runs of one sign; in each, the first sample of the largest |theta|
        cut = np.flatnonzero(sign[1:] != sign[:-1]) + 1
        first = np.concatenate(([0], cut))
        last = np.concatenate((cut, [n])) - 1
        largest = np.maximum.reduceat(amp, first)
        at_largest = np.flatnonzero(amp == np.repeat(largest, last - first + 1))
        rocking = sign[first] != 0
        first, last = first[rocking], last[rocking]
        k = at_largest[np.searchsorted(at_largest, first)]
        closed = (first > 0) & (last < n - 1)
        for kk in k[closed & (amp[k] >= min_peak_rad)]:
            tk, vk = _parabolic_vertex(t, theta, int(kk))
            times.append(tk)
            values.append(vk)
    return Peaks(np.array(times), np.array(values))


def _parabolic_vertex(t: NDArray[np.float64], y: NDArray[np.float64], k: int) -> tuple[float, float]:
    """Vertex of the parabola through samples k-1, k, k+1 (equal spacing)."""
    if k == 0 or k == y.size - 1:
        return float(t[k]), float(y[k])
    y0, y1, y2 = y[k - 1], y[k], y[k + 1]
    denom = y0 - 2.0 * y1 + y2
    if denom == 0.0:
        return float(t[k]), float(y1)
    shift = 0.5 * (y0 - y2) / denom
    shift = max(-1.0, min(1.0, shift))
    h = t[k + 1] - t[k]
    return float(t[k] + shift * h), float(y1 - 0.25 * (y0 - y2) * shift)


def rocking_potential(theta: NDArray[np.float64] | float, alpha: float) -> NDArray[np.float64]:
    """V(theta) / (M g R) = cos(alpha - |theta|) - cos(alpha)."""
    return np.cos(alpha - np.abs(theta)) - math.cos(alpha)


def restitution_per_impact(peaks: Peaks | NDArray[np.float64], alpha: float) -> NDArray[np.float64]:
    """mu_eff of each pair of successive peaks, sqrt(V_{n+1} / V_n)."""
    amp = peaks.amplitude_rad if isinstance(peaks, Peaks) else np.abs(np.asarray(peaks, dtype=float))
    v = rocking_potential(amp, alpha)
    return np.sqrt(v[1:] / v[:-1])


#: Impacts over which rockyade reports an effective restitution (run, compare, the matched
#: calibration and the paper study all use this one count, so their mu_eff agree).
MU_EFF_IMPACTS = 4


def effective_restitution(peaks: Peaks | NDArray[np.float64], alpha: float, n_impacts: int | None = None) -> float:
    """Mean effective restitution over the first ``n_impacts`` impacts (geometric mean).

    mu_eff = (V_n / V_0)^(1 / (2 n)), which is the geometric mean of the per-impact values.
    Returns NaN when fewer than two peaks are available.
    """
    amp = peaks.amplitude_rad if isinstance(peaks, Peaks) else np.abs(np.asarray(peaks, dtype=float))
    if n_impacts is not None:
        amp = amp[: n_impacts + 1]
    if amp.size < 2:
        return math.nan
    v = rocking_potential(amp, alpha)
    if v[0] <= 0 or v[-1] <= 0:
        return math.nan
    return float((v[-1] / v[0]) ** (1.0 / (2 * (amp.size - 1))))
