"""Time histories of one or more results."""

from __future__ import annotations

from pathlib import Path

from rockyade.figures.common import plt, save_figure


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
