"""When a DEM block has overturned: it has left its base and lies on another face.

Housner's model overturns a block when |theta| reaches pi/2. A DEM block rotating about a
base corner lands on the face next to that corner when the face reaches the ground:
rotating counter-clockwise (theta > 0) about its left base corner P, the face from P to the
previous vertex, at angle phi from the horizontal, lands at theta = pi - phi; clockwise
about the right corner, the face from P to the next vertex lands at |theta| = phi. For a
rectangle both are pi/2, as in Housner's model; with the base corners at the equivalent base
b_eq (paper Eq 11) the side faces lean in and the block lands a little earlier (specimen 1,
experimental alpha: 1.5655 rad); a chamfered base lands on its chamfer.

The criterion: a body has overturned at the first sample where |theta| >= landing angle -
``LANDING_TOL_RAD`` for the pivot it turns about (capped at pi/2). Once there, a block is
far beyond its tipping angle alpha (the centroid is outside its base): it cannot come back
without the base pushing it, which is also true of Housner's block between alpha and pi/2.

An assembly's run goes on past a block's fall, and its outcome follows one rule for every
block, :func:`block_fall` (the collapse table of :mod:`rockyade.analysis.collapse` applies
the same function to the same samples): a block has **fallen** when it has come down for
good (it lies on another face; or it ends the run dropped by more than half its height and
has hit something; or it ends the run leaning beyond alpha and has stopped turning), and it
is **falling** from its last passage of alpha (or, dropping, from when it last went below
half its height) until then, or to the end of a run that stops first. The run is
``overturned`` when some block has fallen, at the first fall (:func:`run_outcome`); blocks
still falling at the end do not make it so: they have not come down within the run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rockyade.blocks.geometry import LEVEL_TOL

#: How close to the landing angle counts as landed, rad (the contact's elastic tilt is ~1e-5).
LANDING_TOL_RAD = 0.01
#: Dropped: the centroid ends the run lower than its rest height by this fraction of the block height.
DROP_FRACTION = 0.5
#: A dropped block has landed when its centroid no longer descends faster than this, m/s.
LAND_SPEED_M_S = 0.05
#: A block leaning beyond alpha has come to rest when it turns slower than this, rad/s.
REST_SPIN_RAD_S = 0.05


def landing_angles(contact_vertices_m: NDArray[np.float64]) -> tuple[float, float]:
    """Landing angles of a body about its left (theta > 0) and right (theta < 0) base corners, rad.

    Parameters
    ----------
    contact_vertices_m
        (n, 2) contact polygon in the body frame (any origin), counter-clockwise, its base
        the lowest edge.
    """
    verts = np.asarray(contact_vertices_m, dtype=float)
    y = verts[:, 1]
    low = np.flatnonzero(y <= y.min() + LEVEL_TOL * max(float(np.ptp(y)), 1.0))
    left = int(low[np.argmin(verts[low, 0])])
    right = int(low[np.argmax(verts[low, 0])])
    n = len(verts)
    d_left = verts[(left - 1) % n] - verts[left]
    d_right = verts[(right + 1) % n] - verts[right]
    phi_left = math.atan2(d_left[1], d_left[0])  # in (pi/2 - ..., pi): the face leans up-left
    phi_right = math.atan2(d_right[1], d_right[0])
    return min(math.pi - phi_left, 0.5 * math.pi), min(phi_right, 0.5 * math.pi)


def overturn_thresholds(contact_polygons: list[NDArray[np.float64]]) -> NDArray[np.float64]:
    """(nb, 2) rotation at which each body counts as overturned, for theta > 0 and theta < 0."""
    out = np.empty((len(contact_polygons), 2))
    for i, poly in enumerate(contact_polygons):
        left, right = landing_angles(poly)
        out[i] = (left - LANDING_TOL_RAD, right - LANDING_TOL_RAD)
    return out


def stop_angles(contact_polygons: list[NDArray[np.float64]], fixed: list[bool]) -> NDArray[np.float64]:
    """(nb,) |theta| at which each body counts as overturned (the smaller side's threshold;
    infinite for fixed bodies): what the DEM kernels test every sample."""
    thresholds = overturn_thresholds(contact_polygons)
    return np.where(np.asarray(fixed, dtype=bool), np.inf, thresholds.min(axis=1))


@dataclass(frozen=True)
class Fall:
    """How one block's run ended, as sample indices (-1: none).

    Attributes
    ----------
    fall
        First sample at which it has fallen (come down for good).
    tip
        Its last passage of alpha before the fall (or before the end, still falling); -1 if
        it was not beyond alpha then (a block carried down, or dropping flat).
    falling
        First sample of its fall (``tip``, or the start of its final drop below half its
        height; ``fall`` when neither): it is falling from there until ``fall``, or to the end.
    """

    fall: int
    tip: int
    falling: int

    @property
    def fell(self) -> bool:
        """It came down within the run."""
        return self.fall >= 0

    @property
    def falling_at_end(self) -> bool:
        """The run ended while it was still falling (not yet fallen)."""
        return self.fall < 0 and self.falling >= 0


NO_FALL = Fall(-1, -1, -1)


def block_fall(
    t_s: NDArray[np.float64],
    theta_rad: NDArray[np.float64],
    y_m: NDArray[np.float64],
    alpha_rad: float,
    landing_rad: tuple[float, float],
    height_m: float,
    t_landed_s: float | None = None,
) -> Fall:
    """Whether, when and from when a block fell (the one rule of the module docstring).

    Parameters
    ----------
    t_s
        Sample times, s (equally spaced).
    theta_rad, y_m
        The block's rotation from rest (rad) and the vertical displacement of its centroid
        from rest (m) at those times.
    alpha_rad
        Its tipping angle, rad.
    landing_rad
        Its landing angles for theta > 0 and theta < 0 (:func:`landing_angles`), rad.
    height_m
        Its height, m.
    t_landed_s
        When the solver found it lying on another face between samples
        (``meta.overturn_times_s``), s; a run that stops there ends before a sample shows it.

    Returns
    -------
    Fall
        ``fall``: the first sample it lies on another face; else, for a block that ends the
        run dropped by more than ``DROP_FRACTION`` of its height, the first sample of that
        final drop at which it no longer descends faster than ``LAND_SPEED_M_S`` (it hit
        something); else, for a block that ends the run beyond alpha, the first sample after
        its last passage of alpha at which it turns slower than ``REST_SPIN_RAD_S`` (it leans
        on a neighbour or on rubble). Still descending or turning at the end: not fallen but
        falling (``falling >= 0``, ``fall = -1``).
    """
    theta = np.asarray(theta_rad, dtype=float)
    y = np.asarray(y_m, dtype=float)
    t = np.asarray(t_s, dtype=float)
    finite = np.isfinite(theta)
    if not finite.any():
        return NO_FALL
    last = int(np.flatnonzero(finite)[-1])
    landed = (theta >= landing_rad[0] - LANDING_TOL_RAD) | (theta <= -(landing_rad[1] - LANDING_TOL_RAD))
    if t_landed_s is not None:
        landed |= t >= min(t_landed_s, float(t[last]))
    beyond = (np.abs(theta) > alpha_rad) & finite
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    hits = np.flatnonzero(landed & finite)
    drop_start = -1
    if hits.size:
        fall = int(hits[0])
    elif y[last] < -DROP_FRACTION * height_m:
        up = np.flatnonzero(~(y[: last + 1] < -DROP_FRACTION * height_m))
        drop_start = int(up[-1]) + 1 if up.size else 0  # the final drop, to the end of the run
        vy = np.gradient(y[: last + 1], dt) if last > 0 else np.zeros(1)
        fall = _first_settled(vy[drop_start:] >= -LAND_SPEED_M_S, drop_start)
    elif beyond[last]:
        below = np.flatnonzero(~beyond[: last + 1])
        start = int(below[-1]) + 1 if below.size else 0
        omega = np.gradient(theta[: last + 1], dt) if last > 0 else np.zeros(1)
        fall = _first_settled(np.abs(omega[start:]) <= REST_SPIN_RAD_S, start)
    else:
        return NO_FALL
    end = fall if fall >= 0 else last
    tip = -1
    if beyond[end]:
        below = np.flatnonzero(~beyond[: end + 1])
        tip = int(below[-1]) + 1 if below.size else 0
    falling = tip if tip >= 0 else drop_start if drop_start >= 0 else fall
    return Fall(fall, tip, falling)


def _first_settled(ok: NDArray[np.bool_], start: int) -> int:
    """Index (from ``start``) of the first True of ``ok``, -1 if none (still moving at the end)."""
    hit = np.flatnonzero(ok)
    return start + int(hit[0]) if hit.size else -1


def body_falls(
    bodies: Sequence[Any],
    t_s: NDArray[np.float64],
    pos_m: NDArray[np.float64],
    ang_rad: NDArray[np.float64],
    landed_s: Mapping[str, float] | None = None,
) -> dict[str, Fall]:
    """:func:`block_fall` of every moving DEM body from a run's sampled arrays.

    Parameters
    ----------
    bodies
        The DEM bodies (``name``, ``fixed``, ``alpha_rad``, ``contact_vertices_m`` in the body
        frame, ``rest_centroid_m``, ``rest_angle_rad``: :class:`rockyade.dem.model.DemBody`).
    t_s
        (n,) sample times, s.
    pos_m, ang_rad
        (n, nb, 2) centroid positions (base frame, m) and (n, nb) world angles (rad).
    landed_s
        Per block name, when the solver found it lying on another face, s.
    """
    landed_s = landed_s or {}
    out = {}
    for i, body in enumerate(bodies):
        if body.fixed:
            continue
        poly = np.asarray(body.contact_vertices_m, dtype=float)
        out[body.name] = block_fall(
            t_s,
            ang_rad[:, i] - body.rest_angle_rad,
            pos_m[:, i, 1] - body.rest_centroid_m[1],
            float(body.alpha_rad),
            landing_angles(poly),
            float(np.ptp(poly[:, 1])),
            landed_s.get(body.name),
        )
    return out


def run_outcome(
    overturn_times_s: dict[str, float],
    names: list[str],
    falls: Mapping[str, Fall] | None = None,
    t_s: NDArray[np.float64] | None = None,
) -> tuple[str, float | None, str | None]:
    """Status, overturn time and block of an assembly's run: ``overturned`` at the first
    block's fall (the run itself goes on to the end), else ``completed``.

    Parameters
    ----------
    overturn_times_s
        Per block, when the solver found it lying on another face, s.
    names
        The blocks, in the scene's order (ties go to the first).
    falls, t_s
        :func:`body_falls` of the run and its sample times (s): the fall of the module
        docstring's rule, which the collapse table gives too. Without them, a block falls
        when it lies on another face (``overturn_times_s``) only.
    """
    if falls is not None and t_s is not None:
        times = {name: float(t_s[f.fall]) for name, f in falls.items() if f.fell}
        for name, t in overturn_times_s.items():  # landed between the last samples of a run
            times[name] = min(times.get(name, t), t)
    else:
        times = dict(overturn_times_s)
    if not times:
        return "completed", None, None
    block = min(times, key=lambda n: (times[n], names.index(n)))
    return "overturned", times[block], block


def first_overturn(theta: NDArray[np.float64], thresholds: NDArray[np.float64]) -> tuple[int, int]:
    """First sample and body that meet the criterion, or (-1, -1).

    Parameters
    ----------
    theta
        (n_samples, nb) rotations from rest, rad.
    thresholds
        :func:`overturn_thresholds` of the bodies (only moving bodies matter).
    """
    theta = np.asarray(theta, dtype=float)
    over = (theta >= thresholds[:, 0]) | (theta <= -thresholds[:, 1])
    over &= np.isfinite(theta)
    hits = np.flatnonzero(over.any(axis=1))
    if hits.size == 0:
        return -1, -1
    k = int(hits[0])
    return k, int(np.flatnonzero(over[k])[0])


CRITERION = (
    f"the block left its base and lies on another face: |theta| within {LANDING_TOL_RAD:g} rad of the angle at "
    "which the face next to its pivot corner reaches the ground (pi/2 for a rectangle)"
)
