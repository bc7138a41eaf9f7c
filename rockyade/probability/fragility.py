"""Collapse fragility: lognormal curves fitted by maximum likelihood, against any intensity measure.

P(collapse | IM = x) = Phi(ln(x / theta) / beta), fitted to grouped outcomes (n_i collapses
out of N_i records at intensity x_i, a multiple-stripe analysis) by maximising the binomial
likelihood sum_i [n_i ln p_i + (N_i - n_i) ln(1 - p_i)] (Baker 2015, "Efficient analytical
fragility function fitting using dynamic structural analysis", Earthquake Spectra 31) with
scipy. When every run has its own intensity (PGV, Arias intensity, a/(g tan alpha) ...
differ from record to record at one load factor) each run is its own stripe of one: the
same likelihood over individual outcomes (Shinozuka et al. 2000, "Statistical analysis of
fragility curves", J. Eng. Mech. 126), :func:`fit_lognormal_points`. The measures are those
of :mod:`rockyade.motion.intensity`.

Probabilities estimated from n runs carry binomial confidence bands: Wilson's score interval
and the exact Clopper-Pearson one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize, stats

from rockyade.errors import InputError

#: Range of the fitted dispersion beta (log-standard deviation): below it the stripes are
#: separated in all but name, above it the curve says nothing.
MIN_BETA, MAX_BETA = 1e-3, 10.0


@dataclass(frozen=True)
class Fragility:
    """A fitted lognormal fragility curve.

    Attributes
    ----------
    median
        theta: intensity with 50 % probability of collapse (units of the IM).
    beta
        Logarithmic standard deviation.
    n_points
        Stripes used.
    status
        "fitted", or why not: "no collapse", "all collapse", or "separated" when no run
        collapses below the intensity of a run that does not (the likelihood then grows
        without bound as beta -> 0: the data fix a threshold, ``median``, not a slope;
        ``beta`` is NaN), or "no trend" when the likelihood's maximum lies on the bounds of
        the fit (beta beyond ``MAX_BETA`` or the median far outside the tested intensities:
        collapses do not grow with the intensity; ``median`` and ``beta`` are NaN and the
        probability is the overall fraction of collapses, ``fraction``).
    fraction
        Collapses over runs, all stripes together.
    """

    median: float
    beta: float
    n_points: int
    status: str = "fitted"
    fraction: float = math.nan

    def probability(self, im: ArrayLike) -> np.ndarray:
        """P(collapse) at intensities ``im``.

        Parameters
        ----------
        im
            Intensity-measure values, in the measure's units (e.g. m/s^2 for PGA).
        """
        x = np.asarray(im, dtype=float)
        if self.status == "separated":
            return (x > self.median).astype(float)
        if self.status == "no trend":
            return np.full(x.shape, self.fraction)
        if self.status != "fitted":
            return np.full(x.shape, 0.0 if self.status == "no collapse" else 1.0)
        with np.errstate(divide="ignore"):
            return stats.norm.cdf(np.log(np.maximum(x, 1e-300) / self.median) / self.beta)


def fit_lognormal(im: ArrayLike, n_collapse: ArrayLike, n_total: ArrayLike) -> Fragility:
    """Maximum-likelihood lognormal fragility from grouped outcomes.

    Parameters
    ----------
    im
        Intensity of each stripe (> 0).
    n_collapse, n_total
        Collapses and records at each stripe.
    """
    x = np.asarray(im, dtype=float)
    k = np.asarray(n_collapse, dtype=float)
    n = np.asarray(n_total, dtype=float)
    if not (x.shape == k.shape == n.shape) or x.size < 2:
        raise InputError("im", "needs at least two stripes with matching collapse counts")
    if np.any(x <= 0) or np.any(k < 0) or np.any(k > n) or np.any(n <= 0):
        raise InputError("im", "intensities must be > 0 and 0 <= collapses <= records")
    if k.sum() == 0:
        return Fragility(math.inf, math.nan, int(x.size), "no collapse")
    if np.all(k == n):
        return Fragility(0.0, math.nan, int(x.size), "all collapse")
    top_survivor = float(np.max(x[k < n]))
    lowest_collapse = float(np.min(x[k > 0]))
    if top_survivor <= lowest_collapse:  # (quasi-)complete separation: no finite maximum
        return Fragility(math.sqrt(top_survivor * lowest_collapse), math.nan, int(x.size), "separated")
    logx = np.log(x)

    def nll(params: np.ndarray) -> float:
        mu, log_beta = params
        p = stats.norm.cdf((logx - mu) / math.exp(log_beta))
        p = np.clip(p, 1e-12, 1 - 1e-12)
        return -float(np.sum(k * np.log(p) + (n - k) * np.log(1 - p)))

    frac = k / n
    order = np.argsort(logx)
    cum = np.maximum.accumulate(frac[order])
    start_mu = float(np.interp(0.5, cum, logx[order])) if frac.max() >= 0.5 else float(logx.max())
    # bounded: a nearly separated sample drives beta to 0 or the median far out (exp overflows)
    bounds = [(float(logx.min()) - 5.0, float(logx.max()) + 5.0), (math.log(MIN_BETA), math.log(MAX_BETA))]
    best = optimize.minimize(
        nll,
        [start_mu, math.log(0.4)],
        method="Nelder-Mead",
        bounds=bounds,
        options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000},
    )
    mu, log_beta = best.x
    at_bound = any(min(v - lo, hi - v) < 1e-6 * max(1.0, abs(v)) for v, (lo, hi) in zip(best.x, bounds, strict=True))
    if at_bound and log_beta > math.log(MIN_BETA) + 1e-6:
        return Fragility(math.nan, math.nan, int(x.size), "no trend", float(k.sum() / n.sum()))
    return Fragility(float(math.exp(mu)), float(math.exp(log_beta)), int(x.size))


def fit_lognormal_points(im: ArrayLike, collapsed: ArrayLike) -> Fragility:
    """Maximum-likelihood lognormal fragility from individual runs (intensity, collapsed or not).

    Runs at equal intensity are grouped into stripes first, so that stripes and points give
    the same fit (:func:`fit_lognormal`).

    Parameters
    ----------
    im
        Intensity of each run (> 0; NaN runs are dropped).
    collapsed
        True where the run collapsed (overturned).
    """
    x = np.asarray(im, dtype=float)
    c = np.asarray(collapsed, dtype=bool)
    if x.shape != c.shape:
        raise InputError("im", "needs one collapse flag per intensity")
    keep = np.isfinite(x)
    x, c = x[keep], c[keep]
    if np.any(x <= 0):
        raise InputError("im", "intensities must be > 0")
    levels, inverse = np.unique(x, return_inverse=True)
    if levels.size < 2:
        raise InputError("im", f"needs runs at two intensities or more, got {levels.size}")
    n_total = np.bincount(inverse).astype(float)
    n_collapse = np.bincount(inverse, weights=c.astype(float))
    return fit_lognormal(levels, n_collapse, n_total)


def wilson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion k / n (Wilson 1927).

    Parameters
    ----------
    k, n
        Successes and trials (n > 0).
    confidence
        Two-sided level.
    """
    if n <= 0 or k < 0 or k > n:
        raise InputError("n", f"needs 0 <= k <= n and n > 0, got k = {k}, n = {n}")
    z = float(stats.norm.ppf(0.5 + confidence / 2.0))
    phat = k / n
    den = 1.0 + z * z / n
    centre = (phat + z * z / (2 * n)) / den
    half = z * math.sqrt(phat * (1 - phat) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


def clopper_pearson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper & Pearson 1934) interval of a binomial proportion k / n.

    Parameters
    ----------
    k, n
        Successes and trials (n > 0).
    confidence
        Two-sided level.
    """
    if n <= 0 or k < 0 or k > n:
        raise InputError("n", f"needs 0 <= k <= n and n > 0, got k = {k}, n = {n}")
    a = 1.0 - confidence
    lo = 0.0 if k == 0 else float(stats.beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(stats.beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi
