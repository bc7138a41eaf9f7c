"""Time histories of one or more results: a display object and two plot functions.

:class:`HistoryDisplay` follows scikit-learn's displays: built from results
(:meth:`HistoryDisplay.from_result`, :meth:`HistoryDisplay.from_results`) it draws at
once and keeps what it drew (``figure_``, ``ax_``); :meth:`HistoryDisplay.plot` draws it
again elsewhere. :func:`plot_result` and :func:`plot_results` return ``(fig, ax)`` as every
plot function of :mod:`rockyade.figures` does. A Result knows nothing of figures.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rockyade.figures.canvas import axes_list, figure_of, new_figure, save_figure
from rockyade.result import Result

#: Line styles cycled over the results, so that overlapping curves stay distinguishable.
LINE_STYLES = ("-", "--", ":", "-.")


class HistoryDisplay:
    """A per-block quantity of one or more results against time: one panel per block,
    one curve per result.

    Parameters
    ----------
    results
        ``{label: Result}``, drawn in that order. Failed results are listed in the legend
        as failed, with no curve.
    quantity
        Column of each block: ``theta_rad`` (rad), ``omega_rad_s`` (rad/s), ``x_m`` (m) ...

    Attributes
    ----------
    figure_
        The figure drawn into (after :meth:`plot`).
    ax_
        Its Axes: one Axes for one block, else a list (bottom block first).
    """

    def __init__(self, results: Mapping[str, Result], quantity: str = "theta_rad") -> None:
        self.results = dict(results)
        self.quantity = quantity
        self.figure_: Figure | None = None
        self.ax_: Axes | list[Axes] | None = None

    @classmethod
    def from_result(
        cls,
        result: Result,
        *,
        quantity: str = "theta_rad",
        label: str | None = None,
        ax: Axes | Sequence[Axes] | None = None,
        path: str | Path | None = None,
        title: str = "",
    ) -> HistoryDisplay:
        """Draw one result.

        Parameters
        ----------
        result
            The result.
        quantity
            Per-block column, e.g. ``theta_rad`` (rad).
        label
            Legend entry (default: the result's solver).
        ax, path, title
            As for :meth:`plot`.
        """
        name = label or str(result.meta.solver or "result")
        return cls({name: result}, quantity).plot(ax, path=path, title=title)

    @classmethod
    def from_results(
        cls,
        results: Mapping[str, Result],
        *,
        quantity: str = "theta_rad",
        ax: Axes | Sequence[Axes] | None = None,
        path: str | Path | None = None,
        title: str = "",
    ) -> HistoryDisplay:
        """Draw several results on the same panels.

        Parameters
        ----------
        results
            ``{label: Result}``, drawn in that order.
        quantity
            Per-block column, e.g. ``theta_rad`` (rad).
        ax, path, title
            As for :meth:`plot`.
        """
        return cls(results, quantity).plot(ax, path=path, title=title)

    def plot(
        self, ax: Axes | Sequence[Axes] | None = None, *, path: str | Path | None = None, title: str = ""
    ) -> HistoryDisplay:
        """Draw the curves; return the display, its ``figure_`` and ``ax_`` set.

        Parameters
        ----------
        ax
            Axes to draw into: one per block of the first result (one Axes for one block).
            None: a new figure (pyplot's without ``path``, so that it shows in a notebook).
        path
            PNG to write (atomically); None writes nothing.
        title
            Figure title.

        Raises
        ------
        InputError
            ``ax`` is not one Axes per block.
        """
        first = next(iter(self.results.values()))
        blocks = first.blocks or [""]
        if ax is None:
            fig, grid = new_figure(
                path, len(blocks), 1, figsize=(9, 2.8 * len(blocks) + 0.6), sharex=True, squeeze=False
            )
            axes = list(grid[:, 0])
        else:
            axes = axes_list(ax, len(blocks))
            fig = figure_of(axes[0])
        for panel, block in zip(axes, blocks, strict=True):
            for i, (label, res) in enumerate(self.results.items()):
                style = LINE_STYLES[i % len(LINE_STYLES)]
                if not res.ok:
                    panel.plot([], [], style, label=f"{label}: failed, no curve")
                    continue
                if block and block not in res.blocks:
                    continue
                panel.plot(res.t, res.series(self.quantity, block or None), style, lw=1.1, label=label)
            name = f"{block}: " if block else ""
            panel.set_ylabel(f"{name}theta (rad)" if self.quantity == "theta_rad" else f"{name}{self.quantity}")
            panel.axhline(0.0, color="0.6", lw=0.5)
            panel.grid(alpha=0.3)
            panel.legend(loc="upper right", fontsize=8)
        axes[-1].set_xlabel("time t (s)")
        if title:
            fig.suptitle(title)
        if path is not None:
            save_figure(fig, path)
        self.figure_ = fig
        self.ax_ = axes[0] if len(axes) == 1 else axes
        return self


def plot_result(
    result: Result,
    ax: Axes | Sequence[Axes] | None = None,
    *,
    quantity: str = "theta_rad",
    label: str | None = None,
    path: str | Path | None = None,
    title: str = "",
) -> tuple[Figure, Axes | list[Axes]]:
    """A per-block quantity of one result against time, one panel per block.

    Parameters
    ----------
    result
        The result.
    ax
        Axes to draw into, one per block (e.g. to overlay several results); None: a new figure.
    quantity
        Per-block column: ``theta_rad`` (rad, default), ``omega_rad_s`` (rad/s), ``x_m`` (m) ...
    label
        Legend entry (default: the result's solver).
    path
        PNG to write (atomically); None writes nothing.
    title
        Figure title.

    Returns
    -------
    fig, ax
        The figure and its Axes (a list of Axes, bottom block first, when there are several).
    """
    display = HistoryDisplay.from_result(result, quantity=quantity, label=label, ax=ax, path=path, title=title)
    assert display.figure_ is not None and display.ax_ is not None
    return display.figure_, display.ax_


def plot_results(
    results: Mapping[str, Result] | Result,
    path: str | Path | None = None,
    title: str = "",
    quantity: str = "theta_rad",
    ax: Axes | Sequence[Axes] | None = None,
) -> tuple[Figure, Axes | list[Axes]]:
    """A per-block quantity against time: one panel per block, one curve per result.

    Parameters
    ----------
    results
        ``{label: Result}`` (or one Result, labelled by its solver). Failed results are
        listed in the legend as failed, with no curve.
    path
        PNG to write (atomically); None writes nothing.
    title
        Figure title.
    quantity
        Column of each block: ``theta_rad`` (rad), ``omega_rad_s`` (rad/s), ``x_m`` (m) ...
    ax
        Axes to draw into: one per block of the first result (one Axes for one block).

    Returns
    -------
    fig, ax
        The figure and its Axes (a list of Axes, bottom block first, when there are several).
    """
    if isinstance(results, Result):
        results = {str(results.meta.solver or "result"): results}
    display = HistoryDisplay.from_results(results, quantity=quantity, ax=ax, path=path, title=title)
    assert display.figure_ is not None and display.ax_ is not None
    return display.figure_, display.ax_
