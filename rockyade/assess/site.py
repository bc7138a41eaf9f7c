"""The site and the place of a mechanism in its building: what the code's demand depends on.

The site's elastic spectrum is either

* NTC 2018's (:class:`NtcSite`, Section 3.2.3.2.1, :mod:`rockyade.motion.ntc2018`): the
  site's ag, F0 and TC* for the limit state's return period (NTC 2018 Allegato A), the
  subsoil category A-E (SS, CC of Tab. 3.2.IV) and the topographic category T1-T4 (ST of
  Tab. 3.2.V); what an Italian verdict uses; or
* EN 1998-1's (:class:`Site`, Section 3.2.2.2, :mod:`rockyade.motion.ec8`): a spectrum type
  (1 or 2), a ground type (A-E) and the design ground acceleration on type A ground
  ag = gamma_I agR (EN 1998-1 3.2.1(3): agR the reference peak ground acceleration, gamma_I
  the importance factor).

One g everywhere in the check: an acceleration given in g (``0.25g``, the site's ag/g) is
turned into m/s^2 with standard gravity, 9.80665 m/s^2 (:data:`rockyade.constants.CODE_GRAVITY`,
the g of records in g), the same g that turns the multiplier alpha0 into a0* = alpha0 g / (e* FC):
the check a0* >= ag S / q is then alpha0 / (e* FC) >= (ag/g) S / q whatever the value of g.

A mechanism sits at ground level (the default) or at a height Z of a building of height H,
N storeys and fundamental period T1 (the demand is then the floor's: Circolare 2019
C8.7.1, with the floor spectrum of C7.2.3, :mod:`rockyade.assess.floor_spectra`). The checks
take the form of Circolare 2019 C8.7.1.2.1 at ground level and at height (the default), or
the superseded form of Circolare 2009 C8A.4.2.3 when asked for by name (``code_form``). Without a given T1 it is the
code's simplified estimate T1 = Ct H^(3/4) with Ct = 0.05 (EN 1998-1 4.3.3.2.2(3), Eq 4.6,
"all other structures", buildings up to 40 m; NTC 2008 7.3.3.2, Eq 7.3.5 gives the same
C1 = 0.050).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from rockyade.assess.floor_spectra import BUILDING_DAMPING, SLV_DAMPING, FloorSpectrum, check_damping
from rockyade.constants import CODE_GRAVITY as G
from rockyade.errors import InputError
from rockyade.motion.ec8 import EC8_GROUND, ElasticSpectrum
from rockyade.motion.ntc2018 import NtcSpectrum, ntc_spectrum, soil_factors, topography_factor

#: Largest design ground acceleration accepted, in g: above it the number is a typing error.
MAX_AG_G = 1.0
#: Range of the importance factor gamma_I (EN 1998-1 4.2.5: 0.8 to 1.4 for classes I-IV).
IMPORTANCE_RANGE = (0.5, 2.0)
#: Ct of the simplified period T1 = Ct H^(3/4) (EN 1998-1 Eq 4.6).
CT_MASONRY = 0.05
#: The simplified period holds for buildings up to this height, m (EN 1998-1 4.3.3.2.2(3)).
MAX_T1_FORMULA_HEIGHT_M = 40.0
#: Largest building height and storey count accepted.
MAX_BUILDING_HEIGHT_M = 300.0
MAX_STOREYS = 100
#: The forms of the checks: Circolare 2019 C8.7.1.2.1 (the default; at height on the floor
#: spectra of C7.2.3), or the superseded Circolare 2009 C8A.4.2.3 form, asked for by name.
CODE_FORMS = ("circolare2019", "circolare2009")
#: Largest mechanism period T0 accepted, s (the spectra are used up to 4 s).
MAX_MECHANISM_PERIOD_S = 4.0

_ACCEL = re.compile(r"^\s*([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(g|m/s2|m/s\^2|m/s\*\*2)\s*$")


def parse_acceleration(text: str | float, field: str = "--ag", max_g: float = MAX_AG_G) -> float:
    """An acceleration given with its unit, ``"0.25g"`` or ``"2.45m/s2"``, in m/s^2.

    Parameters
    ----------
    text
        The value and its unit (``g``, taken as standard gravity 9.80665 m/s^2 as the code check's g, or ``m/s2``);
        a bare number is refused (0.25 would be 0.25 m/s^2 or 0.25 g).
    field
        The option named in errors.
    max_g
        Largest value accepted, in g.

    Raises
    ------
    InputError
        No unit, not a number, <= 0 or above ``max_g``.
    """
    match = _ACCEL.match(str(text))
    if match is None:
        raise InputError(
            field,
            f"must be an acceleration with its unit, e.g. 0.25g or 2.45m/s2 (in (0, {max_g:g}] g), got {text!r}",
        )
    value = float(match.group(1)) * (G if match.group(2) == "g" else 1.0)
    if not (math.isfinite(value) and 0.0 < value <= max_g * G):
        raise InputError(field, f"must be in (0, {max_g:g}] g (0 to {max_g * G:.4g} m/s^2), got {text!r}")
    return value


@dataclass(frozen=True)
class Site:
    """The site's elastic spectrum of EN 1998-1 (3.2.2.2).

    Attributes
    ----------
    spectrum_type
        1 or 2 (EN 1998-1 3.2.2.2(2)).
    ground
        Ground type A-E (Table 3.1).
    agR_m_s2
        Reference peak ground acceleration on type A ground, m/s^2.
    importance
        Importance factor gamma_I.
    """

    spectrum_type: int
    ground: str
    agR_m_s2: float
    importance: float = 1.0

    def __post_init__(self) -> None:
        if self.spectrum_type not in EC8_GROUND:
            raise InputError("--spectrum-type", f"must be 1 or 2 (EN 1998-1 3.2.2.2), got {self.spectrum_type!r}")
        ground = str(self.ground).upper()
        if ground not in EC8_GROUND[1]:
            raise InputError("--ground", f"must be one of A, B, C, D, E (EN 1998-1 Table 3.1), got {self.ground!r}")
        object.__setattr__(self, "ground", ground)
        ag = self.agR_m_s2
        if not (isinstance(ag, (int, float)) and math.isfinite(ag) and 0.0 < ag <= MAX_AG_G * G):
            raise InputError("--ag", f"must be in (0, {MAX_AG_G:g}] g, got {ag!r} m/s^2")
        lo, hi = IMPORTANCE_RANGE
        gi = self.importance
        if isinstance(gi, bool) or not (isinstance(gi, (int, float)) and math.isfinite(gi) and lo <= gi <= hi):
            raise InputError("--importance", f"must be in [{lo:g}, {hi:g}] (gamma_I, EN 1998-1 4.2.5), got {gi!r}")
        if self.ag_m_s2 > MAX_AG_G * G:
            raise InputError("--importance", f"gamma_I agR = {self.ag_m_s2 / G:.3g} g is above {MAX_AG_G:g} g")

    @property
    def ag_m_s2(self) -> float:
        """Design ground acceleration ag = gamma_I agR, m/s^2."""
        return self.importance * self.agR_m_s2

    @property
    def spectrum(self) -> ElasticSpectrum:
        """The 5 % damped elastic spectrum at ag."""
        return ElasticSpectrum.ec8(self.spectrum_type, self.ground, ag_m_s2=self.ag_m_s2)

    @property
    def S(self) -> float:
        """Soil factor S (EN 1998-1 Tables 3.2, 3.3)."""
        return EC8_GROUND[self.spectrum_type][self.ground][0]

    def describe(self) -> str:
        """One line: type, ground, ag, gamma_I, S."""
        gi = f" x gamma_I {self.importance:g}" if self.importance != 1.0 else ""
        return (
            f"EC8 Type {self.spectrum_type} spectrum, ground {self.ground} (S = {self.S:g}), "
            f"ag = {self.ag_m_s2 / G:.4g} g{gi} ({self.ag_m_s2:.4g} m/s^2)"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: the inputs and the spectrum's parameters."""
        return {
            "spectrum_type": self.spectrum_type,
            "ground": self.ground,
            "agR_m_s2": self.agR_m_s2,
            "importance_factor": self.importance,
            "ag_m_s2": self.ag_m_s2,
            "ag_g": self.ag_m_s2 / G,
            "spectrum": self.spectrum.as_dict(),
            "source": "EN 1998-1 3.2.2.2 (Eqs 3.2-3.5, Tables 3.2 and 3.3); ag = gamma_I agR (3.2.1(3))",
            "spectrum_code": self.spectrum_code,
        }

    @property
    def spectrum_code(self) -> str:
        """Whose spectrum: ``ec8``."""
        return "ec8"

    @property
    def spectrum_clause(self) -> str:
        """The clause of the spectrum and of SDe (for the checks' sources)."""
        return "EN 1998-1 3.2.2.2 (Eqs 3.2-3.5); SDe(T) = Se(T) (T / 2 pi)^2, Eq 3.7"


@dataclass(frozen=True)
class NtcSite:
    """The site's elastic spectrum of NTC 2018 (3.2.3.2.1; module docstring).

    Attributes
    ----------
    ag_g
        ag on type A ground for the limit state's return period, in g (Allegato A).
    F0
        Maximum spectral amplification (Allegato A).
    tc_star_s
        TC*, s (Allegato A).
    soil
        Subsoil category A-E (Tab. 3.2.II).
    topography
        Topographic category T1-T4 (Tab. 3.2.III).
    height_ratio
        Height of the site above the base of the relief over the relief's height (1: at the
        top, where ST is Tab. 3.2.V's value).
    """

    ag_g: float
    F0: float
    tc_star_s: float
    soil: str = "A"
    topography: str = "T1"
    height_ratio: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "soil", str(self.soil).upper())
        object.__setattr__(self, "topography", str(self.topography).upper())
        self.spectrum  # noqa: B018 -- validates every parameter now, naming the option

    @property
    def ag_m_s2(self) -> float:
        """ag, m/s^2 (ag/g x 9.80665, standard gravity)."""
        return self.ag_g * G

    @property
    def spectrum(self) -> NtcSpectrum:
        """The 5 % damped elastic spectrum (NTC 2018 Eqs 3.2.2)."""
        return ntc_spectrum(self.ag_g, self.F0, self.tc_star_s, self.soil, self.topography, self.height_ratio, g=G)

    @property
    def SS(self) -> float:
        """Stratigraphic amplification SS (Tab. 3.2.IV)."""
        return soil_factors(self.soil, self.ag_g, self.F0, self.tc_star_s)[0]

    @property
    def CC(self) -> float:
        """The coefficient of TC = CC TC* (Tab. 3.2.IV)."""
        return soil_factors(self.soil, self.ag_g, self.F0, self.tc_star_s)[1]

    @property
    def ST(self) -> float:
        """Topographic amplification ST (Tab. 3.2.V, at ``height_ratio``)."""
        return topography_factor(self.topography, self.height_ratio)

    @property
    def S(self) -> float:
        """S = SS ST (NTC 2018 3.2.3.2.1)."""
        return self.SS * self.ST

    @property
    def spectrum_code(self) -> str:
        """Whose spectrum: ``ntc2018``."""
        return "ntc2018"

    @property
    def spectrum_clause(self) -> str:
        """The clause of the spectrum and of SDe (for the checks' sources)."""
        return "NTC 2018 3.2.3.2.1 (Eqs 3.2.2); SDe(T) = Se(T) (T / 2 pi)^2, NTC 2018 3.2.3.2.3 Eq 3.2.12"

    def describe(self) -> str:
        """One line: the site's parameters and the spectrum's."""
        sp = self.spectrum
        ratio = f" at {self.height_ratio:g} of the relief's height" if self.topography != "T1" else ""
        return (
            f"NTC 2018 spectrum (3.2.3.2.1): ag = {self.ag_g:.4g} g ({self.ag_m_s2:.4g} m/s^2), F0 = {self.F0:g}, "
            f"TC* = {self.tc_star_s:g} s; soil {self.soil} (SS = {self.SS:.4g}, CC = {self.CC:.5g}), "
            f"topography {self.topography}"
            f"{ratio} (ST = {self.ST:.4g}): S = {self.S:.4g}, TB = {sp.TB_s:.4g} s, TC = {sp.TC_s:.4g} s, "
            f"TD = {sp.TD_s:.4g} s"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: the inputs and the spectrum's parameters."""
        return {
            "spectrum_code": self.spectrum_code,
            "ag_g": self.ag_g,
            "ag_m_s2": self.ag_m_s2,
            "F0": self.F0,
            "TC_star_s": self.tc_star_s,
            "soil": self.soil,
            "SS": self.SS,
            "CC": self.CC,
            "topography": self.topography,
            "topography_height_ratio": self.height_ratio,
            "ST": self.ST,
            "S": self.S,
            "spectrum": self.spectrum.as_dict(),
            "source": "NTC 2018 3.2.3.2.1 (Eqs 3.2.2-3.2.7, Tabs 3.2.IV and 3.2.V); ag, F0, TC* of the site from "
            "Allegato A for the limit state's return period",
        }


#: Either site (the checks read ``ag_m_s2``, ``S``, ``spectrum`` and ``spectrum_clause``).
AnySite = Site | NtcSite


@dataclass(frozen=True)
class Position:
    """Where the mechanism is: at ground level, or at a height of a building.

    Attributes
    ----------
    z_m
        Height above the foundation of the mechanism (the centroid of the weights that
        move, Circolare 2019 C8.7.1), m; None: at ground level.
    building_height_m
        Height H of the building, m.
    storeys
        Number of storeys N.
    T1_s
        Fundamental period of the building, s (None: the simplified formula, module docstring).
    code_form
        ``circolare2019`` (None: the default) or ``circolare2009`` (:data:`CODE_FORMS`), at ground
        level and at height.
    building_damping
        The building's equivalent viscous damping xi1 of the floor spectrum, a ratio (None: 5 %).
    mechanism_period_s
        The mechanism's period T0 in the linear check, s (None: 0, a mechanism rigid until it
        moves, whose demand is the floor's peak acceleration; Circolare 2019 C8.7.1.2.1.5).
    mechanism_damping
        The mechanism's equivalent damping in the nonlinear check of the 2019 form, at ground level
        and at height, a ratio (None: 8 %, Circolare 2019 C8.7.1.2.1.8).
    """

    z_m: float | None = None
    building_height_m: float | None = None
    storeys: int | None = None
    T1_s: float | None = None
    code_form: str | None = None
    building_damping: float | None = None
    mechanism_period_s: float | None = None
    mechanism_damping: float | None = None

    def __post_init__(self) -> None:
        given = [v is not None for v in (self.z_m, self.building_height_m, self.storeys)]
        if any(given) and not all(given):
            raise InputError("--z", "a mechanism at height needs --z, --building-height and --storeys together")
        height_only = {
            "--t1": self.T1_s,
            "--building-damping-pct": self.building_damping,
            "--mechanism-period": self.mechanism_period_s,
        }
        for option, value in height_only.items():
            if value is not None and self.z_m is None:
                raise InputError(option, "applies to a mechanism at height (with --z, --building-height, --storeys)")
        self._check_form_options()
        if self.z_m is None:
            return
        H = self.building_height_m
        if not (isinstance(H, (int, float)) and math.isfinite(H) and 0.0 < H <= MAX_BUILDING_HEIGHT_M):
            raise InputError("--building-height", f"must be in (0, {MAX_BUILDING_HEIGHT_M:g}] m, got {H!r}")
        z = self.z_m
        if not (isinstance(z, (int, float)) and math.isfinite(z) and 0.0 < z <= H):
            raise InputError("--z", f"must be in (0, H] with H = {H:g} m (--building-height), got {z!r}")
        n = self.storeys
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_STOREYS:
            raise InputError("--storeys", f"must be an integer in [1, {MAX_STOREYS}], got {n!r}")
        t1 = self.T1_s
        if t1 is not None and not (isinstance(t1, (int, float)) and math.isfinite(t1) and 0.0 < t1 <= 4.0):
            raise InputError("--t1", f"must be in (0, 4] s (the spectra are taken up to 4 s), got {t1!r}")

    def _check_form_options(self) -> None:
        """The form of the checks, the options of the 2019 form, and none of them with the 2009 form."""
        if self.code_form is not None and self.code_form not in CODE_FORMS:
            raise InputError("--code-form", f"must be one of {', '.join(CODE_FORMS)}, got {self.code_form!r}")
        form_2019_only = {
            "--building-damping-pct": self.building_damping,
            "--mechanism-period": self.mechanism_period_s,
            "--mechanism-damping-pct": self.mechanism_damping,
        }
        if self.method == "circolare2009":
            for option, value in form_2019_only.items():
                if value is not None:
                    raise InputError(option, "is an input of the Circolare 2019 form, not of --code-form circolare2009")
        for option, value in (
            ("--building-damping-pct", self.building_damping),
            ("--mechanism-damping-pct", self.mechanism_damping),
        ):
            if value is not None:
                check_damping(value, option)
        t0 = self.mechanism_period_s
        if t0 is not None and not (
            isinstance(t0, (int, float)) and math.isfinite(t0) and 0.0 <= t0 <= MAX_MECHANISM_PERIOD_S
        ):
            raise InputError("--mechanism-period", f"must be in [0, {MAX_MECHANISM_PERIOD_S:g}] s, got {t0!r}")

    def floor(self, spectrum: ElasticSpectrum) -> FloorSpectrum:
        """The floor spectrum at this height over the site's ``spectrum`` (Circolare 2019 C7.2.3,
        first mode: gamma, psi, T1, xi1 of this position)."""
        return FloorSpectrum(spectrum, self.period_s, self.gamma, self.psi, self.xi1)

    @property
    def method(self) -> str:
        """The form of the checks: ``circolare2019`` unless ``circolare2009`` was asked for."""
        return self.code_form or CODE_FORMS[0]

    @property
    def xi1(self) -> float:
        """The building's damping of the floor spectrum, a ratio (5 % unless given)."""
        return BUILDING_DAMPING if self.building_damping is None else float(self.building_damping)

    @property
    def T0_s(self) -> float:
        """The mechanism's period in the linear check, s (0 unless given)."""
        return 0.0 if self.mechanism_period_s is None else float(self.mechanism_period_s)

    @property
    def xi_slv(self) -> float:
        """The mechanism's damping in the nonlinear check, a ratio (8 % unless given)."""
        return SLV_DAMPING if self.mechanism_damping is None else float(self.mechanism_damping)

    @property
    def at_height(self) -> bool:
        """True for a mechanism at a height of a building."""
        return self.z_m is not None

    @property
    def psi(self) -> float:
        """psi(Z) = Z / H (Circolare 2009 C8A.4.2.3; Circolare 2019 C7.2.3: the linear first mode, normalised at
        the top)."""
        assert self.z_m is not None and self.building_height_m is not None
        return self.z_m / self.building_height_m

    @property
    def gamma(self) -> float:
        """gamma = 3 N / (2 N + 1), the modal participation factor (Circolare 2019 Eq C7.2.10)."""
        assert self.storeys is not None
        return 3.0 * self.storeys / (2.0 * self.storeys + 1.0)

    @property
    def period_s(self) -> float:
        """T1, s: given, or Ct H^(3/4) (module docstring)."""
        if self.T1_s is not None:
            return float(self.T1_s)
        assert self.building_height_m is not None
        return CT_MASONRY * self.building_height_m**0.75

    @property
    def period_source(self) -> str:
        """Where T1 comes from."""
        if self.T1_s is not None:
            return "given (--t1)"
        source = f"T1 = Ct H^(3/4), Ct = {CT_MASONRY:g} (EN 1998-1 4.3.3.2.2(3), Eq 4.6; NTC 2008 7.3.3.2, Eq 7.3.5)"
        if self.building_height_m is not None and self.building_height_m > MAX_T1_FORMULA_HEIGHT_M:
            source += f"; note: the formula is for buildings up to {MAX_T1_FORMULA_HEIGHT_M:g} m"
        return source

    def describe(self) -> str:
        """One line."""
        if not self.at_height:
            form = (
                "Circolare 2009 C8A.4.2.3 form (--code-form circolare2009)"
                if self.method == "circolare2009"
                else f"Circolare 2019 C8.7.1.2.1 form, mechanism's xi = {100 * self.xi_slv:g} % in the nonlinear check"
            )
            return f"at ground level ({form})"
        form = (
            "Circolare 2009 C8A.4.2.3 form (--code-form circolare2009)"
            if self.method == "circolare2009"
            else f"Circolare 2019 floor spectrum, xi1 = {100 * self.xi1:g} %, T0 = {self.T0_s:g} s, mechanism's "
            f"xi = {100 * self.xi_slv:g} % in the nonlinear check"
        )
        return (
            f"at Z = {self.z_m:g} m of a {self.building_height_m:g} m building of {self.storeys} storeys "
            f"(psi = Z/H = {self.psi:.4g}, gamma = 3N/(2N+1) = {self.gamma:.4g}, T1 = {self.period_s:.4g} s: "
            f"{self.period_source}; {form})"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready."""
        damping = {} if self.method == "circolare2009" else {"mechanism_damping_nonlinear": self.xi_slv}
        if not self.at_height:
            return {"at": "ground level", "code_form": self.method, **damping}
        return {
            "at": "height",
            "z_m": self.z_m,
            "building_height_m": self.building_height_m,
            "storeys": self.storeys,
            "psi": self.psi,
            "gamma": self.gamma,
            "T1_s": self.period_s,
            "T1_source": self.period_source,
            "code_form": self.method,
            **(
                {}
                if self.method == "circolare2009"
                else {"building_damping": self.xi1, "mechanism_period_s": self.T0_s, **damping}
            ),
        }
