"""DEM parameters from classical parameters (paper Eqs 6-15) against the printed numbers."""

from __future__ import annotations

import math

import pytest

from rockyade import paper
from rockyade.blocks.classical import classical_parameters
from rockyade.calibration.equations import (
    equivalent_half_base_eq11,
    generalized_damping_factor_eq12,
    paper_calibration,
    rayleigh_constants_eq6,
    stiffness_damping_eq13,
    stiffness_eq8,
    stiffness_eq9,
    stiffness_eq10,
    xi_min_eq15,
)
from rockyade.constants import G
from rockyade.dem.model import time_step_eq7
from rockyade.errors import CalibrationError, InputError


def test_equations_on_specimen1_experimental():
    spec = paper.specimen(1)
    e = spec.experimental
    M, R, h = spec.mass_kg, math.hypot(0.125, 0.5), 0.5
    k1 = stiffness_eq8(M, e["p_rad_s"])
    k2 = stiffness_eq9(M, R)
    assert k1 == M * 3.84**2
    assert k2 == pytest.approx(M * 3 * G / (4 * R))
    k = stiffness_eq10(k1, k2)
    assert k == pytest.approx(M / 2 * (3.84**2 + 3 * G / (4 * R)))
    gamma = generalized_damping_factor_eq12(k, R)
    assert gamma == pytest.approx(M / 2 * (R * 3.84**2 + 0.75 * G), rel=1e-12)  # Eq 12, 2nd form
    b = stiffness_damping_eq13(gamma, e["mu"])
    assert math.sqrt(b) == pytest.approx(0.0057 * math.log(gamma / e["mu"] ** 2) - 0.0336)
    assert b == pytest.approx(1.98e-4, rel=2e-3)  # DESIGN.md: Eq 13's beta = 1.98e-4 s
    assert equivalent_half_base_eq11(h, e["alpha_rad"]) * 2 == pytest.approx(0.24, abs=0.005)  # Table 5
    assert xi_min_eq15(b, 3.84) == pytest.approx(2 * math.pi * b * 3.84)
    a_r, b_r = rayleigh_constants_eq6(xi_min_eq15(b, 3.84), 3.84)
    assert b_r == pytest.approx(b, rel=1e-12)  # Eq 15 then Eq 6 gives b back
    assert a_r == pytest.approx(xi_min_eq15(b, 3.84) * 2 * math.pi * 3.84)


def test_eq10_theoretical_matches_table5_for_rectangles_1_and_2():
    for key in ("1", "2"):
        spec = paper.specimen(key)
        t = spec.theoretical
        R = classical_parameters(spec.block()).R_m
        k = stiffness_eq10(stiffness_eq8(spec.mass_kg, t["p_rad_s"]), stiffness_eq9(spec.mass_kg, R))
        printed = paper.table(5).loc[key, "K_T_paper_N_per_m"]
        assert k == pytest.approx(printed, rel=0.01)


def test_paper_calibration_scales_and_records():
    spec = paper.specimen(1)
    cal = paper_calibration(spec.block(), **spec.experimental)
    assert cal.stiffness_reading == "MN/m" and cal.stiffness_scale == 1e6
    assert cal.K_N_per_m == pytest.approx(cal.K_paper * 1e6)
    assert cal.Ks_N_per_m == cal.K_N_per_m
    assert cal.friction_angle_deg == 30.0 and cal.cohesion_Pa == 0.0 and cal.rayleigh_a_1_s == 0.0
    assert cal.f_min_hz == 3.84  # Eq 14
    assert cal.dt_eq7_s == pytest.approx(time_step_eq7(503, cal.K_N_per_m, 0.1))
    assert cal.dt_eq7_s == pytest.approx(0.1 * 2 * math.sqrt(503 / 7.2988e9), rel=1e-4)
    assert cal.settlement_m == pytest.approx(503 * G / cal.K_N_per_m)
    assert cal.settlement_m < 1e-4 * 1.0


def test_stiffness_read_as_newton_per_metre_is_refused():
    spec = paper.specimen(1)
    with pytest.raises(InputError, match="sinks") as info:
        paper_calibration(spec.block(), **spec.experimental, stiffness_scale="N/m")
    assert info.value.field == "contact.stiffness_scale"
    assert "0.677" in str(info.value)  # M g / K = 0.676... m, printed rounded up: it is above the limit


def test_eq13_outside_its_range_fails_clearly():
    with pytest.raises(CalibrationError, match="Eq 13"):
        stiffness_damping_eq13(100.0, 0.9)


def test_bad_stiffness_scale_names_field():
    spec = paper.specimen(1)
    for bad in ("GN/m", -1.0, float("nan")):
        with pytest.raises(InputError) as info:
            paper_calibration(spec.block(), stiffness_scale=bad)
        assert info.value.field == "contact.stiffness_scale"


def test_table6_biblock_parameters():
    for key in ("upper", "lower"):
        spec = paper.specimen(key)
        cal = paper_calibration(spec.block(), **spec.experimental)
        assert 2 * cal.b_eq_m == pytest.approx(paper.table(6).loc[key, "base_eq_2b_m"], abs=0.005)
        assert cal.K_paper == pytest.approx(paper.table(6).loc[key, "K_paper_N_per_m"], rel=0.03)


@pytest.mark.parametrize(
    ("contact", "method"),
    [
        ({"calibration": "paper"}, "paper"),
        ({"calibration": "paper", "K_N_per_m": 5e9, "Ks_N_per_m": 2e9}, "paper"),
        ({"calibration": "matched", "beta_s": 1e-4}, "paper"),
        ({"K_N_per_m": 5e9, "beta_s": 1e-4}, "explicit"),
        ({"jkn_Pa_per_m": 4e10, "beta_s": 1e-4}, "udec"),
    ],
    ids=["paper", "explicit K and Ks", "explicit beta", "explicit", "udec"],
)
def test_calibrate_gives_the_joint_the_model_runs(contact, method):
    """One dispatch: the joint that calibrate() returns for a block is the one the model built
    from its scene runs (the model is handed the joints, it calibrates nothing)."""
    from rockyade.calibration.calibrate import calibrate, calibration_method
    from rockyade.calibration.model_stage import calibrated_model
    from rockyade.scene import scene_from_dict

    from .conftest import free_scene_dict

    d = free_scene_dict()
    d["contact"] = contact
    scene = scene_from_dict(d)
    spec = scene.blocks[0]
    cal = calibrate(spec.block(), scene.contact, alpha_rad=spec.alpha_rad, p_rad_s=spec.p_rad_s, mu=spec.mu)
    assert repr(calibrated_model(scene).bodies[0].joint) == repr(cal.joint)
    assert cal.method == calibration_method(scene.contact) == method
