"""Drawings of assemblies: the scene at rest with block names, snapshots of a run, animations.

Blocks are drawn in the base frame (positions relative to the base, which is the hatched
line y = 0): moving blocks in stone colour, fixed blocks (they move with the base) grey and
hatched. A block's polygon at time t is v + k (v(t) - v), v(t) = R(theta)(v - c) + c + (x, y):
v its vertices at rest, c its centroid at rest, and theta, x, y the Result's rotation and
centroid displacement from rest; k is a display magnification (1: true scale). Magnifying
each vertex's displacement keeps blocks that touch at a corner touching there (a rocking
column stays on its pivot); at large k theta the drawn blocks distort, which the titles say.
Colours give each block's rotation from rest on a scale of at least
:data:`MIN_COLOUR_SCALE_RAD`, so that elastic tilts of micro-radians stay pale.

Names are written inside blocks at the largest size that fits (along the block's own base
direction, or across it for tall blocks), and left out where that size would be below
:data:`MIN_LABEL_PT` (e.g. the units of a 1,000-block wall in one figure).

As every plot function of :mod:`rockyade.figures`: :func:`draw_assembly` and
:func:`draw_snapshots` return ``(fig, ax)`` (``(fig, axes)`` for several panels) and take
``ax=`` to draw into your own Axes; :func:`animate` returns ``(fig, ax, animation)``. With a
``path`` the figure is drawn by Agg outside pyplot and written atomically; with neither
``path`` nor ``ax`` it comes from pyplot on your backend (inline in a notebook). Nothing
here selects a backend or calls ``plt.show()``. :func:`write_snapshots` writes the PNGs of
``rockyade run --snapshots`` (a grid, or one file per time).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import LinearSegmentedColormap, Normalize
from matplotlib.figure import Figure
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.figures.block_drawing import (
    FIGURE_WIDTH_IN,
    STONE,
    bounds_of,
    draw_blocks,
    draw_rest_outline,
    figure_for,
    setup_axes,
)
from rockyade.figures.canvas import axes_list, save_figure
from rockyade.io.atomic import atomic_path
from rockyade.result import Result, column
from rockyade.scene.placement import PlacedBlock, placed_blocks, rotation_matrix

#: Labels smaller than MIN_LABEL_PT (points) are left out, larger than MAX_LABEL_PT capped;
#: below READABLE_LABEL_PT for most blocks, no label is printed.
MIN_LABEL_PT = 4.5
READABLE_LABEL_PT = 6.0
MAX_LABEL_PT = 10.0
#: Colours of moving blocks by |rotation|: stone at rest, dark red at the largest rotation shown.
ROTATION_CMAP = LinearSegmentedColormap.from_list("stone_to_red", [STONE, "#e8a15c", "#c0392b", "#5e0d0d"])
#: The ``gid`` of the block names drawn (:func:`drawn_names`).
NAME_GID = "block-name"


# ---------------------------------------------------------------------- geometry


def moving_polygons(placed: Sequence[PlacedBlock], result: Result, index: int, scale: float = 1.0) -> list[np.ndarray]:
    """Polygons of the blocks at sample ``index`` of ``result``, base frame, m.

    Fixed blocks, and blocks the result has no columns for, are drawn at rest.
    """
    names = result.blocks
    frame = result.frame
    out = []
    for b in placed:
        key = column(b.name, "theta_rad", names)
        if b.fixed or b.name not in names or key not in frame:
            out.append(b.vertices_m)
            continue
        theta = float(frame[key].iat[index])
        dx = float(frame[column(b.name, "x_m", names)].iat[index])
        dy = float(frame[column(b.name, "y_m", names)].iat[index])
        c = np.asarray(b.centroid_m)
        moved = (b.vertices_m - c) @ rotation_matrix(theta).T + c + np.array([dx, dy])
        out.append(b.vertices_m + scale * (moved - b.vertices_m))
    return out


def rotations(placed: Sequence[PlacedBlock], result: Result, index: int) -> np.ndarray:
    """|theta| of each block at sample ``index`` (0 for fixed or missing blocks), rad."""
    names = result.blocks
    out = np.zeros(len(placed))
    for i, b in enumerate(placed):
        key = column(b.name, "theta_rad", names)
        if not b.fixed and b.name in names and key in result.frame:
            out[i] = abs(float(result.frame[key].iat[index]))
    return out


def sample_index(result: Result, t_s: float, field: str = "times") -> int:
    """Index of the sample nearest ``t_s``; InputError outside the result's time span."""
    t = result.t
    if t.size == 0:
        raise InputError(field, "the result has no samples (the run failed)")
    half = 0.5 * (t[1] - t[0]) if t.size > 1 else 0.0
    if not (t[0] - half <= t_s <= t[-1] + half):
        end = f"; the run stopped at {t[-1]:.4g} s ({result.status})" if result.status != "completed" else ""
        raise InputError(field, f"t = {t_s:g} s is outside the result's {t[0]:g}-{t[-1]:g} s{end}")
    return int(np.argmin(np.abs(t - t_s)))


# ---------------------------------------------------------------------- labels


def _points_per_metre(fig, ax) -> float:
    """Drawing scale after layout (equal aspect), points per metre."""
    fig.canvas.draw()
    (x0, _), (x1, _) = ax.transData.transform([(0.0, 0.0), (1.0, 0.0)])
    return abs(x1 - x0) * 72.0 / fig.dpi


def _label_blocks(fig, ax, placed: Sequence[PlacedBlock]) -> int:
    """Write each block's name inside it where it fits; return how many were left out.

    Names share one size (the median of what fits, at most MAX_LABEL_PT); a block too small
    for it gets a smaller one, down to MIN_LABEL_PT, below which its name is left out. When
    the shared size would be below READABLE_LABEL_PT no name is printed.
    """
    scale = _points_per_metre(fig, ax)
    fits = []
    for b in placed:
        local = (b.vertices_m - np.asarray(b.centroid_m)) @ rotation_matrix(-b.rotation_rad).T
        w, h = np.ptp(local, axis=0) * scale
        chars = max(len(b.name), 1)
        along = min(0.7 * h, 0.9 * w / (0.62 * chars), MAX_LABEL_PT)
        across = min(0.7 * w, 0.9 * h / (0.62 * chars), MAX_LABEL_PT)
        fits.append((along, 0.0) if along >= 0.8 * across else (across, 90.0))  # prefer along the base
    common = min(MAX_LABEL_PT, float(np.median([size for size, _ in fits])))
    if common < READABLE_LABEL_PT:  # most names would be specks: print none
        return len(placed)
    skipped = 0
    for b, (size, turn) in zip(placed, fits, strict=True):
        if size < MIN_LABEL_PT:
            skipped += 1
            continue
        angle = (math.degrees(b.rotation_rad) + turn + 90.0) % 180.0 - 90.0
        ax.text(
            *b.centroid_m,
            b.name,
            ha="center",
            va="center",
            rotation=angle,
            rotation_mode="anchor",
            fontsize=max(min(size, common), MIN_LABEL_PT),
            color="#2b241b",
            zorder=5,
            gid=NAME_GID,
            bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=1.0) if b.fixed else None,
        )
    return skipped


def _title(scene, label: str | None) -> str:
    n = len(scene.blocks)
    n_fixed = sum(1 for b in scene.blocks if b.fixed)
    name = label or (Path(scene.source).name if scene.source else "scene")
    fixed = f", {n_fixed} fixed (grey, hatched)" if n_fixed else ""
    return f"{name}: {n} block{'s' if n != 1 else ''}{fixed}"


# ---------------------------------------------------------------------- figures


def drawn_names(ax) -> list[str]:
    """The block names written in ``ax`` by :func:`draw_assembly` (those that fitted).

    Parameters
    ----------
    ax
        The Axes :func:`draw_assembly` drew into.
    """
    return [t.get_text() for t in ax.texts if t.get_gid() == NAME_GID]


def draw_assembly(
    scene, path: str | Path | None = None, title: str | None = None, labels: bool = True, *, ax=None
) -> tuple[Figure, Axes]:
    """Draw a scene's blocks at rest with their names.

    Parameters
    ----------
    scene
        A validated :class:`~rockyade.scene.Scene`.
    path
        PNG file to write (atomically); None writes nothing.
    title
        Axes title (default: the scene file name and block counts; when names had to be
        left out, a second line names the bottom-left and top-right blocks).
    labels
        Write block names (where they fit; :func:`drawn_names` lists those written).
    ax
        Axes to draw into (equal aspect, limits and ground set here); None: a new figure
        (pyplot's without ``path``, so that it shows in a notebook).

    Returns
    -------
    fig, ax
        The figure and its Axes.
    """
    placed = placed_blocks(scene)
    polygons = [b.vertices_m for b in placed]
    bounds = bounds_of(polygons)
    if ax is None:
        fig, axes = figure_for(bounds, path=path)
        ax = axes[0, 0]
    else:
        ax = axes_list(ax, 1)[0]
        fig = ax.figure
    setup_axes(ax, bounds)
    draw_blocks(ax, polygons, [b.fixed for b in placed])
    skipped = _label_blocks(fig, ax, placed) if labels else 0
    heading = title or _title(scene, None)
    if skipped:
        first = min(placed, key=lambda b: (round(b.centroid_m[1], 9), b.centroid_m[0]))
        last = max(placed, key=lambda b: (round(b.centroid_m[1], 9), b.centroid_m[0]))
        heading += (
            f"\n{skipped} names too small to print: bottom left {first.name}, top right {last.name} "
            "(all in the scene file)"
        )
    ax.set_title(heading, fontsize=10)
    if path is not None:
        save_figure(fig, path)
    return fig, ax


#: The colour scale of rotations spans at least this, rad.
MIN_COLOUR_SCALE_RAD = 1e-3


def _rotation_norm(placed, result, indices) -> float:
    peak = max(float(rotations(placed, result, i).max()) for i in indices)
    return max(peak, MIN_COLOUR_SCALE_RAD)


def draw_snapshots(
    scene,
    result: Result,
    times_s: Sequence[float],
    path: str | Path | None = None,
    *,
    scale: float = 1.0,
    title: str | None = None,
    ax=None,
) -> tuple[Figure, Any]:
    """Draw the moving assembly at chosen times, one panel per time, coloured by rotation.

    Parameters
    ----------
    scene
        The scene that was run.
    result
        Its Result (per block ``theta_rad``, ``x_m``, ``y_m`` from rest).
    times_s
        Times to draw, s (the nearest samples are used).
    path
        PNG to write (atomically); None writes nothing.
    scale
        Display magnification k of displacements and rotations (1: true scale).
    title
        Figure title (default: scene file name and solver).
    ax
        Axes to draw into, one per time (one Axes for one time); None: a new figure of
        panels (pyplot's without ``path``).

    Returns
    -------
    fig, axes
        The figure and its Axes (one Axes for one time, else a list in the order of ``times_s``).
    """
    if not times_s:
        raise InputError("times", "give at least one time")
    if not (math.isfinite(scale) and scale > 0):
        raise InputError("scale", f"must be a number > 0, got {scale!r}")
    placed = placed_blocks(scene)
    indices = [sample_index(result, float(t)) for t in times_s]
    frames = [moving_polygons(placed, result, i, scale) for i in indices]
    rest = [b.vertices_m for b in placed]
    bounds = _clip_bounds(bounds_of(rest + [p for f in frames for p in f]), bounds_of(rest))
    norm = Normalize(0.0, _rotation_norm(placed, result, indices))
    fixed = [b.fixed for b in placed]
    moving_idx = [i for i, b in enumerate(placed) if not b.fixed]
    solver = result.meta.solver
    heading = title or (_title(scene, None) + (f" ({solver})" if solver else ""))
    if scale != 1.0:
        heading += f"; vertex displacements x{scale:g}"
    n = len(indices)
    if ax is None:
        aspect = (bounds[1] - bounds[0]) / max(bounds[3] - bounds[2], 1e-9)
        cols = min(n, 3 if aspect < 1.3 else 2 if aspect < 2.6 else 1)
        rows = math.ceil(n / cols)
        fig, grid = figure_for(bounds, (rows, cols), width_in=FIGURE_WIDTH_IN + 1.0, path=path)
        panels = list(grid.flat)
        for extra in panels[n:]:
            extra.set_visible(False)
        panels = panels[:n]
    else:
        panels = axes_list(ax, n)
        fig = panels[0].figure
    for k, panel in enumerate(panels):
        setup_axes(panel, bounds)
        draw_rest_outline(panel, rest)
        colours = ROTATION_CMAP(norm(rotations(placed, result, indices[k])[moving_idx]))
        draw_blocks(panel, frames[k], fixed, facecolors=colours)
        panel.set_title(f"t = {result.t[indices[k]]:.3f} s", fontsize=10)
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=ROTATION_CMAP), ax=panels, shrink=0.8, pad=0.02)
    bar.set_label("|rotation from rest| (rad)")
    fig.suptitle(heading + ("\nrest positions dashed; positions relative to the base" if n > 1 else ""), fontsize=10)
    if path is not None:
        save_figure(fig, path)
    return fig, panels[0] if n == 1 else panels


def write_snapshots(
    scene,
    result: Result,
    times_s: Sequence[float],
    path: str | Path,
    layout: str = "grid",
    scale: float = 1.0,
    title: str | None = None,
) -> list[Path]:
    """Write snapshots of a run as PNG: one grid of panels (``layout = "grid"``, ``path``) or
    one file per time (``"files"``, ``<stem>_t<time>s.png`` beside ``path``).

    Parameters
    ----------
    scene, result, times_s, scale, title
        As for :func:`draw_snapshots`.
    path
        The PNG (grid) or the name the files are made from (files).
    layout
        "grid" or "files".

    Returns
    -------
    list of Path
        Files written.
    """
    if layout not in ("grid", "files"):
        raise InputError("layout", f"must be grid or files, got {layout!r}")
    path = Path(path)
    if layout == "grid":
        draw_snapshots(scene, result, times_s, path, scale=scale, title=title)
        return [path]
    if not times_s:
        raise InputError("times", "give at least one time")
    written = []
    for t in times_s:
        out = path.with_name(f"{path.stem}_t{result.t[sample_index(result, float(t))]:.3f}s.png")
        draw_snapshots(scene, result, [t], out, scale=scale, title=title)
        written.append(out)
    return written


def _clip_bounds(bounds, rest_bounds) -> tuple[float, float, float, float]:
    """The drawn area: everything, but no more than one assembly size beyond the rest bounds
    sideways and upwards, and not below the base (a block thrown far away leaves the picture
    rather than shrinking the assembly)."""
    x0, x1, y0, y1 = rest_bounds
    size = max(x1 - x0, y1 - y0)
    return (max(bounds[0], x0 - size), min(bounds[1], x1 + size), max(bounds[2], y0), min(bounds[3], y1 + size))


def animation_writer_for(path: str | Path, fps: float):
    """The matplotlib writer for ``path``: Pillow for .gif, ffmpeg for .mp4.

    Raises
    ------
    InputError
        Another suffix, or a writer that is not available here (saying which is).
    """
    from matplotlib import animation

    suffix = Path(path).suffix.lower()
    if suffix == ".gif":
        if not animation.writers.is_available("pillow"):
            raise InputError("animation", "writing a GIF needs Pillow, which is not installed (pip install pillow)")
        return animation.PillowWriter(fps=fps)  # type: ignore[arg-type]  # any fps > 0 works; the stub says int
    if suffix == ".mp4":
        if not animation.writers.is_available("ffmpeg"):
            raise InputError(
                "animation", "writing an MP4 needs ffmpeg, which is not installed here: write a .gif instead"
            )
        return animation.FFMpegWriter(fps=fps)  # type: ignore[arg-type]  # any fps > 0 works; the stub says int
    raise InputError("animation", f"must end in .gif (Pillow) or .mp4 (ffmpeg), got {suffix or 'no suffix'!r}")


def animation_times(result: Result, fps: float, speed: float, max_frames: int = 600) -> NDArray[np.float64]:
    """Simulated times of the frames of :func:`animate`, s: every ``speed / fps`` seconds, or
    further apart so that there are at most ``max_frames``.

    Parameters
    ----------
    result
        The run.
    fps
        Frames per second of the animation.
    speed
        Simulated seconds per second of animation.
    max_frames
        Upper bound on the number of frames.
    """
    t = result.t
    if t.size == 0:
        raise InputError("animation", "the result has no samples (the run failed)")
    step = max(speed / fps, (t[-1] - t[0]) / max(max_frames - 1, 1))
    return np.arange(t[0], t[-1] + 0.5 * step, step)


def animate(
    scene,
    result: Result,
    path: str | Path | None = None,
    fps: float = 20.0,
    speed: float = 1.0,
    scale: float = 1.0,
    max_frames: int = 600,
    *,
    ax=None,
):
    """An animation of the run; written as GIF (Pillow) or MP4 (ffmpeg) when ``path`` is given.

    Parameters
    ----------
    scene, result
        The scene and its run.
    path
        .gif or .mp4 to write (atomically: :func:`rockyade.io.atomic.atomic_path`); None writes nothing.
    fps
        Frames per second of the animation.
    speed
        Simulated seconds per second of animation (1: real time, 0.25: slow motion).
    scale
        Display magnification of displacements and rotations.
    max_frames
        Upper bound on the number of frames (the time step between frames grows to fit;
        :func:`animation_times`).
    ax
        Axes to animate in; None: a new figure (pyplot's without ``path``).

    Returns
    -------
    fig, ax, animation
        The figure, its Axes and the :class:`matplotlib.animation.FuncAnimation` (keep it: in
        Jupyter, ``IPython.display.HTML(animation.to_jshtml())`` plays it).
    """
    from matplotlib import animation

    if not (math.isfinite(fps) and fps > 0):
        raise InputError("fps", f"must be a number > 0, got {fps!r}")
    if not (math.isfinite(speed) and speed > 0):
        raise InputError("speed", f"must be a number > 0, got {speed!r}")
    writer = animation_writer_for(path, fps) if path is not None else None
    t = result.t
    times = animation_times(result, fps, speed, max_frames)
    indices = [int(np.argmin(np.abs(t - x))) for x in times]
    placed = placed_blocks(scene)
    rest = [b.vertices_m for b in placed]
    frames = [moving_polygons(placed, result, i, scale) for i in indices]
    bounds = _clip_bounds(bounds_of(rest + [p for f in frames for p in f]), bounds_of(rest))
    if ax is None:
        fig, axes = figure_for(bounds, width_in=8.0, path=path)
        ax = axes[0, 0]
    else:
        ax = axes_list(ax, 1)[0]
        fig = ax.figure
    setup_axes(ax, bounds)
    draw_rest_outline(ax, rest)
    fixed = [b.fixed for b in placed]
    moving_idx = [i for i, b in enumerate(placed) if not b.fixed]
    norm = Normalize(0.0, _rotation_norm(placed, result, indices))
    coll = draw_blocks(ax, frames[0], fixed)
    clock = ax.set_title("", fontsize=10)
    note = f" (motion x{scale:g})" if scale != 1.0 else ""

    def update(k: int):
        coll.set_verts([p for p, f in zip(frames[k], fixed, strict=True) if not f])
        coll.set_facecolor(ROTATION_CMAP(norm(rotations(placed, result, indices[k])[moving_idx])))
        clock.set_text(f"{_title(scene, None)}\nt = {t[indices[k]]:.2f} s{note}")
        return coll, clock

    if path is not None:
        _write_frames(fig, update, len(indices), path, writer)
    update(0)
    anim = animation.FuncAnimation(fig, update, frames=len(indices), blit=False)
    if path is not None:
        # its frames are in the file: matplotlib would warn that it was dropped unseen
        anim._draw_was_started = True  # type: ignore[attr-defined]
    return fig, ax, anim


def _write_frames(fig, update, n_frames: int, path: str | Path, writer) -> None:
    """Each frame drawn once into ``writer`` (``FuncAnimation.save`` draws each twice), with
    the layout of the first frame kept: the blocks move inside axes whose limits do not change,
    so the constrained layout is solved once rather than on every frame. After the first frame
    the figure has no layout engine at all: with any engine, even ``"none"``'s placeholder,
    each ``savefig`` of the writer draws the figure once more before drawing it into the frame.
    The writer opens the file itself and takes its format from its suffix; written atomically."""
    engine = fig.get_layout_engine()
    with atomic_path(path) as tmp, writer.saving(fig, str(tmp), dpi=90):
        for k in range(n_frames):
            update(k)
            writer.grab_frame()
            if k == 0:
                with matplotlib.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
                    fig.set_layout_engine(None)  # None under these settings: no engine
    fig.set_layout_engine(engine)
