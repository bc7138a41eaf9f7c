"""The command line as a user meets it: quick to answer, clear errors (exit 2 naming the
option or field), no traceback for a closed pipe or an unwritable output, total time printed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from rockyade.cli import main

from .conftest import EXAMPLES, ROOT

#: The package ``rockyade.scene`` itself is light (its names load on first use: ``rockyade build``'s
#: options come from its ``generator_options``); its dataclasses and loader are not.
HEAVY = (
    "numpy",
    "scipy",
    "numba",
    "pandas",
    "matplotlib",
    "rockyade.solvers",
    "rockyade.scene.description",
    "rockyade.scene.loading",
)


def _python(code: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, cwd=cwd or ROOT, timeout=120
    )


def test_building_the_parser_imports_no_heavy_module():
    proc = _python(
        f"""
        import sys
        from rockyade.cli import build_parser
        build_parser().format_help()
        print(sorted(m for m in {HEAVY!r} if m in sys.modules))
        """
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_params_json_imports_neither_pandas_nor_the_solvers():
    proc = _python(
        """
        import sys, io, contextlib
        from rockyade.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["params", "--specimen", "1", "--json"]) == 0
        print(sorted(m for m in ("scipy", "numba", "pandas", "matplotlib", "rockyade.solvers") if m in sys.modules))
        """
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_calibrate_json_imports_neither_numba_nor_the_motions():
    """The paper's calibration is arithmetic: the one calibrate() takes a scene's ContactSpec,
    which must not load the motion types (scipy, numba); only a matched one runs the DEM."""
    proc = _python(
        """
        import sys, io, contextlib
        from rockyade.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["calibrate", "--specimen", "1", "--json"]) == 0
        print(sorted(m for m in ("scipy", "numba", "pandas", "matplotlib", "rockyade.motion") if m in sys.modules))
        """
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_solver_names_of_the_parser_are_the_registry_s():
    from rockyade.cli.common import SOLVER_NAMES
    from rockyade.solvers import solver_names

    assert list(SOLVER_NAMES) == solver_names()


def test_run_prints_solver_and_total_wall_time(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code = main(["run", str(EXAMPLES / "specimen1_free.toml"), "--out", "sub/r.csv"])
    out = capsys.readouterr().out
    assert code == 0 and "(solver)" in out and "(total)" in out
    line = next(x for x in out.splitlines() if "wall time" in x)
    solver_s = float(line.split("wall time ")[1].split(" s (solver)")[0])
    total_s = float(line.split("), ")[1].split(" s (total)")[0])
    assert total_s >= solver_s
    assert (tmp_path / "sub" / "r.csv").is_file() and (tmp_path / "sub" / "r.json").is_file()


def test_closed_pipe_ends_quietly():
    """`rockyade tables | head -1`: a pipe of one page, closed after the first line."""
    import fcntl

    read_end, write_end = os.pipe()
    fcntl.fcntl(write_end, 1031, 4096)  # F_SETPIPE_SZ: the table does not fit in the pipe
    proc = subprocess.Popen([sys.executable, "-m", "rockyade", "tables"], stdout=write_end, stderr=subprocess.PIPE)
    os.close(write_end)
    with os.fdopen(read_end, "rb") as reader:
        assert reader.readline()
    err = proc.communicate(timeout=120)[1].decode()
    assert proc.returncode == 141
    assert "Traceback" not in err and "BrokenPipe" not in err and "Exception ignored" not in err


@pytest.mark.parametrize(
    ("argv", "names"),
    [
        (["motion", "spectrum", "REC", "--t-min", "0"], "t-min"),
        (["motion", "spectrum", "REC", "--t-max", "0.01"], "t-max"),
        (["compare", "SCENE", "--solvers", "housner", "--reference", "yade"], "reference"),
        (["compare", "SCENE", "--solvers", "housner,nope"], "solvers"),
        (["calibrate", "--specimen", "1", "--friction-angle", "95"], "--friction-angle"),
        (
            [
                "batch",
                "STUDY",
                "--out",
                "o",
                "--executor",
                "dask",
                "--scheduler",
                "tcp://127.0.0.1:9",
                "--scheduler-timeout",
                "1",
            ],
            "scheduler",
        ),
        (["batch", "STUDY", "--out", "o", "--workers", "0"], "workers"),
        (["run", "SCENE", "--out", "FILE/x.csv"], "--out"),
        (["tables", "--out", "FILE/tables"], "--out"),
        (
            ["motion", "synth", "--type", "2", "--ground", "D", "--ag-s", "2.8", "--seed", "1", "--out", "FILE/s"],
            "--out",
        ),
    ],
)
def test_clear_errors_name_the_option(tmp_path, capsys, argv, names):
    record = tmp_path / "r.txt"
    record.write_text("0 0.1\n0.01 0.2\n0.02 -0.1\n0.03 0.0\n")
    study = tmp_path / "study.toml"
    study.write_text(f'solvers = ["housner"]\n[base]\nfile = "{EXAMPLES / "specimen1_pulse.toml"}"\n')
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    subst = {"REC": str(record), "STUDY": str(study), "o": str(tmp_path / "o")}
    subst["SCENE"] = str(EXAMPLES / "specimen1_free.toml")
    code = main([subst.get(a, a.replace("FILE", str(blocker))) for a in argv])
    err = capsys.readouterr().err
    assert code == 2, err
    assert f"error: {names}:" in err and "Traceback" not in err


def test_units_named_by_the_file_win_or_conflict_is_refused(tmp_path, capsys):
    at2 = tmp_path / "q.AT2"
    at2.write_text("PEER\nquake\nACCELERATION IN UNITS OF G\nNPTS= 4, DT= .0100 SEC\n 0.1 0.2 -0.1 0.0\n")
    assert main(["motion", "info", str(at2), "--units", "cm/s2"]) == 2
    err = capsys.readouterr().err
    assert "in g" in err and "cm/s2" in err and "line 3" in err
    assert main(["motion", "info", str(at2), "--units", "g", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["pga_m_s2"] == pytest.approx(0.2 * 9.80665)
    csv = tmp_path / "q.csv"
    csv.write_text("time_s,accel_g\n0,0.1\n0.01,0.2\n0.02,-0.1\n")
    assert main(["motion", "info", str(csv), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["units_in_file"] == "g" and info["pga_m_s2"] == pytest.approx(0.2 * 9.80665)
    assert main(["motion", "info", str(csv), "--units", "m/s2"]) == 2


def test_batch_with_a_failed_run_exits_non_zero_and_lists_it(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text((EXAMPLES / "specimen3_free.toml").read_text().replace("duration_s = 4.0", "duration_s = 0.5"))
    study = tmp_path / "study.toml"
    study.write_text(
        f'solvers = ["housner", "reference"]\n[base]\nfile = "{scene}"\n'
        '[grid]\n"contact.calibration" = ["paper", "matched"]\n"blocks.0.mu" = [0.99]\n'
    )
    code = main(["batch", str(study), "--out", str(tmp_path / "out"), "--quiet", "--workers", "1"])
    out = capsys.readouterr().out
    assert code == 1
    assert "1 failed run(s):" in out and "CalibrationError" in out and "_reference" in out


def test_output_files_respect_the_umask(tmp_path):
    from rockyade.io.atomic import write_text
    from rockyade.result import Result
    from rockyade.scene import load_scene
    from rockyade.solvers import run

    result = run(load_scene(EXAMPLES / "specimen1_free.toml"), "housner")
    old = os.umask(0o027)
    try:
        result.write(tmp_path / "r.csv")
        write_text(tmp_path / "t.txt", "x")
    finally:
        os.umask(old)
    for name in ("r.csv", "r.json", "t.txt"):
        assert (tmp_path / name).stat().st_mode & 0o777 == 0o640, name
    assert Result.read(tmp_path / "r.csv").status == "completed"


#: Another process writing ``sys.argv[1]``: holds its lock until its standard input closes,
#: then releases it as a writer that ends does (the lock file removed).
HOLD_UNTIL_STDIN_CLOSES = (
    "import sys\nfrom rockyade.io.locking import output_lock\n"
    "with output_lock(sys.argv[1]):\n    print('held', flush=True)\n    sys.stdin.read()\n"
)


def test_a_second_writer_of_the_same_output_is_refused(tmp_path, capsys):
    """The first writer is another process holding the output's lock (it imports the lock
    alone); the second is the command's ``main`` in this process (a process of its own only
    added rockyade's imports, some 1.2 s of CPU)."""
    out = tmp_path / "r.csv"
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD_UNTIL_STDIN_CLOSES, str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        capsys.readouterr()
        code = main(["run", str(EXAMPLES / "specimen1_free.toml"), "--out", str(out)])
        err = capsys.readouterr().err
        assert code == 2, err
        assert "error: out:" in err and "being written by another rockyade process" in err
        assert f"pid {holder.pid}" in err
    finally:
        holder.communicate(timeout=60)  # its input closed: it releases the lock and ends
    assert holder.returncode == 0
    assert not out.exists()
    assert not (tmp_path / ".r.csv.lock").exists()  # released and removed
    assert main(["run", str(EXAMPLES / "specimen1_free.toml"), "--out", str(out)]) == 0 and out.is_file()


def test_motion_synth_shows_progress(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ROCKYADE_CACHE", str(tmp_path / "cache"))
    argv = ["motion", "synth", "--type", "2", "--ground", "D", "--ag-s", "2.8", "--count", "1", "--seed", "3"]
    code = main([*argv, "--strong", "2", "--decay", "2", "--rise", "1", "--out", str(tmp_path / "s")])
    err = capsys.readouterr().err
    assert code == 0 and "synthesising suite" in err and "1/1" in err


def test_motion_synth_replaces_its_suite_as_a_whole_and_writes_nowhere_else(tmp_path, monkeypatch, capsys):
    """A suite of 1 record written over one of 2 left the old record_02.csv beside the new suite.json
    ('motion check' then read 2 records of two seeds); an assessment's folder got the records mixed
    into it, and a link was written through."""
    monkeypatch.setenv("ROCKYADE_CACHE", str(tmp_path / "cache"))
    argv = ["motion", "synth", "--type", "2", "--ground", "D", "--ag-s", "2.8", "--strong", "2", "--decay", "2"]
    out = tmp_path / "s"
    assert main([*argv, "--rise", "1", "--count", "2", "--seed", "3", "--out", str(out), "--quiet"]) == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "record_01.csv",
        "record_02.csv",
        "suite.json",
    ]
    assert main([*argv, "--rise", "1", "--count", "1", "--seed", "4", "--out", str(out), "--quiet"]) == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == ["record_01.csv", "suite.json"]
    assert json.loads((out / "suite.json").read_text())["settings"]["seed"] == 4
    capsys.readouterr()
    other = tmp_path / "assessment"
    other.mkdir()
    (other / "assess.json").write_text("{}")
    target = tmp_path / "elsewhere"
    target.mkdir()
    (tmp_path / "link").symlink_to(target)
    for folder, words in ((other, "not a suite's (assess.json)"), (tmp_path / "link", "symbolic link")):
        assert main([*argv, "--rise", "1", "--count", "1", "--seed", "4", "--out", str(folder), "--quiet"]) == 2
        assert "--out" in (err := capsys.readouterr().err) and words in err
    assert [p.name for p in other.iterdir()] == ["assess.json"] and not any(target.iterdir())
