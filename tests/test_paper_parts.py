"""``make run``'s paper study: its cross-check has the bi-block with the exact two-block solver
and says which PGA it scans; its header names every solver it runs; the CPU time it prints
counts the processes below it, finished or still running. No study runs here."""

from __future__ import annotations

import subprocess
import sys

from rockyade.analysis.crosscheck_statistics import MIN_RECORDS
from rockyade.solvers import make_solver
from rockyade.studies import free_rocking, paper, paper_crosscheck
from rockyade.studies.report import cpu_seconds


def test_the_cross_check_has_the_bi_block_with_the_exact_solver_at_both_steps():
    todo, _ = paper_crosscheck.jobs(use_yade=False)
    [job] = [j for j in todo if j.folder == "biblock"]
    assert job.solvers == ("twoblock", "reference") and job.dt_factors == (1.0, 0.5)
    # a paired interval (from MIN_RECORDS; under 10 the index calls it rough): 6 keep the part within
    # its 2 minutes on 2 cores (10 took 145 s), the 20-record study is docs/verification.md's
    assert MIN_RECORDS <= job.records < 10
    scene = paper_crosscheck.specimen_scene(job.specimen, job.calibration)
    assert len(scene.blocks) == 2
    for name in job.solvers:  # both reach the scene's alpha, p and mu (twoblock refuses a mu it cannot reach)
        make_solver(name).check_scene(scene)


def test_the_cross_check_says_its_pga_is_the_records_own_peak_not_ag_s():
    line = paper_crosscheck.PGA_LINE
    assert "own peak ground acceleration times the load factor" in line and "ag S" in line


def test_the_report_header_names_every_solver_the_parts_run():
    from rockyade.siconos.backend import siconos_available

    line = paper.solvers_line(paper.PARTS, use_yade=True)
    for name in ("Housner", "reference DEM", "twoblock", "YADE", "Siconos"):
        assert name in line, name
    assert ("not Siconos" in line) != siconos_available()
    quick = paper.solvers_line(("tables", "free"), use_yade=False)
    assert "twoblock" not in quick and "Siconos" not in quick and "--no-yade" in quick


def test_cpu_time_counts_a_child_still_running_and_after_it_ended():
    start = cpu_seconds()
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.5: pass\n"
            "import sys; sys.stdout.write('x'); sys.stdout.flush(); time.sleep(30)",
        ],
        stdout=subprocess.PIPE,
    )
    try:
        assert child.stdout is not None and child.stdout.read(1) == b"x"  # it has burnt its 0.5 s of CPU
        assert cpu_seconds() - start >= 0.5  # counted while it runs (/proc)
    finally:
        child.kill()
        child.wait()
    assert cpu_seconds() - start >= 0.5  # and once it has ended (its parent waited for it)


def test_the_free_rocking_caption_names_yade_only_where_it_ran():
    # `rockyade paper --only free --no-yade` captioned every figure "... and YADE (dashed green ...)"
    # although no YADE curve was drawn
    without = free_rocking.figure_caption("specimen 1", with_yade=False)
    assert "dashed green" not in without and "YADE off" in without
    with_yade = free_rocking.figure_caption("specimen 1", with_yade=True, extra=" Note.")
    assert "YADE (dashed green" in with_yade and with_yade.endswith(" Note.")


def test_paper_refuses_a_linked_out_and_another_commands_results(tmp_path, monkeypatch, capsys):
    # `rockyade paper --out DIR` wrote its tables and index.md into an uncertainty study's folder
    # and through a symbolic link, exit 0; every other study refuses both
    from rockyade.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "frag").mkdir()
    (tmp_path / "frag" / "fragility.json").write_text("{}")
    assert main(["paper", "--only", "tables", "--no-yade", "--out", "frag"]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "'rockyade fragility'" in err
    assert sorted(p.name for p in (tmp_path / "frag").iterdir()) == ["fragility.json"]
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to("real")
    assert main(["paper", "--only", "tables", "--no-yade", "--out", "link"]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert not any((tmp_path / "real").iterdir())


def test_paper_refuses_a_worker_count_out_of_range_before_any_part(tmp_path, monkeypatch, capsys):
    # `rockyade paper --only free --workers 0` ran, the part stopped on the executor's check
    # (a traceback in free_error.log) and the study ended with exit 1
    from rockyade.cli import main

    monkeypatch.chdir(tmp_path)
    for workers in ("0", "-1", "1025"):
        assert main(["paper", "--only", "free", "--no-yade", "--workers", workers, "--out", "out"]) == 2
        err = capsys.readouterr().err
        assert "--workers" in err and "[1, 1024]" in err
    assert not (tmp_path / "out").exists()
