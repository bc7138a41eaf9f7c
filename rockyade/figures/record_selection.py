"""The figure of ``rockyade motion select``: the scaled records' spectra, their mean, the site's
spectrum and the band of NTC 2018 3.2.3.6 (10 % below, 30 % above) over the range checked."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from rockyade.constants import ACCEL_UNIT_LABELS
from rockyade.figures.canvas import accel_scale, axes_list, new_figure, other_accel_axis, save_figure


def plot_selection(
    periods_s: ArrayLike,
    target_m_s2: ArrayLike,
    scaled_m_s2: ArrayLike,
    names: list[str],
    band: tuple[float, float],
    t_range: tuple[float, float],
    path: str | Path | None = None,
    title: str = "",
    verdict: str = "",
    ax: Any = None,
    accel_unit: str = "g",
) -> tuple[Any, Any]:
    """Each scaled record's 5 % spectrum (thin, labelled in the legend), their mean (thick), the
    target and its band (shaded) over the range checked (dotted verticals at its ends).

    Parameters
    ----------
    periods_s
        Periods, s (log axis).
    target_m_s2
        The site's elastic spectrum at them, m/s^2.
    scaled_m_s2
        The scaled records' spectra (rows), m/s^2.
    names
        The records' names.
    band
        (below, above) as fractions of the target (0.10, 0.30).
    t_range
        The range checked, s.
    path
        PNG to write (None: not written).
    title, verdict
        The figure's title, and a line under it (compatible or not, worst deviation).
    ax
        Axes to draw into.
    accel_unit
        "g" (standard gravity) or "m/s2"; the other on the right.
    """
    scale = accel_scale(accel_unit)
    periods = np.asarray(periods_s, dtype=float)
    target = np.asarray(target_m_s2, dtype=float) / scale
    scaled = np.atleast_2d(np.asarray(scaled_m_s2, dtype=float)) / scale
    if ax is None:
        fig, ax = new_figure(path, figsize=(9, 6.5))
    else:
        ax = axes_list(ax, 1)[0]
        fig = ax.figure
    below, above = band
    inside = (periods >= t_range[0]) & (periods <= t_range[1])
    ax.fill_between(
        periods[inside],
        (1 - below) * target[inside],
        (1 + above) * target[inside],
        color="C1",
        alpha=0.18,
        label=f"band: -{100 * below:.0f} % / +{100 * above:.0f} % (NTC 2018 3.2.3.6)",
    )
    for k, (psa, name) in enumerate(zip(scaled, names, strict=True)):
        ax.plot(periods, psa, lw=0.7, alpha=0.75, color=f"C{(k % 8) + 2}", label=name)
    ax.plot(periods, target, color="C1", lw=2.2, label="site's elastic spectrum (5 %)")
    ax.plot(periods, scaled.mean(axis=0), color="k", lw=2.0, label=f"mean of the {len(names)} scaled records")
    for t in t_range:
        ax.axvline(t, color="0.4", ls=":", lw=1)
    ax.set_xscale("log")
    ax.set_xlabel("period T (s); dotted: the range checked")
    ax.set_ylabel(f"pseudo-acceleration PSA ({ACCEL_UNIT_LABELS[accel_unit]}), 5 % damping")
    other_accel_axis(ax, accel_unit, "y", "PSA")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3, frameon=False)
    if title or verdict:
        ax.set_title("\n".join(t for t in (title, verdict) if t), fontsize=9)
    if path is not None:
        save_figure(fig, path)
    return fig, ax


__all__ = ["plot_selection"]
