"""Classical (Housner) rocking parameters of a rigid block: alpha, p, mu (paper Section 2).

For a rectangle of base 2b and height 2h the paper gives alpha = atan(b/h) (Eq 2),
p = sqrt(3 g / (4 R)) (Eq 3) and mu = 1 - 3/2 sin^2(alpha) (Eq 4). This module computes the
general forms that reduce to those for rectangles:

* alpha of a pivot: angle between the vertical and the line pivot -> centroid (Eq 2
  generalised);
* p of a pivot: p^2 = M g R / I_O with I_O the inertia about that pivot (Eq 3 generalised);
* mu of an impact that moves the pivot from A to B: conservation of angular momentum about
  B (the derivation behind Eq 4):  mu = (I_c + M (r_G - r_B).(r_G - r_A)) / I_B.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

from rockyade.blocks.geometry import Block
from rockyade.constants import G
from rockyade.errors import InputError

# --------------------------------------------------------------------------- Eqs 2-4


def alpha_rectangle(b: float, h: float) -> float:
    """Critical angle of a rectangle, alpha = atan(b / h), rad (paper Eq 2).

    Parameters
    ----------
    b, h
        Half width and half height, m.
    """
    return math.atan2(b, h)


def p_rectangle(R: float, g: float = G) -> float:
    """Frequency parameter of a rectangle, p = sqrt(3 g / (4 R)), rad/s (paper Eq 3).

    Parameters
    ----------
    R
        Distance from a base corner to the centroid, sqrt(b^2 + h^2), m.
    """
    return math.sqrt(3.0 * g / (4.0 * R))


def mu_rectangle(alpha: float) -> float:
    """Coefficient of restitution of a rectangle, mu = 1 - 3/2 sin^2(alpha) (paper Eq 4)."""
    return 1.0 - 1.5 * math.sin(alpha) ** 2


def uplift_acceleration(alpha: float, g: float = G) -> float:
    """Base acceleration that starts rocking from rest, g tan(alpha), m/s^2."""
    return g * math.tan(alpha)


def frequency_parameter(mass: float, R: float, inertia_pivot: float, g: float = G) -> float:
    """p = sqrt(M g R / I_O), rad/s (Eq 3 generalised to any inertia)."""
    return math.sqrt(mass * g * R / inertia_pivot)


def inertia_for_frequency(mass: float, R: float, p: float, g: float = G) -> float:
    """Inertia about the pivot that gives frequency parameter ``p``: I_O = M g R / p^2."""
    return mass * g * R / (p * p)


# ------------------------------------------------------------------ general forms

#: The side a block turns to when it rocks about each pivot: about its left base corner
#: (theta > 0, counter-clockwise) its top moves towards -x; about its right one, towards +x.
TURNS_TO = {"left": "-x", "right": "+x"}


@dataclass(frozen=True)
class Pivot:
    """Rocking about one base corner: the classical parameters of one direction.

    Attributes
    ----------
    x_m
        Pivot abscissa in the block frame, m.
    R_m
        Distance pivot -> centroid, m.
    alpha_rad
        Angle between the vertical and the line pivot -> centroid, rad.
    I_O_kgm2
        Inertia about the pivot, kg m^2.
    p_rad_s
        Frequency parameter sqrt(M g R / I_O), rad/s.
    turns_to
        The side the block turns to about this pivot: "-x" (left pivot, theta > 0) or "+x"
        (right pivot, theta < 0).
    mu
        Restitution of the impact that ends a half-cycle on this pivot (the pivot moves to the
        other corner): angular momentum about the new pivot (:func:`body_restitution`).
    uplift_accel_m_s2
        The base acceleration, away from ``turns_to``, that lifts the block at rest about this
        pivot, m/s^2: lambda g, lambda = tan(alpha) for the body alone, and with loads that
        carry no mass (their moment about the pivot) the limit analysis' multiplier of the
        block (:func:`rigid_body_classical`).
    """

    x_m: float
    R_m: float
    alpha_rad: float
    I_O_kgm2: float
    p_rad_s: float
    turns_to: str = ""
    mu: float = math.nan
    uplift_accel_m_s2: float = math.nan


def pivot_about(block: Block, pivot_m: np.ndarray, g: float = G) -> Pivot:
    """Classical parameters of rocking about ``pivot_m`` (a base corner, block frame); ``mu`` and
    ``turns_to`` are left to :func:`rigid_body_classical`, which knows the other pivot."""
    return _pivot(block.mass_kg, block.centroid_m, block.inertia_c_kgm2, pivot_m, g)


def _pivot(mass_kg: float, centroid_m, inertia_c_kgm2: float, pivot_m, g: float) -> Pivot:
    dx = float(centroid_m[0]) - float(pivot_m[0])
    dy = float(centroid_m[1]) - float(pivot_m[1])
    R = math.hypot(dx, dy)
    I_O = inertia_c_kgm2 + mass_kg * R * R
    return Pivot(float(pivot_m[0]), R, math.atan2(abs(dx), dy), I_O, frequency_parameter(mass_kg, R, I_O, g))


def body_restitution(mass_kg: float, centroid_m, inertia_c_kgm2: float, from_pivot_m, to_pivot_m) -> float:
    """Angular-velocity ratio after/before an impact that moves the pivot of a rigid body from
    A to B (Housner 1963, Eq 4 generalised to any centroid; the paper's derivation).

    Angular momentum about the new pivot B is conserved through the impact (the impulse acts at
    B): I_c w- + M (r_G - r_B) x v_G = I_B w+, with v_G = w- z x (r_G - r_A), so

        mu = w+/w- = (I_c + M (r_G - r_B).(r_G - r_A)) / (I_c + M |r_G - r_B|^2).

    For a rectangle with its centroid on its axis, 1 - 1.5 sin^2(alpha) (Eq 4). For an asymmetric
    body (a block with a load off its axis) the two impacts differ: from the side of the smaller
    alpha to the larger and back.

    Parameters
    ----------
    mass_kg, centroid_m, inertia_c_kgm2
        The body's mass (kg), centroid (m) and inertia about its centroid (kg m^2).
    from_pivot_m, to_pivot_m
        The pivot before and after the impact, same frame, m.
    """
    gx, gy = float(centroid_m[0]), float(centroid_m[1])
    ra = (gx - float(from_pivot_m[0]), gy - float(from_pivot_m[1]))
    rb = (gx - float(to_pivot_m[0]), gy - float(to_pivot_m[1]))
    i_b = inertia_c_kgm2 + mass_kg * (rb[0] * rb[0] + rb[1] * rb[1])
    return (inertia_c_kgm2 + mass_kg * (rb[0] * ra[0] + rb[1] * ra[1])) / i_b


def restitution(block: Block, from_pivot_m: np.ndarray, to_pivot_m: np.ndarray) -> float:
    """Angular-velocity ratio after/before an impact that moves the pivot (general Eq 4,
    :func:`body_restitution` of the block)."""
    return body_restitution(block.mass_kg, block.centroid_m, block.inertia_c_kgm2, from_pivot_m, to_pivot_m)


@dataclass(frozen=True)
class ClassicalParameters:
    """Classical rocking parameters of one block (or of a block with the masses it carries).

    Each direction has its own parameters, in ``left`` (rocking about the left base corner,
    theta > 0, turning towards -x) and ``right`` (towards +x): alpha, R, p, the restitution of the
    impact that ends it and the uplift acceleration. The headline values (``alpha_rad``,
    ``p_rad_s``, ``mu``, ``R_m``, ``I_O_kgm2``) are those of the left pivot for a symmetric
    block. For an asymmetric block the headline is the pivot with the smaller alpha (it governs
    uplift), ``mu`` is the mean over one full cycle, sqrt(mu_left_to_right * mu_right_to_left),
    and ``uplift_accel_m_s2`` the smaller of the two directions'.

    ``source`` records for each of alpha, p, mu whether it came from the geometry or from
    an explicit override (the paper's experimental values, for example). ``carried_kg`` is the
    mass of the loads the body carries (0: the block alone).
    """

    mass_kg: float
    alpha_rad: float
    p_rad_s: float
    mu: float
    R_m: float
    I_O_kgm2: float
    I_c_kgm2: float
    centroid_height_m: float
    uplift_accel_m_s2: float
    left: Pivot
    right: Pivot
    mu_left_to_right: float
    mu_right_to_left: float
    symmetric: bool
    source: dict[str, str]
    carried_kg: float = 0.0

    def as_dict(self) -> dict[str, object]:
        """Plain dictionary, JSON-ready."""
        return asdict(self)

    def pivot(self, turns_to: str) -> Pivot:
        """The direction turning towards ``turns_to`` ("+x": the right pivot; "-x": the left one)."""
        if turns_to not in ("+x", "-x"):
            raise ValueError(f"turns_to must be +x or -x, got {turns_to!r}")
        return self.right if turns_to == "+x" else self.left

    def theta_over_alpha(self, theta_rad) -> float:
        """The largest rotation over the alpha of the side the block turns to: theta / alpha_left
        where theta > 0 (about the left pivot), -theta / alpha_right where theta < 0 (NaN samples
        ignored; NaN without a finite sample). 1 is the static overturning angle of that side."""
        theta = np.asarray(theta_rad, dtype=float)
        theta = theta[np.isfinite(theta)]
        if not theta.size:
            return math.nan
        return float(max(theta.max(initial=0.0) / self.left.alpha_rad, -theta.min(initial=0.0) / self.right.alpha_rad))


def rigid_body_classical(
    mass_kg: float,
    centroid_m,
    inertia_c_kgm2: float,
    pivots_m,
    g: float = G,
    *,
    load_moments_Nm: tuple[float, float] = (0.0, 0.0),
    carried_kg: float = 0.0,
) -> ClassicalParameters:
    """The classical parameters of a rigid body rocking on two base corners, each direction its own.

    * alpha, R, I_O and p of each pivot (Eqs 2-3 generalised: alpha between the vertical and the
      line pivot -> centroid, p^2 = M g R / I_O);
    * mu of each impact, from the angular momentum about the new pivot (:func:`body_restitution`);
    * the uplift acceleration of each direction, lambda g, from the moments about the pivot at
      rest: turning towards +x about the right pivot P_R,
      lambda = (W (x_R - x_c) + M_R) / (W y_c), and towards -x about P_L,
      lambda = (W (x_c - x_L) - M_L) / (W y_c), W = M g, y_c the centroid's height above the pivots
      and M_L, M_R the counter-clockwise moments about the pivots of the loads that carry no mass
      (0: lambda = tan(alpha)). It is the limit analysis' multiplier of the block, (W b + N d) /
      (W h_c) for a massless vertical load N at lever d (docs/limit.md).

    Parameters
    ----------
    mass_kg, centroid_m, inertia_c_kgm2
        The body: mass (kg), centroid (x, y) and inertia about it (kg m^2), in the block frame (the
        base at y = 0); with loads that carry mass, the loaded body
        (:func:`rockyade.scene.carried.loaded_mass_properties`).
    pivots_m
        (left, right) base corners, same frame, m.
    g
        Gravity, m/s^2.
    load_moments_Nm
        (M_L, M_R): counter-clockwise moments of the forces without mass about the left and right
        pivots, N m.
    carried_kg
        The part of ``mass_kg`` that loads carry, kg (reported).
    """
    left_xy, right_xy = pivots_m
    left = _pivot(mass_kg, centroid_m, inertia_c_kgm2, left_xy, g)
    right = _pivot(mass_kg, centroid_m, inertia_c_kgm2, right_xy, g)
    mu_lr = body_restitution(mass_kg, centroid_m, inertia_c_kgm2, left_xy, right_xy)
    mu_rl = body_restitution(mass_kg, centroid_m, inertia_c_kgm2, right_xy, left_xy)
    weight = mass_kg * g
    cx, cy = float(centroid_m[0]), float(centroid_m[1])
    lam_left = (weight * (cx - float(left_xy[0])) - load_moments_Nm[0]) / (weight * (cy - float(left_xy[1])))
    lam_right = (weight * (float(right_xy[0]) - cx) + load_moments_Nm[1]) / (weight * (cy - float(right_xy[1])))
    left = replace(left, turns_to=TURNS_TO["left"], mu=mu_lr, uplift_accel_m_s2=lam_left * g)
    right = replace(right, turns_to=TURNS_TO["right"], mu=mu_rl, uplift_accel_m_s2=lam_right * g)
    tol = 1e-9
    symmetric = (
        abs(left.alpha_rad - right.alpha_rad) <= tol * max(left.alpha_rad, 1.0)
        and abs(left.p_rad_s - right.p_rad_s) <= tol * max(left.p_rad_s, 1.0)
        and abs(mu_lr - mu_rl) <= tol
        and abs(lam_left - lam_right) <= tol * max(abs(lam_left), 1.0)
    )
    governing = left if left.alpha_rad <= right.alpha_rad else right
    return ClassicalParameters(
        mass_kg=mass_kg,
        alpha_rad=governing.alpha_rad,
        p_rad_s=governing.p_rad_s,
        mu=mu_lr if symmetric else math.sqrt(mu_lr * mu_rl),
        R_m=governing.R_m,
        I_O_kgm2=governing.I_O_kgm2,
        I_c_kgm2=inertia_c_kgm2,
        centroid_height_m=cy,
        symmetric=symmetric,
        source={"alpha_rad": "geometry", "p_rad_s": "geometry", "mu": "geometry"},
        carried_kg=carried_kg,
        **_sides(left, right),
    )


def _sides(left: Pivot, right: Pivot) -> dict[str, Any]:
    """The fields of :class:`ClassicalParameters` that follow from its two directions."""
    return {
        "left": left,
        "right": right,
        "mu_left_to_right": left.mu,
        "mu_right_to_left": right.mu,
        "uplift_accel_m_s2": min(left.uplift_accel_m_s2, right.uplift_accel_m_s2),
    }


def with_overrides(
    cp: ClassicalParameters,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
    g: float = G,
) -> ClassicalParameters:
    """``cp`` with explicit values (e.g. the paper's experimental ones, Tables 3-4). An override
    makes the block symmetric in that parameter (both pivots take the value; an alpha's uplift
    acceleration is g tan(alpha))."""
    check_classical_overrides(alpha_rad, p_rad_s, mu)
    left, right, source = cp.left, cp.right, dict(cp.source)
    a, p, m = cp.alpha_rad, cp.p_rad_s, cp.mu
    if alpha_rad is not None:
        a, source["alpha_rad"] = float(alpha_rad), "override"
        up = uplift_acceleration(a, g)
        left, right = (replace(pv, alpha_rad=a, uplift_accel_m_s2=up) for pv in (left, right))
    if p_rad_s is not None:
        p, source["p_rad_s"] = float(p_rad_s), "override"
        left, right = (replace(pv, p_rad_s=p) for pv in (left, right))
    if mu is not None:
        m, source["mu"] = float(mu), "override"
        left, right = (replace(pv, mu=m) for pv in (left, right))
    symmetric = cp.symmetric or (alpha_rad is not None and p_rad_s is not None and mu is not None)
    return replace(cp, alpha_rad=a, p_rad_s=p, mu=m, symmetric=symmetric, source=source, **_sides(left, right))


def classical_parameters(
    block: Block,
    *,
    alpha_rad: float | None = None,
    p_rad_s: float | None = None,
    mu: float | None = None,
    g: float = G,
) -> ClassicalParameters:
    """Classical parameters of a block, from its geometry or from explicit overrides.

    Parameters
    ----------
    block
        The block.
    alpha_rad, p_rad_s, mu
        Optional overrides (e.g. experimental values, paper Tables 3-4). An override makes
        the block symmetric in that parameter (both pivots take the value).
    g
        Gravity, m/s^2.
    """
    check_classical_overrides(alpha_rad, p_rad_s, mu)
    cp = rigid_body_classical(block.mass_kg, block.centroid_m, block.inertia_c_kgm2, block.pivots_m, g)
    return with_overrides(cp, alpha_rad=alpha_rad, p_rad_s=p_rad_s, mu=mu, g=g)


def check_classical_overrides(
    alpha_rad: float | None, p_rad_s: float | None, mu: float | None, prefix: str = ""
) -> None:
    """Validate classical overrides; raise InputError naming the field and its range."""
    for name, value, lo, hi, lo_open, hi_open in (
        ("alpha_rad", alpha_rad, 0.0, math.pi / 2, True, True),
        ("p_rad_s", p_rad_s, 0.0, math.inf, True, True),
        ("mu", mu, 0.0, 1.0, True, False),
    ):
        if value is None:
            continue
        field = f"{prefix}{name}"
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(field, f"must be a number, got {value!r}")
        if not math.isfinite(value):
            raise InputError(field, f"must be finite, got {value!r}")
        low_bad = value <= lo if lo_open else value < lo
        high_bad = value >= hi if hi_open else value > hi
        if low_bad or high_bad:
            lb = "(" if lo_open else "["
            hb = ")" if hi_open else "]"
            hi_txt = "pi/2" if hi == math.pi / 2 else ("inf" if hi == math.inf else f"{hi:g}")
            raise InputError(field, f"must be in {lb}{lo:g}, {hi_txt}{hb}, got {value!r}")
