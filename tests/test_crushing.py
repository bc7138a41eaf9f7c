"""Masonry that crushes at the hinges (issue 33, item 6): with fm the hinges move into their joints
by the stress block's resultant, a / 2 with a = N / (0.85 fm t), iterated with the limit analysis'
normal forces to a fixed point; the multiplier falls as fm falls and tends to the rigid one.

Closed form for one block of width B, height H and weight W on the base: the base carries N = W
whatever lambda, so lambda = (B/2 - a/2) / (H/2) = (B - a) / H, a = W / (0.85 fm t).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from rockyade.cli import main
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.limit import limit_analysis
from rockyade.limit.crushing import STRESS_BLOCK_FACTOR

from .conftest import EXAMPLES
from .limit_scenes import block_scene, course_wall_scene


def one_block(fm_mpa: float, width: float = 0.25, height: float = 2.5, density: float = 1800.0) -> float:
    weight = density * width * height * 0.4 * G  # block_scene's blocks are 0.4 m deep
    a = weight / (STRESS_BLOCK_FACTOR * fm_mpa * 1e6 * 0.4)
    return (width - a) / height


@pytest.mark.parametrize("fm", [0.3, 1.0, 3.0, 30.0])
def test_one_block_against_the_closed_form(fm):
    scene = block_scene(0.25, 2.5, density=1800.0)
    result = limit_analysis(scene, "+x", fm_MPa=fm)
    assert result.crushing is not None and result.crushing.converged
    assert result.load_multiplier == pytest.approx(one_block(fm), rel=1e-9)
    kin = result.kinematic
    assert kin.d0_star_m == pytest.approx(one_block(fm) * 2.5 / 2, rel=1e-4)  # the centroid over the moved hinge


@pytest.mark.slow
def test_the_multiplier_falls_with_fm_and_tends_to_the_rigid_one():
    scene = course_wall_scene(6, unit_length=0.5, unit_height=0.4)
    rigid = limit_analysis(scene, "+x", nonlinear=False).load_multiplier
    fms = [0.2, 0.5, 1.0, 3.0, 10.0, 100.0, 1e4, 1e6]
    lams = [limit_analysis(scene, "+x", fm_MPa=fm, nonlinear=False).load_multiplier for fm in fms]
    assert np.all(np.diff(lams) > 0.0) and lams[-1] < rigid
    gaps = rigid - np.array(lams)
    # the loss of capacity goes as 1/fm once the hinges move little: 100 times fm, 1/100 of the loss
    assert gaps[-1] == pytest.approx(gaps[-2] / 100.0, rel=1e-2)
    assert lams[-1] == pytest.approx(rigid, rel=1e-6)


def test_a_joint_that_cannot_carry_its_force_is_named():
    result = limit_analysis(block_scene(0.25, 2.5, density=1800.0), "+x", fm_MPa=0.01, nonlinear=False)
    assert result.crushing is not None and result.crushing.crushed == ["b01-base"]


def test_fm_must_be_positive():
    with pytest.raises(InputError, match="fm_MPa"):
        limit_analysis(block_scene(0.25, 2.5), "+x", fm_MPa=0.0)


@pytest.mark.parametrize("command", ["limit", "assess"])
@pytest.mark.parametrize("value", ["0", "-1", "nan"])
def test_fm_at_or_below_zero_exits_2_naming_it(command, value, capsys):
    site = ["--spectrum-type", "1", "--ground", "B", "--ag", "0.25g", "--static-only", "--knowledge-level", "LC1"]
    argv = [command, str(EXAMPLES / "free_standing_wall.toml"), "--fm", value] + (site if command == "assess" else [])
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--fm" in err and err.count("\n") == 1


@pytest.mark.slow
def test_assess_lists_crushing_among_the_checks_made(capsys):
    wall = str(EXAMPLES / "free_standing_wall.toml")
    site = ["--spectrum-type", "1", "--ground", "B", "--ag", "0.25g", "--static-only", "--knowledge-level", "LC1"]
    assert main(["assess", wall, *site, "--fm", "1"]) == 0
    out = capsys.readouterr().out
    made = out[out.index("checks made:") : out.index("code verdict:")]
    assert "masonry crushing at the hinges, fm = 1 MPa" in made and "0.85 fm" in made
    assert "finite compressive strength" not in out[out.index("checks not made:") :]
    assert main(["assess", wall, *site, "--fm", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["fm_MPa"] == 1.0 and data["crushing"]["converged"]
    assert data["alpha0"] == pytest.approx((0.25 - 1125 * G / (0.85e6)) / 2.5, rel=1e-9)
