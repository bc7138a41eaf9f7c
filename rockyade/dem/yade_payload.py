"""A DEM model as the JSON data the YADE driver (:mod:`rockyade.dem.yade_driver`) reads.

Scenes are data, never code: no value is pasted into Python source for YADE. Everything
about the contacts (sphere centres, their copies, materials and collision masks) is decided
here (:mod:`rockyade.dem.yade_contacts`); the driver only builds what the data says.
"""

from __future__ import annotations

import math

import numpy as np

from rockyade.dem.model import DemModel
from rockyade.dem.yade_contacts import BASE_BIT, plan_contacts

#: Radius of the vertex spheres: this fraction of the largest of the blocks' smallest
#: dimensions (a contact breaks when it penetrates deeper than the sphere's radius, so a
#: heavy block landing on a small one must not meet spheres scaled to the small one).
SPHERE_RADIUS_FRACTION = 1e-3
#: Half thickness (z) of the prisms as a fraction of the block size (contacts are at z = 0).
PRISM_HALF_THICKNESS_FRACTION = 0.05
FORMAT = "rockyade-yade-scene-2"


def sphere_radii(model: DemModel) -> np.ndarray:
    """Radius of each body's vertex spheres, m (see SPHERE_RADIUS_FRACTION): the same for all,
    from the moving blocks' sizes (a large fixed abutment does not round the small blocks)."""
    small = [float(np.min(np.ptp(b.contact_vertices_m, axis=0))) for b in model.bodies if not b.fixed]
    return np.full(len(model.bodies), SPHERE_RADIUS_FRACTION * max(small))


def scene_payload(model: DemModel) -> dict[str, object]:
    """The DEM model as the JSON data the YADE driver reads."""
    radii = sphere_radii(model)
    plan = plan_contacts(model, radii)
    params = model.joints.params
    materials = []
    for v in plan.variants:
        j = params[v.joint]
        materials.append(
            {
                "kn": v.factor * j.K_N_per_m,
                "ks": v.factor * j.Ks_N_per_m,
                "cn": v.factor * j.beta_s * j.K_N_per_m,
                "cs": v.factor * j.beta_s * j.Ks_N_per_m,
                "friction_angle_rad": math.radians(j.friction_angle_deg),
                "joint": v.joint,
                "factor": v.factor,
            }
        )
    bodies = []
    for i, b in enumerate(model.bodies):
        size = float(np.max(np.ptp(b.contact_vertices_m, axis=0)))
        bodies.append(
            {
                "name": b.name,
                "fixed": bool(b.fixed),
                "mass_kg": b.mass_kg,
                "inertia_kgm2": b.inertia_kgm2,
                "vertices_m": b.contact_vertices_m.tolist(),
                "sphere_centers_m": plan.centers_m[i].tolist(),
                "sphere_copies": [[list(c) for c in vertex] for vertex in plan.copies[i]],
                "prism_mask": plan.prism_mask(i),
                "sphere_radius_m": float(radii[i]),
                "prism_half_thickness_m": max(PRISM_HALF_THICKNESS_FRACTION * size, 5 * float(radii[i])),
                "centroid0_m": model.pos0_m[i].tolist(),
                "angle0_rad": float(model.ang0_rad[i]),
                "rest_angle_rad": b.rest_angle_rad,
                "vel0_m_s": model.vel0_m_s[i].tolist(),
                "angvel0_rad_s": float(model.angvel0_rad_s[i]),
                "accel_point_m": list(b.accel_point_m),
            }
        )
    motion = model.motion
    return {
        "format": FORMAT,
        "scene_hash": model.scene_hash,
        "dt_s": model.dt_s,
        "n_steps": model.n_steps,
        "steps_per_sample": model.steps_per_sample,
        "n_samples": model.n_samples,
        "g": model.g,
        "min_sphere_radius_m": float(radii.min()),
        "base_mask": BASE_BIT,
        "materials": materials,
        "bodies": bodies,
        "contact_plan": plan.report,
        "motion": None
        if motion is None
        else {"t_s": motion.t_s.tolist(), "ah_m_s2": motion.ah_m_s2.tolist(), "av_m_s2": motion.av_m_s2.tolist()},
    }
