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
    return scene_from_dict(
        wall_section(height_m=H, thickness_m=T, length_m=L, density_kg_m3=RHO, motion={"type": "rest"}, **kwargs)
    )


@pytest.mark.parametrize("courses", [1, 4])
def test_a_free_top_wall_tips_at_t_over_h(courses):
    """b / h_c of the whole wall: (t/2) / (H/2); a joint higher up gives t / (H - z) > t / H."""
    scene = section(courses=courses)
    assert [b.width_m for b in scene.blocks] == [T] * courses  # width_m is the wall's thickness
    assert {b.thickness_m for b in scene.blocks} == {L}  # thickness_m is the wall's length
    for direction in ("+x", "-x"):
        assert limit_analysis(scene, direction=direction, nonlinear=False).load_multiplier == pytest.approx(
            T / H, rel=1e-9
        )


def test_an_overburden_gives_w_b_plus_n_d_over_w_h():
    q, e = 10000.0, 0.05
    scene = section(courses=3, overburden_n_per_m=q, overburden_eccentricity_m=e)
    w = RHO * T * H * L * G
    n = q * L
    assert [(x.block, x.point_m, x.force_N) for x in scene.loads] == [("w03", (e, H), (0.0, -n))]
    assert scene.loads[0].mass_kg == pytest.approx(n / G)  # the overburden carries its mass by default
    # towards +x the wall turns about (t/2, 0): the load is t/2 - e from it, at height H
    assert limit_analysis(scene, direction="+x", nonlinear=False).load_multiplier == pytest.approx(
        (w * T / 2 + n * (T / 2 - e)) / (w * H / 2 + n * H), rel=1e-9
    )
    assert limit_analysis(scene, direction="-x", nonlinear=False).load_multiplier == pytest.approx(
        (w * T / 2 + n * (T / 2 + e)) / (w * H / 2 + n * H), rel=1e-9
    )


def test_a_restrained_top_needs_a_gap_and_is_frictionless():
    with pytest.raises(InputError, match="clamp") as info:
        wall_section(top="restrained")
    assert info.value.field == "gap_m"
    scene = section(courses=2, top="restrained", gap_m=0.01)
    assert sum(b.fixed for b in scene.blocks) == 2
    assert {j.blocks for j in scene.joints} == {("w02", "restraint_near"), ("w02", "restraint_far")}
    assert all(j.get("friction_angle_deg") == 0.0 for j in scene.joints)
    # the gap lets the wall turn before it meets a restraint: its static threshold is the free wall's
    assert limit_analysis(scene, direction="+x", nonlinear=False).load_multiplier == pytest.approx(T / H, rel=1e-9)


def test_rockyade_build_wall_section(tmp_path):
    out = tmp_path / "ws.toml"
    assert (
        main(
            [
                "build",
                "wall-section",
                "--height-m",
                "2.4",
                "--thickness-m",
                "0.25",
                "--length-m",
                "1.5",
                "--courses",
                "2",
                "--overburden-n-per-m",
                "5000",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    scene = load_scene(out)
    assert [b.width_m for b in scene.blocks] == [0.25, 0.25] and scene.blocks[0].thickness_m == 1.5
    assert scene.loads[0].force_N == (0.0, -7500.0)
    assert main(["build", "wall-section", "--top", "restrained", "--out", str(tmp_path / "x.toml")]) == 2


def three_hinge(t: float, h: float, h1: float, hr: float) -> float:
    """The paper's Fig. 2 by virtual work (docs/assemblies.md): the lower block (h1) turns about the
    toe, the upper one hinges on it and slides up the restraint's corner (t/2, h - hr)."""
    h2, w2 = h - h1, h1 / (h - hr - h1)
    return (h1 * t / 2 + h2 * t * (1 + w2 / 2)) / (h1 * h1 / 2 + h2 * (h1 - w2 * h2 / 2))


@pytest.mark.parametrize("split", [0.5, 0.4])
def test_two_courses_split_at_a_height_form_the_three_hinge_mechanism(split):
    """--split puts the joint of a two-course wall where the engineer says (17/35 at half height)."""
    scene = section(courses=2, split=split, top="restrained-far")
    assert [b.height_m for b in scene.blocks if not b.fixed] == pytest.approx([H * split, H * (1 - split)])
    expected = three_hinge(T, H, H * split, 0.3)
    if split == 0.5:
        assert expected == pytest.approx(17 / 35, rel=1e-12)
    assert limit_analysis(scene, direction="+x", nonlinear=False).load_multiplier == pytest.approx(expected, rel=1e-9)
    with pytest.raises(InputError, match="2 courses") as info:
        wall_section(courses=3, split=split)
    assert info.value.field == "split"


def test_a_floor_over_the_top_with_a_gap_lets_the_wall_turn():
    scene = section(top="floor", gap_m=0.01)
    floor = scene.blocks[-1]
    assert floor.name == "floor" and floor.fixed and floor.position_m == pytest.approx((-T / 2 + 0.3, H + 0.01))
    assert [j.blocks for j in scene.joints] == [("w01", "floor")]
    assert limit_analysis(scene, direction="+x", nonlinear=False).load_multiplier == pytest.approx(T / H, rel=1e-9)
    # the top corner of a wall turning about its toe rises at most sqrt(t^2 + H^2) - H = 0.01496 m
    with pytest.raises(InputError, match=r"< 0.01496 m with top = 'floor'") as info:
        wall_section(top="floor", gap_m=0.015)
    assert info.value.field == "gap_m"


@pytest.mark.parametrize(
    ("former", "now"),
    [
        ([], ["--courses", "2", "--top", "restrained-far"]),
        (
            ["--blocks", "1", "--restraint", "floor", "--gap-m", "0.01", "--wall-height-m", "2.4"],
            ["--top", "floor", "--gap-m", "0.01", "--height-m", "2.4"],
        ),
        (
            ["--split", "0.4", "--restraint-friction-deg", "10", "--wall-thickness-m", "0.4"],
            [
                "--courses",
                "2",
                "--split",
                "0.4",
                "--top",
                "restrained-far",
                "--restraint-friction-deg",
                "10",
                "--thickness-m",
                "0.4",
            ],
        ),
    ],
)
def test_restrained_wall_is_an_alias_of_wall_section(former, now, tmp_path, capsys):
    """The alias maps its options onto wall-section's and writes the same scene; its --help says so."""
    import tomllib

    assert main(["build", "restrained-wall", *former, "--motion", "rest", "--out", str(tmp_path / "a.toml")]) == 0
    assert main(["build", "wall-section", *now, "--motion", "rest", "--out", str(tmp_path / "b.toml")]) == 0
    a, b = (tomllib.loads((tmp_path / name).read_text()) for name in ("a.toml", "b.toml"))
    assert a == b
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["build", "restrained-wall", "--help"])
    assert "alias of `rockyade build wall-section`" in " ".join(capsys.readouterr().out.split())
