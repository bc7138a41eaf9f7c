"""The figure of a cross-check: paired ratios of collapse intensities, with their intervals.

A display object (computed data in, ``plot(ax=)`` draws, ``figure_`` and ``ax_`` kept)::

    from rockyade.figures.paired_ratios import PairedRatios

    display = PairedRatios.from_pairs(pairs)       # pairs.csv of rockyade crosscheck
    display.plot()                                 # on the screen (pyplot), or plot(ax=ax)
    display.save("crosscheck.png")

One row per pair of solvers at each time-step factor (``a / b``), and per solver against
itself at a finer step (``a: dt x 0.5 / dt x 1``): the median ratio (dot) and its bootstrap
95 % interval (bar), on a logarithmic axis around 1, with the band of agreement
(1 +/- tolerance) shaded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Self

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

from rockyade.errors import InputError
from rockyade.figures.canvas import figure_of, new_figure, save_figure

#: Ratios marked on the axis (those inside its limits).
TICKS = (0.25, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3, 1.5, 2.0, 4.0)
COARSE_TICKS = (0.25, 0.5, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.5, 2.0, 4.0)
#: The columns the display reads.
COLUMNS = (
    "kind",
    "solver_a",
    "solver_b",
    "dt_factor_a",
    "dt_factor_b",
    "median_ratio",
    "ratio_low",
    "ratio_high",
    "records",
)


@dataclass
class PairedRatios:
    """Paired ratios of collapse intensities with their intervals (module docstring).

    Attributes
    ----------
    labels
        One label per row, top to bottom.
    median, low, high
        The median ratio and its interval per row (-).
    kinds
        ``solvers`` (two solvers) or ``dt`` (a solver at a finer step against itself), per row.
    tolerance
        The band of agreement, 1 +/- tolerance.
    measure
        The intensity measure's name (for the axis label).
    figure_, ax_
        What :meth:`plot` drew in (None before).
    """

    labels: list[str]
    median: np.ndarray
    low: np.ndarray
    high: np.ndarray
    kinds: list[str]
    tolerance: float = 0.05
    measure: str = "pga"
    figure_: Figure | None = field(default=None, repr=False)
    ax_: Axes | None = field(default=None, repr=False)

    @classmethod
    def from_pairs(cls, pairs: pd.DataFrame, measure: str = "pga", tolerance: float = 0.05) -> PairedRatios:
        """The display of ``pairs.csv`` (:func:`rockyade.studies.crosscheck.reporting.summarise`); with a
        ``scene`` column (several cross-checks in one table), each label starts with it.

        Raises
        ------
        InputError
            A column missing.
        """
        missing = [c for c in COLUMNS if c not in pairs.columns]
        if missing:
            raise InputError("pairs", f"needs the columns {', '.join(COLUMNS)}; missing {', '.join(missing)}")
        labels = []
        for _, r in pairs.iterrows():
            scene = f"{r['scene']}: " if "scene" in pairs.columns else ""
            bare = not math.isfinite(float(r["ratio_low"])) and int(r["records"]) > 0
            n = f"(n = {r['records']}{', no interval' if bare else ''})"
            if r["kind"] == "dt":
                labels.append(f"{scene}{r['solver_a']}: dt x {r['dt_factor_a']:g} / dt x {r['dt_factor_b']:g} {n}")
            else:
                labels.append(f"{scene}{r['solver_a']} / {r['solver_b']}, dt x {r['dt_factor_a']:g} {n}")
        return cls(
            labels,
            pairs["median_ratio"].to_numpy(dtype=float),
            pairs["ratio_low"].to_numpy(dtype=float),
            pairs["ratio_high"].to_numpy(dtype=float),
            [str(k) for k in pairs["kind"]],
            tolerance,
            measure,
        )

    def plot(self, ax: Axes | None = None, path: str | Path | None = None) -> Self:
        """Draw the ratios (``ax`` given: into it; else a new figure, for a file when ``path``
        is given); return self with ``figure_`` and ``ax_`` set."""
        if ax is None:
            n = max(1, len(self.labels))
            width = 4.5 + 0.07 * max((len(label) for label in self.labels), default=20)
            fig, ax = new_figure(path, figsize=(width, 1.6 + 0.38 * n), layout="constrained")
        else:
            fig = figure_of(ax)
        y = np.arange(len(self.labels))[::-1]
        ax.axvspan(
            1 - self.tolerance,
            1 + self.tolerance,
            color="0.88",
            zorder=0,
            label=f"agreement band 1 \u00b1 {100 * self.tolerance:g} %",
        )
        ax.axvline(1.0, color="0.4", lw=0.8, zorder=1)
        colors = {"solvers": "#1f4e9c", "dt": "#b2182b"}
        for kind, label in (("solvers", "two solvers, a / b"), ("dt", "one solver, finer step / own step")):
            rows = [k for k, kk in enumerate(self.kinds) if kk == kind]
            if not rows:
                continue
            med, lo, hi = self.median[rows], self.low[rows], self.high[rows]
            err = np.vstack([np.where(np.isfinite(lo), med - lo, 0.0), np.where(np.isfinite(hi), hi - med, 0.0)])
            ax.errorbar(
                med,
                y[rows],
                xerr=err,
                fmt="o",
                color=colors[kind],
                capsize=3,
                ms=5,
                lw=1.4,
                zorder=3,
                label=f"{label}: median, 95 % interval",
            )
        finite = np.concatenate([v[np.isfinite(v)] for v in (self.median, self.low, self.high)] + [np.array([1.0])])
        span = max(float(np.max(np.abs(np.log(finite)))), math.log(1 + 2.5 * self.tolerance))
        ax.set_xscale("log")
        low, high = math.exp(-1.15 * span), math.exp(1.15 * span)
        ax.set_xlim(low, high)
        ticks = [t for t in TICKS if low <= t <= high]
        if len(ticks) > 8:  # a wide range: fewer marks, so that they do not run into each other
            ticks = [t for t in COARSE_TICKS if low <= t <= high]
        ax.xaxis.set_major_locator(FixedLocator(ticks))
        ax.xaxis.set_minor_locator(NullLocator())
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _pos: f"{v:.3g}"))
        ax.set_yticks(y, self.labels)
        ax.set_ylim(-0.7, len(self.labels) - 0.3)
        ax.set_xlabel(f"ratio of collapse intensities ({self.measure}), paired by record")
        ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1.01), ncols=2, fontsize=8, frameon=False)
        ax.grid(axis="x", which="both", lw=0.3, color="0.8")
        self.figure_, self.ax_ = fig, ax
        return self

    def save(self, path: str | Path) -> Path:
        """Write the figure (drawn now for a file if :meth:`plot` was not called) as PNG."""
        if self.figure_ is None:
            self.plot(path=path)
        assert self.figure_ is not None
        return save_figure(self.figure_, path)


__all__ = ["PairedRatios"]
