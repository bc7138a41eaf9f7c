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

from rockyade.blocks.calibration import ContactParameters
from rockyade.errors import InputError
from rockyade.motion.ground import GroundMotion

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


@dataclass(frozen=True)
class MatchedBeta:
    """Result of a matched calibration.

    Attributes
    ----------
    beta_s
        Matched stiffness-proportional damping, s.
    mu_eff, mu_target
        Achieved and target effective restitution.
    mu_max, mu_min
        Reachable range: mu_eff without damping and with the heaviest damping tried.
    beta_max_s
        Heaviest damping tried, s.
    beta_eq13_s
        The paper's empirical value (Eq 13), for comparison.
    n_runs
        DEM runs used.
    n_impacts
        Impacts averaged per run.
    """

    beta_s: float
    mu_eff: float
    mu_target: float
    mu_max: float
    mu_min: float
    beta_max_s: float
    beta_eq13_s: float
    n_runs: int
    n_impacts: int

    def as_cli_dict(self) -> dict[str, float]:
        """Keys for ``rockyade calibrate --method matched --json``."""
        return {
            "beta_s": self.beta_s,
            "beta_matched_s": self.beta_s,
            "mu_eff_matched": self.mu_eff,
            "mu_target": self.mu_target,
            "mu_reachable_min": self.mu_min,
            "mu_reachable_max": self.mu_max,
            "beta_eq13_s": self.beta_eq13_s,
            "matching_runs": self.n_runs,
            "matching_impacts": self.n_impacts,
        }
