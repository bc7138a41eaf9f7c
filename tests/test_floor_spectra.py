"""Mechanisms at height by Circolare 2019 C8.7.1 with the floor spectra of C7.2.3: the floor
spectrum against its closed form, the linear and nonlinear checks against hand calculations,
the superseded 2009 form kept by name, and bad input refused naming the option."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.assess import Position, Site
from rockyade.assess.code import CHECK_SOURCES, checks_not_made, code_checks
from rockyade.assess.floor_spectra import FLOOR_A, FLOOR_B, FloorSpectrum, displacement_demand, secant_period
from rockyade.assess.site import NtcSite
from rockyade.cli import main
from rockyade.constants import CODE_GRAVITY as G
from rockyade.limit import limit_analysis
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, stack

NTC = ["--knowledge-level", "LC1", "--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B"]
HEIGHT = ["--z", "6", "--building-height", "9", "--storeys", "3", "--t1", "0.3"]


def wall(tmp_path, capsys):
    """The tuff wall of the how-to without its roof, 2.4 m x 0.36 m."""
    scene = tmp_path / "wall.toml"
    build = ["build", "wall-section", "--height-m", "2.4", "--thickness-m", "0.36", "--motion", "rest"]
    assert main([*build, "--out", str(scene)]) == 0
    capsys.readouterr()
    return scene


def block(width: float = 0.25, height: float = 2.5):
    return scene_from_dict(stack(widths_m=[width], heights_m=height, layout="column", motion=rest_motion()))


def floor(T1: float = 0.3, xi1: float = 0.05) -> FloorSpectrum:
    """EC8 Type 1, ground B, ag = 0.25 g: plateau 2.5 x 0.25 g x 1.2 on 0.15-0.5 s."""
    return FloorSpectrum(ElasticSpectrum.ec8(1, "B", ag_m_s2=0.25 * G), T1, 9 / 7, 6 / 9, xi1)


def test_the_floor_spectrum_is_the_clauses_closed_form():
    f = floor()
    plateau = 2.5 * 0.25 * G * 1.2
    a_z = plateau * (9 / 7) * (6 / 9) * math.sqrt(1 + 0.0004 * 25)  # C7.2.7: Se(T1) |gamma psi| sqrt(1 + 0.0004 xi^2)
    assert f.peak_m_s2 == pytest.approx(a_z, rel=1e-12)
    amp = 1.1 / math.sqrt(0.05)  # C7.2.9 at 5 %: 4.919
    assert f.amplification(0.05) == pytest.approx(amp, rel=1e-12) and amp == pytest.approx(4.9193, abs=1e-4)
    assert f.amplification(0.08) == pytest.approx(amp * math.sqrt(10 / 13), rel=1e-12)  # eta(8 %)
    T = np.array([0.0, 0.12, FLOOR_A * 0.3, 0.3, FLOOR_B * 0.3 - 1e-12, 0.5, 0.9])
    got = f.psa(T, 0.05)
    assert got[0] == pytest.approx(a_z, rel=1e-12)  # the floor's peak at T = 0
    assert got[1] == pytest.approx(amp * a_z / (1 + (amp - 1) * (1 - 0.12 / 0.24) ** 1.6), rel=1e-12)
    assert got[2:5] == pytest.approx([amp * a_z] * 3, rel=1e-12)  # the plateau a T1 .. b T1
    fall = amp * a_z / (1 + (amp - 1) * (0.5 / 0.33 - 1) ** 1.2)
    assert got[5] == pytest.approx(max(fall, plateau), rel=1e-12)
    # C7.2.5: not below the ground's spectrum beyond T1 (at 0.9 s the fall is below Se)
    ground = 2.5 * 0.25 * G * 1.2 * 0.5 / 0.9
    assert got[6] == pytest.approx(ground, rel=1e-12) and amp * a_z / (1 + (amp - 1) * (0.9 / 0.33 - 1) ** 1.2) < ground
    assert f.sde([0.5], 0.05)[0] == pytest.approx(got[5] * (0.5 / (2 * math.pi)) ** 2, rel=1e-12)


def test_the_building_damping_enters_both_the_peak_and_the_amplification():
    stiff, damped = floor(xi1=0.05), floor(xi1=0.10)
    eta10 = math.sqrt(10 / 15)
    assert damped.peak_m_s2 / stiff.peak_m_s2 == pytest.approx(eta10 * math.sqrt(1.04) / math.sqrt(1.01), rel=1e-12)
    assert damped.amplification(0.05) == pytest.approx(1.1 / math.sqrt(0.10), rel=1e-12)  # 3.48: the yielding building


def test_the_checks_at_height_are_2019s_linear_and_nonlinear_by_default():
    kin = limit_analysis(block(), fc=1.35).kinematic
    site = Site(1, "B", 0.25 * G)
    linear, nonlinear = code_checks(kin, site, Position(6.0, 9.0, 3, T1_s=0.3))
    f = floor()
    assert linear.name == "linear, at height" and linear.source.startswith(CHECK_SOURCES["linear, at height"])
    assert "C8.7.1.2.1.7" in linear.source and "C7.2.10" in linear.source
    assert linear.demand == pytest.approx(f.peak_m_s2 / 2.0, rel=1e-12)  # T0 = 0: the floor's peak / q
    assert linear.ag_capacity_m_s2 == pytest.approx(site.ag_m_s2 * 2.0 * kin.a0_star_m_s2 / f.peak_m_s2, rel=1e-12)
    # nonlinear: d_SLV = 0.4 d0* = 0.4 b = 0.05 m for one block; T_SLV = 1.68 pi sqrt(d / a(d))
    d, a = nonlinear.capacity, nonlinear.terms["a_SLV_m_s2"]
    assert d == pytest.approx(0.05, rel=1e-6)
    # the centroid 0.125 - 0.05 = 0.075 m from the pivot's vertical: alpha = tan(asin(0.075 / R)), R = |(0.125, 1.25)|
    exact = math.tan(math.asin(0.075 / math.hypot(0.125, 1.25))) * G / 1.35
    assert a == pytest.approx(exact, rel=1e-4)
    assert nonlinear.terms["T_SLV_s"] == pytest.approx(1.68 * math.pi * math.sqrt(d / a), rel=1e-12)
    demand, bound = displacement_demand(f, nonlinear.terms["T_SLV_s"], 0.08)
    assert nonlinear.demand == pytest.approx(demand, rel=1e-12) and nonlinear.status == "not verified"
    assert nonlinear.terms["T_SLV_s"] > FLOOR_B * 0.3 and bound == pytest.approx(
        f.psa([0.3], 0.08)[0] * (FLOOR_B * 0.3 / (2 * math.pi)) ** 2, rel=1e-12
    )
    assert "C8.7.1.10" in nonlinear.source and "C8.7.1.12" in nonlinear.source and "xi = 8 %" in nonlinear.source


def test_the_displacement_demand_has_the_floor_of_eq_c8_7_1_12():
    f = floor(T1=0.3)
    # just above b T1 = 0.33 s SeZ T^2 still grows: the demand is above its floor; at 0.4 s SeZ has fallen by a
    # third and SeZ(0.4) 0.4^2 < SeZ(T1) 0.33^2: the floor governs
    near, bound_near = displacement_demand(f, 0.35, 0.08)
    far, bound_far = displacement_demand(f, 0.4, 0.08)
    assert near == pytest.approx(float(f.sde([0.35], 0.08)[0]), rel=1e-12) and near > bound_near
    assert far == pytest.approx(bound_far, rel=1e-12) and float(f.sde([0.4], 0.08)[0]) < bound_far
    inside, none = displacement_demand(f, 0.3, 0.08)
    assert math.isnan(none) and inside == pytest.approx(float(f.sde([0.3], 0.08)[0]))
    assert secant_period(0.05, 1.0) == pytest.approx(1.68 * math.pi * math.sqrt(0.05))


def test_a_mechanism_with_a_period_takes_the_floor_spectrum_there():
    kin = limit_analysis(block(), fc=1.35).kinematic
    site = Site(1, "B", 0.25 * G)
    linear, _ = code_checks(kin, site, Position(6.0, 9.0, 3, T1_s=0.3, mechanism_period_s=0.3))
    assert linear.demand == pytest.approx(floor().psa([0.3], 0.05)[0] / 2.0, rel=1e-12)  # on the plateau: A a_Z / q


def test_the_2009_form_is_kept_by_name_and_says_so():
    kin = limit_analysis(block(), fc=1.35).kinematic
    site = Site(1, "B", 0.25 * G)
    pos = Position(6.0, 9.0, 3, T1_s=0.3, code_form="circolare2009")
    [check] = code_checks(kin, site, pos)
    plateau = 2.5 * 0.25 * G * 1.2
    assert check.name == "linear, at height (Circolare 2009)"
    assert check.demand == pytest.approx(plateau * (6 / 9) * (9 / 7) / 2.0, rel=1e-12)
    assert "superseded" in check.source and "--code-form circolare2009" in check.source
    notes = checks_not_made(kin, pos)
    assert any("nonlinear check at height" in n and "circolare2009" in n for n in notes)
    assert pos.to_dict()["code_form"] == "circolare2009"


@pytest.mark.slow
def test_assess_prints_the_floor_spectrum_checks_with_their_clauses(tmp_path, capsys):
    scene = wall(tmp_path, capsys)
    assert main(["assess", str(scene), *NTC, "--static-only", *HEIGHT]) == 0
    text = capsys.readouterr().out
    assert "linear, at height: a0* = " in text and "SeZ(T0 = 0 s, 5 %) / q" in text
    assert "nonlinear, at height: d_SLV = " in text and "SeZ(T_SLV = " in text
    assert "Circolare 2019 floor spectrum, xi1 = 5 %" in text
    assert main(["assess", str(scene), *NTC, "--static-only", *HEIGHT, "--code-form", "circolare2009"]) == 0
    assert "Se(T1) psi gamma / q" in capsys.readouterr().out
    # the option's former name still works
    assert main(["assess", str(scene), *NTC, "--static-only", *HEIGHT, "--height-check", "circolare2009"]) == 0
    assert "Se(T1) psi gamma / q" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "option"),
    [
        (["--building-damping-pct", "50"], "--building-damping-pct"),
        (["--mechanism-damping-pct", "1"], "--mechanism-damping-pct"),
        (["--mechanism-period", "-1"], "--mechanism-period"),
        (["--code-form", "circolare2009", "--mechanism-damping-pct", "8"], "--mechanism-damping-pct"),
        (["--code-form", "circolare2009", "--building-damping-pct", "8"], "--building-damping-pct"),
    ],
)
def test_bad_floor_options_are_refused_naming_them(tmp_path, capsys, extra, option):
    scene = wall(tmp_path, capsys)
    assert main(["assess", str(scene), *NTC, "--static-only", *HEIGHT, *extra]) == 2
    assert option in capsys.readouterr().err


def test_floor_options_apply_at_height_only():
    with pytest.raises(Exception, match="--building-damping-pct"):
        Position(building_damping=0.05)
    with pytest.raises(Exception, match="--mechanism-period"):
        Position(mechanism_period_s=0.2)
    with pytest.raises(Exception, match="--t1"):
        Position(T1_s=0.3)
    # the form of the checks and the mechanism's damping apply at ground level too
    assert Position(code_form="circolare2009").method == "circolare2009"
    assert Position(mechanism_damping=0.10).xi_slv == 0.10
    with pytest.raises(Exception, match="--code-form"):
        Position(code_form="circolare2013")
    with pytest.raises(Exception, match="--mechanism-damping-pct"):
        Position(code_form="circolare2009", mechanism_damping=0.08)


def test_the_ntc_site_reaches_the_floor_spectrum_through_its_own_spectrum():
    kin = limit_analysis(block(), fc=1.35).kinematic
    site = NtcSite(0.2, 2.4, 0.3, "B")
    linear, _ = code_checks(kin, site, Position(6.0, 9.0, 3, T1_s=0.3))
    se_t1 = 0.2 * G * 1.2 * 2.4  # T1 = 0.3 s on the plateau TB = 0.14 s .. TC = 0.42 s
    assert linear.terms["a_Z_m_s2"] == pytest.approx(se_t1 * (9 / 7) * (6 / 9) * math.sqrt(1.01), rel=1e-12)


def test_the_verify_row_of_the_worked_example_passes(tmp_path):
    """``rockyade verify --only floor_spectrum``: the how-to's mechanism at height against its hand calculation."""
    from rockyade.studies.verification import verify

    table = verify(tmp_path, ["floor_spectrum"], ["reference"])
    # seven at height, three at ground level (the 2019 form, its ag, the 2009 form)
    assert len(table) == 10 and set(table["check"]) == {"floor_spectrum"}
    assert table["passed"].all(), table[~table["passed"]].to_string()
    assert table["difference"].abs().max() < 1e-3
