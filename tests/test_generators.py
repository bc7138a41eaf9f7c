"""Assembly generators: every scene validates, joints are flush, geometry and masses are right,
the TOML writer round-trips, and ``rockyade build`` writes files that load from anywhere."""

from __future__ import annotations

import inspect
import itertools
import math
import random
import shlex
import tomllib

import numpy as np
import pytest

from rockyade.cli import main
from rockyade.cli.build import COMMON, COMMON_PARAMS, KINDS
from rockyade.errors import InputError
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import (
    GENERATORS,
    arch,
    column,
    drum_column,
    frame_frequency,
    frame_gamma,
    pulse_motion,
    restrained_wall,
    rocking_frame,
    stack,
    tapered_widths,
    wall,
    write_scene,
)
from rockyade.scene.generators.scene_tables import (
    DEFAULT_FRICTION_ANGLE_DEG,
    DEFAULT_JKN_PA_PER_M,
    DEFAULT_JOINT_DAMPING_RATIO,
    DEFAULT_PULSE,
)
from rockyade.scene.placement import candidate_pairs, penetration_depth, placed_blocks, rest_contacts
from rockyade.scene.toml_writer import toml_text

from .conftest import EXAMPLES

FLUSH = 1e-12  # m: joints flush to this


def _placed(data: dict):
    return placed_blocks(scene_from_dict(data))


def _max_penetration(placed) -> float:
    polys = [b.vertices_m for b in placed]
    return max((penetration_depth(polys[i], polys[j]) for i, j in candidate_pairs(polys)), default=-math.inf)


def _mass(data: dict) -> float:
    return sum(spec.block().mass_kg for spec in scene_from_dict(data).blocks)


VARIANTS = [
    ("wall", {}),
    ("wall", {"bond": "stack", "courses": 3, "units_per_course": 4}),
    ("wall", {"openings": [(0.8, 0.0, 0.8, 0.6), (1.8, 0.4, 0.4, 0.4)], "units_per_course": 8, "courses": 6}),
    ("wall", {"openings": [(0.5, 0.3, 0.5, 0.5)], "lintel": "none"}),
    ("column", {}),
    ("column", {"drums": 3, "capital_width_m": 0.5, "capital_height_m": 0.15, "layout": "column"}),
    ("arch", {}),
    ("arch", {"shape": "pointed", "voussoirs": 12, "piers": "fixed"}),
    ("arch", {"shape": "pointed", "voussoirs": 9, "centre_offset_m": 0.4, "pier_height_m": 0.0}),
    ("arch", {"voussoirs": 2}),
    ("frame", {}),
    ("frame", {"gamma": 0.8, "beam_overhang_m": 0.1}),
    ("stack", {}),
    ("stack", {"widths_m": [0.5, 0.4, 0.3], "heights_m": [0.6, 0.5, 0.4], "taper": "continuous", "top_width_m": 0.2}),
    ("restrained-wall", {}),
    ("restrained-wall", {"blocks": 1, "restraint": "floor", "gap_m": 0.01}),
]


@pytest.mark.parametrize(("kind", "kwargs"), VARIANTS)
def test_every_generator_validates_and_blocks_touch_without_overlap(kind, kwargs):
    data = GENERATORS[kind](**kwargs)
    scene = scene_from_dict(data)
    placed = placed_blocks(scene)
    assert len(placed) == len(data["blocks"])
    assert _max_penetration(placed) <= FLUSH
    assert min(float(b.vertices_m[:, 1].min()) for b in placed) >= -FLUSH
    # every block rests on something or on the base at rest (nothing floats), except the
    # lintel-less wall, whose units over the opening stand on nothing
    touching = {c.a for c in rest_contacts(placed)} | {c.b for c in rest_contacts(placed) if c.b >= 0}
    if kwargs.get("lintel") != "none" and kwargs.get("gap_m", 0) == 0:
        assert touching == set(range(len(placed)))


def test_python_defaults_match_the_cli_defaults():
    for kind, (_, options) in KINDS.items():
        params = inspect.signature(GENERATORS[kind]).parameters
        for opt in options:
            if opt.dest in params:
                default = params[opt.dest].default
                if kind == "stack" and opt.dest == "heights_m":
                    assert opt.default == [default]
                elif not (kind == "stack" and opt.dest == "widths_m"):
                    assert opt.default == default, (kind, opt.flag)
        for opt in COMMON:
            if opt.dest in COMMON_PARAMS:
                assert opt.default == params[opt.dest].default, (kind, opt.flag)
    assert inspect.signature(stack).parameters["widths_m"].default == (0.4, 0.35, 0.3, 0.25)
    cli = {opt.dest: opt.default for opt in COMMON}
    assert pulse_motion(cli["amplitude_g"], cli["period_s"], cli["pulse_shape"], cli["cycles"]) == DEFAULT_PULSE
    assert (cli["jkn_pa_per_m"], cli["damping_ratio"], cli["friction_angle_deg"]) == (
        DEFAULT_JKN_PA_PER_M,
        DEFAULT_JOINT_DAMPING_RATIO,
        DEFAULT_FRICTION_ANGLE_DEG,
    )


# ---------------------------------------------------------------------- walls


def _courses(placed, unit_height):
    rows: dict[int, list] = {}
    for b in placed:
        rows.setdefault(round(float(b.vertices_m[:, 1].min()) / unit_height), []).append(b)
    return rows


def _head_joints(row) -> list[float]:
    """x of the head joints of a course (right edges, without the wall's end)."""
    rights = sorted(float(b.vertices_m[:, 0].max()) for b in row)
    return rights[:-1]


def test_running_bond_offsets_head_joints_by_half_a_unit_and_joints_are_flush():
    L, H, n = 0.37, 0.19, 7
    data = wall(courses=6, units_per_course=n, unit_length_m=L, unit_height_m=H)
    placed = _placed(data)
    rows = _courses(placed, H)
    assert sorted(rows) == list(range(6))
    for c, row in rows.items():
        heads = _head_joints(row)
        assert len(heads) == (n - 1 if c % 2 == 0 else n)
        # the wall's two ends are flush in every course, at 0 and n L
        assert min(float(b.vertices_m[:, 0].min()) for b in row) == pytest.approx(0.0, abs=FLUSH)
        assert max(float(b.vertices_m[:, 0].max()) for b in row) == pytest.approx(n * L, abs=FLUSH)
        if c > 0:
            below = _head_joints(rows[c - 1])
            gaps = [min(abs(x - y) for y in below) for x in heads]
            assert gaps == pytest.approx([L / 2] * len(heads), abs=FLUSH)
    # bed joints: each course interface is one flush joint over the whole wall length
    contacts = rest_contacts(placed)
    for c in range(1, 6):
        length = sum(
            k.length_m
            for k in contacts
            if k.kind == "bed"
            and k.b >= 0
            and abs(k.ends_m[0][1] - c * H) < FLUSH
            and abs(k.ends_m[1][1] - c * H) < FLUSH
        )
        assert length == pytest.approx(n * L, abs=1e-9)
    # course levels are exactly the multiples of the unit height
    levels = np.unique(np.round(np.concatenate([b.vertices_m[:, 1] for b in placed]) / H, 6))
    assert levels.tolist() == [float(k) for k in range(7)]
    for b in placed:
        y = b.vertices_m[:, 1]
        assert np.abs(y / H - np.round(y / H)).max() * H < FLUSH


def test_stack_bond_aligns_head_joints():
    placed = _placed(wall(courses=3, units_per_course=4, bond="stack"))
    rows = _courses(placed, 0.2)
    assert _head_joints(rows[0]) == pytest.approx(_head_joints(rows[1]), abs=FLUSH)
    assert _head_joints(rows[0]) == pytest.approx([0.4, 0.8, 1.2], abs=FLUSH)


def test_names_count_course_and_unit():
    data = wall(courses=12, units_per_course=3)
    names = [b["name"] for b in data["blocks"]]
    assert names[:3] == ["c01_u01", "c01_u02", "c01_u03"]
    assert names[3:7] == ["c02_u01", "c02_u02", "c02_u03", "c02_u04"]
    assert names[-1] == "c12_u04"
    assert len(set(names)) == len(names)


def test_openings_are_empty_and_the_mass_is_density_times_solid_area():
    rho, t = 1900.0, 0.25
    openings = [(0.8, 0.0, 0.8, 1.2), (2.4, 0.6, 0.8, 0.6)]
    data = wall(courses=8, units_per_course=9, unit_thickness_m=t, density_kg_m3=rho, openings=openings)
    placed = _placed(data)
    for x, y, w, h in openings:
        hole = np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]])
        assert max(penetration_depth(b.vertices_m, hole) for b in placed) <= FLUSH
    solid = 9 * 0.4 * 8 * 0.2 - sum(w * h for *_, w, h in openings)
    assert _mass(data) == pytest.approx(rho * t * solid, rel=1e-12)
    # one lintel per opening, resting on the opening's top edge, bearing half a unit each side
    lintels = {b.name: b for b in placed if b.name.startswith("lintel")}
    assert sorted(lintels) == ["lintel1", "lintel2"]
    for (x, y, w, h), name in zip(openings, ("lintel1", "lintel2"), strict=True):
        v = lintels[name].vertices_m
        assert v[:, 1].min() == pytest.approx(y + h, abs=FLUSH)
        assert v[:, 0].min() == pytest.approx(x - 0.2, abs=FLUSH)
        assert v[:, 0].max() == pytest.approx(x + w + 0.2, abs=FLUSH)


def test_cut_slivers_are_left_out_and_the_void_grows_only_by_them():
    # the opening's right jamb 1 cm past a head joint would leave 1 cm pieces: they go
    data = wall(courses=2, units_per_course=4, bond="stack", openings=[(0.4, 0.0, 0.41, 0.4)], lintel="none")
    widths = sorted(b["width_m"] for b in data["blocks"])
    assert min(widths) == pytest.approx(0.39)
    assert len(data["blocks"]) == 6


def test_lintel_none_leaves_units_over_the_opening_unsupported():
    data = wall(courses=4, units_per_course=4, bond="stack", openings=[(0.4, 0.0, 0.8, 0.4)], lintel="none")
    placed = _placed(data)
    supported = {c.upper for c in rest_contacts(placed) if c.kind == "bed"}
    floating = [b.name for b in placed if b.index not in supported]
    assert floating == ["c03_u02", "c03_u03"]


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"courses": 0}, "courses"),
        ({"unit_length_m": -0.1}, "unit_length_m"),
        ({"bond": "flemish"}, "bond"),
        ({"openings": [(2.3, 0.0, 0.4, 0.4)]}, "openings[0].width_m"),
        ({"openings": [(0.0, 0.9, 0.4, 0.4)]}, "openings[0].height_m"),
        ({"openings": [(0.4, 0, 0.4, 0.4), (0.6, 0.2, 0.4, 0.4)]}, "openings[1]"),
        ({"openings": [(0.4, 0, 0.4)]}, "openings[0]"),
        ({"density_kg_m3": 0}, "density_kg_m3"),
    ],
)
def test_wall_refuses_bad_values_naming_the_parameter(kwargs, field):
    with pytest.raises(InputError) as err:
        wall(**kwargs)
    assert err.value.field == field


# ---------------------------------------------------------------------- arches


def _faces(placed):
    return {b.name: b.vertices_m for b in placed}


@pytest.mark.parametrize(
    "kwargs",
    [
        {"voussoirs": 11},
        {"voussoirs": 8},
        {"voussoirs": 12, "shape": "pointed"},
        {"voussoirs": 7, "shape": "pointed", "centre_offset_m": 0.3},
    ],
)
def test_arch_voussoirs_share_faces_exactly_and_are_symmetric(kwargs):
    n = kwargs["voussoirs"]
    data = arch(span_m=2.0, ring_depth_m=0.3, pier_height_m=1.0, pier_width_m=0.5, **kwargs)
    faces = _faces(_placed(data))
    names = [f"v{k:02d}" for k in range(1, n + 1)]
    for a, b in itertools.pairwise(names):
        shared = [p for p in faces[a] if np.min(np.hypot(*(faces[b] - p).T)) < FLUSH]
        assert len(shared) == 2, (a, b)
    # the springing voussoirs sit flat on the piers' tops, flush with their inner faces
    for name, inner in (("v01", -1.0), (names[-1], 1.0)):
        low = faces[name][np.abs(faces[name][:, 1] - 1.0) < FLUSH]
        assert len(low) == 2
        assert sorted(np.abs(low[:, 0])) == pytest.approx([1.0, 1.3], abs=FLUSH)
        assert np.sign(low[0, 0]) == np.sign(inner)
    # mirror symmetry about x = 0
    for k in range(n):
        mirrored = faces[names[n - 1 - k]] * np.array([-1.0, 1.0])
        dist = [np.min(np.hypot(*(mirrored - p).T)) for p in faces[names[k]]]
        assert max(dist) < FLUSH


def test_semicircular_arch_points_lie_on_the_circles_and_the_mass_is_the_polygonal_ring():
    n, span, depth, t, rho = 9, 3.0, 0.4, 0.6, 2100.0
    data = arch(span_m=span, ring_depth_m=depth, thickness_m=t, voussoirs=n, pier_height_m=0.0, density_kg_m3=rho)
    placed = _placed(data)
    r_i, r_e = span / 2, span / 2 + depth
    for b in placed:
        radii = np.sort(np.hypot(b.vertices_m[:, 0], b.vertices_m[:, 1]))
        assert radii == pytest.approx([r_i, r_i, r_e, r_e], abs=FLUSH)
    ring = n * 0.5 * (r_e**2 - r_i**2) * math.sin(math.pi / n)
    assert _mass(data) == pytest.approx(rho * t * ring, rel=1e-12)


def test_pointed_arch_crown_and_fixed_piers():
    data = arch(shape="pointed", voussoirs=10, piers="fixed", span_m=2.0)
    scene = scene_from_dict(data)
    assert [b.fixed for b in scene.blocks[:2]] == [True, True]
    faces = _faces(placed_blocks(scene))
    crown = faces["v05"][np.abs(faces["v05"][:, 0]) < FLUSH]
    # equilateral arch: the intrados apex is at sqrt(R^2 - e^2) = sqrt(3) above the springing
    assert sorted(crown[:, 1]) == pytest.approx([1.0 + math.sqrt(3.0), 1.0 + math.sqrt(2.3**2 - 1.0)], abs=FLUSH)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"voussoirs": 1}, "voussoirs"),
        ({"centre_offset_m": 0.5}, "centre_offset_m"),
        ({"piers": "fixed", "pier_height_m": 0.0}, "piers"),
        ({"shape": "gothic"}, "shape"),
    ],
)
def test_arch_refuses_bad_values(kwargs, field):
    with pytest.raises(InputError) as err:
        arch(**kwargs)
    assert err.value.field == field


# ---------------------------------------------------------------------- columns, frames, walls at the top


def test_drum_column_stacks_equal_drums_flush_and_both_layouts_place_them_alike():
    positioned = _placed(
        drum_column(drums=8, diameter_m=0.3, drum_height_m=0.45, capital_width_m=0.6, capital_height_m=0.2)
    )
    column = _placed(
        drum_column(
            drums=8, diameter_m=0.3, drum_height_m=0.45, capital_width_m=0.6, capital_height_m=0.2, layout="column"
        )
    )
    assert [b.name for b in positioned] == [f"d{k:02d}" for k in range(1, 9)] + ["capital"]
    for a, b in zip(positioned, column, strict=True):
        assert np.abs(a.vertices_m - b.vertices_m).max() < FLUSH
    tops = [float(b.vertices_m[:, 1].max()) for b in positioned]
    assert tops == pytest.approx([0.45 * k for k in range(1, 9)] + [3.8], abs=FLUSH)
    beds = [c for c in rest_contacts(positioned) if c.b >= 0]
    assert [round(c.length_m, 12) for c in beds] == [0.3] * 8


def test_round_drums_carry_a_cylinders_mass_and_inertia_into_housner_and_both_dems():
    """Issue "What users hit" 4: drums were square prisms (six 0.8 x 1 m drums of 2700 kg/m^3:
    10,368 kg instead of the cylinders' 8,143 kg). A round drum now writes m = rho pi D^2/4 h
    and I = m (3 r^2 + h^2)/12, and the solvers read them: Housner's p and both DEMs' bodies."""
    from rockyade.calibration.model_stage import calibrated_model
    from rockyade.scene.generators import round_drum_mass_inertia
    from rockyade.solvers import run
    from rockyade.yade.payload import scene_payload

    round_column = scene_from_dict(column(drums=6, diameter_m=0.8, drum_height_m=1.0, density_kg_m3=2700))
    square = scene_from_dict(column(drums=6, diameter_m=0.8, drum_height_m=1.0, density_kg_m3=2700, section="square"))
    assert sum(b.block().mass_kg for b in round_column.blocks) == pytest.approx(8143.0, abs=0.5)
    assert sum(b.block().mass_kg for b in square.blocks) == pytest.approx(10368.0)
    mass, inertia = round_drum_mass_inertia(0.8, 1.0, 2700.0)
    assert mass == pytest.approx(2700 * math.pi * 0.16) and inertia == pytest.approx(mass * (3 * 0.16 + 1.0) / 12)
    drum = round_column.blocks[0]
    assert drum.block().inertia_c_kgm2 == pytest.approx(inertia)
    classical = drum.classical()
    i_o = inertia + mass * classical.R_m**2  # about the pivot corner
    assert classical.p_rad_s == pytest.approx(math.sqrt(mass * 9.81 * classical.R_m / i_o))
    body = calibrated_model(round_column).bodies[0]
    assert (body.mass_kg, body.inertia_kgm2, body.p_rad_s) == pytest.approx((mass, inertia, classical.p_rad_s))
    payload = scene_payload(calibrated_model(round_column))["bodies"][0]  # what YADE is given
    assert (payload["mass_kg"], payload["inertia_kgm2"]) == pytest.approx((mass, inertia))
    # one round drum rocking freely: Housner and the reference DEM cross zero together
    data = column(1, diameter_m=0.8, drum_height_m=2.0, density_kg_m3=2700, duration_s=1.0)
    data.update(sample_dt_s=0.001, motion={"type": "free", "theta0_rad": 0.1, "block": "d01"})
    one = scene_from_dict(data)
    crossings = []
    for solver in ("housner", "reference"):
        theta = run(one, solver).series("theta_rad")
        crossings.append(int(np.flatnonzero(np.sign(theta[:-1]) != np.sign(theta[1:]))[0]))
    assert abs(crossings[0] - crossings[1]) <= 2  # samples of 1 ms (measured: the same sample)


def test_generators_import_under_the_names_the_cli_uses():
    """Issue "What users hit" 10: ``from rockyade.scene.generators import column`` gave the
    module; every kind of ``rockyade build`` is now a function of its own name (modules are
    plural, so none hides a function), and the former names still work."""
    import importlib

    import rockyade.scene.generators as generators

    assert set(GENERATORS) == set(KINDS)
    for kind, function in GENERATORS.items():
        name = kind.replace("-", "_")
        assert getattr(generators, name) is function and inspect.isfunction(function), kind
        assert function.__name__ == name
    for module in ("walls", "columns", "arches", "frames", "restrained_walls"):
        assert inspect.ismodule(importlib.import_module(f"rockyade.scene.generators.{module}"))
    assert generators.drum_column is generators.column and generators.rocking_frame is generators.frame


def test_continuous_taper_has_straight_sides():
    widths, top = tapered_widths(5, 0.5, 0.25, "continuous")
    placed = _placed(stack(widths_m=widths, heights_m=0.4, taper="continuous", top_width_m=top))
    left = np.vstack([b.vertices_m[b.vertices_m[:, 0] < 0] for b in placed])
    # every left vertex lies on the line from (-0.25, 0) to (-0.125, 2.0)
    expected_x = -0.25 + (0.125 / 2.0) * left[:, 1]
    assert np.abs(left[:, 0] - expected_x).max() < FLUSH
    assert tapered_widths(3, 0.4, 0.2) == ([0.4, 0.3, 0.2], None)


def test_frame_gamma_and_frequency():
    data = rocking_frame(column_width_m=0.2, column_height_m=1.2, span_m=1.0, beam_height_m=0.2, gamma=0.75)
    assert frame_gamma(data) == pytest.approx(0.75, rel=1e-12)
    scene = scene_from_dict(data)
    col = scene.blocks[0].classical()
    # p_hat from the closed form of Makris & Vassiliou with the column's own p
    assert frame_frequency(0.2, 1.2, 0.75) == pytest.approx(col.p_rad_s * math.sqrt(2.5 / 3.25), rel=1e-9)
    with pytest.raises(InputError) as err:
        rocking_frame(span_m=0.2)
    assert err.value.field == "span_m"


def test_restrained_wall_touches_its_fixed_restraint():
    placed = _placed(restrained_wall(wall_height_m=2.4, wall_thickness_m=0.3, restraint_height_m=0.25))
    names = [b.name for b in placed]
    assert names == ["w01", "w02", "restraint_far"]
    assert placed[2].fixed
    heads = [c for c in rest_contacts(placed) if c.kind == "head"]
    assert len(heads) == 1 and {heads[0].a, heads[0].b} == {1, 2}
    assert heads[0].length_m == pytest.approx(0.25, abs=FLUSH)
    floor = _placed(restrained_wall(blocks=1, restraint="floor"))
    beds = [c for c in rest_contacts(floor) if c.b >= 0]
    assert len(beds) == 1 and floor[beds[0].b].fixed and beds[0].length_m == pytest.approx(0.3, abs=FLUSH)


# ---------------------------------------------------------------------- TOML writer


def test_toml_writer_round_trips_scenes_and_floats_exactly():
    for kind, kwargs in VARIANTS:
        data = GENERATORS[kind](**kwargs)
        assert tomllib.loads(toml_text(data, "header\nsecond line")) == data
    rng = random.Random(7)
    values = [rng.uniform(-1e3, 1e3) * 10 ** rng.randint(-12, 12) for _ in range(300)] + [0.1 + 0.2, 1e10, 5e-324]
    assert tomllib.loads(toml_text({"x": values}))["x"] == values


def test_toml_writer_text_is_readable_and_refuses_what_toml_cannot_hold():
    text = toml_text({"a": 1, "name": 'say "hi"\n', "t": {"k": [1.5, 2]}, "items": [{"n": "b1"}, {"n": "b2"}]}, "top")
    assert text.splitlines()[0] == "# top"
    assert "[t]" in text and text.count("[[items]]") == 2
    assert 'name = "say \\"hi\\"\\n"' in text
    assert "k = [1.5, 2]" in text
    with pytest.raises(InputError):
        toml_text({"x": math.nan})
    with pytest.raises(InputError):
        toml_text({"x": [1.0, None]})


# ---------------------------------------------------------------------- CLI


def test_build_writes_scenes_that_load_from_another_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "records").mkdir()
    t = np.arange(0, 1.0, 0.01)
    (tmp_path / "records" / "r.csv").write_text("t,a\n" + "\n".join(f"{a:.3f},{0.5 * math.sin(6 * a):.5f}" for a in t))
    commands = [
        ["wall", "--courses", "4", "--opening", "0.8,0,0.8,0.4", "--out", "scenes/wall.toml"],
        ["arch", "--voussoirs", "7", "--piers", "fixed", "--out", "scenes/arch.json"],
        [
            "frame",
            "--gamma",
            "0.5",
            "--motion",
            "record",
            "--record",
            "records/r.csv",
            "--out",
            "scenes/a/frame.toml",
        ],
        ["column", "--drums", "4", "--motion", "free", "--free-block", "d01", "--out", "scenes/column.toml"],
        ["stack", "--blocks", "4", "--bottom-width-m", "0.4", "--top-width-m", "0.25", "--out", "scenes/stack.toml"],
        ["restrained-wall", "--blocks", "1", "--motion", "rest", "--out", "scenes/rwall.toml", "--draw", "rwall.png"],
    ]
    for words in commands:
        assert main(["build", *words]) == 0
    out = capsys.readouterr().out
    assert "wrote scenes/wall.toml: " in out and "wrote rwall.png" in out
    monkeypatch.chdir(tmp_path / "records")
    wall_scene = load_scene("../scenes/wall.toml")
    assert len(wall_scene.blocks) == len(wall(courses=4, openings=[(0.8, 0, 0.8, 0.4)])["blocks"])
    assert "lintel1" in [b.name for b in wall_scene.blocks]
    frame = load_scene("../scenes/a/frame.toml")
    assert frame.motion.type == "record"
    assert tomllib.loads((tmp_path / "scenes/a/frame.toml").read_text())["motion"]["file"] == "../../records/r.csv"
    assert frame_gamma(tomllib.loads((tmp_path / "scenes/a/frame.toml").read_text())) == pytest.approx(0.5)
    assert load_scene("../scenes/column.toml").motion.released_block == "d01"
    assert load_scene("../scenes/arch.json").blocks[0].fixed
    assert [b.width_m for b in load_scene("../scenes/stack.toml").blocks] == pytest.approx([0.4, 0.35, 0.3, 0.25])
    text = (tmp_path / "scenes/wall.toml").read_text()
    assert text.startswith("# A dry masonry wall")
    assert "rockyade build wall --courses 4 --opening 0.8,0,0.8,0.4 --out wall.toml" in text


@pytest.mark.parametrize(
    ("words", "needle"),
    [
        (["wall", "--unit-length-m", "-1"], "--unit-length-m: must be in (0, 1000] m"),
        (["wall", "--opening", "2.2,0,0.6,0.6"], "--opening #1 width_m"),
        (["arch", "--voussoirs", "1"], "--voussoirs: must be an integer in [2, 201]"),
        (["column", "--capital-width-m", "0.5"], "--capital-height-m: give both --capital-width-m"),
        (["frame", "--motion", "free"], "--free-block: is required"),
        (["frame", "--motion", "record", "--record", "nowhere.at2"], "--record: file not found"),
        (["stack", "--blocks", "3"], "--blocks: a linear taper needs"),
        (["wall", "--contact", "udec", "--jkn-pa-per-m", "0"], "--jkn-pa-per-m: must be in [1, 1e+15] Pa/m, got 0"),
        # a wall its default joints cannot carry: run would refuse it, so build does, before writing
        (["wall", "--courses", "12", "--jkn-pa-per-m", "1e9"], "--jkn-pa-per-m: K = "),
    ],
)
def test_build_bad_values_exit_2_with_one_line_naming_the_option(tmp_path, capsys, words, needle):
    assert main(["build", *words, "--out", str(tmp_path / "x.toml")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and needle in err
    assert not (tmp_path / "x.toml").exists()


def test_write_scene_refuses_other_suffixes(tmp_path):
    with pytest.raises(InputError):
        write_scene(tmp_path / "x.yaml", wall(courses=1, units_per_course=1))


def test_example_assemblies_load_and_are_what_their_command_makes(tmp_path, monkeypatch, capsys):

    files = sorted((EXAMPLES / "assemblies").glob("*.toml"))
    assert len(files) >= 5
    monkeypatch.chdir(tmp_path)
    for path in files:
        load_scene(path)
        made_by = next(line for line in path.read_text().splitlines() if line.startswith("# Made by rockyade"))
        words = shlex.split(made_by.split(": ", 1)[1])
        assert words[:2] == ["rockyade", "build"] and words[-2:] == ["--out", path.name]
        assert main(words[1:]) == 0
        assert tomllib.loads((tmp_path / path.name).read_text()) == tomllib.loads(path.read_text()), path.name
    capsys.readouterr()
