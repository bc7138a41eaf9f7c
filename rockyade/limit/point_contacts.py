"""Point contacts at rest: a corner of one body touching another body where they share no segment.

The joints of :func:`~rockyade.scene.placement.rest_contacts` are segments two bodies share. A
corner can also touch another body at a single point: the corner of a course just below a fixed
restraint (the course's top corner on the restraint's bottom corner), a block's corner in a
re-entrant angle, a tilted block's corner on the base. Left out, a mechanism may pass a moving
block through a fixed one there. Here every such point becomes a contact.

Which relative velocities dv (of body a on body b at the point) keep the two bodies apart to
first order follows from their tangent cones there (the directions from the point into each
body: an edge's half-plane, or a corner's angle): dv must not point into b, and -dv must not
point into a. The admissible directions are what remains of the circle:

* a corner on the inside of an edge (or on the base): one half-plane, a contact with the edge's
  normal, as at the end of a joint;
* two corners meeting (the course's corner on the restraint's corner): the admissible set is not
  convex (a corner can pass the other on either side: up along the restraint's face, or under
  its bottom face). It is the union of two half-planes, or of two cones, each bounded by a face
  through the point. A linear programme takes one of them at a time:
  :mod:`rockyade.limit.admissible` searches them (branch and bound) for the lowest admissible
  mechanism.

Each way is a contact of zero length (both ends at the point) with the normal of one face and the
friction of the pair; a way bounded by two faces is two such contacts.

Point contacts are sought between a moving block and a fixed one, and between a moving block and
the base; not between two moving blocks (two corners meeting diagonally in a stack-bond grid are
not a contact), which would cost about two seconds on a wall of a thousand blocks.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rockyade.scene.placement import candidate_pairs

#: Two directions closer than this are one, rad (merging the excluded cones of two corners).
ANGLE_TOL = 1.0e-9


@dataclass(frozen=True)
class PointContact:
    """A point where body ``a`` touches body ``b`` (-1: the base) without a shared segment.

    Attributes
    ----------
    a, b
        Body indices; ``a`` is the moving body when one of them is fixed (or the base).
    point_m
        The point at rest, base frame, m.
    ways
        The ways the contact can hold, each a tuple of unit normals (from ``b`` into ``a``): the
        mechanism is admissible at the point when, for one way, every normal n of it has
        dv . n >= 0 (dv: the velocity of a relative to b). One way: a plain contact.
    """

    a: int
    b: int
    point_m: tuple[float, float]
    ways: tuple[tuple[tuple[float, float], ...], ...]


def _angle(v: NDArray[np.float64]) -> float:
    return math.atan2(float(v[1]), float(v[0])) % (2.0 * math.pi)


def _cone(poly: NDArray[np.float64], p: NDArray[np.float64], tol: float) -> tuple[float, float] | None:
    """The open cone of directions from ``p`` into the convex counter-clockwise ``poly``, as
    (start angle, width) in rad, counter-clockwise; None when ``p`` is not on its boundary."""
    n = len(poly)
    d = np.hypot(*(poly - p).T)
    k = int(np.argmin(d))
    if d[k] <= tol:  # a corner: from the edge leaving it to the edge arriving at it
        start = _angle(poly[(k + 1) % n] - poly[k])
        end = _angle(poly[(k - 1) % n] - poly[k])
        return start, (end - start) % (2.0 * math.pi)
    for i in range(n):
        a, b = poly[i], poly[(i + 1) % n]
        edge = b - a
        length = float(np.hypot(*edge))
        s = float((p - a) @ edge) / length
        off = float(edge[0] * (p - a)[1] - edge[1] * (p - a)[0]) / length  # > 0: inside (left of the edge)
        if -tol <= s <= length + tol and abs(off) <= tol:
            return _angle(edge), math.pi
    return None


def _ways(cones: Sequence[tuple[float, float]]) -> tuple[tuple[tuple[float, float], ...], ...]:
    """The admissible ways left by excluded open cones (start, width): the closed arcs of the circle
    outside them, each as the normals of the half-planes whose intersection it is (an arc wider
    than a half-plane gives two ways, a half-plane each)."""
    two_pi = 2.0 * math.pi
    # merge the excluded arcs on the circle
    arcs = sorted(((s % two_pi), w) for s, w in cones)
    merged: list[list[float]] = []
    for s, w in arcs:
        if merged and s <= merged[-1][0] + merged[-1][1] + ANGLE_TOL:
            merged[-1][1] = max(merged[-1][1], s + w - merged[-1][0])
        else:
            merged.append([s, w])
    if len(merged) > 1 and merged[-1][0] + merged[-1][1] >= merged[0][0] + two_pi - ANGLE_TOL:
        last = merged.pop()
        merged[0] = [last[0], max(last[1], merged[0][0] + two_pi + merged[0][1] - last[0])]
    if any(w >= two_pi - ANGLE_TOL for _, w in merged):
        return ()
    ways: list[tuple[tuple[float, float], ...]] = []
    for k, (s, w) in enumerate(merged):
        nxt = merged[(k + 1) % len(merged)]
        lo = s + w  # the admissible arc runs from the end of this excluded arc to the next's start
        hi = nxt[0] if len(merged) > 1 else s
        width = (hi - lo) % two_pi or (two_pi if len(merged) == 1 else 0.0)
        n_lo = (math.cos(lo + math.pi / 2), math.sin(lo + math.pi / 2))
        n_hi = (math.cos(hi - math.pi / 2), math.sin(hi - math.pi / 2))
        if width <= math.pi + ANGLE_TOL:
            same = math.hypot(n_lo[0] - n_hi[0], n_lo[1] - n_hi[1]) <= 1e-9
            ways.append((n_lo,) if same else (n_lo, n_hi))
        else:
            ways += [(n_lo,), (n_hi,)]
    return tuple(ways)


def _on_boundary(poly: NDArray[np.float64], points: NDArray[np.float64], tol: float) -> NDArray[np.bool_]:
    """Which ``points`` lie within ``tol`` of the convex counter-clockwise ``poly``'s boundary (all at once)."""
    edges = np.roll(poly, -1, axis=0) - poly
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.hypot(edges[:, 0], edges[:, 1])[:, None]
    signed = np.max(np.einsum("pkd,kd->pk", points[:, None, :] - poly[None, :, :], normals), axis=1)
    return np.abs(signed) <= tol


def point_contacts(
    polygons: Sequence[NDArray[np.float64]],
    fixed: NDArray[np.bool_],
    covered: Callable[[int, int, NDArray[np.float64]], bool],
    tol: float,
) -> list[PointContact]:
    """The point contacts of placed convex polygons (module docstring).

    Parameters
    ----------
    polygons
        Block polygons at rest, base frame, m (counter-clockwise).
    fixed
        (nb,) True for fixed blocks (only pairs of a moving and a fixed block are examined).
    covered
        ``covered(i, j, p)``: True when bodies i and j (j = -1: the base) already have a joint
        (a shared segment) through point ``p``.
    tol
        Distance within which a point touches, m.
    """
    out: list[PointContact] = []
    base_cone = (math.pi, math.pi)  # the base fills y < 0
    for i, poly in enumerate(polygons):
        if fixed[i]:
            continue
        for p in poly[np.abs(poly[:, 1]) <= tol]:
            if not covered(i, -1, p):
                cone_i = _cone(poly, p, tol)
                assert cone_i is not None  # p is a corner of poly
                ways = _ways([base_cone, ((cone_i[0] + math.pi) % (2 * math.pi), cone_i[1])])
                out.append(PointContact(i, -1, (float(p[0]), float(p[1])), ways))
    pairs = candidate_pairs(list(polygons), margin=tol) if np.any(fixed) else []
    for i, j in pairs:
        if fixed[i] == fixed[j]:
            continue  # two fixed blocks, or two moving ones (module docstring)
        seen: list[NDArray[np.float64]] = []
        touching = np.vstack(
            (
                polygons[i][_on_boundary(polygons[j], polygons[i], tol)],
                polygons[j][_on_boundary(polygons[i], polygons[j], tol)],
            )
        )
        for p in touching:
            if any(np.hypot(*(p - q)) <= tol for q in seen) or covered(i, j, p):
                continue
            cone_i, cone_j = _cone(polygons[i], p, tol), _cone(polygons[j], p, tol)
            if cone_i is None or cone_j is None:
                continue
            seen.append(p)
            a, b = (j, i) if fixed[i] else (i, j)
            cone_a, cone_b = (cone_j, cone_i) if fixed[i] else (cone_i, cone_j)
            # dv (a on b) must not point into b, nor -dv into a
            ways = _ways([cone_b, ((cone_a[0] + math.pi) % (2 * math.pi), cone_a[1])])
            out.append(PointContact(a, b, (float(p[0]), float(p[1])), ways))
    return out
