"""Point loads ([[loads]]): validation, the closed forms lambda = (W b + N d) / (W h_c) without
the load's mass and (W b + N d) / (W h_c + N h_N) with it in Housner's modified Eq 1 and the
limit analysis, and free rocking of a loaded block in Housner against the reference DEM."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.constants import G
from rockyade.errors import InputError, InputNote
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


def top_load(x, n, mass=0.0):
    """A vertical load n (N, downwards) on the top face at x (block frame: the base runs
    from -0.2 to 0.2 m); ``mass``: its mass_kg (0: without mass; None: not given, the default
    mass of its weight n / g)."""
    load = {"block": "pier", "point_m": [x, HEIGHT], "force_N": [0.0, -n]}
    if mass is not None:
        load["mass_kg"] = mass
    return [load]


def closed_form(n, d, with_mass=False):
    """lambda = (W b + N d) / (W h_c) for a load without mass: the block's statics about the
    pivot; with the load's mass its horizontal force lambda N acts at the load's height h_N:
    lambda = (W b + N d) / (W h_c + N h_N)."""
    return (W * B + n * d) / (W * H_C + (n * HEIGHT if with_mass else 0.0))


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
                    {
                        "name": "f",
                        "width_m": 1,
                        "height_m": 0.2,
                        "thickness_m": 1,
                        "mass_kg": 10,
                        "position_m": [0, 0],
                        "fixed": True,
                    },
                    {
                        "name": "b",
                        "width_m": 0.2,
                        "height_m": 1,
                        "thickness_m": 1,
                        "mass_kg": 10,
                        "position_m": [0.4, 0.2],
                    },
                ],
                "motion": {"type": "rest"},
                "loads": [{"block": "f", "point_m": [0.5, 0.2], "force_N": [0, -10]}],
            }
        )
    assert info.value.field == "loads[0].block"


def test_loads_are_in_the_canonical_scene_and_its_hash():
    plain = block_scene([])
    loaded = block_scene(top_load(0.1, 2000.0))
    assert loaded.to_dict()["loads"] == [
        {"block": "pier", "point_m": [0.1, 2.0], "force_N": [0.0, -2000.0], "mass_kg": 0.0}
    ]
    assert "loads" not in plain.to_dict()
    assert plain.scene_hash != loaded.scene_hash
    assert scene_from_dict(loaded.to_dict()) == loaded
    default = block_scene(top_load(0.1, 2000.0, mass=None))
    assert "mass_kg" not in default.to_dict()["loads"][0]
    assert len({default.scene_hash, loaded.scene_hash, block_scene(top_load(0.1, 2000.0, 2000.0 / G)).scene_hash}) == 3


def test_a_negative_load_mass_is_refused():
    with pytest.raises(InputError) as info:
        block_scene(top_load(0.0, 100.0, mass=-1.0))
    assert info.value.field == "loads[0].mass_kg"


def test_a_load_mass_ten_times_its_weight_over_g_is_accepted_with_a_note(tmp_path, capsys):
    """Issue 34: mass_kg = 10 N / g was accepted silently (a unit slip, or a floor carried
    elsewhere): accepted as given, with a note naming the field, the ratio and the default; the
    command prints it as one line and exits 0. A mass within twice N / g, or none, says nothing."""
    import warnings

    from rockyade.cli import main

    with pytest.warns(
        InputNote, match=r"loads\[0\]\.mass_kg: 1\.019e\+04 kg is 10 times the load's weight / g"
    ) as notes:
        scene = block_scene(top_load(0.0, 10000.0, mass=10 * 10000.0 / G))
    assert scene.loads[0].mass_kg == pytest.approx(10 * 10000.0 / G)  # as given
    assert "mass_kg = -fy / g" in str(notes[0].message)
    with pytest.warns(InputNote, match="does not weigh on the block"):
        block_scene(top_load(0.0, 0.0, mass=500.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputNote)
        block_scene(top_load(0.0, 10000.0, mass=2 * 10000.0 / G))
        block_scene(top_load(0.0, 10000.0, mass=None))
        block_scene(top_load(0.0, 10000.0, mass=0.0))
    path = tmp_path / "heavy.toml"
    path.write_text(
        "duration_s = 1.0\nsample_dt_s = 0.01\n"
        '[[blocks]]\nname = "pier"\nwidth_m = 0.4\nheight_m = 2.0\nthickness_m = 1.0\nmass_kg = 1000\n'
        '[motion]\ntype = "rest"\n'
        '[[loads]]\nblock = "pier"\npoint_m = [0.0, 2.0]\nforce_N = [0.0, -5000.0]\nmass_kg = 5097\n'
    )
    assert main(["params", "--scene", str(path)]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line]
    assert len(err) == 1 and err[0].startswith("rockyade: note: ") and "loads[0].mass_kg: 5097 kg is 10 times" in err[0]


def test_the_default_mass_is_the_weight_over_g():
    """mass_kg omitted: the load's mass is -fy / g (the code's carried vertical load); the
    same scene with mass_kg = N / g written out gives the same multiplier."""
    n, x = 6000.0, 0.05
    implied = limit_analysis(block_scene(top_load(x, n, mass=None)), direction="+x", nonlinear=False).load_multiplier
    written = limit_analysis(block_scene(top_load(x, n, mass=n / G)), direction="+x", nonlinear=False).load_multiplier
    assert implied == pytest.approx(closed_form(n, B - x, with_mass=True), rel=1e-6)
    assert written == pytest.approx(implied, rel=1e-12)


@pytest.mark.parametrize("with_mass", [False, True])
@pytest.mark.parametrize(("x", "n"), [(0.1, 5000.0), (-0.15, 20000.0), (0.0, 3000.0)])
def test_housner_and_limit_analysis_give_the_closed_form(x, n, with_mass):
    """Housner's uplift threshold (modified Eq 1) and the LP limit analysis: about the left
    pivot (a_h > 0, limit direction -x) the arm is d = x + b, about the right one b - x; with
    the load's mass its horizontal force adds N h_N to the overturning moment."""
    scene = block_scene(top_load(x, n, mass=n / G if with_mass else 0.0))
    model = housner_model(scene)
    left, right = closed_form(n, x + B, with_mass), closed_form(n, B - x, with_mass)
    assert model.uplift_multiplier(+1) == pytest.approx(left, rel=1e-12)
    assert model.uplift_multiplier(-1) == pytest.approx(right, rel=1e-12)
    assert limit_analysis(scene, direction="-x", nonlinear=False).load_multiplier == pytest.approx(left, rel=1e-6)
    assert limit_analysis(scene, direction="+x", nonlinear=False).load_multiplier == pytest.approx(right, rel=1e-6)


def test_the_engineers_roof_by_hand():
    """A 2.4 m tuff wall 0.36 m thick (1600 kg/m^3), per metre: W = 1600 x 9.81 x 0.36 x 2.4
    = 13561.34 N, b = 0.18 m, h_c = 1.2 m; a timber roof N = 6 kN/m at 0.05 m from the axis
    towards +x, so its lever about the +x pivot is d = 0.18 - 0.05 = 0.13 m and h_N = 2.4 m:
    without its mass alpha0 = (13561.34 x 0.18 + 6000 x 0.13) / (13561.34 x 1.2)
    = 3221.04 / 16273.61 = 0.19793; with it (13561.34 x 1.2 + 6000 x 2.4 = 30673.61)
    alpha0 = 3221.04 / 30673.61 = 0.10501 (the engineer's "about 0.105").
    e* with the roof as a P_i: s1 = 1382.4 x 1.2 + 611.62 x 2.4 = 3126.78,
    s2 = 1382.4 x 1.44 + 611.62 x 5.76 = 5513.31, M* = s1^2 / s2 = 1773.3 kg, e* = 1773.3 / 1994.02 = 0.8893."""
    from rockyade.scene.generators.wall_sections import wall_section

    lam = {}
    kin = {}
    for with_mass in (False, True):
        data = wall_section(
            height_m=2.4,
            thickness_m=0.36,
            density_kg_m3=1600.0,
            overburden_n_per_m=6000.0,
            overburden_eccentricity_m=0.05,
            motion={"type": "rest"},
        )
        if not with_mass:
            data["loads"] = [{**q, "mass_kg": 0.0} for q in data["loads"]]
        result = limit_analysis(scene_from_dict(data), direction="+x")
        lam[with_mass], kin[with_mass] = result.load_multiplier, result.kinematic
    assert lam[False] == pytest.approx(3221.04 / 16273.61, rel=1e-5)
    assert round(lam[False], 3) == 0.198
    assert lam[True] == pytest.approx(3221.04 / 30673.61, rel=1e-5)
    assert round(lam[True], 3) == 0.105
    assert kin[False].e_star == pytest.approx(1.0, rel=1e-9)
    assert kin[True].M_star_kg == pytest.approx(3126.78**2 / 5513.31, rel=1e-4)
    assert kin[True].e_star == pytest.approx(0.8893, abs=1e-4)
    assert kin[True].participating_mass_kg == pytest.approx(1382.4 + 6000.0 / G, rel=1e-9)


def test_housner_onset_under_a_slow_ramp_is_the_closed_form():
    """A base acceleration rising at 0.05 g/s from 0: the block lifts when a_h / g reaches
    lambda (Housner's rest phase finds the crossing exactly on the ramp)."""
    n, x = 8000.0, 0.05
    rate = 0.05 * G
    t_end = 10.0
    motion = {"type": "sampled", "accel_m_s2": [0.0, rate * t_end], "t_s": [0.0, t_end]}
    result = run(block_scene(top_load(x, n), motion, duration=t_end), "housner")
    onset = result.meta.extra["uplift_times_s"][0] * rate / G
    assert onset == pytest.approx(closed_form(n, x + B), rel=1e-9)
    unloaded = run(block_scene([], motion, duration=t_end), "housner")
    assert unloaded.meta.extra["uplift_times_s"][0] * rate / G == pytest.approx(B / H_C, rel=1e-9)


def test_a_horizontal_load_lowers_the_threshold_on_its_side():
    """A horizontal push P at the top: lambda = (W b - P h) / (W h_c) about the pivot it tips towards."""
    p = 300.0
    scene = block_scene([{"block": "pier", "point_m": [0.0, HEIGHT], "force_N": [-p, 0.0]}])
    model = housner_model(scene)
    assert model.uplift_multiplier(+1) == pytest.approx((W * B - p * HEIGHT) / (W * H_C), rel=1e-12)
    assert limit_analysis(scene, direction="-x", nonlinear=False).load_multiplier == pytest.approx(
        (W * B - p * HEIGHT) / (W * H_C), rel=1e-6
    )


def first_crossings(theta, dt, count=3):
    return np.nonzero(np.diff(np.sign(theta)))[0][:count] * dt


@pytest.mark.parametrize("mass", [0.0, 1500.0 / G, 750.0 / G])
def test_free_rocking_of_a_loaded_block_housner_against_the_reference_dem(mass):
    """An eccentric top load (1.5 kN, 0.1 m right of the axis) released at 0.06 rad, without
    mass, with the mass of its weight and with half of it (the rest of its force without
    mass): both solvers cross theta = 0 at the same times within 0.5 % (Housner's p, alpha and
    mu of the loaded block against the DEM's merged body), and the load changes them (it is
    really applied)."""
    motion = {"type": "free", "theta0_rad": 0.06}
    loaded = block_scene(top_load(0.1, 1500.0, mass), motion, duration=1.6 if mass == 0.0 else 2.2)
    times = {}
    for name in ("housner", "reference"):
        result = run(loaded, name)
        assert result.meta.status == "completed"
        theta = result.frame[result.frame.columns[result.frame.columns.str.contains("theta")][0]].to_numpy()
        times[name] = first_crossings(theta, 0.001)
    assert len(times["housner"]) == 3
    np.testing.assert_allclose(times["reference"], times["housner"], rtol=5e-3)
    bare = run(block_scene([], motion, duration=2.2), "housner")
    theta = bare.frame[bare.frame.columns[bare.frame.columns.str.contains("theta")][0]].to_numpy()
    assert abs(first_crossings(theta, 0.001)[1] - times["housner"][1]) > 0.05


def test_a_load_that_tips_the_block_overturns_it_at_rest():
    """A horizontal load above the static threshold (P h > W b): the block at rest tips over in Housner."""
    p = 1.2 * W * B / HEIGHT
    scene = block_scene([{"block": "pier", "point_m": [0.0, HEIGHT], "force_N": [-p, 0.0]}], duration=3.0)
    assert run(scene, "housner").meta.status == "overturned"


def test_the_reference_dem_energy_balance_counts_the_loads_work():
    scene = block_scene(top_load(0.1, 1500.0), {"type": "free", "theta0_rad": 0.06}, duration=0.5)
    result = run(scene, "reference")
    weight_height = W * H_C
    assert result.meta.extra["energy_balance_max_error_J"] < 1e-3 * weight_height
    assert math.isfinite(result.meta.extra["initial_potential_energy_J"])


@pytest.mark.yade
@pytest.mark.parametrize("mass", [0.0, 1500.0 / G])
def test_free_rocking_of_a_loaded_block_yade_against_the_reference_dem(mass):
    """The same release in YADE (the load a non-colliding clump member, its force summed with
    its current arm; its mass in the body's from the DEM model): theta = 0 crossings within
    0.5 % of the reference DEM's."""
    require_yade()
    scene = block_scene(top_load(0.1, 1500.0, mass), {"type": "free", "theta0_rad": 0.06}, duration=2.2)
    times = {}
    for name in ("reference", "yade"):
        result = run(scene, name)
        assert result.meta.status == "completed"
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
    from rockyade.calibration.model_stage import calibrated_model
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
