"""A scene whose loads no equilibrium at rest can carry is refused by every solver before it runs,
naming the load and the block, and the limit analysis' "unstable" says the same (issue 26 item 4:
one block of 11 kN under an upward 20 kN load was "completed" by all three solvers)."""

from __future__ import annotations

import pytest

from rockyade.cli import main
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.limit import limit_analysis
from rockyade.limit.report_text import text_report
from rockyade.limit.standing import check_loads_stand, unbalanced_loads
from rockyade.scene import scene_from_dict
from rockyade.solvers import make_solver, run, solver_names

MASS = 1121.7  # kg: a weight of 11 kN


def scene(loads, blocks=None, friction_deg=30.0):
    blocks = blocks or [{"name": "b", "width_m": 0.4, "height_m": 1.4, "thickness_m": 1.0, "mass_kg": MASS}]
    return scene_from_dict(
        {
            "duration_s": 0.5,
            "sample_dt_s": 0.001,
            "blocks": blocks,
            "contact": {"calibration": "paper", "friction_angle_deg": friction_deg},
            "motion": {"type": "rest"},
            "loads": loads,
        }
    )


LIFT = [{"block": "b", "point_m": [0.0, 1.4], "force_N": [0.0, 20000.0]}]


def two_courses(load_y: float):
    """A stack of two 0.4 x 0.7 m blocks; the top one pulled up by ``load_y`` N at its top."""
    blocks = [
        {"name": "lower", "width_m": 0.4, "height_m": 0.7, "thickness_m": 1.0, "mass_kg": 500.0, "position_m": [0, 0]},
        {
            "name": "upper",
            "width_m": 0.4,
            "height_m": 0.7,
            "thickness_m": 1.0,
            "mass_kg": 500.0,
            "position_m": [0, 0.7],
        },
    ]
    return scene([{"block": "upper", "point_m": [0.0, 1.4], "force_N": [0.0, load_y]}], blocks)


@pytest.mark.parametrize("solver", solver_names())
def test_every_solver_refuses_a_block_its_load_lifts_off(solver):
    with pytest.raises(InputError) as info:
        make_solver(solver).run(scene(LIFT))
    assert info.value.field == "loads[0]"
    message = info.value.message
    assert "(0, 20000) N on b" in message and "lifts b off" in message and "unstable" in message


def test_a_top_course_pulled_off_names_the_top_block_only():
    found = unbalanced_loads(two_courses(6000.0))  # the upper block weighs 4903 N
    assert found is not None
    assert found.moving == ("upper",) and found.lifted == ("upper",) and found.loads == (0,) and found.flies_apart
    assert found.carried_fraction == pytest.approx(500.0 * G / 6000.0, rel=1e-6)
    assert unbalanced_loads(two_courses(4000.0)) is None  # less than its weight: carried


def test_a_horizontal_load_past_the_overturning_one_is_a_collapse_not_a_flight():
    # overturns at F = W b / h_c = 11 kN x 0.2 / 0.7 = 3.14 kN (friction 30 deg would carry 6.35 kN)
    push = [{"block": "b", "point_m": [0.0, 0.7], "force_N": [4000.0, 0.0]}]
    found = unbalanced_loads(scene(push))
    assert found is not None and found.moving == ("b",) and found.lifted == () and not found.flies_apart
    assert "overturns or slides b at rest" in found.message
    check_loads_stand(scene(push))  # it runs: the dynamics show the collapse
    assert found.carried_fraction == pytest.approx(MASS * G * 0.2 / 0.7 / 4000.0, rel=1e-6)
    assert unbalanced_loads(scene([{"block": "b", "point_m": [0.0, 0.7], "force_N": [3000.0, 0.0]}])) is None


def test_a_carried_load_still_runs():
    result = run(scene([{"block": "b", "point_m": [0.0, 1.4], "force_N": [0.0, -2000.0]}]), "housner")
    assert result.meta.status == "completed"


def test_the_limit_analysis_says_unstable_with_the_same_words(tmp_path, capsys):
    limit = limit_analysis(scene(LIFT))
    assert limit.status == "unstable"
    text = "\n".join(text_report(limit))
    assert "lifts b off its supports" in text
    path = tmp_path / "fly.json"
    path.write_text(__import__("json").dumps(scene(LIFT).to_dict()))
    assert main(["run", str(path), "--solver", "reference", "--out", str(tmp_path / "r.csv")]) == 2
    assert "loads[0]" in capsys.readouterr().err
    assert not (tmp_path / "r.csv").exists()
