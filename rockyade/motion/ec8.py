"""Eurocode 8 horizontal elastic response spectrum (EN 1998-1:2004, Section 3.2.2.2).

    0 <= T <= TB :  Se = ag S [1 + T / TB (2.5 eta - 1)]
    TB <= T <= TC:  Se = 2.5 ag S eta
    TC <= T <= TD:  Se = 2.5 ag S eta TC / T
    TD <= T      :  Se = 2.5 ag S eta TC TD / T^2        (defined up to 4 s)

with the damping correction eta = sqrt(10 / (5 + xi[%])) >= 0.55 (Eq 3.6). Tables 3.2
(Type 1) and 3.3 (Type 2) give S, TB, TC, TD for ground types A-E. The seed paper's suite
(Section 3.3) is Type 2, ground D (TB 0.10 s, TC 0.30 s), with a plateau of 7 m/s^2 and
ag S = 2.8 m/s^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rockyade.errors import InputError

#: (S, TB, TC, TD) per spectrum type and ground type, EN 1998-1 Tables 3.2 and 3.3.
EC8_GROUND = {
    1: {
        "A": (1.0, 0.15, 0.4, 2.0),
        "B": (1.2, 0.15, 0.5, 2.0),
        "C": (1.15, 0.20, 0.6, 2.0),
        "D": (1.35, 0.20, 0.8, 2.0),
        "E": (1.4, 0.15, 0.5, 2.0),
    },
    2: {
        "A": (1.0, 0.05, 0.25, 1.2),
        "B": (1.35, 0.05, 0.25, 1.2),
        "C": (1.5, 0.10, 0.25, 1.2),
        "D": (1.8, 0.10, 0.30, 1.2),
        "E": (1.6, 0.05, 0.25, 1.2),
    },
}


def damping_correction(damping: float) -> float:
    """eta = sqrt(10 / (5 + xi)) with xi in %, not below 0.55 (EN 1998-1 Eq 3.6)."""
    if not 0.0 <= damping < 1.0:
        raise InputError("damping", f"must be in [0, 1) (0.05 = 5 %), got {damping!r}")
    return max(0.55, math.sqrt(10.0 / (5.0 + 100.0 * damping)))


@dataclass(frozen=True)
class ElasticSpectrum:
    """A spectrum of the EC8 shape.

    Attributes
    ----------
    ag_m_s2
        Design ground acceleration on type A ground, m/s^2.
    S
        Soil factor.
    TB_s, TC_s, TD_s
        Corner periods, s.
    damping
        Damping ratio of the spectrum (0.05: eta = 1).
    label
        Description.
    """

    ag_m_s2: float
    S: float
    TB_s: float
    TC_s: float
    TD_s: float
    damping: float = 0.05
    label: str = "custom"

    def __post_init__(self) -> None:
        for name in ("ag_m_s2", "S", "TB_s", "TC_s", "TD_s"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise InputError(name, f"must be a number > 0, got {value!r}")
        if not self.TB_s < self.TC_s < self.TD_s:
            raise InputError(
                "TC_s", f"corner periods must satisfy TB < TC < TD, got {self.TB_s}, {self.TC_s}, {self.TD_s}"
            )
        damping_correction(self.damping)

    @classmethod
    def ec8(
        cls,
        spectrum_type: int,
        ground: str,
        *,
        ag_m_s2: float | None = None,
        ag_s_m_s2: float | None = None,
        damping: float = 0.05,
    ) -> ElasticSpectrum:
        """EC8 spectrum of ``spectrum_type`` (1 or 2) and ground type A-E.

        Give the design ground acceleration either as ``ag_m_s2`` or as the product
        ``ag_s_m_s2`` = ag S (the paper gives ag S = 2.8 m/s^2).
        """
        if spectrum_type not in EC8_GROUND:
            raise InputError("spectrum_type", f"must be 1 or 2, got {spectrum_type!r}")
        ground_key = str(ground).upper()
        if ground_key not in EC8_GROUND[spectrum_type]:
            raise InputError("ground", f"must be one of A, B, C, D, E, got {ground!r}")
        S, TB, TC, TD = EC8_GROUND[spectrum_type][ground_key]
        if (ag_m_s2 is None) == (ag_s_m_s2 is None):
            raise InputError("ag_m_s2", "give exactly one of ag_m_s2 and ag_s_m_s2 (ag times S)")
        ag = ag_m_s2 if ag_m_s2 is not None else ag_s_m_s2 / S  # type: ignore[operator]
        label = f"EC8 Type {spectrum_type}, ground {ground_key}, ag S = {ag * S:.3g} m/s^2, {100 * damping:g} %"
        return cls(float(ag), S, TB, TC, TD, damping, label)

    @property
    def eta(self) -> float:
        """Damping correction factor."""
        return damping_correction(self.damping)

    @property
    def ag_s_m_s2(self) -> float:
        """ag S: the spectrum at T = 0 (the expected peak ground acceleration), m/s^2."""
        return self.ag_m_s2 * self.S

    @property
    def plateau_m_s2(self) -> float:
        """2.5 ag S eta, m/s^2."""
        return 2.5 * self.ag_s_m_s2 * self.eta

    def psa(self, periods_s: ArrayLike) -> NDArray[np.float64]:
        """Elastic spectral acceleration Se(T), m/s^2."""
        T = np.asarray(periods_s, dtype=float)
        if np.any(T < 0):
            raise InputError("period", "must be >= 0 s")
        ags, eta = self.ag_s_m_s2, self.eta
        out = np.empty_like(T)
        a = self.TB_s >= T
        b = (self.TB_s < T) & (self.TC_s >= T)
        c = (self.TC_s < T) & (self.TD_s >= T)
        d = self.TD_s < T
        out[a] = ags * (1.0 + T[a] / self.TB_s * (2.5 * eta - 1.0))
        out[b] = 2.5 * ags * eta
        out[c] = 2.5 * ags * eta * self.TC_s / T[c]
        out[d] = 2.5 * ags * eta * self.TC_s * self.TD_s / T[d] ** 2
        return out

    def as_dict(self) -> dict[str, object]:
        """JSON-ready description."""
        return {
            "ag_m_s2": self.ag_m_s2,
            "S": self.S,
            "TB_s": self.TB_s,
            "TC_s": self.TC_s,
            "TD_s": self.TD_s,
            "damping": self.damping,
            "ag_s_m_s2": self.ag_s_m_s2,
            "plateau_m_s2": self.plateau_m_s2,
            "label": self.label,
        }
