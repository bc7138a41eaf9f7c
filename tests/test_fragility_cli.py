"""``rockyade fragility`` and ``rockyade assess``: outputs, JSON keys, exit codes, bad input."""

from __future__ import annotations

import json
import shutil

import pandas as pd
import pytest

from rockyade.cli import main
from rockyade.scene.generators import rest_motion, stack, write_scene

from .conftest import EC8_LC1, EXAMPLES

#: What the assessment's JSON holds at least (the brief's keys and the checks).
ASSESS_KEYS = (
    "alpha0",
    "e_star",
    "M_star_kg",
    "a0_star_m_s2",
    "d0_star_m",
    "du_star_m",
    "Ts_s",
    "checks",
    "verdict",
    "site",
    "position",
    "code_capacity_ag_g",
    "dynamic",
)
CHECK_KEYS = ("name", "demand", "capacity", "unit", "verdict", "source", "ag_capacity_g")


def strict_json(text: str) -> dict:
    """Parse as a strict parser would: NaN or Infinity is an error."""

    def refuse(constant: str) -> None:
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def run_cli(capsys, *argv: str) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture
def wall(tmp_path):
    """A free-standing wall 1 m high and 0.25 m thick (one block, a 1 m strip)."""
    path = tmp_path / "wall.toml"
    write_scene(path, stack(widths_m=[0.25], heights_m=1.0, thickness_m=1.0, layout="column", motion=rest_motion()))
    return path


@pytest.fixture
def records(tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    for name in ("ricker_pulse_T0.5s.AT2", "ec8_type2_D_record21.AT2"):
        shutil.copy(EXAMPLES / "records" / name, folder / name)
    return folder


def test_fragility_of_a_block_under_records_writes_every_output(capsys, tmp_path, wall, records):
    out = tmp_path / "frag"
    code, text, _ = run_cli(
        capsys, "fragility", wall, "--records", records, "--levels", "0.2,0.5,1,2", "--out", out, "--quiet"
    )
    assert code == 0
    assert "a load factor multiplies a record's accelerations as read" in text
    assert "cost: 8 runs of housner" in text and "stripes (pga in g" in text
    for name in ("runs.csv", "stripes.csv", "records.csv", "fragility.json", "fragility.png"):
        assert (out / name).is_file()
    runs = pd.read_csv(out / "runs.csv")
    assert len(runs) == 8 and set(runs["solver"]) == {"housner"}
    assert not runs.loc[runs.pga_g == 0.2, "collapsed"].any()  # below g tan(alpha) = 0.25 g nothing moves
    data = strict_json((out / "fragility.json").read_text())
    # two records: too few for a fit (fewer than 5: refused, saying so)
    assert data["measure"]["name"] == "pga" and data["fit"]["status"].startswith("not fitted: 2 records")
    assert data["collapse_rule"].startswith("the block overturns")
    assert data["levels_source"] == "given" and len(data["stripes"]) == 4


@pytest.mark.slow
def test_fragility_with_an_ec8_suite_in_sa(capsys, tmp_path, wall):
    out = tmp_path / "frag"
    code, text, _ = run_cli(
        capsys,
        "fragility",
        wall,
        "--suite",
        "ec8",
        "--spectrum-type",
        "1",
        "--ground",
        "B",
        "--ag",
        "0.25g",
        "--count",
        "2",
        "--intensity",
        "sa(0.5)",
        "--levels",
        "0.3,1.5",
        "--no-extend",
        "--out",
        out,
        "--quiet",
    )
    assert code == 0, text
    runs = pd.read_csv(out / "runs.csv")
    assert list(runs.columns[:6]) == ["run", "record", "record_index", "sa_m_s2", "sa_g", "load_factor"]
    assert "ec8-1B record 01" in set(runs["record"]) and len(runs) == 4
    data = json.loads((out / "fragility.json").read_text())
    assert data["measure"] == {"name": "sa(0.5 s)", "kind": "sa", "period_s": 0.5, "unit": "g"}
    assert data["motions"]["kind"] == "synthetic" and data["motions"]["count"] == 2


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--records", "REC", "--intensity", "pgd"], "--intensity"),
        (["--records", "REC", "--intensity", "sa"], "--intensity"),
        (["--records", "REC", "--levels", "0.2"], "--levels"),
        (["--records", "REC", "--levels", "a,b"], "--levels"),
        (["--records", "REC", "--seed", "3"], "--seed"),
        (["--records", "REC", "--ground", "B"], "--ground"),
        (["--suite", "ec8", "--spectrum-type", "1", "--ground", "B"], "--ag"),
        (["--suite", "ec8", "--spectrum-type", "3", "--ground", "B", "--ag", "0.2g"], "spectrum"),
        (["--suite", "ec8", "--spectrum-type", "1", "--ground", "B", "--ag", "0.2"], "--ag"),
        (["--suite", "ec8", "--spectrum-type", "1", "--ground", "B", "--ag", "0.2g", "--units", "g"], "--units"),
        (["--suite", "paper", "--ag", "0.2g"], "--ag"),
        (["--records", "REC", "--workers", "0"], "--workers"),
        (["--records", "REC", "--fallen-blocks", "2"], "--fallen-blocks"),
        (["--records", "REC", "--sample-dt", "5"], "--sample-dt"),
        (["--records", "REC", "--yade-timeout", "10"], "--yade-timeout"),
    ],
)
def test_fragility_bad_input_exits_2_with_one_line(capsys, tmp_path, wall, records, extra, message):
    argv = [str(records) if a == "REC" else a for a in extra]
    code, _, err = run_cli(capsys, "fragility", wall, *argv, "--out", tmp_path / "o", "--quiet")
    assert code == 2
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_a_level_out_of_a_records_reach_is_refused_before_any_run(capsys, tmp_path, wall, records):
    code, _, err = run_cli(
        capsys, "fragility", wall, "--records", records, "--levels", "0.5,40", "--out", tmp_path / "o"
    )
    assert code == 2 and "load factor" in err and not (tmp_path / "o" / "runs.csv").exists()


def test_a_solver_that_refuses_the_scene_is_refused_before_any_run(capsys, tmp_path, records):
    """--solver housner on the bi-block: one line naming blocks, exit 2, no --out (before, every
    run failed with that refusal and a set of failed runs was written, exit 1)."""
    code, _, err = run_cli(
        capsys,
        "fragility",
        EXAMPLES / "biblock_geometry.toml",
        "--records",
        records,
        "--solver",
        "housner",
        "--levels",
        "0.5,1",
        "--out",
        tmp_path / "o",
    )
    assert code == 2 and err.count("\n") == 1 and "blocks:" in err and "housner solver takes one block" in err
    assert not (tmp_path / "o").exists()


def test_an_out_that_holds_other_files_is_refused_before_any_run(capsys, tmp_path, wall, records):
    """A folder of another command's files (a comparison's) is refused, naming --out and one of
    them, and left as it was: the fragility's set would be mixed with them."""
    out = tmp_path / "o"
    out.mkdir()
    (out / "wall_compare.csv").write_text("block,solver\n")
    code, _, err = run_cli(capsys, "fragility", wall, "--records", records, "--levels", "0.5,1", "--out", out)
    assert code == 2 and err.count("\n") == 1 and "--out" in err and "wall_compare.csv" in err
    assert sorted(p.name for p in out.iterdir()) == ["wall_compare.csv"]


def test_assess_static_only_gives_the_documented_json(capsys, wall):
    code, text, _ = run_cli(
        capsys,
        "assess",
        wall,
        *EC8_LC1,
        "--static-only",
        "--json",
    )
    assert code == 0
    data = json.loads(text)
    for key in ASSESS_KEYS:
        assert key in data
    assert data["alpha0"] == pytest.approx(0.25) and data["e_star"] == pytest.approx(1.0)
    assert data["verdict"] == "verified" and data["dynamic"] is None  # a0* = 1.816 >= 1.471 m/s^2 (g = 9.80665)
    [linear, nonlinear] = data["checks"]
    for key in CHECK_KEYS:
        assert key in linear and key in nonlinear
    assert linear["demand"] == pytest.approx(0.25 * 9.80665 * 1.2 / 2) and linear["unit"] == "m/s^2"
    assert "C8.7.1" in linear["source"] and "Eq 3.7" in nonlinear["source"]


@pytest.mark.slow
def test_assess_text_and_files_with_the_dynamics(capsys, tmp_path, wall, records):
    out = tmp_path / "assess"
    code, text, _ = run_cli(
        capsys,
        "assess",
        wall,
        *EC8_LC1,
        "--records",
        records,
        "--load-factors",
        "0.5,2",
        "--no-extend",
        "--out",
        out,
        "--quiet",
    )
    assert code == 0, text
    assert "NOT VERIFIED" in text and "a0* = alpha0 g / (e* FC) = 1.816 m/s^2" in text
    assert "at the code's demand (lambda = 1, ag = 0.25 g)" in text
    # the code's verdict is printed before the runs start, the dynamic answer after them
    assert text.index("code verdict:") < text.index("runs planned") < text.index("runs of housner done")
    assert "dynamics: not run" not in text
    data = strict_json((out / "assess.json").read_text())
    assert data["dynamic"]["at_code_demand"]["n_runs"] == 2
    runs = pd.read_csv(out / "runs.csv")
    assert sorted(runs["ag_g"].unique()) == pytest.approx([0.125, 0.25, 0.5])
    # each record scaled to PGA = lambda ag S: the Ricker pulse's PGA is 3 m/s^2
    ricker = runs[runs.record.str.startswith("ricker")]
    assert ricker["load_factor"].to_numpy() == pytest.approx(ricker["ag_m_s2"].to_numpy() * 1.2 / 3.0, rel=1e-6)
    for name in ("assess.png", "stripes.csv", "records.csv"):
        assert (out / name).is_file()


def test_assess_at_height_uses_the_floor_demand(capsys, wall):
    code, text, _ = run_cli(
        capsys,
        "assess",
        wall,
        *EC8_LC1,
        "--z",
        "6",
        "--building-height",
        "9",
        "--storeys",
        "3",
        "--static-only",
    )
    assert code == 0
    assert "SeZ(T0 = 0 s, 5 %) / q" in text and "Ct H^(3/4)" in text
    assert text.rstrip().endswith("dynamics: not run (--static-only)")


@pytest.mark.parametrize(
    ("site", "extra", "option"),
    [
        ({}, ["--code", "ec8-3"], "--code"),
        ({"--spectrum-type": "3"}, [], "--spectrum-type"),
        ({"--ground": "F"}, [], "--ground"),
        ({"--ag": "0g"}, [], "--ag"),
        ({"--ag": "5g"}, [], "--ag"),
        ({"--ag": "0.25"}, [], "--ag"),
        ({}, ["--importance", "7"], "--importance"),
        ({}, ["--fc", "0.5"], "--fc"),
        ({}, ["--z", "10", "--building-height", "9", "--storeys", "3", "--static-only"], "--z"),
        ({}, ["--z", "3", "--static-only"], "--z"),
        ({}, ["--z", "3", "--building-height", "9", "--storeys", "3"], "--static-only"),
        ({}, ["--static-only", "--load-factors", "1,2"], "--load-factors"),
        ({}, ["--load-factors", "0,1"], "--load-factors"),
        ({}, ["--friction-angle-deg", "95"], "--friction-angle-deg"),
    ],
)
def test_assess_bad_input_exits_2_naming_the_option(capsys, wall, site, extra, option):
    given = {"--spectrum-type": "1", "--ground": "B", "--ag": "0.25g", **site}
    argv = [x for pair in given.items() for x in pair] + extra
    code, _, err = run_cli(capsys, "assess", wall, "--knowledge-level", "LC1", *argv, "--quiet")
    assert code == 2, err
    assert err.count("\n") == 1 and option in err and "Traceback" not in err


def test_a_wall_that_cannot_stand_exits_1_without_a_number(capsys, tmp_path):
    path = tmp_path / "overhang.toml"
    common = {"thickness_m": 0.2, "density_kg_m3": 2000.0}
    blocks = [
        {"name": "a", "width_m": 0.4, "height_m": 1.0, "position_m": [0, 0], **common},
        {"name": "b", "width_m": 0.4, "height_m": 0.2, "position_m": [0.35, 1], **common},
    ]
    write_scene(path, {"duration_s": 1.0, "sample_dt_s": 0.01, "blocks": blocks, "motion": rest_motion()})
    code, out, err = run_cli(
        capsys, "assess", path, "--knowledge-level", "LC1", "--spectrum-type", "1", "--ground", "B", "--ag", "0.2g"
    )
    assert code == 1 and "cannot stand" in err and out == ""
    code, out, err = run_cli(capsys, "fragility", path, "--suite", "paper", "--count", "1", "--out", tmp_path / "o")
    assert code == 1 and "cannot stand" in err


def test_both_commands_are_listed_in_the_help(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    assert "fragility" in text and "assess" in text
