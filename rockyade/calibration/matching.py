"""Matched damping: the contact damping with which the reference DEM loses the target energy.

The paper derives the stiffness-proportional damping b from an empirical fit (Eq 13).
rockyade can instead *match* it: find beta such that the reference DEM's effective
restitution (DESIGN.md: mu_eff = sqrt(V(theta_n+1) / V(theta_n)) from successive peaks)
equals the target mu. Each evaluation is a short free-rocking run of the block alone on a
rigid base, with the joint its calibration gives (:mod:`rockyade.calibration.calibrate`)
and a trial damping beta, released at alpha / 2 and measured over its first ``N_IMPACTS``
impacts after the release; beta is found by Brent's method (scipy) to within ``MU_RTOL``
of the target. The runs go through the model builder and the engine every DEM solver
uses (:func:`rockyade.dem.model_from_scene.build_dem_model`, :func:`rockyade.dem.engine.simulate_model`).

Energy loss in this DEM comes from the dashpots within a bounded range: without damping
the corner impacts already lose some energy (mu_eff < 1), and with very heavy damping the
impact becomes perfectly inelastic (about Housner's value). A target outside that range
cannot be matched by damping alone: :func:`match_beta` says so, with the range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq

from rockyade.blocks.classical import ClassicalParameters, classical_parameters
from rockyade.blocks.geometry import Block
from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.dem.engine import simulate_model
from rockyade.dem.joints import ContactParameters
from rockyade.dem.model_from_scene import build_dem_model
from rockyade.errors import CalibrationError, at_least, at_most
from rockyade.kernel import simulation as kernel
from rockyade.scene import Scene, scene_from_dict

#: Impacts after the release over which mu_eff is measured.
N_IMPACTS = MU_EFF_IMPACTS
#: Relative tolerance on mu_eff (the issue asks for 0.2 %).
MU_RTOL = 5e-4
#: Largest beta tried, as a multiple of 1 / w_contact (xi = BETA_MAX_XI at the contact mode).
BETA_MAX_XI = 4.0
#: Matched results kept (by block, classical parameters and joint), oldest dropped first.
CACHE_SIZE = 256


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
        The paper's empirical value (Eq 13), s, for comparison.
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
        """Keys for ``rockyade calibrate --method matched --json`` (s for the betas)."""
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


def free_rocking_duration(alpha_rad: float, p_rad_s: float, mu: float, theta0_rad: float, n_peaks: int) -> float:
    """Time to the ``n_peaks``-th peak of free rocking, from Housner's linearised equation, s.

    theta'' = p^2 (theta - alpha) about a pivot: from rest at theta_k the block reaches
    the impact after arccosh(alpha / (alpha - theta_k)) / p with speed
    p sqrt(alpha^2 - (alpha - theta_k)^2); the impact multiplies it by mu, and the next
    peak theta_{k+1} solves (alpha - theta_{k+1})^2 = alpha^2 - mu^2 (alpha^2 - (alpha - theta_k)^2).
    The nonlinear block is a little slower: callers add a margin.

    Parameters
    ----------
    alpha_rad, p_rad_s, mu
        Slenderness angle (rad), frequency parameter (1/s) and restitution.
    theta0_rad
        Release tilt from rest, rad (0 < theta0 < alpha).
    n_peaks
        Peaks counted after the release.
    """
    t, theta = 0.0, theta0_rad
    for k in range(n_peaks):
        quarter = math.acosh(alpha_rad / (alpha_rad - theta)) / p_rad_s
        t += quarter if k == 0 else 2.0 * quarter
        theta = alpha_rad - math.sqrt(alpha_rad**2 - mu**2 * (alpha_rad**2 - (alpha_rad - theta) ** 2))
    return t


def free_rocking_scene(
    block: Block, *, alpha_rad: float | None = None, p_rad_s: float | None = None, mu: float | None = None
) -> tuple[Scene, ClassicalParameters]:
    """The block alone on a rigid base, released from rest at alpha / 2, and its classical parameters.

    The run lasts 1.3 times Housner's time to the ``N_IMPACTS + 2``-th peak plus 0.3 s,
    sampled every 1 ms. Its joint is given to the model builder (the ``[contact]`` table
    keeps its defaults: Eq 7's time-step fraction, no mass damping).

    Parameters
    ----------
    block
        The block (geometry, mass, inertia).
    alpha_rad, p_rad_s, mu
        Classical overrides (rad, 1/s, -); None: the geometry's value.
    """
    cp = classical_parameters(block, alpha_rad=alpha_rad, p_rad_s=p_rad_s, mu=mu)
    theta0 = 0.5 * cp.alpha_rad
    t_peak = free_rocking_duration(cp.alpha_rad, cp.p_rad_s, cp.mu, theta0, N_IMPACTS + 2)
    block_table: dict[str, object] = {
        "name": "block",
        "vertices_m": block.vertices_m.tolist(),
        "thickness_m": block.thickness_m,
        "mass_kg": block.mass_kg,
    }
    if block.inertia_given:
        block_table["inertia_kgm2"] = block.inertia_c_kgm2
    for key, value in (("alpha_rad", alpha_rad), ("p_rad_s", p_rad_s), ("mu", mu)):
        if value is not None:
            block_table[key] = value
    scene = scene_from_dict(
        {
            "duration_s": round(1.3 * t_peak + 0.3, 3),
            "sample_dt_s": 0.001,
            "blocks": [block_table],
            "motion": {"type": "free", "theta0_rad": theta0},
        }
    )
    return scene, cp


def dem_effective_mu(
    block: Block,
    joint: ContactParameters,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
) -> float:
    """Effective restitution of the reference DEM for one block in free rocking on ``joint``.

    Parameters
    ----------
    block
        The block.
    joint
        The joint beneath it (stiffness N/m, damping ``beta_s`` in s, friction angle).
    alpha_rad, p_rad_s, mu
        Classical overrides (rad, 1/s, -), as in the block's scene.

    Returns
    -------
    float
        mu_eff over the first ``N_IMPACTS`` impacts; NaN when the block does not rock that
        many times or the run does not complete.
    """
    scene, cp = free_rocking_scene(block, alpha_rad=alpha_rad, p_rad_s=p_rad_s, mu=mu)
    model = build_dem_model(scene, [joint])
    out, _ = simulate_model(model, record_energy=False)
    ang, status, n_filled = out[1], int(out[6]), int(out[7])
    theta = ang[:n_filled, 0]
    t = np.arange(n_filled, dtype=float) * model.sample_dt_s
    peaks = find_peaks(t, theta, min_peak_rad=1e-3 * cp.alpha_rad)
    if len(peaks) < N_IMPACTS + 1 or status != kernel.STATUS_COMPLETED:
        return math.nan
    return effective_restitution(peaks, cp.alpha_rad, N_IMPACTS)


_MATCHED: dict[tuple[object, ...], MatchedBeta] = {}


def match_beta(
    block: Block,
    joint: ContactParameters,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
) -> MatchedBeta:
    """Damping beta (s) with which the reference DEM's effective mu equals the target mu.

    Parameters
    ----------
    block
        The block.
    joint
        Its calibrated joint (:func:`rockyade.calibration.calibrate.calibrate`): its stiffness
        (N/m) and friction are kept, its damping is varied; its ``beta_eq13_s`` (s) starts
        the search.
    alpha_rad, p_rad_s, mu
        Classical overrides (rad, 1/s, -); the target is this mu (the geometry's without it).

    Raises
    ------
    CalibrationError
        When the target is outside the range the dashpot can reach, with that range.

    Notes
    -----
    Results are kept by block, classical parameters and the joint's stiffness, friction
    and Eq 13 value, so a scene matches each distinct block once per process.
    """
    key = (
        tuple(map(tuple, block.vertices_m.round(12).tolist())),
        block.thickness_m,
        block.mass_kg,
        block.inertia_c_kgm2 if block.inertia_given else None,
        alpha_rad,
        p_rad_s,
        mu,
        joint.K_N_per_m,
        joint.Ks_N_per_m,
        joint.friction_angle_deg,
        joint.beta_eq13_s,
    )
    found = _MATCHED.get(key)
    if found is None:
        found = _match(block, joint, alpha_rad, p_rad_s, mu)
        if len(_MATCHED) >= CACHE_SIZE:
            _MATCHED.pop(next(iter(_MATCHED)))
        _MATCHED[key] = found
    return found


def _match(
    block: Block, joint: ContactParameters, alpha: float | None, p: float | None, mu: float | None
) -> MatchedBeta:
    """The search behind :func:`match_beta` (uncached)."""
    target = classical_parameters(block, alpha_rad=alpha, p_rad_s=p, mu=mu).mu
    runs = 0

    def mu_of(beta: float) -> float:
        nonlocal runs
        runs += 1
        return dem_effective_mu(block, replace(joint, beta_s=beta), alpha_rad=alpha, p_rad_s=p, mu=mu)

    mu_max = mu_of(0.0)
    omega_contact = math.sqrt(2.0 * joint.K_N_per_m / block.mass_kg)
    beta_max = 2.0 * BETA_MAX_XI / omega_contact
    if not math.isfinite(mu_max):
        raise CalibrationError("the undamped reference DEM does not rock freely for this block (no peaks)")
    if target > mu_max * (1 + MU_RTOL):
        mu_low = mu_of(beta_max)
        raise CalibrationError(
            f"target mu = {target:.6g} is above what the DEM reaches without damping ({at_most(mu_max, 6)}): "
            "the corner impacts alone lose more energy; reachable range "
            f"[{at_least(mu_low, 6)}, {at_most(mu_max, 6)}]. "
            "Damping cannot add energy: check mu or the stiffness"
        )
    # bracket: increase beta until mu_eff falls below the target
    lo, f_lo = 0.0, mu_max - target
    hi = max(joint.beta_eq13_s or 1e-5, 1e-6)
    f_hi = mu_of(hi) - target
    mu_min = f_hi + target
    while f_hi > 0 and hi < beta_max:
        lo, f_lo = hi, f_hi
        hi = min(4.0 * hi, beta_max)
        f_hi = mu_of(hi) - target
        mu_min = min(mu_min, f_hi + target)
    if f_hi > MU_RTOL * target:  # as at the top: a target within the tolerance is reached
        raise CalibrationError(
            f"target mu = {target:.6g} is below what the DEM reaches with the heaviest damping tried "
            f"(beta = {beta_max:.3g} s, mu_eff = {at_least(mu_min, 6)}); reachable range "
            f"[{at_least(mu_min, 6)}, {at_most(mu_max, 6)}]. "
            "Damping alone cannot dissipate that much at the corner impacts"
        )
    if abs(f_lo) <= MU_RTOL * target:
        beta = lo
    elif f_hi >= 0.0:
        beta = hi
    else:
        beta = brentq(lambda b: mu_of(b) - target, lo, hi, xtol=1e-9, rtol=1e-4, maxiter=60)
    achieved = mu_of(beta)
    if hi < beta_max:  # report the whole reachable range, down to the heaviest damping
        mu_min = min(mu_min, mu_of(beta_max))
    if abs(achieved - target) > 2e-3 * target:
        raise CalibrationError(f"matching did not converge: mu_eff = {achieved:.5f} for target {target:.5f}")
    return MatchedBeta(
        beta_s=float(beta),
        mu_eff=achieved,
        mu_target=target,
        mu_max=mu_max,
        mu_min=mu_min,
        beta_max_s=beta_max,
        beta_eq13_s=joint.beta_eq13_s or math.nan,
        n_runs=runs,
        n_impacts=N_IMPACTS,
    )
