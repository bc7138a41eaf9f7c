"""Starting values of a free-rocking identification from the record's peaks and zero crossings.

* the quarter period of free rocking from rest at theta_0 scales as 1/p:
  T_q = tau(theta_0 / alpha) / p (Housner's linearised value is
  (1/p) arccosh(1 / (1 - theta_0/alpha)); tau is the exact one, an elliptic integral of the
  energy integral at p = 1: :func:`quarter_period_p1`);
  each half period between two zero crossings, 2 tau(A_k/alpha) / p with A_k the peak
  between them, gives (alpha, p) from the amplitude dependence of the period;
* mu from the potential energy at successive peaks,
  mu^2 = V(A_{k+1}) / V(A_k), V(A) = cos(alpha - A) - cos(alpha) (DESIGN.md);
* the release time: the first crossing minus T_q(theta_0); the offset from the rest at the
  end of the record or from the geometric decay of the peaks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import optimize, special

from rockyade.blocks.restitution import effective_restitution
from rockyade.identification.forward_model import FreeRockingFit, IdentificationError
from rockyade.identification.measurement import MeasuredHistory


def quarter_period_p1(ratio: ArrayLike, alpha_rad: ArrayLike) -> NDArray[np.float64]:
    """Time from rest at theta_0 = ratio alpha to the first impact, for p = 1 rad/s.

    Exact for Housner's nonlinear equation, theta'' = -p^2 sin(alpha - theta) for theta > 0
    (paper Eq 1 without base motion): the energy integral (Housner 1963)
    theta'^2 / 2 = p^2 [cos(alpha - theta_0) - cos(alpha - theta)] gives the time from
    theta_0 to 0 as a quadrature which, with x = sin((alpha - theta) / 2), is the elliptic
    integral of the first kind (Byrd & Friedman 1971, formula 217.00)

        T = F(phi | m) / p,  m = cos^2((alpha - theta_0) / 2),
        sin^2(phi) = sin(theta_0 / 2) sin(alpha - theta_0 / 2) / (sin^2(alpha / 2) m),

    (``scipy.special.ellipkinc``). It scales as 1/p; the linearised value is
    arccosh(1 / (1 - ratio)). It agrees with the time of the first impact from
    :func:`rockyade.housner.solve` to 1e-12 (relative) for ratio 0.01-0.98 and alpha
    0.05-1.5 rad.

    Parameters
    ----------
    ratio
        theta_0 / alpha (scalar or array).
    alpha_rad
        Slenderness angle, rad (scalar or array, broadcast against ``ratio``).

    Returns
    -------
    numpy.ndarray
        Time to the first impact, s (for p = 1 rad/s); inf where there is none (ratio
        outside (0, 1): at rest upright, or overturning; alpha - theta_0 beyond pi, or too
        little energy to reach theta = 0: possible only for alpha beyond pi, which the search
        grid of alpha may reach, where the time for alpha - theta passing pi is
        2 K(m) - F(phi | m)).
    """
    r = np.asarray(ratio, dtype=float)
    alpha = np.asarray(alpha_rad, dtype=float)
    theta0 = r * alpha
    m = np.cos(0.5 * (alpha - theta0)) ** 2
    reach = np.sin(0.5 * theta0) * np.sin(alpha - 0.5 * theta0)  # sin^2(alpha/2) - sin^2((alpha - theta_0)/2)
    with np.errstate(invalid="ignore", divide="ignore"):
        phi = np.arcsin(np.sqrt(np.clip(reach / (np.sin(0.5 * alpha) ** 2 * m), 0.0, 1.0)))
        t = special.ellipkinc(phi, m)
        # alpha beyond pi: alpha - theta passes pi on the way (x is not monotone there)
        t = np.where(alpha > math.pi, 2.0 * special.ellipk(m) - t, t)
    falls_back = (r > 0.0) & (r < 1.0) & (alpha - theta0 < math.pi) & (reach > 0.0)
    return np.where(falls_back, t, np.inf)


@dataclass(frozen=True)
class Guess:
    """The starting point and what the record shows.

    Attributes
    ----------
    fit
        Starting values of the unknowns.
    noise_rad
        Noise level estimated from second differences, rad.
    crossings_s
        Times the reading crosses the offset (impacts), s.
    amplitudes_rad
        Release tilt, then the peak of each closed excursion after it, rad.
    half_periods_s
        Time between successive crossings, s.
    notes
        How each value was obtained.
    """

    fit: FreeRockingFit
    noise_rad: float
    crossings_s: NDArray[np.float64]
    amplitudes_rad: NDArray[np.float64]
    half_periods_s: NDArray[np.float64]
    notes: tuple[str, ...] = field(default=())


def noise_level(theta: NDArray[np.float64]) -> float:
    """Standard deviation of white measurement noise, rad, from second differences.

    The second difference of white noise has variance 6 sigma^2; the median absolute value
    (/0.6745) ignores the few samples at impacts and keeps the estimate robust.

    Parameters
    ----------
    theta
        Measured rotation at equally spaced samples, rad.
    """
    d2 = np.diff(theta, 2)
    return float(np.median(np.abs(d2)) / 0.6745 / math.sqrt(6.0))


def _crossings(t: NDArray[np.float64], y: NDArray[np.float64], threshold: float):
    """Zero crossings of y with hysteresis ``threshold`` and the extreme between them.

    Returns the crossing times (linear interpolation at the last sign change before the
    signal leaves the band), the signed extremes of the excursions between crossings
    (index-aligned: extreme k lies before crossing k) and the extreme indices.
    """
    state = 0
    last_sign_change = -1
    crossings: list[float] = []
    extremes: list[float] = []
    extreme_index: list[int] = []
    ext_i = 0
    # the loop on Python floats (the same doubles: the same arithmetic, the same result),
    # several times faster than indexing the arrays one numpy scalar at a time
    tl: list[float] = t.tolist()
    yl: list[float] = y.tolist()
    for i, v in enumerate(yl):
        if i > 0 and (yl[i - 1] > 0) != (v > 0):
            last_sign_change = i
        s = 1 if v > threshold else (-1 if v < -threshold else 0)
        if state == 0:
            if s != 0:
                state = s
                ext_i = i
            continue
        if s == -state:
            j = last_sign_change
            frac = yl[j - 1] / (yl[j - 1] - yl[j])
            crossings.append(float(tl[j - 1] + frac * (tl[j] - tl[j - 1])))
            extremes.append(float(yl[ext_i]))
            extreme_index.append(ext_i)
            state = s
            ext_i = i
        elif s == state and abs(v) > abs(yl[ext_i]):
            ext_i = i
    return np.array(crossings), np.array(extremes), np.array(extreme_index, dtype=int)


def _smooth(y: NDArray[np.float64], width: int) -> NDArray[np.float64]:
    if width <= 1:
        return y
    kernel = np.ones(width) / width
    return np.convolve(np.pad(y, width // 2, mode="edge"), kernel, mode="valid")[: y.size]


def _peak_value(t: NDArray[np.float64], y: NDArray[np.float64], i: int, half_window_s: float) -> float:
    """Extreme of y near sample i from a least-squares parabola over +/- ``half_window_s``
    (noise on single samples biases the raw extreme)."""
    dt = float(t[1] - t[0])
    w = max(2, round(half_window_s / dt))
    lo, hi = max(0, i - w), min(y.size, i + w + 1)
    if hi - lo < 5:
        return float(y[i])
    tt = t[lo:hi] - t[i]
    c2, c1, c0 = np.polyfit(tt, y[lo:hi], 2)
    if c2 == 0.0 or abs(-c1 / (2 * c2)) > tt.max() - tt.min():
        return float(y[i])
    return float(c0 - c1 * c1 / (4.0 * c2))


def _offset_from_peaks(peaks: NDArray[np.float64]) -> float | None:
    """Offset o that makes successive peaks decay geometrically: (P_{k+1} - o)^2 = (P_k - o)(P_{k+2} - o)."""
    values = []
    for k in range(min(len(peaks) - 2, 6)):
        a, b, c = peaks[k], peaks[k + 1], peaks[k + 2]
        den = a + c - 2.0 * b
        if abs(den) > 1e-12:
            values.append((a * c - b * b) / den)
    return float(np.median(values)) if values else None


def _alpha_p_from_half_periods(amplitudes: NDArray[np.float64], half_periods: NDArray[np.float64]):
    """(alpha, p) that fit half periods 2 tau(A/alpha, alpha) / p best (relative error)."""
    a_max = float(np.max(amplitudes))

    def p_and_cost(alpha: float) -> tuple[float, float]:
        tau = 2.0 * quarter_period_p1(amplitudes / alpha, alpha)
        if not np.all(np.isfinite(tau)):
            return math.nan, math.inf
        # T = tau / p: least squares on relative errors gives 1/p = mean(T / tau)
        inv_p = float(np.mean(half_periods / tau))
        cost = float(np.sum((half_periods - tau * inv_p) ** 2 / half_periods**2))
        return 1.0 / inv_p, cost

    grid = a_max * np.geomspace(1.05, 40.0, 60)
    costs = [p_and_cost(a)[1] for a in grid]
    k = int(np.argmin(costs))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    best = optimize.minimize_scalar(
        lambda a: p_and_cost(a)[1], bounds=(lo, hi), method="bounded", options={"xatol": 1e-6 * a_max}
    )
    alpha = float(best.x)
    return min(alpha, 1.5), p_and_cost(alpha)[0]


def initial_guess(history: MeasuredHistory) -> Guess:
    """Starting values from the record's peaks and zero crossings (module docstring).

    Parameters
    ----------
    history
        The measured history (times in s, rotation in rad).

    Raises
    ------
    IdentificationError
        When the reading never crosses its rest value clearly (no impact to fit).
    """
    t, y = history.t_s, history.theta_rad
    noise = noise_level(y)
    amplitude = float(np.max(y) - np.min(y))
    notes = [f"noise {noise:.3g} rad (second differences)"]
    tail = y[-max(10, y.size // 10) :]
    quiet_tail = float(np.std(tail)) < max(4.0 * noise, 1e-3 * amplitude)
    offset = float(np.median(tail))
    threshold = max(6.0 * noise, 0.02 * amplitude)
    for _ in range(3):
        crossings, extremes, ext_index = _crossings(t, y - offset, threshold)
        if quiet_tail or len(extremes) < 4:
            break
        refined = _offset_from_peaks(extremes[1:] + offset)
        if refined is None:
            break
        offset = refined
    notes.append("offset from the rest at the end" if quiet_tail else "offset from the decay of the peaks")
    if crossings.size < 1:
        cause = (
            f"too noisy: a noise of {noise:.3g} rad hides a swing of {amplitude:.3g} rad"
            if 6.0 * noise > 0.25 * amplitude
            else "the block does not rock (too short, or no release in the record)"
        )
        raise IdentificationError(
            f"{history.source or 'the record'}: the rotation never crosses its rest value clearly (threshold "
            f"{threshold:.3g} rad): no impact, nothing to identify: {cause}"
        )
    # release tilt: the extreme of the first excursion (a hold, or a record starting at rest)
    first_seg = y[: np.searchsorted(t, crossings[0])]
    smooth = _smooth(first_seg - offset, 5)
    k0 = int(np.argmax(np.abs(smooth)))
    side = 1 if smooth[k0] > 0 else -1
    theta0 = float(abs(smooth[k0]))
    started_moving = k0 == 0 and abs(smooth[-1]) < abs(smooth[0]) and first_seg.size > 3
    peak_values = [
        _peak_value(t, y - offset, int(i), 0.05 * float(np.median(np.diff(crossings))) if crossings.size > 1 else 0.02)
        for i in ext_index[1:]
    ]
    amplitudes = np.concatenate([[theta0], np.abs(peak_values)])
    half_periods = np.diff(crossings)
    usable = amplitudes[1 : 1 + half_periods.size] > 10.0 * max(noise, 1e-12)
    amps_hp = amplitudes[1 : 1 + half_periods.size][usable]
    hps = half_periods[usable]
    if hps.size >= 2:
        alpha, p = _alpha_p_from_half_periods(amps_hp, hps)
        notes.append(f"alpha, p from {hps.size} half periods and their amplitudes (exact Housner periods)")
    elif hps.size == 1:
        alpha = 2.0 * max(theta0, amps_hp[0])
        p = float(2.0 * quarter_period_p1(amps_hp[0] / alpha, alpha) / hps[0])
        notes.append("one half period only: alpha guessed as twice the release tilt")
    else:
        alpha = 2.0 * theta0
        p = float(quarter_period_p1(0.5, alpha) / max(crossings[0] - t[0], history.dt_s))
        notes.append("no complete half period: alpha guessed as twice the release tilt, p from the first fall")
    alpha = max(alpha, 1.02 * theta0)
    peaks_for_mu = amplitudes[amplitudes > 10.0 * max(noise, 1e-12)]
    mu = effective_restitution(peaks_for_mu[:8], alpha) if peaks_for_mu.size >= 2 else 0.9
    mu = float(min(max(mu, 0.05), 0.999)) if math.isfinite(mu) else 0.9
    ratio = min(theta0 / alpha, 0.98)
    t_release = float(crossings[0] - quarter_period_p1(ratio, alpha) / p)
    if started_moving:
        notes.append("the record starts after the release: release time extrapolated before it")
    fit = FreeRockingFit(alpha, p, mu, t_release, offset, ratio, side)
    return Guess(fit, noise, crossings, amplitudes, half_periods, tuple(notes))
