"""Blocks drawn in the base frame: the pieces every assembly figure shares.

The base is the hatched band below the black line y = 0; moving blocks are stone coloured
(or coloured by the caller), fixed blocks (they move with the base) grey and hatched; the
axes are in metres at equal aspect, and a figure's panels keep the drawing's aspect within
:data:`FIGURE_WIDTH_IN` x :data:`MAX_HEIGHT_IN` inches. Used by the drawings of assemblies and
their runs (:mod:`rockyade.figures.assembly`) and of collapse mechanisms
(:mod:`rockyade.figures.collapse_mechanism`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.patches import Rectangle

from rockyade.figures.canvas import new_figure

STONE = "#dccbaa"
STONE_EDGE = "#4a3f31"
FIXED = "#b9b9b9"
FIGURE_WIDTH_IN = 10.0
MAX_HEIGHT_IN = 8.0


def bounds_of(polygons: Sequence[np.ndarray]) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) of the polygons, m, with y0 at most 0 (the base is drawn)."""
    pts = np.vstack(polygons)
    x0, y0 = pts.min(axis=0)
    x1, y1 = pts.max(axis=0)
    return float(x0), float(x1), min(float(y0), 0.0), float(y1)


def axis_limits(bounds: tuple[float, float, float, float]) -> tuple[tuple[float, float], tuple[float, float], float]:
    """Axis limits with a margin, and the depth of the hatched ground band, m."""
    x0, x1, y0, y1 = bounds
    size = max(x1 - x0, y1 - y0)
    pad = 0.06 * size
    ground = 0.04 * size
    return (x0 - pad, x1 + pad), (min(y0, 0.0) - ground - 0.5 * pad, y1 + pad), ground


def line_width(n_blocks: int) -> float:
    """The blocks' outline width, points: thinner for many blocks."""
    return float(np.clip(1.2 / math.sqrt(max(n_blocks, 1) / 10.0), 0.25, 1.0))


def draw_ground(ax, xlim: tuple[float, float], depth: float) -> None:
    """The base: a hatched band ``depth`` m deep below the line y = 0 across ``xlim``."""
    ax.add_patch(
        Rectangle(
            (xlim[0], -depth),
            xlim[1] - xlim[0],
            depth,
            facecolor="white",
            edgecolor="0.35",
            hatch="////",
            linewidth=0.0,
            zorder=0,
        )
    )
    ax.plot(xlim, (0.0, 0.0), color="black", linewidth=1.6, zorder=3, solid_capstyle="butt")


def draw_blocks(
    ax,
    polygons: Sequence[np.ndarray],
    fixed: Sequence[bool],
    facecolors=None,
    zorder: float = 2.0,
) -> PolyCollection:
    """Moving blocks as one collection (returned, for animations) and fixed blocks as another."""
    lw = line_width(len(polygons))
    moving = [p for p, f in zip(polygons, fixed, strict=True) if not f]
    still = [p for p, f in zip(polygons, fixed, strict=True) if f]
    coll = PolyCollection(
        moving,
        facecolors=STONE if facecolors is None else facecolors,
        edgecolors=STONE_EDGE,
        linewidths=lw,
        zorder=zorder,
    )
    ax.add_collection(coll)
    if still:
        ax.add_collection(
            PolyCollection(still, facecolors=FIXED, edgecolors="0.25", linewidths=lw, hatch="///", zorder=zorder)
        )
    return coll


def draw_rest_outline(ax, rest: Sequence[np.ndarray]) -> None:
    """The blocks at rest as thin dashed outlines (behind the moving blocks)."""
    ax.add_collection(
        PolyCollection(rest, facecolors="none", edgecolors="0.5", linewidths=0.5, linestyles="--", zorder=1)
    )


def figure_for(
    bounds: tuple[float, float, float, float],
    panels: tuple[int, int] = (1, 1),
    width_in: float = FIGURE_WIDTH_IN,
    path: str | Path | None = "file",
):
    """A figure whose panels fit the drawing's aspect within ``width_in`` x MAX_HEIGHT_IN:
    outside pyplot (Agg) when it is for a file (``path`` not None), else pyplot's."""
    xlim, ylim, _ = axis_limits(bounds)
    aspect = (ylim[1] - ylim[0]) / (xlim[1] - xlim[0])
    rows, cols = panels
    panel_w = width_in / cols
    panel_h = panel_w * aspect
    if panel_h * rows > MAX_HEIGHT_IN:  # tall assemblies: narrower panels rather than a long strip
        panel_h = MAX_HEIGHT_IN / rows
        panel_w = max(panel_h / aspect, 1.2)
    width = max(panel_w * cols + 1.2, 4.5)
    height = panel_h * rows + 0.35 * rows + 0.8
    shared = rows * cols > 1
    return new_figure(
        None if path is None else Path(str(path)),
        rows,
        cols,
        figsize=(width, height),
        squeeze=False,
        sharex=shared,
        sharey=shared,
        layout="constrained",
    )


def setup_axes(ax, bounds) -> float:
    """Limits, equal aspect, labels in m, grid and the base of a drawing of ``bounds``; returns
    the base band's depth, m."""
    xlim, ylim, ground = axis_limits(bounds)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal", adjustable="box")
    spec = ax.get_subplotspec()
    if spec is None or spec.is_last_row():
        ax.set_xlabel("x (m)")
    if spec is None or spec.is_first_col():
        ax.set_ylabel("y (m)")
    ax.grid(alpha=0.25, linewidth=0.5)
    ax.set_axisbelow(True)
    draw_ground(ax, xlim, ground)
    return ground
