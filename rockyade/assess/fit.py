"""The lognormal fragility of stripes, and how sure it is.

* Per stripe: runs, failed runs, collapses, the fraction and its 95 % Wilson interval
  (:func:`rockyade.probability.fragility.wilson_interval`). Failed runs are left out of
  every count and probability (and counted).
* The curve P(collapse | IM = x) = Phi(ln(x / theta) / beta), by maximum likelihood on the
  stripes (Baker 2015, :func:`rockyade.probability.fragility.fit_lognormal`).
* Its band: the records are the sample, so they are resampled (a record keeps its outcomes
  at every level: a nonparametric bootstrap over records, ``BOOTSTRAP_DRAWS`` draws with a
  fixed seed); each draw is fitted again; the band is
  the pointwise 5 %-95 % range of the fitted curves, and the medians' and betas' 5 %-95 %
  ranges are their intervals. Draws whose fit has no slope (separated stripes, no trend)
  give no curve and are counted.
* How few records is too few: below :data:`MIN_RECORDS` (5) records the fit is refused (a
  lognormal median from so few records cannot be bounded: the bootstrap over records has
  only a handful of distinct resamples); below :data:`FEW_RECORDS` (10) it is fitted with a
  warning. A bootstrap band whose end is the median itself says why (a share of the draws
  that give back exactly the median: the band does not measure the uncertainty on that side).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray
from scipy import special, stats

from rockyade.probability.fragility import MAX_BETA, MIN_BETA, Fragility, fit_lognormal, wilson_interval

#: Bootstrap draws, their seed and the band's two-sided level.
BOOTSTRAP_DRAWS = 300
BOOTSTRAP_SEED = 20240611
BAND_LEVEL = 0.90
#: Two-sided level of the stripes' Wilson intervals.
STRIPE_LEVEL = 0.95
#: Fewest records a fit is made on, and the number below which it carries a warning.
MIN_RECORDS = 5
FEW_RECORDS = 10


def stripe_table(runs: pd.DataFrame, level_column: str) -> pd.DataFrame:
    """Per level: ``n_runs`` (that did not fail), ``n_failed``, ``n_collapse``, ``fraction``
    and its Wilson interval ``fraction_lo``, ``fraction_hi`` (95 %).

    Parameters
    ----------
    runs
        One row per run: ``level_column`` (the level, SI), ``status``, ``collapsed``.
    level_column
        The column of the level.
    """
    rows = []
    for level, group in runs.groupby(level_column, sort=True):
        done = group[group["status"] != "failed"]
        n, k = len(done), int(done["collapsed"].astype(bool).sum())
        lo, hi = wilson_interval(k, n, STRIPE_LEVEL) if n else (math.nan, math.nan)
        rows.append(
            {
                level_column: float(level),
                "n_runs": n,
                "n_failed": len(group) - n,
                "n_collapse": k,
                "fraction": k / n if n else math.nan,
                "fraction_lo": lo,
                "fraction_hi": hi,
            }
        )
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class StripeFit:
    """A fitted fragility with its bootstrap band (module docstring).

    Attributes
    ----------
    fragility
        The maximum-likelihood fit on all records (median in SI).
    levels_si
        The levels tested, SI.
    median_interval_si, beta_interval
        5 %-95 % of the bootstrap's medians (SI) and betas (NaN without enough draws).
    grid_si, band_lo, band_hi
        The band of the curve: intensities (SI) and the 5 % and 95 % probabilities there.
    draws, fitted_draws
        Bootstrap draws, and those that gave a curve.
    notes
        Warnings on the fit (few records, a band ending at the median), in words.
    """

    fragility: Fragility
    levels_si: tuple[float, ...]
    median_interval_si: tuple[float, float]
    beta_interval: tuple[float, float]
    grid_si: NDArray[np.float64]
    band_lo: NDArray[np.float64]
    band_hi: NDArray[np.float64]
    draws: int
    fitted_draws: int
    notes: tuple[str, ...] = ()

    @property
    def fitted(self) -> bool:
        """True when the curve has a median and a slope."""
        return self.fragility.status == "fitted"

    @property
    def extrapolated(self) -> bool:
        """True when the median lies outside the tested levels (the curve is not tested there)."""
        m = self.fragility.median
        return bool(self.levels_si) and math.isfinite(m) and not min(self.levels_si) <= m <= max(self.levels_si)

    def to_dict(self, scale: float, unit: str) -> dict[str, Any]:
        """JSON-ready, intensities in SI and divided by ``scale`` (in ``unit``)."""
        f = self.fragility
        shown = f"_{unit.replace('/', '_')}"
        return {
            "status": f.status,
            f"median{shown}": f.median / scale,
            "median_si": f.median,
            "beta": f.beta,
            f"median_interval{shown}": [v / scale for v in self.median_interval_si],
            "beta_interval": list(self.beta_interval),
            "interval_level": BAND_LEVEL,
            "interval_method": f"bootstrap over records, {self.draws} draws (seed {BOOTSTRAP_SEED}), "
            f"{self.fitted_draws} with a fitted curve",
            "extrapolated": self.extrapolated,
            "fraction": f.fraction,
            "stripes": f.n_points,
            "method": "maximum likelihood on the stripes (Baker 2015)",
            "notes": list(self.notes),
        }


def _outcomes(runs: pd.DataFrame, level_column: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(levels, records x levels matrix: 1 collapse, 0 not, NaN failed or not run)."""
    levels = np.array(sorted(runs[level_column].unique()), dtype=float)
    records = sorted(runs["record_index"].unique())
    where = {r: k for k, r in enumerate(records)}
    matrix = np.full((len(records), levels.size), np.nan)
    done = runs[runs["status"] != "failed"]
    for r, level, c in zip(done["record_index"], done[level_column], done["collapsed"], strict=True):
        matrix[where[r], int(np.searchsorted(levels, level))] = float(bool(c))
    return levels, matrix


def _counts(
    levels: NDArray[np.float64], matrix: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]] | None:
    """(levels, collapses, runs) of the stripes that have runs; None with fewer than two."""
    n = np.sum(np.isfinite(matrix), axis=0).astype(float)
    k = np.nansum(matrix, axis=0)
    keep = n > 0
    if keep.sum() < 2:
        return None
    return levels[keep], k[keep], n[keep]


def _fit(levels: NDArray[np.float64], matrix: NDArray[np.float64]) -> Fragility | None:
    counts = _counts(levels, matrix)
    return None if counts is None else fit_lognormal(*counts)


def _nll_and_gradient(
    params: NDArray[np.float64], logx: NDArray[np.float64], k: NDArray[np.float64], n: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]]:
    """The binomial negative log-likelihood of :func:`~rockyade.probability.fragility.fit_lognormal`
    in (mu = ln median, s = ln beta), and its gradient."""
    mu, log_beta = params
    beta = math.exp(log_beta)
    z = (logx - mu) / beta
    log_p, log_q = special.log_ndtr(z), special.log_ndtr(-z)
    log_phi = -0.5 * z * z - 0.5 * math.log(2.0 * math.pi)
    value = -float(np.sum(k * log_p + (n - k) * log_q))
    # phi / Phi and phi / (1 - Phi), the inverse Mills ratios, in logs: finite for any z
    dz = -(k * np.exp(log_phi - log_p) - (n - k) * np.exp(log_phi - log_q))  # d nll / d z
    return value, np.array([float(np.sum(dz)) * (-1.0 / beta), float(np.sum(dz * -z))])


def refit(
    x: NDArray[np.float64], k: NDArray[np.float64], n: NDArray[np.float64], start: tuple[float, float]
) -> tuple[float, float] | None:
    """(median, beta) of :func:`~rockyade.probability.fragility.fit_lognormal` (the same binomial
    likelihood, the same answer), found fast: Newton steps from ``start`` = (median, beta), the
    Hessian from central differences of the analytic gradient, each step at most 1 in
    (ln median, ln beta) and halved until the likelihood grows. A bootstrap draw starts from
    the full fit, and this takes a fraction of a millisecond; where Newton does not settle
    inside the fit's bounds, :func:`fit_lognormal` itself answers. None where the fit has no
    slope (no collapse, all collapse, separated stripes, no trend).
    """
    if k.sum() == 0 or np.all(k == n) or np.max(x[k < n]) <= np.min(x[k > 0]):
        return None
    quick = _newton(np.log(x), k, n, start)
    if quick is not None:
        return quick
    full = fit_lognormal(x, k, n)
    return (full.median, full.beta) if full.status == "fitted" else None


def _newton(
    logx: NDArray[np.float64], k: NDArray[np.float64], n: NDArray[np.float64], start: tuple[float, float]
) -> tuple[float, float] | None:
    """The maximum by Newton steps (:func:`refit`), or None when it does not settle inside the bounds."""
    lo = np.array([float(logx.min()) - 5.0, math.log(MIN_BETA)])
    hi = np.array([float(logx.max()) + 5.0, math.log(MAX_BETA)])
    p = np.clip([math.log(start[0]), math.log(start[1])], lo + 1e-3, hi - 1e-3)
    value, grad = _nll_and_gradient(p, logx, k, n)
    h = 1e-5
    for _ in range(100):
        hess = np.empty((2, 2))
        for j in range(2):
            e = np.zeros(2)
            e[j] = h
            hess[:, j] = (_nll_and_gradient(p + e, logx, k, n)[1] - _nll_and_gradient(p - e, logx, k, n)[1]) / (2 * h)
        try:
            step = -np.linalg.solve(0.5 * (hess + hess.T), grad)
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(step)) or float(step @ grad) >= 0.0:
            step = -grad  # not a descent direction: steepest descent
        step *= min(1.0, 1.0 / max(float(np.max(np.abs(step))), 1e-300))
        for _halving in range(60):
            trial = p + step
            if np.all(trial > lo) and np.all(trial < hi):
                t_value, t_grad = _nll_and_gradient(trial, logx, k, n)
                if t_value <= value:
                    break
            step *= 0.5
        else:
            return None
        p, value, grad = trial, t_value, t_grad
        if np.max(np.abs(step)) < 1e-10:
            edge = np.minimum(p - lo, hi - p)
            return None if np.any(edge < 1e-6) else (math.exp(p[0]), math.exp(p[1]))
    return None


def fit_stripes(
    runs: pd.DataFrame,
    level_column: str,
    grid_si: NDArray[np.float64] | None = None,
    draws: int = BOOTSTRAP_DRAWS,
    seed: int = BOOTSTRAP_SEED,
) -> StripeFit:
    """The fit and its band (module docstring).

    Parameters
    ----------
    runs
        One row per run: ``record_index``, ``level_column`` (SI), ``status``, ``collapsed``.
    level_column
        The column of the level.
    grid_si
        Intensities of the band (default: 200 from 0 to twice the largest level).
    draws, seed
        The bootstrap.
    """
    levels, matrix = _outcomes(runs, level_column)
    n_records = matrix.shape[0]
    notes: list[str] = []
    if n_records < MIN_RECORDS:
        best: Fragility | None = Fragility(
            math.nan,
            math.nan,
            int(levels.size),
            f"not fitted: {n_records} records, fewer than {MIN_RECORDS}: a lognormal median from so few records "
            "cannot be bounded (run more records)",
        )
    else:
        best = _fit(levels, matrix)
        if n_records < FEW_RECORDS:
            notes.append(
                f"fitted on {n_records} records, fewer than {FEW_RECORDS}: the median and beta are rough and the "
                "bootstrap band is wide or uninformative (run more records)"
            )
    if best is None:
        best = Fragility(math.nan, math.nan, int(levels.size), "not fitted: fewer than two stripes with runs")
    grid = np.linspace(0.0, 2.0 * float(levels.max()), 201)[1:] if grid_si is None else np.asarray(grid_si)
    rng = np.random.default_rng(seed)
    medians, betas, curves = [], [], []
    for _ in range(draws if best.status == "fitted" else 0):
        counts = _counts(levels, matrix[rng.integers(0, n_records, n_records)])
        fit = None if counts is None else refit(*counts, (best.median, best.beta))
        if fit is None:
            continue
        medians.append(fit[0])
        betas.append(fit[1])
        curves.append(stats.norm.cdf(np.log(grid / fit[0]) / fit[1]))
    tail = 50.0 * (1.0 - BAND_LEVEL)
    if len(curves) >= max(10, draws // 2):
        band = np.percentile(np.array(curves), [tail, 100.0 - tail], axis=0)
        m_int = tuple(float(v) for v in np.percentile(medians, [tail, 100.0 - tail]))
        b_int = tuple(float(v) for v in np.percentile(betas, [tail, 100.0 - tail]))
        same = float(np.mean(np.abs(np.array(medians) / best.median - 1.0) <= 1e-6))
        for end, side in ((m_int[0], "lower"), (m_int[1], "upper")):
            if abs(end / best.median - 1.0) <= 1e-6:
                notes.append(
                    f"the band's {side} end is the median itself: {100 * same:.0f} % of the bootstrap draws give back "
                    "exactly the fitted median (resampled records that change no stripe around it), so the band "
                    f"does not measure the uncertainty on its {side} side"
                )
    else:  # too few draws with a curve: no band rather than a band of a few
        band = np.full((2, grid.size), np.nan)
        m_int, b_int = (math.nan, math.nan), (math.nan, math.nan)
    return StripeFit(
        best,
        tuple(float(v) for v in levels),
        (m_int[0], m_int[1]),
        (b_int[0], b_int[1]),
        grid,
        band[0],
        band[1],
        draws if best.status == "fitted" else 0,
        len(curves),
        tuple(notes),
    )
