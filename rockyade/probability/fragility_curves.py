"""Collapse fragility: lognormal curves fitted by maximum likelihood, against any intensity measure.

P(collapse | IM = x) = Phi(ln(x / theta) / beta), fitted to grouped outcomes (n_i collapses
out of N_i records at intensity x_i, a multiple-stripe analysis) by maximising the binomial
likelihood sum_i [n_i ln p_i + (N_i - n_i) ln(1 - p_i)] (Baker 2015, "Efficient analytical
fragility function fitting using dynamic structural analysis", Earthquake Spectra 31) by
Newton steps on its analytic gradient and Hessian (:func:`fit_lognormal`, the one fit of the
package: the paper study, ``rockyade fragility``, ``assess``, ``uncertainty`` and the
bootstrap of :mod:`rockyade.assess.stripe_fit`, which starts each draw from the full fit).

When every run has its own intensity (PGV, Arias intensity, a/(g tan alpha) ... differ
from record to record at one load factor) each run is its own stripe of one: the
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
from scipy import optimize, special

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
            return special.ndtr(np.log(np.maximum(x, 1e-300) / self.median) / self.beta)  # the normal's CDF


def fit_lognormal(
    im: ArrayLike, n_collapse: ArrayLike, n_total: ArrayLike, start: tuple[float, float] | None = None
) -> Fragility:
    """Maximum-likelihood lognormal fragility from grouped outcomes.

    The binomial likelihood (module docstring) in (mu, s) = (ln median, ln beta), written with
    log Phi (:func:`scipy.special.log_ndtr`: finite however far a stripe lies in a tail), is
    maximised by Newton steps with its analytic gradient and Hessian (:func:`nll_and_derivatives`),
    each step at most 1 in (mu, s) and halved until the likelihood grows, inside the bounds
    mu in [ln min(im) - 5, ln max(im) + 5] and beta in [:data:`MIN_BETA`, :data:`MAX_BETA`];
    where Newton does not settle inside them, a bounded quasi-Newton search (L-BFGS-B, the same
    gradient) finds the bounded maximum, and a maximum on a bound is "no trend".

    Parameters
    ----------
    im
        Intensity of each stripe (> 0).
    n_collapse, n_total
        Collapses and records at each stripe.
    start
        (median, beta) to start from (a bootstrap draw starts from the full fit; the answer is
        the same maximum); default: the intensity where the running maximum of the collapse
        fractions crosses 1/2, and beta = 0.4.

    Returns
    -------
    Fragility
        ``status`` "fitted", or (without a finite maximum, decided before any search) "no
        collapse", "all collapse", "separated"; or "no trend" (the maximum on the bounds).
    """
    x = np.asarray(im, dtype=float)
    k = np.asarray(n_collapse, dtype=float)
    n = np.asarray(n_total, dtype=float)
    if not (x.shape == k.shape == n.shape) or x.ndim != 1 or x.size < 2:
        raise InputError("im", "needs at least two stripes with matching collapse counts")
    if np.any(x <= 0) or np.any(k < 0) or np.any(k > n) or np.any(n <= 0):
        raise InputError("im", "intensities must be > 0 and 0 <= collapses <= records")
    unbounded = separation(x, k, n)
    if unbounded is not None:
        return unbounded
    logx = np.log(x)
    lo = np.array([float(logx.min()) - 5.0, math.log(MIN_BETA)])
    hi = np.array([float(logx.max()) + 5.0, math.log(MAX_BETA)])
    if start is None:
        frac = k / n
        order = np.argsort(logx)
        cum = np.maximum.accumulate(frac[order])
        mu0 = float(np.interp(0.5, cum, logx[order])) if frac.max() >= 0.5 else float(logx.max())
        p0 = np.array([mu0, math.log(0.4)])
    else:
        p0 = np.array([math.log(start[0]), math.log(start[1])])
    p0 = np.clip(p0, lo + 1e-3, hi - 1e-3)
    best = _newton(p0, logx, k, n, lo, hi)
    if best is None:  # the maximum lies on (or beyond) a bound: find it there
        found = optimize.minimize(
            lambda p: nll_and_derivatives(p, logx, k, n)[:2],
            p0,
            jac=True,
            method="L-BFGS-B",
            bounds=list(zip(lo, hi, strict=True)),
            options={"ftol": 1e-14, "gtol": 1e-10, "maxiter": 1000},
        )
        best = np.asarray(found.x, dtype=float)
        edge = np.minimum(best - lo, hi - best)
        if np.any(edge < 1e-6 * np.maximum(1.0, np.abs(best))) and best[1] > lo[1] + 1e-6:
            return Fragility(math.nan, math.nan, int(x.size), "no trend", float(k.sum() / n.sum()))
    return Fragility(float(math.exp(best[0])), float(math.exp(best[1])), int(x.size))


def separation(x: np.ndarray, k: np.ndarray, n: np.ndarray) -> Fragility | None:
    """The answer where the likelihood has no finite maximum, else None.

    "no collapse" (median +inf), "all collapse" (median 0), or "separated" when no run
    collapses below the intensity of a run that does not (quasi-complete separation: the
    likelihood grows without bound as beta -> 0; the median is the geometric mean of the
    highest intensity with a survivor and the lowest with a collapse, beta NaN).

    Parameters
    ----------
    x, k, n
        Intensities (> 0), collapses and runs of the stripes.
    """
    if k.sum() == 0:
        return Fragility(math.inf, math.nan, int(x.size), "no collapse")
    if np.all(k == n):
        return Fragility(0.0, math.nan, int(x.size), "all collapse")
    top_survivor = float(np.max(x[k < n]))
    lowest_collapse = float(np.min(x[k > 0]))
    if top_survivor <= lowest_collapse:
        return Fragility(math.sqrt(top_survivor * lowest_collapse), math.nan, int(x.size), "separated")
    return None


def nll_and_derivatives(
    params: ArrayLike, logx: np.ndarray, k: np.ndarray, n: np.ndarray
) -> tuple[float, np.ndarray, np.ndarray]:
    """The binomial negative log-likelihood of :func:`fit_lognormal` in (mu, s) = (ln median,
    ln beta), its gradient and its Hessian, analytic.

    With z = (ln x - mu) / beta, l1 = phi(z) / Phi(z) and l2 = phi(z) / Phi(-z) (the inverse
    Mills ratios, from log Phi: finite for any z), the terms' derivatives in z are
    g = -(k l1 - (n - k) l2) and h = k (z l1 + l1^2) + (n - k) (l2^2 - z l2); then
    dz/dmu = -1/beta and dz/ds = -z give
    d/dmu = -sum g / beta, d/ds = -sum g z, d2/dmu2 = sum h / beta^2,
    d2/dmu ds = sum (h z + g) / beta, d2/ds2 = sum (h z^2 + g z).

    Parameters
    ----------
    params
        (mu, s).
    logx, k, n
        ln intensities, collapses and runs of the stripes.
    """
    mu, log_beta = (float(v) for v in np.asarray(params, dtype=float))
    beta = math.exp(log_beta)
    z = (logx - mu) / beta
    log_p, log_q = special.log_ndtr(z), special.log_ndtr(-z)
    log_phi = -0.5 * z * z - 0.5 * math.log(2.0 * math.pi)
    value = -float(np.sum(k * log_p + (n - k) * log_q))
    l1, l2 = np.exp(log_phi - log_p), np.exp(log_phi - log_q)
    g = -(k * l1 - (n - k) * l2)
    h = k * (z * l1 + l1 * l1) + (n - k) * (l2 * l2 - z * l2)
    grad = np.array([-float(np.sum(g)) / beta, -float(np.sum(g * z))])
    hmm = float(np.sum(h)) / beta**2
    hms = float(np.sum(h * z + g)) / beta
    hss = float(np.sum(h * z * z + g * z))
    return value, grad, np.array([[hmm, hms], [hms, hss]])


def _newton(
    p: np.ndarray, logx: np.ndarray, k: np.ndarray, n: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> np.ndarray | None:
    """The maximum of :func:`fit_lognormal` by damped Newton steps from ``p``; None when it
    does not settle strictly inside the bounds (lo, hi)."""
    value, grad, hess = nll_and_derivatives(p, logx, k, n)
    for _ in range(200):
        try:
            step = -np.linalg.solve(hess, grad)
        except np.linalg.LinAlgError:
            step = -grad
        if not np.all(np.isfinite(step)) or float(step @ grad) >= 0.0:
            step = -grad  # the Hessian is not positive definite here: steepest descent
        step = step * min(1.0, 1.0 / max(float(np.max(np.abs(step))), 1e-300))
        for _halving in range(60):
            trial = p + step
            if np.all(trial > lo) and np.all(trial < hi):
                t_value, t_grad, t_hess = nll_and_derivatives(trial, logx, k, n)
                if t_value <= value:
                    break
            step = step * 0.5
        else:
            return None
        p, value, grad, hess = trial, t_value, t_grad, t_hess
        if float(np.max(np.abs(step))) < 1e-12 or float(np.max(np.abs(grad))) < 1e-12 * max(1.0, float(k.sum())):
            edge = np.minimum(p - lo, hi - p)
            return None if np.any(edge < 1e-6) else p
    return None


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


def _check_counts(k: int, n: int) -> None:
    """Refuse counts that are not a binomial sample: needs 0 <= k <= n and n > 0."""
    if n <= 0 or k < 0 or k > n:
        raise InputError("n", f"needs 0 <= k <= n and n > 0, got k = {k}, n = {n}")


def wilson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion k / n (Wilson 1927).

    Parameters
    ----------
    k, n
        Successes and trials (n > 0).
    confidence
        Two-sided level.
    """
    _check_counts(k, n)
    z = float(special.ndtri(0.5 + confidence / 2.0))  # the normal's quantile
    phat = k / n
    den = 1.0 + z * z / n
    centre = (phat + z * z / (2 * n)) / den
    half = z * math.sqrt(phat * (1 - phat) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


def clopper_pearson_interval(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper & Pearson 1934) interval of a binomial proportion k / n; parameters as
    :func:`wilson_interval`."""
    # scipy.stats here, not with the module: its import costs some 0.7 s of CPU, which every
    # fragility and assess command paid at start-up for the normal distribution alone
    # (scipy.special's ndtr and ndtri, the functions scipy.stats.norm itself calls)
    from scipy import stats

    _check_counts(k, n)
    a = 1.0 - confidence
    lo = 0.0 if k == 0 else float(stats.beta.ppf(a / 2, k, n - k + 1))
    hi = 1.0 if k == n else float(stats.beta.ppf(1 - a / 2, k + 1, n - k))
    return lo, hi
