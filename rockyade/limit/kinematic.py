"""The code's kinematic quantities of a mechanism (the kinematic method of NTC 2018 for
existing masonry, as its Circolare 2019 sets it out in C8.7.1; EN 1998-3 uses the same ideas).

Linear kinematic analysis:

* alpha0, the multiplier that activates the mechanism, by virtual work: the limit-analysis
  multiplier of the critical mechanism;
* the participating mass M* = (sum P_i dx_i)^2 / (g sum P_i dx_i^2), kg, and the
  participating mass fraction e* = g M* / sum P_i, with P_i the weights of the blocks that
  take part and dx_i the virtual horizontal displacements of their centroids;
* the spectral acceleration that activates the mechanism a0* = alpha0 g / (e* FC), m/s^2,
  FC the confidence factor (1.35 for the limited knowledge level LC1), g the code check's
  (:data:`rockyade.constants.CODE_GRAVITY`: standard gravity, 9.80665 m/s^2, the same g that turns
  the site's ag in g into m/s^2; docs/conventions.md).

Nonlinear kinematic analysis: alpha(dk) as the mechanism moves
(:mod:`rockyade.limit.finite`), dk the horizontal displacement of a control point k (here
the centroid of the block with the largest virtual horizontal displacement, the highest
one of a tie), down to alpha = 0 at dk,0; the equivalent single-degree-of-freedom system
d* = dk sum P_i dx_i^2 / (dx_k sum P_i dx_i), a* = alpha g / (e* FC); d0* (at alpha = 0),
the ultimate displacement du* = 0.4 d0*, and the secant period Ts = 2 pi sqrt(ds* / as*)
at ds* = 0.4 du* (as* the spectral acceleration of the curve at ds*).

The weights P_i are those of the blocks (masses x g, at their centroids) and of the loads they
carry (Circolare 2019 C8.7.1: "i pesi dei blocchi e i carichi verticali portati"), each at its
own point with its own virtual displacement dx_i: a load's mass (:class:`~rockyade.limit.rigid_blocks.PointLoad`
``mass_kg``; by default that of its weight) is a P_i. A load given without mass (``mass_kg = 0``)
acts in alpha0 and in alpha(dk) but carries no inertia, so it does not enter M*, e* or sum P_i.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rockyade.constants import CODE_GRAVITY
from rockyade.errors import InputError
from rockyade.limit.finite import CapacityCurve, capacity_curve
from rockyade.limit.lp import DIRECTIONS
from rockyade.limit.mechanism import Mechanism, point_velocity
from rockyade.limit.rigid_blocks import RigidBlockModel

#: The code's confidence factor FC for the limited knowledge level (LC1).
DEFAULT_FC = 1.35
#: du* = DU_FRACTION d0*, ds* = DS_FRACTION du* (Circolare 2019 C8.7.1).
DU_FRACTION = 0.4
DS_FRACTION = 0.4


@dataclass(frozen=True)
class KinematicQuantities:
    """The code's quantities of one mechanism (module docstring).

    Attributes
    ----------
    alpha0
        Multiplier that activates the mechanism.
    M_star_kg
        Participating mass M*, kg.
    e_star
        Participating mass fraction e* = M* / (sum of the participating blocks' masses).
    participating_mass_kg
        sum P_i / g over the blocks that take part and the loads they carry, kg.
    FC
        Confidence factor.
    a0_star_m_s2
        a0* = alpha0 g / (e* FC), m/s^2.
    control_block
        Name of the block whose centroid is the control point k.
    d_star_factor
        d* / dk = sum P dx^2 / (dx_k sum P dx).
    curve
        The capacity curve alpha(dk), or None (``nonlinear_note`` says why).
    d0_star_m, du_star_m, ds_star_m
        d0*, du* = 0.4 d0*, ds* = 0.4 du*, m (None without a curve reaching alpha = 0).
    as_star_m_s2
        a* at ds*, m/s^2.
    Ts_s
        Secant period 2 pi sqrt(ds* / as*), s.
    nonlinear_note
        Why there is no nonlinear result, else None.
    g
        The g of a0* and a*, m/s^2: the code check's, standard gravity
        (:data:`rockyade.constants.CODE_GRAVITY`).
    """

    alpha0: float
    M_star_kg: float
    e_star: float
    participating_mass_kg: float
    FC: float
    a0_star_m_s2: float
    control_block: str
    d_star_factor: float
    curve: CapacityCurve | None
    d0_star_m: float | None
    du_star_m: float | None
    ds_star_m: float | None
    as_star_m_s2: float | None
    Ts_s: float | None
    nonlinear_note: str | None
    g: float

    def spectral(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """The capacity curve of the equivalent system: (d*, m; a*, m/s^2), or None."""
        if self.curve is None:
            return None
        scale = self.g / (self.e_star * self.FC)
        return self.curve.dk_m * self.d_star_factor, self.curve.alpha * scale

    def to_dict(self) -> dict[str, object]:
        """Plain data (the curve as lists of d* and alpha)."""
        out: dict[str, object] = {
            "alpha0": self.alpha0,
            "M_star_kg": self.M_star_kg,
            "e_star": self.e_star,
            "participating_mass_kg": self.participating_mass_kg,
            "FC": self.FC,
            "a0_star_m_s2": self.a0_star_m_s2,
            "control_block": self.control_block,
            "d_star_factor": self.d_star_factor,
            "d0_star_m": self.d0_star_m,
            "du_star_m": self.du_star_m,
            "ds_star_m": self.ds_star_m,
            "as_star_m_s2": self.as_star_m_s2,
            "Ts_s": self.Ts_s,
            "nonlinear_note": self.nonlinear_note,
        }
        if self.curve is not None:
            out["curve"] = {
                "dk_m": self.curve.dk_m.tolist(),
                "alpha": self.curve.alpha.tolist(),
                "max_joint_gap_m": self.curve.max_joint_gap_m,
                "opened_hinges": [list(h) for h in self.curve.opened],
                "max_overlap_m": self.curve.max_overlap_m,
            }
        return out


def check_fc(value: float) -> float:
    """A confidence factor in [1, 10], else InputError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError("FC", f"must be a number in [1, 10], got {value!r}")
    if not 1.0 <= value <= 10.0:
        raise InputError("FC", f"must be in [1, 10] (the code's confidence factor, 1.35 for LC1), got {value:g}")
    return float(value)


def control_block(model: RigidBlockModel, mechanism: Mechanism, direction: str) -> int:
    """The block whose centroid has the largest virtual displacement along the load (the
    highest centroid among ties within 1e-9)."""
    d = DIRECTIONS[direction]
    dx = d * mechanism.velocities[:, 0]
    dx[~mechanism.moving] = -np.inf
    best = float(dx.max())
    ties = np.flatnonzero(dx >= best - 1e-9 * max(abs(best), 1.0))
    return int(ties[np.argmax(model.centroids_m[ties, 1])])


def kinematic_quantities(
    model: RigidBlockModel,
    mechanism: Mechanism,
    alpha0: float,
    direction: str,
    fc: float = DEFAULT_FC,
    nonlinear: bool = True,
) -> KinematicQuantities:
    """The code's linear and nonlinear quantities of a mechanism (module docstring).

    Parameters
    ----------
    model, mechanism
        The rigid-block model and its collapse mechanism.
    alpha0
        The mechanism's multiplier (the limit-analysis load multiplier).
    direction
        "+x" or "-x".
    fc
        Confidence factor FC (default 1.35).
    nonlinear
        Also follow the mechanism to alpha = 0 (skipped, with a note, when a joint slides with friction
        or when alpha0 is 0).
    """
    fc = check_fc(fc)
    d = DIRECTIONS[direction]
    points = [(i, p, mass) for i, p, mass in model.weight_points() if mechanism.moving[i]]
    m = np.array([mass for _, _, mass in points])
    dx = np.array([d * point_velocity(mechanism.velocities[i], model.centroids_m[i], p)[0] for i, p, _ in points])
    sum_m = float(m.sum())
    s1, s2 = float(np.sum(m * dx)), float(np.sum(m * dx * dx))
    M_star = s1 * s1 / s2
    e_star = M_star / sum_m
    a0_star = alpha0 * CODE_GRAVITY / (e_star * fc)
    k = control_block(model, mechanism, direction)
    dx_k = d * float(mechanism.velocities[k, 0])
    factor = s2 / (dx_k * s1)
    curve = None
    note = None
    values: dict[str, float | None] = dict.fromkeys(("d0", "du", "ds", "as", "Ts"))
    if not nonlinear:
        note = "not asked for"
    elif alpha0 <= 0.0:
        note = "alpha0 = 0: the mechanism moves under any load, so it has no capacity curve to follow"
    elif any(model.interfaces[s.interface].friction_angle_deg for s in mechanism.sliding):
        note = (
            "a joint slides with friction: the code's nonlinear analysis follows rocking mechanisms (hinges, "
            "and frictionless sliding on a restraint); a block sliding with friction keeps alpha = tan(phi) and "
            "never reaches alpha = 0"
        )
    else:
        curve = capacity_curve(model, mechanism, direction, k)
        if curve.d0_m is None:
            note = f"the mechanism could not be followed to alpha = 0: {curve.stopped}"
        else:
            scale = CODE_GRAVITY / (e_star * fc)
            d_star = curve.dk_m * factor
            a_star = curve.alpha * scale
            d0 = curve.d0_m * factor
            du = DU_FRACTION * d0
            ds = DS_FRACTION * du
            as_ = float(np.interp(ds, d_star, a_star))
            period = 2.0 * math.pi * math.sqrt(ds / as_) if as_ > 0.0 and ds > 0.0 else None
            values = {"d0": d0, "du": du, "ds": ds, "as": as_, "Ts": period}
            if period is None:
                note = "the capacity curve has no positive a* at ds*: no secant period"
    return KinematicQuantities(
        alpha0=float(alpha0),
        M_star_kg=M_star,
        e_star=e_star,
        participating_mass_kg=sum_m,
        FC=fc,
        a0_star_m_s2=a0_star,
        control_block=model.names[k],
        d_star_factor=factor,
        curve=curve,
        d0_star_m=values["d0"],
        du_star_m=values["du"],
        ds_star_m=values["ds"],
        as_star_m_s2=values["as"],
        Ts_s=values["Ts"],
        nonlinear_note=note,
        g=CODE_GRAVITY,
    )
