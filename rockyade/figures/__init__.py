"""Figures (matplotlib): time histories, base motions, and the studies' plots.

``canvas`` (figures outside pyplot for files, the atomic PNG writer), ``histories``
(quantities of results against time: :class:`HistoryDisplay`, :func:`plot_result`,
:func:`plot_results`), ``base_motions`` (accelerograms, spectra). Importing this
package never selects a matplotlib backend. Every plot function returns ``(fig, ax)`` (or
``(fig, axes)``), accepts ``ax=`` to draw into an existing figure, and writes a PNG only
when given a path. May import ``result``, ``analysis`` and below.
"""

from rockyade.figures.base_motions import plot_accelerogram, plot_spectra
from rockyade.figures.canvas import new_figure, save_figure
from rockyade.figures.histories import HistoryDisplay, plot_result, plot_results

__all__ = [
    "HistoryDisplay",
    "new_figure",
    "plot_accelerogram",
    "plot_result",
    "plot_results",
    "plot_spectra",
    "save_figure",
]
