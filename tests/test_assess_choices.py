"""The engineer's choices in ``rockyade assess`` (issue 33, items 3 and 4): which way the wall can go
(the governing direction and the side the load is on, a floor or roof on the side it turns to, one
direction examined), and the confidence and behaviour factors (the knowledge level or FC, never a
silent default; q = 2 with its clause beside every linear check); CC printed with the site."""

from __future__ import annotations

import json

import pytest

from rockyade.assess.code import KNOWLEDGE_LEVELS, confidence_factor
from rockyade.cli import main
from rockyade.errors import InputError

from .conftest import EXAMPLES

ROOF = str(EXAMPLES / "tuff_wall_roof.toml")  # 2.4 x 0.36 m tuff, a 6 kN/m roof 0.05 m towards +x, with its mass
NTC = ["--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B", "--static-only"]


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_the_code_check_needs_a_knowledge_level_or_fc(capsys):
    code, out, err = run(capsys, "assess", ROOF, *NTC)
    assert code == 2 and out == ""
    assert "--knowledge-level" in err and "--fc" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        (["--knowledge-level", "LC4"], "--knowledge-level"),
        (["--knowledge-level", "high"], "--knowledge-level"),
        (["--fc", "0.9"], "--fc"),
        (["--knowledge-level", "LC2", "--fc", "1.2"], "--fc"),
    ],
)
def test_a_bad_knowledge_level_or_fc_exits_2_naming_the_field(capsys, extra, field):
    code, _, err = run(capsys, "assess", ROOF, *NTC, *extra)
    assert code == 2 and field in err and "Traceback" not in err


def test_the_knowledge_levels_give_the_codes_fc():
    assert KNOWLEDGE_LEVELS == {"LC1": 1.35, "LC2": 1.20, "LC3": 1.00}
    assert confidence_factor("lc2", None)[0] == 1.20
    assert "Tab. C8.5.IV" in confidence_factor("LC3", None)[1]
    assert confidence_factor(None, 1.1)[0] == 1.1
    with pytest.raises(InputError) as exc:
        confidence_factor(None, None)
    assert exc.value.field == "--knowledge-level"


@pytest.mark.slow
def test_fc_scales_a0_star_and_is_reported_with_its_source(capsys):
    data = {}
    for level in ("LC1", "LC2", "LC3"):
        code, out, _ = run(capsys, "assess", ROOF, *NTC, "--knowledge-level", level, "--json")
        assert code == 0
        data[level] = json.loads(out)
    assert data["LC1"]["FC"] == 1.35 and data["LC2"]["FC"] == 1.2 and data["LC3"]["FC"] == 1.0
    assert "knowledge level LC2" in data["LC2"]["FC_source"]
    ratio = data["LC3"]["a0_star_m_s2"] / data["LC1"]["a0_star_m_s2"]
    assert ratio == pytest.approx(1.35, rel=1e-12)  # a0* = alpha0 g / (e* FC)


@pytest.mark.slow
def test_q_and_its_clause_beside_every_linear_check(capsys):
    code, out, _ = run(capsys, "assess", ROOF, *NTC, "--knowledge-level", "LC1")
    assert code == 0
    assert "ag S / q = 1.961 x 1.2 / 2 = 1.177 m/s^2 (q = 2, Circolare 2019 C8.7.1)" in out
    height = ["--z", "6", "--building-height", "9", "--storeys", "3"]
    code, out, _ = run(capsys, "assess", ROOF, *NTC, "--knowledge-level", "LC1", *height)
    assert code == 0 and "(q = 2, Circolare 2019 C8.7.1)" in out.split("checks made:")[1]


def test_the_verdict_names_the_direction_and_the_loaded_side(capsys):
    code, out, _ = run(capsys, "assess", ROOF, *NTC, "--knowledge-level", "LC1")
    assert code == 0
    verdict = next(line for line in out.splitlines() if line.startswith("code verdict:"))
    assert "governed by the mechanism towards +x (the lower a0* of +x and -x)" in verdict
    assert "load 0 bears on w01 0.05 m towards +x of its axis" in verdict
    floor = [line for line in out.splitlines() if "the side load 0 bears on" in line]
    assert len(floor) == 1
    assert "--top floor" in floor[0] and "restrained-far" in floor[0] and "--direction -x" in floor[0]
    assert "CC = 1.3995" in out  # TC = CC TC* (Tab. 3.2.IV), printed with the site


def test_one_direction_examined_is_said_as_such(capsys):
    code, out, _ = run(capsys, "assess", ROOF, *NTC, "--knowledge-level", "LC1", "--direction=-x")
    assert code == 0
    assert "towards +x and -x are examined" not in out
    assert "only the section's mechanism towards -x is examined (--direction -x)" in out
    assert "governed by the mechanism towards -x (the only one examined: --direction -x)" in out
    assert "the side load 0 bears on" not in out  # it turns away from the roof's side
