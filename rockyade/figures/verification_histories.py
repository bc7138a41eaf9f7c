"""Figures of the verification report: the time histories each check compares."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rockyade.figures.canvas import axes_list, new_figure, save_figure
from rockyade.result import Result

#: check -> (title, [(block in the DEM results or None for a single-block result, legend)])
PANELS: dict[str, tuple[str, list[tuple[str | None, str]]]] = {
    "frame": (
        "Rocking frame under a one-sine pulse: left column against Housner's column with p_hat",
        [("column_left", "left column")],
    ),
    "drums": (
        "8 drums under a slow ramp: bottom and top drum against a monolithic column",
        [("d01", "bottom drum"), ("d08", "top drum")],
    ),
    "pad": ("Block on a pad under a pulse: upper block", [("upper", "upper block")]),
    "wall": ("1,000-block wall at rest: largest rotation of any block", []),
    "agreement": (
        "5-course wall (0.4 x 1 m) under a one-sine pulse (0.5 g, 0.4 s): top course, reference DEM and YADE",
        [],
    ),
    "loaded_pushover": (
        "Block 0.4 x 2 m with an 8 kN top load, pushed in held levels around (W b + N d) / (W h_c): rotation",
        [("pier", "block")],
    ),
}
STYLES = {"reference": ("C0", "-"), "yade": ("C3", "--")}


def _series(result: Result, name: str | None, quantity: str = "theta_rad") -> np.ndarray | None:
    blocks = result.blocks
    if len(blocks) == 1:
        return result.series(quantity)
    if name in blocks:
        return result.series(quantity, name)
    return None


def plot_check(check: str, results: dict[str, Result], path: str | Path | None = None, *, ax=None):
    """theta(t) (rad against s) of the blocks a check compares, one curve per solver (closed
    forms in black).

    Parameters
    ----------
    check
        The check's name (:data:`PANELS`).
    results
        ``{solver: Result}``.
    path
        PNG to write (atomically); None writes nothing.
    ax
        Axes to draw into; None: a new figure (pyplot's without ``path``).

    Returns
    -------
    fig, ax
        The figure and its Axes.
    """
    title, panels = PANELS.get(check, (check, []))
    if ax is None:
        fig, ax = new_figure(path, figsize=(9, 4.2))
    else:
        ax = axes_list(ax, 1)[0]
        fig = ax.figure
    if check == "wall":
        for solver, result in results.items():
            theta = np.column_stack([np.abs(result.series("theta_rad", b)) for b in result.blocks])
            ax.plot(result.t, theta.max(axis=1), label=f"{solver}: max over {len(result.blocks)} blocks")
        ax.axhline(1e-3, color="k", lw=0.8, ls=":", label="tolerance 1e-3 rad")
        ax.set_yscale("log")
    elif check == "agreement":
        for solver, result in results.items():
            top = [b for b in result.blocks if b.startswith(max(n.split("_")[0] for n in result.blocks) + "_")]
            colour, style = STYLES.get(solver, ("0.3", "-"))
            for k, name in enumerate(top):
                ax.plot(
                    result.t,
                    result.series("theta_rad", name),
                    style,
                    color=colour,
                    lw=1,
                    label=f"{solver} (top course)" if k == 0 else None,
                )
    else:
        for solver, result in results.items():
            exact = solver.startswith("housner")
            for k, (panel, legend) in enumerate(panels):
                series = _series(result, None if exact else panel)
                if series is None or (exact and k > 0):
                    continue
                colour, style = ("k", ":") if exact else STYLES.get(solver, ("0.3", "-"))
                width = 2.0 if exact else 1.1
                ax.plot(
                    result.t,
                    series,
                    style,
                    color=colour if k == 0 or exact else f"C{k + 4}",
                    lw=width,
                    label=solver if exact else f"{solver}: {legend}",
                )
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("rotation theta (rad)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if path is not None:
        save_figure(fig, path)
    return fig, ax
