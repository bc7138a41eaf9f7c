"""``rockyade limit`` bounded like ``run`` (issue 26 item 6): a cost estimate before the programme,
refusal above the documented limits without --allow-large, progress of the coulomb iterations and a
time limit; the programme assembled from arrays gives the same matrix."""

from __future__ import annotations

from pathlib import Path

import pytest

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.limit import analysis_cost as limit_cost
from rockyade.limit import limit_analysis
from rockyade.limit.coulomb import solve_coulomb
from rockyade.limit.lp import equilibrium_system, highs_method, solve_equilibrium
from rockyade.limit.rigid_blocks import rigid_block_model
from rockyade.scene import load_scene

WALL = Path(__file__).resolve().parents[1] / "examples" / "assemblies" / "wall_5_courses.toml"


@pytest.fixture(scope="module")
def model():
    return rigid_block_model(load_scene(WALL))


def test_the_estimate_counts_the_programme_it_will_solve(model):
    cost = limit_cost.estimate_limit_cost(model, "associated")
    A = equilibrium_system(model, "+x")[0]
    assert (cost.rows, cost.variables, cost.nonzeros) == (A.shape[0], A.shape[1], A.nnz)
    assert cost.blocks == model.n_blocks and cost.joints == len(model.interfaces)
    assert cost.programmes == cost.max_programmes == 1
    coulomb = limit_cost.estimate_limit_cost(model, "coulomb", max_iterations=7)
    assert (coulomb.programmes, coulomb.max_programmes) == (8, 8)
    assert coulomb.expected_time_s == pytest.approx(8 * cost.expected_time_s)
    assert "expected" in cost.describe() and "MB" in cost.describe()


def test_an_analysis_above_the_limits_is_refused_unless_allowed(model, monkeypatch, capsys):
    monkeypatch.setattr(limit_cost, "LIMITS", {"expected_time_s": 1e-12, "memory_bytes": 1e15})
    with pytest.raises(InputError, match="--allow-large"):
        limit_cost.check_limit_cost(limit_cost.estimate_limit_cost(model))
    assert main(["limit", str(WALL)]) == 2
    err = capsys.readouterr().err
    assert "cost:" in err and "--allow-large" in err
    assert main(["limit", str(WALL), "--allow-large", "--json"]) == 0
    assert '"cost"' in capsys.readouterr().out


def test_the_coulomb_iterations_report_progress_and_stop_at_the_time_limit(model):
    start = solve_equilibrium(model, "+x")
    seen = []
    done = solve_coulomb(model, start, on_iteration=lambda k, lam, s: seen.append((k, lam)))
    assert done.converged and [k for k, _ in seen] == list(range(1, done.iterations + 1))
    assert seen[-1][1] == pytest.approx(done.solution.load_multiplier)
    stopped = solve_coulomb(model, start, time_limit_s=0.0)
    assert not stopped.converged and stopped.iterations == 0
    assert "time limit of 0 s" in stopped.reason


@pytest.mark.parametrize("value", ["0", "-1", "nan", "1e9"])
def test_a_bad_time_limit_is_refused(value, capsys):
    assert main(["limit", str(WALL), f"--time-limit={value}"]) == 2
    assert "--time-limit" in capsys.readouterr().err
    with pytest.raises(InputError, match="time_limit_s"):
        limit_analysis(load_scene(WALL), time_limit_s=float(value))


def test_the_method_is_the_interior_point_one_where_it_was_measured_faster():
    assert highs_method("highs", 100) == "highs-ds"
    assert highs_method("highs", 11485) == "highs-ipm"  # the 999-block wall
    assert highs_method("highs", 35329) == "highs-ds"  # the 3,015-block wall: ipm's crossover imprecise
    assert highs_method("highs-ds", 10**6) == "highs-ds"


def test_the_interior_point_method_gives_the_same_multiplier(model):
    ds = solve_equilibrium(model, "+x", method="highs-ds")
    ipm = solve_equilibrium(model, "+x", method="highs-ipm")
    assert ipm.load_multiplier == pytest.approx(ds.load_multiplier, rel=1e-6)
