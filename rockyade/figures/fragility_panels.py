"""Fragility curves with their stripes: the one drawing of ``rockyade paper``'s fragility figure
and of ``rockyade fragility`` / ``assess``.

What is drawn is computed elsewhere (:func:`rockyade.probability.fragility_curves.fit_lognormal`, the
stripes of :mod:`rockyade.assess.stripes`) and handed over in the figure's unit
(:class:`FragilityCurve`: the fraction of records that collapse at each stripe, with or
without its Wilson interval, the fitted curve, its bootstrap band). :class:`FragilityDisplay`
follows scikit-learn's displays: computed data in, :meth:`FragilityDisplay.plot` draws into
given Axes or a new figure and keeps ``figure_`` and ``ax_``.

Each curve is solid over the levels its stripes tested and dotted beyond them (there it is
the fit's extrapolation); its median is marked on the curve at P = 0.5 where asked (a
diamond beyond the tested levels, an arrow at the edge beyond the axis).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rockyade.figures.canvas import save_figure, single_axes
from rockyade.figures.styles import LineStyle
from rockyade.probability.fragility_curves import Fragility

#: How a missing curve shows in the legend: a red cross, its text red.
MISSING_COLOUR = "#b2182b"


@dataclass(frozen=True)
class FragilityCurve:
    """One set of stripes and its fit, every intensity in the figure's unit.

    Attributes
    ----------
    levels, fractions
        The stripes' intensities and the fraction of records that collapse there.
    label
        Legend entry of the points.
    colour, marker
        Their look (``colour`` the curve's too, unless ``point_colour`` is given); ``filled``:
        filled markers (else open).
    fraction_lo, fraction_hi
        The fractions' confidence interval (drawn as error bars), or None.
    fragility
        The fit, its median in the figure's unit (None: points only). A "fitted" one is
        drawn as a curve, a "separated" one as a vertical line at its threshold.
    curve_label
        Legend entry of the curve ("" for none).
    tested_max
        The largest intensity tested: the curve is solid up to it, dotted beyond (default:
        the largest level).
    mark_median
        Mark the median at P = 0.5.
    band
        ``(x, lo, hi)``: a band around the curve (e.g. a bootstrap's 5 %-95 %), or None;
        ``band_label`` its legend entry.
    lw
        Width of the curve.
    """

    levels: np.ndarray
    fractions: np.ndarray
    label: str
    colour: str = "#1f4e79"
    marker: str = "o"
    filled: bool = False
    fraction_lo: np.ndarray | None = None
    fraction_hi: np.ndarray | None = None
    fragility: Fragility | None = None
    curve_label: str = ""
    tested_max: float = math.nan
    mark_median: bool = False
    band: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    band_label: str = ""
    band_colour: str = "#9ecae1"
    lw: float = 1.3
    point_colour: str | None = None


@dataclass(frozen=True)
class Mark:
    """A vertical line at an intensity (figure's unit), with its legend entry and look."""

    x: float
    label: str
    colour: str = "0.45"
    style: str = "--"
    lw: float = 1.3
    alpha: float = 1.0
    zorder: float = 2.5


@dataclass
class FragilityDisplay:
    """Stripes and fitted fragility curves in one Axes.

    Parameters
    ----------
    curves
        Drawn in order.
    x_max
        Right end of the x axis (the figure's unit); the axis starts at 0.
    xlabel, ylabel, title
        Labels ("" for none); the x label should carry the unit.
    beyond
        Intensity from which the axis is beyond every tested level: shaded grey to
        ``x_max`` and said so, ``beyond_text`` (None: no shading).
    marks
        Vertical lines (:class:`Mark`).
    missing
        Legend lines for curves that could not be drawn (a red cross, red text).
    ylim
        y range (room above 1 for a legend inside).
    legend
        "upper left" (inside; curves rise to the right) or "below" (under the axes, outside).

    Attributes
    ----------
    figure_, ax_
        The figure and Axes drawn into (after :meth:`plot`).
    """

    curves: Sequence[FragilityCurve]
    x_max: float
    xlabel: str = ""
    ylabel: str = "P(collapse)"
    title: str = ""
    beyond: float | None = None
    beyond_text: str = "beyond the largest tested level"
    marks: Sequence[Mark] = ()
    missing: Sequence[str] = ()
    ylim: tuple[float, float] = (-0.03, 1.03)
    legend: str = "upper left"
    legend_fontsize: float = 7.0
    figure_: Figure | None = field(default=None, init=False)
    ax_: Axes | None = field(default=None, init=False)

    def plot(
        self, ax: Axes | None = None, *, path: str | Path | None = None, figsize: tuple[float, float] = (6.4, 4.2)
    ) -> FragilityDisplay:
        """Draw; return the display with ``figure_`` and ``ax_`` set.

        Parameters
        ----------
        ax
            Axes to draw into; None: a new figure (pyplot's without ``path``).
        path
            PNG to write (atomically); None writes nothing.
        figsize
            Size of a new figure, inches.
        """
        fig, ax = single_axes(ax, path, figsize)
        grid = np.linspace(self.x_max / 400, self.x_max, 400)
        for curve in self.curves:
            _draw_curve(ax, curve, grid, self.x_max)
        for mark in self.marks:
            ax.axvline(
                mark.x,
                color=mark.colour,
                ls=mark.style,
                lw=mark.lw,
                alpha=mark.alpha,
                zorder=mark.zorder,
                label=mark.label,
            )
        if self.beyond is not None and self.beyond < self.x_max:
            ax.axvspan(self.beyond, self.x_max, color="0.92", lw=0, zorder=0)
            ax.text(
                self.x_max,
                0.5,
                self.beyond_text + " ",
                rotation=90,
                fontsize=6.5,
                color="0.4",
                ha="right",
                va="center",
            )
        for text in self.missing:  # a legend entry, so that it never covers the points
            ax.plot([], [], ls="none", marker="x", color=MISSING_COLOUR, label=text)
        if self.title:
            ax.set_title(self.title)
        ax.set_xlim(0, self.x_max)
        ax.set_ylim(*self.ylim)
        ax.set_yticks(np.linspace(0, 1, 6))
        if self.xlabel:
            ax.set_xlabel(self.xlabel)
        if self.ylabel:
            ax.set_ylabel(self.ylabel)
        ax.grid(alpha=0.3)
        _legend(ax, self.legend, self.legend_fontsize, set(self.missing))
        if path is not None:
            save_figure(fig, path)
        self.figure_, self.ax_ = fig, ax
        return self


def _draw_curve(ax: Axes, c: FragilityCurve, grid: np.ndarray, x_max: float) -> None:
    """One curve: its band, its fit, its points."""
    f = c.fragility
    tested = float(np.max(c.levels)) if math.isnan(c.tested_max) and len(c.levels) else c.tested_max
    if f is not None and f.status == "fitted":
        if c.band is not None and not np.all(np.isnan(c.band[1])):
            ax.fill_between(*c.band, color=c.band_colour, alpha=0.55, lw=0, label=c.band_label or None)
        p = f.probability(grid)
        inside = grid <= tested
        ax.plot(grid[inside], p[inside], color=c.colour, lw=c.lw, label=c.curve_label or None)
        ax.plot(grid[~inside], p[~inside], color=c.colour, lw=min(c.lw, 1.4), ls=":")
        if c.mark_median:  # on the curve (an arrow at the edge when beyond the axis)
            beyond_axis = f.median > x_max
            shape = ">" if beyond_axis else ("D" if f.median > tested else "o")
            ax.plot(min(f.median, x_max), 0.5, shape, color=c.colour, mfc="white", ms=6, mew=1.3, zorder=5)
    elif f is not None and f.status == "separated":
        ax.axvline(f.median, color=c.colour, lw=1.4, label=c.curve_label or None)
    style: LineStyle = {"color": c.point_colour or c.colour, "ms": 4.5, "label": c.label}
    if not c.filled:
        style["mfc"], style["mew"] = "none", 1.2
    if c.fraction_lo is not None and c.fraction_hi is not None:
        lo = np.clip(c.fractions - c.fraction_lo, 0.0, None)  # >= 0 (the interval's rounding)
        hi = np.clip(c.fraction_hi - c.fractions, 0.0, None)
        ax.errorbar(c.levels, c.fractions, yerr=[lo, hi], fmt=c.marker, capsize=2.5, lw=0.9, **style)
    else:
        ax.plot(c.levels, c.fractions, c.marker, ls="none", **style)


def _legend(ax: Axes, where: str, fontsize: float, missing: set[str]) -> None:
    if where == "below":  # under the axes, outside them: it never covers a point, a bar or a line
        legend = ax.legend(fontsize=fontsize, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=1, frameon=False)
    else:
        legend = ax.legend(fontsize=fontsize, loc=where)  # type: ignore[call-overload]  # a str loc
    for text in legend.get_texts():
        if text.get_text() in missing:
            text.set_color(MISSING_COLOUR)


__all__ = ["FragilityCurve", "FragilityDisplay", "Mark"]
