"""Lock files and temporary files never follow a link: an output folder that someone else can
write to cannot be used to wipe or fill a file elsewhere (as root, any file)."""

from __future__ import annotations

import os

import pytest

from rockyade.errors import InputError
from rockyade.io import atomic
from rockyade.io.locking import DIR_LOCK_NAME, output_lock

from .conftest import EXAMPLES

SCENE = EXAMPLES / "specimen1_free.toml"


def _victim(tmp_path):
    victim = tmp_path / "elsewhere" / "precious.txt"
    victim.parent.mkdir()
    victim.write_text("precious\n")
    return victim


@pytest.mark.parametrize("kind", ["symlink", "dangling symlink", "hard link"])
def test_a_lock_file_that_is_a_link_is_refused_and_its_target_kept(tmp_path, kind):
    victim = _victim(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    lock = out / ".r.csv.lock"
    if kind == "symlink":
        lock.symlink_to(victim)
    elif kind == "dangling symlink":
        lock.symlink_to(tmp_path / "elsewhere" / "new.txt")
    else:
        os.link(victim, lock)
    with pytest.raises(InputError) as info, output_lock(out / "r.csv"):
        pass
    assert info.value.field == "out" and str(lock) in info.value.message
    assert ("symbolic link" if "symlink" in kind else "hard link") in info.value.message
    assert victim.read_text() == "precious\n"
    assert not (tmp_path / "elsewhere" / "new.txt").exists()
    assert os.path.lexists(lock)  # left for the user to look at


def test_rockyade_run_with_a_linked_lock_file_exits_2_and_wipes_nothing(tmp_path, capsys):
    """``rockyade run``'s ``main`` in this process (the exit code and message are the command's;
    a traceback would be an exception raised here)."""
    from rockyade.cli import main

    victim = _victim(tmp_path)
    (tmp_path / ".r.csv.lock").symlink_to(victim)
    code = main(["run", str(SCENE), "--out", str(tmp_path / "r.csv")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "symbolic link" in err and "Traceback" not in err
    assert victim.read_text() == "precious\n" and not (tmp_path / "r.csv").exists()


def test_a_folder_lock_that_is_a_link_is_refused(tmp_path):
    victim = _victim(tmp_path)
    out = tmp_path / "batch"
    out.mkdir()
    (out / DIR_LOCK_NAME).symlink_to(victim)
    with pytest.raises(InputError, match="symbolic link"), output_lock(out):
        pass
    assert victim.read_text() == "precious\n"


@pytest.mark.parametrize("kind", ["folder", "fifo"])
def test_a_lock_file_that_is_not_a_plain_file_is_refused(tmp_path, kind):
    lock = tmp_path / ".r.csv.lock"
    if kind == "folder":
        lock.mkdir()
    else:
        os.mkfifo(lock)
    with pytest.raises(InputError, match=r"folder|not a plain file"), output_lock(tmp_path / "r.csv"):
        pass


def test_a_stale_lock_file_of_a_dead_process_is_reused(tmp_path):
    lock = tmp_path / ".r.csv.lock"
    lock.write_text("999999\n")  # left by a killed writer: its flock died with it
    with output_lock(tmp_path / "r.csv"):
        assert lock.read_text().split()[0] == str(os.getpid())  # the PID, then the lock's token
    assert not lock.exists()


def test_a_lock_file_is_created_exclusively_and_removed(tmp_path):
    with output_lock(tmp_path / "r.csv") as lock:
        assert lock.is_file() and not lock.is_symlink() and lock.stat().st_nlink == 1
    assert not lock.exists()


def test_a_temporary_name_that_exists_as_a_link_is_skipped(tmp_path, monkeypatch):
    """The random name of a temporary file is taken (a link planted there): the writer never
    opens it, takes the next name, and the link's target is untouched."""
    victim = _victim(tmp_path)
    names = iter(["planted", "planted", "free"])
    monkeypatch.setattr(atomic, "_random_part", lambda: next(names))
    (tmp_path / ".r.txt.planted.tmp").symlink_to(victim)
    atomic.write_text(tmp_path / "r.txt", "result\n")
    assert (tmp_path / "r.txt").read_text() == "result\n"
    assert victim.read_text() == "precious\n"
    assert (tmp_path / ".r.txt.planted.tmp").is_symlink()
    assert not (tmp_path / ".r.txt.free.tmp").exists()


def test_a_destination_that_is_a_link_is_replaced_not_written_through(tmp_path):
    victim = _victim(tmp_path)
    (tmp_path / "r.txt").symlink_to(victim)
    atomic.write_text(tmp_path / "r.txt", "result\n")
    assert not (tmp_path / "r.txt").is_symlink() and (tmp_path / "r.txt").read_text() == "result\n"
    assert victim.read_text() == "precious\n"


def test_temporary_files_are_created_with_o_excl_and_o_nofollow(tmp_path):
    fd, tmp = atomic.create_temporary(tmp_path / "r.txt")
    os.close(fd)
    assert tmp.is_file() and tmp.name.startswith(".r.txt.") and tmp.name.endswith(".tmp")
    assert tmp.stat().st_mode & 0o777 == 0o600
    victim = _victim(tmp_path)
    names = iter(["x"] * atomic.TEMP_ATTEMPTS)  # every name tried is taken: refused, nothing opened
    (tmp_path / ".r.txt.x.tmp").symlink_to(victim)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(atomic, "_random_part", lambda: next(names))
        with pytest.raises(FileExistsError):
            atomic.create_temporary(tmp_path / "r.txt")
    assert victim.read_text() == "precious\n"


def test_stale_temporaries_are_removed_without_following_links(tmp_path):
    victim = _victim(tmp_path)
    (tmp_path / ".r.csv.abc.tmp").symlink_to(victim)
    (tmp_path / ".old.csv.def.tmp").write_text("half")
    (tmp_path / ".dir.tmp").mkdir()
    removed = atomic.remove_stale_temporaries(tmp_path)
    assert sorted(p.name for p in removed) == [".old.csv.def.tmp", ".r.csv.abc.tmp"]
    assert victim.read_text() == "precious\n" and (tmp_path / ".dir.tmp").is_dir()


def test_a_path_for_a_writer_that_opens_the_file_itself_is_renamed_only_when_complete(tmp_path):
    """atomic_path (the animations' writers open the file and take its format from the suffix):
    the temporary file ends in the destination's suffix and is renamed onto it when the block
    ends; a failed writer leaves the previous file and no temporary; a stale one is cleared."""
    dest = tmp_path / "run.gif"
    dest.write_text("previous")
    with atomic.atomic_path(dest) as tmp:
        assert tmp.parent == tmp_path and tmp.name.startswith(".run.gif.") and tmp.suffix == ".gif"
        assert not tmp.is_symlink() and tmp.read_bytes() == b""
        tmp.write_text("new")
    assert dest.read_text() == "new" and not tmp.exists()
    with pytest.raises(RuntimeError), atomic.atomic_path(dest) as tmp:
        tmp.write_text("half")
        raise RuntimeError("the writer failed")
    assert dest.read_text() == "new" and not tmp.exists()
    (tmp_path / ".run.gif.abc.tmp.gif").write_text("killed")
    assert [p.name for p in atomic.remove_stale_temporaries(tmp_path)] == [".run.gif.abc.tmp.gif"]
