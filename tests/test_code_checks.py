"""What ``rockyade assess`` says about its checks: each with its clause and formula, the checks
it does not make listed with the reason, every load and whether its mass takes part, a wall in
courses that turns as one body, the NTC site by default, the fit's warnings, and rotations
against the whole's alpha."""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pandas as pd
import pytest

from rockyade.assess import Position, Site, assess, records_in_folder
from rockyade.assess.code import CHECK_SOURCES, code_checks
from rockyade.assess.fragility_analysis import fragility_plan
from rockyade.assess.measures import Measure
from rockyade.assess.site import NtcSite
from rockyade.assess.stripe_fit import FEW_RECORDS, MIN_RECORDS, fit_stripes
from rockyade.assess.stripes import run_stripe_task, whole_alpha
from rockyade.cli import main
from rockyade.constants import CODE_GRAVITY, G
from rockyade.limit import limit_analysis
from rockyade.runner import Executor
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, stack

from .conftest import EXAMPLES

NTC = ["--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B"]
#: The knowledge level LC1 (FC = 1.35), which ``rockyade assess`` needs.
LC1 = ["--knowledge-level", "LC1"]


def courses(n: int, width: float = 0.3, height: float = 2.4):
    data = stack(
        widths_m=[width] * n,
        heights_m=height / n,
        thickness_m=1.0,
        density_kg_m3=1800.0,
        layout="column" if n == 1 else "positioned",
        motion=rest_motion(),
    )
    return scene_from_dict(data)


def roof_wall(tmp_path, capsys, mass: str = "carried"):
    out = tmp_path / f"roof_{mass}.toml"
    assert (
        main(
            [
                "build",
                "wall-section",
                "--height-m",
                "2.4",
                "--thickness-m",
                "0.36",
                "--density-kg-m3",
                "1600",
                "--overburden-n-per-m",
                "6000",
                "--overburden-eccentricity-m",
                "0.05",
                "--overburden-mass",
                mass,
                "--motion",
                "rest",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    capsys.readouterr()
    return out


def test_every_check_names_its_clause_and_formula():
    kin = limit_analysis(courses(1)).kinematic
    site = NtcSite(0.2, 2.4, 0.3, "B")
    ground = code_checks(kin, site, Position())
    height = code_checks(kin, site, Position(6.0, 9.0, 3))
    for check in ground + height:
        assert "Circolare" in check.source and ">=" in check.source
        assert check.source.startswith(CHECK_SOURCES[check.name])
    assert "NTC 2018 3.2.3.2.1" in ground[0].source and "Eq 3.2.12" in ground[1].source
    linear, nonlinear = height  # Circolare 2019 C8.7.1 on the floor spectra of C7.2.3
    assert "C8.7.1.2.1.7" in linear.source and "Eq C8.7.1.12" in nonlinear.source
    [form_2009] = code_checks(kin, site, Position(6.0, 9.0, 3, code_form="circolare2009"))
    assert form_2009.source.startswith(CHECK_SOURCES[form_2009.name]) and "superseded" in form_2009.source
    ground_2009 = code_checks(kin, site, Position(code_form="circolare2009"))[1]
    assert ground_2009.name == "nonlinear, ground level (Circolare 2009)" and "superseded" in ground_2009.source
    assert "C8.7.1.2.1.8" in ground[1].source and "Eq C8.7.1.10" in ground[1].source
    ec8 = code_checks(kin, Site(1, "B", 0.25 * G), Position())
    assert "EN 1998-1" in ec8[1].source


def test_the_checks_not_made_are_in_the_output_itself(tmp_path, capsys):
    scene = roof_wall(tmp_path, capsys)
    assert main(["assess", str(scene), *LC1, *NTC, "--static-only", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["notes"], "the JSON lists the checks not made"
    not_made = [n for n in data["notes"] if n.startswith("not made: ")]
    assert any("sliding mechanisms" in n for n in not_made) and any("SLD" in n for n in not_made)
    assert all(c["source"] for c in data["checks"])
    assert data["site"]["spectrum_code"] == "ntc2018" and data["g_m_s2"] == CODE_GRAVITY
    height = ["--z", "6", "--building-height", "9", "--storeys", "3"]
    assert main(["assess", str(scene), *LC1, *NTC, "--static-only", *height]) == 0
    text = capsys.readouterr().out
    assert "checks not made:" in text and "the floor spectrum's higher modes" in text
    assert "clause: Circolare 2019 C8.7.1.2.1.8, nonlinear kinematic analysis at height" in text


@pytest.mark.slow
def test_every_load_says_whether_its_mass_takes_part(tmp_path, capsys):
    """The engineer's roof: alpha0 = 0.1050 with its mass (test_loads checks it by hand), 0.1979 without."""
    for mass, alpha0, words in (("carried", 0.1050, "with its mass 611.6 kg"), ("none", 0.1979, "without mass")):
        scene = roof_wall(tmp_path, capsys, mass)
        assert main(["assess", str(scene), *LC1, *NTC, "--static-only", "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        [load] = data["loads"]
        assert load["mass_takes_part"] == (mass == "carried")
        assert round(data["alpha0"], 4) == alpha0
        assert main(["assess", str(scene), *LC1, *NTC, "--static-only"]) == 0
        assert words in capsys.readouterr().out
        assert main(["limit", str(scene)]) == 0
        assert words in capsys.readouterr().out


def test_courses_that_turn_as_one_body_are_said_to_and_their_e_star_explained():
    """4 courses turning about the base as one: the code's e* = (1/4) / (1/3 - 1/(12 n^2)) with
    n = 4 is 0.25 / (1/3 - 1/192) = 0.76190; the same body as one block has e* = 1, so a0* is
    1 / 0.76190 = 1.3125 times the monolith's."""
    site = Site(1, "B", 0.25 * G)
    result = assess(courses(4), site, fc=1.35)
    rigid = result.to_dict()["rigid_body_mechanism"]
    assert rigid["e_star_blocks"] == pytest.approx(0.25 / (1 / 3 - 1 / 192), rel=1e-9)
    assert rigid["e_star_one_body"] == pytest.approx(1.0, rel=1e-9)
    monolith = assess(courses(1), site, fc=1.35)
    assert rigid["a0_star_one_body_m_s2"] == pytest.approx(monolith.limit.kinematic.a0_star_m_s2, rel=1e-9)
    assert any("not expected to act as separate blocks" in n for n in result.notes)
    assert monolith.to_dict()["rigid_body_mechanism"] is None


def test_assess_takes_the_ntc_spectrum_unless_ec8_is_asked_for(tmp_path, capsys):
    scene = str(EXAMPLES / "free_standing_wall.toml")
    assert main(["assess", scene, *LC1, "--ag", "0.2g", "--static-only"]) == 2
    assert "--f0" in capsys.readouterr().err
    assert main(["assess", scene, *LC1, *NTC, "--ground", "B", "--static-only"]) == 2
    assert "EC8 option" in capsys.readouterr().err
    ec8 = ["assess", scene, *LC1, "--spectrum", "ec8"]
    assert main([*ec8, "--ag", "0.25g", "--ground", "B", "--static-only"]) == 2
    assert "--spectrum-type" in capsys.readouterr().err
    assert main([*ec8, "--spectrum-type", "1", "--ground", "B", "--ag", "0.25g", "--static-only", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["site"]["spectrum_code"] == "ec8"
    assert main(["assess", scene, *LC1, *NTC, "--count", "3"]) == 2
    assert "--records" in capsys.readouterr().err


def _runs(records: int, levels, median: float = 2.0, beta: float = 0.4, seed: int = 5) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    cap = median * np.exp(beta * rng.standard_normal(records))
    return pd.DataFrame(
        [
            {"record_index": r, "level": x, "status": "completed", "collapsed": bool(x >= cap[r])}
            for x in levels
            for r in range(records)
        ]
    )


def test_a_fit_on_few_records_is_refused_or_warned():
    levels = np.geomspace(0.5, 8.0, 8)
    three = fit_stripes(_runs(MIN_RECORDS - 2, levels), "level")
    assert not three.fitted and "fewer than 5" in three.fragility.status
    seven = fit_stripes(_runs(FEW_RECORDS - 3, levels), "level")
    assert seven.fitted and any("fewer than 10" in n for n in seven.notes)
    many = fit_stripes(_runs(40, levels), "level")
    assert not any("fewer than" in n for n in many.notes)


def test_a_band_ending_at_the_median_says_why():
    """6 records: 5 collapse from level 2 on, one from level 4 on (beside them, every level
    brackets no other outcome). A resample with no late record has no slope (no fit); one with
    exactly one gives back the full sample's outcomes, hence its median, in 6 (1/6) (5/6)^5 = 40 %
    of the draws; more late records only raise the median: the band's lower end is the median."""
    levels = [1.0, 2.0, 3.0, 4.0, 5.0]
    rows = [
        {"record_index": r, "level": x, "status": "completed", "collapsed": x >= (4.0 if r == 5 else 2.0)}
        for x in levels
        for r in range(6)
    ]
    fit = fit_stripes(pd.DataFrame(rows), "level")
    assert fit.fitted
    lo, _ = fit.median_interval_si
    assert lo == pytest.approx(fit.fragility.median, rel=1e-6)
    assert any("lower end is the median itself" in n for n in fit.notes)
    assert any("fewer than 10" in n for n in fit.notes)


def test_rotations_are_against_the_whole_alpha(tmp_path):
    """A 4-course wall and its monolith (0.3 x 2.4 m) under the Ricker pulse at 0.2 g: the whole's
    alpha is atan(0.15 / 1.2) for both; the per-course ratio (each course's own alpha, atan(0.15 /
    0.3)) is kept in its own column and is about 4 times smaller."""
    folder = tmp_path / "records"
    folder.mkdir()
    shutil.copy(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2", folder / "ricker.AT2")
    records = records_in_folder(folder)
    alpha = math.atan(0.15 / 1.2)
    ratios = {}
    for n in (1, 4):
        scene = courses(n)
        assert whole_alpha(scene) == pytest.approx(alpha, rel=1e-9)
        plan = fragility_plan(
            scene,
            records,
            Measure("pga"),
            "reference",
            levels=[0.2, 0.4],
            executor=Executor("threads", 1),
            progress=False,
            tail_s=1.0,
        )
        row = run_stripe_task(plan.stripes.tasks([0.2 * G])[0])
        assert row["status"] == "completed" and not row["collapsed"]
        ratios[n] = (row["max_theta_over_alpha"], row["max_theta_over_own_alpha"])
    assert ratios[1][0] == pytest.approx(ratios[1][1], rel=1e-9)
    assert ratios[4][0] == pytest.approx(ratios[1][0], rel=0.25)
    assert ratios[4][1] < 0.5 * ratios[4][0]


@pytest.mark.parametrize("position", [Position(), Position(3.3, 9.8, 3)], ids=["ground", "at height"])
def test_the_ag_at_which_a_check_is_met_is_met_there_on_an_ntc_site(position):
    """NTC 2018's spectrum is not proportional to ag: on soil C, SS = 1.70 - 0.60 F0 ag/g (Tab. 3.2.IV) rises
    to its bound 1.5 as ag falls, and TD = 4 ag/g + 1.6 s falls with it, so 'met up to ag = ag x capacity /
    demand' was not where the check is met (a two-storey tuff wall at 0.18 g: 0.0531 g against 0.0508 g
    for the linear check at height, 0.0921 g against 0.1019 g for the nonlinear one); made again at the ag
    it gives, each check is met exactly (capacity / demand = 1)."""
    kin = limit_analysis(courses(1, 0.4, 6.5), fc=1.35).kinematic
    site = NtcSite(0.18, 2.45, 0.32, "C")
    checks = code_checks(kin, site, position)
    assert len(checks) == 2 and all(c.applies for c in checks)
    for i, check in enumerate(checks):
        there = NtcSite(check.ag_capacity_m_s2 / CODE_GRAVITY, 2.45, 0.32, "C")
        assert code_checks(kin, there, position)[i].ratio == pytest.approx(1.0, rel=1e-7), check.name
    linear = checks[0]
    assert linear.ag_capacity_m_s2 < site.ag_m_s2 * linear.ratio  # SS is larger at the lower ag
    # by hand, ground level: a0* q = ag 1.5 (SS at its bound), so ag = a0* q / 1.5
    if not position.at_height:
        assert linear.ag_capacity_m_s2 == pytest.approx(kin.a0_star_m_s2 * 2 / 1.5, rel=1e-9)
    # on soil B at 0.2 g SS is at its bound 1.2 down to ag = 0: proportional, the same as before
    flat = code_checks(kin, NtcSite(0.2, 2.4, 0.3, "B"), Position())[0]
    assert flat.ag_capacity_m_s2 == pytest.approx(0.2 * CODE_GRAVITY * flat.ratio, rel=1e-9)


def test_a_mechanism_turning_above_the_scenes_base_at_height_says_which_z_the_code_means(tmp_path, capsys):
    """Z is the height of the lines the mechanism turns about (Circolare 2019 C8.7.1.2.1.5): a two-storey
    wall whose upper storey overturns on the lower one turns 3.2 m above the scene's base, and --z given as
    the wall's base put the floor's demand at psi = 3.3 / 9.8 where the code's is 6.5 / 9.8, without a word."""
    blocks = [
        ("w01", 0.8, 3.2, 0.0),
        ("w02", 0.4, 3.3, 3.2),
    ]
    text = 'duration_s = 3.0\nsample_dt_s = 0.002\n[contact]\nfriction_angle_deg = 30.0\n[motion]\ntype = "rest"\n'
    for name, width, height, y in blocks:
        text += (
            f'[[blocks]]\nname = "{name}"\nwidth_m = {width}\nheight_m = {height}\nthickness_m = 1.0\n'
            f"density_kg_m3 = 1600.0\nposition_m = [0.0, {y}]\n"
        )
    scene = tmp_path / "two_storeys.toml"
    scene.write_text(text)
    height = ["--z", "3.3", "--building-height", "9.8", "--storeys", "3", "--static-only"]
    assert main(["assess", str(scene), *LC1, *NTC, *height]) == 0
    out = capsys.readouterr().out
    assert "w02 turns clockwise on w01 about (0.2, 3.2) m" in out
    assert "hinges at y = 3.2 m of the scene" in out and "give --z 6.5" in out
    single = tmp_path / "one.toml"
    single.write_text(text.split("[[blocks]]")[0] + "[[blocks]]" + text.split("[[blocks]]")[2])
    single.write_text(single.read_text().replace("position_m = [0.0, 3.2]", "position_m = [0.0, 0.0]"))
    assert main(["assess", str(single), *LC1, *NTC, *height]) == 0
    assert "of the scene, above its base" not in capsys.readouterr().out  # it turns on its base: Z is --z


def test_a_period_beyond_the_spectra_is_refused_without_naming_a_spectrum_not_used(capsys):
    """On the NTC 2018 site (the default) the refusal of --t1 named 'the EC8 spectrum'."""
    height = ["--z", "3", "--building-height", "9", "--storeys", "3", "--t1", "5", "--static-only"]
    assert main(["assess", str(EXAMPLES / "tuff_wall_roof.toml"), *LC1, *NTC, *height]) == 2
    err = capsys.readouterr().err
    assert "--t1: must be in (0, 4] s" in err and "EC8" not in err
