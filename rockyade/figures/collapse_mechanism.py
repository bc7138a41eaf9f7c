"""The collapse mechanism drawn: the assembly at rest (dashed) and displaced along the mechanism.

A mechanism is a virtual velocity field without a physical size, so it is drawn at a
chosen scale: every vertex p of a moving block is moved by s v(p), v(p) the block's
velocity at p, with s such that the largest vertex displacement is
:data:`DISPLAY_FRACTION` of the assembly's size (and no block turns more than
:data:`MAX_DRAWN_ROTATION_RAD`). Moving a vertex by the velocity field keeps a hinge's point
where it is on both blocks (the blocks turn about it), at the price of a slight distortion
of blocks that turn (a rotation drawn to first order). Hinges are red dots, sliding joints
thick blue lines, blocks that move orange, blocks at rest stone, fixed blocks grey and
hatched. Where the nonlinear kinematic analysis reached alpha = 0, a second panel shows the
capacity curve a*(d*) of the equivalent system with a0*, d0*, du* and the secant of Ts.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from rockyade.errors import InputError
from rockyade.figures.block_drawing import (
    FIGURE_WIDTH_IN,
    FIXED,
    MAX_HEIGHT_IN,
    STONE,
    axis_limits,
    bounds_of,
    draw_blocks,
    draw_rest_outline,
    figure_for,
    setup_axes,
)
from rockyade.figures.canvas import axes_list, new_figure, save_figure
from rockyade.limit.analysis import LimitResult
from rockyade.limit.mechanism import point_velocity
from rockyade.limit.report_text import plural

#: The largest vertex displacement drawn, as a fraction of the assembly's size.
DISPLAY_FRACTION = 0.08
#: The largest rotation drawn, rad.
MAX_DRAWN_ROTATION_RAD = 0.12
MOVING = "#e8a15c"
HINGE = "#c0392b"
SLIDE = "#1f5fa8"


def displaced_polygons(result: LimitResult) -> tuple[list[np.ndarray], float]:
    """The blocks moved along the mechanism at the drawing scale, and that scale s."""
    model = result.model
    mech = result.mechanism
    rest = list(model.polygons_m)
    if mech is None:
        return rest, 0.0
    vel = mech.velocities
    peak = 0.0
    for i in np.flatnonzero(mech.moving).tolist():
        v = np.array([point_velocity(vel[i], model.centroids_m[i], p) for p in rest[i]])
        peak = max(peak, float(np.max(np.hypot(v[:, 0], v[:, 1]))))
    omega = float(np.max(np.abs(vel[:, 2])))
    scale = DISPLAY_FRACTION * model.size_m / max(peak, 1e-300)
    if omega * scale > MAX_DRAWN_ROTATION_RAD:
        scale = MAX_DRAWN_ROTATION_RAD / omega
    out = []
    for i, poly in enumerate(rest):
        if not mech.moving[i]:
            out.append(poly)
            continue
        v = np.array([point_velocity(vel[i], model.centroids_m[i], p) for p in poly])
        out.append(poly + scale * v)
    return out, scale


def draw_mechanism(result: LimitResult, path: str | Path | None = None, title: str | None = None, *, ax=None):
    """Draw the assembly at rest and along its collapse mechanism (axes in m), and where the
    nonlinear kinematic analysis reached alpha = 0 its capacity curve a* (m/s²) against d* (mm).

    Parameters
    ----------
    result
        A :class:`~rockyade.limit.analysis.LimitResult` (any status: without a mechanism
        the assembly is drawn at rest, titled with the status).
    path
        PNG file to write (atomically); None writes nothing.
    title
        First line of the title (default: "limit analysis").
    ax
        One Axes (the mechanism alone) or two (the mechanism and the capacity curve) to draw
        into; None: a new figure (pyplot's without ``path``), with both panels when there is
        a capacity curve.

    Returns
    -------
    fig, ax
        The figure and the mechanism's Axes, or ``(fig, (ax, capacity_ax))`` with two panels.
    """
    model = result.model
    mech = result.mechanism
    rest = list(model.polygons_m)
    moved, scale = displaced_polygons(result)
    bounds = bounds_of(rest + moved)
    curve = result.kinematic.spectral() if result.kinematic is not None else None
    cax = None
    if ax is not None:
        given = [ax] if isinstance(ax, Axes) else list(ax)
        panels = axes_list(given, len(given))
        if len(panels) not in (1, 2):
            raise InputError("ax", f"must be 1 or 2 matplotlib Axes, got {len(panels)}")
        ax, cax = panels[0], (panels[1] if len(panels) == 2 and curve is not None else None)
        fig = ax.figure
    elif curve is None:
        fig, axes = figure_for(bounds, path=path)
        ax = axes[0, 0]
    else:
        fig, ax, cax = _two_panels(bounds, path)
    setup_axes(ax, bounds)
    fixed = [bool(f) for f in model.fixed]
    colours = []
    if mech is not None:
        draw_rest_outline(ax, rest)
        colours = [MOVING if mech.moving[i] else STONE for i in range(model.n_blocks) if not fixed[i]]
    draw_blocks(ax, moved, fixed, facecolors=colours or None)
    handles: list[Artist] = []
    if mech is not None:
        vel = mech.velocities
        for slide in mech.sliding:
            itf = model.interfaces[slide.interface]
            ends = itf.ends_m + (
                0.0
                if itf.b < 0
                else scale * np.array([point_velocity(vel[itf.b], model.centroids_m[itf.b], p) for p in itf.ends_m])
            )
            ax.plot(ends[:, 0], ends[:, 1], color=SLIDE, linewidth=3.0, solid_capstyle="butt", zorder=6)
        for hinge in mech.hinges:
            itf = model.interfaces[hinge.interface]
            p = np.asarray(hinge.point_m)
            if itf.b >= 0:
                p = p + scale * point_velocity(vel[itf.b], model.centroids_m[itf.b], p)
            ax.plot(*p, "o", color=HINGE, markersize=7, markeredgecolor="white", markeredgewidth=1.0, zorder=7)
        _load_arrow(ax, bounds, result.direction)
        n_fixed = int(model.fixed.sum())
        handles = [Patch(facecolor=MOVING, edgecolor="0.3", label="moves")]
        if int(mech.moving.sum()) < model.n_blocks - n_fixed:
            handles.append(Patch(facecolor=STONE, edgecolor="0.3", label="stays at rest"))
        if n_fixed:
            handles.append(Patch(facecolor=FIXED, edgecolor="0.3", hatch="///", label="fixed"))
        handles.append(Line2D([], [], color="0.5", linestyle="--", label="at rest"))
        if mech.hinges:
            handles.append(Line2D([], [], marker="o", color=HINGE, linestyle="none", label="hinge"))
        if mech.sliding:
            handles.append(Line2D([], [], color=SLIDE, linewidth=3.0, label="sliding joint"))
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, framealpha=0.9)
    heading = title or "limit analysis"
    if result.status == "collapse" and mech is not None:  # a collapse always has its mechanism
        heading += (
            f": collapse at lambda = {result.load_multiplier:.4f} towards {result.direction} "
            f"({plural(len(mech.hinges), 'hinge')}, {plural(len(mech.sliding), 'sliding joint')})"
            "\nmechanism drawn at an arbitrary scale (displacements magnified); rest positions dashed"
        )
    elif result.status == "unstable":
        heading += ": unstable, it cannot stand under gravity alone (no multiplier)"
    else:
        heading += ": no mechanism (lambda unbounded)"
    if cax is None or curve is None:  # cax is made only with a capacity curve
        ax.set_title(heading, fontsize=10)
    else:
        fig.suptitle(heading, fontsize=10)
        _draw_capacity(cax, result.kinematic, *curve)
    if path is not None:
        save_figure(fig, path)
    return (fig, ax) if cax is None else (fig, (ax, cax))


def _two_panels(bounds, path: str | Path | None):
    """A figure with the assembly (left) and the capacity curve (right, narrower)."""
    xlim, ylim, _ = axis_limits(bounds)
    aspect = (ylim[1] - ylim[0]) / max(xlim[1] - xlim[0], 1e-9)
    width = FIGURE_WIDTH_IN + 4.0
    # the drawing's width: its share of the figure less its legend and labels (about 2 in), so that the
    # figure is as tall as the drawing at equal scales (no empty band above and below it)
    drawing_w = width * 2.6 / 3.6 - 2.0
    height = float(np.clip(drawing_w * aspect, 3.5, MAX_HEIGHT_IN)) + 1.2
    fig, axes = new_figure(path, 1, 2, figsize=(width, height), layout="constrained", width_ratios=[2.6, 1.0])
    return fig, axes[0], axes[1]


def _draw_capacity(ax, kin, d_star: np.ndarray, a_star: np.ndarray) -> None:
    """a*(d*) of the equivalent system with d0*, du*, ds* and the secant of Ts."""
    keep = a_star >= 0.0
    ax.plot(d_star[keep] * 1e3, a_star[keep], color="black", linewidth=1.5, label="a*(d*)")
    ax.plot([0.0], [kin.a0_star_m_s2], "o", color=HINGE, label=f"a0* = {kin.a0_star_m_s2:.3g} m/s²")
    if kin.d0_star_m is not None:
        ax.axvline(kin.d0_star_m * 1e3, color="0.5", linestyle=":", linewidth=1.0)
        ax.axvline(
            kin.du_star_m * 1e3, color=SLIDE, linestyle="--", linewidth=1.0, label=f"du* = {kin.du_star_m * 1e3:.3g} mm"
        )
        if kin.Ts_s is not None:
            ax.plot(
                [0.0, kin.ds_star_m * 1e3 * 2.5],
                [0.0, kin.as_star_m_s2 * 2.5],
                color=MOVING,
                linewidth=1.2,
                label=f"secant at ds*: Ts = {kin.Ts_s:.3g} s",
            )
            ax.plot([kin.ds_star_m * 1e3], [kin.as_star_m_s2], "s", color=MOVING)
        ax.annotate(
            f"d0* = {kin.d0_star_m * 1e3:.3g} mm",
            (kin.d0_star_m * 1e3, 0.0),
            textcoords="offset points",
            xytext=(-4, 6),
            ha="right",
            fontsize=8,
        )
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=0.0, top=1.1 * kin.a0_star_m_s2)
    ax.set_xlabel("d* (mm)")
    ax.set_ylabel("a* (m/s²)")
    ax.set_title(f"equivalent system (e* = {kin.e_star:.3f}, FC = {kin.FC:g})", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper right")


def _load_arrow(ax, bounds, direction: str) -> None:
    """An arrow showing the sense of the horizontal load, top right."""
    x0, x1, _, y1 = bounds
    size = max(x1 - x0, y1 - bounds[2])
    length = 0.12 * size
    xa, xb = x1 - 0.02 * size - length, x1 - 0.02 * size
    tail, head = (xa, xb) if direction == "+x" else (xb, xa)
    y = y1 + 0.02 * size
    ax.annotate(
        "", xy=(head, y), xytext=(tail, y), arrowprops=dict(arrowstyle="-|>", color="black", linewidth=1.5), zorder=8
    )
    ax.text(0.5 * (xa + xb), y + 0.01 * size, "lambda m g", ha="center", va="bottom", fontsize=8)
