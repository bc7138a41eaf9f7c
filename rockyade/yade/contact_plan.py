"""How the YADE backend gives every contact of an assembly its joint.

A block in YADE is one clump: a small sphere at every vertex of its contact polygon and one
Polyhedra prism (the polygon extruded in z) as the surface the other blocks' vertex spheres
meet (``Ig2_Sphere_Polyhedra_ScGeom``); the base is a Box. Only sphere-prism and
sphere-base pairs have a geometry functor, so every vertex meets every other block and the
base, as the reference DEM's vertices do.

YADE computes a contact's parameters from the two bodies' materials
(``Ip2_ViscElMat_ViscElMat_ViscElPhys``: in series, zeros skipped); prisms and base carry
zeros, so a sphere's material is its contacts' joint. A vertex meets blocks whose joints
differ (``JointTable.joint_for``), so each vertex sphere has *copies*, one per joint it
needs, at the same place, and collision masks decide which copy meets which block:

* every block has a *label* (one mask bit, bits 1-30; bit 0 is the base). Up to 30 blocks
  each have their own bit and every pair gets exactly ``joint_for(a, b)``. Beyond that,
  blocks share bits: blocks with the same own joint (and fixed flag) share a pool of bits,
  and within a pool no two blocks closer than two rest contacts share a bit, so the blocks a
  vertex touches at rest are always told apart;
* a copy's mask holds the bits of the labels it meets; in a shared label the block touching
  the vertex's block at rest decides, else the joint most of its blocks need.

A flush joint end (a vertex of each block at the same point) has both vertex spheres
touching the other block: each takes half the joint (K/2, Ks/2, same beta and friction), so
the end carries K as in the reference DEM and the statics (one joint, never 2K).

The contacts YADE gives a different joint than the reference DEM are counted exactly and
reported (:func:`plan_contacts`): with up to 30 blocks none; beyond, only pairs that do not
touch at rest can differ.

Sphere placement (body frame): a vertex sphere of radius r is tangent to the edges next to
its vertex that carry a joint at rest (so a base corner rocks about the exact corner as in
the reference DEM; with joints on both edges the sphere is inscribed in the corner, its
centre r from both); a vertex with no joint at rest is inscribed. A sphere that would
touch a block it has no joint with at rest is inscribed instead.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from rockyade.dem.model import DemModel
from rockyade.scene.placement import candidate_pairs, penetration_depth, rotation_matrix

#: Mask bit of the base.
BASE_BIT = 1
#: Number of label bits (bits 1-30 of YADE's 32-bit signed mask).
N_LABELS = 30
#: Two points closer than this fraction of the smaller block size are the same point.
SAME_POINT_TOL = 1e-6
#: Smallest 1 + cos(corner angle) for an inscribed sphere (sharper corners take the bisector).
MIN_CORNER_OPENING = 0.05
#: Contacts listed by name in the report.
MAX_LISTED = 20


@dataclass(frozen=True)
class Variant:
    """A joint as one sphere material: joint ``joint`` of the model's table times ``factor``
    (1, or 1/2 at a flush joint end)."""

    joint: int
    factor: float


@dataclass
class ContactPlan:
    """Everything the YADE driver needs to give each contact its joint.

    Attributes
    ----------
    variants
        Sphere materials: (joint, factor) per material, in order.
    labels
        (nb,) label (mask bit index - 1) of each block's prism.
    centers_m
        Per body, (nv, 2) vertex sphere centres in the body frame, m.
    copies
        Per body, per vertex: (variant index, mask) of each copy of the vertex sphere.
    report
        Which contacts differ from ``JointTable.joint_for`` (see :func:`plan_contacts`).
    """

    variants: list[Variant]
    labels: NDArray[np.int64]
    centers_m: list[NDArray[np.float64]]
    copies: list[list[list[tuple[int, int]]]]
    report: dict[str, object] = field(default_factory=dict)

    def prism_mask(self, body: int) -> int:
        """Collision mask of a body's prism."""
        return 1 << (1 + int(self.labels[body]))


# ---------------------------------------------------------------------- geometry


def _inward_normals(poly: NDArray[np.float64]) -> NDArray[np.float64]:
    """Inward unit normals of a counter-clockwise polygon's edges (edge k: vertex k to k+1)."""
    edges = np.roll(poly, -1, axis=0) - poly
    normals = np.column_stack([-edges[:, 1], edges[:, 0]])
    return normals / np.hypot(normals[:, 0], normals[:, 1])[:, None]


def _point_segment_distance(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    d = b - a
    t = float(np.clip((p - a) @ d / max(float(d @ d), 1e-300), 0.0, 1.0))
    return float(np.hypot(*(p - a - t * d)))


def _polygon_distance(p: NDArray[np.float64], poly: NDArray[np.float64]) -> float:
    """Signed distance from a point to a convex CCW polygon (negative inside), m."""
    normals = _inward_normals(poly)
    depth = np.min(np.einsum("ij,ij->i", p - poly, normals))
    if depth >= 0.0:
        return -float(depth)
    n = len(poly)
    return min(_point_segment_distance(p, poly[k], poly[(k + 1) % n]) for k in range(n))


def world_polygons(model: DemModel) -> list[NDArray[np.float64]]:
    """Every body's contact polygon in the base frame at rest, m."""
    return [
        b.contact_vertices_m @ rotation_matrix(b.rest_angle_rad).T + np.asarray(b.rest_centroid_m) for b in model.bodies
    ]


def _sizes(model: DemModel) -> NDArray[np.float64]:
    return np.array([float(np.min(np.ptp(b.contact_vertices_m, axis=0))) for b in model.bodies])


def _bearing_edges(model: DemModel, polys: list[NDArray[np.float64]], sizes) -> list[dict[int, set[int]]]:
    """Per body: edge index -> partners (-1 the base) of the rest joints lying on that edge."""
    out: list[dict[int, set[int]]] = [defaultdict(set) for _ in model.bodies]
    for c in model.rest_contacts:
        ends = np.asarray(c.ends_m, dtype=float)
        for me, other in ((c.a, c.b), (c.b, c.a)):
            if me < 0:
                continue
            poly = polys[me]
            tol = SAME_POINT_TOL * sizes[me] * 10
            n = len(poly)
            for k in range(n):
                a, b = poly[k], poly[(k + 1) % n]
                if all(_point_segment_distance(e, a, b) <= tol for e in ends):
                    out[me][k].add(other)
    return out


def _inscribed(v, n1, n2, r):
    opening = 1.0 + float(n1 @ n2)
    if opening < MIN_CORNER_OPENING:  # a very sharp corner: on the bisector, r inside
        m = (n1 + n2) / max(float(np.hypot(*(n1 + n2))), 1e-12)
        return v + r * m
    return v + r * (n1 + n2) / opening


def sphere_centers(model: DemModel, radii: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """Vertex sphere centres in each body's frame (see module docstring), m.

    ``radii``: each body's sphere radius, m."""
    polys = world_polygons(model)
    sizes = _sizes(model)
    bearing = _bearing_edges(model, polys, sizes)
    near: dict[int, set[int]] = defaultdict(set)
    for i, j in candidate_pairs(polys, margin=2 * float(np.max(radii))):
        near[i].add(j)
        near[j].add(i)
    out = []
    for i, body in enumerate(model.bodies):
        radius = float(radii[i])
        poly = body.contact_vertices_m
        normals = _inward_normals(poly)
        rot = rotation_matrix(body.rest_angle_rad)
        n = len(poly)
        centers = np.empty_like(poly)
        for v in range(n):
            prev, nxt = (v - 1) % n, v
            n1, n2 = normals[prev], normals[nxt]
            on_prev, on_next = prev in bearing[i], nxt in bearing[i]
            inscribed = _inscribed(poly[v], n1, n2, radius)
            if on_prev and not on_next:
                c = poly[v] + radius * n1
            elif on_next and not on_prev:
                c = poly[v] + radius * n2
            else:
                c = inscribed
            partners = bearing[i].get(prev, set()) | bearing[i].get(nxt, set())
            world = rot @ c + np.asarray(body.rest_centroid_m)
            touches_other = any(
                j not in partners and _polygon_distance(world, polys[j]) < radius * (1 - 1e-6) for j in near[i]
            ) or (-1 not in partners and world[1] < radius * (1 - 1e-6))
            centers[v] = inscribed if touches_other else c
        out.append(centers)
    return out


def flush_ends(model: DemModel, polys: list[NDArray[np.float64]] | None = None) -> set[tuple[int, int, int]]:
    """(body, vertex, other body) of the vertex spheres at a flush joint end: a vertex of each
    of the two blocks at the same end of their rest joint."""
    polys = polys if polys is not None else world_polygons(model)
    sizes = _sizes(model)
    out: set[tuple[int, int, int]] = set()
    for c in model.rest_contacts:
        if c.b < 0:
            continue
        tol = SAME_POINT_TOL * min(sizes[c.a], sizes[c.b]) * 10
        for end in np.asarray(c.ends_m, dtype=float):
            va = np.flatnonzero(np.hypot(*(polys[c.a] - end).T) <= tol)
            vb = np.flatnonzero(np.hypot(*(polys[c.b] - end).T) <= tol)
            if va.size and vb.size:
                out.add((c.a, int(va[0]), c.b))
                out.add((c.b, int(vb[0]), c.a))
    return out


# ---------------------------------------------------------------------- joints wanted


def body_row(model: DemModel, a: int) -> NDArray[np.int64]:
    """``joint_for(a, b)`` for every body b and, last, the base; -1 where no contact acts
    (the body itself, two fixed bodies, a fixed body and the base)."""
    jt = model.joints
    nb = len(model.bodies)
    own, fixed = jt.own_joint, jt.fixed
    k = np.array([p.K_N_per_m for p in jt.params] + [math.inf])
    b = np.arange(nb)
    if fixed[a]:
        row = np.where(fixed, -1, own)
    else:
        a_is_lo = a < b
        own_lo = np.where(a_is_lo, own[a], own)
        own_hi = np.where(a_is_lo, own, own[a])
        row = np.where(k[own_hi] < k[own_lo], own_hi, own_lo)
        row = np.where(fixed, own[a], row)
    row = row.astype(np.int64)
    sel = jt.pair_a == a
    row[jt.pair_b[sel]] = jt.pair_joint[sel]
    sel = jt.pair_b == a
    row[jt.pair_a[sel]] = jt.pair_joint[sel]
    row[a] = -1
    base = -1 if fixed[a] else int(jt.base_joint[a])
    return np.append(row, base)


def _rest_neighbours(model: DemModel) -> list[set[int]]:
    out: list[set[int]] = [set() for _ in model.bodies]
    for c in model.rest_contacts:
        if c.b >= 0:
            out[c.a].add(c.b)
            out[c.b].add(c.a)
    return out


# ---------------------------------------------------------------------- labels


def assign_labels(model: DemModel, n_labels: int = N_LABELS) -> NDArray[np.int64]:
    """A mask label per body (see module docstring)."""
    nb = len(model.bodies)
    if nb <= n_labels:
        return np.arange(nb, dtype=np.int64)
    jt = model.joints
    k = np.array([p.K_N_per_m for p in jt.params])
    keys = sorted(
        {(bool(jt.fixed[i]), int(jt.own_joint[i])) for i in range(nb)},
        key=lambda key: (key[0], k[key[1]] if key[1] >= 0 else 0.0, key[1]),
    )
    by_class = {key: [i for i in range(nb) if (bool(jt.fixed[i]), int(jt.own_joint[i])) == key] for key in keys}
    pools: dict[tuple[bool, int], list[int]] = {}
    if len(keys) <= n_labels:
        # every class at least one label, the rest in proportion to the class sizes
        extra = n_labels - len(keys)
        shares = np.array([len(by_class[key]) for key in keys], dtype=float)
        quota = shares / shares.sum() * extra
        counts = np.floor(quota).astype(int)
        for idx in np.argsort(-(quota - counts))[: extra - int(counts.sum())]:
            counts[idx] += 1
        start = 0
        for key, c in zip(keys, counts, strict=True):
            pools[key] = list(range(start, start + 1 + int(c)))
            start += 1 + int(c)
    else:  # more classes than labels: consecutive classes (by stiffness) share a label
        for idx, key in enumerate(keys):
            pools[key] = [idx * n_labels // len(keys)]
    neighbours = _rest_neighbours(model)
    centroids = np.array([b.rest_centroid_m for b in model.bodies], dtype=float)
    labels = np.full(nb, -1, dtype=np.int64)
    members: dict[int, list[int]] = defaultdict(list)
    for i in range(nb):
        pool = pools[(bool(jt.fixed[i]), int(jt.own_joint[i]))]
        close = set(neighbours[i])
        for j in neighbours[i]:
            close |= neighbours[j]
        close.discard(i)
        taken = [int(labels[j]) for j in close if labels[j] >= 0]
        # fewest conflicts, then the label whose blocks are farthest away (the blocks a vertex
        # cannot tell apart are then far from each other), then the lowest
        costs = []
        for lab in pool:
            gap = min((float(np.hypot(*(centroids[j] - centroids[i]))) for j in members[lab]), default=math.inf)
            costs.append((taken.count(lab), -gap, lab))
        best = min(costs)[2]
        labels[i] = best
        members[best].append(i)
    return labels


# ---------------------------------------------------------------------- copies


def _choose(codes: NDArray[np.int64], labels: NDArray[np.int64], priority: dict[int, int], n_labels: int):
    """The code each label gets for one vertex: a body given priority (touching at rest)
    decides its label, else the most frequent code among the label's bodies (-1 skipped)."""
    chosen = np.full(n_labels, -1, dtype=np.int64)
    valid = codes >= 0
    if valid.any():
        pairs = labels[valid] * (int(codes.max()) + 1) + codes[valid]
        uniq, counts = np.unique(pairs, return_counts=True)
        width = int(codes.max()) + 1
        best_count = np.zeros(n_labels, dtype=np.int64)
        for u, cnt in zip(uniq, counts, strict=True):
            lab, code = divmod(int(u), width)
            if cnt > best_count[lab]:
                best_count[lab], chosen[lab] = cnt, code
    for body, code in priority.items():
        chosen[labels[body]] = code
    return chosen


def plan_contacts(model: DemModel, radii: NDArray[np.float64], n_labels: int = N_LABELS) -> ContactPlan:
    """Sphere centres, copies, masks and materials for a model (see module docstring).

    The report counts, over every vertex and every other body, the contacts whose joint
    differs from ``JointTable.joint_for`` (times 1/2 at flush ends): ``differ_at_rest``
    (pairs touching at rest; 0 by construction unless labels ran out) and
    ``differ_in_motion`` (pairs that can only meet in motion), with examples by name.
    """
    nb = len(model.bodies)
    polys = world_polygons(model)
    centers = sphere_centers(model, radii)
    flush = flush_ends(model, polys)
    labels = assign_labels(model, n_labels)
    neighbours = _rest_neighbours(model)
    variant_index: dict[tuple[int, float], int] = {}
    variants: list[Variant] = []

    def variant(code: int) -> int:
        key = (code // 2, 0.5 if code % 2 else 1.0)
        if key not in variant_index:
            variant_index[key] = len(variants)
            variants.append(Variant(*key))
        return variant_index[key]

    copies: list[list[list[tuple[int, int]]]] = []
    counts = {"differ_at_rest": 0, "differ_in_motion": 0, "vertex_body_pairs": 0}
    examples: list[dict[str, object]] = []
    closest = math.inf
    names = model.names
    for a in range(nb):
        row = body_row(model, a)
        body_codes = np.where(row[:nb] >= 0, 2 * row[:nb], -1)
        base_code = 2 * int(row[nb]) if row[nb] >= 0 else -1
        priority = {b: int(body_codes[b]) for b in neighbours[a]}
        shared = _choose(body_codes, labels, priority, n_labels)
        body_copies = []
        gaps: dict[int, float] = {}
        for v in range(len(model.bodies[a].contact_vertices_m)):
            codes = body_codes.copy()
            chosen = shared.copy()
            for b in neighbours[a]:
                if (a, v, b) in flush and codes[b] >= 0:
                    codes[b] += 1
                    chosen[labels[b]] = codes[b]
            # the labels each code meets, and the base
            masks: dict[int, int] = defaultdict(int)
            for lab in range(n_labels):
                if chosen[lab] >= 0:
                    masks[int(chosen[lab])] |= 1 << (1 + lab)
            if base_code >= 0:
                masks[base_code] |= BASE_BIT
            body_copies.append([(variant(code), mask) for code, mask in sorted(masks.items())])
            used = chosen[labels]
            differ = (used != codes) & (np.arange(nb) != a) & ((codes >= 0) | (used >= 0))
            counts["vertex_body_pairs"] += nb - 1
            for b in np.flatnonzero(differ).tolist():
                at_rest = int(b) in neighbours[a]
                counts["differ_at_rest" if at_rest else "differ_in_motion"] += 1
                if int(b) not in gaps:
                    gaps[int(b)] = -penetration_depth(polys[a], polys[int(b)])
                closest = min(closest, gaps[int(b)])
                if len(examples) < MAX_LISTED:
                    examples.append(
                        {
                            "vertex_of": names[a],
                            "vertex": v,
                            "meets": names[int(b)],
                            "touch_at_rest": at_rest,
                            "reference_joint": _describe(int(codes[b])),
                            "yade_joint": _describe(int(used[b])),
                        }
                    )
        copies.append(body_copies)
    report: dict[str, object] = {
        **counts,
        "labels": int(labels.max()) + 1 if nb else 0,
        "flush_vertex_spheres": len(flush),
        "closest_differing_pair_gap_m": None if math.isinf(closest) else closest,
        "examples": examples,
    }
    return ContactPlan(variants, labels, centers, copies, report)


def _describe(code: int) -> str:
    if code < 0:
        return "no contact"
    return f"joint {code // 2}" + (" x 1/2 (flush end)" if code % 2 else "")
