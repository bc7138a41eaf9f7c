"""``rockyade verify``'s checks of a check an engineer can sign (issue 33): the loaded block's classical
parameters by hand (``loaded_classical``), Coulomb against associated friction on the restrained wall
(``code_friction``) and the masonry's crushing at the hinges against its closed form and as fm tends to
infinity (``crushing``); they run no solver but Housner's model and the limit analysis' programmes
(:mod:`rockyade.studies.verification` describes each)."""

from __future__ import annotations

import math

from rockyade.constants import G
from rockyade.result import Result
from rockyade.scene import Scene, scene_from_dict
from rockyade.scene.generators import rest_motion, stack, wall_section
from rockyade.studies.verify_rows import EXACT, Row, at_most, known, relative

#: The loaded wall of ``loaded_classical`` (docs/howto/is-this-wall-safe.md): thickness, height (m),
#: density (kg/m^3), the load per metre (N) and its offset from the axis towards +x (m).
TUFF_T, TUFF_H, TUFF_RHO, TUFF_N, TUFF_E = 0.45, 3.2, 1600.0, 12000.0, 0.125


def loaded_tuff_wall(motion: dict | None = None, duration_s: float = 1.0) -> Scene:
    """The 0.45 x 3.2 m tuff wall (a 1 m strip) with 12 kN/m at 0.125 m from its axis, with its mass."""
    return scene_from_dict(
        wall_section(
            height_m=TUFF_H,
            thickness_m=TUFF_T,
            density_kg_m3=TUFF_RHO,
            overburden_n_per_m=TUFF_N,
            overburden_eccentricity_m=TUFF_E,
            motion=motion or rest_motion(),
            duration_s=duration_s,
        )
    )


def check_loaded_classical(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The loaded wall's classical parameters, each direction its own, against the hand calculation:
    the body of the wall (m at (0, H/2)) and the load's mass (N/g at (e, H)); alpha = atan(lever / y_c)
    about each corner; mu from the angular momentum about the new pivot (Housner 1963 generalised);
    the uplift multiplier tan(alpha) = (W b + N d) / (W h_c + N h_N) of the limit analysis."""
    from rockyade.limit import limit_analysis
    from rockyade.scene.carried import loaded_classical

    scene = loaded_tuff_wall()
    cp = loaded_classical(scene, G)["w01"]
    m, m_n = TUFF_T * TUFF_H * TUFF_RHO, TUFF_N / G
    big = m + m_n
    xc, yc = m_n * TUFF_E / big, (m * TUFF_H / 2 + m_n * TUFF_H) / big
    i_c = (
        m * (TUFF_T**2 + TUFF_H**2) / 12
        + m * (xc**2 + (TUFF_H / 2 - yc) ** 2)
        + m_n * ((TUFF_E - xc) ** 2 + (TUFF_H - yc) ** 2)
    )
    right, left = (xc - TUFF_T / 2, yc), (xc + TUFF_T / 2, yc)  # centroid - pivot
    dot = right[0] * left[0] + right[1] * left[1]
    src = "hand calculation (docs/howto/is-this-wall-safe.md)"
    w = m * G
    rows = [
        Row(
            "loaded_classical",
            "classical",
            "alpha towards +x (rad)",
            cp.right.alpha_rad,
            math.atan2(-right[0], yc),
            src,
            relative(1e-12),
        ),
        Row(
            "loaded_classical",
            "classical",
            "alpha towards -x (rad)",
            cp.left.alpha_rad,
            math.atan2(left[0], yc),
            src,
            relative(1e-12),
        ),
        Row(
            "loaded_classical",
            "classical",
            "mu ending a half-cycle towards +x",
            cp.right.mu,
            (i_c + big * dot) / (i_c + big * (left[0] ** 2 + yc**2)),
            src,
            relative(1e-12),
        ),
        Row(
            "loaded_classical",
            "classical",
            "mu ending a half-cycle towards -x",
            cp.left.mu,
            (i_c + big * dot) / (i_c + big * (right[0] ** 2 + yc**2)),
            src,
            relative(1e-12),
        ),
    ]
    for turns, lever in (("+x", TUFF_T / 2 - TUFF_E), ("-x", TUFF_T / 2 + TUFF_E)):
        expected = (w * TUFF_T / 2 + TUFF_N * lever) / (w * TUFF_H / 2 + TUFF_N * TUFF_H)
        uplift = cp.pivot(turns).uplift_accel_m_s2 / G
        lam = known(limit_analysis(scene, turns, nonlinear=False).load_multiplier, "load multiplier")
        what = "(W b + N d) / (W h_c + N h_N)"
        rows.append(
            Row(
                "loaded_classical",
                "classical",
                f"uplift lambda towards {turns}",
                uplift,
                expected,
                what,
                relative(1e-12),
            )
        )
        rows.append(Row("loaded_classical", "limit", f"lambda towards {turns}", lam, expected, what, relative(1e-9)))
    return rows, {}


def corner_friction_wall(corner_friction_deg: float = 35.0) -> Scene:
    """The 8-course tuff wall (2.4 x 0.36 m, 1600 kg/m^3, joints at 35 degrees) restrained on the far face
    of its top course, a roof of 6 kN/m at 0.05 m without mass, the restraint's contact with the top
    corner of the course below (w07) at ``corner_friction_deg``, the top course's face frictionless
    (examples/tuff_wall_restrained_corner.toml)."""
    data = wall_section(
        height_m=2.4,
        thickness_m=0.36,
        courses=8,
        top="restrained-far",
        overburden_n_per_m=6000.0,
        overburden_eccentricity_m=0.05,
        density_kg_m3=1600.0,
        contact={"calibration": "paper", "friction_angle_deg": 35.0},
        motion=rest_motion(),
    )
    data["loads"] = [{**q, "mass_kg": 0.0} for q in data["loads"]]
    data["joints"] = [
        {**j, "friction_angle_deg": corner_friction_deg} if "w07" in j["blocks"] else j for j in data["joints"]
    ]
    return scene_from_dict(data)


def squeezed_top() -> float:
    """The restrained wall's multiplier towards its restraint with the corner frictionless (tests/test_restraints.py):
    the seven lower courses turn about the toe and the top course (W_c = 1600 g 0.36 0.3 a course) and the roof
    (N = 6000 N, without mass) rise t + 2.1 tan 35: (W_L t/2 + (W_c + N)(t + 2.1 tan 35)) / (W_L 1.05), W_L = 7 W_c."""
    wc = 1600.0 * G * 0.36 * 0.3
    return (7 * wc * 0.18 + (wc + 6000.0) * (0.36 + 2.1 * math.tan(math.radians(35.0)))) / (7 * wc * 1.05)


def check_code_friction(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The restrained wall towards its restraint: with the corner frictionless both rules give the
    closed form (W_L t/2 + (W_c + N)(t + 2.1 tan 35)) / (W_L 1.05) = 1.3019 (tests/test_restraints.py);
    with it at 35 degrees the coulomb multiplier lies below the associated one and the code takes it."""
    from rockyade.limit import limit_analysis

    closed = squeezed_top()
    free = limit_analysis(corner_friction_wall(0.0), "+x", coulomb_check=True, nonlinear=False)
    rough = limit_analysis(corner_friction_wall(35.0), "+x", coulomb_check=True, nonlinear=False)
    if rough.friction_check is None or rough.load_multiplier is None:
        raise RuntimeError("the associated mechanism of the restrained wall does not slide with friction")
    coulomb = known(rough.friction_check.coulomb_multiplier, "coulomb multiplier")
    code = known(rough.for_code.load_multiplier, "code multiplier")
    closed_src = "(W_L t/2 + (W_c + N)(t + 2.1 tan 35)) / (W_L 1.05)"
    rows = [
        Row(
            "code_friction",
            "limit",
            f"frictionless corner: {what} lambda",
            known(lam, "lambda"),
            closed,
            closed_src,
            relative(1e-9),
        )
        for what, lam in (("associated", free.load_multiplier), ("the code's", free.for_code.load_multiplier))
    ]
    return [
        *rows,
        Row(
            "code_friction",
            "limit",
            "35 deg corner: coulomb lambda (<= associated)",
            coulomb,
            rough.load_multiplier,
            "the associated multiplier (an upper bound where joints slide)",
            at_most(),
        ),
        Row(
            "code_friction",
            "limit",
            "35 deg corner: coulomb lambda, measured",
            coulomb,
            1.6205,
            "issue 33 (1.6205; associated 3.5891)",
            relative(5e-5),
        ),
        Row(
            "code_friction",
            "limit",
            "35 deg corner: the code's lambda = the lower",
            code,
            min(coulomb, rough.load_multiplier),
            "min(associated, coulomb)",
            EXACT,
        ),
    ], {}


def check_crushing(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """A block 0.25 x 2.5 m (1800 kg/m^3, 1 m deep) with the hinge moved by the stress block,
    lambda = (B - a) / H with a = W / (0.85 fm t), at fm = 1 MPa; and as fm tends to infinity (1e6 MPa)
    the rigid multiplier, of the block and of a 6-course stack."""
    from rockyade.limit import limit_analysis

    block = scene_from_dict(stack(widths_m=[0.25], heights_m=2.5, thickness_m=1.0, density_kg_m3=1800.0))
    weight = 1800.0 * 0.25 * 2.5 * G
    expected = (0.25 - weight / (0.85 * 1.0e6)) / 2.5
    lam = known(limit_analysis(block, "+x", fm_MPa=1.0).load_multiplier, "lambda")
    courses = scene_from_dict(stack(widths_m=[0.5] * 6, heights_m=0.4, thickness_m=1.0, density_kg_m3=1800.0))
    rows = [
        Row(
            "crushing",
            "limit",
            "block, fm = 1 MPa: lambda",
            lam,
            expected,
            "(B - a) / H, a = W / (0.85 fm t)",
            relative(1e-9),
        )
    ]
    for name, scene in (("block", block), ("6 courses", courses)):
        rigid = known(limit_analysis(scene, "+x").load_multiplier, "lambda")
        far = known(limit_analysis(scene, "+x", fm_MPa=1.0e6).load_multiplier, "lambda")
        rows.append(
            Row(
                "crushing",
                "limit",
                f"{name}, fm = 1e6 MPa: lambda",
                far,
                rigid,
                "the rigid blocks' lambda",
                relative(1e-6),
            )
        )
    return rows, {}
