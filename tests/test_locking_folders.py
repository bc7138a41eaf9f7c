"""A lock covers the folder it is in: nothing writes inside a running batch's output folder
(issue: `run --out` inside a batch's folder was allowed and the batch overwrote its file),
except the batch's own workers."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from rockyade.batch import expand, run_study_tasks
from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.io.locking import DIR_LOCK_NAME, lock_token, output_lock, writing_for
from rockyade.scene import load_scene

from .conftest import EXAMPLES

HOLD = (
    "import sys, time\nfrom rockyade.io.locking import lock_token, output_lock\n"
    "with output_lock(sys.argv[1]):\n    print('held', lock_token(sys.argv[1]), flush=True)\n    time.sleep(120)\n"
)


class Holder:
    """Another process holding the lock of ``path`` (as a running batch holds its folder's)."""

    def __init__(self, path: Path) -> None:
        path.mkdir(parents=True, exist_ok=True)
        self.proc = subprocess.Popen([sys.executable, "-c", HOLD, str(path)], stdout=subprocess.PIPE, text=True)
        assert self.proc.stdout is not None
        word, self.token = self.proc.stdout.readline().split()
        assert word == "held"

    def __enter__(self) -> Holder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.proc.kill()
        self.proc.wait()


def test_a_file_inside_a_locked_folder_is_refused(tmp_path):
    out = tmp_path / "batch"
    with Holder(out) as holder:
        for inside in (out / "r.csv", out / "runs" / "x.csv", out / "deep" / "er" / "x.csv"):
            with pytest.raises(InputError) as info, output_lock(inside):
                pass
            assert info.value.field == "out"
            assert f"inside {out}" in info.value.message and f"pid {holder.proc.pid}" in info.value.message
        with pytest.raises(InputError), output_lock(_folder(out / "sub")):  # compare --out, a second batch
            pass
        with output_lock(tmp_path / "beside.csv"):  # outside it: free
            pass


def _folder(path: Path) -> Path:
    path.mkdir(parents=True, exist_ok=True)
    return path


def test_the_command_line_run_is_refused_inside_a_running_batch_s_folder(tmp_path, capsys):
    """The command's ``main`` in this process, the batch's lock held by another (``Holder``):
    the two processes the property needs; a third for the command only added its start-up."""
    out = tmp_path / "batch"
    with Holder(out) as holder:
        capsys.readouterr()
        mine = out / "runs" / "mine.csv"
        argv = ["run", str(EXAMPLES / "specimen3_free.toml"), "--solver", "housner", "--out", str(mine)]
        code = main(argv)  # a traceback would end the test
        err = capsys.readouterr().err
        assert code == 2, err
        assert "Traceback" not in err and f"pid {holder.proc.pid}" in err
        assert not (out / "runs" / "mine.csv").exists()


def test_a_batch_is_refused_over_a_folder_a_run_is_writing_in(tmp_path):
    out = _folder(tmp_path / "batch")
    (out / DIR_LOCK_NAME).write_text("")  # left by an earlier batch
    with Holder(out / "r.csv"):
        base = load_scene(EXAMPLES / "specimen3_free.toml").to_dict()
        tasks = expand([("s", base)], {}, ["housner"])
        with pytest.raises(InputError) as info:
            run_study_tasks(tasks, out, executor="threads", workers=1, progress=False)
        assert info.value.field == "out" and "something inside it" in info.value.message


def test_a_process_writing_for_the_folder_s_holder_is_let_through(tmp_path):
    out = tmp_path / "batch"
    with Holder(out) as holder:
        with writing_for(out, holder.token), output_lock(out / "runs" / "x.csv"):
            pass
        with writing_for(out, "0" * 16), pytest.raises(InputError), output_lock(out / "runs" / "x.csv"):
            pass  # not the holder's token


def test_this_process_s_own_folder_lock_lets_it_write_inside(tmp_path):
    with output_lock(tmp_path):
        assert len(lock_token(tmp_path)) == 16
        with output_lock(tmp_path / "runs" / "x.csv"):
            pass


def test_a_link_in_place_of_a_folder_lock_is_not_followed(tmp_path):
    victim = tmp_path / "victim"
    victim.write_text("keep")
    folder = _folder(tmp_path / "out")
    (folder / DIR_LOCK_NAME).symlink_to(victim)
    with output_lock(folder / "r.csv"):
        pass
    assert victim.read_text() == "keep"
