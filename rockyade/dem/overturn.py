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
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from rockyade.blocks.geometry import LEVEL_TOL

#: How close to the landing angle counts as landed, rad (the contact's elastic tilt is ~1e-5).
LANDING_TOL_RAD = 0.01


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


def run_outcome(overturn_times_s: dict[str, float], names: list[str]) -> tuple[str, float | None, str | None]:
    """Status, overturn time and block of an assembly's run from its blocks' overturn times:
    ``overturned`` at the first block's fall (the run itself goes on to the end)."""
    if not overturn_times_s:
        return "completed", None, None
    block = min(overturn_times_s, key=lambda n: (overturn_times_s[n], names.index(n)))
    return "overturned", overturn_times_s[block], block


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
