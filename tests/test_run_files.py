"""A worker run's files (rockyade.io.run_files), the one way every engine keeps them: where a
run works, what a failed or successful run keeps, and the private folders a killed process
left (issue 34: a failed run's old Siconos files stayed beside its successful rerun; after
kill -9 of the parent, $TMPDIR/rockyade-siconos-* stayed for good)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rockyade.io import run_files


def _output(path: Path, complete: bool, status: str = "completed") -> None:
    with open(path, "wb") as fh:
        np.savez(fh, pos=np.zeros((1, 1, 2)), meta=json.dumps({"status": status, "complete": complete}))


def _ended(files: run_files.RunFiles, complete: bool | None, log: str = "log") -> None:
    """What a run leaves at its end: its scene data, its log, and an output when ``complete`` is not None."""
    files.working(".json").write_text("{}")
    files.working(".log").write_text(log)
    if complete is not None:
        _output(files.working(".npz"), complete)


@pytest.fixture
def scratch(tmp_path, monkeypatch) -> Path:
    """A temporary folder of its own for the private folders (TMPDIR)."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    monkeypatch.setattr("tempfile.tempdir", str(folder))
    return folder


def _dead_pid() -> int:
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(done.stdout)


def test_a_private_run_is_removed_when_it_succeeds_and_kept_in_place_when_it_fails(scratch):
    ok = run_files.start("engine", "a", ".engine", None)
    assert ok.private and ok.folder.parent == scratch.resolve() and f"-{os.getpid()}-" in ok.folder.name
    _ended(ok, complete=True)
    assert ok.keep(True, None, None) is None and not ok.folder.exists()

    failed = run_files.start("engine", "a", ".engine", None)
    _ended(failed, complete=False)
    log = failed.keep(False, None, None)
    assert log == failed.folder / "a.engine.log" and log.read_text() == "log"
    assert sorted(p.name for p in failed.folder.iterdir()) == ["a.engine.json", "a.engine.log", "a.engine.npz"]


def test_a_successful_rerun_removes_the_failed_runs_files_it_replaces(scratch, tmp_path):
    """failed_dir keeps a failed run's files; the same run succeeding later keeps none and
    removes those (they were the files of the result it replaces)."""
    out = tmp_path / "out"
    failed = run_files.start("engine", "x", ".engine", None)
    _ended(failed, complete=False)
    assert failed.keep(False, None, out) == out.resolve() / "x.engine.log"
    assert sorted(p.name for p in out.iterdir()) == ["x.engine.json", "x.engine.log", "x.engine.npz"]
    assert not failed.folder.exists()

    rerun = run_files.start("engine", "x", ".engine", None)
    _ended(rerun, complete=True)
    assert rerun.keep(True, None, out) is None
    assert not list(out.iterdir()) and not list(scratch.iterdir())


def test_a_failed_run_goes_beside_a_complete_runs_files_and_replaces_a_failed_ones(tmp_path):
    work = tmp_path / "work"
    first = run_files.start("engine", "x", ".engine", work)
    assert not first.private and first.working(".npz").name == "x.running.engine.npz"
    _ended(first, complete=True, log="complete")
    assert first.keep(True, work, None) == work.resolve() / "x.engine.log"

    timeout = run_files.start("engine", "x", ".engine", work)
    _ended(timeout, complete=False, log="timeout")
    assert timeout.keep(False, work, None).name == "x_failed.engine.log"
    assert (work / "x.engine.log").read_text() == "complete"  # untouched

    again = run_files.start("engine", "y", ".engine", work)
    _ended(again, complete=False, log="first failure")
    again.keep(False, work, None)
    retry = run_files.start("engine", "y", ".engine", work)
    _ended(retry, complete=None, log="second failure")  # no output this time
    assert retry.keep(False, work, None).name == "y.engine.log"  # a failed run's files are replaced
    assert (work / "y.engine.log").read_text() == "second failure" and not (work / "y.engine.npz").exists()
    assert not list(work.glob("*.running.*"))


def test_an_interrupted_run_leaves_none_of_its_files(scratch, tmp_path):
    private = run_files.start("engine", "a", ".engine", None)
    _ended(private, complete=False)
    private.discard()
    assert not private.folder.exists()
    work = tmp_path / "work"
    kept = run_files.start("engine", "a", ".engine", work)
    _ended(kept, complete=True)
    kept.keep(True, work, None)
    own = run_files.start("engine", "a", ".engine", work)
    _ended(own, complete=False)
    own.discard()
    assert sorted(p.name for p in work.iterdir()) == ["a.engine.json", "a.engine.log", "a.engine.npz"]


def test_the_private_folders_of_dead_processes_are_removed_and_no_other(scratch):
    dead = _dead_pid()
    stale = scratch / f"rockyade-engine-{dead}-abc"
    stale.mkdir()
    (stale / "k.running.engine.json").write_text("{}")
    (stale / "k.running.engine.npz.part").write_text("")
    empty = scratch / f"rockyade-engine-{dead}-def"
    empty.mkdir()
    kept = scratch / f"rockyade-engine-{dead}-ghi"  # a failed run's files, its log named in a Result
    kept.mkdir()
    (kept / "k.engine.log").write_text("why it failed")
    alive = scratch / f"rockyade-engine-{os.getpid()}-jkl"
    alive.mkdir()
    (alive / "k.running.engine.json").write_text("{}")
    other = scratch / f"rockyade-other-{dead}-mno"
    other.mkdir()
    target = scratch / "target"
    target.mkdir()
    (target / "k.running.engine.json").write_text("{}")
    (scratch / f"rockyade-engine-{dead}-lnk").symlink_to(target)
    assert sorted(run_files.remove_stale_folders("engine")) == sorted([stale, empty])
    assert kept.is_dir() and alive.is_dir() and other.is_dir() and (target / "k.running.engine.json").is_file()


def test_a_processs_first_private_run_sweeps_the_stale_folders(scratch, monkeypatch):
    dead = _dead_pid()
    stale = scratch / f"rockyade-engine-{dead}-abc"
    stale.mkdir()
    (stale / "k.running.engine.log").write_text("")
    monkeypatch.setattr(run_files, "_SWEPT", set())
    files = run_files.start("engine", "a", ".engine", None)
    assert not stale.exists() and files.folder.is_dir()
