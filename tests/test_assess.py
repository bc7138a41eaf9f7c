"""rockyade.assess: the code's checks against hand calculations, the intensity measures, the
records, the fit and its band, and the collapse of real runs (Housner and the reference DEM)."""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from rockyade.assess import (
    DynamicSettings,
    Measure,
    Position,
    SceneCannotStandError,
    Site,
    assess,
    code_checks,
    parse_acceleration,
    parse_measure,
    records_in_folder,
)
from rockyade.assess.assessment import add_pushover
from rockyade.assess.code import NOT_APPLICABLE, NOT_VERIFIED, VERIFIED, Check, check_code, verdict
from rockyade.assess.fragility_analysis import EXTEND_RATIO, _next_level, check_levels, fragility_plan, run_fragility
from rockyade.assess.stripe_fit import fit_stripes, stripe_table
from rockyade.assess.stripes import StripePlan, run_stripe_task
from rockyade.constants import CODE_GRAVITY, G
from rockyade.errors import InputError
from rockyade.limit import limit_analysis
from rockyade.motion.records import read_record
from rockyade.motion.spectra import response_spectrum
from rockyade.runner import Executor
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, stack

from .conftest import EC8_LC1, EXAMPLES
from .limit_scenes import block_scene, positioned_scene

THREADS = Executor("threads", 1)


def wall_scene(width: float = 0.25, height: float = 2.5, courses: int = 1):
    """A free-standing wall section, 1 m long, of ``courses`` equal courses (one block: a column scene)."""
    layout = "column" if courses == 1 else "positioned"
    data = stack(
        widths_m=[width] * courses,
        heights_m=height / courses,
        thickness_m=1.0,
        density_kg_m3=1800.0,
        layout=layout,
        motion=rest_motion(),
    )
    return scene_from_dict(data, source="wall.toml")


@pytest.fixture
def two_records(tmp_path):
    """The Ricker pulse (5 s) and record 21 of the paper's suite (20 s), each once."""
    folder = tmp_path / "records"
    folder.mkdir()
    for name in ("ricker_pulse_T0.5s.AT2", "ec8_type2_D_record21.AT2"):
        shutil.copy(EXAMPLES / "records" / name, folder / name)
    return folder


# ---------------------------------------------------------------------- inputs


def test_an_acceleration_needs_its_unit_and_a_sane_value():
    assert parse_acceleration("0.25g") == pytest.approx(0.25 * CODE_GRAVITY)
    assert parse_acceleration(" 0.25 g") == pytest.approx(0.25 * CODE_GRAVITY)
    assert parse_acceleration("2.45m/s2") == pytest.approx(2.45)
    assert parse_acceleration("2.45 m/s^2") == pytest.approx(2.45)
    for bad in ("0.25", "0g", "-0.1g", "1.5g", "abc", "nan g", "0.25 gal"):
        with pytest.raises(InputError) as info:
            parse_acceleration(bad)
        assert info.value.field == "--ag"


def test_a_negative_acceleration_with_its_unit_is_told_its_range_not_its_unit():
    with pytest.raises(InputError) as info:
        parse_acceleration("-0.2g")
    assert "must be in (0, " in info.value.message and "with its unit" not in info.value.message


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"spectrum_type": 3}, "--spectrum-type"),
        ({"ground": "F"}, "--ground"),
        ({"agR_m_s2": 0.0}, "--ag"),
        ({"agR_m_s2": 30.0}, "--ag"),
        ({"importance": 3.0}, "--importance"),
    ],
)
def test_a_bad_site_names_the_option(kwargs, field):
    site = {"spectrum_type": 1, "ground": "B", "agR_m_s2": 2.45, **kwargs}
    with pytest.raises(InputError) as info:
        Site(**site)
    assert info.value.field == field


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"z_m": 10.0, "building_height_m": 9.0, "storeys": 3}, "--z"),
        ({"z_m": 3.0}, "--z"),
        ({"T1_s": 0.3}, "--t1"),
        ({"z_m": 3.0, "building_height_m": 9.0, "storeys": 0}, "--storeys"),
        ({"z_m": 3.0, "building_height_m": 9.0, "storeys": 3, "T1_s": 9.0}, "--t1"),
    ],
)
def test_a_bad_position_names_the_option(kwargs, field):
    with pytest.raises(InputError) as info:
        Position(**kwargs)
    assert info.value.field == field


def test_only_the_implemented_code_is_taken():
    assert check_code("ntc2018") == "ntc2018"
    with pytest.raises(InputError) as info:
        check_code("ec8-3")
    assert info.value.field == "--code" and "ntc2018" in info.value.message


# ---------------------------------------------------------------------- the code's checks


def test_the_checks_of_a_free_standing_wall_match_the_hand_calculation():
    """The hand calculation of docs/limit.md (the wall of docs/howto/is-this-wall-safe.md): a 0.25 m x 2.5 m wall,
    EC8 Type 1, ground B (S = 1.2, TB 0.15, TC 0.5, TD 2 s), ag = 0.25 g, FC 1.35, q = 2."""
    b, fc, q = 0.125, 1.35, 2.0
    result = limit_analysis(wall_scene(), fc=fc)
    kin = result.kinematic
    assert kin.alpha0 == pytest.approx(0.1, rel=1e-12)
    assert kin.e_star == pytest.approx(1.0, rel=1e-12)
    a0 = 0.1 * CODE_GRAVITY / 1.35  # 0.72642 m/s^2
    assert kin.a0_star_m_s2 == pytest.approx(a0, rel=1e-12)
    ag, S = 0.25 * G, 1.2
    site = Site(1, "B", ag)
    linear, nonlinear = code_checks(kin, site, Position())
    assert linear.demand == pytest.approx(ag * S / q) and linear.demand == pytest.approx(1.4715)
    assert linear.capacity == pytest.approx(a0) and linear.status == NOT_VERIFIED
    assert linear.ag_capacity_m_s2 == pytest.approx(a0 * q / S)  # 0.1235 g
    # nonlinear, Circolare 2019 C8.7.1.2.1.8: d_SLV = 0.4 d0* = 0.4 b; on the capacity curve there the block has
    # turned by theta with R sin(a) - R sin(a - theta) = d_SLV (R, a: its centroid's radius and angle from the toe),
    # where alpha = tan(a - theta) (test_limit_kinematic checks the curve)
    assert kin.du_star_m == pytest.approx(0.4 * b, rel=1e-6)
    R = math.hypot(b, 1.25)
    alpha = math.tan(math.asin((b - 0.4 * b) / R))
    a_slv = alpha * CODE_GRAVITY / fc  # e* = 1
    t_slv = 1.68 * math.pi * math.sqrt(0.4 * b / a_slv)  # Eq C8.7.1.10: 1.79 s
    assert nonlinear.terms["a_SLV_m_s2"] == pytest.approx(a_slv, rel=1e-4)
    assert nonlinear.terms["T_SLV_s"] == pytest.approx(t_slv, rel=1e-4)
    assert 0.5 < t_slv < 2.0  # between TC and TD: Se = 2.5 ag S eta TC / T, eta(8 %) = sqrt(10 / 13)
    sde = 2.5 * ag * S * math.sqrt(10 / 13) * 0.5 / t_slv * (t_slv / (2 * math.pi)) ** 2
    assert nonlinear.demand == pytest.approx(sde, rel=1e-4)
    assert nonlinear.capacity == pytest.approx(0.4 * b, rel=1e-6)
    assert nonlinear.status == NOT_VERIFIED
    assert nonlinear.ag_capacity_m_s2 == pytest.approx(ag * 0.4 * b / sde, rel=1e-4)
    assert verdict([linear, nonlinear]) == NOT_VERIFIED
    # the superseded Circolare 2009 form, by name: du* against SDe(Ts) at 5 %, Ts at ds* = 0.4 du*
    _, form_2009 = code_checks(kin, site, Position(code_form="circolare2009"))
    ts = kin.Ts_s
    assert 0.5 < ts < 2.0
    sde_2009 = 2.5 * ag * S * 0.5 / ts * (ts / (2 * math.pi)) ** 2
    assert form_2009.name == "nonlinear, ground level (Circolare 2009)"
    assert form_2009.demand == pytest.approx(sde_2009, rel=1e-12) and form_2009.status == NOT_VERIFIED
    assert form_2009.ag_capacity_m_s2 == pytest.approx(ag * 0.4 * b / sde_2009, rel=1e-6)
    # the same wall on a site a fifth as strong: the linear check holds
    weak = code_checks(kin, Site(1, "B", 0.05 * G), Position())
    assert weak[0].status == VERIFIED and verdict(weak) == VERIFIED


def test_a_mechanism_at_height_takes_the_floor_demand_and_the_simplified_period():
    """The superseded Circolare 2009 form, asked for by name (the 2019 form: tests/test_floor_spectra.py)."""
    kin = limit_analysis(wall_scene(), fc=1.35).kinematic
    site = Site(1, "B", 0.25 * G)
    pos = Position(6.0, 9.0, 3, code_form="circolare2009")
    assert pos.period_s == pytest.approx(0.05 * 9.0**0.75)  # 0.26 s: on the plateau TB-TC
    assert "Eq 4.6" in pos.period_source
    [check] = code_checks(kin, site, pos)
    plateau = 2.5 * 0.25 * G * 1.2
    assert check.terms["Se_T1_m_s2"] == pytest.approx(plateau)
    assert check.demand == pytest.approx(plateau * (6.0 / 9.0) * (9.0 / 7.0) / 2.0)
    assert check.ag_capacity_m_s2 == pytest.approx(site.ag_m_s2 * kin.a0_star_m_s2 / check.demand)
    given = code_checks(kin, site, Position(6.0, 9.0, 3, T1_s=1.0, code_form="circolare2009"))[0]
    assert given.terms["Se_T1_m_s2"] == pytest.approx(2.5 * 0.25 * G * 1.2 * 0.5 / 1.0)


def test_the_importance_factor_multiplies_ag():
    kin = limit_analysis(wall_scene(), fc=1.35).kinematic
    plain = code_checks(kin, Site(1, "B", 0.2 * G), Position())[0]
    important = code_checks(kin, Site(1, "B", 0.2 * G, importance=1.4), Position())[0]
    assert important.demand == pytest.approx(1.4 * plain.demand)


def test_a_sliding_mechanism_has_no_nonlinear_check():
    scene = block_scene(2.0, 0.4, friction_deg=10.0)
    kin = limit_analysis(scene).kinematic
    linear, nonlinear = code_checks(kin, Site(1, "A", 0.1 * G), Position())
    assert linear.applies and nonlinear.status == NOT_APPLICABLE and "slides" in nonlinear.reason
    assert verdict([nonlinear]) == NOT_APPLICABLE and math.isnan(nonlinear.ratio)


def test_a_verdict_needs_one_check_met():
    def check(status: str) -> Check:
        return Check("c", "a0*", "", 1.0, 1.0, "m/s^2", status)

    assert verdict([check(NOT_VERIFIED), check(VERIFIED)]) == VERIFIED
    assert verdict([check(NOT_VERIFIED), check(NOT_APPLICABLE)]) == NOT_VERIFIED
    assert verdict([]) == NOT_APPLICABLE


def test_a_scene_that_cannot_stand_has_no_verdict():
    overhang = positioned_scene(
        [
            {"name": "a", "width_m": 0.4, "height_m": 1.0, "position_m": [0.0, 0.0]},
            {"name": "b", "width_m": 0.4, "height_m": 0.2, "position_m": [0.35, 1.0]},
        ]
    )
    with pytest.raises(SceneCannotStandError):
        assess(overhang, Site(1, "B", 0.1 * G), fc=1.35)


def test_the_dynamic_part_is_refused_at_height():
    with pytest.raises(InputError) as info:
        assess(wall_scene(), Site(1, "B", 0.1 * G), fc=1.35, position=Position(6.0, 9.0, 3), dynamic=DynamicSettings())
    assert info.value.field == "--static-only"


# ---------------------------------------------------------------------- measures and records


def test_measures_parse_and_refuse():
    assert parse_measure("PGA") == Measure("pga")
    assert parse_measure("sa(0.5)") == Measure("sa", 0.5)
    assert parse_measure("sa(1.2s)").period_s == 1.2
    assert parse_measure("sa(0.5)").column == "sa_g" and parse_measure("pgv").column == "pgv_m_s"
    for bad in ("sa", "sa()", "pgd", "sa(20)", "sa(-1)"):
        with pytest.raises(InputError) as info:
            parse_measure(bad)
        assert info.value.field == "--intensity"


def test_measures_of_a_record_and_their_scaling():
    rec = read_record(EXAMPLES / "records" / "ec8_type2_D_record21.AT2")
    assert Measure("pga").of_record(rec) == pytest.approx(np.max(np.abs(rec.accel_m_s2)))
    _, psa = response_spectrum(rec.accel_m_s2, rec.dt_s, np.array([0.5]), 0.05)
    assert Measure("sa", 0.5).of_record(rec) == pytest.approx(psa[0])
    doubled = rec.with_accel(2.0 * rec.accel_m_s2, "x2")
    for m in (Measure("pga"), Measure("pgv"), Measure("sa", 0.5)):
        assert m.of_record(doubled) == pytest.approx(2.0 * m.of_record(rec), rel=1e-9)


def test_pgv_of_a_sine_is_its_closed_form():
    """a = A sin(w t) from rest: v = (A / w) (1 - cos w t), max 2 A / w."""
    from rockyade.motion.records import Record

    t = np.arange(0, 2.0 + 1e-9, 1e-4)
    amp, w = 3.0, 2 * math.pi * 2.0
    rec = Record(t, amp * np.sin(w * t), "m/s2", "sine")
    assert Measure("pgv").of_record(rec) == pytest.approx(2 * amp / w, rel=1e-6)


def test_a_records_folder_refuses_the_same_record_twice_and_an_empty_folder(tmp_path, two_records):
    twins = tmp_path / "twins"
    twins.mkdir()
    shutil.copy(EXAMPLES / "records" / "ec8_type2_D_record21.AT2", twins)
    shutil.copy(EXAMPLES / "records_csv" / "ec8_type2_D_record21.csv", twins)
    with pytest.raises(InputError) as info:
        records_in_folder(twins)  # record 21 as .AT2 and as .csv
    assert "same accelerogram" in info.value.message
    with pytest.raises(InputError):
        records_in_folder(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError):
        records_in_folder(tmp_path / "empty")
    records = records_in_folder(two_records)
    assert records.count == 2 and records.label(0) == "ec8_type2_D_record21.AT2"


# ---------------------------------------------------------------------- the fit


def _synthetic_runs(median: float, beta: float, records: int, levels: np.ndarray, seed: int) -> pd.DataFrame:
    """Outcomes of a record-to-record lognormal capacity: record r collapses at every level above
    its own capacity c_r ~ lognormal(median, beta), as a rigid block does above its threshold."""
    rng = np.random.default_rng(seed)
    capacity = median * np.exp(beta * rng.standard_normal(records))
    rows = [
        {"record_index": r, "level": float(x), "status": "completed", "collapsed": bool(x >= capacity[r])}
        for x in levels
        for r in range(records)
    ]
    return pd.DataFrame(rows)


def test_the_fit_recovers_a_known_lognormal_and_its_band_covers_it():
    levels = np.geomspace(0.5, 8.0, 9)
    runs = _synthetic_runs(2.0, 0.4, 400, levels, seed=11)
    fit = fit_stripes(runs, "level")
    f = fit.fragility
    assert f.status == "fitted"
    assert f.median == pytest.approx(2.0, rel=0.05)
    assert f.beta == pytest.approx(0.4, rel=0.12)
    lo, hi = fit.median_interval_si
    assert lo < 2.0 < hi and fit.beta_interval[0] < 0.4 < fit.beta_interval[1]
    truth = stats.norm.cdf(np.log(fit.grid_si / 2.0) / 0.4)
    inside = np.mean((fit.band_lo - 0.02 <= truth) & (truth <= fit.band_hi + 0.02))
    assert inside > 0.9
    table = stripe_table(runs, "level")
    assert list(table["n_runs"]) == [400] * 9 and table["fraction"].is_monotonic_increasing


def test_failed_runs_are_left_out_and_counted():
    runs = _synthetic_runs(2.0, 0.4, 30, np.geomspace(0.5, 8.0, 6), seed=3)
    runs.loc[runs.index[:5], "status"] = "failed"
    table = stripe_table(runs, "level")
    assert int(table["n_failed"].sum()) == 5 and int(table["n_runs"].sum()) == len(runs) - 5


def test_levels_are_extended_towards_the_median():
    def table(fractions):
        return pd.DataFrame({"x": [1.0, 2.0, 4.0], "n_runs": [10] * 3, "fraction": fractions})

    assert _next_level(table([0.0, 0.1, 0.3]), "x") == pytest.approx(4.0 * EXTEND_RATIO)
    assert _next_level(table([0.6, 0.9, 1.0]), "x") == pytest.approx(1.0 / EXTEND_RATIO)
    assert _next_level(table([0.1, 0.5, 0.9]), "x") is None
    with pytest.raises(InputError):
        check_levels([0.2], Measure("pga"))
    with pytest.raises(InputError):
        check_levels([0.2, -0.1], Measure("pga"))
    assert check_levels([0.2, 0.1, 0.2], Measure("pga")) == pytest.approx((0.1 * CODE_GRAVITY, 0.2 * CODE_GRAVITY))


# ---------------------------------------------------------------------- real runs


def test_a_block_overturns_under_a_strong_pulse_and_not_under_a_weak_one(two_records):
    """Housner, the real solver: the 0.25 x 1 m block under the Ricker pulse scaled to PGA 0.1 g
    (below its uplift g tan(alpha) = 0.25 g: it cannot move) and to 3 g."""
    scene = scene_from_dict(stack(widths_m=[0.25], heights_m=1.0, layout="column", motion=rest_motion()))
    records = records_in_folder(two_records)
    plan = fragility_plan(
        scene, records, Measure("pga"), "housner", levels=[0.1, 3.0], executor=THREADS, progress=False
    )
    assert isinstance(plan.stripes, StripePlan) and plan.stripes.solver.name == "housner"
    assert plan.static_acceleration_m_s2 == pytest.approx(0.25 * G, rel=1e-9)
    ricker = 1  # sorted by name: record 21 first
    weak = plan.stripes.tasks([0.1 * G])[ricker]
    strong = plan.stripes.tasks([3.0 * G])[ricker]
    assert weak.load_factor == pytest.approx(0.1 * G / 3.0, rel=1e-6)  # its PGA is 3 m/s^2
    low, high = run_stripe_task(weak), run_stripe_task(strong)
    assert low["status"] == "completed" and not low["collapsed"] and low["max_theta_over_alpha"] == 0.0
    assert high["status"] == "overturned" and high["collapsed"]
    assert strong.scene.duration_s == pytest.approx(5.0 + 5.0)  # the record, then 5 s of free motion


def test_an_assembly_collapses_when_a_block_falls_in_the_reference_dem(two_records):
    """Two stacked blocks (0.2 x 0.4 m each) under the Ricker pulse: still at 0.05 g, fallen at 2 g."""
    data = stack(widths_m=[0.2, 0.2], heights_m=0.4, motion=rest_motion())
    scene = scene_from_dict(data)
    records = records_in_folder(two_records)
    plan = fragility_plan(
        scene, records, Measure("pga"), levels=[0.05, 2.0], executor=THREADS, progress=False, tail_s=2.0
    )
    assert plan.stripes.solver.name == "reference"
    low = run_stripe_task(plan.stripes.tasks([0.05 * G])[1])
    high = run_stripe_task(plan.stripes.tasks([2.0 * G])[1])
    assert low["status"] == "completed" and not low["collapsed"] and low["n_fallen"] == 0
    assert high["collapsed"] and high["n_fallen"] >= 1
    with pytest.raises(InputError):
        fragility_plan(scene, records, Measure("pga"), fallen_blocks=3, executor=THREADS, progress=False)


def test_a_fragility_analysis_runs_through_the_runner_and_writes_one_row_per_run(two_records):
    scene = wall_scene(0.25, 1.0)
    records = records_in_folder(two_records)
    plan = fragility_plan(
        scene, records, Measure("pga"), levels=[0.2, 0.6, 1.2, 2.4], extend=False, executor=THREADS, progress=False
    )
    result = run_fragility(plan, Executor("local", 2), progress=False)
    assert len(result.runs) == 8 and list(result.runs["run"]) == list(range(8))
    assert {"pga_m_s2", "pga_g", "load_factor", "collapsed", "status"} <= set(result.runs.columns)
    assert np.allclose(result.runs["pga_g"], np.repeat([0.2, 0.6, 1.2, 2.4], 2))
    assert not result.runs.loc[result.runs.pga_g == 0.2, "collapsed"].any()  # below g tan(alpha)
    data = result.to_dict()
    assert data["measure"]["name"] == "pga" and len(data["stripes"]) == 4
    assert "as read" in data["load_factor"]


@pytest.mark.slow
def test_the_verify_checks_of_limit_analysis_the_code_and_the_fit_pass(tmp_path):
    from rockyade.studies.verification import verify

    table = verify(tmp_path, ["kinematic", "code", "fragility_fit"], ["reference"])
    assert set(table["check"]) == {"kinematic", "code", "fragility_fit"}
    assert len(table) >= 20 and table["passed"].all(), table[~table["passed"]].to_string()


def test_finite_or_null_makes_json_strict():
    """A number that does not exist (NaN) or lies beyond the data (inf) is null, nested or not."""
    import math

    import numpy as np

    from rockyade.io.strict_json import finite_or_null

    data = {"beta": math.nan, "band": (1.0, np.float64("inf")), "rows": [{"fraction": -math.inf, "n": 3}], "s": "x"}
    assert finite_or_null(data) == {"beta": None, "band": [1.0, None], "rows": [{"fraction": None, "n": 3}], "s": "x"}


@pytest.mark.slow
def test_the_dem_pushover_of_the_example_wall_lands_on_the_codes_curve(tmp_path, capsys):
    """``rockyade assess --pushover`` on examples/free_standing_wall.toml (alpha0 = b / h = 0.1):
    the reference DEM's onset (held levels every 1 % of alpha0) is within 2 % of alpha0, the
    curve's first point sits on the code's a* axis (d* ~ 0, a* within 2 % of a0*), and the
    figure carries the DEM line over the code's curve."""
    from matplotlib import pyplot as plt

    from rockyade.cli import main
    from rockyade.figures.wall_assessment import plot_capacity
    from rockyade.scene import load_scene

    scene = load_scene(EXAMPLES / "free_standing_wall.toml")
    a = assess(scene, Site(1, "B", 0.25 * G, 1.0), fc=1.35, direction="+x")
    add_pushover(a, scene)
    kin, push = a.limit.kinematic, a.pushover
    assert kin is not None and push is not None
    assert kin.alpha0 == pytest.approx(0.1, rel=1e-9)
    assert abs(push.onset.multiplier / kin.alpha0 - 1.0) <= 0.02
    assert push.onset.below <= kin.alpha0 * (1 + 1e-6)
    d0, a0 = float(push.d_star_m[0]), float(push.a_star_m_s2[0])
    assert abs(d0) < 0.02 * kin.d0_star_m  # on the a* axis
    assert abs(a0 / kin.a0_star_m_s2 - 1.0) <= 0.02
    assert push.d_star_m[-1] > kin.d0_star_m  # the run went past the code's d0*: it overturned
    data = a.to_dict()
    assert data["pushover_onset_lambda"] == pytest.approx(push.onset.multiplier)
    assert data["pushover_onset_minus_alpha0_pct"] == pytest.approx(100 * (push.onset.multiplier / 0.1 - 1))
    fig, ax = plot_capacity(a)
    labels = [line.get_label() for line in ax.get_lines()]
    assert any(lab.startswith("reference DEM pushover") for lab in labels), labels
    dem = next(line for line in ax.get_lines() if line.get_label().startswith("reference DEM pushover"))
    assert np.asarray(dem.get_ydata())[0] == pytest.approx(a0)
    plt.close(fig)
    # the command: the option, the words, the JSON
    assert (
        main(
            [
                "assess",
                str(EXAMPLES / "free_standing_wall.toml"),
                *EC8_LC1,
                "--static-only",
                "--pushover",
                "--out",
                str(tmp_path / "out"),
            ]
        )
        == 0
    )
    assert "pushover (reference DEM" in capsys.readouterr().out
    written = json.loads((tmp_path / "out" / "assess.json").read_text())
    assert abs(written["pushover_onset_minus_alpha0_pct"]) <= 2.0
    assert (tmp_path / "out" / "assess.png").stat().st_size > 0


def test_the_figures_heading_wraps_to_its_panel(tmp_path, capsys):
    """An NTC 2018 site's line (~180 characters) is wrapped over the one panel of a static check,
    not drawn on one line that widened the PNG to twice the panel's width (6.4 inches at 130 dpi:
    832 px)."""
    import matplotlib.image

    from rockyade.cli import main

    site = ["--knowledge-level", "LC1", "--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B"]
    out = tmp_path / "out"
    code = main(["assess", str(EXAMPLES / "tuff_wall_roof.toml"), *site, "--static-only", "--out", str(out)])
    assert code == 0 and "NOT VERIFIED" in capsys.readouterr().out
    height, width = matplotlib.image.imread(out / "assess.png").shape[:2]
    assert width <= 1.1 * 6.4 * 130, (width, height)
