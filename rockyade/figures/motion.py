"""Figures of base motions: accelerograms and response spectra."""

from __future__ import annotations

from pathlib import Path

from rockyade.figures.common import plt, save_figure


def plot_accelerogram(t, accel, vel, disp, path: str | Path, title: str = "") -> None:
    """Acceleration, velocity and displacement of a record, three panels."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 6.5), sharex=True)
    for ax, y, label in zip(
        axes, (accel, vel, disp), ("acceleration (m/s$^2$)", "velocity (m/s)", "displacement (m)"), strict=True
    ):
        ax.plot(t, y, lw=0.7)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time t (s)")
    if title:
        fig.suptitle(title)
    save_figure(fig, path)


def plot_spectra(periods, target, mean, path: str | Path, individual=None, title: str = "", band: float = 0.1) -> None:
    """Target spectrum with a +/- band, the suite mean, and (light) the individual spectra."""
    fig, ax = plt.subplots(figsize=(8, 5))
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
    ax.set_ylabel("pseudo-acceleration PSA (m/s$^2$), 5 % damping")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    if title:
        ax.set_title(title)
    save_figure(fig, path)
