"""Collapse of an assembly: the state of every block over time, which blocks fell and when.

Each moving block is, at each sample, in one of five states (codes in :data:`STATES`):

* ``fallen``: it has come down for good, from the first of: it lies on another face
  (|theta| within ``LANDING_TOL_RAD`` of its landing angle, :mod:`rockyade.dem.overturn`:
  the DEMs' overturn criterion); it ends the run dropped by more than ``DROP_FRACTION`` of
  its height (carried down by the blocks under it, or fallen off them) and has stopped
  descending (it hit something: vertical speed above -``LAND_SPEED_M_S``); it ends the run
  beyond its tipping angle alpha, leaning on a neighbour or on rubble, and has stopped
  turning after its last passage of alpha (``REST_SPIN_RAD_S``). A block still moving at
  the end of the run falls at its last sample. Once fallen, fallen to the end. The report
  also gives ``tipped_time_s``, when the block last passed alpha before falling (from there
  gravity alone no longer brings it back; none for a block carried down or dropping flat);
* ``sliding``: its base slides: the horizontal speed of the point of the block that was the
  middle of its base at rest exceeds ``SLIDE_SPEED_M_S`` while it is not rocking fast
  enough to explain it (rocking about a corner moves that point by b (1 - cos theta)), and,
  where the result records it (both DEMs' ``slipping``; Housner has none), one of the block's
  contacts slips: a drum carried by the rocking drums under it moves fast but does not slide;
* ``rocking``: |theta| above ``ROCK_FRACTION`` x alpha (and at least ``ROCK_MIN_RAD``);
* ``carried``: none of the above, but it moves (its centroid faster than ``SLIDE_SPEED_M_S``
  or it turns faster than ``REST_SPIN_RAD_S``): a beam on rocking columns, a course on a
  rocking wall;
* ``rest`` otherwise.

The thresholds are stated here and in docs/assemblies.md; none depends on the solver, so
the same analysis reads Housner, reference DEM and YADE results.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from rockyade.dem.overturn import LANDING_TOL_RAD, landing_angles
from rockyade.result import Result
from rockyade.scene import Scene

STATES = ("rest", "rocking", "sliding", "fallen", "carried")
REST, ROCKING, SLIDING, FALLEN, CARRIED = range(5)

#: Rocking: |theta| above this fraction of alpha ...
ROCK_FRACTION = 0.01
#: ... and above this absolute rotation (the contacts' elastic tilt is ~1e-5 rad).
ROCK_MIN_RAD = 1e-4
#: Sliding: horizontal speed of the base's middle point above this, m/s.
SLIDE_SPEED_M_S = 0.01
#: Fallen off: the centroid dropped by more than this fraction of the block height.
DROP_FRACTION = 0.5
#: A dropped block has landed when its centroid no longer descends faster than this, m/s.
LAND_SPEED_M_S = 0.05
#: A block leaning beyond alpha has come to rest when it turns slower than this, rad/s.
REST_SPIN_RAD_S = 0.05


@dataclass(frozen=True)
class BlockGeometry:
    """What the analysis needs of one block.

    Attributes
    ----------
    name
        Block name.
    alpha_rad
        Tipping angle (the DEM's own, or the classical one).
    landing_rad
        (left, right) landing angles, rad.
    height_m
        Height of the block, m.
    base_mid_m
        Middle of the base at rest relative to the centroid, rest frame, m.
    """

    name: str
    alpha_rad: float
    landing_rad: tuple[float, float]
    height_m: float
    base_mid_m: tuple[float, float]


def block_geometry(scene: Scene, result: Result) -> list[BlockGeometry]:
    """Geometry of the moving blocks (lengths in m, angles in rad), from the DEM's bodies in
    the result when it has them (both DEMs record them), else from the scene (Housner: the
    block's own polygon).

    Parameters
    ----------
    scene
        The scene that produced ``result`` (its blocks, bottom to top).
    result
        The run's Result (any solver)."""
    bodies = result.meta.get("bodies") or {}
    out = []
    for spec in scene.blocks:
        if spec.fixed:
            continue
        body = bodies.get(spec.name)
        if body is not None:
            poly = np.asarray(body["contact_vertices_m"], dtype=float)
            alpha = float(body["alpha_rad"])
        else:
            block = spec.block()
            poly = block.vertices_m - np.asarray(block.centroid_m)
            alpha = spec.classical().alpha_rad
        low = poly[:, 1] <= poly[:, 1].min() + 1e-9 * max(float(np.ptp(poly[:, 1])), 1.0)
        base_mid = (float(poly[low, 0].mean()), float(poly[:, 1].min()))
        out.append(BlockGeometry(spec.name, alpha, landing_angles(poly), float(np.ptp(poly[:, 1])), base_mid))
    return out


def _series(result: Result, quantity: str, name: str) -> NDArray[np.float64]:
    return np.asarray(result.series(quantity, name), dtype=float)


def block_states(scene: Scene, result: Result) -> tuple[NDArray[np.int8], list[BlockGeometry]]:
    """(n_samples, n_moving) state codes (see module docstring) and the blocks' geometry.

    Parameters
    ----------
    scene
        The scene that produced ``result`` (its blocks, bottom to top).
    result
        The run's Result (any solver)."""
    geometry = block_geometry(scene, result)
    t = result.t
    n = t.size
    states = np.zeros((n, len(geometry)), dtype=np.int8)
    dt = float(t[1] - t[0]) if n > 1 else 1.0
    for j, g in enumerate(geometry):
        theta = _series(result, "theta_rad", g.name)
        x = _series(result, "x_m", g.name)
        y = _series(result, "y_m", g.name)
        fallen = _fallen_mask(theta, y, g, t, _solver_fall_time(result, g.name))
        # the rest-frame middle of the base, rotated with the block, relative to its rest place
        c, s = np.cos(theta), np.sin(theta)
        bx = x + c * g.base_mid_m[0] - s * g.base_mid_m[1] - g.base_mid_m[0]
        speed = np.abs(np.gradient(bx, dt)) if n > 1 else np.zeros(n)
        rocking = np.abs(theta) > max(ROCK_MIN_RAD, ROCK_FRACTION * g.alpha_rad)
        rocking_speed = np.abs(np.gradient(theta, dt)) * abs(g.base_mid_m[1]) * np.abs(np.sin(theta)) if n > 1 else 0.0
        sliding = speed > SLIDE_SPEED_M_S + rocking_speed
        slipping = _slipping(result, g.name)
        if slipping is not None:  # the DEM says whether a contact slips: a block carried
            sliding &= slipping  # by the rocking blocks under it does not slide
        moving = np.zeros(n, dtype=bool)
        if n > 1:
            moving = (np.hypot(np.gradient(x, dt), np.gradient(y, dt)) > SLIDE_SPEED_M_S) | (
                np.abs(np.gradient(theta, dt)) > REST_SPIN_RAD_S
            )
        code = np.where(moving, CARRIED, REST)
        code = np.where(rocking, ROCKING, code)
        code = np.where(sliding, SLIDING, code)
        code = np.where(fallen, FALLEN, code)
        states[:, j] = code
    return states, geometry


def _slipping(result: Result, name: str) -> NDArray[np.bool_] | None:
    """The reference DEM's per-block slip flag (one of the block's contact points slips), if recorded."""
    try:
        return np.asarray(result.series("slipping", name), dtype=bool)
    except KeyError:
        return None


def _fall_and_tip(
    theta: NDArray[np.float64], y: NDArray[np.float64], g: BlockGeometry, t: NDArray[np.float64], t_solver: float | None
) -> tuple[int, int]:
    """Sample of the fall and of the tip that led to it (see module docstring), -1 if none.

    The fall is when the block has come down: the first sample it lies on another face; or,
    for a block that ends the run dropped by more than ``DROP_FRACTION`` of its height (it
    was carried down by the blocks under it, or fell off them), the first sample of that
    final drop at which it stops descending (it hit something); or, for a block that ends
    the run beyond its tipping angle leaning on a neighbour or on rubble, the first sample
    after its last passage of alpha at which it stops turning. Still moving at the end: the
    last sample. The tip is the last passage of alpha before the fall (-1 if the block was
    not beyond alpha when it fell: a block carried down or dropping flat).

    ``t_solver`` is the time at which the solver itself found the block overturned (between
    samples, ``meta["overturn_times_s"]``): a run that stops there ends before a sample shows it.
    """
    finite = np.isfinite(theta)
    if not finite.any():
        return -1, -1
    last = int(np.flatnonzero(finite)[-1])
    landed = (theta >= g.landing_rad[0] - LANDING_TOL_RAD) | (theta <= -(g.landing_rad[1] - LANDING_TOL_RAD))
    if t_solver is not None:
        landed |= t >= min(t_solver, float(t[last]))
    beyond = (np.abs(theta) > g.alpha_rad) & finite
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    hits = np.flatnonzero(landed & finite)
    if hits.size:
        fall = int(hits[0])
    elif y[last] < -DROP_FRACTION * g.height_m:
        up = np.flatnonzero(~(y[: last + 1] < -DROP_FRACTION * g.height_m))
        start = int(up[-1]) + 1 if up.size else 0  # the final drop, to the end of the run
        vy = np.gradient(y[: last + 1], dt) if last > 0 else np.zeros(1)
        fall = _first_settled(vy, start, last, LAND_SPEED_M_S, -1)
    elif beyond[last]:
        below = np.flatnonzero(~beyond[: last + 1])
        start = int(below[-1]) + 1 if below.size else 0
        omega = np.gradient(theta[: last + 1], dt) if last > 0 else np.zeros(1)
        fall = _first_settled(omega, start, last, REST_SPIN_RAD_S, 0)
    else:
        return -1, -1
    if not beyond[fall]:
        return fall, -1
    below = np.flatnonzero(~beyond[: fall + 1])
    tip = int(below[-1]) + 1 if below.size else 0
    return fall, tip


def _first_settled(rate: NDArray[np.float64], start: int, last: int, limit: float, sign: int) -> int:
    """First sample in [start, last] where a descent stops (``sign = -1``: rate >= -limit) or
    a motion stops (``sign = 0``: |rate| <= limit); ``last`` if it never does."""
    window = rate[start : last + 1]
    ok = window >= -limit if sign < 0 else np.abs(window) <= limit
    hit = np.flatnonzero(ok)
    return start + int(hit[0]) if hit.size else last


def _solver_fall_time(result: Result, name: str) -> float | None:
    times = result.meta.get("overturn_times_s") or {}
    if name in times:
        return float(times[name])
    if result.meta.get("overturned_block") == name and result.meta.get("overturn_time_s") is not None:
        return float(result.meta["overturn_time_s"])
    return None


def _fallen_mask(
    theta: NDArray[np.float64], y: NDArray[np.float64], g: BlockGeometry, t: NDArray[np.float64], t_solver: float | None
) -> NDArray[np.bool_]:
    """True from the sample where the block fell for good."""
    mask = np.zeros(theta.size, dtype=bool)
    fall, _ = _fall_and_tip(theta, y, g, t, t_solver)
    if fall >= 0:
        mask[fall:] = True
    return mask


def collapse_report(scene: Scene, result: Result) -> pd.DataFrame:
    """One row per moving block: whether and when it fell, time spent rocking and sliding,
    peak and residual rotation and displacement.

    Columns: ``block``, ``fell``, ``fall_time_s``, ``tipped_time_s``, ``max_abs_theta_rad``,
    ``max_theta_over_alpha``, ``residual_theta_rad``, ``residual_x_m``, ``residual_y_m``,
    ``rocking_time_s``, ``sliding_time_s``, ``final_state``.

    Parameters
    ----------
    scene
        The scene that produced ``result`` (its blocks, bottom to top).
    result
        The run's Result (any solver).
    """
    states, geometry = block_states(scene, result)
    t = result.t
    dt = float(t[1] - t[0]) if t.size > 1 else 0.0
    rows = []
    for j, g in enumerate(geometry):
        theta = _series(result, "theta_rad", g.name)
        finite = np.isfinite(theta)
        fell = np.flatnonzero(states[:, j] == FALLEN)
        last = int(np.flatnonzero(finite)[-1]) if finite.any() else -1
        _, tip = _fall_and_tip(theta, _series(result, "y_m", g.name), g, t, _solver_fall_time(result, g.name))
        rows.append(
            {
                "block": g.name,
                "fell": bool(fell.size),
                "fall_time_s": float(t[fell[0]]) if fell.size else math.nan,
                "tipped_time_s": float(t[tip]) if fell.size and tip >= 0 else math.nan,
                "max_abs_theta_rad": float(np.nanmax(np.abs(theta))) if finite.any() else math.nan,
                "max_theta_over_alpha": float(np.nanmax(np.abs(theta)) / g.alpha_rad) if finite.any() else math.nan,
                "residual_theta_rad": float(theta[last]) if last >= 0 else math.nan,
                "residual_x_m": float(_series(result, "x_m", g.name)[last]) if last >= 0 else math.nan,
                "residual_y_m": float(_series(result, "y_m", g.name)[last]) if last >= 0 else math.nan,
                "rocking_time_s": float(np.sum(states[:, j] == ROCKING) * dt),
                "sliding_time_s": float(np.sum(states[:, j] == SLIDING) * dt),
                "final_state": STATES[int(states[last, j])] if last >= 0 else "rest",
            }
        )
    return pd.DataFrame(rows)


def state_frame(scene: Scene, result: Result) -> pd.DataFrame:
    """The states as a DataFrame: ``t_s`` (s) and one categorical column per moving block.

    Parameters
    ----------
    scene
        The scene that produced ``result`` (its blocks, bottom to top).
    result
        The run's Result (any solver)."""
    states, geometry = block_states(scene, result)
    data: dict[str, object] = {"t_s": result.t}
    for j, g in enumerate(geometry):
        data[g.name] = pd.Categorical.from_codes(states[:, j], categories=list(STATES))
    return pd.DataFrame(data)
