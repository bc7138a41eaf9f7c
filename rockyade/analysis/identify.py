"""Classical parameters alpha, p, mu identified from a measured free-rocking history.

The paper's experimental parameters (Tables 3-4, E columns) were "adjusted by means of a
minimized error surface" on free-rocking tests. rockyade does the same with Housner's exact
solution (:mod:`rockyade.solvers.housner`): the measured rotation is modelled as

    theta_m(t) = s theta_H(t - t_r; alpha, p, mu, r alpha) + o        (t >= t_r)
    theta_m(t) = s r alpha + o                                        (t <  t_r, the hold)

with theta_H the free rocking of a symmetric block released at rest from the tilt
theta_0 = r alpha (paper Eq 1, base at rest, omega multiplied by mu at each impact), s the
side it was tilted to, t_r the release time and o the sensor offset. The six unknowns
(alpha, p, mu, t_r, o, r) minimise the sum of squared differences over every sample
(scipy's trust-region least squares). The model is evaluated at the measurement times
exactly: the solver is advanced from the release to the first sample after it, then sampled
on the measurement grid.

Starting point (:func:`initial_guess`), from the peaks and zero crossings of the record:

* the quarter period of free rocking from rest at theta_0 scales as 1/p:
  T_q = tau(theta_0 / alpha) / p (Housner's linearised value is
  (1/p) arccosh(1 / (1 - theta_0/alpha)); tau is taken from the exact solver at p = 1);
  each half period between two zero crossings, 2 tau(A_k/alpha) / p with A_k the peak
  between them, gives (alpha, p) from the amplitude dependence of the period;
* mu from the potential energy at successive peaks,
  mu^2 = V(A_{k+1}) / V(A_k), V(A) = cos(alpha - A) - cos(alpha) (DESIGN.md);
* t_r = (first crossing) - T_q(theta_0); o from the rest at the end or from the peaks.

95 % intervals: Gauss-Newton covariance s^2 (J^T J)^-1 (J the Jacobian at the optimum,
s^2 = SSR / (n - 6)) with Student's t quantile (Bates & Watts 1988, Ch. 2). When the
residuals are serially correlated (lag-1 autocorrelation above 3/sqrt(n)) the covariance is
the Newey-West (1987) sandwich with a Bartlett kernel instead, on scores prewhitened by the
residuals' AR(1) coefficient (Andrews & Monahan 1992), so that model error or coloured
noise widens the intervals; ``ci_method`` says which was used.

A parameter the data cannot identify is not returned as a number: it is listed in
``unidentifiable`` with the reason (too few impacts above the noise, too short, too
noisy, or an interval wider than ``max_relative_ci`` of the value).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import optimize, stats

from rockyade.analysis.measurement import MeasuredHistory
from rockyade.analysis.peaks import effective_restitution
from rockyade.errors import InputError, RockyadeError
from rockyade.solvers.housner import HousnerModel, solve

#: The fitted unknowns, in the order of the parameter vector.
FIT_PARAMETERS = ("alpha_rad", "p_rad_s", "mu", "release_time_s", "offset_rad", "release_ratio")
#: The classical parameters reported with intervals.
CLASSICAL = ("alpha_rad", "p_rad_s", "mu")
#: Impacts above the noise needed to identify alpha and p separately (the amplitude
#: dependence of the half period) and mu (at least one impact).
MIN_IMPACTS = {"alpha_rad": 2, "p_rad_s": 2, "mu": 1}
#: A parameter whose 95 % half interval exceeds this fraction of its value is unidentified.
DEFAULT_MAX_RELATIVE_CI = 0.10
#: An impact is observable when the peak before it exceeds this many residual rms.
OBSERVABLE_PEAK_RMS = 5.0
#: Confidence level of the reported intervals.
CONFIDENCE = 0.95
#: Relative finite-difference step of the Jacobian (the solver is accurate to ~1e-11).
DIFF_STEP = 1e-6


class IdentificationError(RockyadeError):
    """The record shows no free rocking that Housner's model can be fitted to."""


@dataclass(frozen=True)
class FreeRockingFit:
    """Values of the six unknowns.

    Attributes
    ----------
    alpha_rad, p_rad_s, mu
        Classical parameters (rad, rad/s, -).
    release_time_s
        Time of the release, s (in the record's time base).
    offset_rad
        Sensor offset: the reading when the block stands upright, rad.
    release_ratio
        theta_0 / alpha, the release tilt as a fraction of alpha (0 < r < 1).
    side
        +1 when released tilted to theta > 0, -1 otherwise.
    """

    alpha_rad: float
    p_rad_s: float
    mu: float
    release_time_s: float
    offset_rad: float
    release_ratio: float
    side: int = 1

    @property
    def vector(self) -> NDArray[np.float64]:
        """The unknowns in :data:`FIT_PARAMETERS` order."""
        return np.array([getattr(self, k) for k in FIT_PARAMETERS])

    @classmethod
    def from_vector(cls, x: NDArray[np.float64], side: int) -> FreeRockingFit:
        """Unknowns from a parameter vector."""
        return cls(*(float(v) for v in x), side=side)

    @property
    def theta0_rad(self) -> float:
        """Signed release tilt, rad."""
        return self.side * self.release_ratio * self.alpha_rad


def model_history(fit: FreeRockingFit, t0_s: float, dt_s: float, n: int, step_s: float | None = None):
    """The modelled measurement at t0 + k dt (k = 0..n-1), and Housner's trajectory.

    Returns
    -------
    theta
        Modelled reading, rad (hold, then free rocking, plus the offset).
    trajectory
        The solver's trajectory from the first sample after the release (or None when the
        release is after the record).
    delta_s
        Time from the release to that first sample, s.
    """
    theta = np.full(n, fit.theta0_rad + fit.offset_rad)
    i0 = max(0, math.ceil((fit.release_time_s - t0_s) / dt_s - 1e-9))
    if i0 >= n:
        return theta, None, 0.0
    model = HousnerModel.symmetric(fit.alpha_rad, fit.p_rad_s, fit.mu)
    start = abs(fit.theta0_rad)
    omega = 0.0
    delta = t0_s + i0 * dt_s - fit.release_time_s
    if delta > 1e-12:
        head = solve(model, None, delta, start, 0.0, sample_dt_s=delta, step_s=step_s)
        if head.status == "overturned":
            theta[i0:] = fit.side * 0.5 * math.pi + fit.offset_rad
            return theta, head, delta
        start, omega = float(head.theta_rad[-1]), float(head.omega_rad_s[-1])
    duration = (n - 1 - i0) * dt_s
    if duration <= 0.0:
        theta[i0:] = fit.side * start + fit.offset_rad
        return theta, None, delta
    traj = solve(model, None, duration, start, omega, sample_dt_s=dt_s, step_s=step_s)
    m = traj.theta_rad.size
    theta[i0 : i0 + m] = fit.side * traj.theta_rad + fit.offset_rad
    if m < n - i0:  # overturned: lying on its side
        theta[i0 + m :] = fit.side * math.copysign(0.5 * math.pi, traj.theta_rad[-1]) + fit.offset_rad
    return theta, traj, delta


# ------------------------------------------------------------------ starting point


@functools.lru_cache(maxsize=4096)
def quarter_period_p1(ratio: float, alpha_rad: float) -> float:
    """Time from rest at theta_0 = ratio alpha to the first impact, for p = 1 rad/s.

    Exact (Housner's nonlinear equation through the solver); it scales as 1/p. The
    linearised value is arccosh(1 / (1 - ratio)).
    """
    linear = math.acosh(1.0 / (1.0 - ratio))
    model = HousnerModel.symmetric(alpha_rad, 1.0, 1.0)
    duration = 1.5 * linear + 1.0
    traj = solve(model, None, duration, ratio * alpha_rad, 0.0, sample_dt_s=duration, step_s=2.5e-3)
    if traj.n_impacts == 0:
        return math.inf
    return float(traj.impacts[0, 0])


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
    for i, v in enumerate(y):
        if i > 0 and (y[i - 1] > 0) != (v > 0):
            last_sign_change = i
        s = 1 if v > threshold else (-1 if v < -threshold else 0)
        if state == 0:
            if s != 0:
                state = s
                ext_i = i
            continue
        if s == -state:
            j = last_sign_change
            frac = y[j - 1] / (y[j - 1] - y[j])
            crossings.append(float(t[j - 1] + frac * (t[j] - t[j - 1])))
            extremes.append(float(y[ext_i]))
            extreme_index.append(ext_i)
            state = s
            ext_i = i
        elif s == state and abs(v) > abs(y[ext_i]):
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
        tau = np.array([2.0 * quarter_period_p1(round(a / alpha, 12), round(alpha, 12)) for a in amplitudes])
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
        p = 2.0 * quarter_period_p1(amps_hp[0] / alpha, alpha) / hps[0]
        notes.append("one half period only: alpha guessed as twice the release tilt")
    else:
        alpha = 2.0 * theta0
        p = quarter_period_p1(0.5, alpha) / max(crossings[0] - t[0], history.dt_s)
        notes.append("no complete half period: alpha guessed as twice the release tilt, p from the first fall")
    alpha = max(alpha, 1.02 * theta0)
    peaks_for_mu = amplitudes[amplitudes > 10.0 * max(noise, 1e-12)]
    mu = effective_restitution(peaks_for_mu[:8], alpha) if peaks_for_mu.size >= 2 else 0.9
    mu = float(min(max(mu, 0.05), 0.999)) if math.isfinite(mu) else 0.9
    ratio = min(theta0 / alpha, 0.98)
    t_release = float(crossings[0] - quarter_period_p1(round(ratio, 12), round(alpha, 12)) / p)
    if started_moving:
        notes.append("the record starts after the release: release time extrapolated before it")
    fit = FreeRockingFit(alpha, p, mu, t_release, offset, ratio, side)
    return Guess(fit, noise, crossings, amplitudes, half_periods, tuple(notes))


# ------------------------------------------------------------------ the fit


@dataclass
class Identification:
    """Identified classical parameters, their 95 % intervals and the fit's diagnostics.

    Attributes
    ----------
    fit
        Values of the six unknowns at the optimum.
    ci
        95 % interval [lo, hi] of each unknown (``FIT_PARAMETERS`` keys).
    covariance
        Covariance of the unknowns (``FIT_PARAMETERS`` order).
    ci_method
        How the intervals were computed.
    rms_residual_rad
        Root mean square of measured minus modelled rotation, rad.
    n_samples, n_impacts
        Samples fitted; impacts of the fitted model within the record whose preceding peak
        exceeds ``OBSERVABLE_PEAK_RMS`` residual rms (observable above the noise).
    residual_lag1_correlation
        Lag-1 autocorrelation of the residuals.
    unidentifiable
        Parameter -> why it could not be identified (its value is then not reported).
    guess
        The starting point.
    history
        The measurement.
    evaluations
        Model evaluations used.
    """

    fit: FreeRockingFit
    ci: dict[str, tuple[float, float]]
    covariance: NDArray[np.float64]
    ci_method: str
    rms_residual_rad: float
    n_samples: int
    n_impacts: int
    residual_lag1_correlation: float
    unidentifiable: dict[str, str]
    guess: Guess
    history: MeasuredHistory
    evaluations: int
    max_relative_ci: float = DEFAULT_MAX_RELATIVE_CI

    @property
    def identified(self) -> bool:
        """True when alpha, p and mu were all identified."""
        return not self.unidentifiable

    def value(self, name: str) -> float | None:
        """An identified value, or None when it is unidentifiable."""
        return None if name in self.unidentifiable else float(getattr(self.fit, name))

    def modelled(self) -> NDArray[np.float64]:
        """The fitted model at the measurement times, rad."""
        h = self.history
        return model_history(self.fit, float(h.t_s[0]), h.dt_s, h.t_s.size)[0]

    def as_dict(self) -> dict[str, object]:
        """JSON-ready summary (the ``rockyade identify --json`` output)."""
        out: dict[str, object] = {}
        for name in CLASSICAL:
            out[name] = self.value(name)
            out[f"{name}_ci"] = None if name in self.unidentifiable else list(self.ci[name])
        out.update(
            {
                "release_time_s": self.fit.release_time_s,
                "release_time_s_ci": list(self.ci["release_time_s"]),
                "offset_rad": self.fit.offset_rad,
                "offset_rad_ci": list(self.ci["offset_rad"]),
                "release_theta_rad": self.fit.theta0_rad,
                "rms_residual_rad": self.rms_residual_rad,
                "n_impacts": self.n_impacts,
                "n_samples": self.n_samples,
                "sample_rate_hz": self.history.rate_hz,
                "confidence": CONFIDENCE,
                "ci_method": self.ci_method,
                "residual_lag1_correlation": self.residual_lag1_correlation,
                "covariance_alpha_p_mu": self.covariance[:3, :3].tolist(),
                "identified": self.identified,
                "unidentifiable": dict(self.unidentifiable),
                "max_relative_ci": self.max_relative_ci,
                "source": self.history.source,
                "input_notes": list(self.history.notes),
                "model": "Housner free rocking, symmetric block (paper Eq 1), released at rest",
            }
        )
        return out


def _bounds(guess: Guess, history: MeasuredHistory) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    t0 = float(history.t_s[0])
    first_crossing = float(guess.crossings_s[0])
    span = history.duration_s
    lo = np.array([1e-4, 1e-3, 1e-3, t0 - span, -np.inf, 1e-3])
    hi = np.array([0.5 * math.pi - 1e-3, np.inf, 1.0, first_crossing, np.inf, 0.999])
    return lo, hi


def _covariance(jac: NDArray[np.float64], resid: NDArray[np.float64], n_par: int) -> tuple[NDArray, str, float]:
    """Gauss-Newton covariance, or the Newey-West one when the residuals are correlated."""
    n = resid.size
    dof = max(n - n_par, 1)
    s2 = float(resid @ resid) / dof
    _u, sv, vt = np.linalg.svd(jac, full_matrices=False)
    keep = sv > sv[0] * 1e-12
    inv = (vt[keep].T / sv[keep] ** 2) @ vt[keep]
    rho1 = float(resid[:-1] @ resid[1:] / (resid @ resid)) if n > 2 and resid @ resid > 0 else 0.0
    if rho1 <= 3.0 / math.sqrt(n):
        return s2 * inv, "gauss-newton (residuals uncorrelated)", rho1
    # Newey-West (Bartlett kernel) on the scores J_t r_t prewhitened by the residuals' AR(1)
    # coefficient and recoloured (Andrews & Monahan 1992): the kernel alone under-estimates
    # the long-run variance of strongly correlated residuals
    rho = min(rho1, 0.97)
    g = jac * resid[:, None]
    e = g[1:] - rho * g[:-1]
    r = resid[1:] - rho * resid[:-1]
    denom = float(r @ r)
    m = r.size
    lag = 1
    limit = max(2, m // 10)
    while lag < limit and abs(float(r[:-lag] @ r[lag:])) / denom > 2.0 / math.sqrt(m):
        lag *= 2
    bandwidth = min(2 * lag, limit)
    meat = e.T @ e
    for ell in range(1, bandwidth + 1):
        w = 1.0 - ell / (bandwidth + 1.0)
        gamma = e[:-ell].T @ e[ell:]
        meat += w * (gamma + gamma.T)
    meat *= (n / m) * (n / dof) / (1.0 - rho) ** 2
    cov = inv @ meat @ inv
    text = f"newey-west, AR(1)-prewhitened (residual lag-1 correlation {rho1:.2f}, bandwidth {bandwidth} samples)"
    return cov, text, rho1


def _observable_impacts(fit: FreeRockingFit, traj, delta: float, t_end_rel: float, level: float) -> int:
    """Impacts of the model before the record ends whose preceding peak exceeds ``level``."""
    if traj is None or traj.n_impacts == 0:
        return 0
    times = traj.impacts[:, 0] + delta
    omega = traj.impacts[:, 1]
    # the peak before an impact from its speed: omega^2 / (2 p^2) = cos(alpha - A) - cos(alpha)
    c = np.clip(math.cos(fit.alpha_rad) + omega**2 / (2.0 * fit.p_rad_s**2), -1.0, 1.0)
    amp = fit.alpha_rad - np.arccos(c)
    return int(np.sum((times <= t_end_rel) & (amp > level)))


def identify(
    history: MeasuredHistory,
    *,
    max_relative_ci: float = DEFAULT_MAX_RELATIVE_CI,
    guess: Guess | None = None,
) -> Identification:
    """Identify alpha, p, mu (and the release time, offset, release tilt) of a free-rocking record.

    Parameters
    ----------
    history
        The measured rotation (:func:`rockyade.analysis.measurement.read_measurement`).
    max_relative_ci
        A parameter whose 95 % half interval exceeds this fraction of its value is
        reported as unidentifiable.
    guess
        Starting point (default :func:`initial_guess`).

    Raises
    ------
    IdentificationError
        When the record shows no impact at all.
    """
    if not (0.0 < max_relative_ci <= 10.0):
        raise InputError("max_relative_ci", f"must be in (0, 10], got {max_relative_ci!r}")
    guess = guess or initial_guess(history)
    t, y, dt = history.t_s, history.theta_rad, history.dt_s
    t0 = float(t[0])
    n = t.size
    step = 1.0 / (400.0 * guess.fit.p_rad_s * 1.3)
    side = guess.fit.side
    evaluations = 0
    lo, hi = _bounds(guess, history)

    def residuals(x: NDArray[np.float64], m: int) -> NDArray[np.float64]:
        nonlocal evaluations
        evaluations += 1
        fit = FreeRockingFit.from_vector(x, side)
        return model_history(fit, t0, dt, m, step)[0] - y[:m]

    x = np.clip(guess.fit.vector, lo + 1e-12, hi - 1e-12)
    # continuation: the first half cycles, then the whole record (avoids cycle slips)
    windows = []
    c = guess.crossings_s
    if c.size > 4:
        windows.append(int(min(n, np.searchsorted(t, c[3]) + 1)))
    windows.append(n)
    result = None
    for m in windows:
        result = optimize.least_squares(
            residuals,
            x,
            args=(m,),
            bounds=(lo, hi),
            method="trf",
            x_scale="jac",
            diff_step=DIFF_STEP,
            xtol=1e-12,
            ftol=1e-12,
            gtol=1e-12,
            max_nfev=400,
        )
        x = result.x
    assert result is not None
    fit = FreeRockingFit.from_vector(x, side)
    resid = result.fun
    jac = result.jac
    cov, method, rho1 = _covariance(jac, resid, x.size)
    tq = stats.t.ppf(0.5 + CONFIDENCE / 2.0, max(n - x.size, 1))
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    ci = {name: (float(v - tq * s), float(v + tq * s)) for name, v, s in zip(FIT_PARAMETERS, x, se, strict=True)}
    rms = float(math.sqrt(np.mean(resid**2)))
    _modelled, traj, delta = model_history(fit, t0, dt, n, step)
    t_end_rel = float(t[-1]) - fit.release_time_s
    n_impacts = _observable_impacts(fit, traj, delta, t_end_rel, OBSERVABLE_PEAK_RMS * rms)
    unidentifiable = _unidentifiable(fit, ci, cov, n_impacts, rms, history, max_relative_ci, lo, hi, x)
    return Identification(
        fit=fit,
        ci=ci,
        covariance=cov,
        ci_method=method,
        rms_residual_rad=rms,
        n_samples=n,
        n_impacts=n_impacts,
        residual_lag1_correlation=rho1,
        unidentifiable=unidentifiable,
        guess=guess,
        history=history,
        evaluations=evaluations,
        max_relative_ci=max_relative_ci,
    )


def _unidentifiable(fit, ci, cov, n_impacts, rms, history, max_rel, lo, hi, x) -> dict[str, str]:
    """Which classical parameters the data leave undetermined, and why."""
    out: dict[str, str] = {}
    theta0 = abs(fit.theta0_rad)
    span = history.duration_s
    sd = np.sqrt(np.maximum(np.diag(cov)[:2], 1e-300))
    corr = float(cov[0, 1] / (sd[0] * sd[1]))
    for k, name in enumerate(CLASSICAL):
        value = float(getattr(fit, name))
        half = 0.5 * (ci[name][1] - ci[name][0])
        rel = half / abs(value) if value else math.inf
        if n_impacts < MIN_IMPACTS[name]:
            why = (
                "the amplitude dependence of the period that separates alpha from p"
                if name != "mu"
                else "an impact to lose energy at"
            )
            out[name] = (
                f"too few impacts: {n_impacts} observable above the noise (peak > {OBSERVABLE_PEAK_RMS:g} x rms "
                f"residual {rms:.3g} rad) in a {span:.3g} s record, {MIN_IMPACTS[name]} needed for {why}"
            )
        elif not math.isfinite(rel) or rel > max_rel:
            if rms > 0.05 * theta0:
                cause = f"too noisy: rms residual {rms:.3g} rad is {100 * rms / theta0:.0f} % of the release tilt"
            elif n_impacts < 4:
                cause = f"too short: {n_impacts} observable impacts in a {span:.3g} s record"
            else:
                cause = (
                    f"weakly constrained: a release at {fit.release_ratio:.2f} alpha and {n_impacts} impacts above "
                    f"a noise of {rms:.3g} rad leave alpha and p correlated ({corr:.3f}); release from a larger "
                    "tilt, record longer or with less noise"
                )
            out[name] = f"95 % interval +/-{100 * rel:.3g} % of the value (limit {100 * max_rel:g} %): {cause}"
        elif x[k] <= lo[k] * (1 + 1e-9) or (math.isfinite(hi[k]) and x[k] >= hi[k] * (1 - 1e-9)):
            bound = lo[k] if x[k] <= lo[k] * (1 + 1e-9) else hi[k]
            out[name] = f"the optimum lies on the bound {bound:g} of the search: no interval"
    return out


def error_surface(
    result: Identification, alpha_range: tuple[float, float], p_range: tuple[float, float], n: int = 31
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """RMS misfit over an alpha-p grid, the other unknowns held at the optimum (the paper's
    "minimized error surface").

    Returns
    -------
    alphas, ps
        Grid axes (rad, rad/s).
    rms
        (len(ps), len(alphas)) RMS of measured minus modelled rotation, rad.
    """
    h = result.history
    alphas = np.linspace(*alpha_range, n)
    ps = np.linspace(*p_range, n)
    rms = np.empty((n, n))
    base = result.fit
    for i, p in enumerate(ps):
        for j, a in enumerate(alphas):
            ratio = min(abs(base.theta0_rad) / a, 0.999)
            fit = FreeRockingFit(a, p, base.mu, base.release_time_s, base.offset_rad, ratio, base.side)
            m = model_history(fit, float(h.t_s[0]), h.dt_s, h.t_s.size)[0]
            rms[i, j] = math.sqrt(float(np.mean((m - h.theta_rad) ** 2)))
    return alphas, ps, rms


def synthetic_measurement(
    alpha_rad: float,
    p_rad_s: float,
    mu: float,
    *,
    theta0_rad: float,
    rate_hz: float = 200.0,
    duration_s: float = 8.0,
    hold_s: float = 0.5,
    release_offset_s: float = 0.0,
    offset_rad: float = 0.0,
    noise_rad: float = 0.0,
    seed: int = 0,
    source: str = "synthetic",
) -> MeasuredHistory:
    """A free-rocking record made by Housner's solver, with a hold, an offset and white noise.

    The release happens at ``hold_s + release_offset_s`` (``release_offset_s`` lets the
    release fall between samples); the noise is Gaussian with standard deviation
    ``noise_rad`` from ``numpy.random.default_rng(seed)``.
    """
    from rockyade.analysis.measurement import measured_history

    dt = 1.0 / rate_hz
    n = round(duration_s * rate_hz) + 1
    truth = FreeRockingFit(
        alpha_rad,
        p_rad_s,
        mu,
        hold_s + release_offset_s,
        offset_rad,
        abs(theta0_rad) / alpha_rad,
        1 if theta0_rad >= 0 else -1,
    )
    theta = model_history(truth, 0.0, dt, n)[0]
    rng = np.random.default_rng(seed)
    theta = theta + noise_rad * rng.standard_normal(n)
    return measured_history(np.arange(n) * dt, theta, source)
