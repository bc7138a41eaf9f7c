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

from rockyade.constants import ACCEL_UNIT_LABELS, ACCEL_UNITS
from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open

__all__ = [
    "accel_scale",
    "axes_list",
    "file_figure",
    "new_figure",
    "other_accel_axis",
    "save_figure",
    "single_axes",
]


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


def figure_of(ax: Axes) -> Figure:
    """The Figure ``ax`` is drawn in: ``ax.figure``, or the top-level Figure when ``ax`` lies in
    a SubFigure (only a Figure can be saved)."""
    fig = ax.figure
    return fig if isinstance(fig, Figure) else fig.figure


def single_axes(ax: Axes | None, path: str | Path | None, figsize: tuple[float, float]) -> tuple[Figure, Axes]:
    """The figure and axes a one-panel plot draws in: ``ax`` and its figure (:func:`figure_of`),
    or, when ``ax`` is None, a new figure of ``figsize`` inches (:func:`new_figure`: for
    ``path``, or pyplot's when None)."""
    if ax is None:
        fig, new = new_figure(path, figsize=figsize)
        return fig, new
    return figure_of(ax), ax


def save_figure(fig: Figure, path: str | Path, dpi: int = 130) -> Path:
    """Write ``fig`` as PNG atomically (the file is complete or absent); return the path."""
    path = Path(path)
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=dpi, bbox_inches="tight")
    return path


def accel_scale(unit: str, field_name: str = "accel_unit") -> float:
    """m/s^2 per ``unit`` ("g": standard gravity, or "m/s2"); InputError for another unit.

    Parameters
    ----------
    unit
        "g" or "m/s2".
    field_name
        The option or argument that gave it (named in the error).
    """
    if unit not in ACCEL_UNITS:
        raise InputError(field_name, f"must be one of {', '.join(ACCEL_UNITS)}, got {unit!r}")
    return ACCEL_UNITS[unit]


def other_accel_axis(ax: Axes, unit: str, which: str = "x", what: str = "") -> Any:
    """A secondary axis (top or right) giving the accelerations of ``ax`` in the other unit:
    a figure in g shows m/s^2 as well, and the reverse.

    Parameters
    ----------
    ax
        Axes whose ``which`` axis holds accelerations in ``unit``.
    unit
        "g" or "m/s2".
    which
        "x" (the secondary axis on top) or "y" (on the right).
    what
        What the axis holds (e.g. "PGA"), for its label.
    """
    other = "m/s2" if unit == "g" else "g"
    factor = accel_scale(unit) / accel_scale(other)
    functions = (lambda v: v * factor, lambda v: v / factor)
    if which == "x":
        axis = ax.secondary_xaxis("top", functions=functions)
        axis.set_xlabel(f"{what} ({ACCEL_UNIT_LABELS[other]})".strip(), fontsize=8)
    else:
        axis = ax.secondary_yaxis("right", functions=functions)
        axis.set_ylabel(f"{what} ({ACCEL_UNIT_LABELS[other]})".strip(), fontsize=8)
    return axis
