"""Intensity measures of a base motion for rocking blocks, beside the PGA.

Rocking response correlates poorly with the PGA alone; the literature prefers velocity-based
and dimensionless measures. Of the horizontal base acceleration a(t) (piecewise linear,
as every solver sees it, :class:`rockyade.motion.ground.GroundMotion`):

* ``pga_m_s2``: peak ground acceleration max |a|, m/s^2;
* ``pgv_m_s``: peak ground velocity max |v|, v = int a dt from rest, m/s;
* ``pgv_over_pga_s``: PGV / PGA, s, a measure of the pulse duration that governs
  overturning (Makris & Konstantinidis 2003, "The rocking spectrum and the limitations of
  practical design methodologies", Earthquake Eng. Struct. Dyn. 32);
* ``arias_m_s``: Arias intensity I_A = pi / (2 g) int a^2 dt, m/s (Arias 1970, "A measure of
  earthquake intensity", in Seismic Design for Nuclear Power Plants, MIT Press), integrated
  exactly for the piecewise-linear a(t);
* ``significant_duration_s``: D_5-95, the time between 5 % and 95 % of the final Arias
  intensity (Trifunac & Brady 1975, "A study on the duration of strong earthquake ground
  motion", Bull. Seismol. Soc. Am. 65);
* ``pga_over_g_tan_alpha``: PGA / (g tan alpha), the peak acceleration over the uplift
  threshold of the block (Makris & Konstantinidis 2003; the dimensionless fragility
  curves of Dimitrakopoulos & Paraskeva 2015, Earthquake Eng. Struct. Dyn. 44);
* ``pgv_p_over_g_tan_alpha``: PGV p / (g tan alpha), the peak velocity over the block's
  velocity scale g tan(alpha) / p (the dimensional analysis of rocking of Dimitrakopoulos
  & DeJong 2012, "Revisiting the rocking block: closed-form solutions and similarity
  laws", Proc. R. Soc. A 468).

The last two need the block's alpha (and p).
"""

from __future__ import annotations

import math

import numpy as np

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.motion.ground import GroundMotion

#: Measures of the motion alone.
MOTION_MEASURES = ("pga_m_s2", "pgv_m_s", "pgv_over_pga_s", "arias_m_s", "significant_duration_s")
#: Measures that also need the block (alpha, p).
BLOCK_MEASURES = ("pga_over_g_tan_alpha", "pgv_p_over_g_tan_alpha")
#: Every intensity measure, by name.
INTENSITY_MEASURES = MOTION_MEASURES + BLOCK_MEASURES
#: How each measure scales with a load factor lambda on the acceleration: IM(lambda a) = lambda^k IM(a).
SCALING_EXPONENT = {
    "pga_m_s2": 1,
    "pgv_m_s": 1,
    "pgv_over_pga_s": 0,
    "arias_m_s": 2,
    "significant_duration_s": 0,
    "pga_over_g_tan_alpha": 1,
    "pgv_p_over_g_tan_alpha": 1,
}
LABELS = {
    "pga_m_s2": "PGA (m/s$^2$)",
    "pgv_m_s": "PGV (m/s)",
    "pgv_over_pga_s": "PGV/PGA (s)",
    "arias_m_s": "Arias intensity (m/s)",
    "significant_duration_s": "significant duration D$_{5-95}$ (s)",
    "pga_over_g_tan_alpha": r"PGA / (g tan$\alpha$)",
    "pgv_p_over_g_tan_alpha": r"PGV p / (g tan$\alpha$)",
}


def check_measure(name: str, field: str = "intensity_measure") -> str:
    """``name`` if it is a known intensity measure, else InputError listing them."""
    if name not in INTENSITY_MEASURES:
        raise InputError(field, f"must be one of {', '.join(INTENSITY_MEASURES)}, got {name!r}")
    return name


def arias_history(motion: GroundMotion, g: float = G) -> np.ndarray:
    """Cumulative Arias intensity pi / (2 g) int_0^t a^2 dt at the motion's samples, m/s (Arias 1970).

    Exact for a linear a between samples: int a^2 = dt (a0^2 + a0 a1 + a1^2) / 3.
    """
    a = motion.ah_m_s2
    dt = np.diff(motion.t_s)
    pieces = dt * (a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3.0
    return math.pi / (2.0 * g) * np.concatenate([[0.0], np.cumsum(pieces)])


def significant_duration(motion: GroundMotion, lower: float = 0.05, upper: float = 0.95, g: float = G) -> float:
    """Time between ``lower`` and ``upper`` fractions of the final Arias intensity, s
    (D_5-95 by default; Trifunac & Brady 1975)."""
    if not 0.0 <= lower < upper <= 1.0:
        raise InputError("significant_duration", f"needs 0 <= lower < upper <= 1, got {lower}, {upper}")
    husid = arias_history(motion, g)
    total = husid[-1]
    if total <= 0.0:
        return 0.0
    t_lo = float(np.interp(lower * total, husid, motion.t_s))
    t_hi = float(np.interp(upper * total, husid, motion.t_s))
    return t_hi - t_lo


def intensity_measures(
    motion: GroundMotion, alpha_rad: float | None = None, p_rad_s: float | None = None, g: float = G
) -> dict[str, float]:
    """Intensity measures of a base motion (module docstring), by name.

    Parameters
    ----------
    motion
        Horizontal base acceleration.
    alpha_rad, p_rad_s
        The block's critical angle (rad) and frequency parameter (rad/s); without them
        the block measures are NaN.
    g
        Gravity, m/s^2.
    """
    pga = motion.pga_m_s2
    v, _ = motion.velocity_displacement()
    pgv = float(np.max(np.abs(v)))
    out = {
        "pga_m_s2": pga,
        "pgv_m_s": pgv,
        "pgv_over_pga_s": pgv / pga if pga > 0 else math.nan,
        "arias_m_s": float(arias_history(motion, g)[-1]),
        "significant_duration_s": significant_duration(motion, g=g),
        "pga_over_g_tan_alpha": math.nan,
        "pgv_p_over_g_tan_alpha": math.nan,
    }
    if alpha_rad is not None:
        uplift = g * math.tan(alpha_rad)
        out["pga_over_g_tan_alpha"] = pga / uplift
        if p_rad_s is not None:
            out["pgv_p_over_g_tan_alpha"] = pgv * p_rad_s / uplift
    return out


def scaled(measures: dict[str, float], load_factor: float) -> dict[str, float]:
    """The measures of the same motion with its acceleration multiplied by ``load_factor``."""
    return {k: v * load_factor ** SCALING_EXPONENT[k] for k, v in measures.items()}
