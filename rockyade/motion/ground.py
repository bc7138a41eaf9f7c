"""A base motion as every solver sees it: piecewise-linear base acceleration samples.

:class:`GroundMotion` holds the samples; :func:`ground_acceleration` is the one compiled
lookup of the base acceleration at a time t, shared by the reference DEM's kernel (which
steps forward in time) and Housner's integrator (whose root finding goes back and forth).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray


@numba.njit(cache=True, nogil=True, inline="always")
def ground_acceleration(t: float, t_s, ah, av, hint: int) -> tuple[float, float, int]:
    """Base acceleration at time ``t``: linear between samples, zero outside them.

    Parameters
    ----------
    t
        Time, s; any value, in any order from one call to the next.
    t_s
        (n,) strictly increasing sample times, s (n < 2: no motion, zero everywhere).
    ah, av
        (n,) horizontal and vertical base acceleration at ``t_s``, m/s^2.
    hint
        Index of the interval [t_s[j], t_s[j + 1]) found by the last call (0 at first). It
        is checked, then its successor (a time stepper's next step), and only then is the
        interval searched by bisection, so the answer never depends on the hint.

    Returns
    -------
    ah, av
        Base acceleration at ``t``, m/s^2: a_j + w (a_{j+1} - a_j) with
        w = (t - t_j) / (t_{j+1} - t_j) on t_j <= t < t_{j+1}, the last sample itself at
        t = t_{n-1}, and 0 for t < t_0 or t > t_{n-1} (``GroundMotion.horizontal``, as
        ``numpy.interp`` with ``left = right = 0``).
    hint
        The interval used, to pass to the next call (unchanged when ``t`` is outside).
    """
    n = t_s.size
    if n < 2 or t < t_s[0] or t > t_s[n - 1]:
        return 0.0, 0.0, hint
    if t == t_s[n - 1]:
        return ah[n - 1], av[n - 1], n - 2
    j = min(max(hint, 0), n - 2)
    if t < t_s[j] or t >= t_s[j + 1]:
        # t < t_s[n - 1] here: a successor interval exists whenever t >= t_s[j + 1]
        if t >= t_s[j + 1] and t < t_s[j + 2]:
            j += 1
        else:
            j = np.searchsorted(t_s, t, side="right") - 1
    w = (t - t_s[j]) / (t_s[j + 1] - t_s[j])
    return ah[j] + w * (ah[j + 1] - ah[j]), av[j] + w * (av[j + 1] - av[j]), j


@numba.njit(cache=True, nogil=True, inline="always")
def aligned_step(t: float, h_max: float, duration: float, t_s) -> float:
    """The next step of an integrator at ``t``: at most ``h_max``, ending on the next base-motion
    sample when that is nearer (halving the gap when it is only a little longer than ``h_max``,
    so that no sliver of a step is left before the sample), and not past ``duration``; <= 0:
    the end (Housner's and the two-block integrators, whose forcing is then smooth within a step).

    Parameters
    ----------
    t, h_max, duration
        Time, the largest step and the end time, s.
    t_s
        (n,) the base motion's sample times, s.
    """
    h = h_max
    n = t_s.size
    if n >= 2 and t < t_s[n - 1]:
        j = np.searchsorted(t_s, t, side="right")
        if j < n:
            gap = t_s[j] - t
            if gap < h:
                h = gap
            elif gap < h * 1.1:
                h = 0.5 * gap
    if t + h > duration:
        h = duration - t
    return h


@dataclass(frozen=True, init=False)
class GroundMotion:
    """Horizontal (and optional vertical) base acceleration, linear between samples.

    Sign convention: ``ah_m_s2 > 0`` accelerates the base towards +x, which makes a block
    resting on it rock with theta'' > 0 (pivot on the left corner). ``av_m_s2 > 0``
    accelerates the base upwards (adds to gravity). Outside [t_s[0], t_s[-1]] the
    acceleration is zero.

    Attributes
    ----------
    t_s
        Strictly increasing sample times, s, starting at 0.
    ah_m_s2, av_m_s2
        Horizontal and vertical base acceleration at ``t_s``, m/s^2.
    label
        Human-readable description (e.g. "harmonic 3.3 Hz, 6 mm").
    """

    t_s: NDArray[np.float64]
    ah_m_s2: NDArray[np.float64]
    av_m_s2: NDArray[np.float64]
    label: str = ""

    def __init__(self, t_s: ArrayLike, ah_m_s2: ArrayLike, av_m_s2: ArrayLike | None = None, label: str = "") -> None:
        # Written out (not the dataclass's) so that the arguments may be any array-like and
        # ``av_m_s2`` None (no vertical motion), while the attributes are always float arrays,
        # contiguous and writable (a read-only one, a cached synthetic record's, is copied): numba
        # compiles a kernel once per argument type, and a read-only array is another type, which
        # would compile every kernel twice and miss the code ``make setup`` compiled.
        t = np.require(t_s, dtype=float, requirements=["C", "W"])
        ah = np.require(ah_m_s2, dtype=float, requirements=["C", "W"])
        av = np.zeros_like(ah) if av_m_s2 is None else np.require(av_m_s2, dtype=float, requirements=["C", "W"])
        if t.ndim != 1 or t.size < 2 or ah.shape != t.shape or av.shape != t.shape:
            raise ValueError("t_s, ah_m_s2 and av_m_s2 must be 1-D arrays of the same length >= 2")
        if not np.all(np.diff(t) > 0):
            raise ValueError("t_s must be strictly increasing")
        if not (np.all(np.isfinite(ah)) and np.all(np.isfinite(av))):
            raise ValueError("base acceleration contains NaN or infinite values")
        object.__setattr__(self, "t_s", t)
        object.__setattr__(self, "ah_m_s2", ah)
        object.__setattr__(self, "av_m_s2", av)
        object.__setattr__(self, "label", label)

    @classmethod
    def uniform(cls, dt_s: float, ah: ArrayLike, av: ArrayLike | None = None, label: str = "") -> GroundMotion:
        """Samples at a constant interval ``dt_s`` from t = 0."""
        ah = np.asarray(ah, dtype=float)
        return cls(np.arange(ah.size) * dt_s, ah, None if av is None else np.asarray(av, float), label)

    @property
    def duration_s(self) -> float:
        """Time of the last sample, s."""
        return float(self.t_s[-1])

    @property
    def has_vertical(self) -> bool:
        """True when any vertical acceleration is non-zero."""
        return bool(np.any(self.av_m_s2 != 0.0))

    def horizontal(self, t: ArrayLike) -> NDArray[np.float64]:
        """Horizontal base acceleration at times ``t``, m/s^2."""
        return np.interp(np.asarray(t, dtype=float), self.t_s, self.ah_m_s2, left=0.0, right=0.0)

    def vertical(self, t: ArrayLike) -> NDArray[np.float64]:
        """Vertical base acceleration at times ``t``, m/s^2."""
        return np.interp(np.asarray(t, dtype=float), self.t_s, self.av_m_s2, left=0.0, right=0.0)

    def velocity_displacement(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Horizontal base velocity (m/s) and displacement (m) at ``t_s``, from rest.

        Exact for the piecewise-linear acceleration: velocity by the trapezoid rule, and
        displacement by integrating the piecewise-quadratic velocity exactly.
        """
        dt = np.diff(self.t_s)
        a0, a1 = self.ah_m_s2[:-1], self.ah_m_s2[1:]
        from scipy.integrate import cumulative_trapezoid

        v = cumulative_trapezoid(self.ah_m_s2, self.t_s, initial=0.0)
        dd = v[:-1] * dt + dt * dt * (a0 / 3.0 + a1 / 6.0)
        d = np.concatenate([[0.0], np.cumsum(dd)])
        return v, d

    @property
    def pga_m_s2(self) -> float:
        """Peak absolute horizontal acceleration, m/s^2."""
        return float(np.max(np.abs(self.ah_m_s2)))
