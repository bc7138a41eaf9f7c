"""A DEM model as the JSON data the YADE driver (:mod:`rockyade.yade.driver`) reads.

Scenes are data, never code: no value is pasted into Python source for YADE. Everything
about the contacts (sphere centres, their copies, materials and collision masks) is decided
here (:mod:`rockyade.yade.contact_plan`); the driver only builds what the data says.

Same role as :mod:`rockyade.siconos.payload`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

from __future__ import annotations

import math

import numpy as np

from rockyade.dem.model import DemModel
from rockyade.dem.worker_backend import body_payload
from rockyade.errors import InputError
from rockyade.yade.contact_plan import BASE_BIT, plan_contacts

#: Radius of the vertex spheres: at least this fraction of the largest of the moving
#: blocks' smallest dimensions ...
SPHERE_RADIUS_FRACTION = 1e-3
#: ... and at least the penetration of the heaviest block hitting the softest joint at this
#: speed, v sqrt(M / K) (a contact breaks when it penetrates deeper than the sphere's
#: radius: YADE's sphere-polyhedron contact then loses its normal) ...
IMPACT_SPEED_M_S = 0.5
#: ... but at most this fraction of that dimension (the spheres round the corners).
SPHERE_RADIUS_MAX_FRACTION = 1e-2
#: Half thickness (z) of the prisms as a fraction of the block size (contacts are at z = 0).
PRISM_HALF_THICKNESS_FRACTION = 0.05
FORMAT = "rockyade-yade-scene-2"


def sphere_radii(model: DemModel) -> np.ndarray:
    """Radius of each body's vertex spheres, m (see SPHERE_RADIUS_FRACTION): the same for all,
    from the moving blocks (a large fixed abutment does not round the small blocks)."""
    moving = [b for b in model.bodies if not b.fixed]
    size = max(float(np.min(np.ptp(b.contact_vertices_m, axis=0))) for b in moving)
    k_min = min(p.K_N_per_m for p in model.joints.params)
    impact = IMPACT_SPEED_M_S * math.sqrt(max(b.mass_kg for b in moving) / k_min)
    radius = min(max(SPHERE_RADIUS_FRACTION * size, impact), SPHERE_RADIUS_MAX_FRACTION * size)
    return np.full(len(model.bodies), radius)


def rectangle(vertices: np.ndarray, tol: float = 1e-9) -> dict[str, object] | None:
    """A rectangular contact polygon as a box (centre, half sides, angle of its first edge
    in the body frame), or None. YADE's Box-Sphere contact is several times cheaper than its
    Polyhedra-Sphere contact and keeps its normal however deep a sphere goes."""
    if len(vertices) != 4:
        return None
    edges = np.roll(vertices, -1, axis=0) - vertices
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    scale = float(lengths.max())
    if np.any(np.abs(edges[0] + edges[2]) > tol * scale) or np.any(np.abs(edges[1] + edges[3]) > tol * scale):
        return None
    if abs(float(edges[0] @ edges[1])) > tol * scale * scale:
        return None
    return {
        "center_m": vertices.mean(axis=0).tolist(),
        "half_extents_m": [float(lengths[0]) / 2, float(lengths[1]) / 2],
        "angle_rad": math.atan2(float(edges[0, 1]), float(edges[0, 0])),
    }


def equivalent_loads(model: DemModel) -> list[dict[str, list[float]] | None]:
    """Each body's point loads as one force at one body point, for YADE (None: no load).

    The kernel's reduction (:mod:`rockyade.kernel.point_loads`: the resultant F and the sums
    M0 = r_b x F, Q = r_b . F) is one force F at r = (Q F + M0 (F_y, -F_x)) / |F|^2 (then
    r . F = Q and r x F = M0, so the torque cos(theta) M0 - sin(theta) Q is the same at every
    angle). ``point_m`` is relative to the centroid, in the body frame at angle 0 (the frame
    of ``vertices_m``), m; ``force_N`` in N.

    Raises
    ------
    InputError
        A body whose loads have no resultant but a moment (a pure couple).
    """
    out: list[dict[str, list[float]] | None] = [None] * len(model.bodies)
    if model.load_force_N is None or model.load_arm_Nm is None:
        return out
    for i, body in enumerate(model.bodies):
        fx, fy = (float(v) for v in model.load_force_N[i])
        m0, q = (float(v) for v in model.load_arm_Nm[i])
        f2 = fx * fx + fy * fy
        if body.fixed or (f2 == 0.0 and m0 == 0.0 and q == 0.0):
            continue
        size = float(np.max(np.ptp(body.contact_vertices_m, axis=0)))
        if f2 == 0.0 or math.hypot(m0, q) > 1e6 * size * math.sqrt(f2):
            raise InputError(
                "loads",
                f"the loads on {body.name} are a couple without resultant: the yade solver applies one force "
                "per block; use the reference DEM",
            )
        out[i] = {"point_m": [(q * fx + m0 * fy) / f2, (q * fy - m0 * fx) / f2], "force_N": [fx, fy]}
    return out


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
    loads = equivalent_loads(model)
    bodies = []
    for i, b in enumerate(model.bodies):
        size = float(np.max(np.ptp(b.contact_vertices_m, axis=0)))
        bodies.append(
            {
                **body_payload(model, i),
                "sphere_centers_m": plan.centers_m[i].tolist(),
                "sphere_copies": [[list(c) for c in vertex] for vertex in plan.copies[i]],
                "prism_mask": plan.prism_mask(i),
                "prism_box": rectangle(b.contact_vertices_m),
                "sphere_radius_m": float(radii[i]),
                "prism_half_thickness_m": max(PRISM_HALF_THICKNESS_FRACTION * size, 5 * float(radii[i])),
                "load": loads[i],
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
        "stop_on_overturn": bool(model.stop_on_overturn),
        "min_sphere_radius_m": float(radii.min()),
        "base_mask": BASE_BIT,
        "materials": materials,
        "bodies": bodies,
        "contact_plan": plan.report,
        "motion": None
        if motion is None
        else {"t_s": motion.t_s.tolist(), "ah_m_s2": motion.ah_m_s2.tolist(), "av_m_s2": motion.av_m_s2.tolist()},
    }
