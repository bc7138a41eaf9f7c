"""The studies' figure conventions: one look per solver, and the states of a harmonic test."""

from __future__ import annotations

from typing import Any, TypedDict


class LineStyle(TypedDict, total=False):
    """The keyword arguments of a look, as matplotlib's ``plot``/``errorbar`` take them."""

    color: str
    lw: float
    alpha: float
    ls: str | tuple[int, tuple[int, ...]]
    zorder: int
    marker: str
    ms: float
    mfc: str
    mew: float
    label: str


#: One look per solver in every study figure. The reference DEM is a wide translucent
#: band, Housner a thin solid line and YADE a dashed line on top, so that curves that
#: coincide stay visible (a dashed line inside a band) instead of hiding each other.
SOLVER_STYLES: dict[str, LineStyle] = {
    "reference": {"color": "#f28e2b", "lw": 4.0, "alpha": 0.45, "ls": "-", "zorder": 2},
    "housner": {"color": "#1f4e9c", "lw": 1.0, "alpha": 1.0, "ls": "-", "zorder": 3},
    "yade": {"color": "#1b7837", "lw": 1.3, "alpha": 1.0, "ls": (0, (4, 3)), "zorder": 4},
}
SOLVER_LABELS = {"housner": "Housner (exact)", "reference": "reference DEM", "yade": "YADE"}


def plot_solver(ax: Any, solver: str, t: Any, y: Any, label: str | None = None) -> None:
    """Draw one solver's curve in its study style."""
    ax.plot(t, y, label=label or SOLVER_LABELS.get(solver, solver), **SOLVER_STYLES[solver])
