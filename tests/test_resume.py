"""Studies that resume and never mix results (issue 26 item 2): the journal of finished runs
(:mod:`rockyade.runner.journal`), a result set replaced as a whole (:mod:`rockyade.io.resultset`),
``fragility`` and ``assess`` stopped by Ctrl-C or kill -9 and resumed without repeating a run."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.io.resultset import COMMIT_DIR, replacing_set, settle
from rockyade.runner.journal import Journal, read_run, write_run
from rockyade.scene.generators import rest_motion, stack, write_scene

from .conftest import EXAMPLES
from .processes import sigint_default

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def wall(tmp_path):
    """A free-standing wall 1 m high and 0.25 m thick (one block, a 1 m strip)."""
    path = tmp_path / "wall.toml"
    write_scene(path, stack(widths_m=[0.25], heights_m=1.0, thickness_m=1.0, layout="column", motion=rest_motion()))
    return path


@pytest.fixture
def records(tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    for name in ("ricker_pulse_T0.5s.AT2", "ec8_type2_D_record21.AT2"):
        shutil.copy(EXAMPLES / "records" / name, folder / name)
    return folder


# ---------------------------------------------------------------------- the journal


def test_a_journal_keeps_completed_runs_and_runs_failed_ones_again(tmp_path):
    j = Journal(tmp_path / "j", {"command": "x", "options": {"a": 1}}, resume=False)
    j.record("h1_housner", {"status": "completed", "scene_hash": "h1", "summary": {"run": 0, "v": 1.5}})
    j.record("h2_housner", {"status": "failed", "scene_hash": "h2", "summary": {"run": 1}})
    again = Journal(tmp_path / "j", {"command": "x", "options": {"a": 1}}, resume=True)
    assert again.done("h1_housner", "h1") == {"run": 0, "v": 1.5}
    assert again.done("h2_housner", "h2") is None  # failed: run again
    assert again.done("h1_housner", "other") is None  # another scene under the name
    assert again.resumed == 1
    # without --resume an earlier journal is cleared
    Journal(tmp_path / "j", {"command": "x", "options": {"a": 1}}, resume=False)
    assert read_run(tmp_path / "j", "h1_housner", "h1") is None


def test_a_journal_refuses_to_resume_another_study(tmp_path):
    Journal(tmp_path / "j", {"command": "fragility", "options": {"levels": "0.2,0.5"}}, resume=False)
    with pytest.raises(InputError) as info:
        Journal(tmp_path / "j", {"command": "fragility", "options": {"levels": "0.3,0.5"}}, resume=True)
    assert info.value.field == "--resume" and "levels" in info.value.message
    with pytest.raises(InputError, match="written by 'fragility', not 'assess'"):
        Journal(tmp_path / "j", {"command": "assess", "options": {}}, resume=True)


def test_a_run_record_is_whole_and_durable(tmp_path, monkeypatch):
    """Each record is written atomically and fsynced (not an os.sync of the machine)."""
    synced = []
    real = os.fsync
    monkeypatch.setattr(os, "fsync", lambda fd: (synced.append(fd), real(fd))[1])
    monkeypatch.setattr(os, "sync", lambda: pytest.fail("os.sync() syncs the whole machine"))
    write_run(tmp_path, "a_b", {"status": "completed", "scene_hash": "a", "summary": {}})
    assert len(synced) >= 2  # the file and its folder
    assert [p.name for p in tmp_path.iterdir()] == ["a_b.json"]


# ---------------------------------------------------------------------- result sets


def _old_set(folder: Path) -> dict[str, bytes]:
    folder.mkdir(exist_ok=True)
    for name, text in (("runs.csv", "old runs"), ("fig.png", "old figure"), ("set.json", "old json")):
        (folder / name).write_text(text)
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def _contents(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir()}


def test_a_set_that_fails_while_written_leaves_the_old_set_whole(tmp_path):
    before = _old_set(tmp_path / "out")
    with (
        pytest.raises(OSError, match=r"fig\.png"),
        replacing_set(tmp_path / "out", ("runs.csv", "fig.png", "set.json"), "set.json") as stage,
    ):
        (stage / "runs.csv").write_text("new runs")
        raise OSError(28, "No space left on device", str(tmp_path / "out" / "fig.png"))
    assert _contents(tmp_path / "out") == before  # nothing staged is left either


def test_a_set_is_replaced_as_a_whole_and_a_file_the_new_set_lacks_goes(tmp_path):
    _old_set(tmp_path / "out")
    with replacing_set(tmp_path / "out", ("runs.csv", "fig.png", "set.json"), "set.json") as stage:
        (stage / "runs.csv").write_text("new runs")
        (stage / "set.json").write_text("new json")
    assert _contents(tmp_path / "out") == {"runs.csv": b"new runs", "set.json": b"new json"}


@pytest.mark.parametrize("moved", [0, 1, 2])
def test_a_swap_killed_half_way_is_finished_by_the_next_writer(tmp_path, moved):
    """A commit folder left by a kill after ``moved`` steps of the swap: the folder never
    holds the old set's JSON beside a new file, and settling gives the new set whole."""
    out = tmp_path / "out"
    _old_set(out)
    commit = out / COMMIT_DIR
    commit.mkdir()
    (commit / "runs.csv").write_text("new runs")
    (commit / "set.json").write_text("new json")
    (commit / ".names").write_text("runs.csv\nset.json\n")
    if moved >= 1:
        (out / "set.json").unlink()  # step 2: the old set is no longer complete
    if moved >= 2:
        os.replace(commit / "runs.csv", out / "runs.csv")
    settle(out, ("runs.csv", "fig.png", "set.json"), "set.json")
    assert _contents(out) == {"runs.csv": b"new runs", "set.json": b"new json"}


# ---------------------------------------------------------------------- commands


#: The fragility's load levels (x 2 records: the runs of a study); runs of under a second each.
LEVELS = 10


def _fragility(folder: Path, *extra: str, levels_count: int = LEVELS) -> list[str]:
    levels = ",".join(f"{0.3 + 0.1 * i:.2f}" for i in range(levels_count))
    return [
        sys.executable,
        "-m",
        "rockyade",
        "fragility",
        "wall.toml",
        "--records",
        "records",
        "--levels",
        levels,
        "--no-extend",
        "--solver",
        "reference",
        "--tail",
        "20",
        "--workers",
        "1",
        "--out",
        "frag",
        "--quiet",
        *extra,
    ]


def _records_in(partial: Path) -> set[str]:
    """The runs' records in a journal (not its identity, nor the partial summary)."""
    skip = {"study.json", "partial.json", "assess.json"}
    return {p.name for p in partial.glob("*.json") if p.name not in skip} if partial.is_dir() else set()


def _start(folder: Path, argv: list[str]) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen(
        argv,
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        env=env,
        preexec_fn=sigint_default,
    )


def _wait_for_records(proc: subprocess.Popen[str], partial: Path, n: int) -> None:
    end = time.monotonic() + 600
    while len(_records_in(partial)) < n:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "no run finished in 10 min"
        time.sleep(0.02)


@pytest.mark.parametrize("how", ["ctrl-c", "kill-9"])
@pytest.mark.slow
def test_fragility_stopped_then_resumed_repeats_no_run(tmp_path, wall, records, how, monkeypatch, capsys):
    """Ctrl-C (a partial summary marked partial) or kill -9 in the middle of a fragility,
    then ``--resume``: every run finished before the stop is read back, none is run twice,
    and the result is the whole set (20 runs, each once). The stop hits a real process; the
    resume runs in this one (the same ``main``; a second process would only add its start-up)."""
    proc = _start(tmp_path, _fragility(tmp_path))
    partial = tmp_path / "frag" / "partial"
    _wait_for_records(proc, partial, 2)
    if how == "ctrl-c":
        os.killpg(proc.pid, signal.SIGINT)
        _out, err = proc.communicate(timeout=600)
        assert proc.returncode == 130, err
        assert "run the same command with --resume" in err and "partial/runs.csv" in err
        summary = json.loads((partial / "partial.json").read_text())
        assert summary["partial"] is True and summary["unfinished"] > 0
        assert len(pd.read_csv(partial / "runs.csv")) == summary["finished"]
    else:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate(timeout=600)
    assert not (tmp_path / "frag" / "fragility.json").exists()  # nothing that looks complete
    kept = _records_in(partial)
    assert 2 <= len(kept) < 2 * LEVELS
    capsys.readouterr()
    monkeypatch.chdir(tmp_path)
    code = main(_fragility(tmp_path, "--resume")[3:])  # without `python -m rockyade`
    done = capsys.readouterr()
    assert code == 0, done.err
    assert f"resumed: {len(kept)} run(s) read back" in done.out  # runs repeated: 0
    runs = pd.read_csv(tmp_path / "frag" / "runs.csv")
    assert sorted(runs["run"]) == list(range(2 * LEVELS)) and runs["scene_hash"].is_unique
    assert not partial.exists() and (tmp_path / "frag" / "fragility.json").is_file()


def test_resume_of_another_studys_folder_is_refused(tmp_path, wall, records, capsys):
    out = tmp_path / "frag"
    Journal(out / "partial", {"command": "assess", "scene_hash": "x", "options": {}}, resume=False)
    code = main(
        [
            "fragility",
            str(wall),
            "--records",
            str(records),
            "--levels",
            "0.2,0.5",
            "--out",
            str(out),
            "--quiet",
            "--resume",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and "--resume" in err and "written by 'assess', not 'fragility'" in err
    assert len(err.strip().splitlines()) == 1


def test_an_error_after_the_checks_leaves_no_empty_out_folder(tmp_path, wall, records, capsys):
    """A level no record reaches within the largest load factor: refused before --out is made."""
    out = tmp_path / "frag"
    code = main(
        ["fragility", str(wall), "--records", str(records), "--levels", "0.2,500", "--out", str(out), "--quiet"]
    )
    assert code == 2 and "--levels" in capsys.readouterr().err
    assert not out.exists()


def test_an_interrupt_before_any_run_leaves_no_empty_out_folder(tmp_path):
    from rockyade.runner.study_folder import StudyFolder, StudySet

    def study_output(out, ident, resume, names, last):
        return StudyFolder(out, StudySet(ident["command"], names, last), ident, resume)

    out = tmp_path / "new"
    with pytest.raises(KeyboardInterrupt), study_output(out, {"command": "x"}, False, ("a.json",), "a.json"):
        raise KeyboardInterrupt
    assert not out.exists()
    kept = tmp_path / "kept"
    kept.mkdir()
    with pytest.raises(KeyboardInterrupt), study_output(kept, {"command": "x"}, False, ("a.json",), "a.json"):
        raise KeyboardInterrupt
    assert kept.is_dir() and not list(kept.iterdir())  # a folder the user made stays, empty as it was


def test_fragility_takes_the_executor_options_of_batch(tmp_path, wall, records, capsys):
    pytest.importorskip("dask")
    out = tmp_path / "frag"
    code = main(
        [
            "fragility",
            str(wall),
            "--records",
            str(records),
            "--levels",
            "0.2,1",
            "--out",
            str(out),
            "--quiet",
            "--executor",
            "dask",
            "--workers",
            "2",
        ]
    )
    assert code == 0, capsys.readouterr()
    assert len(pd.read_csv(out / "runs.csv")) == 4
    code = main(
        [
            "fragility",
            str(wall),
            "--records",
            str(records),
            "--levels",
            "0.2,1",
            "--out",
            str(out),
            "--quiet",
            "--scheduler",
            "tcp://127.0.0.1:9",
        ]
    )
    assert code == 2 and "--scheduler: needs --executor dask" in capsys.readouterr().err


def _namespace_or_skip() -> None:
    probe = subprocess.run(["unshare", "-Urm", "true"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("cannot mount a tmpfs here (no user namespaces)")


@pytest.mark.slow
def test_a_full_disk_leaves_the_previous_set_whole_and_names_the_file(tmp_path, wall, records, monkeypatch):
    """A real full disk (a small tmpfs): a complete fragility set, the disk filled but for
    room for the new runs' records and tables, a new fragility over it (a real process): it
    fails naming the file it could not write, and the previous set is there byte for byte (it
    used to leave the new runs.csv, stripes.csv and fragility.json beside the old
    fragility.png). The previous set is written in this process and copied onto the disk."""
    _namespace_or_skip()
    disk = tmp_path / "disk"
    disk.mkdir()
    monkeypatch.chdir(tmp_path)
    first = ["fragility", "wall.toml", "--records", "records", "--out", "frag", "--quiet", "--levels", "0.2,0.5,1,2"]
    assert main(first) == 0
    py = f"PYTHONPATH={ROOT} {sys.executable} -m rockyade fragility wall.toml --records records --out frag --quiet"
    script = (
        f"mount -t tmpfs -o size=1m tmpfs {disk} && "
        f"cp -r {tmp_path}/records {tmp_path}/wall.toml {tmp_path}/frag {disk}/ && "
        f"cd {disk} && sha256sum frag/*.* && echo FIRST && "
        "(cat /dev/zero > filler 2>/dev/null; true) && truncate -s -64k filler && "
        f"{py} --levels 0.3,0.6,1.2,2.4; echo EXIT $? && sha256sum frag/*.* && ls -A frag && echo FILES"
    )
    proc = subprocess.run(["unshare", "-Urm", "sh", "-c", script], capture_output=True, text=True, timeout=600)
    out = proc.stdout
    assert "FIRST" in out and "FILES" in out, out + proc.stderr
    first, after = out.split("FIRST")
    assert "EXIT 1" in after, out + proc.stderr
    assert "frag/fragility.png: no space left on the device (disk full)" in proc.stderr, proc.stderr
    sums_before = [line for line in first.splitlines() if "frag/" in line]
    sums_after = [line for line in after.split("EXIT 1")[1].splitlines() if "frag/" in line]
    assert len(sums_before) == 5 and sums_after == sums_before
    listing = after.split("EXIT 1")[1].split("FILES")[0]
    assert ".set." not in listing  # nothing staged is left
    assert "partial" in listing  # the finished runs are kept: --resume writes the set once there is room


# ---------------------------------------------------------------------- record folders


def test_linked_records_are_followed_and_counted(tmp_path, records):
    """One real record and two links to record files elsewhere: three records (it used to
    run one, silently); a folder of links only reads as well."""
    from rockyade.assess import records_in_folder

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    shutil.copy(EXAMPLES / "records" / "ec8_type2_D_record21.AT2", elsewhere / "b.AT2")
    half = pd.read_csv(EXAMPLES / "records_csv" / "ec8_type2_D_record21.csv", comment="#")
    half["accel_m_s2"] *= 0.5  # another accelerogram
    half.to_csv(elsewhere / "c.csv", index=False)
    mixed = tmp_path / "mixed"
    mixed.mkdir()
    shutil.copy(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2", mixed / "a.AT2")
    (mixed / "b.AT2").symlink_to(elsewhere / "b.AT2")
    (mixed / "c.csv").symlink_to(elsewhere / "c.csv")
    assert records_in_folder(mixed).count == 3
    links = tmp_path / "links"
    links.mkdir()
    (links / "b.AT2").symlink_to(elsewhere / "b.AT2")
    assert records_in_folder(links).count == 1


def test_a_link_to_no_record_file_is_refused_naming_it(tmp_path):
    from rockyade.assess import records_in_folder

    folder = tmp_path / "recs"
    folder.mkdir()
    shutil.copy(EXAMPLES / "records" / "ricker_pulse_T0.5s.AT2", folder / "a.AT2")
    (folder / "gone.AT2").symlink_to(tmp_path / "nowhere.AT2")
    with pytest.raises(InputError) as info:
        records_in_folder(folder)
    assert info.value.field == "--records" and "gone.AT2" in info.value.message


def test_a_batch_whose_scheduler_does_not_answer_leaves_no_empty_out_folder(tmp_path, capsys):
    pytest.importorskip("distributed")
    study = tmp_path / "study.toml"
    study.write_text(f'name = "s"\nsolvers = ["housner"]\n[base]\nfile = "{EXAMPLES / "specimen1_free.toml"}"\n')
    out = tmp_path / "out"
    code = main(
        [
            "batch",
            str(study),
            "--out",
            str(out),
            "--executor",
            "dask",
            "--scheduler",
            "tcp://127.0.0.1:9",
            "--scheduler-timeout",
            "1",
            "--quiet",
        ]
    )
    assert code == 2 and "no Dask scheduler answered" in capsys.readouterr().err
    assert not out.exists()


# ---------------------------------------------------------------------- Ctrl-C


def test_the_ctrl_c_handler_never_raises(capsys):
    """The handler counts and returns (an exception raised from a signal handler surfaces at an
    arbitrary point of the main thread: the stray 'SystemError: <built-in function isinstance>
    returned a result with an exception set' from random.seed); after the second Ctrl-C of
    in-process runs the next Ctrl-C is Python's own."""
    import threading

    from rockyade.runner.stopping import StopRequest

    assert threading.current_thread() is threading.main_thread()
    before = signal.getsignal(signal.SIGINT)
    with StopRequest(raise_on_second=True) as stop:
        assert signal.getsignal(signal.SIGINT) == stop._handler
        stop._handler(signal.SIGINT, None)
        stop._handler(signal.SIGINT, None)  # used to raise KeyboardInterrupt here
        assert stop.requested and stop.now
        assert signal.getsignal(signal.SIGINT) == before
    assert signal.getsignal(signal.SIGINT) == before
    assert "finishes first" in capsys.readouterr().err


def test_threads_stop_at_a_safe_point_after_the_second_ctrl_c():
    """Runs on threads of this process: after a second Ctrl-C the loop raises KeyboardInterrupt
    at its next wait (not the handler), abandoning the running threads."""
    import threading

    from rockyade.runner.stopping import StopRequest
    from rockyade.runner.threads import Batch, run_threads

    release = threading.Event()
    stop = StopRequest(raise_on_second=True)
    started: set[int] = set()

    def job(i: int) -> int:
        if i == 0:
            stop._handler(signal.SIGINT, None)
            stop._handler(signal.SIGINT, None)
        release.wait(60)
        return i

    with pytest.raises(KeyboardInterrupt):  # while job 0 still runs
        run_threads(Batch([0, 1], job, lambda i, v: None, None, stop, started), 2)
    assert not release.is_set()
    release.set()


@pytest.mark.slow
def test_assess_stopped_keeps_its_static_answer_and_resumes(tmp_path, wall, records, monkeypatch, capsys):
    """Ctrl-C in the dynamics of ``assess --out`` (a real process): the static answer is written
    (marked partial) with the runs that finished, and ``--resume`` (run in this process) runs
    only the others."""
    factors = ",".join(f"{0.5 + 0.1 * i:.1f}" for i in range(15))
    argv = [sys.executable, "-m", "rockyade", "assess", "wall.toml", "--knowledge-level", "LC1", "--spectrum-type", "1",
            "--ground", "B", "--ag", "0.25g", "--records", "records", "--load-factors", factors, "--no-extend",
            "--solver", "reference", "--tail", "20", "--workers", "1", "--out", "a", "--quiet"]  # fmt: skip
    proc = _start(tmp_path, argv)
    partial = tmp_path / "a" / "partial"
    _wait_for_records(proc, partial, 2)
    os.killpg(proc.pid, signal.SIGINT)
    _out, err = proc.communicate(timeout=600)
    assert proc.returncode == 130, err
    static = json.loads((partial / "assess.json").read_text())
    assert static["partial"] is True and static["alpha0"] > 0 and static["verdict"]
    assert "a/partial/runs.csv" in err and not (tmp_path / "a" / "assess.json").exists()
    kept = _records_in(partial)
    capsys.readouterr()
    monkeypatch.chdir(tmp_path)
    code = main([*argv[3:], "--resume"])  # without `python -m rockyade`
    done = capsys.readouterr()
    assert code == 0, done.err
    assert f"resumed: {len(kept)} run(s) read back" in done.out
    assert len(pd.read_csv(tmp_path / "a" / "runs.csv")) == 30 and not partial.exists()


@pytest.mark.parametrize("executor", ["local", "dask"])
@pytest.mark.slow
def test_a_fragility_opens_no_listening_socket(tmp_path, wall, records, executor):
    """The study commands on local processes or Dask's threaded scheduler open no port (polled
    over the process tree while it runs, to the end). Two levels (4 runs): every part of the
    study (its runs on the executor, the fit, the figure) runs as with more."""
    if executor == "dask":
        pytest.importorskip("dask")
    from .test_robust_batch import _listening_sockets_of_tree

    argv = _fragility(tmp_path, "--executor", executor, "--workers", "2", levels_count=2)  # the last --workers
    proc = _start(tmp_path, argv)
    seen: set[str] = set()
    polls = 0
    while proc.poll() is None:
        seen |= _listening_sockets_of_tree(proc.pid)
        polls += 1
        time.sleep(0.02)
    _out, err = proc.communicate()
    assert proc.returncode == 0, err
    assert polls > 10 and not seen


def test_the_interrupt_message_names_an_option_the_command_has():
    """`fragility` and `assess` said 'run the same command with --resume' and had no --resume;
    a study run by `paper` has none either."""
    from rockyade.cli import build_parser
    from rockyade.errors import BatchInterruptedError

    parser = build_parser()
    commands = parser._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    for name in ("batch", "fragility", "assess", "uncertainty"):
        assert "--resume" in commands[name]._option_string_actions, name
    assert "--resume" not in commands["paper"]._option_string_actions
    assert "--resume" in str(BatchInterruptedError(1, 2, None))
    assert "--resume" not in str(BatchInterruptedError(1, 2, None, resume_option=None))
