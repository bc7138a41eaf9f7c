"""Scene files: the issue's TOML works as written; every bad value gets a clear error."""

from __future__ import annotations

import copy
import json
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rockyade.errors import InputError
from rockyade.scene import load_scene, scene_from_dict

from .conftest import free_scene_dict

ISSUE_TOML = """\
duration_s = 4.0
sample_dt_s = 0.001
[[blocks]]
name = "specimen1"
width_m = 0.25
height_m = 1.0
thickness_m = 0.754
mass_kg = 503
alpha_rad = 0.235
p_rad_s = 3.84
mu = 0.936
[contact]
calibration = "paper"
[motion]
type = "free"
theta0_rad = 0.1175
"""


def test_issue_toml_works_as_written(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(ISSUE_TOML)
    scene = load_scene(path)
    assert scene.duration_s == 4.0 and scene.n_samples == 4001
    b = scene.blocks[0]
    assert (b.name, b.width_m, b.height_m, b.mass_kg, b.alpha_rad, b.mu) == (
        "specimen1",
        0.25,
        1.0,
        503,
        0.235,
        0.936,
    )
    assert scene.contact.calibration == "paper"
    assert scene.motion.type == "free" and scene.motion.initial_theta_rad == 0.1175


def test_toml_and_json_give_the_same_scene_and_hash(tmp_path):
    t = tmp_path / "s.toml"
    t.write_text(ISSUE_TOML)
    j = tmp_path / "s.json"
    j.write_text(json.dumps(free_scene_dict()))
    a, b = load_scene(t), load_scene(j)
    assert a.to_dict() == b.to_dict()
    assert a.scene_hash == b.scene_hash and len(a.scene_hash) == 16


def test_hash_changes_with_physics():
    a = scene_from_dict(free_scene_dict())
    b = scene_from_dict(free_scene_dict(mu=0.93))
    assert a.scene_hash != b.scene_hash


def test_canonical_dict_round_trips(tmp_path):
    scene = scene_from_dict(free_scene_dict())
    path = tmp_path / "c.json"
    scene.write_json(path)
    assert load_scene(path).to_dict() == scene.to_dict()


def test_examples_all_load(examples_dir):
    paths = sorted(examples_dir.glob("*.toml"))
    assert len(paths) >= 5
    for path in paths:
        load_scene(path)


def _with(path: list, value):
    d = free_scene_dict()
    target = d
    for key in path[:-1]:
        target = target[key]
    if value is _DELETE:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return d


_DELETE = object()


@pytest.mark.parametrize(
    ("path", "value", "field", "text"),
    [
        (["duration_s"], 0.0, "duration_s", "(0, 100000]"),
        (["duration_s"], _DELETE, "duration_s", "required"),
        (["sample_dt_s"], -0.001, "sample_dt_s", "[1e-06, 10]"),
        (["sample_dt_s"], 10.0, "sample_dt_s", "<= duration_s"),
        (["blocks", 0, "width_m"], 0.0, "blocks[0].width_m", "[0.001, 1000]"),
        (["blocks", 0, "height_m"], -1.0, "blocks[0].height_m", "[0.001, 1000]"),
        (["blocks", 0, "thickness_m"], _DELETE, "blocks[0].thickness_m", "required"),
        (["blocks", 0, "mass_kg"], float("nan"), "blocks[0].mass_kg", "finite"),
        (["blocks", 0, "alpha_rad"], math.pi / 2, "blocks[0].alpha_rad", "pi/2"),
        (["blocks", 0, "alpha_rad"], 2.0, "blocks[0].alpha_rad", "pi/2"),
        (["blocks", 0, "mu"], 1.01, "blocks[0].mu", "[0.05, 0.9999]"),
        (["blocks", 0, "mu"], 0.0, "blocks[0].mu", "[0.05, 0.9999]"),
        (["blocks", 0, "p_rad_s"], "fast", "blocks[0].p_rad_s", "number"),
        (["blocks", 0, "colour"], "red", "blocks[0].colour", "unknown key"),
        (["blocks", 0, "name"], "1st", "blocks[0].name", "start with a letter"),
        (["contact", "calibration"], "fitted", "contact.calibration", "'paper', 'matched'"),
        (["contact", "friction_angle_deg"], 95.0, "contact.friction_angle_deg", "[0, 90)"),
        (["contact", "cohesion_Pa"], 1000.0, "contact.cohesion_Pa", "must be 0"),
        (["contact", "stiffness_scale"], "GN/m", "contact.stiffness_scale", "MN/m"),
        (["contact", "K"], 1e9, "contact.K", "unknown key"),
        (["motion", "type"], "quake", "motion.type", "must be one of"),
        (["motion", "theta0_rad"], 2.0, "motion.theta0_rad", "pi/2"),
        (["motion", "theta0_rad"], _DELETE, "motion.theta0_rad", "required"),
        (["motion", "block"], "nope", "motion.block", "no block"),
        (["motion", "speed"], 1, "motion.speed", "unknown key"),
        (["extra"], 1, "extra", "unknown key"),
    ],
)
def test_bad_values_name_field_and_range(path, value, field, text):
    with pytest.raises(InputError) as info:
        scene_from_dict(_with(path, value), source="test.toml")
    assert info.value.field == field
    assert text in str(info.value)
    assert str(info.value).startswith("test.toml: ")


def test_both_mass_and_density_rejected():
    d = free_scene_dict(density_kg_m3=2650)
    with pytest.raises(InputError, match="exactly one of mass_kg and density_kg_m3"):
        scene_from_dict(d)


def test_both_inertia_and_p_rejected():
    with pytest.raises(InputError) as info:
        scene_from_dict(free_scene_dict(inertia_kgm2=40.0))
    assert info.value.field == "blocks[0].p_rad_s"


def test_stack_must_rest_on_block_below():
    d = free_scene_dict()
    upper = copy.deepcopy(d["blocks"][0])
    upper["name"] = "upper"
    upper["x_offset_m"] = 2.0
    d["blocks"].append(upper)
    with pytest.raises(InputError) as info:
        scene_from_dict(d)
    assert info.value.field == "blocks[1].x_offset_m"


def test_duplicate_block_names_rejected():
    d = free_scene_dict()
    d["blocks"].append(copy.deepcopy(d["blocks"][0]))
    with pytest.raises(InputError, match="duplicate"):
        scene_from_dict(d)


def test_bad_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("duration_s = = 3")
    with pytest.raises(InputError, match="not valid TOML"):
        load_scene(bad)
    with pytest.raises(InputError, match="file not found"):
        load_scene(tmp_path / "missing.toml")
    other = tmp_path / "scene.yaml"
    other.write_text("x")
    with pytest.raises(InputError, match=r"use \.toml or \.json"):
        load_scene(other)


NUMERIC_FIELDS = [
    ("duration_s",),
    ("sample_dt_s",),
    ("blocks", 0, "width_m"),
    ("blocks", 0, "height_m"),
    ("blocks", 0, "thickness_m"),
    ("blocks", 0, "mass_kg"),
    ("blocks", 0, "alpha_rad"),
    ("blocks", 0, "p_rad_s"),
    ("blocks", 0, "mu"),
    ("motion", "theta0_rad"),
]


@settings(max_examples=150, deadline=None)
@given(
    target=st.sampled_from(NUMERIC_FIELDS),
    value=st.one_of(
        st.floats(allow_nan=True, allow_infinity=True),
        st.text(max_size=5),
        st.booleans(),
        st.none(),
        st.lists(st.integers(), max_size=2),
    ),
)
def test_property_any_value_is_accepted_or_rejected_with_its_field(target, value):
    """Whatever is put in a numeric field, the scene is either valid or the error names a
    field; it never raises anything but InputError."""
    d = _with(list(target), value)
    try:
        scene = scene_from_dict(d)
    except InputError as exc:
        assert exc.field
        assert exc.message
    else:
        assert scene.duration_s > 0 and math.isfinite(scene.duration_s)
        cp = scene.blocks[0].classical()
        assert 0 < cp.alpha_rad < math.pi / 2 and 0 < cp.mu <= 1 and cp.p_rad_s > 0
