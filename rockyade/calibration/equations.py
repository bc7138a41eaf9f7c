"""DEM contact parameters derived from the classical parameters (paper Sections 4-6).

One function per equation of the paper, each citing its number:

* Eq 6  Rayleigh constants a = xi w, b = xi / w from (xi_min, f_min);
* Eq 7  time step dt = frac 2 sqrt(M_min / K_max): :func:`rockyade.dem.model.time_step_eq7`,
  where the model chooses its time step;
* Eq 8  K1 = M p^2;   Eq 9  K2 = M 3g/(4R) (M p_theory^2 for any polygon);
* Eq 10 K = (K1 + K2) / 2;
* Eq 11 b_eq = h tan(alpha);
* Eq 12 Gamma = K R = M/2 (R p^2 + 3/4 g);
* Eq 13 sqrt(b) = 0.0057 ln(Gamma / mu^2) - 0.0336 (empirical);
* Eq 14 f_min = p;   Eq 15 xi_min = 2 pi b f_min.

Stiffness scale. Eq 10's K is dimensionally N/m, but read as N/m it lets the block sink
M g / K ~ 0.7 m into its base (specimen 1). rockyade multiplies the paper's K by an explicit
``stiffness_scale`` (default 1e6, i.e. the printed numbers read as MN/m), records the choice
in every output, and refuses a static settlement M g / K above 1e-4 of the block height.
Eqs 12-13 are evaluated with the paper's own (unscaled) K, as the paper fitted them; Eq 7
uses the scaled K actually simulated.

:func:`paper_calibration` puts them together into the joint the model runs
(:class:`rockyade.dem.joints.ContactParameters`); :mod:`rockyade.calibration.calibrate`
applies a scene's explicit values and the other methods.
"""

from __future__ import annotations

import math

from rockyade.blocks.classical import classical_parameters
from rockyade.blocks.geometry import Block
from rockyade.constants import (
    DEFAULT_FRICTION_ANGLE_DEG,
    DEFAULT_STIFFNESS_SCALE,
    DEFAULT_TIME_STEP_FRAC,
    MAX_SETTLEMENT_FRACTION,
    STIFFNESS_SCALES,
    G,
)
from rockyade.dem.joints import ContactParameters
from rockyade.dem.model import time_step_eq7
from rockyade.errors import CalibrationError, InputError, at_least, at_most

#: Range of Gamma / mu^2 covered by the paper's four specimens (Fig. 11), for a warning.
EQ13_FITTED_RANGE = (7.0e2, 5.0e3)

# ------------------------------------------------------------------ the equations


def rayleigh_constants_eq6(xi_min: float, f_min_hz: float) -> tuple[float, float]:
    """Rayleigh constants (a, b) from damping ratio and frequency (paper Eq 6).

    Parameters
    ----------
    xi_min
        Damping ratio at ``f_min_hz`` (-).
    f_min_hz
        Frequency of the minimum damping ratio, Hz.

    Returns
    -------
    a
        Mass-proportional constant, 1/s.
    b
        Stiffness-proportional constant, s.
    """
    omega = 2.0 * math.pi * f_min_hz
    return xi_min * omega, xi_min / omega


def stiffness_eq8(mass_kg: float, p_rad_s: float) -> float:
    """K1 = M p^2, in the paper's units (paper Eq 8).

    Parameters
    ----------
    mass_kg
        Block mass, kg.
    p_rad_s
        Frequency parameter p, 1/s.
    """
    return mass_kg * p_rad_s**2


def stiffness_eq9(mass_kg: float, R_m: float, g: float = G) -> float:
    """K2 = M 3 g / (4 R), in the paper's units (paper Eq 9; rectangles).

    Parameters
    ----------
    mass_kg
        Block mass, kg.
    R_m
        Distance from the pivot to the centroid, m.
    g
        Gravity, m/s^2.
    """
    return mass_kg * 3.0 * g / (4.0 * R_m)


def stiffness_eq10(k1: float, k2: float) -> float:
    """K = (K1 + K2) / 2, in the paper's units (paper Eq 10).

    Parameters
    ----------
    k1, k2
        Eq 8 and Eq 9 values, in the paper's units (read as N/m before the stiffness scale).
    """
    return 0.5 * (k1 + k2)


def equivalent_half_base_eq11(h_m: float, alpha_rad: float) -> float:
    """Equivalent half base b_eq = h tan(alpha), m (paper Eq 11).

    Parameters
    ----------
    h_m
        Height of the centroid above the base, m (half the height of a rectangle).
    alpha_rad
        Slenderness angle, rad.
    """
    return h_m * math.tan(alpha_rad)


def generalized_damping_factor_eq12(k_paper: float, R_m: float) -> float:
    """Generalised damping factor Gamma = K R (paper Eq 12), with the paper's unscaled K;
    for rectangles this equals M/2 (R p^2 + 3/4 g).

    Parameters
    ----------
    k_paper
        Eq 10's K in the paper's units (before the stiffness scale).
    R_m
        Distance from the pivot to the centroid, m.
    """
    return k_paper * R_m


def stiffness_damping_eq13(gamma: float, mu: float) -> float:
    """Stiffness-proportional damping constant b, s (paper Eq 13, empirical).

    sqrt(b) = 0.0057 ln(Gamma / mu^2) - 0.0336.

    Parameters
    ----------
    gamma
        Eq 12's Gamma (paper units).
    mu
        Coefficient of restitution (-).

    Raises
    ------
    CalibrationError
        When the right-hand side is negative (Gamma / mu^2 < exp(0.0336 / 0.0057) ~ 363),
        far outside the paper's data.
    """
    root = 0.0057 * math.log(gamma / mu**2) - 0.0336
    if root < 0.0:
        raise CalibrationError(
            f"Eq 13 gives sqrt(b) = {root:.4g} < 0 for Gamma/mu^2 = {gamma / mu**2:.4g} "
            f"(needs > {math.exp(0.0336 / 0.0057):.0f}; the paper's data span "
            f"{EQ13_FITTED_RANGE[0]:.0f}-{EQ13_FITTED_RANGE[1]:.0f}): "
            "use calibration = 'matched' or give contact.beta_s"
        )
    return root * root


def f_min_eq14(p_rad_s: float) -> float:
    """f_min = p, Hz (paper Eq 14): the paper sets the number in Hz equal to p in 1/s.

    Parameters
    ----------
    p_rad_s
        Frequency parameter p, 1/s.
    """
    return p_rad_s


def xi_min_eq15(b_s: float, f_min_hz: float) -> float:
    """Damping ratio xi_min = 2 pi b f_min (paper Eq 15).

    Parameters
    ----------
    b_s
        Stiffness-proportional damping constant b, s.
    f_min_hz
        Eq 14's frequency, Hz.
    """
    return 2.0 * math.pi * b_s * f_min_hz


# ------------------------------------------------------------------ stiffness scale


def stiffness_scale_factor(scale: float | str | None) -> tuple[float, str]:
    """Factor converting the paper's K to N/m, and its readable name.

    Parameters
    ----------
    scale
        ``"N/m"``, ``"kN/m"``, ``"MN/m"``, a positive number, or None (the default, MN/m).

    Returns
    -------
    factor, name
        The factor (N/m per paper unit) and its name, e.g. ``(1e6, "MN/m")``.

    Raises
    ------
    InputError
        Another name, or a number that is not finite and positive.
    """
    if scale is None:
        return DEFAULT_STIFFNESS_SCALE, "MN/m"
    if isinstance(scale, str):
        if scale not in STIFFNESS_SCALES:
            raise InputError(
                "contact.stiffness_scale",
                f"must be one of {sorted(STIFFNESS_SCALES)} or a number > 0, got {scale!r}",
            )
        return STIFFNESS_SCALES[scale], scale
    if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) or scale <= 0:
        raise InputError("contact.stiffness_scale", f"must be a number > 0, got {scale!r}")
    names = {v: k for k, v in STIFFNESS_SCALES.items()}
    return float(scale), names.get(float(scale), f"x{float(scale):g} N/m")


def check_settlement(
    supported_mass_kg: float, k_N_per_m: float, height_m: float, field_name: str, g: float = G
) -> float:
    """Static settlement M g / K, m.

    Parameters
    ----------
    supported_mass_kg
        Mass resting on the joint, kg.
    k_N_per_m
        Joint stiffness (scaled), N/m.
    height_m
        Block height, m.
    field_name
        Field the error names (e.g. ``contact.stiffness_scale``).
    g
        Gravity, m/s^2.

    Raises
    ------
    InputError
        When the settlement is above ``MAX_SETTLEMENT_FRACTION`` (1e-4) of the block height.
    """
    settlement = supported_mass_kg * g / k_N_per_m
    limit = MAX_SETTLEMENT_FRACTION * height_m
    if settlement > limit:
        raise InputError(
            field_name,
            f"K = {k_N_per_m:.4g} N/m gives a static settlement M g / K = {at_least(settlement)} m, "
            f"above {MAX_SETTLEMENT_FRACTION:g} of the block height ({at_most(limit)} m): the block "
            "sinks into its base. Raise the stiffness (the paper's K reads as MN/m: "
            "stiffness_scale = 'MN/m') or check the units",
        )
    return settlement


# ------------------------------------------------------------------ calibration


def paper_calibration(
    block: Block,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
    stiffness_scale: float | str | None = None,
    friction_angle_deg: float = DEFAULT_FRICTION_ANGLE_DEG,
    supported_mass_kg: float | None = None,
    frac: float = DEFAULT_TIME_STEP_FRAC,
    g: float = G,
    field_prefix: str = "contact.",
    beta_s: float | None = None,
) -> ContactParameters:
    """DEM contact parameters of the paper (Eqs 10-15) for the joint beneath ``block``.

    Parameters
    ----------
    block
        The block (mass in kg, geometry in m).
    alpha_rad, p_rad_s, mu
        Classical parameters to calibrate with (rad, 1/s, -; e.g. the experimental ones);
        default: those of the geometry.
    stiffness_scale
        Reading of the paper's K (default "MN/m"), see module docstring.
    friction_angle_deg
        Joint friction angle, degrees (paper: 30).
    supported_mass_kg
        Mass resting on the joint (block plus blocks above) for the settlement check, kg;
        default the block's mass.
    frac
        Eq 7 fraction of the critical time step (-).
    g
        Gravity, m/s^2.
    field_prefix
        Prefix of the field a settlement error names (``contact.``).
    beta_s
        An explicit damping constant, s: used instead of Eq 13, which is then only
        reported (and may be out of its range without failing).

    Raises
    ------
    InputError
        A bad stiffness scale, or a settlement above 1e-4 of the block height.
    CalibrationError
        Eq 13 without a value (``beta_s`` not given).
    """
    geometric = classical_parameters(block, g=g)
    used = classical_parameters(block, alpha_rad=alpha_rad, p_rad_s=p_rad_s, mu=mu, g=g)
    factor, reading = stiffness_scale_factor(stiffness_scale)
    R = geometric.R_m
    k1 = stiffness_eq8(block.mass_kg, used.p_rad_s)
    k2 = stiffness_eq8(block.mass_kg, geometric.p_rad_s)  # Eq 9 for any polygon: M p_theory^2
    k_paper = stiffness_eq10(k1, k2)
    gamma = generalized_damping_factor_eq12(k_paper, R)
    notes: list[str] = []
    lo, hi = EQ13_FITTED_RANGE
    ratio = gamma / used.mu**2
    if not lo <= ratio <= hi:
        notes.append(f"Gamma/mu^2 = {ratio:.0f} outside the paper's data ({lo:.0f}-{hi:.0f}): Eq 13 is extrapolated")
    if beta_s is None:
        beta = beta_eq13 = stiffness_damping_eq13(gamma, used.mu)
    else:
        beta = float(beta_s)
        try:
            beta_eq13: float | None = stiffness_damping_eq13(gamma, used.mu)
        except CalibrationError:
            beta_eq13 = None
            notes.append("Eq 13 has no value here (sqrt(b) < 0); beta_s explicit")
    f_min = f_min_eq14(used.p_rad_s)
    k = k_paper * factor
    settlement = check_settlement(
        supported_mass_kg or block.mass_kg, k, block.height_m, f"{field_prefix}stiffness_scale", g
    )
    return ContactParameters(
        K_N_per_m=k,
        Ks_N_per_m=k,
        friction_angle_deg=float(friction_angle_deg),
        cohesion_Pa=0.0,
        beta_s=beta,
        rayleigh_a_1_s=0.0,
        xi_min=xi_min_eq15(beta, f_min),
        f_min_hz=f_min,
        b_eq_m=equivalent_half_base_eq11(used.centroid_height_m, used.alpha_rad),
        K_paper=k_paper,
        stiffness_scale=factor,
        stiffness_reading=reading,
        gamma=gamma,
        beta_eq13_s=beta_eq13,
        method="paper" if beta_s is None else "explicit",
        dt_eq7_s=time_step_eq7(block.mass_kg, k, frac),
        settlement_m=settlement,
        notes=tuple(notes),
    )
