"""Matched calibration: the contact damping that makes the DEM lose the target energy.

The paper derives the stiffness-proportional damping b from an empirical fit (Eq 13).
rockyade can instead *match* it: find beta such that the reference DEM's effective
restitution (DESIGN.md: mu_eff = sqrt(V(theta_n+1) / V(theta_n)) from successive peaks)
equals the target mu. Each evaluation is a short free-rocking run of the block alone on a
rigid base, released at alpha / 2, measured over its first ``N_IMPACTS`` impacts after the
release; beta is found by Brent's method (scipy) to within ``MU_RTOL`` of the target.

Energy loss in this DEM comes from the dashpots within a bounded range: without damping
the corner impacts already lose some energy (mu_eff < 1), and with very heavy damping the
impact becomes perfectly inelastic (about Housner's value). A target outside that range
cannot be matched by damping alone: :func:`match_beta` says so, with the range.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.optimize import brentq

from rockyade.blocks.classical import classical_parameters
from rockyade.blocks.geometry import Block
from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.constants import DEFAULT_FRICTION_ANGLE_DEG, G
from rockyade.dem.build import build_dem_model
from rockyade.dem.engine import simulate_model
from rockyade.dem.joints import MatchedBeta
from rockyade.dem.model import DemModel
from rockyade.errors import CalibrationError
from rockyade.kernel import simulation as kernel
from rockyade.scene import Scene, scene_from_dict

#: Impacts after the release over which mu_eff is measured.
N_IMPACTS = MU_EFF_IMPACTS
#: Relative tolerance on mu_eff (the issue asks for 0.2 %).
MU_RTOL = 5e-4
#: Largest beta tried, as a multiple of 1 / w_contact (xi = BETA_MAX_XI at the contact mode).
BETA_MAX_XI = 4.0


def free_rocking_duration(alpha_rad: float, p_rad_s: float, mu: float, theta0_rad: float, n_peaks: int) -> float:
    """Time to the ``n_peaks``-th peak of free rocking, from Housner's linearised equation, s.

    theta'' = p^2 (theta - alpha) about a pivot: from rest at theta_k the block reaches
    the impact after arccosh(alpha / (alpha - theta_k)) / p with speed
    p sqrt(alpha^2 - (alpha - theta_k)^2); the impact multiplies it by mu, and the next
    peak theta_{k+1} solves (alpha - theta_{k+1})^2 = alpha^2 - mu^2 (alpha^2 - (alpha - theta_k)^2).
    The nonlinear block is a little slower: callers add a margin.
    """
    t, theta = 0.0, theta0_rad
    for k in range(n_peaks):
        quarter = math.acosh(alpha_rad / (alpha_rad - theta)) / p_rad_s
        t += quarter if k == 0 else 2.0 * quarter
        theta = alpha_rad - math.sqrt(alpha_rad**2 - mu**2 * (alpha_rad**2 - (alpha_rad - theta) ** 2))
    return t


def _free_rocking_scene(block: Block, alpha, p, mu, beta, stiffness_scale, friction_angle_deg, K):
    """The block alone on a rigid base, released at alpha / 2 with damping ``beta``."""
    cp = classical_parameters(block, alpha_rad=alpha, p_rad_s=p, mu=mu)
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
    for key, value in (("alpha_rad", alpha), ("p_rad_s", p), ("mu", mu)):
        if value is not None:
            block_table[key] = value
    contact: dict[str, object] = {
        "calibration": "paper",
        "beta_s": beta,
        "stiffness_scale": stiffness_scale if stiffness_scale is not None else "MN/m",
        "friction_angle_deg": friction_angle_deg,
    }
    if K is not None:
        contact["K_N_per_m"] = K
    scene = scene_from_dict(
        {
            "duration_s": round(1.3 * t_peak + 0.3, 3),
            "sample_dt_s": 0.001,
            "blocks": [block_table],
            "contact": contact,
            "motion": {"type": "free", "theta0_rad": theta0},
        }
    )
    return scene, cp


def dem_effective_mu(
    block: Block,
    beta_s: float,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
    stiffness_scale: float | str | None = None,
    friction_angle_deg: float = DEFAULT_FRICTION_ANGLE_DEG,
    K_N_per_m: float | None = None,
) -> float:
    """Effective restitution of the DEM (the reference kernel) for one block with damping ``beta_s``."""
    scene, cp = _free_rocking_scene(
        block, alpha_rad, p_rad_s, mu, beta_s, stiffness_scale, friction_angle_deg, K_N_per_m
    )
    model = build_dem_model(scene)
    out, _ = simulate_model(model, record_energy=False)
    ang, status, n_filled = out[1], int(out[6]), int(out[7])
    theta = ang[:n_filled, 0]
    t = np.arange(n_filled) * model.sample_dt_s
    peaks = find_peaks(t, theta, min_peak_rad=1e-3 * cp.alpha_rad)
    if len(peaks) < N_IMPACTS + 1 or status != kernel.STATUS_COMPLETED:
        return math.nan
    return effective_restitution(peaks, cp.alpha_rad, N_IMPACTS)


def matched_betas(scene: Scene) -> dict[str, MatchedBeta]:
    """Matched damping of every block of a ``calibration = "matched"`` scene, by block name.

    Blocks with an explicit ``contact.beta_s`` need none (an empty dictionary is returned).
    """
    c = scene.contact
    if c.calibration != "matched" or c.beta_s is not None:
        return {}
    out = {}
    for spec in scene.blocks:
        out[spec.name] = match_beta(
            spec.block(),
            alpha_rad=spec.alpha_rad,
            p_rad_s=spec.p_rad_s,
            mu=spec.mu,
            stiffness_scale=c.stiffness_scale,
            friction_angle_deg=c.friction_angle_deg,
            K_N_per_m=c.K_N_per_m,
        )
    return out


def build_matched_model(scene: Scene, g: float = G) -> DemModel:
    """The scene's DEM model, with the damping matched first when the scene asks for it.

    This is the stage the solvers call: matching runs short DEM models of each block
    alone, then the scene's model is built with the matched values (never the other way).
    """
    return build_dem_model(scene, g=g, matched=matched_betas(scene))


def match_beta(
    block: Block,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
    stiffness_scale: float | str | None = None,
    friction_angle_deg: float = DEFAULT_FRICTION_ANGLE_DEG,
    K_N_per_m: float | None = None,
) -> MatchedBeta:
    """Damping beta (s) that makes the reference DEM's effective mu equal the target mu.

    Raises
    ------
    CalibrationError
        When the target is outside the range the dashpot can reach, with that range.
    """
    key = (
        tuple(map(tuple, block.vertices_m.round(12).tolist())),
        block.thickness_m,
        block.mass_kg,
        block.inertia_c_kgm2 if block.inertia_given else None,
        alpha_rad,
        p_rad_s,
        mu,
        stiffness_scale,
        friction_angle_deg,
        K_N_per_m,
    )
    return _match_cached(key)


@functools.lru_cache(maxsize=256)
def _match_cached(key: tuple) -> MatchedBeta:
    verts, thickness, mass, inertia, alpha, p, mu, scale, friction, K = key
    block = Block.polygon(verts, thickness, mass_kg=mass, inertia_kgm2=inertia)
    from rockyade.calibration.equations import paper_calibration

    paper = paper_calibration(
        block, alpha_rad=alpha, p_rad_s=p, mu=mu, stiffness_scale=scale, friction_angle_deg=friction
    )
    target = classical_parameters(block, alpha_rad=alpha, p_rad_s=p, mu=mu).mu
    k = K if K is not None else paper.K_N_per_m
    runs = 0

    def mu_of(beta: float) -> float:
        nonlocal runs
        runs += 1
        return dem_effective_mu(
            block,
            beta,
            alpha_rad=alpha,
            p_rad_s=p,
            mu=mu,
            stiffness_scale=scale,
            friction_angle_deg=friction,
            K_N_per_m=K,
        )

    mu_max = mu_of(0.0)
    omega_contact = math.sqrt(2.0 * k / block.mass_kg)
    beta_max = 2.0 * BETA_MAX_XI / omega_contact
    if not math.isfinite(mu_max):
        raise CalibrationError("the undamped reference DEM does not rock freely for this block (no peaks)")
    if target > mu_max * (1 + MU_RTOL):
        mu_low = mu_of(beta_max)
        raise CalibrationError(
            f"target mu = {target:.6g} is above what the DEM reaches without damping ({mu_max:.6g}): "
            f"the corner impacts alone lose more energy; reachable range [{mu_low:.6g}, {mu_max:.6g}]. "
            "Damping cannot add energy: check mu or the stiffness"
        )
    # bracket: increase beta until mu_eff falls below the target
    lo, f_lo = 0.0, mu_max - target
    hi = max(paper.beta_eq13_s or 1e-5, 1e-6)
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
            f"(beta = {beta_max:.3g} s, mu_eff = {mu_min:.6g}); reachable range [{mu_min:.6g}, {mu_max:.6g}]. "
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
        beta_eq13_s=paper.beta_eq13_s or math.nan,
        n_runs=runs,
        n_impacts=N_IMPACTS,
    )
