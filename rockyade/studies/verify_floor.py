"""``rockyade verify``'s check of a mechanism at height (Circolare 2019 C8.7.1 on the floor
spectrum of C7.2.3): the worked example of docs/howto/is-this-wall-safe.md ("A mechanism at
height"), every number against the hand calculation printed there; and the same wall at ground
level, whose nonlinear check (Circolare 2019 C8.7.1.2.1.8: the site's SDe at T_SLV and 8 %) gives
the number the floor spectrum gives at height, where the ground's spectrum governs (C7.2.5).

The wall: tuff 2.4 m x 0.36 m, 1600 kg/m^3, a roof of 6 kN/m at 0.05 m from its axis with its
mass; at Z = 7 m of a 10 m building of 3 storeys, T1 = 0.3 s, xi1 = 5 %; the site: ag = 0.2 g,
F0 = 2.4, TC* = 0.3 s, soil B. No published worked example of the 2019 floor spectra for a local
mechanism was found to check against (the report of the work that added this check lists the
searches); the hand calculation is the reference.
"""

from __future__ import annotations

from rockyade.constants import CODE_GRAVITY
from rockyade.result import Result
from rockyade.studies.verify_rows import Row, known, relative

#: The hand calculation's numbers (docs/howto/is-this-wall-safe.md, "A mechanism at height").
HAND = {
    "a_Z_m_s2": 5.1091,  # Se(T1) gamma psi sqrt(1 + 0.0004 x 25) = 5.6486 x 9/7 x 0.7 x 1.00499
    "linear_demand_m_s2": 2.5546,  # a_Z / q
    "a_SLV_m_s2": 0.51288,  # alpha(theta = 0.041924 rad) g / (e* FC)
    "T_SLV_s": 2.0057,  # 1.68 pi sqrt(0.074068 / 0.51288)
    "nonlinear_demand_m": 0.10567,  # Se(T_SLV, 8 %) (T_SLV / 2 pi)^2 (C7.2.5's floor governs)
    "floor_m": 0.060807,  # A a_Z (b T1 / 2 pi)^2, Eq C8.7.1.12's lower bound
    "capacity_ag_g": 0.14018,  # 0.2 g x 0.074068 / 0.10567
    "ground_nonlinear_demand_m": 0.10567,  # at ground level: Se(T_SLV, 8 %) (T_SLV / 2 pi)^2, the same number
    "ground_nonlinear_ag_g": 0.14018,  # 0.2 g x 0.074068 / 0.10567
    "ground_nonlinear_2009_m": 0.0766,  # the 2009 form: Se(Ts = 1.275 s, 5 %) (Ts / 2 pi)^2 = 1.860 x 0.04118
}
SOURCE = "hand calculation (docs/howto/is-this-wall-safe.md, a mechanism at height)"


def check_floor_spectrum(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The checks at height of the how-to's wall against its hand calculation (module docstring)."""
    from rockyade.assess import Position
    from rockyade.assess.code import code_capacity_ag, code_checks
    from rockyade.assess.site import NtcSite
    from rockyade.limit import limit_analysis
    from rockyade.scene import scene_from_dict
    from rockyade.scene.generators import rest_motion
    from rockyade.scene.generators.wall_sections import wall_section

    wall = wall_section(
        height_m=2.4,
        thickness_m=0.36,
        overburden_n_per_m=6000.0,
        overburden_eccentricity_m=0.05,
        density_kg_m3=1600.0,
        motion=rest_motion(),
    )
    kin = limit_analysis(scene_from_dict(wall), "+x", fc=1.35).kinematic
    assert kin is not None
    site = NtcSite(0.2, 2.4, 0.3, "B")
    checks = code_checks(kin, site, Position(7.0, 10.0, 3, T1_s=0.3))
    linear, nonlinear = checks
    _, ground = code_checks(kin, site, Position())
    _, ground_2009 = code_checks(kin, site, Position(code_form="circolare2009"))
    values = {
        "a_Z_m_s2": linear.terms["a_Z_m_s2"],
        "linear_demand_m_s2": linear.demand,
        "a_SLV_m_s2": known(nonlinear.terms.get("a_SLV_m_s2"), "a(d_SLV)"),
        "T_SLV_s": known(nonlinear.terms.get("T_SLV_s"), "T_SLV"),
        "nonlinear_demand_m": nonlinear.demand,
        "floor_m": nonlinear.terms["bound_m"],
        "capacity_ag_g": code_capacity_ag(checks) / CODE_GRAVITY,
        "ground_nonlinear_demand_m": ground.demand,
        "ground_nonlinear_ag_g": ground.ag_capacity_m_s2 / CODE_GRAVITY,
        "ground_nonlinear_2009_m": ground_2009.demand,
    }
    words = {
        "a_Z_m_s2": "floor's peak a_Z (C7.2.7) (m/s^2)",
        "linear_demand_m_s2": "linear demand a_Z / q (m/s^2)",
        "a_SLV_m_s2": "a(d_SLV) on the capacity curve (m/s^2)",
        "T_SLV_s": "T_SLV = 1.68 pi sqrt(d_SLV / a(d_SLV)) (C8.7.1.10) (s)",
        "nonlinear_demand_m": "nonlinear demand SeZ(T_SLV, 8 %) T_SLV^2 / 4 pi^2 (C8.7.1.12) (m)",
        "floor_m": "C8.7.1.12's floor SeZ(T1) (b T1)^2 / 4 pi^2 (m)",
        "capacity_ag_g": "code capacity ag (g)",
        "ground_nonlinear_demand_m": "at ground level: nonlinear demand SDe(T_SLV, 8 %) (C8.7.1.2.1.8) (m)",
        "ground_nonlinear_ag_g": "at ground level: the nonlinear check's ag (g)",
        "ground_nonlinear_2009_m": "at ground level, the 2009 form: SDe(Ts, 5 %) (C8A.4.2.3) (m)",
    }
    tolerance = {"ground_nonlinear_2009_m": relative(1e-3)}  # the how-to prints 0.0766 m
    rows = [
        Row("floor_spectrum", "assess", words[k], values[k], HAND[k], SOURCE, tolerance.get(k, relative(2e-4)))
        for k in HAND
    ]
    return rows, {}
