"""Probabilities of overturning and of exceeding theta/alpha levels from many runs, with
binomial confidence bands; fragility fits against intensity measures; the spread that the
classical parameters alone cause.

Input: one row per run with ``solver``, ``load_factor``, ``status`` (completed, overturned,
failed), ``max_theta_over_alpha`` and, for the spread, ``sample``, ``nominal`` and
``record`` (the runs table of :mod:`rockyade.studies.uncertainty`). Failed runs are
counted and left out of every probability. An overturned run exceeds every level.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np
import pandas as pd

from rockyade.probability.fragility_curves import fit_lognormal_points, wilson_interval

#: Peak theta/alpha above which a run counts as rocking (for the spread factor).
ROCKING_RATIO = 0.01


def level_column(level: float) -> str:
    """Column name of P(max theta/alpha >= level), e.g. ``p_theta_alpha_ge_0.5``.

    Parameters
    ----------
    level
        The level of theta/alpha (-).
    """
    return f"p_theta_alpha_ge_{level:g}"


def _exceeds(frame: pd.DataFrame, level: float) -> np.ndarray:
    ratio = frame["max_theta_over_alpha"].to_numpy(dtype=float)
    return (frame["status"].to_numpy() == "overturned") | (np.nan_to_num(ratio, nan=-1.0) >= level)


def exceedance_table(runs: pd.DataFrame, levels: Iterable[float], confidence: float = 0.95) -> pd.DataFrame:
    """Per solver and load factor: runs, failures, P(overturn) and P(theta/alpha >= level),
    each with its Wilson interval (``_lo``, ``_hi``).

    Parameters
    ----------
    runs
        One row per run (module docstring): ``solver``, ``load_factor``, ``status``,
        ``max_theta_over_alpha`` (-).
    levels
        Levels of theta/alpha (-), one probability column each (:func:`level_column`).
    confidence
        Two-sided level of the intervals.
    """
    rows = []
    for (solver, lf), group in runs.groupby(["solver", "load_factor"], sort=True):
        done = group[group["status"] != "failed"]
        n = len(done)
        row = {"solver": solver, "load_factor": float(lf), "n_runs": n, "n_failed": int(len(group) - n)}
        events = {"p_overturn": (done["status"] == "overturned").to_numpy()}
        for level in levels:
            events[level_column(level)] = _exceeds(done, level)
        for name, flags in events.items():
            k = int(np.sum(flags))
            lo, hi = wilson_interval(k, n, confidence) if n else (math.nan, math.nan)
            row.update({name: k / n if n else math.nan, f"{name}_lo": lo, f"{name}_hi": hi})
        rows.append(row)
    return pd.DataFrame(rows)


def fragility_table(runs: pd.DataFrame, measures: Iterable[str]) -> pd.DataFrame:
    """Lognormal fragility (maximum likelihood on individual runs) per solver and measure.

    Parameters
    ----------
    runs
        One row per run (module docstring): ``solver``, ``load_factor``, ``status``,
        ``max_theta_over_alpha`` (-), and a column per measure.
    measures
        Intensity-measure columns (units as :mod:`rockyade.motion.intensity` names them,
        e.g. ``pga_m_s2``).
    """
    rows = []
    for solver, group in runs.groupby("solver", sort=True):
        done = group[group["status"] != "failed"]
        collapsed = (done["status"] == "overturned").to_numpy()
        for measure in measures:
            fit = fit_lognormal_points(done[measure].to_numpy(dtype=float), collapsed)
            rows.append(
                {
                    "solver": solver,
                    "measure": measure,
                    "median": fit.median,
                    "beta": fit.beta,
                    "status": fit.status,
                    "n_runs": len(done),
                    "n_overturned": int(collapsed.sum()),
                }
            )
    return pd.DataFrame(rows)


def spread_table(runs: pd.DataFrame) -> pd.DataFrame:
    """What the parameters alone change, per solver and load factor (every sample runs every record).

    Columns: ``p_overturn_nominal`` (the nominal block over the records, NaN without one);
    the 5 %, 50 % and 95 % quantiles over samples of each sample's P(overturn) over the
    records; ``records_mixed_fraction``, the fraction of records that overturn some samples
    and not others; ``theta_ratio_q05`` / ``theta_ratio_q95``, the medians over records of
    the 5 % and 95 % quantiles over samples of the peak theta/alpha; and
    ``theta_spread_factor``, the median of their ratio q95 / q05 over the records that rock
    in every sample (q05 >= ``ROCKING_RATIO``).

    Parameters
    ----------
    runs
        One row per run (module docstring): ``solver``, ``load_factor``, ``status``,
        ``max_theta_over_alpha`` (-), ``sample``, ``nominal`` and ``record``.
    """
    rows = []
    done = runs[runs["status"] != "failed"].copy()
    done["overturned"] = done["status"] == "overturned"
    for (solver, lf), group in done.groupby(["solver", "load_factor"], sort=True):
        sampled = group[~group["nominal"].astype(bool)]
        nominal = group[group["nominal"].astype(bool)]
        per_sample = sampled.groupby("sample")["overturned"].mean()
        per_record = sampled.groupby("record")
        mixed = per_record["overturned"].agg(lambda s: bool(s.any() and not s.all()))
        q05 = per_record["max_theta_over_alpha"].quantile(0.05)
        q95 = per_record["max_theta_over_alpha"].quantile(0.95)
        factor = (q95 / q05).where(q05 >= ROCKING_RATIO)
        rows.append(
            {
                "solver": solver,
                "load_factor": float(lf),
                "samples": int(per_sample.size),
                "records": int(mixed.size),
                "p_overturn_nominal": float(nominal["overturned"].mean()) if len(nominal) else math.nan,
                "p_overturn_sample_q05": float(per_sample.quantile(0.05)),
                "p_overturn_sample_median": float(per_sample.median()),
                "p_overturn_sample_q95": float(per_sample.quantile(0.95)),
                "records_mixed_fraction": float(mixed.mean()),
                "theta_ratio_q05": float(q05.median()),
                "theta_ratio_q95": float(q95.median()),
                "theta_spread_factor": float(np.nanmedian(factor)) if factor.notna().any() else math.nan,
            }
        )
    return pd.DataFrame(rows)
