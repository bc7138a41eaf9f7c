"""Classical parameters alpha, p, mu identified from a measured free-rocking history.

The paper's experimental parameters (Tables 3-4, E columns) were "adjusted by means of a
minimized error surface" on free-rocking tests. rockyade does the same with Housner's exact
solution (:mod:`rockyade.housner`): the measured rotation is modelled as

    theta_m(t) = s theta_H(t - t_r; alpha, p, mu, r alpha) + o        (t >= t_r)
    theta_m(t) = s r alpha + o                                        (t <  t_r, the hold)

with theta_H the free rocking of a symmetric block released at rest from the tilt
theta_0 = r alpha (paper Eq 1, base at rest, omega multiplied by mu at each impact), s the
side it was tilted to, t_r the release time and o the sensor offset. The six unknowns
(alpha, p, mu, t_r, o, r) minimise the sum of squared differences over every sample
(scipy's trust-region least squares). The model is evaluated at the measurement times
exactly: the solver is advanced from the release to the first sample after it, then sampled
on the measurement grid.

Starting point: :func:`rockyade.identification.start.initial_guess` (peaks, zero crossings
and exact Housner periods). The model: :mod:`rockyade.identification.forward_model`.

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

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import optimize, stats
from threadpoolctl import threadpool_limits

from rockyade.errors import InputError
from rockyade.identification.forward_model import (
    FIT_PARAMETERS,
    FreeRockingFit,
    IdentificationError,
    model_history,
    synthetic_measurement,
)
from rockyade.identification.measurement import MeasuredHistory
from rockyade.identification.start import Guess, initial_guess

__all__ = [
    "CLASSICAL",
    "FIT_PARAMETERS",
    "FreeRockingFit",
    "Guess",
    "Identification",
    "IdentificationError",
    "error_surface",
    "identify",
    "initial_guess",
    "model_history",
    "synthetic_measurement",
]

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
        """An identified value, or None when it is unidentifiable.

        Parameters
        ----------
        name
            ``alpha_rad`` (rad), ``p_rad_s`` (1/s), ``mu`` (-), ``release_time_s`` (s),
            ``offset_rad`` (rad) or ``release_ratio`` (-).
        """
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
        The measured rotation (:func:`rockyade.identification.measurement.read_measurement`).
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
    # one BLAS thread: the trust-region steps take the SVD of the n x 6 Jacobian (n samples),
    # which OpenBLAS threads from about 4000 rows, where the threads only add synchronisation
    # (loaded 2-core machine: an SVD of 8001 x 6 took 15.8 ms CPU, 32 ms wall, against 1.0 ms)
    with threadpool_limits(limits=1, user_api="blas"):
        return _fit(history, max_relative_ci, guess)


def _fit(history: MeasuredHistory, max_relative_ci: float, guess: Guess) -> Identification:
    """:func:`identify` from its starting point."""
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
                "for the amplitude dependence of the period that separates alpha from p"
                if name != "mu"
                else "to measure the energy an impact takes away"
            )
            out[name] = (
                f"too few impacts: {n_impacts} observable above the noise (peak > {OBSERVABLE_PEAK_RMS:g} x rms "
                f"residual {rms:.3g} rad) in a {span:.3g} s record, {MIN_IMPACTS[name]} needed {why}"
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

    Parameters
    ----------
    result
        An identification (its history and optimum).
    alpha_range, p_range
        Grid bounds of alpha (rad) and p (1/s).
    n
        Grid points along each axis.

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
