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
def face_separation(wv, wn, wd, ref: int, face: int, other: int, n_other: int) -> float:
    """Least signed distance of ``other``'s vertices from the line of ``ref``'s edge ``face``.

    Parameters
    ----------
    wv, wn
        (nb, maxv, 2) world vertices and outward unit edge normals (edge e runs from vertex
        e to vertex e + 1, counter-clockwise).
    wd
        (nb, maxv) offsets of the edge lines, n_e . v_e.
    """
    nx = wn[ref, face, 0]
    ny = wn[ref, face, 1]
    s = math.inf
    for v in range(n_other):
        s = min(s, nx * wv[other, v, 0] + ny * wv[other, v, 1])
    return s - wd[ref, face]


@numba.njit(cache=True, nogil=True, inline="always")
def top_two_separations(wv, wn, wd, ref: int, n_ref: int, other: int, n_other: int) -> tuple[float, int, float]:
    """The largest face separation over ``ref``'s edges, its edge, and the second largest;
    stops at a separating axis (then the second is -inf)."""
    s1 = -math.inf
    f1 = NO_FACE
    s2 = -math.inf
    for f in range(n_ref):
        s = face_separation(wv, wn, wd, ref, f, other, n_other)
        if s > s1:
            s2 = s1
            s1 = s
            f1 = f
            if s > 0.0:
                return s1, f1, -math.inf
        elif s > s2:
            s2 = s
    return s1, f1, s2


@numba.njit(cache=True, nogil=True, inline="always")
def incident_edge(wn, ref: int, face: int, inc: int, n_inc: int) -> tuple[int, float]:
    """Edge of ``inc`` most anti-parallel to the reference face's normal, and half the gap
    of its normal's dot product to the next edge's (the relative rotation, rad, under which
    the choice cannot change)."""
    nx = wn[ref, face, 0]
    ny = wn[ref, face, 1]
    best = math.inf
    second = math.inf
    edge = 0
    for e in range(n_inc):
        d = nx * wn[inc, e, 0] + ny * wn[inc, e, 1]
        if d < best:
            second = best
            best = d
            edge = e
        elif d < second:
            second = d
    return edge, 0.5 * (second - best)


@numba.njit(cache=True, nogil=True, inline="always")
def separating_axis_test(
    wv, wn, wd, flen, nverts, a: int, b: int, prev_side: int, prev_face: int, tol: float
) -> tuple[int, int, float]:
    """Reference face of a pair and how far the pair may move before the answer can change.

    Returns
    -------
    side
        0: a face of ``a``; 1: a face of ``b``; ``NO_FACE``: a separating axis exists.
    face
        The reference face (an edge index of that body).
    slack
        A bound, m: while no vertex of either body has moved by more than ``slack`` in the
        other body's frame since this test, every face separation has changed by less
        than ``slack``, so the test would give the same answer (with contact: the same
        reference face under the hysteresis rule and no separating axis; without: the same
        separating axis). Temporal coherence, as physics engines cache separating axes.
    """
    na = nverts[a]
    nb_ = nverts[b]
    sa, fa, sa2 = top_two_separations(wv, wn, wd, a, na, b, nb_)
    if sa > 0.0:
        return NO_FACE, NO_FACE, sa
    sb, fb, sb2 = top_two_separations(wv, wn, wd, b, nb_, a, na)
    if sb > 0.0:
        return NO_FACE, NO_FACE, sb
    best = sa if sa > sb else sb
    side = NO_FACE
    face = NO_FACE
    if prev_side >= 0:
        if prev_side == 0:
            sp = sa if prev_face == fa else face_separation(wv, wn, wd, a, prev_face, b, nb_)
        else:
            sp = sb if prev_face == fb else face_separation(wv, wn, wd, b, prev_face, a, na)
        if sp >= best - tol:
            side = prev_side
            face = prev_face
    if side == NO_FACE:
        if abs(sa - sb) > tol:
            side = 0 if sa > sb else 1
        elif abs(flen[a, fa] - flen[b, fb]) > tol:
            # a tie (parallel faces): the longer face, then the face pointing up, then body a
            side = 0 if flen[a, fa] > flen[b, fb] else 1
        else:
            side = 1 if wn[b, fb, 1] > wn[a, fa, 1] + 1e-9 else 0
        face = fa if side == 0 else fb
    # the chosen face's separation and the largest of all the others
    if side == 0:
        s_star = sa if face == fa else face_separation(wv, wn, wd, a, face, b, nb_)
        other = max(sa2 if face == fa else sa, sb)
    else:
        s_star = sb if face == fb else face_separation(wv, wn, wd, b, face, a, na)
        other = max(sb2 if face == fb else sb, sa)
    # kept while s_star + tol >= every other separation and none of them becomes positive
    slack = min(0.5 * (s_star + tol - other), -other)
    return side, face, slack


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
    inside, p0x, p0y, p1x, p1y = _clip_segment(d0, d1, p0x, p0y, p1x, p1y)
    if not inside:
        return 0
    # side plane at r1: keep t.p <= t.r1
    off = tx * r1x + ty * r1y
    d0 = tx * p0x + ty * p0y - off
    d1 = tx * p1x + ty * p1y - off
    inside, p0x, p0y, p1x, p1y = _clip_segment(d0, d1, p0x, p0y, p1x, p1y)
    if not inside:
        return 0
    nx = wn[ref, face, 0]
    ny = wn[ref, face, 1]
    off = nx * r0x + ny * r0y
    n = _keep_if_below(out, 0, p0x, p0y, nx * p0x + ny * p0y - off)
    return _keep_if_below(out, n, p1x, p1y, nx * p1x + ny * p1y - off)


@numba.njit(cache=True, nogil=True, inline="always")
def _clip_segment(
    d0: float, d1: float, p0x: float, p0y: float, p1x: float, p1y: float
) -> tuple[bool, float, float, float, float]:
    """The segment p0-p1 clipped to the side d <= 0 of a side plane, ``d0`` and ``d1`` its ends'
    signed distances (m): (False, ...) when the whole segment is beyond, else (True, new ends)."""
    if d0 > 0.0 and d1 > 0.0:
        return False, p0x, p0y, p1x, p1y
    if d0 > 0.0:
        w = d0 / (d0 - d1)
        p0x = p0x + w * (p1x - p0x)
        p0y = p0y + w * (p1y - p0y)
    elif d1 > 0.0:
        w = d0 / (d0 - d1)
        p1x = p0x + w * (p1x - p0x)
        p1y = p0y + w * (p1y - p0y)
    return True, p0x, p0y, p1x, p1y


@numba.njit(cache=True, nogil=True, inline="always")
def _keep_if_below(out, n: int, px: float, py: float, s: float) -> int:
    """Write point (px, py) with penetration -``s`` (m) as ``out``'s row ``n`` when it is on or below
    the reference face (``s`` <= 0, its signed distance); the number of rows written."""
    if s <= 0.0:
        out[n, 0] = px
        out[n, 1] = py
        out[n, 2] = -s
        return n + 1
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
