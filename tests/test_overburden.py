"""Generators' overburden: floor and roof loads at the top of walls, wall sections and columns,
written as [[loads]] with their mass (by default) and checked against lambda = (W b + N d) / (W h_c + N h_N),
or (W b + N d) / (W h_c) without it."""

from __future__ import annotations

import pytest

from rockyade.cli import main
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.limit import limit_analysis
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import rest_motion, restrained_wall, stack, wall
from rockyade.scene.generators.overburden import add_overburden


@pytest.mark.parametrize("with_mass", [False, True])
def test_a_column_top_load_gives_the_closed_form_in_the_limit_analysis(with_mass):
    data = add_overburden(
        stack(widths_m=[0.4], heights_m=2.0, motion=rest_motion()),
        "point",
        force_N=5000.0,
        eccentricity_m=-0.1,
        with_mass=with_mass,
    )
    assert data["loads"][0]["mass_kg"] == (pytest.approx(5000.0 / G) if with_mass else 0.0)
    scene = scene_from_dict(data)
    w = scene.blocks[0].block().mass_kg * G
    # pushed towards +x the block turns about its right corner: the load is 0.3 m from it; with
    # its mass, lambda N acts at the top, h_N = 2 m
    over = w * 1.0 + (5000 * 2.0 if with_mass else 0.0)
    assert limit_analysis(scene, direction="+x").load_multiplier == pytest.approx((w * 0.2 + 5000 * 0.3) / over, 1e-6)
    assert limit_analysis(scene, direction="-x").load_multiplier == pytest.approx((w * 0.2 + 5000 * 0.1) / over, 1e-6)


def test_a_wall_section_carries_its_load_per_metre_times_its_length():
    data = restrained_wall(blocks=1, wall_length_m=2.0, gap_m=0.05)
    loaded = add_overburden(data, "section", force_N_per_m=10000.0, eccentricity_m=0.1)
    assert loaded["loads"] == [
        {"block": "w01", "point_m": [0.1, 3.0], "force_N": [0.0, -20000.0], "mass_kg": pytest.approx(20000.0 / G)}
    ]
    assert "loads" not in data  # the input is not changed


def test_an_in_plane_wall_shares_its_load_among_the_top_units():
    data = wall(courses=3, units_per_course=3)
    loaded = add_overburden(data, "line", force_N_per_m=10000.0)
    scene = scene_from_dict(loaded)
    top = max(float(b["position_m"][1]) for b in data["blocks"])
    total_length = sum(float(b["width_m"]) for b in data["blocks"] if float(b["position_m"][1]) == top)
    assert len(scene.loads) == 3
    assert sum(-q.force_N[1] for q in scene.loads) == pytest.approx(10000.0 * total_length)
    with pytest.raises(InputError, match="out of plane"):
        add_overburden(data, "line", force_N_per_m=1.0, eccentricity_m=0.1)


@pytest.mark.parametrize(
    ("kind", "kwargs", "field"),
    [
        ("point", {"force_N": -1.0}, "overburden_N"),
        ("point", {"force_N": float("inf")}, "overburden_N"),
        ("point", {"force_N": 10.0, "eccentricity_m": 0.5}, "overburden_eccentricity_m"),
        ("section", {"force_N_per_m": 1e9}, "overburden_N_per_m"),
        ("top", {}, "overburden"),
    ],
)
def test_bad_overburdens_are_refused(kind, kwargs, field):
    with pytest.raises(InputError) as info:
        add_overburden(stack(widths_m=[0.4], heights_m=2.0), kind, **kwargs)
    assert info.value.field == field


def test_rockyade_build_writes_the_overburden(tmp_path, capsys):
    out = tmp_path / "rw.toml"
    assert (
        main(
            [
                "build",
                "restrained-wall",
                "--blocks",
                "1",
                "--gap-m",
                "0.05",
                "--overburden-n-per-m",
                "20000",
                "--overburden-eccentricity-m",
                "0.1",
                "--motion",
                "gravity-ramp",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    scene = load_scene(out)
    assert scene.motion.type == "gravity-ramp"
    assert [(q.block, q.point_m, q.force_N) for q in scene.loads] == [("w01", (0.1, 3.0), (0.0, -20000.0))]
    assert scene.loads[0].mass_kg == pytest.approx(20000.0 / G)
    assert (
        main(
            [
                "build",
                "restrained-wall",
                "--blocks",
                "1",
                "--gap-m",
                "0.05",
                "--overburden-n-per-m",
                "20000",
                "--overburden-mass",
                "none",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    assert load_scene(out).loads[0].mass_kg == 0.0
    assert (
        main(["build", "wall-section", "--overburden-n-per-m", "6000", "--overburden-mass", "none", "--out", str(out)])
        == 0
    )
    assert load_scene(out).loads[0].mass_kg == 0.0
    assert (
        main(
            [
                "build",
                "column",
                "--top-load-n",
                "100",
                "--top-load-eccentricity-m",
                "5",
                "--out",
                str(tmp_path / "c.toml"),
            ]
        )
        == 2
    )
    assert "--top-load-eccentricity-m" in capsys.readouterr().err
