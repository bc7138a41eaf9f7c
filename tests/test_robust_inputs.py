"""Bad, absurd and oversized inputs: each refused with the field and its range, never a
traceback; every physical input bounded; a cost estimate before any run."""

from __future__ import annotations

import copy
import math
import re

import numpy as np
import pytest

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.runner.cost_limits import LIMITS, check_cost, estimate_cost
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.bounds import BOUNDS

from .conftest import EXAMPLES, ROOT, free_scene_dict


def _refused(d: dict, field: str, *words: str) -> str:
    with pytest.raises(InputError) as info:
        scene_from_dict(d, source="s.toml")
    assert info.value.field == field, str(info.value)
    for word in words:
        assert word in str(info.value)
    return str(info.value)


def _polygon(vertices) -> dict:
    d = free_scene_dict()
    block = d["blocks"][0]
    for key in ("width_m", "height_m", "alpha_rad", "p_rad_s", "mu"):
        block.pop(key)
    block["vertices_m"] = vertices
    return d


def test_non_utf8_scene_names_the_byte(tmp_path):
    path = tmp_path / "s.toml"
    path.write_bytes((EXAMPLES / "specimen1_free.toml").read_bytes().replace(b"specimen1", b"sp\xe9cimen", 1))
    with pytest.raises(InputError, match=r"not UTF-8 text \(byte 0xe9"):
        load_scene(path)


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_nesting_a_thousand_deep_is_an_error(tmp_path, suffix):
    path = tmp_path / f"s{suffix}"
    deep = "[" * 5000 + "]" * 5000
    path.write_text(f'{{"duration_s": {deep}}}' if suffix == ".json" else f"duration_s = {deep}\n")
    with pytest.raises(InputError, match=r"nested too deeply|nesting deeper"):
        load_scene(path)


def test_nesting_given_as_a_dictionary_is_bounded():
    d = free_scene_dict()
    deep: list = []
    for _ in range(1200):
        deep = [deep]
    d["motion"]["theta0_rad"] = deep
    with pytest.raises(InputError, match="nesting deeper than 32 levels") as info:
        scene_from_dict(d)
    assert info.value.field.startswith("scene.motion.theta0_rad[0][0]")


def test_integer_beyond_float_range(tmp_path):
    d = free_scene_dict()
    d["duration_s"] = 10**400
    _refused(d, "duration_s", "finite number in (0, 100000]")
    path = tmp_path / "s.json"
    path.write_text((EXAMPLES / "specimen1_free.toml").read_text() and '{"duration_s": 1' + "0" * 5000 + "}")
    with pytest.raises(InputError):
        load_scene(path)


@pytest.mark.parametrize(
    ("key", "value", "field"),
    [
        ("width_m", 5e-324, "blocks[0].width_m"),
        ("mass_kg", 5e-324, "blocks[0].mass_kg"),
        ("thickness_m", 1e-300, "blocks[0].thickness_m"),
        ("mu", 1e-12, "blocks[0].mu"),
        ("p_rad_s", 1e30, "blocks[0].p_rad_s"),
        ("inertia_kgm2", 1e-9, "blocks[0].inertia_kgm2"),
    ],
)
def test_subnormal_and_absurd_block_values(key, value, field):
    d = free_scene_dict(**({"p_rad_s": None} if key == "inertia_kgm2" else {}))
    d["blocks"][0][key] = value
    _refused(d, field, "must be in [")


def test_collinear_and_self_intersecting_polygons():
    _refused(_polygon([[0, 0], [1, 0], [2, 0]]), "blocks[0].vertices_m", "no area")
    angles = [math.pi / 2 + k * 4 * math.pi / 5 for k in range(5)]
    star = [[math.cos(a), math.sin(a)] for a in angles]  # a pentagram: every turn to the left
    _refused(_polygon(star), "blocks[0].vertices_m", "crosses itself")
    # a vertex in the middle of an edge is dropped, not an error
    scene = scene_from_dict(_polygon([[0, 0], [0.125, 0], [0.25, 0], [0.25, 1], [0, 1]]))
    assert len(scene.blocks[0].block().vertices_m) == 4


@pytest.mark.parametrize(
    ("table", "key", "value", "field", "words"),
    [
        ("output", "accel_point", [1e300, 0.0], "output.accel_point", ["[-1000, 1000] m"]),
        ("output", "accel_lowpass_hz", 1e-300, "output.accel_lowpass_hz", ["[0.1, 10000]"]),
        ("output", "accel_lowpass_hz", 600.0, "output.accel_lowpass_hz", ["Nyquist", "500 Hz"]),
        ("contact", "dt_s", 1e-9, "contact.dt_s", ["[1e-08, 0.01]"]),
        ("contact", "time_step_frac", 1e-12, "contact.time_step_frac", ["[0.001, 1]"]),
        ("contact", "beta_s", 10.0, "contact.beta_s", ["[0, 0.1]"]),
        ("motion", "omega0_rad_s", 1e9, "motion.omega0_rad_s", ["[-100, 100]"]),
    ],
)
def test_physical_inputs_are_bounded(table, key, value, field, words):
    d = free_scene_dict()
    d.setdefault(table, {})[key] = value
    _refused(d, field, *words)


def test_harmonic_start_is_bounded():
    d = free_scene_dict()
    d["motion"] = {"type": "harmonic", "amplitude_mm": 6.0, "frequency_hz": 3.3, "cycles": 20, "start_s": 1e5}
    _refused(d, "motion.start_s", "[0, 1000]")


def test_unknown_key_is_named_with_its_likely_meaning():
    d = free_scene_dict()
    d["blocks"][0]["width_mm"] = d["blocks"][0].pop("width_m")
    message = _refused(d, "blocks[0].width_mm", "unknown key", "width_m")
    assert "did you mean width_m?" in message
    # a key under another name, not a misspelling: the required key's error shows what was given
    d = free_scene_dict()
    d["motion"] = {"type": "record", "path": "x.AT2"}
    message = _refused(d, "motion.file", "is required")
    assert "also in this table: path" in message


def test_numpy_arrays_and_scalars_are_accepted():
    d = _polygon(np.array([[0.0, 0.0], [0.25, 0.0], [0.25, 1.0], [0.0, 1.0]]))
    d["duration_s"] = np.float64(1.0)
    d["blocks"][0]["mass_kg"] = np.int64(503)
    d["motion"]["theta0_rad"] = np.float32(0.1)
    scene = scene_from_dict(d)
    plain = scene_from_dict(copy.deepcopy(scene.to_dict()))
    assert scene.scene_hash == plain.scene_hash and scene.duration_s == 1.0
    assert isinstance(scene.blocks[0].vertices_m[0][0], float)


def test_every_documented_bound_is_in_the_docs():
    text = (ROOT / "docs" / "robustness.md").read_text()
    for name, bound in BOUNDS.items():
        row = next((line for line in text.splitlines() if f"`{name}`" in line), None)
        assert row is not None, f"{name} is not documented"
        numbers = {float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", row.split(f"`{name}`")[1])}
        assert any(math.isclose(bound.hi, x, rel_tol=1e-3) for x in numbers), (name, row)
    for name, limit in LIMITS.items():
        assert f"`{name}`" in text and f"{limit:.3g}" in text, name


# --------------------------------------------------------------------- cost


def _long(duration: float, sample_dt: float, **contact) -> dict:
    d = free_scene_dict(duration=duration)
    d["sample_dt_s"] = sample_dt
    d["contact"].update(contact)
    return d


def test_cost_estimate_of_an_example_matches_the_model():
    from rockyade.calibration.model_stage import calibrated_model

    d = load_scene(EXAMPLES / "specimen1_harmonic.toml").to_dict()
    d["contact"]["calibration"] = "paper"
    scene = scene_from_dict(d)
    est = estimate_cost(scene, "reference")
    model = calibrated_model(scene)
    assert est.integration_steps == model.n_steps
    assert est.motion_samples == model.motion.t_s.size
    assert est.output_samples == scene.n_samples and not est.over_limits(LIMITS)
    assert estimate_cost(scene, "yade").wall_time_s > est.wall_time_s


@pytest.mark.parametrize(
    ("d", "solver", "what"),
    [
        (_long(1000.0, 0.0001), "housner", "output samples"),
        (_long(4.0, 0.001, dt_s=1e-8), "reference", "integration steps"),
        (_long(4.0, 0.001, dt_s=1e-8), "yade", "integration steps"),
    ],
)
def test_cost_above_the_limits_is_refused_unless_allowed(d, solver, what):
    scene = scene_from_dict(d)
    with pytest.raises(InputError) as info:
        check_cost(scene, solver)
    assert info.value.field == "allow_large" and what in str(info.value) and "--allow-large" in str(info.value)
    assert check_cost(scene, solver, allow_large=True).over_limits(LIMITS)


def test_long_harmonic_motion_is_refused_by_its_samples():
    d = free_scene_dict()
    d["motion"] = {"type": "harmonic", "amplitude_mm": 1.0, "frequency_hz": 100.0, "cycles": 100_000, "start_s": 900}
    with pytest.raises(InputError, match="base-motion samples"):
        check_cost(scene_from_dict(d), "housner")


def test_cli_refuses_a_large_run_before_running(tmp_path, capsys):
    scene = tmp_path / "big.toml"
    scene.write_text(
        (EXAMPLES / "specimen1_free.toml")
        .read_text()
        .replace("sample_dt_s = 0.001", "sample_dt_s = 0.00001")
        .replace("duration_s = 4.0", "duration_s = 100.0")
    )
    assert main(["run", str(scene), "--out", str(tmp_path / "r.csv")]) == 2
    err = capsys.readouterr().err
    assert "allow_large:" in err and "1e+07 output samples" in err and "--allow-large" in err
    assert not (tmp_path / "r.csv").exists()


# ---------------------------------------------------------------------- scene files: size, duplicates


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_a_huge_scene_file_is_refused_at_once_with_its_size_and_the_cap(tmp_path, suffix):
    """A 200 MB scene (about 1e8 inline samples) used to be refused after 207 s and 6.5 GB."""
    import time

    from rockyade.scene.loading import MAX_SCENE_BYTES

    path = tmp_path / f"huge{suffix}"
    with path.open("wb") as fh:  # sparse: 200 MB that cost no disk
        fh.write(b"duration_s = 1.0\n" if suffix == ".toml" else b'{"duration_s": 1.0, "x": [')
        fh.truncate(200_000_000)
    start = time.perf_counter()
    with pytest.raises(InputError) as info:
        load_scene(path)
    elapsed = time.perf_counter() - start
    assert elapsed < 1.0
    message = str(info.value)
    assert str(path) in message and "200,000,000 bytes" in message and f"{MAX_SCENE_BYTES:,}" in message
    assert main(["run", str(path)]) == 2


def test_a_scene_just_under_the_cap_is_read(tmp_path, monkeypatch):
    from rockyade.scene import loading

    text = (EXAMPLES / "specimen1_free.toml").read_bytes()
    path = tmp_path / "s.toml"
    path.write_bytes(text)
    monkeypatch.setattr(loading, "MAX_SCENE_BYTES", len(text))
    assert load_scene(path).duration_s > 0
    monkeypatch.setattr(loading, "MAX_SCENE_BYTES", len(text) - 1)
    with pytest.raises(InputError, match=f"has {len(text)} bytes"):
        load_scene(path)


@pytest.mark.parametrize(
    ("splice", "key"),
    [(("{", '{"duration_s": 40.0, '), "duration_s"), (('"motion": {', '"motion": {"theta0_rad": 0.2, '), "theta0_rad")],
)
def test_json_scenes_with_a_key_twice_are_refused_naming_it(tmp_path, splice, key):
    """TOML refuses a key given twice; JSON readers keep the last value: both refuse it now."""
    import json

    body = json.dumps(free_scene_dict()).replace(*splice, 1)
    assert body.count(f'"{key}"') == 2
    path = tmp_path / "s.json"
    path.write_text(body)
    with pytest.raises(InputError) as info:
        load_scene(path)
    assert f"the key '{key}' appears twice" in str(info.value) and str(path) in str(info.value)
    toml = tmp_path / "s.toml"
    toml.write_text(f"{key} = 1.0\n{key} = 2.0\n")
    with pytest.raises(InputError, match="not valid TOML"):
        load_scene(toml)
