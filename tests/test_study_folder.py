"""One output folder for every study (rockyade.runner.study_folder.StudyFolder): a study never
writes into another command's results (issue 34 section 5, "Lost"), never through a link, a
resume refused for changed options names them, a run record edited by hand is not trusted, and
a bad count or a negative level is refused naming its option."""

from __future__ import annotations

import argparse
import json
import math
import shutil
from pathlib import Path

import pytest

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.runner.journal import DAMAGED, Journal, find_run, write_run
from rockyade.runner.study_folder import (
    ASSESS,
    BATCH,
    CROSSCHECK,
    FRAGILITY,
    UNCERTAINTY,
    StudyFolder,
    StudySet,
    check_out,
    holders,
)
from rockyade.scene.generators import rest_motion, stack, write_scene

from .conftest import EXAMPLES


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    """A wall scene and a folder of two records in ``tmp_path``."""
    write_scene(
        tmp_path / "wall.toml",
        stack(widths_m=[0.25], heights_m=1.0, thickness_m=1.0, layout="column", motion=rest_motion()),
    )
    records = tmp_path / "records"
    records.mkdir()
    for name in ("ricker_pulse_T0.5s.AT2", "ec8_type2_D_record21.AT2"):
        shutil.copy(EXAMPLES / "records" / name, records / name)
    return tmp_path


def _argv(command: str, base: Path, out: Path) -> list[str]:
    """A valid ``rockyade <command>`` writing ``out`` (it is refused before any run)."""
    wall, records = str(base / "wall.toml"), str(base / "records")
    return {
        "fragility": ["fragility", wall, "--records", records, "--levels", "0.2,0.5", "--quiet"],
        "assess": [
            "assess",
            wall,
            "--spectrum-type",
            "1",
            "--ground",
            "B",
            "--ag",
            "0.25g",
            "--records",
            records,
            "--quiet",
        ],
        "crosscheck": ["crosscheck", str(EXAMPLES / "specimen1_record.toml"), "--records", records, "--quiet"],
        "uncertainty": ["uncertainty", str(EXAMPLES / "studies" / "uncertainty_specimen1.toml"), "--quiet"],
        "batch": ["batch", str(EXAMPLES / "studies" / "harmonic_sweep.toml"), "--quiet"],
    }[command] + ["--out", str(out)]


def _complete_set(out: Path, kind: StudySet) -> dict[str, bytes]:
    """A complete set of ``kind`` in ``out`` (its files, the last one marking it; a batch-shaped
    study's ``study.json`` naming its command); the folder's bytes."""
    out.mkdir(parents=True, exist_ok=True)
    for name in kind.names:
        (out / name).write_text(f"{kind.command} {name}\n")
    if kind.keeps_runs:
        (out / "runs").mkdir(exist_ok=True)
        (out / "runs" / "abc_housner.json").write_text("{}\n")
        (out / "study.json").write_text(json.dumps({"command": kind.command}) + "\n")
        if kind is UNCERTAINTY:
            for name in BATCH.names:
                (out / name).write_text(f"batch {name}\n")
    return _bytes(out)


def _bytes(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


#: (command run, the command whose results hold --out, extra options): issue 34, "Lost (8)".
CLASHES = [
    ("fragility", CROSSCHECK, ()),
    ("fragility", CROSSCHECK, ("--resume",)),
    ("fragility", ASSESS, ()),
    ("fragility", BATCH, ("--resume",)),
    ("assess", FRAGILITY, ()),
    ("crosscheck", FRAGILITY, ()),
    ("uncertainty", CROSSCHECK, ()),
    ("uncertainty", FRAGILITY, ()),
    ("batch", UNCERTAINTY, ()),
    ("batch", FRAGILITY, ()),
]


@pytest.mark.parametrize(("command", "holder", "extra"), CLASHES, ids=lambda v: getattr(v, "command", str(v)))
def test_a_study_refuses_an_out_holding_another_commands_results(command, holder, extra, inputs, capsys):
    """Exit 2, one line naming --out and the command whose results are there; not one byte of
    them changed (fragility used to replace a crosscheck's runs.csv beside its crosscheck.json)."""
    out = inputs / "out"
    before = _complete_set(out, holder)
    code = main([*_argv(command, inputs, out), *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "--out" in err and f"'rockyade {holder.command}'" in err and len(err.strip().splitlines()) == 1
    assert _bytes(out) == before


@pytest.mark.parametrize("command", ["fragility", "assess", "crosscheck"])
def test_an_unfinished_study_of_another_command_is_refused_too(command, inputs, capsys):
    """A journal another command left (``partial/study.json`` names it) is its results as well."""
    out = inputs / "out"
    other = "crosscheck" if command != "crosscheck" else "fragility"
    Journal(out / "partial", {"command": other, "options": {}}, resume=False).record(
        "h_housner", {"status": "completed", "scene_hash": "h", "summary": {"run": 0}}
    )
    before = _bytes(out)
    assert main(_argv(command, inputs, out)) == 2
    assert f"'rockyade {other}'" in capsys.readouterr().err and _bytes(out) == before


def test_the_python_api_refuses_too_and_its_own_results_are_welcome(tmp_path):
    """run_study_tasks (a batch from Python) over a fragility set: refused naming it; the
    holders of each set are told apart (an uncertainty study's folder has a batch summary too)."""
    from rockyade.batch import expand, run_study_tasks
    from rockyade.scene import load_scene

    out = tmp_path / "out"
    before = _complete_set(out, FRAGILITY)
    base = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    with pytest.raises(InputError, match="'rockyade fragility'"):
        run_study_tasks(expand([("s", base)], {}, ["housner"]), out, workers=1, progress=False)
    assert _bytes(out) == before
    for kind in (BATCH, FRAGILITY, ASSESS, CROSSCHECK, UNCERTAINTY):
        _complete_set(tmp_path / kind.command, kind)
        assert [command for command, _why in holders(tmp_path / kind.command)] == [kind.command]


@pytest.mark.parametrize("command", ["fragility", "assess", "crosscheck", "uncertainty", "batch"])
def test_every_study_refuses_an_out_holding_files_that_are_not_its_set(command, inputs, capsys):
    """A comparison's loose files (no study's mark) are not a set to replace: exit 2 naming --out
    and a file, before any run, and the folder as it was (batch, uncertainty and crosscheck used
    to write their sets beside them)."""
    out = inputs / "out"
    out.mkdir()
    (out / "wall_compare.csv").write_text("block,solver\n")
    (out / "wall_compare.png").write_bytes(b"png")
    before = _bytes(out)
    code = main(_argv(command, inputs, out))
    err = capsys.readouterr().err
    assert code == 2, err
    assert "--out" in err and "wall_compare.csv" in err and len(err.strip().splitlines()) == 1
    assert _bytes(out) == before


@pytest.mark.parametrize("kind", [BATCH, FRAGILITY, ASSESS, CROSSCHECK, UNCERTAINTY], ids=lambda k: k.command)
def test_a_folder_holding_its_own_complete_set_is_welcome(kind, tmp_path):
    """Its own set (and, for a study that keeps its runs, their batch summary and runs) is no
    stranger's file: a second run replaces it (an uncertainty study's summary.csv was taken
    for one, and 'make bench-all' refused to run it again over its own folder)."""
    out = tmp_path / "out"
    _complete_set(out, kind)
    check_out(out, kind)  # raises on anything it would refuse
    with StudyFolder(out, kind, {"command": kind.command, "options": {}}):
        pass


def test_the_python_api_refuses_loose_files_once_it_holds_the_folder(tmp_path):
    """run_study_tasks checks the folder's files under its lock: the same refusal from Python."""
    from rockyade.batch import expand, run_study_tasks
    from rockyade.scene import load_scene

    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    base = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    with pytest.raises(InputError, match=r"notes\.txt") as info:
        run_study_tasks(expand([("s", base)], {}, ["housner"]), out, workers=1, progress=False)
    assert info.value.field == "out"
    assert _bytes(out) == {"notes.txt": b"mine\n"}


@pytest.mark.parametrize("command", ["fragility", "assess", "crosscheck", "uncertainty", "batch"])
@pytest.mark.parametrize("dangling", [False, True], ids=["link", "dangling link"])
def test_every_study_refuses_an_out_that_is_a_link(command, dangling, inputs, capsys):
    """One rule for all (batch used to write through a link crosscheck refused; a dangling link
    gave "File exists"): exit 2 naming --out, nothing made where the link points."""
    target = inputs / "elsewhere"
    if not dangling:
        target.mkdir()
    link = inputs / "out"
    link.symlink_to(target)
    code = main(_argv(command, inputs, link))
    err = capsys.readouterr().err
    assert code == 2 and "--out" in err and "symbolic link" in err and len(err.strip().splitlines()) == 1
    assert (not target.exists()) if dangling else not list(target.iterdir())


def test_a_refused_resume_names_the_options_that_changed():
    """Not the two option dictionaries: '--tail: 5.0 then, 20.0 now'."""
    from rockyade.runner.journal import default_option_name, differences

    then = {"command": "fragility", "scene_hash": "a", "options": {"tail": 5.0, "levels": "0.2,0.5", "quiet": False}}
    now = {"command": "fragility", "scene_hash": "a", "options": {"tail": 20.0, "levels": "0.2,0.5", "quiet": False}}
    said = differences(then, now, default_option_name)
    assert said == "--tail: 5.0 then, 20.0 now"
    assert "{" not in differences(then, {**now, "scene_hash": "b"}, default_option_name)


def test_the_same_files_by_a_relative_or_an_absolute_path_are_the_same_study(tmp_path, monkeypatch):
    from rockyade.cli.resumable import identity

    monkeypatch.chdir(tmp_path)
    (tmp_path / "records").mkdir()
    relative = argparse.Namespace(records=Path("records"), tail=5.0, out=Path("a"))
    absolute = argparse.Namespace(records=tmp_path / "records", tail=5.0, out=tmp_path / "b")
    assert identity("fragility", relative, "h") == identity("fragility", absolute, "h")


def test_a_fragility_resume_with_another_tail_is_refused_naming_it(inputs, capsys):
    out = inputs / "out"
    argv = _argv("fragility", inputs, out)
    Journal(out / "partial", _identity_of([*argv, "--tail", "5"]), resume=False)
    assert main([*argv, "--tail", "20", "--resume"]) == 2
    err = capsys.readouterr().err
    assert "--resume" in err and "--tail: 5.0 then, 20.0 now" in err and "'options'" not in err


def _identity_of(argv: list[str]) -> dict[str, object]:
    from rockyade.cli import build_parser
    from rockyade.cli.resumable import file_digest, identity

    args = build_parser().parse_args(argv)
    return identity("fragility", args, file_digest(args.scene))


def test_a_run_record_edited_into_valid_json_is_not_trusted(tmp_path, capsys):
    """``batch --resume`` after a record's row was edited (a peak of 1e300 and a new key, still
    valid JSON): the run is made again, the summary has its real peak and no new column, and the
    batch says which record was not as written."""
    from rockyade.batch import expand, run_study_tasks
    from rockyade.scene import load_scene

    base = load_scene(EXAMPLES / "specimen1_free.toml").to_dict()
    base["duration_s"] = 1.0
    tasks = expand([("s", base)], {"motion.theta0_rad": [0.05, 0.1]}, ["housner"], save_history=False)
    first = run_study_tasks(tasks, tmp_path, workers=1, progress=False)
    record = tmp_path / "runs" / f"{first.run[0]}.json"
    data = json.loads(record.read_text())
    data["summary"]["max_abs_theta_rad"] = 1e300
    data["summary"]["planted"] = 1
    record.write_text(json.dumps(data))
    assert find_run(tmp_path / "runs", first.run[0], first.scene_hash[0]) == DAMAGED
    capsys.readouterr()
    again = run_study_tasks(tasks, tmp_path, workers=1, progress=False, resume=True)
    assert again.max_abs_theta_rad[0] == pytest.approx(first.max_abs_theta_rad[0]) and "planted" not in again
    err = capsys.readouterr().err
    assert "not as they were written" in err and first.run[0] in err
    assert json.loads(record.read_text())["summary"].get("planted") is None  # written again


def test_records_are_sealed_and_read_back_as_written(tmp_path):
    write_run(tmp_path, "a_b", {"status": "completed", "scene_hash": "a", "summary": {"x": math.nan, "n": 2}})
    found = find_run(tmp_path, "a_b", "a")
    assert not isinstance(found, str) and found is not None
    assert math.isnan(found.summary["x"]) and found.summary["n"] == 2
    data = json.loads((tmp_path / "a_b.json").read_text())
    data["status"] = "overturned"
    (tmp_path / "a_b.json").write_text(json.dumps(data))
    assert find_run(tmp_path, "a_b", "a") == DAMAGED


def test_resume_with_nothing_to_resume_is_refused_and_a_failed_run_keeps_the_journal(tmp_path):
    kind = StudySet("x", ("x.csv", "x.json"), "x.json")
    out = tmp_path / "out"
    with StudyFolder(out, kind, {"options": {}}, False) as folder:
        folder.journal.record("h_s", {"status": "failed", "scene_hash": "h", "summary": {"run": 0}})
        with folder.replacing() as stage:
            (stage / "x.json").write_text("{}")
        folder.finish(failed=1)
    assert (out / "partial" / "h_s.json").is_file()  # --resume runs the failed run again
    with StudyFolder(out, kind, {"options": {}}, True) as folder:
        folder.finish()
    assert not (out / "partial").exists()
    with pytest.raises(InputError, match="nothing to resume") as info, StudyFolder(out, kind, {"options": {}}, True):
        pass
    assert info.value.field == "--resume"


@pytest.mark.parametrize(
    ("argv", "option", "words"),
    [
        (["fragility", "{wall}", "--suite", "paper", "--count", "0"], "--count", "[1, 30]"),
        (["fragility", "{wall}", "--records", "{records}", "--levels", "-0.3,0.6"], "--levels", "> 0"),
        (
            ["crosscheck", "{wall}", "--suite", "ec8", "--spectrum-type", "1", "--ground", "B", "--ag", "-0.25g"],
            "--ag",
            "(0, ",
        ),
        (
            [
                "assess",
                "{wall}",
                "--spectrum-type",
                "1",
                "--ground",
                "B",
                "--ag",
                "-0.25g",
                "--static-only",
                "--knowledge-level",
                "LC1",
            ],
            "--ag",
            "(0, ",
        ),
    ],
)
def test_a_bad_count_or_a_negative_value_is_refused_naming_its_option(argv, option, words, inputs, capsys):
    """``--count 0`` was taken as the whole suite; ``-0.3,0.6`` and ``-0.25g`` got argparse's
    "expected one argument" instead of the option's own range."""
    filled = [a.format(wall=inputs / "wall.toml", records=inputs / "records") for a in argv]
    if argv[0] != "assess":
        filled += ["--out", str(inputs / "out")]
    code = main(filled)
    err = capsys.readouterr().err
    assert code == 2 and option in err and words in err and "expected one argument" not in err, err
    assert not (inputs / "out").exists()


def test_a_ctrl_c_between_two_rounds_of_stripes_stops_the_fragility(inputs, monkeypatch):
    """The stripes extended round by round share one stop request: a Ctrl-C as the first round's
    last run ends (delivered as the signal handler does) starts no second round; the analysis
    stops with the rows of the first (their partial summary is the command's to write)."""
    import signal

    import rockyade.assess.fragility_analysis as fa
    from rockyade.assess import fragility_plan, parse_measure, records_in_folder
    from rockyade.assess.stripes import StripesInterruptedError
    from rockyade.runner import Executor
    from rockyade.scene import load_scene

    plan = fragility_plan(
        load_scene(inputs / "wall.toml"),
        records_in_folder(inputs / "records"),
        parse_measure("pga"),
        "housner",
        levels=[0.05, 0.1],  # nothing moves: the levels are extended upwards
        extend=True,
        executor=Executor("threads", 1),
        progress=False,
    )
    real = fa.run_stripes
    rounds: list[int] = []

    def ctrl_c_at_the_end(*args, **kwargs):
        rows = real(*args, **kwargs)
        rounds.append(len(rows))
        kwargs["stop"]._handler(signal.SIGINT, None)
        return rows

    monkeypatch.setattr(fa, "run_stripes", ctrl_c_at_the_end)
    with pytest.raises(StripesInterruptedError) as info:
        fa.run_fragility(plan, Executor("threads", 1), progress=False)
    assert rounds == [4] and len(info.value.rows) == 4 and info.value.plan is plan


def test_an_uncertainty_study_runs_again_into_the_folder_it_wrote(tmp_path):
    """Its folder holds the batch summary of its runs beside its set: 'rockyade uncertainty' run
    again into its own --out was refused for summary.csv and summary.parquet, the files it wrote."""
    out = tmp_path / "uncertainty"
    _complete_set(out, UNCERTAINTY)
    check_out(out, UNCERTAINTY)
    (out / "notes.txt").write_text("mine\n")
    with pytest.raises(InputError, match=r"notes\.txt"):
        check_out(out, UNCERTAINTY)
