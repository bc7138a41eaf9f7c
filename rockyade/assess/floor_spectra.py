"""The floor spectrum of a building (Circolare 2019 C7.2.3): the demand on a mechanism at height.

The clause's "formulazione semplificata, a diverse quote, per elementi non strutturali, impianti,
eventuali meccanismi locali", valid whatever the structure, builds the acceleration spectrum at a
height z from the building's modes and the ground's elastic spectrum. With the first mode only,
which the clause finds sufficient for the local mechanisms of multi-storey buildings:

* the floor's peak acceleration (C7.2.7, C7.2.8 with one mode)::

      a_Z(z) = Se(T1, xi1) |gamma1 psi1(z)| sqrt(1 + 0.0004 xi1^2)      (xi1 in %)

* the floor spectrum at a period T and the damping xi of the mechanism (C7.2.6, C7.2.9)::

      A = 1.1 xi1^-0.5 eta(xi)                                          (xi1 as a ratio, below)
      SeZ(T) = A a_Z / (1 + (A - 1) (1 - T / (a T1))^1.6)    T < a T1
      SeZ(T) = A a_Z                                          a T1 <= T < b T1
      SeZ(T) = A a_Z / (1 + (A - 1) (T / (b T1) - 1)^1.2)    T >= b T1

  with a = 0.8, b = 1.1 (C7.2.6), eta(xi) = sqrt(10 / (5 + xi)) >= 0.55 (NTC 2018 Eq 3.2.4), and
  not below the ground's spectrum for T > T1 (C7.2.5: SeZ >= Se(T, xi));
* gamma1 = 3 N / (2 N + 1) (C7.2.10, masses uniform over the height, a linear first mode
  normalised at the top: psi1(z) = z / H); T1 from the structure or, without it, its simplified
  estimate; xi1 the building's equivalent viscous damping (5 % elastic).

**Reading of xi_k.** The clause writes the amplification 1.1 xi_k^-0.5 and the peak's factor
sqrt(1 + 0.0004 xi_k^2), and says xi_k is "in percentuale". With xi_k = 5 (per cent) the
amplification would be 1.1 / sqrt(5) = 0.49: a floor spectrum whose peak at the building's own
period is half the floor's peak acceleration, against the clause's own words (the floor
spectra "presentano una forte amplificazione in corrispondenza del periodo fondamentale").
The amplification is read with xi_k as a ratio, 1.1 / sqrt(0.05) = 4.92 at 5 % (falling to
3.48 at 10 %, as the clause says it falls when the building yields), and the peak's factor
with xi_k in per cent, sqrt(1 + 0.0004 x 25) = 1.005 (with a ratio it would be 1 whatever
the damping). Both readings are printed with every check (:attr:`FloorSpectrum.amplification`).

The checks built on it are :func:`rockyade.assess.code.code_checks`'s at height.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rockyade.errors import InputError
from rockyade.motion.ec8 import ElasticSpectrum, damping_correction

#: a and b of C7.2.6: the floor spectrum's plateau spans a T1 to b T1.
FLOOR_A = 0.8
FLOOR_B = 1.1
#: Exponents of C7.2.6's rising and falling branches.
RISE_EXPONENT = 1.6
FALL_EXPONENT = 1.2
#: Equivalent damping of a mechanism free to vibrate at its period T0 for the damage limit state
#: and the linear check (Circolare 2019 C8.7.1.2.1.5: 5 %), and of a mechanism's nonlinear
#: check at the life-safety limit state (C8.7.1.2.1.8: 8 %; 10 % at the collapse limit state).
SLD_DAMPING = 0.05
SLV_DAMPING = 0.08
#: The building's elastic damping (the 5 % of the ground's spectrum).
BUILDING_DAMPING = 0.05
#: Range accepted for a damping ratio here (2 % to 30 %).
DAMPING_RANGE = (0.02, 0.30)


def check_damping(value: float, option: str) -> float:
    """A damping ratio in :data:`DAMPING_RANGE`, else InputError naming ``option`` (given in %)."""
    lo, hi = DAMPING_RANGE
    if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
        shown = f"{100 * value:g} %" if isinstance(value, (int, float)) and not isinstance(value, bool) else repr(value)
        raise InputError(option, f"must be in [{100 * lo:g}, {100 * hi:g}] %, got {shown}")
    return float(value)


@dataclass(frozen=True)
class FloorSpectrum:
    """The first mode's floor spectrum at a height of a building (module docstring).

    Attributes
    ----------
    ground
        The site's elastic spectrum at the ground (5 %; the clause's damping replaces it where
        it asks for another).
    T1_s
        The building's fundamental period, s.
    gamma1
        Its first mode's participation factor.
    psi1
        Its first mode's value at the height z (normalised at the top).
    building_damping
        The building's equivalent viscous damping xi1, a ratio.
    """

    ground: ElasticSpectrum
    T1_s: float
    gamma1: float
    psi1: float
    building_damping: float = BUILDING_DAMPING

    def __post_init__(self) -> None:
        if not (math.isfinite(self.T1_s) and self.T1_s > 0.0):
            raise InputError("--t1", f"must be > 0 s, got {self.T1_s!r}")
        check_damping(self.building_damping, "--building-damping-pct")

    def ground_psa(self, periods_s: ArrayLike, damping: float) -> NDArray[np.float64]:
        """Se(T, xi), the ground's elastic spectrum at damping ``damping`` (NTC 2018 Eq 3.2.4), m/s^2."""
        return dataclasses.replace(self.ground, damping=damping).psa(periods_s)

    @property
    def peak_m_s2(self) -> float:
        """a_Z = Se(T1, xi1) |gamma1 psi1| sqrt(1 + 0.0004 xi1^2), xi1 in % (C7.2.7, C7.2.8), m/s^2."""
        se = float(self.ground_psa([self.T1_s], self.building_damping)[0])
        xi_pct = 100.0 * self.building_damping
        return se * abs(self.gamma1 * self.psi1) * math.sqrt(1.0 + 0.0004 * xi_pct**2)

    def amplification(self, damping: float) -> float:
        """A = 1.1 xi1^-0.5 eta(xi): the plateau over a_Z (C7.2.6, C7.2.9; xi1 as a ratio, module
        docstring), for a mechanism of damping ``damping``."""
        return 1.1 / math.sqrt(self.building_damping) * damping_correction(damping)

    def psa(self, periods_s: ArrayLike, damping: float) -> NDArray[np.float64]:
        """SeZ(T, xi, z) of C7.2.6 with C7.2.5's floor (the ground's Se(T, xi) for T > T1), m/s^2."""
        T = np.atleast_1d(np.asarray(periods_s, dtype=float))
        if np.any(T < 0) or not np.all(np.isfinite(T)):
            raise InputError("period", "must be finite and >= 0 s")
        amp, peak = self.amplification(damping), self.peak_m_s2
        top = amp * peak
        lo, hi = FLOOR_A * self.T1_s, FLOOR_B * self.T1_s
        out = np.full_like(T, top)
        rise, fall = lo > T, hi <= T
        out[rise] = top / (1.0 + (amp - 1.0) * (1.0 - T[rise] / lo) ** RISE_EXPONENT)
        out[fall] = top / (1.0 + (amp - 1.0) * (T[fall] / hi - 1.0) ** FALL_EXPONENT)
        beyond = self.T1_s < T
        if np.any(beyond):
            out[beyond] = np.maximum(out[beyond], self.ground_psa(T[beyond], damping))
        return out

    def sde(self, periods_s: ArrayLike, damping: float) -> NDArray[np.float64]:
        """The floor's displacement spectrum SeZ(T) T^2 / (4 pi^2) (Circolare 2019 C8.7.1.2.1.8), m."""
        T = np.atleast_1d(np.asarray(periods_s, dtype=float))
        return self.psa(T, damping) * (T / (2.0 * math.pi)) ** 2

    def describe(self, damping: float) -> str:
        """One line: the floor's peak and plateau at ``damping``, with their terms."""
        se_t1 = float(self.ground_psa([self.T1_s], self.building_damping)[0])
        return (
            f"floor spectrum (Circolare 2019 C7.2.5-C7.2.10, first mode): a_Z = Se(T1 = {self.T1_s:.4g} s, "
            f"xi1 = {100 * self.building_damping:g} %) |gamma1 psi1| sqrt(1 + 0.0004 xi1^2) = {se_t1:.4g} x "
            f"{abs(self.gamma1 * self.psi1):.4g} x {math.sqrt(1.0 + 0.0004 * (100 * self.building_damping) ** 2):.4f} "
            f"= {self.peak_m_s2:.4g} m/s^2; plateau A a_Z on [{FLOOR_A:g} T1, {FLOOR_B:g} T1] with A = 1.1 xi1^-0.5 "
            f"eta(xi = {100 * damping:g} %) = {self.amplification(damping):.4g} (xi1 as a ratio)"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: the inputs and the peak."""
        return {
            "T1_s": self.T1_s,
            "gamma1": self.gamma1,
            "psi1": self.psi1,
            "building_damping": self.building_damping,
            "a": FLOOR_A,
            "b": FLOOR_B,
            "peak_acceleration_m_s2": self.peak_m_s2,
            "source": "Circolare 2019 C7.2.3, Eqs C7.2.5-C7.2.10 (first mode; xi1 as a ratio in 1.1 xi1^-0.5, "
            "in per cent in sqrt(1 + 0.0004 xi1^2))",
        }


def secant_period(d_slv_m: float, a_slv_m_s2: float) -> float:
    """T_SLV = 1.68 pi sqrt(d_SLV / a(d_SLV)) (Circolare 2019 Eq C8.7.1.10), s."""
    return 1.68 * math.pi * math.sqrt(d_slv_m / a_slv_m_s2)


def displacement_demand(floor: FloorSpectrum, period_s: float, damping: float = SLV_DAMPING) -> tuple[float, float]:
    """(demand, floor term) of Circolare 2019 Eq C8.7.1.12, m: SeZ(T_SLV, xi) T_SLV^2 / (4 pi^2), and not
    below SeZ(T1, xi) b^2 T1^2 / (4 pi^2) when T_SLV > b T1 (the second number; NaN when it does not apply)."""
    demand = float(floor.sde([period_s], damping)[0])
    bound = math.nan
    if period_s > FLOOR_B * floor.T1_s:
        bound = float(floor.psa([floor.T1_s], damping)[0]) * (FLOOR_B * floor.T1_s / (2.0 * math.pi)) ** 2
        demand = max(demand, bound)
    return demand, bound


__all__ = [
    "BUILDING_DAMPING",
    "FLOOR_A",
    "FLOOR_B",
    "SLD_DAMPING",
    "SLV_DAMPING",
    "FloorSpectrum",
    "check_damping",
    "displacement_demand",
    "secant_period",
]
