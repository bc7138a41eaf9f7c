"""What a study file's grid may hold: keys with alternatives, record files named from the
study, grids too large to build, duplicate grid points, relative outputs, and what the
summary says about a motion the runs leave out."""

from __future__ import annotations

import json
import re
import shutil
import time
from pathlib import Path

import pandas as pd
import pytest

from rockyade.batch import comparable, expand, load_study, run_study_tasks, study_tasks
from rockyade.batch import study as study_file
from rockyade.batch.running import keeping_files, output
from rockyade.batch.study import ALTERNATIVES, MAX_RUNS, MAX_RUNS_ALLOWED
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.scene import load_scene, scene_from_dict

from .conftest import EXAMPLES

ROOT = Path(__file__).resolve().parents[1]


def _study(folder: Path, body: str, name: str = "study.toml") -> Path:
    path = folder / name
    path.write_text(body)
    return path


def _base(example: str) -> str:
    return json.dumps(str(EXAMPLES / example))


# ---------------------------------------------------------------------- keys with alternatives


def test_a_grid_over_amplitude_g_runs_on_a_scene_given_in_g(tmp_path):
    """examples/specimen1_pulse.toml gives amplitude_g; its canonical form holds
    amplitude_m_s2. A grid over amplitude_g replaces it (it used to fail naming
    motion.amplitude_m_s2, a key the user never wrote)."""
    grid = '"motion.amplitude_g" = [0.3, 0.5]'
    path = _study(tmp_path, f"[base]\nfile = {_base('specimen1_pulse.toml')}\n[grid]\n{grid}\n")
    tasks = list(study_tasks(load_study(path)))
    assert [t.scene.motion.amplitude_m_s2 for t in tasks] == pytest.approx([0.3 * G, 0.5 * G])
    assert [t.labels["motion.amplitude_g"] for t in tasks] == [0.3, 0.5]


def _sampled_scene(folder: Path) -> Path:
    d = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    d.update(duration_s=0.5, sample_dt_s=0.01)
    d["motion"] = {"type": "sampled", "accel_m_s2": [0.0, 1.0, 0.0, -1.0, 0.0], "dt_s": 0.05}
    path = folder / "sampled.json"
    path.write_text(json.dumps(d))
    return path


def _vertices_scene(folder: Path) -> Path:
    d = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    block = d["blocks"][0]
    w, h = block.pop("width_m"), block.pop("height_m")
    block.pop("alpha_rad", None)
    block["vertices_m"] = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]]
    path = folder / "polygon.json"
    path.write_text(json.dumps(d))
    return path


# (base scene, grid key, values, what the scene then holds)
CASES = {
    "amplitude_g": ("specimen1_pulse.toml", "motion.amplitude_g", [0.2], lambda s: s.motion.amplitude_m_s2 / G),
    "amplitude_m_s2": ("specimen1_pulse.toml", "motion.amplitude_m_s2", [2.0], lambda s: s.motion.amplitude_m_s2),
    "density_kg_m3": ("specimen1_free.toml", "blocks.0.density_kg_m3", [2000.0], lambda s: s.blocks[0].density_kg_m3),
    "mass_kg": (None, "blocks.0.mass_kg", [300.0], lambda s: s.blocks[0].mass_kg),  # base given by density
    "inertia_kgm2": ("specimen1_free.toml", "blocks.0.inertia_kgm2", [100.0], lambda s: s.blocks[0].inertia_kgm2),
    "p_rad_s": (None, "blocks.0.p_rad_s", [3.0], lambda s: s.blocks[0].p_rad_s),  # base given by inertia
    "vertices_m": (
        "specimen3_free.toml",
        "blocks.0.vertices_m",
        [[[0.0, 0.0], [0.2, 0.0], [0.2, 0.8], [0.0, 0.8]]],
        lambda s: s.blocks[0].vertices_m[2][1],
    ),
    "width_m": ("polygon", "blocks.0.width_m", [0.2], lambda s: s.blocks[0].width_m),
    "height_m": ("polygon", "blocks.0.height_m", [0.8], lambda s: s.blocks[0].height_m),
    "t_s": ("sampled", "motion.t_s", [[0.0, 0.05, 0.1, 0.2, 0.3]], lambda s: s.motion.t_s[-1]),
    "dt_s": ("sampled_t", "motion.dt_s", [0.04], lambda s: s.motion.dt_s),
    "duration_s": ("specimen1_harmonic.toml", "motion.duration_s", [2.0], lambda s: s.motion.cycles),
    "cycles": ("harmonic_duration", "motion.cycles", [3], lambda s: s.motion.cycles),
}


def _base_for(case: str, folder: Path) -> Path:
    example, key, *_ = CASES[case]
    if example == "polygon":
        return _vertices_scene(folder)
    if example in ("sampled", "sampled_t"):
        path = _sampled_scene(folder)
        if example == "sampled_t":
            d = json.loads(path.read_text())
            d["motion"] = {**{k: v for k, v in d["motion"].items() if k != "dt_s"}, "t_s": [0, 0.05, 0.1, 0.15, 0.2]}
            path.write_text(json.dumps(d))
        return path
    if example == "harmonic_duration":
        d = load_scene(EXAMPLES / "specimen1_harmonic.toml").to_dict()
        d["motion"].pop("cycles")
        d["motion"]["duration_s"] = 2.0
        path = folder / "harmonic.json"
        path.write_text(json.dumps(d))
        return path
    if example is None:  # the other of the pair given in the base
        d = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
        block = d["blocks"][0]
        if key.endswith("mass_kg"):
            block.pop("mass_kg")
            block["density_kg_m3"] = 2600.0
        else:
            block.pop("p_rad_s")
            block["inertia_kgm2"] = 40.0
        path = folder / "other.json"
        path.write_text(json.dumps(d))
        return path
    return EXAMPLES / example


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_grid_key_replaces_its_alternatives(case, tmp_path):
    _example, key, values, read = CASES[case]
    base = _base_for(case, tmp_path)
    grid = f"{json.dumps(key)} = {json.dumps(values)}"
    if case in ("width_m", "height_m"):  # a rectangle needs both
        partner = "height_m" if case == "width_m" else "width_m"
        grid += f'\n"blocks.0.{partner}" = {CASES[partner][2]}'
    path = _study(tmp_path, f"[base]\nfile = {json.dumps(str(base))}\n[grid]\n{grid}\n")
    (task,) = list(study_tasks(load_study(path)))
    expected = values[0]
    if case == "vertices_m":
        expected = 0.8
    elif case == "duration_s":
        expected = round(2.0 * task.scene.motion.frequency_hz)
    elif case == "t_s":
        expected = 0.3
    assert read(task.scene) == pytest.approx(expected)


@pytest.mark.parametrize("key", sorted(ALTERNATIVES))
def test_each_alternative_is_one_the_scene_format_takes_only_alone(key, tmp_path):
    """ALTERNATIVES is the scene format's: a table that holds a key and its alternative is
    refused by the scene reader (so replacing one by the other is what the user meant)."""
    assert key in CASES
    base = _base_for(key, tmp_path)
    d = load_scene(base).to_dict()
    table = d["motion"] if CASES[key][1].startswith("motion.") else d["blocks"][0]
    for other in ALTERNATIVES[key]:
        both = json.loads(json.dumps(d))
        target = both["motion"] if table is d["motion"] else both["blocks"][0]
        target[key] = CASES[key][2][0]
        target[other] = target.get(other, CASES[other][2][0])
        with pytest.raises(InputError):
            scene_from_dict(both)


def test_every_exactly_one_of_pair_of_the_scene_format_is_an_alternative():
    """The scene readers' messages "give exactly one of A and B" / "give either A or B"
    name pairs ALTERNATIVES must hold (a new pair fails here until it is added)."""
    sources = [ROOT / "rockyade" / p for p in ("scene/loading.py", "motion/types.py", "motion/spec.py")]
    pairs = set()
    for source in sources:
        text = source.read_text()
        pairs |= set(re.findall(r"give exactly one of (\w+)(?: \([^)]*\))? and (\w+)", text))
        pairs |= set(re.findall(r"give either (\w+) or (\w+)", text))
    assert len(pairs) >= 5
    for a, b in pairs:
        assert b in ALTERNATIVES.get(a, ()) and a in ALTERNATIVES.get(b, ()), (a, b)


def test_a_grid_setting_a_key_and_its_alternative_is_refused(tmp_path):
    path = _study(
        tmp_path,
        f'[base]\nfile = {_base("specimen1_pulse.toml")}\n[grid]\n"motion.amplitude_g" = [0.3]\n'
        '"motion.amplitude_m_s2" = [3.0]\n',
    )
    with pytest.raises(InputError) as info:
        load_study(path)
    assert info.value.field == "grid.motion.amplitude_m_s2" and "grid.motion.amplitude_g" in info.value.message


# ---------------------------------------------------------------------- record files from the study


def test_record_files_in_a_grid_are_named_from_the_study_file(tmp_path, monkeypatch):
    studies = tmp_path / "studies"
    (studies / "records").mkdir(parents=True)
    for name in ("ricker_pulse_T0.5s.AT2", "ec8_type2_D_record21.AT2"):
        shutil.copy(EXAMPLES / "records" / name, studies / "records" / name)
    path = _study(
        studies,
        f"[base]\nfile = {_base('specimen1_record.toml')}\n[grid]\n"
        '"motion.file" = ["records/ricker_pulse_T0.5s.AT2", "records/ec8_type2_D_record21.AT2"]\n',
    )
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    tasks = list(study_tasks(load_study(Path("../studies/study.toml"))))
    files = [Path(t.scene.motion.file) for t in tasks]
    names = ("ricker_pulse_T0.5s.AT2", "ec8_type2_D_record21.AT2")
    assert files == [(studies / "records" / n).resolve() for n in names]
    path.write_text(path.read_text().replace("ec8_type2_D_record21", "missing"))
    with pytest.raises(InputError) as info:  # the grid's points are made as they are asked for
        list(study_tasks(load_study(Path("../studies/study.toml"))))
    tried = str((studies / "records" / "missing.AT2").resolve())
    assert info.value.field == "motion.file" and tried in info.value.message
    assert "motion.file = records/missing.AT2" in info.value.message  # the grid point


# ---------------------------------------------------------------------- the study: read once, points as asked


def test_a_study_reads_its_base_scene_once_and_makes_its_points_as_they_are_asked_for(tmp_path, monkeypatch):
    import rockyade.scene as scene_package

    reads = []
    read = scene_package.load_scene
    monkeypatch.setattr(scene_package, "load_scene", lambda path: reads.append(path) or read(path))
    path = _study(
        tmp_path,
        f'solvers = ["reference", "housner"]\n[base]\nfile = {_base("specimen3_free.toml")}\n[grid]\n'
        '"blocks.0.mu" = [0.9, 0.95, 2.0]\n',  # the last is not a valid scene
    )
    study = load_study(path)
    assert study.run_count == 6 and study.solver_names == ("reference", "housner") and len(reads) == 1
    tasks = study_tasks(study)
    first = [next(tasks) for _ in range(4)]  # two points x two solvers: the bad point not made yet
    assert [t.index for t in first] == [0, 1, 2, 3] and [t.labels["blocks.0.mu"] for t in first] == [
        0.9,
        0.9,
        0.95,
        0.95,
    ]
    with pytest.raises(InputError) as info:
        next(tasks)
    assert info.value.field == "blocks[0].mu" and "blocks.0.mu = 2.0" in info.value.message
    assert len(reads) == 1  # every point from the scene read once


def test_a_study_made_in_python_checks_its_run_count_when_made(monkeypatch):
    monkeypatch.setattr(study_file, "MAX_RUNS", 3)
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    grid = {"motion.theta0_rad": [0.01, 0.02]}
    with pytest.raises(InputError, match="4 runs"):
        study_file.make_study([("s", base)], grid, ["reference", "housner"])
    assert study_file.make_study([("s", base)], grid, ["reference", "housner"], allow_large=True).run_count == 4


# ---------------------------------------------------------------------- huge grids


def test_a_grid_of_a_billion_runs_is_refused_at_once(tmp_path):
    values = ", ".join(str(i) for i in range(1000))
    path = _study(
        tmp_path,
        f'[base]\nfile = {_base("specimen1_harmonic.toml")}\n[grid]\n"motion.amplitude_mm" = [{values}]\n'
        f'"motion.frequency_hz" = [{values}]\n"motion.cycles" = [{values}]\n',
    )
    start = time.perf_counter()
    with pytest.raises(InputError) as info:
        load_study(path)
    assert time.perf_counter() - start < 1.0
    assert info.value.field == "grid" and "1,000,000,000 runs" in info.value.message
    assert f"{MAX_RUNS:,}" in info.value.message and "--allow-large" in info.value.message
    with pytest.raises(InputError) as info:  # --allow-large does not lift the ceiling
        load_study(path, allow_large=True)
    assert f"{MAX_RUNS_ALLOWED:,}" in info.value.message


def test_a_list_of_a_million_values_is_refused_at_once(tmp_path):
    values = ", ".join(str(i) for i in range(1_000_000))
    base = _base("specimen1_harmonic.toml")
    path = _study(tmp_path, f'[base]\nfile = {base}\n[grid]\n"motion.cycles" = [{values}]\n')
    start = time.perf_counter()
    with pytest.raises(InputError) as info:
        load_study(path)
    assert time.perf_counter() - start < 1.0
    assert "bytes" in info.value.message or "1,000,000 runs" in info.value.message


def test_allow_large_lifts_the_run_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(study_file, "MAX_RUNS", 3)
    path = _study(
        tmp_path,
        f'solvers = ["reference", "housner"]\n[base]\nfile = {_base("specimen3_free.toml")}\n[grid]\n'
        '"motion.theta0_rad" = [0.01, 0.02]\n',
    )
    with pytest.raises(InputError, match="4 runs"):
        load_study(path)
    assert len(list(study_tasks(load_study(path, allow_large=True)))) == 4


# ---------------------------------------------------------------------- outputs, duplicates


def test_output_paths_are_absolute_on_the_client(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    out = output("rel/out")
    assert Path(out.out_dir) == tmp_path / "rel" / "out" and out.runs == tmp_path / "rel" / "out" / "runs"
    (task,) = expand([("s", base)], {}, ["yade"])
    assert task.solver.workdir is None  # the folder goes to the run once, beside the task
    assert Path(keeping_files(task, out).solver.workdir) == tmp_path / "rel" / "out" / "runs" / "yade"


def _duplicates(out: Path) -> list:
    base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
    base["duration_s"] = 0.5
    # 0.03 twice, and 0.05 written two ways (the same scene)
    grid = {"motion.theta0_rad": [0.03, 0.05, 0.03, 0.050000000000000000001]}
    return expand([("s", base)], grid, ["reference"])


@pytest.mark.parametrize("executor,workers", [("threads", 1), ("local", 2), ("dask", 2)])
def test_duplicate_grid_points_run_once_and_are_reported(tmp_path, executor, workers):
    if executor == "dask":
        pytest.importorskip("dask")
    tasks = _duplicates(tmp_path)
    summary = run_study_tasks(tasks, tmp_path, executor=executor, workers=workers, progress=False)
    assert list(summary["index"]) == [0, 1, 2, 3]
    assert (summary.status == "completed").all() and (summary.failure_reason.fillna("") == "").all()
    assert summary["duplicate_of"].tolist()[:2] == [-1, -1] and summary["duplicate_of"].tolist()[2:] == [0, 1]
    assert summary.loc[2, "run"] == summary.loc[0, "run"] and summary.loc[3, "run"] == summary.loc[1, "run"]
    assert len(list((tmp_path / "runs").glob("*.json"))) == 2
    for column in ("max_abs_theta_rad",):
        assert summary.loc[2, column] == summary.loc[0, column]
    resumed = run_study_tasks(
        _duplicates(tmp_path), tmp_path, executor=executor, workers=workers, progress=False, resume=True
    )
    pd.testing.assert_frame_equal(comparable(resumed), comparable(summary))


# ---------------------------------------------------------------------- motion coverage


def test_the_summary_says_how_much_of_the_record_s_pga_was_left_out(tmp_path):
    base = load_scene(EXAMPLES / "specimen1_record.toml").to_dict()
    base["sample_dt_s"] = 0.01
    grid = {"duration_s": [0.4, 8.0]}  # the Ricker pulse peaks after 0.4 s
    tasks = expand([("s", base)], grid, ["housner"])
    summary = run_study_tasks(tasks, tmp_path, executor="threads", workers=1, progress=False)
    short, whole = summary.iloc[0], summary.iloc[1]
    assert short["motion_pga_left_out_fraction"] > 0.5 and short["motion_time_left_out_s"] > 0
    assert whole["motion_pga_left_out_fraction"] == 0.0 and whole["motion_time_left_out_s"] == 0.0
    meta = json.loads((tmp_path / "runs" / f"{short['run']}.json").read_text())
    assert meta["motion_coverage"]["status"] == "cut"


def test_the_batch_command_refuses_a_large_grid_unless_allowed(tmp_path, monkeypatch, capsys):
    from rockyade.cli import main

    monkeypatch.setattr(study_file, "MAX_RUNS", 1)
    path = _study(
        tmp_path,
        f'solvers = ["housner"]\n[base]\nfile = {_base("specimen3_free.toml")}\n[grid]\n'
        '"motion.theta0_rad" = [0.01, 0.02]\n',
    )
    assert main(["batch", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "2 runs, more than the limit of 1" in capsys.readouterr().err
    assert main(["batch", str(path), "--out", str(tmp_path / "out"), "--quiet", "--allow-large"]) == 0


@pytest.mark.parametrize("solver", ["housner", "reference"])
def test_every_result_carries_its_motion_coverage(solver):
    from rockyade.solvers import make_solver

    scene = scene_from_dict(
        {**load_scene(EXAMPLES / "specimen1_record.toml").to_dict(), "duration_s": 1.0, "sample_dt_s": 0.01}
    )
    result = make_solver(solver).run(scene)
    coverage = result.meta.motion_coverage
    assert coverage["status"] == "cut" and coverage["time_left_out_s"] == pytest.approx(4.0)
    assert coverage["message"].startswith("the scene ends at 1 s")
    free = make_solver(solver).run(load_scene(EXAMPLES / "specimen3_free.toml"))
    assert free.meta.motion_coverage["status"] == "no base motion"


def test_a_grid_over_the_motion_gives_the_scenes_read_whole(tmp_path):
    """A grid that changes only the motion reads only the motion of each point: the same
    scenes (and hashes) as reading each point whole, and the same error for a bad point."""
    import copy
    import itertools

    from rockyade.scene import load_scene, scene_from_dict

    base = load_scene("examples/specimen2_record21.toml").to_dict()
    grid = {"motion.record": [3, 21], "motion.load_factor": [0.4, 1.3]}
    tasks = expand([("s2", base)], grid, ["housner"])
    for task, (record, lf) in zip(tasks, itertools.product(*grid.values()), strict=True):
        d = copy.deepcopy(base)
        d["motion"].update(record=record, load_factor=lf)
        whole = scene_from_dict(d)
        assert task.scene == whole and task.scene_hash == whole.scene_hash
    with pytest.raises(InputError) as bad:
        expand([("s2", base)], {"motion.load_factor": [0.4, -1.0]}, ["housner"])
    assert bad.value.field == "motion.load_factor" and "motion.load_factor = -1.0" in bad.value.message
    free = load_scene("examples/specimen1_free.toml").to_dict()
    tilts = expand([("s1", free)], {"motion.theta0_rad": [0.05, 0.1]}, ["housner"])
    assert [t.scene.motion.initial_theta_rad for t in tilts] == [0.05, 0.1]
    with pytest.raises(InputError, match="no block named 'nope'"):  # checked with the blocks, as read whole
        expand([("s1", free)], {"motion.block": ["nope"]}, ["housner"])
