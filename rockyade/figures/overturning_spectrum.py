"""The overturning spectrum under one-sine pulses: a display object.

The study (:mod:`rockyade.studies.overturning`) computes the scan and the minima;
:class:`OverturningSpectrumDisplay` draws them, following scikit-learn's displays: computed
data in (:meth:`OverturningSpectrumDisplay.from_frames` from the study's tables),
:meth:`OverturningSpectrumDisplay.plot` draws into given Axes or a new figure and keeps
``figure_`` and ``ax_``. Every quantity is a ratio: the pulse's circular frequency over the
block's frequency parameter, omega_p / p (-), and its amplitude over the uplift acceleration,
a_p / (g tan alpha) (-) (Housner, G. W., 1963, "The behavior of inverted pendulum structures
during earthquakes", Bull. Seismol. Soc. Am. 53(2)).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import NDArray

from rockyade.figures.canvas import save_figure, single_axes
from rockyade.figures.styles import SOLVER_STYLES

#: The axes' labels (ratios: no unit, shown as (-)).
X_LABEL = r"pulse frequency / frequency parameter, $\omega_p\,/\,p$ (-)"
Y_LABEL = r"pulse amplitude / uplift acceleration, $a_p\,/\,(g\,\tan\alpha)$ (-)"


@dataclass
class OverturningSpectrumDisplay:
    """Minimum overturning amplitude of a one-sine pulse against its frequency, and every
    amplitude at which Housner's block overturns.

    Parameters
    ----------
    omega_ratio
        (n,) frequencies of the spectrum, omega_p / p (-).
    housner_min, reference_min
        (n,) minimum overturning amplitudes a_p / (g tan alpha) (-) of Housner's solution
        and of the reference DEM; NaN: no overturn up to ``max_ratio``.
    overturned_omega, overturned_amplitude
        (m,) every (frequency, amplitude) of Housner's full scan at which the block overturns (-).
    max_ratio
        The largest amplitude scanned (-): the top of the figure.
    title
        The figure's title ("" for none).

    Attributes
    ----------
    figure_
        The figure drawn into (after :meth:`plot`).
    ax_
        Its Axes.
    """

    omega_ratio: NDArray[np.float64]
    housner_min: NDArray[np.float64]
    reference_min: NDArray[np.float64]
    overturned_omega: NDArray[np.float64]
    overturned_amplitude: NDArray[np.float64]
    max_ratio: float
    title: str = "Overturning under a one-sine pulse (specimen 1)"
    figure_: Figure | None = field(default=None, init=False)
    ax_: Axes | None = field(default=None, init=False)

    @classmethod
    def from_frames(
        cls, scan: pd.DataFrame, spectrum: pd.DataFrame, max_ratio: float, **kwargs: str
    ) -> OverturningSpectrumDisplay:
        """The display of the study's tables (nothing drawn yet).

        Parameters
        ----------
        scan
            One row per run: ``solver``, ``omega_ratio``, ``amplitude_ratio`` (-), ``overturned``.
        spectrum
            ``omega_ratio``, ``housner_min_ratio``, ``reference_min_ratio`` (-).
        max_ratio
            The largest amplitude scanned (-).
        **kwargs
            ``title``.
        """
        over = scan[(scan.solver == "housner") & scan.overturned.astype(bool)]
        return cls(
            spectrum.omega_ratio.to_numpy(float),
            spectrum.housner_min_ratio.to_numpy(float),
            spectrum.reference_min_ratio.to_numpy(float),
            over.omega_ratio.to_numpy(float),
            over.amplitude_ratio.to_numpy(float),
            float(max_ratio),
            **kwargs,
        )

    def plot(
        self, ax: Axes | None = None, *, path: str | Path | None = None, figsize: tuple[float, float] = (8.5, 5.5)
    ) -> OverturningSpectrumDisplay:
        """Draw the spectrum; return the display with ``figure_`` and ``ax_`` set.

        Parameters
        ----------
        ax
            Axes to draw into; None: a new figure (pyplot's without ``path``, so that it shows
            in a notebook).
        path
            PNG to write (atomically); None writes nothing.
        figsize
            Size of a new figure, inches.
        """
        fig, ax = single_axes(ax, path, figsize)
        housner = SOLVER_STYLES["housner"]["color"]
        dem = SOLVER_STYLES["reference"]["color"]
        ax.scatter(
            self.overturned_omega,
            self.overturned_amplitude,
            s=7,
            color=housner,
            alpha=0.45,
            lw=0,
            label="Housner: overturns (every amplitude scanned)",
        )
        ax.plot(self.omega_ratio, self.housner_min, "-o", color=housner, ms=4, label="Housner: minimum")
        ax.plot(
            self.omega_ratio,
            self.reference_min,
            "--s",
            color=dem,
            ms=5,
            mfc="none",
            mew=1.3,
            label="reference DEM: minimum",
        )
        for minima, colour, who in ((self.housner_min, housner, "Housner"), (self.reference_min, dem, "reference DEM")):
            survived = np.isnan(minima)  # no overturn up to the largest amplitude scanned
            if survived.any():
                ax.plot(
                    self.omega_ratio[survived],
                    np.full(int(survived.sum()), self.max_ratio),
                    "^",
                    color=colour,
                    ms=9,
                    mfc="none",
                    mew=1.5,
                    clip_on=False,
                    label=f"{who}: no overturn up to {self.max_ratio:g} (the scan's limit)",
                )
        ax.set_xlabel(X_LABEL)
        ax.set_ylabel(Y_LABEL)
        ax.set_ylim(1.0, self.max_ratio)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
        if self.title:
            ax.set_title(self.title)
        if path is not None:
            save_figure(fig, path)
        self.figure_, self.ax_ = fig, ax
        return self


__all__ = ["OverturningSpectrumDisplay"]
