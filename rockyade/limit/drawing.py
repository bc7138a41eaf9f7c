"""The collapse mechanism drawn: the assembly at rest (dashed) and displaced along the mechanism.

A mechanism is a virtual velocity field without a physical size, so it is drawn at a
chosen scale: every vertex p of a moving block is moved by s v(p), v(p) the block's
velocity at p, with s such that the largest vertex displacement is
:data:`DISPLAY_FRACTION` of the assembly's size (and no block turns more than
:data:`MAX_DRAWN_ROTATION_RAD`). Moving a vertex by the velocity field keeps a hinge's point
where it is on both blocks (the blocks turn about it), at the price of a slight distortion
of blocks that turn (a rotation drawn to first order). Hinges are red dots, sliding joints
thick blue lines, blocks that move orange, blocks at rest stone, fixed blocks grey and
hatched.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from rockyade.figures.assembly import (
    FIXED,
    STONE,
    _bounds,
    _draw_blocks,
    _draw_rest_outline,
    _figure_for,
    _setup_axes,
)
from rockyade.figures.common import save_figure
from rockyade.limit.analysis import LimitResult
from rockyade.limit.mechanism import point_velocity
from rockyade.limit.report import plural

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
    for i in np.flatnonzero(mech.moving):
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


def draw_mechanism(result: LimitResult, path: str | Path, title: str | None = None) -> Path:
    """Draw the assembly at rest and along its collapse mechanism; write a PNG.

    Parameters
    ----------
    result
        A :class:`~rockyade.limit.analysis.LimitResult` (any status: without a mechanism
        the assembly is drawn at rest, titled with the status).
    path
        PNG file to write.
    title
        First line of the title (default: "limit analysis").
    """
    model = result.model
    mech = result.mechanism
    rest = list(model.polygons_m)
    moved, scale = displaced_polygons(result)
    bounds = _bounds(rest + moved)
    fig, axes = _figure_for(bounds)
    ax = axes[0, 0]
    _setup_axes(ax, bounds)
    fixed = [bool(f) for f in model.fixed]
    colours = []
    if mech is not None:
        _draw_rest_outline(ax, rest)
        colours = [MOVING if mech.moving[i] else STONE for i in range(model.n_blocks) if not fixed[i]]
    _draw_blocks(ax, moved, fixed, facecolors=colours or None)
    handles = []
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
    if result.status == "collapse":
        heading += (
            f": collapse at lambda = {result.load_multiplier:.4f} towards {result.direction} "
            f"({plural(len(mech.hinges), 'hinge')}, {plural(len(mech.sliding), 'sliding joint')})"
            "\nmechanism drawn at an arbitrary scale (displacements magnified); rest positions dashed"
        )
    elif result.status == "unstable":
        heading += ": unstable, it cannot stand under gravity alone (no multiplier)"
    else:
        heading += ": no mechanism (lambda unbounded)"
    ax.set_title(heading, fontsize=10)
    return save_figure(fig, path)


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
