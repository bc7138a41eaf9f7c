"""Time histories of one or more results."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rockyade.figures.common import axes_list, new_figure, save_figure
from rockyade.result import Result

#: Line styles cycled over the results, so that overlapping curves stay distinguishable.
LINE_STYLES = ("-", "--", ":", "-.")


def plot_results(
    results: Mapping[str, Result] | Result,
    path: str | Path | None = None,
    title: str = "",
    quantity: str = "theta_rad",
    ax: Any = None,
) -> tuple[Any, Any]:
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
        Column of each block: ``theta_rad`` (rad), ``omega_rad_s`` (rad/s), ``x_m`` ...
    ax
        Axes to draw into: one per block of the first result (one Axes for one block).

    Returns
    -------
    fig, ax
        The figure and its Axes (a list of Axes, top block last, when there are several).
    """
    if isinstance(results, Result):
        results = {str(results.meta.get("solver", "result")): results}
    first = next(iter(results.values()))
    blocks = first.blocks or [""]
    if ax is None:
        fig, grid = new_figure(path, len(blocks), 1, figsize=(9, 2.8 * len(blocks) + 0.6), sharex=True, squeeze=False)
        axes = list(grid[:, 0])
    else:
        axes = axes_list(ax, len(blocks))
        fig = axes[0].figure
    for panel, block in zip(axes, blocks, strict=True):
        for i, (label, res) in enumerate(results.items()):
            if not res.ok:
                panel.plot([], [], LINE_STYLES[i % len(LINE_STYLES)], label=f"{label}: failed, no curve")
                continue
            if block and block not in res.blocks:
                continue
            panel.plot(
                res.t, res.series(quantity, block or None), LINE_STYLES[i % len(LINE_STYLES)], lw=1.1, label=label
            )
        name = f"{block}: " if block else ""
        panel.set_ylabel(f"{name}theta (rad)" if quantity == "theta_rad" else f"{name}{quantity}")
        panel.axhline(0.0, color="0.6", lw=0.5)
        panel.grid(alpha=0.3)
        panel.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time t (s)")
    if title:
        fig.suptitle(title)
    if path is not None:
        save_figure(fig, path)
    return fig, axes[0] if len(axes) == 1 else axes
