"""A scene resolved into the DEM model both DEM solvers run (see :mod:`rockyade.dem.model`).

Bodies: the contact polygon of each block is its own, with its base corners moved to the
equivalent base x_c +/- b_eq, b_eq = h tan(alpha) (paper Eq 11) when alpha is
overridden; when p is overridden the inertia is set so that the DEM rocks with that p:
I_O = M g R / p^2 (Eq 8 does not do it: a stiff contact does not change p). Joints: the
contact parameters of the interface beneath each block (paper Eqs 10-15, or explicit
values); a matched calibration must have been resolved before (:mod:`rockyade.dem.matching`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from scipy.spatial import ConvexHull

from rockyade.blocks.calibration import ContactParameters, check_settlement, paper_calibration, time_step_eq7
from rockyade.blocks.classical import frequency_parameter, inertia_for_frequency
from rockyade.blocks.geometry import LEVEL_TOL, Block
from rockyade.constants import G
from rockyade.dem.model import STABILITY_MARGIN, DemBody, DemModel, MatchedBeta, check_user_dt, stability_limit
from rockyade.errors import InputError
from rockyade.scene import BlockSpec, Scene

# ---------------------------------------------------------------------- bodies


def contact_polygon(block: Block, alpha_rad: float | None) -> np.ndarray:
    """The block's polygon with its base corners at x_c +/- h tan(alpha) (paper Eq 11).

    Without an alpha override the polygon is the block's own. Vertices are returned in the
    block frame, counter-clockwise; a vertex that the moved corners leave inside the hull
    is dropped.
    """
    verts = block.vertices_m.copy()
    if alpha_rad is None:
        return _from_bottom_left(verts)
    cx, cy = block.centroid_m
    b_eq = cy * math.tan(alpha_rad)
    on_base = np.abs(verts[:, 1]) <= LEVEL_TOL * max(block.height_m, 1.0)
    others = verts[~on_base]
    new_base = np.array([[cx - b_eq, 0.0], [cx + b_eq, 0.0]])
    points = np.vstack([new_base, others])
    hull = ConvexHull(points)
    return _from_bottom_left(points[hull.vertices])  # hull vertices: counter-clockwise in 2-D


def _from_bottom_left(verts: np.ndarray) -> np.ndarray:
    """Counter-clockwise vertices renumbered to start at the bottom-left corner."""
    low = verts[:, 1] <= verts[:, 1].min() + LEVEL_TOL * max(float(np.ptp(verts[:, 1])), 1.0)
    start = int(np.flatnonzero(low)[np.argmin(verts[low, 0])])
    return np.roll(verts, -start, axis=0)


def _dem_body(
    spec: BlockSpec,
    index: int,
    joint: ContactParameters,
    rest_centroid: tuple[float, float],
    accel_point: object,
    g: float,
) -> DemBody:
    block = spec.block()
    cx, cy = block.centroid_m
    polygon = contact_polygon(block, spec.alpha_rad)
    notes: list[str] = []
    if spec.alpha_rad is not None:
        notes.append(
            f"base corners at the equivalent base b_eq = h tan(alpha) = {cy * math.tan(spec.alpha_rad):.6g} m (Eq 11)"
        )
    xs = polygon[np.abs(polygon[:, 1]) <= LEVEL_TOL * max(block.height_m, 1.0), 0]
    pivot_left = np.array([xs.min(), 0.0])
    R = float(np.hypot(cx - pivot_left[0], cy))
    alpha = math.atan2(abs(cx - pivot_left[0]), cy)
    inertia = block.inertia_c_kgm2
    if spec.p_rad_s is not None:
        i_o = inertia_for_frequency(block.mass_kg, R, spec.p_rad_s, g)
        inertia = i_o - block.mass_kg * R * R
        if inertia <= 0:
            raise InputError(
                f"blocks[{index}].p_rad_s",
                f"p = {spec.p_rad_s:g} 1/s cannot be reached by this block: it needs p^2 < g / R = "
                f"{g / R:.4g} 1/s^2 (a positive centroidal inertia)",
            )
        notes.append(
            f"centroidal inertia set to {inertia:.6g} kg m^2 so that p = sqrt(M g R / I_O) = {spec.p_rad_s:g} 1/s"
        )
    p = frequency_parameter(block.mass_kg, R, inertia + block.mass_kg * R * R, g)
    if accel_point == "top_centre":
        point = (0.0, block.height_m - cy)
    else:
        point = (float(accel_point[0]) - cx, float(accel_point[1]) - cy)  # type: ignore[index]
    return DemBody(
        name=spec.name,
        mass_kg=block.mass_kg,
        inertia_kgm2=inertia,
        contact_vertices_m=polygon - np.array([cx, cy]),
        rest_centroid_m=rest_centroid,
        accel_point_m=point,
        joint=joint,
        alpha_rad=alpha,
        p_rad_s=p,
        R_m=R,
        notes=tuple(notes),
    )


# ---------------------------------------------------------------------- joints


def _joint(
    scene: Scene, index: int, g: float, beta_override: float | None, matched: Mapping[str, MatchedBeta] | None
) -> ContactParameters:
    """Contact parameters of the interface beneath block ``index``."""
    spec = scene.blocks[index]
    block = spec.block()
    c = scene.contact
    supported = sum(b.block().mass_kg for b in scene.blocks[index:])
    joint = paper_calibration(
        block,
        alpha_rad=spec.alpha_rad,
        p_rad_s=spec.p_rad_s,
        mu=spec.mu,
        stiffness_scale=c.stiffness_scale,
        friction_angle_deg=c.friction_angle_deg,
        supported_mass_kg=supported,
        frac=c.time_step_frac,
        g=g,
    )
    notes = list(joint.notes)
    changes: dict[str, object] = {}
    if c.K_N_per_m is not None:
        changes["K_N_per_m"] = c.K_N_per_m
        changes["Ks_N_per_m"] = c.K_N_per_m
        notes.append("K_N_per_m explicit")
    if c.Ks_N_per_m is not None:
        changes["Ks_N_per_m"] = c.Ks_N_per_m
        notes.append("Ks_N_per_m explicit")
    method = joint.method
    beta = None
    if beta_override is not None:
        beta, method = beta_override, "explicit"
    elif c.beta_s is not None:
        beta, method = c.beta_s, "explicit"
        notes.append("beta_s explicit")
    elif c.calibration == "matched":
        found = (matched or {}).get(spec.name)
        if found is None:
            raise InputError(
                "contact.calibration",
                "matched: the damping must be matched before the model is built "
                "(rockyade.dem.matching.build_matched_model, or the solvers, do it)",
            )
        beta, method = found.beta_s, "matched"
        notes.append(
            f"beta matched: reference DEM effective mu {found.mu_eff:.5f} for target {found.mu_target:.5f} "
            f"(reachable {found.mu_min:.4f}-{found.mu_max:.4f}); Eq 13 gives {joint.beta_eq13_s:.4g} s"
        )
    if beta is not None:
        changes["beta_s"] = beta
        changes["xi_min"] = 2.0 * math.pi * beta * joint.f_min_hz
    k = float(changes.get("K_N_per_m", joint.K_N_per_m))  # type: ignore[arg-type]
    settlement = check_settlement(
        supported, k, block.height_m, "contact.K_N_per_m" if c.K_N_per_m else "contact.stiffness_scale", g
    )
    changes.update(
        method=method,
        notes=tuple(notes),
        settlement_m=settlement,
        dt_eq7_s=time_step_eq7(block.mass_kg, k, c.time_step_frac),
    )
    return replace(joint, **changes)  # type: ignore[arg-type]


# ---------------------------------------------------------------------- model


def build_dem_model(
    scene: Scene,
    g: float = G,
    beta_override: float | None = None,
    matched: Mapping[str, MatchedBeta] | None = None,
) -> DemModel:
    """Resolve a scene into the DEM model both DEM solvers run.

    Parameters
    ----------
    scene
        A validated scene.
    g
        Gravity, m/s^2.
    beta_override
        Damping constant for every joint, s (used by the matched calibration itself).
    matched
        Matched damping per block name, for ``calibration = "matched"``
        (:func:`rockyade.dem.matching.matched_betas`).
    """
    joints = [_joint(scene, i, g, beta_override, matched) for i in range(len(scene.blocks))]
    bodies: list[DemBody] = []
    base_y = 0.0
    for index, (spec, joint) in enumerate(zip(scene.blocks, joints, strict=True)):
        block = spec.block()
        cx, cy = block.centroid_m
        rest = (spec.x_offset_m + cx, base_y + cy)
        bodies.append(_dem_body(spec, index, joint, rest, scene.output.accel_point, g))
        base_y += block.height_m
    bodies_t = tuple(bodies)
    nb = len(bodies_t)
    pos0 = np.array([b.rest_centroid_m for b in bodies_t], dtype=float)
    ang0 = np.zeros(nb)
    vel0 = np.zeros((nb, 2))
    angvel0 = np.zeros(nb)
    theta0, omega0 = scene.motion.initial_theta_rad, scene.motion.initial_omega_rad_s
    if theta0 != 0.0 or omega0 != 0.0:
        k = scene.released_index
        verts = bodies_t[k].contact_vertices_m + pos0[k]
        base = verts[np.abs(verts[:, 1] - verts[:, 1].min()) <= 1e-9]
        turning_left = theta0 > 0 or (theta0 == 0 and omega0 > 0)
        pivot = base[np.argmin(base[:, 0])] if turning_left else base[np.argmax(base[:, 0])]
        c, s = math.cos(theta0), math.sin(theta0)
        for j in range(k, nb):
            r = pos0[j] - pivot
            pos0[j] = pivot + np.array([c * r[0] - s * r[1], s * r[0] + c * r[1]])
            ang0[j] = theta0
            r = pos0[j] - pivot
            vel0[j] = omega0 * np.array([-r[1], r[0]])
            angvel0[j] = omega0
    dt_eq7 = time_step_eq7(
        min(b.mass_kg for b in bodies_t),
        max(b.joint.K_N_per_m for b in bodies_t),
        scene.contact.time_step_frac,
    )
    dt_stable, _ = stability_limit(bodies_t, scene.contact.mass_damping_1_s)
    if scene.contact.dt_s is not None:
        check_user_dt(scene.contact.dt_s, dt_stable)
        dt_target, source = scene.contact.dt_s, "user"
    elif dt_eq7 <= STABILITY_MARGIN * dt_stable:
        dt_target, source = dt_eq7, "Eq 7"
    else:
        dt_target, source = (
            STABILITY_MARGIN * dt_stable,
            f"{STABILITY_MARGIN:g} x stability limit (Eq 7 above it)",
        )
    steps = max(1, math.ceil(scene.sample_dt_s / dt_target - 1e-9))
    return DemModel(
        bodies=bodies_t,
        motion=scene.motion.ground_motion(scene.duration_s),
        pos0_m=pos0,
        ang0_rad=ang0,
        vel0_m_s=vel0,
        angvel0_rad_s=angvel0,
        dt_s=scene.sample_dt_s / steps,
        dt_eq7_s=dt_eq7,
        dt_stable_s=dt_stable,
        dt_source=source,
        steps_per_sample=steps,
        n_samples=scene.n_samples,
        sample_dt_s=scene.sample_dt_s,
        duration_s=scene.duration_s,
        mass_damping_1_s=scene.contact.mass_damping_1_s,
        g=g,
        scene_hash=scene.scene_hash,
        calibration=scene.contact.calibration,
    )
