"""Checks of a drawn figure that a reader would otherwise catch: text drawn over text, a legend
drawn over the data.

:func:`overlapping_texts` draws the figure and compares the window extents (the bounding boxes
matplotlib gives each text artist after a draw) of every visible, non-empty text: titles, axis
labels, tick labels, annotations, legend entries. Two that intersect by more than a pixel are
drawn over each other (two x-labels run into one line, a tick label under a title).
:func:`covered_markers` finds the data markers (points, error bar caps) that a legend inside the
axes hides.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.text import Text

#: Overlaps of at most this many pixels each way are not counted (antialiased edges touch).
TOLERANCE_PX = 1.0


def _visible(artist) -> bool:
    while artist is not None:
        if not artist.get_visible():
            return False
        artist = getattr(artist, "axes", None) if artist is not getattr(artist, "axes", None) else None
    return True


def _draw(fig: Figure):
    """Lay ``fig`` out (on Agg when it has no canvas that renders) and return its renderer.

    A draw without rendering (``Figure.draw_without_rendering``): every artist is placed and
    every text measured by Agg's renderer, as in a draw, but no pixel is painted; the window
    extents (and so what is found) are a full draw's.
    """
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    fig.draw_without_rendering()
    return canvas.get_renderer()


def covered_markers(fig: Figure) -> list[str]:
    """Labels (or "unlabelled") of the lines whose markers a legend inside their axes covers.

    Parameters
    ----------
    fig
        A figure (drawn here).
    """
    renderer = _draw(fig)
    found = []
    for ax in fig.axes:
        legend = ax.get_legend()
        if legend is None or not legend.get_visible():
            continue
        box = legend.get_window_extent(renderer)
        for line in ax.get_lines():
            if not isinstance(line, Line2D) or line.get_marker() in (None, "", "None", " ") or not line.get_visible():
                continue
            xy = np.column_stack([line.get_xdata(orig=False), line.get_ydata(orig=False)]).astype(float)
            if xy.size == 0:
                continue
            points = line.get_transform().transform(xy)
            inside = (
                (points[:, 0] > box.x0) & (points[:, 0] < box.x1) & (points[:, 1] > box.y0) & (points[:, 1] < box.y1)
            )
            if inside.any():
                label = str(line.get_label())
                found.append("unlabelled" if label.startswith("_") else label)
    return found


def overlapping_texts(fig: Figure) -> list[tuple[str, str]]:
    """Pairs of visible texts of ``fig`` whose boxes overlap (by more than :data:`TOLERANCE_PX`).

    Parameters
    ----------
    fig
        A figure (drawn here on its own canvas).

    Returns
    -------
    list of (str, str)
        The two texts of each overlapping pair, as written; empty when none overlap.
    """
    renderer = _draw(fig)
    texts = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip() and _visible(t)]
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in texts]
    found = []
    for (ta, a), (tb, b) in combinations(boxes, 2):
        dx = min(a.x1, b.x1) - max(a.x0, b.x0)
        dy = min(a.y1, b.y1) - max(a.y0, b.y0)
        if dx > TOLERANCE_PX and dy > TOLERANCE_PX:
            found.append((ta, tb))
    return found
