"""A DEM model as the JSON data the YADE driver (:mod:`rockyade.dem.yade_driver`) reads.

Scenes are data, never code: no value is pasted into Python source for YADE.
"""

from __future__ import annotations

import math

import numpy as np

from rockyade.blocks.geometry import LEVEL_TOL
from rockyade.dem.model import DemModel
from rockyade.errors import InputError

#: Radius of the vertex spheres as a fraction of the smallest block dimension.
SPHERE_RADIUS_FRACTION = 1e-3
#: Thickness of the contact slabs as a fraction of the block height.
SLAB_FRACTION = 0.05
MAX_BLOCKS = 30



def _roles(vertices: np.ndarray) -> list[str]:
    y = vertices[:, 1]
    tol = LEVEL_TOL * max(float(np.ptp(y)), 1.0) * 10
    return ["base" if v <= y.min() + tol else "top" if v >= y.max() - tol else "side" for v in y]


def scene_payload(model: DemModel) -> dict[str, object]:
    """The DEM model as the JSON data the YADE driver reads."""
    nb = len(model.bodies)
    if nb > MAX_BLOCKS:
        raise InputError(
            "blocks", f"the YADE backend takes at most {MAX_BLOCKS} blocks (collision mask bits), got {nb}"
        )
    sizes = [float(np.min(np.ptp(b.contact_vertices_m, axis=0))) for b in model.bodies]
    radius = SPHERE_RADIUS_FRACTION * min(sizes)

    if any(b.fixed for b in model.bodies) or model.joints.n_pairs > nb - 1:
        raise InputError("blocks", "the YADE backend runs single columns only (no fixed or side-by-side blocks)")

    def joint(i: int) -> dict[str, float]:
        j = model.joints.params[int(model.joints.base_joint[i])]
        return {
            "kn": j.K_N_per_m,
            "ks": j.Ks_N_per_m,
            "cn": j.beta_s * j.K_N_per_m,
            "cs": j.beta_s * j.Ks_N_per_m,
            "friction_angle_rad": math.radians(j.friction_angle_deg),
        }

    bodies = []
    for i, b in enumerate(model.bodies):
        verts = b.contact_vertices_m
        roles = _roles(verts)
        height = float(np.ptp(verts[:, 1]))
        s = SLAB_FRACTION * height
        slabs = []
        if i + 1 < nb:  # a block rests on this one: its top face
            top = verts[[r == "top" for r in roles]]
            slabs.append(
                {
                    "center_m": [float(top[:, 0].mean()), float(verts[:, 1].max() - s / 2)],
                    "half_extents_m": [float(np.ptp(top[:, 0]) / 2), s / 2],
                    "mask_bits": [i + 1],
                }
            )
        if i > 0:  # this block rests on another: its base face
            base = verts[[r == "base" for r in roles]]
            slabs.append(
                {
                    "center_m": [float(base[:, 0].mean()), float(verts[:, 1].min() + s / 2)],
                    "half_extents_m": [float(np.ptp(base[:, 0]) / 2), s / 2],
                    "mask_bits": [i - 1],
                }
            )
        bodies.append(
            {
                "name": b.name,
                "mass_kg": b.mass_kg,
                "inertia_kgm2": b.inertia_kgm2,
                "vertices_m": verts.tolist(),
                "vertex_roles": roles,
                "centroid0_m": model.pos0_m[i].tolist(),
                "rest_centroid_m": list(b.rest_centroid_m),
                "angle0_rad": float(model.ang0_rad[i]),
                "vel0_m_s": model.vel0_m_s[i].tolist(),
                "angvel0_rad_s": float(model.angvel0_rad_s[i]),
                "accel_point_m": list(b.accel_point_m),
                "joint_below": joint(i),
                "joint_above": joint(i + 1) if i + 1 < nb else None,
                "thickness_m": max(0.1 * height, 10 * radius),
                "slabs": slabs,
            }
        )
    motion = model.motion
    return {
        "format": "rockyade-yade-scene-1",
        "scene_hash": model.scene_hash,
        "dt_s": model.dt_s,
        "n_steps": model.n_steps,
        "steps_per_sample": model.steps_per_sample,
        "n_samples": model.n_samples,
        "g": model.g,
        "sphere_radius_m": radius,
        "bodies": bodies,
        "motion": None
        if motion is None
        else {"t_s": motion.t_s.tolist(), "ah_m_s2": motion.ah_m_s2.tolist(), "av_m_s2": motion.av_m_s2.tolist()},
    }
