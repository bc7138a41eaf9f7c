"""The DEM model of a scene, read by both DEM solvers (reference DEM and YADE).

From a validated Scene this module resolves, once, everything the two DEMs must share so
that they simulate exactly the same system:

* bodies: mass, centroidal inertia and contact polygon of each block. The polygon is the
  block's own, with its base corners moved to the equivalent base x_c +/- b_eq,
  b_eq = h tan(alpha) (paper Eq 11) when alpha is overridden. When p is overridden the
  inertia is set so that the DEM rocks with that p: I_O = M g R / p^2 (Eq 8 does not do
  it: a stiff contact does not change p);
* joints: the contact parameters of the interface beneath each block, as the calibration
  stage gives them (:mod:`rockyade.calibration.calibrate`: paper Eqs 10-15, matched
  damping, or explicit values), and which pair of bodies uses which (:mod:`rockyade.dem.joints`);
* the initial state (rest, or the released block tilted about its pivot);
* the time step: Eq 7 by default, checked against the stability limit of the explicit
  central-difference scheme for the linearised contact system at rest with its
  stiffness-proportional damping, dt <= (2 / w_max) (sqrt(1 + xi^2) - xi); a user time
  step above that limit is refused;
* the base motion, as piecewise-linear acceleration samples;
* the scene's point loads (``[[loads]]``), reduced per body to a resultant and two moments
  (:mod:`rockyade.kernel.point_loads`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from rockyade.constants import DEFAULT_TIME_STEP_FRAC
from rockyade.dem.joints import ContactParameters, JointTable
from rockyade.errors import InputError, at_least, at_most

if TYPE_CHECKING:  # names only: the calibration imports this module (Eq 7) without the motions and scenes
    from rockyade.motion.ground import GroundMotion
    from rockyade.scene.placement import RestContact

#: Default time step = min(Eq 7, STABILITY_MARGIN * stability limit).
STABILITY_MARGIN = 0.8


def time_step_eq7(mass_min_kg: float, k_max_N_per_m: float, frac: float = DEFAULT_TIME_STEP_FRAC) -> float:
    """Time step of the central-difference scheme, dt = frac 2 sqrt(M_min / K_max), s (paper Eq 7).

    Parameters
    ----------
    mass_min_kg
        Smallest moving mass, kg.
    k_max_N_per_m
        Largest contact stiffness, N/m.
    frac
        Fraction of the critical step 2 sqrt(M / K) (the paper: 0.1).
    """
    return frac * 2.0 * math.sqrt(mass_min_kg / k_max_N_per_m)


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
        The block's own joint (the interface beneath it, calibrated from it); None for a
        fixed body. Which joint a contact uses is decided by ``DemModel.joints``.
    alpha_rad, p_rad_s, R_m
        The DEM's own classical parameters (contact polygon and inertia), left pivot of
        its base in its own frame; NaN for a fixed body.
    notes
        How the body was derived from the block.
    fixed
        Moves with the base (does not move in the base frame).
    rest_angle_rad
        Orientation at rest, rad: the body's world angle is rest_angle + theta.
    """

    name: str
    mass_kg: float
    inertia_kgm2: float
    contact_vertices_m: np.ndarray = field(repr=False)
    rest_centroid_m: tuple[float, float]
    accel_point_m: tuple[float, float]
    joint: ContactParameters | None
    alpha_rad: float
    p_rad_s: float
    R_m: float
    notes: tuple[str, ...] = ()
    fixed: bool = False
    rest_angle_rad: float = 0.0


@dataclass(frozen=True)
class DemModel:
    """Everything both DEMs need, resolved from a scene (see module docstring)."""

    bodies: tuple[DemBody, ...]
    joints: JointTable
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
    static_settlement_m: float = math.nan
    w_max_rad_s: float = math.nan
    stop_angle_rad: np.ndarray | None = field(default=None, repr=False)
    stop_on_overturn: bool = True
    rest_contacts: tuple[RestContact, ...] = ()
    base_at_rest: str = "free"
    #: (nb, 2) resultant of each body's point loads, N, and (nb, 2) their (M0, Q), N m
    #: (:mod:`rockyade.kernel.point_loads`); None: no loads
    load_force_N: np.ndarray | None = field(default=None, repr=False)
    load_arm_Nm: np.ndarray | None = field(default=None, repr=False)

    @property
    def motion_label(self) -> str:
        """What moves the base: the ground motion's label, or ``base_at_rest`` ("free"
        rocking from a tilt, or "rest") when the base does not move."""
        return self.motion.label if self.motion is not None else self.base_at_rest

    @property
    def n_steps(self) -> int:
        """Number of integration steps."""
        return (self.n_samples - 1) * self.steps_per_sample

    @property
    def names(self) -> list[str]:
        """Body names, bottom to top."""
        return [b.name for b in self.bodies]

    @property
    def moving(self) -> list[int]:
        """Indices of the bodies that move (not fixed)."""
        return [i for i, b in enumerate(self.bodies) if not b.fixed]

    def joint_summary(self) -> dict[str, object]:
        """Contact parameters actually used: each moving block's joint against the base (its
        own joint unless overridden) by name, and for assemblies the whole joint table."""
        out: dict[str, object] = {
            b.name: self.joints.params[int(self.joints.base_joint[i])].as_dict()
            for i, b in enumerate(self.bodies)
            if not b.fixed
        }
        if self.joints.n_pairs or any(b.fixed for b in self.bodies):
            out["joint_table"] = self.joints.summary(self.names)
        return out

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
                "fixed": b.fixed,
                "rest_centroid_m": list(b.rest_centroid_m),
                "rest_angle_rad": b.rest_angle_rad,
            }
            for b in self.bodies
        }

    def with_dt(self, dt_s: float) -> DemModel:
        """The model with another time step (rounded down to divide the sample interval).

        Parameters
        ----------
        dt_s
            The time step wanted, s.

        Raises
        ------
        InputError
            Above the stability limit.
        """
        check_user_dt(dt_s, self.dt_stable_s)
        steps = math.ceil(self.sample_dt_s / dt_s - 1e-9)
        return replace(self, dt_s=self.sample_dt_s / steps, steps_per_sample=steps, dt_source="user")

    def with_dt_factor(self, factor: float) -> DemModel:
        """The model with its time step times ``factor`` in (0, 1] (a solver's ``dt_factor``):
        the steps per sample divided by ``factor`` and rounded up, so that the step still
        divides the sample interval and is at most ``factor`` times the one chosen (0.5 halves
        it exactly); itself for 1.

        Parameters
        ----------
        factor
            The factor on the time step, in (0, 1].
        """
        if factor == 1.0:
            return self
        steps = math.ceil(self.steps_per_sample / factor - 1e-9)
        return replace(
            self,
            dt_s=self.sample_dt_s / steps,
            steps_per_sample=steps,
            dt_source=f"{self.dt_source}, times dt_factor {factor:g}",
        )


def check_user_dt(dt_s: float, dt_stable_s: float) -> None:
    """Refuse a time step above the stability limit.

    Parameters
    ----------
    dt_s
        The time step asked for, s.
    dt_stable_s
        The stability limit of the explicit scheme, s.

    Raises
    ------
    InputError
        ``dt_s`` above ``dt_stable_s`` (field ``contact.dt_s``).
    """
    if dt_s > dt_stable_s:
        raise InputError(
            "contact.dt_s",
            f"{at_least(dt_s, 4)} s is above the stability limit {at_most(dt_stable_s, 4)} s of the explicit scheme "
            "for these contacts (stiffness and damping); use a smaller time step or leave it to Eq 7",
        )
