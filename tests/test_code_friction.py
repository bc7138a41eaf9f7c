"""Friction that does not overstate the capacity (issue 33, item 2): where the associated mechanism
slides with friction, a coulomb (non-dilatant) pass runs and the code's quantities take the lower
multiplier; the output gives both and says which.

The case: the 8-course tuff wall restrained on the far face of its top course, the restraint's
contact with the top corner of the course below at the joints' 35 degrees, the roof without mass
(tests/limit_scenes.py): towards the restraint 3.5891 associated, 1.6205 coulomb; the same contact
frictionless 1.3019, the closed form of tests/test_restraints.py.
"""

from __future__ import annotations

import json

import pytest

from rockyade.cli import main
from rockyade.limit import limit_analysis
from rockyade.studies.verify_assess import squeezed_top

from .limit_scenes import block_scene, corner_friction_wall


def test_the_code_takes_the_coulomb_multiplier_where_the_mechanism_slides():
    result = limit_analysis(corner_friction_wall(), "+x", coulomb_check=True)
    check = result.friction_check
    assert check is not None and result.mechanism.slides
    assert result.load_multiplier == pytest.approx(3.5891, abs=5e-5)  # the associated programme's answer
    assert check.coulomb_multiplier == pytest.approx(1.6205, abs=5e-5)
    assert check.taken == "coulomb" and check.ratio == pytest.approx(3.5891 / 1.6205, rel=1e-4)
    code = result.for_code
    assert code.friction_rule == "coulomb" and code.kinematic.alpha0 == check.coulomb_multiplier
    data = result.to_dict()
    assert data["load_multiplier"] == result.load_multiplier and data["alpha0"] == check.coulomb_multiplier
    assert data["code_friction"]["associated"] == result.load_multiplier and data["code_friction"]["taken"] == "coulomb"


def test_a_frictionless_corner_gives_the_closed_form_under_both_rules():
    result = limit_analysis(corner_friction_wall(0.0), "+x", coulomb_check=True)
    assert result.load_multiplier == pytest.approx(squeezed_top(), rel=1e-9)
    assert round(squeezed_top(), 4) == 1.3019
    assert result.for_code.load_multiplier == pytest.approx(squeezed_top(), rel=1e-9)


def test_no_coulomb_pass_without_sliding_with_friction():
    result = limit_analysis(block_scene(0.4, 2.0), "+x", coulomb_check=True)
    assert result.friction_check is None and result.for_code is result
    assert result.load_multiplier == pytest.approx(0.2, rel=1e-12)


def test_limit_prints_both_and_says_which(tmp_path, capsys):
    from rockyade.scene.toml_writer import write_toml

    path = tmp_path / "wall.toml"
    write_toml(path, corner_friction_wall().to_dict())
    assert main(["limit", str(path)]) == 0
    out = capsys.readouterr().out
    assert "lambda = 3.5891" in out
    assert "associated (dilatant) lambda = 3.5891, coulomb (non-dilatant) lambda = 1.6205" in out
    assert "the code's quantities take the coulomb one, the lower of the two" in out
    assert "alpha0 = 1.6205" in out
    assert main(["limit", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["code_friction"]["coulomb"] == pytest.approx(1.6205, abs=5e-5) and data["alpha0"] == pytest.approx(
        1.6205, abs=5e-5
    )
    assert main(["limit", str(path), "--friction-rule", "associated"]) == 0
    out = capsys.readouterr().out
    assert "no coulomb pass was asked (--friction-rule associated)" in out and "alpha0 = 3.5891" in out


def test_assess_checks_the_coulomb_mechanism_and_gives_both(tmp_path, capsys):
    from rockyade.scene.toml_writer import write_toml

    path = tmp_path / "wall.toml"
    write_toml(path, corner_friction_wall().to_dict())
    site = ["--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B", "--static-only"]
    site += ["--knowledge-level", "LC1"]
    assert main(["assess", str(path), *site, "--direction", "+x"]) == 0
    out = capsys.readouterr().out
    assert "associated (dilatant) lambda = 3.5891, coulomb (non-dilatant) lambda = 1.6205" in out
    assert "kinematic quantities: alpha0 = 1.6205" in out
    assert main(["assess", str(path), *site, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    towards = data["other_direction"] if data["direction"] == "-x" else data
    friction = towards["code_friction"]
    assert friction["taken"] == "coulomb" and friction["associated"] == pytest.approx(3.5891, abs=5e-5)
