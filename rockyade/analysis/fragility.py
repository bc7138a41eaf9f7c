"""Collapse fragility: lognormal curves fitted by maximum likelihood.

P(collapse | IM = x) = Phi(ln(x / theta) / beta), fitted to grouped outcomes (n_i collapses
out of N_i records at intensity x_i, a multiple-stripe analysis) by maximising the binomial
likelihood sum_i [n_i ln p_i + (N_i - n_i) ln(1 - p_i)] (Baker 2015) with scipy.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize, stats

from rockyade.errors import InputError


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
        "fitted", or why not ("no collapse", "all collapse").
    """

    median: float
    beta: float
    n_points: int
    status: str = "fitted"

    def probability(self, im: ArrayLike) -> np.ndarray:
        """P(collapse) at intensities ``im``."""
        x = np.asarray(im, dtype=float)
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
    logx = np.log(x)

    def nll(params: np.ndarray) -> float:
        mu, log_beta = params
        p = stats.norm.cdf((logx - mu) / math.exp(log_beta))
        p = np.clip(p, 1e-12, 1 - 1e-12)
        return -float(np.sum(k * np.log(p) + (n - k) * np.log(1 - p)))

    frac = k / n
    start_mu = float(np.interp(0.5, np.maximum.accumulate(frac), logx)) if frac.max() >= 0.5 else float(logx.max())
    best = optimize.minimize(
        nll, [start_mu, math.log(0.4)], method="Nelder-Mead", options={"xatol": 1e-8, "fatol": 1e-10, "maxiter": 4000}
    )
    mu, log_beta = best.x
    return Fragility(float(math.exp(mu)), float(math.exp(log_beta)), int(x.size))
