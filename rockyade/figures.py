"""Figures (matplotlib, Agg backend): time histories of one or more results."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from rockyade.io.atomic import atomic_open


def save_figure(fig: plt.Figure, path: str | Path, dpi: int = 130) -> None:
    """Save ``fig`` as PNG atomically and close it."""
    with atomic_open(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)


def plot_results(results: dict, path: str | Path, title: str = "", quantity: str = "theta_rad") -> None:
    """theta(t) of each block, one panel per block, one curve per result (label -> Result)."""
    first = next(iter(results.values()))
    blocks = first.blocks
    fig, axes = plt.subplots(len(blocks), 1, figsize=(9, 2.8 * len(blocks) + 0.6), sharex=True, squeeze=False)
    styles = ["-", "--", ":", "-."]
    for ax, block in zip(axes[:, 0], blocks, strict=True):
        for i, (label, res) in enumerate(results.items()):
            if not res.ok or block not in res.blocks:
                continue
            ax.plot(res.t, res.series(quantity, block), styles[i % len(styles)], lw=1.1, label=label)
        ax.set_ylabel(f"{block}: theta (rad)" if quantity == "theta_rad" else f"{block}: {quantity}")
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time t (s)")
    if title:
        fig.suptitle(title)
    save_figure(fig, path)


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
