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
from dataclasses import asdict, dataclass

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


@dataclass(frozen=True)
class Pivot:
    """Rocking about one base corner.

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
    """

    x_m: float
    R_m: float
    alpha_rad: float
    I_O_kgm2: float
    p_rad_s: float


def pivot_about(block: Block, pivot_m: np.ndarray, g: float = G) -> Pivot:
    """Classical parameters of rocking about ``pivot_m`` (a base corner, block frame)."""
    cx, cy = block.centroid_m
    dx = cx - float(pivot_m[0])
    R = math.hypot(dx, cy)
    alpha = math.atan2(abs(dx), cy)
    I_O = block.inertia_about(pivot_m)
    return Pivot(float(pivot_m[0]), R, alpha, I_O, frequency_parameter(block.mass_kg, R, I_O, g))


def restitution(block: Block, from_pivot_m: np.ndarray, to_pivot_m: np.ndarray) -> float:
    """Angular-velocity ratio after/before an impact that moves the pivot (general Eq 4).

    Angular momentum about the new pivot B is conserved through the impact (the impulse
    acts at B): I_c w- + M (r_G - r_B) x v_G = I_B w+, with v_G = w- z x (r_G - r_A), so
    w+/w- = (I_c + M (r_G - r_B).(r_G - r_A)) / I_B.
    """
    g_pos = np.asarray(block.centroid_m)
    ra = g_pos - from_pivot_m
    rb = g_pos - to_pivot_m
    return float((block.inertia_c_kgm2 + block.mass_kg * (rb @ ra)) / block.inertia_about(to_pivot_m))


@dataclass(frozen=True)
class ClassicalParameters:
    """Classical rocking parameters of one block.

    The headline values (``alpha_rad``, ``p_rad_s``, ``mu``, ``R_m``, ``I_O_kgm2``) are
    those of the left pivot (theta > 0) for a symmetric block. For an asymmetric block the
    headline is the pivot with the smaller alpha (it governs uplift) and ``mu`` is the mean
    over one full cycle, sqrt(mu_left_to_right * mu_right_to_left).

    ``source`` records for each of alpha, p, mu whether it came from the geometry or from
    an explicit override (the paper's experimental values, for example).
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

    def as_dict(self) -> dict[str, object]:
        """Plain dictionary, JSON-ready."""
        return asdict(self)


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
    left_xy, right_xy = block.pivots_m
    left = pivot_about(block, left_xy, g)
    right = pivot_about(block, right_xy, g)
    mu_lr = restitution(block, left_xy, right_xy)
    mu_rl = restitution(block, right_xy, left_xy)
    tol = 1e-9
    symmetric = (
        abs(left.alpha_rad - right.alpha_rad) <= tol * max(left.alpha_rad, 1.0)
        and abs(left.p_rad_s - right.p_rad_s) <= tol * max(left.p_rad_s, 1.0)
        and abs(mu_lr - mu_rl) <= tol
    )
    governing = left if left.alpha_rad <= right.alpha_rad else right
    source = {"alpha_rad": "geometry", "p_rad_s": "geometry", "mu": "geometry"}
    a = governing.alpha_rad
    p = governing.p_rad_s
    m = mu_lr if symmetric else math.sqrt(mu_lr * mu_rl)
    if alpha_rad is not None:
        a, source["alpha_rad"] = float(alpha_rad), "override"
        left = Pivot(left.x_m, left.R_m, a, left.I_O_kgm2, left.p_rad_s)
        right = Pivot(right.x_m, right.R_m, a, right.I_O_kgm2, right.p_rad_s)
    if p_rad_s is not None:
        p, source["p_rad_s"] = float(p_rad_s), "override"
        left = Pivot(left.x_m, left.R_m, left.alpha_rad, left.I_O_kgm2, p)
        right = Pivot(right.x_m, right.R_m, right.alpha_rad, right.I_O_kgm2, p)
    if mu is not None:
        m, source["mu"] = float(mu), "override"
        mu_lr = mu_rl = m
    symmetric = symmetric or (alpha_rad is not None and p_rad_s is not None and mu is not None)
    return ClassicalParameters(
        mass_kg=block.mass_kg,
        alpha_rad=a,
        p_rad_s=p,
        mu=m,
        R_m=governing.R_m,
        I_O_kgm2=governing.I_O_kgm2,
        I_c_kgm2=block.inertia_c_kgm2,
        centroid_height_m=block.centroid_m[1],
        uplift_accel_m_s2=uplift_acceleration(min(left.alpha_rad, right.alpha_rad), g),
        left=left,
        right=right,
        mu_left_to_right=mu_lr,
        mu_right_to_left=mu_rl,
        symmetric=symmetric,
        source=source,
    )


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
