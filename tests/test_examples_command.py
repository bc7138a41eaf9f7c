"""``rockyade examples --out DIR`` (issue "What users hit", item 13): the example scenes,
studies and records copied out of the package, refusing what it must not overwrite."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from rockyade.cli import main
from rockyade.cli.examples import example_files, examples_root

from .conftest import EXAMPLES


def test_copies_every_example_and_lists_it(tmp_path, capsys):
    out = tmp_path / "mine"
    assert main(["examples", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    expected = example_files(examples_root())
    assert (out / "specimen1_free.toml").read_bytes() == (EXAMPLES / "specimen1_free.toml").read_bytes()
    assert (out / "records" / "ec8_type2_D_record21.AT2").is_file()
    assert (out / "studies" / "harmonic_sweep.toml").is_file()
    assert sorted(p.relative_to(out) for p in out.rglob("*") if p.is_file()) == sorted(expected)
    for rel in expected:
        assert str(out / rel) in printed
    assert not [p for p in tmp_path.iterdir() if p.name != "mine"]  # no staging folder left


def test_refuses_a_non_empty_folder_unless_forced(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (out / "specimen1_free.toml").write_text("# edited")
    assert main(["examples", "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert (out / "specimen1_free.toml").read_text() == "# edited"
    assert main(["examples", "--out", str(out), "--force"]) == 0
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "specimen1_free.toml").read_bytes() == (EXAMPLES / "specimen1_free.toml").read_bytes()


def test_an_empty_folder_is_filled(tmp_path):
    out = tmp_path / "empty"
    out.mkdir()
    assert main(["examples", "--out", str(out)]) == 0
    assert (out / "specimen1_free.toml").is_file()


def test_never_writes_through_a_symlink(tmp_path, capsys):
    target = tmp_path / "elsewhere"
    target.mkdir()
    link = tmp_path / "link"
    link.symlink_to(target)
    assert main(["examples", "--out", str(link)]) == 2
    assert "symlink" in capsys.readouterr().err
    out = tmp_path / "forced"
    out.mkdir()
    (out / "keep").write_text("x")
    (out / "records").symlink_to(target)
    assert main(["examples", "--out", str(out), "--force"]) == 2
    assert "symlink" in capsys.readouterr().err
    assert list(target.iterdir()) == []


def test_a_file_is_refused(tmp_path, capsys):
    out = tmp_path / "file"
    out.write_text("x")
    assert main(["examples", "--out", str(out)]) == 2
    assert "file" in capsys.readouterr().err


@pytest.mark.slow
def test_a_copied_scene_runs(tmp_path):
    out = tmp_path / "ex"
    assert main(["examples", "--out", str(out)]) == 0
    proc = subprocess.run(
        [sys.executable, "-m", "rockyade", "run", "specimen1_record.toml", "--out", "r/r.csv"],
        cwd=out,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert Path(out / "r" / "r.json").is_file()
