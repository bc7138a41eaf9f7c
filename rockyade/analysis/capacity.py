"""The capacity curve of a pushover run and the onset of the mechanism it shows.

A pushover (:class:`rockyade.motion.quasistatic.Pushover`) raises the horizontal base
acceleration slowly after the gravity ramp; the load multiplier is lambda(t) = |a_h| / g.
The capacity curve is lambda against the horizontal displacement of a control point along
the push (a block and a material point of it; default the top block's top centre), from
its position when the push starts (after the gravity ramp and the settling).

The displacement of a material point p of a block that turned by theta and whose centroid
moved by (x, y) is (x, y) + (R(theta) - I) (p - c), c the centroid at rest; the Result's
``x_m``, ``y_m`` and ``theta_rad`` give all three.

The onset (:func:`pushover_onset`): with held levels, the first level during whose hold the
control displacement grows by more than ``threshold_m`` (the assembly does not stand at it:
the mechanism has formed, and lambda_limit lies between the level before and this one);
with a continuous rise, the first lambda at which the control point has moved by more than
``threshold_m`` from its position when the push started (this includes the ramp's dynamic
lag: about +2 % on a block at 0.1 g/s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.motion.quasistatic import Pushover
from rockyade.result import Result
from rockyade.scene import Scene
from rockyade.scene.placement import placed_blocks

#: Default onset threshold: growth of the control displacement, m.
ONSET_THRESHOLD_M = 1.0e-3


def control_point(scene: Scene, block: str | None = None, point_m: tuple[float, float] | None = None):
    """The control block's index and the control point at rest, base frame, m.

    Parameters
    ----------
    block
        Block name; default the moving block whose top is highest.
    point_m
        Base-frame point at rest, m; default the top centre of that block (the mean x of its
        highest vertices).
    """
    placed = placed_blocks(scene)
    if block is None:
        moving = [b for b in placed if not b.fixed]
        index = max(moving, key=lambda b: (float(b.vertices_m[:, 1].max()), b.index)).index
    else:
        names = [b.name for b in placed]
        if block not in names:
            raise InputError("control_block", f"no block named {block!r}; blocks: {names[:20]}")
        index = names.index(block)
    if point_m is None:
        v = placed[index].vertices_m
        top = v[:, 1].max()
        highest = v[v[:, 1] >= top - 1e-9 * max(1.0, abs(top))]
        point_m = (float(highest[:, 0].mean()), float(top))
    return index, (float(point_m[0]), float(point_m[1]))


def _direction(scene: Scene) -> float:
    direction = getattr(scene.motion, "direction", "+x")
    return 1.0 if direction == "+x" else -1.0


def _push_start(scene: Scene) -> float:
    start = getattr(scene.motion, "push_start_s", None)
    return float(start) if start is not None else 0.0


def capacity_curve(
    result: Result, scene: Scene, block: str | None = None, point_m: tuple[float, float] | None = None
) -> pd.DataFrame:
    """The capacity curve of a run (module docstring).

    Parameters
    ----------
    result
        A DEM (or Housner) Result of ``scene``.
    scene
        The scene it ran (a pushover, or any motion with a horizontal base acceleration).
    block, point_m
        The control block and point (:func:`control_point`).

    Returns
    -------
    pandas.DataFrame
        ``t_s``; ``lambda`` = |a_h| / g; ``displacement_m``, the control point's horizontal
        displacement along the push from its position when the push started, m;
        ``control_x_m``, ``control_y_m`` its absolute displacement from rest, m.
    """
    index, point = control_point(scene, block, point_m)
    name = scene.blocks[index].name
    placed = placed_blocks(scene)[index]
    rx, ry = point[0] - placed.centroid_m[0], point[1] - placed.centroid_m[1]
    t = result.t
    theta = result.series("theta_rad", name)
    x = result.series("x_m", name)
    y = result.series("y_m", name)
    c, s = np.cos(theta), np.sin(theta)
    ux = x + (c - 1.0) * rx - s * ry
    uy = y + s * rx + (c - 1.0) * ry
    start = _push_start(scene)
    k0 = int(np.searchsorted(t, start - 1e-9)) if t.size else 0
    k0 = min(k0, max(t.size - 1, 0))
    sign = _direction(scene)
    lam = np.abs(result.frame["ag_m_s2"].to_numpy()) / G
    return pd.DataFrame(
        {
            "t_s": t,
            "lambda": lam,
            "displacement_m": sign * (ux - (ux[k0] if ux.size else 0.0)),
            "control_x_m": ux,
            "control_y_m": uy,
        }
    )


@dataclass(frozen=True)
class Onset:
    """Where a pushover's mechanism formed.

    Attributes
    ----------
    multiplier
        The onset's lambda (NaN: none within the run).
    below
        The last held level at which the assembly stood (NaN without levels or none).
    time_s
        When the onset was seen, s.
    rule
        How it was measured, in words.
    """

    multiplier: float
    below: float
    time_s: float
    rule: str


def pushover_onset(curve: pd.DataFrame, scene: Scene, threshold_m: float = ONSET_THRESHOLD_M) -> Onset:
    """The onset of the mechanism in a pushover's capacity curve (module docstring).

    Parameters
    ----------
    curve
        :func:`capacity_curve` of the run.
    scene
        The scene (a ``pushover`` motion gives the held levels and their times).
    threshold_m
        Growth of the control displacement that marks the onset, m.
    """
    if not (isinstance(threshold_m, (int, float)) and math.isfinite(threshold_m) and threshold_m > 0):
        raise InputError("threshold_m", f"must be a length > 0 in metres, got {threshold_m!r}")
    t = curve["t_s"].to_numpy()
    u = curve["displacement_m"].to_numpy()
    lam = curve["lambda"].to_numpy()
    motion = scene.motion
    levels = motion.levels() if isinstance(motion, Pushover) else np.zeros(0)
    if isinstance(motion, Pushover) and levels.size:
        t_path, lam_path = motion.lambda_path(scene.duration_s)
        below = math.nan
        for level in levels:
            # the hold of this level: the path's flat stretch at it
            flat = np.nonzero((lam_path[:-1] == level) & (lam_path[1:] == level))[0]
            if flat.size == 0:
                continue
            t0, t1 = t_path[flat[0]], t_path[flat[0] + 1]
            inside = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
            if not inside.any():
                if t.size and t[-1] < scene.duration_s - 1.5 * scene.sample_dt_s:  # it stopped early (an overturn)
                    return Onset(float(level), below, float(t[-1]), "the run ended while rising to this level")
                break  # the run's duration ends before this level

            span = u[inside]
            if np.max(np.abs(span - span[0])) > threshold_m or t[-1] < t1 - 1e-9:
                grown = np.nonzero(np.abs(span - span[0]) > threshold_m)[0]
                when = float(t[inside][grown[0]]) if grown.size else float(t[inside][-1])
                rule = (
                    f"first held level at which the control displacement grew by more than {threshold_m:g} m "
                    "during the hold (or the run ended in it)"
                )
                return Onset(float(level), below, when, rule)
            below = float(level)
        return Onset(math.nan, below, math.nan, "no held level showed the mechanism")
    start = _push_start(scene)
    moved = np.nonzero((t >= start) & (np.abs(u) > threshold_m))[0]
    rule = f"first lambda at which the control point moved more than {threshold_m:g} m from where the push started"
    if moved.size == 0:
        return Onset(math.nan, math.nan, math.nan, rule)
    k = int(moved[0])
    return Onset(float(lam[k]), math.nan, float(t[k]), rule)
