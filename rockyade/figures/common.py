"""What every figure module shares: figures that leave matplotlib's state alone, and the
atomic PNG writer.

Nothing here selects a backend. A figure drawn for a file is a bare
:class:`matplotlib.figure.Figure` rendered by Agg (pyplot never sees it, so nothing is
shown or leaked); a figure drawn for the screen (no file, no axes given) comes from
pyplot on the user's backend, so it shows inline in a notebook. Every plot function
returns ``(fig, ax)`` (or ``(fig, axes)``) and accepts ``ax=`` to draw into.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open

__all__ = ["axes_list", "file_figure", "new_figure", "save_figure"]


def new_figure(path: str | Path | None = None, nrows: int = 1, ncols: int = 1, **subplots: Any) -> tuple[Figure, Any]:
    """A figure and its axes, as ``pyplot.subplots`` returns them.

    Parameters
    ----------
    path
        Where the figure will be written. Given: a Figure outside pyplot, drawn by Agg.
        None: a pyplot figure on the current backend (shown inline in a notebook).
    nrows, ncols, **subplots
        Passed to ``Figure.subplots`` (``figsize`` goes to the figure).
    """
    if path is None:
        import matplotlib.pyplot as plt  # only for figures meant for the screen

        return plt.subplots(nrows, ncols, **subplots)
    return file_figure(nrows, ncols, **subplots)


def file_figure(nrows: int = 1, ncols: int = 1, **subplots: Any) -> tuple[Figure, Any]:
    """A figure outside pyplot, drawn by Agg (for files and animations), and its axes.

    ``figsize`` and ``layout`` go to the Figure, the rest to ``Figure.subplots``.
    """
    fig = Figure(figsize=subplots.pop("figsize", None), layout=subplots.pop("layout", None))
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, **subplots)


def axes_list(ax: Axes | Sequence[Axes] | np.ndarray, count: int, field_name: str = "ax") -> list[Axes]:
    """``ax`` as a list of ``count`` Axes (one Axes is accepted when ``count`` is 1)."""
    items = [ax] if isinstance(ax, Axes) else list(np.ravel(np.asarray(ax, dtype=object)))
    if len(items) != count or not all(isinstance(a, Axes) for a in items):
        raise InputError(field_name, f"must be {count} matplotlib Axes, got {len(items)} item(s)")
    return items


def save_figure(fig: Figure, path: str | Path, dpi: int = 130) -> Path:
    """Write ``fig`` as PNG atomically (the file is complete or absent); return the path."""
    path = Path(path)
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=dpi, bbox_inches="tight")
    return path
