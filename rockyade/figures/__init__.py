"""Figures (matplotlib): time histories, base motions, and the studies' plots.

``common`` (pyplot and the atomic PNG writer), ``histories`` (theta(t) of results),
``motion`` (accelerograms, spectra). May import ``result``, ``analysis`` and below.
"""

from rockyade.figures.common import plt, save_figure
from rockyade.figures.histories import plot_results
from rockyade.figures.motion import plot_accelerogram, plot_spectra

__all__ = ["plot_accelerogram", "plot_results", "plot_spectra", "plt", "save_figure"]
