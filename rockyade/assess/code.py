"""The code's checks of a mechanism: the kinematic method of NTC 2018 (Circolare 2019 C8.7.1).

The capacity side is :mod:`rockyade.limit.kinematic` (alpha0, M*, e*, a0*, d0*, du*, Ts);
here the demand of the site (:mod:`rockyade.assess.site`: NTC 2018's elastic spectrum
3.2.3.2.1, or EN 1998-1's 3.2.2.2 when asked for) and the comparison, each check with its
clause and formula (:data:`CHECK_SOURCES`):

* linear kinematic analysis, a mechanism at ground level: a0* >= ag S / q (Circolare 2019
  C8.7.1.2.1.7, the same form as Circolare 2009 C8A.4.2.3);
* nonlinear kinematic analysis, a mechanism at ground level (Circolare 2019 C8.7.1.2.1.8):
  d_SLV = 0.4 d0* (C8.7.1.2.1.6, the du* of the capacity curve) >= SDe(T_SLV, xi), the elastic
  displacement spectrum SDe(T) = Se(T, xi) (T / 2 pi)^2 (NTC 2018 3.2.3.2.3 Eq 3.2.12; EN 1998-1
  3.2.2.2 Eq 3.7) at the secant period T_SLV = 1.68 pi sqrt(d_SLV / a(d_SLV)) (Eq C8.7.1.10) and
  the mechanism's damping xi = 8 % (C8.7.1.2.1.8; Se scaled by eta(xi) = sqrt(10 / (5 + xi)),
  NTC 2018 Eq 3.2.4), for T_SLV up to 4 s. The clause takes the largest spectral displacement
  over [T0, T_SLV]; the code's spectra do not decrease with T, so that is SDe(T_SLV).
  Or, asked for by name (``circolare2009``), the superseded form of Circolare 2009 C8A.4.2.3:
  du* >= SDe(Ts) at 5 %, Ts = 2 pi sqrt(ds* / as*), ds* = 0.4 du*;
* a mechanism at height Z of a building of height H, N storeys and period T1, by Circolare 2019
  C8.7.1 with the floor spectrum SeZ of C7.2.3 (:mod:`rockyade.assess.floor_spectra`; first
  mode, psi(Z) = Z / H, gamma = 3 N / (2 N + 1), the building's damping xi1):

  - linear (C8.7.1.2.1.7 on C8.7.1.2.1.5): ag,SLV = q ag,SLD, ag,SLD the ag at which the floor's
    demand at the mechanism's period T0 and 5 % damping, SeZ(T0) (= a_Z, the floor's peak, at
    T0 = 0, a mechanism rigid until it moves: Eqs C8.7.1.8 and C7.2.8; Eqs C8.7.1.9 and C7.2.5
    for T0 > 0), reaches a0*: the check a0* >= SeZ(T0) / q;
  - nonlinear (C8.7.1.2.1.8): d_SLV = 0.4 d0* >= SeZ(T_SLV, xi) T_SLV^2 / (4 pi^2) (Eq C8.7.1.12,
    not below SeZ(T1, xi) b^2 T1^2 / (4 pi^2) when T_SLV > b T1), with T_SLV of Eq C8.7.1.10 and
    the mechanism's damping xi = 8 %;

  or, asked for by name (``circolare2009``), the superseded form of Circolare 2009 C8A.4.2.3:
  a0* >= Se(T1) psi(Z) gamma / q (linear only).

with the behaviour factor q = 2. The linear and the nonlinear analyses are two ways of checking
the same mechanism (the linear one, with q, the simpler and more conservative): the mechanism
is verified when one of the checks that apply is met. Each check also gives the ag at which it is
met, its ag_capacity: the code's capacity in the units of the site's shaking, with the site's other
parameters (F0, TC*, soil, topography) held. EC8's demand is proportional to ag, so there it is
ag x capacity / demand; NTC 2018's is not where SS (Tab. 3.2.IV: soils C, D, E, and B below its
bound) or TD = 4 ag/g + 1.6 s (Eq 3.2.6, for a period beyond TD) change with ag, so there the
check is made again at other ag until capacity = demand (:func:`_ag_met`).

Checks the tool does not make are listed, with the reason, by :func:`checks_not_made` (they
go into the output's notes).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rockyade.assess.floor_spectra import SLD_DAMPING, displacement_demand, secant_period
from rockyade.assess.site import MAX_AG_G, AnySite, NtcSite, Position
from rockyade.constants import CODE_GRAVITY as G
from rockyade.errors import InputError
from rockyade.limit.kinematic import KinematicQuantities
from rockyade.motion.ec8 import damping_correction

#: Codes whose checks are implemented.
CODES = ("ntc2018",)
#: Behaviour factor of the linear kinematic check (Circolare 2019 C8.7.1).
Q_FACTOR = 2.0
#: Where q comes from, printed beside every linear check.
Q_CLAUSE = "Circolare 2019 C8.7.1"
#: The confidence factor of each knowledge level for masonry buildings (NTC 2018 8.5.4; Circolare 2019
#: C8.5.4, Tab. C8.5.IV): limited (LC1), adequate (LC2), accurate (LC3).
KNOWLEDGE_LEVELS = {"LC1": 1.35, "LC2": 1.20, "LC3": 1.00}
KNOWLEDGE_CLAUSE = "NTC 2018 8.5.4, Circolare 2019 C8.5.4 Tab. C8.5.IV"


def confidence_factor(level: str | None, fc: float | None) -> tuple[float, str]:
    """FC and where it comes from: the knowledge level (``LC1``, ``LC2``, ``LC3``: 1.35, 1.20, 1.00) or
    the engineer's own value; one of the two, never a default (the code's check is the engineer's).

    Raises
    ------
    InputError
        Neither given, or both (naming ``--knowledge-level`` and ``--fc``); an unknown level (naming
        ``--knowledge-level``); FC outside [1, 10] (naming ``--fc``).
    """
    if level is None and fc is None:
        raise InputError(
            "--knowledge-level",
            "the code check needs the confidence factor: give the knowledge level, --knowledge-level LC1, LC2 or LC3 "
            f"(FC 1.35, 1.20, 1.00; {KNOWLEDGE_CLAUSE}), or --fc FC",
        )
    if level is not None and fc is not None:
        raise InputError("--fc", "give the knowledge level (--knowledge-level) or FC (--fc), not both")
    if level is not None:
        key = str(level).strip().upper()
        if key not in KNOWLEDGE_LEVELS:
            raise InputError("--knowledge-level", f"must be LC1, LC2 or LC3 ({KNOWLEDGE_CLAUSE}), got {level!r}")
        value = KNOWLEDGE_LEVELS[key]
        return value, f"knowledge level {key}, {KNOWLEDGE_CLAUSE}"
    assert fc is not None
    from rockyade.limit.kinematic import check_fc

    try:
        value = check_fc(fc)
    except InputError as exc:
        raise InputError("--fc", exc.message) from None
    return (
        value,
        f"as given (--fc; the knowledge levels of {KNOWLEDGE_CLAUSE}: LC1 1.35, LC2 1.20, LC3 1.00)",
    )


#: The clause every check comes from.
CLAUSE = "NTC 2018 8.7.1, Circolare 2019 C8.7.1 (kinematic analysis of local mechanisms)"
#: Each check's clause and formula (the check's ``source``).
CHECK_SOURCES = {
    "linear, ground level": "Circolare 2019 C8.7.1.2.1.7, linear kinematic analysis at ground level (the same form as "
    "Circolare 2009 C8A.4.2.3): a0* = alpha0 g / (e* FC) >= ag S / q",
    "nonlinear, ground level": "Circolare 2019 C8.7.1.2.1.8, nonlinear kinematic analysis at ground level: d_SLV = "
    "0.4 d0* (C8.7.1.2.1.6) >= SDe(T_SLV) = Se(T_SLV, xi) T_SLV^2 / (4 pi^2), the elastic displacement spectrum "
    "at the mechanism's damping xi (the largest over [T0, T_SLV]: the code's spectrum does not decrease with T), "
    "T_SLV = 1.68 pi sqrt(d_SLV / a(d_SLV)) (Eq C8.7.1.10)",
    "nonlinear, ground level (Circolare 2009)": "Circolare 2009 C8A.4.2.3 form, asked for with --code-form "
    "circolare2009 (superseded: Circolare 2019 C8.7.1.2.1.8 takes the displacement spectrum at T_SLV with the "
    "mechanism's damping, the default): du* = 0.4 d0* >= SDe(Ts), Ts = 2 pi sqrt(ds* / as*), ds* = 0.4 du*, 5 %",
    "linear, at height": "Circolare 2019 C8.7.1.2.1.7 on C8.7.1.2.1.5, linear kinematic analysis at height: "
    "ag,SLV = q ag,SLD, ag,SLD the ag at which the floor's demand SeZ(T0, 5 %) (Eqs C7.2.5-C7.2.10; the floor's peak "
    "a_Z at T0 = 0, Eqs C8.7.1.8 and C7.2.8) reaches a0* = alpha0 g / (e* FC) (Eq C8.7.1.9): a0* >= SeZ(T0) / q",
    "nonlinear, at height": "Circolare 2019 C8.7.1.2.1.8, nonlinear kinematic analysis at height: d_SLV = 0.4 d0* "
    "(C8.7.1.2.1.6) >= SeZ(T_SLV, xi) T_SLV^2 / (4 pi^2), not below SeZ(T1, xi) b^2 T1^2 / (4 pi^2) for T_SLV > b T1 "
    "(Eq C8.7.1.12), T_SLV = 1.68 pi sqrt(d_SLV / a(d_SLV)) (Eq C8.7.1.10), SeZ of Eqs C7.2.5-C7.2.10",
    "linear, at height (Circolare 2009)": "Circolare 2009 C8A.4.2.3 form, asked for with --code-form circolare2009 "
    "(superseded: Circolare 2019 C8.7.1 takes the demand at height from the floor spectra of C7.2.3, the default): "
    "a0* >= Se(T1) psi(Z) gamma / q",
}

VERIFIED, NOT_VERIFIED, NOT_APPLICABLE = "verified", "not verified", "not applicable"


def check_code(code: str) -> str:
    """``code`` if implemented, else InputError naming the codes."""
    if code not in CODES:
        raise InputError("--code", f"must be one of {', '.join(CODES)}, got {code!r}")
    return code


def displacement_spectrum(site: AnySite, period_s: float) -> float:
    """SDe(T) = Se(T) (T / 2 pi)^2, m (NTC 2018 Eq 3.2.12; EN 1998-1 Eq 3.7)."""
    se = float(site.spectrum.psa([period_s])[0])
    return se * (period_s / (2.0 * math.pi)) ** 2


@dataclass(frozen=True)
class Check:
    """One check of the code.

    Attributes
    ----------
    name
        What is checked (``linear, ground level``, ...).
    quantity
        The capacity compared (``a0*``, ``du*``).
    inequality
        The check as the code writes it.
    demand, capacity
        Its two sides, in ``unit`` (NaN when it does not apply).
    unit
        ``m/s^2`` or ``m``.
    status
        ``verified``, ``not verified`` or ``not applicable``.
    terms
        The numbers the demand is made of (ag, S, q, Se(T), psi, gamma, Ts, ...).
    ag_capacity_m_s2
        The site's ag at which capacity = demand, m/s^2 (NaN when it does not apply).
    reason
        Why it does not apply (else empty).
    source
        Clause and equations.
    demand_text
        How the demand is made, in words and numbers (the text's and the report's; empty where the
        check does not apply).
    """

    name: str
    quantity: str
    inequality: str
    demand: float
    capacity: float
    unit: str
    status: str
    terms: dict[str, float] = field(default_factory=dict)
    ag_capacity_m_s2: float = math.nan
    reason: str = ""
    source: str = CLAUSE
    demand_text: str = ""

    @property
    def applies(self) -> bool:
        """True when the check could be made."""
        return self.status != NOT_APPLICABLE

    @property
    def ratio(self) -> float:
        """capacity / demand (>= 1: verified)."""
        return self.capacity / self.demand if self.applies and self.demand > 0 else math.nan

    def to_dict(self) -> dict[str, object]:
        """JSON-ready (the demand and capacity with their unit, the verdict, its source)."""
        return {
            "name": self.name,
            "quantity": self.quantity,
            "inequality": self.inequality,
            "demand": self.demand,
            "capacity": self.capacity,
            "unit": self.unit,
            "capacity_over_demand": self.ratio,
            "verdict": self.status,
            "terms": dict(self.terms),
            "ag_capacity_m_s2": self.ag_capacity_m_s2,
            "ag_capacity_g": self.ag_capacity_m_s2 / G,
            "reason": self.reason,
            "source": self.source,
            "demand_text": self.demand_text,
        }


def _check(name: str, quantity: str, inequality: str, demand: float, capacity: float, unit: str, **kw: Any) -> Check:
    status = VERIFIED if capacity >= demand else NOT_VERIFIED
    return Check(name, quantity, inequality, demand, capacity, unit, status, **kw)


def _not_applicable(name: str, quantity: str, inequality: str, unit: str, reason: str) -> Check:
    source = CHECK_SOURCES.get(name, CLAUSE)
    return Check(name, quantity, inequality, math.nan, math.nan, unit, NOT_APPLICABLE, reason=reason, source=source)


def code_checks(kin: KinematicQuantities, site: AnySite, position: Position, q: float = Q_FACTOR) -> list[Check]:
    """The checks of a mechanism's kinematic quantities against the site's demand (module docstring).

    Parameters
    ----------
    kin
        The mechanism's quantities (:func:`rockyade.limit.kinematic_quantities`).
    site
        The site's spectrum.
    position
        At ground level, or at a height of a building.
    q
        Behaviour factor of the linear check (2).
    """
    checks = _checks_at(kin, site, position, q)
    if not isinstance(site, NtcSite):
        return checks
    return [
        dataclasses.replace(c, ag_capacity_m_s2=_ag_met(kin, site, position, q, i, c.ag_capacity_m_s2))
        if c.applies and math.isfinite(c.ag_capacity_m_s2)
        else c
        for i, c in enumerate(checks)
    ]


def _ratio_at(kin: KinematicQuantities, site: NtcSite, position: Position, q: float, i: int, ag_g: float) -> float:
    """capacity / demand of check ``i`` with the site's ag set to ``ag_g`` (g), minus 1."""
    check = _checks_at(kin, dataclasses.replace(site, ag_g=ag_g), position, q)[i]
    return check.ratio - 1.0


def _ag_met(kin: KinematicQuantities, site: NtcSite, position: Position, q: float, i: int, guess: float) -> float:
    """The ag (m/s^2) at which check ``i`` is met exactly on the NTC 2018 site with its other
    parameters held: the root of capacity / demand = 1, bracketed from ``guess`` (ag x capacity /
    demand, exact where the spectrum is proportional to ag) within NTC 2018's ag of (0, 1] g;
    ``guess`` where no root lies there."""
    from scipy.optimize import brentq

    lo_limit, hi_limit = 1e-4, MAX_AG_G
    x0 = min(max(guess / G, lo_limit), hi_limit)
    f0 = _ratio_at(kin, site, position, q, i, x0)
    if f0 == 0.0 or not math.isfinite(f0):
        return guess
    step = 1.25 if f0 > 0 else 0.8
    x1, f1 = x0, f0
    while f1 * f0 > 0:
        x_next = min(max(x1 * step, lo_limit), hi_limit)
        if x_next == x1:
            return guess
        x1, f1 = x_next, _ratio_at(kin, site, position, q, i, x_next)
        if not math.isfinite(f1):
            return guess
    a, b = sorted((x0, x1))
    return float(brentq(lambda x: _ratio_at(kin, site, position, q, i, x), a, b, xtol=1e-10, rtol=1e-12)) * G


def _checks_at(kin: KinematicQuantities, site: AnySite, position: Position, q: float) -> list[Check]:
    """The checks with each ag_capacity = ag x capacity / demand (:func:`code_checks` refines it)."""
    ag, S = site.ag_m_s2, site.S
    a0 = kin.a0_star_m_s2
    checks = []
    if not position.at_height:
        demand = ag * S / q
        checks.append(
            _check(
                "linear, ground level",
                "a0*",
                "a0* >= ag S / q",
                demand,
                a0,
                "m/s^2",
                terms={"ag_m_s2": ag, "S": S, "q": q},
                ag_capacity_m_s2=ag * a0 / demand,
                source=f"{CHECK_SOURCES['linear, ground level']}; q = {q:g} ({Q_CLAUSE}); "
                f"S from {site.spectrum_clause.split(';')[0]}",
                demand_text=f"ag S / q = {ag:.4g} x {S:g} / {q:g} = {demand:.4g} m/s^2",
            )
        )
        if position.method == "circolare2009":
            checks.append(_ground_nonlinear_2009(kin, site))
        else:
            checks.append(_ground_nonlinear_2019(kin, site, position.xi_slv))
        return checks
    if position.method == "circolare2009":
        return [_height_check_2009(kin, site, position, q)]
    return height_checks_2019(kin, site, position, q)


def _ground_nonlinear_2009(kin: KinematicQuantities, site: AnySite) -> Check:
    """The superseded nonlinear check at ground level of Circolare 2009 C8A.4.2.3 (module docstring)."""
    ag, S = site.ag_m_s2, site.S
    name, inequality = "nonlinear, ground level (Circolare 2009)", "du* >= SDe(Ts)"
    if kin.du_star_m is None or kin.Ts_s is None:
        return _not_applicable(name, "du*", inequality, "m", f"no capacity curve to alpha = 0 ({kin.nonlinear_note})")
    if kin.Ts_s > 4.0:
        return _not_applicable(name, "du*", inequality, "m", f"Ts = {kin.Ts_s:.3g} s is beyond the spectrum's 4 s")
    sde = displacement_spectrum(site, kin.Ts_s)
    se = float(site.spectrum.psa([kin.Ts_s])[0])
    return _check(
        name,
        "du*",
        inequality,
        sde,
        kin.du_star_m,
        "m",
        terms={"Ts_s": kin.Ts_s, "Se_Ts_m_s2": se, "ag_m_s2": ag, "S": S},
        ag_capacity_m_s2=ag * kin.du_star_m / sde,
        source=f"{CHECK_SOURCES[name]}; {site.spectrum_clause}",
        demand_text=f"SDe(Ts = {kin.Ts_s:.4g} s, 5 %) = Se (Ts / 2 pi)^2 = {se:.4g} x "
        f"{(kin.Ts_s / (2 * math.pi)) ** 2:.4g} = {sde:.4g} m",
    )


def _slv_point(kin: KinematicQuantities) -> tuple[float, float, float] | str:
    """(d_SLV, a(d_SLV), T_SLV) on the capacity curve (Circolare 2019 C8.7.1.2.1.6, Eq C8.7.1.10), or
    why there is none (a reason for a check not made)."""
    curve = kin.spectral()
    if kin.du_star_m is None or curve is None:
        return f"no capacity curve to alpha = 0 ({kin.nonlinear_note})"
    d_slv = kin.du_star_m
    a_slv = float(np.interp(d_slv, curve[0], curve[1]))
    if a_slv <= 0.0:
        return "the capacity curve has no a > 0 at d_SLV"
    T_slv = secant_period(d_slv, a_slv)
    if T_slv > 4.0:
        return f"T_SLV = {T_slv:.3g} s is beyond the spectrum's 4 s"
    return d_slv, a_slv, T_slv


def _ground_nonlinear_2019(kin: KinematicQuantities, site: AnySite, xi: float) -> Check:
    """The nonlinear check at ground level of Circolare 2019 C8.7.1.2.1.8 (module docstring): d_SLV against the
    site's elastic displacement spectrum at T_SLV and the mechanism's damping ``xi``."""
    ag, S = site.ag_m_s2, site.S
    name, inequality = "nonlinear, ground level", "d_SLV >= SDe(T_SLV, xi)"
    point = _slv_point(kin)
    if isinstance(point, str):
        return _not_applicable(name, "d_SLV", inequality, "m", point)
    d_slv, a_slv, T_slv = point
    damped = dataclasses.replace(site.spectrum, damping=xi)
    se = float(damped.psa([T_slv])[0])
    factor = (T_slv / (2.0 * math.pi)) ** 2
    sde = se * factor
    return _check(
        name,
        "d_SLV",
        inequality,
        sde,
        d_slv,
        "m",
        terms={
            "T_SLV_s": T_slv,
            "a_SLV_m_s2": a_slv,
            "xi": xi,
            "eta": damping_correction(xi),
            "Se_TSLV_m_s2": se,
            "ag_m_s2": ag,
            "S": S,
        },
        ag_capacity_m_s2=ag * d_slv / sde,
        source=f"{CHECK_SOURCES[name]}; xi = {100 * xi:g} % (C8.7.1.2.1.8), eta(xi) = sqrt(10 / (5 + xi)) >= 0.55 "
        f"(NTC 2018 Eq 3.2.4; EN 1998-1 Eq 3.6); {site.spectrum_clause}",
        demand_text=f"SDe(T_SLV = {T_slv:.4g} s, {100 * xi:g} %) = Se (T_SLV / 2 pi)^2 = {se:.4g} x {factor:.4g} = "
        f"{sde:.4g} m (a(d_SLV) = {a_slv:.4g} m/s^2, eta = {damping_correction(xi):.4g})",
    )


def _height_check_2009(kin: KinematicQuantities, site: AnySite, position: Position, q: float) -> Check:
    """The superseded linear check at height of Circolare 2009 C8A.4.2.3 (module docstring)."""
    ag, S, a0 = site.ag_m_s2, site.S, kin.a0_star_m_s2
    T1 = position.period_s
    se_t1 = float(site.spectrum.psa([T1])[0])
    psi, gamma = position.psi, position.gamma
    demand = se_t1 * psi * gamma / q
    name = "linear, at height (Circolare 2009)"
    return _check(
        name,
        "a0*",
        "a0* >= Se(T1) psi(Z) gamma / q",
        demand,
        a0,
        "m/s^2",
        terms={"Se_T1_m_s2": se_t1, "T1_s": T1, "psi": psi, "gamma": gamma, "q": q, "ag_m_s2": ag, "S": S},
        ag_capacity_m_s2=ag * a0 / demand,
        source=f"{CHECK_SOURCES[name]}; psi(Z) = Z/H, gamma = 3N/(2N+1), q = {q:g} ({Q_CLAUSE}); "
        f"T1: {position.period_source}; Se from {site.spectrum_clause}",
        demand_text=f"Se(T1) psi gamma / q = {se_t1:.4g} x {psi:.4g} x {gamma:.4g} / {q:g} = {demand:.4g} m/s^2 "
        f"(T1 = {T1:.3g} s)",
    )


def height_checks_2019(kin: KinematicQuantities, site: AnySite, position: Position, q: float = Q_FACTOR) -> list[Check]:
    """The linear and nonlinear checks of a mechanism at height by Circolare 2019 C8.7.1 on the
    floor spectrum of C7.2.3 (module docstring)."""
    ag, a0 = site.ag_m_s2, kin.a0_star_m_s2
    floor = position.floor(site.spectrum)
    common = {"T1_s": floor.T1_s, "psi": floor.psi1, "gamma": floor.gamma1, "xi1": floor.building_damping}
    where = (
        f"T1: {position.period_source}; xi1 = {100 * floor.building_damping:g} %; psi(Z) = Z/H, gamma = 3N/(2N+1) "
        f"(Eq C7.2.10); Se from {site.spectrum_clause.split(';')[0]}"
    )
    T0 = position.T0_s
    sez_t0 = float(floor.psa([T0], SLD_DAMPING)[0])
    name = "linear, at height"
    linear = _check(
        name,
        "a0*",
        "a0* >= SeZ(T0) / q",
        sez_t0 / q,
        a0,
        "m/s^2",
        terms={**common, "a_Z_m_s2": floor.peak_m_s2, "T0_s": T0, "SeZ_T0_m_s2": sez_t0, "q": q, "ag_m_s2": ag},
        ag_capacity_m_s2=ag * a0 * q / sez_t0,
        source=f"{CHECK_SOURCES[name]}; q = {q:g}; T0 = {T0:g} s; {where}",
        demand_text=f"SeZ(T0 = {T0:g} s, 5 %) / q = {sez_t0:.4g} / {q:g} = {sez_t0 / q:.4g} m/s^2 (the floor's peak "
        f"a_Z = {floor.peak_m_s2:.4g} m/s^2, T1 = {floor.T1_s:.3g} s)",
    )
    name, inequality = "nonlinear, at height", "d_SLV >= SeZ(T_SLV, xi) T_SLV^2 / (4 pi^2)"
    point = _slv_point(kin)
    if isinstance(point, str):
        return [linear, _not_applicable(name, "d_SLV", inequality, "m", point)]
    d_slv, a_slv, T_slv = point
    xi = position.xi_slv
    demand, bound = displacement_demand(floor, T_slv, xi)
    sez = float(floor.psa([T_slv], xi)[0])
    floor_words = "" if math.isnan(bound) else f", not below SeZ(T1) (b T1 / 2 pi)^2 = {bound:.4g} m"
    nonlinear = _check(
        name,
        "d_SLV",
        inequality,
        demand,
        d_slv,
        "m",
        terms={**common, "a_SLV_m_s2": a_slv, "T_SLV_s": T_slv, "xi": xi, "SeZ_TSLV_m_s2": sez, "bound_m": bound},
        ag_capacity_m_s2=ag * d_slv / demand,
        source=f"{CHECK_SOURCES[name]}; xi = {100 * xi:g} %; {where}",
        demand_text=f"SeZ(T_SLV = {T_slv:.4g} s, {100 * xi:g} %) (T_SLV / 2 pi)^2 = {sez:.4g} x "
        f"{(T_slv / (2 * math.pi)) ** 2:.4g} = {float(floor.sde([T_slv], xi)[0]):.4g} m{floor_words} "
        f"(a(d_SLV) = {a_slv:.4g} m/s^2)",
    )
    return [linear, nonlinear]


def checks_not_made(
    kin: KinematicQuantities | None, position: Position, direction: str | None = None, crushing: bool = False
) -> list[str]:
    """The checks of the kinematic method this tool does not make, each with the reason (for
    the output's notes).

    Parameters
    ----------
    kin, position
        The governing mechanism's quantities, where it is.
    direction
        The one direction examined (``--direction``), or None for both.
    crushing
        Whether the masonry's compressive strength was taken at the hinges (``--fm``).
    """
    out = []
    if position.at_height and position.method == "circolare2009":
        out.append(
            "not made: the nonlinear check at height: the Circolare 2009 form asked for (--code-form "
            "circolare2009) has its linear check only here; the default, Circolare 2019 C8.7.1 with the floor "
            "spectra of C7.2.3, makes both"
        )
    elif position.at_height:
        out.append(
            "not made: the floor spectrum's higher modes and the building's own nonlinearity beyond T1 and xi1: the "
            "floor spectrum is the first mode's (Circolare 2019 C7.2.3: sufficient for local mechanisms in "
            "multi-storey buildings); give T1 and xi1 of the damaged building (--t1, --building-damping-pct) where "
            "it yields at the site's shaking (C7.2.3, C8.7.1.2.1.8)"
        )
    if kin is not None and kin.nonlinear_note and "slides" in kin.nonlinear_note:
        out.append(
            "not made: the nonlinear check of this mechanism, in which a joint slides: the code's nonlinear "
            "kinematic analysis follows rocking (hinged) mechanisms; the linear check stands alone"
        )
    out.append(
        "not made: a check of sliding mechanisms as such (the code's kinematic method is written for rocking "
        "mechanisms): the limit analysis lets joints slide, and where its mechanism slides with friction the "
        "quantities take the lower of the associated (dilatant) and the coulomb (non-dilatant) multipliers; the "
        "coulomb rule is an iterated heuristic, not a bound"
    )
    out.append(
        "not made: the damage limit state (SLD) and operational checks; only the life-safety checks (SLV) with the "
        "site's spectrum as given"
    )
    examined = (
        f"only the section's mechanism towards {direction} is examined (--direction {direction}): the other "
        "direction is not checked"
        if direction
        else "only the section's mechanisms towards +x and -x are examined"
    )
    if not crushing:
        out.append(
            "not made: the finite compressive strength of the masonry at the hinges (rigid blocks: each hinge at the "
            "edge of its joint), which lowers alpha0 (--fm MPa takes it)"
        )
    out.append(f"not made: mechanisms outside the scene's section (in-plane, corners, roof thrust): {examined}")
    return out


def verdict(checks: list[Check]) -> str:
    """``verified`` when a check that applies is met, ``not verified`` when none is,
    ``not applicable`` when none applies (module docstring)."""
    made = [c for c in checks if c.applies]
    if not made:
        return NOT_APPLICABLE
    return VERIFIED if any(c.status == VERIFIED for c in made) else NOT_VERIFIED


def code_capacity_ag(checks: list[Check]) -> float:
    """The largest ag at which a check that applies is met, m/s^2: the code's capacity in
    the site's shaking (NaN when none applies)."""
    values = [c.ag_capacity_m_s2 for c in checks if c.applies]
    return max(values) if values else math.nan
