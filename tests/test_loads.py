"""Point loads ([[loads]]): validation, the closed form lambda = (W b + N d) / (W h_c) in
Housner's modified Eq 1 and the limit analysis, and free rocking of a loaded block in Housner
against the reference DEM."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.housner import housner_model
from rockyade.limit import limit_analysis
from rockyade.scene import scene_from_dict
from rockyade.solvers import run

from .processes import require_yade

MASS, WIDTH, HEIGHT = 1000.0, 0.4, 2.0
W = MASS * G
B, H_C = WIDTH / 2, HEIGHT / 2


def block_scene(loads, motion=None, duration=1.0, **extra):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": 0.001,
            "blocks": [{"name": "pier", "width_m": WIDTH, "height_m": HEIGHT, "thickness_m": 1.0, "mass_kg": MASS}],
            "motion": motion or {"type": "rest"},
            "loads": loads,
            **extra,
        }
    )


def top_load(x, n):
    """A vertical load n (N, downwards) on the top face at x (block frame: the base runs
    from -0.2 to 0.2 m)."""
    return [{"block": "pier", "point_m": [x, HEIGHT], "force_N": [0.0, -n]}]


def closed_form(n, d):
    """lambda = (W b + N d) / (W h_c): the block's statics about the pivot."""
    return (W * B + n * d) / (W * H_C)


@pytest.mark.parametrize(
    ("loads", "field", "words"),
    [
        ([{"block": "peir", "point_m": [0, 2], "force_N": [0, -1]}], "loads[0].block", "did you mean 'pier'"),
        ([{"block": "pier", "point_m": [0.3, 2.0], "force_N": [0, -1]}], "loads[0].point_m", "outside block pier"),
        ([{"block": "pier", "point_m": [0.0, 2.0], "force_N": [0, -1e9]}], "loads[0].force_N", "times the weight"),
        ([{"block": "pier", "point_m": [0.0, 2.0], "force_N": [0, -1e11]}], "loads[0].force_N", "within +/-1e+10 N"),
        ([{"block": "pier", "point_m": [0.0, 2.0], "force_N": [0, float("nan")]}], "loads[0].force_N[1]", "finite"),
        ([{"block": "pier", "point_m": [0.0, 2.0, 1.0], "force_N": [0, -1]}], "loads[0].point_m", "[x, y]"),
    ],
)
def test_bad_loads_are_refused_naming_the_field(loads, field, words):
    with pytest.raises(InputError) as info:
        block_scene(loads)
    assert info.value.field == field
    assert words in info.value.message


def test_a_load_on_a_fixed_block_is_refused():
    with pytest.raises(InputError, match="fixed") as info:
        scene_from_dict(
            {
                "duration_s": 1.0,
                "sample_dt_s": 0.01,
                "blocks": [
                    {"name": "f", "width_m": 1, "height_m": 0.2, "thickness_m": 1, "mass_kg": 10,
                     "position_m": [0, 0], "fixed": True},
                    {"name": "b", "width_m": 0.2, "height_m": 1, "thickness_m": 1, "mass_kg": 10,
                     "position_m": [0.4, 0.2]},
                ],
                "motion": {"type": "rest"},
                "loads": [{"block": "f", "point_m": [0.5, 0.2], "force_N": [0, -10]}],
            }
        )
    assert info.value.field == "loads[0].block"


def test_loads_are_in_the_canonical_scene_and_its_hash():
    plain = block_scene([])
    loaded = block_scene(top_load(0.1, 2000.0))
    assert loaded.to_dict()["loads"] == [{"block": "pier", "point_m": [0.1, 2.0], "force_N": [0.0, -2000.0]}]
    assert "loads" not in plain.to_dict()
    assert plain.scene_hash != loaded.scene_hash
    assert scene_from_dict(loaded.to_dict()) == loaded


@pytest.mark.parametrize(("x", "n"), [(0.1, 5000.0), (-0.15, 20000.0), (0.0, 3000.0)])
def test_housner_and_limit_analysis_give_the_closed_form(x, n):
    """Housner's uplift threshold (modified Eq 1) and the LP limit analysis: about the left
    pivot (a_h > 0, limit direction -x) the arm is d = x + b, about the right one b - x."""
    scene = block_scene(top_load(x, n))
    model = housner_model(scene)
    assert model.uplift_multiplier(+1) == pytest.approx(closed_form(n, x + B), rel=1e-12)
    assert model.uplift_multiplier(-1) == pytest.approx(closed_form(n, B - x), rel=1e-12)
    assert limit_analysis(scene, direction="-x").load_multiplier == pytest.approx(closed_form(n, x + B), rel=1e-6)
    assert limit_analysis(scene, direction="+x").load_multiplier == pytest.approx(closed_form(n, B - x), rel=1e-6)


def test_housner_onset_under_a_slow_ramp_is_the_closed_form():
    """A base acceleration rising at 0.05 g/s from 0: the block lifts when a_h / g reaches
    lambda (Housner's rest phase finds the crossing exactly on the ramp)."""
    n, x = 8000.0, 0.05
    rate = 0.05 * G
    t_end = 10.0
    motion = {"type": "sampled", "accel_m_s2": [0.0, rate * t_end], "t_s": [0.0, t_end]}
    result = run(block_scene(top_load(x, n), motion, duration=t_end), "housner")
    onset = result.meta["uplift_times_s"][0] * rate / G
    assert onset == pytest.approx(closed_form(n, x + B), rel=1e-9)
    unloaded = run(block_scene([], motion, duration=t_end), "housner")
    assert unloaded.meta["uplift_times_s"][0] * rate / G == pytest.approx(B / H_C, rel=1e-9)


def test_a_horizontal_load_lowers_the_threshold_on_its_side():
    """A horizontal push P at the top: lambda = (W b - P h) / (W h_c) about the pivot it tips towards."""
    p = 300.0
    scene = block_scene([{"block": "pier", "point_m": [0.0, HEIGHT], "force_N": [-p, 0.0]}])
    model = housner_model(scene)
    assert model.uplift_multiplier(+1) == pytest.approx((W * B - p * HEIGHT) / (W * H_C), rel=1e-12)
    assert limit_analysis(scene, direction="-x").load_multiplier == pytest.approx(
        (W * B - p * HEIGHT) / (W * H_C), rel=1e-6
    )


def first_crossings(theta, dt, count=3):
    return np.nonzero(np.diff(np.sign(theta)))[0][:count] * dt


def test_free_rocking_of_a_loaded_block_housner_against_the_reference_dem():
    """An eccentric top load (1.5 kN, 0.1 m right of the axis) released at 0.06 rad: both
    solvers cross theta = 0 at the same times within 0.5 %, and the load changes them
    (it is really applied)."""
    motion = {"type": "free", "theta0_rad": 0.06}
    loaded = block_scene(top_load(0.1, 1500.0), motion, duration=1.6)
    times = {}
    for name in ("housner", "reference"):
        result = run(loaded, name)
        assert result.meta["status"] == "completed"
        theta = result.frame[result.frame.columns[result.frame.columns.str.contains("theta")][0]].to_numpy()
        times[name] = first_crossings(theta, 0.001)
    assert len(times["housner"]) == 3
    np.testing.assert_allclose(times["reference"], times["housner"], rtol=5e-3)
    bare = run(block_scene([], motion, duration=1.6), "housner")
    theta = bare.frame[bare.frame.columns[bare.frame.columns.str.contains("theta")][0]].to_numpy()
    assert abs(first_crossings(theta, 0.001)[1] - times["housner"][1]) > 0.05


def test_a_load_that_tips_the_block_overturns_it_at_rest():
    """A horizontal load above the static threshold (P h > W b): the block at rest tips over in Housner."""
    p = 1.2 * W * B / HEIGHT
    scene = block_scene([{"block": "pier", "point_m": [0.0, HEIGHT], "force_N": [-p, 0.0]}], duration=3.0)
    assert run(scene, "housner").meta["status"] == "overturned"


def test_the_reference_dem_energy_balance_counts_the_loads_work():
    scene = block_scene(top_load(0.1, 1500.0), {"type": "free", "theta0_rad": 0.06}, duration=0.5)
    result = run(scene, "reference")
    weight_height = W * H_C
    assert result.meta["energy_balance_max_error_J"] < 1e-3 * weight_height
    assert math.isfinite(result.meta["initial_potential_energy_J"])


@pytest.mark.yade
def test_free_rocking_of_a_loaded_block_yade_against_the_reference_dem():
    """The same release in YADE (the load a non-colliding clump member, its force summed with
    its current arm): theta = 0 crossings within 0.5 % of the reference DEM's."""
    require_yade()
    scene = block_scene(top_load(0.1, 1500.0), {"type": "free", "theta0_rad": 0.06}, duration=1.6)
    times = {}
    for name in ("reference", "yade"):
        result = run(scene, name)
        assert result.meta["status"] == "completed"
        theta = result.frame[result.frame.columns[result.frame.columns.str.contains("theta")][0]].to_numpy()
        times[name] = first_crossings(theta, 0.001)
    assert len(times["yade"]) == 3
    np.testing.assert_allclose(times["yade"], times["reference"], rtol=5e-3)


def test_yade_refuses_a_couple_without_resultant():
    from rockyade.yade.backend import yade_model
    from rockyade.yade.payload import scene_payload

    couple = [
        {"block": "pier", "point_m": [0.0, HEIGHT], "force_N": [100.0, 0.0]},
        {"block": "pier", "point_m": [0.0, 0.0], "force_N": [-100.0, 0.0]},
    ]
    with pytest.raises(InputError, match="couple") as info:
        scene_payload(yade_model(block_scene(couple)))
    assert info.value.field == "loads"


def test_loads_act_without_energy_terms_and_in_a_batch_group():
    """Without energy terms a single block takes the fast single-body path, and grouped batch
    runs share one model: neither may drop the loads. The loaded block's theta is the same
    with and without energy terms, and a loaded scene is never grouped."""
    from rockyade.solvers import make_solver

    loaded = block_scene(top_load(0.1, 1500.0), {"type": "free", "theta0_rad": 0.06}, duration=1.0)
    bare = block_scene([], {"type": "free", "theta0_rad": 0.06}, duration=1.0)
    theta = {}
    for energy in (True, False):
        result = make_solver("reference", record_energy=energy).run(loaded)
        theta[energy] = result.frame[result.frame.columns[result.frame.columns.str.contains("theta")][0]].to_numpy()
    np.testing.assert_array_equal(theta[False], theta[True])
    fast = make_solver("reference", record_energy=False)
    free = fast.run(bare)
    theta_bare = free.frame[free.frame.columns[free.frame.columns.str.contains("theta")][0]].to_numpy()
    assert np.max(np.abs(theta_bare - theta[False])) > 1e-3
    assert fast.group_key(loaded) is None
    assert fast.group_key(bare) is not None


def test_housner_energy_counts_the_loads_potential_and_is_conserved_between_impacts():
    """A loaded block (1.5 kN, 0.1 m right of the axis, and 300 N horizontally, both on the top face)
    released at 0.06 rad rocks freely: HousnerModel.energy(), which adds the dead load's potential
    -F . u, is conserved between impacts to 1e-6 relative; without the loads' terms (the number it
    gave before) it is not (a change of several per cent within one half-cycle)."""
    import dataclasses
    import itertools

    from rockyade.housner import solve

    loads = [{"block": "pier", "point_m": [0.1, HEIGHT], "force_N": [300.0, -1500.0]}]
    model = housner_model(block_scene(loads, {"type": "free", "theta0_rad": 0.06}, duration=3.0))
    assert model.loaded and model.load_b_left != 0.0 and model.load_a_left != model.load_a_right
    bare = dataclasses.replace(model, load_a_left=0.0, load_b_left=0.0, load_a_right=0.0, load_b_right=0.0)
    traj = solve(model, None, 3.0, 0.06, sample_dt_s=0.0005)
    bounds = np.concatenate([[0.0], traj.impacts[:, 0], [3.0]])
    checked, worst_old = 0, 0.0
    for t0, t1 in itertools.pairwise(bounds):
        inside = (traj.t_s > t0 + 1e-6) & (traj.t_s < t1 - 1e-6) & (traj.theta_rad != 0.0)
        if inside.sum() < 10:
            continue
        theta, omega = traj.theta_rad[inside], traj.omega_rad_s[inside]
        side = 1 if theta[0] > 0 else -1
        e = np.array([model.energy(side, th, om) for th, om in zip(theta, omega, strict=True)])
        old = np.array([bare.energy(side, th, om) for th, om in zip(theta, omega, strict=True)])
        assert np.ptp(e) / abs(e[0]) < 1e-6
        worst_old = max(worst_old, float(np.ptp(old) / abs(old[0])))
        checked += 1
    assert checked >= 2, traj.impacts
    assert worst_old > 0.05, worst_old


def test_the_dem_settlement_check_counts_the_loads():
    """The static settlement check of the DEM's model counts the loads with the weights: one
    block on two springs K settles by (W + N) / (2 K). K is chosen so that the block alone
    settles half the limit (1e-4 of its height): a load N = 0.5 W gives 1.5 x that, and a load
    N = 5 W takes it three times past the limit and is refused (gravity alone, as before, passed it)."""
    from rockyade.calibration.model import calibrated_model
    from rockyade.constants import MAX_SETTLEMENT_FRACTION

    k = W / (2 * 0.5 * MAX_SETTLEMENT_FRACTION * HEIGHT)
    contact = {"calibration": "paper", "K_N_per_m": k}
    bare = calibrated_model(block_scene([], contact=contact))
    assert bare.static_settlement_m == pytest.approx(W / (2 * k), rel=1e-9)
    light = calibrated_model(block_scene(top_load(0.0, 0.5 * W), contact=contact))
    assert light.static_settlement_m == pytest.approx(1.5 * W / (2 * k), rel=1e-9)
    with pytest.raises(InputError) as info:
        calibrated_model(block_scene(top_load(0.0, 5.0 * W), contact=contact))
    assert info.value.field == "contact.K_N_per_m" and "sink" in str(info.value)
