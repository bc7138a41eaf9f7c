"""A scene resolved into the DEM model both DEM solvers run (see :mod:`rockyade.dem.model`).

Bodies: the contact polygon of each block is its own, with its base corners moved to the
equivalent base x_c +/- b_eq, b_eq = h tan(alpha) (paper Eq 11) when alpha is
overridden; when p is overridden the inertia is set so that the DEM rocks with that p:
I_O = M g R / p^2 (Eq 8 does not do it: a stiff contact does not change p). Each body is
placed at rest as the scene says (stacked, or at ``position_m`` rotated by
``rotation_rad``).

Joints (:mod:`rockyade.dem.joints`): each moving block's own joint is given, as the
calibration stage computed it (:func:`rockyade.calibration.model_stage.calibrated_model`
calibrates, then builds here); this module resolves the joint of every pair touching at
rest (bed, head, block-base, block-fixed). The time step (Eq 7, kept below the stability
limit) and the static settlement come from the springs at rest (:mod:`rockyade.dem.statics`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from rockyade.blocks.classical import frequency_parameter, inertia_for_frequency
from rockyade.blocks.geometry import LEVEL_TOL, Block
from rockyade.constants import MAX_SETTLEMENT_FRACTION, G
from rockyade.dem.joints import ContactParameters, JointTable, resolve_joints
from rockyade.dem.model import STABILITY_MARGIN, DemBody, DemModel, check_user_dt, time_step_eq7
from rockyade.dem.overturn import stop_angles
from rockyade.dem.statics import mass_vector, rest_load_wrenches, rest_springs, stability_limit, static_penetration
from rockyade.errors import InputError, at_least, at_most
from rockyade.scene import BlockSpec, Scene
from rockyade.scene.carried import carried_on, loaded_mass_properties, residual_force
from rockyade.scene.placement import PlacedBlock, RestContact, placed_blocks, rest_contacts, rotation_matrix

# ---------------------------------------------------------------------- bodies


def contact_polygon(block: Block, alpha_rad: float | None) -> np.ndarray:
    """The block's polygon with its base corners at x_c +/- h tan(alpha) (paper Eq 11).

    Without an alpha override the polygon is the block's own. Vertices are returned in the
    block frame, counter-clockwise; a vertex that the moved corners leave inside the hull
    is dropped.

    Parameters
    ----------
    block
        The block (vertices in m, base on y = 0).
    alpha_rad
        The alpha override, rad; None keeps the block's own base.

    Returns
    -------
    numpy.ndarray
        (n, 2) vertices, m, starting at the bottom-left corner.
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
    from scipy.spatial import ConvexHull  # here: scipy.spatial costs 0.2-1 s to import, most scenes need none

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
    joint: ContactParameters | None,
    placed: PlacedBlock,
    accel_point: object,
    g: float,
    carried: Sequence[tuple[tuple[float, float], float]] = (),
) -> DemBody:
    """The DEM body of one block, with the masses of the loads it carries merged in
    (:func:`rockyade.scene.carried.loaded_mass_properties`): the body's centroid is the
    loaded block's, its contact polygon and output point are given from there."""
    block = spec.block()
    cx, cy = block.centroid_m
    polygon = contact_polygon(block, spec.alpha_rad)
    notes: list[str] = []
    if spec.alpha_rad is not None:
        notes.append(
            f"base corners at the equivalent base b_eq = h tan(alpha) = {cy * math.tan(spec.alpha_rad):.6g} m (Eq 11)"
        )
    if accel_point == "top_centre":
        point = (0.0, block.height_m - cy)
    else:
        point = (float(accel_point[0]) - cx, float(accel_point[1]) - cy)  # type: ignore[index]
    common: dict[str, Any] = dict(
        name=spec.name,
        mass_kg=block.mass_kg,
        contact_vertices_m=polygon - np.array([cx, cy]),
        rest_centroid_m=placed.centroid_m,
        accel_point_m=point,
        joint=joint,
        fixed=spec.fixed,
        rest_angle_rad=placed.rotation_rad,
    )
    if spec.fixed:
        nan = math.nan
        return DemBody(inertia_kgm2=block.inertia_c_kgm2, alpha_rad=nan, p_rad_s=nan, R_m=nan, **common)
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
    mass = block.mass_kg
    if carried:
        props = loaded_mass_properties(mass, placed.centroid_m, inertia, carried)
        shift = rotation_matrix(-placed.rotation_rad) @ (np.asarray(props.centroid_m) - np.asarray(placed.centroid_m))
        cx, cy = cx + float(shift[0]), cy + float(shift[1])  # the loaded block's centroid, block frame
        mass, inertia = props.mass_kg, props.inertia_c_kgm2
        common.update(
            mass_kg=mass,
            contact_vertices_m=polygon - np.array([cx, cy]),
            rest_centroid_m=props.centroid_m,
            accel_point_m=(point[0] - float(shift[0]), point[1] - float(shift[1])),
        )
        notes.append(f"carries {props.carried_kg:.6g} kg of load mass: centroid and inertia of the loaded block")
        R = float(np.hypot(cx - pivot_left[0], cy))
        alpha = math.atan2(abs(cx - pivot_left[0]), cy)
    p = frequency_parameter(mass, R, inertia + mass * R * R, g)
    return DemBody(inertia_kgm2=inertia, alpha_rad=alpha, p_rad_s=p, R_m=R, notes=tuple(notes), **common)


def world_polygon(body: DemBody) -> np.ndarray:
    """A body's contact polygon in the base frame at rest.

    Parameters
    ----------
    body
        The body (polygon relative to its centroid, rest centroid and angle).

    Returns
    -------
    numpy.ndarray
        (n, 2) vertices, m.
    """
    return body.contact_vertices_m @ rotation_matrix(body.rest_angle_rad).T + np.asarray(body.rest_centroid_m)


def _released_group(index: int, contacts: list[RestContact]) -> list[int]:
    """The released block and every block resting on it, through bed joints, transitively."""
    group, todo = {index}, [index]
    while todo:
        k = todo.pop()
        for c in contacts:
            if c.kind != "bed" or c.b < 0 or k not in (c.a, c.b) or c.upper == k:
                continue
            if c.upper not in group:
                group.add(c.upper)
                todo.append(c.upper)
    return sorted(group)


def _initial_state(scene: Scene, bodies: tuple[DemBody, ...], contacts: list[RestContact]):
    nb = len(bodies)
    pos0 = np.array([b.rest_centroid_m for b in bodies], dtype=float)
    ang0 = np.array([b.rest_angle_rad for b in bodies], dtype=float)
    vel0 = np.zeros((nb, 2))
    angvel0 = np.zeros(nb)
    theta0, omega0 = scene.motion.initial_theta_rad, scene.motion.initial_omega_rad_s
    if theta0 == 0.0 and omega0 == 0.0:
        return pos0, ang0, vel0, angvel0
    k = scene.released_index
    verts = world_polygon(bodies[k])
    low = verts[:, 1] <= verts[:, 1].min() + LEVEL_TOL * max(float(np.ptp(verts[:, 1])), 1.0)
    base = verts[low]
    turning_left = theta0 > 0 or (theta0 == 0 and omega0 > 0)
    pivot = base[np.argmin(base[:, 0])] if turning_left else base[np.argmax(base[:, 0])]
    c, s = math.cos(theta0), math.sin(theta0)
    for j in _released_group(k, contacts):
        r = pos0[j] - pivot
        r = np.array([c * r[0] - s * r[1], s * r[0] + c * r[1]])
        pos0[j] = pivot + r
        ang0[j] += theta0
        vel0[j] = omega0 * np.array([-r[1], r[0]])
        angvel0[j] = omega0
    return pos0, ang0, vel0, angvel0


def _calibration_label(scene: Scene) -> str:
    """Where the joints' stiffness comes from, as the result's metadata says it."""
    c = scene.contact
    if c.jkn_Pa_per_m is not None:
        return "udec (jkn_Pa_per_m)"
    if c.K_N_per_m is not None:
        return "explicit (K_N_per_m)"
    return c.calibration


def _check_settlement(
    springs, bodies: tuple[DemBody, ...], contacts: list[RestContact], joints: JointTable, scene: Scene, g: float
) -> float:
    """Largest static penetration under gravity and the scene's point loads, m; refused above
    MAX_SETTLEMENT_FRACTION of the blocks' height."""
    body_names = [b.name for b in bodies]
    centroids = np.array([b.rest_centroid_m for b in bodies], dtype=float)
    loads = None
    if scene.loads:
        located = [(body_names.index(q.block), q.point_m, residual_force(q, g)) for q in scene.loads]
        loads = rest_load_wrenches(len(bodies), centroids, located)
    pen = static_penetration(springs, [b.mass_kg for b in bodies], [b.fixed for b in bodies], g, loads)
    if pen is None or pen.size == 0:
        return math.nan
    owner = springs.contact[springs.normal]
    heights = np.array([_joint_height(contacts[int(k)], bodies) for k in owner])
    worst = int(np.argmax(pen / heights))
    c = contacts[int(owner[worst])]
    height = heights[worst]
    if pen[worst] > MAX_SETTLEMENT_FRACTION * height:
        names = bodies[c.a].name + ("-base" if c.b < 0 else f"-{bodies[c.b].name}")
        k = joints.params[joints.joint_for(c.a, c.b)].K_N_per_m
        factor = pen[worst] / (MAX_SETTLEMENT_FRACTION * height)  # the settlement goes as 1/K
        if scene.contact.jkn_Pa_per_m is not None:
            field_name = "contact.jkn_Pa_per_m"
            jkn = scene.contact.jkn_Pa_per_m
            advice = (
                f"raise jkn_Pa_per_m from {jkn:.4g} to at least {at_least(jkn * factor)} Pa/m "
                f"({at_least(factor)} times), or the [[joints]] override of this pair"
            )
        elif scene.contact.explicit_stiffness:
            field_name = "contact.K_N_per_m"
            advice = f"raise K_N_per_m at least {at_least(factor)} times"
        else:
            field_name = "contact.stiffness_scale"
            advice = "raise the stiffness (the paper's K reads as MN/m: stiffness_scale = 'MN/m') or check the units"
        raise InputError(
            field_name,
            f"K = {k:.4g} N/m lets the joint {names} sink {at_least(pen[worst])} m under the static load, above "
            f"{MAX_SETTLEMENT_FRACTION:g} of the block height ({at_most(MAX_SETTLEMENT_FRACTION * height)} m): the "
            f"blocks sink into each other; {advice}",
        )
    return float(pen.max())


def _joint_height(c: RestContact, bodies: tuple[DemBody, ...]) -> float:
    """Height of the smaller moving block of a joint, m (the settlement scale)."""
    heights = [float(np.ptp(bodies[i].contact_vertices_m[:, 1])) for i in (c.a, c.b) if i >= 0 and not bodies[i].fixed]
    return min(heights)


# ---------------------------------------------------------------------- loads


def load_arrays(
    scene: Scene, bodies: Sequence[DemBody], g: float = G
) -> tuple[np.ndarray, np.ndarray] | tuple[None, None]:
    """Each body's point loads reduced for the kernel (:mod:`rockyade.kernel.point_loads`).

    A load F at the base-frame point p acts on its body at r_b = R(-theta_rest) (p - c), its
    arm from the centroid c in the body frame at angle 0 (the frame the kernel turns by the
    body's angle). The weight of the load's mass acts through its body's (the mass is merged
    into the body, :func:`_dem_body`): F here is the rest, :func:`rockyade.scene.carried.residual_force`.

    Returns
    -------
    load_force, load_arm
        (nb, 2) resultant (Fx, Fy), N, and (nb, 2) (M0, Q) = (sum r_b x F, sum r_b . F), N m;
        (None, None) when the scene has no loads.
    """
    if not scene.loads:
        return None, None
    names = [b.name for b in bodies]
    force = np.zeros((len(bodies), 2))
    arm = np.zeros((len(bodies), 2))
    for load in scene.loads:
        i = names.index(load.block)
        body = bodies[i]
        r = rotation_matrix(-body.rest_angle_rad) @ (np.asarray(load.point_m) - np.asarray(body.rest_centroid_m))
        fx, fy = residual_force(load, g)
        force[i] += (fx, fy)
        arm[i, 0] += r[0] * fy - r[1] * fx
        arm[i, 1] += r[0] * fx + r[1] * fy
    return force, arm


# ---------------------------------------------------------------------- model


def build_dem_model(
    scene: Scene,
    joints: Sequence[ContactParameters | None],
    g: float = G,
    *,
    rigid_contacts: bool = False,
) -> DemModel:
    """Resolve a scene and its blocks' own joints into the DEM model both DEM solvers run.

    Parameters
    ----------
    scene
        A validated scene.
    joints
        The own joint of each block, bottom to top (None for a fixed block): the interface
        beneath it, stiffness in N/m and damping in s, as the calibration stage computed it
        (:func:`rockyade.calibration.calibrate.calibrate`).
    g
        Gravity, m/s^2.
    rigid_contacts
        True for a solver whose contacts are rigid (Siconos: unilateral constraints, no
        springs): the springs' static settlement is then not checked (it is not the model
        that runs; ``static_settlement_m`` is NaN). The penalty DEMs leave it False.

    Raises
    ------
    InputError
        Joints that do not match the blocks, a settlement above the limit (penalty
        contacts only), or a time step above the stability limit.
    """
    own = list(joints)
    if len(own) != len(scene.blocks) or any(
        (j is None) != spec.fixed for j, spec in zip(own, scene.blocks, strict=True)
    ):
        raise InputError(
            "joints",
            f"must give one joint per moving block and None per fixed block ({len(scene.blocks)} blocks), "
            f"got {len(own)}",
        )
    placed = placed_blocks(scene)
    bodies = tuple(
        _dem_body(
            spec,
            i,
            own[i],
            placed[i],
            scene.output.accel_point,
            g,
            () if spec.fixed else carried_on(scene.loads, spec.name, g),
        )
        for i, spec in enumerate(scene.blocks)
    )
    contacts = rest_contacts(placed, [world_polygon(b) for b in bodies])
    table = resolve_joints(
        scene,
        own,
        contacts,
        [spec.thickness_m for spec in scene.blocks],
        [float(np.ptp(p.vertices_m[:, 0])) for p in placed],
    )
    centroids = np.array([b.rest_centroid_m for b in bodies], dtype=float)
    fixed = [b.fixed for b in bodies]
    springs = rest_springs(centroids, fixed, contacts, table)
    mass = mass_vector([b.mass_kg for b in bodies], [b.inertia_kgm2 for b in bodies], fixed)
    dt_stable, w_max = stability_limit(springs, mass, scene.contact.mass_damping_1_s)
    settlement = math.nan if rigid_contacts else _check_settlement(springs, bodies, contacts, table, scene, g)
    pos0, ang0, vel0, angvel0 = _initial_state(scene, bodies, contacts)
    moving = [b for b in bodies if not b.fixed]
    dt_eq7 = time_step_eq7(
        min(b.mass_kg for b in moving),
        max(p.K_N_per_m for p in table.params),
        scene.contact.time_step_frac,
    )
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
    load_force, load_arm = load_arrays(scene, bodies, g)
    return DemModel(
        bodies=bodies,
        joints=table,
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
        calibration=_calibration_label(scene),
        static_settlement_m=settlement,
        w_max_rad_s=w_max,
        stop_angle_rad=stop_angles([b.contact_vertices_m for b in bodies], fixed),
        stop_on_overturn=not scene.positioned,
        rest_contacts=tuple(contacts),
        base_at_rest=scene.motion.type,
        load_force_N=load_force,
        load_arm_Nm=load_arm,
    )
