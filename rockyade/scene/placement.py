"""Where the blocks of a scene stand at rest, which of them overlap, and which touch.

A positioned scene places each block's frame origin at ``position_m`` in the base frame,
rotated by ``rotation_rad`` (counter-clockwise) about it; a column scene stacks its blocks
bottom to top, each shifted by ``x_offset_m``. Both become :class:`PlacedBlock` records:
the block polygon in the base frame at rest.

Two convex polygons *overlap* when the separating-axis test finds them interpenetrating by
more than a tolerance on every axis (their edge normals); they *touch* when an edge of one
and an edge of the other are anti-parallel, on the same line within a tolerance, and share
a segment of positive length: the rest interface of a joint, whose length is the shared
length. The base is the line y = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from rockyade.scene.frozen_cache import computed_once

#: Overlaps deeper than this fraction of the smaller block's size are refused.
OVERLAP_TOL = 1e-6
#: Edges within this fraction of the block size of each other's line touch at rest.
TOUCH_TOL = 1e-6
#: An interface whose normal is within 45 degrees of vertical is a bed joint.
BED_NORMAL_MIN_Y = math.cos(math.radians(45.0))


@dataclass(frozen=True)
class PlacedBlock:
    """A block of a scene at rest, in the base frame.

    Attributes
    ----------
    index, name
        Position in the scene's block list and name.
    vertices_m
        (n, 2) polygon in the base frame, counter-clockwise, m.
    centroid_m
        Centroid in the base frame, m.
    rotation_rad
        Orientation at rest (counter-clockwise), rad.
    fixed
        Moves with the base.
    """

    index: int
    name: str
    vertices_m: NDArray[np.float64]
    centroid_m: tuple[float, float]
    rotation_rad: float
    fixed: bool

    @cached_property
    def size_m(self) -> float:
        """Largest extent of the polygon, m (computed once: the block is frozen)."""
        return float(np.max(np.ptp(self.vertices_m, axis=0)))


@dataclass(frozen=True)
class RestContact:
    """Two bodies (or a body and the base) touching at rest along a segment.

    Attributes
    ----------
    a, b
        Body indices, a < b; ``b = -1`` is the base (then ``a`` is the body).
    kind
        "bed" (interface normal within 45 degrees of vertical) or "head".
    length_m
        Length of the shared segment, m.
    normal
        Unit normal of the interface, pointing from ``b`` (or the base) into ``a``.
    upper
        The body above a bed joint (the higher centroid), else -1.
    ends_m
        The two ends of the shared segment, base frame, m.
    """

    a: int
    b: int
    kind: str
    length_m: float
    normal: tuple[float, float]
    upper: int
    ends_m: tuple[tuple[float, float], tuple[float, float]]


def rotation_matrix(angle_rad: float) -> NDArray[np.float64]:
    """2-D rotation by ``angle_rad`` counter-clockwise."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s], [s, c]])


def place_polygon(vertices_m: NDArray[np.float64], position_m, rotation_rad: float) -> NDArray[np.float64]:
    """Block-frame vertices rotated about the frame origin, then moved to ``position_m``."""
    return vertices_m @ rotation_matrix(rotation_rad).T + np.asarray(position_m, dtype=float)


def placed_blocks(scene) -> list[PlacedBlock]:
    """The scene's blocks at rest in the base frame (see module docstring).

    Computed once per scene (a scene is frozen; the vertices are read-only): loading,
    the model build and the analyses all ask.

    Parameters
    ----------
    scene
        A :class:`~rockyade.scene.Scene` (positioned or column).
    """
    return list(computed_once(scene, "_placed_blocks", lambda: tuple(_placed_blocks(scene))))


def scene_rest_contacts(scene) -> list[RestContact]:
    """:func:`rest_contacts` of the scene's own polygons (:func:`placed_blocks`), once per scene.

    Parameters
    ----------
    scene
        A :class:`~rockyade.scene.Scene` (positioned or column).
    """
    return list(computed_once(scene, "_rest_contacts", lambda: tuple(rest_contacts(placed_blocks(scene)))))


def _placed_blocks(scene) -> list[PlacedBlock]:
    out: list[PlacedBlock] = []
    base_y = 0.0
    for i, spec in enumerate(scene.blocks):
        block = spec.block()
        if spec.position_m is not None:
            # the block's polygon is stored with its lowest vertex on y = 0: put the user's
            # vertex coordinates back so that position_m places their origin
            shift = min(v[1] for v in spec.vertices_m) if spec.vertices_m is not None else 0.0
            rotation = spec.rotation_rad
            position = np.asarray(spec.position_m) + rotation_matrix(rotation) @ np.array([0.0, shift])
        else:
            position, rotation = (spec.x_offset_m, base_y), 0.0
            base_y += block.height_m
        verts = place_polygon(block.vertices_m, position, rotation)
        verts.setflags(write=False)
        centroid = place_polygon(np.array([block.centroid_m]), position, rotation)[0]
        out.append(
            PlacedBlock(i, spec.name, verts, (float(centroid[0]), float(centroid[1])), float(rotation), spec.fixed)
        )
    return out


# ---------------------------------------------------------------------- pair search


def candidate_pairs(polygons: list[NDArray[np.float64]], margin: float = 0.0) -> list[tuple[int, int]]:
    """Pairs (i < j) whose bounding boxes, grown by ``margin``, overlap (sort and sweep on x)."""
    if not polygons:
        return []
    lo = np.array([p.min(axis=0) for p in polygons]) - margin
    hi = np.array([p.max(axis=0) for p in polygons]) + margin
    order = np.argsort(lo[:, 0], kind="stable")
    pairs: list[tuple[int, int]] = []
    active: list[int] = []
    for i in order:
        x0 = lo[i, 0]
        active = [j for j in active if hi[j, 0] >= x0]
        for j in active:
            if lo[i, 1] <= hi[j, 1] and lo[j, 1] <= hi[i, 1]:
                pairs.append((int(min(i, j)), int(max(i, j))))
        active.append(int(i))
    return sorted(pairs)


def edge_normals(poly: NDArray[np.float64]) -> NDArray[np.float64]:
    """Outward unit normals of a counter-clockwise polygon's edges."""
    edges = np.concatenate((poly[1:], poly[:1])) - poly  # np.roll(poly, -1, axis=0) - poly
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    return normals / np.hypot(normals[:, 0], normals[:, 1])[:, None]


def penetration_depth(
    p: NDArray[np.float64],
    q: NDArray[np.float64],
    normals: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> float:
    """Separating-axis penetration of two convex polygons, m (<= 0: apart or touching).

    The smallest overlap of the two polygons' projections over all their edge normals;
    negative values are separations. ``normals`` are the two polygons' edge normals, when
    the caller has them.
    """
    depth = math.inf
    for axes in normals if normals is not None else (edge_normals(p), edge_normals(q)):
        pp = p @ axes.T
        qq = q @ axes.T
        overlap = np.minimum(pp.max(axis=0), qq.max(axis=0)) - np.maximum(pp.min(axis=0), qq.min(axis=0))
        depth = min(depth, float(overlap.min()))
    return depth


def overlapping_pairs(blocks: list[PlacedBlock], tol: float = OVERLAP_TOL) -> list[tuple[int, int, float]]:
    """Pairs of blocks that interpenetrate at rest deeper than ``tol`` x the smaller size.

    Returns (i, j, depth_m) triples.
    """
    polys = [b.vertices_m for b in blocks]
    normals = [edge_normals(p) for p in polys]
    out = []
    for i, j in candidate_pairs(polys):
        depth = penetration_depth(polys[i], polys[j], (normals[i], normals[j]))
        if depth > tol * min(blocks[i].size_m, blocks[j].size_m):
            out.append((i, j, depth))
    return out


# ---------------------------------------------------------------------- rest contacts


def _shared_segment(
    p: NDArray[np.float64],
    q: NDArray[np.float64],
    tol: float,
    normals: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
) -> tuple[float, NDArray[np.float64], tuple[tuple[float, float], tuple[float, float]]]:
    """The boundary segment two touching convex polygons share: length, normal (q -> p), ends.

    ``normals`` are the two polygons' :func:`edge_normals`, when the caller has them."""
    np_, nq = normals if normals is not None else (edge_normals(p), edge_normals(q))
    best, normal, ends = 0.0, np.zeros(2), ((0.0, 0.0), (0.0, 0.0))
    # the edge pairs that can be anti-parallel, all at once (a looser test than the exact one
    # below, which decides), in the order of a loop over e, then f
    edges, faces = np.nonzero(np_ @ nq.T <= -1.0 + 1e-6)
    for e, f in zip(edges.tolist(), faces.tolist(), strict=True):
        a0, a1 = p[e], p[(e + 1) % len(p)]
        if np_[e] @ nq[f] > -1.0 + 1e-9:
            continue
        b0, b1 = q[f], q[(f + 1) % len(q)]
        if abs((b0 - a0) @ np_[e]) > tol or abs((b1 - a0) @ np_[e]) > tol:
            continue
        d = (a1 - a0) / np.hypot(*(a1 - a0))
        s = sorted((0.0, float((a1 - a0) @ d)))
        t = sorted((float((b0 - a0) @ d), float((b1 - a0) @ d)))
        lo, hi = max(s[0], t[0]), min(s[1], t[1])
        if hi - lo > best:
            best, normal = hi - lo, -np_[e]
            e0, e1 = a0 + lo * d, a0 + hi * d
            ends = ((float(e0[0]), float(e0[1])), (float(e1[0]), float(e1[1])))
    return best, normal, ends


def rest_contacts(blocks: list[PlacedBlock], polygons: list[NDArray[np.float64]] | None = None) -> list[RestContact]:
    """Joints at rest: body pairs and body-base interfaces sharing a segment of positive length.

    Parameters
    ----------
    blocks
        The placed blocks (centroids, fixed flags, sizes).
    polygons
        Contact polygons in the base frame (default: the blocks' own polygons). The DEMs
        pass theirs, whose base corners may sit at the equivalent base b_eq (Eq 11).
    """
    polys = polygons if polygons is not None else [b.vertices_m for b in blocks]
    normals = [edge_normals(p) for p in polys]
    out: list[RestContact] = []
    for i, p in enumerate(polys):
        if blocks[i].fixed:
            continue
        tol = TOUCH_TOL * blocks[i].size_m
        on_base = np.abs(p[:, 1]) <= tol
        if on_base.sum() >= 2:
            xs = p[on_base, 0]
            ends = ((float(xs.min()), 0.0), (float(xs.max()), 0.0))
            out.append(RestContact(i, -1, "bed", float(xs.max() - xs.min()), (0.0, 1.0), i, ends))
    for i, j in candidate_pairs(polys, margin=TOUCH_TOL * max((b.size_m for b in blocks), default=1.0)):
        if blocks[i].fixed and blocks[j].fixed:
            continue
        tol = TOUCH_TOL * min(blocks[i].size_m, blocks[j].size_m)
        length, normal, ends = _shared_segment(polys[i], polys[j], tol, (normals[i], normals[j]))
        if length <= tol:
            continue
        bed = abs(normal[1]) >= BED_NORMAL_MIN_Y
        upper = (i if blocks[i].centroid_m[1] > blocks[j].centroid_m[1] else j) if bed else -1
        kind = "bed" if bed else "head"
        out.append(RestContact(i, j, kind, float(length), (float(normal[0]), float(normal[1])), upper, ends))
    return out
