"""Figures of an uncertainty study: probabilities with confidence bands, fragility against an
intensity measure, and the spread the parameters alone cause."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.constants import ACCEL_UNIT_LABELS, ACCEL_UNIT_TEXT, LOAD_FACTOR_LABEL
from rockyade.figures.canvas import accel_scale, axes_list, figure_of, new_figure, other_accel_axis, save_figure
from rockyade.motion.intensity import LABELS
from rockyade.probability.exceedance import level_column
from rockyade.probability.fragility_curves import Fragility, wilson_interval

SOLVER_COLOURS = {"housner": "C0", "reference": "C1", "yade": "C2"}


def _colour(solver: str, k: int) -> str:
    return SOLVER_COLOURS.get(solver, f"C{k + 3}")


def plot_uncertainty(
    study: Any,
    probabilities: pd.DataFrame,
    runs: pd.DataFrame,
    fragility: pd.DataFrame,
    spread: pd.DataFrame | None,
    path: str | Path | None = None,
    n_bins: int = 8,
    *,
    ax: Any = None,
    accel_unit: str = "g",
) -> tuple[Any, Any]:
    """Three panels: P(overturn) and P(theta/alpha >= level) against the load factor with 95 %
    Wilson bands; the fragility against the study's first intensity measure (binned fractions
    with their bands, and the fitted lognormal curve); per-sample P(overturn) against the
    nominal block (pairing "all"), or the peak theta/alpha of every run.

    Parameters
    ----------
    study, probabilities, runs, fragility, spread
        The study and its tables (:func:`rockyade.studies.uncertainty.run_uncertainty`).
    path
        PNG to write (atomically); None writes nothing.
    n_bins
        Bins of the intensity measure for the fractions of the fragility panel.
    ax
        Three Axes to draw into; None: a new figure (pyplot's without ``path``).
    accel_unit
        "g" (default) or "m/s2": the unit of a PGA axis (the other unit on the opposite side).

    Returns
    -------
    fig, axes
        The figure and its three Axes.
    """
    measure = study.measures[0]
    scale = accel_scale(accel_unit) if measure == "pga_m_s2" else 1.0
    if ax is None:
        fig, axes = new_figure(path, 1, 3, figsize=(16, 4.8))
    else:
        axes = axes_list(ax, 3)
        fig = figure_of(axes[0])
    ax = axes[0]
    styles = ["--", ":", "-."]
    markers = ["v", "^", "D"]
    for k, (solver, group) in enumerate(probabilities.groupby("solver")):
        c = _colour(solver, k)
        x = group["load_factor"].to_numpy()
        ax.plot(x, group["p_overturn"], "o-", color=c, label=f"{solver}: overturn")
        ax.fill_between(x, group["p_overturn_lo"], group["p_overturn_hi"], color=c, alpha=0.18, lw=0)
        for j, level in enumerate(study.levels):
            col = level_column(level)
            ax.plot(  # open markers: a level's curve stays visible where it meets P(overturn)
                x,
                group[col],
                styles[j % 3],
                marker=markers[j % 3],
                mfc="none",
                ms=6 + 2 * j,
                color=c,
                lw=1.0,
                label=f"{solver}: theta/alpha >= {level:g}",
            )
    ax.set_xlabel(LOAD_FACTOR_LABEL)
    ax.set_ylabel("probability (95 % Wilson band)")
    ax.set_ylim(-0.02, 1.02)
    ax.set_title(f"{study.name}: {study.samples} parameter samples x records", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)

    ax = axes[1]
    for k, (solver, group) in enumerate(runs[runs["status"] != "failed"].groupby("solver")):
        c = _colour(solver, k)
        x = group[measure].to_numpy(dtype=float) / scale
        y = (group["status"] == "overturned").to_numpy()
        edges = np.unique(np.quantile(x, np.linspace(0, 1, n_bins + 1)))
        idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, edges.size - 2)
        for b in range(edges.size - 1):
            sel = idx == b
            if not sel.any():
                continue
            n, kk = int(sel.sum()), int(y[sel].sum())
            lo, hi = wilson_interval(kk, n)
            xm = float(np.median(x[sel]))
            yerr = [[max(kk / n - lo, 0.0)], [max(hi - kk / n, 0.0)]]
            ax.errorbar(xm, kk / n, yerr=yerr, fmt="s", color=c, ms=4, capsize=2)
        row = fragility[(fragility["solver"] == solver) & (fragility["measure"] == measure)]
        if len(row) and row.iloc[0]["status"] == "fitted":
            fit = Fragility(
                float(row.iloc[0]["median"]) / scale, float(row.iloc[0]["beta"]), int(row.iloc[0]["n_runs"])
            )
            xs = np.geomspace(max(x.min(), 1e-6) * 0.8, x.max() * 1.2, 200)
            unit = f" {ACCEL_UNIT_TEXT[accel_unit]}" if measure == "pga_m_s2" else ""
            ax.plot(
                xs,
                fit.probability(xs),
                "-",
                color=c,
                label=f"{solver}: median {fit.median:.3g}{unit}, beta {fit.beta:.2f}",
            )
        else:
            ax.plot([], [], "-", color=c, label=f"{solver}: {row.iloc[0]['status'] if len(row) else 'no fit'}")
    if measure == "pga_m_s2":
        ax.set_xlabel(f"PGA ({ACCEL_UNIT_LABELS[accel_unit]})")
        other_accel_axis(ax, accel_unit, "x", "PGA")
    else:
        ax.set_xlabel(LABELS.get(measure, measure))
    ax.set_ylabel("P(overturn)")
    ax.set_ylim(-0.02, 1.02)
    ax.set_title("fragility: binned fractions (95 % bands) and lognormal MLE fit", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)

    ax = axes[2]
    if spread is not None and len(spread):
        for k, (solver, group) in enumerate(spread.groupby("solver")):
            c = _colour(solver, k)
            x = group["load_factor"].to_numpy()
            ax.fill_between(
                x,
                group["p_overturn_sample_q05"],
                group["p_overturn_sample_q95"],
                color=c,
                alpha=0.25,
                lw=0,
                label=f"{solver}: 5-95 % over parameter samples",
            )
            ax.plot(x, group["p_overturn_sample_median"], "-", color=c, lw=1.0, label=f"{solver}: median sample")
            if group["p_overturn_nominal"].notna().any():
                ax.plot(x, group["p_overturn_nominal"], "k*", ms=7, label="nominal block" if k == 0 else None)
        ax.set_ylabel("P(overturn) over the records, per parameter sample")
        ax.set_ylim(-0.02, 1.02)
        ax.set_title("spread caused by alpha, p, mu alone (same records)", fontsize=9)
        ax.set_xlabel(LOAD_FACTOR_LABEL)
    else:
        done = runs[runs["status"] != "failed"]
        for k, (solver, group) in enumerate(done.groupby("solver")):
            ax.semilogy(
                group["load_factor"] + 0.01 * k,
                group["max_theta_over_alpha"].clip(lower=1e-4),
                ".",
                color=_colour(solver, k),
                ms=3,
                alpha=0.5,
                label=solver,
            )
        ax.set_ylabel("peak theta / alpha (every run)")
        ax.set_title("peak rotation of every run", fontsize=9)
        ax.set_xlabel(LOAD_FACTOR_LABEL)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    if path is not None:
        save_figure(fig, path)
    return fig, axes
