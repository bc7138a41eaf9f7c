"""Figures of base motions: accelerograms and response spectra."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rockyade.constants import ACCEL_UNIT_LABELS
from rockyade.figures.canvas import accel_scale, axes_list, figure_of, new_figure, other_accel_axis, save_figure


def plot_accelerogram(
    t: ArrayLike,
    accel: ArrayLike,
    vel: ArrayLike,
    disp: ArrayLike,
    path: str | Path | None = None,
    title: str = "",
    ax: Any = None,
    accel_unit: str = "m/s2",
) -> tuple[Any, Any]:
    """Acceleration (m/s^2 given), velocity (m/s) and displacement (m) of a record against time (s).

    ``ax``: three Axes to draw into. ``path``: PNG to write. ``accel_unit``: "m/s2" or "g"
    (standard gravity), the unit the acceleration is drawn in (the other unit on the right).
    Returns ``(fig, axes)``.
    """
    scale = accel_scale(accel_unit)
    if ax is None:
        fig, axes = new_figure(path, 3, 1, figsize=(9, 6.5), sharex=True)
        axes = list(axes)
    else:
        axes = axes_list(ax, 3)
        fig = figure_of(axes[0])
    labels = (f"acceleration ({ACCEL_UNIT_LABELS[accel_unit]})", "velocity (m/s)", "displacement (m)")
    for panel, y, label in zip(axes, (np.asarray(accel) / scale, vel, disp), labels, strict=True):
        panel.plot(t, y, lw=0.7)
        panel.set_ylabel(label)
        panel.grid(alpha=0.3)
    other_accel_axis(axes[0], accel_unit, "y")
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
    individual: Iterable[ArrayLike] | None = None,
    title: str = "",
    band: float = 0.1,
    ax: Any = None,
    damping: float | None = None,
    accel_unit: str = "m/s2",
) -> tuple[Any, Any]:
    """Pseudo-acceleration spectra (m/s^2 given) against period (s, log axis).

    ``target`` with a +/- ``band`` (fraction), ``mean`` (the suite mean, or the spectrum
    of one record), and ``individual`` spectra in light grey; any may be None. ``ax``:
    Axes to draw into. ``path``: PNG to write. ``damping``: the ratio, named on the axis
    when given. ``accel_unit``: "m/s2" or "g" (standard gravity), the unit drawn (the other
    on the right). Returns ``(fig, ax)``.
    """
    scale = accel_scale(accel_unit)
    target = None if target is None else np.asarray(target) / scale
    mean = None if mean is None else np.asarray(mean) / scale
    individual = None if individual is None else [np.asarray(psa) / scale for psa in individual]
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
    ax.set_ylabel(f"pseudo-acceleration PSA ({ACCEL_UNIT_LABELS[accel_unit]}){damping_note}")
    other_accel_axis(ax, accel_unit, "y", "PSA")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    if title:
        ax.set_title(title)
    if path is not None:
        save_figure(fig, path)
    return fig, ax
