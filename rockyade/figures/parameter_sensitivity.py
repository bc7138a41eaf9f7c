"""How much each response changes when a classical parameter changes: a display.

:class:`SensitivityDisplay` takes the table a sensitivity study computed (one row per response,
solver, parameter and change) and draws one panel of bars per response, Housner beside the
reference DEM, following scikit-learn's displays (``plot(ax=)``, ``figure_``, ``ax_``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from rockyade.figures.canvas import axes_list, figure_of, new_figure, save_figure
from rockyade.figures.styles import SOLVER_LABELS, SOLVER_STYLES


@dataclass
class SensitivityDisplay:
    """The change of each response (%) when alpha, p or mu changes by -5 % or +5 %.

    Parameters
    ----------
    table
        One row per ``response``, ``solver`` (housner, reference), ``parameter`` (alpha_rad,
        p_rad_s, mu) and ``change_pct`` (-5, +5): the response's ``relative_change_pct`` (%),
        NaN where the DEM cannot be matched to that mu (the panel says so).

    Attributes
    ----------
    figure_, ax_
        The figure and its Axes, one per response (after :meth:`plot`).
    """

    table: pd.DataFrame
    figure_: Figure | None = field(default=None, init=False)
    ax_: list[Axes] | None = field(default=None, init=False)

    def plot(self, ax: Axes | Sequence[Axes] | None = None, *, path: str | Path | None = None) -> SensitivityDisplay:
        """Draw the bars; return the display with ``figure_`` and ``ax_`` set.

        Parameters
        ----------
        ax
            Axes to draw into, one per response; None: a new figure (pyplot's without ``path``).
        path
            PNG to write (atomically); None writes nothing.
        """
        responses = list(dict.fromkeys(self.table.response))
        if ax is None:
            fig, grid = new_figure(
                path, 1, len(responses), figsize=(4.2 * len(responses), 4.2), sharey=True, squeeze=False
            )
            axes = list(grid[0])
        else:
            axes = axes_list(ax, len(responses))
            fig = figure_of(axes[0])
        labels = [f"{p} {c:+.0f}%" for p in ("alpha_rad", "p_rad_s", "mu") for c in (-5, 5)]
        y = np.arange(len(labels))
        for panel, response in zip(axes, responses, strict=True):
            for k, solver in enumerate(("housner", "reference")):
                sel = self.table[(self.table.response == response) & (self.table.solver == solver)]
                values = [
                    sel[(sel.parameter == lab.split()[0]) & (np.isclose(sel.change_pct, float(lab.split()[1][:-1])))][
                        "relative_change_pct"
                    ].iloc[0]
                    for lab in labels
                ]
                offset = y + (k - 0.5) * 0.38
                panel.barh(
                    offset, values, height=0.38, color=SOLVER_STYLES[solver]["color"], label=SOLVER_LABELS[solver]
                )
                for pos, value in zip(offset, values, strict=True):
                    if np.isnan(value):  # say why there is no bar
                        panel.text(0, pos, "  DEM: mu not reachable", va="center", fontsize=7, color="0.35")
            panel.axvline(0, color="0.3", lw=0.6)
            panel.set_title(response, fontsize=9)
            panel.set_xlabel("change of the response (%)")
            panel.grid(alpha=0.3, axis="x")
        axes[0].set_yticks(y, labels)
        axes[0].legend(fontsize=8)
        if path is not None:
            save_figure(fig, path)
        self.figure_, self.ax_ = fig, axes
        return self


__all__ = ["SensitivityDisplay"]
