"""How deep the DEM's bodies ever went into each other and into the base.

Penalty contacts let bodies interpenetrate by the contact's elastic deflection (about a
micrometre at the paper's stiffness, read as MN/m). A deeper overlap means a contact that
was missed: a vertex that passed through a neighbour. Both DEMs record their bodies
(contact polygon, rest centroid and rest angle) in the result's metadata, so this check
reads any DEM result the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rockyade.result import Result
from rockyade.scene.placement import candidate_pairs, penetration_depth, rotation_matrix


@dataclass(frozen=True)
class Overlap:
    """The deepest overlap of a run.

    Attributes
    ----------
    depth_m
        Deepest penetration between two bodies or of a body into the base, m (0 if none).
    between
        The two bodies (the second ``"base"`` for the base).
    t_s
        When, s.
    """

    depth_m: float
    between: tuple[str, str]
    t_s: float


def polygons_at(result: Result, k: int) -> dict[str, np.ndarray]:
    """Every body's contact polygon in the base frame at sample ``k`` (from the result's bodies).

    Parameters
    ----------
    result
        A DEM result (its metadata records the bodies).
    k
        Sample index.

    Returns
    -------
    dict
        Body name -> (n, 2) vertices, m.
    """
    out = {}
    for name, body in (result.meta.bodies or {}).items():
        verts = np.asarray(body["contact_vertices_m"], dtype=float)
        rest = np.asarray(body["rest_centroid_m"], dtype=float)
        if body.get("fixed"):
            out[name] = verts @ rotation_matrix(body["rest_angle_rad"]).T + rest
            continue
        theta = result.series("theta_rad", name)[k] + body["rest_angle_rad"]
        shift = np.array([result.series("x_m", name)[k], result.series("y_m", name)[k]])
        out[name] = verts @ rotation_matrix(theta).T + rest + shift
    return out


def max_overlap(result: Result, every: int = 1) -> Overlap:
    """The deepest overlap over the run's samples (every ``every``-th sample).

    Parameters
    ----------
    result
        A DEM result (its metadata records the bodies).
    every
        Stride over the samples (1: every sample).
    """
    worst = Overlap(0.0, ("", ""), 0.0)
    for k in range(0, len(result.t), every):
        polys = polygons_at(result, k)
        names = list(polys)
        if not all(np.all(np.isfinite(p)) for p in polys.values()):
            continue
        for name, p in polys.items():
            depth = -float(p[:, 1].min())
            if depth > worst.depth_m:
                worst = Overlap(depth, (name, "base"), float(result.t[k]))
        for i, j in candidate_pairs([polys[n] for n in names]):
            depth = penetration_depth(polys[names[i]], polys[names[j]])
            if depth > worst.depth_m:
                worst = Overlap(depth, (names[i], names[j]), float(result.t[k]))
    return worst
