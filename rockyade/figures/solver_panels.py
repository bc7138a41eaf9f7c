"""Panels of solver curves against time: the display behind the paper study's history figures.

A study computes what each panel shows (:class:`Curve`, :class:`Panel`: which solver, its
label, its samples, the panel's title, scale, reference lines, shaded spans and note) and
:class:`SolverPanelsDisplay` draws it, following scikit-learn's displays: computed data in,
:meth:`SolverPanelsDisplay.plot` draws into given Axes or a new figure, and keeps
``figure_`` and ``ax_``. Each solver keeps its study look (:data:`rockyade.figures.styles.SOLVER_STYLES`),
so curves that coincide stay visible.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rockyade.figures.canvas import axes_list, figure_of, new_figure, save_figure
from rockyade.figures.styles import LineStyle, plot_solver

#: How a failed run shows: a legend entry with a red cross and no curve.
FAILED_STYLE: LineStyle = {"color": "red", "ls": "none", "marker": "x"}


@dataclass(frozen=True)
class Curve:
    """One solver's curve in a panel.

    Attributes
    ----------
    solver
        Its look: a key of :data:`rockyade.figures.styles.SOLVER_STYLES` (``housner``,
        ``reference``, ``yade`` ...).
    label
        Legend entry.
    t, y
        Samples (time in s, the panel's quantity in its unit). None: the run failed; the
        legend says so and no curve is drawn.
    """

    solver: str
    label: str
    t: np.ndarray | None = None
    y: np.ndarray | None = None

    @property
    def failed(self) -> bool:
        """True when there is no curve to draw."""
        return self.t is None or self.y is None


@dataclass(frozen=True)
class Span:
    """A shaded time span (s) with its legend label (e.g. the states of a harmonic test)."""

    start_s: float
    end_s: float
    label: str
    colour: str


@dataclass(frozen=True)
class Panel:
    """What one panel shows.

    Attributes
    ----------
    curves
        Solver curves, drawn in order.
    trace
        A plain grey line ``(t, y)`` drawn before the curves (a base motion), or None.
    title, ylabel
        The panel's title and y label.
    ylim
        Fixed y range, or None for matplotlib's.
    hlines
        Reference lines ``(y, linestyle)`` (e.g. ``(0, "-")``, or ``(1, "--")`` at the
        critical angle).
    spans
        Shaded time spans, drawn under everything.
    note
        Text boxed in the panel's lower left, wrapped at ``note_width`` characters ("" for none).
    legend_loc, legend_ncol
        Where the legend goes and in how many columns (no legend when there is nothing to label).
    """

    curves: Sequence[Curve] = ()
    trace: tuple[np.ndarray, np.ndarray] | None = None
    title: str = ""
    ylabel: str = ""
    ylim: tuple[float, float] | None = None
    hlines: Sequence[tuple[float, str]] = ((0.0, "-"),)
    spans: Sequence[Span] = ()
    note: str = ""
    note_width: int = 110
    legend_loc: Any = "best"
    legend_ncol: int = 1


@dataclass
class SolverPanelsDisplay:
    """A grid of panels of solver curves against time (rows top to bottom).

    Parameters
    ----------
    rows
        The panels, row by row; every row has the same number of panels.
    title
        Figure title ("" for none).
    xlabel
        Label of the bottom row's x axes.
    height_ratios
        Relative heights of the rows, or None for equal rows.

    Attributes
    ----------
    figure_
        The figure drawn into (after :meth:`plot`).
    ax_
        Its Axes, as a list of rows.
    """

    rows: Sequence[Sequence[Panel]]
    title: str = ""
    xlabel: str = "time t (s)"
    height_ratios: Sequence[float] | None = None
    figure_: Figure | None = field(default=None, init=False)
    ax_: list[list[Axes]] | None = field(default=None, init=False)

    def plot(
        self,
        ax: Axes | Sequence[Axes] | None = None,
        *,
        path: str | Path | None = None,
        figsize: tuple[float, float] | None = None,
    ) -> SolverPanelsDisplay:
        """Draw the panels; return the display with ``figure_`` and ``ax_`` set.

        Parameters
        ----------
        ax
            Axes to draw into, one per panel (row by row); None: a new figure sharing x
            (pyplot's without ``path``, so that it shows in a notebook).
        path
            PNG to write (atomically); None writes nothing.
        figsize
            Size of a new figure, inches (default: 10 wide, 2.8 per row).

        Raises
        ------
        InputError
            ``ax`` is not one Axes per panel.
        """
        n_rows, n_cols = len(self.rows), len(self.rows[0])
        if ax is None:
            size = figsize or (10.0, 2.8 * n_rows + 0.8)
            kw = {"gridspec_kw": {"height_ratios": list(self.height_ratios)}} if self.height_ratios else {}
            fig, grid = new_figure(path, n_rows, n_cols, figsize=size, sharex=True, squeeze=False, **kw)
            axes = [list(r) for r in grid]
        else:
            flat = axes_list(ax, n_rows * n_cols)
            axes = [flat[i * n_cols : (i + 1) * n_cols] for i in range(n_rows)]
            fig = figure_of(flat[0])
        for row_axes, row in zip(axes, self.rows, strict=True):
            for panel_ax, panel in zip(row_axes, row, strict=True):
                _draw_panel(panel_ax, panel)
        for panel_ax in axes[-1]:
            panel_ax.set_xlabel(self.xlabel)
        if self.title:
            fig.suptitle(self.title, fontsize=11)
        if path is not None:
            save_figure(fig, path)
        self.figure_, self.ax_ = fig, axes
        return self


def _draw_panel(ax: Axes, panel: Panel) -> None:
    """Draw one panel into ``ax``."""
    for span in panel.spans:
        if span.end_s > span.start_s:
            ax.axvspan(span.start_s, span.end_s, color=span.colour, alpha=0.5, lw=0, label=span.label)
    if panel.trace is not None:
        ax.plot(panel.trace[0], panel.trace[1], color="0.3", lw=0.7)
    for curve in panel.curves:
        if curve.failed:
            ax.plot([], [], label=curve.label, **FAILED_STYLE)
        else:
            plot_solver(ax, curve.solver, curve.t, curve.y, curve.label)
    for level, style in panel.hlines:
        ax.axhline(level, color="0.45", lw=0.6, ls=style)
    if panel.ylim is not None:
        ax.set_ylim(*panel.ylim)
    if panel.title:
        ax.set_title(panel.title, fontsize=9)
    ax.set_ylabel(panel.ylabel)
    ax.grid(alpha=0.3)
    if panel.note:
        ax.text(
            0.01,
            0.04,
            "\n".join(textwrap.wrap(panel.note, panel.note_width)),
            transform=ax.transAxes,
            fontsize=7.5,
            va="bottom",
            bbox={"facecolor": "white", "edgecolor": "0.5", "alpha": 0.9},
        )
    if panel.curves or panel.spans:
        ax.legend(fontsize=7, loc=panel.legend_loc, ncol=panel.legend_ncol)


__all__ = ["Curve", "Panel", "SolverPanelsDisplay", "Span"]
