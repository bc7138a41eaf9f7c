"""The bi-block's map of rocking patterns over base-motion frequency and amplitude: a display.

:class:`PatternMapDisplay` takes the cells a study computed (a solver's dominant pattern per
frequency and amplitude, the paper's reported pattern where it reports one) and draws them,
following scikit-learn's displays: :meth:`PatternMapDisplay.plot` draws into given Axes or a
new figure and keeps ``figure_`` and ``ax_``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from rockyade.figures.canvas import save_figure, single_axes

COLOURS = {
    "rest": "#eeeeee",
    "1": "#f4a261",
    "2": "#e76f51",
    "3": "#2a9d8f",
    "4": "#8ab17d",
    "overturn-lower": "#264653",
    "overturn-upper": "#6d597a",
    "failed": "#000000",
}
#: The legend in words (paper Fig. 16 for patterns 1-4).
PATTERN_NAMES = {
    "rest": "rest: neither block rocks",
    "1": "1: both rock, same way",
    "2": "2: both rock, opposite ways",
    "3": "3: the stack rocks as one body",
    "4": "4: only the upper block rocks",
    "overturn-lower": "OT lower: the lower block overturns",
    "overturn-upper": "OT upper: the upper block overturns",
    "failed": "failed run (no result)",
}


@dataclass
class PatternMapDisplay:
    """The dominant rocking pattern per cell (colour: a solver's) with the paper's reported
    regions outlined (solid where the solver agrees, dashed where not).

    Parameters
    ----------
    cells
        One row per cell: ``frequency_hz``, ``amplitude_mm``, ``pattern_dem`` (the solver's
        pattern, a key of :data:`COLOURS`), ``pattern_paper`` (NaN where the paper reports none)
        and ``agree``.
    frequencies_hz, amplitudes_mm
        The grid's frequencies (Hz, x) and table displacement amplitudes (mm, y).
    solver_label
        The solver whose patterns colour the cells, in words (the title).

    Attributes
    ----------
    figure_, ax_
        The figure and Axes drawn into (after :meth:`plot`).
    """

    cells: pd.DataFrame
    frequencies_hz: Sequence[float]
    amplitudes_mm: Sequence[float]
    solver_label: str = "reference DEM"
    figure_: Figure | None = field(default=None, init=False)
    ax_: Axes | None = field(default=None, init=False)

    def plot(self, ax: Axes | None = None, *, path: str | Path | None = None) -> PatternMapDisplay:
        """Draw the map; return the display with ``figure_`` and ``ax_`` set.

        Parameters
        ----------
        ax
            Axes to draw into; None: a new figure (pyplot's without ``path``).
        path
            PNG to write (atomically); None writes nothing.
        """
        fig, ax = single_axes(ax, path, (10.5, 6))
        f_index = {f: i for i, f in enumerate(self.frequencies_hz)}
        a_index = {a: j for j, a in enumerate(self.amplitudes_mm)}
        for _, row in self.cells.iterrows():
            i, j = f_index[row.frequency_hz], a_index[row.amplitude_mm]
            ax.add_patch(Rectangle((i - 0.5, j - 0.5), 1, 1, color=COLOURS.get(row.pattern_dem, "#000000")))
            label = row.pattern_dem.replace("overturn-", "OT ") if isinstance(row.pattern_dem, str) else "?"
            ax.text(
                i,
                j,
                label,
                ha="center",
                va="center",
                fontsize=9,
                color="white" if label.startswith(("OT", "2", "failed")) else "black",
            )
            if not pd.isna(row.pattern_paper):
                ax.add_patch(
                    Rectangle(
                        (i - 0.45, j - 0.45),
                        0.9,
                        0.9,
                        fill=False,
                        lw=2.0,
                        ec="#1d3557" if row.pattern_paper == "2" else "#e63946",
                        ls="-" if row.agree else "--",
                    )
                )
        ax.set_xlim(-0.5, len(self.frequencies_hz) - 0.5)
        ax.set_ylim(-0.5, len(self.amplitudes_mm) - 0.5)
        ax.set_xticks(range(len(self.frequencies_hz)), [f"{f:g}" for f in self.frequencies_hz])
        ax.set_yticks(range(len(self.amplitudes_mm)), [f"{a:g}" for a in self.amplitudes_mm])
        ax.set_xlabel("table frequency (Hz)")
        ax.set_ylabel("table displacement amplitude (mm)")
        shown = [p for p in COLOURS if p in set(self.cells.pattern_dem) or p in ("1", "2", "3", "4", "rest")]
        handles = [Rectangle((0, 0), 1, 1, color=COLOURS[p]) for p in shown]
        handles += [
            Rectangle((0, 0), 1, 1, fill=False, ec="#1d3557", lw=2),
            Rectangle((0, 0), 1, 1, fill=False, ec="#e63946", lw=2),
            Rectangle((0, 0), 1, 1, fill=False, ec="0.3", lw=2, ls="--"),
        ]
        labels = [PATTERN_NAMES[p] for p in shown] + [
            "paper's region of pattern 2 (opposite ways)",
            "paper's region of pattern 3 (one body)",
            "dashed outline: the solver disagrees",
        ]
        ax.legend(
            handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, title="cell colour: the solver"
        )
        ax.set_title(f"Bi-block: dominant rocking pattern ({self.solver_label}) and the paper's regions")
        if path is not None:
            save_figure(fig, path)
        self.figure_, self.ax_ = fig, ax
        return self


__all__ = ["COLOURS", "PATTERN_NAMES", "PatternMapDisplay"]
