"""One calibration: the joint beneath a block, whatever the method.

Every caller computes a block's joint here: the model the DEM solvers run
(:func:`rockyade.calibration.model_stage.calibrated_model`), ``rockyade calibrate`` and
``rockyade calibrate --from`` (identified values, :mod:`rockyade.identification.identified`).
The method follows from the scene's ``[contact]`` table (:func:`calibration_method`):

* ``udec``: ``jkn_Pa_per_m`` given: K = jkn x (L / 2) x t per contact point, L the block's
  base width (the model builder gives each joint at rest its own length), beta explicit;
* ``explicit``: ``K_N_per_m`` and ``beta_s`` given: no classical calibration;
* ``paper``: the paper's Eqs 10-15 from the block's classical parameters
  (:func:`rockyade.calibration.equations.paper_calibration`), an explicit ``K_N_per_m``,
  ``Ks_N_per_m`` or ``beta_s`` replacing the calibrated value (Eq 7's time step follows K,
  Eq 15's xi_min follows beta);
* ``matched``: as ``paper``, then the damping matched so that the reference DEM's effective
  mu equals mu (:mod:`rockyade.calibration.matching`), with xi_min by Eq 15 for that beta.

The model builder (:mod:`rockyade.dem.model_from_scene`) runs the joints it is given: it knows no
calibration. The matching runs the reference DEM (numba): it is imported when a block is
matched, so that the other methods stay quick to load.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from rockyade.blocks.geometry import Block
from rockyade.calibration.equations import paper_calibration, xi_min_eq15
from rockyade.constants import G
from rockyade.dem.joints import ContactParameters, udec_stiffness
from rockyade.dem.model import time_step_eq7
from rockyade.errors import InputError
from rockyade.scene import ContactSpec
from rockyade.scene.description import CALIBRATIONS

if TYPE_CHECKING:
    from rockyade.calibration.matching import MatchedBeta

#: The calibration methods, as :func:`calibration_method` names them.
METHODS = ("udec", "explicit", "paper", "matched")


@dataclass(frozen=True)
class Calibration:
    """The calibrated joint of one block and how it was found.

    Attributes
    ----------
    joint
        The joint beneath the block (stiffness N/m, damping s, friction degrees, ...), as
        the model runs it.
    method
        One of :data:`METHODS`.
    matched
        The matching's result (achieved mu, reachable range, runs) for ``matched``; None
        otherwise.
    """

    joint: ContactParameters
    method: str
    matched: MatchedBeta | None = None

    def report(self) -> dict[str, object]:
        """The keys ``rockyade calibrate --json`` prints: the joint's
        (:meth:`~rockyade.dem.joints.ContactParameters.report`), and the matching's for
        ``matched`` (:meth:`~rockyade.calibration.matching.MatchedBeta.as_cli_dict`)."""
        out = self.joint.report()
        if self.matched is not None:
            out.update(self.matched.as_cli_dict())
        return out


def calibration_method(contact: ContactSpec) -> str:
    """The method a ``[contact]`` table asks for (see the module docstring).

    ``jkn_Pa_per_m`` makes it ``udec``; ``K_N_per_m`` with ``beta_s`` ``explicit``; else
    ``calibration`` (``paper`` or ``matched``), an explicit ``beta_s`` making it ``paper``
    (nothing left to match).

    Parameters
    ----------
    contact
        The ``[contact]`` settings (stiffness in N/m or Pa/m, damping in s).

    Returns
    -------
    str
        One of :data:`METHODS`.

    Raises
    ------
    InputError
        ``calibration`` is neither ``paper`` nor ``matched``.
    """
    if contact.calibration not in CALIBRATIONS:
        raise InputError(
            "contact.calibration", f"must be one of {', '.join(CALIBRATIONS)}, got {contact.calibration!r}"
        )
    if contact.jkn_Pa_per_m is not None:
        return "udec"
    if contact.K_N_per_m is not None and contact.beta_s is not None:
        return "explicit"
    if contact.calibration == "matched" and contact.beta_s is None:
        return "matched"
    return "paper"


def calibrate(
    block: Block,
    contact: ContactSpec | None = None,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
    supported_mass_kg: float | None = None,
    g: float = G,
) -> Calibration:
    """The joint beneath ``block`` by the method its contact settings ask for.

    Parameters
    ----------
    block
        The block (geometry, mass in kg: Eqs 8-11).
    contact
        The scene's ``[contact]`` settings (method, stiffness scale, explicit K in N/m,
        beta in s, friction in degrees, time-step fraction, ...); default: the paper's
        calibration with the defaults of a scene.
    alpha_rad, p_rad_s, mu
        The block's classical parameters to calibrate with (rad, 1/s, -), e.g. the
        experimental or identified ones; None: the geometry's value.
    supported_mass_kg
        Mass resting on the joint (the block and those above it), kg, for the settlement
        check of the paper's stiffness; default the block's mass.
    g
        Gravity, m/s^2.

    Returns
    -------
    Calibration
        The joint (its ``notes`` say where each value comes from), the method, and the
        matching's result for ``matched``.

    Raises
    ------
    InputError
        A stiffness that lets the block settle more than 1e-4 of its height, a bad
        stiffness scale or calibration method.
    CalibrationError
        Eq 13 without a value (paper), or a target mu the dashpot cannot reach (matched).
    """
    c = contact if contact is not None else ContactSpec()
    method = calibration_method(c)
    if method == "udec":
        assert c.jkn_Pa_per_m is not None
        base_width = float(np.ptp(block.vertices_m[block.vertices_m[:, 1] <= 1e-9 * block.height_m, 0]))
        jks = c.jks_Pa_per_m if c.jks_Pa_per_m is not None else c.jkn_Pa_per_m
        K = udec_stiffness(c.jkn_Pa_per_m, base_width, block.thickness_m)
        Ks = udec_stiffness(jks, base_width, block.thickness_m)
        note = f"UDEC-style: K = jkn x (L/2) x t with L = base width {base_width:.6g} m"
        return Calibration(explicit_joint(K, Ks, c.beta_s or 0.0, c, block.mass_kg, (note,)), method)
    if method == "explicit":
        assert c.K_N_per_m is not None and c.beta_s is not None
        Ks = c.Ks_N_per_m if c.Ks_N_per_m is not None else c.K_N_per_m
        joint = explicit_joint(c.K_N_per_m, Ks, c.beta_s, c, block.mass_kg, ("K and beta explicit",))
        return Calibration(joint, method)
    classical = {"alpha_rad": alpha_rad, "p_rad_s": p_rad_s, "mu": mu}
    joint = paper_calibration(
        block,
        alpha_rad=alpha_rad,
        p_rad_s=p_rad_s,
        mu=mu,
        stiffness_scale=c.stiffness_scale,
        friction_angle_deg=c.friction_angle_deg,
        supported_mass_kg=supported_mass_kg if c.K_N_per_m is None else None,
        frac=c.time_step_frac,
        g=g,
        beta_s=c.beta_s,
    )
    joint = _with_explicit_values(joint, c, block.mass_kg)
    if method == "paper":
        return Calibration(joint, method)
    from rockyade.calibration.matching import match_beta  # runs the reference DEM (numba)

    matched = match_beta(block, joint, **classical)
    note = (
        f"beta matched: reference DEM effective mu {matched.mu_eff:.5f} for target "
        f"{matched.mu_target:.5f} (reachable {matched.mu_min:.4f}-{matched.mu_max:.4f}); "
        f"Eq 13 gives {joint.beta_eq13_s:.4g} s"
        if joint.beta_eq13_s is not None
        else "beta matched (Eq 13 has no value here)"
    )
    joint = replace(
        joint,
        beta_s=matched.beta_s,
        xi_min=xi_min_eq15(matched.beta_s, joint.f_min_hz),
        method="matched",
        notes=(*joint.notes, note),
    )
    return Calibration(joint, method, matched)


def explicit_joint(
    K_N_per_m: float, Ks_N_per_m: float, beta_s: float, contact: ContactSpec, mass_kg: float, notes: Sequence[str]
) -> ContactParameters:
    """A joint given by its values, without classical calibration.

    Parameters
    ----------
    K_N_per_m, Ks_N_per_m
        Normal and shear stiffness per contact point, N/m.
    beta_s
        Stiffness-proportional damping, s.
    contact
        The contact settings (friction angle in degrees, Eq 7's time-step fraction).
    mass_kg
        The block's mass, kg (Eq 7's time step of the block alone).
    notes
        Where the values come from.
    """
    return ContactParameters(
        K_N_per_m=float(K_N_per_m),
        Ks_N_per_m=float(Ks_N_per_m),
        friction_angle_deg=float(contact.friction_angle_deg),
        cohesion_Pa=0.0,
        beta_s=float(beta_s),
        rayleigh_a_1_s=0.0,
        xi_min=math.nan,
        f_min_hz=math.nan,
        b_eq_m=math.nan,
        K_paper=math.nan,
        stiffness_scale=1.0,
        stiffness_reading="N/m (explicit)",
        gamma=math.nan,
        beta_eq13_s=None,
        method="explicit",
        dt_eq7_s=time_step_eq7(mass_kg, K_N_per_m, contact.time_step_frac),
        settlement_m=math.nan,
        notes=tuple(notes),
    )


def _with_explicit_values(joint: ContactParameters, c: ContactSpec, mass_kg: float) -> ContactParameters:
    """The paper's joint with the contact's explicit K, Ks and beta noted (K, Ks replaced;
    beta was given to Eqs 14-15 already); Eq 7's time step for the K used."""
    notes = list(joint.notes)
    k, ks = joint.K_N_per_m, joint.Ks_N_per_m
    if c.K_N_per_m is not None:
        k = ks = c.K_N_per_m
        notes.append("K_N_per_m explicit")
    if c.Ks_N_per_m is not None:
        ks = c.Ks_N_per_m
        notes.append("Ks_N_per_m explicit")
    if c.beta_s is not None:
        notes.append("beta_s explicit")
    return replace(
        joint, K_N_per_m=k, Ks_N_per_m=ks, notes=tuple(notes), dt_eq7_s=time_step_eq7(mass_kg, k, c.time_step_frac)
    )
