"""The lognormal fragility of stripes, and how sure it is.

* Per stripe: runs, failed runs, collapses, the fraction and its 95 % Wilson interval
  (:func:`rockyade.probability.fragility_curves.wilson_interval`). Failed runs are left out of
  every count and probability (and counted).
* The curve P(collapse | IM = x) = Phi(ln(x / theta) / beta), by maximum likelihood on the
  stripes (Baker 2015, :func:`rockyade.probability.fragility_curves.fit_lognormal`).
* Its band: the records are the sample, so they are resampled (a record keeps its outcomes
  at every level: a nonparametric bootstrap over records, ``BOOTSTRAP_DRAWS`` draws with a
  fixed seed); each draw is fitted again (the same fit, started from the full one); the band is
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

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from rockyade.probability.fragility_curves import Fragility, fit_lognormal, wilson_interval

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

    def to_dict(self, scale: float, unit: str) -> dict[str, object]:
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
        # the same fit, started from the full one: the same maximum, found in a few Newton steps
        draw = None if counts is None else fit_lognormal(*counts, start=(best.median, best.beta))
        if draw is None or draw.status != "fitted":
            continue
        medians.append(draw.median)
        betas.append(draw.beta)
        curves.append(draw.probability(grid))
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
