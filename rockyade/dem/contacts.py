"""Narrow phase of the reference DEM: the contact manifold of two convex polygons, and the
joint of a pair.

One manifold per pair of touching polygons, counted once, as Box2D's ``b2CollidePolygons``
builds it (E. Catto, "Contact Manifolds", GDC 2007; "Computing Distance", GDC 2010; the
Box2D source ``b2_collide_polygon.c``):

1. **Reference face** by the separating-axis test: for every edge of either polygon, the
   separation is the least signed distance of the other polygon's vertices from the edge's
   line (outward normal); the reference face is the edge with the largest separation (the
   least penetration). A positive separation is a separating axis: no contact.
2. **Hysteresis** (Box2D keeps polygon A unless B is better by a tolerance): the reference
   face of the last step is kept unless another face is better by ``HYSTERESIS_REL`` times
   the smaller polygon's size. A first contact whose best faces tie within that tolerance
   takes the longer face (the vertices of the shorter face bear on it: a narrow block on a
   wide one, a column's top corners on a cap beam), then the face that points up (the lower
   block's top face of a flush joint), then the lower body index.
3. **Incident edge**: the edge of the other polygon whose normal is most anti-parallel to
   the reference normal.
4. **Clipping**: the incident edge clipped to the reference face's two side planes; the
   clipped points below the reference face are the contact points (at most two). A flush
   joint (two equal blocks corner to corner) gives two points at its ends, each with the
   joint's K: one joint, never two contacts per corner.

A vertex that lies on a corner of the other block (a flush joint) is never tested against
the side edge: the axis of the side edges separates by the whole block width, not by the
distance to the side edge, so the bed face always wins.

The base is the half-plane y <= 0 with normal +y: every vertex below it is a contact point
(the base has no side planes to clip to).
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: Keep the last step's reference face unless another is better by this fraction of the
#: smaller polygon's size (Box2D's relative tolerance; here about 1e-5 m for a 1 m block, far
#: above rounding and far below any rocking motion).
HYSTERESIS_REL = 1e-5

NO_FACE = -1


@numba.njit(cache=True, nogil=True, inline="always")
def face_separation(wv, wn, ref: int, face: int, other: int, n_other: int) -> float:
    """Least signed distance of ``other``'s vertices from the line of ``ref``'s edge ``face``.

    Parameters
    ----------
    wv, wn
        (nb, maxv, 2) world vertices and outward unit edge normals (edge e runs from vertex
        e to vertex e + 1, counter-clockwise).
    """
    nx = wn[ref, face, 0]
    ny = wn[ref, face, 1]
    d = nx * wv[ref, face, 0] + ny * wv[ref, face, 1]
    s = math.inf
    for v in range(n_other):
        p = nx * wv[other, v, 0] + ny * wv[other, v, 1]
        if p < s:
            s = p
    return s - d


@numba.njit(cache=True, nogil=True, inline="always")
def max_separation(wv, wn, ref: int, n_ref: int, other: int, n_other: int) -> tuple[float, int]:
    """Largest face separation over ``ref``'s edges and its edge; stops at a separating axis."""
    best = -math.inf
    best_face = NO_FACE
    for f in range(n_ref):
        s = face_separation(wv, wn, ref, f, other, n_other)
        if s > best:
            best = s
            best_face = f
            if s > 0.0:
                break
    return best, best_face


@numba.njit(cache=True, nogil=True, inline="always")
def incident_edge(wn, ref: int, face: int, inc: int, n_inc: int) -> int:
    """Edge of ``inc`` most anti-parallel to the reference face's normal."""
    nx = wn[ref, face, 0]
    ny = wn[ref, face, 1]
    best = math.inf
    edge = 0
    for e in range(n_inc):
        d = nx * wn[inc, e, 0] + ny * wn[inc, e, 1]
        if d < best:
            best = d
            edge = e
    return edge


@numba.njit(cache=True, nogil=True, inline="always")
def choose_reference(
    wv, wn, flen, nverts, a: int, b: int, prev_side: int, prev_face: int, tol: float
) -> tuple[int, int, float]:
    """Reference face of a pair: (side 0 = a's face / 1 = b's face, face, separation).

    ``side = NO_FACE`` when a separating axis exists (no contact).
    """
    na = nverts[a]
    nb_ = nverts[b]
    sa, fa = max_separation(wv, wn, a, na, b, nb_)
    if sa > 0.0:
        return NO_FACE, NO_FACE, sa
    sb, fb = max_separation(wv, wn, b, nb_, a, na)
    if sb > 0.0:
        return NO_FACE, NO_FACE, sb
    best = sa if sa > sb else sb
    if prev_side >= 0:
        if prev_side == 0:
            sp = face_separation(wv, wn, a, prev_face, b, nb_)
        else:
            sp = face_separation(wv, wn, b, prev_face, a, na)
        if sp >= best - tol:
            return prev_side, prev_face, sp
    if abs(sa - sb) > tol:
        if sa > sb:
            return 0, fa, sa
        return 1, fb, sb
    # a tie (parallel faces): the longer face, then the face pointing up, then body a
    la = flen[a, fa]
    lb = flen[b, fb]
    if abs(la - lb) > tol:
        if la > lb:
            return 0, fa, sa
        return 1, fb, sb
    if wn[b, fb, 1] > wn[a, fa, 1] + 1e-9:
        return 1, fb, sb
    return 0, fa, sa


@numba.njit(cache=True, nogil=True, inline="always")
def clip_manifold(wv, wn, flen, nverts, ref: int, face: int, inc: int, edge: int, out) -> int:
    """Clip ``inc``'s edge ``edge`` to the side planes of ``ref``'s face ``face``
    (Box2D's ``b2ClipSegmentToLine`` twice) and keep the points below the face.

    Parameters
    ----------
    out
        (2, 3) scratch: x, y of each contact point (on the incident body's boundary) and its
        penetration depth (>= 0), m.

    Returns
    -------
    int
        Number of contact points written (0, 1 or 2).
    """
    nr = nverts[ref]
    ni = nverts[inc]
    f2 = face + 1 if face + 1 < nr else 0
    e2 = edge + 1 if edge + 1 < ni else 0
    r0x = wv[ref, face, 0]
    r0y = wv[ref, face, 1]
    r1x = wv[ref, f2, 0]
    r1y = wv[ref, f2, 1]
    inv = 1.0 / flen[ref, face]
    tx = (r1x - r0x) * inv
    ty = (r1y - r0y) * inv
    p0x = wv[inc, edge, 0]
    p0y = wv[inc, edge, 1]
    p1x = wv[inc, e2, 0]
    p1y = wv[inc, e2, 1]
    # side plane at r0: keep t.p >= t.r0
    off = tx * r0x + ty * r0y
    d0 = off - (tx * p0x + ty * p0y)
    d1 = off - (tx * p1x + ty * p1y)
    if d0 > 0.0 and d1 > 0.0:
        return 0
    if d0 > 0.0:
        w = d0 / (d0 - d1)
        p0x = p0x + w * (p1x - p0x)
        p0y = p0y + w * (p1y - p0y)
    elif d1 > 0.0:
        w = d0 / (d0 - d1)
        p1x = p0x + w * (p1x - p0x)
        p1y = p0y + w * (p1y - p0y)
    # side plane at r1: keep t.p <= t.r1
    off = tx * r1x + ty * r1y
    d0 = tx * p0x + ty * p0y - off
    d1 = tx * p1x + ty * p1y - off
    if d0 > 0.0 and d1 > 0.0:
        return 0
    if d0 > 0.0:
        w = d0 / (d0 - d1)
        p0x = p0x + w * (p1x - p0x)
        p0y = p0y + w * (p1y - p0y)
    elif d1 > 0.0:
        w = d0 / (d0 - d1)
        p1x = p0x + w * (p1x - p0x)
        p1y = p0y + w * (p1y - p0y)
    nx = wn[ref, face, 0]
    ny = wn[ref, face, 1]
    off = nx * r0x + ny * r0y
    n = 0
    s = nx * p0x + ny * p0y - off
    if s <= 0.0:
        out[n, 0] = p0x
        out[n, 1] = p0y
        out[n, 2] = -s
        n += 1
    s = nx * p1x + ny * p1y - off
    if s <= 0.0:
        out[n, 0] = p1x
        out[n, 1] = p1y
        out[n, 2] = -s
        n += 1
    return n


@numba.njit(cache=True, nogil=True)
def joint_for(a: int, b: int, nb: int, base_joint, own_joint, pair_keys, pair_joint, fixed, kn) -> int:
    """Index of the joint between bodies ``a`` and ``b`` (``b = -1``: the base), exactly
    :meth:`rockyade.dem.joints.JointTable.joint_for`: the base joint; a pair resolved at build
    (``pair_keys`` = lo * (nb + 1) + hi, sorted); else the moving body's own joint against a
    fixed body, else the softer (lower K) own joint, ties to the lower index."""
    if b < 0:
        return base_joint[a]
    lo = a if a < b else b
    hi = b if a < b else a
    key = lo * (nb + 1) + hi
    k = np.searchsorted(pair_keys, key)
    if k < pair_keys.size and pair_keys[k] == key:
        return pair_joint[k]
    if fixed[lo]:
        return own_joint[hi]
    if fixed[hi]:
        return own_joint[lo]
    ja = own_joint[lo]
    jb = own_joint[hi]
    return jb if kn[jb] < kn[ja] else ja
