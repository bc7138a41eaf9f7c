"""The DEM model of a scene, read by both DEM solvers (reference DEM and YADE).

From a validated Scene this module resolves, once, everything the two DEMs must share so
that they simulate exactly the same system:

* bodies: mass, centroidal inertia and contact polygon of each block. The polygon is the
  block's own, with its base corners moved to the equivalent base x_c +/- b_eq,
  b_eq = h tan(alpha) (paper Eq 11) when alpha is overridden. When p is overridden the
  inertia is set so that the DEM rocks with that p: I_O = M g R / p^2 (Eq 8 does not do
  it: a stiff contact does not change p);
* joints: the contact parameters of the interface beneath each block (paper Eqs 10-15,
  or matched damping, or explicit values); a contact between two bodies uses the joint of
  the upper one;
* the initial state (rest, or the released block tilted about its pivot);
* the time step: Eq 7 by default, checked against the stability limit of the explicit
  central-difference scheme for the linearised contact system at rest with its
  stiffness-proportional damping, dt <= (2 / w_max) (sqrt(1 + xi^2) - xi); a user time
  step above that limit is refused;
* the base motion, as piecewise-linear acceleration samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.linalg import eigh
from scipy.spatial import ConvexHull

from rockyade.calibration import ContactParameters, check_settlement, paper_calibration, time_step_eq7
from rockyade.classical import frequency_parameter, inertia_for_frequency
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.geometry import LEVEL_TOL, Block
from rockyade.motion.ground import GroundMotion
from rockyade.scene import BlockSpec, Scene

#: Default time step = min(Eq 7, STABILITY_MARGIN * stability limit).
STABILITY_MARGIN = 0.8


@dataclass(frozen=True)
class DemBody:
    """One rigid block as the DEMs see it.

    Attributes
    ----------
    name
        Block name.
    mass_kg, inertia_kgm2
        Mass and centroidal inertia (adjusted to p when p is overridden).
    contact_vertices_m
        (n, 2) contact polygon relative to the centroid, body frame, counter-clockwise.
    rest_centroid_m
        Centroid at rest, base frame (x, y), m.
    accel_point_m
        Output point relative to the centroid, body frame, m.
    joint
        Contact parameters of the interface beneath this block.
    alpha_rad, p_rad_s, R_m
        The DEM's own classical parameters (contact polygon and inertia), left pivot.
    notes
        How the body was derived from the block.
    """

    name: str
    mass_kg: float
    inertia_kgm2: float
    contact_vertices_m: np.ndarray = field(repr=False)
    rest_centroid_m: tuple[float, float]
    accel_point_m: tuple[float, float]
    joint: ContactParameters
    alpha_rad: float
    p_rad_s: float
    R_m: float
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class DemModel:
    """Everything both DEMs need, resolved from a scene (see module docstring)."""

    bodies: tuple[DemBody, ...]
    motion: GroundMotion | None
    pos0_m: np.ndarray
    ang0_rad: np.ndarray
    vel0_m_s: np.ndarray
    angvel0_rad_s: np.ndarray
    dt_s: float
    dt_eq7_s: float
    dt_stable_s: float
    dt_source: str
    steps_per_sample: int
    n_samples: int
    sample_dt_s: float
    duration_s: float
    mass_damping_1_s: float
    g: float
    scene_hash: str
    calibration: str

    @property
    def n_steps(self) -> int:
        """Number of integration steps."""
        return (self.n_samples - 1) * self.steps_per_sample

    @property
    def names(self) -> list[str]:
        """Body names, bottom to top."""
        return [b.name for b in self.bodies]

    def joint_summary(self) -> dict[str, dict[str, object]]:
        """Contact parameters actually used, per joint (named by the block above it)."""
        return {b.name: b.joint.as_dict() for b in self.bodies}

    def body_summary(self) -> dict[str, dict[str, object]]:
        """The DEM's bodies: mass, inertia, contact polygon, own alpha and p."""
        return {
            b.name: {
                "mass_kg": b.mass_kg,
                "inertia_kgm2": b.inertia_kgm2,
                "contact_vertices_m": b.contact_vertices_m.tolist(),
                "alpha_rad": b.alpha_rad,
                "p_rad_s": b.p_rad_s,
                "R_m": b.R_m,
                "notes": list(b.notes),
            }
            for b in self.bodies
        }

    def with_dt(self, dt_s: float) -> DemModel:
        """The model with another time step (rounded down to divide the sample interval).

        Raises
        ------
        InputError
            Above the stability limit.
        """
        check_user_dt(dt_s, self.dt_stable_s)
        steps = math.ceil(self.sample_dt_s / dt_s - 1e-9)
        return replace(self, dt_s=self.sample_dt_s / steps, steps_per_sample=steps, dt_source="user")


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


def _joint(scene: Scene, index: int, g: float, beta_override: float | None) -> ContactParameters:
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
        from rockyade.matching import match_beta

        matched = match_beta(
            block,
            alpha_rad=spec.alpha_rad,
            p_rad_s=spec.p_rad_s,
            mu=spec.mu,
            stiffness_scale=c.stiffness_scale,
            friction_angle_deg=c.friction_angle_deg,
            K_N_per_m=changes.get("K_N_per_m"),  # type: ignore[arg-type]
        )
        beta, method = matched.beta_s, "matched"
        notes.append(
            f"beta matched: reference DEM effective mu {matched.mu_eff:.5f} for target {matched.mu_target:.5f} "
            f"(reachable {matched.mu_min:.4f}-{matched.mu_max:.4f}); Eq 13 gives {joint.beta_eq13_s:.4g} s"
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


# ---------------------------------------------------------------------- stability


def stability_limit(bodies: tuple[DemBody, ...], mass_damping: float) -> tuple[float, float]:
    """Largest stable time step of the explicit scheme for the system at rest, and w_max.

    The contact springs active at rest (base corners on their support, and support corners
    on the base of the block above) give K; M = diag(m, m, I). With the stiffness
    proportional dashpots the damping ratio of a mode is at most beta_max w / 2 (+ the
    mass-proportional a / (2 w)); the central-difference limit is
    (2 / w) (sqrt(1 + xi^2) - xi), smallest for the highest mode.
    """
    nb = len(bodies)
    K = np.zeros((3 * nb, 3 * nb))
    M = np.zeros(3 * nb)
    for i, b in enumerate(bodies):
        M[3 * i : 3 * i + 2] = b.mass_kg
        M[3 * i + 2] = b.inertia_kgm2

    def add_spring(a: int, b: int, point: np.ndarray, direction: np.ndarray, k: float) -> None:
        row = np.zeros(3 * nb)
        for body, sign in ((a, 1.0), (b, -1.0)):
            if body < 0:
                continue
            r = point - np.asarray(bodies[body].rest_centroid_m)
            row[3 * body : 3 * body + 3] += sign * np.array(
                [direction[0], direction[1], r[0] * direction[1] - r[1] * direction[0]]
            )
        K[:, :] += k * np.outer(row, row)

    n, t = np.array([0.0, 1.0]), np.array([1.0, 0.0])
    for i, body in enumerate(bodies):
        c = np.asarray(body.rest_centroid_m)
        verts = body.contact_vertices_m + c
        base_y = verts[:, 1].min()
        base = verts[np.abs(verts[:, 1] - base_y) <= 1e-9 * max(1.0, abs(base_y))]
        if i == 0:
            supports = [(p, -1) for p in base]
        else:
            below = bodies[i - 1].contact_vertices_m + np.asarray(bodies[i - 1].rest_centroid_m)
            top_y = below[:, 1].max()
            top = below[np.abs(below[:, 1] - top_y) <= 1e-9 * max(1.0, abs(top_y))]
            supports = [(p, i - 1) for p in base if top[:, 0].min() - 1e-12 <= p[0] <= top[:, 0].max() + 1e-12]
            supports += [(p, i - 1) for p in top if base[:, 0].min() < p[0] < base[:, 0].max()]
        for point, other in supports:
            add_spring(i, other, point, n, body.joint.K_N_per_m)
            add_spring(i, other, point, t, body.joint.Ks_N_per_m)
    w2 = eigh(K, np.diag(M), eigvals_only=True)
    w_max = math.sqrt(max(float(w2.max()), 0.0))
    beta_max = max(b.joint.beta_s for b in bodies)
    xi = 0.5 * beta_max * w_max + (0.5 * mass_damping / w_max if w_max > 0 else 0.0)
    return (2.0 / w_max) * (math.sqrt(1.0 + xi * xi) - xi), w_max


def check_user_dt(dt_s: float, dt_stable_s: float) -> None:
    """Refuse a time step above the stability limit."""
    if dt_s > dt_stable_s:
        raise InputError(
            "contact.dt_s",
            f"{dt_s:.4g} s is above the stability limit {dt_stable_s:.4g} s of the explicit scheme "
            "for these contacts (stiffness and damping); use a smaller time step or leave it to Eq 7",
        )


# ---------------------------------------------------------------------- model


def build_dem_model(scene: Scene, g: float = G, beta_override: float | None = None) -> DemModel:
    """Resolve a scene into the DEM model both DEM solvers run.

    Parameters
    ----------
    scene
        A validated scene.
    g
        Gravity, m/s^2.
    beta_override
        Damping constant for every joint, s (used by the matched calibration itself).
    """
    joints = [_joint(scene, i, g, beta_override) for i in range(len(scene.blocks))]
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
