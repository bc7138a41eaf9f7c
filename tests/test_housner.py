"""Exact Housner solver (paper Eq 1)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from rockyade.blocks.restitution import effective_restitution, find_peaks, restitution_per_impact
from rockyade.constants import G
from rockyade.housner import HousnerModel, solve
from rockyade.motion.ground import GroundMotion
from rockyade.scene import scene_from_dict
from rockyade.solvers.housner import HousnerSolver

from .conftest import free_scene_dict

SPEC1 = HousnerModel.symmetric(0.235, 3.84, 0.936)


@pytest.mark.parametrize("ratio", [0.2, 0.5, 0.8])
def test_linearised_quarter_period_for_small_alpha(ratio):
    """Release at theta0 = ratio * alpha: the first impact comes after a quarter period
    (1/p) arccosh(1 / (1 - theta0/alpha)) of the linearised equation; the nonlinear
    solution tends to it as alpha -> 0 (error O(alpha^2))."""
    alpha, p = 0.005, 3.0
    model = HousnerModel.symmetric(alpha, p, 1.0)
    traj = solve(model, None, 2.0, ratio * alpha)
    expected = math.acosh(1.0 / (1.0 - ratio)) / p
    assert traj.impacts[0][0] == pytest.approx(expected, rel=2e-5)


def test_each_impact_multiplies_omega_by_mu_exactly():
    traj = solve(SPEC1, None, 4.0, 0.1175)
    assert len(traj.impacts) >= 8
    for _, before, after in traj.impacts:
        assert after / before == pytest.approx(0.936, rel=1e-14)


def test_effective_restitution_from_peaks_equals_mu():
    traj = solve(SPEC1, None, 4.0, 0.1175)
    peaks = traj.peaks[:, 1]
    per_impact = restitution_per_impact(np.concatenate([[0.1175], peaks]), 0.235)
    assert np.max(np.abs(per_impact - 0.936)) < 1e-6
    assert np.all(np.sign(peaks[1:]) == -np.sign(peaks[:-1]))  # alternate sides


def test_energy_conserved_between_impacts():
    traj = solve(SPEC1, None, 4.0, 0.1175, sample_dt_s=0.0005)
    bounds = np.concatenate([[0.0], traj.impacts[:, 0], [4.0]])
    checked = 0
    for t0, t1 in itertools.pairwise(bounds):
        inside = (traj.t_s > t0) & (traj.t_s < t1)
        if inside.sum() < 10:
            continue
        side = 1 if traj.theta_rad[inside][0] > 0 else -1
        e = [
            SPEC1.energy(side, th, om) for th, om in zip(traj.theta_rad[inside], traj.omega_rad_s[inside], strict=True)
        ]
        assert (max(e) - min(e)) / abs(e[0]) < 1e-8
        checked += 1
    assert checked >= 8


def test_free_rocking_dies_out_to_rest():
    traj = solve(SPEC1, None, 30.0, 0.1175)
    assert traj.status == "completed"
    assert np.all(traj.theta_rad[-1000:] == 0.0) and np.all(traj.omega_rad_s[-1000:] == 0.0)
    assert traj.t_s[-1] == pytest.approx(30.0)


def test_block_at_rest_below_uplift_and_rocks_just_above():
    uplift = G * math.tan(0.235)
    t = np.linspace(0.0, 3.0, 301)
    below = GroundMotion(t, 0.999 * uplift * np.sin(2 * math.pi * t))
    traj = solve(SPEC1, below, 3.0)
    assert traj.uplift_times_s.size == 0 and np.all(traj.theta_rad == 0.0)
    above = GroundMotion(t, 1.01 * uplift * np.sin(2 * math.pi * t))
    traj = solve(SPEC1, above, 3.0)
    assert traj.uplift_times_s.size
    # the crossing of a_h = g tan(alpha) is exact on the linear segment
    t_up = traj.uplift_times_s[0]
    assert 1.01 * uplift * np.interp(t_up, t, np.sin(2 * math.pi * t)) == pytest.approx(uplift, rel=1e-9)
    assert np.max(np.abs(traj.theta_rad)) > 1e-6 and traj.n_impacts > 0


def test_positive_base_acceleration_tilts_towards_positive_theta():
    t = np.array([0.0, 0.05, 0.3])
    motion = GroundMotion(t, np.array([0.0, 5.0, 0.0]))
    traj = solve(SPEC1, motion, 0.6)
    assert traj.peaks[0, 1] > 0


def test_overturning_detected_with_time():
    traj = solve(SPEC1, None, 5.0, 0.24)  # released beyond alpha: falls
    assert traj.status == "overturned"
    assert traj.overturn_time_s is not None and 0 < traj.overturn_time_s < 5.0
    assert traj.alpha_exceeded_time_s is None or traj.alpha_exceeded_time_s < traj.overturn_time_s


def test_overturn_by_strong_pulse():
    t = np.linspace(0, 2, 2001)
    a = np.where(t < 0.5, 3.0 * G * math.tan(0.235) * np.sin(2 * math.pi * t), 0.0)
    traj = solve(SPEC1, GroundMotion(t, a), 6.0)
    assert traj.status == "overturned"
    assert traj.alpha_exceeded_time_s < traj.overturn_time_s


def test_asymmetric_model_uses_both_pivots():
    model = HousnerModel(0.2, 0.3, 3.5, 3.9, 0.92, 0.85)
    traj = solve(model, None, 3.0, 0.1)
    ratios = [after / before for _, before, after in traj.impacts[:4]]
    assert ratios[0] == pytest.approx(0.92) and ratios[1] == pytest.approx(0.85)


def test_run_scene_csv_peak_decay_gives_mu(tmp_path):
    scene = scene_from_dict(free_scene_dict())
    result = HousnerSolver().run(scene)
    out = tmp_path / "r.csv"
    result.write(out)
    from rockyade.result import Result

    back = Result.read(out)
    peaks = find_peaks(back.t, back.series("theta_rad"))
    mu = effective_restitution(peaks, 0.235, n_impacts=5)
    assert mu == pytest.approx(0.936, abs=2e-5)
    assert back.meta.status == "completed" and back.meta.solver == "housner"
    assert back.frame["t_s"].iloc[0] == 0.0
    assert np.allclose(np.diff(back.frame["t_s"]), 0.001)


def test_run_scene_refuses_stacks(examples_dir):
    from rockyade.errors import InputError
    from rockyade.scene import load_scene

    with pytest.raises(InputError, match="one block"):
        HousnerSolver().run(load_scene(examples_dir / "biblock_free.toml"))


def test_overturned_history_ends_at_overturn():
    scene = scene_from_dict(free_scene_dict(theta0=0.24, duration=5.0))
    result = HousnerSolver().run(scene)
    assert result.status == "overturned"
    assert result.t[-1] <= result.meta.overturn_time_s
    assert result.meta.overturned_block == "specimen1"


def test_top_acceleration_at_rest_is_the_base_acceleration():
    t = np.linspace(0.0, 1.0, 101)
    a = 0.5 * np.sin(2 * math.pi * t)
    d = free_scene_dict(duration=1.0)
    d["motion"] = {"type": "sampled", "dt_s": 0.01, "accel_m_s2": a.tolist()}
    result = HousnerSolver().run(scene_from_dict(d))
    assert np.allclose(result.series("ax_m_s2"), np.interp(result.t, t, a), atol=1e-12)
    assert np.allclose(result.series("theta_rad"), 0.0)
