"""A loaded block is reported as it is solved (issue 33, item 1): the classical parameters of the
body that rocks, the masses of its loads in, each direction its own alpha, R, p, mu and uplift
acceleration, in every solver's metadata, console line and theta / alpha.

The case: a tuff wall 0.45 x 3.2 m (1600 kg/m^3, a 1 m strip) carrying 12 kN/m at 0.125 m from
its axis (towards +x), with the load's mass; checked against a hand calculation written out here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.blocks.classical import body_restitution, classical_parameters
from rockyade.blocks.geometry import Block
from rockyade.constants import G
from rockyade.scene import scene_from_dict
from rockyade.scene.carried import loaded_classical
from rockyade.scene.generators import wall_section

T, H, RHO, N, E = 0.45, 3.2, 1600.0, 12000.0, 0.125


def tuff_wall(amplitude_g: float | None = None, mass: str = "carried") -> dict:
    motion = (
        {"type": "rest"}
        if amplitude_g is None
        else {"type": "pulse", "shape": "sine", "amplitude_g": amplitude_g, "period_s": 1.0, "cycles": 1}
    )
    scene = wall_section(
        height_m=H,
        thickness_m=T,
        density_kg_m3=RHO,
        overburden_n_per_m=N,
        overburden_eccentricity_m=E,
        motion=motion,
        duration_s=3.0,
    )
    if mass == "none":
        scene["loads"] = [{**q, "mass_kg": 0.0} for q in scene["loads"]]
    return scene


def hand() -> dict[str, float]:
    """The loaded wall by hand: the wall's mass at (0, H/2), the load's N/g at (E, H)."""
    m, m_n = T * H * RHO, N / G
    big_m = m + m_n
    xc, yc = m_n * E / big_m, (m * H / 2 + m_n * H) / big_m
    i_c = m * (T**2 + H**2) / 12 + m * (xc**2 + (H / 2 - yc) ** 2) + m_n * ((E - xc) ** 2 + (H - yc) ** 2)
    w = m * G
    out = {"M": big_m, "xc": xc, "yc": yc, "I_c": i_c}
    for side, pivot in (("plus", T / 2), ("minus", -T / 2)):
        lever = abs(pivot - xc)
        r = math.hypot(lever, yc)
        out[f"alpha_{side}"] = math.atan2(lever, yc)
        out[f"p_{side}"] = math.sqrt(big_m * G * r / (i_c + big_m * r * r))
        out[f"R_{side}"] = r
    # the impact that ends rocking towards +x moves the pivot from (T/2, 0) to (-T/2, 0)
    ra, rb = (xc - T / 2, yc), (xc + T / 2, yc)
    out["mu_plus"] = (i_c + big_m * (ra[0] * rb[0] + ra[1] * rb[1])) / (i_c + big_m * (rb[0] ** 2 + rb[1] ** 2))
    out["mu_minus"] = (i_c + big_m * (ra[0] * rb[0] + ra[1] * rb[1])) / (i_c + big_m * (ra[0] ** 2 + ra[1] ** 2))
    # the limit analysis' multiplier of the block, the load's mass at its point (docs/limit.md)
    out["lambda_plus"] = (w * T / 2 + N * (T / 2 - E)) / (w * H / 2 + N * H)
    out["lambda_minus"] = (w * T / 2 + N * (T / 2 + E)) / (w * H / 2 + N * H)
    return out


def test_the_loaded_walls_classical_parameters_by_hand():
    cp = loaded_classical(scene_from_dict(tuff_wall()), G)["w01"]
    h = hand()
    right, left = cp.pivot("+x"), cp.pivot("-x")
    assert (right.turns_to, left.turns_to) == ("+x", "-x")
    assert right.alpha_rad == pytest.approx(h["alpha_plus"], rel=1e-12)
    assert left.alpha_rad == pytest.approx(h["alpha_minus"], rel=1e-12)
    assert round(right.alpha_rad, 4) == 0.0841 and round(left.alpha_rad, 4) == 0.1239  # the numbers
    assert right.R_m == pytest.approx(h["R_plus"], rel=1e-12) and left.R_m == pytest.approx(h["R_minus"], rel=1e-12)
    assert right.p_rad_s == pytest.approx(h["p_plus"], rel=1e-12)
    assert left.p_rad_s == pytest.approx(h["p_minus"], rel=1e-12)
    assert right.mu == pytest.approx(h["mu_plus"], rel=1e-12) and left.mu == pytest.approx(h["mu_minus"], rel=1e-12)
    assert right.mu != pytest.approx(left.mu, abs=1e-4)  # an asymmetric body: two impacts, two mu
    assert right.uplift_accel_m_s2 == pytest.approx(h["lambda_plus"] * G, rel=1e-12)
    assert left.uplift_accel_m_s2 == pytest.approx(h["lambda_minus"] * G, rel=1e-12)
    assert round(right.uplift_accel_m_s2 / G, 4) == 0.0843  # loaded alpha0 of the issue
    assert right.uplift_accel_m_s2 / G == pytest.approx(math.tan(right.alpha_rad), rel=1e-12)
    assert cp.mass_kg == pytest.approx(h["M"], rel=1e-12) and cp.I_c_kgm2 == pytest.approx(h["I_c"], rel=1e-12)
    assert cp.carried_kg == pytest.approx(N / G, rel=1e-12)
    assert not cp.symmetric and cp.alpha_rad == right.alpha_rad
    assert cp.uplift_accel_m_s2 == right.uplift_accel_m_s2


def test_a_load_without_mass_keeps_the_walls_alpha_and_moves_its_uplift():
    cp = loaded_classical(scene_from_dict(tuff_wall(mass="none")), G)["w01"]
    bare = classical_parameters(Block.rectangle(T, H, 1.0, density_kg_m3=RHO))
    assert cp.left.alpha_rad == pytest.approx(bare.alpha_rad) == pytest.approx(cp.right.alpha_rad)
    w = T * H * RHO * G
    assert cp.right.uplift_accel_m_s2 / G == pytest.approx((w * T / 2 + N * (T / 2 - E)) / (w * H / 2), rel=1e-12)
    assert cp.left.uplift_accel_m_s2 / G == pytest.approx((w * T / 2 + N * (T / 2 + E)) / (w * H / 2), rel=1e-12)
    assert cp.carried_kg == 0.0 and not cp.symmetric


def test_a_symmetric_block_keeps_housners_rectangle():
    cp = classical_parameters(Block.rectangle(0.4, 2.0, 1.0, density_kg_m3=2000.0))
    alpha = math.atan(0.2 / 1.0)
    assert cp.symmetric and cp.left.mu == pytest.approx(1 - 1.5 * math.sin(alpha) ** 2, rel=1e-12)
    assert cp.left.mu == cp.right.mu == cp.mu
    assert cp.left.uplift_accel_m_s2 == pytest.approx(G * 0.2, rel=1e-12) == cp.right.uplift_accel_m_s2
    assert body_restitution(1.0, (0.0, 1.0), 1 / 3 * (0.04 + 1.0), (-0.2, 0.0), (0.2, 0.0)) == pytest.approx(cp.mu)


def test_theta_over_alpha_takes_the_side_the_block_turns_to():
    cp = loaded_classical(scene_from_dict(tuff_wall()), G)["w01"]
    theta = np.array([0.0, 0.05, -0.05, np.nan])  # the same rotation either way
    assert cp.theta_over_alpha(theta) == pytest.approx(0.05 / cp.right.alpha_rad)  # towards +x: the smaller alpha
    assert cp.theta_over_alpha(np.array([0.05])) == pytest.approx(0.05 / cp.left.alpha_rad)
    assert math.isnan(cp.theta_over_alpha(np.array([np.nan])))


@pytest.mark.parametrize(("amplitude_g", "rocks"), [(0.08, False), (0.087, True)])
def test_housner_solves_and_reports_the_loaded_wall(amplitude_g, rocks):
    from rockyade.analysis.metrics import run_metrics
    from rockyade.solvers import make_solver

    scene = scene_from_dict(tuff_wall(amplitude_g))
    result = make_solver("housner").run(scene)
    theta = result.series("theta_rad", "w01")
    assert (float(np.max(np.abs(theta))) > 0.0) is rocks  # uplift at 0.0843 g, between the two pulses
    meta = result.meta.classical["w01"]
    h = hand()
    assert meta["symmetric"] is False
    assert meta["right"]["alpha_rad"] == pytest.approx(h["alpha_plus"], rel=1e-12)
    assert meta["left"]["alpha_rad"] == pytest.approx(h["alpha_minus"], rel=1e-12)
    assert meta["right"]["uplift_accel_m_s2"] == pytest.approx(h["lambda_plus"] * G, rel=1e-12)
    assert meta["mass_kg"] == pytest.approx(h["M"], rel=1e-12)
    ratio = run_metrics(scene, result)["w01"]["max_theta_over_alpha"]
    expected = max(np.max(theta, initial=0.0) / h["alpha_minus"], -np.min(theta, initial=0.0) / h["alpha_plus"])
    assert ratio == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("solver", ["reference", "yade", "siconos"])
def test_every_solver_reports_the_loaded_wall_as_housner_does(solver):
    from rockyade.solvers import make_solver

    from .processes import require_siconos, require_yade

    {"yade": require_yade, "siconos": require_siconos}.get(solver, lambda: None)()
    scene = scene_from_dict({**tuff_wall(), "duration_s": 0.02})
    result = make_solver(solver).run(scene)
    assert result.ok, result.meta.failure_reason
    classical = result.meta.classical["w01"]
    assert classical["right"]["alpha_rad"] == pytest.approx(hand()["alpha_plus"], rel=1e-12)
    assert classical["left"]["mu"] == pytest.approx(hand()["mu_minus"], rel=1e-12)
    if result.meta.bodies:  # the DEMs' own body: its left pivot's alpha, the loaded one
        assert result.meta.bodies["w01"]["alpha_rad"] == pytest.approx(hand()["alpha_minus"], rel=1e-9)


def test_rockyade_run_prints_each_direction(tmp_path, capsys, monkeypatch):
    from rockyade.cli import main
    from rockyade.scene.toml_writer import write_toml

    monkeypatch.chdir(tmp_path)
    write_toml("wall.toml", tuff_wall(0.087))
    assert main(["run", "wall.toml"]) == 0
    out = capsys.readouterr().out
    assert "towards +x: alpha = 0.0841 rad" in out and "towards -x: alpha = 0.1239 rad" in out
    assert "uplift at 0.827 m/s^2 (0.0843 g)" in out
    assert "alpha of the side it turns to" in out
