"""The elastic response spectrum of NTC 2018 (D.M. 17/01/2018, Section 3.2.3.2.1), horizontal.

The site is given by the three parameters of its hazard for the limit state's return period
(NTC 2018 3.2 and its Allegato A, which tabulates them on a grid of sites): ag (the maximum
horizontal acceleration on rigid level ground, type A, as a fraction of g), F0 (the maximum
amplification of the spectrum, >= 2.2) and TC* (the start of the constant-velocity branch on
type A ground, s). Then (Eqs 3.2.2)::

    0  <= T < TB:  Se = ag S eta F0 [T / TB + (1 / (eta F0)) (1 - T / TB)]
    TB <= T < TC:  Se = ag S eta F0
    TC <= T < TD:  Se = ag S eta F0 (TC / T)
    TD <= T     :  Se = ag S eta F0 (TC TD / T^2)

with S = SS ST, eta = sqrt(10 / (5 + xi)) >= 0.55 (Eq 3.2.4), TC = CC TC* (Eq 3.2.5),
TB = TC / 3 (Eq 3.2.6), TD = 4.0 ag / g + 1.6 s (Eq 3.2.7). The first branch is EC8's line
from ag S to F0 ag S eta. Soil amplification SS and CC (Tab. 3.2.IV), by the subsoil
category:

    A: SS = 1.00;                                   CC = 1.00
    B: SS = 1.40 - 0.40 F0 ag/g, within [1.00, 1.20]; CC = 1.10 (TC*)^-0.20
    C: SS = 1.70 - 0.60 F0 ag/g, within [1.00, 1.50]; CC = 1.05 (TC*)^-0.33
    D: SS = 2.40 - 1.50 F0 ag/g, within [0.90, 1.80]; CC = 1.25 (TC*)^-0.50
    E: SS = 2.00 - 1.10 F0 ag/g, within [1.00, 1.60]; CC = 1.15 (TC*)^-0.40

Topographic amplification ST (Tab. 3.2.V, at the top of the relief): T1 1.0, T2 1.2, T3 1.2,
T4 1.4. It decreases linearly with height down the slope to 1 at its base (3.2.3.2.1): ST at a
point at a fraction r of the relief's height above its base is 1 + (ST_top - 1) r.

The site's parameters for a return period between the grid's are interpolated by Allegato A's
Eq 2 (log p = log p1 + log(p2 / p1) log(TR / TR1) / log(TR2 / TR1)); that interpolation is
not implemented here: give the three parameters for the return period you need.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rockyade.constants import STANDARD_GRAVITY
from rockyade.errors import InputError
from rockyade.motion.ec8 import ElasticSpectrum

#: (SS = a - b F0 ag/g, SS lower bound, SS upper bound, CC factor, CC exponent) by subsoil
#: category, NTC 2018 Tab. 3.2.IV.
NTC_SOIL = {
    "A": (1.00, 0.00, 1.00, 1.00, 1.00, 0.00),
    "B": (1.40, 0.40, 1.00, 1.20, 1.10, -0.20),
    "C": (1.70, 0.60, 1.00, 1.50, 1.05, -0.33),
    "D": (2.40, 1.50, 0.90, 1.80, 1.25, -0.50),
    "E": (2.00, 1.10, 1.00, 1.60, 1.15, -0.40),
}
#: ST at the top of the relief by topographic category, NTC 2018 Tab. 3.2.V.
NTC_TOPOGRAPHY = {"T1": 1.0, "T2": 1.2, "T3": 1.2, "T4": 1.4}
#: Ranges accepted for the site's parameters (Allegato A's grid: ag up to about 0.5 g on the
#: longest return periods, F0 about 2.2 to 3.0, TC* about 0.2 to 0.6 s; wider here).
AG_RANGE_G = (0.0, 1.0)
F0_RANGE = (1.5, 4.0)
TC_STAR_RANGE_S = (0.05, 1.5)


def soil_factors(soil: str, ag_g: float, F0: float, tc_star_s: float) -> tuple[float, float]:
    """(SS, CC) of NTC 2018 Tab. 3.2.IV for subsoil category ``soil`` (A-E)."""
    key = str(soil).upper()
    if key not in NTC_SOIL:
        raise InputError("--soil", f"must be one of A, B, C, D, E (NTC 2018 Tab. 3.2.II), got {soil!r}")
    a, b, lo, hi, cc_factor, cc_exp = NTC_SOIL[key]
    ss = min(max(a - b * F0 * ag_g, lo), hi)
    return ss, cc_factor * tc_star_s**cc_exp


def topography_factor(category: str, height_ratio: float = 1.0) -> float:
    """ST of NTC 2018 Tab. 3.2.V for ``category`` (T1-T4) at ``height_ratio`` of the relief's
    height above its base (1: at the top, the table's value; 0: at the base, 1)."""
    key = str(category).upper()
    if key not in NTC_TOPOGRAPHY:
        raise InputError("--topography", f"must be one of T1, T2, T3, T4 (NTC 2018 Tab. 3.2.III), got {category!r}")
    if not (isinstance(height_ratio, (int, float)) and 0.0 <= height_ratio <= 1.0):
        raise InputError("--topography-height-ratio", f"must be in [0, 1] (1: at the top), got {height_ratio!r}")
    return 1.0 + (NTC_TOPOGRAPHY[key] - 1.0) * float(height_ratio)


@dataclass(frozen=True)
class NtcSpectrum(ElasticSpectrum):
    """An elastic spectrum of NTC 2018's shape (module docstring): EC8's with the site's F0
    in place of 2.5. ``ag_m_s2``, ``S`` (= SS ST), the corner periods and ``damping`` as in
    :class:`~rockyade.motion.ec8.ElasticSpectrum`."""

    F0: float = 2.5

    @property
    def plateau_m_s2(self) -> float:
        """ag S eta F0, m/s^2."""
        return self.F0 * self.ag_s_m_s2 * self.eta

    def psa(self, periods_s: ArrayLike) -> NDArray[np.float64]:
        """Elastic spectral acceleration Se(T), m/s^2 (NTC 2018 Eqs 3.2.2)."""
        T = np.asarray(periods_s, dtype=float)
        if np.any(T < 0):
            raise InputError("period", "must be >= 0 s")
        top = self.plateau_m_s2
        ags = self.ag_s_m_s2
        out = np.empty_like(T)
        a = self.TB_s > T
        b = (self.TB_s <= T) & (self.TC_s > T)
        c = (self.TC_s <= T) & (self.TD_s > T)
        d = self.TD_s <= T
        out[a] = ags + (top - ags) * T[a] / self.TB_s
        out[b] = top
        out[c] = top * self.TC_s / T[c]
        out[d] = top * self.TC_s * self.TD_s / T[d] ** 2
        return out

    def as_dict(self) -> dict[str, object]:
        """JSON-ready description, with F0."""
        return {**super().as_dict(), "F0": self.F0}


def ntc_spectrum(
    ag_g: float,
    F0: float,
    tc_star_s: float,
    soil: str = "A",
    topography: str = "T1",
    height_ratio: float = 1.0,
    g: float = STANDARD_GRAVITY,
    damping: float = 0.05,
) -> NtcSpectrum:
    """NTC 2018's horizontal elastic spectrum of a site (module docstring).

    Parameters
    ----------
    ag_g
        ag on type A ground, in g (Allegato A gives it so).
    F0
        Maximum spectral amplification (Allegato A).
    tc_star_s
        TC* on type A ground, s (Allegato A).
    soil, topography, height_ratio
        Subsoil category A-E, topographic category T1-T4 and the height ratio of
        :func:`topography_factor`.
    g
        The value of g that turns ag into m/s^2 (the ratios ag/g in SS and TD use ``ag_g``).
    damping
        Damping ratio (0.05: eta = 1).
    """
    for name, value, (lo, hi) in (
        ("--ag", ag_g, AG_RANGE_G),
        ("--f0", F0, F0_RANGE),
        ("--tc-star", tc_star_s, TC_STAR_RANGE_S),
    ):
        if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value)):
            raise InputError(name, f"must be a number, got {value!r}")
        if not (lo < value <= hi if name == "--ag" else lo <= value <= hi):
            raise InputError(
                name, f"must be in [{lo:g}, {hi:g}] (NTC 2018 Allegato A's range is narrower), got {value!r}"
            )
    ss, cc = soil_factors(soil, ag_g, F0, tc_star_s)
    st = topography_factor(topography, height_ratio)
    tc = cc * tc_star_s
    tb = tc / 3.0
    td = 4.0 * ag_g + 1.6
    label = (
        f"NTC 2018, ag = {ag_g:.4g} g, F0 = {F0:g}, TC* = {tc_star_s:g} s, soil {str(soil).upper()} "
        f"(SS = {ss:.4g}, CC = {cc:.4g}), {str(topography).upper()} (ST = {st:.4g}), {100 * damping:g} %"
    )
    return NtcSpectrum(ag_g * g, ss * st, tb, tc, td, damping, label, F0=float(F0))
