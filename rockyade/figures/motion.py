"""Figures of base motions: accelerograms and response spectra."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from numpy.typing import ArrayLike

from rockyade.figures.common import axes_list, new_figure, save_figure


def plot_accelerogram(
    t: ArrayLike,
    accel: ArrayLike,
    vel: ArrayLike,
    disp: ArrayLike,
    path: str | Path | None = None,
    title: str = "",
    ax: Any = None,
) -> tuple[Any, Any]:
    """Acceleration (m/s^2), velocity (m/s) and displacement (m) of a record against time (s).

    ``ax``: three Axes to draw into. ``path``: PNG to write. Returns ``(fig, axes)``.
    """
    if ax is None:
        fig, axes = new_figure(path, 3, 1, figsize=(9, 6.5), sharex=True)
        axes = list(axes)
    else:
        axes = axes_list(ax, 3)
        fig = axes[0].figure
    for panel, y, label in zip(
        axes, (accel, vel, disp), ("acceleration (m/s$^2$)", "velocity (m/s)", "displacement (m)"), strict=True
    ):
        panel.plot(t, y, lw=0.7)
        panel.set_ylabel(label)
        panel.grid(alpha=0.3)
    axes[-1].set_xlabel("time t (s)")
    if title:
        fig.suptitle(title)
    if path is not None:
        save_figure(fig, path)
    return fig, axes


def plot_spectra(
    periods: ArrayLike,
    target: ArrayLike | None,
    mean: ArrayLike | None,
    path: str | Path | None = None,
    individual: ArrayLike | None = None,
    title: str = "",
    band: float = 0.1,
    ax: Any = None,
    damping: float | None = None,
) -> tuple[Any, Any]:
    """Pseudo-acceleration spectra (m/s^2) against period (s, log axis).

    ``target`` with a +/- ``band`` (fraction), ``mean`` (the suite mean, or the spectrum
    of one record), and ``individual`` spectra in light grey; any may be None. ``ax``:
    Axes to draw into. ``path``: PNG to write. ``damping``: the ratio, named on the axis
    when given. Returns ``(fig, ax)``.
    """
    if ax is None:
        fig, ax = new_figure(path, figsize=(8, 5))
    else:
        ax = axes_list(ax, 1)[0]
        fig = ax.figure
    if individual is not None:
        for k, psa in enumerate(individual):
            ax.plot(periods, psa, color="0.8", lw=0.6, label="records" if k == 0 else None)
    if target is not None:
        ax.fill_between(
            periods, (1 - band) * target, (1 + band) * target, color="C1", alpha=0.2, label=f"target +/-{band:.0%}"
        )
        ax.plot(periods, target, color="C1", lw=2, label="target")
    if mean is not None:
        ax.plot(periods, mean, color="C0", lw=1.6, label="mean" if individual is not None else "spectrum")
    ax.set_xscale("log")
    ax.set_xlabel("period T (s)")
    damping_note = f", {100 * damping:g} % damping" if damping is not None else ""
    ax.set_ylabel(f"pseudo-acceleration PSA (m/s$^2$){damping_note}")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    if title:
        ax.set_title(title)
    if path is not None:
        save_figure(fig, path)
    return fig, ax
