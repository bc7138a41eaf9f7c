"""Collapse of an assembly: the state of every block over time, which blocks fell and when.

Each moving block is, at each sample, in one of six states (codes in :data:`STATES`):

* ``fallen``: it has come down for good (:func:`rockyade.dem.overturn.block_fall`, the rule
  the DEMs' run status follows too), from the first of: it lies on another face (|theta|
  within ``LANDING_TOL_RAD`` of its landing angle); it ends the run dropped by more than
  ``DROP_FRACTION`` of its height (carried down by the blocks under it, or fallen off them)
  and has stopped descending (it hit something: vertical speed above -``LAND_SPEED_M_S``);
  it ends the run beyond its tipping angle alpha, leaning on a neighbour or on rubble, and
  has stopped turning after its last passage of alpha (``REST_SPIN_RAD_S``). Once fallen,
  fallen to the end;
* ``falling``: on its way down: from its last passage of alpha before it fell (from there
  gravity alone no longer brings it back; ``tipped_time_s``), or for a block carried down or
  dropping flat from when it last went below half its height, until it has fallen. A block
  still descending or turning beyond alpha when the run ends is ``falling`` to the end: it
  has not fallen within the run, and a longer run says where it lands;
* ``sliding``: its base slides on what it rests on: the point of the block that was the
  middle of its base at rest moves along the joint, relative to the block (or base) under
  it, faster than ``SLIDE_SPEED_M_S`` beyond what its rocking on that block explains
  (rocking about a corner moves that point by b (1 - cos theta)), on every block it rests
  on, and, where the result records it (both DEMs' ``slipping``; Housner has none), one of
  its contacts slips. A drum carried by the rocking drums under it moves fast with them but
  does not slide on them;
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

from rockyade.dem.overturn import (
    DROP_FRACTION,
    LAND_SPEED_M_S,
    LANDING_TOL_RAD,
    REST_SPIN_RAD_S,
    Fall,
    block_fall,
    landing_angles,
)
from rockyade.result import Result
from rockyade.scene import Scene
from rockyade.scene.placement import placed_blocks, scene_rest_contacts

STATES = ("rest", "rocking", "sliding", "fallen", "carried", "falling")
REST, ROCKING, SLIDING, FALLEN, CARRIED, FALLING = range(6)

__all__ = [
    "CARRIED",
    "DROP_FRACTION",
    "FALLEN",
    "FALLING",
    "LANDING_TOL_RAD",
    "LAND_SPEED_M_S",
    "REST",
    "REST_SPIN_RAD_S",
    "ROCKING",
    "SLIDING",
    "STATES",
    "BlockGeometry",
    "block_geometry",
    "block_states",
    "collapse_report",
    "state_frame",
]

#: Rocking: |theta| above this fraction of alpha ...
ROCK_FRACTION = 0.01
#: ... and above this absolute rotation (the contacts' elastic tilt is ~1e-5 rad).
ROCK_MIN_RAD = 1e-4
#: Sliding: speed of the base's middle point along the joint it rests on above this, m/s.
SLIDE_SPEED_M_S = 0.01


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
    bodies = result.meta.bodies or {}
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


class _Columns:
    """A result's per-block columns as float arrays, each looked up once (a DataFrame
    lookup costs ~0.1 ms; a 1,000-block wall asks for each column several times)."""

    def __init__(self, result: Result) -> None:
        self.result = result
        self._arrays: dict[tuple[str, str], NDArray[np.float64]] = {}

    def __call__(self, quantity: str, name: str) -> NDArray[np.float64]:
        key = (quantity, name)
        array = self._arrays.get(key)
        if array is None:
            array = self._arrays[key] = np.asarray(self.result.series(quantity, name), dtype=float)
        return array


def block_states(scene: Scene, result: Result) -> tuple[NDArray[np.int8], list[BlockGeometry]]:
    """(n_samples, n_moving) state codes (see module docstring) and the blocks' geometry.

    Parameters as :func:`block_geometry`."""
    states, geometry, _ = _block_states(scene, result, _Columns(result))
    return states, geometry


def _block_states(
    scene: Scene, result: Result, columns: _Columns
) -> tuple[NDArray[np.int8], list[BlockGeometry], list[Fall]]:
    """:func:`block_states`, and each block's :func:`block_fall_of`."""
    geometry = block_geometry(scene, result)
    falls = []
    t = result.t
    n = t.size
    states = np.zeros((n, len(geometry)), dtype=np.int8)
    dt = float(t[1] - t[0]) if n > 1 else 1.0
    supports, centroids = _supports(scene)
    for j, g in enumerate(geometry):
        theta = columns("theta_rad", g.name)
        x = columns("x_m", g.name)
        y = columns("y_m", g.name)
        fall = block_fall_of(g, result, columns)
        falls.append(fall)
        rocking = np.abs(theta) > max(ROCK_MIN_RAD, ROCK_FRACTION * g.alpha_rad)
        sliding = _sliding(columns, g, supports.get(g.name, []), centroids, dt)
        slipping = _slipping(result, g.name)
        if slipping is not None:  # the DEM says whether a contact slips
            sliding &= slipping
        moving = np.zeros(n, dtype=bool)
        if n > 1:
            moving = (np.hypot(np.gradient(x, dt), np.gradient(y, dt)) > SLIDE_SPEED_M_S) | (
                np.abs(np.gradient(theta, dt)) > REST_SPIN_RAD_S
            )
        code = np.where(moving, CARRIED, REST)
        code = np.where(rocking, ROCKING, code)
        code = np.where(sliding, SLIDING, code)
        if fall.falling >= 0:
            code[fall.falling :] = FALLING
        if fall.fell:
            code[fall.fall :] = FALLEN
        states[:, j] = code
    return states, geometry, falls


@dataclass(frozen=True)
class _Support:
    """A joint a block rests on at rest: the block (or base, None) under it, the joint's
    middle (base frame, m) and its direction (unit vector along the joint)."""

    below: str | None
    point_m: tuple[float, float]
    tangent: tuple[float, float]


def _supports(scene: Scene) -> tuple[dict[str, list[_Support]], dict[str, tuple[float, float]]]:
    """Per moving block, the joints it rests on: its bed joints with a block or the base
    under it; a block without one (a voussoir between radial joints) takes all its joints.
    And every block's centroid at rest (base frame, m)."""
    placed = placed_blocks(scene)
    contacts = scene_rest_contacts(scene)
    out: dict[str, list[_Support]] = {}
    touching: dict[str, list[_Support]] = {}
    for c in contacts:
        mid = tuple(0.5 * (np.asarray(c.ends_m[0]) + np.asarray(c.ends_m[1])))
        tangent = (c.normal[1], -c.normal[0])
        pairs = [(c.a, c.b), (c.b, c.a)] if c.b >= 0 else [(c.a, -1)]
        for me, other in pairs:
            if placed[me].fixed:
                continue
            below = None if other < 0 or placed[other].fixed else placed[other].name
            support = _Support(below, (float(mid[0]), float(mid[1])), tangent)
            touching.setdefault(placed[me].name, []).append(support)
            if c.kind == "bed" and c.upper == me:
                out.setdefault(placed[me].name, []).append(support)
    for b in placed:
        if not b.fixed and b.name not in out:
            out[b.name] = touching.get(b.name, [])
    return out, {b.name: b.centroid_m for b in placed}


def _material_point(
    columns: _Columns, n: int, name: str | None, point_m: NDArray[np.float64], centroid_m: tuple[float, float]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Path (x, y) of the material point of block ``name`` that was at ``point_m`` at rest,
    and the block's rotation, over ``n`` samples; the base (None) does not move in the base frame."""
    if name is None:
        return np.full(n, point_m[0]), np.full(n, point_m[1]), np.zeros(n)
    theta = columns("theta_rad", name)
    rx, ry = point_m[0] - centroid_m[0], point_m[1] - centroid_m[1]
    c, s = np.cos(theta), np.sin(theta)
    x = centroid_m[0] + columns("x_m", name) + c * rx - s * ry
    y = centroid_m[1] + columns("y_m", name) + s * rx + c * ry
    return x, y, theta


def _sliding(
    columns: _Columns,
    g: BlockGeometry,
    supports: list[_Support],
    centroids: dict[str, tuple[float, float]],
    dt: float,
) -> NDArray[np.bool_]:
    """Samples at which the block slides on every joint it rests on (see module docstring)."""
    n = columns("theta_rad", g.name).size
    if n < 2:
        return np.zeros(n, dtype=bool)
    if not supports:  # in the air at rest: against the base
        supports = [_Support(None, (0.0, 0.0), (1.0, 0.0))]
    sliding = np.ones(n, dtype=bool)
    for sup in supports:
        point = np.asarray(sup.point_m, dtype=float)
        xj, yj, thj = _material_point(columns, n, g.name, point, centroids[g.name])
        xs, ys, ths = _material_point(columns, n, sup.below, point, centroids[sup.below] if sup.below else (0.0, 0.0))
        # the joint's direction turns with the block under it
        tx = np.cos(ths) * sup.tangent[0] - np.sin(ths) * sup.tangent[1]
        ty = np.sin(ths) * sup.tangent[0] + np.cos(ths) * sup.tangent[1]
        along = tx * (xj - xs) + ty * (yj - ys)
        speed = np.abs(np.gradient(along, dt))
        relative = thj - ths
        rocking_speed = np.abs(np.gradient(relative, dt)) * abs(g.base_mid_m[1]) * np.abs(np.sin(relative))
        sliding &= speed > SLIDE_SPEED_M_S + rocking_speed
    return sliding


def _slipping(result: Result, name: str) -> NDArray[np.bool_] | None:
    """The DEMs' per-block slip flag (one of the block's contact points slips), if recorded."""
    try:
        return np.asarray(result.series("slipping", name), dtype=bool)
    except KeyError:
        return None


def block_fall_of(g: BlockGeometry, result: Result, columns: _Columns | None = None) -> Fall:
    """:func:`rockyade.dem.overturn.block_fall` of one block of a result (sample indices).

    Parameters
    ----------
    g
        The block (:func:`block_geometry`).
    result
        The run's Result (any solver).
    columns
        The result's columns, each looked up once (internal)."""
    columns = columns or _Columns(result)
    return block_fall(
        result.t,
        columns("theta_rad", g.name),
        columns("y_m", g.name),
        g.alpha_rad,
        g.landing_rad,
        g.height_m,
        _solver_fall_time(result, g.name),
    )


def _solver_fall_time(result: Result, name: str) -> float | None:
    """When the solver found the block lying on another face (between samples), s."""
    if result.meta.overturn_times_s is not None:  # both DEMs: per block
        times = result.meta.overturn_times_s or {}
        return float(times[name]) if name in times else None
    if result.meta.overturned_block == name and result.meta.overturn_time_s is not None:
        return float(result.meta.overturn_time_s)
    return None


def collapse_report(scene: Scene, result: Result) -> pd.DataFrame:
    """One row per moving block: whether and when it fell, time spent rocking and sliding,
    peak and residual rotation and displacement.

    Columns: ``block``, ``fell`` (it came down within the run), ``fall_time_s``,
    ``falling_at_end`` (the run ended while it was still falling: not fallen),
    ``tipped_time_s`` (its last passage of alpha before it fell, or before the end while
    falling), ``max_abs_theta_rad``, ``max_theta_over_alpha``, ``residual_theta_rad``,
    ``residual_x_m``, ``residual_y_m``, ``rocking_time_s``, ``sliding_time_s``,
    ``final_state``. Times in s, angles in rad, displacements in m.

    Parameters as :func:`block_geometry`.
    """
    columns = _Columns(result)
    states, geometry, falls = _block_states(scene, result, columns)
    t = result.t
    dt = float(t[1] - t[0]) if t.size > 1 else 0.0
    rows = []
    for j, g in enumerate(geometry):
        theta = columns("theta_rad", g.name)
        finite = np.isfinite(theta)
        last = int(np.flatnonzero(finite)[-1]) if finite.any() else -1
        fall = falls[j]
        rows.append(
            {
                "block": g.name,
                "fell": fall.fell,
                "fall_time_s": float(t[fall.fall]) if fall.fell else math.nan,
                "falling_at_end": fall.falling_at_end,
                "tipped_time_s": float(t[fall.tip]) if fall.tip >= 0 else math.nan,
                "max_abs_theta_rad": float(np.nanmax(np.abs(theta))) if finite.any() else math.nan,
                "max_theta_over_alpha": float(np.nanmax(np.abs(theta)) / g.alpha_rad) if finite.any() else math.nan,
                "residual_theta_rad": float(theta[last]) if last >= 0 else math.nan,
                "residual_x_m": float(columns("x_m", g.name)[last]) if last >= 0 else math.nan,
                "residual_y_m": float(columns("y_m", g.name)[last]) if last >= 0 else math.nan,
                "rocking_time_s": float(np.sum(states[:, j] == ROCKING) * dt),
                "sliding_time_s": float(np.sum(states[:, j] == SLIDING) * dt),
                "final_state": STATES[int(states[last, j])] if last >= 0 else "rest",
            }
        )
    return pd.DataFrame(rows)


def state_frame(scene: Scene, result: Result) -> pd.DataFrame:
    """The states as a DataFrame: ``t_s`` (s) and one categorical column per moving block.

    Parameters as :func:`block_geometry`."""
    states, geometry = block_states(scene, result)
    data: dict[str, object] = {"t_s": result.t}
    for j, g in enumerate(geometry):
        data[g.name] = pd.Categorical.from_codes(states[:, j], categories=list(STATES))
    return pd.DataFrame(data)
