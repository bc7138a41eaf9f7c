"""The out-of-plane wall section (rockyade build wall-section): each case's static threshold
against its closed form in the limit analysis."""

from __future__ import annotations

import pytest

from rockyade.cli import main
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.limit import limit_analysis
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import wall_section

H, T, L, RHO = 3.0, 0.3, 2.0, 2000.0


def section(**kwargs):
    return scene_from_dict(wall_section(height_m=H, thickness_m=T, length_m=L, density_kg_m3=RHO,
                                        motion={"type": "rest"}, **kwargs))


@pytest.mark.parametrize("courses", [1, 4])
def test_a_free_top_wall_tips_at_t_over_h(courses):
    """b / h_c of the whole wall: (t/2) / (H/2); a joint higher up gives t / (H - z) > t / H."""
    scene = section(courses=courses)
    assert [b.width_m for b in scene.blocks] == [T] * courses  # width_m is the wall's thickness
    assert {b.thickness_m for b in scene.blocks} == {L}  # thickness_m is the wall's length
    for direction in ("+x", "-x"):
        assert limit_analysis(scene, direction=direction).load_multiplier == pytest.approx(T / H, rel=1e-9)


def test_an_overburden_gives_w_b_plus_n_d_over_w_h():
    q, e = 10000.0, 0.05
    scene = section(courses=3, overburden_n_per_m=q, overburden_eccentricity_m=e)
    w = RHO * T * H * L * G
    n = q * L
    assert [(x.block, x.point_m, x.force_N) for x in scene.loads] == [("w03", (e, H), (0.0, -n))]
    assert scene.loads[0].mass_kg == pytest.approx(n / G)  # the overburden carries its mass by default
    # towards +x the wall turns about (t/2, 0): the load is t/2 - e from it, at height H
    assert limit_analysis(scene, direction="+x").load_multiplier == pytest.approx(
        (w * T / 2 + n * (T / 2 - e)) / (w * H / 2 + n * H), rel=1e-9)
    assert limit_analysis(scene, direction="-x").load_multiplier == pytest.approx(
        (w * T / 2 + n * (T / 2 + e)) / (w * H / 2 + n * H), rel=1e-9)


def test_a_restrained_top_needs_a_gap_and_is_frictionless():
    with pytest.raises(InputError, match="clamp") as info:
        wall_section(top="restrained")
    assert info.value.field == "gap_m"
    scene = section(courses=2, top="restrained", gap_m=0.01)
    assert sum(b.fixed for b in scene.blocks) == 2
    assert {j.blocks for j in scene.joints} == {("w02", "restraint_near"), ("w02", "restraint_far")}
    assert all(j.get("friction_angle_deg") == 0.0 for j in scene.joints)
    # the gap lets the wall turn before it meets a restraint: its static threshold is the free wall's
    assert limit_analysis(scene, direction="+x").load_multiplier == pytest.approx(T / H, rel=1e-9)


def test_rockyade_build_wall_section(tmp_path):
    out = tmp_path / "ws.toml"
    assert main(["build", "wall-section", "--height-m", "2.4", "--thickness-m", "0.25", "--length-m", "1.5",
                 "--courses", "2", "--overburden-n-per-m", "5000", "--out", str(out)]) == 0
    scene = load_scene(out)
    assert [b.width_m for b in scene.blocks] == [0.25, 0.25] and scene.blocks[0].thickness_m == 1.5
    assert scene.loads[0].force_N == (0.0, -7500.0)
    assert main(["build", "wall-section", "--top", "restrained", "--out", str(tmp_path / "x.toml")]) == 2
